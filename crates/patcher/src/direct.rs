//! The direct formulation: a sparse QP on the CL C values through the analysis spline
//! written in Hermite form, and the lower bound on the orientation deviation (SPEC §6).
//!
//! The analysis spline's linear form (knot slopes as variables, tied to the values by the
//! spline's own conditions) is in [`crate::hermite`].
//!
//! # The direct QP
//!
//! New values `y_i = C_i + δ_i` at `i = first..=last` (every other point fixed), the
//! slopes `m_k` of the window `lo = first − W .. hi = last + W` (clipped to the path,
//! W = [`HERMITE_WINDOW_POINTS`]) and `t`. On a span the quadratic q' has Bernstein coefficients
//! `b0 = m_k`, `b1 = 3σ_k − m_k − m_{k+1}`, `b2 = m_{k+1}`; by the convex-hull property
//! `|b_i| ≤ v` gives `|q'| ≤ v` on the whole span, hence on every sample whatever the step.
//! `q''` is linear on a span (its ends bind) and `q'''` constant.
//!
//! ```text
//! minimise    t + μ Σ_i (w_i² + ε)·δ_i²            w_i = |sin P_i|, μ = direct_quad_weight/m
//! subject to  Hermite continuity and end rows        (equalities, above)
//!             −t ≤ w_i·δ_i ≤ t                       (t ≥ largest approximate deviation)
//!             t ≤ d                                  (only with opts.max_deviation_deg = Some(d))
//!             |m_k| ≤ v,  |q''(s_k)| ≤ a             every knot k of the constrained range
//!             |b1(span)| ≤ v,  |q'''(span)| ≤ j      every span of the constrained range
//!             σ·m_k ≥ 0, σ·b1 ≥ 0                    knots/spans in [s(first), s(last)]
//!                                                    (only with monotone = Some(σ))
//! ```
//!
//! Before solving, a necessary condition skips a certainly infeasible QP: when the ends a, b
//! of the constrained range are fixed points, `|C_b − C_a| ≤ v·(s_b − s_a)`.
//!
//! The constrained range is the spans in `[s(first − 3), s(last + 3)]` (clipped to the
//! path, [`crate::tolerances::CONSTRAINED_MARGIN_POINTS`]). `(v, a, j)` are `lim` (V/F, A/F², J/F³, with the
//! caller's margin). Each inequality row is divided by its bound so all rows have unit
//! scale; each continuity row by `h_{k−1} + h_k`. Every row touches at most 5 variables, so
//! the KKT system clarabel factors is banded-sparse. The deviation of a point whose C
//! changes by δ with P unchanged is `2·asin(|sin P|·|sin(δ/2)|)`; the QP uses its
//! linearisation `|sin P|·|δ|`, which is never below the exact value for |δ| ≤ 180° up to
//! the second order in |sin P| (so `t ≤ d` is a slightly conservative form of the exact
//! limit for small P; the reported deviation always uses the exact formula). `ε`
//! ([`crate::SolverSettings::direct_pole_regularisation`]) keeps a point exactly at the pole (w = 0) from being
//! free. The small quadratic (weight μ, [`crate::SolverSettings::direct_quad_weight`]) pulls the points that do not bind the maximum back
//! towards their original values.
//!
//! # The bound
//!
//! [`deviation_bound_sampled`] is the exact minimax of the *exact* deviation for C-only changes at
//! `first..=last` with the constraints checked on the samples (every `step_mm` on each span
//! and at every knot, a bounded number per span: [`crate::tolerances::BOUND_SAMPLES_PER_SPAN`]), no
//! monotonicity: since the deviation of point i is increasing in
//! |δ_i| on [0°, 180°], `max_i dev_i ≤ T` ⇔ `|δ_i| ≤ g_i(T) = 2·asin(sin(T/2)/w_i)` (no
//! bound when `sin(T/2) ≥ w_i`), an LP feasibility problem on the same Hermite rows;
//! bisection on T.

use crate::{
    candidate::{Candidate, PatchFailure},
    hermite::{Hermite, push_abs, push_sign},
    limits::CLimits,
    options::PatchOptions,
    report::{QpStats, QpStatus},
    spline::{AnalysisSpline, span_offsets},
    tolerances::{
        BOUND_BISECTIONS, BOUND_BRACKET_SLACK_DEG, BOUND_REL_TOL, HERMITE_WINDOW_POINTS,
        NOT_WORSE_SLACK,
    },
};

/// New C values for points `first..=last` (others fixed) minimising the largest orientation
/// deviation such that the analysis spline of the whole path satisfies `lim` on every
/// sample, monotone with sign `monotone` (+1/−1) over `[s(first), s(last)]` when given.
///
/// The QP is written out in the module docs. `s_mm`, `p_deg` (primary, degrees) and
/// `c_deg` are per point of the whole path; the constraints cover the spans within
/// [`crate::tolerances::CONSTRAINED_MARGIN_POINTS`] of the range, so the caller verifies the result.
#[allow(clippy::too_many_arguments)]
pub fn direct_patch(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    lim: &CLimits,
    monotone: Option<f64>,
    opts: &PatchOptions,
) -> Result<Candidate, PatchFailure> {
    let hm = Hermite::new(s_mm, c_deg, first, last, HERMITE_WINDOW_POINTS)?;
    let spans = hm.constrained_spans();
    if !within_reach(s_mm, c_deg, first, last, &spans, lim.v) {
        // Net change beyond v·length.
        return Err(PatchFailure::Solver(QpStats {
            status: QpStatus::SkippedInfeasible,
            ..QpStats::default()
        }));
    }
    let nd = hm.nd;
    let t = hm.vars(); // index of the epigraph variable
    let mut qp = hm.builder(1);
    for k in spans.clone() {
        let h = hm.h(k);
        push_abs(&mut qp, &hm.m(k), lim.v);
        push_abs(&mut qp, &hm.d2(k, 0.0), lim.a);
        let b1 = hm.b1(k);
        push_abs(&mut qp, &b1, lim.v);
        push_abs(&mut qp, &hm.d3(k), lim.j);
        let end = k + 1 == spans.end;
        if end {
            push_abs(&mut qp, &hm.m(k + 1), lim.v);
            push_abs(&mut qp, &hm.d2(k, h), lim.a);
        }
        if let Some(sigma) = monotone {
            if (first..=last).contains(&k) {
                push_sign(&mut qp, &hm.m(k), sigma);
            }
            if k >= first && k < last {
                push_sign(&mut qp, &b1, sigma);
            }
            if end && (first..=last).contains(&(k + 1)) {
                push_sign(&mut qp, &hm.m(k + 1), sigma);
            }
        }
    }
    let st = &opts.solver;
    let mu = st.direct_quad_weight / nd as f64;
    for i in 0..nd {
        let w = p_deg[first + i].to_radians().sin().abs();
        qp.add_le(&[(i, w), (t, -1.0)], 0.0);
        qp.add_le(&[(i, -w), (t, -1.0)], 0.0);
        qp.add_square(
            &[(i, 1.0)],
            mu * (w * w + st.direct_pole_regularisation),
            0.0,
        );
    }
    if let Some(d) = opts.max_deviation_deg {
        qp.add_le(&[(t, 1.0)], d);
    }
    qp.add_linear(t, 1.0);
    let mut stats = QpStats::default();
    match qp.solve(&mut stats) {
        Ok(x) => Ok(Candidate {
            first,
            last,
            c_deg: (0..nd).map(|i| c_deg[first + i] + x[i]).collect(),
            c_offset_deg: 0.0,
            qp: stats,
        }),
        Err(_) => Err(PatchFailure::Solver(stats)),
    }
}

/// Necessary condition for the direct QP: when both ends `a`, `b` of the constrained spans
/// are fixed points (outside `first..=last`), `|q'| ≤ v` on `[s_a, s_b]` needs
/// `|C_b − C_a| ≤ v·(s_b − s_a)`. `false` only when the QP is certainly infeasible, so
/// the solve can be skipped.
fn within_reach(
    s: &[f64],
    c: &[f64],
    first: usize,
    last: usize,
    spans: &std::ops::Range<usize>,
    v: f64,
) -> bool {
    let (a, b) = (spans.start, spans.end);
    if a >= first || b <= last {
        return true;
    }
    (c[b] - c[a]).abs() <= v * (s[b] - s[a])
}

/// Exact orientation deviation, degrees, of a point at primary `p_deg` whose C changes by
/// `dc_deg` (P unchanged): `2·asin(|sin P|·|sin(ΔC/2)|)`.
pub fn orientation_deviation_deg(p_deg: f64, dc_deg: f64) -> f64 {
    let x = p_deg.to_radians().sin().abs() * (dc_deg.to_radians() / 2.0).sin().abs();
    2.0 * x.min(1.0).asin().to_degrees()
}

/// The smallest possible largest orientation deviation (degrees) over C-only changes at
/// points `first..=last` such that the analysis spline satisfies `lim` (no monotonicity
/// asked), with the constraints on `samples_per_span + 1` equally spaced
/// samples of each span of the constrained range (spans within
/// [`crate::tolerances::CONSTRAINED_MARGIN_POINTS`] of the range), knots included: a relaxation of what the
/// verification checks (every s), hence a lower bound. Bisection (at most [`BOUND_BISECTIONS`] steps, to
/// [`BOUND_REL_TOL`]) on the exact deviation, an LP feasibility problem per step (module
/// docs); returns the smallest feasible T found.
pub fn deviation_bound_sampled(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    lim: &CLimits,
    samples_per_span: usize,
) -> Result<(f64, QpStats), PatchFailure> {
    deviation_bound_in(s_mm, p_deg, c_deg, first, last, None, lim, samples_per_span)
}

/// The bound of one zone, as the patcher is held to it: [`deviation_bound_sampled`] with
/// the limits `lim` strict only on the samples within `s_mm[zone.0] ..= s_mm[zone.1]`
/// (the zone must reach feed there); on every other constrained sample each derivative
/// may keep the size it had before (`|q⁽ᵏ⁾| ≤ max(limit, |q⁽ᵏ⁾_before|)`: nowhere worse),
/// which is still a linear constraint. Points `first..=last` are movable.
#[allow(clippy::too_many_arguments)]
pub fn deviation_bound_zone(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    zone: (usize, usize),
    lim: &CLimits,
    samples_per_span: usize,
) -> Result<(f64, QpStats), PatchFailure> {
    if zone.0 > zone.1 || zone.1 >= s_mm.len() {
        return Err(PatchFailure::TooShort);
    }
    deviation_bound_in(
        s_mm,
        p_deg,
        c_deg,
        first,
        last,
        Some(zone),
        lim,
        samples_per_span,
    )
}

#[allow(clippy::too_many_arguments)]
fn deviation_bound_in(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    zone: Option<(usize, usize)>,
    lim: &CLimits,
    samples_per_span: usize,
) -> Result<(f64, QpStats), PatchFailure> {
    let hm = Hermite::new(s_mm, c_deg, first, last, HERMITE_WINDOW_POINTS)?;
    let nd = hm.nd;
    let mut base = hm.builder(0);
    let spans = hm.constrained_spans();
    // The analysis spline before any change, for "not worse" outside the zone.
    let before = match zone {
        Some(_) => Some(AnalysisSpline::new(s_mm, c_deg).map_err(|_| PatchFailure::TooShort)?),
        None => None,
    };
    let relaxed = |t: f64, d: usize, limit: f64| -> f64 {
        match (zone, &before) {
            (Some((a, b)), Some(pp)) if t < s_mm[a] || t > s_mm[b] => {
                limit.max(pp.eval_derivs(t)[d].abs() * (1.0 + NOT_WORSE_SLACK))
            }
            _ => limit,
        }
    };
    let mut ts = Vec::new();
    for k in spans.clone() {
        span_offsets(hm.h(k), samples_per_span, &mut ts);
        for &tau in &ts {
            let t = s_mm[k] + tau;
            push_abs(&mut base, &hm.d1(k, tau), relaxed(t, 1, lim.v));
            push_abs(&mut base, &hm.d2(k, tau), relaxed(t, 2, lim.a));
        }
        // The third derivative is constant on the span: take it at the span's middle.
        let mid = 0.5 * (s_mm[k] + s_mm[k + 1]);
        push_abs(&mut base, &hm.d3(k), relaxed(mid, 3, lim.j));
    }
    let w: Vec<f64> = (first..=last)
        .map(|i| p_deg[i].to_radians().sin().abs())
        .collect();
    let mut stats = QpStats::default();
    let mut feasible = |tdeg: f64| -> bool {
        let mut qp = base.clone();
        let st = (tdeg.to_radians() / 2.0).sin();
        for (i, wi) in w.iter().enumerate() {
            if st < *wi {
                let g = 2.0 * (st / wi).asin().to_degrees();
                qp.add_le(&[(i, 1.0)], g);
                qp.add_le(&[(i, -1.0)], g);
            }
        }
        qp.solve(&mut stats).is_ok()
    };
    debug_assert_eq!(w.len(), nd);
    let wmax = w.iter().fold(0.0f64, |m, v| m.max(*v));
    let mut hi = 2.0 * wmax.min(1.0).asin().to_degrees() + BOUND_BRACKET_SLACK_DEG;
    if !feasible(hi) {
        return Err(PatchFailure::Solver(stats));
    }
    if feasible(0.0) {
        return Ok((0.0, stats));
    }
    let mut lo = 0.0;
    for _ in 0..BOUND_BISECTIONS {
        if hi - lo <= BOUND_REL_TOL * hi {
            break;
        }
        let mid = 0.5 * (lo + hi);
        if feasible(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Ok((hi, stats))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::verify::{AxisChange, verify_change};
    use polepatch_kinematics::{Axis, Machine};

    /// A planted C swing: tool axis passing at angular distance `d_deg` from the pole on
    /// a straight line s = X, continuous branch (P keeps its sign).
    pub(crate) fn swing(n: usize, spacing: f64, d_deg: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let s: Vec<f64> = (0..n).map(|i| i as f64 * spacing).collect();
        let mid = s[n - 1] / 2.0;
        let mut p = Vec::new();
        let mut c = Vec::new();
        for &si in &s {
            // Tool axis: tilt (rad) along x by the distance to the middle, offset d in y.
            let ax = ((si - mid) * 0.4).to_radians(); // 0.4° per mm
            let ay = d_deg.to_radians();
            let v = [ax.sin(), ay.sin(), 1.0];
            let nrm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let (i, j, k) = (v[0] / nrm, v[1] / nrm, v[2] / nrm);
            // i = sin C sin A, j = −cos C sin A, k = cos A, A ≥ 0.
            let a = k.clamp(-1.0, 1.0).acos();
            let cc = i.atan2(-j);
            p.push(a.to_degrees());
            c.push(cc.to_degrees());
        }
        // Unwrap C.
        for i in 1..n {
            while c[i] - c[i - 1] > 180.0 {
                c[i] -= 360.0;
            }
            while c[i] - c[i - 1] < -180.0 {
                c[i] += 360.0;
            }
        }
        (s, p, c)
    }

    fn ucp_limits(feed: f64, margin: f64) -> CLimits {
        // UCP710 C: 20 rpm, 0.83 rev/s², 50 rev/s³ (SPEC §1).
        let f = feed / 60.0;
        let k = 1.0 - margin;
        CLimits {
            v: k * 120.0 / f,
            a: k * 0.83 * 360.0 / (f * f),
            j: k * 50.0 * 360.0 / (f * f * f),
        }
    }

    /// Planted: C must turn 90° between the fixed points 6 mm apart at |C_s| ≤ 3°/mm: no
    /// solve, a reported failure; at 20°/mm the test lets it through.
    #[test]
    fn net_change_beyond_reach_skips_the_solve() {
        let s: Vec<f64> = (0..41).map(|i| i as f64 * 0.5).collect();
        let c: Vec<f64> = s
            .iter()
            .map(|&x| if x < 10.0 { 0.0 } else { 90.0 })
            .collect();
        let p = vec![1.0; s.len()];
        let lim = |v: f64| CLimits { v, a: 1e3, j: 1e5 };
        let r = direct_patch(
            &s,
            &p,
            &c,
            17,
            23,
            &lim(3.0),
            None,
            &PatchOptions::default(),
        );
        match r {
            Err(PatchFailure::Solver(st)) => assert_eq!(st.solves, 0, "{st:?}"),
            other => panic!("expected a skipped solve, got {other:?}"),
        }
        let spans = 14..26;
        assert!(within_reach(&s, &c, 17, 23, &spans, 20.0));
        assert!(!within_reach(&s, &c, 17, 23, &spans, 3.0));
    }

    #[test]
    fn deviation_formula() {
        assert_eq!(orientation_deviation_deg(0.0, 120.0), 0.0);
        assert!((orientation_deviation_deg(90.0, 30.0) - 30.0).abs() < 1e-12);
        assert!((orientation_deviation_deg(2.0, 180.0) - 4.0).abs() < 1e-9);
    }

    #[test]
    fn direct_reaches_feed_on_a_swing() {
        let (s, p, c) = swing(101, 1.0, 0.5);
        let lim = ucp_limits(1000.0, 0.02);
        let lim0 = ucp_limits(1000.0, 0.0);
        let (first, last) = (20, 80);
        let cand = direct_patch(
            &s,
            &p,
            &c,
            first,
            last,
            &lim,
            Some((c[last] - c[first]).signum()),
            &PatchOptions::default(),
        )
        .expect("solvable");
        let mut c2 = c.clone();
        c2[first..=last].copy_from_slice(&cand.c_deg);
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let ch = [AxisChange {
            axis: Axis::C,
            before: &c,
            after: &c2,
        }];
        let v = verify_change(&s, &ch, first, last, 3, &m, 1000.0 / 60.0);
        assert!(
            v.core_min_before < 0.5,
            "planted case must be below feed: {v:?}"
        );
        assert!(v.passes(), "{v:?}");
        let dev = (first..=last)
            .map(|i| orientation_deviation_deg(p[i], c2[i] - c[i]))
            .fold(0.0, f64::max);
        let (bound, _) = deviation_bound_sampled(
            &s,
            &p,
            &c,
            first,
            last,
            &lim0,
            crate::tolerances::BOUND_SAMPLES_PER_SPAN,
        )
        .unwrap();
        assert!(bound <= dev + 1e-6, "bound {bound} vs achieved {dev}");
        assert!(
            dev <= 1.25 * bound + 1e-3,
            "achieved {dev} vs bound {bound}"
        );
    }
}
