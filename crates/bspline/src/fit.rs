//! Weighted least-squares fit with given knots.

use crate::{error::SplineError, spline::BSpline};

/// The cubic spline on `knots` (clamped, as from [`crate::knots::clamped_cubic`]) minimising
/// `Σ w[i]·(f(s[i]) − y[i])²`; `w = None` means all ones.
pub fn fit_least_squares(
    s: &[f64],
    y: &[f64],
    w: Option<&[f64]>,
    knots: &[f64],
) -> Result<BSpline, SplineError> {
    let _ = (s, y, w, knots);
    todo!()
}
