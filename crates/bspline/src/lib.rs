//! Cubic B-splines for polepatch (and anyone else): a spline type with evaluation of the
//! value and first three derivatives, basis rows (the linear map from control points to a
//! value or derivative, used to build QP constraints), interpolation with not-a-knot or
//! clamped end conditions, weighted least squares with given knots, and sampling at a
//! fixed step (fs = F·Tcy).
//!
//! Parameters are whatever the caller uses (polepatch: path length s in mm); values are
//! scalars (polepatch: an axis value, mm or degrees).

pub mod basis;
pub mod error;
pub mod fit;
pub mod interp;
pub mod knots;
pub mod sample;
pub mod spline;

pub use basis::BasisRow;
pub use error::SplineError;
pub use fit::fit_least_squares;
pub use interp::{interpolate_clamped, interpolate_not_a_knot};
pub use sample::sample_params;
pub use spline::BSpline;
