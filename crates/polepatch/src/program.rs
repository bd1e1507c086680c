//! From NC bytes to the patcher's paths: parse, group into runs, pick the axes.

use crate::error::Error;
use crate::settings::CL_SNIFF_BYTES;
pub use crate::tolerances::MIN_FEED_MM_MIN;
use polepatch_kinematics::{Machine, PoleDistance};
use polepatch_nc::{Dialect, FileStyle, Program, RotaryLetters, Run, modal};
use polepatch_patcher::Path;

/// Why one run cannot be analysed (the others still can).
#[derive(Debug, Clone, PartialEq)]
pub enum RunProblem {
    /// No F in force and no fallback feed given.
    NoFeed,
    /// The feed is below [`MIN_FEED_MM_MIN`]: the run's F, or under G93 its slowest
    /// block's.
    FeedTooLow {
        /// The feed along the tool tip, mm/min.
        feed_mm_min: f64,
        /// File line of the block with that feed (the run's first point's until the
        /// reader sets it from `point`).
        line: usize,
        /// The run's point whose block has that feed (0: the run's F, stated before or
        /// at its first point).
        point: usize,
        /// Under G93: the block's F as written, 1/min.
        inverse_time_per_min: Option<f64>,
    },
    /// A rotary axis moves in the run while its value at some point is unknown (after an
    /// expression, a datum change or a call): reading it as anything would guess.
    UnknownRotary {
        /// The letter.
        letter: char,
    },
    /// The run turns a tilting axis other than the one analysed (`B` in a program read
    /// with `A` and `C`: an A-B trunnion's program on an A-C machine), or holds it away
    /// from 0: the tool axis depends on an axis the machine does not have, so nothing the
    /// analysis says about the run would be true.
    OtherRotary {
        /// The letter the machine does not have.
        letter: char,
        /// The letters analysed (`"A and C"`).
        analysed: String,
    },
}

impl std::fmt::Display for RunProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunProblem::NoFeed => {
                write!(f, "no feed (F) in force for this run; give one with --feed")
            }
            RunProblem::FeedTooLow {
                feed_mm_min,
                line,
                inverse_time_per_min: Some(per_min),
                ..
            } => write!(
                f,
                "line {line}: inverse-time feed F{} (G93, 1/min) moves the tool tip at {} \
                 mm/min, below polepatch's minimum of {MIN_FEED_MM_MIN} mm/min; the run is \
                 left as it is",
                crate::report::feed_text(*per_min),
                crate::report::feed_text(*feed_mm_min)
            ),
            RunProblem::FeedTooLow {
                feed_mm_min, line, ..
            } => write!(
                f,
                "line {line}: feed F{} mm/min is below polepatch's minimum of \
                 {MIN_FEED_MM_MIN} mm/min; the run is left as it is",
                crate::report::feed_text(*feed_mm_min)
            ),
            RunProblem::UnknownRotary { letter } => write!(
                f,
                "the rotary axes move in this run but {letter} is unknown at some of its points \
                 (after an expression, a datum change or a call); the run is left as it is"
            ),
            RunProblem::OtherRotary { letter, analysed } => write!(
                f,
                "the run turns {letter} (or holds it away from 0), an axis the machine does not \
                 have — polepatch analyses {analysed} — so its words are carried through as \
                 written and the run is left as it is"
            ),
        }
    }
}

/// The rotary letters programs for `machine` are read with, when it can be read,
/// analysed and patched: its two letters must be among A B C (A-C, B-C, an A-B trunnion
/// whose platter is B, …); any other letter is refused by name. Every pair of axes is
/// read through its own kinematics: the distance from the pole is the angle between the
/// tool and the pole axis ([`PoleDistance`]), every change is checked through the pair's
/// forward kinematics, and the other IK branch as (−P, C + 180°) is taken on the standard
/// form only ([`Machine::standard_form`]; a 45° nutating table has another).
pub fn check_layout(machine: &Machine) -> Result<RotaryLetters, Error> {
    let (p, c) = (machine.primary_letter(), machine.c_letter());
    match RotaryLetters::new(p as u8, c as u8) {
        Some(letters) if p.is_ascii() && c.is_ascii() => Ok(letters),
        _ => Err(Error::machine(
            &machine.name,
            format!(
                "its rotary axes are called {p} and {c}; polepatch reads programs \
                 with rotary words A, B and C so far (issue 29)"
            ),
        )),
    }
}

/// The rotary letters A B C of `machine` that turn without end (its pole axis without a
/// `range_deg`; the tilting axis always has a range): a feed move that turns one by more
/// than half a turn is a wrap ([`polepatch_nc::ReadOptions::endless`]).
pub fn endless_letters(machine: &Machine) -> [bool; 3] {
    let mut endless = [false; 3];
    let c = machine.c_letter();
    if machine.c_range_deg.is_none() && ('A'..='C').contains(&c) {
        endless[c as usize - 'A' as usize] = true;
    }
    endless
}

/// The letters of the machine's auxiliary axes ([`polepatch_kinematics::Controller::auxiliary_axes`]):
/// one letter each, not X Y Z nor the machine's rotary letters (those it moves).
fn auxiliary_letters(machine: &Machine) -> Result<Vec<u8>, Error> {
    machine
        .controller
        .auxiliary_axes
        .iter()
        .map(|a| {
            let l = a.trim().to_ascii_uppercase();
            match l.as_bytes() {
                [c] if c.is_ascii_alphabetic()
                    && !b"XYZ".contains(c)
                    && *c != machine.primary_letter() as u8
                    && *c != machine.c_letter() as u8 =>
                {
                    Ok(*c)
                }
                _ => Err(Error::machine(
                    &machine.name,
                    format!(
                        "[controller] auxiliary_axes: '{a}' is not one letter other than \
                     X Y Z, {} and {} (the axes the machine moves)",
                        machine.primary_letter(),
                        machine.c_letter()
                    ),
                )),
            }
        })
        .collect()
}

/// How to read programs for `machine`: the dialect detected, the machine's TCPM codes;
/// in inches when the program states no units and `inch` is true, else mm.
pub fn read_options_with(
    machine: &Machine,
    inch: bool,
) -> Result<polepatch_nc::ReadOptions, Error> {
    check_layout(machine)?;
    let codes = |field: &str, list: &[String]| {
        list.iter()
            .map(|c| {
                polepatch_nc::Code::parse(c).map_err(|e| {
                    Error::machine(&machine.name, format!("[controller] {field}: {e}"))
                })
            })
            .collect::<Result<Vec<_>, _>>()
    };
    Ok(polepatch_nc::ReadOptions {
        dialect: Dialect::Auto,
        controller: polepatch_nc::ControllerCodes {
            on: codes("tcpm_on", &machine.controller.tcpm_on)?,
            off: codes("tcpm_off", &machine.controller.tcpm_off)?,
            always: machine.controller.tcpm_always,
            auxiliary: auxiliary_letters(machine)?,
        },
        flow: None,
        inch,
        endless: endless_letters(machine),
    })
}

/// One run of the program with its path for the patcher.
#[derive(Debug, Clone)]
pub struct RunPath {
    /// The run as the NC crate found it.
    pub run: Run,
    /// The path (axes X Y Z P C), or why there is none.
    pub path: Result<Path, RunProblem>,
    /// What the program says of the tool in use ([`crate::tool::Tracker`]).
    pub found_tool: crate::tool::FoundTool,
}

/// A parsed program with its runs as paths for a machine.
#[derive(Debug, Clone)]
pub struct LoadedProgram {
    /// Name used in messages and reports (a file name, or what the caller chose).
    pub name: String,
    /// The parsed program.
    pub program: Program,
    /// Letter used as the primary rotary axis: the machine's (a program tilting with
    /// another letter is refused, `Error::ForeignAxis`).
    pub primary_letter: u8,
    /// Letter of the pole axis: the machine's (C on the built-ins; B on an A-B trunnion
    /// whose platter is B).
    pub pole_letter: u8,
    /// Runs in file order.
    pub runs: Vec<RunPath>,
    /// Things the user should know (e.g. primary-letter substitution).
    pub warnings: Vec<String>,
    /// Chord tolerance for runs patched through the kinematic chain, mm (default
    /// [`crate::machine_frame::CHORD_TOLERANCE_MM`]; see [`crate::options::PatchOptions`]).
    pub chord_tolerance_mm: f64,
    /// What the rest of the file says about `program`, a stretch of it
    /// (the one reader's stretch; the whole file is one stretch).
    pub window: Window,
    /// What the reader carried through without analysing; empty for a
    /// stretch (the stream lists it once for the file).
    pub notes: crate::notes::Notes,
    /// The caller's tool options ([`crate::options::PatchOptions::tool`]).
    pub tool: crate::tool::ToolOptions,
    /// The machine's distance from the pole (the one rule of "near the pole").
    pub(crate) pole: PoleDistance,
}

/// What a stretch of a file ([`LoadedProgram::window`]) needs from the rest of the file,
/// per run of the stretch where it is per run.
#[derive(Debug, Clone)]
pub struct Window {
    /// Number (from 0) in the whole file of the stretch's first run.
    pub first_run: usize,
    /// The whole file's number style.
    pub style: FileStyle,
    /// The run's end pose ([`EndPose`](crate::EndPose)), decided on the blocks after it in the
    /// whole file (restating blocks numbered in the stretch's program).
    pub end: Vec<crate::end_pose::EndPose>,
    /// The run's work offset ([`LoadedProgram::datum_mm`]) from the whole file's
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
    /// The programmed feed of run `r`, mm/min: its path's, or, for a run that cannot be
    /// analysed, the F the reader found (`None`: none).
    pub fn run_feed_mm_min(&self, r: usize) -> Option<f64> {
        let rp = &self.runs[r];
        rp.path
            .as_ref()
            .ok()
            .map(|p| p.feed_mm_min)
            .or(rp.run.feed_mm_min)
    }
    /// Number of run `r` in the file, from 1 (as reports give it).
    pub fn run_number(&self, r: usize) -> usize {
        r + 1 + self.window.first_run
    }
    /// The file's number style (of the whole file, also for a stretch).
    pub fn file_style(&self) -> FileStyle {
        self.window.style
    }
    /// The end pose of run `r` ([`EndPose`](crate::EndPose)), as the survey of the
    /// whole file decided it.
    pub fn end_pose(&self, r: usize) -> crate::end_pose::EndPose {
        self.window.end[r].clone()
    }

    /// The work offset (machine coordinates of the program's zero, mm) for run `r`, or `None`
    /// when it is not known for certain:
    ///
    /// - the last frame change before the run states its values (Heidenhain `G54 X Y Z`):
    ///   those values;
    /// - else, when the program changes its frame at most once before the run (a named work
    ///   offset such as Fanuc `G54`, or nothing at all): `given` (`--work-offset`);
    /// - else (the frame changed more than once, or by a shift polepatch does not follow —
    ///   `G92`, `TRANS`, … — after the last stated datum): unknown.
    pub fn datum_mm(&self, r: usize) -> Option<[f64; 3]> {
        self.window.datum_mm[r]
    }

    /// The program's rotary letters: the tilting axis and the pole axis.
    pub fn letters(&self) -> RotaryLetters {
        RotaryLetters {
            tilt: self.primary_letter,
            pole: self.pole_letter,
        }
    }
    /// Index of the primary letter in [`polepatch_nc::Modal::pos`].
    pub fn primary_index(&self) -> usize {
        self.letters().tilt_index()
    }
    /// Index of the pole letter in [`polepatch_nc::Modal::pos`].
    pub fn pole_index(&self) -> usize {
        self.letters().pole_index()
    }
}

/// `e`, or — when it is a syntax error and `bytes` is a CL file — the error that says so
/// ([`cl_file_error`]).
pub(crate) fn or_cl_file(e: Error, bytes: &[u8], name: &str) -> Error {
    match e {
        Error::Parse(_) => cl_file_error(bytes, name).unwrap_or(e),
        e => e,
    }
}

/// When `bytes` is a CL file (an APT `GOTO/` record starts a line within its first
/// [`CL_SNIFF_BYTES`]), the error that says so, at that line: given instead of the NC
/// reader's message about the first line it cannot read (`PARTNO`, `SPINDL/RPM,…`), which
/// would be about the wrong thing.
pub fn cl_file_error(bytes: &[u8], name: &str) -> Option<Error> {
    let head = &bytes[..bytes.len().min(CL_SNIFF_BYTES)];
    let record = head.split(|&b| b == b'\n' || b == b'\r').find(|l| {
        let t = l.trim_ascii_start();
        t.len() >= 5 && t[..5].eq_ignore_ascii_case(b"GOTO/")
    })?;
    // Line numbers as the reader counts them (CR LF, LF or CR alone each end one line).
    let line = line_number(head, record.as_ptr() as usize - head.as_ptr() as usize);
    Some(Error::Unsupported {
        path: name.to_string(),
        line,
        what: "this is a CL file (APT GOTO/ records), not an NC program: post it with \
               `polepatch post`"
            .to_string(),
    })
}

/// 1-based line of byte `at` of `bytes` (CR LF, LF or a CR alone ends a line).
fn line_number(bytes: &[u8], at: usize) -> usize {
    let mut line = 1;
    let mut k = 0;
    while k < at {
        match bytes[k] {
            b'\n' => line += 1,
            b'\r' if bytes.get(k + 1) != Some(&b'\n') => line += 1,
            _ => {}
        }
        k += 1;
    }
    line
}

/// A run with its path for the patcher: axes X Y Z, the tilting and the pole letter of
/// `letters`; the run's feed, else `feed_fallback_mm_min`.
pub(crate) fn run_path(
    run: Run,
    letters: RotaryLetters,
    feed_fallback_mm_min: Option<f64>,
    first_line: usize,
) -> RunPath {
    let path = run_check(&run, letters, feed_fallback_mm_min, first_line).map(|feed| Path {
        s_mm: if run.block_feed_mm_min.is_empty() {
            run.s_mm.clone()
        } else {
            block_feed_parameter(&run, feed)
        },
        axes: run.axes5(letters),
        feed_mm_min: feed,
    });
    RunPath {
        run,
        path,
        found_tool: crate::tool::FoundTool::default(),
    }
}

/// Whether a run's path parameter follows its tool-tip length when the tips move (a ball's
/// centre kept): under feed per minute, each block's span scaled by its own feed as
/// [`block_feed_parameter`] scales it (the patcher's `segment_scale`); not under G93, where
/// each block keeps its time whatever its length.
pub(crate) fn parameter_is_length(run: &Run) -> bool {
    run.feed_mode != polepatch_nc::FeedMode::InverseTime
}

/// The path parameter of a run whose blocks have different feeds — an inverse-time (G93)
/// run, or a G94 pass whose F changes ([`polepatch_nc::RunBuilder::passes`]) — at its
/// reference feed `f_ref` ([`reference_feed`]): block k of tool-tip length L_k
/// and feed F_k (its time L_k/F_k) spans u_k − u_{k−1} = L_k·f_ref/F_k, so that moving
/// along u at f_ref takes every block its programmed time.
///
/// This is Equation 6 at each block's own feed: on a block, q_u = q_s·F_k/f_ref, so the
/// bound V/|q_u| on u̇ is (f_ref/F_k)·V/|q_s| and the ratio u̇/f_ref = ṡ/F_k — and likewise
/// for A and J (q_uu = q_ss·(F_k/f_ref)², q_uuu = q_sss·(F_k/f_ref)³). The analysis
/// spline is the interpolant over u (the same points, knots spaced by block time); when
/// every block has the same feed, u = s and the run is analysed exactly as in G94.
fn block_feed_parameter(run: &Run, f_ref: f64) -> Vec<f64> {
    let feeds = &run.block_feed_mm_min;
    if feeds.iter().all(|&f| f == feeds[0]) {
        return run.s_mm.clone();
    }
    let mut u = Vec::with_capacity(run.s_mm.len());
    u.push(0.0);
    for (k, f) in feeds.iter().enumerate() {
        let l = run.s_mm[k + 1] - run.s_mm[k];
        u.push(u[k] + l * f_ref / f);
    }
    u
}

/// Whether a run can be analysed with the rotary letters `letters`: its feed
/// ([`run_feed`]), or why not — the one rule every read uses (the whole program, the
/// stream survey, the no-zone fast path).
pub(crate) fn run_check(
    run: &Run,
    letters: RotaryLetters,
    feed_fallback_mm_min: Option<f64>,
    first_line: usize,
) -> Result<f64, RunProblem> {
    let feed = run_feed(run, feed_fallback_mm_min, first_line)?;
    other_rotary_still(run, letters)?;
    rotary_known(run, letters)?;
    Ok(feed)
}

/// The rotary letter that is not analysed (B when the program is read with A and C, and
/// so on: [`RotaryLetters::other`]) may appear in a run only parked at 0 (module docs of
/// [`RunProblem::OtherRotary`]).
fn other_rotary_still(run: &Run, letters: RotaryLetters) -> Result<(), RunProblem> {
    let letter = letters.other();
    let other = modal::axis_index(letter).unwrap_or(modal::B);
    if run.pos.iter().any(|p| p[other].is_some_and(|v| v != 0.0)) {
        return Err(RunProblem::OtherRotary {
            letter: letter as char,
            analysed: format!("{} and {}", letters.tilt as char, letters.pole as char),
        });
    }
    Ok(())
}

/// A run whose rotary axes (the tilting one and the pole axis of `letters`) move may not
/// have a point where one of them is unknown: [`Run::axes5`] reads an unknown value as 0,
/// which is right only where the axis is not programmed at all in the run.
fn rotary_known(run: &Run, letters: RotaryLetters) -> Result<(), RunProblem> {
    let moves = |i: usize| {
        let mut known = run.pos.iter().filter_map(|p| p[i]);
        known.next().is_some_and(|v0| known.any(|v| v != v0))
    };
    let (p_idx, c_idx) = (letters.tilt_index(), letters.pole_index());
    let rotary_moves = moves(p_idx) || moves(c_idx);
    for (i, letter) in [(p_idx, letters.tilt as char), (c_idx, letters.pole as char)] {
        let unknown = run.pos.iter().filter(|p| p[i].is_none()).count();
        if unknown > 0 && (rotary_moves || unknown < run.pos.len()) {
            return Err(RunProblem::UnknownRotary { letter });
        }
    }
    Ok(())
}

/// The feed a run is analysed at, mm/min (its F; under G93 its blocks' common feed; the
/// fallback where no F is in force), or why it has none; `first_line` is the line of its
/// first point (for messages).
fn run_feed(
    run: &Run,
    feed_fallback_mm_min: Option<f64>,
    first_line: usize,
) -> Result<f64, RunProblem> {
    let feed = if run.block_feed_mm_min.is_empty() {
        run.feed_mm_min
            .or(feed_fallback_mm_min)
            .ok_or(RunProblem::NoFeed)?
    } else {
        reference_feed(run)
    };
    if feed < MIN_FEED_MM_MIN {
        // Under G93 the slowest block, named at its own line with its F as written.
        let slowest = (!run.block_feed_mm_min.is_empty()).then(|| {
            let feeds = &run.block_feed_mm_min;
            let k = (0..feeds.len())
                .min_by(|&a, &b| feeds[a].total_cmp(&feeds[b]))
                .unwrap_or(0);
            let d = run.s_mm[k + 1] - run.s_mm[k];
            (k + 1, feeds[k] / d)
        });
        return Err(RunProblem::FeedTooLow {
            feed_mm_min: feed,
            line: first_line,
            point: slowest.map_or(0, |(p, _)| p),
            inverse_time_per_min: slowest.map(|(_, f)| f),
        });
    }
    Ok(feed)
}

/// The reference feed of a run whose blocks have their own feeds (G93, or a G94 pass whose
/// F changes): the feed that covers the greatest length of it (its cutting feed: a pass's
/// plunge at F500 before 50 mm at F2000 is analysed at 2000, its cut exactly as a pass at
/// one feed would be, the plunge's blocks spanning L·2000/500), the higher of equal ones;
/// or the block feed when they are all equal; a block slower than [`MIN_FEED_MM_MIN`]
/// makes the run too slow to analyse (its feed, the lowest). Any reference gives each
/// block its own feed ([`block_feed_parameter`]); this one keeps most of the pass at u = s.
pub(crate) fn reference_feed(run: &Run) -> f64 {
    let feeds = &run.block_feed_mm_min;
    if feeds.iter().all(|&f| f == feeds[0]) {
        return feeds[0];
    }
    if feeds.iter().any(|&f| f < MIN_FEED_MM_MIN) {
        return feeds.iter().copied().fold(f64::INFINITY, f64::min);
    }
    let mut by_feed: Vec<(f64, f64)> = Vec::new();
    for (k, &f) in feeds.iter().enumerate() {
        let l = run.s_mm[k + 1] - run.s_mm[k];
        match by_feed.iter_mut().find(|(g, _)| *g == f) {
            Some((_, len)) => *len += l,
            None => by_feed.push((f, l)),
        }
    }
    by_feed
        .into_iter()
        .max_by(|a, b| a.1.total_cmp(&b.1).then(a.0.total_cmp(&b.0)))
        .map_or(feeds[0], |(f, _)| f)
}
