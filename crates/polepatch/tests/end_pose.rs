//! Issue 21 §3: the next pass starts the way CAM posts write it — a retract (restating the
//! rotary values or not), then one positioning move with X Y and both rotary axes at that
//! clearance under TCPM. That leaves the run's end free, so a flip is re-selected (no
//! orientation change), the restating retract is rewritten to the new branch, and the
//! report names the deciding block; a positioning move below the clearance pins it.
//! Whole-program and stretch paths agree.

use polepatch::PatchOptions;
use polepatch::kinematics::Machine;
use polepatch::patch_nc_to;
use polepatch_fixturegen::{Pass, joints};

/// A Heidenhain ISO program: one pass (B-C, domain rule, `d` from the pole), a retract to
/// Z+10 (restating B and C when `restate`), a positioning move to the next pass at
/// `position_z`, a second pass far from the pole. Returns the text and the lines of the
/// retract and of the positioning move.
fn program(d: f64, restate: bool, position_z: f64) -> (String, usize, usize) {
    let pass = Pass {
        pole_distance_deg: d,
        b_axis: true,
        domain_rule: true,
        // The B-C domain rule picks the branch by the sign of i: the pass crosses i = 0.
        azimuth_deg: 90.0,
        ..Pass::default()
    };
    let j = joints(&pass);
    let mut lines: Vec<String> = vec![
        "%TWO G71 *".into(),
        "N10 G90 *".into(),
        "N20 T1 M6 *".into(),
        "N30 M128 *".into(),
        format!(
            "N40 G00 X{:+.3} Y+0 Z+10 B{:+.3} C{:+.3} *",
            j[0][0], j[0][3], j[0][4]
        ),
        format!("N50 G01 Z{:+.3} F2000 *", j[0][2]),
    ];
    let mut n = 60;
    for q in &j[1..] {
        lines.push(format!(
            "N{n} X{:+.3} Y+0 Z{:+.3} B{:+.3} C{:+.3} *",
            q[0], q[2], q[3], q[4]
        ));
        n += 10;
    }
    let last = j[j.len() - 1];
    let retract = if restate {
        format!("N{n} G00 Z+10 B{:+.3} C{:+.3} *", last[3], last[4])
    } else {
        format!("N{n} G00 Z+10 *")
    };
    lines.push(retract);
    let retract_line = lines.len();
    n += 10;
    lines.push(format!("N{n} G00 X+0 Y+20 Z{position_z:+.3} B+30 C+0 *"));
    let position_line = lines.len();
    n += 10;
    lines.push(format!("N{n} G01 Z-5 F2000 *"));
    for k in 1..=20 {
        n += 10;
        lines.push(format!(
            "N{n} X{:+.3} B+30 C{:+.3} *",
            f64::from(k),
            f64::from(k)
        ));
    }
    lines.push(format!("N{} M30 *", n + 10));
    lines.push("N999999 %TWO G71 *".into());
    (lines.join("\n") + "\n", retract_line, position_line)
}

fn patch_both_ways(text: &str, m: &Machine) -> (Vec<u8>, polepatch::FileReport) {
    let opts = PatchOptions::default();
    let mut out = Vec::new();
    let report = patch_nc_to(text.as_bytes(), m, &opts, &mut out).unwrap();
    (out, report)
}

#[test]
fn positioning_above_the_clearance_frees_the_end_and_rewrites_the_restating_retract() {
    let m = Machine::builtin("mikron-hsm600").unwrap();
    for restate in [false, true] {
        let (text, retract_line, position_line) = program(4.0, restate, 10.0);
        let (out, report) = patch_both_ways(&text, &m);
        assert_eq!(report.zones.len(), 1, "{report:?}");
        let z = &report.zones[0];
        assert_eq!(z.end_pose, Some(polepatch::EndFreedom::Free), "{z:?}");
        assert_eq!(z.end_pose_line, Some(position_line), "{z:?}");
        assert_eq!(z.reason, polepatch::ZoneReason::Reselected, "{z:?}");
        assert!(z.max_deviation_deg < 1e-3, "{z:?}");
        let out = String::from_utf8(out).unwrap();
        let (before, after) = (
            text.lines().nth(retract_line - 1).unwrap(),
            out.lines().nth(retract_line - 1).unwrap(),
        );
        if restate {
            // The retract restates the run's new last values: the other branch.
            assert_ne!(before, after);
            let last_cut = out.lines().nth(retract_line - 2).unwrap();
            let word = |line: &str, l: char| -> f64 {
                line.split(' ')
                    .find_map(|w| w.strip_prefix(l))
                    .unwrap()
                    .parse()
                    .unwrap()
            };
            assert_eq!(
                word(after, 'B'),
                word(last_cut, 'B'),
                "{last_cut} / {after}"
            );
            assert_eq!(
                word(after, 'C'),
                word(last_cut, 'C'),
                "{last_cut} / {after}"
            );
            assert_eq!(word(after, 'B'), -word(before, 'B'));
        } else {
            assert_eq!(
                before, after,
                "no rotary word is written into a plain retract"
            );
        }
        // The positioning move and everything after it are as they were.
        for (a, b) in text.lines().zip(out.lines()).skip(position_line - 1) {
            assert_eq!(a, b);
        }
    }
}

#[test]
fn positioning_below_the_clearance_pins_the_end() {
    let m = Machine::builtin("mikron-hsm600").unwrap();
    let (text, _, position_line) = program(4.0, true, 5.0);
    let (out, report) = patch_both_ways(&text, &m);
    assert_eq!(report.zones.len(), 1, "{report:?}");
    let z = &report.zones[0];
    assert_eq!(z.end_pose, Some(polepatch::EndFreedom::Pinned), "{z:?}");
    assert_eq!(z.end_pose_line, Some(position_line), "{z:?}");
    assert_ne!(z.reason, polepatch::ZoneReason::Reselected, "{z:?}");
    // Nothing after the run is written.
    let last_run_line = position_line - 2;
    for (a, b) in text
        .lines()
        .zip(String::from_utf8(out).unwrap().lines())
        .skip(last_run_line)
    {
        assert_eq!(a, b);
    }
}
