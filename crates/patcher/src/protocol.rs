//! The protocol between the driver and the methods (ripgrep's `Searcher` + `Sink`): a
//! method ([`Proposer`]) sees one zone ([`ZoneCtx`]) and offers [`Proposal`]s to a
//! [`Sink`]; the driver ([`crate::driver`]) owns the sink, rounds and verifies what it is
//! offered and keeps the best. Nothing here names a method or the driver: the methods and
//! the driver both stand on this module, and the strategy table ([`crate::strategy`])
//! hands the methods to the driver.

use crate::{
    analysis::Zone,
    options::PatchOptions,
    report::{Method, QpStats},
    settings::SolverSettings,
};
use polepatch_kinematics::Machine;
use std::ops::Range;

/// What happens to the points after a candidate's last point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tail {
    /// They keep their values.
    Keep,
    /// They move to the other IK branch as a block, `(P, C) → (−P, C + shift)`: the same
    /// tool axes, every derivative's size kept.
    Reselect {
        /// ±180°.
        shift_deg: f64,
    },
    /// C gets a 360° multiple added (`--c-offset`, the C-only method).
    COffset {
        /// The multiple of 360°.
        deg: f64,
    },
}

/// A method's proposal for a zone: new (unrounded) values for points `first..=last`.
#[derive(Debug, Clone)]
pub struct Proposal {
    /// The method that made it.
    pub method: Method,
    /// First point with new values.
    pub first: usize,
    /// Last point with new values.
    pub last: usize,
    /// New primary values for `first..=last`, degrees.
    pub p: Vec<f64>,
    /// New C values for `first..=last`, degrees.
    pub c: Vec<f64>,
    /// The points after `last`.
    pub tail: Tail,
    /// Solver statistics of the solves that made it.
    pub qp: QpStats,
}

/// What the driver says about a proposal it was offered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Offered {
    /// Reaches feed over the zone's core and nothing got worse, as written.
    pub passes: bool,
    /// Exact largest orientation change, degrees, as written.
    pub deviation_deg: f64,
}

/// Where a method hands its proposals (the driver's checker).
pub trait Sink {
    /// Round, verify and consider `p`; `None` when it cannot be evaluated (non-finite
    /// values, a range the zone may not change).
    fn offer(&mut self, p: Proposal) -> Option<Offered>;
    /// Add the statistics of solves that made no proposal.
    fn add_stats(&mut self, qp: &QpStats);
    /// The smallest deviation of a passing proposal so far (within the cap), degrees.
    fn best_passing_deg(&self) -> Option<f64>;
}

/// What a method sees of one zone.
pub struct ZoneCtx<'a> {
    /// Path length per point, mm.
    pub s: &'a [f64],
    /// The program's tool axes (what every change is measured against).
    pub target: &'a [[f64; 3]],
    /// Per point, the most its orientation may change, degrees: the safety bound near the
    /// pole ([`crate::driver::pole_bound_deg`]); a proposal beyond it is refused.
    pub bound_deg: &'a [f64],
    /// The machine.
    pub machine: &'a Machine,
    /// The caller's options.
    pub opts: &'a PatchOptions,
    /// Numerical settings.
    pub settings: &'a SolverSettings,
    /// Programmed feed, mm/min.
    pub feed_mm_min: f64,
    /// The zone.
    pub zone: &'a Zone,
    /// The spans that must reach feed (the zone ± the core margin).
    pub core: Range<usize>,
    /// First point a proposal may change.
    pub lower: usize,
    /// Last point a proposal may change (the run's last, or the one before it when the
    /// last must stay).
    pub end: usize,
    /// Current primary values of the whole path, degrees.
    pub p: &'a [f64],
    /// Current C values of the whole path, degrees.
    pub c: &'a [f64],
    /// The margin on the limits for this rung of the ladder.
    pub margin: f64,
    /// Index of the rung (0: the configured margin).
    pub rung: usize,
}

/// A method: proposes candidates for a zone.
pub trait Proposer {
    /// Offer candidates for `ctx`'s zone to `sink`.
    fn propose(&mut self, ctx: &ZoneCtx<'_>, sink: &mut dyn Sink);
}
