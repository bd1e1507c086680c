//! `polepatch bench`: the suite agrees with `polepatch patch --report`, the references
//! relate to ours as they should (the C-only LP bound is a lower bound; the joint reference
//! the best found, which polepatch stays within SPEC §6's 1.25× of), the strategies sit
//! side by side, the plots are SVG, and the command fails clearly without inputs.

use polepatch::kinematics::Machine;
use polepatch_cli::bench::{
    BenchOptions, BenchStrategy, BoundKind, BoundStatus, RATIO_TARGET, run,
};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_polepatch"))
}

/// Small fixtures with one zone each on both machines (the bound LP is quick on them).
fn small_set() -> Vec<PathBuf> {
    [
        "dialects/fanuc.nc",
        "dialects/sinumerik.mpf",
        "dialects/heidenhain_latin1.I",
    ]
    .iter()
    .map(|f| root().join("fixtures").join(f))
    .collect()
}

/// B-C programs of the three dialects (the small set's are A-C): with both, each machine
/// gets programs posted for it.
fn small_set_bc() -> Vec<PathBuf> {
    [
        "generated/fanuc-bc-flip-d0.5.nc",
        "generated/sinumerik-bc-swing-d1.mpf",
        "generated/heidenhain-bc-flip-d0.1.I",
    ]
    .iter()
    .map(|f| root().join("fixtures").join(f))
    .collect()
}

fn machines() -> Vec<Machine> {
    Machine::builtin_names()
        .iter()
        .map(|n| Machine::builtin(n).unwrap())
        .collect()
}

/// The per-zone figures both documents carry (not the solve times, which are measured).
const FIGURES: &[&str] = &[
    "run",
    "lines",
    "kind",
    "min_abs_primary_deg",
    "before",
    "after",
    "ideal_time_s",
    "max_deviation_deg",
    "points_modified",
    "primary_points_modified",
    "branch_reselected",
    "reselected_points",
    "patch_length_mm",
    "outcome",
    "method",
    "qp_status",
    "qp_iterations",
    "qp_solves",
    "decimals",
    "primary_decimals",
    "c_offset_deg",
];

fn without_time(v: &Value) -> Value {
    let mut v = v.clone();
    if let Some(o) = v.as_object_mut() {
        o.remove("time_s");
    }
    v
}

/// `bench` on `file` with `bench_args` and `patch` with `patch_args` write the same zone
/// figures, and the table row carries them.
fn bench_agrees_with_patch(file: &Path, bench_args: &[&str], patch_args: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let stem = file.file_name().unwrap().to_string_lossy().into_owned();
    let mut compared = 0;
    for m in Machine::builtin_names() {
        // The machines the program was posted for (its rotary letters).
        let fits = polepatch::analyze_nc(
            &std::fs::read(file).unwrap(),
            &Machine::builtin(m).unwrap(),
            &polepatch::AnalyzeOptions::default(),
        );
        if matches!(fits, Err(polepatch::Error::ForeignAxis { .. })) {
            continue;
        }
        compared += 1;
        let json = dir.path().join(format!("bench-{m}.json"));
        let out = bin()
            .arg("bench")
            .arg(file)
            .args(["--machine", m, "--no-bound", "--json"])
            .arg(&json)
            .args(bench_args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let table = String::from_utf8(out.stdout).unwrap();
        let bench: Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();

        let report = dir.path().join(format!("patch-{m}.json"));
        let out = bin()
            .arg("patch")
            .arg(file)
            .arg("-o")
            .arg(dir.path().join(format!("out-{m}.nc")))
            .args(["--machine", m, "--report"])
            .arg(&report)
            .args(patch_args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let patch: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();

        let cases = bench["cases"].as_array().unwrap();
        assert_eq!(cases.len(), 1);
        let ours = cases[0]["zones"].as_array().unwrap();
        let theirs = patch["zones"].as_array().unwrap();
        assert!(!theirs.is_empty(), "fixture must have a zone on {m}");
        assert_eq!(ours.len(), theirs.len(), "{m}: zone count");
        for (a, b) in ours.iter().zip(theirs) {
            for k in FIGURES {
                let (x, y) = if matches!(*k, "before" | "after") {
                    // The estimated time is a float sum: equal, but compare it apart.
                    (without_time(&a[k]), without_time(&b[k]))
                } else {
                    (a[k].clone(), b[k].clone())
                };
                assert_eq!(x, y, "{m}: field {k} differs");
            }
            for side in ["before", "after"] {
                let (x, y) = (
                    a[side]["time_s"].as_f64().unwrap(),
                    b[side]["time_s"].as_f64().unwrap(),
                );
                assert!(
                    (x - y).abs() <= 1e-12 * y.abs(),
                    "{m}: {side} time {x} vs {y}"
                );
            }
            // The printed table row carries the same figures.
            let f = |side: &str, key: &str| b[side][key].as_f64().unwrap();
            let row = table
                .lines()
                .find(|l| l.contains(m) && l.contains(stem.as_str()))
                .unwrap_or_else(|| panic!("no table row for {m}:\n{table}"));
            for key in ["c_ratio", "primary_ratio", "overall_ratio", "time_s"] {
                let want = format!("{:.3} → {:.3}", f("before", key), f("after", key));
                assert!(row.contains(&want), "{m}: {key} {want} not in {row}");
            }
            let dev = format!("{:.3}", b["max_deviation_deg"].as_f64().unwrap());
            assert!(row.contains(&dev), "{m}: deviation {dev} not in {row}");
            let lines = &b["lines"];
            assert!(row.contains(&format!("{}–{}", lines[0], lines[1])), "{row}");
        }
    }
    assert!(compared > 0, "{stem}: posted for no built-in machine");
}

#[test]
fn bench_rows_reproduce_patch_report() {
    bench_agrees_with_patch(&root().join("fixtures/dialects/fanuc.nc"), &[], &[]);
    bench_agrees_with_patch(
        &root().join("fixtures/dialects/fanuc.nc"),
        &["--strategy", "only-c"],
        &["--only-c"],
    );
}

/// One C-offset default everywhere (issue 11): on `%SING` with C written in (−180°, 180°]
/// — where joining C across its wrap is what the 360° offset is for — `bench` measures
/// exactly what `patch` writes, with either method.
#[test]
fn bench_and_patch_agree_where_c_wraps() {
    let text = std::fs::read_to_string(root().join("fixtures/c17/SING.I")).unwrap();
    let wrapped: String = text
        .split_inclusive('\n')
        .map(|line| {
            let Some(i) = line.find(" C+") else {
                return line.to_string();
            };
            let end = line[i + 3..].find(' ').map_or(line.len(), |k| i + 3 + k);
            let v: f64 = line[i + 3..end].parse().unwrap();
            if v <= 180.0 {
                return line.to_string();
            }
            let w = format!("{:.3}", v - 360.0);
            let w = w.trim_end_matches('0').trim_end_matches('.');
            format!("{} C{w}{}", &line[..i], &line[end..])
        })
        .collect();
    assert!(wrapped.contains("C-148.494"), "the planted wrap");
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("SINGW.I");
    std::fs::write(&file, wrapped).unwrap();
    bench_agrees_with_patch(&file, &[], &[]);
    bench_agrees_with_patch(&file, &["--strategy", "only-c"], &["--only-c"]);
}

/// The C-only LP bound is a lower bound for `only-c`; the joint reference is the best
/// found, and polepatch's default stays within SPEC §6's 1.25× of it on every zone.
#[test]
fn references_relate_to_ours() {
    let opts = BenchOptions {
        strategies: vec![BenchStrategy::Polepatch, BenchStrategy::OnlyC],
        ..BenchOptions::default()
    };
    let files: Vec<PathBuf> = small_set().into_iter().chain(small_set_bc()).collect();
    let report = run(&files, &machines(), &opts);
    assert!(report.errors.is_empty(), "{:?}", report.errors);
    let mut compared = [0, 0];
    for z in report.zones() {
        assert_eq!(
            z.bound.status,
            BoundStatus::Ok,
            "{}: {:?}",
            z.row.file,
            z.bound
        );
        let b = z.bound.bound_deg.unwrap();
        match z.strategy {
            BenchStrategy::OnlyC => {
                assert_eq!(z.bound.kind, BoundKind::COnlyLp);
                if !z.at_feed_c {
                    continue;
                }
                // The bisection returns a feasible T: above the true minimum by at most its
                // last interval; ours is feasible (with margin, rounded), so bound ≤ ours.
                assert!(
                    b <= z.row.max_deviation_deg * (1.0 + 1e-6) + 1e-6,
                    "{} on {}: bound {b}° above ours {}°",
                    z.row.file,
                    z.machine,
                    z.row.max_deviation_deg
                );
                compared[1] += 1;
            }
            _ => {
                assert_eq!(z.bound.kind, BoundKind::BestFound);
                assert!(z.at_feed_both, "{}: {:?}", z.row.file, z.row);
                let r = z.ratio.expect("a zone at feed with a positive reference");
                assert!(
                    r <= RATIO_TARGET,
                    "{} on {}: ours {}° against the reference {b}° ({:?})",
                    z.row.file,
                    z.machine,
                    z.row.max_deviation_deg,
                    z.bound.method
                );
                compared[0] += 1;
            }
        }
    }
    assert!(
        compared[0] >= 6 && compared[1] >= 4,
        "compared {compared:?}"
    );
}

/// The peers run through the same pipeline and sit beside polepatch in the table.
#[test]
fn strategies_side_by_side() {
    let opts = BenchOptions {
        strategies: BenchStrategy::ALL.to_vec(),
        skip_bound: true,
        ..BenchOptions::default()
    };
    let report = run(&small_set()[..1], &machines(), &opts);
    assert!(report.errors.is_empty(), "{:?}", report.errors);
    // An A-C program: measured on the A-C machine only.
    assert_eq!(report.cases.len(), BenchStrategy::ALL.len());
    for s in BenchStrategy::ALL {
        let sum = report.summary(s);
        assert_eq!(sum.zones, 1, "{s:?}: the one zone");
        if s == BenchStrategy::Polepatch {
            assert_eq!(sum.at_feed_both, 1, "polepatch brings both axes to feed");
        }
    }
    // The peers rewrite the cone by rule and are scored as they are: on fanuc.nc FREEZE
    // leaves C below feed.
    assert_eq!(report.summary(BenchStrategy::Freeze).at_feed_c, 0);
    let out = bin()
        .arg("bench")
        .arg(root().join("fixtures/dialects/fanuc.nc"))
        .args(["--strategy", "all", "--no-bound"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(table.contains("Side by side"), "{table}");
    for s in BenchStrategy::ALL {
        assert!(
            table.contains(&format!("\n{}: ", s.name())),
            "{} summary",
            s.name()
        );
    }
    let bad = bin()
        .arg("bench")
        .arg(root().join("fixtures/dialects/fanuc.nc"))
        .args(["--strategy", "nonsense"])
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown strategy 'nonsense'"));
}

/// A minimal well-formedness check of an SVG document: starts with `<svg`, every element
/// closed in order, and it draws lines.
fn assert_svg(path: &Path) {
    let text = std::fs::read_to_string(path).unwrap();
    let name = path.display();
    assert!(text.trim_start().starts_with("<svg"), "{name}: not an SVG");
    let mut stack: Vec<String> = Vec::new();
    let mut rest = text.as_str();
    while let Some(i) = rest.find('<') {
        let j = rest[i..]
            .find('>')
            .unwrap_or_else(|| panic!("{name}: unclosed tag"))
            + i;
        let tag = &rest[i + 1..j];
        if let Some(close) = tag.strip_prefix('/') {
            let open = stack
                .pop()
                .unwrap_or_else(|| panic!("{name}: stray </{close}>"));
            assert_eq!(open, close.trim(), "{name}: <{open}> closed by </{close}>");
        } else if !tag.ends_with('/') && !tag.starts_with('?') && !tag.starts_with('!') {
            let el = tag.split_whitespace().next().unwrap_or("").to_string();
            stack.push(el);
        }
        rest = &rest[j + 1..];
    }
    assert!(stack.is_empty(), "{name}: unclosed {stack:?}");
    assert!(
        text.contains("<polyline") || text.contains("<path"),
        "{name}: no lines"
    );
    assert!(text.contains("C limits"), "{name}: no limiting-axis legend");
    assert!(
        text.contains("primary after"),
        "{name}: no primary-axis panel"
    );
}

#[test]
fn plots_are_valid_svg() {
    let dir = tempfile::tempdir().unwrap();
    let plots = dir.path().join("plots");
    let out = bin()
        .arg("bench")
        .args(small_set())
        .args(["--no-bound", "--plots"])
        .arg(&plots)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut files: Vec<PathBuf> = std::fs::read_dir(&plots)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    // One zone per fixture on the machine it was posted for (A-C programs: the UCP710).
    assert_eq!(files.len(), 3, "{files:?}");
    assert!(
        files
            .iter()
            .any(|f| f.file_name().unwrap() == "fanuc-mikron-ucp710-run1-zone1.svg"),
        "{files:?}"
    );
    for f in &files {
        assert_svg(f);
    }
}

#[test]
fn without_paths_outside_the_repository_it_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let out = bin().arg("bench").current_dir(dir.path()).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("fixtures/"), "{err}");
}

#[test]
fn csv_has_reference_and_ratio_columns() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("b.csv");
    let out = bin()
        .arg("bench")
        .arg(root().join("fixtures/dialects/fanuc.nc"))
        .args(["-m", "mikron-ucp710", "--csv"])
        .arg(&csv)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&header[..3], &["file", "machine", "strategy"]);
    assert_eq!(
        &header[header.len() - 7..],
        &[
            "at_feed_c",
            "at_feed_both",
            "reference_kind",
            "bound_deg",
            "ratio",
            "ball_centre_shift_um",
            "ball_centre_shift_um_per_mm_radius"
        ]
    );
    let row: Vec<&str> = lines.next().expect("one zone row").split(',').collect();
    assert_eq!(row.len(), header.len());
    assert_eq!(row[2], "polepatch");
    let n = header.len();
    assert_eq!(&row[n - 7..n - 4], &["true", "true", "best-found"]);
    let bound: f64 = row[n - 4].parse().unwrap();
    let ratio: f64 = row[n - 3].parse().unwrap();
    // The tool is unknown: the centre shift per mm of radius, 1000·2·sin(δ/2).
    assert_eq!(row[n - 2], "");
    let per_mm: f64 = row[n - 1].parse().unwrap();
    let dev: f64 = row[header
        .iter()
        .position(|h| *h == "max_deviation_deg")
        .unwrap()]
    .parse()
    .unwrap();
    assert!(
        (per_mm - 2e3 * (dev.to_radians() / 2.0).sin()).abs() < 1e-2,
        "{row:?}"
    );
    assert!(
        bound > 0.0 && ratio > 0.0 && ratio <= RATIO_TARGET,
        "{row:?}"
    );
}

/// The table rows of `docs/quality.md` for the dialect fixtures, without the measured
/// solve time (last column).
fn doc_rows(text: &str, files: &[&str]) -> Vec<String> {
    text.lines()
        .filter(|l| files.iter().any(|f| l.starts_with(f)))
        .map(|l| {
            let mut cols: Vec<&str> = l.split_whitespace().collect();
            if !l.contains("no zone") {
                cols.pop();
            }
            cols.join(" ")
        })
        .collect()
}

#[test]
fn docs_quality_table_matches_a_fresh_run() {
    let files = ["fanuc.nc", "heidenhain_latin1.I", "sinumerik.mpf"];
    let doc = std::fs::read_to_string(root().join("docs/quality.md")).unwrap();
    let out = bin()
        .arg("bench")
        .arg(root().join("fixtures/dialects"))
        .args(["--strategy", "all"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fresh = String::from_utf8(out.stdout).unwrap();
    let want = doc_rows(&doc, &files);
    // 3 A-C files × their machine: 5 strategies' zone rows and one side-by-side row each.
    assert_eq!(want.len(), 18, "docs/quality.md lacks the dialect rows");
    assert_eq!(
        doc_rows(&fresh, &files),
        want,
        "docs/quality.md is stale: regenerate it with the command at its top"
    );
}

/// Issue 27 §7: the `ctr µm` column. With a D10 ball at its tip the centre is kept (the
/// column is the report's `max_cutter_shift_mm` in µm, within the written rounding of 0);
/// with the ball at its centre X Y Z do not move; with the tool unknown the column gives
/// the shift per mm of radius, 1000·2·sin(δ/2).
#[test]
fn the_ball_centre_shift_column() {
    use polepatch::tool::{Tool, ToolOptions, ToolPoint};
    use polepatch_cli::bench::BallCentreShift;
    let files = [root().join("fixtures/c17/SING.I")];
    let ucp = [Machine::builtin("mikron-ucp710").unwrap()];
    let bench = |tool: Option<&str>, point: Option<ToolPoint>| {
        let opts = BenchOptions {
            skip_bound: true,
            tool: ToolOptions {
                tool: tool.map(|t| Tool::parse(t).unwrap()),
                point,
                ..ToolOptions::default()
            },
            ..BenchOptions::default()
        };
        let report = run(&files, &ucp, &opts);
        assert!(report.errors.is_empty(), "{:?}", report.errors);
        assert!(report.zones().count() > 0);
        report
    };
    for point in [ToolPoint::Tip, ToolPoint::Centre] {
        let report = bench(Some("ball:10"), Some(point));
        for z in report.zones() {
            let BallCentreShift::Ball(um) = z.ball_centre_shift else {
                panic!("{:?}", z.ball_centre_shift)
            };
            assert_eq!(um, z.row.max_cutter_shift_mm.unwrap() * 1e3);
            assert!(um <= 1.0, "{point:?}: {um} µm");
            assert!(z.at_feed_both);
        }
    }
    let report = bench(None, None);
    for z in report.zones() {
        let BallCentreShift::PerMmRadius(per_mm) = z.ball_centre_shift else {
            panic!("{:?}", z.ball_centre_shift)
        };
        let want = 1e3 * 2.0 * (z.row.max_deviation_deg.to_radians() / 2.0).sin();
        assert!((per_mm - want).abs() < 1e-9, "{per_mm} {want}");
        assert!(per_mm > 0.0);
    }
    let report = bench(Some("flat:10"), None);
    for z in report.zones() {
        assert_eq!(z.ball_centre_shift, BallCentreShift::None);
    }
    // The command line: the column and its flag.
    let out = bin()
        .current_dir(root())
        .args([
            "bench",
            "fixtures/c17/SING.I",
            "-m",
            "mikron-ucp710",
            "--no-bound",
            "--tool",
            "ball:10",
            "--tool-point",
            "tip",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(table.lines().next().unwrap().contains("ctr µm"), "{table}");
    let row = table.lines().find(|l| l.starts_with("SING.I")).unwrap();
    let cols: Vec<&str> = row.split_whitespace().collect();
    let um: f64 = cols[cols.len() - 2].parse().unwrap();
    assert!(um <= 1.0, "{row}");
}
