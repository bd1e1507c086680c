//! `polepatch simulate`: the cycle time a jerk-limited controller would take, per run, next
//! to Equation 6's estimate and L/F; the trajectory as CSV; the feed and each axis' share
//! of its limits along s as SVG (before and after, given two programs).

use crate::{check_positive, machine};
use anyhow::{Context, Result, bail};
use plotters::prelude::*;
use polepatch::kinematics::{Axis, Machine};
use polepatch::report::SimulateReport;
use polepatch::report::axis_letter;
use polepatch::simulate::{SimState, SimulateOptions, simulate_nc_owned};
use polepatch_cli::files::read;
use polepatch_cli::outputs::{Input, Output, plan};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub(crate) struct SimulateArgs {
    /// NC program; a second one (e.g. the patched program) is simulated too and compared.
    #[arg(required = true, num_args = 1..=2)]
    programs: Vec<PathBuf>,
    /// Machine: a built-in name (mikron-ucp710, mikron-hsm600) or a TOML file.
    #[arg(long, short)]
    machine: String,
    /// Print one JSON document (an array with one report per program) instead of the table.
    #[arg(long)]
    json: bool,
    /// Write the trajectory at the machine's Tcy as CSV (one program only): run, t_s, s_mm,
    /// X, Y, Z, the tilting and the pole axis (by their letters, e.g. A, C), feed_mm_min.
    #[arg(long)]
    trajectory: Option<PathBuf>,
    /// Draw the feed and each axis' share of its limits along s (SVG).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// How the program is read: --feed, --units, --work-offset.
    #[command(flatten)]
    read: crate::ReadArgs,
    /// Interpolation cycle time override, ms (default: the machine's).
    #[arg(long)]
    tcy_ms: Option<f64>,
    /// The planner: `jerk` (a jerk-limited controller within every axis' V, A and J, the
    /// default), `cycles` (the same limits simulated cycle by cycle, over them where it
    /// cannot brake in time; docs/simulation.md) or `linuxcnc` (a model of LinuxCNC 2.9's
    /// planner: V and A only, each line stopping within itself at half the acceleration;
    /// docs/linuxcnc.md, docs/validation.md).
    #[arg(long, value_enum, default_value_t = crate::lcnc_planner::Planner::Jerk)]
    planner: crate::lcnc_planner::Planner,
    /// With `--planner cycles` (experimental): where the motion would be put on its
    /// velocity limit within one cycle, go back and brake in time instead — within the
    /// axes' jerk on more programs, somewhat slower, at up to 2.4× the computing
    /// (docs/simulation.md, "Jerk at every cycle").
    #[arg(long)]
    rewind: bool,
}

/// Largest number of bins of the plot along s (the bins double in width when full, so
/// the memory is bounded whatever the program's length).
const PLOT_BINS: usize = 4000;

/// One bin of the plot: the lowest feed and each axis' largest share in [s, s + width).
#[derive(Debug, Clone, Copy)]
struct Bin {
    feed_min: f64,
    share_max: [f64; 5],
}

/// States gathered along s into at most [`PLOT_BINS`] bins.
struct Binned {
    width_mm: f64,
    bins: Vec<Option<Bin>>,
}

impl Binned {
    fn new() -> Binned {
        Binned {
            width_mm: 1e-3,
            bins: Vec::new(),
        }
    }
    fn add(&mut self, s: &SimState) {
        let mut k = (s.s_total_mm / self.width_mm) as usize;
        while k >= PLOT_BINS {
            // Merge pairs: the same bins at twice the width.
            let merged: Vec<Option<Bin>> = self
                .bins
                .chunks(2)
                .map(|c| {
                    c.iter().flatten().copied().reduce(|a, b| Bin {
                        feed_min: a.feed_min.min(b.feed_min),
                        share_max: std::array::from_fn(|i| a.share_max[i].max(b.share_max[i])),
                    })
                })
                .collect();
            self.bins = merged;
            self.width_mm *= 2.0;
            k = (s.s_total_mm / self.width_mm) as usize;
        }
        if self.bins.len() <= k {
            self.bins.resize(k + 1, None);
        }
        let b = self.bins[k].get_or_insert(Bin {
            feed_min: f64::INFINITY,
            share_max: [0.0; 5],
        });
        b.feed_min = b.feed_min.min(s.feed_mm_min);
        for (m, v) in b.share_max.iter_mut().zip(s.shares) {
            *m = m.max(v);
        }
    }
    fn points(&self) -> impl Iterator<Item = (f64, Bin)> + '_ {
        self.bins
            .iter()
            .enumerate()
            .filter_map(|(k, b)| b.map(|b| ((k as f64 + 0.5) * self.width_mm, b)))
    }
}

pub(crate) fn run(args: SimulateArgs) -> Result<ExitCode> {
    check_positive("--feed", args.read.feed)?;
    crate::check_tcy_ms(args.tcy_ms)?;
    if args.planner == crate::lcnc_planner::Planner::Linuxcnc {
        if args.trajectory.is_some() || args.plot.is_some() {
            return Err(crate::usage(
                "--planner linuxcnc gives times only: no --trajectory or --plot",
            ));
        }
        if args.rewind {
            return Err(crate::usage(
                "--rewind is for --planner cycles, not --planner linuxcnc",
            ));
        }
        let tcy_s = args.tcy_ms.map(|ms| ms / 1000.0);
        return crate::lcnc_planner::run(
            &args.programs,
            &args.machine,
            &args.read,
            tcy_s,
            args.json,
        );
    }
    if args.rewind && args.planner != crate::lcnc_planner::Planner::Cycles {
        return Err(crate::usage(
            "--rewind is for --planner cycles (the default planner needs no rewinds: it is \
             within every axis' limits)",
        ));
    }
    if args.trajectory.is_some() && args.programs.len() > 1 {
        bail!("--trajectory writes one program's trajectory: give one program");
    }
    // The output-path policy (docs/output-paths.md): never an input, never two outputs
    // on one path; checked before anything is written.
    let mut inputs: Vec<Input> = args
        .programs
        .iter()
        .map(|p| Input::new("the program", p))
        .collect();
    inputs.extend(crate::machine_input(&args.machine));
    let mut outputs = Vec::new();
    if let Some(p) = &args.trajectory {
        outputs.push(Output::new("--trajectory", p));
    }
    if let Some(p) = &args.plot {
        outputs.push(Output::new("--plot", p));
    }
    let targets = plan(&inputs, outputs)?;
    let trajectory_target = args.trajectory.as_ref().map(|_| &targets[0]);
    let plot_target = args
        .plot
        .as_ref()
        .map(|_| &targets[usize::from(args.trajectory.is_some())]);
    let machine = machine(&args.machine)?;
    let mut reports: Vec<SimulateReport> = Vec::new();
    let mut plots: Vec<Binned> = Vec::new();
    for program in &args.programs {
        let name = program.display().to_string();
        let bytes = read(program)?;
        let mut opts = SimulateOptions {
            read: args.read.options(name.clone())?,
            ..SimulateOptions::default()
        };
        opts.sim.tcy_s = args.tcy_ms.map(|ms| ms / 1000.0);
        opts.sim.every_cycle = args.trajectory.is_some();
        opts.sim.rewind = args.rewind;
        opts.sim.per_cycle = args.planner == crate::lcnc_planner::Planner::Cycles;
        let mut binned = Binned::new();
        let want_plot = args.plot.is_some();
        let report = if let Some(target) = trajectory_target {
            let path = &target.path;
            let mut report = None;
            let primary_guess = machine.primary_letter();
            let mut sink = target
                .create(None)
                .with_context(|| format!("writing the trajectory {}", path.display()))?;
            let written = (|| -> std::io::Result<()> {
                let mut buffered = std::io::BufWriter::with_capacity(1 << 16, &mut sink);
                let w: &mut dyn Write = &mut buffered;
                let mut failure: Option<std::io::Error> = None;
                let mut header_written = false;
                let mut on = |s: &SimState| {
                    if want_plot {
                        binned.add(s);
                    }
                    if failure.is_some() {
                        return;
                    }
                    let r = (|| {
                        if !header_written {
                            header_written = true;
                            writeln!(
                                w,
                                "run,t_s,s_mm,X,Y,Z,{primary_guess},{},feed_mm_min",
                                machine.c_letter()
                            )?;
                        }
                        let q = s.axes;
                        writeln!(
                            w,
                            "{},{},{},{},{},{},{},{},{}",
                            s.run, s.t_s, s.s_mm, q[0], q[1], q[2], q[3], q[4], s.feed_mm_min
                        )
                    })();
                    if let Err(e) = r {
                        failure = Some(e);
                    }
                };
                let r = simulate_nc_owned(bytes, &machine, &opts, Some(&mut on))
                    .map_err(std::io::Error::other)?;
                if let Some(e) = failure {
                    return Err(e);
                }
                if !header_written {
                    // Nothing simulated: the columns alone (a CSV with no rows).
                    writeln!(
                        w,
                        "run,t_s,s_mm,X,Y,Z,{primary_guess},{},feed_mm_min",
                        machine.c_letter()
                    )?;
                }
                report = Some(r);
                buffered.flush()
            })();
            written.with_context(|| format!("writing the trajectory {}", path.display()))?;
            let report = report.context("no report")?;
            // (A program of another tilting letter is refused before any row: the header's
            // letter is the program's.)
            debug_assert_eq!(report.primary, primary_guess.to_string());
            sink.commit()
                .with_context(|| format!("writing {}", path.display()))?;
            report
        } else if want_plot {
            let mut on = |s: &SimState| binned.add(s);
            simulate_nc_owned(bytes, &machine, &opts, Some(&mut on))?
        } else {
            simulate_nc_owned(bytes, &machine, &opts, None)?
        };
        reports.push(report);
        plots.push(binned);
    }
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    if args.json {
        writeln!(out, "{}", serde_json::to_string_pretty(&reports)?)?;
    } else {
        for r in &reports {
            print_report(&mut out, r)?;
        }
        if let [a, b] = &reports[..] {
            writeln!(
                out,
                "\n{} against {}: simulated {:.3} s → {:.3} s ({}), Equation 6 {:.3} s → {:.3} s",
                b.file,
                a.file,
                a.total.time_s,
                b.total.time_s,
                pct_text(b.total.time_s, a.total.time_s),
                a.total.eq6_time_s,
                b.total.eq6_time_s
            )?;
        }
    }
    out.flush()?;
    drop(out);
    if let Some(target) = plot_target {
        let path = &target.path;
        let svg = plot(&reports, &plots, &machine)
            .map_err(|e| anyhow::anyhow!("drawing {}: {e}", path.display()))?;
        target
            .write(svg.as_bytes(), None)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    let mut failed = false;
    for r in &reports {
        for w in &r.warnings {
            eprintln!("polepatch: warning: {w}");
        }
        for run in r.runs.iter().filter(|x| x.error.is_some()) {
            failed = true;
            eprintln!(
                "polepatch: error: {}: run {} (lines {}–{}): {}",
                r.file,
                run.run,
                run.lines[0],
                run.lines[1],
                run.error.as_deref().unwrap_or("")
            );
        }
    }
    Ok(if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}

fn pct(x: f64, of: f64) -> f64 {
    100.0 * (x / of - 1.0)
}

/// `x` against `of` in per cent for people: `+1.3 %`, or `-` where `of` is 0 (no NaN).
fn pct_text(x: f64, of: f64) -> String {
    if of > 0.0 && x.is_finite() {
        format!("{:+.1} %", pct(x, of))
    } else {
        "-".to_string()
    }
}

/// The lowest feed of a run for the table, mm/min: whole numbers from 10 up, else the
/// digits that say it (a feed of 0.4 mm/min is not "0").
fn lowest_feed_text(f: f64) -> String {
    if f >= 10.0 {
        format!("{f:.0}")
    } else {
        format!("{:.2e}", f)
            .parse::<f64>()
            .map_or_else(|_| "-".into(), polepatch::report::feed_text)
    }
}

/// The table of one report.
fn print_report(out: &mut impl Write, r: &SimulateReport) -> std::io::Result<()> {
    if let Some(why) = &r.nothing_to_simulate {
        return writeln!(
            out,
            "{} on {}: nothing to simulate: {why}",
            r.file, r.machine
        );
    }
    writeln!(
        out,
        "{} on {} (Tcy {} ms)\n{:>5} {:>13} {:>11} {:>9} {:>9} {:>10} {:>10} {:>18}",
        r.file,
        r.machine,
        r.tcy_s * 1000.0,
        "run",
        "lines",
        "length mm",
        "F mm/min",
        "L/F s",
        "Eq. 6 s",
        "simulated",
        "lowest feed (line)"
    )?;
    for run in &r.runs {
        let lines = format!("{}–{}", run.lines[0], run.lines[1]);
        let feed = run
            .feed_mm_min
            .map_or("no F".into(), polepatch::report::feed_text);
        if let Some(e) = &run.error {
            writeln!(
                out,
                "{:>5} {lines:>13} {:>11.3} {feed:>9}  not simulated: {e}",
                run.run, run.length_mm
            )?;
            continue;
        }
        let low = match (run.min_feed_mm_min, run.min_feed_line) {
            (Some(f), Some(l)) => format!("{} ({l})", lowest_feed_text(f)),
            _ => "-".into(),
        };
        writeln!(
            out,
            "{:>5}{} {lines:>12} {:>11.3} {feed:>9} {:>9.3} {:>10.3} {:>10.3} {low:>18}",
            run.run,
            if run.joined { "+" } else { " " },
            run.length_mm,
            run.ideal_time_s,
            run.eq6_time_s,
            run.time_s
        )?;
    }
    let t = &r.total;
    if t.runs == 0 {
        writeln!(out, "total: no run simulated (each run above says why)")?;
    } else {
        writeln!(
            out,
            "total over {} runs: L/F {:.3} s, Equation 6 {:.3} s ({}), simulated {:.3} s ({})",
            t.runs,
            t.ideal_time_s,
            t.eq6_time_s,
            pct_text(t.eq6_time_s, t.ideal_time_s),
            t.time_s,
            pct_text(t.time_s, t.ideal_time_s)
        )?;
    }
    if r.runs.iter().any(|x| x.joined) {
        writeln!(
            out,
            "(+: moves on from the run before without a stop, after a feed change)"
        )?;
    }
    if t.clips > 0 {
        writeln!(
            out,
            "note: {} cycles were put on the velocity limit by the simulator (see docs/simulation.md)",
            t.clips
        )?;
    }
    Ok(())
}

/// The SVG: the feed along s (every program), then each axis' share of its limits
/// (one panel per program).
fn plot(
    reports: &[SimulateReport],
    plots: &[Binned],
    machine: &Machine,
) -> Result<String, Box<dyn std::error::Error>> {
    let mut buf = String::new();
    {
        let panels = 1 + plots.len();
        let root =
            SVGBackend::with_string(&mut buf, (960, 300 * panels as u32)).into_drawing_area();
        root.fill(&WHITE)?;
        let areas = root.split_evenly((panels, 1));
        let s_max = plots
            .iter()
            .flat_map(|p| p.points().map(|(s, _)| s))
            .fold(1e-9f64, f64::max);
        let f_max = reports
            .iter()
            .flat_map(|r| r.runs.iter().filter_map(|x| x.feed_mm_min))
            .fold(1.0f64, f64::max);
        let colors = [
            RGBColor(31, 119, 180),
            RGBColor(214, 39, 40),
            RGBColor(44, 160, 44),
            RGBColor(148, 103, 189),
            RGBColor(255, 127, 14),
        ];
        let mut chart = ChartBuilder::on(&areas[0])
            .caption(
                format!("feed along s on {}", machine.name),
                ("sans-serif", 16),
            )
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..s_max, 0.0..f_max * 1.05)?;
        chart
            .configure_mesh()
            .x_desc("s, mm (simulated runs one after another)")
            .y_desc("feed, mm/min")
            .draw()?;
        for (k, (p, r)) in plots.iter().zip(reports).enumerate() {
            let c = colors[k % colors.len()];
            chart
                .draw_series(LineSeries::new(p.points().map(|(s, b)| (s, b.feed_min)), c))?
                .label(format!("{} ({:.3} s)", r.file, r.total.time_s))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()?;
        for (k, (p, r)) in plots.iter().zip(reports).enumerate() {
            let mut chart = ChartBuilder::on(&areas[k + 1])
                .caption(
                    format!(
                        "{}: each axis' share of its limits (largest of V, A, J)",
                        r.file
                    ),
                    ("sans-serif", 16),
                )
                .margin(10)
                .x_label_area_size(35)
                .y_label_area_size(60)
                .build_cartesian_2d(0.0..s_max, 0.0..1.1f64)?;
            chart
                .configure_mesh()
                .x_desc("s, mm")
                .y_desc("share")
                .draw()?;
            let letters = polepatch::nc::RotaryLetters {
                tilt: r.primary.as_bytes().first().copied().unwrap_or(b'A'),
                pole: machine.c_letter() as u8,
            };
            for axis in Axis::ALL {
                let c = colors[axis.index()];
                chart
                    .draw_series(LineSeries::new(
                        p.points().map(|(s, b)| (s, b.share_max[axis.index()])),
                        c,
                    ))?
                    .label(axis_letter(axis, letters))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }
        root.present()?;
    }
    Ok(buf)
}
