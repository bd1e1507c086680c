//! `polepatch post`: CL file → joints → TCPM NC program (patched unless `--no-patch`).

use crate::{check_positive, machine};
use anyhow::{Context, Result, bail};
use polepatch::cl::{ParseOptions, Units};
use polepatch::kinematics::BranchRule;
use polepatch::nc::Dialect;
use polepatch::post::{ARC_TOLERANCE_MM, PostOptions, post_cl, read_cl_for_post};
use polepatch_cli::files::read;
use polepatch_cli::outputs::{Input, Output, plan};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Clone, Copy, clap::ValueEnum)]
enum DialectArg {
    Heidenhain,
    Sinumerik,
    Fanuc,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum BranchArg {
    /// Nearest to the previous point (continuous).
    Nearest,
    /// G16 Table 1's domain rule (P flips sign near the pole).
    Domain,
    /// Always P ≥ 0.
    Positive,
    /// Always P ≤ 0.
    Negative,
}

#[derive(clap::Args)]
pub(crate) struct PostArgs {
    /// CL file: APT CLDATA (GOTO/x,y,z,i,j,k …) or CSV x,y,z,i,j,k[,f].
    cl: PathBuf,
    /// Machine: a built-in name or a TOML file.
    #[arg(long, short)]
    machine: String,
    /// Dialect to write.
    #[arg(long, value_enum)]
    dialect: DialectArg,
    /// Output NC program.
    #[arg(long, short)]
    output: PathBuf,
    /// Write the joints as the inverse kinematics gives them (no patch).
    #[arg(long)]
    no_patch: bool,
    /// IK branch rule.
    #[arg(long, value_enum, default_value = "nearest")]
    branch: BranchArg,
    /// Write the patch report as JSON here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Feed in mm/min for points without one.
    #[arg(long)]
    feed: Option<f64>,
    /// Decimals of the rotary words.
    #[arg(long, default_value_t = 3)]
    rotary_decimals: usize,
    /// Units of the program written (default: the CL file's).
    #[arg(long, value_enum)]
    units: Option<crate::UnitsArg>,
    /// Write every arc as chords (default: G2/G3 where the arc lies in a principal plane
    /// with a fixed tool axis).
    #[arg(long)]
    linearize: bool,
    /// Chordal tolerance of arcs written as chords, mm.
    #[arg(long, default_value_t = ARC_TOLERANCE_MM)]
    arc_tolerance: f64,
    /// Skip every APT record with this major word (e.g. THREAD) instead of refusing the
    /// file; repeat for several. Only records polepatch would refuse can be skipped.
    #[arg(long, value_name = "RECORD")]
    ignore: Vec<String>,
    /// Drill peck cycles whose first peck differs from the following ones (CAMWorks'
    /// 1STPECK/SUBPECK) with the smaller peck throughout (default: refused).
    #[arg(long)]
    uniform_peck: bool,
    /// The cutter and the point X Y Z state (as `patch`; default: the CL file's CUTTER/ or
    /// TLDATA/, at the tip).
    #[command(flatten)]
    tool: crate::ToolArgs,
}

pub(crate) fn run(args: PostArgs) -> Result<ExitCode> {
    check_positive("--feed", args.feed)?;
    if args.rotary_decimals > 9 {
        bail!(
            "--rotary-decimals must be at most 9, got {}",
            args.rotary_decimals
        );
    }
    let machine = machine(&args.machine)?;
    let name = args.cl.display().to_string();
    let mut inputs = vec![Input::new("the CL input", &args.cl)];
    inputs.extend(crate::machine_input(&args.machine));
    inputs.extend(args.tool.inputs());
    let mut outputs = vec![Output::new("-o", &args.output)];
    if let Some(path) = &args.report {
        outputs.push(Output::new("--report", path));
    }
    let targets = plan(&inputs, outputs)?;
    let parse = ParseOptions {
        ignore: args.ignore.clone(),
        uniform_peck: args.uniform_peck,
    };
    if let Err(m) = parse.check() {
        bail!("{m}");
    }
    let mut opts = PostOptions {
        dialect: match args.dialect {
            DialectArg::Heidenhain => Dialect::Heidenhain,
            DialectArg::Sinumerik => Dialect::Sinumerik,
            DialectArg::Fanuc => Dialect::Fanuc,
        },
        branch: match args.branch {
            BranchArg::Nearest => BranchRule::Nearest,
            BranchArg::Domain => BranchRule::DomainRule,
            BranchArg::Positive => BranchRule::PreferPositive,
            BranchArg::Negative => BranchRule::PreferNegative,
        },
        patch: !args.no_patch,
        patch_options: polepatch::PatchOptions {
            read: polepatch::ReadOptions {
                name: name.clone(),
                feed_fallback_mm_min: args.feed,
                ..polepatch::ReadOptions::default()
            },
            tool: args.tool.options()?,
            ..polepatch::PatchOptions::default()
        },
        rotary_decimals: args.rotary_decimals,
        linear_decimals: 3,
        units: args.units.map(|u| match u {
            crate::UnitsArg::Mm => Units::Mm,
            crate::UnitsArg::Inch => Units::Inch,
        }),
        linearize: args.linearize,
        arc_tolerance_mm: args.arc_tolerance,
    };
    let cl_bytes = read(&args.cl)?;
    // `--ignore`'s one rule: a record refused in this file may be skipped.
    let cl = read_cl_for_post(&cl_bytes, &name, &parse, &machine, &opts)?;
    polepatch::post::tool_from_cl(&cl_bytes, &cl, &mut opts);
    let (bytes, report) = post_cl(&cl, &machine, &opts)?;
    targets[0]
        .write(&bytes, None)
        .with_context(|| format!("cannot write {}", args.output.display()))?;
    for n in &cl.notes {
        // (A report's warnings name each INSERT with the program line it was written at.)
        if report.is_some() && n.contains(": INSERT/") {
            continue;
        }
        eprintln!("polepatch: note: {name}: {n}");
    }
    // Skipped records (the report's warnings say it too).
    if report.is_none() {
        for n in polepatch::post::skip_notes(&cl, &name) {
            eprintln!("polepatch: note: {n}");
        }
    }
    // Every record kind read, once, with its count (and what was skipped on request).
    if !cl.records.is_empty() {
        let list = cl
            .records
            .iter()
            .map(|(w, n)| match cl.skipped.get(w) {
                Some(_) => format!("{w} {n} (skipped, --ignore)"),
                None => format!("{w} {n}"),
            })
            .collect::<Vec<_>>()
            .join(", ");
        eprintln!("polepatch: note: {name}: records read: {list}");
    }
    let points = cl.point_count();
    match &report {
        Some(r) => {
            let reached = r
                .zones
                .iter()
                .filter(|z| z.outcome == polepatch::Outcome::Reached)
                .count();
            println!(
                "{name} → {}: {points} points, {} zone(s), {reached} reach feed, {} words patched",
                args.output.display(),
                r.zones.len(),
                r.words_changed
            );
            crate::patch::print_warnings(r);
            if let Some(target) = targets.get(1) {
                target
                    .write(serde_json::to_string_pretty(r)?.as_bytes(), None)
                    .with_context(|| format!("cannot write {}", target.path.display()))?;
            }
        }
        None if args.report.is_some() => {
            eprintln!(
                "polepatch: note: {name}: no patch report written (the program was not patched)"
            );
            println!(
                "{name} → {}: {points} points, not patched",
                args.output.display()
            );
        }
        None if args.no_patch => println!(
            "{name} → {}: {points} points, not patched (--no-patch)",
            args.output.display()
        ),
        None => println!(
            "{name} → {}: {points} points, no G1 run to patch (holes and rapids only)",
            args.output.display()
        ),
    }
    Ok(ExitCode::SUCCESS)
}
