//! Issue 9: C17's avoidance by reorienting the workpiece (`polepatch reorient`).

use polepatch::kinematics::Machine;
use polepatch::load_nc;
use polepatch::nc::modal;
use polepatch::reorient::{Tilt, reorient_nc, search};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(p: &str) -> Vec<u8> {
    std::fs::read(root().join(p)).unwrap()
}

/// (line, A, C) of every block that writes a rotary word, in order.
fn rotary_words(bytes: &[u8], machine: &Machine) -> Vec<(usize, f64, f64)> {
    let lp = load_nc(bytes, "x", machine, None).unwrap();
    let p = &lp.program;
    (0..p.blocks.len())
        .filter(|&b| {
            p.state(b).tcpm.is_on() && p.word(b, b'A').is_some() && p.word(b, b'C').is_some()
        })
        .map(|b| {
            let st = p.state(b);
            (
                p.blocks[b].line,
                st.pos[modal::A].unwrap(),
                st.pos[modal::C].unwrap(),
            )
        })
        .collect()
}

fn c17_machine(sense: f64) -> Machine {
    let mut m = Machine::builtin("mikron-ucp710").unwrap();
    m.primary_sense = sense;
    m.c_sense = sense;
    m
}

fn mod360(d: f64) -> f64 {
    let w = d.rem_euclid(360.0);
    w.min(360.0 - w)
}

/// The paper's experiment: `%SING` reoriented by θx = 10°, θz = 180° gives `%NON_SING`'s
/// rotary words, point for point; with C17's own senses (−1) the same mapping is
/// θx = −10°.
#[test]
fn sing_reoriented_gives_non_sing() {
    let sing = read("fixtures/c17/SING.I");
    let non_sing = read("fixtures/c17/NON_SING.I");
    for (sense, theta_x) in [(1.0, 10.0), (-1.0, -10.0)] {
        let m = c17_machine(sense);
        let tilt = Tilt {
            theta_x_deg: theta_x,
            theta_z_deg: 180.0,
            pivot_mm: [0.0; 3],
        };
        let (out, report) = reorient_nc(&sing, &m, &tilt, "SING.I", 5.0).unwrap();
        let ours = rotary_words(&out, &m);
        let theirs = rotary_words(&non_sing, &m);
        assert_eq!(theirs.len(), 55);
        // Our output also writes A and C into the first TCPM move (N70), which NON_SING
        // leaves at the inherited A0 C0: compare the blocks NON_SING writes.
        let ours: Vec<_> = ours
            .into_iter()
            .filter(|(l, _, _)| theirs.iter().any(|t| t.0 == *l))
            .collect();
        assert_eq!(ours.len(), theirs.len());
        for (o, t) in ours.iter().zip(&theirs) {
            assert!(
                (o.1 - t.1).abs() <= 0.002,
                "sense {sense} line {}: A {} vs {}",
                o.0,
                o.1,
                t.1
            );
            assert!(
                mod360(o.2 - t.2) <= 0.002,
                "sense {sense} line {}: C {} vs {}",
                o.0,
                o.2,
                t.2
            );
        }
        // And the machine no longer crawls: C peaks near 18 rpm (C17), below its 20 rpm.
        let c = report.after.peak_speed["C"];
        assert!((15.0..20.0).contains(&c), "peak C {c}");
        assert!(report.before.peak_speed["C"] > 150.0);
        assert_eq!(report.after.zones, 0);
        assert!(report.after.min_pole_distance_deg > report.before.min_pole_distance_deg);
    }
}

/// There and back: (θx, θz) then the inverse rotation R_z(−θz)·R_x(−θx) as two steps
/// returns the original positions within the file's precision, and the original rotary
/// words up to the IK branch where the path crossed the pole.
#[test]
fn reorientation_and_back_returns_the_words() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let sing = read("fixtures/c17/SING.I");
    let pivot = [25.0, 25.0, -8.0];
    let step = |bytes: &[u8], tx: f64, tz: f64| {
        let tilt = Tilt {
            theta_x_deg: tx,
            theta_z_deg: tz,
            pivot_mm: pivot,
        };
        reorient_nc(bytes, &m, &tilt, "x", 5.0).unwrap().0
    };
    let there = step(&sing, 12.0, 30.0);
    let back = step(&step(&there, -12.0, 0.0), 0.0, -30.0);
    let a = load_nc(&sing, "a", &m, None).unwrap();
    let b = load_nc(&back, "b", &m, None).unwrap();
    let (mut compared, mut same_branch) = (0, 0);
    for blk in 0..a.program.blocks.len() {
        let (sa, sb) = (a.program.state(blk), b.program.state(blk));
        if !(a.program.blocks[blk].is_move && sa.tcpm.is_on()) {
            continue;
        }
        for i in [modal::X, modal::Y, modal::Z] {
            let (x, y) = (sa.pos[i].unwrap(), sb.pos[i].unwrap());
            assert!(
                (x - y).abs() <= 0.0015 + 1e-9,
                "block {blk} axis {i}: {x} vs {y}"
            );
        }
        // The rotary words come back — or, where the path passed the pole on the way
        // (C17's programs start at A0 C0, where C is free), as the other IK branch of the
        // same tool axis, (−A, C + 180°).
        let (a0, c0) = (sa.pos[modal::A].unwrap(), sa.pos[modal::C].unwrap());
        let (a1, c1) = (sb.pos[modal::A].unwrap(), sb.pos[modal::C].unwrap());
        if a0.abs() <= 0.01 {
            assert!(a1.abs() <= 0.01, "block {blk}: A {a0} vs {a1}");
            continue;
        }
        // Three programs were written with 3 decimals on the way (3 × 0.0005° on each
        // rotary word; C's error on the tool axis scales with sin A, so C itself is
        // compared through the tool axis).
        let tol = 0.0015 + 1e-9;
        let axis_err = polepatch::kinematics::angle_between_deg(
            polepatch::kinematics::forward(&m, a0, c0),
            polepatch::kinematics::forward(&m, a1, c1),
        );
        assert!(
            axis_err <= 2.0 * tol,
            "block {blk}: tool axis off by {axis_err}°"
        );
        let same = (a0 - a1).abs() <= tol;
        let other = (a0 + a1).abs() <= tol;
        assert!(same || other, "block {blk}: A{a0} C{c0} vs A{a1} C{c1}");
        if same {
            same_branch += 1;
        }
        compared += 1;
    }
    assert!(compared >= 50);
    eprintln!("round trip: {same_branch} of {compared} points on the original branch");
}

/// A tilt that needs the primary axis outside its range is refused, with the line.
#[test]
fn leaving_the_primary_range_is_refused_with_the_line() {
    let mut m = Machine::builtin("mikron-ucp710").unwrap();
    m.primary_range_deg = (-30.0, 30.0);
    let tilt = Tilt {
        theta_x_deg: 25.0,
        theta_z_deg: 180.0,
        pivot_mm: [0.0; 3],
    };
    let e = reorient_nc(&read("fixtures/c17/SING.I"), &m, &tilt, "SING.I", 5.0).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("SING.I:"), "{msg}");
    assert!(msg.contains("outside the machine's range"), "{msg}");
}

/// The search on `%SING` finds a tilt whose program reaches feed on both rotary axes
/// (C ≤ 20 rpm, no zone), with the smallest |θx| on its grid.
#[test]
fn search_on_sing_finds_a_small_tilt() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let (_, report) = search(&read("fixtures/c17/SING.I"), &m, [0.0; 3], "SING.I", 5.0).unwrap();
    assert!(
        report.after.peak_speed["C"] <= 20.0,
        "{:?}",
        report.after.peak_speed
    );
    assert_eq!(report.after.zones, 0);
    let tx = report.theta_x_deg.abs();
    // No smaller tilt on the grid was feasible.
    assert!(
        report
            .alternatives
            .iter()
            .filter(|a| a.theta_x_deg.abs() < tx - 1e-9)
            .all(|a| a.rejected.is_some())
    );
    eprintln!(
        "search: θx {} θz {} (C {:.1} rpm, {} candidates)",
        report.theta_x_deg,
        report.theta_z_deg,
        report.after.peak_speed["C"],
        report.alternatives.len()
    );
}

/// Issue 19 §1: `reorient` reads TCPM as the controller does — after `G43` (which replaces
/// `G43.4`) or a skippable `M128`, no move is under TCPM, so nothing is rewritten.
#[test]
fn reorient_follows_the_tcpm_state() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let tilt = Tilt {
        theta_x_deg: 10.0,
        theta_z_deg: 0.0,
        pivot_mm: [0.0; 3],
    };
    let fanuc = String::from_utf8(read("fixtures/generated/fanuc-ac-flip-d0.5.nc")).unwrap();
    let sing = String::from_utf8(read("fixtures/c17/SING.I")).unwrap();
    for (label, text) in [
        (
            "G43 after G43.4",
            fanuc.replace("G43.4 H1\n", "G43.4 H1\nG43 H1\n"),
        ),
        ("/M128", sing.replace("N65 M128 *", "/N65 M128 *")),
    ] {
        assert!(text != fanuc && text != sing, "{label}");
        let e = reorient_nc(text.as_bytes(), &m, &tilt, "t", 5.0).unwrap_err();
        assert!(
            e.to_string().contains("no move with TCPM on"),
            "{label}: {e}"
        );
    }
}

/// The machine a fixture is written for: B programs on the HSM600, A on the UCP710.
fn machine_for(bytes: &[u8]) -> Machine {
    let text = String::from_utf8_lossy(bytes);
    let b = text.lines().any(|l| {
        l.split(|c: char| c.is_whitespace()).any(|w| {
            w.starts_with('B')
                && w[1..].starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+')
        })
    });
    Machine::builtin(if b { "mikron-hsm600" } else { "mikron-ucp710" }).unwrap()
}

/// Issue 19: θ = 0, 0 rewrote `%SING` onto the other IK branch (the first move is on the
/// pole, and the nearest solution from there is the other branch). No tilt changes
/// nothing, byte for byte, on every fixture; a pure turn θz adds sc·θz to every C and
/// keeps every primary value.
#[test]
fn no_tilt_changes_nothing_and_a_pure_turn_only_turns_c() {
    let mut checked = 0;
    for path in polepatch_fixturegen::nc_files(&root().join("fixtures")) {
        let bytes = std::fs::read(&path).unwrap();
        let m = machine_for(&bytes);
        let name = path.display().to_string();
        let zero = Tilt {
            theta_x_deg: 0.0,
            theta_z_deg: 0.0,
            pivot_mm: [0.0; 3],
        };
        let Ok((out, report)) = reorient_nc(&bytes, &m, &zero, &name, 5.0) else {
            continue; // a program without TCPM moves: refused, tested elsewhere
        };
        assert_eq!(report.words_changed, 0, "{name}");
        assert!(out == bytes, "{name}: θ = 0 changed the program");
        let turn = Tilt {
            theta_z_deg: 77.0,
            ..zero
        };
        let (out, _) = reorient_nc(&bytes, &m, &turn, &name, 5.0).unwrap();
        let (before, after) = (rotary_words_of(&bytes, &m), rotary_words_of(&out, &m));
        assert_eq!(before.len(), after.len(), "{name}");
        for (b, a) in before.iter().zip(&after) {
            assert!(
                (b.1 - a.1).abs() < 2e-3,
                "{name} line {}: P {} → {}",
                b.0,
                b.1,
                a.1
            );
            assert!(
                mod360(a.2 - b.2 - m.c_sense * 77.0) < 2e-3,
                "{name} line {}: C {} → {}",
                b.0,
                b.2,
                a.2
            );
        }
        checked += 1;
    }
    assert!(checked >= 40, "only {checked} fixtures checked");
}

/// A tilt below `BRANCH_KEEP_DEG` keeps every move on the program's side of the pole (the
/// sign of its primary value), on `%SING` whose first move is on the pole and on the
/// domain-rule programs that flip the primary near it.
#[test]
fn a_tiny_tilt_keeps_every_branch() {
    for p in [
        "fixtures/c17/SING.I",
        "fixtures/generated/fanuc-ac-flip-d0.5.nc",
        "fixtures/generated/heidenhain-bc-flip-d2.I",
        "fixtures/generated/sinumerik-ac-swing-d0.1.mpf",
    ] {
        let bytes = read(p);
        let m = machine_for(&bytes);
        for (tx, tz) in [(1e-6, 0.0), (0.01, 0.0), (-0.3, 25.0), (0.9, -140.0)] {
            let tilt = Tilt {
                theta_x_deg: tx,
                theta_z_deg: tz,
                pivot_mm: [0.0; 3],
            };
            let (out, _) = reorient_nc(&bytes, &m, &tilt, p, 5.0).unwrap();
            let (before, after) = (rotary_words_of(&bytes, &m), rotary_words_of(&out, &m));
            for (b, a) in before.iter().zip(&after) {
                if b.1.abs() > tx.abs() + 1e-3 {
                    assert_eq!(
                        b.1 < 0.0,
                        a.1 < 0.0,
                        "{p} θ {tx},{tz} line {}: primary {} → {}",
                        b.0,
                        b.1,
                        a.1
                    );
                }
            }
        }
    }
}

/// Issue 19: θx = 1e9 was accepted. Tilts are finite, |θx| ≤ 90°, |θz| ≤ 360°.
#[test]
fn out_of_range_tilts_are_refused() {
    let bytes = read("fixtures/c17/SING.I");
    let m = c17_machine(1.0);
    for (tx, tz) in [
        (1e9, 0.0),
        (90.5, 0.0),
        (-91.0, 0.0),
        (0.0, 361.0),
        (0.0, -1e300),
        (f64::NAN, 0.0),
    ] {
        let tilt = Tilt {
            theta_x_deg: tx,
            theta_z_deg: tz,
            pivot_mm: [0.0; 3],
        };
        let e = reorient_nc(&bytes, &m, &tilt, "SING.I", 5.0).unwrap_err();
        assert!(
            matches!(e, polepatch::Error::Options(_))
                && e.to_string().contains("outside the accepted range"),
            "{tx}, {tz}: {e}"
        );
    }
    for (tx, tz) in [(90.0, 0.0), (-10.0, 360.0)] {
        let tilt = Tilt {
            theta_x_deg: tx,
            theta_z_deg: tz,
            pivot_mm: [0.0; 3],
        };
        if let Err(polepatch::Error::Options(e)) = reorient_nc(&bytes, &m, &tilt, "SING.I", 5.0) {
            panic!("{tx}, {tz}: {e}");
        }
    }
}

/// (line, P, C) of every move under TCPM, from the modal state (whichever tilting letter).
fn rotary_words_of(bytes: &[u8], machine: &Machine) -> Vec<(usize, f64, f64)> {
    let lp = load_nc(bytes, "x", machine, None).unwrap();
    let p = &lp.program;
    let pi = lp.primary_index();
    (0..p.blocks.len())
        .filter(|&b| p.blocks[b].is_move && p.state(b).tcpm.is_on())
        .filter_map(|b| {
            let st = p.state(b);
            Some((p.blocks[b].line, st.pos[pi]?, st.pos[modal::C]?))
        })
        .collect()
}
