//! Cubic interpolation: not-a-knot (the analysis spline) and clamped.

use crate::{error::SplineError, spline::BSpline};

/// The interpolating cubic spline through `(s[i], y[i])` with not-a-knot end conditions —
/// the same curve as `scipy.interpolate.CubicSpline(s, y)` (its default `bc_type`).
/// n = 2 gives the line and n = 3 the parabola through the points (as scipy); n < 2 is an
/// error, as are non-increasing or non-finite input.
pub fn interpolate_not_a_knot(s: &[f64], y: &[f64]) -> Result<BSpline, SplineError> {
    let _ = (s, y);
    todo!()
}

/// The interpolating cubic spline through `(s[i], y[i])` with first derivatives `d0` at
/// `s[0]` and `dn` at `s[n-1]` (n ≥ 2).
pub fn interpolate_clamped(s: &[f64], y: &[f64], d0: f64, dn: f64) -> Result<BSpline, SplineError> {
    let _ = (s, y, d0, dn);
    todo!()
}
