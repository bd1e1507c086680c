//! The patcher's numerical tolerances in one place (kurbo's `DEFAULT_ACCURACY`, ruckig's
//! `profile.hpp`): round-off allowances, the accuracy of local models (how many points of
//! unchanged path a window keeps), sample counts of relaxations and bounds, and solver
//! caps. Each has a doc line with its unit and why it has its value.
//!
//! The knobs of the methods themselves — weights, trust regions, widening and iteration
//! counts, the margin ladder — are fields of [`crate::SolverSettings`], which a caller may
//! change per call. What is here is fixed: changing one changes what "equal", "not worse"
//! or "enough points" mean, and every method together with it.
//!
//! The option defaults that are not fields' literals (the singular cone [`crate::CONE_DEG`],
//! the pole reach [`crate::POLE_REACH_DEG`]) are in [`crate::settings`]; the limits of the
//! options (what [`crate::PatchOptions::validate`] accepts) stay with the options.

// --- Equation 6 and "not worse" ------------------------------------------------------

/// Ratios below `1 − RATIO_TOL` count as "below feed" (absorbs round-off in the bound).
pub const RATIO_TOL: f64 = 1e-9;

/// Resolution of the "not lower than before" comparison: a ratio may fall by this fraction
/// of itself (0.01 %, a feed difference no controller resolves). It absorbs round-off, the
/// solvers' own tolerance (clarabel's feasibility tolerance is relative to the problem's
/// norms: with C changes of 100° the slope equalities hold to ~1e-7, which q''' multiplies
/// by 6/h²; measured: 3.6e-6 on q''' at 0.25 mm spacing) and what a change propagates,
/// through the spline's decay, beyond the window a solver constrains.
pub const NOT_WORSE_REL: f64 = 1e-4;

/// Relative slack of a solver's "not worse than before" row: a bound is the value before
/// times `1 + NOT_WORSE_SLACK` (round-off only; the verification allows
/// [`NOT_WORSE_REL`]).
pub const NOT_WORSE_SLACK: f64 = 1e-9;

/// Slack on `max_deviation_deg`, degrees: a written deviation up to the cap plus this is
/// within it (round-off of the exact angle).
pub const CAP_SLACK_DEG: f64 = 1e-9;

/// With a ball's centre kept, a later solve on the settled tip path that reaches feed on no
/// more zones is kept only when it lowers the zones' estimated time by more than this
/// fraction (the estimate's own accuracy, `TIME_REL_TOL`, is 10⁻³ per span).
pub const CENTRE_TIME_REL: f64 = 1e-3;

/// A largest orientation change at or below this, degrees, is none: a start within the
/// limits with it cannot be bettered (the joint patch stops there).
pub const ZERO_DEVIATION_DEG: f64 = 1e-9;

/// |P| at or below which a point counts as on the pole, degrees: C does not orient the
/// tool there, so C's continuity is judged on the points off it.
pub const POLE_DEG: f64 = 1e-6;

// --- The analysis's time --------------------------------------------------------------

/// A piece of a span is bisected while the bound on its time error exceeds this fraction
/// of its time ([`crate::analysis`]).
pub const TIME_REL_TOL: f64 = 1e-3;

/// Most bisections of a span for its time (at most `2^TIME_MAX_DEPTH` pieces).
pub const TIME_MAX_DEPTH: u32 = 6;

// --- Windows: how much unchanged path a local model keeps ------------------------------
//
// The influence of a changed value on the analysis spline decays by a factor
// ≈ 2 − √3 ≈ 0.27 per knot: n points of unchanged path make a window's spline equal to the
// whole path's to about 0.27ⁿ of the change.

/// Points of unchanged path kept either side of a change when verifying it
/// ([`crate::verify`]): 0.27³⁰ ≈ 10⁻¹⁷, round-off.
pub const VERIFY_MARGIN_POINTS: usize = 30;

/// Points of unchanged path either side of a candidate's change and its zone that the
/// driver's candidate check hands the verification (the whole run is verified again at
/// the end): one more than [`VERIFY_MARGIN_POINTS`].
pub const CHECK_MARGIN_POINTS: usize = VERIFY_MARGIN_POINTS + 1;

/// Spans next to a verification window's end that was cut (not a path end) left out of
/// the "never worse" comparison: there the window's spline differs from the whole path's.
pub const WINDOW_GUARD_SPANS: usize = 10;

/// Points of the path kept either side of the modified range as Hermite unknowns in the
/// direct QP and the C-only bound ([`crate::hermite`]); beyond them the slope is fixed to
/// the current spline's.
pub const HERMITE_WINDOW_POINTS: usize = 16;

/// Points either side of the modified range whose spans a Hermite QP constrains.
pub const CONSTRAINED_MARGIN_POINTS: usize = 3;

/// Points of the path either side of the moving range in the joint patch's window
/// ([`crate::joint`]). The window's spans next to a cut end are left out of the rows
/// ([`EDGE_SPANS`]): the fixed end slope is exact only to about 0.27^window of the change.
pub const JOINT_WINDOW_POINTS: usize = 24;

/// Spans at each end of a joint window inside the path left unconstrained: the fixed end
/// slope's error (about 0.27^window of the change) enters q''' amplified by 6/h² next to
/// the end; 8 spans further it has decayed by 0.27⁸ ≈ 3·10⁻⁵.
pub const EDGE_SPANS: usize = 8;

/// At least this many points of the path either side of a joint window go into the
/// spline the window's end slopes are taken from.
pub const WIDEN_POINTS: usize = 16;

/// A limit row of the joint window is never bounded below this fraction of its limit
/// (the room for rounding and "not worse" may eat the rest): the row stays well posed.
pub const MIN_ROW_BOUND: f64 = 1e-3;

// --- Samples of relaxations and bounds ------------------------------------------------

/// Rows per span (plus the spline's vertex of q' before) of the joint window's "not worse"
/// velocity rows on a span that exceeded the velocity limit before.
pub const NOT_WORSE_SAMPLES_PER_SPAN: usize = 8;

/// Samples of q' per span in the relaxation behind the reasons ([`crate::proof`], its ends
/// included). Fewer samples keep it a relaxation; more tighten it.
pub const PROOF_SAMPLES_PER_SPAN: usize = 8;

/// Spans beyond the movable points and the core that the relaxation constrains (fewer
/// constraints keep it a relaxation; these are where a change still matters).
pub const PROOF_SPAN_MARGIN: usize = 40;

/// Samples per span of the C-only deviation bound ([`crate::direct::deviation_bound_sampled`],
/// both ends included): the bound checks the limits there only, a relaxation of the exact
/// requirement (every s of the span), so it stays a lower bound; more samples tighten it.
/// Bounded per span whatever the feed.
pub const BOUND_SAMPLES_PER_SPAN: usize = 32;

/// Most bisection steps of the C-only deviation bound.
pub const BOUND_BISECTIONS: usize = 25;

/// The C-only deviation bound stops bisecting when the bracket is narrower than this
/// fraction of its upper end (the bound is then known to 0.01 %).
pub const BOUND_REL_TOL: f64 = 1e-4;

/// Steps of the trapezoid rule in G16's reachability test (the largest change of C a
/// velocity envelope allows over a patch, [`crate::g16`]).
pub const REACH_STEPS: usize = 256;

/// Relative slack of G16's reachability test that skips hopeless widenings (the trapezoid
/// rule under-estimates the integral of the concave velocity envelope slightly).
pub const REACH_SLACK: f64 = 1e-3;

// --- Solvers ---------------------------------------------------------------------------

/// Clarabel's iteration cap. The patcher's QPs converge or prove infeasibility in 10–30
/// iterations; one that has not after this many is reported as not solved rather than
/// ground on (clarabel's default is 200). Tolerances stay at clarabel's defaults (1e-8):
/// looser ones change which candidates pass verification. (The joint patch's own solver
/// has its settings in [`crate::SolverSettings::ipm`].)
pub const CLARABEL_MAX_ITER: u32 = 60;

/// A path segment whose tool tips are closer than this, mm, has no feed scale of its own
/// ([`crate::centre::segment_scale`]: 1).
pub const ZERO_SEGMENT_MM: f64 = 1e-9;

/// The SCP of the joint patch ([`crate::joint::solve_joint`]) stops when an accepted step
/// gains less than [`crate::SolverSettings::scp_rel_tol`] times the merit, the merit
/// taken at least this (dimensionless): at a merit of 0 it still stops on a gain of
/// round-off instead of going on to its last solve.
pub const SCP_MERIT_FLOOR: f64 = 1e-12;

/// The smallest cap of a point in a capped joint solve, degrees (a point exactly on the
/// pole whose bound is 0 still gets a cone that is not degenerate; the driver measures
/// the written angle against the bound itself).
pub const MIN_POINT_CAP_DEG: f64 = 1e-6;

/// A pivot of the joint window's dense elimination ([`crate::window`]) at or below this
/// fraction of the matrix's largest entry vanishes (dimensionless): some thousands of
/// times double precision's round-off, where the eliminated end slopes would carry no
/// digits.
pub const PIVOT_REL_TOL: f64 = 1e-12;

/// A sign row `σ·f ≥ 0` of a Hermite QP ([`crate::hermite`]) is divided by its largest
/// coefficient, at least this (in the row's units): a row of zeros is left as it is
/// instead of divided by zero.
pub const SIGN_ROW_SCALE_FLOOR: f64 = 1e-300;

// --- Zero tests -----------------------------------------------------------------------

/// A net change of C over a C-only range at or below this, degrees, has no direction
/// ([`crate::c_only`]: the direct QP is then tried without a monotone direction): a
/// change of round-off size has no sign to hold to.
pub const ZERO_NET_C_DEG: f64 = 1e-9;

/// The shift that puts the points after a branch switch on the other branch is taken in
/// (−180°, 180°] up to this slack, degrees ([`crate::starts::tail_shift`]): a shift of
/// 180° that the wrapping left a round-off above it is +180°, not −180°.
pub const HALF_TURN_SLACK_DEG: f64 = 1e-9;

/// Slack on the upper end of the C-only deviation bound's bracket, degrees
/// ([`crate::direct::deviation_bound_sampled`]): 2·asin(max w) allows every change, and
/// the slack keeps the round-off of the `asin` from making that end infeasible.
pub const BOUND_BRACKET_SLACK_DEG: f64 = 1e-9;

/// Points either side of a zone over which G16's method takes the median CL spacing
/// ([`crate::g16`]: its join step and shortest span are fractions of it): a few, so the
/// spacing is the zone's own, not the path's elsewhere.
pub const G16_SPACING_POINTS: usize = 5;

// --- The interior-point method (crate::ipm) --------------------------------------------

/// Iterative refinement of a KKT solve stops when the residual is below this fraction of
/// `1 + ‖rhs‖∞` (dimensionless): a few hundred times double precision's round-off, below
/// which a step only moves round-off.
pub const IPM_REFINE_REL_TOL: f64 = 1e-13;

/// A cold start's slacks and multipliers are shifted into their cones unless they lie at
/// least this deep inside already (on the equilibrated problem): a point on a cone's
/// boundary leaves the first step no room.
pub const IPM_COLD_DEPTH: f64 = 1e-8;

/// After each step the linear slacks and multipliers are at least this: one that rounded
/// to 0 would make the scaling `z/s` infinite or zero.
pub const IPM_SLACK_FLOOR: f64 = 1e-300;
