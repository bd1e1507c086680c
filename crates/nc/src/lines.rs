//! Splitting a file into lines.
//!
//! A file ends its lines with `\n` (a `\r` before it belongs to the line ending: CR LF),
//! or — when it holds no `\n` at all but does hold a `\r` — with `\r` alone (the classic
//! Mac convention some old controllers and editors still write). In a file with `\n`
//! endings a lone `\r` inside a line is a blank, as controllers read it; an error in such a
//! line after the `\r` says where it is ([`explain_lone_cr`]): most editors show the line
//! as two. A final line without an ending is a line; a final empty segment after the last
//! ending is not.
//!
//! A UTF-8 byte-order mark ([`BOM`]) at the start of the file, as some Windows editors
//! write it, belongs to no line: the first line starts after it, so every reader of lines
//! (the dialect's detection, the lexer, conversational lines) sees the program's first
//! line as the controller does, and its columns as an editor shows them. The mark is
//! copied to the output like every byte outside the words polepatch changes.

/// The UTF-8 byte-order mark.
pub const BOM: &[u8] = b"\xEF\xBB\xBF";

use std::ops::Range;

/// A file's line ending (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineEnds {
    /// `\n` or `\r\n`.
    Lf,
    /// `\r` alone (the file has no `\n`).
    Cr,
}

impl LineEnds {
    /// The convention of `bytes` (module docs). Reads up to the first `\n`; only a file
    /// without one is read to its end.
    pub fn of(bytes: &[u8]) -> LineEnds {
        if find_byte(bytes, 0, b'\n').is_none() && bytes.contains(&b'\r') {
            LineEnds::Cr
        } else {
            LineEnds::Lf
        }
    }

    fn byte(self) -> u8 {
        match self {
            LineEnds::Lf => b'\n',
            LineEnds::Cr => b'\r',
        }
    }

    /// Offset of the first line-ending byte at or after `from`.
    pub(crate) fn find(self, bytes: &[u8], from: usize) -> Option<usize> {
        find_byte(bytes, from, self.byte())
    }

    /// The offset just past the line ending at or after `at` (the end of `bytes` if none).
    pub(crate) fn cut_after(self, bytes: &[u8], at: usize) -> usize {
        if at >= bytes.len() {
            return bytes.len();
        }
        self.find(bytes, at).map_or(bytes.len(), |nl| nl + 1)
    }

    /// The lines of `bytes` from byte `start` (a line start), numbered from 1 there: each
    /// line's span without its ending, and its number. From the start of the file, the
    /// first line starts after a byte-order mark (module docs).
    pub(crate) fn lines_from(
        self,
        bytes: &[u8],
        start: usize,
    ) -> impl Iterator<Item = (Range<usize>, usize)> + '_ {
        let n = bytes.len();
        let mut start = if start == 0 && bytes.starts_with(BOM) {
            BOM.len()
        } else {
            start
        };
        let mut line = 0;
        std::iter::from_fn(move || {
            if start >= n {
                return None;
            }
            let (end, next) = match self.find(bytes, start) {
                Some(nl) => (
                    if self == LineEnds::Lf && nl > start && bytes[nl - 1] == b'\r' {
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
}

/// `e`, an error in the line `span` of `bytes`, with what a lone carriage return before its
/// column does to that line (module docs): an LF-terminated controller reads one block
/// there, where most editors show two lines, so a message about "this block" needs the CR
/// named and placed. Unchanged when no CR stands before the error's column.
pub(crate) fn explain_lone_cr(
    bytes: &[u8],
    span: &Range<usize>,
    mut e: crate::ParseError,
) -> crate::ParseError {
    let line = &bytes[span.clone()];
    let before = &line[..e.column.saturating_sub(1).min(line.len())];
    if let Some(cr) = before.iter().position(|&b| b == b'\r') {
        e.message.push_str(&format!(
            " — line {} holds a carriage return (CR) at col {} that does not end it: the file \
             ends its lines with LF, so an LF-terminated controller reads all of line {} as one \
             block, where most editors show it as two lines",
            e.line,
            cr + 1,
            e.line
        ));
    }
    e
}

/// Offset of the first `needle` at or after `from`, eight bytes at a time.
pub(crate) fn find_byte(bytes: &[u8], from: usize, needle: u8) -> Option<usize> {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    let pattern = LO * u64::from(needle);
    let mut i = from;
    while let Some(chunk) = bytes.get(i..i + 8) {
        let x = u64::from_le_bytes(chunk.try_into().unwrap_or([0; 8])) ^ pattern;
        // The lowest set bit marks the first zero byte of x, i.e. the first match.
        let t = x.wrapping_sub(LO) & !x & HI;
        if t != 0 {
            return Some(i + (t.trailing_zeros() / 8) as usize);
        }
        i += 8;
    }
    bytes
        .get(i..)?
        .iter()
        .position(|&b| b == needle)
        .map(|k| i + k)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(s: &[u8]) -> Vec<(Range<usize>, usize)> {
        LineEnds::of(s).lines_from(s, 0).collect()
    }

    #[test]
    fn byte_search() {
        let text = b"0123456789\nabcdefghijklmnopqrstuvwxyz\n\x8a\n\r";
        for needle in [b'\n', b'\r', b'z', 0x8a] {
            for from in 0..text.len() + 2 {
                let naive = text
                    .get(from..)
                    .and_then(|t| t.iter().position(|&b| b == needle))
                    .map(|k| from + k);
                assert_eq!(find_byte(text, from, needle), naive, "{from}");
            }
        }
    }

    #[test]
    fn lf_crlf_and_cr_alone() {
        assert_eq!(
            lines(b"G1 X1\r\nY2\n\nZ3"),
            vec![(0..5, 1), (7..9, 2), (10..10, 3), (11..13, 4)]
        );
        assert_eq!(lines(b"X1\n"), vec![(0..2, 1)]);
        assert!(lines(b"").is_empty());
        // No LF anywhere: CR ends lines.
        assert_eq!(LineEnds::of(b"G1 X1\rY2\r"), LineEnds::Cr);
        assert_eq!(
            lines(b"G1 X1\rY2\r\rZ3"),
            vec![(0..5, 1), (6..8, 2), (9..9, 3), (10..12, 4)]
        );
        // With LF endings a lone CR stays inside its line (a blank to the lexer).
        assert_eq!(lines(b"G1 X1\rY2\nZ3\n"), vec![(0..8, 1), (9..11, 2)]);
    }

    /// Issue 42 item 5: a byte-order mark belongs to no line; a file that only starts with
    /// its first bytes, or holds them later, is read as it is.
    #[test]
    fn a_byte_order_mark_is_before_the_first_line() {
        assert_eq!(
            lines(b"\xEF\xBB\xBF%T G71 *\nN10 G90 *\n"),
            vec![(3..11, 1), (12..21, 2)]
        );
        assert_eq!(lines(b"\xEF\xBB\xBF"), vec![]);
        assert_eq!(lines(b"\xEF\xBB\xBF\rX1\r"), vec![(3..3, 1), (4..6, 2)]);
        // Not a mark: a part of one, or one after the start.
        assert_eq!(lines(b"\xEF\xBBX1\n"), vec![(0..4, 1)]);
        assert_eq!(lines(b"X1\n\xEF\xBB\xBFX2\n"), vec![(0..2, 1), (3..8, 2)]);
        // A read from a later line start is not the file's start.
        let text = b"X1\n\xEF\xBB\xBFX2\n";
        let from: Vec<_> = LineEnds::Lf.lines_from(text, 3).collect();
        assert_eq!(from, vec![(3..8, 1)]);
    }

    /// Issue 42 item 1: an error after a lone CR says where the CR is and why the line is
    /// one block; one before it, or in a line without one, is left as it is.
    #[test]
    fn a_lone_cr_before_an_error_is_named() {
        let text = b"N80 G1 X1\nN84 X55.455\rN85X56 Y2\n";
        let span = 10..31;
        let e = crate::ParseError::at(2, 16, "X appears twice in this block");
        let e = explain_lone_cr(text, &span, e);
        assert!(
            e.message.starts_with(
                "X appears twice in this block — line 2 holds a carriage \
                                   return (CR) at col 12"
            ) && e.message.contains("editors show it as two lines"),
            "{}",
            e.message
        );
        let before = crate::ParseError::at(2, 5, "X value 'y' is not a number");
        assert_eq!(explain_lone_cr(text, &span, before.clone()), before);
        let plain = crate::ParseError::at(1, 8, "m");
        assert_eq!(explain_lone_cr(text, &(0..9), plain.clone()), plain);
    }
}
