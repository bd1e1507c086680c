//! Property tests: parsing never panics, a parsed program is written back byte for byte,
//! and editing one C word changes only the bytes of its number.

use polepatch_nc::{Dialect, Edit, NumberStyle, Program, parse, write};
use proptest::prelude::*;
use std::path::Path;

/// Bytes that NC lexing cares about, plus a few arbitrary ones.
const ALPHABET: &[u8] = b"NGXYZABCFMTSIJKRHD0123456789.+-=*;()%/ \t\r\n\"[]#$_,:\x00\xe9\xff";

fn fixture_lines() -> Vec<Vec<u8>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let mut lines = Vec::new();
    for rel in [
        "c17/SING.I",
        "dialects/sinumerik.mpf",
        "dialects/fanuc.nc",
        "dialects/heidenhain_latin1.I",
    ] {
        let bytes = std::fs::read(dir.join(rel)).unwrap();
        lines.extend(bytes.split_inclusive(|&b| b == b'\n').map(<[u8]>::to_vec));
    }
    lines
}

fn nc_byte() -> impl Strategy<Value = u8> {
    prop_oneof![4 => prop::sample::select(ALPHABET), 1 => any::<u8>()]
}

/// A program made of fixture lines, some of them mutated (a byte replaced, inserted or
/// removed).
fn mutated_program() -> impl Strategy<Value = Vec<u8>> {
    let lines = fixture_lines();
    let n = lines.len();
    prop::collection::vec(
        (
            0..n,
            prop::option::weighted(0.5, (any::<prop::sample::Index>(), 0u8..3, nc_byte())),
        ),
        1..40,
    )
    .prop_map(move |picks| {
        let mut out = Vec::new();
        for (i, m) in picks {
            let mut line = lines[i].clone();
            if let Some((at, op, b)) = m {
                let k = at.index(line.len() + 1);
                match op {
                    0 if k < line.len() => line[k] = b,
                    1 => line.insert(k, b),
                    _ if k < line.len() => {
                        line.remove(k);
                    }
                    _ => {}
                }
            }
            out.extend(line);
        }
        out
    })
}

/// Edit the C word of the `pick`-th block that has one; check that only its number
/// changed and that the file reads back with the rounded value.
fn check_c_edit(
    program: &Program,
    pick: prop::sample::Index,
    value: f64,
) -> Result<(), TestCaseError> {
    let with_c: Vec<usize> = (0..program.blocks.len())
        .filter(|&b| program.word(b, b'C').is_some())
        .collect();
    if with_c.is_empty() {
        return Ok(());
    }
    let block = with_c[pick.index(with_c.len())];
    let w = program.word(block, b'C').unwrap().clone();
    let style = NumberStyle::of(program, b'C');
    let out = write(
        program,
        &[Edit {
            block,
            letter: b'C',
            value,
            decimals: 3,
        }],
    );
    let bytes = &program.bytes;
    let new = style.render(value, 3);
    prop_assert_eq!(&out[..w.value_span().start], &bytes[..w.value_span().start]);
    prop_assert_eq!(
        &out[w.value_span().start..w.value_span().start + new.len()],
        new.as_bytes()
    );
    prop_assert_eq!(
        &out[w.value_span().start + new.len()..],
        &bytes[w.value_span().end..]
    );
    let back = parse(out, program.dialect).map_err(|e| TestCaseError::fail(e.to_string()))?;
    prop_assert_eq!(
        back.word(block, b'C').unwrap().value,
        style.rounded(value, 3)
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic_and_round_trip(bytes in prop::collection::vec(nc_byte(), 0..400)) {
        if let Ok(program) = parse(bytes.clone(), Dialect::Auto) {
            prop_assert!(write(&program, &[]) == bytes);
            let _ = polepatch_nc::runs(&program);
            for letter in *b"XYZABCF" {
                let _ = NumberStyle::of(&program, letter);
            }
        }
    }

    #[test]
    fn mutated_fixtures_round_trip(
        bytes in mutated_program(),
        pick in any::<prop::sample::Index>(),
        value in -720.0f64..720.0,
    ) {
        if let Ok(program) = parse(bytes.clone(), Dialect::Auto) {
            prop_assert!(write(&program, &[]) == bytes);
            let _ = polepatch_nc::runs(&program);
            check_c_edit(&program, pick, value)?;
        }
    }

    #[test]
    fn unmutated_fixture_lines_always_parse(bytes in prop::collection::vec(prop::sample::select(fixture_lines()), 1..60)) {
        let bytes: Vec<u8> = bytes.concat();
        let program = parse(bytes.clone(), Dialect::Auto).map_err(|e| TestCaseError::fail(e.to_string()))?;
        prop_assert!(write(&program, &[]) == bytes);
        for run in polepatch_nc::runs(&program) {
            prop_assert!(run.len() >= 2);
            prop_assert!(run.s_mm.windows(2).all(|w| w[1] > w[0]));
        }
    }
}
