//! Named tolerances and discretisation constants of the simulator, each with its unit.

/// Fraction of every axis limit (V, A, J) the simulator plans with. The plan holds the
/// limits at the start of each cycle; over one cycle Tcy the path derivatives, the feed
/// and the acceleration change by O(Tcy), which this margin absorbs (0.2 %).
pub const LIMIT_USE: f64 = 0.998;

/// Relative slack when comparing a feed with its ceiling (rounding only).
pub const CEILING_REL: f64 = 1e-9;

/// A pass ends when it is this close to the end of the path, mm: the state that comes
/// this close is put at the end (one state, never a second one at the same time). The
/// last point is then taken as reached (the spline is evaluated there exactly).
pub const END_MM: f64 = 1e-5;

/// Bisection steps on the jerk of one cycle (the chosen jerk is within 2^-16 of the
/// largest safe one, relative to the jerk range).
pub const JERK_BISECTIONS: usize = 24;

/// Default largest number of cells per span of the path (between two programmed points).
/// A span is cut into ⌈h / (F·Tcy)⌉ cells (Equation 6's sampling step) up to this many,
/// so that the grid, and the memory, are bounded by the points, not by the run time.
pub const MAX_CELLS_PER_SPAN: usize = 8;

/// Fractions of the acceleration and jerk caps the backward pass plans with: the forward
/// pass follows the backward profile with the full caps, and this room lets it do so
/// within a cycle's discretisation (1 % of A, 2 % of J: the recorded profile is
/// interpolated between grid points, which bends it most where the jerk switches).
pub const BACKWARD_USE: [f64; 2] = [0.99, 0.98];

/// The backward pass records its state where the jerk changes by more than this fraction
/// of its size from one cycle to the next (a switch of the bang-bang profile).
pub const JERK_SWITCH: f64 = 0.25;

/// States of the backward pass's record held in one block (`Store` in lib.rs): 1.5 MB
/// of (x, v, a). The record grows a block at a time (the first as a vector grows, up to
/// this), never held twice.
pub const RECORD_BLOCK_STATES: usize = 1 << 16;

/// A state within this fraction of a flat ceiling (or [`CRUISE_ABS_MM_S`], the larger),
/// whose acceleration changes its speed by less than that in a cycle, cruises: when no
/// trajectory is asked for it jumps to the next grid point in one step with a = 0. The
/// speed and acceleration it drops are below 10⁻⁷ of the feed and 10⁻⁷·F/Tcy.
pub const CRUISE_REL: f64 = 1e-7;
/// … or this, mm/s (the resolution of the jerk bisection at the slowest feeds).
pub const CRUISE_ABS_MM_S: f64 = 1e-9;

/// Where the velocity limit is below what one cycle at the jerk cap makes
/// (W < j_cap·Tcy²), a pass at rest crawls at a speed whose step from rest is at most this
/// share of the jerk cap (finite differences: a jerk of this share for one cycle).
pub const CRAWL_JERK_SHARE: f64 = 0.5;

/// Within this fraction under a flat ceiling a pass settles (takes the jerk that brings
/// the acceleration to 0 when that is safe) instead of the largest safe jerk.
pub const SETTLE_REL: f64 = 1e-6;

/// Where the ceiling is below one cycle at the jerk cap (j_cap·Tcy², the crawl regime) a
/// state within this fraction of the ceiling cruises (see [`CRUISE_REL`]): the cycle is
/// too coarse there to come closer without chattering.
pub const CRAWL_CRUISE_REL: f64 = 1e-3;

/// `(1 + CEILING_REL)^(3/2)` to rounding (the next term, 3/8·CEILING_REL², is far below
/// it): [`CEILING_REL`] on P = W^(3/2), in which the passes compare speeds with their
/// ceiling without a cube root.
pub const CEILING_REL_P: f64 = 1.0 + 1.5 * CEILING_REL;

/// An acceleration counts as within its cap a_cap up to this fraction of the cap …
/// (rounding of the cap's terms: a state put exactly on the cap stays safe).
pub const A_CAP_SLACK_REL: f64 = 1e-12;
/// … plus this, mm/s² (rounding where the cap is near 0).
pub const A_CAP_SLACK_MM_S2: f64 = 1e-12;

/// Pieces of the look-ahead ramp of a safe state (pass.rs module docs: a down to the
/// ceiling's a_W at the jerk cap, checked under the ceiling at the end of each piece).
pub const RAMP_STEPS: usize = 8;
/// Pieces of that ramp checked at most (the ceiling's a_W moves as the ramp goes, so the
/// ramp may take longer than the first estimate; four estimates' worth).
pub const RAMP_STEPS_MAX: usize = 4 * RAMP_STEPS;
/// The ramp's jerk at least this, mm/s³: where the jerk cap is 0 the ramp is long (and
/// fails the ceiling), not a division by 0.
pub const RAMP_JERK_FLOOR_MM_S3: f64 = 1e-300;

/// Halvings of a time within one cycle (when the speed reaches 0 within it, when x
/// reaches the end of the path): 2⁻⁶⁰ of Tcy, below the rounding of t.
pub const TIME_BISECTIONS: usize = 60;

/// A step is one interpolation cycle when its time is Tcy to within this fraction of Tcy
/// (the rounding of t summed over cycles); the trajectory's `cycle` flag.
pub const CYCLE_MATCH_REL: f64 = 1e-9;

/// A jumped cruise is cut into its whole cycles with this slack, in cycles (the rounding
/// of its time over Tcy: a cruise of exactly n cycles is n, not n − 1).
pub const CYCLE_COUNT_SLACK: f64 = 1e-9;

/// A cycle of a cut cruise whose time is within this fraction of the cruise's end time
/// (relative to that time, at least 1 s) is the end itself, not a cycle before it.
pub const TIME_MATCH_REL: f64 = 1e-12;

/// A crawl (a pass that makes no progress, pass.rs) moves this fraction under the
/// velocity limit: strictly under it, so that the crawl is never a clip against it.
pub const CRAWL_UNDER_LIMIT_REL: f64 = 1e-9;

/// Steps without progress in a row after which a pass gives up: the limits allow no
/// motion there (`SimError::Stalled`). About 17 minutes of cycles at 1 ms.
pub const STALL_STEPS: u32 = 1_000_000;

/// Steps a rewinding pass keeps before handing them out: how far back a rewind can go
/// (16 s of cycles at 1 ms; at most this many steps held).
pub const REWIND_STEPS: usize = 16_384;
/// How far a rewinding forward pass may be above the backward profile (under the
/// velocity limit) and go on braking, relative to the profile.
pub const OVER_PROFILE_REL: f64 = 2e-3;
/// Steps a pass may undo by rewinds: one per this many steps taken, plus
/// [`REWIND_BUDGET_STEPS`]; past it, clips (the work stays within a small multiple of
/// the motion's cycles where the profile is clipped at almost every cycle).
pub const REWIND_BUDGET_PER_STEP_INV: u64 = 4;
/// See [`REWIND_BUDGET_PER_STEP_INV`], steps.
pub const REWIND_BUDGET_STEPS: u64 = 100_000;
/// Tries per dip: each lowers its speed by the factor [`DIP_TIGHTEN`].
pub const DIP_TRIES: u32 = 40;
/// Factor on a dip's speed when the motion is above the ceiling there again (the
/// braking is computed coarser than the motion).
pub const DIP_TIGHTEN: f64 = 0.97;
/// Dips kept at once, at most (beyond: clips).
pub const DIPS_MAX: usize = 4096;
/// A state above its ceiling within this many cycles' travel of a dip (at the larger of
/// the speeds at the two ends of the cycle) is at that dip …
pub const DIP_NEAR_CYCLES: f64 = 2.0;
/// … plus this, mm (rounding at a standstill).
pub const DIP_NEAR_MM: f64 = 1e-9;
/// The braking a rewind checks against the dips is in pieces of at least this many
/// cycles …
pub const BRAKE_PIECE_CYCLES: f64 = 4.0;
/// … and of at least this fraction of the time to the next dip at the speed where each
/// starts (the inverse: 8 pieces to the next dip).
pub const BRAKE_PIECES_TO_GO: f64 = 8.0;
/// Pieces of that braking, at most (beyond: the state cannot brake in time).
pub const BRAKE_PIECES_MAX: usize = 100_000;
/// Share of the |a| at which the jerk cap runs out (`Caps::a_for_jerk`) that the
/// braking holds (room for the jerk to bring it back).
pub const BRAKE_A_SHARE: f64 = 0.8;
/// The time to the next dip is taken at a speed of at least this, mm/s (a braking that
/// starts at rest).
pub const BRAKE_SPEED_FLOOR_MM_S: f64 = 1e-12;

/// The first guess of the passes' cube root: the bits of p divided by 3 plus this
/// (two thirds of the exponent bias, 1023·2⁵²·2/3, lowered to balance the guess's error
/// over a binade: within about 3 % everywhere).
pub const CBRT_GUESS_BIAS: u64 = 0x2A9F_7893_782D_A1CE;
/// Halley steps from that guess (cubic convergence: 3 % → 10⁻⁵ → 10⁻¹⁵ → rounding).
pub const CBRT_HALLEY_STEPS: usize = 3;

/// Grid points whose path derivatives are evaluated in one batch (`Grid::new`): the
/// batch's derivatives, 160 bytes a point, are held at once (640 kB).
pub const GRID_BATCH_POINTS: usize = 4096;

/// LinuxCNC's planner model (linuxcnc.rs): displacements below this are no motion,
/// mm or ° (emccanon's `applyMinDisplacement`).
pub const LCNC_MIN_DISPLACEMENT: f64 = 1e-7;
/// LinuxCNC's `TP_VEL_EPSILON` (tp_types.h), mm/s.
pub const LCNC_VEL_EPSILON: f64 = 1e-8;
/// LinuxCNC's `TP_POS_EPSILON` (tp_types.h), mm.
pub const LCNC_POS_EPSILON: f64 = 1e-12;
/// LinuxCNC's `TP_TIME_EPSILON` (tp_types.h), s.
pub const LCNC_TIME_EPSILON: f64 = 1e-12;
/// Bound on the cycles of one run of the LinuxCNC model, per segment: a segment that
/// does not finish within this many cycles means the model is stuck (never seen; a
/// guard, not a limit).
pub const LCNC_MAX_CYCLES_PER_SEGMENT: usize = 10_000_000;

/// Shares of each axis' A and J that a segment's speed may take with its curvature terms
/// (|q_ss|·V² ≤ σ·A, |q_sss|·V³ ≤ σ·J), leaving the rest for the path's acceleration and
/// jerk (`segments.rs`): a high share cruises faster, a low one changes speed faster; the
/// motion is planned with each and the fastest plan kept.
pub const SPEED_SHARES: [f64; 2] = [0.8, 0.5];
/// A grid cell joins the segment before it while the merged segment's V, A and J each
/// stay at or above this share of the largest of its cells' own (`segments.rs`). The
/// motion is planned once per share (few long segments with low limits, or many short
/// ones with a = 0 between them) and the fastest plan is the motion.
pub const MERGE_RATIOS: [f64; 4] = [0.8, 0.6, 0.4, 0.2];
/// Largest path acceleration of a segment where no axis bounds it (no axis moves), mm/s².
pub const SEGMENT_A_MAX_MM_S2: f64 = 1e9;
/// Largest path jerk of a segment where no axis bounds it, mm/s³.
pub const SEGMENT_J_MAX_MM_S3: f64 = 1e12;
/// Speeds, as shares of a segment's V, at which its caps are taken again for the speed
/// changes below them (ascending, the last 1: the caps fall with the speed, so a change
/// at low speed may accelerate and jerk harder; `segments.rs`).
pub const BAND_SHARES: [f64; 5] = [0.25, 0.5, 0.7, 0.85, 1.0];
/// The search for the largest speed a change reaches within a length stops when its
/// bracket is within this share of the speed.
pub const REACH_REL: f64 = 1e-9;
/// A junction's speed is known before the motion after it is (`segments.rs::Lookahead`)
/// where the segment after it changes between the junction's cap and any lower speed in
/// its length less this share: room for the searches that give the speeds (exact to
/// [`REACH_REL`], far below this).
pub const JUNCTION_CAP_ROOM: f64 = 1e-6;
/// Newton steps that polish the closed-form root of a speed change's length
/// (`segments.rs::reach`).
pub const REACH_NEWTON_STEPS: usize = 3;

/// A motion planned in at least this many segments (summed over the plans compared) has
/// its plans' times, and its pieces, made on all cores (`segments.rs::plan`): the same
/// numbers, in less time; a shorter one on one thread, where handing work to others
/// costs more than it saves.
pub const PARALLEL_MIN_SEGMENTS: usize = 512;
