//! Named tolerances and discretisation constants of the simulator, each with its unit.

/// Fraction of every axis limit (V, A, J) the simulator plans with. The plan holds the
/// limits at the start of each cycle; over one cycle Tcy the path derivatives, the feed
/// and the acceleration change by O(Tcy), which this margin absorbs (0.2 %).
pub const LIMIT_USE: f64 = 0.998;

/// Relative slack when comparing a feed with its ceiling (rounding only).
pub const CEILING_REL: f64 = 1e-9;

/// A pass ends when it is this close to the end of the path, mm. The last point is then
/// taken as reached (the spline is evaluated there exactly).
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

/// A state whose speed is within this fraction of a flat ceiling …
pub const CRUISE_REL: f64 = 1e-9;
/// … and whose |acceleration| is below this, mm/s², cruises: it may jump to the next grid
/// point in one step (when no trajectory is asked for). The acceleration set to 0 there
/// is far below any machine's A·Tcy.
pub const CRUISE_ACCEL_MM_S2: f64 = 1e-6;

/// Where the velocity limit is below what one cycle at the jerk cap makes
/// (W < j_cap·Tcy²), a pass at rest crawls at a speed whose step from rest is at most this
/// share of the jerk cap (finite differences: a jerk of this share for one cycle).
pub const CRAWL_JERK_SHARE: f64 = 0.5;
