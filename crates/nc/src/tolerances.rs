//! Named tolerances and tuning numbers of the NC crate: each with its unit and why it has
//! its value. (G- and M-code numbers, unit conversions such as 25.4 mm per inch, and the
//! limits of exact `f64` arithmetic are definitions, written where they are used.)

/// A G1 block whose tool tip moves less than this (mm) has zero tool-tip length: it ends
/// the current run and is not part of any run. Exact repeats give 0; the tolerance only
/// absorbs rounding from inch conversion and incremental sums.
pub const ZERO_LENGTH_MM: f64 = 1e-9;

/// Half a turn, degrees, and the round-off a written value may carry: a plain rotary move
/// larger than this is a wrap on an axis that may take the shorter way. The 1e-9° of
/// round-off is far below the 0.0001° a program writes, so a move of half a turn exactly
/// is read as written.
pub(crate) const HALF_TURN_DEG: f64 = 180.0 + 1e-9;

/// Below this (degrees) two modulo positions are the same (no turn for ACP/ACN, an
/// ambiguous half turn for DC): positions modulo 360 differ by rounding only, far below the
/// 0.0001° a program writes.
pub(crate) const FORM_EPS_DEG: f64 = 1e-9;

/// Degrees by which an unedited direction word (`C=DC(…)`), moved from the patched position
/// before it, may miss the unwrapped position it reached in the original and still move
/// as it did: both come from the same written value by different sums, which differ by
/// rounding only; 1e-6° is far below the 0.001° a program writes.
pub(crate) const DIRECTION_FORM_REACH_TOL_DEG: f64 = 1e-6;

/// How near a G or M word's value must be to a code (`M98`, `G66.1`) for a flow statement
/// to be read as that code: values are read correctly rounded from their few decimals, so
/// a value that is the code differs from it by rounding only (well below 1e-9) and one that
/// is not differs by at least a last written digit.
pub(crate) const CODE_MATCH_TOL: f64 = 1e-9;

/// How near ten times a G or M value must be to a whole number for the value to be a code
/// with at most one decimal (`G43.4` → 434; 43.4 × 10 is 433.99999999999994 in `f64`): the
/// rounding of the product is below 1e-12, and a second decimal (`G43.45`) is 0.5 away.
pub(crate) const CODE10_ROUND_TOL: f64 = 1e-6;

/// How many bytes at the start of a file the dialect is guessed from (64 KiB): the header
/// and the first blocks, where a program writes what the guess looks for (`BEGIN PGM`,
/// `%NAME G71`, `TRAORI`, `G43.4`, `M128`, its comment style); the guess does not grow
/// with the file.
pub(crate) const DETECT_HEAD_BYTES: usize = 64 * 1024;

/// Size of the windows [`crate::scan`] lexes on several threads at a time, bytes (256 KiB):
/// large enough that starting threads costs nothing, small enough that a window's words
/// stay a small part of any program worth doing this for.
pub(crate) const SCAN_WINDOW_BYTES: usize = 256 << 10;

/// Size of the first window a threaded read lexes, bytes (4 KiB); each next one is twice
/// the last, up to [`SCAN_WINDOW_BYTES`]: a read that stops early (a stretch of a file read
/// again from a place in it) lexes at most a few times what it reads.
pub(crate) const SCAN_FIRST_WINDOW_BYTES: usize = 4 << 10;

/// Most threads the reader lexes on (at most the machine's available parallelism): the
/// value the threaded reader was introduced with (issue 10 §2). The count changes only the
/// time a read takes, never what it reads (tested on 1, 2 and 3 threads).
pub(crate) const MAX_SCAN_THREADS: usize = 8;
