//! The G16 patch (SPEC §3 steps 3–5): split, fit C_b and C_a, join search, patch QP,
//! projection of the CL points.

use crate::{
    analysis::Zone,
    candidate::{Candidate, PatchFailure},
    limits::CLimits,
    options::PatchOptions,
};

/// Propose new C values for `zone` of a path (`s_mm`, primary `p_deg`, `c_deg` per point)
/// by the G16 method; `extra` widens the patch by that many CL points on each side beyond
/// the join found by the join search (the caller's extension loop).
pub fn g16_patch(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    zone: &Zone,
    extra: usize,
    lim: &CLimits,
    opts: &PatchOptions,
) -> Result<Candidate, PatchFailure> {
    let _ = (s_mm, p_deg, c_deg, zone, extra, lim, opts);
    todo!()
}
