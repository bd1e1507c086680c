//! Shared checks of the patch tests.
#![allow(dead_code)]

use polepatch::kinematics::{Axis, Machine};
use polepatch::nc::{Dialect, parse};
use polepatch::patcher::direct::deviation_bound_zone;
use polepatch::patcher::{AnalysisOptions, CLimits, PatchOptions, analyze_path};
use polepatch::program::{LoadedProgram, load_nc};
use polepatch::{FileReport, patch_loaded};
use std::path::{Path, PathBuf};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every NC fixture under fixtures/ (recursively), sorted.
pub fn fixtures() -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root().join("fixtures")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if matches!(
                p.extension().and_then(|x| x.to_str()),
                Some("I" | "H" | "mpf" | "MPF" | "nc" | "NC" | "ngc" | "tap")
            ) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

pub fn load_bytes(bytes: &[u8], name: &str, machine: &Machine) -> LoadedProgram {
    load_nc(bytes.to_vec(), name, machine, None).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Per run: (lowest C ratio, number of zones) as `polepatch analyze` sees the program.
pub fn c_ratios_and_zones(lp: &LoadedProgram, machine: &Machine, cone: f64) -> Vec<(f64, usize)> {
    let opts = AnalysisOptions {
        cone_deg: cone,
        ..AnalysisOptions::default()
    };
    lp.runs
        .iter()
        .map(|r| match &r.path {
            Ok(p) => {
                let a = analyze_path(p, machine, &opts).unwrap();
                (a.axis_min[Axis::C.index()].0, a.zones.len())
            }
            Err(_) => (f64::NAN, 0),
        })
        .collect()
}

/// Bytes of `line` with the C word at `span` removed (and one separator byte before it
/// when `with_sep`).
fn strip(line: &[u8], span: Option<std::ops::Range<usize>>, with_sep: bool) -> Vec<u8> {
    match span {
        None => line.to_vec(),
        Some(r) => {
            let start = if with_sep && r.start > 0 && line[r.start - 1] == b' ' {
                r.start - 1
            } else {
                r.start
            };
            [&line[..start], &line[r.end..]].concat()
        }
    }
}

/// Assert that `out` differs from `inp` only in C words (changed, or inserted where a
/// block had none).
pub fn assert_only_c_words_differ(name: &str, inp: &[u8], out: &[u8]) {
    let a = parse(inp.to_vec(), Dialect::Auto).unwrap();
    let b = parse(out.to_vec(), Dialect::Auto)
        .unwrap_or_else(|e| panic!("{name}: output does not parse: {e}"));
    assert_eq!(
        a.blocks.len(),
        b.blocks.len(),
        "{name}: block count changed"
    );
    for (ba, bb) in a.blocks.iter().zip(&b.blocks) {
        let la = &inp[ba.span()];
        let lb = &out[bb.span()];
        if la == lb {
            continue;
        }
        let ca = a
            .block_words(a.blocks.iter().position(|x| x == ba).unwrap())
            .iter()
            .find(|w| w.letter == b'C')
            .map(|w| w.span().start - ba.span().start..w.span().end - ba.span().start);
        let ib = b.blocks.iter().position(|x| x == bb).unwrap();
        let cb = b
            .block_words(ib)
            .iter()
            .find(|w| w.letter == b'C')
            .map(|w| w.span().start - bb.span().start..w.span().end - bb.span().start);
        assert!(
            cb.is_some(),
            "{name} line {}: changed without a C word",
            ba.line
        );
        let inserted = ca.is_none();
        assert_eq!(
            strip(la, ca, false),
            strip(lb, cb, inserted),
            "{name} line {}: bytes other than the C word differ:\n  in:  {}\n  out: {}",
            ba.line,
            String::from_utf8_lossy(la),
            String::from_utf8_lossy(lb)
        );
    }
    // Line endings and anything between blocks.
    let ends_a: Vec<&[u8]> = a
        .blocks
        .iter()
        .zip(a.blocks.iter().skip(1))
        .map(|(x, y)| &inp[x.span().end..y.span().start])
        .collect();
    let ends_b: Vec<&[u8]> = b
        .blocks
        .iter()
        .zip(b.blocks.iter().skip(1))
        .map(|(x, y)| &out[x.span().end..y.span().start])
        .collect();
    assert_eq!(ends_a, ends_b, "{name}: line endings changed");
}

/// Patch `bytes` and check the invariants of issue 4. Returns the report.
pub fn check_patch(
    name: &str,
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> (FileReport, Vec<u8>) {
    let lp = load_bytes(bytes, name, machine);
    let before = c_ratios_and_zones(&lp, machine, opts.cone_deg);
    let (out, report) = patch_loaded(&lp, machine, opts);
    if before.iter().all(|r| r.1 == 0) {
        assert_eq!(
            out, bytes,
            "{name} on {}: a program with no zone must come out byte-identical",
            machine.name
        );
    }
    assert_only_c_words_differ(name, bytes, &out);
    let lp2 = load_bytes(&out, name, machine);
    let after = c_ratios_and_zones(&lp2, machine, opts.cone_deg);
    assert_eq!(before.len(), after.len());
    for (k, (b, a)) in before.iter().zip(&after).enumerate() {
        if b.0.is_nan() {
            continue;
        }
        if a.1 > 0 {
            // Left below feed: acceptable only when no C-only change of the whole run can
            // reach feed (the bound LP is infeasible).
            if let Some(dev) = reachable_bound_deg(&lp, k, machine) {
                // Reachable with exact values: acceptable only if the file's precision is
                // what stops it (more decimals than allowed would reach feed).
                let fine = PatchOptions {
                    max_decimals: 8,
                    ..opts.clone()
                };
                let (out, _) = patch_loaded(&lp, machine, &fine);
                let zones_left =
                    c_ratios_and_zones(&load_bytes(&out, name, machine), machine, opts.cone_deg)[k]
                        .1;
                assert!(
                    zones_left == 0,
                    "{name} on {}: run {} still has {} zone(s) after patching (C ratio {:.4} → {:.4}), \
                     yet C-only changes could reach feed with max deviation {dev:.3}°, even with 8 decimals",
                    machine.name,
                    k + 1,
                    a.1,
                    b.0,
                    a.0
                );
                eprintln!(
                    "note: {name} on {}: run {} reaches feed only with more than {} decimals (bound {dev:.3}°)",
                    machine.name,
                    k + 1,
                    opts.max_decimals
                );
            } else {
                eprintln!(
                    "note: {name} on {}: run {} cannot reach feed on C (bound infeasible); C ratio {:.4} → {:.4}",
                    machine.name,
                    k + 1,
                    b.0,
                    a.0
                );
            }
        }
        assert!(
            a.0 >= b.0 - 1e-9,
            "{name} on {}: run {} C ratio got worse: {} → {}",
            machine.name,
            k + 1,
            b.0,
            a.0
        );
    }
    for z in &report.zones {
        assert!(
            z.after.c_ratio >= z.before.c_ratio - 1e-9,
            "{name}: zone got worse: {z:?}"
        );
    }
    (report, out)
}

/// The smallest max orientation deviation with which C-only changes at points 1.. of run
/// `r` make its zones reach feed on C without making any other sample worse, or `None`
/// when no such change exists (unrounded values: the file's precision is not counted).
pub fn reachable_bound_deg(lp: &LoadedProgram, r: usize, machine: &Machine) -> Option<f64> {
    let path = lp.runs[r].path.as_ref().ok()?;
    let n = path.s_mm.len();
    let a = analyze_path(path, machine, &AnalysisOptions::default()).ok()?;
    let zone = (
        a.zones.iter().map(|z| z.first).min()?,
        a.zones.iter().map(|z| z.last).max()?,
    );
    let p: Vec<f64> = path.axes.iter().map(|q| q[Axis::Primary.index()]).collect();
    let c: Vec<f64> = path.axes.iter().map(|q| q[Axis::C.index()]).collect();
    let lim = CLimits::new(machine, path.feed_mm_min, 0.0);
    let step = path.feed_mm_min / 60.0 * machine.tcy_s;
    deviation_bound_zone(&path.s_mm, &p, &c, 1, n - 1, zone, &lim, step)
        .ok()
        .map(|b| b.0)
}

pub fn machines() -> Vec<Machine> {
    Machine::builtin_names()
        .iter()
        .map(|n| Machine::builtin(n).unwrap())
        .collect()
}

pub fn name_of(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}
