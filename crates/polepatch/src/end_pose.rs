//! Whether a run may end in another pose than the program's.
//!
//! A patch may change the values of a run's last point — and a branch re-selection puts the
//! last point on the other IK branch, `(P, C) → (−P, C ± 180°)`: the same tool axis, but
//! the table turned half a revolution about it. What happens after the run then moves from
//! that pose. Writing the program's values back into the next move (a "restoring" word)
//! does not help: that move would then swing the table during its own motion — with TCPM
//! off and the tool still at the part, that moves the part under the tool.
//!
//! So the last point of a run may change only when every move after it, up to the block
//! that programs both rotary axes again, is independent of the pose:
//! - a move with TCPM active and no rotary word (the controller keeps the tool axis and
//!   moves the tool tip in part coordinates: the same motion relative to the part);
//! - a move with TCPM off and no rotary word that changes only Z (along the tool axis, which
//!   both poses share);
//! - the block that programs both rotary axes again counts when it moves nothing else (a
//!   rotary-only repositioning, as the program already had there);
//! - a tool change (T, M6) or the program's end (M2, M30), or the end of the file, ends the
//!   scan (free).
//!
//! Anything else — a move with X or Y in machine coordinates, a move that programs one
//! rotary axis alone, a rotary word together with a linear move, incremental mode — fixes
//! the last point (`keep_last_point`). No rotary word is ever written after a run's last
//! point. (A next run that starts at this run's last block is covered by the same rules:
//! if its first move programs the rotary axes, the last point stays; if not, its rotary
//! values are the modal ones, whatever they are.)

use crate::program::LoadedProgram;
use polepatch_nc::modal::{C, X, Y};
use polepatch_nc::{Modal, Word};

/// Whether the moves after run `r` of `lp` are independent of the pose its last point is
/// in (module docs).
pub fn end_pose_is_free(lp: &LoadedProgram, r: usize) -> bool {
    if let Some(w) = &lp.window {
        return w.end_free[r];
    }
    let program = &lp.program;
    let run = &lp.runs[r].run;
    let Some(&last) = run.blocks.last() else {
        return false;
    };
    let mut prev = program.state(last);
    for b in last + 1..program.blocks.len() {
        let st = program.state(b);
        let after = After {
            words: program.block_words(b),
            is_move: program.blocks[b].is_move,
            state: &st,
            before: &prev,
        };
        if let Some(free) = after.verdict(lp.primary_letter) {
            return free;
        }
        prev = st;
    }
    true
}

/// One block after a run's last point, for [`After::verdict`].
#[derive(Debug, Clone, Copy)]
pub struct After<'a> {
    /// Its words.
    pub words: &'a [Word],
    /// It moves ([`polepatch_nc::Block::is_move`]).
    pub is_move: bool,
    /// The modal state after it.
    pub state: &'a Modal,
    /// The modal state before it.
    pub before: &'a Modal,
}

impl After<'_> {
    /// What this block says about the pose of the last point before it, for a program
    /// whose tilting letter is `primary` (`b'A'` or `b'B'`): `Some(true)` free,
    /// `Some(false)` fixed, `None` the next block decides (module docs). The answer for a
    /// run is that of the first block after it that decides, free at the end of the file.
    pub fn verdict(&self, primary: u8) -> Option<bool> {
        let has = |l: u8| self.words.iter().any(|w| w.letter == l);
        let m_code = |v: f64| self.words.iter().any(|w| w.letter == b'M' && w.value == v);
        if has(b'T') || m_code(6.0) || m_code(2.0) || m_code(30.0) {
            return Some(true);
        }
        let (st, prev) = (self.state, self.before);
        if st.incremental {
            return Some(false);
        }
        let p_idx = if primary == b'A' {
            polepatch_nc::modal::A
        } else {
            polepatch_nc::modal::B
        };
        let (has_p, has_c) = (has(primary), has(b'C'));
        let linear_moves = st.pos[..3] != prev.pos[..3];
        if self.is_move {
            if has_p && has_c {
                return Some(!linear_moves);
            }
            if has_p || has_c {
                return Some(false);
            }
            let xy_moves = st.pos[X] != prev.pos[X] || st.pos[Y] != prev.pos[Y];
            if !st.tcpm.is_on() && xy_moves {
                return Some(false);
            }
        } else if st.pos[p_idx] != prev.pos[p_idx] || st.pos[C] != prev.pos[C] {
            // A non-move that names a rotary axis (a datum shift on it): be safe.
            return Some(false);
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::program::load_nc;
    use polepatch_kinematics::Machine;

    fn free(text: &str) -> Vec<bool> {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let lp = load_nc(text.as_bytes().to_vec(), "t", &m, None).unwrap();
        (0..lp.runs.len())
            .map(|r| end_pose_is_free(&lp, r))
            .collect()
    }

    const CUT: &str = "M128\nG1 X0 Y0 Z0 A5 C10 F1000\nX1 A4 C20\nX2 A3 C30\n";

    #[test]
    fn program_end_tool_change_and_end_of_file_are_free() {
        assert_eq!(free(&format!("{CUT}M30\n")), [true]);
        assert_eq!(free(&format!("{CUT}T2 M6\nG0 X50 Y50\n")), [true]);
        assert_eq!(free(CUT), [true]);
    }

    /// C17's `%SING` ends with M00, M129, a Z-only retract, a rotary-only move: free.
    #[test]
    fn retract_along_the_tool_axis_then_rotary_only_is_free() {
        let text = format!("{CUT}M00\nM129\nG1 Z150\nA0 C0\nX0 Y0\nM30\n");
        assert!(free(&text)[0]);
    }

    #[test]
    fn tcpm_moves_without_rotary_words_are_free() {
        assert_eq!(
            free(&format!("{CUT}G0 Z50\nG0 X100 Y40\nM129\nM30\n")),
            [true]
        );
    }

    /// Machine-coordinate X/Y moves, one rotary word alone, rotary words with a linear
    /// move: the pose matters, the last point stays.
    #[test]
    fn pose_dependent_moves_fix_the_last_point() {
        assert_eq!(free(&format!("{CUT}M129\nG0 X50\nM30\n")), [false]);
        assert_eq!(free(&format!("{CUT}G0 Z50 C0\nM30\n")), [false]);
        assert_eq!(free(&format!("{CUT}G0 Z50 A0 C0\nM30\n")), [false]);
        assert_eq!(free(&format!("{CUT}G91\nG0 Z5\nM30\n")), [false]);
    }

    /// A feed change splits the motion into two runs sharing a point: when the second
    /// run's first move programs the rotary axes, the first run's end stays.
    #[test]
    fn a_run_continued_by_the_next_keeps_its_end() {
        let text = format!("{CUT}X3 A2 C40 F2000\nX4 A1 C50\nM30\n");
        assert_eq!(free(&text), [false, true]);
        let text = format!("{CUT}X3 F2000\nX4\nM30\n");
        assert_eq!(free(&text), [true, true]);
    }
}
