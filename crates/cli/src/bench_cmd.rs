//! `polepatch bench`: the quality suite's command line, table, CSV, JSON and plots.

use crate::{check_positive, machine};
use anyhow::{Context, Result, bail};
use polepatch::kinematics::Machine;
use polepatch::patcher::PatchOptions;
use polepatch::report::{FiguresRow, ZoneRow};
use polepatch_cli::bench::{
    BallCentreShift, BenchOptions, BenchReport, BenchStrategy, BenchZone, BoundStatus,
    RATIO_TARGET, plot,
};
use polepatch_cli::outputs::{Input, Output, Target, plan};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Arguments of `polepatch bench`.
#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub(crate) struct BenchArgs {
    /// NC programs or folders of them (default: fixtures/ of the repository, run from its root).
    paths: Vec<PathBuf>,
    /// Machines, repeatable: built-in names or TOML files (default: both built-in machines).
    #[arg(long, short)]
    machine: Vec<String>,
    /// Write the per-zone rows as CSV to this file.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Write the whole suite as one JSON document to this file.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Write one SVG per zone into this folder.
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Plot only the programs whose file name contains this text.
    #[arg(long, requires = "plots")]
    plot_only: Option<String>,
    /// Feed in mm/min for runs with no F in force.
    #[arg(long)]
    feed: Option<f64>,
    /// A fixed singular cone, degrees (see `patch`). Default: a 5° cone and the pole reach.
    #[arg(long)]
    cone: Option<f64>,
    /// Pole reach, degrees (see `patch`). Default 10; with --cone, the cone.
    #[arg(long)]
    pole_reach: Option<f64>,
    /// Safety margin on the rotary axes' limits the patch aims at, as a fraction.
    #[arg(long, default_value_t = PatchOptions::default().margin)]
    margin: f64,
    /// Strategies to compare, repeatable: polepatch (the default of `patch`), only-c,
    /// freeze, linearize, smooth, or all (default: polepatch).
    #[arg(long)]
    strategy: Vec<String>,
    /// Skip the references (their solves take most of the time).
    #[arg(long)]
    no_bound: bool,
    /// Worker threads (default: all cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// The cutter for every program (as `patch`): ball:D, flat:D or bull:D,R (mm).
    /// Default: per run, from the program; the `ctr µm` column then gives the shift per
    /// mm of a ball's radius.
    #[arg(long, value_parser = polepatch::tool::Tool::parse, value_name = "KIND:D[,R]")]
    tool: Option<polepatch::tool::Tool>,
    /// Which point of the tool X Y Z are (as `patch`): tip or centre.
    #[arg(long, value_parser = polepatch::tool::ToolPoint::parse, value_name = "tip|centre")]
    tool_point: Option<polepatch::tool::ToolPoint>,
    /// How far a flat or bull-nose cutter's surface may move at a CL point, mm (as `patch`).
    #[arg(long, value_name = "MM", default_value_t = polepatch::tool::SURFACE_TOLERANCE_MM)]
    surface_tolerance: f64,
}

/// Files of the inputs: folders expand recursively (hidden entries skipped), sorted.
fn expand(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for input in inputs {
        if !input.is_dir() {
            if !input.exists() {
                bail!("{}: no such file or folder", input.display());
            }
            out.push(input.clone());
            continue;
        }
        let mut found = Vec::new();
        let mut stack = vec![input.clone()];
        while let Some(dir) = stack.pop() {
            for e in std::fs::read_dir(&dir)
                .with_context(|| format!("cannot read folder {}", dir.display()))?
            {
                let p = e?.path();
                if p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with('.'))
                {
                    continue;
                }
                if p.is_dir() {
                    stack.push(p);
                } else {
                    found.push(p);
                }
            }
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

pub(crate) fn run(args: BenchArgs) -> Result<ExitCode> {
    check_positive("--feed", args.feed)?;
    let (cone_deg, pole_reach_deg) = crate::cone_and_reach(args.cone, args.pole_reach)?;
    check_positive("--surface-tolerance", Some(args.surface_tolerance))?;
    if !(0.0..0.5).contains(&args.margin) {
        bail!("--margin must be in [0, 0.5), got {}", args.margin);
    }
    let paths = if args.paths.is_empty() {
        let d = PathBuf::from("fixtures");
        if !d.is_dir() {
            bail!(
                "no PATHS given and there is no fixtures/ folder here: run from the repository root or name the programs"
            );
        }
        vec![d]
    } else {
        args.paths.clone()
    };
    let files = expand(&paths)?;
    if files.is_empty() {
        bail!("no input files");
    }
    let mut inputs: Vec<Input> = files.iter().map(|f| Input::new("the input", f)).collect();
    for m in &args.machine {
        inputs.extend(crate::machine_input(m));
    }
    let mut outputs = Vec::new();
    if let Some(path) = &args.json {
        outputs.push(Output::new("--json", path));
    }
    if let Some(path) = &args.csv {
        outputs.push(Output::new("--csv", path));
    }
    // Checked now (before the suite runs), and again with the plots once their names are
    // known (before anything is written).
    plan(&inputs, outputs.clone())?;
    let machines: Vec<Machine> = if args.machine.is_empty() {
        Machine::builtin_names()
            .iter()
            .map(|n| machine(n))
            .collect::<Result<_>>()?
    } else {
        args.machine
            .iter()
            .map(|n| machine(n))
            .collect::<Result<_>>()?
    };
    let mut strategies = Vec::new();
    for name in &args.strategy {
        if name == "all" {
            strategies.extend(BenchStrategy::ALL);
            continue;
        }
        match BenchStrategy::from_name(name) {
            Some(s) => strategies.push(s),
            None => bail!(
                "unknown strategy '{name}': polepatch, only-c, freeze, linearize, smooth or all"
            ),
        }
    }
    if strategies.is_empty() {
        strategies.push(BenchStrategy::Polepatch);
    }
    strategies.dedup();
    let opts = BenchOptions {
        patch: PatchOptions {
            cone_deg,
            pole_reach_deg,
            margin: args.margin,
            ..PatchOptions::default()
        },
        strategies,
        feed_fallback_mm_min: args.feed,
        skip_bound: args.no_bound,
        plots: args.plots.is_some(),
        tool: polepatch::tool::ToolOptions {
            tool: args.tool,
            point: args.tool_point,
            surface_tolerance_mm: args.surface_tolerance,
            ..polepatch::tool::ToolOptions::default()
        },
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()
        .context("starting worker threads")?;
    let report = pool.install(|| polepatch_cli::bench::run(&files, &machines, &opts));

    print!("{}", table(&report));
    for e in &report.errors {
        eprintln!("polepatch: error: {} on {}: {}", e.file, e.machine, e.error);
    }
    let plots = match &args.plots {
        Some(dir) => plot_files(&report, dir, args.plot_only.as_deref()),
        None => Vec::new(),
    };
    let n_files = outputs.len();
    outputs.extend(
        plots
            .iter()
            .map(|(path, _)| Output::new("the plot", path.clone())),
    );
    let targets = plan(&inputs, outputs)?;
    let write = |target: &Target, bytes: &[u8]| {
        target
            .write(bytes, None)
            .with_context(|| format!("cannot write {}", target.path.display()))
    };
    let mut files_out = targets[..n_files].iter();
    if args.json.is_some() {
        let doc = serde_json::to_string_pretty(&report)?;
        write(files_out.next().expect("planned"), doc.as_bytes())?;
    }
    if args.csv.is_some() {
        write(files_out.next().expect("planned"), &csv_rows(&report)?)?;
    }
    if let Some(dir) = &args.plots {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        for ((_, p), target) in plots.iter().zip(&targets[n_files..]) {
            let svg = plot::render_svg(p).map_err(anyhow::Error::msg)?;
            write(target, svg.as_bytes())?;
        }
        eprintln!(
            "polepatch: {} plot(s) written to {}",
            plots.len(),
            dir.display()
        );
    }
    Ok(if report.errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

fn short_name(file: &str) -> String {
    Path::new(file)
        .file_name()
        .map_or(file.to_string(), |n| n.to_string_lossy().into_owned())
}

/// `before → after` of a figure, 3 decimals.
pub(crate) fn arrow(before: f64, after: f64) -> String {
    format!("{before:.3} → {after:.3}")
}

fn bound_text(z: &BenchZone) -> String {
    match (&z.bound.status, z.bound.bound_deg) {
        (BoundStatus::Ok, Some(b)) => format!("{b:.3}"),
        (BoundStatus::Unreachable, _) => "unreachable".into(),
        (BoundStatus::Skipped, _) => "-".into(),
        _ => "error".into(),
    }
}

fn ratio_text(z: &BenchZone) -> String {
    match z.ratio {
        Some(r) => format!("{r:.3}"),
        None => "—".into(),
    }
}

fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// The tables: one row per zone and strategy (a program × machine with no zone gets one
/// row saying so); the strategies side by side per program × machine; the headline figures
/// per strategy.
pub(crate) fn table(report: &BenchReport) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<30} {:<13} {:<9} {:>3} {:>11} {:>15} {:>15} {:>15} {:>4} {:>4} {:>21} {:>7} {:>11} {:>6} {:>6} {:>8} {:>9} {:>8}",
        "file",
        "machine",
        "strategy",
        "run",
        "lines",
        "C ratio",
        "primary ratio",
        "overall ratio",
        "C✓",
        "A✓",
        "time s (L/F)",
        "dev °",
        "ref °",
        "ours/r",
        "points",
        "len mm",
        "ctr µm",
        "solve ms"
    );
    for case in &report.cases {
        let name = short_name(&case.file);
        if case.zones.is_empty() {
            let _ = writeln!(
                out,
                "{name:<30} {:<13} {:<9} {:>3} {:>11} no zone",
                case.machine,
                case.strategy.name(),
                "-",
                "-"
            );
            continue;
        }
        for z in &case.zones {
            let r = &z.row;
            let f = |g: fn(&FiguresRow) -> f64| arrow(g(&r.before), g(&r.after));
            let _ = writeln!(
                out,
                "{name:<30} {:<13} {:<9} {:>3} {:>11} {:>15} {:>15} {:>15} {:>4} {:>4} {:>21} {:>7.3} {:>11} {:>6} {:>6} {:>8.3} {:>9} {:>8.3}",
                case.machine,
                case.strategy.name(),
                r.run,
                format!("{}–{}", r.lines[0], r.lines[1]),
                f(|x| x.c_ratio),
                f(|x| x.primary_ratio),
                f(|x| x.overall_ratio),
                yes(z.at_feed_c),
                yes(z.at_feed_both),
                format!(
                    "{} ({:.3})",
                    arrow(r.before.time_s, r.after.time_s),
                    r.ideal_time_s
                ),
                r.max_deviation_deg,
                bound_text(z),
                ratio_text(z),
                r.points_modified,
                r.patch_length_mm,
                z.ball_centre_shift.text(),
                r.solve_time_ms,
            );
        }
    }
    let strategies = report.strategies();
    if strategies.len() > 1 {
        let _ = writeln!(
            out,
            "\nSide by side (zones at feed on C / on both rotary axes, of all zones; largest deviation °; estimated time of the runs with zones and their simulated time, s):"
        );
        let mut head = format!("{:<30} {:<13}", "file", "machine");
        for s in &strategies {
            let _ = write!(head, " {:>36}", s.name());
        }
        let _ = writeln!(out, "{head}");
        let mut k = 0;
        while k < report.cases.len() {
            let (file, machine) = (&report.cases[k].file, &report.cases[k].machine);
            let mut line = format!("{:<30} {:<13}", short_name(file), machine);
            while k < report.cases.len()
                && &report.cases[k].file == file
                && &report.cases[k].machine == machine
            {
                let c = &report.cases[k];
                let zc = c.zones.iter().filter(|z| z.at_feed_c).count();
                let zb = c.zones.iter().filter(|z| z.at_feed_both).count();
                let dev = c
                    .zones
                    .iter()
                    .map(|z| z.row.max_deviation_deg)
                    .fold(0.0, f64::max);
                let _ = write!(
                    line,
                    " {:>36}",
                    format!(
                        "{zc}/{zb} of {} {dev:.3}° {}s sim {}s",
                        c.zones.len(),
                        seconds_text(c.time_s[1]),
                        seconds_text(c.sim_time_s[1])
                    )
                );
                k += 1;
            }
            let _ = writeln!(out, "{line}");
        }
    }
    let opt = |v: Option<f64>| v.map_or("—".to_string(), |v| format!("{v:.3}"));
    for strategy in strategies {
        let s = report.summary(strategy);
        let reference = if strategy.both_axes() {
            "best found (both axes)"
        } else {
            "C-only LP bound"
        };
        let _ = writeln!(
            out,
            "\n{}: {} zone(s): {} at feed on C, {} on both rotary axes; reference unreachable for {}; largest deviation {:.3}°; time of the runs with zones {:.3} → {:.3} s (L/F {:.3} s), simulated {:.3} → {:.3} s{}.",
            strategy.name(),
            s.zones,
            s.at_feed_c,
            s.at_feed_both,
            s.unreachable,
            s.max_deviation_deg,
            s.time_s[0],
            s.time_s[1],
            s.time_s[2],
            s.sim_time_s[0],
            s.sim_time_s[1],
            if s.not_compared > 0 {
                format!(
                    " ({} program(s) left out: the output reads as other runs than the input)",
                    s.not_compared
                )
            } else {
                String::new()
            }
        );
        let _ = writeln!(
            out,
            "  ours/reference ({reference}) over {} zone(s): median {}, worst {}; {} within {RATIO_TARGET} (SPEC §6).",
            s.ratios,
            opt(s.ratio_median),
            opt(s.ratio_worst),
            s.ratio_within_target
        );
    }
    out
}

fn csv_rows(report: &BenchReport) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["file", "machine", "strategy"];
    header.extend(ZoneRow::CSV_COLUMNS);
    header.extend([
        "at_feed_c",
        "at_feed_both",
        "reference_kind",
        "bound_deg",
        "ratio",
        "ball_centre_shift_um",
        "ball_centre_shift_um_per_mm_radius",
    ]);
    w.write_record(&header)?;
    for z in report.zones() {
        let mut rec = vec![
            z.row.file.clone(),
            z.machine.clone(),
            z.strategy.name().to_string(),
        ];
        rec.extend(z.row.csv_fields());
        rec.push(z.at_feed_c.to_string());
        rec.push(z.at_feed_both.to_string());
        rec.push(z.bound.kind.to_string());
        rec.push(match (&z.bound.status, z.bound.bound_deg) {
            (BoundStatus::Ok, Some(b)) => format!("{b:.6}"),
            (s, _) => s.to_string(),
        });
        rec.push(z.ratio.map_or(String::new(), |v| format!("{v:.6}")));
        let (um, per_mm) = match z.ball_centre_shift {
            BallCentreShift::Ball(v) => (format!("{v:.3}"), String::new()),
            BallCentreShift::PerMmRadius(v) => (String::new(), format!("{v:.3}")),
            BallCentreShift::None => (String::new(), String::new()),
        };
        rec.push(um);
        rec.push(per_mm);
        w.write_record(&rec)?;
    }
    Ok(w.into_inner()?)
}

/// One SVG per zone with plot data: `<file-stem>-<machine>-run<r>-zone<k>.svg`, k counting
/// the zones of the run from 1; with `only`, just the files whose name contains it. The
/// paths and the plots, to be checked by the output policy and then written.
fn plot_files<'a>(
    report: &'a BenchReport,
    dir: &Path,
    only: Option<&str>,
) -> Vec<(PathBuf, &'a plot::ZonePlot)> {
    let mut out = Vec::new();
    for case in &report.cases {
        if only.is_some_and(|o| !short_name(&case.file).contains(o)) {
            continue;
        }
        let stem = Path::new(&case.file)
            .file_stem()
            .map_or("program".to_string(), |s| s.to_string_lossy().into_owned());
        let mut k = 0;
        let mut last_run = 0;
        for z in &case.zones {
            if z.row.run != last_run {
                k = 0;
                last_run = z.row.run;
            }
            k += 1;
            let Some(p) = &z.plot else { continue };
            let suffix = match case.strategy {
                BenchStrategy::Polepatch => String::new(),
                s => format!("-{}", s.name()),
            };
            let path = dir.join(format!(
                "{stem}-{}-run{}-zone{k}{suffix}.svg",
                case.machine, z.row.run
            ));
            out.push((path, p));
        }
    }
    out
}

/// Seconds with 3 decimals, "—" where there is no number (a strategy whose output reads as
/// other runs: `BenchCase::time_s`).
fn seconds_text(t_s: f64) -> String {
    if t_s.is_finite() {
        format!("{t_s:.3}")
    } else {
        "—".to_string()
    }
}
