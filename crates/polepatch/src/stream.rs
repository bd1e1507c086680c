//! Patching a program a stretch at a time: memory is the input plus the runs near the
//! pole, not the whole parsed program.
//!
//! A parsed program costs about ten times its bytes (words, blocks, modal states, run
//! positions). Only runs that come within the cone can hold a zone, and a patch changes
//! words of its own run only; so [`patch_nc_to`] reads the program once as a stream
//! ([`polepatch_nc::scan_blocks`]) and then reads again, from the places the first read
//! kept ([`polepatch_nc::Resume`]), only the stretches that hold such runs, which it parses
//! in full:
//!
//! 1. **Survey.** The runs ([`polepatch_nc::RunBuilder`], the same walk as the whole-program
//!    path), each with its first and last block, whether a point is within the cone for
//!    either tilting letter, whether it has a feed; which letters the runs use (the
//!    tilting letter in use, [`polepatch_nc::primary_in_use`]); the file's number style
//!    ([`polepatch_nc::StyleEvidence`]); the frame changes (for the work offset,
//!    [`crate::machine_frame::datum_at`]); and for every run its end pose
//!    ([`crate::end_pose::After::verdict`], decided by the first block after the run that
//!    decides, with the blocks before it that restate the run's last values — for both
//!    tilting letters since the one in use is known only at the end); the tool the program
//!    uses ([`crate::tool::Tracker`]); and for every run a stretch may hold, the place
//!    before its first block where a read resumes ([`RunRec::kept`]).
//! 2. **Stretches.** A run near the pole (or without a feed, which the report lists) is
//!    a stretch from its first block (point 0) to its last — or to the last block after
//!    it that restates its last values, when its end is free (that block is rewritten
//!    with it; such a block never belongs to another run). Two runs may share a block (a
//!    feed change splits a path into two runs with a common point): the block is then in
//!    both stretches, and written with the first (the whole-program path builds every
//!    run's path from the original values too, and never changes a first point that is
//!    another run's last, so the second stretch has it unchanged — checked when writing).
//!    Runs planned together ([`crate::plan`]: the positioning move that frees one's end
//!    goes to the next one's first point, which the plan may move) are one stretch.
//! 3. **Patch.** The second read resumes at each stretch's place
//!    ([`polepatch_nc::scan_resumed`]: the bytes between stretches are not lexed again),
//!    builds the stretch as a program of its own ([`polepatch_nc::ProgramBuilder`]: the
//!    file's lines, states and bytes), with the runs exactly as the first read found them
//!    (the run walk taken up at the run's first block, [`RunBuilder::resumed_at`]; checked),
//!    and hands it to
//!    [`crate::patch::patch_program`] with what the rest of the file says
//!    ([`crate::program::Window`]: run numbers, number style, end poses, work offsets).
//!    Bytes between stretches are copied; each stretch is written as
//!    [`crate::patch::patch_program`] returns it (the one application of its edits,
//!    [`polepatch_nc::apply_edits`], in the file's style).
//!
//! The output and the report are those of the whole-program path
//! (see [`load_nc`]) — tested on every
//! fixture, both machines, and programs built to cross stretch boundaries. Programs the
//! whole-program path rejects (no runs, no rotary words) are handed to it for its error.
//!
//! Stretches are read again and patched on all cores in batches of about 1/256 of the file
//! (16 KiB to 256 KiB of it), then written in file order.
//!
//! [`analyze_nc_each`] reads the same way with every run a stretch, and hands each run's
//! report out as it is made (a program of many runs has a report larger than itself).
//! [`each_run`] (`crate::simulate`) reads the same stretches for their runs alone
//! ([`polepatch_nc::stretch::read_stretch_runs`]: the runs and the line of each block, no
//! program), and hands each run out with its path and the lines of its points.
//!
//! Memory: the input, the output writer's buffer, one record per run (first and last
//! block, flags: ~64 B), and the batch of stretches in hand. A single run is parsed whole,
//! so one giant run costs ~10× its own bytes (its run alone, ~112 B a point, for
//! [`each_run`]); runs that share a block are not joined, so a program of many runs is
//! bounded by its longest run.

use crate::end_pose::{After, EndPose, Scan, Step};
use crate::error::Error;
use crate::patch::patch_program;
use crate::program::{LoadedProgram, RunPath, Window, run_path};
use crate::report::FileReport;
use crate::report::{AnalyzeReport, RunReport};
use crate::settings::BATCH_FRACTION;
use crate::settings::BATCH_MAX_BYTES;
use crate::settings::BATCH_MIN_BYTES;
use crate::tolerances::RANGE_SLACK_DEG;
use polepatch_kinematics::Machine;
use polepatch_nc::{
    Dialect, FileStyle, ProgramBuilder, Resume, RotaryLetters, Run, RunBreak, RunBuilder, Scanned,
    StyleEvidence, scan_blocks_with,
};
use std::borrow::Cow;
use std::io::Write;
use std::ops::ControlFlow;

/// The two readings the survey follows at once, in the per-letter arrays (`l`): the
/// machine's rotary letters, and the same with the third letter of A B C as the tilting
/// axis ([`RotaryLetters::other`]) — a program posted for another machine, refused by
/// name ([`Error::ForeignAxis`]) — in alphabetical order of the tilting letter (A-C and
/// B-C for both built-ins).
fn readings(machine: RotaryLetters) -> [RotaryLetters; 2] {
    let other = machine.with_tilt(machine.other());
    if machine.tilt < other.tilt {
        [machine, other]
    } else {
        [other, machine]
    }
}

/// What the survey keeps of one run.
#[derive(Debug, Clone)]
struct RunRec {
    first_block: usize,
    last_block: usize,
    /// Some point is within the cone if A (index 0) or B (index 1) is the tilting axis
    /// (a value never programmed reads as 0, as [`Run::axes5`] reads it).
    near: [bool; 2],
    /// The run cannot be analysed if A (index 0) or B (index 1) is the tilting letter (no
    /// feed, a feed too low, an unknown rotary value: [`crate::program::run_check`]): the
    /// report lists it.
    feedless: [bool; 2],
    /// End pose per tilting letter, as the blocks after the run decide it.
    end: [EndRec; 2],
    /// Work offset for this run ([`crate::machine_frame::datum_at`]).
    datum_mm: Option<[f64; 3]>,
    /// The first move after the run's last block: where its X Y Z are restored when the
    /// run's last point gets new ones ([`crate::patch`], step 3).
    next_move: Option<usize>,
    /// What ended the run in the file.
    ended_by: RunBreak,
    /// For a run a stretch may hold ([`Reading::keep_all`], else a run near the pole or
    /// without a feed for either tilting letter): where the second read resumes (before
    /// the run's first block), and the tool the program uses for the run.
    kept: Option<Box<Kept>>,
}

/// What the survey keeps of a run a stretch may hold ([`RunRec::kept`]).
#[derive(Debug, Clone)]
struct Kept {
    /// Where the second read resumes: before the run's first block (`None`: from the start
    /// of the file — every run opens where the survey took a place for it, so this is a
    /// fallback that costs time, never a different reading).
    start: Option<Resume>,
    tool: crate::tool::FoundTool,
}

/// The end pose of a run as the survey finds it ([`crate::end_pose`]).
#[derive(Debug, Clone, Default)]
struct EndRec {
    /// Free or not, and the 1-based line of the block that decided; `None` until one does.
    decided: Option<(bool, usize)>,
    /// Blocks that restate the run's last values: (file block index, 1-based line).
    restate: Vec<(usize, usize)>,
    scan: Scan,
    /// The positioning move that freed the end, if it was one.
    next: Option<crate::end_pose::NextMove>,
    /// That move's file block index.
    next_block: Option<usize>,
}

impl EndRec {
    /// Let block `i` (on `line`) have its say, when undecided.
    fn step(&mut self, after: &After<'_>, letters: RotaryLetters, i: usize, line: usize) {
        if self.decided.is_some() {
            return;
        }
        match after.verdict(letters, &mut self.scan) {
            Step::Free => {
                self.decided = Some((true, line));
                self.next = after.next_move(letters, line);
                self.next_block = self.next.map(|_| i);
            }
            Step::Pinned => {
                self.decided = Some((false, line));
                self.restate.clear();
            }
            Step::Restate => self.restate.push((i, line)),
            Step::Continue => {}
        }
    }

    /// The end pose, block indices re-based by `first` (the stretch's first block).
    fn pose(&self, first: usize) -> EndPose {
        let (free, line) = self.decided.map_or((true, None), |(f, l)| (f, Some(l)));
        EndPose {
            free,
            decided_line: line,
            restate: if free {
                self.restate.iter().map(|&(b, _)| b - first).collect()
            } else {
                Vec::new()
            },
            next: if free { self.next } else { None },
            carried_xy: self.scan.carried_xy,
        }
    }
}

/// The first read's findings.
struct Survey {
    dialect: Dialect,
    /// How the file is read: the dialect found and its program flow settled.
    read: polepatch_nc::ReadOptions,
    runs: Vec<RunRec>,
    /// Some run point has a value for X Y Z A B C.
    uses: [bool; 6],
    /// The file's number style; with `partial_style`, only of the lines from there on.
    style: FileStyle,
    /// A patch counts the style from the first run it may patch on
    /// ([`Reading::lazy_style`]): the byte where it began (the file's length if no run
    /// did) and what it counted; [`Survey::complete_style`] counts the lines before.
    partial_style: Option<(usize, StyleEvidence)>,
    /// What the reader carried through without analysing.
    notes: crate::notes::Notes,
    /// Blocks in the file.
    blocks: usize,
    /// The first G1 move that cannot start a run, and why ([`NoRunWhy`]).
    no_run_why: Option<NoRunWhy>,
    /// The line of the first G1 move with an I, J or K word (a tool-direction vector:
    /// some controllers' 5-axis programs without rotary words).
    first_vector: Option<usize>,
    /// The first word of each rotary letter (A, B, C): its line and column; and the first
    /// one that is not 0 (the axis turned, not parked).
    first_word: [Option<(usize, usize)>; 3],
    first_turn: [Option<(usize, usize)>; 3],
    /// The first move that takes a rotary axis beyond the machine's range: the program
    /// cannot run on it as written ([`Error::BeyondRange`]).
    beyond_range: Option<BeyondRange>,
}

/// A rotary value beyond the machine's range, where it is programmed.
#[derive(Debug, Clone, Copy)]
struct BeyondRange {
    line: usize,
    column: usize,
    letter: u8,
    value_deg: f64,
    range_deg: (f64, f64),
}

/// Why a G1 move cannot start a run: what [`Error`] a program without runs gets, from its
/// first such move.
#[derive(Debug, Clone, Copy)]
enum NoRunWhy {
    /// Its axis or feed words are expressions or variables (at `line`).
    NotAnalysable { line: usize },
    /// Incremental mode, programmed at `set_line`; the move at `line`.
    Incremental { set_line: usize, line: usize },
    /// X Y Z are not all known (at `line`).
    PositionUnknown { line: usize },
}

impl NoRunWhy {
    /// The move at `line` of a block `block` in state `st` cannot start a run, and why;
    /// `incremental_set_line` is where the incremental mode in force was programmed.
    fn of(
        block: &polepatch_nc::Block,
        st: &polepatch_nc::Modal,
        incremental_set_line: Option<usize>,
    ) -> Option<NoRunWhy> {
        if !block.is_move || st.motion != polepatch_nc::Motion::Linear {
            return None;
        }
        let line = block.line;
        if block.flags.has(polepatch_nc::Flags::NOT_ANALYSABLE) {
            Some(NoRunWhy::NotAnalysable { line })
        } else if st.incremental {
            Some(NoRunWhy::Incremental {
                set_line: incremental_set_line.unwrap_or(line),
                line,
            })
        } else if st.pos[..3].iter().any(Option::is_none) {
            Some(NoRunWhy::PositionUnknown { line })
        } else {
            None
        }
    }

    /// The error of a program named `name` that has no run.
    fn error(self, name: &str) -> Error {
        let path = name.to_string();
        match self {
            NoRunWhy::NotAnalysable { line } => Error::NothingAnalysable { path, line },
            NoRunWhy::Incremental { set_line, line } => Error::Unsupported {
                path,
                line: set_line,
                what: format!(
                    "incremental mode (G91) is not supported: polepatch reads absolute programs \
                     (G90), because a rotary value changed in incremental mode would shift every \
                     later position (the first move in it is at line {line})"
                ),
            },
            NoRunWhy::PositionUnknown { line } => Error::Unsupported {
                path,
                line,
                what: "G1 moves from a position the program does not state (after G28/G53/G92 \
                       or a datum change, or before X Y Z are all programmed): nothing can be \
                       analysed without it"
                    .to_string(),
            },
        }
    }
}

/// The first read in progress.
struct Surveying {
    /// The two readings followed ([`readings`]).
    readings: [RotaryLetters; 2],
    /// The machine's distance from the pole.
    pole: polepatch_kinematics::PoleDistance,
    /// [`Reading::lazy_style`].
    lazy_style: Option<usize>,
    /// Some run given out may be patched (for the tilting letter it may have): the style
    /// is counted from then on.
    may_patch: bool,
    cone_deg: f64,
    fallback: Option<f64>,
    work_offset_mm: Option<[f64; 3]>,
    runs: Vec<RunRec>,
    uses: [bool; 6],
    datum_shifts: Vec<(usize, [f64; 3])>,
    frame_changes: Vec<usize>,
    /// Runs given out whose end pose is not decided yet, per letter.
    pending: [Vec<usize>; 2],
    /// Runs given out that no move has followed yet ([`RunRec::next_move`]).
    awaiting_move: Vec<usize>,
    /// The end pose of the open run so far, from the blocks after its last block, per
    /// letter.
    first_after: [EndRec; 2],
    /// [`Reading::keep_all`].
    keep_all: bool,
    /// The tool in use ([`crate::tool`]): a run's is the program's as it stands at the
    /// run's last block (a tool change ends runs).
    tracker: crate::tool::Tracker,
    /// The open run's first block, and where a read resumes before it.
    open_start: Option<(usize, Resume)>,
}

impl Surveying {
    /// Keep what matters of a run the run walk gives out.
    fn take(&mut self, run: Run) {
        let mut near = [false; 2];
        for p in &run.pos {
            for (u, v) in self.uses.iter_mut().zip(p) {
                *u |= v.is_some();
            }
            for (l, letters) in self.readings.iter().enumerate() {
                // A value never programmed reads as 0, as `Run::axes5` reads it.
                let primary_deg = p[letters.tilt_index()].unwrap_or(0.0);
                near[l] |= self.pole.near(primary_deg, self.cone_deg);
            }
        }
        let first_block = run.blocks[0];
        let r = self.runs.len();
        let feedless = self
            .readings
            .map(|letters| crate::program::run_check(&run, letters, self.fallback, 0).is_err());
        let start = self
            .open_start
            .take_if(|(f, _)| *f == first_block)
            .map(|(_, at)| at);
        let kept = (self.keep_all || near.iter().chain(&feedless).any(|&b| b)).then(|| {
            Box::new(Kept {
                start,
                tool: self.tracker.found(),
            })
        });
        for (l, rec) in self.first_after.iter().enumerate() {
            if rec.decided.is_none() {
                self.pending[l].push(r);
            }
        }
        self.runs.push(RunRec {
            first_block,
            last_block: *run.blocks.last().unwrap_or(&first_block),
            near,
            feedless,
            end: self.first_after.clone(),
            datum_mm: crate::machine_frame::datum_at(
                &self.datum_shifts,
                &self.frame_changes,
                first_block,
                self.work_offset_mm,
            ),
            next_move: None,
            ended_by: run.ended_by,
            kept,
        });
        self.awaiting_move.push(r);
        if let Some(own) = self.lazy_style
            && !self.may_patch
        {
            // A patch patches the runs near the pole or without a feed for the tilting
            // letter: the machine's own once the runs use it, else either.
            let rec = &self.runs[r];
            let wanted = |l: usize| rec.near[l] || rec.feedless[l];
            self.may_patch = if self.uses[self.readings[own].tilt_index()] {
                wanted(own)
            } else {
                wanted(0) || wanted(1)
            };
        }
    }

    /// Block `i` (on `line`) has its say on the end pose of the runs before it, per
    /// letter: the pending ones and, with `open`, the open run's.
    fn decide(&mut self, after: &After<'_>, i: usize, line: usize, open: bool) {
        for (l, letters) in self.readings.into_iter().enumerate() {
            let runs = &mut self.runs;
            self.pending[l].retain(|&r| {
                runs[r].end[l].step(after, letters, i, line);
                runs[r].end[l].decided.is_none()
            });
            if open {
                self.first_after[l].step(after, letters, i, line);
            }
        }
    }
}

/// What both reads need to know of the caller's options: built once per call, from the
/// patch's or the analysis' options ([`Reading::patch`], [`Reading::analysis`]).
struct Reading<'a> {
    name: &'a str,
    /// The machine's rotary letters.
    letters: RotaryLetters,
    /// The machine's bounded rotary ranges, degrees, by letter (the tilting axis always;
    /// the pole axis unless it turns endlessly).
    ranges: Vec<(u8, (f64, f64))>,
    /// Runs are passes: a change of F under G94 does not end one ([`RunBuilder::passes`]).
    /// The simulator, which takes its motions apart at every feed change and joins them
    /// itself, reads without.
    passes: bool,
    /// The machine's distance from the pole.
    pole: polepatch_kinematics::PoleDistance,
    /// How far from the pole a zone can lie (the cone, or the pole reach beyond it).
    cone_deg: f64,
    fallback: Option<f64>,
    work_offset_mm: Option<[f64; 3]>,
    /// How the machine's programs are read.
    read: polepatch_nc::ReadOptions,
    /// Chord tolerance for the chain path, mm.
    chord_tolerance_mm: f64,
    /// The caller's tool options.
    tool: crate::tool::ToolOptions,
    /// A patch, with the machine's own reading at this index of [`readings`] (0 for A-C, 1
    /// for B-C): the survey counts
    /// the file's number style only from the first run that may be patched on (a program
    /// with none is copied; its style is never used), and [`Survey::complete_style`] the
    /// lines before. `None`: from the start.
    lazy_style: Option<usize>,
    /// Every run may be a stretch (an analysis): the survey keeps where the second read
    /// resumes for each ([`RunRec::kept`]); else only for the runs a patch may patch.
    keep_all: bool,
}

/// The run walk of a reading: passes or runs ([`Reading::passes`]).
fn run_builder(rd: &Reading<'_>) -> RunBuilder {
    RunBuilder::of_kind(rd.passes)
}

/// The machine's bounded rotary ranges by letter ([`Reading::ranges`]).
fn ranges(machine: &Machine, letters: RotaryLetters) -> Vec<(u8, (f64, f64))> {
    std::iter::once((letters.tilt, machine.primary_range_deg))
        .chain(machine.c_range_deg.map(|r| (letters.pole, r)))
        .collect()
}

impl<'a> Reading<'a> {
    /// How a patch with `opts` reads for `machine`.
    fn patch(opts: &'a crate::options::PatchOptions, machine: &Machine) -> Result<Self, Error> {
        let letters = crate::program::check_layout(machine)?;
        Ok(Reading {
            name: &opts.read.name,
            letters,
            ranges: ranges(machine, letters),
            passes: true,
            pole: polepatch_kinematics::PoleDistance::of(machine),
            cone_deg: opts.patch.reach_deg(),
            fallback: opts.read.feed_fallback_mm_min,
            work_offset_mm: opts.read.work_offset_mm,
            read: crate::program::read_options_with(machine, opts.read.inch)?,
            chord_tolerance_mm: opts.chord_tolerance_mm,
            tool: opts.tool.clone(),
            lazy_style: readings(letters).iter().position(|r| *r == letters),
            keep_all: false,
        })
    }

    /// How an analysis (and [`load_nc`], [`each_run`]) with `opts` reads for `machine`.
    fn analysis(
        opts: &'a crate::options::AnalyzeOptions,
        machine: &Machine,
    ) -> Result<Self, Error> {
        let letters = crate::program::check_layout(machine)?;
        Ok(Reading {
            name: &opts.read.name,
            letters,
            ranges: ranges(machine, letters),
            passes: true,
            pole: polepatch_kinematics::PoleDistance::of(machine),
            cone_deg: opts.analysis.reach_deg(),
            fallback: opts.read.feed_fallback_mm_min,
            work_offset_mm: opts.read.work_offset_mm,
            read: crate::program::read_options_with(machine, opts.read.inch)?,
            chord_tolerance_mm: crate::machine_frame::CHORD_TOLERANCE_MM,
            tool: crate::tool::ToolOptions::default(),
            lazy_style: None,
            keep_all: true,
        })
    }
}

impl BeyondRange {
    /// The first word of block `s` that moves a bounded rotary axis (`ranges`, by letter)
    /// beyond its range, as the controller reaches it (the unwrapped position of a
    /// direction form).
    fn of(s: &Scanned<'_>, ranges: &[(u8, (f64, f64))]) -> Option<BeyondRange> {
        for w in s.words {
            let Some(&(letter, (lo, hi))) = ranges.iter().find(|r| r.0 == w.letter) else {
                continue;
            };
            let idx = polepatch_nc::modal::axis_index(letter).unwrap_or(0);
            if let Some(v) = s.state.pos[idx]
                && !(lo - RANGE_SLACK_DEG..=hi + RANGE_SLACK_DEG).contains(&v)
            {
                return Some(BeyondRange {
                    line: s.block.line,
                    column: (w.start as usize).saturating_sub(s.block.span().start) + 1,
                    letter,
                    value_deg: v,
                    range_deg: (lo, hi),
                });
            }
        }
        None
    }
}

impl Survey {
    /// The file's number style from all its lines, where the survey counted it only from
    /// a point on ([`Reading::lazy_style`]): the lines before it are lexed again.
    fn complete_style(&mut self, bytes: &[u8], rd: &Reading<'_>) -> Result<(), Error> {
        if let Some((from, counted)) = self.partial_style.take() {
            let mut ev = polepatch_nc::style_evidence_to(bytes, from, &self.read)
                .map_err(|e| Error::Parse(e.with_path(rd.name)))?;
            ev.merge(&counted);
            self.style = ev.style();
        }
        Ok(())
    }

    /// What the file's report lists besides its runs: the lines carried through without
    /// analysis, and the warnings — `first` (the primary letter's substitution, or why
    /// nothing is analysed) before the notes'.
    fn head(
        &self,
        rd: &Reading<'_>,
        letters: RotaryLetters,
        first: Option<String>,
    ) -> (Vec<crate::notes::NotAnalysed>, Vec<String>) {
        let (not_analysed, warnings) = self.notes.finish(letters, rd.cone_deg, rd.name);
        (not_analysed, first.into_iter().chain(warnings).collect())
    }
}

/// The first read (module docs, step 1), read again when the file's program flow must
/// settle the TCPM states ([`polepatch_nc::flow`]).
fn survey(bytes: &[u8], opts: &Reading<'_>) -> Result<Survey, Error> {
    let mut read = opts.read.clone();
    loop {
        let (mut sv, settled) = survey_once(bytes, opts, &read)?;
        match settled {
            polepatch_nc::Settled::Done(dialect) => {
                sv.dialect = dialect;
                read.dialect = dialect;
                sv.read = read;
                return Ok(sv);
            }
            polepatch_nc::Settled::Again(settled) => read = settled,
        }
    }
}

/// The first word of each rotary letter A B C (not an auxiliary axis), and its first that
/// is not 0 (a letter that has turned has both), as (line, column).
fn first_rotary_words(
    s: &Scanned<'_>,
    auxiliary: &[u8],
    first_word: &mut [Option<(usize, usize)>; 3],
    first_turn: &mut [Option<(usize, usize)>; 3],
) {
    for w in s.words {
        if auxiliary.contains(&w.letter) {
            continue;
        }
        let l = match w.letter {
            b'A' => 0,
            b'B' => 1,
            b'C' => 2,
            _ => continue,
        };
        if first_turn[l].is_some() {
            continue;
        }
        let column = (w.start as usize).saturating_sub(s.block.span().start) + 1;
        let at = (s.block.line, column);
        first_word[l].get_or_insert(at);
        if w.value != 0.0 {
            first_turn[l].get_or_insert(at);
        }
    }
}

/// A restating block that another run holds (from its first block on) cannot be rewritten
/// for this one: the run's last point stays (decided there). Nothing after the others
/// decides: the end of the file leaves them free.
fn pin_ends_restated_by_other_runs(runs: &mut [RunRec]) {
    let firsts: Vec<usize> = runs.iter().map(|r| r.first_block).collect();
    for r in 0..runs.len() {
        let next_first = firsts[r + 1..].iter().copied().min();
        for e in &mut runs[r].end {
            if let Some(nf) = next_first
                && let Some(&(_, line)) = e.restate.iter().find(|&&(b, _)| b >= nf)
            {
                e.decided = Some((false, line));
                e.restate.clear();
            }
        }
    }
}

/// Where a read resumes, as the survey goes ([`RunRec::kept`]): before the block in hand
/// (after the one before it), and before the last block that moved or changed a position —
/// the two blocks where the run walk opens a run (`RunBuilder`: at the block in hand, or at
/// that last place).
struct Places {
    before: Resume,
    before_last_pos: Option<(usize, Resume)>,
}

impl Places {
    fn new(read: &polepatch_nc::ReadOptions) -> Places {
        Places {
            before: Resume::file_start(read),
            before_last_pos: None,
        }
    }

    /// The walk has taken block `i`; its open run starts at block `first`: the survey
    /// keeps the place before it, when that run is new.
    fn open(&self, sv: &mut Surveying, first: Option<usize>, i: usize) {
        if let Some(f) = first
            && sv.open_start.as_ref().is_none_or(|(g, _)| *g != f)
        {
            sv.open_start = if f == i {
                Some((f, self.before.clone()))
            } else {
                self.before_last_pos.clone().filter(|(b, _)| *b == f)
            };
        }
    }

    /// Block `i` (`s`; the state before it `prev`) is read: the places move on.
    fn after(&mut self, s: &Scanned<'_>, prev: &polepatch_nc::Modal, i: usize) {
        let after = s.resume_after();
        if s.block.is_move || s.state.pos != prev.pos {
            self.before_last_pos = Some((i, std::mem::replace(&mut self.before, after)));
        } else {
            self.before = after;
        }
    }
}

/// The first read of one reading (module docs, step 1): the runs, what decides their ends,
/// the file's number style, notes, and the first words that tell why a program has no run.
fn survey_once(
    bytes: &[u8],
    opts: &Reading<'_>,
    read: &polepatch_nc::ReadOptions,
) -> Result<(Survey, polepatch_nc::Settled), Error> {
    let mut sv = Surveying {
        readings: readings(opts.letters),
        pole: opts.pole.clone(),
        lazy_style: opts.lazy_style,
        may_patch: false,
        cone_deg: opts.cone_deg,
        fallback: opts.fallback,
        work_offset_mm: opts.work_offset_mm,
        runs: Vec::new(),
        uses: [false; 6],
        datum_shifts: Vec::new(),
        frame_changes: Vec::new(),
        pending: [Vec::new(), Vec::new()],
        awaiting_move: Vec::new(),
        first_after: [EndRec::default(), EndRec::default()],
        keep_all: opts.keep_all,
        tracker: crate::tool::Tracker::default(),
        open_start: None,
    };
    // The dialect the tool descriptions are read in (the reader's, detected as it does).
    let dialect = match read.dialect {
        Dialect::Auto => polepatch_nc::detect_dialect(bytes),
        d => d,
    };
    let mut places = Places::new(read);
    let mut style = StyleEvidence::default();
    // Where the style is counted from: the first block, or (lazy) none yet.
    let mut style_from = opts.lazy_style.is_none().then_some(0usize);
    let mut notes = crate::notes::Notes::new();
    let mut builder = run_builder(opts);
    let mut prev = opts.read.initial();
    let mut i = 0usize;
    let mut no_run_why = None;
    let mut first_vector = None;
    let mut incremental_set_line = None;
    let mut first_word: [Option<(usize, usize)>; 3] = [None; 3];
    let mut first_turn: [Option<(usize, usize)>; 3] = [None; 3];
    let mut beyond_range: Option<BeyondRange> = None;
    let settled = scan_blocks_with(bytes, read, |s: Scanned<'_>| {
        // A move to a rotary value beyond the machine's range (as the controller reaches
        // it: the unwrapped position of a direction form).
        if beyond_range.is_none() && s.block.is_move {
            beyond_range = BeyondRange::of(&s, &opts.ranges);
        }
        if s.state.incremental && !prev.incremental {
            incremental_set_line = Some(s.block.line);
        }
        if no_run_why.is_none() {
            no_run_why = NoRunWhy::of(s.block, s.state, incremental_set_line);
        }
        first_rotary_words(
            &s,
            &opts.read.controller.auxiliary,
            &mut first_word,
            &mut first_turn,
        );
        // (Only while no rotary word has been read: the hint is for programs without.)
        if first_vector.is_none()
            && first_word.iter().all(Option::is_none)
            && s.block.is_move
            && s.state.motion == polepatch_nc::Motion::Linear
            && s.words
                .iter()
                .any(|w| matches!(w.letter, b'I' | b'J' | b'K'))
        {
            first_vector = Some(s.block.line);
        }
        if style_from.is_some() {
            style.add_block(bytes, s.words);
        }
        notes.push(s.block, s.words, &prev, s.state);
        notes.lookalike(s.block.line, s.lookalike);
        if let Some(d) = s.stated_datum {
            sv.datum_shifts.push((i, d));
        }
        if s.frame_changed {
            sv.frame_changes.push(i);
        }
        builder.push(i, s.block, s.state, &mut |run| sv.take(run));
        places.open(&mut sv, builder.open_run_first_block(), i);
        // After the runs this block ends: a tool change is the next run's.
        sv.tracker
            .block(dialect, s.block, &bytes[s.block.span()], s.words, s.state);
        places.after(&s, &prev, i);
        if s.block.is_move {
            for r in sv.awaiting_move.drain(..) {
                sv.runs[r].next_move = Some(i);
            }
        }
        if style_from.is_none() && sv.may_patch {
            style_from = Some(s.block.span().start);
            style.add_block(bytes, s.words);
        }
        // Deciding blocks count from the open run's last block on: when this block
        // extended it, or no run is open, the verdicts seen so far are spent (the open run's
        // are not taken; a run this block ended is among the pending ones now).
        let spent = builder.open_run_last_block().is_none_or(|last| last == i);
        let after = After::new(s.words, s.block.is_move, s.block.flags, s.state, &prev);
        sv.decide(&after, i, s.block.line, !spent);
        if spent {
            sv.first_after = [EndRec::default(), EndRec::default()];
        }
        prev = *s.state;
        i += 1;
        ControlFlow::Continue(())
    })
    .map_err(|e| Error::Parse(e.with_path(opts.name)))?;
    builder.finish(&mut |run| sv.take(run));
    pin_ends_restated_by_other_runs(&mut sv.runs);
    Ok((
        Survey {
            dialect: read.dialect,
            read: read.clone(),
            runs: sv.runs,
            uses: sv.uses,
            style: style.style(),
            partial_style: match style_from {
                Some(0) => None,
                from => Some((from.unwrap_or(bytes.len()), style)),
            },
            notes,
            blocks: i,
            no_run_why,
            first_vector,
            first_word,
            first_turn,
            beyond_range,
        },
        settled,
    ))
}

/// A stretch to parse in full: blocks `first_block..=last_block`, runs `runs` (numbers in
/// the file, from 0).
#[derive(Debug, Clone)]
struct Stretch {
    first_block: usize,
    last_block: usize,
    runs: std::ops::Range<usize>,
    /// The whole file ([`load_program`]): its bytes from the first to the last, also
    /// before the first block and after the last.
    whole: bool,
}

/// The stretches (module docs, step 2): one per run `wanted` picks.
/// A stretch reaches to the last block that restates its run's last values (for the
/// tilting letter `l`), when the run's end is free: those blocks are rewritten with it —
/// and to the first move after the run, where X Y Z the last point relied on are restored
/// (a ball's centre kept moves its tips; [`crate::patch`], step 3), unless that move
/// belongs to the next run.
fn stretches(runs: &[RunRec], l: usize, wanted: impl Fn(&RunRec) -> bool) -> Vec<Stretch> {
    let one: Vec<Stretch> = runs
        .iter()
        .enumerate()
        .filter(|(_, rec)| wanted(rec))
        .map(|(r, rec)| {
            let end = &rec.end[l];
            let free = end.decided.is_none_or(|(free, _)| free);
            let restated = end.restate.iter().map(|&(b, _)| b).max().filter(|_| free);
            let next_first = runs.get(r + 1).map_or(usize::MAX, |n| n.first_block);
            let next_move = rec.next_move.filter(|&b| free && b < next_first);
            Stretch {
                first_block: rec.first_block,
                last_block: rec
                    .last_block
                    .max(restated.unwrap_or(0))
                    .max(next_move.unwrap_or(0)),
                runs: r..r + 1,
                whole: false,
            }
        })
        .collect();
    // Runs whose end's positioning move goes to the next run's first point are planned
    // together (crate::plan): one stretch.
    let mut out: Vec<Stretch> = Vec::with_capacity(one.len());
    for st in one {
        if let Some(last) = out.last_mut()
            && last.runs.end == st.runs.start
            && runs[last.runs.end - 1].end[l].next_block == Some(runs[st.runs.start].first_block)
        {
            last.last_block = last.last_block.max(st.last_block);
            last.runs.end = st.runs.end;
            continue;
        }
        out.push(st);
    }
    out
}

/// A stretch being read in the second pass.
struct InHand {
    stretch: Stretch,
    program: ProgramBuilder,
    /// Byte just past the stretch's last line (its line ending included).
    end_byte: Option<usize>,
    /// Its runs, each with the program's tool for it.
    runs: Vec<(Run, crate::tool::FoundTool)>,
}

/// After the first read: the survey and the reading (`l`, of [`readings`]) for the
/// stretches, or a program that holds nothing to analyse.
enum Begun {
    Stretches {
        sv: Box<Survey>,
        l: usize,
    },
    /// The program was read and holds nothing to analyse
    /// ([`Error::is_nothing_to_analyse`]; `why` says what): the survey for its notes.
    Nothing {
        sv: Box<Survey>,
        l: usize,
        why: Error,
    },
}

/// The first read, and what it says of the program as a whole: an empty program, a
/// program with no run (the first G1 move that cannot start one, a CL file) or with no
/// rotary word is an error — [`Begun::Nothing`] where the error only says there is nothing
/// to analyse.
fn begin(bytes: &[u8], machine: &Machine, rd: &Reading<'_>) -> Result<Begun, Error> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(Error::Empty {
            path: rd.name.to_string(),
        });
    }
    let sv = survey(bytes, rd)?;
    // The letters in use ([`polepatch_nc::primary_of`]): the machine's, or the third
    // letter of A B C as the tilting axis where the program never programs the machine's.
    let own = rd.letters;
    let in_use = polepatch_nc::primary_of(&sv.uses, own);
    let l = readings(own).iter().position(|r| *r == in_use).unwrap_or(0);
    // A rotary letter the machine does not have is refused (issue 29) where the program
    // uses it as its tilting axis (reading it as the machine's would patch with the
    // wrong kinematics) or turns it beside the machine's (an A-B trunnion's program on an
    // A-C machine): named at its first word. A letter only ever written 0 (a post's
    // `B0` reset) is carried through.
    let slot = |letter: u8| usize::from(letter - b'A');
    let foreign = own.other();
    let at = if in_use != own {
        sv.first_word[slot(foreign)]
    } else {
        sv.first_turn[slot(foreign)]
    };
    if let Some((line, column)) = at {
        // The built-ins the program fits: they have every rotary letter it turns, and the
        // tilting letter it uses (an A-B trunnion's program fits no A-C or B-C machine).
        let turned: Vec<char> = b"ABC"
            .iter()
            .filter(|&&c| sv.first_turn[slot(c)].is_some() || c == in_use.tilt)
            .map(|&c| c as char)
            .collect();
        let fits: Vec<String> = Machine::builtin_names()
            .iter()
            .filter_map(|n| Machine::builtin(n))
            .filter(|m| {
                m.name != machine.name
                    && m.primary_letter() == in_use.tilt as char
                    && turned
                        .iter()
                        .all(|&c| c == m.primary_letter() || c == m.c_letter())
            })
            .map(|m| format!("{} has {} and {}", m.name, m.primary_letter(), m.c_letter()))
            .collect();
        return Err(Error::ForeignAxis {
            path: rd.name.to_string(),
            line,
            column,
            letter: foreign as char,
            machine: machine.name.clone(),
            axes: format!("{} and {}", machine.primary_letter(), machine.c_letter()),
            fits: if fits.is_empty() {
                String::new()
            } else {
                format!("; the built-in {}", fits.join(", the built-in "))
            },
        });
    }
    if let Some(b) = sv.beyond_range.filter(|_| in_use == own) {
        return Err(Error::BeyondRange {
            path: rd.name.to_string(),
            line: b.line,
            column: b.column,
            letter: b.letter as char,
            value_deg: b.value_deg,
            machine: machine.name.clone(),
            range: format!("[{}, {}]", b.range_deg.0, b.range_deg.1),
        });
    }
    let why = if sv.runs.is_empty() {
        Some(match sv.no_run_why {
            Some(why) => why.error(rd.name),
            None => crate::program::cl_file_error(bytes, rd.name).unwrap_or(Error::NoRuns {
                path: rd.name.to_string(),
            }),
        })
    } else if !sv.uses[in_use.tilt_index()] && !sv.uses[in_use.pole_index()] {
        Some(Error::NoRotary {
            path: rd.name.to_string(),
            primary: machine.primary_letter(),
            vectors: sv
                .first_vector
                .map(|line| {
                    format!(
                        " Its G1 moves carry I J K words (first at line {line}): tool-direction \
                         vectors, which polepatch does not read — it patches the rotary axes' \
                         values ({} and {}); post the CL data for this machine \
                         (`polepatch post`) to get them",
                        machine.primary_letter(),
                        machine.c_letter()
                    )
                })
                .unwrap_or_default(),
        })
    } else {
        None
    };
    match why {
        None => Ok(Begun::Stretches {
            sv: Box::new(sv),
            l,
        }),
        Some(why) if why.is_nothing_to_analyse() => Ok(Begun::Nothing {
            sv: Box::new(sv),
            l,
            why,
        }),
        Some(e) => Err(e),
    }
}

/// [`crate::patch_nc_to`] with [`crate::hooks::Hooks`]: `progress` after each batch of stretches is
/// written (and at the end), `cancelled` before each stretch is patched and before each
/// batch is written ([`Error::Cancelled`]).
pub fn patch_nc_hooked(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::PatchOptions,
    out: &mut dyn Write,
    hooks: crate::hooks::Hooks<'_>,
) -> Result<FileReport, Error> {
    opts.check()?;
    let rd = Reading::patch(opts, machine)?;
    let (sv, l, first, nothing) = match begin(bytes, machine, &rd)? {
        Begun::Nothing { sv, l, why } => {
            let why = format!("{why}: nothing to patch, written unchanged");
            (sv, l, Some(why), true)
        }
        Begun::Stretches { sv, l } => (sv, l, None, false),
    };
    let letters = readings(rd.letters)[l];
    let mut report = FileReport::unchanged(&opts.read.name, machine, Vec::new());
    (report.not_analysed, report.warnings) = sv.head(&rd, letters, first);
    // A program with nothing to analyse has no run to patch either.
    let todo = if nothing {
        Vec::new()
    } else {
        stretches(&sv.runs, l, |rec| rec.near[l] || rec.feedless[l])
    };
    let mut sv = sv;
    if !todo.is_empty() {
        sv.complete_style(bytes, &rd)?;
    }
    if todo.is_empty() {
        // No run comes near the pole: no zone, and the output is the input.
        if (hooks.cancelled)() {
            return Err(Error::Cancelled);
        }
        out.write_all(bytes).map_err(Error::Output)?;
        (hooks.progress)(bytes.len(), bytes.len());
        return Ok(report);
    }
    // Set when a stretch was skipped because the caller cancelled: its part is not
    // written, and the patch ends with `Error::Cancelled`.
    let stopped = std::sync::atomic::AtomicBool::new(false);
    let cancelled = || {
        let c = stopped.load(std::sync::atomic::Ordering::Relaxed) || (hooks.cancelled)();
        if c {
            stopped.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        c
    };
    let mut parts: Vec<Part> = Vec::new();
    let result = each_stretch(
        bytes,
        &sv,
        &todo,
        l,
        &rd,
        |lp| {
            if cancelled() {
                return (
                    Vec::new(),
                    FileReport::unchanged(&opts.read.name, machine, Vec::new()),
                );
            }
            let (output, part) = patch_program(&lp, machine, &opts.patch);
            let output = match output {
                Cow::Owned(bytes) => bytes,
                Cow::Borrowed(_) => lp.program.bytes,
            };
            #[cfg(test)]
            let output = tests::planted(output);
            (output, part)
        },
        |(output, part), replaced| {
            if cancelled() {
                return Err(std::io::Error::other("cancelled"));
            }
            (hooks.progress)(replaced.end, bytes.len());
            parts.push(Part {
                replaced,
                output,
                report: part,
                put_back: None,
            });
            Ok(())
        },
    );
    if stopped.load(std::sync::atomic::Ordering::Relaxed) {
        return Err(Error::Cancelled);
    }
    result?;
    let (output, unverified) = verified_output(bytes, machine, opts, &mut parts, &cancelled)?;
    if cancelled() {
        return Err(Error::Cancelled);
    }
    report.warnings.extend(unverified);
    for part in parts {
        if let Some(why) = &part.put_back {
            report.warnings.push(why.clone());
        }
        merge(&mut report, part.report);
    }
    out.write_all(&output).map_err(Error::Output)?;
    (hooks.progress)(bytes.len(), bytes.len());
    report.warn_tools();
    Ok(report)
}

/// A stretch as patched: the input bytes it replaces, its output, its report, and — when
/// the written program failed its verification there — why it was put back.
struct Part {
    replaced: std::ops::Range<usize>,
    output: Vec<u8>,
    report: FileReport,
    put_back: Option<String>,
}

/// The program as the parts write it: the input, with each part's range replaced by its
/// output (by its input where it was put back). A part that starts at the block the
/// previous one ended at (two runs sharing a point) has that block written with the
/// previous part: a run never changes its first point.
fn assemble(bytes: &[u8], parts: &[Part]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len() + bytes.len() / 64);
    let mut copied_to = 0usize;
    for part in parts {
        let replaced = &part.replaced;
        let shared = copied_to.saturating_sub(replaced.start);
        let output: &[u8] = if part.put_back.is_some() {
            &bytes[replaced.clone()]
        } else {
            &part.output
        };
        assert!(
            output.get(..shared) == bytes.get(replaced.start..replaced.start + shared),
            "a run changed its first point (line shared with the run before it)"
        );
        out.extend_from_slice(&bytes[copied_to.min(replaced.start)..replaced.start]);
        out.extend_from_slice(&output[shared.min(output.len())..]);
        copied_to = copied_to.max(replaced.end);
    }
    out.extend_from_slice(&bytes[copied_to.min(bytes.len())..]);
    out
}

/// The output of `parts`, verified against the input ([`crate::verify`]): where the written
/// program fails, the part that wrote the failing lines (or the last part before them: a
/// later line relies on what it changed) is put back, its zones marked
/// [`crate::ZoneReason::Verification`], and the program verified again. A program that
/// still fails with nothing left to put back is [`Error::Unverified`].
///
/// The bench's peers ([`polepatch_patcher::Strategy`] other than polepatch: methods shown
/// for comparison, unverified by design) are not put back: what fails is returned as
/// warnings, so that the bench shows what the peer does.
fn verified_output(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::PatchOptions,
    parts: &mut [Part],
    cancelled: &dyn Fn() -> bool,
) -> Result<(Vec<u8>, Vec<String>), Error> {
    let peer = opts.patch.strategy != polepatch_patcher::Strategy::Polepatch;
    // The file lines each part covers.
    let mut lines = Vec::with_capacity(parts.len());
    let (mut at, mut line) = (0usize, 1usize);
    for part in parts.iter() {
        let count = |from: usize, to: usize| crate::verify::lines_in(&bytes[from..to]);
        // Parts are in file order; one may start at the line the one before ended at.
        if part.replaced.start >= at {
            line += count(at, part.replaced.start);
        } else {
            line -= count(part.replaced.start, at);
        }
        at = part.replaced.start;
        let first = line;
        let last = first + count(part.replaced.start, part.replaced.end).max(1) - 1;
        lines.push([first, last]);
    }
    loop {
        let output = assemble(bytes, parts);
        if output == bytes || cancelled() {
            return Ok((output, Vec::new()));
        }
        let claims: Vec<crate::verify::Claim> = parts
            .iter()
            .filter(|p| p.put_back.is_none())
            .flat_map(|p| p.report.zones.iter())
            .filter(|z| z.outcome == crate::Outcome::Reached)
            .map(|z| crate::verify::Claim {
                lines: z.core_lines,
                both_axes: opts.patch.axes == polepatch_patcher::PatchAxes::Both,
            })
            .collect();
        let check =
            crate::verify::verify_claims(bytes, &output, machine, opts, &opts.read.name, &claims)?;
        if check.passed() {
            return Ok((output, Vec::new()));
        }
        if peer {
            let said = check.violations.iter().map(|v| {
                format!(
                    "{}: the {} peer's output fails its verification at line {} ({}: {}): \
                     peers are shown for comparison, not to be run",
                    opts.read.name,
                    opts.patch.strategy.name(),
                    v.line,
                    v.check.name(),
                    v.message
                )
            });
            return Ok((output, said.collect()));
        }
        let mut put = false;
        for v in &check.violations {
            // The parts that wrote the line (two when runs share it), else the last one
            // before it (a later line relies on what it changed), else — the program as a
            // whole, or a part already put back — the last changed one before.
            let changed = |k: &usize| {
                parts[*k].put_back.is_none()
                    && parts[*k].output != bytes[parts[*k].replaced.clone()]
            };
            let mut blame: Vec<usize> = (0..parts.len())
                .filter(|&k| lines[k][0] <= v.line && v.line <= lines[k][1])
                .filter(changed)
                .collect();
            if blame.is_empty() {
                let before = if v.line == 0 {
                    parts.len()
                } else {
                    lines
                        .iter()
                        .position(|r| r[0] > v.line)
                        .unwrap_or(parts.len())
                };
                blame.extend((0..before).rev().find(changed));
            }
            for k in blame {
                let why = format!(
                    "{}: lines {}–{} keep their values: the written program failed its \
                     verification at line {} ({}: {})",
                    opts.read.name,
                    lines[k][0],
                    lines[k][1],
                    v.line,
                    v.check.name(),
                    v.message
                );
                put_back(&mut parts[k], why);
                put = true;
            }
        }
        if !put {
            return Err(Error::Unverified {
                path: opts.read.name.clone(),
                violations: check.violations,
            });
        }
    }
}

/// Part `p` keeps the input's values: its zones say why ([`crate::ZoneReason::Verification`]).
fn put_back(p: &mut Part, why: String) {
    for row in &mut p.report.zones {
        if row.outcome != crate::Outcome::Unchanged || row.points_modified > 0 {
            row.not_written();
        }
        row.reason = crate::ZoneReason::Verification;
    }
    p.report.words_changed = 0;
    p.report.written_c_decimals = p.report.file_c_decimals;
    p.report.written_primary_decimals = p.report.file_primary_decimals;
    p.put_back = Some(why);
}

/// Equation 6 along every run of an NC program held in memory, a stretch at a time
/// (module docs; every run is a stretch): the report of [`crate::analyze_nc`] on the
/// whole program, with memory for the input, one record per run and the report.
pub fn analyze_nc_stretches(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::AnalyzeOptions,
) -> Result<AnalyzeReport, Error> {
    let mut report = None;
    let mut runs = Vec::new();
    analyze_nc_each(bytes, machine, opts, &mut |piece| {
        match piece {
            Piece::Head(head) => report = Some(head.clone()),
            Piece::Run(run) => runs.push(*run),
        }
        Ok(())
    })?;
    // analyze_nc_each hands out the head before any run, or fails.
    let Some(mut report) = report else {
        return Err(Error::NoRuns {
            path: opts.read.name.clone(),
        });
    };
    report.runs = runs;
    Ok(report)
}

/// A piece of the analysis report, as [`analyze_nc_each`] hands it out.
#[derive(Debug)]
pub enum Piece<'a> {
    /// The report without its runs (file, machine, cone, primary letter, warnings): first.
    Head(&'a AnalyzeReport),
    /// One run's report, in file order.
    Run(Box<RunReport>),
}

/// [`crate::analyze_nc`] handing out the report as it is made, so that it need not be
/// kept: `each` gets the head ([`Piece::Head`]), then every run's report in file order.
/// An error of `each` stops the reading ([`Error::Output`]).
pub fn analyze_nc_each(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::AnalyzeOptions,
    each: &mut dyn FnMut(Piece<'_>) -> std::io::Result<()>,
) -> Result<(), Error> {
    // A CL file handed to `analyze`: say so, not what the NC reader saw first.
    analyze_each(bytes, machine, opts, each)
        .map_err(|e| crate::program::or_cl_file(e, bytes, &opts.read.name))
}

fn analyze_each(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::AnalyzeOptions,
    each: &mut dyn FnMut(Piece<'_>) -> std::io::Result<()>,
) -> Result<(), Error> {
    opts.check()?;
    let rd = Reading::analysis(opts, machine)?;
    let (sv, l, first, nothing) = match begin(bytes, machine, &rd)? {
        Begun::Nothing { sv, l, why } => {
            let why = format!("{why}: no run analysed");
            (sv, l, Some(why), true)
        }
        Begun::Stretches { sv, l } => (sv, l, None, false),
    };
    let letters = readings(rd.letters)[l];
    let (not_analysed, warnings) = sv.head(&rd, letters, first);
    each(Piece::Head(&AnalyzeReport {
        file: opts.read.name.clone(),
        machine: machine.name.clone(),
        cone_deg: opts.analysis.cone_deg,
        pole_reach_deg: opts.analysis.pole_reach_deg,
        primary: (letters.tilt as char).to_string(),
        warnings,
        not_analysed,
        runs: Vec::new(),
    }))
    .map_err(Error::Output)?;
    if nothing {
        return Ok(());
    }
    let todo = stretches(&sv.runs, l, |_| true);
    each_stretch(
        bytes,
        &sv,
        &todo,
        l,
        &rd,
        |lp| crate::analyze::analyze_program(&lp, machine, &opts.analysis).runs,
        |runs, _| {
            runs.into_iter()
                .try_for_each(|r| each(Piece::Run(Box::new(r))))
        },
    )
}

/// A run as [`each_run`] hands it out: the run, its path and the lines of its points,
/// without the program around it.
pub(crate) struct RunRead {
    /// Number of the run in the file, from 1 (as reports give it).
    pub number: usize,
    /// The run as the NC crate found it, ended as in the file.
    pub run: Run,
    /// The path (axes X Y Z P C), or why there is none.
    pub path: Result<polepatch_patcher::Path, crate::program::RunProblem>,
    /// The file line (1-based) of each point.
    pub point_lines: Vec<usize>,
    /// The work offset for the run ([`LoadedProgram::datum_mm`]).
    pub datum_mm: Option<[f64; 3]>,
}

/// Every run of the program, as the analysis reads it (every run a stretch), handed to
/// `work` (on all cores) and the results of each stretch to `sink` in file order; the
/// tilting letter in use. A stretch is read for its runs only
/// ([`polepatch_nc::stretch::read_stretch_runs`]): a run costs its points, not its program.
pub(crate) fn each_run<T: Send>(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::AnalyzeOptions,
    work: impl Fn(RunRead) -> T + Sync,
    mut sink: impl FnMut(Vec<T>) -> std::io::Result<()>,
) -> Result<char, Error> {
    // The simulator takes a motion apart at every feed change and joins the runs itself.
    let rd = Reading {
        passes: false,
        ..Reading::analysis(opts, machine)?
    };
    let (sv, l) = match begin(bytes, machine, &rd)? {
        Begun::Nothing { why, .. } => return Err(why),
        Begun::Stretches { sv, l, .. } => (sv, l),
    };
    let todo = stretches(&sv.runs, l, |_| true);
    let letters = readings(rd.letters)[l];
    in_batches(
        bytes,
        &sv,
        &todo,
        |st| {
            let recs = &sv.runs[st.runs.clone()];
            let read = polepatch_nc::stretch::read_stretch_runs(
                bytes,
                &sv.read,
                &stretch_spec(resume_place(recs, st), st, rd.passes),
                |first| recs.iter().any(|r| r.first_block == first),
            )
            .map_err(|e| Error::Parse(e.with_path(rd.name)))?;
            check_runs(&read.runs, recs, st);
            let line = |b: usize| read.lines[b - st.first_block];
            let out = read
                .runs
                .into_iter()
                .zip(recs)
                .enumerate()
                .map(|(k, (mut run, rec))| {
                    run.ended_by = rec.ended_by;
                    let point_lines: Vec<usize> = run.blocks.iter().map(|&b| line(b)).collect();
                    let mut rp = run_path(run, letters, rd.fallback, point_lines[0]);
                    // A G93 block too slow to analyse is named at its own line.
                    if let Err(crate::program::RunProblem::FeedTooLow { line, point, .. }) =
                        &mut rp.path
                    {
                        *line = point_lines[*point];
                    }
                    work(RunRead {
                        number: st.runs.start + k + 1,
                        run: rp.run,
                        path: rp.path,
                        point_lines,
                        datum_mm: rec.datum_mm,
                    })
                })
                .collect();
            Ok((out, 0..0))
        },
        |t, _| sink(t),
    )?;
    Ok(letters.tilt as char)
}

/// Read `bytes` (named `name` in messages) as one stretch of the one reader
/// (the module docs) and build each run's path for `machine`; `feed_fallback_mm_min` is
/// used for runs with no F in force. A program with nothing to analyse is an error.
pub fn load_nc(
    bytes: &[u8],
    name: &str,
    machine: &Machine,
    feed_fallback_mm_min: Option<f64>,
) -> Result<LoadedProgram, Error> {
    load_nc_with(
        bytes,
        machine,
        &crate::options::AnalyzeOptions {
            read: crate::options::ReadOptions {
                feed_fallback_mm_min,
                ..crate::options::ReadOptions::named(name)
            },
            ..crate::options::AnalyzeOptions::default()
        },
    )
}

/// [`load_nc`] with the reading options of `opts` (name, feed fallback, work offset,
/// units; its analysis options are not used).
pub fn load_nc_with(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::AnalyzeOptions,
) -> Result<LoadedProgram, Error> {
    opts.check()?;
    load_program(bytes, machine, opts)
        .map_err(|e| crate::program::or_cl_file(e, bytes, &opts.read.name))
}

/// The whole program as one stretch ([`load_nc`]): the same two reads as
/// a patch, with every block and every run in the stretch. A program that holds nothing to
/// analyse is an error here.
pub(crate) fn load_program(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::options::AnalyzeOptions,
) -> Result<LoadedProgram, Error> {
    let name = opts.read.name.as_str();
    let rd = Reading::analysis(opts, machine)?;
    let (sv, l) = match begin(bytes, machine, &rd)? {
        Begun::Nothing { why, .. } => return Err(why),
        Begun::Stretches { sv, l, .. } => (sv, l),
    };
    let whole = Stretch {
        first_block: 0,
        last_block: sv.blocks.saturating_sub(1),
        runs: 0..sv.runs.len(),
        whole: true,
    };
    let mut loaded = None;
    each_stretch(
        bytes,
        &sv,
        &[whole],
        l,
        &rd,
        |lp| lp,
        |lp, _| {
            loaded = Some(lp);
            Ok(())
        },
    )?;
    let mut lp = loaded.ok_or(Error::NoRuns {
        path: name.to_string(),
    })?;
    lp.notes = sv.notes;
    Ok(lp)
}

/// The second read (module docs, step 3): each stretch of `todo` read again from where the
/// survey left a place before it ([`Kept::start`]), built as a program with its runs and
/// what the rest of the file says, handed to `work` — in batches on all cores — and the
/// results to `sink` in file order, with the bytes of the file the stretch covers. Only the
/// stretches are lexed again, not the bytes between them.
fn each_stretch<T: Send>(
    bytes: &[u8],
    sv: &Survey,
    todo: &[Stretch],
    l: usize,
    rd: &Reading<'_>,
    work: impl Fn(LoadedProgram) -> T + Sync,
    sink: impl FnMut(T, std::ops::Range<usize>) -> std::io::Result<()>,
) -> Result<(), Error> {
    in_batches(
        bytes,
        sv,
        todo,
        |st| {
            let hand = read_stretch(bytes, sv, st, rd)?;
            let replaced = hand.program.base()..hand.end_byte.unwrap_or(bytes.len());
            Ok((work(loaded(bytes, hand, sv, l, rd)), replaced))
        },
        sink,
    )
}

/// The stretches of `todo` made into results by `make` (each with the bytes of the file it
/// covers), in batches of about [`BATCH_FRACTION`] of the file on all cores, and handed to
/// `sink` in file order.
fn in_batches<T: Send>(
    bytes: &[u8],
    sv: &Survey,
    todo: &[Stretch],
    make: impl Fn(&Stretch) -> Result<(T, std::ops::Range<usize>), Error> + Sync,
    mut sink: impl FnMut(T, std::ops::Range<usize>) -> std::io::Result<()>,
) -> Result<(), Error> {
    use rayon::prelude::*;
    let batch_bytes = (bytes.len() / BATCH_FRACTION).clamp(BATCH_MIN_BYTES, BATCH_MAX_BYTES);
    // About where each stretch starts in the file: its batch is cut by these.
    let near_byte: Vec<usize> = todo
        .iter()
        .map(|st| {
            sv.runs[st.runs.clone()]
                .first()
                .and_then(|r| r.kept.as_ref()?.start.as_ref())
                .map_or(0, Resume::near_byte)
        })
        .collect();
    let mut k = 0usize;
    while k < todo.len() {
        let (mut e, mut size) = (k, 0usize);
        while e < todo.len() && (e == k || size < batch_bytes) {
            let next = near_byte.get(e + 1).copied().unwrap_or(bytes.len());
            size += next.saturating_sub(near_byte[e]);
            e += 1;
        }
        let parts: Vec<Result<(T, std::ops::Range<usize>), Error>> =
            todo[k..e].par_iter().map(&make).collect();
        for part in parts {
            let (t, replaced) = part?;
            sink(t, replaced).map_err(Error::Output)?;
        }
        k = e;
    }
    Ok(())
}

/// Read stretch `st` again ([`polepatch_nc::stretch`]): from the place the survey kept
/// before its first run (or, for the whole file and where none was kept, from the start),
/// its blocks into a program and its runs as the survey found them, each with the tool the
/// survey found for it.
fn read_stretch(
    bytes: &[u8],
    sv: &Survey,
    st: &Stretch,
    rd: &Reading<'_>,
) -> Result<InHand, Error> {
    let recs = &sv.runs[st.runs.clone()];
    let spec = stretch_spec(resume_place(recs, st), st, rd.passes);
    let read = polepatch_nc::stretch::read_stretch(bytes, &sv.read, &spec, |first| {
        recs.iter().any(|r| r.first_block == first)
    })
    .map_err(|e| Error::Parse(e.with_path(rd.name)))?;
    check_runs(&read.runs, recs, st);
    // What ended each run in the file, the tool the survey tracked.
    let runs = read
        .runs
        .into_iter()
        .zip(recs)
        .map(|(mut run, rec)| {
            run.ended_by = rec.ended_by;
            let tool = rec
                .kept
                .as_ref()
                .map(|k| k.tool.clone())
                .unwrap_or_default();
            (run, tool)
        })
        .collect();
    Ok(InHand {
        stretch: st.clone(),
        program: read.program,
        end_byte: Some(read.end_byte),
        runs,
    })
}

/// Where the second read of stretch `st` (of runs `recs`) resumes: the place the survey
/// kept before its first run, or none (the whole file, or none kept: from the start).
fn resume_place(recs: &[RunRec], st: &Stretch) -> Option<Resume> {
    (!st.whole)
        .then(|| recs.first()?.kept.as_ref()?.start.clone())
        .flatten()
}

/// The second read of stretch `st`, from `resumed` ([`resume_place`]).
fn stretch_spec(
    resumed: Option<Resume>,
    st: &Stretch,
    passes: bool,
) -> polepatch_nc::stretch::StretchSpec {
    use polepatch_nc::stretch::{ReadFrom, StretchSpec};
    StretchSpec {
        from: resumed.map_or(ReadFrom::FileStart, |at| ReadFrom::RunStart(Box::new(at))),
        first_block: st.first_block,
        last_block: st.last_block,
        whole: st.whole,
        passes,
    }
}

/// The runs of the second read are those the survey found: the same blocks (a stretch's
/// end is its run's end or later).
///
/// # Panics
/// If they are not (a defect of the reader, not of the program).
fn check_runs(runs: &[Run], recs: &[RunRec], st: &Stretch) {
    assert!(
        runs.len() == recs.len()
            && runs.iter().zip(recs).all(|(run, rec)| {
                run.blocks.first() == Some(&rec.first_block)
                    && run.blocks.last() == Some(&rec.last_block)
            }),
        "the second read found other runs than the survey in the stretch at block {}",
        st.first_block
    );
}

/// A stretch as a loaded program: its blocks, its runs (block indices re-based) with their
/// paths, and what the rest of the file says about it.
fn loaded(bytes: &[u8], hand: InHand, sv: &Survey, l: usize, rd: &Reading<'_>) -> LoadedProgram {
    let base = hand.program.base();
    let end = hand.end_byte.unwrap_or(bytes.len());
    let program = hand.program.finish(bytes[base..end].to_vec(), sv.dialect);
    let first = hand.stretch.first_block;
    let letters = readings(rd.letters)[l];
    let recs = &sv.runs[hand.stretch.runs.clone()];
    let runs: Vec<RunPath> = hand
        .runs
        .into_iter()
        .map(|(mut run, tool)| {
            for b in &mut run.blocks {
                *b -= first;
            }
            let line = program.blocks[run.blocks[0]].line;
            let mut rp = run_path(run, letters, rd.fallback, line);
            // A G93 block too slow to analyse is named at its own line.
            if let Err(crate::program::RunProblem::FeedTooLow { line, point, .. }) = &mut rp.path {
                *line = program.blocks[rp.run.blocks[*point]].line;
            }
            rp.found_tool = tool;
            rp
        })
        .collect();
    LoadedProgram {
        name: rd.name.to_string(),
        program,
        primary_letter: letters.tilt,
        pole_letter: letters.pole,
        runs,
        warnings: Vec::new(),
        chord_tolerance_mm: rd.chord_tolerance_mm,
        window: Window {
            first_run: hand.stretch.runs.start,
            style: sv.style,
            end: recs.iter().map(|r| r.end[l].pose(first)).collect(),
            datum_mm: recs.iter().map(|r| r.datum_mm).collect(),
        },
        notes: crate::notes::Notes::new(),
        tool: rd.tool.clone(),
        pole: rd.pole.clone(),
    }
}

/// Add a stretch's report to the file's.
fn merge(report: &mut FileReport, part: FileReport) {
    report.words_changed += part.words_changed;
    if part.file_c_decimals.is_some() {
        report.file_c_decimals = part.file_c_decimals;
        report.file_primary_decimals = part.file_primary_decimals;
    }
    report.written_c_decimals = report.written_c_decimals.max(part.written_c_decimals);
    report.written_primary_decimals = report
        .written_primary_decimals
        .max(part.written_primary_decimals);
    report.untouched_runs.extend(part.untouched_runs);
    report.warnings.extend(part.warnings);
    report.zones.extend(part.zones);
}

#[cfg(test)]
mod tests {
    /// A defect to plant in the output of every stretch that holds the marker (the stretches
    /// are patched on worker threads): the marker, the bytes to find and what to write
    /// instead.
    static PLANT: std::sync::Mutex<Option<(String, String, String)>> = std::sync::Mutex::new(None);

    /// A stretch's output with the planted defect, if any.
    pub(super) fn planted(output: Vec<u8>) -> Vec<u8> {
        let plant = PLANT.lock().map(|p| p.clone()).unwrap_or(None);
        match plant {
            Some((marker, find, with)) => {
                let text = String::from_utf8_lossy(&output).into_owned();
                // The last occurrence: the stretch's retract, after its pass.
                if let (true, Some(at)) = (text.contains(&marker), text.rfind(&find)) {
                    format!("{}{with}{}", &text[..at], &text[at + find.len()..]).into_bytes()
                } else {
                    output
                }
            }
            None => output,
        }
    }

    /// A zone whose written values fail the check of the written program is put back with
    /// reason `verification`, the line and the check in the warnings; the rest is written.
    /// Planted: the stretch's output with its retract lowered to cutting depth (the crash of
    /// issue 39 class 1), on a program of two passes of which only the first is planted.
    #[test]
    fn a_zone_that_fails_the_check_is_put_back() {
        let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
        let pass =
            std::fs::read_to_string(root.join("fixtures/verify/fanuc-g434-retract-restated.nc"))
                .unwrap();
        // The pass twice: the second's retract at Z60 (not planted), after a tool change —
        // else the positioning move of the second would go where the first's end is freed
        // to, and the two would be planned together (crate::plan) and put back together.
        let body = pass
            .trim_end_matches("%\n")
            .trim_end_matches("M30\n")
            .trim_end_matches("G49\n")
            .replacen("G1 X0.5 ", "G1 X0.5 (PLANTED) ", 1);
        let second: String = pass
            .lines()
            .skip_while(|l| !l.starts_with("G0 X0 Y0 Z50."))
            .map(|l| format!("{}\n", l.replace("Z50.", "Z60.")))
            .collect();
        let program = format!("{body}T1 M6\nG43.4 H1\n{second}");
        let machine = polepatch_kinematics::Machine::builtin("mikron-ucp710").unwrap();
        let opts = crate::options::PatchOptions::named("planted.nc");
        let (clean, clean_report) = crate::patch_nc(program.as_bytes(), &machine, &opts).unwrap();
        assert_eq!(clean_report.zones.len(), 2);
        assert!(
            clean_report
                .zones
                .iter()
                .all(|z| z.outcome == crate::Outcome::Reached)
        );
        let set = |v| *PLANT.lock().unwrap() = v;
        set(Some(("(PLANTED)".into(), "Z50. A".into(), "Z-4. A".into())));
        let result = crate::patch_nc(program.as_bytes(), &machine, &opts);
        set(None);
        let (out, report) = result.unwrap();
        let (first, second) = (&report.zones[0], &report.zones[1]);
        assert_eq!(first.outcome, crate::Outcome::Unchanged, "{first:?}");
        assert_eq!(first.reason, crate::ZoneReason::Verification);
        assert_eq!(second.outcome, crate::Outcome::Reached, "{second:?}");
        let retract = program
            .lines()
            .position(|l| l.starts_with("G0 Z50."))
            .unwrap()
            + 1;
        assert!(
            report.warnings.iter().any(|w| w.contains(&format!(
                "failed its verification at line {retract} (positioning_target"
            ))),
            "{:?}",
            report.warnings
        );
        // The first pass as read, the second as patched without the plant.
        let text = String::from_utf8(out).unwrap();
        let clean = String::from_utf8(clean).unwrap();
        let split = retract + 1;
        let head = |t: &str| t.lines().take(split).collect::<Vec<_>>().join("\n");
        let tail = |t: &str| t.lines().skip(split).collect::<Vec<_>>().join("\n");
        assert_eq!(head(&text), head(&program));
        assert_eq!(tail(&text), tail(&clean));
    }
}
