//! `polepatch simulate`: the table and JSON, the trajectory CSV (columns, one row per
//! cycle, full precision, the runs' ends), the plot, two programs compared, and refusals.

mod common;

use common::{polepatch, root, temp_dir};

#[test]
fn json_trajectory_and_plot() {
    let dir = temp_dir("simulate-cli");
    let csv = dir.join("sing.csv");
    let svg = dir.join("sing.svg");
    let (code, out, err) = polepatch(&[
        "simulate",
        "fixtures/c17/SING.I",
        "-m",
        "mikron-ucp710",
        "--json",
        "--trajectory",
        csv.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let rep = &doc[0];
    let total = rep["total"]["time_s"].as_f64().unwrap();
    assert!(total >= rep["total"]["eq6_time_s"].as_f64().unwrap());
    let runs = rep["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 3);
    // The CSV: header, one row per cycle, each run from s = 0 to its length.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("run,t_s,s_mm,X,Y,Z,A,C,feed_mm_min"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect())
        .collect();
    assert!(rows.iter().all(|r| r.len() == 9));
    for run in runs {
        let n = run["run"].as_f64().unwrap();
        let mine: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] == n).collect();
        assert_eq!(mine[0][2], 0.0);
        let len = run["length_mm"].as_f64().unwrap();
        assert!((mine.last().unwrap()[2] - len).abs() < 1e-6);
        // Interpolation cycles of 1 ms, each state once; the last step may be partial, or
        // the rest-to-rest creep over the last nanometres (`pass.rs`, END_MM: a few ms).
        for (k, w) in mine.windows(2).enumerate() {
            let dt = w[1][1] - w[0][1];
            let last = k + 2 == mine.len();
            assert!(
                (dt - 1e-3).abs() < 1e-9 || (last && dt > 0.0 && dt < 1e-2),
                "dt = {dt}"
            );
        }
    }
    let last_t = rows.last().unwrap()[1];
    assert!((last_t - total).abs() < 1e-9, "{last_t} vs {total}");
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(plot.starts_with("<svg") && plot.contains("feed along s"));
}

#[test]
fn two_programs_are_compared_and_outputs_never_overwrite_inputs() {
    let dir = temp_dir("simulate-cli-2");
    let patched = dir.join("SING.patched.I");
    let (code, _, err) = polepatch(&[
        "patch",
        "fixtures/c17/SING.I",
        "-m",
        "mikron-ucp710",
        "-o",
        patched.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = polepatch(&[
        "simulate",
        "fixtures/c17/SING.I",
        patched.to_str().unwrap(),
        "-m",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("against fixtures/c17/SING.I: simulated"),
        "{out}"
    );
    // The trajectory may not be an input.
    let input = root().join("fixtures/c17/SING.I");
    let before = std::fs::read(&input).unwrap();
    let (code, _, err) = polepatch(&[
        "simulate",
        "fixtures/c17/SING.I",
        "-m",
        "mikron-ucp710",
        "--trajectory",
        "fixtures/c17/SING.I",
    ]);
    assert_ne!(code, 0);
    assert!(
        err.contains("polepatch never writes over a file it reads"),
        "{err}"
    );
    assert_eq!(std::fs::read(&input).unwrap(), before);
    // One trajectory, one program.
    let (code, _, err) = polepatch(&[
        "simulate",
        "fixtures/c17/SING.I",
        patched.to_str().unwrap(),
        "-m",
        "mikron-ucp710",
        "--trajectory",
        dir.join("t.csv").to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(err.contains("give one program"), "{err}");
}

/// `--planner cycles --rewind`: the same program simulates with fewer cycles put on the
/// velocity limit (the `clips` of the JSON) than `--planner cycles` alone and no faster;
/// the default planner puts none there. `--rewind` is refused (usage, 64) without
/// `--planner cycles`.
#[test]
fn rewind_puts_fewer_cycles_on_the_limit() {
    let run = |extra: &[&str]| {
        let mut args = vec![
            "simulate",
            "fixtures/c17/SING.I",
            "-m",
            "mikron-ucp710",
            "--json",
        ];
        args.extend_from_slice(extra);
        let (code, out, err) = polepatch(&args);
        assert_eq!(code, 0, "{err}");
        let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
        let total = &doc[0]["total"];
        (
            total["time_s"].as_f64().unwrap(),
            total["clips"].as_u64().unwrap(),
        )
    };
    let (_, clips_default) = run(&[]);
    assert_eq!(clips_default, 0);
    let (t_cycles, clips_cycles) = run(&["--planner", "cycles"]);
    let (t_rewind, clips_rewind) = run(&["--planner", "cycles", "--rewind"]);
    assert!(
        clips_rewind < clips_cycles,
        "{clips_rewind} cycles on the limit with --rewind, {clips_cycles} without"
    );
    assert!(
        t_rewind >= t_cycles * (1.0 - 1e-3),
        "{t_rewind} s against {t_cycles} s"
    );
    for planner in ["linuxcnc", "jerk"] {
        let (code, _, err) = polepatch(&[
            "simulate",
            "fixtures/c17/SING.I",
            "-m",
            "mikron-ucp710",
            "--planner",
            planner,
            "--rewind",
        ]);
        assert_eq!(code, 64, "{err}");
        assert!(err.contains("--rewind"), "{err}");
    }
}

/// Issue 43, "one answer": a program with nothing to simulate says so, whatever output
/// was asked for (before: "error: writing the trajectory /dev/null: … no G1 motion"), and
/// the trajectory is its columns alone.
#[test]
fn a_program_of_rapid_moves_has_nothing_to_simulate() {
    let dir = temp_dir("simulate-cli-rapids");
    let prog = dir.join("rapids.I");
    std::fs::write(
        &prog,
        "%L G71 *\nN10 G90 *\nN20 G00 X+0 Y+0 Z+0 A+20 C+30 *\nN30 X+10 *\nN40 M30 *\n",
    )
    .unwrap();
    let csv = dir.join("t.csv");
    for extra in [vec![], vec!["--trajectory", csv.to_str().unwrap()]] {
        let mut args = vec!["simulate", prog.to_str().unwrap(), "-m", "mikron-ucp710"];
        args.extend(extra);
        let (code, out, err) = polepatch(&args);
        assert_eq!(code, 0, "{err}");
        assert!(
            out.contains("nothing to simulate: the program has no G1 motion"),
            "{out}"
        );
        assert!(!err.contains("error"), "{err}");
    }
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        "run,t_s,s_mm,X,Y,Z,A,C,feed_mm_min\n"
    );
    let (code, out, _) = polepatch(&[
        "simulate",
        prog.to_str().unwrap(),
        "-m",
        "mikron-ucp710",
        "--json",
    ]);
    assert_eq!(code, 0);
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(doc[0]["nothing_to_simulate"].is_string(), "{out}");
}

/// Issue 43: feeds print as numbers a person can use (F0.0001 was printed "F0") and the
/// totals of a program whose runs all fail are not "(NaN %)".
#[test]
fn tiny_feeds_and_empty_totals_print_as_numbers() {
    let dir = temp_dir("simulate-cli-tiny-feed");
    let prog = dir.join("slow.I");
    std::fs::write(
        &prog,
        "%L G71 *\nN10 G90 *\nN20 G01 X+0 Y+0 Z+0 A+20 C+30 F0.0001 *\nN30 X+0.001 *\nN40 M30 *\n",
    )
    .unwrap();
    let (code, out, err) = polepatch(&["simulate", prog.to_str().unwrap(), "-m", "mikron-ucp710"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("F0.0001 mm/min"), "{out}");
    assert!(!out.contains("NaN") && !err.contains("NaN"), "{out}{err}");
    assert!(out.contains("no run simulated"), "{out}");
}

/// Issue 43: a G93 block's F0 is named at its own line (7), as the inverse-time feed it
/// is — not at the run's first line in mm/min.
#[test]
fn an_inverse_time_f0_is_named_at_its_line() {
    let dir = temp_dir("simulate-cli-g93");
    let prog = dir.join("g93.ngc");
    std::fs::write(
        &prog,
        "G21 G90\nG94\nG1 X0 Y0 Z0 A20 C30 F1000\nX1\nX2\nG93\nG1 X3 F0\nX4 F1\nM30\n",
    )
    .unwrap();
    let (code, _, err) = polepatch(&["simulate", prog.to_str().unwrap(), "-m", "mikron-ucp710"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("line 7: inverse-time feed F0 (G93, 1/min)"),
        "{err}"
    );
}

/// Issue 40: `--units` reaches the simulator. A program that states no units, read in
/// inches by `simulate --units inch` (lengths ×25.4), and `patch --units inch --simulate`
/// simulates the same inch reading it patched (it simulated a millimetre reading before).
#[test]
fn units_reach_the_simulation() {
    let dir = temp_dir("simulate-units");
    let text = std::fs::read_to_string(root().join("fixtures/shop/ac-flip-d0.5-fanuc-g94.nc"))
        .unwrap()
        .replace("G90 G21 G94", "G90 G94");
    let prog = dir.join("no-units.nc");
    std::fs::write(&prog, &text).unwrap();
    let p = prog.to_str().unwrap();
    let sim = |units: &[&str]| -> serde_json::Value {
        let mut args = vec!["simulate", p, "-m", "mikron-ucp710", "--json"];
        args.extend_from_slice(units);
        let (code, out, err) = polepatch(&args);
        assert_eq!(code, 0, "{err}");
        serde_json::from_str::<serde_json::Value>(&out).unwrap()[0].clone()
    };
    let (mm, inch) = (sim(&[]), sim(&["--units", "inch"]));
    let length = |r: &serde_json::Value| r["runs"][0]["length_mm"].as_f64().unwrap();
    assert!((length(&inch) / length(&mm) - 25.4).abs() < 1e-9);
    let total = |r: &serde_json::Value| r["total"]["time_s"].as_f64().unwrap();
    assert!((total(&inch) - total(&mm)).abs() > 0.01 * total(&mm));
    let report = dir.join("r.json");
    let (code, _, err) = polepatch(&[
        "patch",
        p,
        "-m",
        "mikron-ucp710",
        "--units",
        "inch",
        "--simulate",
        "-o",
        dir.join("out.nc").to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let before = r["simulated"]["before_s"].as_f64().unwrap();
    assert!(
        (before - total(&inch)).abs() <= 1e-9 * before,
        "{before} vs {} (mm: {})",
        total(&inch),
        total(&mm)
    );
}
