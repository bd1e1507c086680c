//! Analysis and patching of 5-axis paths near the pole.
//!
//! Works on in-memory paths (no file I/O): see [`Path`]. The NC crate and the CLI do the
//! file side.

pub mod analysis;
pub mod both;
pub mod c_only;
pub mod candidate;
pub mod direct;
pub mod g16;
pub(crate) mod hermite;
pub mod joint;
pub mod limits;
pub mod options;
pub mod patch;
pub mod path;
pub mod peers;
mod qp;
pub mod reference;
pub mod report;
pub mod spline;
#[cfg(test)]
mod testutil;
pub mod verify;

pub use analysis::{AnalysisOptions, RunAnalysis, Sample, Zone, ZoneKind, analyze_path};
pub use candidate::{Candidate, PatchFailure};
pub use limits::{CLimits, GeomLimits};
pub use options::{PatchAxes, PatchOptions};
pub use patch::{PatchResult, patch_path, report_unpatched};
pub use path::{Path, PathError};
pub use peers::Strategy;
pub use report::{Method, Outcome, QpStats, QpStatus, ZoneFigures, ZoneReport};
