//! From NC bytes to the patcher's paths: parse, group into runs, pick the axes.

use crate::error::Error;
use polepatch_kinematics::Machine;
use polepatch_nc::{Dialect, FileStyle, Program, Run, modal};
use polepatch_patcher::Path;

/// Why one run cannot be analysed (the others still can).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RunProblem {
    /// No F in force and no fallback feed given.
    NoFeed,
}

impl std::fmt::Display for RunProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunProblem::NoFeed => {
                write!(f, "no feed (F) in force for this run; give one with --feed")
            }
        }
    }
}

/// One run of the program with its path for the patcher.
#[derive(Debug, Clone)]
pub struct RunPath {
    /// The run as the NC crate found it.
    pub run: Run,
    /// The path (axes X Y Z P C), or why there is none.
    pub path: Result<Path, RunProblem>,
}

/// A parsed program with its runs as paths for a machine.
#[derive(Debug, Clone)]
pub struct LoadedProgram {
    /// Name used in messages and reports (a file name, or what the caller chose).
    pub name: String,
    /// The parsed program.
    pub program: Program,
    /// Letter used as the primary rotary axis (the machine's, unless the file uses only the
    /// other tilting letter; see `warnings`).
    pub primary_letter: u8,
    /// Runs in file order.
    pub runs: Vec<RunPath>,
    /// Things the user should know (e.g. primary-letter substitution).
    pub warnings: Vec<String>,
    /// Work offset given by the caller (machine coordinates of the program's zero, mm),
    /// used with a machine's kinematic chain; `None`: from the program
    /// ([`crate::machine_frame::run_datum`]).
    pub work_offset_mm: Option<[f64; 3]>,
    /// When `program` is a stretch of a larger file ([`crate::stream`]): what the rest
    /// of the file says about it. `None` for a whole program.
    pub window: Option<Window>,
}

/// What a stretch of a file ([`LoadedProgram::window`]) needs from the rest of the file,
/// per run of the stretch where it is per run.
#[derive(Debug, Clone)]
pub struct Window {
    /// Number (from 0) in the whole file of the stretch's first run.
    pub first_run: usize,
    /// The whole file's number style.
    pub style: FileStyle,
    /// The run's end pose ([`crate::end_pose`]), decided on the blocks after it in the
    /// whole file (restating blocks numbered in the stretch's program).
    pub end: Vec<crate::end_pose::EndPose>,
    /// The run's work offset ([`crate::machine_frame::run_datum`]) from the whole file's
    /// frame changes.
    pub datum_mm: Vec<Option<[f64; 3]>>,
}

impl LoadedProgram {
    /// 1-based file line of point `k` of run `r`.
    pub fn line_of(&self, r: usize, k: usize) -> usize {
        self.program.blocks[self.runs[r].run.blocks[k]].line
    }
    /// File lines of the first and last point of run `r`.
    pub fn lines_of_run(&self, r: usize) -> [usize; 2] {
        [
            self.line_of(r, 0),
            self.line_of(r, self.runs[r].run.len() - 1),
        ]
    }
    /// Number of run `r` in the file, from 1 (as reports give it).
    pub fn run_number(&self, r: usize) -> usize {
        r + 1 + self.window.as_ref().map_or(0, |w| w.first_run)
    }
    /// The file's number style (of the whole file, also for a stretch).
    pub fn file_style(&self) -> FileStyle {
        match &self.window {
            Some(w) => w.style,
            None => FileStyle::of(&self.program),
        }
    }
    /// Index of the primary letter in [`polepatch_nc::Modal::pos`].
    pub fn primary_index(&self) -> usize {
        if self.primary_letter == b'A' {
            modal::A
        } else {
            modal::B
        }
    }
}

/// Parse `bytes` named `name` (for messages).
pub fn parse_program(bytes: Vec<u8>, name: &str) -> Result<Program, Error> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(Error::Empty {
            path: name.to_string(),
        });
    }
    polepatch_nc::parse(bytes, Dialect::Auto).map_err(|e| Error::Parse(e.with_path(name)))
}

/// Parse `bytes` and build each run's path for `machine`; `feed_fallback_mm_min` is used
/// for runs with no F in force.
pub fn load_nc(
    bytes: Vec<u8>,
    name: &str,
    machine: &Machine,
    feed_fallback_mm_min: Option<f64>,
) -> Result<LoadedProgram, Error> {
    load(
        parse_program(bytes, name)?,
        name,
        machine,
        feed_fallback_mm_min,
    )
}

/// Why a program has no run of G1 motion to analyse: the first G1 block that could not
/// start one, and the reason, or plainly [`Error::NoRuns`] when there is no G1 move.
fn why_no_runs(program: &Program, name: &str) -> Error {
    for (i, block) in program.blocks.iter().enumerate() {
        if !block.is_move {
            continue;
        }
        let st = program.state(i);
        if st.motion != polepatch_nc::Motion::Linear {
            continue;
        }
        let what = if st.incremental {
            "incremental mode (G91) is not supported: polepatch reads absolute programs (G90), \
             because a rotary value changed in incremental mode would shift every later position"
        } else if st.pos[..3].iter().any(Option::is_none) {
            "G1 moves from a position the program does not state (after G28/G53/G92 or a datum \
             change, or before X Y Z are all programmed): nothing can be analysed without it"
        } else {
            continue;
        };
        return Error::Unsupported {
            path: name.to_string(),
            line: block.line,
            what: what.to_string(),
        };
    }
    // A CL file handed to `patch`: say what it is.
    if let Some(k) = program.blocks.iter().position(|b| {
        let line = &program.bytes[b.span()];
        let t = line.trim_ascii_start();
        t.len() >= 5 && t[..5].eq_ignore_ascii_case(b"GOTO/")
    }) {
        return Error::Unsupported {
            path: name.to_string(),
            line: program.blocks[k].line,
            what: "this is a CL file (APT GOTO/ records), not an NC program: post it with \
                   `polepatch post`"
                .to_string(),
        };
    }
    Error::NoRuns {
        path: name.to_string(),
    }
}

fn tilt_letter(idx: usize) -> u8 {
    if idx == modal::A { b'A' } else { b'B' }
}

/// The warning when the program's tilting letter (`p_idx`, `modal::A` or `modal::B`) is
/// not the machine's.
pub(crate) fn primary_mismatch_warning(
    name: &str,
    machine: &Machine,
    p_idx: usize,
) -> Option<String> {
    let used = tilt_letter(p_idx) as char;
    let own = machine.primary_letter();
    (used != own).then(|| {
        format!(
            "{name}: the program uses {used} but machine {} has {own}: {own}'s limits are applied to {used}",
            machine.name
        )
    })
}

/// A run with its path for the patcher: axes X Y Z, the tilting letter at `p_idx`
/// (`modal::A` or `modal::B`) and C; the run's feed, else `feed_fallback_mm_min`.
pub(crate) fn run_path(run: Run, p_idx: usize, feed_fallback_mm_min: Option<f64>) -> RunPath {
    let path = run
        .feed_mm_min
        .or(feed_fallback_mm_min)
        .ok_or(RunProblem::NoFeed)
        .map(|feed| Path {
            s_mm: run.s_mm.clone(),
            axes: run.axes5(p_idx),
            feed_mm_min: feed,
        });
    RunPath { run, path }
}

/// Group a parsed program into runs and build each run's path for `machine`.
/// `feed_fallback_mm_min` is used for runs with no F in force.
pub fn load(
    program: Program,
    name: &str,
    machine: &Machine,
    feed_fallback_mm_min: Option<f64>,
) -> Result<LoadedProgram, Error> {
    let runs = polepatch_nc::runs(&program);
    if runs.is_empty() {
        return Err(why_no_runs(&program, name));
    }
    let own = if machine.primary_letter() == 'A' {
        modal::A
    } else {
        modal::B
    };
    let p_idx = polepatch_nc::primary_in_use(&runs, own);
    let primary_letter = tilt_letter(p_idx);
    let warnings: Vec<String> = primary_mismatch_warning(name, machine, p_idx)
        .into_iter()
        .collect();
    let has = |idx: usize| runs.iter().any(|r| r.uses(idx));
    if !has(p_idx) && !has(modal::C) {
        return Err(Error::NoRotary {
            path: name.to_string(),
            primary: machine.primary_letter(),
        });
    }
    let runs = runs
        .into_iter()
        .map(|run| run_path(run, p_idx, feed_fallback_mm_min))
        .collect();
    Ok(LoadedProgram {
        name: name.to_string(),
        program,
        primary_letter,
        runs,
        warnings,
        work_offset_mm: None,
        window: None,
    })
}
