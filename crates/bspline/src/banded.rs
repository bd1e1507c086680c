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
/// as `A = L·U` (L unit lower, U upper; both stored in the band, U's diagonal also as
/// reciprocals so the substitutions multiply instead of divide).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BandedLu {
    lu: Vec<[f64; W]>,
    inv_diag: Vec<f64>,
}

impl BandedLu {
    /// Factor the band matrix `rows` (entries outside the matrix are ignored). On a zero or
    /// non-finite pivot returns its row index.
    pub(crate) fn factor(mut a: Vec<[f64; W]>) -> Result<BandedLu, usize> {
        let n = a.len();
        // Clear the corners that lie outside the matrix, so the loops need no masks.
        for (i, row) in a.iter_mut().enumerate() {
            for (d, v) in row.iter_mut().enumerate() {
                let j = (i + d).wrapping_sub(KB);
                if j >= n {
                    *v = 0.0;
                }
            }
        }
        let mut inv_diag = vec![0.0; n];
        for k in 0..n {
            let piv = a[k][KB];
            if !(piv.is_finite() && piv.abs() >= f64::MIN_POSITIVE) {
                return Err(k);
            }
            let inv = 1.0 / piv;
            inv_diag[k] = inv;
            let (u3, u4) = (a[k][3], a[k][4]);
            if k + 1 < n {
                let r = &mut a[k + 1];
                let l = r[1] * inv;
                r[1] = l;
                r[2] -= l * u3;
                r[3] -= l * u4;
            }
            if k + 2 < n {
                let r = &mut a[k + 2];
                let l = r[0] * inv;
                r[0] = l;
                r[1] -= l * u3;
                r[2] -= l * u4;
            }
        }
        Ok(BandedLu { lu: a, inv_diag })
    }

    /// Order of the matrix.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.lu.len()
    }

    /// Solve `A x = b` in place (`b.len() == n`).
    pub(crate) fn solve_in_place(&self, b: &mut [f64]) {
        let a = &self.lu;
        assert_eq!(b.len(), a.len());
        // L y = b: y_i = b_i − L(i,i−1)·y_{i−1} − L(i,i−2)·y_{i−2} (corners are zero).
        let (mut y2, mut y1) = (0.0, 0.0);
        for (bi, r) in b.iter_mut().zip(a) {
            let y = *bi - r[1] * y1 - r[0] * y2;
            *bi = y;
            y2 = y1;
            y1 = y;
        }
        // U x = y: x_i = (y_i − U(i,i+1)·x_{i+1} − U(i,i+2)·x_{i+2}) / U(i,i).
        let (mut x1, mut x2) = (0.0, 0.0);
        for ((bi, r), inv) in b.iter_mut().zip(a).zip(&self.inv_diag).rev() {
            let x = (*bi - r[3] * x1 - r[4] * x2) * inv;
            *bi = x;
            x2 = x1;
            x1 = x;
        }
    }

    /// Solve `Aᵀ z = b` in place (`b.len() == n`): `Uᵀ w = b`, then `Lᵀ z = w`.
    pub(crate) fn solve_transpose_in_place(&self, b: &mut [f64]) {
        let a = &self.lu;
        let n = a.len();
        assert_eq!(b.len(), n);
        // Uᵀ w = b: w_j = (b_j − U(j−1,j)·w_{j−1} − U(j−2,j)·w_{j−2}) / U(j,j).
        for j in 0..n {
            let mut v = b[j];
            if j >= 1 {
                v -= a[j - 1][3] * b[j - 1];
            }
            if j >= 2 {
                v -= a[j - 2][4] * b[j - 2];
            }
            b[j] = v * self.inv_diag[j];
        }
        // Lᵀ z = w: z_k = w_k − L(k+1,k)·z_{k+1} − L(k+2,k)·z_{k+2}.
        for k in (0..n).rev() {
            let mut v = b[k];
            if k + 1 < n {
                v -= a[k + 1][1] * b[k + 1];
            }
            if k + 2 < n {
                v -= a[k + 2][0] * b[k + 2];
            }
            b[k] = v;
        }
    }

    /// [`BandedLu::solve_transpose_in_place`] for a right-hand side that is zero but for
    /// `rhs` at `start..start + rhs.len()`, computed only where the solution is not
    /// negligible: into `out` (cleared first), returning the index of `out[0]`; entries
    /// outside `first..first + out.len()` are taken as zero.
    ///
    /// The forward sweep (`Uᵀ w = b`) is zero before `start` and, past the right-hand
    /// side, a homogeneous two-term recurrence: it stops once two consecutive `|w_j|` are
    /// at most `tol` times the largest `|w|` so far (what follows is that recurrence
    /// continued from two values that small). The backward sweep (`Lᵀ z = w`) stops the same
    /// way below `start`. For the matrices of this crate, whose inverses decay
    /// geometrically away from the diagonal, the entries left out are at most about
    /// `tol` times the largest entry each, and decreasing: the row is exact to that. With
    /// `tol = 0` the computed entries are bit for bit those of the full solve (the sweeps
    /// then stop only on exact zeros).
    pub(crate) fn solve_transpose_local(
        &self,
        start: usize,
        rhs: &[f64],
        tol: f64,
        out: &mut Vec<f64>,
    ) -> usize {
        let a = &self.lu;
        let n = a.len();
        assert!(start + rhs.len() <= n);
        out.clear();
        // Forward: w_j for j = start.. (w is exactly zero before start).
        let mut peak = 0.0f64;
        let mut j = start;
        while j < n {
            let mut v = rhs.get(j - start).copied().unwrap_or(0.0);
            if j > start {
                v -= a[j - 1][3] * out[j - 1 - start];
            }
            if j > start + 1 {
                v -= a[j - 2][4] * out[j - 2 - start];
            }
            let w = v * self.inv_diag[j];
            out.push(w);
            peak = peak.max(w.abs());
            j += 1;
            if j - start > rhs.len() + 1 {
                let m = out.len();
                if out[m - 1].abs() <= tol * peak && out[m - 2].abs() <= tol * peak {
                    break;
                }
            }
        }
        let end = j;
        // Backward: z_k for k = end − 1 down, the entries from end on taken as zero. Below
        // start w is zero; the entries found there are put in front of `out` at the end.
        let mut below = Vec::new();
        let mut zpeak = 0.0f64;
        let (mut z1, mut z2) = (0.0, 0.0);
        for k in (0..end).rev() {
            let mut v = if k >= start { out[k - start] } else { 0.0 };
            if k + 1 < end {
                v -= a[k + 1][1] * z1;
            }
            if k + 2 < end {
                v -= a[k + 2][0] * z2;
            }
            if k >= start {
                out[k - start] = v;
            } else {
                below.push(v);
            }
            zpeak = zpeak.max(v.abs());
            z2 = z1;
            z1 = v;
            if k + 1 < start && z1.abs() <= tol * zpeak && z2.abs() <= tol * zpeak {
                break;
            }
        }
        let first = start - below.len();
        if !below.is_empty() {
            below.reverse();
            out.splice(0..0, below);
        }
        first
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

    /// The local transposed solve with `tol = 0` is the full one bit for bit on the
    /// entries it returns (up to the sign of a zero), and the others are exactly zero.
    #[test]
    fn local_transposed_solve_with_zero_tolerance_is_the_full_one() {
        for n in [1, 2, 3, 4, 5, 17, 60] {
            let (band, _) = example(n);
            let lu = BandedLu::factor(band).unwrap();
            let mut out = Vec::new();
            for start in 0..n {
                let rhs: Vec<f64> = (0..4.min(n - start)).map(|i| 1.0 + i as f64).collect();
                let mut full = vec![0.0; n];
                full[start..start + rhs.len()].copy_from_slice(&rhs);
                lu.solve_transpose_in_place(&mut full);
                let first = lu.solve_transpose_local(start, &rhs, 0.0, &mut out);
                for (i, f) in full.iter().enumerate() {
                    let l = if (first..first + out.len()).contains(&i) {
                        out[i - first]
                    } else {
                        0.0
                    };
                    // Equal as numbers (bit for bit but for the sign of a zero).
                    assert_eq!(l, *f, "n={n} start={start} i={i}");
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
