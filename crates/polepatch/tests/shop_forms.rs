//! Issue 20: the programs shops have — Heidenhain conversational (FUNCTION TCPM and M128),
//! inverse-time feed (Fanuc and LinuxCNC), spaces inside words, a machine whose TCP is
//! switched by its own M codes or always on, variables in one run — are read, analysed
//! and patched like the G94 ISO program of the same path: the same zones and ratios, the
//! same rotary values written, and nothing but rotary words changed (the F words of G93
//! blocks included).

use polepatch::kinematics::{Controller, Machine};
use polepatch::nc::modal::{A, C};
use polepatch::nc::{Dialect, FeedMode, parse};
use polepatch::{FileReport, PatchOptions, UntouchedReason, patch_nc};
use std::path::PathBuf;

fn shop(name: &str) -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/shop")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

/// The UCP710 with LinuxCNC's switchable-kinematics codes, or always TCP.
fn linuxcnc(always: bool) -> Machine {
    let mut m = Machine::builtin("mikron-ucp710").unwrap();
    m.controller = Controller {
        tcpm_on: if always { vec![] } else { vec!["M428".into()] },
        tcpm_off: if always {
            vec![]
        } else {
            vec!["M429".into(), "M430".into()]
        },
        tcpm_always: always,

        ..Default::default()
    };
    m
}

/// The pass's points as written: (X, A, C) of every move that ends on the cut (Y0 Z-5), in
/// file order, repeats dropped.
fn pass_values(bytes: &[u8]) -> Vec<[f64; 3]> {
    let p = parse(bytes.to_vec(), Dialect::Auto).unwrap();
    let mut out = Vec::new();
    for b in 0..p.blocks.len() {
        let st = p.state(b);
        if p.blocks[b].is_move && st.pos[2] == Some(-5.0) && st.pos[1] == Some(0.0) {
            let v = [st.pos[0].unwrap(), st.pos[A].unwrap(), st.pos[C].unwrap()];
            if out.last() != Some(&v) {
                out.push(v);
            }
        }
    }
    out
}

/// The program with its rotary words taken out, each line's words separated by one space:
/// what must not change (a patch may add rotary words to a block of its pass that had none,
/// like a plunge's end).
fn without_rotary_values(bytes: &[u8]) -> Vec<u8> {
    let p = parse(bytes.to_vec(), Dialect::Auto).unwrap();
    let mut out = Vec::new();
    let mut at = 0;
    for w in &p.words {
        if matches!(w.letter, b'A' | b'B' | b'C') {
            out.extend_from_slice(&bytes[at..w.span().start]);
            at = w.span().end;
        }
    }
    out.extend_from_slice(&bytes[at..]);
    String::from_utf8_lossy(&out)
        .lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" ") + "\n")
        .collect::<String>()
        .into_bytes()
}

/// The G94 twin with the conversational forms' approach: a positioning move to the first
/// point at Z0, a plunge at F500, the cut at F2000 (the first cut block states it).
fn plunged_twin(twin: &[u8]) -> Vec<u8> {
    let text = String::from_utf8(twin.to_vec()).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let first = lines
        .iter()
        .position(|l| l.starts_with("G1 X0 Y0 Z-5 "))
        .unwrap();
    let start = lines[first]
        .trim_end_matches(" F2000")
        .replacen("G1", "G0", 1);
    lines[first] = format!("{}\nG1 Z-5 F500", start.replace("Z-5", "Z0"));
    lines[first + 1].push_str(" F2000");
    let mut out = lines.join("\n");
    out.push('\n');
    out.into_bytes()
}

fn patched(bytes: &[u8], m: &Machine) -> (Vec<u8>, FileReport) {
    patch_nc(bytes, m, &PatchOptions::default()).unwrap()
}

#[test]
fn every_form_patches_like_its_g94_iso_twin() {
    for stem in ["ac-flip-d0.5", "ac-swing-d1"] {
        let ucp = Machine::builtin("mikron-ucp710").unwrap();
        let twin = shop(&format!("{stem}-fanuc-g94.nc"));
        let (twin_out, twin_report) = patched(&twin, &ucp);
        assert!(!twin_report.zones.is_empty(), "{stem}: the twin has a zone");
        assert!(
            twin_report
                .zones
                .iter()
                .all(|z| z.outcome == polepatch::Outcome::Reached)
        );
        let want = pass_values(&twin_out);
        // The forms plunge at F500 from a positioning move and cut at F2000: under G94 one
        // pass (issue 41: a change of F does not end it), so their twin plunges too; under
        // G93 the plunge (G94) and the cut are two runs, as in the twin without a plunge.
        let plunged = plunged_twin(&twin);
        let (plunged_out, plunged_report) = patched(&plunged, &ucp);
        let plunged_want = pass_values(&plunged_out);
        for (form, machine) in [
            ("conv-function-tcpm.H", ucp.clone()),
            ("conv-m128.H", ucp.clone()),
            ("fanuc-g93.nc", ucp.clone()),
            ("linuxcnc-g93-m428.ngc", linuxcnc(false)),
            ("always-tcp.ngc", linuxcnc(true)),
            ("spaced-words.nc", ucp.clone()),
            ("variables.nc", ucp.clone()),
        ] {
            let name = format!("{stem}-{form}");
            let input = shop(&name);
            let (out, report) = patched(&input, &machine);
            let (twin_report, want) = if !form.contains("g93") {
                (&plunged_report, &plunged_want)
            } else {
                (&twin_report, &want)
            };
            assert!(out != input, "{name}: patched");
            assert_eq!(
                without_rotary_values(&out),
                without_rotary_values(&input),
                "{name}: only rotary values change (F words of G93 blocks included)"
            );
            assert_eq!(report.zones.len(), twin_report.zones.len(), "{name}");
            for (z, t) in report.zones.iter().zip(&twin_report.zones) {
                assert_eq!(z.kind, t.kind, "{name}");
                assert_eq!(z.outcome, t.outcome, "{name}");
                for (a, b) in [
                    (z.before.c_ratio, t.before.c_ratio),
                    (z.before.primary_ratio, t.before.primary_ratio),
                    (z.after.c_ratio, t.after.c_ratio),
                    (z.after.primary_ratio, t.after.primary_ratio),
                    (z.max_deviation_deg, t.max_deviation_deg),
                ] {
                    assert!(
                        (a - b).abs() <= 1e-9 * b.abs().max(1.0),
                        "{name}: {a} vs {b}"
                    );
                }
                let g93 = form.contains("g93");
                assert_eq!(
                    z.feed_mode,
                    if g93 {
                        FeedMode::InverseTime
                    } else {
                        FeedMode::PerMinute
                    },
                    "{name}"
                );
            }
            assert_eq!(
                &pass_values(&out),
                want,
                "{name}: the same rotary values written"
            );
            let expression = report
                .not_analysed
                .iter()
                .any(|n| n.reason == polepatch::report::SkipReason::Expression);
            assert_eq!(
                expression,
                form == "variables.nc",
                "{name}: {:?}",
                report.not_analysed
            );
        }
    }
}

/// Without the machine's word for M428 (or that its kinematics are always TCP), the same
/// LinuxCNC programs are machine coordinates: left byte for byte, reported.
#[test]
fn linuxcnc_tcp_needs_the_machines_codes() {
    let ucp = Machine::builtin("mikron-ucp710").unwrap();
    for name in [
        "ac-flip-d0.5-linuxcnc-g93-m428.ngc",
        "ac-flip-d0.5-always-tcp.ngc",
    ] {
        let input = shop(name);
        let (out, report) = patched(&input, &ucp);
        assert!(out == input, "{name}");
        // No TCPM, or (after `M6`, which a Fanuc-style control may run as a macro, and no
        // code the reader knows settling it after) unknown: left either way.
        assert!(
            report.untouched_runs.iter().any(|u| matches!(
                u.reason,
                UntouchedReason::NoTcpm | UntouchedReason::TcpmUnknown
            ) && u.zones > 0),
            "{name}: {:?}",
            report.untouched_runs
        );
    }
}

/// Issue 20 §3: Equation 6 on a G93 run is the G94 analysis at the same block feeds.
#[test]
fn equation_6_on_g93_is_g94_at_the_block_feeds() {
    let ucp = Machine::builtin("mikron-ucp710").unwrap();
    let g93 = polepatch::analyze_nc(
        &shop("ac-swing-d1-fanuc-g93.nc"),
        &ucp,
        &polepatch::AnalyzeOptions::default(),
    )
    .unwrap();
    let g94 = polepatch::analyze_nc(
        &shop("ac-swing-d1-fanuc-g94.nc"),
        &ucp,
        &polepatch::AnalyzeOptions::default(),
    )
    .unwrap();
    let cut = |r: &polepatch::AnalyzeReport| {
        r.runs
            .iter()
            .filter(|run| run.points > 50)
            .cloned()
            .collect::<Vec<_>>()
    };
    let (a, b) = (cut(&g93), cut(&g94));
    assert_eq!(a.len(), 1);
    assert_eq!(b.len(), 1);
    assert_eq!(a[0].feed_mode, FeedMode::InverseTime);
    assert_eq!(a[0].feed_mm_min, Some(2000.0));
    let (fa, fb) = (
        a[0].figures.as_ref().unwrap(),
        b[0].figures.as_ref().unwrap(),
    );
    assert_eq!(fa.min_ratio, fb.min_ratio);
    assert_eq!(fa.time_s, fb.time_s);
    assert_eq!(fa.axis_min_ratio, fb.axis_min_ratio);
    assert_eq!(fa.zones.len(), fb.zones.len());
}

/// Issue 20 §7: a program that holds nothing to analyse — no G1 motion (a drilling or
/// subprogram-call program), no rotary word (3-axis), every G1 move an expression — is
/// read, written unchanged and reported with a warning (exit 0); the expression lines are
/// listed as not analysed (`--strict`: 2). `simulate` says a program without G1 motion has
/// nothing to simulate, and refuses the others by name.
#[test]
fn a_program_with_nothing_to_analyse_is_written_unchanged() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    for (text, why, listed) in [
        (
            "G0 X0 Y0 Z50\nG81 X10 Y10 Z-5 R2 F100\nX20\nG80\nM30\n",
            "no G1 motion",
            0,
        ),
        (
            "G1 X0 Y0 Z0 F1000\nX10\nX20 Y5\nM30\n",
            "no rotary axis words",
            0,
        ),
        // A vector program (tool directions as I J K on G1, no rotary words): said so.
        (
            "G1 X0 Y0 Z0 F1000\nG1 X1 I0 J0.1 K0.995\nX2\nM30\n",
            "is this a 5-axis program? Its G1 moves carry I J K words (first at line 2): \
             tool-direction vectors, which polepatch does not read",
            0,
        ),
        (
            "M128\nG1 X0 Y0 Z0 A#1 C0 F1000\nG1 X1 A#2 C#3\nM30\n",
            "expressions or variables",
            1,
        ),
    ] {
        let (out, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default())
            .unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(out, text.as_bytes());
        assert!(report.zones.is_empty());
        assert!(
            report.warnings.iter().any(|w| w.contains(why)),
            "{:?}",
            report.warnings
        );
        assert_eq!(report.not_analysed.len(), listed, "{text}");
        assert_eq!(report.strict_failures(), listed, "{text}");
        let a = polepatch::analyze_nc(text.as_bytes(), &m, &polepatch::AnalyzeOptions::default())
            .unwrap();
        assert!(a.runs.is_empty());
        assert!(
            a.warnings.iter().any(|w| w.contains(why)),
            "{:?}",
            a.warnings
        );
        // Issue 43: a program without G1 motion is simulated as nothing to simulate (said
        // so, exit 0); the others, which move, are simulated or refused by name.
        let sim = polepatch::simulate::simulate_nc(
            text.as_bytes(),
            &m,
            &polepatch::simulate::SimulateOptions::default(),
        );
        if why == "no G1 motion" {
            let sim = sim.unwrap_or_else(|e| panic!("{text}: {e}"));
            assert!(sim.nothing_to_simulate.is_some(), "{text}");
        } else {
            assert!(sim.is_err(), "{text}");
        }
    }
}

/// A CL file handed to `patch` or `analyze` is named as one, at its first `GOTO/` record —
/// whatever line the NC reader would stumble on first (CAMWorks' `SPINDL/RPM,…` on line 1
/// read as an S word without a number).
#[test]
fn a_cl_file_is_named_as_one() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/cl");
    for (file, line) in [
        ("camworks_plate.apt", 15),
        ("camworks_bracket_inch.apt", 9),
        ("nx_5axis.cls", 13),
        ("SING.apt", 5),
    ] {
        let bytes = std::fs::read(root.join(file)).unwrap();
        let opts = PatchOptions::named(file.to_string());
        let want = format!("{file}:{line}: this is a CL file");
        let e = patch_nc(&bytes, &m, &opts).unwrap_err().to_string();
        assert!(e.starts_with(&want), "{e}");
        let a = polepatch::AnalyzeOptions {
            read: polepatch::ReadOptions {
                name: file.to_string(),
                ..polepatch::ReadOptions::default()
            },
            ..polepatch::AnalyzeOptions::default()
        };
        let e = polepatch::analyze_nc(&bytes, &m, &a)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(&want), "{e}");
    }
}

/// Conversational as manuals and forums show it — no `BEGIN PGM`, `M128` on the approach
/// block, which leaves A and C unstated — is read as conversational, and the run starts
/// where the rotary axes are first programmed: its zone is patched, rotary words only.
#[test]
fn a_conversational_fragment_with_an_unstated_start_is_patched() {
    let mut text = String::from("; TNC 5-axis\nL X+0 Y+0 Z+50 R0 FMAX M128 ; TCPM ON\n");
    for k in 0..41 {
        let a = if k == 20 {
            0.3
        } else {
            -2.0 + 0.1 * f64::from(k)
        };
        let c = 30.0 + f64::from(k) + if a > 0.0 { 150.0 } else { 0.0 };
        text += &format!(
            "L X{:+.3} Y{:+.3} Z-5 A{a:+.3} C{c:+.3} F1500\n",
            10.0 + 0.5 * f64::from(k),
            0.1 * f64::from(k)
        );
    }
    text += "L Z+50 R0 FMAX\nM129 ; TCPM OFF\nM30\n";
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let (out, report) = patched(text.as_bytes(), &m);
    assert!(
        report.untouched_runs.is_empty(),
        "{:?}",
        report.untouched_runs
    );
    assert_eq!(report.zones.len(), 1);
    assert_eq!(report.zones[0].outcome, polepatch::Outcome::Reached);
    assert_eq!(
        without_rotary_values(&out),
        without_rotary_values(text.as_bytes())
    );
}
