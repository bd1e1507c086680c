//! `polepatch patch`: one file or a batch.

use crate::{PatchArgs, check_positive, machine};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use polepatch::patcher::{PatchAxes, PatchOptions};
use polepatch::{FileReport, ZoneRow};
use polepatch_cli::files::{JobError, patch_file, write_atomic};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn options(args: &PatchArgs) -> Result<PatchOptions> {
    check_positive("--cone", Some(args.cone))?;
    if let Some(d) = args.max_deviation
        && !(d.is_finite() && d >= 0.0)
    {
        bail!("--max-deviation must be an angle ≥ 0°, got {d}");
    }
    check_positive("--feed", args.feed)?;
    check_positive("--max-patch-length", args.max_patch_length)?;
    if !(0.0..0.5).contains(&args.margin) {
        bail!("--margin must be in [0, 0.5), got {}", args.margin);
    }
    if args.max_decimals > 9 {
        bail!(
            "--max-decimals must be at most 9, got {}",
            args.max_decimals
        );
    }
    Ok(PatchOptions {
        cone_deg: args.cone,
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
    })
}

/// Files named on the command line; folders expand to the files in them (recursively,
/// skipping hidden entries), each with its path relative to the folder's parent.
fn expand(inputs: &[PathBuf]) -> Result<Vec<(PathBuf, PathBuf)>> {
    let mut out = Vec::new();
    for input in inputs {
        if input.is_dir() {
            let base = input.parent().unwrap_or(Path::new(""));
            let mut stack = vec![input.clone()];
            while let Some(dir) = stack.pop() {
                let mut entries: Vec<_> = std::fs::read_dir(&dir)
                    .with_context(|| format!("cannot read folder {}", dir.display()))?
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|p| {
                        !p.file_name()
                            .is_some_and(|n| n.to_string_lossy().starts_with('.'))
                    })
                    .collect();
                entries.sort();
                for p in entries {
                    if p.is_dir() {
                        stack.push(p);
                    } else {
                        let rel = p.strip_prefix(base).unwrap_or(&p).to_path_buf();
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

pub(crate) fn run(args: PatchArgs) -> Result<ExitCode> {
    let opts = polepatch::PatchOptions {
        patch: options(&args)?,
        feed_fallback_mm_min: args.feed,
        work_offset_mm: args.work_offset,
        ..polepatch::PatchOptions::default()
    };
    let machine = machine(&args.machine)?;
    for (flag, path) in [("--report", &args.report), ("--csv", &args.csv)] {
        if let Some(path) = path {
            for input in &args.inputs {
                if input.is_file() && polepatch_cli::files::same_file(input, path) {
                    bail!(
                        "{flag} {} is the input file; polepatch never modifies its input",
                        path.display()
                    );
                }
            }
        }
    }
    let mut names: Vec<PathBuf> = Vec::new();
    let reports: Vec<Result<FileReport, JobError>> = match (&args.output, &args.out_dir) {
        (Some(output), None) => {
            if args.inputs.len() != 1 || args.inputs[0].is_dir() {
                bail!("-o/--output takes one input file; use --out-dir for several or a folder");
            }
            names.push(args.inputs[0].clone());
            vec![patch_file(&args.inputs[0], output, &machine, &opts)]
        }
        (None, Some(dir)) => {
            let files = expand(&args.inputs)?;
            if files.is_empty() {
                bail!("no input files");
            }
            names = files.iter().map(|(input, _)| input.clone()).collect();
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(args.jobs.unwrap_or(0))
                .build()
                .context("starting worker threads")?;
            let bar = if std::io::stderr().is_terminal() && files.len() > 1 {
                let b = ProgressBar::new(files.len() as u64);
                b.set_style(
                    ProgressStyle::with_template(
                        "{bar:40} {pos}/{len} files {elapsed_precise} {msg}",
                    )
                    .expect("valid template"),
                );
                b
            } else {
                ProgressBar::hidden()
            };
            let out = pool.install(|| {
                files
                    .par_iter()
                    .map(|(input, rel)| {
                        let output = dir.join(rel);
                        if let Some(parent) = output.parent() {
                            std::fs::create_dir_all(parent).map_err(|cause| JobError::Write {
                                path: parent.display().to_string(),
                                cause,
                            })?;
                        }
                        let r = patch_file(input, &output, &machine, &opts);
                        bar.inc(1);
                        r
                    })
                    .collect()
            });
            bar.finish_and_clear();
            out
        }
        _ => bail!("give either -o OUTPUT (one input) or --out-dir DIR"),
    };

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
        print_summary(&names, &reports);
    }
    for rep in &ok {
        for w in &rep.warnings {
            eprintln!("polepatch: warning: {w}");
        }
        for u in &rep.untouched_runs {
            eprintln!(
                "polepatch: warning: {}: run {}, lines {}–{}: {}",
                rep.file, u.run, u.lines[0], u.lines[1], u.message
            );
        }
    }
    if let Some(path) = &args.report {
        let doc = if ok.len() == 1 && args.output.is_some() {
            serde_json::to_string_pretty(ok[0])?
        } else {
            serde_json::to_string_pretty(&ok)?
        };
        write_atomic(path, doc.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.csv {
        write_atomic(path, &csv_rows(&ok)?)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let below: usize = ok.iter().map(|r| r.zones_below_feed()).sum();
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
    if args.strict && below > 0 {
        eprintln!("polepatch: {below} zone(s) stay below feed (--strict)");
        return Ok(ExitCode::from(2));
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

/// One line per input file, in input order; a file that failed says so (its error is
/// printed on standard error).
fn print_summary(inputs: &[PathBuf], reports: &[Result<FileReport, JobError>]) {
    println!(
        "{:<40} {:>5} {:>7} {:>15} {:>15} {:>13} {:>8} {:>6} {:>8}",
        "file", "zones", "reached", "C ratio", "overall", "time s", "dev °", "points", "words"
    );
    for (input, r) in inputs.iter().zip(reports) {
        let rep = match r {
            Ok(rep) => rep,
            Err(_) => {
                let name = input.file_name().map_or(input.display().to_string(), |n| {
                    n.to_string_lossy().into_owned()
                });
                println!("{name:<40} failed, not written (see the error above)");
                continue;
            }
        };
        let reached = rep.zones.iter().filter(|z| z.outcome == "reached").count();
        let min =
            |f: &dyn Fn(&ZoneRow) -> f64| rep.zones.iter().map(f).fold(f64::INFINITY, f64::min);
        let sum = |f: &dyn Fn(&ZoneRow) -> f64| rep.zones.iter().map(f).sum::<f64>();
        let name = Path::new(&rep.file)
            .file_name()
            .map_or(rep.file.clone(), |n| n.to_string_lossy().into_owned());
        if rep.zones.is_empty() {
            println!(
                "{name:<40} {:>5} {:>7} {:>15} {:>15} {:>13} {:>8} {:>6} {:>8}",
                0, "-", "-", "-", "-", "-", 0, rep.words_changed
            );
            continue;
        }
        println!(
            "{:<40} {:>5} {:>7} {:>15} {:>15} {:>13} {:>8.3} {:>6} {:>8}",
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
        );
        // Why each zone ended as it did (a fixed set, docs/user-guide.md), counted.
        let counts: Vec<String> = polepatch::patcher::Reason::ALL
            .iter()
            .filter_map(|r| {
                let k = rep.zones.iter().filter(|z| z.reason == r.name()).count();
                (k > 0).then(|| format!("{} {k}", r.name()))
            })
            .collect();
        println!("  reasons: {}", counts.join(", "));
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
                println!(
                    "  note: {letter} written with {written} decimals (the file uses {file}) so that Equation 6 holds on the written values"
                );
            }
        }
    }
}
