//! The quality suite behind `polepatch bench` (SPEC §5, §6, issue 8 §5): every program ×
//! machine × strategy through the same code paths as `analyze` ([`analyze_program`]) and
//! `patch` ([`patch_loaded`]), each zone measured against a reference.
//!
//! # Strategies
//! [`BenchStrategy::Polepatch`] is what `polepatch patch` does by default (both rotary
//! axes); [`BenchStrategy::OnlyC`] is `--only-c` (G16's method); the peers
//! [`BenchStrategy::Freeze`], [`BenchStrategy::Linearize`], [`BenchStrategy::Smooth`] are
//! the pole strategies CAM posts and controllers document (`Strategy::Freeze` and the others of [`polepatch_patcher::Strategy`]),
//! applied through the same pipeline and scored by the same Equation-6 analysis.
//!
//! # The reference of a zone
//! - For the strategies that may change both rotary axes: [`zone_reference`] — the best
//!   orientation change **found** by several exact methods, each with more effort than the
//!   patcher spends (re-selection; the joint SCP from four starts over the zone's whole
//!   territory, no margin, unrounded), or a proof that no values reach feed. It is an
//!   upper bound on the optimum (the problem is not convex), not a lower bound: `ours /
//!   reference < 1` means polepatch beat every reference start.
//! - For `only-c`: the LP bound of [`deviation_bound_zone`] — the exact minimum for C-only
//!   changes at the CL points (a true lower bound for that method).
//!
//! A zone's territory is its run (from its second point; the last too when
//! `polepatch::end_pose` frees it), cut at the midpoints between it and the run's other
//! zones so that each zone gets its own reference.

pub mod plot;

use crate::files::{JobError, read};
use polepatch::LoadedProgram;
use polepatch::analyze_program;
use polepatch::load_nc;
use polepatch::report::AnalyzeReport;
use polepatch::tool::ToolKind;
use polepatch::{Error, FileReport, ZoneRow, ZoneTool, patch_nc};
use polepatch_kinematics::{Axis, Machine};
use polepatch_patcher::quality::deviation_bound_zone;
use polepatch_patcher::quality::{Reference, ReferenceMethod, zone_reference};
use polepatch_patcher::{
    AnalysisOptions, CLimits, PatchAxes, PatchFailure, PatchOptions, Strategy, Zone, analyze_path,
};
use serde::Serialize;
use std::path::Path as FsPath;
use std::time::Instant;

/// A strategy of the suite (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BenchStrategy {
    /// polepatch, both rotary axes (the default of `polepatch patch`).
    Polepatch,
    /// polepatch `--only-c` (G16's C-only method).
    OnlyC,
    /// C held inside the cone (ModuleWorks FREEZE, Fanuc tool posture control).
    Freeze,
    /// C linear in s across the cone (ModuleWorks LINEAR_INTERPOLATION, Fusion
    /// LINEARIZE_ROTARY).
    Linearize,
    /// A cubic C blend across the cone (ModuleWorks SMOOTH_INTERPOLATION).
    Smooth,
}

impl BenchStrategy {
    /// Every strategy, polepatch's first.
    pub const ALL: [BenchStrategy; 5] = [
        BenchStrategy::Polepatch,
        BenchStrategy::OnlyC,
        BenchStrategy::Freeze,
        BenchStrategy::Linearize,
        BenchStrategy::Smooth,
    ];
    /// The name on the command line and in tables.
    pub fn name(self) -> &'static str {
        match self {
            BenchStrategy::Polepatch => "polepatch",
            BenchStrategy::OnlyC => "only-c",
            BenchStrategy::Freeze => "freeze",
            BenchStrategy::Linearize => "linearize",
            BenchStrategy::Smooth => "smooth",
        }
    }
    /// The strategy of a name.
    pub fn from_name(name: &str) -> Option<BenchStrategy> {
        BenchStrategy::ALL.into_iter().find(|s| s.name() == name)
    }
    /// The patch options of this strategy from the suite's.
    pub fn options(self, base: &PatchOptions) -> PatchOptions {
        let (axes, strategy) = match self {
            BenchStrategy::Polepatch => (PatchAxes::Both, Strategy::Polepatch),
            BenchStrategy::OnlyC => (PatchAxes::OnlyC, Strategy::Polepatch),
            BenchStrategy::Freeze => (PatchAxes::Both, Strategy::Freeze),
            BenchStrategy::Linearize => (PatchAxes::Both, Strategy::Linearize),
            BenchStrategy::Smooth => (PatchAxes::Both, Strategy::Smooth),
        };
        PatchOptions {
            axes,
            strategy,
            ..base.clone()
        }
    }
    /// Whether "reaching feed" means both rotary axes (all but `only-c`).
    pub fn both_axes(self) -> bool {
        self != BenchStrategy::OnlyC
    }
}

/// Options of the suite. Plain struct; see each field for its default.
#[derive(Debug, Clone)]
pub struct BenchOptions {
    /// Options of the patch (the same as `polepatch patch`). Default: [`PatchOptions`]'s.
    pub patch: PatchOptions,
    /// Strategies to run. Default: `[Polepatch]`.
    pub strategies: Vec<BenchStrategy>,
    /// Feed, mm/min, for runs with no F in force. Default `None`.
    pub feed_fallback_mm_min: Option<f64>,
    /// Skip the references (faster). Default false.
    pub skip_bound: bool,
    /// Keep the data of the per-zone plots ([`BenchZone::plot`]). Default false.
    pub plots: bool,
    /// The tool and the point X Y Z state (`--tool`, `--tool-point`,
    /// `--surface-tolerance`, as `patch`). Default: from the program and the TCPM codes.
    pub tool: polepatch::tool::ToolOptions,
}

impl Default for BenchOptions {
    fn default() -> Self {
        BenchOptions {
            patch: PatchOptions::default(),
            strategies: vec![BenchStrategy::Polepatch],
            feed_fallback_mm_min: None,
            skip_bound: false,
            plots: false,
            tool: polepatch::tool::ToolOptions::default(),
        }
    }
}

/// Which reference a zone gets ([`ZoneBound::kind`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundKind {
    /// `best-found`: both axes, the best of several exact methods (an upper bound of the
    /// optimum).
    BestFound,
    /// `c-only-lp`: the LP bound for C-only changes (a lower bound).
    COnlyLp,
}

impl BoundKind {
    /// The reference of a strategy that changes both rotary axes (`both`) or C only.
    pub fn of(both: bool) -> BoundKind {
        if both {
            BoundKind::BestFound
        } else {
            BoundKind::COnlyLp
        }
    }
    /// `best-found` or `c-only-lp`: its serde form.
    pub fn name(self) -> &'static str {
        match self {
            BoundKind::BestFound => "best-found",
            BoundKind::COnlyLp => "c-only-lp",
        }
    }
}

impl std::fmt::Display for BoundKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How a zone's reference ended ([`ZoneBound::status`]); written `ok`, `unreachable`,
/// `failed`, `skipped` or `error: …` (its `Display`, in the JSON too).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BoundStatus {
    /// The reference was found.
    Ok,
    /// Proven: no values reach feed.
    Unreachable,
    /// Every method failed numerically.
    Failed,
    /// Not computed (`--skip-bound`, or no analysis zone under the row).
    Skipped,
    /// It could not be computed, and why.
    Error(String),
}

impl std::fmt::Display for BoundStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BoundStatus::Ok => f.write_str("ok"),
            BoundStatus::Unreachable => f.write_str("unreachable"),
            BoundStatus::Failed => f.write_str("failed"),
            BoundStatus::Skipped => f.write_str("skipped"),
            BoundStatus::Error(why) => write!(f, "error: {why}"),
        }
    }
}

impl Serialize for BoundStatus {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// The reference of one zone (module docs).
#[derive(Debug, Clone, Serialize)]
pub struct ZoneBound {
    /// `best-found` or `c-only-lp`.
    pub kind: BoundKind,
    /// `ok`, `unreachable` (proven: no values reach feed), `failed`, `skipped`, or
    /// `error: …`.
    pub status: BoundStatus,
    /// The reference deviation, degrees (`ok` only).
    pub bound_deg: Option<f64>,
    /// The method that found it (`best-found` only): `reselect`, `as-is`,
    /// `other-branch`, `freeze`, `linearize`.
    pub method: Option<ReferenceMethod>,
    /// File lines of the first and last movable point of the reference's territory.
    pub lines: [usize; 2],
    /// Wall time, ms.
    pub time_ms: f64,
}

/// One zone of the suite: the `patch` report row, its reference and the ratio.
#[derive(Debug, Clone, Serialize)]
pub struct BenchZone {
    /// Machine name.
    pub machine: String,
    /// Strategy.
    pub strategy: BenchStrategy,
    /// The row `polepatch patch --report` writes for this zone.
    #[serde(flatten)]
    pub row: ZoneRow,
    /// Whether the zone reaches feed on C (after, on the values as written).
    pub at_feed_c: bool,
    /// Whether it reaches feed on both rotary axes.
    pub at_feed_both: bool,
    /// The zone's reference.
    pub bound: ZoneBound,
    /// `max_deviation_deg / reference` for a zone at feed (both axes for the strategies
    /// that change both, C for `only-c`) with a positive reference (`None` otherwise).
    pub ratio: Option<f64>,
    /// The ball-centre shift of the zone ([`BallCentreShift`]).
    pub ball_centre_shift: BallCentreShift,
    /// Plot data (with [`BenchOptions::plots`]).
    #[serde(skip)]
    pub plot: Option<plot::ZonePlot>,
}

/// How far the centre of a ball-end mill moves at a written point of a zone, in µm (the
/// table's `ctr µm` column).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", content = "um", rename_all = "snake_case")]
pub enum BallCentreShift {
    /// A ball of known radius: the largest distance between the original and the written
    /// centre at a point, µm (the row's `max_cutter_shift_mm`; within the written rounding
    /// of 0 where the patch keeps the centre: a ball at its tip, or at its centre).
    Ball(f64),
    /// The tool is unknown: the shift per mm of the ball's radius were X Y Z its tip,
    /// µm/mm (1000 · 2·sin(δ/2), δ the zone's largest orientation change).
    PerMmRadius(f64),
    /// A flat or bull-nose cutter (its figure is the surface bound, `max_cutter_shift_mm`),
    /// or a zone not changed.
    None,
}

impl BallCentreShift {
    /// The shift of a report row.
    pub fn of(row: &ZoneRow) -> BallCentreShift {
        match row.tool {
            ZoneTool::Known(t) if t.kind == ToolKind::Ball => row
                .max_cutter_shift_mm
                .map_or(BallCentreShift::None, |v| BallCentreShift::Ball(v * 1e3)),
            ZoneTool::Unknown => BallCentreShift::PerMmRadius(row.centre_shift_per_mm_radius * 1e3),
            ZoneTool::Known(_) | ZoneTool::NotPatched => BallCentreShift::None,
        }
    }

    /// For the table: `0.4` (µm), `17.5/mm` (µm per mm of radius), `—`.
    pub fn text(self) -> String {
        match self {
            BallCentreShift::Ball(v) => format!("{v:.1}"),
            BallCentreShift::PerMmRadius(v) => format!("{v:.1}/mm"),
            BallCentreShift::None => "—".into(),
        }
    }
}

/// One program on one machine with one strategy.
#[derive(Debug, Clone, Serialize)]
pub struct BenchCase {
    /// Input file.
    pub file: String,
    /// Machine name.
    pub machine: String,
    /// Strategy.
    pub strategy: BenchStrategy,
    /// Zones `polepatch analyze` finds.
    pub zones_analyzed: usize,
    /// Words changed or inserted.
    pub words_changed: usize,
    /// Runs left as they are, and why.
    pub untouched_runs: Vec<polepatch::UntouchedRun>,
    /// Notes (as `patch` prints them).
    pub warnings: Vec<String>,
    /// Wall time of the patch of the whole program, ms.
    pub patch_time_ms: f64,
    /// Estimated machining time of the runs that hold a zone, before and after, s (∫ds/ṡ
    /// over the whole runs, the written program analysed), and their ideal L/F: the same
    /// stretch for every strategy. After is not a number (JSON `null`) where the output
    /// reads as other runs than the input (a warning says so).
    pub time_s: [f64; 3],
    /// Simulated time of the same runs (`polepatch simulate`: a jerk-limited controller),
    /// before and after, s.
    pub sim_time_s: [f64; 2],
    /// One entry per zone.
    pub zones: Vec<BenchZone>,
}

/// A program that could not be read, on a machine.
#[derive(Debug, Clone, Serialize)]
pub struct BenchError {
    /// Input file.
    pub file: String,
    /// Machine name.
    pub machine: String,
    /// The error message.
    pub error: String,
}

/// The whole suite.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Cases in input order: file, then machine, then strategy.
    pub cases: Vec<BenchCase>,
    /// Inputs that failed.
    pub errors: Vec<BenchError>,
}

/// Headline figures of one strategy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    /// Zones.
    pub zones: usize,
    /// Zones at feed on C.
    pub at_feed_c: usize,
    /// Zones at feed on both rotary axes.
    pub at_feed_both: usize,
    /// Zones whose reference is `unreachable`.
    pub unreachable: usize,
    /// Zones with a ratio.
    pub ratios: usize,
    /// Median of ours/reference.
    pub ratio_median: Option<f64>,
    /// Largest ours/reference.
    pub ratio_worst: Option<f64>,
    /// Zones with ours/reference ≤ [`RATIO_TARGET`] (SPEC §6).
    pub ratio_within_target: usize,
    /// Largest orientation change, degrees.
    pub max_deviation_deg: f64,
    /// Estimated time of the runs holding zones before and after, and L/F, s.
    pub time_s: [f64; 3],
    /// Simulated time of the same runs before and after, s.
    pub sim_time_s: [f64; 2],
    /// Cases left out of `time_s` and `sim_time_s`: their output reads as other runs than
    /// the input ([`BenchCase::time_s`]).
    pub not_compared: usize,
}

/// SPEC §6: ours within this factor of the reference.
pub const RATIO_TARGET: f64 = 1.25;

/// A zone is at feed when its ratio after is at least 1 − this.
pub const AT_FEED_TOL: f64 = 1e-9;

impl BenchReport {
    /// Every zone of every case.
    pub fn zones(&self) -> impl Iterator<Item = &BenchZone> {
        self.cases.iter().flat_map(|c| c.zones.iter())
    }

    /// The strategies present, in order.
    pub fn strategies(&self) -> Vec<BenchStrategy> {
        let mut out: Vec<BenchStrategy> = Vec::new();
        for c in &self.cases {
            if !out.contains(&c.strategy) {
                out.push(c.strategy);
            }
        }
        out
    }

    /// The headline figures of one strategy.
    pub fn summary(&self, strategy: BenchStrategy) -> Summary {
        let zones: Vec<&BenchZone> = self.zones().filter(|z| z.strategy == strategy).collect();
        let mut ratios: Vec<f64> = zones.iter().filter_map(|z| z.ratio).collect();
        ratios.sort_by(f64::total_cmp);
        let median = (!ratios.is_empty()).then(|| {
            let m = ratios.len() / 2;
            if ratios.len() % 2 == 1 {
                ratios[m]
            } else {
                0.5 * (ratios[m - 1] + ratios[m])
            }
        });
        let mut time_s = [0.0; 3];
        let mut sim_time_s = [0.0; 2];
        // Cases whose output reads as other runs have no times after: left out of the
        // totals, before and after alike, and counted.
        let compared = |c: &&BenchCase| c.time_s[1].is_finite() && c.sim_time_s[1].is_finite();
        let cases: Vec<&BenchCase> = self
            .cases
            .iter()
            .filter(|c| c.strategy == strategy)
            .collect();
        let not_compared = cases.iter().filter(|c| !compared(c)).count();
        for c in cases.into_iter().filter(compared) {
            for (t, v) in time_s.iter_mut().zip(c.time_s) {
                *t += v;
            }
            for (t, v) in sim_time_s.iter_mut().zip(c.sim_time_s) {
                *t += v;
            }
        }
        Summary {
            zones: zones.len(),
            at_feed_c: zones.iter().filter(|z| z.at_feed_c).count(),
            at_feed_both: zones.iter().filter(|z| z.at_feed_both).count(),
            unreachable: zones
                .iter()
                .filter(|z| z.bound.status == BoundStatus::Unreachable)
                .count(),
            ratios: ratios.len(),
            ratio_median: median,
            ratio_worst: ratios.last().copied(),
            ratio_within_target: ratios.iter().filter(|&&r| r <= RATIO_TARGET).count(),
            max_deviation_deg: zones
                .iter()
                .map(|z| z.row.max_deviation_deg)
                .fold(0.0, f64::max),
            time_s,
            sim_time_s,
            not_compared,
        }
    }
}

/// Run the suite on `files` × `machines` × `opts.strategies`, program × machine pairs in
/// parallel (rayon's current pool).
pub fn run(files: &[std::path::PathBuf], machines: &[Machine], opts: &BenchOptions) -> BenchReport {
    use rayon::prelude::*;
    let pairs: Vec<(&std::path::PathBuf, &Machine)> = files
        .iter()
        .flat_map(|f| machines.iter().map(move |m| (f, m)))
        .collect();
    // A program is measured on the machines it was posted for: on a machine without its
    // rotary letters it is refused (`Error::ForeignAxis`), and the pair is left out.
    let results: Vec<Result<Vec<BenchCase>, BenchError>> = pairs
        .par_iter()
        .map(|(f, m)| match bench_file(f, m, opts) {
            Err(JobError::Input(Error::ForeignAxis { .. })) => Ok(Vec::new()),
            r => r.map_err(|e| BenchError {
                file: f.display().to_string(),
                machine: m.name.clone(),
                error: e.to_string(),
            }),
        })
        .collect();
    let mut report = BenchReport {
        cases: Vec::new(),
        errors: Vec::new(),
    };
    for r in results {
        match r {
            Ok(c) => report.cases.extend(c),
            Err(e) => report.errors.push(e),
        }
    }
    report
}

/// Read `file` and run [`bench_program`] on it.
pub fn bench_file(
    file: &FsPath,
    machine: &Machine,
    opts: &BenchOptions,
) -> Result<Vec<BenchCase>, JobError> {
    let name = file.display().to_string();
    let mut lp = load_nc(&read(file)?, &name, machine, opts.feed_fallback_mm_min)?;
    lp.tool = opts.tool.clone();
    Ok(bench_program(&lp, machine, opts)?)
}

/// The analysis zones of every run (original values), for the references.
fn analysis_zones(lp: &LoadedProgram, machine: &Machine, opts: &PatchOptions) -> Vec<Vec<Zone>> {
    let aopts = AnalysisOptions {
        cone_deg: opts.cone_deg,
        pole_reach_deg: opts.pole_reach_deg,
        tcy_s: opts.tcy_s,
        keep_samples: false,
    };
    lp.runs
        .iter()
        .map(|rp| match &rp.path {
            Ok(p) => analyze_path(p, machine, &aopts)
                .map(|a| {
                    polepatch_patcher::quality::merge_zones(&a.zones, opts.solver.merge_gap_points)
                })
                .unwrap_or_default(),
            Err(_) => Vec::new(),
        })
        .collect()
}

/// Analyse, patch with every strategy, and measure one loaded program (its tool options
/// are `lp.tool`: [`bench_file`] sets them to `opts.tool`).
pub fn bench_program(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &BenchOptions,
) -> Result<Vec<BenchCase>, Error> {
    let aopts = AnalysisOptions {
        cone_deg: opts.patch.cone_deg,
        pole_reach_deg: opts.patch.pole_reach_deg,
        tcy_s: opts.patch.tcy_s,
        keep_samples: false,
    };
    let analysis: AnalyzeReport = analyze_program(lp, machine, &aopts);
    let zones_analyzed = analysis
        .runs
        .iter()
        .filter_map(|r| r.figures.as_ref())
        .map(|f| f.zones.len())
        .sum();
    let zones = analysis_zones(lp, machine, &opts.patch);
    // The simulated time of the runs with a zone (as `time_s`), of a program's bytes.
    // As the bench reads its programs (`load_nc`: a program without units in mm).
    let sim_opts = polepatch::SimulateOptions {
        read: polepatch::ReadOptions {
            name: lp.name.clone(),
            feed_fallback_mm_min: opts.feed_fallback_mm_min,
            work_offset_mm: None,
            inch: false,
        },
        sim: polepatch::sim::SimOptions {
            tcy_s: opts.patch.tcy_s,
            ..Default::default()
        },
    };
    let simulated = |bytes: &[u8]| -> f64 {
        polepatch::simulate_nc(bytes, machine, &sim_opts)
            .map(|rep| {
                rep.runs
                    .iter()
                    .enumerate()
                    .filter(|(r, _)| zones.get(*r).is_some_and(|z| !z.is_empty()))
                    .map(|(_, run)| run.time_s)
                    .fold(0.0, |a, b| a + b)
            })
            .unwrap_or(f64::NAN)
    };
    let sim_before = simulated(&lp.program.bytes);
    // References, computed once per zone and strategy kind (both axes / C only).
    let mut refs: std::collections::HashMap<(usize, usize, bool), ZoneBound> =
        std::collections::HashMap::new();
    let mut cases = Vec::new();
    for &strategy in &opts.strategies {
        let popts = strategy.options(&opts.patch);
        let t0 = Instant::now();
        let (bytes, report): (_, FileReport) = patch_nc(
            &lp.program.bytes,
            machine,
            &polepatch::PatchOptions {
                read: polepatch::ReadOptions {
                    feed_fallback_mm_min: opts.feed_fallback_mm_min,
                    name: lp.name.clone(),
                    ..polepatch::ReadOptions::default()
                },
                patch: popts,
                chord_tolerance_mm: lp.chord_tolerance_mm,
                tool: lp.tool.clone(),
            },
        )?;
        let patch_time_ms = t0.elapsed().as_secs_f64() * 1e3;
        let sim_after = if report.words_changed > 0 {
            simulated(&bytes)
        } else {
            sim_before
        };
        let after = if report.words_changed > 0 {
            Some(load_nc(
                &bytes,
                &lp.name,
                machine,
                opts.feed_fallback_mm_min,
            )?)
        } else {
            None
        };
        // The time of every run with a zone, before and after (XYZ never change, so runs
        // match one to one).
        let after_analysis = after.as_ref().map(|a| analyze_program(a, machine, &aopts));
        // A strategy whose output reads as other runs (a peer's C swing of more than half a
        // turn in a feed move is a wrap on an endless axis, issue 42: it ends a run) has no
        // run-for-run times: said, and its times are not a number ("—" in the table).
        let mut warnings = report.warnings.clone();
        let runs_differ = after_analysis.as_ref().is_some_and(|a| {
            a.runs.len() != analysis.runs.len()
                || a.runs
                    .iter()
                    .zip(&analysis.runs)
                    .any(|(x, y)| x.lines != y.lines)
        });
        if runs_differ {
            warnings.push(format!(
                "{}: the output reads as other runs than the input (a rotary move it wrote \
                 ends a run, e.g. a wrap on an endless axis): its times are not compared",
                strategy.name()
            ));
        }
        let sim_after = if runs_differ { f64::NAN } else { sim_after };
        let mut time_s = [0.0; 3];
        for (r, rr) in analysis.runs.iter().enumerate() {
            let (Some(fb), false) = (&rr.figures, zones[r].is_empty()) else {
                continue;
            };
            let fa = after_analysis
                .as_ref()
                .and_then(|a| a.runs.get(r))
                .and_then(|x| x.figures.as_ref())
                .unwrap_or(fb);
            time_s[0] += fb.time_s;
            time_s[1] += if runs_differ { f64::NAN } else { fa.time_s };
            time_s[2] += fb.ideal_time_s;
        }
        let after = if opts.plots { after } else { None };
        let mut out = Vec::with_capacity(report.zones.len());
        for row in &report.zones {
            let r = row.run - 1;
            let (first, last) = point_range(lp, r, row.lines);
            // The analysis zone this row is about (the one of least |P| it overlaps).
            let zone = zones[r]
                .iter()
                .filter(|z| z.first <= last && z.last >= first)
                .min_by(|a, b| a.min_abs_primary_deg.total_cmp(&b.min_abs_primary_deg))
                .cloned();
            let at_feed_c = row.after.c_ratio >= 1.0 - AT_FEED_TOL;
            let at_feed_both = at_feed_c && row.after.primary_ratio >= 1.0 - AT_FEED_TOL;
            let both = strategy.both_axes();
            let bound = match (&zone, opts.skip_bound) {
                (Some(z), false) => refs
                    .entry((r, z.first, both))
                    .or_insert_with(|| reference(lp, r, z, &zones[r], machine, &opts.patch, both))
                    .clone(),
                _ => ZoneBound {
                    kind: BoundKind::of(both),
                    status: BoundStatus::Skipped,
                    bound_deg: None,
                    method: None,
                    lines: row.lines,
                    time_ms: 0.0,
                },
            };
            let at_feed = if both { at_feed_both } else { at_feed_c };
            let ratio = match bound.bound_deg {
                Some(b) if b > 0.0 && at_feed => Some(row.max_deviation_deg / b),
                _ => None,
            };
            let plot = if opts.plots {
                plot_data(lp, after.as_ref(), r, first, last, machine, &opts.patch)
            } else {
                None
            };
            out.push(BenchZone {
                machine: machine.name.clone(),
                strategy,
                row: row.clone(),
                at_feed_c,
                at_feed_both,
                bound,
                ratio,
                ball_centre_shift: BallCentreShift::of(row),
                plot,
            });
        }
        cases.push(BenchCase {
            file: lp.name.clone(),
            machine: machine.name.clone(),
            strategy,
            zones_analyzed,
            words_changed: report.words_changed,
            untouched_runs: report.untouched_runs,
            warnings,
            patch_time_ms,
            time_s,
            sim_time_s: [sim_before, sim_after],
            zones: out,
        });
    }
    Ok(cases)
}

/// Point indices in run `r` of the file lines `[first, last]` of a report row.
fn point_range(lp: &LoadedProgram, r: usize, lines: [usize; 2]) -> (usize, usize) {
    let n = lp.runs[r].run.len();
    let first = (0..n).find(|&k| lp.line_of(r, k) == lines[0]).unwrap_or(0);
    let last = (0..n)
        .rev()
        .find(|&k| lp.line_of(r, k) == lines[1])
        .unwrap_or(n - 1);
    (first, last.max(first))
}

/// The reference of `zone` of run `r` (module docs): its territory, then the joint
/// reference (`both`) or the C-only LP bound.
fn reference(
    lp: &LoadedProgram,
    r: usize,
    zone: &Zone,
    run_zones: &[Zone],
    machine: &Machine,
    opts: &PatchOptions,
    both: bool,
) -> ZoneBound {
    let n = lp.runs[r].run.len();
    let end = if lp.end_pose(r).free { n - 1 } else { n - 2 };
    let (mut lo, mut hi) = (1, end);
    for z in run_zones {
        if z.last < zone.first {
            lo = lo.max((z.last + zone.first) / 2 + 1);
        } else if z.first > zone.last {
            hi = hi.min((zone.last + z.first) / 2);
        }
    }
    let lines = [lp.line_of(r, lo), lp.line_of(r, hi)];
    let mut out = ZoneBound {
        kind: BoundKind::of(both),
        status: BoundStatus::Skipped,
        bound_deg: None,
        method: None,
        lines,
        time_ms: 0.0,
    };
    let Ok(path) = &lp.runs[r].path else {
        out.status = BoundStatus::Error("run not analysed".into());
        return out;
    };
    let p: Vec<f64> = path.axes.iter().map(|q| q[Axis::Primary.index()]).collect();
    let c: Vec<f64> = path.axes.iter().map(|q| q[Axis::C.index()]).collect();
    let t0 = Instant::now();
    if both {
        let res = zone_reference(
            &path.s_mm,
            &p,
            &c,
            zone,
            lo,
            hi,
            machine,
            path.feed_mm_min,
            opts.max_decimals,
        );
        out.status = match res {
            Ok(Reference::Best {
                deviation_deg,
                method,
            }) => {
                out.bound_deg = Some(deviation_deg);
                out.method = Some(method);
                BoundStatus::Ok
            }
            Ok(Reference::Unreachable) => BoundStatus::Unreachable,
            Ok(Reference::Failed) => BoundStatus::Failed,
            Err(e) => BoundStatus::Error(format!("{e:?}")),
        };
    } else {
        let lim = CLimits::new(machine, path.feed_mm_min, 0.0);
        let res = deviation_bound_zone(
            &path.s_mm,
            &p,
            &c,
            lo,
            hi,
            (zone.first, zone.last),
            &lim,
            polepatch_patcher::quality::BOUND_SAMPLES_PER_SPAN,
        );
        out.status = match res {
            Ok((b, _)) => {
                out.bound_deg = Some(b);
                BoundStatus::Ok
            }
            Err(PatchFailure::Solver(_)) => BoundStatus::Unreachable,
            Err(e) => BoundStatus::Error(format!("{e:?}")),
        };
    }
    out.time_ms = t0.elapsed().as_secs_f64() * 1e3;
    out
}

/// The plot data of the zone at points `first..=last` of run `r`: the zone ± half its
/// length (at least 3 points) either side.
fn plot_data(
    before: &LoadedProgram,
    after: Option<&LoadedProgram>,
    r: usize,
    first: usize,
    last: usize,
    machine: &Machine,
    opts: &PatchOptions,
) -> Option<plot::ZonePlot> {
    let pb = before.runs[r].path.as_ref().ok()?;
    let pa = match after {
        Some(a) => a.runs.get(r)?.path.as_ref().ok()?,
        None => pb,
    };
    if pa.s_mm.len() != pb.s_mm.len() {
        return None;
    }
    let s = &pb.s_mm;
    let n = s.len();
    let half = ((last - first) / 2).max(3);
    let lo = first.saturating_sub(half);
    let hi = (last + half).min(n - 1);
    let aopts = AnalysisOptions {
        cone_deg: opts.cone_deg,
        pole_reach_deg: opts.pole_reach_deg,
        tcy_s: opts.tcy_s,
        keep_samples: true,
    };
    let ab = analyze_path(pb, machine, &aopts).ok()?;
    let aa = analyze_path(pa, machine, &aopts).ok()?;
    let sb = polepatch_patcher::quality::axis_splines(pb).ok()?;
    let sa = polepatch_patcher::quality::axis_splines(pa).ok()?;
    let (s0, s1) = (s[lo], s[hi]);
    let window = |v: &[polepatch_patcher::Sample]| -> Vec<plot::RatioSample> {
        v.iter()
            .filter(|x| x.s_mm >= s0 && x.s_mm <= s1)
            .map(|x| plot::RatioSample {
                s_mm: x.s_mm,
                ratio: x.bound.ratio,
                c_ratio: x.axis_ratio[Axis::C.index()],
                axis: x.bound.axis,
            })
            .collect()
    };
    let curve = |sp: &polepatch_patcher::spline::AnalysisSpline| -> Vec<(f64, f64)> {
        let m = 400;
        (0..=m)
            .map(|k| {
                let t = s0 + (s1 - s0) * k as f64 / m as f64;
                (t, sp.eval(t))
            })
            .collect()
    };
    let (ci, pi) = (Axis::C.index(), Axis::Primary.index());
    let points = |p: &polepatch_patcher::Path, i: usize| -> Vec<(f64, f64)> {
        (lo..=hi).map(|k| (s[k], p.axes[k][i])).collect()
    };
    Some(plot::ZonePlot {
        title: format!(
            "{} on {}, run {}, lines {}–{}",
            FsPath::new(&before.name)
                .file_name()
                .map_or(before.name.clone(), |f| f.to_string_lossy().into_owned()),
            machine.name,
            r + 1,
            before.line_of(r, first),
            before.line_of(r, last)
        ),
        primary_letter: before.primary_letter as char,
        zone_s_mm: (s[first], s[last]),
        c_points_before: points(pb, ci),
        c_points_after: points(pa, ci),
        c_curve_before: curve(&sb[ci]),
        c_curve_after: curve(&sa[ci]),
        p_points_before: points(pb, pi),
        p_points_after: points(pa, pi),
        p_curve_before: curve(&sb[pi]),
        p_curve_after: curve(&sa[pi]),
        ratio_before: window(&ab.samples),
        ratio_after: window(&aa.samples),
    })
}
