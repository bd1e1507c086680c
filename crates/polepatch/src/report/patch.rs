//! The report of a patch: per zone ([`ZoneRow`], also the CSV row), per run left as it
//! is ([`UntouchedRun`]) and per file ([`FileReport`], the JSON of `polepatch patch
//! --report`).

use super::{
    SimulatedTimes, axis_letter, by_name, by_name_or_dash, feed_mode_by_name, limit_by_name,
    limit_name,
};
use crate::tool::{Tool, ToolPoint};
use polepatch_kinematics::{LimitKind, Machine};
use polepatch_nc::FeedMode;
use polepatch_patcher::{Method, Outcome, QpStatus, ZoneFigures, ZoneKind};
use serde::Serialize;

/// Equation-6 figures of a zone, with axis letters (report form of [`ZoneFigures`]).
#[derive(Debug, Clone, Serialize)]
pub struct FiguresRow {
    /// Lowest C-limited ratio.
    pub c_ratio: f64,
    /// Lowest primary-limited ratio.
    pub primary_ratio: f64,
    /// Lowest overall ratio.
    pub overall_ratio: f64,
    /// Limiting axis letter (`null`: the feed).
    pub limiting_axis: Option<String>,
    /// `V`, `A`, `J` or `F` ([`limit_name`]).
    #[serde(serialize_with = "limit_by_name")]
    pub limiting_limit: LimitKind,
    /// Estimated time over the zone, s.
    pub time_s: f64,
}

impl FiguresRow {
    /// The report form of `f`, axes named with the program's tilting letter.
    pub(crate) fn new(f: &ZoneFigures, letters: polepatch_nc::RotaryLetters) -> Self {
        FiguresRow {
            c_ratio: f.c_ratio,
            primary_ratio: f.primary_ratio,
            overall_ratio: f.overall_ratio,
            limiting_axis: f.limiting_axis.map(|a| axis_letter(a, letters)),
            limiting_limit: f.limiting_kind,
            time_s: f.time_s,
        }
    }
}

/// One zone of one file (a report row; also the CSV row, flattened).
#[derive(Debug, Clone, Serialize)]
pub struct ZoneRow {
    /// Input file.
    pub file: String,
    /// Run number, from 1.
    pub run: usize,
    /// File lines of the first and last point of the zone/patch.
    pub lines: [usize; 2],
    /// File lines of the first and last point of the zone's core (the zone ± a few points):
    /// where `reached` says the written program reaches feed, and where `verify` holds it
    /// to that (JSON only).
    pub core_lines: [usize; 2],
    /// `a_flip` or `c_swing` (in text: `A-flip`, `C-swing`).
    pub kind: ZoneKind,
    /// Smallest |primary|, degrees.
    pub min_abs_primary_deg: f64,
    /// Before patching.
    pub before: FiguresRow,
    /// After patching, on the values as written (the `before` figures when the patch was
    /// not written).
    pub after: FiguresRow,
    /// L/F over the zone, s.
    pub ideal_time_s: f64,
    /// Largest orientation deviation, degrees.
    pub max_deviation_deg: f64,
    /// Points of the zone whose primary axis or C changed.
    pub points_modified: usize,
    /// Points of the zone whose primary axis changed.
    pub primary_points_modified: usize,
    /// Whether the IK branch was re-selected (points put on the other branch, `(P, C) →
    /// (−P, C ± 180°)`).
    pub branch_reselected: bool,
    /// Points after the zone re-selected onto the other branch as a block (both words
    /// rewritten, tool axes unchanged).
    pub reselected_points: usize,
    /// Patched length, mm.
    pub patch_length_mm: f64,
    /// `reached`, `improved` or `unchanged`.
    #[serde(serialize_with = "by_name")]
    pub outcome: Outcome,
    /// Why (a fixed set, [`ZoneReason`]): the patcher's reasons ([`Reason`]: `reached`,
    /// `reselected`, `end_pinned`, `range`, `deviation_cap`, `safety_bound`, `tip_path`,
    /// `proven_unreachable`, `not_found`, `not_patched`), then the library's, where the
    /// run's circumstances decided (`tcpm_unknown`, `centre_path`, `tool_limited`, …).
    pub reason: ZoneReason,
    /// Whether the run's last point could change: `free` or `pinned`
    /// ([`crate::EndPose`]); `None`, written `-`, for a run that was not patched.
    #[serde(serialize_with = "by_name_or_dash")]
    pub end_pose: Option<EndFreedom>,
    /// File line of the block after the run that decided its end pose (`None`: the end of
    /// the file, or a run without TCPM, whose end is always pinned).
    pub end_pose_line: Option<usize>,
    /// The IK branch the run starts on as written: `program` (the input's) or `other`
    /// (the plan put it on the other branch, the positioning move before it rewritten to
    /// go there: [`crate::plan`]); `None`, written `-`, for a run that was not patched.
    #[serde(serialize_with = "by_name_or_dash")]
    pub start_branch: Option<Branch>,
    /// The branch the run ends on as written (the same names).
    #[serde(serialize_with = "by_name_or_dash")]
    pub end_branch: Option<Branch>,
    /// `reselect`, `joint`, `peer`, `g16_patch`, `direct` or `none` (in text and CSV:
    /// `g16-patch`).
    pub method: Method,
    /// Last solver status.
    pub qp_status: QpStatus,
    /// Interior-point iterations, summed.
    pub qp_iterations: u32,
    /// QP solves.
    pub qp_solves: u32,
    /// Solve time, ms, summed.
    pub solve_time_ms: f64,
    /// Decimal places written for the changed C words.
    pub decimals: usize,
    /// Decimal places written for the changed primary-axis words.
    pub primary_decimals: usize,
    /// 360° multiple added to C after the zone.
    pub c_offset_deg: f64,
    /// Feed mode of the run: `G94` (feed per minute) or `G93` (inverse time: each block
    /// keeps its time, F words untouched).
    #[serde(serialize_with = "feed_mode_by_name")]
    pub feed_mode: FeedMode,
    /// The tool the run was patched for, written `ball D10`, `flat D12`, `bull D10 R2`,
    /// `unknown`, or `-` for a run that was not patched ([`crate::tool`]).
    #[serde(serialize_with = "by_name")]
    pub tool: ZoneTool,
    /// Where the tool was found (`--tool`, `tool table (T5)`, `line 12: TOOL DEF …`,
    /// `CL line 9: CUTTER/…`), or why it is unknown.
    pub tool_source: String,
    /// What another source says of the tool where it disagrees with the one used (`the
    /// tool table's entry for T5 says ball D10, the program's description says flat D10
    /// (line 4: …): the program's is used`); `None` where none does
    /// ([`crate::tool::RunTool::disagreement`]).
    pub tool_disagreement: Option<String>,
    /// Which point of the tool X Y Z state: `tip` or `centre`; `None`, written `-`, for a
    /// run that was not patched.
    #[serde(serialize_with = "by_name_or_dash")]
    pub tool_point: Option<ToolPoint>,
    /// Why that point (`--tool-point`, the machine file, the TCPM code).
    pub tool_point_source: String,
    /// 2·sin(δ/2) for the zone's largest orientation change δ: how far a ball's centre
    /// moves per mm of its radius when the tool turns about its tip (the figure to read
    /// when the tool is unknown).
    pub centre_shift_per_mm_radius: f64,
    /// The largest displacement of the cutter at a written point, mm: a ball's centre
    /// (from the written values: 0 within rounding where the centre is kept), the bound
    /// 2·√(R² + r²)·sin(δ/2) on a flat or bull-nose cutter's end; `None` when the tool is
    /// unknown.
    pub max_cutter_shift_mm: Option<f64>,
    /// A ball programmed at its tip: the largest distance between the centre's path of the
    /// written blocks and the original's, between the points (the controller moving the
    /// tip on a line and the rotary axes linearly), mm; `None` otherwise.
    pub centre_chord_mm: Option<f64>,
    /// Reason `deviation_cap`, `safety_bound` or `tool_limited`: the orientation change a
    /// patch reaching feed needed, degrees.
    pub needed_deviation_deg: Option<f64>,
    /// On the last zone of a run whose end is free: the positioning move after the run
    /// (the rapid or rotary repositioning that freed it) — its line and its time before
    /// and after the patch, s (each axis at its V and A limits, the slowest setting the
    /// time: the slowest axis' trapezoid). A re-selected end can make it turn C
    /// by up to 180° more, or less.
    pub rapid_line: Option<usize>,
    /// That move's time from the original end, s.
    pub rapid_time_before_s: Option<f64>,
    /// That move's time from the patched end, s.
    pub rapid_time_after_s: Option<f64>,
}

/// Why a zone ended as it did (its row's `reason`): the patcher's [`Reason`], one fixed
/// set; the library sets the last six (`tcpm_unknown` … `tool_limited`) where the run's
/// circumstances decided, not the solve. `polepatch patch` counts them per file.
pub use polepatch_patcher::Reason as ZoneReason;

/// Whether a patched run's last point could change (a zone row's `end_pose`: what the
/// blocks after the run allow, [`crate::EndPose`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EndFreedom {
    /// The last point may change.
    Free,
    /// The last point keeps its values.
    Pinned,
}

impl EndFreedom {
    /// `free` or `pinned`: its serde form.
    pub fn name(self) -> &'static str {
        match self {
            EndFreedom::Free => "free",
            EndFreedom::Pinned => "pinned",
        }
    }
}

impl std::fmt::Display for EndFreedom {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The tool a zone's run was patched for (a zone row's `tool`, [`crate::tool`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ZoneTool {
    /// The run was not patched (written `-`).
    NotPatched,
    /// The tool is not known (written `unknown`).
    Unknown,
    /// This tool (written as [`Tool::describe`] does: `ball D10`, `bull D10 R2`).
    Known(Tool),
}

impl ZoneTool {
    /// The tool, when known.
    pub fn tool(self) -> Option<Tool> {
        match self {
            ZoneTool::Known(t) => Some(t),
            ZoneTool::NotPatched | ZoneTool::Unknown => None,
        }
    }
}

impl std::fmt::Display for ZoneTool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ZoneTool::NotPatched => f.write_str("-"),
            ZoneTool::Unknown => f.write_str("unknown"),
            ZoneTool::Known(t) => f.write_str(&t.describe()),
        }
    }
}

/// Report name of a feed mode: `G94`, `G93` or `G95`.
pub fn feed_mode_name(m: polepatch_nc::FeedMode) -> &'static str {
    match m {
        polepatch_nc::FeedMode::PerMinute => "G94",
        polepatch_nc::FeedMode::InverseTime => "G93",
        polepatch_nc::FeedMode::PerRevolution => "G95",
    }
}

impl ZoneRow {
    /// The row of a zone whose patch was found but not written (the run keeps its values,
    /// [`UntouchedRun`] says why): outcome `unchanged`, the figures after are the figures
    /// before, nothing deviates or moves. The method and solver figures stay: they say what
    /// was tried.
    pub fn not_written(&mut self) {
        self.outcome = Outcome::Unchanged;
        self.after = self.before.clone();
        self.max_deviation_deg = 0.0;
        self.points_modified = 0;
        self.primary_points_modified = 0;
        self.branch_reselected = false;
        self.reselected_points = 0;
        self.patch_length_mm = 0.0;
        self.c_offset_deg = 0.0;
        self.centre_shift_per_mm_radius = 0.0;
        self.max_cutter_shift_mm = self.max_cutter_shift_mm.map(|_| 0.0);
        self.centre_chord_mm = None;
        self.rapid_time_after_s = self.rapid_time_before_s;
        self.start_branch = self.start_branch.map(|_| Branch::Program);
        self.end_branch = self.end_branch.map(|_| Branch::Program);
    }
}

impl ZoneRow {
    /// CSV column names of [`ZoneRow::csv_fields`] (the row's fields after `file`).
    pub const CSV_COLUMNS: [&'static str; 46] = [
        "run",
        "first_line",
        "last_line",
        "kind",
        "min_abs_primary_deg",
        "c_ratio_before",
        "c_ratio_after",
        "primary_ratio_before",
        "primary_ratio_after",
        "overall_ratio_before",
        "overall_ratio_after",
        "limiting_before",
        "limiting_after",
        "time_before_s",
        "time_after_s",
        "ideal_time_s",
        "max_deviation_deg",
        "points_modified",
        "primary_points_modified",
        "branch_reselected",
        "reselected_points",
        "patch_length_mm",
        "outcome",
        "reason",
        "end_pose",
        "end_pose_line",
        "start_branch",
        "end_branch",
        "method",
        "qp_status",
        "qp_iterations",
        "qp_solves",
        "solve_time_ms",
        "decimals",
        "primary_decimals",
        "c_offset_deg",
        "feed_mode",
        "tool",
        "tool_point",
        "centre_shift_per_mm_radius",
        "max_cutter_shift_um",
        "centre_chord_um",
        "needed_deviation_deg",
        "rapid_line",
        "rapid_time_before_s",
        "rapid_time_after_s",
    ];

    /// The row as CSV fields, in [`ZoneRow::CSV_COLUMNS`] order.
    pub fn csv_fields(&self) -> Vec<String> {
        let lim = |f: &FiguresRow| {
            format!(
                "{}:{}",
                f.limiting_axis.as_deref().unwrap_or("-"),
                limit_name(f.limiting_limit)
            )
        };
        vec![
            self.run.to_string(),
            self.lines[0].to_string(),
            self.lines[1].to_string(),
            self.kind.to_string(),
            format!("{:.6}", self.min_abs_primary_deg),
            format!("{:.6}", self.before.c_ratio),
            format!("{:.6}", self.after.c_ratio),
            format!("{:.6}", self.before.primary_ratio),
            format!("{:.6}", self.after.primary_ratio),
            format!("{:.6}", self.before.overall_ratio),
            format!("{:.6}", self.after.overall_ratio),
            lim(&self.before),
            lim(&self.after),
            format!("{:.6}", self.before.time_s),
            format!("{:.6}", self.after.time_s),
            format!("{:.6}", self.ideal_time_s),
            format!("{:.6}", self.max_deviation_deg),
            self.points_modified.to_string(),
            self.primary_points_modified.to_string(),
            self.branch_reselected.to_string(),
            self.reselected_points.to_string(),
            format!("{:.3}", self.patch_length_mm),
            self.outcome.to_string(),
            self.reason.to_string(),
            self.end_pose.map_or("-", EndFreedom::name).to_string(),
            self.end_pose_line.map_or(String::new(), |l| l.to_string()),
            self.start_branch.map_or("-", Branch::name).to_string(),
            self.end_branch.map_or("-", Branch::name).to_string(),
            self.method.to_string(),
            self.qp_status.to_string(),
            self.qp_iterations.to_string(),
            self.qp_solves.to_string(),
            format!("{:.3}", self.solve_time_ms),
            self.decimals.to_string(),
            self.primary_decimals.to_string(),
            format!("{}", self.c_offset_deg),
            feed_mode_name(self.feed_mode).to_string(),
            self.tool.to_string(),
            self.tool_point.map_or("-", ToolPoint::name).to_string(),
            format!("{:.6}", self.centre_shift_per_mm_radius),
            self.max_cutter_shift_mm
                .map_or(String::new(), |v| format!("{:.3}", v * 1e3)),
            self.centre_chord_mm
                .map_or(String::new(), |v| format!("{:.3}", v * 1e3)),
            self.needed_deviation_deg
                .map_or(String::new(), |v| format!("{v:.6}")),
            self.rapid_line.map_or(String::new(), |l| l.to_string()),
            self.rapid_time_before_s
                .map_or(String::new(), |v| format!("{v:.6}")),
            self.rapid_time_after_s
                .map_or(String::new(), |v| format!("{v:.6}")),
        ]
    }
}

/// Which IK branch a run's end is on, as written (the plan's choice, [`crate::plan`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Branch {
    /// The input's values.
    Program,
    /// The other branch: `(−P, C ± 180°)`, the same tool axis.
    Other,
}

impl Branch {
    /// `program` or `other`: its serde form.
    pub fn name(self) -> &'static str {
        match self {
            Branch::Program => "program",
            Branch::Other => "other",
        }
    }
}

impl std::fmt::Display for Branch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a run was left as it is although polepatch could have looked at it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum UntouchedReason {
    /// No TCPM active: X Y Z are machine coordinates, so rotary words cannot change alone.
    NoTcpm,
    /// Incremental mode (G91): a changed value would shift every later position.
    Incremental,
    /// No feed in force and none given.
    NoFeed,
    /// The run's values could not be analysed (a path error).
    Invalid,
    /// With the machine's kinematic chain: the patch would make a linear axis worse in the
    /// machine frame, or could not be written through the chain.
    MachineFrame,
    /// TCPM is switched by a block that block delete (`/`) may skip: X Y Z may be machine
    /// coordinates.
    TcpmUncertain,
    /// The feed is below [`crate::program::MIN_FEED_MM_MIN`].
    FeedTooLow,
    /// A rotary axis moves while its value at some point is unknown.
    UnknownRotary,
    /// The file does not settle whether TCPM is on (after a call of code outside it, where
    /// a jump, a label or a loop joins different states, after `TRACON`/`G43.8`:
    /// [`polepatch_nc::flow`]): X Y Z may be machine coordinates.
    TcpmUnknown,
    /// A ball programmed at its tip: keeping its centre at the points would move it off its
    /// original path between them by more than the chord tolerance ([`crate::tool`]).
    CentrePath,
    /// A rotation, scaling or mirror image of the frame is in force (`G68`, `G51`, `G51.1`,
    /// Heidenhain `G73`/`G72`/`G28`, `CYCL DEF 8/10/11/19/26`, `PLANE`, Sinumerik
    /// `ROT`/`SCALE`/`MIRROR`, `CYCLE800`): the program's X Y Z and tool axis are not the
    /// frame polepatch computes in.
    FrameTransformed,
    /// The run turns a tilting axis the machine does not have (or holds it away from 0).
    OtherRotary,
    /// A rotary word in a Sinumerik direction form (`C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`)
    /// cannot make the patched move (DC goes the shorter way, ACP/ACN in their direction),
    /// or the patch would insert a plain word of a letter the file writes in that form.
    DirectionForm,
    /// The patch would change a word whose value is a macro variable or an expression
    /// (`C#105`, read as the variable's constant value): such a word is never rewritten.
    MacroVariable,
}

impl UntouchedReason {
    /// The reason a zone of such a run reports, where it says more than `not_patched`.
    pub fn zone_reason(self) -> Option<ZoneReason> {
        match self {
            UntouchedReason::TcpmUnknown => Some(ZoneReason::TcpmUnknown),
            UntouchedReason::FrameTransformed => Some(ZoneReason::FrameTransformed),
            UntouchedReason::DirectionForm => Some(ZoneReason::DirectionForm),
            UntouchedReason::MacroVariable => Some(ZoneReason::MacroVariable),
            UntouchedReason::CentrePath => Some(ZoneReason::CentrePath),
            _ => None,
        }
    }
}

/// A run left byte-identical, and why.
#[derive(Debug, Clone, Serialize)]
pub struct UntouchedRun {
    /// Run number, from 1.
    pub run: usize,
    /// File lines of the first and last point.
    pub lines: [usize; 2],
    /// Why.
    pub reason: UntouchedReason,
    /// Singular zones the run holds (reported in [`FileReport::zones`] as `unchanged`).
    pub zones: usize,
    /// A point of the run is as near the pole as a zone can lie (the larger of the cone and
    /// the pole reach, as every other "near the pole" of a run), or its primary value is
    /// not stated:
    /// the run may hold a zone. With `zones` = 0 such a run was not analysed (no feed,
    /// invalid values), so whether it reaches feed is unknown ([`FileReport::runs_not_analysed`]).
    pub near_pole: bool,
    /// The message for people.
    pub message: String,
}

/// What patching one program did (the JSON of `polepatch patch --report`).
#[derive(Debug, Clone, Serialize)]
pub struct FileReport {
    /// Input file (or the name given for in-memory input).
    pub file: String,
    /// Output file (when written; set by the caller that writes it).
    pub output: Option<String>,
    /// Machine name.
    pub machine: String,
    /// Words changed or inserted.
    pub words_changed: usize,
    /// Decimal places of the file's C words (`None` when no run came near the pole, so
    /// the file's style was not read).
    pub file_c_decimals: Option<usize>,
    /// Decimal places written for changed C words (more than the file's when its
    /// precision could not hold Equation 6).
    pub written_c_decimals: Option<usize>,
    /// Decimal places of the file's primary-axis words (`None` as for C).
    pub file_primary_decimals: Option<usize>,
    /// Decimal places written for changed primary-axis words.
    pub written_primary_decimals: Option<usize>,
    /// Runs left as they are (no TCPM, G91, no feed, invalid values), with why.
    pub untouched_runs: Vec<UntouchedRun>,
    /// Lines carried through without analysis (expressions, arcs and skippable blocks near
    /// the pole, …; [`super::NotAnalysed`]).
    pub not_analysed: Vec<crate::notes::NotAnalysed>,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// One row per zone.
    pub zones: Vec<ZoneRow>,
    /// The simulated cycle time of the input and of the output
    /// ([`super::compare`]), when the caller asked for it (`patch --simulate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simulated: Option<SimulatedTimes>,
}

impl FileReport {
    /// The report of a file left as it is: no zone, no word changed.
    pub fn unchanged(file: &str, machine: &Machine, warnings: Vec<String>) -> FileReport {
        FileReport {
            file: file.to_string(),
            output: None,
            machine: machine.name.clone(),
            words_changed: 0,
            file_c_decimals: None,
            written_c_decimals: None,
            file_primary_decimals: None,
            written_primary_decimals: None,
            untouched_runs: Vec::new(),
            not_analysed: Vec::new(),
            warnings,
            zones: Vec::new(),
            simulated: None,
        }
    }
    /// Zones that stay below feed (including those of untouched runs).
    pub fn zones_below_feed(&self) -> usize {
        self.zones
            .iter()
            .filter(|z| z.outcome != Outcome::Reached)
            .count()
    }
    /// What `--strict` counts as a failure: zones that stay below feed (those of untouched
    /// runs included), runs near the pole that could not be analysed (no feed, a feed too
    /// low, G93 with differing feeds, an unknown rotary value, invalid values:
    /// [`FileReport::runs_not_analysed`]) and lines carried through without analysis.
    pub fn strict_failures(&self) -> usize {
        self.zones_below_feed()
            + self.runs_not_analysed()
            + self.not_analysed.len()
            + self.zones_with_unknown_tool()
    }
    /// Zones whose tool orientation changed while the tool is unknown: whether the cutter
    /// stayed on the part cannot be told ([`crate::tool`]).
    pub fn zones_with_unknown_tool(&self) -> usize {
        self.zones
            .iter()
            .filter(|z| z.tool == ZoneTool::Unknown && z.max_deviation_deg > 0.0)
            .count()
    }
    /// Add the tool warnings a report needs: each disagreement between the sources of a
    /// tool once ([`ZoneRow::tool_disagreement`]), and once the warning a report with
    /// [`FileReport::zones_with_unknown_tool`] needs.
    pub fn warn_tools(&mut self) {
        let mut said: Vec<&str> = Vec::new();
        for z in &self.zones {
            if let Some(d) = &z.tool_disagreement
                && !said.contains(&d.as_str())
            {
                said.push(d);
            }
        }
        let said: Vec<String> = said
            .into_iter()
            .map(|d| format!("{}: the tool's sources disagree: {d}", self.file))
            .collect();
        self.warnings.extend(said);
        self.warn_unknown_tool();
    }

    /// Add, once, the warning a report with [`FileReport::zones_with_unknown_tool`] needs.
    pub fn warn_unknown_tool(&mut self) {
        let n = self.zones_with_unknown_tool();
        if n == 0 {
            return;
        }
        let worst = self
            .zones
            .iter()
            .filter(|z| z.tool == ZoneTool::Unknown)
            .map(|z| z.centre_shift_per_mm_radius)
            .fold(0.0, f64::max);
        self.warnings.push(format!(
            "{}: the tool is not known for {n} changed zone(s): a ball programmed at its tip moves \
             its centre by up to {:.4} mm per mm of its radius there (the zones' \
             centre_shift_per_mm_radius), a flat or bull-nose cutter its edge; say the tool \
             with --tool ball:D, flat:D or bull:D,R, a tool table (--tools FILE), or in the \
             program (TOOL DEF, the CAM post's tool comments), and the point X Y Z state with \
             --tool-point tip|centre",
            self.file, worst
        ));
    }
    /// Runs that may hold a zone (a point within the cone) but could not be analysed (no
    /// feed, invalid values): whether they reach feed is unknown.
    pub fn runs_not_analysed(&self) -> usize {
        self.untouched_runs
            .iter()
            .filter(|u| u.near_pole && u.zones == 0)
            .count()
    }
    /// Runs left because no TCPM is active although they hold a singular zone.
    pub fn runs_left_without_tcpm(&self) -> usize {
        self.untouched_runs
            .iter()
            .filter(|u| {
                matches!(
                    u.reason,
                    UntouchedReason::NoTcpm
                        | UntouchedReason::TcpmUncertain
                        | UntouchedReason::TcpmUnknown
                ) && u.zones > 0
            })
            .count()
    }
}
