//! Analysis and patching of 5-axis paths near the pole.
//!
//! Works on in-memory paths (no file I/O): see [`Path`]. The NC crate and the CLI do the
//! file side. [`driver`] is where the algorithm reads from top to bottom; each method
//! ([`reselect`], [`joint_method`], [`c_only`], [`peers`]) only proposes candidates, through
//! the [`protocol`]; [`strategy`] (the top) says which methods a strategy asks and hands
//! them to the driver.
//!
//! From the ground up: the [`path`] and its [`analysis`] ([`spline`], [`zones`]); the
//! [`options`] and [`settings`]; the solvers ([`qp`], [`ipm`], the joint patch [`joint`],
//! G16's [`g16`], the [`direct`] QP); [`verify`] and the proofs ([`proof`]); the
//! [`protocol`] and the [`starts`] the methods share; the methods; the [`driver`]; the
//! [`strategy`] table. The bench reference ([`reference`]) stands beside the driver.

pub(crate) mod analysis;
pub(crate) mod c_only;
pub(crate) mod candidate;
pub(crate) mod centre;
pub(crate) mod direct;
pub(crate) mod driver;
pub(crate) mod error;
pub(crate) mod free_start;
pub(crate) mod g16;
pub(crate) mod hermite;
pub(crate) mod ipm;
pub(crate) mod joint;
pub(crate) mod joint_method;
pub(crate) mod limits;
pub(crate) mod options;
pub(crate) mod path;
pub(crate) mod peers;
pub(crate) mod proof;
pub(crate) mod protocol;
mod qp;
pub mod quality;
pub(crate) mod reference;
pub(crate) mod report;
pub(crate) mod reselect;
pub(crate) mod settings;
pub mod spline;
pub(crate) mod starts;
pub(crate) mod strategy;
#[cfg(test)]
mod testutil;
pub(crate) mod tolerances;
pub(crate) mod verify;
pub(crate) mod window;
pub(crate) mod zones;

pub use analysis::{
    AnalysisOptions, CONE_DEG, POLE_REACH_DEG, RunAnalysis, Sample, Zone, ZoneKind, analyze_path,
    pole_dominates, validate,
};
pub use candidate::{Candidate, PatchFailure};
pub use centre::KeepCentre;
pub use driver::{PatchResult, report_unpatched};
pub use error::{OptionField, OptionRule, OptionsError};
pub use free_start::patch_path_free_start;
pub use limits::{CLimits, GeomLimits};
pub use options::{MAX_WRITTEN_DECIMALS, PatchAxes, PatchOptions, Strategy};
pub use path::{Path, PathError};
pub use report::{Method, Outcome, QpStats, QpStatus, Reason, ZoneFigures, ZoneReport};
pub use settings::SolverSettings;
pub use strategy::patch_path;
