//! Equation 6 of G16: the feed bound from geometric derivatives along the path.
//!
//! With s̈ = s⃛ = 0 at a local feed minimum, for each axis q with derivatives
//! q_s, q_ss, q_sss along the tool-tip path length s:
//!
//! ```text
//! ṡ ≤ min( F, V/|q_s|, sqrt(A/|q_ss|), cbrt(J/|q_sss|) )   over axes      (eq. 6)
//! ```

use crate::machine::{Axis, AxisLimits, Machine};
use serde::Serialize;

/// Which term of Equation 6 binds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum LimitKind {
    /// The programmed feed itself (nothing else limits).
    Feed,
    /// The axis velocity limit V.
    Velocity,
    /// The axis acceleration limit A.
    Acceleration,
    /// The axis jerk limit J.
    Jerk,
}

/// The bound of one axis: min(V/|q_s|, sqrt(A/|q_ss|), cbrt(J/|q_sss|)) in mm/s and the
/// term that gives it. A zero derivative gives +∞ for its term.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AxisBound {
    /// Bound on the feed, mm/s (may be +∞).
    pub feed_mm_s: f64,
    /// Binding term (never `Feed`).
    pub kind: LimitKind,
}

/// The overall bound at one path parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FeedBound {
    /// Reachable feed, mm/s, ≤ the programmed feed.
    pub feed_mm_s: f64,
    /// `feed_mm_s / programmed feed`, in (0, 1].
    pub ratio: f64,
    /// Limiting axis, `None` when the programmed feed binds.
    pub axis: Option<Axis>,
    /// Binding term.
    pub kind: LimitKind,
}

/// Equation 6 for one axis. `d = [q_s, q_ss, q_sss]` per mm (mm/mm or °/mm^k).
pub fn axis_feed_bound(limits: &AxisLimits, d: [f64; 3]) -> AxisBound {
    let _ = (limits, d);
    todo!()
}

/// Equation 6 over all axes. `d[axis] = [q_s, q_ss, q_sss]` in [`Axis`] order; `feed_mm_s`
/// is the programmed feed. Ties go to the earlier axis and the earlier term.
pub fn feed_bound(machine: &Machine, d: &[[f64; 3]; 5], feed_mm_s: f64) -> FeedBound {
    let _ = (machine, d, feed_mm_s);
    todo!()
}
