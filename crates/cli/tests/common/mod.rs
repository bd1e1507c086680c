//! Shared checks of the patch tests.
#![allow(dead_code)]

use polepatch::FileReport;
use polepatch::LoadedProgram;
use polepatch::kinematics::{Axis, Machine};
use polepatch::load_nc;
use polepatch::nc::{Dialect, parse};
use polepatch::patcher::quality::NOT_WORSE_REL;
use polepatch::patcher::quality::deviation_bound_zone;
use polepatch::patcher::quality::{SpanFigures, analyze_spans};
use polepatch::patcher::{AnalysisOptions, CLimits, PatchAxes, PatchOptions, analyze_path};
use std::path::{Path, PathBuf};

/// Run the `polepatch` binary in the repository root: (exit code, stdout, stderr).
pub fn polepatch(args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_polepatch"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Run the `polepatch` binary in `dir`: (exit code, stdout, stderr).
pub fn polepatch_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_polepatch"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh, empty temporary folder for this test process.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("polepatch-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every NC fixture under fixtures/ (recursively), sorted.
pub fn fixtures() -> Vec<PathBuf> {
    polepatch_fixturegen::nc_files(&root().join("fixtures"))
}

pub fn load_bytes(bytes: &[u8], name: &str, machine: &Machine) -> LoadedProgram {
    load_nc(bytes, name, machine, None).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Patch `lp`'s bytes through the one pipeline ([`polepatch::patch_nc`]) with the
/// patcher's options `opts`, the tool options `lp.tool`.
pub fn patch_lp(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &PatchOptions,
) -> (Vec<u8>, FileReport) {
    polepatch::patch_nc(
        &lp.program.bytes,
        machine,
        &polepatch::PatchOptions {
            read: polepatch::ReadOptions {
                name: lp.name.clone(),
                ..polepatch::ReadOptions::default()
            },
            patch: opts.clone(),
            tool: lp.tool.clone(),
            ..polepatch::PatchOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{}: {e}", lp.name))
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

/// Bytes of block `b` of a parsed program with every word whose letter is in `letters`
/// removed, together with the blanks before it (an inserted word brings its separator).
fn strip_words(p: &polepatch::nc::Program, b: usize, letters: &[u8]) -> Vec<u8> {
    let span = p.blocks[b].span();
    let bytes = &p.bytes;
    let mut out = Vec::new();
    let mut pos = span.start;
    for w in p.block_words(b) {
        if !letters.contains(&w.letter) {
            continue;
        }
        let mut start = w.span().start;
        while start > pos && (bytes[start - 1] == b' ' || bytes[start - 1] == b'\t') {
            start -= 1;
        }
        out.extend_from_slice(&bytes[pos..start]);
        pos = w.span().end;
    }
    out.extend_from_slice(&bytes[pos..span.end]);
    out
}

/// Assert that `out` differs from `inp` only in words with the given letters (changed, or
/// inserted where a block had none), line endings and all other bytes unchanged.
pub fn assert_only_words_differ(name: &str, inp: &[u8], out: &[u8], letters: &[u8]) {
    let a = parse(inp.to_vec(), Dialect::Auto).unwrap();
    let b = parse(out.to_vec(), Dialect::Auto)
        .unwrap_or_else(|e| panic!("{name}: output does not parse: {e}"));
    assert_eq!(
        a.blocks.len(),
        b.blocks.len(),
        "{name}: block count changed"
    );
    for (i, (ba, bb)) in a.blocks.iter().zip(&b.blocks).enumerate() {
        if inp[ba.span()] == out[bb.span()] {
            continue;
        }
        assert_eq!(
            strip_words(&a, i, letters),
            strip_words(&b, i, letters),
            "{name} line {}: bytes other than the {} words differ:\n  in:  {}\n  out: {}",
            ba.line,
            String::from_utf8_lossy(letters),
            String::from_utf8_lossy(&inp[ba.span()]),
            String::from_utf8_lossy(&out[bb.span()])
        );
    }
    // Line endings and anything between blocks.
    let ends = |p: &polepatch::nc::Program, t: &[u8]| -> Vec<Vec<u8>> {
        p.blocks
            .iter()
            .zip(p.blocks.iter().skip(1))
            .map(|(x, y)| t[x.span().end..y.span().start].to_vec())
            .collect()
    };
    assert_eq!(ends(&a, inp), ends(&b, out), "{name}: line endings changed");
}

/// [`assert_only_words_differ`] for C words.
pub fn assert_only_c_words_differ(name: &str, inp: &[u8], out: &[u8]) {
    assert_only_words_differ(name, inp, out, b"C");
}

/// [`assert_only_words_differ`] for the rotary words (A, B, C).
pub fn assert_only_rotary_words_differ(name: &str, inp: &[u8], out: &[u8]) {
    assert_only_words_differ(name, inp, out, b"ABC");
}

/// Patch `bytes` and check the invariants of the method `opts.axes` selects. Returns the
/// report and the output.
pub fn check_patch(
    name: &str,
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> (FileReport, Vec<u8>) {
    match opts.axes {
        PatchAxes::OnlyC => check_patch_only_c(name, bytes, machine, opts),
        PatchAxes::Both => check_patch_both(name, bytes, machine, opts),
    }
}

/// Per run, Equation 6 over every span (exact over the span; `None` for a run not
/// analysed).
fn run_spans(lp: &LoadedProgram, machine: &Machine, cone: f64) -> Vec<Option<Vec<SpanFigures>>> {
    let opts = AnalysisOptions {
        cone_deg: cone,
        ..AnalysisOptions::default()
    };
    lp.runs
        .iter()
        .map(|r| {
            r.path
                .as_ref()
                .ok()
                .map(|p| analyze_spans(p, machine, &opts).unwrap().1)
        })
        .collect()
}

/// The invariants of issue 8 for the default method (both rotary axes):
/// - a program without zone comes out byte-identical; only rotary words differ;
/// - every zone the report lists reaches feed on both rotary axes (on the written values,
///   read back) and the file read back has no singular zone left;
/// - nothing is worse: on every span of every run, the lowest ratio of every axis is at
///   least `min(before, 1)` (to `NOT_WORSE_REL`), and X Y Z (hence s) are unchanged.
pub fn check_patch_both(
    name: &str,
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> (FileReport, Vec<u8>) {
    let m = &machine.name;
    let lp = load_bytes(bytes, name, machine);
    let before = c_ratios_and_zones(&lp, machine, opts.cone_deg);
    let (out, report) = patch_lp(&lp, machine, opts);
    if before.iter().all(|r| r.1 == 0) {
        assert_eq!(out, bytes, "{name} on {m}: no zone, so byte-identical");
    }
    // A ball programmed at its tip, known from the program (issue 27): its X Y Z move to
    // keep the centre, and the linear axes may take a span's limit over from the rotary
    // axes the patch freed (the span may not get slower).
    let keeps_centre = report.zones.iter().any(|z| {
        z.tool
            .tool()
            .is_some_and(|t| t.kind == polepatch::tool::ToolKind::Ball)
            && z.tool_point == Some(polepatch::tool::ToolPoint::Tip)
            && z.points_modified > 0
    });
    if keeps_centre {
        assert_only_words_differ(name, bytes, &out, b"ABCXYZ");
    } else {
        assert_only_rotary_words_differ(name, bytes, &out);
    }
    let lp2 = load_bytes(&out, name, machine);
    let after = c_ratios_and_zones(&lp2, machine, opts.cone_deg);
    let mut proven = 0;
    let mut left_on_purpose = 0;
    for z in &report.zones {
        // A run whose X Y Z are machine coordinates for this machine (the shop forms whose
        // TCP needs the machine's own codes) is left on purpose.
        if left_without_tcpm(&report, z.run) {
            left_on_purpose += 1;
            continue;
        }
        // A flat or bull-nose cutter's zone held by the surface bound (issue 27): the
        // cap is the tool's; every written deviation within it.
        if z.reason == polepatch::ZoneReason::ToolLimited {
            // Within the default surface tolerance (0.005 mm) and short of what it needed.
            assert!(
                z.max_cutter_shift_mm.is_some_and(|s| s <= 0.005 + 1e-6)
                    && z.needed_deviation_deg
                        .is_some_and(|d| d > z.max_deviation_deg),
                "{name} on {m}: {z:?}"
            );
            left_on_purpose += 1;
            continue;
        }
        // A zone whose patch cannot be written in the file's words (issue 30): a
        // Sinumerik direction form that cannot make the patched move, a word whose value
        // is a macro variable (`C#105`). Its run is listed with the reason.
        if matches!(
            z.reason,
            polepatch::ZoneReason::DirectionForm | polepatch::ZoneReason::MacroVariable
        ) {
            assert!(
                z.outcome == polepatch::Outcome::Unchanged
                    && report.untouched_runs.iter().any(|u| u.run == z.run),
                "{name} on {m}: {z:?}"
            );
            left_on_purpose += 1;
            continue;
        }
        if z.outcome != polepatch::Outcome::Reached {
            // Left below feed: only where no values at all can reach it (the LP proof).
            assert!(
                proven_unreachable(&lp, z, machine, opts),
                "{name} on {m}: zone left below feed, yet reachable: {z:?}"
            );
            eprintln!(
                "note: {name} on {m}: zone lines {:?} proven unreachable",
                z.lines
            );
            proven += 1;
            continue;
        }
        assert!(
            z.after.c_ratio >= 1.0 - 1e-9 && z.after.primary_ratio >= 1.0 - 1e-9,
            "{name} on {m}: both rotary axes must reach feed: {z:?}"
        );
    }
    let left: usize = after.iter().map(|a| a.1).sum();
    if proven == 0 && left_on_purpose == 0 {
        assert_eq!(
            left, 0,
            "{name} on {m}: zones left after patching: {after:?}"
        );
    }
    let (sb, sa) = (
        run_spans(&lp, machine, opts.cone_deg),
        run_spans(&lp2, machine, opts.cone_deg),
    );
    for (k, (b, a)) in sb.iter().zip(&sa).enumerate() {
        let (Some(b), Some(a)) = (b, a) else { continue };
        assert_eq!(
            b.len(),
            a.len(),
            "{name} on {m}: run {}: spans moved",
            k + 1
        );
        for (x, y) in b.iter().zip(a) {
            if keeps_centre {
                let floor = x.bound.ratio.min(1.0) * (1.0 - NOT_WORSE_REL) - 1e-12;
                assert!(
                    y.bound.ratio >= floor,
                    "{name} on {m}: run {}, s = {:.3} mm: slower, {:.4} → {:.4}",
                    k + 1,
                    x.min_s_mm,
                    x.bound.ratio,
                    y.bound.ratio
                );
            }
            for axis in 0..5 {
                if keeps_centre && axis < 3 {
                    continue;
                }
                // "Not worse" to the patcher's resolution (0.01 % of the ratio).
                let floor = x.axis_ratio[axis].min(1.0) * (1.0 - NOT_WORSE_REL) - 1e-12;
                assert!(
                    y.axis_ratio[axis] >= floor,
                    "{name} on {m}: run {}, s = {:.3} mm: axis {axis} ratio {:.4} → {:.4}",
                    k + 1,
                    x.min_s_mm,
                    x.axis_ratio[axis],
                    y.axis_ratio[axis]
                );
            }
        }
    }
    (report, out)
}

/// Whether the zone of report row `z` is proven unreachable: with every point of its run
/// but the first (and the last, where `polepatch::end_pose` keeps it) free, no values
/// bring the zone's original singular zones to feed on both rotary axes (the relaxation
/// [`polepatch::patcher::quality::reachable`] is infeasible).
pub fn proven_unreachable(
    lp: &LoadedProgram,
    z: &polepatch::ZoneRow,
    machine: &Machine,
    opts: &PatchOptions,
) -> bool {
    let r = z.run - 1;
    let Ok(path) = &lp.runs[r].path else {
        return false;
    };
    let n = path.s_mm.len();
    let a = analyze_path(
        path,
        machine,
        &AnalysisOptions {
            cone_deg: opts.cone_deg,
            ..AnalysisOptions::default()
        },
    )
    .unwrap();
    let (l0, l1) = (z.lines[0], z.lines[1]);
    let inside: Vec<_> = a
        .zones
        .iter()
        .filter(|x| lp.line_of(r, x.first) <= l1 && lp.line_of(r, x.last) >= l0)
        .collect();
    if inside.is_empty() {
        return false;
    }
    let zone = polepatch::patcher::Zone {
        first: inside.iter().map(|x| x.first).min().unwrap(),
        last: inside.iter().map(|x| x.last).max().unwrap(),
        ..inside[0].clone()
    };
    let end = if lp.end_pose(r).free { n - 1 } else { n - 2 };
    let p: Vec<f64> = path.axes.iter().map(|q| q[Axis::Primary.index()]).collect();
    let c: Vec<f64> = path.axes.iter().map(|q| q[Axis::C.index()]).collect();
    !polepatch::patcher::quality::reachable(
        &path.s_mm,
        &p,
        &c,
        1,
        end,
        polepatch::patcher::quality::zone_core(&zone, n, opts.solver.core_margin_points),
        machine,
        path.feed_mm_min,
        opts.axes,
        true,
    )
    .unwrap_or(true)
}

/// Whether run `run` (from 1) was left because its X Y Z are machine coordinates for this
/// machine (the shop forms whose TCP needs the machine's own codes): on purpose.
fn left_without_tcpm(report: &FileReport, run: usize) -> bool {
    report.untouched_runs.iter().any(|u| {
        u.run == run
            && matches!(
                u.reason,
                polepatch::UntouchedReason::NoTcpm
                    | polepatch::UntouchedReason::TcpmUncertain
                    | polepatch::UntouchedReason::TcpmUnknown
            )
    })
}

/// The invariants of issue 4 for the C-only method (`--only-c`). Returns the report.
pub fn check_patch_only_c(
    name: &str,
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> (FileReport, Vec<u8>) {
    let lp = load_bytes(bytes, name, machine);
    let before = c_ratios_and_zones(&lp, machine, opts.cone_deg);
    let (out, report) = patch_lp(&lp, machine, opts);
    if before.iter().all(|r| r.1 == 0) {
        assert_eq!(
            out, bytes,
            "{name} on {}: a program with no zone must come out byte-identical",
            machine.name
        );
    }
    let moved_centre = report.zones.iter().any(|z| {
        z.tool
            .tool()
            .is_some_and(|t| t.kind == polepatch::tool::ToolKind::Ball)
            && z.tool_point == Some(polepatch::tool::ToolPoint::Tip)
            && z.points_modified > 0
    });
    if moved_centre {
        // A ball programmed at its tip keeps its centre: X Y Z change with C.
        assert_only_words_differ(name, bytes, &out, b"CXYZ");
    } else {
        assert_only_c_words_differ(name, bytes, &out);
    }
    let lp2 = load_bytes(&out, name, machine);
    let after = c_ratios_and_zones(&lp2, machine, opts.cone_deg);
    assert_eq!(before.len(), after.len());
    for (k, (b, a)) in before.iter().zip(&after).enumerate() {
        if b.0.is_nan() || left_without_tcpm(&report, k + 1) {
            continue;
        }
        // A ball programmed at its tip keeps its centre: X Y Z move with C, which the bound
        // LP below does not model (its answer is no bound on that patch); a flat or
        // bull-nose cutter's zone is held by the surface bound, which it does not know.
        // A zone whose patch cannot be written in the file's words (issue 30: a direction
        // form, a macro-variable word) is left on purpose. So is one whose patches that
        // reach feed all turn some tool axis beyond the safety bound near the pole (twice
        // its distance from the pole, at most the pole reach): the bound LP below knows no
        // such bound (and is a relaxation: its deviation is a lower bound, not a patch).
        let reach = opts.reach_deg();
        let keeps_centre = report.zones.iter().any(|z| {
            z.run == k + 1
                && ((z
                    .tool
                    .tool()
                    .is_some_and(|t| t.kind == polepatch::tool::ToolKind::Ball)
                    && z.tool_point == Some(polepatch::tool::ToolPoint::Tip))
                    || matches!(
                        z.reason,
                        polepatch::ZoneReason::ToolLimited
                            | polepatch::ZoneReason::DirectionForm
                            | polepatch::ZoneReason::MacroVariable
                    )
                    || (z.reason == polepatch::ZoneReason::SafetyBound && {
                        assert!(
                            z.max_deviation_deg <= reach + 1e-3 && z.needed_deviation_deg.is_some(),
                            "{name}: {z:?}"
                        );
                        eprintln!(
                            "note: {name} on {}: run {} left below feed by the safety bound \
                             (needs {:?}°, wrote {:.3}°)",
                            machine.name,
                            k + 1,
                            z.needed_deviation_deg,
                            z.max_deviation_deg
                        );
                        true
                    }))
        });
        if a.1 > 0 && !keeps_centre {
            // Left below feed: acceptable only when no C-only change of the whole run can
            // reach feed (the bound LP is infeasible).
            if let Some(dev) = reachable_bound_deg(&lp, k, machine) {
                // Reachable with exact values: acceptable only if the file's precision is
                // what stops it (more decimals than allowed would reach feed).
                let fine = PatchOptions {
                    max_decimals: 8,
                    ..opts.clone()
                };
                let (out, _) = patch_lp(&lp, machine, &fine);
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
    // A run whose end is pinned (`polepatch::end_pose`) keeps its last point, as the
    // patch does.
    let end = if lp.end_pose(r).free { n - 1 } else { n - 2 };
    deviation_bound_zone(
        &path.s_mm,
        &p,
        &c,
        1,
        end,
        zone,
        &lim,
        polepatch::patcher::quality::BOUND_SAMPLES_PER_SPAN,
    )
    .ok()
    .map(|b| b.0)
}

/// The lines of every singular zone `polepatch analyze` finds in `bytes` (default options).
pub fn analysed_zone_lines(bytes: &[u8], machine: &Machine) -> Vec<[usize; 2]> {
    let a = polepatch::analyze_nc(bytes, machine, &Default::default()).unwrap();
    a.runs
        .iter()
        .filter_map(|r| r.figures.as_ref())
        .flat_map(|f| f.zones.iter().map(|z| z.lines))
        .collect()
}

pub fn machines() -> Vec<Machine> {
    Machine::builtin_names()
        .iter()
        .map(|n| Machine::builtin(n).unwrap())
        .collect()
}

/// The built-in machines a program was posted for: those whose rotary letters it uses.
/// On the others it is refused by name, with line and column (`Error::ForeignAxis`,
/// issue 29) — checked here for every machine left out.
pub fn machines_for(name: &str, bytes: &[u8]) -> Vec<Machine> {
    machines()
        .into_iter()
        .filter(|m| {
            let opts = polepatch::AnalyzeOptions {
                read: polepatch::ReadOptions {
                    name: name.to_string(),
                    ..polepatch::ReadOptions::default()
                },
                ..polepatch::AnalyzeOptions::default()
            };
            match polepatch::analyze_nc(bytes, m, &opts) {
                Err(polepatch::Error::ForeignAxis {
                    line,
                    column,
                    letter,
                    ..
                }) => {
                    assert!(line >= 1 && column >= 1, "{name} on {}", m.name);
                    assert_ne!(letter, m.primary_letter(), "{name} on {}", m.name);
                    false
                }
                _ => true,
            }
        })
        .collect()
}

pub fn name_of(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}
