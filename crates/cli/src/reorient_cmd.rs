//! `polepatch reorient`: C17's avoidance — tilt the workpiece on a jig.

use crate::{check_positive, machine, parse_xyz};
use anyhow::{Context, Result, bail};
use plotters::prelude::*;
use polepatch::load_nc;
use polepatch::reorient::{ReorientReport, Tilt, pole_after, reorient_nc, search, tool_axes};
use polepatch_cli::files::read;
use polepatch_cli::outputs::{Input, Output, plan};
use polepatch_kinematics::vec3::{cross, norm_direct};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
#[command(allow_negative_numbers = true)]
pub(crate) struct ReorientArgs {
    /// NC program (with TCPM: its X Y Z are part coordinates).
    file: PathBuf,
    /// Machine: a built-in name or a TOML file.
    #[arg(long, short)]
    machine: String,
    /// Tilt about the workpiece's x axis, degrees (with --theta-z; without both, search).
    #[arg(long, requires = "theta_z")]
    theta_x: Option<f64>,
    /// Turn about the workpiece's z axis, degrees, applied first: R = Rx(θx)·Rz(θz).
    #[arg(long, requires = "theta_x")]
    theta_z: Option<f64>,
    /// Pivot of the tool-tip positions, X,Y,Z in mm (default: the program's origin).
    #[arg(long, value_parser = parse_xyz, value_name = "X,Y,Z")]
    pivot: Option<[f64; 3]>,
    /// Write the reoriented program here (nothing is written without it).
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// Print one JSON document instead of the table.
    #[arg(long)]
    json: bool,
    /// Draw the tool orientations on the sphere with the pole before and after (SVG).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Singular cone, degrees.
    #[arg(long, default_value_t = polepatch::patcher::PatchOptions::default().cone_deg)]
    cone: f64,
}

pub(crate) fn run(args: ReorientArgs) -> Result<ExitCode> {
    check_positive("--cone", Some(args.cone))?;
    for (name, v) in [("--theta-x", args.theta_x), ("--theta-z", args.theta_z)] {
        if let Some(v) = v
            && !v.is_finite()
        {
            bail!("{name} must be a finite number of degrees, got {v}");
        }
    }
    let machine = machine(&args.machine)?;
    let name = args.file.display().to_string();
    let mut inputs = vec![Input::new("the input", &args.file)];
    inputs.extend(crate::machine_input(&args.machine));
    let mut outputs = Vec::new();
    if let Some(path) = &args.output {
        outputs.push(Output::new("-o", path));
    }
    if let Some(path) = &args.plot {
        outputs.push(Output::new("--plot", path));
    }
    let targets = plan(&inputs, outputs)?;
    let mut targets = targets.iter();
    let (out_target, plot_target) = (
        args.output.as_ref().and_then(|_| targets.next()),
        args.plot.as_ref().and_then(|_| targets.next()),
    );
    let bytes = read(&args.file)?;
    let pivot = args.pivot.unwrap_or([0.0; 3]);
    let (out, report) = match (args.theta_x, args.theta_z) {
        (Some(tx), Some(tz)) => {
            let tilt = Tilt {
                theta_x_deg: tx,
                theta_z_deg: tz,
                pivot_mm: pivot,
            };
            reorient_nc(&bytes, &machine, &tilt, &name, args.cone)?
        }
        _ => search(&bytes, &machine, pivot, &name, args.cone)?,
    };
    if let Some(target) = out_target {
        target
            .write(&out, Some(&args.file))
            .with_context(|| format!("cannot write {}", target.path.display()))?;
    }
    if let Some(target) = plot_target {
        let path = &target.path;
        let lp = load_nc(&bytes, &name, &machine, None)?;
        let axes = tool_axes(&lp, &machine);
        let tilt = Tilt {
            theta_x_deg: report.theta_x_deg,
            theta_z_deg: report.theta_z_deg,
            pivot_mm: pivot,
        };
        let svg = sphere_svg(&axes, pole_after(&tilt), &report, args.cone)
            .map_err(|e| anyhow::anyhow!("drawing {}: {e}", path.display()))?;
        target
            .write(svg.as_bytes(), None)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report);
    }
    if !report.untouched_lines.is_empty() {
        eprintln!(
            "polepatch: warning: {}: {} move(s) with TCPM off (lines {}) are machine coordinates and were left as they are; check them against the jig",
            report.file,
            report.untouched_lines.len(),
            compress(&report.untouched_lines)
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// `3, 4, 5, 9` → `3–5, 9`.
fn compress(lines: &[usize]) -> String {
    let mut parts = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let mut j = i;
        while j + 1 < lines.len() && lines[j + 1] == lines[j] + 1 {
            j += 1;
        }
        parts.push(if j > i {
            format!("{}–{}", lines[i], lines[j])
        } else {
            lines[i].to_string()
        });
        i = j + 1;
    }
    parts.join(", ")
}

fn print_report(r: &ReorientReport) {
    println!(
        "{} on {}: θx {:.3}°, θz {:.3}° ({}), pivot {:?} mm, {} words changed",
        r.file, r.machine, r.theta_x_deg, r.theta_z_deg, r.objective, r.pivot_mm, r.words_changed
    );
    println!("{:<28} {:>14} {:>14}", "", "before", "after");
    println!(
        "{:<28} {:>14.3} {:>14.3}",
        "min pole distance, °", r.before.min_pole_distance_deg, r.after.min_pole_distance_deg
    );
    println!(
        "{:<28} {:>14.3} {:>14.3}",
        "estimated time, s", r.before.time_s, r.after.time_s
    );
    println!(
        "{:<28} {:>14} {:>14}",
        "singular zones", r.before.zones, r.after.zones
    );
    for (l, v) in &r.before.peak_speed {
        let unit = if matches!(l.as_str(), "X" | "Y" | "Z") {
            "m/min"
        } else {
            "rpm"
        };
        println!(
            "{:<28} {:>14.3} {:>14.3}",
            format!("peak {l}, {unit}"),
            v,
            r.after.peak_speed.get(l).copied().unwrap_or(f64::NAN)
        );
    }
    for (l, v) in &r.before.min_ratio {
        println!(
            "{:<28} {:>14.3} {:>14.3}",
            format!("min feed ratio {l}"),
            v,
            r.after.min_ratio.get(l).copied().unwrap_or(f64::NAN)
        );
    }
    if !r.alternatives.is_empty() {
        let feasible = r
            .alternatives
            .iter()
            .filter(|a| a.rejected.is_none())
            .count();
        println!(
            "search: {} candidates evaluated, {} reach feed on both rotary axes (all in --json)",
            r.alternatives.len(),
            feasible
        );
    }
}

/// Tool orientations on the upper hemisphere, seen from above (orthographic: x = i,
/// y = j), with the pole before (the centre) and after (`Rᵀ·ẑ`) and their cones.
fn sphere_svg(
    axes: &[[f64; 3]],
    pole_after: [f64; 3],
    r: &ReorientReport,
    cone_deg: f64,
) -> Result<String, Box<dyn std::error::Error>> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (720, 760)).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(
            &format!(
                "{}: tool orientations (part frame), θx {:.2}°, θz {:.2}°",
                r.file, r.theta_x_deg, r.theta_z_deg
            ),
            ("sans-serif", 16),
        )?;
        let mut chart = ChartBuilder::on(&root)
            .margin(15)
            .x_label_area_size(35)
            .y_label_area_size(45)
            .build_cartesian_2d(-1.05f64..1.05f64, -1.05f64..1.05f64)?;
        chart
            .configure_mesh()
            .x_desc("i (x component of the tool axis)")
            .y_desc("j")
            .draw()?;
        let circle = |c: [f64; 3], radius_deg: f64| -> Vec<(f64, f64)> {
            // A small circle of angular radius `radius_deg` about unit vector c.
            let a = if c[2].abs() < 0.9 {
                [0.0, 0.0, 1.0]
            } else {
                [1.0, 0.0, 0.0]
            };
            let u = normalize(cross(c, a));
            let v = cross(c, u);
            let (s, k) = radius_deg.to_radians().sin_cos();
            (0..=72)
                .map(|t| {
                    let phi = (t as f64) * std::f64::consts::TAU / 72.0;
                    let p: Vec<f64> = (0..3)
                        .map(|i| k * c[i] + s * (phi.cos() * u[i] + phi.sin() * v[i]))
                        .collect();
                    (p[0], p[1])
                })
                .collect()
        };
        chart.draw_series(LineSeries::new(
            circle([0.0, 0.0, 1.0], 90.0),
            BLACK.mix(0.4),
        ))?;
        let blue = RGBColor(31, 119, 180);
        let red = RGBColor(214, 39, 40);
        chart
            .draw_series(
                axes.iter()
                    .filter(|o| o[2] >= 0.0)
                    .map(|o| Circle::new((o[0], o[1]), 2, blue.filled())),
            )?
            .label("tool orientations")
            .legend(move |(x, y)| Circle::new((x + 10, y), 3, blue.filled()));
        chart
            .draw_series(LineSeries::new(
                circle([0.0, 0.0, 1.0], cone_deg),
                BLACK.stroke_width(2),
            ))?
            .label(format!("pole before (P = 0) and its {cone_deg}° cone"))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        chart
            .draw_series(LineSeries::new(
                circle(pole_after, cone_deg),
                red.stroke_width(2),
            ))?
            .label("pole after the tilt, and its cone")
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2)));
        chart.draw_series(std::iter::once(Cross::new(
            (0.0, 0.0),
            6,
            BLACK.stroke_width(2),
        )))?;
        chart.draw_series(std::iter::once(Cross::new(
            (pole_after[0], pole_after[1]),
            6,
            red.stroke_width(2),
        )))?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()?;
        root.present()?;
    }
    Ok(buf)
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = norm_direct(a);
    [a[0] / n, a[1] / n, a[2] / n]
}
