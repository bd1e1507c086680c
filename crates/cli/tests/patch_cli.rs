//! `polepatch patch` as a user runs it: one file, a folder batch, --strict, refusals.

mod common;
use common::{assert_only_rotary_words_differ, polepatch, root, temp_dir};
use polepatch_fixturegen::{Dialect, Pass, program};

#[test]
fn one_file_with_report() {
    let dir = temp_dir("one");
    let out = dir.join("SING.out.I");
    let report = dir.join("r.json");
    let (code, stdout, err) = polepatch(&[
        "patch",
        "fixtures/c17/SING.I",
        "-o",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--report",
        report.to_str().unwrap(),
        "--strict",
        // An M128 program: X Y Z are the ball's centre (--strict needs the tool known).
        "--tool",
        "ball:10",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("SING.I"), "{stdout}");
    let input = std::fs::read(root().join("fixtures/c17/SING.I")).unwrap();
    assert_only_rotary_words_differ("SING", &input, &std::fs::read(&out).unwrap());
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let zones = doc["zones"].as_array().unwrap();
    assert_eq!(zones.len(), 1);
    assert_eq!(zones[0]["outcome"], "reached");
    // Issue 8: A and C both reach feed on SING (A's jerk held the C-only patch at 0.607).
    assert_eq!(zones[0]["after"]["c_ratio"].as_f64().unwrap(), 1.0);
    assert_eq!(zones[0]["after"]["primary_ratio"].as_f64().unwrap(), 1.0);
    assert!(zones[0]["primary_points_modified"].as_u64().unwrap() > 0);
    // The output has the input's permissions, not the temporary file's owner-only mode.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&out), mode(&root().join("fixtures/c17/SING.I")));
        assert_eq!(mode(&report), 0o644);
    }
    // Nothing but the output and the report in the folder: no temporary file left behind.
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(names, ["SING.out.I", "r.json"]);
}

#[test]
fn folder_batch_with_csv() {
    let dir = temp_dir("batch");
    let out = dir.join("out");
    let csv = dir.join("zones.csv");
    let (code, stdout, err) = polepatch(&[
        "patch",
        "fixtures/c17",
        "fixtures/dialects",
        "--out-dir",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    for f in [
        "c17/SING.I",
        "c17/NON_SING.I",
        "dialects/fanuc.nc",
        "dialects/sinumerik.mpf",
    ] {
        assert!(out.join(f).exists(), "{f} missing; stdout: {stdout}");
    }
    // The program without zone is byte-identical.
    assert_eq!(
        std::fs::read(out.join("c17/NON_SING.I")).unwrap(),
        std::fs::read(root().join("fixtures/c17/NON_SING.I")).unwrap()
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    assert!(text.starts_with("file,run,first_line"), "{text}");
    assert!(text.lines().count() >= 4, "{text}");
}

#[test]
fn strict_exits_2_when_a_zone_stays_below_feed() {
    // 15 mm at F5000 on the UCP710 with the last point held by the move after it: no values
    // reach feed (tests/patch.rs has the proof).
    let pass = Pass {
        pole_distance_deg: 1.0,
        circle_radius_deg: 5.0,
        half_sweep_deg: 80.0,
        azimuth_deg: 0.0,
        length_mm: 15.0,
        spacing_mm: 0.5,
        feed_mm_min: 5000.0,
        b_axis: false,
        domain_rule: false,
        rotary_decimals: 3,
    };
    let dir = temp_dir("strict");
    let input = dir.join("short.nc");
    let text =
        program(&pass, Dialect::Fanuc, "SHORT").replace("\nG49\n", "\nG0 Z50. A0. C0.\nG49\n");
    std::fs::write(&input, text).unwrap();
    let out = dir.join("short.out.nc");
    let args = [
        "patch",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ];
    let (code, _, err) = polepatch(&args);
    assert_eq!(code, 0, "{err}");
    let mut strict = args.to_vec();
    strict.push("--strict");
    let (code, _, err) = polepatch(&strict);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("stay below feed"), "{err}");
}

/// Issue 8: `--only-c` keeps G16's C-only method and reproduces its output byte for byte
/// (the golden files were written by polepatch before the joint method existed).
#[test]
fn only_c_reproduces_the_c_only_output() {
    let dir = temp_dir("onlyc");
    // SING is an A-C program: on the B-C machine it is refused (issue 29).
    // (SING is an A-C program: the B-C machine refuses it, issue 29.)
    {
        let m = "mikron-ucp710";
        let out = dir.join(format!("SING.{m}.I"));
        let (code, _, err) = polepatch(&[
            "patch",
            "fixtures/c17/SING.I",
            "-o",
            out.to_str().unwrap(),
            "--machine",
            m,
            "--only-c",
        ]);
        assert_eq!(code, 0, "{err}");
        let golden = root().join(format!("crates/cli/tests/data/SING.only-c.{m}.I"));
        assert_eq!(
            std::fs::read(&out).unwrap(),
            std::fs::read(golden).unwrap(),
            "{m}: --only-c output changed"
        );
    }
}

#[test]
fn refusals() {
    let dir = temp_dir("refuse");
    let input = dir.join("SING.I");
    std::fs::copy(root().join("fixtures/c17/SING.I"), &input).unwrap();
    let before = std::fs::read(&input).unwrap();
    let (code, _, err) = polepatch(&[
        "patch",
        input.to_str().unwrap(),
        "-o",
        input.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 1);
    assert!(
        err.contains("polepatch never writes over a file it reads"),
        "{err}"
    );
    assert_eq!(std::fs::read(&input).unwrap(), before);
    // A syntax error: no output file at all.
    let bad = dir.join("bad.nc");
    std::fs::write(&bad, "G1 X0 Y0 Z0 A1 C0 F1000\nX1 C1..5\n").unwrap();
    let out = dir.join("bad.out.nc");
    let (code, _, err) = polepatch(&[
        "patch",
        bad.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("bad.nc:2:"), "{err}");
    assert!(!out.exists());
    // No output named: a usage error (exit 64, issue 26 item 4).
    let (code, _, err) = polepatch(&["patch", "fixtures/c17/SING.I", "--machine", "mikron-ucp710"]);
    assert_eq!(code, 64);
    assert!(err.contains("-o OUTPUT"), "{err}");
}

/// Issue 10's check: `SING.I` without `M128` (X Y Z are machine coordinates): no rotary
/// word changes, a clear report line, exit 0; exit 2 with --strict.
#[test]
fn no_tcpm_is_never_patched() {
    let dir = temp_dir("notcpm");
    let input = dir.join("SING_noM128.I");
    let text = std::fs::read_to_string(root().join("fixtures/c17/SING.I")).unwrap();
    std::fs::write(&input, text.replace("N65 M128 *\n", "")).unwrap();
    let out = dir.join("out.I");
    let report = dir.join("r.json");
    let args = [
        "patch",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--report",
        report.to_str().unwrap(),
    ];
    let (code, _, err) = polepatch(&args);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&input).unwrap());
    assert!(err.contains("run 1, lines 12–66: no TCPM active"), "{err}");
    assert!(
        err.contains("1 run(s) with singular zones left as they are"),
        "{err}"
    );
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    assert_eq!(doc["words_changed"], 0);
    assert_eq!(doc["untouched_runs"][0]["reason"], "no_tcpm");
    let mut strict = args.to_vec();
    strict.push("--strict");
    let (code, _, err) = polepatch(&strict);
    assert_eq!(code, 2, "{err}");
}

/// Issue 11: the CLI writes what the library (`polepatch::patch_nc`, also behind the C
/// ABI) returns, bytes and report, on the C17 and dialect fixtures × both machines.
#[test]
fn the_cli_writes_what_the_library_returns() {
    let dir = temp_dir("same");
    for file in [
        "fixtures/c17/SING.I",
        "fixtures/c17/NON_SING.I",
        "fixtures/dialects/fanuc.nc",
        "fixtures/dialects/sinumerik.mpf",
        "fixtures/dialects/heidenhain_latin1.I",
    ] {
        for machine in ["mikron-ucp710", "mikron-hsm600"] {
            let out = dir.join("out");
            let report = dir.join("report.json");
            let (code, _, err) = polepatch(&[
                "patch",
                file,
                "-o",
                out.to_str().unwrap(),
                "--machine",
                machine,
                "--report",
                report.to_str().unwrap(),
            ]);
            let opts = polepatch::PatchOptions::named(file);
            let m = polepatch::kinematics::Machine::builtin(machine).unwrap();
            let library =
                polepatch::patch_nc(&std::fs::read(root().join(file)).unwrap(), &m, &opts);
            // A program posted for the other machine: the same refusal from both.
            if let Err(e) = &library {
                assert!(
                    matches!(e, polepatch::Error::ForeignAxis { .. }),
                    "{file} {machine}: {e}"
                );
                assert_eq!(code, 1, "{file} {machine}: {err}");
                assert!(err.contains(&e.to_string()), "{file} {machine}: {err}");
                continue;
            }
            assert_eq!(code, 0, "{file} {machine}: {err}");
            let (want, want_report) = library.unwrap();
            assert_eq!(std::fs::read(&out).unwrap(), want, "{file} {machine}");
            let strip = |mut v: serde_json::Value| {
                v.as_object_mut().unwrap().remove("output");
                for z in v["zones"].as_array_mut().unwrap() {
                    z.as_object_mut().unwrap().remove("solve_time_ms");
                }
                v
            };
            let got: serde_json::Value =
                serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
            assert_eq!(
                strip(got),
                strip(serde_json::to_value(&want_report).unwrap()),
                "{file} {machine}"
            );
        }
    }
}

/// Issue 21 §6: options mean what they say. G16's join options need `--only-c` (the
/// default method has no joins) and are refused without it; `--max-patch-length` holds for
/// the default method too; the summary counts the zones' reasons.
#[test]
fn options_mean_what_they_say() {
    let dir = temp_dir("options");
    let out = dir.join("o.I");
    let o = out.to_str().unwrap();
    for flag in ["--c-offset", "--no-jerk-continuity"] {
        let (code, _, err) = polepatch(&[
            "patch",
            "fixtures/c17/SING.I",
            "-o",
            o,
            "--machine",
            "mikron-ucp710",
            flag,
        ]);
        // A usage error: 64, not --strict's 2 (issue 26 item 4).
        assert_eq!(code, 64, "{flag}: {err}");
        assert!(err.contains("--only-c"), "{flag}: {err}");
        assert!(!out.exists(), "{flag}: nothing written");
    }
    let report = dir.join("r.json");
    let (code, stdout, err) = polepatch(&[
        "patch",
        "fixtures/c17/SING.I",
        "-o",
        o,
        "--machine",
        "mikron-ucp710",
        "--max-patch-length",
        "12",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("reasons:"), "{stdout}");
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    for z in doc["zones"].as_array().unwrap() {
        assert!(z["patch_length_mm"].as_f64().unwrap() <= 12.0 + 1e-9, "{z}");
        assert!(z["reason"].is_string(), "{z}");
    }
}

/// Issue 27 §5: no tool given and none in the program (SING calls T5 without describing
/// it): the file is patched as before, the table's tool column says unknown, the report
/// gives every changed zone's centre shift per mm of radius, one warning says how to give
/// the tool, and `--strict` exits 2. Given the tool, `--strict` passes.
#[test]
fn an_unknown_tool_warns_and_fails_strict() {
    let dir = temp_dir("unknown-tool");
    let out = dir.join("SING.out.I");
    let report = dir.join("r.json");
    let args = |strict: bool, tool: Option<&str>| {
        let mut a = vec![
            "patch",
            "fixtures/c17/SING.I",
            "-o",
            out.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--report",
            report.to_str().unwrap(),
        ];
        if strict {
            a.push("--strict");
        }
        if let Some(t) = tool {
            a.extend(["--tool", t]);
        }
        a.into_iter().map(String::from).collect::<Vec<String>>()
    };
    let run = |a: Vec<String>| {
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        polepatch(&refs)
    };
    let (code, stdout, err) = run(args(false, None));
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("unknown"), "the tool column: {stdout}");
    let warnings: Vec<&str> = err
        .lines()
        .filter(|l| l.contains("the tool is not known"))
        .collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(warnings[0].contains("--tool ball:D"), "{}", warnings[0]);
    assert!(
        warnings[0].contains("--tool-point tip|centre"),
        "{}",
        warnings[0]
    );
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let zones = doc["zones"].as_array().unwrap();
    assert!(!zones.is_empty());
    for z in zones {
        assert_eq!(z["tool"], "unknown");
        let dev = z["max_deviation_deg"].as_f64().unwrap();
        let per_mm = z["centre_shift_per_mm_radius"].as_f64().unwrap();
        assert!(dev > 0.0);
        assert!(
            (per_mm - 2.0 * (dev.to_radians() / 2.0).sin()).abs() < 1e-12,
            "{z}"
        );
    }
    // The patch is written all the same.
    assert_ne!(
        std::fs::read(&out).unwrap(),
        std::fs::read(root().join("fixtures/c17/SING.I")).unwrap()
    );

    let (code, _, err) = run(args(true, None));
    assert_eq!(code, 2, "--strict with the tool unknown: {err}");
    assert!(err.contains("the tool is not known"), "{err}");

    let (code, stdout, err) = run(args(true, Some("ball:10")));
    assert_eq!(code, 0, "--strict with the tool given: {err}");
    assert!(!err.contains("the tool is not known"), "{err}");
    assert!(stdout.contains("ball D10"), "{stdout}");
}

/// Issue 28 §3: the patcher's one rule set behind the flags — the refusal is the
/// library's, with the flag's name, a usage error (64), nothing written.
#[test]
fn options_are_refused_by_the_patchers_rules_naming_the_flag() {
    let dir = temp_dir("option-rules");
    let out = dir.join("o.I");
    let o = out.to_str().unwrap();
    for (flag, value, want) in [
        (
            "--max-deviation",
            "0",
            "--max-deviation must be a positive number of degrees, got 0",
        ),
        (
            "--margin=-0.1",
            "",
            "--margin must be a fraction in [0, 0.5), got -0.1",
        ),
        (
            "--max-decimals",
            "12",
            "--max-decimals must be at most 9, got 12",
        ),
        (
            "--pole-reach",
            "95",
            "--pole-reach must be an angle from 0 to 90 degrees, got 95",
        ),
    ] {
        let mut args = vec![
            "patch",
            "fixtures/c17/SING.I",
            "-o",
            o,
            "--machine",
            "mikron-ucp710",
            flag,
        ];
        if !value.is_empty() {
            args.push(value);
        }
        let (code, _, err) = polepatch(&args);
        assert_eq!(code, 64, "{flag}: {err}");
        assert!(err.contains(want), "{flag}: {err}");
        assert!(!out.exists(), "{flag}: nothing written");
    }
}
