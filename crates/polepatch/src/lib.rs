//! polepatch: find and patch the places where the rotary axes slow a table-table 5-axis
//! machine near the pole — as a library, bytes in and bytes out.
//!
//! ```no_run
//! use polepatch::{PatchOptions, kinematics::Machine, patch_nc};
//! let machine = Machine::builtin("mikron-ucp710").unwrap();
//! let input = std::fs::read("SING.I").unwrap();
//! let (output, report) = patch_nc(&input, &machine, &PatchOptions::default()).unwrap();
//! assert_eq!(report.zones_below_feed(), 0);
//! # let _ = output;
//! ```
//!
//! [`patch_nc`] and [`analyze_nc`] are the entry points for NC programs held in memory
//! ([`stream::patch_nc_to`] writes the output to a writer as it goes, parsing in full only
//! the stretches near the pole); [`program::load_nc`] + [`patch::patch_loaded`] the same
//! on the whole parsed program, for callers that want it (the quality suite). CAM plugins that hold CL points rather
//! than a file use the patcher directly on a [`patcher::Path`].
//!
//! This crate does no file I/O and depends on no command-line crate: the `polepatch`
//! binary (`polepatch-cli`) and the C ABI (`polepatch-capi`) are thin layers over it.

pub use polepatch_bspline as bspline;
pub use polepatch_cl as cl;
pub use polepatch_kinematics as kinematics;
pub use polepatch_nc as nc;
pub use polepatch_patcher as patcher;
pub use polepatch_simulate as sim;

pub mod end_pose;
pub mod error;
pub mod far;
pub mod machine_frame;
pub mod patch;
pub mod post;
pub mod program;
pub mod reorient;
pub mod report;
pub mod simulate;
pub mod stream;

pub use error::Error;
pub use patch::{FileReport, UntouchedReason, UntouchedRun, ZoneRow, patch_loaded, patch_program};
pub use report::AnalyzeReport;
pub use simulate::{SimulateOptions, SimulateReport, simulate_nc, simulate_nc_with};

use polepatch_kinematics::Machine;
use polepatch_patcher::AnalysisOptions;

/// Options of [`patch_nc`]. Plain struct; see each field for its default.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchOptions {
    /// Options of the patcher (cone, margin, decimals, …). Default: [`patcher::PatchOptions`]'s.
    /// Its `c_decimals` and `p_decimals` are read from the file and need not be set.
    pub patch: patcher::PatchOptions,
    /// Feed, mm/min, for runs with no F in force. Default `None` (such runs are reported
    /// and left as they are).
    pub feed_fallback_mm_min: Option<f64>,
    /// Name of the input in messages and in the report (`file`). Default `"input"`.
    pub name: String,
    /// Work offset (machine coordinates of the program's zero, mm) for a machine with a
    /// kinematic chain. Default `None`: the program's own datum (Heidenhain `G54 X Y Z`).
    pub work_offset_mm: Option<[f64; 3]>,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            patch: patcher::PatchOptions::default(),
            feed_fallback_mm_min: None,
            name: "input".to_string(),
            work_offset_mm: None,
        }
    }
}

/// Options of [`analyze_nc`]. Plain struct; see each field for its default.
#[derive(Debug, Clone, PartialEq)]
pub struct AnalyzeOptions {
    /// Options of the analysis (cone, Tcy). Default: [`AnalysisOptions`]'s.
    pub analysis: AnalysisOptions,
    /// Feed, mm/min, for runs with no F in force. Default `None`.
    pub feed_fallback_mm_min: Option<f64>,
    /// Name of the input in messages and in the report. Default `"input"`.
    pub name: String,
    /// Work offset for a machine with a kinematic chain (as [`PatchOptions::work_offset_mm`]).
    pub work_offset_mm: Option<[f64; 3]>,
}

impl Default for AnalyzeOptions {
    fn default() -> Self {
        AnalyzeOptions {
            analysis: AnalysisOptions::default(),
            feed_fallback_mm_min: None,
            name: "input".to_string(),
            work_offset_mm: None,
        }
    }
}

/// Patch an NC program held in memory: the rewritten bytes (identical to `bytes` except
/// the rotary words that had to change) and the report.
///
/// Bad input (syntax errors with line and column, an empty program, no G1 motion, no
/// rotary words) is an [`Error`]; a zone that cannot reach feed is a status in the report.
pub fn patch_nc(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<(Vec<u8>, FileReport), Error> {
    if let Some(report) = far::far_from_pole(bytes, machine, opts)? {
        return Ok((bytes.to_vec(), report));
    }
    let mut out = Vec::with_capacity(bytes.len());
    let report = stream::patch_nc_to(bytes, machine, opts, &mut out)?;
    Ok((out, report))
}

/// Equation 6 along every run of an NC program held in memory (what `polepatch analyze`
/// prints).
pub fn analyze_nc(
    bytes: &[u8],
    machine: &Machine,
    opts: &AnalyzeOptions,
) -> Result<AnalyzeReport, Error> {
    stream::analyze_nc_stretches(bytes, machine, opts)
}
