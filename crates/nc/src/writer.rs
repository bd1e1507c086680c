//! Rewriting: changed or inserted words, every other byte copied.
//!
//! [`write()`] writes edits as they are in the program's own style (a whole program);
//! `write_styled`, in a given file's style, is the last step of [`crate::apply_edits`].

use crate::modal::AXES;
use crate::program::Program;
use crate::style::{FileStyle, NumberStyle};
use crate::word::RotaryForm;

/// Set word `letter` of block `block` to `value`, written with `decimals` places in the
/// file's style for that letter ([`crate::NumberStyle::of`]). A block without the word gets
/// one inserted after its last axis word that precedes the letter in X Y Z A B C order,
/// else before its first axis word, else after the last word before the block end,
/// separated as the file separates words.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edit {
    /// Block index.
    pub block: usize,
    /// Upper-case address letter.
    pub letter: u8,
    /// New value, in the units written in the file.
    pub value: f64,
    /// Decimal places to write.
    pub decimals: usize,
}

/// The program's bytes with `edits` applied (any order; at most one edit per block and
/// letter — if a pair repeats, the last edit wins). Nothing else changes.
///
/// An existing word has only its number (`value_span`) replaced: letter, `=`, sign
/// position and everything around stay. An inserted word is `sep letter [=] number`
/// placed right after its anchor word, where `sep` is the gap the block leaves before its
/// anchor word (or after it), else the file's usual gap between words (a space or
/// nothing). With no edits this is a plain copy.
///
/// # Panics
/// If an edit names a block that does not exist.
pub fn write(program: &Program, edits: &[Edit]) -> Vec<u8> {
    if edits.is_empty() {
        return program.bytes.clone();
    }
    write_styled(program, edits, &FileStyle::of(program))
}

/// [`write`] with the file's style given: `program` may be a stretch of a larger file
/// ([`crate::ProgramBuilder`]) whose own words are too few to show the file's style.
/// Letters other than X Y Z A B C are written in `program`'s style for them.
///
/// # Panics
/// If an edit names a block that does not exist.
pub(crate) fn write_styled(program: &Program, edits: &[Edit], file: &FileStyle) -> Vec<u8> {
    let bytes = &program.bytes;
    if edits.is_empty() {
        return bytes.clone();
    }
    let mut order: Vec<usize> = (0..edits.len()).collect();
    order.sort_by_key(|&i| (edits[i].block, edits[i].letter.to_ascii_uppercase()));
    let mut styles: [Option<NumberStyle>; 26] = [None; 26];
    // (start, end, rank, replacement)
    let mut splices: Vec<(usize, usize, usize, Vec<u8>)> = Vec::with_capacity(edits.len());
    for (k, &i) in order.iter().enumerate() {
        let e = &edits[i];
        let letter = e.letter.to_ascii_uppercase();
        if order.get(k + 1).is_some_and(|&j| {
            (edits[j].block, edits[j].letter.to_ascii_uppercase()) == (e.block, letter)
        }) {
            continue;
        }
        assert!(
            e.block < program.blocks.len(),
            "edit of block {} but the program has {}",
            e.block,
            program.blocks.len()
        );
        let style =
            *styles[usize::from(letter.wrapping_sub(b'A')).min(25)].get_or_insert_with(|| {
                file.letter(letter)
                    .unwrap_or_else(|| NumberStyle::of(program, letter))
            });
        let number = style.render(e.value, e.decimals);
        let own_rank = rank(letter);
        if let Some(w) = program.word(e.block, letter) {
            splices.push((
                w.value_span().start,
                w.value_span().end,
                own_rank,
                number.into_bytes(),
            ));
            continue;
        }
        let words = program.block_words(e.block);
        let preceding = words
            .iter()
            .rposition(|w| rank(w.letter) < own_rank && own_rank < AXES.len());
        // No axis word before it in X Y Z A B C order, but one after it (`Z… C…` getting an
        // X): the new word goes right before that one, so the axes stay in order.
        if preceding.is_none()
            && own_rank < AXES.len()
            && let Some(next) = words.iter().find(|w| rank(w.letter) < AXES.len())
        {
            let mut text = Vec::with_capacity(number.len() + 3);
            inserted(&mut text, program, e.block, letter, &style, file, &number);
            text.extend_from_slice(file.gap);
            splices.push((next.span().start, next.span().start, own_rank, text));
            continue;
        }
        let anchor = preceding.or_else(|| words.len().checked_sub(1));
        let mut text = Vec::with_capacity(number.len() + 3);
        let at = match anchor {
            Some(a) => {
                let gap_before = a
                    .checked_sub(1)
                    .map(|p| &bytes[words[p].span().end..words[a].span().start]);
                let gap_after = words
                    .get(a + 1)
                    .map(|n| &bytes[words[a].span().end..n.span().start]);
                let blank = |g: &&[u8]| g.iter().all(|&b| b == b' ' || b == b'\t');
                match gap_before.filter(blank).or(gap_after.filter(blank)) {
                    Some(g) => text.extend_from_slice(g),
                    None => text.extend_from_slice(file.gap),
                }
                words[a].span().end
            }
            None => program.blocks[e.block].span().start,
        };
        inserted(&mut text, program, e.block, letter, &style, file, &number);
        if anchor.is_none() && !program.blocks[e.block].span().is_empty() {
            text.push(b' ');
        }
        splices.push((at, at, own_rank, text));
    }
    splices.sort_by_key(|s| (s.0, s.2));
    // An inserted word ends with a number: when the byte after the insertion point would
    // run on into it (a digit, a sign, a point; for an `=` word anything but a blank or
    // `;`, as Sinumerik's `=` values end at a blank: `C=268.358(`), the last word inserted
    // there is followed by a blank.
    for k in 0..splices.len() {
        let (at, end) = (splices[k].0, splices[k].1);
        let last_here = splices.get(k + 1).is_none_or(|n| n.0 != at);
        let equals = splices[k].3.contains(&b'=');
        let runs_on = |b: u8| {
            b.is_ascii_digit()
                || matches!(b, b'.' | b'+' | b'-' | b',')
                || (equals && !(b.is_ascii_whitespace() || b == b';'))
        };
        if at == end && last_here && bytes.get(at).copied().is_some_and(runs_on) {
            splices[k].3.push(b' ');
        }
    }
    let extra: usize = splices.iter().map(|s| s.3.len()).sum();
    let mut out = Vec::with_capacity(bytes.len() + extra);
    let mut pos = 0;
    for (start, end, _, text) in &splices {
        out.extend_from_slice(&bytes[pos..*start]);
        out.extend_from_slice(text);
        pos = *end;
    }
    out.extend_from_slice(&bytes[pos..]);
    out
}

/// An inserted word: `letter [=] number`, or where the letter's word before it is in a
/// direction form ([`inserted_form`]), `letter=FORM(number)`.
fn inserted(
    text: &mut Vec<u8>,
    program: &Program,
    block: usize,
    letter: u8,
    style: &NumberStyle,
    file: &FileStyle,
    number: &str,
) {
    text.push(letter);
    let form = inserted_form(program, block, letter);
    if form.is_directional() {
        text.push(b'=');
        text.extend_from_slice(form.name().as_bytes());
        text.push(b'(');
        text.extend_from_slice(number.as_bytes());
        text.push(b')');
        return;
    }
    if style.equals {
        text.push(b'=');
    }
    text.extend_from_slice(file.letter_gap);
    text.extend_from_slice(number.as_bytes());
}

/// The form a word of `letter` inserted into `block` is written in: that of the last word
/// of the letter before it (`C=DC(…)` in a program that writes them), else of the first
/// after it (a stretch of a file may start at the block), else plain.
pub fn inserted_form(program: &Program, block: usize, letter: u8) -> RotaryForm {
    if !matches!(letter, b'A' | b'B' | b'C') {
        return RotaryForm::Plain;
    }
    let words = program.blocks[block].words();
    program.words[..words.start]
        .iter()
        .rev()
        .chain(&program.words[words.end..])
        .find(|w| w.letter == letter)
        .map_or(RotaryForm::Plain, |w| w.form)
}

/// Position of `letter` in X Y Z A B C order; other letters come after.
fn rank(letter: u8) -> usize {
    AXES.iter().position(|&l| l == letter).unwrap_or(AXES.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dialect, parse};

    fn edit(src: &str, edits: &[Edit]) -> String {
        let p = parse(src.as_bytes().to_vec(), Dialect::Auto).unwrap();
        String::from_utf8(write(&p, edits)).unwrap()
    }

    fn c(block: usize, value: f64) -> Edit {
        Edit {
            block,
            letter: b'C',
            value,
            decimals: 3,
        }
    }

    #[test]
    fn no_edits_is_a_copy() {
        let src = "N1 G01 X+1 C+12.5 *\r\nN2 C+13 *";
        assert_eq!(edit(src, &[]), src);
    }

    #[test]
    fn replaces_only_the_number() {
        let src = "N1 G01 X+1 C+12.5 *\nN2 X+2 C+13.125 *\n";
        assert_eq!(
            edit(src, &[c(0, 12.25)]),
            "N1 G01 X+1 C+12.25 *\nN2 X+2 C+13.125 *\n"
        );
        assert_eq!(
            edit(src, &[c(1, -0.0001), c(0, 180.0)]),
            "N1 G01 X+1 C+180 *\nN2 X+2 C+0 *\n"
        );
        assert_eq!(
            edit("N10 G1 X=1.25 C=30\n", &[c(0, 31.5)]),
            "N10 G1 X=1.25 C=31.5\n"
        );
    }

    /// A word inserted right before a byte that would run on into its number gets a blank
    /// after it (a Sinumerik `=` value ends at a blank; here the block's `(` opens text the
    /// reader takes as a comment).
    #[test]
    fn an_inserted_word_never_runs_into_what_follows() {
        let out = edit("N10 X1 A=2 C=3\nN20 X2(5 Y1\n", &[c(1, 4.5)]);
        assert_eq!(out, "N10 X1 A=2 C=3\nN20 X2 C=4.500 (5 Y1\n");
        let p = parse(out.into_bytes(), Dialect::Auto).unwrap();
        assert_eq!(p.word(1, b'C').unwrap().value, 4.5);
        // Before a letter, a blank or (without `=`) a comment nothing is added.
        assert_eq!(
            edit("N1 X1 C2\nN2 X2Y3\n", &[c(1, 7.0)]),
            "N1 X1 C2\nN2 X2Y3C7.000\n"
        );
        assert_eq!(
            edit("N1 X1 C2\nN2 X2(c)\n", &[c(1, 7.0)]),
            "N1 X1 C2\nN2 X2 C7.000(c)\n"
        );
    }

    #[test]
    fn inserts_in_the_file_way() {
        let src = "N1 G01 X+1 Y+2 Z+3 A+4 C+12.5 F100 *\nN2 X+2 A+5 F200 *\nN3 F300 *\n";
        assert_eq!(
            edit(src, &[c(1, 13.0), c(2, 14.0)]),
            "N1 G01 X+1 Y+2 Z+3 A+4 C+12.5 F100 *\nN2 X+2 A+5 C+13 F200 *\nN3 F300 C+14 *\n"
        );
        // Without spaces, and with a comment at the end.
        let src = "G1 X1. Y2. C3.5\nG1X10.Y5.(CUT)\nX11.\tY5.\n";
        assert_eq!(
            edit(src, &[c(1, 4.0), c(2, 4.5)]),
            "G1 X1. Y2. C3.5\nG1X10.Y5.C4.(CUT)\nX11.\tY5.\tC4.5\n"
        );
        // Two insertions at one place keep X Y Z A B C order.
        let ab = [
            Edit {
                block: 0,
                letter: b'C',
                value: 1.0,
                decimals: 1,
            },
            Edit {
                block: 0,
                letter: b'A',
                value: 2.0,
                decimals: 1,
            },
        ];
        assert_eq!(
            edit("G1 X1.5 Y2.5 F100\n", &ab),
            "G1 X1.5 Y2.5 A2.0 C1.0 F100\n",
            "fixed one decimal"
        );
    }

    /// An axis letter earlier than every axis word of the block goes before the first of
    /// them (`X Y` into `G1 Z… C… F…`), not after F.
    #[test]
    fn inserts_keep_axis_order_when_nothing_precedes() {
        let xy = [
            Edit {
                block: 0,
                letter: b'Y',
                value: -2.076,
                decimals: 3,
            },
            Edit {
                block: 0,
                letter: b'X',
                value: -5.105,
                decimals: 3,
            },
        ];
        assert_eq!(
            edit("N70 G1 Z-1.497 C45.631 F800.\n", &xy),
            "N70 G1 X-5.105 Y-2.076 Z-1.497 C45.631 F800.\n"
        );
        assert_eq!(
            edit("G1X1.Z2.\n", &xy[..1]),
            "G1X1.Y-2.076Z2.\n",
            "after X, before Z, no gap in a tight file"
        );
    }

    #[test]
    fn last_edit_of_a_pair_wins() {
        assert_eq!(
            edit("G1 X1.5 Y2 C1.5\n", &[c(0, 2.0), c(0, 3.0)]),
            "G1 X1.5 Y2 C3\n"
        );
    }
}
