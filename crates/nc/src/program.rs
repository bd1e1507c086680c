//! A parsed program ([`Program`]): its blocks, words with byte spans and modal states. The
//! one reader makes them (`reader.rs`: [`crate::scan_blocks`], which every other way of
//! reading is built on: [`crate::scan`], [`crate::parse`] through [`crate::ProgramBuilder`]
//! in `builder.rs`, and the stretch reader of the library).

// The basic types and dialect detection, at the paths they had when they lived here.
pub use crate::block::{Block, Flags};
pub use crate::detect::detect;
pub use crate::dialect::Dialect;
use crate::lines::LineEnds;
use crate::modal::{Modal, PackedModal};
pub use crate::word::{RotaryForm, Word};

/// A parsed program. Owns the bytes it was parsed from.
#[derive(Debug, Clone)]
pub struct Program {
    /// The file as read.
    pub bytes: Vec<u8>,
    /// Every line, in order.
    pub blocks: Vec<Block>,
    /// All words of all blocks, in file order.
    pub words: Vec<Word>,
    /// Dialect used.
    pub dialect: Dialect,
    /// Datum shifts that state their values (Heidenhain ISO `G54 X… Y… Z…`), in file order:
    /// the block and the new datum's X Y Z (mm; a missing axis is 0). A work-offset
    /// selection that only names a register (Fanuc/Sinumerik `G54`) is not here.
    pub datum_shifts: Vec<(usize, [f64; 3])>,
    /// Blocks that change the coordinate frame without stating it: a work-offset selection
    /// by name (Fanuc/Sinumerik `G54`…`G59`, `G500`…) or a shift/rotation whose values
    /// polepatch does not follow (`G92`, `G52`, `G10`, `TRANS`, `ROT`, …), in file order.
    pub frame_changes: Vec<usize>,
    /// Modal states, one per change: block `b`'s state is `states[blocks[b].state]`.
    pub(crate) states: Vec<PackedModal>,
    /// The file's line ending.
    pub line_ends: LineEnds,
}

impl Program {
    /// The words of a block.
    pub fn block_words(&self, block: usize) -> &[Word] {
        &self.words[self.blocks[block].words()]
    }
    /// The modal state after `block`.
    pub fn state(&self, block: usize) -> Modal {
        self.states[self.blocks[block].state as usize].unpack()
    }
    /// The modal state in force before `block` (the state after the previous block; for
    /// the first, the power-on default, or for a stretch of a file built with
    /// [`ProgramBuilder`](crate::ProgramBuilder) the state it starts from).
    pub fn state_before(&self, block: usize) -> Modal {
        block
            .checked_sub(1)
            .map_or_else(|| self.states[0].unpack(), |b| self.state(b))
    }
    /// The word with `letter` in a block, if any (the last one if repeated).
    pub fn word(&self, block: usize, letter: u8) -> Option<&Word> {
        self.block_words(block)
            .iter()
            .rev()
            .find(|w| w.letter == letter)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modal::X;
    use crate::parse;

    fn p(s: &str) -> Program {
        parse(s.as_bytes().to_vec(), Dialect::Auto).unwrap()
    }

    #[test]
    fn state_before() {
        let prog = p("G1 X1\nX2\n");
        assert_eq!(prog.state_before(0), Modal::default());
        assert_eq!(prog.state_before(1).pos[X], Some(1.0));
    }
}
