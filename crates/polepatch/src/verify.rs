//! The written program, held against its input: [`verify_nc`] (`polepatch verify`).
//!
//! A patch is checked zone by zone in the patcher's model; this module checks the **bytes
//! that are written**, as a whole, against the bytes that were read — whoever wrote them
//! (polepatch, a re-post, an edit by hand). Both programs are read with the one reader
//! ([`polepatch_nc::scan_blocks_with`]), at the same time, and paired line by line: a patch
//! never adds or drops a line.
//!
//! # What is checked
//! Per line (`o` the original's, `p` the patched one's):
//!
//! 1. **Text.** A line that does not move is byte-identical. A move may differ only in its
//!    X Y Z words and the machine's two rotary words (changed, or inserted where the file
//!    relied on a modal value): the line without those words and without blanks is the
//!    same, and so is the modal state after it except the positions (motion, feed, feed
//!    mode, TCPM, units, incremental, frame transformation, canned cycle).
//! 2. **The tool's reference point**, at every move whose values differ: the point the part
//!    sees — a ball's centre where the tool is a ball programmed at its tip (tip + R·o, o
//!    the tool axis in the part frame from the rotary values, [`polepatch_kinematics::forward`]),
//!    else the point X Y Z state (the tip, or the centre under `M128`) — within
//!    [`REFERENCE_TOL_MM`] plus the rounding of the patched program's words (its most
//!    decimals per letter: a post that drops trailing zeros writes `Z-5` for −5.000). Under TCPM
//!    X Y Z are part coordinates; without it, on a machine with a kinematic chain and a known
//!    work offset, the tip in the part frame comes through the chain; anywhere else (TCPM
//!    unknown or uncertain, no chain, incremental mode, a frame rotation, an arc, a canned
//!    cycle, an expression) nothing may change at all.
//! 3. **Positioning moves** (G0, `FMAX`) keep their X Y Z target (as the program states it,
//!    within the rounding) and may only restate rotary values — under TCPM; without it a
//!    rotary value changed at a positioning move turns the part under the tool.
//! 4. **The orientation change** at every move: the angle between the tool axes of `o` and
//!    `p` within the safety bound (the pole reach, [`polepatch_patcher::driver`]'s), the
//!    caller's `max_deviation_deg` and a flat or bull-nose cutter's surface cap
//!    ([`crate::tool::deviation_cap_deg`]), plus the rounding of the written rotary words.
//! 5. **Equation 6 over every run of the written program** (the reader's runs of `p`, not
//!    the patch's): paired with the run of `o` over the same lines, span by span — where `o`
//!    reaches feed `p` reaches it (within [`REACHED_TOL`]; a span's ratio is the lowest over
//!    the axes: the feed the machine keeps there), elsewhere the run's lowest ratio is no
//!    lower than `o`'s by more than [`RATIO_TOL_REL`] ([`slower`]); the run's estimated time
//!    ∫ds/ṡ no greater than `o`'s by more than [`TIME_TOL_REL`] (plus both estimates' error
//!    bounds).
//! 6. **The program's time**: the runs' times plus every positioning move's (each axis at
//!    its velocity and acceleration limits, the slowest setting the time:
//!    [`crate::end_pose::positioning_time_s`]) no greater than `o`'s (within
//!    [`TIME_TOL_REL`]). Only what differs is computed; the rest is the same on both sides.
//! 7. **What the patch claims** ([`Claim`], given by the pipeline, not by `polepatch
//!    verify`): a zone the report calls reached reaches feed on both rotary axes over its
//!    lines in the written run.
//!
//! What it cannot know: the tool is what it was told (the options, the tool table, the
//! program's own descriptions); it checks geometry and Equation 6, not the part's CAD; the
//! positioning moves' time is an estimate (no jerk, no controller look-ahead).
//!
//! Memory: one block of each program at a time (the patched program is read on a thread of
//! its own and handed over in batches), plus the runs in hand.

use crate::error::Error;
use crate::settings::BATCH_BLOCKS;
use crate::tolerances::LINE_MATCH_MM;
pub use crate::tolerances::RATIO_TOL_REL;
pub use crate::tolerances::REACHED_TOL;
pub use crate::tolerances::REFERENCE_TOL_MM;
pub use crate::tolerances::TIME_TOL_REL;
use crate::tool::{RunTool, ToolDemand, ToolKind, ToolPoint};
pub use crate::violation::{Check, Violation};
use polepatch_kinematics::vec3::{along, norm_direct, sub};
use polepatch_kinematics::{Machine, angle_between_deg, forward};
use polepatch_nc::{
    Block, Dialect, Flags, Modal, Motion, ReadOptions, RotaryLetters, Run, RunBuilder, Scanned,
    Settled, Tcpm, Word, modal, scan_blocks_with,
};
use polepatch_patcher::{AnalysisOptions, Path};
use std::collections::VecDeque;
use std::ops::ControlFlow;

/// A zone the patch reports reached, to be held against the written program
/// ([`verify_claims`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Claim {
    /// File lines of the zone's core (`ZoneRow::core_lines`): where the report's `reached`
    /// says the written values reach feed. Not the patch's whole range, which may keep a
    /// slowness of the program's own that the patch only must not make worse (the
    /// Equation-6 check of every run holds it to that).
    pub lines: [usize; 2],
    /// Both rotary axes reach feed there (`false`: C only, G16's method, `--only-c`).
    pub both_axes: bool,
}

/// What [`verify_nc`] found.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct VerifyReport {
    /// The original's name.
    pub original: String,
    /// The patched program's name.
    pub patched: String,
    /// The machine.
    pub machine: String,
    /// Lines of each program.
    pub lines: usize,
    /// Lines whose bytes differ.
    pub lines_changed: usize,
    /// Moves whose values differ (checked for their reference point and orientation).
    pub moves_changed: usize,
    /// Largest distance between the two programs' reference points at a changed move, mm.
    pub max_reference_shift_mm: f64,
    /// Largest orientation change at a move, degrees.
    pub max_deviation_deg: f64,
    /// Runs whose points differ, analysed on both sides.
    pub runs_compared: usize,
    /// Positioning moves whose start or target differ, timed on both sides.
    pub positioning_moves_compared: usize,
    /// Estimated time of what differs (those runs and positioning moves) in the original, s.
    pub time_before_s: f64,
    /// The same in the patched program, s.
    pub time_after_s: f64,
    /// What does not hold, in line order (empty: the patched program is verified).
    pub violations: Vec<Violation>,
}

impl VerifyReport {
    /// Every check holds.
    pub fn passed(&self) -> bool {
        self.violations.is_empty()
    }
}

/// Hold `patched` against `original` for `machine` (module docs), reading both as a patch
/// with `opts` reads (units, feed fallback, work offset, tool options, cone, pole reach and
/// `max_deviation_deg`). `opts.read.name` names the patched program in messages; the original's
/// name is `original_name`.
///
/// Bad input (either program unreadable) is an [`Error`]; what does not hold is in
/// [`VerifyReport::violations`].
pub fn verify_nc(
    original: &[u8],
    patched: &[u8],
    machine: &Machine,
    opts: &crate::options::PatchOptions,
    original_name: &str,
) -> Result<VerifyReport, Error> {
    verify_claims(original, patched, machine, opts, original_name, &[])
}

/// [`verify_nc`], and every zone of `claims` (reported reached) reaching feed on both
/// rotary axes over its lines in the written program.
pub fn verify_claims(
    original: &[u8],
    patched: &[u8],
    machine: &Machine,
    opts: &crate::options::PatchOptions,
    original_name: &str,
    claims: &[Claim],
) -> Result<VerifyReport, Error> {
    opts.check()?;
    let letters = crate::program::check_layout(machine)?;
    let mut read = crate::program::read_options_with(machine, opts.read.inch)?;
    read.dialect = polepatch_nc::detect_dialect(original);
    let mut report = VerifyReport {
        original: original_name.to_string(),
        patched: opts.read.name.clone(),
        machine: machine.name.clone(),
        ..VerifyReport::default()
    };
    let (lines_o, lines_p) = (line_count(original), line_count(patched));
    if lines_o != lines_p {
        let line = line_added_or_deleted(original, patched);
        report.lines = lines_o;
        report.violations.push(Violation {
            line,
            check: Check::Lines,
            message: format!(
                "the programs have {lines_o} and {lines_p} lines: a line was {} at line {line} \
                 (a patch never adds or deletes one)",
                if lines_p < lines_o {
                    "deleted"
                } else {
                    "added"
                }
            ),
        });
        return Ok(report);
    }
    report.lines = lines_o;
    if original == patched {
        return Ok(report);
    }
    loop {
        let mut cmp = Comparison::new(original, patched, machine, opts, letters, claims);
        let settled = lockstep(original, patched, &read, &mut cmp, &opts.read.name)?;
        match settled {
            Settled::Done(_) => {
                cmp.finish();
                let mut r = cmp.report;
                r.original = report.original;
                r.patched = report.patched;
                r.machine = report.machine;
                r.lines = report.lines;
                r.violations.sort_by_key(|v| v.line);
                return Ok(r);
            }
            Settled::Again(settled) => read = settled,
        }
    }
}

/// Line endings in `bytes` as the reader counts them (CR LF, LF, or a CR alone).
pub(crate) fn lines_in(bytes: &[u8]) -> usize {
    let mut n = 0;
    let mut k = 0;
    while k < bytes.len() {
        match bytes[k] {
            b'\n' => n += 1,
            b'\r' if bytes.get(k + 1) != Some(&b'\n') => n += 1,
            _ => {}
        }
        k += 1;
    }
    n
}

/// Lines as the reader counts them: CR LF, LF, or a CR alone ends one; a last line without
/// an ending counts.
fn line_count(bytes: &[u8]) -> usize {
    lines_in(bytes) + usize::from(!bytes.is_empty() && !matches!(bytes.last(), Some(b'\n' | b'\r')))
}

/// Two lines that may be the same line of a program and its patch: the same text but for
/// numbers, and the X Y Z numbers within [`LINE_MATCH_MM`] (a patch moves a tip that far at
/// most for the tools it keeps; a line of a pass 0.5 mm on is another line).
fn same_line(a: &str, b: &str) -> bool {
    // An axis word: a letter of X Y Z A B C and a number (`X0.5`, `X+0.5`, `C=12`).
    let axis = |w: &str| -> Option<(char, f64)> {
        let mut c = w.chars();
        let l = c.next()?.to_ascii_uppercase();
        let v = c.as_str().trim_start_matches('=').parse::<f64>().ok()?;
        "XYZABC".contains(l).then_some((l, v))
    };
    let split = |l: &str| -> (Vec<String>, Vec<(char, f64)>) {
        let (mut text, mut words) = (Vec::new(), Vec::new());
        for w in l.split_whitespace() {
            match axis(w) {
                Some(aw) => words.push(aw),
                None => text.push(w.to_string()),
            }
        }
        (text, words)
    };
    let ((ta, wa), (tb, wb)) = (split(a), split(b));
    ta == tb
        && wa.iter().all(|&(l, x)| {
            !"XYZ".contains(l)
                || wb
                    .iter()
                    .find(|&&(m, _)| m == l)
                    .is_none_or(|&(_, y)| (x - y).abs() <= LINE_MATCH_MM)
        })
}

/// The 1-based line of `original` where `patched`, which has a different number of lines,
/// lost or gained one: the first line from which the programs pair better shifted by one.
fn line_added_or_deleted(original: &[u8], patched: &[u8]) -> usize {
    let (o, p): (Vec<String>, Vec<String>) = (
        String::from_utf8_lossy(original)
            .lines()
            .map(String::from)
            .collect(),
        String::from_utf8_lossy(patched)
            .lines()
            .map(String::from)
            .collect(),
    );
    (0..o.len().min(p.len()))
        .find(|&i| !same_line(&o[i], &p[i]))
        .unwrap_or(o.len().min(p.len()))
        + 1
}

/// One block of the patched program, as its reader hands it over.
struct Rec {
    block: Block,
    words: Vec<Word>,
    state: Modal,
}

/// Read both programs at once: the patched one on a thread of its own, its blocks handed
/// to `cmp` beside the original's. Ends as the original's read ends ([`Settled`]).
fn lockstep(
    original: &[u8],
    patched: &[u8],
    read: &ReadOptions,
    cmp: &mut Comparison<'_>,
    patched_name: &str,
) -> Result<Settled, Error> {
    let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<Rec>>(4);
    std::thread::scope(|scope| {
        let reader = scope.spawn(move || {
            let mut batch = Vec::with_capacity(BATCH_BLOCKS);
            let r = scan_blocks_with(patched, read, |s: Scanned<'_>| {
                batch.push(Rec {
                    block: s.block.clone(),
                    words: s.words.to_vec(),
                    state: *s.state,
                });
                if batch.len() == BATCH_BLOCKS {
                    let full = std::mem::replace(&mut batch, Vec::with_capacity(BATCH_BLOCKS));
                    if tx.send(full).is_err() {
                        return ControlFlow::Break(());
                    }
                }
                ControlFlow::Continue(())
            });
            if !batch.is_empty() {
                let _ = tx.send(batch);
            }
            r
        });
        let mut inbox: VecDeque<Rec> = VecDeque::new();
        let mut ended = false;
        let settled = scan_blocks_with(original, read, |s: Scanned<'_>| {
            if inbox.is_empty() && !ended {
                match rx.recv() {
                    Ok(batch) => inbox.extend(batch),
                    Err(_) => ended = true,
                }
            }
            match inbox.pop_front() {
                Some(p) => {
                    cmp.block(&s, &p);
                    ControlFlow::Continue(())
                }
                None => {
                    cmp.report.violations.push(Violation {
                        line: s.block.line,
                        check: Check::Lines,
                        message: "the patched program ends here (a line was deleted)".into(),
                    });
                    ControlFlow::Break(())
                }
            }
        });
        drop(rx);
        let theirs = reader
            .join()
            .unwrap_or_else(|_| Err(polepatch_nc::ParseError::at(0, 0, "the reader stopped")));
        let _settled = theirs.map_err(|e| Error::Parse(e.with_path(patched_name)))?;
        settled.map_err(|e| Error::Parse(e.with_path(&cmp.report.original)))
    })
}

/// The tool and the point X Y Z state at a block, and what bounds its orientation change.
struct BlockTool {
    tool: RunTool,
    /// Largest orientation change allowed here, degrees (before the rounding's room).
    bound_deg: f64,
}

/// A distance held against its tolerance once the files' precision is known.
struct Pending {
    line: usize,
    check: Check,
    /// The distance (mm) or angle (degrees).
    amount: f64,
    /// The tolerance before rounding.
    base: f64,
    rounding: Rounding,
    /// What, for people (the tolerance is added).
    message: String,
}

/// What the rounding of the written words adds to a [`Pending`] tolerance.
#[derive(Clone, Copy)]
enum Rounding {
    /// A point: the half units of the X Y Z words whose value the patched block changed
    /// (`rewritten`; an axis written as it was has no rounding to allow: a word restated
    /// with its own value, or carried, is exact), in inch times 25.4, and a ball's centre
    /// (radius `radius_mm`, 0 for a point on the axis) turned by the rotary words'.
    Linear {
        inch: bool,
        radius_mm: f64,
        rewritten: [bool; 3],
    },
    /// An angle: the rotary words' half units, degrees.
    Rotary,
}

/// The comparison in progress.
struct Comparison<'a> {
    original: &'a [u8],
    patched: &'a [u8],
    machine: &'a Machine,
    opts: &'a crate::options::PatchOptions,
    letters: RotaryLetters,
    claims: &'a [Claim],
    report: VerifyReport,
    /// The program's tool ([`crate::tool::Tracker`]), fed the original's blocks.
    tracker: crate::tool::Tracker,
    dialect: Dialect,
    /// Block index.
    i: usize,
    /// States before the block.
    prev_o: Modal,
    prev_p: Modal,
    /// The most decimals a word of X Y Z, P, C has in the patched program: its precision,
    /// which the rounding tolerances use once the whole file is read ([`Pending`]). Only the
    /// written side rounds: the original's values are what the tool path is, as written.
    dec_p: [usize; 5],
    /// Distances to hold against a tolerance that depends on the files' precision.
    pending: Vec<Pending>,
    /// A tool change, the program's end or a rotary-only repositioning came since the two
    /// programs last had the same positions: the blocks the end-pose rules take to free a
    /// run's end ([`crate::end_pose`]: the change cycle takes the tool away; a repositioning
    /// of both rotary axes and nothing else turns the table where the program itself turns
    /// it, with the tool where the program put it). A move the same in both programs that
    /// differs only by where the run before left the axes is then the same move, from a
    /// pose the patch chose.
    since_tool_change: bool,
    /// The highest part-frame Z a retract of the original (a move under TCPM that raises
    /// only Z) reached since it last cut (a feed move in X or Y), mm: the clearance of
    /// check 3.
    clearance_mm: Option<f64>,
    /// The work offset: the program's stated datum shifts and other frame changes.
    datum_shifts: Vec<(usize, [f64; 3])>,
    frame_changes: Vec<usize>,
    runs_o: RunBuilder,
    runs_p: RunBuilder,
    queue_o: VecDeque<Run>,
    queue_p: VecDeque<Run>,
    /// Line of each block (for runs' messages), while a run may use it.
    lines: VecDeque<(usize, usize)>,
}

/// The index in the 5-array `[X, Y, Z, P, C]` of a word's letter for `letters`.
fn slot(letter: u8, letters: RotaryLetters) -> Option<usize> {
    match letter {
        b'X' => Some(0),
        b'Y' => Some(1),
        b'Z' => Some(2),
        l if l == letters.tilt => Some(3),
        l if l == letters.pole => Some(4),
        _ => None,
    }
}

/// Decimal places of a word's number as written.
fn decimals(bytes: &[u8], w: &Word) -> usize {
    let text = &bytes[w.value_span()];
    text.iter().position(|&b| b == b'.').map_or(0, |dot| {
        text[dot + 1..]
            .iter()
            .take_while(|b| b.is_ascii_digit())
            .count()
    })
}

/// Half a unit of the last decimal of `decimals` places.
fn half_unit(decimals: usize) -> f64 {
    0.5 * 10f64.powi(-(decimals.min(15) as i32))
}

impl<'a> Comparison<'a> {
    fn new(
        original: &'a [u8],
        patched: &'a [u8],
        machine: &'a Machine,
        opts: &'a crate::options::PatchOptions,
        letters: RotaryLetters,
        claims: &'a [Claim],
    ) -> Self {
        let initial = crate::program::read_options_with(machine, opts.read.inch)
            .map(|r| r.initial())
            .unwrap_or_default();
        Comparison {
            original,
            patched,
            machine,
            opts,
            letters,
            claims,
            report: VerifyReport::default(),
            tracker: crate::tool::Tracker::default(),
            dialect: polepatch_nc::detect_dialect(original),
            i: 0,
            prev_o: initial,
            prev_p: initial,
            dec_p: [0; 5],
            pending: Vec::new(),
            since_tool_change: false,
            clearance_mm: None,
            datum_shifts: Vec::new(),
            frame_changes: Vec::new(),
            runs_o: RunBuilder::passes(),
            runs_p: RunBuilder::passes(),
            queue_o: VecDeque::new(),
            queue_p: VecDeque::new(),
            lines: VecDeque::new(),
        }
    }

    fn violation(&mut self, line: usize, check: Check, message: String) {
        self.report.violations.push(Violation {
            line,
            check,
            message,
        });
    }

    /// One pair of blocks.
    fn block(&mut self, o: &Scanned<'_>, p: &Rec) {
        let i = self.i;
        let line = o.block.line;
        if let Some(d) = o.stated_datum {
            self.datum_shifts.push((i, d));
        }
        if o.frame_changed {
            self.frame_changes.push(i);
        }
        let text_o = &self.original[o.block.span()];
        let text_p = &self.patched[p.block.span()];
        let same_text = text_o == text_p;
        if !same_text {
            self.report.lines_changed += 1;
            self.text(line, o, p);
        }
        self.state(line, o.state, &p.state);
        self.decimals(&p.words);
        let repositioning = same_text && self.rotary_repositioning(o, p);
        if o.block.is_move && p.block.is_move && o.state.pos != p.state.pos {
            self.report.moves_changed += 1;
            if !((self.since_tool_change || repositioning) && same_text) {
                self.move_values(i, line, o, p);
            }
        }
        if o.state.pos == p.state.pos {
            self.since_tool_change = false;
        } else if o.block.flags.has(Flags::TOOL_CHANGE)
            || o.block.flags.has(Flags::PROGRAM_END)
            || repositioning
        {
            self.since_tool_change = true;
        }
        if o.block.is_move && (self.prev_o.pos != self.prev_p.pos || o.state.pos != p.state.pos) {
            self.positioning(line, o.block, o.state, &p.state);
        }
        if o.block.is_move {
            self.clearance(o.state);
        }
        // The runs of both programs, paired as they end.
        self.lines.push_back((i, line));
        let (queue_o, queue_p) = (&mut self.queue_o, &mut self.queue_p);
        self.runs_o
            .push(i, o.block, o.state, &mut |r| queue_o.push_back(r));
        self.runs_p
            .push(i, &p.block, &p.state, &mut |r| queue_p.push_back(r));
        self.pair_runs();
        // After the runs this block ends: a tool change is the next run's.
        self.tracker
            .block(self.dialect, o.block, text_o, o.words, o.state);
        self.prev_o = *o.state;
        self.prev_p = p.state;
        self.i += 1;
    }

    /// Check 1: a line that differs differs only in the words a patch may change.
    fn text(&mut self, line: usize, o: &Scanned<'_>, p: &Rec) {
        if !(o.block.is_move && p.block.is_move) {
            self.violation(
                line,
                Check::Text,
                "the line changed, but it is not a move (only the axis words of moves may \
                 change)"
                    .into(),
            );
            return;
        }
        let letters = self.letters;
        let skeleton = |bytes: &[u8], span: std::ops::Range<usize>, words: &[Word]| {
            let mut keep = vec![true; span.len()];
            for w in words.iter().filter(|w| slot(w.letter, letters).is_some()) {
                for k in w.span() {
                    if let Some(x) = k.checked_sub(span.start).and_then(|k| keep.get_mut(k)) {
                        *x = false;
                    }
                }
            }
            bytes[span]
                .iter()
                .zip(keep)
                .filter(|(b, k)| *k && !matches!(b, b' ' | b'\t'))
                .map(|(b, _)| *b)
                .collect::<Vec<u8>>()
        };
        let a = skeleton(self.original, o.block.span(), o.words);
        let b = skeleton(self.patched, p.block.span(), &p.words);
        if a != b {
            self.violation(
                line,
                Check::Text,
                format!(
                    "the line changed outside its X Y Z, {} and {} words: `{}` became `{}`",
                    self.letters.tilt as char,
                    self.letters.pole as char,
                    String::from_utf8_lossy(&self.original[o.block.span()]).trim(),
                    String::from_utf8_lossy(&self.patched[p.block.span()]).trim()
                ),
            );
        }
    }

    /// Check 1: the modal state after the line, but for the positions.
    fn state(&mut self, line: usize, o: &Modal, p: &Modal) {
        let mut differ = Vec::new();
        if o.motion != p.motion {
            differ.push(format!("motion {:?} → {:?}", o.motion, p.motion));
        }
        if o.feed_mm_min != p.feed_mm_min || o.inverse_time_per_min != p.inverse_time_per_min {
            let f = |m: &Modal| {
                m.feed_mm_min
                    .or(m.inverse_time_per_min)
                    .map_or("none".to_string(), |v| format!("{v}"))
            };
            differ.push(format!("feed {} → {}", f(o), f(p)));
        }
        if o.feed_mode != p.feed_mode {
            differ.push(format!("feed mode {:?} → {:?}", o.feed_mode, p.feed_mode));
        }
        if o.tcpm != p.tcpm || o.tcpm_centre != p.tcpm_centre {
            differ.push(format!("TCPM {:?} → {:?}", o.tcpm, p.tcpm));
        }
        if o.inch != p.inch {
            differ.push("units".into());
        }
        if o.incremental != p.incremental {
            differ.push("incremental mode".into());
        }
        if o.transform != p.transform {
            differ.push("frame transformation".into());
        }
        if o.canned_cycle != p.canned_cycle {
            differ.push("canned cycle".into());
        }
        let other = modal::axis_index(self.letters.other()).unwrap_or(modal::B);
        if o.pos[other] != p.pos[other] {
            differ.push(format!(
                "{} (not an axis of the patch)",
                self.letters.other() as char
            ));
        }
        for k in 0..6 {
            if o.pos[k].is_some() != p.pos[k].is_some() {
                differ.push(format!("whether {} is known", modal::AXES[k] as char));
            }
        }
        if !differ.is_empty() {
            self.violation(
                line,
                Check::State,
                format!("the state after the line differs: {}", differ.join(", ")),
            );
        }
    }

    /// The most decimals of X Y Z, P, C words in the patched program so far.
    fn decimals(&mut self, p: &[Word]) {
        for w in p {
            if let Some(k) = slot(w.letter, self.letters) {
                self.dec_p[k] = self.dec_p[k].max(decimals(self.patched, w));
            }
        }
    }

    /// `[X, Y, Z, P, C]` of a state, where all are known.
    fn values(&self, st: &Modal) -> Option<[f64; 5]> {
        Some([
            st.pos[modal::X]?,
            st.pos[modal::Y]?,
            st.pos[modal::Z]?,
            st.pos[self.letters.tilt_index()].unwrap_or(0.0),
            st.pos[self.letters.pole_index()].unwrap_or(0.0),
        ])
    }

    /// The tool at a block in state `st` and the bound on its orientation change.
    fn block_tool(&self, st: &Modal) -> BlockTool {
        let tool = crate::tool::for_run(
            &self.opts.tool,
            &self.tracker.found(),
            self.machine,
            st.tcpm.is_on(),
            st.tcpm_centre,
        );
        let mut bound_deg = self.opts.patch.reach_deg();
        if let Some(cap) = self.opts.patch.max_deviation_deg {
            bound_deg = bound_deg.min(cap);
        }
        if let ToolDemand::Cap { reach_mm } = tool.demand() {
            bound_deg = bound_deg.min(crate::tool::cap_for_reach_deg(
                reach_mm,
                self.opts.tool.surface_tolerance_mm,
            ));
        }
        BlockTool { tool, bound_deg }
    }

    /// Why values may not change at a move in state `st` (block `b`), if they may not.
    fn untouchable(&self, b: &Block, st: &Modal, i: usize) -> Option<&'static str> {
        if b.flags.has(Flags::ARC) || matches!(st.motion, Motion::ArcCw | Motion::ArcCcw) {
            Some("an arc")
        } else if b.flags.has(Flags::NOT_ANALYSABLE) {
            Some("a move with expressions or variables")
        } else if st.canned_cycle {
            Some("a canned cycle")
        } else if st.incremental || b.flags.has(Flags::INCREMENTAL_WORDS) {
            Some("incremental mode")
        } else if st.transform != 0 {
            Some("a rotation, scaling or mirror image of the frame")
        } else {
            match st.tcpm {
                Tcpm::On => None,
                Tcpm::Unknown => Some("TCPM not settled by the file"),
                Tcpm::Uncertain => Some("TCPM switched by a skippable block"),
                Tcpm::Off if st.inch => Some("no TCPM, in inch"),
                Tcpm::Off if self.chain_datum(i).is_none() => {
                    Some("no TCPM, and no kinematic chain with a known work offset")
                }
                Tcpm::Off => None,
            }
        }
    }

    /// The machine's chain and the work offset at block `i`, when both are known.
    fn chain_datum(&self, i: usize) -> Option<(&'a polepatch_kinematics::Chain, [f64; 3])> {
        let chain = self.machine.chain.as_ref()?;
        let d = crate::machine_frame::datum_at(
            &self.datum_shifts,
            &self.frame_changes,
            i,
            self.opts.read.work_offset_mm,
        )?;
        Some((chain, d))
    }

    /// The tool's reference point of values `q` in state `st` at block `i`, mm, in the
    /// part frame.
    fn reference(&self, q: [f64; 5], st: &Modal, i: usize, tool: &RunTool) -> Option<[f64; 3]> {
        let xyz = [q[0], q[1], q[2]];
        let tip = if st.tcpm.is_on() {
            xyz
        } else {
            let (chain, d) = self.chain_datum(i)?;
            chain.part_tip(self.machine, d, q[3], q[4], xyz)
        };
        Some(match tool.demand() {
            ToolDemand::KeepCentre { offset_mm } => {
                along(tip, forward(self.machine, q[3], q[4]), offset_mm)
            }
            _ => tip,
        })
    }

    /// How far rounding moves a reference point on one side, mm: the half units of the
    /// X Y Z words the patch rewrote (`rewritten`), and a ball's centre turned by the
    /// rotary words' half units. (An integer-valued program's half unit is 0.5 mm: allowed
    /// on every axis, a point could move 0.87 mm unseen.)
    fn rounding_mm(
        &self,
        dec: &[usize; 5],
        inch: bool,
        radius_mm: f64,
        rewritten: [bool; 3],
    ) -> f64 {
        let unit = if inch { 25.4 } else { 1.0 };
        let xyz = (0..3)
            .filter(|&k| rewritten[k])
            .map(|k| (half_unit(dec[k]) * unit).powi(2))
            .sum::<f64>()
            .sqrt();
        xyz + radius_mm * (half_unit(dec[3]) + half_unit(dec[4])).to_radians()
    }

    /// A move without TCPM that differs only by where the previous blocks left the axes and
    /// programs Z alone, on a table-table machine: the spindle moves along machine Z, which
    /// is the tool axis in either pose. It is the same move in both programs when it rises
    /// (Z known before and after, higher after) or goes to a machine position (a reference
    /// or machine-coordinate move, `G53`, `SUPA`, `G28`: Z unknown after, in both) — the
    /// retracts the end-pose rules count as independent of the pose ([`crate::end_pose`];
    /// a machine position is taken to be above the part, as tool-change and home positions
    /// are). The block itself is the same; what it starts from is checked where that was
    /// written.
    fn retract_from_either_pose(&self, o: &Scanned<'_>, p: &Rec) -> bool {
        if o.state.tcpm.is_on()
            || self.machine.layout() != polepatch_kinematics::Layout::TableTable
            || self.original[o.block.span()] != self.patched[p.block.span()]
        {
            return false;
        }
        let axis_words: Vec<u8> = o
            .words
            .iter()
            .map(|w| w.letter)
            .filter(|l| modal::axis_index(*l).is_some())
            .collect();
        if axis_words != [b'Z'] {
            return false;
        }
        let rises_or_leaves =
            |prev: &Modal, cur: &Modal| match (prev.pos[modal::Z], cur.pos[modal::Z]) {
                (Some(a), Some(b)) => b > a,
                (_, None) => true,
                (None, Some(_)) => false,
            };
        rises_or_leaves(&self.prev_o, o.state) && rises_or_leaves(&self.prev_p, &p.state)
    }

    /// A move that programs both rotary axes and no linear one, to the same values in both
    /// programs (the end-pose rules' rotary-only repositioning: it frees a run's end).
    fn rotary_repositioning(&self, o: &Scanned<'_>, p: &Rec) -> bool {
        let letters: Vec<u8> = o.words.iter().map(|w| w.letter).collect();
        let has = |l: u8| letters.contains(&l);
        o.block.is_move
            && has(self.letters.tilt)
            && has(self.letters.pole)
            && !(has(b'X') || has(b'Y') || has(b'Z'))
            && o.state.pos[self.letters.tilt_index()] == p.state.pos[self.letters.tilt_index()]
            && o.state.pos[self.letters.pole_index()] == p.state.pos[self.letters.pole_index()]
    }

    /// Checks 2–4 at a move whose values differ.
    fn move_values(&mut self, i: usize, line: usize, o: &Scanned<'_>, p: &Rec) {
        if self.retract_from_either_pose(o, p) {
            return;
        }
        if let Some(why) = self.untouchable(o.block, o.state, i) {
            self.violation(
                line,
                Check::Untouchable,
                format!("the move's values changed, but nothing may change here ({why})"),
            );
            return;
        }
        let (Some(qo), Some(qp)) = (self.values(o.state), self.values(&p.state)) else {
            return;
        };
        let bt = self.block_tool(o.state);
        // 4: the orientation change.
        let dev = angle_between_deg(
            forward(self.machine, qo[3], qo[4]),
            forward(self.machine, qp[3], qp[4]),
        );
        self.report.max_deviation_deg = self.report.max_deviation_deg.max(dev);
        self.pending.push(Pending {
            line,
            check: Check::Deviation,
            amount: dev,
            base: bt.bound_deg,
            rounding: Rounding::Rotary,
            message: format!(
                "the tool axis turns {dev:.4}°, more than the {:.4}° allowed here ({})",
                bt.bound_deg,
                match bt.tool.tool {
                    Some(t) if t.kind != ToolKind::Ball => format!(
                        "the {} cutter's surface tolerance, the pole reach or --max-deviation",
                        t.describe()
                    ),
                    _ => "the pole reach or --max-deviation".to_string(),
                }
            ),
        });
        let rotary_changed = qo[3] != qp[3] || qo[4] != qp[4];
        if o.state.motion == Motion::Rapid {
            // 3: a positioning move keeps its target, and turns only under TCPM.
            if rotary_changed && !o.state.tcpm.is_on() {
                self.violation(
                    line,
                    Check::PositioningTarget,
                    "a positioning move without TCPM changed its rotary values: X Y Z are \
                     machine coordinates, so the part turns under the tool"
                        .into(),
                );
            }
            let d = norm_direct(sub([qo[0], qo[1], qo[2]], [qp[0], qp[1], qp[2]]));
            self.pending.push(Pending {
                line,
                check: Check::PositioningTarget,
                amount: d,
                base: REFERENCE_TOL_MM,
                rounding: Rounding::Linear {
                    inch: o.state.inch,
                    radius_mm: 0.0,
                    rewritten: std::array::from_fn(|k| qo[k] != qp[k]),
                },
                message: format!(
                    "the positioning move's target X{:.4} Y{:.4} Z{:.4} became X{:.4} Y{:.4} \
                     Z{:.4} (mm): {d:.4} mm away (a positioning move may only restate rotary \
                     values)",
                    qo[0], qo[1], qo[2], qp[0], qp[1], qp[2]
                ),
            });
            return;
        }
        // 2: the tool's reference point.
        let (Some(ro), Some(rp)) = (
            self.reference(qo, o.state, i, &bt.tool),
            self.reference(qp, &p.state, i, &bt.tool),
        ) else {
            return;
        };
        let radius = match bt.tool.demand() {
            ToolDemand::KeepCentre { offset_mm } => offset_mm,
            _ => 0.0,
        };
        let d = norm_direct(sub(ro, rp));
        self.report.max_reference_shift_mm = self.report.max_reference_shift_mm.max(d);
        let what = match bt.tool.tool {
            Some(t) if radius > 0.0 => format!("the {}'s centre (tip + R·o)", t.describe()),
            _ if bt.tool.point == ToolPoint::Centre => "the ball's centre".to_string(),
            _ => "the point X Y Z state".to_string(),
        };
        self.pending.push(Pending {
            line,
            check: Check::ReferencePoint,
            amount: d,
            base: REFERENCE_TOL_MM,
            rounding: Rounding::Linear {
                inch: o.state.inch,
                radius_mm: radius,
                rewritten: std::array::from_fn(|k| qo[k] != qp[k]),
            },
            message: format!(
                "{what} moved {d:.4} mm: ({:.4}, {:.4}, {:.4}) became ({:.4}, {:.4}, {:.4}){}",
                ro[0],
                ro[1],
                ro[2],
                rp[0],
                rp[1],
                rp[2],
                if o.state.tcpm.is_on() {
                    ""
                } else {
                    " in the part frame, through the kinematic chain"
                }
            ),
        });
    }

    /// Check 6: a move outside the runs (a positioning move, a rotary-only G1) whose start
    /// or target differ, timed on both sides.
    fn positioning(&mut self, line: usize, b: &Block, o: &Modal, p: &Modal) {
        let rapid = o.motion == Motion::Rapid;
        let tip_still = matches!(
            (self.values(&self.prev_o), self.values(o)),
            (Some(a), Some(c)) if a[..3] == c[..3]
        );
        if !(rapid || (o.motion == Motion::Linear && tip_still)) || b.flags.has(Flags::ARC) {
            return;
        }
        let (Some(a0), Some(a1), Some(b0), Some(b1)) = (
            self.values(&self.prev_o),
            self.values(o),
            self.values(&self.prev_p),
            self.values(p),
        ) else {
            return;
        };
        self.report.positioning_moves_compared += 1;
        self.report.time_before_s += crate::end_pose::positioning_time_s(self.machine, a0, a1);
        self.report.time_after_s += crate::end_pose::positioning_time_s(self.machine, b0, b1);
        // 3: a positioning move that turns the rotary axes from or to other values than
        // the original's turns the table under the tool on another way: under TCPM the tool
        // tip stays on the programmed line, so that is safe only above the clearance the
        // program retracted to (crate::end_pose's proof), with the tip there at both ends.
        // A tool change or the program's own rotary-only repositioning took the tool away
        // (check 2's exemption).
        let turns = |x: [f64; 5], y: [f64; 5]| x[3] != y[3] || x[4] != y[4];
        let other_way = (turns(a0, a1) || turns(b0, b1)) && (turns(a0, b0) || turns(a1, b1));
        if rapid && other_way && !self.since_tool_change {
            let low = a0[2].min(a1[2]);
            let fine = o.tcpm.is_on()
                && p.tcpm.is_on()
                && self
                    .clearance_mm
                    .is_some_and(|c| low >= c - REFERENCE_TOL_MM);
            if !fine {
                self.violation(
                    line,
                    Check::PositioningTarget,
                    format!(
                        "the positioning move turns the rotary axes another way than the                          original's (from P{:.4} C{:.4} to P{:.4} C{:.4}; the original: from                          P{:.4} C{:.4} to P{:.4} C{:.4}) {}",
                        b0[3],
                        b0[4],
                        b1[3],
                        b1[4],
                        a0[3],
                        a0[4],
                        a1[3],
                        a1[4],
                        match self.clearance_mm {
                            _ if !(o.tcpm.is_on() && p.tcpm.is_on()) => {
                                "without TCPM: the part turns under the tool".to_string()
                            }
                            Some(c) => format!(
                                "with the tool tip at Z{low:.4}, below the clearance Z{c:.4}                                  the program retracted to"
                            ),
                            None => "before the program retracted the tool".to_string(),
                        }
                    ),
                );
            }
        }
    }

    /// The clearance after a move of the original in state `o` (check 3): a move under
    /// TCPM that raises only Z sets it; a feed move in X or Y (cutting) clears it.
    fn clearance(&mut self, o: &Modal) {
        let (Some(a), Some(b)) = (self.values(&self.prev_o), self.values(o)) else {
            self.clearance_mm = None;
            return;
        };
        let z_only = a[0] == b[0] && a[1] == b[1] && a[3] == b[3] && a[4] == b[4];
        if o.tcpm.is_on() && z_only && b[2] > a[2] {
            self.clearance_mm = Some(self.clearance_mm.map_or(b[2], |c| c.max(b[2])));
        } else if o.motion != Motion::Rapid && (a[0] != b[0] || a[1] != b[1]) {
            self.clearance_mm = None;
        }
    }

    /// Pair the runs both programs have ended so far.
    fn pair_runs(&mut self) {
        while let (Some(ro), Some(rp)) = (self.queue_o.front(), self.queue_p.front()) {
            if ro.blocks != rp.blocks {
                // One program's run has no partner: report at the earlier one, drop it.
                let (first_o, first_p) = (ro.blocks[0], rp.blocks[0]);
                let line = self.line_of(first_o.min(first_p));
                self.violation(
                    line,
                    Check::RunStructure,
                    format!(
                        "the runs differ from here: a run over lines {}–{} in the original, \
                         {}–{} in the patched program (a block's motion or feed changed)",
                        self.line_of(first_o),
                        self.line_of(*ro.blocks.last().unwrap_or(&first_o)),
                        self.line_of(first_p),
                        self.line_of(*rp.blocks.last().unwrap_or(&first_p)),
                    ),
                );
                if first_o <= first_p {
                    self.queue_o.pop_front();
                } else {
                    self.queue_p.pop_front();
                }
                continue;
            }
            let (Some(ro), Some(rp)) = (self.queue_o.pop_front(), self.queue_p.pop_front()) else {
                break;
            };
            if ro.pos != rp.pos {
                self.compare_runs(&ro, &rp);
            }
        }
        // Lines no run in hand can use any more.
        let keep_from = [
            self.queue_o.front().map(|r| r.blocks[0]),
            self.queue_p.front().map(|r| r.blocks[0]),
            self.runs_o.open_run_first_block(),
            self.runs_p.open_run_first_block(),
        ]
        .into_iter()
        .flatten()
        .min()
        .unwrap_or(self.i.saturating_sub(1));
        while self.lines.front().is_some_and(|&(b, _)| b < keep_from) {
            self.lines.pop_front();
        }
    }

    /// The file line of block `b` (one still in hand).
    fn line_of(&self, b: usize) -> usize {
        self.lines
            .iter()
            .find(|&&(k, _)| k == b)
            .map_or(0, |&(_, l)| l)
    }

    /// Check 5: a run whose points differ, on both sides.
    fn compare_runs(&mut self, ro: &Run, rp: &Run) {
        let first_line = self.line_of(ro.blocks[0]);
        let lines: Vec<usize> = ro.blocks.iter().map(|&b| self.line_of(b)).collect();
        let fallback = self.opts.read.feed_fallback_mm_min;
        let path_o = crate::program::run_path(ro.clone(), self.letters, fallback, first_line).path;
        let path_p = crate::program::run_path(rp.clone(), self.letters, fallback, first_line).path;
        let (po, pp) = match (path_o, path_p) {
            (Ok(a), Ok(b)) => (a, b),
            (Err(_), Err(_)) => return,
            (Ok(_), Err(e)) => {
                self.violation(
                    first_line,
                    Check::RunStructure,
                    format!("the run can no longer be analysed: {e}"),
                );
                return;
            }
            (Err(_), Ok(_)) => return,
        };
        let opts = AnalysisOptions {
            cone_deg: self.opts.patch.cone_deg,
            pole_reach_deg: self.opts.patch.pole_reach_deg,
            ..AnalysisOptions::default()
        };
        let (Some((ao, so)), Some((ap, sp))) = (
            spans(&po, self.machine, &opts),
            spans(&pp, self.machine, &opts),
        ) else {
            self.violation(
                first_line,
                Check::RunStructure,
                "the run's points cannot be analysed in one of the programs (repeated or \
                 invalid values)"
                    .into(),
            );
            return;
        };
        self.report.runs_compared += 1;
        self.report.time_before_s += ao.time_s;
        self.report.time_after_s += ap.time_s;
        let names = [
            "X".to_string(),
            "Y".to_string(),
            "Z".to_string(),
            (self.letters.tilt as char).to_string(),
            (self.letters.pole as char).to_string(),
        ];
        // Equation 6 span by span, and the run's worst place.
        if let Some(w) = slower(&so, &sp) {
            let (l0, l1) = (lines[w.span], lines[w.span + 1]);
            self.violation(
                l1,
                Check::FeedRatio,
                format!(
                    "between lines {l0} and {l1} {} (on the written values; run over lines \
                     {}–{})",
                    w.describe([&names[0], &names[1], &names[2], &names[3], &names[4]]),
                    lines[0],
                    lines[lines.len() - 1]
                ),
            );
        }
        let tol = ao.time_s * TIME_TOL_REL + ao.time_error_s + ap.time_error_s;
        if ap.time_s > ao.time_s + tol {
            self.violation(
                lines[0],
                Check::RunTime,
                format!(
                    "the run over lines {}–{} takes {:.4} s by Equation 6, the original {:.4} s",
                    lines[0],
                    lines[lines.len() - 1],
                    ap.time_s,
                    ao.time_s
                ),
            );
        }
        // 7: the zones the report calls reached, over their lines.
        for c in self.claims {
            let inside: Vec<usize> = (0..sp.len())
                .filter(|&k| lines[k] >= c.lines[0] && lines[k + 1] <= c.lines[1])
                .collect();
            if inside.is_empty() {
                continue;
            }
            let axes: &[usize] = if c.both_axes { &[3, 4] } else { &[4] };
            for &ax in axes {
                if let Some(&k) = inside
                    .iter()
                    .find(|&&k| sp[k].axis_ratio[ax] < 1.0 - REACHED_TOL)
                {
                    self.violation(
                        lines[k + 1],
                        Check::ReportedReached,
                        format!(
                            "the zone over lines {}–{} is reported reached, but {} reaches {:.4} \
                             of the feed between lines {} and {} of the written program",
                            c.lines[0],
                            c.lines[1],
                            names[ax],
                            sp[k].axis_ratio[ax],
                            lines[k],
                            lines[k + 1]
                        ),
                    );
                    break;
                }
            }
        }
    }

    /// The runs still open, the distances held against the files' precision, and the
    /// program's time.
    fn finish(&mut self) {
        for p in std::mem::take(&mut self.pending) {
            let room = match p.rounding {
                Rounding::Linear {
                    inch,
                    radius_mm,
                    rewritten,
                } => self.rounding_mm(&self.dec_p, inch, radius_mm, rewritten),
                Rounding::Rotary => half_unit(self.dec_p[3]) + half_unit(self.dec_p[4]),
            };
            let tol = p.base + room;
            if p.amount > tol {
                let unit = match p.rounding {
                    Rounding::Linear { .. } => "mm",
                    Rounding::Rotary => "°",
                };
                self.violation(
                    p.line,
                    p.check,
                    format!("{} (allowed {tol:.4} {unit} with the rounding)", p.message),
                );
            }
        }
        let (queue_o, queue_p) = (&mut self.queue_o, &mut self.queue_p);
        self.runs_o.finish(&mut |r| queue_o.push_back(r));
        self.runs_p.finish(&mut |r| queue_p.push_back(r));
        self.pair_runs();
        if let Some(r) = self.queue_o.front().or(self.queue_p.front()) {
            let line = self.line_of(r.blocks[0]);
            self.violation(
                line,
                Check::RunStructure,
                "a run has no partner in the other program".into(),
            );
        }
        let (before, after) = (self.report.time_before_s, self.report.time_after_s);
        if after > before * (1.0 + TIME_TOL_REL) + 1e-9 {
            self.violation(
                0,
                Check::ProgramTime,
                format!(
                    "the program is slower: what differs takes {after:.4} s against {before:.4} s \
                     in the original (runs by Equation 6, positioning moves at the axes' velocity \
                     and acceleration)"
                ),
            );
        }
    }
}

/// Where `after` is slower than `before` by Equation 6 (the ratio of a span is the lowest
/// over the axes: the feed the machine keeps there), if anywhere: the rule of check 5, also
/// the machine-frame check of a run patched through the kinematic chain ([`crate::patch`]).
///
/// - A span where `before` reaches feed ([`REACHED_TOL`]) reaches it in `after`: a patch
///   never makes the machine slow where it did not.
/// - The run's lowest ratio is no lower than `before`'s by more than [`RATIO_TOL_REL`].
///   Below feed the spans may trade (a joint patch spreads the rotary motion over the zone;
///   an axis may slow where another limited the span more before), but the worst place
///   never gets worse — and the run's time is checked apart.
///
/// The spans pair by index.
pub fn slower(
    before: &[polepatch_patcher::quality::SpanFigures],
    after: &[polepatch_patcher::quality::SpanFigures],
) -> Option<Slower> {
    let overall = |f: &polepatch_patcher::quality::SpanFigures| {
        f.axis_ratio.iter().copied().fold(f64::INFINITY, f64::min)
    };
    let limiting = |f: &polepatch_patcher::quality::SpanFigures| {
        (0..5)
            .min_by(|&i, &j| f.axis_ratio[i].total_cmp(&f.axis_ratio[j]))
            .unwrap_or(0)
    };
    for (k, (a, b)) in before.iter().zip(after).enumerate() {
        let (ra, rb) = (overall(a), overall(b));
        if ra >= 1.0 - REACHED_TOL && rb < 1.0 - REACHED_TOL {
            return Some(Slower {
                span: k,
                axis: limiting(b),
                before: ra,
                after: rb,
                at_feed: true,
            });
        }
    }
    let lowest = |spans: &[polepatch_patcher::quality::SpanFigures]| {
        spans
            .iter()
            .enumerate()
            .map(|(k, f)| (k, overall(f)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
    };
    let ((_, ra), (k, rb)) = (lowest(before)?, lowest(after)?);
    (rb < ra.min(1.0) * (1.0 - RATIO_TOL_REL)).then(|| Slower {
        span: k,
        axis: limiting(&after[k]),
        before: ra,
        after: rb,
        at_feed: false,
    })
}

/// Where a run got slower ([`slower`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slower {
    /// The span (from point `span` to `span + 1`).
    pub span: usize,
    /// The axis that limits the written ratio there, X Y Z P C order (0…4).
    pub axis: usize,
    /// The ratio before: the span's when `at_feed`, else the run's lowest.
    pub before: f64,
    /// The ratio after at that span.
    pub after: f64,
    /// The span was at feed before (else: the run's lowest ratio got lower).
    pub at_feed: bool,
}

impl Slower {
    /// For people: `C limits it to 0.882 of the feed where it reached feed`.
    pub fn describe(&self, letters: [&str; 5]) -> String {
        if self.at_feed {
            format!(
                "Equation 6 allows {:.3} of the feed ({} limiting) where the original reaches \
                 feed",
                self.after, letters[self.axis]
            )
        } else {
            format!(
                "the run's lowest Equation-6 ratio {:.3} ({} limiting) is below the original's \
                 {:.3}",
                self.after, letters[self.axis], self.before
            )
        }
    }
}

/// Equation 6 over every span of a path.
fn spans(
    path: &Path,
    machine: &Machine,
    opts: &AnalysisOptions,
) -> Option<(
    polepatch_patcher::RunAnalysis,
    Vec<polepatch_patcher::quality::SpanFigures>,
)> {
    polepatch_patcher::quality::analyze_spans(path, machine, opts).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_counted_as_the_reader_counts_them() {
        assert_eq!(line_count(b""), 0);
        assert_eq!(line_count(b"a"), 1);
        assert_eq!(line_count(b"a\n"), 1);
        assert_eq!(line_count(b"a\r\nb"), 2);
        assert_eq!(line_count(b"a\rb\n"), 2);
        // A patched pass with a line deleted: found where the X values stop pairing.
        let o = b"G1 X0 A1 C2\nX0.5 A1.1 C3\nX1 A1.2 C4\nX1.5 A1.3 C5\n";
        let p = b"G1 X0 A1 C2\nX0.5001 A-1.1 C183\nX1.5001 A-1.3 C185\n";
        assert_eq!(line_added_or_deleted(o, p), 3);
    }

    #[test]
    fn decimals_are_read_from_the_bytes() {
        let w = |text: &[u8]| Word {
            letter: text[0],
            form: polepatch_nc::RotaryForm::Plain,
            tail: 0,
            start: 0,
            value_start: 1,
            end: text.len() as u32,
            value: 0.0,
        };
        assert_eq!(decimals(b"X1.250", &w(b"X1.250")), 3);
        assert_eq!(decimals(b"X-.5", &w(b"X-.5")), 1);
        assert_eq!(decimals(b"X10", &w(b"X10")), 0);
        assert_eq!(decimals(b"X10.", &w(b"X10.")), 0);
    }
}
