//! `polepatch filter`: a LinuxCNC program filter ([docs/linuxcnc.md](../../../docs/linuxcnc.md)).
//!
//! LinuxCNC's GUIs run the `[FILTER]` program of a file's extension on every program the
//! operator opens, as `sh -c "PROGRAM 'FILE'"`, load what it prints on standard output,
//! show `FILTER_PROGRESS=N` lines (percent) of its standard error as a progress bar, and on
//! a non-zero exit show the operator its standard error instead of loading anything. So:
//! the patched program (byte-identical except the rotary words that change) on standard
//! output, written only once the whole file is patched; progress, the summary and the
//! warnings on standard error; exit 1 on a program or machine polepatch refuses, 2 with
//! `--strict` when a zone stays below feed or a run near the pole could not be analysed.

use crate::{PatchArgs, machine};
use anyhow::{Context, Result};
use polepatch::patcher::PatchOptions;
use polepatch_cli::files;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub(crate) struct FilterArgs {
    /// The NC program LinuxCNC opens (appended by LinuxCNC); `-` for standard input.
    file: PathBuf,
    /// Machine: a built-in name (mikron-ucp710, mikron-hsm600) or a TOML file.
    #[arg(long, short)]
    machine: String,
    /// How the program is read: --feed, --units, --work-offset (as `patch`).
    #[command(flatten)]
    read: crate::ReadArgs,
    /// Singular cone, degrees (as `patch`). Default: a 5° cone and the pole reach.
    #[arg(long)]
    cone: Option<f64>,
    /// Pole reach, degrees (as `patch`). Default 10; with --cone, the cone.
    #[arg(long)]
    pole_reach: Option<f64>,
    /// Largest orientation change allowed at any point, degrees (as `patch`).
    #[arg(long)]
    max_deviation: Option<f64>,
    /// Change C only, never the primary axis (G16's method).
    #[arg(long)]
    only_c: bool,
    /// Refuse the program (exit 2, nothing loaded) if a zone stays below feed or a run
    /// near the pole could not be analysed.
    #[arg(long)]
    strict: bool,
    /// Also write the per-zone report as JSON to this file (replaced on every open).
    #[arg(long)]
    report: Option<PathBuf>,
    /// The cutter and the point X Y Z state (as `patch`).
    #[command(flatten)]
    tool: crate::ToolArgs,
}

impl FilterArgs {
    /// The `patch` arguments these stand for (every other option at its default).
    fn patch_args(&self) -> PatchArgs {
        PatchArgs {
            inputs: vec![self.file.clone()],
            output: Some(PathBuf::from("-")),
            out_dir: None,
            machine: self.machine.clone(),
            report: self.report.clone(),
            csv: None,
            strict: self.strict,
            read: self.read.clone(),
            cone: self.cone,
            pole_reach: self.pole_reach,
            max_deviation: self.max_deviation,
            margin: PatchOptions::default().margin,
            max_decimals: PatchOptions::default().max_decimals,
            max_patch_length: None,
            only_c: self.only_c,
            no_jerk_continuity: false,
            c_offset: false,
            jobs: None,
            simulate: false,
            chord_tolerance: polepatch::machine_frame::CHORD_TOLERANCE_MM,
            tool: self.tool.clone(),
        }
    }
}

pub(crate) fn run(args: FilterArgs) -> Result<ExitCode> {
    let pa = args.patch_args();
    let opts = crate::patch::file_options(&pa)?;
    let machine = machine(&args.machine)?;
    let mut inputs = vec![polepatch_cli::outputs::Input::new("the input", &args.file)];
    inputs.extend(crate::machine_input(&args.machine));
    inputs.extend(args.tool.inputs());
    let report_target = match &args.report {
        Some(p) => Some(
            polepatch_cli::outputs::plan(
                &inputs,
                vec![polepatch_cli::outputs::Output::new("--report", p)],
            )?
            .remove(0),
        ),
        None => None,
    };
    let name = files::shown(&args.file);
    let bytes = files::read(&args.file)?;
    let mut opts = opts;
    opts.read.name = name;
    // Progress in whole percent, each value once, as LinuxCNC reads it.
    let last = Mutex::new(None::<usize>);
    let progress = |done: usize, total: usize| {
        let pct = (done * 100).checked_div(total).unwrap_or(100).min(100);
        let mut last = last.lock().unwrap_or_else(|p| p.into_inner());
        if *last != Some(pct) {
            *last = Some(pct);
            eprintln!("FILTER_PROGRESS={pct}");
        }
    };
    progress(0, 1);
    let hooks = polepatch::Hooks {
        progress: &progress,
        cancelled: &|| false,
    };
    // The whole output first: a program refused half-way prints nothing.
    let mut output = Vec::with_capacity(bytes.len());
    let report = polepatch::patch_nc_hooked(&bytes, &machine, &opts, &mut output, hooks)?;
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(&output)
        .and_then(|()| stdout.flush())
        .context("writing the patched program to standard output")?;
    summary(&report);
    if let Some(target) = report_target {
        let doc = serde_json::to_string_pretty(&report)?;
        target
            .write(doc.as_bytes(), None)
            .with_context(|| format!("cannot write {}", target.path.display()))?;
    }
    let below = report.zones_below_feed();
    let unknown_tool = report.zones_with_unknown_tool();
    let unanalysed = report.strict_failures() - below - unknown_tool;
    if args.strict && below + unanalysed + unknown_tool > 0 {
        eprintln!(
            "polepatch: {}: refused (--strict): {below} zone(s) stay below feed, {unanalysed} run(s) or line range(s) near the pole could not be analysed, {unknown_tool} changed zone(s) with the tool unknown",
            report.file
        );
        return Ok(ExitCode::from(crate::STRICT_EXIT));
    }
    Ok(ExitCode::SUCCESS)
}

/// What the operator's terminal shows: one line for the file, then every warning.
fn summary(rep: &polepatch::FileReport) {
    if rep.zones.is_empty() {
        eprintln!(
            "polepatch: {}: no singular zone on {}; program unchanged",
            rep.file, rep.machine
        );
    } else {
        let reached = rep
            .zones
            .iter()
            .filter(|z| z.outcome == polepatch::Outcome::Reached)
            .count();
        let before: f64 = rep.zones.iter().map(|z| z.before.time_s).sum();
        let after: f64 = rep.zones.iter().map(|z| z.after.time_s).sum();
        let dev = rep
            .zones
            .iter()
            .map(|z| z.max_deviation_deg)
            .fold(0.0, f64::max);
        eprintln!(
            "polepatch: {}: {} singular zone(s) on {}, {reached} reach the programmed feed; \
             estimated time over them {before:.3} s → {after:.3} s; largest change of tool \
             orientation {dev:.3}°; {} word(s) changed",
            rep.file,
            rep.zones.len(),
            rep.machine,
            rep.words_changed
        );
    }
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
    let no_tcpm = rep.runs_left_without_tcpm();
    if no_tcpm > 0 {
        eprintln!(
            "polepatch: {no_tcpm} run(s) with singular zones left as they are: no TCPM active, \
             X Y Z are machine coordinates (a LinuxCNC machine whose kinematics are always TCP \
             says `tcpm_always = true` under [controller]; docs/linuxcnc.md)"
        );
    }
}
