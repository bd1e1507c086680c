//! Knot vectors: the standard constructions.
//!
//! (The span search lives with the Cox–de Boor recurrence, `cox_de_boor::find_span`, and is
//! used through [`crate::BSpline::eval_derivs`] and [`crate::BSpline::basis_row`].)

/// Clamped cubic knot vector with the given breakpoints (first and last repeated 4 times).
///
/// `[b0, b0, b0, b0, b1, …, b(m−2), b(m−1), b(m−1), b(m−1), b(m−1)]`: `m + 6` knots, hence
/// `m + 2` cubic control points. Empty `breaks` give an empty vector; the breakpoints are
/// not checked here ([`crate::BSpline::new`] does).
pub fn clamped_cubic(breaks: &[f64]) -> Vec<f64> {
    let (Some(&first), Some(&last)) = (breaks.first(), breaks.last()) else {
        return Vec::new();
    };
    let inner = if breaks.len() > 2 {
        &breaks[1..breaks.len() - 1]
    } else {
        &[][..]
    };
    let mut k = Vec::with_capacity(inner.len() + 8);
    k.extend([first; 4]);
    k.extend_from_slice(inner);
    k.extend([last; 4]);
    k
}

/// Not-a-knot cubic knot vector for data parameters `s` (n ≥ 4): `s[1]` and `s[n-2]` are
/// not knots.
///
/// `[s0, s0, s0, s0, s2, …, s(n−3), s(n−1) ×4]`: `n + 4` knots, `n` control points, one per
/// data point. For n = 2 or 3 it is the single Bézier span `[s0 ×4, s(n−1) ×4]` that
/// [`crate::interpolate_not_a_knot`] uses for the line or parabola; n < 2 gives
/// `clamped_cubic(s)`.
pub fn not_a_knot(s: &[f64]) -> Vec<f64> {
    let n = s.len();
    if n < 4 {
        return match n {
            0 | 1 => clamped_cubic(s),
            _ => clamped_cubic(&[s[0], s[n - 1]]),
        };
    }
    let mut k = Vec::with_capacity(n + 4);
    k.extend([s[0]; 4]);
    k.extend_from_slice(&s[2..n - 2]);
    k.extend([s[n - 1]; 4]);
    k
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamped_has_quadruple_ends() {
        assert_eq!(
            clamped_cubic(&[0.0, 1.0, 3.0]),
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 3.0, 3.0, 3.0, 3.0]
        );
        assert_eq!(
            clamped_cubic(&[2.0, 5.0]),
            vec![2.0, 2.0, 2.0, 2.0, 5.0, 5.0, 5.0, 5.0]
        );
        assert!(clamped_cubic(&[]).is_empty());
    }

    #[test]
    fn not_a_knot_drops_second_and_second_to_last() {
        let s = [0.0, 1.0, 2.0, 4.0, 7.0, 8.0];
        assert_eq!(
            not_a_knot(&s),
            vec![0.0, 0.0, 0.0, 0.0, 2.0, 4.0, 8.0, 8.0, 8.0, 8.0]
        );
        assert_eq!(not_a_knot(&s).len(), s.len() + 4);
        assert_eq!(not_a_knot(&s[..4]), clamped_cubic(&[0.0, 4.0]));
        assert_eq!(not_a_knot(&s[..3]), clamped_cubic(&[0.0, 2.0]));
        assert_eq!(not_a_knot(&s[..2]), clamped_cubic(&[0.0, 1.0]));
    }
}
