//! Small clarabel helpers: a QP builder with sparse rows, the solver settings, one timed
//! solve.

use crate::report::QpStats;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT::NonnegativeConeT,
};
use std::time::Instant;

/// Clarabel's iteration cap. The patcher's QPs converge or prove infeasibility in 10–30
/// iterations; one that has not after this many is reported as not solved rather than
/// ground on (clarabel's default is 200). Tolerances stay at clarabel's defaults (1e-8):
/// looser ones change which candidates pass verification.
pub(crate) const SOLVER_MAX_ITER: u32 = 60;

/// The settings every patcher solve uses: quiet, [`SOLVER_MAX_ITER`], the rest clarabel's
/// defaults.
pub(crate) fn settings() -> DefaultSettings<f64> {
    DefaultSettings {
        verbose: false,
        max_iter: SOLVER_MAX_ITER,
        ..DefaultSettings::default()
    }
}

/// Add `other` into `acc` (sums; status of the latest).
pub(crate) fn add_stats(acc: &mut QpStats, other: &QpStats) {
    acc.iterations += other.iterations;
    acc.solves += other.solves;
    acc.solve_time_s += other.solve_time_s;
    if !other.status.is_empty() {
        acc.status = other.status.clone();
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

/// A QP with a general (sparse, symmetric) quadratic objective and both equality and
/// inequality rows, in clarabel's form `A·x + s = b`, `s` in the zero cone (equalities,
/// first) then the nonnegative cone (inequalities):
///
/// ```text
/// minimise ½·xᵀ·H·x + qᵀ·x   subject to   A_eq·x = b_eq,   A_le·x ≤ b_le
/// ```
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

    /// Solve with clarabel ([`settings`]), adding this solve's figures to `stats` (status of
    /// this solve, iterations, one solve, wall time of setup and solve). `Ok(x)` when clarabel reports
    /// `Solved` or `AlmostSolved`, otherwise its status.
    pub(crate) fn solve(&self, stats: &mut QpStats) -> Result<Vec<f64>, SolverStatus> {
        use clarabel::solver::SupportedConeT::ZeroConeT;
        let started = Instant::now();
        let n = self.n;
        let h = CscMatrix::new_from_triplets(
            n,
            n,
            self.h_rows.clone(),
            self.h_cols.clone(),
            self.h_vals.clone(),
        );
        let m = self.eq.len() + self.le.len();
        let (mut ai, mut aj, mut av) = (Vec::new(), Vec::new(), Vec::new());
        let mut b = Vec::with_capacity(m);
        for (r, (row, rhs)) in self.eq.iter().chain(&self.le).enumerate() {
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
        if h.check_format().is_err() || a.check_format().is_err() {
            stats.status = "BadMatrix".into();
            return Err(SolverStatus::NumericalError);
        }
        let mut solver = match DefaultSolver::new(&h, &self.q, &a, &b, &cones, settings()) {
            Ok(s) => s,
            Err(e) => {
                stats.status = format!("SetupError({e})");
                return Err(SolverStatus::NumericalError);
            }
        };
        solver.solve();
        let sol = &solver.solution;
        stats.status = format!("{:?}", sol.status);
        stats.iterations += sol.iterations;
        stats.solves += 1;
        stats.solve_time_s += started.elapsed().as_secs_f64();
        match sol.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => Ok(sol.x.clone()),
            s => Err(s),
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
        assert!(st.status.contains("Infeasible"), "{}", st.status);
    }
}
