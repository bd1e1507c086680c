//! Canned cycles: `CYCLE/mode,…` … `CYCLE/OFF`. While a cycle is on, every `GOTO` is a
//! hole: the point is the top of the hole and the tool axis its axis.
//!
//! Read (the APT form CAMWorks, NCL and SolidCAM-style posts write; keywords in any order):
//!
//! ```text
//! CYCLE/mode, FEDTO,d, MMPM|IPM,f | MMPR|IPR,f, RAPTO,r [,RTRCTO,t] [,DWELL,s] [,STEP,p | INCR,p]
//! CYCLE/ON      the last cycle again          CYCLE/OFF     no cycle
//! CYCLE/INIT    (CAMWorks) no cycle until the next definition; a GOTO before it is refused
//! ```
//!
//! - `d` depth below the top along the tool axis (> 0), `r` the clearance above the top
//!   where the feed starts (≥ 0, required), `t` where the tool returns (above the top;
//!   default r), `s` dwell at the bottom in seconds, `p` the peck (CAMWorks'
//!   `1STPECK,p1,SUBPECK,p2`: read when p1 = p2; otherwise refused, or with
//!   [`crate::ParseOptions::uniform_peck`] the smaller of the two throughout);
//! - the feed: the record's (per-revolution values times the spindle speed in force), else
//!   the `FEDRAT` in force, else the record is refused;
//! - modes: `DRILL`; `DEEP`, `DEEP2` (peck drilling, full retract: `STEP` required);
//!   `BRKCHP` (peck drilling, chip breaking: `STEP` required); `TAP`; `BORE`, `REAM` (feed
//!   in, feed out). Any other mode, keyword or a number that follows no keyword (positional
//!   values mean a clearance in some CAM systems and a rapid rate in others) is refused
//!   with its column.

use crate::At;

/// What the cycle does at each hole.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CycleKind {
    /// Feed to depth (dwell if given), rapid out.
    Drill,
    /// Peck drilling, full retract after each peck.
    Deep,
    /// Peck drilling, short retract (chip breaking).
    ChipBreak,
    /// Tapping (feed in, spindle reverse, feed out).
    Tap,
    /// Boring / reaming: feed in, feed out.
    Bore,
}

/// A canned cycle as the CL states it, lengths in mm.
#[derive(Debug, Clone, PartialEq)]
pub struct Cycle {
    /// What it does.
    pub kind: CycleKind,
    /// The mode as written (`DRILL`, `DEEP2`, …), for messages.
    pub mode: String,
    /// Depth below the hole's top point, along the tool axis, mm (> 0).
    pub depth_mm: f64,
    /// Feed, mm/min.
    pub feed_mm_min: f64,
    /// Clearance above the top where the feed starts (`RAPTO`), mm (≥ 0).
    pub clearance_mm: f64,
    /// Where the tool returns above the top (`RTRCTO`; `None`: the clearance), mm.
    pub retract_mm: Option<f64>,
    /// Dwell at the bottom, s (0: none).
    pub dwell_s: f64,
    /// Peck depth (`STEP`/`INCR`), mm.
    pub peck_mm: Option<f64>,
    /// Where the `CYCLE` record is.
    pub at: At,
}

impl Cycle {
    /// The level above the top the tool returns to after the hole, mm: the larger of the
    /// clearance and `RTRCTO` (never below where the feed started).
    pub fn return_mm(&self) -> f64 {
        self.retract_mm
            .map_or(self.clearance_mm, |t| t.max(self.clearance_mm))
    }
}

/// What a `CYCLE` record says.
#[derive(Debug, Clone, PartialEq)]
pub enum CycleRecord {
    /// A new cycle, on from here.
    Define(Cycle),
    /// `CYCLE/ON`.
    On,
    /// `CYCLE/OFF`.
    Off,
    /// `CYCLE/INIT` (CAMWorks, before each cycle): no cycle until the next definition.
    Init,
}

/// The state a cycle record is read in.
pub(crate) struct CycleContext {
    /// Length scale (25.4 in an inch file).
    pub scale: f64,
    /// The `FEDRAT` in force, mm/min.
    pub feed_mm_min: Option<f64>,
    /// The spindle speed in force, rpm (per-revolution feeds).
    pub spindle_rpm: Option<f64>,
    /// [`crate::ParseOptions::uniform_peck`].
    pub uniform_peck: bool,
}

/// Read the fields of a `CYCLE` record: `(text, where)` per comma-separated field.
/// `number` reads a field as a finite number (with its error).
///
/// The steps: the mode ([`cycle_mode`]: a record without values, or a cycle's kind); each
/// keyword and its value ([`CycleValues::read`]); the cycle from what was read
/// ([`CycleValues::define`]).
pub(crate) fn parse_cycle(
    fields: &[(&str, At)],
    at: At,
    ctx: &CycleContext,
    number: &dyn Fn(&str, At, &str) -> Result<f64, crate::ClError>,
) -> Result<CycleRecord, crate::ClError> {
    let (mode, kind) = match cycle_mode(fields, at)? {
        Mode::Record(record) => return Ok(record),
        Mode::Define(mode, kind) => (mode, kind),
    };
    let mut values = CycleValues::default();
    let mut k = 1;
    while k < fields.len() {
        values.read(fields, k, &mode, ctx, number)?;
        // A value that follows its keyword: the next field must be a keyword again
        // (a second value, e.g. STEP,p1,p2 or DWELL,s1,s2, is refused there).
        k += 2;
    }
    values.define(kind, mode, at, ctx)
}

/// What a `CYCLE` record's first field says.
enum Mode {
    /// `OFF`, `ON` or `INIT`: the whole record.
    Record(CycleRecord),
    /// A cycle of this kind follows (the mode as written, upper case).
    Define(String, CycleKind),
}

fn cycle_err(at: At, m: String) -> crate::ClError {
    crate::err(at.line, at.column, m)
}

/// The mode of a `CYCLE` record (its first field).
fn cycle_mode(fields: &[(&str, At)], at: At) -> Result<Mode, crate::ClError> {
    let e = cycle_err;
    let Some(&(first, first_at)) = fields.first() else {
        return Err(e(at, "CYCLE without a mode".into()));
    };
    let mode = first.trim().to_ascii_uppercase();
    let kind = match mode.as_str() {
        "OFF" | "ON" | "INIT" if fields.len() > 1 => {
            return Err(e(
                fields[1].1,
                format!("CYCLE/{mode} takes no values, got '{}'", fields[1].0.trim()),
            ));
        }
        "OFF" => return Ok(Mode::Record(CycleRecord::Off)),
        "ON" => return Ok(Mode::Record(CycleRecord::On)),
        "INIT" => return Ok(Mode::Record(CycleRecord::Init)),
        "DRILL" => CycleKind::Drill,
        "DEEP" | "DEEP2" => CycleKind::Deep,
        "BRKCHP" => CycleKind::ChipBreak,
        "TAP" => CycleKind::Tap,
        "BORE" | "REAM" => CycleKind::Bore,
        "" => return Err(e(first_at, "CYCLE without a mode".into())),
        other => {
            return Err(e(
                first_at,
                format!(
                    "CYCLE/{other} is not posted (modes read: DRILL, DEEP, DEEP2, BRKCHP, TAP, BORE, REAM)"
                ),
            ));
        }
    };
    Ok(Mode::Define(mode, kind))
}

/// The values a cycle definition states, as read so far (lengths in mm, feed in mm/min).
#[derive(Default)]
struct CycleValues {
    depth: Option<f64>,
    feed: Option<f64>,
    clearance: Option<f64>,
    retract: Option<f64>,
    dwell: f64,
    peck: Option<f64>,
    /// CAMWorks' `1STPECK` and where it is.
    first_peck: Option<(f64, At)>,
    /// CAMWorks' `SUBPECK`.
    sub_peck: Option<f64>,
}

impl CycleValues {
    /// Read the keyword `fields[k]` and its value `fields[k + 1]` of a `CYCLE/mode`.
    fn read(
        &mut self,
        fields: &[(&str, At)],
        k: usize,
        mode: &str,
        ctx: &CycleContext,
        number: &dyn Fn(&str, At, &str) -> Result<f64, crate::ClError>,
    ) -> Result<(), crate::ClError> {
        let e = cycle_err;
        // The value after keyword `fields[k]`.
        let value = |k: usize, what: &str| -> Result<f64, crate::ClError> {
            match fields.get(k + 1) {
                Some(&(t, a)) => number(t, a, what),
                None => Err(e(
                    fields[k].1,
                    format!("CYCLE/{mode}: {what} without a value"),
                )),
            }
        };
        let (t, a) = fields[k];
        let key = t.trim().to_ascii_uppercase();
        let positive = |v: f64, what: &str, strict: bool| {
            if v > 0.0 || (!strict && v == 0.0) {
                Ok(v)
            } else {
                Err(e(
                    fields[k + 1].1,
                    format!(
                        "CYCLE/{mode}: {what} {v} must be {}",
                        if strict { "positive" } else { "0 or more" }
                    ),
                ))
            }
        };
        match key.as_str() {
            "FEDTO" | "DEPTH" => {
                let v = value(k, "FEDTO (depth)")?;
                self.depth =
                    Some(positive(v, "FEDTO (the depth below the GOTO point)", true)? * ctx.scale);
            }
            "MMPM" | "IPM" => {
                let v = positive(value(k, "feed")?, "feed", true)?;
                self.feed = Some(if key == "IPM" { v * 25.4 } else { v });
            }
            "MMPR" | "IPR" => {
                let v = positive(
                    value(k, "feed per revolution")?,
                    "feed per revolution",
                    true,
                )?;
                let Some(rpm) = ctx.spindle_rpm else {
                    return Err(e(
                        a,
                        format!(
                            "CYCLE/{mode}: a feed per revolution ({key}) needs the spindle speed, and no SPINDL/rpm is in force"
                        ),
                    ));
                };
                self.feed = Some(v * rpm * if key == "IPR" { 25.4 } else { 1.0 });
            }
            "RAPTO" => {
                self.clearance =
                    Some(positive(value(k, "RAPTO")?, "RAPTO (clearance)", false)? * ctx.scale)
            }
            "RTRCTO" => {
                self.retract =
                    Some(positive(value(k, "RTRCTO")?, "RTRCTO (retract)", false)? * ctx.scale)
            }
            "DWELL" => self.dwell = positive(value(k, "DWELL")?, "DWELL (seconds)", false)?,
            "STEP" | "INCR" => {
                self.peck =
                    Some(positive(value(k, "STEP (peck)")?, "STEP (peck)", true)? * ctx.scale)
            }
            // CAMWorks: the first peck and the following ones.
            "1STPECK" => {
                self.first_peck = Some((
                    positive(value(k, "1STPECK")?, "1STPECK", true)? * ctx.scale,
                    a,
                ))
            }
            "SUBPECK" => {
                self.sub_peck = Some(positive(value(k, "SUBPECK")?, "SUBPECK", true)? * ctx.scale)
            }
            "" => return Err(e(a, format!("CYCLE/{mode}: an empty field"))),
            _ if t.trim().parse::<f64>().is_ok() => {
                return Err(e(
                    a,
                    format!(
                        "CYCLE/{mode}: the value '{}' follows no keyword (FEDTO, RAPTO, RTRCTO, DWELL, STEP, MMPM, IPM…); positional cycle values mean different things to different CAM systems, so polepatch does not guess",
                        t.trim()
                    ),
                ));
            }
            other => {
                return Err(e(
                    a,
                    format!(
                        "CYCLE/{mode}: '{other}' is not read (FEDTO, RAPTO, RTRCTO, DWELL, STEP, INCR, MMPM, IPM, MMPR, IPR are)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The peck from CAMWorks' first and following pecks (when no `STEP` gave one): read
    /// when they are equal, else the smaller with [`crate::ParseOptions::uniform_peck`],
    /// else refused.
    fn resolve_peck(&mut self, mode: &str, ctx: &CycleContext) -> Result<(), crate::ClError> {
        match (self.first_peck, self.sub_peck) {
            (Some((f, _)), Some(s)) if f == s => self.peck = self.peck.or(Some(f)),
            (Some((f, _)), Some(s)) if ctx.uniform_peck => self.peck = self.peck.or(Some(f.min(s))),
            (Some((f, fa)), Some(s)) => {
                return Err(cycle_err(
                    fa,
                    format!(
                        "CYCLE/{mode}: a first peck (1STPECK {f}) other than the following ones (SUBPECK {s}) is not posted (the dialects' peck cycles take one peck); give --uniform-peck to drill with the smaller one throughout"
                    ),
                ));
            }
            (Some((f, _)), None) | (None, Some(f)) => self.peck = self.peck.or(Some(f)),
            (None, None) => {}
        }
        Ok(())
    }

    /// The cycle: depth, clearance and a feed (the record's, else the `FEDRAT` in force)
    /// required, and a peck for peck drilling.
    fn define(
        mut self,
        kind: CycleKind,
        mode: String,
        at: At,
        ctx: &CycleContext,
    ) -> Result<CycleRecord, crate::ClError> {
        let e = cycle_err;
        self.resolve_peck(&mode, ctx)?;
        let depth_mm = self.depth.ok_or_else(|| {
            e(
                at,
                format!("CYCLE/{mode} without FEDTO (the depth): the holes cannot be drilled"),
            )
        })?;
        let clearance_mm = self.clearance.ok_or_else(|| {
            e(
                at,
                format!(
                    "CYCLE/{mode} without RAPTO (the clearance above the hole where the feed starts)"
                ),
            )
        })?;
        let feed_mm_min = self.feed.or(ctx.feed_mm_min).ok_or_else(|| {
            e(
                at,
                format!("CYCLE/{mode} without a feed (no MMPM/IPM value and no FEDRAT before it)"),
            )
        })?;
        if matches!(kind, CycleKind::Deep | CycleKind::ChipBreak) && self.peck.is_none() {
            return Err(e(
                at,
                format!("CYCLE/{mode} (peck drilling) without STEP (the peck depth)"),
            ));
        }
        Ok(CycleRecord::Define(Cycle {
            kind,
            mode,
            depth_mm,
            feed_mm_min,
            clearance_mm,
            retract_mm: self.retract,
            dwell_s: self.dwell,
            peck_mm: self.peck,
            at,
        }))
    }
}
