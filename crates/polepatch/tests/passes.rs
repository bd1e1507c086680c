//! The pass as the unit (issue 41 item 1): a change of F inside a pass (G94 or G93), a
//! block that does not move the tool (`G92 E0`), and an auxiliary axis the machine file
//! names (an extruder on `A` of a B-C printer) do not cut a near-pole pass into pieces.
//! Each case: the zone found, patched to feed, the written program verified by the one
//! check and simulated (whole program) no slower than its input.

use polepatch::kinematics::Machine;
use polepatch::simulate::{SimulateOptions, simulate_nc};
use polepatch::verify::verify_nc;
use polepatch::{Outcome, PatchOptions, patch_nc};
use std::path::PathBuf;

fn shop(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/shop")
        .join(name);
    std::fs::read_to_string(p).unwrap()
}

fn opts(name: &str) -> PatchOptions {
    PatchOptions::named(name)
}

/// The simulated time of the whole program, s.
fn simulated_s(bytes: &[u8], m: &Machine) -> f64 {
    simulate_nc(bytes, m, &SimulateOptions::default())
        .unwrap()
        .total
        .time_s
}

/// Patch `text` on `m`: one zone, reached on both rotary axes, the written program verified
/// and simulated no slower than the input (0.1 % for the simulator's cycle rounding).
/// Returns the written program.
fn one_zone_reached(what: &str, text: &str, m: &Machine) -> String {
    let o = opts(what);
    let (out, report) = patch_nc(text.as_bytes(), m, &o).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(report.zones.len(), 1, "{what}: {:?}", report.zones);
    let z = &report.zones[0];
    assert_eq!(z.outcome, Outcome::Reached, "{what}: {z:?}");
    assert!(z.after.c_ratio >= 1.0 - 1e-9 && z.after.primary_ratio >= 1.0 - 1e-9);
    let check = verify_nc(text.as_bytes(), &out, m, &o, what).unwrap();
    assert!(check.passed(), "{what}: {:?}", check.violations);
    let (before, after) = (simulated_s(text.as_bytes(), m), simulated_s(&out, m));
    assert!(
        after <= before * 1.001,
        "{what}: simulated {before:.3} s → {after:.3} s"
    );
    // Faster where the rotary axes limited it (a feed that alternates every block keeps
    // X at its jerk limit, in the input as in the output: that part is the program's).
    assert!(z.after.time_s < 0.6 * z.before.time_s, "{what}: {z:?}");
    String::from_utf8(out).unwrap()
}

/// The cut blocks of a G94 shop program (after its first cut block, which states F2000),
/// each given its own F by `feed(k)`.
fn with_feeds(text: &str, feed: impl Fn(usize) -> Option<f64>) -> String {
    let mut k = 0;
    let mut cutting = false;
    let mut out = String::new();
    for l in text.lines() {
        let mut line = l.to_string();
        if cutting && l.starts_with('X') {
            if let Some(f) = feed(k) {
                line.push_str(&format!(" F{f}"));
            }
            k += 1;
        }
        cutting |= l.starts_with("G1 X0 Y0 Z-5");
        out.push_str(&line);
        out.push('\n');
    }
    out
}

/// A pass 0.5° from the pole whose F changes every block (feed-optimised output): one pass,
/// one zone, each block analysed at its own feed (before: 40 two-point runs and no zone).
#[test]
fn a_pass_whose_feed_changes_every_block_is_one_zone() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let text = with_feeds(&shop("ac-flip-d0.5-fanuc-g94.nc"), |k| {
        Some(if k % 2 == 0 { 1800.0 } else { 2200.0 })
    });
    let out = one_zone_reached("every block", &text, &m);
    // Every F word as written.
    let feeds = |t: &str| {
        t.split_whitespace()
            .filter(|w| w.starts_with('F'))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    assert_eq!(feeds(&out), feeds(&text));
}

/// The same pass with one block's F changed: one zone (before: split in two, both reported
/// reached, and the written program 18 % slower than its input).
#[test]
fn a_pass_with_one_block_at_another_feed_is_one_zone() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let text = with_feeds(&shop("ac-flip-d0.5-fanuc-g94.nc"), |k| match k {
        40 => Some(2001.0),
        41 => Some(2000.0),
        _ => None,
    });
    one_zone_reached("one block", &text, &m);
}

/// Under G93 each block has its own inverse-time F already: a pass whose blocks' feeds
/// (length × F) change every block is one run, and so is one with one block changed.
#[test]
fn an_inverse_time_pass_whose_feed_changes_is_one_zone() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let text = shop("ac-flip-d0.5-fanuc-g93.nc");
    for (what, factor) in [
        (
            "G93 every block",
            (|k: usize| if k % 2 == 0 { 0.9 } else { 1.1 }) as fn(usize) -> f64,
        ),
        (
            "G93 one block",
            |k: usize| if k == 40 { 1.0005 } else { 1.0 },
        ),
    ] {
        let mut k = 0;
        let changed: String = text
            .lines()
            .map(|l| {
                let l = match l.rsplit_once(" F") {
                    Some((head, f)) if l.starts_with('X') => {
                        let f: f64 = f.parse().unwrap();
                        k += 1;
                        format!("{head} F{:.3}", f * factor(k - 1))
                    }
                    _ => l.to_string(),
                };
                l + "\n"
            })
            .collect();
        assert!(k > 80, "{what}: {k} blocks");
        one_zone_reached(what, &changed, &m);
    }
}

/// `G92 E0` (an extruder reset) between near-pole blocks is not a datum shift of an axis
/// polepatch analyses: the pass goes on through it, its zone is found and patched. A `G92`
/// of an analysed axis is a datum shift: it ends what is known (the runs around it are
/// analysed apart, nothing across it changes).
#[test]
fn g92_of_an_extruder_does_not_end_the_pass() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let text = shop("ac-flip-d0.5-fanuc-g94.nc");
    let mid = text.lines().position(|l| l.starts_with("X25 ")).unwrap();
    let with = |insert: &str| {
        let mut lines: Vec<&str> = text.lines().collect();
        lines.insert(mid, insert);
        lines.join("\n") + "\n"
    };
    let out = one_zone_reached("G92 E0", &with("G92 E0"), &m);
    assert!(out.contains("\nG92 E0\n"));
    // A datum shift of X: not carried through.
    let shifted = with("G92 X25");
    let (_, report) = patch_nc(shifted.as_bytes(), &m, &opts("G92 X25")).unwrap();
    assert!(
        report
            .zones
            .iter()
            .all(|z| z.lines[1] < mid + 1 || z.lines[0] > mid + 1),
        "no zone spans the datum shift: {:?}",
        report.zones
    );
}

/// A B-C printer whose extruder is `A` (the multi-axis printing programs of issue 41): the
/// machine file names `A` as auxiliary, so its words are carried, never read as a rotary
/// axis of another machine; the near-pole pass is found and patched, the extruder words
/// and `G92 A0` written as they were.
#[test]
fn an_auxiliary_axis_is_carried_through() {
    let mut m = Machine::builtin("mikron-hsm600").unwrap();
    // The A-C pass on the B-C machine: its A words become B (the tilt), and an extruder A
    // grows along the pass, reset halfway.
    let text = shop("ac-flip-d0.5-fanuc-g94.nc");
    let mut e = 0.0;
    let mut printed = String::new();
    for l in text.lines() {
        let mut line = l.replace(" A", " B");
        if line.starts_with('X') || line.starts_with("G1 X") {
            e += 0.0123;
            line.push_str(&format!(" A{e:.4}"));
        }
        if line.starts_with("X25 ") {
            printed.push_str("G92 A0\n");
            e = 0.0;
        }
        printed.push_str(&line);
        printed.push('\n');
    }
    // Without the declaration: refused at the first A word, by name.
    let err = patch_nc(printed.as_bytes(), &m, &opts("printer")).unwrap_err();
    assert!(err.to_string().contains("A is not an axis"), "{err}");
    m.controller.auxiliary_axes = vec!["A".into()];
    let out = one_zone_reached("printer", &printed, &m);
    let extruder = |t: &str| {
        t.split_whitespace()
            .filter(|w| w.starts_with('A'))
            .map(str::to_string)
            .collect::<Vec<_>>()
    };
    assert_eq!(extruder(&out), extruder(&printed));
    assert!(out.contains("\nG92 A0\n"));
    // An auxiliary letter that is one of the machine's own axes is refused.
    m.controller.auxiliary_axes = vec!["B".into()];
    let err = patch_nc(printed.as_bytes(), &m, &opts("printer")).unwrap_err();
    assert!(err.to_string().contains("auxiliary_axes"), "{err}");
}
