//! What a line says ([`Scan`], lexed on any thread: ISO lines here, Heidenhain
//! conversational lines in [`crate::conversational`], the readings they share in
//! `lexed.rs`) and how it changes the modal state ([`Interpreter::apply`], in file order).
//! The rules are in [`crate::modal`]'s docs; the TCPM codes in [`crate::tcpm`].

use crate::block::{Block, Flags};
use crate::dialect::Dialect;
use crate::error::ParseError;
use crate::lexed::{Scan, after_lex, function, m_code};
use crate::lexer::{Lexer, Token};
use crate::modal::{A, AXES, B, C, FeedMode, Modal, Motion, Tcpm, X, Y, Z};
use crate::statements::is_sinumerik_frame;
use crate::tcpm::{ControllerCodes, ReadOptions, Switch, code10};
use crate::tolerances::{HALF_TURN_DEG, ZERO_LENGTH_MM};
use crate::word::{RotaryForm, Word};
use std::ops::Range;

pub(crate) struct Interpreter {
    pub(crate) dialect: Dialect,
    pub(crate) controller: ControllerCodes,
    pub(crate) modal: Modal,
    /// How program flow settles TCPM (`None` on a first read: see [`crate::flow`]).
    plan: Option<std::sync::Arc<crate::flow::FlowPlan>>,
    cursor: crate::flow::Cursor,
    /// The flow events of a first read.
    pub(crate) recorder: Option<crate::flow::Recorder>,
    /// The datum the last block stated (Heidenhain `G54 X Y Z`), taken by the caller.
    pub(crate) stated_datum: Option<[f64; 3]>,
    /// The last block changed the frame without stating it, taken by the caller.
    pub(crate) frame_changed: bool,
    /// Where the last block holds a word that looks like a TCPM code, taken by the caller
    /// ([`crate::tcpm::lookalike`]).
    pub(crate) lookalike: Option<Range<usize>>,
    /// Fanuc macro variables whose value is a constant here ([`Interpreter::constants`]).
    pub(crate) consts: std::collections::HashMap<u32, f64>,
    /// The rotary axes A B C that turn without end ([`ReadOptions::endless`]).
    endless: [bool; 3],
}

/// The rotary axis (index into [`crate::Modal::pos`]) that the block's plain absolute word
/// turns by more than half a turn in a move that also moves the tool tip, on an axis for
/// which `endless` holds: a wrap ([`Flags::ROTARY_WRAP`]), if there is one. A move of half
/// a turn exactly is read as written.
fn wrap_axis(
    s: &Scan,
    before: &[Option<f64>; 6],
    after: &[Option<f64>; 6],
    endless: impl Fn(usize) -> bool,
) -> Option<usize> {
    let tip = |p: &[Option<f64>; 6]| Some([p[X]?, p[Y]?, p[Z]?]);
    let (t0, t1) = (tip(before)?, tip(after)?);
    let d2: f64 = t0.iter().zip(t1).map(|(a, b)| (b - a) * (b - a)).sum();
    if d2.sqrt() <= ZERO_LENGTH_MM {
        return None;
    }
    (A..=C).find(|&k| {
        s.axes[k].is_some()
            && s.axes_form[k - A] == RotaryForm::Plain
            && s.axes_incremental & bit(k) == 0
            && endless(k)
            && matches!((before[k], after[k]), (Some(p), Some(q)) if (q - p).abs() > HALF_TURN_DEG)
    })
}

/// `#100`, `-#100`, `+#100`: a macro variable's number (below 1000) and whether it is
/// negated.
fn macro_variable(text: &[u8]) -> Option<(u32, bool)> {
    let (neg, t) = match text.first()? {
        b'-' => (true, &text[1..]),
        b'+' => (false, &text[1..]),
        _ => (false, text),
    };
    let digits = t.strip_prefix(b"#")?;
    if digits.is_empty() || digits.len() > 9 || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    // Local (#1–#33) and common (#100–#199, #500–#999) variables, which only programs
    // change; system variables (#1000 on: positions, offsets, modal information) may change
    // under the program.
    let n: u32 = std::str::from_utf8(digits).ok()?.parse().ok()?;
    (1..1000).contains(&n).then_some((n, neg))
}

/// The assignment a parameter token at `at..end` starts, if `=` follows it: the variable
/// (`None` for `#<name>`, `#[…]`) and the value when it is a plain number alone up to the
/// end of the block (a comment may follow).
fn macro_assignment(
    bytes: &[u8],
    param: Range<usize>,
    end: usize,
) -> Option<(Option<u32>, Option<f64>)> {
    let blank = |c: u8| matches!(c, b' ' | b'\t');
    let mut i = param.end;
    while i < end && blank(bytes[i]) {
        i += 1;
    }
    if i >= end || bytes[i] != b'=' {
        return None;
    }
    let var = macro_variable(&bytes[param]).and_then(|(n, neg)| (!neg).then_some(n));
    i += 1;
    while i < end && blank(bytes[i]) {
        i += 1;
    }
    let start = i;
    while i < end && (bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'-' | b'+')) {
        i += 1;
    }
    let value = crate::lexer::parse_number(&bytes[start..i]);
    while i < end && blank(bytes[i]) {
        i += 1;
    }
    let rest_is_comment = i >= end || matches!(bytes[i], b'(' | b';');
    Some((var, value.filter(|v| v.is_finite() && rest_is_comment)))
}

/// Identifiers of program flow: LinuxCNC O-word statements (`o100 call`, `o<x> if`, …) and
/// Sinumerik jumps, loops and calls.
const FLOW: &[&[u8]] = &[
    b"CALL",
    b"SUB",
    b"ENDSUB",
    b"RETURN",
    b"IF",
    b"ELSE",
    b"ELSEIF",
    b"ENDIF",
    b"WHILE",
    b"ENDWHILE",
    b"DO",
    b"REPEAT",
    b"ENDREPEAT",
    b"BREAK",
    b"CONTINUE",
    b"GOTO",
    b"GOTOF",
    b"GOTOB",
    b"GOTOC",
    b"LOOP",
    b"ENDLOOP",
    b"FOR",
    b"ENDFOR",
    b"UNTIL",
    b"RET",
    b"PCALL",
    b"MCALL",
];

/// What a Sinumerik frame instruction does to the transformation bits, given whether the
/// block states values (axis words, `RPL=`): (switched on, switched off).
fn sinumerik_frame_transform(name: &[u8], with_values: bool) -> (u8, u8) {
    use crate::modal::transform::{ALL, MIRROR, ROTATION, SCALING};
    let up = name.to_ascii_uppercase();
    let core = |r: &[u8]| matches!(r, b"TRANS" | b"ROT" | b"SCALE" | b"MIRROR");
    // `A…`: additive (needs values); `C…`: the same as the plain form.
    let (base, additive): (&[u8], bool) = match up.as_slice() {
        [b'A', r @ ..] if core(r) => (r, true),
        [b'C', r @ ..] if core(r) => (r, false),
        r => (r, false),
    };
    match base {
        // Without values, TRANS, ROT, SCALE and MIRROR delete the programmable frame.
        b"TRANS" | b"ROT" | b"SCALE" | b"MIRROR" if !with_values && !additive => (0, ALL),
        b"TRANS" => (0, 0),
        b"ROT" | b"RPL" | b"TOFRAME" | b"TOROT" | b"PAROT" => (ROTATION, 0),
        b"TOROTOF" | b"PAROTOF" => (0, ROTATION),
        b"SCALE" => (SCALING, 0),
        b"MIRROR" => (MIRROR, 0),
        _ => (0, 0),
    }
}

/// Whether a Sinumerik `CYCLE800(…)` call (`args`: its parenthesised argument list) swivels
/// the frame: its rotation angles (arguments 8–10, `_A _B _C`, after retract, carrier,
/// state, mode and the shift `_X0 _Y0 _Z0`) are not all zero. `CYCLE800()` and a call with
/// zero angles (posts write one to align the table before `TRAORI`) do not; angles that are
/// not plain numbers may.
pub(crate) fn cycle800_rotates(args: &[u8]) -> bool {
    let inner = args
        .iter()
        .position(|&c| c == b'(')
        .map_or(&args[..0], |k| &args[k + 1..]);
    let inner = inner.strip_suffix(b")").unwrap_or(inner);
    let mut fields = Vec::new();
    let (mut start, mut quoted) = (0, false);
    for (k, &c) in inner.iter().enumerate() {
        match c {
            b'"' => quoted = !quoted,
            b',' if !quoted => {
                fields.push(&inner[start..k]);
                start = k + 1;
            }
            _ => {}
        }
    }
    fields.push(&inner[start..]);
    fields.iter().skip(7).take(3).any(|f| {
        let f = f.trim_ascii();
        !f.is_empty() && crate::lexer::parse_number(f) != Some(0.0)
    })
}

/// The index of `letter` in X Y Z A B C F (the axes in [`AXES`] order, then F).
fn axis_or_feed(letter: u8) -> Option<usize> {
    match letter {
        b'X' => Some(X),
        b'Y' => Some(Y),
        b'Z' => Some(Z),
        b'A' => Some(A),
        b'B' => Some(B),
        b'C' => Some(C),
        b'F' => Some(6),
        _ => None,
    }
}

/// Bit of axis index `i` in [`Scan::axes_expr`].
fn bit(i: usize) -> u8 {
    1 << i
}

/// Whether comment text hides what looks like an axis word (`X12`, `C-5.`).
fn looks_like_axis_words(text: &[u8]) -> bool {
    text.windows(2).any(|w| {
        AXES.contains(&w[0].to_ascii_uppercase())
            && (w[1].is_ascii_digit() || matches!(w[1], b'+' | b'-' | b'.'))
    })
}

/// One ISO line as its tokens are read: where it is, and what a token leaves for the
/// tokens after it.
struct IsoLine {
    span: Range<usize>,
    line: usize,
    /// X Y Z A B C F seen in this block, with the column of the first.
    seen: [Option<usize>; 7],
    // Values the frame codes read after the words: Heidenhain ISO G73's H, LinuxCNC
    // G10's R; the Sinumerik frame instruction and CYCLE800's argument list.
    h_word: Option<f64>,
    r_word: Option<f64>,
    sinumerik_frame: Option<Range<usize>>,
    cycle800_level: Option<bool>,
    rpl: bool,
}

impl IsoLine {
    fn new(span: Range<usize>, line: usize) -> Self {
        IsoLine {
            span,
            line,
            seen: [None; 7],
            h_word: None,
            r_word: None,
            sinumerik_frame: None,
            cycle800_level: None,
            rpl: false,
        }
    }

    /// A word of `letter` at `at`: an error if it is an axis or F the block named before.
    /// (Every word of every block passes here: inlined, its error apart.)
    #[inline]
    fn once(&mut self, letter: u8, at: usize) -> Result<(), ParseError> {
        if let Some(k) = axis_or_feed(letter) {
            let column = at - self.span.start + 1;
            if let Some(first) = self.seen[k] {
                return Err(self.twice(letter, column, first));
            }
            self.seen[k] = Some(column);
        }
        Ok(())
    }

    /// The error of a second `letter` word at `column`, the first at column `first`.
    #[cold]
    fn twice(&self, letter: u8, column: usize, first: usize) -> ParseError {
        ParseError::at(
            self.line,
            column,
            format!(
                "{} appears twice in this block (first at col {first}); controllers \
                 reject such a block and polepatch will not guess which is meant",
                letter as char
            ),
        )
    }
}

/// An assignment to `letter` (`X=…`, `F#100`, `o<name>`), `value` the text after the letter.
fn assignment(letter: u8, value: &[u8], s: &mut Scan) {
    if let Some(i) = AXES.iter().position(|&l| l == letter) {
        s.axes_expr |= bit(i);
        s.vars[i] = macro_variable(value);
    } else if letter == b'F' {
        s.feed_expr = true;
        s.vars[6] = macro_variable(value);
    } else if letter == b'O' {
        // `o<name> call`, `o<name> sub`: LinuxCNC program flow.
        s.unknown_after = true;
        s.breaks = true;
        s.maybe_flow = true;
    } else if !matches!(letter, b'R' | b'S') {
        s.breaks = true;
    }
}

/// The units a `%` line states (`%NAME G71`).
fn percent_units(text: &[u8], s: &mut Scan) {
    for w in text.split(|b| b.is_ascii_whitespace()) {
        if w.eq_ignore_ascii_case(b"G70") {
            s.inch = Some(true);
        } else if w.eq_ignore_ascii_case(b"G71") {
            s.inch = Some(false);
        }
    }
}

impl Interpreter {
    pub(crate) fn new(opts: &ReadOptions, dialect: Dialect) -> Self {
        let always = opts.controller.always;
        Interpreter {
            dialect,
            controller: opts.controller.clone(),
            modal: opts.initial(),
            plan: opts.flow.clone().filter(|_| !always),
            cursor: crate::flow::Cursor::default(),
            // Kinematics that are always TCP: flow cannot change it.
            recorder: (opts.flow.is_none() && !always).then(crate::flow::Recorder::default),
            stated_datum: None,
            frame_changed: false,
            lookalike: None,
            consts: std::collections::HashMap::new(),
            endless: opts.endless,
        }
    }

    /// An interpreter that lexes as this one does (lexing reads only the dialect and the
    /// controller's codes), for a thread that lexes ahead while this one applies blocks to
    /// the modal state ([`crate::reader`]).
    pub(crate) fn lexing_twin(&self) -> Interpreter {
        Interpreter {
            dialect: self.dialect,
            controller: self.controller.clone(),
            modal: self.modal,
            plan: None,
            cursor: crate::flow::Cursor::default(),
            recorder: None,
            stated_datum: None,
            frame_changed: false,
            lookalike: None,
            consts: std::collections::HashMap::new(),
            endless: self.endless,
        }
    }

    /// Take up a read where another left it ([`crate::Resume`]): its modal state and
    /// macro constants; flow is not recorded again.
    pub(crate) fn resume(&mut self, modal: Modal, consts: &std::collections::HashMap<u32, f64>) {
        self.modal = modal;
        self.consts = consts.clone();
        self.recorder = None;
    }

    /// Record block labels numbered `targets` too (a second pass).
    pub(crate) fn record_block_labels(&mut self, targets: std::collections::HashSet<u64>) {
        self.recorder = Some(crate::flow::Recorder::with_block_labels(targets));
    }

    fn g(&self, code: Option<i64>, s: &mut Scan) {
        use crate::modal::transform::{MIRROR, ROTATION, SCALING};
        let heidenhain = self.dialect == Dialect::Heidenhain;
        if let Some(sw) = code.and_then(|c| self.controller.g(self.dialect, c)) {
            s.tcpm = Some(sw);
            return;
        }
        if self.dialect == Dialect::MillPlus && crate::millplus::g(code, s) {
            return;
        }
        match code {
            Some(0) => s.motion = Some(Motion::Rapid),
            Some(10) => s.motion = Some(Motion::Linear),
            Some(20) => s.motion = Some(Motion::ArcCw),
            Some(30) => s.motion = Some(Motion::ArcCcw),
            // Heidenhain ISO: G73 rotates the frame (`G73 G90 H+30`), G72 scales it
            // (`G72 F0.8`), G28 mirrors it (`G28 X`); their values are read after the words
            // ([`Interpreter::lex`]).
            Some(c @ (730 | 720 | 280)) if heidenhain => {
                s.datum_shift = true;
                s.breaks = true;
                s.heidenhain_frame = Some(c);
            }
            // Canned cycles (Fanuc, Haas, LinuxCNC; Heidenhain ISO uses G2xx + G79).
            Some(730 | 740 | 760 | 810..=890) if !heidenhain => {
                s.cycle = Some(true);
                s.breaks = true;
            }
            Some(800) => s.cycle = Some(false),
            // Heidenhain ISO cycle call: the cycle moves the tool.
            Some(790) if heidenhain => {
                s.unknown_after = true;
                s.breaks = true;
            }
            // Plane, cutter compensation off, path control modes, initial/R plane return.
            Some(170 | 180 | 190 | 400 | 600 | 610 | 640 | 6410..=6450 | 980 | 990) => {}
            Some(900) => s.incremental = Some(false),
            Some(910) => s.incremental = Some(true),
            Some(200 | 700 | 7000) => s.inch = Some(true),
            Some(210 | 710 | 7100) => s.inch = Some(false),
            Some(940) => s.feed_mode = Some(FeedMode::PerMinute),
            Some(930) => s.feed_mode = Some(FeedMode::InverseTime),
            Some(950) => s.feed_mode = Some(FeedMode::PerRevolution),
            Some(540) if heidenhain => {
                s.datum_shift = true;
                s.stated_datum = true;
            }
            Some(530) if heidenhain => s.datum_shift = true,
            Some(540..=590 | 5000 | 5050..=5990) => s.work_offset = true,
            // Fanuc: G68 rotation (G68.1–G68.4: tilted working planes), G69 its end; G51
            // scaling, G50 its end; G51.1 mirror image, G50.1 its end.
            Some(680..=684) => {
                s.datum_shift = true;
                s.transform_on |= ROTATION;
            }
            Some(690) => {
                s.datum_shift = true;
                s.transform_off |= ROTATION;
            }
            Some(510) => {
                s.datum_shift = true;
                s.transform_on |= SCALING;
            }
            Some(500) => {
                s.datum_shift = true;
                s.transform_off |= SCALING;
            }
            Some(511) => {
                s.datum_shift = true;
                s.transform_on |= MIRROR;
            }
            Some(501) => {
                s.datum_shift = true;
                s.transform_off |= MIRROR;
            }
            Some(920) => s.g92 = true,
            Some(100 | 520) => s.datum_shift = true,
            Some(530 | 280 | 300) => s.reference = true,
            Some(40) => {
                s.no_move = true;
                s.breaks = true;
            }
            Some(650 | 660 | 661) => {
                s.no_move = true;
                s.unknown_after = true;
                s.breaks = true;
                s.maybe_flow = true;
            }
            _ => s.breaks = true,
        }
    }

    /// An identifier (`name`, its bytes at `at`).
    fn ident(&self, name: &[u8], at: Range<usize>, s: &mut Scan) {
        if let Some(sw) = self.controller.ident(self.dialect, name) {
            s.tcpm = Some(sw);
            return;
        }
        let is = |n: &[u8]| name.eq_ignore_ascii_case(n);
        if is(b"MSG") {
        } else if is_sinumerik_frame(name) {
            s.datum_shift = true;
        } else if is(b"SUPA") {
            s.reference = true;
        } else if FLOW.iter().any(|n| is(n)) {
            // Program flow (jumps, loops, calls): the blocks after it may not follow the
            // ones before it, so positions are unknown after it.
            s.unknown_after = true;
            s.breaks = true;
            s.maybe_flow = true;
        } else {
            s.breaks = true;
            // Sinumerik: a label, or a subprogram called by its name; Fanuc: `END 1`.
            s.maybe_flow |= self.dialect == Dialect::Sinumerik || is(b"END");
            // A word the reader does not know that looks like a TCPM code: warned about.
            if s.lookalike.is_none() && crate::tcpm::lookalike(name, &self.controller).is_some() {
                s.lookalike = Some(at);
            }
        }
    }

    /// Read the line `span` (its words appended to `words`) and apply it.
    pub(crate) fn block(
        &mut self,
        bytes: &[u8],
        span: Range<usize>,
        line: usize,
        words: &mut Vec<Word>,
    ) -> Result<Block, ParseError> {
        let first_word = words.len();
        let mut s = self.lex(bytes, span.clone(), line, words)?;
        Ok(self.apply(&mut s, line, span, first_word..words.len()))
    }

    /// What a line says (its words appended to `words`), before the modal state: this
    /// depends on the dialect only, so lines can be lexed in any order
    /// ([`crate::scan`] does it on several threads).
    pub(crate) fn lex(
        &self,
        bytes: &[u8],
        span: Range<usize>,
        line: usize,
        words: &mut Vec<Word>,
    ) -> Result<Scan, ParseError> {
        let mut s = Scan::default();
        self.lex_into(bytes, span, line, words, &mut s)?;
        Ok(s)
    }

    /// [`Interpreter::lex`] into `s`, which is `Scan::default()` (a reader that keeps the
    /// lines of a window fills them in place: a `Scan` is a few hundred bytes). An error
    /// after a lone CR in the line names the CR ([`crate::lines::explain_lone_cr`]).
    pub(crate) fn lex_into(
        &self,
        bytes: &[u8],
        span: Range<usize>,
        line: usize,
        words: &mut Vec<Word>,
        s: &mut Scan,
    ) -> Result<(), ParseError> {
        let first = words.len();
        self.lex_line(bytes, span.clone(), line, words, s)
            .map_err(|e| crate::lines::explain_lone_cr(bytes, &span, e))?;
        // Whether the block may say something of the tool ([`crate::tooldesc`]): looked at
        // here, where lines are lexed side by side, not where blocks are taken in order.
        if crate::tooldesc::may_name_tool(&bytes[span], &words[first..]) {
            s.flags.set(Flags::MAY_NAME_TOOL);
        }
        Ok(())
    }

    fn lex_line(
        &self,
        bytes: &[u8],
        span: Range<usize>,
        line: usize,
        words: &mut Vec<Word>,
        s: &mut Scan,
    ) -> Result<(), ParseError> {
        if self.dialect == Dialect::Conversational {
            *s = crate::conversational::lex(&self.controller, bytes, span, line, words)?;
            return Ok(());
        }
        let mut l = IsoLine::new(span.clone(), line);
        let mut lexer = Lexer::new(bytes, span.clone());
        loop {
            // Most tokens are plain words: read without the general path.
            let token = match lexer.next_plain_word() {
                Some(t) => t,
                None => match lexer.next() {
                    Some(t) => {
                        t.map_err(|e| ParseError::at(line, e.at - span.start + 1, e.message))?
                    }
                    None => break,
                },
            };
            match token {
                Token::Word {
                    letter,
                    span: wspan,
                    value_span,
                    value,
                    form,
                } => {
                    self.word(&mut l, letter, wspan.start, value, form, s)?;
                    // Offsets fit: files are at most 4 GiB.
                    words.push(Word {
                        letter,
                        form,
                        // `)` and the blanks before it: a few bytes.
                        tail: (wspan.end - value_span.end).min(255) as u8,
                        start: wspan.start as u32,
                        value_start: value_span.start as u32,
                        end: value_span.end as u32,
                        value,
                    });
                }
                Token::Ident { name, span: ispan } => {
                    let is_function = bytes[name.clone()].eq_ignore_ascii_case(b"FUNCTION");
                    if is_function && self.dialect == Dialect::Heidenhain {
                        function(&bytes[ispan.start..span.end], s);
                        break;
                    }
                    self.ident_token(&mut l, bytes, name, ispan, s);
                }
                Token::Assign {
                    letter,
                    span: aspan,
                } => {
                    l.once(letter, aspan.start)?;
                    assignment(letter, &bytes[aspan.start + 1..aspan.end], s);
                }
                Token::Indexed { letter, .. } => crate::millplus::indexed(self.dialect, letter, s),
                Token::Percent { span } => {
                    percent_units(&bytes[span], s);
                    // `%NAME` in a Heidenhain ISO block calls another program.
                    s.maybe_flow |= self.dialect == Dialect::Heidenhain;
                }
                Token::Slash { .. } => {
                    s.flags.set(Flags::SKIPPABLE);
                    s.breaks = true;
                }
                Token::Comment { span } => {
                    let text = &bytes[span];
                    if text.first() == Some(&b'(')
                        && text.last() != Some(&b')')
                        && looks_like_axis_words(text)
                    {
                        s.flags.set(Flags::UNCLOSED_COMMENT);
                    }
                }
                // A parameter outside an axis word (an assignment `#<a> = 5`, `#1=#2+1`):
                // no motion, but the line is not a plain move either.
                Token::Param { span: pspan } => {
                    s.breaks = true;
                    match macro_assignment(bytes, pspan, span.end) {
                        Some((Some(n), value)) if s.assign.is_none() => {
                            s.assign = Some((n, value));
                        }
                        Some(_) => s.assign_other = true,
                        None => {}
                    }
                }
                Token::BlockEnd { .. } | Token::Other { .. } => {}
            }
        }
        self.frames_after_words(
            s,
            l.h_word,
            l.r_word,
            l.sinumerik_frame.map(|r| &bytes[r]),
            l.rpl,
            l.cycle800_level,
        );
        if s.maybe_flow {
            s.flow = crate::statements::read_iso(self.dialect, bytes, span.clone());
        }
        after_lex(bytes, &span, s);
        Ok(())
    }

    /// A word with a plain number (`letter` at `at`, its `value` and rotary `form`).
    fn word(
        &self,
        l: &mut IsoLine,
        letter: u8,
        at: usize,
        value: f64,
        form: RotaryForm,
        s: &mut Scan,
    ) -> Result<(), ParseError> {
        if matches!(letter, b'A' | b'B' | b'C') {
            s.axes_form[usize::from(letter - b'A')] = form;
        }
        l.once(letter, at)?;
        // An auxiliary axis of the machine (an extruder on `A`): carried like `E`.
        let read_as = if self.controller.auxiliary.contains(&letter) {
            b'E'
        } else {
            letter
        };
        match read_as {
            b'X' => s.axes[X] = Some(value),
            b'Y' => s.axes[Y] = Some(value),
            b'Z' => s.axes[Z] = Some(value),
            b'A' => s.axes[A] = Some(value),
            b'B' => s.axes[B] = Some(value),
            b'C' => s.axes[C] = Some(value),
            b'F' => s.feed = Some(value),
            b'G' => self.g(code10(value), s),
            b'M' => m_code(self.dialect, &self.controller, code10(value), s),
            // Heidenhain ISO `T5 G17` calls the tool; elsewhere a T word
            // alone selects the next tool (the change is `M6`): a preselect
            // moves nothing and ends no run.
            b'T' if self.dialect == Dialect::Heidenhain => {
                s.flags.set(Flags::TOOL_CHANGE);
                s.breaks = true;
            }
            b'T' => {}
            b'N' => {
                s.number =
                    (value >= 0.0 && value.fract() == 0.0 && value < 1e15).then_some(value as u64);
            }
            b'R' => l.r_word = Some(value),
            // Spindle, arc centre, program number; extruder and auxiliary axes
            // are carried through (listed by the caller).
            b'S' | b'I' | b'J' | b'K' | b'E' | b'U' | b'V' | b'W' => {}
            // A program number or LinuxCNC o-word, a label or subprogram call.
            b'O' | b'L' => {
                s.maybe_flow = true;
                if letter == b'L' {
                    s.breaks = true;
                }
            }
            // D/H offsets, P Q L parameters.
            _ => {
                if letter == b'H' {
                    l.h_word = Some(value);
                }
                s.breaks = true
            }
        }
        Ok(())
    }

    /// An identifier token (`name`, the token at `ispan`) other than Heidenhain's
    /// `FUNCTION`: Sinumerik's frame instructions are noted for after the words.
    fn ident_token(
        &self,
        l: &mut IsoLine,
        bytes: &[u8],
        name: Range<usize>,
        ispan: Range<usize>,
        s: &mut Scan,
    ) {
        let n = &bytes[name.clone()];
        if self.dialect == Dialect::Sinumerik {
            if n.eq_ignore_ascii_case(b"CYCLE800") {
                l.cycle800_level = Some(!cycle800_rotates(&bytes[name.end..ispan.end]));
            } else if n.eq_ignore_ascii_case(b"RPL") {
                l.rpl = true;
            } else if is_sinumerik_frame(n) {
                l.sinumerik_frame = Some(name.clone());
            }
        }
        self.ident(n, name, s)
    }
    /// The frame transformations of a block, once its words are read.
    fn frames_after_words(
        &self,
        s: &mut Scan,
        h_word: Option<f64>,
        r_word: Option<f64>,
        sinumerik_frame: Option<&[u8]>,
        rpl: bool,
        cycle800_level: Option<bool>,
    ) {
        use crate::modal::transform::{MIRROR, ROTATION, SCALING};
        let has_axes = s.axes.iter().any(Option::is_some) || s.axes_expr != 0;
        match self.dialect {
            Dialect::Heidenhain => match s.heidenhain_frame {
                // G73 H…: a rotation (H0 ends it).
                Some(730) => {
                    if h_word == Some(0.0) {
                        s.transform_off |= ROTATION;
                    } else {
                        s.transform_on |= ROTATION;
                    }
                }
                // G72 F…: a scaling factor, not a feed (F1 ends it).
                Some(720) => {
                    if s.feed == Some(1.0) {
                        s.transform_off |= SCALING;
                    } else {
                        s.transform_on |= SCALING;
                    }
                    s.feed = None;
                }
                // G28 X Y: a mirror image of the named axes (none: it ends).
                Some(280) => {
                    if has_axes {
                        s.transform_on |= MIRROR;
                    } else {
                        s.transform_off |= MIRROR;
                    }
                }
                _ => {}
            },
            Dialect::Sinumerik => {
                if let Some(name) = sinumerik_frame {
                    let (on, off) = sinumerik_frame_transform(name, has_axes || rpl);
                    s.transform_on |= on;
                    s.transform_off |= off;
                }
                match cycle800_level {
                    Some(true) => s.transform_off |= ROTATION,
                    Some(false) => s.transform_on |= ROTATION,
                    None => {}
                }
                if cycle800_level.is_some() {
                    s.datum_shift = true;
                }
            }
            _ => {
                // LinuxCNC `G10 L2 P1 R30`: the coordinate system is rotated.
                if s.datum_shift && r_word.is_some_and(|r| r != 0.0) {
                    s.transform_on |= ROTATION;
                }
            }
        }
    }
    /// Fanuc/Haas macro variables with constant values (`#100=1200.` then `G1 F#100`, `X#101`):
    /// a use takes the value of the variable's assignment of a plain number when nothing
    /// between them can change it — straight-line blocks only: any program flow (a jump, a
    /// loop, a call, a label, `M6` that may run a macro, `G65`), a block-delete block, an
    /// assignment that is not a plain number or whose variable is not named by its number
    /// forgets every value. A file whose flow joins paths (a jump or a loop anywhere, read
    /// again with its [`crate::flow::FlowPlan`]) and a machine that is always TCP (whose
    /// reader does not look at flow) evaluate none. Uses are substituted into `s`, and a
    /// block left without an expression is analysed like any other.
    fn constants(&mut self, s: &mut Scan) {
        let on = self.dialect == Dialect::Fanuc && self.plan.is_none() && !self.controller.always;
        if !on {
            return;
        }
        let had_expr = s.axes_expr != 0 || s.feed_expr;
        for (i, v) in s.vars.iter().enumerate() {
            let Some((n, neg)) = *v else { continue };
            let Some(&value) = self.consts.get(&n) else {
                continue;
            };
            let value = if neg { -value } else { value };
            if i < 6 {
                s.axes[i] = Some(value);
                s.axes_expr &= !bit(i);
            } else {
                s.feed = Some(value);
                s.feed_expr = false;
            }
        }
        if had_expr && s.axes_expr == 0 && !s.feed_expr {
            s.flags.clear(Flags::NOT_ANALYSABLE);
            if s.expr_breaks {
                s.breaks = false;
            }
        }
        if s.flow.is_some()
            || s.maybe_flow
            || s.unknown_after
            || s.assign_other
            || s.flags.has(Flags::SKIPPABLE)
        {
            self.consts.clear();
        } else if let Some((n, v)) = s.assign {
            match v {
                Some(v) => {
                    self.consts.insert(n, v);
                }
                None => {
                    self.consts.remove(&n);
                }
            }
        }
    }

    /// Update the modal state; the block's `state` index is set by the caller.
    pub(crate) fn apply(
        &mut self,
        s: &mut Scan,
        line: usize,
        span: Range<usize>,
        words: Range<usize>,
    ) -> Block {
        self.constants(s);
        // G92 shifts the axes it names: a datum shift of ours only where it names one.
        s.datum_shift |= s.g92 && (s.axes.iter().any(Option::is_some) || s.axes_expr != 0);
        self.follow_flow(s, line);
        // A Heidenhain control (ISO or conversational) turns a plain rotary word the way it
        // is written unless M126 is active; the machine's endless axes count elsewhere.
        let endless_axes = if matches!(self.dialect, Dialect::Heidenhain | Dialect::Conversational)
        {
            [false; 3]
        } else {
            self.endless
        };
        let pos_before = self.modal.pos;
        let mut out = Outcome {
            breaks: s.breaks,
            flags: s.flags,
            is_move: false,
        };
        self.apply_modes(s, &mut out);
        self.apply_tcpm(s, &mut out);
        self.apply_feed_mode(s, &mut out);
        let scale = if self.modal.inch { 25.4 } else { 1.0 };
        self.lookalike = s.lookalike.take();
        if s.stated_datum {
            let v = |i: usize| s.axes[i].unwrap_or(0.0) * scale;
            self.stated_datum = Some([v(X), v(Y), v(Z)]);
        } else if s.datum_shift || s.work_offset {
            self.frame_changed = true;
        }
        self.apply_feed(s, scale);
        apply_positions(&mut self.modal, s, scale, &mut out);
        let m = &self.modal;
        if s.axes_incremental != 0 {
            out.flags.set(Flags::INCREMENTAL_WORDS);
            out.breaks = true;
        }
        if out.is_move && !out.breaks && m.motion == Motion::Linear && !m.incremental {
            let endless = |k: usize| endless_axes[k - A] || m.shortest_path;
            if wrap_axis(s, &pos_before, &m.pos, endless).is_some() {
                out.flags.set(Flags::ROTARY_WRAP);
                out.breaks = true;
            }
        }
        // Offsets fit: files are at most 4 GiB.
        Block {
            line,
            start: span.start as u32,
            end: span.end as u32,
            words_start: words.start as u32,
            words_end: words.end as u32,
            state: 0,
            is_move: out.is_move,
            breaks_run: out.breaks,
            flags: out.flags,
        }
    }

    /// Program flow before the block: the state the flow plan settles at its line
    /// ([`crate::flow`]), and the block's flow events for the recorder of a first read.
    fn follow_flow(&mut self, s: &Scan, line: usize) {
        let always = self.controller.always;
        if let Some(plan) = &self.plan {
            let (tcpm, join) = self.cursor.at(plan, line);
            if let Some(t) = tcpm {
                self.modal.tcpm = t;
            }
            if join {
                self.modal.pos = [None; 6];
            }
        }
        if let Some(r) = &mut self.recorder
            && (s.flow.is_some()
                || s.tcpm.is_some()
                || s.flags.has(Flags::PROGRAM_END)
                || (s.number.is_some() && r.wants_block_labels()))
        {
            r.block(&crate::flow::BlockFlow {
                line,
                stmt: s.flow.as_ref(),
                switch: s.tcpm.filter(|_| !always).map(Switch::state),
                skippable: s.flags.has(Flags::SKIPPABLE),
                program_end: s.flags.has(Flags::PROGRAM_END),
                number: s.number,
            });
        }
    }

    /// The modes the block sets: shortest path, motion, canned cycle, incremental, units,
    /// frame transformations.
    fn apply_modes(&mut self, s: &Scan, out: &mut Outcome) {
        let m = &mut self.modal;
        if let Some(sp) = s.shortest_path {
            m.shortest_path = sp;
        }
        if out.flags.has(Flags::PROGRAM_END) {
            // "At the end of program, M126 is automatically canceled" (Heidenhain).
            m.shortest_path = false;
        }
        if let Some(mo) = s.motion {
            m.motion = mo;
            // A motion code ends a canned cycle (Fanuc group 01 over group 09).
            m.canned_cycle = false;
        }
        if let Some(c) = s.cycle {
            m.canned_cycle = c;
        }
        if s.rapid_once {
            // FMAX holds for its own block: the state after it is a rapid, and the next
            // `L` block sets linear motion again.
            m.motion = Motion::Rapid;
        }
        if let Some(inc) = s.incremental {
            m.incremental = inc;
        }
        if let Some(inch) = s.inch {
            m.inch = inch;
            out.flags.set(Flags::UNITS);
        }
        m.transform = (m.transform & !s.transform_off) | s.transform_on;
    }

    /// TCPM after the block: its switch, and code it runs that may switch it.
    fn apply_tcpm(&mut self, s: &Scan, out: &mut Outcome) {
        let always = self.controller.always;
        let m = &mut self.modal;
        if let Some(sw) = s.tcpm {
            if !always {
                m.tcpm = m.tcpm.switched(sw.state(), out.flags.has(Flags::SKIPPABLE));
            }
            if sw == Switch::On {
                m.tcpm_centre = s.tcpm_centre;
            }
            out.breaks = true;
        }
        if !always {
            match &s.flow {
                // Code outside the file runs: it may switch TCPM.
                Some(crate::flow::Stmt::External) => m.tcpm = Tcpm::Unknown,
                Some(crate::flow::Stmt::ToolChange) => m.tcpm = m.tcpm.after_tool_change(),
                // Flow that joins paths, on a read without its plan: unknown until solved.
                Some(st) if self.plan.is_none() && st.is_global() => m.tcpm = Tcpm::Unknown,
                _ => {}
            }
            if self.plan.as_ref().is_some_and(|p| p.all_unknown()) {
                m.tcpm = Tcpm::Unknown;
            }
        }
    }

    /// The feed mode (per minute, inverse time, per revolution): a change forgets the feed.
    fn apply_feed_mode(&mut self, s: &Scan, out: &mut Outcome) {
        let m = &mut self.modal;
        if let Some(fm) = s.feed_mode
            && fm != m.feed_mode
        {
            m.feed_mode = fm;
            m.feed_mm_min = None;
            out.breaks = true;
        }
        m.inverse_time_per_min = None;
    }

    /// The feed the block states, in mm/min (`scale`: mm per program unit).
    fn apply_feed(&mut self, s: &Scan, scale: f64) {
        let m = &mut self.modal;
        if s.feed_expr || s.feed_unknown {
            m.feed_mm_min = None;
        } else if let Some(f) = s.feed {
            match m.feed_mode {
                FeedMode::PerMinute => {
                    // Heidenhain conversational inch programs give F in 1/10 inch/min.
                    let f_scale = if self.dialect == Dialect::Conversational && m.inch {
                        2.54
                    } else {
                        scale
                    };
                    m.feed_mm_min = Some(f * f_scale);
                }
                FeedMode::InverseTime => m.inverse_time_per_min = Some(f),
                FeedMode::PerRevolution => m.feed_mm_min = None,
            }
        }
    }
}

/// What [`Interpreter::apply`] finds out about a block as it goes.
struct Outcome {
    /// The block ends a run.
    breaks: bool,
    flags: Flags,
    /// The block moves the tool.
    is_move: bool,
}

/// The positions after the block (`scale`: mm per program unit of a linear value), and
/// whether it moves.
fn apply_positions(m: &mut Modal, s: &Scan, scale: f64, out: &mut Outcome) {
    let has_axes = s.axes.iter().any(Option::is_some) || s.axes_expr != 0;
    if s.datum_shift || s.reference || s.unknown_after {
        // Linear positions unknown afterwards; so are rotary axes named in the block.
        for (i, p) in m.pos.iter_mut().enumerate() {
            if i < A || s.axes[i].is_some() || s.axes_expr & bit(i) != 0 || s.unknown_after {
                *p = None;
            }
        }
        out.is_move = s.reference && has_axes;
        out.breaks = true;
        return;
    }
    if s.no_move {
        out.breaks = true;
        return;
    }
    if s.work_offset {
        m.pos[X] = None;
        m.pos[Y] = None;
        m.pos[Z] = None;
        out.breaks = true;
    }
    for (i, v) in s.axes.iter().enumerate() {
        let form = if i >= A {
            s.axes_form[i - A]
        } else {
            RotaryForm::Plain
        };
        if let Some(v) = *v
            && form.is_directional()
        {
            // A position modulo 360 and a direction (absolute in G91 too): the
            // controller's unwrapped position follows from where the axis is; from
            // an unknown position, the value itself (the same pose). DC to a half
            // turn names no direction: unknown.
            m.pos[i] = match m.pos[i] {
                Some(p) => form.delta(p, v).map(|d| p + d),
                None => Some(v.rem_euclid(360.0)),
            };
            if m.pos[i].is_none() {
                out.breaks = true;
            }
        } else if let Some(v) = *v {
            let v = if i < A { v * scale } else { v };
            m.pos[i] = if m.incremental || s.axes_incremental & bit(i) != 0 {
                m.pos[i].map(|p| p + v)
            } else {
                Some(v)
            };
        }
        if s.axes_expr & bit(i) != 0 {
            m.pos[i] = None;
        }
    }
    if s.xy_unknown_after {
        m.pos[X] = None;
        m.pos[Y] = None;
    }
    if m.canned_cycle && has_axes {
        // A hole: the tool goes down and back to a plane the reader does not
        // follow.
        m.pos[Z] = None;
        out.is_move = true;
        out.breaks = true;
    } else if has_axes || s.xy_unknown_after {
        out.is_move = m.motion != Motion::None;
        if m.motion != Motion::Linear {
            out.breaks = true;
        }
        if matches!(m.motion, Motion::ArcCw | Motion::ArcCcw) {
            out.flags.set(Flags::ARC);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::modal::{C, X};
    use crate::{Dialect, Flags, parse};

    fn read(src: &str) -> crate::Program {
        parse(src.as_bytes().to_vec(), Dialect::Fanuc).unwrap()
    }

    /// Issue 30 item 11: a macro variable assigned a constant, used with nothing between
    /// that can change it, is read as its value.
    #[test]
    fn macro_constants_are_evaluated_in_straight_line_code() {
        let p = read("#100=1200. (FEED)\n#101 = -10.\nG1 X#101 Y0 F#100\nX-#101 C#105\n");
        assert_eq!(p.state(2).feed_mm_min, Some(1200.0));
        assert_eq!(p.state(2).pos[X], Some(-10.0));
        assert!(!p.blocks[2].flags.has(Flags::NOT_ANALYSABLE));
        assert!(!p.blocks[2].breaks_run);
        assert_eq!(p.state(3).pos[X], Some(10.0));
        // #105 was never assigned: listed as before.
        assert!(p.blocks[3].flags.has(Flags::NOT_ANALYSABLE));
        assert_eq!(p.state(3).pos[C], None);
        // A reassignment in straight-line code: the new value.
        let p = read("#100=1200.\n#100=800.\nG1 X1 F#100\n");
        assert_eq!(p.state(2).feed_mm_min, Some(800.0));
        // System variables may change under the program.
        let p = read("#5221=-100.\nG1 X#5221 F100.\n");
        assert_eq!(p.state(1).pos[X], None);
    }

    /// Anything that may change a variable between assignment and use leaves the use an
    /// expression: a call, a tool change (a macro), a non-constant assignment, a
    /// block-delete block, a loop or jump anywhere in the file.
    #[test]
    fn flow_calls_and_other_assignments_forget_the_values() {
        for src in [
            "#100=1200.\nM98 P2000\nG1 X1 F#100\n",
            "#100=1200.\nT2 M6\nG1 X1 F#100\n",
            "#100=1200.\nG65 P9000 A1.\nG1 X1 F#100\n",
            "#100=1200.\n#100=#100*2\nG1 X1 F#100\n",
            "#100=1200.\n#[#1]=5.\nG1 X1 F#100\n",
            "#100=1200.\n/#100=500.\nG1 X1 F#100\n",
            "#100=1200.\nIF [#1 GT 0] THEN #100=500.\nG1 X1 F#100\n",
            "#100=1200.\nN10 G1 X1 F#100\n#100=500.\nGOTO 10\nM30\n",
            "#100=1200.\nWHILE [#1 LT 3] DO 1\nG1 X1 F#100\n#1=#1+1\nEND 1\n",
        ] {
            let p = read(src);
            let b = p
                .blocks
                .iter()
                .position(|b| String::from_utf8_lossy(&p.bytes[b.span()]).contains("F#100"))
                .unwrap();
            assert!(p.blocks[b].flags.has(Flags::NOT_ANALYSABLE), "{src}");
            assert_eq!(p.state(b).feed_mm_min, None, "{src}");
        }
    }

    fn read_endless(src: &str, endless: [bool; 3]) -> crate::Program {
        let opts = crate::ReadOptions {
            endless,
            ..crate::ReadOptions::default()
        };
        crate::parse_with(src.as_bytes().to_vec(), &opts).unwrap()
    }

    fn wraps(p: &crate::Program) -> Vec<usize> {
        (0..p.blocks.len())
            .filter(|&b| p.blocks[b].flags.has(Flags::ROTARY_WRAP))
            .map(|b| p.blocks[b].line)
            .collect()
    }

    /// Issue 42's closing check: NX's Haas VF2 TR post writes the platter modulo 360
    /// (`B359.857` then `B7.501` in one cutting move). A controller that takes the shorter
    /// way turns +7.644°; read as written it is −352.356°. On an axis that turns without
    /// end the block is a wrap: it ends runs and belongs to none.
    #[test]
    fn a_feed_move_over_half_a_turn_on_an_endless_axis_is_a_wrap() {
        let src =
            "G1 X0 Y0 Z0 A-2.5 B352.158 F10\nX1 A-2.6 B359.857\nX2 A-2.7 B7.501\nX3 B15.092\n";
        let p = read_endless(src, [false, true, false]);
        assert_eq!(wraps(&p), vec![3]);
        assert!(p.blocks[2].breaks_run && p.blocks[2].is_move);
        // The value after it is the one written (the same pose either way).
        assert_eq!(p.state(2).pos[crate::modal::B], Some(7.501));
        let runs = crate::runs(&p);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0].blocks, vec![0, 1]);
        assert_eq!(runs[1].blocks, vec![2, 3]);
        // An axis with a range (no endless axis) is read as written: one run.
        let p = read_endless(src, [false; 3]);
        assert!(wraps(&p).is_empty());
        assert_eq!(crate::runs(&p).len(), 1);
        // Only the endless axis counts: A turning 352° on the same read is read as written.
        let p = read_endless("G1 X0 Y0 Z0 A-176 B0 F10\nX1 A176\n", [false, true, false]);
        assert!(wraps(&p).is_empty());
    }

    /// What is not a wrap: half a turn exactly (either way the same), a move without
    /// tool-tip motion (a rotary-only repositioning: in no run), a rapid, incremental words,
    /// and a Sinumerik direction form (its direction is written).
    #[test]
    fn what_is_not_a_wrap() {
        let c = [false, false, true];
        for src in [
            "G1 X0 Y0 Z0 A2 C10 F100\nX1 C190\n",
            "G1 X0 Y0 Z0 A2 C10 F100\nA0 C350\n",
            "G1 X0 Y0 Z0 A2 C10 F100\nG0 X1 C350\n",
            "G1 X0 Y0 Z0 A2 C10 F100\nG91 X1 C340\n",
            "N1 G1 X0 Y0 Z0 A2 C10 F100\nN2 TRAORI\nN3 X1 C=ACP(350)\n",
        ] {
            assert!(wraps(&read_endless(src, c)).is_empty(), "{src}");
        }
        assert_eq!(
            wraps(&read_endless("G1 X0 Y0 Z0 A2 C10 F100\nX1 C190.001\n", c)),
            vec![2]
        );
    }

    /// Heidenhain `M126` (shortest-path traverse): under it a plain move over half a turn is
    /// a wrap on any rotary axis; `M127` and the program's end switch it off. Not a Fanuc
    /// code.
    #[test]
    fn heidenhain_m126_makes_every_rotary_axis_take_the_shorter_way() {
        let conv = "0 BEGIN PGM W MM\n1 L X+0 Y+0 Z+0 B+5 C+350 R0 F1000\n2 M126\n\
                    3 L X+0 Y+0 Z+0 R0 F1000\n4 L X+1 C+10\n5 M127\n6 L X+2 C+350\n\
                    7 END PGM W MM\n";
        let p = read_endless(conv, [false; 3]);
        assert_eq!(wraps(&p), vec![5]);
        assert!(p.state(3).shortest_path && !p.state(5).shortest_path);
        let iso = "%W G71 *\nN10 G01 X+0 Y+0 Z+0 B+5 C+350 F1000 *\nN20 M126 *\n\
                   N30 X+1 C+10 *\nN40 M30 *\nN50 G01 X+0 C+350 F1000 *\n";
        let p = read_endless(iso, [false; 3]);
        assert_eq!(wraps(&p), vec![4]);
        assert!(!p.state(5).shortest_path);
        let fanuc = "G1 X0 Y0 Z0 B5 C350 F1000\nM126\nX1 C10\n";
        assert!(wraps(&read_endless(fanuc, [false; 3])).is_empty());
        // Without M126 a Heidenhain control turns as written, even on a machine whose C
        // turns without end (the bench's SINGW.I): no wrap; with it, the wrap.
        let plain = "%W G71 *\nN10 G01 X+0 Y+0 Z+0 B+5 C+350 F1000 *\nN20 X+1 C+10 *\n";
        assert!(wraps(&read_endless(plain, [false, false, true])).is_empty());
        let conv = "0 BEGIN PGM W MM\n1 L X+0 Y+0 Z+0 B+5 C+350 R0 F1000\n\
                    2 L X+1 C+10\n3 END PGM W MM\n";
        assert!(wraps(&read_endless(conv, [false, false, true])).is_empty());
        assert_eq!(wraps(&read_endless(iso, [false, false, true])), vec![4]);
    }
}
