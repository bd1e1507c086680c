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
//! ([`patch_nc_to`] writes the output to a writer as it goes, parsing in full only the
//! stretches near the pole); [`load_nc`] reads a whole program with its runs as
//! paths, through the same reader, for callers that want it (the quality suite, reorient).
//! CAM plugins that hold CL points rather than a file use the patcher directly on a
//! [`patcher::Path`].
//!
//! This crate does no file I/O and depends on no command-line crate: the `polepatch`
//! binary (`polepatch-cli`) and the C ABI (`polepatch-capi`) are thin layers over it.

pub use polepatch_bspline as bspline;
pub use polepatch_cl as cl;
pub use polepatch_kinematics as kinematics;
pub use polepatch_nc as nc;
pub use polepatch_patcher as patcher;
pub use polepatch_simulate as sim;

// The documented API: the entry points and options below, and these modules.
pub mod joints;
pub mod machine_frame;
pub mod post;
pub mod reorient;
pub mod report;
pub mod simulate;
pub mod tool;
pub mod verify;

// The pipeline's rooms, private: what callers need of them is re-exported here.
mod analyze;
mod end_pose;
mod error;
mod hooks;
mod notes;
mod patch;
mod program;
mod stream;
mod violation;

pub use analyze::analyze_program;
pub use end_pose::EndPose;
pub use error::Error;
pub use hooks::Hooks;
pub use program::{LoadedProgram, MIN_FEED_MM_MIN, RunPath, RunProblem, Window};
pub use report::{
    AnalyzeReport, EndFreedom, FileReport, Outcome, SimulateReport, UntouchedReason, UntouchedRun,
    ZoneReason, ZoneRow, ZoneTool,
};
pub use simulate::{SimulateOptions, simulate_nc, simulate_nc_with};
pub use stream::{Piece, analyze_nc_each, load_nc, load_nc_with};

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
    /// With a kinematic chain, for runs without TCPM: how far the tool tip may leave the
    /// programmed line between two points when the rewritten block's axes are
    /// interpolated linearly, mm (never more than the original block did, either).
    /// Default [`machine_frame::CHORD_TOLERANCE_MM`] (0.005 mm). Also how far the centre
    /// of a ball programmed at its tip may leave its original path between two points
    /// ([`tool`]).
    pub chord_tolerance_mm: f64,
    /// The cutting tool and the point X Y Z state ([`tool`]). Default: from the program
    /// and the TCPM codes.
    pub tool: tool::ToolOptions,
    /// Read a program that states no length units (no G20/G21, G70/G71, G700/G710,
    /// `%NAME G71`, `BEGIN PGM … MM|INCH`) in inches, as a control set to inches does
    /// (`--units inch`). Default false: mm. The report's warnings say which was assumed.
    pub inch: bool,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            patch: patcher::PatchOptions::default(),
            feed_fallback_mm_min: None,
            name: "input".to_string(),
            work_offset_mm: None,
            chord_tolerance_mm: machine_frame::CHORD_TOLERANCE_MM,
            tool: tool::ToolOptions::default(),
            inch: false,
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
    /// Read a program that states no length units in inches (as [`PatchOptions::inch`]).
    /// Default false: mm.
    pub inch: bool,
}

impl Default for AnalyzeOptions {
    fn default() -> Self {
        AnalyzeOptions {
            analysis: AnalysisOptions::default(),
            feed_fallback_mm_min: None,
            name: "input".to_string(),
            work_offset_mm: None,
            inch: false,
        }
    }
}

/// Most decimal places a rotary value may be written with (`max_decimals`): the patcher's
/// rule ([`patcher::PatchOptions::validate`]).
pub use patcher::MAX_WRITTEN_DECIMALS;

/// `v` is a positive, finite number, else an [`Error::Options`] naming `field` and `unit`.
pub(crate) fn positive(field: &str, unit: &str, v: f64) -> Result<(), Error> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::Options(format!(
            "{field} must be a positive number of {unit}, got {v}"
        )))
    }
}

/// The options every entry point shares: feed fallback and work offset.
fn check_common(
    feed_fallback_mm_min: Option<f64>,
    work_offset_mm: Option<[f64; 3]>,
) -> Result<(), Error> {
    if let Some(f) = feed_fallback_mm_min {
        positive("feed_fallback_mm_min", "mm/min", f)?;
    }
    if let Some(w) = work_offset_mm
        && w.iter().any(|v| !v.is_finite())
    {
        return Err(Error::Options(format!(
            "work_offset_mm must be three finite numbers of mm, got {w:?}"
        )));
    }
    Ok(())
}

/// Check the patcher's options: the patcher's one rule set
/// ([`patcher::PatchOptions::validate`]), its refusal as an [`Error::Options`] naming the
/// field, its unit and the value. [`PatchOptions::check`] and [`joints::patch_joints`]
/// call it.
pub fn check_patcher_options(p: &patcher::PatchOptions) -> Result<(), Error> {
    p.validate().map_err(|e| Error::Options(e.to_string()))
}

impl PatchOptions {
    /// Every value in range, or an [`Error::Options`] naming the field. The entry points
    /// ([`patch_nc`], [`patch_nc_to`]) call it, so a
    /// caller need not; a front end checks earlier only to name its own flags.
    pub fn check(&self) -> Result<(), Error> {
        check_patcher_options(&self.patch)?;
        self.tool.check()?;
        check_common(self.feed_fallback_mm_min, self.work_offset_mm)
    }
}

impl AnalyzeOptions {
    /// Every value in range, or an [`Error::Options`] naming the field ([`analyze_nc`] and
    /// [`stream::analyze_nc_each`] call it).
    pub fn check(&self) -> Result<(), Error> {
        self.analysis
            .validate()
            .map_err(|e| Error::Options(e.to_string()))?;
        check_common(self.feed_fallback_mm_min, self.work_offset_mm)
    }
}

/// Patch an NC program held in memory: the rewritten bytes (identical to `bytes` except
/// the rotary words that had to change) and the report. [`patch_nc_to`] into a `Vec`.
///
/// Programs of up to 4 GiB are read (the reader's byte offsets are 32-bit); memory is about
/// twice the input for a program far from the pole, plus about ten times each run near it
/// (docs/performance-nc.md). Where memory cannot be had the call returns
/// [`Error::OutOfMemory`] (or a parse error naming it) instead of aborting the process.
///
/// Bad input (syntax errors with line and column, an empty program, no G1 motion, no
/// rotary words) is an [`Error`]; a zone that cannot reach feed is a status in the report.
pub fn patch_nc(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<(Vec<u8>, FileReport), Error> {
    // The output is about the input's size: a host that cannot give it gets an error,
    // not an abort (the reader reserves its own tables the same way).
    let mut out = Vec::new();
    out.try_reserve(bytes.len())
        .map_err(|_| Error::OutOfMemory {
            what: "the output",
            bytes: bytes.len(),
        })?;
    let report = patch_nc_to(bytes, machine, opts, &mut out)?;
    Ok((out, report))
}

/// Patch an NC program held in memory, writing the output to `out`: the one entry every
/// caller goes through (the CLI's file jobs, [`patch_nc`], hence the C ABI and `post`).
///
/// The one reader: a first read finds the runs and which come near the pole; a program with
/// none has no zone, and its output is its input, written in one piece. Otherwise a second
/// read parses the stretches near the pole; they are patched and written in file order,
/// everything between them copied.
///
/// On an error nothing more is written; what was written before it must be discarded by
/// the caller (the CLI writes to a temporary file). A failed write is [`Error::Output`].
pub fn patch_nc_to(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
    out: &mut dyn std::io::Write,
) -> Result<FileReport, Error> {
    patch_nc_hooked(bytes, machine, opts, out, Hooks::NONE)
}

/// [`patch_nc_to`] with [`Hooks`]: progress as the output is written, and a cancellation
/// check between stretches (a cancelled patch ends with [`Error::Cancelled`]).
pub fn patch_nc_hooked(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
    out: &mut dyn std::io::Write,
    hooks: Hooks<'_>,
) -> Result<FileReport, Error> {
    if (hooks.cancelled)() {
        return Err(Error::Cancelled);
    }
    stream::patch_nc_hooked(bytes, machine, opts, out, hooks)
        .map_err(|e| program::or_cl_file(e, bytes, &opts.name))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The default options with one change.
    fn with(change: impl Fn(&mut PatchOptions)) -> PatchOptions {
        let mut o = PatchOptions::default();
        change(&mut o);
        o
    }

    #[test]
    fn defaults_pass_the_checks() {
        assert!(PatchOptions::default().check().is_ok());
        assert!(AnalyzeOptions::default().check().is_ok());
    }

    #[test]
    fn every_option_out_of_range_is_named() {
        let bad: Vec<(&str, PatchOptions)> = vec![
            ("cone_deg", with(|o| o.patch.cone_deg = 0.0)),
            ("cone_deg", with(|o| o.patch.cone_deg = f64::NAN)),
            (
                "max_deviation_deg",
                with(|o| o.patch.max_deviation_deg = Some(-1.0)),
            ),
            ("tcy_s", with(|o| o.patch.tcy_s = Some(f64::INFINITY))),
            (
                "max_patch_length_mm",
                with(|o| o.patch.max_patch_length_mm = Some(0.0)),
            ),
            ("margin", with(|o| o.patch.margin = 0.5)),
            ("margin", with(|o| o.patch.margin = -0.01)),
            (
                "max_decimals",
                with(|o| o.patch.max_decimals = MAX_WRITTEN_DECIMALS + 1),
            ),
            (
                "feed_fallback_mm_min",
                with(|o| o.feed_fallback_mm_min = Some(0.0)),
            ),
            (
                "work_offset_mm",
                with(|o| o.work_offset_mm = Some([0.0, f64::NAN, 0.0])),
            ),
        ];
        let program = b"%P G71 *\nN10 G01 X0 Y0 Z0 A1 C0 F1000 *\nN20 X1 A0.5 C90 *\n";
        let m = kinematics::Machine::builtin("mikron-ucp710").unwrap();
        for (field, o) in bad {
            match o.check() {
                Err(Error::Options(msg)) => assert!(msg.starts_with(field), "{field}: {msg}"),
                other => panic!("{field}: {other:?}"),
            }
            // Every entry point refuses them, before reading the program.
            assert!(
                matches!(patch_nc(program, &m, &o), Err(Error::Options(_))),
                "{field}"
            );
            let mut sink = Vec::new();
            assert!(
                matches!(
                    patch_nc_to(program, &m, &o, &mut sink),
                    Err(Error::Options(_))
                ),
                "{field}"
            );
        }
    }

    #[test]
    fn analysis_and_reorientation_options_are_checked() {
        let program = b"%P G71 *\nN10 G01 X0 Y0 Z0 A1 C0 F1000 *\nN20 X1 A0.5 C90 *\n";
        let m = kinematics::Machine::builtin("mikron-ucp710").unwrap();
        let analyze = |cone_deg, tcy_s| {
            let opts = AnalyzeOptions {
                analysis: patcher::AnalysisOptions {
                    cone_deg,
                    tcy_s,
                    ..patcher::AnalysisOptions::default()
                },
                ..AnalyzeOptions::default()
            };
            match analyze_nc(program, &m, &opts) {
                Err(Error::Options(msg)) => msg,
                other => panic!("{other:?}"),
            }
        };
        assert!(analyze(-5.0, None).starts_with("cone_deg"));
        assert!(analyze(5.0, Some(0.0)).starts_with("tcy_s"));
        let tilt = |theta_x_deg, pivot_mm| reorient::Tilt {
            theta_x_deg,
            theta_z_deg: 0.0,
            pivot_mm,
        };
        for (t, cone, field) in [
            (tilt(f64::NAN, [0.0; 3]), 5.0, "θx"),
            (tilt(10.0, [0.0, f64::INFINITY, 0.0]), 5.0, "the pivot"),
            (tilt(10.0, [0.0; 3]), 0.0, "cone_deg"),
        ] {
            match reorient::reorient_nc(program, &m, &t, "p", cone) {
                Err(Error::Options(msg)) => assert!(msg.starts_with(field), "{msg}"),
                other => panic!("{field}: {other:?}"),
            }
        }
        assert!(matches!(
            reorient::search(program, &m, [0.0; 3], "p", -1.0),
            Err(Error::Options(msg)) if msg.starts_with("cone_deg")
        ));
    }
}
