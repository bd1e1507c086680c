//! The B-spline type and its evaluation.

use crate::error::SplineError;

/// A scalar B-spline of degree `degree` (≤ 3 in practice) with a clamped or general knot
/// vector `knots` (length `coeffs.len() + degree + 1`) and control points `coeffs`.
/// Its domain is `[knots[degree], knots[len - degree - 1]]`; evaluation outside extends the
/// end polynomial pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct BSpline {
    degree: usize,
    knots: Vec<f64>,
    coeffs: Vec<f64>,
}

impl BSpline {
    /// A spline from its parts; checks lengths, non-decreasing finite knots.
    pub fn new(degree: usize, knots: Vec<f64>, coeffs: Vec<f64>) -> Result<BSpline, SplineError> {
        let _ = (degree, knots, coeffs);
        todo!()
    }
    /// Degree.
    pub fn degree(&self) -> usize {
        self.degree
    }
    /// Knot vector.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }
    /// Control points.
    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }
    /// Domain `(start, end)`.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.knots.len() - self.degree - 1])
    }
    /// Value at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        self.eval_derivs(t)[0]
    }
    /// Value and first three derivatives at `t`: `[y, y', y'', y''']` (zero above degree).
    pub fn eval_derivs(&self, t: f64) -> [f64; 4] {
        let _ = t;
        todo!()
    }
    /// `eval_derivs` at many sorted (non-decreasing) parameters, written into `out`
    /// (same length as `ts`). Amortises the span search; the fast path.
    pub fn eval_derivs_sorted(&self, ts: &[f64], out: &mut [[f64; 4]]) {
        let _ = (ts, out);
        todo!()
    }
    /// The derivative spline (degree − 1).
    pub fn derivative(&self) -> BSpline {
        todo!()
    }
}
