//! Issue 29: machines of other layouts. A head-table B-C and a head-head C-B machine (the
//! standard form: pole axis along Z called C, tilting axis about Y) read, analyse and patch
//! a planted pass 1° from the pole to feed on both rotary axes, and the deviation reported
//! is the angle an independent forward kinematics of that layout gives for the written
//! words; an A-B trunnion whose platter (the pole axis) is called B reads, analyses and
//! patches its own letters; pairs whose zones and branches are not wired yet (a 45°
//! nutating table) are refused by name, never patched with the wrong kinematics.

use polepatch::PatchOptions;
use polepatch::kinematics::Machine;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn machine(file: &str) -> Machine {
    Machine::from_file(&root().join("crates/kinematics/machines").join(file)).unwrap()
}

/// The values of the letters `l0` and `l1` in force after each line of a program (modal
/// words), once both are known.
fn pair_per_line(text: &str, l0: &str, l1: &str) -> Vec<Option<(f64, f64)>> {
    let (mut v0, mut v1) = (None, None);
    text.lines()
        .map(|line| {
            for tok in line.split_whitespace() {
                let (l, v) = tok.split_at(1);
                if let Ok(v) = v.parse::<f64>() {
                    if l == l0 {
                        v0 = Some(v);
                    } else if l == l1 {
                        v1 = Some(v);
                    }
                }
            }
            v0.zip(v1)
        })
        .collect()
}

/// The largest angle, degrees, between the tool axes `fk` gives for the values of the
/// letters `l0`, `l1` in force after each line of `input` and of `output` (the same lines:
/// a rewrite changes words, never lines).
fn worst_change_deg(
    input: &str,
    output: &str,
    (l0, l1): (&str, &str),
    fk: impl Fn(f64, f64) -> [f64; 3],
) -> f64 {
    let (before, after) = (pair_per_line(input, l0, l1), pair_per_line(output, l0, l1));
    assert_eq!(before.len(), after.len());
    before
        .iter()
        .zip(&after)
        .filter_map(|(b, a)| {
            let ((b0, b1), (a0, a1)) = (b.as_ref()?, a.as_ref()?);
            Some(angle_deg(fk(*b0, *b1), fk(*a0, *a1)))
        })
        .fold(0.0, f64::max)
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
        let worst = worst_change_deg(&input, &out, ("B", "C"), reference_fk);
        assert!(worst > 0.1, "{file}: nothing turned");
        assert!(
            (worst - z.max_deviation_deg).abs() < 1e-6,
            "{file}: reference {worst:.9}° vs reported {:.9}°",
            z.max_deviation_deg
        );
    }
}

/// A CL pass (APT, F2000): X from 0 to 40 mm at Z −5, the tool axis `axis(sweep, by)`
/// normalised, with `sweep` going from tan 15° to tan −15° and `by` = tan 1°: the caller
/// puts the 1 on the pole's direction, so the pass goes by the pole 1° from it.
fn cl_pass(axis: impl Fn(f64, f64) -> [f64; 3]) -> String {
    let mut apt = String::from("UNITS/MM\nFEDRAT/2000\n");
    for k in 0..=40 {
        let t = f64::from(k) / 40.0;
        let o = axis(
            (15.0 - 30.0 * t).to_radians().tan(),
            1f64.to_radians().tan(),
        );
        let n = o.iter().map(|v| v * v).sum::<f64>().sqrt();
        apt += &format!(
            "GOTO/{k},0,-5,{:.9},{:.9},{:.9}\n",
            o[0] / n,
            o[1] / n,
            o[2] / n
        );
    }
    apt + "FINI\n"
}

/// Tool axis in the part frame of the 45° nutating table: B about (0, 1, 1)/√2 carrying
/// the C table about Z, the tool along Z at zero (Rodrigues' formula, written here apart
/// from the kinematics crate). The senses do not matter for the angle between two
/// orientations: negating both B and C mirrors every orientation in the plane x = 0
/// (which holds both axes), and a mirror keeps angles.
fn reference_fk_nutating(b_deg: f64, c_deg: f64) -> [f64; 3] {
    let (b, c) = (b_deg.to_radians(), c_deg.to_radians());
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let n = [0.0, h, h];
    let z = [0.0, 0.0, 1.0];
    // R(n, b)·z = z cos b + (n × z) sin b + n (n·z)(1 − cos b)
    let nxz = [n[1] * z[2] - n[2] * z[1], n[2] * z[0] - n[0] * z[2], 0.0];
    let t: [f64; 3] =
        std::array::from_fn(|k| z[k] * b.cos() + nxz[k] * b.sin() + n[k] * h * (1.0 - b.cos()));
    [
        c.cos() * t[0] - c.sin() * t[1],
        c.sin() * t[0] + c.cos() * t[1],
        t[2],
    ]
}

/// Issue 29: a 45° nutating table (B at 45° between +Y and +Z, carrying the C table). A
/// pass whose tool axis goes by 1° from the pole, posted for the machine by `post` (its
/// own inverse kinematics), is found — at its distance from the pole, the angle between the
/// tool and C's axis, not |B| — and patched to feed on both rotary axes; the reported
/// deviation is the angle an independent FK of the layout gives for the written words.
#[test]
fn a_45_degree_nutating_table_patches_a_planted_pass() {
    use polepatch::post::{PostOptions, post_cl, read_cl};
    let nut = machine("example-nutating-table-45.toml");
    assert!(nut.standard_form().is_none());
    // X from 0 to 40 mm; the tool axis tilts from +15° to −15° about Y while it stays 1°
    // from the pole in Y.
    let apt = cl_pass(|sweep, by| [sweep, by, 1.0]);
    let cl = read_cl(apt.as_bytes(), "nut.apt").unwrap();
    let post = PostOptions {
        patch: false,
        ..PostOptions::default()
    };
    let (nc, _) = post_cl(&cl, &nut, &post).unwrap();
    let input = String::from_utf8(nc).unwrap();
    let (out, report) =
        polepatch::patch_nc(input.as_bytes(), &nut, &PatchOptions::default()).unwrap();
    assert_eq!(report.zones.len(), 1, "{report:?}\n{input}");
    let z = &report.zones[0];
    assert!((z.min_abs_primary_deg - 1.0).abs() < 0.05, "{z:?}");
    assert!(z.before.overall_ratio < 0.9, "{z:?}");
    assert_eq!(z.outcome, polepatch::Outcome::Reached, "{z:?}");
    assert!(z.after.overall_ratio >= 1.0 - 1e-3, "{z:?}");
    let out = String::from_utf8(out).unwrap();
    let worst = worst_change_deg(&input, &out, ("B", "C"), reference_fk_nutating);
    assert!(worst > 0.1, "nothing turned");
    assert!(
        (worst - z.max_deviation_deg).abs() < 1e-6,
        "reference {worst:.9}° vs reported {:.9}°",
        z.max_deviation_deg
    );
    // As small a change as on a table whose B turns about Y, with the same limits, for the
    // same CL pass (2.7227° against 2.7247° when this was written).
    let mut upright = nut.clone();
    upright.rotary.primary.direction = [0.0, 1.0, 0.0];
    assert!(upright.standard_form().is_some());
    let (nc_up, _) = post_cl(&cl, &upright, &post).unwrap();
    let (_, report_up) = polepatch::patch_nc(&nc_up, &upright, &PatchOptions::default()).unwrap();
    let dev_up = report_up.zones[0].max_deviation_deg;
    assert!(
        z.max_deviation_deg <= 1.05 * dev_up,
        "nutating {:.4}° against upright {dev_up:.4}°",
        z.max_deviation_deg
    );
    // The patched program has no zone left.
    let a =
        polepatch::analyze_nc(out.as_bytes(), &nut, &polepatch::AnalyzeOptions::default()).unwrap();
    let left: usize = a
        .runs
        .iter()
        .filter_map(|r| r.figures.as_ref())
        .map(|f| f.zones.len())
        .sum();
    assert_eq!(left, 0, "{a:?}");
}

/// `post` writes the machine's own letters: A and B for an A-B trunnion whose platter is
/// B (no C word); the 45° nutating table, whose letters are B and C, is posted through its
/// own inverse kinematics.
#[test]
fn post_writes_the_machines_letters() {
    use polepatch::post::{PostOptions, post_cl, read_cl};
    let apt = b"UNITS/MM\nFEDRAT/1000\nGOTO/10,0,-5,0.2588190,0,0.9659258\nGOTO/11,0,-5,0.25,0.05,0.9669\nFINI\n";
    let cl = read_cl(apt, "t.apt").unwrap();
    let opts = PostOptions {
        patch: false,
        ..PostOptions::default()
    };
    let ab = machine("example-trunnion-ab.toml");
    let (out, _) = post_cl(&cl, &ab, &opts).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains(" A") && text.contains(" B") && !text.contains(" C"),
        "{text}"
    );
    let nut = machine("example-nutating-table-45.toml");
    let (out, _) = post_cl(&cl, &nut, &opts).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains(" B") && text.contains(" C"), "{text}");
}

/// Tool axis in the part frame of a table-table pair: the tilting axis A about X, then the
/// platter about Z (the pole axis, B on the trunnion). The senses do not matter for the
/// angle between two orientations: u·v = cos A₁ cos A₂ + sin A₁ sin A₂ cos(B₁ − B₂) for
/// every sign of A and of B.
fn reference_fk_ab(a_deg: f64, b_deg: f64) -> [f64; 3] {
    let (a, b) = (a_deg.to_radians(), b_deg.to_radians());
    let t = [0.0, -a.sin(), a.cos()];
    [
        b.cos() * t[0] - b.sin() * t[1],
        b.sin() * t[0] + b.cos() * t[1],
        t[2],
    ]
}

/// Issue 29: an A-B trunnion (A tilting about X, the platter B about the table's normal,
/// the pole axis). A planted pass 1° from the pole written with its letters (the A-C
/// fixture with its C words written as B) is found, patched to feed on both rotary axes
/// with B as the pole axis, and the deviation reported is the angle of an independent FK;
/// the result is the A-C machine's with the same axes, letter for letter: the letters are
/// names, the kinematics are the pair's.
#[test]
fn an_a_b_trunnion_patches_its_own_letters() {
    let ac = std::fs::read_to_string(root().join("fixtures/generated/heidenhain-ac-swing-d1.I"))
        .unwrap();
    let ab_text = ac.replace(" C+", " B+").replace(" C-", " B-");
    assert!(!ab_text.contains(" C"), "every C word written as B");
    let ab = machine("example-trunnion-ab.toml");
    assert_eq!((ab.primary_letter(), ab.c_letter()), ('A', 'B'));
    let (out, report) =
        polepatch::patch_nc(ab_text.as_bytes(), &ab, &PatchOptions::default()).unwrap();
    assert_eq!(report.zones.len(), 1, "{report:?}");
    let z = &report.zones[0];
    assert_eq!(z.outcome, polepatch::Outcome::Reached, "{z:?}");
    assert!(
        z.before.overall_ratio < 0.9 && z.after.overall_ratio >= 1.0 - 1e-3,
        "{z:?}"
    );
    let out = String::from_utf8(out).unwrap();
    assert!(!out.contains(" C"), "no C word written:\n{out}");
    let worst = worst_change_deg(&ab_text, &out, ("A", "B"), reference_fk_ab);
    assert!(worst > 0.1, "nothing turned");
    assert!(
        (worst - z.max_deviation_deg).abs() < 1e-6,
        "reference {worst:.9}° vs reported {:.9}°",
        z.max_deviation_deg
    );
    // The same machine with its platter called C patches the A-C program to the same words.
    let mut ac_machine = ab.clone();
    ac_machine.rotary.c.letter = 'C';
    let (out_ac, report_ac) =
        polepatch::patch_nc(ac.as_bytes(), &ac_machine, &PatchOptions::default()).unwrap();
    assert_eq!(
        String::from_utf8(out_ac)
            .unwrap()
            .replace(" C+", " B+")
            .replace(" C-", " B-"),
        out
    );
    assert_eq!(report_ac.zones[0].max_deviation_deg, z.max_deviation_deg);
    // Analysis names the file's letters.
    let a = polepatch::analyze_nc(
        ab_text.as_bytes(),
        &ab,
        &polepatch::AnalyzeOptions::default(),
    )
    .unwrap();
    assert_eq!(a.primary, "A");
    let ratios = &a.runs[0].figures.as_ref().unwrap().axis_min_ratio;
    assert!(
        ratios.contains_key("B") && !ratios.contains_key("C"),
        "{ratios:?}"
    );
}

/// A program for an A-C machine on the A-B trunnion: its C words are of an axis the
/// trunnion does not have — refused at the first C word that turns, naming the built-in
/// that has A and C.
#[test]
fn an_a_c_program_on_the_trunnion_is_refused_at_its_first_c_word() {
    let ac = std::fs::read(root().join("fixtures/generated/heidenhain-ac-swing-d1.I")).unwrap();
    let ab = machine("example-trunnion-ab.toml");
    let e = polepatch::patch_nc(&ac, &ab, &PatchOptions::default()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(
            e,
            polepatch::Error::ForeignAxis {
                letter: 'C',
                line: 7,
                ..
            }
        ),
        "{msg}"
    );
    assert!(
        msg.contains("C is not an axis of machine example-trunnion-ab")
            && msg.contains("the built-in mikron-ucp710 has A and C"),
        "{msg}"
    );
}

/// Issue 29's check: a program posted for an A-B trunnion by a CAM system (NX's Haas VF-TR
/// post form: A tilting, the platter B, no TCPM) is analysed on the trunnion and its
/// near-pole run found — the B swing where A passes 1° from the pole — with the axes named
/// by their letters.
#[test]
fn a_cam_trunnion_program_is_analysed_and_its_pole_pass_found() {
    let bytes = std::fs::read(root().join("fixtures/cam/haas-vf2tr-trunnion-ab.nc")).unwrap();
    let ab = machine("example-trunnion-ab.toml");
    let opts = polepatch::AnalyzeOptions {
        read: polepatch::ReadOptions {
            inch: true,
            ..polepatch::ReadOptions::default()
        },
        ..Default::default()
    };
    let a = polepatch::analyze_nc(&bytes, &ab, &opts).unwrap();
    let zones: Vec<_> = a
        .runs
        .iter()
        .filter_map(|r| r.figures.as_ref())
        .flat_map(|f| f.zones.iter())
        .collect();
    assert_eq!(zones.len(), 1, "{a:?}");
    let z = zones[0];
    assert!((z.min_abs_primary_deg - 1.0).abs() < 1e-9, "{z:?}");
    assert!(z.c_ratio_min < 1.0, "{z:?}");
    // The zone holds the line where A is 1° (`X.3937 A1. B180.`).
    let text = String::from_utf8(bytes).unwrap();
    let line = text.lines().position(|l| l.contains("A1. B180.")).unwrap() + 1;
    assert!(
        z.lines[0] <= line && line <= z.lines[1],
        "{z:?}, line {line}"
    );
    let f = a.runs[0].figures.as_ref().unwrap();
    assert_eq!(f.limiting_axis.as_deref(), Some("B"), "{f:?}");
}

/// Issue 29: the LinuxCNC `xyzab_tdr_kins` table (A about X carried by B about Y, the tool
/// along Z at zero), read from an INI in the style of LinuxCNC's sim config: its pole is the
/// tool along X (B = ±90°), where A cannot turn the tool. A pass posted 1° from that pole is
/// found at its distance from the pole (not |B|), and the patch makes it faster within the
/// safety bound, its deviation the angle of the module's own forward kinematics,
/// (sin B, −sin A cos B, cos A cos B), for the written words.
#[test]
fn a_linuxcnc_xyzab_tdr_pass_by_its_pole_along_x_is_found_and_patched() {
    use polepatch::post::{PostOptions, post_cl, read_cl};
    let ini = root().join("crates/kinematics/tests/linuxcnc/xyzab-tdr/xyzab-tdr.ini");
    let tdr = Machine::from_file(&ini).unwrap();
    assert_eq!((tdr.primary_letter(), tdr.c_letter()), ('B', 'A'));
    let apt = cl_pass(|sweep, by| [1.0, sweep, by]);
    let cl = read_cl(apt.as_bytes(), "tdr.apt").unwrap();
    let post = PostOptions {
        patch: false,
        dialect: polepatch::nc::Dialect::Fanuc,
        ..PostOptions::default()
    };
    let (nc, _) = post_cl(&cl, &tdr, &post).unwrap();
    let input = String::from_utf8(nc).unwrap();
    let (out, report) =
        polepatch::patch_nc(input.as_bytes(), &tdr, &PatchOptions::default()).unwrap();
    assert_eq!(report.zones.len(), 1, "{report:?}\n{input}");
    let z = &report.zones[0];
    assert!((z.min_abs_primary_deg - 1.0).abs() < 0.05, "{z:?}");
    assert!(
        z.after.overall_ratio > 2.0 * z.before.overall_ratio,
        "{z:?}"
    );
    assert!(z.max_deviation_deg <= 10.0 + 1e-6, "{z:?}");
    let fk = |a_deg: f64, b_deg: f64| {
        let (a, b) = (a_deg.to_radians(), b_deg.to_radians());
        [b.sin(), -a.sin() * b.cos(), a.cos() * b.cos()]
    };
    let out = String::from_utf8(out).unwrap();
    let worst = worst_change_deg(&input, &out, ("A", "B"), fk);
    assert!(worst > 0.1, "nothing turned");
    assert!(
        (worst - z.max_deviation_deg).abs() < 1e-6,
        "reference {worst:.9}° vs reported {:.9}°",
        z.max_deviation_deg
    );
}
