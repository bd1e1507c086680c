//! Issue 19 §5–§6 at the command line: errors printed once, a summary that shows only what
//! was written, bounded and validated machine files, `--strict` on runs that could not be
//! analysed, reorient's tilt range and its zero tilt.

mod common;
use common::{polepatch, polepatch_in, root, temp_dir};

fn sing() -> String {
    std::fs::read_to_string(root().join("fixtures/c17/SING.I")).unwrap()
}

fn ucp710_toml() -> String {
    std::fs::read_to_string(root().join("crates/kinematics/machines/mikron-ucp710.toml")).unwrap()
}

/// `analyze` and `reorient` printed the parse error twice (its text, then again as its
/// cause); a machine file's I/O error too.
#[test]
fn an_error_is_printed_once() {
    let dir = temp_dir("msg-once");
    std::fs::write(
        dir.join("bad.I"),
        sing().replace("N360 X+25 ", "N360 X+2..5 "),
    )
    .unwrap();
    let want = "bad.I:41:6: X value '+2..5' is not a number";
    for args in [
        vec!["analyze", "bad.I", "--machine", "mikron-ucp710"],
        vec![
            "reorient",
            "bad.I",
            "--machine",
            "mikron-ucp710",
            "--theta-x",
            "10",
            "--theta-z",
            "0",
        ],
        vec!["reorient", "bad.I", "--machine", "mikron-ucp710"],
        vec![
            "patch",
            "bad.I",
            "-o",
            "out.I",
            "--machine",
            "mikron-ucp710",
        ],
    ] {
        let (code, _, err) = polepatch_in(&dir, &args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert_eq!(err.matches(want).count(), 1, "{args:?}: {err}");
    }
    // A folder given as the machine file: its I/O error once.
    let (code, _, err) = polepatch_in(&dir, &["analyze", "bad.I", "--machine", "."]);
    assert_eq!(code, 1, "{err}");
    assert_eq!(err.matches("os error").count(), 1, "{err}");
}

/// SING without its M128 on the machine with the example chain: the patch is found but
/// would leave the programmed line between points (or slow Y in the machine frame), so it
/// is not written. The summary and the report
/// showed the patch's "after" figures (ratio 1.000, 50 points, 0.54°) for a file left as
/// it was.
#[test]
fn the_summary_shows_no_after_figures_for_a_patch_not_written() {
    let dir = temp_dir("msg-summary");
    std::fs::write(dir.join("nom128.I"), sing().replace("N65 M128 *\n", "")).unwrap();
    let machine = root().join("crates/kinematics/machines/mikron-ucp710-example-chain.toml");
    let (code, stdout, err) = polepatch_in(
        &dir,
        &[
            "patch",
            "nom128.I",
            "-o",
            "out.I",
            "--machine",
            machine.to_str().unwrap(),
            "--report",
            "r.json",
        ],
    );
    assert_eq!(code, 0, "{err}");
    // Not written because of the machine frame, or (first) the chord check between points.
    assert!(
        err.contains("in the machine frame") || err.contains("leave the programmed line"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(dir.join("out.I")).unwrap(),
        std::fs::read(dir.join("nom128.I")).unwrap()
    );
    let row = stdout
        .lines()
        .find(|l| l.starts_with("nom128.I"))
        .unwrap_or_else(|| panic!("{stdout}"));
    let cols: Vec<&str> = row.split_whitespace().collect();
    // file zones reached C-ratio(3) overall(3) time(3) dev points words
    assert_eq!(cols[2], "0", "{row}");
    assert_eq!(cols[3], cols[5], "C ratio before = after: {row}");
    assert_eq!(cols[6], cols[8], "overall before = after: {row}");
    assert_eq!(cols[9], cols[11], "time before = after: {row}");
    // dev points words, then the tool column.
    assert_eq!(&cols[12..15], ["0.000", "0", "0"], "{row}");
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("r.json")).unwrap()).unwrap();
    let z = &doc["zones"][0];
    assert_eq!(z["outcome"], "unchanged");
    assert_eq!(z["before"], z["after"]);
    assert_eq!(z["points_modified"], 0);
    assert_eq!(z["max_deviation_deg"], 0.0);
}

/// A file that fails is listed as failed, with no figures.
#[test]
fn a_failed_file_has_no_figures_in_the_summary() {
    let dir = temp_dir("msg-failed");
    std::fs::create_dir_all(dir.join("in")).unwrap();
    std::fs::write(dir.join("in/good.I"), sing()).unwrap();
    std::fs::write(dir.join("in/bad.I"), sing().replace("C+211.506", "C+21..1")).unwrap();
    let (code, stdout, _) = polepatch_in(
        &dir,
        &[
            "patch",
            "in",
            "--out-dir",
            "o",
            "--machine",
            "mikron-ucp710",
        ],
    );
    assert_eq!(code, 1);
    let row = stdout.lines().find(|l| l.starts_with("bad.I")).unwrap();
    assert!(
        row.contains("failed, not written") && !row.contains('→'),
        "{row}"
    );
}

/// `--machine /dev/zero` was read without limit.
#[cfg(unix)]
#[test]
fn an_endless_machine_file_is_refused() {
    let (code, _, err) = polepatch(&["analyze", "fixtures/c17/SING.I", "--machine", "/dev/zero"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("/dev/zero") && err.contains("longer than 1048576 bytes"),
        "{err}"
    );
}

/// `v_rpm = 1e-300` gave a 300-digit time; a third `range_deg` value was dropped; a Tcy of
/// 1e-300 ms.
#[test]
fn absurd_machine_values_are_refused_naming_the_field() {
    let dir = temp_dir("msg-machine");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    for (from, to, want) in [
        (
            "v_rpm = 15.0",
            "v_rpm = 1e-300",
            "primary.v_rpm = 1e-300 is outside the accepted range 0.001 to 1000000",
        ),
        (
            "range_deg = [-100.0, 120.0]",
            "range_deg = [-100.0, 120.0, 5.0]",
            "primary.range_deg must have 2 values, got 3",
        ),
        (
            "tcy_ms = 1.0",
            "tcy_ms = 1e-300",
            "tcy_ms must be a cycle time from 0.1 to 100 ms, got 1e-300",
        ),
    ] {
        let text = ucp710_toml();
        assert!(text.contains(from), "{from}");
        std::fs::write(dir.join("m.toml"), text.replacen(from, to, 1)).unwrap();
        let (code, stdout, err) = polepatch_in(&dir, &["analyze", "SING.I", "--machine", "m.toml"]);
        assert_eq!(code, 1, "{to}: {err}");
        assert!(stdout.is_empty());
        assert!(err.contains("m.toml") && err.contains(want), "{to}: {err}");
    }
    let (code, _, err) = polepatch_in(
        &dir,
        &[
            "simulate",
            "SING.I",
            "--machine",
            "mikron-ucp710",
            "--tcy-ms",
            "1e-9",
        ],
    );
    // A command-line value out of range is a usage error (issue 26 item 4: exit 64, apart
    // from a bad machine file's 1 above and --strict's 2).
    assert_eq!(code, 64, "{err}");
    assert!(
        err.contains("--tcy-ms must be a cycle time from 0.1 to 100 ms"),
        "{err}"
    );
}

/// `--strict` exited 0 when a run near the pole had no usable F: whether it reaches feed
/// is unknown, so it is exit 2. A run without F far from the pole holds no zone: exit 0.
#[test]
fn strict_fails_when_a_run_near_the_pole_could_not_be_analysed() {
    let dir = temp_dir("msg-strict");
    std::fs::write(dir.join("nof.I"), sing().replace(" F2000", "")).unwrap();
    let args = |f: &'static str| {
        vec![
            "patch",
            f,
            "-o",
            "out.I",
            "--machine",
            "mikron-ucp710",
            "--strict",
        ]
    };
    let (code, _, err) = polepatch_in(&dir, &args("nof.I"));
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("could not be analysed"), "{err}");
    // Without --strict: written unchanged, exit 0, with the warning.
    let (code, _, err) = polepatch_in(
        &dir,
        &[
            "patch",
            "nof.I",
            "-o",
            "out.I",
            "--machine",
            "mikron-ucp710",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("no feed (F) in force"), "{err}");
    // A program without F whose runs stay 30° from the pole: no zone possible, exit 0.
    let far = "%FAR G71 *\nN10 G90 *\nN20 M128 *\nN30 G01 X0 Y0 Z0 A30 C0 *\nN40 X1 A31 C1 *\nN50 X2 A32 C2 *\nN60 M30 *\n";
    std::fs::write(dir.join("far.I"), far).unwrap();
    let (code, _, err) = polepatch_in(&dir, &args("far.I"));
    assert_eq!(code, 0, "{err}");
}

/// θx = 1e9 was accepted; θ = 0, 0 rewrote every word onto the other branch.
#[test]
fn reorient_refuses_absurd_tilts_and_a_zero_tilt_changes_nothing() {
    let dir = temp_dir("msg-tilt");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    for (tx, tz) in [("1e9", "0"), ("0", "-400"), ("95", "0")] {
        let (code, _, err) = polepatch_in(
            &dir,
            &[
                "reorient",
                "SING.I",
                "--machine",
                "mikron-ucp710",
                "--theta-x",
                tx,
                "--theta-z",
                tz,
                "-o",
                "out.I",
            ],
        );
        assert_eq!(code, 1, "{tx} {tz}: {err}");
        assert!(err.contains("outside the accepted range"), "{err}");
        assert!(!dir.join("out.I").exists());
    }
    let (code, stdout, err) = polepatch_in(
        &dir,
        &[
            "reorient",
            "SING.I",
            "--machine",
            "mikron-ucp710",
            "--theta-x",
            "0",
            "--theta-z",
            "0",
            "-o",
            "out.I",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("0 words changed"), "{stdout}");
    assert_eq!(
        std::fs::read(dir.join("out.I")).unwrap(),
        sing().into_bytes()
    );
}
