//! A run whose X Y Z are machine coordinates (no TCPM) is never patched by changing rotary
//! words alone (SPEC §6, issue 10): on a table-table machine that would move the part under
//! the tool. Regression tests named after what broke: `SING.I` without its `M128` line was
//! patched exactly like the original.

mod common;
use polepatch::kinematics::Machine;
use polepatch::{PatchOptions, UntouchedReason, patch_nc};

fn sing() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/c17/SING.I"
    ))
    .unwrap()
}

fn without_line(bytes: &[u8], needle: &str) -> Vec<u8> {
    let text = String::from_utf8_lossy(bytes);
    let kept: Vec<&str> = text
        .split_inclusive('\n')
        .filter(|l| !l.contains(needle))
        .collect();
    assert_eq!(
        kept.len() + 1,
        text.split_inclusive('\n').count(),
        "{needle} once"
    );
    kept.concat().into_bytes()
}

#[test]
fn sing_without_m128_is_left_byte_identical_and_reported() {
    let input = without_line(&sing(), "M128");
    for m in common::machines_for("SING", &input) {
        let name = &m.name;
        let (out, report) = patch_nc(&input, &m, &PatchOptions::default()).unwrap();
        assert_eq!(out, input, "{name}: no byte may change");
        assert_eq!(report.words_changed, 0);
        assert_eq!(report.runs_left_without_tcpm(), 1, "{report:#?}");
        let u = &report.untouched_runs[0];
        assert_eq!(u.reason, UntouchedReason::NoTcpm);
        assert!(u.message.contains("no TCPM"), "{}", u.message);
        assert!(u.zones >= 1);
        // The zone is still reported, as below feed and unchanged.
        assert!(!report.zones.is_empty());
        for z in &report.zones {
            assert_eq!(z.outcome, polepatch::Outcome::Unchanged);
            assert_eq!(z.points_modified, 0);
            assert!(z.before.c_ratio < 1.0);
        }
        assert_eq!(report.zones_below_feed(), report.zones.len());
    }
}

/// The same program with TCPM on is patched (the guard is about TCPM, not the file).
#[test]
fn sing_with_m128_is_patched() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let (out, report) = patch_nc(&sing(), &m, &PatchOptions::default()).unwrap();
    assert_ne!(out, sing());
    assert!(
        report.untouched_runs.is_empty(),
        "{:?}",
        report.untouched_runs
    );
    assert!(
        report
            .zones
            .iter()
            .all(|z| z.outcome == polepatch::Outcome::Reached)
    );
}

/// TCPM switched off inside the program (M129 before the cut) leaves that run alone; the
/// Fanuc and Sinumerik spellings are read the same way.
#[test]
fn tcpm_off_in_every_dialect() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let heid = String::from_utf8(sing())
        .unwrap()
        .replace("N65 M128 *", "N65 M129 *");
    let fanuc = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/generated/fanuc-ac-swing-d0.5.nc"
    ))
    .unwrap()
    .replace("G43.4 H1", "G49");
    let sin = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/generated/sinumerik-ac-swing-d0.5.mpf"
    ))
    .unwrap()
    .replace("TRAORI", "TRAFOOF");
    for (label, text) in [("heidenhain", heid), ("fanuc", fanuc), ("sinumerik", sin)] {
        let (out, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default()).unwrap();
        assert_eq!(out, text.as_bytes(), "{label}");
        assert!(report.runs_left_without_tcpm() >= 1, "{label}: {report:#?}");
    }
}

/// `%SING`'s cut (N110–N610) written in incremental mode (G91) after an absolute start:
/// left alone with a reason (a changed value would shift every later position).
#[test]
fn incremental_runs_are_left_alone() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let sing = String::from_utf8(sing()).unwrap();
    let word = |line: &str, l: char| -> f64 {
        line.split(' ')
            .find_map(|w| w.strip_prefix(l))
            .map_or(0.0, |v| v.parse().unwrap())
    };
    let cut: Vec<[f64; 5]> = sing
        .lines()
        .filter(|l| l.contains(" Z-8 ") && l.contains(" Y+0 "))
        .map(|l| ['X', 'Y', 'Z', 'A', 'C'].map(|c| word(l, c)))
        .collect();
    assert_eq!(cut.len(), 51);
    let mut text = String::from("%INC G71 *\nN1 M128 *\n");
    let p0 = cut[0];
    text += &format!(
        "N2 G90 G01 X{:+} Y{:+} Z{:+} A{:+} C{:+} F2000 *\nN3 G91 *\n",
        p0[0], p0[1], p0[2], p0[3], p0[4]
    );
    for (k, w) in cut.windows(2).enumerate() {
        let d: Vec<f64> = (0..5).map(|i| w[1][i] - w[0][i]).collect();
        text += &format!("N{} X{:+.3} A{:+.3} C{:+.3} *\n", k + 4, d[0], d[3], d[4]);
    }
    text += "N999 M30 *\n";
    let (out, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default()).unwrap();
    assert_eq!(out, text.as_bytes());
    assert!(!report.untouched_runs.is_empty(), "{report:#?}");
    assert!(
        report
            .untouched_runs
            .iter()
            .all(|u| u.reason == UntouchedReason::Incremental && u.zones >= 1),
        "{:?}",
        report.untouched_runs
    );
    assert!(report.untouched_runs[0].message.contains("G91"));
}

fn generated(name: &str) -> String {
    std::fs::read_to_string(format!(
        "{}/../../fixtures/generated/{name}",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap()
}

/// Issue 19 §1: codes that end or replace TCPM in each controller's modal groups — Fanuc
/// `G43`/`G44` (group 8) after `G43.4`, Sinumerik `TRANSMIT`/`TRACYL` after `TRAORI` —
/// leave the run after them in machine coordinates: untouched, byte for byte, reported.
#[test]
fn codes_that_replace_tcpm_leave_the_run_alone() {
    let fanuc = generated("fanuc-ac-flip-d0.5.nc");
    let sin = generated("sinumerik-ac-flip-d0.5.mpf");
    let cases = [
        (
            "G43 after G43.4",
            fanuc.replace("G43.4 H1\n", "G43.4 H1\nG43 H1\n"),
        ),
        (
            "G44 after G43.4",
            fanuc.replace("G43.4 H1\n", "G43.4 H1\nG44 H1\n"),
        ),
        (
            "TRANSMIT after TRAORI",
            sin.replace("TRAORI\r\n", "TRAORI\r\nTRANSMIT\r\n"),
        ),
        (
            "TRACYL after TRAORI",
            sin.replace("TRAORI\r\n", "TRAORI\r\nTRACYL(40)\r\n"),
        ),
    ];
    // A-C programs: their machines (issue 29 refuses them on a B-C one).
    for m in common::machines_for("fanuc-ac-flip-d0.5.nc", fanuc.as_bytes()) {
        let name = &m.name;
        for (label, text) in &cases {
            assert!(
                text != &fanuc && text != &sin,
                "{label}: the case was built"
            );
            let (out, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default()).unwrap();
            assert!(
                out == text.as_bytes(),
                "{label} on {name}: no byte may change"
            );
            assert!(report.runs_left_without_tcpm() >= 1, "{label}: {report:#?}");
            assert!(
                report.zones_below_feed() >= 1,
                "{label}: --strict must exit 2"
            );
        }
    }
}

/// Issue 19 §1: a TCPM switch in a block that block delete may skip leaves the state
/// uncertain: the run is left as it is and reported with its own reason.
#[test]
fn a_skippable_tcpm_block_is_uncertain_and_left_alone() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let heid = String::from_utf8(sing())
        .unwrap()
        .replace("N65 M128 *", "/N65 M128 *");
    // (After `M6`, which a Fanuc-style control may run as a macro, TCPM is unknown: `G49`
    // settles it first, so what is left uncertain is the skippable switch's doing.)
    let fanuc = generated("fanuc-ac-flip-d0.5.nc").replace("G43.4 H1\n", "G49\n/N50 G43.4 H1\n");
    let sin = generated("sinumerik-ac-flip-d0.5.mpf").replace("TRAORI\r\n", "/N6 TRAORI\r\n");
    for (label, text) in [("heidenhain", heid), ("fanuc", fanuc), ("sinumerik", sin)] {
        assert!(text.contains("/N"), "{label}: the case was built");
        let (out, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default()).unwrap();
        assert!(out == text.as_bytes(), "{label}: no byte may change");
        assert!(
            report
                .untouched_runs
                .iter()
                .any(|u| u.reason == UntouchedReason::TcpmUncertain && u.zones >= 1),
            "{label}: {:#?}",
            report.untouched_runs
        );
        assert!(report.zones_below_feed() >= 1, "{label}");
    }
}

/// Issue 19 §5: an arc or a block that block delete may skip, inside a zone, is not
/// analysed: the report lists it (so `--strict` exits 2), whatever the runs either side
/// report.
#[test]
fn arcs_and_skippable_blocks_inside_a_zone_are_listed() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let flip = generated("heidenhain-ac-flip-d0.5.I");
    let cases = [
        (
            "arc",
            flip.replace(
                "N540 X+24.5 Y+0 Z-5 A+0.591 C+58.315 *",
                "N540 G02 X+24.5 Y+0 I+24.25 J+0.25 A+0.591 C+58.315 *\nN545 G01 *",
            ),
            polepatch::report::SkipReason::ArcNearPole,
        ),
        (
            "skippable",
            flip.replace(
                "N540 X+24.5 Y+0 Z-5 A+0.591 C+58.315 *",
                "/N540 X+24.5 Y+0 Z-5 A+0.591 C+58.315 *",
            ),
            polepatch::report::SkipReason::SkippableNearPole,
        ),
    ];
    for (label, text, reason) in cases {
        assert!(text != flip, "{label}: the case was built");
        let (_, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default()).unwrap();
        let listed: Vec<_> = report
            .not_analysed
            .iter()
            .filter(|n| n.reason == reason)
            .collect();
        assert_eq!(listed.len(), 1, "{label}: {:?}", report.not_analysed);
        assert!(listed[0].lines[0] >= 50, "{label}: {:?}", listed[0]);
        assert!(report.strict_failures() >= 1, "{label}");
        // Far from the pole the same blocks are not listed.
        let far = generated("heidenhain-ac-flip-d20.I");
        let far_text = far.replacen(" X+2 Y+0 Z-5", " G02 X+2 Y+0 I+1 J+0 Z-5", 1);
        assert!(far_text != far);
        let (_, report) = patch_nc(far_text.as_bytes(), &m, &PatchOptions::default()).unwrap();
        assert!(report.not_analysed.is_empty(), "{:?}", report.not_analysed);
    }
}

/// Issue 42 item 5: `TRAOOF` (a post's typo of `TRAFOOF`) passed in silence: an unknown
/// word. A word within an edit or two of a TCPM code is warned about, with its line and
/// column; no fixture of the repository holds one.
#[test]
fn a_word_that_looks_like_a_tcpm_code_is_warned_about() {
    let sin = generated("sinumerik-ac-flip-d0.5.mpf");
    let typo = sin.replacen("\nTRAFOOF", "\nN9 TRAOOF", 1);
    assert_ne!(typo, sin);
    let line = typo[..typo.find("TRAOOF").unwrap()].matches('\n').count() + 1;
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let warned = |text: &str| -> Vec<String> {
        let (_, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default()).unwrap();
        report
            .warnings
            .into_iter()
            .filter(|w| w.contains("look like a TCPM code"))
            .collect()
    };
    let w = warned(&typo);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].contains(&format!(
            "line {line}, col 4: TRAOOF looks like the TCPM code TRAFOOF"
        )),
        "{w:?}"
    );
    assert!(warned(&sin).is_empty());
    // No false alarm on the repository's programs.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let mut stack = vec![root];
    let mut read = 0;
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
            if ["apt", "cls", "csv", "toml", "json", "md", "ini"].contains(&ext) {
                continue;
            }
            let bytes = std::fs::read(&p).unwrap();
            let mut found = Vec::new();
            let r = polepatch::nc::scan_blocks(&bytes, polepatch::nc::Dialect::Auto, |s| {
                if let Some(l) = s.lookalike {
                    found.push((s.block.line, l.clone()));
                }
                std::ops::ControlFlow::Continue(())
            });
            if r.is_ok() {
                read += 1;
            }
            assert!(found.is_empty(), "{}: {found:?}", p.display());
        }
    }
    assert!(read > 100, "{read} programs read");
}
