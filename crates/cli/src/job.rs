//! Patching a whole program: runs → patcher → edits → bytes, and writing them safely.

use crate::program::{InputError, LoadedProgram, load, read_program};
use crate::report::{axis_letter, limit_name, zone_kind_name};
use polepatch_kinematics::Machine;
use polepatch_nc::{Edit, NumberStyle, Program, modal};
use polepatch_patcher::{Method, Outcome, PatchOptions, ZoneFigures, ZoneReport, patch_path};
use serde::Serialize;
use std::io::Write;
use std::path::Path as FsPath;

/// Equation-6 figures of a zone, with axis letters (report form of [`ZoneFigures`]).
#[derive(Debug, Clone, Serialize)]
pub struct FiguresRow {
    /// Lowest C-limited ratio.
    pub c_ratio: f64,
    /// Lowest primary-limited ratio.
    pub primary_ratio: f64,
    /// Lowest overall ratio.
    pub overall_ratio: f64,
    /// Limiting axis letter (`null`: the feed).
    pub limiting_axis: Option<String>,
    /// `V`, `A`, `J` or `F`.
    pub limiting_limit: &'static str,
    /// Estimated time over the zone, s.
    pub time_s: f64,
}

impl FiguresRow {
    fn new(f: &ZoneFigures, primary_letter: u8) -> Self {
        FiguresRow {
            c_ratio: f.c_ratio,
            primary_ratio: f.primary_ratio,
            overall_ratio: f.overall_ratio,
            limiting_axis: f.limiting_axis.map(|a| axis_letter(a, primary_letter)),
            limiting_limit: limit_name(f.limiting_kind),
            time_s: f.time_s,
        }
    }
}

/// One zone of one file (a report row; also the CSV row, flattened).
#[derive(Debug, Clone, Serialize)]
pub struct ZoneRow {
    /// Input file.
    pub file: String,
    /// Run number, from 1.
    pub run: usize,
    /// File lines of the first and last point of the zone/patch.
    pub lines: [usize; 2],
    /// `A-flip` or `C-swing`.
    pub kind: &'static str,
    /// Smallest |primary|, degrees.
    pub min_abs_primary_deg: f64,
    /// Before patching.
    pub before: FiguresRow,
    /// After patching, on the values as written.
    pub after: FiguresRow,
    /// L/F over the zone, s.
    pub ideal_time_s: f64,
    /// Largest orientation deviation, degrees.
    pub max_deviation_deg: f64,
    /// Points whose C changed.
    pub points_modified: usize,
    /// Patched length, mm.
    pub patch_length_mm: f64,
    /// `reached`, `improved` or `unchanged`.
    pub outcome: &'static str,
    /// `g16-patch`, `direct` or `none`.
    pub method: &'static str,
    /// Last solver status.
    pub qp_status: String,
    /// Interior-point iterations, summed.
    pub qp_iterations: u32,
    /// QP solves.
    pub qp_solves: u32,
    /// Solve time, ms, summed.
    pub solve_time_ms: f64,
    /// Decimal places written for the changed C words.
    pub decimals: usize,
    /// 360° multiple added to C after the zone.
    pub c_offset_deg: f64,
}

/// Report name of an outcome.
pub fn outcome_name(o: Outcome) -> &'static str {
    match o {
        Outcome::Reached => "reached",
        Outcome::Improved => "improved",
        Outcome::Unchanged => "unchanged",
    }
}

fn method_name(m: Method) -> &'static str {
    match m {
        Method::G16Patch => "g16-patch",
        Method::Direct => "direct",
        Method::None => "none",
    }
}

impl ZoneRow {
    /// CSV column names of [`ZoneRow::csv_fields`] (the row's fields after `file`).
    pub const CSV_COLUMNS: [&'static str; 27] = [
        "run",
        "first_line",
        "last_line",
        "kind",
        "min_abs_primary_deg",
        "c_ratio_before",
        "c_ratio_after",
        "primary_ratio_before",
        "primary_ratio_after",
        "overall_ratio_before",
        "overall_ratio_after",
        "limiting_before",
        "limiting_after",
        "time_before_s",
        "time_after_s",
        "ideal_time_s",
        "max_deviation_deg",
        "points_modified",
        "patch_length_mm",
        "outcome",
        "method",
        "qp_status",
        "qp_iterations",
        "qp_solves",
        "solve_time_ms",
        "decimals",
        "c_offset_deg",
    ];

    /// The row as CSV fields, in [`ZoneRow::CSV_COLUMNS`] order.
    pub fn csv_fields(&self) -> Vec<String> {
        let lim = |f: &FiguresRow| {
            format!(
                "{}:{}",
                f.limiting_axis.as_deref().unwrap_or("-"),
                f.limiting_limit
            )
        };
        vec![
            self.run.to_string(),
            self.lines[0].to_string(),
            self.lines[1].to_string(),
            self.kind.to_string(),
            format!("{:.6}", self.min_abs_primary_deg),
            format!("{:.6}", self.before.c_ratio),
            format!("{:.6}", self.after.c_ratio),
            format!("{:.6}", self.before.primary_ratio),
            format!("{:.6}", self.after.primary_ratio),
            format!("{:.6}", self.before.overall_ratio),
            format!("{:.6}", self.after.overall_ratio),
            lim(&self.before),
            lim(&self.after),
            format!("{:.6}", self.before.time_s),
            format!("{:.6}", self.after.time_s),
            format!("{:.6}", self.ideal_time_s),
            format!("{:.6}", self.max_deviation_deg),
            self.points_modified.to_string(),
            format!("{:.3}", self.patch_length_mm),
            self.outcome.to_string(),
            self.method.to_string(),
            self.qp_status.clone(),
            self.qp_iterations.to_string(),
            self.qp_solves.to_string(),
            format!("{:.3}", self.solve_time_ms),
            self.decimals.to_string(),
            format!("{}", self.c_offset_deg),
        ]
    }

    fn new(lp: &LoadedProgram, run: usize, z: &ZoneReport) -> Self {
        let pl = lp.primary_letter;
        ZoneRow {
            file: lp.name.clone(),
            run: run + 1,
            lines: [lp.line_of(run, z.first), lp.line_of(run, z.last)],
            kind: zone_kind_name(z.kind),
            min_abs_primary_deg: z.min_abs_primary_deg,
            before: FiguresRow::new(&z.before, pl),
            after: FiguresRow::new(&z.after, pl),
            ideal_time_s: z.ideal_time_s,
            max_deviation_deg: z.max_deviation_deg,
            points_modified: z.points_modified,
            patch_length_mm: z.patch_length_mm,
            outcome: outcome_name(z.outcome),
            method: method_name(z.method),
            qp_status: z.qp.status.clone(),
            qp_iterations: z.qp.iterations,
            qp_solves: z.qp.solves,
            solve_time_ms: z.qp.solve_time_s * 1e3,
            decimals: z.decimals,
            c_offset_deg: z.c_offset_deg,
        }
    }
}

/// What patching one program did.
#[derive(Debug, Clone, Serialize)]
pub struct FileReport {
    /// Input file.
    pub file: String,
    /// Output file (when written).
    pub output: Option<String>,
    /// Machine name.
    pub machine: String,
    /// C words changed or inserted.
    pub words_changed: usize,
    /// Decimal places of the file's C words (`None` when no run came near the pole, so
    /// the file's style was not read).
    pub file_c_decimals: Option<usize>,
    /// Decimal places written for changed C words (more than the file's when its
    /// precision could not hold Equation 6).
    pub written_c_decimals: Option<usize>,
    /// Runs not analysed, and why.
    pub skipped_runs: Vec<String>,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// One row per zone.
    pub zones: Vec<ZoneRow>,
}

impl FileReport {
    /// Zones whose C stays below feed.
    pub fn zones_below_feed(&self) -> usize {
        self.zones.iter().filter(|z| z.outcome != "reached").count()
    }
}

/// Patch a loaded program: the edits to write and the report.
pub fn patch_program(
    lp: &LoadedProgram,
    machine: &Machine,
    opts: &PatchOptions,
) -> (Vec<Edit>, FileReport) {
    let program = &lp.program;
    // The file's C style is only needed when some run comes near the pole; reading it costs
    // a pass over every word, so a program without such a run skips it.
    let near_pole = lp.runs.iter().any(|r| {
        r.path.as_ref().is_ok_and(|p| {
            p.axes
                .iter()
                .any(|q| q[polepatch_kinematics::Axis::Primary.index()].abs() <= opts.cone_deg)
        })
    });
    if !near_pole {
        let skipped = lp
            .runs
            .iter()
            .enumerate()
            .filter_map(|(r, rp)| {
                rp.path
                    .as_ref()
                    .err()
                    .map(|problem| skipped_run(lp, r, problem))
            })
            .collect();
        return (
            Vec::new(),
            FileReport {
                file: lp.name.clone(),
                output: None,
                machine: machine.name.clone(),
                words_changed: 0,
                file_c_decimals: None,
                written_c_decimals: None,
                skipped_runs: skipped,
                warnings: lp.warnings.clone(),
                zones: Vec::new(),
            },
        );
    }
    let style = NumberStyle::of(program, b'C');
    let opts = PatchOptions {
        c_decimals: style.decimals,
        max_decimals: opts.max_decimals.max(style.decimals),
        ..opts.clone()
    };
    let mut edits: Vec<Edit> = Vec::new();
    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    let mut written_decimals = style.decimals;
    for (r, rp) in lp.runs.iter().enumerate() {
        let path = match &rp.path {
            Ok(p) => p,
            Err(problem) => {
                skipped.push(skipped_run(lp, r, problem));
                continue;
            }
        };
        let result = match patch_path(path, machine, &opts) {
            Ok(res) => res,
            Err(e) => {
                skipped.push(format!("run {}: {e}", r + 1));
                continue;
            }
        };
        rows.extend(result.zones.iter().map(|z| ZoneRow::new(lp, r, z)));
        for k in 0..rp.run.len() {
            if !result.changed[k] {
                continue;
            }
            if k == 0 {
                // Point 0 belongs to the block before the run; the patcher never moves it.
                debug_assert!(false, "patcher changed the start point of a run");
                continue;
            }
            written_decimals = written_decimals.max(result.decimals);
            edits.push(Edit {
                block: rp.run.blocks[k],
                letter: b'C',
                value: result.c_deg[k],
                decimals: result.decimals,
            });
        }
    }
    restore_modal_c(program, &mut edits, style.decimals);
    edits.sort_by_key(|e| e.block);
    let report = FileReport {
        file: lp.name.clone(),
        output: None,
        machine: machine.name.clone(),
        words_changed: edits.len(),
        file_c_decimals: Some(style.decimals),
        written_c_decimals: Some(written_decimals),
        skipped_runs: skipped,
        warnings: lp.warnings.clone(),
        zones: rows,
    };
    (edits, report)
}

fn skipped_run(lp: &LoadedProgram, r: usize, problem: &crate::program::RunProblem) -> String {
    format!(
        "run {} (lines {}–{}): {problem}",
        r + 1,
        lp.line_of(r, 0),
        lp.line_of(r, lp.runs[r].run.len() - 1)
    )
}

/// A block after an edited one that relied on modal C (no C word) would now inherit the new
/// value: give the next such move its original C explicitly.
fn restore_modal_c(program: &Program, edits: &mut Vec<Edit>, decimals: usize) {
    let edited: std::collections::HashSet<usize> = edits.iter().map(|e| e.block).collect();
    let mut extra = Vec::new();
    for e in edits.iter() {
        let next = (e.block + 1..program.blocks.len())
            .find(|&b| program.blocks[b].is_move || program.word(b, b'C').is_some());
        let Some(b) = next else { continue };
        if edited.contains(&b) || program.word(b, b'C').is_some() {
            continue;
        }
        if let Some(c) = program.state(b).pos[modal::C] {
            extra.push(Edit {
                block: b,
                letter: b'C',
                value: c,
                decimals,
            });
        }
    }
    edits.extend(extra);
}

/// Read, patch and write one file. The output is written to a temporary file beside it and
/// renamed on success: nothing half-written, the input never touched.
pub fn patch_file(
    input: &FsPath,
    output: &FsPath,
    machine: &Machine,
    opts: &PatchOptions,
    feed_fallback_mm_min: Option<f64>,
) -> Result<FileReport, JobError> {
    let name = input.display().to_string();
    if same_file(input, output) {
        return Err(JobError::Overwrite { path: name });
    }
    let program = read_program(input)?;
    let lp = load(program, &name, machine, feed_fallback_mm_min)?;
    let (edits, mut report) = patch_program(&lp, machine, opts);
    // No edit: the input bytes are the output (nc::write would copy them unchanged).
    let bytes: std::borrow::Cow<[u8]> = if edits.is_empty() {
        std::borrow::Cow::Borrowed(&lp.program.bytes)
    } else {
        std::borrow::Cow::Owned(polepatch_nc::write(&lp.program, &edits))
    };
    write_atomic_like(output, &bytes, Some(input)).map_err(|source| JobError::Write {
        path: output.display().to_string(),
        source,
    })?;
    report.output = Some(output.display().to_string());
    Ok(report)
}

fn same_file(a: &FsPath, b: &FsPath) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    }
}

/// Write `bytes` to `path` through a temporary file in the same folder and a rename.
/// The file gets the permissions of the file it replaces, else those of `like` (the
/// input), else rw-r--r-- — not the temporary file's owner-only mode.
pub fn write_atomic_like(
    path: &FsPath,
    bytes: &[u8],
    like: Option<&FsPath>,
) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => FsPath::new("."),
    };
    let perms = std::fs::metadata(path)
        .or_else(|e| like.map_or(Err(e), std::fs::metadata))
        .map(|m| m.permissions())
        .ok();
    let mut tmp = tempfile::NamedTempFile::new_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    if let Some(perms) = perms.or_else(default_permissions) {
        tmp.as_file().set_permissions(perms)?;
    }
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// [`write_atomic_like`] without a model file (reports, CSV).
pub fn write_atomic(path: &FsPath, bytes: &[u8]) -> std::io::Result<()> {
    write_atomic_like(path, bytes, None)
}

#[cfg(unix)]
fn default_permissions() -> Option<std::fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Some(std::fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn default_permissions() -> Option<std::fs::Permissions> {
    None
}

/// Errors of a patch job.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// Bad input file.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The output could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// Output path.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// Output and input are the same file.
    #[error("{path}: the output would overwrite the input; polepatch never modifies its input")]
    Overwrite {
        /// Path.
        path: String,
    },
}
