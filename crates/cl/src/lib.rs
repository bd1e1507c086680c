//! Cutter locations (CL) as CAM systems hand them out: tool-tip position and tool axis
//! per point, in the part frame — G16's stage 1, before any machine's inverse kinematics —
//! and the set-up records between them.
//!
//! Two formats ([`parse`] detects which):
//!
//! - **APT CLDATA** ([`apt`]): moves (`GOTO`, `RAPID`, `CIRCLE`/`MOVARC` arcs, `CYCLE`
//!   holes, `FROM`, `GOHOME`, `GODLTA`), feeds, units, and machine set-up (`LOADTL`,
//!   `SPINDL`, `COOLNT`, `CUTCOM`, `DELAY`, `STOP`, comments). A record that changes the
//!   motion and is not read stops the read with its line, column and name (unless skipped
//!   by name, [`ParseOptions::ignore`]); records that do not change the motion are counted.
//!   Coordinate-frame records (`TRNTYP`, `CSYS`, `MSYS`, …) are read as the CAM systems
//!   that write them mean them, or refused ([`frames`]).
//! - **CSV** ([`csv`]) `x,y,z,i,j,k[,f]` per line, mm and mm/min: straight moves.
//!
//! Errors name the line and column and the value. Lengths are mm inside (inch files are
//! converted on read), feeds mm/min; a coordinate beyond [`MAX_COORDINATE_MM`] is refused.
//! A tool axis is normalised when its length is within [`UNIT_TOLERANCE`] of 1 and refused
//! otherwise. A UTF-8 byte-order mark at the start of the file is skipped.

pub mod apt;
pub mod arcs;
pub mod csv;
pub mod cycles;
pub mod frames;
pub mod records;
pub mod tolerances;
mod values;
pub mod write;

pub use arcs::{Arc, ArcError, Plane};
pub use cycles::{Cycle, CycleKind};
pub use records::{
    ClItem, ClPoint, ClProgram, CompSide, Coolant, Cutter, CutterShape, MoveKind, Skipped,
    SpindleDir, Units,
};
pub use write::{to_apt, to_csv};

pub use tolerances::{MAX_COORDINATE_MM, MAX_FEED_MM_MIN, MAX_SPINDLE_RPM, UNIT_TOLERANCE};

/// mm per inch.
pub const MM_PER_INCH: f64 = 25.4;

/// Where a record starts in the file: 1-based line and byte column.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct At {
    /// 1-based line of the record's first line (a `$`-continued record has its first line).
    pub line: usize,
    /// 1-based byte column of the record word (or of the value a message is about).
    pub column: usize,
}

/// A bad record.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{line}:{column}: {message}")]
pub struct ClError {
    /// 1-based line.
    pub line: usize,
    /// 1-based byte column.
    pub column: usize,
    /// What is wrong, naming the value.
    pub message: String,
    /// The major word of the record this error refuses (`CUTCOM`, `THREAD`), where the
    /// refusal is of a record whose skipping (`--ignore WORD`, [`ParseOptions::ignore`])
    /// leaves every other record meaning what it says: records polepatch does not post,
    /// frame records, and forms of `COOLNT`, `DELAY` and `CUTCOM` it does not post (the
    /// moves are then posted at the CL points without the controller's compensation).
    /// `None` for bad values and for refusals no skipping can answer (a tool axis out of
    /// range, a tilted hole, a move polepatch cannot read).
    pub refused_record: Option<String>,
}

impl ClError {
    /// This error, as the refusal of the record `word` ([`ClError::refused_record`]).
    pub fn refusing(mut self, word: &str) -> Self {
        self.refused_record = Some(word.to_ascii_uppercase());
        self
    }
}

pub(crate) fn err(line: usize, column: usize, message: impl Into<String>) -> ClError {
    ClError {
        line,
        column,
        message: message.into(),
        refused_record: None,
    }
}

/// How to read a CL file. Plain struct; see each field for its default.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParseOptions {
    /// APT records to skip, by major word (`THREAD`, `INSERT`, …), case-insensitive: each
    /// is counted in [`ClProgram::skipped`] instead of being read. The reader skips what it
    /// is told; which records may be skipped is the post's rule (a record refused in the
    /// file: `polepatch::post::read_cl_for_post`). Default none.
    pub ignore: Vec<String>,
    /// Peck cycles whose first peck differs from the following ones (CAMWorks'
    /// `1STPECK,p1,SUBPECK,p2`) are drilled with the smaller peck throughout instead of
    /// being refused (the dialects' peck cycles take one peck). Default `false`.
    pub uniform_peck: bool,
}

impl ParseOptions {
    /// An error for an empty record name in `ignore`.
    pub fn check(&self) -> Result<(), String> {
        if self.ignore.iter().any(|w| w.trim().is_empty()) {
            return Err("--ignore needs a record name".into());
        }
        Ok(())
    }
}

/// The lines of `text`: ends at LF, CR LF or a lone CR (old Mac files); a line end at the
/// end of the text starts no further line.
pub(crate) fn lines(text: &str) -> impl Iterator<Item = &str> {
    let text = match text.strip_suffix('\n') {
        Some(t) => t.strip_suffix('\r').unwrap_or(t),
        None => text.strip_suffix('\r').unwrap_or(text),
    };
    text.split('\n')
        .flat_map(|l| l.strip_suffix('\r').unwrap_or(l).split('\r'))
}

/// Read a CL file with the default options ([`parse_with`]).
pub fn parse(bytes: &[u8]) -> Result<ClProgram, ClError> {
    parse_with(bytes, &ParseOptions::default())
}

/// Read a CL file: APT when a line starts with an APT record word (`GOTO/`, `FEDRAT/`,
/// `MULTAX`, …), else CSV.
pub fn parse_with(bytes: &[u8], opts: &ParseOptions) -> Result<ClProgram, ClError> {
    opts.check().map_err(|m| err(1, 1, m))?;
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let before = &bytes[..e.valid_up_to()];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let col = before.len()
            - before
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1)
            + 1;
        err(line, col, "the file is not text (invalid UTF-8)")
    })?;
    let is_apt = lines(text).any(|l| {
        let u = l.trim_start().to_ascii_uppercase();
        [
            "GOTO/", "FEDRAT/", "MULTAX", "PARTNO", "RAPID", "UNITS/", "UNIT/", "TLAXIS", "LOADTL",
            "CUTTER", "CIRCLE/", "CYCLE/", "SPINDL", "COOLNT", "FROM/", "$$",
        ]
        .iter()
        .any(|k| u.starts_with(k))
    });
    if is_apt {
        apt::parse_apt(text, opts)
    } else {
        csv::parse_csv(text)
    }
}

fn unit_axis(v: [f64; 3], line: usize, column: usize) -> Result<[f64; 3], ClError> {
    // Scaled first: the squares of 1e200 overflow.
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    let n = if m > 0.0 && m.is_finite() {
        let s = [v[0] / m, v[1] / m, v[2] / m];
        m * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
    } else {
        m
    };
    if n.is_nan() || (n - 1.0).abs() > UNIT_TOLERANCE {
        return Err(err(
            line,
            column,
            format!(
                "tool axis ({}, {}, {}) has length {n:.6}, not 1",
                v[0], v[1], v[2]
            ),
        ));
    }
    Ok([v[0] / n, v[1] / n, v[2] / n])
}
