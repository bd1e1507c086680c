//! Issue 27's checks, through the library: the cutter is kept where CAM put it.
//!
//! - `fixtures/c17/SING.I` (an `M128` program) on the UCP710 with a D10 ball at its tip:
//!   every zone reaches feed, X Y Z change only on points whose orientation changed, and
//!   every written block's ball centre (tip + R·o, o from the forward kinematics of the
//!   written A C) is within 0.001 mm plus the written rounding of the original centre;
//!   without a tool point (`M128`: the centre) X Y Z are byte-identical.
//! - Heidenhain conversational `FUNCTION TCPM … REFPNT CENTER-CENTER`: X Y Z unchanged;
//!   `REFPNT TIP-TIP`: the centres kept.
//! - The CAMWorks APT file (`CUTTER/10,5,…`) posted with the patch: the centres kept.
//! - A flat D10: every written point within the surface bound; zones that needed more
//!   report `tool_limited` with the deviation they needed.
//! - Each tool-source reader on its fixture: the kind, diameter, corner radius and line.

use polepatch::kinematics::{Machine, forward};
use polepatch::post::{PostOptions, post_cl, read_cl, tool_from_cl};
use polepatch::tool::{SURFACE_TOLERANCE_MM, Tool, ToolKind, ToolOptions, ToolPoint};
use polepatch::{FileReport, PatchOptions, ZoneTool, patch_nc};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fixture(rel: &str) -> Vec<u8> {
    std::fs::read(root().join(rel)).unwrap()
}

fn ucp710() -> Machine {
    Machine::builtin("mikron-ucp710").unwrap()
}

fn with_tool(tool: Option<&str>, point: Option<ToolPoint>) -> PatchOptions {
    PatchOptions {
        tool: ToolOptions {
            tool: tool.map(|t| Tool::parse(t).unwrap()),
            point,
            ..ToolOptions::default()
        },
        ..PatchOptions::default()
    }
}

/// One axis word of a line: its value and its decimals.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Word {
    value: f64,
    decimals: u32,
}

/// A move under TCPM: its file line, X Y Z A C in force (with the words that last set
/// them), and the text of its X Y Z words.
#[derive(Debug, Clone)]
struct Point {
    line: usize,
    axes: [Word; 5],
    xyz_text: Vec<String>,
    other_text: Vec<String>,
    /// A rapid move (`FMAX`, `G0`): no cut.
    rapid: bool,
}

/// The moves between the TCPM switch (`M128`, `FUNCTION TCPM`, `G43.4`) and its end of a
/// Heidenhain program (ISO or conversational) or a Fanuc-style one, read word by word: a
/// small reader of the fixtures' forms, independent of the library's.
fn points(text: &str) -> Vec<Point> {
    let mut on = false;
    let mut axes: [Option<Word>; 5] = [None; 5];
    let mut out = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let up = line.to_ascii_uppercase();
        if up.contains("M129") || up.contains("RESET TCPM") || up.contains("G49") {
            on = false;
            continue;
        }
        if up.contains("M128") || up.contains("FUNCTION TCPM") || up.contains("G43.4") {
            on = true;
            continue;
        }
        if !on || up.contains("G54") || up.contains("TOOL") {
            continue;
        }
        let mut moved = false;
        let mut xyz_text = Vec::new();
        let mut other_text = Vec::new();
        for tok in line.split_whitespace() {
            let Some(letter) = tok.chars().next() else {
                continue;
            };
            let rest = &tok[1..];
            let slot = "XYZAC".find(letter.to_ascii_uppercase());
            let number = rest.starts_with(['+', '-', '.']) || rest.starts_with(char::is_numeric);
            match (slot, number, rest.parse::<f64>()) {
                (Some(i), true, Ok(value)) => {
                    let decimals = rest.split_once('.').map_or(0, |(_, d)| d.len() as u32);
                    axes[i] = Some(Word { value, decimals });
                    moved = true;
                    if i < 3 {
                        xyz_text.push(tok.to_string());
                    }
                }
                _ => other_text.push(tok.to_string()),
            }
        }
        if moved && let [Some(x), Some(y), Some(z), Some(a), Some(c)] = axes {
            let rapid =
                up.contains("FMAX") || up.split_whitespace().any(|w| w == "G0" || w == "G00");
            out.push(Point {
                line: k + 1,
                axes: [x, y, z, a, c],
                xyz_text,
                other_text,
                rapid,
            });
        }
    }
    out
}

fn centre(m: &Machine, p: &Point, radius: f64) -> [f64; 3] {
    let o = forward(m, p.axes[3].value, p.axes[4].value);
    std::array::from_fn(|i| p.axes[i].value + radius * o[i])
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// The angle between the tool axes of two points, degrees.
fn turn_deg(m: &Machine, a: &Point, b: &Point) -> f64 {
    let (oa, ob) = (
        forward(m, a.axes[3].value, a.axes[4].value),
        forward(m, b.axes[3].value, b.axes[4].value),
    );
    let dot: f64 = (0..3).map(|i| oa[i] * ob[i]).sum();
    dot.clamp(-1.0, 1.0).acos().to_degrees()
}

/// How far the written rounding of X Y Z may move a point: half a unit of the last decimal
/// the patch writes them with (the most decimals of a rewritten X Y Z word), per axis.
fn xyz_rounding(before: &[Point], after: &[Point]) -> f64 {
    let decimals = |p: &Point| {
        p.xyz_text
            .iter()
            .map(|w| w.split_once('.').map_or(0, |(_, d)| d.len() as i32))
            .max()
            .unwrap_or(0)
    };
    let d = before
        .iter()
        .zip(after)
        .filter(|(p, q)| p.xyz_text != q.xyz_text)
        .map(|(_, q)| decimals(q))
        .chain(after.iter().map(decimals))
        .max()
        .unwrap_or(0);
    3f64.sqrt() * 0.5 * 10f64.powi(-d)
}

/// The same moves before and after, one to one.
fn pairs(before: &[u8], after: &[u8]) -> (Vec<Point>, Vec<Point>) {
    let (b, a) = (
        points(&String::from_utf8_lossy(before)),
        points(&String::from_utf8_lossy(after)),
    );
    assert_eq!(b.len(), a.len(), "the same moves");
    assert!(b.len() > 10, "{} moves", b.len());
    for (p, q) in b.iter().zip(&a) {
        assert_eq!(p.line, q.line);
    }
    (b, a)
}

/// A ball at its tip: X Y Z change only where the orientation changed, and every written
/// centre of a cutting move is within 0.001 mm plus the written rounding of the original.
/// Returns how many points turned and the largest centre error, mm. (A rapid retract after
/// the run — `L Z+100 R0 FMAX` — keeps its own Z and the modal X Y of the rewritten last
/// point: its centre may move by R·|Δo|, above the part; it is not checked.)
fn centres_kept(m: &Machine, before: &[u8], after: &[u8], radius: f64, what: &str) -> (usize, f64) {
    centres_kept_in(m, before, after, radius, what, 0..=usize::MAX)
}

/// [`centres_kept`] on the moves whose lines are in `lines`.
fn centres_kept_in(
    m: &Machine,
    before: &[u8],
    after: &[u8],
    radius: f64,
    what: &str,
    lines: std::ops::RangeInclusive<usize>,
) -> (usize, f64) {
    let (b, a) = pairs(before, after);
    let rounding = xyz_rounding(&b, &a);
    let mut turned = 0;
    let mut worst: f64 = 0.0;
    for (p, q) in b.iter().zip(&a).filter(|(p, _)| lines.contains(&p.line)) {
        let turn = turn_deg(m, p, q);
        if turn > 0.0 {
            turned += 1;
        }
        let xyz_same = (0..3).all(|i| p.axes[i].value == q.axes[i].value);
        assert!(
            xyz_same || turn > 0.0,
            "{what}: line {}: X Y Z changed ({:?} → {:?}) but the orientation did not",
            p.line,
            p.xyz_text,
            q.xyz_text
        );
        if p.rapid {
            continue;
        }
        let err = dist(centre(m, p, radius), centre(m, q, radius));
        worst = worst.max(err);
        let limit = 0.001 + rounding;
        assert!(
            err <= limit,
            "{what}: line {}: the ball's centre moved {err} mm (limit {limit} mm)",
            p.line
        );
    }
    (turned, worst)
}

/// X Y Z words byte-identical, lines otherwise differing only in rotary words.
fn xyz_identical(before: &[u8], after: &[u8], what: &str) {
    let (b, a) = pairs(before, after);
    for (p, q) in b.iter().zip(&a) {
        assert_eq!(p.xyz_text, q.xyz_text, "{what}: line {}", p.line);
        assert_eq!(p.other_text, q.other_text, "{what}: line {}", p.line);
    }
    let (bt, at) = (
        String::from_utf8_lossy(before).into_owned(),
        String::from_utf8_lossy(after).into_owned(),
    );
    assert_eq!(
        bt.lines().count(),
        at.lines().count(),
        "{what}: no line added"
    );
}

fn all_reached(report: &FileReport, what: &str) {
    assert!(!report.zones.is_empty(), "{what}: zones");
    for z in &report.zones {
        assert_eq!(
            z.outcome,
            polepatch::Outcome::Reached,
            "{what}: {:?} {}",
            z.lines,
            z.reason
        );
        assert!(z.after.c_ratio >= 1.0 - 1e-9 && z.after.primary_ratio >= 1.0 - 1e-9);
    }
}

#[test]
fn sing_with_a_ball_at_its_tip_keeps_the_centre() {
    let m = ucp710();
    let input = fixture("fixtures/c17/SING.I");
    let opts = with_tool(Some("ball:10"), Some(ToolPoint::Tip));
    let (out, report) = patch_nc(&input, &m, &opts).unwrap();
    all_reached(&report, "SING ball:10 tip");
    let (turned, worst) = centres_kept(&m, &input, &out, 5.0, "SING ball:10 tip");
    assert!(turned > 10, "{turned} points turned");
    // X Y Z did change (else the check above says nothing).
    assert_ne!(points(&String::from_utf8_lossy(&out))[20].xyz_text, {
        let b = points(&String::from_utf8_lossy(&input));
        b[20].xyz_text.clone()
    });
    for z in &report.zones {
        assert_eq!(
            (z.tool.to_string(), z.tool_point.map(ToolPoint::name)),
            ("ball D10".to_string(), Some("tip"))
        );
        assert_eq!(z.tool_source, "--tool");
        assert_eq!(z.tool_point_source, "--tool-point");
        let shift = z.max_cutter_shift_mm.unwrap();
        assert!(shift <= 0.001 + 0.5e-3 * 3f64.sqrt(), "{shift}");
        let chord = z.centre_chord_mm.unwrap();
        assert!(chord <= opts.chord_tolerance_mm + 1e-3, "{chord}");
    }
    println!("SING ball:10 tip: {turned} points turned, largest centre error {worst:.6} mm");
}

#[test]
fn sing_with_m128_keeps_x_y_z() {
    let m = ucp710();
    let input = fixture("fixtures/c17/SING.I");
    for (what, opts) in [
        ("ball:10", with_tool(Some("ball:10"), None)),
        ("no tool", PatchOptions::default()),
    ] {
        let (out, report) = patch_nc(&input, &m, &opts).unwrap();
        all_reached(&report, what);
        assert_ne!(out, input, "{what}: patched");
        xyz_identical(&input, &out, what);
        for z in &report.zones {
            assert_eq!(
                z.tool_point,
                Some(polepatch::tool::ToolPoint::Centre),
                "{what}"
            );
            assert!(
                z.tool_point_source.contains("M128"),
                "{}",
                z.tool_point_source
            );
        }
    }
}

#[test]
fn refpnt_center_center_keeps_x_y_z_and_tip_tip_the_centre() {
    let m = ucp710();
    let centre_file = fixture("fixtures/tools/ac-swing-d1-conv-refpnt-centre.H");
    let (out, report) = patch_nc(&centre_file, &m, &PatchOptions::default()).unwrap();
    assert_ne!(out, centre_file, "CENTER-CENTER: patched");
    xyz_identical(&centre_file, &out, "REFPNT CENTER-CENTER");
    for z in report.zones.iter().filter(|z| z.max_deviation_deg > 0.0) {
        assert_eq!(
            (z.tool.to_string(), z.tool_point.map(ToolPoint::name)),
            ("ball D10".to_string(), Some("centre"))
        );
        assert!(
            z.tool_source.starts_with("line 4: 3 TOOL DEF 1"),
            "{}",
            z.tool_source
        );
    }

    let tip_file = fixture("fixtures/tools/ac-swing-d1-conv-refpnt-tip.H");
    let (out, report) = patch_nc(&tip_file, &m, &PatchOptions::default()).unwrap();
    all_reached(&report, "REFPNT TIP-TIP");
    let (turned, worst) = centres_kept(&m, &tip_file, &out, 5.0, "REFPNT TIP-TIP");
    assert!(turned > 0, "TIP-TIP: the orientation changed somewhere");
    assert!(
        points(&String::from_utf8_lossy(&out))
            .iter()
            .zip(points(&String::from_utf8_lossy(&tip_file)))
            .any(|(a, b)| a.xyz_text != b.xyz_text),
        "TIP-TIP: X Y Z rewritten"
    );
    for z in report.zones.iter().filter(|z| z.max_deviation_deg > 0.0) {
        assert_eq!(
            (z.tool.to_string(), z.tool_point.map(ToolPoint::name)),
            ("ball D10".to_string(), Some("tip"))
        );
    }
    println!("REFPNT TIP-TIP: {turned} points turned, largest centre error {worst:.6} mm");
}

#[test]
fn the_camworks_apt_posted_with_the_patch_keeps_the_centres() {
    let m = ucp710();
    let name = "fixtures/tools/camworks_ball_swing.apt";
    let bytes = fixture(name);
    let cl = read_cl(&bytes, name).unwrap();
    let post = |patch: bool| {
        let mut opts = PostOptions {
            patch,
            ..PostOptions::default()
        };
        tool_from_cl(&bytes, &cl, &mut opts);
        // The CL file's cutter is the program's, not a tool for the whole program.
        assert_eq!(opts.patch_options.tool.tool, None);
        assert_eq!(opts.patch_options.tool.point, Some(ToolPoint::Tip));
        post_cl(&cl, &m, &opts).unwrap()
    };
    let (raw, none) = post(false);
    assert!(none.is_none());
    let (patched, report) = post(true);
    let report = report.unwrap();
    assert_ne!(raw, patched, "the swing is patched");
    all_reached(&report, "CAMWorks APT");
    let (turned, worst) = centres_kept(&m, &raw, &patched, 5.0, "CAMWorks APT");
    assert!(turned > 0);
    for z in report.zones.iter().filter(|z| z.max_deviation_deg > 0.0) {
        assert_eq!(
            (z.tool.to_string(), z.tool_point.map(ToolPoint::name)),
            ("ball D10".to_string(), Some("tip"))
        );
        assert!(
            z.tool_source
                .starts_with("CL line 9: CUTTER/10.000000,5.000000"),
            "{}",
            z.tool_source
        );
    }
    // And against the CL file itself: each posted tip + R·o is the GOTO's tip + R·(i j k)
    // within the post's rounding (3 decimals) and 0.001 mm.
    let gotos: Vec<[f64; 6]> = String::from_utf8_lossy(&bytes)
        .lines()
        .filter_map(|l| l.strip_prefix("GOTO/"))
        .map(|r| {
            let v: Vec<f64> = r.split(',').map(|x| x.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4], v[5]]
        })
        .collect();
    let written = points(&String::from_utf8_lossy(&patched));
    let rounding = xyz_rounding(&written, &written);
    let near = |c: [f64; 3]| {
        gotos
            .iter()
            .map(|g| dist(c, std::array::from_fn(|i| g[i] + 5.0 * g[i + 3])))
            .fold(f64::INFINITY, f64::min)
    };
    for p in written.iter().filter(|p| !p.rapid) {
        let e = near(centre(&m, p, 5.0));
        assert!(
            e <= 0.001 + rounding,
            "line {}: {e} mm from every CL centre",
            p.line
        );
    }
    println!("CAMWorks APT: {turned} points turned, largest centre error {worst:.6} mm");
}

/// A flat D10: every written point's end moves at most the surface tolerance (from the
/// written A C: 2·R·sin(δ/2), R = 5 mm the largest distance of its end from the tip); the
/// zones that needed more say `tool_limited` and how much they needed.
#[test]
fn a_flat_end_mill_stays_within_the_surface_bound() {
    let m = ucp710();
    for rel in [
        "fixtures/c17/SING.I",
        "fixtures/tools/fusion-ac-swing-d0.5-flat.nc",
    ] {
        let input = fixture(rel);
        for tol in [SURFACE_TOLERANCE_MM, 0.05] {
            let mut opts = with_tool(Some("flat:10"), None);
            opts.tool.surface_tolerance_mm = tol;
            let (out, report) = patch_nc(&input, &m, &opts).unwrap();
            let mut limited = 0;
            for z in &report.zones {
                assert_eq!(z.tool.to_string(), "flat D10");
                let shift = z.max_cutter_shift_mm.unwrap();
                assert!(shift <= tol * (1.0 + 1e-9), "{rel} {tol}: {shift}");
                if z.reason == polepatch::ZoneReason::ToolLimited {
                    limited += 1;
                    let needed = z.needed_deviation_deg.expect("the deviation needed");
                    let cap =
                        polepatch::tool::deviation_cap_deg(&Tool::parse("flat:10").unwrap(), tol);
                    assert!(needed > cap, "{rel}: needed {needed}° ≤ cap {cap}°");
                    assert_ne!(z.outcome, polepatch::Outcome::Reached);
                }
            }
            if tol == SURFACE_TOLERANCE_MM {
                assert!(limited > 0, "{rel}: a 0.057° cap stops these zones");
            }
            // The written values: no point turned by more than the cap allows (the
            // written rotary rounding, ≤ 0.5·10⁻⁶° at 6 decimals, aside).
            if rel.ends_with("SING.I") {
                let (b, a) = pairs(&input, &out);
                for (p, q) in b.iter().zip(&a) {
                    let moved = 2.0 * 5.0 * (turn_deg(&m, p, q).to_radians() / 2.0).sin();
                    assert!(moved <= tol + 1e-6, "{rel}: line {}: {moved} mm", p.line);
                    assert_eq!(p.xyz_text, q.xyz_text, "a flat end mill's X Y Z stay");
                }
            }
        }
    }
}

/// Each reader of a tool's description, on the fixture written in its style: the kind,
/// the diameter, the corner radius and the line it came from.
#[test]
fn each_tool_source_on_its_fixture() {
    let m = ucp710();
    let cases: [(&str, ToolKind, f64, f64, &str); 15] = [
        (
            "fusion-ac-swing-d0.5-ball.nc",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 3: (T1  D=10. CR=5.",
        ),
        (
            "fusion-ac-swing-d0.5-flat.nc",
            ToolKind::Flat,
            12.0,
            0.0,
            "line 4: (T2  D=12. CR=0.",
        ),
        (
            "mastercam-ac-swing-d0.5-ball.nc",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 3: ( TOOL - 1  10MM BALL ENDMILL",
        ),
        (
            "nx-ac-swing-d0.5-ball.nc",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 4: (   1       BALL_MILL_D10",
        ),
        (
            "powermill-ac-swing-d0.5-ball.nc",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 4: (",
        ),
        (
            "hypermill-ac-swing-d1-bull.H",
            ToolKind::Bull,
            10.0,
            2.0,
            "line 4: 3 * - TOOL: T1554880489 | TGT-VLM10-R2 / DM=10 CR=2",
        ),
        (
            "ac-swing-d1-conv-refpnt-tip.H",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 4: 3 TOOL DEF 1 L+0 R+5 R2+5",
        ),
        (
            "ac-swing-d1-conv-refpnt-centre.H",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 4: 3 TOOL DEF 1 L+0 R+5 R2+5",
        ),
        // Issue 42's forms.
        (
            "cuq-ac-swing-d0.5-ball.nc",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 2: N2(Ball cutter D=10.00)",
        ),
        (
            "mastercam-pipe-ac-swing-d0.5-ball.nc",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 5: ( T1 | 10. BALL ENDMILL | H1 | D1 | TOOL DIA. - 10. )",
        ),
        (
            "tooldia-ac-swing-d0.5-flat.nc",
            ToolKind::Flat,
            10.0,
            0.0,
            "line 3: ( TOOL: T1 = 10.0 dia. ENDMILLM1000:REG )",
        ),
        (
            "hypermill-toollist-ac-swing-d1-ball.H",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 9: 3 * - T313732062 | KUG-D10-L90 / DM=10 CR=5",
        ),
        // Issue 39's.
        (
            "fusion-inch-ac-swing-d0.5-ball.nc",
            ToolKind::Ball,
            12.7,
            6.35,
            "line 3: (T1  D=0.5 CR=0.25",
        ),
        (
            "conv-tooldef-no-r2-flat.H",
            ToolKind::Flat,
            10.0,
            0.0,
            "line 4: 3 TOOL DEF 1 L+0 R+5",
        ),
        (
            "conv-toolcall-speed-only.H",
            ToolKind::Ball,
            10.0,
            5.0,
            "line 4: 3 TOOL DEF 1 L+0 R+5 R2+5",
        ),
    ];
    for (file, kind, d, r, source) in cases {
        let rel = format!("fixtures/tools/{file}");
        let (_, report) = patch_nc(&fixture(&rel), &m, &PatchOptions::default()).unwrap();
        let want = Tool {
            kind,
            diameter_mm: d,
            corner_radius_mm: r,
        };
        assert!(!report.zones.is_empty(), "{file}: zones");
        for z in &report.zones {
            let ZoneTool::Known(got) = z.tool else {
                panic!("{file}: no tool: {}", z.tool_source);
            };
            assert!(got.same_as(&want), "{file}: {got:?}, {}", z.tool_source);
            assert!(
                z.tool_source.starts_with(source),
                "{file}: source {:?}, expected {source:?}…",
                z.tool_source
            );
        }
        assert_eq!(report.zones_with_unknown_tool(), 0, "{file}");
    }
    // APT CUTTER (read by `post`), for the tool its LOADTL loads.
    let apt = fixture("fixtures/tools/camworks_ball_swing.apt");
    let tools = polepatch::tool::cl_tools(&read_cl(&apt, "camworks_ball_swing.apt").unwrap());
    let (tool, source) = tools.by_tool[&1].clone();
    assert_eq!(tool, Some(Tool::parse("ball:10").unwrap()));
    assert!(
        source.starts_with("CL line 9: CUTTER/10.000000,5.000000"),
        "{source}"
    );
}

/// No tool given and none in the program: the report says unknown, every changed zone
/// gives its centre shift per mm of radius (2·sin(δ/2)), one warning, a strict failure.
#[test]
fn an_unknown_tool_is_never_silent() {
    let m = ucp710();
    let (_, report) = patch_nc(
        &fixture("fixtures/c17/SING.I"),
        &m,
        &PatchOptions::default(),
    )
    .unwrap();
    let changed: Vec<_> = report
        .zones
        .iter()
        .filter(|z| z.max_deviation_deg > 0.0)
        .collect();
    assert!(!changed.is_empty());
    for z in &changed {
        assert_eq!(z.tool, polepatch::ZoneTool::Unknown);
        assert!(z.tool_source.contains("T5"), "{}", z.tool_source);
        let want = 2.0 * (z.max_deviation_deg.to_radians() / 2.0).sin();
        assert!((z.centre_shift_per_mm_radius - want).abs() < 1e-12);
        assert_eq!(z.max_cutter_shift_mm, None);
    }
    assert_eq!(report.zones_with_unknown_tool(), changed.len());
    assert!(report.strict_failures() >= changed.len());
    let warnings: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("the tool is not known"))
        .collect();
    assert_eq!(warnings.len(), 1, "{:?}", report.warnings);
    assert!(warnings[0].contains("--tool ball:D"), "{}", warnings[0]);
}

/// The centre between the points, on a case built to exceed the chord tolerance: a D50
/// ball at its tip on SING, whose centre path between the 1 mm-spaced points leaves the
/// original's line by 2.9 µm (`centre_chord_mm`), against a chord tolerance of 1 µm
/// (limit 1 + 1 µm of rounding room). The run is solved again with its orientation change
/// capped; whatever is written keeps the centre path within the limit, and a zone that
/// could not be brought to feed that way reports `centre_path` (the run keeps its values
/// where no capped solve kept the path: `untouched_runs` says why). With the default 5 µm
/// it is written and reaches feed.
#[test]
fn a_centre_path_beyond_the_chord_tolerance_is_not_written() {
    let m = ucp710();
    let input = fixture("fixtures/c17/SING.I");
    let mut opts = with_tool(Some("ball:50"), Some(ToolPoint::Tip));
    let (_, written) = patch_nc(&input, &m, &opts).unwrap();
    let chord = written.zones[0].centre_chord_mm.unwrap();
    assert!(chord > 0.0025 && chord < 0.004, "{chord}");
    all_reached(&written, "ball:50, default chord tolerance");

    opts.chord_tolerance_mm = 0.001;
    let (out, report) = patch_nc(&input, &m, &opts).unwrap();
    assert!(!report.zones.is_empty());
    for z in &report.zones {
        assert_eq!(z.reason, polepatch::ZoneReason::CentrePath, "{z:?}");
        assert_ne!(z.outcome, polepatch::Outcome::Reached, "{z:?}");
        assert!(
            z.centre_chord_mm.is_none_or(|c| c <= 0.002 + 1e-12),
            "written beyond the limit: {z:?}"
        );
    }
    if let Some(u) = report.untouched_runs.first() {
        assert_eq!(out, input, "the run keeps its values");
        assert_eq!(u.reason, polepatch::UntouchedReason::CentrePath);
        assert!(
            u.message.contains("chord tolerance 0.001 mm"),
            "{}",
            u.message
        );
    }
}

/// Issue 42: the ball forms added, each under its tip-referring TCPM code: every written
/// centre (tip + R·o, o from the written A C) kept within 1 µm plus rounding — which fails
/// where the description is not read (the zones then change the orientation with X Y Z
/// left) or read with the wrong size.
#[test]
fn new_ball_forms_keep_the_centre() {
    let m = ucp710();
    for (file, radius) in [
        ("cuq-ac-swing-d0.5-ball.nc", 5.0),
        ("mastercam-pipe-ac-swing-d0.5-ball.nc", 5.0),
        ("hypermill-toollist-ac-swing-d1-ball.H", 5.0),
        // Inches: the tip and R in the file's unit (0.25 in).
        ("fusion-inch-ac-swing-d0.5-ball.nc", 0.25),
    ] {
        let input = fixture(&format!("fixtures/tools/{file}"));
        let (out, report) = patch_nc(&input, &m, &PatchOptions::default()).unwrap();
        all_reached(&report, file);
        let (turned, worst) = centres_kept(&m, &input, &out, radius, file);
        assert!(turned > 0, "{file}: the orientation changed somewhere");
        for z in &report.zones {
            assert_eq!(z.tool_point, Some(ToolPoint::Tip), "{file}");
            assert_eq!(z.tool_disagreement, None, "{file}");
        }
        println!("{file}: {turned} points turned, largest centre error {worst:.7}");
    }
}

/// Issue 39: Fusion writes its tool list before `G20`; the list is in inches, wherever the
/// tool change is (here moved before `G20` as well).
#[test]
fn a_tool_list_before_g20_is_in_inches() {
    let m = ucp710();
    let text =
        String::from_utf8(fixture("fixtures/tools/fusion-inch-ac-swing-d0.5-ball.nc")).unwrap();
    let moved = text.replace("G20\n", "").replace("T1 M6\n", "T1 M6\nG20\n");
    assert_ne!(moved, text);
    for (what, input) in [("as posted", text), ("change before G20", moved)] {
        let (out, report) = patch_nc(input.as_bytes(), &m, &PatchOptions::default()).unwrap();
        for z in &report.zones {
            assert_eq!(
                z.tool.to_string(),
                "ball D12.7",
                "{what}: {}",
                z.tool_source
            );
        }
        let (turned, _) = centres_kept(&m, input.as_bytes(), &out, 0.25, what);
        assert!(turned > 0, "{what}");
    }
}

/// Issue 39: a list of hyperMILL descriptions just before the call (a flat D12, then a ball
/// D10) and `TOOL CALL "FLAT-D12"`: the flat, so every zone stays within the flat's cap
/// (2·asin(0.005/12) = 0.0477°); a call that names neither leaves the tool unknown, the list
/// named.
#[test]
fn a_list_before_the_call_gives_the_tool_it_names() {
    let m = ucp710();
    let input = fixture("fixtures/tools/hypermill-list-call-flat-d12.H");
    let (_, report) = patch_nc(&input, &m, &PatchOptions::default()).unwrap();
    let cap =
        polepatch::tool::deviation_cap_deg(&Tool::parse("flat:12").unwrap(), SURFACE_TOLERANCE_MM);
    assert!((cap - 0.0477).abs() < 1e-3, "{cap}");
    assert!(!report.zones.is_empty());
    for z in &report.zones {
        assert_eq!(z.tool.to_string(), "flat D12", "{}", z.tool_source);
        assert!(
            z.tool_source
                .starts_with("line 4: 3 * - TOOL: T1 | FLAT-D12"),
            "{}",
            z.tool_source
        );
        assert!(
            z.max_deviation_deg <= cap * (1.0 + 1e-6),
            "{} > {cap}",
            z.max_deviation_deg
        );
    }
    let other = String::from_utf8(input)
        .unwrap()
        .replace("\"FLAT-D12\" Z", "\"GB02\" Z");
    let (_, report) = patch_nc(other.as_bytes(), &m, &PatchOptions::default()).unwrap();
    for z in &report.zones {
        assert_eq!(z.tool, ZoneTool::Unknown);
        assert!(
            z.tool_source
                .contains("line 4, line 5 describe tools just before the call"),
            "{}",
            z.tool_source
        );
    }
}

/// Issue 39: `TOOL CALL Z S10000` calls no tool 'Z' (the tool in use, a new speed), and a
/// `TOOL DEF` without R2 is a flat end mill (held to its cap).
#[test]
fn tool_call_axis_and_tool_def_without_r2() {
    let m = ucp710();
    let (out, report) = patch_nc(
        &fixture("fixtures/tools/conv-toolcall-speed-only.H"),
        &m,
        &PatchOptions::default(),
    )
    .unwrap();
    all_reached(&report, "TOOL CALL Z S10000");
    for z in &report.zones {
        assert_eq!(z.tool.to_string(), "ball D10", "{}", z.tool_source);
        assert!(!z.tool_source.contains("'Z'") && !z.tool_source.contains("\"Z\""));
    }
    centres_kept(
        &m,
        &fixture("fixtures/tools/conv-toolcall-speed-only.H"),
        &out,
        5.0,
        "TOOL CALL Z",
    );
    let flat = fixture("fixtures/tools/conv-tooldef-no-r2-flat.H");
    let (out, report) = patch_nc(&flat, &m, &PatchOptions::default()).unwrap();
    let cap =
        polepatch::tool::deviation_cap_deg(&Tool::parse("flat:10").unwrap(), SURFACE_TOLERANCE_MM);
    for z in &report.zones {
        assert_eq!(z.tool.to_string(), "flat D10", "{}", z.tool_source);
        assert!(z.max_deviation_deg <= cap * (1.0 + 1e-6));
    }
    let (b, a) = pairs(&flat, &out);
    for (p, q) in b.iter().zip(&a) {
        assert!(turn_deg(&m, p, q) <= cap + 1e-6, "line {}", p.line);
        assert_eq!(p.xyz_text, q.xyz_text, "a flat end mill's X Y Z stay");
    }
}

/// Issue 39: a tool table entry that contradicts itself is refused with its key; one that
/// disagrees with the program's own description is said (the zone's field and a warning)
/// and the program's is used: the centres of its D10 ball are kept.
#[test]
fn tool_tables_that_contradict() {
    use polepatch::tool::ToolTable;
    let e = ToolTable::from_toml_str(
        "[tool.5]\nkind = \"ball\"\ndiameter_mm = 10\ncorner_radius_mm = 2\n",
        "tools.toml",
    )
    .unwrap_err();
    assert!(
        e.contains("tools.toml: tool 5") && e.contains("corner_radius_mm = 2"),
        "{e}"
    );
    let e = ToolTable::from_toml_str(
        "[tool.flat]\nkind = \"flat\"\ndiameter_mm = 10\ncorner_radius_mm = 1\n",
        "t",
    )
    .unwrap_err();
    assert!(e.contains("tool flat"), "{e}");
    let m = ucp710();
    let input = fixture("fixtures/tools/ac-swing-d1-conv-refpnt-tip.H");
    let mut opts = PatchOptions::default();
    opts.tool.table =
        ToolTable::from_toml_str("[tool.1]\nkind = \"flat\"\ndiameter_mm = 10\n", "t").unwrap();
    let (out, report) = patch_nc(&input, &m, &opts).unwrap();
    all_reached(&report, "table disagrees");
    for z in &report.zones {
        assert_eq!(z.tool.to_string(), "ball D10");
        let d = z.tool_disagreement.as_deref().unwrap();
        assert!(d.contains("tool table's entry for T1 says flat D10"), "{d}");
    }
    let said: Vec<_> = report
        .warnings
        .iter()
        .filter(|w| w.contains("sources disagree"))
        .collect();
    assert_eq!(said.len(), 1, "{:?}", report.warnings);
    centres_kept(&m, &input, &out, 5.0, "table disagrees");
}

/// Issue 39: `DL` in a `TOOL CALL` under `FUNCTION TCPM … TIP-TIP`. DL−5 on a D10 ball: the
/// controlled point is the ball's centre, so X Y Z stay as they are; DL−2: the centre is
/// 3 mm above the point X Y Z state, and it is kept there (a patch that ignored DL keeps
/// it 5 mm up and fails this by 2 mm × |Δo|).
#[test]
fn a_tool_call_delta_length() {
    let m = ucp710();
    let centre = fixture("fixtures/tools/conv-tip-dl-minus-r.H");
    let (out, report) = patch_nc(&centre, &m, &PatchOptions::default()).unwrap();
    assert_ne!(out, centre, "patched");
    xyz_identical(&centre, &out, "DL-5");
    for z in &report.zones {
        assert_eq!(z.tool_point, Some(ToolPoint::Centre));
        assert!(
            z.tool_point_source.contains("line 5, col 24: DL-5"),
            "{}",
            z.tool_point_source
        );
    }
    let between = fixture("fixtures/tools/conv-tip-dl-minus-2.H");
    let (out, report) = patch_nc(&between, &m, &PatchOptions::default()).unwrap();
    all_reached(&report, "DL-2");
    let (turned, worst) = centres_kept(&m, &between, &out, 3.0, "DL-2");
    assert!(turned > 0);
    assert!(
        points(&String::from_utf8_lossy(&out))
            .iter()
            .zip(points(&String::from_utf8_lossy(&between)))
            .any(|(a, b)| a.xyz_text != b.xyz_text),
        "DL-2: X Y Z rewritten"
    );
    println!("DL-2: {turned} points turned, largest centre error {worst:.6} mm");
}

/// Issue 39: an APT file with a second `CUTTER/` after `LOADTL/2`, posted and patched:
/// the first pass is the ball's (centres kept), the second the flat's (within its cap), each
/// source the CL line of its cutter — never `--tool`.
#[test]
fn post_reads_each_cutter_for_the_tool_loaded() {
    let m = ucp710();
    let name = "fixtures/tools/apt-two-cutters-swing.apt";
    let bytes = fixture(name);
    let cl = read_cl(&bytes, name).unwrap();
    let post = |patch: bool| {
        let mut opts = PostOptions {
            patch,
            ..PostOptions::default()
        };
        tool_from_cl(&bytes, &cl, &mut opts);
        post_cl(&cl, &m, &opts).unwrap()
    };
    let (raw, _) = post(false);
    let (patched, report) = post(true);
    let report = report.unwrap();
    let text = String::from_utf8_lossy(&raw).into_owned();
    // The second tool change of the written program.
    let second = text
        .lines()
        .position(|l| l.contains("T2 "))
        .expect("the second tool change")
        + 1;
    let cap =
        polepatch::tool::deviation_cap_deg(&Tool::parse("flat:12").unwrap(), SURFACE_TOLERANCE_MM);
    let (mut balls, mut flats) = (0, 0);
    for z in &report.zones {
        assert_ne!(z.tool_source, "--tool");
        if z.lines[0] < second {
            balls += 1;
            assert_eq!(z.tool.to_string(), "ball D10", "{}", z.tool_source);
            assert!(
                z.tool_source.starts_with("CL line 10: CUTTER/10."),
                "{}",
                z.tool_source
            );
        } else {
            flats += 1;
            assert_eq!(z.tool.to_string(), "flat D12", "{}", z.tool_source);
            assert!(
                z.tool_source.starts_with("CL line 73: CUTTER/12."),
                "{}",
                z.tool_source
            );
            assert!(
                z.max_deviation_deg <= cap * (1.0 + 1e-6),
                "{}",
                z.max_deviation_deg
            );
        }
    }
    assert!(balls > 0 && flats > 0, "{balls} {flats}");
    let (turned, _) = centres_kept_in(&m, &raw, &patched, 5.0, "APT ball pass", 0..=second);
    assert!(turned > 0);
}

/// Issue 42: a tool comment in no form polepatch reads is named where the tool stays
/// unknown.
#[test]
fn an_unread_tool_comment_is_named() {
    let m = ucp710();
    let text = String::from_utf8(fixture("fixtures/tools/fusion-ac-swing-d0.5-ball.nc"))
        .unwrap()
        .replace("(T1  D=10. CR=5. - ZMIN=-5. - ball end mill)\n", "")
        .replace("T1 M6", "T3 M06 (BALL 6MM)");
    let (_, report) = patch_nc(text.as_bytes(), &m, &PatchOptions::default()).unwrap();
    assert!(!report.zones.is_empty());
    for z in &report.zones {
        assert_eq!(z.tool, ZoneTool::Unknown);
        assert!(
            z.tool_source.contains("T3")
                && z.tool_source
                    .contains("(BALL 6MM) is no form polepatch reads"),
            "{}",
            z.tool_source
        );
    }
}
