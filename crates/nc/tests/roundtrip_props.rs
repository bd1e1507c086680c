//! Property tests: parsing never panics, a parsed program is written back byte for byte,
//! editing one C word changes only the bytes of its number, and random valid blocks in
//! every dialect are read with the values they were written with.

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
        "shop/ac-flip-d0.5-linuxcnc-g93-m428.ngc",
        "shop/ac-swing-d1-variables.nc",
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

/// How a random block writes its words.
#[derive(Debug, Clone, Copy)]
enum Form {
    HeidenhainIso,
    Conversational,
    Sinumerik,
    Fanuc,
    FanucSpaced,
}

/// A block's values per axis X Y Z A C (some absent), each with its decimals.
type Block = Vec<Option<(f64, usize)>>;

/// Random moves: the form, and the blocks.
fn valid_program() -> impl Strategy<Value = (Form, Vec<Block>)> {
    let form = prop_oneof![
        Just(Form::HeidenhainIso),
        Just(Form::Conversational),
        Just(Form::Sinumerik),
        Just(Form::Fanuc),
        Just(Form::FanucSpaced),
    ];
    let value = prop::option::weighted(0.8, (-999.0f64..999.0, 0usize..5));
    let block = prop::collection::vec(value, 5..=5);
    (form, prop::collection::vec(block, 1..20))
}

fn render(form: Form, v: f64, decimals: usize) -> String {
    let t = format!("{v:.decimals$}");
    match form {
        Form::HeidenhainIso | Form::Conversational if !t.starts_with('-') => format!("+{t}"),
        _ => t,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 500, ..ProptestConfig::default() })]

    #[test]
    fn random_valid_blocks_read_back_as_written((form, blocks) in valid_program()) {
        let mut text = String::from(match form {
            Form::HeidenhainIso => "%P G71 *\nN1 M128 *\n",
            Form::Conversational => "0 BEGIN PGM P MM\n1 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\n",
            Form::Sinumerik => "; p\nTRAORI\n",
            Form::Fanuc | Form::FanucSpaced => "(P)\nG43.4 H1\n",
        });
        let mut want = Vec::new();
        for (k, b) in blocks.iter().enumerate() {
            let mut words = Vec::new();
            for (i, letter) in ['X', 'Y', 'Z', 'A', 'C'].into_iter().enumerate() {
                if let Some((v, d)) = b[i] {
                    let n = render(form, v, d);
                    words.push(match form {
                        Form::Sinumerik if i >= 3 => format!("{letter}={n}"),
                        Form::FanucSpaced => format!("{letter}  {n}"),
                        _ => format!("{letter}{n}"),
                    });
                    want.push((k, letter as u8, n.parse::<f64>().unwrap()));
                }
            }
            let body = words.join(" ");
            text += &match form {
                Form::HeidenhainIso => format!("N{} G01 {body} F1000 *\n", k + 2),
                Form::Conversational => format!("{} L {body} R0 F1000\n", k + 2),
                _ => format!("G1 {body} F1000\n"),
            };
        }
        let bytes = text.into_bytes();
        let program = parse(bytes.clone(), Dialect::Auto).map_err(|e| TestCaseError::fail(format!("{form:?}: {e}")))?;
        prop_assert!(write(&program, &[]) == bytes);
        for (k, letter, v) in want {
            let w = program.word(k + 2, letter);
            prop_assert!(w.is_some(), "{:?} block {} has no {}", form, k, letter as char);
            prop_assert_eq!(w.unwrap().value, v);
        }
    }
}
