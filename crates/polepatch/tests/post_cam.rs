//! Issue 16: `post` on CL files in the styles CAM systems write (`fixtures/cl/`: a
//! CAMWorks/SolidCAM-style plate in mm with drill and peck cycles, a compensated contour
//! with arcs; the same style in inches; an NX/CATIA-style 5-axis file with `MULTAX`, `$`
//! continuations, a swing past the pole, a tilted circle, a circle whose tool axis turns
//! and a helix). Every hole is one canned cycle at its position and depth with no feed
//! move between holes; every arc, as the controller will cut it (G2/G3) or as chords,
//! stays within the tolerance of the true circle; `UNIT/INCH` and `UNITS/INCHES` post the
//! same program; what is not posted is refused naming the record.

use polepatch::cl::{Arc, ClProgram, MoveKind, Units, parse};
use polepatch::kinematics::Machine;
use polepatch::nc::{Dialect, Motion, modal, parse as parse_nc};
use polepatch::post::{PostOptions, post_cl, read_cl};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(root().join("fixtures/cl").join(name)).unwrap()
}

const FIXTURES: [&str; 3] = [
    "camworks_plate.apt",
    "camworks_bracket_inch.apt",
    "nx_5axis.cls",
];

const DIALECTS: [Dialect; 3] = [Dialect::Heidenhain, Dialect::Sinumerik, Dialect::Fanuc];

fn ucp710() -> Machine {
    Machine::builtin("mikron-ucp710").unwrap()
}

/// Post `cl` in `dialect`; Heidenhain in mm (it takes no inch programs from polepatch).
fn post(cl: &ClProgram, dialect: Dialect, patch: bool, tweak: impl Fn(&mut PostOptions)) -> String {
    let mut opts = PostOptions {
        dialect,
        patch,
        units: (dialect == Dialect::Heidenhain).then_some(Units::Mm),
        ..PostOptions::default()
    };
    tweak(&mut opts);
    let (bytes, _) = post_cl(cl, &ucp710(), &opts).unwrap();
    String::from_utf8(bytes).unwrap()
}

/// A number after `letter` in a line's words (`X-12.5`, `Q201=-15`).
fn word(line: &str, letter: &str) -> Option<f64> {
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(letter))
        .and_then(|v| v.trim_start_matches('=').parse().ok())
}

/// The canned cycles of a posted program: (x, y, bottom, feed start R) in mm, in order.
fn cycles(text: &str, dialect: Dialect) -> Vec<[f64; 4]> {
    let inch = text.contains("G20") || text.contains("G700");
    let k = if inch { 25.4 } else { 1.0 };
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut at = [f64::NAN; 2];
    for (i, l) in lines.iter().enumerate() {
        if let (Some(x), Some(y)) = (word(l, "X"), word(l, "Y")) {
            at = [x, y];
        }
        match dialect {
            Dialect::Fanuc => {
                if l.starts_with("G98 G") {
                    let v = |c: &str| word(l, c).unwrap() * k;
                    out.push([v("X"), v("Y"), v("Z"), v("R")]);
                }
            }
            Dialect::Sinumerik => {
                if let Some(args) = l.strip_prefix("CYCLE8") {
                    let a: Vec<f64> = args[2..args.len() - 1]
                        .split(',')
                        .map(|s| s.parse().unwrap_or(f64::NAN))
                        .collect();
                    // RTP, RFP, SDIS, DP, …
                    out.push([at[0] * k, at[1] * k, a[3] * k, (a[1] + a[2]) * k]);
                }
            }
            _ => {
                if l.contains(" G79 ") {
                    // The definition just before: Q lines back to its G2xx line.
                    let q = |n: u32| {
                        lines[..i]
                            .iter()
                            .rev()
                            .take_while(|l| l.starts_with('Q'))
                            .find_map(|l| word(l, &format!("Q{n}")))
                            .unwrap()
                    };
                    out.push([at[0], at[1], q(203) + q(201), q(203) + q(200)]);
                }
            }
        }
    }
    out
}

/// Every hole of `cl` is one canned cycle of `text` at its position and depth (x, y,
/// bottom, feed start within the last written digit), in order, and there is no feed move
/// between two cycle calls of one tool. Returns the number of holes.
fn check_holes(cl: &ClProgram, text: &str, dialect: Dialect, what: &str) -> usize {
    let holes: Vec<[f64; 4]> = cl
        .points()
        .filter_map(|p| match &p.kind {
            MoveKind::Hole(c) => Some([
                p.pos_mm[0],
                p.pos_mm[1],
                p.pos_mm[2] - c.depth_mm,
                p.pos_mm[2] + c.clearance_mm,
            ]),
            _ => None,
        })
        .collect();
    let got = cycles(text, dialect);
    assert_eq!(got.len(), holes.len(), "{what} {dialect:?}\n{text}");
    // Within the last written digit (inch: 0.0001 in).
    let tol = if text.contains("G20") || text.contains("G700") {
        0.0013
    } else {
        0.0006
    };
    for (g, h) in got.iter().zip(&holes) {
        for i in 0..4 {
            assert!(
                (g[i] - h[i]).abs() <= tol,
                "{what} {dialect:?}: {g:?} vs {h:?}\n{text}"
            );
        }
    }
    // Between two cycle calls of one tool: rapids, cycle lines and parameters only, never
    // a feed move.
    let lines: Vec<&str> = text.lines().collect();
    let calls: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.starts_with("G98 G") || l.starts_with("CYCLE8") || l.contains(" G79 "))
        .map(|(i, _)| i)
        .collect();
    for w in calls.windows(2) {
        let between = &lines[w[0] + 1..w[1]];
        if between.iter().any(|l| l.contains("M6") || l.contains(" T")) {
            continue;
        }
        for l in between {
            let feed_move = ["G01", "G1 ", "G02", "G03", "G2 ", "G3 "]
                .iter()
                .any(|g| l.contains(g));
            assert!(
                !feed_move,
                "{what} {dialect:?}: '{l}' between holes\n{text}"
            );
        }
    }
    got.len()
}

/// Issue 16 check 1: every hole becomes one canned cycle at its position and depth, and
/// there is no feed move between holes.
#[test]
fn every_hole_is_one_canned_cycle_at_its_position_and_depth() {
    let mut checked = 0;
    for name in FIXTURES {
        let cl = parse(&fixture(name)).unwrap();
        for dialect in DIALECTS {
            for patch in [false, true] {
                let text = post(&cl, dialect, patch, |_| {});
                checked += check_holes(&cl, &text, dialect, name);
            }
        }
    }
    // 5 holes on the plate, 3 on the bracket; 3 dialects; patched or not.
    assert_eq!(checked, (5 + 3) * 3 * 2);
}

/// A piece of the posted path: a straight segment or the controller's arc.
enum Piece {
    Line([f64; 3], [f64; 3]),
    Arc {
        start: [f64; 3],
        end: [f64; 3],
        center: [f64; 3],
        /// Index of the plane normal (X 0, Y 1, Z 2).
        normal: usize,
        cw: bool,
    },
}

impl Piece {
    fn end(&self) -> [f64; 3] {
        match self {
            Piece::Line(_, e) | Piece::Arc { end: e, .. } => *e,
        }
    }

    /// Points along the piece, as the controller moves (arcs: the circle through the
    /// start about the centre, the normal axis linear in the angle).
    fn samples(&self) -> Vec<[f64; 3]> {
        match *self {
            Piece::Line(a, b) => (0..=8)
                .map(|k| {
                    let t = k as f64 / 8.0;
                    [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i]))
                })
                .collect(),
            Piece::Arc {
                start,
                end,
                center,
                normal,
                cw,
            } => {
                let (u, v) = match normal {
                    2 => (0, 1),
                    1 => (2, 0),
                    _ => (1, 2),
                };
                let ang = |p: [f64; 3]| (p[v] - center[v]).atan2(p[u] - center[u]);
                let r = (start[u] - center[u]).hypot(start[v] - center[v]);
                let mut sweep = ang(end) - ang(start);
                let tau = std::f64::consts::TAU;
                if cw {
                    sweep = -((-sweep).rem_euclid(tau));
                } else {
                    sweep = sweep.rem_euclid(tau);
                }
                if sweep.abs() < 1e-9 {
                    sweep = if cw { -tau } else { tau };
                }
                (0..=64)
                    .map(|k| {
                        let t = k as f64 / 64.0;
                        let a = ang(start) + t * sweep;
                        let mut p = [0.0; 3];
                        p[u] = center[u] + r * a.cos();
                        p[v] = center[v] + r * a.sin();
                        p[normal] = start[normal] + t * (end[normal] - start[normal]);
                        p
                    })
                    .collect()
            }
        }
    }
}

/// The posted program's path, piece by piece (mm), with the reader's positions.
fn pieces(text: &str) -> Vec<Piece> {
    let prog = parse_nc(text.as_bytes().to_vec(), Dialect::Auto).unwrap();
    let heidenhain = prog.dialect == Dialect::Heidenhain;
    let mut out = Vec::new();
    let mut prev: Option<[f64; 3]> = None;
    let mut plane = 2;
    let mut cc = [0.0; 3];
    for b in 0..prog.blocks.len() {
        let st = prog.state(b);
        let k = if st.inch { 25.4 } else { 1.0 };
        for w in prog.block_words(b) {
            if w.letter == b'G' {
                match w.value.round() as i64 {
                    17 => plane = 2,
                    18 => plane = 1,
                    19 => plane = 0,
                    _ => {}
                }
            }
        }
        let centre_word = |l: u8| prog.word(b, l).map(|w| w.value * k);
        if heidenhain && !prog.blocks[b].is_move {
            for (i, l) in [b'I', b'J', b'K'].into_iter().enumerate() {
                if let Some(v) = centre_word(l) {
                    cc[i] = v;
                }
            }
        }
        if !prog.blocks[b].is_move {
            continue;
        }
        let Some(p) = (|| Some([st.pos[modal::X]?, st.pos[modal::Y]?, st.pos[modal::Z]?]))() else {
            continue;
        };
        // The first move: a piece from where the machine was (taken as its own end).
        let s = prev.unwrap_or(p);
        {
            match st.motion {
                Motion::ArcCw | Motion::ArcCcw => {
                    let center = if heidenhain {
                        let mut c = cc;
                        c[plane] = s[plane];
                        c
                    } else {
                        let mut c = s;
                        for (i, l) in [b'I', b'J', b'K'].into_iter().enumerate() {
                            c[i] += centre_word(l).unwrap_or(0.0);
                        }
                        c
                    };
                    out.push(Piece::Arc {
                        start: s,
                        end: p,
                        center,
                        normal: plane,
                        cw: st.motion == Motion::ArcCw,
                    });
                }
                _ => out.push(Piece::Line(s, p)),
            }
        }
        prev = Some(p);
    }
    out
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// How far the posted path between each CL arc's start and end gets from the true arc
/// (mm), for every arc of `cl`: (arc, worst distance, pieces that were controller arcs).
fn arc_errors(cl: &ClProgram, text: &str) -> Vec<(Arc, f64, usize)> {
    let path = pieces(text);
    let mut out = Vec::new();
    let mut next = 0;
    let mut prev_end: Option<[f64; 3]> = None;
    // Match the CL moves (holes aside) to the path in order, by position.
    for p in cl.points() {
        if matches!(p.kind, MoveKind::Hole(_)) {
            prev_end = None;
            continue;
        }
        let start_piece = next;
        let found = path[next..]
            .iter()
            .position(|q| dist(q.end(), p.pos_mm) < 0.002)
            .map(|i| next + i);
        let Some(end_piece) = found else {
            // A move the path starts with (no piece ends before it).
            assert!(
                prev_end.is_none() || next == 0,
                "CL line {} ({:?}) not found after piece {next} ending {:?}",
                p.line,
                p.pos_mm,
                path.get(next.wrapping_sub(1)).map(Piece::end)
            );
            continue;
        };
        next = end_piece + 1;
        if let MoveKind::Arc(a) = &p.kind {
            let mut worst = 0.0f64;
            let mut arcs = 0;
            for q in &path[start_piece..=end_piece] {
                if matches!(q, Piece::Arc { .. }) {
                    arcs += 1;
                }
                for s in q.samples() {
                    worst = worst.max(a.distance_mm(s));
                }
            }
            out.push((a.clone(), worst, arcs));
        }
        prev_end = Some(p.pos_mm);
    }
    out
}

/// Issue 16 check 2: every arc's posted points (or the controller's arc) stay within the
/// tolerance of the true circle. The written coordinates are rounded to 0.001 mm (0.0001
/// inch): the bound is the tolerance plus that rounding (√3 × half the last digit).
#[test]
fn every_arc_stays_within_the_tolerance_of_the_true_circle() {
    let mut arcs_checked = 0;
    let mut as_g2g3 = 0;
    for name in FIXTURES {
        let cl = parse(&fixture(name)).unwrap();
        let n_arcs = cl
            .points()
            .filter(|p| matches!(p.kind, MoveKind::Arc(_)))
            .count();
        for dialect in DIALECTS {
            for (linearize, tol) in [(false, 0.001), (true, 0.001), (true, 0.01)] {
                let text = post(&cl, dialect, false, |o| {
                    o.linearize = linearize;
                    o.arc_tolerance_mm = tol;
                });
                let inch = text.contains("G20") || text.contains("G700");
                let rounding = 3f64.sqrt() * if inch { 0.00127 } else { 0.0005 };
                let errs = arc_errors(&cl, &text);
                assert_eq!(errs.len(), n_arcs, "{name} {dialect:?}");
                for (a, worst, g2) in errs {
                    assert!(
                        worst <= tol + rounding,
                        "{name} {dialect:?} linearize {linearize}: {worst} mm from the arc {a:?}\n{text}"
                    );
                    if linearize {
                        assert_eq!(g2, 0, "--linearize writes chords only");
                    }
                    as_g2g3 += g2;
                    arcs_checked += 1;
                }
            }
        }
    }
    // 3 + 2 + 3 arcs, 3 dialects, 3 settings.
    assert_eq!(arcs_checked, 8 * 3 * 3);
    // G2/G3 where the arc allows it: the plate's 3 and bracket's 2 in XY, the NX helix
    // (not on Heidenhain); the tilted circle and the turning axis always as chords.
    assert_eq!(as_g2g3, (3 + 2) * 3 + 2);
}

/// A planted arc: the controller's arc from the posted words is the CL's circle (centre,
/// radius, direction), in all three planes and both senses, and a tilted one is chords.
#[test]
fn planted_arcs_in_every_plane_and_sense() {
    for (normal, start, end, centre) in [
        ("0,0,1", [10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0; 3]),
        ("0,0,-1", [10.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0; 3]),
        ("0,1,0", [10.0, 0.0, 0.0], [0.0, 0.0, 10.0], [0.0; 3]),
        ("0,-1,0", [10.0, 0.0, 0.0], [0.0, 0.0, 10.0], [0.0; 3]),
        ("1,0,0", [0.0, 10.0, 0.0], [0.0, 0.0, 10.0], [0.0; 3]),
        ("-1,0,0", [0.0, 10.0, 0.0], [0.0, 0.0, 10.0], [0.0; 3]),
        ("0.6,0,0.8", [8.0, 0.0, -6.0], [0.0, 10.0, 0.0], [0.0; 3]),
    ] {
        let f = |p: [f64; 3]| format!("{},{},{}", p[0], p[1], p[2]);
        let text = format!(
            "MULTAX\nFEDRAT/500\nGOTO/{},0,0,1\nCIRCLE/{},{normal},10\nGOTO/{}\n",
            f(start),
            f(centre),
            f(end)
        );
        let cl = parse(text.as_bytes()).unwrap();
        for dialect in DIALECTS {
            let out = post(&cl, dialect, false, |_| {});
            let errs = arc_errors(&cl, &out);
            assert_eq!(errs.len(), 1);
            let (_, worst, g2) = &errs[0];
            assert!(
                *worst <= 0.001 + 0.0009,
                "{normal} {dialect:?}: {worst}\n{out}"
            );
            let principal = !normal.contains('.');
            let heidenhain_xy = dialect != Dialect::Heidenhain || normal.starts_with("0,0");
            assert_eq!(
                *g2,
                usize::from(principal && heidenhain_xy),
                "{normal} {dialect:?}\n{out}"
            );
        }
    }
}

/// Issue 16 check 3: `UNIT/INCH` (CAMWorks) and `UNITS/INCHES` post identical programs,
/// in inches and in mm.
#[test]
fn unit_inch_and_units_inches_post_identical_programs() {
    let unit = fixture("camworks_bracket_inch.apt");
    let text = String::from_utf8(unit.clone()).unwrap();
    assert!(text.contains("\r\nUNIT/INCH\r\n"));
    let units = text.replace("\r\nUNIT/INCH\r\n", "\r\nUNITS/INCHES\r\n");
    let a = parse(&unit).unwrap();
    let b = parse(units.as_bytes()).unwrap();
    assert_eq!(a.units, Units::Inch);
    for dialect in DIALECTS {
        for patch in [false, true] {
            let pa = post(&a, dialect, patch, |_| {});
            let pb = post(&b, dialect, patch, |_| {});
            assert_eq!(pa, pb, "{dialect:?}");
            // And in mm: every length and feed converted.
            let ma = post(&a, dialect, patch, |o| o.units = Some(Units::Mm));
            let mb = post(&b, dialect, patch, |o| o.units = Some(Units::Mm));
            assert_eq!(ma, mb);
            if dialect == Dialect::Fanuc {
                assert!(pa.contains("G20") && ma.contains("G21"));
                assert!(pa.contains("F12.") && ma.contains("F304.8"), "{pa}\n{ma}");
                assert!(pa.contains("X2.25 Y1.5 Z-0.125") && ma.contains("X57.15 Y38.1 Z-3.175"));
            }
        }
    }
}

/// The posted programs go through the one patch pipeline: the NX file's swing past the
/// pole is a zone that reaches feed in every dialect; the 3-axis files have none.
#[test]
fn posted_cam_programs_patch_like_any_program() {
    for name in FIXTURES {
        let cl = parse(&fixture(name)).unwrap();
        for dialect in DIALECTS {
            let opts = PostOptions {
                dialect,
                units: (dialect == Dialect::Heidenhain).then_some(Units::Mm),
                ..PostOptions::default()
            };
            let (bytes, report) = post_cl(&cl, &ucp710(), &opts).unwrap();
            let report = report.unwrap();
            let outcomes: Vec<_> = report.zones.iter().map(|z| z.outcome).collect();
            if name.starts_with("nx") {
                assert_eq!(
                    outcomes,
                    [polepatch::Outcome::Reached],
                    "{name} {dialect:?}"
                );
            } else {
                assert!(outcomes.is_empty(), "{name} {dialect:?}: {outcomes:?}");
            }
            // And the patched program reads back.
            parse_nc(bytes, Dialect::Auto).unwrap();
        }
    }
}

/// What `post` does not write is refused naming the record, with its line and column.
#[test]
fn what_is_not_posted_is_refused_naming_the_record() {
    let m = ucp710();
    let refused = |text: &str| -> String {
        let cl = read_cl(text.as_bytes(), "t.apt");
        match cl {
            Err(e) => e.to_string(),
            Ok(cl) => post_cl(
                &cl,
                &m,
                &PostOptions {
                    patch_options: polepatch::PatchOptions {
                        read: polepatch::ReadOptions {
                            name: "t.apt".into(),
                            ..polepatch::ReadOptions::default()
                        },
                        ..Default::default()
                    },
                    ..PostOptions::default()
                },
            )
            .map(|_| "posted".to_string())
            .unwrap_or_else(|e| e.to_string()),
        }
    };
    for (text, want) in [
        (
            "MULTAX\nFEDRAT/100\nGOTO/0,0,10,0,0,1\nCYCLE/DRILL,FEDTO,5,RAPTO,2\nGOTO/0,0,0,0,0.6,0.8\nCYCLE/OFF\n",
            "t.apt:4:1: CYCLE/DRILL (line 4): the tool axis (0.000000, 0.600000, 0.800000) at line 5 is not +Z",
        ),
        (
            "MULTAX\nFEDRAT/100\nGOTO/0,0,10,0,0,1\nCUTCOM/LEFT\nGOTO/10,0,0,0,0.6,0.8\n",
            "t.apt:4:1: CUTCOM/LEFT (line 4): the tool axis (0.000000, 0.600000, 0.800000) at line 5 is not +Z",
        ),
        (
            "FEDRAT/100\nGOTO/10,0,0\nCUTCOM/RIGHT\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,10,0\n",
            "t.apt:3:1: CUTCOM/RIGHT (line 3): the compensation would start on a circular move",
        ),
        (
            "FEDRAT/100\nGOTO/0,0,0\nCUTCOM/LEFT\nGOTO/10,0,0\nCUTCOM/OFF\nCIRCLE/10,10,0,0,0,1,10\nGOTO/20,10,0\n",
            "t.apt:5:1: CUTCOM/OFF (line 5): the compensation would end on a circular move",
        ),
        (
            "LOADTL/1\nFEDRAT/100\nGOTO/0,0,0\nCUTCOM/LEFT,5\nGOTO/10,0,0\n",
            "t.apt:4:1: CUTCOM/LEFT (line 4): offset register 5 is not the tool's (T1)",
        ),
        (
            "FEDRAT/100\nGOTO/0,0,10\nCYCLE/TAP,FEDTO,5,RAPTO,2\nGOTO/0,0,0\n",
            "t.apt:3:1: CYCLE/TAP: tapping with the spindle stopped",
        ),
        (
            "SPINDL/100,CLW\nFEDRAT/100\nGOTO/0,0,10\nCYCLE/DEEP,FEDTO,5,RAPTO,2,STEP,1,DWELL,1\nGOTO/0,0,0\n",
            "t.apt:4:1: CYCLE/DEEP: DWELL on a peck-drilling cycle",
        ),
        (
            "GOTO/0,0,0\n  GOTO/1,0,0\n",
            "t.apt:1:1: no feed for this move",
        ),
        (
            "RAPID\nGOTO/0,0,0\n  GOTO/1,0,0\n",
            "t.apt:3:3: no feed for this move",
        ),
        (
            "FEDRAT/100\nGOTO/0,0,0\n  THREAD/TURN,1.5\n",
            "t.apt:3:3: THREAD records are not posted",
        ),
        (
            "FEDRAT/100\nGOTO/0,0,0\nAUXFUN/88\n",
            "t.apt:3:1: AUXFUN records are not posted",
        ),
        (
            // A continuation line after a line that does not end with `$`.
            "FEDRAT/100\nGOTO/0,0,0\n0,0,1\n",
            "t.apt:3:1: '0,0,1' does not start with an APT record word",
        ),
        (
            // At the units record (issue: the refusal named no line).
            "PARTNO/X\n  UNITS/INCHES\nFEDRAT/1\nGOTO/0,0,0\n",
            "t.apt:2:3: the CL file is in inches (this record): inch output for Heidenhain",
        ),
        (
            // The repro without TRNTYP/WORLD: in which frame the GOTO is is not
            // stated.
            "CSYS/0,-1.,0,0,1.,0,0,0,0,0,1.,0\nFEDRAT/100\nGOTO/10.,0,5.,0,0,1.\n",
            "t.apt:1:1: CSYS other than the identity (setup tool axis (0, 0, 1)) without TRNTYP/WORLD",
        ),
        (
            "MSYS/0,0,0,1,0,0,0,1,0\nFEDRAT/100\nGOTO/0,0,0\nMSYS/0,0,50,1,0,0,0,1,0\nGOTO/0,0,0\n",
            "t.apt:4:1: MSYS names a machine coordinate system",
        ),
        (
            "FEDRAT/100\nGOTO/0,0,0\nTRACUT/1,0,0,10,0,1,0,0,0,0,1,0\nGOTO/1,0,0\n",
            "t.apt:3:1: TRACUT records are not posted",
        ),
    ] {
        let e = refused(text);
        assert!(e.contains(want), "{text}\n→ {e}\nwanted {want}");
    }
}

/// CAMWorks' setups (`fixtures/cl/camworks_setups.apt`: after `TRNTYP/WORLD`, a setup
/// turned 90° about Z, one moved by (−60, −20, 30) and one with the tool along +X): CAMWorks
/// writes world coordinates whatever the `CSYS`, so the program is the one posted from the
/// same file without its `TRNTYP`/`CSYS` records, every point is the GOTO as written, the
/// side setup is cut with the primary axis at ±90°, and the arcs (one in YZ) stay within
/// the tolerance. Before, `CSYS` was applied as part = R·v + t: the first setup posted
/// turned by 90°, the second moved, the third refused (tool axis −Z).
#[test]
fn camworks_setups_post_the_world_values_as_written() {
    let text = String::from_utf8(fixture("camworks_setups.apt")).unwrap();
    let bare: String = text
        .lines()
        .filter(|l| !l.starts_with("TRNTYP") && !l.starts_with("CSYS"))
        .map(|l| format!("{l}\n"))
        .collect();
    let cl = parse(text.as_bytes()).unwrap();
    let without = parse(bare.as_bytes()).unwrap();
    let key = |c: &ClProgram| -> Vec<_> {
        c.points()
            .map(|p| (p.pos_mm, p.axis, p.kind.clone()))
            .collect()
    };
    assert_eq!(key(&cl), key(&without));
    let side = cl
        .points()
        .find(|p| p.pos_mm == [120.0, 10.0, -15.0])
        .unwrap();
    assert_eq!(side.axis, [1.0, 0.0, 0.0]);
    for dialect in DIALECTS {
        let out = post(&cl, dialect, false, |_| {});
        assert_eq!(out, post(&without, dialect, false, |_| {}), "{dialect:?}");
        // The written points are the GOTOs (the first and the side setup's first cut).
        let moves: Vec<[Option<f64>; 4]> = out
            .lines()
            .map(|l| {
                let l = l.trim_end_matches(" *");
                [word(l, "X"), word(l, "Y"), word(l, "Z"), word(l, "A")]
            })
            // Moves (under TCPM every one states A); not the INSERT text `X120. Y40. Z30.`.
            .filter(|m| m.iter().all(Option::is_some))
            .collect();
        assert_eq!(
            moves[0][..3],
            [Some(-10.0), Some(5.0), Some(25.0)],
            "{dialect:?}\n{out}"
        );
        let cut = moves
            .iter()
            .find(|m| m[..3] == [Some(120.0), Some(10.0), Some(-15.0)])
            .unwrap_or_else(|| panic!("{dialect:?}\n{out}"));
        assert_eq!(cut[3].map(f64::abs), Some(90.0), "{dialect:?}: {cut:?}");
        let rounding = 3f64.sqrt() * 0.0005;
        let errs = arc_errors(&cl, &out);
        assert_eq!(errs.len(), 3, "{dialect:?}");
        for (a, worst, _) in errs {
            assert!(worst <= 0.001 + rounding, "{dialect:?}: {worst} from {a:?}");
        }
    }
}

/// The same checks on CL files from elsewhere (real CAM output is not committed):
/// `POLEPATCH_REAL_CL=DIR [POLEPATCH_REAL_CL_IGNORE=INSERT,…] [POLEPATCH_REAL_CL_UNIFORM_PECK=1]
/// cargo test -p polepatch --test post_cam real_cl_files -- --nocapture` posts every file of
/// DIR in the three dialects; a file is either refused (the reason is printed) or every hole
/// and arc passes the checks above. Skipped (with a message) without the variable.
#[test]
fn real_cl_files() {
    let Ok(dir) = std::env::var("POLEPATCH_REAL_CL") else {
        eprintln!("real_cl_files: skipped (set POLEPATCH_REAL_CL to a folder of CL files)");
        return;
    };
    let opts = polepatch::cl::ParseOptions {
        ignore: std::env::var("POLEPATCH_REAL_CL_IGNORE")
            .map(|v| v.split(',').map(str::to_string).collect())
            .unwrap_or_default(),
        uniform_peck: std::env::var("POLEPATCH_REAL_CL_UNIFORM_PECK").is_ok(),
    };
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    let (mut posted, mut refused, mut holes, mut arcs) = (0, 0, 0, 0);
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let cl = match polepatch::cl::parse_with(&std::fs::read(&f).unwrap(), &opts) {
            Ok(cl) => cl,
            Err(e) => {
                eprintln!("{name}: refused: {e}");
                refused += 1;
                continue;
            }
        };
        let mut ok = true;
        for dialect in DIALECTS {
            let o = PostOptions {
                dialect,
                units: (dialect == Dialect::Heidenhain).then_some(Units::Mm),
                ..PostOptions::default()
            };
            match post_cl(&cl, &ucp710(), &o) {
                Err(e) => {
                    eprintln!("{name} {dialect:?}: refused: {e}");
                    ok = false;
                    break;
                }
                Ok((bytes, _)) => {
                    let text = String::from_utf8(bytes).unwrap();
                    holes += check_holes(&cl, &text, dialect, &name);
                    let inch = text.contains("G20") || text.contains("G700");
                    let rounding = 3f64.sqrt() * if inch { 0.00127 } else { 0.0005 };
                    for (a, worst, _) in arc_errors(&cl, &text) {
                        assert!(
                            worst <= o.arc_tolerance_mm + rounding,
                            "{name} {dialect:?}: {worst} mm from {a:?}"
                        );
                        arcs += 1;
                    }
                }
            }
        }
        if ok {
            posted += 1;
        } else {
            refused += 1;
        }
    }
    eprintln!(
        "real_cl_files: {posted} posted in 3 dialects ({holes} holes, {arcs} arcs checked), {refused} refused"
    );
}

/// The tilted part of the NX file: the rotary axes go to P 0, C 0 under TCPM before a
/// vertical section, and the C after it continues from 0 (no jump of C in a feed move).
#[test]
fn holes_are_drilled_with_the_rotary_axes_at_zero() {
    let text = "MULTAX\nFEDRAT/500\nGOTO/0,0,20,0,0.1736482,0.9848078\nGOTO/0,0,30,0,0,1\n\
                CYCLE/DRILL,FEDTO,5,RAPTO,2\nGOTO/10,0,0,0,0,1\nCYCLE/OFF\nRAPID\nGOTO/10,0,30\n\
                GOTO/10,0,20,0,0.1736482,0.9848078\n";
    let cl = parse(text.as_bytes()).unwrap();
    let out = post(&cl, Dialect::Fanuc, false, |_| {});
    // Tilted (A10 C180), vertical with C held, C to 0 in place under TCPM, TCPM off, the
    // hole, TCPM on, and the tilt again continues from C 0 (A−10 C0, the same tool axis).
    assert!(
        out.contains(
            "G01 X0. Y0. Z20. A10. C180. F500.\nX0. Y0. Z30. A0. C180.\nG00 X0. Y0. Z30. A0. C0.\n\
             G49\nG43 H1\nG00 X10. Y0. Z30. A0. C0.\nX10. Y0. Z2. A0. C0.\n\
             G98 G81 X10. Y0. Z-5. R2. F500.\nG80\nG43.4 H1\nG00 X10. Y0. Z30. A0. C0.\n\
             G01 X10. Y0. Z20. A-10. C0. F500.\n"
        ),
        "{out}"
    );
}
