//! `polepatch post`: a CL program (G16's stage 1, [`polepatch_cl`]) → joints by the
//! machine's inverse kinematics → an NC program in a chosen dialect ([`polepatch_nc::emit`])
//! → (unless asked not to) the one patch pipeline, [`crate::patch_nc`], on that program.
//!
//! A post-processor is judged on one rule: every record that changes what the machine
//! does is posted correctly or refused with its line and column, naming it. Here:
//!
//! - straight and rapid moves: X Y Z and the joints of the tool axis, under TCPM;
//! - arcs: `G2`/`G3` when the arc lies in a principal plane (within `arc_tolerance_mm`)
//!   with a fixed tool axis and a sweep of at most one turn (a helix along the plane's
//!   normal included; Heidenhain: the XY plane only, no helix); otherwise, or with `linearize`, chords within `arc_tolerance_mm` of the true
//!   arc (the tool axis turned along the arc by great-circle interpolation), which the pole
//!   analysis and patch then see like any other points;
//! - holes of canned cycles and moves under cutter compensation: with the tool along +Z
//!   only. The rotary axes are first put at P 0, C 0 under TCPM (the tool tip stays where
//!   it is), TCPM is switched off, and the cycles / G41–G42 are the plain 3-axis ones of
//!   the dialect. A tilted hole, or a tool axis other than +Z under compensation, is
//!   refused (no tilted working plane or 3D compensation is written);
//! - tool change, spindle, coolant, dwell, stops, comments: the dialect's words.
//!
//! The program is written first exactly as the IK gives it (`patch: false` stops there),
//! then patched like any other program, so `post` and `patch` can never disagree.

use crate::error::Error;
use crate::report::FileReport;
pub use crate::settings::ARC_TOLERANCE_MM;
pub use crate::tolerances::SAME_AXIS_TOL;
use polepatch_cl::{
    Arc, ClError, ClItem, ClPoint, ClProgram, CompSide, Coolant, CycleKind, MoveKind, ParseOptions,
    Plane, SpindleDir, Units,
};
use polepatch_kinematics::{BranchRule, IkSolution, Machine, inverse, inverse_path_from};
use polepatch_nc::Dialect;
use polepatch_nc::emit::{
    self, ArcPlane, Comp, EmitArc, EmitHole, EmitOptions, EmitPoint, HoleKind, Item, Spindle, emit,
};

/// Options of [`post_cl`]. Plain struct; see each field for its default.
#[derive(Debug, Clone, PartialEq)]
pub struct PostOptions {
    /// Dialect written. Default Heidenhain ISO.
    pub dialect: Dialect,
    /// IK branch rule. Default [`BranchRule::Nearest`].
    pub branch: BranchRule,
    /// Patch the posted program (default `true`); `false` writes the joints as the IK
    /// gives them.
    pub patch: bool,
    /// Options of the patch (name, feed fallback for points without a feed, …).
    pub patch_options: crate::options::PatchOptions,
    /// Decimals of rotary words. Default 3.
    pub rotary_decimals: usize,
    /// Decimals of linear words in mm (inch output writes one more). Default 3.
    pub linear_decimals: usize,
    /// Units written (`None`: the CL file's). Default `None`.
    pub units: Option<Units>,
    /// Write every arc as chords (default `false`: `G2`/`G3` where the module docs say).
    pub linearize: bool,
    /// Chordal tolerance of arcs written as chords, and how far an arc may leave a
    /// principal plane to be written as `G2`/`G3`, mm. Default [`ARC_TOLERANCE_MM`].
    pub arc_tolerance_mm: f64,
}

impl Default for PostOptions {
    fn default() -> Self {
        PostOptions {
            dialect: Dialect::Heidenhain,
            branch: BranchRule::Nearest,
            patch: true,
            patch_options: crate::options::PatchOptions::default(),
            rotary_decimals: 3,
            linear_decimals: 3,
            units: None,
            linearize: false,
            arc_tolerance_mm: ARC_TOLERANCE_MM,
        }
    }
}

/// Read a CL file (APT or CSV, [`polepatch_cl::parse_with`]); errors name `name`, the line
/// and the column.
pub fn read_cl_with(bytes: &[u8], name: &str, opts: &ParseOptions) -> Result<ClProgram, Error> {
    polepatch_cl::parse_with(bytes, opts).map_err(|record| Error::Cl {
        path: name.to_string(),
        record,
    })
}

/// [`read_cl_with`] with the default options.
pub fn read_cl(bytes: &[u8], name: &str) -> Result<ClProgram, Error> {
    read_cl_with(bytes, name, &ParseOptions::default())
}

/// Read a CL file to post it on `machine` with `opts`, skipping the records `parse.ignore`
/// names by the one rule of `--ignore`: **a record refused in this file may be skipped**.
///
/// A kind polepatch never posts (`THREAD`, `TRACUT`, …: every one is refused) or does not
/// count as posted (`INSERT`) is skipped wherever it is. A kind it posts
/// ([`polepatch_cl::apt::POSTED`]: `CUTCOM`, `COOLNT`, …) is skipped only where the file
/// holds one that is refused — the reader's or the post's refusal naming that kind
/// ([`ClError::refused_record`]: `CUTCOM/LEFT` with the tool along X) — and then every
/// record of the kind is skipped (the moves are posted at the CL points without
/// compensation), with the refusal kept in [`polepatch_cl::Skipped::refused`] for
/// [`skip_notes`]. Asking to skip a posted kind of which every record here is posted is
/// an error naming it: those records would be dropped, not refused.
///
/// Where a posted kind is asked for, the file is read and its items posted (without the
/// patch) once, plus once per posted kind whose refusal is found; else it is read once.
pub fn read_cl_for_post(
    bytes: &[u8],
    name: &str,
    parse: &ParseOptions,
    machine: &Machine,
    opts: &PostOptions,
) -> Result<ClProgram, Error> {
    parse
        .check()
        .map_err(|m| Error::Options(crate::error::OptionError::with_message("parse", m)))?;
    let asked: Vec<String> = parse
        .ignore
        .iter()
        .map(|w| w.trim().to_ascii_uppercase())
        .collect();
    let posted = |w: &str| polepatch_cl::apt::POSTED.contains(&w);
    // The kinds skipped so far, and the refusals that let the posted ones be skipped.
    let mut skip: Vec<String> = asked.iter().filter(|w| !posted(w)).cloned().collect();
    if skip.len() == asked.len() {
        // Nothing to prove: the post reads the file once.
        let attempt = ParseOptions {
            ignore: skip,
            ..parse.clone()
        };
        return read_cl_with(bytes, name, &attempt);
    }
    let mut refusals: Vec<(String, String)> = Vec::new();
    loop {
        let attempt = ParseOptions {
            ignore: skip.clone(),
            ..parse.clone()
        };
        let read = read_cl_with(bytes, name, &attempt);
        let result = read.and_then(|cl| post_items(&cl, machine, opts).map(|_| cl));
        match result {
            Ok(mut cl) => {
                if let Some(w) = asked
                    .iter()
                    .find(|w| posted(w) && !skip.contains(w) && cl.records.contains_key(*w))
                {
                    return Err(crate::error::OptionError::with_message("--ignore", format!(
                        "--ignore {w}: polepatch posts the {} {w} record(s) of {name}; only records it refuses in the file can be skipped",
                        cl.records[w]
                    )).into());
                }
                for (w, why) in refusals {
                    if let Some(s) = cl.skipped.get_mut(&w) {
                        s.refused = Some(why);
                    }
                }
                return Ok(cl);
            }
            Err(Error::Cl { path, record }) => match &record.refused_record {
                Some(w) if asked.contains(w) && !skip.contains(w) => {
                    // The refusal, without its hint of the way out just taken.
                    let message = record.message.split(" (--ignore ").next().unwrap_or("");
                    refusals.push((
                        w.clone(),
                        format!("line {}, col {}: {message}", record.line, record.column),
                    ));
                    skip.push(w.clone());
                }
                _ => return Err(Error::Cl { path, record }),
            },
            Err(e) => return Err(e),
        }
    }
}

/// What became of the records `--ignore` skipped, one line per kind for the report and the
/// user: how many, where the first is, why they could be skipped (the refusal of a kind
/// polepatch posts) and what the program then does without them.
pub fn skip_notes(cl: &ClProgram, name: &str) -> Vec<String> {
    cl.skipped
        .iter()
        .map(|(w, s)| {
            let why = s.refused.as_ref().map_or(String::new(), |r| {
                format!("; without it the post refused {r}")
            });
            let then = match w.as_str() {
                "CUTCOM" => "; the moves are posted at the CL points without cutter compensation",
                "COOLNT" => "; no coolant words are written for them",
                "DELAY" => "; no dwells are written for them",
                "INSERT" => "; their text is not written into the program",
                _ => "",
            };
            format!(
                "{name}: {} {w} record(s) skipped (--ignore {w}), the first at line {}{why}{then}",
                s.count, s.first.line
            )
        })
        .collect()
}

/// What is being written: 5-axis under TCPM, or with the tool along +Z and TCPM off
/// (holes, cutter compensation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Frame {
    Tcpm,
    Vertical,
}

/// Why the tool must be vertical: a hole's cycle or the cutter compensation.
#[derive(Debug, Clone)]
struct VerticalReason {
    what: String,
    line: usize,
    column: usize,
}

/// The post's state while it walks the CL items.
struct Poster<'a> {
    machine: &'a Machine,
    opts: &'a PostOptions,
    items: Vec<Item>,
    /// The last IK solution (C continuity), in the program's terms.
    prev: Option<IkSolution>,
    /// Tool tip after the last move, mm.
    pos: Option<[f64; 3]>,
    /// P and C after the last move.
    rotary: Option<(f64, f64)>,
    frame: Frame,
    /// Cutter compensation on (since which CUTCOM record), and whether the next move is the
    /// cancel move after `CUTCOM/OFF` (still vertical).
    comp: Option<VerticalReason>,
    comp_cancel_pending: Option<VerticalReason>,
    /// A compensation start waiting for its first straight move.
    comp_start_pending: Option<VerticalReason>,
    tool: Option<u32>,
    spindle: Option<(f64, SpindleDir)>,
}

fn cl_error(name: &str, line: usize, column: usize, message: String) -> Error {
    Error::Cl {
        path: name.to_string(),
        record: ClError {
            line,
            column,
            message,
            refused_record: None,
        },
    }
}

/// The refusal of a form of cutter compensation polepatch does not post, at `at`: a refusal
/// of the `CUTCOM` records ([`ClError::refused_record`]), which `--ignore CUTCOM` answers by
/// posting the moves at the CL points without compensation.
fn comp_refusal(name: &str, line: usize, column: usize, message: String) -> Error {
    Error::Cl {
        path: name.to_string(),
        record: ClError {
            line,
            column,
            message: format!(
                "{message} (--ignore CUTCOM posts the moves at the CL points without compensation)"
            ),
            refused_record: Some("CUTCOM".into()),
        },
    }
}

impl Poster<'_> {
    fn name(&self) -> &str {
        &self.opts.patch_options.read.name
    }

    /// An error at CL point `p`'s record.
    fn at_point(&self, p: &ClPoint, what: String) -> Error {
        cl_error(self.name(), p.line, p.column, what)
    }

    /// The joints of tool axis `axis` for the move of CL point `src`, continuing from the
    /// last point.
    fn joints(&mut self, axis: [f64; 3], src: &ClPoint) -> Result<IkSolution, Error> {
        let s = inverse_path_from(self.machine, &[axis], self.opts.branch, self.prev)[0];
        let (lo, hi) = self.machine.primary_range_deg;
        if !(lo <= s.p_deg && s.p_deg <= hi) {
            return Err(self.at_point(
                src,
                format!(
                    "the tool axis ({:.6}, {:.6}, {:.6}) needs {}{:.3}, outside the machine's range [{lo}, {hi}] on either IK branch",
                    axis[0],
                    axis[1],
                    axis[2],
                    self.machine.primary_letter(),
                    s.p_deg
                ),
            ));
        }
        self.prev = Some(s);
        Ok(s)
    }

    /// The tool must be along +Z here (on the pole, P = 0): else refused naming why.
    fn check_vertical(
        &self,
        axis: [f64; 3],
        line: usize,
        why: &VerticalReason,
    ) -> Result<(), Error> {
        if inverse(self.machine, axis).is_none() && axis[2] > 0.0 {
            return Ok(());
        }
        let comp = why.what.starts_with("CUTCOM");
        let message = format!(
            "{}: the tool axis ({:.6}, {:.6}, {:.6}) at line {line} is not +Z; polepatch posts {} with the tool along +Z only (no tilted working plane — PLANE, CYCLE800, G68.2 — and no 3D compensation is written): refused",
            why.what,
            axis[0],
            axis[1],
            axis[2],
            if comp {
                "cutter compensation"
            } else {
                "canned cycles"
            }
        );
        Err(if comp {
            comp_refusal(self.name(), why.line, why.column, message)
        } else {
            cl_error(self.name(), why.line, why.column, message)
        })
    }

    /// Into the vertical frame: the rotary axes to P 0, C 0 under TCPM at the current tool
    /// tip (the tip stays; only the orientation may turn), then TCPM off (by the emitter).
    fn enter_vertical(&mut self) {
        if self.frame == Frame::Vertical {
            return;
        }
        if let Some(pos) = self.pos
            && self.rotary != Some((0.0, 0.0))
        {
            self.items.push(Item::Move(EmitPoint {
                xyz_mm: pos,
                p_deg: 0.0,
                c_deg: 0.0,
                feed_mm_min: None,
                rapid: true,
                tcpm: true,
            }));
        }
        self.rotary = Some((0.0, 0.0));
        self.prev = Some(IkSolution {
            p_deg: 0.0,
            c_deg: 0.0,
        });
        self.frame = Frame::Vertical;
    }

    /// The feed of a feed move, or the error naming its line.
    fn feed(&self, p: &ClPoint) -> Result<f64, Error> {
        p.feed_mm_min
            .or(self.opts.patch_options.read.feed_fallback_mm_min)
            .ok_or_else(|| {
                self.at_point(
                    p,
                    "no feed for this move (no FEDRAT before it, no f column): give --feed".into(),
                )
            })
    }

    /// The reason the next straight move must be vertical, if any.
    fn vertical_reason(&self) -> Option<VerticalReason> {
        self.comp
            .clone()
            .or_else(|| self.comp_cancel_pending.clone())
    }

    /// A straight move to `pos` with tool axis `axis`, for the move of CL point `src`.
    fn straight(
        &mut self,
        pos: [f64; 3],
        axis: [f64; 3],
        feed: Option<f64>,
        rapid: bool,
        src: &ClPoint,
    ) -> Result<(), Error> {
        let (p_deg, c_deg, tcpm) = match self.vertical_reason() {
            Some(why) => {
                self.check_vertical(axis, src.line, &why)?;
                self.enter_vertical();
                (0.0, 0.0, false)
            }
            None => {
                let s = self.joints(axis, src)?;
                self.frame = Frame::Tcpm;
                (s.p_deg, s.c_deg, true)
            }
        };
        self.comp_start_pending = None;
        self.comp_cancel_pending = None;
        self.items.push(Item::Move(EmitPoint {
            xyz_mm: pos,
            p_deg,
            c_deg,
            feed_mm_min: if rapid { None } else { feed },
            rapid,
            tcpm,
        }));
        self.pos = Some(pos);
        self.rotary = Some((p_deg, c_deg));
        Ok(())
    }

    fn arc(&mut self, p: &ClPoint, a: &Arc) -> Result<(), Error> {
        let feed = self.feed(p)?;
        let tol = self.opts.arc_tolerance_mm;
        let fixed_axis = (0..3).all(|i| (p.axis[i] - a.start_axis[i]).abs() <= SAME_AXIS_TOL);
        let one_turn = a.sweep_rad <= std::f64::consts::TAU * (1.0 + 1e-12);
        let heidenhain = matches!(
            self.opts.dialect,
            Dialect::Heidenhain | Dialect::Conversational | Dialect::Auto
        );
        // Heidenhain's circle in ISO programs: the XY plane, no helix (its helix is a polar
        // block polepatch does not write).
        let plane = a
            .principal_plane(tol)
            .filter(|pl| !heidenhain || (*pl == Plane::Xy && a.lead_mm.abs() <= tol));
        if let Some(why) = &self.comp_cancel_pending {
            return Err(comp_refusal(
                self.name(),
                why.line,
                why.column,
                format!(
                    "{}: the compensation would end on a circular move (line {}); controllers end it on a straight move: refused",
                    why.what, p.line
                ),
            ));
        }
        let comp = self.comp.clone();
        if let Some(why) = &comp
            && self.comp_start_pending.is_some()
        {
            return Err(comp_refusal(
                self.name(),
                why.line,
                why.column,
                format!(
                    "{}: the compensation would start on a circular move (line {}); controllers start it on a straight move: refused",
                    why.what, p.line
                ),
            ));
        }
        match plane {
            Some(pl) if !self.opts.linearize && fixed_axis && one_turn => {
                if let Some(why) = &comp
                    && pl != Plane::Xy
                {
                    return Err(comp_refusal(
                        self.name(),
                        why.line,
                        why.column,
                        format!(
                            "{}: a circular move outside the XY plane (line {}) under compensation: refused",
                            why.what, p.line
                        ),
                    ));
                }
                let Some(start) = self.pos else {
                    return Err(self.at_point(p, "an arc with no point before it".into()));
                };
                let tcpm = match self.vertical_reason() {
                    Some(why) => {
                        self.check_vertical(p.axis, p.line, &why)?;
                        self.enter_vertical();
                        false
                    }
                    None => {
                        // The orientation does not change along the arc: the joints are
                        // the start's (restated in place if the IK names them otherwise,
                        // e.g. after a vertical section).
                        let s = self.joints(p.axis, p)?;
                        if self.rotary != Some((s.p_deg, s.c_deg)) {
                            self.items.push(Item::Move(EmitPoint {
                                xyz_mm: start,
                                p_deg: s.p_deg,
                                c_deg: s.c_deg,
                                feed_mm_min: None,
                                rapid: true,
                                tcpm: true,
                            }));
                            self.rotary = Some((s.p_deg, s.c_deg));
                        }
                        self.frame = Frame::Tcpm;
                        true
                    }
                };
                let normal_axis = pl.normal_index();
                self.items.push(Item::Arc(EmitArc {
                    end_mm: p.pos_mm,
                    center_mm: a.center_mm,
                    start_mm: start,
                    plane: match pl {
                        Plane::Xy => ArcPlane::Xy,
                        Plane::Zx => ArcPlane::Zx,
                        Plane::Yz => ArcPlane::Yz,
                    },
                    ccw: a.normal[normal_axis] > 0.0,
                    feed_mm_min: feed,
                    tcpm,
                }));
                self.pos = Some(p.pos_mm);
                Ok(())
            }
            _ => {
                // Chords within the tolerance; the tool axis turns along the arc.
                let pts = a.chord_points(tol, p.pos_mm);
                let n = pts.len();
                for (k, q) in pts.into_iter().enumerate() {
                    let t = (k + 1) as f64 / n as f64;
                    let axis = if k + 1 == n {
                        p.axis
                    } else {
                        a.axis_at(t, p.axis).ok_or_else(|| {
                            self.at_point(
                                p,
                                "the tool axis turns by 180° along the arc: no unique way to turn it"
                                    .into(),
                            )
                        })?
                    };
                    self.straight(q, axis, Some(feed), false, p)?;
                }
                Ok(())
            }
        }
    }

    fn hole(&mut self, p: &ClPoint, c: &polepatch_cl::Cycle) -> Result<(), Error> {
        let why = VerticalReason {
            what: format!("CYCLE/{} (line {})", c.mode, c.at.line),
            line: c.at.line,
            column: c.at.column,
        };
        if let Some(comp) = &self.comp {
            return Err(comp_refusal(
                self.name(),
                c.at.line,
                c.at.column,
                format!("{}: a hole while {} is on: refused", why.what, comp.what),
            ));
        }
        self.check_vertical(p.axis, p.line, &why)?;
        let refuse = |m: String| cl_error(self.name(), c.at.line, c.at.column, m);
        let kind = match c.kind {
            CycleKind::Drill => HoleKind::Drill,
            CycleKind::Deep | CycleKind::ChipBreak if c.dwell_s > 0.0 => {
                return Err(refuse(format!(
                    "CYCLE/{}: DWELL on a peck-drilling cycle is not posted",
                    c.mode
                )));
            }
            CycleKind::Deep | CycleKind::ChipBreak => {
                // The reader requires STEP; a cycle built otherwise may lack it.
                let Some(peck) = c.peck_mm.filter(|p| *p > 0.0) else {
                    return Err(refuse(format!(
                        "CYCLE/{} (peck drilling) without a positive peck",
                        c.mode
                    )));
                };
                if c.kind == CycleKind::Deep {
                    HoleKind::Deep(peck)
                } else {
                    HoleKind::ChipBreak(peck)
                }
            }
            CycleKind::Tap => match self.spindle {
                Some((rpm, dir)) if dir != SpindleDir::Off => HoleKind::Tap {
                    rpm,
                    cw: dir == SpindleDir::Cw,
                },
                _ => {
                    return Err(refuse(format!(
                        "CYCLE/{}: tapping with the spindle stopped (no SPINDL/rpm,CLW|CCLW before it)",
                        c.mode
                    )));
                }
            },
            CycleKind::Bore => HoleKind::Bore,
        };
        self.enter_vertical();
        self.items.push(Item::Hole(EmitHole {
            top_mm: p.pos_mm,
            depth_mm: c.depth_mm,
            clearance_mm: c.clearance_mm,
            return_mm: c.return_mm(),
            feed_mm_min: c.feed_mm_min,
            dwell_s: c.dwell_s,
            kind,
        }));
        let [x, y, z] = p.pos_mm;
        self.pos = Some([x, y, z + c.return_mm()]);
        Ok(())
    }

    fn item(&mut self, item: &ClItem) -> Result<(), Error> {
        match item {
            ClItem::Move(p) => match &p.kind {
                MoveKind::Linear => {
                    let f = self.feed(p)?;
                    self.straight(p.pos_mm, p.axis, Some(f), false, p)
                }
                MoveKind::Rapid => self.straight(p.pos_mm, p.axis, None, true, p),
                MoveKind::Arc(a) => self.arc(p, a),
                MoveKind::Hole(c) => self.hole(p, c),
            },
            ClItem::ToolChange {
                tool,
                length_offset,
                at,
            } => {
                if let Some(why) = &self.comp {
                    return Err(comp_refusal(
                        self.name(),
                        at.line,
                        at.column,
                        format!("LOADTL while {} is on: refused", why.what),
                    ));
                }
                self.items.push(Item::ToolChange {
                    tool: *tool,
                    length_offset: *length_offset,
                });
                self.tool = Some(*tool);
                // After a tool change the tool is where the changer left it.
                self.pos = None;
                self.rotary = None;
                self.frame = Frame::Tcpm;
                Ok(())
            }
            ClItem::Spindle { rpm, dir, at } => {
                let s = match (dir, rpm) {
                    (SpindleDir::Off, _) => Spindle::Off,
                    (SpindleDir::Cw, Some(r)) => Spindle::Cw(*r),
                    (SpindleDir::Ccw, Some(r)) => Spindle::Ccw(*r),
                    // The reader gives every start its speed; a program built otherwise
                    // may not.
                    (_, None) => {
                        return Err(cl_error(
                            self.name(),
                            at.line,
                            at.column,
                            "SPINDL starts the spindle without a speed".into(),
                        ));
                    }
                };
                self.spindle = match (dir, rpm) {
                    (SpindleDir::Off, _) => None,
                    (d, Some(r)) => Some((*r, *d)),
                    _ => None,
                };
                self.items.push(Item::Spindle(s));
                Ok(())
            }
            ClItem::Coolant { mode, .. } => {
                self.items.push(Item::Coolant(match mode {
                    Coolant::Flood => emit::Coolant::Flood,
                    Coolant::Mist => emit::Coolant::Mist,
                    Coolant::Off => emit::Coolant::Off,
                }));
                Ok(())
            }
            ClItem::CutterComp { side, register, at } => self.cutcom(*side, *register, *at),
            ClItem::Dwell { seconds, .. } => {
                self.items.push(Item::Dwell(*seconds));
                Ok(())
            }
            ClItem::Stop { optional, .. } => {
                self.items.push(Item::Stop(*optional));
                Ok(())
            }
            ClItem::Comment(c) => {
                self.items.push(Item::Comment(c.clone()));
                Ok(())
            }
            ClItem::Insert { text, .. } => {
                self.items.push(Item::Raw(text.clone()));
                Ok(())
            }
            // Read for the patch ([`crate::tool::cl_tools`]); nothing to write.
            ClItem::Cutter(_) => Ok(()),
        }
    }

    fn cutcom(
        &mut self,
        side: CompSide,
        register: Option<u32>,
        at: polepatch_cl::At,
    ) -> Result<(), Error> {
        let what = format!(
            "CUTCOM/{} (line {})",
            match side {
                CompSide::Left => "LEFT",
                CompSide::Right => "RIGHT",
                CompSide::Off => "OFF",
            },
            at.line
        );
        let why = VerticalReason {
            what: what.clone(),
            line: at.line,
            column: at.column,
        };
        if side == CompSide::Off {
            if self.comp.take().is_some() {
                self.items.push(Item::Comp(Comp::Off));
                // The cancel move is still a compensated (vertical) move.
                self.comp_cancel_pending = Some(why);
            }
            return Ok(());
        }
        let fanuc = self.opts.dialect == Dialect::Fanuc;
        if let Some(r) = register
            && !fanuc
            && Some(r) != self.tool
        {
            return Err(comp_refusal(
                self.name(),
                at.line,
                at.column,
                format!(
                    "{what}: offset register {r} is not the tool's ({}); Heidenhain and Sinumerik compensate with the radius of the active tool: refused",
                    self.tool
                        .map_or("no tool loaded".to_string(), |t| format!("T{t}"))
                ),
            ));
        }
        let d = register.or(self.tool).unwrap_or(1);
        self.items.push(Item::Comp(match side {
            CompSide::Left => Comp::Left(d),
            _ => Comp::Right(d),
        }));
        self.comp_start_pending = Some(why.clone());
        self.comp = Some(why);
        Ok(())
    }
}

/// The items of the NC program for `cl` on `machine` (module docs): IK, arcs, holes,
/// set-up. Errors name the CL line (and column for a record).
pub fn post_items(
    cl: &ClProgram,
    machine: &Machine,
    opts: &PostOptions,
) -> Result<Vec<Item>, Error> {
    if !(opts.arc_tolerance_mm.is_finite() && (1e-6..=1.0).contains(&opts.arc_tolerance_mm)) {
        return Err(crate::error::OptionError::with_message(
            "arc_tolerance_mm",
            format!(
                "arc tolerance {} mm must be within 0.000001…1 mm",
                opts.arc_tolerance_mm
            ),
        )
        .into());
    }
    let mut p = Poster {
        machine,
        opts,
        items: Vec::with_capacity(cl.items.len() + 8),
        prev: None,
        pos: None,
        rotary: None,
        frame: Frame::Tcpm,
        comp: None,
        comp_cancel_pending: None,
        comp_start_pending: None,
        tool: None,
        spindle: None,
    };
    for item in &cl.items {
        p.item(item)?;
    }
    if let Some(why) = &p.comp_start_pending {
        return Err(comp_refusal(
            p.name(),
            why.line,
            why.column,
            format!(
                "{}: no move after it to start the compensation on",
                why.what
            ),
        ));
    }
    Ok(p.items)
}

/// The point of the tool a posted program's X Y Z state, where the caller did not say it:
/// the tip (APT's `GOTO/` states the tip). The patch then keeps a ball's centre and caps a
/// flat or bull-nose cutter's orientation change ([`crate::tool`]). The cutters themselves
/// are the CL file's `CUTTER/` and `TLDATA/` records, each for the tool loaded after it,
/// which [`post_cl`] reads ([`crate::tool::cl_tools`]): not a tool for the whole program,
/// and never reported as `--tool`. `_cl_bytes` (the CL file's bytes) is kept for callers.
pub fn tool_from_cl(_cl_bytes: &[u8], _cl: &ClProgram, opts: &mut PostOptions) {
    let t = &mut opts.patch_options.tool;
    if t.point.is_none() {
        t.point = Some(crate::tool::ToolPoint::Tip);
    }
}

/// The CL file's `INSERT` records in the patch report: each one where it was written (a
/// warning), and those between two moves with the primary axis within `cone_deg` on
/// either side (the reach of the pole) as lines not analysed — the text is the user's, polepatch does
/// not read what it does to the motion there.
fn list_inserts(
    cl: &ClProgram,
    items: &[Item],
    out: &[u8],
    cone_deg: f64,
    report: &mut FileReport,
) {
    let texts: Vec<(&str, usize)> = cl
        .items
        .iter()
        .filter_map(|i| match i {
            ClItem::Insert { text, at } => Some((text.as_str(), at.line)),
            _ => None,
        })
        .collect();
    if texts.is_empty() {
        return;
    }
    // The primary axis of the moves either side of each raw line, in item order.
    let mut near = Vec::with_capacity(texts.len());
    for (k, item) in items.iter().enumerate() {
        if !matches!(item, Item::Raw(_)) {
            continue;
        }
        let p = |it: &Item| match it {
            Item::Move(m) => Some(m.p_deg),
            _ => None,
        };
        let before = items[..k].iter().rev().find_map(p);
        let after = items[k + 1..].iter().find_map(p);
        // Text before the first move or after the last cuts no run.
        near.push(
            before
                .zip(after)
                .is_some_and(|(b, a)| b.abs().min(a.abs()) <= cone_deg),
        );
    }
    // Program lines of the raw lines, in order.
    let mut next = 0;
    let mut lines = Vec::with_capacity(texts.len());
    // (The post writes `\n` line ends.)
    for (n, line) in out.split(|&b| b == b'\n').enumerate() {
        if next < texts.len() && line == texts[next].0.as_bytes() {
            lines.push(n + 1);
            next += 1;
        }
    }
    for (k, &(text, cl_line)) in texts.iter().enumerate() {
        let Some(&line) = lines.get(k) else { break };
        report.warnings.push(format!(
            "{}: line {cl_line}: INSERT/{text} written as it is at line {line} of the program",
            cl_name(report)
        ));
        if near.get(k) == Some(&true) {
            report.not_analysed.push(crate::notes::NotAnalysed {
                lines: [line, line],
                reason: crate::notes::SkipReason::Insert,
                message: crate::notes::insert_message(line, cl_line),
            });
        }
    }
    report.not_analysed.sort_by_key(|n| n.lines);
}

/// The `INSERT` record (text, where) written at program line `line` of `out`, if any.
fn insert_at<'a>(
    cl: &'a ClProgram,
    out: &[u8],
    line: usize,
) -> Option<(&'a str, polepatch_cl::At)> {
    let text = out.split(|&b| b == b'\n').nth(line.checked_sub(1)?)?;
    cl.items.iter().find_map(|i| match i {
        ClItem::Insert { text: t, at } if t.as_bytes() == text => Some((t.as_str(), *at)),
        _ => None,
    })
}

fn cl_name(report: &FileReport) -> &str {
    &report.file
}

/// Post a CL program for `machine`: the NC bytes and, when patched, the patch report
/// (`None` with `patch: false`, or when the program has no G1 run for the patch to look at:
/// holes and rapids only).
pub fn post_cl(
    cl: &ClProgram,
    machine: &Machine,
    opts: &PostOptions,
) -> Result<(Vec<u8>, Option<FileReport>), Error> {
    if opts.dialect == Dialect::MillPlus {
        return Err(crate::error::OptionError::with_message(
            "dialect",
            "MillPlus programs are read, not written: post for heidenhain, sinumerik or fanuc",
        )
        .into());
    }
    let inch = opts.units.unwrap_or(cl.units) == Units::Inch;
    if inch
        && matches!(
            opts.dialect,
            Dialect::Heidenhain | Dialect::Conversational | Dialect::Auto
        )
    {
        let why = "inch output for Heidenhain is not written: Heidenhain inch programs take F in 0.1 inch/min, which polepatch's reader does not read; post in mm (--units mm)";
        // At the CL file's units record when the inches are the file's, else the option's.
        return Err(match (opts.units, cl.units_at) {
            (None, Some(at)) => cl_error(
                &opts.patch_options.read.name,
                at.line,
                at.column,
                format!("the CL file is in inches (this record): {why}"),
            ),
            _ => crate::error::OptionError::with_message("units", format!("--units inch: {why}"))
                .into(),
        });
    }
    let items = post_items(cl, machine, opts)?;
    let program_name = cl
        .name
        .clone()
        .unwrap_or_else(|| "POLEPATCH".to_string())
        .split_whitespace()
        .next()
        .unwrap_or("POLEPATCH")
        .to_string();
    let mut comments = vec![format!(
        "posted by polepatch for {} from {}",
        machine.name, opts.patch_options.read.name
    )];
    for (w, n) in &cl.skipped {
        comments.push(format!(
            "{w} records skipped by --ignore {w}: {}, the first at line {}",
            n.count, n.first.line
        ));
    }
    // The writer writes the machine's own letters, among A B C.
    let (p, c) = (machine.primary_letter(), machine.c_letter());
    let Some(letters) =
        polepatch_nc::RotaryLetters::new(p as u8, c as u8).filter(|_| p.is_ascii() && c.is_ascii())
    else {
        return Err(Error::machine(
            &machine.name,
            format!(
                "its rotary axes are called {p} and {c}; post writes rotary words A, B \
                 and C so far (issue 29), so it would write words for axes the machine does not \
                 have"
            ),
        ));
    };
    let bytes = emit(
        &items,
        &EmitOptions {
            dialect: opts.dialect,
            name: program_name,
            letters,
            rotary_decimals: opts.rotary_decimals,
            linear_decimals: opts.linear_decimals + usize::from(inch),
            comments,
            inch,
        },
    );
    if !opts.patch {
        return Ok((bytes, None));
    }
    // The CL file's cutters, by the tool each is for, as the program's own description
    // (the written program does not carry them).
    let mut patch_options = std::borrow::Cow::Borrowed(&opts.patch_options);
    if patch_options.tool.cl.is_empty() {
        let tools = crate::tool::cl_tools(cl);
        if !tools.is_empty() {
            patch_options.to_mut().tool.cl = tools;
        }
    }
    match crate::entry::patch_nc(&bytes, machine, &patch_options) {
        Ok((out, mut report)) => {
            report
                .warnings
                .extend(skip_notes(cl, &opts.patch_options.read.name));
            list_inserts(
                cl,
                &items,
                &out,
                opts.patch_options.patch.reach_deg(),
                &mut report,
            );
            Ok((out, Some(report)))
        }
        // An INSERT's text the reader cannot read: said at its CL line.
        Err(Error::Parse(e)) if insert_at(cl, &bytes, e.line).is_some() => {
            let (text, at) = insert_at(cl, &bytes, e.line).expect("matched");
            Err(cl_error(
                &opts.patch_options.read.name,
                at.line,
                at.column,
                format!(
                    "INSERT/{text}: its text, written as it is at line {} of the program, is not \
                     an NC block polepatch can read ({}); skip INSERT records with --ignore INSERT",
                    e.line, e.message
                ),
            ))
        }
        // A program of holes and rapids only: nothing for the patch to look at.
        Err(Error::NoRuns { .. }) => Ok((bytes, None)),
        Err(e) => Err(e),
    }
}
