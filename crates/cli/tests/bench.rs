//! `polepatch bench`: the suite agrees with `polepatch patch --report`, the bound is a lower
//! bound, the plots are SVG, and the command fails clearly without inputs.

use polepatch::kinematics::Machine;
use polepatch_cli::bench::{BenchOptions, run};
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
    "patch_length_mm",
    "outcome",
    "method",
    "qp_status",
    "qp_iterations",
    "qp_solves",
    "decimals",
    "c_offset_deg",
];

fn without_time(v: &Value) -> Value {
    let mut v = v.clone();
    if let Some(o) = v.as_object_mut() {
        o.remove("time_s");
    }
    v
}

#[test]
fn bench_rows_reproduce_patch_report() {
    let dir = tempfile::tempdir().unwrap();
    let file = root().join("fixtures/dialects/fanuc.nc");
    for m in Machine::builtin_names() {
        let json = dir.path().join(format!("bench-{m}.json"));
        let out = bin()
            .arg("bench")
            .arg(&file)
            .args(["--machine", m, "--no-bound", "--json"])
            .arg(&json)
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
            .arg(&file)
            .arg("-o")
            .arg(dir.path().join(format!("out-{m}.nc")))
            .args(["--machine", m, "--report"])
            .arg(&report)
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
                .find(|l| l.contains(m) && l.contains("fanuc.nc"))
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
}

#[test]
fn bound_is_never_above_our_deviation() {
    let report = run(&small_set(), &machines(), &BenchOptions::default());
    assert!(report.errors.is_empty(), "{:?}", report.errors);
    let mut compared = 0;
    for z in report.zones() {
        assert_eq!(z.bound.status, "ok", "{}: {:?}", z.row.file, z.bound);
        let b = z.bound.bound_deg.unwrap();
        if z.row.outcome != "reached" {
            continue;
        }
        // The bisection returns a feasible T: above the true minimum by at most its last
        // interval; ours is feasible (with margin, rounded), so bound ≤ ours up to that.
        assert!(
            b <= z.row.max_deviation_deg * (1.0 + 1e-6) + 1e-6,
            "{} on {}: bound {b}° above ours {}°",
            z.row.file,
            z.machine,
            z.row.max_deviation_deg
        );
        let r = z
            .ratio
            .expect("a reached zone with a positive bound has a ratio");
        assert!(r >= 1.0 - 1e-6, "ratio {r}");
        compared += 1;
    }
    assert!(compared >= 4, "only {compared} zones compared");
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
    // One zone per fixture and machine.
    assert_eq!(files.len(), 6, "{files:?}");
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
fn csv_has_bound_and_ratio_columns() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("b.csv");
    let out = bin()
        .arg("bench")
        .arg(root().join("fixtures/dialects/fanuc.nc"))
        .args(["-m", "mikron-hsm600", "--csv"])
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
    assert_eq!(&header[header.len() - 2..], &["bound_deg", "ratio"]);
    let row: Vec<&str> = lines.next().expect("one zone row").split(',').collect();
    assert_eq!(row.len(), header.len());
    let bound: f64 = row[header.len() - 2].parse().unwrap();
    let ratio: f64 = row[header.len() - 1].parse().unwrap();
    assert!(bound > 0.0 && ratio >= 1.0 - 1e-6, "{row:?}");
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
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let fresh = String::from_utf8(out.stdout).unwrap();
    let want = doc_rows(&doc, &files);
    assert_eq!(want.len(), 6, "docs/quality.md lacks the dialect rows");
    assert_eq!(
        doc_rows(&fresh, &files),
        want,
        "docs/quality.md is stale: regenerate it with the command at its top"
    );
}
