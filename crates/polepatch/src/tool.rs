//! The cutting tool: what it is, which point of it the program's X Y Z state, and where
//! polepatch learnt both.
//!
//! A patch changes the tool's orientation at fixed X Y Z. Where X Y Z are a ball's
//! **centre** that keeps the contact (G16's premise); where they are its **tip** the centre
//! moves by 2R·sin(δ/2), so the tip is rewritten to keep the centre
//! ([`polepatch_patcher::KeepCentre`]). A flat or bull-nose cutter turned about its tip moves
//! its cutting edge: the deviation is capped so that the cutter's surface moves at most a
//! surface tolerance ([`deviation_cap_deg`]).
//!
//! **The tool of a run** (the first that says it): `--tool ball:10` for the whole program;
//! a tool table file (`--tools FILE`) by the active tool's number or name; the program,
//! where it describes the tool in use ([`Tracker`]). **The point X Y Z refer to**:
//! `--tool-point`; the machine file's `[controller] tool_point`; the TCPM code in force —
//! Heidenhain `M128` (its manuals: the tool length refers to the ball's centre) and
//! `FUNCTION TCPM … REFPNT CENTER-CENTER` the centre, every other (`FUNCTION TCPM`'s default
//! `TIP-TIP`, `TRAORI`, `G43.4`, `G234`, a machine's own codes) and APT's `GOTO/` the tip.
//!
//! Program forms read (each as real posts write it; the fixtures under `fixtures/tools/`):
//!
//! | form | example | tool |
//! |---|---|---|
//! | Heidenhain `TOOL DEF` | `TOOL DEF 5 L+0 R+5 R2+5` (then `TOOL CALL 5 Z`) | R radius, R2 corner radius |
//! | Heidenhain ISO `G99` | `N10 G99 T5 L+0 R+5 R2+5 *` (then `T5 G17`) | the same |
//! | Fusion / HSM / Inventor CAM | `(T1 D=10. CR=5. - ZMIN=-5. - ball end mill)`, `;  #31 D=10 CR=5 - ZMIN=… - ball end mill` | D, CR, the type text |
//! | hyperMILL | `* - TOOL: T313 \| BALL_D10 / DM=10 CR=5 TL=90` (before `TOOL CALL`), `; T1554 \| … / DM=20 CR=2 TL=106` | DM, CR |
//! | Siemens NX tool list | `(TOOL-NO. TOOL-NAME DIAMETER OFFSET)` … `(   3   BALL_MILL   0.236   0  )` | a name with `BALL`: a ball of that diameter |
//! | Mastercam | `( TOOL - 12 3/16 BALL ENDMILL DIA. OFF. - 12 LEN. - 12 DIA. - .1875 )` | DIA., `BALL`/`FLAT` in the name |
//! | PowerMill | `( NO. \| ID \| DIA.\| TIP RAD\|LENGTH)` … `(    1\|name\| 4.0 \|  0.0 \| 75.0 )` | DIA., TIP RAD |
//!
//! Kinds from geometry: a corner radius of half the diameter (within
//! [`CORNER_TOLERANCE_MM`]) is a ball, none a flat end mill, between a bull-nose; a type
//! text that says `ball`, `bull` or `flat` must agree, and one that names another kind
//! (drill, chamfer, probe, face mill, lollipop, tapered) gives no tool. Values are in the
//! program's unit (inch programs converted). A description belongs to the tool that the
//! next tool change calls (by number, by name, or the description just before the change
//! when it has neither).

use crate::error::Error;
use polepatch_nc::{Dialect, Word};
use std::collections::HashMap;

/// Two radii closer than this are equal when a corner radius is compared with half a
/// diameter, mm (posts round both: Fusion writes D=0.1181 CR=0.0591 for a 3 mm probe).
pub const CORNER_TOLERANCE_MM: f64 = 2e-3;

/// The default surface tolerance for flat and bull-nose cutters, mm: how far their
/// cutting surface may move at a CL point when the patch turns the tool about its tip.
pub const SURFACE_TOLERANCE_MM: f64 = 0.005;

/// A cutter's shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolKind {
    /// A ball-end mill (corner radius = half the diameter).
    Ball,
    /// A flat end mill (no corner radius).
    Flat,
    /// A bull-nose (torus) end mill: 0 < corner radius < half the diameter.
    Bull,
}

/// A cutter.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Tool {
    /// Its shape.
    pub kind: ToolKind,
    /// Diameter, mm.
    pub diameter_mm: f64,
    /// Corner radius, mm (half the diameter for a ball, 0 for a flat end mill).
    pub corner_radius_mm: f64,
}

impl Tool {
    /// A tool from its diameter and corner radius (mm), its kind from their ratio; `None`
    /// for values that make no cutter.
    pub fn from_geometry(diameter_mm: f64, corner_radius_mm: f64) -> Option<Tool> {
        if !(diameter_mm.is_finite() && diameter_mm > 0.0 && corner_radius_mm.is_finite()) {
            return None;
        }
        let half = diameter_mm / 2.0;
        let kind = if (corner_radius_mm - half).abs() <= CORNER_TOLERANCE_MM {
            ToolKind::Ball
        } else if corner_radius_mm.abs() <= CORNER_TOLERANCE_MM / 2.0 {
            ToolKind::Flat
        } else if corner_radius_mm > 0.0 && corner_radius_mm < half {
            ToolKind::Bull
        } else {
            return None;
        };
        Some(Tool {
            kind,
            diameter_mm,
            corner_radius_mm: match kind {
                ToolKind::Ball => half,
                ToolKind::Flat => 0.0,
                ToolKind::Bull => corner_radius_mm,
            },
        })
    }

    /// Read `ball:10`, `flat:12`, `bull:10,2` (diameter, corner radius; mm).
    pub fn parse(text: &str) -> Result<Tool, String> {
        let bad = || {
            format!(
                "tool '{text}' is not ball:D, flat:D or bull:D,R (diameter D and corner radius R \
                 in mm, e.g. ball:10, flat:12, bull:10,2)"
            )
        };
        let (kind, rest) = text.trim().split_once(':').ok_or_else(bad)?;
        let nums: Vec<f64> = rest
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad())?;
        let tool = match (kind.trim().to_ascii_lowercase().as_str(), nums.as_slice()) {
            ("ball", [d]) => Tool::from_geometry(*d, d / 2.0),
            ("flat", [d]) => Tool::from_geometry(*d, 0.0),
            ("bull", [d, r]) => Tool::from_geometry(*d, *r).filter(|t| t.kind == ToolKind::Bull),
            _ => None,
        };
        tool.ok_or_else(bad)
    }

    /// For people: `ball D10`, `flat D12`, `bull D10 R2`.
    pub fn describe(&self) -> String {
        let n = |v: f64| {
            let s = format!("{v:.4}");
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        match self.kind {
            ToolKind::Ball => format!("ball D{}", n(self.diameter_mm)),
            ToolKind::Flat => format!("flat D{}", n(self.diameter_mm)),
            ToolKind::Bull => format!(
                "bull D{} R{}",
                n(self.diameter_mm),
                n(self.corner_radius_mm)
            ),
        }
    }

    /// The largest distance from the tip (the axis's end) of a point of the cutter's end —
    /// its bottom face and corner, where a flat or bull-nose cutter cuts on a 5-axis
    /// surface — mm: `√(R² + r²)` (R the radius, r the corner radius; R for a flat).
    pub fn end_reach_mm(&self) -> f64 {
        let r_tool = self.diameter_mm / 2.0;
        (r_tool * r_tool + self.corner_radius_mm * self.corner_radius_mm).sqrt()
    }
}

/// The largest change of tool orientation, degrees, that moves no point of a flat or
/// bull-nose cutter's end by more than `surface_tolerance_mm` when it turns about its tip.
///
/// A rotation by δ about the tip moves a point at distance d from it by the chord
/// 2d·sin(δ/2); every point of the cutter's end is within [`Tool::end_reach_mm`] of the tip,
/// so no point of the surface that cuts moves by more than 2·D·sin(δ/2), and the cap is
/// δ = 2·asin(ε / (2D)) (docs/method.md has the proof and its assumption: the cutter cuts
/// with its end, not its flank).
pub fn deviation_cap_deg(tool: &Tool, surface_tolerance_mm: f64) -> f64 {
    let reach = tool.end_reach_mm();
    let x = (surface_tolerance_mm / (2.0 * reach)).min(1.0);
    2.0 * x.asin().to_degrees()
}

/// The centre of a ball moves by this much per mm of its radius when the tool turns by
/// `deviation_deg` about its tip: 2·sin(δ/2).
pub fn centre_shift_per_mm_radius(deviation_deg: f64) -> f64 {
    2.0 * (deviation_deg.to_radians() / 2.0).sin()
}

/// Which point of the tool the program's X Y Z are.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolPoint {
    /// The tool tip (the end of its axis).
    Tip,
    /// The centre of the ball.
    Centre,
}

impl std::fmt::Display for ToolPoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl ToolPoint {
    /// `tip` or `centre` (also `center`).
    pub fn parse(text: &str) -> Result<ToolPoint, String> {
        match text.trim().to_ascii_lowercase().as_str() {
            "tip" => Ok(ToolPoint::Tip),
            "centre" | "center" => Ok(ToolPoint::Centre),
            _ => Err(format!("tool point '{text}' is not tip or centre")),
        }
    }

    /// `tip` or `centre`.
    pub fn name(self) -> &'static str {
        match self {
            ToolPoint::Tip => "tip",
            ToolPoint::Centre => "centre",
        }
    }
}

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

/// A tool table file (`--tools FILE`, TOML): tool number or name → tool.
///
/// ```toml
/// [tool.5]
/// kind = "ball"            # ball, flat or bull
/// diameter_mm = 10.0
/// [tool.12]
/// kind = "bull"
/// diameter_mm = 12.0
/// corner_radius_mm = 2.0
/// [tool."BALL_D6"]         # a tool called by name (Sinumerik T="BALL_D6", TOOL CALL "…")
/// kind = "ball"
/// diameter_mm = 6.0
/// ```
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ToolTable {
    /// The tools.
    pub tools: HashMap<ToolId, Tool>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct TableFile {
    #[serde(default)]
    tool: HashMap<String, TableEntry>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct TableEntry {
    kind: String,
    diameter_mm: f64,
    #[serde(default)]
    corner_radius_mm: Option<f64>,
}

impl ToolTable {
    /// Read a tool table's TOML text; `origin` names it in errors.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<ToolTable, String> {
        let file: TableFile = toml::from_str(text).map_err(|e| format!("{origin}: {e}"))?;
        let mut tools = HashMap::new();
        for (key, e) in file.tool {
            let spec = match e.kind.to_ascii_lowercase().as_str() {
                "bull" => format!(
                    "bull:{},{}",
                    e.diameter_mm,
                    e.corner_radius_mm.unwrap_or(-1.0)
                ),
                k => format!("{k}:{}", e.diameter_mm),
            };
            let tool = Tool::parse(&spec).map_err(|m| format!("{origin}: tool {key}: {m}"))?;
            let id = key
                .parse::<u64>()
                .map_or_else(|_| ToolId::Name(key.to_ascii_uppercase()), ToolId::Number);
            tools.insert(id, tool);
        }
        Ok(ToolTable { tools })
    }
}

/// How the caller says the tool: [`crate::PatchOptions::tool`].
#[derive(Debug, Clone, PartialEq)]
pub struct ToolOptions {
    /// The tool for the whole program (`--tool ball:10`); `None`: per run, from the table
    /// or the program. Default `None`.
    pub tool: Option<Tool>,
    /// A tool table (`--tools FILE`). Default empty.
    pub table: ToolTable,
    /// Which point X Y Z state (`--tool-point`); `None`: from the machine file or the TCPM
    /// code. Default `None`.
    pub point: Option<ToolPoint>,
    /// How far a flat or bull-nose cutter's surface may move at a CL point, mm. Default
    /// [`SURFACE_TOLERANCE_MM`].
    pub surface_tolerance_mm: f64,
}

impl Default for ToolOptions {
    fn default() -> Self {
        ToolOptions {
            tool: None,
            table: ToolTable::default(),
            point: None,
            surface_tolerance_mm: SURFACE_TOLERANCE_MM,
        }
    }
}

impl ToolOptions {
    /// Refuse a surface tolerance that is not a positive length.
    pub fn check(&self) -> Result<(), Error> {
        if !(self.surface_tolerance_mm.is_finite() && self.surface_tolerance_mm > 0.0) {
            return Err(Error::Options(format!(
                "surface_tolerance_mm must be a positive number of mm, got {}",
                self.surface_tolerance_mm
            )));
        }
        Ok(())
    }
}

/// What the program says of the tool in use at a run ([`Tracker`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FoundTool {
    /// The tool the last tool change called, if it named one.
    pub id: Option<ToolId>,
    /// The program's description of it, and where (`line 12: TOOL DEF 5 L+0 R+5 R2+5`).
    pub described: Option<(Tool, String)>,
}

/// The tool, the point and where they came from, for one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunTool {
    /// The tool, if known.
    pub tool: Option<Tool>,
    /// Where it was found (`--tool`, `tool table (T5)`, `line 12: …`), or why unknown.
    pub tool_source: String,
    /// The point X Y Z state.
    pub point: ToolPoint,
    /// Why that point (`--tool-point`, `machine file`, `M128`, `G43.4`, …).
    pub point_source: String,
}

/// Resolve a run's tool and point (module docs' order).
pub fn resolve(
    opts: &ToolOptions,
    found: &FoundTool,
    machine_point: Option<ToolPoint>,
    tcpm_centre: bool,
    tcpm_code: &str,
) -> RunTool {
    let from_table = found
        .id
        .as_ref()
        .and_then(|id| opts.table.tools.get(id).map(|t| (*t, id)));
    let (tool, tool_source) = if let Some(t) = opts.tool {
        (Some(t), "--tool".to_string())
    } else if let Some((t, id)) = from_table {
        (Some(t), format!("tool table ({id})"))
    } else if let Some((t, src)) = &found.described {
        (Some(*t), src.clone())
    } else {
        let why = match &found.id {
            Some(id) => format!("unknown: the program calls {id} without describing it"),
            None => "unknown: the program names no tool".to_string(),
        };
        (None, why)
    };
    let (point, point_source) = if let Some(p) = opts.point {
        (p, "--tool-point".to_string())
    } else if let Some(p) = machine_point {
        (p, "machine file [controller] tool_point".to_string())
    } else if tcpm_centre {
        (ToolPoint::Centre, tcpm_code.to_string())
    } else {
        (ToolPoint::Tip, tcpm_code.to_string())
    };
    RunTool {
        tool,
        tool_source,
        point,
        point_source,
    }
}

/// Reads the tool in use from a program, block by block in file order (module docs).
#[derive(Debug, Default, Clone)]
pub struct Tracker {
    /// Descriptions by tool id.
    defs: HashMap<ToolId, (Tool, String)>,
    /// A description that names no tool, for the next tool change (hyperMILL's `* - TOOL:`).
    pending: Option<(Tool, String)>,
    /// The tool a `T` word selected, for the next `M6`.
    selected: Option<ToolId>,
    /// An `M6` was seen (before it, a bare `T` is the change: Grbl-style files).
    any_m6: bool,
    /// The tool in use.
    active: Option<ToolId>,
    /// The description of the tool in use (taken at its change).
    active_desc: Option<(Tool, String)>,
    /// Inside an NX tool list (its header seen): rows are `( n NAME diameter offset )`.
    nx_table: bool,
    /// Inside a PowerMill tool table (its header seen).
    powermill_table: bool,
    /// The program is in inches now (descriptions are kept in the program's unit and
    /// converted at the tool change: posts write their tool list before `G20`).
    inch: bool,
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
fn kind_from_text(text: &str) -> Option<Option<ToolKind>> {
    let t = text.to_ascii_uppercase();
    let has = |w: &str| t.contains(w);
    if has("BALL") {
        Some(Some(ToolKind::Ball))
    } else if has("BULL") || has("TORUS") || has("RADIUS") || has("TIP_RADIUSED") {
        Some(Some(ToolKind::Bull))
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
        Some(Some(ToolKind::Flat))
    } else {
        None
    }
}

/// A tool from a diameter, a corner radius (if given) and a type text (if any): the
/// geometry's kind, which the text must not contradict.
fn tool_of(d_mm: f64, cr_mm: Option<f64>, text: Option<&str>) -> Option<Tool> {
    let named = text.and_then(kind_from_text);
    let cr = match (cr_mm, named) {
        (Some(r), _) => r,
        (None, Some(Some(ToolKind::Ball))) => d_mm / 2.0,
        (None, Some(Some(ToolKind::Flat))) => 0.0,
        _ => return None,
    };
    let t = Tool::from_geometry(d_mm, cr)?;
    match named {
        Some(None) => None,
        Some(Some(k)) if k != t.kind => None,
        _ => Some(t),
    }
}

impl Tracker {
    /// Changes whenever [`Tracker::found`] may give something else.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// The program's tool at this point (the next run's, when called between runs).
    pub fn found(&self) -> FoundTool {
        FoundTool {
            id: self.active.clone(),
            described: self.active_desc.clone().or_else(|| {
                self.active
                    .as_ref()
                    .and_then(|id| self.defs.get(id).cloned())
                    .map(|(t, src)| (self.in_mm(t), src))
            }),
        }
    }

    fn change_to(&mut self, id: Option<ToolId>) {
        let desc = self
            .pending
            .take()
            .or_else(|| id.as_ref().and_then(|i| self.defs.get(i).cloned()));
        self.active = id;
        self.active_desc = desc.map(|(t, src)| (self.in_mm(t), src));
        self.revision += 1;
    }

    fn define(&mut self, id: ToolId, desc: (Tool, String)) {
        self.defs.insert(id, desc);
        self.revision += 1;
    }

    /// A tool described in the program's unit, in mm.
    fn in_mm(&self, t: Tool) -> Tool {
        let u = if self.inch { 25.4 } else { 1.0 };
        Tool {
            diameter_mm: t.diameter_mm * u,
            corner_radius_mm: t.corner_radius_mm * u,
            ..t
        }
    }

    /// Take the block on `line` (`text`: its bytes; `words` its words; `inch`: its unit).
    pub fn block(
        &mut self,
        dialect: Dialect,
        line: usize,
        text: &[u8],
        words: &[Word],
        inch: bool,
    ) {
        if self.inch != inch {
            self.revision += 1;
        }
        self.inch = inch;
        if !may_name_tool(text, words) {
            // What a block without a T, a comment or M6 does (below): it ends a table.
            self.nx_table = false;
            self.powermill_table = false;
            return;
        }
        let unit = 1.0;
        let raw = String::from_utf8_lossy(text);
        let up = raw.to_ascii_uppercase();
        self.descriptions(line, &raw, &up, unit);
        if dialect == Dialect::Conversational {
            self.conversational(line, &raw, &up, unit);
            return;
        }
        let word = |l: u8| words.iter().rev().find(|w| w.letter == l).map(|w| w.value);
        let g = |c: f64| {
            words
                .iter()
                .any(|w| w.letter == b'G' && (w.value - c).abs() < 1e-9)
        };
        let m6 = words
            .iter()
            .any(|w| w.letter == b'M' && (w.value - 6.0).abs() < 1e-9);
        // Heidenhain ISO `G99 T5 L+0 R+5 R2+5`: a tool definition.
        if dialect == Dialect::Heidenhain && g(99.0) {
            if let (Some(t), Some(r)) = (word(b'T'), value_after(&up, "R")) {
                let r2 = value_after(&up, "R2");
                if let (Some(n), Some(tool)) = (
                    whole(t),
                    r2.and_then(|r2| Tool::from_geometry(2.0 * r * unit, r2 * unit)),
                ) {
                    self.define(ToolId::Number(n), (tool, source(line, &raw)));
                }
            }
            return;
        }
        // `T="NAME"` (Sinumerik).
        let named = up.find("T=\"").and_then(|k| {
            let rest = &up[k + 3..];
            rest.find('"').map(|e| ToolId::Name(rest[..e].to_string()))
        });
        let selected = named.or_else(|| word(b'T').and_then(whole).map(ToolId::Number));
        // Heidenhain ISO `T5 G17`: the tool call.
        let heidenhain_call = dialect == Dialect::Heidenhain && (g(17.0) || g(18.0) || g(19.0));
        if let Some(id) = selected {
            if m6 || heidenhain_call || !self.any_m6 {
                self.change_to(Some(id.clone()));
            }
            self.selected = Some(id);
        } else if m6 {
            let id = self.selected.clone();
            self.change_to(id);
        }
        self.any_m6 |= m6;
    }

    fn conversational(&mut self, line: usize, raw: &str, up: &str, unit: f64) {
        let toks: Vec<&str> = up.split_whitespace().collect();
        let start = usize::from(
            toks.first()
                .is_some_and(|t| t.bytes().all(|b| b.is_ascii_digit())),
        );
        let toks = &toks[start..];
        if toks.len() < 2 || toks[0] != "TOOL" {
            return;
        }
        let id = toks.get(2).and_then(|t| {
            let t = t.trim_matches('"');
            if t.is_empty() || t.starts_with('S') && t.len() > 1 && t[1..].parse::<f64>().is_ok() {
                None
            } else {
                Some(
                    t.parse::<u64>()
                        .map_or_else(|_| ToolId::Name(t.to_string()), ToolId::Number),
                )
            }
        });
        match toks[1] {
            "DEF" => {
                let r = value_after(up, "R");
                let r2 = value_after(up, "R2");
                if let (Some(id), Some(r), Some(r2)) = (id, r, r2)
                    && let Some(tool) = Tool::from_geometry(2.0 * r * unit, r2 * unit)
                {
                    self.define(id, (tool, source(line, raw)));
                }
            }
            "CALL" if id.is_some() => self.change_to(id),
            _ => {}
        }
    }

    /// Tool descriptions in comments (module docs' table).
    fn descriptions(&mut self, line: usize, raw: &str, up: &str, unit: f64) {
        // NX tool list and PowerMill table headers.
        if up.contains("TOOL-NO.") && up.contains("DIAMETER") {
            self.nx_table = true;
            return;
        }
        if up.contains("DIA.") && up.contains("TIP RAD") {
            self.powermill_table = true;
            return;
        }
        let comment = comment_text(up);
        let Some(c) = comment else {
            self.nx_table = false;
            self.powermill_table = false;
            return;
        };
        // Fusion: `T1 D=10. CR=5. - ZMIN=-5. - ball end mill`; its Heidenhain form
        // `#31 D=10 CR=5 - … - ball end mill`.
        if let Some(d) = value_after(c, "D=") {
            let id = fusion_id(c);
            let cr = value_after(c, "CR=");
            let text = c.rsplit(" - ").next();
            if let (Some(id), Some(tool)) = (id, tool_of(d * unit, cr.map(|r| r * unit), text)) {
                self.define(id, (tool, source(line, raw)));
            }
            return;
        }
        // hyperMILL: `TOOL: T313 | NAME / DM=10 CR=5 TL=90`.
        if let Some(d) = value_after(c, "DM=") {
            let cr = value_after(c, "CR=").unwrap_or(0.0);
            if let Some(tool) = Tool::from_geometry(d * unit, cr * unit) {
                self.pending = Some((tool, source(line, raw)));
            }
            return;
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
            if let (Some(n), Some(d)) = (n, d)
                && let Some(tool) = tool_of(d * unit, None, Some(name))
            {
                self.define(ToolId::Number(n), (tool, source(line, raw)));
            }
            return;
        }
        // PowerMill table row: `1|NAME| 4.0 | 0.0 | 75.0`.
        if self.powermill_table {
            let cols: Vec<&str> = c.split('|').map(str::trim).collect();
            if let [n, _name, d, r, ..] = cols.as_slice()
                && let (Ok(n), Ok(d), Ok(r)) =
                    (n.parse::<u64>(), d.parse::<f64>(), r.parse::<f64>())
            {
                if let Some(tool) = Tool::from_geometry(d * unit, r * unit) {
                    self.define(ToolId::Number(n), (tool, source(line, raw)));
                }
                return;
            }
            self.powermill_table = false;
        }
        // NX tool list row: `3 BALL_MILL 0.236 0`.
        if self.nx_table {
            let cols: Vec<&str> = c.split_whitespace().collect();
            if let [n, name, d, ..] = cols.as_slice()
                && let (Ok(n), Ok(d)) = (n.parse::<u64>(), d.parse::<f64>())
            {
                if let Some(tool) = tool_of(d * unit, None, Some(name)) {
                    self.define(ToolId::Number(n), (tool, source(line, raw)));
                }
                return;
            }
            if !c.trim_start().starts_with('-') {
                self.nx_table = false;
            }
        }
    }
}

/// The tool number of a Fusion description: `T1 D=…` or `#31 D=…`.
fn fusion_id(c: &str) -> Option<ToolId> {
    let before = c.split("D=").next()?.trim();
    let tok = before.split_whitespace().last()?;
    let digits = tok.trim_start_matches(['T', '#']);
    digits.parse::<u64>().ok().map(ToolId::Number)
}

/// The text of a line's comment, upper case: inside `( )` or after `;` (also a
/// conversational `* -` line).
/// Whether a block (`text`, `words`) may say anything of the tool: a T in any case (`T`
/// words, `TOOL DEF`/`TOOL CALL`, `T="…"`, the tables' headers), a comment
/// ([`comment_text`]'s forms) or M6. Most blocks do not, and [`Tracker::block`] skips them
/// without looking further.
fn may_name_tool(text: &[u8], words: &[Word]) -> bool {
    if text.iter().any(|&b| matches!(b, b'T' | b't' | b'(' | b';')) {
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

/// The tool of a CL file (APT `CUTTER/d[,r,e,f,α,β,h]`, NX `TLDATA/MILL,d,r,…`), the last
/// one before the first `GOTO/`, mm (`unit_mm` per unit of the file), with where it was.
pub fn cl_tool(bytes: &[u8], unit_mm: f64) -> Option<(Tool, String)> {
    let text = String::from_utf8_lossy(bytes);
    let mut found = None;
    for (k, line) in text.lines().enumerate() {
        let up = line.trim().to_ascii_uppercase();
        if up.starts_with("GOTO") {
            break;
        }
        let args = |key: &str| -> Option<Vec<f64>> {
            let rest = up.strip_prefix(key)?.trim_start().strip_prefix('/')?;
            Some(
                rest.split(',')
                    .map(|v| v.trim().trim_end_matches('$').trim().parse::<f64>())
                    .take_while(Result::is_ok)
                    .flatten()
                    .collect(),
            )
        };
        let tool = if let Some(v) = args("CUTTER") {
            match v.as_slice() {
                // `CUTTER/d`: a flat end mill; `CUTTER/d,r[,e,f,α…]`: r the corner radius
                // (a base angle α ≠ 0 is a drill or a cone, no mill).
                [d] => Tool::from_geometry(d * unit_mm, 0.0),
                [d, r] => Tool::from_geometry(d * unit_mm, r * unit_mm),
                [d, r, _e, _f, alpha, ..] if *alpha == 0.0 => {
                    Tool::from_geometry(d * unit_mm, r * unit_mm)
                }
                [d, r, _, _] | [d, r, _] => Tool::from_geometry(d * unit_mm, r * unit_mm),
                _ => None,
            }
        } else if let Some(v) = up
            .strip_prefix("TLDATA")
            .and_then(|r| r.trim_start().strip_prefix('/'))
            .and_then(|r| r.strip_prefix("MILL,"))
            .map(|r| {
                r.split(',')
                    .map(|v| v.trim().parse::<f64>())
                    .take_while(Result::is_ok)
                    .flatten()
                    .collect::<Vec<f64>>()
            })
        {
            match v.as_slice() {
                [d, r, _len, _taper, tip, ..] if *tip == 0.0 => {
                    Tool::from_geometry(d * unit_mm, r * unit_mm)
                }
                [d, r] | [d, r, _] => Tool::from_geometry(d * unit_mm, r * unit_mm),
                _ => None,
            }
        } else {
            continue;
        };
        found = tool.map(|t| (t, source(k + 1, line)));
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tools_from_options_and_geometry() {
        assert_eq!(
            Tool::parse("ball:10").unwrap(),
            Tool {
                kind: ToolKind::Ball,
                diameter_mm: 10.0,
                corner_radius_mm: 5.0
            }
        );
        assert_eq!(Tool::parse("flat:12").unwrap().kind, ToolKind::Flat);
        let b = Tool::parse("bull:10,2").unwrap();
        assert_eq!((b.kind, b.corner_radius_mm), (ToolKind::Bull, 2.0));
        for bad in [
            "ball",
            "ball:x",
            "bull:10",
            "bull:10,5",
            "bull:10,6",
            "flat:-1",
            "cone:5",
        ] {
            assert!(Tool::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(b.describe(), "bull D10 R2");
        // Fusion's probe: D=0.1181 CR=0.0591 is half within the tolerance.
        assert_eq!(
            Tool::from_geometry(3.0, 1.5005).unwrap().kind,
            ToolKind::Ball
        );
    }

    /// The cap's bound, planted: a flat D10 turned by δ about its tip moves its edge point
    /// (5 mm from the tip) by 2·5·sin(δ/2); at the cap that is the tolerance.
    #[test]
    fn the_surface_cap() {
        let flat = Tool::parse("flat:10").unwrap();
        let cap = deviation_cap_deg(&flat, 0.005);
        let moved = 2.0 * 5.0 * (cap.to_radians() / 2.0).sin();
        assert!((moved - 0.005).abs() < 1e-12, "{cap} {moved}");
        assert!((cap - 0.0573).abs() < 1e-3);
        // A bull-nose's corner reaches farther from the tip: a smaller cap.
        let bull = Tool::parse("bull:10,2").unwrap();
        assert!(deviation_cap_deg(&bull, 0.005) < cap);
        assert!((centre_shift_per_mm_radius(1.0) * 5.0 - 0.08726).abs() < 1e-4);
    }

    fn track(dialect: Dialect, text: &str) -> Vec<FoundTool> {
        let prog = polepatch_nc::parse(text.as_bytes().to_vec(), dialect).unwrap();
        let mut t = Tracker::default();
        (0..prog.blocks.len())
            .map(|b| {
                let blk = &prog.blocks[b];
                t.block(
                    prog.dialect,
                    blk.line,
                    &prog.bytes[blk.span()],
                    prog.block_words(b),
                    prog.state(b).inch,
                );
                t.found()
            })
            .collect()
    }

    fn last_tool(f: &[FoundTool]) -> Option<Tool> {
        f.last().and_then(|x| x.described.as_ref().map(|d| d.0))
    }

    #[test]
    fn program_forms() {
        let ball10 = Tool::parse("ball:10").unwrap();
        // Fusion, the header listing every tool; the change picks one.
        let f = track(
            Dialect::Auto,
            "(T1  D=10. CR=5. - ZMIN=-5. - ball end mill)\n(T2 D=12 CR=0 - ZMIN=-1 - flat end mill)\nT2 M6\nT1 M6\n",
        );
        assert_eq!(f[2].described.as_ref().unwrap().0.kind, ToolKind::Flat);
        assert_eq!(last_tool(&f), Some(ball10));
        assert!(
            f[3].described
                .as_ref()
                .unwrap()
                .1
                .starts_with("line 1: (T1")
        );
        // Fusion inch: values in inches.
        let f = track(
            Dialect::Auto,
            "G20\n(T3  D=0.25 CR=0.125 - ZMIN=-1.03 - BALL END MILL)\nT3 M6\n",
        );
        assert!((last_tool(&f).unwrap().diameter_mm - 6.35).abs() < 1e-9);
        // A drill is no mill.
        let f = track(
            Dialect::Auto,
            "(T11 D=8. CR=0. TAPER=118DEG - ZMIN=-21. - DRILL)\nT11 M6\n",
        );
        assert_eq!(last_tool(&f), None);
        assert_eq!(f[1].id, Some(ToolId::Number(11)));
        // Heidenhain conversational TOOL DEF / TOOL CALL.
        let f = track(
            Dialect::Conversational,
            "0 BEGIN PGM T MM\n1 TOOL DEF 5 L+0 R+5 R2+5\n2 TOOL CALL 5 Z S12000\n",
        );
        assert_eq!(last_tool(&f), Some(ball10));
        // Heidenhain ISO G99 / T5 G17.
        let f = track(
            Dialect::Heidenhain,
            "%T G71 *\nN10 G99 T5 L+0 R+5 R2+2 *\nN20 T5 G17 S1000 *\n",
        );
        assert_eq!(last_tool(&f).unwrap().kind, ToolKind::Bull);
        // hyperMILL: the description before the call.
        let f = track(
            Dialect::Conversational,
            "0 BEGIN PGM T MM\n1 * - TOOL: T313732062 | BALL / DM=2 CR=1 TL=155\n2 TOOL CALL \"GB02\" Z S14000\n",
        );
        assert_eq!(last_tool(&f), Some(Tool::parse("ball:2").unwrap()));
        // Mastercam.
        let f = track(
            Dialect::Auto,
            "( TOOL - 12  3/16 BALL ENDMILL    DIA. OFF. - 12  LEN. - 12  DIA. - .1875 )\nG20\nT12 M6\n",
        );
        assert!(last_tool(&f).is_some_and(|t| t.kind == ToolKind::Ball));
        // NX's tool list.
        let f = track(
            Dialect::Auto,
            "(TOOL-NO.   TOOL-NAME                   DIAMETER   OFFSET )\n(   3       BALL_MILL                    6.000      0     )\nT3 M06\n",
        );
        assert_eq!(last_tool(&f), Some(Tool::parse("ball:6").unwrap()));
        // Sinumerik by name, from a table.
        let f = track(Dialect::Sinumerik, "N10 T=\"BALL6\"\nN20 M6\n");
        assert_eq!(f[1].id, Some(ToolId::Name("BALL6".into())));
        // A preselect after the change is not the change.
        let f = track(
            Dialect::Auto,
            "(T1 D=10 CR=5 - ball end mill)\n(T2 D=12 - flat end mill)\nT1 M6\nT2\n",
        );
        assert_eq!(last_tool(&f), Some(ball10));
    }

    #[test]
    fn cl_cutters() {
        let (t, src) = cl_tool(
            b"CUTTER/14.,7.,0,7.,0,0,73.\nLOAD/TOOL,5\nGOTO/0,0,0\n",
            1.0,
        )
        .unwrap();
        assert_eq!((t.kind, t.diameter_mm), (ToolKind::Ball, 14.0));
        assert!(src.starts_with("line 1"));
        assert_eq!(
            cl_tool(b"CUTTER/10,5\nGOTO/1,2,3\n", 1.0).unwrap().0.kind,
            ToolKind::Ball
        );
        assert_eq!(
            cl_tool(b"CUTTER/20.,0,10.,0,0,0,100.\n", 1.0)
                .unwrap()
                .0
                .kind,
            ToolKind::Flat
        );
        assert!(
            cl_tool(b"CUTTER/6.5,0,3.25,1.95,31.,0,105.\n", 1.0).is_none(),
            "a drill"
        );
        assert_eq!(
            cl_tool(b"TLDATA/MILL,32.0000,5.0000,75.0000,0.0000,0.0000\n", 1.0)
                .unwrap()
                .0
                .kind,
            ToolKind::Bull
        );
        let inch = cl_tool(b"CUTTER/.5,.25\n", 25.4).unwrap().0;
        assert!((inch.diameter_mm - 12.7).abs() < 1e-9);
    }

    #[test]
    fn tool_tables() {
        let t = ToolTable::from_toml_str(
            "[tool.5]\nkind = \"ball\"\ndiameter_mm = 10\n[tool.\"bull6\"]\nkind = \"bull\"\ndiameter_mm = 6\ncorner_radius_mm = 1\n",
            "tools.toml",
        )
        .unwrap();
        assert_eq!(t.tools[&ToolId::Number(5)].kind, ToolKind::Ball);
        assert_eq!(t.tools[&ToolId::Name("BULL6".into())].corner_radius_mm, 1.0);
        let e = ToolTable::from_toml_str("[tool.5]\nkind = \"bull\"\ndiameter_mm = 6\n", "t")
            .unwrap_err();
        assert!(e.contains("tool 5"), "{e}");
    }
}
