//! What the check of a written program against its input finds ([`crate::verify`]): a
//! [`Violation`] names the line and the [`Check`]. Its own room, importing nothing of the
//! crate, so that an [`crate::Error`] can carry violations.

/// What a check is about ([`Violation::check`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Check {
    /// The programs have different numbers of lines (a line added or deleted).
    Lines,
    /// A line differs outside the words a patch may change.
    Text,
    /// The modal state after a line differs (feed, motion, TCPM, units, …).
    State,
    /// The tool's reference point moved (a ball's centre, else the programmed point).
    ReferencePoint,
    /// A positioning move's X Y Z target moved, or its rotary values changed without TCPM.
    PositioningTarget,
    /// The orientation change exceeds its bound.
    Deviation,
    /// Values changed where nothing may change (no TCPM and no chain, TCPM unknown, an arc,
    /// incremental mode, …).
    Untouchable,
    /// The runs of the two programs do not pair (a block's motion changed).
    RunStructure,
    /// Equation 6 lower on a span of a run of the written program.
    FeedRatio,
    /// A run's estimated time greater.
    RunTime,
    /// The program's estimated time (runs and positioning moves) greater.
    ProgramTime,
    /// A zone the report calls reached does not reach feed in the written program.
    ReportedReached,
}

impl Check {
    /// The name in reports: `reference_point`, `feed_ratio`, ….
    pub fn name(self) -> &'static str {
        match self {
            Check::Lines => "lines",
            Check::Text => "text",
            Check::State => "state",
            Check::ReferencePoint => "reference_point",
            Check::PositioningTarget => "positioning_target",
            Check::Deviation => "deviation",
            Check::Untouchable => "untouchable",
            Check::RunStructure => "run_structure",
            Check::FeedRatio => "feed_ratio",
            Check::RunTime => "run_time",
            Check::ProgramTime => "program_time",
            Check::ReportedReached => "reported_reached",
        }
    }
}

/// One thing that does not hold.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Violation {
    /// 1-based line of the patched program it is about (0: the program as a whole).
    pub line: usize,
    /// Which check.
    pub check: Check,
    /// What, for people (values in mm and degrees).
    pub message: String,
}
