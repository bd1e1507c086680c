//! The no-zone fast path (`far::far_from_pole`) answers only with the full path's answer:
//! on every fixture, both machines and several cones, when it says "far" the full
//! pipeline leaves the program unchanged and reports the same thing.

use polepatch::far::far_from_pole;
use polepatch::kinematics::Machine;
use polepatch::program::load_nc;
use polepatch::{PatchOptions, patch_loaded};
use std::path::PathBuf;

fn fixtures() -> Vec<PathBuf> {
    polepatch_fixturegen::nc_files(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures"),
    )
}

#[test]
fn far_means_what_the_full_path_says() {
    let mut far = 0;
    let mut near = 0;
    for path in fixtures() {
        let bytes = std::fs::read(&path).unwrap();
        for machine in ["mikron-ucp710", "mikron-hsm600"] {
            let machine = Machine::builtin(machine).unwrap();
            for cone_deg in [0.05, 5.0, 30.0] {
                let mut opts = PatchOptions {
                    name: path.display().to_string(),
                    ..PatchOptions::default()
                };
                opts.patch.cone_deg = cone_deg;
                let Some(report) = far_from_pole(&bytes, &machine, &opts).unwrap() else {
                    near += 1;
                    continue;
                };
                far += 1;
                let lp = load_nc(bytes.clone(), &opts.name, &machine, None).unwrap();
                let (out, full) = patch_loaded(&lp, &machine, &opts.patch);
                assert_eq!(out, bytes, "{}", path.display());
                assert_eq!(
                    format!("{report:?}"),
                    format!("{full:?}"),
                    "{} cone {cone_deg}",
                    path.display()
                );
            }
        }
    }
    // Both answers occur on the fixtures (the generated d20 programs are far at 5°, the
    // near-pole ones near).
    assert!(far >= 20 && near >= 100, "far {far}, near {near}");
}

/// A file with a syntax error far from the pole gets the full path's error (line and
/// column), not a copy.
#[test]
fn errors_anywhere_are_found() {
    let machine = Machine::builtin("mikron-ucp710").unwrap();
    let mut text = String::from("%P G71 *\nN1 M128 *\nN2 G01 X0 Y0 Z0 A30 C0 F1000 *\n");
    for k in 0..50_000 {
        text.push_str(&format!("N{k} X{} A30 C{} *\n", k % 100, k % 360));
    }
    text.push_str("N9 X1..2 *\n");
    let opts = PatchOptions::default();
    assert!(
        far_from_pole(b"G1 X0 Y0 Z0 A30 C0 F1000\nX1 C1\n", &machine, &opts)
            .unwrap()
            .is_some()
    );
    let e = far_from_pole(text.as_bytes(), &machine, &opts).unwrap_err();
    let full = polepatch::patch_nc(text.as_bytes(), &machine, &opts).unwrap_err();
    assert_eq!(e.to_string(), full.to_string());
    assert!(e.to_string().contains(":50004:"), "{e}");
}
