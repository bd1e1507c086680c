//! Sampling parameters at a fixed step (fs = F·Tcy, G16 eq. 8).

/// Parameters from `a` to `b` inclusive, spaced by at most `step` (> 0): `a, a+step, …`
/// and `b` itself (the last gap may be shorter). `a == b` gives `[a]`.
pub fn sample_params(a: f64, b: f64, step: f64) -> Vec<f64> {
    let _ = (a, b, step);
    todo!()
}
