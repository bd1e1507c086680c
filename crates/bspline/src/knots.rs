//! Knot vectors: span search and the standard constructions.

/// Clamped cubic knot vector with the given breakpoints (first and last repeated 4 times).
pub fn clamped_cubic(breaks: &[f64]) -> Vec<f64> {
    let _ = breaks;
    todo!()
}

/// Not-a-knot cubic knot vector for data parameters `s` (n ≥ 4): `s[1]` and `s[n-2]` are
/// not knots.
pub fn not_a_knot(s: &[f64]) -> Vec<f64> {
    let _ = s;
    todo!()
}
