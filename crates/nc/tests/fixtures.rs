//! The NC files under `fixtures/`: byte-faithful round trip first, then what polepatch
//! reads from each dialect.

use polepatch_nc::{Dialect, Edit, NumberStyle, Program, RunBreak, modal, parse, runs, write};
use std::path::{Path, PathBuf};

fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

fn all_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            all_files(&path, out);
        } else {
            out.push(path);
        }
    }
}

fn load(rel: &str) -> Program {
    let bytes = std::fs::read(fixtures_dir().join(rel)).unwrap();
    parse(bytes, Dialect::Auto).unwrap()
}

fn block_of(p: &Program, n: f64) -> usize {
    (0..p.blocks.len())
        .find(|&b| p.word(b, b'N').is_some_and(|w| w.value == n))
        .unwrap()
}

/// The first promise: every fixture is written back byte for byte.
#[test]
fn write_of_parse_is_identity_for_every_fixture() {
    let mut files = Vec::new();
    all_files(&fixtures_dir(), &mut files);
    files.sort();
    let nc_files: Vec<_> = files
        .iter()
        .filter(|f| {
            f.extension().is_some_and(|e| {
                ["I", "H", "nc", "mpf", "spf", "ngc", "tap"].contains(&e.to_str().unwrap_or(""))
            })
        })
        .collect();
    assert!(nc_files.len() >= 5, "fixtures found: {files:?}");
    for f in nc_files {
        let bytes = std::fs::read(f).unwrap();
        let program =
            parse(bytes.clone(), Dialect::Auto).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(
            write(&program, &[]) == bytes,
            "{} not written back identically",
            f.display()
        );
    }
}

#[test]
fn sing_runs() {
    let p = load("c17/SING.I");
    assert_eq!(p.dialect, Dialect::Heidenhain);
    let r = runs(&p);
    let ns = |run: &polepatch_nc::Run| {
        run.blocks
            .iter()
            .map(|&b| p.word(b, b'N').unwrap().value)
            .collect::<Vec<_>>()
    };
    // N80 only turns A and C at (0, 0, 100): a zero-length G1, point 0 of the main run.
    // The main run N80…N620 ends at the M00 of N630. The retract N650 (after M129) runs
    // from N620's position and ends at N660 (rotary only); N670 runs from N660 and ends at
    // the datum shift of N690. N700 starts from an unknown position and M30 follows.
    assert_eq!(r.len(), 3);
    let main = &r[0];
    let expect: Vec<f64> = std::iter::once(80.0)
        .chain((9..=62).map(|k| f64::from(k) * 10.0))
        .collect();
    assert_eq!(ns(main), expect);
    assert_eq!(main.len(), 55);
    assert_eq!(main.feed_mm_min, Some(2000.0));
    assert!(main.tcpm.is_on());
    assert_eq!(main.ended_by, RunBreak::Block);
    assert_eq!(
        main.pos[0],
        [
            Some(0.0),
            Some(0.0),
            Some(100.0),
            Some(14.825),
            None,
            Some(137.259)
        ]
    );
    let at25 = main
        .pos
        .iter()
        .position(|q| q[modal::X] == Some(25.0) && q[modal::Z] == Some(-8.0))
        .unwrap();
    assert_eq!(p.word(main.blocks[at25], b'N').unwrap().value, 360.0);
    // 20 (Y) + 108 (Z) + 20 (Y) + 25 (X).
    assert!((main.s_mm[at25] - 173.0).abs() < 1e-12);
    assert_eq!(main.pos[at25][modal::C], Some(180.0));
    assert!((main.length_mm() - 218.0).abs() < 1e-12);
    assert_eq!(ns(&r[1]), vec![620.0, 650.0]);
    assert!(!r[1].tcpm.is_on());
    assert_eq!(r[1].ended_by, RunBreak::ZeroLength);
    assert_eq!(ns(&r[2]), vec![660.0, 670.0]);
    assert_eq!(r[2].ended_by, RunBreak::Block);
    // N60 is a datum shift, not a move; N80 is kept out of every run's motion.
    let n60 = block_of(&p, 60.0);
    assert!(!p.blocks[n60].is_move && p.blocks[n60].breaks_run);
    assert_eq!(p.state(n60).pos[..3], [None, None, None]);
}

#[test]
fn sing_c_style() {
    let p = load("c17/SING.I");
    let st = NumberStyle::of(&p, b'C');
    assert!(st.plus_sign && st.strip_trailing_zeros && st.leading_zero);
    assert!(!st.trailing_point && !st.equals);
    assert_eq!(st.decimals, 3);
    assert_eq!(st.render(148.4944, 3), "+148.494");
    assert_eq!(st.render(180.0, 3), "+180");
}

#[test]
fn sing_edit_changes_only_the_c_value() {
    let p = load("c17/SING.I");
    let b = block_of(&p, 350.0);
    let out = write(
        &p,
        &[Edit {
            block: b,
            letter: b'C',
            value: 150.0,
            decimals: 3,
        }],
    );
    let text = String::from_utf8(out).unwrap();
    let orig = String::from_utf8(p.bytes.clone()).unwrap();
    assert_eq!(
        text,
        orig.replace(
            "N350 X+24 Y+0 Z-8 A+1.196 C+148.494 *",
            "N350 X+24 Y+0 Z-8 A+1.196 C+150 *"
        )
    );
}

#[test]
fn non_sing_has_one_main_run() {
    let p = load("c17/NON_SING.I");
    let r = runs(&p);
    assert_eq!(r[0].len(), 55);
    assert!(r[0].pos.iter().all(|q| q[modal::A].unwrap() >= 11.0));
}

#[test]
fn sinumerik_fixture() {
    let p = load("dialects/sinumerik.mpf");
    assert_eq!(p.dialect, Dialect::Sinumerik);
    assert!(p.bytes.windows(2).any(|w| w == b"\r\n"));
    let r = runs(&p);
    assert_eq!(r.len(), 1);
    let run = &r[0];
    assert_eq!(run.len(), 10, "N7 (G0 start) then N10…N90");
    assert_eq!(p.word(run.blocks[0], b'N').unwrap().value, 7.0);
    assert!(run.tcpm.is_on());
    assert_eq!(run.feed_mm_min, Some(1500.0));
    assert_eq!(
        run.pos[1],
        [
            Some(10.0),
            Some(0.0),
            Some(-5.0),
            Some(2.5),
            None,
            Some(30.0)
        ]
    );
    assert_eq!(run.ended_by, RunBreak::Block);
    let st = NumberStyle::of(&p, b'C');
    assert!(st.equals && !st.plus_sign && st.strip_trailing_zeros);
    assert_eq!(st.decimals, 2);
    // The word keeps `C=` and the comment stays; CRLF stays.
    let b = block_of(&p, 20.0);
    let out = write(
        &p,
        &[Edit {
            block: b,
            letter: b'C',
            value: 40.0,
            decimals: 2,
        }],
    );
    let text = String::from_utf8(out).unwrap();
    assert!(text.contains("N20 X11 Y0.2 Z-5 A=2.1 C=40 ; approaching the pole\r\n"));
}

#[test]
fn fanuc_fixture_and_modal_omission() {
    let p = load("dialects/fanuc.nc");
    assert_eq!(p.dialect, Dialect::Fanuc);
    let r = runs(&p);
    assert_eq!(r.len(), 1);
    let run = &r[0];
    assert_eq!(p.word(run.blocks[0], b'N').unwrap().value, 60.0);
    assert_eq!(run.len(), 10);
    assert!(run.tcpm.is_on());
    assert_eq!(run.feed_mm_min, Some(800.0));
    let n90 = block_of(&p, 90.0);
    let n120 = block_of(&p, 120.0);
    // C is modal: N90 keeps N80's C.
    assert_eq!(p.state(n90).pos[modal::C], Some(52.5));
    let st = NumberStyle::of(&p, b'C');
    assert!(!st.plus_sign && st.trailing_point && st.strip_trailing_zeros && !st.leading_zero);
    let edits = [
        Edit {
            block: n90,
            letter: b'C',
            value: 60.0,
            decimals: 3,
        },
        Edit {
            block: n120,
            letter: b'C',
            value: 150.5,
            decimals: 3,
        },
    ];
    let out = String::from_utf8(write(&p, &edits)).unwrap();
    let orig = String::from_utf8(p.bytes.clone()).unwrap();
    let expect = orig
        .replace("N90 X-3. Y-1. A1.5\n", "N90 X-3. Y-1. A1.5 C60.\n")
        .replace("N120 G1X0.Y.5A.5\n", "N120 G1X0.Y.5A.5C150.5\n");
    assert_eq!(out, expect);
    // The rewritten program reads back with the new values.
    let back = parse(out.into_bytes(), Dialect::Auto).unwrap();
    assert_eq!(back.state(n120).pos[modal::C], Some(150.5));
}

#[test]
fn heidenhain_non_utf8_fixture() {
    let p = load("dialects/heidenhain_latin1.I");
    assert_eq!(p.dialect, Dialect::Heidenhain);
    assert!(std::str::from_utf8(&p.bytes).is_err());
    let r = runs(&p);
    assert_eq!(r.len(), 1);
    assert_eq!(r[0].len(), 9, "N60 (G00 start) then N70…N140");
    assert!(r[0].tcpm.is_on());
    let b = block_of(&p, 90.0);
    let out = write(
        &p,
        &[Edit {
            block: b,
            letter: b'C',
            value: 30.0,
            decimals: 3,
        }],
    );
    let mut expect = p.bytes.clone();
    let w = p.word(b, b'C').unwrap();
    expect.splice(w.value_span(), b"+30".iter().copied());
    assert_eq!(out, expect);
}
