//! Issue 26: TCPM through calls, labels and jumps. A run after a call, a label or a jump is
//! rewritten only where the file settles that TCPM is on there; where the called code or a
//! joining path switches it off, the run is left as a run without TCPM; where the file
//! cannot settle it (code outside the file, paths with different states meeting), the run
//! is left with reason `tcpm_unknown`. One near-pole pass (the generated A-C swing 0.5° from
//! the pole) in every dialect's call, label and jump forms.

use polepatch::kinematics::{Controller, Machine};
use polepatch::{FileReport, PatchOptions, UntouchedReason, patch_nc};

fn fixture(path: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../../fixtures/{path}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

fn ucp() -> Machine {
    Machine::builtin("mikron-ucp710").unwrap()
}

/// The UCP710 with LinuxCNC's switchable-kinematics codes.
fn linuxcnc() -> Machine {
    let mut m = ucp();
    m.controller = Controller {
        tcpm_on: vec!["M428".into()],
        tcpm_off: vec!["M429".into()],
        tcpm_always: false,

        ..Default::default()
    };
    m
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Want {
    /// The zone is patched.
    Patched,
    /// The run is left byte-identical, for this reason.
    Left(UntouchedReason),
}

fn check(label: &str, text: &str, m: &Machine, want: Want) -> FileReport {
    let (out, report) = patch_nc(text.as_bytes(), m, &PatchOptions::default())
        .unwrap_or_else(|e| panic!("{label}: {e}"));
    assert!(!report.zones.is_empty(), "{label}: the zone is found");
    match want {
        Want::Patched => {
            assert_ne!(out, text.as_bytes(), "{label}: patched");
            assert!(
                report
                    .zones
                    .iter()
                    .all(|z| z.outcome == polepatch::Outcome::Reached),
                "{label}: {:#?}",
                report.zones
            );
        }
        Want::Left(reason) => {
            assert_eq!(
                String::from_utf8_lossy(&out),
                text,
                "{label}: no byte may change"
            );
            assert_eq!(report.words_changed, 0, "{label}");
            assert!(
                report
                    .untouched_runs
                    .iter()
                    .any(|u| u.reason == reason && u.zones > 0),
                "{label}: {:#?}",
                report.untouched_runs
            );
            let zone_reason = reason
                .zone_reason()
                .unwrap_or(polepatch::ZoneReason::NotPatched);
            assert!(
                report
                    .zones
                    .iter()
                    .all(|z| z.outcome == polepatch::Outcome::Unchanged && z.reason == zone_reason),
                "{label}: {:#?}",
                report.zones
            );
        }
    }
    report
}

/// The generated Fanuc A-C swing with `before_cut` in place of its `G43.4 H1` line and
/// `after_end` after its `M30`.
fn fanuc(before_cut: &str, after_end: &str) -> String {
    let base = fixture("generated/fanuc-ac-swing-d0.5.nc");
    assert!(base.contains("G43.4 H1\n") && base.contains("M30\n"));
    base.replace("G43.4 H1\n", before_cut)
        .replace("M30\n", &format!("M30\n{after_end}"))
}

#[test]
fn the_plain_program_is_patched_in_every_dialect() {
    check(
        "fanuc",
        &fixture("generated/fanuc-ac-swing-d0.5.nc"),
        &ucp(),
        Want::Patched,
    );
    check(
        "sinumerik",
        &fixture("generated/sinumerik-ac-swing-d0.5.mpf"),
        &ucp(),
        Want::Patched,
    );
    check(
        "heidenhain",
        &fixture("generated/heidenhain-ac-swing-d0.5.I"),
        &ucp(),
        Want::Patched,
    );
    check(
        "conversational",
        &fixture("shop/ac-swing-d1-conv-function-tcpm.H"),
        &ucp(),
        Want::Patched,
    );
}

/// The minimal case: `G43.4 H1`, `M98 P2000`, then the zone, with `O2000` = `G49`
/// `M99` further down. Was: exit 0 with `A1 C180` written as `A0.015 C90.186`.
#[test]
fn fanuc_calls() {
    let left_off = Want::Left(UntouchedReason::NoTcpm);
    let unknown = Want::Left(UntouchedReason::TcpmUnknown);
    for (label, before, after, want) in [
        (
            "a subprogram that ends TCPM",
            "G43.4 H1\nM98 P2000\n",
            "O2000\nG49\nM99\n",
            left_off,
        ),
        (
            "a subprogram that keeps it",
            "G43.4 H1\nM98 P2000\n",
            "O2000 (SPINDLE CHECK)\nS12000 M3\nM99\n",
            Want::Patched,
        ),
        (
            "a subprogram repeated (old form: three times)",
            "G43.4 H1\nM98 P32000\n",
            "O2000\nG49\nM99\n",
            left_off,
        ),
        (
            "a subprogram outside the file",
            "G43.4 H1\nM98 P9001\n",
            "",
            unknown,
        ),
        ("a macro call", "G43.4 H1\nG65 P9001 A1.\n", "", unknown),
        ("an external call", "G43.4 H1\nM198 P100\n", "", unknown),
        (
            "a local subprogram by block number (Haas M97)",
            "G43.4 H1\nM97 P500\n",
            "N500 G49\nM99\n",
            left_off,
        ),
        (
            "a subprogram that switches TCPM on, called from without it",
            "G49\nM98 P2000\n",
            "O2000\nG43.4 H1\nM99\n",
            Want::Patched,
        ),
        (
            "a tool change after G43.4 (a macro on Fanuc controls)",
            "G43.4 H1\nM6\n",
            "",
            unknown,
        ),
    ] {
        check(label, &fanuc(before, after), &ucp(), want);
    }
}

#[test]
fn fanuc_jumps_and_loops() {
    let base = fixture("generated/fanuc-ac-swing-d0.5.nc");
    // `IF […] GOTO` over `G43.4`: the target joins TCPM off and on.
    let jump = base
        .replace("G43.4 H1\n", "IF [#1 EQ 1] GOTO 100\nG43.4 H1\n")
        .replacen("G1 X0 ", "N100 G1 X0 ", 1);
    check(
        "IF GOTO over G43.4",
        &jump,
        &ucp(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
    // An unconditional GOTO over G43.4: the switch is never reached (the G49 settles the
    // state the tool change's macro left unknown).
    let over = base
        .replace("G43.4 H1\n", "G49\nGOTO 100\nG43.4 H1\n")
        .replacen("G1 X0 ", "N100 G1 X0 ", 1);
    check(
        "GOTO over G43.4",
        &over,
        &ucp(),
        Want::Left(UntouchedReason::NoTcpm),
    );
    // A jump that stays within TCPM: settled on, patched.
    let within = base
        .replace("G43.4 H1\n", "G43.4 H1\nIF [#1 EQ 1] GOTO 100\nS12000\n")
        .replacen("G1 X0 ", "N100 G1 X0 ", 1);
    check("IF GOTO within TCPM", &within, &ucp(), Want::Patched);
    // A computed jump: control may reach any block.
    let computed = base.replace("G43.4 H1\n", "G43.4 H1\nGOTO #10\n");
    check(
        "computed GOTO",
        &computed,
        &ucp(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
    // A loop whose body ends TCPM: its start joins on and off.
    let looped = base
        .replace("G43.4 H1\n", "G43.4 H1\nWHILE [#1 LT 3] DO 1\n")
        .replace("G49\n", "G49\n#1=#1+1\nEND 1\n");
    check(
        "WHILE DO over the cut",
        &looped,
        &ucp(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
}

#[test]
fn linuxcnc_subroutines_and_conditions() {
    let base = fixture("shop/ac-swing-d1-linuxcnc-g93-m428.ngc");
    assert!(base.contains("M428 (TCP KINEMATICS)\n"));
    check("plain", &base, &linuxcnc(), Want::Patched);
    let sub = format!(
        "o200 sub\nM429\no200 endsub\n{}",
        base.replace(
            "M428 (TCP KINEMATICS)\n",
            "M428 (TCP KINEMATICS)\no200 call\n"
        )
    );
    check(
        "o200 call of a sub holding M429",
        &sub,
        &linuxcnc(),
        Want::Left(UntouchedReason::NoTcpm),
    );
    let keep = format!(
        "o200 sub\nS12000\no200 endsub\n{}",
        base.replace(
            "M428 (TCP KINEMATICS)\n",
            "M428 (TCP KINEMATICS)\no200 call\n"
        )
    );
    check(
        "o200 call of a sub that keeps TCP",
        &keep,
        &linuxcnc(),
        Want::Patched,
    );
    let outside = base.replace(
        "M428 (TCP KINEMATICS)\n",
        "M428 (TCP KINEMATICS)\no<probe> call\n",
    );
    check(
        "o<probe> call of a file outside",
        &outside,
        &linuxcnc(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
    let cond = base.replace(
        "M428 (TCP KINEMATICS)\n",
        "o100 if [#<_tcp> GT 0]\nM428 (TCP KINEMATICS)\no100 endif\n",
    );
    check(
        "M428 inside o100 if",
        &cond,
        &linuxcnc(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
}

#[test]
fn sinumerik_jumps_and_calls() {
    // (The fixture's lines end CRLF; LF here, as most Sinumerik posts write them.)
    let base = fixture("generated/sinumerik-ac-swing-d0.5.mpf").replace("\r\n", "\n");
    assert!(base.contains("TRAORI\n"));
    let cut = |s: &str| s.replacen("G1 X0 ", "SKIP: G1 X0 ", 1);
    for (label, text, want) in [
        (
            "GOTOF over TRAORI",
            cut(&base.replace("TRAORI\n", "IF R1==1 GOTOF SKIP\nTRAORI\n")),
            Want::Left(UntouchedReason::TcpmUnknown),
        ),
        (
            "unconditional GOTOF over TRAORI",
            cut(&base.replace("TRAORI\n", "GOTOF SKIP\nTRAORI\n")),
            Want::Left(UntouchedReason::NoTcpm),
        ),
        (
            "a subprogram called by name",
            base.replace("TRAORI\n", "TRAORI\nL9001\n"),
            Want::Left(UntouchedReason::TcpmUnknown),
        ),
        (
            "a subprogram called by its name",
            base.replace("TRAORI\n", "TRAORI\nTOOL_CHECK\n"),
            Want::Left(UntouchedReason::TcpmUnknown),
        ),
        (
            "TRACON after TRAORI",
            base.replace("TRAORI\n", "TRAORI\nTRACON(1)\n"),
            Want::Left(UntouchedReason::TcpmUnknown),
        ),
        (
            "instructions a post writes are not calls",
            base.replace(
                "TRAORI\n",
                "TRAORI\nORIWKS\nCYCLE832(0.01,_ORI_FINISH,1)\nFFWON\nSOFT\n",
            ),
            Want::Patched,
        ),
    ] {
        check(label, &text, &ucp(), want);
    }
}

#[test]
fn heidenhain_iso_labels() {
    let base = fixture("generated/heidenhain-ac-swing-d0.5.I");
    assert!(base.contains("N40 M128 *\n"));
    let end = "N1070 M30 *\n";
    assert!(base.contains(end));
    let with = |call: &str, sub: &str| {
        base.replace("N40 M128 *\n", &format!("N40 M128 *\n{call}"))
            .replace(end, &format!("{end}{sub}"))
    };
    check(
        "L1,0 of a label holding M129",
        &with(
            "N45 L1,0 *\n",
            "N2000 G98 L1 *\nN2010 M129 *\nN2020 G98 L0 *\n",
        ),
        &ucp(),
        Want::Left(UntouchedReason::NoTcpm),
    );
    check(
        "L1,0 of a label that keeps M128",
        &with(
            "N45 L1,0 *\n",
            "N2000 G98 L1 *\nN2010 S12000 *\nN2020 G98 L0 *\n",
        ),
        &ucp(),
        Want::Patched,
    );
    check(
        "a call of another program",
        &with("N45 %TOOLCHK *\n", ""),
        &ucp(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
}

#[test]
fn conversational_labels_and_jumps() {
    let base = fixture("shop/ac-swing-d1-conv-function-tcpm.H");
    let on = "5 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\n";
    assert!(base.contains(on));
    let end = "112 L  M30\n";
    assert!(base.contains(end));
    let with = |after_on: &str, after_end: &str| {
        base.replace(on, &format!("{on}{after_on}"))
            .replace(end, &format!("{end}{after_end}"))
    };
    check(
        "CALL LBL 1 whose label ends TCPM",
        &with(
            "5 CALL LBL 1\n",
            "112 LBL 1\n112 FUNCTION RESET TCPM\n112 LBL 0\n",
        ),
        &ucp(),
        Want::Left(UntouchedReason::NoTcpm),
    );
    check(
        "CALL LBL \"CHECK\" that keeps it",
        &with(
            "5 CALL LBL \"CHECK\" REP 2\n",
            "112 LBL \"CHECK\"\n112 L M3\n112 LBL 0\n",
        ),
        &ucp(),
        Want::Patched,
    );
    check(
        "CALL PGM",
        &with("5 CALL PGM TNC:\\PROBE.H\n", ""),
        &ucp(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
    // `FN 9: … GOTO LBL` over FUNCTION TCPM.
    let jump = base
        .replace(on, &format!("4 FN 9: IF +Q1 EQU +0 GOTO LBL 7\n{on}"))
        .replace("7  L  Z+0 R0 FMAX M8\n", "7 LBL 7\n7  L  Z+0 R0 FMAX M8\n");
    assert_ne!(jump, base);
    check(
        "FN 9 GOTO over FUNCTION TCPM",
        &jump,
        &ucp(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
}

/// A lone CR inside a `;` comment of an LF file: a control that ends lines at CR runs the
/// text after it (here `M129`) as a block.
#[test]
fn a_lone_cr_may_hide_a_block() {
    let base = fixture("generated/sinumerik-ac-swing-d0.5.mpf").replace("\r\n", "\n");
    let text = base.replace("TRAORI\n", "TRAORI ; 5 axes\rTRAFOOF\n");
    assert_ne!(text, base);
    check(
        "CR in a comment",
        &text,
        &ucp(),
        Want::Left(UntouchedReason::TcpmUnknown),
    );
}

/// Issue 26 §2 with TCPM: a rotation, scaling or mirror image in force leaves the run (the
/// program's X Y Z and the tool axis are not in the frame polepatch computes in); its end
/// gives the patch back.
#[test]
fn a_transformed_frame_leaves_a_tcpm_run() {
    let frame = Want::Left(UntouchedReason::FrameTransformed);
    for (code, want) in [
        ("G68 X0 Y0 R30\n", frame),
        ("G51 X0 Y0 P0.999\n", frame),
        ("G51.1 X0\n", frame),
        ("G68.2 X0 Y0 Z0 I0 J15 K0\n", frame),
        ("G68 X0 Y0 R30\nG69\n", Want::Patched),
        ("G51.1 X0\nG50.1 X0\n", Want::Patched),
    ] {
        check(code, &fanuc(&format!("{code}G43.4 H1\n"), ""), &ucp(), want);
    }
    let sin = fixture("generated/sinumerik-ac-swing-d0.5.mpf").replace("\r\n", "\n");
    for (code, want) in [
        ("ROT Z30\n", frame),
        ("AROT RPL=30\n", frame),
        ("SCALE X2 Y2\n", frame),
        ("MIRROR X0\n", frame),
        ("CYCLE800(1,\"TC1\",0,57,0,0,0,30,0,0,0,0,0,-1)\n", frame),
        ("ROT Z30\nTRANS\n", Want::Patched),
        ("CYCLE800()\n", Want::Patched),
    ] {
        check(
            code,
            &sin.replace("TRAORI\n", &format!("{code}TRAORI\n")),
            &ucp(),
            want,
        );
    }
    let conv = fixture("shop/ac-swing-d1-conv-function-tcpm.H");
    let on = "5 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\n";
    for (code, want) in [
        ("4 CYCL DEF 10.0 ROTATION\n4 CYCL DEF 10.1 ROT+30\n", frame),
        (
            "4 CYCL DEF 11.0 SCALING\n4 CYCL DEF 11.1 SCL 0.999\n",
            frame,
        ),
        ("4 CYCL DEF 8.0 MIRROR IMAGE\n4 CYCL DEF 8.1 X\n", frame),
        (
            "4 CYCL DEF 26.0 AXIS-SPECIFIC SCALING\n4 CYCL DEF 26.1 X1.5 CCX+0\n",
            frame,
        ),
        ("4 PLANE SPATIAL SPA+0 SPB+15 SPC+0 STAY\n", frame),
        (
            "4 PLANE SPATIAL SPA+0 SPB+15 SPC+0 STAY\n4 PLANE RESET STAY\n",
            Want::Patched,
        ),
    ] {
        check(
            code,
            &conv.replace(on, &format!("{code}{on}")),
            &ucp(),
            want,
        );
    }
}
