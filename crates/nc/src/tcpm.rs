//! Which codes switch tool-centre-point management (TCPM) on and off: each dialect's
//! built-in codes, and the machine's own ([`ControllerCodes`], from the machine file's
//! `[controller]` section).
//!
//! With TCPM on, X Y Z are tool-tip positions in the part frame and the controller moves
//! the linear axes to follow the rotary ones: a patch may change rotary words alone. With
//! it off, X Y Z are machine-axis positions, and a rotary word changed alone would move
//! the part under the tool. So every code that ends or *replaces* TCPM counts as off — a
//! code the reader mistook for "on" would gouge, one mistaken for "off" only leaves a run
//! unpatched — and a switch in a block that block delete (`/`) may skip leaves the state
//! [`crate::Tcpm::Uncertain`], which every caller treats as off.
//!
//! The built-in table (docs/reading.md shows it with an example block each):
//!
//! | dialect | on | off (ends or replaces TCPM) |
//! |---|---|---|
//! | Heidenhain (ISO and conversational) | `M128`, `FUNCTION TCPM …` | `M129`, `FUNCTION RESET TCPM`, `M2`, `M30`, `END PGM` |
//! | Sinumerik | `TRAORI` | `TRAFOOF`, `TRANSMIT`, `TRACYL`, `TRAANG`, `M2`, `M30` |
//! | Fanuc, Haas, LinuxCNC and other ISO | `G43.4`, `G43.5`, `G234` (Haas TCPC) | `G49`, `G43`, `G44` (group 8 replaces G43.4), `G43.1`, `G43.7`, `M2`, `M30` |
//! | MillPlus | `G141` (3D tool correction with the tool orientation) | `G40`, `M2`, `M30` |
//!
//! Codes whose effect the reader does not know leave the state [`crate::Tcpm::Unknown`]
//! (never patched) until a code of the table settles it: Sinumerik `TRACON`, Fanuc
//! `G43.8`/`G43.9`. So do calls, labels and jumps the file does not settle
//! ([`crate::flow`]).
//!
//! A machine adds its own codes (`tcpm_on = ["M428"]`, `tcpm_off = ["M429", "M430"]` for
//! LinuxCNC's switchable kinematics), or says its kinematics are always TCP
//! (`tcpm_always = true`: every block is read with TCPM on and no code turns it off).

use crate::dialect::Dialect;
use crate::modal::{Modal, Tcpm};
use crate::tolerances::CODE10_ROUND_TOL;

/// A code that can switch TCPM: a G or M code (number × 10: `G43.4` → 434) or an
/// identifier (`TRAORI`, upper case).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Code {
    /// `G` code, number × 10.
    G(i64),
    /// `M` code, number × 10.
    M(i64),
    /// An identifier such as `TRAORI` (upper case).
    Ident(String),
}

impl Code {
    /// Read a code as a machine file writes it: `"M428"`, `"G43.4"`, `"TRAORI"`.
    pub fn parse(text: &str) -> Result<Code, String> {
        let t = text.trim();
        let bad = || {
            format!(
                "TCPM code '{text}' is not a G or M code (`G43.4`, `M428`) or an identifier \
                 (`TRAORI`)"
            )
        };
        let first = t.chars().next().ok_or_else(bad)?;
        let rest = &t[first.len_utf8()..];
        let g_or_m = matches!(first, 'G' | 'g' | 'M' | 'm');
        if g_or_m && !rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit() || b == b'.') {
            let v = crate::lexer::parse_number(rest.as_bytes()).ok_or_else(bad)?;
            let code = code10(v).ok_or_else(bad)?;
            return Ok(if first.eq_ignore_ascii_case(&'G') {
                Code::G(code)
            } else {
                Code::M(code)
            });
        }
        // An identifier: two or more letters, digits or `_`, starting with letters (not a
        // G or M code with a bad number).
        let starts_as_code = g_or_m && !rest.starts_with(|c: char| c.is_ascii_alphabetic());
        if t.len() >= 2
            && t.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
            && first.is_ascii_alphabetic()
            && !starts_as_code
        {
            return Ok(Code::Ident(t.to_ascii_uppercase()));
        }
        Err(bad())
    }
}

impl std::fmt::Display for Code {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let num = |c: i64| {
            if c % 10 == 0 {
                format!("{}", c / 10)
            } else {
                format!("{}.{}", c / 10, c % 10)
            }
        };
        match self {
            Code::G(c) => write!(f, "G{}", num(*c)),
            Code::M(c) => write!(f, "M{}", num(*c)),
            Code::Ident(s) => f.write_str(s),
        }
    }
}

/// `G`/`M` code number times ten (`G43.4` → 434, `M128` → 1280), if it is one.
pub(crate) fn code10(v: f64) -> Option<i64> {
    let t = v * 10.0;
    let r = t.round();
    ((t - r).abs() < CODE10_ROUND_TOL && (0.0..1e9).contains(&r)).then_some(r as i64)
}

/// A machine's own TCPM codes, added to its dialect's built-in ones (module docs).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ControllerCodes {
    /// Codes that switch TCPM on. Default none.
    pub on: Vec<Code>,
    /// Codes that end it. Default none.
    pub off: Vec<Code>,
    /// The machine's kinematics are always TCP: X Y Z are always part-frame tool-tip
    /// positions. Default false.
    pub always: bool,
    /// Letters of auxiliary axes (an extruder on `A` of a B-C printer): their words are
    /// carried through like `E`, never read as an axis polepatch follows. Default none.
    pub auxiliary: Vec<u8>,
}

/// What a code does to TCPM.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Switch {
    On,
    Off,
    /// A code whose effect on TCPM the reader does not know (`TRACON` after `TRAORI`,
    /// `G43.8`): the state after it is [`crate::Tcpm::Unknown`] until a code settles it.
    Unknown,
}

impl Switch {
    /// The state the switch sets.
    pub(crate) fn state(self) -> Tcpm {
        match self {
            Switch::On => Tcpm::On,
            Switch::Off => Tcpm::Off,
            Switch::Unknown => Tcpm::Unknown,
        }
    }
}

impl ControllerCodes {
    fn find(&self, code: &Code) -> Option<Switch> {
        if self.on.contains(code) {
            Some(Switch::On)
        } else if self.off.contains(code) {
            Some(Switch::Off)
        } else {
            None
        }
    }

    /// What G code `g` (× 10) does in `dialect`: the machine's codes first, then the table.
    pub(crate) fn g(&self, dialect: Dialect, g: i64) -> Option<Switch> {
        if let Some(s) = self.find(&Code::G(g)) {
            return Some(s);
        }
        match dialect {
            Dialect::Fanuc | Dialect::Auto => match g {
                434 | 435 | 2340 => Some(Switch::On),
                490 | 430 | 440 | 431 | 437 => Some(Switch::Off),
                // Tool-length compensation forms whose TCPM meaning differs by controller
                // (Fanuc's cutting-point and tool-centre-point variants): not guessed.
                438 | 439 => Some(Switch::Unknown),
                _ => None,
            },
            // MillPlus: G141 3D tool correction with the tool orientation; G40 ends it.
            Dialect::MillPlus => match g {
                1410 => Some(Switch::On),
                400 => Some(Switch::Off),
                _ => None,
            },
            Dialect::Sinumerik | Dialect::Heidenhain | Dialect::Conversational => None,
        }
    }

    /// What M code `m` (× 10) does in `dialect`.
    pub(crate) fn m(&self, dialect: Dialect, m: i64) -> Option<Switch> {
        if let Some(s) = self.find(&Code::M(m)) {
            return Some(s);
        }
        match (dialect, m) {
            (_, 20 | 300) => Some(Switch::Off),
            (Dialect::Heidenhain | Dialect::Conversational, 1280) => Some(Switch::On),
            (Dialect::Heidenhain | Dialect::Conversational, 1290) => Some(Switch::Off),
            _ => None,
        }
    }

    /// What identifier `name` does in `dialect` (any case).
    pub(crate) fn ident(&self, dialect: Dialect, name: &[u8]) -> Option<Switch> {
        if !self.on.is_empty() || !self.off.is_empty() {
            let upper = String::from_utf8_lossy(name).to_ascii_uppercase();
            if let Some(s) = self.find(&Code::Ident(upper)) {
                return Some(s);
            }
        }
        let is = |n: &[u8]| name.eq_ignore_ascii_case(n);
        match dialect {
            Dialect::Sinumerik => {
                if is(b"TRAORI") {
                    Some(Switch::On)
                } else if is(b"TRAFOOF") || is(b"TRANSMIT") || is(b"TRACYL") || is(b"TRAANG") {
                    Some(Switch::Off)
                } else if is(b"TRACON") {
                    // A cascade of transformations: whether TRAORI's tool-tip frame holds
                    // depends on the cascade, which the reader does not follow.
                    Some(Switch::Unknown)
                } else {
                    None
                }
            }
            _ => None,
        }
    }
}

/// The TCPM codes that are identifiers, of every dialect (module docs' table), and `TCPM`
/// itself (Heidenhain's `FUNCTION TCPM`, and what posts call it in comments and macros).
pub const TCPM_IDENTIFIERS: &[&str] = &[
    "TRAORI", "TRAFOOF", "TRANSMIT", "TRACYL", "TRAANG", "TRACON", "TCPM",
];

/// The TCPM code identifier `name` looks like without being it — a post's typo such as
/// `TRAOOF` for `TRAFOOF` —, if any: an identifier the reader does not know, of four or more
/// characters, with the code's first letter, within an edit distance (insertions,
/// deletions, substitutions, swaps of neighbours) of 1 of a code of up to six characters
/// and of 2 of a longer one (`TRAFOOF`, `TRANSMIT`). The codes are [`TCPM_IDENTIFIERS`] and the machine's own
/// identifiers; the nearest is named. The reader does not read such a word as a switch (a controller would reject
/// it, or run something else); the report warns with its line and column, since a program
/// that was meant to switch TCPM there is read with the state it had.
pub fn lookalike(name: &[u8], controller: &ControllerCodes) -> Option<String> {
    if name.len() < 4 {
        return None;
    }
    let upper = name.to_ascii_uppercase();
    let own = controller
        .on
        .iter()
        .chain(&controller.off)
        .filter_map(|c| match c {
            Code::Ident(s) => Some(s.as_str()),
            _ => None,
        });
    TCPM_IDENTIFIERS
        .iter()
        .copied()
        .chain(own)
        .filter(|code| code.as_bytes()[0] == upper[0])
        .map(|code| (edit_distance(&upper, code.as_bytes()), code))
        .filter(|&(d, code)| d >= 1 && d <= if code.len() <= 6 { 1 } else { 2 })
        .min_by_key(|&(d, _)| d)
        .map(|(_, code)| code.to_string())
}

/// The edit distance of `a` and `b` with swaps of neighbouring characters (optimal string
/// alignment): the fewest insertions, deletions, substitutions and swaps from one to the
/// other.
fn edit_distance(a: &[u8], b: &[u8]) -> usize {
    let (n, m) = (a.len(), b.len());
    // Rows i − 2, i − 1 and i of the table.
    let mut rows = [vec![0; m + 1], (0..=m).collect::<Vec<_>>(), vec![0; m + 1]];
    for i in 1..=n {
        rows[2][0] = i;
        for j in 1..=m {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut d = (rows[1][j] + 1)
                .min(rows[2][j - 1] + 1)
                .min(rows[1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d = d.min(rows[0][j - 2] + 1);
            }
            rows[2][j] = d;
        }
        rows.rotate_left(1);
    }
    rows[1][m]
}

/// The state before a program's first block on a machine with `controller`'s codes (TCPM
/// on from the start where the kinematics are always TCP).
pub fn initial(controller: &ControllerCodes) -> Modal {
    Modal {
        tcpm: if controller.always {
            Tcpm::On
        } else {
            Tcpm::Off
        },
        ..Modal::default()
    }
}

/// How to read a program: its dialect, the machine's TCPM codes, how the file's program
/// flow settles TCPM, and the units of a program that does not state them.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// Dialect (default: detected).
    pub dialect: Dialect,
    /// The machine's own TCPM codes (default: none beyond the dialect's).
    pub controller: ControllerCodes,
    /// How program flow settles TCPM (default `None`: not known yet; a read that finds
    /// flow returns the plan in [`crate::Settled::Again`]).
    pub flow: Option<std::sync::Arc<crate::flow::FlowPlan>>,
    /// Read lengths (and feeds) in inches until the program states its units (G20/G21,
    /// G70/G71, G700/G710, `%NAME G71`, `BEGIN PGM … MM|INCH`): what a controller set to
    /// inches does with a program that states none. Default false: mm.
    pub inch: bool,
    /// The rotary axes A, B, C (in that order) that turn without end on the machine (no
    /// travel range): a controller may take the shorter way to a plain absolute value on
    /// them (Haas and Fanuc rollover, a Sinumerik modulo axis), so a feed move that turns one
    /// by more than half a turn is read as a wrap ([`crate::Flags::ROTARY_WRAP`]). Not in a
    /// Heidenhain program (ISO or conversational): that control turns as written unless
    /// `M126` is active, which the program says. Default: none (every rotary value read as
    /// written).
    pub endless: [bool; 3],
}

impl ReadOptions {
    /// Read as `dialect` with the built-in codes only, in mm.
    pub fn dialect(dialect: Dialect) -> Self {
        ReadOptions {
            dialect,
            controller: ControllerCodes::default(),
            flow: None,
            inch: false,
            endless: [false; 3],
        }
    }

    /// The modal state at the start of a program read this way.
    pub fn initial(&self) -> Modal {
        Modal {
            inch: self.inch,
            ..initial(&self.controller)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_parse_and_print() {
        assert_eq!(Code::parse("M428"), Ok(Code::M(4280)));
        assert_eq!(Code::parse("g43.4"), Ok(Code::G(434)));
        assert_eq!(Code::parse(" TRAORI "), Ok(Code::Ident("TRAORI".into())));
        assert_eq!(Code::parse("traori"), Ok(Code::Ident("TRAORI".into())));
        for bad in ["", "M", "G1.2.3", "M-5", "X 1", "43.4", "M4e2"] {
            assert!(Code::parse(bad).is_err(), "{bad}");
        }
        for t in ["M428", "G43.4", "G234", "TRAORI"] {
            assert_eq!(Code::parse(t).unwrap().to_string(), t);
        }
    }

    #[test]
    fn edit_distances() {
        assert_eq!(edit_distance(b"TRAOOF", b"TRAFOOF"), 1);
        assert_eq!(edit_distance(b"TRAFOOF", b"TRAFOOF"), 0);
        assert_eq!(edit_distance(b"TARORI", b"TRAORI"), 1, "a swap");
        assert_eq!(edit_distance(b"TRAOR", b"TRAORI"), 1);
        assert_eq!(edit_distance(b"TRAFO", b"TRAFOOF"), 2);
        assert_eq!(edit_distance(b"", b"TCPM"), 4);
        assert_eq!(edit_distance(b"CYCLE800", b"TRAORI"), 8);
    }

    /// Issue 42 item 5: a word that looks like a TCPM code is found; the codes themselves,
    /// short words and the identifiers real programs write are not.
    #[test]
    fn tcpm_lookalikes() {
        let c = ControllerCodes::default();
        for (typo, code) in [
            ("TRAOOF", "TRAFOOF"),
            ("traoof", "TRAFOOF"),
            ("TRAFOF", "TRAFOOF"),
            ("TRAFFOOF", "TRAFOOF"),
            ("TARORI", "TRAORI"),
            ("TRAOR", "TRAORI"),
            ("TRAORII", "TRAORI"),
            ("TCMP", "TCPM"),
            ("TRACYLL", "TRACYL"),
        ] {
            assert_eq!(
                lookalike(typo.as_bytes(), &c).as_deref(),
                Some(code),
                "{typo}"
            );
        }
        for fine in [
            "TRAORI", "TRAFOOF", "Traori", "TRACON", "TCPM", "TRA", "MSG", "SOFT", "FFWON",
            "ORIWKS", "ORIAXES", "CYCLE800", "CYCLE832", "SUPA", "TRANS", "ATRANS", "CTRANS",
            "TOFRAME", "TOROT", "GOTOF", "ENDIF", "DIAMOF", "COMPCAD", "BRISK", "G64", "TEMP",
            "TOOL", "TCP", "STOPRE", "WHEN",
        ] {
            assert_eq!(lookalike(fine.as_bytes(), &c), None, "{fine}");
        }
        // The machine's own identifiers count too.
        let own = ControllerCodes {
            on: vec![Code::parse("RTCPON").unwrap()],
            off: vec![Code::parse("RTCPOFF").unwrap()],
            always: false,
            auxiliary: Vec::new(),
        };
        assert_eq!(lookalike(b"RTCP_OFF", &own).as_deref(), Some("RTCPOFF"));
        assert_eq!(lookalike(b"RTCP_OFF", &c), None);
    }

    #[test]
    fn the_table() {
        let c = ControllerCodes::default();
        assert_eq!(c.g(Dialect::Fanuc, 434), Some(Switch::On));
        assert_eq!(
            c.g(Dialect::Fanuc, 430),
            Some(Switch::Off),
            "G43 replaces G43.4"
        );
        assert_eq!(c.g(Dialect::Fanuc, 440), Some(Switch::Off));
        assert_eq!(
            c.g(Dialect::Heidenhain, 430),
            None,
            "G43 is paraxial compensation in Heidenhain ISO"
        );
        assert_eq!(c.m(Dialect::Fanuc, 1280), None, "M128 is Heidenhain's");
        assert_eq!(c.m(Dialect::Heidenhain, 1280), Some(Switch::On));
        assert_eq!(c.m(Dialect::Sinumerik, 300), Some(Switch::Off));
        assert_eq!(c.ident(Dialect::Sinumerik, b"Tracyl"), Some(Switch::Off));
        assert_eq!(c.ident(Dialect::Fanuc, b"TRAORI"), None);
        let own = ControllerCodes {
            on: vec![Code::parse("M428").unwrap()],
            off: vec![Code::parse("M429").unwrap(), Code::parse("G43.4").unwrap()],
            always: false,
            auxiliary: Vec::new(),
        };
        assert_eq!(own.m(Dialect::Fanuc, 4280), Some(Switch::On));
        assert_eq!(own.m(Dialect::Fanuc, 4290), Some(Switch::Off));
        assert_eq!(
            own.g(Dialect::Fanuc, 434),
            Some(Switch::Off),
            "the machine's own first"
        );
    }
}
