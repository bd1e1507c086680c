//! The analysis spline (SPEC §2), in one place.
//!
//! For each axis of a run, the analysis spline is the not-a-knot interpolating cubic of the
//! axis values over the tool-tip path length s (knots at the CL points). Everything in the
//! patcher that evaluates it goes through here:
//! - [`SplineSystem`] factors the not-a-knot system once per knot vector (a run, or a
//!   window of it) and fits any number of axes on it ([`SplineSystem::fit`]; the splines
//!   share one copy of their breaks), or several at once with its factors freed before
//!   their pieces are made ([`SplineSystem::fit_axes`]: the least memory on a long run);
//! - [`AnalysisSpline`] evaluates a fitted axis (piecewise-polynomial form), and hands out
//!   one span at a time as a [`SpanCubic`];
//! - [`SpanCubic::peaks`] is the exact largest `|q'|`, `|q''|`, `|q'''|` over a span, which
//!   is all Equation 6 needs to bound it (its ratio is decreasing in each derivative's
//!   size); [`span_maxima`] does it for every span.
//!
//! # Exact per-span bounds instead of sampling at F·Tcy
//! On a span `[s_k, s_{k+1}]` of length h the spline is one cubic
//! `q(τ) = a0 + a1·τ + a2·τ² + a3·τ³`, `τ ∈ [0, h]`, so
//!
//! ```text
//! q'(τ)   = a1 + 2·a2·τ + 3·a3·τ²   a quadratic: max |q'| at τ = 0, τ = h or the vertex
//!                                    τ* = −a2/(3·a3) when it lies inside
//! q''(τ)  = 2·a2 + 6·a3·τ           linear: max |q''| at τ = 0 or τ = h
//! q'''    = 6·a3                    constant
//! ```
//!
//! These maxima are exact (to rounding), and the largest of a continuous function over the
//! span is at least its largest over **any** set of samples in the span — in particular
//! over SPEC §2's samples every F·Tcy and at every knot. Equation 6 evaluated at the peaks
//! therefore gives a ratio that is at most the sampled one: the check is at least as strict
//! as sampling at any Tcy, and costs one evaluation per span and axis whatever the feed and
//! the block length (a 46 m move at F0.0001 is one span: one evaluation, where sampling at
//! F·Tcy took 2.8·10¹⁰ samples). See `docs/method.md`.
//!
//! The solvers use the same spline in linear form (`crate::hermite`: the knot slopes tied
//! to the values by the same end conditions), tested against this module.

use crate::path::PathError;
use polepatch_bspline::{NotAKnotSystem, PpCubic};

/// `count + 1` equally spaced offsets `0, h/count, …, h` on a span of length `h` (both ends
/// included; `count ≥ 1`), into `out` (cleared first): where a solver places sampled rows
/// on a span (a bounded number per span, whatever the feed).
pub fn span_offsets(h: f64, count: usize, out: &mut Vec<f64>) {
    out.clear();
    let count = count.max(1);
    out.extend((0..=count).map(|i| h * i as f64 / count as f64));
}

/// Range `[min, max]` of `|p|` over `[lo, hi]` for the quadratic `p(τ) = c0 + c1·τ + c2·τ²`
/// (exact: the range of a continuous function on an interval is spanned by its values at
/// the ends and at an interior critical point; `|p|` has minimum 0 when that range holds
/// 0). NaN coefficients give NaN.
fn abs_range_quadratic(c: [f64; 3], lo: f64, hi: f64) -> (f64, f64) {
    let p = |t: f64| c[0] + t * (c[1] + t * c[2]);
    let (a, b) = (p(lo), p(hi));
    if [a, b, c[0], c[1], c[2]].iter().any(|x| !x.is_finite()) {
        return (f64::NAN, f64::NAN);
    }
    let (mut mn, mut mx) = (a.min(b), a.max(b));
    if c[2] != 0.0 {
        let v = -c[1] / (2.0 * c[2]);
        if v > lo && v < hi {
            let pv = p(v);
            mn = mn.min(pv);
            mx = mx.max(pv);
        }
    }
    let top = mx.abs().max(mn.abs());
    let bottom = if mn <= 0.0 && mx >= 0.0 {
        0.0
    } else {
        mn.abs().min(mx.abs())
    };
    (bottom, top)
}

/// One span of an analysis spline: its length `h` (mm) and the Taylor coefficients of its
/// cubic about the span's left knot, `q(τ) = a[0] + a[1]·τ + a[2]·τ² + a[3]·τ³`, τ ∈ [0, h]
/// (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpanCubic {
    /// Span length, mm.
    pub h: f64,
    /// Taylor coefficients about the left knot.
    pub a: [f64; 4],
}

impl SpanCubic {
    /// Coefficients of `q'(τ) = c0 + c1·τ + c2·τ²`.
    fn d1(&self) -> [f64; 3] {
        [self.a[1], 2.0 * self.a[2], 3.0 * self.a[3]]
    }

    /// `[q', q'', q''']` at `τ`.
    pub fn derivs(&self, tau: f64) -> [f64; 3] {
        let a = &self.a;
        [
            a[1] + tau * (2.0 * a[2] + tau * 3.0 * a[3]),
            2.0 * a[2] + 6.0 * a[3] * tau,
            6.0 * a[3],
        ]
    }

    /// The exact largest `|q'|`, `|q''|`, `|q'''|` over the span, and where the first two
    /// are reached (τ, mm from the left knot). Non-finite coefficients give NaN peaks (a
    /// bad spline cannot pass for a smooth one).
    pub fn peaks(&self) -> ([f64; 3], [f64; 2]) {
        if self.a.iter().any(|x| !x.is_finite()) || !self.h.is_finite() {
            return ([f64::NAN; 3], [0.0, 0.0]);
        }
        let c = self.d1();
        let h = self.h;
        let q1 = |t: f64| (c[0] + t * (c[1] + t * c[2])).abs();
        let (mut p1, mut at1) = (q1(0.0), 0.0);
        if q1(h) > p1 {
            (p1, at1) = (q1(h), h);
        }
        if c[2] != 0.0 {
            let v = -c[1] / (2.0 * c[2]);
            if v > 0.0 && v < h && q1(v) > p1 {
                (p1, at1) = (q1(v), v);
            }
        }
        let (d2a, d2b) = (2.0 * self.a[2], 2.0 * self.a[2] + 6.0 * self.a[3] * h);
        let (p2, at2) = if d2b.abs() > d2a.abs() {
            (d2b.abs(), h)
        } else {
            (d2a.abs(), 0.0)
        };
        ([p1, p2, (6.0 * self.a[3]).abs()], [at1, at2])
    }

    /// The exact smallest and largest `|q'|`, `|q''|`, `|q'''|` over `[lo, hi] ⊂ [0, h]`,
    /// as `(mins, maxs)`.
    pub fn abs_range(&self, lo: f64, hi: f64) -> ([f64; 3], [f64; 3]) {
        let (m1, x1) = abs_range_quadratic(self.d1(), lo, hi);
        let (m2, x2) = abs_range_quadratic([2.0 * self.a[2], 6.0 * self.a[3], 0.0], lo, hi);
        let j = (6.0 * self.a[3]).abs();
        ([m1, m2, j], [x1, x2, j])
    }
}

/// The not-a-knot system of one knot vector, factored once. The splines it fits hold one
/// copy of their break points between them (the first fit's): five axes of a long run
/// hold 8 bytes a point of breaks, not 40.
#[derive(Debug, Clone)]
pub struct SplineSystem {
    sys: NotAKnotSystem,
    breaks: std::sync::OnceLock<std::sync::Arc<[f64]>>,
}

impl SplineSystem {
    /// Factor the system of the knots `s_mm` (≥ 2, finite, strictly increasing).
    pub fn new(s_mm: &[f64]) -> Result<SplineSystem, PathError> {
        NotAKnotSystem::new(s_mm)
            .map(|sys| SplineSystem {
                sys,
                breaks: std::sync::OnceLock::new(),
            })
            .map_err(|e| PathError::Spline(e.to_string()))
    }

    /// The weights `w_i` with `q^(order)(t) = Σ_i w_i·y_i` for the analysis spline of any
    /// values `y` on these knots (order 0..=3).
    pub fn data_row(&self, t: f64, order: usize) -> Vec<f64> {
        self.sys.data_row(t, order)
    }

    /// [`SplineSystem::data_row`] where it is not negligible: the weights of points
    /// `start..start + out.len()` (`start` returned, `out` cleared first), the others
    /// below `polepatch_bspline::interp::DATA_ROW_TOL` of the largest and taken as zero
    /// ([`polepatch_bspline::NotAKnotSystem::data_row_local`]). O(1) in the knots.
    pub fn data_row_local(&self, t: f64, order: usize, out: &mut Vec<f64>) -> usize {
        self.sys.data_row_local(t, order, out)
    }

    /// The analysis spline of the values `y` (one per knot, finite).
    pub fn fit(&self, y: &[f64]) -> Result<AnalysisSpline, PathError> {
        let mut pp = self
            .sys
            .solve(y)
            .map_err(|e| PathError::Spline(e.to_string()))?
            .to_pp();
        pp.share_breaks(self.breaks.get_or_init(|| pp.shared_breaks()));
        Ok(AnalysisSpline { pp })
    }

    /// The analysis splines of `count` axes, `values(a)` the values of axis `a` (one per
    /// knot, finite), the system consumed: every axis solved first, the system's factors
    /// then freed, and only then each solution put in piecewise-polynomial form — the
    /// same splines as [`SplineSystem::fit`] on each, with at most one of the factors and
    /// the five splines' pieces held at a time (peak memory of a long run).
    pub fn fit_axes(
        self,
        count: usize,
        mut values: impl FnMut(usize) -> Vec<f64>,
    ) -> Result<Vec<AnalysisSpline>, PathError> {
        let solved = (0..count)
            .map(|a| self.sys.solve(&values(a)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| PathError::Spline(e.to_string()))?;
        drop(self.sys);
        let mut breaks = self.breaks.into_inner();
        Ok(solved
            .into_iter()
            .map(|b| {
                let mut pp = b.to_pp();
                drop(b);
                pp.share_breaks(breaks.get_or_insert_with(|| pp.shared_breaks()));
                AnalysisSpline { pp }
            })
            .collect())
    }
}

/// One axis' analysis spline, ready for evaluation.
#[derive(Debug, Clone)]
pub struct AnalysisSpline {
    pp: PpCubic,
}

impl AnalysisSpline {
    /// The analysis spline of `y` over `s_mm` (factors a system for this one fit; use
    /// [`SplineSystem`] to fit several axes on the same knots).
    pub fn new(s_mm: &[f64], y: &[f64]) -> Result<AnalysisSpline, PathError> {
        SplineSystem::new(s_mm)?.fit(y)
    }

    /// Value at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        self.pp.eval(t)
    }

    /// `[q, q', q'', q''']` at `t` (per mm).
    pub fn eval_derivs(&self, t: f64) -> [f64; 4] {
        self.pp.eval_derivs(t)
    }

    /// The polynomial piece used at `t`, looked for first at `hint` and its neighbours;
    /// splines fitted by one [`SplineSystem`] share their pieces.
    pub fn piece_near(&self, t: f64, hint: usize) -> usize {
        self.pp.piece_near(t, hint)
    }

    /// [`AnalysisSpline::eval_derivs`] on piece `j` (from [`AnalysisSpline::piece_near`]
    /// of a spline of the same system).
    pub fn eval_derivs_on(&self, j: usize, t: f64) -> [f64; 4] {
        self.pp.eval_derivs_on(j, t)
    }

    /// [`AnalysisSpline::eval_derivs`] at sorted parameters `ts`, into `out` (same length).
    pub fn eval_derivs_sorted(&self, ts: &[f64], out: &mut [[f64; 4]]) {
        self.pp.eval_derivs_sorted(ts, out);
    }

    /// The span `[s0, s0 + h]` (between two consecutive knots) as a [`SpanCubic`].
    pub fn span(&self, s0: f64, h: f64) -> SpanCubic {
        let d = self.pp.eval_derivs(s0);
        SpanCubic {
            h,
            a: [d[0], d[1], 0.5 * d[2], d[3] / 6.0],
        }
    }
}

/// For every span `k` of `s_mm` (`[s_k, s_{k+1}]`), the exact largest `|q'|`, `|q''|`,
/// `|q'''|` of `spline` over the span ([`SpanCubic::peaks`]).
pub fn span_maxima(s_mm: &[f64], spline: &AnalysisSpline) -> Vec<[f64; 3]> {
    s_mm.windows(2)
        .map(|w| spline.span(w[0], w[1] - w[0]).peaks().0)
        .collect()
}

/// The largest change of `|q'|`, `|q''|`, `|q'''|` on the spans `spans` of the knots `s_mm`
/// that a perturbation of at most 1 in every value can cause: for each derivative, the
/// largest ℓ1 norm of its data row ([`SplineSystem::data_row`]) at the span's ends and
/// middle. Rounding every value to `d` decimals perturbs each by at most `0.5·10^−d`, so
/// it moves each derivative by at most that times this gain: what a solver must leave as
/// margin for the written values to keep its bounds (SPEC §4).
pub fn rounding_gain(s_mm: &[f64], spans: std::ops::Range<usize>) -> Result<[f64; 3], PathError> {
    let sys = SplineSystem::new(s_mm)?;
    let mut g = [0.0f64; 3];
    let l1 = |t: f64, order: usize| sys.data_row(t, order).iter().map(|w| w.abs()).sum::<f64>();
    for k in spans {
        let (a, b) = (s_mm[k], s_mm[k + 1]);
        let mid = 0.5 * (a + b);
        g[0] = g[0].max(l1(a, 1)).max(l1(mid, 1)).max(l1(b, 1));
        g[1] = g[1].max(l1(a, 2)).max(l1(b, 2));
        g[2] = g[2].max(l1(mid, 3));
    }
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The solver's sample offsets: `count + 1` points, both ends, equally spaced.
    #[test]
    fn offsets_cover_the_span() {
        let mut o = Vec::new();
        span_offsets(1.0, 4, &mut o);
        assert_eq!(o, vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        span_offsets(0.1, 0, &mut o);
        assert_eq!(o, vec![0.0, 0.1]);
    }

    /// A cubic is reproduced by its not-a-knot interpolant, so the peaks are the cubic's:
    /// q = s³ on [0, 4]: q' = 3s², q'' = 6s, q''' = 6, largest at each span's right end,
    /// exactly (no sampling).
    #[test]
    fn peaks_of_a_planted_cubic() {
        let s: Vec<f64> = (0..5).map(|i| i as f64).collect();
        let y: Vec<f64> = s.iter().map(|x| x * x * x).collect();
        let sp = AnalysisSpline::new(&s, &y).unwrap();
        let pk = span_maxima(&s, &sp);
        assert_eq!(pk.len(), 4);
        for (k, p) in pk.iter().enumerate() {
            let r = k as f64 + 1.0;
            assert!((p[0] - 3.0 * r * r).abs() < 1e-9, "{k}: {p:?}");
            assert!((p[1] - 6.0 * r).abs() < 1e-9, "{k}: {p:?}");
            assert!((p[2] - 6.0).abs() < 1e-9, "{k}: {p:?}");
        }
    }

    /// splitmix64, for the seeded sweeps below.
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// The exact peaks and ranges against dense sampling, on random cubics (vertex inside
    /// or outside, sign changes, degenerate a3 = 0 and a2 = a3 = 0): every sample lies in
    /// the range, and the range's ends are reached by some sample to within the sampling's
    /// resolution. The peak is where it says it is.
    #[test]
    fn exact_peaks_and_ranges_bound_dense_samples() {
        let mut r = rng(7);
        for case in 0..500 {
            let mut a = [r() * 10.0, r() * 10.0, r() * 10.0, r() * 10.0];
            if case % 7 == 0 {
                a[3] = 0.0;
            }
            if case % 11 == 0 {
                a[2] = 0.0;
                a[3] = 0.0;
            }
            let h = 0.1 + 2.0 * (r() + 1.0);
            let sc = SpanCubic { h, a };
            let (pk, at) = sc.peaks();
            let (lo, hi) = (h * 0.25 * (r() + 1.0), h * (0.5 + 0.25 * (r() + 1.0)));
            let (mins, maxs) = sc.abs_range(lo, hi);
            let mut dense_max = [0.0f64; 3];
            let (mut in_min, mut in_max) = ([f64::INFINITY; 3], [0.0f64; 3]);
            for i in 0..=20_000 {
                let t = h * f64::from(i) / 20_000.0;
                let d = sc.derivs(t);
                for m in 0..3 {
                    dense_max[m] = dense_max[m].max(d[m].abs());
                    assert!(d[m].abs() <= pk[m] * (1.0 + 1e-12) + 1e-12, "{case}: {m}");
                }
                if t >= lo && t <= hi {
                    for m in 0..3 {
                        in_min[m] = in_min[m].min(d[m].abs());
                        in_max[m] = in_max[m].max(d[m].abs());
                        assert!(d[m].abs() >= mins[m] - 1e-9 && d[m].abs() <= maxs[m] + 1e-9);
                    }
                }
            }
            for m in 0..3 {
                let tol = 1e-3 * (1.0 + pk[m]);
                assert!(
                    pk[m] - dense_max[m] < tol,
                    "{case}: {m} {pk:?} {dense_max:?}"
                );
                assert!(
                    in_min[m] - mins[m] < tol && maxs[m] - in_max[m] < tol,
                    "{case}: {m}"
                );
            }
            assert!((sc.derivs(at[0])[0].abs() - pk[0]).abs() < 1e-9);
            assert!((sc.derivs(at[1])[1].abs() - pk[1]).abs() < 1e-9);
        }
        // NaN never passes for a smooth span.
        let bad = SpanCubic {
            h: 1.0,
            a: [0.0, f64::NAN, 0.0, 0.0],
        };
        assert!(bad.peaks().0.iter().all(|v| v.is_nan()));
        assert!(bad.abs_range(0.0, 1.0).1[0].is_nan());
    }

    /// At least as strict as SPEC §2's sampling: on an interpolant of random data, the exact
    /// span maxima are ≥ the largest derivative over the samples every F·Tcy and at every
    /// knot, for several steps — and the vertex of q' between samples is found.
    #[test]
    fn exact_maxima_are_at_least_the_sampled_ones() {
        let mut r = rng(11);
        let s: Vec<f64> = (0..40)
            .scan(0.0, |acc, _| {
                *acc += 0.2 + r().abs();
                Some(*acc)
            })
            .collect();
        let y: Vec<f64> = s.iter().map(|_| 20.0 * r()).collect();
        let sp = AnalysisSpline::new(&s, &y).unwrap();
        let exact = span_maxima(&s, &sp);
        let mut strictly_above = 0;
        for step in [0.5, 0.1, 1.0 / 60.0] {
            for k in 0..s.len() - 1 {
                let (a, b) = (s[k], s[k + 1]);
                let mut t = a;
                let mut sampled = [0.0f64; 3];
                while t <= b {
                    let d = sp.eval_derivs(t.min(b - 1e-12));
                    for m in 0..3 {
                        sampled[m] = sampled[m].max(d[m + 1].abs());
                    }
                    t += step;
                }
                for m in 0..3 {
                    assert!(
                        exact[k][m] >= sampled[m] * (1.0 - 1e-12),
                        "span {k} order {m}"
                    );
                    if exact[k][m] > sampled[m] * (1.0 + 1e-6) {
                        strictly_above += 1;
                    }
                }
            }
        }
        assert!(strictly_above > 0, "coarse sampling misses some peaks");
    }

    /// The rounding gain bounds what an actual worst-case perturbation does, and is reached
    /// by the perturbation with the signs of the data row (planted).
    #[test]
    fn rounding_gain_is_the_worst_case() {
        let s: Vec<f64> = (0..30).map(|i| i as f64 * 0.5).collect();
        let g = rounding_gain(&s, 10..20).unwrap();
        let sys = SplineSystem::new(&s).unwrap();
        // The third derivative at the middle of span 15, perturbed by the row's signs.
        let t = 0.5 * (s[15] + s[16]);
        let w = sys.data_row(t, 3);
        let y: Vec<f64> = w.iter().map(|v| v.signum()).collect();
        let q3 = sys.fit(&y).unwrap().eval_derivs(t)[3];
        assert!((q3 - w.iter().map(|v| v.abs()).sum::<f64>()).abs() < 1e-9);
        assert!(q3 <= g[2] + 1e-9);
        // Uniform spacing h: the third-derivative gain scales as 1/h³.
        assert!(g[2] > 10.0 / 0.125 && g[2] < 100.0 / 0.125, "{g:?}");
    }

    /// The splines one system fits hold one copy of the break points between them, and
    /// evaluate as splines with their own copy do, bit for bit.
    #[test]
    fn splines_of_one_system_share_one_copy_of_their_breaks() {
        let s: Vec<f64> = (0..40)
            .map(|i| i as f64 * 0.3 + (i % 3) as f64 * 0.05)
            .collect();
        let sys = SplineSystem::new(&s).unwrap();
        let ys: Vec<Vec<f64>> = (0..5)
            .map(|a| s.iter().map(|t| (t * (a + 1) as f64).sin()).collect())
            .collect();
        let fitted: Vec<AnalysisSpline> = ys.iter().map(|y| sys.fit(y).unwrap()).collect();
        let first = fitted[0].pp.shared_breaks();
        for (a, y) in fitted.iter().zip(&ys) {
            assert!(std::sync::Arc::ptr_eq(&a.pp.shared_breaks(), &first));
            let alone = AnalysisSpline::new(&s, y).unwrap();
            assert_eq!(a.pp, alone.pp);
            for k in 0..400 {
                let t = k as f64 * 0.03 - 0.1;
                assert_eq!(a.eval_derivs(t), alone.eval_derivs(t));
            }
        }
    }

    /// The axes fitted together by a consumed system are the splines of each fitted
    /// alone, sharing one copy of their breaks.
    #[test]
    fn axes_fitted_together_are_the_axes_fitted_one_by_one() {
        let s: Vec<f64> = (0..50)
            .map(|i| i as f64 * 0.2 + (i % 4) as f64 * 0.03)
            .collect();
        let y = |a: usize| -> Vec<f64> { s.iter().map(|t| (t * (a + 2) as f64).cos()).collect() };
        let one = SplineSystem::new(&s).unwrap();
        let alone: Vec<AnalysisSpline> = (0..5).map(|a| one.fit(&y(a)).unwrap()).collect();
        let together = SplineSystem::new(&s).unwrap().fit_axes(5, y).unwrap();
        assert_eq!(together.len(), 5);
        for (a, b) in together.iter().zip(&alone) {
            assert_eq!(a.pp, b.pp);
            assert!(std::sync::Arc::ptr_eq(
                &a.pp.shared_breaks(),
                &together[0].pp.shared_breaks()
            ));
        }
        let bad = SplineSystem::new(&s).unwrap().fit_axes(2, |_| vec![1.0; 3]);
        assert!(matches!(bad, Err(PathError::Spline(_))));
    }

    /// Fitting several axes on one factored system equals fitting each alone.
    #[test]
    fn one_system_many_axes() {
        let s = [0.0, 0.7, 1.5, 2.0, 3.2, 4.0];
        let sys = SplineSystem::new(&s).unwrap();
        for y in [
            [0.0, 1.0, -2.0, 0.5, 3.0, 1.0],
            [5.0, 4.0, 4.5, 7.0, 6.0, 6.5],
        ] {
            let a = sys.fit(&y).unwrap();
            let b = AnalysisSpline::new(&s, &y).unwrap();
            for t in [0.0, 0.3, 1.9, 3.99] {
                assert_eq!(a.eval_derivs(t), b.eval_derivs(t));
            }
            for (k, &yk) in y.iter().enumerate() {
                assert!((a.eval(s[k]) - yk).abs() < 1e-12);
            }
        }
    }
}
