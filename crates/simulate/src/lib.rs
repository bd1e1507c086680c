//! How long a jerk-limited controller takes along a program's path: a trajectory within
//! every axis' V, A and J and the programmed feed, as fast as those allow.
//!
//! Equation 6 (`polepatch_kinematics::feed`) bounds the feed at each point of a path with
//! s̈ = s⃛ = 0; its time estimate ∫ds/ṡ ignores the time the machine needs to change
//! speed between points. This crate builds the motion itself.
//!
//! # The path
//! A *motion* is one or more runs that follow one another without a stop (a feed change
//! between two runs: they share a point). Its path is the analysis spline
//! (`polepatch_patcher::spline`: the not-a-knot cubic of each axis over s, the
//! interpolation Equation 6 uses) through all their points; s is the tool-tip path length
//! the programmed feed refers to. The motion starts and ends at rest.
//!
//! # The method
//! With v = ṡ, a = s̈, j = s⃛ and the chain rule q̇ = q_s·v, q̈ = q_ss·v² + q_s·a,
//! q⃛ = q_sss·v³ + 3·q_ss·v·a + q_s·j, the axes' limits become limits of the motion along
//! s ([`caps`]):
//!
//! ```text
//! v ≤ W(s)        |a| ≤ a_cap(s, v) = min_i (A_i − |q_ss^i|·v²) / |q_s^i|
//!                 |j| ≤ j_cap(s, v, |a|) = min_i (J_i − |q_sss^i|·v³ − 3·|q_ss^i|·v·|a|) / |q_s^i|
//! ```
//!
//! (a sufficient condition by the triangle inequality; exact on a straight line).
//!
//! **The default** (`segments.rs`, since 2026-11-29): the path is cut into segments of
//! constant limits V, A, J (each the worst of its grid cells', so that any motion within
//! them meets every axis' limits there), passed with a = 0 between segments, and each
//! segment is the time-optimal S-curve between its two junction speeds, found by a
//! backward and a forward pass over the junctions. It is within every axis' V, A and J at
//! every instant by construction, in closed form (the work grows with the segments, not
//! the cycles), and on a straight line it is the time-optimal rest-to-rest profile. On a
//! curved path it is slower than the fastest motion the limits allow (constant limits
//! within a segment, a = 0 at its ends): `docs/simulation.md` measures by how much.
//!
//! **The per-cycle passes** ([`SimOptions::per_cycle`], `simulate --planner cycles`;
//! the default until 2026-11-29), below: closer to the fastest motion on curved paths,
//! but where a pass cannot brake in time it is put on its ceiling (a *clip*), over the
//! axes' acceleration and jerk there.
//!
//! 1. **Velocity limit curve W(s)** ([`grid::Grid`]): each span between two points is cut
//!    into cells (Equation 6's step F·Tcy, at most [`tolerances::MAX_CELLS_PER_SPAN`]); on
//!    each cell `kinematics::feed_bound` (Equation 6) with the largest |q_s|, |q_ss|,
//!    |q_sss| over the cell, capped by F; W is linear between grid points and below
//!    Equation 6 everywhere. On W with a = j = 0 every axis is within its limits.
//! 2. **Backward pass** ([`pass`]): from rest at the end of the path towards its start,
//!    the largest jerk each cycle that keeps the motion under W, with a look-ahead that
//!    starts ramping the acceleration down when the ramp would just meet W (Ruckig's
//!    S-curve rule against a moving target). Read forward, it is the latest the motion
//!    can brake for every slow-down ahead and still stop at the end. The limits are
//!    symmetric in the signs of a and j, so a motion allowed backward is allowed forward.
//! 3. **Forward pass**: from rest at the start, the same rule under the backward profile
//!    B(s) (its speed and acceleration at the grid points). Accelerating as hard as the
//!    limits allow until the ramp-down meets B, then following B to the end, it is the
//!    trajectory: one state per interpolation cycle Tcy.
//!
//! Both passes step at Tcy (the controller's cycle), with every limit used at
//! [`tolerances::LIMIT_USE`] of its value to absorb the change within a cycle, and jump a
//! cruise at a flat ceiling in one step — the forward pass only when no trajectory is
//! asked for, the backward pass always (its profile is a ceiling: the same one for the
//! report and the trajectory, and nothing recorded per cycle of a long cruise) — so the
//! work is bounded by the points and the speed changes, not by the run time, and the
//! memory by the points whatever the mode. The simulator's memory is the spline, the
//! passes' ceilings, the backward profile and the grid of one motion: it grows with the
//! motion's points, not its duration. Equation 6's analysis of the parts runs once the
//! passes' arrays are freed, the backward pass's record is kept in blocks and turned
//! forward into the profile of its exact length, and the velocity limit the forward pass
//! consults beside its profile is computed where it is asked for: with the reading around
//! it, about 0.6 KB a point (docs/simulation.md, "Speed and memory"; `tests/memory.rs`).
//!
//! On a straight line this is the time-optimal jerk-limited rest-to-rest profile (the
//! 7-segment S-curve) to a cycle; on a curved path it is a jerk-limited motion under the
//! velocity limit curve, within the sufficient condition above; `docs/simulation.md`
//! compares it with the closed form and with Equation 6 and L/F.

pub mod caps;
pub mod error;
pub mod grid;
pub mod linuxcnc;
mod pass;
mod segments;
pub mod tolerances;

pub use error::SimError;
pub use grid::{Geometry, Grid};

use pass::{Ceiling, Limit, Pass, Sink, State};
use polepatch_kinematics::Machine;
use polepatch_patcher::{AnalysisOptions, Path, analyze_path};
use rayon::prelude::*;

/// Options of [`simulate`]. Plain struct; see each field for its default.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOptions {
    /// Interpolation cycle time, s; `None` (default) uses the machine's `tcy_s`.
    pub tcy_s: Option<f64>,
    /// Largest number of grid cells per span. Default [`tolerances::MAX_CELLS_PER_SPAN`].
    pub max_cells_per_span: usize,
    /// Hand out every interpolation cycle of the forward pass, the trajectory (for a
    /// trajectory at Tcy); default `false`: a cruise at a flat limit is one step. The
    /// backward pass jumps its cruises either way.
    pub every_cycle: bool,
    /// Where the trajectory would be put on its ceiling (a *clip*, which jumps speed and
    /// acceleration within one cycle), go back and brake in time instead (`pass.rs`,
    /// "Rewinds instead of clips"); default `false`. Experimental (issue 32): on the
    /// fixtures it takes the runs within every axis' V, A and J by finite differences
    /// from 2 to 80 of 132 at a median +0.9 % of time, but costs up to 2.4× the work
    /// and lands up to 0.1 mm short of a run's end before creeping to it
    /// (docs/simulation.md, "Jerk at every cycle"). Implies [`SimOptions::per_cycle`].
    pub rewind: bool,
    /// Simulate with the per-cycle passes (`pass.rs`: a jerk bisected at every cycle under
    /// a velocity limit curve) instead of the segments of constant limits (`segments.rs`,
    /// the default); default `false`. Kept as a second model to compare with: it is
    /// faster on curved paths but puts the motion on its ceiling where it cannot brake in
    /// time (a *clip*: over the limits by finite differences).
    pub per_cycle: bool,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            tcy_s: None,
            max_cells_per_span: tolerances::MAX_CELLS_PER_SPAN,
            every_cycle: false,
            rewind: false,
            per_cycle: false,
        }
    }
}

/// One state of the simulated motion, as handed to the caller's sink.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// Time since the start of the motion, s.
    pub t_s: f64,
    /// Path parameter from the start of the motion, mm.
    pub s_mm: f64,
    /// Feed ṡ, mm/s.
    pub feed_mm_s: f64,
    /// Path acceleration s̈, mm/s².
    pub accel_mm_s2: f64,
    /// Path jerk s⃛ over the step that ended here, mm/s³.
    pub jerk_mm_s3: f64,
    /// The part (run) of the motion this state is in (a shared point: the earlier part).
    pub part: usize,
    /// Whether this state is one interpolation cycle after the previous one (false: the
    /// first state, the last, partial cycle, or a jumped cruise).
    pub cycle: bool,
}

/// The lowest feed at a programmed point of a part (its first and last points excluded).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MinFeed {
    /// Feed there, mm/s.
    pub feed_mm_s: f64,
    /// Index of the point in its part.
    pub point: usize,
    /// s of the point in its part, mm.
    pub s_mm: f64,
}

/// What the simulation found for one part (run) of a motion.
#[derive(Debug, Clone, PartialEq)]
pub struct PartSim {
    /// Simulated time over the part, s.
    pub time_s: f64,
    /// Equation 6's estimate ∫ds/ṡ on the part's own path (what `analyze` reports), s.
    pub eq6_time_s: f64,
    /// L/F, s.
    pub ideal_time_s: f64,
    /// Path length, mm.
    pub length_mm: f64,
    /// Programmed feed, mm/min.
    pub feed_mm_min: f64,
    /// The lowest feed at one of its points (`None` for a part of two points).
    pub min_feed: Option<MinFeed>,
}

/// The result of [`simulate`].
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// Per part, in order.
    pub parts: Vec<PartSim>,
    /// Total simulated time, s.
    pub time_s: f64,
    /// Cycles where a pass had to put the motion on its ceiling (0 on every path the
    /// tests know; any other count says the plan may exceed a limit there).
    pub clips: usize,
    /// Steps of the forward pass.
    pub steps: u64,
}

/// Backward pass: the speed and (forward) acceleration at each grid point, and at every
/// state where the jerk switches (so that no cell of the recorded profile holds a switch,
/// which an interpolant between grid points would round off).
///
/// Recorded (x, v, a) in blocks of [`tolerances::RECORD_BLOCK_STATES`]: the record is the
/// largest array of the pass, and its length (grid points and switches) is known only at
/// the end; a vector that doubles holds up to twice it, and for a moment both blocks when
/// it moves. [`Profile::from_record`] turns it forward into arrays of its exact length,
/// freeing each block as it is read.
struct Store<'a> {
    /// Pass positions of the grid points (backward order).
    grid: &'a [f64],
    next: usize,
    prev_j: f64,
    blocks: Vec<Vec<[f64; 3]>>,
}

impl Store<'_> {
    /// The last state recorded.
    fn last(&self) -> Option<[f64; 3]> {
        self.blocks.last().and_then(|b| b.last()).copied()
    }

    fn push(&mut self, x: f64, v: f64, a: f64) {
        if self.last().is_none_or(|l| x > l[0]) {
            let full = self
                .blocks
                .last()
                .is_none_or(|b| b.len() == tolerances::RECORD_BLOCK_STATES);
            if full {
                // The first block grows as a vector does (a short motion holds little),
                // up to the size of a block; the others are allocated whole.
                let room = if self.blocks.is_empty() {
                    0
                } else {
                    tolerances::RECORD_BLOCK_STATES
                };
                self.blocks.push(Vec::with_capacity(room));
            }
            if let Some(b) = self.blocks.last_mut() {
                b.push([x, v, a]);
            }
        }
    }
}

impl Sink for Store<'_> {
    fn step(&mut self, from: &State, to: &State, j: f64, _c: bool) {
        if (j - self.prev_j).abs() > tolerances::JERK_SWITCH * j.abs().max(self.prev_j.abs()) {
            self.push(from.x, from.v, from.a);
        }
        self.prev_j = j;
        while self.next < self.grid.len() && self.grid[self.next] <= to.x {
            let g = self.grid[self.next];
            let u = if to.x > from.x {
                ((g - from.x) / (to.x - from.x)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            self.push(
                g,
                from.v + u * (to.v - from.v),
                from.a + u * (to.a - from.a),
            );
            self.next += 1;
        }
    }
}

/// Where a motion is among its parts, and what it found at the points it passed: each
/// part's time and its lowest feed at one of its points (both models hand their points to
/// it).
pub(crate) struct Parts {
    /// The part the motion is in (at a shared point: the earlier).
    pub part: usize,
    start_t: f64,
    /// Each part's time, s, in order, for the parts ended so far.
    pub times: Vec<f64>,
    /// Each part's lowest feed at one of its points (its first and last excluded).
    pub min: Vec<Option<MinFeed>>,
}

impl Parts {
    pub(crate) fn new(n: usize) -> Parts {
        Parts {
            part: 0,
            start_t: 0.0,
            times: Vec::with_capacity(n),
            min: vec![None; n],
        }
    }

    /// Point `k` of `geo` passed at speed `v` (mm/s) at time `t` (s).
    pub(crate) fn passed(&mut self, geo: &Geometry, k: usize, v: f64, t: f64) {
        let p = self.part;
        let first = if p == 0 { 0 } else { geo.part_end[p - 1] };
        if k > first && k < geo.part_end[p] {
            let better = self.min[p].is_none_or(|m| v < m.feed_mm_s);
            if better {
                self.min[p] = Some(MinFeed {
                    feed_mm_s: v,
                    point: k - first,
                    s_mm: geo.knots[k] - geo.knots[first],
                });
            }
        }
        if k == geo.part_end[p] {
            self.times.push(t - self.start_t);
            self.start_t = t;
            if p + 1 < geo.part_end.len() {
                self.part += 1;
            }
        }
    }

    /// The parts not ended by the last point (a motion cut short), each its time from
    /// the last end to `t`.
    pub(crate) fn finish(&mut self, n: usize, t: f64) {
        while self.times.len() < n {
            self.times.push(t - self.start_t);
            self.start_t = t;
        }
    }
}

/// Forward pass: the results and the caller's sink.
struct Forward<'a> {
    geo: &'a Geometry,
    user: &'a mut dyn FnMut(&Step, &Geometry),
    parts: Parts,
    next_knot: usize,
    started: bool,
    /// Hand out every cycle: cut jumped cruises into their cycles.
    every_cycle: bool,
    /// Cycle time, s.
    dt: f64,
}

impl Sink for Forward<'_> {
    fn step(&mut self, from: &State, to: &State, j: f64, cycle: bool) {
        // A jumped cruise (constant speed, a = 0, whole cycles but at the end of the
        // path) is handed out cycle by cycle when every cycle is asked for: the states
        // the cycles would have had, exactly.
        if self.every_cycle && !cycle && j == 0.0 && from.a == 0.0 && to.a == 0.0 && from.v == to.v
        {
            let n = ((to.t - from.t) / self.dt + tolerances::CYCLE_COUNT_SLACK).floor() as u64;
            let mut prev = *from;
            for k in 1..=n {
                let t = from.t + k as f64 * self.dt;
                if t >= to.t - tolerances::TIME_MATCH_REL * to.t.abs().max(1.0) {
                    break;
                }
                let x = from.x + k as f64 * self.dt * from.v;
                if x >= to.x {
                    break;
                }
                let next = State { t, x, ..*from };
                self.one(&prev, &next, 0.0, true);
                prev = next;
            }
            let whole = ((to.t - prev.t) / self.dt - 1.0).abs() < tolerances::CYCLE_MATCH_REL;
            self.one(&prev, to, 0.0, whole);
            return;
        }
        self.one(from, to, j, cycle);
    }
}

impl Forward<'_> {
    /// One state handed out (see [`Sink::step`]).
    fn one(&mut self, from: &State, to: &State, j: f64, cycle: bool) {
        if !self.started {
            self.started = true;
            (self.user)(
                &Step {
                    t_s: from.t,
                    s_mm: from.x,
                    feed_mm_s: from.v,
                    accel_mm_s2: from.a,
                    jerk_mm_s3: 0.0,
                    part: 0,
                    cycle: false,
                },
                self.geo,
            );
        }
        // Points passed in this step: the feed there, part ends.
        let knots = &self.geo.knots;
        let end = self.geo.length();
        while self.next_knot < knots.len()
            && (knots[self.next_knot] <= to.x || (to.x >= end && self.next_knot + 1 == knots.len()))
        {
            let k = self.next_knot;
            let u = if to.x > from.x {
                ((knots[k] - from.x) / (to.x - from.x)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let v = from.v + u * (to.v - from.v);
            let t = from.t + u * (to.t - from.t);
            self.parts.passed(self.geo, k, v, t);
            self.next_knot += 1;
        }
        (self.user)(
            &Step {
                t_s: to.t,
                s_mm: to.x,
                feed_mm_s: to.v,
                accel_mm_s2: to.a,
                jerk_mm_s3: j,
                part: self.parts.part,
                cycle: cycle && (to.t - from.t) > 0.0,
            },
            self.geo,
        );
    }
}

/// Simulate a motion: `parts` are runs that follow one another without a stop (each
/// part's first point is the last point of the part before), at rest at the start and
/// the end. `sink` gets every state of the motion in order (with the geometry, to
/// evaluate axis values): every cycle with [`SimOptions::every_cycle`], else every step.
pub fn simulate(
    parts: &[Path],
    machine: &Machine,
    opts: &SimOptions,
    sink: &mut dyn FnMut(&Step, &Geometry),
) -> Result<Simulation, SimError> {
    let tcy_s = opts.tcy_s.unwrap_or(machine.tcy_s);
    if !(tcy_s.is_finite() && tcy_s > 0.0) {
        return Err(SimError::BadCycleTime(tcy_s));
    }
    // The passes first, all they held (spline, grid, ceilings, profile) freed on return;
    // then Equation 6 on each part, whose own spline and solver are then the only
    // whole-motion arrays alive: the peak is one of the two, not their sum.
    let motion = if opts.per_cycle || opts.rewind {
        passes(parts, machine, opts, tcy_s, sink)?
    } else {
        let geo = Geometry::new(parts)?;
        let p = segments::plan(
            &geo,
            machine,
            tcy_s,
            opts.max_cells_per_span,
            opts.every_cycle,
            sink,
        );
        Motion {
            part_times: p.part_times,
            min: p.min,
            stats: pass::PassStats {
                time_s: p.time_s,
                clips: 0,
                steps: p.steps,
            },
        }
    };
    let aopts = AnalysisOptions {
        tcy_s: Some(tcy_s),
        ..AnalysisOptions::default()
    };
    // Each part's analysis on its own (on all cores where there are several), only its
    // three figures kept; the first failure in order is the motion's.
    let estimate = |p: &Path| {
        analyze_path(p, machine, &aopts).map(|a| (a.time_s, a.ideal_time_s, a.length_mm))
    };
    let estimates: Vec<_> = if parts.len() > 1 {
        parts.par_iter().map(estimate).collect()
    } else {
        parts.iter().map(estimate).collect()
    };
    let mut out_parts = Vec::with_capacity(parts.len());
    for (k, (p, e)) in parts.iter().zip(estimates).enumerate() {
        let (eq6_time_s, ideal_time_s, length_mm) =
            e.map_err(|source| SimError::Path { part: k, source })?;
        out_parts.push(PartSim {
            time_s: motion.part_times[k],
            eq6_time_s,
            ideal_time_s,
            length_mm,
            feed_mm_min: p.feed_mm_min,
            min_feed: motion.min[k],
        });
    }
    Ok(Simulation {
        parts: out_parts,
        time_s: motion.stats.time_s,
        clips: motion.stats.clips,
        steps: motion.stats.steps,
    })
}

/// What the forward pass found: each part's time and lowest feed, and the pass's counts.
struct Motion {
    part_times: Vec<f64>,
    min: Vec<Option<MinFeed>>,
    stats: pass::PassStats,
}

/// The backward profile B(s): speed and acceleration at increasing s.
struct Profile {
    x: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
}

impl Profile {
    /// The backward pass's record ([`Store::blocks`]) read backward: s = L − x and the
    /// acceleration's sign turned (`len`: L, mm); each block freed once read.
    fn from_record(mut blocks: Vec<Vec<[f64; 3]>>, len: f64) -> Profile {
        let n = blocks.iter().map(Vec::len).sum();
        let mut b = Profile {
            x: Vec::with_capacity(n),
            v: Vec::with_capacity(n),
            a: Vec::with_capacity(n),
        };
        while let Some(block) = blocks.pop() {
            for &[x, v, a] in block.iter().rev() {
                b.x.push(len - x);
                b.v.push(v);
                b.a.push(-a);
            }
        }
        b
    }
}

/// The spline of the motion, the grid of W, the backward pass and the forward pass that
/// hands the states to `sink`; everything but the results dropped on return.
fn passes(
    parts: &[Path],
    machine: &Machine,
    opts: &SimOptions,
    tcy_s: f64,
    sink: &mut dyn FnMut(&Step, &Geometry),
) -> Result<Motion, SimError> {
    let geo = Geometry::new(parts)?;
    let grid = Grid::new(&geo, machine, tcy_s, opts.max_cells_per_span);
    let b = backward(&geo, &grid, machine, tcy_s)?;

    // Forward pass under B: the trajectory.
    let fwd = Pass {
        geo: &geo,
        machine,
        ceiling: Ceiling::new(&b.x, &b.v, Some(&b.a)),
        limit: Some(Limit {
            x: &grid.s,
            v: &grid.limit,
        }),
        forward: true,
        dt: tcy_s,
        use_caps: [1.0, 1.0],
        // The same steps whether or not every cycle is handed out (the sink cuts the
        // jumped cruises into cycles): one answer.
        every_cycle: false,
        rewind: opts.rewind,
    };
    let mut out = Forward {
        geo: &geo,
        user: sink,
        parts: Parts::new(parts.len()),
        next_knot: 1,
        started: false,
        every_cycle: opts.every_cycle,
        dt: tcy_s,
    };
    let stats = fwd
        .run(&mut out)
        .map_err(|s| SimError::Stalled { s_mm: s })?;
    let mut part_times = out.parts.times;
    while part_times.len() < parts.len() {
        part_times.push(0.0);
    }
    Ok(Motion {
        part_times,
        min: out.parts.min,
        stats,
    })
}

/// The backward pass under W from the end of the motion, recorded ([`Store`]) and turned
/// into B(s).
fn backward(
    geo: &Geometry,
    grid: &Grid,
    machine: &Machine,
    tcy_s: f64,
) -> Result<Profile, SimError> {
    let len = geo.length();
    let xb: Vec<f64> = grid.s.iter().rev().map(|s| len - s).collect();
    let wb: Vec<f64> = grid.limit.iter().rev().copied().collect();
    let back = Pass {
        geo,
        machine,
        ceiling: Ceiling::new(&xb, &wb, None),
        limit: None,
        forward: false,
        dt: tcy_s,
        use_caps: tolerances::BACKWARD_USE,
        // The backward profile is a ceiling, not the trajectory: it jumps cruises in both
        // modes (the same profile for the report and the trajectory, and a long cruise
        // records nothing per cycle: memory bounded by the points).
        every_cycle: false,
        rewind: false,
    };
    let mut store = Store {
        grid: &xb,
        next: 1,
        prev_j: 0.0,
        blocks: Vec::new(),
    };
    store.push(0.0, 0.0, 0.0);
    back.run(&mut store)
        .map_err(|s| SimError::Stalled { s_mm: s })?;
    if let Some([x, v, _]) = store.last()
        && x < len
    {
        store.push(len, v, 0.0);
    }
    let record = store.blocks;
    // What only the backward pass used, freed before the forward pass (peak memory).
    drop(back);
    drop((xb, wb));
    Ok(Profile::from_record(record, len))
}
