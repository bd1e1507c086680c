//! The problem [`Problem`] holds: its unknowns (a band along the path and a small dense
//! border), objective, rows and second-order cones, and its equilibration.

/// A convex QP with second-order cones whose unknowns are `nb` **band** unknowns, ordered
/// along the path (every row, cone and entry of `H` couples unknowns within a short
/// stretch of that order), and `k` **border** unknowns that any row may touch (unknown
/// `nb + b` is border unknown `b`):
///
/// ```text
/// minimise    ½·xᵀ·H·x + cᵀ·x
/// subject to  lo_p ≤ a_p·x (− e) ≤ hi_p      two-sided rows over band unknowns ("pairs"),
///                                           each side optionally relaxed by the elastic
///                                           border unknown e: a·x − e ≤ hi, −a·x − e ≤ −lo
///             g_r·x ≤ h_r                    one-sided rows (any unknowns)
///             ‖(h_k − g_k·x)_{k≥1}‖₂ ≤ h_0 − g_0·x   second-order cones (2 to MAX_CONE rows)
/// ```
///
/// There are no equalities: the patcher eliminates its own (`crate::hermite`), which
/// keeps the KKT matrix positive definite and its band narrow.
#[derive(Debug, Clone)]
pub struct Problem {
    pub(super) nb: usize,
    pub(super) k: usize,
    /// Linear objective, `nb + k`.
    pub(super) c: Vec<f64>,
    /// Entries of H, `(i, j, v)` with `i ≥ j` (unknown indices); repeated pairs add up.
    pub(super) h: Vec<(u32, u32, f64)>,
    /// Pairs: band row `pair_ptr[p]..pair_ptr[p + 1]` of `pair_idx`, `pair_val`.
    pub(super) pair_ptr: Vec<u32>,
    pub(super) pair_idx: Vec<u32>,
    pub(super) pair_val: Vec<f64>,
    pub(super) pair_lo: Vec<f64>,
    pub(super) pair_hi: Vec<f64>,
    /// Per pair: 1 when relaxed by the elastic unknown, else 0.
    pub(super) pair_el: Vec<f64>,
    /// The elastic unknown's border index.
    pub(super) elastic: Option<usize>,
    /// One-sided rows: band part `one_ptr[r]..one_ptr[r + 1]`, border coefficients
    /// `one_border[r·k..(r + 1)·k]`, right-hand side.
    pub(super) one_ptr: Vec<u32>,
    pub(super) one_idx: Vec<u32>,
    pub(super) one_val: Vec<f64>,
    pub(super) one_border: Vec<f64>,
    pub(super) one_rhs: Vec<f64>,
    /// Cones: rows `cone_ptr[c]..cone_ptr[c + 1]`, each row like a one-sided row
    /// (`crow_*`).
    pub(super) cone_ptr: Vec<u32>,
    pub(super) crow_ptr: Vec<u32>,
    pub(super) crow_idx: Vec<u32>,
    pub(super) crow_val: Vec<f64>,
    pub(super) crow_border: Vec<f64>,
    pub(super) crow_rhs: Vec<f64>,
    /// A row being compacted (kept between the builder's calls: no allocation per row).
    scratch: Vec<(usize, f64)>,
}

impl Problem {
    /// An empty problem with `nb` band and `k` border unknowns (zero objective, no rows).
    pub fn new(nb: usize, k: usize) -> Problem {
        Problem {
            nb,
            k,
            c: vec![0.0; nb + k],
            h: Vec::new(),
            pair_ptr: vec![0],
            pair_idx: Vec::new(),
            pair_val: Vec::new(),
            pair_lo: Vec::new(),
            pair_hi: Vec::new(),
            pair_el: Vec::new(),
            elastic: None,
            one_ptr: vec![0],
            one_idx: Vec::new(),
            one_val: Vec::new(),
            one_border: Vec::new(),
            one_rhs: Vec::new(),
            cone_ptr: vec![0],
            crow_ptr: vec![0],
            crow_idx: Vec::new(),
            crow_val: Vec::new(),
            crow_border: Vec::new(),
            crow_rhs: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// Add `v` to the linear objective of unknown `i`.
    pub fn add_linear(&mut self, i: usize, v: f64) {
        self.c[i] += v;
    }

    /// Add `v` to `H[i][j]` and `H[j][i]` (once when `i == j`).
    pub fn add_h(&mut self, i: usize, j: usize, v: f64) {
        let (a, b) = if i >= j { (i, j) } else { (j, i) };
        self.h.push((a as u32, b as u32, v));
    }

    /// Add `weight·(row·x − target)²` to the objective (its constant dropped).
    pub fn add_square(&mut self, row: &[(usize, f64)], weight: f64, target: f64) {
        let mut row_c = std::mem::take(&mut self.scratch);
        compact_into(row, &mut row_c);
        // Each unordered pair of r·rᵀ once (add_h puts it on both sides).
        for (a, &(i, ri)) in row_c.iter().enumerate() {
            self.c[i] -= 2.0 * weight * target * ri;
            for &(j, rj) in &row_c[..=a] {
                self.add_h(i, j, 2.0 * weight * ri * rj);
            }
        }
        self.scratch = row_c;
    }

    /// Add `lo ≤ row·x ≤ hi` over band unknowns (an infinite bound is no row), each side
    /// relaxed by the border unknown `elastic` when given (`row·x − e ≤ hi`,
    /// `−row·x − e ≤ −lo`; one elastic unknown per problem).
    pub fn add_pair(&mut self, row: &[(usize, f64)], lo: f64, hi: f64, elastic: Option<usize>) {
        let mut row_c = std::mem::take(&mut self.scratch);
        compact_into(row, &mut row_c);
        self.add_pair_compact(&row_c, lo, hi, elastic);
        self.scratch = row_c;
    }

    fn add_pair_compact(&mut self, row: &[(usize, f64)], lo: f64, hi: f64, elastic: Option<usize>) {
        debug_assert!(
            row.iter().all(|e| e.0 < self.nb),
            "a pair is over band unknowns"
        );
        if let Some(e) = elastic {
            debug_assert!(e >= self.nb && self.elastic.is_none_or(|b| b == e - self.nb));
            self.elastic = Some(e - self.nb);
        }
        if lo.is_finite() && hi.is_finite() {
            for &(j, v) in row {
                self.pair_idx.push(j as u32);
                self.pair_val.push(v);
            }
            self.pair_ptr.push(self.pair_idx.len() as u32);
            self.pair_lo.push(lo);
            self.pair_hi.push(hi);
            self.pair_el.push(if elastic.is_some() { 1.0 } else { 0.0 });
            return;
        }
        for (sign, rhs) in [(1.0, hi), (-1.0, -lo)] {
            if rhs.is_finite() {
                let mut r: Vec<(usize, f64)> = row.iter().map(|&(j, v)| (j, sign * v)).collect();
                if let Some(e) = elastic {
                    r.push((e, -1.0));
                }
                self.add_le(&r, rhs);
            }
        }
    }

    /// Add the one-sided row `row·x ≤ rhs` (band or border unknowns).
    pub fn add_le(&mut self, row: &[(usize, f64)], rhs: f64) {
        let mut row_c = std::mem::take(&mut self.scratch);
        compact_into(row, &mut row_c);
        let b0 = self.one_border.len();
        self.one_border.resize(b0 + self.k, 0.0);
        for &(j, v) in &row_c {
            if j < self.nb {
                self.one_idx.push(j as u32);
                self.one_val.push(v);
            } else {
                self.one_border[b0 + j - self.nb] += v;
            }
        }
        self.one_ptr.push(self.one_idx.len() as u32);
        self.one_rhs.push(rhs);
        self.scratch = row_c;
    }

    /// Add the second-order cone `‖(rhs_k − row_k·x)_{k≥1}‖₂ ≤ rhs_0 − row_0·x` over the rows
    /// `(row_k, rhs_k)` (2 to [`super::MAX_CONE`]; band or border unknowns).
    pub fn add_soc(&mut self, rows: &[(&[(usize, f64)], f64)]) {
        assert!(
            (2..=super::MAX_CONE).contains(&rows.len()),
            "second-order cones have 2 to {} rows",
            super::MAX_CONE
        );
        let mut row_c = std::mem::take(&mut self.scratch);
        for (row, rhs) in rows {
            compact_into(row, &mut row_c);
            let b0 = self.crow_border.len();
            self.crow_border.resize(b0 + self.k, 0.0);
            for &(j, v) in &row_c {
                if j < self.nb {
                    self.crow_idx.push(j as u32);
                    self.crow_val.push(v);
                } else {
                    self.crow_border[b0 + j - self.nb] += v;
                }
            }
            self.crow_ptr.push(self.crow_idx.len() as u32);
            self.crow_rhs.push(*rhs);
        }
        self.scratch = row_c;
        self.cone_ptr.push(self.crow_rhs.len() as u32);
    }

    /// Number of pairs, one-sided rows and cones.
    pub(super) fn pairs(&self) -> usize {
        self.pair_lo.len()
    }
    pub(super) fn ones(&self) -> usize {
        self.one_rhs.len()
    }
    pub(super) fn cones(&self) -> usize {
        self.cone_ptr.len() - 1
    }

    /// The half-bandwidth the rows, cones and `H` need.
    pub(super) fn half_bandwidth(&self) -> usize {
        let nb = self.nb as u32;
        let spread = |idx: &[u32]| {
            let (mut lo, mut hi) = (u32::MAX, 0u32);
            for &i in idx.iter().filter(|&&i| i < nb) {
                lo = lo.min(i);
                hi = hi.max(i);
            }
            if lo == u32::MAX {
                0
            } else {
                (hi - lo) as usize
            }
        };
        let mut w = 0;
        for p in 0..self.pairs() {
            let (a, b) = (self.pair_ptr[p] as usize, self.pair_ptr[p + 1] as usize);
            w = w.max(spread(&self.pair_idx[a..b]));
        }
        for r in 0..self.ones() {
            let (a, b) = (self.one_ptr[r] as usize, self.one_ptr[r + 1] as usize);
            w = w.max(spread(&self.one_idx[a..b]));
        }
        for c in 0..self.cones() {
            let (a, b) = (
                self.crow_ptr[self.cone_ptr[c] as usize] as usize,
                self.crow_ptr[self.cone_ptr[c + 1] as usize] as usize,
            );
            w = w.max(spread(&self.crow_idx[a..b]));
        }
        for &(i, j, _) in &self.h {
            if i < nb && j < nb {
                w = w.max((i - j) as usize);
            }
        }
        w
    }

    /// The problem equilibrated: every pair (both sides, its elastic term included), every
    /// one-sided row and every cone (its rows together) divided by its largest
    /// coefficient, the objective by its largest one (unless `scale_objective` is false:
    /// [`super::IpmSettings::scale_objective`]). Neither changes the solution, and the
    /// tolerances then mean the same on every row.
    pub(super) fn equilibrated(self, scale_objective: bool) -> Problem {
        let mut p = self;
        let fin = |m: f64| if m > 0.0 && m.is_finite() { m } else { 1.0 };
        let obj = if !scale_objective {
            1.0
        } else {
            fin(p
                .c
                .iter()
                .map(|v| v.abs())
                .chain(p.h.iter().map(|e| e.2.abs()))
                .fold(0.0f64, f64::max))
        };
        p.c.iter_mut().for_each(|v| *v /= obj);
        p.h.iter_mut().for_each(|e| e.2 /= obj);
        for q in 0..p.pairs() {
            let (a, b) = (p.pair_ptr[q] as usize, p.pair_ptr[q + 1] as usize);
            let m = p.pair_val[a..b]
                .iter()
                .fold(p.pair_el[q], |m, v| m.max(v.abs()));
            let m = fin(m);
            p.pair_val[a..b].iter_mut().for_each(|v| *v /= m);
            p.pair_lo[q] /= m;
            p.pair_hi[q] /= m;
            p.pair_el[q] /= m;
        }
        let k = p.k;
        for r in 0..p.ones() {
            let (a, b) = (p.one_ptr[r] as usize, p.one_ptr[r + 1] as usize);
            let m = fin(p.one_val[a..b]
                .iter()
                .chain(&p.one_border[r * k..(r + 1) * k])
                .fold(0.0f64, |m, v| m.max(v.abs())));
            p.one_val[a..b].iter_mut().for_each(|v| *v /= m);
            p.one_border[r * k..(r + 1) * k]
                .iter_mut()
                .for_each(|v| *v /= m);
            p.one_rhs[r] /= m;
        }
        for c in 0..p.cones() {
            let (r0, r1) = (p.cone_ptr[c] as usize, p.cone_ptr[c + 1] as usize);
            let (a, b) = (p.crow_ptr[r0] as usize, p.crow_ptr[r1] as usize);
            let m = fin(p.crow_val[a..b]
                .iter()
                .chain(&p.crow_border[r0 * k..r1 * k])
                .fold(0.0f64, |m, v| m.max(v.abs())));
            p.crow_val[a..b].iter_mut().for_each(|v| *v /= m);
            p.crow_border[r0 * k..r1 * k]
                .iter_mut()
                .for_each(|v| *v /= m);
            p.crow_rhs[r0..r1].iter_mut().for_each(|v| *v /= m);
        }
        p
    }
}

/// `row` with repeated unknowns summed (in the row's order), sorted by unknown, zeros
/// dropped, into `out` (cleared first: the builder reuses one buffer, no allocation per row).
pub(super) fn compact_into(row: &[(usize, f64)], out: &mut Vec<(usize, f64)>) {
    out.clear();
    out.extend_from_slice(row);
    out.sort_by_key(|e| e.0);
    let mut w = 0;
    for r in 0..out.len() {
        let (k, v) = out[r];
        if w > 0 && out[w - 1].0 == k {
            out[w - 1].1 += v;
        } else {
            out[w] = (k, v);
            w += 1;
        }
    }
    out.truncate(w);
    out.retain(|e| e.1 != 0.0);
}

#[cfg(test)]
mod tests {
    use super::compact_into;

    /// Repeated unknowns are summed in the row's order, the result sorted by unknown and
    /// its zeros dropped; the buffer's previous content does not matter.
    #[test]
    fn compact_sums_sorts_and_drops_zeros() {
        let mut out = vec![(9, 9.0); 3];
        compact_into(
            &[(3, 1.0), (1, 2.0), (3, 0.5), (2, 1.0), (2, -1.0)],
            &mut out,
        );
        assert_eq!(out, vec![(1, 2.0), (3, 1.5)]);
        compact_into(&[], &mut out);
        assert!(out.is_empty());
    }
}
