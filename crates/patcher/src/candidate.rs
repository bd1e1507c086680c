//! A proposed set of new C values for one zone, and why a proposal could not be made.

use crate::report::QpStats;

/// New C values proposed for points `first..=last` of a path (unrounded, degrees).
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// First modified point index.
    pub first: usize,
    /// Last modified point index (inclusive).
    pub last: usize,
    /// New C for `first..=last`, degrees (len = last − first + 1), before rounding.
    pub c_deg: Vec<f64>,
    /// 360° multiple to add to every point after `last` to the end of the path (0 if none).
    pub c_offset_deg: f64,
    /// Solver statistics of the solves that made this candidate.
    pub qp: QpStats,
}

/// Why no candidate was produced (a numerical outcome, not bad input).
#[derive(Debug, Clone, PartialEq)]
pub enum PatchFailure {
    /// The QP is infeasible or the solver did not converge.
    Solver(QpStats),
    /// No join indices with the sign of the net change exist within the run.
    NoJoin,
    /// Not enough points around the zone to fit or to join.
    TooShort,
}
