//! polepatch on LinuxCNC's own planner (issue 31, check 1): a headless LinuxCNC 2.9
//! simulation (Debian's `linuxcnc-uspace`) with `[FILTER]` set to `polepatch filter` opens
//! C17's SING in LinuxCNC syntax, runs the patched program, and takes less time than the
//! unpatched one. Built and driven by `benches/linuxcnc/lcnc_bench.py`.
//!
//! Where LinuxCNC is not installed the test says so and passes without running
//! (`.ci/run` installs it when it runs as root with apt-get).

mod common;
use common::{root, temp_dir};
use std::process::Command;

const PYTHON: &str = "/usr/bin/python3";

/// Why LinuxCNC cannot run here, if it cannot.
fn missing() -> Option<String> {
    let which = Command::new("sh")
        .args(["-c", "command -v linuxcnc"])
        .output();
    if !which.is_ok_and(|o| o.status.success()) {
        return Some("the `linuxcnc` command is not installed".into());
    }
    let module = Command::new(PYTHON)
        .args(["-c", "import linuxcnc, hal"])
        .output();
    if !module.is_ok_and(|o| o.status.success()) {
        return Some(format!("{PYTHON} cannot import the `linuxcnc` module"));
    }
    None
}

fn bench(args: &[&str]) -> std::process::Output {
    Command::new(PYTHON)
        .arg(root().join("benches/linuxcnc/lcnc_bench.py"))
        .args(args)
        .env("POLEPATCH", env!("CARGO_BIN_EXE_polepatch"))
        .current_dir(root())
        .output()
        .unwrap()
}

#[test]
fn linuxcnc_runs_sing_through_the_filter_faster() {
    if let Some(why) = missing() {
        eprintln!(
            "SKIPPED linuxcnc_runs_sing_through_the_filter_faster: {why} \
             (apt-get install linuxcnc-uspace to run it)"
        );
        return;
    }
    let d = temp_dir("linuxcnc");
    let converted = bench(&["convert", "fixtures/c17/SING.I"]);
    assert!(converted.status.success());
    let program = d.join("SING.ngc");
    std::fs::write(&program, &converted.stdout).unwrap();
    let run = |filter: bool| -> serde_json::Value {
        let json = d.join(if filter { "after.json" } else { "before.json" });
        let mut args = vec![
            "run",
            program.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--json",
            json.to_str().unwrap(),
        ];
        if filter {
            args.push("--filter");
        }
        let out = bench(&args);
        let doc: serde_json::Value = std::fs::read_to_string(&json)
            .ok()
            .and_then(|t| serde_json::from_str(&t).ok())
            .unwrap_or_else(|| panic!("no result: {}", String::from_utf8_lossy(&out.stderr)));
        assert!(doc["error"].is_null(), "LinuxCNC: {}", doc["error"]);
        doc
    };
    let before = run(false);
    let after = run(true);
    let filter = &after["filter"];
    assert_eq!(filter["exit"], 0, "{filter}");
    assert!(
        filter["command"]
            .as_str()
            .unwrap()
            .contains("filter --machine"),
        "{filter}"
    );
    assert_eq!(filter["progress"].as_array().unwrap().last().unwrap(), 100);
    assert!(
        filter["stderr"]
            .as_str()
            .unwrap()
            .contains("1 reach the programmed feed"),
        "{filter}"
    );
    let t0 = before["cycle_time_s"].as_f64().unwrap();
    let t1 = after["cycle_time_s"].as_f64().unwrap();
    eprintln!("LinuxCNC: SING {t0:.3} s → {t1:.3} s through polepatch filter");
    assert!(t0 > 20.0, "the run completed: {t0} s");
    assert!(t1 < t0 - 0.5, "faster after: {t0} s → {t1} s");
    std::fs::remove_dir_all(&d).unwrap();
}
