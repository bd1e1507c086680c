//! A QP builder with sparse rows, for clarabel (one timed solve).

use crate::report::{QpStats, QpStatus};
use crate::tolerances::CLARABEL_MAX_ITER;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, SupportedConeT::NonnegativeConeT,
};
use std::time::Instant;

/// The settings every patcher solve uses: quiet, [`CLARABEL_MAX_ITER`], the rest clarabel's
/// defaults.
pub(crate) fn settings() -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        max_iter: CLARABEL_MAX_ITER,
        ..DefaultSettings::default()
    }
}

/// Add `other` into `acc` (sums; status of the latest).
pub(crate) fn add_stats(acc: &mut QpStats, other: &QpStats) {
    acc.iterations += other.iterations;
    acc.solves += other.solves;
    acc.solve_time_s += other.solve_time_s;
    if other.status != QpStatus::NotRun {
        acc.status = other.status;
    }
}

/// A sparse linear form: `Σ coeff · x[var]` over `(var, coeff)`.
pub(crate) type Row = Vec<(usize, f64)>;

/// Merge repeated variables of a row (summing them) and drop zero coefficients.
pub(crate) fn compact(row: &[(usize, f64)]) -> Row {
    let mut r: Row = row.to_vec();
    r.sort_by_key(|e| e.0);
    let mut out: Row = Vec::with_capacity(r.len());
    for (k, v) in r {
        match out.last_mut() {
            Some(last) if last.0 == k => last.1 += v,
            _ => out.push((k, v)),
        }
    }
    out.retain(|e| e.1 != 0.0);
    out
}

/// `a·ra + b·rb` as a compact row.
pub(crate) fn combine(a: f64, ra: &[(usize, f64)], b: f64, rb: &[(usize, f64)]) -> Row {
    let mut r: Row = ra.iter().map(|&(k, v)| (k, a * v)).collect();
    r.extend(rb.iter().map(|&(k, v)| (k, b * v)));
    compact(&r)
}

/// `c·r` as a row.
pub(crate) fn scaled(c: f64, r: &[(usize, f64)]) -> Row {
    r.iter().map(|&(k, v)| (k, c * v)).collect()
}

/// A QP (or SOCP) with a general (sparse, symmetric) quadratic objective, equality and
/// inequality rows and second-order cones, in clarabel's form `A·x + s = b`, `s` in the
/// zero cone (equalities, first), the nonnegative cone (inequalities), then one
/// second-order cone per [`QpBuilder::add_soc`] block:
///
/// ```text
/// minimise ½·xᵀ·H·x + qᵀ·x   subject to   A_eq·x = b_eq,   A_le·x ≤ b_le,
///                                         ‖(b_k − a_k·x)_{k≥1}‖ ≤ b_0 − a_0·x   per block
/// ```
///
/// It is solved by clarabel ([`QpBuilder::solve`]); the joint patch's QPs go to the
/// banded interior-point method instead ([`crate::ipm::Problem`]).
///
/// Only the upper triangle of `H` is stored (clarabel reads nothing else).
#[derive(Debug, Clone)]
pub(crate) struct QpBuilder {
    n: usize,
    h_rows: Vec<usize>,
    h_cols: Vec<usize>,
    h_vals: Vec<f64>,
    q: Vec<f64>,
    eq: Vec<(Row, f64)>,
    le: Vec<(Row, f64)>,
    soc: Vec<Vec<(Row, f64)>>,
}

impl QpBuilder {
    /// An empty problem in `n` variables (zero objective, no constraints).
    pub(crate) fn new(n: usize) -> QpBuilder {
        QpBuilder {
            n,
            h_rows: Vec::new(),
            h_cols: Vec::new(),
            h_vals: Vec::new(),
            q: vec![0.0; n],
            eq: Vec::new(),
            le: Vec::new(),
            soc: Vec::new(),
        }
    }

    /// Add `c·x[var]` to the objective.
    pub(crate) fn add_linear(&mut self, var: usize, c: f64) {
        self.q[var] += c;
    }

    /// Add `weight·(row·x − target)²` to the objective (the constant is dropped).
    pub(crate) fn add_square(&mut self, row: &[(usize, f64)], weight: f64, target: f64) {
        let r = compact(row);
        for (a, &(i, ri)) in r.iter().enumerate() {
            self.q[i] -= 2.0 * weight * target * ri;
            for &(j, rj) in &r[a..] {
                // r is sorted by variable, so i ≤ j: the upper triangle of 2·w·r·rᵀ.
                self.h_rows.push(i);
                self.h_cols.push(j);
                self.h_vals.push(2.0 * weight * ri * rj);
            }
        }
    }

    /// Add the equality `row·x = rhs`.
    pub(crate) fn add_eq(&mut self, row: &[(usize, f64)], rhs: f64) {
        self.eq.push((compact(row), rhs));
    }

    /// Add the inequality `row·x ≤ rhs`.
    pub(crate) fn add_le(&mut self, row: &[(usize, f64)], rhs: f64) {
        self.le.push((compact(row), rhs));
    }

    /// Add the second-order cone `‖(rhs_k − row_k·x)_{k≥1}‖₂ ≤ rhs_0 − row_0·x` over the
    /// rows of `block` (`(row_k, rhs_k)`, at least 2).
    #[cfg(test)]
    pub(crate) fn add_soc(&mut self, block: &[(Row, f64)]) {
        debug_assert!(block.len() >= 2, "a second-order cone needs 2 rows or more");
        self.soc
            .push(block.iter().map(|(r, b)| (compact(r), *b)).collect());
    }

    /// Solve with clarabel ([`settings`]), adding this solve's figures to `stats` (status of
    /// this solve, iterations, one solve, wall time of setup and solve). `Ok(x)` when clarabel reports
    /// `Solved` or `AlmostSolved`, otherwise its status.
    pub(crate) fn solve(&self, stats: &mut QpStats) -> Result<Vec<f64>, QpStatus> {
        self.solve_with(stats, settings())
    }

    fn solve_with(
        &self,
        stats: &mut QpStats,
        settings: DefaultSettings<f64>,
    ) -> Result<Vec<f64>, QpStatus> {
        use clarabel::solver::SupportedConeT::{SecondOrderConeT, ZeroConeT};
        let started = Instant::now();
        let n = self.n;
        let h = CscMatrix::new_from_triplets(
            n,
            n,
            self.h_rows.clone(),
            self.h_cols.clone(),
            self.h_vals.clone(),
        );
        let m = self.eq.len() + self.le.len() + self.soc.iter().map(Vec::len).sum::<usize>();
        let (mut ai, mut aj, mut av) = (Vec::new(), Vec::new(), Vec::new());
        let mut b = Vec::with_capacity(m);
        let rows = self
            .eq
            .iter()
            .chain(&self.le)
            .chain(self.soc.iter().flatten());
        for (r, (row, rhs)) in rows.enumerate() {
            for &(j, v) in row {
                ai.push(r);
                aj.push(j);
                av.push(v);
            }
            b.push(*rhs);
        }
        let a = CscMatrix::new_from_triplets(m, n, ai, aj, av);
        let mut cones = Vec::new();
        if !self.eq.is_empty() {
            cones.push(ZeroConeT(self.eq.len()));
        }
        if !self.le.is_empty() {
            cones.push(NonnegativeConeT(self.le.len()));
        }
        for block in &self.soc {
            cones.push(SecondOrderConeT(block.len()));
        }
        if h.check_format().is_err() || a.check_format().is_err() {
            stats.status = QpStatus::SetupError;
            return Err(QpStatus::SetupError);
        }
        let mut solver = match DefaultSolver::new(&h, &self.q, &a, &b, &cones, settings) {
            Ok(s) => s,
            Err(e) => {
                let _ = e;
                stats.status = QpStatus::SetupError;
                return Err(QpStatus::SetupError);
            }
        };
        solver.solve();
        let sol = &solver.solution;
        stats.status = QpStatus::from_clarabel(sol.status);
        stats.iterations += sol.iterations;
        stats.solves += 1;
        stats.solve_time_s += started.elapsed().as_secs_f64();
        if stats.status.is_solved() {
            Ok(sol.x.clone())
        } else {
            Err(stats.status)
        }
    }
}

#[cfg(test)]
mod qp_builder_tests {
    use super::*;

    #[test]
    fn builder_equality_and_bound_planted() {
        // minimise (x0 − 1)² + (x1 − 2)² s.t. x0 + x1 = 1, x1 ≤ 0.5 → (0.5, 0.5).
        let mut qp = QpBuilder::new(2);
        qp.add_square(&[(0, 1.0)], 1.0, 1.0);
        qp.add_square(&[(1, 1.0)], 1.0, 2.0);
        qp.add_eq(&[(0, 1.0), (1, 1.0)], 1.0);
        qp.add_le(&[(1, 1.0)], 0.5);
        let mut st = QpStats::default();
        let x = qp.solve(&mut st).unwrap();
        assert!(
            (x[0] - 0.5).abs() < 1e-6 && (x[1] - 0.5).abs() < 1e-6,
            "{x:?}"
        );
        assert_eq!(st.solves, 1);
    }

    #[test]
    fn builder_off_diagonal_square_is_symmetric() {
        // minimise (x0 − x1 − 1)² + 1e-3·(x0² + x1²): x0 = −x1 = 1/(2 + 1e-3). A lower
        // triangular H would be read wrongly by clarabel and miss this.
        let mut qp = QpBuilder::new(2);
        qp.add_square(&[(1, -1.0), (0, 1.0)], 1.0, 1.0);
        qp.add_square(&[(0, 1.0)], 1e-3, 0.0);
        qp.add_square(&[(1, 1.0)], 1e-3, 0.0);
        let mut st = QpStats::default();
        let x = qp.solve(&mut st).unwrap();
        let want = 1.0 / (2.0 + 1e-3);
        assert!(
            (x[0] - want).abs() < 1e-6 && (x[1] + want).abs() < 1e-6,
            "{x:?}"
        );
    }

    #[test]
    fn builder_infeasible_reports_status() {
        let mut qp = QpBuilder::new(1);
        qp.add_le(&[(0, 1.0)], -1.0);
        qp.add_le(&[(0, -1.0)], -1.0);
        let mut st = QpStats::default();
        assert!(qp.solve(&mut st).is_err());
        assert!(st.status.is_infeasible(), "{}", st.status);
    }
}

/// The banded interior-point method ([`crate::ipm::Problem`]) against clarabel on the
/// same problems: seeded random QPs with second-order cones whose rows couple
/// neighbouring band unknowns, two-sided rows (some one-sided, some relaxed by an elastic
/// border unknown), rows on the border unknowns alone and a quadratic objective — the
/// shapes of the joint patch's QPs. Both solutions agree to 1e-5.
#[cfg(test)]
mod ipm_against_clarabel {
    use super::*;
    use crate::ipm::{IpmSettings, IpmStatus, Problem};

    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn sym(&mut self) -> f64 {
            2.0 * self.next() - 1.0
        }
    }

    #[test]
    fn random_banded_socps_agree() {
        for seed in 1..=12u64 {
            let mut rng = Rng(seed * 7919);
            let nb = 12 + (rng.next() * 40.0) as usize;
            let (t, e) = (nb, nb + 1);
            let n = nb + 2;
            let mut ip = Problem::new(nb, 2);
            let mut cl = QpBuilder::new(n);
            let xs: Vec<f64> = (0..nb).map(|_| rng.sym() * 3.0).collect();
            let local = |rng: &mut Rng, len: usize| -> Row {
                let at = (rng.next() * (nb - len) as f64) as usize;
                (at..at + len).map(|j| (j, rng.sym())).collect()
            };
            for _ in 0..nb {
                let r = local(&mut rng, 3);
                let (wt, tg) = (0.01 + rng.next(), rng.sym());
                ip.add_square(&r, wt, tg);
                cl.add_square(&r, wt, tg);
            }
            for j in 0..nb {
                ip.add_square(&[(j, 1.0)], 1e-3, 0.0);
                cl.add_square(&[(j, 1.0)], 1e-3, 0.0);
            }
            ip.add_linear(t, 1.0);
            cl.add_linear(t, 1.0);
            ip.add_linear(e, 50.0);
            cl.add_linear(e, 50.0);
            for _ in 0..3 * nb {
                let len = 2 + (rng.next() * 3.0) as usize;
                let r = local(&mut rng, len);
                let at: f64 = r.iter().map(|&(j, v)| v * xs[j]).sum();
                // Some rows tight at the planted point, some infeasible without e.
                let (lo, hi) = (at - 0.5 * rng.next(), at + 0.5 * rng.next());
                let shift = if rng.next() < 0.1 { 1.0 } else { 0.0 };
                let elastic = rng.next() < 0.5;
                let lo = if rng.next() < 0.2 {
                    f64::NEG_INFINITY
                } else {
                    lo + shift
                };
                let hi = if rng.next() < 0.2 {
                    f64::INFINITY
                } else {
                    hi + shift * 0.5
                };
                let el = elastic.then_some(e);
                let (lo, hi) = if el.is_none() {
                    (lo - shift, hi)
                } else {
                    (lo, hi)
                };
                ip.add_pair(&r, lo, hi, el);
                let mut up = r.clone();
                let mut dn: Row = r.iter().map(|&(j, v)| (j, -v)).collect();
                if let Some(e) = el {
                    up.push((e, -1.0));
                    dn.push((e, -1.0));
                }
                if hi.is_finite() {
                    cl.add_le(&up, hi);
                }
                if lo.is_finite() {
                    cl.add_le(&dn, -lo);
                }
            }
            ip.add_le(&[(e, -1.0)], 0.0);
            cl.add_le(&[(e, -1.0)], 0.0);
            ip.add_le(&[(t, 1.0)], 100.0);
            cl.add_le(&[(t, 1.0)], 100.0);
            for _ in 0..nb / 2 {
                let (u, v) = (local(&mut rng, 4), local(&mut rng, 3));
                let (bu, bv) = (rng.sym(), rng.sym());
                let rows: Vec<(Row, f64)> = vec![(vec![(t, -1.0)], 0.0), (u, bu), (v, bv)];
                let view: Vec<(&[(usize, f64)], f64)> =
                    rows.iter().map(|(r, b)| (r.as_slice(), *b)).collect();
                ip.add_soc(&view);
                cl.add_soc(&rows);
            }
            let sol = ip.solve(&IpmSettings::default());
            assert_eq!(sol.status, IpmStatus::Solved, "seed {seed}");
            let want = cl
                .solve(&mut QpStats::default())
                .expect("clarabel solves it");
            let objf = |x: &[f64]| -> (f64, f64) {
                let mut o: f64 = cl.q.iter().zip(x).map(|(a, b)| a * b).sum();
                for ((&i, &j), &v) in cl.h_rows.iter().zip(&cl.h_cols).zip(&cl.h_vals) {
                    o += if i == j {
                        0.5 * v * x[i] * x[i]
                    } else {
                        v * x[i] * x[j]
                    };
                }
                let mut viol: f64 = 0.0;
                for (row, rhs) in &cl.le {
                    let g: f64 = row.iter().map(|&(j, v)| v * x[j]).sum();
                    viol = viol.max(g - rhs);
                }
                for b in &cl.soc {
                    let sv: Vec<f64> = b
                        .iter()
                        .map(|(row, rhs)| rhs - row.iter().map(|&(j, v)| v * x[j]).sum::<f64>())
                        .collect();
                    viol = viol.max((sv[1] * sv[1] + sv[2] * sv[2]).sqrt() - sv[0]);
                }
                (o, viol)
            };
            let ((on, vn), (oc, vc)) = (objf(&sol.x), objf(&want));
            assert!(vn < 1e-7 && vc < 1e-6, "seed {seed}: violations {vn} {vc}");
            assert!(
                (on - oc).abs() < 1e-5 * (1.0 + oc.abs()),
                "seed {seed}: {on} vs {oc}"
            );
        }
    }
}
