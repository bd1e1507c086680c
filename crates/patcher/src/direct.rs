//! The direct formulation: a QP on the CL C values through the analysis spline, and the
//! lower bound on the orientation deviation (SPEC §6, bench).

use crate::{
    candidate::{Candidate, PatchFailure},
    limits::CLimits,
    options::PatchOptions,
    report::QpStats,
};

/// New C values for points `first..=last` (others fixed) minimising the largest orientation
/// deviation such that the analysis spline of the whole path satisfies `lim` on every
/// sample, monotone with sign `monotone` (+1/−1) over `[s(first), s(last)]` when given.
pub fn direct_patch(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    lim: &CLimits,
    monotone: Option<f64>,
    opts: &PatchOptions,
) -> Result<Candidate, PatchFailure> {
    let _ = (s_mm, p_deg, c_deg, first, last, lim, monotone, opts);
    todo!()
}

/// The smallest possible largest orientation deviation (degrees) over C-only changes at
/// points `first..=last` such that the analysis spline satisfies `lim` (no monotonicity
/// asked): the bound the bench compares against.
pub fn deviation_bound(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    lim: &CLimits,
) -> Result<(f64, QpStats), PatchFailure> {
    let _ = (s_mm, p_deg, c_deg, first, last, lim);
    todo!()
}
