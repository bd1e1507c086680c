//! Issue 29: machines of other layouts. A head-table B-C and a head-head C-B machine (the
//! standard form: pole axis along Z called C, tilting axis about Y) read, analyse and patch
//! a planted pass 1° from the pole to feed on both rotary axes, and the deviation reported
//! is the angle an independent forward kinematics of that layout gives for the written
//! words; pairs whose zones, branches or letters are not wired yet (a 45° nutating table,
//! an A-B trunnion whose pole axis is B) are refused by name, never patched with the wrong
//! kinematics.

use polepatch::PatchOptions;
use polepatch::kinematics::Machine;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn machine(file: &str) -> Machine {
    Machine::from_file(&root().join("crates/kinematics/machines").join(file)).unwrap()
}

/// The (B, C) in force after each line of a Heidenhain ISO program (modal words).
fn rotary_per_line(text: &str) -> Vec<Option<(f64, f64)>> {
    let (mut b, mut c) = (None, None);
    text.lines()
        .map(|line| {
            for tok in line.split_whitespace() {
                let (l, v) = tok.split_at(1);
                if let Ok(v) = v.parse::<f64>() {
                    match l {
                        "B" => b = Some(v),
                        "C" => c = Some(v),
                        _ => {}
                    }
                }
            }
            b.zip(c)
        })
        .collect()
}

/// Tool axis in the part frame of a B head (about +Y) and a C rotation about +Z. Whether C
/// turns the table (part frame = Rz(−C)·head) or the head (Rz(C)·head) does not change the
/// angle between two orientations of a B head: both are in the XZ plane before C, and the
/// angle between u and Rz(δ)·v is even in δ there.
fn reference_fk(b_deg: f64, c_deg: f64) -> [f64; 3] {
    let (b, c) = (b_deg.to_radians(), c_deg.to_radians());
    let t = [b.sin(), 0.0, b.cos()];
    [
        c.cos() * t[0] - c.sin() * t[1],
        c.sin() * t[0] + c.cos() * t[1],
        t[2],
    ]
}

fn angle_deg(u: [f64; 3], v: [f64; 3]) -> f64 {
    let cross = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let s = cross.iter().map(|x| x * x).sum::<f64>().sqrt();
    let d: f64 = u.iter().zip(&v).map(|(a, b)| a * b).sum();
    s.atan2(d).to_degrees()
}

#[test]
fn head_table_and_head_head_patch_a_planted_pass_with_the_right_deviation() {
    let input = std::fs::read_to_string(root().join("fixtures/generated/heidenhain-bc-swing-d1.I"))
        .unwrap();
    for file in ["example-head-table-bc.toml", "example-head-head-cb.toml"] {
        let m = machine(file);
        let (out, report) =
            polepatch::patch_nc(input.as_bytes(), &m, &PatchOptions::default()).unwrap();
        assert_eq!(report.zones.len(), 1, "{file}");
        let z = &report.zones[0];
        assert_eq!(z.outcome, polepatch::Outcome::Reached, "{file}: {z:?}");
        assert!(z.after.overall_ratio >= 1.0 - 1e-3, "{file}: {z:?}");
        let out = String::from_utf8(out).unwrap();
        let (before, after) = (rotary_per_line(&input), rotary_per_line(&out));
        assert_eq!(before.len(), after.len());
        let worst = before
            .iter()
            .zip(&after)
            .filter_map(|(b, a)| {
                let ((b0, c0), (b1, c1)) = (b.as_ref()?, a.as_ref()?);
                Some(angle_deg(reference_fk(*b0, *c0), reference_fk(*b1, *c1)))
            })
            .fold(0.0, f64::max);
        assert!(worst > 0.1, "{file}: nothing turned");
        assert!(
            (worst - z.max_deviation_deg).abs() < 1e-6,
            "{file}: reference {worst:.9}° vs reported {:.9}°",
            z.max_deviation_deg
        );
    }
}

#[test]
fn pairs_not_wired_yet_are_refused_by_name() {
    let input = std::fs::read(root().join("fixtures/generated/heidenhain-bc-swing-d1.I")).unwrap();
    for (file, says) in [
        ("example-nutating-table-45.toml", "not of that form"),
        ("example-trunnion-ab.toml", "pole axis is called B"),
    ] {
        let m = machine(file);
        let err = polepatch::patch_nc(&input, &m, &PatchOptions::default())
            .err()
            .unwrap_or_else(|| panic!("{file}: patched"))
            .to_string();
        assert!(err.contains(says) && err.contains(&m.name), "{file}: {err}");
    }
}

/// `post` names the tilting axis A or B and the pole axis C: a machine whose pole axis is
/// called B (an A-B trunnion) is refused rather than given C words; the 45° nutating table,
/// whose letters are B and C, is posted through its own inverse kinematics.
#[test]
fn post_refuses_letters_it_cannot_write() {
    use polepatch::post::{PostOptions, post_cl, read_cl};
    let apt = b"UNITS/MM\nFEDRAT/1000\nGOTO/10,0,-5,0.2588190,0,0.9659258\nGOTO/11,0,-5,0.25,0.05,0.9669\nFINI\n";
    let cl = read_cl(apt, "t.apt").unwrap();
    let opts = PostOptions {
        patch: false,
        ..PostOptions::default()
    };
    let ab = machine("example-trunnion-ab.toml");
    let err = match post_cl(&cl, &ab, &opts) {
        Ok(_) => panic!("posted for an A-B trunnion"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("called A and B"), "{err}");
    let nut = machine("example-nutating-table-45.toml");
    let (out, _) = post_cl(&cl, &nut, &opts).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains(" B") && text.contains(" C"), "{text}");
}
