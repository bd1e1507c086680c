//! The CL reader's numerical tolerances and the limits of the values it reads, in one
//! place (the patcher's `tolerances.rs` manner), each with its unit and why it has its
//! value. The public ones are re-exported where they were first named: the crate root,
//! [`crate::arcs`] and [`crate::frames`].

// --- Tolerances ------------------------------------------------------------------------

/// A tool axis may differ from unit length by this much (CAM files round to 4–7
/// decimals); it is then normalised.
pub const UNIT_TOLERANCE: f64 = 1e-3;

/// An end point of an arc may be this far from the circle (mm): CAM files write 4–6
/// decimals, inch files 0.0001 in = 0.00254 mm.
pub const ON_CIRCLE_TOL_MM: f64 = 0.005;

/// Rotation matrices and MCS axes are accepted when orthonormal within this (CAM files
/// write 6–7 decimals).
pub const FRAME_TOLERANCE: f64 = 1e-4;

/// Two `MSYS` records name the same MCS when their origins agree within this, mm.
pub const MSYS_ORIGIN_TOLERANCE_MM: f64 = 1e-4;

/// Two `MSYS` records name the same MCS when their axes agree within this.
pub const MSYS_AXIS_TOLERANCE: f64 = 1e-6;

/// A `CSYS` rotation is the identity when every entry is within this of the identity's
/// (dimensionless; with a zero origin it then states no frame): round-off of a written
/// identity only, far below [`FRAME_TOLERANCE`], so that a small rotation is never taken
/// for none.
pub(crate) const CSYS_IDENTITY_TOLERANCE: f64 = 1e-9;

/// Unit vectors less than this angle apart, radians, are the same to the great-circle
/// interpolation of the tool axis along an arc ([`crate::arcs::slerp`]: the first is
/// returned): below it `sin(angle)` would divide round-off.
pub(crate) const SLERP_SAME_RAD: f64 = 1e-12;

/// Unit vectors within this angle of opposite, radians, have no great circle between them
/// ([`crate::arcs::slerp`]: `None`): every plane through both is one.
pub(crate) const SLERP_OPPOSITE_RAD: f64 = 1e-9;

/// Most chords an arc is split into ([`crate::Arc::segments`]): a tolerance far below the
/// radius' precision would ask for billions; 10⁷ chords still take a full turn in steps
/// below 10⁻⁶ rad (the caller checks the tolerance's range).
pub(crate) const MAX_ARC_CHORDS: f64 = 1e7;

// --- Limits of what is read -------------------------------------------------------------

/// The largest coordinate accepted, mm (100 m): beyond any machine's travel, and small
/// enough that every value prints as a plain number in an NC word. The CL reader knows no
/// machine; a machine's own travel, where it has one, is checked by the post.
pub const MAX_COORDINATE_MM: f64 = 100_000.0;

/// The largest feed accepted, mm/min (1000 m/min).
pub const MAX_FEED_MM_MIN: f64 = 1_000_000.0;

/// The largest spindle speed accepted, rpm.
pub const MAX_SPINDLE_RPM: f64 = 1_000_000.0;

/// The longest dwell accepted (`DELAY`, a cycle's `DWELL`), s: 100000 s, more than a day,
/// longer than any pause a program means.
pub(crate) const MAX_DWELL_S: f64 = 1e5;
