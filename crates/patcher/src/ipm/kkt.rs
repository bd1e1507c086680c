//! The KKT matrix of one problem: the unknowns' order along the path (the band), its
//! shape, and the assembly of `H + Gᵀ·V·G` and `A` from a pattern computed once per
//! solve.

// Index loops mirror the assembly's formulas.
#![allow(clippy::needless_range_loop)]

use super::Banded;
use super::band::{BorderedBand, Slot};

/// The unknowns' order and the matrix shape, fixed for a problem.
pub(super) struct Layout {
    /// Band index of each variable (`None`: border).
    pub(super) var_band: Vec<Option<usize>>,
    /// Border index of each border variable.
    pub(super) var_border: Vec<Option<usize>>,
    /// Band index of each equality's multiplier.
    pub(super) eq_band: Vec<usize>,
    /// Band size, half-bandwidth, border size.
    pub(super) nb: usize,
    pub(super) w: usize,
    pub(super) k: usize,
}

impl Layout {
    pub(super) fn new(p: &Banded) -> Layout {
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

    pub(super) fn var_slot(&self, j: usize) -> Slot {
        match self.var_band[j] {
            Some(b) => Slot::Band(b),
            None => Slot::Border(self.var_border[j].unwrap_or(0)),
        }
    }
}

/// One entry of a row with its place in the KKT system.
#[derive(Clone, Copy)]
pub(super) struct Entry {
    pub(super) var: usize,
    pub(super) slot: Slot,
    pub(super) v: f64,
}

/// The fixed shape of the KKT matrix of one problem, computed once per solve: where each
/// product of [`Banded::solve`]'s iteration matrix lands (flat indices into the
/// [`BorderedBand`]'s storage), so that an iteration only multiplies and adds.
pub(super) struct Assembler {
    /// `H` and `A` (the parts that do not change), unregularised.
    pub(super) base: BorderedBand,
    /// Linear row r's pairs `lp_ptr[r]..lp_ptr[r + 1]`: where `d_r·g_a·g_b` is added.
    pub(super) lp_ptr: Vec<usize>,
    pub(super) lp_dst: Vec<u32>,
    pub(super) lp_coef: Vec<f64>,
    /// Per cone block: its variables' count, `G_c` (q × nv, row-major) and, for every
    /// pair `i ≤ j` of its variables in order, where `(G_cᵀ·V·G_c)_ij` is added
    /// (`pair_ptr` into `pair_dst`).
    pub(super) cones: Vec<ConePattern>,
    /// The diagonal entries that get `+δ` (variables) and `−δ` (multipliers).
    pub(super) reg_plus: Vec<u32>,
    pub(super) reg_minus: Vec<u32>,
}

pub(super) struct ConePattern {
    pub(super) nv: usize,
    pub(super) g: Vec<f64>,
    pub(super) pair_ptr: Vec<usize>,
    pub(super) pair_dst: Vec<u32>,
}

impl Assembler {
    pub(super) fn new(
        p: &Banded,
        lay: &Layout,
        entries: &[Vec<Entry>],
        blocks: &[(usize, usize)],
    ) -> Self {
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
    pub(super) fn assemble(
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
