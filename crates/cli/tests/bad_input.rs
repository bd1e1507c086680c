//! Issue 10 §3: bad input found by trying, and a fuzz-style property over the whole
//! `patch` path (random bytes, truncated files, mutated fixtures): never a panic, never an
//! output left behind on failure, never the input changed; a message with the line where
//! the input is at fault.

mod common;
use common::{polepatch, root, temp_dir};
use polepatch::PatchOptions;
use polepatch::kinematics::Machine;
use polepatch_cli::files::{JobError, patch_file};
use proptest::prelude::*;
use std::path::Path;

fn sing() -> String {
    std::fs::read_to_string(root().join("fixtures/c17/SING.I")).unwrap()
}

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Patch `bytes` (as a file in its own folder) with the CLI; the exit code and stderr,
/// after checking that the input is unchanged and that no output exists on failure.
fn patch_cli(name: &str, bytes: &[u8]) -> (i32, String) {
    let dir = temp_dir(name);
    let input = dir.join(format!("{name}.I"));
    std::fs::write(&input, bytes).unwrap();
    let out = dir.join("out.I");
    let (code, _, err) = polepatch(&[
        "patch",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), bytes, "input changed");
    if code == 1 {
        assert_eq!(listing(&dir), vec![format!("{name}.I")], "left behind");
    }
    (code, err)
}

#[test]
fn an_infinite_coordinate_is_an_error_at_its_column() {
    let text = sing().replace("N360 X+25 ", "N360 X1e999 ");
    let (code, err) = patch_cli("inf", text.as_bytes());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("inf.I:41:6: X value '1e999' is in exponent notation"),
        "{err}"
    );
    let text = sing().replace("N360 X+25 ", "N360 X+25E3 ");
    let (code, err) = patch_cli("exp", text.as_bytes());
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("'+25E3'"), "{err}");
}

#[test]
fn a_nul_byte_inside_a_word_is_an_error_not_skipped() {
    let text = sing().replace("C+211.506", "C+\u{0}211.506");
    let (code, err) = patch_cli("nul", text.as_bytes());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("nul.I:42:29: control byte 0x00 (NUL)"),
        "{err}"
    );
}

#[test]
fn incremental_programs_are_told_what_is_not_supported() {
    let text = sing().replace("G90", "G91");
    assert!(text.contains("G91"));
    let (code, err) = patch_cli("g91", text.as_bytes());
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("incremental mode (G91) is not supported"),
        "{err}"
    );
    // The error names the G91 line, and the first move in it (issue 19 §6).
    assert!(err.contains("g91.I:2:"), "{err}");
    assert!(err.contains("the first move in it is at line 4"), "{err}");
}

#[test]
fn output_equal_to_input_is_refused_in_any_spelling() {
    let dir = temp_dir("spell");
    let input = dir.join("SING.I");
    std::fs::write(&input, sing()).unwrap();
    let before = std::fs::read(&input).unwrap();
    let link = dir.join("link.I");
    #[cfg(unix)]
    std::os::unix::fs::symlink(&input, &link).unwrap();
    let dotted = dir.join(".").join("SING.I");
    let upward = dir.join("..").join(dir.file_name().unwrap()).join("SING.I");
    let mut outputs = vec![input.clone(), dotted, upward];
    if cfg!(unix) {
        outputs.push(link.clone());
    }
    for out in &outputs {
        let (code, _, err) = polepatch(&[
            "patch",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
        ]);
        assert_eq!(code, 1, "{}: {err}", out.display());
        assert!(err.contains("would overwrite the input"), "{err}");
    }
    // The report or the CSV written over the input.
    for flag in ["--report", "--csv"] {
        let (code, _, err) = polepatch(&[
            "patch",
            input.to_str().unwrap(),
            "-o",
            dir.join("out.I").to_str().unwrap(),
            "--machine",
            "mikron-ucp710",
            flag,
            input.to_str().unwrap(),
        ]);
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("is the input file"), "{err}");
        assert!(!dir.join("out.I").exists());
    }
    // A folder batch into its own folder.
    let (code, _, err) = polepatch(&[
        "patch",
        dir.to_str().unwrap(),
        "--out-dir",
        dir.parent().unwrap().to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("would overwrite the input"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

#[test]
fn a_batch_with_bad_files_finishes_the_good_ones() {
    let dir = temp_dir("batch");
    let inputs = dir.join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    std::fs::write(inputs.join("a_good.I"), sing()).unwrap();
    std::fs::write(
        inputs.join("b_bad.I"),
        sing().replace("C+211.506", "C+21..1"),
    )
    .unwrap();
    std::fs::write(inputs.join("c_binary.I"), [0u8, 159, 146, 150, 255, 10, 7]).unwrap();
    std::fs::copy(
        root().join("fixtures/c17/NON_SING.I"),
        inputs.join("d_good.I"),
    )
    .unwrap();
    let out = dir.join("out");
    let (code, stdout, err) = polepatch(&[
        "patch",
        inputs.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("b_bad.I:42:"), "{err}");
    assert!(err.contains("c_binary.I:1:"), "{err}");
    assert!(err.contains("2 of 4 files failed"), "{err}");
    for bad in ["b_bad.I", "c_binary.I"] {
        assert!(
            stdout
                .lines()
                .any(|l| l.starts_with(bad) && l.contains("failed, not written")),
            "{stdout}"
        );
    }
    let written = listing(&out.join("in"));
    assert_eq!(written, vec!["a_good.I", "d_good.I"]);
    // The good ones are exactly what a single-file run writes.
    let single = dir.join("single.I");
    let (code, _, err) = polepatch(&[
        "patch",
        inputs.join("a_good.I").to_str().unwrap(),
        "-o",
        single.to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        std::fs::read(&single).unwrap(),
        std::fs::read(out.join("in/a_good.I")).unwrap()
    );
}

/// A mutation of a fixture: overwrite, insert or delete bytes at a position, or cut the
/// file there.
#[derive(Debug, Clone)]
enum Mutation {
    Set(usize, u8),
    Insert(usize, Vec<u8>),
    Delete(usize, usize),
    Truncate(usize),
}

fn apply(bytes: &[u8], muts: &[Mutation]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for m in muts {
        let n = b.len().max(1);
        match m {
            Mutation::Set(i, v) => {
                let i = i % n;
                if i < b.len() {
                    b[i] = *v;
                }
            }
            Mutation::Insert(i, v) => {
                let i = i % (b.len() + 1);
                b.splice(i..i, v.iter().copied());
            }
            Mutation::Delete(i, k) => {
                let i = i % n;
                let j = (i + k).min(b.len());
                if i < j {
                    b.drain(i..j);
                }
            }
            Mutation::Truncate(i) => b.truncate(i % n),
        }
    }
    b
}

fn mutation() -> impl Strategy<Value = Mutation> {
    // Bytes that matter to the lexer, and any byte.
    let byte = prop_oneof![
        prop::sample::select(b"0123456789+-.XYZABCFGMN *;()%=[]#\n\r\t\x00eE".to_vec()),
        any::<u8>(),
    ];
    prop_oneof![
        (any::<usize>(), byte.clone()).prop_map(|(i, v)| Mutation::Set(i, v)),
        (any::<usize>(), prop::collection::vec(byte, 1..6))
            .prop_map(|(i, v)| Mutation::Insert(i, v)),
        (any::<usize>(), 1usize..40).prop_map(|(i, k)| Mutation::Delete(i, k)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

/// The library half of the CLI path ([`patch_file`]: read, parse, patch, write) on one
/// input: Ok with an output, or an error with a location and no output; never a panic,
/// never the input changed.
fn check_patch_file(dir: &Path, bytes: &[u8], machine: &Machine) -> Result<(), TestCaseError> {
    let input = dir.join("in.I");
    let output = dir.join("out.I");
    std::fs::write(&input, bytes).unwrap();
    let _ = std::fs::remove_file(&output);
    let r =
        std::panic::catch_unwind(|| patch_file(&input, &output, machine, &PatchOptions::default()));
    let r = r.map_err(|_| TestCaseError::fail("panic"))?;
    prop_assert_eq!(std::fs::read(&input).unwrap(), bytes);
    match r {
        Ok(_) => {
            prop_assert!(output.exists());
            // Issue 19: the output differs from the input in rotary words only.
            let out = std::fs::read(&output).unwrap();
            prop_assert_eq!(without_rotary_words(&out), without_rotary_words(bytes));
        }
        Err(e) => {
            prop_assert!(!output.exists(), "output left behind after: {}", e);
            prop_assert_eq!(listing(dir), vec!["in.I".to_string()]);
            let msg = e.to_string();
            prop_assert!(!msg.is_empty());
            if let JobError::Input(polepatch::Error::Parse(p)) = &e {
                prop_assert!(
                    msg.contains(&format!(":{}:{}:", p.line, p.column)) && p.column >= 1,
                    "{}",
                    msg
                );
            }
        }
    }
    Ok(())
}

/// Each line of a program (as the reader splits it) with its rotary words (A B C, letter
/// to last digit) and all blanks taken out: what a patch may not change.
fn without_rotary_words(bytes: &[u8]) -> Vec<Vec<u8>> {
    let Ok(p) = polepatch::nc::parse(bytes.to_vec(), polepatch::nc::Dialect::Auto) else {
        return vec![bytes.to_vec()];
    };
    (0..p.blocks.len())
        .map(|b| {
            let span = p.blocks[b].span();
            let mut keep = vec![true; span.len()];
            for w in p.block_words(b) {
                if matches!(w.letter, b'A' | b'B' | b'C') {
                    for k in w.span() {
                        keep[k - span.start] = false;
                    }
                }
            }
            p.bytes[span.clone()]
                .iter()
                .zip(keep)
                .filter(|&(&c, k)| k && !c.is_ascii_whitespace())
                .map(|(&c, _)| c)
                .collect()
        })
        .collect()
}

fn seeds() -> Vec<Vec<u8>> {
    [
        "fixtures/c17/SING.I",
        "fixtures/dialects/fanuc.nc",
        "fixtures/dialects/sinumerik.mpf",
        "fixtures/dialects/heidenhain_latin1.I",
        "fixtures/shop/ac-flip-d0.5-conv-function-tcpm.H",
        "fixtures/shop/ac-flip-d0.5-linuxcnc-g93-m428.ngc",
        "fixtures/shop/ac-swing-d1-fanuc-g93.nc",
        "fixtures/shop/ac-swing-d1-variables.nc",
    ]
    .iter()
    .map(|p| std::fs::read(root().join(p)).unwrap())
    .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn mutated_fixtures_never_panic_nor_leave_output(
        which in 0usize..8,
        muts in prop::collection::vec(mutation(), 1..5),
    ) {
        let dir = temp_dir(&format!("fuzz-lib-{which}"));
        let bytes = apply(&seeds()[which], &muts);
        check_patch_file(&dir, &bytes, &Machine::builtin("mikron-ucp710").unwrap())?;
    }

    #[test]
    fn random_bytes_never_panic_nor_leave_output(
        bytes in prop::collection::vec(any::<u8>(), 0..400),
    ) {
        let dir = temp_dir("fuzz-random");
        check_patch_file(&dir, &bytes, &Machine::builtin("mikron-hsm600").unwrap())?;
    }
}

proptest! {
    // The binary itself (argument handling, printing, exit codes): fewer cases, each a
    // process.
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    #[test]
    fn the_binary_on_mutated_fixtures_exits_0_1_or_2(
        which in 0usize..8,
        muts in prop::collection::vec(mutation(), 1..4),
    ) {
        let bytes = apply(&seeds()[which], &muts);
        let (code, err) = patch_cli(&format!("fuzz-bin-{which}"), &bytes);
        prop_assert!(matches!(code, 0..=2), "exit {}: {}", code, err);
        if code == 1 {
            prop_assert!(err.contains("polepatch: error:"), "{}", err);
        }
    }
}

#[test]
fn every_truncation_of_a_small_program_is_handled() {
    let bytes = std::fs::read(root().join("fixtures/dialects/fanuc.nc")).unwrap();
    let dir = temp_dir("truncate");
    let machine = Machine::builtin("mikron-ucp710").unwrap();
    let step = (bytes.len() / 97).max(1);
    for n in (0..=bytes.len()).step_by(step) {
        check_patch_file(&dir, &bytes[..n], &machine)
            .unwrap_or_else(|e| panic!("truncated at {n}: {e}"));
    }
}

#[test]
fn a_malformed_work_offset_is_refused_with_the_expected_form() {
    for bad in ["1,2", "a,b,c", "1,2,inf"] {
        let (code, _, err) = polepatch(&[
            "analyze",
            "fixtures/c17/SING.I",
            "--machine",
            "mikron-ucp710",
            "--work-offset",
            bad,
        ]);
        assert_ne!(code, 0, "{bad}");
        assert!(err.contains("X,Y,Z"), "{bad}: {err}");
    }
}
