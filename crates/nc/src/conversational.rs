//! Heidenhain conversational (Klartext) lines: what each says ([`lex`]).
//!
//! A line is an optional block number (digits, no `N`), a keyword and its words:
//!
//! | line | read as |
//! |---|---|
//! | `BEGIN PGM NAME MM` / `INCH` (`IN`, as NX's posts write it) | program start; INCH: lengths ×25.4, F in 1/10 inch/min ×2.54 |
//! | `END PGM NAME` | program end (TCPM off) |
//! | `L X+10 Y-5 Z+0 A+0 C+90 R0 F2000 M3` | linear move; `FMAX` a rapid for this block only; `FAUTO`, `FU`, `FZ` no feed per minute; `IX+5` incremental for this block (the block is never changed and ends runs); `RL`/`RR`/`R+`/`R-` radius compensation ends runs |
//! | `C`, `CR`, `CT` (arcs), `CP`, `LP` (polar), `APPR`, `DEP` | moves polepatch does not follow: they end runs (`LP`, `CP`, `APPR`, `DEP` leave X Y Z unknown) |
//! | `CC X+25 Y+25` | circle centre: not a move |
//! | `RND`, `CHF` | a corner rounded or chamfered: ends runs |
//! | `LN …` | 3D-compensated line with normal vectors: a move that ends runs |
//! | `TOOL CALL 5 Z S12000` | tool change; `TOOL DEF`: ends runs |
//! | `BLK FORM 0.1 Z X+0 Y+0 Z-40` | blank definition: not a move |
//! | `CYCL DEF 7.x` (datum shift), `247` (datum setting), `8`, `10`, `11`, `19`, `26` | frame changes (positions unknown after); `8.1`, `10.1`, `11.1`, `19.1`, `26.1` switch a mirror image, rotation or scaling on, or off where their values are the identity ([`crate::modal::transform`]) |
//! | `CYCL DEF` (other), `CYCL CALL`, `M99` | cycle definition ends runs; a cycle call moves the tool (positions unknown after) |
//! | `LBL n`, `LBL "NAME"`, `LBL 0`, `CALL LBL n [REP m]`, `CALL PGM`, `SEL PGM` | labels, returns and calls ([`crate::flow`]): positions unknown after; TCPM as the file's flow settles it |
//! | `FN 0..8`, `Q1 = …` | parameter arithmetic: ends runs; `FN 9..12: IF … GOTO LBL n` (conditional jumps, [`crate::flow`]): positions unknown after |
//! | `TRANS MIRROR/ROTATION/SCALE/DATUM …` (`… RESET`) | TNC7 frames: frame changes, transformations on (off) |
//! | `FUNCTION TCPM …`, `FUNCTION RESET TCPM`, `M128`, `M129` | TCPM on / off |
//! | `PLANE …` | tilted working plane: a frame change and a rotation (positions unknown after); `PLANE RESET` ends the rotation |
//! | `STOP`, `TCH PROBE`, anything else | ends runs; lines polepatch does not model leave positions unknown and are flagged |
//! | `* - text`, `; text` | comments |
//!
//! An axis word whose value is a Q parameter (`X+Q1`, `C-QR5`) marks the block not
//! analysable (positions unknown after it), never the file.

use crate::block::Flags;
use crate::dialect::Dialect;
use crate::error::ParseError;
use crate::flow::{Key, Stmt};
use crate::lexed::{Scan, after_lex, function, m_code};
use crate::lexer::parse_number;
use crate::modal::transform;
use crate::modal::{A, AXES, B, C, Motion};
use crate::tcpm::{ControllerCodes, code10};
use crate::word::{RotaryForm, Word};
use std::ops::Range;

fn axis_index(letter: u8) -> Option<usize> {
    AXES.iter().position(|&l| l == letter)
}

fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// The blank-separated tokens of `bytes[range]` up to a `;` comment, as absolute ranges.
fn tokens(bytes: &[u8], range: Range<usize>) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut i = range.start;
    while i < range.end {
        while i < range.end && is_blank(bytes[i]) {
            i += 1;
        }
        if i >= range.end || bytes[i] == b';' {
            break;
        }
        let start = i;
        while i < range.end && !is_blank(bytes[i]) && bytes[i] != b';' {
            i += 1;
        }
        out.push(start..i);
    }
    out
}

/// A keyword of the line, upper case.
fn upper(bytes: &[u8], r: &Range<usize>) -> Vec<u8> {
    bytes[r.clone()].to_ascii_uppercase()
}

/// The words of a move or M-code line (`L`, `C`, `CC`, …): `toks` after the keyword.
struct Words<'a> {
    bytes: &'a [u8],
    line: usize,
    line_start: usize,
}

/// A word that is a plain number, `letter` at `start` and its value at `value`.
fn plain_word(letter: u8, start: usize, value: &Range<usize>, v: f64) -> Word {
    Word {
        letter,
        start: start as u32,
        value_start: value.start as u32,
        end: value.end as u32,
        value: v,
        form: RotaryForm::Plain,
        tail: 0,
    }
}

/// What a letter written without a number right after it (`Z 25.000`, `F MAX`, `F`) stands
/// for.
enum Lone {
    /// The number in the next token is its value.
    Value(Range<usize>),
    /// `F MAX`: the next token is read too.
    Rapid,
    /// An empty `F` field: no word.
    Empty,
}

/// Where the words of a line go as they are read.
struct Sink<'s> {
    s: &'s mut Scan,
    words: &'s mut Vec<Word>,
    /// X Y Z A B C and F named so far in the block.
    seen: [bool; 7],
}

impl Words<'_> {
    fn err(&self, at: usize, message: String) -> ParseError {
        ParseError::at(self.line, at - self.line_start + 1, message)
    }

    /// Read the words of `toks` into `s` and `words`.
    fn read(
        &self,
        controller: &ControllerCodes,
        toks: &[Range<usize>],
        s: &mut Scan,
        words: &mut Vec<Word>,
    ) -> Result<(), ParseError> {
        let b = self.bytes;
        let mut out = Sink {
            s,
            words,
            seen: [false; 7],
        };
        let mut k = 0;
        while k < toks.len() {
            let t = &toks[k];
            k += 1;
            let text = &b[t.clone()];
            let letters = text.iter().take_while(|c| c.is_ascii_alphabetic()).count();
            let name = text[..letters].to_ascii_uppercase();
            let mut value = t.start + letters..t.end;
            // `L Z 25.000 FMAX` (an APT post's output): a blank between an axis letter (or
            // F) and its number, read as the word — the blank stays in the file; a letter
            // left without a number says the blank is what is wrong.
            let lone = value.is_empty()
                && matches!(name.as_slice(), [l] | [b'I', l] if axis_index(*l).is_some() || *l == b'F');
            if lone {
                match self.lone_letter(&name, t, toks.get(k))? {
                    Lone::Value(next) => {
                        value = next;
                        k += 1;
                    }
                    Lone::Rapid => {
                        out.s.rapid_once = true;
                        k += 1;
                        continue;
                    }
                    Lone::Empty => continue,
                }
            }
            // An axis word, possibly incremental (`IX+5`).
            let (incremental, axis) = match name.as_slice() {
                [l] => (false, axis_index(*l)),
                [b'I', l] => (true, axis_index(*l)),
                _ => (false, None),
            };
            if let Some(i) = axis {
                let at = t.start + usize::from(incremental);
                self.axis_word(i, incremental, at, value, &mut out)?;
                continue;
            }
            let value_text = &b[value.clone()];
            match name.as_slice() {
                b"F" => self.feed_word(t.start, value, &mut out)?,
                b"FMAX" => out.s.rapid_once = true,
                b"FAUTO" | b"FU" | b"FZ" => out.s.feed_unknown = true,
                // `M` alone: no miscellaneous function (older TNC listings write the empty
                // dialog field).
                b"M" if value_text.is_empty() => {}
                b"M" => self.m_word(controller, t.start, value, &mut out)?,
                // Radius compensation: R0 none, RL/RR/R+/R- on (ends runs).
                b"R" if value_text == b"0" => {}
                b"RL" | b"RR" | b"R" => out.s.breaks = true,
                // Arc direction, arc radius, polar coordinates, approach lengths…: read by
                // the arc and polar moves, which end runs anyway.
                _ => out.s.breaks = true,
            }
        }
        Ok(())
    }

    /// What the letter `name` of the token `t`, written without a number, stands for, given
    /// the token after it.
    fn lone_letter(
        &self,
        name: &[u8],
        t: &Range<usize>,
        next: Option<&Range<usize>>,
    ) -> Result<Lone, ParseError> {
        let b = self.bytes;
        match next {
            Some(next) if parse_number(&b[next.clone()]).is_some() => Ok(Lone::Value(next.clone())),
            // `F MAX` (older TNC listings, NX's posts for them): `FMAX`.
            Some(next) if name == b"F" && b[next.clone()].eq_ignore_ascii_case(b"MAX") => {
                Ok(Lone::Rapid)
            }
            // An empty `F` field (`L R F M30`, older TNC listings): no feed given.
            _ if name == b"F" => Ok(Lone::Empty),
            _ => Err(self.err(
                t.start,
                format!(
                    "{} word has no number (a blank after the letter is read only when \
                     a number follows it)",
                    String::from_utf8_lossy(name)
                ),
            )),
        }
    }

    /// The word of axis `i` (incremental: `IX+5`), its letter at `at` and its value at
    /// `value`.
    fn axis_word(
        &self,
        i: usize,
        incremental: bool,
        at: usize,
        value: Range<usize>,
        out: &mut Sink<'_>,
    ) -> Result<(), ParseError> {
        let letter = AXES[i];
        let value_text = &self.bytes[value.clone()];
        if std::mem::replace(&mut out.seen[i], true) {
            return Err(self.err(
                at,
                format!(
                    "{} appears twice in this block; the control rejects such a block",
                    letter as char
                ),
            ));
        }
        if value_text.is_empty() {
            return Err(self.err(at, format!("{} word has no number", letter as char)));
        }
        match parse_number(value_text) {
            Some(v) if v.is_finite() => {
                out.s.axes[i] = Some(v);
                if incremental {
                    out.s.axes_incremental |= 1 << i;
                }
                out.words.push(plain_word(letter, at, &value, v));
            }
            _ if value_text.iter().any(|c| c.eq_ignore_ascii_case(&b'Q')) => {
                out.s.axes_expr |= 1 << i;
            }
            _ => {
                return Err(self.err(
                    at,
                    format!(
                        "{} value '{}' is not a number",
                        letter as char,
                        String::from_utf8_lossy(value_text)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The F word at `start`, its value at `value`.
    fn feed_word(
        &self,
        start: usize,
        value: Range<usize>,
        out: &mut Sink<'_>,
    ) -> Result<(), ParseError> {
        let value_text = &self.bytes[value.clone()];
        if std::mem::replace(&mut out.seen[6], true) {
            return Err(self.err(start, "F appears twice in this block".into()));
        }
        match parse_number(value_text) {
            Some(v) if v.is_finite() => {
                out.s.feed = Some(v);
                out.words.push(plain_word(b'F', start, &value, v));
            }
            _ if value_text.iter().any(|c| c.eq_ignore_ascii_case(&b'Q')) => {
                out.s.feed_expr = true;
            }
            _ => {
                return Err(self.err(
                    start,
                    format!(
                        "F value '{}' is not a number",
                        String::from_utf8_lossy(value_text)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The M word at `start`, its value at `value` (not empty).
    fn m_word(
        &self,
        controller: &ControllerCodes,
        start: usize,
        value: Range<usize>,
        out: &mut Sink<'_>,
    ) -> Result<(), ParseError> {
        let value_text = &self.bytes[value.clone()];
        let v = parse_number(value_text)
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                self.err(
                    start,
                    format!(
                        "M value '{}' is not a number",
                        String::from_utf8_lossy(value_text)
                    ),
                )
            })?;
        out.words.push(plain_word(b'M', start, &value, v));
        match code10(v) {
            // Machine coordinates for this block; retract along the tool axis;
            // cycle call: positions unknown after.
            Some(910 | 920 | 1400 | 990 | 890) => {
                out.s.unknown_after = true;
                out.s.breaks = true;
            }
            c => m_code(Dialect::Conversational, controller, c, out.s),
        }
        Ok(())
    }
}

/// A control byte outside a comment: the line is refused.
fn check_control_bytes(bytes: &[u8], span: &Range<usize>, line: usize) -> Result<(), ParseError> {
    for (k, &c) in bytes[span.clone()].iter().enumerate() {
        if (c < 0x20 && !is_blank(c)) || c == 0x7f {
            // Inside a comment the bytes are the user's.
            let before = &bytes[span.start..span.start + k];
            if !before.contains(&b';') && before.trim_ascii_start().first() != Some(&b'*') {
                return Err(ParseError::at(
                    line,
                    k + 1,
                    format!(
                        "control byte 0x{c:02X} in the program text; the file is damaged or not \
                         an NC program"
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// What a conversational line says (module docs), its words appended to `words`.
pub(crate) fn lex(
    controller: &ControllerCodes,
    bytes: &[u8],
    span: Range<usize>,
    line: usize,
    words: &mut Vec<Word>,
) -> Result<Scan, ParseError> {
    let mut scan = Scan::default();
    check_control_bytes(bytes, &span, line)?;
    let mut toks = tokens(bytes, span.clone());
    // Block number.
    if toks
        .first()
        .is_some_and(|t| bytes[t.clone()].iter().all(u8::is_ascii_digit))
    {
        toks.remove(0);
    }
    let Some(first) = toks.first().cloned() else {
        return Ok(scan);
    };
    let key = upper(bytes, &first);
    let rest = &toks[1..];
    let l = Line {
        bytes,
        rest,
        second: rest.first().map(|t| upper(bytes, t)).unwrap_or_default(),
        words: Words {
            bytes,
            line,
            line_start: span.start,
        },
    };
    let s = &mut scan;
    match key.as_slice() {
        k if k.first() == Some(&b'*') => {}
        b"BEGIN" => l.begin(s),
        b"END" => {
            s.flags.set(Flags::PROGRAM_END);
            m_code(Dialect::Conversational, controller, Some(300), s);
        }
        b"L" | b"LN" | b"C" | b"CR" | b"CT" | b"LP" | b"CP" | b"APPR" | b"DEP" | b"CC" | b"BLK"
        | b"RND" | b"CHF" => l.path(&key, controller, s, words)?,
        b"TOOL" => l.tool(s),
        b"CYCL" => l.cycle(s),
        b"TCH" => {
            s.unknown_after = true;
            s.breaks = true;
        }
        b"LBL" => s.flow = Some(l.label()),
        b"CALL" => s.flow = Some(l.call()),
        b"SEL" => {
            if l.second == b"PGM" {
                s.flow = Some(Stmt::External);
            } else {
                s.breaks = true;
            }
        }
        b"FN" => l.parameter_function(s),
        k if k.first() == Some(&b'Q') => s.breaks = true,
        b"FUNCTION" => function(&bytes[first.start..span.end], s),
        b"PLANE" => l.plane(s),
        b"TRANS" => l.trans(s),
        b"STOP" => {
            s.breaks = true;
            l.words.read(controller, rest, s, words)?;
        }
        k if k.first() == Some(&b'M') && k.len() > 1 && k[1].is_ascii_digit() => {
            l.words.read(controller, &toks, s, words)?;
        }
        _ => {
            s.flags.set(Flags::NOT_MODELLED);
            s.unknown_after = true;
            s.breaks = true;
        }
    }
    after_lex(bytes, &span, s);
    Ok(scan)
}

/// A conversational line after its keyword: what each keyword's reading needs.
struct Line<'a> {
    bytes: &'a [u8],
    /// The tokens after the keyword.
    rest: &'a [Range<usize>],
    /// The first of them, upper case (empty if there is none).
    second: Vec<u8>,
    /// Their reader as words.
    words: Words<'a>,
}

impl Line<'_> {
    /// `BEGIN PGM NAME MM`: the program's units.
    fn begin(&self, s: &mut Scan) {
        // `INCH` (NX's Heidenhain posts write `IN`) or `MM`; anything else states no
        // units.
        if let Some(unit) = self.rest.last() {
            let u = upper(self.bytes, unit);
            if u == b"INCH" || u == b"IN" {
                s.inch = Some(true);
            } else if u == b"MM" {
                s.inch = Some(false);
            }
        }
        s.breaks = true;
    }

    /// The path keywords: lines, arcs, polar moves, approach and departure, circle centre
    /// and blank, corners (`key`, upper case).
    fn path(
        &self,
        key: &[u8],
        controller: &ControllerCodes,
        s: &mut Scan,
        words: &mut Vec<Word>,
    ) -> Result<(), ParseError> {
        let (bytes, rest) = (self.bytes, self.rest);
        match key {
            b"L" => {
                s.motion = Some(Motion::Linear);
                self.words.read(controller, rest, s, words)?;
            }
            b"LN" => {
                s.motion = Some(Motion::Linear);
                s.flags.set(Flags::NOT_MODELLED);
                s.breaks = true;
                let axes: Vec<_> = rest
                    .iter()
                    .filter(|t| {
                        let txt = upper(bytes, t);
                        txt.len() >= 2
                            && matches!(txt[0], b'X' | b'Y' | b'Z')
                            && !txt[1].is_ascii_alphabetic()
                    })
                    .cloned()
                    .collect();
                self.words.read(controller, &axes, s, words)?;
                // The tool axis follows the normal vectors: rotary positions unknown.
                for i in [A, B, C] {
                    s.axes_expr |= 1 << i;
                }
            }
            b"C" | b"CR" | b"CT" => {
                s.motion = Some(Motion::ArcCw);
                self.words.read(controller, rest, s, words)?;
                s.breaks = true;
            }
            b"LP" | b"CP" | b"APPR" | b"DEP" => {
                s.motion = Some(if key == b"LP" {
                    Motion::Linear
                } else {
                    Motion::ArcCw
                });
                s.flags.set(Flags::ARC);
                s.xy_unknown_after = true;
                if key != b"LP" {
                    s.unknown_after = true;
                }
                s.breaks = true;
            }
            b"CC" | b"BLK" => {
                // A circle centre or the blank: axis words that are not a move.
                s.no_move = true;
            }
            // `RND`, `CHF`.
            _ => s.breaks = true,
        }
        Ok(())
    }

    /// `TOOL CALL …`, `TOOL DEF …`.
    fn tool(&self, s: &mut Scan) {
        // `TOOL CALL 5 Z S12000`, `TOOL CALL "BALL6" Z`: a tool change. A call that
        // names no tool (`TOOL CALL Z S10000`, `TOOL CALL S10000`: a new spindle speed
        // or axis for the tool in use) changes nothing that moves: it ends no run.
        if self.second == b"CALL" {
            let third = self
                .rest
                .get(1)
                .map(|t| upper(self.bytes, t))
                .unwrap_or_default();
            let names_tool = third
                .first()
                .is_some_and(|c| c.is_ascii_digit() || matches!(c, b'"' | b'\'' | b'Q'));
            if names_tool {
                s.flags.set(Flags::TOOL_CHANGE);
                s.breaks = true;
            }
        } else {
            s.breaks = true;
        }
    }

    /// `CYCL DEF n…`, `CYCL CALL`.
    fn cycle(&self, s: &mut Scan) {
        let (bytes, rest) = (self.bytes, self.rest);
        if self.second == b"DEF" {
            let number = rest.get(1).map(|t| upper(bytes, t)).unwrap_or_default();
            let mut parts = number.split(|&c| c == b'.');
            let major = parts.next().unwrap_or_default();
            let minor = parts.next().unwrap_or_default();
            if matches!(major, b"7" | b"247" | b"8" | b"10" | b"11" | b"19" | b"26") {
                s.datum_shift = true;
                s.unknown_after = true;
                if minor == b"1" {
                    cycle_transform(major, &upper_tokens(bytes, &rest[2..]), s);
                }
            } else {
                s.no_move = true;
            }
        } else {
            s.unknown_after = true;
        }
        s.breaks = true;
    }

    /// `LBL n`, `LBL "NAME"`: a label; `LBL 0`: a return.
    fn label(&self) -> Stmt {
        let name = self
            .rest
            .first()
            .map(|t| label_name(self.bytes, t))
            .unwrap_or_default();
        if name == "0" {
            Stmt::Return {
                falls_through: true,
            }
        } else {
            Stmt::Label(Key::Label(name))
        }
    }

    /// `CALL LBL n [REP m]`, `CALL PGM`, `CALL SELECTED PGM`.
    fn call(&self) -> Stmt {
        let (bytes, rest) = (self.bytes, self.rest);
        if self.second == b"LBL" {
            let name = rest
                .get(1)
                .map(|t| label_name(bytes, t))
                .unwrap_or_default();
            if name.starts_with('Q') {
                Stmt::Opaque
            } else {
                let rep = rest.iter().position(|t| upper(bytes, t) == b"REP");
                let times = rep
                    .and_then(|k| rest.get(k + 1))
                    .map(|t| upper(bytes, t))
                    .and_then(|t| crate::lexer::parse_number(&t));
                Stmt::Call {
                    key: Key::Label(name),
                    repeats: rep.is_some() && times != Some(0.0),
                }
            }
        } else {
            // CALL PGM, CALL SELECTED PGM: a program outside the file.
            Stmt::External
        }
    }

    /// `FN n: …`: parameter arithmetic, and the conditional jumps `FN 9`…`FN 12`.
    fn parameter_function(&self, s: &mut Scan) {
        let (bytes, rest) = (self.bytes, self.rest);
        let n = rest
            .first()
            .map(|t| {
                bytes[t.clone()]
                    .iter()
                    .take_while(|c| c.is_ascii_digit())
                    .fold(0u32, |a, &d| {
                        a.saturating_mul(10).saturating_add(u32::from(d - b'0'))
                    })
            })
            .unwrap_or(0);
        if (9..=12).contains(&n) {
            // `FN 9: IF +Q1 EQU +0 GOTO LBL 5`: a conditional jump.
            let goto = rest.iter().position(|t| upper(bytes, t) == b"GOTO");
            let name = goto
                .and_then(|k| rest.get(k + 2))
                .map(|t| label_name(bytes, t));
            s.flow = Some(match name {
                Some(name) if !name.starts_with('Q') && !name.is_empty() => Stmt::Jump {
                    key: Key::Label(name),
                    cond: true,
                },
                _ => Stmt::Opaque,
            });
        }
        s.breaks = true;
    }

    /// `PLANE …`, `PLANE RESET`.
    fn plane(&self, s: &mut Scan) {
        s.datum_shift = true;
        s.unknown_after = true;
        s.breaks = true;
        // A tilted working plane rotates the frame; `PLANE RESET` ends it.
        if self.second == b"RESET" {
            s.transform_off |= transform::ROTATION;
        } else {
            s.transform_on |= transform::ROTATION;
        }
    }

    /// `TRANS DATUM/MIRROR/ROTATION/SCALE …` and their `RESET`.
    fn trans(&self, s: &mut Scan) {
        // TNC7 frames: `TRANS DATUM …`, `TRANS MIRROR …`, `TRANS ROTATION …`,
        // `TRANS SCALE …`; `… RESET` ends them.
        s.datum_shift = true;
        s.unknown_after = true;
        s.breaks = true;
        let reset = self.rest.iter().any(|t| upper(self.bytes, t) == b"RESET");
        let bit = match self.second.as_slice() {
            b"MIRROR" => transform::MIRROR,
            b"ROTATION" => transform::ROTATION,
            b"SCALE" | b"SCALING" => transform::SCALING,
            b"DATUM" => 0,
            _ => transform::ALL,
        };
        if reset {
            s.transform_off |= bit;
        } else {
            s.transform_on |= bit;
        }
    }
}

/// A label's name as `LBL` and `CALL LBL` write it: a number, or a quoted name (upper case).
fn label_name(bytes: &[u8], t: &Range<usize>) -> String {
    let text = upper(bytes, t);
    let text = text.strip_prefix(b"\"").unwrap_or(&text);
    let text = text.strip_suffix(b"\"").unwrap_or(text);
    String::from_utf8_lossy(text).into_owned()
}

/// The upper-case text of tokens.
fn upper_tokens(bytes: &[u8], toks: &[Range<usize>]) -> Vec<Vec<u8>> {
    toks.iter().map(|t| upper(bytes, t)).collect()
}

/// What the `.1` line of a frame cycle does (`CYCL DEF 8.1 X Y`, `10.1 ROT+30`,
/// `11.1 SCL 0.8`, `26.1 X1.5 CCX+0`, `19.1 A+0 B+45`): a transformation on, or off where
/// its values are the identity.
fn cycle_transform(major: &[u8], toks: &[Vec<u8>], s: &mut Scan) {
    let number_after = |t: &[u8], k: usize| crate::lexer::parse_number(&t[k..]);
    let (bit, identity) = match major {
        // Mirror image: the axes named (none: off).
        b"8" => (transform::MIRROR, toks.is_empty()),
        b"10" => (
            transform::ROTATION,
            toks.iter()
                .filter(|t| t.starts_with(b"ROT"))
                .all(|t| number_after(t, 3) == Some(0.0)),
        ),
        b"11" => {
            // `SCL 0.8` or `SCL0.8`.
            let v = toks.iter().enumerate().find_map(|(k, t)| {
                t.strip_prefix(b"SCL").and_then(|r| {
                    if r.is_empty() {
                        toks.get(k + 1).and_then(|n| crate::lexer::parse_number(n))
                    } else {
                        crate::lexer::parse_number(r)
                    }
                })
            });
            (transform::SCALING, v == Some(1.0))
        }
        b"26" => (
            transform::SCALING,
            toks.iter()
                .filter(|t| matches!(t.first(), Some(b'X' | b'Y' | b'Z')))
                .all(|t| number_after(t, 1) == Some(1.0)),
        ),
        b"19" => (
            transform::ROTATION,
            toks.iter()
                .filter(|t| matches!(t.first(), Some(b'A' | b'B' | b'C')))
                .all(|t| number_after(t, 1) == Some(0.0)),
        ),
        _ => (0, true),
    };
    if identity {
        s.transform_off |= bit;
    } else {
        s.transform_on |= bit;
    }
}

#[cfg(test)]
mod tests {
    use crate::modal::{A, C, Motion, Tcpm, X, Z};
    use crate::{Dialect, Flags, parse, runs};

    const PGM: &str = "0  BEGIN PGM SING MM\n\
        1  BLK FORM 0.1 Z  X-50  Y-50  Z-40\n\
        2  BLK FORM 0.2  X+50  Y+50  Z+0\n\
        3  TOOL CALL 5 Z S12000\n\
        4  L  Z+100 R0 FMAX M3\n\
        5  FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS\n\
        6  L  X+0  Y+0  A+10  C+0 R0 FMAX\n\
        7  L  Z+5 R0 FMAX M8\n\
        8  L  X+10  Y-5  Z+0  A+14.351  C+135.638 R0 F2000\n\
        9  L  X+11  A+13.2  C+140.1\n\
        10 L  X+12  A+12.2  C+145.1 ; cut\n\
        11 * - RETRACT\n\
        12 FUNCTION RESET TCPM\n\
        13 L  Z+100 R0 FMAX M30\n\
        14 END PGM SING MM\n";

    #[test]
    fn a_program() {
        let p = parse(PGM.as_bytes().to_vec(), Dialect::Auto).unwrap();
        assert_eq!(p.dialect, Dialect::Conversational);
        // BLK FORM's axis words are not positions.
        assert_eq!(p.state(2).pos[X], None);
        assert!(p.blocks[3].flags.has(Flags::TOOL_CHANGE));
        assert_eq!(p.state(4).motion, Motion::Rapid, "FMAX");
        assert_eq!(p.state(5).tcpm, Tcpm::On);
        assert_eq!(p.state(8).motion, Motion::Linear);
        assert_eq!(p.state(8).feed_mm_min, Some(2000.0));
        assert_eq!(p.state(9).pos[A], Some(13.2));
        assert_eq!(p.state(9).pos[Z], Some(0.0));
        assert_eq!(p.state(12).tcpm, Tcpm::Off);
        assert!(p.blocks[14].flags.has(Flags::PROGRAM_END));
        let r = runs(&p);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].blocks, vec![7, 8, 9, 10]);
        assert!(r[0].tcpm.is_on());
        assert_eq!(r[0].pos[3][C], Some(145.1));
        // The words keep their bytes.
        let w = p.word(9, b'C').unwrap();
        assert_eq!(&p.bytes[w.value_span()], b"+140.1");
        assert_eq!(crate::write(&p, &[]), PGM.as_bytes());
    }

    /// Issue 30 item 7: blanks after the letter, as APT posts and older TNC listings
    /// write them.
    #[test]
    fn blanks_after_the_letter() {
        let p = parse(
            b"0 BEGIN PGM T MM\n1 L Z 25.000 FMAX\n2 L X1.9685 Y-.3937 M3 F MAX\n3 L X 2 Y -1 A +1 C 5 F 900\n".to_vec(),
            Dialect::Auto,
        )
        .unwrap();
        assert_eq!(p.state(1).pos[Z], Some(25.0));
        assert_eq!(p.state(1).motion, Motion::Rapid);
        assert_eq!(p.state(2).motion, Motion::Rapid, "F MAX");
        // Empty `M` and `F` fields, as older TNC listings write them: nothing.
        assert!(
            parse(
                b"0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+0 F9.8 M\n2 L X+1 M\n3 L R F M30\n".to_vec(),
                Dialect::Auto
            )
            .is_ok()
        );
        assert_eq!(p.state(3).pos[C], Some(5.0));
        assert_eq!(p.state(3).feed_mm_min, Some(900.0));
        // The value keeps its bytes; the word starts at its letter.
        let w = p.word(3, b'A').unwrap();
        assert_eq!(&p.bytes[w.value_span()], b"+1");
        assert_eq!(crate::write(&p, &[]), p.bytes.as_slice());
        for (line, col) in [("1 L Z FMAX", 5), ("1 L X+1 C", 9)] {
            let e = parse(
                format!("0 BEGIN PGM T MM\n{line}\n").into_bytes(),
                Dialect::Auto,
            )
            .unwrap_err();
            assert_eq!((e.line, e.column), (2, col), "{line}");
            assert!(e.message.contains("a blank after the letter"), "{e}");
        }
    }

    #[test]
    fn what_is_not_followed() {
        let p = |body: &str| {
            parse(
                format!(
                    "0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+0 A+1 C+0 R0 F1000\n{body}\n3 L X+5 Y+0 Z+0\n"
                )
                .into_bytes(),
                Dialect::Auto,
            )
            .unwrap()
        };
        // An incremental word: never changed, ends runs.
        let q = p("2 L IX+2 IC+5");
        assert!(q.blocks[2].breaks_run && q.blocks[2].flags.has(Flags::INCREMENTAL_WORDS));
        assert_eq!(q.state(2).pos[X], Some(2.0));
        assert_eq!(q.state(2).pos[C], Some(5.0));
        // A Q parameter: not analysable, the axis unknown after.
        let q = p("2 L X+Q1 C+5");
        assert!(q.blocks[2].flags.has(Flags::NOT_ANALYSABLE));
        assert_eq!(q.state(2).pos[X], None);
        // Arcs and labels end runs; a label or call leaves positions unknown.
        let q = p("2 CR X+3 Y+3 R+5 DR-");
        assert!(q.blocks[2].breaks_run && q.blocks[2].flags.has(Flags::ARC));
        assert_eq!(q.state(2).pos[X], Some(3.0));
        for line in [
            "2 LBL 1",
            "2 CALL LBL 1",
            "2 CYCL CALL",
            "2 PLANE RESET STAY",
            "2 SOMETHING NEW",
        ] {
            let q = p(line);
            assert!(q.blocks[2].breaks_run, "{line}");
            assert_eq!(q.state(2).pos[X], None, "{line}");
        }
        assert!(
            p("2 SOMETHING NEW").blocks[2]
                .flags
                .has(Flags::NOT_MODELLED)
        );
        // A datum shift's axis words are not moves.
        let q = p("2 CYCL DEF 7.1 X+10");
        assert!(!q.blocks[2].is_move);
        // Duplicated words are refused with their column.
        let e = parse(
            b"0 BEGIN PGM T MM\n1 L X+1 C+5 C+6\n".to_vec(),
            Dialect::Auto,
        )
        .unwrap_err();
        assert_eq!((e.line, e.column), (2, 13));
        // INCH: lengths in inches, F in 1/10 inch/min.
        let q = parse(
            b"0 BEGIN PGM T INCH\n1 L X+1 Y+0 Z+0 R0 F100\n".to_vec(),
            Dialect::Auto,
        )
        .unwrap();
        assert_eq!(q.state(1).pos[X], Some(25.4));
        assert!((q.state(1).feed_mm_min.unwrap() - 254.0).abs() < 1e-9);
        let _ = A;
    }
}
