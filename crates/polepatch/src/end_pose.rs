//! Whether a run may end in another pose than the program's, which block says so, and
//! which blocks after it restate its last values.
//!
//! A patch may change the values of a run's last point — and a branch re-selection puts
//! the last point on the other IK branch, `(P, C) → (−P, C ± 180°)`: the same tool axis,
//! but the table turned half a revolution about it. What happens after the run then moves
//! from that pose. The blocks after the run are read in order until one decides:
//!
//! **Independent of the pose** (the scan goes on):
//! - a move with TCPM active and no rotary word: the controller keeps the tool axis and
//!   moves the tool tip in part coordinates — the same motion relative to the part from
//!   either pose. A Z-only move up under TCPM is a **retract**: the highest part-frame Z it
//!   reaches is the program's **clearance**;
//! - a move with TCPM off and no rotary word that changes only Z (along the tool axis,
//!   which both poses share);
//! - a move that **restates** the run's last rotary values (every rotary word it has
//!   equals the value in force: a retract such as `G0 Z+50 A… C…`), with TCPM active or
//!   moving only Z: it moves nothing rotary from either pose. It is rewritten with the
//!   run's new last values — the same orientation on the new branch — so it restates them
//!   still ([`EndPose::restate`]).
//!
//! **Free** (the last point may change):
//! - a tool change (T, M6) or the program's end (M2, M30), or the end of the file;
//! - a block that programs both rotary axes and moves nothing else (a rotary-only
//!   repositioning, as C17's `%SING` has);
//! - **a positioning move above the clearance**: under TCPM, a move with rotary words whose
//!   tool tip starts and ends at or above the clearance the program itself retracted to
//!   (X and Y may move). *Proof.* The part and its fixtures lie below the clearance the
//!   program retracted to (that is what a retract height is). Under TCPM the controller
//!   moves the tool tip in the part frame on the programmed line between the block's end
//!   points, both at Z ≥ clearance, so the tip stays at Z ≥ clearance during the move,
//!   whatever the rotary axes do and from whichever pose they start; the tool extends
//!   from the tip along the tool axis, away from the part (|P| < 90°: the axis points up),
//!   so no point of the tool comes below the clearance. Starting from the other branch
//!   only changes how the table turns under that tool tip (C travels up to 180° more).
//!   (This holds for controllers that interpolate the tool tip linearly under TCPM, which
//!   Heidenhain M128, Sinumerik TRAORI and Fanuc G43.4 with linear rapid do; a machine
//!   set up for non-linear rapid positioning under TCPM should pin run ends — a caller
//!   can — as this module cannot see its parameters.)
//!
//! **Pinned** (the last point keeps its values; [`EndPose::decided_line`] says which block):
//! anything else — a rotary word in a Sinumerik direction form (`C=DC(…)`, `C=ACP(…)`,
//! `C=ACN(…)`: where it goes depends on where the axis starts), a move with X or Y in
//! machine coordinates, a move that changes a rotary
//! axis below the clearance or with TCPM off (together with a linear move, or one rotary
//! axis alone), a positioning move before any retract, incremental mode, a non-move naming
//! a rotary axis (a datum shift on it), or a restating block that belongs to another run
//! (it cannot be rewritten for this one). No rotary word other than a restating block's is
//! ever written after a run's last point.
//!
//! A run without TCPM is pinned by the pipeline whatever follows (its X Y Z are machine
//! coordinates: [`crate::patch`]).

use polepatch_nc::modal::{X, Y, Z};
use polepatch_nc::{Flags, Modal, RotaryLetters, Word};

/// What the blocks after a run say about its last point.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct EndPose {
    /// The last point may change (module docs).
    pub free: bool,
    /// The 1-based file line of the block that decided (`None`: the end of the file).
    pub decided_line: Option<usize>,
    /// Blocks before the deciding one that restate the run's last rotary values: when the
    /// last point changes they are rewritten with its new values.
    pub restate: Vec<usize>,
    /// The positioning move that freed the end (a rotary-only repositioning or a move above
    /// the clearance), when it is one: a changed last point changes how far it turns the
    /// rotary axes (`NextMove::time_s`).
    pub next: Option<NextMove>,
    /// Before the deciding block, a move under TCPM without rotary words moved X or Y
    /// below the clearance: it carries the last point's orientation along the part. The
    /// tool tip's path is the same from either pose, but a ball programmed at its tip moves
    /// its centre by R·|Δo| there (issue 39: 15 µm on a lead-out at cutting depth), so a
    /// run whose ball centre is kept keeps its end ([`crate::patch`]).
    pub carried_xy: bool,
}

/// The move after a run that freed its end: where it takes the rotary axes, and how far it
/// moves the tool tip (what it costs does not depend on the run's end otherwise).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NextMove {
    /// Its 1-based file line.
    pub line: usize,
    /// The primary axis' and C's values it programs, degrees.
    pub p_deg: f64,
    /// C, degrees.
    pub c_deg: f64,
    /// |ΔX|, |ΔY|, |ΔZ| of the tool tip over the move, mm.
    pub linear_mm: [f64; 3],
}

impl NextMove {
    /// The move's time from the run's last pose `(p_deg, c_deg)`, s: every axis at its
    /// velocity and acceleration limits (a trapezoid, jerk left out), the slowest axis
    /// setting the time — how a controller positions with rapid traverse. An estimate for
    /// comparing two ends of the same run, not the controller's exact time.
    pub fn time_s(&self, machine: &polepatch_kinematics::Machine, p_deg: f64, c_deg: f64) -> f64 {
        let d = [
            self.linear_mm[0],
            self.linear_mm[1],
            self.linear_mm[2],
            (self.p_deg - p_deg).abs(),
            (self.c_deg - c_deg).abs(),
        ];
        d.iter()
            .zip(&machine.limits)
            .map(|(&d, lim)| trapezoid_time_s(d, lim.v, lim.a))
            .fold(0.0, f64::max)
    }
}

/// A positioning move's time from the values `from` to `to` (`[X, Y, Z, P, C]`, mm and
/// degrees), s: every axis at its velocity and acceleration limits (a trapezoid, jerk left
/// out), the slowest axis setting the time ([`NextMove::time_s`]'s estimate; X Y Z as
/// the program states them).
pub fn positioning_time_s(
    machine: &polepatch_kinematics::Machine,
    from: [f64; 5],
    to: [f64; 5],
) -> f64 {
    from.iter()
        .zip(&to)
        .zip(&machine.limits)
        .map(|((a, b), lim)| trapezoid_time_s((b - a).abs(), lim.v, lim.a))
        .fold(0.0, f64::max)
}

/// The time to travel `d` from rest to rest at velocity `v` and acceleration `a` at most.
fn trapezoid_time_s(d: f64, v: f64, a: f64) -> f64 {
    if [d, v, a].iter().any(|x| x.is_nan() || *x <= 0.0) {
        return 0.0;
    }
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

/// One block's answer (see [`After::verdict`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// The last point may change.
    Free,
    /// The last point keeps its values.
    Pinned,
    /// This block does not decide.
    Continue,
    /// This block restates the run's last values (rewritten when they change); it does
    /// not decide.
    Restate,
}

/// What the scan after a run has seen so far (the program's clearance).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Scan {
    /// The highest part-frame Z a retract (a Z-only move up under TCPM) reached since the
    /// run's last point, mm.
    pub clearance_mm: Option<f64>,
    /// A move under TCPM without rotary words moved X or Y below the clearance
    /// ([`EndPose::carried_xy`]).
    pub carried_xy: bool,
}

/// One block after a run's last point, for [`After::verdict`]: what the verdicts of both
/// tilting letters need of its words, read once ([`After::new`]).
#[derive(Debug, Clone, Copy)]
pub struct After<'a> {
    /// It moves ([`polepatch_nc::Block::is_move`]).
    is_move: bool,
    /// What the reader marked on it ([`polepatch_nc::Block::flags`]): a tool change or the
    /// program's end in any dialect (Heidenhain `TOOL CALL`, `END PGM` included), and
    /// block delete.
    flags: Flags,
    /// The modal state after it.
    state: &'a Modal,
    /// The modal state before it.
    before: &'a Modal,
    /// Letters it has a word of (bit `letter − b'A'`).
    letters: u32,
    /// Letters it has a word of in a Sinumerik direction form (`C=DC(…)`, …).
    directional: u32,
    /// It has M6, M2 or M30.
    ends: bool,
}

/// The bit of `letter` (`b'A'`…`b'Z'`) in [`After`]'s letter sets.
fn bit(letter: u8) -> u32 {
    1u32.checked_shl(u32::from(letter.wrapping_sub(b'A')))
        .unwrap_or(0)
}

impl<'a> After<'a> {
    /// The block with words `words`, in state `state` after it and `before` before it.
    pub fn new(
        words: &[Word],
        is_move: bool,
        flags: Flags,
        state: &'a Modal,
        before: &'a Modal,
    ) -> Self {
        let mut letters = 0;
        let mut directional = 0;
        let mut ends = false;
        for w in words {
            letters |= bit(w.letter);
            if w.form.is_directional() {
                directional |= bit(w.letter);
            }
            // A T word alone selects the next tool (Fanuc, Sinumerik, LinuxCNC): the
            // change is `M6` (or the reader's tool change: Heidenhain ISO `T5 G17`,
            // `TOOL CALL 5`), and only that frees the end.
            ends |= w.letter == b'M' && (w.value == 6.0 || w.value == 2.0 || w.value == 30.0);
        }
        After {
            is_move,
            flags,
            state,
            before,
            letters,
            directional,
            ends,
        }
    }
}

impl After<'_> {
    /// The positioning move this block is, when it freed the end by moving the rotary axes
    /// to known values (`line` its file line).
    pub fn next_move(&self, letters: RotaryLetters, line: usize) -> Option<NextMove> {
        if !self.is_move {
            return None;
        }
        let (p_idx, c_idx) = (letters.tilt_index(), letters.pole_index());
        let (st, prev) = (self.state, self.before);
        let linear = |i: usize| match (prev.pos[i], st.pos[i]) {
            (Some(a), Some(b)) => Some((b - a).abs()),
            _ => None,
        };
        Some(NextMove {
            line,
            p_deg: st.pos[p_idx]?,
            c_deg: st.pos[c_idx]?,
            linear_mm: [linear(X)?, linear(Y)?, linear(Z)?],
        })
    }

    /// What this block says about the pose of the run's last point before it, for a
    /// program read with the rotary letters `letters`, given what the scan
    /// saw so far (updated: a retract raises the clearance). Module docs.
    pub fn verdict(&self, letters: RotaryLetters, scan: &mut Scan) -> Step {
        let step = self.verdict_executed(letters, scan);
        // A block the operator may skip (block delete) cannot free the end: skipped, the
        // blocks after it move from the run's last pose. As a restatement it is still
        // rewritten (executed, it restates the new values; skipped, it does nothing).
        if step == Step::Free && self.flags.has(Flags::SKIPPABLE) {
            return Step::Pinned;
        }
        step
    }

    /// [`After::verdict`] for a block that is executed.
    fn verdict_executed(&self, letters: RotaryLetters, scan: &mut Scan) -> Step {
        if self.flags.has(Flags::TOOL_CHANGE) || self.flags.has(Flags::PROGRAM_END) || self.ends {
            return Step::Free;
        }
        let has = |l: u8| self.letters & bit(l) != 0;
        let (st, prev) = (self.state, self.before);
        if st.incremental {
            return Step::Pinned;
        }
        let (p_idx, c_idx) = (letters.tilt_index(), letters.pole_index());
        let (has_p, has_c) = (has(letters.tilt), has(letters.pole));
        let rotary_moves = st.pos[p_idx] != prev.pos[p_idx] || st.pos[c_idx] != prev.pos[c_idx];
        let xy_moves = st.pos[X] != prev.pos[X] || st.pos[Y] != prev.pos[Y];
        let z_moves = st.pos[Z] != prev.pos[Z];
        if !self.is_move {
            // A non-move that names a rotary axis (a datum shift on it): be safe.
            return if rotary_moves {
                Step::Pinned
            } else {
                Step::Continue
            };
        }
        // A Z-only move up under TCPM (restating the rotary values or not) is a retract.
        if st.tcpm.is_on()
            && !xy_moves
            && !rotary_moves
            && let (Some(z0), Some(z1)) = (prev.pos[Z], st.pos[Z])
            && z1 > z0
        {
            scan.clearance_mm = Some(scan.clearance_mm.map_or(z1, |c| c.max(z1)));
        }
        if has_p || has_c {
            // A Sinumerik direction form (`C=DC(…)`, `C=ACP(…)`, `C=ACN(…)`) moves from
            // where the axis is: from another pose it reaches another unwrapped position,
            // or turns another way.
            if self.directional & (bit(letters.tilt) | bit(letters.pole)) != 0 {
                return Step::Pinned;
            }
            if !rotary_moves && (st.tcpm.is_on() || !xy_moves) {
                return Step::Restate;
            }
            if has_p && has_c && !xy_moves && !z_moves {
                return Step::Free; // a rotary-only repositioning
            }
            let above =
                |z: Option<f64>| matches!((z, scan.clearance_mm), (Some(z), Some(c)) if z >= c);
            if st.tcpm.is_on() && prev.tcpm.is_on() && above(prev.pos[Z]) && above(st.pos[Z]) {
                return Step::Free; // a positioning move above the clearance
            }
            return Step::Pinned;
        }
        if st.tcpm.is_on() {
            let above = matches!((st.pos[Z], scan.clearance_mm), (Some(z), Some(c)) if z >= c);
            scan.carried_xy |= xy_moves && !above;
            return Step::Continue;
        }
        if xy_moves {
            return Step::Pinned;
        }
        Step::Continue
    }
}

#[cfg(test)]
mod tests {
    /// Planted: the trapezoid's time below and above the distance that reaches v, and the
    /// slowest axis setting a move's time (C turning 180° more costs 180/v).
    #[test]
    fn a_positioning_move_takes_its_slowest_axis_time() {
        assert!((trapezoid_time_s(4.0, 2.0, 1.0) - 4.0).abs() < 1e-12); // d = v²/a: 2·√4
        assert!((trapezoid_time_s(1.0, 2.0, 1.0) - 2.0).abs() < 1e-12);
        assert!((trapezoid_time_s(10.0, 2.0, 1.0) - 7.0).abs() < 1e-12); // 10/2 + 2/1
        assert_eq!(trapezoid_time_s(0.0, 2.0, 1.0), 0.0);
        let m = polepatch_kinematics::Machine::builtin("mikron-ucp710").unwrap();
        let next = NextMove {
            line: 1,
            p_deg: 10.0,
            c_deg: 90.0,
            linear_mm: [0.0; 3],
        };
        let c = &m.limits[4];
        // Both turns beyond v²/a (48° on the UCP710's C): the far one costs 180/v more.
        let t_near = next.time_s(&m, 10.0, -10.0);
        let t_far = next.time_s(&m, 10.0, -190.0);
        assert!((t_near - trapezoid_time_s(100.0, c.v, c.a)).abs() < 1e-12);
        assert!(
            (t_far - t_near - 180.0 / c.v).abs() < 1e-9,
            "{t_near} {t_far}"
        );
    }

    use super::*;
    use crate::stream::load_nc;
    use polepatch_kinematics::Machine;

    fn poses(text: &str) -> Vec<EndPose> {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let lp = load_nc(text.as_bytes(), "t", &m, None).unwrap();
        (0..lp.runs.len()).map(|r| lp.end_pose(r)).collect()
    }

    fn free(text: &str) -> Vec<bool> {
        poses(text).iter().map(|e| e.free).collect()
    }

    const CUT: &str = "M128\nG1 X0 Y0 Z0 A5 C10 F1000\nX1 A4 C20\nX2 A3 C30\n";

    #[test]
    fn program_end_tool_change_and_end_of_file_are_free() {
        assert_eq!(free(&format!("{CUT}M30\n")), [true]);
        assert_eq!(free(&format!("{CUT}T2 M6\nG0 X50 Y50\n")), [true]);
        assert_eq!(free(CUT), [true]);
        assert_eq!(poses(CUT)[0].decided_line, None);
    }

    /// Heidenhain conversational: `TOOL CALL` and `END PGM` free the end as `T… M6` and
    /// `M30` do (the reader's block flags, not the words, say so).
    #[test]
    fn conversational_tool_call_and_end_pgm_are_free() {
        let cut = "BEGIN PGM T MM\nM128\nL X+0 Y+0 Z+0 A+5 C+10 R0 F1000\n\
                   L X+1 A+4 C+20\nL X+2 A+3 C+30\n";
        let e = &poses(&format!(
            "{cut}TOOL CALL 2 Z S1000\nL X+50 Y+50 FMAX\nEND PGM T MM\n"
        ))[0];
        assert!(e.free, "{e:?}");
        assert_eq!(e.decided_line, Some(6));
        let e = &poses(&format!("{cut}M129\nEND PGM T MM\n"))[0];
        assert!(e.free, "{e:?}");
        assert_eq!(e.decided_line, Some(7));
    }

    /// A block the operator may skip cannot free the end: skipped, what follows moves from
    /// the run's last pose.
    #[test]
    fn a_skippable_block_never_frees_the_end() {
        let e = &poses(&format!("{CUT}M129\nG1 Z150\n/A0 C0\nX0 Y0\nM30\n"))[0];
        assert!(!e.free, "{e:?}");
        assert_eq!(e.decided_line, Some(7));
        let e = &poses(&format!("{CUT}/T2 M6\nG0 X50 Y50\nM30\n"))[0];
        assert!(!e.free, "{e:?}");
    }

    /// C17's `%SING` ends with M00, M129, a Z-only retract, a rotary-only move: free.
    #[test]
    fn retract_along_the_tool_axis_then_rotary_only_is_free() {
        let text = format!("{CUT}M00\nM129\nG1 Z150\nA0 C0\nX0 Y0\nM30\n");
        let e = &poses(&text)[0];
        assert!(e.free);
        assert_eq!(e.decided_line, Some(8), "the rotary-only block decides");
    }

    #[test]
    fn tcpm_moves_without_rotary_words_are_free() {
        assert_eq!(
            free(&format!("{CUT}G0 Z50\nG0 X100 Y40\nM129\nM30\n")),
            [true]
        );
    }

    /// Machine-coordinate X/Y moves, one rotary word alone, rotary words with a linear
    /// move below any clearance: the pose matters, the last point stays.
    #[test]
    fn pose_dependent_moves_fix_the_last_point() {
        assert_eq!(free(&format!("{CUT}M129\nG0 X50\nM30\n")), [false]);
        assert_eq!(free(&format!("{CUT}G0 Z50 C0\nM30\n")), [false]);
        assert_eq!(free(&format!("{CUT}G0 Z50 A0 C0\nM30\n")), [false]);
        assert_eq!(free(&format!("{CUT}G91\nG0 Z5\nM30\n")), [false]);
        // A positioning move with no retract before it, or one that descends below the
        // clearance, or with TCPM off.
        assert_eq!(free(&format!("{CUT}G0 X40 Y5 A10 C90\nM30\n")), [false]);
        assert_eq!(
            free(&format!("{CUT}G0 Z50\nG0 X40 Y5 Z20 A10 C90\nM30\n")),
            [false]
        );
        assert_eq!(
            free(&format!("{CUT}G0 Z50\nM129\nG0 X40 Y5 A10 C90\nM30\n")),
            [false]
        );
    }

    /// Issue 21 §3: the way CAM posts start the next pass — a retract, then one
    /// positioning move with X Y and both rotary axes at that clearance under TCPM — leaves
    /// the last point free, decided by the positioning move; a retract that restates the
    /// run's last values is listed for rewriting.
    #[test]
    fn positioning_above_the_clearance_is_free() {
        let e = &poses(&format!("{CUT}G0 Z50\nG0 X40 Y5 A10 C90\nG1 Z0\nM30\n"))[0];
        assert!(e.free, "{e:?}");
        assert_eq!(e.decided_line, Some(6));
        assert!(e.restate.is_empty());
        // With the retract restating A and C (line 5), and the positioning move above it.
        let e = &poses(&format!("{CUT}G0 Z50 A3 C30\nG0 X40 Y5 Z60 A10 C90\nM30\n"))[0];
        assert!(e.free, "{e:?}");
        assert_eq!((e.decided_line, e.restate.clone()), (Some(6), vec![4]));
        // A restating block whose Z is below a later positioning move's start is fine; one
        // that is another run's first point is not rewritten: pinned.
        let e = &poses(&format!("{CUT}G0 Z50 A3 C30\nG1 Z0 F500\nX5\nM30\n"))[0];
        assert!(!e.free, "{e:?}");
    }

    /// A change of feed mode (G94 to G93) splits the motion into two runs sharing a point:
    /// when the second run's first move programs the rotary axes, the first run's end
    /// stays. A change of F under G94 does not split it (issue 41: the pass is the unit).
    #[test]
    fn a_run_continued_by_the_next_keeps_its_end() {
        let text = format!("{CUT}G93 X3 A2 C40 F60\nX4 A1 C50 F60\nM30\n");
        assert_eq!(free(&text), [false, true]);
        let text = format!("{CUT}G93 X3 F60\nX4 F60\nM30\n");
        assert_eq!(free(&text), [true, true]);
        let text = format!("{CUT}X3 A2 C40 F2000\nX4 A1 C50\nM30\n");
        assert_eq!(free(&text), [true]);
    }
}
