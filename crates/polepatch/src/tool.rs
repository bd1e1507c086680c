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
//! the program's own description of the tool in use ([`Tracker`]; for `post`, the CL
//! file's `CUTTER/` or `TLDATA/` for the tool loaded after it, [`ClTools`]); a tool table
//! file (`--tools FILE`) by the active tool's number or name. The program's description
//! comes before the table: it is written by the CAM system that computed the path, for this
//! program's tool numbers, while a table is keyed by numbers and names shared between
//! programs, so an entry that disagrees with the program is more likely another program's
//! tool. Any source that disagrees with the one used is said: the zone's
//! `tool_disagreement` and a warning ([`RunTool::disagreement`]).
//!
//! **The point X Y Z refer to**: `--tool-point`; the machine file's `[controller]
//! tool_point`; the TCPM code in force — Heidenhain `M128` (its manuals: the tool length
//! refers to the ball's centre) and `FUNCTION TCPM … REFPNT CENTER-CENTER` the centre, every
//! other (`FUNCTION TCPM`'s default `TIP-TIP`, `TRAORI`, `G43.4`, `G234`, a machine's own
//! codes) and APT's `GOTO/` the tip.
//!
//! **Length deltas** (Heidenhain `TOOL CALL 5 Z S12000 DL-5`, ISO `T5 G17 DL-5`, in force until
//! the next tool call): the controller takes the tool as DL longer than its table says
//! (its manuals: DL > 0 an oversize, DL < 0 an undersize), so the point it brings to X Y Z
//! lies h = h₀ − DL above the tip along the tool axis (h₀ = 0 for the tip, R2 for the
//! centre): with `DL-5` under `TIP-TIP` a D10 ball's X Y Z state its centre. Honoured: a
//! ball's centre lies R − h above the point X Y Z state ([`RunTool::centre_offset_mm`]) —
//! kept by rewriting X Y Z where that is above 0, nothing to rewrite where it is 0, and
//! where it is below 0 (the point above the centre) the orientation change is capped so
//! the centre moves at most the surface tolerance; a flat or bull-nose cutter's cap is taken
//! about that point ([`Tool::reach_from_mm`]).
//!
//! **What the program says** is read by [`polepatch_nc::tooldesc`] (its module docs have
//! the forms read — `TOOL DEF`, `G99`, the CAM systems' comments and tool lists —, which
//! description a call takes, and the unit of a description's values): a diameter, a corner
//! radius where stated and the kind a type text names, with its line. Judged here as a
//! cutter ([`Tracker`]). A CL file's cutters (`post`) come from `polepatch_cl`'s records
//! ([`cl_tools`]): `CUTTER/10,5,0,5,0,0,75`, `TLDATA/MILL,10,5,75,0,0` (d, r: no base, side,
//! taper or tip angle; Creo's `$$-> CUTTER / 6` is read and said: a diameter without its
//! end's shape, no tool), for the tool of the `LOADTL/` after it, or before it with no move
//! between; in the CL file's units.
//!
//! Kinds from geometry: a corner radius of half the diameter (within
//! [`CORNER_TOLERANCE_MM`]) is a ball, none a flat end mill, between a bull-nose; a type
//! text that says `ball`, `bull` or `flat` must agree, and one that names another kind
//! (drill, chamfer, probe, face mill, lollipop, tapered) gives no tool (said in the report).

use crate::error::Error;
pub use crate::settings::SURFACE_TOLERANCE_MM;
pub use crate::tolerances::CORNER_TOLERANCE_MM;
use crate::tolerances::SAME_POINT_MM;
use polepatch_cl::{ClItem, ClProgram, CutterShape};
pub use polepatch_nc::tooldesc::ToolId;
use polepatch_nc::tooldesc::{self, Cutter, CutterKind, Described};
use polepatch_nc::{Block, Dialect, Modal, Word};
use std::collections::HashMap;

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
        self.reach_from_mm(0.0)
    }

    /// The largest distance of a point of the cutter's end (its bottom face and corner)
    /// from the point on its axis `height_mm` above the tip (towards the spindle; below
    /// it where negative), mm: every such point lies within R of the axis and between the
    /// tip and the corner's top (r above it), so at most √(R² + max(|h|, |r − h|)²) — exact
    /// at the corner's edge. At h = 0 that is [`Tool::end_reach_mm`].
    pub fn reach_from_mm(&self, height_mm: f64) -> f64 {
        let r_tool = self.diameter_mm / 2.0;
        let dz = height_mm
            .abs()
            .max((self.corner_radius_mm - height_mm).abs());
        (r_tool * r_tool + dz * dz).sqrt()
    }

    /// Whether `other` is the same cutter: the same kind, diameter and corner radius within
    /// [`CORNER_TOLERANCE_MM`] (one in inches converted and one in mm are the same).
    pub fn same_as(&self, other: &Tool) -> bool {
        self.kind == other.kind
            && (self.diameter_mm - other.diameter_mm).abs() <= CORNER_TOLERANCE_MM
            && (self.corner_radius_mm - other.corner_radius_mm).abs() <= CORNER_TOLERANCE_MM
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
    cap_for_reach_deg(tool.end_reach_mm(), surface_tolerance_mm)
}

/// The largest change of tool orientation, degrees, that moves no point within `reach_mm`
/// of the point the tool turns about by more than `surface_tolerance_mm`:
/// δ = 2·asin(ε / (2·reach)) ([`deviation_cap_deg`] for a cutter turned about its tip).
pub fn cap_for_reach_deg(reach_mm: f64, surface_tolerance_mm: f64) -> f64 {
    let x = (surface_tolerance_mm / (2.0 * reach_mm)).min(1.0);
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
///
/// An entry that contradicts itself (`kind = "ball"` with a corner radius other than half
/// the diameter, `kind = "flat"` with one other than 0) is refused with its key.
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
        // In key order, so that the first error is the same every time.
        let mut entries: Vec<(String, TableEntry)> = file.tool.into_iter().collect();
        entries.sort_by(|a, b| a.0.cmp(&b.0));
        for (key, e) in entries {
            let kind = e.kind.to_ascii_lowercase();
            let spec = match kind.as_str() {
                "bull" => format!(
                    "bull:{},{}",
                    e.diameter_mm,
                    e.corner_radius_mm.unwrap_or(-1.0)
                ),
                k => format!("{k}:{}", e.diameter_mm),
            };
            let tool = Tool::parse(&spec).map_err(|m| format!("{origin}: tool {key}: {m}"))?;
            if let Some(r) = e.corner_radius_mm
                && (r - tool.corner_radius_mm).abs() > CORNER_TOLERANCE_MM
            {
                let should = match tool.kind {
                    ToolKind::Ball => format!(
                        "a ball's corner radius is half its diameter ({} mm)",
                        tool.corner_radius_mm
                    ),
                    _ => "a flat end mill has none (a bull-nose is kind = \"bull\")".to_string(),
                };
                return Err(format!(
                    "{origin}: tool {key}: kind = \"{kind}\" with corner_radius_mm = {r}: {should}; \
                     say which the tool is"
                ));
            }
            let id = key
                .parse::<u64>()
                .map_or_else(|_| ToolId::Name(key.to_ascii_uppercase()), ToolId::Number);
            if tools.insert(id.clone(), tool).is_some() {
                return Err(format!(
                    "{origin}: tool {key}: a second entry for {id} (names are compared in upper \
                     case, as programs call them)"
                ));
            }
        }
        Ok(ToolTable { tools })
    }
}

/// The cutters a CL file describes, for the program `post` writes from it
/// ([`cl_tools`]): the CAM system's own description of each tool, which the written program
/// does not carry.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClTools {
    /// By the tool number its `LOADTL/` loads: the tool (`None`: a cutter polepatch does not
    /// model, or two different cutters for one number) and where it is said (`CL line 9:
    /// CUTTER/10,5,…`, or why it is not known).
    pub by_tool: HashMap<u64, (Option<Tool>, String)>,
    /// The cutter of the moves before the first `LOADTL/`, where one is described.
    pub before_first_load: Option<(Option<Tool>, String)>,
}

impl ClTools {
    /// No cutter described.
    pub fn is_empty(&self) -> bool {
        self.by_tool.is_empty() && self.before_first_load.is_none()
    }

    /// What the CL file says of the tool a run of the written program uses (`id`: the tool
    /// its last tool change called, `None` before the first).
    fn of(&self, id: Option<&ToolId>) -> Option<(Option<Tool>, String)> {
        match id {
            None => self.before_first_load.clone(),
            Some(ToolId::Number(n)) => self.by_tool.get(n).cloned(),
            Some(ToolId::Name(_)) => None,
        }
    }
}

/// The cutters of a CL file's `CUTTER/` and `TLDATA/` records ([`polepatch_cl::Cutter`]),
/// by the tool each describes: the cutter in force (the last record before) at the first
/// move after each `LOADTL/` — so one written before its `LOADTL/` (CAMWorks, NX) or after
/// it (Creo's order: `LOADTL / 2`, then the cutter) — and, before any `LOADTL/`, at the first
/// move. A cutter that changes between the moves of one tool, or a number loaded again with
/// another cutter, leaves that tool unknown (its source says why).
pub fn cl_tools(cl: &ClProgram) -> ClTools {
    let mut out = ClTools::default();
    let mut current: Option<(Option<Tool>, String)> = None;
    let mut loaded: Option<u64> = None;
    // A move since the last LOADTL (or the start); a cutter read since the last move.
    let (mut moved, mut fresh) = (false, false);
    for item in &cl.items {
        match item {
            ClItem::Cutter(c) => {
                let src = format!("CL line {}: {}", c.at.line, c.text);
                current = Some(match c.shape {
                    CutterShape::EndMill {
                        diameter_mm,
                        corner_radius_mm,
                    } => match Tool::from_geometry(diameter_mm, corner_radius_mm) {
                        Some(t) => (Some(t), src),
                        None => (None, format!("{src} (no cutter polepatch models)")),
                    },
                    CutterShape::DiameterOnly { diameter_mm } => (
                        None,
                        format!(
                            "{src} (a diameter, {diameter_mm} mm, without the shape of its end: \
                             Creo writes this comment for every kind of tool)"
                        ),
                    ),
                    CutterShape::Other => (None, format!("{src} (no end mill polepatch models)")),
                });
                fresh = true;
            }
            ClItem::ToolChange { tool, .. } => {
                loaded = Some(u64::from(*tool));
                moved = false;
            }
            ClItem::Move(_) => {
                if (!moved || fresh)
                    && let Some(c) = &current
                {
                    match loaded {
                        Some(n) => {
                            let mut slot = out.by_tool.remove(&n);
                            settle(&mut slot, c, &format!("tool {n}"));
                            out.by_tool.extend(slot.map(|s| (n, s)));
                        }
                        None => settle(
                            &mut out.before_first_load,
                            c,
                            "the moves before its first LOADTL",
                        ),
                    }
                }
                moved = true;
                fresh = false;
            }
            _ => {}
        }
    }
    out
}

/// The start of a [`ClTools`] source whose tool the CL file gives two cutters.
const CL_TWO_CUTTERS: &str = "the CL file gives";

/// Record cutter `c` for `what`, whose cutter so far is `slot`.
fn settle(slot: &mut Option<(Option<Tool>, String)>, c: &(Option<Tool>, String), what: &str) {
    match slot {
        None => *slot = Some(c.clone()),
        Some(old) if old.1.starts_with(CL_TWO_CUTTERS) => {}
        Some(old) if !differ(old.0.as_ref(), c.0.as_ref()) => {}
        Some(old) => {
            *old = (
                None,
                format!("{CL_TWO_CUTTERS} {what} two cutters: {}; {}", old.1, c.1),
            )
        }
    }
}

/// How the caller says the tool: [`crate::options::PatchOptions::tool`].
#[derive(Debug, Clone, PartialEq)]
pub struct ToolOptions {
    /// The tool for the whole program (`--tool ball:10`); `None`: per run, from the program
    /// or the table. Default `None`.
    pub tool: Option<Tool>,
    /// A tool table (`--tools FILE`). Default empty.
    pub table: ToolTable,
    /// The cutters of the CL file a program was posted from (`post` fills it: [`cl_tools`]),
    /// the program's own description. Default empty.
    pub cl: ClTools,
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
            cl: ClTools::default(),
            point: None,
            surface_tolerance_mm: SURFACE_TOLERANCE_MM,
        }
    }
}

impl ToolOptions {
    /// Refuse a surface tolerance that is not a positive length.
    pub fn check(&self) -> Result<(), Error> {
        if !(self.surface_tolerance_mm.is_finite() && self.surface_tolerance_mm > 0.0) {
            return Err(crate::error::OptionError::new(
                "surface_tolerance_mm",
                format_args!(
                    "must be a positive number of mm, got {}",
                    self.surface_tolerance_mm
                ),
            )
            .into());
        }
        Ok(())
    }
}

/// What the program says of the tool in use at a run ([`Tracker`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FoundTool {
    /// The tool the last tool change called, if it named one.
    pub id: Option<ToolId>,
    /// The program's description of it: the tool (`None`: a cutter polepatch does not
    /// model) and where (`line 12: TOOL DEF 5 L+0 R+5 R2+5`, with why where it gives no
    /// tool).
    pub described: Option<(Option<Tool>, String)>,
    /// Why no description was taken where the program has something like one: a list
    /// before the call that does not name it, a comment polepatch does not read.
    pub note: Option<String>,
    /// The tool call's length delta (Heidenhain `DL`), mm, and where (`line 3, col 28:
    /// DL-5`); `None` where the call gives none.
    pub delta_length: Option<(f64, String)>,
}

/// The tool, the point and where they came from, for one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunTool {
    /// The tool, if known.
    pub tool: Option<Tool>,
    /// Where it was found (`--tool`, `tool table (T5)`, `line 12: …`, `CL line 9: …`), or
    /// why unknown.
    pub tool_source: String,
    /// The point X Y Z state: the tip or the ball's centre (a length delta may put it
    /// elsewhere on the axis: [`RunTool::height_mm`]).
    pub point: ToolPoint,
    /// Why that point (`--tool-point`, `machine file`, `M128`, `G43.4`, a `DL`, …).
    pub point_source: String,
    /// How far above the tool tip, along the tool axis towards the spindle, the point X Y Z
    /// state lies, mm: 0 at the tip, the corner radius at a ball's or torus' centre, minus
    /// the tool call's DL (module docs).
    pub height_mm: f64,
    /// What another source says of the tool where it disagrees with the one used (the
    /// report's `tool_disagreement` and a warning); `None` where none does.
    pub disagreement: Option<String>,
}

/// What a run's tool asks of the patch ([`RunTool::demand`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToolDemand {
    /// Keep the ball's centre, `offset_mm` above the point X Y Z state along the tool
    /// axis: X Y Z are rewritten ([`polepatch_patcher::KeepCentre`]).
    KeepCentre {
        /// The centre's height above the point X Y Z state, mm (> 0).
        offset_mm: f64,
    },
    /// Cap the change of orientation: no point of the cutter that cuts lies farther than
    /// `reach_mm` from the point the tool turns about ([`cap_for_reach_deg`]).
    Cap {
        /// mm.
        reach_mm: f64,
    },
    /// Nothing: X Y Z are the ball's centre, or the tool is unknown.
    Nothing,
}

impl RunTool {
    /// For a ball: the height of its centre above the point X Y Z state, mm (R − h; R at
    /// the tip, 0 at the centre).
    pub fn centre_offset_mm(&self) -> Option<f64> {
        self.tool
            .filter(|t| t.kind == ToolKind::Ball)
            .map(|t| t.corner_radius_mm - self.height_mm)
    }

    /// What the tool asks of the patch (module docs).
    pub fn demand(&self) -> ToolDemand {
        let Some(t) = self.tool else {
            return ToolDemand::Nothing;
        };
        match self.centre_offset_mm() {
            Some(off) if off > SAME_POINT_MM => ToolDemand::KeepCentre { offset_mm: off },
            // The point above the centre: the centre (and the ball's surface with it) moves
            // by 2·|off|·sin(δ/2).
            Some(off) if off < -SAME_POINT_MM => ToolDemand::Cap { reach_mm: -off },
            Some(_) => ToolDemand::Nothing,
            None => ToolDemand::Cap {
                reach_mm: t.reach_from_mm(self.height_mm),
            },
        }
    }
}

/// How two sources' tools compare, for [`RunTool::disagreement`]: `None` where they agree.
fn differ(a: Option<&Tool>, b: Option<&Tool>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => !a.same_as(b),
        (None, None) => false,
        _ => true,
    }
}

fn said(t: Option<&Tool>) -> String {
    t.map_or("no tool polepatch models".to_string(), Tool::describe)
}

/// The tool and point of X Y Z where the program stands at a run (or a block): what the
/// program says of its tool (`found`), the caller's options, the machine file's tool point
/// and the TCPM code in force ([`resolve`], with the TCPM code named for the report). The
/// one rule the patch and the check of the written program ([`crate::verify`]) use.
pub fn for_run(
    opts: &ToolOptions,
    found: &FoundTool,
    machine: &polepatch_kinematics::Machine,
    tcpm_on: bool,
    tcpm_centre: bool,
) -> RunTool {
    let machine_point = machine
        .controller
        .tool_point
        .as_deref()
        .and_then(|p| ToolPoint::parse(p).ok());
    let code = if !tcpm_on {
        "no TCPM: X Y Z through the kinematic chain are the tool tip's"
    } else if tcpm_centre {
        "M128 or FUNCTION TCPM … REFPNT CENTER-CENTER: the tool length refers to the ball's centre"
    } else {
        "the TCPM code in force (FUNCTION TCPM, TRAORI, G43.4, G234, …) refers to the tool tip"
    };
    resolve(opts, found, machine_point, tcpm_on && tcpm_centre, code)
}

/// Resolve a run's tool and point (module docs' order).
pub fn resolve(
    opts: &ToolOptions,
    found: &FoundTool,
    machine_point: Option<ToolPoint>,
    tcpm_centre: bool,
    tcpm_code: &str,
) -> RunTool {
    // The program's own word: its text, or the CL file it was posted from.
    let program = found
        .described
        .clone()
        .or_else(|| opts.cl.of(found.id.as_ref()));
    let table = found
        .id
        .as_ref()
        .and_then(|id| opts.table.tools.get(id).map(|t| (*t, id)));
    let mut disagree = Vec::new();
    let (tool, tool_source) = if let Some(t) = opts.tool {
        if let Some((p, src)) = &program
            && differ(Some(&t), p.as_ref())
        {
            disagree.push(format!(
                "--tool says {}, the program's description says {} ({src}): --tool is used",
                t.describe(),
                said(p.as_ref())
            ));
        }
        if let Some((tt, id)) = table
            && !t.same_as(&tt)
        {
            disagree.push(format!(
                "--tool says {}, the tool table's entry for {id} says {}: --tool is used",
                t.describe(),
                tt.describe()
            ));
        }
        (Some(t), "--tool".to_string())
    } else if let Some((p, src)) = &program {
        let src = match p {
            Some(_) => src.clone(),
            None => format!("unknown: {src}"),
        };
        if let Some((tt, id)) = table
            && differ(Some(&tt), p.as_ref())
        {
            disagree.push(format!(
                "the tool table's entry for {id} says {}, the program's description says {} \
                 ({src}): the program's is used",
                tt.describe(),
                said(p.as_ref())
            ));
        }
        (*p, src)
    } else if let Some((t, id)) = table {
        (Some(t), format!("tool table ({id})"))
    } else {
        let mut why = match &found.id {
            Some(id) => format!("unknown: the program calls {id} without describing it"),
            None => "unknown: the program names no tool".to_string(),
        };
        if let Some(n) = &found.note {
            why = format!("{why} ({n})");
        }
        (None, why)
    };
    let (mut point, mut point_source) = if let Some(p) = opts.point {
        (p, "--tool-point".to_string())
    } else if let Some(p) = machine_point {
        (p, "machine file [controller] tool_point".to_string())
    } else if tcpm_centre {
        (ToolPoint::Centre, tcpm_code.to_string())
    } else {
        (ToolPoint::Tip, tcpm_code.to_string())
    };
    // A length delta the program gives by a parameter: the point is not known.
    let (tool, tool_source) = match &found.delta_length {
        Some((dl, src)) if dl.is_nan() => (
            None,
            format!(
                "unknown: {src} is a parameter polepatch does not evaluate, so the point of the \
                 tool X Y Z state is not known"
            ),
        ),
        _ => (tool, tool_source),
    };
    let base = match (point, tool) {
        (ToolPoint::Centre, Some(t)) => t.corner_radius_mm,
        _ => 0.0,
    };
    let mut height_mm = base;
    if let Some((dl, src)) = &found.delta_length
        && *dl != 0.0
        && !dl.is_nan()
    {
        if opts.point.is_some() {
            point_source.push_str(&format!(
                " (the program's {src} not applied: --tool-point says the point)"
            ));
        } else {
            height_mm = base - dl;
            let at = if base == 0.0 { "tip" } else { "centre" };
            point_source = format!(
                "{point_source}; {src}: the controller takes the tool as {} mm {}, so X Y Z state \
             the point {} mm {} its {at}",
                dl.abs(),
                if *dl < 0.0 { "shorter" } else { "longer" },
                dl.abs(),
                if *dl < 0.0 { "above" } else { "below" }
            );
            if let Some(t) = tool
                && t.kind == ToolKind::Ball
                && (t.corner_radius_mm - height_mm).abs() <= SAME_POINT_MM
            {
                point = ToolPoint::Centre;
                point_source.push_str(": the ball's centre");
            } else if height_mm.abs() <= SAME_POINT_MM {
                point = ToolPoint::Tip;
                point_source.push_str(": the tip");
            }
        }
    }
    RunTool {
        tool,
        tool_source,
        point,
        point_source,
        height_mm,
        disagreement: (!disagree.is_empty()).then(|| disagree.join("; ")),
    }
}

/// One description of a tool in the program (module docs' table).
/// What a description in the program's text gives as a tool, and its source (with why
/// where it gives none).
fn described_tool(d: &Described) -> (Option<Tool>, String) {
    match d.cutter {
        Cutter::Other => (
            None,
            format!("{} (a cutter polepatch does not model)", d.source),
        ),
        Cutter::Mill {
            diameter_mm,
            corner_radius_mm,
            named,
        } => match mill(diameter_mm, corner_radius_mm, named.map(kind_of)) {
            Ok(t) => (Some(t), d.source.clone()),
            Err(why) => (None, format!("{} ({why})", d.source)),
        },
    }
}

/// The kind a description's text names, as a [`ToolKind`].
fn kind_of(k: CutterKind) -> ToolKind {
    match k {
        CutterKind::Ball => ToolKind::Ball,
        CutterKind::Flat => ToolKind::Flat,
        CutterKind::Bull => ToolKind::Bull,
    }
}

/// An end mill from a diameter and a corner radius (mm; where stated) and the kind a text
/// names: the geometry's kind, which the text must not contradict.
fn mill(d_mm: f64, cr_mm: Option<f64>, named: Option<ToolKind>) -> Result<Tool, String> {
    let cr = match (cr_mm, named) {
        (Some(r), _) => r,
        (None, Some(ToolKind::Ball)) => d_mm / 2.0,
        (None, Some(ToolKind::Flat)) => 0.0,
        (None, Some(ToolKind::Bull)) => return Err("a bull-nose without its corner radius".into()),
        (None, None) => return Err("neither a corner radius nor a kind".into()),
    };
    let t = Tool::from_geometry(d_mm, cr).ok_or_else(|| {
        format!("diameter {d_mm} mm with corner radius {cr} mm is no cutter polepatch models")
    })?;
    match named {
        Some(k) if k != t.kind => Err(format!(
            "its text says {} but diameter {d_mm} mm with corner radius {cr} mm is a {}",
            kind_name(k),
            kind_name(t.kind)
        )),
        _ => Ok(t),
    }
}

fn kind_name(k: ToolKind) -> &'static str {
    match k {
        ToolKind::Ball => "ball",
        ToolKind::Flat => "flat end mill",
        ToolKind::Bull => "bull-nose",
    }
}

/// The tool in use, block by block in file order: the program's text read by
/// [`polepatch_nc::tooldesc::Tracker`] (descriptions, calls, `DL`, units), each description
/// it takes judged as a cutter here ([`Tool::from_geometry`], the type text's kind).
#[derive(Debug, Default, Clone)]
pub struct Tracker {
    text: tooldesc::Tracker,
}

impl Tracker {
    /// Changes whenever [`Tracker::found`] may give something else.
    pub fn revision(&self) -> u64 {
        self.text.revision()
    }

    /// The program's tool at this point (the next run's, when called between runs).
    pub fn found(&self) -> FoundTool {
        let said = self.text.found();
        FoundTool {
            id: said.id,
            described: said.described.as_ref().map(described_tool),
            note: said.note,
            delta_length: said.delta_length,
        }
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
        self.text.block(dialect, block, text, words, state);
    }
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
                    blk,
                    &prog.bytes[blk.span()],
                    prog.block_words(b),
                    &prog.state(b),
                );
                t.found()
            })
            .collect()
    }

    fn last_tool(f: &[FoundTool]) -> Option<Tool> {
        f.last()
            .and_then(|x| x.described.as_ref().and_then(|d| d.0))
    }

    #[test]
    fn program_forms() {
        let ball10 = Tool::parse("ball:10").unwrap();
        // Fusion, the header listing every tool; the change picks one.
        let f = track(
            Dialect::Auto,
            "(T1  D=10. CR=5. - ZMIN=-5. - ball end mill)\n(T2 D=12 CR=0 - ZMIN=-1 - flat end mill)\nT2 M6\nT1 M6\n",
        );
        assert_eq!(
            f[2].described.as_ref().unwrap().0.unwrap().kind,
            ToolKind::Flat
        );
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

    /// The unit of a description: the program's where it is written; before the program
    /// states one, the one it states first (posts write the header first); mm if none.
    #[test]
    fn description_units() {
        let d = |text: &str| last_tool(&track(Dialect::Auto, text)).map(|t| t.diameter_mm);
        let ball = "(T1 D=0.5 CR=0.25 - ball end mill)\n";
        assert_eq!(d(&format!("{ball}G20\nT1 M6\n")), Some(12.7));
        // The change before G20 as well: the list is still the inch program's.
        assert_eq!(d(&format!("{ball}T1 M6\nG20\n")), Some(12.7));
        assert_eq!(d(&format!("{ball}T1 M6\n")), Some(0.5), "no unit: mm");
        // Written under G21, read in mm whatever follows.
        assert_eq!(
            d("G21\n(T1 D=12 CR=6 - ball end mill)\nG20\nT1 M6\n"),
            Some(12.0)
        );
        // Heidenhain's BEGIN PGM states it first.
        assert_eq!(
            d("0 BEGIN PGM T INCH\n1 TOOL DEF 5 L+0 R+0.25 R2+0.25\n2 TOOL CALL 5 Z\n"),
            Some(12.7)
        );
    }

    /// `TOOL CALL`: the tool by number, name or parameter; an axis letter or `S` is none;
    /// `DL` read with its column and in force until the next call.
    #[test]
    fn tool_calls() {
        let f = track(
            Dialect::Conversational,
            "0 BEGIN PGM T MM\n1 TOOL DEF 5 L+0 R+5\n2 TOOL CALL 5 Z S12000 DL-0.5 DR+0\n\
             3 TOOL CALL Z S10000\n4 TOOL CALL QS1 Z\n5 TOOL CALL \"BALL D6\" Z S1 DL+Q5\n",
        );
        assert_eq!(f[2].id, Some(ToolId::Number(5)));
        assert_eq!(
            f[2].described.as_ref().unwrap().0,
            Some(Tool::parse("flat:10").unwrap()),
            "no R2: a flat end mill"
        );
        assert_eq!(
            f[2].delta_length,
            Some((-0.5, "line 3, col 24: DL-0.5".to_string()))
        );
        // `Z S10000`: the same tool, its DL the new call's (none).
        assert_eq!(f[3].id, Some(ToolId::Number(5)));
        assert_eq!(f[3].delta_length, None);
        assert_eq!(f[4].id, None);
        assert!(f[4].note.as_deref().unwrap().contains("parameter QS1"));
        assert_eq!(f[5].id, Some(ToolId::Name("BALL D6".into())));
        assert!(f[5].delta_length.as_ref().unwrap().0.is_nan());
        // Heidenhain ISO: the DL of the `T5 G17` block.
        let f = track(
            Dialect::Heidenhain,
            "%T G71 *\nN10 G99 T5 L+0 R+5 R2+5 *\nN20 T5 G17 S1000 DL-5 *\n",
        );
        assert_eq!(f[2].delta_length.as_ref().map(|d| d.0), Some(-5.0));
    }

    /// The forms of issue 42 and which description a call takes.
    #[test]
    fn more_forms_and_matching() {
        let ball10 = Some(Tool::parse("ball:10").unwrap());
        // CUQ: no number, before the change.
        let f = track(
            Dialect::Auto,
            "N1(File : t.nc)\nN2(Ball cutter D=10.00)\nN3(Offset=0.00 LACE CENTER)\nN4T006M06F800\n",
        );
        assert_eq!(last_tool(&f), ball10);
        // ... but not across a block of code, nor as another number's.
        let f = track(Dialect::Auto, "(Ball cutter D=10.00)\nG90 G21\nT6 M6\n");
        assert_eq!(last_tool(&f), None);
        let f = track(Dialect::Auto, "(T2 D=10 CR=5 - ball end mill)\nT1 M6\n");
        assert_eq!(last_tool(&f), None);
        // Mastercam's fields: D1 the offset register, TOOL DIA. the diameter.
        let f = track(
            Dialect::Auto,
            "( T3 | 1/4 BALL ENDMILL | H3 | D3 | TOOL DIA. - .25 )\nG20\nT3 M6\n",
        );
        assert!((last_tool(&f).unwrap().diameter_mm - 6.35).abs() < 1e-9);
        // `TOOL: T1 = 10.0 dia. …`.
        let f = track(Dialect::Auto, "( TOOL: T1 = 10.0 dia. BALLMILL )\nT1 M6\n");
        assert_eq!(last_tool(&f), ball10);
        // hyperMILL: the list before the call, none named by it: no tool, the list said.
        let f = track(
            Dialect::Conversational,
            "0 BEGIN PGM T MM\n1 * - TOOL: T1 | A / DM=12 CR=0\n2 * - TOOL: T2 | B / DM=10 CR=5\n\
             3 TOOL CALL \"C\" Z\n",
        );
        assert_eq!(f[3].described, None);
        assert!(
            f[3].note.as_deref().unwrap().contains("line 2, line 3"),
            "{f:?}"
        );
        // A type text that contradicts the geometry gives no tool, said.
        let f = track(Dialect::Auto, "(T1 D=10 CR=2 - ball end mill)\nT1 M6\n");
        let (t, src) = f[1].described.clone().unwrap();
        assert_eq!(t, None);
        assert!(src.contains("its text says ball"), "{src}");
        // NX's `TOOL NO.`: no diameter, named.
        let f = track(
            Dialect::Sinumerik,
            "N10 ;TOOL NO. :8\nN20 ;TOOL TYPE :Milling Tool-5 Parameters\nN30 T8 M6\n",
        );
        assert!(
            f[2].note
                .as_deref()
                .unwrap()
                .contains("line 2: N20 ;TOOL TYPE :Milling Tool-5"),
            "{f:?}"
        );
    }

    /// What a tool asks of the patch with a length delta (module docs): the centre's height
    /// above the point X Y Z state is R − h, h = h₀ − DL.
    #[test]
    fn delta_length_demands() {
        let run = |tool: &str, centre: bool, dl: Option<f64>| {
            let found = FoundTool {
                delta_length: dl.map(|v| (v, format!("DL{v}"))),
                ..FoundTool::default()
            };
            let opts = ToolOptions {
                tool: Some(Tool::parse(tool).unwrap()),
                ..ToolOptions::default()
            };
            resolve(&opts, &found, None, centre, "code")
        };
        let keep = |off: f64| ToolDemand::KeepCentre { offset_mm: off };
        assert_eq!(run("ball:10", false, None).demand(), keep(5.0));
        let centred = run("ball:10", false, Some(-5.0));
        assert_eq!(centred.demand(), ToolDemand::Nothing);
        assert_eq!(centred.point, ToolPoint::Centre);
        assert!(
            centred.point_source.contains("DL-5"),
            "{}",
            centred.point_source
        );
        assert_eq!(run("ball:10", false, Some(-2.0)).demand(), keep(3.0));
        assert_eq!(run("ball:10", false, Some(1.0)).demand(), keep(6.0));
        // Above the centre: the centre moves with the turn, capped.
        assert_eq!(
            run("ball:10", false, Some(-7.0)).demand(),
            ToolDemand::Cap { reach_mm: 2.0 }
        );
        // M128 (the centre) with an oversize: the centre 1 mm above X Y Z.
        assert_eq!(run("ball:10", true, None).demand(), ToolDemand::Nothing);
        assert_eq!(run("ball:10", true, Some(1.0)).demand(), keep(1.0));
        // A flat D10 turned about a point 3 mm up its axis: its edge √(5² + 3²) away.
        assert_eq!(
            run("flat:10", false, Some(-3.0)).demand(),
            ToolDemand::Cap {
                reach_mm: 34f64.sqrt()
            }
        );
        assert_eq!(
            run("bull:10,2", false, None).demand(),
            ToolDemand::Cap {
                reach_mm: Tool::parse("bull:10,2").unwrap().end_reach_mm()
            }
        );
        // A DL by parameter: the point is not known, nor then the tool's demand.
        let q = run("ball:10", false, Some(f64::NAN));
        assert_eq!((q.tool, q.demand()), (None, ToolDemand::Nothing));
        assert!(q.tool_source.contains("parameter"), "{}", q.tool_source);
    }

    /// `--tool` over the program over the table, every disagreement said.
    #[test]
    fn sources_and_disagreements() {
        let found = FoundTool {
            id: Some(ToolId::Number(5)),
            described: Some((Tool::parse("ball:10").ok(), "line 4: TOOL DEF 5".into())),
            ..FoundTool::default()
        };
        let table =
            ToolTable::from_toml_str("[tool.5]\nkind = \"flat\"\ndiameter_mm = 10\n", "t").unwrap();
        let mut opts = ToolOptions {
            table,
            ..ToolOptions::default()
        };
        let r = resolve(&opts, &found, None, false, "code");
        assert_eq!(r.tool, Tool::parse("ball:10").ok());
        assert_eq!(r.tool_source, "line 4: TOOL DEF 5");
        assert!(r.disagreement.unwrap().contains("the program's is used"));
        opts.tool = Tool::parse("ball:10").ok();
        let r = resolve(&opts, &found, None, false, "code");
        assert_eq!(r.tool_source, "--tool");
        assert!(
            r.disagreement
                .unwrap()
                .contains("tool table's entry for T5 says flat D10")
        );
        // Agreeing sources: nothing said.
        opts.table = ToolTable::default();
        assert_eq!(
            resolve(&opts, &found, None, false, "code").disagreement,
            None
        );
        // The table alone.
        let described = FoundTool {
            described: None,
            ..found.clone()
        };
        opts.tool = None;
        opts.table
            .tools
            .insert(ToolId::Number(5), Tool::parse("flat:6").unwrap());
        assert_eq!(
            resolve(&opts, &described, None, false, "code").tool_source,
            "tool table (T5)"
        );
    }

    fn cl(text: &str) -> ClTools {
        cl_tools(&polepatch_cl::parse(text.as_bytes()).unwrap())
    }

    fn cl_tool(c: &ClTools, n: u64) -> Option<Tool> {
        c.by_tool.get(&n).and_then(|x| x.0)
    }

    #[test]
    fn cl_cutters() {
        let c = cl("CUTTER/14.,7.,0,7.,0,0,73.\nLOAD/TOOL,5\nGOTO/0,0,0\n");
        assert_eq!(cl_tool(&c, 5), Some(Tool::parse("ball:14").unwrap()));
        assert!(c.by_tool[&5].1.starts_with("CL line 1: CUTTER/14."));
        // No LOADTL: the cutter of the first moves.
        let c = cl("CUTTER/10,5\nGOTO/1,2,3\n");
        assert_eq!(c.before_first_load.unwrap().0.unwrap().kind, ToolKind::Ball);
        let c = cl("CUTTER/20.,0,10.,0,0,0,100.\nLOADTL/1\nGOTO/0,0,0\n");
        assert_eq!(cl_tool(&c, 1).unwrap().kind, ToolKind::Flat);
        // A drill (base angle 31°) is no end mill: said, no tool.
        let c = cl("CUTTER/6.5,0,3.25,1.95,31.,0,105.\nLOADTL/1\nGOTO/0,0,0\n");
        assert_eq!(cl_tool(&c, 1), None);
        assert!(c.by_tool[&1].1.contains("no end mill"), "{:?}", c.by_tool);
        let c = cl("TLDATA/MILL,32.0000,5.0000,75.0000,0.0000,0.0000\nLOAD/TOOL,3\nGOTO/0,0,0\n");
        assert_eq!(cl_tool(&c, 3).unwrap().kind, ToolKind::Bull);
        // Inches, the units record before or after the cutter.
        for text in [
            "UNITS/INCHES\nCUTTER/.5,.25\nLOADTL/1\nGOTO/0,0,0\n",
            "CUTTER/.5,.25\nUNITS/INCHES\nLOADTL/1\nGOTO/0,0,0\n",
        ] {
            let d = cl_tool(&cl(text), 1).unwrap().diameter_mm;
            assert!((d - 12.7).abs() < 1e-9, "{text}: {d}");
        }
    }

    /// Several cutters: each for the tool whose moves it comes before, written before its
    /// LOADTL (CAMWorks) or after it (Creo's order); Creo's commented diameter is no
    /// shape; a cutter changing between one tool's moves leaves it unknown.
    #[test]
    fn cl_cutters_per_tool() {
        let camworks = "CUTTER/10,5,0,5,0,0,75\nLOADTL/1\nGOTO/0,0,0\nGOTO/1,0,0\n\
                        CUTTER/12,0,6,0,0,0,80\nLOADTL/2\nGOTO/0,0,0\nGOTO/1,0,0\n";
        let c = cl(camworks);
        assert_eq!(cl_tool(&c, 1), Some(Tool::parse("ball:10").unwrap()));
        assert_eq!(cl_tool(&c, 2), Some(Tool::parse("flat:12").unwrap()));
        assert!(c.by_tool[&2].1.starts_with("CL line 5:"), "{:?}", c.by_tool);
        let after = "LOADTL/1\nCUTTER/10,5\nGOTO/0,0,0\nLOADTL/2\nCUTTER / 12.000000\nGOTO/0,0,0\n";
        let c = cl(after);
        assert_eq!(cl_tool(&c, 1), Some(Tool::parse("ball:10").unwrap()));
        assert_eq!(cl_tool(&c, 2), Some(Tool::parse("flat:12").unwrap()));
        assert!(
            c.by_tool[&2].1.starts_with("CL line 5: CUTTER / 12"),
            "{:?}",
            c.by_tool
        );
        // Creo's comment: the diameter, not the kind: said, no tool.
        let c = cl("LOADTL / 2\n$$-> CUTTER / 6.000000\nGOTO / 0, 0, 0\n");
        assert_eq!(cl_tool(&c, 2), None);
        assert!(
            c.by_tool[&2].1.contains("without the shape of its end"),
            "{:?}",
            c.by_tool
        );
        let changed = "CUTTER/10,5\nLOADTL/1\nGOTO/0,0,0\nCUTTER/12\nGOTO/1,0,0\n";
        let c = cl(changed);
        assert_eq!(cl_tool(&c, 1), None);
        assert!(c.by_tool[&1].1.contains("two cutters"), "{:?}", c.by_tool);
        // The same cutter again for the same tool is no conflict.
        let again = "CUTTER/10,5\nLOADTL/1\nGOTO/0,0,0\nCUTTER/10,5\nLOADTL/1\nGOTO/1,0,0\n";
        assert_eq!(
            cl_tool(&cl(again), 1),
            Some(Tool::parse("ball:10").unwrap())
        );
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
        // Entries that contradict themselves, or name one tool twice.
        for (text, key) in [
            (
                "[tool.5]\nkind = \"ball\"\ndiameter_mm = 10\ncorner_radius_mm = 2\n",
                "tool 5",
            ),
            (
                "[tool.7]\nkind = \"flat\"\ndiameter_mm = 10\ncorner_radius_mm = 1\n",
                "tool 7",
            ),
            (
                "[tool.ab]\nkind = \"flat\"\ndiameter_mm = 10\n[tool.AB]\nkind = \"flat\"\ndiameter_mm = 10\n",
                "tool ab",
            ),
        ] {
            let e = ToolTable::from_toml_str(text, "t").unwrap_err();
            assert!(e.starts_with(&format!("t: {key}")), "{e}");
        }
        // Agreeing values are fine.
        assert!(
            ToolTable::from_toml_str(
                "[tool.5]\nkind = \"ball\"\ndiameter_mm = 10\ncorner_radius_mm = 5\n",
                "t"
            )
            .is_ok()
        );
    }
}
