//! What a program's text says of its tool: the descriptions CAM systems and controllers
//! write (comments, Heidenhain `TOOL DEF` and ISO `G99`), the tool calls (`T`/`M6`,
//! `T="NAME"`, `TOOL CALL`, Heidenhain ISO `T5 G17`) and their length deltas (`DL`), read
//! block by block in file order by one [`Tracker`].
//!
//! This module reads text only: a description is a diameter, a corner radius where stated
//! and the kind its text names ([`Described`], in mm), with the line that says it. What
//! cutter that is — whether the numbers make a ball, a bull-nose or no cutter at all, and
//! whether the text agrees — is the tool model's judgement (`polepatch::tool`), as is which
//! point of the tool X Y Z state.
//!
//! Forms read (each as real posts write it; the fixtures under `fixtures/tools/`):
//!
//! | form | example | cutter | names its tool by |
//! |---|---|---|---|
//! | Heidenhain `TOOL DEF` | `TOOL DEF 5 L+0 R+5 R2+5` (then `TOOL CALL 5 Z`); without `R2` a flat end mill | R radius, R2 corner radius | number or name |
//! | Heidenhain ISO `G99` | `N10 G99 T5 L+0 R+5 R2+5 *` (then `T5 G17`) | the same | number |
//! | Fusion / HSM / Inventor CAM | `(T1 D=10. CR=5. - ZMIN=-5. - ball end mill)`, `;  #31 D=10 CR=5 - ZMIN=… - ball end mill` | D, CR, the type text | number |
//! | `D=` and a type text (CUQ) | `N2(Ball cutter D=10.00)` (then `N4T006M06`) | D, the type text | — |
//! | hyperMILL | `* - TOOL: T313 \| BALL_D10 / DM=10 CR=5 TL=90` or `* - T313 \| …` before `TOOL CALL`; its `TOOLLIST`: `; T1554 \| … / DM=20 CR=2 TL=106` | DM, CR | its own T number and name (the call may use neither) |
//! | Siemens NX tool list | `(TOOL-NO. TOOL-NAME DIAMETER OFFSET)` … `(   3   BALL_MILL   0.236   0  )` | a name with `BALL`: a ball of that diameter | number |
//! | Mastercam | `( TOOL - 12 3/16 BALL ENDMILL DIA. OFF. - 12 LEN. - 12 DIA. - .1875 )`, `( T1 \| 1/4 BALL ENDMILL \| H1 \| D1 \| TOOL DIA. - .25 )` (`D1` the offset register) | DIA., `BALL`/`FLAT`/`ENDMILL` in the name | number |
//! | PowerMill | `( NO. \| ID \| DIA.\| TIP RAD\|LENGTH)` … `(    1\|name\| 4.0 \|  0.0 \| 75.0 )` | DIA., TIP RAD | number |
//! | `TOOL: Tn = d dia.` (LinuxCNC's boat demos) | `( TOOL: T1 = 10.0 dia. ENDMILLM1000:REG )` | dia., the type text | number |
//!
//! Forms seen in real programs and not read (they state no diameter, or only inside a
//! name): NX's `;TOOL NO. :8` / `;TOOL TYPE :Milling Tool-5 Parameters`, `( *** TOOL CHANGE:
//! T03: BALL_MILL *** )`, `; TOOL NAME PLANFRAS_D80`, `(Current Tool: 8)`, `T02 M06 (BALL
//! 6MM)`, FreeCAD's `(TC: 5mm Endmill)`. Where a call's tool stays unknown, the note names
//! such a comment before it (`… line 4: (BALL 6MM) is no form polepatch reads`).
//!
//! **Which description is a call's**: the latest that gives the number or name the call
//! uses; else, of the descriptions that give no number the call could contradict (none, or
//! the CAM's own: hyperMILL's), the one in the group just before the call (descriptions and
//! comments with no other block between them and the call) — several there is a list, not
//! the call's, and the tool stays unknown with the list named. A description that gives
//! another number is never the call's (`(T2 D=12 …)` before `T1 M6`).
//!
//! **Kinds a type text names**: `ball`; `bull`, `torus`, `radius` a bull-nose; `flat`,
//! `end mill` a flat end mill; a drill, chamfer, probe, face mill, lollipop, tapered, spot,
//! thread mill or tap is [`Cutter::Other`].
//!
//! **Units**: a description's values are in the program's unit at the line it is written.
//! One written before the program first states its unit (`G20`/`G21`, `G70`/`G71`, a
//! `%NAME G71` header, `BEGIN PGM … MM`) is in the unit the program then states: posts write
//! their tool list in the header, before the unit code (Fusion's `(T1 D=0.5 …)` comes before
//! `G20`), in the unit of the program that follows. A program that never states one is in mm.

use crate::{Block, Dialect, Flags, Modal, Word};
use std::collections::HashMap;

/// A tool's number or name as the program calls it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum ToolId {
    /// `T5`, `TOOL CALL 5`.
    Number(u64),
    /// `T="BALL6"`, `TOOL CALL "BALL6"` (upper case).
    Name(String),
}

impl std::fmt::Display for ToolId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ToolId::Number(n) => write!(f, "T{n}"),
            ToolId::Name(s) => write!(f, "\"{s}\""),
        }
    }
}

/// The kind of end mill a description's text names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CutterKind {
    /// `BALL`.
    Ball,
    /// `FLAT`, `END MILL`, `ENDMILL`.
    Flat,
    /// `BULL`, `TORUS`, `RADIUS`, `TIP_RADIUSED`.
    Bull,
}

/// What a description says of its cutter, in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cutter {
    /// An end mill.
    Mill {
        /// Diameter, mm.
        diameter_mm: f64,
        /// Corner radius, mm, where stated (`TOOL DEF` without `R2`: 0).
        corner_radius_mm: Option<f64>,
        /// The kind its text names, where it names one.
        named: Option<CutterKind>,
    },
    /// A cutter that is no end mill: its text names a drill, a chamfer mill, ….
    Other,
}

/// One description of a tool, as the program's text gives it.
#[derive(Debug, Clone, PartialEq)]
pub struct Described {
    /// What it says.
    pub cutter: Cutter,
    /// Where: `line N: text` (the text trimmed to 80 characters).
    pub source: String,
}

/// What the program says of the tool in use at a point of it ([`Tracker::found`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ToolSaid {
    /// The tool the last tool change called, if it named one.
    pub id: Option<ToolId>,
    /// The description that change takes (module docs).
    pub described: Option<Described>,
    /// Why no description was taken where the program has something like one: a list
    /// before the call that does not name it, a comment in no form read, a call by a
    /// parameter.
    pub note: Option<String>,
    /// The tool call's length delta (Heidenhain `DL`), mm, and where (`line 3, col 28:
    /// DL-5`); NaN where the call gives it by a parameter; `None` where the call gives none.
    pub delta_length: Option<(f64, String)>,
}

#[derive(Debug, Clone)]
struct Desc {
    /// What it says, in the program's unit.
    shape: Shape,
    /// mm per unit of its values; `None` while the program has stated no unit.
    unit: Option<f64>,
    /// `line N: text`.
    source: String,
}

/// What a description says of its cutter, in the program's unit.
#[derive(Debug, Clone, Copy)]
enum Shape {
    /// An end mill: diameter, corner radius (where stated), the kind its text names.
    Mill {
        d: f64,
        cr: Option<f64>,
        named: Option<CutterKind>,
    },
    /// A cutter polepatch does not model (its text names a drill, a chamfer mill, …).
    Other,
}

impl Desc {
    /// What it says, in mm; values of a description written before the program stated
    /// its unit are in `unit_now` (mm per unit).
    fn in_mm(&self, unit_now: f64) -> Described {
        let u = self.unit.unwrap_or(unit_now);
        let cutter = match self.shape {
            Shape::Other => Cutter::Other,
            Shape::Mill { d, cr, named } => Cutter::Mill {
                diameter_mm: d * u,
                corner_radius_mm: cr.map(|r| r * u),
                named,
            },
        };
        Described {
            cutter,
            source: self.source.clone(),
        }
    }

    fn line(&self) -> &str {
        self.source.split(':').next().unwrap_or("")
    }
}

/// Reads the tool in use from a program, block by block in file order (module docs).
#[derive(Debug, Default, Clone)]
pub struct Tracker {
    /// Every description read, in file order.
    descs: Vec<Desc>,
    /// The latest description giving each number or name.
    by_id: HashMap<ToolId, usize>,
    /// The current group's descriptions that give no number a call could contradict
    /// (module docs).
    group: Vec<usize>,
    /// The current group's last comment that looks like a tool's and that no form reads.
    unread: Option<String>,
    /// The tool a `T` word selected, for the next `M6`.
    selected: Option<ToolId>,
    /// An `M6` was seen (before it, a bare `T` is the change: Grbl-style files).
    any_m6: bool,
    /// The tool in use.
    active: Option<ToolId>,
    /// The description its change took, or why none.
    taken: Option<usize>,
    note: Option<String>,
    /// The tool call's length delta: value in the program's unit, mm per unit (`None`
    /// while no unit is stated), where.
    delta: Option<(f64, Option<f64>, String)>,
    /// Inside an NX tool list (its header seen): rows are `( n NAME diameter offset )`.
    nx_table: bool,
    /// Inside a PowerMill tool table (its header seen).
    powermill_table: bool,
    /// The program is in inches now.
    inch: bool,
    /// The program has stated its unit.
    unit_stated: bool,
    /// Counts the changes of what [`Tracker::found`] gives (a caller keeps one copy per
    /// revision, not one per run).
    revision: u64,
}

/// `line N: text` for a source, the text trimmed to 80 characters.
fn source(line: usize, text: &str) -> String {
    let t: String = text.trim().chars().take(80).collect();
    format!("line {line}: {t}")
}

/// The number after `key` (`D=10.`, `CR=5`, `DM=2`) in upper-case `text`.
fn value_after(text: &str, key: &str) -> Option<f64> {
    let mut from = 0;
    while let Some(k) = text[from..].find(key) {
        let at = from + k;
        // A key starts a word (`CR=` not inside `DCR=`).
        let starts = at == 0 || !text.as_bytes()[at - 1].is_ascii_alphanumeric();
        let rest = &text[at + key.len()..];
        let num: String = rest
            .trim_start()
            .chars()
            .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+'))
            .collect();
        if starts && let Ok(v) = num.parse::<f64>() {
            return Some(v);
        }
        from = at + key.len();
    }
    None
}

/// A kind from a type text: `Some(Some(kind))` where it names one, `Some(None)` where it
/// names a tool that is no mill polepatch models, `None` where it says nothing.
fn kind_from_text(text: &str) -> Option<Option<CutterKind>> {
    let t = text.to_ascii_uppercase();
    let has = |w: &str| t.contains(w);
    if has("BALL") {
        Some(Some(CutterKind::Ball))
    } else if has("BULL") || has("TORUS") || has("RADIUS") || has("TIP_RADIUSED") {
        Some(Some(CutterKind::Bull))
    } else if has("DRILL")
        || has("CHAMFER")
        || has("PROBE")
        || has("FACE")
        || has("LOLLIPOP")
        || has("TAPER")
        || has("SPOT")
        || has("THREAD")
        || has("TAP")
    {
        Some(None)
    } else if has("FLAT") || has("END MILL") || has("ENDMILL") {
        Some(Some(CutterKind::Flat))
    } else {
        None
    }
}

/// A description's shape from a diameter, a corner radius (where stated) and a type text.
fn shape(d: f64, cr: Option<f64>, text: Option<&str>) -> Shape {
    match text.and_then(kind_from_text) {
        Some(None) => Shape::Other,
        named => Shape::Mill {
            d,
            cr,
            named: named.flatten(),
        },
    }
}

/// A description read from a line: what it names its tool by, and its shape.
struct Read {
    /// The numbers or names it gives its tool.
    ids: Vec<ToolId>,
    /// Its number is the program's tool number (`TOOL DEF 5`, Fusion's `T5`, a list's
    /// row): a call of another number is another tool's. False where the id is the CAM
    /// system's own (hyperMILL's `T1554880489`) or it gives none.
    strict: bool,
    shape: Shape,
}

/// What a block does to the tool in use.
enum Call {
    /// No tool change.
    None,
    /// A change to the tool it names (`None`: it names none, or by a parameter, `note`).
    Change(Option<ToolId>, Option<String>),
}

impl Tracker {
    /// Changes whenever [`Tracker::found`] may give something else.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// mm per unit of the program's values now.
    fn unit(&self) -> f64 {
        if self.inch { 25.4 } else { 1.0 }
    }

    /// What the program says of its tool at this point (the next run's, when called
    /// between runs).
    pub fn found(&self) -> ToolSaid {
        let unit = self.unit();
        // A description naming the tool in use, written after its change, is its too.
        let named = self
            .active
            .as_ref()
            .and_then(|id| self.by_id.get(id).copied());
        let k = match (self.taken, named) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        };
        ToolSaid {
            id: self.active.clone(),
            described: k.map(|k| self.descs[k].in_mm(unit)),
            note: if k.is_none() { self.note.clone() } else { None },
            delta_length: self
                .delta
                .as_ref()
                .map(|(v, u, src)| (v * u.unwrap_or(unit), src.clone())),
        }
    }

    /// The tool change to `id`: the description it takes (module docs).
    fn change_to(&mut self, id: Option<ToolId>, note: Option<String>) {
        let by = id.as_ref().and_then(|i| self.by_id.get(i).copied());
        let (taken, why) = match (by, self.group.as_slice()) {
            (Some(k), _) => (Some(k), None),
            (None, [k]) => (Some(*k), None),
            (None, []) => (
                None,
                note.or_else(|| {
                    self.unread
                        .as_ref()
                        .map(|u| format!("{u} is no form polepatch reads"))
                }),
            ),
            (None, many) => {
                let lines: Vec<&str> = many.iter().map(|&k| self.descs[k].line()).collect();
                (
                    None,
                    Some(format!(
                        "{} describe tools just before the call, none by the number or name it \
                         calls: a list, not the call's",
                        lines.join(", ")
                    )),
                )
            }
        };
        self.active = id;
        self.taken = taken;
        self.note = why;
        self.end_group();
        self.revision += 1;
    }

    /// A block that is neither a comment nor a description ends the group before it.
    fn end_group(&mut self) {
        self.group.clear();
        self.unread = None;
    }

    fn define(&mut self, line: usize, raw: &str, read: Read) {
        let k = self.descs.len();
        for id in &read.ids {
            self.by_id.insert(id.clone(), k);
        }
        if !read.strict {
            self.group.push(k);
        }
        self.descs.push(Desc {
            shape: read.shape,
            unit: self.unit_stated.then(|| self.unit()),
            source: source(line, raw),
        });
        self.revision += 1;
    }

    /// Take the block (`text`: its bytes; `words` its words; `state` the modal state
    /// after it).
    pub fn block(
        &mut self,
        dialect: Dialect,
        block: &Block,
        text: &[u8],
        words: &[Word],
        state: &Modal,
    ) {
        if self.inch != state.inch {
            self.revision += 1;
        }
        self.inch = state.inch;
        // The first unit the program states is the unit of what it wrote before.
        if block.flags.has(Flags::UNITS) && !self.unit_stated {
            self.unit_stated = true;
            let u = self.unit();
            for d in self.descs.iter_mut().filter(|d| d.unit.is_none()) {
                d.unit = Some(u);
            }
            if let Some(dl) = &mut self.delta {
                dl.1.get_or_insert(u);
            }
            self.revision += 1;
        }
        let code = !comment_only(text);
        if !block.flags.has(Flags::MAY_NAME_TOOL) {
            // What a block without a T, a comment or M6 does (below): it ends a table and
            // the group.
            self.nx_table = false;
            self.powermill_table = false;
            if code {
                self.end_group();
            }
            return;
        }
        let line = block.line;
        let raw = String::from_utf8_lossy(text);
        let up = raw.to_ascii_uppercase();
        let call = if dialect == Dialect::Conversational {
            self.conversational(line, &raw, &up)
        } else {
            self.iso(dialect, line, &raw, &up, words)
        };
        if code && matches!(call, Call::None) {
            self.end_group();
        }
        self.descriptions(line, &raw, &up);
        if let Call::Change(id, note) = call {
            self.change_to(id, note);
        }
    }

    /// An ISO block: Heidenhain `G99` definitions, `T`/`M6` changes, `T="NAME"`.
    fn iso(&mut self, dialect: Dialect, line: usize, raw: &str, up: &str, words: &[Word]) -> Call {
        let word = |l: u8| words.iter().rev().find(|w| w.letter == l).map(|w| w.value);
        let g = |c: f64| {
            words
                .iter()
                .any(|w| w.letter == b'G' && (w.value - c).abs() < 1e-9)
        };
        let m6 = words
            .iter()
            .any(|w| w.letter == b'M' && (w.value - 6.0).abs() < 1e-9);
        // Heidenhain ISO `G99 T5 L+0 R+5 R2+5`: a tool definition (no R2: a flat end mill).
        if dialect == Dialect::Heidenhain && g(99.0) {
            if let (Some(n), Some(r)) = (word(b'T').and_then(whole), value_after(up, "R")) {
                let r2 = value_after(up, "R2").unwrap_or(0.0);
                self.define(
                    line,
                    raw,
                    Read {
                        ids: vec![ToolId::Number(n)],
                        strict: true,
                        shape: Shape::Mill {
                            d: 2.0 * r,
                            cr: Some(r2),
                            named: None,
                        },
                    },
                );
            }
            return Call::None;
        }
        // `T="NAME"` (Sinumerik).
        let named = up.find("T=\"").and_then(|k| {
            let rest = &up[k + 3..];
            rest.find('"').map(|e| ToolId::Name(rest[..e].to_string()))
        });
        let selected = named.or_else(|| word(b'T').and_then(whole).map(ToolId::Number));
        // Heidenhain ISO `T5 G17`: the tool call (with its `DL`).
        let heidenhain_call = dialect == Dialect::Heidenhain && (g(17.0) || g(18.0) || g(19.0));
        let call = if let Some(id) = selected {
            let change = m6 || heidenhain_call || !self.any_m6;
            self.selected = Some(id.clone());
            if change {
                Call::Change(Some(id), None)
            } else {
                Call::None
            }
        } else if m6 {
            Call::Change(self.selected.clone(), None)
        } else {
            Call::None
        };
        self.any_m6 |= m6;
        if heidenhain_call && matches!(call, Call::Change(..)) {
            self.set_delta(line, raw, up);
        }
        call
    }

    /// The `DL` of a tool call (none: 0): in force until the next call.
    fn set_delta(&mut self, line: usize, raw: &str, up: &str) {
        let unit = self.unit_stated.then(|| self.unit());
        self.delta = delta_length(up).map(|(v, at, len)| {
            let word: String = raw[at..at + len].to_string();
            let src = format!("line {line}, col {}: {word}", at + 1);
            match v {
                Some(v) => (v, unit, src),
                // A parameter: the controlled point is not known.
                None => (f64::NAN, unit, src),
            }
        });
        self.revision += 1;
    }

    /// A conversational block: `TOOL DEF` definitions, `TOOL CALL` changes.
    fn conversational(&mut self, line: usize, raw: &str, up: &str) -> Call {
        let t = up.trim_start();
        let t = t
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start();
        let Some(rest) = t.strip_prefix("TOOL") else {
            return Call::None;
        };
        let rest = rest.trim_start();
        let (def, args) = if let Some(a) = rest.strip_prefix("DEF") {
            (true, a.trim_start())
        } else if let Some(a) = rest.strip_prefix("CALL") {
            (false, a.trim_start())
        } else {
            return Call::None;
        };
        // The tool: a number (`5`, an indexed `5.1`), a name in quotes, a parameter
        // (`QS1`, `Q5`); else none (`TOOL CALL Z S10000`: the tool in use, a new speed).
        enum Named {
            Id(ToolId),
            Parameter(String),
            None,
        }
        let first = args.split_whitespace().next().unwrap_or("");
        let named = if let Some(q) = args.strip_prefix('"') {
            match q.find('"') {
                Some(e) => Named::Id(ToolId::Name(q[..e].to_string())),
                None => Named::None,
            }
        } else if first.starts_with(|c: char| c.is_ascii_digit()) {
            match first.parse::<u64>() {
                Ok(n) => Named::Id(ToolId::Number(n)),
                Err(_) => Named::Id(ToolId::Name(first.to_string())),
            }
        } else if first.starts_with('Q') {
            Named::Parameter(first.to_string())
        } else {
            Named::None
        };
        if def {
            // `TOOL DEF 5 L+0 R+5 R2+5`; without R2 a flat end mill; without R (`TOOL DEF
            // 5`, a preselection) no description.
            if let (Named::Id(id), Some(r)) = (named, value_after(up, "R")) {
                let r2 = value_after(up, "R2").unwrap_or(0.0);
                self.define(
                    line,
                    raw,
                    Read {
                        ids: vec![id],
                        strict: true,
                        shape: Shape::Mill {
                            d: 2.0 * r,
                            cr: Some(r2),
                            named: None,
                        },
                    },
                );
            }
            return Call::None;
        }
        self.set_delta(line, raw, up);
        match named {
            Named::Id(id) => Call::Change(Some(id), None),
            Named::Parameter(p) => Call::Change(
                None,
                Some(format!(
                    "line {line}: TOOL CALL names its tool by the parameter {p}, which polepatch \
                     does not evaluate"
                )),
            ),
            // The tool in use, called again: its DL is the new call's.
            Named::None => Call::None,
        }
    }

    /// Tool descriptions in comments (module docs' table).
    fn descriptions(&mut self, line: usize, raw: &str, up: &str) {
        // NX tool list and PowerMill table headers.
        if up.contains("TOOL-NO.") && up.contains("DIAMETER") {
            self.nx_table = true;
            return;
        }
        if up.contains("DIA.") && up.contains("TIP RAD") {
            self.powermill_table = true;
            return;
        }
        let Some(c) = comment_text(up) else {
            self.nx_table = false;
            self.powermill_table = false;
            return;
        };
        if let Some(read) = self.read_comment(c) {
            self.define(line, raw, read);
        } else if looks_like_a_tool(c) {
            self.unread = Some(source(line, raw));
        }
    }

    /// A comment's description, where it is one of the forms read (module docs' table).
    fn read_comment(&mut self, c: &str) -> Option<Read> {
        // PowerMill table row: `1|NAME| 4.0 | 0.0 | 75.0`.
        if self.powermill_table {
            let cols: Vec<&str> = c.split('|').map(str::trim).collect();
            if let [n, _name, d, r, ..] = cols.as_slice()
                && let (Ok(n), Ok(d), Ok(r)) =
                    (n.parse::<u64>(), d.parse::<f64>(), r.parse::<f64>())
            {
                return Some(Read {
                    ids: vec![ToolId::Number(n)],
                    strict: true,
                    shape: Shape::Mill {
                        d,
                        cr: Some(r),
                        named: None,
                    },
                });
            }
            self.powermill_table = false;
        }
        // NX tool list row: `3 BALL_MILL 0.236 0`.
        if self.nx_table {
            let cols: Vec<&str> = c.split_whitespace().collect();
            if let [n, name, d, ..] = cols.as_slice()
                && let (Ok(n), Ok(d)) = (n.parse::<u64>(), d.parse::<f64>())
            {
                return Some(Read {
                    ids: vec![ToolId::Number(n)],
                    strict: true,
                    shape: shape(d, None, Some(name)),
                });
            }
            if !c.trim_start().starts_with('-') {
                self.nx_table = false;
            }
        }
        // hyperMILL: `TOOL: T313 | NAME / DM=10 CR=5 TL=90`, `T313 | NAME / DM=…`: its own
        // T number and name.
        if let Some(d) = value_after(c, "DM=") {
            let cr = value_after(c, "CR=").unwrap_or(0.0);
            let head = c.split('/').next().unwrap_or("");
            let head = head.trim_start().trim_start_matches("TOOL:").trim_start();
            let mut ids = Vec::new();
            if let Some(n) = head
                .split_whitespace()
                .next()
                .and_then(|t| t.strip_prefix('T'))
                .and_then(|t| t.parse::<u64>().ok())
            {
                ids.push(ToolId::Number(n));
            }
            if let Some((_, name)) = head.split_once('|')
                && !name.trim().is_empty()
            {
                ids.push(ToolId::Name(name.trim().to_string()));
            }
            return Some(Read {
                ids,
                strict: false,
                shape: Shape::Mill {
                    d,
                    cr: Some(cr),
                    named: None,
                },
            });
        }
        // Mastercam, fields between `|`: `T1 | 1/4 BALL ENDMILL | H1 | D1 | TOOL DIA. - .25`.
        let fields: Vec<&str> = c.split('|').map(str::trim).collect();
        if fields.len() >= 3
            && let Some(n) = fields[0]
                .strip_prefix('T')
                .and_then(|t| t.trim().parse::<u64>().ok())
            && let Some(d) = fields
                .iter()
                .filter(|f| f.contains("DIA"))
                .find_map(|f| number_after_dash(f))
        {
            let cr = fields
                .iter()
                .filter(|f| f.contains("RAD"))
                .find_map(|f| number_after_dash(f));
            return Some(Read {
                ids: vec![ToolId::Number(n)],
                strict: true,
                shape: shape(d, cr, Some(fields[1])),
            });
        }
        // Mastercam: `TOOL - 12 3/16 BALL ENDMILL DIA. OFF. - 12 LEN. - 12 DIA. - .1875`.
        if c.contains("TOOL -") && c.contains("DIA. -") {
            let n = c
                .split("TOOL -")
                .nth(1)
                .and_then(|r| r.split_whitespace().next())
                .and_then(|t| t.parse::<u64>().ok());
            let d = c.rsplit("DIA. -").next().and_then(|r| {
                r.split_whitespace()
                    .next()
                    .and_then(|t| t.trim_end_matches(')').parse::<f64>().ok())
            });
            let name = c.split("DIA. OFF.").next().unwrap_or("");
            if let (Some(n), Some(d)) = (n, d) {
                return Some(Read {
                    ids: vec![ToolId::Number(n)],
                    strict: true,
                    shape: shape(d, None, Some(name)),
                });
            }
        }
        // `TOOL: T1 = 10.0 dia. ENDMILL…` (LinuxCNC's boat demos).
        if let Some(rest) = c.trim_start().strip_prefix("TOOL:") {
            let toks: Vec<&str> = rest.split_whitespace().collect();
            if let [t, "=", d, dia, ..] = toks.as_slice()
                && dia.starts_with("DIA")
                && let (Some(n), Ok(d)) = (
                    t.strip_prefix('T').and_then(|n| n.parse::<u64>().ok()),
                    d.parse::<f64>(),
                )
            {
                let text = rest.split_once("DIA").map_or("", |(_, r)| r);
                return Some(Read {
                    ids: vec![ToolId::Number(n)],
                    strict: true,
                    shape: shape(d, None, Some(text)),
                });
            }
        }
        // Fusion: `T1 D=10. CR=5. - ZMIN=-5. - ball end mill`; its Heidenhain form
        // `#31 D=10 CR=5 - … - ball end mill`; without a number and with a type text,
        // `Ball cutter D=10.00` (CUQ).
        if let Some(d) = value_after(c, "D=") {
            let cr = value_after(c, "CR=");
            let text = c.rsplit(" - ").next();
            return match fusion_id(c) {
                Some(id) => Some(Read {
                    ids: vec![id],
                    strict: true,
                    shape: shape(d, cr, text),
                }),
                None if text.and_then(kind_from_text).is_some() => Some(Read {
                    ids: Vec::new(),
                    strict: false,
                    shape: shape(d, cr, text),
                }),
                None => None,
            };
        }
        None
    }
}

/// The number after the last `-` of a Mastercam field (`TOOL DIA. - .25`).
fn number_after_dash(field: &str) -> Option<f64> {
    field
        .rsplit('-')
        .next()
        .and_then(|r| r.split_whitespace().next())
        .and_then(|t| t.trim_end_matches(')').parse::<f64>().ok())
}

/// A comment that may describe a tool in a form polepatch does not read: a tool word and
/// a number.
fn looks_like_a_tool(c: &str) -> bool {
    ["TOOL", "CUTTER", "BALL", "MILL", "DIA"]
        .iter()
        .any(|w| c.contains(w))
        && c.bytes().any(|b| b.is_ascii_digit())
}

/// The `DL` word of a tool call in upper-case `up`: its value (`None`: a parameter,
/// `DL+Q5`), byte offset and length.
fn delta_length(up: &str) -> Option<(Option<f64>, usize, usize)> {
    let b = up.as_bytes();
    let mut from = 0;
    while let Some(k) = up[from..].find("DL") {
        let at = from + k;
        from = at + 2;
        if at > 0 && b[at - 1].is_ascii_alphanumeric() {
            continue;
        }
        let rest = &up[at + 2..];
        let len = rest
            .find(|c: char| c.is_ascii_whitespace() || c == '*' || c == ';')
            .unwrap_or(rest.len());
        let value = &rest[..len];
        if value.is_empty() {
            continue;
        }
        return Some((value.parse::<f64>().ok(), at, 2 + len));
    }
    None
}

/// The tool number of a Fusion description: `T1 D=…` or `#31 D=…`.
fn fusion_id(c: &str) -> Option<ToolId> {
    let before = c.split("D=").next()?.trim();
    let tok = before.split_whitespace().last()?;
    let digits = tok.trim_start_matches(['T', '#']);
    digits.parse::<u64>().ok().map(ToolId::Number)
}

/// Whether a block (`text`, `words`) may say anything of the tool: a T in any case (`T`
/// words, `TOOL DEF`/`TOOL CALL`, `T="…"`, the tables' headers), a comment
/// ([`comment_text`]'s forms) or M6. Most blocks do not, and [`Tracker::block`] skips them
/// without looking further.
pub(crate) fn may_name_tool(text: &[u8], words: &[Word]) -> bool {
    // Every block of a program passes here: the bytes are looked at in chunks, each
    // without an early exit (which the compiler turns into a few vector compares).
    let marked = |c: &[u8]| {
        c.iter()
            .fold(false, |f, &b| f | matches!(b, b'T' | b't' | b'(' | b';'))
    };
    if text.chunks(32).any(marked) {
        return true;
    }
    let t = text.trim_ascii_start();
    let digits = t.iter().take_while(|b| b.is_ascii_digit()).count();
    if t[digits..].trim_ascii_start().starts_with(b"*") {
        return true;
    }
    words
        .iter()
        .any(|w| w.letter == b'M' && (w.value - 6.0).abs() < 1e-9)
}

/// Whether a block holds nothing but comments (and a block number): `(…)`, `; …`, a
/// conversational `* - …` line, or nothing.
fn comment_only(text: &[u8]) -> bool {
    let mut t = text.trim_ascii();
    if let Some(r) = t.strip_prefix(b"N").or_else(|| t.strip_prefix(b"n"))
        && r.first().is_some_and(u8::is_ascii_digit)
    {
        t = r;
    }
    let digits = t.iter().take_while(|b| b.is_ascii_digit()).count();
    t = t[digits..].trim_ascii_start();
    loop {
        match t.first() {
            None | Some(b';' | b'*') => return true,
            Some(b'(') => match t.iter().position(|&b| b == b')') {
                Some(k) => t = t[k + 1..].trim_ascii_start(),
                None => return true,
            },
            _ => return false,
        }
    }
}

/// The text of a line's comment, upper case: inside `( )` or after `;` (also a
/// conversational `* -` line).
fn comment_text(up: &str) -> Option<&str> {
    if let Some(k) = up.find('(') {
        let rest = &up[k + 1..];
        return Some(rest.rfind(')').map_or(rest, |e| &rest[..e]));
    }
    if let Some(k) = up.find(';') {
        return Some(&up[k + 1..]);
    }
    let t = up.trim_start();
    let t = t
        .trim_start_matches(|c: char| c.is_ascii_digit())
        .trim_start();
    t.strip_prefix("* -").or_else(|| t.strip_prefix("*-"))
}

fn whole(v: f64) -> Option<u64> {
    (v >= 0.0 && v.fract() == 0.0 && v < 1e15).then_some(v as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// What the tracker says after each block of `text`.
    fn said(dialect: Dialect, text: &str) -> Vec<ToolSaid> {
        let prog = crate::parse(text.as_bytes().to_vec(), dialect).unwrap();
        let mut t = Tracker::default();
        (0..prog.blocks.len())
            .map(|b| {
                let blk = &prog.blocks[b];
                t.block(
                    prog.dialect,
                    blk,
                    &prog.bytes[blk.span()],
                    prog.block_words(b),
                    &prog.state(b),
                );
                t.found()
            })
            .collect()
    }

    fn mill(d: f64, cr: Option<f64>, named: Option<CutterKind>) -> Cutter {
        Cutter::Mill {
            diameter_mm: d,
            corner_radius_mm: cr,
            named,
        }
    }

    #[test]
    fn a_key_is_read_where_it_starts_a_word() {
        assert_eq!(value_after("T1 D=10. CR=5.", "D="), Some(10.0));
        assert_eq!(value_after("T1 D=10. CR=5.", "CR="), Some(5.0));
        assert_eq!(value_after("DCR=3 CR=2", "CR="), Some(2.0));
        assert_eq!(value_after("ZMIN=-5.", "ZMIN="), Some(-5.0));
        assert_eq!(value_after("NO VALUE", "D="), None);
    }

    #[test]
    fn a_type_text_names_a_kind_or_another_cutter() {
        assert_eq!(
            kind_from_text("ball end mill"),
            Some(Some(CutterKind::Ball))
        );
        assert_eq!(kind_from_text("TORUS"), Some(Some(CutterKind::Bull)));
        assert_eq!(
            kind_from_text("flat end mill"),
            Some(Some(CutterKind::Flat))
        );
        assert_eq!(kind_from_text("SPOT DRILL"), Some(None));
        assert_eq!(kind_from_text("ZMIN=-5."), None);
    }

    #[test]
    fn a_length_delta_is_read_with_its_column_or_as_a_parameter() {
        assert_eq!(
            delta_length("TOOL CALL 5 Z S1 DL-0.5 DR+0"),
            Some((Some(-0.5), 17, 6))
        );
        assert_eq!(delta_length("TOOL CALL 5 Z DL+Q5"), Some((None, 14, 5)));
        // Inside a word (`MODL`) or without a value: none.
        assert_eq!(delta_length("MODL-5 DL *"), None);
    }

    #[test]
    fn comments_are_told_from_code() {
        assert!(comment_only(b"N10 (T1 D=10)"));
        assert!(comment_only(b"; list"));
        assert!(comment_only(b"5 * - TOOL: T1 | A / DM=12"));
        assert!(!comment_only(b"T1 M6 (BALL)"));
        assert_eq!(
            comment_text("N2(BALL CUTTER D=10.00)"),
            Some("BALL CUTTER D=10.00")
        );
        assert_eq!(comment_text("N2 ; T3 D=6"), Some(" T3 D=6"));
        assert_eq!(comment_text("1 * - T313 | A"), Some(" T313 | A"));
        assert_eq!(comment_text("G1 X0"), None);
        assert_eq!(fusion_id("#31 D=10 CR=5"), Some(ToolId::Number(31)));
        assert_eq!(fusion_id("BALL CUTTER D=10.00"), None);
    }

    /// A call takes the description of its number, in the unit the program states first,
    /// with the line that says it.
    #[test]
    fn a_call_takes_its_description_in_mm() {
        let f = said(
            Dialect::Auto,
            "(T1 D=0.5 CR=0.25 - ball end mill)\n(T2 D=0.25 - flat end mill)\nG20\nT1 M6\n",
        );
        let d = f[3].described.as_ref().unwrap();
        assert_eq!(d.cutter, mill(12.7, Some(6.35), Some(CutterKind::Ball)));
        assert!(d.source.starts_with("line 1: (T1"), "{}", d.source);
        assert_eq!(f[3].id, Some(ToolId::Number(1)));
        // A drill is another cutter.
        let f = said(Dialect::Auto, "(T11 D=8. CR=0. - DRILL)\nT11 M6\n");
        assert_eq!(f[1].described.as_ref().unwrap().cutter, Cutter::Other);
    }

    #[test]
    fn tool_def_and_tool_call_with_its_length_delta() {
        let f = said(
            Dialect::Conversational,
            "0 BEGIN PGM T MM\n1 TOOL DEF 5 L+0 R+5 R2+2\n2 TOOL CALL 5 Z S12000 DL-0.5\n\
             3 TOOL CALL QS1 Z\n",
        );
        assert_eq!(
            f[2].described.as_ref().map(|d| d.cutter),
            Some(mill(10.0, Some(2.0), None))
        );
        assert_eq!(
            f[2].delta_length,
            Some((-0.5, "line 3, col 24: DL-0.5".to_string()))
        );
        assert_eq!(f[3].id, None);
        assert!(f[3].note.as_deref().unwrap().contains("parameter QS1"));
        // Heidenhain ISO: `G99` defines, `T5 G17` calls.
        let f = said(
            Dialect::Heidenhain,
            "%T G71 *\nN10 G99 T5 L+0 R+5 *\nN20 T5 G17 S1000 DL-5 *\n",
        );
        assert_eq!(
            f[2].described.as_ref().map(|d| d.cutter),
            Some(mill(10.0, Some(0.0), None))
        );
        assert_eq!(f[2].delta_length.as_ref().map(|d| d.0), Some(-5.0));
    }

    /// The tables' rows and the forms without a number: only in the group just before the
    /// call, and never as another number's.
    #[test]
    fn tables_and_groups() {
        let f = said(
            Dialect::Auto,
            "( NO. | ID | DIA.| TIP RAD|LENGTH)\n(    1|name| 4.0 |  0.5 | 75.0 )\nT1 M6\n",
        );
        assert_eq!(
            f[2].described.as_ref().map(|d| d.cutter),
            Some(mill(4.0, Some(0.5), None))
        );
        let f = said(Dialect::Auto, "(Ball cutter D=10.00)\nT6 M6\n");
        assert_eq!(
            f[1].described.as_ref().map(|d| d.cutter),
            Some(mill(10.0, None, Some(CutterKind::Ball)))
        );
        let f = said(Dialect::Auto, "(Ball cutter D=10.00)\nG90 G21\nT6 M6\n");
        assert_eq!(f[2].described, None);
        let f = said(Dialect::Auto, "(T2 D=10 CR=5 - ball end mill)\nT1 M6\n");
        assert_eq!(f[1].described, None);
        // A comment like a tool's in no form read is named in the note.
        let f = said(Dialect::Auto, "(BALL 6MM)\nT2 M6\n");
        assert!(
            f[1].note
                .as_deref()
                .unwrap()
                .contains("is no form polepatch reads"),
            "{:?}",
            f[1]
        );
    }
}
