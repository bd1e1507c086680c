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
//!    V = min( F, V_i/|q_s|, √(σ·A_i/|q_ss|), ∛(σ·J_i/|q_sss|) )        (σ: SPEED_SHARES)
//!    A(v) = min_i (A_i − |q_ss|·v²)/|q_s|,   and 3·|q_ss|·v·A ≤ (J_i − |q_sss|·v³)/2
//!    J(v) = min_i (J_i − |q_sss|·v³ − 3·|q_ss|·v·A(v))/|q_s|
//!    ```
//!
//!    Every state on the segment with speed at most v, |a| ≤ A(v) and |j| ≤ J(v) meets
//!    every axis' limits there (each term of the sufficient condition is increasing in
//!    |q_s|, |q_ss|, |q_sss|, the speed and |a|), for any v ≤ V ([`Peaks::caps_at`]).
//!    σ < 1 keeps room for A and J where Equation 6 binds. A cell joins the segment
//!    before it while the merged limits at V stay within a share (one of
//!    [`MERGE_RATIOS`]) of the largest of the segment's cells' and of the cell's own;
//!    otherwise it starts a new segment. Few long segments have low limits, many short
//!    ones a = 0 between them, a high σ cruises faster and a low one changes speed
//!    faster: the motion is planned for each pair and the fastest plan is the motion
//!    (each is within the limits; step 3 says how the fastest is found).
//! 2. **The junctions** between segments are passed with a = 0 (and v under both
//!    segments' V). With a = 0 at both ends and constant caps, the distance to change
//!    speed from v₀ to v₁ is (v₀ + v₁)/2 · T with T = Δv/A + A/J (or 2·√(Δv/J) when A is
//!    not reached): closed forms ([`change`], [`reach`]). A backward pass over the
//!    junctions from rest at the end (the fastest speed from which each later junction
//!    can still be met) and a forward pass from rest at the start give the junction
//!    speeds — the classic look-ahead of a CNC planner, over the whole motion, run as
//!    the segments come ([`Lookahead`]): the backward pass reaches a junction's cap
//!    whatever follows where a bound of it that grows with the speed after does
//!    ([`surely_reached`]), and the segments before that junction are passed then, with
//!    the speeds of the passes over the whole motion to the last bit.
//! 3. **Caps in bands of speed.** A plan is built with each segment's caps
//!    at [`BAND_SHARES`] of its V (A(v) and J(v) grow as the speed falls: near the pole
//!    several times). A change of speed then follows a(v) = min(rise, A, fall): the
//!    rise at each band's jerk from the lower speed (a²/2 = ∫J dv), the plateau at A of
//!    the band of the higher speed, the fall to a = 0 at the higher speed — a piecewise
//!    linear a² in v whose stretches are pieces of constant jerk ([`rise`]); a fall of
//!    speed is a rise run backwards. Lengths are no longer closed forms: the junction
//!    speeds are searched ([`reach_banded`], false position). The caps need not be
//!    monotone across bands (a lower band's larger A leaves less of J).
//! 4. **Each segment** is then the time-optimal motion between its two junction speeds
//!    under its caps: a speed change up to a peak v_p ≤ V, a cruise, and a speed change
//!    down, v_p searched so that the segment's length is covered exactly.
//! 5. **The plan.** Every plan is first timed in closed form twice: with each segment's
//!    caps at its V (one band: the estimate) and with the largest of its bands' caps (a
//!    lower bound of its banded time: the banded motion keeps those caps). The plan of
//!    the least estimate is built with its bands, and the plan of the least lower bound
//!    too where that bound is below the first's banded time; the faster is the motion.
//!    (The estimate alone chose a plan up to 10 % slower on the fixtures' motions: the
//!    bands help plans unequally, and a lower band's J may be below the top's. Building
//!    every plan whose bound is below the best time found — the fastest of the eight,
//!    exactly — gained no more on the fixtures and cost twice the time on near-pole
//!    programs.)
//!
//! The motion is a sequence of pieces of constant jerk, evaluated exactly wherever it is
//! asked (every cycle for a trajectory): its finite differences are within the limits by
//! construction. On a straight line there is one segment with the axis' own limits (its
//! bands are one), and the motion is the time-optimal rest-to-rest S-curve. On a curved
//! path the price of the proof is the caps held constant over a segment (per band) and
//! a = 0 at its ends; the time is an upper bound of what the limits allow
//! (docs/simulation.md measures it against TOPP-RA's lower bound and the per-cycle
//! passes).
//!
//! The work grows with the cells (one walk for every plan, one more for the plans built
//! with bands, and for a plan of more than [`KEPT_SEGMENTS`] one more to hand its
//! segments out, beside the states) and the segments (a few closed forms each, a short
//! search per junction with bands), not the cycles. The memory grows with each plan's
//! look-ahead (the segments after the last junction whose speed is known: a braking
//! distance's worth where the caps allow), and four numbers a segment for the plans built
//! with bands where they are long, not with whole plans.

use polepatch_kinematics::Machine;
use rayon::prelude::*;

use crate::grid::{Cell, Geometry, for_each_cell};
use crate::pass::cbrt;
use crate::tolerances::{
    BAND_SHARES, JUNCTION_CAP_ROOM, LIMIT_USE, MERGE_RATIOS, PARALLEL_MIN_SEGMENTS,
    REACH_NEWTON_STEPS, REACH_REL, SEGMENT_A_MAX_MM_S2, SEGMENT_J_MAX_MM_S3, SPEED_SHARES,
    TIME_BISECTIONS,
};
use crate::{MinFeed, Parts, Step};

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
    fn limits(&self, machine: &Machine, share: f64) -> Limits {
        let v = self.speed(machine, share);
        let (a, j) = self.caps_at(machine, v);
        Limits { v, a, j }
    }

    /// The segment's speed V: the feed, each axis' V, and its curvature terms within
    /// `share` of A and J.
    fn speed(&self, machine: &Machine, share: f64) -> f64 {
        // The least of the square and cube roots is the root of the least radicand: one
        // root each.
        let (mut v, mut v2, mut v3) = (self.feed_mm_s, f64::INFINITY, f64::INFINITY);
        for i in 0..5 {
            let l = machine.limits[i];
            let (vl, al, jl) = (LIMIT_USE * l.v, LIMIT_USE * l.a, LIMIT_USE * l.j);
            let [m1, m2, m3] = self.m[i];
            if m1 > 0.0 {
                v = v.min(vl / m1);
            }
            if m2 > 0.0 {
                v2 = v2.min(share * al / m2);
            }
            if m3 > 0.0 {
                v3 = v3.min(share * jl / m3);
            }
        }
        if v2.is_finite() {
            v = v.min(v2.sqrt());
        }
        if v3.is_finite() {
            v = v.min(cbrt(v3));
        }
        v
    }

    /// The path's |acceleration| and |jerk| caps for every speed up to `v` (below the
    /// segment's V): the rest of each axis' A after its curvature term at `v`, at most so
    /// much that the v·|a| term takes half of J's rest; then the rest of J.
    fn caps_at(&self, machine: &Machine, v: f64) -> (f64, f64) {
        let mut a = SEGMENT_A_MAX_MM_S2;
        for i in 0..5 {
            let l = machine.limits[i];
            let (al, jl) = (LIMIT_USE * l.a, LIMIT_USE * l.j);
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
            let jl = LIMIT_USE * machine.limits[i].j;
            let [m1, m2, m3] = self.m[i];
            if m1 > 0.0 {
                j = j.min((jl - m3 * v * v * v - 3.0 * m2 * v * a) / m1);
            }
        }
        (a, j)
    }
}

/// A segment: where it starts, its length, its limits (its caps at its V), and its
/// largest caps over its bands (`low`: the caps of a bound from below of its banded
/// time).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Segment {
    s0_mm: f64,
    len_mm: f64,
    lim: Limits,
    low: Limits,
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

    fn close(&self, machine: &Machine) -> Segment {
        let low = self
            .banded(machine)
            .bands
            .iter()
            .fold(self.lim, |l, b| Limits {
                v: l.v,
                a: l.a.max(b.a),
                j: l.j.max(b.j),
            });
        Segment {
            s0_mm: self.s0_mm,
            len_mm: self.s1_mm - self.s0_mm,
            lim: self.lim,
            low,
        }
    }

    /// The segment with its caps at [`BAND_SHARES`] of its speed (the last share is 1:
    /// its V and caps).
    fn banded(&self, machine: &Machine) -> Banded {
        let v = self.lim.v;
        Banded {
            s0_mm: self.s0_mm,
            len_mm: self.s1_mm - self.s0_mm,
            bands: std::array::from_fn(|b| {
                if BAND_SHARES[b] >= 1.0 {
                    return self.lim;
                }
                let vb = v * BAND_SHARES[b];
                let (a, j) = self.peaks.caps_at(machine, vb);
                Limits { v: vb, a, j }
            }),
        }
    }
}

/// The merge plans: every speed share of [`SPEED_SHARES`] (by index) with every merge
/// share of [`MERGE_RATIOS`].
fn all_plans() -> Vec<(usize, f64)> {
    (0..SPEED_SHARES.len())
        .flat_map(|k| MERGE_RATIOS.iter().map(move |&r| (k, r)))
        .collect()
}

/// The segments of the path (module docs, step 1), once per plan `(speed share index,
/// merge share)`, in one walk over the cells; each closed by `close` and handed to `sink`
/// with its plan's index as it is closed (in order within a plan).
fn walk_segments<T>(
    geo: &Geometry,
    machine: &Machine,
    tcy_s: f64,
    max_cells: usize,
    plans: &[(usize, f64)],
    close: &dyn Fn(&Open) -> T,
    sink: &mut dyn FnMut(usize, T),
) {
    let mut open: Vec<Option<Open>> = vec![None; plans.len()];
    for_each_cell(geo, tcy_s, max_cells, &mut |c: &Cell| {
        let p = Peaks::of(c);
        let mut own: [Option<Limits>; SPEED_SHARES.len()] = [None; SPEED_SHARES.len()];
        for (k, &(share, ratio)) in plans.iter().enumerate() {
            let own = *own[share].get_or_insert_with(|| p.limits(machine, SPEED_SHARES[share]));
            if let Some(o) = &mut open[k] {
                let merged = o.peaks.merge(&p);
                let ok = |m: f64, a: f64, b: f64| m >= ratio * a.max(b);
                // The merged limits as `Peaks::limits` makes them, the caps only for a
                // speed that passes.
                let v = merged.speed(machine, SPEED_SHARES[share]);
                let caps = ok(v, o.best.v, own.v).then(|| merged.caps_at(machine, v));
                if let Some((a, j)) = caps
                    && ok(a, o.best.a, own.a)
                    && ok(j, o.best.j, own.j)
                {
                    o.best = Limits {
                        v: o.best.v.max(own.v),
                        a: o.best.a.max(own.a),
                        j: o.best.j.max(own.j),
                    };
                    o.peaks = merged;
                    o.lim = Limits { v, a, j };
                    o.s1_mm = c.s1_mm;
                    continue;
                }
                sink(k, close(o));
            }
            open[k] = Some(Open::of(c, p, own));
        }
    });
    for (k, o) in open.iter().enumerate() {
        if let Some(o) = o {
            sink(k, close(o));
        }
    }
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

/// The largest x in [`lo`, `hi`] with `f(x) ≤ 0`, for `f` increasing with `f(lo) ≤ 0 <
/// f(hi)`: false position with the Illinois rule, the bracket kept, to [`REACH_REL`] of
/// `hi` (a smooth f: a few steps where halving takes thirty).
fn largest_within(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (mut flo, mut fhi) = (f(lo), f(hi));
    let mut side = 0i8;
    for _ in 0..TIME_BISECTIONS {
        if hi - lo <= REACH_REL * hi.abs() {
            break;
        }
        let mut x = if fhi > flo {
            lo + (hi - lo) * (-flo / (fhi - flo))
        } else {
            0.5 * (lo + hi)
        };
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
            if !(x > lo && x < hi) {
                break;
            }
        }
        let fx = f(x);
        if fx <= 0.0 {
            lo = x;
            flo = fx;
            if side == -1 {
                fhi *= 0.5;
            }
            side = -1;
        } else {
            hi = x;
            fhi = fx;
            if side == 1 {
                flo *= 0.5;
            }
            side = 1;
        }
    }
    lo
}

/// Top speed of a segment (its V).
fn top_speed(seg: &impl Seg) -> f64 {
    let b = seg.bands();
    b[b.len() - 1].v
}

/// The largest speed v ≥ `v0` to which a change from `v0` ([`change`]) fits in `len`:
/// the root of the change's length, then lowered by the last digits that v0 + Δv rounds
/// up, so that the change never needs more than `len`.
fn reach(v0: f64, len: f64, a: f64, j: f64) -> f64 {
    let mut v1 = reach_root(v0, len, a, j);
    for _ in 0..REACH_NEWTON_STEPS {
        if v1 <= v0 || change(v0, v1, a, j).1 <= len {
            break;
        }
        // The next float below (v1 > v0 ≥ 0: positive and finite).
        v1 = f64::from_bits(v1.to_bits() - 1);
    }
    if change(v0, v1, a, j).1 > len { v0 } else { v1 }
}

/// The root of [`change`]'s length `len` from `v0` (both regimes, closed forms).
fn reach_root(v0: f64, len: f64, a: f64, j: f64) -> f64 {
    if len <= 0.0 {
        return v0;
    }
    // While A is not reached: x = √Δv solves x³ + p·x = q with p = 2·v0, q = len·√j: one
    // real root, x = w − p/(3·w) with w = ∛(q/2 + √(q²/4 + p³/27)) (Cardano without the
    // cancelling difference of two cube roots), polished by Newton where x ≪ w.
    let q = len * j.sqrt();
    let p = 2.0 * v0;
    let w = cbrt(0.5 * q + (0.25 * q * q + p * p * p / 27.0).sqrt());
    let mut x = if w > 0.0 { w - p / (3.0 * w) } else { 0.0 };
    if x.is_nan() || x <= 0.0 || x * x < 1e-6 * w * w {
        x = (q / p.max(f64::MIN_POSITIVE)).min(cbrt(q));
    }
    for _ in 0..REACH_NEWTON_STEPS {
        let d = 3.0 * x * x + p;
        if d.is_nan() || d <= 0.0 {
            break;
        }
        x -= (x * x * x + p * x - q) / d;
    }
    let x = x.max(0.0);
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

/// The pieces of one change of speed (at most [`MAX_CHANGE_PIECES`]).
#[derive(Debug, Clone, Copy)]
struct Pieces {
    p: [Piece; MAX_CHANGE_PIECES],
    n: usize,
}

/// Pieces of a change of speed under banded caps: intervals (≤ 3 bands) × sub-intervals
/// (≤ 4: where the rise, the plateau and the fall take over).
const MAX_CHANGE_PIECES: usize = 4 * BAND_SHARES.len();

impl Pieces {
    fn new() -> Pieces {
        Pieces {
            p: [Piece { t: 0.0, j: 0.0 }; MAX_CHANGE_PIECES],
            n: 0,
        }
    }

    fn push(&mut self, t: f64, j: f64) {
        if t > 0.0 && self.n < MAX_CHANGE_PIECES {
            self.p[self.n] = Piece { t, j };
            self.n += 1;
        }
    }

    fn as_slice(&self) -> &[Piece] {
        &self.p[..self.n]
    }

    /// Time and distance from speed `v0` (a = 0).
    fn time_distance(&self, v0: f64) -> (f64, f64) {
        let (mut t, mut s, mut v, mut a) = (0.0, 0.0, v0, 0.0);
        for p in self.as_slice() {
            (s, v, a) = advance(s, v, a, p.j, p.t);
            t += p.t;
        }
        (t, s)
    }
}

/// Banded caps (`bands`, ascending in speed; each band's caps hold at every speed up to
/// its `v`): the pieces of the time-optimal rise from `v_lo` to `v_hi` (≤ the last band's
/// speed) with a = 0 at both ends. With the acceleration as a function of speed, a rise at
/// jerk J gives a²/2 = ∫J dv from `v_lo`, a fall to 0 at `v_hi` a²/2 = ∫J dv to `v_hi`,
/// and a ≤ A of the band of `v_hi` throughout (the plateau): a(v) is the least of the
/// three, its square piecewise linear in v. Each stretch where one of them is the least,
/// within one band, is one piece of constant jerk (+J, 0 or −J).
fn rise(v_lo: f64, v_hi: f64, bands: &[Limits]) -> Pieces {
    let mut out = Pieces::new();
    if v_hi <= v_lo {
        return out;
    }
    let band_of = |v: f64| {
        bands
            .iter()
            .position(|b| v <= b.v)
            .unwrap_or(bands.len() - 1)
    };
    let ap = bands[band_of(v_hi)].a;
    let ap2 = ap * ap;
    // Breakpoints: v_lo, the bands' tops strictly between, v_hi.
    const NB: usize = BAND_SHARES.len();
    let mut x = [0.0; NB + 1];
    let mut nx = 0;
    x[nx] = v_lo;
    nx += 1;
    for b in bands {
        if b.v > v_lo && b.v < v_hi && nx < NB {
            x[nx] = b.v;
            nx += 1;
        }
    }
    x[nx] = v_hi;
    nx += 1;
    let jerk: [f64; NB] = std::array::from_fn(|i| {
        if i + 1 < nx {
            bands[band_of(x[i + 1])].j
        } else {
            0.0
        }
    });
    // a² of the rise and of the fall at the breakpoints.
    let mut r = [0.0; NB + 1];
    let mut f = [0.0; NB + 1];
    for i in 0..nx - 1 {
        r[i + 1] = r[i] + 2.0 * jerk[i] * (x[i + 1] - x[i]);
    }
    for i in (0..nx - 1).rev() {
        f[i] = f[i + 1] + 2.0 * jerk[i] * (x[i + 1] - x[i]);
    }
    for i in 0..nx - 1 {
        let (x0, x1, jj) = (x[i], x[i + 1], jerk[i]);
        let rr = |y: f64| r[i] + 2.0 * jj * (y - x0);
        let ff = |y: f64| f[i] - 2.0 * jj * (y - x0);
        let e = |y: f64| rr(y).min(ff(y)).min(ap2).max(0.0);
        // Where the least of the three changes within [x0, x1].
        let mut y = [x0, x1, x1, x1, x1];
        let mut ny = 1;
        for c in [
            x0 + (ap2 - r[i]) / (2.0 * jj),
            x0 + (f[i] - ap2) / (2.0 * jj),
            x0 + (f[i] - r[i]) / (4.0 * jj),
        ] {
            if c > x0 && c < x1 {
                y[ny] = c;
                ny += 1;
            }
        }
        y[ny] = x1;
        ny += 1;
        y[..ny].sort_by(f64::total_cmp);
        for k in 0..ny - 1 {
            let (y0, y1) = (y[k], y[k + 1]);
            if y1 <= y0 {
                continue;
            }
            let mid = 0.5 * (y0 + y1);
            let (rm, fm) = (rr(mid), ff(mid));
            let (a0, a1) = (e(y0).sqrt(), e(y1).sqrt());
            if ap2 <= rm && ap2 <= fm {
                out.push((y1 - y0) / ap, 0.0);
            } else if rm <= fm {
                out.push((a1 - a0) / jj, jj);
            } else {
                out.push((a0 - a1) / jj, -jj);
            }
        }
    }
    out
}

/// The pieces of a change of speed from `v0` to `v1` (a = 0 at both ends) under banded
/// caps: a rise, or a rise turned in time (a fall is a rise run backwards: same jerks,
/// pieces in reverse order).
fn change_pieces(v0: f64, v1: f64, bands: &[Limits]) -> Pieces {
    if one_band(bands) {
        let Limits { a, j, .. } = bands[bands.len() - 1];
        let mut out = Pieces::new();
        let dv = (v1 - v0).abs();
        let sign = if v1 > v0 { 1.0 } else { -1.0 };
        if dv * j >= a * a {
            out.push(a / j, sign * j);
            out.push(dv / a - a / j, 0.0);
            out.push(a / j, -sign * j);
        } else if dv > 0.0 {
            let tj = (dv / j).sqrt();
            out.push(tj, sign * j);
            out.push(tj, -sign * j);
        }
        return out;
    }
    if v1 >= v0 {
        rise(v0, v1, bands)
    } else {
        let mut up = rise(v1, v0, bands);
        up.p[..up.n].reverse();
        up
    }
}

/// Whether the bands' caps are all the top band's (a line: the caps do not depend on the
/// speed), so that the closed forms hold. (The caps need not be monotone across bands: a
/// lower band's larger A leaves less of J for its jerk.)
fn one_band(bands: &[Limits]) -> bool {
    let top = bands[bands.len() - 1];
    bands.iter().all(|b| b.a == top.a && b.j == top.j)
}

/// Time and distance of a change of speed under banded caps.
fn change_banded(v0: f64, v1: f64, bands: &[Limits]) -> (f64, f64) {
    if one_band(bands) {
        let top = bands[bands.len() - 1];
        return change(v0, v1, top.a, top.j);
    }
    change_pieces(v0, v1, bands).time_distance(v0)
}

/// The largest speed v ≥ `v0`, at most the last band's, to which a change from `v0`
/// fits in `len` under banded caps: the closed form under the top band's caps where the
/// bands are one, else a search from `v0` (or from that closed form's speed where it
/// fits: a guess, since a lower band's jerk may be below the top's).
fn reach_banded(v0: f64, len: f64, bands: &[Limits]) -> f64 {
    let top = bands[bands.len() - 1];
    let guess = reach(v0, len, top.a, top.j);
    if one_band(bands) {
        return guess;
    }
    if change_banded(v0, top.v, bands).1 <= len {
        return top.v;
    }
    let lo = if guess > v0 && guess < top.v && change_banded(v0, guess, bands).1 <= len {
        guess
    } else {
        v0
    };
    largest_within(lo, top.v, |v| change_banded(v0, v, bands).1 - len)
}

/// A segment's place and its caps, banded or not.
trait Seg {
    fn s0_mm(&self) -> f64;
    fn len_mm(&self) -> f64;
    /// Caps in bands of speed, ascending; the last is the segment's V and its caps.
    fn bands(&self) -> &[Limits];
}

impl Seg for Segment {
    fn s0_mm(&self) -> f64 {
        self.s0_mm
    }
    fn len_mm(&self) -> f64 {
        self.len_mm
    }
    fn bands(&self) -> &[Limits] {
        std::slice::from_ref(&self.lim)
    }
}

impl<T: Seg> Seg for &T {
    fn s0_mm(&self) -> f64 {
        (*self).s0_mm()
    }
    fn len_mm(&self) -> f64 {
        (*self).len_mm()
    }
    fn bands(&self) -> &[Limits] {
        (*self).bands()
    }
}

/// A segment with its caps at [`BAND_SHARES`] of its speed.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Banded {
    s0_mm: f64,
    len_mm: f64,
    bands: [Limits; BAND_SHARES.len()],
}

impl Seg for Banded {
    fn s0_mm(&self) -> f64 {
        self.s0_mm
    }
    fn len_mm(&self) -> f64 {
        self.len_mm
    }
    fn bands(&self) -> &[Limits] {
        &self.bands
    }
}

/// The most pieces of one segment: a change up, a cruise, a change down.
const MAX_SEGMENT_PIECES: usize = 2 * MAX_CHANGE_PIECES + 1;

/// Segments whose pieces are made at once before they are handed out ([`plan`]).
const PIECES_CHUNK: usize = 4096;

/// Chunks of [`PIECES_CHUNK`] segments the walk that hands out a long plan's segments
/// may have ready before they are handed out ([`plan`]).
const WALKED_CHUNKS_AHEAD: usize = 2;

/// Segments a [`Lookahead`] holds before its first backward pass, and at least between
/// two (each pass runs over all it holds: doubling the wait keeps the work linear where
/// the speeds stay unknown long).
const LOOKAHEAD_MIN_SEGMENTS: usize = 1024;

/// Segments (over all plans) the walk gathers before handing them to the plans' timers
/// at once ([`plan_times`]).
const TIMER_BATCH_SEGMENTS: usize = 8 * PIECES_CHUNK;

/// A plan built with its bands keeps its segments for the motion's states up to this many
/// (about 3 MB); a longer one keeps only their speeds and their changes' length, and is
/// walked again.
const KEPT_SEGMENTS: usize = 4 * PIECES_CHUNK;

/// The pieces of segment `seg` from junction speed `u0` to `u1` (module docs, step 3).
fn segment_pieces(seg: &impl Seg, u0: f64, u1: f64, out: &mut Vec<Piece>) {
    pieces_at(seg, u0, peak(seg, u0, u1), u1, out);
}

/// A segment's top speed between its junction speeds, and the length and time of its
/// changes up to it and down from it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Top {
    vp: f64,
    used_mm: f64,
    t_s: f64,
}

/// The top speed of segment `seg` between junction speeds `u0` and `u1` (its V where the
/// changes up to it and down from it fit its length, else the largest that fits), with
/// what its changes take there.
fn peak(seg: &impl Seg, u0: f64, u1: f64) -> Top {
    let bands = seg.bands();
    let v = bands[bands.len() - 1].v;
    let len = seg.len_mm();
    let at = |vp: f64| {
        let (used_mm, t_s) = changes(seg, u0, vp, u1);
        Top { vp, used_mm, t_s }
    };
    let lo0 = u0.max(u1);
    let top = at(v);
    if top.used_mm <= len {
        top
    } else {
        at(largest_within(lo0, v.max(lo0), |vp| {
            changes(seg, u0, vp, u1).0 - len
        }))
    }
}

/// The length the changes from `u0` up to `vp` and down to `u1` take on `seg`, and their
/// time.
fn changes(seg: &impl Seg, u0: f64, vp: f64, u1: f64) -> (f64, f64) {
    let bands = seg.bands();
    let (up, down) = (change_banded(u0, vp, bands), change_banded(vp, u1, bands));
    (up.1 + down.1, up.0 + down.0)
}

/// The pieces of segment `seg` from `u0` up to its top speed, a cruise, and down to `u1`.
fn pieces_at(seg: &impl Seg, u0: f64, top: Top, u1: f64, out: &mut Vec<Piece>) {
    out.clear();
    let bands = seg.bands();
    let vp = top.vp;
    out.extend_from_slice(change_pieces(u0, vp, bands).as_slice());
    let cruise = seg.len_mm() - top.used_mm;
    if cruise > 0.0 && vp > 0.0 {
        out.push(Piece {
            t: cruise / vp,
            j: 0.0,
        });
    }
    out.extend_from_slice(change_pieces(vp, u1, bands).as_slice());
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
    // Each segmentation timed with its caps at its top speed (the estimate) and with its
    // largest banded caps (a lower bound of its banded time), closed forms, all of them
    // at once. The one with the least estimate is built with its banded caps, and the one
    // with the least lower bound where that bound is below the first's banded time; the
    // faster is the motion.
    let plans = all_plans();
    let close = |o: &Open| o.close(machine);
    let bounds = plan_times(geo, machine, tcy_s, max_cells, &plans, &close);
    let mut first = 0;
    for (k, b) in bounds.iter().enumerate() {
        if b.0 < bounds[first].0 {
            first = k;
        }
    }
    let banded = |this, also| banded_time(geo, machine, tcy_s, max_cells, this, also);
    // The plan of the least lower bound is the one likeliest to beat the first: built
    // too while its bound is below the first's banded time (its segments gathered in the
    // same walk where its bound is below the first's estimate, where it will likely pass).
    let mut second = first;
    for (k, b) in bounds.iter().enumerate() {
        if k != first && (second == first || b.1 < bounds[second].1) {
            second = k;
        }
    }
    let together = second != first && bounds[second].1 < bounds[first].0;
    let (mut best, gathered) = banded(plans[first], together.then_some(plans[second]));
    let mut best_plan = plans[first];
    if second != first && bounds[second].1 < best.time_s {
        let p = match gathered {
            Some(segs) => {
                let mut timer = BandedTimer::new();
                segs.into_iter().for_each(|seg| timer.push(seg));
                timer.finish()
            }
            None => banded(plans[second], None).0,
        };
        if p.time_s < best.time_s {
            (best, best_plan) = (p, plans[second]);
        }
    }
    // The motion's states: its segments' pieces (each depends on its junction speeds and
    // top speed only) made in chunks, on all cores where a chunk is long, then handed out
    // in order, state by state. From the segments kept, or from the plan walked again
    // where it was too long to keep.
    let mut out = Emit::new(geo, every_cycle, tcy_s, sink);
    let mut pieces: Vec<Vec<Piece>> = Vec::new();
    let mut emit = |chunk: &[Passed]| {
        if pieces.len() < chunk.len() {
            pieces.resize_with(chunk.len(), || Vec::with_capacity(MAX_SEGMENT_PIECES));
        }
        let make = |(p, out): (&Passed, &mut Vec<Piece>)| pieces_at(&p.seg, p.u0, p.top, p.u1, out);
        let slots = &mut pieces[..chunk.len()];
        if chunk.len() >= PARALLEL_MIN_SEGMENTS {
            chunk.par_iter().zip(slots.par_iter_mut()).for_each(make);
        } else {
            chunk.iter().zip(slots.iter_mut()).for_each(make);
        }
        for (p, pieces) in chunk.iter().zip(pieces.iter()) {
            out.segment(&p.seg, p.u0, pieces);
        }
    };
    match best.built {
        Built::Kept(kept) => kept.chunks(PIECES_CHUNK).for_each(&mut emit),
        Built::Speeds(speeds) => {
            // The same walk as the one that timed it (the same segments, in order), on a
            // thread of its own, its chunks handed out here as they come.
            std::thread::scope(|scope| {
                let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<Passed>>(WALKED_CHUNKS_AHEAD);
                scope.spawn(move || {
                    let mut chunk = Vec::with_capacity(PIECES_CHUNK);
                    let mut next = speeds.iter();
                    walk_segments(
                        geo,
                        machine,
                        tcy_s,
                        max_cells,
                        &[best_plan],
                        &|o: &Open| o.banded(machine),
                        &mut |_, seg| {
                            let [u0, u1, vp, used_mm] =
                                *next.next().expect("the same segments as timed");
                            // The times are not needed to hand the segments out.
                            let top = Top {
                                vp,
                                used_mm,
                                t_s: 0.0,
                            };
                            chunk.push(Passed {
                                seg,
                                u0,
                                u1,
                                top,
                                t_s: 0.0,
                            });
                            if chunk.len() == PIECES_CHUNK {
                                let full =
                                    std::mem::replace(&mut chunk, Vec::with_capacity(PIECES_CHUNK));
                                // Only fails where the receiver panicked: that panic is
                                // the one the scope passes on.
                                let _ = tx.send(full);
                            }
                        },
                    );
                    let _ = tx.send(chunk);
                });
                for chunk in rx {
                    emit(&chunk);
                }
            });
        }
    }
    out.finish()
}

/// Each plan's time with its caps at V and with its low caps (module docs, step 5), in
/// one walk of the cells; the segments handed to the plans' [`Timer`]s in batches, the
/// timers on all cores where a batch is long.
fn plan_times(
    geo: &Geometry,
    machine: &Machine,
    tcy_s: f64,
    max_cells: usize,
    plans: &[(usize, f64)],
    close: &dyn Fn(&Open) -> Segment,
) -> Vec<(f64, f64)> {
    let mut timers: Vec<(Timer, Timer)> = plans
        .iter()
        .map(|_| (Timer::default(), Timer::default()))
        .collect();
    let mut batch: Vec<Vec<Segment>> = plans.iter().map(|_| Vec::new()).collect();
    let mut held = 0;
    walk_segments(
        geo,
        machine,
        tcy_s,
        max_cells,
        plans,
        close,
        &mut |k, seg| {
            batch[k].push(seg);
            held += 1;
            if held >= TIMER_BATCH_SEGMENTS {
                hand(&mut timers, &mut batch, true);
                held = 0;
            }
        },
    );
    hand(&mut timers, &mut batch, held >= PARALLEL_MIN_SEGMENTS);
    let finish = |(e, l): (Timer, Timer)| (e.finish(), l.finish());
    if timers.iter().map(|t| t.0.held()).sum::<usize>() >= PARALLEL_MIN_SEGMENTS {
        timers.into_par_iter().map(finish).collect()
    } else {
        timers.into_iter().map(finish).collect()
    }
}

/// Each plan's batch of segments to its two timers: with its caps at V and with its low
/// caps (on all cores when `parallel`).
fn hand(timers: &mut [(Timer, Timer)], batch: &mut [Vec<Segment>], parallel: bool) {
    let take = |(t, b): (&mut (Timer, Timer), &mut Vec<Segment>)| {
        for seg in b.drain(..) {
            t.0.push(seg);
            t.1.push(Segment {
                lim: seg.low,
                ..seg
            });
        }
    };
    if parallel {
        timers
            .par_iter_mut()
            .zip(batch.par_iter_mut())
            .for_each(take);
    } else {
        timers.iter_mut().zip(batch.iter_mut()).for_each(take);
    }
}

/// The junction speeds of a plan over segments handed to it in order (module docs, step
/// 2: the backward pass from rest at the end, then the forward pass from rest at the
/// start), holding only the segments whose speeds are not yet known: the memory of a
/// plan bounded by its look-ahead, not by the motion.
///
/// From rest after the last segment held, a speed each junction surely reaches whatever
/// follows ([`surely_reached`], a bound that grows with the speed after the junction).
/// Where that reaches a junction's cap, the backward pass's speed there is its cap,
/// whatever follows, and from that junction back the pass is the same operations on the
/// same numbers as over the whole motion: the forward pass runs to it and hands each
/// segment on with its speeds, those of the passes over the whole motion.
/// [`Lookahead::finish`] ends the motion at rest. (The backward pass's own speeds from
/// rest would not do as the bound: a change's reach, with a = 0 at both ends, falls as
/// the speed it starts from rises while it more than triples it.)
struct Lookahead<S> {
    /// Segments from the first junction the forward pass has not passed.
    segs: std::collections::VecDeque<S>,
    /// Forward speed at the first junction held, mm/s.
    u0: f64,
    /// Segments held at which the next backward pass runs.
    check_at: usize,
    /// The backward pass's junction speeds (reused).
    u: Vec<f64>,
}

impl<S> Default for Lookahead<S> {
    fn default() -> Self {
        Lookahead {
            segs: std::collections::VecDeque::new(),
            u0: 0.0,
            check_at: LOOKAHEAD_MIN_SEGMENTS,
            u: Vec::new(),
        }
    }
}

impl<S: Seg + Copy> Lookahead<S> {
    /// Take the next segment; `known` gets, in order, each segment whose junction speeds
    /// (`u0` before it, `u1` after) are known.
    fn push(&mut self, seg: S, known: &mut dyn FnMut(&S, f64, f64)) {
        self.segs.push_back(seg);
        if self.segs.len() >= self.check_at {
            self.advance(false, known);
            self.check_at = (2 * self.segs.len()).max(LOOKAHEAD_MIN_SEGMENTS);
        }
    }

    /// The motion ends at rest after the last segment pushed: the rest to `known`.
    fn finish(&mut self, known: &mut dyn FnMut(&S, f64, f64)) {
        self.advance(true, known);
    }

    /// [`Lookahead::push`] the next segment, or with `None` [`Lookahead::finish`].
    fn take(&mut self, seg: Option<S>, known: &mut dyn FnMut(&S, f64, f64)) {
        match seg {
            Some(seg) => self.push(seg, known),
            None => self.finish(known),
        }
    }

    /// The backward pass over the segments held, from the last junction whose speed is
    /// known (`end`: the end, at rest), and the forward pass up to it.
    fn advance(&mut self, end: bool, known: &mut dyn FnMut(&S, f64, f64)) {
        let n = self.segs.len();
        let cap = |k: usize| top_speed(&self.segs[k - 1]).min(top_speed(&self.segs[k]));
        // u[k]: the speed between held segments k − 1 and k (u[0] is the forward pass's).
        let (upto, last) = if end {
            (n, 0.0)
        } else {
            // From the last junction held back: a speed each junction surely reaches
            // whatever follows (from rest after the last), until one surely reaches its
            // cap.
            let mut lo = 0.0;
            let mut found = None;
            for k in (1..n).rev() {
                let (c, s) = (cap(k), &self.segs[k]);
                let r = surely_reached(s, lo);
                if r >= c * (1.0 + JUNCTION_CAP_ROOM) {
                    found = Some((k, c));
                    break;
                }
                lo = c.min(r);
            }
            match found {
                Some(f) => f,
                None => return,
            }
        };
        let mut u = std::mem::take(&mut self.u);
        u.clear();
        u.resize(upto + 1, 0.0);
        u[upto] = last;
        for k in (1..upto).rev() {
            let s = &self.segs[k];
            u[k] = cap(k).min(reach_banded(u[k + 1], s.len_mm(), s.bands()));
        }
        for (k, seg) in self.segs.iter().take(upto).enumerate() {
            let u1 = u[k + 1].min(reach_banded(self.u0, seg.len_mm(), seg.bands()));
            known(seg, self.u0, u1);
            self.u0 = u1;
        }
        self.segs.drain(..upto);
        self.u = u;
    }
}

/// A speed that the backward pass reaches over `seg` from every speed at least `lo` at
/// its end (a lower bound of the pass's [`reach_banded`], which falls as the speed it
/// starts from rises while it more than triples it, and so bounds nothing by itself).
///
/// A change from x ≥ `lo` to v ≥ x takes its mean speed times its time, at most
/// v·T(v − `lo`) with T the time of that change under the least of the segment's bands'
/// caps (a time that grows with the change, and is longest under the least caps). A v with
/// v·T(v − `lo`) within the length less [`JUNCTION_CAP_ROOM`] is reached from every such x
/// (from an x above it, by not braking): the root of v·T(v − `lo`) = length, in closed form
/// (a quadratic where A is reached, Newton on the cubic from above where it is not),
/// checked, and halved towards `lo` where the check fails.
fn surely_reached(seg: &impl Seg, lo: f64) -> f64 {
    let (a, j) = seg
        .bands()
        .iter()
        .fold((f64::INFINITY, f64::INFINITY), |(a, j), b| {
            (a.min(b.a), j.min(b.j))
        });
    let len = seg.len_mm();
    let fits = |v: f64| v * change(lo, v, a, j).0 <= len * (1.0 - JUNCTION_CAP_ROOM);
    let target = len * (1.0 - 2.0 * JUNCTION_CAP_ROOM);
    // A reached: v·((v − lo)/a + a/j) = target, a quadratic in v.
    let b = a / j - lo / a;
    let mut v = 0.5 * a * (-b + (b * b + 4.0 * target / a).sqrt());
    let a_reached = v - lo >= a * a / j;
    if !a_reached {
        // A not reached: 2·v·√((v − lo)/j) = target, the cubic v²·(v − lo) = q, whose root
        // Newton approaches from above (from lo + ∛q, above it) where it is convex.
        let q = 0.25 * j * target * target;
        v = lo + cbrt(q);
        for _ in 0..REACH_NEWTON_STEPS + 3 {
            let d = v * (3.0 * v - 2.0 * lo);
            if d.is_nan() || d <= 0.0 {
                break;
            }
            v -= (v * v * (v - lo) - q) / d;
        }
    }
    for _ in 0..4 {
        if v > lo && fits(v) {
            return v;
        }
        v = lo + 0.5 * (v - lo);
    }
    lo
}

/// A plan's time with each segment's caps at its V (the estimate) or with its low caps
/// (a lower bound of its banded time): the forward pass of [`Lookahead`], each segment's
/// pieces timed.
struct Timer {
    ahead: Lookahead<Segment>,
    pieces: Vec<Piece>,
    time_s: f64,
}

impl Default for Timer {
    fn default() -> Self {
        Timer {
            ahead: Lookahead::default(),
            pieces: Vec::with_capacity(MAX_SEGMENT_PIECES),
            time_s: 0.0,
        }
    }
}

impl Timer {
    fn push(&mut self, seg: Segment) {
        self.take(Some(seg));
    }

    /// The next segment (`None`: the end of the motion), and the time of each segment
    /// whose speeds are then known.
    fn take(&mut self, seg: Option<Segment>) {
        let Timer {
            ahead,
            pieces,
            time_s,
        } = self;
        ahead.take(seg, &mut |seg, u0, u1| {
            segment_pieces(seg, u0, u1, pieces);
            *time_s += pieces.iter().map(|p| p.t).sum::<f64>();
        });
    }

    /// Segments held.
    fn held(&self) -> usize {
        self.ahead.segs.len()
    }

    fn finish(mut self) -> f64 {
        self.take(None);
        self.time_s
    }
}

/// A segment of a plan built with its bands, with its junction speeds, its top speed and
/// its time.
#[derive(Debug, Clone, Copy)]
struct Passed {
    seg: Banded,
    u0: f64,
    u1: f64,
    top: Top,
    t_s: f64,
}

/// A plan built with its banded caps (module docs, steps 2–4) as its segments come: the
/// [`Lookahead`]'s speeds, then each segment's top speed and time, in chunks of
/// [`PIECES_CHUNK`] (on all cores where a chunk is long), handed on in order.
struct BandedRun {
    ahead: Lookahead<Banded>,
    ready: Vec<(Banded, f64, f64)>,
}

impl BandedRun {
    fn new() -> BandedRun {
        BandedRun {
            ahead: Lookahead::default(),
            ready: Vec::new(),
        }
    }

    fn push(&mut self, seg: Banded, out: &mut dyn FnMut(&[Passed])) {
        self.take(Some(seg), out);
    }

    fn finish(mut self, out: &mut dyn FnMut(&[Passed])) {
        self.take(None, out);
    }

    /// The next segment (`None`: the end of the motion); the segments whose speeds are
    /// then known passed on in chunks (all that are left at the end).
    fn take(&mut self, seg: Option<Banded>, out: &mut dyn FnMut(&[Passed])) {
        let end = seg.is_none();
        let ready = &mut self.ready;
        self.ahead
            .take(seg, &mut |s, u0, u1| ready.push((*s, u0, u1)));
        if end || self.ready.len() >= PIECES_CHUNK {
            Self::pass(&mut self.ready, out);
        }
    }

    /// Each ready segment's top speed and time, handed on.
    fn pass(ready: &mut Vec<(Banded, f64, f64)>, out: &mut dyn FnMut(&[Passed])) {
        let top = |&(seg, u0, u1): &(Banded, f64, f64)| {
            let top = peak(&seg, u0, u1);
            let (vp, used, t) = (top.vp, top.used_mm, top.t_s);
            let cruise = seg.len_mm() - used;
            let t_s = if cruise > 0.0 && vp > 0.0 {
                t + cruise / vp
            } else {
                t
            };
            Passed {
                seg,
                u0,
                u1,
                top,
                t_s,
            }
        };
        let passed: Vec<Passed> = if ready.len() >= PARALLEL_MIN_SEGMENTS {
            ready.par_iter().map(top).collect()
        } else {
            ready.iter().map(top).collect()
        };
        ready.clear();
        if !passed.is_empty() {
            out(&passed);
        }
    }
}

/// A plan built with its bands: its time, and its segments with their speeds.
#[derive(Debug, Default)]
struct BandedTime {
    time_s: f64,
    built: Built,
}

/// What a plan built with its bands keeps for the motion's states.
#[derive(Debug)]
enum Built {
    /// Its segments with their speeds, up to [`KEPT_SEGMENTS`] of them.
    Kept(Vec<Passed>),
    /// Each segment's junction speeds, top speed and its changes' length (`u0`, `u1`, `vp`,
    /// `used_mm`), the segments to be
    /// walked again.
    Speeds(Vec<[f64; 4]>),
}

impl Default for Built {
    fn default() -> Self {
        Built::Kept(Vec::new())
    }
}

/// A plan built with its banded caps as its segments come: its time and what it keeps.
struct BandedTimer {
    run: BandedRun,
    out: BandedTime,
}

impl BandedTimer {
    fn new() -> BandedTimer {
        BandedTimer {
            run: BandedRun::new(),
            out: BandedTime::default(),
        }
    }

    fn push(&mut self, seg: Banded) {
        let out = &mut self.out;
        self.run.push(seg, &mut |p| out.take(p));
    }

    fn finish(self) -> BandedTime {
        let BandedTimer { run, mut out } = self;
        run.finish(&mut |p| out.take(p));
        out
    }
}

impl BandedTime {
    /// The next segments of the plan, passed.
    fn take(&mut self, passed: &[Passed]) {
        for p in passed {
            self.time_s += p.t_s;
        }
        let speeds = |p: &Passed| [p.u0, p.u1, p.top.vp, p.top.used_mm];
        if let Built::Kept(k) = &self.built
            && k.len() + passed.len() > KEPT_SEGMENTS
        {
            self.built = Built::Speeds(k.iter().map(speeds).collect());
        }
        match &mut self.built {
            Built::Kept(k) => k.extend_from_slice(passed),
            Built::Speeds(v) => v.extend(passed.iter().map(speeds)),
        }
    }
}

/// Plan `this` built with its banded caps in one walk of the cells; with `also`, the
/// segments of that plan gathered in the same walk (`None` where they are more than
/// [`KEPT_SEGMENTS`]: to be walked again if needed).
fn banded_time(
    geo: &Geometry,
    machine: &Machine,
    tcy_s: f64,
    max_cells: usize,
    this: (usize, f64),
    also: Option<(usize, f64)>,
) -> (BandedTime, Option<Vec<Banded>>) {
    let mut timer = BandedTimer::new();
    let mut gathered = also.map(|_| Vec::new());
    let plans: Vec<(usize, f64)> = std::iter::once(this).chain(also).collect();
    walk_segments(
        geo,
        machine,
        tcy_s,
        max_cells,
        &plans,
        &|o: &Open| o.banded(machine),
        &mut |k, seg| {
            if k == 0 {
                timer.push(seg);
            } else if let Some(g) = &mut gathered {
                if g.len() < KEPT_SEGMENTS {
                    g.push(seg);
                } else {
                    gathered = None;
                }
            }
        },
    );
    (timer.finish(), gathered)
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
    parts: Parts,
    next_knot: usize,
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
            parts: Parts::new(parts),
            next_knot: 1,
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
                part: self.parts.part,
                cycle,
            },
            self.geo,
        );
    }

    /// The pieces of one segment from its start (speed `u0`, a = 0).
    fn segment(&mut self, seg: &impl Seg, u0: f64, pieces: &[Piece]) {
        let end = seg.s0_mm() + seg.len_mm();
        let (mut s, mut v, mut a) = (seg.s0_mm(), u0, 0.0);
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
            self.parts.passed(self.geo, k, vk.max(0.0), tk);
            self.next_knot += 1;
        }
    }

    fn finish(mut self) -> Planned {
        let end = self.geo.length();
        // The last state: the end at rest, after the last whole cycle.
        if self.every_cycle || self.last.1 < end || self.last.0 < self.t {
            let whole = self.every_cycle && ((self.t - self.last.0) / self.dt - 1.0).abs() < 1e-9;
            self.hand_out(self.t, end, 0.0, 0.0, 0.0, whole);
        }
        self.parts.finish(self.geo.part_end.len(), self.t);
        Planned {
            part_times: self.parts.times,
            min: self.parts.min,
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
            let lim = Limits {
                v: 40.0,
                a: 500.0,
                j: 5000.0,
            };
            let seg = Segment {
                s0_mm: 0.0,
                len_mm: len,
                lim,
                low: lim,
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

#[cfg(test)]
mod banded_tests {
    use super::*;

    /// `reach` inverts `change` over a wide range of speeds, lengths and caps: never past
    /// the length, and short of it by at most 10⁻⁶ of it.
    #[test]
    fn reach_inverts_the_change_over_a_wide_range() {
        for &v0 in &[0.0, 1e-3, 0.1, 3.0, 30.0, 500.0] {
            for &len in &[1e-6, 1e-3, 0.05, 1.0, 20.0, 3000.0] {
                for &(a, j) in &[
                    (1.0, 10.0),
                    (100.0, 300.0),
                    (1000.0, 5000.0),
                    (5.0, 1e5),
                    (5000.0, 50.0),
                ] {
                    let v1 = reach(v0, len, a, j);
                    let d = change(v0, v1, a, j).1;
                    let rel = (d - len) / len;
                    // A change too small for v0 + Δv to hold it exactly (Δv within 10⁻⁶ of
                    // v0: its last digits) is held to the rounding of v0 + Δv.
                    let (low, high) = if v1 - v0 > 1e-6 * v0 {
                        (-1e-6, 0.0)
                    } else {
                        (-1.0, 0.0)
                    };
                    assert!(
                        (low..=high).contains(&rel),
                        "v0 {v0} len {len} a {a} j {j}: v1 {v1} d {d}"
                    );
                }
            }
        }
    }

    /// Bands whose caps are not monotone in speed (a lower band's larger A leaves it less
    /// jerk), as `Peaks::caps_at` gives near the pole.
    fn bands() -> [Limits; 3] {
        [
            Limits {
                v: 2.0,
                a: 60.0,
                j: 800.0,
            },
            Limits {
                v: 5.0,
                a: 30.0,
                j: 2000.0,
            },
            Limits {
                v: 8.0,
                a: 10.0,
                j: 1500.0,
            },
        ]
    }

    /// A change under banded caps ends at its speed with a = 0, and every piece keeps
    /// the jerk of the band it runs in and the acceleration of the band of the change's
    /// top speed; a fall is the rise run backwards (same time and length).
    #[test]
    fn a_banded_change_keeps_each_bands_caps() {
        let b = bands();
        for &(v0, v1) in &[
            (0.0, 8.0),
            (0.5, 4.0),
            (1.0, 1.5),
            (3.0, 7.9),
            (8.0, 0.0),
            (6.0, 2.0),
        ] {
            let ps = change_pieces(v0, v1, &b);
            let hi = f64::max(v0, v1);
            let ap = b.iter().find(|x| hi <= x.v).map_or(0.0, |x| x.a);
            let (mut s, mut v, mut a) = (0.0, v0, 0.0);
            for p in ps.as_slice() {
                let (s1, v_end, a_end) = advance(s, v, a, p.j, p.t);
                // The band of the piece: the highest speed it reaches.
                let top = v.max(v_end);
                let band = b.iter().find(|x| top <= x.v * (1.0 + 1e-9)).unwrap();
                assert!(
                    p.j.abs() <= band.j * (1.0 + 1e-12),
                    "{v0}→{v1}: {p:?} in {band:?}"
                );
                assert!(a_end.abs() <= ap * (1.0 + 1e-9) && top <= hi * (1.0 + 1e-9));
                (s, v, a) = (s1, v_end, a_end);
            }
            assert!(
                (v - v1).abs() <= 1e-9 && a.abs() <= 1e-6,
                "{v0}→{v1}: v {v} a {a}"
            );
            let (t_up, d_up) = change_banded(v0, v1, &b);
            let (t_down, d_down) = change_banded(v1, v0, &b);
            assert!((t_up - t_down).abs() <= 1e-12 && (d_up - d_down).abs() <= 1e-9);
            assert!((d_up - s).abs() <= 1e-9);
        }
    }

    /// `reach_banded` finds the largest speed whose change fits, with bands that are not
    /// monotone: the change to it fits, a little more does not.
    #[test]
    fn the_banded_reach_fits_and_is_the_largest() {
        let b = bands();
        for &(v0, len) in &[
            (0.0, 0.01),
            (0.0, 0.5),
            (1.0, 0.2),
            (4.0, 1.0),
            (0.0, 100.0),
        ] {
            let v1 = reach_banded(v0, len, &b);
            assert!(
                change_banded(v0, v1, &b).1 <= len * (1.0 + 1e-12),
                "{v0} {len}: {v1}"
            );
            if v1 < 8.0 {
                let more = v1 + 1e-6 * (v1 - v0).max(1e-3);
                assert!(change_banded(v0, more, &b).1 > len, "{v0} {len}: {v1}");
            }
        }
    }

    /// A plan's time under each segment's largest banded caps is a lower bound of its
    /// banded time (what the choice among the plans relies on): on runs of segments with
    /// bands that are not monotone, scaled, of lengths from a fraction of a speed change
    /// to many. (The time under the caps at V is not an upper bound: a lower band's J may
    /// be below the top's.)
    #[test]
    fn the_largest_banded_caps_bound_the_banded_time_from_below() {
        let b = bands();
        let (mut strict, mut cases) = (0, 0);
        for scale in [0.5, 1.0, 3.0] {
            for lens in [
                vec![0.05, 0.2, 0.01, 1.0],
                vec![2.0; 6],
                vec![0.3, 0.002, 0.3, 5.0, 0.04],
            ] {
                let banded: Vec<Banded> = lens
                    .iter()
                    .enumerate()
                    .map(|(k, &len)| {
                        let f = scale * (1.0 + 0.3 * k as f64);
                        let sc = |x: Limits| Limits {
                            v: x.v * f,
                            a: x.a * f,
                            j: x.j * f,
                        };
                        // The bands ascending, the top repeated up to BAND_SHARES' count.
                        let mut bands = [sc(b[2]); BAND_SHARES.len()];
                        bands[0] = sc(b[0]);
                        bands[1] = sc(b[1]);
                        Banded {
                            s0_mm: 0.0,
                            len_mm: len,
                            bands,
                        }
                    })
                    .collect();
                let segs: Vec<Segment> = banded
                    .iter()
                    .map(|x| {
                        let lim = x.bands[x.bands.len() - 1];
                        let low = x.bands.iter().fold(lim, |l, y| Limits {
                            v: l.v,
                            a: l.a.max(y.a),
                            j: l.j.max(y.j),
                        });
                        Segment {
                            s0_mm: 0.0,
                            len_mm: x.len_mm,
                            lim,
                            low,
                        }
                    })
                    .collect();
                let mut lower = Timer::default();
                for seg in &segs {
                    lower.push(Segment {
                        lim: seg.low,
                        ..*seg
                    });
                }
                let lower = lower.finish();
                let mut t = BandedTimer::new();
                banded.into_iter().for_each(|seg| t.push(seg));
                let t = t.finish().time_s;
                assert!(lower <= t * (1.0 + 1e-9), "{lower} {t}");
                strict += usize::from(lower < t * (1.0 - 1e-3));
                cases += 1;
            }
        }
        // Not a bound that holds by being equal: below by more than 0.1 % in most cases.
        assert!(2 * strict > cases, "{strict} of {cases}");
    }

    /// The passes over the whole motion at once (module docs, step 2): the reference
    /// [`Lookahead`] must equal. Each segment's junction speeds (before, after).
    fn whole_motion<S: Seg>(segs: &[S]) -> Vec<(f64, f64)> {
        let n = segs.len();
        let mut u = vec![0.0; n + 1];
        for k in (0..n).rev() {
            let s = &segs[k];
            let cap = if k == 0 {
                0.0
            } else {
                top_speed(&segs[k - 1]).min(top_speed(s))
            };
            u[k] = cap.min(reach_banded(u[k + 1], s.len_mm(), s.bands()));
        }
        let mut u0 = 0.0;
        let mut out = Vec::with_capacity(n);
        for (k, s) in segs.iter().enumerate() {
            let u1 = u[k + 1].min(reach_banded(u0, s.len_mm(), s.bands()));
            out.push((u0, u1));
            u0 = u1;
        }
        out
    }

    /// Segments of a plan, pseudo-random but repeatable: lengths, speeds and caps over
    /// several orders of magnitude, with a long stretch of tiny caps under a high speed
    /// (where no junction's speed is known before the stretch ends) in the middle.
    fn plan_like(n: usize) -> Vec<Banded> {
        let mut x: u64 = 0x2545_f491_4f6c_dd1d;
        let mut r = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|k| {
                let slow = k > n / 3 && k < n / 3 + n / 5;
                let len = 10f64.powf(-2.0 + 3.0 * r());
                let v = if slow { 500.0 } else { 10f64.powf(3.0 * r()) };
                let (a, j) = if slow {
                    (1e-3 * (1.0 + r()), 1e-2 * (1.0 + r()))
                } else {
                    (10f64.powf(1.0 + 3.0 * r()), 10f64.powf(2.0 + 4.0 * r()))
                };
                // Caps that grow as the speed falls, as near the pole.
                let bands = std::array::from_fn(|b| {
                    let f = 1.0 + (1.0 - BAND_SHARES[b]) * 2.0 * r();
                    Limits {
                        v: v * BAND_SHARES[b],
                        a: a * f,
                        j: j * f,
                    }
                });
                Banded {
                    s0_mm: 0.0,
                    len_mm: len,
                    bands,
                }
            })
            .collect()
    }

    /// The look-ahead hands on exactly the junction speeds of the passes over the whole
    /// motion (to the last bit), holding a few checks' worth of segments where the speeds
    /// allow, for banded segments and for segments of one band. (A look-ahead that trusted
    /// the backward pass from rest as a lower bound failed here.)
    #[test]
    fn the_lookahead_equals_the_whole_motion_passes() {
        let banded = plan_like(40_000);
        let single: Vec<Segment> = banded
            .iter()
            .map(|b| Segment {
                s0_mm: 0.0,
                len_mm: b.len_mm,
                lim: b.bands[BAND_SHARES.len() - 1],
                low: b.bands[BAND_SHARES.len() - 1],
            })
            .collect();
        fn check<S: Seg + Copy>(segs: &[S]) {
            let reference = whole_motion(segs);
            let mut got = Vec::with_capacity(segs.len());
            let mut ahead = Lookahead::default();
            let (mut most, mut most_before_slow) = (0, 0);
            for (k, &seg) in segs.iter().enumerate() {
                ahead.push(seg, &mut |_, u0, u1| got.push((u0, u1)));
                most = most.max(ahead.segs.len());
                if k < segs.len() / 3 {
                    most_before_slow = most;
                }
            }
            // Before the stretch of tiny caps, a window of a few checks' length; in it,
            // the whole stretch held (no junction there is known before its end).
            assert!(
                most_before_slow <= 2 * LOOKAHEAD_MIN_SEGMENTS,
                "{most_before_slow}"
            );
            assert!(most >= segs.len() / 5, "{most}");
            ahead.finish(&mut |_, u0, u1| got.push((u0, u1)));
            assert_eq!(got.len(), reference.len());
            for (k, (g, r)) in got.iter().zip(&reference).enumerate() {
                assert!(
                    g.0.to_bits() == r.0.to_bits() && g.1.to_bits() == r.1.to_bits(),
                    "segment {k}: {g:?} against {r:?}"
                );
            }
            // Not a reference that agrees by being trivial: most junctions move.
            let moving = reference.iter().filter(|r| r.1 > 0.0).count();
            assert!(moving > segs.len() * 9 / 10, "{moving}");
        }
        check(&banded);
        check(&single);
    }

    /// The look-ahead's bound: from every speed at least `lo` the backward pass's reach
    /// over the segment is at least [`surely_reached`], in both regimes, for banded
    /// segments whose caps grow as the speed falls; and it is no trivial bound.
    #[test]
    fn the_surely_reached_speed_is_reached_from_every_speed_above_lo() {
        let segs = plan_like(3000);
        let mut above = 0;
        for (k, seg) in segs.iter().enumerate() {
            let top = top_speed(seg);
            let lo = top * [0.0, 0.01, 0.1, 0.3, 0.6][k % 5];
            let r = surely_reached(seg, lo);
            assert!(r >= lo, "{r} {lo}");
            above += usize::from(r > lo * (1.0 + 1e-6) + f64::MIN_POSITIVE);
            for i in 0..=100 {
                let x = lo + (r - lo) * i as f64 / 100.0;
                // The pass reaches at most the segment's top speed.
                let got = reach_banded(x, seg.len_mm, &seg.bands);
                assert!(
                    got >= r.min(top) * (1.0 - 1e-9),
                    "segment {k}: from {x} reached {got} < {r} (lo {lo})"
                );
            }
        }
        // All but the stretch of tiny caps (a fifth), where the bound stays near lo.
        assert!(above > segs.len() * 3 / 4, "{above}");
    }
}
