//! The axes' limits as limits on the motion along the path (the 1-D reduction).
//!
//! With `v = ṡ`, `a = s̈`, `j = s⃛` and an axis q(s) with derivatives q_s, q_ss, q_sss
//! (per mm, from the analysis spline):
//!
//! ```text
//! q̇ = q_s·v        q̈ = q_ss·v² + q_s·a        q⃛ = q_sss·v³ + 3·q_ss·v·a + q_s·j
//! ```
//!
//! The triangle inequality gives a sufficient condition for every axis i:
//!
//! ```text
//! |q_s|·v ≤ V_i,    |q_ss|·v² + |q_s|·|a| ≤ A_i,    |q_sss|·v³ + 3·|q_ss|·v·|a| + |q_s|·|j| ≤ J_i
//! ```
//!
//! so at a point of the path, with speed v and acceleration a,
//!
//! ```text
//! |a| ≤ a_cap(v)    = min_i (A_i − |q_ss^i|·v²) / |q_s^i|
//! |j| ≤ j_cap(v,|a|) = min_i (J_i − |q_sss^i|·v³ − 3·|q_ss^i|·v·|a|) / |q_s^i|
//! ```
//!
//! (an axis with q_s = 0 only needs its own curvature terms within its limits). The
//! condition is exact on a straight line (q_ss = q_sss = 0): the 1-D problem is then
//! V, A, J divided by the largest |q_s|. At a = 0, j = 0 it is Equation 6 itself: v may
//! be anything up to the Equation-6 bound. It is symmetric in the signs of a and j, so a
//! motion along the path is allowed forward exactly when it is allowed backward (what the
//! backward pass relies on).

use polepatch_kinematics::Machine;

use crate::tolerances::LIMIT_USE;

/// |q_s|, |q_ss|, |q_sss| of the five axes at one point of the path ([`polepatch_kinematics::Axis`] order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Local {
    /// |q_s| per axis (mm/mm or °/mm).
    pub qs: [f64; 5],
    /// |q_ss| per axis (per mm²).
    pub qss: [f64; 5],
    /// |q_sss| per axis (per mm³).
    pub qsss: [f64; 5],
}

impl Local {
    /// From `[q, q', q'', q''']` of each axis.
    pub fn from_derivs(d: &[[f64; 4]; 5]) -> Local {
        Local {
            qs: d.map(|e| e[1].abs()),
            qss: d.map(|e| e[2].abs()),
            qsss: d.map(|e| e[3].abs()),
        }
    }

    /// Largest speed along the path the axes' velocity limits allow, mm/s (+∞ if no axis
    /// moves).
    pub fn v_cap(&self, m: &Machine) -> f64 {
        let mut c = f64::INFINITY;
        for (l, qs) in m.limits.iter().zip(self.qs) {
            if qs > 0.0 {
                c = c.min(LIMIT_USE * l.v / qs);
            }
        }
        c
    }

    /// Largest |path acceleration| at speed `v`, mm/s²; negative when no acceleration
    /// keeps every axis within A at this speed.
    pub fn a_cap(&self, m: &Machine, v: f64) -> f64 {
        Caps::new(self, m).a_cap(v)
    }

    /// Largest |path jerk| at speed `v` and |acceleration| `a_abs`, mm/s³; negative when
    /// no jerk keeps every axis within J.
    pub fn j_cap(&self, m: &Machine, v: f64, a_abs: f64) -> f64 {
        Caps::new(self, m).j_cap(v, a_abs)
    }
}

/// The caps of [`Local`] at one point, prepared for many speeds and accelerations (a
/// pass asks them some thirty times per cycle): the planned limits and 1/|q_s| of each
/// axis (0 for an axis that does not move, whose own curvature terms only need room).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Caps {
    a: [f64; 5],
    j: [f64; 5],
    qss: [f64; 5],
    /// 3·|q_ss| (the factor of the jerk cap's v·|a| term, as `3.0 * qss` rounds it).
    qss3: [f64; 5],
    qsss: [f64; 5],
    inv_qs: [f64; 5],
    /// Every axis moves (1/|q_s| > 0): each bounds the caps by its own term, with no
    /// branch (the same minimum as [`Caps::bound`] takes).
    all_move: bool,
}

impl Caps {
    /// The caps of `loc` on `m`.
    pub fn new(loc: &Local, m: &Machine) -> Caps {
        let inv_qs = loc.qs.map(|q| if q > 0.0 { 1.0 / q } else { 0.0 });
        Caps {
            a: std::array::from_fn(|i| LIMIT_USE * m.limits[i].a),
            j: std::array::from_fn(|i| LIMIT_USE * m.limits[i].j),
            qss: loc.qss,
            qss3: loc.qss.map(|q| 3.0 * q),
            qsss: loc.qsss,
            inv_qs,
            all_move: inv_qs.iter().all(|&i| i > 0.0),
        }
    }

    /// [`Local::a_cap`].
    #[inline]
    pub fn a_cap(&self, v: f64) -> f64 {
        let mut c = f64::INFINITY;
        if self.all_move {
            for i in 0..5 {
                c = c.min((self.a[i] - self.qss[i] * v * v) * self.inv_qs[i]);
            }
            return c;
        }
        for i in 0..5 {
            let room = self.a[i] - self.qss[i] * v * v;
            c = self.bound(c, i, room);
        }
        c
    }

    /// [`Local::j_cap`].
    #[inline]
    pub fn j_cap(&self, v: f64, a_abs: f64) -> f64 {
        let mut c = f64::INFINITY;
        if self.all_move {
            for i in 0..5 {
                let room = self.j[i] - self.qsss[i] * v * v * v - self.qss3[i] * v * a_abs;
                c = c.min(room * self.inv_qs[i]);
            }
            return c;
        }
        for i in 0..5 {
            let room = self.j[i] - self.qsss[i] * v * v * v - self.qss3[i] * v * a_abs;
            c = self.bound(c, i, room);
        }
        c
    }

    /// The largest |path acceleration| at speed `v` at which some jerk keeps every axis
    /// within J (`j_cap(v, |a|) ≥ 0`), mm/s²: `min_i (J_i − |q_sss^i|·v³)/(3·|q_ss^i|·v)`
    /// over the axes with curvature, 0 where an axis' `|q_sss|·v³` alone is above its J,
    /// +∞ when no axis bounds it. Above it the state is beyond the jerk limits whatever the
    /// jerk, and no jerk can bring |a| back ([`Caps::j_cap`] < 0).
    pub fn a_for_jerk(&self, v: f64) -> f64 {
        let mut c = f64::INFINITY;
        for i in 0..5 {
            let room = self.j[i] - self.qsss[i] * v * v * v;
            let per_a = 3.0 * self.qss[i] * v;
            if room < 0.0 {
                return 0.0;
            }
            if per_a > 0.0 {
                c = c.min(room / per_a);
            }
        }
        c
    }

    /// `c` lowered by axis `i`'s cap with `room` left of its limit.
    fn bound(&self, c: f64, i: usize, room: f64) -> f64 {
        if self.inv_qs[i] > 0.0 {
            c.min(room * self.inv_qs[i])
        } else if room < 0.0 {
            c.min(room)
        } else {
            c
        }
    }
}

/// Each axis' use of its limits at a state of the motion: the largest of |q̇|/V, |q̈|/A,
/// |q⃛|/J (signed chain rule, not the bound above), per axis.
pub fn shares(m: &Machine, d: &[[f64; 4]; 5], v: f64, a: f64, j: f64) -> [f64; 5] {
    std::array::from_fn(|i| {
        let [_, qs, qss, qsss] = d[i];
        let l = &m.limits[i];
        let vel = (qs * v).abs() / l.v;
        let acc = (qss * v * v + qs * a).abs() / l.a;
        let jerk = (qsss * v * v * v + 3.0 * qss * v * a + qs * j).abs() / l.j;
        vel.max(acc).max(jerk)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m() -> Machine {
        Machine::builtin("mikron-ucp710").unwrap()
    }

    /// On a line along X the caps are X's limits (times the planning margin).
    #[test]
    fn a_line_has_the_axis_limits() {
        let mut d = [[0.0; 4]; 5];
        d[0][1] = 1.0;
        let l = Local::from_derivs(&d);
        let x = m().limits[0];
        assert_eq!(l.v_cap(&m()), LIMIT_USE * x.v);
        assert_eq!(l.a_cap(&m(), 123.0), LIMIT_USE * x.a);
        assert_eq!(l.j_cap(&m(), 123.0, 999.0), LIMIT_USE * x.j);
    }

    /// Planted state on a curve: any (a, j) within the caps keeps every axis within its
    /// limits by the signed chain rule, and the caps are reached (the binding axis at 1).
    #[test]
    fn within_the_caps_every_axis_is_within_its_limits() {
        let m = m();
        let mut d = [[0.0; 4]; 5];
        d[0] = [0.0, 0.8, 0.01, -0.002];
        d[1] = [0.0, -0.6, 0.02, 0.001];
        d[4] = [0.0, 2.0, 3.0, 18.0];
        let l = Local::from_derivs(&d);
        let v = 5.0;
        let a = 0.7 * l.a_cap(&m, v);
        let j = l.j_cap(&m, v, a);
        assert!(a > 0.0 && j > 0.0, "{a} {j}");
        for sa in [-1.0, 1.0] {
            for sj in [-1.0, 1.0] {
                let sh = shares(&m, &d, v, sa * a, sj * j);
                assert!(sh.iter().all(|&s| s <= LIMIT_USE + 1e-12), "{sh:?}");
            }
        }
        // Same signs of the terms as the bound: the binding axis reaches its jerk share.
        let sh = shares(&m, &d, v, a, j);
        assert!((sh[4] - LIMIT_USE).abs() < 1e-9, "{sh:?}");
    }

    /// Where every axis moves, the caps without branches are the caps with them, to the
    /// bit.
    #[test]
    fn the_branch_free_caps_are_the_caps() {
        let m = m();
        let mut d = [[0.0; 4]; 5];
        d[0] = [0.0, 0.8, 0.01, -0.002];
        d[1] = [0.0, -0.6, 0.02, 0.001];
        d[2] = [0.0, 0.1, -0.3, 0.05];
        d[3] = [0.0, 1.5, 0.7, -4.0];
        d[4] = [0.0, 2.0, 3.0, 18.0];
        let fast = Caps::new(&Local::from_derivs(&d), &m);
        assert!(fast.all_move);
        let general = Caps {
            all_move: false,
            ..fast
        };
        for v in [0.0, 0.3, 5.0, 40.0, 1e3] {
            assert_eq!(fast.a_cap(v).to_bits(), general.a_cap(v).to_bits(), "{v}");
            for a in [0.0, 2.0, 300.0] {
                assert_eq!(
                    fast.j_cap(v, a).to_bits(),
                    general.j_cap(v, a).to_bits(),
                    "{v} {a}"
                );
            }
        }
    }

    /// At the acceleration `a_for_jerk` gives, the jerk cap is 0 (the binding axis has
    /// no jerk left), below it positive, above it negative.
    #[test]
    fn a_for_jerk_is_where_the_jerk_cap_runs_out() {
        let m = m();
        let mut d = [[0.0; 4]; 5];
        d[0] = [0.0, 0.8, 0.01, -0.002];
        d[4] = [0.0, 2.0, 3.0, 18.0];
        let c = Caps::new(&Local::from_derivs(&d), &m);
        let v = 5.0;
        let a = c.a_for_jerk(v);
        assert!(a > 0.0 && a.is_finite(), "{a}");
        assert!(
            c.j_cap(v, a).abs() < 1e-9 * m.limits[4].j,
            "{}",
            c.j_cap(v, a)
        );
        assert!(c.j_cap(v, 0.99 * a) > 0.0);
        assert!(c.j_cap(v, 1.01 * a) < 0.0);
        // A line has no curvature: any acceleration leaves jerk.
        let mut line = [[0.0; 4]; 5];
        line[0][1] = 1.0;
        let c = Caps::new(&Local::from_derivs(&line), &m);
        assert_eq!(c.a_for_jerk(v), f64::INFINITY);
        // Past the speed where q_sss·v³ alone uses up C's J: none.
        let c = Caps::new(&Local::from_derivs(&d), &m);
        let v_j = (m.limits[4].j * LIMIT_USE / 18.0).cbrt();
        assert_eq!(c.a_for_jerk(1.01 * v_j), 0.0);
    }

    /// Above the Equation-6 bound there is no room at a = 0 (negative caps).
    #[test]
    fn above_equation_6_the_caps_are_negative() {
        let m = m();
        let mut d = [[0.0; 4]; 5];
        d[0][1] = 1.0;
        d[4] = [0.0, 0.0, 3.0, 0.0];
        let l = Local::from_derivs(&d);
        let eq6 = (m.limits[4].a / 3.0).sqrt();
        assert!(l.a_cap(&m, 0.99 * eq6) > 0.0);
        assert!(l.a_cap(&m, 1.01 * eq6) < 0.0);
    }
}
