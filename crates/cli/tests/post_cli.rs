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
        text.contains("(THREAD records skipped by --ignore THREAD: 1)"),
        "{text}"
    );
    let (code, _, err) = args(&["--ignore", "GOTO"]);
    assert_eq!(code, 1);
    assert!(
        err.contains("--ignore GOTO: polepatch posts GOTO records"),
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
