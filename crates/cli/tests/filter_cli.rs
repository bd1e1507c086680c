//! `polepatch filter` (LinuxCNC's `[FILTER]`), `-` for standard input and output in
//! `patch` (issue 31 item 1), and the smaller command-line defects of issue 26 item 4.

mod common;
use common::{polepatch, root, temp_dir};
use std::io::Write;
use std::process::{Command, Stdio};

/// Run the binary with `stdin` on standard input: (exit code, stdout bytes, stderr).
fn piped(args: &[&str], stdin: &[u8]) -> (i32, Vec<u8>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_polepatch"))
        .args(args)
        .current_dir(root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // A usage error may end the process before it reads its input: a broken pipe here is
    // not a failure (the exit code and stderr say what happened).
    if let Err(e) = child.stdin.take().unwrap().write_all(stdin) {
        assert_eq!(e.kind(), std::io::ErrorKind::BrokenPipe, "{e}");
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        out.stdout,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The file form's output of `fixtures/c17/SING.I` on the UCP710.
fn file_form(name: &str) -> Vec<u8> {
    let d = temp_dir(name);
    let out = d.join("SING.patched.I");
    let (code, _, err) = polepatch(&[
        "patch",
        "fixtures/c17/SING.I",
        "-o",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(&out).unwrap();
    std::fs::remove_dir_all(&d).unwrap();
    bytes
}

#[test]
fn patch_dash_reads_stdin_and_writes_stdout_byte_for_byte_as_the_file_form() {
    let expected = file_form("dash");
    let input = std::fs::read(root().join("fixtures/c17/SING.I")).unwrap();
    assert_ne!(expected, input, "SING is patched");
    let (code, out, err) = piped(
        &["patch", "-", "-o", "-", "--machine", "mikron-ucp710"],
        &input,
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, expected, "standard output is the file form's output");
    // The summary goes to standard error when the program is on standard output.
    assert!(err.contains("<stdin>") && err.contains("reached"), "{err}");
    // No file named `-` was made.
    assert!(!root().join("-").exists());
}

#[test]
fn patch_dash_refuses_out_dir_and_two_standard_outputs_as_usage_errors() {
    let (code, _, err) = piped(
        &[
            "patch",
            "-",
            "--out-dir",
            "/tmp",
            "--machine",
            "mikron-ucp710",
        ],
        b"",
    );
    assert_eq!(code, 64, "{err}");
    assert!(err.contains("standard input"), "{err}");
    let (code, out, err) = piped(
        &[
            "patch",
            "fixtures/c17/SING.I",
            "-o",
            "-",
            "--report",
            "-",
            "--machine",
            "mikron-ucp710",
        ],
        b"",
    );
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty());
    assert!(err.contains("standard output"), "{err}");
}

#[test]
fn filter_prints_the_patched_program_and_progress_and_summary_on_stderr() {
    let expected = file_form("filter");
    let (code, out, err) = piped(
        &[
            "filter",
            "--machine",
            "mikron-ucp710",
            "fixtures/c17/SING.I",
        ],
        b"",
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, expected);
    // LinuxCNC's progress protocol: `FILTER_PROGRESS=N` lines, N in percent, rising to 100.
    let progress: Vec<u32> = err
        .lines()
        .filter_map(|l| l.strip_prefix("FILTER_PROGRESS="))
        .map(|n| n.parse().unwrap())
        .collect();
    assert_eq!(progress.first(), Some(&0), "{err}");
    assert_eq!(progress.last(), Some(&100), "{err}");
    assert!(progress.windows(2).all(|w| w[0] < w[1]), "{progress:?}");
    assert!(
        err.contains("1 singular zone(s)") && err.contains("1 reach the programmed feed"),
        "{err}"
    );
    // Standard input too.
    let input = std::fs::read(root().join("fixtures/c17/SING.I")).unwrap();
    let (code, out, _) = piped(&["filter", "--machine", "mikron-ucp710", "-"], &input);
    assert_eq!((code, out), (0, expected));
}

#[test]
fn filter_refuses_bad_input_with_nothing_on_stdout_and_a_clear_message() {
    let (code, out, err) = piped(
        &["filter", "--machine", "mikron-ucp710", "-"],
        b"G1 X1 Y2 A3 C4 F100\nG1 X2 C12..5\n",
    );
    assert_eq!(code, 1, "{err}");
    assert!(
        out.is_empty(),
        "nothing loaded: {}",
        String::from_utf8_lossy(&out)
    );
    assert!(
        err.contains("polepatch: error:") && err.contains("<stdin>:2"),
        "{err}"
    );
    let (code, out, err) = piped(&["filter", "--machine", "no-such-machine", "-"], b"G1 X1\n");
    assert_eq!(code, 1, "{err}");
    assert!(out.is_empty());
    assert!(err.contains("no-such-machine"), "{err}");
}

#[test]
fn filter_strict_refuses_a_zone_below_feed_with_the_strict_code() {
    // A cap of 0.001° allows almost no orientation change: SING's zone stays below feed.
    let (code, out, err) = piped(
        &[
            "filter",
            "--machine",
            "mikron-ucp710",
            "--strict",
            "--max-deviation",
            "0.001",
            "--only-c",
            "fixtures/c17/SING.I",
        ],
        b"",
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("refused (--strict)"), "{err}");
    // The program was printed (a filter's output is only loaded on exit 0).
    assert!(!out.is_empty());
}

/// Issue 26 item 4: usage errors exit 64 (sysexits' EX_USAGE), apart from `--strict`'s 2.
#[test]
fn usage_errors_exit_64_not_the_strict_code() {
    for args in [
        &["patch", "--bogus"][..],
        &["patch", "fixtures/c17/SING.I", "--machine", "mikron-ucp710"],
        &["analyze"],
        &[
            "analyze",
            "fixtures/c17/SING.I",
            "--machine",
            "mikron-ucp710",
            "--cone",
            "-1",
        ],
        &[
            "patch",
            "fixtures/c17/SING.I",
            "-o",
            "/tmp/x.I",
            "--machine",
            "mikron-ucp710",
            "--margin",
            "0.7",
        ],
    ] {
        let (code, _, err) = polepatch(args);
        assert_eq!(code, 64, "{args:?}: {err}");
    }
    let (code, out, _) = polepatch(&["--help"]);
    assert_eq!(code, 0);
    assert!(out.contains("filter"));
}

/// Issue 26 item 4: a negative work offset needs no `=`.
#[test]
fn a_negative_work_offset_is_accepted_without_equals() {
    let with_eq = polepatch(&[
        "analyze",
        "fixtures/c17/SING.I",
        "--machine",
        "crates/kinematics/machines/mikron-ucp710-example-chain.toml",
        "--work-offset=-30.489,-7.1,38.054",
        "--json",
    ]);
    let without = polepatch(&[
        "analyze",
        "fixtures/c17/SING.I",
        "--machine",
        "crates/kinematics/machines/mikron-ucp710-example-chain.toml",
        "--work-offset",
        "-30.489,-7.1,38.054",
        "--json",
    ]);
    assert_eq!(without.0, 0, "{}", without.2);
    assert_eq!(with_eq, without);
    // A value that is not X,Y,Z is still refused.
    let (code, _, err) = polepatch(&[
        "analyze",
        "fixtures/c17/SING.I",
        "--machine",
        "mikron-ucp710",
        "--work-offset",
        "-30",
    ]);
    assert_eq!(code, 64, "{err}");
    assert!(err.contains("X,Y,Z"), "{err}");
}

/// `simulate --planner linuxcnc`: the model's times, slower than L/F on SING's near-pole
/// run (the segment-stop rule) and faster after the patch.
#[test]
fn simulate_with_the_linuxcnc_planner_model() {
    let d = temp_dir("lcnc-model");
    let patched = d.join("SING.patched.I");
    std::fs::write(&patched, file_form("lcnc-model-src")).unwrap();
    let (code, out, err) = polepatch(&[
        "simulate",
        "fixtures/c17/SING.I",
        patched.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--planner",
        "linuxcnc",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let total = |k: usize| doc[k]["time_s"].as_f64().unwrap();
    let ideal = doc[0]["ideal_time_s"].as_f64().unwrap();
    assert!(total(0) > 1.2 * ideal, "{} against L/F {ideal}", total(0));
    assert!(total(1) < total(0) - 0.5, "{} → {}", total(0), total(1));
    let (code, _, err) = polepatch(&[
        "simulate",
        "fixtures/c17/SING.I",
        "--machine",
        "mikron-ucp710",
        "--planner",
        "linuxcnc",
        "--plot",
        "/tmp/x.svg",
    ]);
    assert_eq!(code, 64, "{err}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// Issue 26 item 4: a patch killed outright leaves `.<name>.polepatch-tmp-XXXXXX`; the next
/// run that writes the same output removes it and says so.
#[test]
fn the_next_run_removes_the_temporary_file_of_a_killed_run() {
    let d = temp_dir("stale-tmp");
    let stale = d.join(".SING.patched.I.polepatch-tmp-k1lLed");
    let f = std::fs::File::create(&stale).unwrap();
    f.set_modified(std::time::SystemTime::now() - std::time::Duration::from_secs(3600))
        .unwrap();
    drop(f);
    let out = d.join("SING.patched.I");
    let (code, _, err) = polepatch(&[
        "patch",
        "fixtures/c17/SING.I",
        "-o",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!stale.exists());
    assert!(
        err.contains("polepatch-tmp-k1lLed") && err.contains("killed"),
        "{err}"
    );
    let names: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("SING.patched.I")]);
    std::fs::remove_dir_all(&d).unwrap();
}
