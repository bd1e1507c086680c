//! APT CLDATA, the text form CAM post-processors read: one record per line, `$` at the end
//! of a line continues the record on the next, `$$` starts a comment (a comment that ends
//! with `$` continues on the next line, as Creo writes its `$$-> CSYS / …  $`). Each record is a
//! major word, optionally `/` and comma-separated values and minor words. The table of
//! records and what becomes of each is in `docs/post.md`; in short:
//!
//! - posted: `GOTO`, `FROM`, `GOHOME`, `GODLTA`, `RAPID`, `FEDRAT`, `CIRCLE`, `MOVARC`,
//!   `CYCLE`, `LOADTL`/`LOAD/TOOL`, `SPINDL`, `COOLNT`, `CUTCOM`, `DELAY`, `STOP`, `OPSTOP`,
//!   `TLAXIS`, `UNITS`/`UNIT`, `PARTNO`/`PPRINT`/`TPRINT` (comments), `INSERT` (its text
//!   written into the program as it is, and listed in [`ClProgram::notes`]; it can still be
//!   skipped with `--ignore INSERT`);
//! - read, no effect on the motion (counted): [`PASSIVE`]; of them `CUTTER` and `TLDATA`
//!   (and Creo's `$$-> CUTTER / d`, a comment Creo writes for it) become
//!   [`ClItem::Cutter`], the cutter of the moves after it;
//! - frames ([`crate::frames`]): `TRNTYP/WORLD,0,0,0` and `CSYS` (CAMWorks: the values
//!   stay world coordinates; `CSYS` gives the setup's tool axis for 3-value `GOTO`s),
//!   `MSYS` (NX: the values are in that MCS; another MCS later is refused); `TRACUT`,
//!   `INDEX`, `COPY`, `REFSYS`, `TRANS`, `ORIGIN` refused by name;
//! - every other record stops the read with its line, column and name, unless the caller
//!   skips it by name ([`crate::ParseOptions::ignore`]).
//!
//! Lengths are converted to mm (`UNITS/INCHES`, `UNIT/INCH`), feeds to mm/min.

use crate::arcs::Arc;
use crate::cycles::{Cycle, CycleContext, CycleRecord, parse_cycle};
use crate::frames::{Frames, refused_frame_record};
use crate::records::{
    At, ClItem, ClPoint, ClProgram, CompSide, Coolant, Cutter, CutterShape, MoveKind, SpindleDir,
    Units,
};
use crate::tolerances::MAX_DWELL_S;
use crate::values::{coordinate, number};
use crate::{ClError, MAX_FEED_MM_MIN, MAX_SPINDLE_RPM, MM_PER_INCH, ParseOptions, err, unit_axis};
use polepatch_kinematics::vec3;

/// Records that do not change what the machine does: read, counted, not posted.
pub const PASSIVE: &[&str] = &[
    "FINI",
    "END",
    "CUTTER",
    "TOLER",
    "INTOL",
    "OUTOL",
    "MACHIN",
    "MODE",
    "MULTAX",
    "TLDATA",
    "PAINT",
    "SELECT",
    "SELCTL",
    "TOOL PATH",
    "END-OF-PATH",
    "CLRSRF",
    "DISPLY",
    "REWIND",
    "SEQNO",
    // CAMWorks: tool geometry for its simulation.
    "CSI_SET_FLUTE_LENGTH",
    "CSI_SET_EXTENSION_LENGTH",
];

/// Records polepatch posts: `--ignore` skips them only where one of them is refused in the
/// file (`polepatch::post::read_cl_for_post`).
pub const POSTED: &[&str] = &[
    "GOTO", "FROM", "GOHOME", "GODLTA", "RAPID", "FEDRAT", "CIRCLE", "MOVARC", "CYCLE", "LOADTL",
    "LOAD", "SPINDL", "COOLNT", "CUTCOM", "DELAY", "STOP", "OPSTOP", "TLAXIS", "UNITS", "UNIT",
    "PARTNO", "PPRINT", "TPRINT",
];

/// One record: its text (continuation lines joined) and where each piece came from.
struct Record {
    /// Read from a comment (Creo's `$$-> CUTTER / d`).
    from_comment: bool,
    text: String,
    /// (offset in `text`, line, column of that byte): one entry per joined line.
    pieces: Vec<(usize, usize, usize)>,
}

impl Record {
    /// Line and column of byte `offset` of the record text.
    fn at(&self, offset: usize) -> At {
        let &(start, line, column) = self
            .pieces
            .iter()
            .rev()
            .find(|p| p.0 <= offset)
            .unwrap_or(&self.pieces[0]);
        At {
            line,
            column: column + (offset - start),
        }
    }

    /// The comma-separated fields after byte `from`, each trimmed, with where it starts.
    fn fields(&self, from: usize) -> Vec<(&str, At)> {
        let s = &self.text[from..];
        let mut out = Vec::new();
        let mut start = 0;
        for (i, c) in s.char_indices().chain(std::iter::once((s.len(), ','))) {
            if c == ',' {
                let raw = &s[start..i];
                let lead = raw.len() - raw.trim_start().len();
                out.push((raw.trim(), self.at(from + start + lead)));
                start = i + 1;
            }
        }
        out
    }
}

/// The records of `text`: `$` continuation joined, `$$` comments removed, blank records
/// dropped. A `$$` comment that ends with `$` continues on the next line, which is comment
/// too (Creo: `$$-> CSYS / 1.0, 0.0, 0.0, 0.0,  $` and two lines of numbers).
fn records(text: &str) -> Result<Vec<Record>, ClError> {
    let mut out = Vec::new();
    let mut cur: Option<Record> = None;
    let mut line_no = 0;
    let mut comment_continues = false;
    for raw in crate::lines(text) {
        line_no += 1;
        if comment_continues {
            comment_continues = raw.trim_end().ends_with('$');
            continue;
        }
        if let Some(p) = raw.find("$$") {
            comment_continues = raw[p + 2..].trim_end().ends_with('$');
        }
        let code = match raw.find("$$") {
            // Creo states the cutter in a comment of its own, `$$-> CUTTER / 6.000000`: read
            // as the record it names (its columns the file's).
            Some(p) if cur.is_none() && raw[..p].trim().is_empty() => {
                if let Some(k) = creo_cutter(&raw[p..]) {
                    comment_continues = false;
                    out.push(Record {
                        from_comment: true,
                        text: raw[p + k..].trim_end().to_string(),
                        pieces: vec![(0, line_no, p + k + 1)],
                    });
                    continue;
                }
                &raw[..p]
            }
            Some(p) => &raw[..p],
            None => raw,
        };
        let trimmed = code.trim_end();
        let (body, continued) = match trimmed.strip_suffix('$') {
            Some(b) => (b, true),
            None => (trimmed, false),
        };
        let lead = body.len() - body.trim_start().len();
        let rec = cur.get_or_insert_with(|| Record {
            from_comment: false,
            text: String::new(),
            pieces: Vec::new(),
        });
        if !body.trim().is_empty() {
            rec.pieces.push((rec.text.len(), line_no, lead + 1));
            rec.text.push_str(body.trim_start());
        } else if rec.pieces.is_empty() && continued {
            // A record that starts with a bare `$` line: keep its line for messages.
            rec.pieces.push((0, line_no, 1));
        }
        if !continued {
            let rec = cur.take().expect("set above");
            if !rec.text.trim().is_empty() {
                out.push(rec);
            }
        }
    }
    if let Some(rec) = cur
        && !rec.pieces.is_empty()
    {
        let at = rec.at(0);
        return Err(err(
            at.line,
            at.column,
            "the file ends inside a continued record ('$' at the end of the last line)",
        ));
    }
    Ok(out)
}

/// Where the record starts in a Creo `$$-> CUTTER / d` comment (`comment` from its `$$`).
fn creo_cutter(comment: &str) -> Option<usize> {
    let rest = comment.strip_prefix("$$->")?;
    let lead = rest.len() - rest.trim_start().len();
    let body = rest.trim_start();
    let word = body.get(..6)?;
    (word.eq_ignore_ascii_case("CUTTER") && body[6..].trim_start().starts_with('/'))
        .then_some(4 + lead)
}

/// A `CIRCLE`/`MOVARC` record waiting for the `GOTO` of its end point.
struct PendingCircle {
    center: [f64; 3],
    normal: [f64; 3],
    /// `None`: CAMWorks' `CIRCLE/xc,yc,zc,i,j,k`, the radius is the start point's.
    radius_mm: Option<f64>,
    /// `MOVARC`'s `ANGLE`, degrees.
    angle_deg: Option<f64>,
    at: At,
}

/// The reader's state between records.
struct Reader<'o> {
    opts: &'o ParseOptions,
    prog: ClProgram,
    units_seen: bool,
    inch: bool,
    feed: Option<f64>,
    rapid_next: bool,
    axis: [f64; 3],
    /// Tool tip after the last move, when known (unknown after a hole).
    pos: Option<[f64; 3]>,
    /// Tool axis of the last move (an arc's start axis).
    last_axis: [f64; 3],
    /// The frame records read (`TRNTYP`, `CSYS`, `MSYS`).
    frames: Frames,
    from: Option<([f64; 3], [f64; 3])>,
    /// `CIRCLE`/`MOVARC` waiting for its `GOTO`.
    circle: Option<PendingCircle>,
    /// The last cycle defined, and whether it is on.
    cycle: Option<Cycle>,
    cycle_on: bool,
    /// `CYCLE/INIT` (CAMWorks) waiting for the cycle it prepares.
    cycle_init: Option<At>,
    spindle_rpm: Option<f64>,
    spindle_dir: Option<SpindleDir>,
    /// `CUTCOM/ON` waiting for its side.
    cutcom_on: Option<At>,
    /// Items of cutters read before the first units record: in the file's units, scaled
    /// when they are known (a CL file's values are all in its units).
    cutters_before_units: Vec<usize>,
}

/// Whether `w` can be an APT major word: a letter, then letters, digits, `_`, `-` or
/// blanks (`GOTO`, `LOAD`, `CSI_SET_FLUTE_LENGTH`, `TOOL PATH`, `END-OF-PATH`).
fn is_record_word(w: &str) -> bool {
    let mut c = w.chars();
    c.next().is_some_and(|f| f.is_ascii_alphabetic())
        && c.all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | ' '))
}

/// The error for a record that does not start with a major word (`0.0, 1.0, …`): most
/// often the continuation of a line that does not end with `$`.
fn no_record_word(text: &str, at: At) -> ClError {
    let shown: String = text.chars().take(40).collect();
    e(
        at,
        format!(
            "'{shown}' does not start with an APT record word (GOTO/, FEDRAT/, …): values without a record, as a continuation line is when the line before it does not end with '$'"
        ),
    )
}

fn e(at: At, message: impl Into<String>) -> ClError {
    err(at.line, at.column, message)
}

/// The error for values after a record that takes none (`GOHOME/Z`).
fn no_args(f: &[(&str, At)], w: &str) -> Result<(), ClError> {
    match f.first() {
        Some(&(t, a)) if !t.is_empty() => Err(e(a, format!("{w} takes no values, got '{t}'"))),
        _ => Ok(()),
    }
}

impl Reader<'_> {
    fn scale(&self) -> f64 {
        if self.inch { MM_PER_INCH } else { 1.0 }
    }

    /// x y z [i j k] of a GOTO-like record: a point in mm and the tool axis (the last one
    /// when only x y z).
    fn point(&mut self, word: &str, f: &[(&str, At)], at: At) -> Result<[f64; 3], ClError> {
        if f.len() != 3 && f.len() != 6 {
            return Err(e(
                f.first().map_or(at, |x| x.1),
                format!("{word} needs x,y,z or x,y,z,i,j,k; got {} values", f.len()),
            ));
        }
        let mut v = [0.0; 6];
        for (i, &(t, a)) in f.iter().enumerate() {
            let what = ["x", "y", "z", "i", "j", "k"][i];
            v[i] = number(t, a, what)?;
            if i < 3 {
                v[i] = coordinate(v[i] * self.scale(), a, what, t)?;
            }
        }
        if f.len() == 6 {
            self.axis = unit_axis([v[3], v[4], v[5]], f[3].1.line, f[3].1.column)?;
        }
        Ok([v[0], v[1], v[2]])
    }

    fn push_move(&mut self, pos: [f64; 3], kind: MoveKind, at: At) {
        self.last_axis = self.axis;
        self.pos = match kind {
            MoveKind::Hole(_) => None,
            _ => Some(pos),
        };
        self.prog.items.push(ClItem::Move(ClPoint {
            pos_mm: pos,
            axis: self.axis,
            feed_mm_min: self.feed,
            kind,
            line: at.line,
            column: at.column,
        }));
        self.rapid_next = false;
    }

    /// A move may not start while a `CUTCOM/ON` has no side yet.
    fn check_cutcom(&self) -> Result<(), ClError> {
        match self.cutcom_on {
            Some(at) => Err(e(
                at,
                "CUTCOM/ON without LEFT or RIGHT before the next move: the side of the compensation is unknown",
            )),
            None => Ok(()),
        }
    }

    /// The major word of a record and the byte where its values start (after `/`, or after
    /// the blank of `PARTNO NAME`, `PPRINT text`); a `RAPID,` before the word is read here.
    fn major_word(&mut self, rec: &Record, at0: At) -> Result<(String, Option<usize>), ClError> {
        let (head, args_from) = match rec.text.find('/') {
            Some(p) => (&rec.text[..p], Some(p + 1)),
            None => (rec.text.as_str(), None),
        };
        // `RAPID, GOTO/…` on one line: the prefix words, then the record.
        let mut words: Vec<String> = head
            .split(',')
            .map(|w| w.trim().to_ascii_uppercase())
            .collect();
        let word = words.pop().unwrap_or_default();
        for w in &words {
            match w.as_str() {
                "RAPID" => self.rapid_next = true,
                other if !is_record_word(other) => return Err(no_record_word(&rec.text, at0)),
                other => {
                    return Err(e(
                        at0,
                        format!(
                            "'{other},{word}' is not posted (a motion statement polepatch does not read); give --ignore {other} to skip it"
                        ),
                    )
                    .refusing(other));
                }
            }
        }
        if !is_record_word(&word) {
            return Err(no_record_word(&rec.text, at0));
        }
        // Records without '/' but with blanks: `PARTNO NAME`, `PPRINT text`.
        let (word, args_from) = match args_from {
            Some(p) => (word, Some(p)),
            None => match word.split_once(char::is_whitespace) {
                Some((w, _)) if ["PARTNO", "PPRINT", "TPRINT"].contains(&w) => {
                    let off = rec.text.find(char::is_whitespace).unwrap_or(0);
                    (w.to_string(), Some(off + 1))
                }
                _ => (word, None),
            },
        };
        Ok((word, args_from))
    }

    /// Read one record: counted, skipped when the caller asks, else read by its kind.
    fn record(&mut self, rec: &Record) -> Result<(), ClError> {
        let at0 = rec.at(0);
        let (word, args_from) = self.major_word(rec, at0)?;
        *self.prog.records.entry(word.clone()).or_default() += 1;
        if self
            .opts
            .ignore
            .iter()
            .any(|w| w.eq_ignore_ascii_case(&word))
        {
            let skipped = self
                .prog
                .skipped
                .entry(word)
                .or_insert_with(|| crate::Skipped {
                    first: at0,
                    ..crate::Skipped::default()
                });
            skipped.count += 1;
            return Ok(());
        }
        let args = args_from.map_or("", |p| &rec.text[p..]);
        let f = args_from.map_or_else(Vec::new, |p| rec.fields(p));
        match word.as_str() {
            "GOTO" => self.goto(&f, at0)?,
            "FROM" => self.from(&f, at0)?,
            "GOHOME" => self.gohome(&f, at0)?,
            "GODLTA" => self.godlta(&f, args, at0)?,
            "FEDRAT" => self.fedrat(&f, at0)?,
            "RAPID" => self.rapid(&f)?,
            "UNITS" | "UNIT" => self.units(&word, &f, args, at0)?,
            "TLAXIS" => self.tlaxis(&f, args, at0)?,
            "CIRCLE" | "MOVARC" => self.circle(&word, &f, at0)?,
            "CYCLE" => self.cycle(&f, at0)?,
            "LOADTL" | "LOAD" => self.loadtl(&word, &f, at0)?,
            "CUTTER" | "TLDATA" => self.cutter(&word, &f, rec, at0),
            "SPINDL" => self.spindl(&f, at0)?,
            "COOLNT" => self.coolnt(&f, at0)?,
            "CUTCOM" => self.cutcom(&f, at0)?,
            "DELAY" => self.delay(&f, args, at0)?,
            "STOP" | "OPSTOP" => self.stop(&word, &f, at0)?,
            "PARTNO" => self.partno(args, at0)?,
            "PPRINT" | "TPRINT" => self.pprint(&word, args, at0)?,
            "INSERT" => self.insert(args, at0)?,
            "TRNTYP" => self.frames.trntyp(&f, at0)?,
            "CSYS" => self.axis = self.frames.csys(&f, at0, self.scale())?,
            "MSYS" => {
                let first_move = self.prog.points().next().map(|p| At {
                    line: p.line,
                    column: p.column,
                });
                self.frames.msys(&f, at0, self.scale(), first_move)?;
            }
            w if PASSIVE.contains(&w) => {}
            other => {
                if let Some(refused) = refused_frame_record(other, at0) {
                    return Err(refused);
                }
                return Err(e(
                    at0,
                    format!(
                        "{other} records are not posted (their effect on the motion is not read by polepatch); give --ignore {other} to skip them"
                    ),
                )
                .refusing(other));
            }
        }
        Ok(())
    }

    /// `GOTO/x,y,z[,i,j,k]`: a straight or rapid move, the end of a pending arc, or a hole while a cycle is on.
    fn goto(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        self.check_cutcom()?;
        if let Some(init) = self.cycle_init {
            return Err(e(
                init,
                "CYCLE/INIT without a cycle before the next GOTO (is it a hole or a move?): refused",
            ));
        }
        let p = self.point("GOTO", f, at)?;
        let kind = if let Some(PendingCircle {
            center: c,
            normal: n,
            radius_mm: r,
            angle_deg: angle,
            at: cat,
        }) = self.circle.take()
        {
            if self.rapid_next {
                return Err(e(cat, "RAPID before a circular move (CIRCLE): refused"));
            }
            let Some(start) = self.pos else {
                return Err(e(
                    cat,
                    "CIRCLE after a hole or at the start: its start point is unknown",
                ));
            };
            // Without a stated radius: the start point's distance from the axis.
            let r = r.unwrap_or_else(|| {
                let a = vec3::sub(start, c);
                let ax = vec3::dot(a, n);
                vec3::norm(vec3::sub(a, vec3::scale(n, ax)))
            });
            MoveKind::Arc(
                Arc::new(c, n, r, start, p, angle, self.last_axis)
                    .map_err(|m| e(cat, format!("CIRCLE: {m}")))?,
            )
        } else if self.cycle_on {
            if self.rapid_next {
                return Err(e(
                    at,
                    "RAPID before a GOTO while a CYCLE is on (is it a hole or a move between holes?): refused; end the cycle with CYCLE/OFF first",
                ));
            }
            MoveKind::Hole(self.cycle.clone().expect("on implies defined"))
        } else if self.rapid_next {
            MoveKind::Rapid
        } else {
            MoveKind::Linear
        };
        self.push_move(p, kind, at);
        Ok(())
    }

    /// `FROM/x,y,z[,i,j,k]`: a rapid move, and the home point.
    fn from(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        self.check_cutcom()?;
        let p = self.point("FROM", f, at)?;
        self.from = Some((p, self.axis));
        self.push_move(p, MoveKind::Rapid, at);
        Ok(())
    }

    /// `GOHOME`: a rapid move to the `FROM` point.
    fn gohome(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        no_args(f, "GOHOME")?;
        self.check_cutcom()?;
        let Some((p, axis)) = self.from else {
            return Err(e(
                at,
                "GOHOME without a FROM point before it: where home is is unknown",
            ));
        };
        self.axis = axis;
        self.push_move(p, MoveKind::Rapid, at);
        Ok(())
    }

    /// `GODLTA/d` or `/dx,dy,dz`: a move by d along the tool axis or by the vector.
    fn godlta(&mut self, f: &[(&str, At)], args: &str, at: At) -> Result<(), ClError> {
        self.check_cutcom()?;
        if self.cycle_on || self.circle.is_some() {
            return Err(e(at, "GODLTA while a CYCLE or CIRCLE is pending: refused"));
        }
        let Some(pos) = self.pos else {
            return Err(e(
                at,
                "GODLTA after a hole or at the start: the point it moves from is unknown",
            ));
        };
        let d = match f.len() {
            1 => {
                let d = number(f[0].0, f[0].1, "distance")? * self.scale();
                [self.axis[0] * d, self.axis[1] * d, self.axis[2] * d]
            }
            3 => {
                let mut d = [0.0; 3];
                for (i, &(t, a)) in f.iter().enumerate() {
                    d[i] = number(t, a, ["dx", "dy", "dz"][i])? * self.scale();
                }
                d
            }
            n => {
                return Err(e(
                    f.first().map_or(at, |x| x.1),
                    format!("GODLTA needs d or dx,dy,dz; got {n} values"),
                ));
            }
        };
        let mut p = [0.0; 3];
        for i in 0..3 {
            p[i] = coordinate(pos[i] + d[i], f[0].1, "GODLTA target", args)?;
        }
        let kind = if self.rapid_next {
            MoveKind::Rapid
        } else {
            MoveKind::Linear
        };
        self.push_move(p, kind, at);
        Ok(())
    }

    /// `RAPID`: the next move is rapid.
    fn rapid(&mut self, f: &[(&str, At)]) -> Result<(), ClError> {
        no_args(f, "RAPID")?;
        self.rapid_next = true;
        Ok(())
    }

    /// `UNITS/MM|INCHES|INCH`, `UNIT/MM|INCH`: the units of the values from here.
    fn units(&mut self, word: &str, f: &[(&str, At)], args: &str, at: At) -> Result<(), ClError> {
        let v = args.trim().to_ascii_uppercase();
        let inch = match v.as_str() {
            "MM" => false,
            "INCHES" | "INCH" => true,
            other => {
                return Err(e(
                    f.first().map_or(at, |x| x.1),
                    format!("{word} '{other}' is not MM, INCH or INCHES"),
                ));
            }
        };
        self.inch = inch;
        if !self.units_seen {
            self.units_seen = true;
            self.prog.units = if inch { Units::Inch } else { Units::Mm };
            self.prog.units_at = Some(at);
        }
        Ok(())
    }

    /// `TLAXIS/i,j,k`: the tool axis for the next 3-value GOTOs.
    fn tlaxis(&mut self, f: &[(&str, At)], args: &str, at: At) -> Result<(), ClError> {
        if f.len() != 3 {
            return Err(e(
                f.first().map_or(at, |x| x.1),
                format!(
                    "TLAXIS needs i,j,k; got '{}' (other TLAXIS forms are not posted)",
                    args.trim()
                ),
            ));
        }
        let mut v = [0.0; 3];
        for (i, &(t, a)) in f.iter().enumerate() {
            v[i] = number(t, a, ["i", "j", "k"][i])?;
        }
        self.axis = unit_axis(v, f[0].1.line, f[0].1.column)?;
        Ok(())
    }

    /// `CYCLE/…`: a cycle defined, `ON`, `OFF` or `INIT` (`crate::cycles`).
    fn cycle(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        let ctx = CycleContext {
            scale: self.scale(),
            feed_mm_min: self.feed,
            spindle_rpm: self.spindle_rpm,
            uniform_peck: self.opts.uniform_peck,
        };
        match parse_cycle(f, at, &ctx, &number)? {
            CycleRecord::Define(c) => {
                for (v, what) in [
                    (c.depth_mm, "FEDTO"),
                    (c.clearance_mm, "RAPTO"),
                    (c.retract_mm.unwrap_or(0.0), "RTRCTO"),
                    (c.peck_mm.unwrap_or(0.0), "STEP"),
                ] {
                    coordinate(v, at, what, &format!("{v}"))?;
                }
                if c.feed_mm_min > MAX_FEED_MM_MIN || c.dwell_s > MAX_DWELL_S {
                    return Err(e(
                        at,
                        format!(
                            "CYCLE/{}: feed {} mm/min or dwell {} s out of range (at most {MAX_FEED_MM_MIN} mm/min, 100000 s)",
                            c.mode, c.feed_mm_min, c.dwell_s
                        ),
                    ));
                }
                self.cycle = Some(c);
                self.cycle_on = true;
                self.cycle_init = None;
            }
            CycleRecord::On => {
                if self.cycle.is_none() {
                    return Err(e(at, "CYCLE/ON without a cycle defined before it"));
                }
                self.cycle_on = true;
                self.cycle_init = None;
            }
            CycleRecord::Off => {
                self.cycle_on = false;
                self.cycle_init = None;
            }
            CycleRecord::Init => {
                self.cycle_on = false;
                self.cycle_init = Some(at);
            }
        }
        Ok(())
    }

    /// `COOLNT/ON|FLOOD|MIST|OFF`.
    fn coolnt(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        let mut mode = None;
        for &(t, a) in f {
            mode = Some(match t.to_ascii_uppercase().as_str() {
                "ON" | "FLOOD" => Coolant::Flood,
                "MIST" => Coolant::Mist,
                "OFF" => Coolant::Off,
                other => {
                    return Err(e(
                        a,
                        format!(
                            "COOLNT/{other} is not posted (ON, FLOOD, MIST, OFF are); give --ignore COOLNT to skip every COOLNT record"
                        ),
                    )
                    .refusing("COOLNT"));
                }
            });
        }
        let mode = mode.ok_or_else(|| e(at, "COOLNT without a mode"))?;
        self.prog.items.push(ClItem::Coolant { mode, at });
        Ok(())
    }

    /// `DELAY/t`: dwell, seconds.
    fn delay(&mut self, f: &[(&str, At)], args: &str, at: At) -> Result<(), ClError> {
        if f.len() != 1 {
            return Err(e(
                f.first().map_or(at, |x| x.1),
                format!(
                    "DELAY needs one value (seconds); got '{}' (DELAY/REV is not posted; --ignore DELAY skips every DELAY record)",
                    args.trim()
                ),
            )
            .refusing("DELAY"));
        }
        let s = number(f[0].0, f[0].1, "DELAY seconds")?;
        if !(0.0..=MAX_DWELL_S).contains(&s) {
            return Err(e(f[0].1, format!("DELAY {s} s must be within 0…100000 s")));
        }
        self.prog.items.push(ClItem::Dwell { seconds: s, at });
        Ok(())
    }

    /// `STOP`, `OPSTOP`.
    fn stop(&mut self, word: &str, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        no_args(f, word)?;
        self.prog.items.push(ClItem::Stop {
            optional: word == "OPSTOP",
            at,
        });
        Ok(())
    }

    /// `PARTNO name`: a comment, a note and the program name.
    fn partno(&mut self, args: &str, at: At) -> Result<(), ClError> {
        let name = args.trim().trim_matches('\'').trim().to_string();
        self.prog
            .notes
            .push(format!("line {}: PARTNO {name}", at.line));
        self.prog
            .items
            .push(ClItem::Comment(format!("PARTNO {name}")));
        self.prog.name = Some(name);
        Ok(())
    }

    /// `PPRINT text`, `TPRINT text`: a comment and a note.
    fn pprint(&mut self, word: &str, args: &str, at: At) -> Result<(), ClError> {
        let text = args.trim().trim_matches('\'').trim().to_string();
        self.prog
            .notes
            .push(format!("line {}: {word} {text}", at.line));
        self.prog.items.push(ClItem::Comment(text));
        Ok(())
    }

    /// `INSERT/text`: text for the NC program.
    fn insert(&mut self, args: &str, at: At) -> Result<(), ClError> {
        // Text for the NC program, written there as it is (every APT post does);
        // listed for the user.
        let text = args.trim_end().to_string();
        if let Some(c) = text.chars().find(|c| c.is_control()) {
            return Err(e(
                at,
                format!(
                    "INSERT text holds the control character {:?}; it cannot be written into an NC program",
                    c
                ),
            ));
        }
        self.prog.notes.push(format!(
            "line {}: INSERT/{text} is written into the program as it is",
            at.line
        ));
        self.prog.items.push(ClItem::Insert { text, at });
        Ok(())
    }

    fn fedrat(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        let mut value: Option<(f64, At)> = None;
        let mut per_inch = self.inch;
        let mut per_rev = false;
        for &(t, a) in f {
            match t.to_ascii_uppercase().as_str() {
                "MMPM" => per_inch = false,
                "IPM" => per_inch = true,
                "MMPR" => (per_inch, per_rev) = (false, true),
                "IPR" => (per_inch, per_rev) = (true, true),
                "" => {}
                _ => value = Some((number(t, a, "feed")?, a)),
            }
        }
        let (v, va) = value.ok_or_else(|| e(at, "FEDRAT without a value"))?;
        if v <= 0.0 {
            return Err(e(va, format!("feed {v} must be positive")));
        }
        let mut mm_min = if per_inch { v * MM_PER_INCH } else { v };
        if per_rev {
            let Some(rpm) = self.spindle_rpm else {
                return Err(e(
                    va,
                    "a feed per revolution (MMPR/IPR) needs the spindle speed, and no SPINDL/rpm is in force",
                ));
            };
            mm_min *= rpm;
        }
        if mm_min > MAX_FEED_MM_MIN {
            return Err(e(
                va,
                format!(
                    "feed {mm_min} mm/min is beyond the {MAX_FEED_MM_MIN} mm/min polepatch accepts"
                ),
            ));
        }
        self.feed = Some(mm_min);
        Ok(())
    }

    fn circle(&mut self, word: &str, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        if self.cycle_on {
            return Err(e(at, format!("{word} while a CYCLE is on: refused")));
        }
        if self.circle.is_some() {
            return Err(e(at, format!("{word} after a CIRCLE that had no GOTO")));
        }
        // CAMWorks writes CIRCLE/xc,yc,zc,i,j,k (the radius is the start point's).
        let with_radius = f.len() >= 7;
        if f.len() < 6 || (word == "MOVARC" && !with_radius) {
            return Err(e(
                f.first().map_or(at, |x| x.1),
                format!("{word} needs xc,yc,zc,i,j,k[,r]; got {} values", f.len()),
            ));
        }
        let mut v = [0.0; 7];
        for (i, &(t, a)) in f.iter().take(7).enumerate() {
            let what = ["xc", "yc", "zc", "i", "j", "k", "r"][i];
            v[i] = number(t, a, what)?;
            if i < 3 || i == 6 {
                v[i] = coordinate(v[i] * self.scale(), a, what, t)?;
            }
        }
        let n = unit_axis([v[3], v[4], v[5]], f[3].1.line, f[3].1.column)?;
        let center = [v[0], v[1], v[2]];
        let mut angle = None;
        let rest = &f[f.len().min(7)..];
        if word == "MOVARC" {
            match rest {
                [(k, _), (t, a)] if k.eq_ignore_ascii_case("ANGLE") => {
                    angle = Some(number(t, *a, "ANGLE")?);
                }
                [] => {}
                [(t, a), ..] => {
                    return Err(e(*a, format!("MOVARC: '{t}' is not read (ANGLE,a is)")));
                }
            }
        } else {
            // CIRCLE's further values are CAM tolerances (NX: tol, …): numbers only.
            for &(t, a) in rest {
                number(t, a, "CIRCLE value")?;
            }
        }
        self.circle = Some(PendingCircle {
            center,
            normal: n,
            radius_mm: with_radius.then_some(v[6]),
            angle_deg: angle,
            at,
        });
        Ok(())
    }

    /// `CUTTER/…` or `TLDATA/…`: the cutter's shape, where it is an end mill
    /// ([`Cutter`]). Never an error: the record does not move the machine, and a cutter
    /// polepatch cannot read is an unknown tool to the patch.
    fn cutter(&mut self, word: &str, f: &[(&str, At)], rec: &Record, at: At) {
        let text = rec.text.trim();
        let text: String = text.chars().take(80).collect();
        let kind = f
            .first()
            .map(|(t, _)| t.to_ascii_uppercase())
            .unwrap_or_default();
        let nums: Option<Vec<f64>> = match word {
            // `TLDATA/MILL,d,r,l,taper,tip,…`.
            "TLDATA" if kind == "MILL" => f[1..].iter().map(|(t, _)| t.parse().ok()).collect(),
            "TLDATA" => None,
            _ => f.iter().map(|(t, _)| t.parse().ok()).collect(),
        };
        let s = self.scale();
        let shape = nums.map_or(CutterShape::Other, |v| {
            let zero = |x: Option<&f64>| x.is_none_or(|&a| a == 0.0);
            let end_mill = match word {
                // d, r, length, taper angle, tip angle.
                "TLDATA" => v.len() >= 2 && zero(v.get(3)) && zero(v.get(4)),
                // d, r, e, f, base angle α, side angle β, height.
                _ => !v.is_empty() && zero(v.get(4)) && zero(v.get(5)),
            };
            match v.as_slice() {
                // Creo writes its comment with the diameter alone for every tool.
                [d] if rec.from_comment => CutterShape::DiameterOnly { diameter_mm: d * s },
                [d, ..] if end_mill => CutterShape::EndMill {
                    diameter_mm: d * s,
                    corner_radius_mm: v.get(1).copied().unwrap_or(0.0) * s,
                },
                _ => CutterShape::Other,
            }
        });
        if !self.units_seen {
            self.cutters_before_units.push(self.prog.items.len());
        }
        self.prog
            .items
            .push(ClItem::Cutter(Cutter { shape, text, at }));
    }

    fn loadtl(&mut self, word: &str, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        // `LOAD/TOOL,n,…` (NX) is `LOADTL/n,…`.
        let f = if word == "LOAD" {
            match f.first() {
                Some((t, _)) if t.eq_ignore_ascii_case("TOOL") => &f[1..],
                _ => {
                    return Err(e(
                        f.first().map_or(at, |x| x.1),
                        "LOAD other than LOAD/TOOL,n is not posted",
                    ));
                }
            }
        } else {
            f
        };
        let int = |t: &str, a: At, what: &str| -> Result<u32, ClError> {
            let v = number(t, a, what)?;
            if v < 0.0 || v.fract() != 0.0 || v > 99_999_999.0 {
                return Err(e(
                    a,
                    format!("{what} '{t}' is not a tool or register number"),
                ));
            }
            Ok(v as u32)
        };
        let Some(&(t, a)) = f.first() else {
            return Err(e(at, format!("{word} without a tool number")));
        };
        let tool = int(t, a, "tool number")?;
        let mut length_offset = tool;
        let mut k = 1;
        while k < f.len() {
            let (t, a) = f[k];
            match t.to_ascii_uppercase().as_str() {
                "ADJUST" | "OFFSET" => {
                    let &(v, va) = f
                        .get(k + 1)
                        .ok_or_else(|| e(a, format!("{t} without a register number")))?;
                    length_offset = int(v, va, "length offset register")?;
                    k += 2;
                }
                "LENGTH" => {
                    // The controller's tool table holds the length; a value here does not
                    // move the machine.
                    let &(v, va) = f.get(k + 1).ok_or_else(|| e(a, "LENGTH without a value"))?;
                    number(v, va, "tool length")?;
                    k += 2;
                }
                "SPINDL" => {
                    let &(v, va) = f.get(k + 1).ok_or_else(|| e(a, "SPINDL without a speed"))?;
                    let rpm = number(v, va, "spindle speed")?;
                    self.check_rpm(rpm, va)?;
                    self.spindle_rpm = Some(rpm);
                    k += 2;
                }
                "MILL" | "LARGE" | "SMALL" | "HIGH" | "LOW" | "AUTO" | "MANUAL" => k += 1,
                other => {
                    return Err(e(
                        a,
                        format!(
                            "{word}: '{other}' is not read (ADJUST, OFFSET, LENGTH, SPINDL are)"
                        ),
                    ));
                }
            }
        }
        self.prog.items.push(ClItem::ToolChange {
            tool,
            length_offset,
            at,
        });
        // A speed given with the tool is the speed of the next SPINDL start.
        Ok(())
    }

    fn check_rpm(&self, rpm: f64, at: At) -> Result<(), ClError> {
        if !(rpm > 0.0 && rpm <= MAX_SPINDLE_RPM) {
            return Err(e(
                at,
                format!("spindle speed {rpm} must be within 0…{MAX_SPINDLE_RPM} rpm (and not 0)"),
            ));
        }
        Ok(())
    }

    fn spindl(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        let mut rpm = None;
        let mut dir = None;
        let mut on = false;
        for &(t, a) in f {
            match t.to_ascii_uppercase().as_str() {
                "RPM" | "" => {}
                "CLW" => dir = Some(SpindleDir::Cw),
                "CCLW" => dir = Some(SpindleDir::Ccw),
                "OFF" => dir = Some(SpindleDir::Off),
                "ON" => on = true,
                "SFM" | "SMM" => {
                    return Err(e(
                        a,
                        format!(
                            "SPINDL/{t}: constant surface speed is not posted (give the speed in RPM)"
                        ),
                    ));
                }
                "LOW" | "MEDIUM" | "HIGH" | "RANGE" => {}
                _ if t.parse::<f64>().is_ok() => {
                    let v = number(t, a, "spindle speed")?;
                    self.check_rpm(v, a)?;
                    rpm = Some(v);
                }
                other => {
                    return Err(e(
                        a,
                        format!("SPINDL: '{other}' is not read (rpm, RPM, CLW, CCLW, ON, OFF are)"),
                    ));
                }
            }
        }
        let dir = match (dir, on) {
            (Some(d), _) => d,
            (None, true) => self
                .spindle_dir
                .filter(|d| *d != SpindleDir::Off)
                .ok_or_else(|| e(at, "SPINDL/ON without a direction before it (CLW or CCLW)"))?,
            // A speed alone starts the spindle clockwise (APT's default direction).
            (None, false) if rpm.is_some() => SpindleDir::Cw,
            (None, false) => return Err(e(at, "SPINDL without a speed or a direction")),
        };
        if dir != SpindleDir::Off && rpm.is_none() && self.spindle_rpm.is_none() {
            return Err(e(
                at,
                "SPINDL starts the spindle without a speed (no rpm given before)",
            ));
        }
        if rpm.is_some() {
            self.spindle_rpm = rpm;
        }
        self.spindle_dir = Some(dir);
        // A start carries the speed in force (a LOADTL/…,SPINDL,rpm or an earlier SPINDL).
        let rpm = if dir == SpindleDir::Off {
            None
        } else {
            self.spindle_rpm
        };
        self.prog.items.push(ClItem::Spindle { rpm, dir, at });
        Ok(())
    }

    fn cutcom(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        let mut side = None;
        let mut register = None;
        let mut on = false;
        for &(t, a) in f {
            match t.to_ascii_uppercase().as_str() {
                "LEFT" => side = Some(CompSide::Left),
                "RIGHT" => side = Some(CompSide::Right),
                "OFF" => side = Some(CompSide::Off),
                "ON" => on = true,
                "XYPLAN" | "" => {}
                "YZPLAN" | "ZXPLAN" => {
                    return Err(e(
                        a,
                        format!(
                            "CUTCOM/…,{t}: compensation outside the XY plane is not posted (--ignore CUTCOM posts the moves at the CL points without compensation)"
                        ),
                    )
                    .refusing("CUTCOM"));
                }
                _ if t.parse::<f64>().is_ok() => {
                    let v = number(t, a, "CUTCOM register")?;
                    if v < 0.0 || v.fract() != 0.0 || v > 99_999.0 {
                        return Err(e(
                            a,
                            format!("CUTCOM register '{t}' is not a register number"),
                        ));
                    }
                    register = Some(v as u32);
                }
                other => {
                    return Err(e(
                        a,
                        format!(
                            "CUTCOM: '{other}' is not read (LEFT, RIGHT, OFF, ON, XYPLAN, a register are)"
                        ),
                    ));
                }
            }
        }
        match side {
            Some(side) => {
                self.cutcom_on = None;
                self.prog
                    .items
                    .push(ClItem::CutterComp { side, register, at });
            }
            None if on => self.cutcom_on = Some(at),
            None => return Err(e(at, "CUTCOM without LEFT, RIGHT, OFF or ON")),
        }
        Ok(())
    }
}

/// Read APT CLDATA (module docs).
pub fn parse_apt(text: &str, opts: &ParseOptions) -> Result<ClProgram, ClError> {
    let mut r = Reader {
        opts,
        prog: ClProgram::default(),
        units_seen: false,
        inch: false,
        feed: None,
        rapid_next: false,
        axis: [0.0, 0.0, 1.0],
        pos: None,
        last_axis: [0.0, 0.0, 1.0],
        frames: Frames::default(),
        from: None,
        circle: None,
        cycle: None,
        cycle_on: false,
        cycle_init: None,
        spindle_rpm: None,
        spindle_dir: None,
        cutcom_on: None,
        cutters_before_units: Vec::new(),
    };
    for rec in records(text)? {
        r.record(&rec)?;
    }
    // A cutter described before the units record is in the file's units.
    if r.prog.units == Units::Inch {
        for &k in &r.cutters_before_units {
            if let ClItem::Cutter(c) = &mut r.prog.items[k] {
                match &mut c.shape {
                    CutterShape::EndMill {
                        diameter_mm,
                        corner_radius_mm,
                    } => {
                        *diameter_mm *= MM_PER_INCH;
                        *corner_radius_mm *= MM_PER_INCH;
                    }
                    CutterShape::DiameterOnly { diameter_mm } => *diameter_mm *= MM_PER_INCH,
                    CutterShape::Other => {}
                }
            }
        }
    }
    if let Some(c) = r.circle {
        return Err(e(c.at, "CIRCLE without the GOTO of its end point"));
    }
    if r.prog.point_count() == 0 {
        return Err(err(1, 1, "no GOTO record: no cutter location in the file"));
    }
    Ok(r.prog)
}

#[cfg(test)]
mod tests {
    use crate::records::{Cutter, CutterShape};
    use crate::{
        ClItem, CompSide, Coolant, CycleKind, MoveKind, ParseOptions, SpindleDir, Units, parse,
        parse_with, to_apt, to_csv,
    };

    const APT: &str = "PARTNO/BLADE 7\n$$ a comment\nUNITS/MM\nMULTAX/ON\nCUTTER/6.0\nLOADTL/5\nFEDRAT/2000.0,MMPM\nGOTO/1.0,2.0,3.0,0.0,0.0,1.0\nGOTO/1.5,2.0,$\n3.0,0.6,0.0,0.8\nRAPID\nGOTO/0,0,50\nPPRINT/END OF PASS\nFINI\n";

    #[test]
    fn apt_records() {
        let p = parse(APT.as_bytes()).unwrap();
        let pts: Vec<_> = p.points().collect();
        assert_eq!(pts.len(), 3);
        assert_eq!(p.name.as_deref(), Some("BLADE 7"));
        assert_eq!(pts[1].pos_mm, [1.5, 2.0, 3.0]);
        assert_eq!(pts[1].axis, [0.6, 0.0, 0.8]);
        assert_eq!(pts[1].line, 9, "a continued record has its first line");
        assert!(pts[2].is_rapid() && !pts[1].is_rapid());
        assert_eq!(
            pts[2].axis,
            [0.6, 0.0, 0.8],
            "GOTO/x,y,z keeps the last axis"
        );
        assert_eq!(pts[0].feed_mm_min, Some(2000.0));
        assert_eq!(p.records["CUTTER"], 1);
        assert_eq!(p.records["GOTO"], 3);
        assert!(p.notes.iter().any(|n| n.contains("PPRINT END OF PASS")));
        // `CUTTER/6.0`: a flat end mill, for the tool loaded after it.
        assert!(matches!(
            p.items[1],
            ClItem::Cutter(Cutter {
                shape: CutterShape::EndMill {
                    diameter_mm: 6.0,
                    corner_radius_mm: 0.0
                },
                ..
            })
        ));
        assert!(matches!(
            p.items[2],
            ClItem::ToolChange {
                tool: 5,
                length_offset: 5,
                ..
            }
        ));
        assert!(p.items.contains(&ClItem::Comment("END OF PASS".into())));
    }

    #[test]
    fn inch_units_both_spellings_and_ipm() {
        let p = parse(b"UNITS/INCHES\nFEDRAT/IPM,10\nGOTO/1,0,0,0,0,1\n").unwrap();
        let q = p.points().next().unwrap();
        assert_eq!(q.pos_mm, [25.4, 0.0, 0.0]);
        assert_eq!(q.feed_mm_min, Some(254.0));
        assert_eq!(p.units, Units::Inch);
        let camworks = parse(b"UNIT/INCH\nFEDRAT/IPM,10\nGOTO/1,0,0,0,0,1\n").unwrap();
        assert_eq!(camworks.items, p.items);
        assert_eq!(camworks.units, Units::Inch);
        // A feed without a unit is in the file's units.
        let p = parse(b"UNIT/INCH\nFEDRAT/10\nGOTO/1,0,0\n").unwrap();
        assert_eq!(p.points().next().unwrap().feed_mm_min, Some(254.0));
        assert_eq!(parse(b"UNIT/MM\nGOTO/1,0,0\n").unwrap().units, Units::Mm);
    }

    #[test]
    fn bad_records_name_line_and_column() {
        let e = parse(b"MULTAX\nGOTO/1,2,x3,0,0,1\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 10));
        assert!(e.message.contains("z 'x3' is not a number"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2,3,0,0,0\n").unwrap_err();
        assert!(e.message.contains("length 0"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2,3,0,0.5,0.5\n").unwrap_err();
        assert!(e.message.contains("not 1"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2\n").unwrap_err();
        assert!(e.message.contains("got 2 values"), "{e}");
        let e = parse(b"MULTAX\nGOTO/1,2,$\n").unwrap_err();
        assert!(e.message.contains("ends inside a continued record"), "{e}");
        let e = parse(b"\xff\xfe").unwrap_err();
        assert!(e.message.contains("not text"), "{e}");
        assert!(parse(b"").is_err());
        assert!(parse(b"FEDRAT/-5\nGOTO/0,0,0\n").is_err());
        // A value on a continuation line is located on its own line.
        let e = parse(b"MULTAX\nGOTO/1,2,$\n  3,0,0,q\n").unwrap_err();
        assert_eq!((e.line, e.column), (3, 9), "{e}");
        // A huge axis does not overflow into a NaN axis.
        let e = parse(b"GOTO/0,0,0,1e300,0,1e300\n").unwrap_err();
        assert!(e.message.contains("not 1"), "{e}");
    }

    /// Issue 19 §5: `GOTO/1e308` was written as a 309-digit word.
    #[test]
    fn out_of_range_coordinates_are_refused_with_their_column() {
        let e = parse(b"MULTAX\nGOTO/0,1e308,0,0,0,1\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 8));
        assert!(
            e.message.contains("y '1e308'") && e.message.contains("100000"),
            "{e}"
        );
        // In inches the limit is on the converted value.
        let e = parse(b"UNITS/INCHES\nGOTO/4000,0,0\n").unwrap_err();
        assert!(e.message.contains("x '4000'"), "{e}");
        assert!(parse(b"UNITS/INCHES\nGOTO/3900,0,0\n").is_ok());
        let e = parse(b"FEDRAT/1e300\nGOTO/0,0,0\n").unwrap_err();
        assert!(e.message.contains("feed"), "{e}");
        let e = parse(b"GOTO/0,0,0\nCIRCLE/0,0,0,0,0,1,1e200\nGOTO/1,0,0\n").unwrap_err();
        assert!(e.message.contains("r '1e200'"), "{e}");
    }

    #[test]
    fn arcs_take_the_previous_point_and_the_next_goto() {
        let p = parse(
            b"UNIT/MM\nFEDRAT/500\nGOTO/10,0,-2\nCIRCLE/0,0,-2,0,0,-1,10,0.01\nGOTO/0,-10,-2\nGOTO/0,-20,-2\n",
        )
        .unwrap();
        let pts: Vec<_> = p.points().collect();
        let MoveKind::Arc(a) = &pts[1].kind else {
            panic!("{:?}", pts[1].kind)
        };
        // Clockwise seen from +Z (axis −Z) from (10,0) to (0,−10): a quarter.
        assert!((a.sweep_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(a.radius_mm, 10.0);
        assert_eq!(pts[2].kind, MoveKind::Linear, "CIRCLE applies to one GOTO");
        let e = parse(b"GOTO/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nGOTO/0,11,0\n").unwrap_err();
        assert_eq!((e.line, e.column), (2, 1));
        assert!(e.message.contains("off the circle"), "{e}");
        let e = parse(b"GOTO/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nFINI\n").unwrap_err();
        assert!(e.message.contains("without the GOTO"), "{e}");
        let e = parse(b"GOTO/10,0,0\nCIRCLE/0,0,0,0,0,1,10\nRAPID\nGOTO/0,10,0\n").unwrap_err();
        assert!(e.message.contains("RAPID before a circular"), "{e}");
        // MOVARC (ISO 4343 posts): the angle, here one and a half turns of a helix.
        let p = parse(b"GOTO/5,0,0\nMOVARC/0,0,0,0,0,1,5,ANGLE,540\nGOTO/-5,0,-3\n").unwrap();
        let MoveKind::Arc(a) = &p.points().nth(1).unwrap().kind else {
            panic!()
        };
        assert!((a.sweep_rad - 3.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(a.lead_mm, -3.0);
    }

    #[test]
    fn cycles_make_holes_with_the_feed_of_the_record() {
        let text = "UNIT/MM\nLOADTL/3\nSPINDL/1200,CLW\nRAPID\nGOTO/10,10,20\n\
                    CYCLE/DRILL,FEDTO,12.5,MMPM,150,RAPTO,2,RTRCTO,5\n\
                    GOTO/10,10,0\nGOTO/30,10,-1\nCYCLE/OFF\nRAPID\nGOTO/30,10,50\n";
        let p = parse(text.as_bytes()).unwrap();
        let pts: Vec<_> = p.points().collect();
        assert_eq!(pts.len(), 4);
        let MoveKind::Hole(c) = &pts[1].kind else {
            panic!("{:?}", pts[1].kind)
        };
        assert_eq!(c.kind, CycleKind::Drill);
        assert_eq!(
            (c.depth_mm, c.feed_mm_min, c.clearance_mm, c.retract_mm),
            (12.5, 150.0, 2.0, Some(5.0))
        );
        assert_eq!(c.at.line, 6);
        assert!(matches!(pts[2].kind, MoveKind::Hole(_)));
        assert!(pts[3].is_rapid());
        // Peck drilling in inches with the feed from FEDRAT.
        let p = parse(
            b"UNITS/INCHES\nFEDRAT/IPM,4\nCYCLE/DEEP2,FEDTO,0.5,RAPTO,0.1,STEP,0.1\nGOTO/1,1,0\nCYCLE/OFF\n",
        )
        .unwrap();
        let MoveKind::Hole(c) = &p.points().next().unwrap().kind else {
            panic!()
        };
        assert_eq!(c.kind, CycleKind::Deep);
        assert!((c.depth_mm - 12.7).abs() < 1e-12 && (c.feed_mm_min - 101.6).abs() < 1e-12);
        assert!((c.peck_mm.unwrap() - 2.54).abs() < 1e-12);
        // Refusals, each at its field.
        for (text, at, what) in [
            (
                "CYCLE/DRILL,FEDTO,5,MMPM,100\nGOTO/0,0,0\n",
                (1, 1),
                "without RAPTO",
            ),
            (
                "CYCLE/DRILL,5,MMPM,100,2\nGOTO/0,0,0\n",
                (1, 13),
                "follows no keyword",
            ),
            (
                "CYCLE/DRILL,FEDTO,5,RAPTO,2\nGOTO/0,0,0\n",
                (1, 1),
                "without a feed",
            ),
            (
                "CYCLE/DEEP,FEDTO,5,MMPM,9,RAPTO,2\nGOTO/0,0,0\n",
                (1, 1),
                "without STEP",
            ),
            (
                "CYCLE/THRU,FEDTO,5\nGOTO/0,0,0\n",
                (1, 7),
                "CYCLE/THRU is not posted",
            ),
            (
                "CYCLE/DRILL,FEDTO,-5,MMPM,9,RAPTO,2\nGOTO/0,0,0\n",
                (1, 19),
                "must be positive",
            ),
            (
                "CYCLE/DRILL,FEDTO,5,MMPM,9,RAPTO,2,ORIENT,0\nGOTO/0,0,0\n",
                (1, 36),
                "'ORIENT'",
            ),
            ("CYCLE/ON\nGOTO/0,0,0\n", (1, 1), "without a cycle"),
            (
                "FEDRAT/9\nCYCLE/DRILL,FEDTO,5,RAPTO,2\nRAPID\nGOTO/0,0,0\n",
                (4, 1),
                "RAPID before a GOTO while a CYCLE",
            ),
            (
                "CYCLE/DRILL,FEDTO,5,IPR,0.1,RAPTO,2\nGOTO/0,0,0\n",
                (1, 21),
                "spindle speed",
            ),
        ] {
            let e = parse(text.as_bytes()).unwrap_err();
            assert_eq!((e.line, e.column), at, "{text}: {e}");
            assert!(e.message.contains(what), "{text}: {e}");
        }
        // Per-revolution feed with a spindle speed.
        let p =
            parse(b"SPINDL/1000,CLW\nCYCLE/TAP,FEDTO,8,MMPR,1.25,RAPTO,3\nGOTO/0,0,0\n").unwrap();
        let MoveKind::Hole(c) = &p.points().next().unwrap().kind else {
            panic!()
        };
        assert_eq!((c.kind, c.feed_mm_min), (CycleKind::Tap, 1250.0));
    }

    /// `CUTTER/` and `TLDATA/` as end mills (mm, the file's units), other shapes as none,
    /// Creo's commented `$$-> CUTTER / d` read at its own column; none is an error.
    #[test]
    fn cutters() {
        let p = parse(
            b"UNITS/MM\nCUTTER/10,5,0,5,0,0,75\nCUTTER/6.5,0,3.25,1.95,31.,0,105.\n\
              TLDATA/MILL,32.0,5.0,75.0,0.0,0.0\nTLDATA/DRILL,8,118\n  $$-> CUTTER / 6.000000\n\
              CUTTER/10,0,5,0,0,10,60\nCUTTER/x\nGOTO/0,0,0\n",
        )
        .unwrap();
        let cutters: Vec<_> = p
            .items
            .iter()
            .filter_map(|i| match i {
                ClItem::Cutter(c) => Some((c.shape, c.at.line, c.at.column)),
                _ => None,
            })
            .collect();
        let mill = |d: f64, r: f64| CutterShape::EndMill {
            diameter_mm: d,
            corner_radius_mm: r,
        };
        assert_eq!(
            cutters,
            [
                (mill(10.0, 5.0), 2, 1),
                (CutterShape::Other, 3, 1),
                (mill(32.0, 5.0), 4, 1),
                (CutterShape::Other, 5, 1),
                (CutterShape::DiameterOnly { diameter_mm: 6.0 }, 6, 8),
                // A side angle: tapered.
                (CutterShape::Other, 7, 1),
                (CutterShape::Other, 8, 1),
            ]
        );
        assert_eq!(p.records["CUTTER"], 5);
        let inch = parse(b"CUTTER/.5,.25\nUNITS/INCHES\nGOTO/0,0,0\n").unwrap();
        assert!(matches!(
            inch.items[0],
            ClItem::Cutter(Cutter { shape: CutterShape::EndMill { diameter_mm: d, corner_radius_mm: r }, .. }) if (d - 12.7).abs() < 1e-12 && (r - 6.35).abs() < 1e-12
        ));
    }

    #[test]
    fn set_up_records() {
        let p = parse(
            b"LOAD/TOOL,7,ADJUST,17\nSPINDL/RPM,5000,CCLW\nCOOLNT/ON\nCOOLNT/flood\nCOOLNT/MIST\n\
              CUTCOM/ON\nCUTCOM/LEFT,12\nGOTO/0,0,0\nCUTCOM/OFF\nDELAY/1.5\nOPSTOP\nSPINDL/OFF\n\
              COOLNT/OFF\nSTOP\nLOADTL/2,SPINDL,800\nSPINDL/CLW\nSELCTL/4\n",
        )
        .unwrap();
        let items: Vec<_> = p
            .items
            .iter()
            .filter(|i| !matches!(i, ClItem::Move(_)))
            .map(|i| match i {
                ClItem::ToolChange {
                    tool,
                    length_offset,
                    ..
                } => format!("T{tool} H{length_offset}"),
                ClItem::Spindle { rpm, dir, .. } => format!("S{rpm:?} {dir:?}"),
                ClItem::Coolant { mode, .. } => format!("{mode:?}"),
                ClItem::CutterComp { side, register, .. } => format!("{side:?} {register:?}"),
                ClItem::Dwell { seconds, .. } => format!("dwell {seconds}"),
                ClItem::Stop { optional, .. } => format!("stop {optional}"),
                ClItem::Comment(c) => c.clone(),
                ClItem::Insert { text, .. } => format!("insert {text}"),
                ClItem::Cutter(c) => format!("cutter {:?}", c.shape),
                ClItem::Move(_) => unreachable!(),
            })
            .collect();
        assert_eq!(
            items,
            [
                "T7 H17",
                "SSome(5000.0) Ccw",
                "Flood",
                "Flood",
                "Mist",
                "Left Some(12)",
                "Off None",
                "dwell 1.5",
                "stop true",
                "SNone Off",
                "Off",
                "stop false",
                "T2 H2",
                "SSome(800.0) Cw",
            ]
        );
        let _ = (CompSide::Left, Coolant::Off, SpindleDir::Off);
        for (text, what) in [
            ("SPINDL/300,SMM,CLW\nGOTO/0,0,0\n", "constant surface speed"),
            ("SPINDL/CLW\nGOTO/0,0,0\n", "without a speed"),
            ("COOLNT/THRU\nGOTO/0,0,0\n", "COOLNT/THRU is not posted"),
            ("CUTCOM/ON\nGOTO/0,0,0\n", "CUTCOM/ON without LEFT or RIGHT"),
            ("CUTCOM/LEFT,YZPLAN\nGOTO/0,0,0\n", "outside the XY plane"),
            ("LOADTL/2.5\nGOTO/0,0,0\n", "not a tool"),
            ("GOHOME\nGOTO/0,0,0\n", "without a FROM"),
        ] {
            let e = parse(text.as_bytes()).unwrap_err();
            assert!(e.message.contains(what), "{text}: {e}");
        }
    }

    #[test]
    fn from_gohome_godlta_and_tlaxis_are_moves() {
        let p = parse(
            b"FROM/0,0,100\nTLAXIS/0,0.6,0.8\nFEDRAT/100\nGOTO/1,2,3\nGODLTA/5\nGODLTA/1,0,0\nRAPID,GOTO/0,0,50\nGOHOME\n",
        )
        .unwrap();
        let pts: Vec<_> = p.points().collect();
        assert!(pts[0].is_rapid() && pts[0].axis == [0.0, 0.0, 1.0]);
        assert_eq!(pts[1].axis, [0.0, 0.6, 0.8]);
        assert_eq!(
            pts[2].pos_mm,
            [1.0, 5.0, 7.0],
            "GODLTA/d along the tool axis"
        );
        assert_eq!(pts[3].pos_mm, [2.0, 5.0, 7.0]);
        assert!(pts[4].is_rapid() && pts[4].pos_mm == [0.0, 0.0, 50.0]);
        assert!(pts[5].is_rapid() && pts[5].pos_mm == [0.0, 0.0, 100.0]);
        assert_eq!(
            pts[5].axis,
            [0.0, 0.0, 1.0],
            "GOHOME returns to FROM's axis too"
        );
    }

    /// Issue 30 item 3: a `$$` comment ending with `$` continues on the next line, as
    /// comment (Creo's CSYS comment); a line of values without a record word is refused
    /// naming that, and no `--ignore` is suggested for a number.
    #[test]
    fn a_comment_continues_as_comment() {
        let text = "$$-> CSYS / 1.0000000000, 0.0000000000, 0.0000000000, 0.0000000000,  $\n\
                    \x20           0.0000000000, 1.0000000000, 0.0000000000, 0.0000000000,  $\n\
                    \x20           0.0000000000, 0.0000000000, 1.0000000000, 0.0000000000\n\
                    MULTAX / ON\n\
                    GOTO / 1.0, 2.0, 3.0,  $\n\
                    0.0, 0.0, 1.0\n";
        let p = parse(text.as_bytes()).unwrap();
        assert_eq!(p.point_count(), 1);
        assert_eq!(p.points().next().unwrap().pos_mm, [1.0, 2.0, 3.0]);
        // Without the comment, the same lines are values without a record.
        let bare = text.replacen(
            "$$-> CSYS / 1.0000000000, 0.0000000000, 0.0000000000, 0.0000000000,  $",
            "$$-> CSYS",
            1,
        );
        let e = parse(bare.as_bytes()).unwrap_err();
        assert_eq!(e.line, 2, "{e}");
        assert!(
            e.message.contains("does not start with an APT record word"),
            "{e}"
        );
        assert!(!e.message.contains("--ignore"), "{e}");
    }

    /// Issue 30 item 4: `INSERT/` text is kept for the program, in file order, and listed.
    #[test]
    fn insert_records_are_kept_and_listed() {
        let p = parse(b"UNIT/MM\nINSERT/14MM CRB 4FL 32 LOC  \nGOTO/0,0,0\nINSERT/M88\n").unwrap();
        let inserts: Vec<_> = p
            .items
            .iter()
            .filter_map(|i| match i {
                ClItem::Insert { text, at } => Some((text.as_str(), at.line)),
                _ => None,
            })
            .collect();
        assert_eq!(inserts, [("14MM CRB 4FL 32 LOC", 2), ("M88", 4)]);
        assert_eq!(p.records["INSERT"], 2);
        assert!(
            p.notes
                .iter()
                .any(|n| n.contains("line 2: INSERT/14MM CRB 4FL 32 LOC")),
            "{:?}",
            p.notes
        );
        // Still skippable on request.
        let q = parse_with(
            b"INSERT/M88\nGOTO/0,0,0\n",
            &ParseOptions {
                ignore: vec!["INSERT".into()],
                ..ParseOptions::default()
            },
        )
        .unwrap();
        assert_eq!(q.skipped["INSERT"].count, 1);
        assert_eq!(q.items.len(), 1);
    }

    /// Issue 16 §6: a record nobody handles stops the read naming it, unless skipped.
    #[test]
    fn unknown_records_stop_the_read_unless_ignored() {
        let text = "GOTO/0,0,0\n  THREAD/TURN,1.5\nGOTO/1,0,0\nTHREAD/OFF\n";
        let e = parse(text.as_bytes()).unwrap_err();
        assert_eq!((e.line, e.column), (2, 3));
        assert!(
            e.message.contains("THREAD records are not posted")
                && e.message.contains("--ignore THREAD"),
            "{e}"
        );
        let opts = ParseOptions {
            ignore: vec!["thread".into()],
            ..ParseOptions::default()
        };
        let p = parse_with(text.as_bytes(), &opts).unwrap();
        assert_eq!(p.point_count(), 2);
        assert_eq!(p.skipped["THREAD"].count, 2);
        assert_eq!(p.records["THREAD"], 2);
        for w in [
            "AUXFUN/10",
            "TURRET/2",
            "TRNTYP/1",
            "PREFUN/54",
            "TLON,GOFWD/(CIRCLE/0,0,0,1)",
        ] {
            let e = parse(format!("GOTO/0,0,0\n{w}\n").as_bytes()).unwrap_err();
            assert_eq!(e.line, 2, "{w}");
            let name = w.split(['/', ',']).next().unwrap();
            assert!(e.message.contains(name), "{w}: {e}");
            // The refusal names the record kind `--ignore` would skip.
            assert_eq!(e.refused_record.as_deref(), Some(name), "{w}");
        }
        // The reader skips what it is told, posted kinds too (which of those may be
        // skipped is the post's rule: a record refused in the file).
        let p = parse_with(
            b"GOTO/0,0,0\n  COOLNT/FLOOD\nGOTO/1,0,0\nCOOLNT/OFF\n",
            &ParseOptions {
                ignore: vec!["coolnt".into()],
                ..ParseOptions::default()
            },
        )
        .unwrap();
        assert_eq!(p.point_count(), 2);
        assert_eq!(p.items.len(), 2);
        assert_eq!(p.skipped["COOLNT"].count, 2);
        assert_eq!(p.skipped["COOLNT"].first, crate::At { line: 2, column: 3 });
        // A bad value is not a refusal of the record: nothing to skip.
        let e = parse(b"GOTO/0,0,0\nGOTO/1,2,3.5.1\n").unwrap_err();
        assert_eq!(e.refused_record, None, "{e}");
        // Forms of posted records polepatch does not post are refusals of them.
        for (text, name) in [
            ("COOLNT/THRU\n", "COOLNT"),
            ("DELAY/REV,2\n", "DELAY"),
            ("CUTCOM/LEFT,YZPLAN\n", "CUTCOM"),
        ] {
            let e = parse(format!("GOTO/0,0,0\n{text}").as_bytes()).unwrap_err();
            assert_eq!(e.refused_record.as_deref(), Some(name), "{text}: {e}");
        }
    }

    /// The file's first units record is where an inch refusal points.
    #[test]
    fn the_first_units_record_is_located() {
        let p = parse(b"PARTNO/X\n  UNITS/INCHES\nUNITS/MM\nGOTO/0,0,0\n").unwrap();
        assert_eq!(p.units, Units::Inch);
        assert_eq!(p.units_at, Some(crate::At { line: 2, column: 3 }));
        assert_eq!(parse(b"GOTO/0,0,0\n").unwrap().units_at, None);
    }

    /// CAMWorks' forms: CIRCLE without a radius (the start point's), CYCLE/INIT before a
    /// cycle, 1STPECK/SUBPECK (read when equal), RAPID/ with a slash.
    #[test]
    fn camworks_forms() {
        let p = parse(
            b"UNIT/MM\nRAPID/\nGOTO/0,0,10\nFEDRAT/100,MMPM\nGOTO/-1.2,0,0\nCIRCLE/0,0,0,0,0,1.\nGOTO/0,-1.2,0\n\
              CYCLE/INIT\nCYCLE/DEEP2,FEDTO,10.,1STPECK,2.,SUBPECK,2.,MMPM,50.,RAPTO,3.\nGOTO/5,5,0\nCYCLE/OFF\n",
        )
        .unwrap();
        let pts: Vec<_> = p.points().collect();
        assert!(pts[0].is_rapid());
        let MoveKind::Arc(a) = &pts[2].kind else {
            panic!()
        };
        assert!((a.radius_mm - 1.2).abs() < 1e-12);
        // From 180° to 270° counter-clockwise: a quarter.
        assert!((a.sweep_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let MoveKind::Hole(c) = &pts[3].kind else {
            panic!()
        };
        assert_eq!(c.peck_mm, Some(2.0));
        for (text, at, what) in [
            (
                "FEDRAT/9\nCYCLE/INIT\nGOTO/0,0,0\n",
                (2, 1),
                "CYCLE/INIT without a cycle",
            ),
            (
                "CYCLE/DEEP2,FEDTO,9,1STPECK,5.,SUBPECK,2.,MMPM,9,RAPTO,3\nGOTO/0,0,0\n",
                (1, 21),
                "1STPECK 5",
            ),
        ] {
            let e = parse(text.as_bytes()).unwrap_err();
            assert_eq!((e.line, e.column), at, "{text}: {e}");
            assert!(e.message.contains(what), "{text}: {e}");
        }
        // On request, the smaller peck throughout.
        let opts = ParseOptions {
            uniform_peck: true,
            ..ParseOptions::default()
        };
        let p = parse_with(
            b"CYCLE/DEEP2,FEDTO,9,1STPECK,5.,SUBPECK,2.,MMPM,9,RAPTO,3\nGOTO/0,0,0\n",
            &opts,
        )
        .unwrap();
        let MoveKind::Hole(c) = &p.points().next().unwrap().kind else {
            panic!()
        };
        assert_eq!(c.peck_mm, Some(2.0));
    }

    #[test]
    fn writers_read_back() {
        let text = "FEDRAT/500\nGOTO/10,0,-2,0,0,1\nCIRCLE/0,0,-2,0,0,-1,10\nGOTO/0,-10,-2\n\
                    RAPID\nGOTO/0,0,20\nCYCLE/DEEP,FEDTO,8,MMPM,90,RAPTO,2,STEP,3\nGOTO/0,0,0\n\
                    GOTO/5,0,0\nCYCLE/OFF\nGOTO/5,0,20\n";
        let p = parse(text.as_bytes()).unwrap();
        let pts: Vec<_> = p.points().cloned().collect();
        let q = parse(to_apt(&pts, "X", 7).as_bytes()).unwrap();
        let back: Vec<_> = q.points().cloned().collect();
        assert_eq!(back.len(), pts.len());
        // The same kinds (a cycle's record line aside).
        let kind = |k: &MoveKind| match k {
            MoveKind::Hole(c) => MoveKind::Hole(crate::Cycle {
                at: Default::default(),
                ..c.clone()
            }),
            k => k.clone(),
        };
        for (a, b) in pts.iter().zip(&back) {
            assert_eq!(a.pos_mm, b.pos_mm);
            assert_eq!(a.axis, b.axis);
            assert_eq!(kind(&a.kind), kind(&b.kind));
        }
        let c = parse(to_csv(&pts, 7).as_bytes()).unwrap();
        assert_eq!(c.point_count(), pts.len());
    }
}
