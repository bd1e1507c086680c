//! Cubic B-splines for polepatch (and anyone else): a spline type with evaluation of the
//! value and first three derivatives, basis rows (the linear map from control points to a
//! value or derivative, used to build QP constraints), interpolation with not-a-knot or
//! clamped end conditions, weighted least squares with given knots, and sampling at a
//! fixed step (fs = F·Tcy).
//!
//! Parameters are whatever the caller uses (polepatch: path length s in mm); values are
//! scalars (polepatch: an axis value, mm or degrees).
//!
//! ```
//! use polepatch_bspline::{interpolate_not_a_knot, sample_params};
//! // C-axis values (degrees) at cumulative path lengths s (mm).
//! let s = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5];
//! let c_deg = [114.0, 118.0, 130.0, 160.0, 200.0, 230.0];
//! let c = interpolate_not_a_knot(&s, &c_deg)?;
//! let ts = sample_params(0.0, 2.5, 0.05); // fs = F·Tcy
//! let mut d = vec![[0.0; 4]; ts.len()];
//! c.eval_derivs_sorted(&ts, &mut d); // [C, C_s, C_ss, C_sss] at each sample
//! assert!((d[10][0] - c_deg[1]).abs() < 1e-12);
//! # Ok::<(), polepatch_bspline::SplineError>(())
//! ```
//!
//! Algorithms and measured speed: `docs/bspline.md`. In brief: evaluation by the
//! Cox–de Boor recurrence (Piegl & Tiller A2.3), with a per-span Taylor form and Horner's
//! rule on the sorted fast path ([`BSpline::eval_derivs_sorted`], [`PpCubic`]);
//! interpolation in B-spline form solved by a small banded LU without pivoting (the
//! collocation matrix is totally positive); least squares by faer's dense Householder QR.

// Index loops mirror the formulas (A(i, j), ders[k][j]) and read better than iterators here.
#![allow(clippy::needless_range_loop)]

mod banded;
pub mod basis;
mod cox_de_boor;
pub mod error;
pub mod fit;
pub mod interp;
pub mod knots;
pub mod pp;
pub mod sample;
pub mod spline;
pub mod tolerances;

pub use basis::BasisRow;
pub use error::SplineError;
pub use fit::fit_least_squares;
pub use interp::{NotAKnotSystem, interpolate_clamped, interpolate_not_a_knot};
pub use pp::PpCubic;
pub use sample::sample_params;
pub use spline::BSpline;
