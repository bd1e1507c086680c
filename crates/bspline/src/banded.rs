//! A small banded LU solver (bandwidth 2 below and 2 above the diagonal, no pivoting) for
//! the interpolation systems.
//!
//! Why our own: faer 0.24 has no banded solver, and its sparse LU carries symbolic
//! analysis and general-sparse overhead that dominates on these tiny-bandwidth systems
//! (measured in `docs/bspline.md`: tens of times slower at n = 5000).
//!
//! Why no pivoting: the B-spline collocation matrices we factor are totally positive
//! (Karlin), and Gaussian elimination without pivoting is backward stable for totally
//! positive matrices (de Boor & Pinkus, *Backward error analysis for totally positive
//! linear systems*, Numer. Math. 27, 1977). The clamped system adds two derivative rows
//! that merely fix the second and second-to-last control point; they are eliminated
//! without growth (see `interp.rs`). A zero or non-finite pivot is still reported.

/// Half bandwidth (both below and above the diagonal).
const KB: usize = 2;
/// Band row width.
pub(crate) const W: usize = 2 * KB + 1;

/// An n×n matrix with `A(i, j) = rows[i][j + 2 − i]` for `|i − j| ≤ 2`, factored in place
/// as `A = L·U` (L unit lower, U upper; both stored in the band).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BandedLu {
    lu: Vec<[f64; W]>,
}

impl BandedLu {
    /// Factor the band matrix `rows` (entries outside the matrix are ignored). On a zero or
    /// non-finite pivot returns its row index.
    pub(crate) fn factor(mut a: Vec<[f64; W]>) -> Result<BandedLu, usize> {
        let n = a.len();
        for k in 0..n {
            let piv = a[k][KB];
            if !(piv.is_finite() && piv.abs() >= f64::MIN_POSITIVE) {
                return Err(k);
            }
            let end = (k + KB + 1).min(n);
            let urow = a[k];
            for i in k + 1..end {
                let l = a[i][k + KB - i] / piv;
                a[i][k + KB - i] = l;
                if l != 0.0 {
                    for j in k + 1..end {
                        a[i][j + KB - i] -= l * urow[j + KB - k];
                    }
                }
            }
        }
        Ok(BandedLu { lu: a })
    }

    /// Order of the matrix.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.lu.len()
    }

    /// Solve `A x = b` in place (`b.len() == n`).
    pub(crate) fn solve_in_place(&self, b: &mut [f64]) {
        let a = &self.lu;
        let n = a.len();
        debug_assert_eq!(b.len(), n);
        for i in 0..n {
            let mut v = b[i];
            for k in i.saturating_sub(KB)..i {
                v -= a[i][k + KB - i] * b[k];
            }
            b[i] = v;
        }
        for i in (0..n).rev() {
            let mut v = b[i];
            for j in i + 1..(i + KB + 1).min(n) {
                v -= a[i][j + KB - i] * b[j];
            }
            b[i] = v / a[i][KB];
        }
    }

    /// Solve `Aᵀ z = b` in place (`b.len() == n`): `Uᵀ w = b`, then `Lᵀ z = w`.
    pub(crate) fn solve_transpose_in_place(&self, b: &mut [f64]) {
        let a = &self.lu;
        let n = a.len();
        debug_assert_eq!(b.len(), n);
        for j in 0..n {
            let mut v = b[j];
            for i in j.saturating_sub(KB)..j {
                v -= a[i][j + KB - i] * b[i];
            }
            b[j] = v / a[j][KB];
        }
        for k in (0..n).rev() {
            let mut v = b[k];
            for i in k + 1..(k + KB + 1).min(n) {
                v -= a[i][k + KB - i] * b[i];
            }
            b[k] = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Diagonally dominant random band matrix and its dense form.
    fn example(n: usize) -> (Vec<[f64; W]>, Vec<Vec<f64>>) {
        let mut x = 12345u64;
        let mut r = move || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let mut band = vec![[0.0; W]; n];
        let mut dense = vec![vec![0.0; n]; n];
        for i in 0..n {
            for d in 0..W {
                let j = i as isize + d as isize - KB as isize;
                if j < 0 || j >= n as isize {
                    continue;
                }
                let v = if d == KB { 3.0 + r() } else { r() };
                band[i][d] = v;
                dense[i][j as usize] = v;
            }
        }
        (band, dense)
    }

    fn matvec(a: &[Vec<f64>], x: &[f64], transpose: bool) -> Vec<f64> {
        let n = x.len();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| if transpose { a[j][i] } else { a[i][j] } * x[j])
                    .sum()
            })
            .collect()
    }

    #[test]
    fn solves_and_transposed_solves_recover_planted_solution() {
        for n in [1, 2, 3, 4, 5, 17] {
            let (band, dense) = example(n);
            let lu = BandedLu::factor(band).unwrap();
            assert_eq!(lu.len(), n);
            let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.1).collect();
            for transpose in [false, true] {
                let mut b = matvec(&dense, &x, transpose);
                if transpose {
                    lu.solve_transpose_in_place(&mut b);
                } else {
                    lu.solve_in_place(&mut b);
                }
                for (got, want) in b.iter().zip(&x) {
                    assert!((got - want).abs() < 1e-12, "n={n} transpose={transpose}");
                }
            }
        }
    }

    #[test]
    fn zero_pivot_is_reported() {
        let band = vec![[0.0, 0.0, 1.0, 1.0, 0.0], [0.0, 1.0, 1.0, 0.0, 0.0]];
        assert_eq!(BandedLu::factor(band), Err(1));
        assert_eq!(
            BandedLu::factor(vec![[0.0, 0.0, f64::NAN, 0.0, 0.0]]),
            Err(0)
        );
    }
}
