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

/// `--rewind`: the same program simulates with fewer cycles put on the velocity limit
/// (the `clips` of the JSON) and no faster than by default; refused (usage, 64) with the
/// LinuxCNC planner, which has no such cycles.
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
    let (t_default, clips_default) = run(&[]);
    let (t_rewind, clips_rewind) = run(&["--rewind"]);
    assert!(
        clips_rewind < clips_default,
        "{clips_rewind} cycles on the limit with --rewind, {clips_default} without"
    );
    assert!(
        t_rewind >= t_default * (1.0 - 1e-3),
        "{t_rewind} s against {t_default} s"
    );
    let (code, _, err) = polepatch(&[
        "simulate",
        "fixtures/c17/SING.I",
        "-m",
        "mikron-ucp710",
        "--planner",
        "linuxcnc",
        "--rewind",
    ]);
    assert_eq!(code, 64, "{err}");
    assert!(err.contains("--rewind"), "{err}");
}
