//! Patching a whole program: runs → patcher → edits → bytes.
//!
//! [`patch_program`] is the one pipeline: every caller (the `polepatch` binary, `bench`,
//! the criterion benches, the tests, the C ABI) goes through it, by way of
//! [`crate::patch_nc`] for bytes or [`patch_loaded`] for a program already loaded.
//!
//! # What is never patched
//! A run whose X Y Z are machine coordinates (no TCPM: M128, TRAORI, G43.4 not active) is
//! analysed and reported but left byte-identical: on a table-table machine without TCPM,
//! changing a rotary value while X Y Z stay moves the part under the tool (a gouge).
//! A run in incremental mode (G91) is left the same way: a changed value there would shift
//! every later position. Both appear in [`FileReport::untouched_runs`] when they hold a
//! singular zone.

use crate::machine_frame;
use crate::program::{LoadedProgram, RunProblem};
use crate::report::{axis_letter, limit_name, zone_kind_name};
use crate::tool::{RunTool, ToolKind, ToolPoint};
use polepatch_kinematics::Machine;
use polepatch_nc::{Edit, NumberStyle, Tcpm};
use polepatch_patcher::KeepCentre;
use polepatch_patcher::{
    Method, Outcome, PatchOptions, QpStatus, ZoneFigures, ZoneReport, patch_path, report_unpatched,
};
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
    /// `V`, `A`, `J` or `F`.
    pub limiting_limit: &'static str,
    /// Estimated time over the zone, s.
    pub time_s: f64,
}

impl FiguresRow {
    fn new(f: &ZoneFigures, primary_letter: u8) -> Self {
        FiguresRow {
            c_ratio: f.c_ratio,
            primary_ratio: f.primary_ratio,
            overall_ratio: f.overall_ratio,
            limiting_axis: f.limiting_axis.map(|a| axis_letter(a, primary_letter)),
            limiting_limit: limit_name(f.limiting_kind),
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
    /// `A-flip` or `C-swing`.
    pub kind: &'static str,
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
    pub outcome: &'static str,
    /// Why (a fixed set: [`polepatch_patcher::Reason`]): `reached`, `reselected`,
    /// `end_pinned`, `range`, `deviation_cap`, `safety_bound`, `tip_path`,
    /// `proven_unreachable`, `not_found`, `not_patched`.
    pub reason: &'static str,
    /// Whether the run's last point could change: `free` or `pinned`
    /// ([`crate::end_pose`]); `-` for a run that was not patched.
    pub end_pose: &'static str,
    /// File line of the block after the run that decided its end pose (`None`: the end of
    /// the file, or a run without TCPM, whose end is always pinned).
    pub end_pose_line: Option<usize>,
    /// `reselect`, `joint`, `g16-patch`, `direct` or `none`.
    pub method: &'static str,
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
    pub feed_mode: &'static str,
    /// The tool the run was patched for (`ball D10`, `flat D12`, `bull D10 R2`), `unknown`,
    /// or `-` for a run that was not patched ([`crate::tool`]).
    pub tool: String,
    /// Where the tool was found (`--tool`, `tool table (T5)`, `line 12: TOOL DEF …`), or
    /// why it is unknown.
    pub tool_source: String,
    /// Which point of the tool X Y Z state: `tip`, `centre`, or `-`.
    pub tool_point: &'static str,
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
    /// time: [`crate::end_pose::NextMove::time_s`]). A re-selected end can make it turn C
    /// by up to 180° more, or less.
    pub rapid_line: Option<usize>,
    /// That move's time from the original end, s.
    pub rapid_time_before_s: Option<f64>,
    /// That move's time from the patched end, s.
    pub rapid_time_after_s: Option<f64>,
}

/// How many times a run whose kept ball centre would leave its path between the points by
/// more than the chord tolerance is solved again with its orientation change capped.
const CENTRE_PATH_RETRIES: usize = 3;

/// The cap of such a retry: the deviation that gave the excursion, scaled by the tolerance
/// over the excursion and by this margin.
const CENTRE_PATH_CAP_SAFETY: f64 = 0.9;

/// Below this, a positioning move's time after a run is the same before and after a patch
/// (what the end's choice ignores), s.
const RAPID_TIME_TOL_S: f64 = 1e-3;

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
        self.outcome = "unchanged";
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
    }
}

/// Report name of an outcome.
pub fn outcome_name(o: Outcome) -> &'static str {
    match o {
        Outcome::Reached => "reached",
        Outcome::Improved => "improved",
        Outcome::Unchanged => "unchanged",
    }
}

fn method_name(m: Method) -> &'static str {
    match m {
        Method::Reselect => "reselect",
        Method::Joint => "joint",
        Method::Peer => "peer",
        Method::G16Patch => "g16-patch",
        Method::Direct => "direct",
        Method::None => "none",
    }
}

impl ZoneRow {
    /// CSV column names of [`ZoneRow::csv_fields`] (the row's fields after `file`).
    pub const CSV_COLUMNS: [&'static str; 44] = [
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
                f.limiting_limit
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
            self.end_pose.to_string(),
            self.end_pose_line.map_or(String::new(), |l| l.to_string()),
            self.method.to_string(),
            self.qp_status.to_string(),
            self.qp_iterations.to_string(),
            self.qp_solves.to_string(),
            format!("{:.3}", self.solve_time_ms),
            self.decimals.to_string(),
            self.primary_decimals.to_string(),
            format!("{}", self.c_offset_deg),
            self.feed_mode.to_string(),
            self.tool.clone(),
            self.tool_point.to_string(),
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

    fn new(lp: &LoadedProgram, run: usize, z: &ZoneReport) -> Self {
        let pl = lp.primary_letter;
        ZoneRow {
            file: lp.name.clone(),
            run: lp.run_number(run),
            lines: [lp.line_of(run, z.first), lp.line_of(run, z.last)],
            kind: zone_kind_name(z.kind),
            min_abs_primary_deg: z.min_abs_primary_deg,
            before: FiguresRow::new(&z.before, pl),
            after: FiguresRow::new(&z.after, pl),
            ideal_time_s: z.ideal_time_s,
            max_deviation_deg: z.max_deviation_deg,
            points_modified: z.points_modified,
            primary_points_modified: z.primary_points_modified,
            branch_reselected: z.reselected_points > 0 || z.method == Method::Reselect,
            reselected_points: z.reselected_points,
            patch_length_mm: z.patch_length_mm,
            outcome: outcome_name(z.outcome),
            reason: z.reason.name(),
            end_pose: "-",
            end_pose_line: None,
            method: method_name(z.method),
            qp_status: z.qp.status,
            qp_iterations: z.qp.iterations,
            qp_solves: z.qp.solves,
            solve_time_ms: z.qp.solve_time_s * 1e3,
            decimals: z.decimals,
            primary_decimals: z.p_decimals,
            c_offset_deg: z.c_offset_deg,
            feed_mode: feed_mode_name(lp.runs[run].run.feed_mode),
            tool: "-".to_string(),
            tool_source: String::new(),
            tool_point: "-",
            tool_point_source: String::new(),
            centre_shift_per_mm_radius: crate::tool::centre_shift_per_mm_radius(
                z.max_deviation_deg,
            ),
            max_cutter_shift_mm: None,
            centre_chord_mm: None,
            needed_deviation_deg: z.needed_deviation_deg,
            rapid_line: None,
            rapid_time_before_s: None,
            rapid_time_after_s: None,
        }
    }
}

/// Why a run was left as it is although polepatch could have looked at it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
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
    pub fn zone_reason(self) -> Option<&'static str> {
        match self {
            UntouchedReason::TcpmUnknown => Some("tcpm_unknown"),
            UntouchedReason::FrameTransformed => Some("frame_transformed"),
            UntouchedReason::DirectionForm => Some("direction_form"),
            UntouchedReason::MacroVariable => Some("macro_variable"),
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
    /// A point of the run is within the singular cone, or its primary value is not stated:
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
    /// the pole, …; [`crate::notes`]).
    pub not_analysed: Vec<crate::notes::NotAnalysed>,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// One row per zone.
    pub zones: Vec<ZoneRow>,
    /// The simulated cycle time of the input and of the output
    /// ([`crate::simulate::compare`]), when the caller asked for it (`patch --simulate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simulated: Option<crate::simulate::SimulatedTimes>,
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
        self.zones.iter().filter(|z| z.outcome != "reached").count()
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
            .filter(|z| z.tool == "unknown" && z.max_deviation_deg > 0.0)
            .count()
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
            .filter(|z| z.tool == "unknown")
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

/// Patch a loaded program: the edits to write and the report.
///
/// `opts.c_decimals` and `opts.p_decimals` are taken from the file (its number style);
/// `opts.max_decimals` is raised to the file's decimals when lower.
pub fn patch_program(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &PatchOptions,
) -> (Vec<Edit>, FileReport) {
    let program = &lp.program;
    let mut report = FileReport::unchanged(&lp.name, machine, lp.warnings.clone());
    let (not_analysed, warnings) = lp
        .notes
        .finish(lp.primary_index(), opts.reach_deg(), &lp.name);
    report.not_analysed = not_analysed;
    report.warnings.extend(warnings);
    // The file's number style is only needed when some run comes near the pole; reading
    // it costs a pass over every word, so a program without such a run skips it.
    let pi = polepatch_kinematics::Axis::Primary.index();
    let near_pole = lp.runs.iter().any(|r| {
        r.path
            .as_ref()
            .is_ok_and(|p| p.axes.iter().any(|q| q[pi].abs() <= opts.reach_deg()))
    });
    if !near_pole {
        for (r, rp) in lp.runs.iter().enumerate() {
            if let Err(problem) = &rp.path {
                report.untouched_runs.push(untouched(
                    lp,
                    r,
                    problem_reason(problem),
                    0,
                    problem.to_string(),
                    opts.reach_deg(),
                ));
            }
        }
        return (Vec::new(), report);
    }
    let file_style = lp.file_style();
    let style_of = |l: u8| {
        file_style
            .letter(l)
            .unwrap_or_else(|| NumberStyle::of(program, l))
    };
    let c_style = style_of(b'C');
    let p_style = style_of(lp.primary_letter);
    let opts = PatchOptions {
        c_decimals: c_style.decimals,
        p_decimals: p_style.decimals,
        max_decimals: opts
            .max_decimals
            .max(c_style.decimals)
            .max(p_style.decimals),
        ..opts.clone()
    };
    let xyz_decimals = style_of(b'X').decimals.max(machine_frame::MIN_XYZ_DECIMALS);
    // X Y Z rewritten to keep a ball's centre are written as the file writes them, to a
    // micrometre at least (a file of round values, `X0.5 Y0 Z-5`, shows no precision).
    let xyz_file_decimals = [b'X', b'Y', b'Z']
        .map(|l| style_of(l).decimals)
        .into_iter()
        .max()
        .unwrap_or(0)
        .max(machine_frame::MIN_XYZ_DECIMALS);
    let mut edits: Vec<Edit> = Vec::new();
    let mut written_c = c_style.decimals;
    let mut written_p = p_style.decimals;
    // For each patched run: its index, its first zone row and its edits.
    let mut run_edit_ranges: Vec<(usize, usize, std::ops::Range<usize>)> = Vec::new();
    'runs: for (r, rp) in lp.runs.iter().enumerate() {
        let path = match &rp.path {
            Ok(p) => p,
            Err(problem) => {
                report.untouched_runs.push(untouched(
                    lp,
                    r,
                    problem_reason(problem),
                    0,
                    problem.to_string(),
                    opts.reach_deg(),
                ));
                continue;
            }
        };
        // A zone needs a point in the cone (`detect_zones`): a run with none has nothing to
        // patch or report, and its analysis is skipped.
        if !path.axes.iter().any(|q| q[pi].abs() <= opts.reach_deg()) {
            continue;
        }
        let incremental = rp
            .run
            .blocks
            .iter()
            .skip(1)
            .any(|&b| program.state(b).incremental);
        let chain = machine
            .chain
            .as_ref()
            .and_then(|ch| machine_frame::run_datum(lp, r, lp.work_offset_mm).map(|d| (ch, d)));
        let inch = rp.run.blocks.iter().any(|&b| program.state(b).inch);
        let leave = if rp.run.transform != 0 {
            Some((
                UntouchedReason::FrameTransformed,
                "a rotation, scaling or mirror image of the frame is in force (G68, G51, G51.1, \
                 G73/G72/G28 in Heidenhain ISO, CYCL DEF 8/10/11/19/26, PLANE, ROT/SCALE/MIRROR, \
                 CYCLE800): the program's X Y Z and tool axis are not in the frame polepatch \
                 computes in, so the run is left as it is",
            ))
        } else if rp.run.tcpm == Tcpm::Unknown {
            Some((
                UntouchedReason::TcpmUnknown,
                "whether TCPM is on here is not settled by the file: the run follows a call of \
                 code outside it, a label or a jump where ways with different TCPM states meet, \
                 or a code whose effect on TCPM polepatch does not know (TRACON, G43.8); X Y Z \
                 may be machine coordinates, so the run is left as it is",
            ))
        } else if rp.run.tcpm == Tcpm::Uncertain {
            Some((
                UntouchedReason::TcpmUncertain,
                "TCPM is switched by a block that block delete (`/`) may skip: whether X Y Z are \
                 part or machine coordinates depends on the block-delete switch, so the run is \
                 left as it is",
            ))
        } else if !rp.run.tcpm.is_on() && (chain.is_none() || inch || incremental) {
            Some((
                UntouchedReason::NoTcpm,
                if machine.chain.is_none() {
                    "no TCPM active (M128, TRAORI or G43.4) — X Y Z are machine coordinates; \
                     changing rotary words alone would move the part under the tool, so the run is \
                     left as it is (if the controller switches TCPM with other codes, or always \
                     runs with it, say so in the machine file's [controller] section: tcpm_on, \
                     tcpm_always; else give the machine's kinematic chain to patch it)"
                } else if chain.is_none() {
                    "no TCPM active and the work offset is unknown (the program states no datum \
                     with values): X Y Z cannot be recomputed, so the run is left as it is \
                     (give --work-offset X,Y,Z)"
                } else {
                    "no TCPM active, in inch or incremental mode: X Y Z are not recomputed there, \
                     so the run is left as it is"
                },
            ))
        } else if incremental {
            Some((
                UntouchedReason::Incremental,
                "incremental mode (G91) — a changed value would shift every later position; \
                 polepatch patches absolute (G90) programs only; left as it is",
            ))
        } else {
            None
        };
        if let Some((reason, message)) = leave {
            match report_unpatched(path, machine, &opts) {
                Ok(zones) => {
                    if !zones.is_empty() {
                        report.zones.extend(zones.iter().map(|z| {
                            let mut row = ZoneRow::new(lp, r, z);
                            if let Some(why) = reason.zone_reason() {
                                row.reason = why;
                            }
                            row
                        }));
                        report.untouched_runs.push(untouched(
                            lp,
                            r,
                            reason,
                            zones.len(),
                            message.to_string(),
                            opts.reach_deg(),
                        ));
                    }
                }
                Err(e) => report.untouched_runs.push(untouched(
                    lp,
                    r,
                    UntouchedReason::Invalid,
                    0,
                    e.to_string(),
                    opts.reach_deg(),
                )),
            }
            continue;
        }
        let end = crate::end_pose::end_pose(lp, r);
        let mut run_opts = PatchOptions {
            // Without TCPM the moves after the run are in machine coordinates: the last
            // point keeps its values (X Y Z included).
            keep_last_point: !rp.run.tcpm.is_on() || !end.free,
            ..opts.clone()
        };
        // The tool, and what it asks of the patch (crate::tool).
        let rt = run_tool(lp, r, machine);
        let mut tool_capped = false;
        match rt.tool {
            Some(t) if t.kind == ToolKind::Ball && rt.point == ToolPoint::Tip => {
                run_opts.keep_centre = Some(KeepCentre {
                    radius_mm: t.diameter_mm / 2.0,
                    // Without TCPM the part-frame tips go through the chain, not to the
                    // file: kept exact there.
                    decimals: match (rp.run.tcpm.is_on(), inch) {
                        (false, _) => 9,
                        (true, false) => xyz_file_decimals,
                        // 10⁻⁴ inch is 2.5 µm: one more.
                        (true, true) => xyz_file_decimals.max(MIN_INCH_XYZ_DECIMALS),
                    },
                    unit_mm: if inch && rp.run.tcpm.is_on() {
                        25.4
                    } else {
                        1.0
                    },
                    s_is_length: rp.run.feed_mode != polepatch_nc::FeedMode::InverseTime,
                });
            }
            Some(t) if t.kind != ToolKind::Ball => {
                let cap = crate::tool::deviation_cap_deg(&t, lp.tool.surface_tolerance_mm);
                if run_opts.max_deviation_deg.is_none_or(|c| cap <= c) {
                    run_opts.max_deviation_deg = Some(cap);
                    tool_capped = true;
                }
            }
            _ => {}
        }
        // Without TCPM (and with a chain) the patcher works on the part-frame path.
        let part_path = match (rp.run.tcpm, chain) {
            (Tcpm::Off, Some((ch, d))) => {
                Some(machine_frame::part_frame_path(ch, machine, d, path))
            }
            _ => None,
        };
        let work_path = part_path.as_ref().unwrap_or(path);
        let patch_with = |o: &PatchOptions| {
            if part_path.is_some() {
                machine_frame::patch_part_frame(work_path, machine, o)
            } else {
                patch_path(work_path, machine, o)
            }
        };
        let mut patched = patch_with(&run_opts);
        // The positioning move after a free end starts from the patched end: where that
        // costs more time than the patch saves in the run (a re-selected end whose next
        // rapid turns C by 180° more), the end is pinned instead when that is faster overall
        // (issue 31: every move the patch changes is accounted for).
        let rapid = |res: &polepatch_patcher::PatchResult| -> Option<(usize, f64, f64)> {
            let next = end.next.as_ref()?;
            let n = path.axes.len();
            let (p0, c0) = (path.axes[n - 1][3], path.axes[n - 1][4]);
            let (p1, c1) = (*res.p_deg.last()?, *res.c_deg.last()?);
            Some((
                next.line,
                next.time_s(machine, p0, c0),
                next.time_s(machine, p1, c1),
            ))
        };
        let run_time = |res: &polepatch_patcher::PatchResult| -> f64 {
            res.zones.iter().map(|z| z.after.time_s).sum::<f64>()
                + rapid(res).map_or(0.0, |(_, _, after)| after)
        };
        if let Ok(res) = &patched
            && !run_opts.keep_last_point
            && rapid(res).is_some_and(|(_, before, after)| after > before + RAPID_TIME_TOL_S)
        {
            let pinned_opts = PatchOptions {
                keep_last_point: true,
                ..run_opts.clone()
            };
            if let Ok(pinned) = patch_with(&pinned_opts)
                && run_time(&pinned) + RAPID_TIME_TOL_S < run_time(res)
            {
                patched = Ok(pinned);
                run_opts = pinned_opts;
            }
        }
        // A ball programmed at its tip keeps its centre at the points; between them its
        // path may not leave the original's line by more than the chord tolerance (where
        // the original block stayed within it). Where it would, the patch is solved again
        // with its orientation change capped in proportion (the centre's excursion between
        // two points grows with the change), up to CENTRE_PATH_RETRIES times.
        let chord_limit = lp.chord_tolerance_mm + machine_frame::TIP_TOLERANCE_MM;
        let mut centre_capped = false;
        let mut retries = 0;
        let (result, first_row) = loop {
            let result = match patched {
                Ok(res) => res,
                Err(e) => {
                    report.untouched_runs.push(untouched(
                        lp,
                        r,
                        UntouchedReason::Invalid,
                        0,
                        e.to_string(),
                        opts.reach_deg(),
                    ));
                    continue 'runs;
                }
            };
            let first_row = report.zones.len();
            report.zones.extend(result.zones.iter().map(|z| {
                let mut row = ZoneRow::new(lp, r, z);
                tool_fields(&mut row, &rt, z, work_path, &result, machine, tool_capped);
                if centre_capped && z.reason == polepatch_patcher::Reason::DeviationCap {
                    row.reason = "centre_path";
                }
                row.end_pose = if run_opts.keep_last_point {
                    "pinned"
                } else {
                    "free"
                };
                row.end_pose_line = if rp.run.tcpm.is_on() {
                    end.decided_line
                } else {
                    None
                };
                row
            }));
            if rp.run.tcpm.is_on()
                && let (Some((line, before, after)), Some(last)) =
                    (rapid(&result), report.zones[first_row..].last_mut())
            {
                last.rapid_line = Some(line);
                last.rapid_time_before_s = Some(before);
                last.rapid_time_after_s = Some(if run_opts.keep_last_point {
                    before
                } else {
                    after
                });
            }
            let rows = &report.zones[first_row..];
            let worst_chord = rows
                .iter()
                .filter_map(|z| z.centre_chord_mm)
                .fold(0.0, f64::max);
            if worst_chord <= chord_limit {
                break (result, first_row);
            }
            let worst_dev = rows.iter().map(|z| z.max_deviation_deg).fold(0.0, f64::max);
            if retries < CENTRE_PATH_RETRIES && worst_dev > 0.0 {
                retries += 1;
                let cap = worst_dev * (chord_limit / worst_chord) * CENTRE_PATH_CAP_SAFETY;
                run_opts.max_deviation_deg =
                    Some(run_opts.max_deviation_deg.map_or(cap, |c| c.min(cap)));
                centre_capped = true;
                report.zones.truncate(first_row);
                patched = patch_with(&run_opts);
                continue;
            }
            let row = rows
                .iter()
                .find(|z| z.centre_chord_mm.is_some_and(|c| c > chord_limit))
                .expect("a row over the limit");
            let why = format!(
                "between the points of lines {}–{} the ball's centre (X Y Z rewritten to keep it \
                 at the points) would leave the line between its original positions by {:.3} mm \
                 with the axes interpolated between the blocks (chord tolerance {} mm; the points \
                 are too far apart for the orientation change, also with the change capped); \
                 the run keeps its values",
                row.lines[0],
                row.lines[1],
                row.centre_chord_mm.unwrap_or(0.0),
                lp.chord_tolerance_mm
            );
            for row in &mut report.zones[first_row..] {
                row.not_written();
                row.reason = "centre_path";
            }
            report.untouched_runs.push(untouched(
                lp,
                r,
                UntouchedReason::CentrePath,
                result.zones.len(),
                why,
                opts.cone_deg,
            ));
            continue 'runs;
        };
        let first_edit = edits.len();
        let mut run_edits: Vec<Edit> = Vec::new();

        if let Some((ch, d)) = chain {
            match through_chain(
                lp,
                r,
                path,
                work_path,
                &result,
                machine,
                ch,
                d,
                &opts,
                xyz_decimals,
                lp.chord_tolerance_mm,
            ) {
                Ok(xyz) => run_edits = xyz,
                Err(why) => {
                    for row in &mut report.zones[first_row..] {
                        row.not_written();
                        row.reason = polepatch_patcher::Reason::NotPatched.name();
                    }
                    report.untouched_runs.push(untouched(
                        lp,
                        r,
                        UntouchedReason::MachineFrame,
                        result.zones.len(),
                        why,
                        opts.reach_deg(),
                    ));
                    continue;
                }
            }
        }
        edits.append(&mut run_edits);
        // A ball's centre kept under TCPM: the tips the patcher rewrote, in the file's unit
        // and decimals; blocks after the run that restate its last point follow it.
        if let (Some(keep), true) = (&run_opts.keep_centre, rp.run.tcpm.is_on()) {
            let n = rp.run.len();
            for k in 1..n {
                for (i, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                    if !result.xyz_changed[k][i] {
                        continue;
                    }
                    let value = result.xyz_mm[k][i] / keep.unit_mm;
                    edits.push(Edit {
                        block: rp.run.blocks[k],
                        letter,
                        value,
                        decimals: result.xyz_decimals,
                    });
                    if k == n - 1 && !run_opts.keep_last_point {
                        for &b in &end.restate {
                            if program.block_words(b).iter().any(|w| w.letter == letter) {
                                edits.push(Edit {
                                    block: b,
                                    letter,
                                    value,
                                    decimals: result.xyz_decimals,
                                });
                            }
                        }
                    }
                }
            }
        }
        let letters = [
            (
                lp.primary_letter,
                &result.p_deg,
                &result.p_changed,
                result.p_decimals,
            ),
            (b'C', &result.c_deg, &result.c_changed, result.c_decimals),
        ];
        for (letter, values, changed, decimals) in letters {
            for k in 0..rp.run.len() {
                if !changed[k] {
                    continue;
                }
                if k == 0 {
                    // Point 0 belongs to the block before the run; the patcher never moves it.
                    debug_assert!(false, "patcher changed the start point of a run");
                    continue;
                }
                if letter == b'C' {
                    written_c = written_c.max(decimals);
                } else {
                    written_p = written_p.max(decimals);
                }
                edits.push(Edit {
                    block: rp.run.blocks[k],
                    letter,
                    value: values[k],
                    decimals,
                });
            }
            // The run ends on new values: the blocks after it that restated its last
            // values restate the new ones (crate::end_pose).
            let n = rp.run.len();
            if !run_opts.keep_last_point && changed[n - 1] {
                for &b in &end.restate {
                    if program.block_words(b).iter().any(|w| w.letter == letter) {
                        edits.push(Edit {
                            block: b,
                            letter,
                            value: values[n - 1],
                            decimals,
                        });
                    }
                }
            }
        }
        run_edit_ranges.push((r, first_row, first_edit..edits.len()));
    }
    let file_decimals = |l: u8| match l {
        b'C' => c_style.decimals,
        b'X' | b'Y' | b'Z' => style_of(l).decimals,
        _ => p_style.decimals,
    };
    // Inside a run, a point that relied on a modal value keeps it; after a run only the
    // blocks that restate its last values are written: its end point only moves when what
    // follows does not depend on the pose (crate::end_pose).
    let run_of: std::collections::HashMap<usize, usize> = lp
        .runs
        .iter()
        .enumerate()
        .flat_map(|(r, rp)| rp.run.blocks.iter().skip(1).map(move |&b| (b, r)))
        .collect();
    let same_run = |edited: usize, b: usize| {
        run_of
            .get(&edited)
            .is_some_and(|r| run_of.get(&b) == Some(r))
    };
    polepatch_nc::restore_modal(program, &mut edits, &file_decimals, &same_run);
    let edits = direction_forms(lp, edits, &run_edit_ranges, &run_of, &mut report, &opts);
    let mut edits = edits;
    edits.sort_by_key(|e| (e.block, e.letter));
    report.words_changed = edits.len();
    report.file_c_decimals = Some(c_style.decimals);
    report.written_c_decimals = Some(written_c);
    report.file_primary_decimals = Some(p_style.decimals);
    report.written_primary_decimals = Some(written_p);
    (edits, report)
}

/// Rotary words in a Sinumerik direction form (`C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`): the
/// edits of such words are written modulo 360 in the same form where it makes the patched
/// move ([`polepatch_nc::write_direction_forms`]); a run whose edits ask a move the form
/// cannot make keeps its values (its zones `direction_form`), and the check is made again
/// without it (its edits changed where the next words start from).
fn direction_forms(
    lp: &LoadedProgram,
    edits: Vec<Edit>,
    run_edit_ranges: &[(usize, usize, std::ops::Range<usize>)],
    run_of: &std::collections::HashMap<usize, usize>,
    report: &mut FileReport,
    opts: &PatchOptions,
) -> Vec<Edit> {
    let program = &lp.program;
    // The run each edit belongs to (words restored by `restore_modal` are in its run).
    let mut owner: Vec<Option<usize>> = vec![None; edits.len()];
    for (r, _, range) in run_edit_ranges {
        for o in &mut owner[range.clone()] {
            *o = Some(*r);
        }
    }
    for (o, e) in owner.iter_mut().zip(&edits) {
        if o.is_none() {
            *o = run_of.get(&e.block).copied();
        }
    }
    let mut dropped: Vec<usize> = Vec::new();
    loop {
        let mut kept: Vec<Edit> = edits
            .iter()
            .zip(&owner)
            .filter(|(_, o)| o.is_none_or(|r| !dropped.contains(&r)))
            .map(|(e, _)| *e)
            .collect();
        let conflicts = polepatch_nc::write_direction_forms(program, &mut kept);
        let Some(k) = conflicts.first() else {
            return kept;
        };
        // The run of the edit that causes it.
        let run = edits
            .iter()
            .zip(&owner)
            .filter(|(e, o)| e.block == k.cause && o.is_some_and(|r| !dropped.contains(&r)))
            .find_map(|(_, o)| *o);
        let Some(run) = run else {
            // Not attributable (should not happen): write nothing in a direction form.
            report
                .warnings
                .push(format!("{}; no rotary word was changed", k.message));
            return Vec::new();
        };
        dropped.push(run);
        let reason = if k.variable {
            UntouchedReason::MacroVariable
        } else {
            UntouchedReason::DirectionForm
        };
        let Some((_, first_row, _)) = run_edit_ranges.iter().find(|(r, _, _)| *r == run) else {
            continue;
        };
        let zones = report.zones[*first_row..]
            .iter()
            .take_while(|z| z.run == lp.run_number(run))
            .count();
        for row in &mut report.zones[*first_row..*first_row + zones] {
            row.not_written();
            row.reason = reason.zone_reason().unwrap_or("not_patched");
        }
        report.untouched_runs.push(untouched(
            lp,
            run,
            reason,
            zones,
            if k.variable {
                format!("{}; the run keeps its values", k.message)
            } else {
                format!(
                    "{}: the form cannot make the patched move, and polepatch never writes a \
                     word that makes a different one; the run keeps its values",
                    k.message
                )
            },
            opts.reach_deg(),
        ));
    }
}

/// With a kinematic chain: for a run without TCPM, the X Y Z edits that keep the part-frame
/// tool tip of every changed point (from the written rotary values, checked within
/// [`machine_frame::TIP_TOLERANCE_MM`]); for every run, the machine-frame check (no axis's
/// lowest Equation-6 ratio worse than `min(before, 1)`). `Err` says why the run must keep
/// its original values.
#[allow(clippy::too_many_arguments)]
fn through_chain(
    lp: &LoadedProgram,
    r: usize,
    path: &polepatch_patcher::Path,
    work_path: &polepatch_patcher::Path,
    result: &polepatch_patcher::PatchResult,
    machine: &Machine,
    chain: &polepatch_kinematics::Chain,
    datum_mm: [f64; 3],
    opts: &PatchOptions,
    xyz_decimals: usize,
    chord_tolerance_mm: f64,
) -> Result<Vec<Edit>, String> {
    let rp = &lp.runs[r];
    let tcpm = rp.run.tcpm.is_on();
    let n = path.axes.len();
    let changed = |k: usize| result.p_changed[k] || result.c_changed[k];
    if !(0..n).any(changed) {
        return Ok(Vec::new());
    }
    let mut after: Vec<[f64; 5]> = path.axes.clone();
    let mut edits = Vec::new();
    for (k, point) in after.iter_mut().enumerate() {
        point[3] = result.p_deg[k];
        point[4] = result.c_deg[k];
        if tcpm || !changed(k) {
            continue;
        }
        // The part-frame tip as the patch wants it (moved to keep a ball's centre).
        let tip = result.xyz_mm[k];
        let (p, c) = (result.p_deg[k], result.c_deg[k]);
        let exact = chain.program_xyz(machine, datum_mm, p, c, tip);
        let mut written = exact;
        let mut ok = false;
        for decimals in xyz_decimals..=xyz_decimals.max(6) {
            written = exact.map(|v| machine_frame::round_to(v, decimals));
            let back = chain.part_tip(machine, datum_mm, p, c, written);
            let err = (0..3).map(|i| (back[i] - tip[i]).abs()).fold(0.0, f64::max);
            if err <= machine_frame::TIP_TOLERANCE_MM {
                ok = true;
                for (i, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                    if written[i] != path.axes[k][i] {
                        edits.push(Edit {
                            block: rp.run.blocks[k],
                            letter,
                            value: written[i],
                            decimals,
                        });
                    }
                }
                break;
            }
        }
        if !ok {
            return Err(format!(
                "the tool tip at line {} cannot be kept within {} mm through the kinematic chain",
                lp.line_of(r, k),
                machine_frame::TIP_TOLERANCE_MM
            ));
        }
        point[..3].copy_from_slice(&written);
    }
    if !tcpm {
        // Between the points (issue 19 §2): the tool tip under linear interpolation of the
        // written values may not leave the programmed line by more than the tolerance, nor
        // by more than the original block did.
        for k in 1..n {
            if !(changed(k - 1) || changed(k)) {
                continue;
            }
            let tip = |i: usize| {
                [
                    work_path.axes[i][0],
                    work_path.axes[i][1],
                    work_path.axes[i][2],
                ]
            };
            let err = |from: &[f64; 5], to: &[f64; 5], tips| {
                machine_frame::chord_error_mm(chain, machine, datum_mm, from, to, tips)
            };
            let new = err(
                &after[k - 1],
                &after[k],
                [result.xyz_mm[k - 1], result.xyz_mm[k]],
            );
            let old = err(&path.axes[k - 1], &path.axes[k], [tip(k - 1), tip(k)]);
            // The endpoints themselves may move by the tip tolerance (rounding).
            if new > chord_tolerance_mm.max(old) + machine_frame::TIP_TOLERANCE_MM {
                return Err(format!(
                    "between lines {} and {} the tool tip would leave the programmed line by \
                     {new:.3} mm with the axes interpolated linearly (without TCPM; the original \
                     block: {old:.3} mm, chord tolerance {chord_tolerance_mm} mm), so the run \
                     keeps its values",
                    lp.line_of(r, k - 1),
                    lp.line_of(r, k)
                ));
            }
        }
    }
    let aopts = polepatch_patcher::AnalysisOptions {
        cone_deg: opts.cone_deg,
        pole_reach_deg: opts.pole_reach_deg,
        tcy_s: opts.tcy_s,
        keep_samples: false,
    };
    let frame = |values: &[[f64; 5]]| {
        machine_frame::machine_frame_path(
            chain,
            machine,
            datum_mm,
            tcpm,
            values,
            &path.s_mm,
            path.feed_mm_min,
        )
    };
    let before = machine_frame::axis_min_ratios(&frame(&path.axes), machine, &aopts)
        .map_err(|e| format!("machine-frame analysis failed before the patch: {e}"))?;
    let after_r = machine_frame::axis_min_ratios(&frame(&after), machine, &aopts)
        .map_err(|e| format!("machine-frame analysis failed after the patch: {e}"))?;
    if let Some(axis) = machine_frame::worse_axis(&before, &after_r) {
        let l = axis_letter(axis, lp.primary_letter);
        return Err(format!(
            "the patch would slow {l} in the machine frame (its lowest ratio {:.3} → {:.3}; \
             the linear axes follow the table near the pole), so the run keeps its values",
            before[axis.index()],
            after_r[axis.index()]
        ));
    }
    Ok(edits)
}

/// Run `r`'s tool and the point its X Y Z state ([`crate::tool::resolve`]).
fn run_tool(lp: &LoadedProgram, r: usize, machine: &Machine) -> RunTool {
    let rp = &lp.runs[r];
    let machine_point = machine
        .controller
        .tool_point
        .as_deref()
        .and_then(|p| ToolPoint::parse(p).ok());
    let code = if !rp.run.tcpm.is_on() {
        "no TCPM: X Y Z through the kinematic chain are the tool tip's"
    } else if rp.run.tcpm_centre {
        "M128 or FUNCTION TCPM … REFPNT CENTER-CENTER: the tool length refers to the ball's centre"
    } else {
        "the TCPM code in force (FUNCTION TCPM, TRAORI, G43.4, G234, …) refers to the tool tip"
    };
    crate::tool::resolve(
        &lp.tool,
        &rp.found_tool,
        machine_point,
        rp.run.tcpm_centre,
        code,
    )
}

/// Fewest decimals for X Y Z of an inch program rewritten to keep a ball's centre
/// (5: 0.25 µm per axis).
const MIN_INCH_XYZ_DECIMALS: usize = 5;

/// Distance from `p` to the segment `a`–`b`, mm.
fn point_segment_mm(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab: [f64; 3] = std::array::from_fn(|i| b[i] - a[i]);
    let ap: [f64; 3] = std::array::from_fn(|i| p[i] - a[i]);
    let len2: f64 = ab.iter().map(|v| v * v).sum();
    let t = if len2 > 0.0 {
        (ab.iter().zip(&ap).map(|(x, y)| x * y).sum::<f64>() / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|i| (ap[i] - t * ab[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Points sampled inside each block for the centre's path between two points.
const CENTRE_CHORD_SAMPLES: usize = 8;

/// The tool figures of a patched zone's row (module [`crate::tool`]): the tool and its
/// point, the cutter's largest displacement at a written point, the centre's path between
/// the points (a ball at its tip), and `tool_limited` where the tool's cap stopped it.
#[allow(clippy::too_many_arguments)]
fn tool_fields(
    row: &mut ZoneRow,
    rt: &RunTool,
    z: &ZoneReport,
    before: &polepatch_patcher::Path,
    result: &polepatch_patcher::PatchResult,
    machine: &Machine,
    tool_capped: bool,
) {
    use polepatch_kinematics::forward;
    row.tool = rt.tool.map_or("unknown".to_string(), |t| t.describe());
    row.tool_source = rt.tool_source.clone();
    row.tool_point = rt.point.name();
    row.tool_point_source = rt.point_source.clone();
    if tool_capped && z.reason == polepatch_patcher::Reason::DeviationCap {
        row.reason = "tool_limited";
    }
    let Some(tool) = rt.tool else { return };
    let at = |k: usize, t: f64| -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3]) {
        // Tip and tool axis at parameter t of block k (k − 1 → k), before and after.
        let lerp = |a: f64, b: f64| a + (b - a) * t;
        let q0: [f64; 5] = std::array::from_fn(|i| lerp(before.axes[k - 1][i], before.axes[k][i]));
        let x1 = |j: usize| {
            [
                result.xyz_mm[j][0],
                result.xyz_mm[j][1],
                result.xyz_mm[j][2],
            ]
        };
        let (a, b) = (x1(k - 1), x1(k));
        let tip1: [f64; 3] = std::array::from_fn(|i| lerp(a[i], b[i]));
        let p1 = lerp(result.p_deg[k - 1], result.p_deg[k]);
        let c1 = lerp(result.c_deg[k - 1], result.c_deg[k]);
        (
            [q0[0], q0[1], q0[2]],
            forward(machine, q0[3], q0[4]),
            tip1,
            forward(machine, p1, c1),
        )
    };
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    match tool.kind {
        ToolKind::Ball => {
            let reach = if rt.point == ToolPoint::Tip {
                tool.diameter_mm / 2.0
            } else {
                0.0
            };
            let centre = |tip: [f64; 3], o: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|i| tip[i] + reach * o[i])
            };
            let mut at_points: f64 = 0.0;
            let mut between: f64 = 0.0;
            let m = CENTRE_CHORD_SAMPLES;
            for k in z.first.max(1)..=z.last {
                let (t0, o0, t1, o1) = at(k, 1.0);
                at_points = at_points.max(dist(centre(t0, o0), centre(t1, o1)));
                if rt.point != ToolPoint::Tip {
                    continue;
                }
                // Between the points: how far the centre leaves the line between the
                // block's original centres (what CAM's chord tolerance bounds), written
                // against original; only where the written block leaves it more.
                let (a0, ao, _, _) = at(k, 0.0);
                let (b0, bo, _, _) = at(k, 1.0);
                let (a, b) = (centre(a0, ao), centre(b0, bo));
                let (mut old_dev, mut new_dev): (f64, f64) = (0.0, 0.0);
                for s in 1..m {
                    let (t0, o0, t1, o1) = at(k, s as f64 / m as f64);
                    old_dev = old_dev.max(point_segment_mm(centre(t0, o0), a, b));
                    new_dev = new_dev.max(point_segment_mm(centre(t1, o1), a, b));
                }
                if new_dev > old_dev {
                    between = between.max(new_dev);
                }
            }
            row.max_cutter_shift_mm = Some(at_points);
            row.centre_chord_mm = (rt.point == ToolPoint::Tip).then_some(between);
        }
        ToolKind::Flat | ToolKind::Bull => {
            row.max_cutter_shift_mm = Some(
                tool.end_reach_mm() * crate::tool::centre_shift_per_mm_radius(z.max_deviation_deg),
            );
        }
    }
}

fn problem_reason(p: &RunProblem) -> UntouchedReason {
    match p {
        RunProblem::NoFeed => UntouchedReason::NoFeed,
        RunProblem::FeedTooLow { .. } => UntouchedReason::FeedTooLow,
        RunProblem::UnknownRotary { .. } => UntouchedReason::UnknownRotary,
        RunProblem::OtherRotary { .. } => UntouchedReason::OtherRotary,
    }
}

fn untouched(
    lp: &LoadedProgram,
    r: usize,
    reason: UntouchedReason,
    zones: usize,
    message: String,
    cone_deg: f64,
) -> UntouchedRun {
    let pi = lp.primary_index();
    UntouchedRun {
        run: lp.run_number(r),
        lines: lp.lines_of_run(r),
        reason,
        zones,
        near_pole: lp.runs[r]
            .run
            .pos
            .iter()
            .any(|p| p[pi].is_none_or(|v| v.abs() <= cone_deg)),
        message,
    }
}

/// Patch a loaded program and render the output bytes: `(output, report)`. The output
/// is the input bytes, unchanged, when nothing was changed.
pub fn patch_loaded(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &PatchOptions,
) -> (Vec<u8>, FileReport) {
    let (edits, mut report) = patch_program(lp, machine, opts);
    report.warn_unknown_tool();
    let bytes = if edits.is_empty() {
        lp.program.bytes.clone()
    } else {
        polepatch_nc::write_styled(&lp.program, &edits, &lp.file_style())
    };
    (bytes, report)
}
