//! Issue 39: the written program held against its input (`polepatch::verify`), on every
//! fixture and on planted defects, and the ways a patch moved the tool against the part,
//! each on a fixture written in the style it was found in (`fixtures/verify/`), checked with
//! a reader and a forward kinematics written here.

mod common;
use polepatch::kinematics::Machine;
use polepatch::tool::{Tool, ToolOptions, ToolPoint};
use polepatch::verify::{Check, verify_nc};
use polepatch::{Outcome, PatchOptions, patch_nc};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fixture(rel: &str) -> Vec<u8> {
    let p = root().join("fixtures").join(rel);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn ucp710() -> Machine {
    Machine::builtin("mikron-ucp710").unwrap()
}

fn ball_at_tip() -> ToolOptions {
    ToolOptions {
        tool: Some(Tool::parse("ball:10").unwrap()),
        point: Some(ToolPoint::Tip),
        ..ToolOptions::default()
    }
}

fn opts(name: &str, tool: ToolOptions) -> PatchOptions {
    PatchOptions {
        tool,
        ..PatchOptions::named(name)
    }
}

/// One move of a program as this test reads it: the line, rapid or not, and X Y Z A C
/// after it (modal values carried).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Move {
    line: usize,
    rapid: bool,
    q: [f64; 5],
}

/// The moves of a Fanuc/G-code or Heidenhain conversational program: words X Y Z A C with
/// a number (`X0.5`, `X+0.5`), `G0`/`G00`/`FMAX` rapid and `G1`/`G01`/`L` feed; lines of
/// tool, blank and program definitions skipped. Independent of the library's reader.
fn moves(bytes: &[u8]) -> Vec<Move> {
    let text = String::from_utf8_lossy(bytes);
    let mut q: [Option<f64>; 5] = [None; 5];
    let mut rapid = true;
    let mut out = Vec::new();
    for (k, raw) in text.lines().enumerate() {
        let line = raw.split(['(', ';']).next().unwrap_or("");
        let up = line.to_ascii_uppercase();
        if ["TOOL", "BLK", "BEGIN", "END PGM", "FUNCTION", "CYCL"]
            .iter()
            .any(|w| up.contains(w))
        {
            continue;
        }
        let mut moved = false;
        for tok in up.split_whitespace() {
            let (letter, rest) = tok.split_at(1);
            if matches!(tok, "G0" | "G00" | "FMAX") {
                rapid = true;
            }
            if matches!(tok, "G1" | "G01" | "L") {
                rapid = false;
            }
            let Some(i) = "XYZAC".find(letter) else {
                continue;
            };
            if let Ok(v) = rest.parse::<f64>() {
                q[i] = Some(v);
                moved = true;
            }
        }
        if up.contains("FMAX") {
            rapid = true;
        }
        if moved && let [Some(x), Some(y), Some(z), Some(a), Some(c)] = q {
            out.push(Move {
                line: k + 1,
                rapid,
                q: [x, y, z, a, c],
            });
        }
    }
    out
}

/// G16 eq. 1, the UCP710's senses: the tool axis in the part frame.
fn tool_axis(a_deg: f64, c_deg: f64) -> [f64; 3] {
    let (a, c) = (a_deg.to_radians(), c_deg.to_radians());
    [c.sin() * a.sin(), -c.cos() * a.sin(), a.cos()]
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// A ball of radius `r_mm` at its tip: its centre at every feed move of `after` within 1 µm
/// plus the rounding of the written X Y Z (4 decimals) and rotary words (4) of `before`'s;
/// every positioning move's X Y Z target unchanged. Returns the moves whose values changed.
fn centres_and_targets_kept(before: &[u8], after: &[u8], r_mm: f64, what: &str) -> usize {
    let (b, a) = (moves(before), moves(after));
    assert_eq!(b.len(), a.len(), "{what}: the same moves");
    let rounding = 3f64.sqrt() * 0.5e-4 + r_mm * (2.0 * 0.5e-4f64).to_radians();
    let mut changed = 0;
    for (p, q) in b.iter().zip(&a) {
        assert_eq!((p.line, p.rapid), (q.line, q.rapid), "{what}");
        if p.q == q.q {
            continue;
        }
        changed += 1;
        let tip = |m: &Move| [m.q[0], m.q[1], m.q[2]];
        if p.rapid {
            assert!(
                dist(tip(p), tip(q)) <= 1e-9,
                "{what}: line {}: the positioning target moved from {:?} to {:?}",
                p.line,
                tip(p),
                tip(q)
            );
            continue;
        }
        let centre = |m: &Move| {
            let o = tool_axis(m.q[3], m.q[4]);
            [
                m.q[0] + r_mm * o[0],
                m.q[1] + r_mm * o[1],
                m.q[2] + r_mm * o[2],
            ]
        };
        let d = dist(centre(p), centre(q));
        assert!(
            d <= 1e-3 + rounding,
            "{what}: line {}: the ball's centre moved {d} mm",
            p.line
        );
    }
    changed
}

fn reached(report: &polepatch::FileReport, what: &str) {
    assert!(!report.zones.is_empty(), "{what}: no zone");
    for z in &report.zones {
        assert_eq!(z.outcome, Outcome::Reached, "{what}: {z:?}");
    }
}

/// Class 1: the block after the run that restates its last rotary values — a retract —
/// keeps its own X Y Z (it was written with the last point's: `G0 Z50. A… C…` became
/// `G0 Z-5.0002 …`, a crash at cutting depth), and the move after it that relied on the
/// run's last X Y gets them back.
#[test]
fn a_restated_retract_keeps_its_height() {
    for (f, what) in [
        (
            "verify/fanuc-g434-retract-restated.nc",
            "Fanuc G43.4, Fusion tool comment",
        ),
        (
            "verify/conv-retract-restated.H",
            "conversational FUNCTION TCPM, TOOL DEF",
        ),
    ] {
        let input = fixture(f);
        // The program's own tool (a D10 ball at its tip), and the same said on the command
        // line.
        for tool in [ToolOptions::default(), ball_at_tip()] {
            let (out, report) = patch_nc(&input, &ucp710(), &opts(f, tool)).unwrap();
            reached(&report, what);
            let changed = centres_and_targets_kept(&input, &out, 5.0, what);
            assert!(changed > 10, "{what}: {changed}");
            // The retract still rises to its height, restating the run's new last values.
            let text = String::from_utf8(out.clone()).unwrap();
            let retract = text
                .lines()
                .find(|l| (l.contains("Z50.") || l.contains("Z+100")) && l.contains('C'))
                .unwrap_or_else(|| panic!("{what}: no retract in\n{text}"));
            let last = moves(&out).into_iter().rfind(|m| !m.rapid).unwrap();
            let m = moves(&out)
                .into_iter()
                .find(|m| m.rapid && m.q[2] > 0.0 && m.line > last.line)
                .unwrap();
            assert_eq!(
                (m.q[3], m.q[4]),
                (last.q[3], last.q[4]),
                "{what}: {retract}"
            );
            let check = verify_nc(&input, &out, &ucp710(), &opts(f, ball_at_tip()), f).unwrap();
            assert!(check.passed(), "{what}: {:?}", check.violations);
        }
    }
}

/// Class 2: a bare preselect `T2` and a `TOOL CALL S10000` (a spindle speed) in the middle
/// of a near-pole pass end no run: the pass is patched as one (before, the runs on either
/// side were patched apart from the point they share, and the block between them turned C
/// 137.6° over 0.83 mm).
#[test]
fn a_preselect_or_a_speed_change_does_not_cut_the_pass() {
    for f in [
        "verify/fanuc-preselect-mid-pass.nc",
        "verify/conv-tool-call-speed-mid-pass.H",
    ] {
        let input = fixture(f);
        let (out, report) = patch_nc(&input, &ucp710(), &opts(f, ToolOptions::default())).unwrap();
        reached(&report, f);
        assert_eq!(report.zones.len(), 1, "{f}: one pass, one zone");
        let changed = centres_and_targets_kept(&input, &out, 5.0, f);
        assert!(changed > 10, "{f}: {changed}");
        // The written program, analysed: one run over the pass, at feed.
        let a =
            polepatch::analyze_nc(&out, &ucp710(), &polepatch::AnalyzeOptions::default()).unwrap();
        let pass = a
            .runs
            .iter()
            .find(|r| r.points > 50)
            .unwrap_or_else(|| panic!("{f}: the pass is cut: {:?}", a.runs));
        assert!(pass.figures.as_ref().unwrap().zones.is_empty(), "{f}");
    }
}

/// The patched output of `f` on `m` with `tool`, when the program fits the machine.
fn patched(f: &std::path::Path, m: &Machine, tool: &ToolOptions) -> Option<(Vec<u8>, Vec<u8>)> {
    let input = std::fs::read(f).unwrap();
    let name = f.display().to_string();
    match patch_nc(&input, m, &opts(&name, tool.clone())) {
        Ok((out, _)) => Some((input, out)),
        Err(polepatch::Error::ForeignAxis { .. }) => None,
        Err(e) => panic!("{name} on {}: {e}", m.name),
    }
}

/// Every fixture × both built-in machines × (the program's tool; a D10 ball at its tip):
/// the written output passes `verify` against its input.
#[test]
fn every_fixture_output_is_verified() {
    let files = polepatch_fixturegen::nc_files(&root().join("fixtures"));
    assert!(files.len() >= 100, "{}", files.len());
    let (mut checked, mut changed) = (0, 0);
    for f in &files {
        for m in common::machines() {
            for tool in [ToolOptions::default(), ball_at_tip()] {
                let Some((input, out)) = patched(f, &m, &tool) else {
                    continue;
                };
                let name = f.display().to_string();
                let check = verify_nc(&input, &out, &m, &opts(&name, tool), &name).unwrap();
                assert!(
                    check.passed(),
                    "{name} on {}: {:?}",
                    m.name,
                    check.violations
                );
                checked += 1;
                changed += usize::from(input != out);
            }
        }
    }
    assert!(
        checked >= 200 && changed >= 100,
        "{checked} checked, {changed} changed"
    );
}

/// `text` with line `line` (1-based) replaced by `with(old)`.
fn edit_line(text: &str, line: usize, with: impl Fn(&str) -> String) -> String {
    text.split_inclusive('\n')
        .enumerate()
        .map(|(k, l)| {
            if k + 1 == line {
                let body = l.trim_end_matches('\n');
                format!("{}\n", with(body))
            } else {
                l.to_string()
            }
        })
        .collect()
}

/// The 1-based line of the first line of `text` that `pick` takes.
fn line_where(text: &str, pick: impl Fn(&str) -> bool) -> usize {
    text.lines().position(pick).unwrap() + 1
}

/// The checks that fail on `planted` against `input`, with their lines.
fn fails(input: &[u8], planted: &str, o: &PatchOptions) -> Vec<(usize, Check)> {
    let r = verify_nc(input, planted.as_bytes(), &ucp710(), o, "input").unwrap();
    r.violations.iter().map(|v| (v.line, v.check)).collect()
}

/// Planted defects in a verified output are refused by name, at their line: a retract
/// lowered, one X of a patched block moved 0.01 mm with a ball at its tip, a feed word
/// changed, one block of the pass moved to the other branch ((A, C) → (−A, C + 180°): the
/// same tool axis, a table swing), a rotary kink where nothing was patched, a deleted line.
#[test]
fn planted_defects_are_refused_at_their_line() {
    let f = "verify/fanuc-g434-retract-restated.nc";
    let input = fixture(f);
    let o = opts(f, ball_at_tip());
    let (out, _) = patch_nc(&input, &ucp710(), &o).unwrap();
    let out = String::from_utf8(out).unwrap();
    assert!(fails(&input, &out, &o).is_empty());

    // A retract lowered.
    let l = line_where(&out, |l| l.starts_with("G0 ") && l.contains("Z50."));
    let t = edit_line(&out, l, |s| s.replace("Z50.", "Z-4."));
    assert!(
        fails(&input, &t, &o).contains(&(l, Check::PositioningTarget)),
        "{:?}",
        fails(&input, &t, &o)
    );

    // One X of a patched block moved 0.01 mm.
    let l = line_where(&out, |l| l.starts_with("X25.") || l.starts_with("X24.9"));
    let t = edit_line(&out, l, |s| {
        let (x, rest) = s[1..].split_once(' ').unwrap();
        format!("X{:.4} {rest}", x.parse::<f64>().unwrap() + 0.01)
    });
    assert!(
        fails(&input, &t, &o).contains(&(l, Check::ReferencePoint)),
        "{:?}",
        fails(&input, &t, &o)
    );

    // A feed word changed.
    let l = line_where(&out, |l| l.contains("F3000"));
    let t = edit_line(&out, l, |s| s.replace("F3000", "F2500"));
    let got = fails(&input, &t, &o);
    assert!(
        got.contains(&(l, Check::Text)) && got.contains(&(l, Check::State)),
        "{got:?}"
    );

    // One block far from the pole moved to the other branch: the same tool axis.
    let l = line_where(&input_text(&input), |l| l.starts_with("X5 "));
    let t = edit_line(&out, l, |s| {
        let w: Vec<&str> = s.split_whitespace().collect();
        let a: f64 = w[1][1..].parse().unwrap();
        let c: f64 = w[2][1..].parse().unwrap();
        format!("{} A{:.3} C{:.3}", w[0], -a, c + 180.0)
    });
    let got = fails(&input, &t, &o);
    // Read as written, Equation 6 fails. Where C swings more than half a turn into the
    // block (C + 180.06° here), on the UCP710's endless C that is a wrap (issue 42) which no
    // run spans: the runs no longer pair with the input's, and the block itself turns the
    // tool axis away as it goes — refused at its line.
    assert!(
        got.iter().any(|&(_, c)| c == Check::FeedRatio)
            || (got.contains(&(l, Check::Deviation))
                && got.iter().any(|&(_, c)| c == Check::RunStructure)),
        "{got:?}"
    );

    // A rotary kink where nothing was patched: C 2° off at one block of the approach side.
    let l = line_where(&input_text(&input), |l| l.starts_with("X2 "));
    let t = edit_line(&out, l, |s| {
        let w: Vec<&str> = s.split_whitespace().collect();
        let c: f64 = w[2][1..].parse().unwrap();
        format!("{} {} C{:.3}", w[0], w[1], c + 2.0)
    });
    let got = fails(&input, &t, &o);
    assert!(
        got.iter()
            .any(|&(_, c)| c == Check::FeedRatio || c == Check::ReferencePoint),
        "{got:?}"
    );

    // A deleted line.
    let l = line_where(&out, |l| l.starts_with("X10 ") || l.starts_with("X10."));
    let t: String = out
        .split_inclusive('\n')
        .enumerate()
        .filter(|(k, _)| k + 1 != l)
        .map(|(_, s)| s)
        .collect();
    assert_eq!(fails(&input, &t, &o), vec![(l, Check::Lines)]);
}

fn input_text(b: &[u8]) -> String {
    String::from_utf8(b.to_vec()).unwrap()
}

/// A lead-out at cutting depth under TCPM without rotary words (`G1 X35. D1`, which ends
/// the run) carries the last point's orientation along the part: the tip's path is the same
/// from either pose, but a ball at its tip moves its centre (15 µm here). Its end is kept
/// (`EndPose::carried_xy`); before, the written program's check found it and put the zone
/// back (the put-back itself: the unit test `stream::tests`).
#[test]
fn a_lead_out_at_cutting_depth_keeps_a_ball_runs_end() {
    let f = "verify/fanuc-g434-retract-restated.nc";
    let text = input_text(&fixture(f));
    let l = line_where(&text, |l| l.starts_with("G0 Z50.") && l.contains('C'));
    let planted = edit_line(&text, l, |s| format!("G1 X35. D1\n{s}"));
    let o = opts(f, ball_at_tip());
    let (out, report) = patch_nc(planted.as_bytes(), &ucp710(), &o).unwrap();
    for z in &report.zones {
        assert_eq!(z.end_pose, Some(polepatch::EndFreedom::Pinned), "{z:?}");
        assert_ne!(z.reason, polepatch::ZoneReason::Verification, "{z:?}");
    }
    centres_and_targets_kept(planted.as_bytes(), &out, 5.0, f);
    let check = verify_nc(planted.as_bytes(), &out, &ucp710(), &o, f).unwrap();
    assert!(check.passed(), "{:?}", check.violations);
}

/// `reached` is a claim about the zone's core (`core_lines`), not the patch's whole range:
/// a slowness of the program's own inside the range but outside the core (NX's Haas UMC-750
/// program, `nx_haas_umc750_g234.txt`: a 0.004 mm block turning C 2.8°, 0.888 of the feed
/// in input and output) is the program's, held only to "no worse" by the Equation-6 check of
/// the run. Planted in the input and the output alike, at the same line: the claim on the
/// core holds, the same claim over the whole range is refused at that block.
#[test]
fn reached_is_claimed_over_the_zone_core() {
    use polepatch::verify::{Claim, verify_claims};
    let f = "ac-flip-d0.5-fanuc-g94.nc";
    let input = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures/shop")
            .join(f),
    )
    .unwrap();
    let m = ucp710();
    let o = opts(f, ToolOptions::default());
    let (out, report) = patch_nc(input.as_bytes(), &m, &o).unwrap();
    let z = &report.zones[0];
    assert_eq!(z.outcome, Outcome::Reached);
    let (lines, core) = (z.lines, z.core_lines);
    assert!(
        lines[0] < core[0] && core[1] < lines[1],
        "{lines:?} {core:?}"
    );
    // The program's own kink: a block 0.004 mm long turning C by 2.8° and back, four lines
    // after the range's first, in both programs (the output keeps the patch's values around
    // it, so the block's neighbours are each program's own).
    let at = lines[0] + 3;
    let plant = |text: &str| {
        let mut l: Vec<String> = text.lines().map(str::to_string).collect();
        let (x, a, c) = {
            let w: Vec<&str> = l[at - 1].split_whitespace().collect();
            let v = |p: char| {
                w.iter().find(|s| s.starts_with(p)).unwrap()[1..]
                    .parse::<f64>()
                    .unwrap()
            };
            (v('X'), v('A'), v('C'))
        };
        l[at - 1] = format!("X{:.3} A{a} C{:.3}", x - 0.004, c + 2.8);
        l.insert(at, format!("X{x} A{a} C{c}"));
        l.join("\n") + "\n"
    };
    let (pi, po) = (plant(&input), plant(&String::from_utf8(out).unwrap()));
    let claim = |lines: [usize; 2]| Claim {
        lines,
        both_axes: true,
    };
    let on_core = verify_claims(pi.as_bytes(), po.as_bytes(), &m, &o, f, &[claim(core)]).unwrap();
    assert!(on_core.passed(), "{:?}", on_core.violations);
    let over_range = verify_claims(
        pi.as_bytes(),
        po.as_bytes(),
        &m,
        &o,
        f,
        &[claim([lines[0], lines[1] + 1])],
    )
    .unwrap();
    assert!(
        over_range
            .violations
            .iter()
            .any(|v| v.check == Check::ReportedReached),
        "{:?}",
        over_range.violations
    );
}
