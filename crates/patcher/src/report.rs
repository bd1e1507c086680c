//! Per-zone results (the report rows).

use crate::analysis::ZoneKind;
use polepatch_kinematics::{Axis, LimitKind};
use serde::Serialize;

/// Equation-6 figures over a zone's s range, before or after patching.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ZoneFigures {
    /// Lowest C-limited ratio.
    pub c_ratio: f64,
    /// Lowest primary-limited ratio.
    pub primary_ratio: f64,
    /// Lowest overall ratio.
    pub overall_ratio: f64,
    /// Axis limiting there (`None`: the feed).
    pub limiting_axis: Option<Axis>,
    /// Limit binding there.
    pub limiting_kind: LimitKind,
    /// Estimated time ∫ds/ṡ over the s range, s.
    pub time_s: f64,
}

/// Outcome of one zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Outcome {
    /// C reaches feed (C ratio ≥ 1 on the written values).
    Reached,
    /// Improved, but C stays below feed (best improvement kept).
    Improved,
    /// Nothing better was found: original values kept.
    Unchanged,
}

/// Which formulation produced the written values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Method {
    /// G16 patch spline joined to C_b and C_a, CL points projected onto it.
    G16Patch,
    /// QP directly on the CL C values through the analysis spline (fallback).
    Direct,
    /// Nothing written.
    None,
}

/// Solver statistics, summed over every solve made for the zone.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct QpStats {
    /// Status of the last solve (clarabel's `SolverStatus` as text).
    pub status: String,
    /// Interior-point iterations, summed.
    pub iterations: u32,
    /// Number of QP solves.
    pub solves: u32,
    /// Solve time, seconds, summed.
    pub solve_time_s: f64,
}

/// One zone's report row (SPEC §5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ZoneReport {
    /// First point index of the zone / patch (whichever is wider).
    pub first: usize,
    /// Last point index.
    pub last: usize,
    /// Kind of zone.
    pub kind: ZoneKind,
    /// Smallest |primary| in the zone, degrees.
    pub min_abs_primary_deg: f64,
    /// Figures before patching over `[s(first), s(last)]`.
    pub before: ZoneFigures,
    /// Figures after patching, same s range, on the values as written.
    pub after: ZoneFigures,
    /// L/F over the same range, s.
    pub ideal_time_s: f64,
    /// Largest orientation deviation of a modified point, degrees.
    pub max_deviation_deg: f64,
    /// Points whose C changed.
    pub points_modified: usize,
    /// Length of the patched s range, mm.
    pub patch_length_mm: f64,
    /// Outcome.
    pub outcome: Outcome,
    /// Formulation that produced the values.
    pub method: Method,
    /// Solver statistics.
    pub qp: QpStats,
    /// Decimal places the modified C words need.
    pub decimals: usize,
    /// 360° multiple added to C after the zone (0 when none).
    pub c_offset_deg: f64,
}
