//! The motion planned in segments of constant limits, in closed form (the default).
//!
//! # The problem
//! Along the path s ∈ [0, L] the axes' limits are, by the sufficient condition of
//! [`crate::caps`], limits on v = ṡ, a = s̈, j = s⃛ that depend on where the motion is
//! and on v and |a| themselves. A motion that keeps them at every instant keeps every
//! axis within V, A and J at every cycle. This module finds such a motion with a proof
//! that it does, fast enough to run on every program:
//!
//! 1. **Segments of constant limits.** The grid's cells ([`crate::grid::for_each_cell`]:
//!    each with the largest |q_s|, |q_ss|, |q_sss| of every axis over it and the
//!    programmed feed) are merged, in order, into segments. A segment's *peaks* are the
//!    largest of its cells' (per axis and order); from them ([`Peaks::limits`]):
//!
//!    ```text
//!    V = min( F, V_i/|q_s|, √(σ·A_i/|q_ss|), ∛(σ·J_i/|q_sss|) )          (σ: SPEED_SHARE)
//!    A = min_i (A_i − |q_ss|·V²)/|q_s|,   and 3·|q_ss|·V·A ≤ (J_i − |q_sss|·V³)/2
//!    J = min_i (J_i − |q_sss|·V³ − 3·|q_ss|·V·A)/|q_s|
//!    ```
//!
//!    Every state with v ≤ V, |a| ≤ A, |j| ≤ J on the segment then meets every axis'
//!    limits there (each term of the sufficient condition is increasing in |q_s|,
//!    |q_ss|, |q_sss|, v and |a|). σ < 1 keeps room for A and J where Equation 6 binds. A
//!    cell joins the segment before it while the merged limits stay within a share (one
//!    of [`MERGE_RATIOS`]) of the largest of the segment's cells' and of the cell's own;
//!    otherwise it starts a new segment. Few long segments have low limits, many short
//!    ones a = 0 between them: the motion is planned for each share and the fastest plan
//!    is the motion (each is within the limits).
//! 2. **The junctions** between segments are passed with a = 0 (and v under both
//!    segments' V). With a = 0 at both ends, the distance to change speed from v₀ to v₁ is
//!    (v₀ + v₁)/2 · T with T = Δv/A + A/J (or 2·√(Δv/J) when A is not reached): closed
//!    forms ([`change`], [`reach`]). A backward pass over the junctions from rest at the
//!    end (the fastest speed from which each later junction can still be met) and a
//!    forward pass from rest at the start give the junction speeds — the classic
//!    look-ahead of a CNC planner, over the whole motion.
//! 3. **Each segment** is then the time-optimal motion between its two junction speeds
//!    under its constant limits: a jerk-limited speed change up to a peak v_p ≤ V, a
//!    cruise, and a speed change down (the 7-phase S-curve), v_p found by bisection so that
//!    the segment's length is covered exactly.
//!
//! The motion is a sequence of pieces of constant jerk, evaluated exactly wherever it is
//! asked (every cycle for a trajectory): its finite differences are within the limits by
//! construction. On a straight line there is one segment with the axis' own limits, and
//! the motion is the time-optimal rest-to-rest S-curve. On a curved path the price of the
//! proof is the constant limits within a segment and a = 0 at its ends; the time is an
//! upper bound of what the limits allow (docs/simulation.md measures it against TOPP-RA's
//! lower bound and the per-cycle passes).
//!
//! The work grows with the cells (the grid, once) and the segments (a few closed forms
//! each), not the cycles; the memory with the segments (five numbers each).

use polepatch_kinematics::Machine;

use crate::grid::{Cell, Geometry, for_each_cell};
use crate::tolerances::{
    LIMIT_USE, MERGE_RATIOS, SEGMENT_A_MAX_MM_S2, SEGMENT_J_MAX_MM_S3, SPEED_SHARE, TIME_BISECTIONS,
};
use crate::{MinFeed, Step};

/// The largest |q_s|, |q_ss|, |q_sss| of each axis over a set of cells and its lowest
/// programmed feed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Peaks {
    m: [[f64; 3]; 5],
    feed_mm_s: f64,
}

/// Constant limits of a segment: speed mm/s, |acceleration| mm/s², |jerk| mm/s³.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Limits {
    v: f64,
    a: f64,
    j: f64,
}

impl Peaks {
    fn of(c: &Cell) -> Peaks {
        Peaks {
            m: c.peaks,
            feed_mm_s: c.feed_mm_s,
        }
    }

    fn merge(&self, o: &Peaks) -> Peaks {
        Peaks {
            m: std::array::from_fn(|i| std::array::from_fn(|k| self.m[i][k].max(o.m[i][k]))),
            feed_mm_s: self.feed_mm_s.min(o.feed_mm_s),
        }
    }

    /// The segment's constant limits (module docs, step 1) with the machine's limits
    /// used at [`LIMIT_USE`].
    fn limits(&self, machine: &Machine) -> Limits {
        let lim = |i: usize| {
            let l = machine.limits[i];
            (LIMIT_USE * l.v, LIMIT_USE * l.a, LIMIT_USE * l.j)
        };
        let mut v = self.feed_mm_s;
        for i in 0..5 {
            let (vl, al, jl) = lim(i);
            let [m1, m2, m3] = self.m[i];
            if m1 > 0.0 {
                v = v.min(vl / m1);
            }
            if m2 > 0.0 {
                v = v.min((SPEED_SHARE * al / m2).sqrt());
            }
            if m3 > 0.0 {
                v = v.min((SPEED_SHARE * jl / m3).cbrt());
            }
        }
        let mut a = SEGMENT_A_MAX_MM_S2;
        for i in 0..5 {
            let (_, al, jl) = lim(i);
            let [m1, m2, m3] = self.m[i];
            if m1 > 0.0 {
                a = a.min((al - m2 * v * v) / m1);
            }
            if m2 > 0.0 && v > 0.0 {
                a = a.min((jl - m3 * v * v * v) / (6.0 * m2 * v));
            }
        }
        let mut j = SEGMENT_J_MAX_MM_S3;
        for i in 0..5 {
            let (_, _, jl) = lim(i);
            let [m1, m2, m3] = self.m[i];
            if m1 > 0.0 {
                j = j.min((jl - m3 * v * v * v - 3.0 * m2 * v * a) / m1);
            }
        }
        Limits { v, a, j }
    }
}

/// A segment: where it starts, its length and its limits.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    s0_mm: f64,
    len_mm: f64,
    lim: Limits,
}

/// A segment being merged: its peaks and limits, the largest of its cells' own limits,
/// and where it starts and ends.
#[derive(Debug, Clone, Copy)]
struct Open {
    peaks: Peaks,
    lim: Limits,
    best: Limits,
    s0_mm: f64,
    s1_mm: f64,
}

impl Open {
    fn of(c: &Cell, p: Peaks, own: Limits) -> Open {
        Open {
            peaks: p,
            lim: own,
            best: own,
            s0_mm: c.s0_mm,
            s1_mm: c.s1_mm,
        }
    }

    fn close(&self) -> Segment {
        Segment {
            s0_mm: self.s0_mm,
            len_mm: self.s1_mm - self.s0_mm,
            lim: self.lim,
        }
    }
}

/// The segments of the path (module docs, step 1), once per merge ratio of
/// [`MERGE_RATIOS`], in one walk over the cells.
fn segmentations(
    geo: &Geometry,
    machine: &Machine,
    tcy_s: f64,
    max_cells: usize,
) -> Vec<Vec<Segment>> {
    let mut out: Vec<Vec<Segment>> = vec![Vec::new(); MERGE_RATIOS.len()];
    let mut open: Vec<Option<Open>> = vec![None; MERGE_RATIOS.len()];
    for_each_cell(geo, tcy_s, max_cells, &mut |c: &Cell| {
        let p = Peaks::of(c);
        let own = p.limits(machine);
        for (k, &ratio) in MERGE_RATIOS.iter().enumerate() {
            if let Some(o) = &mut open[k] {
                let merged = o.peaks.merge(&p);
                let lm = merged.limits(machine);
                let ok = |m: f64, a: f64, b: f64| m >= ratio * a.max(b);
                if ok(lm.v, o.best.v, own.v)
                    && ok(lm.a, o.best.a, own.a)
                    && ok(lm.j, o.best.j, own.j)
                {
                    o.best = Limits {
                        v: o.best.v.max(own.v),
                        a: o.best.a.max(own.a),
                        j: o.best.j.max(own.j),
                    };
                    o.peaks = merged;
                    o.lim = lm;
                    o.s1_mm = c.s1_mm;
                    continue;
                }
                out[k].push(o.close());
            }
            open[k] = Some(Open::of(c, p, own));
        }
    });
    for (k, o) in open.iter().enumerate() {
        if let Some(o) = o {
            out[k].push(o.close());
        }
    }
    out
}

/// Time and distance of a jerk-limited change of speed from `v0` to `v1` with a = 0 at
/// both ends, |a| ≤ `a`, |j| ≤ `j`: `(T, (v0 + v1)/2·T)`.
fn change(v0: f64, v1: f64, a: f64, j: f64) -> (f64, f64) {
    let dv = (v1 - v0).abs();
    let t = if dv * j >= a * a {
        dv / a + a / j
    } else {
        2.0 * (dv / j).sqrt()
    };
    (t, 0.5 * (v0 + v1) * t)
}

/// The largest speed v ≥ `v0` to which a change from `v0` ([`change`]) fits in `len`.
fn reach(v0: f64, len: f64, a: f64, j: f64) -> f64 {
    if len <= 0.0 {
        return v0;
    }
    // While A is not reached: x = √Δv solves x³ + 2·v0·x = len·√j (increasing, convex for
    // x > 0: Newton from an upper bound falls monotonically onto the root).
    let q = len * j.sqrt();
    let mut x = q.cbrt();
    if v0 > 0.0 {
        x = x.min(q / (2.0 * v0));
    }
    for _ in 0..100 {
        let f = x * x * x + 2.0 * v0 * x - q;
        let nx = x - f / (3.0 * x * x + 2.0 * v0);
        // Stop where Newton no longer falls (the root, to rounding) or on NaN.
        if nx.partial_cmp(&x) != Some(std::cmp::Ordering::Less) || nx <= 0.0 {
            break;
        }
        x = nx;
    }
    let dv = x * x;
    if dv * j < a * a {
        return v0 + dv;
    }
    // A reached: (2·v0 + Δv)·(Δv/a + a/j) = 2·len, a quadratic in Δv.
    let qa = 1.0 / a;
    let qb = a / j + 2.0 * v0 / a;
    let qc = 2.0 * v0 * a / j - 2.0 * len;
    let disc = (qb * qb - 4.0 * qa * qc).max(0.0);
    let dv = if qc < 0.0 {
        -2.0 * qc / (qb + disc.sqrt())
    } else {
        0.0
    };
    v0 + dv.max(a * a / j)
}

/// One piece of constant jerk: its duration (s) and jerk (mm/s³).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    t: f64,
    j: f64,
}

/// The pieces of a change of speed from `v0` to `v1` ([`change`]).
fn change_pieces(v0: f64, v1: f64, a: f64, j: f64, out: &mut Vec<Piece>) {
    let dv = (v1 - v0).abs();
    if dv == 0.0 {
        return;
    }
    let sign = if v1 > v0 { 1.0 } else { -1.0 };
    if dv * j >= a * a {
        out.push(Piece {
            t: a / j,
            j: sign * j,
        });
        out.push(Piece {
            t: dv / a - a / j,
            j: 0.0,
        });
        out.push(Piece {
            t: a / j,
            j: -sign * j,
        });
    } else {
        let tj = (dv / j).sqrt();
        out.push(Piece { t: tj, j: sign * j });
        out.push(Piece {
            t: tj,
            j: -sign * j,
        });
    }
}

/// The pieces of segment `seg` from junction speed `u0` to `u1` (module docs, step 3).
fn segment_pieces(seg: &Segment, u0: f64, u1: f64, out: &mut Vec<Piece>) {
    out.clear();
    let Limits { v, a, j } = seg.lim;
    let len = seg.len_mm;
    let used = |vp: f64| change(u0, vp, a, j).1 + change(vp, u1, a, j).1;
    let lo0 = u0.max(u1);
    let vp = if used(v) <= len {
        v
    } else {
        let (mut lo, mut hi) = (lo0, v.max(lo0));
        for _ in 0..TIME_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if !(mid > lo && mid < hi) {
                break;
            }
            if used(mid) <= len {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    change_pieces(u0, vp, a, j, out);
    let cruise = len - used(vp);
    if cruise > 0.0 && vp > 0.0 {
        out.push(Piece {
            t: cruise / vp,
            j: 0.0,
        });
    }
    change_pieces(vp, u1, a, j, out);
}

/// The state after time `t` of constant jerk `j` from (s, v, a).
#[inline]
fn advance(s: f64, v: f64, a: f64, j: f64, t: f64) -> (f64, f64, f64) {
    (
        s + t * (v + t * (0.5 * a + t * j / 6.0)),
        v + t * (a + 0.5 * j * t),
        a + j * t,
    )
}

/// What the planned motion gives back: each part's time, its lowest feed at a point,
/// and the number of states handed out.
pub(crate) struct Planned {
    pub part_times: Vec<f64>,
    pub min: Vec<Option<MinFeed>>,
    pub steps: u64,
    pub time_s: f64,
}

/// Plan the motion on `geo` and hand its states to `sink`: every cycle of `tcy_s` when
/// `every_cycle`, else the ends of its pieces.
pub(crate) fn plan(
    geo: &Geometry,
    machine: &Machine,
    tcy_s: f64,
    max_cells: usize,
    every_cycle: bool,
    sink: &mut dyn FnMut(&Step, &Geometry),
) -> Planned {
    // Each segmentation planned (its junctions and time); the fastest handed out.
    let mut best: Option<(f64, Vec<Segment>, Vec<f64>)> = None;
    for segs in segmentations(geo, machine, tcy_s, max_cells) {
        let u = junctions(&segs);
        let t = time_of(&segs, &u);
        if best.as_ref().is_none_or(|b| t < b.0) {
            best = Some((t, segs, u));
        }
    }
    let (_, segs, u) = best.unwrap_or_default();
    // Forward, segment by segment, handing out the states as they are computed.
    let mut out = Emit::new(geo, every_cycle, tcy_s, sink);
    let mut pieces = Vec::with_capacity(7);
    let mut u0 = 0.0;
    for (k, seg) in segs.iter().enumerate() {
        let u1 = u[k + 1].min(reach(u0, seg.len_mm, seg.lim.a, seg.lim.j));
        segment_pieces(seg, u0, u1, &mut pieces);
        out.segment(seg, u0, &pieces);
        u0 = u1;
    }
    out.finish()
}

/// The backward pass over the junctions (module docs, step 2): the fastest speed at each
/// junction from which the rest of the motion can still be met, from rest at the end; at
/// rest at the start.
fn junctions(segs: &[Segment]) -> Vec<f64> {
    let n = segs.len();
    let mut u = vec![0.0; n + 1];
    for k in (0..n).rev() {
        let cap = if k == 0 {
            0.0
        } else {
            segs[k - 1].lim.v.min(segs[k].lim.v)
        };
        let s = &segs[k];
        u[k] = cap.min(reach(u[k + 1], s.len_mm, s.lim.a, s.lim.j));
    }
    u
}

/// The time of the motion on `segs` with the backward junction speeds `u` (the forward
/// pass of [`plan`] without its states).
fn time_of(segs: &[Segment], u: &[f64]) -> f64 {
    let mut pieces = Vec::with_capacity(7);
    let (mut u0, mut t) = (0.0, 0.0);
    for (k, seg) in segs.iter().enumerate() {
        let u1 = u[k + 1].min(reach(u0, seg.len_mm, seg.lim.a, seg.lim.j));
        segment_pieces(seg, u0, u1, &mut pieces);
        t += pieces.iter().map(|p| p.t).sum::<f64>();
        u0 = u1;
    }
    t
}

/// Hands out the states of the motion, and finds where it passes the path's points.
struct Emit<'a, 'b> {
    geo: &'a Geometry,
    sink: &'b mut dyn FnMut(&Step, &Geometry),
    every_cycle: bool,
    dt: f64,
    /// Time at the start of the current segment.
    t: f64,
    /// The next cycle's time (every cycle).
    next_cycle: u64,
    /// The last state handed out: t, s, v, a.
    last: (f64, f64, f64, f64),
    part: usize,
    part_start_t: f64,
    part_times: Vec<f64>,
    next_knot: usize,
    min: Vec<Option<MinFeed>>,
    steps: u64,
}

impl<'a, 'b> Emit<'a, 'b> {
    fn new(
        geo: &'a Geometry,
        every_cycle: bool,
        dt: f64,
        sink: &'b mut dyn FnMut(&Step, &Geometry),
    ) -> Emit<'a, 'b> {
        let parts = geo.part_end.len();
        let mut e = Emit {
            geo,
            sink,
            every_cycle,
            dt,
            t: 0.0,
            next_cycle: 1,
            last: (0.0, 0.0, 0.0, 0.0),
            part: 0,
            part_start_t: 0.0,
            part_times: Vec::with_capacity(parts),
            next_knot: 1,
            min: vec![None; parts],
            steps: 0,
        };
        e.hand_out(0.0, 0.0, 0.0, 0.0, 0.0, false);
        e
    }

    fn hand_out(&mut self, t: f64, s: f64, v: f64, a: f64, j: f64, cycle: bool) {
        self.steps += 1;
        self.last = (t, s, v, a);
        (self.sink)(
            &Step {
                t_s: t,
                s_mm: s,
                feed_mm_s: v,
                accel_mm_s2: a,
                jerk_mm_s3: j,
                part: self.part,
                cycle,
            },
            self.geo,
        );
    }

    /// The pieces of one segment from its start (speed `u0`, a = 0).
    fn segment(&mut self, seg: &Segment, u0: f64, pieces: &[Piece]) {
        let end = seg.s0_mm + seg.len_mm;
        let (mut s, mut v, mut a) = (seg.s0_mm, u0, 0.0);
        let mut t0 = self.t;
        for (i, p) in pieces.iter().enumerate() {
            let last_piece = i + 1 == pieces.len();
            // The path's points passed in this piece.
            let (s1, v1, a1) = advance(s, v, a, p.j, p.t);
            let s1 = if last_piece { end } else { s1.min(end) };
            self.knots(t0, s, v, a, p, s1);
            if self.every_cycle {
                loop {
                    let tc = self.next_cycle as f64 * self.dt;
                    if tc >= t0 + p.t {
                        break;
                    }
                    let (sc, vc, ac) = advance(s, v, a, p.j, tc - t0);
                    self.hand_out(tc, sc.min(s1), vc.max(0.0), ac, p.j, true);
                    self.next_cycle += 1;
                }
            } else {
                self.hand_out(t0 + p.t, s1, v1.max(0.0), a1, p.j, false);
            }
            s = s1;
            v = v1;
            a = a1;
            t0 += p.t;
        }
        self.t = t0;
    }

    /// The path's points at or before `s1` reached in piece `p` (from t0, s, v, a): the
    /// feed there, and each part's end time.
    fn knots(&mut self, t0: f64, s: f64, v: f64, a: f64, p: &Piece, s1: f64) {
        let knots = &self.geo.knots;
        let n = knots.len();
        while self.next_knot < n && (knots[self.next_knot] <= s1) {
            let k = self.next_knot;
            let target = knots[k];
            // s(τ) is increasing on the piece: bisection on τ.
            let (mut lo, mut hi) = (0.0, p.t);
            for _ in 0..TIME_BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if !(mid > lo && mid < hi) {
                    break;
                }
                if advance(s, v, a, p.j, mid).0 < target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let tau = if target >= s1 { p.t } else { hi };
            let (_, vk, _) = advance(s, v, a, p.j, tau);
            let tk = t0 + tau;
            self.passed(k, vk.max(0.0), tk);
            self.next_knot += 1;
        }
    }

    fn passed(&mut self, k: usize, v: f64, t: f64) {
        let p = self.part;
        let first = if p == 0 { 0 } else { self.geo.part_end[p - 1] };
        if k > first && k < self.geo.part_end[p] {
            let better = self.min[p].is_none_or(|m| v < m.feed_mm_s);
            if better {
                self.min[p] = Some(MinFeed {
                    feed_mm_s: v,
                    point: k - first,
                    s_mm: self.geo.knots[k] - self.geo.knots[first],
                });
            }
        }
        if k == self.geo.part_end[p] {
            self.part_times.push(t - self.part_start_t);
            self.part_start_t = t;
            if p + 1 < self.geo.part_end.len() {
                self.part += 1;
            }
        }
    }

    fn finish(mut self) -> Planned {
        let end = self.geo.length();
        // The last state: the end at rest, after the last whole cycle.
        if self.every_cycle || self.last.1 < end || self.last.0 < self.t {
            let whole = self.every_cycle && ((self.t - self.last.0) / self.dt - 1.0).abs() < 1e-9;
            self.hand_out(self.t, end, 0.0, 0.0, 0.0, whole);
        }
        while self.part_times.len() < self.geo.part_end.len() {
            let t = self.t - self.part_start_t;
            self.part_times.push(t);
            self.part_start_t = self.t;
        }
        Planned {
            part_times: self.part_times,
            min: self.min,
            steps: self.steps,
            time_s: self.t,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance of a change is its time times the mean speed, and `reach` inverts it
    /// in both regimes (A reached or not).
    #[test]
    fn reach_inverts_the_change_in_both_regimes() {
        for &(v0, len, a, j) in &[
            (0.0, 1.0, 1000.0, 5000.0),
            (0.0, 100.0, 1000.0, 5000.0),
            (20.0, 0.01, 1000.0, 5000.0),
            (50.0, 500.0, 200.0, 80000.0),
            (3.0, 1e-6, 10.0, 1e9),
        ] {
            let v1 = reach(v0, len, a, j);
            let (_, d) = change(v0, v1, a, j);
            assert!((d - len).abs() <= 1e-9 * len.max(1e-3), "{v0} {len}: {d}");
            // Symmetric: down from v1 to v0 over the same length.
            assert_eq!(change(v1, v0, a, j), change(v0, v1, a, j));
        }
    }

    /// The pieces of a segment cover its length exactly, end at its junction speeds with
    /// a = 0, and stay within its limits.
    #[test]
    fn a_segments_pieces_cover_it_within_its_limits() {
        for &(u0, u1, len) in &[
            (0.0f64, 0.0f64, 50.0f64),
            (0.0, 0.0, 0.5),
            (10.0, 30.0, 40.0),
            (30.0, 0.0, 200.0),
            (25.0, 25.0, 0.001),
        ] {
            let seg = Segment {
                s0_mm: 0.0,
                len_mm: len,
                lim: Limits {
                    v: 40.0,
                    a: 500.0,
                    j: 5000.0,
                },
            };
            if reach(u0.min(u1), len, 500.0, 5000.0) < u0.max(u1) {
                continue;
            }
            let mut ps = Vec::new();
            segment_pieces(&seg, u0, u1, &mut ps);
            let (mut s, mut v, mut a) = (0.0, u0, 0.0);
            for p in &ps {
                assert!(p.t >= 0.0 && p.j.abs() <= 5000.0);
                let (s1, v1, a1) = advance(s, v, a, p.j, p.t);
                // Speed within the piece: at its ends and where a = 0 inside.
                assert!(v1 <= 40.0 * (1.0 + 1e-12) && a1.abs() <= 500.0 * (1.0 + 1e-12));
                (s, v, a) = (s1, v1, a1);
            }
            assert!(
                (s - len).abs() <= 1e-9 * len.max(1.0),
                "{u0} {u1} {len}: {s}"
            );
            assert!((v - u1).abs() <= 1e-9 * 40.0 && a.abs() <= 1e-9 * 500.0);
        }
    }
}
