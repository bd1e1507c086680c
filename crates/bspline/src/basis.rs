//! Basis rows: the linear map from control points to a value or derivative.

use crate::spline::BSpline;

/// `value_or_derivative(t) = Σ_k weights[k] · coeffs[first + k]` for k in 0..=degree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BasisRow {
    /// Index of the first control point involved.
    pub first: usize,
    /// Weights of control points `first ..= first + degree` (unused entries are 0).
    pub weights: [f64; 4],
}

impl BSpline {
    /// The basis row of the `order`-th derivative (0..=3) at `t`, for this spline's knots.
    pub fn basis_row(&self, t: f64, order: usize) -> BasisRow {
        let _ = (t, order);
        todo!()
    }
}
