//! The small algebra of 3-vectors (`[f64; 3]`: tool axes, points in mm) that every crate
//! shares, so that one formula is written once: [`add`], [`sub`], [`scale`], [`dot`],
//! [`cross`], [`norm`] and [`norm_direct`], and [`along`] (a point on the tool axis, the ball's centre
//! `tip + R·o`).
//!
//! Each is written in one fixed order of operations (a dot product sums x, then y, then
//! z), so that a result is the same to the bit wherever it is computed. [`norm`] is
//! `hypot`'s (no overflow or underflow); [`norm_direct`] the plain `√(a·a)` (faster, for
//! lengths in mm where neither can happen). The two differ in the last bits: each caller
//! keeps the one it had.

/// `a + b`.
#[inline]
pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `k·a`.
#[inline]
pub fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// `a · b`, summed x + y + z.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a|`, as `hypot(hypot(x, y), z)`.
#[inline]
pub fn norm(a: [f64; 3]) -> f64 {
    a[0].hypot(a[1]).hypot(a[2])
}

/// `|a|` as `√(x·x + y·y + z·z)` ([`dot`]`(a, a).sqrt()`).
#[inline]
pub fn norm_direct(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The point `height_mm` from `point_mm` along the unit tool axis `o` (towards the
/// spindle): `point + h·o`, each coordinate `point[i] + h·o[i]`. With the tip and a ball's
/// radius (or the centre's height above the point X Y Z state), the ball's centre.
#[inline]
pub fn along(point_mm: [f64; 3], o: [f64; 3], height_mm: f64) -> [f64; 3] {
    [
        point_mm[0] + height_mm * o[0],
        point_mm[1] + height_mm * o[1],
        point_mm[2] + height_mm * o[2],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_operations_of_planted_vectors() {
        let (a, b) = ([1.0, 2.0, 3.0], [4.0, -5.0, 6.0]);
        assert_eq!(add(a, b), [5.0, -3.0, 9.0]);
        assert_eq!(sub(a, b), [-3.0, 7.0, -3.0]);
        assert_eq!(scale(a, 2.0), [2.0, 4.0, 6.0]);
        assert_eq!(dot(a, b), 12.0);
        assert_eq!(cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
        assert_eq!(norm([3.0, 4.0, 12.0]), 13.0);
        assert_eq!(
            along([1.0, 1.0, 1.0], [0.0, 0.0, 1.0], 5.0),
            [1.0, 1.0, 6.0]
        );
    }

    /// `hypot` keeps a norm of huge or tiny components that the plain square root loses.
    #[test]
    fn the_norm_neither_overflows_nor_underflows() {
        assert!((norm([3e200, 4e200, 0.0]) / 5e200 - 1.0).abs() < 1e-15);
        assert!((norm([3e-200, 4e-200, 0.0]) / 5e-200 - 1.0).abs() < 1e-15);
        assert!(
            dot([3e200, 4e200, 0.0], [3e200, 4e200, 0.0])
                .sqrt()
                .is_infinite()
        );
    }
}
