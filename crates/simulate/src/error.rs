//! Bad input to the simulator (an error), kept apart from what the simulation found.

use polepatch_patcher::PathError;

/// Why a motion cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A part of the motion is not a valid path (too short, not increasing, not finite,
    /// bad feed); `part` counts from 0.
    #[error("part {part} of the motion: {source}")]
    Path {
        /// Index of the part.
        part: usize,
        /// What is wrong with it.
        source: PathError,
    },
    /// No part at all.
    #[error("nothing to simulate: the motion has no part")]
    Empty,
    /// Two consecutive parts do not share their boundary point (the last point of one
    /// must be the first point of the next).
    #[error(
        "part {part} starts at {start:?}, not where part {previous} ends ({end:?}): parts of one motion must share their boundary point"
    )]
    NotJoined {
        /// Index of the part.
        part: usize,
        /// Index of the part before it.
        previous: usize,
        /// Its first point, X Y Z P C.
        start: [f64; 5],
        /// The end of the part before, X Y Z P C.
        end: [f64; 5],
    },
    /// The limits allow no motion at a point of the path (a limit curve of 0 there).
    #[error("the limits allow no motion at s = {s_mm} mm of the path")]
    Stalled {
        /// Where, mm along the motion.
        s_mm: f64,
    },
    /// The interpolation cycle time is not positive and finite, s.
    #[error("interpolation cycle time must be positive and finite, got {0} s")]
    BadCycleTime(f64),
}
