//! Issue 42's closing check found a misreading: NX's Haas VF2 TR post writes the platter B
//! modulo 360 — `B359.857` then `B7.501` in one cutting move at |A| = 2.7°
//! (`../shared/realworld/new/nx_haas_vf2tr_ab.ptp`, line 555). A controller that takes the
//! shorter way on an endless axis (Haas and Fanuc rollover, a Sinumerik modulo axis,
//! Heidenhain `M126`) turns +7.644°; read as written it is −352.356°, a singular zone that
//! is not there. Read as written under TCPM, the patch rewrote the pass as a back-and-forth
//! of the platter that the rollover controller then runs. Which way the machine goes is not
//! in the program: the move is listed (`rotary_wrap`, line and column), no run spans it and
//! nothing is changed; a machine whose axis never takes the shorter way says so with a
//! range. `fixtures/cam/haas-vf2tr-platter-wrap.nc` is written in the post's style, with
//! `G234` (TCPC) so that a patch would be allowed.

use polepatch::kinematics::Machine;
use polepatch::report::SkipReason;
use polepatch::{AnalyzeOptions, PatchOptions, analyze_nc, patch_nc};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fixture() -> Vec<u8> {
    std::fs::read(root().join("fixtures/cam/haas-vf2tr-platter-wrap.nc")).unwrap()
}

fn trunnion_text() -> String {
    std::fs::read_to_string(root().join("crates/kinematics/machines/example-trunnion-ab.toml"))
        .unwrap()
}

/// The example A-B trunnion: its platter B has no range (it turns without end).
fn trunnion() -> Machine {
    Machine::from_toml_str(&trunnion_text(), "example-trunnion-ab.toml").unwrap()
}

/// The same machine, its platter given a range: a controller that never takes the shorter
/// way (LinuxCNC's limits, a Heidenhain axis without modulo display).
fn trunnion_with_platter_range() -> Machine {
    let text = trunnion_text().replacen(
        "letter = \"B\"\n",
        "letter = \"B\"\nrange_deg = [-36000.0, 36000.0]\n",
        1,
    );
    assert_ne!(text, trunnion_text());
    Machine::from_toml_str(&text, "trunnion-b-range.toml").unwrap()
}

fn opts() -> PatchOptions {
    PatchOptions::named("wrap")
}

/// The feed moves whose B word differs from the B before it by more than 180°, with the
/// column of the word, by a plain scan of the text (not polepatch's reader).
fn wraps_in_text(bytes: &[u8]) -> Vec<(usize, usize, f64, f64)> {
    let text = String::from_utf8_lossy(bytes);
    let (mut b_prev, mut feed, mut out) = (None::<f64>, false, Vec::new());
    for (i, line) in text.lines().enumerate() {
        let code = line.split('(').next().unwrap();
        if code.contains("G00") || code.contains("G0 ") {
            feed = false;
        }
        if code.contains("G01") {
            feed = true;
        }
        if let Some(j) = code.find('B') {
            let num: String = code[j + 1..]
                .chars()
                .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == '-')
                .collect();
            let v: f64 = num.parse().unwrap();
            if let Some(p) = b_prev
                && feed
                && code.contains('X')
                && (v - p).abs() > 180.0
            {
                out.push((i + 1, j + 1, p, v));
            }
            b_prev = Some(v);
        }
    }
    out
}

#[test]
fn a_platter_written_modulo_360_is_listed_not_misread() {
    let bytes = fixture();
    let wraps = wraps_in_text(&bytes);
    assert_eq!(wraps.len(), 1, "{wraps:?}");
    let (line, column, from, to) = wraps[0];
    let (out, report) = patch_nc(&bytes, &trunnion(), &opts()).unwrap();
    // Nothing is changed, and no zone is reported where the platter only turns 7.8°.
    assert!(out == bytes, "the program was changed");
    assert!(report.zones.is_empty(), "{:?}", report.zones);
    let items: Vec<_> = report
        .not_analysed
        .iter()
        .filter(|n| n.reason == SkipReason::RotaryWrap)
        .collect();
    assert_eq!(items.len(), 1, "{:?}", report.not_analysed);
    assert_eq!(items[0].lines, [line, line]);
    let msg = &items[0].message;
    let shorter = to - from + 360.0;
    for part in [
        format!("line {line}, col {column}: a feed move turns B from {from}° to {to}°"),
        format!("{:.1}° as written", to - from),
        format!("+{shorter:.1}° instead"),
        "the move is kept as written and no run is analysed across it".to_string(),
        "range_deg for B".to_string(),
    ] {
        assert!(msg.contains(&part), "{part:?} not in {msg}");
    }
    // The analysis ends a run before the wrap and starts the next at its end point.
    let a = analyze_nc(&bytes, &trunnion(), &AnalyzeOptions::default()).unwrap();
    assert!(
        a.runs.iter().any(|r| r.lines[1] == line - 1),
        "{:?}",
        a.runs
    );
    assert!(a.runs.iter().any(|r| r.lines[0] == line), "{:?}", a.runs);
    assert!(
        a.runs
            .iter()
            .all(|r| r.figures.as_ref().is_none_or(|f| f.zones.is_empty()))
    );
}

/// The way out the message names: a platter with a range never takes the shorter way, so
/// the move is read as written — the −352° turn is a zone and patched, only rotary words
/// change.
#[test]
fn a_platter_with_a_range_is_read_as_written() {
    let bytes = fixture();
    let (out, report) = patch_nc(&bytes, &trunnion_with_platter_range(), &opts()).unwrap();
    assert!(
        !report
            .not_analysed
            .iter()
            .any(|n| n.reason == SkipReason::RotaryWrap),
        "{:?}",
        report.not_analysed
    );
    let (line, ..) = wraps_in_text(&bytes)[0];
    assert!(
        report
            .zones
            .iter()
            .any(|z| z.lines[0] <= line && line <= z.lines[1]),
        "{:?}",
        report.zones
    );
    assert!(out != bytes);
}
