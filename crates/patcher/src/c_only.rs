//! The C-only method (G16 §3.2, `--only-c`): the primary axis keeps its values and only C
//! is patched; Equation 6 is verified on C.
//!
//! For each singular zone (in path order, on the C values already updated by the zones
//! before it), candidates are tried at widening levels `extra` = 0, 1, 2, 4, 8, …: the
//! G16 patch ([`crate::g16::g16_patch`]) with `extra` CL points beyond its joins, and the
//! direct QP ([`crate::direct::direct_patch`]) over the hull of the zone widened by
//! `extra`, the G16 patch's range and the previous level's direct range, monotone with the
//! sign of the net change, then (only if that does not pass) without monotonicity. A
//! candidate is applied, rounded as written (`c_decimals`, then one more decimal at a time
//! up to `max_decimals` when only the rounding breaks it) and verified
//! ([`crate::verify::verify_change`]): C reaches feed around the patch and no sample gets
//! worse.
//!
//! **Selection (SPEC §6).** Of the passing candidates the one with the smallest exact max
//! orientation deviation ([`orientation_deviation_deg`]) is kept. Widening goes on after
//! the first pass while a level lowers the best deviation by at least
//! [`DEVIATION_IMPROVEMENT_MIN`], for at most [`MAX_LEVELS_AFTER_PASS`] levels. When no
//! candidate passes within the limits, the best improvement (if any) is kept, else the
//! zone is left as it was.

use crate::{
    analysis::{AnalysisOptions, RATIO_TOL, Zone, analyze_path, validate},
    candidate::{Candidate, PatchFailure},
    direct::{direct_patch, orientation_deviation_deg},
    g16::g16_patch,
    limits::CLimits,
    options::{PatchOptions, round_written},
    patch::{PatchResult, merge_zones, zone_figures},
    path::{Path, PathError},
    qp::add_stats,
    report::{Method, Outcome, QpStats, ZoneReport},
    verify::{AxisChange, VERIFY_MARGIN_POINTS, Verdict, verify_change},
};
use polepatch_kinematics::{Axis, Machine};

/// Factors applied to `PatchOptions::margin`, in order, when no candidate passes
/// verification: the configured margin, a quarter of it, none.
pub const MARGIN_LADDER: [f64; 3] = [1.0, 0.25, 0.0];

/// Largest range the direct QP is tried on, points (its rows are sparse, but a wider
/// range than this is not a patch any more).
pub const DIRECT_MAX_POINTS: usize = 400;

/// A widening level after the first passing candidate that lowers the best max
/// orientation deviation by less than this fraction of it ends the search (the direct QP's
/// min-max over a growing range only goes down, and levels off within a few levels).
pub const DEVIATION_IMPROVEMENT_MIN: f64 = 0.05;

/// Most widening levels tried after the level of the first passing candidate (a cap on
/// the extra solves the improvement search may cost).
pub const MAX_LEVELS_AFTER_PASS: usize = 3;

/// Which formulations [`patch_c_only`] may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Methods {
    /// Try the G16 patch.
    pub g16: bool,
    /// Try the direct QP.
    pub direct: bool,
}

/// A candidate after rounding and verification.
#[derive(Debug, Clone)]
struct Checked {
    method: Method,
    first: usize,
    last: usize,
    /// Written values for `first..=last`.
    values: Vec<f64>,
    offset: f64,
    decimals: usize,
    verdict: Verdict,
}

/// Both formulations (the default).
pub(crate) const ALL_METHODS: Methods = Methods {
    g16: true,
    direct: true,
};

/// The C-only method on a path, with a choice of formulations.
pub(crate) fn patch_c_only(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
    methods: Methods,
) -> Result<PatchResult, PathError> {
    validate(path)?;
    let n = path.s_mm.len();
    let c0: Vec<f64> = path.axes.iter().map(|q| q[Axis::C.index()]).collect();
    let pi = Axis::Primary.index();
    if !path.axes.iter().any(|q| q[pi].abs() <= opts.cone_deg) {
        return Ok(PatchResult::unchanged(path, opts));
    }
    let aopts = AnalysisOptions {
        cone_deg: opts.cone_deg,
        tcy_s: opts.tcy_s,
        keep_samples: false,
    };
    let analysis = analyze_path(path, machine, &aopts)?;
    if analysis.zones.is_empty() {
        return Ok(PatchResult::unchanged(path, opts));
    }
    let ctx = Ctx {
        s: &path.s_mm,
        p: path.axes.iter().map(|q| q[pi]).collect(),
        lim: std::cell::Cell::new(CLimits::new(machine, path.feed_mm_min, opts.margin)),
        machine,
        feed_mm_s: path.feed_mm_min / 60.0,
        opts,
        methods,
    };
    let mut cur = c0.clone();
    let mut changed = vec![false; n];
    let mut done: Vec<(Zone, Option<Checked>, Outcome, QpStats)> = Vec::new();
    // Point 0 is where the run starts: it belongs to the block before the run and is never moved.
    let mut lower = 1;
    for zone in merge_zones(&analysis.zones) {
        let mut stats = QpStats::default();
        // The margin only guards the solvers' aim against projection and rounding; what
        // counts is the verification on the written values, without margin. When nothing
        // passes with the configured margin, aim closer to the limits before giving up.
        let mut found: Option<(Checked, bool)> = None;
        for factor in MARGIN_LADDER {
            ctx.lim.set(CLimits::new(
                machine,
                path.feed_mm_min,
                opts.margin * factor,
            ));
            match ctx.patch_zone(&cur, &zone, lower, &mut stats) {
                Some((c, true)) => {
                    found = Some((c, true));
                    break;
                }
                Some((c, false)) => {
                    let better = found.as_ref().is_none_or(|(b, _)| {
                        c.verdict.core_min_after > b.verdict.core_min_after + RATIO_TOL
                    });
                    if better {
                        found = Some((c, false));
                    }
                }
                None => {}
            }
            if opts.margin == 0.0 {
                break;
            }
        }
        let (kept, outcome) = match found {
            Some((c, true)) => (Some(c), Outcome::Reached),
            Some((c, false)) => (Some(c), Outcome::Improved),
            None => (None, Outcome::Unchanged),
        };
        if let Some(k) = &kept {
            for (i, v) in (k.first..=k.last).zip(&k.values) {
                cur[i] = *v;
                changed[i] = cur[i] != c0[i];
            }
            if k.offset != 0.0 {
                for i in k.last + 1..n {
                    cur[i] = round_written(cur[i] + k.offset, k.decimals);
                    changed[i] = cur[i] != c0[i];
                }
            }
            lower = k.last + 1;
        } else {
            lower = lower.max(zone.last + 1);
        }
        done.push((zone, kept, outcome, stats));
    }

    let mut after_path = path.clone();
    for (q, c) in after_path.axes.iter_mut().zip(&cur) {
        q[Axis::C.index()] = *c;
    }
    let mut reports = Vec::with_capacity(done.len());
    let mut decimals = opts.c_decimals;
    for (zone, kept, outcome, qp) in done {
        let (first, last) = match &kept {
            Some(k) => (zone.first.min(k.first), zone.last.max(k.last)),
            None => (zone.first, zone.last),
        };
        let before = zone_figures(path, machine, &aopts, first, last)?;
        let after = match &kept {
            Some(_) => zone_figures(&after_path, machine, &aopts, first, last)?,
            None => before,
        };
        let max_dev = (first..=last)
            .map(|i| orientation_deviation_deg(ctx.p[i], cur[i] - c0[i]))
            .fold(0.0, f64::max);
        let d = kept.as_ref().map_or(opts.c_decimals, |k| k.decimals);
        decimals = decimals.max(d);
        reports.push(ZoneReport {
            first,
            last,
            kind: zone.kind,
            min_abs_primary_deg: zone.min_abs_primary_deg,
            before,
            after,
            ideal_time_s: (path.s_mm[last] - path.s_mm[first]) / (path.feed_mm_min / 60.0),
            max_deviation_deg: max_dev,
            points_modified: kept
                .as_ref()
                .map_or(0, |k| (k.first..=k.last).filter(|&i| changed[i]).count()),
            primary_points_modified: 0,
            reselected_points: 0,
            patch_length_mm: kept
                .as_ref()
                .map_or(0.0, |k| path.s_mm[k.last] - path.s_mm[k.first]),
            outcome,
            method: kept.as_ref().map_or(Method::None, |k| k.method),
            qp,
            decimals: d,
            p_decimals: opts.p_decimals,
            c_offset_deg: kept.as_ref().map_or(0.0, |k| k.offset),
        });
    }
    Ok(PatchResult {
        p_deg: ctx.p.clone(),
        p_changed: vec![false; n],
        p_decimals: opts.p_decimals,
        c_deg: cur,
        c_changed: changed,
        c_decimals: decimals,
        zones: reports,
    })
}

/// What every zone shares.
struct Ctx<'a> {
    s: &'a [f64],
    p: Vec<f64>,
    /// Limits with the margin (what the solvers aim at); lowered along
    /// [`MARGIN_LADDER`] when no candidate passes.
    lim: std::cell::Cell<CLimits>,
    /// The machine (its limits without margin are what the verification checks).
    machine: &'a Machine,
    /// Programmed feed, mm/s.
    feed_mm_s: f64,
    opts: &'a PatchOptions,
    methods: Methods,
}

impl Ctx<'_> {
    /// The last point that may move (the path's last, unless it must stay).
    fn end(&self) -> usize {
        let n = self.s.len();
        if self.opts.keep_last_point {
            n - 2
        } else {
            n - 1
        }
    }

    /// Try candidates for `zone` on the current values `cur`, not touching points before
    /// `lower`. `Some((kept, reached))`, or `None` when nothing better was found.
    ///
    /// Widening levels `extra` = 0, 1, 2, 4, …: at each, the G16 patch widened by `extra`
    /// and the direct QP over the hull of the zone widened by `extra`, the G16 patch's
    /// range and the previous level's direct range (so the direct range only grows and its
    /// min-max deviation can only go down), monotone first, without monotonicity only
    /// when the monotone candidate does not pass. Among the passing candidates the one with
    /// the smallest exact max deviation is kept. The widening stops at the first level
    /// after a pass that lowers the best deviation by less than
    /// [`DEVIATION_IMPROVEMENT_MIN`], after [`MAX_LEVELS_AFTER_PASS`] levels past the
    /// first pass, or at the run's ends / `max_patch_length_mm`.
    ///
    /// Needless solves are cut: the direct QP is not solved again on the range of the
    /// previous level (same problem, same answer), and once the G16 patch fails (no join, or
    /// infeasible after its own widening to the run's ends) it is not tried at wider levels,
    /// which would repeat that widening.
    fn patch_zone(
        &self,
        cur: &[f64],
        zone: &Zone,
        lower: usize,
        stats: &mut QpStats,
    ) -> Option<(Checked, bool)> {
        let n = self.s.len();
        let mut best: Option<Checked> = None;
        let mut passed: Option<(Checked, f64)> = None;
        let mut direct_range: Option<(usize, usize)> = None;
        let mut levels_after_pass = 0usize;
        let mut g16_gave_up = false;
        let mut extra = 0usize;
        loop {
            let zone_range = (
                zone.first.saturating_sub(extra).max(lower),
                (zone.last + extra).min(self.end()),
            );
            if zone_range.0 > zone_range.1 {
                break;
            }
            let best_before = passed.as_ref().map(|p| p.1);
            let mut range = zone_range;
            let consider = |c: Checked, passed: &mut Option<(Checked, f64)>| {
                let dev = self.max_deviation(cur, &c);
                if passed.as_ref().is_none_or(|p| dev < p.1) {
                    *passed = Some((c, dev));
                }
            };
            if self.methods.g16 && !g16_gave_up {
                match g16_patch(
                    self.s,
                    &self.p,
                    cur,
                    zone,
                    extra,
                    &self.lim.get(),
                    self.opts,
                ) {
                    Ok(c) => {
                        add_stats(stats, &c.qp);
                        if c.first >= lower && c.last < n && c.first <= c.last {
                            range = (range.0.min(c.first), range.1.max(c.last));
                            if let Some(ok) = self.check(cur, &c, Method::G16Patch, &mut best) {
                                consider(ok, &mut passed);
                            }
                        }
                    }
                    Err(PatchFailure::Solver(st)) => {
                        add_stats(stats, &st);
                        g16_gave_up = true;
                    }
                    Err(_) => g16_gave_up = true,
                }
            }
            if let Some(d) = direct_range {
                range = (range.0.min(d.0), range.1.max(d.1));
            }
            if self.methods.direct
                && range.1 - range.0 < DIRECT_MAX_POINTS
                && direct_range != Some(range)
            {
                direct_range = Some(range);
                let (first, last) = range;
                let net = cur[last] - cur[first];
                let sigma = (net.abs() > 1e-9).then(|| net.signum());
                let tries: &[Option<f64>] = if sigma.is_some() {
                    &[sigma, None]
                } else {
                    &[None]
                };
                for &mono in tries {
                    match direct_patch(
                        self.s,
                        &self.p,
                        cur,
                        first,
                        last,
                        &self.lim.get(),
                        mono,
                        self.opts,
                    ) {
                        Ok(c) => {
                            add_stats(stats, &c.qp);
                            if let Some(ok) = self.check(cur, &c, Method::Direct, &mut best) {
                                consider(ok, &mut passed);
                                break;
                            }
                        }
                        Err(PatchFailure::Solver(st)) => add_stats(stats, &st),
                        Err(_) => {}
                    }
                }
            }
            if let Some((_, dev)) = &passed {
                if let Some(prev) = best_before
                    && prev - dev < DEVIATION_IMPROVEMENT_MIN * prev
                {
                    break;
                }
                if *dev == 0.0 || levels_after_pass >= MAX_LEVELS_AFTER_PASS {
                    break;
                }
                levels_after_pass += 1;
            }
            let at_ends = range.0 <= lower && range.1 >= self.end();
            let too_long = self
                .opts
                .max_patch_length_mm
                .is_some_and(|l| self.s[range.1] - self.s[range.0] >= l);
            if at_ends || too_long || extra > n {
                break;
            }
            extra = if extra == 0 { 1 } else { 2 * extra };
        }
        match passed {
            Some((c, _)) => Some((c, true)),
            None => best.map(|b| (b, false)),
        }
    }

    /// Largest exact orientation deviation of a checked candidate against `cur`.
    fn max_deviation(&self, cur: &[f64], c: &Checked) -> f64 {
        (c.first..=c.last)
            .zip(&c.values)
            .map(|(i, v)| orientation_deviation_deg(self.p[i], v - cur[i]))
            .fold(0.0, f64::max)
    }

    /// Round and verify a candidate; `Some` when it passes, else it may become `best`.
    fn check(
        &self,
        cur: &[f64],
        cand: &Candidate,
        method: Method,
        best: &mut Option<Checked>,
    ) -> Option<Checked> {
        let n = self.s.len();
        let (first, last) = (cand.first, cand.last);
        if cand.c_deg.len() != last - first + 1 || cand.c_deg.iter().any(|v| !v.is_finite()) {
            return None;
        }
        if last > self.end() || (cand.c_offset_deg != 0.0 && self.opts.keep_last_point) {
            return None; // would move the last point, which must stay
        }
        // Window of the path that the verification reads.
        let lo = first.saturating_sub(VERIFY_MARGIN_POINTS + 1);
        let hi = (last + VERIFY_MARGIN_POINTS + 1).min(n - 1);
        let before = &cur[lo..=hi];
        let build = |d: Option<usize>| -> Vec<f64> {
            let r = |v: f64| d.map_or(v, |d| round_written(v, d));
            let mut w = before.to_vec();
            for (i, v) in (first..=last).zip(&cand.c_deg) {
                w[i - lo] = r(*v);
            }
            if cand.c_offset_deg != 0.0 {
                for i in last + 1..=hi {
                    w[i - lo] = r(cur[i] + cand.c_offset_deg);
                }
            }
            w
        };
        let verify = |after: &[f64]| {
            let ch = [AxisChange {
                axis: Axis::C,
                before,
                after,
            }];
            verify_change(
                &self.s[lo..=hi],
                &ch,
                first - lo,
                last - lo,
                self.machine,
                self.feed_mm_s,
            )
        };
        let mut last_checked = None;
        for d in self.opts.c_decimals..=self.opts.max_decimals.max(self.opts.c_decimals) {
            let w = build(Some(d));
            let v = verify(&w);
            let checked = Checked {
                method,
                first,
                last,
                values: w[first - lo..=last - lo].to_vec(),
                offset: cand.c_offset_deg,
                decimals: d,
                verdict: v,
            };
            if v.passes() {
                return Some(checked);
            }
            last_checked = Some(checked);
            if d == self.opts.c_decimals && !verify(&build(None)).passes() {
                break; // not a rounding problem: more decimals will not help
            }
        }
        if let Some(c) = last_checked
            && c.verdict.improves()
            && c.verdict.core_min_after > 0.0
            && best
                .as_ref()
                .is_none_or(|b| c.verdict.core_min_after > b.verdict.core_min_after + RATIO_TOL)
        {
            *best = Some(c);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::direct::deviation_bound_sampled;
    use crate::limits::CLimits;
    use crate::testutil::{machine, planted, sing_path};

    const DIRECT_ONLY: Methods = Methods {
        g16: false,
        direct: true,
    };

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
                        let res = patch_c_only(&path, &m, &opts, DIRECT_ONLY).unwrap();
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
                                crate::direct::BOUND_SAMPLES_PER_SPAN,
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
        let res = patch_c_only(&three, &m, &PatchOptions::default(), DIRECT_ONLY).unwrap();
        assert_eq!(res.c_deg.len(), 3);
        let mut pole = planted(81, 1.0, 0.0, false, 2000.0);
        pole.axes[40][3] = 0.0;
        let res = patch_c_only(&pole, &m, &PatchOptions::default(), DIRECT_ONLY).unwrap();
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
            let res = patch_c_only(&path, &m, &opts, DIRECT_ONLY).unwrap();
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
                crate::direct::BOUND_SAMPLES_PER_SPAN,
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
