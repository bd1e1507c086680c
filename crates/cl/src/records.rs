//! What a CL file says, in file order: moves (straight, rapid, circular, drilled holes) and
//! the machine set-up records between them (tool change, spindle, coolant, cutter
//! compensation, dwell, stops, comments). Lengths in mm, feeds in mm/min, whatever the
//! file's units (converted on read); tool axes are unit vectors in the part frame.

pub use crate::At;
use crate::arcs::Arc;
use crate::cycles::Cycle;
use std::collections::BTreeMap;

/// Length units of a CL file (`UNITS/MM|INCHES`, `UNIT/MM|INCH`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Units {
    /// Millimetres (the default when the file does not say).
    #[default]
    Mm,
    /// Inches (values are multiplied by 25.4 on read).
    Inch,
}

/// How a point is reached.
#[derive(Debug, Clone, PartialEq)]
pub enum MoveKind {
    /// A straight feed move (`GOTO`, `GODLTA`).
    Linear,
    /// A rapid move (`RAPID` before it; `FROM`, `GOHOME`).
    Rapid,
    /// A circular (or helical) feed move from the previous point (`CIRCLE`/`MOVARC` before
    /// the `GOTO`).
    Arc(Arc),
    /// A hole drilled by a canned cycle (`GOTO` while a `CYCLE` is on): the point is the
    /// top of the hole, the tool axis its axis.
    Hole(Cycle),
}

/// One cutter location and how the tool gets there.
#[derive(Debug, Clone, PartialEq)]
pub struct ClPoint {
    /// Tool tip, part frame, mm.
    pub pos_mm: [f64; 3],
    /// Tool axis, unit vector, part frame.
    pub axis: [f64; 3],
    /// Feed in force, mm/min (`None` before any feed; a hole's feed is in its cycle).
    pub feed_mm_min: Option<f64>,
    /// Straight, rapid, arc or hole.
    pub kind: MoveKind,
    /// 1-based line of the record in the file.
    pub line: usize,
    /// 1-based byte column of the record (its major word; a CSV line's first field).
    pub column: usize,
}

impl ClPoint {
    /// A straight feed move (`rapid` false) or a rapid move, at column 1 of `line`.
    pub fn straight(
        pos_mm: [f64; 3],
        axis: [f64; 3],
        feed_mm_min: Option<f64>,
        rapid: bool,
        line: usize,
    ) -> Self {
        ClPoint {
            pos_mm,
            axis,
            feed_mm_min,
            kind: if rapid {
                MoveKind::Rapid
            } else {
                MoveKind::Linear
            },
            line,
            column: 1,
        }
    }

    /// A rapid move.
    pub fn is_rapid(&self) -> bool {
        self.kind == MoveKind::Rapid
    }
}

/// Spindle direction (`SPINDL/…,CLW|CCLW`, `SPINDL/OFF`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpindleDir {
    /// Clockwise (M3).
    Cw,
    /// Counter-clockwise (M4).
    Ccw,
    /// Stopped (M5).
    Off,
}

/// Coolant (`COOLNT/…`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coolant {
    /// Flood (`ON`, `FLOOD`): M8.
    Flood,
    /// Mist (`MIST`): M7.
    Mist,
    /// Off: M9.
    Off,
}

/// Cutter radius compensation side (`CUTCOM/LEFT|RIGHT|OFF`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CompSide {
    /// Tool left of the contour (G41).
    Left,
    /// Tool right of the contour (G42).
    Right,
    /// Off (G40).
    Off,
}

/// A machine set-up record or a move, in file order.
#[derive(Debug, Clone, PartialEq)]
pub enum ClItem {
    /// A move to a point.
    Move(ClPoint),
    /// `LOADTL/n` (`LOAD/TOOL,n`): tool change.
    ToolChange {
        /// Tool number.
        tool: u32,
        /// Length offset register (`ADJUST,h` / `OFFSET,h`; else the tool number).
        length_offset: u32,
        /// Where the record is.
        at: At,
    },
    /// `CUTTER/…`, `TLDATA/…` (Creo also writes `$$-> CUTTER / d`): the cutter of the
    /// moves after it ([`Cutter`]). It does not move the machine; `post` reads it for the
    /// tool the patch keeps on the part.
    Cutter(Cutter),
    /// `SPINDL/…`: speed and/or direction.
    Spindle {
        /// Speed, rpm (`None`: unchanged).
        rpm: Option<f64>,
        /// Direction.
        dir: SpindleDir,
        /// Where the record is.
        at: At,
    },
    /// `COOLNT/…`.
    Coolant {
        /// Mode.
        mode: Coolant,
        /// Where the record is.
        at: At,
    },
    /// `CUTCOM/LEFT|RIGHT[,n]|OFF`.
    CutterComp {
        /// Side.
        side: CompSide,
        /// Offset register (`CUTCOM/LEFT,n`), if given.
        register: Option<u32>,
        /// Where the record is.
        at: At,
    },
    /// `DELAY/t`: dwell, seconds.
    Dwell {
        /// Seconds.
        seconds: f64,
        /// Where the record is.
        at: At,
    },
    /// `STOP` (M0) or `OPSTOP` (M1).
    Stop {
        /// `OPSTOP`: optional stop.
        optional: bool,
        /// Where the record is.
        at: At,
    },
    /// `PPRINT`/`PARTNO`/`TPRINT` text, written as a comment.
    Comment(String),
    /// `INSERT/text`: text for the NC program, written there as it is (a line of its own).
    Insert {
        /// The text after `INSERT/`, trailing blanks removed.
        text: String,
        /// Where the record is.
        at: At,
    },
}

/// A cutter description: APT `CUTTER/d[,r[,e,f[,α[,β[,h]]]]]` (d the diameter, r the corner
/// radius, e f the corner's centre, α the base angle, β the side angle, h the height), NX
/// `TLDATA/MILL,d,r,l,taper,tip[,…]`, Creo's `$$-> CUTTER / d`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cutter {
    /// Its shape, mm.
    pub shape: CutterShape,
    /// The record as written (its first line, trimmed), for messages.
    pub text: String,
    /// Where the record is.
    pub at: At,
}

/// What a [`Cutter`] record says of the cutter's shape, lengths in mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CutterShape {
    /// An end mill (flat, bull-nose or ball: no base, side, taper or tip angle); APT's
    /// `CUTTER/d` is a flat end mill of diameter d.
    EndMill {
        /// Diameter, mm.
        diameter_mm: f64,
        /// Corner radius, mm.
        corner_radius_mm: f64,
    },
    /// A diameter without the shape of the end: Creo's `$$-> CUTTER / d`, which Creo writes
    /// for every kind of tool.
    DiameterOnly {
        /// Diameter, mm.
        diameter_mm: f64,
    },
    /// Another shape (a drill, a chamfer or tapered mill), or values not read.
    Other,
}

/// A CL file read.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClProgram {
    /// Moves and set-up records in file order.
    pub items: Vec<ClItem>,
    /// Notes for the user (`PARTNO`, `PPRINT`, a CSV header line).
    pub notes: Vec<String>,
    /// Program name (`PARTNO`), if any.
    pub name: Option<String>,
    /// The file's units (its first `UNITS`/`UNIT` record; mm when it has none).
    pub units: Units,
    /// Where that first units record is (`None`: the file has none, or is CSV).
    pub units_at: Option<At>,
    /// How many records of each kind the file has (APT major word → count), every record
    /// counted, whatever became of it.
    pub records: BTreeMap<String, usize>,
    /// Records skipped on request (`ParseOptions::ignore`), by major word.
    pub skipped: BTreeMap<String, Skipped>,
}

/// The records of one kind skipped on request.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Skipped {
    /// How many.
    pub count: usize,
    /// Where the first one is.
    pub first: At,
    /// Why they may be skipped, where they are records polepatch posts: the refusal of one
    /// of them in this file (`line L, col C: message`), filled in by the post's rule.
    /// `None` for records polepatch never posts.
    pub refused: Option<String>,
}

impl ClProgram {
    /// The points in order.
    pub fn points(&self) -> impl Iterator<Item = &ClPoint> {
        self.items.iter().filter_map(|i| match i {
            ClItem::Move(p) => Some(p),
            _ => None,
        })
    }

    /// Number of points.
    pub fn point_count(&self) -> usize {
        self.points().count()
    }

    /// A program of straight moves (CSV, tests).
    pub fn from_points(points: Vec<ClPoint>) -> Self {
        ClProgram {
            items: points.into_iter().map(ClItem::Move).collect(),
            ..ClProgram::default()
        }
    }
}
