//! The proofs behind the driver's reasons `proven_unreachable`, `end_pinned` and `range`
//! ([`why_not_reached`]); the bench reference ([`crate::reference`]) asks the same
//! relaxation first.
//!
//! # The relaxation (a proof when infeasible)
//! A written patch passes when, on the values as written ([`crate::driver`]):
//! - every checked rotary axis reaches feed on the zone's core spans: its ratio, the
//!   minimum over the span of Equation 6, is at least `X = 1 − RATIO_TOL`;
//! - no other span gets worse: its ratio is at least
//!   `X = crate::verify::not_worse_floor(before)`;
//! - the primary axis (and C, where its range is finite) stays within the machine's range.
//!
//! Equation 6's ratio is at least X on a span exactly when, for the derivative of order
//! p = 1, 2, 3, `|q⁽ᵖ⁾(s)| ≤ L_p / (F·X)^p` at **every** s of the span (the limits V, A, J).
//! [`reachable`] keeps these bounds at finitely many s only — `PROOF_SAMPLES_PER_SPAN + 1`
//! points of each span for q', both ends for q'', q''' (constant) — on the spans within
//! [`PROOF_SPAN_MARGIN`] of the movable points and the core, and no rounding room and no
//! margin at all. The analysis spline is modelled exactly: the Hermite rows of
//! [`crate::hermite`] over the **whole** run (not-a-knot at both of its ends). Every
//! values that pass therefore satisfy the LP (rounded or not, on either IK branch, with a
//! tail re-selected or not: the LP's variables are any values of the movable points): the
//! LP is a relaxation of the requirement. So when clarabel proves it infeasible
//! (`PrimalInfeasible`, to its certificate tolerance), **no** values of the movable points
//! pass. A solver error proves nothing (the zone is then `not_found`).
//!
//! The driver asks it three ways for a zone that did not reach feed: with the points it
//! may change (infeasible: `proven_unreachable`, unless one of the next two is feasible);
//! with the run's last point free too when it must stay (feasible: `end_pinned`); without
//! the range rows (feasible: `range`).

use crate::{
    analysis::Zone,
    candidate::PatchFailure,
    hermite::{Aff, Hermite, push_abs},
    limits::GeomLimits,
    options::{PatchAxes, PatchOptions},
    path::Path,
    qp::QpBuilder,
    report::{QpStats, Reason},
    spline::{AnalysisSpline, span_offsets},
    tolerances::{PROOF_SAMPLES_PER_SPAN, PROOF_SPAN_MARGIN, RATIO_TOL},
    verify::not_worse_floor,
    zones::zone_core,
};
use polepatch_kinematics::{Axis, Machine, axis_feed_ratio};

/// Whether some values of points `first..=last` could pass (the relaxation of the module
/// docs; `Ok(false)` is a proof that none can). `p_deg`, `c_deg` are the values of the
/// whole path before the change, `core` the spans that must reach feed; `axes` which
/// rotary axes may change and are checked; `ranges` whether the machine's axis ranges
/// count.
#[allow(clippy::too_many_arguments)]
pub fn reachable(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    core: std::ops::Range<usize>,
    machine: &Machine,
    feed_mm_min: f64,
    axes: PatchAxes,
    ranges: bool,
) -> Result<bool, PatchFailure> {
    let n = s_mm.len();
    if first > last || last >= n {
        return Err(PatchFailure::TooShort);
    }
    let feed_mm_s = feed_mm_min / 60.0;
    let moving: &[Axis] = match axes {
        PatchAxes::Both => &[Axis::Primary, Axis::C],
        PatchAxes::OnlyC => &[Axis::C],
    };
    let mut hermites: Vec<(Axis, Hermite)> = Vec::new();
    let mut offset = 0;
    for &axis in moving {
        let y = if axis == Axis::C { c_deg } else { p_deg };
        let h = Hermite::with_offset(s_mm, y, first, last, n, offset)?;
        offset += h.vars();
        hermites.push((axis, h));
    }
    let mut qp = QpBuilder::new(offset);
    for (_, h) in &hermites {
        h.add_equalities(&mut qp);
    }
    let spans = first.min(core.start).saturating_sub(PROOF_SPAN_MARGIN)
        ..(last.max(core.end) + PROOF_SPAN_MARGIN).min(n - 1);
    let mut taus = Vec::new();
    for (axis, h) in &hermites {
        let y = if *axis == Axis::C { c_deg } else { p_deg };
        let before = AnalysisSpline::new(s_mm, y).map_err(|_| PatchFailure::TooShort)?;
        let lim = GeomLimits::of(machine, *axis, feed_mm_min, 0.0);
        let limits = machine.limit(*axis);
        for k in spans.clone() {
            let hk = s_mm[k + 1] - s_mm[k];
            let x = if core.contains(&k) {
                1.0 - RATIO_TOL
            } else {
                let peaks = before.span(s_mm[k], hk).peaks().0;
                let r = axis_feed_ratio(limits, peaks, feed_mm_s);
                not_worse_floor(r)
            };
            if x <= 0.0 || x.is_nan() {
                continue; // the span may be anything
            }
            let row = |qp: &mut QpBuilder, f: &Aff, b: f64| {
                if b.is_finite() {
                    push_abs(qp, f, b);
                }
            };
            span_offsets(hk, PROOF_SAMPLES_PER_SPAN, &mut taus);
            for &tau in &taus {
                row(&mut qp, &h.d1(k, tau), lim.v / x);
            }
            row(&mut qp, &h.d2(k, 0.0), lim.a / (x * x));
            row(&mut qp, &h.d2(k, hk), lim.a / (x * x));
            row(&mut qp, &h.d3(k), lim.j / (x * x * x));
        }
        if ranges {
            let range = if *axis == Axis::C {
                machine.c_range_deg
            } else {
                Some(machine.primary_range_deg)
            };
            if let Some((lo, hi)) = range {
                for (i, yi) in y.iter().enumerate().take(last + 1).skip(first) {
                    let v = h.delta_var(i);
                    qp.add_le(&[(v, 1.0)], hi - yi);
                    qp.add_le(&[(v, -1.0)], yi - lo);
                }
            }
        }
    }
    let mut st = QpStats::default();
    match qp.solve(&mut st) {
        Ok(_) => Ok(true),
        Err(s) if s.is_infeasible() => Ok(false),
        Err(_) => Err(PatchFailure::Solver(st)),
    }
}

/// The reason a zone that did not reach feed (and whose patch was not refused by the cap)
/// ended so (module docs): the relaxation with the points the zone could change
/// (`lower..=end` on the current values `p`, `c`), then with the last point free, then
/// without the ranges.
#[allow(clippy::too_many_arguments)]
pub(crate) fn why_not_reached(
    path: &Path,
    p: &[f64],
    c: &[f64],
    zone: &Zone,
    machine: &Machine,
    opts: &PatchOptions,
    lower: usize,
    end: usize,
) -> Reason {
    let n = path.s_mm.len();
    let core = zone_core(zone, n, opts.solver.core_margin_points);
    let lp = |last: usize, ranges: bool| {
        reachable(
            &path.s_mm,
            p,
            c,
            lower,
            last,
            core.clone(),
            machine,
            path.feed_mm_min,
            opts.axes,
            ranges,
        )
    };
    if lower > end {
        return Reason::NotFound;
    }
    match lp(end, true) {
        Ok(false) => {}
        _ => return Reason::NotFound,
    }
    if end < n - 1 && lp(n - 1, true) == Ok(true) {
        return Reason::EndPinned;
    }
    if lp(end, false) == Ok(true) {
        return Reason::Range;
    }
    Reason::ProvenUnreachable
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{machine, planted, sing_path};

    fn pc(path: &Path) -> (Vec<f64>, Vec<f64>) {
        (
            path.axes.iter().map(|q| q[3]).collect(),
            path.axes.iter().map(|q| q[4]).collect(),
        )
    }

    /// A relaxation holds whatever passes: where the patcher writes values that reach feed
    /// (verified), the relaxation over the same points is feasible — on SING and planted
    /// flips and swings, both machines.
    #[test]
    fn what_passes_satisfies_the_relaxation() {
        let cases = [
            ("mikron-ucp710", sing_path()),
            ("mikron-hsm600", sing_path()),
            ("mikron-ucp710", planted(241, 0.5, 0.5, false, 1000.0)),
            ("mikron-hsm600", planted(241, 0.5, 2.0, true, 3000.0)),
        ];
        for (name, path) in cases {
            let m = machine(name);
            let res = crate::patch_path(&path, &m, &PatchOptions::default()).unwrap();
            assert!(!res.zones.is_empty());
            let (p, c) = pc(&path);
            let n = p.len();
            let a = crate::analyze_path(&path, &m, &Default::default()).unwrap();
            for z in &a.zones {
                let core = zone_core(z, n, 3);
                assert_eq!(
                    reachable(
                        &path.s_mm,
                        &p,
                        &c,
                        1,
                        n - 1,
                        core,
                        &m,
                        path.feed_mm_min,
                        PatchAxes::Both,
                        true
                    ),
                    Ok(true),
                    "{name}: the patcher reached feed, so the relaxation must be feasible"
                );
            }
        }
    }

    /// The proof, planted: a pass 1° from the pole on a 5° circle, 15 mm long at F5000 on
    /// the UCP710 — the tool axis must turn far more than A and C can in 15 mm — is
    /// infeasible with its last point held; and a relaxation with fewer points movable is
    /// never feasible where one with more is not (monotone, as a relaxation must be).
    #[test]
    fn an_impossible_zone_is_proven_unreachable() {
        let m = machine("mikron-ucp710");
        let pass = polepatch_fixturegen::Pass {
            pole_distance_deg: 1.0,
            circle_radius_deg: 5.0,
            half_sweep_deg: 80.0,
            length_mm: 15.0,
            spacing_mm: 0.5,
            feed_mm_min: 5000.0,
            ..polepatch_fixturegen::Pass::default()
        };
        let axes = polepatch_fixturegen::joints(&pass);
        let path = Path {
            s_mm: axes.iter().map(|q| q[0]).collect(),
            axes,
            feed_mm_min: 5000.0,
        };
        let (p, c) = pc(&path);
        let n = p.len();
        let lp = |last: usize| {
            reachable(
                &path.s_mm,
                &p,
                &c,
                1,
                last,
                0..n - 1,
                &m,
                5000.0,
                PatchAxes::Both,
                true,
            )
        };
        assert_eq!(lp(n - 2), Ok(false), "pinned: no values reach feed");
        // Movable points a subset: still infeasible.
        assert_eq!(
            reachable(
                &path.s_mm,
                &p,
                &c,
                5,
                n - 6,
                0..n - 1,
                &m,
                5000.0,
                PatchAxes::Both,
                true
            ),
            Ok(false)
        );
        // The driver's reason for it.
        let opts = PatchOptions {
            keep_last_point: true,
            ..PatchOptions::default()
        };
        let res = crate::patch_path(&path, &m, &opts).unwrap();
        for z in &res.zones {
            assert_ne!(z.outcome, crate::Outcome::Reached);
            assert!(
                matches!(z.reason, Reason::ProvenUnreachable | Reason::EndPinned),
                "{z:?}"
            );
        }
    }

    /// The range rows are what `ranges` adds: a swing 0.5° from the pole over 30 mm at
    /// F1000 on the UCP710, every point but the two ends movable. Without the range rows
    /// the relaxation is feasible (C can make its half turn in 30 mm at ≤ 7.2 °/mm); with a
    /// primary range [20°, 30°] it is not (the ends sit near 6°, and A, at feed there
    /// before, cannot jump 14° within one 0.5 mm span) — the two LPs the driver's reason
    /// `range` compares. (The relaxation says nothing about the orientation: only fixed
    /// points and the ranges can make it infeasible.)
    #[test]
    fn the_range_rows_are_what_ranges_adds() {
        let mut m = machine("mikron-ucp710");
        m.primary_range_deg = (20.0, 30.0);
        let path = planted(61, 0.5, 0.5, false, 1000.0);
        let (p, c) = pc(&path);
        let a = crate::analyze_path(&path, &m, &Default::default()).unwrap();
        let core = zone_core(&a.zones[0], 61, 3);
        let lp = |ranges| {
            reachable(
                &path.s_mm,
                &p,
                &c,
                1,
                59,
                core.clone(),
                &m,
                1000.0,
                PatchAxes::Both,
                ranges,
            )
        };
        assert_eq!(lp(false), Ok(true), "without the range rows");
        assert_eq!(lp(true), Ok(false), "with them");
    }
}
