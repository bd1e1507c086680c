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
