//! `polepatch post` as a user runs it.

mod common;
use common::{polepatch, temp_dir};

/// `polepatch post CL --machine mikron-ucp710 --dialect D -o OUT`.
fn post(cl: &std::path::Path, dialect: &str, out: &std::path::Path) -> (i32, String, String) {
    polepatch(&[
        "post",
        cl.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--dialect",
        dialect,
        "-o",
        out.to_str().unwrap(),
    ])
}

#[test]
fn the_bundled_cl_example_posts_and_patches_in_every_dialect() {
    let dir = temp_dir("post");
    for (dialect, ext) in [("heidenhain", "I"), ("sinumerik", "mpf"), ("fanuc", "nc")] {
        let out = dir.join(format!("sing.{ext}"));
        let report = dir.join(format!("{dialect}.json"));
        let (code, stdout, err) = polepatch(&[
            "post",
            "fixtures/cl/SING.apt",
            "--machine",
            "mikron-ucp710",
            "--dialect",
            dialect,
            "--branch",
            "positive",
            "-o",
            out.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(stdout.contains("1 zone(s), 1 reach feed"), "{stdout}");
        // The posted program is a program `patch` and `analyze` read like any other.
        let (code, stdout, err) = polepatch(&[
            "analyze",
            out.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
        ]);
        assert_eq!(code, 0, "{err}");
        assert!(stdout.contains("no singular zone"), "{stdout}");
    }
}

#[test]
fn bad_records_are_refused_with_line_and_column_and_nothing_written() {
    let dir = temp_dir("post-bad");
    let cl = dir.join("bad.apt");
    std::fs::write(
        &cl,
        "MULTAX/ON\nFEDRAT/1000,MMPM\nGOTO/1,2,3,0,0,1\nGOTO/1,2,3.5.1,0,0,1\n",
    )
    .unwrap();
    let out = dir.join("out.I");
    let (code, _, err) = post(&cl, "heidenhain", &out);
    assert_eq!(code, 1);
    assert!(
        err.contains("bad.apt:4:10: z '3.5.1' is not a number"),
        "{err}"
    );
    assert!(!out.exists());
    // No feed for a cutting move: the line, and the way out.
    std::fs::write(&cl, "1,2,3,0,0,1\n2,2,3,0,0,1\n").unwrap();
    let (code, _, err) = post(&cl, "fanuc", &out);
    assert_eq!(code, 1);
    assert!(
        err.contains("bad.apt:1:") && err.contains("--feed"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn a_cl_file_given_to_patch_is_named_as_such() {
    let dir = temp_dir("cl-to-patch");
    let (code, _, err) = polepatch(&[
        "patch",
        "fixtures/cl/SING.apt",
        "-o",
        dir.join("x.I").to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("SING.apt:5: this is a CL file"), "{err}");
}

/// Issue 16 §6: a record whose meaning for the motion is unknown stops the post with the
/// file, line, column and name; `--ignore NAME` skips it and says so; a record polepatch
/// posts cannot be ignored.
#[test]
fn unknown_records_stop_the_post_unless_ignored_by_name() {
    let dir = temp_dir("post-ignore");
    let cl = dir.join("thread.apt");
    std::fs::write(
        &cl,
        "UNIT/MM\nFEDRAT/500\nGOTO/0,0,0\n  THREAD/TURN,1.5\nGOTO/10,0,0\n",
    )
    .unwrap();
    let out = dir.join("out.nc");
    let (code, _, err) = post(&cl, "fanuc", &out);
    assert_eq!(code, 1);
    assert!(
        err.contains("thread.apt:4:3: THREAD records are not posted")
            && err.contains("--ignore THREAD"),
        "{err}"
    );
    assert!(!out.exists());
    let args = |extra: &[&str]| {
        let mut a = vec![
            "post",
            cl.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--dialect",
            "fanuc",
            "-o",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        polepatch(&a)
    };
    let (code, _, err) = args(&["--ignore", "thread"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("THREAD 1 (skipped, --ignore)"), "{err}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("(THREAD records skipped by --ignore THREAD: 1, the first at line 4)"),
        "{text}"
    );
    assert!(
        err.contains("1 THREAD record(s) skipped (--ignore THREAD), the first at line 4"),
        "{err}"
    );
    // GOTO records are posted here (the THREAD one still stops the read first).
    let (code, _, err) = args(&["--ignore", "GOTO", "--ignore", "THREAD"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("--ignore GOTO: polepatch posts the 2 GOTO record(s) of")
            && err.contains("only records it refuses in the file can be skipped"),
        "{err}"
    );
}

/// `UNIT/INCH` (CAMWorks) and `UNITS/INCHES` give byte-identical programs; `--units mm`
/// converts every length and feed; a CSV file with a UTF-8 byte-order mark keeps its first
/// point.
#[test]
fn units_both_spellings_and_a_byte_order_mark() {
    let dir = temp_dir("post-units");
    let bracket =
        std::fs::read_to_string(common::root().join("fixtures/cl/camworks_bracket_inch.apt"))
            .unwrap();
    let a = dir.join("unit.apt");
    let b = dir.join("units.apt");
    std::fs::write(&a, &bracket).unwrap();
    std::fs::write(&b, bracket.replace("UNIT/INCH\r\n", "UNITS/INCHES\r\n")).unwrap();
    let mut outputs = Vec::new();
    for (cl, units) in [(&a, "inch"), (&b, "inch"), (&a, "mm"), (&b, "mm")] {
        let out = dir.join(format!(
            "{}.{units}.mpf",
            cl.file_stem().unwrap().to_str().unwrap()
        ));
        let (code, _, err) = polepatch(&[
            "post",
            cl.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--dialect",
            "sinumerik",
            "--units",
            units,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        // Programs name their source: compare without that comment line.
        let text = std::fs::read_to_string(&out).unwrap();
        outputs.push(
            text.lines()
                .filter(|l| !l.contains("posted by polepatch"))
                .collect::<Vec<_>>()
                .join("\n"),
        );
    }
    assert_eq!(outputs[0], outputs[1]);
    assert_eq!(outputs[2], outputs[3]);
    assert!(outputs[0].contains("G700") && outputs[2].contains("G71"));
    assert!(outputs[2].contains("X57.15 Y38.1 Z-3.175") && outputs[2].contains("F304.8"));
    // Heidenhain in inches is refused with the way out, at the units record.
    let (code, _, err) = post(&a, "heidenhain", &dir.join("x.I"));
    assert_eq!(code, 1);
    assert!(err.contains("--units mm"), "{err}");
    assert!(
        err.contains("unit.apt:4:1: the CL file is in inches (this record)"),
        "{err}"
    );
    // A CSV with a byte-order mark: both points posted.
    let csv = dir.join("bom.csv");
    std::fs::write(&csv, b"\xEF\xBB\xBF1,2,3,0,0,1,1000\n4,5,6,0,0,1\n").unwrap();
    let out = dir.join("bom.nc");
    let (code, stdout, err) = post(&csv, "fanuc", &out);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains(": 2 points"), "{stdout}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("X1. Y2. Z3.") && text.contains("X4. Y5. Z6."),
        "{text}"
    );
}

/// Issue 19 §5: `GOTO/1e308` was posted as a 309-digit word; it is refused with its
/// column, nothing written.
#[test]
fn out_of_range_coordinates_are_refused() {
    let dir = temp_dir("post-huge");
    let cl = dir.join("huge.apt");
    std::fs::write(
        &cl,
        "MULTAX\nFEDRAT/100\nGOTO/0,0,0,0,0,1\nGOTO/1e308,0,0,0,0,1\n",
    )
    .unwrap();
    let out = dir.join("out.I");
    let (code, _, err) = post(&cl, "heidenhain", &out);
    assert_eq!(code, 1);
    assert!(err.contains("huge.apt:4:6: x '1e308'"), "{err}");
    assert!(!out.exists());
}

/// A point of a posted program: X Y Z, the primary axis and C, and the decimals written
/// (linear, rotary).
struct Posted {
    xyz: [f64; 3],
    a_deg: f64,
    c_deg: f64,
    decimals: (usize, usize),
}

/// The G1 points of a posted program for an A-C machine (every straight move writes X Y Z
/// A C): comments dropped, rapids skipped.
fn posted_points(text: &str) -> Vec<Posted> {
    let mut out = Vec::new();
    for line in text.lines() {
        let code = line.split([';', '(']).next().unwrap_or("");
        if code.contains("G00") || code.contains("G0 ") {
            continue;
        }
        let mut words = std::collections::HashMap::new();
        let b = code.as_bytes();
        let mut i = 0;
        while i < b.len() {
            if b[i].is_ascii_uppercase() {
                let j = (i + 1..b.len())
                    .find(|&j| !(b[j].is_ascii_digit() || matches!(b[j], b'.' | b'-' | b'+')))
                    .unwrap_or(b.len());
                let num = &code[i + 1..j];
                if let Ok(v) = num.parse::<f64>() {
                    let dec = num.split_once('.').map_or(0, |(_, d)| d.len());
                    words.insert(b[i], (v, dec));
                }
                i = j.max(i + 1);
            } else {
                i += 1;
            }
        }
        if let [Some(x), Some(y), Some(z), Some(a), Some(c)] =
            [b'X', b'Y', b'Z', b'A', b'C'].map(|l| words.get(&l).copied())
        {
            out.push(Posted {
                xyz: [x.0, y.0, z.0],
                a_deg: a.0,
                c_deg: c.0,
                decimals: (x.1.max(y.1).max(z.1), a.1.max(c.1)),
            });
        }
    }
    out
}

/// A near-pole CL path as research data sets write it: the tool axis tilts along X and
/// passes 1° from the pole, so C swings through 180° and the patch turns the tool.
fn near_pole_cl() -> Vec<[f64; 6]> {
    (0..81)
        .map(|k| {
            let x = -20.0 + 0.5 * f64::from(k);
            let (i, j) = (x.to_radians().sin(), 1f64.to_radians().sin());
            let n = (i * i + j * j + 1.0).sqrt();
            [x, 5.0, -2.0 + 0.001 * x * x, i / n, j / n, 1.0 / n]
        })
        .collect()
}

/// The largest distance, mm, between the ball centre of each posted point (tip + R·o, o by
/// the UCP710's forward kinematics: o = (sin C sin A, −cos C sin A, cos A)) and the CL
/// point's (tip + R·(i, j, k)), and the bound it must keep: 1 µm plus the rounding of the
/// written words.
fn centre_error(cl: &[[f64; 6]], program: &str, radius_mm: f64) -> (f64, f64) {
    let pts = posted_points(program);
    assert_eq!(pts.len(), cl.len(), "one G1 point per CL point:\n{program}");
    // The file's precision (a post drops trailing zeros: `X+0`, `X-19.5`).
    let lin_dec = pts.iter().map(|p| p.decimals.0).max().unwrap_or(0);
    let rot_dec = pts.iter().map(|p| p.decimals.1).max().unwrap_or(0);
    let lin = 0.5 * 10f64.powi(-(lin_dec as i32)) * 3f64.sqrt();
    let rot = radius_mm * 2.0 * (0.5 * 10f64.powi(-(rot_dec as i32))).to_radians();
    let mut worst = 0f64;
    for (p, q) in pts.iter().zip(cl) {
        let (a, c) = (p.a_deg.to_radians(), p.c_deg.to_radians());
        let o = [c.sin() * a.sin(), -c.cos() * a.sin(), a.cos()];
        let d: f64 = (0..3)
            .map(|k| {
                let posted = p.xyz[k] + radius_mm * o[k];
                let wanted = q[k] + radius_mm * q[3 + k];
                (posted - wanted).powi(2)
            })
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d);
    }
    (worst, 1e-3 + lin + rot)
}

/// Issue 39 class 7: `post` had no `--tool`, `--tools` or `--tool-point` (exit 64), though
/// its unknown-tool warning named them, so a CSV CL file never got its tool and a
/// tip-programmed ball's centre moved (61 µm). With them — the same flags as `patch` — the
/// patched program keeps every ball centre within 1 µm plus rounding of the CL's; without
/// them the warning says so, and the flags it names work.
#[test]
fn post_takes_the_tool_and_keeps_a_tip_programmed_balls_centre() {
    let dir = temp_dir("post-tool");
    let cl = near_pole_cl();
    let mut csv = String::from("x,y,z,i,j,k,f\n");
    for p in &cl {
        csv.push_str(&format!(
            "{:.6},{:.6},{:.6},{:.9},{:.9},{:.9},2000\n",
            p[0], p[1], p[2], p[3], p[4], p[5]
        ));
    }
    let csv_path = dir.join("pole.csv");
    std::fs::write(&csv_path, &csv).unwrap();
    let run = |cl_path: &std::path::Path, dialect: &str, extra: &[&str]| {
        let out = dir.join(format!("pole.{dialect}.{}", extra.len()));
        let mut a = vec![
            "post",
            cl_path.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--dialect",
            dialect,
            "-o",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        let (code, stdout, err) = polepatch(&a);
        assert_eq!(code, 0, "{dialect} {extra:?}: {err}");
        assert!(stdout.contains("1 zone(s), 1 reach feed"), "{stdout}");
        (std::fs::read_to_string(&out).unwrap(), err)
    };
    for dialect in ["heidenhain", "sinumerik", "fanuc"] {
        // Without the tool: said, with the flags that say it.
        let (program, err) = run(&csv_path, dialect, &[]);
        assert!(
            err.contains("the tool is not known for 1 changed zone(s)")
                && err.contains("--tool ball:D")
                && err.contains("--tools FILE")
                && err.contains("--tool-point tip|centre"),
            "{err}"
        );
        // … and then the centre moved (what this test must catch).
        let (moved, bound) = centre_error(&cl, &program, 5.0);
        assert!(moved > 20.0 * bound, "{dialect}: {moved} mm");
        // With them: the centre kept at every point.
        let (program, err) = run(
            &csv_path,
            dialect,
            &["--tool", "ball:10", "--tool-point", "tip"],
        );
        assert!(!err.contains("the tool is not known"), "{err}");
        let (worst, bound) = centre_error(&cl, &program, 5.0);
        assert!(worst <= bound, "{dialect}: {worst} mm > {bound} mm");
    }
    // A tool table by the number LOADTL calls (an APT file without CUTTER).
    let mut apt = String::from(
        "PARTNO/POLE_TABLE\nUNITS/MM\nMULTAX/ON\nLOADTL/5\nSPINDL/12000,CLW\nFEDRAT/2000,MMPM\n",
    );
    for p in &cl {
        apt.push_str(&format!(
            "GOTO/{:.6},{:.6},{:.6},{:.9},{:.9},{:.9}\n",
            p[0], p[1], p[2], p[3], p[4], p[5]
        ));
    }
    apt.push_str("FINI\n");
    let apt_path = dir.join("pole.apt");
    std::fs::write(&apt_path, apt).unwrap();
    let table = dir.join("tools.toml");
    std::fs::write(&table, "[tool.5]\nkind = \"ball\"\ndiameter_mm = 10\n").unwrap();
    let (program, err) = run(&apt_path, "fanuc", &["--tools", table.to_str().unwrap()]);
    assert!(!err.contains("the tool is not known"), "{err}");
    let (worst, bound) = centre_error(&cl, &program, 5.0);
    assert!(worst <= bound, "--tools: {worst} mm > {bound} mm");
    // The table is an input: it may not be the output.
    let (code, _, err) = polepatch(&[
        "post",
        apt_path.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--dialect",
        "fanuc",
        "--tools",
        table.to_str().unwrap(),
        "-o",
        table.to_str().unwrap(),
    ]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("tool table"), "{err}");
}

/// Issue 42 item 2: `post` refused `CUTCOM/LEFT` with the tool along X, and then refused
/// `--ignore CUTCOM` because it posts CUTCOM records. One rule now: a record refused in
/// this file may be skipped; the moves are posted without compensation and the note says
/// which records, how many and the first line. A kind posted everywhere in the file may not
/// be skipped.
#[test]
fn a_refused_record_can_be_ignored_and_the_note_says_so() {
    let dir = temp_dir("post-ignore-cutcom");
    // CAMWorks style: a side wall machined with the tool along +X, under compensation.
    let side = "$$ Side wall, SolidWorks CAM style\n\
PARTNO/SIDE_WALL\n\
UNIT/MM\n\
MULTAX/ON\n\
CUTTER/6.,0,3.,0,0,0,51.\n\
LOADTL/3\n\
SPINDL/6000,CLW\n\
COOLNT/FLOOD\n\
RAPID\n\
GOTO/-30.0000,0.0000,10.0000,1.000000,0.000000,0.000000\n\
FEDRAT/400.,MMPM\n\
GOTO/-30.0000,0.0000,-5.0000,1.000000,0.000000,0.000000\n\
CUTCOM/LEFT\n\
GOTO/-30.0000,10.0000,-5.0000,1.000000,0.000000,0.000000\n\
GOTO/-30.0000,40.0000,-5.0000,1.000000,0.000000,0.000000\n\
GOTO/-30.0000,40.0000,-15.0000,1.000000,0.000000,0.000000\n\
CUTCOM/OFF\n\
GOTO/-30.0000,50.0000,-15.0000,1.000000,0.000000,0.000000\n\
RAPID\n\
GOTO/-30.0000,50.0000,10.0000,1.000000,0.000000,0.000000\n\
COOLNT/OFF\n\
FINI\n";
    let cl = dir.join("side.apt");
    std::fs::write(&cl, side).unwrap();
    let out = dir.join("side.mpf");
    let report = dir.join("side.json");
    let post_with = |extra: &[&str]| {
        let mut a = vec![
            "post",
            cl.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            "--dialect",
            "sinumerik",
            "-o",
            out.to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        polepatch(&a)
    };
    let (code, _, err) = post_with(&[]);
    assert_eq!(code, 1);
    assert!(
        err.contains("side.apt:13:1: CUTCOM/LEFT (line 13): the tool axis (1.000000, 0.000000, 0.000000) at line 14 is not +Z")
            && err.contains("--ignore CUTCOM posts the moves at the CL points without compensation"),
        "{err}"
    );
    assert!(!out.exists());
    let (code, _, err) = post_with(&["--ignore", "cutcom"]);
    assert_eq!(code, 0, "{err}");
    let note = "side.apt: 2 CUTCOM record(s) skipped (--ignore CUTCOM), the first at line 13; \
                without it the post refused line 13, col 1: CUTCOM/LEFT (line 13)";
    assert!(err.contains(note), "{err}");
    assert!(
        err.contains("the moves are posted at the CL points without cutter compensation"),
        "{err}"
    );
    let program = std::fs::read_to_string(&out).unwrap();
    assert!(
        program.contains("; CUTCOM records skipped by --ignore CUTCOM: 2, the first at line 13"),
        "{program}"
    );
    assert!(
        !program.contains("G41") && !program.contains("G42"),
        "{program}"
    );
    // Every feed move of the CL is a move of the program, with the tool along +X (A 90,
    // C 90): the compensated contour at the CL points.
    assert_eq!(posted_points(&program).len(), 5, "{program}");
    assert!(program.contains("X-30 Y40 Z-15 A90 C90"), "{program}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert!(
        json["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w.as_str().unwrap().contains(note)),
        "{json}"
    );
    // Where every CUTCOM is posted (the tool along +Z), skipping them is refused: it would
    // drop them, not answer a refusal. So is skipping a kind posted everywhere (COOLNT).
    std::fs::write(
        &cl,
        side.replace("1.000000,0.000000,0.000000", "0.000000,0.000000,1.000000"),
    )
    .unwrap();
    let (code, _, err) = post_with(&["--ignore", "CUTCOM"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("--ignore CUTCOM: polepatch posts the 2 CUTCOM record(s) of")
            && err.contains("only records it refuses in the file can be skipped"),
        "{err}"
    );
    let (code, _, err) = post_with(&["--ignore", "COOLNT"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("--ignore COOLNT: polepatch posts the 2 COOLNT"),
        "{err}"
    );
    // A form the reader refuses (COOLNT/THRU) is answered by --ignore COOLNT, which its
    // message names.
    std::fs::write(&cl, side.replace("COOLNT/FLOOD", "COOLNT/THRU")).unwrap();
    let (code, _, err) = post_with(&[]);
    assert_eq!(code, 1);
    assert!(
        err.contains("side.apt:8:8: COOLNT/THRU is not posted") && err.contains("--ignore COOLNT"),
        "{err}"
    );
    let (code, _, err) = post_with(&["--ignore", "COOLNT", "--ignore", "CUTCOM"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("2 COOLNT record(s) skipped (--ignore COOLNT), the first at line 8")
            && err.contains("no coolant words are written for them")
            && err.contains(note),
        "{err}"
    );
}
