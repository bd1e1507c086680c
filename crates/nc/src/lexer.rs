//! Byte-level lexing of one line into words and pass-through tokens.
//!
//! The rules are shared by all dialects and only ASCII is interpreted; any other byte
//! is kept inside the token it falls in (comments, strings, unknown tokens):
//!
//! - blanks (space, tab, CR, VT, FF) separate tokens and are skipped;
//! - `;` starts a comment to the end of the line, `(` a comment to the next `)`;
//! - `*` ends the block (Heidenhain); it and the rest of the line pass through;
//! - `%` starts a pass-through rest of line (`%NAME G71 *`, `N999999 %SING G71 *`);
//! - a letter followed by a sign, digit or `.` is an address word (`C+148.494`, `X-.5`,
//!   `G01`, `X10.`); followed by `=` it is a Sinumerik word (`X=12.5`); blanks may stand
//!   between the letter and its number and between a sign and its digits (`X  6.302`,
//!   `Y -11.56`, `Z- 5`: RS274/NGC and Fanuc accept them), and belong to the word;
//! - a letter whose value is not a plain number (`A#<a>`, `X=R1+2`, `X+Q5`, `F=FGREF(5)`,
//!   `Z=_Z_HOME`: Sinumerik user variables start with `_`) is an [`Token::Assign`]: the
//!   reader marks such a block as not analysable;
//! - a letter, an index and `=` (`A5=15.`, `B7=254`, `L1=1`, `R1=5`, Sinumerik's `A3=` of
//!   an orientation vector) is an indexed address, [`Token::Indexed`]: a parameter, not the
//!   letter's word (two of them with one letter are not "the word twice");
//! - a letter followed by a letter or `_`, or a `_` followed by a letter or digit, starts an
//!   identifier (`TRAORI`, `CYCLE800(…)`, `MSG("…")`, `_X_HOME=-365.`), which takes a
//!   following `(…)`/`[…]` and `=expression` along;
//! - `/` with optional level digits is the block-delete marker;
//! - `#` starts a parameter (`#12`, `#<name>`, `#[expr]`);
//! - anything else up to the next blank, letter, `;` or `(` is an unknown token.
//!
//! Errors: a malformed or non-finite number on an address word, an axis value in exponent
//! notation
//! (`X1e999`: a plain decimal or `X1 E999`? polepatch does not guess), a letter that needs
//! a number but has none (`X`, `X+`), and an ASCII control byte (NUL, ESC, DEL…) outside
//! a comment.

use crate::word::RotaryForm;
use std::ops::Range;

/// One token of a line. Spans are absolute byte offsets into the file.
#[derive(Debug, Clone, PartialEq)]
pub enum Token {
    /// An address word with a plain number: `C+148.494`, `X=12.5`, `G43.4`.
    Word {
        /// Upper-case letter.
        letter: u8,
        /// Letter to last digit.
        span: Range<usize>,
        /// The number, sign included.
        value_span: Range<usize>,
        /// The number as written.
        value: f64,
        /// A rotary word's direction form (`C=DC(12.5)`: the span ends at the `)`).
        form: RotaryForm,
    },
    /// An identifier with its arguments or assignment: `TRAORI`, `CYCLE800(0,1)`,
    /// `MSG("…")`.
    Ident {
        /// The whole token.
        span: Range<usize>,
        /// The identifier alone (letters, digits and `_`).
        name: Range<usize>,
    },
    /// A letter with a value that is not a plain number, on a letter where that is
    /// allowed (`T="MILL"`, `R1=R2*3`, `S=R5`).
    Assign {
        /// Upper-case letter.
        letter: u8,
        /// The whole token.
        span: Range<usize>,
    },
    /// An indexed address and its value: a letter, an index and `=` (`A5=15.`, `B7=254`,
    /// `L1=1`, `R1=R2*3`, `A3=0.5`). What it means depends on the dialect (MillPlus
    /// parameters, Sinumerik R parameters and orientation vectors): the reader decides.
    Indexed {
        /// Upper-case letter.
        letter: u8,
        /// The whole token, from the letter to the end of the value.
        span: Range<usize>,
    },
    /// `;` comment to the end of the line, or `( … )` comment.
    Comment {
        /// The comment, delimiters included.
        span: Range<usize>,
    },
    /// `*` block end and the rest of the line.
    BlockEnd {
        /// From `*` to the end of the line.
        span: Range<usize>,
    },
    /// `%` and the rest of the line.
    Percent {
        /// From `%` to the end of the line.
        span: Range<usize>,
    },
    /// A parameter reference or assignment target: `#12`, `#<name>`, `#[expr]`.
    Param {
        /// The reference.
        span: Range<usize>,
    },
    /// `/` block-delete marker with optional level digits.
    Slash {
        /// The marker.
        span: Range<usize>,
    },
    /// Anything else, kept as it is.
    Other {
        /// The token.
        span: Range<usize>,
    },
}

/// A lexing error at an absolute byte offset.
#[derive(Debug, Clone, PartialEq)]
pub struct LexError {
    /// Absolute byte offset of the offending word.
    pub at: usize,
    /// What is wrong, naming the value.
    pub message: String,
}

/// Letters whose values polepatch reads as numbers and needs plain (axis words and F).
pub const AXIS_LETTERS: &[u8] = b"XYZABCF";
/// Letters that always need a number after them.
pub const NUMBER_LETTERS: &[u8] = b"XYZABCFGMNTS";

fn is_blank(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// An ASCII control byte that is not a blank (NUL, ESC, DEL, …): a damaged or binary
/// file. Outside comments it is an error, not something to skip.
fn is_control(b: u8) -> bool {
    (b < 0x20 && !is_blank(b)) || b == 0x7f
}

/// The error for a control byte: its code and, for NUL, its name.
fn control_message(b: u8) -> String {
    let name = match b {
        0 => " (NUL)",
        0x1a => " (SUB, end-of-file mark)",
        0x1b => " (ESC)",
        0x7f => " (DEL)",
        _ => "",
    };
    format!(
        "control byte 0x{b:02X}{name} in the program text; the file is damaged or not an NC program"
    )
}

fn is_axis(letter: u8) -> bool {
    AXIS_LETTERS.contains(&letter)
}

fn is_non_finite_name(text: &[u8]) -> bool {
    let t = match text.first() {
        Some(b'+' | b'-') => &text[1..],
        _ => text,
    };
    t.eq_ignore_ascii_case(b"nan")
        || t.eq_ignore_ascii_case(b"inf")
        || t.eq_ignore_ascii_case(b"infinity")
}

/// Whether a value that is not a plain number reads as an expression or a variable: after
/// an optional sign, a variable (`#1`, `#<name>`, `R1`, `Q5`, `$P_X`, a Sinumerik user
/// variable `_XH`), a bracket (`[…]`, `(…)`), `<`, or a function name (`IC(5)`).
fn is_expression_start(text: &[u8]) -> bool {
    let t = match text.first() {
        Some(b'+' | b'-') => &text[1..],
        _ => text,
    };
    t.first().is_some_and(|&c| {
        c.is_ascii_alphabetic() || matches!(c, b'#' | b'[' | b'(' | b'<' | b'$' | b'_')
    })
}

/// Exact powers of ten representable in f64.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parse a plain decimal number: optional sign, digits with at most one `.`, at least one
/// digit (`12`, `-.5`, `+180.`, `0.25`). No exponent. The result is correctly rounded
/// (same as `str::parse::<f64>`). `None` if malformed.
pub fn parse_number(text: &[u8]) -> Option<f64> {
    let (neg, body) = match text.first()? {
        b'-' => (true, &text[1..]),
        b'+' => (false, &text[1..]),
        _ => (false, text),
    };
    let mut mantissa: u64 = 0;
    let mut digits = 0usize;
    let mut frac = 0usize;
    let mut point = false;
    let mut exact = true;
    for &b in body {
        match b {
            b'0'..=b'9' => {
                digits += 1;
                if point {
                    frac += 1;
                }
                if exact {
                    mantissa = mantissa * 10 + u64::from(b - b'0');
                    if mantissa >= (1u64 << 53) {
                        exact = false;
                    }
                }
            }
            b'.' if !point => point = true,
            _ => return None,
        }
    }
    if digits == 0 {
        return None;
    }
    let magnitude = if exact && frac < POW10.len() {
        // Both operands exact: one correctly rounded division (Clinger's fast path).
        mantissa as f64 / POW10[frac]
    } else {
        std::str::from_utf8(body).ok()?.parse::<f64>().ok()?
    };
    Some(if neg { -magnitude } else { magnitude })
}

/// Where the parts of a word are: its `letter` at `p`, whether `=` follows the letter, and
/// where its value starts (`ns`).
struct WordAt {
    p: usize,
    letter: u8,
    eq: bool,
    ns: usize,
}

/// Tokens of one line.
pub struct Lexer<'a> {
    bytes: &'a [u8],
    pos: usize,
    end: usize,
}

impl<'a> Lexer<'a> {
    /// Lex `line` (a byte range of `bytes`, without its line ending).
    pub fn new(bytes: &'a [u8], line: Range<usize>) -> Self {
        let end = line.end.min(bytes.len());
        Lexer {
            bytes,
            pos: line.start.min(end),
            end,
        }
    }

    fn err(&self, at: usize, message: String) -> Option<Result<Token, LexError>> {
        Some(Err(LexError { at, message }))
    }

    fn text(&self, r: Range<usize>) -> String {
        String::from_utf8_lossy(&self.bytes[r]).into_owned()
    }

    /// End of a bracketed group starting at `i` (`(` or `[`), quotes respected; the
    /// line end if unclosed.
    fn skip_group(&self, mut i: usize) -> usize {
        let b = self.bytes;
        let mut depth = 0usize;
        let mut in_str = false;
        while i < self.end {
            let c = b[i];
            i += 1;
            if in_str {
                in_str = c != b'"';
                continue;
            }
            match c {
                b'"' => in_str = true,
                b'(' | b'[' => depth += 1,
                b')' | b']' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        return i;
                    }
                }
                _ => {}
            }
        }
        self.end
    }

    /// End of an expression starting at `i`: up to a blank or `;` outside brackets and
    /// quotes, or the line end.
    fn skip_expr(&self, mut i: usize) -> usize {
        let b = self.bytes;
        while i < self.end {
            match b[i] {
                b'(' | b'[' => i = self.skip_group(i),
                b'"' => {
                    i += 1;
                    while i < self.end && b[i] != b'"' {
                        i += 1;
                    }
                    i = (i + 1).min(self.end);
                }
                c if is_blank(c) || c == b';' => return i,
                _ => i += 1,
            }
        }
        self.end
    }

    /// Scan `[sign] [0-9.]*` from `i`: (end of sign, end of number, value if it could be
    /// computed exactly on the way — a well-formed number of at most 15 significant
    /// digits and 22 decimals; `None` leaves it to [`parse_number`]).
    fn scan_number(&self, i: usize) -> (usize, usize, Option<f64>) {
        let b = self.bytes;
        let mut e = i;
        let neg = e < self.end && b[e] == b'-';
        if e < self.end && matches!(b[e], b'+' | b'-') {
            e += 1;
            // `Z- 5`: blanks between a sign and its digits.
            let mut k = e;
            while k < self.end && is_blank(b[k]) {
                k += 1;
            }
            if k > e && k < self.end && (b[k].is_ascii_digit() || b[k] == b'.') {
                e = k;
            }
        }
        let digits_start = e;
        let mut mantissa: u64 = 0;
        let mut frac = 0usize;
        let mut points = 0usize;
        while e < self.end {
            let c = b[e];
            let d = c.wrapping_sub(b'0');
            if d < 10 {
                // Wraps only past 19 digits, which the check below sends to the slow path.
                mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
                frac += points;
            } else if c == b'.' {
                points += 1;
            } else {
                break;
            }
            e += 1;
        }
        let n = e - digits_start;
        let fast = points <= 1
            && n > points
            && n - points <= 19
            && mantissa < (1 << 53)
            && frac < POW10.len();
        let value = fast.then(|| {
            let m = mantissa as f64 / POW10[frac];
            if neg { -m } else { m }
        });
        (digits_start, e, value)
    }

    /// The next token if it is a common word ([`Lexer::plain_word`]), the blanks before
    /// it skipped; `None` leaves the rest of the line to [`Iterator::next`]. For a reader
    /// of every line: most tokens are such words.
    #[inline(always)]
    pub(crate) fn next_plain_word(&mut self) -> Option<Token> {
        let b = self.bytes;
        let mut p = self.pos;
        while p < self.end && is_blank(b[p]) {
            p += 1;
        }
        self.pos = p;
        let c = *b.get(p).filter(|_| p < self.end)?;
        // A letter followed by a letter or `_` (an identifier) is no plain word either.
        if !c.is_ascii_alphabetic() {
            return None;
        }
        self.plain_word(p, c.to_ascii_uppercase())
    }

    /// The common word, `letter` at `p` and right after it a plain number — an optional
    /// sign, digits with at most one `.`, at most 19 digits and 22 decimals, exact in an
    /// `f64` — ending at the line end, a blank, `*`, `;`, `(` or a letter other than `E`:
    /// the token [`Lexer::word`] gives for it, in one pass. `None` for anything else
    /// (`Lexer::word` reads it).
    #[inline(always)]
    fn plain_word(&mut self, p: usize, letter: u8) -> Option<Token> {
        let b = &self.bytes[..self.end];
        let ns = p + 1;
        let (neg, ds) = match b.get(ns)? {
            b'-' => (true, ns + 1),
            b'+' => (false, ns + 1),
            _ => (false, ns),
        };
        let mut e = ds;
        let mut mantissa: u64 = 0;
        // Digits before the point, then after it. Wraps only past 19 digits, which the
        // check below refuses.
        while let Some(&c) = b.get(e) {
            let d = c.wrapping_sub(b'0');
            if d >= 10 {
                break;
            }
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
            e += 1;
        }
        let point = b.get(e) == Some(&b'.');
        let mut frac = 0usize;
        if point {
            e += 1;
            let fs = e;
            while let Some(&c) = b.get(e) {
                let d = c.wrapping_sub(b'0');
                if d >= 10 {
                    break;
                }
                mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
                e += 1;
            }
            frac = e - fs;
        }
        let digits = e - ds - usize::from(point);
        if digits == 0 || digits > 19 || mantissa >= (1 << 53) || frac >= POW10.len() {
            return None;
        }
        if let Some(&t) = b.get(e)
            && !(is_blank(t)
                || matches!(t, b'*' | b';' | b'(')
                || (t.is_ascii_alphabetic() && !matches!(t, b'e' | b'E')))
        {
            return None;
        }
        let m = mantissa as f64 / POW10[frac];
        self.pos = e;
        Some(Token::Word {
            letter,
            span: p..e,
            value_span: ns..e,
            value: if neg { -m } else { m },
            form: RotaryForm::Plain,
        })
    }

    fn word(&mut self, p: usize, letter: u8) -> Option<Result<Token, LexError>> {
        let b = self.bytes;
        let l = letter as char;
        let q = p + 1;
        let eq = q < self.end && b[q] == b'=';
        let ns = self.value_start(if eq { q + 1 } else { q });
        if eq
            && matches!(letter, b'A' | b'B' | b'C')
            && let Some(t) = self.direction_form(p, letter, ns)
        {
            return Some(Ok(t));
        }
        let (ds, e, fast) = self.scan_number(ns);
        if e < self.end && is_control(b[e]) {
            return self.err(e, control_message(b[e]));
        }
        if is_axis(letter)
            && let Some(message) = self.misread_number(letter, ns, ds, e)
        {
            return self.err(p, message);
        }
        let followed_by_expr = e < self.end
            && matches!(
                b[e],
                b'+' | b'-' | b'*' | b'/' | b'[' | b'(' | b'<' | b'>' | b'^' | b'#'
            );
        if e == ds
            || (eq && followed_by_expr)
            || (!eq && e < self.end && matches!(b[e], b'#' | b'['))
        {
            return self.not_plain(WordAt { p, letter, eq, ns }, ds, e);
        }
        let value = match fast.or_else(|| {
            let text = &b[ns..e];
            if text.iter().any(|&c| is_blank(c)) {
                let plain: Vec<u8> = text.iter().copied().filter(|&c| !is_blank(c)).collect();
                parse_number(&plain)
            } else {
                parse_number(text)
            }
        }) {
            Some(v) => v,
            None => {
                return self.err(
                    p,
                    format!("{l} value '{}' is not a number", self.text(ns..e)),
                );
            }
        };
        if !value.is_finite() {
            return self.err(
                p,
                format!("{l} value '{}' is not a finite number", self.text(ns..e)),
            );
        }
        if !eq && e < self.end && b[e] == b'=' {
            // An indexed address (`A5=15.`, `R1=5`) when the index is an unsigned whole
            // number written right after the letter; any other number before `=` is an
            // assignment the reader cannot read either.
            let x = self.skip_expr(e + 1);
            self.pos = x;
            let index = &b[q..e];
            return Some(Ok(if index.iter().all(u8::is_ascii_digit) {
                Token::Indexed { letter, span: p..x }
            } else {
                Token::Assign { letter, span: p..x }
            }));
        }
        self.pos = e;
        Some(Ok(Token::Word {
            letter,
            span: p..e,
            value_span: ns..e,
            value,
            form: RotaryForm::Plain,
        }))
    }

    /// Where a word's value starts, `ns` just past its letter (and `=`): `X  6.302`,
    /// `Y -11.56`: blanks before a number belong to the word.
    fn value_start(&self, ns: usize) -> usize {
        let b = self.bytes;
        let mut k = ns;
        while k < self.end && is_blank(b[k]) {
            k += 1;
        }
        if k > ns
            && k < self.end
            && (b[k].is_ascii_digit()
                || b[k] == b'.'
                || (matches!(b[k], b'+' | b'-')
                    && b[k + 1..self.end]
                        .iter()
                        .find(|&&c| !is_blank(c))
                        .is_some_and(|c| c.is_ascii_digit() || *c == b'.')))
        {
            k
        } else {
            ns
        }
    }

    /// Why the number of an axis word (`letter`, its value from `ns`, the digits `ds..e`)
    /// is refused when a number in another notation runs on after it: exponent notation
    /// (`X1.5E3`) or a decimal comma (`X1,5`).
    fn misread_number(&self, letter: u8, ns: usize, ds: usize, e: usize) -> Option<String> {
        let b = self.bytes;
        let l = letter as char;
        if e > ds && e + 1 < self.end && matches!(b[e], b'e' | b'E') {
            let k = if matches!(b[e + 1], b'+' | b'-') {
                e + 2
            } else {
                e + 1
            };
            if k < self.end && b[k].is_ascii_digit() {
                let mut x = k;
                while x < self.end && b[x].is_ascii_digit() {
                    x += 1;
                }
                return Some(format!(
                    "{l} value '{}' is in exponent notation (or an E word follows without a blank); \
                     NC programs use plain decimals and polepatch will not guess which is meant",
                    self.text(ns..x)
                ));
            }
        }
        if e > ds && e + 1 < self.end && b[e] == b',' && b[e + 1].is_ascii_digit() {
            let mut x = e + 1;
            while x < self.end && b[x].is_ascii_digit() {
                x += 1;
            }
            return Some(format!(
                "{l} value '{}' is not a number (a decimal comma? NC programs use a point)",
                self.text(ns..x)
            ));
        }
        None
    }

    /// A word whose value is not a plain number (`at`; the number scanned from its value
    /// start is `ds..e`): an expression or variable, or an error naming the value.
    fn not_plain(&mut self, at: WordAt, ds: usize, e: usize) -> Option<Result<Token, LexError>> {
        let b = self.bytes;
        let WordAt { p, letter, eq, ns } = at;
        let l = letter as char;
        let q = p + 1;
        let x = self.skip_expr(ns);
        if is_axis(letter) {
            let text = &b[ns..x];
            return if text.is_empty() {
                self.err(p, format!("{l} word has no number"))
            } else if matches!(text, b"+" | b"-") {
                self.err(
                    p,
                    format!("{l} value '{}' is not a number", self.text(ns..x)),
                )
            } else if is_non_finite_name(text) {
                self.err(
                    p,
                    format!("{l} value '{}' is not a finite number", self.text(ns..x)),
                )
            } else if is_expression_start(text) {
                // An expression or a variable: the reader marks the block.
                self.pos = x;
                Some(Ok(Token::Assign { letter, span: p..x }))
            } else {
                self.err(
                    p,
                    format!("{l} value '{}' is not a number", self.text(ns..x)),
                )
            };
        }
        if NUMBER_LETTERS.contains(&letter) && !eq && e == ds {
            let next = b.get(e).copied().filter(|_| e < self.end);
            if !matches!(next, Some(b'#' | b'[')) {
                return if e > ns {
                    self.err(
                        p,
                        format!("{l} value '{}' is not a number", self.text(ns..e)),
                    )
                } else {
                    self.err(p, format!("{l} word has no number"))
                };
            }
        }
        self.pos = x.max(q);
        Some(Ok(if x > q {
            Token::Assign {
                letter,
                span: p..self.pos,
            }
        } else {
            Token::Other { span: p..q }
        }))
    }

    /// A Sinumerik rotary word in a direction form, `C=DC(12.5)`, `C=ACP(12.5)`,
    /// `C=ACN(12.5)` (`ns`: just past the `=`), with a plain number in its brackets (blanks
    /// allowed around it); `None` for anything else (`C=DC(R1)` is an expression).
    fn direction_form(&mut self, p: usize, letter: u8, ns: usize) -> Option<Token> {
        let b = self.bytes;
        let open = b[ns..self.end].iter().position(|&c| c == b'(')? + ns;
        let form = match b[ns..open].to_ascii_uppercase().as_slice() {
            b"DC" => RotaryForm::Dc,
            b"ACP" => RotaryForm::Acp,
            b"ACN" => RotaryForm::Acn,
            _ => return None,
        };
        let mut vs = open + 1;
        while vs < self.end && is_blank(b[vs]) {
            vs += 1;
        }
        let (ds, e, fast) = self.scan_number(vs);
        if e == ds {
            return None;
        }
        let mut close = e;
        while close < self.end && is_blank(b[close]) {
            close += 1;
        }
        if close >= self.end || b[close] != b')' {
            return None;
        }
        // `C=DC(5)+1` is an expression.
        if b.get(close + 1)
            .is_some_and(|&c| close + 1 < self.end && !is_blank(c) && c != b';')
        {
            return None;
        }
        let value = fast.or_else(|| parse_number(&b[vs..e]))?;
        if !value.is_finite() || b[vs..e].iter().any(|&c| is_blank(c)) {
            return None;
        }
        self.pos = close + 1;
        Some(Token::Word {
            letter,
            span: p..close + 1,
            value_span: vs..e,
            value,
            form,
        })
    }

    fn ident(&mut self, p: usize) -> Option<Result<Token, LexError>> {
        let b = self.bytes;
        let mut i = p + 1;
        while i < self.end && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
            i += 1;
        }
        let name = p..i;
        let letter = b[p].to_ascii_uppercase();
        if is_axis(letter) && is_non_finite_name(&b[p + 1..i]) {
            return self.err(
                p,
                format!(
                    "{} value '{}' is not a finite number",
                    letter as char,
                    self.text(p + 1..i)
                ),
            );
        }
        while i < self.end && matches!(b[i], b'(' | b'[') {
            i = self.skip_group(i);
        }
        if i < self.end && b[i] == b'=' {
            i = self.skip_expr(i + 1);
        }
        self.pos = i;
        Some(Ok(Token::Ident { span: p..i, name }))
    }
}

impl Iterator for Lexer<'_> {
    type Item = Result<Token, LexError>;

    fn next(&mut self) -> Option<Self::Item> {
        let b = self.bytes;
        let mut p = self.pos;
        while p < self.end && is_blank(b[p]) {
            p += 1;
        }
        self.pos = p;
        if p >= self.end {
            return None;
        }
        let c = b[p];
        if is_control(c) {
            return self.err(p, control_message(c));
        }
        match c {
            b'A'..=b'Z' | b'a'..=b'z' => {
                let next = if p + 1 < self.end { b[p + 1] } else { b' ' };
                if next.is_ascii_alphabetic() || next == b'_' {
                    self.ident(p)
                } else if let Some(t) = self.plain_word(p, c.to_ascii_uppercase()) {
                    Some(Ok(t))
                } else {
                    self.word(p, c.to_ascii_uppercase())
                }
            }
            // A Sinumerik user variable or name: `_X_HOME=-365.`, `_camtolerance=.02`.
            b'_' if p + 1 < self.end && (b[p + 1].is_ascii_alphanumeric() || b[p + 1] == b'_') => {
                self.ident(p)
            }
            b';' => {
                self.pos = self.end;
                Some(Ok(Token::Comment { span: p..self.end }))
            }
            b'(' => {
                let mut i = p + 1;
                while i < self.end && b[i] != b')' {
                    i += 1;
                }
                self.pos = (i + 1).min(self.end);
                Some(Ok(Token::Comment { span: p..self.pos }))
            }
            b'*' => {
                self.pos = self.end;
                Some(Ok(Token::BlockEnd { span: p..self.end }))
            }
            b'%' => {
                self.pos = self.end;
                Some(Ok(Token::Percent { span: p..self.end }))
            }
            b'/' => {
                let mut i = p + 1;
                while i < self.end && b[i].is_ascii_digit() {
                    i += 1;
                }
                self.pos = i;
                Some(Ok(Token::Slash { span: p..i }))
            }
            b'"' => {
                let mut i = p + 1;
                while i < self.end && b[i] != b'"' {
                    i += 1;
                }
                self.pos = (i + 1).min(self.end);
                Some(Ok(Token::Other { span: p..self.pos }))
            }
            b'#' => {
                // A parameter: `#12`, `#<name>`, `#[expr]` (LinuxCNC, Fanuc macro B).
                let mut i = p + 1;
                match b.get(i).filter(|_| i < self.end) {
                    Some(b'<') => {
                        while i < self.end && b[i] != b'>' {
                            i += 1;
                        }
                        i = (i + 1).min(self.end);
                    }
                    Some(b'[') => i = self.skip_group(i),
                    _ => {
                        while i < self.end && b[i].is_ascii_digit() {
                            i += 1;
                        }
                    }
                }
                self.pos = i;
                Some(Ok(Token::Param { span: p..i }))
            }
            _ => {
                let mut i = p + 1;
                while i < self.end
                    && !(is_blank(b[i])
                        || b[i].is_ascii_alphabetic()
                        || matches!(b[i], b';' | b'('))
                {
                    i += 1;
                }
                self.pos = i;
                Some(Ok(Token::Other { span: p..i }))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lex(s: &str) -> Vec<Token> {
        Lexer::new(s.as_bytes(), 0..s.len())
            .collect::<Result<_, _>>()
            .unwrap()
    }

    fn lex_err(s: &str) -> LexError {
        Lexer::new(s.as_bytes(), 0..s.len())
            .find_map(|t| t.err())
            .expect("an error")
    }

    /// The one-pass reading of a plain word gives what the general word reader gives, and
    /// leaves to it every word it does not read.
    #[test]
    fn plain_words_read_as_the_general_reader_reads_them() {
        let numbers = [
            "0",
            "-0",
            "+0",
            "12",
            "12.",
            ".5",
            "-.5",
            "+.5",
            "+148.494",
            "0.1",
            "-360.000",
            "9007199254740991",
            "9007199254740993",
            "1234567890123456789",
            "12345678901234567890",
            "0.0000000000000000000001",
            "0.00000000000000000000001",
            "1..2",
            "1.2.",
            ".",
            "+",
            "-",
            "",
            "+-1",
            "- 5",
            " 5",
            "=5",
            "=-.5",
            "#1",
            "[1]",
            "1,5",
            "1e5",
            "1E5",
            "1e",
            "5=3",
        ];
        let after = [
            "", " ", "\t", "\r", "*", " *", ";c", "(c)", "Y1", "E5", "e", "G1", "#", "[", "=", ",",
            ",5", "+1", "-", "/", "\x00", "\x7f", "\u{e9}", ".", "_",
        ];
        for letter in ["X", "c", "G", "N", "F", "E", "R", "H", "Q"] {
            for n in numbers {
                for a in after {
                    let line = format!("{letter}{n}{a}");
                    let bytes = line.as_bytes();
                    let mut fast = Lexer::new(bytes, 0..bytes.len());
                    let up = bytes[0].to_ascii_uppercase();
                    let Some(t) = fast.plain_word(0, up) else {
                        continue;
                    };
                    let mut general = Lexer::new(bytes, 0..bytes.len());
                    let g = general.word(0, up);
                    assert_eq!(Some(Ok(t.clone())), g, "{line:?}");
                    assert_eq!(fast.pos, general.pos, "{line:?}");
                    if let Token::Word { value, .. } = t {
                        let Some(Ok(Token::Word { value: v, .. })) = g else {
                            unreachable!()
                        };
                        assert_eq!(value.to_bits(), v.to_bits(), "{line:?}");
                    }
                }
            }
        }
    }

    /// Lexing a line with plain words taken first gives the tokens (and errors) of the
    /// general reader.
    #[test]
    fn plain_words_first_give_the_same_tokens() {
        for line in [
            "N50 X+0.000 Y+0.000 Z-8 A+35.000 C-360.000 *",
            "G1X10.Y-.5Z3 F1200.(c) ;x",
            "  n10 g01 x1 y 2 Z- 5 TRAORI X=R1 A5=15. C=DC(12.5)",
            "X1e5",
            "X",
            "G1 X1,5",
            "#1=5 X#1 %NAME G71",
            "/2 N1 G0 X1\x00",
            "_X_HOME=-365. MSG(\"a\") \"s\" X1. Y2",
        ] {
            let bytes = line.as_bytes();
            // (The lexer does not move past an error: a reader stops there.)
            let mut general = Vec::new();
            for t in Lexer::new(bytes, 0..bytes.len()) {
                let err = t.is_err();
                general.push(t);
                if err {
                    break;
                }
            }
            let mut lx = Lexer::new(bytes, 0..bytes.len());
            let mut mixed = Vec::new();
            loop {
                match lx.next_plain_word() {
                    Some(t) => mixed.push(Ok(t)),
                    None => match lx.next() {
                        Some(t) => mixed.push(t),
                        None => break,
                    },
                }
                if mixed.last().is_some_and(|t| t.is_err()) {
                    break;
                }
            }
            assert_eq!(mixed, general, "{line}");
        }
    }

    #[test]
    fn numbers_parse_like_std() {
        for s in [
            "0",
            "-0",
            "+0",
            "12",
            "12.",
            ".5",
            "-.5",
            "+148.494",
            "0.1",
            "123456789012345678901234.5",
            "0.30000000000000004",
            "1.0000000000000000000000001",
            "9007199254740993",
        ] {
            let std: f64 = s.parse().unwrap();
            assert_eq!(
                parse_number(s.as_bytes()).unwrap().to_bits(),
                std.to_bits(),
                "{s}"
            );
        }
        for s in ["", ".", "+", "-", "1..2", "1.2.", "+-1", "1e5", "--1", " 1"] {
            assert_eq!(parse_number(s.as_bytes()), None, "{s}");
        }
    }

    #[test]
    fn word_values_match_std_parse() {
        let mut x = 0.123_456_789_f64;
        for k in 0..20_000 {
            x = (x * 7919.0 + 0.618).fract();
            let v = (x - 0.5) * 10f64.powi(k % 12 - 3);
            for text in [
                format!("{:.*}", k as usize % 9, v),
                format!("{:+.3}", v),
                format!("{v}"),
            ] {
                let src = format!("C{text}");
                let t = lex(&src);
                let expect: f64 = text.parse().unwrap();
                assert!(
                    matches!(t[0], Token::Word { value, .. } if value.to_bits() == expect.to_bits()),
                    "{src}"
                );
            }
        }
        for text in [
            "123456789012345678",
            "0.000000000000000000000001",
            "00000000000000000000001.5",
            "-0",
        ] {
            let t = lex(&format!("X{text}"));
            let expect: f64 = text.parse().unwrap();
            assert!(
                matches!(t[0], Token::Word { value, .. } if value.to_bits() == expect.to_bits()),
                "{text}"
            );
        }
    }

    #[test]
    fn heidenhain_block() {
        let t = lex("N120 X+1 Y+0 Z-8 A+14.351 C+135.638 *");
        assert_eq!(t.len(), 7);
        assert_eq!(
            t[5],
            Token::Word {
                letter: b'C',
                span: 26..35,
                value_span: 27..35,
                value: 135.638,
                form: RotaryForm::Plain,
            }
        );
        assert_eq!(t[6], Token::BlockEnd { span: 36..37 });
    }

    #[test]
    fn fanuc_without_spaces_and_comment() {
        let t = lex("G1X10.Y-.5(CUT)");
        assert!(matches!(
            t[0],
            Token::Word {
                letter: b'G',
                value: 1.0,
                ..
            }
        ));
        assert!(matches!(
            t[1],
            Token::Word {
                letter: b'X',
                value: 10.0,
                ..
            }
        ));
        assert!(matches!(
            t[2],
            Token::Word {
                letter: b'Y',
                value: -0.5,
                ..
            }
        ));
        assert_eq!(t[3], Token::Comment { span: 10..15 });
    }

    #[test]
    fn sinumerik_tokens() {
        let t =
            lex(r#"N10 G1 X=12.5 TRAORI CYCLE800(0,"TC1",1) MSG("a;b") R1=R2*3 T="MILL" ; done"#);
        assert!(
            matches!(t[2], Token::Word { letter: b'X', value: 12.5, ref value_span, .. } if *value_span == (9..13))
        );
        assert!(matches!(t[3], Token::Ident { .. }));
        assert!(matches!(&t[4], Token::Ident { span, .. } if span.end == 40));
        assert!(matches!(&t[5], Token::Ident { span, .. } if span.len() == 10));
        assert!(matches!(t[6], Token::Indexed { letter: b'R', .. }));
        assert!(matches!(t[7], Token::Assign { letter: b'T', .. }));
        assert!(matches!(t[8], Token::Comment { .. }));
    }

    #[test]
    fn errors_name_the_value() {
        assert_eq!(
            lex_err("N1 C12..5").message,
            "C value '12..5' is not a number"
        );
        assert_eq!(lex_err("N1 C12..5").at, 3);
        assert_eq!(
            lex_err("CNaN").message,
            "C value 'NaN' is not a finite number"
        );
        assert_eq!(
            lex_err("C=inf").message,
            "C value 'inf' is not a finite number"
        );
        // Expressions and variables are tokens the reader flags, not errors.
        for text in [
            "X=IC(5)",
            "X[#1+2]",
            "A#<a_angle>",
            "X+Q5",
            "F=FGREF(5000)",
            "X=R1+2",
        ] {
            assert!(
                matches!(lex(text)[0], Token::Assign { .. }),
                "{text}: {:?}",
                lex(text)
            );
        }
        assert_eq!(
            lex_err("X\u{fc}").message,
            "X value '\u{fc}' is not a number"
        );
        assert_eq!(lex_err("G1 X").message, "X word has no number");
        assert_eq!(lex_err("G1 X+ Y1").message, "X value '+' is not a number");
        let huge = format!("X{}", "9".repeat(400));
        assert!(lex_err(&huge).message.ends_with("is not a finite number"));
    }

    /// Issue 30 item 1: Sinumerik user variables start with `_` (`SUPA G0 Z=_Z_HOME D0`),
    /// and are read like any other variable; assigning one is an identifier.
    #[test]
    fn sinumerik_user_variables_are_variables() {
        for text in ["X=_XH", "Z=_Z_HOME", "X=-_XH", "F=_F_CUTTING"] {
            assert!(
                matches!(lex(text)[0], Token::Assign { .. }),
                "{text}: {:?}",
                lex(text)
            );
        }
        let t = lex("N120 _X_HOME=-365. _Y_HOME=224. _Z_HOME=610.");
        assert_eq!(t.len(), 4, "{t:?}");
        assert!(t[1..].iter().all(|t| matches!(t, Token::Ident { .. })));
        assert!(matches!(&t[1], Token::Ident { span, .. } if span.len() == 13));
        // `_` alone is not a name.
        assert!(matches!(lex("G1 _ X1")[1], Token::Other { .. }));
    }

    /// Issue 30 item 6: an indexed address is its own token (MillPlus `A5=15. B7=254`,
    /// `L1=1`, `F2=15000.`; Sinumerik `R1=5`, `A3=0.5`), not the letter's word.
    #[test]
    fn indexed_addresses() {
        let t = lex("N3780 G7 A5=15. B5=0.0 C5=210. B7=254 C7=255 L1=1");
        let indexed: Vec<u8> = t
            .iter()
            .filter_map(|t| match t {
                Token::Indexed { letter, .. } => Some(*letter),
                _ => None,
            })
            .collect();
        assert_eq!(indexed, b"ABCBCL");
        assert!(matches!(&t[2], Token::Indexed { span, .. } if span.len() == 6));
        assert!(matches!(
            lex("R1=R2*3")[0],
            Token::Indexed { letter: b'R', .. }
        ));
        assert!(matches!(
            lex("F2=15000.")[0],
            Token::Indexed { letter: b'F', .. }
        ));
        // A number that is not an index before `=` is not one.
        assert!(matches!(lex("X1.5=3")[0], Token::Assign { .. }));
    }

    #[test]
    fn exponent_notation_on_an_axis_is_refused_with_its_column() {
        let e = lex_err("N360 X1e999 Y+0");
        assert_eq!(e.at, 5);
        assert!(
            e.message
                .starts_with("X value '1e999' is in exponent notation")
        );
        assert!(lex_err("G1 C1.5E-3").message.contains("'1.5E-3'"));
        // A letter E after a number with a blank is an ordinary word; `E` alone is not
        // an exponent.
        assert!(
            Lexer::new(b"G1 X1 E999", 0..10).all(|t| t.is_ok()),
            "X1 E999 is two words"
        );
        assert!(Lexer::new(b"G1 X1E", 0..6).all(|t| t.is_ok()));
    }

    #[test]
    fn control_bytes_are_errors_outside_comments() {
        let line = b"N370 X+26 C+\x00211.506 *";
        let e = Lexer::new(line, 0..line.len())
            .find_map(|t| t.err())
            .expect("an error");
        assert_eq!(e.at, 12);
        assert!(e.message.contains("0x00 (NUL)"), "{}", e.message);
        let line = b"G1 X1\x00 Y2";
        let e = Lexer::new(line, 0..line.len())
            .find_map(|t| t.err())
            .expect("an error");
        assert_eq!(e.at, 5);
        let line = b"\x1bG1 X1";
        assert!(Lexer::new(line, 0..line.len()).any(|t| t.is_err()));
        // Inside a comment the bytes are the user's: passed through.
        let line = b"G1 X1 (a\x00b) ; c\x07";
        assert!(Lexer::new(line, 0..line.len()).all(|t| t.is_ok()));
    }

    /// Issue 30 item 10: Sinumerik direction forms are rotary words whose number is in
    /// brackets; anything else in the brackets is an expression.
    #[test]
    fn direction_forms() {
        let t = lex("N20 G1 X1 A=ACP(  5.5 ) C=DC(350.) B=acn(0)");
        assert!(matches!(
            &t[3],
            Token::Word { letter: b'A', value: 5.5, form: RotaryForm::Acp, span, value_span }
                if *span == (10..23) && *value_span == (18..21)
        ));
        assert!(matches!(
            &t[4],
            Token::Word { letter: b'C', value: 350.0, form: RotaryForm::Dc, span, .. }
                if *span == (24..34)
        ));
        assert!(matches!(
            t[5],
            Token::Word {
                letter: b'B',
                value: 0.0,
                form: RotaryForm::Acn,
                ..
            }
        ));
        for text in ["C=DC(R1)", "C=DC(5)+1", "C=ACX(5)", "C=DC(5", "X=DC(5)"] {
            assert!(
                !matches!(lex(text)[0], Token::Word { .. }),
                "{text}: {:?}",
                lex(text)
            );
        }
    }
}
