//! Analysis and patching of 5-axis paths near the pole.
//!
//! Works on in-memory paths (no file I/O): see [`Path`]. The NC crate and the CLI do the
//! file side. [`driver`] is where the algorithm reads from top to bottom; each method
//! ([`reselect`], [`joint_method`], [`c_only`], [`peers`]) only proposes candidates.

pub mod analysis;
pub mod c_only;
pub mod candidate;
pub mod centre;
pub mod direct;
pub mod driver;
pub mod g16;
pub(crate) mod hermite;
pub mod ipm;
pub mod joint;
pub mod joint_method;
pub mod limits;
pub mod options;
pub mod path;
pub mod peers;
mod qp;
pub mod reference;
pub mod report;
pub mod reselect;
pub mod settings;
pub mod spline;
#[cfg(test)]
mod testutil;
pub mod verify;
pub(crate) mod window;

pub use analysis::{
    AnalysisOptions, CONE_DEG, POLE_REACH_DEG, RunAnalysis, Sample, Zone, ZoneKind, analyze_path,
    pole_dominates,
};
pub use candidate::{Candidate, PatchFailure};
pub use centre::KeepCentre;
pub use driver::{PatchResult, patch_path, report_unpatched};
pub use limits::{CLimits, GeomLimits};
pub use options::{PatchAxes, PatchOptions};
pub use path::{Path, PathError};
pub use peers::Strategy;
pub use report::{Method, Outcome, QpStats, QpStatus, Reason, ZoneFigures, ZoneReport};
pub use settings::SolverSettings;
