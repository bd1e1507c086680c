//! The KKT system's linear algebra: a symmetric banded matrix with a dense border,
//! factored as a quasi-definite `L·D·Lᵀ` (band first, the border by its Schur
//! complement), and iterative refinement against the unregularised matrix.

// Index loops mirror the factorisation's formulas (rows, columns, band offsets).
#![allow(clippy::needless_range_loop)]

use super::inf_norm;

/// A symmetric matrix: banded `nb × nb` (half-bandwidth `w`, lower part stored by
/// diagonals), a dense border `C` (`k × nb`) and corner `E` (`k × k`), factored in place.
pub(super) struct BorderedBand {
    pub(super) nb: usize,
    pub(super) w: usize,
    pub(super) k: usize,
    /// Row i's band from left to right: `band[i·(w+1) + t] = M[i][i + t − w]`
    /// (`t = w` is the diagonal; entries left of column 0 stay 0). After factoring, the
    /// unit L below the diagonal and D on it.
    pub(super) band: Vec<f64>,
    /// `border[r·nb + i] = M[nb + r][i]`.
    pub(super) border: Vec<f64>,
    /// `corner[r·k + q] = M[nb + r][nb + q]`.
    pub(super) corner: Vec<f64>,
    /// After factoring: `Y = B⁻¹·Cᵀ` (column-major by border row: `y[r·nb + i]`).
    pub(super) y: Vec<f64>,
    /// After factoring: the Schur complement's `L·D·Lᵀ` (dense, k × k).
    pub(super) schur: Vec<f64>,
}

impl BorderedBand {
    pub(super) fn new(nb: usize, w: usize, k: usize) -> BorderedBand {
        BorderedBand {
            nb,
            w,
            k,
            band: vec![0.0; nb * (w + 1)],
            border: vec![0.0; k * nb],
            corner: vec![0.0; k * k],
            y: vec![0.0; k * nb],
            schur: vec![0.0; k * k],
        }
    }

    /// Add `v` at `(i, j)` and `(j, i)` of the symmetric matrix (once on the diagonal);
    /// `i`, `j` are unknown indices: `nb + r` is border row r.
    pub(super) fn add_sym(&mut self, i: usize, j: usize, v: f64) {
        let (nb, k, w) = (self.nb, self.k, self.w);
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if j >= nb {
            let (a, b) = (i - nb, j - nb);
            self.corner[a * k + b] += v;
            if a != b {
                self.corner[b * k + a] += v;
            }
        } else if i >= nb {
            self.border[(i - nb) * nb + j] += v;
        } else {
            debug_assert!(i - j <= w, "({i}, {j}) outside the band");
            self.band[i * (w + 1) + j + w - i] += v;
        }
    }

    /// `M·x` (unfactored; call before [`BorderedBand::factor`] or on a copy).
    pub(super) fn mul(&self, x: &[f64], out: &mut [f64]) {
        let (nb, w, k) = (self.nb, self.w, self.k);
        let wp = w + 1;
        out.iter_mut().for_each(|v| *v = 0.0);
        for i in 0..nb {
            let lo = i.saturating_sub(w);
            let row = &self.band[i * wp + (lo + w - i)..i * wp + w];
            let xi = x[i];
            let mut acc = self.band[i * wp + w] * xi;
            for ((v, xm), om) in row.iter().zip(&x[lo..i]).zip(&mut out[lo..i]) {
                acc += v * xm;
                *om += v * xi;
            }
            out[i] += acc;
        }
        for r in 0..k {
            let row = &self.border[r * nb..(r + 1) * nb];
            let mut acc = 0.0;
            for i in 0..nb {
                acc += row[i] * x[i];
                out[i] += row[i] * x[nb + r];
            }
            for q in 0..k {
                acc += self.corner[r * k + q] * x[nb + q];
            }
            out[nb + r] += acc;
        }
    }

    /// Factor in place: banded `L·D·Lᵀ` (unit L below the diagonal, D on it), then the
    /// border's Schur complement. `false` on a zero or non-finite pivot.
    pub(super) fn factor(&mut self) -> bool {
        let (nb, w, k) = (self.nb, self.w, self.k);
        let wp = w + 1;
        // u[m − lo] = L_jm·D_m for the row j in hand.
        let mut u = vec![0.0; w];
        for j in 0..nb {
            let lo = j.saturating_sub(w);
            let cnt = j - lo;
            let (head, rest) = self.band.split_at_mut(j * wp);
            let rowj = &rest[..wp];
            for (idx, m) in (lo..j).enumerate() {
                u[idx] = rowj[w - cnt + idx] * head[m * wp + w];
            }
            // D_j = M_jj − Σ L_jm·D_m·L_jm.
            let dj = rowj[w]
                - rowj[w - cnt..w]
                    .iter()
                    .zip(&u[..cnt])
                    .map(|(a, b)| a * b)
                    .sum::<f64>();
            if !(dj.is_finite() && dj != 0.0) {
                return false;
            }
            self.band[j * wp + w] = dj;
            for i in j + 1..(j + wp).min(nb) {
                // L_ij = (M_ij − Σ_m L_im·L_jm·D_m) / D_j, m from max(i − w, lo) to j − 1.
                let lo_i = i - w.min(i);
                let from = lo_i.max(lo);
                let row_i = &self.band[i * wp..(i + 1) * wp];
                let acc: f64 = row_i[from + w - i..j + w - i]
                    .iter()
                    .zip(&u[from - lo..cnt])
                    .map(|(a, b)| a * b)
                    .sum();
                let at = i * wp + (j + w - i);
                self.band[at] = (self.band[at] - acc) / dj;
            }
        }
        if k == 0 {
            return true;
        }
        // Y = B⁻¹·Cᵀ, S = E − C·Y.
        for r in 0..k {
            let mut col = self.border[r * nb..(r + 1) * nb].to_vec();
            self.band_solve(&mut col);
            self.y[r * nb..(r + 1) * nb].copy_from_slice(&col);
        }
        for r in 0..k {
            for q in 0..k {
                let mut v = self.corner[r * k + q];
                let (cr, yq) = (
                    &self.border[r * nb..(r + 1) * nb],
                    &self.y[q * nb..(q + 1) * nb],
                );
                for i in 0..nb {
                    v -= cr[i] * yq[i];
                }
                self.schur[r * k + q] = v;
            }
        }
        // Dense L·D·Lᵀ of the k × k Schur complement.
        for j in 0..k {
            let mut dj = self.schur[j * k + j];
            for m in 0..j {
                dj -= self.schur[j * k + m] * self.schur[j * k + m] * self.schur[m * k + m];
            }
            if !(dj.is_finite() && dj != 0.0) {
                return false;
            }
            self.schur[j * k + j] = dj;
            for i in j + 1..k {
                let mut v = self.schur[i * k + j];
                for m in 0..j {
                    v -= self.schur[i * k + m] * self.schur[j * k + m] * self.schur[m * k + m];
                }
                self.schur[i * k + j] = v / dj;
            }
        }
        true
    }

    /// Solve with the factored band only (in place).
    pub(super) fn band_solve(&self, x: &mut [f64]) {
        let (nb, w) = (self.nb, self.w);
        let wp = w + 1;
        for i in 0..nb {
            let lo = i.saturating_sub(w);
            let row = &self.band[i * wp + (lo + w - i)..i * wp + w];
            let acc: f64 = row.iter().zip(&x[lo..i]).map(|(a, b)| a * b).sum();
            x[i] -= acc;
        }
        for i in 0..nb {
            x[i] /= self.band[i * wp + w];
        }
        // Lᵀ: column i of L is L_ri = band[r·wp + (i + w − r)] for r in i+1 ..= i+w.
        for i in (0..nb).rev() {
            let hi = (i + wp).min(nb);
            let mut v = x[i];
            for r in i + 1..hi {
                v -= self.band[r * wp + (i + w - r)] * x[r];
            }
            x[i] = v;
        }
    }

    /// Solve `M·x = rhs` with the factors (in place, `x` holds `rhs` on entry).
    pub(super) fn solve(&self, x: &mut [f64]) {
        let (nb, k) = (self.nb, self.k);
        let (u, v) = x.split_at_mut(nb);
        self.band_solve(u);
        if k == 0 {
            return;
        }
        // v ← S⁻¹·(g − C·u′), u ← u′ − Y·v.
        for r in 0..k {
            let cr = &self.border[r * nb..(r + 1) * nb];
            let mut acc = 0.0;
            for i in 0..nb {
                acc += cr[i] * u[i];
            }
            v[r] -= acc;
        }
        for i in 0..k {
            for m in 0..i {
                v[i] -= self.schur[i * k + m] * v[m];
            }
        }
        for i in 0..k {
            v[i] /= self.schur[i * k + i];
        }
        for i in (0..k).rev() {
            for r in i + 1..k {
                v[i] -= self.schur[r * k + i] * v[r];
            }
        }
        for r in 0..k {
            let yr = &self.y[r * nb..(r + 1) * nb];
            for i in 0..nb {
                u[i] -= yr[i] * v[r];
            }
        }
    }
}

impl BorderedBand {
    /// Copy another matrix of the same shape.
    pub(super) fn copy_from(&mut self, o: &BorderedBand) {
        self.band.copy_from_slice(&o.band);
        self.border.copy_from_slice(&o.border);
        self.corner.copy_from_slice(&o.corner);
    }
}

/// Iterative refinement of `sol` (solved with the regularised factors `kkt`) against the
/// unregularised matrix `unreg`, until the residual is below 1e-13 of the right-hand side
/// or `max_steps` steps, whichever first (a step that does not lower it ends it).
pub(super) fn refine(
    kkt: &BorderedBand,
    unreg: &BorderedBand,
    rhs: &[f64],
    sol: &mut [f64],
    tmp: &mut [f64],
    max_steps: u32,
) {
    let nk = rhs.len();
    let target = 1e-13 * (1.0 + inf_norm(rhs));
    let mut last = f64::INFINITY;
    for _ in 0..max_steps {
        unreg.mul(sol, tmp);
        for i in 0..nk {
            tmp[i] = rhs[i] - tmp[i];
        }
        let res = inf_norm(tmp);
        if res <= target || res >= last {
            break;
        }
        last = res;
        kkt.solve(tmp);
        for i in 0..nk {
            sol[i] += tmp[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bordered banded factorisation solves a random quasi-definite system exactly.
    #[test]
    fn bordered_band_solves_quasi_definite_systems() {
        let (nb, w, k) = (30, 4, 2);
        let mut m = BorderedBand::new(nb, w, k);
        let mut seed = 1u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for i in 0..nb {
            let sign = if i % 5 == 4 { -1.0 } else { 1.0 };
            m.add_sym(i, i, sign * (4.0 + rnd()));
            for d in 1..=w.min(i) {
                m.add_sym(i, i - d, 0.3 * rnd());
            }
            for r in 0..k {
                m.add_sym(nb + r, i, 0.2 * rnd());
            }
        }
        for r in 0..k {
            m.add_sym(nb + r, nb + r, 6.0);
        }
        let x: Vec<f64> = (0..nb + k).map(|_| rnd()).collect();
        let mut b = vec![0.0; nb + k];
        m.mul(&x, &mut b);
        assert!(m.factor());
        m.solve(&mut b);
        for (u, v) in b.iter().zip(&x) {
            assert!((u - v).abs() < 1e-10, "{u} vs {v}");
        }
    }
}
