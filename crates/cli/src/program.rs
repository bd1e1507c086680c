//! From an NC file to the patcher's paths: read, parse, group into runs, pick the axes.

use polepatch_kinematics::Machine;
use polepatch_nc::{Dialect, ParseError, Program, Run, modal};
use polepatch_patcher::Path;
use std::path::Path as FsPath;

/// Bad input at the file level.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// File.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// Syntax error with line and column.
    #[error("{0}")]
    Parse(#[from] ParseError),
    /// Nothing but whitespace.
    #[error("{path}: empty program")]
    Empty {
        /// File.
        path: String,
    },
    /// No G1 motion at all.
    #[error("{path}: no G1 motion to analyse")]
    NoRuns {
        /// File.
        path: String,
    },
    /// No rotary axis words in any G1 run.
    #[error(
        "{path}: no rotary axis words ({primary} or C) in any G1 run; is this a 5-axis program?"
    )]
    NoRotary {
        /// File.
        path: String,
        /// The machine's primary letter.
        primary: char,
    },
}

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

/// A program read from a file, with its runs as paths for a machine.
#[derive(Debug, Clone)]
pub struct LoadedProgram {
    /// File name as given.
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
}

impl LoadedProgram {
    /// 1-based file line of point `k` of run `r`.
    pub fn line_of(&self, r: usize, k: usize) -> usize {
        self.program.blocks[self.runs[r].run.blocks[k]].line
    }
}

/// Read and parse `file`.
pub fn read_program(file: &FsPath) -> Result<Program, InputError> {
    let name = file.display().to_string();
    let bytes = std::fs::read(file).map_err(|source| InputError::Io {
        path: name.clone(),
        source,
    })?;
    parse_program(bytes, &name)
}

/// Parse bytes named `name` (for messages).
pub fn parse_program(bytes: Vec<u8>, name: &str) -> Result<Program, InputError> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(InputError::Empty {
            path: name.to_string(),
        });
    }
    polepatch_nc::parse(bytes, Dialect::Auto).map_err(|e| InputError::Parse(e.with_path(name)))
}

/// Group a parsed program into runs and build each run's path for `machine`.
/// `feed_fallback_mm_min` is used for runs with no F in force.
pub fn load(
    program: Program,
    name: &str,
    machine: &Machine,
    feed_fallback_mm_min: Option<f64>,
) -> Result<LoadedProgram, InputError> {
    let runs = polepatch_nc::runs(&program);
    if runs.is_empty() {
        return Err(InputError::NoRuns {
            path: name.to_string(),
        });
    }
    let letter = |i: usize| if i == modal::A { b'A' } else { b'B' };
    let own = if machine.primary_letter() == 'A' {
        modal::A
    } else {
        modal::B
    };
    let p_idx = polepatch_nc::primary_in_use(&runs, own);
    let primary_letter = letter(p_idx);
    let mut warnings = Vec::new();
    if p_idx != own {
        warnings.push(format!(
            "{name}: the program uses {} but machine {} has {}: {}'s limits are applied to {}",
            primary_letter as char,
            machine.name,
            letter(own) as char,
            letter(own) as char,
            primary_letter as char
        ));
    }
    let has = |idx: usize| runs.iter().any(|r| r.uses(idx));
    if !has(p_idx) && !has(modal::C) {
        return Err(InputError::NoRotary {
            path: name.to_string(),
            primary: machine.primary_letter(),
        });
    }
    let runs = runs
        .into_iter()
        .map(|run| {
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
        })
        .collect();
    Ok(LoadedProgram {
        name: name.to_string(),
        program,
        primary_letter,
        runs,
        warnings,
    })
}
