//! Machine files end to end (issues 39 and 42): what a machine file says reaches the
//! analysis and the patch, and a machine that cannot be right is refused by name.

mod common;

use common::{polepatch, root, temp_dir};
use std::path::Path;

fn analyze_json(program: &str, machine: &str) -> serde_json::Value {
    let (code, out, err) = polepatch(&["analyze", program, "--machine", machine, "--json"]);
    assert_eq!(code, 0, "stderr: {err}");
    serde_json::from_str(&out).expect("one JSON document")
}

/// Every zone of an analysis, as (first line, last line, kind).
fn zones(doc: &serde_json::Value) -> Vec<(u64, u64, String)> {
    doc["runs"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r["zones"].as_array().unwrap().iter())
        .map(|z| {
            (
                z["lines"][0].as_u64().unwrap(),
                z["lines"][1].as_u64().unwrap(),
                z["kind"].as_str().unwrap().to_string(),
            )
        })
        .collect()
}

/// The UCP710 in the chain form with one line replaced, written to `dir`.
fn ucp710_edited(dir: &Path, name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(
        root().join("crates/kinematics/machines/mikron-ucp710-chain-form.toml"),
    )
    .unwrap();
    assert!(text.contains(from), "{from}");
    let path = dir.join(name);
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    path.to_str().unwrap().to_string()
}

/// Issue 39, class 6: `tool_direction = [0, 0, -1]` (the spindle below the tip) put the
/// pole 180° away and SING had "no singular zone". Its pole is the tool against C at
/// A = 0: SING's C-swing is found where the upright machine finds it.
#[test]
fn sing_has_its_zone_on_a_machine_whose_tool_points_up() {
    let dir = temp_dir("tool-up");
    let up = ucp710_edited(
        &dir,
        "up.toml",
        "tool_direction = [0.0, 0.0, 1.0]",
        "tool_direction = [0.0, 0.0, -1.0]",
    );
    let upright = zones(&analyze_json("fixtures/c17/SING.I", "mikron-ucp710"));
    assert_eq!(upright, [(32, 50, "c_swing".to_string())]);
    assert_eq!(zones(&analyze_json("fixtures/c17/SING.I", &up)), upright);
    let (code, _, err) = polepatch(&["analyze", "fixtures/c17/SING.I", "--machine", &up]);
    assert_eq!(code, 0);
    assert!(
        err.contains("points from the tip down to the spindle"),
        "{err}"
    );
}

/// Issue 39, class 6: a rotary direction `[1e-320, 0, 0]` gave NaN kinematics ("no singular
/// zone" with C at 192 rpm). Refused, naming the field.
#[test]
fn a_direction_too_short_to_normalise_is_refused_by_field() {
    let dir = temp_dir("denormal");
    let bad = ucp710_edited(
        &dir,
        "bad.toml",
        "direction = [1.0, 0.0, 0.0]",
        "direction = [1e-320, 0.0, 0.0]",
    );
    let (code, out, err) = polepatch(&["analyze", "fixtures/c17/SING.I", "--machine", &bad]);
    assert_eq!(code, 1, "{out}");
    assert!(
        err.contains("bad.toml") && err.contains("rotary[1].direction = [1e-320, 0, 0]"),
        "{err}"
    );
}

/// A pass that crosses 1° from the pole of a head-head C-B (the tool axis
/// `(u, 0.0175, 1)`, `u` from −0.2 to 0.2 along X), posted with 5axiskins' inverse
/// (`sin B = |o_xy|`, `C = atan2(−o_y, −o_x)`), with W words on its positioning and on one
/// point of the zone.
fn planted_bridge_pass() -> String {
    let pose = |x: f64| {
        let o = [x / 150.0, 0.0175, 1.0];
        let n = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt();
        let o = o.map(|v| v / n);
        let b = o[0].hypot(o[1]).atan2(o[2]).to_degrees();
        let c = (-o[1]).atan2(-o[0]).to_degrees();
        (b, c)
    };
    let (b0, c0) = pose(-30.0);
    let mut text = format!(
        "%\n(planted pass 1 deg from the pole of a head-head C-B)\nG21 G90 G94\n\
         G0 X-30 Y0 Z20 B{b0:.4} C{c0:.4} W0\nG1 Z0 F1000\n"
    );
    for k in 0..=60 {
        let x = -30.0 + k as f64;
        let (b, c) = pose(x);
        let w = if k == 31 { " W0" } else { "" };
        text.push_str(&format!("X{x:.3} Y0.000 Z0.000 B{b:.4} C{c:.4}{w}\n"));
    }
    text.push_str("G0 Z50 W10\nM2\n%\n");
    text
}

/// Issue 42 item 3: LinuxCNC's bridge mill (`5axiskins`, head-head C-B with a W quill) is
/// read from its INI; a pass near its pole is found and patched, W carried through.
#[test]
fn the_bridge_mill_ini_analyses_and_patches_with_w_carried() {
    let ini = "crates/kinematics/tests/linuxcnc/5axis-bridge/5axis-bridge.ini";
    let dir = temp_dir("bridge");
    let program = dir.join("pass.ngc");
    let text = planted_bridge_pass();
    std::fs::write(&program, &text).unwrap();
    let doc = analyze_json(program.to_str().unwrap(), ini);
    assert_eq!(doc["primary"], "B");
    assert_eq!(zones(&doc), [(29, 43, "c_swing".to_string())]);
    let out = dir.join("out.ngc");
    let report = dir.join("report.json");
    let (code, _, err) = polepatch(&[
        "patch",
        program.to_str().unwrap(),
        "--machine",
        ini,
        "-o",
        out.to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("moves the tool along its axis by W"), "{err}");
    let patched = std::fs::read_to_string(&out).unwrap();
    assert_ne!(patched, text);
    // Only B and C words changed: every other word, W among them, as written.
    let strip = |l: &str| -> String {
        l.split_whitespace()
            .filter(|w| !w.starts_with('B') && !w.starts_with('C'))
            .collect::<Vec<_>>()
            .join(" ")
    };
    assert_eq!(patched.lines().count(), text.lines().count());
    for (a, b) in text.lines().zip(patched.lines()) {
        assert_eq!(strip(a), strip(b));
    }
    assert!(patched.contains("X1.000 Y0.000 Z0.000 B") && patched.contains(" W0\n"));
    assert!(patched.contains("G0 Z50 W10\n"));
    let rep: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let zone = &rep["zones"][0];
    assert_eq!(zone["reason"], "reached", "{zone}");
}

/// LinuxCNC's own bridge-mill demo program (`5axisgui.ngc`, parametric: every axis word an
/// expression) on the bridge-mill INI: read without a crash, nothing analysable, the
/// output the input byte for byte (W words among it).
#[test]
fn linuxcncs_bridgemill_demo_is_carried_through() {
    let program = root().join("../shared/realworld/hunt3/lcnc_bridgemill_5axisgui.ngc");
    if !program.exists() {
        eprintln!("skipped: {} is not there", program.display());
        return;
    }
    let ini = "crates/kinematics/tests/linuxcnc/5axis-bridge/5axis-bridge.ini";
    let dir = temp_dir("bridge-demo");
    let out = dir.join("out.ngc");
    let (code, _, err) = polepatch(&[
        "patch",
        program.to_str().unwrap(),
        "--machine",
        ini,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read(&out).unwrap(),
        std::fs::read(&program).unwrap()
    );
    assert!(err.contains("W (first at line 18)"), "{err}");
}

/// Issue 39, class 6: a C range `[100, 200]` with SING at C 245° was patched as if the
/// program's values had to be brought into the range: the joint patch's range rows
/// (`crates/patcher/src/joint.rs`, "the machine's ranges as bounds on each point's
/// changes") force every point beyond 200° down to it, and the tool turned 6.25° in
/// silence. The program cannot run on that machine: it is an error at the first word
/// beyond the range — SING's `N36 A+0 C+0` (line 6, column 9), before its pass reaches
/// `C+211.506` — found by the survey (`Error::BeyondRange`).
#[test]
fn a_program_beyond_the_machines_c_range_is_refused_at_its_word() {
    let dir = temp_dir("c-range");
    let m = ucp710_edited(
        &dir,
        "c-range.toml",
        "# No range_deg: C is an endless rotary table.",
        "range_deg = [100.0, 200.0]",
    );
    let out = dir.join("out.I");
    let (code, _, err) = polepatch(&[
        "patch",
        "fixtures/c17/SING.I",
        "--machine",
        &m,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("SING.I:6:9: C0 is beyond") && err.contains("[100, 200]"),
        "{err}"
    );
    assert!(!out.exists());
}
