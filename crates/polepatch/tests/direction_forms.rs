//! Issue 30 item 10: Sinumerik `C=DC(…)`, `C=ACP(…)`, `C=ACN(…)` (a modulo C axis, as on a
//! TRAORI machine with an endless table). The reader follows the unwrapped C the controller
//! reaches; a patched word keeps its form, written modulo 360, only where that form makes
//! the patched move; elsewhere the zone is refused by name (`direction_form`).
//!
//! "The patched motion" is what the same program, written with plain unwrapped `C=` values,
//! is patched to: the direction-form output, read as the controller moves, must reach the
//! same C at every block.

use polepatch::kinematics::Machine;
use polepatch::nc::modal::{A, C};
use polepatch::nc::{Dialect, RotaryForm, parse};
use polepatch::patcher::PatchAxes;
use polepatch::{PatchOptions, UntouchedReason, patch_nc};
use std::path::PathBuf;

fn cam(name: &str) -> Vec<u8> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/cam")
        .join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn ucp710() -> Machine {
    Machine::builtin("mikron-ucp710").unwrap()
}

fn opts(only_c: bool) -> PatchOptions {
    let mut o = PatchOptions::named("direction-forms");
    if only_c {
        o.patch.axes = PatchAxes::OnlyC;
    }
    o
}

/// The program with every direction-form C word written as the plain unwrapped position
/// the controller reaches (`C=-80.426`).
fn plain_equivalent(bytes: &[u8]) -> Vec<u8> {
    let p = parse(bytes.to_vec(), Dialect::Auto).unwrap();
    let mut out = Vec::new();
    let mut at = 0;
    for (b, _) in p.blocks.iter().enumerate() {
        for w in p.block_words(b) {
            if w.letter == b'C' && w.form.is_directional() {
                out.extend_from_slice(&bytes[at..w.start as usize]);
                out.extend_from_slice(format!("C={:.3}", p.state(b).pos[C].unwrap()).as_bytes());
                at = w.span().end;
            }
        }
    }
    out.extend_from_slice(&bytes[at..]);
    out
}

/// C and A after every block, as the controller moves.
fn motion(bytes: &[u8]) -> Vec<(Option<f64>, Option<f64>)> {
    let p = parse(bytes.to_vec(), Dialect::Auto).unwrap();
    assert_eq!(p.dialect, Dialect::Sinumerik);
    (0..p.blocks.len())
        .map(|b| (p.state(b).pos[A], p.state(b).pos[C]))
        .collect()
}

/// The forms of the C words, in order.
fn c_forms(bytes: &[u8]) -> Vec<RotaryForm> {
    let p = parse(bytes.to_vec(), Dialect::Auto).unwrap();
    p.words
        .iter()
        .filter(|w| w.letter == b'C')
        .map(|w| w.form)
        .collect()
}

/// Patch `bytes` and its plain equivalent: the patch reaches feed, every C word written
/// keeps its form (and every block that had one still has it), and the controller's
/// unwrapped C (and A) after every block is the plain patch's.
fn patched_in_form(name: &str, only_c: bool) -> Vec<u8> {
    let bytes = cam(name);
    let (out, report) = patch_nc(&bytes, &ucp710(), &opts(only_c)).unwrap();
    assert!(!report.zones.is_empty(), "{name}: no zone");
    assert!(
        report
            .zones
            .iter()
            .all(|z| z.outcome == polepatch::Outcome::Reached),
        "{name}: {:?} {:?}",
        report.zones,
        report.untouched_runs
    );
    assert_ne!(out, bytes, "{name}: nothing written");
    let before = c_forms(&bytes);
    let after = c_forms(&out);
    assert!(after.len() >= before.len(), "{name}: a C word went");
    assert!(
        after.iter().all(|f| f.is_directional()),
        "{name}: a plain C word was written: {after:?}"
    );
    let plain = plain_equivalent(&bytes);
    let (plain_out, plain_report) = patch_nc(&plain, &ucp710(), &opts(only_c)).unwrap();
    assert_eq!(plain_report.zones.len(), report.zones.len());
    let (got, want) = (motion(&out), motion(&plain_out));
    assert_eq!(got.len(), want.len());
    let mut changed = 0;
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        for (x, y) in [(g.0, w.0), (g.1, w.1)] {
            match (x, y) {
                (Some(x), Some(y)) => assert!(
                    (x - y).abs() < 2e-3,
                    "{name}: block {k}: the controller reaches {x}, the patch {y}"
                ),
                (x, y) => assert_eq!(x.is_some(), y.is_some(), "{name}: block {k}"),
            }
        }
        changed += usize::from(g.1 != motion(&bytes)[k].1);
    }
    assert!(changed > 10, "{name}: only {changed} C positions changed");
    // Nothing but rotary words changed: the lines without A or C words are the input's.
    let keep = |b: &[u8]| -> Vec<String> {
        String::from_utf8_lossy(b)
            .lines()
            .map(|l| {
                l.split(' ')
                    .filter(|w| !w.starts_with('A') && !w.starts_with("C="))
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .collect()
    };
    assert_eq!(keep(&out), keep(&bytes), "{name}: other words changed");
    out
}

/// A DC program near the pole (C from 279.6° through 0° on the way the shorter way takes):
/// read as the controller moves, patched to feed on the Mikron UCP 710 (endless C), every C
/// word written back as `C=DC(…)` in [0, 360).
#[test]
fn dc_program_is_patched_in_dc_form() {
    let bytes = cam("sinumerik-traori-dc.mpf");
    let m = motion(&bytes);
    // `G00 C=DC(0.0)`, then DC(279.574): the shorter way is −80.426°.
    let p = parse(bytes.clone(), Dialect::Auto).unwrap();
    let first = p
        .blocks
        .iter()
        .position(|b| String::from_utf8_lossy(&p.bytes[b.span()]).contains("DC(279.574)"))
        .unwrap();
    assert!(
        (m[first].1.unwrap() + 80.426).abs() < 1e-9,
        "{:?}",
        m[first]
    );
    let out = patched_in_form("sinumerik-traori-dc.mpf", false);
    for w in parse(out, Dialect::Auto).unwrap().words {
        if w.letter == b'C' {
            assert!(
                (0.0..360.0).contains(&w.value),
                "C=DC({}) outside [0, 360)",
                w.value
            );
        }
    }
}

/// ACP (C rising through 360°) and ACN (C falling through 0°): with the C-only method
/// the patched C keeps its direction and each word is written in its own form; the default
/// method re-selects the branch (the patched C turns back a little), which ACP/ACN cannot
/// make: both zones are refused by name and the file is written unchanged.
#[test]
fn acp_and_acn_keep_their_direction_or_refuse_the_zone() {
    let name = "sinumerik-traori-acp-acn.mpf";
    let bytes = cam(name);
    let forms = c_forms(&bytes);
    assert!(forms.contains(&RotaryForm::Acp) && forms.contains(&RotaryForm::Acn));
    let out = patched_in_form(name, true);
    let out_forms = c_forms(&out);
    // Each word kept its own form (one inserted at each plunge takes its neighbour's).
    assert_eq!(
        out_forms.iter().filter(|f| **f == RotaryForm::Acp).count(),
        forms.iter().filter(|f| **f == RotaryForm::Acp).count() + 1
    );
    assert_eq!(
        out_forms.iter().filter(|f| **f == RotaryForm::Acn).count(),
        forms.iter().filter(|f| **f == RotaryForm::Acn).count() + 1
    );
    let (out, report) = patch_nc(&bytes, &ucp710(), &opts(false)).unwrap();
    assert_eq!(out, bytes, "a zone ACP/ACN cannot make was written");
    assert_eq!(report.zones.len(), 2);
    assert!(
        report
            .zones
            .iter()
            .all(|z| z.reason == polepatch::ZoneReason::DirectionForm)
    );
    let refused: Vec<_> = report
        .untouched_runs
        .iter()
        .filter(|u| u.reason == UntouchedReason::DirectionForm)
        .collect();
    assert_eq!(refused.len(), 2, "{:?}", report.untouched_runs);
    assert!(refused[0].message.contains("C=ACP(…) would move"));
    assert!(refused[1].message.contains("C=ACN(…) would move"));
}
