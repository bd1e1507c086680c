//! The kinematic chain: where the rotary axes sit (a point on each axis line), the
//! optional part of a machine description (`[chain]`, or `point_mm` of each `[[rotary]]`).
//! What the points mean, and the conversions between machine-frame X Y Z and the tool tip in
//! the part frame that use them, are in `frames.rs` ([`Chain::program_xyz`],
//! [`Chain::part_tip`]).

use serde::{Deserialize, Serialize};

/// Where the rotary axes sit (frames and conventions: `frames.rs`). Optional part of a
/// machine description (`[chain]`, or `point_mm` of each `[[rotary]]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Chain {
    /// A point on the primary (tilting) axis line, mm (`p`): machine coordinates for a
    /// table axis, relative to the spindle gauge point for a head axis; every axis at zero.
    pub primary_axis_point_mm: [f64; 3],
    /// A point on the C (pole) axis line, mm (`c`), the same way, every axis at zero.
    pub c_axis_point_mm: [f64; 3],
}

impl Chain {
    /// Rotary axes intersecting at machine zero (C17's set-up).
    pub const AT_ORIGIN: Chain = Chain {
        primary_axis_point_mm: [0.0; 3],
        c_axis_point_mm: [0.0; 3],
    };

    /// Check the values: finite.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("chain.primary_axis_point_mm", self.primary_axis_point_mm),
            ("chain.c_axis_point_mm", self.c_axis_point_mm),
        ] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(format!("{name} must be finite, got {v:?}"));
            }
        }
        Ok(())
    }
}
