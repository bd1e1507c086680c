//! A model of LinuxCNC 2.9's trajectory planner on a run of G1 lines with rotary motion:
//! what a LinuxCNC user's machine takes, rather than the jerk-limited controller of the
//! rest of this crate.
//!
//! Read from LinuxCNC's source at the version Debian 12 ships
//! (2.9.0~pre1+git20230208.f1270d6ed7): `src/emc/task/emccanon.cc` (what each line asks)
//! and `src/emc/tp/tp.c`, `tc.c`, `blendmath.h` (how the planner moves along it). Velocity
//! and acceleration only: 2.9's planner has no jerk limit. Units: mm, degrees, seconds.
//!
//! # Each line (emccanon.cc: `getStraightVelocity`, `getStraightAcceleration`)
//! A G1 line with rotary motion is a segment of its own (`see_segment` never joins it to
//! the next). With dᵢ the displacement of axis i (X Y Z in mm, A/B and C in degrees) and L
//! the X Y Z length (the path length the feed refers to; the rotary length when X Y Z do
//! not move):
//!
//! ```text
//! v_max = L / maxᵢ(dᵢ / Vᵢ)      a_max = L / maxᵢ(dᵢ / Aᵢ)      v_req = min(F, v_max)
//! ```
//!
//! The axis limits are the INI's `[AXIS_*]` ones: in the world frame, not the joints'
//! (with non-trivial kinematics LinuxCNC does not bound the joints while planning, its
//! issue #97). The planner also clamps v_max to L / T (one servo period, `tcClampVelocityByLength`)
//! and a line with X Y Z motion to `[TRAJ]MAX_LINEAR_VELOCITY`.
//!
//! # The segment-stop rule (tp.c, tc.c)
//! In G64 every segment has the parabolic terminal condition, and a segment with rotary
//! motion can neither be blended by an arc nor be tangent to its neighbour
//! (`tpCheckBlendArcType`, `tpSetupTangent` refuse rotary motion). So:
//! - Its final velocity is 0 (`tpGetRealFinalVel`: 0 unless tangent): each segment plans a
//!   trapezoid that stops at its own end (`tpCalculateTrapezoidalAccel`), at **half** its
//!   acceleration (`tcGetOverallMaxAccel`: ×0.5 for a parabolic blend with either
//!   neighbour, so that two blending segments together stay within the limit).
//! - The next segment starts when this one is on its final deceleration and slower than its
//!   blend velocity (`tcIsBlending`); from then both move in the same cycles (the next
//!   one's own trapezoid from rest: its `target_vel` during the blend is not read for
//!   an unsynchronised move), until this one reaches its end.
//! - The blend velocity (`tpComputeBlendVelocity`, blend tolerance 0): with a = a_max/2,
//!   v_r = min(√(a·L'), v_req) (L' = L, or L/2 for the last segment in the queue, which a
//!   blend may still shorten), t_blend = min(L₁/v_r1, L₂/v_r2, max(v_r1/a₁, v_r2/a₂)),
//!   v_blend = min(v_r, a·t_blend).
//!
//! So a short segment never goes faster than it could stop from within itself at half the
//! acceleration (√(a_max·L/2)), before and after a patch: 1 mm lines with 1.5° of C each
//! take about 0.1 s where the feed would take 0.03 s. The model steps the planner's own
//! cycle (`tpRunCycle`: regular cycles, split cycles at a segment's end) at the servo
//! period and counts the cycles until the last segment has stopped.

use crate::tolerances::{
    LCNC_MAX_CYCLES_PER_SEGMENT as MAX_CYCLES_PER_SEGMENT,
    LCNC_MIN_DISPLACEMENT as MIN_DISPLACEMENT, LCNC_POS_EPSILON as POS_EPSILON,
    LCNC_TIME_EPSILON as TIME_EPSILON, LCNC_VEL_EPSILON as VEL_EPSILON,
};

/// Limits and settings of a LinuxCNC machine, in the planner's units.
#[derive(Debug, Clone, PartialEq)]
pub struct LinuxCncMachine {
    /// Velocity limit per axis X Y Z (mm/s), primary and C (°/s): `[AXIS_*]MAX_VELOCITY`.
    pub v_max: [f64; 5],
    /// Acceleration limit per axis, mm/s² and °/s²: `[AXIS_*]MAX_ACCELERATION`.
    pub a_max: [f64; 5],
    /// Servo period, s (`[EMCMOT]SERVO_PERIOD` / 10⁹; 0.001 by default).
    pub cycle_s: f64,
    /// `[TRAJ]MAX_LINEAR_VELOCITY`, mm/s: caps every line with X Y Z motion.
    pub max_linear_velocity_mm_s: f64,
}

impl LinuxCncMachine {
    /// The LinuxCNC configuration of a polepatch machine, as `benches/linuxcnc/lcnc_bench.py`
    /// writes it: each axis' V and A in `[AXIS_*]` (and `[JOINT_*]`), the servo period
    /// Tcy, `[TRAJ]MAX_LINEAR_VELOCITY` the fastest linear axis. The jerk limits are not
    /// used (2.9's planner has none).
    pub fn of(machine: &polepatch_kinematics::Machine) -> LinuxCncMachine {
        LinuxCncMachine {
            v_max: machine.limits.map(|l| l.v),
            a_max: machine.limits.map(|l| l.a),
            cycle_s: machine.tcy_s,
            max_linear_velocity_mm_s: machine.limits[..3].iter().map(|l| l.v).fold(0.0, f64::max),
        }
    }
}

/// What the model finds along a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinuxCncRun {
    /// Time from rest at the first point to rest at the last, s (cycles × period).
    pub time_s: f64,
    /// Servo cycles.
    pub cycles: usize,
    /// Segments (lines with motion).
    pub segments: usize,
    /// Largest speed of each axis in the world frame, X Y Z mm/s, primary and C °/s.
    pub peak_axis_velocity: [f64; 5],
}

/// One segment (`TC_STRUCT` of a line) with the state the planner keeps.
#[derive(Debug, Clone)]
struct Tc {
    /// Length, mm (or ° for a rotary-only line).
    target: f64,
    progress: f64,
    v: f64,
    /// Half of `a_max`: every segment blends parabolically with its neighbours.
    a_t: f64,
    /// min(v_req, v_max, linear cap): `tpGetRealTargetVel` at feed scale 1.
    v_target: f64,
    /// Axis displacement per unit of progress.
    unit: [f64; 5],
    finalized: bool,
    cycle_s: f64,
    on_final_decel: bool,
    blending_next: bool,
    blend_vel: f64,
    splitting: bool,
    remove: bool,
    active: bool,
}

impl Tc {
    /// `tpCalculateTrapezoidalAccel` with final velocity 0: (acceleration, desired speed).
    fn trapezoidal(&self) -> (f64, f64) {
        let dx = self.target - self.progress;
        let a = self.a_t;
        let ct = self.cycle_s;
        let term3 = (a * ct * 0.5).powi(2);
        let discr = a * (2.0 * dx - self.v * ct) + term3;
        let mut max_new_v = -a * ct * 0.5;
        if discr > term3 {
            max_new_v += discr.sqrt();
        }
        let new_v = max_new_v.clamp(-self.v_target, self.v_target);
        let dt = ct.max(TIME_EPSILON);
        let acc = ((new_v - self.v) / dt).clamp(-a, a);
        (acc, max_new_v)
    }

    /// `tcUpdateDistFromAccel`.
    fn advance(&mut self, acc: f64, v_desired: f64) {
        let ct = self.cycle_s;
        let mut v_next = self.v + acc * ct;
        if v_next < 0.0 {
            v_next = 0.0;
            if self.target - self.progress < self.v * ct {
                self.progress = self.target;
            }
        } else {
            self.progress = (self.progress + (v_next + self.v) * 0.5 * ct).min(self.target);
        }
        self.v = v_next;
        self.on_final_decel = (v_desired - self.v).abs() < VEL_EPSILON && acc < 0.0;
    }

    /// `tpCheckEndCondition` with final velocity 0: flags a split cycle when the end is
    /// less than one period away.
    fn check_end(&mut self, period_s: f64) {
        self.cycle_s = period_s;
        let dx = self.target - self.progress;
        if dx <= POS_EPSILON {
            self.progress = self.target;
            self.split(0.0);
            return;
        }
        let v_avg = self.v * 0.5;
        let mut dt = TIME_EPSILON * 0.5;
        if v_avg > VEL_EPSILON {
            dt = dt.max(dx / v_avg);
        } else if dx > v_avg * period_s && dx > POS_EPSILON {
            return;
        }
        let a_f = -self.v / dt;
        let a = a_f.clamp(-self.a_t, self.a_t);
        if a != a_f {
            let disc = (self.v / a).powi(2) + 2.0 / a * dx;
            if disc < 0.0 {
                return;
            }
            dt = if disc < TIME_EPSILON * TIME_EPSILON {
                -self.v / a
            } else if a > 0.0 {
                -self.v / a + disc.sqrt()
            } else {
                -self.v / a - disc.sqrt()
            };
        }
        if dt < TIME_EPSILON {
            self.progress = self.target;
            self.split(0.0);
        } else if dt < period_s {
            self.split(dt);
        }
    }

    /// `tcSetSplitCycle`.
    fn split(&mut self, split_s: f64) {
        self.splitting = true;
        self.cycle_s = split_s;
    }

    /// `tpUpdateCycle`.
    fn update(&mut self, period_s: f64) {
        let (acc, v_desired) = self.trapezoidal();
        self.advance(acc, v_desired);
        self.check_end(period_s);
    }

    /// `tcIsBlending`: latched once the blend starts.
    fn is_blending(&mut self) -> bool {
        self.blending_next |= self.on_final_decel && self.v < self.blend_vel;
        self.blending_next
    }

    /// `tpCalculateTriangleVel`.
    fn triangle_vel(&self) -> f64 {
        let length = if self.finalized {
            self.target
        } else {
            self.target / 2.0
        };
        (self.a_t * length).sqrt()
    }
}

/// `tpComputeBlendVelocity` with blend tolerance 0: (this segment's, the next one's).
fn blend_velocities(this: &Tc, next: &Tc) -> (f64, f64) {
    let v_this = this.triangle_vel().min(this.v_target);
    let v_next = next.triangle_vel().min(next.v_target);
    let t_max_reachable = (this.target / v_this).min(next.target / v_next);
    let t_max_blend = (v_this / this.a_t).max(v_next / next.a_t);
    let t_blend = t_max_reachable.min(t_max_blend);
    (
        v_this.min(t_blend * this.a_t),
        v_next.min(t_blend * next.a_t),
    )
}

/// A line from `from` to `to` at `feed_mm_s` as the interpreter sends it
/// (emccanon.cc), or `None` when nothing moves.
fn segment(m: &LinuxCncMachine, from: &[f64; 5], to: &[f64; 5], feed_mm_s: f64) -> Option<Tc> {
    let d: [f64; 5] = std::array::from_fn(|i| {
        let d = (to[i] - from[i]).abs();
        if d < MIN_DISPLACEMENT { 0.0 } else { d }
    });
    let linear = d[..3].iter().any(|&x| x > 0.0);
    let angular = d[3..].iter().any(|&x| x > 0.0);
    if !linear && !angular {
        return None;
    }
    let axes = if linear && !angular {
        0..3
    } else if linear {
        0..5
    } else {
        3..5
    };
    let t_v = axes.clone().map(|i| d[i] / m.v_max[i]).fold(0.0, f64::max);
    let t_a = axes.map(|i| d[i] / m.a_max[i]).fold(0.0, f64::max);
    let length = if linear {
        d[..3].iter().map(|x| x * x).sum::<f64>().sqrt()
    } else {
        d[3..].iter().map(|x| x * x).sum::<f64>().sqrt()
    };
    let v_max = (length / t_v).min(length / m.cycle_s);
    let mut v_target = feed_mm_s.min(v_max);
    if linear {
        v_target = v_target.min(m.max_linear_velocity_mm_s);
    }
    Some(Tc {
        target: length,
        progress: 0.0,
        v: 0.0,
        a_t: 0.5 * length / t_a,
        v_target,
        unit: std::array::from_fn(|i| (to[i] - from[i]) / length),
        finalized: true,
        cycle_s: m.cycle_s,
        on_final_decel: false,
        blending_next: false,
        blend_vel: 0.0,
        splitting: false,
        remove: false,
        active: false,
    })
}

/// The time LinuxCNC 2.9 takes along `points` (X Y Z mm, primary and C degrees, as
/// programmed) from rest to rest at `feed_mm_min`, in G64 without tolerance, feed override
/// 100 %. (A rotary-only line takes F as °/min, as LinuxCNC does.)
pub fn run_time(m: &LinuxCncMachine, points: &[[f64; 5]], feed_mm_min: f64) -> LinuxCncRun {
    let feed = feed_mm_min / 60.0;
    let mut queue: std::collections::VecDeque<Tc> = points
        .windows(2)
        .filter_map(|w| segment(m, &w[0], &w[1], feed))
        .collect();
    let segments = queue.len();
    if let Some(last) = queue.back_mut() {
        last.finalized = false;
    }
    let period = m.cycle_s;
    let mut cycles = 0usize;
    let mut peak = [0.0f64; 5];
    let guard = MAX_CYCLES_PER_SEGMENT.saturating_mul(segments.max(1));
    while !queue.is_empty() && cycles < guard {
        cycles += 1;
        let mut before = [0.0f64; 2];
        for (b, t) in before.iter_mut().zip(&queue) {
            *b = t.progress;
        }
        let (first, rest) = queue.make_contiguous().split_at_mut(1);
        let tc = &mut first[0];
        let next = rest.first_mut();
        if !tc.active {
            // tpActivateSegment
            tc.active = true;
            tc.blending_next = false;
            tc.on_final_decel = false;
        }
        if tc.splitting {
            // tpHandleSplitCycle: this one lands on its end; the next gets a full cycle.
            tc.progress = tc.target;
            tc.remove = true;
            if let Some(n) = next {
                n.update(period);
            }
        } else {
            tc.cycle_s = period;
            tc.update(period);
            match next {
                Some(n) => {
                    let (v_this, v_next) = blend_velocities(tc, n);
                    tc.blend_vel = v_this;
                    n.blend_vel = v_next;
                    if tc.is_blending() {
                        n.update(period);
                    }
                }
                None => tc.blend_vel = 0.0,
            }
        }
        // Axis speeds this cycle: the displacement of the (up to) two moving segments.
        let mut step = [0.0f64; 5];
        for (t, p0) in queue.iter().zip(&before) {
            for (s, u) in step.iter_mut().zip(&t.unit) {
                *s += (t.progress - p0) * u;
            }
        }
        for (p, s) in peak.iter_mut().zip(step) {
            *p = p.max(s.abs() / period);
        }
        if queue.front().is_some_and(|t| t.remove) {
            queue.pop_front();
        }
    }
    LinuxCncRun {
        time_s: cycles as f64 * period,
        cycles,
        segments,
        peak_axis_velocity: peak,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn machine() -> LinuxCncMachine {
        LinuxCncMachine {
            v_max: [500.0, 500.0, 500.0, 90.0, 120.0],
            a_max: [2500.0, 3000.0, 2100.0, 298.8, 298.8],
            cycle_s: 0.001,
            max_linear_velocity_mm_s: 500.0,
        }
    }

    /// One long straight line: a trapezoid at half the acceleration, within a few cycles.
    #[test]
    fn a_straight_line_is_a_trapezoid_at_half_the_acceleration() {
        let m = machine();
        let (l, f) = (100.0, 3000.0);
        let r = run_time(&m, &[[0.0; 5], [l, 0.0, 0.0, 0.0, 0.0]], f);
        let (v, a) = (f / 60.0, m.a_max[0] / 2.0);
        let expected = l / v + v / a;
        assert!(
            (r.time_s - expected).abs() < 0.005,
            "{} s against {expected} s",
            r.time_s
        );
        assert!((r.peak_axis_velocity[0] - v).abs() < 1e-6);
    }

    /// The segment-stop rule: short lines with rotary motion each stay below the speed
    /// they can stop from within themselves at half the acceleration (√(a·L/2)), so a
    /// run of them takes far longer than L/F.
    #[test]
    fn short_rotary_lines_are_limited_by_stopping_within_each() {
        let m = machine();
        let points: Vec<[f64; 5]> = (0..=50)
            .map(|k| [k as f64, 0.0, 0.0, 10.0, 1.5 * k as f64])
            .collect();
        let r = run_time(&m, &points, 3000.0);
        let lf = 50.0 / 50.0;
        // C's acceleration bounds the line's: a = L / (dC / A_C) = 1 / (1.5 / 298.8).
        let a_line: f64 = 298.8 / 1.5;
        let v_stop = (a_line / 2.0 * 1.0).sqrt();
        // Two segments move at once during a blend: their sum may pass one segment's
        // bound a little, never the feed (50 mm/s here).
        assert!(
            r.peak_axis_velocity[0] <= v_stop * 1.05,
            "X peaks at {} mm/s, the stop rule allows {v_stop}",
            r.peak_axis_velocity[0]
        );
        assert!(r.time_s > 2.0 * lf, "{} s against L/F {lf} s", r.time_s);
        assert_eq!(r.segments, 50);
    }

    /// The axis velocity limit: a line whose C turn is the slowest axis runs at C's limit.
    #[test]
    fn the_slowest_axis_sets_the_lines_speed() {
        let m = machine();
        let r = run_time(&m, &[[0.0; 5], [100.0, 0.0, 0.0, 0.0, 360.0]], 6000.0);
        assert!(r.peak_axis_velocity[4] <= m.v_max[4] * (1.0 + 1e-9));
        assert!((r.peak_axis_velocity[4] - m.v_max[4]).abs() < 1e-6);
        // Cruise at 120 °/s over 360° plus the ramps at half of 298.8 °/s².
        let expected = 360.0 / 120.0 + 120.0 / 149.4;
        assert!((r.time_s - expected).abs() < 0.01, "{}", r.time_s);
    }

    #[test]
    fn no_motion_takes_no_time() {
        let r = run_time(&machine(), &[[1.0; 5], [1.0; 5]], 1000.0);
        assert_eq!((r.cycles, r.segments), (0, 0));
    }
}
