//! The one reader: [`scan_blocks_with`] reads a program block by block — lexing lines on
//! several threads, ahead of the thread that applies them to the modal state in file order
//! — and gives each block, its words and the state after it to a visitor; [`scan`] and
//! [`scan_blocks`] are its simpler forms, [`crate::parse`] collects it into a [`Program`].
//! A visitor may keep the place after a block ([`Scanned::resume_after`]) and read again
//! from there later ([`scan_resumed`]): a reader that reads a file once and then only the
//! stretches it needs.

use crate::block::Block;
use crate::detect::detect;
use crate::dialect::Dialect;
use crate::error::ParseError;
use crate::interp::Interpreter;
use crate::lexed::Scan;
use crate::lines::LineEnds;
use crate::modal::Modal;
use crate::style::StyleEvidence;
use crate::tcpm::ReadOptions;
use crate::tolerances::{MAX_SCAN_THREADS, SCAN_FIRST_WINDOW_BYTES, SCAN_WINDOW_BYTES};
use crate::word::Word;
use std::ops::Range;

/// How a read ended ([`scan_blocks_with`]).
#[must_use = "a read that found program flow must be read again with its plan"]
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Settled {
    /// The states given were final; the dialect used.
    Done(Dialect),
    /// The file has program flow that joins paths ([`crate::flow`]): the TCPM states given
    /// were provisional. Read it again with these options (the dialect and the flow plan
    /// set), which then ends [`Settled::Done`].
    Again(ReadOptions),
}

impl Settled {
    /// The dialect of a read that ended [`Settled::Done`], or the options to read again
    /// with.
    pub fn done(self) -> Result<Dialect, ReadOptions> {
        match self {
            Settled::Done(d) => Ok(d),
            Settled::Again(o) => Err(o),
        }
    }
}

/// Read `bytes` block by block without building a [`Program`]: `visit` gets each block
/// (its [`Block::words`] index the slice it is given), its words and the modal state after
/// it, in file order, and may stop the scan early with `ControlFlow::Break`. Memory is one
/// block's words. Same rules and the same errors, in the same order, as [`parse`] (which
/// reads the whole file and so also reports an error after a point where `visit` stopped).
///
/// Returns the dialect used (`Dialect::Auto` is detected as in [`parse`]), or that the
/// file must be read again with the plan of its program flow ([`Settled`]).
///
/// [`Program`]: crate::Program
/// [`parse`]: crate::parse
pub fn scan(
    bytes: &[u8],
    dialect: Dialect,
    mut visit: impl FnMut(&Block, &[Word], &Modal) -> std::ops::ControlFlow<()>,
) -> Result<Settled, ParseError> {
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
    ///
    /// [`Program::datum_shifts`]: crate::Program::datum_shifts
    pub stated_datum: Option<[f64; 3]>,
    /// The block changes the frame without stating it, as [`Program::frame_changes`].
    ///
    /// [`Program::frame_changes`]: crate::Program::frame_changes
    pub frame_changed: bool,
    /// The file's line ending.
    pub line_ends: LineEnds,
    /// A word of the block that looks like a TCPM code without being one
    /// ([`crate::tcpm::lookalike`]), for a warning.
    pub lookalike: Option<&'a Lookalike>,
    /// The macro variables the reader holds constant after the block.
    consts: &'a std::collections::HashMap<u32, f64>,
}

impl Scanned<'_> {
    /// Where a read can resume after this block ([`scan_resumed`]): the next line, the
    /// modal state after this block, and what else the reader holds between blocks.
    pub fn resume_after(&self) -> Resume {
        Resume {
            after: Some(self.block.span().end),
            ends: Some(self.line_ends),
            line: self.block.line,
            modal: *self.state,
            consts: self.consts.clone(),
        }
    }
}

/// A place to resume reading a file at: the start of a line, with the reader's state before
/// it ([`Scanned::resume_after`], [`Resume::file_start`]). A read resumed there gives the
/// same blocks, states and errors as the read of the whole file gives from there on, when
/// both use the same settled options (the dialect found, the flow plan: [`Settled`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Resume {
    /// The end of the block before (its line ending not included); `None` at the start of
    /// the file. The line to read next starts after that line ending (found when the read
    /// resumes: a survey keeps many such places and resumes at few).
    after: Option<usize>,
    /// The file's line ending (`None` at the start: not looked at yet).
    ends: Option<LineEnds>,
    /// The number of the line before it (0 at the start of the file).
    line: usize,
    /// The modal state before it.
    modal: Modal,
    /// Fanuc macro variables held constant (none in most files: no allocation).
    consts: std::collections::HashMap<u32, f64>,
}

impl Resume {
    /// The start of the file, as `opts` reads it.
    pub fn file_start(opts: &ReadOptions) -> Resume {
        Resume {
            after: None,
            ends: None,
            line: 0,
            modal: opts.initial(),
            consts: std::collections::HashMap::new(),
        }
    }

    /// About where reading resumes: the end of the block before it (0 at the start of the
    /// file), bytes.
    pub fn near_byte(&self) -> usize {
        self.after.unwrap_or(0)
    }

    /// The modal state before the line there.
    pub fn state(&self) -> &Modal {
        &self.modal
    }
}

/// Read `bytes` from `from` on, as [`scan_blocks_with`] reads them there, until `visit`
/// stops or the file ends. `opts` must be the options the read that made `from` settled
/// on (the dialect found, the flow plan: [`Settled`]); a read that resumes does not
/// settle flow again.
pub fn scan_resumed(
    bytes: &[u8],
    opts: &ReadOptions,
    from: &Resume,
    visit: impl FnMut(Scanned<'_>) -> std::ops::ControlFlow<()>,
) -> Result<(), ParseError> {
    if u32::try_from(bytes.len()).is_err() {
        return Err(too_big(bytes.len()));
    }
    let dialect = match opts.dialect {
        Dialect::Auto => detect(bytes),
        d => d,
    };
    let mut interp = Interpreter::new(opts, dialect);
    interp.resume(from.modal, &from.consts);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get().min(MAX_SCAN_THREADS));
    let ends = from.ends.unwrap_or_else(|| LineEnds::of(bytes));
    let start = from.after.map_or(0, |end| ends.cut_after(bytes, end));
    read(bytes, ends, (start, from.line), threads, &mut interp, visit).map(|_| ())
}

/// An identifier the reader does not know that looks like a TCPM code: a post's typo
/// (`TRAOOF` for `TRAFOOF`) leaves TCPM as it was where the program meant to switch it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Lookalike {
    /// 1-based byte column in its line.
    pub column: usize,
    /// The word as written.
    pub word: String,
    /// The code it looks like.
    pub code: String,
}

/// [`scan`], with what the block does to the coordinate frame.
pub fn scan_blocks(
    bytes: &[u8],
    dialect: Dialect,
    visit: impl FnMut(Scanned<'_>) -> std::ops::ControlFlow<()>,
) -> Result<Settled, ParseError> {
    scan_blocks_with(bytes, &ReadOptions::dialect(dialect), visit)
}

/// [`scan_blocks`] with the machine's TCPM codes: the one reader.
///
/// Where `opts` has no flow plan and the file has program flow that joins paths (labels,
/// jumps, calls of its own subprograms: [`crate::flow`]), the states given to `visit` are
/// provisional and the result is [`Settled::Again`] with the plan: read again with it.
pub fn scan_blocks_with(
    bytes: &[u8],
    opts: &ReadOptions,
    visit: impl FnMut(Scanned<'_>) -> std::ops::ControlFlow<()>,
) -> Result<Settled, ParseError> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get().min(MAX_SCAN_THREADS));
    scan_with(bytes, opts, threads, visit)
}

/// [`scan_blocks_with`] on `threads` threads.
pub(crate) fn scan_with(
    bytes: &[u8],
    opts: &ReadOptions,
    threads: usize,
    visit: impl FnMut(Scanned<'_>) -> std::ops::ControlFlow<()>,
) -> Result<Settled, ParseError> {
    if u32::try_from(bytes.len()).is_err() {
        return Err(too_big(bytes.len()));
    }
    let dialect = match opts.dialect {
        Dialect::Auto => detect(bytes),
        d => d,
    };
    let mut interp = Interpreter::new(opts, dialect);
    let ends = LineEnds::of(bytes);
    let completed = read(bytes, ends, (0, 0), threads, &mut interp, visit)?;
    let Some(mut flow) = interp.recorder.take() else {
        return Ok(Settled::Done(dialect));
    };
    if !completed {
        // The visit stopped early: whether the rest of the file has flow is still to see.
        let mut whole = Interpreter::new(opts, dialect);
        read(bytes, ends, (0, 0), threads, &mut whole, |_| {
            std::ops::ControlFlow::Continue(())
        })?;
        flow = whole.recorder.take().unwrap_or_default();
    }
    if !flow.global {
        return Ok(Settled::Done(dialect));
    }
    if flow.needs_block_labels() {
        // Jumps name block numbers: find those blocks.
        let mut again = Interpreter::new(opts, dialect);
        again.record_block_labels(flow.block_targets.clone());
        read(bytes, ends, (0, 0), threads, &mut again, |_| {
            std::ops::ControlFlow::Continue(())
        })?;
        flow = again.recorder.take().unwrap_or_default();
    }
    let plan = flow.solve(crate::tcpm::initial(&opts.controller).tcpm);
    Ok(Settled::Again(ReadOptions {
        dialect,
        controller: opts.controller.clone(),
        flow: Some(std::sync::Arc::new(plan)),
        inch: opts.inch,
        endless: opts.endless,
    }))
}

/// The [`StyleEvidence`] of the lines of `bytes[..end]` (`end` the start of a line), lexed
/// as `opts` reads them: the evidence of the words a read gives its visitor for those
/// blocks, without the modal state. For a reader that counts the file's number style only
/// once it needs it (`polepatch`'s patch: from the first run it may patch on) and counts the
/// lines before then afterwards. Errors as a read's (none where a read of the file took
/// these lines).
pub fn style_evidence_to(
    bytes: &[u8],
    end: usize,
    opts: &ReadOptions,
) -> Result<StyleEvidence, ParseError> {
    let dialect = match opts.dialect {
        Dialect::Auto => detect(bytes),
        d => d,
    };
    let interp = Interpreter::new(opts, dialect);
    let mut ev = StyleEvidence::default();
    let mut words = Vec::with_capacity(32);
    for (span, line) in LineEnds::of(bytes).lines_from(&bytes[..end.min(bytes.len())], 0) {
        words.clear();
        interp.lex(bytes, span, line, &mut words)?;
        ev.add_block(bytes, &words);
    }
    Ok(ev)
}

/// One read of the file (line endings `ends`) with `interp`, from the line that starts at
/// byte `from.0` (whose number is `from.1 + 1`): whether `visit` took every block.
fn read(
    bytes: &[u8],
    ends: LineEnds,
    from: (usize, usize),
    threads: usize,
    interp: &mut Interpreter,
    mut visit: impl FnMut(Scanned<'_>) -> std::ops::ControlFlow<()>,
) -> Result<bool, ParseError> {
    let mut give = |interp: &mut Interpreter, block: &Block, words: &[Word]| {
        let lookalike = interp.lookalike.take().and_then(|at| {
            let word = &bytes[at.clone()];
            Some(Lookalike {
                column: at.start - block.span().start + 1,
                word: String::from_utf8_lossy(word).into_owned(),
                code: crate::tcpm::lookalike(word, &interp.controller)?,
            })
        });
        visit(Scanned {
            block,
            words,
            state: &interp.modal,
            stated_datum: interp.stated_datum.take(),
            frame_changed: std::mem::take(&mut interp.frame_changed),
            lookalike: lookalike.as_ref(),
            line_ends: ends,
            consts: &interp.consts,
        })
    };
    let (start, lines_before) = from;
    if threads <= 1 || bytes.len() - start.min(bytes.len()) < SCAN_WINDOW_BYTES {
        let mut words = Vec::with_capacity(32);
        for (span, line) in ends.lines_from(bytes, start) {
            words.clear();
            let block = interp.block(bytes, span, lines_before + line, &mut words)?;
            if give(interp, &block, &words).is_break() {
                return Ok(false);
            }
        }
        return Ok(true);
    }
    // Windows of up to SCAN_WINDOW_BYTES, each cut at line ends into one part per lexing
    // thread (every thread but this one, at least one). They lex the next window's parts
    // side by side (lexing needs only the dialect and the controller's codes:
    // `lexing_twin`) while this thread applies the window before to the modal state, in
    // file order, and gives its blocks to `visit`. A window is handed over when this thread
    // takes it, and only then is the next lexed: a read that stops lexes at most one window
    // past where it stops. Memory: two windows' words and line summaries (one applied, one
    // being lexed). Nothing read depends on the overlap: the same blocks, states and
    // errors, in the same order, as one thread gives.
    let twin = interp.lexing_twin();
    // This thread applies; the others lex.
    let lexers = (threads - 1).max(1);
    std::thread::scope(|sc| {
        let (full_tx, full_rx) = std::sync::mpsc::sync_channel::<Window>(0);
        let (empty_tx, empty_rx) = std::sync::mpsc::channel::<Vec<LexedPart>>();
        let twin = &twin;
        sc.spawn(move || {
            let mut from = start;
            // Windows grow from the first: a read that stops early (a stretch read again
            // from a place in the file) lexes little past where it stops.
            let mut size = SCAN_FIRST_WINDOW_BYTES;
            while from < bytes.len() {
                let mut parts = empty_rx
                    .try_recv()
                    .unwrap_or_else(|_| (0..lexers).map(|_| LexedPart::default()).collect());
                let to = lex_window(twin, ends, bytes, from, size, &mut parts);
                size = (size * 2).min(SCAN_WINDOW_BYTES);
                // The reader stopped (its visitor, or an error): nothing more to lex.
                if full_tx.send(Window { parts }).is_err() {
                    return;
                }
                from = to;
            }
        });
        let mut line_offset = lines_before;
        for mut window in full_rx {
            for part in &mut window.parts {
                for (k, (span, scan, words)) in part.lines.iter_mut().enumerate() {
                    let line = line_offset + k + 1;
                    let ws = &part.words[words.clone()];
                    let block = interp.apply(scan, line, span.clone(), 0..ws.len());
                    if give(interp, &block, ws).is_break() {
                        return Ok(false);
                    }
                }
                line_offset += part.line_count;
                if let Some(mut e) = part.error.take() {
                    e.line += line_offset - part.line_count;
                    return Err(e);
                }
            }
            // The lexing thread may be done already: then the parts are not needed.
            let _ = empty_tx.send(window.parts);
        }
        Ok(true)
    })
}

/// A window of the file lexed in parts, in file order ([`read`]).
struct Window {
    parts: Vec<LexedPart>,
}

/// Lex the window of `bytes` from `from` (a line start) to about `size` bytes further, cut
/// at line ends into `parts.len()` parts lexed on as many threads; returns where the window
/// ends (a line start, or the end of the file).
fn lex_window(
    interp: &Interpreter,
    ends: LineEnds,
    bytes: &[u8],
    from: usize,
    size: usize,
    parts: &mut [LexedPart],
) -> usize {
    let threads = parts.len();
    let to = ends.cut_after(bytes, from + size);
    let mut cuts = vec![from];
    for k in 1..threads {
        let c = ends
            .cut_after(bytes, from + (to - from) * k / threads)
            .min(to);
        cuts.push(c.max(*cuts.last().unwrap_or(&from)));
    }
    cuts.push(to);
    std::thread::scope(|sc| {
        let (first, rest) = parts.split_at_mut(1);
        let handles: Vec<_> = cuts
            .windows(2)
            .skip(1)
            .zip(rest.iter_mut())
            .map(|(w, part)| {
                let (a, b) = (w[0], w[1]);
                sc.spawn(move || part.lex(interp, ends, bytes, a..b))
            })
            .collect();
        first[0].lex(interp, ends, bytes, cuts[0]..cuts[1]);
        for h in handles {
            h.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
        }
    });
    to
}

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

impl LexedPart {
    /// Lex the lines of `range` (which starts at a line start and ends after a line ending
    /// or at the end of the file), numbering them from 1 within the part.
    fn lex(&mut self, interp: &Interpreter, ends: LineEnds, bytes: &[u8], range: Range<usize>) {
        let sub = &bytes[..range.end];
        self.lines.clear();
        self.words.clear();
        self.line_count = 0;
        self.error = None;
        for (span, _) in ends.lines_from(sub, range.start) {
            self.line_count += 1;
            if self.error.is_some() {
                continue;
            }
            let first = self.words.len();
            // Lexed in place (a `Scan` is a few hundred bytes).
            self.lines
                .push((span.clone(), Scan::default(), first..first));
            let Some((_, scan, words)) = self.lines.last_mut() else {
                continue;
            };
            match interp.lex_into(bytes, span, self.line_count, &mut self.words, scan) {
                Ok(()) => *words = first..self.words.len(),
                Err(e) => {
                    self.lines.pop();
                    self.error = Some(e);
                }
            }
        }
    }
}

fn too_big(len: usize) -> ParseError {
    ParseError::at(
        1,
        1,
        format!("the file has {len} bytes; polepatch reads programs of at most 4 GiB"),
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::modal::{A, C, Motion, Tcpm, X, Y, Z};
    use crate::tcpm::{Code, ControllerCodes};
    use crate::{Flags, Program, parse, parse_with};

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
    fn cr_alone_ends_lines() {
        let prog = p("G1 X1 Y0 Z0 A0 F100\rX2\rX3\r");
        assert_eq!(prog.blocks.len(), 3);
        assert_eq!(prog.line_ends, LineEnds::Cr);
        assert_eq!(prog.blocks[2].line, 3);
        assert_eq!(prog.state(2).pos[X], Some(3.0));
        assert_eq!(crate::runs(&prog).len(), 1);
    }

    #[test]
    fn modal_state() {
        let prog =
            p("G21 G90 G1 X1 Y2 Z3 F100\nG91 X1 C10\nG90 G20 X1 F10\nG0 Z1\nG43.4 H1\nG49\n");
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
        assert!(st[4].tcpm.is_on() && prog.blocks[4].breaks_run);
        assert!(st[5].tcpm == Tcpm::Off && prog.blocks[5].breaks_run);
        assert!(!prog.blocks[1].breaks_run && prog.blocks[1].is_move);
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
            "T5 M6",
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
            // A T word alone preselects the next tool: `M6` changes it (issue 39).
            "T5",
        ] {
            assert!(!breaks(s), "{s} should not break a run");
        }
        // Heidenhain ISO `T5 G17` calls the tool.
        let prog = p("%P G71 *\nN10 G01 X+1 Y+2 Z+3 A+5 F100 *\nN20 T5 G17 S3000 *\nN30 X+4 *\n");
        assert!(prog.blocks[2].breaks_run && prog.blocks[2].flags.has(crate::Flags::TOOL_CHANGE));
    }

    #[test]
    fn errors_have_line_and_column() {
        let e = parse(b"N10 G1 X1\nN20 C12..5\n".to_vec(), Dialect::Auto).unwrap_err();
        assert_eq!((e.line, e.column), (2, 5));
        assert_eq!(
            e.to_string(),
            "line 2, col 5: C value '12..5' is not a number"
        );
        let e = parse(b"N10 G1\r\nN20 X12,5 Y1\r\n".to_vec(), Dialect::Sinumerik).unwrap_err();
        assert_eq!((e.line, e.column), (2, 5));
        assert!(
            e.message.contains("'12,5' is not a number"),
            "{}",
            e.message
        );
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
    pub(crate) fn big(mb: usize) -> Vec<u8> {
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
        let settled = scan_with(bytes, &ReadOptions::default(), threads, |s| {
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
        assert!(matches!(settled, Settled::Done(_)), "no program flow");
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

    /// Every block of `bytes` as a full read gives it, and the place after each.
    fn visited_with_places(bytes: &[u8], opts: &ReadOptions) -> (Visited, Vec<Resume>) {
        let (mut v, mut places) = (Vec::new(), Vec::new());
        let settled = scan_blocks_with(bytes, opts, |s| {
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
            places.push(s.resume_after());
            std::ops::ControlFlow::Continue(())
        })
        .unwrap();
        assert!(matches!(settled, Settled::Done(_)));
        (v, places)
    }

    /// A read resumed after block `k` gives the blocks the full read gives from `k + 1` on.
    fn resumes_as_the_full_read(bytes: &[u8], opts: &ReadOptions, every: usize) {
        let (full, places) = visited_with_places(bytes, opts);
        assert!(full.len() > 2);
        for k in (0..full.len()).step_by(every) {
            let mut got = Vec::new();
            scan_resumed(bytes, opts, &places[k], |s| {
                let b = s.block;
                got.push((
                    b.line,
                    b.span(),
                    s.words.to_vec(),
                    *s.state,
                    b.is_move,
                    b.breaks_run,
                    s.stated_datum,
                    s.frame_changed,
                ));
                // A stretch: up to 40 blocks (the threaded read stops early too).
                if got.len() == 40 {
                    std::ops::ControlFlow::Break(())
                } else {
                    std::ops::ControlFlow::Continue(())
                }
            })
            .unwrap();
            let want = &full[k + 1..(k + 41).min(full.len())];
            assert!(got == want, "resumed after block {k}");
        }
        // And from the start of the file, to its end.
        let mut all = 0usize;
        scan_resumed(bytes, opts, &Resume::file_start(opts), |_| {
            all += 1;
            std::ops::ControlFlow::Continue(())
        })
        .unwrap();
        assert_eq!(all, full.len());
    }

    #[test]
    fn a_read_resumed_at_a_place_reads_what_the_full_read_reads_from_there() {
        // Threaded (a file of several windows), with datum shifts, G92 and comments.
        let big = big(1);
        let opts = ReadOptions::dialect(Dialect::Heidenhain);
        resumes_as_the_full_read(&big, &opts, 997);
        // Fanuc macro constants held across the place, CR LF line ends, a byte-order mark.
        let fanuc = b"\xEF\xBB\xBF%\r\nO1000\r\n#100=1200.\r\nG90 G43.4 H1\r\nG1 X0 Y0 Z5 A10 C0 F#100\r\n\
                      X1 Y1 A11 C5\r\n#101=5.\r\nX2 Y#101 A12 C10 F#100\r\nX3 Y3 A13 C15\r\nM30\r\n%\r\n";
        let opts = ReadOptions::dialect(Dialect::Fanuc);
        resumes_as_the_full_read(fanuc, &opts, 1);
    }

    #[test]
    fn a_visitor_that_stops_early_stops_the_threaded_read_where_one_thread_stops() {
        // Stopping in the third window: the lexing thread is ahead, and must end too.
        let bytes = big(3);
        let stop_at = 3 * (SCAN_WINDOW_BYTES / 40);
        for threads in [1, 2, 3] {
            let mut lines = Vec::new();
            let settled = scan_with(&bytes, &ReadOptions::default(), threads, |s| {
                lines.push(s.block.line);
                if lines.len() == stop_at {
                    std::ops::ControlFlow::Break(())
                } else {
                    std::ops::ControlFlow::Continue(())
                }
            })
            .unwrap();
            assert!(matches!(settled, Settled::Done(_)), "{threads} threads");
            assert_eq!(
                lines,
                (1..=stop_at).collect::<Vec<_>>(),
                "{threads} threads"
            );
        }
    }

    #[test]
    fn scan_on_threads_gives_parses_first_error() {
        let mut bytes = big(9);
        // Two errors in different windows: the first in file order is reported.
        for (at, bad) in [(7usize << 20, &b"X1..2"[..]), (5 << 20, b"C12e5")] {
            let nl = crate::lines::find_byte(&bytes, at, b'\n').unwrap() + 1;
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

    /// Each controller's codes end TCPM as its modal groups say (issue 19: G43/G44 after
    /// G43.4, TRANSMIT/TRACYL after TRAORI, the program's end).
    #[test]
    fn tcpm_ends_as_controllers_define_it() {
        let tcpm_after = |text: &str| {
            let prog = p(text);
            prog.state(prog.blocks.len() - 1).tcpm
        };
        for (on, off) in [
            ("G43.4 H1", "G43 H1"),
            ("G43.4 H1", "G44 H1"),
            ("G43.4 H1", "G49"),
            ("G43.5 H1", "G43 H2"),
            ("G234 H1", "G49"),
            ("G43.4 H1", "M30"),
        ] {
            let text = format!("(FANUC)\nG90 G1 X0 Y0 Z0 F100\n{on}\n");
            assert_eq!(tcpm_after(&text), Tcpm::On, "{on}");
            assert_eq!(
                tcpm_after(&format!("{text}{off}\n")),
                Tcpm::Off,
                "{on} then {off}"
            );
        }
        for off in ["TRAFOOF", "TRANSMIT", "TRACYL(40)", "TRAANG(45)", "M30"] {
            let text = "N10 TRAORI ; 5 axes\n";
            assert_eq!(tcpm_after(text), Tcpm::On);
            assert_eq!(
                tcpm_after(&format!("{text}N20 {off}\n")),
                Tcpm::Off,
                "{off}"
            );
        }
        for (on, off) in [
            ("N10 M128 *", "N20 M129 *"),
            (
                "N10 FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS *",
                "N20 FUNCTION RESET TCPM *",
            ),
        ] {
            let text = format!("%P G71 *\n{on}\n");
            assert_eq!(tcpm_after(&text), Tcpm::On, "{on}");
            assert_eq!(tcpm_after(&format!("{text}{off}\n")), Tcpm::Off, "{off}");
        }
        // G43 is paraxial compensation in Heidenhain ISO: it does not end M128.
        assert_eq!(tcpm_after("%P G71 *\nN10 M128 *\nN20 G43 *\n"), Tcpm::On);
        // M128 is Heidenhain's; G43.4 Fanuc's.
        assert_eq!(tcpm_after("(F)\nM128\n"), Tcpm::Off);
    }

    /// A TCPM switch that block delete may skip leaves the state uncertain until a switch
    /// that is always executed.
    #[test]
    fn a_skippable_switch_is_uncertain() {
        let prog = p(
            "%P G71 *\n/N65 M128 *\nN70 G01 X+1 Y+0 Z+0 A+1 C+0 F100 *\nN80 M129 *\nN90 M128 *\n/N95 M129 *\n",
        );
        assert_eq!(prog.state(1).tcpm, Tcpm::Uncertain);
        assert_eq!(prog.state(2).tcpm, Tcpm::Uncertain);
        assert!(prog.blocks[1].flags.has(Flags::SKIPPABLE));
        assert_eq!(prog.state(3).tcpm, Tcpm::Off);
        assert_eq!(prog.state(4).tcpm, Tcpm::On);
        assert_eq!(prog.state(5).tcpm, Tcpm::Uncertain);
        // A skippable switch to the state already in force changes nothing.
        assert_eq!(p("(F)\n/N50 G49\n").state(1).tcpm, Tcpm::Off);
        assert_eq!(p("(F)\n/N50 G43.4 H1\n").state(1).tcpm, Tcpm::Uncertain);
        assert_eq!(p("N1 TRAORI\n/N6 TRAORI\n").state(1).tcpm, Tcpm::On);
        assert_eq!(
            p("N1 TRAFOOF ; x\n/N6 TRAORI\n").state(1).tcpm,
            Tcpm::Uncertain
        );
    }

    #[test]
    fn the_machines_own_codes() {
        let codes = ControllerCodes {
            on: vec![Code::parse("M428").unwrap()],
            off: vec![Code::parse("M429").unwrap()],
            always: false,
            auxiliary: Vec::new(),
        };
        let read = |text: &str, c: &ControllerCodes| {
            let prog = parse_with(
                text.as_bytes().to_vec(),
                &ReadOptions {
                    dialect: Dialect::Auto,
                    controller: c.clone(),
                    flow: None,
                    inch: false,
                    endless: [false; 3],
                },
            )
            .unwrap();
            (0..prog.blocks.len())
                .map(|b| prog.state(b).tcpm)
                .collect::<Vec<_>>()
        };
        let text = "(LINUXCNC)\nM428\nG1 X0 Y0 Z0 A0 C0 F100\nM429\nM2\n";
        assert_eq!(
            read(text, &codes),
            [Tcpm::Off, Tcpm::On, Tcpm::On, Tcpm::Off, Tcpm::Off]
        );
        assert_eq!(
            read(text, &ControllerCodes::default()),
            [Tcpm::Off; 5],
            "M428 means nothing without the machine's word"
        );
        let always = ControllerCodes {
            always: true,
            ..ControllerCodes::default()
        };
        assert_eq!(
            read(text, &always),
            [Tcpm::On; 5],
            "always TCP: nothing turns it off"
        );
    }

    #[test]
    fn spaces_inside_words() {
        let prog = p("G1  X   6.302  Y -11.560  Z- 5  A -71.841 C 0.5 F 300\n");
        let st = prog.state(0);
        assert_eq!(st.pos[..3], [Some(6.302), Some(-11.56), Some(-5.0)]);
        assert_eq!(st.pos[A], Some(-71.841));
        assert_eq!(st.pos[C], Some(0.5));
        assert_eq!(st.feed_mm_min, Some(300.0));
        let a = prog.word(0, b'A').unwrap();
        assert_eq!(&prog.bytes[a.span()], b"A -71.841");
        assert_eq!(&prog.bytes[a.value_span()], b"-71.841");
        // A letter with blanks and then no number is still an error.
        assert!(parse(b"G1 X Y1\n".to_vec(), Dialect::Auto).is_err());
    }

    #[test]
    fn a_word_twice_is_refused_with_its_column() {
        let e = parse(
            b"%P G71 *\nN10 G01 A+1 C+180 C+90 A+3 *\n".to_vec(),
            Dialect::Auto,
        )
        .unwrap_err();
        assert_eq!((e.line, e.column), (2, 19));
        assert!(e.message.contains("C appears twice"), "{}", e.message);
        assert!(e.message.contains("col 13"), "{}", e.message);
    }

    #[test]
    fn expressions_flag_the_block_not_the_file() {
        let prog = p("G1 X0 Y0 Z0 A1 C0 F100\nX1 A#<a_angle>\nX2 A2\nX=R1+2 Y1\nF=FGREF(5000)\n");
        let b = &prog.blocks[1];
        assert!(b.flags.has(Flags::NOT_ANALYSABLE) && b.breaks_run);
        assert_eq!(prog.state(1).pos[A], None);
        assert_eq!(prog.state(1).pos[X], Some(1.0));
        assert!(prog.word(1, b'A').is_none(), "no number to rewrite");
        assert_eq!(prog.state(2).pos[A], Some(2.0));
        assert_eq!(prog.state(3).pos[X], None);
        assert_eq!(prog.state(3).pos[Y], Some(1.0));
        assert!(prog.blocks[4].flags.has(Flags::NOT_ANALYSABLE));
        assert_eq!(prog.state(4).feed_mm_min, None);
        assert_eq!(crate::write(&prog, &[]), prog.bytes);
    }

    #[test]
    fn an_unclosed_comment_hiding_axis_words_is_flagged() {
        let prog = p("G1 X0 Y0 Z0 F100\nX1 (TRIM Y2 C45\nX2 (NOTE\nX3 (OK) Y1\n");
        assert!(prog.blocks[1].flags.has(Flags::UNCLOSED_COMMENT));
        assert!(!prog.blocks[2].flags.has(Flags::UNCLOSED_COMMENT));
        assert!(!prog.blocks[3].flags.has(Flags::UNCLOSED_COMMENT));
    }

    #[test]
    fn inverse_time_feed() {
        let prog = p("G93 G1 X0 Y0 Z0 A0 C0 F10\nX1 F20\nX2\nG94 F500\nX3\n");
        assert_eq!(prog.state(0).inverse_time_per_min, Some(10.0));
        assert_eq!(prog.state(0).feed_mm_min, None);
        assert_eq!(prog.state(1).inverse_time_per_min, Some(20.0));
        assert_eq!(prog.state(2).inverse_time_per_min, None, "not modal");
        assert_eq!(prog.state(3).feed_mm_min, Some(500.0));
        assert_eq!(prog.state(4).inverse_time_per_min, None);
        assert!(prog.blocks[3].breaks_run);
    }

    /// LinuxCNC parameters and O-word flow (as its 5-axis demos write them): parameter
    /// assignments are not moves; a call, a subroutine or a loop leaves positions unknown.
    #[test]
    fn linuxcnc_parameters_and_o_words() {
        let prog = p(
            "(LCNC)\n#<zmax> = #1 (=10)\n#<n> = 5\nG0 X0 Y0 Z0 A0 C0\nG1 F#<frate> Z2\no<helix> call [1][2]\no100 call\nG1 X1 F100\n",
        );
        assert!(!prog.blocks[1].is_move && prog.blocks[1].breaks_run);
        assert!(prog.blocks[4].flags.has(Flags::NOT_ANALYSABLE));
        assert_eq!(prog.state(5).pos[X], None, "o<helix> call");
        assert_eq!(prog.state(3).pos[X], Some(0.0));
        let mut q = prog.state(3);
        q.pos = prog.state(6).pos;
        assert_eq!(q.pos[X], None, "o100 call");
    }

    /// Canned cycles are modal until G80 or a motion code: their hole blocks are moves
    /// that end runs, with Z unknown after them (found reading posted drilling programs).
    #[test]
    fn canned_cycles_drill_holes_until_g80() {
        let prog = p(
            "(F)\nG90 G1 X0 Y0 Z5 F100\nG98 G81 X10 Y10 Z-5 R2 F50\nX20 Y10\nG80\nG0 X30 Y30 Z5\nG81 X1 Y1 Z-1 R1\nG1 X2 Y2 Z3\n",
        );
        assert!(prog.state(2).canned_cycle);
        assert!(prog.blocks[2].is_move && prog.blocks[2].breaks_run);
        assert_eq!(prog.state(2).pos[Z], None, "the hole returns to a plane");
        assert!(
            prog.blocks[3].is_move && prog.blocks[3].breaks_run,
            "modal: X20 Y10 is a hole"
        );
        assert!(!prog.state(4).canned_cycle, "G80");
        assert_eq!(prog.state(5).pos[Z], Some(5.0));
        assert!(!prog.state(7).canned_cycle, "G1 ends the cycle");
        assert!(!prog.blocks[7].flags.has(Flags::ARC));
        // M98/M99 and Heidenhain's G79 run other blocks: positions unknown after.
        assert_eq!(p("(F)\nG1 X0 Y0 Z0 F1\nM98 P100\n").state(2).pos[X], None);
        assert_eq!(
            p("%P G71 *\nN1 G01 X0 Y0 Z0 F1 *\nN2 G79 *\n").state(2).pos[X],
            None
        );
    }

    /// Issue 26: rotations, scalings and mirror images of the frame, in every dialect's
    /// forms, and their ends.
    #[test]
    fn frame_transformations() {
        use crate::modal::transform::{ALL, MIRROR, ROTATION, SCALING};
        let after = |text: &str| {
            let prog = p(text);
            prog.state(prog.blocks.len() - 1).transform
        };
        for (text, want) in [
            ("(F)\nG68 X0 Y0 R30\n", ROTATION),
            ("(F)\nG68 X0 Y0 R30\nG69\n", 0),
            ("(F)\nG68.2 X0 Y0 Z0 I0 J30 K0\n", ROTATION),
            ("(F)\nG51 X0 Y0 P0.5\n", SCALING),
            ("(F)\nG51 X0 Y0 P0.5\nG50\n", 0),
            ("(F)\nG51.1 X0\n", MIRROR),
            ("(F)\nG51.1 X0\nG50.1 X0\n", 0),
            ("(F)\nG10 L2 P1 X0 Y0 R15\n", ROTATION),
            ("(F)\nG10 L2 P1 X0 Y0 Z0\n", 0),
            ("%P G71 *\nN10 G73 G90 H+30 *\n", ROTATION),
            ("%P G71 *\nN10 G73 G90 H+30 *\nN20 G73 G90 H+0 *\n", 0),
            ("%P G71 *\nN10 G72 F0.8 *\n", SCALING),
            ("%P G71 *\nN10 G72 F0.8 *\nN20 G72 F1 *\n", 0),
            ("%P G71 *\nN10 G28 X+0 *\n", MIRROR),
            ("%P G71 *\nN10 G28 X+0 *\nN20 G28 *\n", 0),
            ("N10 TRAORI\nN20 ROT Z30\n", ROTATION),
            ("N10 TRAORI\nN20 AROT RPL=30\n", ROTATION),
            ("N10 TRAORI\nN20 ROT Z30\nN30 ROT\n", 0),
            (
                "N10 TRAORI\nN20 SCALE X2 Y2\nN30 MIRROR X0\n",
                SCALING | MIRROR,
            ),
            ("N10 TRAORI\nN20 SCALE X2\nN30 MIRROR X0\nN40 TRANS\n", 0),
            ("N10 TRAORI\nN20 ATRANS X10\n", 0),
            (
                "N10 TRAORI\nN20 CYCLE800(1,\"TC1\",0,57,0,0,0,30,0,0,0,0,0,-1)\n",
                ROTATION,
            ),
            (
                "N10 TRAORI\nN20 CYCLE800(1,\"TC1\",0,57,0,0,0,0,0,R1,0,0,0,-1)\n",
                ROTATION,
            ),
            (
                "N10 CYCLE800(0,\"TC1\",200000,57,0,0,0,0,0,0,0,0,0,-1,100,1)\n",
                0,
            ),
            (
                "N10 TRAORI\nN20 CYCLE800(1,\"TC1\",0,57,0,0,0,30)\nN30 CYCLE800()\n",
                0,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 10.0 ROTATION\n2 CYCL DEF 10.1 ROT+30\n",
                ROTATION,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 10.0 ROTATION\n2 CYCL DEF 10.1 ROT+0\n",
                0,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 11.0 SCALING\n2 CYCL DEF 11.1 SCL 0.8\n",
                SCALING,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 11.0 SCALING\n2 CYCL DEF 11.1 SCL 1\n",
                0,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 8.0 MIRROR IMAGE\n2 CYCL DEF 8.1 X\n",
                MIRROR,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 8.0 MIRROR IMAGE\n2 CYCL DEF 8.1\n",
                0,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 26.0 AXIS-SPECIFIC SCALING\n2 CYCL DEF 26.1 X1.5 CCX+0\n",
                SCALING,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 19.0 WORKING PLANE\n2 CYCL DEF 19.1 A+0 B+45 C+0\n",
                ROTATION,
            ),
            (
                "0 BEGIN PGM T MM\n1 CYCL DEF 19.0 WORKING PLANE\n2 CYCL DEF 19.1 A+0 B+0 C+0\n",
                0,
            ),
            (
                "0 BEGIN PGM T MM\n1 PLANE SPATIAL SPA+0 SPB+45 SPC+0 STAY\n",
                ROTATION,
            ),
            (
                "0 BEGIN PGM T MM\n1 PLANE SPATIAL SPA+0 SPB+45 SPC+0 STAY\n2 PLANE RESET STAY\n",
                0,
            ),
        ] {
            assert_eq!(after(text), want, "{text}");
        }
        // A run under a transformation carries it; every code also ends the known frame.
        let prog = p("(F)\nG68 X0 Y0 R30\nG1 X0 Y0 Z0 A1 C0 F100\nX1 A2\n");
        let r = crate::runs(&prog);
        assert_eq!(r[0].transform, ROTATION);
        assert!(prog.frame_changes.contains(&1));
        assert_eq!(ALL, 7);
    }

    /// Issue 26: TCPM through calls, labels and jumps — the reader's side (the patch's is
    /// in crates/polepatch/tests/flow.rs): a read that meets flow says so, and the read with
    /// its plan settles the states.
    #[test]
    fn program_flow_settles_tcpm() {
        let text =
            "(F)\nG43.4 H1\nM98 P2000\nG1 X0 Y0 Z0 A1 C0 F100\nX1 A2\nM30\nO2000\nG49\nM99\n";
        let first = scan(text.as_bytes(), Dialect::Auto, |_, _, _| {
            std::ops::ControlFlow::Continue(())
        })
        .unwrap();
        let Settled::Again(opts) = first else {
            panic!("flow found")
        };
        assert!(opts.flow.is_some());
        assert_eq!(opts.dialect, Dialect::Fanuc);
        let prog = parse_with(text.as_bytes().to_vec(), &opts).unwrap();
        assert_eq!(prog.state(1).tcpm, Tcpm::On);
        assert_eq!(prog.state(3).tcpm, Tcpm::Off, "settled by O2000's G49");
        assert_eq!(prog.state(4).tcpm, Tcpm::Off);
        assert_eq!(prog.state(7).tcpm, Tcpm::Off, "G49 in the subprogram");
        // parse settles by itself; a file without flow is read once.
        assert_eq!(p(text).state(3).tcpm, Tcpm::Off);
        let plain = "(F)\nG43.4 H1\nG1 X0 Y0 Z0 A1 C0 F100\n";
        assert!(matches!(
            scan(plain.as_bytes(), Dialect::Auto, |_, _, _| {
                std::ops::ControlFlow::Continue(())
            }),
            Ok(Settled::Done(Dialect::Fanuc))
        ));
        // Code outside the file: unknown after the call, settled by the next switch.
        let ext = p("(F)\nG43.4 H1\nG65 P9001\nG1 X0\nG43.4 H1\nG1 X1\n");
        assert_eq!(ext.state(3).tcpm, Tcpm::Unknown);
        assert_eq!(ext.state(5).tcpm, Tcpm::On);
        // Codes whose effect is not known.
        assert_eq!(p("N1 TRAORI\nN2 TRACON(1)\n").state(1).tcpm, Tcpm::Unknown);
        assert_eq!(p("(F)\nG43.4 H1\nG43.8 H1\n").state(2).tcpm, Tcpm::Unknown);
        // An early stop of the visit still finds flow later in the file.
        let mut seen = 0;
        let early = scan(text.as_bytes(), Dialect::Auto, |_, _, _| {
            seen += 1;
            std::ops::ControlFlow::Break(())
        })
        .unwrap();
        assert_eq!(seen, 1);
        assert!(matches!(early, Settled::Again(_)));
    }
}
