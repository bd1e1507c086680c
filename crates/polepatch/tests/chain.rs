//! Issue 10 §1 with a kinematic chain: a program without TCPM is patched by changing X Y Z
//! with the rotary values (the part-frame tool tip unchanged within 1 µm at every point),
//! and TCPM programs are analysed and checked in the machine frame.

use polepatch::ReadOptions;
use polepatch::kinematics::{Chain, Machine};
use polepatch::load_nc;
use polepatch::machine_frame::TIP_TOLERANCE_MM;
use polepatch::nc::{Edit, modal};
use polepatch::{AnalyzeOptions, PatchOptions, UntouchedReason, analyze_nc, patch_nc};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn sing() -> Vec<u8> {
    std::fs::read(root().join("fixtures/c17/SING.I")).unwrap()
}

/// The documented example chain of the UCP710 (crates/kinematics/machines).
fn example_machine() -> Machine {
    let path = root().join("crates/kinematics/machines/mikron-ucp710-example-chain.toml");
    Machine::load(path.to_str().unwrap()).unwrap()
}

/// SING's datum (`N60 G54 Y-7.1 Z+38.054`).
const SING_DATUM: [f64; 3] = [-30.489, -7.1, 38.054];

/// SING's part zero put on the C axis (`N60 G54 X+0 Y+0 Z+38.054`): without TCPM the
/// linear axes then follow the table little near the pole. With SING's own datum the chain
/// patch slows the machine in the machine frame (the patcher solves on the part-frame
/// path), and the written program's rule refuses it:
/// `with_sings_datum_the_chain_patch_slows_the_machine_and_is_not_written`.
const ON_AXIS_DATUM: [f64; 3] = [0.0, 0.0, 38.054];

/// `N60 G54 …` of a datum.
fn datum_line(d: [f64; 3]) -> String {
    format!("N60 G54 X{:+} Y{:+} Z{:+} *\n", d[0], d[1], d[2])
}

/// `%SING` as a post without TCPM writes it for `machine`'s chain: every point of its TCPM
/// run with X Y Z through the chain (3 decimals), `M128` removed, the approach (N70–N100)
/// at rapid and the pass from N110 at F. Returns the program and, per block, the part-frame
/// tool tip it was made from.
///
/// (With the approach in the run, at F, the patch slows the first span in the machine
/// frame — C, 1.000 → 0.882 of the feed: the not-a-knot spline couples the spans — and the
/// written program's rule refuses it: `a_patch_that_slows_a_span_in_the_machine_frame_is_not_written`.)
fn sing_without_tcpm(machine: &Machine) -> (Vec<u8>, Vec<Option<[f64; 3]>>) {
    sing_without_tcpm_at(machine, ON_AXIS_DATUM)
}

/// [`sing_without_tcpm`] with the part zero at `datum`.
fn sing_without_tcpm_at(machine: &Machine, datum: [f64; 3]) -> (Vec<u8>, Vec<Option<[f64; 3]>>) {
    let chain = machine.chain.unwrap();
    let lp = load_nc(&sing(), "SING.I", machine, None).unwrap();
    let program = &lp.program;
    let mut edits = Vec::new();
    let mut tips = vec![None; program.blocks.len()];
    for rp in lp.runs.iter().filter(|rp| rp.run.tcpm.is_on()) {
        for &b in &rp.run.blocks {
            let st = program.state(b);
            let v = |i: usize| st.pos[i].unwrap_or(0.0);
            let tip = [v(modal::X), v(modal::Y), v(modal::Z)];
            tips[b] = Some(tip);
            let x = chain.program_xyz(machine, datum, v(modal::A), v(modal::C), tip);
            for (i, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                let value = (x[i] * 1000.0).round() / 1000.0;
                if program.word(b, letter).is_some() && value != tip[i] {
                    edits.push(Edit {
                        block: b,
                        letter,
                        value,
                        decimals: 3,
                    });
                }
            }
        }
    }
    edits.sort_by_key(|e| (e.block, e.letter));
    let text = String::from_utf8(polepatch::nc::write(program, &edits)).unwrap();
    assert!(text.contains("N65 M128 *\n"));
    let text = text
        .replace("N65 M128 *\n", "")
        .replace(&datum_line(SING_DATUM), &datum_line(datum))
        .replace("N70 G01 ", "N70 G00 ")
        .replace("N110 X", "N110 G01 X");
    (text.into_bytes(), {
        // One line fewer: block indices after line 11 shift by one.
        let mut t = tips;
        t.remove(10);
        t
    })
}

/// The largest chord error (mm) of the written program's blocks in `run_lines` — the
/// part-frame tool tip under linear interpolation of every axis, from the programmed line
/// between the part-frame tips at the points — and, per block, whether it is within
/// `max(tolerance, the input block's) + 1 µm`.
fn chord_errors(
    machine: &Machine,
    datum: [f64; 3],
    input: &[u8],
    output: &[u8],
    tolerance_mm: f64,
) -> (f64, usize) {
    use polepatch::machine_frame::chord_error_mm;
    let chain = machine.chain.unwrap();
    let a = load_nc(input, "in", machine, None).unwrap();
    let b = load_nc(output, "out", machine, None).unwrap();
    assert_eq!(a.runs.len(), b.runs.len());
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for (ra, rb) in a.runs.iter().zip(&b.runs) {
        if ra.run.tcpm.is_on() {
            continue;
        }
        let p = a.letters();
        let (qa, qb) = (ra.run.axes5(p), rb.run.axes5(p));
        let tip = |q: &[f64; 5]| chain.part_tip(machine, datum, q[3], q[4], [q[0], q[1], q[2]]);
        for k in 1..qa.len() {
            if qa[k] == qb[k] && qa[k - 1] == qb[k - 1] {
                continue;
            }
            let tips = [tip(&qa[k - 1]), tip(&qa[k])];
            let old = chord_error_mm(&chain, machine, datum, &qa[k - 1], &qa[k], tips);
            let new = chord_error_mm(&chain, machine, datum, &qb[k - 1], &qb[k], tips);
            assert!(
                new <= tolerance_mm.max(old) + TIP_TOLERANCE_MM,
                "line {}: {new} mm (input {old} mm, tolerance {tolerance_mm})",
                b.line_of(0, 0)
            );
            worst = worst.max(new);
            checked += 1;
        }
    }
    (worst, checked)
}

/// Issue 19 §2: without TCPM the controller interpolates every axis linearly between the
/// points; rewritten with the chain, SING's blocks would take the tool tip off the programmed
/// line (first found: 0.78 mm with the earlier solver, 0.063 mm with the joint patch of issue
/// 21; the original: at most 0.13 mm). With the default chord tolerance the run keeps its
/// values and the report names the block.
#[test]
fn without_tcpm_a_rewrite_that_leaves_the_line_between_points_is_not_written() {
    let machine = example_machine();
    let (input, _) = sing_without_tcpm(&machine);
    let (out, report) = patch_nc(&input, &machine, &PatchOptions::default()).unwrap();
    assert!(out == input, "nothing written");
    let u = &report.untouched_runs[0];
    assert_eq!(u.reason, UntouchedReason::MachineFrame);
    let by_mm: f64 = u
        .message
        .split("leave the programmed line by ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{}", u.message));
    assert!(by_mm > 0.005, "{}", u.message);
    assert!(
        u.message.contains("chord tolerance 0.005 mm"),
        "{}",
        u.message
    );
    assert_eq!(report.zones[0].outcome, polepatch::Outcome::Unchanged);
}

/// The generated near-pole passes (short blocks) written without TCPM for the example
/// chain: patched through the chain with the default chord tolerance, and on the written
/// values every changed block keeps the tool tip within it between the points.
#[test]
fn without_tcpm_every_changed_block_stays_within_the_chord_tolerance() {
    let machine = example_machine();
    let datum = [-30.0, -7.0, 40.0];
    let mut patched = 0;
    for name in [
        "heidenhain-ac-flip-d0.5.I",
        "heidenhain-ac-swing-d0.5.I",
        "heidenhain-ac-flip-d2.I",
        "heidenhain-ac-swing-d0.I",
    ] {
        let tcpm = std::fs::read(root().join("fixtures/generated").join(name)).unwrap();
        let input = machine_coordinates(&machine, &tcpm, datum);
        let opts = PatchOptions {
            read: ReadOptions {
                work_offset_mm: Some(datum),
                ..ReadOptions::default()
            },
            ..PatchOptions::default()
        };
        let (out, report) = patch_nc(&input, &machine, &opts).unwrap();
        let (worst, checked) = chord_errors(
            &machine,
            datum,
            &input,
            &out,
            polepatch::machine_frame::CHORD_TOLERANCE_MM,
        );
        if out != input {
            patched += 1;
            assert!(checked > 0, "{name}");
        }
        eprintln!(
            "{name}: {checked} changed blocks, worst chord {worst:.4} mm; {:?}",
            report.untouched_runs
        );
    }
    assert!(patched >= 1, "the chain path is exercised");
}

/// A TCPM program written without TCPM for `machine`'s chain and work offset `datum`:
/// every point of its TCPM runs with X Y Z through the chain (3 decimals), the M128 line
/// removed.
fn machine_coordinates(machine: &Machine, tcpm_program: &[u8], datum: [f64; 3]) -> Vec<u8> {
    let chain = machine.chain.unwrap();
    let lp = load_nc(tcpm_program, "tcpm", machine, None).unwrap();
    let program = &lp.program;
    let mut edits = Vec::new();
    for rp in lp.runs.iter().filter(|rp| rp.run.tcpm.is_on()) {
        for &b in &rp.run.blocks {
            let st = program.state(b);
            let v = |i: usize| st.pos[i].unwrap_or(0.0);
            let tip = [v(modal::X), v(modal::Y), v(modal::Z)];
            let x = chain.program_xyz(machine, datum, v(lp.primary_index()), v(modal::C), tip);
            for (i, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                let value = (x[i] * 1000.0).round() / 1000.0;
                if value != tip[i] {
                    edits.push(Edit {
                        block: b,
                        letter,
                        value,
                        decimals: 3,
                    });
                }
            }
        }
    }
    edits.sort_by_key(|e| (e.block, e.letter));
    let text = String::from_utf8(polepatch::nc::write(program, &edits)).unwrap();
    let without: Vec<&str> = text
        .split_inclusive('\n')
        .filter(|l| !l.contains("M128"))
        .collect();
    without.concat().into_bytes()
}

/// With a chord tolerance that admits SING's long blocks, the chain path writes X Y Z with
/// the rotary values and the tool tip stays at every point.
#[test]
fn without_tcpm_x_y_z_change_with_the_rotary_axes_and_the_tool_tip_stays() {
    let machine = example_machine();
    let chain = machine.chain.unwrap();
    let (input, tips) = sing_without_tcpm(&machine);
    let opts = PatchOptions {
        read: ReadOptions {
            name: "SING_noM128.I".into(),
            ..ReadOptions::default()
        },
        chord_tolerance_mm: 1.0,
        ..PatchOptions::default()
    };
    let (out, report) = patch_nc(&input, &machine, &opts).unwrap();
    assert!(
        report.untouched_runs.is_empty(),
        "{:?}",
        report.untouched_runs
    );
    assert_eq!(report.zones.len(), 1);
    assert_eq!(
        report.zones[0].outcome,
        polepatch::Outcome::Reached,
        "{:?}",
        report.zones[0]
    );
    // X Y Z and C change together, block by block.
    let before = load_nc(&input, "in", &machine, None).unwrap();
    let after = load_nc(&out, "out", &machine, None).unwrap();
    let (bp, ap) = (&before.program, &after.program);
    assert_eq!(bp.blocks.len(), ap.blocks.len());
    let mut c_changed = 0;
    let mut xyz_with_c = 0;
    let mut worst_mm: f64 = 0.0;
    for (b, tip) in tips.iter().enumerate() {
        let (s0, s1) = (bp.state(b), ap.state(b));
        if s0.pos[modal::C] != s1.pos[modal::C] || s0.pos[modal::A] != s1.pos[modal::A] {
            c_changed += 1;
            if s0.pos[..3] != s1.pos[..3] {
                xyz_with_c += 1;
            }
        }
        // The part-frame tool tip of every point of the converted run, on the written
        // values, against the input's.
        if let Some(orig) = tip {
            let tip_of = |st: &polepatch::nc::Modal| {
                let v = |i: usize| st.pos[i].unwrap();
                chain.part_tip(
                    &machine,
                    ON_AXIS_DATUM,
                    v(modal::A),
                    v(modal::C),
                    [v(modal::X), v(modal::Y), v(modal::Z)],
                )
            };
            let (t0, t1) = (tip_of(&s0), tip_of(&s1));
            let err = (0..3).map(|i| (t1[i] - t0[i]).abs()).fold(0.0, f64::max);
            worst_mm = worst_mm.max(err);
            // And the input is SING's part path (to its 3 written decimals).
            let conv = (0..3).map(|i| (t0[i] - orig[i]).abs()).fold(0.0, f64::max);
            assert!(conv <= 2e-3, "line {}: {conv}", ap.blocks[b].line);
        }
    }
    assert!(c_changed >= 10, "{c_changed} blocks changed");
    // A pose change too small to move the tip by the last written digit keeps its X Y Z
    // (the tip check below covers it).
    assert!(
        xyz_with_c * 10 >= c_changed * 9,
        "{xyz_with_c} of {c_changed} changed poses have new X Y Z"
    );
    assert!(worst_mm <= TIP_TOLERANCE_MM, "tool tip moved {worst_mm} mm");
    // Between the points: within the tolerance given (or the input block's).
    let (worst, checked) = chord_errors(&machine, ON_AXIS_DATUM, &input, &out, 1.0);
    assert!(
        checked >= 10 && worst > 0.5,
        "{checked} blocks, worst {worst} mm"
    );
    // Only X Y Z A C words differ.
    let (a, b) = (
        String::from_utf8_lossy(&input),
        String::from_utf8_lossy(&out),
    );
    for (la, lb) in a.lines().zip(b.lines()) {
        let strip = |l: &str| {
            l.split_whitespace()
                .filter(|w| !w.starts_with(['X', 'Y', 'Z', 'A', 'C']))
                .collect::<Vec<_>>()
                .join(" ")
        };
        assert_eq!(strip(la), strip(lb));
    }
}

#[test]
fn without_tcpm_and_without_a_work_offset_the_run_is_left() {
    // The chain is known but the program states no datum (G54 line removed).
    let machine = example_machine();
    let (input, _) = sing_without_tcpm(&machine);
    let text = String::from_utf8(input).unwrap();
    let text = text.replace(&datum_line(ON_AXIS_DATUM), "");
    let (out, report) = patch_nc(text.as_bytes(), &machine, &PatchOptions::default()).unwrap();
    assert_eq!(out, text.as_bytes());
    assert_eq!(report.untouched_runs[0].reason, UntouchedReason::NoTcpm);
    assert!(
        report.untouched_runs[0].message.contains("--work-offset"),
        "{}",
        report.untouched_runs[0].message
    );
    // Given on the command line, the run is patched (with a chord tolerance that admits
    // SING's long blocks).
    let opts = PatchOptions {
        read: ReadOptions {
            work_offset_mm: Some(ON_AXIS_DATUM),
            ..ReadOptions::default()
        },
        chord_tolerance_mm: 1.0,
        ..PatchOptions::default()
    };
    let (out, report) = patch_nc(text.as_bytes(), &machine, &opts).unwrap();
    assert_ne!(out, text.as_bytes());
    assert_eq!(report.zones[0].outcome, polepatch::Outcome::Reached);
}

/// The set-up: the part 50 mm off the C axis at the zone (the C axis put at
/// machine X = −55.489, Y = −7.1 for SING's datum, so the tool point X25 Y0 of the zone is
/// 50 mm from it). C needs 192 rpm there; the linear axes then follow the table at about
/// 2π·50 mm·192/min ≈ 60 m/min (C17 eq. 6).
#[test]
fn analyze_reports_machine_frame_linear_axes_that_follow_c() {
    let mut machine = Machine::builtin("mikron-ucp710").unwrap();
    machine.chain = Some(Chain {
        primary_axis_point_mm: [0.0, 0.0, -50.0],
        c_axis_point_mm: [-55.489, -7.1, 0.0],
    });
    let report = analyze_nc(&sing(), &machine, &AnalyzeOptions::default()).unwrap();
    let run = &report.runs[0];
    let f = run.figures.as_ref().unwrap();
    assert!(
        (f.peak_speed["C"] - 192.4).abs() < 1.0,
        "{}",
        f.peak_speed["C"]
    );
    let m = run.machine_frame.as_ref().expect("machine-frame figures");
    assert_eq!(m.datum_mm, SING_DATUM);
    let xy = m.peak_speed["X"].max(m.peak_speed["Y"]);
    assert!((55.0..65.0).contains(&xy), "{:?}", m.peak_speed);
    assert!(m.axis_min_ratio["Y"] < 0.3, "{:?}", m.axis_min_ratio);
    // Without a chain there are no machine-frame figures.
    let plain = analyze_nc(
        &sing(),
        &Machine::builtin("mikron-ucp710").unwrap(),
        &AnalyzeOptions::default(),
    )
    .unwrap();
    assert!(plain.runs[0].machine_frame.is_none());
    // The TCPM patch frees C and, with it, the machine-frame X and Y: accepted.
    let (out, rep) = patch_nc(&sing(), &machine, &PatchOptions::default()).unwrap();
    assert_eq!(rep.zones[0].outcome, polepatch::Outcome::Reached);
    let after = analyze_nc(&out, &machine, &AnalyzeOptions::default()).unwrap();
    let ma = after.runs[0].machine_frame.as_ref().unwrap();
    assert!(ma.axis_min_ratio["Y"] > 0.7, "{:?}", ma.axis_min_ratio);
}

/// SING with its M128 deleted (X Y Z stay part coordinates, read now as machine
/// coordinates): with the example chain's A axis 150 mm below the table the patch would
/// slow X in the machine frame (its lowest ratio 0.891 → about 0.56: the tilt the patch
/// adds at the pole moves the part on a long arm), so the run keeps every value and the
/// report says why. (With the example's 50 mm the patch's X ratio is the same as before
/// to the third decimal: too close a call for this test.)
#[test]
fn a_patch_that_slows_a_linear_axis_in_the_machine_frame_is_not_written() {
    let mut machine = example_machine();
    machine.chain = machine.chain.map(|c| Chain {
        primary_axis_point_mm: [0.0, 0.0, -150.0],
        ..c
    });
    let text = String::from_utf8(sing())
        .unwrap()
        .replace("N65 M128 *\n", "");
    // The chord check would stop it first; without it, the machine-frame check does.
    let opts = PatchOptions {
        chord_tolerance_mm: f64::INFINITY,
        ..PatchOptions::default()
    };
    let (out, report) = patch_nc(text.as_bytes(), &machine, &opts).unwrap();
    assert_eq!(out, text.as_bytes());
    let u = &report.untouched_runs[0];
    assert_eq!(u.reason, UntouchedReason::MachineFrame);
    assert!(u.message.contains("in the machine frame"), "{}", u.message);
    assert_eq!(report.zones[0].outcome, polepatch::Outcome::Unchanged);
}

/// The work offset is taken only where it is known for certain.
#[test]
fn the_work_offset_is_known_or_the_run_is_left() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let given = Some([10.0, 20.0, 30.0]);
    let datum = |text: &str, given: Option<[f64; 3]>| {
        let opts = polepatch::AnalyzeOptions {
            read: polepatch::ReadOptions {
                work_offset_mm: given,
                ..polepatch::ReadOptions::default()
            },
            ..polepatch::AnalyzeOptions::default()
        };
        let lp = polepatch::load_nc_with(text.as_bytes(), &m, &opts).unwrap();
        lp.datum_mm(lp.runs.len() - 1)
    };
    let run = "G1 X0 Y0 Z0 A30 C0 F1000\nX1 C10\nX2 C20\n";
    // Fanuc names G54 once: the command line's value.
    assert_eq!(datum(&format!("G54\n{run}"), given), given);
    assert_eq!(datum(&format!("G54\n{run}"), None), None);
    // No frame named at all: the command line's value too.
    assert_eq!(datum(run, given), given);
    // A G92 (or a second offset) after it: not followed, unknown even with a value.
    assert_eq!(datum(&format!("G54\nG92 X0 Y0 Z0\n{run}"), given), None);
    assert_eq!(datum(&format!("G54\n{run}G55\n{run}"), given), None);
    // Heidenhain states its datum: that one.
    let h =
        "%P G71 *\nN1 G54 X1 Y2 Z3 *\nN2 G01 X0 Y0 Z0 A30 C0 F1000 *\nN3 X1 C10 *\nN4 X2 C20 *\n";
    assert_eq!(datum(h, None), Some([1.0, 2.0, 3.0]));
    assert_eq!(datum(h, given), Some([1.0, 2.0, 3.0]));
}

/// Issue 26 §2: a rotation, scaling or mirror image of the frame before a run without TCPM
/// (it was rewritten as if the frame were the datum's alone, moving the tool tip 14–60 mm):
/// the run is left with reason `frame_transformed`, also where the user gives the work
/// offset; the code's end restores the patch.
#[test]
fn a_transformed_frame_leaves_the_run() {
    let machine = example_machine();
    let (input, _) = sing_without_tcpm(&machine);
    let text = String::from_utf8(input).unwrap();
    let datum = &datum_line(ON_AXIS_DATUM);
    assert!(text.contains(datum));
    let opts = PatchOptions {
        chord_tolerance_mm: 1.0,
        ..PatchOptions::default()
    };
    let mut given = opts.clone();
    given.read.work_offset_mm = Some(ON_AXIS_DATUM);
    for code in [
        "N61 G73 G90 H+30 *\n",
        "N61 G72 F0.9995 *\n",
        "N61 G28 X+0 *\n",
        "N61 G68 X+0 Y+0 R+30 *\n",
    ] {
        let t = text.replace(datum, &format!("{datum}{code}"));
        for o in [&opts, &given] {
            let (out, report) = patch_nc(t.as_bytes(), &machine, o).unwrap();
            assert_eq!(out, t.as_bytes(), "{code}");
            let u = &report.untouched_runs[0];
            assert_eq!(u.reason, UntouchedReason::FrameTransformed, "{code}");
            assert!(
                report
                    .zones
                    .iter()
                    .all(|z| z.reason == polepatch::ZoneReason::FrameTransformed),
                "{code}"
            );
        }
    }
    // Cancelled before the run: patched as without it.
    let (baseline, _) = patch_nc(text.as_bytes(), &machine, &opts).unwrap();
    assert_ne!(baseline, text.as_bytes());
    let t = text.replace(
        datum,
        &format!("N58 G73 G90 H+30 *\nN59 G73 G90 H+0 *\n{datum}"),
    );
    let (out, report) = patch_nc(t.as_bytes(), &machine, &opts).unwrap();
    assert!(
        report.untouched_runs.is_empty(),
        "{:?}",
        report.untouched_runs
    );
    assert_ne!(out, t.as_bytes());
}

/// G16 eq. 1 (the UCP710's senses): the tool axis in the part frame, written here apart
/// from the library's forward kinematics.
fn tool_axis(a_deg: f64, c_deg: f64) -> [f64; 3] {
    let (a, c) = (a_deg.to_radians(), c_deg.to_radians());
    [c.sin() * a.sin(), -c.cos() * a.sin(), a.cos()]
}

/// Issue 39 class 4: a ball programmed at its tip, without TCPM, patched through the chain:
/// its centre in the part frame (the chain's part-frame tip + R·o) stays where it was at
/// every point, within 1 µm plus the rounding of the written X Y Z (3 decimals) and rotary
/// words (4). Before the fix the chain kept the tip: the centre moved 0.2255 mm at N110.
#[test]
fn without_tcpm_a_ball_at_its_tip_keeps_its_centre_through_the_chain() {
    let machine = example_machine();
    let chain = machine.chain.unwrap();
    let (input, _) = sing_without_tcpm(&machine);
    let opts = PatchOptions {
        read: ReadOptions {
            name: "SING_noM128_ball.I".into(),
            ..ReadOptions::default()
        },
        chord_tolerance_mm: 1.0,
        tool: polepatch::tool::ToolOptions {
            tool: Some(polepatch::tool::Tool::parse("ball:10").unwrap()),
            ..Default::default()
        },
        ..PatchOptions::default()
    };
    let (out, report) = patch_nc(&input, &machine, &opts).unwrap();
    assert_eq!(report.zones.len(), 1);
    assert_eq!(
        report.zones[0].outcome,
        polepatch::Outcome::Reached,
        "{:?}",
        report.zones[0]
    );
    assert!(report.zones[0].max_deviation_deg > 1.0);
    let before = load_nc(&input, "in", &machine, None).unwrap();
    let after = load_nc(&out, "out", &machine, None).unwrap();
    let centre = |st: &polepatch::nc::Modal| {
        let v = |i: usize| st.pos[i].unwrap();
        let tip = chain.part_tip(
            &machine,
            ON_AXIS_DATUM,
            v(modal::A),
            v(modal::C),
            [v(modal::X), v(modal::Y), v(modal::Z)],
        );
        let o = tool_axis(v(modal::A), v(modal::C));
        [
            tip[0] + 5.0 * o[0],
            tip[1] + 5.0 * o[1],
            tip[2] + 5.0 * o[2],
        ]
    };
    let rounding = 3f64.sqrt() * 0.5e-3 + 5.0 * (2.0 * 0.5e-4f64).to_radians();
    let mut moved = 0;
    for rp in before.runs.iter().filter(|rp| !rp.run.tcpm.is_on()) {
        for &b in &rp.run.blocks[1..] {
            let (s0, s1) = (before.program.state(b), after.program.state(b));
            if s0.pos == s1.pos {
                continue;
            }
            moved += 1;
            let (c0, c1) = (centre(&s0), centre(&s1));
            let d = (0..3).map(|i| (c0[i] - c1[i]).powi(2)).sum::<f64>().sqrt();
            assert!(
                d <= TIP_TOLERANCE_MM + rounding,
                "line {}: the ball's centre moved {d} mm",
                before.program.blocks[b].line
            );
        }
    }
    assert!(moved >= 10, "{moved} points changed");
}

/// With SING's approach in the run at F, the chain patch slows the first span's C in the
/// machine frame (the written program's rule, span by span): the run keeps its values and
/// the report says where.
#[test]
fn a_patch_that_slows_a_span_in_the_machine_frame_is_not_written() {
    let machine = example_machine();
    let (input, _) = sing_without_tcpm(&machine);
    let text = String::from_utf8(input)
        .unwrap()
        .replace("N70 G00 ", "N70 G01 ")
        .replace("N110 G01 X", "N110 X");
    let opts = PatchOptions {
        chord_tolerance_mm: 1.0,
        ..PatchOptions::default()
    };
    let (out, report) = patch_nc(text.as_bytes(), &machine, &opts).unwrap();
    assert_eq!(out, text.as_bytes());
    let u = &report.untouched_runs[0];
    assert_eq!(u.reason, UntouchedReason::MachineFrame, "{}", u.message);
    assert!(
        u.message.contains("would slow the machine between lines"),
        "{}",
        u.message
    );
    assert!(
        report
            .zones
            .iter()
            .all(|z| z.outcome == polepatch::Outcome::Unchanged)
    );
}

/// With SING's own datum the part is 30 mm off the C axis: the chain patch, solved on the
/// part-frame path, slows the machine in the machine frame at the zone's end (a span at
/// feed drops to about 0.9 of it, C limiting: without TCPM the feed is along the machine's
/// X Y Z path, which the table's swing shortens there). The run keeps its values and the
/// report says where (issue 39: the written program is never slower anywhere).
#[test]
fn with_sings_datum_the_chain_patch_slows_the_machine_and_is_not_written() {
    let machine = example_machine();
    let (input, _) = sing_without_tcpm_at(&machine, SING_DATUM);
    let opts = PatchOptions {
        chord_tolerance_mm: 1.0,
        ..PatchOptions::default()
    };
    let (out, report) = patch_nc(&input, &machine, &opts).unwrap();
    assert_eq!(out, input);
    let u = &report.untouched_runs[0];
    assert_eq!(u.reason, UntouchedReason::MachineFrame, "{}", u.message);
    assert!(
        u.message.contains("where the original reaches feed"),
        "{}",
        u.message
    );
}
