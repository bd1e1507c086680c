//! What a line says ([`Scan`], lexed on any thread) and how it changes the modal state
//! ([`Interpreter::apply`], in file order). The rules are in [`crate::modal`]'s docs; the
//! TCPM codes in [`crate::tcpm`]; Heidenhain conversational lines in
//! [`crate::conversational`].

use crate::error::ParseError;
use crate::lexer::{Lexer, Token};
use crate::modal::{A, AXES, B, C, FeedMode, Modal, Motion, Tcpm, X, Y, Z};
use crate::program::{Block, Dialect, Flags, Word};
use crate::tcpm::{ControllerCodes, ReadOptions, Switch, code10};
use std::ops::Range;

/// What one block says, collected before the modal state is updated.
#[derive(Debug, Default)]
pub(crate) struct Scan {
    pub(crate) axes: [Option<f64>; 6],
    /// Bit `i`: axis `i`'s value is an expression or a variable (not a plain number).
    pub(crate) axes_expr: u8,
    /// Bit `i`: axis `i`'s word is incremental for this block only (conversational `IX`).
    pub(crate) axes_incremental: u8,
    pub(crate) feed: Option<f64>,
    /// The F word is an expression or a variable.
    pub(crate) feed_expr: bool,
    /// The feed is not per minute for this block (conversational `FU`, `FZ`, `FAUTO`).
    pub(crate) feed_unknown: bool,
    pub(crate) motion: Option<Motion>,
    /// A canned cycle switched on (`G81`…) or off (`G80`).
    pub(crate) cycle: Option<bool>,
    /// Conversational `FMAX`: this block is a rapid, the next one is not.
    pub(crate) rapid_once: bool,
    pub(crate) incremental: Option<bool>,
    pub(crate) inch: Option<bool>,
    /// Conversational: F is in 1/10 inch/min in an inch program.
    pub(crate) tcpm: Option<Switch>,
    pub(crate) feed_mode: Option<FeedMode>,
    /// Axis words define a datum/frame (Heidenhain G54, G92, G10, G52, TRANS…): not a move.
    pub(crate) datum_shift: bool,
    /// Heidenhain ISO `G54`: the block's X Y Z are the new datum.
    pub(crate) stated_datum: bool,
    /// Work offset selection (Fanuc/Sinumerik G54…G59, G500): positions re-based.
    pub(crate) work_offset: bool,
    /// Reference / machine-coordinate move (G28, G30, G53, SUPA).
    pub(crate) reference: bool,
    /// Axis words are arguments, not a move (G4 dwell, G65 macro call, conversational
    /// `BLK FORM`, `CC`).
    pub(crate) no_move: bool,
    /// Positions are unknown afterwards (macro or subprogram call, label, cycle call).
    pub(crate) unknown_after: bool,
    /// X and Y are unknown afterwards (a polar move).
    pub(crate) xy_unknown_after: bool,
    pub(crate) breaks: bool,
    /// Flags for the block.
    pub(crate) flags: Flags,
}

pub(crate) struct Interpreter {
    pub(crate) dialect: Dialect,
    pub(crate) controller: ControllerCodes,
    pub(crate) modal: Modal,
    /// The datum the last block stated (Heidenhain `G54 X Y Z`), taken by the caller.
    pub(crate) stated_datum: Option<[f64; 3]>,
    /// The last block changed the frame without stating it, taken by the caller.
    pub(crate) frame_changed: bool,
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

impl Interpreter {
    pub(crate) fn new(opts: &ReadOptions, dialect: Dialect) -> Self {
        Interpreter {
            dialect,
            controller: opts.controller.clone(),
            modal: opts.initial(),
            stated_datum: None,
            frame_changed: false,
        }
    }

    fn g(&self, code: Option<i64>, s: &mut Scan) {
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

    pub(crate) fn m(&self, code: Option<i64>, s: &mut Scan) {
        let sw = code.and_then(|c| self.controller.m(self.dialect, c));
        if let Some(sw) = sw {
            s.tcpm = Some(sw);
        }
        match code {
            // Spindle and coolant.
            Some(30 | 40 | 50 | 70 | 80 | 90 | 130 | 140) => {}
            Some(60) => {
                s.flags.set(Flags::TOOL_CHANGE);
                s.breaks = true;
            }
            Some(20 | 300) => {
                s.flags.set(Flags::PROGRAM_END);
                s.breaks = true;
            }
            // Subprogram call and return, cycle call (Heidenhain M99): other blocks run.
            Some(980 | 990) => {
                s.unknown_after = true;
                s.breaks = true;
            }
            // A TCPM switch (breaks through the state change).
            _ if sw.is_some() => {}
            // Stops, anything unknown.
            _ => s.breaks = true,
        }
    }

    fn ident(&self, name: &[u8], s: &mut Scan) {
        if let Some(sw) = self.controller.ident(self.dialect, name) {
            s.tcpm = Some(sw);
            return;
        }
        let is = |n: &[u8]| name.eq_ignore_ascii_case(n);
        if is(b"MSG") {
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
        } else if FLOW.iter().any(|n| is(n)) {
            // Program flow (jumps, loops, calls): the blocks after it may not follow the
            // ones before it, so positions are unknown after it.
            s.unknown_after = true;
            s.breaks = true;
        } else {
            s.breaks = true;
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
        let s = self.lex(bytes, span.clone(), line, words)?;
        Ok(self.apply(s, line, span, first_word..words.len()))
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
        if self.dialect == Dialect::Conversational {
            return crate::conversational::lex(self, bytes, span, line, words);
        }
        let mut s = Scan::default();
        // X Y Z A B C F seen in this block, with the column of the first.
        let mut seen: [Option<usize>; 7] = [None; 7];
        let col = |at: usize| at - span.start + 1;
        let mut once = |letter: u8, at: usize| -> Result<(), ParseError> {
            if let Some(k) = b"XYZABCF".iter().position(|&l| l == letter) {
                if let Some(first) = seen[k] {
                    return Err(ParseError::at(
                        line,
                        col(at),
                        format!(
                            "{} appears twice in this block (first at col {first}); controllers \
                             reject such a block and polepatch will not guess which is meant",
                            letter as char
                        ),
                    ));
                }
                seen[k] = Some(col(at));
            }
            Ok(())
        };
        for token in Lexer::new(bytes, span.clone()) {
            let token =
                token.map_err(|e| ParseError::at(line, e.at - span.start + 1, e.message))?;
            match token {
                Token::Word {
                    letter,
                    span: wspan,
                    value_span,
                    value,
                } => {
                    once(letter, wspan.start)?;
                    match letter {
                        b'X' => s.axes[X] = Some(value),
                        b'Y' => s.axes[Y] = Some(value),
                        b'Z' => s.axes[Z] = Some(value),
                        b'A' => s.axes[A] = Some(value),
                        b'B' => s.axes[B] = Some(value),
                        b'C' => s.axes[C] = Some(value),
                        b'F' => s.feed = Some(value),
                        b'G' => self.g(code10(value), &mut s),
                        b'M' => self.m(code10(value), &mut s),
                        b'T' => {
                            s.flags.set(Flags::TOOL_CHANGE);
                            s.breaks = true;
                        }
                        // Block number, spindle, arc centre and radius, program number;
                        // extruder and auxiliary axes are carried through (listed by the
                        // caller).
                        b'N' | b'S' | b'I' | b'J' | b'K' | b'R' | b'O' | b'E' | b'U' | b'V'
                        | b'W' => {}
                        // D/H offsets, P Q L parameters.
                        _ => s.breaks = true,
                    }
                    // Offsets fit: files are at most 4 GiB.
                    words.push(Word {
                        letter,
                        start: wspan.start as u32,
                        value_start: value_span.start as u32,
                        end: wspan.end as u32,
                        value,
                    });
                }
                Token::Ident { name, span: ispan } => {
                    let is_function = bytes[name.clone()].eq_ignore_ascii_case(b"FUNCTION");
                    if is_function && self.dialect == Dialect::Heidenhain {
                        function(&bytes[ispan.start..span.end], &mut s);
                        break;
                    }
                    self.ident(&bytes[name], &mut s)
                }
                Token::Assign {
                    letter,
                    span: aspan,
                } => {
                    once(letter, aspan.start)?;
                    if let Some(i) = AXES.iter().position(|&l| l == letter) {
                        s.axes_expr |= bit(i);
                    } else if letter == b'F' {
                        s.feed_expr = true;
                    } else if letter == b'O' {
                        // `o<name> call`, `o<name> sub`: LinuxCNC program flow.
                        s.unknown_after = true;
                        s.breaks = true;
                    } else if !matches!(letter, b'R' | b'S') {
                        s.breaks = true;
                    }
                }
                Token::Indexed { letter, .. } => {
                    crate::millplus::indexed(self.dialect, letter, &mut s)
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
                Token::Param { .. } => s.breaks = true,
                Token::BlockEnd { .. } | Token::Other { .. } => {}
            }
        }
        if s.axes_expr != 0 || s.feed_expr {
            s.flags.set(Flags::NOT_ANALYSABLE);
            s.breaks = true;
        }
        Ok(s)
    }

    /// Update the modal state; the block's `state` index is set by the caller.
    pub(crate) fn apply(
        &mut self,
        s: Scan,
        line: usize,
        span: Range<usize>,
        words: Range<usize>,
    ) -> Block {
        let always = self.controller.always;
        let m = &mut self.modal;
        let mut breaks = s.breaks;
        let mut flags = s.flags;
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
            flags.set(Flags::UNITS);
        }
        if let Some(sw) = s.tcpm {
            if !always {
                let target = match sw {
                    Switch::On => Tcpm::On,
                    Switch::Off => Tcpm::Off,
                };
                m.tcpm = if flags.has(Flags::SKIPPABLE) && m.tcpm != target {
                    Tcpm::Uncertain
                } else {
                    target
                };
            }
            breaks = true;
        }
        if let Some(fm) = s.feed_mode
            && fm != m.feed_mode
        {
            m.feed_mode = fm;
            m.feed_mm_min = None;
            breaks = true;
        }
        m.inverse_time_per_min = None;
        let scale = if m.inch { 25.4 } else { 1.0 };
        if s.stated_datum {
            let v = |i: usize| s.axes[i].unwrap_or(0.0) * scale;
            self.stated_datum = Some([v(X), v(Y), v(Z)]);
        } else if s.datum_shift || s.work_offset {
            self.frame_changed = true;
        }
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
        let has_axes = s.axes.iter().any(Option::is_some) || s.axes_expr != 0;
        let mut is_move = false;
        if s.datum_shift || s.reference || s.unknown_after {
            // Linear positions unknown afterwards; so are rotary axes named in the block.
            for (i, p) in m.pos.iter_mut().enumerate() {
                if i < A || s.axes[i].is_some() || s.axes_expr & bit(i) != 0 || s.unknown_after {
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
                is_move = true;
                breaks = true;
            } else if has_axes || s.xy_unknown_after {
                is_move = m.motion != Motion::None;
                if m.motion != Motion::Linear {
                    breaks = true;
                }
                if matches!(m.motion, Motion::ArcCw | Motion::ArcCcw) {
                    flags.set(Flags::ARC);
                }
            }
        }
        if s.axes_incremental != 0 {
            flags.set(Flags::INCREMENTAL_WORDS);
            breaks = true;
        }
        // Offsets fit: files are at most 4 GiB.
        Block {
            line,
            start: span.start as u32,
            end: span.end as u32,
            words_start: words.start as u32,
            words_end: words.end as u32,
            state: 0,
            is_move,
            breaks_run: breaks,
            flags,
        }
    }
}

/// A Heidenhain `FUNCTION …` line (`text` from the word `FUNCTION` on): `FUNCTION TCPM …`
/// switches TCPM on, `FUNCTION RESET TCPM` off; any other function breaks runs.
pub(crate) fn function(text: &[u8], s: &mut Scan) {
    let mut words = text
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
        .skip(1);
    let first = words.next().unwrap_or_default();
    let second = words.next().unwrap_or_default();
    let sw = if first.eq_ignore_ascii_case(b"TCPM") {
        Some(Switch::On)
    } else if first.eq_ignore_ascii_case(b"RESET") && second.eq_ignore_ascii_case(b"TCPM") {
        Some(Switch::Off)
    } else {
        None
    };
    match sw {
        Some(sw) => s.tcpm = Some(sw),
        None => s.breaks = true,
    }
}
