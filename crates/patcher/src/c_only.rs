//! The C-only method (G16 §3.2, `--only-c`) as a method of the driver: the primary axis
//! keeps its values and only C is patched; the driver verifies Equation 6 on C.
//!
//! For a zone, candidates are proposed at widening levels `extra` = 0, 1, 2, 4, 8, …: the
//! G16 patch ([`crate::g16::g16_patch`]) with `extra` CL points beyond its joins, and the
//! direct QP ([`crate::direct::direct_patch`]) over the hull of the zone widened by
//! `extra`, the G16 patch's range and the previous level's direct range, monotone with the
//! sign of the net change, then (only if that does not pass, or passes only beyond the pole
//! reach — the safety bound's, `crate::driver::pole_bound_deg`) without monotonicity.
//!
//! Widening goes on after the first pass while a level lowers the best deviation by at
//! least [`SolverSettings::deviation_improvement_min`], for at most
//! [`SolverSettings::max_levels_after_pass`] levels; it stops at the run's ends or at
//! `max_patch_length_mm`. Needless solves are cut: the direct QP is not solved again on
//! the range of the previous level (same problem, same answer), and once the G16 patch
//! fails (no join, or infeasible after its own widening to the run's ends) it is not
//! tried at wider levels, which would repeat that widening.
//!
//! `max_deviation_deg` is first left out (the driver checks the exact angle of the
//! written values against it); only when nothing within it passes are the levels tried
//! again with it imposed in the QPs (linearised, conservative), so a cap the uncapped
//! result meets never changes that result.

use crate::{
    candidate::{Candidate, PatchFailure},
    direct::direct_patch,
    g16::g16_patch,
    limits::CLimits,
    options::PatchOptions,
    protocol::{Proposal, Proposer, Sink, Tail, ZoneCtx},
    report::Method,
    settings::SolverSettings,
    tolerances::ZERO_NET_C_DEG,
};

/// The C-only method (module docs).
#[derive(Debug, Clone, Copy)]
pub struct COnly {
    /// Propose G16's patch (else the direct QP only).
    pub g16: bool,
}

impl Default for COnly {
    fn default() -> Self {
        COnly { g16: true }
    }
}

impl COnly {
    /// One pass over the widening levels with `opts`.
    fn levels(&self, ctx: &ZoneCtx<'_>, opts: &PatchOptions, sink: &mut dyn Sink) {
        let st: &SolverSettings = ctx.settings;
        let n = ctx.s.len();
        let lim = CLimits::new(ctx.machine, ctx.feed_mm_min, ctx.margin);
        let zone = ctx.zone;
        let reach = ctx.opts.reach_deg();
        let mut direct_range: Option<(usize, usize)> = None;
        let mut levels_after_pass = 0usize;
        let mut g16_gave_up = !self.g16;
        let mut extra = 0usize;
        let offer = |cand: Candidate, method: Method, sink: &mut dyn Sink| {
            let tail = if cand.c_offset_deg != 0.0 {
                Tail::COffset {
                    deg: cand.c_offset_deg,
                }
            } else {
                Tail::Keep
            };
            sink.offer(Proposal {
                method,
                first: cand.first,
                last: cand.last,
                p: ctx.p[cand.first..=cand.last].to_vec(),
                c: cand.c_deg,
                tail,
                qp: cand.qp,
            })
        };
        loop {
            let zone_range = (
                zone.first.saturating_sub(extra).max(ctx.lower),
                (zone.last + extra).min(ctx.end),
            );
            if zone_range.0 > zone_range.1 {
                break;
            }
            let best_before = sink.best_passing_deg();
            let mut range = zone_range;
            if !g16_gave_up {
                match g16_patch(ctx.s, ctx.p, ctx.c, zone, extra, &lim, opts) {
                    Ok(c) => {
                        if c.first >= ctx.lower && c.last < n && c.first <= c.last {
                            range = (range.0.min(c.first), range.1.max(c.last));
                            offer(c, Method::G16Patch, sink);
                        } else {
                            sink.add_stats(&c.qp);
                        }
                    }
                    Err(PatchFailure::Solver(q)) => {
                        sink.add_stats(&q);
                        g16_gave_up = true;
                    }
                    Err(_) => g16_gave_up = true,
                }
            }
            if let Some(d) = direct_range {
                range = (range.0.min(d.0), range.1.max(d.1));
            }
            range = (range.0.max(ctx.lower), range.1.min(ctx.end));
            if range.0 <= range.1
                && range.1 - range.0 < st.direct_max_points
                && direct_range != Some(range)
            {
                direct_range = Some(range);
                let (first, last) = range;
                let net = ctx.c[last] - ctx.c[first];
                let sigma = (net.abs() > ZERO_NET_C_DEG).then(|| net.signum());
                let tries: &[Option<f64>] = if sigma.is_some() {
                    &[sigma, None]
                } else {
                    &[None]
                };
                for &mono in tries {
                    match direct_patch(ctx.s, ctx.p, ctx.c, first, last, &lim, mono, opts) {
                        Ok(c) => {
                            // A pass beyond the pole reach is beyond the safety bound (the
                            // driver refuses it): then try without monotonicity too.
                            if offer(c, Method::Direct, sink)
                                .is_some_and(|o| o.passes && o.deviation_deg <= reach)
                            {
                                break;
                            }
                        }
                        Err(PatchFailure::Solver(q)) => sink.add_stats(&q),
                        Err(_) => {}
                    }
                }
            }
            if let Some(dev) = sink.best_passing_deg() {
                if let Some(prev) = best_before
                    && prev - dev < st.deviation_improvement_min * prev
                {
                    break;
                }
                if dev == 0.0 || levels_after_pass >= st.max_levels_after_pass {
                    break;
                }
                levels_after_pass += 1;
            }
            let at_ends = range.0 <= ctx.lower && range.1 >= ctx.end;
            let too_long = opts
                .max_patch_length_mm
                .is_some_and(|l| ctx.s[range.1] - ctx.s[range.0] >= l);
            if at_ends || too_long || extra > n {
                break;
            }
            extra = if extra == 0 { 1 } else { 2 * extra };
        }
    }
}

/// A sink that passes everything on to `sink` and notes whether a proposal passed with a
/// deviation beyond `cap_deg`.
struct Noting<'s> {
    sink: &'s mut dyn Sink,
    cap_deg: f64,
    passed_beyond: bool,
}

impl Sink for Noting<'_> {
    fn offer(&mut self, p: Proposal) -> Option<crate::protocol::Offered> {
        let o = self.sink.offer(p)?;
        self.passed_beyond |= o.passes && o.deviation_deg > self.cap_deg;
        Some(o)
    }
    fn add_stats(&mut self, qp: &crate::report::QpStats) {
        self.sink.add_stats(qp);
    }
    fn best_passing_deg(&self) -> Option<f64> {
        self.sink.best_passing_deg()
    }
}

impl Proposer for COnly {
    /// The levels without a cap; when nothing within `max_deviation_deg` and the safety
    /// bound passes, again with the cap imposed in the QPs: the smaller of
    /// `max_deviation_deg` and the pole reach — the safety bound of a C-only change
    /// (`crate::driver::pole_bound_deg`, the pole reach), imposed when a proposal passed
    /// beyond it.
    fn propose(&mut self, ctx: &ZoneCtx<'_>, sink: &mut dyn Sink) {
        let uncapped = PatchOptions {
            max_deviation_deg: None,
            ..ctx.opts.clone()
        };
        let reach = ctx.opts.reach_deg();
        let cap = ctx.opts.max_deviation_deg.map_or(reach, |d| d.min(reach));
        let mut noting = Noting {
            sink,
            cap_deg: cap,
            passed_beyond: false,
        };
        self.levels(ctx, &uncapped, &mut noting);
        let (passed_beyond, sink) = (noting.passed_beyond, noting.sink);
        if (ctx.opts.max_deviation_deg.is_some() || passed_beyond)
            && sink.best_passing_deg().is_none()
        {
            let capped = PatchOptions {
                max_deviation_deg: Some(cap),
                ..ctx.opts.clone()
            };
            self.levels(ctx, &capped, sink);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::{AnalysisOptions, analyze_path};
    use crate::direct::deviation_bound_sampled;
    use crate::driver::{PatchResult, patch_with};
    use crate::limits::CLimits;
    use crate::options::PatchAxes;
    use crate::path::Path;
    use crate::report::Outcome;
    use crate::testutil::{machine, planted, sing_path};
    use polepatch_kinematics::Machine;

    /// The C-only method with the direct QP alone.
    fn direct_only(path: &Path, m: &Machine, opts: &PatchOptions) -> PatchResult {
        let opts = PatchOptions {
            axes: PatchAxes::OnlyC,
            ..opts.clone()
        };
        patch_with(path, m, &opts, vec![Box::new(COnly { g16: false })], true).unwrap()
    }

    /// The invariants of the C-only method on a patched path: only C changes (and
    /// `c_changed` says where), C never gets worse, every zone in the cone reaches feed on
    /// C, and the path read back has no zone left.
    fn check_invariants(path: &Path, m: &Machine, res: &PatchResult, opts: &PatchOptions) {
        let before = analyze_path(path, m, &AnalysisOptions::default()).unwrap();
        let mut after_path = path.clone();
        for (q, c) in after_path.axes.iter_mut().zip(&res.c_deg) {
            q[4] = *c;
        }
        for (i, (a, b)) in path.axes.iter().zip(&after_path.axes).enumerate() {
            assert_eq!(a[..4], b[..4]);
            assert_eq!(res.c_changed[i], a[4] != b[4]);
        }
        assert!(!res.p_changed.iter().any(|&c| c), "C-only never moves P");
        let after = analyze_path(&after_path, m, &AnalysisOptions::default()).unwrap();
        assert!(
            after.axis_min[4].0 >= before.axis_min[4].0 - 1e-9,
            "C ratio got worse: {} -> {}",
            before.axis_min[4].0,
            after.axis_min[4].0
        );
        for z in &res.zones {
            if z.min_abs_primary_deg <= opts.cone_deg {
                assert_eq!(z.outcome, Outcome::Reached, "zone not reached: {z:#?}");
                assert!(z.after.c_ratio >= 1.0 - 1e-9, "{z:#?}");
            }
        }
        assert!(after.zones.is_empty(), "zones left: {:?}", after.zones);
    }

    /// Planted flips and swings at 0.01–4° from the pole, two spacings, both machines: the
    /// direct QP alone reaches feed on C; its deviation stays within SPEC §6's 1.25× of the
    /// C-only LP bound over the points it moved.
    #[test]
    fn planted_passes_reach_feed() {
        let opts = PatchOptions::default();
        for (mname, feed) in [("mikron-hsm600", 3000.0), ("mikron-ucp710", 1000.0)] {
            let m = machine(mname);
            let lim0 = CLimits::new(&m, feed, 0.0);
            for flip in [false, true] {
                for d in [0.01, 0.5, 2.0, 4.0] {
                    for spacing in [1.0, 0.5] {
                        let n = (120.0 / spacing) as usize + 1;
                        let path = planted(n, spacing, d, flip, feed);
                        let res = direct_only(&path, &m, &opts);
                        check_invariants(&path, &m, &res, &opts);
                        let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
                        let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
                        for z in &res.zones {
                            // The bound over the points this patch moved (zone ∪ patch).
                            let (bound, _) = deviation_bound_sampled(
                                &path.s_mm,
                                &p,
                                &c,
                                z.first,
                                z.last,
                                &lim0,
                                crate::tolerances::BOUND_SAMPLES_PER_SPAN,
                            )
                            .unwrap();
                            assert!(
                                z.max_deviation_deg <= 1.25 * bound + 1e-3,
                                "{mname} flip={flip} d={d} h={spacing}: {} against {bound}",
                                z.max_deviation_deg
                            );
                        }
                    }
                }
            }
        }
    }

    /// The same planted passes with both formulations (G16 first, direct as fallback).
    #[test]
    fn planted_passes_reach_feed_with_g16() {
        let opts = PatchOptions {
            axes: crate::options::PatchAxes::OnlyC,
            ..PatchOptions::default()
        };
        let mut zones = 0;
        for (mname, feed) in [("mikron-hsm600", 2000.0), ("mikron-ucp710", 2000.0)] {
            let m = machine(mname);
            for flip in [false, true] {
                for d in [0.01, 0.5, 2.0, 4.0] {
                    let path = planted(121, 1.0, d, flip, feed);
                    let res = crate::patch_path(&path, &m, &opts).unwrap();
                    zones += res.zones.len();
                    assert!(
                        res.zones
                            .iter()
                            .all(|z| matches!(z.method, Method::G16Patch | Method::Direct)),
                        "{:?}",
                        res.zones
                    );
                    check_invariants(&path, &m, &res, &opts);
                }
            }
        }
        assert!(zones >= 12, "{zones} zones");
    }

    #[test]
    fn tiny_paths_and_the_exact_pole_do_not_panic() {
        let m = machine("mikron-ucp710");
        let three = Path {
            s_mm: vec![0.0, 1.0, 2.0],
            axes: vec![
                [0.0, 0.0, 0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0, 0.0, 90.0],
                [2.0, 0.0, 0.0, -1.0, 180.0],
            ],
            feed_mm_min: 2000.0,
        };
        let res = direct_only(&three, &m, &PatchOptions::default());
        assert_eq!(res.c_deg.len(), 3);
        let mut pole = planted(81, 1.0, 0.0, false, 2000.0);
        pole.axes[40][3] = 0.0;
        let res = direct_only(&pole, &m, &PatchOptions::default());
        assert_eq!(res.c_deg.len(), 81);
    }

    /// C17's `%SING` on both machines: reached on C, the deviation between the C-only LP
    /// bound and 1.25× it (G16's method keeps A, whose jerk then limits on the UCP710).
    #[test]
    fn c17_sing() {
        let path = sing_path();
        let opts = PatchOptions::default();
        for mname in ["mikron-ucp710", "mikron-hsm600"] {
            let m = machine(mname);
            let res = direct_only(&path, &m, &opts);
            assert_eq!(res.zones.len(), 1);
            let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
            let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
            let z = &res.zones[0];
            let lim0 = CLimits::new(&m, 2000.0, 0.0);
            let (bound, _) = deviation_bound_sampled(
                &path.s_mm,
                &p,
                &c,
                z.first,
                z.last,
                &lim0,
                crate::tolerances::BOUND_SAMPLES_PER_SPAN,
            )
            .unwrap();
            assert!(bound <= z.max_deviation_deg + 1e-6, "{mname}");
            assert!(
                z.max_deviation_deg <= 1.25 * bound,
                "{mname}: {} vs {bound}",
                z.max_deviation_deg
            );
            assert!(
                z.after.time_s < z.before.time_s,
                "{mname}: faster over the zone"
            );
            check_invariants(&path, &m, &res, &opts);
        }
    }
}
