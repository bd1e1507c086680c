//! `polepatch verify ORIGINAL PATCHED`: the patched program held against its original
//! ([`polepatch::verify`]), whoever wrote it.

use crate::{PatchArgs, machine};
use anyhow::Result;
use polepatch_cli::files;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub(crate) struct VerifyArgs {
    /// The program as it was (the input of `patch`, or the post before a re-post).
    original: PathBuf,
    /// The program to check against it.
    patched: PathBuf,
    /// Machine: a built-in name (mikron-ucp710, mikron-hsm600) or a TOML file.
    #[arg(long, short)]
    machine: String,
    /// Print one JSON document instead of the lines.
    #[arg(long)]
    json: bool,
    /// How the programs are read: --feed, --units, --work-offset (as `patch`).
    #[command(flatten)]
    read: crate::ReadArgs,
    /// Pole reach, degrees: the safety bound on the orientation change (as `patch`).
    #[arg(long)]
    pole_reach: Option<f64>,
    /// Singular cone, degrees (as `patch`).
    #[arg(long)]
    cone: Option<f64>,
    /// Largest orientation change allowed at any point, degrees (as `patch`).
    #[arg(long)]
    max_deviation: Option<f64>,
    /// The cutter and the point X Y Z state (as `patch`): give them as `patch` was given.
    #[command(flatten)]
    tool: crate::ToolArgs,
}

impl VerifyArgs {
    /// The `patch` arguments these stand for: the options are read as `patch` reads them.
    fn patch_args(&self) -> PatchArgs {
        PatchArgs {
            inputs: vec![self.original.clone()],
            output: None,
            out_dir: None,
            machine: self.machine.clone(),
            report: None,
            csv: None,
            strict: false,
            read: self.read.clone(),
            cone: self.cone,
            pole_reach: self.pole_reach,
            max_deviation: self.max_deviation,
            margin: polepatch::patcher::PatchOptions::default().margin,
            max_decimals: polepatch::patcher::PatchOptions::default().max_decimals,
            max_patch_length: None,
            only_c: false,
            no_jerk_continuity: false,
            c_offset: false,
            jobs: None,
            simulate: false,
            chord_tolerance: polepatch::machine_frame::CHORD_TOLERANCE_MM,
            tool: self.tool.clone(),
        }
    }
}

pub(crate) fn run(args: VerifyArgs) -> Result<ExitCode> {
    let mut opts = crate::patch::file_options(&args.patch_args())?;
    let machine = machine(&args.machine)?;
    let original = files::read(&args.original)?;
    let patched = files::read(&args.patched)?;
    opts.read.name = args.patched.display().to_string();
    let report = polepatch::verify::verify_nc(
        &original,
        &patched,
        &machine,
        &opts,
        &args.original.display().to_string(),
    )?;
    let mut out = std::io::stdout().lock();
    if args.json {
        serde_json::to_writer_pretty(&mut out, &report)?;
        writeln!(out)?;
    } else {
        for v in &report.violations {
            let at = if v.line > 0 {
                format!("{}:{}", report.patched, v.line)
            } else {
                report.patched.clone()
            };
            writeln!(out, "{at}: {}: {}", v.check.name(), v.message)?;
        }
        writeln!(
            out,
            "{}: {} against {} on {}: {} lines, {} changed, {} moves with new values; largest \
             reference-point shift {:.4} mm, largest orientation change {:.4}°; {} runs and {} \
             positioning moves compared, {:.3} s → {:.3} s",
            if report.passed() {
                "verified"
            } else {
                "NOT verified"
            },
            report.patched,
            report.original,
            report.machine,
            report.lines,
            report.lines_changed,
            report.moves_changed,
            report.max_reference_shift_mm,
            report.max_deviation_deg,
            report.runs_compared,
            report.positioning_moves_compared,
            report.time_before_s,
            report.time_after_s,
        )?;
    }
    out.flush()?;
    Ok(if report.passed() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
