//! Edit planning: the words a rewrite must add so that nothing but the intended values
//! change.
//!
//! A block that relies on a modal axis value (it has no word for that letter) inherits
//! whatever the blocks before it left. When an edit changes the value of a letter in a
//! block, the next move after it that has no word for that letter would inherit the new
//! value and move differently: [`restore_modal`] gives that move its original value
//! explicitly, written in the file's style.

use crate::modal::{AXES, X, Z};
use crate::program::Program;
use crate::writer::Edit;

/// For every edit, find the next block after it that moves or carries the edited letter;
/// when that block has no word for the letter and is not edited for it itself, add an edit
/// that writes the letter's original modal value there (so the move after the rewritten
/// stretch goes where it went before). `decimals_of(letter)` gives the decimals to write
/// the restored value with (the file's).
///
/// Only axis letters (X Y Z A B C) are restored; linear values are written back in the
/// units of the file (inch programs are read in mm). `allow(edited_block, block)` says
/// whether a restoring word may go into `block` for an edit of `edited_block` (a caller
/// may forbid words outside the stretch it rewrote). Edits are appended; the order of
/// `edits` is otherwise kept.
pub fn restore_modal(
    program: &Program,
    edits: &mut Vec<Edit>,
    decimals_of: &dyn Fn(u8) -> usize,
    allow: &dyn Fn(usize, usize) -> bool,
) {
    use std::collections::HashSet;
    let edited: HashSet<(usize, u8)> = edits.iter().map(|e| (e.block, e.letter)).collect();
    // Only the last edit of each letter before a block that relies on it matters; visiting
    // every edit costs a short forward scan each (runs are consecutive blocks).
    let mut added: HashSet<(usize, u8)> = HashSet::new();
    let mut extra = Vec::new();
    for e in edits.iter() {
        let Some(idx) = AXES.iter().position(|&l| l == e.letter) else {
            continue;
        };
        let next = (e.block + 1..program.blocks.len())
            .find(|&b| program.blocks[b].is_move || program.word(b, e.letter).is_some());
        let Some(b) = next else { continue };
        if edited.contains(&(b, e.letter))
            || program.word(b, e.letter).is_some()
            || !allow(e.block, b)
            || !added.insert((b, e.letter))
        {
            continue;
        }
        let st = program.state(b);
        if let Some(v) = st.pos[idx] {
            let v = if (X..=Z).contains(&idx) && st.inch {
                v / 25.4
            } else {
                v
            };
            extra.push(Edit {
                block: b,
                letter: e.letter,
                value: v,
                decimals: decimals_of(e.letter),
            });
        }
    }
    edits.extend(extra);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dialect, parse, write};

    fn c(block: usize, value: f64) -> Edit {
        Edit {
            block,
            letter: b'C',
            value,
            decimals: 3,
        }
    }

    /// The move after an edited block relied on modal C: it gets its old C written out,
    /// and a block that carries its own C is left alone.
    #[test]
    fn next_move_keeps_its_position() {
        let src = "G1 X0 Y0 Z0 A1 C10.5 F100\nX1 C20.25\nX2\nX3 C40.125\n";
        let p = parse(src.as_bytes().to_vec(), Dialect::Auto).unwrap();
        let mut edits = vec![c(1, 25.0)];
        restore_modal(&p, &mut edits, &|_| 3, &|_, _| true);
        assert_eq!(edits.len(), 2);
        let out = String::from_utf8(write(&p, &edits)).unwrap();
        assert_eq!(
            out,
            "G1 X0 Y0 Z0 A1 C10.5 F100\nX1 C25\nX2 C20.25\nX3 C40.125\n"
        );
        // Consecutive edits: only the block after the last one is restored.
        let mut edits = vec![c(1, 25.0), c(2, 30.0)];
        restore_modal(&p, &mut edits, &|_| 3, &|_, _| true);
        assert_eq!(edits.len(), 2, "block 3 has its own C");
        // A caller that forbids words outside its stretch gets none.
        let mut edits = vec![c(1, 25.0)];
        restore_modal(&p, &mut edits, &|_| 3, &|_, b| b <= 1);
        assert_eq!(edits.len(), 1);
    }

    /// Comments and non-moves between the edit and the next move are skipped; the primary
    /// letter is restored like C; an inch program gets its linear value back in inches.
    #[test]
    fn skips_non_moves_and_handles_every_axis_letter() {
        let src = "G20 G1 X0 Y0 Z0 A1 C10 F10\n(NOTE)\nX1 A2 C20\nM8\nY2\n";
        let p = parse(src.as_bytes().to_vec(), Dialect::Auto).unwrap();
        let mut edits = vec![
            Edit {
                block: 2,
                letter: b'A',
                value: -2.0,
                decimals: 3,
            },
            Edit {
                block: 2,
                letter: b'X',
                value: 1.5,
                decimals: 3,
            },
        ];
        restore_modal(&p, &mut edits, &|_| 1, &|_, _| true);
        let out = String::from_utf8(write(&p, &edits)).unwrap();
        assert_eq!(
            out,
            "G20 G1 X0 Y0 Z0 A1 C10 F10\n(NOTE)\nX1.500 A-2.000 C20\nM8\nX1.0 Y2 A2.0\n"
        );
    }
}
