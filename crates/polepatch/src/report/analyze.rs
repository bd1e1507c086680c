//! The report of an analysis (the JSON of `polepatch analyze --json`): per run its
//! Equation-6 figures and zones.

use super::{feed_mode_by_name, limit_by_name, limits_by_name};
use polepatch_kinematics::LimitKind;
use polepatch_nc::FeedMode;
use polepatch_patcher::ZoneKind;
use serde::Serialize;
use std::collections::BTreeMap;

/// A singular zone in a run.
#[derive(Debug, Clone, Serialize)]
pub struct ZoneSummary {
    /// File lines of the first and last point of the zone.
    pub lines: [usize; 2],
    /// `a_flip` or `c_swing` (in text: `A-flip`, `C-swing`).
    pub kind: ZoneKind,
    /// File line of the singular point.
    pub singular_line: usize,
    /// Smallest |primary| in the zone, degrees.
    pub min_abs_primary_deg: f64,
    /// Lowest C-limited Equation-6 ratio in the zone.
    pub c_ratio_min: f64,
}

/// Equation-6 figures of an analysed run.
#[derive(Debug, Clone, Serialize)]
pub struct RunFigures {
    /// Lowest feed ratio over the run (bound / F).
    pub min_ratio: f64,
    /// Axis limiting there (`null`: the feed itself).
    pub limiting_axis: Option<String>,
    /// Limit binding there: `V`, `A`, `J` or `F` ([`super::limit_name`]).
    #[serde(serialize_with = "limit_by_name")]
    pub limiting_limit: LimitKind,
    /// Where, mm along the run.
    pub min_at_s_mm: f64,
    /// File line of the point at or just after that place.
    pub min_at_line: usize,
    /// Lowest ratio per axis letter.
    pub axis_min_ratio: BTreeMap<String, f64>,
    /// Binding limit per axis letter at its lowest ratio (written `V`, `A`, `J`).
    #[serde(serialize_with = "limits_by_name")]
    pub axis_limit: BTreeMap<String, LimitKind>,
    /// Estimated time ∫ds/ṡ, s.
    pub time_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// Peak speed of each axis at the programmed feed: rpm (rotary), m/min (linear).
    pub peak_speed: BTreeMap<String, f64>,
    /// Singular zones.
    pub zones: Vec<ZoneSummary>,
}

/// One run in the analysis report.
#[derive(Debug, Clone, Serialize)]
pub struct RunReport {
    /// Run number, from 1.
    pub run: usize,
    /// File lines of the first point (start position) and of the last block.
    pub lines: [usize; 2],
    /// CL points (blocks + 1).
    pub points: usize,
    /// Path length, mm.
    pub length_mm: f64,
    /// Feed used, mm/min (`null` if none); where the blocks have their own (a pass whose
    /// F changes, G93), the reference feed: the run's length over its programmed time.
    pub feed_mm_min: Option<f64>,
    /// Where the blocks have their own feeds: the lowest and highest, mm/min (absent
    /// otherwise). Equation 6's ratio is against each block's own.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block_feeds_mm_min: Option<[f64; 2]>,
    /// Feed mode: `G94`, or `G93` (inverse time: the feed is each block's length over its
    /// time).
    #[serde(serialize_with = "feed_mode_by_name")]
    pub feed_mode: FeedMode,
    /// Why this run was not analysed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The figures (absent when `error` is set).
    #[serde(flatten)]
    pub figures: Option<RunFigures>,
    /// With the machine's kinematic chain and a known work offset: the linear axes in
    /// the machine frame (what the controller moves).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine_frame: Option<MachineFrameFigures>,
}

/// Equation 6 on the machine-frame X Y Z of a run ([`crate::machine_frame`]).
#[derive(Debug, Clone, Serialize)]
pub struct MachineFrameFigures {
    /// Work offset used (machine coordinates of the program's zero), mm.
    pub datum_mm: [f64; 3],
    /// Peak speed of X Y Z at the programmed feed, m/min.
    pub peak_speed: BTreeMap<String, f64>,
    /// Lowest ratio of X Y Z.
    pub axis_min_ratio: BTreeMap<String, f64>,
    /// Binding limit of X Y Z at their lowest ratio (written `V`, `A`, `J`).
    #[serde(serialize_with = "limits_by_name")]
    pub axis_limit: BTreeMap<String, LimitKind>,
}

/// The whole analysis document.
#[derive(Debug, Clone, Serialize)]
pub struct AnalyzeReport {
    /// File name.
    pub file: String,
    /// Machine name.
    pub machine: String,
    /// Singular cone used, degrees.
    pub cone_deg: f64,
    /// Pole reach used, degrees ([`polepatch_patcher::pole_dominates`]).
    pub pole_reach_deg: f64,
    /// The tilting letter the program uses as the primary axis (`A` or `B`).
    pub primary: String,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// Lines carried through without analysis ([`super::NotAnalysed`]).
    pub not_analysed: Vec<crate::notes::NotAnalysed>,
    /// Runs in file order (last: the CLI prints the report as it goes).
    pub runs: Vec<RunReport>,
}

impl AnalyzeReport {
    /// What `analyze --strict` counts as a failure: runs that could not be analysed and
    /// lines carried through without analysis.
    pub fn strict_failures(&self) -> usize {
        self.runs.iter().filter(|r| r.error.is_some()).count() + self.not_analysed.len()
    }
}
