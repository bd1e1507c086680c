//! Runs of G1 motion with cumulative tool-tip path length s.

use crate::program::Program;

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
    /// Cumulative tool-tip path length at each point, mm (s[0] = 0, strictly increasing).
    pub s_mm: Vec<f64>,
    /// Position of each point: X Y Z (mm), A B C (degrees), `None` where never programmed.
    pub pos: Vec<[Option<f64>; 6]>,
    /// Programmed feed, mm/min (`None` if no F is in force).
    pub feed_mm_min: Option<f64>,
    /// TCPM state during the run.
    pub tcpm: bool,
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
pub fn runs(program: &Program) -> Vec<Run> {
    let _ = program;
    todo!()
}
