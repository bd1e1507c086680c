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
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// C reaches feed (C ratio ≥ 1 on the written values).
    Reached,
    /// Improved, but C stays below feed (best improvement kept).
    Improved,
    /// Nothing better was found: original values kept.
    Unchanged,
}

impl Outcome {
    /// The name used in the reports of `polepatch` (its zone rows, the CSV, the summary):
    /// `reached`, `improved`, `unchanged`. (This type's own serde form, in
    /// [`ZoneReport`]'s JSON, is the variant's name.)
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Reached => "reached",
            Outcome::Improved => "improved",
            Outcome::Unchanged => "unchanged",
        }
    }
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a zone ended as it did: one of a fixed set (Ruckig's `Result` manner), documented
/// in [`crate::driver`] and `docs/method.md`; the summary table counts them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Reason {
    /// A patch reaches feed (joint, G16, direct, or a peer's rule).
    Reached,
    /// Branch re-selection alone reaches feed: no orientation change.
    Reselected,
    /// The run's last point must keep its values, and with it held no values reach feed
    /// while with it free some would (proven by the relaxation).
    EndPinned,
    /// The machine's axis ranges forbid every values that would reach feed (proven).
    Range,
    /// A patch reaching feed exists, but it changes the orientation by more than
    /// `max_deviation_deg`.
    DeviationCap,
    /// A patch reaching feed exists, but it turns some point's tool axis by more than the
    /// safety bound near the pole allows (twice the point's distance from the pole, and at
    /// most the pole reach: `crate::driver::pole_bound_deg`).
    SafetyBound,
    /// With a ball's centre kept (programmed at its tip): a patch reaches feed on the tip
    /// path it was solved on, but the tips it writes move with the orientation, and on
    /// them it falls short (the tip path's length did not settle:
    /// `SolverSettings::centre_s_iterations`).
    TipPath,
    /// No values of the movable points reach feed (the relaxation is infeasible: a proof).
    ProvenUnreachable,
    /// No patch found, and no proof that there is none (or a patch failed the whole-run
    /// verification).
    NotFound,
    /// The run may not be patched (no TCPM, incremental, …): the zone is only reported.
    NotPatched,
    // The reasons below are set by the library (`polepatch`), where the run's circumstances
    // decided, not the solve.
    /// The file does not settle whether TCPM is on (the run is untouched).
    TcpmUnknown,
    /// A rotation, scaling or mirror image of the frame is in force (the run is untouched).
    FrameTransformed,
    /// A Sinumerik direction form (`C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`) cannot make the
    /// patched move (the run is untouched).
    DirectionForm,
    /// The patch would change a word whose value is a macro variable or an expression (the
    /// run is untouched).
    MacroVariable,
    /// A ball programmed at its tip, its centre kept: the orientation change was capped to
    /// keep the centre's path between the points within the chord tolerance and the zone
    /// stopped at that cap, or no cap did and the run keeps its values.
    CentrePath,
    /// A flat or bull-nose cutter's surface bound capped the orientation change and stopped
    /// the zone short of feed.
    ToolLimited,
    /// The written program failed the check of the written bytes against the input
    /// (`polepatch::verify`) where this zone's run was patched: the run keeps its values,
    /// and the report's warnings say which line and which check.
    Verification,
}

impl Reason {
    /// Every reason, in report order.
    pub const ALL: [Reason; 17] = [
        Reason::Reached,
        Reason::Reselected,
        Reason::EndPinned,
        Reason::Range,
        Reason::DeviationCap,
        Reason::SafetyBound,
        Reason::TipPath,
        Reason::ProvenUnreachable,
        Reason::NotFound,
        Reason::NotPatched,
        Reason::TcpmUnknown,
        Reason::FrameTransformed,
        Reason::DirectionForm,
        Reason::MacroVariable,
        Reason::CentrePath,
        Reason::ToolLimited,
        Reason::Verification,
    ];
    /// The name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Reason::Reached => "reached",
            Reason::Reselected => "reselected",
            Reason::EndPinned => "end_pinned",
            Reason::Range => "range",
            Reason::DeviationCap => "deviation_cap",
            Reason::SafetyBound => "safety_bound",
            Reason::TipPath => "tip_path",
            Reason::ProvenUnreachable => "proven_unreachable",
            Reason::NotFound => "not_found",
            Reason::NotPatched => "not_patched",
            Reason::TcpmUnknown => "tcpm_unknown",
            Reason::FrameTransformed => "frame_transformed",
            Reason::DirectionForm => "direction_form",
            Reason::MacroVariable => "macro_variable",
            Reason::CentrePath => "centre_path",
            Reason::ToolLimited => "tool_limited",
            Reason::Verification => "verification",
        }
    }
}

impl std::fmt::Display for Reason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which formulation produced the written values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Branch re-selection alone: the points after the program's IK-branch switch moved to
    /// the other branch, `(P, C) → (−P, C ± 180°)` (no orientation change).
    Reselect,
    /// The joint patch of the primary axis and C ([`crate::joint`]).
    Joint,
    /// A peer strategy's rule ([`crate::peers`]), for the quality suite.
    Peer,
    /// G16 patch spline joined to C_b and C_a, CL points projected onto it.
    G16Patch,
    /// QP directly on the CL C values through the analysis spline (fallback).
    Direct,
    /// Nothing written.
    None,
}

impl Method {
    /// The name used in the reports of `polepatch`: `reselect`, `joint`, `peer`,
    /// `g16-patch`, `direct`, `none`. (This type's own serde form, in [`ZoneReport`]'s
    /// JSON, is the variant's name.)
    pub fn name(self) -> &'static str {
        match self {
            Method::Reselect => "reselect",
            Method::Joint => "joint",
            Method::Peer => "peer",
            Method::G16Patch => "g16-patch",
            Method::Direct => "direct",
            Method::None => "none",
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How a solve ended: clarabel's `SolverStatus`, plus polepatch's own outcomes of a solve
/// that was not run. A numerical outcome, not an error (SPEC: bad input is kept apart).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum QpStatus {
    /// No solve was made.
    #[default]
    NotRun,
    /// Solved to clarabel's default tolerances.
    Solved,
    /// Solved to reduced accuracy.
    AlmostSolved,
    /// Proven primal infeasible (no patch satisfies the constraints).
    PrimalInfeasible,
    /// Proven dual infeasible (unbounded; a modelling error if it happens).
    DualInfeasible,
    /// Primal infeasible to reduced accuracy.
    AlmostPrimalInfeasible,
    /// Dual infeasible to reduced accuracy.
    AlmostDualInfeasible,
    /// The iteration cap was reached.
    MaxIterations,
    /// The time cap was reached.
    MaxTime,
    /// clarabel stopped on a numerical error.
    NumericalError,
    /// clarabel stopped for lack of progress.
    InsufficientProgress,
    /// Not solved: a necessary condition showed the problem infeasible beforehand.
    SkippedInfeasible,
    /// The problem could not be set up (malformed matrices).
    SetupError,
}

impl QpStatus {
    /// clarabel's status as ours.
    pub fn from_clarabel(s: clarabel::solver::SolverStatus) -> QpStatus {
        use clarabel::solver::SolverStatus as S;
        match s {
            S::Unsolved | S::CallbackTerminated => QpStatus::NotRun,
            S::Solved => QpStatus::Solved,
            S::AlmostSolved => QpStatus::AlmostSolved,
            S::PrimalInfeasible => QpStatus::PrimalInfeasible,
            S::DualInfeasible => QpStatus::DualInfeasible,
            S::AlmostPrimalInfeasible => QpStatus::AlmostPrimalInfeasible,
            S::AlmostDualInfeasible => QpStatus::AlmostDualInfeasible,
            S::MaxIterations => QpStatus::MaxIterations,
            S::MaxTime => QpStatus::MaxTime,
            S::NumericalError => QpStatus::NumericalError,
            S::InsufficientProgress => QpStatus::InsufficientProgress,
        }
    }
    /// A usable solution came back (`Solved` or `AlmostSolved`).
    pub fn is_solved(self) -> bool {
        matches!(self, QpStatus::Solved | QpStatus::AlmostSolved)
    }
    /// Infeasibility was proven (by the solver, or beforehand).
    pub fn is_infeasible(self) -> bool {
        matches!(
            self,
            QpStatus::PrimalInfeasible
                | QpStatus::AlmostPrimalInfeasible
                | QpStatus::SkippedInfeasible
        )
    }
    /// The name used in reports (the variant's name).
    pub fn name(self) -> &'static str {
        match self {
            QpStatus::NotRun => "NotRun",
            QpStatus::Solved => "Solved",
            QpStatus::AlmostSolved => "AlmostSolved",
            QpStatus::PrimalInfeasible => "PrimalInfeasible",
            QpStatus::DualInfeasible => "DualInfeasible",
            QpStatus::AlmostPrimalInfeasible => "AlmostPrimalInfeasible",
            QpStatus::AlmostDualInfeasible => "AlmostDualInfeasible",
            QpStatus::MaxIterations => "MaxIterations",
            QpStatus::MaxTime => "MaxTime",
            QpStatus::NumericalError => "NumericalError",
            QpStatus::InsufficientProgress => "InsufficientProgress",
            QpStatus::SkippedInfeasible => "SkippedInfeasible",
            QpStatus::SetupError => "SetupError",
        }
    }
}

impl std::fmt::Display for QpStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Solver statistics, summed over every solve made for the zone.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct QpStats {
    /// Status of the last solve.
    pub status: QpStatus,
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
    /// First and last point of the zone's core (the zone ± the core margin, cut at the
    /// run's ends): where [`Outcome::Reached`] says the written values reach feed.
    pub core: [usize; 2],
    /// Figures before patching, over the spans of the zone and of the patch, ± the core
    /// margin (from the analysis of the whole run).
    pub before: ZoneFigures,
    /// Figures after patching, same spans, from the analysis of the whole run as written.
    pub after: ZoneFigures,
    /// L/F over the same range, s.
    pub ideal_time_s: f64,
    /// Largest orientation deviation of a modified point, degrees.
    pub max_deviation_deg: f64,
    /// Points of the zone's range whose primary axis or C changed.
    pub points_modified: usize,
    /// Points of the zone's range whose primary axis changed.
    pub primary_points_modified: usize,
    /// Points after the range re-selected onto the other IK branch as a block (same tool
    /// axes, both words rewritten).
    pub reselected_points: usize,
    /// Length of the patched s range, mm.
    pub patch_length_mm: f64,
    /// Outcome.
    pub outcome: Outcome,
    /// Why it ended so.
    pub reason: Reason,
    /// Formulation that produced the values.
    pub method: Method,
    /// Solver statistics.
    pub qp: QpStats,
    /// Decimal places the modified C words need.
    pub decimals: usize,
    /// Decimal places the modified primary-axis words need.
    pub p_decimals: usize,
    /// 360° multiple added to C after the zone (0 when none).
    pub c_offset_deg: f64,
    /// The smallest orientation change, degrees, of a patch found that reaches feed but
    /// exceeds `max_deviation_deg` (reason [`Reason::DeviationCap`]); `None` otherwise.
    pub needed_deviation_deg: Option<f64>,
}
