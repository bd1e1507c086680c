//! Blocks: one line of the file each, its words' range and what it does.

use std::ops::Range;

/// What a block does beyond moving: a set of bits ([`Flags::has`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Flags(u16);

impl Flags {
    /// The block carries a block-delete marker (`/`): it may be skipped.
    pub const SKIPPABLE: Flags = Flags(1);
    /// An axis or feed word is an expression or a variable (`A#<a>`, `X=R1+2`, `X+Q5`):
    /// the block cannot be analysed and its axes are unknown after it.
    pub const NOT_ANALYSABLE: Flags = Flags(2);
    /// A tool change (`T…`, `M6`, `TOOL CALL`).
    pub const TOOL_CHANGE: Flags = Flags(4);
    /// The program's end (`M2`, `M30`, `END PGM`).
    pub const PROGRAM_END: Flags = Flags(8);
    /// A circular or polar move (`G2`/`G3`, conversational `C`, `CR`, `CT`, `CP`, `LP`,
    /// `APPR`, `DEP`): polepatch does not follow its path; it ends runs.
    pub const ARC: Flags = Flags(16);
    /// Conversational incremental axis words (`IX+5`): the block ends runs and is never
    /// changed.
    pub const INCREMENTAL_WORDS: Flags = Flags(32);
    /// A `(` comment without its `)` hides what looks like axis words.
    pub const UNCLOSED_COMMENT: Flags = Flags(64);
    /// A conversational line polepatch does not model, which may move the machine: carried
    /// through, positions unknown after it.
    pub const NOT_MODELLED: Flags = Flags(128);
    /// The block states the length units (G20/G21, G70/G71, G700/G710, a `%NAME G71`
    /// header, `BEGIN PGM … MM|INCH`).
    pub const UNITS: Flags = Flags(256);
    /// A feed move with tool-tip motion whose plain absolute word turns a rotary axis by
    /// more than half a turn, on an axis that turns without end
    /// ([`crate::ReadOptions::endless`]) or under Heidenhain `M126`: a controller that takes
    /// the shorter way turns it the other way round (359.857° → 7.501° is +7.644°, not
    /// −352.356°). Which one the machine does is not in the program: the block ends runs,
    /// belongs to none and is never changed.
    pub const ROTARY_WRAP: Flags = Flags(512);
    /// The block may say something of the tool (a `T`, a comment, `M6`, a `*` line): the
    /// tool reader ([`crate::tooldesc`]) looks at its text; other blocks only end a group of
    /// descriptions.
    pub const MAY_NAME_TOOL: Flags = Flags(1024);

    /// Whether every bit of `other` is set.
    pub fn has(self, other: Flags) -> bool {
        self.0 & other.0 == other.0
    }
    /// Set the bits of `other`.
    pub fn set(&mut self, other: Flags) {
        self.0 |= other.0;
    }
    /// Clear the bits of `other`.
    pub(crate) fn clear(&mut self, other: Flags) {
        self.0 &= !other.0;
    }
}

/// One line of the file (a block, a comment line, a `%` line, or empty).
///
/// 32 bytes: offsets are `u32`, and the modal state is kept once per change in the
/// [`crate::Program`] (read it with [`crate::Program::state`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    /// 1-based line number.
    pub line: usize,
    pub(crate) start: u32,
    pub(crate) end: u32,
    pub(crate) words_start: u32,
    pub(crate) words_end: u32,
    /// Index of the modal state after this block in the program's state table.
    pub(crate) state: u32,
    /// The block moves the tool tip or a rotary axis (a G0/G1/G2/G3 move with axis words,
    /// not a datum shift or other non-move use of axis letters).
    pub is_move: bool,
    /// Why this block ends any run of G1 motion (beyond being a non-G1 move), if it does.
    pub breaks_run: bool,
    /// What else the block does.
    pub flags: Flags,
}

impl Block {
    /// Bytes of the line, without its line ending.
    pub fn span(&self) -> Range<usize> {
        self.start as usize..self.end as usize
    }
    /// Indices into [`crate::Program::words`] of this block's words.
    pub fn words(&self) -> Range<usize> {
        self.words_start as usize..self.words_end as usize
    }
    /// Index of the block's modal state in the program's state table: equal indices of
    /// neighbouring blocks mean an equal state (states are stored once per change).
    pub(crate) fn state_index(&self) -> u32 {
        self.state
    }
}
