//! The C-axis limits as geometric bounds along s at a programmed feed.

use polepatch_kinematics::{Axis, Machine};

/// Bounds on the geometric derivatives of C along s that make Equation 6 reach the feed F:
/// |C_s| ≤ `v` (°/mm), |C_ss| ≤ `a` (°/mm²), |C_sss| ≤ `j` (°/mm³).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CLimits {
    /// V/F, °/mm.
    pub v: f64,
    /// A/F², °/mm².
    pub a: f64,
    /// J/F³, °/mm³.
    pub j: f64,
}

impl CLimits {
    /// The bounds for `machine` at feed `feed_mm_min`, scaled by `(1 − margin)` (margin
    /// applied to the machine limits V, A, J).
    pub fn new(machine: &Machine, feed_mm_min: f64, margin: f64) -> CLimits {
        let f = feed_mm_min / 60.0;
        let l = machine.limit(Axis::C);
        let k = 1.0 - margin;
        CLimits {
            v: k * l.v / f,
            a: k * l.a / (f * f),
            j: k * l.j / (f * f * f),
        }
    }
}
