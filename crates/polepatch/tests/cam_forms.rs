//! Issue 30: real CAM output read right the first time. Each fixture in `fixtures/cam/` and
//! `fixtures/cl/` is written in the style of a public program that was misread or refused
//! (the files themselves are not in the repository: `../shared/realworld/`, sources in
//! its SOURCES.tsv), with a near-pole pass of its own so that reading it right is seen
//! where it matters: the zone is found and patched, and nothing but rotary words changes.

use polepatch::kinematics::Machine;
use polepatch::nc::modal::{B, C, X, Z};
use polepatch::nc::{Dialect, FeedMode, ReadOptions, Tcpm, parse, parse_with};
use polepatch::post::{PostOptions, post_cl, read_cl};
use polepatch::report::SkipReason;
use polepatch::{PatchOptions, patch_nc};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn cam(name: &str) -> Vec<u8> {
    let p = root().join("fixtures/cam").join(name);
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn cl(name: &str) -> Vec<u8> {
    std::fs::read(root().join("fixtures/cl").join(name)).unwrap()
}

fn ucp710() -> Machine {
    Machine::builtin("mikron-ucp710").unwrap()
}

fn hsm600() -> Machine {
    Machine::builtin("mikron-hsm600").unwrap()
}

fn opts(name: &str) -> PatchOptions {
    PatchOptions::named(name)
}

/// The program with its rotary words taken out (with the blanks before them, so that a
/// word the patch inserted into a block that had none goes too): what must not change.
fn without_rotary_words(bytes: &[u8]) -> Vec<u8> {
    let p = parse(bytes.to_vec(), Dialect::Auto).unwrap();
    let mut out = Vec::new();
    let mut at = 0;
    for w in &p.words {
        if matches!(w.letter, b'A' | b'B' | b'C') {
            let mut start = w.start as usize;
            while start > at && matches!(bytes[start - 1], b' ' | b'\t') {
                start -= 1;
            }
            out.extend_from_slice(&bytes[at..start]);
            at = w.value_span().end;
        }
    }
    out.extend_from_slice(&bytes[at..]);
    out
}

/// Patch `name` on `m`: a zone is found and reaches feed, and the output differs from the
/// input in rotary words only (in number, not in layout).
fn patches_rotary_words_only(name: &str, bytes: &[u8], m: &Machine, o: &PatchOptions) {
    let (out, report) = patch_nc(bytes, m, o).unwrap();
    assert!(!report.zones.is_empty(), "{name}: no zone found");
    assert!(
        report
            .zones
            .iter()
            .all(|z| z.outcome == polepatch::Outcome::Reached),
        "{name}: {:?}",
        report.zones
    );
    assert!(out != bytes, "{name}: nothing was patched");
    assert!(
        without_rotary_words(&out) == without_rotary_words(bytes),
        "{name}: something other than rotary words changed"
    );
}

/// Item 1: Sinumerik user variables (`SUPA G0 Z=_Z_HOME D0`, `_X_HOME=-365.`, `F=_F_…`)
/// are carried through and listed like any other expression; the file is read to its end
/// and its near-pole pass patched.
#[test]
fn sinumerik_user_variables_are_carried_and_listed() {
    let bytes = cam("sinumerik-840d-user-variables.mpf");
    let p = parse(bytes.clone(), Dialect::Auto).unwrap();
    assert_eq!(p.dialect, Dialect::Sinumerik);
    let (_, report) = patch_nc(&bytes, &hsm600(), &opts("840d")).unwrap();
    let lines_of = |text: &str| -> Vec<usize> {
        String::from_utf8_lossy(&bytes)
            .lines()
            .enumerate()
            .filter(|(_, l)| l.contains(text))
            .map(|(k, _)| k + 1)
            .collect()
    };
    for line in lines_of("Z=_Z_HOME")
        .into_iter()
        .chain(lines_of("F=_F_FINISH"))
    {
        assert!(
            report
                .not_analysed
                .iter()
                .any(|n| n.reason == SkipReason::Expression
                    && (n.lines[0]..=n.lines[1]).contains(&line)),
            "line {line}: {:?}",
            report.not_analysed
        );
    }
    patches_rotary_words_only("840d", &bytes, &hsm600(), &opts("840d"));
    // The minimal line.
    let q = parse(b"N10 G1 X=_XH Y0 F1000\n".to_vec(), Dialect::Auto).unwrap();
    assert_eq!(q.state(0).pos[X], None, "a variable: X unknown after it");
}

/// Item 2: `BEGIN PGM … IN` (NX's Heidenhain posts) is an inch program; a Haas program
/// without G20 is read in mm unless asked otherwise, and the report says which.
#[test]
fn units_stated_as_in_and_units_not_stated() {
    let bytes = cam("tnc-begin-pgm-in.h");
    let p = parse(bytes.clone(), Dialect::Auto).unwrap();
    assert_eq!(p.dialect, Dialect::Conversational);
    let line = |text: &str| {
        (0..p.blocks.len())
            .find(|&b| String::from_utf8_lossy(&p.bytes[p.blocks[b].span()]).contains(text))
            .unwrap()
    };
    let b = line("L X+.0197 B+9.465");
    assert!((p.state(b).pos[X].unwrap() - 0.0197 * 25.4).abs() < 1e-9);
    // F78.7 in 1/10 inch/min, as every other Heidenhain inch program.
    assert!((p.state(b).feed_mm_min.unwrap() - 78.7 * 2.54).abs() < 1e-9);
    let (_, report) = patch_nc(&bytes, &hsm600(), &opts("in")).unwrap();
    assert!(
        !report.warnings.iter().any(|w| w.contains("length units")),
        "{:?}",
        report.warnings
    );
    // Read in mm (as the reader did before), the pass is 25.4 times shorter and crawls.
    let as_mm = String::from_utf8(bytes.clone())
        .unwrap()
        .replace("PGM SPIRAL IN", "PGM SPIRAL MM");
    let (_, mm_report) = patch_nc(as_mm.as_bytes(), &hsm600(), &opts("mm")).unwrap();
    let lowest =
        |r: &polepatch::FileReport| r.zones.iter().map(|z| z.before.c_ratio).fold(1.0, f64::min);
    assert!(
        lowest(&mm_report) < lowest(&report),
        "{} vs {}",
        lowest(&mm_report),
        lowest(&report)
    );

    let haas = cam("haas-umc-inch-no-g20.nc");
    let (_, mm) = patch_nc(&haas, &hsm600(), &opts("haas")).unwrap();
    assert!(
        mm.warnings.iter().any(|w| w.contains(
            "states no length units (G20/G21, G70/G71, BEGIN PGM … MM|INCH): read in mm; if it is written in inches, give --units inch"
        )),
        "{:?}",
        mm.warnings
    );
    let mut inch_opts = opts("haas");
    inch_opts.read.inch = true;
    let (_, inch) = patch_nc(&haas, &hsm600(), &inch_opts).unwrap();
    assert!(
        inch.warnings
            .iter()
            .any(|w| w.contains("read in inches, as asked (--units inch)")),
        "{:?}",
        inch.warnings
    );
    let read = ReadOptions {
        inch: true,
        ..ReadOptions::default()
    };
    let q = parse_with(haas.clone(), &read).unwrap();
    let b = (0..q.blocks.len())
        .find(|&b| String::from_utf8_lossy(&q.bytes[q.blocks[b].span()]).contains("X.0197 "))
        .unwrap();
    assert!((q.state(b).pos[X].unwrap() - 0.0197 * 25.4).abs() < 1e-9);
    assert!((q.state(b).feed_mm_min.unwrap() - 80.0 * 25.4).abs() < 1e-9);
    patches_rotary_words_only("haas inch", &haas, &hsm600(), &inch_opts);
}

/// Item 5 (and issue 29): a program for an A-B trunnion (A tilts, B turns the table) on an
/// A-C or a B-C machine is refused, the letter the machine does not have named at its first
/// word that matters — B where it first turns on the A-C machine, A where it first appears
/// on the B-C machine (the program's tilting axis is not the machine's): reading it with the
/// wrong kinematics would report orientations the real machine does not have.
#[test]
fn rotary_letters_the_machine_does_not_have_are_named() {
    let bytes = cam("haas-vf2tr-trunnion-ab.nc");
    let text = String::from_utf8(bytes.clone()).unwrap();
    // The first word of `letter` (any value, or not 0) by a plain scan of the text.
    let first = |letter: char, turned: bool| -> (usize, usize) {
        for (i, line) in text.lines().enumerate() {
            let code = line.split('(').next().unwrap();
            let b = code.as_bytes();
            for (j, &c) in b.iter().enumerate() {
                if c as char != letter || (j > 0 && b[j - 1].is_ascii_alphabetic()) {
                    continue;
                }
                let num: String = code[j + 1..]
                    .chars()
                    .take_while(|c| c.is_ascii_digit() || *c == '.' || *c == '-')
                    .collect();
                let Ok(v) = num.parse::<f64>() else { continue };
                if !turned || v != 0.0 {
                    return (i + 1, j + 1);
                }
            }
        }
        panic!("no {letter} word");
    };
    for (m, other, turned) in [(ucp710(), 'B', true), (hsm600(), 'A', false)] {
        let e = patch_nc(&bytes, &m, &opts("vf2tr")).unwrap_err();
        let (line, column) = first(other, turned);
        match &e {
            polepatch::Error::ForeignAxis {
                line: l,
                column: c,
                letter,
                ..
            } => assert_eq!((*l, *c, *letter), (line, column, other), "{}: {e}", m.name),
            _ => panic!("{}: {e}", m.name),
        }
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!(
                "vf2tr:{line}:{column}: {other} is not an axis of machine {}",
                m.name
            )),
            "{msg}"
        );
        assert!(
            msg.contains("the program was posted for another machine"),
            "{msg}"
        );
        // It turns both A and B: no built-in machine is suggested.
        assert!(!msg.contains("the built-in"), "{msg}");
        // The analysis refuses it the same way.
        let a = polepatch::analyze_nc(&bytes, &m, &polepatch::AnalyzeOptions::default());
        assert!(
            matches!(a, Err(polepatch::Error::ForeignAxis { .. })),
            "{}",
            m.name
        );
    }
}

/// Item 6: MillPlus as NX posts it: `G7` with indexed addresses, `G93` a datum shift, `G74`
/// machine coordinates, `G81` a cycle definition whose `B` is the clearance, `G79` its
/// call, `G141` the 5-axis correction (TCPM); the near-pole pass under G141 is patched.
#[test]
fn millplus_is_read_as_millplus() {
    let bytes = cam("millplus-g141-spiral.nc");
    let p = parse(bytes.clone(), Dialect::Auto).unwrap();
    assert_eq!(p.dialect, Dialect::MillPlus);
    let block = |text: &str| {
        (0..p.blocks.len())
            .find(|&b| String::from_utf8_lossy(&p.bytes[p.blocks[b].span()]).contains(text))
            .unwrap_or_else(|| panic!("{text}"))
    };
    // G7 with A5= B5= C5= B7= C7=: a frame change, rotary positions unknown after.
    let g7 = block("G7 A5=15.");
    assert!(!p.blocks[g7].is_move);
    assert_eq!(p.state(g7).pos[B], None);
    // G81's B25. is the clearance, not a B position; the block does not move.
    let g81 = block("G81 Y3.");
    assert!(!p.blocks[g81].is_move);
    assert_ne!(p.state(g81).pos[B], Some(25.0));
    // G93 is a datum shift: the feed mode stays per minute.
    let g93 = block("G93 X0.0");
    assert_eq!(p.state(g93).feed_mode, FeedMode::PerMinute);
    assert_eq!(p.state(g93).pos[X], None);
    // G141 switches TCPM on; G40 off.
    assert_eq!(p.state(block("G141 L2=0")).tcpm, Tcpm::On);
    let g40 = (block("G141 L2=0")..p.blocks.len())
        .find(|&b| String::from_utf8_lossy(&p.bytes[p.blocks[b].span()]).ends_with("G40"))
        .unwrap();
    assert_eq!(p.state(g40).tcpm, Tcpm::Off);
    let pass = block("X1. B9.562");
    assert_eq!(p.state(pass).pos[C], Some(174.053));
    assert_eq!(p.state(pass).feed_mm_min, Some(1500.0));
    patches_rotary_words_only("millplus", &bytes, &hsm600(), &opts("millplus"));
    // The indexed addresses are not listed as expressions.
    let (_, report) = patch_nc(&bytes, &hsm600(), &opts("millplus")).unwrap();
    assert!(
        !report
            .not_analysed
            .iter()
            .any(|n| n.lines[0] <= p.blocks[g7].line && p.blocks[g7].line <= n.lines[1]),
        "{:?}",
        report.not_analysed
    );
}

/// Item 7: Heidenhain conversational with a blank after the axis letter (`L Z 25.000
/// FMAX`, an APT post's output) reads as the axis word; a letter left without a number
/// says the blank is the problem.
#[test]
fn conversational_blanks_after_the_letter() {
    let bytes = cam("tnc-apt-post-blanks.h");
    let p = parse(bytes.clone(), Dialect::Auto).unwrap();
    let b = (0..p.blocks.len())
        .find(|&b| String::from_utf8_lossy(&p.bytes[p.blocks[b].span()]).contains("L Z 25.000"))
        .unwrap();
    assert_eq!(p.state(b).pos[Z], Some(25.0));
    // Its tool, `TOOL DEF 102 L+1.000 R+3.000`, has no R2: a flat D6 to the controller and
    // to polepatch (its comment names a 6 mm ball, in no form read). The zone stops at the
    // flat's cap (`tool_limited`), and only rotary words change.
    let (out, report) = patch_nc(&bytes, &ucp710(), &opts("apt post")).unwrap();
    assert!(!report.zones.is_empty());
    for z in &report.zones {
        assert_eq!(z.tool.to_string(), "flat D6", "{}", z.tool_source);
        assert_eq!(z.reason, polepatch::ZoneReason::ToolLimited);
    }
    assert!(out != bytes && without_rotary_words(&out) == without_rotary_words(&bytes));
    // Told it is a ball with X Y Z at its centre, the pass reaches feed.
    let ball = PatchOptions {
        tool: polepatch::tool::ToolOptions {
            tool: polepatch::tool::Tool::parse("ball:6").ok(),
            point: Some(polepatch::tool::ToolPoint::Centre),
            ..Default::default()
        },
        ..opts("apt post")
    };
    patches_rotary_words_only("apt post", &bytes, &ucp710(), &ball);
    let e = parse(b"0 BEGIN PGM 1 MM\n1 L Z FMAX\n".to_vec(), Dialect::Auto).unwrap_err();
    assert_eq!((e.line, e.column), (2, 5));
    assert!(e.message.contains("a blank after the letter"), "{e}");
}

/// Item 9: a rewritten word keeps the file's number style (NX: `.387`, `15.`, zero `0.0`).
#[test]
fn patched_words_keep_the_style_of_the_file() {
    let bytes = cam("haas-umc-inch-no-g20.nc");
    let mut o = opts("haas");
    o.read.inch = true;
    let (out, report) = patch_nc(&bytes, &hsm600(), &o).unwrap();
    assert!(report.words_changed > 0);
    let before = parse(bytes, Dialect::Auto).unwrap();
    let after = parse(out.clone(), Dialect::Auto).unwrap();
    let mut changed = 0;
    for (w0, w1) in before.words.iter().zip(&after.words) {
        let t0 = &before.bytes[w0.value_span()];
        let t1 = &after.bytes[w1.value_span()];
        if t0 == t1 {
            continue;
        }
        changed += 1;
        let t = String::from_utf8_lossy(t1);
        if t == "0.0" {
            continue; // zero as the file writes it
        }
        assert!(!t.starts_with("0.") && !t.starts_with("-0."), "{t}");
        assert!(!(t.contains('.') && t.ends_with('0') && t != "0.0"), "{t}");
    }
    assert!(changed > 0);
}

/// Items 3 and 8 through `post`: a Creo CL file whose `$$` comment continues over lines,
/// and blank-separated columns without a header, are posted and their pass patched.
#[test]
fn creo_comments_and_blank_separated_columns_post() {
    let creo = read_cl(&cl("creo_csys_comment.ncl"), "creo").unwrap();
    let ws = read_cl(&cl("points_blank_separated.txt"), "ws").unwrap();
    assert_eq!(ws.point_count(), 41);
    assert!(ws.notes.is_empty(), "{:?}", ws.notes);
    for (prog, fallback) in [(creo, None), (ws, Some(1500.0))] {
        for dialect in [Dialect::Heidenhain, Dialect::Sinumerik, Dialect::Fanuc] {
            let o = PostOptions {
                dialect,
                patch_options: PatchOptions {
                    read: polepatch::ReadOptions {
                        feed_fallback_mm_min: fallback,
                        ..polepatch::ReadOptions::default()
                    },
                    ..PatchOptions::default()
                },
                ..PostOptions::default()
            };
            let (_, report) = post_cl(&prog, &ucp710(), &o).unwrap();
            let report = report.expect("patched");
            assert!(!report.zones.is_empty());
            assert!(
                report
                    .zones
                    .iter()
                    .all(|z| z.outcome == polepatch::Outcome::Reached)
            );
        }
    }
}

/// Item 4: CAMWorks' `INSERT/` text goes into the program as it is, each one is listed,
/// and the one between moves near the pole is a line not analysed.
#[test]
fn insert_records_are_written_and_listed() {
    let prog = read_cl(&cl("camworks_insert_5axis.apt"), "camworks").unwrap();
    let o = PostOptions {
        dialect: Dialect::Fanuc,
        patch_options: PatchOptions::named("camworks"),
        ..PostOptions::default()
    };
    let (bytes, report) = post_cl(&prog, &ucp710(), &o).unwrap();
    let report = report.unwrap();
    let text = String::from_utf8(bytes).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    for insert in [
        "6MM CRB BALL 2FL 20 LOC",
        "Stock Size X85. Y38. Z48.",
        "M88 (AIR BLAST)",
    ] {
        assert!(lines.contains(&insert), "{insert}:\n{text}");
        assert!(
            report
                .warnings
                .iter()
                .any(|w| w.contains(&format!("INSERT/{insert} written as it is at line"))),
            "{:?}",
            report.warnings
        );
    }
    let near: Vec<_> = report
        .not_analysed
        .iter()
        .filter(|n| n.reason == SkipReason::Insert)
        .collect();
    assert_eq!(near.len(), 1, "{:?}", report.not_analysed);
    let at = lines.iter().position(|l| *l == "M88 (AIR BLAST)").unwrap() + 1;
    assert_eq!(near[0].lines, [at, at]);
    // Text the reader cannot read back is refused at the INSERT, not at the program line.
    let bad = String::from_utf8(cl("camworks_insert_5axis.apt"))
        .unwrap()
        .replace("INSERT/M88 (AIR BLAST)", "INSERT/X");
    let prog = read_cl(bad.as_bytes(), "camworks").unwrap();
    let e = post_cl(&prog, &ucp710(), &o).unwrap_err().to_string();
    assert!(
        e.contains("INSERT/X: its text, written as it is at line"),
        "{e}"
    );
}

/// Item 12: corners at B ≈ 6.4° (a Haas UMC program's, redrawn), where C slows the feed
/// because the tool passes near the pole, are zones by default on both machines and reach
/// feed; the old fixed 5° cone does not see them.
#[test]
fn corners_near_the_pole_are_zones_by_default() {
    let bytes = cam("haas-umc-corners-b6.nc");
    // A B-C program: its machine (an A-C machine refuses it, issue 29).
    {
        let m = hsm600();
        let (_, report) = patch_nc(&bytes, &m, &opts("corners")).unwrap();
        assert!(!report.zones.is_empty(), "{}", m.name);
        for z in &report.zones {
            assert_eq!(z.outcome, polepatch::Outcome::Reached, "{}: {z:?}", m.name);
            assert!(z.min_abs_primary_deg > 5.0, "{z:?}");
        }
        patches_rotary_words_only("corners", &bytes, &m, &opts("corners"));
        let fixed = PatchOptions {
            patch: polepatch::patcher::PatchOptions {
                pole_reach_deg: 5.0,
                ..polepatch::patcher::PatchOptions::default()
            },
            ..opts("corners")
        };
        let (out, report) = patch_nc(&bytes, &m, &fixed).unwrap();
        assert!(report.zones.is_empty(), "{}: {:?}", m.name, report.zones);
        assert_eq!(out, bytes);
    }
}
