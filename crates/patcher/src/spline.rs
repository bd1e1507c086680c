//! The analysis spline (SPEC §2), in one place.
//!
//! For each axis of a run, the analysis spline is the not-a-knot interpolating cubic of the
//! axis values over the tool-tip path length s (knots at the CL points), evaluated at the
//! samples of [`span_offsets`]: every `F·Tcy` from each CL point and at the last CL point
//! (so at every knot). Equation 6 is evaluated on its derivatives. Everything in the
//! patcher that evaluates the spline goes through here:
//! - [`SplineSystem`] factors the not-a-knot system once per knot vector (a run, or a
//!   window of it) and fits any number of axes on it ([`SplineSystem::fit`]);
//! - [`AnalysisSpline`] evaluates a fitted axis (piecewise-polynomial form);
//! - [`span_peaks`] reduces a spline to the largest |q'|, |q''|, |q'''| on each span's
//!   samples, which is all Equation 6 needs to bound a span (its ratio is decreasing in
//!   each derivative's size).
//!
//! The solvers use the same spline in linear form (`crate::hermite`: the knot slopes tied
//! to the values by the same end conditions), tested against this module.

use crate::path::PathError;
use polepatch_bspline::{NotAKnotSystem, PpCubic};

/// The sampling rule of the analysis on one span of length `h`: local offsets
/// `0, step, 2·step, … < h` from the span's first knot, and `h` itself when `with_end` (the
/// last span of a run). `out` is cleared first.
pub fn span_offsets(h: f64, step: f64, with_end: bool, out: &mut Vec<f64>) {
    out.clear();
    let count = (h / step).ceil().max(1.0) as usize;
    for i in 0..count {
        let t = i as f64 * step;
        if t < h {
            out.push(t);
        }
    }
    if with_end {
        out.push(h);
    }
}

/// The not-a-knot system of one knot vector, factored once.
#[derive(Debug, Clone)]
pub struct SplineSystem {
    sys: NotAKnotSystem,
}

impl SplineSystem {
    /// Factor the system of the knots `s_mm` (≥ 2, finite, strictly increasing).
    pub fn new(s_mm: &[f64]) -> Result<SplineSystem, PathError> {
        NotAKnotSystem::new(s_mm)
            .map(|sys| SplineSystem { sys })
            .map_err(|e| PathError::Spline(e.to_string()))
    }

    /// The weights `w_i` with `q^(order)(t) = Σ_i w_i·y_i` for the analysis spline of any
    /// values `y` on these knots (order 0..=3).
    pub fn data_row(&self, t: f64, order: usize) -> Vec<f64> {
        self.sys.data_row(t, order)
    }

    /// The analysis spline of the values `y` (one per knot, finite).
    pub fn fit(&self, y: &[f64]) -> Result<AnalysisSpline, PathError> {
        self.sys
            .solve(y)
            .map(|b| AnalysisSpline { pp: b.to_pp() })
            .map_err(|e| PathError::Spline(e.to_string()))
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

    /// [`AnalysisSpline::eval_derivs`] at sorted parameters `ts`, into `out` (same length).
    pub fn eval_derivs_sorted(&self, ts: &[f64], out: &mut [[f64; 4]]) {
        self.pp.eval_derivs_sorted(ts, out);
    }
}

/// For every span `k` of `s_mm` (`[s_k, s_{k+1}]`), the largest `|q'|`, `|q''|`, `|q'''|`
/// of `spline` over the span's samples ([`span_offsets`] with `step_mm`, the end knot
/// included on the last span).
pub fn span_peaks(s_mm: &[f64], spline: &AnalysisSpline, step_mm: f64) -> Vec<[f64; 3]> {
    let n = s_mm.len();
    let mut ts = Vec::new();
    let mut at = Vec::new();
    let mut span_of = Vec::new();
    for k in 0..n.saturating_sub(1) {
        span_offsets(s_mm[k + 1] - s_mm[k], step_mm, k + 2 == n, &mut ts);
        at.extend(ts.iter().map(|t| s_mm[k] + t));
        span_of.extend(std::iter::repeat_n(k, ts.len()));
    }
    let mut d = vec![[0.0; 4]; at.len()];
    spline.eval_derivs_sorted(&at, &mut d);
    let mut peak = vec![[0.0f64; 3]; n.saturating_sub(1)];
    for (k, e) in span_of.iter().zip(&d) {
        let pk = &mut peak[*k];
        for (m, v) in pk.iter_mut().zip(&e[1..]) {
            // NaN propagates as NaN (f64::max would drop it), so a bad spline cannot
            // pass for a smooth one.
            *m = if v.is_nan() { f64::NAN } else { m.max(v.abs()) };
        }
    }
    peak
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

    /// The sample offsets: every step from 0, below h, and h itself on request.
    #[test]
    fn offsets_follow_the_sampling_rule() {
        let mut o = Vec::new();
        span_offsets(1.0, 0.3, false, &mut o);
        assert_eq!(o.len(), 4);
        span_offsets(1.0, 0.3, true, &mut o);
        assert_eq!(*o.last().unwrap(), 1.0);
        span_offsets(0.1, 0.3, false, &mut o);
        assert_eq!(o, vec![0.0]);
    }

    /// A cubic is reproduced by its not-a-knot interpolant, so the peaks are the cubic's:
    /// q = s³ on [0, 4]: q' = 3s², q'' = 6s, q''' = 6, largest at each span's right end
    /// (sampled exactly when the step divides the spacing).
    #[test]
    fn peaks_of_a_planted_cubic() {
        let s: Vec<f64> = (0..5).map(|i| i as f64).collect();
        let y: Vec<f64> = s.iter().map(|x| x * x * x).collect();
        let sp = AnalysisSpline::new(&s, &y).unwrap();
        let pk = span_peaks(&s, &sp, 0.25);
        assert_eq!(pk.len(), 4);
        for (k, p) in pk.iter().enumerate() {
            // The right end of span k is sampled only on the last span; elsewhere the last
            // sample is 0.25 before it.
            let r = if k == 3 { 4.0 } else { k as f64 + 0.75 };
            assert!((p[0] - 3.0 * r * r).abs() < 1e-9, "{k}: {p:?}");
            assert!((p[1] - 6.0 * r).abs() < 1e-9, "{k}: {p:?}");
            assert!((p[2] - 6.0).abs() < 1e-9, "{k}: {p:?}");
        }
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
