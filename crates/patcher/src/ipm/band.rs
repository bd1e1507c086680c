//! The KKT system's linear algebra: a symmetric banded matrix with a dense border,
//! factored as `L·D·Lᵀ` (band first, row by row; the border by its Schur complement),
//! and iterative refinement against the unregularised matrix.
//!
//! The band's loops run over a half-bandwidth fixed at compile time (the matrix's is
//! rounded up to one of [`WIDTHS`]; the extra diagonals are zero), so that the short inner
//! loops of a narrow band (six for the joint patch) unroll instead of paying their
//! bookkeeping on every entry.

// Index loops mirror the factorisation's formulas (rows, columns, band offsets).
#![allow(clippy::needless_range_loop)]

use super::inf_norm;
use crate::tolerances::IPM_REFINE_REL_TOL;

/// The half-bandwidths the band's loops are compiled for; a wider band uses the same
/// loops with the width read at run time.
pub(super) const WIDTHS: [usize; 6] = [2, 4, 6, 8, 12, 16];

/// A symmetric matrix: banded `nb × nb` (half-bandwidth `w`, lower part stored by
/// rows), a dense border `C` (`k × nb`) and corner `E` (`k × k`), factored in place.
pub(super) struct BorderedBand {
    pub(super) nb: usize,
    pub(super) w: usize,
    pub(super) k: usize,
    /// Row i's band from left to right: `band[i·(w+1) + t] = M[i][i + t − w]`
    /// (`t = w` is the diagonal; entries left of column 0 stay 0). After factoring, the
    /// unit L below the diagonal and D on it.
    pub(super) band: Vec<f64>,
    /// After factoring: `1/D`.
    dinv: Vec<f64>,
    /// `border[r·nb + i] = M[nb + r][i]`.
    pub(super) border: Vec<f64>,
    /// `corner[r·k + q] = M[nb + r][nb + q]`.
    pub(super) corner: Vec<f64>,
    /// After factoring: `Y = B⁻¹·Cᵀ` (column-major by border row: `y[r·nb + i]`).
    y: Vec<f64>,
    /// After factoring: the Schur complement's `L·D·Lᵀ` (dense, k × k).
    schur: Vec<f64>,
}

impl BorderedBand {
    /// A zero matrix with `nb` band unknowns of half-bandwidth at least `w` (rounded up to
    /// one of [`WIDTHS`]) and `k` border unknowns.
    pub(super) fn new(nb: usize, w: usize, k: usize) -> BorderedBand {
        let w = WIDTHS.iter().copied().find(|&c| c >= w).unwrap_or(w);
        BorderedBand {
            nb,
            w,
            k,
            band: vec![0.0; nb * (w + 1)],
            dinv: vec![0.0; nb],
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

    /// Copy another matrix of the same shape.
    pub(super) fn copy_from(&mut self, o: &BorderedBand) {
        self.band.copy_from_slice(&o.band);
        self.border.copy_from_slice(&o.border);
        self.corner.copy_from_slice(&o.corner);
    }

    /// `out = M·x` (unfactored; call before [`BorderedBand::factor`] or on a copy).
    pub(super) fn mul(&self, x: &[f64], out: &mut [f64]) {
        let (nb, k) = (self.nb, self.k);
        out.iter_mut().for_each(|v| *v = 0.0);
        match self.w {
            2 => band_mul::<2>(&self.band, nb, x, out),
            4 => band_mul::<4>(&self.band, nb, x, out),
            6 => band_mul::<6>(&self.band, nb, x, out),
            8 => band_mul::<8>(&self.band, nb, x, out),
            12 => band_mul::<12>(&self.band, nb, x, out),
            16 => band_mul::<16>(&self.band, nb, x, out),
            w => band_mul_dyn(&self.band, nb, w, x, out),
        }
        for r in 0..k {
            let row = &self.border[r * nb..(r + 1) * nb];
            let xr = x[nb + r];
            let mut acc = 0.0;
            for ((c, xi), oi) in row.iter().zip(&x[..nb]).zip(&mut out[..nb]) {
                acc += c * xi;
                *oi += c * xr;
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
        let (nb, k) = (self.nb, self.k);
        let ok = match self.w {
            2 => band_factor::<2>(&mut self.band, &mut self.dinv, nb),
            4 => band_factor::<4>(&mut self.band, &mut self.dinv, nb),
            6 => band_factor::<6>(&mut self.band, &mut self.dinv, nb),
            8 => band_factor::<8>(&mut self.band, &mut self.dinv, nb),
            12 => band_factor::<12>(&mut self.band, &mut self.dinv, nb),
            16 => band_factor::<16>(&mut self.band, &mut self.dinv, nb),
            w => band_factor_dyn(&mut self.band, &mut self.dinv, nb, w),
        };
        if !ok {
            return false;
        }
        if k == 0 {
            return true;
        }
        // Y = B⁻¹·Cᵀ, S = E − C·Y.
        let mut y = std::mem::take(&mut self.y);
        y.copy_from_slice(&self.border);
        for r in 0..k {
            self.band_solve(&mut y[r * nb..(r + 1) * nb]);
        }
        self.y = y;
        for r in 0..k {
            for q in 0..k {
                let (cr, yq) = (
                    &self.border[r * nb..(r + 1) * nb],
                    &self.y[q * nb..(q + 1) * nb],
                );
                let dot: f64 = cr.iter().zip(yq).map(|(a, b)| a * b).sum();
                self.schur[r * k + q] = self.corner[r * k + q] - dot;
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
    fn band_solve(&self, x: &mut [f64]) {
        let nb = self.nb;
        match self.w {
            2 => band_solve::<2>(&self.band, &self.dinv, nb, x),
            4 => band_solve::<4>(&self.band, &self.dinv, nb, x),
            6 => band_solve::<6>(&self.band, &self.dinv, nb, x),
            8 => band_solve::<8>(&self.band, &self.dinv, nb, x),
            12 => band_solve::<12>(&self.band, &self.dinv, nb, x),
            16 => band_solve::<16>(&self.band, &self.dinv, nb, x),
            w => band_solve_dyn(&self.band, &self.dinv, nb, w, x),
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
            v[r] -= cr.iter().zip(u.iter()).map(|(a, b)| a * b).sum::<f64>();
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
            let vr = v[r];
            for (ui, yi) in u.iter_mut().zip(yr) {
                *ui -= yi * vr;
            }
        }
    }
}

/// `out += B·x` for the symmetric band `B` (rows of `W + 1`, lower part).
fn band_mul<const W: usize>(band: &[f64], nb: usize, x: &[f64], out: &mut [f64]) {
    let wp = W + 1;
    // The first W rows reach left of column 0 (their entries there are 0).
    band_mul_dyn(&band[..W.min(nb) * wp], W.min(nb), W, x, out);
    for i in W..nb {
        let row = &band[i * wp..i * wp + wp];
        let xi = x[i];
        let xs = &x[i - W..i];
        let os = &mut out[i - W..i];
        let mut acc = row[W] * xi;
        for t in 0..W {
            acc += row[t] * xs[t];
            os[t] += row[t] * xi;
        }
        out[i] += acc;
    }
}

fn band_mul_dyn(band: &[f64], nb: usize, w: usize, x: &[f64], out: &mut [f64]) {
    let wp = w + 1;
    for i in 0..nb {
        let lo = i.saturating_sub(w);
        let row = &band[i * wp + (lo + w - i)..i * wp + w];
        let xi = x[i];
        let mut acc = band[i * wp + w] * xi;
        for ((v, xm), om) in row.iter().zip(&x[lo..i]).zip(&mut out[lo..i]) {
            acc += v * xm;
            *om += v * xi;
        }
        out[i] += acc;
    }
}

/// Banded `L·D·Lᵀ` row by row: row i's `L_ij = (M_ij − Σ_m L_im·D_m·L_jm)/D_j` for the
/// W columns before it, then `D_i = M_ii − Σ_m L_im²·D_m`.
fn band_factor<const W: usize>(band: &mut [f64], dinv: &mut [f64], nb: usize) -> bool {
    let wp = W + 1;
    if !band_factor_dyn(
        &mut band[..W.min(nb) * wp],
        &mut dinv[..W.min(nb)],
        W.min(nb),
        W,
    ) {
        return false;
    }
    for i in W..nb {
        let (prev, cur) = band.split_at_mut(i * wp);
        let row = &mut cur[..wp];
        // ld[t] = L_im·D_m for m = i − W + t, as they become known.
        let mut ld = [0.0; 16];
        let mut dsum = 0.0;
        for tj in 0..W {
            let j = i - W + tj;
            let rj = &prev[j * wp..j * wp + wp];
            let mut acc = row[tj];
            // m = i − W + tm for tm < tj; L_jm is row j's entry at W + tm − tj.
            for tm in 0..tj {
                acc -= ld[tm] * rj[W + tm - tj];
            }
            let l = acc * dinv[j];
            row[tj] = l;
            ld[tj] = l * rj[W];
            dsum += l * ld[tj];
        }
        let d = row[W] - dsum;
        if !(d.is_finite() && d != 0.0) {
            return false;
        }
        row[W] = d;
        dinv[i] = 1.0 / d;
    }
    true
}

fn band_factor_dyn(band: &mut [f64], dinv: &mut [f64], nb: usize, w: usize) -> bool {
    let wp = w + 1;
    let mut ld = vec![0.0; w];
    for i in 0..nb {
        let (prev, cur) = band.split_at_mut(i * wp);
        let row = &mut cur[..wp];
        let mut dsum = 0.0;
        for tj in w.saturating_sub(i)..w {
            let j = i + tj - w;
            let rj = &prev[j * wp..j * wp + wp];
            let mut acc = row[tj];
            for tm in w.saturating_sub(i)..tj {
                acc -= ld[tm] * rj[w + tm - tj];
            }
            let l = acc * dinv[j];
            row[tj] = l;
            ld[tj] = l * rj[w];
            dsum += l * ld[tj];
        }
        let d = row[w] - dsum;
        if !(d.is_finite() && d != 0.0) {
            return false;
        }
        row[w] = d;
        dinv[i] = 1.0 / d;
    }
    true
}

/// `x ← (L·D·Lᵀ)⁻¹·x`: forward with L by rows, D, backward with Lᵀ by rows.
fn band_solve<const W: usize>(band: &[f64], dinv: &[f64], nb: usize, x: &mut [f64]) {
    let wp = W + 1;
    let h = W.min(nb);
    // Forward (the first W rows reach left of column 0).
    for i in 0..h {
        let row = &band[i * wp..i * wp + wp];
        let mut acc = 0.0;
        for t in W - i..W {
            acc += row[t] * x[i + t - W];
        }
        x[i] -= acc;
    }
    for i in W..nb {
        let row = &band[i * wp..i * wp + wp];
        let xs = &x[i - W..i];
        let mut acc = 0.0;
        for t in 0..W {
            acc += row[t] * xs[t];
        }
        x[i] -= acc;
    }
    for (xi, di) in x[..nb].iter_mut().zip(dinv) {
        *xi *= di;
    }
    // Backward: x_m −= L_im·x_i for the W columns m before each row i, last row first.
    for i in (W..nb).rev() {
        let row = &band[i * wp..i * wp + wp];
        let xi = x[i];
        let xs = &mut x[i - W..i];
        for t in 0..W {
            xs[t] -= row[t] * xi;
        }
    }
    for i in (0..h).rev() {
        let row = &band[i * wp..i * wp + wp];
        let xi = x[i];
        for t in W - i..W {
            x[i + t - W] -= row[t] * xi;
        }
    }
}

fn band_solve_dyn(band: &[f64], dinv: &[f64], nb: usize, w: usize, x: &mut [f64]) {
    let wp = w + 1;
    for i in 0..nb {
        let row = &band[i * wp..i * wp + wp];
        let mut acc = 0.0;
        for t in w.saturating_sub(i)..w {
            acc += row[t] * x[i + t - w];
        }
        x[i] -= acc;
    }
    for (xi, di) in x[..nb].iter_mut().zip(dinv) {
        *xi *= di;
    }
    for i in (0..nb).rev() {
        let row = &band[i * wp..i * wp + wp];
        let xi = x[i];
        for t in w.saturating_sub(i)..w {
            x[i + t - w] -= row[t] * xi;
        }
    }
}

/// Iterative refinement of `sol` (solved with the regularised factors `kkt`) against the
/// unregularised matrix `unreg`, until the residual is below [`IPM_REFINE_REL_TOL`] of the right-hand side
/// or `max_steps` steps, whichever first (a step that does not lower it ends it).
pub(super) fn refine(
    kkt: &BorderedBand,
    unreg: &BorderedBand,
    rhs: &[f64],
    sol: &mut [f64],
    tmp: &mut [f64],
    max_steps: u32,
) {
    let target = IPM_REFINE_REL_TOL * (1.0 + inf_norm(rhs));
    let mut last = f64::INFINITY;
    for _ in 0..max_steps {
        unreg.mul(sol, tmp);
        let mut res = 0.0f64;
        for (t, r) in tmp.iter_mut().zip(rhs) {
            *t = r - *t;
            res = res.max(t.abs());
        }
        if res <= target || res >= last {
            break;
        }
        last = res;
        kkt.solve(tmp);
        for (s, t) in sol.iter_mut().zip(tmp.iter()) {
            *s += t;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bordered banded factorisation solves random symmetric systems (positive
    /// definite band, an indefinite border) exactly, for every compiled width and a wider
    /// one, narrower than the width and not.
    #[test]
    fn bordered_band_solves_symmetric_systems() {
        let mut seed = 1u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for (nb, w, k) in [
            (30, 4, 2),
            (30, 6, 2),
            (5, 6, 2),
            (40, 3, 1),
            (40, 7, 0),
            (50, 16, 2),
            (60, 20, 2),
            (3, 2, 0),
        ] {
            let mut m = BorderedBand::new(nb, w, k);
            for i in 0..nb {
                m.add_sym(i, i, 4.0 + w as f64 * 0.5 + rnd());
                for d in 1..=w.min(i) {
                    m.add_sym(i, i - d, 0.3 * rnd());
                }
                for r in 0..k {
                    m.add_sym(nb + r, i, 0.2 * rnd());
                }
            }
            for r in 0..k {
                m.add_sym(nb + r, nb + r, if r % 2 == 0 { 6.0 } else { -6.0 });
            }
            let x: Vec<f64> = (0..nb + k).map(|_| rnd()).collect();
            let mut b = vec![0.0; nb + k];
            m.mul(&x, &mut b);
            // M·x against a dense product.
            for i in 0..nb {
                let mut acc = 0.0;
                for j in 0..nb {
                    let (a, c) = (i.max(j), i.min(j));
                    if a - c <= m.w {
                        acc += m.band[a * (m.w + 1) + c + m.w - a] * x[j];
                    }
                }
                for r in 0..k {
                    acc += m.border[r * nb + i] * x[nb + r];
                }
                assert!((acc - b[i]).abs() < 1e-12, "({nb}, {w}, {k}) row {i}");
            }
            assert!(m.factor());
            m.solve(&mut b);
            for (u, v) in b.iter().zip(&x) {
                assert!((u - v).abs() < 1e-10, "({nb}, {w}, {k}): {u} vs {v}");
            }
        }
    }
}
