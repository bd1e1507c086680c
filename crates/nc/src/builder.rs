//! Building a [`Program`] from the reader's blocks: [`parse`] a whole file,
//! [`ProgramBuilder`] a stretch of one.

use crate::block::Block;
use crate::dialect::Dialect;
use crate::error::ParseError;
use crate::lines::LineEnds;
use crate::modal::{Modal, PackedModal};
use crate::program::Program;
use crate::reader::{Scanned, Settled, scan_blocks_with};
use crate::tcpm::ReadOptions;
use crate::word::Word;

/// Parse `bytes`. Errors name line and column: malformed or non-finite numbers on address
/// words, an axis word twice in a block, and the like. Unknown words and tokens are kept,
/// not rejected; a block whose axis or feed words are expressions is kept and flagged
/// ([`Flags::NOT_ANALYSABLE`]).
///
/// Every line (see [`crate::lines`]) is one [`Block`]. See [`crate::lexer`] for the token
/// rules and [`crate::modal`] for how the modal state follows the blocks. This is
/// [`scan_blocks`] collected by a [`ProgramBuilder`].
///
/// [`Flags::NOT_ANALYSABLE`]: crate::Flags::NOT_ANALYSABLE
/// [`scan_blocks`]: crate::scan_blocks
pub fn parse(bytes: Vec<u8>, dialect: Dialect) -> Result<Program, ParseError> {
    parse_with(bytes, &ReadOptions::dialect(dialect))
}

/// [`parse`] with the machine's TCPM codes.
pub fn parse_with(bytes: Vec<u8>, opts: &ReadOptions) -> Result<Program, ParseError> {
    let mut opts = opts.clone();
    loop {
        let mut builder = ProgramBuilder::new(0, &opts.initial());
        // Reserved from the size: lines of NC code are rarely shorter than 24 bytes or words
        // than 6; untouched capacity costs address space only, a reallocation a copy. A
        // machine that cannot give the memory gets an error, not an abort.
        builder.reserve(bytes.len()).map_err(|what| {
            ParseError::at(
                1,
                1,
                format!(
                    "not enough memory to read a program of {} bytes ({what})",
                    bytes.len()
                ),
            )
        })?;
        match scan_blocks_with(&bytes, &opts, |s| {
            builder.push(&s);
            std::ops::ControlFlow::Continue(())
        })? {
            Settled::Done(dialect) => return Ok(builder.finish(bytes, dialect)),
            Settled::Again(settled) => opts = settled,
        }
    }
}

/// A [`Program`] for a stretch of a larger file, built from the blocks [`scan_blocks`]
/// gives (consecutive ones): block indices count from the stretch's first block, byte
/// offsets from its first byte, line numbers and modal states are the file's. The
/// stretch's [`Program::datum_shifts`] and [`Program::frame_changes`] are its own.
///
/// [`scan_blocks`]: crate::scan_blocks
#[derive(Debug)]
pub struct ProgramBuilder {
    base: usize,
    blocks: Vec<Block>,
    words: Vec<Word>,
    states: Vec<PackedModal>,
    last: Modal,
    datum_shifts: Vec<(usize, [f64; 3])>,
    frame_changes: Vec<usize>,
    line_ends: LineEnds,
}

impl ProgramBuilder {
    /// A stretch that starts with a block at byte `base` of the file, in modal state
    /// `before` (the state after the block before it).
    pub fn new(base: usize, before: &Modal) -> Self {
        ProgramBuilder {
            base,
            blocks: Vec::new(),
            words: Vec::new(),
            states: vec![PackedModal::pack(before)],
            last: *before,
            datum_shifts: Vec::new(),
            frame_changes: Vec::new(),
            line_ends: LineEnds::Lf,
        }
    }

    /// Reserve room for a program of `bytes` bytes (lines of NC code are rarely shorter
    /// than 24 bytes, words than 6): the error names what could not be allocated.
    pub fn reserve(&mut self, bytes: usize) -> Result<(), &'static str> {
        self.blocks
            .try_reserve(bytes / 24 + 1)
            .map_err(|_| "blocks")?;
        self.words.try_reserve(bytes / 6 + 1).map_err(|_| "words")?;
        self.states
            .try_reserve(bytes / 24 + 1)
            .map_err(|_| "modal states")?;
        Ok(())
    }

    /// Byte offset of the stretch in the file.
    pub fn base(&self) -> usize {
        self.base
    }

    /// Blocks taken so far.
    pub fn len(&self) -> usize {
        self.blocks.len()
    }

    /// Whether no block was taken yet.
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// Take the next block of the file.
    ///
    /// # Panics
    /// If the block starts before the stretch.
    pub fn push(&mut self, s: &Scanned<'_>) {
        let base = u32::try_from(self.base).unwrap_or(u32::MAX);
        assert!(s.block.start >= base, "block before the stretch");
        if *s.state != self.last {
            self.last = *s.state;
            self.states.push(PackedModal::pack(s.state));
        }
        let first = self.words.len();
        self.words
            .extend(s.words[s.block.words()].iter().map(|w| Word {
                start: w.start - base,
                value_start: w.value_start - base,
                end: w.end - base,
                ..w.clone()
            }));
        if let Some(d) = s.stated_datum {
            self.datum_shifts.push((self.blocks.len(), d));
        }
        if s.frame_changed {
            self.frame_changes.push(self.blocks.len());
        }
        self.line_ends = s.line_ends;
        self.blocks.push(Block {
            start: s.block.start - base,
            end: s.block.end - base,
            words_start: first as u32,
            words_end: self.words.len() as u32,
            state: (self.states.len() - 1) as u32,
            ..s.block.clone()
        });
    }

    /// The program of the stretch: `bytes` are the file's bytes from the stretch's first
    /// byte (at least up to the end of its last block).
    ///
    /// # Panics
    /// If `bytes` is shorter than the blocks taken.
    pub fn finish(self, bytes: Vec<u8>, dialect: Dialect) -> Program {
        if let Some(b) = self.blocks.last() {
            assert!(
                b.end as usize <= bytes.len(),
                "bytes shorter than the blocks"
            );
        }
        Program {
            bytes,
            blocks: self.blocks,
            words: self.words,
            dialect,
            datum_shifts: self.datum_shifts,
            frame_changes: self.frame_changes,
            states: self.states,
            line_ends: self.line_ends,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reader::scan_with;
    use crate::reader::tests::big;

    /// A stretch built from scanned blocks is the whole program's, re-based: the same
    /// lines, words, states (before its first block too), frame changes and bytes.
    #[test]
    fn program_builder_gives_the_stretch_of_the_whole_program() {
        let bytes = big(2);
        let prog = parse(bytes.clone(), Dialect::Auto).unwrap();
        let n = prog.blocks.len();
        for (from, to) in [(0, 10), (1, 2), (5, 3000), (n - 50, n), (990, 1010)] {
            let base = prog.blocks[from].span().start;
            let mut builder = ProgramBuilder::new(base, &prog.state_before(from));
            let mut i = 0;
            let settled = scan_with(&bytes, &ReadOptions::default(), 2, |s| {
                if (from..to).contains(&i) {
                    builder.push(&s);
                }
                i += 1;
                std::ops::ControlFlow::Continue(())
            })
            .unwrap();
            assert!(matches!(settled, Settled::Done(_)));
            let end = prog.blocks[to - 1].span().end;
            let sub = builder.finish(bytes[base..end].to_vec(), prog.dialect);
            assert_eq!(sub.blocks.len(), to - from);
            assert_eq!(sub.state_before(0), prog.state_before(from));
            for k in 0..to - from {
                let (a, b) = (&sub.blocks[k], &prog.blocks[from + k]);
                assert_eq!(a.line, b.line);
                assert_eq!(&sub.bytes[a.span()], &bytes[b.span()]);
                assert_eq!(sub.state(k), prog.state(from + k));
                let (wa, wb) = (sub.block_words(k), prog.block_words(from + k));
                assert_eq!(wa.len(), wb.len());
                for (x, y) in wa.iter().zip(wb) {
                    assert_eq!(&sub.bytes[x.value_span()], &bytes[y.value_span()]);
                    assert_eq!((x.letter, x.value), (y.letter, y.value));
                }
            }
            let local = |v: &[usize]| -> Vec<usize> {
                v.iter()
                    .filter(|&&b| (from..to).contains(&b))
                    .map(|b| b - from)
                    .collect()
            };
            assert_eq!(sub.frame_changes, local(&prog.frame_changes));
            let shifts: Vec<usize> = prog.datum_shifts.iter().map(|d| d.0).collect();
            let sub_shifts: Vec<usize> = sub.datum_shifts.iter().map(|d| d.0).collect();
            assert_eq!(sub_shifts, local(&shifts));
        }
        assert!(!prog.frame_changes.is_empty() && !prog.datum_shifts.is_empty());
    }
}
