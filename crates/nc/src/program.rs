//! Parsed program: blocks, words with byte spans, modal state.

use crate::{
    error::ParseError,
    lexer::{Lexer, Token},
    modal::{A, B, C, Modal, Motion, PackedModal, X, Y, Z},
};
use std::ops::Range;

/// Dialect of the file (detected, or forced by the caller).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// Detect from the text (`*` block ends or `%NAME G71` → Heidenhain; `TRAORI`/`;`
    /// comments → Sinumerik; `( )` comments / G43.4 → Fanuc). Reading rules are shared.
    Auto,
    /// Heidenhain in ISO mode.
    Heidenhain,
    /// Siemens Sinumerik.
    Sinumerik,
    /// Fanuc and Fanuc-like.
    Fanuc,
}

/// One address word such as `C+148.494`, `X-.5`, `G01`, `X=10`.
///
/// Offsets are `u32` (a program is at most 4 GiB, see [`parse`]) so that a word takes 24
/// bytes: a large program holds millions of them.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    /// Upper-case letter.
    pub letter: u8,
    /// Byte offset of the letter in the file.
    pub start: u32,
    /// Byte offset of the number (its sign, if any) in the file.
    pub value_start: u32,
    /// Byte offset just past the last digit.
    pub end: u32,
    /// Numeric value as written (no unit conversion).
    pub value: f64,
}

impl Word {
    /// Bytes of the whole word (letter to last digit) in the file.
    pub fn span(&self) -> Range<usize> {
        self.start as usize..self.end as usize
    }
    /// Bytes of the number (sign included) in the file.
    pub fn value_span(&self) -> Range<usize> {
        self.value_start as usize..self.end as usize
    }
}

/// One line of the file (a block, a comment line, a `%` line, or empty).
///
/// 32 bytes: offsets are `u32`, and the modal state is kept once per change in the
/// [`Program`] (read it with [`Program::state`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Block {
    /// 1-based line number.
    pub line: usize,
    start: u32,
    end: u32,
    words_start: u32,
    words_end: u32,
    /// Index of the modal state after this block in the program's state table.
    state: u32,
    /// The block moves the tool tip or a rotary axis (a G0/G1/G2/G3 move with axis words,
    /// not a datum shift or other non-move use of axis letters).
    pub is_move: bool,
    /// Why this block ends any run of G1 motion (beyond being a non-G1 move), if it does.
    pub breaks_run: bool,
}

impl Block {
    /// Bytes of the line, without its line ending.
    pub fn span(&self) -> Range<usize> {
        self.start as usize..self.end as usize
    }
    /// Indices into [`Program::words`] of this block's words.
    pub fn words(&self) -> Range<usize> {
        self.words_start as usize..self.words_end as usize
    }
    /// Index of the block's modal state in the program's state table: equal indices of
    /// neighbouring blocks mean an equal state (states are stored once per change).
    pub(crate) fn state_index(&self) -> u32 {
        self.state
    }
}

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
    states: Vec<PackedModal>,
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
    /// [`ProgramBuilder`] the state it starts from).
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

/// Parse `bytes`. Errors name line and column: malformed or non-finite numbers on address
/// words, an axis word whose value is an expression, and the like. Unknown words and
/// tokens are kept, not rejected.
///
/// Every line (split at `\n`; a `\r` before it belongs to the line ending) is one
/// [`Block`]; a final line without a newline is a block too, a final empty segment after
/// the last newline is not. See [`crate::lexer`] for the token rules and
/// [`crate::modal`] for how the modal state follows the blocks.
pub fn parse(bytes: Vec<u8>, dialect: Dialect) -> Result<Program, ParseError> {
    if u32::try_from(bytes.len()).is_err() {
        return Err(too_big(bytes.len()));
    }
    let dialect = match dialect {
        Dialect::Auto => detect(&bytes),
        d => d,
    };
    // Reserved from the size: lines of NC code are rarely shorter than 24 bytes or words
    // than 6; untouched capacity costs address space only, a reallocation a copy.
    let mut blocks = Vec::with_capacity(bytes.len() / 24 + 1);
    let mut words = Vec::with_capacity(bytes.len() / 6 + 1);
    let mut states = Vec::with_capacity(bytes.len() / 24 + 1);
    let mut interp = Interpreter::new(dialect);
    let mut last = interp.modal;
    states.push(PackedModal::pack(&last));
    for (span, line) in lines(&bytes) {
        let mut block = interp.block(&bytes, span, line, &mut words)?;
        if interp.modal != last {
            last = interp.modal;
            states.push(PackedModal::pack(&last));
        }
        // At most one state per block plus the initial one, so at most 2^32 - 1.
        block.state = (states.len() - 1) as u32;
        if let Some(d) = interp.stated_datum.take() {
            interp.datum_shifts.push((blocks.len(), d));
        }
        if std::mem::take(&mut interp.frame_changed) {
            interp.frame_changes.push(blocks.len());
        }
        blocks.push(block);
    }
    Ok(Program {
        bytes,
        blocks,
        words,
        dialect,
        datum_shifts: interp.datum_shifts,
        frame_changes: interp.frame_changes,
        states,
    })
}

/// The lines of `bytes` with their 1-based numbers: split at `\n`, a `\r` before it
/// belongs to the line ending; a final line without a newline is a line, a final empty
/// segment after the last newline is not.
fn lines(bytes: &[u8]) -> impl Iterator<Item = (Range<usize>, usize)> + '_ {
    lines_from(bytes, 0)
}

/// [`lines`] from byte `start` (a line start), numbered from 1 there.
fn lines_from(bytes: &[u8], start: usize) -> impl Iterator<Item = (Range<usize>, usize)> + '_ {
    let n = bytes.len();
    let mut start = start;
    let mut line = 0;
    std::iter::from_fn(move || {
        if start >= n {
            return None;
        }
        let (end, next) = match find_newline(bytes, start) {
            Some(nl) => (
                if nl > start && bytes[nl - 1] == b'\r' {
                    nl - 1
                } else {
                    nl
                },
                nl + 1,
            ),
            None => (n, n),
        };
        let span = start..end;
        start = next;
        line += 1;
        Some((span, line))
    })
}

/// Read `bytes` block by block without building a [`Program`]: `visit` gets each block
/// (its [`Block::words`] index the slice it is given), its words and the modal state after
/// it, in file order, and may stop the scan early with `ControlFlow::Break`. Memory is one
/// block's words. Same rules and the same errors, in the same order, as [`parse`] (which
/// reads the whole file and so also reports an error after a point where `visit` stopped).
///
/// Returns the dialect used (`Dialect::Auto` is detected as in [`parse`]).
pub fn scan(
    bytes: &[u8],
    dialect: Dialect,
    mut visit: impl FnMut(&Block, &[Word], &Modal) -> std::ops::ControlFlow<()>,
) -> Result<Dialect, ParseError> {
    scan_blocks(bytes, dialect, |s| visit(s.block, s.words, s.state))
}

/// One block as [`scan_blocks`] gives it.
#[derive(Debug, Clone, Copy)]
pub struct Scanned<'a> {
    /// The block; its [`Block::words`] index `words`.
    pub block: &'a Block,
    /// The block's words (offsets into the whole file).
    pub words: &'a [Word],
    /// The modal state after the block.
    pub state: &'a Modal,
    /// The datum the block states, as it goes into [`Program::datum_shifts`].
    pub stated_datum: Option<[f64; 3]>,
    /// The block changes the frame without stating it, as [`Program::frame_changes`].
    pub frame_changed: bool,
}

/// [`scan`], with what the block does to the coordinate frame.
pub fn scan_blocks(
    bytes: &[u8],
    dialect: Dialect,
    visit: impl FnMut(Scanned<'_>) -> std::ops::ControlFlow<()>,
) -> Result<Dialect, ParseError> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get().min(8));
    scan_with(bytes, dialect, threads, visit)
}

/// [`scan_blocks`] on `threads` threads.
fn scan_with(
    bytes: &[u8],
    dialect: Dialect,
    threads: usize,
    mut visit: impl FnMut(Scanned<'_>) -> std::ops::ControlFlow<()>,
) -> Result<Dialect, ParseError> {
    if u32::try_from(bytes.len()).is_err() {
        return Err(too_big(bytes.len()));
    }
    let dialect = match dialect {
        Dialect::Auto => detect(bytes),
        d => d,
    };
    let mut interp = Interpreter::new(dialect);
    let mut give = |interp: &mut Interpreter, block: &Block, words: &[Word]| {
        visit(Scanned {
            block,
            words,
            state: &interp.modal,
            stated_datum: interp.stated_datum.take(),
            frame_changed: std::mem::take(&mut interp.frame_changed),
        })
    };
    if threads <= 1 || bytes.len() < SCAN_WINDOW_BYTES {
        let mut words = Vec::with_capacity(32);
        for (span, line) in lines(bytes) {
            words.clear();
            let block = interp.block(bytes, span, line, &mut words)?;
            if give(&mut interp, &block, &words).is_break() {
                break;
            }
        }
        return Ok(dialect);
    }
    // Windows of about SCAN_WINDOW_BYTES, each cut at newlines into one part per thread;
    // the parts are lexed side by side (lexing needs only the dialect), then applied to
    // the modal state in file order. Memory: one window's words and line summaries.
    let mut line_offset = 0usize;
    let mut from = 0usize;
    let mut parts: Vec<LexedPart> = (0..threads).map(|_| LexedPart::default()).collect();
    while from < bytes.len() {
        let to = cut_after(bytes, from + SCAN_WINDOW_BYTES);
        let mut cuts = vec![from];
        for k in 1..threads {
            let c = cut_after(bytes, from + (to - from) * k / threads).min(to);
            cuts.push(c.max(*cuts.last().unwrap_or(&from)));
        }
        cuts.push(to);
        let interp_ref = &interp;
        std::thread::scope(|sc| {
            let (first, rest) = parts.split_at_mut(1);
            let handles: Vec<_> = cuts
                .windows(2)
                .skip(1)
                .zip(rest.iter_mut())
                .map(|(w, part)| {
                    let (a, b) = (w[0], w[1]);
                    sc.spawn(move || interp_ref.lex_part(bytes, a..b, part))
                })
                .collect();
            interp_ref.lex_part(bytes, cuts[0]..cuts[1], &mut first[0]);
            for h in handles {
                h.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
            }
        });
        for part in &mut parts {
            for (k, (span, scan, words)) in part.lines.drain(..).enumerate() {
                let line = line_offset + k + 1;
                let ws = &part.words[words];
                let block = interp.apply(scan, line, span, 0..ws.len());
                if give(&mut interp, &block, ws).is_break() {
                    return Ok(dialect);
                }
            }
            line_offset += part.line_count;
            if let Some(mut e) = part.error.take() {
                e.line += line_offset - part.line_count;
                return Err(e);
            }
        }
        from = to;
    }
    Ok(dialect)
}

/// A [`Program`] for a stretch of a larger file, built from the blocks [`scan_blocks`]
/// gives (consecutive ones): block indices count from the stretch's first block, byte
/// offsets from its first byte, line numbers and modal states are the file's. The
/// stretch's [`Program::datum_shifts`] and [`Program::frame_changes`] are its own.
#[derive(Debug)]
pub struct ProgramBuilder {
    base: usize,
    blocks: Vec<Block>,
    words: Vec<Word>,
    states: Vec<PackedModal>,
    last: Modal,
    datum_shifts: Vec<(usize, [f64; 3])>,
    frame_changes: Vec<usize>,
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
        }
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
        }
    }
}

/// Size of the windows [`scan`] lexes on several threads at a time, bytes: large enough
/// that starting threads costs nothing, small enough that a window's words stay a small
/// part of any program worth doing this for.
const SCAN_WINDOW_BYTES: usize = 256 << 10;

/// One part of a window, lexed: per line (its span, what it says, its words' range in
/// `words`), up to the first error, which is kept with its line counted within the part.
/// Reused from window to window.
#[derive(Default)]
struct LexedPart {
    lines: Vec<(Range<usize>, Scan, Range<usize>)>,
    words: Vec<Word>,
    /// Lines in the part (all of them, also past an error).
    line_count: usize,
    error: Option<ParseError>,
}

/// The offset just past the newline at or after `at` (the end of `bytes` if none).
fn cut_after(bytes: &[u8], at: usize) -> usize {
    if at >= bytes.len() {
        return bytes.len();
    }
    find_newline(bytes, at).map_or(bytes.len(), |nl| nl + 1)
}

fn too_big(len: usize) -> ParseError {
    ParseError::at(
        1,
        1,
        format!("the file has {len} bytes; polepatch reads programs of at most 4 GiB"),
    )
}

/// Offset of the first `\n` at or after `from`, eight bytes at a time.
fn find_newline(bytes: &[u8], from: usize) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    const NL: u64 = LO * b'\n' as u64;
    let mut i = from;
    while let Some(chunk) = bytes.get(i..i + 8) {
        let x = u64::from_le_bytes(chunk.try_into().unwrap_or([0; 8])) ^ NL;
        // The lowest set bit marks the first zero byte of x, i.e. the first newline.
        let t = x.wrapping_sub(LO) & !x & HI;
        if t != 0 {
            return Some(i + (t.trailing_zeros() / 8) as usize);
        }
        i += 8;
    }
    bytes
        .get(i..)?
        .iter()
        .position(|&b| b == b'\n')
        .map(|k| i + k)
}

/// Guess the dialect from the first 64 KiB: a `*` block end or a `%NAME G71` header →
/// Heidenhain; `TRAORI`/`TRAFOOF` → Sinumerik; `( )` comments or `G43.4` → Fanuc; `;`
/// comments → Sinumerik; else Fanuc.
pub fn detect(bytes: &[u8]) -> Dialect {
    let head = &bytes[..bytes.len().min(64 * 1024)];
    let contains = |needle: &[u8]| {
        head.windows(needle.len())
            .any(|w| w.eq_ignore_ascii_case(needle))
    };
    for line in head.split(|&b| b == b'\n') {
        let code = match line.iter().position(|&b| b == b';') {
            Some(k) => &line[..k],
            None => line,
        };
        let trimmed = code.trim_ascii_end();
        if trimmed.ends_with(b"*") && !trimmed.starts_with(b"(") {
            return Dialect::Heidenhain;
        }
        if line.first() == Some(&b'%')
            && line
                .split(|b| b.is_ascii_whitespace())
                .any(|w| w.eq_ignore_ascii_case(b"G71") || w.eq_ignore_ascii_case(b"G70"))
        {
            return Dialect::Heidenhain;
        }
    }
    if contains(b"TRAORI") || contains(b"TRAFOOF") {
        Dialect::Sinumerik
    } else if head.contains(&b'(') || contains(b"G43.4") {
        Dialect::Fanuc
    } else if head.contains(&b';') {
        Dialect::Sinumerik
    } else {
        Dialect::Fanuc
    }
}

/// Feed interpretation (modal G group 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum FeedMode {
    /// G94: F is a feed per minute.
    PerMinute,
    /// G93 inverse time or G95 feed per revolution: F is not a feed in mm/min.
    Other,
}

/// `G`/`M` code number times ten (`G43.4` → 434, `M128` → 1280), if it is one.
fn code10(v: f64) -> Option<i64> {
    let t = v * 10.0;
    let r = t.round();
    ((t - r).abs() < 1e-6 && (0.0..1e9).contains(&r)).then_some(r as i64)
}

/// What one block says, collected before the modal state is updated.
#[derive(Default)]
struct Scan {
    axes: [Option<f64>; 6],
    feed: Option<f64>,
    motion: Option<Motion>,
    incremental: Option<bool>,
    inch: Option<bool>,
    tcpm: Option<bool>,
    feed_mode: Option<FeedMode>,
    /// Axis words define a datum/frame (Heidenhain G54, G92, G10, G52, TRANS…): not a move.
    datum_shift: bool,
    /// Heidenhain ISO `G54`: the block's X Y Z are the new datum.
    stated_datum: bool,
    /// Work offset selection (Fanuc/Sinumerik G54…G59, G500): positions re-based.
    work_offset: bool,
    /// Reference / machine-coordinate move (G28, G30, G53, SUPA).
    reference: bool,
    /// Axis words are arguments, not a move (G4 dwell, G65 macro call).
    no_move: bool,
    /// Positions are unknown afterwards (macro call).
    unknown_after: bool,
    breaks: bool,
}

struct Interpreter {
    dialect: Dialect,
    modal: Modal,
    feed_mode: FeedMode,
    /// The datum the last block stated (Heidenhain `G54 X Y Z`), taken by `parse`.
    stated_datum: Option<[f64; 3]>,
    /// All stated datums (see [`Program::datum_shifts`]).
    datum_shifts: Vec<(usize, [f64; 3])>,
    /// The last block changed the frame without stating it, taken by `parse`.
    frame_changed: bool,
    /// See [`Program::frame_changes`].
    frame_changes: Vec<usize>,
}

impl Interpreter {
    fn new(dialect: Dialect) -> Self {
        Interpreter {
            dialect,
            modal: Modal::default(),
            feed_mode: FeedMode::PerMinute,
            stated_datum: None,
            datum_shifts: Vec::new(),
            frame_changed: false,
            frame_changes: Vec::new(),
        }
    }

    fn g(&self, code: Option<i64>, s: &mut Scan) {
        let heidenhain = self.dialect == Dialect::Heidenhain;
        match code {
            Some(0) => s.motion = Some(Motion::Rapid),
            Some(10) => s.motion = Some(Motion::Linear),
            Some(20) => s.motion = Some(Motion::ArcCw),
            Some(30) => s.motion = Some(Motion::ArcCcw),
            // Plane, cutter compensation off, canned cycle off, path control modes.
            Some(170 | 180 | 190 | 400 | 800 | 600 | 610 | 640 | 6410..=6450) => {}
            Some(900) => s.incremental = Some(false),
            Some(910) => s.incremental = Some(true),
            Some(200 | 700 | 7000) => s.inch = Some(true),
            Some(210 | 710 | 7100) => s.inch = Some(false),
            Some(434 | 435) => s.tcpm = Some(true),
            Some(490) => s.tcpm = Some(false),
            Some(940) => s.feed_mode = Some(FeedMode::PerMinute),
            Some(930 | 950) => {
                s.feed_mode = Some(FeedMode::Other);
                s.breaks = true;
            }
            Some(540) if heidenhain => {
                s.datum_shift = true;
                s.stated_datum = true;
            }
            Some(530) if heidenhain => s.datum_shift = true,
            Some(540..=590 | 5000 | 5050..=5990) => s.work_offset = true,
            Some(920 | 100 | 520 | 500 | 510 | 680 | 681 | 690) => s.datum_shift = true,
            Some(530 | 280 | 300) => s.reference = true,
            Some(40) => {
                s.no_move = true;
                s.breaks = true;
            }
            Some(650 | 660) => {
                s.no_move = true;
                s.unknown_after = true;
                s.breaks = true;
            }
            _ => s.breaks = true,
        }
    }

    fn m(code: Option<i64>, s: &mut Scan) {
        match code {
            // Spindle and coolant.
            Some(30 | 40 | 50 | 70 | 80 | 90 | 130 | 140) => {}
            Some(1280) => s.tcpm = Some(true),
            Some(1290) => s.tcpm = Some(false),
            // Stops, end of program, tool change, anything unknown.
            _ => s.breaks = true,
        }
    }

    fn ident(name: &[u8], s: &mut Scan) {
        let is = |n: &[u8]| name.eq_ignore_ascii_case(n);
        if is(b"TRAORI") {
            s.tcpm = Some(true);
        } else if is(b"TRAFOOF") {
            s.tcpm = Some(false);
        } else if is(b"MSG") {
        } else if [
            &b"TRANS"[..],
            b"ATRANS",
            b"CTRANS",
            b"ROT",
            b"AROT",
            b"CROT",
            b"SCALE",
            b"ASCALE",
            b"MIRROR",
            b"AMIRROR",
        ]
        .iter()
        .any(|n| is(n))
        {
            s.datum_shift = true;
        } else if is(b"SUPA") {
            s.reference = true;
        } else {
            s.breaks = true;
        }
    }

    fn block(
        &mut self,
        bytes: &[u8],
        span: Range<usize>,
        line: usize,
        words: &mut Vec<Word>,
    ) -> Result<Block, ParseError> {
        let first_word = words.len();
        let s = self.lex(bytes, span.clone(), line, words)?;
        Ok(self.apply(s, line, span, first_word..words.len()))
    }

    /// Lex the lines of `range` (which starts at a line start and ends after a newline or
    /// at the end of the file), numbering them from 1 within the part.
    fn lex_part(&self, bytes: &[u8], range: Range<usize>, part: &mut LexedPart) {
        let sub = &bytes[..range.end];
        part.lines.clear();
        part.words.clear();
        part.line_count = 0;
        part.error = None;
        for (span, _) in lines_from(sub, range.start) {
            part.line_count += 1;
            if part.error.is_some() {
                continue;
            }
            let first = part.words.len();
            match self.lex(bytes, span.clone(), part.line_count, &mut part.words) {
                Ok(scan) => part.lines.push((span, scan, first..part.words.len())),
                Err(e) => part.error = Some(e),
            }
        }
    }

    /// What a line says (its words appended to `words`), before the modal state: this
    /// depends on the dialect only, so lines can be lexed in any order
    /// ([`scan`] does it on several threads).
    fn lex(
        &self,
        bytes: &[u8],
        span: Range<usize>,
        line: usize,
        words: &mut Vec<Word>,
    ) -> Result<Scan, ParseError> {
        let mut s = Scan::default();
        for token in Lexer::new(bytes, span.clone()) {
            let token =
                token.map_err(|e| ParseError::at(line, e.at - span.start + 1, e.message))?;
            match token {
                Token::Word {
                    letter,
                    span,
                    value_span,
                    value,
                } => {
                    match letter {
                        b'X' => s.axes[X] = Some(value),
                        b'Y' => s.axes[Y] = Some(value),
                        b'Z' => s.axes[Z] = Some(value),
                        b'A' => s.axes[A] = Some(value),
                        b'B' => s.axes[B] = Some(value),
                        b'C' => s.axes[C] = Some(value),
                        b'F' => s.feed = Some(value),
                        b'G' => self.g(code10(value), &mut s),
                        b'M' => Self::m(code10(value), &mut s),
                        b'N' | b'S' | b'I' | b'J' | b'K' | b'R' | b'O' => {}
                        // T tool, D/H offsets, U V W axes, P Q L E parameters.
                        _ => s.breaks = true,
                    }
                    // Offsets fit: `parse` rejects files of 4 GiB and more.
                    words.push(Word {
                        letter,
                        start: span.start as u32,
                        value_start: value_span.start as u32,
                        end: span.end as u32,
                        value,
                    });
                }
                Token::Ident { name, .. } => Self::ident(&bytes[name], &mut s),
                Token::Assign { letter, .. } => {
                    if !matches!(letter, b'R' | b'S') {
                        s.breaks = true;
                    }
                }
                Token::Percent { span } => {
                    for w in bytes[span].split(|b| b.is_ascii_whitespace()) {
                        if w.eq_ignore_ascii_case(b"G70") {
                            s.inch = Some(true);
                        } else if w.eq_ignore_ascii_case(b"G71") {
                            s.inch = Some(false);
                        }
                    }
                }
                Token::Slash { .. } => s.breaks = true,
                Token::Comment { .. } | Token::BlockEnd { .. } | Token::Other { .. } => {}
            }
        }
        Ok(s)
    }

    /// Update the modal state; the block's `state` index is set by the caller.
    fn apply(&mut self, s: Scan, line: usize, span: Range<usize>, words: Range<usize>) -> Block {
        let m = &mut self.modal;
        let mut breaks = s.breaks;
        if let Some(mo) = s.motion {
            m.motion = mo;
        }
        if let Some(inc) = s.incremental {
            m.incremental = inc;
        }
        if let Some(inch) = s.inch {
            m.inch = inch;
        }
        if let Some(t) = s.tcpm {
            m.tcpm = t;
            breaks = true;
        }
        if let Some(fm) = s.feed_mode {
            if fm != self.feed_mode {
                self.feed_mode = fm;
                m.feed_mm_min = None;
                breaks = true;
            }
        }
        let scale = if m.inch { 25.4 } else { 1.0 };
        if s.stated_datum {
            let v = |i: usize| s.axes[i].unwrap_or(0.0) * scale;
            self.stated_datum = Some([v(X), v(Y), v(Z)]);
        } else if s.datum_shift || s.work_offset {
            self.frame_changed = true;
        }
        if let Some(f) = s.feed {
            m.feed_mm_min = (self.feed_mode == FeedMode::PerMinute).then_some(f * scale);
        }
        let has_axes = s.axes.iter().any(Option::is_some);
        let mut is_move = false;
        if s.datum_shift || s.reference || s.unknown_after {
            // Linear positions unknown afterwards; so are rotary axes named in the block.
            for (i, p) in m.pos.iter_mut().enumerate() {
                if i < A || s.axes[i].is_some() || s.unknown_after {
                    *p = None;
                }
            }
            is_move = s.reference && has_axes;
            breaks = true;
        } else if s.no_move {
            breaks = true;
        } else {
            if s.work_offset {
                m.pos[X] = None;
                m.pos[Y] = None;
                m.pos[Z] = None;
                breaks = true;
            }
            for (i, v) in s.axes.iter().enumerate() {
                if let Some(v) = *v {
                    let v = if i < A { v * scale } else { v };
                    m.pos[i] = if m.incremental {
                        m.pos[i].map(|p| p + v)
                    } else {
                        Some(v)
                    };
                }
            }
            if has_axes {
                is_move = m.motion != Motion::None;
                if m.motion != Motion::Linear {
                    breaks = true;
                }
            }
        }
        // Offsets fit: `parse` rejects files of 4 GiB and more.
        Block {
            line,
            start: span.start as u32,
            end: span.end as u32,
            words_start: words.start as u32,
            words_end: words.end as u32,
            state: 0,
            is_move,
            breaks_run: breaks,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> Program {
        parse(s.as_bytes().to_vec(), Dialect::Auto).unwrap()
    }

    #[test]
    fn lines_and_endings() {
        let prog = p("G1 X1\r\nY2\n\nZ3");
        assert_eq!(prog.blocks.len(), 4);
        assert_eq!(prog.blocks[0].span(), 0..5);
        assert_eq!(prog.blocks[1].span(), 7..9);
        assert_eq!(prog.blocks[2].span(), 10..10);
        assert_eq!(prog.blocks[3].span(), 11..13);
        assert_eq!(prog.state(3).pos[..3], [Some(1.0), Some(2.0), Some(3.0)]);
        assert_eq!(p("X1\n").blocks.len(), 1);
        assert!(p("").blocks.is_empty());
    }

    #[test]
    fn newline_search() {
        let text = b"0123456789\nabcdefghijklmnopqrstuvwxyz\n\x8a\n";
        for from in 0..text.len() + 2 {
            let naive = text
                .get(from..)
                .and_then(|t| t.iter().position(|&b| b == b'\n'))
                .map(|k| from + k);
            assert_eq!(find_newline(text, from), naive, "{from}");
        }
    }

    #[test]
    fn dialects_are_detected() {
        assert_eq!(detect(b"%P G71 *\nN10 G90 *\n"), Dialect::Heidenhain);
        assert_eq!(detect(b"N10 TRAORI\nN20 G1 X1 ; cut\n"), Dialect::Sinumerik);
        assert_eq!(detect(b"%\nO1234 (PART)\nG43.4 H1\n%\n"), Dialect::Fanuc);
    }

    #[test]
    fn modal_state() {
        let prog = p("G21 G90 G1 X1 Y2 Z3 F100\nG91 X1 C10\nG90 G20 X1 F10\nG0 Z1\nM128\nG49\n");
        let st: Vec<Modal> = (0..prog.blocks.len()).map(|b| prog.state(b)).collect();
        assert_eq!(st[0].feed_mm_min, Some(100.0));
        assert_eq!(st[1].pos[X], Some(2.0));
        assert_eq!(
            st[1].pos[C], None,
            "incremental from an unknown position stays unknown"
        );
        assert!(st[1].incremental);
        assert_eq!(st[2].pos[X], Some(25.4));
        assert!((st[2].feed_mm_min.unwrap() - 254.0).abs() < 1e-12);
        assert_eq!(st[3].motion, Motion::Rapid);
        assert!(prog.blocks[3].breaks_run && prog.blocks[3].is_move);
        assert!(st[4].tcpm && prog.blocks[4].breaks_run);
        assert!(!st[5].tcpm && prog.blocks[5].breaks_run);
        assert!(!prog.blocks[1].breaks_run && prog.blocks[1].is_move);
    }

    #[test]
    fn state_before() {
        let prog = p("G1 X1\nX2\n");
        assert_eq!(prog.state_before(0), Modal::default());
        assert_eq!(prog.state_before(1).pos[X], Some(1.0));
    }

    #[test]
    fn heidenhain_datum_shift_is_not_a_move() {
        let prog =
            p("%P G71 *\nN10 G01 X+1 Y+2 Z+3 A+5 F100 *\nN20 G54 X+1 Y+2 Z+3 *\nN30 X+4 *\n");
        let b = &prog.blocks[2];
        assert!(!b.is_move && b.breaks_run);
        assert_eq!(prog.state(2).pos, [None, None, None, Some(5.0), None, None]);
        assert_eq!(prog.state(3).pos[X], Some(4.0));
        assert!(prog.blocks[3].is_move && !prog.blocks[3].breaks_run);
    }

    #[test]
    fn fanuc_work_offset_select_moves_in_the_new_frame() {
        let prog = p("G1 X1 Y2 Z3\nG54 G0 X5 Y6 (SELECT)\n");
        let b = &prog.blocks[1];
        assert!(b.is_move && b.breaks_run);
        assert_eq!(prog.state(1).pos[..3], [Some(5.0), Some(6.0), None]);
    }

    #[test]
    fn run_breakers() {
        let breaks = |s: &str| p(&format!("G1 X0 Y0 Z0 F100\n{s}\n")).blocks[1].breaks_run;
        for s in [
            "T5",
            "M6",
            "M06",
            "M0",
            "M00",
            "M1",
            "M30",
            "M2",
            "M128",
            "M129",
            "TRAORI",
            "TRAFOOF",
            "G43.4 H1",
            "G49",
            "G92 X0",
            "G10 L2 P1 X0",
            "G53 Z0",
            "G28 Z0",
            "G93",
            "G0 X1",
            "G2 X1 I1",
            "G3 X1 I1",
            "CYCLE800(1)",
            "/N10 X1",
            "G4 X1",
            "T=\"MILL\"",
        ] {
            assert!(breaks(s), "{s} should break a run");
        }
        for s in [
            "",
            "; comment",
            "(comment)",
            "S12000 M13",
            "M8",
            "M9",
            "M3 S100",
            "M05 M09",
            "X1 Y2",
            "F200",
            "MSG(\"hello\")",
            "R1=5",
            "G90",
            "G17",
        ] {
            assert!(!breaks(s), "{s} should not break a run");
        }
    }

    #[test]
    fn errors_have_line_and_column() {
        let e = parse(b"N10 G1 X1\nN20 C12..5\n".to_vec(), Dialect::Auto).unwrap_err();
        assert_eq!((e.line, e.column), (2, 5));
        assert_eq!(
            e.to_string(),
            "line 2, col 5: C value '12..5' is not a number"
        );
        let e = parse(b"N10 G1\r\nN20 X=IC(5) Y1\r\n".to_vec(), Dialect::Sinumerik).unwrap_err();
        assert_eq!((e.line, e.column), (2, 5));
        assert!(e.message.contains("needs a plain number"), "{}", e.message);
    }

    #[test]
    fn non_utf8_passes() {
        let prog = parse(
            b"N10 G1 X1 ; \xe9\xff\nN20 Y\xfc\xfc\n".to_vec(),
            Dialect::Auto,
        );
        assert!(
            prog.is_err(),
            "Y followed by a non-number byte needs a number"
        );
        let prog = parse(
            b"N10 G1 X1 ; \xe9\xff\nN20 \xfc\xfc Y2\n".to_vec(),
            Dialect::Auto,
        )
        .unwrap();
        assert_eq!(prog.state(1).pos[Y], Some(2.0));
    }

    /// A program of about `mb` MB with a comment line, modal changes and feed changes.
    fn big(mb: usize) -> Vec<u8> {
        let mut t = b"%BIG G71 *\nN10 G90 *\nN30 M128 *\n".to_vec();
        let mut k = 0u64;
        while t.len() < mb << 20 {
            let line = match k % 997 {
                0 => "; a comment (with words X1 Y2)\n".to_string(),
                1 => format!("N{k} G01 X+1 Y+2 Z-8 A+10 C+20 F{} *\n", 1000 + k % 7),
                2 => "\r\n".to_string(),
                3 => format!("N{k} G54 X+{} Y+2 Z+0 *\n", k % 5),
                4 => format!("N{k} G92 X+0 *\n"),
                _ => format!(
                    "N{k} X{:+.3} Y{:+.3} A{:+.3} C{:+.3} *\n",
                    k as f64 * 0.01,
                    (k as f64 * 0.001).sin(),
                    (k % 40) as f64 - 20.0,
                    (k * 7 % 720) as f64 - 360.0
                ),
            };
            t.extend_from_slice(line.as_bytes());
            k += 1;
        }
        t
    }

    /// What `scan_with` visits, as (line, span, words, state, is_move, breaks_run,
    /// stated datum, frame changed).
    type Visited = Vec<(
        usize,
        Range<usize>,
        Vec<Word>,
        Modal,
        bool,
        bool,
        Option<[f64; 3]>,
        bool,
    )>;

    fn scanned(bytes: &[u8], threads: usize) -> Result<Visited, ParseError> {
        let mut v = Vec::new();
        scan_with(bytes, Dialect::Auto, threads, |s| {
            let b = s.block;
            v.push((
                b.line,
                b.span(),
                s.words.to_vec(),
                *s.state,
                b.is_move,
                b.breaks_run,
                s.stated_datum,
                s.frame_changed,
            ));
            std::ops::ControlFlow::Continue(())
        })?;
        Ok(v)
    }

    #[test]
    fn scan_on_threads_sees_what_parse_sees() {
        let bytes = big(9);
        let prog = parse(bytes.clone(), Dialect::Auto).unwrap();
        let expected: Visited = (0..prog.blocks.len())
            .map(|i| {
                let b = &prog.blocks[i];
                (
                    b.line,
                    b.span(),
                    prog.block_words(i).to_vec(),
                    prog.state(i),
                    b.is_move,
                    b.breaks_run,
                    prog.datum_shifts
                        .iter()
                        .find(|(k, _)| *k == i)
                        .map(|(_, d)| *d),
                    prog.frame_changes.contains(&i),
                )
            })
            .collect();
        for threads in [1, 2, 3] {
            let got = scanned(&bytes, threads).unwrap();
            assert_eq!(got.len(), expected.len(), "{threads} threads");
            assert!(got == expected, "{threads} threads");
        }
    }

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
            scan_with(&bytes, Dialect::Auto, 2, |s| {
                if (from..to).contains(&i) {
                    builder.push(&s);
                }
                i += 1;
                std::ops::ControlFlow::Continue(())
            })
            .unwrap();
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

    #[test]
    fn scan_on_threads_gives_parses_first_error() {
        let mut bytes = big(9);
        // Two errors in different windows: the first in file order is reported.
        for (at, bad) in [(7usize << 20, &b"X1..2"[..]), (5 << 20, b"C12e5")] {
            let nl = find_newline(&bytes, at).unwrap() + 1;
            bytes.splice(nl..nl, bad.iter().copied().chain(*b"\n"));
        }
        let e = parse(bytes.clone(), Dialect::Auto).unwrap_err();
        assert!(e.message.contains("exponent"), "{}", e.message);
        for threads in [1, 2, 3] {
            let got = scanned(&bytes, threads).unwrap_err();
            assert_eq!((got.line, got.column), (e.line, e.column), "{threads}");
            assert_eq!(got.message, e.message);
        }
    }

    #[test]
    fn heidenhain_datum_shifts_are_kept_with_their_values() {
        let prog = p(
            "%P G71 *\nN10 G54 X-30.489 Y-7.1 Z+38.054 *\nN20 G01 X1 Y2 Z3 F100 *\nN30 G54 X+5 *\n",
        );
        assert_eq!(
            prog.datum_shifts,
            vec![(1, [-30.489, -7.1, 38.054]), (3, [5.0, 0.0, 0.0])]
        );
        assert!(prog.frame_changes.is_empty());
        // A Fanuc work-offset selection names a register only: no values, a frame change.
        let fanuc = p("G54\nG1 X1 Y2 Z3 F100\nG92 X0\n");
        assert!(fanuc.datum_shifts.is_empty());
        assert_eq!(fanuc.frame_changes, vec![0, 2]);
    }
}
