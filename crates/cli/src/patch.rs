//! `polepatch patch`: one file or a batch.

use crate::{PatchArgs, check_positive, machine, usage};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use polepatch::patcher::{PatchAxes, PatchOptions};
use polepatch::{FileReport, ZoneRow};
use polepatch_cli::files::{JobError, patch_job};
use polepatch_cli::outputs::{Input, Output, is_std, plan};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The patcher's options of `args`, checked by the patcher's one rule set
/// ([`PatchOptions::validate`]) and refused as a usage error naming the flag.
fn options(args: &PatchArgs) -> Result<PatchOptions> {
    let (cone_deg, pole_reach_deg) = crate::cone_and_reach(args.cone, args.pole_reach)?;
    let opts = PatchOptions {
        cone_deg,
        pole_reach_deg,
        max_deviation_deg: args.max_deviation,
        margin: args.margin,
        third_derivative_continuity: !args.no_jerk_continuity,
        max_decimals: args.max_decimals,
        max_patch_length_mm: args.max_patch_length,
        allow_c_offset: args.c_offset,
        axes: if args.only_c {
            PatchAxes::OnlyC
        } else {
            PatchAxes::Both
        },
        ..PatchOptions::default()
    };
    opts.validate().map_err(crate::option_error)?;
    Ok(opts)
}

/// Files named on the command line, each with its path under `--out-dir`: a file given
/// keeps its file name; a folder given expands to the regular files in it (recursively,
/// skipping hidden entries, FIFOs and devices, not following links to folders), each under the folder's own name
/// (its real name, so `.` and `..` too) followed by its path inside the folder. The
/// relative paths are made of names only: they cannot leave `--out-dir`. The folder
/// `skip` (`--out-dir`, when it lies inside an input folder) is not expanded: the outputs of
/// an earlier run are not inputs.
fn expand(inputs: &[PathBuf], skip: Option<&Path>) -> Result<Vec<(PathBuf, PathBuf)>> {
    let skip = skip.and_then(|d| d.canonicalize().ok());
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let real = input
                .canonicalize()
                .with_context(|| format!("cannot read folder {}", input.display()))?;
            let top = PathBuf::from(real.file_name().unwrap_or_default());
            let mut stack = vec![(input.clone(), top)];
            while let Some((dir, rel_dir)) = stack.pop() {
                let mut entries: Vec<(PathBuf, bool)> = Vec::new();
                for e in std::fs::read_dir(&dir)
                    .with_context(|| format!("cannot read folder {}", dir.display()))?
                {
                    let e = e.with_context(|| format!("cannot read folder {}", dir.display()))?;
                    if e.file_name().to_string_lossy().starts_with('.') {
                        continue;
                    }
                    let kind = e.file_type()?;
                    // A link to a folder is not followed (a loop would never end).
                    let is_dir = kind.is_dir();
                    if kind.is_symlink() && e.path().is_dir() {
                        continue;
                    }
                    if is_dir && skip.is_some() && e.path().canonicalize().ok() == skip {
                        continue;
                    }
                    // Only regular files (or links to them) are programs: a FIFO or a
                    // device in a folder would block or never end.
                    if !is_dir && !e.path().is_file() {
                        continue;
                    }
                    entries.push((e.path(), is_dir));
                }
                entries.sort();
                for (p, is_dir) in entries {
                    let rel = rel_dir.join(p.file_name().unwrap_or_default());
                    if is_dir {
                        stack.push((p, rel));
                    } else {
                        out.push((p, rel));
                    }
                }
            }
        } else {
            let rel = PathBuf::from(input.file_name().unwrap_or(input.as_os_str()));
            out.push((input.clone(), rel));
        }
    }
    Ok(out)
}

/// The library's options for `args` (checked: a bad value is a usage error).
pub(crate) fn file_options(args: &PatchArgs) -> Result<polepatch::PatchOptions> {
    check_positive("--chord-tolerance", Some(args.chord_tolerance))?;
    let patch = options(args)?;
    // The name is each file's (files::patch_job sets it).
    let read = args.read.options(polepatch::ReadOptions::default().name)?;
    Ok(polepatch::PatchOptions {
        read,
        patch,
        chord_tolerance_mm: args.chord_tolerance,
        tool: args.tool.options()?,
    })
}

/// A report's warnings, the runs it left and the lines it did not analyse, on standard error
/// (`patch` and `post`).
pub(crate) fn print_warnings(rep: &FileReport) {
    for w in &rep.warnings {
        eprintln!("polepatch: warning: {w}");
    }
    for u in &rep.untouched_runs {
        eprintln!(
            "polepatch: warning: {}: run {}, lines {}–{}: {}",
            rep.file, u.run, u.lines[0], u.lines[1], u.message
        );
    }
    for n in &rep.not_analysed {
        eprintln!(
            "polepatch: warning: {}: not analysed: {}",
            rep.file, n.message
        );
    }
}

pub(crate) fn run(args: PatchArgs) -> Result<ExitCode> {
    let opts = file_options(&args)?;
    let machine = machine(&args.machine)?;
    // Every file this command reads and writes, checked together before anything is
    // written (crate::outputs, docs/output-paths.md).
    let files: Vec<(PathBuf, PathBuf)> = match (&args.output, &args.out_dir) {
        (Some(_), None) => {
            if args.inputs.len() != 1 || (!is_std(&args.inputs[0]) && args.inputs[0].is_dir()) {
                return Err(usage(
                    "-o/--output takes one input file; use --out-dir for several or a folder",
                ));
            }
            vec![(args.inputs[0].clone(), PathBuf::new())]
        }
        (None, Some(dir)) => {
            if args.inputs.iter().any(|p| is_std(p)) {
                return Err(usage("- (standard input) takes -o OUTPUT, not --out-dir"));
            }
            let files = expand(&args.inputs, Some(dir))?;
            if files.is_empty() {
                bail!("no input files");
            }
            files
        }
        _ => return Err(usage("give either -o OUTPUT (one input) or --out-dir DIR")),
    };
    let mut inputs: Vec<Input> = files
        .iter()
        .map(|(input, _)| Input::new("the input", input))
        .collect();
    inputs.extend(crate::machine_input(&args.machine));
    inputs.extend(args.tool.inputs());
    let mut planned: Vec<Output> = Vec::new();
    for (input, rel) in &files {
        planned.push(match (&args.output, &args.out_dir) {
            (Some(o), _) => Output::new("-o", o),
            (_, Some(dir)) => Output::under(input, dir, rel)?,
            _ => unreachable!("checked above"),
        });
    }
    for (flag, path) in [("--report", &args.report), ("--csv", &args.csv)] {
        if let Some(path) = path {
            planned.push(Output::new(flag, path));
        }
    }
    let targets = plan(&inputs, planned)?;
    // With an output on standard output, everything else printed goes to standard error.
    let to_stdout = targets.iter().any(|t| t.is_stdout());
    let mut table: Box<dyn std::io::Write> = if to_stdout {
        Box::new(std::io::stderr())
    } else {
        Box::new(std::io::stdout())
    };
    let names: Vec<PathBuf> = files.iter().map(|(input, _)| input.clone()).collect();
    let reports: Vec<Result<FileReport, JobError>> = if files.len() == 1 && args.output.is_some() {
        vec![patch_job(
            &files[0].0,
            &targets[0],
            &machine,
            &opts,
            args.simulate,
        )]
    } else {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(args.jobs.unwrap_or(0))
            .build()
            .context("starting worker threads")?;
        let bar = if std::io::stderr().is_terminal() && files.len() > 1 {
            let b = ProgressBar::new(files.len() as u64);
            b.set_style(
                ProgressStyle::with_template("{bar:40} {pos}/{len} files {elapsed_precise} {msg}")
                    .expect("valid template"),
            );
            b
        } else {
            ProgressBar::hidden()
        };
        let out = pool.install(|| {
            files
                .par_iter()
                .zip(&targets[..files.len()])
                .map(|((input, _), target)| {
                    let r = patch_job(input, target, &machine, &opts, args.simulate);
                    bar.inc(1);
                    r
                })
                .collect()
        });
        bar.finish_and_clear();
        out
    };
    let mut extra = targets[files.len()..].iter();
    let report_target = args.report.as_ref().and_then(|_| extra.next());
    let csv_target = args.csv.as_ref().and_then(|_| extra.next());

    if args.simulate {
        print_simulated(&reports, &mut table);
    }
    let mut ok: Vec<&FileReport> = Vec::new();
    let mut failed = 0;
    for r in &reports {
        match r {
            Ok(rep) => ok.push(rep),
            Err(e) => {
                failed += 1;
                eprintln!("polepatch: error: {e}");
            }
        }
    }
    if failed < reports.len() {
        print_summary(&names, &reports, machine.c_letter(), &mut table)
            .context("printing the summary")?;
    }
    for rep in &ok {
        print_warnings(rep);
    }
    if let Some(target) = report_target {
        let doc = if ok.len() == 1 && args.output.is_some() {
            serde_json::to_string_pretty(ok[0])?
        } else {
            serde_json::to_string_pretty(&ok)?
        };
        target
            .write(doc.as_bytes(), None)
            .with_context(|| format!("cannot write {}", target.path.display()))?;
    }
    if let Some(target) = csv_target {
        target
            .write(&csv_rows(&ok)?, None)
            .with_context(|| format!("cannot write {}", target.path.display()))?;
    }
    let below: usize = ok.iter().map(|r| r.zones_below_feed()).sum();
    let unknown_tool: usize = ok.iter().map(|r| r.zones_with_unknown_tool()).sum();
    let unanalysed: usize = ok
        .iter()
        .map(|r| r.strict_failures() - r.zones_below_feed() - r.zones_with_unknown_tool())
        .sum();
    let no_tcpm: usize = ok.iter().map(|r| r.runs_left_without_tcpm()).sum();
    if no_tcpm > 0 {
        eprintln!(
            "polepatch: {no_tcpm} run(s) with singular zones left as they are: no TCPM active, \
             X Y Z are machine coordinates (changing rotary words alone would gouge)"
        );
    }
    if failed > 0 {
        if reports.len() > 1 {
            eprintln!(
                "polepatch: {failed} of {} files failed (nothing written for them); the other {} were written",
                reports.len(),
                reports.len() - failed
            );
        }
        return Ok(ExitCode::from(1));
    }
    if args.strict && below + unanalysed + unknown_tool > 0 {
        if below > 0 {
            eprintln!("polepatch: {below} zone(s) stay below feed (--strict)");
        }
        if unanalysed > 0 {
            eprintln!(
                "polepatch: {unanalysed} run(s) near the pole or line range(s) could not be \
                 analysed (see the warnings above): whether they reach feed is unknown (--strict)"
            );
        }
        if unknown_tool > 0 {
            eprintln!(
                "polepatch: {unknown_tool} changed zone(s) with the tool unknown: whether the \
                 cutter stayed on the part cannot be told (--strict; give --tool)"
            );
        }
        return Ok(ExitCode::from(crate::STRICT_EXIT));
    }
    Ok(ExitCode::SUCCESS)
}

fn csv_rows(reports: &[&FileReport]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["file"];
    header.extend(ZoneRow::CSV_COLUMNS);
    w.write_record(&header)?;
    for rep in reports {
        for z in &rep.zones {
            let mut rec = vec![z.file.clone()];
            rec.extend(z.csv_fields());
            w.write_record(&rec)?;
        }
    }
    Ok(w.into_inner()?)
}

/// The summary's lines on the plan over the passes of one file's report: the positioning
/// moves after the runs (they start from the patched end; a re-selected end may turn C
/// further, or less) and the runs started on the other branch.
fn print_plan(rep: &FileReport, out: &mut dyn std::io::Write) -> std::io::Result<()> {
    // The positioning moves after runs whose end is free: they start from the patched
    // end (a re-selected end may turn C further, or less).
    let rapids: Vec<(f64, f64)> = rep
        .zones
        .iter()
        .filter_map(|z| z.rapid_time_before_s.zip(z.rapid_time_after_s))
        .collect();
    if !rapids.is_empty() {
        let (b, a) = rapids
            .iter()
            .fold((0.0, 0.0), |(b, a), &(x, y)| (b + x, a + y));
        writeln!(
            out,
            "  positioning moves after the runs ({}): {b:.3} → {a:.3} s",
            rapids.len()
        )?;
    }
    // The plan (crate::plan): runs that start on the other branch (the positioning
    // move before them rewritten to go there).
    let carried: std::collections::BTreeSet<usize> = rep
        .zones
        .iter()
        .filter(|z| z.start_branch == Some(polepatch::Branch::Other))
        .map(|z| z.run)
        .collect();
    if !carried.is_empty() {
        writeln!(
            out,
            "  runs started on the other branch (the move before each rewritten): {}",
            carried.len()
        )?;
    }
    Ok(())
}

/// One line per input file, in input order; a file that failed says so (its error is
/// printed on standard error).
fn print_summary(
    inputs: &[PathBuf],
    reports: &[Result<FileReport, JobError>],
    pole_letter: char,
    out: &mut dyn std::io::Write,
) -> std::io::Result<()> {
    // The pole axis' ratio, by its letter (C on the built-ins, B on an A-B trunnion).
    writeln!(
        out,
        "{:<40} {:>5} {:>7} {:>15} {:>15} {:>13} {:>8} {:>6} {:>8}  tool",
        "file",
        "zones",
        "reached",
        format!("{pole_letter} ratio"),
        "overall",
        "time s",
        "dev °",
        "points",
        "words",
    )?;
    for (input, r) in inputs.iter().zip(reports) {
        let rep = match r {
            Ok(rep) => rep,
            Err(_) => {
                let name = input.file_name().map_or(input.display().to_string(), |n| {
                    n.to_string_lossy().into_owned()
                });
                writeln!(out, "{name:<40} failed, not written (see the error above)")?;
                continue;
            }
        };
        let reached = rep
            .zones
            .iter()
            .filter(|z| z.outcome == polepatch::Outcome::Reached)
            .count();
        let min =
            |f: &dyn Fn(&ZoneRow) -> f64| rep.zones.iter().map(f).fold(f64::INFINITY, f64::min);
        let sum = |f: &dyn Fn(&ZoneRow) -> f64| rep.zones.iter().map(f).sum::<f64>();
        let name = Path::new(&rep.file)
            .file_name()
            .map_or(rep.file.clone(), |n| n.to_string_lossy().into_owned());
        if rep.zones.is_empty() {
            writeln!(
                out,
                "{name:<40} {:>5} {:>7} {:>15} {:>15} {:>13} {:>8} {:>6} {:>8}  -",
                0, "-", "-", "-", "-", "-", 0, rep.words_changed
            )?;
            continue;
        }
        // The tools the changed zones were patched for (`-`: none changed).
        let mut tools: Vec<String> = Vec::new();
        for z in rep
            .zones
            .iter()
            .filter(|z| z.tool != polepatch::ZoneTool::NotPatched)
        {
            let point = z.tool_point.map_or("-", polepatch::tool::ToolPoint::name);
            let t = format!("{} at {point}", z.tool);
            if !tools.contains(&t) {
                tools.push(t);
            }
        }
        let tools = if tools.is_empty() {
            "-".to_string()
        } else {
            tools.join(", ")
        };
        writeln!(
            out,
            "{:<40} {:>5} {:>7} {:>15} {:>15} {:>13} {:>8.3} {:>6} {:>8}  {}",
            name,
            rep.zones.len(),
            reached,
            format!(
                "{:.3} → {:.3}",
                min(&|z| z.before.c_ratio),
                min(&|z| z.after.c_ratio)
            ),
            format!(
                "{:.3} → {:.3}",
                min(&|z| z.before.overall_ratio),
                min(&|z| z.after.overall_ratio)
            ),
            format!(
                "{:.3} → {:.3}",
                sum(&|z| z.before.time_s),
                sum(&|z| z.after.time_s)
            ),
            rep.zones
                .iter()
                .map(|z| z.max_deviation_deg)
                .fold(0.0, f64::max),
            rep.zones.iter().map(|z| z.points_modified).sum::<usize>(),
            rep.words_changed,
            tools,
        )?;
        // Why each zone ended as it did (a fixed set, docs/user-guide.md), counted in the
        // set's order.
        let counts: Vec<String> = polepatch::ZoneReason::ALL
            .iter()
            .filter_map(|name| {
                let k = rep.zones.iter().filter(|z| z.reason == *name).count();
                (k > 0).then(|| format!("{name} {k}"))
            })
            .collect();
        writeln!(out, "  reasons: {}", counts.join(", "))?;
        print_plan(rep, out)?;
        for (letter, written, file) in [
            ("C", rep.written_c_decimals, rep.file_c_decimals),
            (
                "primary",
                rep.written_primary_decimals,
                rep.file_primary_decimals,
            ),
        ] {
            if let (Some(written), Some(file)) = (written, file)
                && written > file
            {
                writeln!(
                    out,
                    "  note: {letter} written with {written} decimals (the file uses {file}) so that Equation 6 holds on the written values"
                )?;
            }
        }
    }
    Ok(())
}

/// `--simulate`: the simulated times the jobs put in the reports, a line per file.
fn print_simulated(reports: &[Result<FileReport, JobError>], out: &mut dyn std::io::Write) {
    for rep in reports.iter().flatten() {
        if let Some(t) = &rep.simulated {
            let _ = writeln!(
                out,
                "{}: simulated {:.3} s → {:.3} s ({:+.1} %), Equation 6 {:.3} s → {:.3} s",
                rep.file,
                t.before_s,
                t.after_s,
                100.0 * (t.after_s / t.before_s - 1.0),
                t.eq6_before_s,
                t.eq6_after_s
            );
        }
    }
}
