//! Heidenhain (Philips) MillPlus: the G codes whose meaning differs from Fanuc's, and what
//! an indexed address (`A5=15.`, `B7=254`, `L1=1`) means in each dialect.
//!
//! | block | MillPlus | read as |
//! |---|---|---|
//! | `G7 A5=15. B5=0 C5=210. B7=254 C7=255 L1=1` | tilted working plane (solid angles `A5= B5= C5=`; `L1=1` turns the rotary axes to it; `B7= C7=` store their positions in E parameters) | a frame change: positions unknown after, rotary ones too |
//! | `G93 X0 Y0 Z0` | datum shift (not inverse time) | a frame change |
//! | `G74 Z-.1 L1`, `G74 X1=1 Y1=1 K1 L1` | positioning in machine coordinates | a reference move (positions unknown after) |
//! | `G174` | retract along the tool axis | positions unknown after |
//! | `G81 Y.1181 Z-.7874 B9.804 F12.5` (`G81`…`G89`) | a cycle *definition*: `B` is the clearance, `Y` the safety distance, not axis positions | not a move |
//! | `G79 X… Y… Z…` | the cycle called at a position | positions unknown after |
//! | `G141 L2=0 F2=15000.` / `G40` | 3D tool correction with the tool orientation (TCPM) on / off ([`crate::tcpm`]) | TCPM on / off |
//! | `B=E254`, `F=E1` | E parameters | expressions (not analysable) |
//!
//! G0–G3, G17–G19, G54, G70/G71 (inch/mm), G90/G91 and G94/G95 are read as everywhere.
//!
//! A file is MillPlus ([`looks_like`]) when a line programs `G141` or `G174`, or `G7`
//! with an indexed address, or starts with `%PM`.

use crate::dialect::Dialect;
use crate::lexed::Scan;
use crate::modal::AXES;

/// What MillPlus G code `code` (× 10) does, when it differs from Fanuc's reading (module
/// docs); `false` leaves the code to the common rules.
pub(crate) fn g(code: Option<i64>, s: &mut Scan) -> bool {
    match code {
        // Tilted working plane; the rotary axes may turn to it (L1=1).
        Some(70) => {
            s.datum_shift = true;
            s.unknown_after = true;
        }
        // Datum shift.
        Some(930) => s.datum_shift = true,
        // Machine coordinates.
        Some(740) => s.reference = true,
        // Tool retract along the tool axis; cycle call at a position.
        Some(1740 | 790) => {
            s.unknown_after = true;
            s.breaks = true;
        }
        // Cycle definitions: their addresses are parameters.
        Some(810..=890) => {
            s.no_move = true;
            s.breaks = true;
        }
        _ => return false,
    }
    true
}

/// What an indexed address of `letter` says in `dialect`: in MillPlus a parameter of its
/// block (G7's plane angles, G74's flags, G141's `F2=`); elsewhere, on an axis letter, a
/// value polepatch does not read (Sinumerik's `A3=` orientation vector, an axis `X1=` of
/// the machine): the block is not analysable and the axis unknown after it; on F, a feed
/// it does not read; `R` and `S` (Sinumerik R parameters) change no motion.
pub(crate) fn indexed(dialect: Dialect, letter: u8, s: &mut Scan) {
    if dialect == Dialect::MillPlus {
        s.breaks = true;
    } else if let Some(i) = AXES.iter().position(|&l| l == letter) {
        s.axes_expr |= 1 << i;
    } else if letter == b'F' {
        s.feed_expr = true;
    } else if !matches!(letter, b'R' | b'S') {
        s.breaks = true;
    }
}

/// Whether `line` (code, comments included) is written the MillPlus way (module docs).
pub(crate) fn looks_like(line: &[u8]) -> bool {
    let t = line.trim_ascii_start();
    if t.len() >= 3 && t[..3].eq_ignore_ascii_case(b"%PM") {
        return true;
    }
    let code = match t.iter().position(|&b| b == b'(' || b == b';') {
        Some(k) => &t[..k],
        None => t,
    };
    let words: Vec<&[u8]> = code
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
        .collect();
    let g = |n: &[u8]| {
        words.iter().any(|w| {
            (w[0] == b'G' || w[0] == b'g') && {
                let digits = w[1..].trim_ascii();
                let digits = &digits[digits.iter().take_while(|&&c| c == b'0').count()..];
                digits == n
            }
        })
    };
    let indexed = words.iter().any(|w| {
        w.len() >= 3
            && w[0].is_ascii_alphabetic()
            && w[1].is_ascii_digit()
            && w[2..]
                .iter()
                .find(|c| !c.is_ascii_digit())
                .is_some_and(|&c| c == b'=')
    });
    g(b"141") || g(b"174") || (g(b"7") && indexed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markers() {
        assert!(looks_like(b"N3780 G7 A5=15. B5=0.0 C5=210. B7=254 C7=255"));
        assert!(looks_like(b"N0540 G141 L2=0 F2=15000."));
        assert!(looks_like(b"N0140 G174"));
        assert!(looks_like(b"%PM1234"));
        for line in [
            &b"N10 G1 X7 A5 C5"[..],
            b"G17 G40 G80",
            b"N10 G1 X=10 A3=0.5 C3=0.8",
            b"(G141 in a comment)",
            b"G1410 X1",
            b"G07 X5",
        ] {
            assert!(!looks_like(line), "{}", String::from_utf8_lossy(line));
        }
    }
}
