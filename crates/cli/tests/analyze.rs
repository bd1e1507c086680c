//! `polepatch analyze` on the C17 programs and on bad input.

use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn polepatch(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_polepatch"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("run polepatch");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn analyze_json(file: &str, machine: &str) -> serde_json::Value {
    let (code, out, err) = polepatch(&["analyze", file, "--machine", machine, "--json"]);
    assert_eq!(code, 0, "stderr: {err}");
    serde_json::from_str(&out).expect("one JSON document")
}

/// The run that carries the cutting pass (the longest one).
fn main_run(doc: &serde_json::Value) -> &serde_json::Value {
    doc["runs"]
        .as_array()
        .unwrap()
        .iter()
        .max_by(|a, b| {
            a["length_mm"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["length_mm"].as_f64().unwrap())
        })
        .unwrap()
}

fn peak(run: &serde_json::Value, axis: &str) -> f64 {
    run["peak_speed"][axis].as_f64().unwrap()
}

#[test]
fn sing_peak_c_speed_is_about_200_rpm_with_a_zone_around_x25() {
    let doc = analyze_json("fixtures/c17/SING.I", "mikron-ucp710");
    let run = main_run(&doc);
    let c = peak(run, "C");
    assert!(
        (180.0..=220.0).contains(&c),
        "peak C speed {c} rpm, C17 §4 says ~200"
    );
    let zones: Vec<_> = doc["runs"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r["zones"].as_array().unwrap().clone())
        .collect();
    assert_eq!(zones.len(), 1, "{zones:?}");
    let z = &zones[0];
    assert_eq!(z["kind"], "c_swing");
    assert!((z["min_abs_primary_deg"].as_f64().unwrap() - 1.0).abs() < 1e-9);
    // The zone spans the X=25 block (file line 41: `N360 X+25 Y+0 Z-8 A+1 C+180 *`).
    let lines = z["lines"].as_array().unwrap();
    let (a, b) = (lines[0].as_u64().unwrap(), lines[1].as_u64().unwrap());
    assert!(a < 41 && 41 < b, "zone lines {a}–{b}");
    assert_eq!(z["singular_line"], 41);
    assert!(z["c_ratio_min"].as_f64().unwrap() < 0.2);
}

#[test]
fn non_sing_peak_c_speed_is_about_18_rpm_and_no_zone() {
    let doc = analyze_json("fixtures/c17/NON_SING.I", "mikron-ucp710");
    let run = main_run(&doc);
    let c = peak(run, "C");
    assert!(
        (16.2..=19.8).contains(&c),
        "peak C speed {c} rpm, C17 §4 says ~18"
    );
    for r in doc["runs"].as_array().unwrap() {
        assert!(r["zones"].as_array().unwrap().is_empty());
    }
}

#[test]
fn json_peak_speed_is_keyed_by_axis_letter() {
    let doc = analyze_json("fixtures/c17/SING.I", "mikron-ucp710");
    for r in doc["runs"].as_array().unwrap() {
        let keys: Vec<&String> = r["peak_speed"].as_object().unwrap().keys().collect();
        assert_eq!(keys, ["A", "C", "X", "Y", "Z"]);
    }
    // On the B-C machine the program's A words are refused (issue 29: reading A as B would
    // analyse with another machine's kinematics), at the first A word.
    let (code, _, err) = polepatch(&[
        "analyze",
        "fixtures/c17/SING.I",
        "--machine",
        "mikron-hsm600",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("fixtures/c17/SING.I:6:5:")
            && err.contains(
                "A is not an axis of machine mikron-hsm600, whose rotary axes are B and C"
            )
            && err.contains("; the built-in mikron-ucp710 has A and C"),
        "{err}"
    );
}

fn temp_file(name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("polepatch-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn fails_with(args: &[&str], needle: &str) {
    let (code, _, err) = polepatch(args);
    assert_ne!(code, 0, "expected failure for {args:?}");
    assert!(!err.contains("panicked"), "panic for {args:?}: {err}");
    assert!(
        err.contains(needle),
        "for {args:?} expected '{needle}' in: {err}"
    );
    assert!(
        err.matches("(os error").count() <= 1,
        "the OS error is said once: {err}"
    );
}

#[test]
fn bad_input_gets_a_clear_message_and_nonzero_exit() {
    fails_with(
        &[
            "analyze",
            "fixtures/c17/SING.I",
            "--machine",
            "mikron-ucp999",
        ],
        "built-ins: mikron-ucp710, mikron-hsm600",
    );
    fails_with(
        &[
            "analyze",
            "fixtures/does-not-exist.I",
            "--machine",
            "mikron-ucp710",
        ],
        "cannot read fixtures/does-not-exist.I",
    );
    let empty = temp_file("empty.nc", b"  \n\n");
    fails_with(
        &[
            "analyze",
            empty.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
        ],
        "empty program",
    );
    // A 3-axis program is read: no run analysed, said as a warning, exit 0 (issue 20 §7).
    let three_axis = temp_file("xyz.nc", b"G1 X0 Y0 Z0 F1000\nX10\nX20 Y5\n");
    let (code, _, err) = polepatch(&[
        "analyze",
        three_axis.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("no rotary axis words"), "{err}");
    let bad = temp_file("bad.nc", b"G1 X0 Y0 Z0 A1 C0 F1000\nX1 C12..5\n");
    fails_with(
        &[
            "analyze",
            bad.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
        ],
        ":2:",
    );
    fails_with(
        &[
            "analyze",
            bad.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
        ],
        "12..5",
    );
    let nan = temp_file("nan.nc", b"G1 X0 Y0 Z0 A1 C0 F1000\nX1 CNaN\n");
    fails_with(
        &[
            "analyze",
            nan.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
        ],
        ":2:",
    );
    // A run without a feed is listed, not an error (issue 20 §7); --strict makes it one.
    let no_f = temp_file("nof.nc", b"G1 X0 Y0 Z0 A1 C0\nX1 C1\nX2 C2\nX3 C3\n");
    fails_with(
        &[
            "analyze",
            no_f.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--strict",
        ],
        "no feed (F)",
    );
    let (code, _, err) = polepatch(&[
        "analyze",
        no_f.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--feed",
        "1000",
    ]);
    assert_eq!(code, 0, "{err}");
    fails_with(
        &[
            "analyze",
            no_f.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--feed",
            "-5",
        ],
        "--feed must be a positive number",
    );
}

/// `analyze` prints its report as runs are analysed: the JSON is the library's report,
/// pretty-printed, byte for byte; the table has one block per run, in order; a run
/// without a feed is listed (exit 0: the file was read; `--strict` makes it 2).
#[test]
fn the_printed_report_is_the_librarys() {
    use polepatch::kinematics::Machine;
    let machine = Machine::builtin("mikron-ucp710").unwrap();
    let feedless = temp_file(
        "feedless.I",
        b"%P G71 *\nN1 M128 *\nN2 G01 X+0 Y+0 Z+0 A+10 C+0 *\nN3 X+1 A+9 C+5 *\nN4 X+2 A+8 C+10 F1000 *\nN5 X+3 A+7 C+15 *\nN6 X+4 A+6 C+20 *\n",
    );
    for (file, code) in [
        ("fixtures/c17/SING.I".to_string(), 0),
        ("fixtures/dialects/fanuc.nc".to_string(), 0),
        (feedless.display().to_string(), 0),
    ] {
        let opts = polepatch::AnalyzeOptions {
            read: polepatch::ReadOptions {
                name: file.clone(),
                ..polepatch::ReadOptions::default()
            },
            ..polepatch::AnalyzeOptions::default()
        };
        let bytes = std::fs::read(root().join(&file)).unwrap();
        let report = polepatch::analyze_nc(&bytes, &machine, &opts).unwrap();
        let (c, out, err) = polepatch(&["analyze", &file, "--machine", "mikron-ucp710", "--json"]);
        assert_eq!(c, code, "{file}: {err}");
        assert_eq!(
            out,
            format!("{}\n", serde_json::to_string_pretty(&report).unwrap()),
            "{file}"
        );
        let (c, table, _) = polepatch(&["analyze", &file, "--machine", "mikron-ucp710"]);
        assert_eq!(c, code);
        let runs: Vec<usize> = table
            .lines()
            .filter_map(|l| l.strip_prefix("run "))
            .map(|l| l.split(':').next().unwrap().parse().unwrap())
            .collect();
        assert_eq!(runs, (1..=report.runs.len()).collect::<Vec<_>>(), "{file}");
    }
}

/// Issue 20 §7 / 19 §5: `analyze` and `patch` agree on exit codes: 0 when the file was read
/// (what could not be analysed is listed), 2 with `--strict`, for a run without a usable
/// feed as for lines carried through (an expression).
#[test]
fn strict_fails_on_what_was_not_analysed() {
    let feedless = temp_file(
        "strict-feedless.I",
        b"%P G71 *\nN1 M128 *\nN2 G01 X+0 Y+0 Z+0 A+1 C+0 *\nN3 X+1 A+0.5 C+50 *\nN4 X+2 A+0.2 C+120 *\n",
    );
    let expression = temp_file(
        "strict-expression.nc",
        b"(X)\nG43.4 H1\nG1 X0 Y0 Z0 A10 C0 F1000\nX1 A#<a>\nX2 A12 C5\nX3 A13 C6\n",
    );
    for file in [&feedless, &expression] {
        let f = file.display().to_string();
        for cmd in ["analyze", "patch"] {
            let out = format!("{f}.out");
            let mut args = vec![cmd, &f, "--machine", "mikron-ucp710"];
            if cmd == "patch" {
                args.extend(["-o", &out]);
            }
            let (c, _, err) = polepatch(&args);
            assert_eq!(c, 0, "{cmd} {f}: {err}");
            assert!(
                err.contains("not analysed") || err.contains("no feed"),
                "{cmd} {f}: {err}"
            );
            args.push("--strict");
            let (c, _, err) = polepatch(&args);
            assert_eq!(c, 2, "{cmd} {f} --strict: {err}");
        }
    }
}
