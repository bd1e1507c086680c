//! One pass of the jerk-limited integrator along the path (forward or backward).
//!
//! Cycle by cycle (step `dt` = Tcy), the pass takes the largest path jerk `j` that is
//! within the local caps ([`crate::caps`]) and keeps the next state *safe* under a ceiling
//! curve W(x) given at grid points (x is the distance along the pass). A state (x, v, a)
//! is safe when v ≤ W(x), |a| ≤ a_cap(v), j_cap(v, |a|) ≥ 0, and — when it accelerates
//! harder than the ceiling does (a > a_W) — the ramp of a down to a_W at the jerk cap
//! still ends under the ceiling:
//!
//! ```text
//! τ = (a − a_W)/j_cap,   x_e = x + v·τ + a·τ²/2 − j_cap·τ³/6,   v_e = v + a·τ − j_cap·τ²/2 ≤ W(x_e)
//! ```
//!
//! (a_W taken at x_e, found by two fixed-point steps). Safety is monotone in j, so the
//! largest safe j is found by bisection. This is the Ruckig/S-curve rule "start the
//! ramp-down when the ramp would just reach the target" applied to a moving target.
//! Where no jerk keeps the state under W (W falls faster than the limits allow, which
//! only the backward pass meets, on the limit curve), the state is put on W: a *clip*,
//! counted; the forward pass runs under the backward pass's profile, which it can follow.
//! A clip takes W's acceleration only as far as the caps at the new point allow, both
//! `a_cap(v)` and [`crate::caps::Caps::a_for_jerk`]: with a larger |a| no jerk is within
//! J (`j_cap < 0`, the 3·|q_ss|·v·|a| term), nothing could bring |a| back, and the pass
//! would brake under W until the speed made room. A state that is there anyway brings
//! |a| back at the jerk cap of a = 0.
//!
//! **Rewinds instead of clips** (optional, [`Pass::rewind`]: the forward pass, whose states
//! are the trajectory; issue 32). A clip jumps the speed and the acceleration within one
//! cycle: a finite difference of the trajectory sees a jerk many times the axes' (142× J
//! on one fixture). Where the forward pass finds itself above its ceiling at x_c, it
//! records a *dip* (x_c, W(x_c)) and goes back over the steps it has not handed out yet
//! ([`REWIND_STEPS`]; 1, 2, 4, … steps) to the latest state from which the hardest braking
//! passes every dip ahead at or under its speed, and goes on from there with that as one
//! more condition of *safe*:
//!
//! ```text
//! braking from (x, v, a): j = −j_b until a = −a_b, then a = −a_b held, in pieces of
//! max(4·Tcy, time to the next dip / 8) with the caps where each piece starts
//! (a_b = min(a_cap(v), 0.8·a_for_jerk(v)), j_b = j_cap(v, a_b)); where v ≤ a²/(2·j_b)
//! it lands (a back to 0 as v reaches 0): v(x_d) ≤ v_d at every dip d ahead.
//! ```
//!
//! A motion found above the ceiling at the same dip again lowers its speed by 3 % (at
//! most 40 times), since the braking is computed coarser than the motion. Work is
//! bounded: a pass undoes at most a quarter of its steps plus 100 000
//! ([`REWIND_BUDGET_STEPS`]); past that, and where no kept state can brake in time, it
//! clips as before (counted). A forward state up to 0.2 % above the backward profile
//! but under the velocity limit itself stands: it turns towards the profile's
//! acceleration from the next cycle, within the caps. And a decelerating motion keeps
//! v ≥ a²/(2·j_cap) (it can still bring a to 0 before it stops: the smallest jerk that
//! keeps it, when the chosen one does not). Why this is not the default:
//! `docs/simulation.md`, "Jerk at every cycle".
//!
//! In both modes the last nanometres to the end ([`END_MM`]) are taken after the last
//! cycle — at the speed there, or from rest in the rest-to-rest time at the jerk cap —
//! not jumped within it.

use std::collections::VecDeque;

use polepatch_kinematics::Machine;

use crate::caps::{Caps, Local};
use crate::grid::{Cursor, Geometry, count_at_most};
use crate::tolerances::{
    A_CAP_SLACK_MM_S2, A_CAP_SLACK_REL, BRAKE_A_SHARE, BRAKE_PIECE_CYCLES, BRAKE_PIECES_MAX,
    BRAKE_PIECES_TO_GO, BRAKE_SPEED_FLOOR_MM_S, CBRT_GUESS_BIAS, CBRT_HALLEY_STEPS, CEILING_REL,
    CEILING_REL_P, CRAWL_CRUISE_REL, CRAWL_JERK_SHARE, CRAWL_UNDER_LIMIT_REL, CRUISE_ABS_MM_S,
    CRUISE_REL, CYCLE_MATCH_REL, DIP_NEAR_CYCLES, DIP_NEAR_MM, DIP_TIGHTEN, DIP_TRIES, DIPS_MAX,
    END_MM, JERK_BISECTIONS, OVER_PROFILE_REL, RAMP_JERK_FLOOR_MM_S3, RAMP_STEPS, RAMP_STEPS_MAX,
    REWIND_BUDGET_PER_STEP_INV, REWIND_BUDGET_STEPS, REWIND_STEPS, SETTLE_REL, STALL_STEPS,
    TIME_BISECTIONS,
};

/// A ceiling along a pass: values at increasing pass positions, and between them W^(3/2)
/// linear, or (given the acceleration of the profile it was recorded from) cubic Hermite;
/// with the acceleration of a motion that follows it, a = W·dW/dx.
pub(crate) struct Ceiling<'a> {
    pub x: &'a [f64],
    pub v: &'a [f64],
    /// P = W^(3/2) at the points.
    p: Vec<f64>,
    /// dP/dx = 1.5·a/√v at the points (NaN at rest), when the profile's acceleration is
    /// given.
    m: Option<Vec<f64>>,
    /// Per cell, what its interpolant needs whatever the position in it, computed once
    /// as [`Ceiling::at_p`] used to compute it at every call (the same values): 1/h and
    /// the two end slopes × h (Hermite), or P₁ − P₀ and its slope (linear).
    cells: Vec<[f64; 3]>,
}

impl<'a> Ceiling<'a> {
    /// A ceiling through `v` at `x`; with `a`, the acceleration of the profile there.
    pub fn new(x: &'a [f64], v: &'a [f64], a: Option<&[f64]>) -> Ceiling<'a> {
        let mut c = Ceiling {
            x,
            v,
            cells: Vec::new(),
            p: v.iter().map(|&w| p_of(w)).collect(),
            m: a.map(|a| {
                v.iter()
                    .zip(a)
                    .map(|(&w, &acc)| {
                        if w > 0.0 {
                            1.5 * acc / w.sqrt()
                        } else {
                            f64::NAN
                        }
                    })
                    .collect()
            }),
        };
        c.cells = (0..x.len().saturating_sub(1))
            .map(|i| c.cell_data(i))
            .collect();
        c
    }

    /// The entry of `cells` for cell `i`.
    fn cell_data(&self, i: usize) -> [f64; 3] {
        let (x0, x1) = (self.x[i], self.x[i + 1]);
        let h = x1 - x0;
        let inv_h = 1.0 / h;
        let (p0, p1) = (self.p[i], self.p[i + 1]);
        match &self.m {
            Some(m) => {
                let secant = (p1 - p0) * inv_h;
                let pick = |a: f64, b: f64| {
                    if !a.is_nan() {
                        a
                    } else if !b.is_nan() {
                        b
                    } else {
                        secant
                    }
                };
                let m0 = pick(m[i], m[i + 1]) * h;
                let m1 = pick(m[i + 1], m[i]) * h;
                [inv_h, m0, m1]
            }
            None => linear_cell(inv_h, p0, p1),
        }
    }

    /// Cell index of `x` ([`cell_of`]).
    #[inline]
    fn cell(&self, x: f64, hint: usize) -> usize {
        cell_of(self.x, x, hint)
    }

    /// (W, a_W) at `x`, and the cell.
    fn at(&self, x: f64, hint: usize) -> (f64, f64, usize) {
        let (p, dp, i) = self.at_p(x, hint);
        let c = cbrt(p);
        let w = c * c;
        // a = W·dW/dx = √W·(dP/dx)/1.5.
        let aw = c * dp / 1.5;
        (w, aw, i)
    }

    /// (P = W^(3/2), dP/dx) at `x`, and the cell: what [`Ceiling::at`] is computed from,
    /// for the comparisons that need no cube root (`above_ceiling`, `accel_within`).
    #[inline(always)]
    fn at_p(&self, x: f64, hint: usize) -> (f64, f64, usize) {
        let i = self.cell(x, hint);
        if self.x.len() < 2 {
            return (self.p[0], 0.0, 0);
        }
        let [inv_h, m0, m1] = self.cells[i];
        let (x0, p0, p1) = (self.x[i], self.p[i], self.p[i + 1]);
        let u = ((x - x0) * inv_h).clamp(0.0, 1.0);
        let (p, dp) = if self.m.is_some() {
            // P as the cubic Hermite interpolant of the values and slopes of the profile
            // the ceiling was recorded from (C¹: a motion can follow it with a continuous
            // acceleration). At rest the slope is the other end's: P is linear in the jerk
            // phase from rest (x = J·t³/6, P = (J/2)^(3/2)·t³).
            let (u2, u3) = (u * u, u * u * u);
            let p = (2.0 * u3 - 3.0 * u2 + 1.0) * p0
                + (u3 - 2.0 * u2 + u) * m0
                + (-2.0 * u3 + 3.0 * u2) * p1
                + (u3 - u2) * m1;
            let dp = ((6.0 * u2 - 6.0 * u) * p0
                + (3.0 * u2 - 4.0 * u + 1.0) * m0
                + (-6.0 * u2 + 6.0 * u) * p1
                + (3.0 * u2 - 2.0 * u) * m1)
                * inv_h;
            (p.max(0.0), dp)
        } else {
            linear_at(u, p0, m0, m1)
        };
        (p, dp, i)
    }
}

/// Cell index of `x` among the increasing `xs`: `i` with `xs[i] ≤ x < xs[i+1]`, clamped
/// to the cells; the cell `hint` and the one after it first.
#[inline]
fn cell_of(xs: &[f64], x: f64, hint: usize) -> usize {
    let n = xs.len();
    let last = n.saturating_sub(2);
    let h = hint.min(last);
    if xs[h] <= x && (h + 1 >= n || x < xs[h + 1]) {
        return h;
    }
    if h + 2 < n && xs[h + 1] <= x && x < xs[h + 2] {
        return h + 1;
    }
    count_at_most(xs, x, h).saturating_sub(1).min(last)
}

/// What a cell of a ceiling with P linear needs whatever the position in it: 1/h, P₁ − P₀
/// and its slope (the entry of [`Ceiling::cells`]).
#[inline]
fn linear_cell(inv_h: f64, p0: f64, p1: f64) -> [f64; 3] {
    [inv_h, p1 - p0, (p1 - p0) * inv_h]
}

/// (P, dP/dx) at `u` (0 to 1) of a cell with P linear: exact for the jerk phase from rest,
/// between the two values elsewhere (m0, m1: P₁ − P₀ and its slope, [`linear_cell`]).
#[inline(always)]
fn linear_at(u: f64, p0: f64, m0: f64, m1: f64) -> (f64, f64) {
    (p0 + u * m0, m1)
}

/// W^(3/2), the ceilings' P.
#[inline]
fn p_of(w: f64) -> f64 {
    w * w.sqrt()
}

/// The velocity limit curve as the forward pass consults it beside its ceiling (where it
/// crawls, or lets a state stand over the profile: a few cycles, not the pass's hot path).
/// The values of [`Ceiling::new`] without an acceleration, computed where they are asked
/// for instead of for every cell up front: 32 bytes a grid point fewer held through the
/// forward pass.
pub(crate) struct Limit<'a> {
    /// Grid points, mm.
    pub x: &'a [f64],
    /// W at the grid points, mm/s.
    pub v: &'a [f64],
}

impl Limit<'_> {
    /// W at `x` (what `Ceiling::new(x, v, None).at(x, 0).0` is, to the bit).
    pub fn w_at(&self, x: f64) -> f64 {
        let i = cell_of(self.x, x, 0);
        let p = if self.x.len() < 2 {
            p_of(self.v[0])
        } else {
            let (x0, x1) = (self.x[i], self.x[i + 1]);
            let inv_h = 1.0 / (x1 - x0);
            let (p0, p1) = (p_of(self.v[i]), p_of(self.v[i + 1]));
            let [inv_h, m0, m1] = linear_cell(inv_h, p0, p1);
            let u = ((x - x0) * inv_h).clamp(0.0, 1.0);
            linear_at(u, p0, m0, m1).0
        };
        let c = cbrt(p);
        c * c
    }
}

/// Whether a speed `v` is above the ceiling W = P^(2/3) by more than [`CEILING_REL`]:
/// `v > W·(1 + CEILING_REL)` ⟺ `v^(3/2) > P·(1 + CEILING_REL)^(3/2)` (both sides
/// non-negative, x ↦ x^(3/2) increasing).
fn above_ceiling(v: f64, p: f64) -> bool {
    v > 0.0 && v * v.sqrt() > p * CEILING_REL_P
}

/// Whether an acceleration `a` is at most the ceiling's a_W = √W·(dP/dx)/1.5 = ∛P·r with
/// r = (dP/dx)/1.5: `a ≤ ∛P·r` ⟺ `a³ ≤ P·r³` (x ↦ x³ increasing on all of ℝ).
fn accel_within(a: f64, p: f64, dp: f64) -> bool {
    let r = dp / 1.5;
    a * a * a <= p * (r * r * r)
}

/// The boundary of `pred` between `good` (where it holds) and `bad` (where it does not),
/// [`JERK_BISECTIONS`] halvings: the last point found to hold, from `good`'s side.
fn bisect(mut good: f64, mut bad: f64, pred: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..JERK_BISECTIONS {
        let mid = 0.5 * (good + bad);
        if pred(mid) {
            good = mid;
        } else {
            bad = mid;
        }
    }
    good
}

/// Cube root of a non-negative `p` (the library's is a slow software routine on this
/// target): exponent-halving first guess, then three Halley steps (cubic convergence: far
/// below rounding after the third).
pub(crate) fn cbrt(p: f64) -> f64 {
    if p <= 0.0 || !p.is_finite() {
        return p.max(0.0);
    }
    let mut y = f64::from_bits(p.to_bits() / 3 + CBRT_GUESS_BIAS);
    for _ in 0..CBRT_HALLEY_STEPS {
        let y3 = y * y * y;
        y *= (y3 + 2.0 * p) / (2.0 * y3 + p);
    }
    y
}

/// The state of the motion along a pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct State {
    /// Time, s.
    pub t: f64,
    /// Distance along the pass, mm.
    pub x: f64,
    /// Speed, mm/s.
    pub v: f64,
    /// Acceleration along the pass, mm/s².
    pub a: f64,
}

impl State {
    /// (x, v, a) after `dt` (s) under jerk `j` (mm/s³).
    #[inline]
    fn after(&self, dt: f64, j: f64) -> (f64, f64, f64) {
        let x1 = self.x + self.v * dt + 0.5 * self.a * dt * dt + j * dt * dt * dt / 6.0;
        let v1 = self.v + self.a * dt + 0.5 * j * dt * dt;
        let a1 = self.a + j * dt;
        (x1, v1, a1)
    }
}

/// What a pass hands out.
pub(crate) trait Sink {
    /// One step from `from` to `to` under jerk `j` (mm/s³); `cycle` is false for a step
    /// that jumped a cruise.
    fn step(&mut self, from: &State, to: &State, j: f64, cycle: bool);
}

/// Outcome of a pass.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct PassStats {
    /// Cycles where the state had to be put on the ceiling.
    pub clips: usize,
    /// Steps taken.
    pub steps: u64,
    /// Time at the end, s.
    pub time_s: f64,
}

/// One pass.
pub(crate) struct Pass<'a> {
    pub geo: &'a Geometry,
    pub machine: &'a Machine,
    pub ceiling: Ceiling<'a>,
    /// The velocity limit curve, when the ceiling is another profile: a crawl (below)
    /// may use it where the profile stopped.
    pub limit: Option<Limit<'a>>,
    /// Forward (x = s) or backward (x = L − s).
    pub forward: bool,
    /// Cycle time, s.
    pub dt: f64,
    /// Fractions of the acceleration and jerk caps this pass plans with (≤ 1).
    pub use_caps: [f64; 2],
    /// Every step is one cycle (no cruise jumps): for a trajectory at Tcy.
    pub every_cycle: bool,
    /// Instead of a clip, go back to where braking still reaches the ceiling there and
    /// take that motion ([`Dip`]); a clip only when that fails.
    pub rewind: bool,
}

/// Where a pass found itself above its ceiling: the speed `v` it must pass `x` at or
/// under. After a rewind every state must be able to brake down to it in time
/// ([`Pass::clears_dips`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Dip {
    x: f64,
    v: f64,
    tries: u32,
}

/// A step taken and not yet handed out: what a rewind needs to start again from it.
struct Pending {
    from: State,
    to: State,
    j: f64,
    cycle: bool,
    hint: usize,
    cursor: Cursor,
    clipped: bool,
}

impl Pass<'_> {
    fn s_of(&self, x: f64, len: f64) -> f64 {
        if self.forward { x } else { len - x }
    }

    #[inline]
    fn caps(&self, caps: &Caps, v: f64, a_abs: f64) -> (f64, f64) {
        let ac = caps.a_cap(v) * self.use_caps[0];
        let jc = caps.j_cap(v, a_abs) * self.use_caps[1];
        (ac, jc)
    }

    /// Whether (x1, v1, a1) is safe (module docs); `vmax` is the feed and the axes' V
    /// here.
    #[allow(clippy::too_many_arguments)]
    fn safe(
        &self,
        caps: &Caps,
        vmax: f64,
        x1: f64,
        v1: f64,
        a1: f64,
        hint: usize,
        len: f64,
        dips: &[Dip],
    ) -> bool {
        // Under the ceiling (below), and then, with dips ahead, able to brake to them.
        let dips_ok = || dips.is_empty() || self.clears_dips(x1, v1, a1, dips, len);
        if v1 > vmax {
            return false;
        }
        let (ac, jc) = self.caps(caps, v1.max(0.0), a1.abs());
        if a1.abs() > ac.max(0.0) * (1.0 + A_CAP_SLACK_REL) + A_CAP_SLACK_MM_S2 || jc < 0.0 {
            return false;
        }
        // The comparisons with W and a_W in P = W^(3/2) (no cube root: see
        // `above_ceiling` and `accel_within`).
        let (p, dp, i) = self.ceiling.at_p(x1, hint);
        if above_ceiling(v1, p) {
            return false;
        }
        if accel_within(a1, p, dp) {
            return dips_ok();
        }
        // The ramp of a down at the jerk cap, in RAMP_STEPS pieces, until it meets the
        // ceiling's acceleration: under the ceiling all the way.
        let aw = cbrt(p) * dp / 1.5;
        let jb = jc.max(RAMP_JERK_FLOOR_MM_S3);
        let dtau = (a1 - aw) / jb / RAMP_STEPS as f64;
        let (mut x, mut v, mut a, mut c) = (x1, v1, a1, i);
        for _ in 0..RAMP_STEPS_MAX {
            x += v * dtau + 0.5 * a * dtau * dtau - jb * dtau * dtau * dtau / 6.0;
            v += a * dtau - 0.5 * jb * dtau * dtau;
            a -= jb * dtau;
            if v <= 0.0 || x >= len {
                return (v <= 0.0 || !above_ceiling(v, self.ceiling.at_p(len, c).0)) && dips_ok();
            }
            let (p, dp, k) = self.ceiling.at_p(x, c);
            c = k;
            if above_ceiling(v, p) {
                return false;
            }
            if accel_within(a, p, dp) {
                return dips_ok();
            }
        }
        dips_ok()
    }

    /// The hardest braking from (x0, v0, a0) — a down at the jerk cap to the largest
    /// deceleration the caps allow along it, then held — passes every dip ahead at or
    /// under its speed. The caps are taken where each piece of the braking starts.
    fn clears_dips(&self, x0: f64, v0: f64, a0: f64, dips: &[Dip], len: f64) -> bool {
        let mut v_min = f64::INFINITY;
        let mut x_last = x0;
        for d in dips.iter().filter(|d| d.x > x0) {
            v_min = v_min.min(d.v);
            x_last = x_last.max(d.x);
        }
        if x_last <= x0 || (v0 <= v_min && a0 <= 0.0) {
            return true;
        }
        let mut cur = Cursor::default();
        let (mut x, mut v, mut a) = (x0, v0, a0);
        for _ in 0..BRAKE_PIECES_MAX {
            // Pieces of BRAKE_PIECES_TO_GO of the time to the last dip at this speed, at
            // least BRAKE_PIECE_CYCLES cycles.
            let x_next = dips
                .iter()
                .filter(|d| d.x > x)
                .fold(x_last, |m, d| m.min(d.x));
            let h = (BRAKE_PIECE_CYCLES * self.dt)
                .max((x_next - x) / (v.max(BRAKE_SPEED_FLOOR_MM_S) * BRAKE_PIECES_TO_GO));
            let (d, _) = self
                .geo
                .derivs_feed_near(self.s_of(x.min(len), len), &mut cur);
            let caps = Caps::new(&Local::from_derivs(&d), self.machine);
            let ab = (caps.a_cap(v) * self.use_caps[0])
                .min(BRAKE_A_SHARE * caps.a_for_jerk(v))
                .max(0.0);
            let jb = (caps.j_cap(v, a.abs().min(ab)) * self.use_caps[1]).max(0.0);
            if a < 0.0 && jb > 0.0 && v <= a * a / (2.0 * jb) {
                // Landing: a back to 0 at the jerk cap, v falling all the way; every dip
                // it reaches is passed at most at v.
                // v reaches 0 at the first root of v + a·τ + jb·τ²/2 (it has one here).
                let disc = (a * a - 2.0 * jb * v).max(0.0);
                let tau = ((-a - disc.sqrt()) / jb).max(0.0);
                let x_stop = x + v * tau + 0.5 * a * tau * tau + jb * tau * tau * tau / 6.0;
                return dips
                    .iter()
                    .all(|d| d.x <= x || d.x > x_stop.max(x) || v <= d.v * (1.0 + CEILING_REL));
            }
            // Towards −ab at the jerk cap for up to `h`, then held for the rest of `h`.
            let target = -ab;
            let j = if jb <= 0.0 {
                0.0
            } else {
                (target - a).signum() * jb
            };
            let t_ramp = if j == 0.0 {
                0.0
            } else {
                ((target - a) / j).clamp(0.0, h)
            };
            let xr = x + v * t_ramp + 0.5 * a * t_ramp * t_ramp + j * t_ramp.powi(3) / 6.0;
            let vr = v + a * t_ramp + 0.5 * j * t_ramp * t_ramp;
            let ar = a + j * t_ramp;
            let th = h - t_ramp;
            let x1 = xr + vr * th + 0.5 * ar * th * th;
            let v1 = vr + ar * th;
            let a1 = ar;
            if v1 <= 0.0 {
                // At rest within the piece, before x1 (if the speed rose first, not
                // above the larger of v and vr on the way).
                let v_up = v.max(vr);
                return dips
                    .iter()
                    .all(|d| d.x <= x || d.x > x1.max(xr) || v_up <= d.v * (1.0 + CEILING_REL));
            }
            for dp in dips.iter().filter(|d| d.x > x && d.x <= x1) {
                let u = (dp.x - x) / (x1 - x);
                if v + u * (v1 - v) > dp.v * (1.0 + CEILING_REL) {
                    return false;
                }
            }
            (x, v, a) = (x1, v1, a1);
            if x >= x_last || (a <= 0.0 && dips.iter().all(|d| d.x <= x || v <= d.v)) {
                return true;
            }
        }
        false
    }

    /// Run the pass from rest at x = 0 to x = L; `sink` gets every step. One
    /// [`Stepper::cycle`] after another until the end; `Err(s)` where the pass made no
    /// progress for [`STALL_STEPS`] steps (s, mm, on the path).
    pub fn run(&self, sink: &mut dyn Sink) -> Result<PassStats, f64> {
        let mut stepper = Stepper::new(self, sink);
        while stepper.st.x < stepper.len - END_MM {
            stepper.cycle()?;
        }
        Ok(stepper.finish())
    }
}

/// The state one cycle on, as the steps of [`Stepper::cycle`] make it.
#[derive(Debug, Clone, Copy)]
struct Next {
    /// Time, s.
    t: f64,
    /// Distance along the pass, mm.
    x: f64,
    /// Speed, mm/s.
    v: f64,
    /// Acceleration along the pass, mm/s².
    a: f64,
    /// Put on a ceiling (a clip, or a crawl that moves): counted in [`PassStats::clips`].
    clipped: bool,
}

/// What one cycle of a pass did ([`Stepper::cycle`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cycle {
    /// Jumped a cruise on a flat stretch of the ceiling to its next grid point.
    Cruised,
    /// One cycle (or the last, partial one): under the ceiling, on it (a clip), or at a
    /// crawl.
    Stepped,
    /// Went back to a kept state from which braking passes a dip ahead; the steps after
    /// it undone.
    Rewound,
}

/// Where a cycle starts: the limits at the state, and the ceiling there.
struct Here {
    /// The caps of the path at the state.
    caps: Caps,
    /// The feed and the axes' velocity limit at the state, mm/s.
    vmax: f64,
    /// The ceiling W at the state, mm/s.
    w: f64,
    /// The ceiling's acceleration a_W there, mm/s².
    aw: f64,
    /// The ceiling's cell of the state.
    cell: usize,
    /// The acceleration cap at the state's speed (this pass's share), mm/s²; negative
    /// where no acceleration is within the limits.
    ac: f64,
    /// The jerk cap at the state's speed and |acceleration| (this pass's share), mm/s³;
    /// negative where no jerk is within the limits.
    jc: f64,
    /// The first of the dips ahead of the state (index in [`Stepper::dips`]).
    ahead_from: usize,
}

/// A pass under way: its state, the steps taken and not handed out yet (what a rewind
/// can go back over), the dips and the counts. [`Stepper::cycle`] takes one cycle.
struct Stepper<'p, 's> {
    pass: &'p Pass<'p>,
    sink: &'s mut dyn Sink,
    /// Length of the pass, mm.
    len: f64,
    /// The state the next cycle starts from.
    st: State,
    stats: PassStats,
    /// The ceiling's cell of the state (where its searches start).
    hint: usize,
    /// Steps without progress in a row.
    idle: u32,
    /// Where the path was last evaluated.
    cursor: Cursor,
    /// The ceiling at the end of the last cycle (x, (W, a_W, cell)): where this one
    /// starts.
    at_end: Option<(f64, (f64, f64, usize))>,
    /// Steps taken and not handed out: kept [`REWIND_STEPS`] deep when the pass rewinds.
    buf: VecDeque<Pending>,
    /// Where the pass found itself above its ceiling, sorted by x.
    dips: Vec<Dip>,
    /// Steps undone by rewinds: past a budget, clips again.
    undone: u64,
}

impl<'p, 's> Stepper<'p, 's> {
    /// At rest at x = 0.
    fn new(pass: &'p Pass<'p>, sink: &'s mut dyn Sink) -> Stepper<'p, 's> {
        Stepper {
            pass,
            sink,
            len: pass.geo.length(),
            st: State {
                t: 0.0,
                x: 0.0,
                v: 0.0,
                a: 0.0,
            },
            stats: PassStats::default(),
            hint: 0,
            idle: 0,
            cursor: Cursor::default(),
            at_end: None,
            buf: VecDeque::new(),
            dips: Vec::new(),
            undone: 0,
        }
    }

    /// One cycle, in its steps: the limits here; a cruise when one may be jumped; else
    /// the jerk, the state a cycle on (a stop within it, a crawl, the end of the path),
    /// that state against the ceiling (it stands, a rewind, or a clip), and the step
    /// kept. `Err(s)`: no progress for [`STALL_STEPS`] steps.
    fn cycle(&mut self) -> Result<Cycle, f64> {
        let (hint0, cursor0) = (self.hint, self.cursor);
        self.forget_passed_dips();
        let here = self.here();
        if let Some(to) = self.cruise(&here) {
            self.take(Pending {
                from: self.st,
                to,
                j: 0.0,
                cycle: false,
                hint: hint0,
                cursor: cursor0,
                clipped: false,
            });
            return Ok(Cycle::Cruised);
        }
        let j = self.jerk(&here);
        let mut next = self.reach(j);
        let crawl = self.crawl_if_stuck(&here, &mut next);
        self.end_of_path(&here, j, &mut next);
        let end = self.pass.ceiling.at(next.x, self.hint);
        self.at_end = Some((next.x, end));
        let (w1, aw1, _) = end;
        let w1 = w1.min(here.vmax);
        let over_ok = self.stands_over_profile(&here, &next, w1);
        if !over_ok && self.rewind(&next, w1) {
            return Ok(Cycle::Rewound);
        }
        if !(over_ok || (crawl && next.v > 0.0)) && next.v > w1 * (1.0 + CEILING_REL) {
            self.clip(&mut next, w1, aw1);
        }
        self.count_idle(next.x)?;
        let dt = self.pass.dt;
        let p = Pending {
            from: self.st,
            to: State {
                t: next.t,
                x: next.x,
                v: next.v,
                a: next.a,
            },
            j,
            cycle: (next.t - self.st.t - dt).abs() <= CYCLE_MATCH_REL * dt,
            hint: hint0,
            cursor: cursor0,
            clipped: next.clipped,
        };
        self.take(p);
        Ok(Cycle::Stepped)
    }

    /// Dips no rewind can reach any more (behind the oldest kept step) are done with.
    fn forget_passed_dips(&mut self) {
        if !self.dips.is_empty() {
            let oldest = self.buf.front().map_or(self.st.x, |p| p.from.x);
            let n = self.dips.partition_point(|d| d.x < oldest);
            self.dips.drain(..n);
        }
    }

    /// The limits at the state and the ceiling there (the end of the last cycle's, when
    /// it ended here).
    fn here(&mut self) -> Here {
        let pass = self.pass;
        let st = self.st;
        // Dips (sorted by x) ahead of this state: the only ones a check looks at.
        let ahead_from = self.dips.partition_point(|d| d.x <= st.x);
        let (d, feed) = pass
            .geo
            .derivs_feed_near(pass.s_of(st.x, self.len), &mut self.cursor);
        let loc = Local::from_derivs(&d);
        let vmax = loc.v_cap(pass.machine).min(feed);
        let caps = Caps::new(&loc, pass.machine);
        let (w, aw, cell) = match self.at_end {
            Some((x, c)) if x == st.x => c,
            _ => pass.ceiling.at(st.x, self.hint),
        };
        self.hint = cell;
        let (ac, jc) = pass.caps(&caps, st.v, st.a.abs());
        Here {
            caps,
            vmax,
            w,
            aw,
            cell,
            ac,
            jc,
            ahead_from,
        }
    }

    /// The dips ahead of the state where the cycle started.
    fn ahead(&self, here: &Here) -> &[Dip] {
        &self.dips[here.ahead_from..]
    }

    /// A cruise on a flat stretch of the ceiling: the state at the next grid point, when
    /// it is safe there (then it is everywhere before it). Within [`CRUISE_REL`] of the
    /// ceiling, or of one cycle at the jerk cap where the ceiling is below that (the crawl
    /// regime, where a cycle's jerk is coarser than the speed).
    fn cruise(&self, here: &Here) -> Option<State> {
        let pass = self.pass;
        let (st, len, i, w) = (self.st, self.len, here.cell, here.w);
        let one_cycle = here.jc.max(0.0) * pass.dt * pass.dt;
        let near = (CRUISE_REL * w)
            .max(CRAWL_CRUISE_REL * w.min(one_cycle))
            .max(CRUISE_ABS_MM_S);
        let cruising =
            !pass.every_cycle && st.a.abs() * pass.dt <= near && st.v > 0.0 && st.v >= w - near;
        if !cruising {
            return None;
        }
        let nx = (i + 1).min(pass.ceiling.x.len() - 1);
        let xn = pass.ceiling.x[nx].min(len);
        let flat = xn > st.x
            && pass.ceiling.v[i] == pass.ceiling.v[nx]
            && pass
                .ceiling
                .m
                .as_ref()
                .is_none_or(|m| m[i] == 0.0 && m[nx] == 0.0)
            && pass.safe(
                &here.caps,
                here.vmax,
                xn,
                st.v,
                0.0,
                i,
                len,
                self.ahead(here),
            );
        if !flat {
            return None;
        }
        // The forward pass jumps whole cycles (to within one cycle of the grid point; the
        // rest is an ordinary cycle), so that its states stay on the cycle grid and a
        // trajectory is the same states with each jump cut into its cycles: one answer
        // with or without a trajectory (issue 43). The end of the path keeps its last,
        // partial cycle.
        let to = if xn >= len - END_MM {
            State {
                t: st.t + (len - st.x) / st.v,
                x: len,
                v: st.v,
                a: 0.0,
            }
        } else if pass.forward {
            // Cycle by cycle as an ordinary cycle at j = 0 computes them (x + v·dt,
            // t + dt: the same bits), up to the grid point; a state that still
            // accelerates a little settles first (an ordinary cycle).
            let mut to = st;
            if st.a == 0.0 {
                let step = st.v * pass.dt;
                while to.x + step < xn {
                    to.x += step;
                    to.t += pass.dt;
                }
            }
            to
        } else {
            State {
                t: st.t + (xn - st.x) / st.v,
                x: xn,
                v: st.v,
                a: 0.0,
            }
        };
        (to.x > st.x).then_some(to)
    }

    /// The range of jerks of this cycle within the caps: [lo, hi], mm/s³; where |a| is
    /// above its cap at this speed, the one jerk that brings it back as fast as allowed —
    /// and where |a| leaves no jerk at all (j_cap < 0: no jerk keeps the axes within J),
    /// at the jerk cap of a = 0 (a |a| held there would brake the motion to a standstill).
    fn jerk_range(&self, here: &Here) -> (f64, f64) {
        let (st, dt) = (self.st, self.pass.dt);
        let jm = here.jc.max(0.0);
        let ac = here.ac.max(0.0);
        let lo = (-jm).max((-ac - st.a) / dt);
        let hi = jm.min((ac - st.a) / dt);
        if lo > hi || (here.jc < 0.0 && st.a != 0.0) {
            let jr = if here.jc < 0.0 {
                (self.pass.caps(&here.caps, st.v, 0.0).1).max(0.0)
            } else {
                jm
            };
            let j = -st.a.signum() * jr;
            return (j, j);
        }
        (lo, hi)
    }

    /// The jerk of this cycle: the largest safe one (bisection); on a flat ceiling just
    /// under it the one that settles (a → 0: the largest would overshoot and chatter about
    /// the ceiling); where none is safe, the hardest braking (or, above the profile
    /// already when rewinding, towards its acceleration). Then, when rewinding, a motion
    /// that decelerates keeps v ≥ a²/(2·j_cap) ([`Stepper::landing_jerk`]).
    fn jerk(&self, here: &Here) -> f64 {
        let pass = self.pass;
        let (st, dt) = (self.st, pass.dt);
        let (lo, hi) = self.jerk_range(here);
        let ahead = self.ahead(here);
        let ok = |j: f64| {
            let (x1, v1, a1) = st.after(dt, j);
            pass.safe(
                &here.caps, here.vmax, x1, v1, a1, self.hint, self.len, ahead,
            )
        };
        let (w0, aw0) = (here.w, here.aw);
        let jz = (-st.a / dt).clamp(lo, hi);
        let settle = aw0 == 0.0 && w0 - st.v <= SETTLE_REL * w0;
        let j = if ok(hi) {
            hi
        } else if settle && ok(jz) {
            jz
        } else if !ok(lo) {
            if pass.rewind && st.v > w0 {
                // Above the profile already (a state let stand): towards its
                // acceleration, not the hardest braking, which would leave it with more
                // deceleration than it can bring back to 0 before it stops.
                ((aw0 - st.a) / dt).clamp(lo, hi)
            } else {
                lo
            }
        } else {
            bisect(lo, hi, ok)
        };
        self.landing_jerk(here, j, hi)
    }

    /// A motion that decelerates must be able to bring a to 0 before it stops
    /// (v ≥ a²/(2·j_cap)): the smallest jerk from `j` towards `hi` that keeps this, when
    /// `j` does not (then the ceiling may be left: a rewind or a clip follows). Only when
    /// the pass rewinds; else `j`.
    fn landing_jerk(&self, here: &Here, j: f64, hi: f64) -> f64 {
        let pass = self.pass;
        let (st, dt) = (self.st, pass.dt);
        let lands = |j: f64| {
            let (_, v1, a1) = st.after(dt, j);
            a1 >= 0.0 || {
                let jf = pass.caps(&here.caps, v1.max(0.0), a1.abs()).1;
                jf > 0.0 && v1 >= a1 * a1 / (2.0 * jf)
            }
        };
        if !pass.rewind || lands(j) || !lands(hi) || st.v <= 0.0 {
            j
        } else {
            bisect(hi, j, lands)
        }
    }

    /// The state one cycle on under jerk `j`; stopped within the cycle (only near a
    /// standstill): at rest where v = 0.
    fn reach(&self, j: f64) -> Next {
        let (st, dt) = (self.st, self.pass.dt);
        let (mut x1, mut v1, mut a1) = st.after(dt, j);
        if v1 < 0.0 {
            let (mut lo_t, mut hi_t) = (0.0, dt);
            for _ in 0..TIME_BISECTIONS {
                let tm = 0.5 * (lo_t + hi_t);
                if st.v + st.a * tm + 0.5 * j * tm * tm > 0.0 {
                    lo_t = tm;
                } else {
                    hi_t = tm;
                }
            }
            let tm = lo_t;
            x1 = (st.x + st.v * tm + 0.5 * st.a * tm * tm + j * tm * tm * tm / 6.0).max(st.x);
            v1 = 0.0;
            a1 = 0.0;
        }
        Next {
            t: st.t + dt,
            x: x1,
            v: v1,
            a: a1,
            clipped: false,
        }
    }

    /// No progress: at rest where the ceiling is below what one cycle at the jerk cap
    /// makes (W < j_cap·Tcy²), or where the ceiling (the backward profile) has come to a
    /// near standstill with a deceleration that would take the motion back: go on at a
    /// crawl under the velocity limit, whose step is a part of the jerk cap (counted as a
    /// clip). Before 2026-11-28 a forward state on such a profile with v > 0 was put back
    /// on it every cycle and never moved ("the limits allow no motion", issue 43). Then,
    /// crawl or not, never backwards (a cycle in which the speed dips below 0 and back).
    /// Whether it crawled.
    fn crawl_if_stuck(&mut self, here: &Here, next: &mut Next) -> bool {
        let (pass, st, dt) = (self.pass, self.st, self.pass.dt);
        let crawl = next.x <= st.x;
        if crawl {
            let xc = next.x.max(st.x);
            let w0 = match &pass.limit {
                Some(l) => l.w_at(xc),
                _ => pass.ceiling.at(xc, self.hint).0,
            };
            let jm = here.jc.max(0.0);
            next.v = (w0.min(here.vmax) * (1.0 - CRAWL_UNDER_LIMIT_REL))
                .min(CRAWL_JERK_SHARE * jm * dt * dt)
                .max(0.0);
            next.a = 0.0;
            next.x = next.x.max(st.x) + next.v * dt;
            if next.v > 0.0 {
                self.stats.clips += 1;
                next.clipped = true;
            }
        }
        next.x = next.x.max(st.x);
        crawl
    }

    /// Past the end: the last, partial cycle, to the time at which x reaches L. Within
    /// [`END_MM`] of the end: this state is the end (one state, not a second one at the
    /// same time), reached after the cycle — the last nanometres at the speed there, or
    /// from rest in the rest-to-rest time at the jerk cap, 4·(d/(2·j))^(1/3) — so that
    /// no cycle of the trajectory jumps them.
    fn end_of_path(&self, here: &Here, j: f64, next: &mut Next) {
        let (st, dt, len) = (self.st, self.pass.dt, self.len);
        if next.x > len {
            let (mut t_lo, mut t_hi) = (0.0, dt);
            for _ in 0..TIME_BISECTIONS {
                let tm = 0.5 * (t_lo + t_hi);
                let xm = st.x + st.v * tm + 0.5 * st.a * tm * tm + j * tm * tm * tm / 6.0;
                if xm < len {
                    t_lo = tm;
                } else {
                    t_hi = tm;
                }
            }
            let tm = t_hi;
            next.x = len;
            next.v = (st.v + st.a * tm + 0.5 * j * tm * tm).max(0.0);
            next.a = st.a + j * tm;
            next.t = st.t + tm;
        }
        if next.x >= len - END_MM && next.x < len {
            let d = len - next.x;
            let jm = here.jc.max(0.0);
            next.t += if next.v > 0.0 {
                (d / next.v).min(dt)
            } else if jm > 0.0 {
                4.0 * (d / (2.0 * jm)).cbrt()
            } else {
                dt
            };
            next.x = len;
        }
    }

    /// Just above a profile that is not itself the limit (the forward pass under the
    /// backward profile, rewinding), by at most [`OVER_PROFILE_REL`], and under the
    /// velocity limit: the state stands, braking at the caps from the next cycle (no state
    /// is safe above the ceiling) — a motion within the limits, where a clip or a rewind
    /// would jump it. `w1`: the ceiling there (at most the feed and the axes' V), mm/s.
    fn stands_over_profile(&self, here: &Here, next: &Next, w1: f64) -> bool {
        let pass = self.pass;
        pass.rewind
            && next.v <= w1 * (1.0 + OVER_PROFILE_REL)
            && pass
                .limit
                .as_ref()
                .is_some_and(|l| next.v <= l.w_at(next.x).min(here.vmax) * (1.0 + CEILING_REL))
    }

    /// Above the ceiling `w1` (mm/s) when rewinding, within the budget of undone steps:
    /// note the dip here and go back to the latest kept state from which braking passes
    /// it at or under its speed. Whether it went back.
    fn rewind(&mut self, next: &Next, w1: f64) -> bool {
        let pass = self.pass;
        let budget = self.stats.steps / REWIND_BUDGET_PER_STEP_INV + REWIND_BUDGET_STEPS;
        let above = next.v > w1 * (1.0 + CEILING_REL)
            && pass.rewind
            && next.x < self.len
            && self.undone < budget;
        if !above {
            return false;
        }
        let Some(k) = self.note_dip(next, w1) else {
            return false;
        };
        match self.braking_start() {
            Some(m) => {
                self.undo(m);
                true
            }
            None => {
                // No state kept can brake to it: the dip is of no use.
                self.dips.remove(k);
                false
            }
        }
    }

    /// The dip at `next` (a dip already there, within two cycles' travel: its speed
    /// lowered by [`DIP_TIGHTEN`], until [`DIP_TRIES`]; else a new one at `w1`, up to
    /// [`DIPS_MAX`]): its index, or `None` when it is given up.
    fn note_dip(&mut self, next: &Next, w1: f64) -> Option<usize> {
        let (x1, v1) = (next.x, next.v);
        let near = DIP_NEAR_CYCLES * self.st.v.max(v1) * self.pass.dt + DIP_NEAR_MM;
        let dips = &mut self.dips;
        let lo_k = dips.partition_point(|d| d.x < x1 - near);
        match (lo_k < dips.len() && dips[lo_k].x <= x1 + near).then_some(lo_k) {
            Some(k) => {
                dips[k].v *= DIP_TIGHTEN;
                dips[k].tries += 1;
                Some(k).filter(|&k| dips[k].tries <= DIP_TRIES)
            }
            None if dips.len() < DIPS_MAX => {
                let at = dips.partition_point(|d| d.x < x1);
                dips.insert(
                    at,
                    Dip {
                        x: x1,
                        v: w1,
                        tries: 0,
                    },
                );
                Some(at)
            }
            None => None,
        }
    }

    /// How many kept steps back (1, 2, 4, …, then all) the latest state is from which the
    /// hardest braking passes every dip ahead ([`Pass::clears_dips`]); `None` if none.
    fn braking_start(&self) -> Option<usize> {
        let (pass, buf) = (self.pass, &self.buf);
        let clears =
            |p: &Pending| pass.clears_dips(p.from.x, p.from.v, p.from.a, &self.dips, self.len);
        let mut m = 1usize;
        while m <= buf.len() {
            if clears(&buf[buf.len() - m]) {
                return Some(m);
            }
            m *= 2;
        }
        if !buf.is_empty() && clears(&buf[0]) {
            return Some(buf.len());
        }
        None
    }

    /// Undo the last `m` kept steps: go on from where the first of them started.
    fn undo(&mut self, m: usize) {
        let keep = self.buf.len() - m;
        let first = &self.buf[keep];
        self.st = first.from;
        self.hint = first.hint;
        self.cursor = first.cursor;
        self.at_end = None;
        self.idle = 0;
        for p in self.buf.drain(keep..) {
            self.stats.steps -= 1;
            if p.clipped {
                self.stats.clips -= 1;
            }
        }
        self.undone += m as u64;
    }

    /// Put the state on the ceiling `w1` (mm/s) with its acceleration `aw1` (mm/s²),
    /// within the caps there at that speed: |a| also where some jerk is left
    /// ([`Caps::a_for_jerk`]) — above it no jerk could bring |a| back, and the pass would
    /// hold it, braking, far under the ceiling. Counted.
    fn clip(&mut self, next: &mut Next, w1: f64, aw1: f64) {
        let pass = self.pass;
        next.clipped = true;
        next.v = w1;
        let (d1, _) = pass
            .geo
            .derivs_feed_near(pass.s_of(next.x, self.len), &mut self.cursor);
        let caps1 = Caps::new(&Local::from_derivs(&d1), pass.machine);
        let lim = (caps1.a_cap(next.v) * pass.use_caps[0])
            .min(caps1.a_for_jerk(next.v))
            .max(0.0);
        next.a = aw1.clamp(-lim, lim);
        self.stats.clips += 1;
    }

    /// Count a step that makes no progress; `Err(s)` past [`STALL_STEPS`] in a row.
    fn count_idle(&mut self, x1: f64) -> Result<(), f64> {
        if x1 <= self.st.x {
            self.idle += 1;
            if self.idle > STALL_STEPS {
                return Err(self.pass.s_of(self.st.x, self.len));
            }
        } else {
            self.idle = 0;
        }
        Ok(())
    }

    /// A step taken: kept for a rewind (handed out when it is [`REWIND_STEPS`] old), or
    /// handed out at once; the state moves on.
    fn take(&mut self, p: Pending) {
        let to = p.to;
        if self.pass.rewind {
            self.buf.push_back(p);
            self.hand_out(REWIND_STEPS);
        } else {
            self.sink.step(&p.from, &p.to, p.j, p.cycle);
        }
        self.st = to;
        self.stats.steps += 1;
    }

    /// Hand out the oldest kept steps until `keep` are left.
    fn hand_out(&mut self, keep: usize) {
        while self.buf.len() > keep {
            let Some(p) = self.buf.pop_front() else {
                break;
            };
            self.sink.step(&p.from, &p.to, p.j, p.cycle);
        }
    }

    /// The end: every kept step handed out; a path shorter than [`END_MM`] reached at
    /// once.
    fn finish(mut self) -> PassStats {
        self.hand_out(0);
        if self.st.x < self.len {
            let to = State {
                x: self.len,
                ..self.st
            };
            self.sink.step(&self.st, &to, 0.0, false);
            self.st = to;
        }
        self.stats.time_s = self.st.t;
        self.stats
    }
}

#[cfg(test)]
mod tests {
    /// The cube root agrees with the library's to rounding over 600 decades.
    #[test]
    fn cube_root() {
        let mut x = 1e-300;
        while x < 1e300 {
            let (a, b) = (super::cbrt(x), x.cbrt());
            assert!((a - b).abs() <= 4.0 * f64::EPSILON * b, "{x}: {a} {b}");
            x *= 1.7;
        }
        assert_eq!(super::cbrt(0.0), 0.0);
        assert_eq!(super::cbrt(-1.0), 0.0);
    }
}
