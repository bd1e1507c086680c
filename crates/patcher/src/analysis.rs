//! Equation-6 analysis of one run with the analysis spline (SPEC §2), and detection of
//! singular zones (SPEC §3 step 2).

use crate::path::{Path, PathError};
use polepatch_kinematics::{FeedBound, LimitKind, Machine};

/// Options of [`analyze_path`].
#[derive(Debug, Clone, PartialEq)]
pub struct AnalysisOptions {
    /// Singular cone: a zone needs a point with |primary| ≤ this, degrees. Default 5.
    pub cone_deg: f64,
    /// Interpolation cycle time override, seconds; `None` uses the machine's `tcy_s`.
    pub tcy_s: Option<f64>,
    /// Keep every sample in [`RunAnalysis::samples`] (for plots). Default false.
    pub keep_samples: bool,
}

impl Default for AnalysisOptions {
    fn default() -> Self {
        AnalysisOptions { cone_deg: 5.0, tcy_s: None, keep_samples: false }
    }
}

/// Kind of singular zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ZoneKind {
    /// The primary axis changes sign near zero (domain-rule posts, G16): C jumps up to 180°.
    AFlip,
    /// The primary axis keeps its sign and C swings fast near the pole (C17 `%SING`).
    CSwing,
}

/// A singular zone: where the C-limited ratio is below 1 with the primary axis inside the
/// cone.
#[derive(Debug, Clone, PartialEq)]
pub struct Zone {
    /// First point index of the zone (the point before the first sample with ratio < 1).
    pub first: usize,
    /// Last point index of the zone.
    pub last: usize,
    /// Index of the singular point (the point of least |primary|; for an A flip the point
    /// just before the sign change).
    pub singular: usize,
    /// Kind.
    pub kind: ZoneKind,
    /// Smallest |primary| over the zone's points, degrees.
    pub min_abs_primary_deg: f64,
    /// Smallest C-limited Equation-6 ratio over the zone.
    pub c_ratio_min: f64,
}

/// One analysis sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Path parameter, mm.
    pub s_mm: f64,
    /// Per-axis ratio min(1, bound/F) in axis order.
    pub axis_ratio: [f64; 5],
    /// Overall bound here.
    pub bound: FeedBound,
}

/// Result of analysing one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunAnalysis {
    /// Path length, mm.
    pub length_mm: f64,
    /// Programmed feed, mm/min.
    pub feed_mm_min: f64,
    /// Sampling step used, mm (F·Tcy).
    pub step_mm: f64,
    /// The lowest bound over the run.
    pub min: FeedBound,
    /// Where it occurs, mm.
    pub min_s_mm: f64,
    /// Lowest ratio per axis (axis order) and the limit that binds there.
    pub axis_min: [(f64, LimitKind); 5],
    /// Estimated time ∫ds/ṡ over the run, s.
    pub time_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// Peak speed per axis at the programmed feed: max |q_s|·F, mm/s or °/s.
    pub peak_speed: [f64; 5],
    /// Singular zones.
    pub zones: Vec<Zone>,
    /// Samples (only with `keep_samples`).
    pub samples: Vec<Sample>,
}

/// Analyse a run: the not-a-knot spline of each axis over s, sampled every F·Tcy and at
/// every knot, Equation 6 at every sample, time by the trapezoidal rule on 1/ṡ, zones.
pub fn analyze_path(
    path: &Path,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> Result<RunAnalysis, PathError> {
    let _ = (path, machine, opts);
    todo!()
}
