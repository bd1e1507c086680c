//! The crate's user-facing defaults and working sizes, each with its unit: what a caller
//! can change through the options (the chord and surface tolerances, the reorientation
//! search) and the sizes of the pipeline's batches and messages. Each is re-exported by the
//! module that uses it, under the name it had there.

// From machine_frame.rs.
/// Default chord tolerance, mm: how far the part-frame tool tip of a block rewritten
/// through the chain may leave the programmed line between its points (issue 19 §2).
pub const CHORD_TOLERANCE_MM: f64 = 0.005;

// From machine_frame.rs.
/// Samples per block for `machine_frame::chord_error_mm`. The tip's distance from the line is a smooth
/// function of the interpolation parameter u that is 0 at both ends; for the rotary steps
/// a rewritten block takes (tens of degrees at most) it is well within one sign change of
/// its curvature over [0, 1], and sampling every 1/32 finds its maximum within about
/// (1/64)²/2 of the maximum's curvature scale — under 0.02 % of it.
pub const CHORD_SAMPLES: usize = 32;

// From notes.rs.
/// At most this many lines are named for one kind of warning.
pub const NAMED_LINES: usize = 5;

// From patch.rs.
/// How many times a run whose kept ball centre would leave its path between the points by
/// more than the chord tolerance is solved again with its orientation change capped.
pub const CENTRE_PATH_RETRIES: usize = 3;

// From patch.rs.
/// Points sampled inside each block for the centre's path between two points.
pub const CENTRE_CHORD_SAMPLES: usize = 8;

// From post.rs.
/// Default chordal tolerance of arcs, mm.
pub const ARC_TOLERANCE_MM: f64 = 0.001;

// From program.rs.
/// How far into a file [`cl_file_error`] looks for an APT `GOTO/` record, bytes.
pub const CL_SNIFF_BYTES: usize = 64 * 1024;

// From reorient.rs.
/// Largest |θx| accepted, degrees: a jig tilts the part at most onto its side; beyond,
/// the tool would reach the faces the program cuts from below.
pub const MAX_THETA_X_DEG: f64 = 90.0;

// From reorient.rs.
/// Largest |θz| accepted, degrees (one turn either way; a larger value is a typing error).
pub const MAX_THETA_Z_DEG: f64 = 360.0;

// From reorient.rs.
/// Search: step of |θx| levels, degrees.
pub const SEARCH_STEP_DEG: f64 = 1.0;

// From reorient.rs.
/// Search: refinement step of |θx| below the first feasible level, degrees.
pub const SEARCH_REFINE_STEP_DEG: f64 = 0.1;

// From reorient.rs.
/// Search: largest tilt tried, degrees.
pub const SEARCH_MAX_TILT_DEG: f64 = 45.0;

// From reorient.rs.
/// Search: θz grid, degrees.
pub const SEARCH_THETA_Z_STEP_DEG: f64 = 15.0;

// From stream.rs.
/// Stretches are patched in batches of about this part of the file's bytes (so that the
/// batch's parsed programs, ~10× their bytes, stay a small part of the file's size) …
pub const BATCH_FRACTION: usize = 256;

// From stream.rs.
/// … but at least this many bytes (small files: one batch) …
pub const BATCH_MIN_BYTES: usize = 16 << 10;

// From stream.rs.
/// … and at most this many.
pub const BATCH_MAX_BYTES: usize = 256 << 10;

// From tool.rs.
/// The default surface tolerance for flat and bull-nose cutters, mm: how far their
/// cutting surface may move at a CL point when the patch turns the tool about its tip.
pub const SURFACE_TOLERANCE_MM: f64 = 0.005;

// From verify.rs.
/// Batches of blocks handed from the patched program's reader to the comparison.
pub const BATCH_BLOCKS: usize = 512;
