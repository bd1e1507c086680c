//! Patching a whole program: runs → patcher → edits → bytes.
//!
//! [`patch_program`] is the one pipeline: every caller (the `polepatch` binary, `bench`,
//! the criterion benches, the tests, the C ABI) goes through it, by way of
//! [`crate::patch_nc`] for bytes or [`crate::stream`] for the stretches of a file.
//!
//! # The steps
//! [`patch_program`] takes them in this order, one function each. Each run's result is
//! computed whole as a `RunOutcome` (`Patched { rows, edits }`, `Left { rows, untouched }`
//! or `Quiet`) and folded into the report once, in run order, after the last step that can
//! change it (the application of the edits, which drops the runs whose direction forms
//! conflict): the report is never written and read back.
//!
//! 1. **The file's styles** (`file_styles`): the decimals the file writes C, the primary
//!    axis and X Y Z with, and the patcher's options they set.
//! 2. **Each run**, in file order (`prepare_run`, then `finish_run`):
//!    1. a run without a path (no feed, a feed too low, an unknown or other rotary value)
//!       is reported untouched; a run with no point within the pole reach
//!       (`near_pole`) has nothing to patch or report, and its analysis is skipped;
//!    2. **a run that may not be patched** (`why_left`: the frame transformed, TCPM not
//!       settled, uncertain, or off where X Y Z cannot be recomputed, incremental mode)
//!       has its zones reported only (`report_left`; below);
//!    3. **the run's options** (`run_options`): its end pose (the last point keeps its
//!       values unless the blocks after the run free it) and its tool (a ball programmed
//!       at its tip keeps its centre, a flat or bull-nose cutter caps the orientation
//!       change: [`crate::tool`]);
//!    4. **the choices** (`RunPatch::choices`): the run patched with its end pinned, its
//!       end free, its start free where the positioning move before it goes to its first
//!       point (`linked_starts`), and on the other branch (`other_branch`) — on the
//!       part-frame path for a run without TCPM (pinned or free end only); then **the
//!       plan** (`plan_runs`, [`crate::plan`]) takes one choice per run over every run at
//!       once — every zone at feed where a choice reaches it, no positioning move slower,
//!       the largest change of orientation the smallest — with the whole turns a linked
//!       run's C is written with, and each run is finished with its choice (`finish_run`,
//!       steps 5 to 7);
//!    5. **the report rows** (`RunPatch::zone_rows`), solved again with the orientation
//!       change capped while a kept ball centre would leave its path between the points
//!       (`RunPatch::rows_within_centre_path`; a run that cannot keep it keeps its values);
//!    6. **through the kinematic chain**, where the machine has one (`through_chain`): the
//!       X Y Z edits of a run without TCPM, and the machine-frame check;
//!    7. **the edits** (`RunPatch::centre_edits`, `RunPatch::rotary_edits`): the tips of a
//!       kept ball centre, then the primary-axis and C words, each with the blocks after
//!       the run that restate its last values ([`crate::end_pose`]).
//! 3. **Modal words, direction forms and the write**, in one application of the edits
//!    ([`polepatch_nc::apply_edits`], its plan made by `edit_plan`: one group per run, the
//!    file's decimals): inside a run, a point that relied on a modal value keeps it; the
//!    edits of Sinumerik `DC`/`ACP`/`ACN` words are written in their form, or their run is
//!    dropped and keeps its values (`direction_form_left` says why); the stretch's bytes
//!    are written in the file's style.
//! 4. **The report's totals** (`finish_report`): the words changed (the edits written),
//!    the file's decimals and those written.
//!
//! # What is never patched
//! A run whose X Y Z are machine coordinates (no TCPM: M128, TRAORI, G43.4 not active) is
//! analysed and reported but left byte-identical: on a table-table machine without TCPM,
//! changing a rotary value while X Y Z stay moves the part under the tool (a gouge).
//! A run in incremental mode (G91) is left the same way: a changed value there would shift
//! every later position. Both appear in [`FileReport::untouched_runs`] when they hold a
//! singular zone.

use crate::end_pose::EndPose;
use crate::machine_frame;
use crate::program::{LoadedProgram, RunPath, RunProblem};
use crate::report::axis_letter;
use crate::report::{
    Branch, EndFreedom, FiguresRow, FileReport, UntouchedReason, UntouchedRun, ZoneReason, ZoneRow,
    ZoneTool,
};
use crate::settings::CENTRE_CHORD_SAMPLES;
use crate::settings::CENTRE_PATH_RETRIES;
use crate::tolerances::CENTRE_PATH_CAP_SAFETY;
use crate::tolerances::MIN_INCH_XYZ_DECIMALS;
use crate::tool::{RunTool, ToolDemand, ToolKind};
use polepatch_kinematics::vec3::along;
use polepatch_kinematics::{Chain, Machine};
use polepatch_nc::modal::AXES;
use polepatch_nc::{Edit, EditGroup, EditPlan, FileStyle, GroupConflict, NumberStyle, Tcpm};
use polepatch_patcher::{
    KeepCentre, Method, PatchOptions, PatchResult, Path, PathError, ZoneReport, patch_path,
    report_unpatched,
};
use std::borrow::Cow;

/// Patch a loaded program: its bytes as patched (borrowed when nothing changes) and the
/// report (the steps of the module docs).
///
/// `opts.c_decimals` and `opts.p_decimals` are taken from the file (its number style);
/// `opts.max_decimals` is raised to the file's decimals when lower.
pub fn patch_program<'p>(
    lp: &'p LoadedProgram,
    machine: &Machine,
    opts: &PatchOptions,
) -> (Cow<'p, [u8]>, FileReport) {
    // A stretch of a file: what the file says as a whole (its notes, the primary
    // letter's substitution) is the stream's to report.
    let mut report = FileReport::unchanged(&lp.name, machine, Vec::new());
    let styles = file_styles(lp, opts);
    // Step 2: each run's choices, the plan over them, each run finished with its choice.
    let linked = linked_starts(lp, &styles.opts);
    // The runs' choices are independent of each other: on all cores (a stretch of linked
    // runs is one part of the stream's batches).
    let prepared: Vec<Prepared> = {
        use rayon::prelude::*;
        (0..lp.runs.len())
            .into_par_iter()
            .map(|r| prepare_run(lp, r, machine, &styles, linked[r]))
            .collect()
    };
    let chosen = plan_runs(lp, machine, &prepared, &linked);
    let mut outcomes: Vec<RunOutcome> = prepared
        .into_iter()
        .zip(chosen)
        .enumerate()
        .map(|(r, (p, c))| finish_run(lp, r, machine, &styles, p, c))
        .collect();
    // The decimals written for the rotary words: the file's, or more where a patched run
    // needed them.
    let mut written = [styles.c.decimals, styles.p.decimals];
    for o in &outcomes {
        if let RunOutcome::Patched { decimals, .. } = o {
            written = [written[0].max(decimals[0]), written[1].max(decimals[1])];
        }
    }
    // Step 3: one application of every patched run's edits (the write included).
    let plan = edit_plan(lp, &styles, &mut outcomes);
    let applied = polepatch_nc::apply_edits(&lp.program, &plan, &styles.file);
    for dropped in applied.dropped {
        let (run, reason, message) = direction_form_left(dropped);
        outcomes[run] =
            std::mem::take(&mut outcomes[run]).left(lp, run, reason, message, opts.reach_deg());
    }
    if let Some(k) = applied.unattributed {
        report
            .warnings
            .push(format!("{}; no rotary word was changed", k.message));
    }
    // Each run's outcome, folded into the report once, in run order.
    for o in outcomes {
        match o {
            RunOutcome::Quiet => {}
            RunOutcome::Left { rows, untouched } => {
                report.zones.extend(rows);
                report.untouched_runs.push(untouched);
            }
            RunOutcome::Patched { rows, .. } => report.zones.extend(rows),
        }
    }
    finish_report(lp, &styles, written, applied.edits_written, &mut report);
    (applied.bytes, report)
}

/// What step 2 makes of one run: computed whole, then folded into the report once
/// ([`patch_program`]).
#[derive(Debug, Default)]
enum RunOutcome {
    /// Nothing to patch or report (no point within the pole reach).
    #[default]
    Quiet,
    /// The run keeps its values: its zones' rows (nothing written) and why.
    Left {
        /// The zones' rows, reported as they are.
        rows: Vec<ZoneRow>,
        /// The run among the untouched, with the reason.
        untouched: UntouchedRun,
    },
    /// The run is patched.
    Patched {
        /// The zones' rows.
        rows: Vec<ZoneRow>,
        /// The words it changes (its blocks, and the blocks after it that restate its end);
        /// taken into the plan of step 3 ([`edit_plan`]).
        edits: Vec<Edit>,
        /// Decimal places written for its changed C and primary-axis words.
        decimals: [usize; 2],
    },
}

impl RunOutcome {
    /// The run left as it is for `reason` (`message` for people): its rows, if any, are
    /// not written.
    fn left(
        self,
        lp: &LoadedProgram,
        r: usize,
        reason: UntouchedReason,
        message: String,
        reach_deg: f64,
    ) -> RunOutcome {
        let mut rows = match self {
            RunOutcome::Quiet => Vec::new(),
            RunOutcome::Left { rows, .. } | RunOutcome::Patched { rows, .. } => rows,
        };
        for row in &mut rows {
            row.not_written();
            row.reason = reason.zone_reason().unwrap_or(ZoneReason::NotPatched);
        }
        let untouched = untouched(lp, r, reason, rows.len(), message, reach_deg);
        RunOutcome::Left { rows, untouched }
    }
}

/// The file's number styles and the patcher's options they set (step 1).
struct Styles {
    /// What the whole file says of its numbers (a stretch's file).
    file: FileStyle,
    /// The style of the C words.
    c: NumberStyle,
    /// The style of the primary-axis words.
    p: NumberStyle,
    /// The caller's options with the file's decimals.
    opts: PatchOptions,
    /// Fewest decimals of X Y Z recomputed through the kinematic chain.
    xyz_decimals: usize,
    /// Decimals of X Y Z rewritten to keep a ball's centre.
    xyz_file_decimals: usize,
}

impl Styles {
    /// The style of `letter`'s words ([`style_of`]).
    fn of(&self, lp: &LoadedProgram, letter: u8) -> NumberStyle {
        style_of(&self.file, lp, letter)
    }
}

/// The style of `letter`'s words: the file's, else the stretch's.
fn style_of(file: &FileStyle, lp: &LoadedProgram, letter: u8) -> NumberStyle {
    file.letter(letter)
        .unwrap_or_else(|| NumberStyle::of(&lp.program, letter))
}

/// Step 1: the file's styles, and `opts` with the decimals they set.
fn file_styles(lp: &LoadedProgram, opts: &PatchOptions) -> Styles {
    let file = lp.file_style();
    let style = |l: u8| style_of(&file, lp, l);
    let c = style(lp.pole_letter);
    let p = style(lp.primary_letter);
    let opts = PatchOptions {
        c_decimals: c.decimals,
        p_decimals: p.decimals,
        max_decimals: opts.max_decimals.max(c.decimals).max(p.decimals),
        ..opts.clone()
    };
    let xyz_decimals = style(b'X').decimals.max(machine_frame::MIN_XYZ_DECIMALS);
    // X Y Z rewritten to keep a ball's centre are written as the file writes them, to a
    // micrometre at least (a file of round values, `X0.5 Y0 Z-5`, shows no precision).
    let xyz_file_decimals = [b'X', b'Y', b'Z']
        .map(|l| style(l).decimals)
        .into_iter()
        .max()
        .unwrap_or(0)
        .max(machine_frame::MIN_XYZ_DECIMALS);
    Styles {
        file,
        c,
        p,
        opts,
        xyz_decimals,
        xyz_file_decimals,
    }
}

/// Whether a point of `path` is within the pole reach: a zone needs one (the patcher's
/// `detect_zones`).
fn near_pole(lp: &LoadedProgram, path: &Path, opts: &PatchOptions) -> bool {
    let pi = polepatch_kinematics::Axis::Primary.index();
    path.axes
        .iter()
        .any(|q| lp.pole.near(q[pi], opts.reach_deg()))
}

/// Step 2, before the plan: run `r` done already (nothing to patch, or left as it is), or
/// open with its choices (`start_linked`: its start may be chosen, [`linked_starts`]).
enum Prepared<'a> {
    Done(RunOutcome),
    Open {
        run: Box<RunPatch<'a>>,
        frame: RunFrame<'a>,
        choices: Vec<RunChoice>,
    },
}

/// One way to patch a run (step 2.4): its end kept or free, its start kept or free, and
/// the patch.
struct RunChoice {
    keep_last_point: bool,
    start_free: bool,
    flipped: bool,
    result: Result<PatchResult, PathError>,
}

/// Step 2.1 to 2.4: what run `r` is before the plan (the sub-steps of the module docs).
fn prepare_run<'a>(
    lp: &'a LoadedProgram,
    r: usize,
    machine: &'a Machine,
    styles: &Styles,
    start_linked: bool,
) -> Prepared<'a> {
    let opts = &styles.opts;
    let rp = &lp.runs[r];
    let path = match &rp.path {
        Ok(p) => p,
        Err(problem) => {
            return Prepared::Done(RunOutcome::Quiet.left(
                lp,
                r,
                problem_reason(problem),
                problem.to_string(),
                opts.reach_deg(),
            ));
        }
    };
    // A run with no point in the cone has nothing to patch or report, and its analysis is
    // skipped.
    if !near_pole(lp, path, opts) {
        return Prepared::Done(RunOutcome::Quiet);
    }
    let frame = RunFrame::of(lp, r, machine);
    if let Some(left) = why_left(rp, &frame, machine) {
        return Prepared::Done(report_left(lp, r, path, machine, opts, left));
    }
    let run = run_options(lp, r, path, machine, styles, &frame);
    let choices = run.choices(start_linked);
    Prepared::Open {
        run: Box::new(run),
        frame,
        choices,
    }
}

/// Which runs' starts may be chosen: run `r`'s first point is where the positioning move
/// that frees run `r − 1`'s end goes ([`crate::end_pose`]: above the clearance, under
/// TCPM), that move programs both rotary axes (its words are rewritten), both runs come
/// within the pole reach and run under TCPM. Then `r` may start on the other branch, the
/// move going there instead ([`crate::plan`]).
fn linked_starts(lp: &LoadedProgram, opts: &PatchOptions) -> Vec<bool> {
    let near = |r: usize| {
        let rp = &lp.runs[r];
        rp.run.tcpm.is_on() && rp.path.as_ref().is_ok_and(|p| near_pole(lp, p, opts))
    };
    let letters = [lp.primary_letter, lp.pole_letter];
    (0..lp.runs.len())
        .map(|r| {
            let Some(prev) = r.checked_sub(1) else {
                return false;
            };
            let Some(next) = lp.end_pose(prev).next else {
                return false;
            };
            let first = lp.runs[r].run.blocks[0];
            let words = lp.program.block_words(first);
            next.line == lp.line_of(r, 0)
                && lp.program.state(first).tcpm.is_on()
                && letters.iter().all(|&l| {
                    words
                        .iter()
                        .any(|w| w.letter == l && !w.form.is_directional())
                })
                && near(prev)
                && near(r)
        })
        .collect()
}

/// The plan (step 2, [`crate::plan`]): the index of each run's choice (0 for a run done
/// already), and where the move after it goes when that is the next run's first point (as
/// the next run's choice writes it). Where no plan keeps every positioning move as fast (a
/// run whose every choice that keeps its ends failed), each run takes its first choice.
fn plan_runs(
    lp: &LoadedProgram,
    machine: &Machine,
    prepared: &[Prepared],
    linked: &[bool],
) -> Vec<(usize, f64, Option<[f64; 2]>)> {
    use crate::plan::{After, Choice, Pass};
    let pi = polepatch_kinematics::Axis::Primary.index();
    let ci = polepatch_kinematics::Axis::C.index();
    let mut passes: Vec<Pass> = Vec::with_capacity(prepared.len());
    // Per run, the index among its choices of each choice offered to the plan.
    let mut offered: Vec<Vec<usize>> = Vec::with_capacity(prepared.len());
    for (r, p) in prepared.iter().enumerate() {
        let path = lp.runs[r].path.as_ref().ok();
        let ends = path.map(|p| {
            let (a, b) = (p.axes[0], p.axes[p.axes.len() - 1]);
            ([a[pi], a[ci]], [b[pi], b[ci]])
        });
        let mut choices = Vec::new();
        let mut index = Vec::new();
        let mut input_s = 0.0;
        if let (
            Prepared::Open {
                choices: all, run, ..
            },
            Some(path),
            Some((s0, e0)),
        ) = (p, path, ends)
        {
            let input_time = run_time(run, path);
            input_s = input_time.map_or(0.0, |t| t.0);
            for (i, ch) in all.iter().enumerate() {
                let Ok(res) = &ch.result else { continue };
                if turns_half_way(path, res) || !within_ranges(machine, res) {
                    continue;
                }
                let n = res.p_deg.len();
                let zones_time: f64 = res.zones.iter().map(|z| z.after.time_s).sum();
                let written = Path {
                    axes: (0..n)
                        .map(|k| {
                            let x = res.xyz_mm[k];
                            [x[0], x[1], x[2], res.p_deg[k], res.c_deg[k]]
                        })
                        .collect(),
                    ..path.clone()
                };
                let written_time = run_time(run, &written);
                // A patch that makes the run slower as a whole (beyond the estimates'
                // tolerance, as `verify` holds it) is not a choice.
                if let (Some((t0, e0)), Some((t1, e1))) = (input_time, written_time)
                    && t1 > t0 + t0 * crate::verify::TIME_TOL_REL + e0 + e1
                {
                    continue;
                }
                let start = [res.p_deg[0], res.c_deg[0]];
                let end = [res.p_deg[n - 1], res.c_deg[n - 1]];
                let below = || {
                    res.zones
                        .iter()
                        .filter(|z| z.outcome != polepatch_patcher::Outcome::Reached)
                };
                choices.push(Choice {
                    start,
                    end,
                    unreached: below().count(),
                    shortfall: below()
                        .map(|z| 1.0 - z.after.overall_ratio.clamp(0.0, 1.0))
                        .sum(),
                    deviation_deg: res
                        .zones
                        .iter()
                        .map(|z| z.max_deviation_deg)
                        .fold(0.0, f64::max),
                    time_s: written_time.map_or(zones_time, |t| t.0),
                    changed_ends: usize::from(start != s0) + usize::from(end != e0),
                    shiftable: linked[r],
                    c_span_deg: [
                        res.c_deg.iter().copied().fold(f64::INFINITY, f64::min),
                        res.c_deg.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    ],
                });
                index.push(i);
            }
        }
        if choices.is_empty() {
            // A run done already, or one whose every patch failed (step 2.5 leaves it as it
            // is): it keeps its values.
            let (s0, e0) = ends.unwrap_or(([f64::NAN; 2], [f64::NAN; 2]));
            choices.push(Choice {
                start: s0,
                end: e0,
                unreached: 0,
                shortfall: 0.0,
                deviation_deg: 0.0,
                time_s: 0.0,
                changed_ends: 0,
                shiftable: false,
                c_span_deg: [s0[1].min(e0[1]), s0[1].max(e0[1])],
            });
            index.push(0);
        }
        let after = match (lp.runs[r].run.tcpm.is_on(), lp.end_pose(r).next, ends) {
            (true, Some(next), Some((_, e0))) => Some(After {
                next,
                input_s: next.time_s(machine, e0[0], e0[1]),
                into_next: linked.get(r + 1).copied().unwrap_or(false),
            }),
            _ => None,
        };
        passes.push(Pass {
            choices,
            input_s,
            after,
        });
        offered.push(index);
    }
    let plan = crate::plan::plan(&passes, machine).unwrap_or_else(|| vec![(0, 0.0); passes.len()]);
    // The next run's first point where the move after a run goes there.
    (0..prepared.len())
        .map(|r| {
            let target = passes[r].after.filter(|a| a.into_next).map(|_| {
                let (c, shift) = plan[r + 1];
                let start = passes[r + 1].choices[c].start;
                [start[0], start[1] + shift]
            });
            let (c, shift) = plan[r];
            (offered[r][c], shift, target)
        })
        .collect()
}

/// Equation 6's time of `path` as run `run` writes it, and its error bound, s — for a run
/// under TCPM (X Y Z part coordinates: the path is what the machine follows); `None`
/// without TCPM (the written X Y Z come through the chain later) or where it cannot be
/// analysed.
fn run_time(run: &RunPatch, path: &Path) -> Option<(f64, f64)> {
    if run.part_path.is_some() {
        return None;
    }
    polepatch_patcher::analyze_path(path, run.machine, &analysis_options(&run.opts))
        .ok()
        .map(|a| (a.time_s, a.time_error_s))
}

/// The analysis options of the patch options `o` (no samples kept).
fn analysis_options(o: &PatchOptions) -> polepatch_patcher::AnalysisOptions {
    polepatch_patcher::AnalysisOptions {
        cone_deg: o.cone_deg,
        pole_reach_deg: o.pole_reach_deg,
        tcy_s: o.tcy_s,
        keep_samples: false,
    }
}

/// Whether `res` writes a block that turns C by half a revolution or more where the
/// program's block did not: a controller that takes the shorter way on an endless C turns
/// it the other way, and the reader does not analyse across such a move. Such a patch is
/// not a choice the plan may take.
fn turns_half_way(path: &Path, res: &PatchResult) -> bool {
    let ci = polepatch_kinematics::Axis::C.index();
    (1..res.c_deg.len()).any(|k| {
        (res.c_deg[k] - res.c_deg[k - 1]).abs() >= 180.0
            && (path.axes[k][ci] - path.axes[k - 1][ci]).abs() < 180.0
    })
}

/// Whether every value `res` writes is within the machine's ranges (a patch on the other
/// branch may leave the primary axis' range, or C's where it has one).
fn within_ranges(machine: &Machine, res: &PatchResult) -> bool {
    let (lo, hi) = machine.primary_range_deg;
    res.p_deg.iter().all(|p| (lo..=hi).contains(p))
        && machine
            .c_range_deg
            .is_none_or(|(lo, hi)| res.c_deg.iter().all(|c| (lo..=hi).contains(c)))
}

/// Step 2.5 to 2.7: run `r` with its choice `c` (the plan's).
fn finish_run(
    lp: &LoadedProgram,
    r: usize,
    machine: &Machine,
    styles: &Styles,
    prepared: Prepared,
    (c, shift_deg, next_target): (usize, f64, Option<[f64; 2]>),
) -> RunOutcome {
    let opts = &styles.opts;
    let (mut run, frame, mut choices) = match prepared {
        Prepared::Done(outcome) => return outcome,
        Prepared::Open {
            run,
            frame,
            choices,
        } => (*run, frame, choices),
    };
    let c = c.min(choices.len() - 1);
    let choice = choices.swap_remove(c);
    run.opts.keep_last_point = choice.keep_last_point;
    run.start_free = choice.start_free;
    run.flipped = choice.flipped;
    run.shift_deg = shift_deg;
    run.next_target = next_target;
    let path = run.path;
    let patched = if shift_deg != 0.0 {
        choice.result.map(|r| run.written(r))
    } else {
        choice.result
    };
    let (result, rows) = match run.rows_within_centre_path(patched) {
        Ok(done) => done,
        Err(left) => return left,
    };
    let mut edits = Vec::new();
    if let Some((ch, d)) = frame.chain {
        match through_chain(
            lp,
            r,
            path,
            run.work_path(),
            &result,
            machine,
            ch,
            d,
            opts,
            styles.xyz_decimals,
            lp.chord_tolerance_mm,
        ) {
            Ok(mut xyz) => edits.append(&mut xyz),
            Err(why) => {
                let rows = RunOutcome::Patched {
                    rows,
                    edits: Vec::new(),
                    decimals: [0; 2],
                };
                return rows.left(lp, r, UntouchedReason::MachineFrame, why, opts.reach_deg());
            }
        }
    }
    run.centre_edits(&result, &mut edits);
    let decimals = run.rotary_edits(&result, &mut edits);
    RunOutcome::Patched {
        rows,
        edits,
        decimals,
    }
}

/// `path` on the other IK branch: every point `(−P, C ± 180°)` — the same tool axes — C
/// turned the way that brings its first value nearer zero (one way for every point, so C's
/// travel is the program's).
fn other_branch(path: &Path) -> Path {
    let half = if path.axes.first().is_some_and(|q| q[4] > 0.0) {
        -180.0
    } else {
        180.0
    };
    Path {
        axes: path
            .axes
            .iter()
            .map(|q| [q[0], q[1], q[2], -q[3], q[4] + half])
            .collect(),
        ..path.clone()
    }
}

/// What decides how run `r`'s X Y Z relate to the machine.
struct RunFrame<'a> {
    /// The machine's kinematic chain and the run's work offset, when both are known.
    chain: Option<(&'a Chain, [f64; 3])>,
    /// A block of the run is in inch.
    inch: bool,
    /// A block of the run (after its start) is in incremental mode (G91).
    incremental: bool,
}

impl<'a> RunFrame<'a> {
    /// Run `r`'s frame on `machine`.
    fn of(lp: &LoadedProgram, r: usize, machine: &'a Machine) -> RunFrame<'a> {
        let program = &lp.program;
        let rp = &lp.runs[r];
        RunFrame {
            chain: machine
                .chain
                .as_ref()
                .and_then(|ch| lp.datum_mm(r).map(|d| (ch, d))),
            inch: rp.run.blocks.iter().any(|&b| program.state(b).inch),
            incremental: rp
                .run
                .blocks
                .iter()
                .skip(1)
                .any(|&b| program.state(b).incremental),
        }
    }
}

/// Step 2.2: why run `rp` may not be patched, and the message for people; `None` when it
/// may.
fn why_left(
    rp: &RunPath,
    frame: &RunFrame,
    machine: &Machine,
) -> Option<(UntouchedReason, &'static str)> {
    if rp.run.transform != 0 {
        Some((
            UntouchedReason::FrameTransformed,
            "a rotation, scaling or mirror image of the frame is in force (G68, G51, G51.1, \
             G73/G72/G28 in Heidenhain ISO, CYCL DEF 8/10/11/19/26, PLANE, ROT/SCALE/MIRROR, \
             CYCLE800): the program's X Y Z and tool axis are not in the frame polepatch \
             computes in, so the run is left as it is",
        ))
    } else if rp.run.tcpm == Tcpm::Unknown {
        Some((
            UntouchedReason::TcpmUnknown,
            "whether TCPM is on here is not settled by the file: the run follows a call of \
             code outside it, a label or a jump where ways with different TCPM states meet, \
             or a code whose effect on TCPM polepatch does not know (TRACON, G43.8); X Y Z \
             may be machine coordinates, so the run is left as it is",
        ))
    } else if rp.run.tcpm == Tcpm::Uncertain {
        Some((
            UntouchedReason::TcpmUncertain,
            "TCPM is switched by a block that block delete (`/`) may skip: whether X Y Z are \
             part or machine coordinates depends on the block-delete switch, so the run is \
             left as it is",
        ))
    } else if !rp.run.tcpm.is_on() && (frame.chain.is_none() || frame.inch || frame.incremental) {
        Some((
            UntouchedReason::NoTcpm,
            if machine.chain.is_none() {
                "no TCPM active (M128, TRAORI or G43.4) — X Y Z are machine coordinates; \
                 changing rotary words alone would move the part under the tool, so the run is \
                 left as it is (if the controller switches TCPM with other codes, or always \
                 runs with it, say so in the machine file's [controller] section: tcpm_on, \
                 tcpm_always; else give the machine's kinematic chain to patch it)"
            } else if frame.chain.is_none() {
                "no TCPM active and the work offset is unknown (the program states no datum \
                 with values): X Y Z cannot be recomputed, so the run is left as it is \
                 (give --work-offset X,Y,Z)"
            } else {
                "no TCPM active, in inch or incremental mode: X Y Z are not recomputed there, \
                 so the run is left as it is"
            },
        ))
    } else if frame.incremental {
        Some((
            UntouchedReason::Incremental,
            "incremental mode (G91) — a changed value would shift every later position; \
             polepatch patches absolute (G90) programs only; left as it is",
        ))
    } else {
        None
    }
}

/// Step 2.2: the zones of run `r`, left as it is for `left` (the reason and its message),
/// reported only; the run among the untouched when it holds one.
fn report_left(
    lp: &LoadedProgram,
    r: usize,
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
    left: (UntouchedReason, &'static str),
) -> RunOutcome {
    let (reason, message) = left;
    match report_unpatched(path, machine, opts) {
        Ok(zones) if zones.is_empty() => RunOutcome::Quiet,
        Ok(zones) => {
            let rows: Vec<ZoneRow> = zones
                .iter()
                .map(|z| {
                    let mut row = zone_row(lp, r, z);
                    if let Some(why) = reason.zone_reason() {
                        row.reason = why;
                    }
                    row
                })
                .collect();
            let untouched = untouched(
                lp,
                r,
                reason,
                zones.len(),
                message.to_string(),
                opts.reach_deg(),
            );
            RunOutcome::Left { rows, untouched }
        }
        Err(e) => RunOutcome::Quiet.left(
            lp,
            r,
            UntouchedReason::Invalid,
            e.to_string(),
            opts.reach_deg(),
        ),
    }
}

/// Step 2.3: run `r`'s options (its end pose, its tool), and the path the patcher works on.
fn run_options<'a>(
    lp: &'a LoadedProgram,
    r: usize,
    path: &'a Path,
    machine: &'a Machine,
    styles: &Styles,
    frame: &RunFrame,
) -> RunPatch<'a> {
    let rp = &lp.runs[r];
    let end = lp.end_pose(r);
    let mut opts = PatchOptions {
        // Without TCPM the moves after the run are in machine coordinates: the last
        // point keeps its values (X Y Z included).
        keep_last_point: !rp.run.tcpm.is_on() || !end.free,
        ..styles.opts.clone()
    };
    // The tool, and what it asks of the patch (crate::tool).
    let tool = run_tool(lp, r, machine);
    let mut tool_capped = false;
    match tool.demand() {
        ToolDemand::KeepCentre { offset_mm } => {
            // A move after the run carries the last point's orientation along the part
            // (crate::end_pose): the ball's centre would move there.
            opts.keep_last_point |= end.carried_xy;
            opts.keep_centre = Some(KeepCentre {
                radius_mm: offset_mm,
                // Without TCPM the part-frame tips go through the chain, not to the
                // file: kept exact there.
                decimals: match (rp.run.tcpm.is_on(), frame.inch) {
                    (false, _) => 9,
                    (true, false) => styles.xyz_file_decimals,
                    // 10⁻⁴ inch is 2.5 µm: one more.
                    (true, true) => styles.xyz_file_decimals.max(MIN_INCH_XYZ_DECIMALS),
                },
                unit_mm: if frame.inch && rp.run.tcpm.is_on() {
                    25.4
                } else {
                    1.0
                },
                s_is_length: crate::program::parameter_is_length(&rp.run),
            });
        }
        ToolDemand::Cap { reach_mm } => {
            let cap = crate::tool::cap_for_reach_deg(reach_mm, lp.tool.surface_tolerance_mm);
            if opts.max_deviation_deg.is_none_or(|c| cap <= c) {
                opts.max_deviation_deg = Some(cap);
                tool_capped = true;
            }
        }
        ToolDemand::Nothing => {}
    }
    // Without TCPM (and with a chain) the patcher works on the part-frame path.
    let part_path = match (rp.run.tcpm, frame.chain) {
        (Tcpm::Off, Some((ch, d))) => Some(machine_frame::part_frame_path(ch, machine, d, path)),
        _ => None,
    };
    RunPatch {
        lp,
        r,
        machine,
        path,
        part_path,
        end,
        tool,
        tool_capped,
        opts,
        start_free: false,
        flipped: false,
        shift_deg: 0.0,
        next_target: None,
    }
}

/// One run being patched: what steps 2.4 to 2.7 share.
#[derive(Clone)]
struct RunPatch<'a> {
    lp: &'a LoadedProgram,
    r: usize,
    machine: &'a Machine,
    /// The run's path, as the file gives it.
    path: &'a Path,
    /// The part-frame path of a run without TCPM (with a chain), which the patcher works
    /// on.
    part_path: Option<Path>,
    /// What the blocks after the run allow its end.
    end: EndPose,
    /// The run's tool and the point its X Y Z state.
    tool: RunTool,
    /// The tool's cap on the orientation change is in force (a flat or bull-nose cutter).
    tool_capped: bool,
    /// The run's options.
    opts: PatchOptions,
    /// The run's first point may change (its start linked, [`linked_starts`]; the plan's
    /// choice): the patch is [`polepatch_patcher::patch_path_free_start`]'s, its end kept.
    start_free: bool,
    /// The patcher works on the run's path on the other branch (every point `(−P, C ±
    /// 180°)`, the same tool axes): its end stays there, its start is free or kept there
    /// (the plan's choice).
    flipped: bool,
    /// Whole turns added to every C value the run writes (the plan's, for a linked start:
    /// the move before it turns C the short way), degrees.
    shift_deg: f64,
    /// Where the positioning move after the run goes when the plan put the next run's
    /// first point on another branch (primary, C, degrees).
    next_target: Option<[f64; 2]>,
}

impl RunPatch<'_> {
    /// The path the patcher works on.
    fn work_path(&self) -> &Path {
        self.part_path.as_ref().unwrap_or(self.path)
    }

    /// Step 2.4: the patch of the run with options `o`.
    fn patch(&self, o: &PatchOptions) -> Result<PatchResult, PathError> {
        if self.flipped {
            let flipped = other_branch(self.path);
            let res = if self.start_free {
                polepatch_patcher::patch_path_free_start(&flipped, self.machine, o)
            } else {
                patch_path(&flipped, self.machine, o)
            };
            return res.map(|r| self.written(r));
        }
        if self.shift_deg != 0.0 {
            let res = if self.start_free {
                polepatch_patcher::patch_path_free_start(self.path, self.machine, o)
            } else {
                patch_path(self.path, self.machine, o)
            };
            return res.map(|r| self.written(r));
        }
        if self.start_free {
            polepatch_patcher::patch_path_free_start(self.work_path(), self.machine, o)
        } else if self.part_path.is_some() {
            machine_frame::patch_part_frame(self.work_path(), self.machine, o)
        } else {
            patch_path(self.work_path(), self.machine, o)
        }
    }

    /// `res` with the plan's whole turns added to C, and what is written marked: what
    /// differs from the file's values.
    fn written(&self, mut res: PatchResult) -> PatchResult {
        for (k, q) in self.path.axes.iter().enumerate() {
            res.c_deg[k] += self.shift_deg;
            res.p_changed[k] = res.p_deg[k] != q[3];
            res.c_changed[k] = res.c_deg[k] != q[4];
        }
        res
    }

    /// The positioning move after a free end: its line and its time from the original end
    /// and from the end of `res`, s.
    fn rapid(&self, res: &PatchResult) -> Option<(usize, f64, f64)> {
        let next = *self.end.next.as_ref()?;
        // Where the move goes in the written program: the next run's first point as the
        // plan writes it.
        let mut written = next;
        if let Some([p, c]) = self.next_target {
            (written.p_deg, written.c_deg) = (p, c);
        }
        let path = self.path;
        let n = path.axes.len();
        let (p0, c0) = (path.axes[n - 1][3], path.axes[n - 1][4]);
        let (p1, c1) = (*res.p_deg.last()?, *res.c_deg.last()?);
        Some((
            next.line,
            next.time_s(self.machine, p0, c0),
            written.time_s(self.machine, p1, c1),
        ))
    }

    /// Step 2.4: the run's choices for the plan ([`crate::plan`]): its end free where the
    /// blocks after it allow (and the run's options do not pin it), its end kept (unless
    /// the free end kept it anyway), and its start free where it is linked to the run
    /// before ([`linked_starts`]; then its end is kept).
    fn choices(&self, start_linked: bool) -> Vec<RunChoice> {
        let mut out = Vec::new();
        let pinned = PatchOptions {
            keep_last_point: true,
            ..self.opts.clone()
        };
        if !self.opts.keep_last_point {
            let free = self.patch(&self.opts);
            let n = self.path.axes.len();
            let kept_end = free
                .as_ref()
                .is_ok_and(|r| !r.p_changed[n - 1] && !r.c_changed[n - 1]);
            out.push(RunChoice {
                keep_last_point: false,
                start_free: false,
                flipped: false,
                result: free,
            });
            if kept_end {
                return self.with_free_start(out, start_linked, &pinned, true);
            }
        }
        out.push(RunChoice {
            keep_last_point: true,
            start_free: false,
            flipped: false,
            result: self.patch(&pinned),
        });
        self.with_free_start(out, start_linked, &pinned, false)
    }

    /// `out` and, for a linked start, the choice with the start free and the end kept;
    /// where the end is free and its patch kept it (`free_end_kept`), the choices that end
    /// on the other branch: the run on the
    /// other branch with its start free (the patcher may re-select the program's branch
    /// at the start), and — for a linked start — kept there whole.
    fn with_free_start(
        &self,
        mut out: Vec<RunChoice>,
        start_linked: bool,
        pinned: &PatchOptions,
        free_end_kept: bool,
    ) -> Vec<RunChoice> {
        if self.part_path.is_some() {
            return out;
        }
        let mut add = |start_free: bool, flipped: bool| {
            let run = RunPatch {
                start_free,
                flipped,
                opts: pinned.clone(),
                ..self.clone()
            };
            out.push(RunChoice {
                keep_last_point: true,
                start_free,
                flipped,
                result: run.patch(pinned),
            });
        };
        if start_linked {
            add(true, false);
        }
        // The other branch at the end, where the free end did not take it.
        if !self.opts.keep_last_point && free_end_kept {
            add(true, true);
            if start_linked {
                add(false, true);
            }
        }
        // A flipped run whose start the patcher put back on the program's branch is a
        // choice for any run; one that starts on the other branch only for a linked start.
        out.retain(|c| {
            !c.flipped
                || start_linked
                || c.result
                    .as_ref()
                    .is_ok_and(|r| !r.p_changed[0] && !r.c_changed[0])
        });
        out
    }

    /// Step 2.5: the report rows of `result`'s zones; `centre_capped`: the orientation
    /// change was capped for a kept ball centre's path.
    fn zone_rows(&self, result: &PatchResult, centre_capped: bool) -> Vec<ZoneRow> {
        let (lp, r) = (self.lp, self.r);
        let rp = &lp.runs[r];
        let mut rows: Vec<ZoneRow> = result
            .zones
            .iter()
            .map(|z| {
                let mut row = zone_row(lp, r, z);
                tool_fields(
                    &mut row,
                    &self.tool,
                    z,
                    self.work_path(),
                    result,
                    self.machine,
                    self.tool_capped,
                );
                if centre_capped && z.reason == polepatch_patcher::Reason::DeviationCap {
                    row.reason = ZoneReason::CentrePath;
                }
                row.end_pose = Some(if self.opts.keep_last_point {
                    EndFreedom::Pinned
                } else {
                    EndFreedom::Free
                });
                // The other branch: C half a turn away (the primary axis' sign then
                // changes); a patched end near its own values is on the program's.
                let branch = |k: usize| {
                    let dc = (result.c_deg[k] - self.path.axes[k][4]).rem_euclid(360.0);
                    Some(if (dc - 180.0).abs() < 90.0 {
                        Branch::Other
                    } else {
                        Branch::Program
                    })
                };
                row.start_branch = branch(0);
                row.end_branch = branch(self.path.axes.len() - 1);
                row.end_pose_line = if rp.run.tcpm.is_on() {
                    self.end.decided_line
                } else {
                    None
                };
                row
            })
            .collect();
        if rp.run.tcpm.is_on()
            && let (Some((line, before, after)), Some(last)) = (self.rapid(result), rows.last_mut())
        {
            last.rapid_line = Some(line);
            last.rapid_time_before_s = Some(before);
            last.rapid_time_after_s = Some(after);
        }
        rows
    }

    /// Step 2.5: the rows of `patched`, solved again with the orientation change capped
    /// while a kept ball centre leaves its path between the points by more than the chord
    /// tolerance (where the original block stayed within it; the centre's excursion
    /// between two points grows with the change), up to CENTRE_PATH_RETRIES times. The
    /// patch and its rows; `Err` with the run's outcome when it keeps its values.
    fn rows_within_centre_path(
        &mut self,
        mut patched: Result<PatchResult, PathError>,
    ) -> Result<(PatchResult, Vec<ZoneRow>), RunOutcome> {
        let (lp, r) = (self.lp, self.r);
        let reach_deg = self.opts.reach_deg();
        let chord_limit = lp.chord_tolerance_mm + machine_frame::TIP_TOLERANCE_MM;
        let mut centre_capped = false;
        let mut retries = 0;
        loop {
            let result = match patched {
                Ok(res) => res,
                Err(e) => {
                    return Err(RunOutcome::Quiet.left(
                        lp,
                        r,
                        UntouchedReason::Invalid,
                        e.to_string(),
                        reach_deg,
                    ));
                }
            };
            let rows = self.zone_rows(&result, centre_capped);
            let worst_chord = rows
                .iter()
                .filter_map(|z| z.centre_chord_mm)
                .fold(0.0, f64::max);
            if worst_chord <= chord_limit {
                return Ok((result, rows));
            }
            let worst_dev = rows.iter().map(|z| z.max_deviation_deg).fold(0.0, f64::max);
            if retries < CENTRE_PATH_RETRIES && worst_dev > 0.0 {
                retries += 1;
                let cap = worst_dev * (chord_limit / worst_chord) * CENTRE_PATH_CAP_SAFETY;
                self.opts.max_deviation_deg =
                    Some(self.opts.max_deviation_deg.map_or(cap, |c| c.min(cap)));
                centre_capped = true;
                patched = self.patch(&self.opts);
                continue;
            }
            let row = rows
                .iter()
                .find(|z| z.centre_chord_mm.is_some_and(|c| c > chord_limit))
                .expect("a row over the limit");
            let why = format!(
                "between the points of lines {}–{} the ball's centre (X Y Z rewritten to keep it \
                 at the points) would leave the line between its original positions by {:.3} mm \
                 with the axes interpolated between the blocks (chord tolerance {} mm; the points \
                 are too far apart for the orientation change, also with the change capped); \
                 the run keeps its values",
                row.lines[0],
                row.lines[1],
                row.centre_chord_mm.unwrap_or(0.0),
                lp.chord_tolerance_mm
            );
            let rows = RunOutcome::Patched {
                rows,
                edits: Vec::new(),
                decimals: [0; 2],
            };
            return Err(rows.left(lp, r, UntouchedReason::CentrePath, why, reach_deg));
        }
    }

    /// Step 2.7: a ball's centre kept under TCPM: the tips the patcher rewrote, in the
    /// file's unit and decimals (a block after the run keeps its own X Y Z: step 3).
    fn centre_edits(&self, result: &PatchResult, edits: &mut Vec<Edit>) {
        let rp = &self.lp.runs[self.r];
        let (Some(keep), true) = (&self.opts.keep_centre, rp.run.tcpm.is_on()) else {
            return;
        };
        let n = rp.run.len();
        for k in 1..n {
            for (i, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                if !result.xyz_changed[k][i] {
                    continue;
                }
                // A block after the run that restates its last rotary values keeps its
                // own X Y Z (a retract's target): only its rotary words follow the run.
                edits.push(Edit {
                    block: rp.run.blocks[k],
                    letter,
                    value: result.xyz_mm[k][i] / keep.unit_mm,
                    decimals: result.xyz_decimals,
                });
            }
        }
    }

    /// Step 2.7: the changed primary-axis and C words, and the decimals written for them
    /// (C, primary). The run ends on new values: the blocks after it that restated its
    /// last values restate the new ones ([`crate::end_pose`]).
    fn rotary_edits(&self, result: &PatchResult, edits: &mut Vec<Edit>) -> [usize; 2] {
        let mut written = [0, 0];
        let rp = &self.lp.runs[self.r];
        let program = &self.lp.program;
        let letters = [
            (
                self.lp.primary_letter,
                &result.p_deg,
                &result.p_changed,
                result.p_decimals,
            ),
            (
                self.lp.pole_letter,
                &result.c_deg,
                &result.c_changed,
                result.c_decimals,
            ),
        ];
        for (letter, values, changed, decimals) in letters {
            for k in 0..rp.run.len() {
                if !changed[k] {
                    continue;
                }
                if k == 0 && !self.start_free && !self.flipped {
                    // Point 0 belongs to the block before the run; the patcher moves it only
                    // where the run's start is free (that block is the positioning move that
                    // goes there: linked_starts).
                    debug_assert!(false, "patcher changed the start point of a run");
                    continue;
                }
                let w = usize::from(letter != self.lp.pole_letter);
                written[w] = written[w].max(decimals);
                edits.push(Edit {
                    block: rp.run.blocks[k],
                    letter,
                    value: values[k],
                    decimals,
                });
            }
            let n = rp.run.len();
            if !self.opts.keep_last_point && changed[n - 1] {
                for &b in &self.end.restate {
                    if program.block_words(b).iter().any(|w| w.letter == letter) {
                        edits.push(Edit {
                            block: b,
                            letter,
                            value: values[n - 1],
                            decimals,
                        });
                    }
                }
            }
        }
        written
    }
}

/// Step 3 as data for [`polepatch_nc::apply_edits`]: one group per run (its blocks
/// after its start point; a patched run's edits, taken from its outcome), and the file's
/// decimals for a restored word. Inside a run, a point that relied on a modal value keeps
/// it; after a run only the blocks that restate its last values are written: its end
/// point only moves when what follows does not depend on the pose ([`crate::end_pose`]).
/// Where the run's last point got new X Y Z (a ball's centre kept), the first move after
/// the run that relies on them gets the original values back: a positioning move keeps
/// its target (its rotary words carry the run's new pose, by design, and are never
/// restored).
fn edit_plan(lp: &LoadedProgram, styles: &Styles, outcomes: &mut [RunOutcome]) -> EditPlan {
    let groups = lp
        .runs
        .iter()
        .zip(outcomes.iter_mut())
        .map(|(rp, o)| EditGroup {
            blocks: rp.run.blocks.iter().skip(1).copied().collect(),
            edits: match o {
                RunOutcome::Patched { edits, .. } => std::mem::take(edits),
                _ => Vec::new(),
            },
            restore_xyz_after: true,
        })
        .collect();
    let restore_decimals = AXES.map(|l| match l {
        b'X' | b'Y' | b'Z' => styles.of(lp, l).decimals,
        l if l == lp.pole_letter => styles.c.decimals,
        _ => styles.p.decimals,
    });
    EditPlan {
        groups,
        restore_decimals,
    }
}

/// Step 4: the words changed (`words`), and the file's decimals and those written, where a
/// run of the stretch comes near the pole (one with only runs that cannot be analysed
/// says nothing of them).
fn finish_report(
    lp: &LoadedProgram,
    styles: &Styles,
    written: [usize; 2],
    words: usize,
    report: &mut FileReport,
) {
    report.words_changed = words;
    let near = lp.runs.iter().any(|rp| {
        rp.path
            .as_ref()
            .is_ok_and(|p| near_pole(lp, p, &styles.opts))
    });
    if near {
        report.file_c_decimals = Some(styles.c.decimals);
        report.written_c_decimals = Some(written[0]);
        report.file_primary_decimals = Some(styles.p.decimals);
        report.written_primary_decimals = Some(written[1]);
    }
}

/// Step 3, for a run whose edits [`polepatch_nc::apply_edits`] dropped: Sinumerik
/// direction-form words (`C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`) are written modulo 360 in the
/// same form where it makes the patched move; a run whose edits ask a move the form cannot
/// make keeps its values (its zones `direction_form`), as does one whose edit would rewrite
/// a variable (`macro_variable`). The run, the reason and the message.
fn direction_form_left(dropped: GroupConflict) -> (usize, UntouchedReason, String) {
    let k = dropped.conflict;
    if k.variable {
        (
            dropped.group,
            UntouchedReason::MacroVariable,
            format!("{}; the run keeps its values", k.message),
        )
    } else {
        (
            dropped.group,
            UntouchedReason::DirectionForm,
            format!(
                "{}: the form cannot make the patched move, and polepatch never writes a \
                 word that makes a different one; the run keeps its values",
                k.message
            ),
        )
    }
}

/// With a kinematic chain: for a run without TCPM, the X Y Z edits that keep the part-frame
/// tool tip of every changed point (from the written rotary values, checked within
/// [`machine_frame::TIP_TOLERANCE_MM`]); for every run, the machine-frame check (no axis's
/// lowest Equation-6 ratio worse than `min(before, 1)`). `Err` says why the run must keep
/// its original values.
#[allow(clippy::too_many_arguments)]
fn through_chain(
    lp: &LoadedProgram,
    r: usize,
    path: &polepatch_patcher::Path,
    work_path: &polepatch_patcher::Path,
    result: &polepatch_patcher::PatchResult,
    machine: &Machine,
    chain: &polepatch_kinematics::Chain,
    datum_mm: [f64; 3],
    opts: &PatchOptions,
    xyz_decimals: usize,
    chord_tolerance_mm: f64,
) -> Result<Vec<Edit>, String> {
    let rp = &lp.runs[r];
    let tcpm = rp.run.tcpm.is_on();
    let n = path.axes.len();
    let changed = |k: usize| result.p_changed[k] || result.c_changed[k];
    if !(0..n).any(changed) {
        return Ok(Vec::new());
    }
    let mut after: Vec<[f64; 5]> = path.axes.clone();
    let mut edits = Vec::new();
    for (k, point) in after.iter_mut().enumerate() {
        point[3] = result.p_deg[k];
        point[4] = result.c_deg[k];
        if tcpm || !changed(k) {
            continue;
        }
        // The part-frame tip as the patch wants it (moved to keep a ball's centre).
        let tip = result.xyz_mm[k];
        let (p, c) = (result.p_deg[k], result.c_deg[k]);
        let exact = chain.program_xyz(machine, datum_mm, p, c, tip);
        let mut written = exact;
        let mut ok = false;
        for decimals in xyz_decimals..=xyz_decimals.max(6) {
            written = exact.map(|v| machine_frame::round_to(v, decimals));
            let back = chain.part_tip(machine, datum_mm, p, c, written);
            let err = (0..3).map(|i| (back[i] - tip[i]).abs()).fold(0.0, f64::max);
            if err <= machine_frame::TIP_TOLERANCE_MM {
                ok = true;
                for (i, letter) in [b'X', b'Y', b'Z'].into_iter().enumerate() {
                    if written[i] != path.axes[k][i] {
                        edits.push(Edit {
                            block: rp.run.blocks[k],
                            letter,
                            value: written[i],
                            decimals,
                        });
                    }
                }
                break;
            }
        }
        if !ok {
            return Err(format!(
                "the tool tip at line {} cannot be kept within {} mm through the kinematic chain",
                lp.line_of(r, k),
                machine_frame::TIP_TOLERANCE_MM
            ));
        }
        point[..3].copy_from_slice(&written);
    }
    if !tcpm {
        // Between the points (issue 19 §2): the tool tip under linear interpolation of the
        // written values may not leave the programmed line by more than the tolerance, nor
        // by more than the original block did.
        for k in 1..n {
            if !(changed(k - 1) || changed(k)) {
                continue;
            }
            let tip = |i: usize| {
                [
                    work_path.axes[i][0],
                    work_path.axes[i][1],
                    work_path.axes[i][2],
                ]
            };
            let err = |from: &[f64; 5], to: &[f64; 5], tips| {
                machine_frame::chord_error_mm(chain, machine, datum_mm, from, to, tips)
            };
            let new = err(
                &after[k - 1],
                &after[k],
                [result.xyz_mm[k - 1], result.xyz_mm[k]],
            );
            let old = err(&path.axes[k - 1], &path.axes[k], [tip(k - 1), tip(k)]);
            // The endpoints themselves may move by the tip tolerance (rounding).
            if new > chord_tolerance_mm.max(old) + machine_frame::TIP_TOLERANCE_MM {
                return Err(format!(
                    "between lines {} and {} the tool tip would leave the programmed line by \
                     {new:.3} mm with the axes interpolated linearly (without TCPM; the original \
                     block: {old:.3} mm, chord tolerance {chord_tolerance_mm} mm), so the run \
                     keeps its values",
                    lp.line_of(r, k - 1),
                    lp.line_of(r, k)
                ));
            }
        }
    }
    let aopts = analysis_options(opts);
    let frame = |values: &[[f64; 5]]| {
        machine_frame::machine_frame_path(
            chain,
            machine,
            datum_mm,
            tcpm,
            values,
            &path.s_mm,
            path.feed_mm_min,
        )
    };
    let spans = |values: &[[f64; 5]], when: &str| {
        polepatch_patcher::quality::analyze_spans(&frame(values), machine, &aopts)
            .map(|(_, spans)| spans)
            .map_err(|e| format!("machine-frame analysis failed {when} the patch: {e}"))
    };
    let (before, after_s) = (spans(&path.axes, "before")?, spans(&after, "after")?);
    // The written program's check, on the machine-frame path (crate::verify).
    if let Some(w) = crate::verify::slower(&before, &after_s) {
        let letters = polepatch_kinematics::Axis::ALL.map(|a| axis_letter(a, lp.letters()));
        return Err(format!(
            "the patch would slow the machine between lines {} and {} in the machine frame: {} \
             (the linear axes follow the table near the pole), so the run keeps its values",
            lp.line_of(r, w.span),
            lp.line_of(r, w.span + 1),
            w.describe([
                &letters[0],
                &letters[1],
                &letters[2],
                &letters[3],
                &letters[4]
            ])
        ));
    }
    Ok(edits)
}

/// Run `r`'s tool and the point its X Y Z state ([`crate::tool::resolve`]).
fn run_tool(lp: &LoadedProgram, r: usize, machine: &Machine) -> RunTool {
    let rp = &lp.runs[r];
    crate::tool::for_run(
        &lp.tool,
        &rp.found_tool,
        machine,
        rp.run.tcpm.is_on(),
        rp.run.tcpm_centre,
    )
}

/// Distance from `p` to the segment `a`–`b`, mm.
fn point_segment_mm(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab: [f64; 3] = std::array::from_fn(|i| b[i] - a[i]);
    let ap: [f64; 3] = std::array::from_fn(|i| p[i] - a[i]);
    let len2: f64 = ab.iter().map(|v| v * v).sum();
    let t = if len2 > 0.0 {
        (ab.iter().zip(&ap).map(|(x, y)| x * y).sum::<f64>() / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (0..3)
        .map(|i| (ap[i] - t * ab[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// The tool figures of a patched zone's row (module [`crate::tool`]): the tool and its
/// point, the cutter's largest displacement at a written point, the centre's path between
/// the points (a ball at its tip), and `tool_limited` where the tool's cap stopped it.
#[allow(clippy::too_many_arguments)]
fn tool_fields(
    row: &mut ZoneRow,
    rt: &RunTool,
    z: &ZoneReport,
    before: &polepatch_patcher::Path,
    result: &polepatch_patcher::PatchResult,
    machine: &Machine,
    tool_capped: bool,
) {
    use polepatch_kinematics::forward;
    row.tool = rt.tool.map_or(ZoneTool::Unknown, ZoneTool::Known);
    row.tool_source = rt.tool_source.clone();
    row.tool_point = Some(rt.point);
    row.tool_point_source = rt.point_source.clone();
    row.tool_disagreement = rt.disagreement.clone();
    if tool_capped && z.reason == polepatch_patcher::Reason::DeviationCap {
        row.reason = ZoneReason::ToolLimited;
    }
    let Some(tool) = rt.tool else { return };
    let at = |k: usize, t: f64| -> ([f64; 3], [f64; 3], [f64; 3], [f64; 3]) {
        // Tip and tool axis at parameter t of block k (k − 1 → k), before and after.
        let lerp = |a: f64, b: f64| a + (b - a) * t;
        let q0: [f64; 5] = std::array::from_fn(|i| lerp(before.axes[k - 1][i], before.axes[k][i]));
        let x1 = |j: usize| {
            [
                result.xyz_mm[j][0],
                result.xyz_mm[j][1],
                result.xyz_mm[j][2],
            ]
        };
        let (a, b) = (x1(k - 1), x1(k));
        let tip1: [f64; 3] = std::array::from_fn(|i| lerp(a[i], b[i]));
        let p1 = lerp(result.p_deg[k - 1], result.p_deg[k]);
        let c1 = lerp(result.c_deg[k - 1], result.c_deg[k]);
        (
            [q0[0], q0[1], q0[2]],
            forward(machine, q0[3], q0[4]),
            tip1,
            forward(machine, p1, c1),
        )
    };
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt();
    match tool.kind {
        ToolKind::Ball => {
            // The centre's height above the point X Y Z state; X Y Z rewritten to keep it.
            let reach = rt.centre_offset_mm().unwrap_or(0.0);
            let keeps = matches!(rt.demand(), ToolDemand::KeepCentre { .. });
            let centre = |tip: [f64; 3], o: [f64; 3]| along(tip, o, reach);
            let mut at_points: f64 = 0.0;
            let mut between: f64 = 0.0;
            let m = CENTRE_CHORD_SAMPLES;
            for k in z.first.max(1)..=z.last {
                let (t0, o0, t1, o1) = at(k, 1.0);
                at_points = at_points.max(dist(centre(t0, o0), centre(t1, o1)));
                if !keeps {
                    continue;
                }
                // Between the points: how far the centre leaves the line between the
                // block's original centres (what CAM's chord tolerance bounds), written
                // against original; only where the written block leaves it more.
                let (a0, ao, _, _) = at(k, 0.0);
                let (b0, bo, _, _) = at(k, 1.0);
                let (a, b) = (centre(a0, ao), centre(b0, bo));
                let (mut old_dev, mut new_dev): (f64, f64) = (0.0, 0.0);
                for s in 1..m {
                    let (t0, o0, t1, o1) = at(k, s as f64 / m as f64);
                    old_dev = old_dev.max(point_segment_mm(centre(t0, o0), a, b));
                    new_dev = new_dev.max(point_segment_mm(centre(t1, o1), a, b));
                }
                if new_dev > old_dev {
                    between = between.max(new_dev);
                }
            }
            row.max_cutter_shift_mm = Some(at_points);
            row.centre_chord_mm = keeps.then_some(between);
        }
        ToolKind::Flat | ToolKind::Bull => {
            row.max_cutter_shift_mm = Some(
                tool.reach_from_mm(rt.height_mm)
                    * crate::tool::centre_shift_per_mm_radius(z.max_deviation_deg),
            );
        }
    }
}

fn problem_reason(p: &RunProblem) -> UntouchedReason {
    match p {
        RunProblem::NoFeed => UntouchedReason::NoFeed,
        RunProblem::FeedTooLow { .. } => UntouchedReason::FeedTooLow,
        RunProblem::UnknownRotary { .. } => UntouchedReason::UnknownRotary,
        RunProblem::OtherRotary { .. } => UntouchedReason::OtherRotary,
    }
}

fn untouched(
    lp: &LoadedProgram,
    r: usize,
    reason: UntouchedReason,
    zones: usize,
    message: String,
    reach_deg: f64,
) -> UntouchedRun {
    let pi = lp.primary_index();
    UntouchedRun {
        run: lp.run_number(r),
        lines: lp.lines_of_run(r),
        reason,
        zones,
        near_pole: lp.runs[r]
            .run
            .pos
            .iter()
            // A value never programmed reads as 0, as `Run::axes5` reads it.
            .any(|p| lp.pole.near(p[pi].unwrap_or(0.0), reach_deg)),
        message,
    }
}

/// The report row of zone `z` of run `run` of `lp`, before the tool and end-pose fields.
fn zone_row(lp: &LoadedProgram, run: usize, z: &ZoneReport) -> ZoneRow {
    let pl = lp.letters();
    ZoneRow {
        file: lp.name.clone(),
        run: lp.run_number(run),
        lines: [lp.line_of(run, z.first), lp.line_of(run, z.last)],
        core_lines: [lp.line_of(run, z.core[0]), lp.line_of(run, z.core[1])],
        kind: z.kind,
        min_abs_primary_deg: z.min_abs_primary_deg,
        before: FiguresRow::new(&z.before, pl),
        after: FiguresRow::new(&z.after, pl),
        ideal_time_s: z.ideal_time_s,
        max_deviation_deg: z.max_deviation_deg,
        points_modified: z.points_modified,
        primary_points_modified: z.primary_points_modified,
        branch_reselected: z.reselected_points > 0 || z.method == Method::Reselect,
        reselected_points: z.reselected_points,
        patch_length_mm: z.patch_length_mm,
        outcome: z.outcome,
        reason: z.reason,
        end_pose: None,
        end_pose_line: None,
        method: z.method,
        qp_status: z.qp.status,
        qp_iterations: z.qp.iterations,
        qp_solves: z.qp.solves,
        solve_time_ms: z.qp.solve_time_s * 1e3,
        decimals: z.decimals,
        primary_decimals: z.p_decimals,
        c_offset_deg: z.c_offset_deg,
        feed_mode: lp.runs[run].run.feed_mode,
        tool: ZoneTool::NotPatched,
        tool_source: String::new(),
        tool_point: None,
        tool_point_source: String::new(),
        tool_disagreement: None,
        centre_shift_per_mm_radius: crate::tool::centre_shift_per_mm_radius(z.max_deviation_deg),
        max_cutter_shift_mm: None,
        centre_chord_mm: None,
        needed_deviation_deg: z.needed_deviation_deg,
        rapid_line: None,
        rapid_time_before_s: None,
        rapid_time_after_s: None,
        start_branch: None,
        end_branch: None,
    }
}
