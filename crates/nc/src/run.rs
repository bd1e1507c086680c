//! Runs of G1 motion with cumulative tool-tip path length s.

use crate::modal::{A, B, C, Modal, RotaryLetters, X, Y, Z};

use crate::block::Block;
use crate::program::Program;
pub use crate::tolerances::ZERO_LENGTH_MM;

/// Why a run ended (for reports).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunBreak {
    /// End of program.
    End,
    /// A G0/G2/G3 move or a block that stops or changes the machine state (tool change,
    /// M00/M01/M02/M30, TCPM on/off, datum shift, reference move).
    Block,
    /// The programmed feed changed.
    FeedChange,
    /// A G1 block without tool-tip motion (kept as it is, never moved).
    ZeroLength,
}

/// A maximal sequence of G1 blocks with constant F, constant TCPM state, tool-tip motion
/// in every block. Point 0 is the position the run starts from (the end of `blocks[0]`,
/// which is not part of the run's motion); point k ≥ 1 is the end of block `blocks[k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Block index of each point (see type docs).
    pub blocks: Vec<usize>,
    /// Cumulative tool-tip path length at each point, mm (`s[0] = 0`, strictly increasing).
    pub s_mm: Vec<f64>,
    /// Position of each point: X Y Z (mm), A B C (degrees), `None` where never programmed.
    pub pos: Vec<[Option<f64>; 6]>,
    /// Programmed feed, mm/min (`None` if no F is in force, and under G93 and G95).
    pub feed_mm_min: Option<f64>,
    /// Feed mode of the run (a change of feed mode ends runs).
    pub feed_mode: crate::FeedMode,
    /// The feed of each block along the tool tip, mm/min, for blocks `1..len()`, where the
    /// blocks have their own: under G93 (inverse time) a block's tool-tip length times its
    /// F (1/min); in a pass whose F changes under G94 ([`RunBuilder::passes`]) each block's
    /// F. Empty otherwise (every block at [`Run::feed_mm_min`]).
    pub block_feed_mm_min: Vec<f64>,
    /// TCPM state during the run (only [`crate::Tcpm::On`] allows changing rotary words
    /// alone).
    pub tcpm: crate::Tcpm,
    /// Frame transformations in force during the run (bits of [`crate::modal::transform`]:
    /// rotation, scaling, mirror image); 0 where none.
    pub transform: u8,
    /// The TCPM code in force refers X Y Z to the centre of a ball
    /// ([`crate::Modal::tcpm_centre`]).
    pub tcpm_centre: bool,
    /// Why the run ended.
    pub ended_by: RunBreak,
}

impl Run {
    /// Number of points (blocks + 1).
    pub fn len(&self) -> usize {
        self.s_mm.len()
    }
    /// Whether the run has no points (never true for a run from [`runs`]).
    pub fn is_empty(&self) -> bool {
        self.s_mm.is_empty()
    }
    /// Total path length, mm.
    pub fn length_mm(&self) -> f64 {
        self.s_mm.last().copied().unwrap_or(0.0)
    }
}

/// The runs of a program (each with at least 2 points), in file order.
///
/// Walking the blocks: a block that breaks runs ([`crate::Block::breaks_run`], which
/// includes every G0/G2/G3 move) ends the current run. A G1 move with tool-tip motion
/// extends the current run, or starts one from the block that established its start
/// position (ending the current run first if F or the TCPM state differs). A G1 move
/// whose start or end X Y Z is unknown, or whose tool-tip length is zero (only rotary
/// motion, or nothing moving), ends the current run and becomes point 0 of the next one.
/// Other blocks (comments, S, coolant, an F alone) are skipped.
pub fn runs(program: &Program) -> Vec<Run> {
    let mut out = Vec::new();
    let mut builder = RunBuilder::default();
    let mut cur_state = Modal::default();
    for (i, b) in program.blocks.iter().enumerate() {
        if b.state_index()
            != program
                .blocks
                .get(i.wrapping_sub(1))
                .map_or(0, |p| p.state_index())
        {
            cur_state = program.state(i);
        }
        builder.push(i, b, &cur_state, &mut |r| out.push(r));
    }
    builder.finish(&mut |r| out.push(r));
    out
}

/// The run-finding walk of [`runs`], one block at a time, for callers that read a
/// program as a stream ([`crate::scan`]) and want each run as it ends instead of
/// a [`Program`] and all runs at once.
#[derive(Debug, Clone, Default)]
pub struct RunBuilder {
    cur: Option<Run>,
    prev: Modal,
    last_pos: Option<usize>,
    /// A change of F under G94 does not end the run ([`RunBuilder::passes`]).
    passes: bool,
}

impl RunBuilder {
    /// A walk whose runs are **passes**: a change of F under G94 (both feeds known) does not
    /// end the run — the machine moves through it without stopping — and each block keeps
    /// its own F ([`Run::block_feed_mm_min`]). Everything else ends runs as
    /// [`RunBuilder::default`]'s walk does (SPEC §4b: the pass is the unit the patch sees).
    pub fn passes() -> RunBuilder {
        RunBuilder {
            passes: true,
            ..RunBuilder::default()
        }
    }

    /// The walk of a kind: passes ([`RunBuilder::passes`]) or runs ([`RunBuilder::default`]).
    pub fn of_kind(passes: bool) -> RunBuilder {
        if passes {
            RunBuilder::passes()
        } else {
            RunBuilder::default()
        }
    }

    /// The walk taken up at block `first` (`st`: the state after it) for the run that
    /// starts there, as the walk of the whole file (`passes` or not) found it: the blocks
    /// after `first` give the same run, which starts at `first` whether the whole walk had
    /// opened it there or only noted `first` as the last place the tool was. For a reader
    /// that reads again only the stretch of a run ([`crate::scan_resumed`]). A run that
    /// ends at the stretch's end is given by [`RunBuilder::finish`], with
    /// [`RunBreak::End`]: the caller knows what ended it in the file.
    pub fn resumed_at(passes: bool, first: usize, st: &Modal) -> RunBuilder {
        RunBuilder {
            cur: None,
            prev: *st,
            last_pos: Some(first),
            passes,
        }
    }

    fn finish_run(&mut self, why: RunBreak, emit: &mut impl FnMut(Run)) {
        if let Some(mut r) = self.cur.take()
            && r.len() >= 2
        {
            r.ended_by = why;
            emit(r);
        }
    }

    fn start(block: usize, st: &Modal) -> Run {
        Run {
            blocks: vec![block],
            s_mm: vec![0.0],
            pos: vec![st.pos],
            feed_mm_min: st.feed_mm_min,
            feed_mode: st.feed_mode,
            block_feed_mm_min: Vec::new(),
            tcpm: st.tcpm,
            transform: st.transform,
            tcpm_centre: st.tcpm_centre,
            ended_by: RunBreak::End,
        }
    }

    /// Take block `i` (`b`, with `st` the modal state after it); `emit` gets the run it
    /// ends, if any.
    pub fn push(&mut self, i: usize, b: &Block, st: &Modal, emit: &mut impl FnMut(Run)) {
        if b.breaks_run {
            self.finish_run(RunBreak::Block, emit);
        } else if b.is_move {
            match (xyz(&self.prev.pos), xyz(&st.pos)) {
                (Some(p0), Some(p1)) => {
                    let d = ((p1[0] - p0[0]).powi(2)
                        + (p1[1] - p0[1]).powi(2)
                        + (p1[2] - p0[2]).powi(2))
                    .sqrt();
                    let inverse_time = st.feed_mode == crate::FeedMode::InverseTime;
                    if d <= ZERO_LENGTH_MM {
                        self.finish_run(RunBreak::ZeroLength, emit);
                        self.cur = Some(Self::start(i, st));
                    } else if inverse_time && st.inverse_time_per_min.is_none() {
                        // A G93 move without F has no time (controllers alarm): it is not
                        // part of any run.
                        self.finish_run(RunBreak::Block, emit);
                        self.cur = Some(Self::start(i, st));
                    } else {
                        // A pass goes on through a change of F under G94: the blocks
                        // so far keep theirs, and each block after states its own.
                        let joins = self.passes
                            && st.feed_mm_min.is_some()
                            && !inverse_time
                            && self.cur.as_ref().is_some_and(|r| {
                                r.len() >= 2
                                    && r.feed_mode == crate::FeedMode::PerMinute
                                    && r.tcpm == st.tcpm
                                    && r.transform == st.transform
                                    && (r.feed_mm_min.is_some() || !r.block_feed_mm_min.is_empty())
                            });
                        if joins {
                            if let Some(r) = &mut self.cur
                                && r.feed_mm_min != st.feed_mm_min
                                && let Some(g) = r.feed_mm_min.take()
                            {
                                r.block_feed_mm_min = vec![g; r.len() - 1];
                            }
                        } else if let Some(r) = &mut self.cur
                            && (r.feed_mm_min != st.feed_mm_min
                                || r.tcpm != st.tcpm
                                || r.transform != st.transform)
                        {
                            if r.len() == 1 {
                                r.feed_mm_min = st.feed_mm_min;
                                r.feed_mode = st.feed_mode;
                                r.tcpm = st.tcpm;
                                r.transform = st.transform;
                                r.tcpm_centre = st.tcpm_centre;
                            } else {
                                self.finish_run(RunBreak::FeedChange, emit);
                            }
                        }
                        let (last_pos, prev) = (self.last_pos, &self.prev);
                        let r = self.cur.get_or_insert_with(|| {
                            let mut r = Self::start(last_pos.unwrap_or(i), prev);
                            r.feed_mm_min = st.feed_mm_min;
                            r.feed_mode = st.feed_mode;
                            r.tcpm = st.tcpm;
                            r.transform = st.transform;
                            r.tcpm_centre = st.tcpm_centre;
                            r
                        });
                        // A rotary axis first programmed by this move: its motion over the
                        // move, from a value the program never stated, is unknown — the run
                        // starts at this move's end instead (that point never changes).
                        if r.len() == 1
                            && [A, B, C]
                                .iter()
                                .any(|&k| r.pos[0][k].is_none() && st.pos[k].is_some())
                        {
                            *r = Self::start(i, st);
                        } else {
                            let s = r.length_mm() + d;
                            r.blocks.push(i);
                            r.s_mm.push(s);
                            r.pos.push(st.pos);
                            if let Some(f) = st.inverse_time_per_min.filter(|_| inverse_time) {
                                r.block_feed_mm_min.push(d * f);
                            } else if !r.block_feed_mm_min.is_empty()
                                && let Some(f) = st.feed_mm_min
                            {
                                r.block_feed_mm_min.push(f);
                            }
                        }
                    }
                }
                _ => {
                    self.finish_run(RunBreak::Block, emit);
                    self.cur = Some(Self::start(i, st));
                }
            }
        }
        if b.is_move || st.pos != self.prev.pos {
            self.last_pos = Some(i);
        }
        self.prev = *st;
    }

    /// The last block of the run in progress, when it has two points or more (it will be
    /// given to `emit` when a later block ends it, or by [`RunBuilder::finish`]).
    pub fn open_run_last_block(&self) -> Option<usize> {
        self.cur
            .as_ref()
            .filter(|r| r.len() >= 2)
            .and_then(|r| r.blocks.last().copied())
    }

    /// The first block of the run in progress (its point 0), if one is open.
    pub fn open_run_first_block(&self) -> Option<usize> {
        self.cur.as_ref().and_then(|r| r.blocks.first().copied())
    }

    /// The end of the program: `emit` gets the run in progress, if any.
    pub fn finish(&mut self, emit: &mut impl FnMut(Run)) {
        self.finish_run(RunBreak::End, emit);
    }
}

fn xyz(pos: &[Option<f64>; 6]) -> Option<[f64; 3]> {
    Some([pos[X]?, pos[Y]?, pos[Z]?])
}

impl Run {
    /// Per point `[X, Y, Z, P, C]` (mm, mm, mm, degrees, degrees), P the tilting axis and
    /// C the pole axis of `letters` (A and C, B and C, or another pair). A value never
    /// programmed reads as 0.
    pub fn axes5(&self, letters: crate::modal::RotaryLetters) -> Vec<[f64; 5]> {
        use crate::modal::{X, Y, Z};
        let (p_idx, c_idx) = (letters.tilt_index(), letters.pole_index());
        self.pos
            .iter()
            .map(|p| {
                let v = |i: usize| p[i].unwrap_or(0.0);
                [v(X), v(Y), v(Z), v(p_idx), v(c_idx)]
            })
            .collect()
    }

    /// Whether any point of the run has a value at index `axis` of [`Run::pos`].
    pub fn uses(&self, axis: usize) -> bool {
        self.pos.iter().any(|p| p[axis].is_some())
    }
}

/// The rotary letters the runs use: `preferred` (the machine's), unless the runs never
/// program its tilting letter but do program the third letter of A B C
/// ([`RotaryLetters::other`]): then that one is read as the tilting axis (a program posted
/// for another machine, which the caller refuses or reports).
pub fn primary_in_use(runs: &[Run], preferred: RotaryLetters) -> RotaryLetters {
    let mut uses = [false; 6];
    for (i, u) in uses.iter_mut().enumerate() {
        *u = runs.iter().any(|r| r.uses(i));
    }
    primary_of(&uses, preferred)
}

/// [`primary_in_use`] from which of X Y Z A B C the runs use (index as
/// [`crate::Modal::pos`]), for callers that read runs one at a time.
pub fn primary_of(uses: &[bool; 6], preferred: RotaryLetters) -> RotaryLetters {
    let other = preferred.other();
    let other_idx = crate::modal::axis_index(other).unwrap_or(crate::modal::B);
    if !uses[preferred.tilt_index()] && uses[other_idx] {
        preferred.with_tilt(other)
    } else {
        preferred
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modal::{A, C};
    use crate::{Dialect, parse};

    fn runs_of(s: &str) -> (Program, Vec<Run>) {
        let p = parse(s.as_bytes().to_vec(), Dialect::Auto).unwrap();
        let r = runs(&p);
        (p, r)
    }

    #[test]
    fn planted_run() {
        let (_, r) =
            runs_of("G0 X0 Y0 Z0\nG1 X3 Y4 F100 C10\n; note\nX6 Y8 C20\nM8\nX6 Y8 Z10\nG0 Z50\n");
        assert_eq!(r.len(), 1);
        // C is first programmed by the first G1 move (its motion from the unknown value is
        // unknown): the run starts at that move's end.
        assert_eq!(r[0].blocks, vec![1, 3, 5]);
        assert_eq!(r[0].s_mm, vec![0.0, 5.0, 15.0]);
        assert_eq!(r[0].pos[1][C], Some(20.0));
        assert_eq!(r[0].pos[0][C], Some(10.0));
        assert_eq!(r[0].feed_mm_min, Some(100.0));
        assert_eq!(r[0].ended_by, RunBreak::Block);
    }

    #[test]
    fn zero_length_block_splits_and_is_not_moved() {
        let (_, r) = runs_of("G1 X0 Y0 Z0 F100\nX1\nX2\nA10 C5\nX3\nX4\n");
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].blocks, vec![0, 1, 2]);
        assert_eq!(r[0].ended_by, RunBreak::ZeroLength);
        assert_eq!(r[1].blocks, vec![3, 4, 5]);
        assert_eq!(r[1].pos[0][A], Some(10.0));
        assert_eq!(r[1].ended_by, RunBreak::End);
    }

    #[test]
    fn feed_change_shares_the_boundary_point() {
        let (_, r) = runs_of("G1 X0 Y0 Z0 F100\nX1\nX2\nF200\nX3\nX4 F300\n");
        assert_eq!(r.len(), 3);
        assert_eq!(r[0].blocks, vec![0, 1, 2]);
        assert_eq!(r[0].ended_by, RunBreak::FeedChange);
        assert_eq!(r[1].blocks, vec![2, 4]);
        assert_eq!(r[1].feed_mm_min, Some(200.0));
        assert_eq!(r[2].blocks, vec![4, 5]);
        assert_eq!(r[2].feed_mm_min, Some(300.0));
    }

    /// Under G93 each block's feed is its length times its F; different feeds do not split
    /// the run (its analysis takes each block at its own feed).
    #[test]
    fn inverse_time_runs_keep_each_blocks_feed() {
        let (_, r) =
            runs_of("G93 G1 X0 Y0 Z0 A1 F10\nX3 Y4 F200\nX6 Y8 F100\nX6 Y8 Z5 F20\nG94 F500\nX7\n");
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].blocks, vec![0, 1, 2, 3]);
        assert_eq!(r[0].feed_mm_min, None);
        assert_eq!(r[0].feed_mode, crate::FeedMode::InverseTime);
        assert_eq!(r[0].block_feed_mm_min, vec![1000.0, 500.0, 100.0]);
        assert_eq!(r[1].feed_mm_min, Some(500.0));
        assert!(r[1].block_feed_mm_min.is_empty());
        // A G93 move without F belongs to no run.
        let (_, r) = runs_of("G93 G1 X0 Y0 Z0 F10\nX1 F10\nX2\nX3 F10\nX4 F10\n");
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].blocks, vec![0, 1]);
        assert_eq!(r[1].blocks, vec![2, 3, 4]);
    }

    #[test]
    fn unknown_start_starts_at_the_end_point() {
        let (_, r) = runs_of("G1 Z5 F100\nX0 Y0\nX1\nG92 X0 Y0 Z0\nG1 X1 Y1 Z1\nX2\n");
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].blocks, vec![1, 2]);
        assert_eq!(r[1].blocks, vec![4, 5]);
    }

    #[test]
    fn primary_in_use_prefers_the_machine_letter_and_falls_back() {
        let prog = crate::parse(
            b"G1 X0 Y0 Z0 B5 C0 F1000\nX1 B4 C10\nX2 B3 C20\n".to_vec(),
            crate::Dialect::Auto,
        )
        .unwrap();
        let rs = runs(&prog);
        use crate::modal::RotaryLetters;
        assert_eq!(primary_in_use(&rs, RotaryLetters::AC), RotaryLetters::BC);
        assert_eq!(primary_in_use(&rs, RotaryLetters::BC), RotaryLetters::BC);
        // For an A-B trunnion (pole B) the program tilts with C, the letter it lacks; read
        // with the machine's letters, B is its pole axis and A, never programmed, 0.
        let ab = RotaryLetters::new(b'A', b'B').unwrap();
        assert_eq!(ab.other(), b'C');
        assert_eq!(primary_in_use(&rs, ab), ab.with_tilt(b'C'));
        assert_eq!(rs[0].axes5(ab).last().unwrap(), &[2.0, 0.0, 0.0, 0.0, 3.0]);
        assert_eq!(
            rs[0].axes5(crate::modal::RotaryLetters::BC).last().unwrap(),
            &[2.0, 0.0, 0.0, 3.0, 20.0]
        );
    }
}
