//! Equation 6 along every run of a loaded program: what `polepatch analyze` reports.

use crate::program::LoadedProgram;
use crate::report::{
    AnalyzeReport, MachineFrameFigures, RunFigures, RunReport, ZoneSummary, axis_letter,
    machine_units,
};
use polepatch_kinematics::{Axis, Machine};
use polepatch_patcher::{AnalysisOptions, RunAnalysis, analyze_path};
use std::collections::BTreeMap;

/// Summarise one analysed run.
pub fn run_figures(lp: &LoadedProgram, r: usize, a: &RunAnalysis) -> RunFigures {
    let pl = lp.letters();
    let s = &lp.runs[r].run.s_mm;
    let k = s
        .partition_point(|&v| v < a.min_s_mm - 1e-9)
        .min(s.len() - 1);
    let mut axis_min_ratio = BTreeMap::new();
    let mut axis_limit = BTreeMap::new();
    let mut peak_speed = BTreeMap::new();
    for axis in Axis::ALL {
        let l = axis_letter(axis, pl);
        axis_min_ratio.insert(l.clone(), a.axis_min[axis.index()].0);
        axis_limit.insert(l.clone(), a.axis_min[axis.index()].1);
        peak_speed.insert(l, machine_units(axis, a.peak_speed[axis.index()]));
    }
    RunFigures {
        min_ratio: a.min.ratio,
        limiting_axis: a.min.axis.map(|x| axis_letter(x, pl)),
        limiting_limit: a.min.kind,
        min_at_s_mm: a.min_s_mm,
        min_at_line: lp.line_of(r, k),
        axis_min_ratio,
        axis_limit,
        time_s: a.time_s,
        ideal_time_s: a.ideal_time_s,
        peak_speed,
        zones: a
            .zones
            .iter()
            .map(|z| ZoneSummary {
                lines: [lp.line_of(r, z.first), lp.line_of(r, z.last)],
                kind: z.kind,
                singular_line: lp.line_of(r, z.singular),
                min_abs_primary_deg: z.min_abs_primary_deg,
                c_ratio_min: z.c_ratio_min,
            })
            .collect(),
    }
}

/// The machine-frame figures of run `r`, when the machine has a chain and the work offset
/// is known.
fn machine_frame_figures(
    lp: &LoadedProgram,
    r: usize,
    path: &polepatch_patcher::Path,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> Option<MachineFrameFigures> {
    let chain = machine.chain.as_ref()?;
    let datum_mm = lp.datum_mm(r)?;
    let mp = crate::machine_frame::machine_frame_path(
        chain,
        machine,
        datum_mm,
        lp.runs[r].run.tcpm.is_on(),
        &path.axes,
        &path.s_mm,
        path.feed_mm_min,
    );
    let a = analyze_path(&mp, machine, opts).ok()?;
    let mut f = MachineFrameFigures {
        datum_mm,
        peak_speed: BTreeMap::new(),
        axis_min_ratio: BTreeMap::new(),
        axis_limit: BTreeMap::new(),
    };
    for axis in [Axis::X, Axis::Y, Axis::Z] {
        let l = axis_letter(axis, lp.letters());
        f.peak_speed
            .insert(l.clone(), machine_units(axis, a.peak_speed[axis.index()]));
        f.axis_min_ratio
            .insert(l.clone(), a.axis_min[axis.index()].0);
        f.axis_limit.insert(l, a.axis_min[axis.index()].1);
    }
    Some(f)
}

/// Analyse every run of a loaded program.
pub fn analyze_program(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> AnalyzeReport {
    let runs = lp
        .runs
        .iter()
        .enumerate()
        .map(|(r, rp)| {
            let n = rp.run.len();
            let mut rep = RunReport {
                run: lp.run_number(r),
                lines: lp.lines_of_run(r),
                points: n,
                length_mm: rp.run.length_mm(),
                // The run's F also when it is not analysed.
                feed_mm_min: lp.run_feed_mm_min(r),
                block_feeds_mm_min: block_feeds(&rp.run),
                feed_mode: rp.run.feed_mode,
                error: None,
                figures: None,
                machine_frame: None,
            };
            match &rp.path {
                Err(problem) => rep.error = Some(problem.to_string()),
                Ok(path) => match analyze_path(path, machine, opts) {
                    Ok(a) => {
                        rep.figures = Some(run_figures(lp, r, &a));
                        rep.machine_frame = machine_frame_figures(lp, r, path, machine, opts);
                    }
                    Err(e) => rep.error = Some(e.to_string()),
                },
            }
            rep
        })
        .collect();
    let (not_analysed, notes_warnings) = lp.notes.finish(lp.letters(), opts.reach_deg(), &lp.name);
    AnalyzeReport {
        file: lp.name.clone(),
        machine: machine.name.clone(),
        cone_deg: opts.cone_deg,
        pole_reach_deg: opts.pole_reach_deg,
        primary: (lp.primary_letter as char).to_string(),
        warnings: lp.warnings.iter().cloned().chain(notes_warnings).collect(),
        not_analysed,
        runs,
    }
}

/// The lowest and highest of a run's block feeds, where its blocks have their own and they
/// differ ([`RunReport::block_feeds_mm_min`]).
fn block_feeds(run: &polepatch_nc::Run) -> Option<[f64; 2]> {
    let f = &run.block_feed_mm_min;
    let lo = f.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo < hi).then_some([lo, hi])
}
