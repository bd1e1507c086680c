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
