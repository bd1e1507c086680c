//! The patcher's numerical settings in one place (Clarabel's `DefaultSettings` manner):
//! a plain struct, every field public and documented with its unit and default.
//!
//! [`SolverSettings::default`] is what `polepatch patch` uses; [`SolverSettings::reference`]
//! is the same with more effort, what the quality suite judges the default against
//! ([`crate::reference`]).
//!
//! These are the knobs of the methods (weights, trust regions, widening and iteration
//! counts); the fixed round-off tolerances and window sizes every method shares are in
//! [`crate::tolerances`].

use crate::ipm::IpmSettings;

// --- The options' defaults ---------------------------------------------------------------

/// Default singular cone, degrees: every stretch where C is below feed and the primary
/// axis comes this close to the pole is a zone ([`crate::analysis::detect_zones`]). 5°:
/// the rule before the pole reach (issue 30, docs/history.md); near the pole a large change
/// of C is a small change of tool axis (≈ sin|P|·ΔC).
pub const CONE_DEG: f64 = 5.0;

/// Default pole reach, degrees: out to this distance from the pole, a stretch where C is
/// below feed is a zone when the pole accounts for at least half its slowdown
/// ([`crate::analysis::pole_dominates`]). 10°, measured (docs/history.md, issue 30): it
/// finds a real Haas UMC program's corners at B 6.2°–7.4° as one zone each, where a 15°
/// reach also joins the last span of C17's `%SING` to its zone and makes G16's method
/// worse there.
pub const POLE_REACH_DEG: f64 = 10.0;

/// Numerical settings of the patcher (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SolverSettings {
    // --- The driver -------------------------------------------------------------------
    /// Factors applied to `PatchOptions::margin`, in order, when no candidate passes
    /// verification: the configured margin, a quarter of it, none. Default `[1, 0.25, 0]`.
    pub margin_ladder: Vec<f64>,
    /// Zones closer than this many points are patched as one. Default 6.
    pub merge_gap_points: usize,
    /// Points either side of a zone whose spans must reach feed with it (the zone's
    /// "core"): what the verification of every candidate checks, what the report's
    /// figures and the proofs cover. Default 3.
    pub core_margin_points: usize,
    /// Tries at scaling a change that reaches feed beyond `max_deviation_deg` into the cap
    /// (the best improvement within it). Default 4.
    pub scale_tries: usize,
    /// Each scaling try aims this fraction of the cap (dimensionless: the deviation is
    /// nearly, not exactly, linear in the scale; rounding adds a little). Default 0.98.
    pub scale_safety: f64,
    /// With a ball's centre kept: solves of a path whose tips move, at most (the tip
    /// path's length s is solved again on the tips the last solve wrote). Default 4.
    pub centre_s_iterations: usize,
    /// With a ball's centre kept: relative change of a block's length (dimensionless)
    /// below which the tip path's length has settled. Default 1e-3.
    pub centre_s_tol: f64,
    /// With a ball's centre kept: narrowing a patch that slowed a linear axis away from its
    /// zone moves its bound at least 1/`narrow_step_div` of the way to the zone. Default 4.
    pub narrow_step_div: usize,

    // --- The joint patch (crate::joint) ----------------------------------------------
    /// Points added on each side of the zone to the range the joint patch may change
    /// first (clipped to the run): at least this many, or the zone's own length times
    /// [`SolverSettings::joint_range_zone_factor`]; doubled while no solution meets the
    /// limits (`crate::joint_method`). Default 10.
    pub joint_range_min_points: usize,
    /// See [`SolverSettings::joint_range_min_points`]. Default 1.0.
    pub joint_range_zone_factor: f64,
    /// Most SCP solves from the chosen start. Default 6.
    pub scp_max_solves: u32,
    /// Solves a start gets when several are screened (the best then goes on): the first
    /// from every start, the rest only for the [`SolverSettings::screen_keep`] best after
    /// one (one solve from a start far outside the limits does not rank the starts well
    /// enough to keep only one). Default 2.
    pub screen_solves: u32,
    /// Starts that go on screening after their first solve. Default 2.
    pub screen_keep: usize,
    /// Tolerance of the interior-point method (feasibility and gap; at least
    /// [`IpmSettings::tol_feas`] and [`IpmSettings::tol_gap`]) in each start's first solve
    /// when several are screened: that solve only ranks the starts, and those that go on
    /// are solved again at the full tolerance from where it ended. Default 1e-4.
    pub screen_ipm_tol: f64,
    /// After that first solve a start ranks as within the limits when its relative excess
    /// over them is at most this (at least [`SolverSettings::elastic_tol`]), and goes on
    /// with the narrow trust region: a loosely solved QP can leave the excess of a start
    /// that meets the limits just above `elastic_tol` (one that cannot meet them stays far
    /// above: 0.1–0.5 on the held-out-like zones). Default 1e-3.
    pub screen_within_tol: f64,
    /// An accepted step that lowers the exact largest deviation by less than this fraction
    /// ends the SCP. Default 0.01.
    pub scp_rel_tol: f64,
    /// Trust region of the first solve, primary axis, degrees. Default 15.
    pub first_trust_p_deg: f64,
    /// Trust region of the first solve, C, degrees (near the pole C may have to move half
    /// a turn). Default 180.
    pub first_trust_c_deg: f64,
    /// Trust region of later solves, primary axis, degrees. Default 2.
    pub trust_p_deg: f64,
    /// Trust region of later solves, C, degrees. Default 30.
    pub trust_c_deg: f64,
    /// The SCP ends when the primary trust region falls below this, degrees.
    /// Default 1e-3.
    pub min_trust_deg: f64,
    /// μ: weight of the sum of squared linearised orientation changes against the largest
    /// (dimensionless): small, it chooses among the minimax solutions. Default 1e-2.
    pub joint_quad_weight: f64,
    /// ε: proximal weight on each step, per degree². Default 1e-8.
    pub proximal_weight: f64,
    /// M: weight of the elastic variable `e` (the largest relative excess over a limit
    /// row) against the largest orientation change (chord). Reaching feed comes first.
    /// Default 1e4.
    pub elastic_weight: f64,
    /// Relative excess over the limit rows (`e`) below which a joint solution counts as
    /// within them (the margin covers it). Default 1e-6.
    pub elastic_tol: f64,
    /// With a cap (`max_deviation_deg`): weight of the largest orientation change (chord)
    /// in the SCP's merit against the excess over the limits and the cap, only to break
    /// ties (dimensionless). Default 1e-6.
    pub cap_tie_weight: f64,
    /// Each SCP solve after the first of a [`crate::joint::solve_joint`] starts the
    /// interior-point method from the previous solve's multipliers and the iterate
    /// (`crate::ipm::Problem::solve_warm`) instead of cold. Default true.
    pub scp_warm_start: bool,
    /// The interior-point solver's settings ([`crate::ipm`]). Default: the objective not
    /// scaled ([`IpmSettings::scale_objective`] false) and a gap tolerance of 1e-7 on it;
    /// the rest [`IpmSettings::default`].
    pub ipm: IpmSettings,
    /// The interior-point solver's settings in a capped joint solve (`max_deviation_deg`,
    /// or the safety bound near the pole: the least excess over the limits within the
    /// caps). Its objective is the excess, weighted by
    /// [`SolverSettings::elastic_weight`], so the scaled objective's gap is already on
    /// its scale. Default [`IpmSettings::default`] (the objective scaled, tolerances
    /// 1e-8).
    pub capped_ipm: IpmSettings,
    /// Margin on the limits of the reference's joint solves ([`crate::reference`]; the
    /// patcher's is `PatchOptions::margin`): just enough that its solution passes the
    /// verification's round-off tolerances. Default 1e-3.
    pub reference_margin: f64,

    // --- The C-only method (crate::c_only) --------------------------------------------
    /// Largest range the direct QP is tried on, points. Default 400.
    pub direct_max_points: usize,
    /// A widening level after the first passing candidate that lowers the best deviation
    /// by less than this fraction of it ends the search. Default 0.05.
    pub deviation_improvement_min: f64,
    /// Most widening levels tried after the level of the first passing candidate.
    /// Default 3.
    pub max_levels_after_pass: usize,

    // --- The direct QP (crate::direct) -----------------------------------------------
    /// μ·m: weight of the quadratic pull-back term, per degree², divided by the number m of
    /// changed points (small, so the minimax term dominates). Default 1e-4.
    pub direct_quad_weight: f64,
    /// ε: added to `sin² P` in the quadratic term so a point exactly at the pole stays
    /// determined (dimensionless). Default 1e-6.
    pub direct_pole_regularisation: f64,

    // --- G16's patch (crate::g16) -----------------------------------------------------
    /// CL points beyond the zone (and the patch extension) on each side used to fit C_b
    /// and C_a. Default 30.
    pub g16_fit_margin_points: usize,
    /// Join-search step as a fraction of the median CL spacing (dimensionless).
    /// Default 0.05.
    pub g16_join_step_fraction: f64,
    /// μ: weight of the least-squares deviation term, 1/degree (the minimax term t has
    /// weight 1): small, it only picks a solution among the minimax optima. Default 1e-3.
    pub g16_lsq_weight: f64,
    /// ε: weight of the jerk energy ∫P'''² ds, mm⁵/degree: small, it smooths the patch
    /// where the deviation does not bind. Default 1e-3.
    pub g16_jerk_weight: f64,
    /// CL points closer than this fraction of the median spacing to a join are not made
    /// breakpoints of the patch (a very short span conditions the QP badly); they are still
    /// projected (dimensionless). Default 0.05.
    pub g16_min_span_fraction: f64,
    /// Most attempts (join-window enlargements plus patch widenings) before giving up.
    /// Default 24.
    pub g16_max_attempts: usize,
    /// Probes per support interval when computing the monotonicity floor ℓ_k in the
    /// extensions. Default 8.
    pub g16_monotone_probes: usize,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            margin_ladder: vec![1.0, 0.25, 0.0],
            merge_gap_points: 6,
            core_margin_points: 3,
            scale_tries: 4,
            scale_safety: 0.98,
            centre_s_iterations: 4,
            centre_s_tol: 1e-3,
            narrow_step_div: 4,
            joint_range_min_points: 10,
            joint_range_zone_factor: 1.0,
            scp_max_solves: 6,
            screen_solves: 2,
            screen_keep: 2,
            screen_ipm_tol: 1e-4,
            screen_within_tol: 1e-3,
            scp_rel_tol: 0.01,
            first_trust_p_deg: 15.0,
            first_trust_c_deg: 180.0,
            trust_p_deg: 2.0,
            trust_c_deg: 30.0,
            min_trust_deg: 1e-3,
            joint_quad_weight: 1e-2,
            proximal_weight: 1e-8,
            elastic_weight: 1e4,
            elastic_tol: 1e-6,
            cap_tie_weight: 1e-6,
            scp_warm_start: true,
            ipm: IpmSettings {
                scale_objective: false,
                tol_gap: 1e-7,
                ..IpmSettings::default()
            },
            capped_ipm: IpmSettings::default(),
            reference_margin: 1e-3,
            direct_max_points: 400,
            deviation_improvement_min: 0.05,
            max_levels_after_pass: 3,
            direct_quad_weight: 1e-4,
            direct_pole_regularisation: 1e-6,
            g16_fit_margin_points: 30,
            g16_join_step_fraction: 0.05,
            g16_lsq_weight: 1e-3,
            g16_jerk_weight: 1e-3,
            g16_min_span_fraction: 0.05,
            g16_max_attempts: 24,
            g16_monotone_probes: 8,
        }
    }
}

impl SolverSettings {
    /// The same settings with more effort: the reference the quality suite judges the
    /// default against: more solves, more screening, a tighter stopping rule (the range
    /// is the caller's: the whole movable territory). Its interior-point method stays as
    /// it was when the quality figures were first taken (regularised factorisation,
    /// `unregularised_first` false; the objective scaled, tolerances 1e-8; every solve
    /// cold, `scp_warm_start` false; every start's first solve to the full tolerance), so
    /// that a change of the default's solver is judged against the same reference.
    pub fn reference() -> SolverSettings {
        SolverSettings {
            scp_max_solves: 24,
            screen_solves: 3,
            scp_rel_tol: 1e-3,
            scp_warm_start: false,
            screen_ipm_tol: 0.0,
            screen_within_tol: 0.0,
            ipm: IpmSettings {
                unregularised_first: false,
                ..IpmSettings::default()
            },
            capped_ipm: IpmSettings {
                unregularised_first: false,
                ..IpmSettings::default()
            },
            ..SolverSettings::default()
        }
    }
}

/// Most decimal places a rotary value may be written with (`max_decimals`): beyond 9 the
/// written digits are below any control's resolution and only lengthen the file.
pub const MAX_WRITTEN_DECIMALS: usize = 9;
