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
mod entry;
mod error;
mod hooks;
mod notes;
mod options;
mod patch;
mod plan;
mod program;
mod settings;
mod stream;
mod tolerances;
mod violation;

pub use analyze::analyze_program;
pub use end_pose::EndPose;
pub use entry::{analyze_nc, patch_nc, patch_nc_hooked, patch_nc_to};
pub use error::{Error, OptionError};
pub use hooks::Hooks;
pub use options::{
    AnalyzeOptions, PatchOptions, ReadOptions, SimulateOptions, check_patcher_options,
};
/// Most decimal places a rotary value may be written with (`max_decimals`): the patcher's
/// rule ([`patcher::PatchOptions::validate`]).
pub use patcher::MAX_WRITTEN_DECIMALS;
pub use program::{LoadedProgram, MIN_FEED_MM_MIN, RunPath, RunProblem, Window};
pub use report::{
    AnalyzeReport, Branch, EndFreedom, FileReport, Outcome, SimulateReport, UntouchedReason,
    UntouchedRun, ZoneReason, ZoneRow, ZoneTool,
};
pub use simulate::{simulate_nc, simulate_nc_owned, simulate_nc_with};
pub use stream::{Piece, analyze_nc_each, load_nc, load_nc_with};
