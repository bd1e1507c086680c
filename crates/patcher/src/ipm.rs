//! A primal–dual interior-point method for the patcher's convex QPs, exploiting their
//! structure: every row of the Hermite forms touches the variables of two or three
//! neighbouring CL points, so with the variables ordered along the path the KKT matrix is
//! **banded**, apart from a few variables every row may touch (the epigraph `t` of the
//! largest deviation, the elastic `e`), kept as a dense **border**.
//!
//! # The problem
//!
//! ```text
//! minimise    ½·xᵀ·H·x + cᵀ·x
//! subject to  A·x = b          (equalities)
//!             G·x + s = h,  s ∈ K = ℝ₊^m × Q^{q_1} × … × Q^{q_p}
//! ```
//!
//! with H positive semidefinite and `Q^q = {(s_0, s_1) : s_0 ≥ ‖s_1‖}` second-order cones
//! (the minimax of orientation changes: `‖r_i‖ ≤ t`). Each variable has a position along the path
//! ([`Banded::position`]; `None` for a border variable).
//!
//! # The method (Mehrotra's predictor–corrector with Nesterov–Todd scaling)
//!
//! As in CVXOPT's `coneqp` (Vandenberghe, "The CVXOPT linear and quadratic cone program
//! solvers", 2010). With slacks `s ∈ K`, multipliers `y`, `z ∈ K`, residuals
//! `r_d = H·x + c + Aᵀ·y + Gᵀ·z`, `r_p = A·x − b`, `r_g = G·x + s − h`, `μ = sᵀz/ν` (ν: one
//! per linear row and per cone), and the scaling `W` with `W·z = W⁻ᵀ·s = λ` (diagonal
//! `√(s/z)` on the linear rows, the Nesterov–Todd matrix on a cone), each iteration solves
//! the Newton system twice with one factorisation, eliminating `ds` and `dz`
//! (`V = W⁻¹·W⁻ᵀ`, `u = λ \ (−r_c)` in the cone's Jordan algebra, `w = V·r_g + W⁻¹·u`):
//!
//! ```text
//! [ H + Gᵀ·V·G   Aᵀ ] [dx]   [ −r_d − Gᵀ·w ]
//! [ A             0 ] [dy] = [ −r_p         ]
//! dz = V·G·dx + w,    ds = −r_g − G·dx
//! ```
//!
//! first with `r_c = λ∘λ` (the affine step), then with
//! `r_c = λ∘λ + (W⁻ᵀ·ds_aff)∘(W·dz_aff) − σ·μ·e` and `σ = (μ_aff/μ)³`; the step keeps `s`
//! and `z` inside K ([`IpmSettings::step_fraction`] of the way to its boundary).
//!
//! # The linear algebra
//!
//! The unknowns `(x, y)` are ordered by position (each equality's multiplier right after
//! the last variable it touches), which makes the matrix above banded of half-bandwidth
//! `w` (about ten for the joint patch), plus `k` border rows and columns. It is regularised
//! (`+δ` on the variables, `−δ` on the multipliers: quasi-definite, so `L·D·Lᵀ` exists in any
//! order without pivoting), factored as a banded `L·D·Lᵀ` in `O(n·w²)` with the border by
//! its Schur complement, and every solve is refined against the unregularised matrix
//! ([`IpmSettings::refinement_steps`]). An iteration costs `O(n·w² + nnz(G)·r)` for `r` the
//! largest row length: linear in the number of CL points, where a general sparse solver
//! pays for its ordering and symbolic analysis on every call.

// Index loops mirror the factorisation's formulas (rows, columns, band offsets).
#![allow(clippy::needless_range_loop)]

use crate::qp::Row;

/// Settings of [`Banded::solve`]. Plain struct: public fields, documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IpmSettings {
    /// Most iterations. Default 60.
    pub max_iter: u32,
    /// Feasibility tolerance, relative to the data's size (`1 + ‖b‖∞`, `1 + ‖h‖∞`,
    /// `1 + ‖c‖∞`). Default 1e-8.
    pub tol_feas: f64,
    /// Complementarity tolerance on `μ`, relative to `1 + |objective|`. Default 1e-8.
    pub tol_gap: f64,
    /// Fraction of the way to the boundary of `s, z ≥ 0` a step goes. Default 0.99.
    pub step_fraction: f64,
    /// Static regularisation of the KKT matrix (`±δ`, on the equilibrated problem).
    /// Default 1e-9.
    pub regularisation: f64,
    /// Most iterative refinement steps per solve (it stops earlier when the residual is
    /// below 1e-13 of the right-hand side). Default 4.
    pub refinement_steps: u32,
}

impl Default for IpmSettings {
    fn default() -> Self {
        IpmSettings {
            max_iter: 60,
            tol_feas: 1e-8,
            tol_gap: 1e-8,
            step_fraction: 0.99,
            regularisation: 1e-9,
            refinement_steps: 4,
        }
    }
}

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpmStatus {
    /// Converged to the tolerances.
    Solved,
    /// Stopped at [`IpmSettings::max_iter`].
    MaxIterations,
    /// A pivot vanished or a value became non-finite.
    NumericalError,
}

/// A solve's result.
#[derive(Debug, Clone, PartialEq)]
pub struct IpmSolution {
    /// The primal solution.
    pub x: Vec<f64>,
    /// Status.
    pub status: IpmStatus,
    /// Iterations made.
    pub iterations: u32,
}

/// A QP with variables placed along the path (module docs).
#[derive(Debug, Clone, Default)]
pub struct Banded {
    n: usize,
    /// Position of each variable along the path; `None`: a border variable.
    pub position: Vec<Option<f64>>,
    /// Upper-or-lower triangle entries of H (`(i, j, v)`, each pair once; `i == j` on the
    /// diagonal).
    pub h: Vec<(usize, usize, f64)>,
    /// Linear objective.
    pub c: Vec<f64>,
    /// Equality rows `row·x = rhs`.
    pub eq: Vec<(Row, f64)>,
    /// Inequality rows `row·x ≤ rhs`.
    pub le: Vec<(Row, f64)>,
    /// Second-order cones: each block of rows `(row_k, rhs_k)` says
    /// `‖(rhs_k − row_k·x)_{k≥1}‖₂ ≤ rhs_0 − row_0·x` (at most [`MAX_CONE`] rows).
    pub soc: Vec<Vec<(Row, f64)>>,
}

/// The unknowns' order and the matrix shape, fixed for a problem.
struct Layout {
    /// Band index of each variable (`None`: border).
    var_band: Vec<Option<usize>>,
    /// Border index of each border variable.
    var_border: Vec<Option<usize>>,
    /// Band index of each equality's multiplier.
    eq_band: Vec<usize>,
    /// Band size, half-bandwidth, border size.
    nb: usize,
    w: usize,
    k: usize,
}

/// Where one unknown of the KKT system lives.
#[derive(Clone, Copy)]
enum Slot {
    Band(usize),
    Border(usize),
}

impl Layout {
    fn new(p: &Banded) -> Layout {
        let n = p.n;
        // Sort keys: a variable by its position; a multiplier right after the largest
        // position of its row's banded variables (or at the front when it has none).
        let mut keys: Vec<(f64, u8, usize)> = Vec::with_capacity(n + p.eq.len());
        let mut var_border = vec![None; n];
        let mut k = 0;
        for (j, pos) in p.position.iter().enumerate() {
            match pos {
                Some(v) => keys.push((*v, 0, j)),
                None => {
                    var_border[j] = Some(k);
                    k += 1;
                }
            }
        }
        for (r, (row, _)) in p.eq.iter().enumerate() {
            let at = row
                .iter()
                .filter_map(|&(j, _)| p.position[j])
                .fold(f64::NEG_INFINITY, f64::max);
            keys.push((at, 1, r));
        }
        keys.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut var_band = vec![None; n];
        let mut eq_band = vec![0; p.eq.len()];
        for (i, &(_, kind, idx)) in keys.iter().enumerate() {
            if kind == 0 {
                var_band[idx] = Some(i);
            } else {
                eq_band[idx] = i;
            }
        }
        let nb = keys.len();
        let mut l = Layout {
            var_band,
            var_border,
            eq_band,
            nb,
            w: 0,
            k,
        };
        // Half-bandwidth: the widest spread of band indices any block of the matrix
        // couples.
        let mut w = 0usize;
        let spread = |idx: &mut dyn Iterator<Item = usize>| {
            let (mut lo, mut hi) = (usize::MAX, 0usize);
            for i in idx {
                lo = lo.min(i);
                hi = hi.max(i);
            }
            if lo == usize::MAX { 0 } else { hi - lo }
        };
        for &(i, j, _) in &p.h {
            if let (Some(a), Some(b)) = (l.var_band[i], l.var_band[j]) {
                w = w.max(a.abs_diff(b));
            }
        }
        for (row, _) in &p.le {
            w = w.max(spread(&mut row.iter().filter_map(|&(j, _)| l.var_band[j])));
        }
        for cone in &p.soc {
            w = w.max(spread(
                &mut cone
                    .iter()
                    .flat_map(|(row, _)| row.iter())
                    .filter_map(|&(j, _)| l.var_band[j]),
            ));
        }
        for (r, (row, _)) in p.eq.iter().enumerate() {
            let m = l.eq_band[r];
            w = w.max(spread(
                &mut row
                    .iter()
                    .filter_map(|&(j, _)| l.var_band[j])
                    .chain(std::iter::once(m)),
            ));
        }
        l.w = w;
        l
    }

    fn var_slot(&self, j: usize) -> Slot {
        match self.var_band[j] {
            Some(b) => Slot::Band(b),
            None => Slot::Border(self.var_border[j].unwrap_or(0)),
        }
    }
}

/// A symmetric matrix: banded `nb × nb` (half-bandwidth `w`, lower part stored by
/// diagonals), a dense border `C` (`k × nb`) and corner `E` (`k × k`), factored in place.
struct BorderedBand {
    nb: usize,
    w: usize,
    k: usize,
    /// Row i's band from left to right: `band[i·(w+1) + t] = M[i][i + t − w]`
    /// (`t = w` is the diagonal; entries left of column 0 stay 0). After factoring, the
    /// unit L below the diagonal and D on it.
    band: Vec<f64>,
    /// `border[r·nb + i] = M[nb + r][i]`.
    border: Vec<f64>,
    /// `corner[r·k + q] = M[nb + r][nb + q]`.
    corner: Vec<f64>,
    /// After factoring: `Y = B⁻¹·Cᵀ` (column-major by border row: `y[r·nb + i]`).
    y: Vec<f64>,
    /// After factoring: the Schur complement's `L·D·Lᵀ` (dense, k × k).
    schur: Vec<f64>,
}

impl BorderedBand {
    fn new(nb: usize, w: usize, k: usize) -> BorderedBand {
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

    /// Add `v` at (a, b) and (b, a) of the symmetric matrix (once on the diagonal).
    fn add(&mut self, a: Slot, b: Slot, v: f64) {
        let mut at = Vec::with_capacity(2);
        self.dsts(a, b, &mut at);
        for i in at {
            self.add_flat(i, v);
        }
    }

    /// `M·x` (unfactored; call before [`BorderedBand::factor`] or on a copy).
    fn mul(&self, x: &[f64], out: &mut [f64]) {
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
    fn factor(&mut self) -> bool {
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
    fn band_solve(&self, x: &mut [f64]) {
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
    fn solve(&self, x: &mut [f64]) {
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

/// Iterative refinement of `sol` (solved with the regularised factors `kkt`) against the
/// unregularised matrix `unreg`, until the residual is below 1e-13 of the right-hand side
/// or `max_steps` steps, whichever first (a step that does not lower it ends it).
fn refine(
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

/// The largest second-order cone (rows) [`Banded::solve`] takes.
pub const MAX_CONE: usize = 8;

fn dot(row: &Row, x: &[f64]) -> f64 {
    row.iter().map(|&(j, v)| v * x[j]).sum()
}

fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// Nesterov–Todd scaling of one second-order cone block at `(s, z)` (both interior):
/// `W` (symmetric, q × q, row-major) with `W·z = W⁻¹·s = λ`, its inverse, and `λ`
/// (Vandenberghe, "The CVXOPT linear and quadratic cone program solvers", §4.2).
struct SocScaling {
    /// `W`, q × q row-major (first q² entries used).
    w: [f64; MAX_CONE * MAX_CONE],
    /// `W⁻¹`, likewise.
    winv: [f64; MAX_CONE * MAX_CONE],
    /// `λ` (first q entries).
    lambda: [f64; MAX_CONE],
}

fn soc_norm(v: &[f64]) -> f64 {
    let r = v[0] * v[0] - v[1..].iter().map(|x| x * x).sum::<f64>();
    r.max(0.0).sqrt()
}

fn soc_scaling(s: &[f64], z: &[f64]) -> SocScaling {
    let q = s.len();
    let (sn, zn) = (soc_norm(s), soc_norm(z));
    let (mut sb, mut zb) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
    for i in 0..q {
        sb[i] = s[i] / sn;
        zb[i] = z[i] / zn;
    }
    let gamma = ((1.0 + (0..q).map(|i| sb[i] * zb[i]).sum::<f64>()) / 2.0).sqrt();
    let mut wb = [0.0; MAX_CONE];
    wb[0] = (sb[0] + zb[0]) / (2.0 * gamma);
    for i in 1..q {
        wb[i] = (sb[i] - zb[i]) / (2.0 * gamma);
    }
    let eta = (sn / zn).sqrt();
    let mut w = [0.0; MAX_CONE * MAX_CONE];
    let mut winv = [0.0; MAX_CONE * MAX_CONE];
    w[0] = eta * wb[0];
    winv[0] = wb[0] / eta;
    for i in 1..q {
        w[i] = eta * wb[i];
        w[i * q] = eta * wb[i];
        winv[i] = -wb[i] / eta;
        winv[i * q] = -wb[i] / eta;
        for j in 1..q {
            let m = f64::from(u8::from(i == j)) + wb[i] * wb[j] / (1.0 + wb[0]);
            w[i * q + j] = eta * m;
            winv[i * q + j] = m / eta;
        }
    }
    let mut lambda = [0.0; MAX_CONE];
    for i in 0..q {
        lambda[i] = (0..q).map(|j| w[i * q + j] * z[j]).sum();
    }
    SocScaling { w, winv, lambda }
}

/// `u ∘ v` of the second-order cone's Jordan algebra: `(uᵀv, u0·v1 + v0·u1)`.
fn soc_prod(u: &[f64], v: &[f64], out: &mut [f64]) {
    out[0] = u.iter().zip(v).map(|(a, b)| a * b).sum();
    for i in 1..u.len() {
        out[i] = u[0] * v[i] + v[0] * u[i];
    }
}

/// The `u` with `λ ∘ u = r` (Jordan division; λ interior).
fn soc_div(lambda: &[f64], r: &[f64], out: &mut [f64]) {
    let l0 = lambda[0];
    let l1r1: f64 = lambda[1..].iter().zip(&r[1..]).map(|(a, b)| a * b).sum();
    let det = l0 * l0 - lambda[1..].iter().map(|x| x * x).sum::<f64>();
    let u0 = (l0 * r[0] - l1r1) / det;
    out[0] = u0;
    for i in 1..lambda.len() {
        out[i] = (r[i] - u0 * lambda[i]) / l0;
    }
}

/// The largest α ≤ `cap` with `v + α·d` in the (closed) second-order cone (v interior).
fn soc_step(v: &[f64], d: &[f64], cap: f64) -> f64 {
    let a = d[0] * d[0] - d[1..].iter().map(|x| x * x).sum::<f64>();
    let b = 2.0 * (v[0] * d[0] - v[1..].iter().zip(&d[1..]).map(|(x, y)| x * y).sum::<f64>());
    let c = (v[0] * v[0] - v[1..].iter().map(|x| x * x).sum::<f64>()).max(0.0);
    let mut alpha = cap;
    if d[0] < 0.0 {
        alpha = alpha.min(-v[0] / d[0]);
    }
    let disc = b * b - 4.0 * a * c;
    if a < 0.0 {
        // Concave: one positive root.
        let r = (-b - disc.max(0.0).sqrt()) / (2.0 * a);
        if r > 0.0 {
            alpha = alpha.min(r);
        }
    } else if a > 0.0 {
        if b < 0.0 && disc >= 0.0 {
            // Smallest positive root, computed without cancellation.
            let r = 2.0 * c / (-b + disc.sqrt());
            alpha = alpha.min(r);
        }
    } else if b < 0.0 {
        alpha = alpha.min(-c / b);
    }
    alpha.max(0.0)
}

/// One entry of a row with its place in the KKT system.
#[derive(Clone, Copy)]
struct Entry {
    var: usize,
    slot: Slot,
    v: f64,
}

/// The fixed shape of the KKT matrix of one problem, computed once per solve: where each
/// product of [`Banded::solve`]'s iteration matrix lands (flat indices into the
/// [`BorderedBand`]'s storage), so that an iteration only multiplies and adds.
struct Assembler {
    /// `H` and `A` (the parts that do not change), unregularised.
    base: BorderedBand,
    /// Linear row r's pairs `lp_ptr[r]..lp_ptr[r + 1]`: where `d_r·g_a·g_b` is added.
    lp_ptr: Vec<usize>,
    lp_dst: Vec<u32>,
    lp_coef: Vec<f64>,
    /// Per cone block: its variables' count, `G_c` (q × nv, row-major) and, for every
    /// pair `i ≤ j` of its variables in order, where `(G_cᵀ·V·G_c)_ij` is added
    /// (`pair_ptr` into `pair_dst`).
    cones: Vec<ConePattern>,
    /// The diagonal entries that get `+δ` (variables) and `−δ` (multipliers).
    reg_plus: Vec<u32>,
    reg_minus: Vec<u32>,
}

struct ConePattern {
    nv: usize,
    g: Vec<f64>,
    pair_ptr: Vec<usize>,
    pair_dst: Vec<u32>,
}

impl BorderedBand {
    /// The flat storage indices (band, then border, then corner) at which [`BorderedBand::add`]
    /// adds a value at `(a, b)`.
    fn dsts(&self, a: Slot, b: Slot, out: &mut Vec<u32>) {
        let nbw = self.band.len();
        let nbo = self.border.len();
        let idx = match (a, b) {
            (Slot::Band(i), Slot::Band(j)) => {
                let (i, j) = if i >= j { (i, j) } else { (j, i) };
                i * (self.w + 1) + (j + self.w - i)
            }
            (Slot::Border(r), Slot::Band(i)) | (Slot::Band(i), Slot::Border(r)) => {
                nbw + r * self.nb + i
            }
            (Slot::Border(r), Slot::Border(q)) => {
                if r != q {
                    out.push((nbw + nbo + q * self.k + r) as u32);
                }
                nbw + nbo + r * self.k + q
            }
        };
        out.push(idx as u32);
    }

    /// Add `v` at the flat storage index `i` ([`BorderedBand::dsts`]).
    #[inline]
    fn add_flat(&mut self, i: u32, v: f64) {
        let i = i as usize;
        let nbw = self.band.len();
        if i < nbw {
            self.band[i] += v;
        } else if i < nbw + self.border.len() {
            self.border[i - nbw] += v;
        } else {
            self.corner[i - nbw - self.border.len()] += v;
        }
    }

    /// Copy another matrix of the same shape.
    fn copy_from(&mut self, o: &BorderedBand) {
        self.band.copy_from_slice(&o.band);
        self.border.copy_from_slice(&o.border);
        self.corner.copy_from_slice(&o.corner);
    }
}

impl Assembler {
    fn new(p: &Banded, lay: &Layout, entries: &[Vec<Entry>], blocks: &[(usize, usize)]) -> Self {
        let mut base = BorderedBand::new(lay.nb, lay.w, lay.k);
        for &(i, j, v) in &p.h {
            base.add(lay.var_slot(i), lay.var_slot(j), v);
        }
        for (r, (row, _)) in p.eq.iter().enumerate() {
            for &(j, v) in row {
                base.add(Slot::Band(lay.eq_band[r]), lay.var_slot(j), v);
            }
        }
        let ml = entries.len() - blocks.iter().map(|b| b.1).sum::<usize>();
        let mut d = Vec::new();
        let (mut lp_ptr, mut lp_dst, mut lp_coef) = (vec![0], Vec::new(), Vec::new());
        for row in &entries[..ml] {
            for (a, ea) in row.iter().enumerate() {
                for eb in &row[a..] {
                    d.clear();
                    base.dsts(ea.slot, eb.slot, &mut d);
                    for &i in &d {
                        lp_dst.push(i);
                        lp_coef.push(ea.v * eb.v);
                    }
                }
            }
            lp_ptr.push(lp_dst.len());
        }
        let cones = blocks
            .iter()
            .map(|&(b0, q)| {
                let mut vars: Vec<Entry> = Vec::new();
                for r in b0..b0 + q {
                    for e in &entries[r] {
                        if !vars.iter().any(|c| c.var == e.var) {
                            vars.push(*e);
                        }
                    }
                }
                let nv = vars.len();
                let mut g = vec![0.0; q * nv];
                for (a, r) in (b0..b0 + q).enumerate() {
                    for e in &entries[r] {
                        let c = vars.iter().position(|c| c.var == e.var).unwrap_or(0);
                        g[a * nv + c] += e.v;
                    }
                }
                let (mut pair_ptr, mut pair_dst) = (vec![0], Vec::new());
                for i in 0..nv {
                    for j in i..nv {
                        base.dsts(vars[i].slot, vars[j].slot, &mut pair_dst);
                        pair_ptr.push(pair_dst.len());
                    }
                }
                ConePattern {
                    nv,
                    g,
                    pair_ptr,
                    pair_dst,
                }
            })
            .collect();
        let (mut reg_plus, mut reg_minus) = (Vec::new(), Vec::new());
        for j in 0..p.n {
            let sl = lay.var_slot(j);
            base.dsts(sl, sl, &mut reg_plus);
        }
        for r in 0..p.eq.len() {
            let sl = Slot::Band(lay.eq_band[r]);
            base.dsts(sl, sl, &mut reg_minus);
        }
        Assembler {
            base,
            lp_ptr,
            lp_dst,
            lp_coef,
            cones,
            reg_plus,
            reg_minus,
        }
    }

    /// The KKT matrix `[H + Gᵀ·V·G, Aᵀ; A, 0]` into `unreg`, and regularised (`±δ`) into
    /// `kkt`: `V` is `d_lp` on the linear rows, `v_cone[b]` (q × q) on cone block b.
    fn assemble(
        &self,
        d_lp: &[f64],
        v_cone: &[Vec<f64>],
        delta: f64,
        kkt: &mut BorderedBand,
        unreg: &mut BorderedBand,
        vg: &mut Vec<f64>,
    ) {
        unreg.copy_from(&self.base);
        for (r, &d) in d_lp.iter().enumerate() {
            let (a, b) = (self.lp_ptr[r], self.lp_ptr[r + 1]);
            for (&i, &c) in self.lp_dst[a..b].iter().zip(&self.lp_coef[a..b]) {
                unreg.add_flat(i, d * c);
            }
        }
        for (cp, v) in self.cones.iter().zip(v_cone) {
            let nv = cp.nv;
            let q = cp.g.len() / nv.max(1);
            // V·G_c (q × nv), then G_cᵀ·(V·G_c) on the pairs i ≤ j.
            vg.clear();
            vg.resize(q * nv, 0.0);
            for a in 0..q {
                for b in 0..q {
                    let vab = v[a * q + b];
                    if vab == 0.0 {
                        continue;
                    }
                    for j in 0..nv {
                        vg[a * nv + j] += vab * cp.g[b * nv + j];
                    }
                }
            }
            let mut pair = 0;
            for i in 0..nv {
                for j in i..nv {
                    let mut acc = 0.0;
                    for a in 0..q {
                        acc += cp.g[a * nv + i] * vg[a * nv + j];
                    }
                    if acc != 0.0 {
                        for &dst in &cp.pair_dst[cp.pair_ptr[pair]..cp.pair_ptr[pair + 1]] {
                            unreg.add_flat(dst, acc);
                        }
                    }
                    pair += 1;
                }
            }
        }
        kkt.copy_from(unreg);
        for &i in &self.reg_plus {
            kkt.add_flat(i, delta);
        }
        for &i in &self.reg_minus {
            kkt.add_flat(i, -delta);
        }
    }
}

impl Banded {
    /// An empty problem in `n` variables, all in the band at position 0.
    pub fn new(n: usize) -> Banded {
        Banded {
            n,
            position: vec![Some(0.0); n],
            h: Vec::new(),
            c: vec![0.0; n],
            eq: Vec::new(),
            le: Vec::new(),
            soc: Vec::new(),
        }
    }

    /// Number of variables.
    pub fn vars(&self) -> usize {
        self.n
    }

    fn h_mul(&self, x: &[f64], out: &mut [f64]) {
        for &(i, j, v) in &self.h {
            out[i] += v * x[j];
            if i != j {
                out[j] += v * x[i];
            }
        }
    }

    /// Solve from the primal point `x0` (any point; feasibility is not required).
    ///
    /// The problem is equilibrated first: every row (every cone's rows together) divided
    /// by its largest coefficient, the objective by its largest one. Neither changes the
    /// solution, and the tolerances then mean the same on every row.
    pub fn solve(&self, x0: &[f64], st: &IpmSettings) -> IpmSolution {
        let scale_row = |(row, rhs): &(Row, f64)| -> (Row, f64) {
            let m = row.iter().fold(0.0f64, |m, e| m.max(e.1.abs()));
            if m > 0.0 && m.is_finite() {
                (row.iter().map(|&(j, v)| (j, v / m)).collect(), rhs / m)
            } else {
                (row.clone(), *rhs)
            }
        };
        let obj = self
            .c
            .iter()
            .map(|v| v.abs())
            .chain(self.h.iter().map(|e| e.2.abs()))
            .fold(0.0f64, f64::max);
        let obj = if obj > 0.0 && obj.is_finite() {
            obj
        } else {
            1.0
        };
        let scaled = Banded {
            n: self.n,
            position: self.position.clone(),
            h: self.h.iter().map(|&(i, j, v)| (i, j, v / obj)).collect(),
            c: self.c.iter().map(|v| v / obj).collect(),
            eq: self.eq.iter().map(scale_row).collect(),
            le: self.le.iter().map(scale_row).collect(),
            soc: self
                .soc
                .iter()
                .map(|cone| {
                    let m = cone
                        .iter()
                        .flat_map(|(row, _)| row.iter())
                        .fold(0.0f64, |m, e| m.max(e.1.abs()));
                    let m = if m > 0.0 && m.is_finite() { m } else { 1.0 };
                    cone.iter()
                        .map(|(row, rhs)| (row.iter().map(|&(j, v)| (j, v / m)).collect(), rhs / m))
                        .collect()
                })
                .collect(),
        };
        scaled.solve_scaled(x0, st)
    }

    fn solve_scaled(&self, x0: &[f64], st: &IpmSettings) -> IpmSolution {
        assert!(
            self.soc.iter().all(|c| (2..=MAX_CONE).contains(&c.len())),
            "second-order cones have 2 to {MAX_CONE} rows"
        );
        let n = self.n;
        let me = self.eq.len();
        let ml = self.le.len();
        // Every cone row after the linear rows: rows[ml..], blocks of `soc` sizes.
        let rows: Vec<&(Row, f64)> = self.le.iter().chain(self.soc.iter().flatten()).collect();
        let mi = rows.len();
        let mut blocks: Vec<(usize, usize)> = Vec::with_capacity(self.soc.len());
        let mut at = ml;
        for cone in &self.soc {
            blocks.push((at, cone.len()));
            at += cone.len();
        }
        let degree = (ml + blocks.len()).max(1) as f64;
        let lay = Layout::new(self);
        let nk = lay.nb + lay.k;
        let slot_index = |sl: Slot| match sl {
            Slot::Band(i) => i,
            Slot::Border(r) => lay.nb + r,
        };
        let entries: Vec<Vec<Entry>> = rows
            .iter()
            .map(|(row, _)| {
                row.iter()
                    .map(|&(j, v)| Entry {
                        var: j,
                        slot: lay.var_slot(j),
                        v,
                    })
                    .collect()
            })
            .collect();
        let x_at: Vec<usize> = (0..n).map(|j| slot_index(lay.var_slot(j))).collect();
        let mut kkt = BorderedBand::new(lay.nb, lay.w, lay.k);
        let mut unreg = BorderedBand::new(lay.nb, lay.w, lay.k);
        let delta = st.regularisation;
        let asm = Assembler::new(self, &lay, &entries, &blocks);
        // The rows of G flat (compressed rows), for the products with G and Gᵀ.
        let mut ent_ptr: Vec<usize> = Vec::with_capacity(mi + 1);
        let (mut ent_var, mut ent_v): (Vec<u32>, Vec<f64>) = (Vec::new(), Vec::new());
        ent_ptr.push(0);
        for row in &entries {
            for e in row {
                ent_var.push(e.var as u32);
                ent_v.push(e.v);
            }
            ent_ptr.push(ent_var.len());
        }
        let mut gtw = vec![0.0; n];
        let mut vg: Vec<f64> = Vec::new();
        let mut d_lp = vec![1.0; ml];
        let mut d_sqrt = vec![1.0; ml];
        let mut v_cone: Vec<Vec<f64>> = blocks
            .iter()
            .map(|&(_, q)| {
                (0..q * q)
                    .map(|i| f64::from(u8::from(i % (q + 1) == 0)))
                    .collect()
            })
            .collect();
        let (mut rhs, mut sol, mut tmp) = (vec![0.0; nk], vec![0.0; nk], vec![0.0; nk]);
        // Start (CVXOPT's): x̂ minimising ½xᵀHx + cᵀx + ½‖G·x − h‖² with A·x = b, then
        // ŝ = h − G·x̂ and ẑ = −ŝ, each moved into the cones' interiors.
        asm.assemble(&d_lp, &v_cone, delta, &mut kkt, &mut unreg, &mut vg);
        let mut x = x0.to_vec();
        if kkt.factor() {
            for j in 0..n {
                rhs[x_at[j]] = -self.c[j];
            }
            for (r, (_, h)) in rows.iter().enumerate() {
                for e in &entries[r] {
                    rhs[x_at[e.var]] += e.v * h;
                }
            }
            for (r, (_, b)) in self.eq.iter().enumerate() {
                rhs[lay.eq_band[r]] = *b;
            }
            sol.copy_from_slice(&rhs);
            kkt.solve(&mut sol);
            refine(&kkt, &unreg, &rhs, &mut sol, &mut tmp, st.refinement_steps);
            if sol.iter().all(|v| v.is_finite()) {
                x = (0..n).map(|j| sol[x_at[j]]).collect();
            }
        }
        let _ = x0;
        let mut y = vec![0.0; me];
        let mut s: Vec<f64> = rows.iter().map(|(row, rhs)| rhs - dot(row, &x)).collect();
        let mut z: Vec<f64> = s.iter().map(|v| -v).collect();
        // Shift into the interior: by 1 + the distance outside (the largest violation).
        let outside = |v: &[f64]| -> f64 {
            let mut a = f64::NEG_INFINITY;
            for r in 0..ml {
                a = a.max(-v[r]);
            }
            for &(b0, q) in &blocks {
                let tail = v[b0 + 1..b0 + q].iter().map(|t| t * t).sum::<f64>().sqrt();
                a = a.max(tail - v[b0]);
            }
            a
        };
        for v in [&mut s, &mut z] {
            let a = outside(v);
            if a >= -1e-8 || !a.is_finite() {
                let shift = if a.is_finite() { 1.0 + a } else { 1.0 };
                for r in 0..ml {
                    v[r] += shift;
                }
                for &(b0, _) in &blocks {
                    v[b0] += shift;
                }
            }
        }
        let scale_b = 1.0 + self.eq.iter().fold(0.0f64, |m, e| m.max(e.1.abs()));
        let scale_h = 1.0 + rows.iter().fold(0.0f64, |m, e| m.max(e.1.abs()));
        let scale_c = 1.0 + inf_norm(&self.c);
        let (mut rd, mut rp, mut rg, mut hx) =
            (vec![0.0; n], vec![0.0; me], vec![0.0; mi], vec![0.0; n]);
        // Per-row scaling data: LP rows `V = z/s`, `W⁻¹ = sqrt(z/s)`; cones their matrices.
        let mut scal: Vec<SocScaling> = Vec::with_capacity(blocks.len());
        let mut lam = vec![0.0; mi];
        let (mut u, mut w_r, mut dz, mut ds, mut gdx) = (
            vec![0.0; mi],
            vec![0.0; mi],
            vec![0.0; mi],
            vec![0.0; mi],
            vec![0.0; mi],
        );
        let (mut dz_a, mut ds_a, mut rc) = (vec![0.0; mi], vec![0.0; mi], vec![0.0; mi]);
        let mut dxy: Vec<f64> = Vec::with_capacity(n + me);
        for it in 0..st.max_iter {
            // Residuals.
            rd.copy_from_slice(&self.c);
            hx.iter_mut().for_each(|v| *v = 0.0);
            self.h_mul(&x, &mut hx);
            for j in 0..n {
                rd[j] += hx[j];
            }
            for (r, (row, _)) in self.eq.iter().enumerate() {
                for &(j, v) in row {
                    rd[j] += v * y[r];
                }
            }
            for r in 0..mi {
                let mut g = 0.0;
                let zr = z[r];
                for k in ent_ptr[r]..ent_ptr[r + 1] {
                    let (j, v) = (ent_var[k] as usize, ent_v[k]);
                    g += v * x[j];
                    rd[j] += v * zr;
                }
                rg[r] = g + s[r] - rows[r].1;
            }
            for (r, (row, rhs_r)) in self.eq.iter().enumerate() {
                rp[r] = dot(row, &x) - rhs_r;
            }
            let mu = s.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>() / degree;
            let obj = 0.5 * hx.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>()
                + self.c.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>();
            if !(obj.is_finite() && mu.is_finite()) {
                return IpmSolution {
                    x,
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            if inf_norm(&rp) <= st.tol_feas * scale_b
                && inf_norm(&rg) <= st.tol_feas * scale_h
                && inf_norm(&rd) <= st.tol_feas * scale_c
                && mu <= st.tol_gap * (1.0 + obj.abs())
            {
                return IpmSolution {
                    x,
                    status: IpmStatus::Solved,
                    iterations: it,
                };
            }
            // Scalings.
            for r in 0..ml {
                lam[r] = (s[r] * z[r]).sqrt();
            }
            scal.clear();
            for &(b0, q) in &blocks {
                let sc = soc_scaling(&s[b0..b0 + q], &z[b0..b0 + q]);
                lam[b0..b0 + q].copy_from_slice(&sc.lambda[..q]);
                scal.push(sc);
            }
            // The matrix: H + Gᵀ·V·G on the variables, A and Aᵀ, regularised.
            for r in 0..ml {
                d_lp[r] = z[r] / s[r];
                d_sqrt[r] = d_lp[r].sqrt();
            }
            for (bi, &(_, q)) in blocks.iter().enumerate() {
                // V = W⁻¹·W⁻¹ (symmetric).
                let wi = &scal[bi].winv;
                let v = &mut v_cone[bi];
                for a in 0..q {
                    for b in 0..q {
                        v[a * q + b] = (0..q).map(|m| wi[a * q + m] * wi[m * q + b]).sum();
                    }
                }
            }
            asm.assemble(&d_lp, &v_cone, delta, &mut kkt, &mut unreg, &mut vg);
            if !kkt.factor() {
                return IpmSolution {
                    x,
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            // One Newton solve for the complementarity residual `rc` (module docs, with
            // u = λ \ (−r_c), w = V·r_g + W⁻¹·u): the steps dx, dy, dz, ds.
            let mut newton = |rc: &[f64], dz: &mut [f64], ds: &mut [f64], dxy: &mut Vec<f64>| {
                for r in 0..ml {
                    u[r] = -rc[r] / lam[r];
                    // V·r_g + W⁻¹·u with V = z/s, W⁻¹ = sqrt(z/s).
                    w_r[r] = d_lp[r] * rg[r] + d_sqrt[r] * u[r];
                }
                for (bi, &(b0, q)) in blocks.iter().enumerate() {
                    let mut neg = [0.0; MAX_CONE];
                    for (d, v) in neg.iter_mut().zip(&rc[b0..b0 + q]) {
                        *d = -v;
                    }
                    soc_div(&lam[b0..b0 + q], &neg[..q], &mut u[b0..b0 + q]);
                    let wi = &scal[bi].winv;
                    // W⁻¹·(W⁻¹·r_g + u).
                    let mut t = [0.0; MAX_CONE];
                    for a in 0..q {
                        t[a] = (0..q).map(|m| wi[a * q + m] * rg[b0 + m]).sum::<f64>() + u[b0 + a];
                    }
                    for a in 0..q {
                        w_r[b0 + a] = (0..q).map(|m| wi[a * q + m] * t[m]).sum();
                    }
                }
                rhs.iter_mut().for_each(|v| *v = 0.0);
                gtw.iter_mut().for_each(|v| *v = 0.0);
                for r in 0..mi {
                    let wr = w_r[r];
                    for k in ent_ptr[r]..ent_ptr[r + 1] {
                        gtw[ent_var[k] as usize] += ent_v[k] * wr;
                    }
                }
                for j in 0..n {
                    rhs[x_at[j]] = -rd[j] - gtw[j];
                }
                for r in 0..me {
                    rhs[lay.eq_band[r]] = -rp[r];
                }
                sol.copy_from_slice(&rhs);
                kkt.solve(&mut sol);
                refine(&kkt, &unreg, &rhs, &mut sol, &mut tmp, st.refinement_steps);
                dxy.clear();
                dxy.extend((0..n).map(|j| sol[x_at[j]]));
                dxy.extend((0..me).map(|r| sol[lay.eq_band[r]]));
                for r in 0..mi {
                    gdx[r] = (ent_ptr[r]..ent_ptr[r + 1])
                        .map(|k| ent_v[k] * dxy[ent_var[k] as usize])
                        .sum();
                    ds[r] = -rg[r] - gdx[r];
                }
                for r in 0..ml {
                    dz[r] = d_lp[r] * gdx[r] + w_r[r];
                }
                for (bi, &(b0, q)) in blocks.iter().enumerate() {
                    let wi = &scal[bi].winv;
                    let mut t = [0.0; MAX_CONE];
                    for a in 0..q {
                        t[a] = (0..q).map(|m| wi[a * q + m] * gdx[b0 + m]).sum();
                    }
                    for a in 0..q {
                        dz[b0 + a] =
                            (0..q).map(|m| wi[a * q + m] * t[m]).sum::<f64>() + w_r[b0 + a];
                    }
                }
            };
            let max_step = |v: &[f64], dv: &[f64]| -> f64 {
                let mut a = f64::INFINITY;
                for r in 0..ml {
                    if dv[r] < 0.0 {
                        a = a.min(-v[r] / dv[r]);
                    }
                }
                for &(b0, q) in &blocks {
                    a = soc_step(&v[b0..b0 + q], &dv[b0..b0 + q], a);
                }
                a
            };
            // Predictor: r_c = λ∘λ.
            for r in 0..ml {
                rc[r] = lam[r] * lam[r];
            }
            for &(b0, q) in &blocks {
                let mut l = [0.0; MAX_CONE];
                l[..q].copy_from_slice(&lam[b0..b0 + q]);
                soc_prod(&l[..q], &l[..q], &mut rc[b0..b0 + q]);
            }
            newton(&rc, &mut dz_a, &mut ds_a, &mut dxy);
            let a_aff = max_step(&s, &ds_a).min(max_step(&z, &dz_a)).min(1.0);
            let mu_aff = (0..mi)
                .map(|r| (s[r] + a_aff * ds_a[r]) * (z[r] + a_aff * dz_a[r]))
                .sum::<f64>()
                / degree;
            let sigma = if mu > 0.0 {
                (mu_aff / mu).powi(3).min(1.0)
            } else {
                0.0
            };
            // Corrector: r_c = λ∘λ + (W⁻ᵀ·ds_a)∘(W·dz_a) − σ·μ·e.
            for r in 0..ml {
                rc[r] = lam[r] * lam[r] + ds_a[r] * dz_a[r] - sigma * mu;
            }
            for (bi, &(b0, q)) in blocks.iter().enumerate() {
                let (w, wi) = (&scal[bi].w, &scal[bi].winv);
                let (mut sd, mut zd) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
                for a in 0..q {
                    sd[a] = (0..q).map(|m| wi[a * q + m] * ds_a[b0 + m]).sum();
                    zd[a] = (0..q).map(|m| w[a * q + m] * dz_a[b0 + m]).sum();
                }
                let mut l = [0.0; MAX_CONE];
                l[..q].copy_from_slice(&lam[b0..b0 + q]);
                let (mut ll, mut sz) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
                soc_prod(&l[..q], &l[..q], &mut ll[..q]);
                soc_prod(&sd[..q], &zd[..q], &mut sz[..q]);
                for a in 0..q {
                    rc[b0 + a] = ll[a] + sz[a];
                }
                rc[b0] -= sigma * mu;
            }
            newton(&rc, &mut dz, &mut ds, &mut dxy);
            let alpha = (st.step_fraction * max_step(&s, &ds).min(max_step(&z, &dz))).min(1.0);
            if !(alpha.is_finite() && dxy.iter().all(|v| v.is_finite())) {
                return IpmSolution {
                    x,
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            for j in 0..n {
                x[j] += alpha * dxy[j];
            }
            for r in 0..me {
                y[r] += alpha * dxy[n + r];
            }
            for r in 0..mi {
                s[r] += alpha * ds[r];
                z[r] += alpha * dz[r];
            }
            for r in 0..ml {
                s[r] = s[r].max(1e-300);
                z[r] = z[r].max(1e-300);
            }
        }
        IpmSolution {
            x,
            status: IpmStatus::MaxIterations,
            iterations: st.max_iter,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// minimise (x0 − 1)² + (x1 − 2)² s.t. x0 + x1 = 1, x1 ≤ 0.5 → (0.5, 0.5).
    #[test]
    fn planted_qp_with_equality_and_bound() {
        let mut p = Banded::new(2);
        p.position = vec![Some(0.0), Some(1.0)];
        p.h = vec![(0, 0, 2.0), (1, 1, 2.0)];
        p.c = vec![-2.0, -4.0];
        p.eq.push((vec![(0, 1.0), (1, 1.0)], 1.0));
        p.le.push((vec![(1, 1.0)], 0.5));
        let r = p.solve(&[0.0, 0.0], &IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        assert!(
            (r.x[0] - 0.5).abs() < 1e-7 && (r.x[1] - 0.5).abs() < 1e-7,
            "{r:?}"
        );
    }

    /// A planted minimax with a border variable: minimise t s.t. |x_i − a_i| ≤ t and a
    /// chain of equalities x_{i+1} − x_i = 1 along the band: the answer is the half range
    /// of a_i − i.
    #[test]
    fn planted_minimax_with_a_border() {
        let n = 40;
        let a: Vec<f64> = (0..n).map(|i| i as f64 + (i as f64 * 0.7).sin()).collect();
        let mut p = Banded::new(n + 1);
        for i in 0..n {
            p.position[i] = Some(i as f64);
        }
        p.position[n] = None;
        p.c[n] = 1.0;
        for i in 0..n - 1 {
            p.eq.push((vec![(i + 1, 1.0), (i, -1.0)], 1.0));
        }
        for (i, ai) in a.iter().enumerate() {
            p.le.push((vec![(i, 1.0), (n, -1.0)], *ai));
            p.le.push((vec![(i, -1.0), (n, -1.0)], -ai));
        }
        let r = p.solve(&vec![0.0; n + 1], &IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        let d: Vec<f64> = a.iter().enumerate().map(|(i, v)| v - i as f64).collect();
        let (lo, hi) = d
            .iter()
            .fold((f64::MAX, f64::MIN), |m, v| (m.0.min(*v), m.1.max(*v)));
        assert!(
            (r.x[n] - 0.5 * (hi - lo)).abs() < 1e-6,
            "{} vs {}",
            r.x[n],
            0.5 * (hi - lo)
        );
        assert!(r.iterations < 40, "{}", r.iterations);
    }

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
            m.add(Slot::Band(i), Slot::Band(i), sign * (4.0 + rnd()));
            for d in 1..=w.min(i) {
                m.add(Slot::Band(i), Slot::Band(i - d), 0.3 * rnd());
            }
            for r in 0..k {
                m.add(Slot::Border(r), Slot::Band(i), 0.2 * rnd());
            }
        }
        for r in 0..k {
            m.add(Slot::Border(r), Slot::Border(r), 6.0);
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

    /// Nesterov–Todd scaling: `W·z = W⁻¹·s = λ`, `W·W⁻¹ = I`, on random interior points;
    /// Jordan division inverts the product.
    #[test]
    fn nesterov_todd_scaling_identities() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for _ in 0..50 {
            let mut s = [0.0, rnd(), rnd()];
            let mut z = [0.0, rnd(), rnd()];
            s[0] = (s[1] * s[1] + s[2] * s[2]).sqrt() + 0.1 + rnd().abs();
            z[0] = (z[1] * z[1] + z[2] * z[2]).sqrt() + 0.1 + rnd().abs();
            let sc = soc_scaling(&s, &z);
            let mul = |m: &[f64], v: &[f64]| -> Vec<f64> {
                (0..3)
                    .map(|a| (0..3).map(|b| m[a * 3 + b] * v[b]).sum())
                    .collect()
            };
            let (wz, wis) = (mul(&sc.w, &z), mul(&sc.winv, &s));
            for a in 0..3 {
                assert!(
                    (wz[a] - sc.lambda[a]).abs() < 1e-10,
                    "{wz:?} {:?}",
                    sc.lambda
                );
                assert!(
                    (wis[a] - sc.lambda[a]).abs() < 1e-10,
                    "{wis:?} {:?}",
                    sc.lambda
                );
                for b in 0..3 {
                    let id: f64 = (0..3).map(|m| sc.w[a * 3 + m] * sc.winv[m * 3 + b]).sum();
                    assert!((id - f64::from(u8::from(a == b))).abs() < 1e-10);
                }
            }
            let r = [rnd(), rnd(), rnd()];
            let mut u = [0.0; 3];
            soc_div(&sc.lambda[..3], &r, &mut u);
            let mut back = [0.0; 3];
            soc_prod(&sc.lambda[..3], &u, &mut back);
            for a in 0..3 {
                assert!((back[a] - r[a]).abs() < 1e-9);
            }
            // The cone step lands on the boundary (or is not limited).
            let d = [rnd() * 5.0, rnd() * 5.0, rnd() * 5.0];
            let al = soc_step(&s, &d, 1e6);
            let v: Vec<f64> = (0..3).map(|a| s[a] + al * d[a]).collect();
            assert!(
                v[0] >= -1e-9
                    && v[0] * v[0] - v[1] * v[1] - v[2] * v[2] >= -1e-7 * (1.0 + v[0] * v[0])
            );
            if al < 1e6 {
                let w: Vec<f64> = (0..3).map(|a| s[a] + 1.001 * al * d[a]).collect();
                assert!(w[0] < 0.0 || w[0] * w[0] - w[1] * w[1] - w[2] * w[2] < 0.0);
            }
        }
    }

    /// Planted SOCP: minimise t s.t. ‖(x0 − 3, x1 − 4)‖ ≤ t, x0 + x1 = 0 → the distance
    /// from (3, 4) to the line x0 + x1 = 0 is 7/√2, at (−0.5, 0.5).
    #[test]
    fn planted_second_order_cone() {
        let mut p = Banded::new(3);
        p.position = vec![Some(0.0), Some(0.0), None];
        p.c[2] = 1.0;
        p.eq.push((vec![(0, 1.0), (1, 1.0)], 0.0));
        p.soc.push(vec![
            (vec![(2, -1.0)], 0.0),
            (vec![(0, 1.0)], 3.0),
            (vec![(1, 1.0)], 4.0),
        ]);
        let r = p.solve(&[0.0; 3], &IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        assert!((r.x[2] - 7.0 / 2f64.sqrt()).abs() < 1e-6, "{r:?}");
        assert!(
            (r.x[0] + 0.5).abs() < 1e-5 && (r.x[1] - 0.5).abs() < 1e-5,
            "{r:?}"
        );
    }

    /// A planted minimax of distances in the plane along a band (Weber-like): the point
    /// chain x_{i+1} − x_i = (1, 0) that comes closest, in the largest Euclidean distance,
    /// to scattered targets: the answer is the smallest enclosing circle of the targets
    /// shifted back by i — checked against a brute-force grid search.
    #[test]
    fn planted_chain_minimax_of_distances() {
        let n = 12;
        let targets: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let t = i as f64;
                [t + (t * 1.3).sin(), (t * 0.7).cos()]
            })
            .collect();
        // Variables: (x_i, y_i) interleaved, then t.
        let mut p = Banded::new(2 * n + 1);
        for i in 0..n {
            p.position[2 * i] = Some(i as f64);
            p.position[2 * i + 1] = Some(i as f64);
        }
        p.position[2 * n] = None;
        p.c[2 * n] = 1.0;
        for i in 0..n - 1 {
            p.eq.push((vec![(2 * i + 2, 1.0), (2 * i, -1.0)], 1.0));
            p.eq.push((vec![(2 * i + 3, 1.0), (2 * i + 1, -1.0)], 0.0));
        }
        for (i, tg) in targets.iter().enumerate() {
            p.soc.push(vec![
                (vec![(2 * n, -1.0)], 0.0),
                (vec![(2 * i, 1.0)], tg[0]),
                (vec![(2 * i + 1, 1.0)], tg[1]),
            ]);
        }
        let r = p.solve(&vec![0.0; 2 * n + 1], &IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        // Brute force over the chain's start (x0, y0).
        let worst = |x0: f64, y0: f64| {
            targets
                .iter()
                .enumerate()
                .map(|(i, t)| ((x0 + i as f64 - t[0]).powi(2) + (y0 - t[1]).powi(2)).sqrt())
                .fold(0.0f64, f64::max)
        };
        let mut best = f64::INFINITY;
        for a in 0..400 {
            for b in 0..400 {
                best = best.min(worst(-2.0 + a as f64 * 0.01, -2.0 + b as f64 * 0.01));
            }
        }
        assert!(
            r.x[2 * n] <= best + 1e-6 && r.x[2 * n] > best - 0.02,
            "{} vs {best}",
            r.x[2 * n]
        );
        assert!((worst(r.x[0], r.x[1]) - r.x[2 * n]).abs() < 1e-6);
    }
}
