//! The direct formulation: a QP on the CL C values through the analysis spline, and the
//! lower bound on the orientation deviation (SPEC §6, bench).
//!
//! # The direct QP
//!
//! The analysis spline of C (SPEC §2: the not-a-knot cubic interpolant of C over s) is
//! linear in the C values, so are its derivatives. Write the new values at the points
//! `i = first..=last` as `x_i = C_i + δ_i` (every other point fixed). For every functional
//! `L` used below (a slope at a knot, a second derivative at a span end, a third derivative
//! on a span, a Bernstein coefficient), `L(x) = L(C) + Σ_i L(e_i)·δ_i`, where `L(e_i)` is
//! the response of the spline to the unit vector at point i. Responses are computed on a
//! window of [`WINDOW_POINTS`] points either side of the range (the response decays by
//! ≈ 0.27 per knot; the caller verifies on the whole path anyway).
//!
//! On a span `[u, w]`, `h = w − u`, the spline's `q'''` is a constant, `q''` is linear, `q'`
//! is a quadratic with Bernstein coefficients
//! `b0 = q'(u)`, `b1 = q'(u) + q''(u)·h/2 = 3σ − q'(u) − q'(w)` (σ the secant slope),
//! `b2 = q'(w)`; by the convex-hull property `|b_k| ≤ v` gives `|q'| ≤ v` on the whole span,
//! hence on every sample whatever the step F·Tcy.
//!
//! Variables `δ ∈ ℝ^m` (m = last − first + 1) and `t ∈ ℝ`:
//!
//! ```text
//! minimise    t + μ Σ_i (w_i² + ε)·δ_i²            w_i = |sin P_i|, μ = DEVIATION_QUAD_WEIGHT/m
//! subject to  −t ≤ w_i·δ_i ≤ t                       (t ≥ largest approximate deviation)
//!             t ≤ d                                  (only with opts.max_deviation_deg = Some(d))
//!             |q'(s_k)|  ≤ v,  |q''(s_k)| ≤ a        every knot k of the constrained range
//!             |b1(span)| ≤ v,  |q'''(span)| ≤ j      every span of the constrained range
//!             σ·q'(s_k) ≥ 0, σ·b1 ≥ 0                knots/spans in [s(first), s(last)]
//!                                                    (only with monotone = Some(σ))
//! ```
//!
//! The constrained range is the spans in `[s(first − 3), s(last + 3)]` (clipped to the
//! path). `(v, a, j)` are `lim` (V/F, A/F², J/F³, with the caller's margin). Each
//! inequality row is divided by its bound so all rows have unit scale. The deviation of a
//! point whose C changes by δ with P unchanged is `2·asin(|sin P|·|sin(δ/2)|)`; the QP uses
//! its linearisation `|sin P|·|δ|`, which is never below the exact value for |δ| ≤ 180°
//! up to the second order in |sin P| (so `t ≤ d` is a slightly conservative form of the
//! exact limit for small P; the reported deviation always uses the exact formula).
//! `ε` ([`PURE_POLE_REGULARISATION`]) keeps a point exactly at the pole (w = 0) from being
//! free. The small quadratic (weight μ) pulls the points that do not bind the maximum back
//! towards their original values.
//!
//! # The bound
//!
//! [`deviation_bound`] is the exact minimax of the *exact* deviation for C-only changes at
//! `first..=last` with the constraints checked on the samples (every `step_mm` on each span
//! and at every knot), no monotonicity: since the deviation of point i is increasing in
//! |δ_i| on [0°, 180°], `max_i dev_i ≤ T` ⇔ `|δ_i| ≤ g_i(T) = 2·asin(sin(T/2)/w_i)` (no
//! bound when `sin(T/2) ≥ w_i`), an LP feasibility problem; bisection on T.

use crate::{
    candidate::{Candidate, PatchFailure},
    limits::CLimits,
    options::PatchOptions,
    qp::{LeqRows, add_stats, solve_diag_qp},
    report::QpStats,
    verify::{NakSystem, span_coeffs, span_offsets},
};

/// Points of the path kept either side of the modified range to build the spline
/// responses.
pub const WINDOW_POINTS: usize = 24;

/// Points either side of the modified range whose spans are constrained.
pub const CONSTRAINED_MARGIN_POINTS: usize = 3;

/// Weight of the quadratic pull-back term, per degree, divided by the number of variables
/// (small, so the minimax term dominates).
pub const DEVIATION_QUAD_WEIGHT: f64 = 1e-4;

/// Added to `sin² P` in the quadratic term so a point exactly at the pole stays determined.
pub const PURE_POLE_REGULARISATION: f64 = 1e-6;

/// Response coefficients smaller than this fraction of their row's largest are dropped.
const DROP_REL: f64 = 1e-12;

/// Sampling step of [`deviation_bound`], mm: finer than F·Tcy at the feeds of interest
/// (F·Tcy = 0.033 mm at F2000 and Tcy 1 ms); use [`deviation_bound_sampled`] to give the
/// analysis step.
pub const BOUND_STEP_MM: f64 = 0.02;

/// Bisection steps of [`deviation_bound`].
pub const BOUND_BISECTIONS: usize = 25;

/// The spline functionals of a window as linear maps of the modified values.
struct Responses {
    /// First path index of the window.
    lo: usize,
    /// Knots of the window.
    s: Vec<f64>,
    /// Base values and slopes (original C).
    y0: Vec<f64>,
    m0: Vec<f64>,
    /// Slopes of the response to each unit vector, per variable.
    m_unit: Vec<Vec<f64>>,
    /// Local index of variable 0.
    var0: usize,
}

/// One span's `(q'(u), c2, c3)` as affine functions: base value and per-variable
/// coefficients.
struct SpanMaps {
    h: f64,
    m0: (f64, Vec<f64>),
    m1: (f64, Vec<f64>),
    c2: (f64, Vec<f64>),
    c3: (f64, Vec<f64>),
}

impl Responses {
    fn new(s_mm: &[f64], c_deg: &[f64], first: usize, last: usize) -> Responses {
        let n = s_mm.len();
        let lo = first.saturating_sub(WINDOW_POINTS);
        let hi = (last + WINDOW_POINTS).min(n - 1);
        let sys = NakSystem::new(&s_mm[lo..=hi]);
        let y0 = c_deg[lo..=hi].to_vec();
        let m0 = sys.slopes(&y0);
        let nw = sys.len();
        let mut e = vec![0.0; nw];
        let m_unit = (first..=last)
            .map(|i| {
                e[i - lo] = 1.0;
                let m = sys.slopes(&e);
                e[i - lo] = 0.0;
                m
            })
            .collect();
        Responses {
            lo,
            s: sys.knots().to_vec(),
            y0,
            m0,
            m_unit,
            var0: first - lo,
        }
    }

    fn vars(&self) -> usize {
        self.m_unit.len()
    }

    /// Maps of local span k.
    fn span(&self, k: usize) -> SpanMaps {
        let (bm0, bc2, bc3, h) = span_coeffs(&self.s, &self.y0, &self.m0, k);
        let nv = self.vars();
        let mut m0 = vec![0.0; nv];
        let mut m1 = vec![0.0; nv];
        let mut c2 = vec![0.0; nv];
        let mut c3 = vec![0.0; nv];
        for i in 0..nv {
            let mu = &self.m_unit[i];
            let li = self.var0 + i;
            let yk = if li == k { 1.0 } else { 0.0 };
            let yk1 = if li == k + 1 { 1.0 } else { 0.0 };
            let sl = (yk1 - yk) / h;
            m0[i] = mu[k];
            m1[i] = mu[k + 1];
            c2[i] = (3.0 * sl - 2.0 * mu[k] - mu[k + 1]) / h;
            c3[i] = (mu[k] + mu[k + 1] - 2.0 * sl) / (h * h);
        }
        SpanMaps {
            h,
            m0: (bm0, m0),
            m1: (self.m0[k + 1], m1),
            c2: (bc2, c2),
            c3: (bc3, c3),
        }
    }

    /// Local spans constrained for the modified range `first..=last` (path indices).
    fn constrained_spans(&self, first: usize, last: usize) -> std::ops::Range<usize> {
        let n_local = self.s.len();
        let a = first.saturating_sub(CONSTRAINED_MARGIN_POINTS).max(self.lo) - self.lo;
        let b = (last + CONSTRAINED_MARGIN_POINTS).min(self.lo + n_local - 1) - self.lo;
        a..b.max(a + 1).min(n_local - 1)
    }
}

/// Linear combination `Σ coef_j·map_j` of affine maps.
fn combine(parts: &[(f64, &(f64, Vec<f64>))]) -> (f64, Vec<f64>) {
    let nv = parts[0].1.1.len();
    let mut base = 0.0;
    let mut lin = vec![0.0; nv];
    for (c, (b, l)) in parts {
        base += c * b;
        for (o, v) in lin.iter_mut().zip(l) {
            *o += c * v;
        }
    }
    (base, lin)
}

/// Push `|base + lin·δ| ≤ bound` (two rows, scaled by 1/bound), or with `sign = Some(σ)`
/// only `σ·(base + lin·δ) ≥ 0`.
fn push_abs(rows: &mut LeqRows, f: &(f64, Vec<f64>), bound: f64) {
    let (base, lin) = f;
    let big = lin.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let keep = |v: f64| v.abs() > DROP_REL * big;
    for sgn in [1.0, -1.0] {
        rows.push(
            lin.iter()
                .enumerate()
                .filter(|(_, v)| keep(**v))
                .map(|(i, v)| (i, sgn * v / bound)),
            (bound - sgn * base) / bound,
        );
    }
}

fn push_sign(rows: &mut LeqRows, f: &(f64, Vec<f64>), sigma: f64) {
    let (base, lin) = f;
    let scale = lin
        .iter()
        .fold(base.abs(), |m, v| m.max(v.abs()))
        .max(1e-300);
    rows.push(
        lin.iter().enumerate().map(|(i, v)| (i, -sigma * v / scale)),
        sigma * base / scale,
    );
}

fn check_range(n: usize, first: usize, last: usize) -> Result<(), PatchFailure> {
    if n < 2 || first > last || last >= n {
        return Err(PatchFailure::TooShort);
    }
    Ok(())
}

/// New C values for points `first..=last` (others fixed) minimising the largest orientation
/// deviation such that the analysis spline of the whole path satisfies `lim` on every
/// sample, monotone with sign `monotone` (+1/−1) over `[s(first), s(last)]` when given.
///
/// The QP is written out in the module docs. `s_mm`, `p_deg` (primary, degrees) and
/// `c_deg` are per point of the whole path; the constraints cover the spans within
/// [`CONSTRAINED_MARGIN_POINTS`] of the range, so the caller verifies the result.
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
    check_range(s_mm.len(), first, last)?;
    let r = Responses::new(s_mm, c_deg, first, last);
    let nv = r.vars();
    let t = nv; // index of the epigraph variable
    let mut rows = LeqRows::default();
    let spans = r.constrained_spans(first, last);
    let (mon_lo, mon_hi) = (first - r.lo, last - r.lo);
    for k in spans.clone() {
        let sp = r.span(k);
        // Knot k: slope and second derivative.
        push_abs(&mut rows, &sp.m0, lim.v);
        let d2u = combine(&[(2.0, &sp.c2)]);
        push_abs(&mut rows, &d2u, lim.a);
        // Span: middle Bernstein coefficient of q' and third derivative.
        let b1 = combine(&[(1.0, &sp.m0), (sp.h, &sp.c2)]);
        push_abs(&mut rows, &b1, lim.v);
        push_abs(&mut rows, &combine(&[(6.0, &sp.c3)]), lim.j);
        if k + 1 == spans.end {
            push_abs(&mut rows, &sp.m1, lim.v);
            let d2w = combine(&[(2.0, &sp.c2), (6.0 * sp.h, &sp.c3)]);
            push_abs(&mut rows, &d2w, lim.a);
        }
        if let Some(sigma) = monotone {
            if k >= mon_lo && k <= mon_hi {
                push_sign(&mut rows, &sp.m0, sigma);
            }
            if k >= mon_lo && k < mon_hi {
                push_sign(&mut rows, &b1, sigma);
            }
            if k + 1 == spans.end && k < mon_hi && k + 1 >= mon_lo {
                push_sign(&mut rows, &sp.m1, sigma);
            }
        }
    }
    let w: Vec<f64> = (first..=last)
        .map(|i| p_deg[i].to_radians().sin().abs())
        .collect();
    for (i, wi) in w.iter().enumerate() {
        rows.push([(i, *wi), (t, -1.0)], 0.0);
        rows.push([(i, -*wi), (t, -1.0)], 0.0);
    }
    if let Some(d) = opts.max_deviation_deg {
        rows.push([(t, 1.0)], d);
    }
    let mu = DEVIATION_QUAD_WEIGHT / nv as f64;
    let mut p_diag: Vec<f64> = w
        .iter()
        .map(|wi| 2.0 * mu * (wi * wi + PURE_POLE_REGULARISATION))
        .collect();
    p_diag.push(0.0);
    let mut q = vec![0.0; nv + 1];
    q[t] = 1.0;
    let (x, stats) = solve_diag_qp(&p_diag, &q, &rows);
    match x {
        Some(x) => Ok(Candidate {
            first,
            last,
            c_deg: (0..nv).map(|i| c_deg[first + i] + x[i]).collect(),
            c_offset_deg: 0.0,
            qp: stats,
        }),
        None => Err(PatchFailure::Solver(stats)),
    }
}

/// Exact orientation deviation, degrees, of a point at primary `p_deg` whose C changes by
/// `dc_deg` (P unchanged): `2·asin(|sin P|·|sin(ΔC/2)|)`.
pub fn orientation_deviation_deg(p_deg: f64, dc_deg: f64) -> f64 {
    let x = p_deg.to_radians().sin().abs() * (dc_deg.to_radians() / 2.0).sin().abs();
    2.0 * x.min(1.0).asin().to_degrees()
}

/// The smallest possible largest orientation deviation (degrees) over C-only changes at
/// points `first..=last` such that the analysis spline satisfies `lim` (no monotonicity
/// asked): the bound the bench compares against. Samples every [`BOUND_STEP_MM`]; see
/// [`deviation_bound_sampled`].
pub fn deviation_bound(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    lim: &CLimits,
) -> Result<(f64, QpStats), PatchFailure> {
    deviation_bound_sampled(s_mm, p_deg, c_deg, first, last, lim, BOUND_STEP_MM)
}

/// [`deviation_bound`] with the constraints on the samples every `step_mm` (> 0) of each
/// span of the constrained range (spans within [`CONSTRAINED_MARGIN_POINTS`] of the range)
/// and at every knot: pass the analysis step F·Tcy to get the bound for what the
/// verification checks. Bisection ([`BOUND_BISECTIONS`] steps) on the exact deviation, an
/// LP feasibility problem per step (module docs); returns the smallest feasible T found.
pub fn deviation_bound_sampled(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    lim: &CLimits,
    step_mm: f64,
) -> Result<(f64, QpStats), PatchFailure> {
    check_range(s_mm.len(), first, last)?;
    if step_mm.is_nan() || step_mm <= 0.0 {
        return Err(PatchFailure::TooShort);
    }
    let r = Responses::new(s_mm, c_deg, first, last);
    let nv = r.vars();
    let spans = r.constrained_spans(first, last);
    let mut spline_rows = LeqRows::default();
    let mut ts = Vec::new();
    for k in spans.clone() {
        let sp = r.span(k);
        span_offsets(sp.h, step_mm, k + 1 == spans.end, &mut ts);
        for &tau in &ts {
            let d1 = combine(&[
                (1.0, &sp.m0),
                (2.0 * tau, &sp.c2),
                (3.0 * tau * tau, &sp.c3),
            ]);
            push_abs(&mut spline_rows, &d1, lim.v);
            let d2 = combine(&[(2.0, &sp.c2), (6.0 * tau, &sp.c3)]);
            push_abs(&mut spline_rows, &d2, lim.a);
        }
        push_abs(&mut spline_rows, &combine(&[(6.0, &sp.c3)]), lim.j);
    }
    let w: Vec<f64> = (first..=last)
        .map(|i| p_deg[i].to_radians().sin().abs())
        .collect();
    let mut stats = QpStats::default();
    let feasible = |tdeg: f64, stats: &mut QpStats| -> bool {
        let mut rows = spline_rows.clone();
        let st = (tdeg.to_radians() / 2.0).sin();
        for (i, wi) in w.iter().enumerate() {
            if st < *wi {
                let g = 2.0 * (st / wi).asin().to_degrees();
                rows.push([(i, 1.0)], g);
                rows.push([(i, -1.0)], g);
            }
        }
        let (x, st) = solve_diag_qp(&vec![0.0; nv], &vec![0.0; nv], &rows);
        add_stats(stats, &st);
        x.is_some()
    };
    let wmax = w.iter().fold(0.0f64, |m, v| m.max(*v));
    let mut hi = 2.0 * wmax.min(1.0).asin().to_degrees() + 1e-9;
    if !feasible(hi, &mut stats) {
        return Err(PatchFailure::Solver(stats));
    }
    if feasible(0.0, &mut stats) {
        return Ok((0.0, stats));
    }
    let mut lo = 0.0;
    for _ in 0..BOUND_BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if feasible(mid, &mut stats) {
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
    use crate::verify::verify_c_change;

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
        let v = verify_c_change(&s, &c, &c2, first, last, &lim0, 1000.0 / 60.0 * 1e-3);
        assert!(
            v.core_min_before < 0.5,
            "planted case must be below feed: {v:?}"
        );
        assert!(v.passes(), "{v:?}");
        let dev = (first..=last)
            .map(|i| orientation_deviation_deg(p[i], c2[i] - c[i]))
            .fold(0.0, f64::max);
        let (bound, _) =
            deviation_bound_sampled(&s, &p, &c, first, last, &lim0, 1000.0 / 60.0 * 1e-3).unwrap();
        assert!(bound <= dev + 1e-6, "bound {bound} vs achieved {dev}");
        assert!(
            dev <= 1.25 * bound + 1e-3,
            "achieved {dev} vs bound {bound}"
        );
    }
}
