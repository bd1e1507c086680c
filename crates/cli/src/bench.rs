//! The quality suite behind `polepatch bench` (SPEC §5, §6): every program × machine through
//! the same code paths as `analyze` ([`analyze_program`]) and `patch` ([`patch_program`]),
//! with a lower bound on the orientation deviation for every zone.
//!
//! # The bound
//!
//! For a zone in run `r` with points `0..n`, the bound is the smallest possible largest
//! orientation deviation (degrees, exact formula `2·asin(|sin P|·|sin(ΔC/2)|)`) over C-only
//! changes at the existing CL points such that the analysis spline of C meets
//! |C_s| ≤ V/F, |C_ss| ≤ A/F², |C_sss| ≤ J/F³ (no margin) on every sample F·Tcy:
//! [`deviation_bound_zone`], an LP bisection. The movable points are the zone's range
//! widened to the whole run, `1..=n−1` (point 0 belongs to the block before the run and is
//! never moved). When a run holds several zones, each zone's range reaches only to the
//! midpoints between it and its neighbours (the neighbours' points stay fixed), so that
//! each zone gets its own bound.
//!
//! The patcher's deviation is compared with the bound only for zones it reached: a zone
//! left below feed did not solve the same problem. `ours / bound ≥ 1` up to the
//! bisection tolerance whenever the patch is feasible for the bound's constraints; SPEC §6
//! asks for `≤ 1.25`.

pub mod plot;

use crate::files::{JobError, read};
use polepatch::program::{LoadedProgram, load_nc};
use polepatch::report::{AnalyzeReport, analyze_program};
use polepatch::{Error, FileReport, ZoneRow, patch_loaded};
use polepatch_kinematics::{Axis, Machine};
use polepatch_patcher::direct::deviation_bound_zone;
use polepatch_patcher::{AnalysisOptions, CLimits, PatchFailure, PatchOptions, analyze_path};
use serde::Serialize;
use std::path::Path as FsPath;
use std::time::Instant;

/// Options of the suite. Plain struct; see each field for its default.
#[derive(Debug, Clone, Default)]
pub struct BenchOptions {
    /// Options of the patch (the same as `polepatch patch`). Default: [`PatchOptions`]'s.
    pub patch: PatchOptions,
    /// Feed, mm/min, for runs with no F in force. Default `None`.
    pub feed_fallback_mm_min: Option<f64>,
    /// Skip the bound LPs (faster). Default false.
    pub skip_bound: bool,
    /// Keep the data of the per-zone plots ([`BenchZone::plot`]). Default false.
    pub plots: bool,
}

/// The deviation bound of one zone.
#[derive(Debug, Clone, Serialize)]
pub struct ZoneBound {
    /// `ok`, `unreachable` (no C-only change of the range reaches feed), `skipped`, or
    /// `error: …`.
    pub status: String,
    /// The bound, degrees (`ok` only).
    pub bound_deg: Option<f64>,
    /// File lines of the first and last movable point of the bound's range.
    pub lines: [usize; 2],
    /// LP solves of the bisection.
    pub lp_solves: u32,
    /// Wall time of the bisection, ms.
    pub time_ms: f64,
}

/// One zone of the suite: the `patch` report row, its bound and the ratio.
#[derive(Debug, Clone, Serialize)]
pub struct BenchZone {
    /// Machine name.
    pub machine: String,
    /// The row `polepatch patch --report` writes for this zone.
    #[serde(flatten)]
    pub row: ZoneRow,
    /// The best possible deviation for C-only changes.
    pub bound: ZoneBound,
    /// `max_deviation_deg / bound_deg` for a reached zone with a positive bound (`None`
    /// otherwise).
    pub ratio: Option<f64>,
    /// Plot data (with [`BenchOptions::plots`]).
    #[serde(skip)]
    pub plot: Option<plot::ZonePlot>,
}

/// One program on one machine.
#[derive(Debug, Clone, Serialize)]
pub struct BenchCase {
    /// Input file.
    pub file: String,
    /// Machine name.
    pub machine: String,
    /// Zones `polepatch analyze` finds.
    pub zones_analyzed: usize,
    /// C words changed or inserted by the patch.
    pub words_changed: usize,
    /// Runs left as they are, and why.
    pub untouched_runs: Vec<polepatch::UntouchedRun>,
    /// Notes (as `patch` prints them).
    pub warnings: Vec<String>,
    /// Wall time of the patch of the whole program, ms.
    pub patch_time_ms: f64,
    /// One entry per zone patched.
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
    /// Cases in input order, machine by machine within a file.
    pub cases: Vec<BenchCase>,
    /// Inputs that failed.
    pub errors: Vec<BenchError>,
}

/// Headline figures of a suite.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    /// Zones patched.
    pub zones: usize,
    /// Zones whose C reaches feed after the patch.
    pub reached: usize,
    /// Zones whose bound is `unreachable`.
    pub unreachable: usize,
    /// Zones with a ratio.
    pub ratios: usize,
    /// Median of ours/bound.
    pub ratio_median: Option<f64>,
    /// Largest ours/bound.
    pub ratio_worst: Option<f64>,
    /// Zones with ours/bound ≤ 1.25 (SPEC §6).
    pub ratio_within_target: usize,
}

/// SPEC §6: ours within this factor of the bound.
pub const RATIO_TARGET: f64 = 1.25;

impl BenchReport {
    /// Every zone of every case.
    pub fn zones(&self) -> impl Iterator<Item = &BenchZone> {
        self.cases.iter().flat_map(|c| c.zones.iter())
    }

    /// The headline figures.
    pub fn summary(&self) -> Summary {
        let mut ratios: Vec<f64> = self.zones().filter_map(|z| z.ratio).collect();
        ratios.sort_by(f64::total_cmp);
        let median = (!ratios.is_empty()).then(|| {
            let m = ratios.len() / 2;
            if ratios.len() % 2 == 1 {
                ratios[m]
            } else {
                0.5 * (ratios[m - 1] + ratios[m])
            }
        });
        Summary {
            zones: self.zones().count(),
            reached: self.zones().filter(|z| z.row.outcome == "reached").count(),
            unreachable: self
                .zones()
                .filter(|z| z.bound.status == "unreachable")
                .count(),
            ratios: ratios.len(),
            ratio_median: median,
            ratio_worst: ratios.last().copied(),
            ratio_within_target: ratios.iter().filter(|&&r| r <= RATIO_TARGET).count(),
        }
    }
}

/// Run the suite on `files` × `machines`, cases in parallel (rayon's current pool).
pub fn run(files: &[std::path::PathBuf], machines: &[Machine], opts: &BenchOptions) -> BenchReport {
    use rayon::prelude::*;
    let pairs: Vec<(&std::path::PathBuf, &Machine)> = files
        .iter()
        .flat_map(|f| machines.iter().map(move |m| (f, m)))
        .collect();
    let results: Vec<Result<BenchCase, BenchError>> = pairs
        .par_iter()
        .map(|(f, m)| {
            bench_file(f, m, opts).map_err(|e| BenchError {
                file: f.display().to_string(),
                machine: m.name.clone(),
                error: e.to_string(),
            })
        })
        .collect();
    let mut report = BenchReport {
        cases: Vec::new(),
        errors: Vec::new(),
    };
    for r in results {
        match r {
            Ok(c) => report.cases.push(c),
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
) -> Result<BenchCase, JobError> {
    let name = file.display().to_string();
    let lp = load_nc(read(file)?, &name, machine, opts.feed_fallback_mm_min)?;
    Ok(bench_program(&lp, machine, opts)?)
}

/// Analyse, patch and bound one loaded program.
pub fn bench_program(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &BenchOptions,
) -> Result<BenchCase, Error> {
    let aopts = AnalysisOptions {
        cone_deg: opts.patch.cone_deg,
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
    let t0 = Instant::now();
    let (bytes, report): (_, FileReport) = patch_loaded(lp, machine, &opts.patch);
    let patch_time_ms = t0.elapsed().as_secs_f64() * 1e3;

    // The program as written, read back: the "after" of the plots.
    let after = if opts.plots && report.words_changed > 0 {
        Some(load_nc(
            bytes,
            &lp.name,
            machine,
            opts.feed_fallback_mm_min,
        )?)
    } else {
        None
    };

    let mut zones = Vec::with_capacity(report.zones.len());
    for row in &report.zones {
        let r = row.run - 1;
        let (first, last) = point_range(lp, r, row.lines);
        // Neighbouring zones of the same run bound this zone's territory.
        let same_run: Vec<(usize, usize)> = report
            .zones
            .iter()
            .filter(|z| z.run == row.run)
            .map(|z| point_range(lp, r, z.lines))
            .collect();
        let n = lp.runs[r].run.len();
        let mut lo = 1;
        let mut hi = n - 1;
        for &(f, l) in &same_run {
            if l < first {
                lo = lo.max((l + first) / 2 + 1);
            } else if f > last {
                hi = hi.min((last + f) / 2);
            }
        }
        let bound = if opts.skip_bound {
            ZoneBound {
                status: "skipped".into(),
                bound_deg: None,
                lines: [lp.line_of(r, lo), lp.line_of(r, hi)],
                lp_solves: 0,
                time_ms: 0.0,
            }
        } else {
            zone_bound(lp, r, lo, hi, (first, last), machine, opts)
        };
        let ratio = match bound.bound_deg {
            Some(b) if b > 0.0 && row.outcome == "reached" => Some(row.max_deviation_deg / b),
            _ => None,
        };
        let plot = if opts.plots {
            plot_data(lp, after.as_ref(), r, first, last, machine, opts)
        } else {
            None
        };
        zones.push(BenchZone {
            machine: machine.name.clone(),
            row: row.clone(),
            bound,
            ratio,
            plot,
        });
    }
    Ok(BenchCase {
        file: lp.name.clone(),
        machine: machine.name.clone(),
        zones_analyzed,
        words_changed: report.words_changed,
        untouched_runs: report.untouched_runs,
        warnings: report.warnings,
        patch_time_ms,
        zones,
    })
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

/// The bound LP over points `lo..=hi` of run `r` (module docs).
fn zone_bound(
    lp: &LoadedProgram,
    r: usize,
    lo: usize,
    hi: usize,
    zone: (usize, usize),
    machine: &Machine,
    opts: &BenchOptions,
) -> ZoneBound {
    let lines = [lp.line_of(r, lo), lp.line_of(r, hi)];
    let Ok(path) = &lp.runs[r].path else {
        return ZoneBound {
            status: "error: run not analysed".into(),
            bound_deg: None,
            lines,
            lp_solves: 0,
            time_ms: 0.0,
        };
    };
    let p: Vec<f64> = path.axes.iter().map(|q| q[Axis::Primary.index()]).collect();
    let c: Vec<f64> = path.axes.iter().map(|q| q[Axis::C.index()]).collect();
    let lim = CLimits::new(machine, path.feed_mm_min, 0.0);
    let step_mm = path.feed_mm_min / 60.0 * opts.patch.tcy_s.unwrap_or(machine.tcy_s);
    let t0 = Instant::now();
    let result = deviation_bound_zone(&path.s_mm, &p, &c, lo, hi, zone, &lim, step_mm);
    let time_ms = t0.elapsed().as_secs_f64() * 1e3;
    match result {
        Ok((b, st)) => ZoneBound {
            status: "ok".into(),
            bound_deg: Some(b),
            lines,
            lp_solves: st.solves,
            time_ms,
        },
        Err(PatchFailure::Solver(st)) => ZoneBound {
            status: "unreachable".into(),
            bound_deg: None,
            lines,
            lp_solves: st.solves,
            time_ms,
        },
        Err(e) => ZoneBound {
            status: format!("error: {e:?}"),
            bound_deg: None,
            lines,
            lp_solves: 0,
            time_ms,
        },
    }
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
    opts: &BenchOptions,
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
        cone_deg: opts.patch.cone_deg,
        tcy_s: opts.patch.tcy_s,
        keep_samples: true,
    };
    let ab = analyze_path(pb, machine, &aopts).ok()?;
    let aa = analyze_path(pa, machine, &aopts).ok()?;
    let sb = polepatch_patcher::analysis::axis_splines(pb).ok()?;
    let sa = polepatch_patcher::analysis::axis_splines(pa).ok()?;
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
    let curve = |sp: &polepatch_bspline::BSpline| -> Vec<(f64, f64)> {
        let m = 400;
        (0..=m)
            .map(|k| {
                let t = s0 + (s1 - s0) * k as f64 / m as f64;
                (t, sp.eval(t))
            })
            .collect()
    };
    let ci = Axis::C.index();
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
        c_points_before: (lo..=hi).map(|k| (s[k], pb.axes[k][ci])).collect(),
        c_points_after: (lo..=hi).map(|k| (s[k], pa.axes[k][ci])).collect(),
        c_curve_before: curve(&sb[ci]),
        c_curve_after: curve(&sa[ci]),
        ratio_before: window(&ab.samples),
        ratio_after: window(&aa.samples),
    })
}
