//! Analysis and patching of 5-axis paths near the pole.
//!
//! Works on in-memory paths (no file I/O): see [`Path`].

pub mod analysis;
pub mod path;

pub use analysis::{AnalysisOptions, RunAnalysis, Sample, Zone, ZoneKind, analyze_path};
pub use path::{Path, PathError};
