//! Dialect detection: which dialect a program is written in, from its first 64 KiB.

use crate::dialect::Dialect;
use crate::lines::LineEnds;
use crate::tolerances::DETECT_HEAD_BYTES;

/// Guess the dialect from the first 64 KiB: a `BEGIN PGM` line → Heidenhain
/// conversational, and so do lines that only conversational has (`L X+10 R0 F…`,
/// `TOOL CALL`, `CYCL DEF`, `BLK FORM`); a `*` block end or a `%NAME G71` header → Heidenhain ISO;
/// `TRAORI`/`TRAFOOF` → Sinumerik; `( )` comments or `G43.4` → Fanuc; `M128` or
/// `FUNCTION TCPM` → Heidenhain ISO; `;` comments → Sinumerik; else Fanuc.
pub fn detect(bytes: &[u8]) -> Dialect {
    let head = &bytes[..bytes.len().min(DETECT_HEAD_BYTES)];
    let contains = |needle: &[u8]| {
        head.windows(needle.len())
            .any(|w| w.eq_ignore_ascii_case(needle))
    };
    let ends = LineEnds::of(head);
    let lines = || ends.lines_from(head, 0).map(|(r, _)| &head[r]);
    // Conversational: a `BEGIN PGM` line (after an optional block number).
    if lines().any(|line| {
        let t = line.trim_ascii_start();
        let t = t[t.iter().take_while(|c| c.is_ascii_digit()).count()..].trim_ascii_start();
        t.len() >= 9
            && t[..5].eq_ignore_ascii_case(b"BEGIN")
            && t[5..]
                .trim_ascii_start()
                .get(..3)
                .is_some_and(|w| w.eq_ignore_ascii_case(b"PGM"))
    }) {
        return Dialect::Conversational;
    }
    // Conversational without its `BEGIN PGM` (a fragment, a listing): a line that starts,
    // after an optional block number, with `L` and a blank and then an address of a
    // straight line (`L X+10 … R0 F2000`, `L  Z+50 R0 FMAX`, `L IX+5`, `L M128`), or with
    // `TOOL CALL`, `CYCL DEF`, `BLK FORM`. (Sinumerik's `L100` subprogram call has no
    // blank; ISO lines start with N, G, M or an address and a number; `FUNCTION TCPM` is
    // also written in Heidenhain ISO programs.)
    if lines().any(|line| {
        let t = line.trim_ascii_start();
        let t = t[t.iter().take_while(|c| c.is_ascii_digit()).count()..].trim_ascii_start();
        let starts = |kw: &[u8]| t.len() >= kw.len() && t[..kw.len()].eq_ignore_ascii_case(kw);
        let straight = t.len() >= 3
            && t[0].eq_ignore_ascii_case(&b'L')
            && (t[1] == b' ' || t[1] == b'\t')
            && t[1..]
                .trim_ascii_start()
                .first()
                .is_some_and(|c| b"XYZABCIRFMxyzabcirfm".contains(c));
        straight || starts(b"TOOL CALL") || starts(b"CYCL DEF") || starts(b"BLK FORM")
    }) {
        return Dialect::Conversational;
    }
    for line in lines() {
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
    // MillPlus: `G141`, `G174`, `G7` with indexed addresses, a `%PM` header.
    if lines().any(crate::millplus::looks_like) {
        return Dialect::MillPlus;
    }
    // M128 as a word (not M1280): Heidenhain's TCPM code.
    let m128 = head.windows(5).enumerate().any(|(k, w)| {
        w[..4].eq_ignore_ascii_case(b"M128")
            && !w[4].is_ascii_digit()
            && (k == 0 || !head[k - 1].is_ascii_alphanumeric())
    }) || head.ends_with(b"M128");
    if contains(b"TRAORI") || contains(b"TRAFOOF") {
        Dialect::Sinumerik
    } else if head.contains(&b'(') || contains(b"G43.4") {
        Dialect::Fanuc
    } else if m128 || contains(b"FUNCTION TCPM") {
        Dialect::Heidenhain
    } else if head.contains(&b';') {
        Dialect::Sinumerik
    } else {
        Dialect::Fanuc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dialects_are_detected() {
        assert_eq!(detect(b"%P G71 *\nN10 G90 *\n"), Dialect::Heidenhain);
        assert_eq!(detect(b"N10 TRAORI\nN20 G1 X1 ; cut\n"), Dialect::Sinumerik);
        assert_eq!(detect(b"%\nO1234 (PART)\nG43.4 H1\n%\n"), Dialect::Fanuc);
        assert_eq!(
            detect(b"0  BEGIN PGM P1 MM\n1  L X+0 R0 FMAX\n"),
            Dialect::Conversational
        );
        assert_eq!(detect(b"BEGIN PGM P1 INCH\r"), Dialect::Conversational);
        // Without BEGIN PGM: a fragment as manuals and forums show it.
        assert_eq!(
            detect(b"; TNC\nL X+0 Y+0 Z+50 R0 FMAX M128 ; TCPM ON\nL X+50 A+30 C+45 F1000\n"),
            Dialect::Conversational
        );
        assert_eq!(detect(b"7 TOOL CALL 5 Z S12000\n"), Dialect::Conversational);
        assert_eq!(detect(b"N10 L100\nN20 G1 X1 ; cut\n"), Dialect::Sinumerik);
        assert_eq!(
            detect(b"N10 FUNCTION TCPM F TCP AXIS POS *\nN20 G01 X+1 *\n"),
            Dialect::Heidenhain
        );
        assert_eq!(detect(b"M128\nG1 X0 Y0\n"), Dialect::Heidenhain);
        assert_eq!(detect(b"G1 X0 M1280\n"), Dialect::Fanuc);
    }
}
