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

/// Bad input to the patcher.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PathError {
    /// Fewer than two points.
    #[error("a path needs at least 2 points, got {0}")]
    TooShort(usize),
    /// `s_mm` and `axes` lengths differ.
    #[error("s has {s} entries but axes has {axes}")]
    LengthMismatch {
        /// s length.
        s: usize,
        /// axes length.
        axes: usize,
    },
    /// s not strictly increasing at a point.
    #[error("s must increase strictly: point {index} has s = {value} mm after {previous} mm")]
    NotIncreasing {
        /// Point index.
        index: usize,
        /// s there.
        value: f64,
        /// s before.
        previous: f64,
    },
    /// A value is NaN or infinite.
    #[error("point {index}: {what} is not finite ({value})")]
    NotFinite {
        /// Point index.
        index: usize,
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// The analysis spline could not be built (should not happen for a validated path).
    #[error("analysis spline: {0}")]
    Spline(String),
    /// Options that mean nothing together, or out of range.
    #[error("options: {0}")]
    Options(String),
    /// Feed not positive and finite.
    #[error("programmed feed must be positive, got {0} mm/min")]
    BadFeed(f64),
}

/// The value the controller receives when `v` is written with `decimals` places
/// (the same rounding as the NC writer: `format!("{:.*}", decimals, v)`).
pub fn round_written(v: f64, decimals: usize) -> f64 {
    format!("{v:.decimals$}").parse().unwrap_or(v)
}
