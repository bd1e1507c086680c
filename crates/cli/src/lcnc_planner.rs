//! `polepatch simulate --planner linuxcnc`: every run through the model of LinuxCNC 2.9's
//! planner ([`polepatch::sim::linuxcnc`]), next to L/F.

use anyhow::Result;
use polepatch::sim::linuxcnc::{LinuxCncMachine, run_time};
use polepatch_cli::files;
use serde::Serialize;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Which planner `simulate` models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Planner {
    /// A jerk-limited controller (V, A and J of every axis), planned in segments of
    /// constant limits: within every axis' limits at every cycle. The default.
    Jerk,
    /// The same controller simulated cycle by cycle under a velocity limit curve (the
    /// model before 2026-11-29): closer to the fastest motion on curved paths, but it
    /// puts the motion on its limit curve where it cannot brake in time, over the axes'
    /// jerk there (docs/simulation.md).
    Cycles,
    /// LinuxCNC 2.9 (V and A of the world axes, G64, the segment-stop rule).
    Linuxcnc,
}

/// One run under the model.
#[derive(Debug, Serialize)]
struct Row {
    run: usize,
    lines: [usize; 2],
    points: usize,
    length_mm: f64,
    feed_mm_min: Option<f64>,
    /// The model's time, s; `null` when the run was not simulated.
    time_s: Option<f64>,
    ideal_time_s: Option<f64>,
    /// X Y Z mm/s, primary and C °/s.
    peak_axis_velocity: Option<[f64; 5]>,
    error: Option<String>,
}

/// One program under the model.
#[derive(Debug, Serialize)]
struct Report {
    file: String,
    machine: String,
    planner: &'static str,
    cycle_s: f64,
    runs: Vec<Row>,
    /// Sum over the runs simulated, s.
    time_s: f64,
    ideal_time_s: f64,
}

pub(crate) fn run(
    programs: &[PathBuf],
    machine_name: &str,
    read: &crate::ReadArgs,
    tcy_s: Option<f64>,
    json: bool,
) -> Result<ExitCode> {
    let machine = crate::machine(machine_name)?;
    let mut lm = LinuxCncMachine::of(&machine);
    if let Some(t) = tcy_s {
        lm.cycle_s = t;
    }
    let mut reports = Vec::new();
    let mut failed = 0usize;
    for program in programs {
        let name = files::shown(program);
        let bytes = files::read(program)?;
        // The whole program is parsed here (this option is for checking a prediction, not
        // for files of gigabytes).
        let opts = polepatch::AnalyzeOptions {
            read: read.options(name.clone())?,
            ..polepatch::AnalyzeOptions::default()
        };
        let lp = polepatch::load_nc_with(&bytes, &machine, &opts)?;
        let mut report = Report {
            file: name,
            machine: machine.name.clone(),
            planner: "linuxcnc-2.9",
            cycle_s: lm.cycle_s,
            runs: Vec::new(),
            time_s: 0.0,
            ideal_time_s: 0.0,
        };
        for (r, rp) in lp.runs.iter().enumerate() {
            let lines = lp.lines_of_run(r);
            let mut row = Row {
                run: r + 1,
                lines,
                points: rp.run.len(),
                length_mm: 0.0,
                feed_mm_min: None,
                time_s: None,
                ideal_time_s: None,
                peak_axis_velocity: None,
                error: None,
            };
            match &rp.path {
                Ok(path) => {
                    let sim = run_time(&lm, &path.axes, path.feed_mm_min);
                    let length = *path.s_mm.last().unwrap_or(&0.0);
                    let ideal = length / (path.feed_mm_min / 60.0);
                    row.length_mm = length;
                    row.feed_mm_min = Some(path.feed_mm_min);
                    row.time_s = Some(sim.time_s);
                    row.ideal_time_s = Some(ideal);
                    row.peak_axis_velocity = Some(sim.peak_axis_velocity);
                    report.time_s += sim.time_s;
                    report.ideal_time_s += ideal;
                }
                Err(e) => {
                    failed += 1;
                    row.error = Some(e.to_string());
                }
            }
            report.runs.push(row);
        }
        reports.push(report);
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    if json {
        writeln!(out, "{}", serde_json::to_string_pretty(&reports)?)?;
    } else {
        for rep in &reports {
            writeln!(
                out,
                "{} on {}: LinuxCNC 2.9 planner model (servo period {} ms)",
                rep.file,
                rep.machine,
                rep.cycle_s * 1000.0
            )?;
            for row in &rep.runs {
                match (row.time_s, row.ideal_time_s) {
                    (Some(t), Some(lf)) => writeln!(
                        out,
                        "  run {}: lines {}–{}, {} points, {:.3} mm at F{}: {t:.3} s (L/F {lf:.3} s)",
                        row.run,
                        row.lines[0],
                        row.lines[1],
                        row.points,
                        row.length_mm,
                        row.feed_mm_min.unwrap_or(0.0)
                    )?,
                    _ => writeln!(
                        out,
                        "  run {}: lines {}–{}: not simulated: {}",
                        row.run,
                        row.lines[0],
                        row.lines[1],
                        row.error.as_deref().unwrap_or("")
                    )?,
                }
            }
            writeln!(
                out,
                "  total over the runs: {:.3} s (L/F {:.3} s)",
                rep.time_s, rep.ideal_time_s
            )?;
        }
        if let [a, b] = &reports[..] {
            writeln!(
                out,
                "\n{} against {}: {:.3} s → {:.3} s ({:+.1} %) on the LinuxCNC 2.9 model",
                b.file,
                a.file,
                a.time_s,
                b.time_s,
                100.0 * (b.time_s / a.time_s - 1.0)
            )?;
        }
    }
    out.flush()?;
    if failed > 0 {
        eprintln!("polepatch: {failed} run(s) not simulated (named above)");
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}
