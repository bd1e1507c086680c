//! In-memory path: what a CAM plugin or the NC reader hands to the patcher.

/// A run of G1 CL points at one programmed feed.
///
/// `axes[i] = [X, Y, Z, P, C]`: X Y Z in mm (the programmed tool-tip position), P the
/// primary rotary angle (A or B) and C in degrees, as written. `s_mm[i]` is the cumulative
/// tool-tip path length (strictly increasing, `s_mm[0]` any value).
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// Cumulative tool-tip path length per point, mm.
    pub s_mm: Vec<f64>,
    /// Axis values per point: X Y Z (mm), P, C (degrees).
    pub axes: Vec<[f64; 5]>,
    /// Programmed feed, mm/min.
    pub feed_mm_min: f64,
}

pub use crate::error::PathError;

/// The value the controller receives when `v` is written with `decimals` places
/// (the same rounding as the NC writer: `format!("{:.*}", decimals, v)`).
pub fn round_written(v: f64, decimals: usize) -> f64 {
    format!("{v:.decimals$}").parse().unwrap_or(v)
}
