//! The bspline crate's round-off tolerances in one place, each with what it compares and
//! why its value (Clarabel's `settings.rs` manner).

/// Relative tolerance of [`NotAKnotSystem::data_row_local`]: a data row's weight is left
/// out when it is at most this times the row's largest weight (1e−18, two orders below
/// the rounding of a double, so sums over the row agree with the full row's to rounding).
///
/// How far the row then reaches: the weights of the not-a-knot interpolant (and of its
/// B-spline coefficients, which the banded solve computes) decay by `ρ = 2 − √3 ≈ 0.268`
/// per knot on even knots, so a weight falls below `DATA_ROW_TOL` of the largest after
/// `K = ln(10¹⁸)/ln(1/ρ) ≈ 31.5`, i.e. about 32 knots either side of `t`. Uneven knots
/// decay at a different rate on each side; the solve does not assume `K` but stops when
/// two consecutive weights are below the tolerance (the banded recurrence has two
/// terms), so the reach adapts to the knots.
pub const DATA_ROW_TOL: f64 = 1e-18;

/// Relative size below which a diagonal entry of R counts as zero (rank deficiency).
pub const RANK_TOLERANCE: f64 = 1e-12;
