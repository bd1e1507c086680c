//! Writing a new 5-axis program (`polepatch post`): Heidenhain ISO with M128, Sinumerik
//! with TRAORI, Fanuc with G43.4. Numbers go through [`NumberStyle`], in each dialect's
//! usual style; every straight move writes every axis word (the simplest program every
//! controller reads the same way).
//!
//! What each [`Item`] becomes:
//!
//! | item | Heidenhain ISO | Sinumerik | Fanuc |
//! |---|---|---|---|
//! | straight move, TCPM | `G00`/`G01 X Y Z A C F` under `M128` | same under `TRAORI` | same under `G43.4 H` |
//! | straight move, vertical | the same with TCPM off (`M129`) | `TRAFOOF` | `G43 H` (length only) |
//! | arc (XY, ZX, YZ) | XY only: `I J` centre block, `G02`/`G03 X Y Z` | `G17`/`G18`/`G19 G2`/`G3 X Y Z I J K` (centre from the start) | same as Sinumerik |
//! | hole | `G200`/`G203`/`G201`/`G206` definition + `G79` | `CYCLE81/82/83/84/85` | `G98 G81/G82/G83/G73/G84/G74/G85/G89 … G80` |
//! | tool change | `T n G17` | `T n M6`, `D1` | `T n M6` |
//! | spindle | `S M3/M4`, `M5` | same | same |
//! | coolant | `M8`, `M7`, `M9` | same | same |
//! | cutter compensation | `G41`/`G42`/`G40` on the next straight move | same | `G41 D`/`G42 D`/`G40` |
//! | dwell | `G04 F s` | `G4 F s` | `G04 X s` |
//! | stop | `M00`/`M01` | `M0`/`M1` | `M00`/`M01` |
//!
//! TCPM is switched on before a straight move or arc that asks for it and off before a
//! tool change, a hole or a move that asks for it off (the caller puts the rotary axes at
//! P 0, C 0 before: the part frame is then the machine's, and 3-axis cycles and cutter
//! compensation mean what the CL means). Each hole is drilled from the return level L =
//! top + return (up first if the tool is below L, then across, then down to L over the
//! hole): never a feed move between holes.
//!
//! Units: every length and feed is written in mm, or in inches with `inch` (`G20`,
//! `G700`, Heidenhain `G70` with F in 0.1 inch/min as Heidenhain inch programs take it).

use crate::dialect::Dialect;
use crate::style::NumberStyle;

/// One straight move: tool tip (part frame, mm), primary and C (degrees), feed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitPoint {
    /// X Y Z, mm.
    pub xyz_mm: [f64; 3],
    /// Primary axis (A or B), degrees.
    pub p_deg: f64,
    /// C, degrees.
    pub c_deg: f64,
    /// Feed, mm/min (written where it changes; `None` for a rapid).
    pub feed_mm_min: Option<f64>,
    /// A rapid move (G0).
    pub rapid: bool,
    /// Under TCPM (`false`: TCPM off, the caller has put P and C at 0).
    pub tcpm: bool,
}

/// Plane of an arc (its normal is the third axis).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArcPlane {
    /// XY, G17.
    Xy,
    /// ZX, G18.
    Zx,
    /// YZ, G19.
    Yz,
}

/// A circular (or helical, along the plane's normal) move from the previous point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitArc {
    /// End point, mm.
    pub end_mm: [f64; 3],
    /// Centre, mm (absolute).
    pub center_mm: [f64; 3],
    /// Start point (the previous point), mm: I J K are written from it.
    pub start_mm: [f64; 3],
    /// Plane.
    pub plane: ArcPlane,
    /// Counter-clockwise seen from the positive normal axis (G3), else clockwise (G2).
    pub ccw: bool,
    /// Feed, mm/min.
    pub feed_mm_min: f64,
    /// Under TCPM.
    pub tcpm: bool,
}

/// What a canned cycle does at a hole.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HoleKind {
    /// Feed to depth, (dwell,) rapid out.
    Drill,
    /// Peck drilling with full retract; the peck, mm.
    Deep(f64),
    /// Peck drilling with chip breaking; the peck, mm.
    ChipBreak(f64),
    /// Tapping at the spindle speed in force (rpm, clockwise = right-hand thread).
    Tap {
        /// Spindle speed, rpm.
        rpm: f64,
        /// Clockwise (right-hand thread).
        cw: bool,
    },
    /// Feed in, feed out.
    Bore,
}

/// One hole, tool along +Z (TCPM off, P and C at 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitHole {
    /// Top of the hole, mm.
    pub top_mm: [f64; 3],
    /// Depth below the top, mm.
    pub depth_mm: f64,
    /// Where the feed starts above the top, mm.
    pub clearance_mm: f64,
    /// Where the tool returns above the top (≥ clearance), mm.
    pub return_mm: f64,
    /// Feed, mm/min.
    pub feed_mm_min: f64,
    /// Dwell at the bottom, s.
    pub dwell_s: f64,
    /// What the cycle does.
    pub kind: HoleKind,
}

/// Spindle state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spindle {
    /// Clockwise at rpm (M3).
    Cw(f64),
    /// Counter-clockwise at rpm (M4).
    Ccw(f64),
    /// Stop (M5).
    Off,
}

/// Coolant.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coolant {
    /// M8.
    Flood,
    /// M7.
    Mist,
    /// M9.
    Off,
}

/// Cutter radius compensation, written on the next straight move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Comp {
    /// G41 with the offset register (Fanuc `D`).
    Left(u32),
    /// G42 with the offset register.
    Right(u32),
    /// G40.
    Off,
}

/// One thing to write, in program order.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// A straight move.
    Move(EmitPoint),
    /// A circular move.
    Arc(EmitArc),
    /// A drilled hole.
    Hole(EmitHole),
    /// Tool change; the length offset register (Fanuc `H`).
    ToolChange {
        /// Tool number.
        tool: u32,
        /// Length offset register.
        length_offset: u32,
    },
    /// Spindle.
    Spindle(Spindle),
    /// Coolant.
    Coolant(Coolant),
    /// Cutter compensation from the next straight move.
    Comp(Comp),
    /// Dwell, seconds.
    Dwell(f64),
    /// Program stop (`true`: optional, M1).
    Stop(bool),
    /// A line written as it is (APT `INSERT/` text): no block number, no `*`, no
    /// comment delimiters. The writer forgets what it knows of the modal state after it
    /// (the next move states G1, F and every axis again), since the text may change any
    /// of it.
    Raw(String),
    /// A comment line.
    Comment(String),
}

/// Marks a body line written as it is ([`Item::Raw`]) until the frame writes it.
const RAW: char = '\u{1}';

impl From<EmitPoint> for Item {
    fn from(p: EmitPoint) -> Self {
        Item::Move(p)
    }
}

/// How to write the program.
#[derive(Debug, Clone, PartialEq)]
pub struct EmitOptions {
    /// Dialect (`Auto` is taken as Heidenhain; MillPlus is not written — `polepatch`'s post
    /// refuses it — and gets the Fanuc form here).
    pub dialect: Dialect,
    /// Program name (Heidenhain `%NAME`, Fanuc comment, Sinumerik comment).
    pub name: String,
    /// Letters of the tilting and the pole axis (A or B and C on most machines; A and B on
    /// an A-B trunnion whose platter is B).
    pub letters: crate::modal::RotaryLetters,
    /// Decimals of rotary words.
    pub rotary_decimals: usize,
    /// Decimals of linear words.
    pub linear_decimals: usize,
    /// Comment lines to put at the top (source notes).
    pub comments: Vec<String>,
    /// Write inches (lengths and feeds divided by 25.4) instead of mm.
    pub inch: bool,
}

fn style(dialect: Dialect) -> NumberStyle {
    match dialect {
        Dialect::Fanuc | Dialect::MillPlus => NumberStyle {
            plus_sign: false,
            decimals: 3,
            strip_trailing_zeros: true,
            trailing_point: true,
            leading_zero: true,
            equals: false,
            zero: None,
        },
        Dialect::Sinumerik => NumberStyle {
            plus_sign: false,
            decimals: 3,
            strip_trailing_zeros: true,
            trailing_point: false,
            leading_zero: true,
            equals: false,
            zero: None,
        },
        Dialect::Heidenhain | Dialect::Conversational | Dialect::Auto => NumberStyle {
            plus_sign: true,
            decimals: 3,
            strip_trailing_zeros: true,
            trailing_point: false,
            leading_zero: true,
            equals: false,
            zero: None,
        },
    }
}

/// Only characters every dialect accepts in a comment or a program name.
fn clean(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || " _-.,:/".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// TCPM state while writing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Tcpm {
    /// Nothing active yet, or after a tool change.
    Off,
    /// Tool-centre-point control on.
    On,
}

/// The writer: dialect, number style and the modal state of what it has written.
struct Writer<'o> {
    o: &'o EmitOptions,
    st: NumberStyle,
    /// mm → output units.
    k: f64,
    /// Decimals of lengths.
    ld: usize,
    lines: Vec<String>,
    feed: Option<f64>,
    /// The motion G code last written (`"G01"`, …), reset by anything that may end it.
    motion: Option<&'static str>,
    tcpm: Tcpm,
    /// Fanuc `G43 H` (length compensation without TCPM) active.
    length_comp: bool,
    length_offset: u32,
    comp_pending: Option<Comp>,
    /// Tool tip after the last move, mm (part frame).
    pos: Option<[f64; 3]>,
    /// P and C after the last move, degrees.
    rotary: Option<(f64, f64)>,
    plane: Option<ArcPlane>,
}

impl Writer<'_> {
    fn heidenhain(&self) -> bool {
        matches!(
            self.o.dialect,
            Dialect::Heidenhain | Dialect::Conversational | Dialect::Auto
        )
    }

    fn len(&self, mm: f64) -> String {
        self.st.render(mm / self.k, self.ld)
    }

    fn plain(&self, v: f64, decimals: usize) -> String {
        NumberStyle {
            plus_sign: false,
            ..self.st
        }
        .render(v, decimals)
    }

    /// A feed in the output's units (Heidenhain inch: 0.1 inch/min).
    fn feed_word(&self, mm_min: f64) -> String {
        let v = if self.o.inch {
            mm_min / 25.4 * if self.heidenhain() { 10.0 } else { 1.0 }
        } else {
            mm_min
        };
        format!("F{}", self.plain(v, if self.o.inch { 2 } else { 1 }))
    }

    fn push(&mut self, s: impl Into<String>) {
        self.lines.push(s.into());
    }

    fn tcpm_on(&mut self) {
        if self.tcpm == Tcpm::On {
            return;
        }
        let h = self.length_offset;
        self.push(match self.o.dialect {
            Dialect::Sinumerik => "TRAORI".to_string(),
            Dialect::Fanuc | Dialect::MillPlus => format!("G43.4 H{h}"),
            _ => "M128".to_string(),
        });
        self.tcpm = Tcpm::On;
        self.length_comp = false;
        self.motion = None;
    }

    fn tcpm_off(&mut self) {
        if self.tcpm == Tcpm::On {
            self.push(match self.o.dialect {
                Dialect::Sinumerik => "TRAFOOF",
                Dialect::Fanuc | Dialect::MillPlus => "G49",
                _ => "M129",
            });
            self.tcpm = Tcpm::Off;
            self.motion = None;
        }
    }

    /// TCPM off with the tool length applied along Z (Fanuc `G43 H`).
    fn vertical(&mut self) {
        self.tcpm_off();
        if self.o.dialect == Dialect::Fanuc && !self.length_comp {
            let h = self.length_offset;
            self.push(format!("G43 H{h}"));
            self.length_comp = true;
        }
    }

    fn axis_words(&self, xyz: [f64; 3], p_deg: f64, c_deg: f64) -> Vec<String> {
        let rd = self.o.rotary_decimals;
        let (p, c) = (self.o.letters.tilt as char, self.o.letters.pole as char);
        vec![
            format!("X{}", self.len(xyz[0])),
            format!("Y{}", self.len(xyz[1])),
            format!("Z{}", self.len(xyz[2])),
            format!("{p}{}", self.st.render(p_deg, rd)),
            format!("{c}{}", self.st.render(c_deg, rd)),
        ]
    }

    fn motion_word(&mut self, g: &'static str, words: &mut Vec<String>) {
        if self.motion != Some(g) {
            words.push(g.to_string());
            self.motion = Some(g);
        }
    }

    fn straight(&mut self, q: &EmitPoint) {
        if q.tcpm {
            self.tcpm_on();
        } else {
            self.vertical();
        }
        let mut words = Vec::with_capacity(9);
        if let Some(c) = self.comp_pending.take() {
            words.push(match (c, self.o.dialect) {
                (Comp::Left(d), Dialect::Fanuc) => format!("G41 D{d}"),
                (Comp::Right(d), Dialect::Fanuc) => format!("G42 D{d}"),
                (Comp::Left(_), _) => "G41".into(),
                (Comp::Right(_), _) => "G42".into(),
                (Comp::Off, _) => "G40".into(),
            });
        }
        self.motion_word(if q.rapid { "G00" } else { "G01" }, &mut words);
        words.extend(self.axis_words(q.xyz_mm, q.p_deg, q.c_deg));
        if !q.rapid && q.feed_mm_min != self.feed {
            if let Some(f) = q.feed_mm_min {
                words.push(self.feed_word(f));
            }
            self.feed = q.feed_mm_min;
        }
        self.push(words.join(" "));
        self.pos = Some(q.xyz_mm);
        self.rotary = Some((q.p_deg, q.c_deg));
    }

    fn arc(&mut self, a: &EmitArc) {
        if a.tcpm {
            self.tcpm_on();
        } else {
            self.vertical();
        }
        let (g17, i0, i1) = match a.plane {
            ArcPlane::Xy => ("G17", 0, 1),
            ArcPlane::Zx => ("G18", 2, 0),
            ArcPlane::Yz => ("G19", 1, 2),
        };
        let centre_letter = |i: usize| ["I", "J", "K"][i];
        let mut words = Vec::new();
        if self.plane != Some(a.plane) {
            words.push(g17.to_string());
            self.plane = Some(a.plane);
        }
        if self.heidenhain() {
            // The circle centre (CC), absolute, in its own block.
            let cc = [i0, i1]
                .iter()
                .map(|&i| format!("{}{}", centre_letter(i), self.len(a.center_mm[i])))
                .collect::<Vec<_>>();
            if !words.is_empty() {
                let g = words.join(" ");
                self.push(g);
                words.clear();
            }
            self.push(cc.join(" "));
        }
        // Sinumerik writes G2/G3, the others G02/G03 (every reader takes both).
        let g: &'static str = match (self.o.dialect, a.ccw) {
            (Dialect::Sinumerik, true) => "G3",
            (Dialect::Sinumerik, false) => "G2",
            (_, true) => "G03",
            (_, false) => "G02",
        };
        self.motion = None;
        self.motion_word(g, &mut words);
        for i in 0..3 {
            words.push(format!("{}{}", ["X", "Y", "Z"][i], self.len(a.end_mm[i])));
        }
        if !self.heidenhain() {
            for i in [i0, i1] {
                words.push(format!(
                    "{}{}",
                    centre_letter(i),
                    self.len(a.center_mm[i] - a.start_mm[i])
                ));
            }
        }
        if Some(a.feed_mm_min) != self.feed {
            words.push(self.feed_word(a.feed_mm_min));
            self.feed = Some(a.feed_mm_min);
        }
        self.push(words.join(" "));
        // An arc's block ends the straight-move modal group for the reader: restate G01.
        self.motion = None;
        self.pos = Some(a.end_mm);
    }

    /// A rapid move of a hole's positioning: tool along +Z, P and C at 0 (a compensation
    /// cancel waiting for its move is written on it).
    fn rapid_to(&mut self, xyz: [f64; 3]) {
        let mut words = Vec::new();
        if let Some(Comp::Off) = self.comp_pending.take() {
            words.push("G40".to_string());
        }
        self.motion_word("G00", &mut words);
        words.extend(self.axis_words(xyz, 0.0, 0.0));
        self.push(words.join(" "));
        self.pos = Some(xyz);
        self.rotary = Some((0.0, 0.0));
    }

    fn hole(&mut self, h: &EmitHole) {
        self.vertical();
        let [x, y, top] = h.top_mm;
        let level = top + h.return_mm;
        let r = top + h.clearance_mm;
        let bottom = top - h.depth_mm;
        // Up (at the old XY), across, down (over the hole): the tool reaches the hole at
        // the return level, never below a level it was asked to clear.
        if let Some(p) = self.pos {
            if p[2] < level {
                self.rapid_to([p[0], p[1], level]);
            }
            let p = self.pos.expect("set");
            if p[0] != x || p[1] != y {
                self.rapid_to([x, y, p[2]]);
            }
            if self.pos.expect("set")[2] > level {
                self.rapid_to([x, y, level]);
            }
        } else {
            self.rapid_to([x, y, level]);
        }
        let f = self.feed_word(h.feed_mm_min);
        let ms = (h.dwell_s * 1000.0).round();
        match self.o.dialect {
            Dialect::Fanuc | Dialect::MillPlus => {
                let (g, extra) = match h.kind {
                    HoleKind::Drill if h.dwell_s > 0.0 => ("G82", format!(" P{ms}")),
                    HoleKind::Drill => ("G81", String::new()),
                    HoleKind::Deep(q) => ("G83", format!(" Q{}", self.plain(q / self.k, self.ld))),
                    HoleKind::ChipBreak(q) => {
                        ("G73", format!(" Q{}", self.plain(q / self.k, self.ld)))
                    }
                    HoleKind::Tap { cw, .. } => (
                        if cw { "G84" } else { "G74" },
                        if h.dwell_s > 0.0 {
                            format!(" P{ms}")
                        } else {
                            String::new()
                        },
                    ),
                    HoleKind::Bore if h.dwell_s > 0.0 => ("G89", format!(" P{ms}")),
                    HoleKind::Bore => ("G85", String::new()),
                };
                let s = format!(
                    "G98 {g} X{} Y{} Z{} R{}{extra} {f}",
                    self.len(x),
                    self.len(y),
                    self.len(bottom),
                    self.len(r)
                );
                self.push(s);
                self.push("G80");
            }
            Dialect::Sinumerik => {
                self.push(f);
                let (rtp, rfp, sdis, dp) = (
                    self.plain(level / self.k, self.ld),
                    self.plain(top / self.k, self.ld),
                    self.plain(h.clearance_mm / self.k, self.ld),
                    self.plain(bottom / self.k, self.ld),
                );
                let dtb = self.plain(h.dwell_s, 3);
                let call = match h.kind {
                    HoleKind::Drill if h.dwell_s > 0.0 => {
                        format!("CYCLE82({rtp},{rfp},{sdis},{dp},,{dtb})")
                    }
                    HoleKind::Drill => format!("CYCLE81({rtp},{rfp},{sdis},{dp},)"),
                    HoleKind::Deep(q) | HoleKind::ChipBreak(q) => {
                        let vari = u8::from(matches!(h.kind, HoleKind::Deep(_)));
                        let fdep = self.plain((top - q) / self.k, self.ld);
                        let fdpr = self.plain(q / self.k, self.ld);
                        format!(
                            "CYCLE83({rtp},{rfp},{sdis},{dp},,{fdep},{fdpr},0,{dtb},0,1,{vari})"
                        )
                    }
                    HoleKind::Tap { rpm, cw } => {
                        let pitch = h.feed_mm_min / rpm / self.k;
                        let pit = self.plain(if cw { pitch } else { -pitch }, 4);
                        let sst = self.plain(rpm, 0);
                        let sdac = if cw { 3 } else { 4 };
                        format!(
                            "CYCLE84({rtp},{rfp},{sdis},{dp},,{dtb},{sdac},0,{pit},0,{sst},{sst})"
                        )
                    }
                    HoleKind::Bore => {
                        let ff = self.feed_word(h.feed_mm_min)[1..].to_string();
                        format!("CYCLE85({rtp},{rfp},{sdis},{dp},,{dtb},{ff},{ff})")
                    }
                };
                self.push(call);
            }
            _ => {
                let fq = self.feed_word(h.feed_mm_min)[1..].to_string();
                let q = |n: u32, v: String| format!("Q{n}={v}");
                let l = |v: f64| self.len(v);
                let mut params = vec![
                    q(200, l(h.clearance_mm)),
                    q(201, l(-h.depth_mm)),
                    q(206, format!("+{fq}")),
                ];
                let (g, name) = match h.kind {
                    HoleKind::Drill | HoleKind::Deep(_) => {
                        let plunge = match h.kind {
                            HoleKind::Deep(p) => p,
                            _ => h.depth_mm,
                        };
                        params.push(q(202, l(plunge)));
                        params.push(q(210, "+0".into()));
                        ("G200", "DRILLING")
                    }
                    HoleKind::ChipBreak(p) => {
                        params.push(q(202, l(p)));
                        params.push(q(210, "+0".into()));
                        ("G203", "UNIVERSAL DRILLING")
                    }
                    HoleKind::Tap { .. } => ("G206", "TAPPING"),
                    HoleKind::Bore => ("G201", "REAMING"),
                };
                params.push(q(203, l(top)));
                params.push(q(204, l(h.return_mm)));
                match h.kind {
                    HoleKind::ChipBreak(_) => {
                        params.push(q(212, "+0".into()));
                        params.push(q(213, "+99".into()));
                        params.push(q(205, "+0".into()));
                        params.push(q(211, self.st.render(h.dwell_s, 3)));
                        params.push(q(208, "+0".into()));
                        params.push(q(256, l(HEIDENHAIN_CHIP_BREAK_MM)));
                    }
                    HoleKind::Bore => {
                        params.push(q(211, self.st.render(h.dwell_s, 3)));
                        params.push(q(208, format!("+{fq}")));
                    }
                    _ => params.push(q(211, self.st.render(h.dwell_s, 3))),
                }
                self.push(format!("{g} {name}"));
                for p in params {
                    self.push(p);
                }
                self.push("G79");
            }
        }
        // The cycle's feed is modal on some controllers: the next feed move restates F.
        self.feed = None;
        self.motion = None;
        self.pos = Some([x, y, level]);
    }
}

pub use crate::settings::HEIDENHAIN_CHIP_BREAK_MM;

/// The program's bytes.
pub fn emit(items: &[Item], o: &EmitOptions) -> Vec<u8> {
    let mut w = Writer {
        o,
        st: style(o.dialect),
        k: if o.inch { 25.4 } else { 1.0 },
        ld: o.linear_decimals,
        lines: Vec::with_capacity(items.len() + 8),
        feed: None,
        motion: None,
        tcpm: Tcpm::Off,
        length_comp: false,
        length_offset: 1,
        comp_pending: None,
        pos: None,
        rotary: None,
        plane: None,
    };
    for item in items {
        match item {
            Item::Move(q) => w.straight(q),
            Item::Arc(a) => w.arc(a),
            Item::Hole(h) => w.hole(h),
            Item::ToolChange {
                tool,
                length_offset,
            } => {
                w.tcpm_off();
                match o.dialect {
                    Dialect::Sinumerik => {
                        w.push(format!("T{tool} M6"));
                        w.push("D1");
                    }
                    Dialect::Fanuc | Dialect::MillPlus => {
                        if w.length_comp {
                            w.push("G49");
                        }
                        w.push(format!("T{tool} M6"));
                    }
                    _ => w.push(format!("T{tool} G17")),
                }
                w.length_comp = false;
                w.length_offset = *length_offset;
                w.motion = None;
                w.pos = None;
            }
            Item::Spindle(s) => {
                let line = match s {
                    Spindle::Cw(rpm) => format!("S{} M3", rpm.round()),
                    Spindle::Ccw(rpm) => format!("S{} M4", rpm.round()),
                    Spindle::Off => "M5".into(),
                };
                w.push(line);
            }
            Item::Coolant(c) => w.push(match c {
                Coolant::Flood => "M8",
                Coolant::Mist => "M7",
                Coolant::Off => "M9",
            }),
            Item::Comp(c) => w.comp_pending = Some(*c),
            Item::Dwell(s) => {
                let t = w.plain(*s, 3);
                w.push(match o.dialect {
                    Dialect::Fanuc | Dialect::MillPlus => format!("G04 X{t}"),
                    Dialect::Sinumerik => format!("G4 F{t}"),
                    _ => format!("G04 F{t}"),
                });
                w.motion = None;
            }
            Item::Stop(optional) => {
                w.push(if *optional { "M01" } else { "M00" });
                w.motion = None;
            }
            Item::Raw(text) => {
                w.push(format!("{RAW}{text}"));
                w.motion = None;
                w.feed = None;
                w.pos = None;
                w.rotary = None;
            }
            Item::Comment(c) => {
                let c = clean(c);
                w.push(match o.dialect {
                    Dialect::Fanuc | Dialect::MillPlus => format!("({c})"),
                    _ => format!("; {c}"),
                });
            }
        }
    }
    w.tcpm_off();
    frame(&w.lines, o)
}

/// The program around its body lines: header, comments, units, end.
fn frame(body: &[String], o: &EmitOptions) -> Vec<u8> {
    let name = clean(&o.name);
    let mut out = String::new();
    match o.dialect {
        Dialect::Heidenhain | Dialect::Conversational | Dialect::Auto => {
            let units = if o.inch { "G70" } else { "G71" };
            let mut n = 0u64;
            out.push_str(&format!("%{name} {units} *\n"));
            let lines = o
                .comments
                .iter()
                .map(|c| format!("; {}", clean(c)))
                .chain(std::iter::once("G90".to_string()))
                .chain(body.iter().cloned())
                .chain(std::iter::once("M30".to_string()))
                .collect::<Vec<_>>();
            for (k, b) in lines.iter().enumerate() {
                if let Some(raw) = b.strip_prefix(RAW) {
                    out.push_str(raw);
                    out.push('\n');
                    continue;
                }
                // A cycle definition's parameter lines (`Q200=…`) continue its block: no
                // N, and the block's `*` after the last one.
                if b.starts_with('Q') {
                    out.push_str(b);
                } else {
                    n += 10;
                    out.push_str(&format!("N{n} {b}"));
                }
                let continued = lines.get(k + 1).is_some_and(|s| s.starts_with('Q'));
                out.push_str(if continued { "\n" } else { " *\n" });
            }
            out.push_str(&format!("N999999 %{name} {units} *\n"));
        }
        Dialect::Sinumerik => {
            out.push_str(&format!("; {name}\n"));
            for c in &o.comments {
                out.push_str(&format!("; {}\n", clean(c)));
            }
            out.push_str(if o.inch { "G90 G700\n" } else { "G90 G71\n" });
            for b in body {
                out.push_str(b.strip_prefix(RAW).unwrap_or(b));
                out.push('\n');
            }
            out.push_str("M30\n");
        }
        Dialect::Fanuc | Dialect::MillPlus => {
            out.push_str(&format!("%\nO1000 ({name})\n"));
            for c in &o.comments {
                out.push_str(&format!("({})\n", clean(c)));
            }
            out.push_str(if o.inch { "G90 G20\n" } else { "G90 G21\n" });
            for b in body {
                out.push_str(b.strip_prefix(RAW).unwrap_or(b));
                out.push('\n');
            }
            out.push_str("M30\n%\n");
        }
    }
    out.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{modal, parse, runs};

    fn pt(xyz: [f64; 3], p: f64, c: f64, feed: Option<f64>, rapid: bool) -> Item {
        Item::Move(EmitPoint {
            xyz_mm: xyz,
            p_deg: p,
            c_deg: c,
            feed_mm_min: feed,
            rapid,
            tcpm: true,
        })
    }

    fn pts() -> Vec<Item> {
        vec![
            pt([0.0, 0.0, 50.0], 10.0, -5.0, None, true),
            pt([1.25, 0.5, -8.0], 14.825, 137.259, Some(2000.0), false),
            pt([2.0, 0.5, -8.0], -0.5, 400.0, Some(2000.0), false),
        ]
    }

    fn opts(dialect: Dialect) -> EmitOptions {
        EmitOptions {
            dialect,
            name: "T (1)".into(),
            letters: crate::modal::RotaryLetters::AC,
            rotary_decimals: 3,
            linear_decimals: 3,
            comments: vec!["from t.apt".into()],
            inch: false,
        }
    }

    const DIALECTS: [Dialect; 3] = [Dialect::Heidenhain, Dialect::Sinumerik, Dialect::Fanuc];

    /// Every dialect reads back (with the nc reader) to the same values, TCPM on, one run.
    #[test]
    fn every_dialect_reads_back() {
        for dialect in DIALECTS {
            let bytes = emit(&pts(), &opts(dialect));
            let prog = parse(bytes.clone(), Dialect::Auto).unwrap();
            assert_eq!(prog.dialect, dialect, "{}", String::from_utf8_lossy(&bytes));
            let r = runs(&prog);
            assert_eq!(r.len(), 1, "{}", String::from_utf8_lossy(&bytes));
            assert!(r[0].tcpm.is_on());
            assert_eq!(r[0].feed_mm_min, Some(2000.0));
            let last = r[0].pos.last().unwrap();
            assert_eq!(last[modal::A], Some(-0.5));
            assert_eq!(last[modal::C], Some(400.0));
            assert_eq!(last[modal::X], Some(2.0));
        }
    }

    fn vertical(xyz: [f64; 3], feed: Option<f64>, rapid: bool) -> Item {
        Item::Move(EmitPoint {
            xyz_mm: xyz,
            p_deg: 0.0,
            c_deg: 0.0,
            feed_mm_min: feed,
            rapid,
            tcpm: false,
        })
    }

    fn hole(x: f64, kind: HoleKind) -> Item {
        Item::Hole(EmitHole {
            top_mm: [x, 10.0, 0.0],
            depth_mm: 12.0,
            clearance_mm: 2.0,
            return_mm: 5.0,
            feed_mm_min: 150.0,
            dwell_s: 0.0,
            kind,
        })
    }

    /// A program with every item: tool change, spindle, coolant, TCPM moves, a vertical
    /// section with cutter compensation and an arc, holes of every kind, dwell, stops.
    fn everything() -> Vec<Item> {
        let mut v = vec![
            Item::Comment("op 1".into()),
            Item::ToolChange {
                tool: 4,
                length_offset: 14,
            },
            Item::Spindle(Spindle::Cw(2000.0)),
            Item::Coolant(Coolant::Flood),
        ];
        v.extend(pts());
        v.push(pt([2.0, 0.5, 20.0], 0.0, 0.0, None, true));
        v.push(Item::Comp(Comp::Left(4)));
        v.push(vertical([10.0, 0.0, -2.0], Some(600.0), false));
        v.push(Item::Arc(EmitArc {
            end_mm: [0.0, -10.0, -2.0],
            center_mm: [0.0, 0.0, -2.0],
            start_mm: [10.0, 0.0, -2.0],
            plane: ArcPlane::Xy,
            ccw: false,
            feed_mm_min: 600.0,
            tcpm: false,
        }));
        v.push(Item::Comp(Comp::Off));
        v.push(vertical([0.0, -15.0, -2.0], Some(600.0), false));
        v.push(Item::Arc(EmitArc {
            end_mm: [5.0, -15.0, 3.0],
            center_mm: [5.0, -15.0, -2.0],
            start_mm: [0.0, -15.0, -2.0],
            plane: ArcPlane::Zx,
            ccw: true,
            feed_mm_min: 300.0,
            tcpm: true,
        }));
        v.push(vertical([0.0, 10.0, 30.0], None, true));
        for (k, kind) in [
            HoleKind::Drill,
            HoleKind::Deep(3.0),
            HoleKind::ChipBreak(2.0),
            HoleKind::Tap {
                rpm: 500.0,
                cw: true,
            },
            HoleKind::Bore,
        ]
        .into_iter()
        .enumerate()
        {
            v.push(hole(k as f64 * 20.0, kind));
        }
        v.push(Item::Dwell(1.5));
        v.push(Item::Stop(true));
        v.push(pt([0.0, 0.0, 50.0], 30.0, 90.0, Some(1000.0), false));
        v.push(Item::Spindle(Spindle::Off));
        v.push(Item::Coolant(Coolant::Off));
        v.push(Item::Stop(false));
        v
    }

    /// Issue 16: every construct the post writes is read back by the nc reader without an
    /// error, in every dialect and in both units; the TCPM moves form runs with their
    /// values, and nothing else does.
    #[test]
    fn every_construct_reads_back() {
        for dialect in DIALECTS {
            for inch in [false, true] {
                let o = EmitOptions {
                    inch,
                    linear_decimals: if inch { 4 } else { 3 },
                    ..opts(dialect)
                };
                let bytes = emit(&everything(), &o);
                let text = String::from_utf8_lossy(&bytes).into_owned();
                let prog = parse(bytes, Dialect::Auto)
                    .unwrap_or_else(|e| panic!("{dialect:?} inch {inch}: {e}\n{text}"));
                assert_eq!(prog.dialect, dialect, "{text}");
                let r = runs(&prog);
                // The TCPM straight moves at feed: one run of the two cutting blocks.
                let tcpm_runs: Vec<_> = r
                    .iter()
                    .filter(|r| r.tcpm.is_on() && r.pos.len() > 1)
                    .collect();
                assert!(!tcpm_runs.is_empty(), "{text}");
                let x = tcpm_runs[0].pos.last().unwrap()[modal::X].unwrap();
                // Within half the last written digit (0.0001 inch = 0.00254 mm).
                assert!(
                    (x - 2.0).abs() < 1.3e-3,
                    "{dialect:?} inch {inch}: {x}\n{text}"
                );
                // No straight feed move between the holes: between the first cycle line
                // and the last, only rapids, cycle lines and parameters.
                let lines: Vec<&str> = text.lines().collect();
                let is_cycle = |l: &&str| {
                    ["G81", "G83", "G73", "G84", "G85", "CYCLE8", "G79"]
                        .iter()
                        .any(|c| l.contains(c))
                };
                let first = lines.iter().position(is_cycle).unwrap();
                let last = lines.iter().rposition(is_cycle).unwrap();
                for l in &lines[first..=last] {
                    assert!(!l.contains("G01") && !l.contains("G1 "), "{l}\n{text}");
                }
                // One cycle call per hole, five holes.
                let cycles = lines.iter().filter(|l| is_cycle(l)).count();
                assert_eq!(cycles, 5, "{text}");
            }
        }
    }

    #[test]
    fn fanuc_holes_and_arcs_as_written() {
        let bytes = emit(&everything(), &opts(Dialect::Fanuc));
        let text = String::from_utf8(bytes).unwrap();
        for want in [
            "T4 M6",
            "S2000 M3",
            "M8",
            "G43.4 H14",
            "G43 H14",
            "G41 D4 G01 X10. Y0. Z-2. A0. C0. F600.",
            "G17 G02 X0. Y-10. Z-2. I-10. J0.",
            "G40 G01 X0. Y-15. Z-2. A0. C0.",
            "G18 G03 X5. Y-15. Z3. K0. I5. F300.",
            "G98 G81 X0. Y10. Z-12. R2. F150.",
            "G80",
            "G98 G83 X20. Y10. Z-12. R2. Q3. F150.",
            "G98 G73 X40. Y10. Z-12. R2. Q2. F150.",
            "G98 G84 X60. Y10. Z-12. R2. F150.",
            "G98 G85 X80. Y10. Z-12. R2. F150.",
            "G04 X1.5",
            "M01",
            "G49\nM30",
        ] {
            assert!(text.contains(want), "{want}\n{text}");
        }
        // Between holes: up to the return level (5 above the top), across, never down
        // below it.
        assert!(text.contains("X0. Y10. Z5. A0. C0.\nG98 G81"), "{text}");
        assert!(
            text.contains("G80\nG00 X20. Y10. Z5. A0. C0.\nG98 G83"),
            "{text}"
        );
    }

    #[test]
    fn heidenhain_cycle_definitions_are_one_block() {
        let bytes = emit(&everything(), &opts(Dialect::Heidenhain));
        let text = String::from_utf8(bytes).unwrap();
        assert!(
            text.contains(
                "G200 DRILLING\nQ200=+2\nQ201=-12\nQ206=+150\nQ202=+12\nQ210=+0\nQ203=+0\nQ204=+5\nQ211=+0 *\nN"
            ),
            "{text}"
        );
        assert!(
            text.contains("I+0 J+0 *\nN"),
            "the circle centre block: {text}"
        );
        assert!(
            text.contains("G02 X+0 Y-10 Z-2 *"),
            "the feed is modal: {text}"
        );
        assert!(text.contains(" T4 G17 *"), "{text}");
        // Inch: G70 and F in 0.1 inch/min.
        let bytes = emit(
            &pts(),
            &EmitOptions {
                inch: true,
                linear_decimals: 4,
                ..opts(Dialect::Heidenhain)
            },
        );
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.starts_with("%T _1_ G70 *"), "{text}");
        assert!(
            text.contains("F787.4"),
            "2000 mm/min = 78.74 inch/min: {text}"
        );
    }
}
