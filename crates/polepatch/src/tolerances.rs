//! The crate's numerical tolerances, each with its unit and why it has its value: how close
//! two numbers must be to be the same (a tip, an axis, a ratio, a time), and the slack the
//! checks allow for rounding. Each is re-exported by the module that uses it, under the name
//! it had there.

// From joints.rs.
/// A tool axis shorter than this (in the units of i j k) is taken for zero and refused:
/// it has no direction to normalise.
pub const ZERO_AXIS_NORM: f64 = 1e-9;

// From joints.rs.
/// Two consecutive tool tips closer than this, mm, are the same point: a run cannot stand
/// still (s must increase), so it is refused with a hint to split the run there.
pub const SAME_TIP_MM: f64 = 1e-9;

// From machine_frame.rs.
/// The part-frame tool tip of a rewritten block without TCPM must be within this of the
/// original, mm (issue 10: "to the file's precision", 1 µm).
pub const TIP_TOLERANCE_MM: f64 = 1e-3;

// From machine_frame.rs.
/// Fewest decimals written for X Y Z recomputed through the chain: rounding to 3 decimals
/// moves a point by at most 0.0005·√3 ≈ 0.00087 mm < [`TIP_TOLERANCE_MM`].
pub const MIN_XYZ_DECIMALS: usize = 3;

// From machine_frame.rs.
/// A part-frame segment shorter than this is a rotary repositioning about the tool tip
/// (mm): without TCPM the program's X Y Z move with it, so the run goes on; in the part
/// frame the tool tip stands still, and the patcher treats the pieces either side as
/// separate paths (as a TCPM program's zero-length block splits its runs).
pub const PART_ZERO_LENGTH_MM: f64 = TIP_TOLERANCE_MM;

// From patch.rs.
/// The cap of such a retry: the deviation that gave the excursion, scaled by the tolerance
/// over the excursion and by this margin.
pub const CENTRE_PATH_CAP_SAFETY: f64 = 0.9;

// From patch.rs.
/// Below this, a positioning move's time after a run is the same before and after a patch
/// (what the end's choice ignores), s.
pub const RAPID_TIME_TOL_S: f64 = 1e-3;

// From patch.rs.
/// Fewest decimals for X Y Z of an inch program rewritten to keep a ball's centre
/// (5: 0.25 µm per axis).
pub const MIN_INCH_XYZ_DECIMALS: usize = 5;

// From post.rs.
/// Two tool axes closer than this (unit vectors, |a − b|) are the same axis: an arc
/// between them keeps a fixed tool axis. CAM files write i j k with 6–9 decimals.
pub const SAME_AXIS_TOL: f64 = 1e-6;

// From program.rs.
/// The lowest feed polepatch analyses, mm/min. Equation 6 itself has no lower limit, but a
/// run at a feed below this (0.04 inch/min) is a typing error or a dwell written as a move,
/// and its time estimate is meaningless; such a run is reported with its line and left as
/// it is.
pub const MIN_FEED_MM_MIN: f64 = 1.0;

// From reorient.rs.
/// Below this |θx|, degrees, every reoriented move keeps the program's IK branch (its side
/// of the pole); from it on, the branch is continued from move to move (`continue_branch`).
/// A tilt of less than 1° moves no tool axis by more than 1°: the program is still where it
/// was relative to the pole, flips and all; a larger tilt is meant to take the path away
/// from the pole, where continuity is what keeps C from swinging.
pub const BRANCH_KEEP_DEG: f64 = 1.0;

// From reorient.rs.
/// Fewest decimals written for reoriented values (the file's if more).
pub const MIN_DECIMALS: usize = 3;

// From stream.rs.
/// A rotary value this far beyond the machine's range still counts as in it, degrees (the
/// range's own round-off).
pub const RANGE_SLACK_DEG: f64 = 1e-9;

// From tool.rs.
/// Two radii closer than this are equal when a corner radius is compared with half a
/// diameter, mm (posts round both: Fusion writes D=0.1181 CR=0.0591 for a 3 mm probe).
pub const CORNER_TOLERANCE_MM: f64 = 2e-3;

// From tool.rs.
/// Two points on the tool axis closer than this are the same point, mm.
pub const SAME_POINT_MM: f64 = 1e-9;

// From verify.rs.
/// How far the tool's reference point may move, mm, beyond the rounding of the words
/// written on both sides (SPEC §6: "a tip-programmed ball's centre within 1 µm (+
/// rounding)").
pub const REFERENCE_TOL_MM: f64 = 1e-3;

// From verify.rs.
/// A run reaches feed on an axis where its Equation-6 ratio is at least `1 − REACHED_TOL`
/// (the analyses of the two sides are the same computation; this absorbs their round-off).
pub const REACHED_TOL: f64 = 1e-6;

// From verify.rs.
/// Where the original is below feed, the written ratio may be this much lower (relative)
/// and still count as no lower (issue 39: "1 % tolerance"): a ball's centre kept moves the
/// tips, which moves X Y Z's own derivatives a little.
pub const RATIO_TOL_REL: f64 = 0.01;

// From verify.rs.
/// A run's or the program's estimated time may be this much greater (relative) and still
/// count as no greater (beyond the estimates' own error bounds).
pub const TIME_TOL_REL: f64 = 1e-3;

// From verify.rs.
/// How far X Y Z numbers of the same line may differ in [`same_line`], mm (or inch).
pub const LINE_MATCH_MM: f64 = 0.1;
