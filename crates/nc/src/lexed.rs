//! What one line says ([`Scan`]), before the modal state: every dialect's lexer fills one
//! (ISO lines in `interp.rs`, Heidenhain conversational lines in [`crate::conversational`]),
//! and the readings they share: M codes, Heidenhain `FUNCTION …`, and how every line's
//! reading ends.

use crate::block::Flags;
use crate::dialect::Dialect;
use crate::modal::{FeedMode, Motion};
use crate::tcpm::{ControllerCodes, Switch};
use crate::word::RotaryForm;
use std::ops::Range;

/// What one block says, collected before the modal state is updated.
#[derive(Debug, Default)]
pub(crate) struct Scan {
    pub(crate) axes: [Option<f64>; 6],
    /// The direction forms of A B C (`C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`).
    pub(crate) axes_form: [RotaryForm; 3],
    /// Axis (X Y Z A B C) and F words whose value is one macro variable (`F#100`,
    /// `X-#101`): its number and whether it is negated.
    pub(crate) vars: [Option<(u32, bool)>; 7],
    /// A macro variable assigned in the block (`#100=1200.`): its number and the value
    /// when it is a plain number.
    pub(crate) assign: Option<(u32, Option<f64>)>,
    /// Another assignment (`#<name>=…`, `#[#1]=…`, a second one): any variable may change.
    pub(crate) assign_other: bool,
    /// `breaks` was set by the expression words alone.
    pub(crate) expr_breaks: bool,
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
    /// `G92` (Fanuc, LinuxCNC): a shift of the axes it names — a datum shift when it names
    /// one polepatch follows (X Y Z A B C); `G92 E0` (an extruder reset) shifts none of them
    /// and changes nothing polepatch reads.
    pub(crate) g92: bool,
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
    /// The block may hold a flow statement ([`crate::flow`]): read it after lexing.
    pub(crate) maybe_flow: bool,
    /// Its flow statement.
    pub(crate) flow: Option<crate::flow::Stmt>,
    /// The block's number (`N…`), when it is a whole number.
    pub(crate) number: Option<u64>,
    /// A TCPM-on code that refers X Y Z to the centre of a ball (Heidenhain `M128`, `FUNCTION
    /// TCPM … REFPNT CENTER-CENTER`) rather than to the tool tip.
    pub(crate) tcpm_centre: bool,
    /// Heidenhain ISO `G73`, `G72` or `G28` (× 10): the frame code whose values the block
    /// gives.
    pub(crate) heidenhain_frame: Option<i64>,
    /// Frame transformations the block switches on (bits of [`crate::modal::transform`]).
    pub(crate) transform_on: u8,
    /// … and off.
    pub(crate) transform_off: u8,
    /// The first identifier the reader does not know that looks like a TCPM code (its
    /// bytes; [`crate::tcpm::lookalike`]).
    pub(crate) lookalike: Option<std::ops::Range<usize>>,
    /// Heidenhain `M126` (true) or `M127` (false): shortest-path traverse of rotary axes on
    /// or off.
    pub(crate) shortest_path: Option<bool>,
}

/// What M code `code` (× 10) says in `dialect` on a machine with `controller`'s codes (ISO and
/// conversational lines alike).
pub(crate) fn m_code(
    dialect: Dialect,
    controller: &ControllerCodes,
    code: Option<i64>,
    s: &mut Scan,
) {
    let sw = code.and_then(|c| controller.m(dialect, c));
    if let Some(sw) = sw {
        s.tcpm = Some(sw);
        // M128: the tool length refers to the ball's centre (Heidenhain's manuals).
        s.tcpm_centre = sw == Switch::On
            && code == Some(1280)
            && matches!(dialect, Dialect::Heidenhain | Dialect::Conversational);
    }
    match code {
        // Spindle and coolant.
        Some(30 | 40 | 50 | 70 | 80 | 90 | 130 | 140) => {}
        Some(60) => {
            s.flags.set(Flags::TOOL_CHANGE);
            s.breaks = true;
            // Fanuc-style controls run M6 as a macro ([`crate::flow`]).
            s.maybe_flow = matches!(dialect, Dialect::Fanuc | Dialect::Auto);
        }
        Some(20 | 300) => {
            s.flags.set(Flags::PROGRAM_END);
            s.breaks = true;
        }
        // Heidenhain M126/M127: rotary axes turn the shorter way to a plain absolute value,
        // or as written ([`crate::Modal::shortest_path`]). A change of how moves are read
        // ends runs.
        Some(c @ (1260 | 1270))
            if matches!(dialect, Dialect::Heidenhain | Dialect::Conversational) =>
        {
            s.shortest_path = Some(c == 1260);
            s.breaks = true;
        }
        // Subprogram call and return, cycle call (Heidenhain M99): other blocks run.
        Some(980 | 990 | 970 | 1980 | 170) => {
            s.unknown_after = true;
            s.breaks = true;
            s.maybe_flow = dialect != Dialect::Heidenhain;
        }
        // A TCPM switch (breaks through the state change).
        _ if sw.is_some() => {}
        // Stops, anything unknown.
        _ => s.breaks = true,
    }
}

/// What every dialect's reading of a line ends with: expressions flag the block; a flow
/// statement ends runs and leaves positions unknown; a lone CR inside the line, with text
/// after it, may be a line end to the control (hiding what follows in a comment, or showing
/// a comment's text as a block), so the block's effect on TCPM and positions is unknown.
pub(crate) fn after_lex(bytes: &[u8], span: &Range<usize>, s: &mut Scan) {
    if s.axes_expr != 0 || s.feed_expr {
        s.flags.set(Flags::NOT_ANALYSABLE);
        s.expr_breaks = !s.breaks;
        s.breaks = true;
    }
    if s.flow.is_some() {
        s.unknown_after = true;
        s.breaks = true;
        s.expr_breaks = false;
    }
    let line = &bytes[span.clone()];
    if has_cr(line)
        && let Some(cr) = line.iter().position(|&b| b == b'\r')
        && line[cr + 1..].iter().any(|b| !b.is_ascii_whitespace())
    {
        s.tcpm = Some(Switch::Unknown);
        s.flags.set(Flags::NOT_MODELLED);
        s.unknown_after = true;
        s.breaks = true;
    }
}

/// Whether `line` holds a CR, eight bytes at a time (every line is looked at).
fn has_cr(line: &[u8]) -> bool {
    const LO: u64 = 0x0101_0101_0101_0101;
    const HI: u64 = 0x8080_8080_8080_8080;
    let mut chunks = line.chunks_exact(8);
    let mut hit = 0u64;
    for c in &mut chunks {
        // A zero byte of `x` (a CR of the chunk) leaves its high bit set here.
        let x = u64::from_le_bytes(c.try_into().unwrap_or([0; 8])) ^ (LO * u64::from(b'\r'));
        hit |= x.wrapping_sub(LO) & !x & HI;
    }
    hit != 0 || chunks.remainder().contains(&b'\r')
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
        // `REFPNT TIP-TIP` (the default), `TIP-CENTER`: X Y Z are the tip; `CENTER-CENTER`:
        // the centre of the ball.
        let mut rest = words.clone();
        s.tcpm_centre = std::iter::once(second)
            .chain(&mut rest)
            .skip_while(|w| !w.eq_ignore_ascii_case(b"REFPNT"))
            .nth(1)
            .is_some_and(|w| w.len() >= 6 && w[..6].eq_ignore_ascii_case(b"CENTER"));
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

#[cfg(test)]
mod tests {
    /// The eight-bytes-at-a-time CR search finds every CR, and nothing else.
    #[test]
    fn cr_found_anywhere() {
        for len in 0..40 {
            let line = vec![b'X'; len];
            assert!(!super::has_cr(&line));
            for at in 0..len {
                let mut l = line.clone();
                l[at] = b'\r';
                assert!(super::has_cr(&l), "{len} {at}");
                // Bytes near CR in value (0x0c, 0x0e, 0x8d) are not CRs.
                for other in [0x0c, 0x0e, 0x8d, 0x00, 0xff] {
                    l[at] = other;
                    assert!(!super::has_cr(&l), "{len} {at} {other}");
                }
            }
        }
    }
}
