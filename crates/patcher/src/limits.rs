//! An axis' limits as geometric bounds along s at a programmed feed.

use polepatch_kinematics::{Axis, Machine};

/// Bounds on the geometric derivatives of one axis along s that make Equation 6 reach the
/// feed F: |q_s| ≤ `v`, |q_ss| ≤ `a`, |q_sss| ≤ `j` (per mm, per mm², per mm³; degrees for
/// a rotary axis, mm for a linear one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeomLimits {
    /// V/F, per mm.
    pub v: f64,
    /// A/F², per mm².
    pub a: f64,
    /// J/F³, per mm³.
    pub j: f64,
}

/// The C axis' [`GeomLimits`] (the name the C-only method and the bound use).
pub type CLimits = GeomLimits;

impl GeomLimits {
    /// C's bounds for `machine` at feed `feed_mm_min`, scaled by `(1 − margin)` (margin
    /// applied to the machine limits V, A, J).
    pub fn new(machine: &Machine, feed_mm_min: f64, margin: f64) -> GeomLimits {
        GeomLimits::of(machine, Axis::C, feed_mm_min, margin)
    }

    /// The bounds of `axis` for `machine` at feed `feed_mm_min`, scaled by `(1 − margin)`.
    pub fn of(machine: &Machine, axis: Axis, feed_mm_min: f64, margin: f64) -> GeomLimits {
        let f = feed_mm_min / 60.0;
        let l = machine.limit(axis);
        let k = 1.0 - margin;
        GeomLimits {
            v: k * l.v / f,
            a: k * l.a / (f * f),
            j: k * l.j / (f * f * f),
        }
    }
}
