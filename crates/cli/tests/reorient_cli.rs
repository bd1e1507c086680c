//! `polepatch reorient` as a user runs it.

mod common;
use common::{polepatch, root, temp_dir};

#[test]
fn given_angles_write_the_program_report_and_plot() {
    let dir = temp_dir("reorient");
    let out = dir.join("NON_SING.ours.I");
    let plot = dir.join("sphere.svg");
    let (code, stdout, err) = polepatch(&[
        "reorient",
        "fixtures/c17/SING.I",
        "--machine",
        "mikron-ucp710",
        "--theta-x",
        "10",
        "--theta-z",
        "180",
        "-o",
        out.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let doc: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(doc["theta_x_deg"], 10.0);
    assert!(doc["after"]["peak_speed"]["C"].as_f64().unwrap() < 20.0);
    assert!(doc["before"]["min_pole_distance_deg"].as_f64().unwrap() < 0.01);
    assert!(doc["after"]["min_pole_distance_deg"].as_f64().unwrap() > 9.9);
    assert!(err.contains("TCPM off (lines 4–6, 70–72, 75)"), "{err}");
    // Only words changed: the same lines, the same non-axis text.
    let a = std::fs::read_to_string(root().join("fixtures/c17/SING.I")).unwrap();
    let b = std::fs::read_to_string(&out).unwrap();
    assert_eq!(a.lines().count(), b.lines().count());
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("pole after the tilt"));
}

#[test]
fn leaving_the_range_is_refused_with_the_line_and_nothing_written() {
    let dir = temp_dir("reorient-r");
    let toml =
        std::fs::read_to_string(root().join("crates/kinematics/machines/mikron-ucp710.toml"))
            .unwrap()
            .replace("range_deg = [-100.0, 120.0]", "range_deg = [-30.0, 30.0]");
    let machine = dir.join("narrow.toml");
    std::fs::write(&machine, toml).unwrap();
    let out = dir.join("out.I");
    let (code, _, err) = polepatch(&[
        "reorient",
        "fixtures/c17/SING.I",
        "--machine",
        machine.to_str().unwrap(),
        "--theta-x",
        "25",
        "--theta-z",
        "180",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(
        err.contains("SING.I:") && err.contains("outside the machine's range"),
        "{err}"
    );
    assert!(!out.exists());
    // Output equal to the input.
    let (code, _, err) = polepatch(&[
        "reorient",
        "fixtures/c17/SING.I",
        "--machine",
        "mikron-ucp710",
        "--theta-x",
        "10",
        "--theta-z",
        "180",
        "-o",
        "fixtures/c17/SING.I",
    ]);
    assert_eq!(code, 1);
    assert!(
        err.contains("polepatch never writes over a file it reads"),
        "{err}"
    );
    // One angle alone is a usage error.
    let (code, _, _) = polepatch(&[
        "reorient",
        "fixtures/c17/SING.I",
        "--machine",
        "mikron-ucp710",
        "--theta-x",
        "10",
    ]);
    assert_ne!(code, 0);
}
