//! Orchestration: detect, patch, verify, extend, never worse.

use crate::{options::PatchOptions, path::{Path, PathError}, report::ZoneReport};
use polepatch_kinematics::Machine;

/// Result of patching one path.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchResult {
    /// C per point, degrees, as it must be written (rounded to `decimals` where changed;
    /// the input value where unchanged).
    pub c_deg: Vec<f64>,
    /// Which points changed.
    pub changed: Vec<bool>,
    /// Decimal places to write the changed C values with (≥ `opts.c_decimals`).
    pub decimals: usize,
    /// One row per zone.
    pub zones: Vec<ZoneReport>,
}

/// Patch every singular zone of `path`.
pub fn patch_path(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<PatchResult, PathError> {
    let _ = (path, machine, opts);
    todo!()
}
