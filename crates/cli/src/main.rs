//! The `polepatch` command line.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use polepatch::Piece;
use polepatch::kinematics::{Axis, Machine};
use polepatch::patcher::{AnalysisOptions, PatchOptions};
use polepatch::report::{AnalyzeReport, LimitKind, axis_letter, limit_name};
use polepatch_cli::files;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "polepatch",
    version,
    about = "Find and patch the places where the C axis slows a table-table 5-axis machine near the pole"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Report where and why the machine slows down (Equation 6 along every G1 run).
    Analyze(AnalyzeArgs),
    /// Rewrite the rotary words near the pole so that both rotary axes reach the programmed
    /// feed (re-selecting the IK branch where that suffices, else the smallest change of
    /// tool orientation); `--only-c` keeps the primary axis (G16's method).
    Patch(PatchArgs),
    /// Post a CL file (APT or CSV x,y,z,i,j,k) as a TCPM program for a machine, with pole
    /// handling (the same patch as `patch`, unless --no-patch).
    Post(post_cmd::PostArgs),
    /// Tilt the workpiece on a jig (C17's avoidance): given angles, or the smallest tilt
    /// that makes the program reach feed on both rotary axes.
    Reorient(reorient_cmd::ReorientArgs),
    /// The cycle time a jerk-limited controller would take, per run, next to Equation 6's
    /// estimate and L/F; the trajectory (CSV) and the feed along s (SVG), before and after.
    Simulate(simulate_cmd::SimulateArgs),
    /// Quality suite: analyze and patch every program × machine, compare the deviation
    /// with the best possible for C-only changes, and print one table.
    Bench(bench_cmd::BenchArgs),
    /// LinuxCNC program filter ([FILTER] in the INI): the patched program on standard
    /// output, FILTER_PROGRESS=N and the summary on standard error (docs/linuxcnc.md).
    Filter(filter_cmd::FilterArgs),
    /// Hold a patched program against its original: line for line, the tool's reference
    /// point (a ball's centre), positioning targets, orientation changes, Equation 6 and
    /// the estimated time of every run; exit 1 naming each line that does not hold.
    Verify(verify_cmd::VerifyArgs),
}

/// Exit status with `--strict` when a zone stays below feed or something near the pole
/// could not be analysed.
pub(crate) const STRICT_EXIT: u8 = 2;
/// Exit status of a usage error (an unknown option, a missing or bad value): 64, as
/// sysexits.h's `EX_USAGE`, apart from `--strict`'s 2 and bad input's 1.
pub(crate) const USAGE_EXIT: u8 = 64;

/// A usage error (exit [`USAGE_EXIT`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub(crate) struct Usage(String);

/// A usage error with this message.
pub(crate) fn usage(message: impl Into<String>) -> anyhow::Error {
    Usage(message.into()).into()
}

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub(crate) struct PatchArgs {
    /// NC programs, or folders of them (with --out-dir).
    #[arg(required = true)]
    pub(crate) inputs: Vec<PathBuf>,
    /// Output file (one input).
    #[arg(long, short, conflicts_with = "out_dir")]
    pub(crate) output: Option<PathBuf>,
    /// Output folder (any number of inputs; each output keeps its file name).
    #[arg(long)]
    pub(crate) out_dir: Option<PathBuf>,
    /// Machine: a built-in name (mikron-ucp710, mikron-hsm600) or a TOML file.
    #[arg(long, short)]
    pub(crate) machine: String,
    /// Write the per-zone report as JSON to this file.
    #[arg(long)]
    pub(crate) report: Option<PathBuf>,
    /// Write the per-zone rows of every file as CSV to this file.
    #[arg(long)]
    pub(crate) csv: Option<PathBuf>,
    /// Exit with status 2 if any zone stays below feed, or a run near the pole could not
    /// be analysed (no feed, invalid values).
    #[arg(long)]
    pub(crate) strict: bool,
    /// How the program is read: --feed, --units, --work-offset.
    #[command(flatten)]
    pub(crate) read: ReadArgs,
    /// A fixed singular cone, degrees: a stretch where C is below feed is a zone when its
    /// primary axis comes within it, and no other. Default: a 5° cone, and out to
    /// --pole-reach the stretches whose slowdown the pole dominates (docs/method.md).
    #[arg(long)]
    pub(crate) cone: Option<f64>,
    /// Pole reach, degrees: out to here a stretch where C is below feed is a zone when the
    /// pole accounts for at least half its slowdown. Default 10; with --cone, the cone.
    #[arg(long)]
    pub(crate) pole_reach: Option<f64>,
    /// Largest orientation change allowed at any point, degrees, on the exact angle of the
    /// written words (default: no limit; the change is always minimised). A cap at or above
    /// what the default achieves changes nothing.
    #[arg(long)]
    pub(crate) max_deviation: Option<f64>,
    /// Safety margin on the rotary axes' limits the solvers aim at, as a fraction (what is
    /// verified is Equation 6 on the written values, without margin).
    #[arg(long, default_value_t = PatchOptions::default().margin)]
    pub(crate) margin: f64,
    /// Most decimal places to write for the rotary words when the file's precision cannot
    /// hold Equation 6.
    #[arg(long, default_value_t = PatchOptions::default().max_decimals)]
    pub(crate) max_decimals: usize,
    /// Longest patch, mm (default: up to the whole run; both methods hold to it).
    #[arg(long)]
    pub(crate) max_patch_length: Option<f64>,
    /// Change C only, never the primary axis (G16's method). Default: both rotary axes may
    /// change (re-selecting the IK branch where that suffices), so that both reach feed.
    #[arg(long)]
    pub(crate) only_c: bool,
    /// With --only-c: do not ask for third-derivative continuity at G16's joins.
    #[arg(long, requires = "only_c")]
    pub(crate) no_jerk_continuity: bool,
    /// With --only-c: allow a 360° multiple offset of C after a zone when it shortens G16's
    /// join (off by default: the move after the run would then turn C the extra revolution
    /// back; the default method re-selects the branch instead).
    #[arg(long, requires = "only_c")]
    pub(crate) c_offset: bool,
    /// Worker threads for batches (default: all cores).
    #[arg(long)]
    pub(crate) jobs: Option<usize>,
    /// Simulate the input and the output (`polepatch simulate`) and put the cycle times
    /// before and after in the report and the summary (takes about as long as
    /// simulating both).
    #[arg(long)]
    pub(crate) simulate: bool,
    /// With a kinematic chain, for runs without TCPM: how far the tool tip may leave the
    /// programmed line between two points of a rewritten block, mm (the controller
    /// interpolates every axis linearly there); a run that would exceed it — and its
    /// original block — keeps its values.
    #[arg(long, value_name = "MM", default_value_t = polepatch::machine_frame::CHORD_TOLERANCE_MM)]
    pub(crate) chord_tolerance: f64,
    /// The cutter and the point X Y Z state.
    #[command(flatten)]
    pub(crate) tool: ToolArgs,
}

/// How a program is read: one group of flags, declared once, which every subcommand that
/// reads an NC program flattens into its arguments (`patch`, `analyze`, `simulate`,
/// `verify`, `filter`); [`ReadArgs::options`] makes the library's [`polepatch::ReadOptions`]
/// of them once.
#[derive(clap::Args, Clone, Default)]
#[command(allow_negative_numbers = true)]
pub(crate) struct ReadArgs {
    /// Feed in mm/min for runs with no F in force.
    #[arg(long)]
    pub(crate) feed: Option<f64>,
    /// Units of a program that states none (no G20/G21, G70/G71, BEGIN PGM … MM|INCH):
    /// nothing in the file tells inches from mm, so say it (default mm; the report says
    /// which was assumed).
    #[arg(long, value_enum)]
    pub(crate) units: Option<UnitsArg>,
    /// Work offset X,Y,Z (mm, machine coordinates of the program's zero) for a machine
    /// with a kinematic chain, where the program only names it (G54); default: the
    /// program's datum shift (Heidenhain G54 X Y Z).
    #[arg(long, value_parser = parse_xyz, value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub(crate) work_offset: Option<[f64; 3]>,
}

impl ReadArgs {
    /// The library's reading options for an input called `name` (`--feed` checked: a bad
    /// value is a usage error).
    pub(crate) fn options(&self, name: String) -> Result<polepatch::ReadOptions> {
        check_positive("--feed", self.feed)?;
        Ok(polepatch::ReadOptions {
            name,
            feed_fallback_mm_min: self.feed,
            work_offset_mm: self.work_offset,
            inch: self.units == Some(UnitsArg::Inch),
        })
    }
}

/// The cutter and the point of it X Y Z state: one group of flags, declared once, which
/// `patch`, `post` and `filter` flatten into their arguments.
#[derive(clap::Args, Clone)]
pub(crate) struct ToolArgs {
    /// The cutter for the whole program: ball:D, flat:D or bull:D,R (diameter and corner
    /// radius, mm). Default: per run, from --tools or the program (TOOL DEF, CAM tool
    /// comments; a CL file's CUTTER/ or TLDATA/); a ball programmed at its tip keeps its
    /// centre (X Y Z rewritten), a flat or bull-nose cutter's orientation change is capped
    /// by --surface-tolerance.
    #[arg(long, value_parser = polepatch::tool::Tool::parse, value_name = "KIND:D[,R]")]
    pub(crate) tool: Option<polepatch::tool::Tool>,
    /// A tool table (TOML: [tool.5] kind = "ball", diameter_mm = 10, corner_radius_mm = …),
    /// looked up by the number or name of the tool each run uses.
    #[arg(long, value_name = "FILE")]
    pub(crate) tools: Option<PathBuf>,
    /// Which point of the tool the program's X Y Z are: tip or centre (of a ball).
    /// Default: the machine file's [controller] tool_point, else the TCPM code's (M128 and
    /// FUNCTION TCPM … REFPNT CENTER-CENTER: centre; the others: tip); for `post`, the tip
    /// (a CL file states the tool tip).
    #[arg(long, value_parser = polepatch::tool::ToolPoint::parse, value_name = "tip|centre")]
    pub(crate) tool_point: Option<polepatch::tool::ToolPoint>,
    /// How far a flat or bull-nose cutter's surface may move at a CL point when the patch
    /// turns it about its tip, mm.
    #[arg(long, value_name = "MM", default_value_t = polepatch::tool::SURFACE_TOLERANCE_MM)]
    pub(crate) surface_tolerance: f64,
}

impl ToolArgs {
    /// The library's tool options: the tool table read from its file, the surface
    /// tolerance checked (a bad value is a usage error).
    pub(crate) fn options(&self) -> Result<polepatch::tool::ToolOptions> {
        check_positive("--surface-tolerance", Some(self.surface_tolerance))?;
        let table = match &self.tools {
            Some(path) => {
                let bytes = files::read(path)?;
                let text = String::from_utf8(bytes).map_err(|_| {
                    anyhow::anyhow!("tool table {}: not UTF-8 text", path.display())
                })?;
                polepatch::tool::ToolTable::from_toml_str(&text, &path.display().to_string())
                    .map_err(|e| anyhow::anyhow!("{e}"))?
            }
            None => polepatch::tool::ToolTable::default(),
        };
        Ok(polepatch::tool::ToolOptions {
            tool: self.tool,
            table,
            point: self.tool_point,
            surface_tolerance_mm: self.surface_tolerance,
            ..polepatch::tool::ToolOptions::default()
        })
    }

    /// The file these flags make the command read (the tool table), for the output-path
    /// checks.
    pub(crate) fn inputs(&self) -> Vec<polepatch_cli::outputs::Input> {
        self.tools
            .iter()
            .map(|t| polepatch_cli::outputs::Input::new("the tool table", t))
            .collect()
    }
}

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
struct AnalyzeArgs {
    /// NC program (Heidenhain ISO, Sinumerik or Fanuc G-code).
    file: PathBuf,
    /// Machine: a built-in name (mikron-ucp710, mikron-hsm600) or a TOML file.
    #[arg(long, short)]
    machine: String,
    /// How the program is read: --feed, --units, --work-offset.
    #[command(flatten)]
    read: ReadArgs,
    /// A fixed singular cone, degrees (see `patch`). Default: a 5° cone and the pole reach.
    #[arg(long)]
    cone: Option<f64>,
    /// Pole reach, degrees (see `patch`). Default 10; with --cone, the cone.
    #[arg(long)]
    pole_reach: Option<f64>,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    json: bool,
    /// Exit with status 2 when a run or lines could not be analysed (no feed, expressions,
    /// arcs or skippable blocks near the pole, …).
    #[arg(long)]
    strict: bool,
}

/// `X,Y,Z` as three finite numbers.
pub(crate) fn parse_xyz(text: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("'{text}': {e}; expected X,Y,Z in mm, e.g. -30.5,-4.3,38"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([x, y, z]),
        _ => Err(format!(
            "'{text}': expected three finite numbers X,Y,Z in mm, e.g. -30.5,-4.3,38"
        )),
    }
}

fn main() -> ExitCode {
    polepatch_cli::outputs::remove_temporaries_on_signal();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // Help and version are printed to standard output and exit 0; a usage error
            // exits USAGE_EXIT (not clap's 2, which is --strict's).
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(USAGE_EXIT)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    let result = match cli.command {
        Command::Analyze(args) => analyze(args),
        Command::Patch(args) => patch::run(args),
        Command::Bench(args) => bench_cmd::run(args),
        Command::Reorient(args) => reorient_cmd::run(args),
        Command::Post(args) => post_cmd::run(args),
        Command::Simulate(args) => simulate_cmd::run(args),
        Command::Filter(args) => filter_cmd::run(args),
        Command::Verify(args) => verify_cmd::run(args),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("polepatch: error: {}", message(&e));
            if e.downcast_ref::<Usage>().is_some() {
                ExitCode::from(USAGE_EXIT)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// An error and its causes, `: `-separated, each cause once: a cause whose text the message
/// already holds (an error that quotes its source) is not repeated.
fn message(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if !text.contains(&part) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&part);
        }
    }
    text
}

mod bench_cmd;
mod filter_cmd;
mod lcnc_planner;
mod patch;
mod post_cmd;
mod reorient_cmd;
mod simulate_cmd;
mod verify_cmd;

/// `--units`: what a program that states no units is read in.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum UnitsArg {
    /// Millimetres (G21, G71, G71).
    Mm,
    /// Inches (G20, G700; not for Heidenhain).
    Inch,
}

/// The files a command reads besides its programs: the machine file, when `--machine`
/// names one rather than a built-in.
pub(crate) fn machine_input(name: &str) -> Vec<polepatch_cli::outputs::Input> {
    if polepatch::kinematics::Machine::builtin(name).is_some() {
        Vec::new()
    } else {
        vec![polepatch_cli::outputs::Input::new("the machine file", name)]
    }
}

pub(crate) fn machine(name: &str) -> Result<Machine> {
    let machine = Machine::load(name)?;
    // What the loader assumed (a LinuxCNC INI without jerk limits, …).
    for w in &machine.warnings {
        eprintln!("polepatch: warning: {w}");
    }
    Ok(machine)
}

/// `--tcy-ms` within the range a machine file accepts (`kinematics::machine::TCY_MS_RANGE`).
pub(crate) fn check_tcy_ms(v: Option<f64>) -> Result<()> {
    if let Some(v) = v {
        polepatch::kinematics::machine::check_tcy_ms("--tcy-ms", v).map_err(usage)?;
    }
    Ok(())
}

/// The cone and the pole reach of `--cone` and `--pole-reach`: the defaults, or a fixed
/// cone (the reach equal to it) unless the reach is given too.
/// The cone and the pole reach of `--cone` and `--pole-reach` (the reach is the cone's
/// when only `--cone` is given), checked by the patcher's rule set
/// ([`AnalysisOptions::validate`]).
pub(crate) fn cone_and_reach(cone: Option<f64>, reach: Option<f64>) -> Result<(f64, f64)> {
    let d = AnalysisOptions::default();
    let a = AnalysisOptions {
        cone_deg: cone.unwrap_or(d.cone_deg),
        pole_reach_deg: reach.or(cone).unwrap_or(d.pole_reach_deg),
        ..d
    };
    a.validate().map_err(option_error)?;
    Ok((a.cone_deg, a.pole_reach_deg))
}

/// The command line's flag for a field of the patcher's options.
pub(crate) fn flag(field: polepatch::patcher::OptionField) -> &'static str {
    use polepatch::patcher::OptionField as F;
    match field {
        F::ConeDeg => "--cone",
        F::PoleReachDeg => "--pole-reach",
        F::MaxDeviationDeg => "--max-deviation",
        F::TcyS => "--tcy-ms",
        F::Margin => "--margin",
        F::ThirdDerivativeContinuity => "--no-jerk-continuity",
        F::MaxDecimals => "--max-decimals",
        F::MaxPatchLengthMm => "--max-patch-length",
        F::AllowCOffset => "--c-offset",
        F::KeepCentreRadiusMm => "--tool",
        F::KeepCentreUnitMm => "--units",
    }
}

/// The patcher's refusal of an option as a usage error naming the flag.
pub(crate) fn option_error(e: polepatch::patcher::OptionsError) -> anyhow::Error {
    usage(e.message(flag(e.field)))
}

pub(crate) fn check_positive(name: &str, v: Option<f64>) -> Result<()> {
    if let Some(v) = v
        && !(v.is_finite() && v > 0.0)
    {
        return Err(usage(format!("{name} must be a positive number, got {v}")));
    }
    Ok(())
}

fn analyze(args: AnalyzeArgs) -> Result<ExitCode> {
    let name = args.file.display().to_string();
    let read = args.read.options(name.clone())?;
    let (cone_deg, pole_reach_deg) = cone_and_reach(args.cone, args.pole_reach)?;
    let machine = machine(&args.machine)?;
    let opts = polepatch::AnalyzeOptions {
        read,
        analysis: AnalysisOptions {
            cone_deg,
            pole_reach_deg,
            ..AnalysisOptions::default()
        },
    };
    let bytes = files::read(&args.file)?;
    let args_strict = args.strict;
    // The report is printed as each run is analysed (a program of many runs has a report
    // larger than itself): the header first, then the runs in file order.
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let mut head: Option<AnalyzeReport> = None;
    let mut failed: Vec<polepatch::report::RunReport> = Vec::new();
    let mut runs = 0usize;
    let json = args.json;
    polepatch::analyze_nc_each(&bytes, &machine, &opts, &mut |piece| match piece {
        Piece::Head(h) => {
            head = Some(h.clone());
            if json {
                // `to_string_pretty` of the whole report, written in pieces.
                let text = serde_json::to_string_pretty(h)?;
                let open = text.strip_suffix("[]\n}").unwrap_or(&text);
                write!(out, "{open}[")
            } else {
                writeln!(
                    out,
                    "{} on {} (singular cone {}°, pole reach {}°)",
                    h.file, h.machine, h.cone_deg, h.pole_reach_deg
                )
            }
        }
        Piece::Run(r) => {
            if json {
                let text = serde_json::to_string_pretty(&r)?;
                let sep = if runs == 0 { "\n" } else { ",\n" };
                let indented: Vec<String> = text.lines().map(|l| format!("    {l}")).collect();
                write!(out, "{sep}{}", indented.join("\n"))?;
            } else {
                let primary = head.as_ref().map_or(b'A', |h| h.primary.as_bytes()[0]);
                let letters = polepatch::nc::RotaryLetters {
                    tilt: primary,
                    pole: machine.c_letter() as u8,
                };
                print_run(&mut out, &r, letters, machine.standard_form().is_some())?;
            }
            runs += 1;
            if r.error.is_some() {
                failed.push(*r);
            }
            Ok(())
        }
    })?;
    if json {
        if runs == 0 {
            writeln!(out, "]\n}}")?;
        } else {
            writeln!(out, "\n  ]\n}}")?;
        }
    }
    out.flush().context("writing the report")?;
    drop(out);
    let Some(report) = head else {
        anyhow::bail!("no report");
    };
    for w in &report.warnings {
        eprintln!("polepatch: warning: {w}");
    }
    for r in &failed {
        eprintln!(
            "polepatch: {}: run {} (lines {}–{}) not analysed: {}",
            report.file,
            r.run,
            r.lines[0],
            r.lines[1],
            r.error.as_deref().unwrap_or("")
        );
    }
    for n in &report.not_analysed {
        eprintln!("polepatch: {}: not analysed: {}", report.file, n.message);
    }
    // The file was read: runs or lines that could not be analysed are listed, and fail
    // only with --strict (as for `patch`).
    let failures = failed.len() + report.not_analysed.len();
    Ok(if args_strict && failures > 0 {
        eprintln!("polepatch: {failures} run(s) or line range(s) not analysed (--strict)");
        ExitCode::from(crate::STRICT_EXIT)
    } else {
        ExitCode::SUCCESS
    })
}

/// One run of `analyze`'s table.
fn print_run(
    out: &mut impl Write,
    r: &polepatch::report::RunReport,
    letters: polepatch::nc::RotaryLetters,
    standard: bool,
) -> std::io::Result<()> {
    {
        let feed = r.feed_mm_min.map_or("no F".to_string(), |f| {
            format!("F{}", polepatch::report::feed_text(f))
        });
        // A pass whose blocks have their own F: the reference and the range.
        let feed = match r.block_feeds_mm_min {
            Some([lo, hi]) => format!(
                "{feed} (the blocks' own F{}–{})",
                polepatch::report::feed_text(lo),
                polepatch::report::feed_text(hi)
            ),
            None => feed,
        };
        writeln!(
            out,
            "\nrun {}: lines {}–{}, {} points, {:.3} mm at {}",
            r.run, r.lines[0], r.lines[1], r.points, r.length_mm, feed
        )?;
        let Some(f) = &r.figures else {
            writeln!(out, "  not analysed: {}", r.error.as_deref().unwrap_or(""))?;
            return Ok(());
        };
        match &f.limiting_axis {
            Some(axis) => writeln!(
                out,
                "  min feed ratio {:.3}: {} {} limit at line {} (s = {:.3} mm)",
                f.min_ratio,
                axis,
                match f.limiting_limit {
                    LimitKind::Velocity => "velocity",
                    LimitKind::Acceleration => "acceleration",
                    LimitKind::Jerk | LimitKind::Feed => "jerk",
                },
                f.min_at_line,
                f.min_at_s_mm
            ),
            None => writeln!(out, "  reaches the programmed feed everywhere"),
        }?;
        writeln!(
            out,
            "  estimated time {:.3} s against L/F {:.3} s ({:+.1} %)",
            f.time_s,
            f.ideal_time_s,
            100.0 * (f.time_s / f.ideal_time_s - 1.0)
        )?;
        let peaks: Vec<String> = Axis::ALL
            .iter()
            .map(|&a| {
                let l = axis_letter(a, letters);
                let unit = if a.is_rotary() { "rpm" } else { "m/min" };
                format!("{l} {:.3} {unit}", f.peak_speed[&l])
            })
            .collect();
        writeln!(out, "  peak speed at F: {}", peaks.join(", "))?;
        let ratios: Vec<String> = Axis::ALL
            .iter()
            .map(|&a| {
                let l = axis_letter(a, letters);
                format!(
                    "{l} {:.3} ({})",
                    f.axis_min_ratio[&l],
                    limit_name(f.axis_limit[&l])
                )
            })
            .collect();
        writeln!(out, "  min ratio per axis: {}", ratios.join(", "))?;
        if let Some(m) = &r.machine_frame {
            let xyz = |map: &std::collections::BTreeMap<String, f64>| {
                ["X", "Y", "Z"]
                    .map(|l| format!("{l} {:.3}", map[l]))
                    .join(", ")
            };
            writeln!(
                out,
                "  machine frame (chain, datum X{:+.3} Y{:+.3} Z{:+.3}): peak speed at F {} m/min; min ratio {}",
                m.datum_mm[0],
                m.datum_mm[1],
                m.datum_mm[2],
                xyz(&m.peak_speed),
                xyz(&m.axis_min_ratio)
            )?;
        }
        if f.zones.is_empty() {
            writeln!(out, "  no singular zone")?;
        }
        for z in &f.zones {
            writeln!(
                out,
                "  singular zone lines {}–{} ({}), {} {:.3}° at line {}, {} ratio {:.3}",
                z.lines[0],
                z.lines[1],
                z.kind,
                // |P| is the distance from the pole on the standard form only.
                if standard {
                    format!("min |{}|", letters.tilt as char)
                } else {
                    "least distance from the pole".to_string()
                },
                z.min_abs_primary_deg,
                z.singular_line,
                letters.pole as char,
                z.c_ratio_min
            )?;
        }
    }
    Ok(())
}
