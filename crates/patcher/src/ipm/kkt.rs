//! The KKT system of one problem: the products with `G` and `Gᵀ` and the assembly of
//! `H + Gᵀ·V·G` into the bordered band matrix, from the problem's rows as they are
//! (each pair's band row once for both its sides).
//!
//! Slack order: pair p's upper side at `2p`, its lower side at `2p + 1`, then the
//! one-sided rows, then every cone's rows.

// Index loops mirror the assembly's formulas.
#![allow(clippy::needless_range_loop)]

use super::band::BorderedBand;
use super::cones::{MAX_CONE, SocScaling};
use super::problem::Problem;

/// One cone's rows gathered densely over the unknowns they touch.
pub(super) struct ConeRows {
    /// First slack index and number of rows.
    pub(super) b0: usize,
    pub(super) q: usize,
    /// The band unknowns the rows touch (sorted).
    vars: Vec<u32>,
    /// `g[a·(nv + k) + j]`: row a's coefficient of `vars[j]` (j < nv) or of border
    /// unknown `j − nv`.
    g: Vec<f64>,
}

/// The structure of one (equilibrated) problem's KKT system.
pub(super) struct Kkt<'a> {
    pub(super) p: &'a Problem,
    pub(super) nb: usize,
    pub(super) k: usize,
    /// Slacks of the pairs (2 each) and of the one-sided rows: the linear part.
    pub(super) ml: usize,
    /// All slacks.
    pub(super) mi: usize,
    pub(super) cones: Vec<ConeRows>,
    /// The right-hand sides of all slacks (`h`).
    pub(super) h: Vec<f64>,
    /// The pairs' band rows padded to [`PW`] entries (a padding entry: the row's last
    /// unknown with coefficient 0), when every pair has at most `PW`; else `None` and the
    /// compressed rows are used.
    fixed: Option<FixedRows>,
    /// The cones as discs, when every cone is one: three rows, the first on border
    /// unknowns only (`‖(u, v)‖ ≤ c·x_border`), the other two on at most [`DW`] band
    /// unknowns together (the joint patch's `‖E·r_i‖ ≤ t`).
    discs: Option<Discs>,
}

/// The width of a disc's band rows (their common unknowns, padded like the pairs).
const DW: usize = 8;

/// Cones `‖(h1 − u·x, h2 − v·x)‖ ≤ h0 − c·x_border` (module docs of [`Kkt`]).
struct Discs {
    idx: Vec<[u32; DW]>,
    u: Vec<[f64; DW]>,
    v: Vec<[f64; DW]>,
    /// Row 0's border coefficients, `k` per cone.
    c: Vec<f64>,
}

/// The pairs' band rows padded to [`PW`] entries: unknowns and coefficients.
type FixedRows = (Vec<[u32; PW]>, Vec<[f64; PW]>);

/// The width the pairs' rows are padded to (the joint patch's rows touch at most four
/// coefficients of one axis).
const PW: usize = 4;

impl<'a> Kkt<'a> {
    pub(super) fn new(p: &'a Problem) -> Kkt<'a> {
        let (nb, k) = (p.nb, p.k);
        let ml = 2 * p.pairs() + p.ones();
        let mut cones = Vec::with_capacity(p.cones());
        for c in 0..p.cones() {
            let (r0, r1) = (p.cone_ptr[c] as usize, p.cone_ptr[c + 1] as usize);
            let q = r1 - r0;
            let mut vars: Vec<u32> =
                p.crow_idx[p.crow_ptr[r0] as usize..p.crow_ptr[r1] as usize].to_vec();
            vars.sort_unstable();
            vars.dedup();
            let nt = vars.len() + k;
            let mut g = vec![0.0; q * nt];
            for (a, r) in (r0..r1).enumerate() {
                for e in p.crow_ptr[r] as usize..p.crow_ptr[r + 1] as usize {
                    let j = vars.binary_search(&p.crow_idx[e]).unwrap_or(0);
                    g[a * nt + j] += p.crow_val[e];
                }
                for b in 0..k {
                    g[a * nt + vars.len() + b] += p.crow_border[r * k + b];
                }
            }
            cones.push(ConeRows {
                b0: ml + r0,
                q,
                vars,
                g,
            });
        }
        let mut h = Vec::with_capacity(ml + p.crow_rhs.len());
        for q in 0..p.pairs() {
            h.push(p.pair_hi[q]);
            h.push(-p.pair_lo[q]);
        }
        h.extend_from_slice(&p.one_rhs);
        h.extend_from_slice(&p.crow_rhs);
        let fits = (0..p.pairs()).all(|q| p.pair_ptr[q + 1] - p.pair_ptr[q] <= PW as u32);
        let fixed = fits.then(|| {
            (0..p.pairs())
                .map(|q| {
                    let (a, b) = (p.pair_ptr[q] as usize, p.pair_ptr[q + 1] as usize);
                    let last = if b > a { p.pair_idx[b - 1] } else { 0 };
                    let mut idx = [last; PW];
                    let mut val = [0.0; PW];
                    idx[..b - a].copy_from_slice(&p.pair_idx[a..b]);
                    val[..b - a].copy_from_slice(&p.pair_val[a..b]);
                    (idx, val)
                })
                .unzip()
        });
        let discs = Discs::of(p);
        Kkt {
            p,
            nb,
            k,
            ml,
            mi: h.len(),
            cones,
            h,
            fixed,
            discs,
        }
    }

    /// `out = G·x`.
    pub(super) fn g_mul(&self, x: &[f64], out: &mut [f64]) {
        let p = self.p;
        let (nb, k) = (self.nb, self.k);
        let xe = p.elastic.map_or(0.0, |e| x[nb + e]);
        let (pairs, rest) = out.split_at_mut(2 * p.pairs());
        if let Some((fidx, fval)) = &self.fixed {
            for (((o, idx), val), &el) in pairs
                .chunks_exact_mut(2)
                .zip(fidx)
                .zip(fval)
                .zip(&p.pair_el)
            {
                let mut ax = 0.0;
                for j in 0..PW {
                    ax += val[j] * x[idx[j] as usize];
                }
                let el = el * xe;
                o[0] = ax - el;
                o[1] = -ax - el;
            }
        } else {
            for (q, o) in pairs.chunks_exact_mut(2).enumerate() {
                let (a, b) = (p.pair_ptr[q] as usize, p.pair_ptr[q + 1] as usize);
                let ax: f64 = p.pair_val[a..b]
                    .iter()
                    .zip(&p.pair_idx[a..b])
                    .map(|(v, &j)| v * x[j as usize])
                    .sum();
                let el = p.pair_el[q] * xe;
                o[0] = ax - el;
                o[1] = -ax - el;
            }
        }
        let xb = &x[nb..];
        let (ones, cones) = rest.split_at_mut(p.ones());
        let row = |ptr: &[u32], idx: &[u32], val: &[f64], border: &[f64], r: usize| {
            let (a, b) = (ptr[r] as usize, ptr[r + 1] as usize);
            let mut g: f64 = val[a..b]
                .iter()
                .zip(&idx[a..b])
                .map(|(v, &j)| v * x[j as usize])
                .sum();
            for (bv, xv) in border[r * k..(r + 1) * k].iter().zip(xb) {
                g += bv * xv;
            }
            g
        };
        for (r, o) in ones.iter_mut().enumerate() {
            *o = row(&p.one_ptr, &p.one_idx, &p.one_val, &p.one_border, r);
        }
        if let Some(dc) = &self.discs {
            for ((((o, idx), u), v), c) in cones
                .chunks_exact_mut(3)
                .zip(&dc.idx)
                .zip(&dc.u)
                .zip(&dc.v)
                .zip(dc.c.chunks_exact(k.max(1)))
            {
                let (mut gu, mut gv) = (0.0, 0.0);
                for j in 0..DW {
                    let xj = x[idx[j] as usize];
                    gu += u[j] * xj;
                    gv += v[j] * xj;
                }
                o[0] = c.iter().zip(xb).map(|(a, b)| a * b).sum();
                o[1] = gu;
                o[2] = gv;
            }
        } else {
            for (r, o) in cones.iter_mut().enumerate() {
                *o = row(&p.crow_ptr, &p.crow_idx, &p.crow_val, &p.crow_border, r);
            }
        }
    }

    /// `out += Gᵀ·z`.
    pub(super) fn gt_mul_add(&self, z: &[f64], out: &mut [f64]) {
        let p = self.p;
        let (nb, k) = (self.nb, self.k);
        let (pairs, rest) = z.split_at(2 * p.pairs());
        let mut ze = 0.0;
        if let Some((fidx, fval)) = &self.fixed {
            for (((zz, idx), val), &el) in pairs.chunks_exact(2).zip(fidx).zip(fval).zip(&p.pair_el)
            {
                let zd = zz[0] - zz[1];
                for j in 0..PW {
                    out[idx[j] as usize] += val[j] * zd;
                }
                ze += el * (zz[0] + zz[1]);
            }
        } else {
            for (q, zz) in pairs.chunks_exact(2).enumerate() {
                let (a, b) = (p.pair_ptr[q] as usize, p.pair_ptr[q + 1] as usize);
                let zd = zz[0] - zz[1];
                for (v, &j) in p.pair_val[a..b].iter().zip(&p.pair_idx[a..b]) {
                    out[j as usize] += v * zd;
                }
                ze += p.pair_el[q] * (zz[0] + zz[1]);
            }
        }
        if let Some(e) = p.elastic {
            out[nb + e] -= ze;
        }
        let (ones, cones) = rest.split_at(p.ones());
        let mut add_row =
            |ptr: &[u32], idx: &[u32], val: &[f64], border: &[f64], r: usize, zr: f64| {
                let (a, b) = (ptr[r] as usize, ptr[r + 1] as usize);
                for (v, &j) in val[a..b].iter().zip(&idx[a..b]) {
                    out[j as usize] += v * zr;
                }
                for (bi, bv) in border[r * k..(r + 1) * k].iter().enumerate() {
                    out[nb + bi] += bv * zr;
                }
            };
        for (r, &zr) in ones.iter().enumerate() {
            add_row(&p.one_ptr, &p.one_idx, &p.one_val, &p.one_border, r, zr);
        }
        if let Some(dc) = &self.discs {
            for ((((zz, idx), u), v), c) in cones
                .chunks_exact(3)
                .zip(&dc.idx)
                .zip(&dc.u)
                .zip(&dc.v)
                .zip(dc.c.chunks_exact(k.max(1)))
            {
                for j in 0..DW {
                    out[idx[j] as usize] += u[j] * zz[1] + v[j] * zz[2];
                }
                for (b, cb) in c.iter().enumerate() {
                    out[nb + b] += cb * zz[0];
                }
            }
        } else {
            for (r, &zr) in cones.iter().enumerate() {
                add_row(&p.crow_ptr, &p.crow_idx, &p.crow_val, &p.crow_border, r, zr);
            }
        }
    }

    /// `H` alone as a bordered band matrix of half-bandwidth `w`.
    pub(super) fn h_matrix(&self, w: usize) -> BorderedBand {
        let mut m = BorderedBand::new(self.nb, w, self.k);
        for &(i, j, v) in &self.p.h {
            m.add_sym(i as usize, j as usize, v);
        }
        m
    }

    /// `unreg = H + Gᵀ·V·G` (`V = d` on the linear slacks, `W⁻¹·W⁻¹` of `scal[c]` on cone
    /// c), and `kkt = unreg + δ·I`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn assemble(
        &self,
        hmat: &BorderedBand,
        d: &[f64],
        scal: &[SocScaling],
        y: &mut Vec<f64>,
        delta: f64,
        unreg: &mut BorderedBand,
        kkt: &mut BorderedBand,
    ) {
        let p = self.p;
        let (nb, k) = (self.nb, self.k);
        let w = unreg.w;
        let wp = w + 1;
        unreg.copy_from(hmat);
        let mut corner_e = 0.0;
        let npairs = p.pairs();
        let band = &mut unreg.band;
        let e_border = p.elastic.map_or(0..0, |e| e * nb..(e + 1) * nb);
        let border = &mut unreg.border[e_border];
        if let Some((fidx, fval)) = &self.fixed {
            for (q, (idx, val)) in fidx.iter().zip(fval).enumerate() {
                let (du, dl) = (d[2 * q], d[2 * q + 1]);
                let dq = du + dl;
                for a in 0..PW {
                    let i = idx[a] as usize;
                    let s = dq * val[a];
                    let base = i * w + w;
                    for b in 0..=a {
                        band[base + idx[b] as usize] += s * val[b];
                    }
                }
                let el = p.pair_el[q];
                if el != 0.0 {
                    let cross = el * (dl - du);
                    for a in 0..PW {
                        border[idx[a] as usize] += cross * val[a];
                    }
                    corner_e += el * el * dq;
                }
            }
        } else {
            for q in 0..npairs {
                let (a0, a1) = (p.pair_ptr[q] as usize, p.pair_ptr[q + 1] as usize);
                let (du, dl) = (d[2 * q], d[2 * q + 1]);
                let dq = du + dl;
                let idx = &p.pair_idx[a0..a1];
                let val = &p.pair_val[a0..a1];
                for (a, (&ia, &va)) in idx.iter().zip(val).enumerate() {
                    let i = ia as usize;
                    let base = i * w + w;
                    let s = dq * va;
                    for (&jb, &vb) in idx[..=a].iter().zip(&val[..=a]) {
                        band[base + jb as usize] += s * vb;
                    }
                }
                let el = p.pair_el[q];
                if el != 0.0 {
                    let cross = el * (dl - du);
                    for (&ia, &va) in idx.iter().zip(val) {
                        border[ia as usize] += cross * va;
                    }
                    corner_e += el * el * dq;
                }
            }
        }
        if let Some(e) = p.elastic {
            unreg.corner[e * k + e] += corner_e;
        }
        for r in 0..p.ones() {
            let dr = d[2 * npairs + r];
            let (a0, a1) = (p.one_ptr[r] as usize, p.one_ptr[r + 1] as usize);
            let idx = &p.one_idx[a0..a1];
            let val = &p.one_val[a0..a1];
            let bor = &p.one_border[r * k..(r + 1) * k];
            for (a, (&ia, &va)) in idx.iter().zip(val).enumerate() {
                let i = ia as usize;
                for (&jb, &vb) in idx[..=a].iter().zip(&val[..=a]) {
                    unreg.band[i * wp + jb as usize + w - i] += dr * va * vb;
                }
                for (b, &bv) in bor.iter().enumerate() {
                    unreg.border[b * nb + i] += dr * bv * va;
                }
            }
            for (b, &bv) in bor.iter().enumerate() {
                for (c, &cv) in bor.iter().enumerate() {
                    unreg.corner[b * k + c] += dr * bv * cv;
                }
            }
        }
        if let Some(dc) = &self.discs {
            dc.assemble(scal, k, unreg);
        } else {
            self.assemble_cones(scal, y, unreg);
        }
        kkt.copy_from(unreg);
        for i in 0..nb {
            kkt.band[i * wp + w] += delta;
        }
        for b in 0..k {
            kkt.corner[b * k + b] += delta;
        }
    }

    /// `unreg += Gᵀ·V·G` over the cones, each gathered densely (any cone).
    fn assemble_cones(&self, scal: &[SocScaling], y: &mut Vec<f64>, unreg: &mut BorderedBand) {
        let (nb, k) = (self.nb, self.k);
        let w = unreg.w;
        let wp = w + 1;
        let mut col = [0.0; MAX_CONE];
        let mut out = [0.0; MAX_CONE];
        for (c, cr) in self.cones.iter().enumerate() {
            let (q, nv) = (cr.q, cr.vars.len());
            let nt = nv + k;
            // Y = W⁻¹·G (q × nt, by columns), then Gᵀ·V·G = Yᵀ·Y.
            y.resize(q * nt, 0.0);
            for j in 0..nt {
                for a in 0..q {
                    col[a] = cr.g[a * nt + j];
                }
                scal[c].apply_inv(&col[..q], &mut out[..q]);
                for a in 0..q {
                    y[a * nt + j] = out[a];
                }
            }
            for i in 0..nt {
                for j in 0..=i {
                    let mut acc = 0.0;
                    for a in 0..q {
                        acc += y[a * nt + i] * y[a * nt + j];
                    }
                    if i < nv {
                        let (gi, gj) = (cr.vars[i] as usize, cr.vars[j] as usize);
                        unreg.band[gi * wp + gj + w - gi] += acc;
                    } else if j < nv {
                        unreg.border[(i - nv) * nb + cr.vars[j] as usize] += acc;
                    } else {
                        let (bi, bj) = (i - nv, j - nv);
                        unreg.corner[bi * k + bj] += acc;
                        if bi != bj {
                            unreg.corner[bj * k + bi] += acc;
                        }
                    }
                }
            }
        }
    }
}

impl Discs {
    /// The problem's cones as discs, or `None` when one is not.
    fn of(p: &Problem) -> Option<Discs> {
        let k = p.k;
        let mut d = Discs {
            idx: Vec::with_capacity(p.cones()),
            u: Vec::with_capacity(p.cones()),
            v: Vec::with_capacity(p.cones()),
            c: Vec::with_capacity(p.cones() * k),
        };
        for cn in 0..p.cones() {
            let r0 = p.cone_ptr[cn] as usize;
            if p.cone_ptr[cn + 1] as usize - r0 != 3 {
                return None;
            }
            let band = |r: usize| p.crow_ptr[r] as usize..p.crow_ptr[r + 1] as usize;
            let no_border = |r: usize| p.crow_border[r * k..(r + 1) * k].iter().all(|&b| b == 0.0);
            if !band(r0).is_empty() || !no_border(r0 + 1) || !no_border(r0 + 2) {
                return None;
            }
            let mut vars: Vec<u32> = band(r0 + 1)
                .chain(band(r0 + 2))
                .map(|e| p.crow_idx[e])
                .collect();
            vars.sort_unstable();
            vars.dedup();
            if vars.len() > DW {
                return None;
            }
            let last = vars.last().copied().unwrap_or(0);
            let mut idx = [last; DW];
            idx[..vars.len()].copy_from_slice(&vars);
            let (mut u, mut v) = ([0.0; DW], [0.0; DW]);
            for (row, out) in [(r0 + 1, &mut u), (r0 + 2, &mut v)] {
                for e in band(row) {
                    let j = vars.binary_search(&p.crow_idx[e]).unwrap_or(0);
                    out[j] += p.crow_val[e];
                }
            }
            d.idx.push(idx);
            d.u.push(u);
            d.v.push(v);
            d.c.extend_from_slice(&p.crow_border[r0 * k..(r0 + 1) * k]);
        }
        Some(d)
    }

    /// `unreg += Gᵀ·V·G` over the discs, `V = W⁻¹·W⁻¹` of each disc's scaling: on the band
    /// `V11·u·uᵀ + V22·v·vᵀ + V12·(u·vᵀ + v·uᵀ)`, against the border `c·(V01·u + V02·v)ᵀ`,
    /// on the corner `V00·c·cᵀ`.
    fn assemble(&self, scal: &[SocScaling], k: usize, unreg: &mut BorderedBand) {
        let (nb, w) = (unreg.nb, unreg.w);
        for ((((sc, idx), u), v), c) in scal
            .iter()
            .zip(&self.idx)
            .zip(&self.u)
            .zip(&self.v)
            .zip(self.c.chunks_exact(k.max(1)))
        {
            // W⁻¹ by columns, then V = W⁻¹·W⁻¹ (symmetric).
            let mut wi = [[0.0; 3]; 3];
            for (j, col) in wi.iter_mut().enumerate() {
                let mut e = [0.0; 3];
                e[j] = 1.0;
                sc.apply_inv(&e, col);
            }
            let vm = |a: usize, b: usize| (0..3).map(|m| wi[m][a] * wi[b][m]).sum::<f64>();
            let (v00, v01, v02, v11, v12, v22) =
                (vm(0, 0), vm(0, 1), vm(0, 2), vm(1, 1), vm(1, 2), vm(2, 2));
            for a in 0..DW {
                let i = idx[a] as usize;
                let base = i * w + w;
                let (pa, qa) = (v11 * u[a] + v12 * v[a], v12 * u[a] + v22 * v[a]);
                for b in 0..=a {
                    unreg.band[base + idx[b] as usize] += pa * u[b] + qa * v[b];
                }
            }
            for (bi, &cb) in c.iter().enumerate() {
                if cb == 0.0 {
                    continue;
                }
                let border = &mut unreg.border[bi * nb..(bi + 1) * nb];
                for a in 0..DW {
                    border[idx[a] as usize] += cb * (v01 * u[a] + v02 * v[a]);
                }
                for (bj, &cj) in c.iter().enumerate() {
                    unreg.corner[bi * k + bj] += v00 * cb * cj;
                }
            }
        }
    }
}
