//! Issue 30 item 11: Fanuc/Haas macro variables with constant values (`#100=1200.` then
//! `G1 F#100`, `G0 X#101`) are read as their values where nothing between assignment and
//! use can change them; a word like `C#105` is read but never rewritten (its zone is
//! refused as `macro_variable`); every other byte stays.

use polepatch::kinematics::Machine;
use polepatch::nc::modal::X;
use polepatch::nc::{Dialect, Flags, parse};
use polepatch::{PatchOptions, UntouchedReason, patch_nc};
use std::path::PathBuf;

fn cam(name: &str) -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/cam")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn line_of(bytes: &[u8], text: &str) -> usize {
    String::from_utf8_lossy(bytes)
        .lines()
        .position(|l| l.contains(text))
        .unwrap_or_else(|| panic!("no line with {text}"))
}

#[test]
fn a_macro_constant_feed_is_analysed_at_its_feed() {
    let bytes = cam("haas-macro-feed-g434.nc");
    let p = parse(bytes.clone(), Dialect::Auto).unwrap();
    assert_eq!(p.dialect, Dialect::Fanuc);
    // `G54 G00 X#101 …` with `#101=-10.`; `G01 Z0. F#102` (300); `… F#100` (1200).
    let g0 = line_of(&bytes, "X#101");
    assert_eq!(p.state(g0).pos[X], Some(-10.0));
    assert_eq!(p.state(line_of(&bytes, "F#102")).feed_mm_min, Some(300.0));
    let cut = line_of(&bytes, "F#100");
    assert_eq!(p.state(cut).feed_mm_min, Some(1200.0));
    assert!(
        p.blocks.iter().all(|b| !b.flags.has(Flags::NOT_ANALYSABLE)),
        "every variable here is a constant"
    );
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let o = PatchOptions::named("macro");
    let (out, report) = patch_nc(&bytes, &m, &o).unwrap();
    assert!(report.not_analysed.is_empty(), "{:?}", report.not_analysed);
    assert_eq!(report.zones.len(), 2, "{:?}", report.zones);
    // The first pass (its plunge at F#102 = 300, its cut at F#100 = 1200 mm/min: one pass,
    // issue 41) is analysed at its blocks' feeds and patched to them.
    let first = &report.zones[0];
    let t2 = line_of(&bytes, "T2 M06") + 1;
    assert!(
        cut <= first.lines[0] && first.lines[1] < t2,
        "{:?}",
        first.lines
    );
    assert_eq!(first.outcome, polepatch::Outcome::Reached, "{first:?}");
    assert!(first.before.c_ratio < 0.1);
    // The second pass holds `C#105` where the patch would change C: refused by name.
    let second = &report.zones[1];
    assert_eq!(second.outcome, polepatch::Outcome::Unchanged);
    assert_eq!(second.reason, polepatch::ZoneReason::MacroVariable);
    let refused = report
        .untouched_runs
        .iter()
        .find(|u| u.reason == UntouchedReason::MacroVariable)
        .expect("the C#105 run is listed");
    assert!(refused.message.contains("`C#105`"), "{}", refused.message);
    // Every line with a variable is written as it was; the second pass is untouched.
    let (a, b) = (
        String::from_utf8_lossy(&bytes),
        String::from_utf8_lossy(&out),
    );
    let (a, b): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    assert_eq!(a.len(), b.len());
    let second_op = line_of(&bytes, "T2 M06");
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        for w in x.split(' ').filter(|w| w.contains('#')) {
            assert!(
                y.split(' ').any(|v| v == w),
                "line {}: {w} went: {y}",
                k + 1
            );
        }
        if k >= second_op {
            assert_eq!(x, y, "line {}", k + 1);
        }
    }
    assert_ne!(out, bytes);
}
