//! The file's number style, so that rewritten words look like their neighbours.

use crate::lexer::parse_number;
use crate::modal::AXES;
use crate::program::Program;
use crate::word::Word;

/// How numbers of one address letter are written in a file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NumberStyle {
    /// Positive values carry an explicit `+` (Heidenhain style `C+12.5`).
    pub plus_sign: bool,
    /// Decimal places written (the maximum seen for this letter).
    pub decimals: usize,
    /// Trailing zeros are dropped (`C+126.28` beside `C+148.494`), and a whole number is
    /// written without a point unless `trailing_point`.
    pub strip_trailing_zeros: bool,
    /// Whole numbers keep a trailing point (`C180.`, Fanuc style).
    pub trailing_point: bool,
    /// A value below 1 in magnitude is written with its leading zero (`0.5`, not `.5`).
    pub leading_zero: bool,
    /// `=` between letter and number (`C=12.5`, Sinumerik).
    pub equals: bool,
    /// How a zero is written when the file writes it its own way (NX posts: `B0.0` beside
    /// `B.387` and `B15.`); `None`: like any other value.
    pub zero: Option<ZeroStyle>,
}

/// How a file writes the value zero (the first zero of the letter, or of the axis words).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ZeroStyle {
    /// A `0` before the point (`0.0`, not `.0`).
    pub leading_zero: bool,
    /// A point (`0.`, `0.0`).
    pub point: bool,
    /// Zeros after the point.
    pub decimals: u8,
}

impl ZeroStyle {
    fn render(self) -> String {
        let mut s = String::with_capacity(3 + usize::from(self.decimals));
        if self.leading_zero || !self.point || self.decimals == 0 {
            s.push('0');
        }
        if self.point {
            s.push('.');
            s.extend(std::iter::repeat_n('0', usize::from(self.decimals)));
        }
        s
    }
}

/// The offset in `bytes[start..start + len]` (a number: at most one point) of its point.
fn point_in(bytes: &[u8], start: usize, len: usize) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    if len <= 8
        && let Some(chunk) = bytes.get(start..start + 8)
    {
        // Eight bytes at a time: the lowest set bit of `t` marks the first `.` exactly;
        // bits past `len` are dropped.
        let x = u64::from_le_bytes(chunk.try_into().unwrap_or([0; 8])) ^ (LO * u64::from(b'.'));
        let t = x.wrapping_sub(LO) & !x & HI;
        let t = if len < 8 {
            t & ((1u64 << (len * 8)) - 1)
        } else {
            t
        };
        return (t != 0).then(|| (t.trailing_zeros() / 8) as usize);
    }
    bytes[start..start + len].iter().position(|&b| b == b'.')
}

/// What the words of one letter show about their style.
#[derive(Default)]
struct Evidence {
    words: usize,
    max_decimals: usize,
    min_decimals: usize,
    /// Non-negative values with / without `+`.
    plus: usize,
    unsigned: usize,
    /// Whole numbers with / without a trailing point.
    point: usize,
    no_point: usize,
    /// Values below 1 written `0.5` / `.5`.
    zero: usize,
    no_zero: usize,
    equals: usize,
    /// Values whose last decimal is a `0` (`12.500`): evidence against stripping.
    trailing_zero: usize,
    /// The first zero written (a zero is evidence of its own form only: `B0.0` says
    /// nothing about how `B.387` is written), and its word's byte offset.
    zero_form: Option<(ZeroStyle, u32)>,
}

impl Evidence {
    fn empty() -> Evidence {
        Evidence {
            min_decimals: usize::MAX,
            ..Evidence::default()
        }
    }

    fn collect(program: &Program, pick: impl Fn(u8) -> bool) -> Evidence {
        let mut e = Evidence::empty();
        let bytes = &program.bytes[..];
        for w in program.words.iter().filter(|w| pick(w.letter)) {
            e.add(bytes, w);
        }
        e
    }

    /// Count word `w` (its offsets index `bytes`).
    fn add(&mut self, bytes: &[u8], w: &Word) {
        self.add_after(bytes, w, bytes.get(w.start as usize + 1).copied());
    }

    /// [`Evidence::add`], `after_letter` the byte after the word's letter.
    fn add_after(&mut self, bytes: &[u8], w: &Word, after_letter: Option<u8>) {
        let e = self;
        let body_start = w.value_start as usize;
        let text = &bytes[body_start..w.end as usize];
        e.words += 1;
        if after_letter == Some(b'=') {
            e.equals += 1;
        }
        let (sign, body_start) = match text.first() {
            Some(b'+') => (Some(b'+'), body_start + 1),
            Some(b'-') => (Some(b'-'), body_start + 1),
            _ => (None, body_start),
        };
        let body = &bytes[body_start..w.end as usize];
        match sign {
            Some(b'+') => e.plus += 1,
            None => e.unsigned += 1,
            _ => {}
        }
        let (decimals, has_point) = match point_in(bytes, body_start, body.len()) {
            Some(k) => (body.len() - k - 1, true),
            None => (0, false),
        };
        e.max_decimals = e.max_decimals.max(decimals);
        // Written as zero: its value is the number parsed, so only a zero value can be.
        if w.value == 0.0 && body.iter().all(|&b| b == b'0' || b == b'.') {
            e.zero_form.get_or_insert((
                ZeroStyle {
                    leading_zero: body.first() == Some(&b'0'),
                    point: has_point,
                    decimals: decimals.min(usize::from(u8::MAX)) as u8,
                },
                w.start,
            ));
            return;
        }
        e.min_decimals = e.min_decimals.min(decimals);
        if decimals > 0 && body.last() == Some(&b'0') {
            e.trailing_zero += 1;
        }
        if decimals == 0 {
            if has_point {
                e.point += 1;
            } else {
                e.no_point += 1;
            }
        } else if body.first() == Some(&b'.') {
            e.no_zero += 1;
        } else if body.first() == Some(&b'0') && body.get(1) == Some(&b'.') {
            e.zero += 1;
        }
    }
}

impl Evidence {
    /// The evidence of the words of `self` and of `other` together (the first zero the
    /// one of the two that comes first in the file).
    fn merged(&self, other: &Evidence) -> Evidence {
        Evidence {
            words: self.words + other.words,
            max_decimals: self.max_decimals.max(other.max_decimals),
            min_decimals: self.min_decimals.min(other.min_decimals),
            plus: self.plus + other.plus,
            unsigned: self.unsigned + other.unsigned,
            point: self.point + other.point,
            no_point: self.no_point + other.no_point,
            zero: self.zero + other.zero,
            no_zero: self.no_zero + other.no_zero,
            equals: self.equals + other.equals,
            trailing_zero: self.trailing_zero + other.trailing_zero,
            zero_form: match (self.zero_form, other.zero_form) {
                (Some(a), Some(b)) => Some(if b.1 < a.1 { b } else { a }),
                (a, b) => a.or(b),
            },
        }
    }

    /// Whether these words strip trailing zeros: `Some(true)` if some are written with
    /// fewer decimals than others, `Some(false)` if one ends in a decimal `0`, `None`
    /// when they cannot tell (no words, or all with the same decimals).
    fn strips(&self) -> Option<bool> {
        if self.trailing_zero > 0 {
            Some(false)
        } else if self.words > 0 && self.min_decimals < self.max_decimals {
            Some(true)
        } else {
            None
        }
    }
}

impl NumberStyle {
    /// The style of `letter` words in `program`, falling back to the style of the other
    /// axis words when the letter never occurs.
    ///
    /// - `plus_sign`: a non-negative value of the letter is written with `+` (if the
    ///   letter has no non-negative value: one of the axis words X Y Z A B C is);
    /// - `decimals`: the most decimals written (a zero — `0`, `0.`, `0.0`, `.000` — counts
    ///   for `decimals` and `plus_sign` only: posts often write it their own way, which
    ///   `zero` keeps: letter, else axis words);
    /// - `strip_trailing_zeros`: some value is written with fewer decimals than that and
    ///   none ends in a decimal `0` (letter; if its words all have the same decimals,
    ///   the axis words decide; else false);
    /// - `trailing_point`: a whole number is written `180.` (letter, else axis words);
    /// - `leading_zero`: false only if values below 1 are written `.5` and never `0.5`
    ///   (letter, else axis words);
    /// - `equals`: a word is written `C=…`.
    pub fn of(program: &Program, letter: u8) -> NumberStyle {
        let letter = letter.to_ascii_uppercase();
        let own = Evidence::collect(program, |l| l == letter);
        let axes = Evidence::collect(program, |l| AXES.contains(&l));
        NumberStyle::from_evidence(&own, &axes)
    }

    fn from_evidence(own: &Evidence, axes: &Evidence) -> NumberStyle {
        let main = if own.words > 0 { own } else { axes };
        let plus = if main.plus + main.unsigned > 0 {
            main
        } else {
            axes
        };
        let point = if main.point + main.no_point > 0 {
            main
        } else {
            axes
        };
        let zero = if main.zero + main.no_zero > 0 {
            main
        } else {
            axes
        };
        NumberStyle {
            plus_sign: plus.plus > 0,
            decimals: main.max_decimals,
            strip_trailing_zeros: main
                .strips()
                .unwrap_or_else(|| axes.strips().unwrap_or(false)),
            trailing_point: point.point > 0,
            leading_zero: !(zero.no_zero > 0 && zero.zero == 0),
            equals: main.equals > 0,
            zero: main.zero_form.or(axes.zero_form).map(|z| z.0),
        }
    }

    /// The number as this style writes it with `decimals` places (not the letter).
    ///
    /// Starts from `format!("{:.*}", decimals, value)` (round half to even on the binary
    /// value, as the patcher verifies), then: a negative zero loses its `-`; trailing
    /// zeros are stripped (and the point unless `trailing_point`) if
    /// `strip_trailing_zeros`, else a whole number gets a point if `trailing_point`; a
    /// leading `0` before the point is dropped unless `leading_zero`; `+` is put before a
    /// non-negative value if `plus_sign`. A value that rounds to zero is written in the
    /// file's `zero` form when it has one.
    pub fn render(&self, value: f64, decimals: usize) -> String {
        let mut s = format!("{:.*}", decimals, value);
        if s.starts_with('-') && s[1..].bytes().all(|b| b == b'0' || b == b'.') {
            s.remove(0);
        }
        if let Some(z) = self.zero
            && s.bytes().all(|b| b == b'0' || b == b'.')
        {
            let z = z.render();
            return if self.plus_sign { format!("+{z}") } else { z };
        }
        if s.contains('.') {
            if self.strip_trailing_zeros {
                let keep = s.trim_end_matches('0').len();
                s.truncate(keep);
                if s.ends_with('.') && !self.trailing_point {
                    s.pop();
                }
            }
        } else if self.trailing_point && s.bytes().all(|b| b.is_ascii_digit() || b == b'-') {
            s.push('.');
        }
        if !self.leading_zero {
            let digits = if s.starts_with('-') { 1 } else { 0 };
            if s[digits..].starts_with("0.") && s.len() > digits + 2 {
                s.remove(digits);
            }
        }
        if self.plus_sign && !s.starts_with('-') {
            s.insert(0, '+');
        }
        s
    }

    /// The value the controller receives: `render` parsed back (NaN if `value` is not
    /// finite).
    pub fn rounded(&self, value: f64, decimals: usize) -> f64 {
        parse_number(self.render(value, decimals).as_bytes()).unwrap_or(f64::NAN)
    }
}

/// How a whole file writes its axis words (X Y Z A B C, each as [`NumberStyle::of`]) and
/// separates words: what [`crate::apply_edits`] needs to write edits into any stretch
/// of the file the file's way.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FileStyle {
    /// Styles of X Y Z A B C, in [`AXES`] order.
    pub axes: [NumberStyle; 6],
    /// The usual gap between two words of a block: a space, unless most words follow
    /// each other directly (`G1X10.Y5.`).
    pub gap: &'static [u8],
    /// The gap between an axis letter and its number: none, unless most axis words have a
    /// blank there (`X 6.302`, as some RS274/NGC posts write).
    pub letter_gap: &'static [u8],
}

impl FileStyle {
    /// The style of `program`'s axis words.
    pub fn of(program: &Program) -> FileStyle {
        let mut ev = StyleEvidence::default();
        for b in &program.blocks {
            ev.add_block(&program.bytes, &program.words[b.words()]);
        }
        ev.style()
    }

    /// The style of axis `letter` (X Y Z A B C), `None` for another letter.
    pub fn letter(&self, letter: u8) -> Option<NumberStyle> {
        let l = letter.to_ascii_uppercase();
        AXES.iter().position(|&a| a == l).map(|i| self.axes[i])
    }
}

/// [`FileStyle`] evidence gathered block by block, for callers that read a file as a
/// stream ([`crate::scan`]): the same figures as [`FileStyle::of`] on the whole program.
pub struct StyleEvidence {
    letters: [Evidence; 6],
    spaced: usize,
    tight: usize,
    /// Axis words with / without a blank between letter and number.
    letter_spaced: usize,
    letter_tight: usize,
}

impl Default for StyleEvidence {
    fn default() -> Self {
        StyleEvidence {
            letters: std::array::from_fn(|_| Evidence::empty()),
            spaced: 0,
            tight: 0,
            letter_spaced: 0,
            letter_tight: 0,
        }
    }
}

impl StyleEvidence {
    /// Count the words of one block (their offsets index `bytes`).
    pub fn add_block(&mut self, bytes: &[u8], words: &[Word]) {
        let mut prev_end = None;
        for w in words {
            // Two words of the block follow each other directly, or with a gap.
            match prev_end {
                Some(end) if end == w.start => self.tight += 1,
                Some(_) => self.spaced += 1,
                None => {}
            }
            prev_end = Some(w.end);
            let i = match w.letter {
                b'X' => 0,
                b'Y' => 1,
                b'Z' => 2,
                b'A' => 3,
                b'B' => 4,
                b'C' => 5,
                _ => continue,
            };
            debug_assert_eq!(AXES[i], w.letter);
            let after_letter = bytes.get(w.start as usize + 1).copied();
            self.letters[i].add_after(bytes, w, after_letter);
            if matches!(after_letter, Some(b' ' | b'\t')) {
                self.letter_spaced += 1;
            } else {
                self.letter_tight += 1;
            }
        }
    }

    /// Count what `other` counted too (other words of the same file).
    pub fn merge(&mut self, other: &StyleEvidence) {
        for (l, o) in self.letters.iter_mut().zip(&other.letters) {
            *l = l.merged(o);
        }
        self.spaced += other.spaced;
        self.tight += other.tight;
        self.letter_spaced += other.letter_spaced;
        self.letter_tight += other.letter_tight;
    }

    /// The file's style from what was counted.
    pub fn style(&self) -> FileStyle {
        // The axis words together: every letter's evidence merged.
        let any_axis = self
            .letters
            .iter()
            .fold(Evidence::empty(), |all, e| all.merged(e));
        FileStyle {
            axes: std::array::from_fn(|i| NumberStyle::from_evidence(&self.letters[i], &any_axis)),
            gap: if self.tight > self.spaced { b"" } else { b" " },
            letter_gap: if self.letter_spaced > self.letter_tight {
                b" "
            } else {
                b""
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Dialect, parse};

    fn style(s: &str, letter: u8) -> NumberStyle {
        NumberStyle::of(
            &parse(s.as_bytes().to_vec(), Dialect::Auto).unwrap(),
            letter,
        )
    }

    const HEID: NumberStyle = NumberStyle {
        plus_sign: true,
        decimals: 3,
        strip_trailing_zeros: true,
        trailing_point: false,
        leading_zero: true,
        equals: false,
        zero: Some(ZeroStyle {
            leading_zero: true,
            point: false,
            decimals: 0,
        }),
    };

    #[test]
    fn heidenhain_style() {
        let st = style("N1 G01 X+0 C+126.28 *\nN2 C+148.494 *\nN3 C+180 *\n", b'C');
        assert_eq!(st, HEID);
        assert_eq!(st.render(180.0, 3), "+180");
        assert_eq!(st.render(126.2800001, 3), "+126.28");
        assert_eq!(st.render(-0.0001, 3), "+0");
        assert_eq!(st.render(-12.5, 3), "-12.5");
        assert_eq!(st.render(0.25, 3), "+0.25");
        assert_eq!(st.rounded(148.4944, 3), 148.494);
        assert_eq!(st.rounded(148.4946, 4), 148.4946);
    }

    #[test]
    fn fanuc_style() {
        let st = style("G1 X10. Y-.5 C12.5\nC180.\nC-.25\n", b'C');
        assert!(!st.plus_sign && st.trailing_point && st.strip_trailing_zeros && !st.leading_zero);
        assert_eq!(st.decimals, 2);
        assert_eq!(st.render(180.0, 3), "180.");
        assert_eq!(st.render(0.5, 3), ".5");
        assert_eq!(st.render(-0.5, 3), "-.5");
        assert_eq!(st.render(0.0, 3), "0.");
        assert_eq!(st.render(-0.0, 3), "0.");
        assert_eq!(st.rounded(-0.4999, 3), -0.5);
    }

    #[test]
    fn fixed_decimals_and_equals() {
        let st = style("N10 G1 X=10.000 A=2.500 C=30.000\n", b'C');
        assert!(st.equals && !st.plus_sign && !st.strip_trailing_zeros);
        assert_eq!(st.decimals, 3);
        assert_eq!(st.render(30.0, 3), "30.000");
        assert_eq!(st.render(-0.0, 3), "0.000");
    }

    #[test]
    fn missing_letter_falls_back_to_axis_words() {
        let st = style("N1 G01 X+1.5 Y+0 A+2.25 *\n", b'C');
        assert!(st.plus_sign && st.strip_trailing_zeros);
        assert_eq!(st.decimals, 2);
        // Only negative C values: the sign style comes from the axis words.
        assert!(style("N1 G01 X+1.5 C-2.5 *\n", b'C').plus_sign);
    }

    #[test]
    fn render_is_based_on_std_format() {
        let st = NumberStyle {
            plus_sign: false,
            decimals: 3,
            strip_trailing_zeros: false,
            trailing_point: false,
            leading_zero: true,
            equals: false,
            zero: None,
        };
        for v in [0.0005, 0.0015, 2.675, -1.0005, 123456.789, 1e-9, -1e-9] {
            let f = format!("{:.3}", v);
            let expected = if f == "-0.000" {
                "0.000".to_string()
            } else {
                f
            };
            assert_eq!(st.render(v, 3), expected, "{v}");
        }
    }

    /// Issue 30 item 9: NX writes zero `B0.0` and every other value without trailing zeros
    /// or a leading zero (`B.387`, `B1.8`, `B15.`): a rewritten word keeps that style.
    #[test]
    fn a_zero_written_its_own_way_is_no_evidence_for_the_others() {
        let src = "N15 G00 B0.0\nN16 G00 C0.0\nN480 G01 X.9857 Y.9845 B.387 C9.03 F9.8\n\
                   N481 X.987 B1.8 C17.521\nN482 B15. C25.815\n";
        let st = style(src, b'B');
        assert!(
            !st.leading_zero && st.strip_trailing_zeros && st.trailing_point,
            "{st:?}"
        );
        assert_eq!(st.decimals, 3);
        assert_eq!(st.render(0.059, 3), ".059");
        assert_eq!(st.render(0.42, 3), ".42");
        assert_eq!(st.render(-0.5, 3), "-.5");
        assert_eq!(st.render(12.0, 3), "12.");
        assert_eq!(st.render(0.0001, 3), "0.0", "zero as the file writes it");
        assert_eq!(st.render(-0.0001, 3), "0.0");
        assert_eq!(st.rounded(0.0004, 3), 0.0);
        // A fixed-decimals file keeps its zeros and its trailing zeros.
        let st = style("N10 G1 X=10.000 A=0.000 C=30.000\n", b'A');
        assert!(!st.strip_trailing_zeros);
        assert_eq!(st.render(2.5, 3), "2.500");
        assert_eq!(st.render(0.0, 3), "0.000");
    }

    /// The evidence of a file counted in two parts and merged is the evidence of the whole.
    #[test]
    fn evidence_merged_from_parts_is_the_wholes() {
        let src = "N1 G01 X+0 C+126.28 *\nN2 C+148.494 Y0.0 *\nN3 C+180 X 5. *\nG1X1.Y2.Z.5B-.5\nX2.0 A0.\n";
        let p = parse(src.as_bytes().to_vec(), Dialect::Auto).unwrap();
        let whole = FileStyle::of(&p);
        for cut in 0..=p.blocks.len() {
            let (mut a, mut b) = (StyleEvidence::default(), StyleEvidence::default());
            for (k, bl) in p.blocks.iter().enumerate() {
                let ev = if k < cut { &mut a } else { &mut b };
                ev.add_block(&p.bytes, &p.words[bl.words()]);
            }
            b.merge(&a);
            assert_eq!(b.style(), whole, "{cut}");
        }
    }

    /// The point of a number found eight bytes at a time is the one found byte by byte.
    #[test]
    fn point_found_eight_bytes_at_a_time() {
        let text = b"12.5 .5 0. 1234567.8 12345678 1234567. .2345678 123.45678901 5 + ...";
        for start in 0..text.len() {
            for len in 0..=(text.len() - start).min(12) {
                let slow = text[start..start + len].iter().position(|&b| b == b'.');
                let slice = &text[start..start + len];
                // Only numbers hold at most one point.
                if slice.iter().filter(|&&b| b == b'.').count() <= 1 {
                    assert_eq!(point_in(text, start, len), slow, "{start} {len}");
                }
            }
        }
    }

    /// The file style gathered block by block is each letter's [`NumberStyle::of`], and the
    /// gap the file uses.
    #[test]
    fn file_style_is_each_letters_style() {
        for src in [
            "N1 G01 X+0 C+126.28 *\nN2 C+148.494 *\nN3 C+180 *\n",
            "G1 X10. Y-.5 C12.5\nC180.\nC-.25\n",
            "N10 G1 X=10.000 A=2.500 C=30.000\n",
            "N1 G01 X+1.5 Y+0 A+2.25 *\n",
            "G1X1.Y2.Z3.B-.5\nX2.\n",
            "(no words at all)\n",
        ] {
            let p = parse(src.as_bytes().to_vec(), Dialect::Auto).unwrap();
            let f = FileStyle::of(&p);
            for (i, &l) in AXES.iter().enumerate() {
                assert_eq!(f.axes[i], NumberStyle::of(&p, l), "{src} {}", l as char);
                assert_eq!(f.letter(l), Some(f.axes[i]));
            }
            assert_eq!(f.letter(b'F'), None);
            let tight = src.starts_with("G1X1.");
            assert_eq!(f.gap, if tight { &b""[..] } else { &b" "[..] }, "{src}");
        }
    }
}
