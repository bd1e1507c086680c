//! The program-flow statement of an ISO-style line (Fanuc, Haas, LinuxCNC, Sinumerik,
//! Heidenhain ISO): labels, calls, returns, jumps and structured statements, as the table in
//! [`crate::flow`]'s docs lists them ([`read_iso`]; conversational lines state theirs in
//! [`crate::conversational`]).

use crate::flow::{Key, Nest, Stmt};
use crate::tolerances::CODE_MATCH_TOL;

/// Sinumerik frame instructions (a shift, rotation, scaling or mirror of the programmable
/// frame).
pub(crate) fn is_sinumerik_frame(name: &[u8]) -> bool {
    [
        &b"TRANS"[..],
        b"ATRANS",
        b"CTRANS",
        b"ROT",
        b"AROT",
        b"CROT",
        b"RPL",
        b"SCALE",
        b"ASCALE",
        b"CSCALE",
        b"MIRROR",
        b"AMIRROR",
        b"CMIRROR",
        b"TOFRAME",
        b"TOROT",
        b"TOROTOF",
        b"PAROT",
        b"PAROTOF",
    ]
    .iter()
    .any(|n| name.eq_ignore_ascii_case(n))
}

/// A token of a line as the statement reader sees it.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    /// An address word with a number (`M98`, `P2000`, `O100`, `N10`).
    Word(u8, f64),
    /// An identifier, upper case (`GOTOF`, `CALL`, `SUB1`).
    Ident(String),
    /// Any other token's text (`:`, `,0`, `100`, `[#1 EQ 1]`, `<name>`).
    Other(Vec<u8>),
}

/// The tokens of a line (comments and block ends dropped).
fn toks(bytes: &[u8], span: std::ops::Range<usize>) -> Vec<Tok> {
    use crate::lexer::{Lexer, Token};
    let mut out = Vec::new();
    for t in Lexer::new(bytes, span).flatten() {
        match t {
            Token::Word { letter, value, .. } => out.push(Tok::Word(letter, value)),
            Token::Ident { name, span } => {
                out.push(Tok::Ident(
                    String::from_utf8_lossy(&bytes[name.clone()]).to_ascii_uppercase(),
                ));
                if span.end > name.end {
                    out.push(Tok::Other(bytes[name.end..span.end].to_vec()));
                }
            }
            Token::Assign { letter, span } => {
                out.push(Tok::Other(bytes[span.start..span.start + 1].to_vec()));
                let _ = letter;
                out.push(Tok::Other(bytes[span.start + 1..span.end].to_vec()));
            }
            Token::Other { span }
            | Token::Param { span }
            | Token::Percent { span }
            | Token::Indexed { span, .. } => out.push(Tok::Other(bytes[span].to_vec())),
            Token::Comment { .. } | Token::BlockEnd { .. } | Token::Slash { .. } => {}
        }
    }
    out
}

/// A whole number from a word value or token text (`100`, `2000.`), if it is one.
fn whole(v: f64) -> Option<u64> {
    (v >= 0.0 && v.fract() == 0.0 && v < 1e15).then_some(v as u64)
}

fn whole_text(t: &[u8]) -> Option<u64> {
    let t = t.strip_suffix(b".").unwrap_or(t);
    (!t.is_empty() && t.iter().all(u8::is_ascii_digit))
        .then(|| std::str::from_utf8(t).ok()?.parse().ok())
        .flatten()
}

/// Sinumerik identifiers that are statements, not subprogram calls (the predefined
/// instructions a CAM post writes). Any other identifier standing as a statement is read as
/// the call of a subprogram (outside the file).
const SINUMERIK_INSTRUCTIONS: &[&str] = &[
    "MSG",
    "DEF",
    "DEFINE",
    "PROC",
    "EXTERN",
    "STOPRE",
    "FNORM",
    "FLIN",
    "FCUB",
    "FCUT",
    "COMPOF",
    "COMPON",
    "COMPCURV",
    "COMPCAD",
    "COMPSURF",
    "SOFT",
    "SOFTA",
    "BRISK",
    "BRISKA",
    "DRIVE",
    "DRIVEA",
    "FFWON",
    "FFWOF",
    "CFC",
    "CFTCP",
    "CFIN",
    "CDON",
    "CDOF",
    "CDOF2",
    "CUT2D",
    "CUT2DF",
    "CUT3DC",
    "CUT3DF",
    "CUT3DFS",
    "CUT3DFF",
    "CUT3DCC",
    "CUT3DCCD",
    "ORIWKS",
    "ORIMKS",
    "ORIAXES",
    "ORIVECT",
    "ORIEULER",
    "ORIRPY",
    "ORIRPY2",
    "ORIVIRT1",
    "ORIVIRT2",
    "ORIAXPOS",
    "ORIPLANE",
    "ORICONCW",
    "ORICONCCW",
    "ORICONIO",
    "ORICONTO",
    "ORICURVE",
    "ORIPATH",
    "ORIPATHS",
    "ORIROTA",
    "ORIROTR",
    "ORIROTT",
    "ORIROTC",
    "ORISON",
    "ORISOF",
    "UPATH",
    "SPATH",
    "OFFN",
    "ACC",
    "VELOLIM",
    "JERKLIM",
    "SPOS",
    "SPOSA",
    "WAITM",
    "WAITS",
    "WAITE",
    "SETAL",
    "SAVE",
    "DISPLOF",
    "DISPLON",
    "PRLOC",
    "FGROUP",
    "FGREF",
    "FL",
    "OST",
    "TRAILON",
    "TRAILOF",
    "WORKPIECE",
    "TOFRAME",
    "TOROT",
    "TOROTOF",
    "TCARR",
    "PAROT",
    "PAROTOF",
    "TCOABS",
    "TCOFR",
    "FA",
    "FPR",
    "FPRAON",
    "FPRAOF",
    "POS",
    "POSA",
    "STOPFIFO",
    "STARTFIFO",
    "FIFOCTRL",
    "IPTRLOCK",
    "IPTRUNLOCK",
    "G_GROUP",
    "SETMS",
    "SPCON",
    "SPCOF",
    "SUPA",
    "MCALL",
    "DIAMON",
    "DIAMOF",
    "DIAM90",
    "CHR",
    "RND",
    "RNDM",
    "CHF",
    "ASPLINE",
    "BSPLINE",
    "CSPLINE",
    "POLY",
    "PO",
    "PL",
    "BAUTO",
    "BNAT",
    "BTAN",
    "EAUTO",
    "ENAT",
    "ETAN",
    "OMA1",
    "OMA2",
    "OMA3",
    "OMA4",
    "OMA5",
    "TLIFT",
    "WALIMON",
    "WALIMOF",
    "G_GROUP",
    "AX",
    "FXS",
    "FXST",
    "FXSW",
    "FOCON",
    "FOCOF",
    "LIMS",
    "CPRECON",
    "CPRECOF",
    "CTOL",
    "OTOL",
    "ATOL",
    "STOLF",
    "G642",
    "G643",
    "G644",
    "G645",
    "CYCLE832",
    "ANG",
    "AR",
    "AP",
    "RP",
    "CR",
    "TURN",
    "CIP",
    "CT",
    "IC",
    "AC",
    "DC",
    "ACP",
    "ACN",
    "CAC",
    "CIC",
    "CDC",
    "CACP",
    "CACN",
];

/// The flow statement of an ISO-style line (Fanuc, Haas, LinuxCNC, Sinumerik, Heidenhain
/// ISO), if it has one (module docs' table).
pub(crate) fn read_iso(
    dialect: crate::Dialect,
    bytes: &[u8],
    span: std::ops::Range<usize>,
) -> Option<Stmt> {
    use crate::Dialect;
    let t = toks(bytes, span);
    let line = Line::new(&t);
    match dialect {
        Dialect::Heidenhain => heidenhain(&line),
        Dialect::Sinumerik => sinumerik(&line),
        _ => linuxcnc_o_word(&line).or_else(|| fanuc(&line)),
    }
}

/// The tokens of a line, and the questions every dialect's reading asks of them.
struct Line<'a> {
    /// Every token.
    all: &'a [Tok],
    /// The tokens after the block number, if there is one.
    body: &'a [Tok],
}

impl<'a> Line<'a> {
    fn new(all: &'a [Tok]) -> Self {
        // Skip a block number.
        let body: &[Tok] = match all.first() {
            Some(Tok::Word(b'N', _)) => &all[1..],
            _ => all,
        };
        Line { all, body }
    }

    /// Whether the line starts with a block number.
    fn numbered(&self) -> bool {
        matches!(self.all.first(), Some(Tok::Word(b'N', _)))
    }

    /// The value of the first word of `letter`.
    fn word(&self, letter: u8) -> Option<f64> {
        self.body.iter().find_map(|x| match x {
            Tok::Word(c, v) if *c == letter => Some(*v),
            _ => None,
        })
    }

    /// Where the identifier `name` stands (also with a number right after it: `DO1`).
    fn ident_at(&self, name: &str) -> Option<usize> {
        self.body
            .iter()
            .position(|x| matches!(x, Tok::Ident(s) if s == name || (s.starts_with(name) && s[name.len()..].bytes().all(|b| b.is_ascii_digit()))))
    }

    /// Whether the line holds the M code `code`.
    fn m(&self, code: f64) -> bool {
        self.body
            .iter()
            .any(|x| matches!(x, Tok::Word(b'M', v) if (*v - code).abs() < CODE_MATCH_TOL))
    }

    /// Whether the line holds the G code `code`.
    fn g(&self, code: f64) -> bool {
        self.body
            .iter()
            .any(|x| matches!(x, Tok::Word(b'G', v) if (*v - code).abs() < CODE_MATCH_TOL))
    }

    /// A jump's target: a number (block), `N100`, or a label name, after the keyword at `i`
    /// whose name is `name_len` long.
    fn target_after(&self, i: usize, name_len: usize) -> Option<Key> {
        let body = self.body;
        if let Some(Tok::Ident(s)) = body.get(i)
            && s.len() > name_len
        {
            return whole_text(&s.as_bytes()[name_len..]).map(Key::Block);
        }
        match body.get(i + 1) {
            Some(Tok::Other(o)) => whole_text(o).map(Key::Block),
            Some(Tok::Word(b'N', v)) => whole(*v).map(Key::Block),
            Some(Tok::Ident(s)) => Some(Key::Label(s.clone())),
            _ => None,
        }
    }
}

/// Heidenhain ISO: `G98 L` labels and returns, `L1,0` calls, `%NAME` calls of other
/// programs.
fn heidenhain(line: &Line<'_>) -> Option<Stmt> {
    let body = line.body;
    // `G98 L1` label, `G98 L0` return; `L1,0` call (`L1,3`: three more times).
    // (`G99 T1 L+0 R+2` defines a tool: its L is a length.)
    if let Some(l) = line.word(b'L')
        && !line.g(99.0)
    {
        let n = whole(l)?;
        if line.g(98.0) {
            return Some(if n == 0 {
                Stmt::Return {
                    falls_through: true,
                }
            } else {
                Stmt::Label(Key::Label(n.to_string()))
            });
        }
        let rep = body.iter().find_map(|x| match x {
            Tok::Other(o) if o.first() == Some(&b',') => whole_text(&o[1..]),
            _ => None,
        })?;
        return Some(Stmt::Call {
            key: Key::Label(n.to_string()),
            repeats: rep > 0,
        });
    }
    // `N50 %NAME *` inside a numbered block: another program is called (the header
    // and end lines name the unit, `%NAME G71`; `% TEXT` with a blank is not a call).
    let called = line.numbered()
        && body.iter().any(|x| match x {
            Tok::Other(o) if o.first() == Some(&b'%') => {
                let up = o.to_ascii_uppercase();
                o.get(1)
                    .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
                    && !up.windows(3).any(|w| w == b"G70" || w == b"G71")
            }
            _ => false,
        });
    called.then_some(Stmt::External)
}

/// Sinumerik: labels, jumps, structured statements, returns, and calls (by keyword or by a
/// subprogram's name).
fn sinumerik(line: &Line<'_>) -> Option<Stmt> {
    let body = line.body;
    // `NAME:` label (a name followed by a colon at the start of the block).
    if let (Some(Tok::Ident(name)), Some(Tok::Other(o))) = (body.first(), body.get(1))
        && o.first() == Some(&b':')
    {
        return Some(Stmt::Label(Key::Label(name.clone())));
    }
    for name in ["GOTOF", "GOTOB", "GOTOC", "GOTO"] {
        if let Some(i) = body
            .iter()
            .position(|x| matches!(x, Tok::Ident(s) if s == name))
        {
            let cond = line.ident_at("IF").is_some() || name == "GOTOC";
            return Some(match line.target_after(i, name.len()) {
                Some(key) => Stmt::Jump { key, cond },
                None => Stmt::Opaque,
            });
        }
    }
    if let Some(stmt) = sinumerik_keyword(body) {
        return Some(stmt);
    }
    if line.m(17.0) {
        return Some(Stmt::Return {
            falls_through: false,
        });
    }
    if let Some(i) = line.ident_at("MCALL") {
        // A modal call of a standard cycle keeps TCPM; of anything else, every
        // later move calls it.
        return match body.get(i + 1) {
            Some(Tok::Ident(s)) if !s.starts_with("CYCLE") => Some(Stmt::Opaque),
            _ => None,
        };
    }
    if line.word(b'L').is_some()
        || body.iter().any(
            |x| matches!(x, Tok::Ident(s) if matches!(s.as_str(), "CALL" | "PCALL" | "EXTCALL")),
        )
    {
        return Some(Stmt::External);
    }
    sinumerik_named_call(body)
}

/// The Sinumerik structured statement or return the block's first identifier is, if it is
/// one.
fn sinumerik_keyword(body: &[Tok]) -> Option<Stmt> {
    let first_ident = body.iter().find_map(|x| match x {
        Tok::Ident(s) => Some(s.as_str()),
        _ => None,
    });
    match first_ident {
        Some("IF" | "WHILE" | "FOR" | "LOOP") => Some(Stmt::Nested {
            role: Nest::Open,
            tag: 0,
        }),
        Some("REPEAT") => {
            // `REPEAT` alone opens a loop; with labels it repeats a section.
            let args = body.iter().skip(1).any(|x| matches!(x, Tok::Ident(_)));
            Some(if args {
                Stmt::Opaque
            } else {
                Stmt::Nested {
                    role: Nest::Open,
                    tag: 0,
                }
            })
        }
        Some("REPEATB" | "CASE") => Some(Stmt::Opaque),
        Some("ELSE") => Some(Stmt::Nested {
            role: Nest::Middle,
            tag: 0,
        }),
        Some("ENDIF" | "ENDWHILE" | "ENDFOR" | "ENDLOOP" | "UNTIL") => Some(Stmt::Nested {
            role: Nest::Close,
            tag: 0,
        }),
        Some("RET") => Some(Stmt::Return {
            falls_through: false,
        }),
        _ => None,
    }
}

/// A Sinumerik subprogram called by its name: the first identifier of the block, not an
/// instruction and not assigned to.
fn sinumerik_named_call(body: &[Tok]) -> Option<Stmt> {
    let first = body.iter().position(|x| matches!(x, Tok::Ident(_)))?;
    let Tok::Ident(name) = &body[first] else {
        return None;
    };
    let assigned = matches!(body.get(first + 1), Some(Tok::Other(o)) if o.first() == Some(&b'='));
    let call = !assigned
        && !SINUMERIK_INSTRUCTIONS.contains(&name.as_str())
        && !name.starts_with("CYCLE")
        && !name.starts_with("TRA")
        && !is_sinumerik_frame(name.as_bytes());
    call.then_some(Stmt::External)
}

/// LinuxCNC o-words (`o<name> call`, `o100 sub`), if the line is one.
fn linuxcnc_o_word(line: &Line<'_>) -> Option<Stmt> {
    let body = line.body;
    if let Some(Tok::Other(o)) = body.first()
        && o.eq_ignore_ascii_case(b"o")
        && let (Some(Tok::Other(name)), Some(Tok::Ident(kw))) = (body.get(1), body.get(2))
    {
        return Some(o_word(
            &format!("O{}", String::from_utf8_lossy(name).to_ascii_uppercase()),
            kw,
        ));
    }
    if let (Some(Tok::Word(b'O', v)), Some(Tok::Ident(kw))) = (body.first(), body.get(1)) {
        return Some(o_word(&format!("O{v}"), kw));
    }
    None
}

/// Fanuc and Haas (and what LinuxCNC shares with them): program numbers, `GOTO`, loops,
/// calls and returns, the tool change.
fn fanuc(line: &Line<'_>) -> Option<Stmt> {
    // A Fanuc program number starts a (sub)program.
    if let (Some(Tok::Word(b'O', v)), None) = (line.all.first(), line.all.get(1)) {
        return whole(*v).map(|n| Stmt::Label(Key::Program(n)));
    }
    if let Some(i) = line.ident_at("GOTO") {
        let cond = line.ident_at("IF").is_some_and(|k| k < i);
        return Some(match line.target_after(i, 4) {
            Some(Key::Block(n)) => Stmt::Jump {
                key: Key::Block(n),
                cond,
            },
            _ => Stmt::Opaque,
        });
    }
    if let Some(stmt) = fanuc_loop(line) {
        return Some(stmt);
    }
    if let Some(stmt) = fanuc_call(line) {
        return Some(stmt);
    }
    if line.m(6.0) {
        return Some(Stmt::ToolChange);
    }
    None
}

/// Fanuc loops: `WHILE [...] DO 1` … `END 1` (also `DO1`, `END1`).
fn fanuc_loop(line: &Line<'_>) -> Option<Stmt> {
    let body = line.body;
    let loop_tag = |i: usize, name: &str| -> u32 {
        let n = match (&body[i], body.get(i + 1)) {
            (Tok::Ident(s), _) if s.len() > name.len() => whole_text(&s.as_bytes()[name.len()..]),
            (_, Some(Tok::Other(o))) => whole_text(o),
            _ => None,
        };
        n.and_then(|n| u32::try_from(n).ok()).unwrap_or(0)
    };
    if let Some(i) = line.ident_at("DO") {
        return Some(Stmt::Nested {
            role: Nest::Open,
            tag: loop_tag(i, "DO"),
        });
    }
    if let Some(i) = line.ident_at("END") {
        return Some(Stmt::Nested {
            role: Nest::Close,
            tag: loop_tag(i, "END"),
        });
    }
    None
}

/// Fanuc calls and returns: `M98`, `M97`, `M99`, `G65`, `G66`, `M198`.
fn fanuc_call(line: &Line<'_>) -> Option<Stmt> {
    let p = line.word(b'P').and_then(whole);
    let repeat = line.word(b'L').and_then(whole).is_some_and(|l| l > 1);
    if line.m(98.0) {
        return Some(match p {
            // `M98 P32000`: three times program 2000 (the old form, count first).
            Some(p) if p > 9999 => Stmt::Call {
                key: Key::Program(p % 10000),
                repeats: p / 10000 > 1 || repeat,
            },
            Some(p) => Stmt::Call {
                key: Key::Program(p),
                repeats: repeat,
            },
            None => Stmt::External,
        });
    }
    if line.m(97.0) {
        return Some(match p {
            Some(p) => Stmt::Call {
                key: Key::Block(p),
                repeats: repeat,
            },
            None => Stmt::Opaque,
        });
    }
    if line.m(99.0) {
        return Some(if p.is_some() {
            Stmt::Opaque
        } else {
            Stmt::Return {
                falls_through: false,
            }
        });
    }
    if line.g(65.0) {
        return Some(match p {
            Some(p) => Stmt::Call {
                key: Key::Program(p),
                repeats: repeat,
            },
            None => Stmt::External,
        });
    }
    if line.g(66.0) || line.g(66.1) {
        return Some(Stmt::Opaque);
    }
    if line.m(198.0) {
        return Some(Stmt::External);
    }
    None
}

/// A LinuxCNC o-word statement `oNAME keyword`.
fn o_word(name: &str, kw: &str) -> Stmt {
    let key = Key::Label(name.to_string());
    match kw {
        "SUB" => Stmt::SubStart(key),
        "ENDSUB" => Stmt::SubEnd(key),
        "CALL" => Stmt::Call {
            key,
            repeats: false,
        },
        "RETURN" => Stmt::Return {
            falls_through: false,
        },
        "IF" | "ELSEIF" | "ELSE" | "ENDIF" | "WHILE" | "ENDWHILE" | "DO" | "REPEAT"
        | "ENDREPEAT" | "BREAK" | "CONTINUE" => Stmt::Group(Key::Group(name.to_string())),
        _ => Stmt::Opaque,
    }
}
