//! The two rotary axes of a 5-axis machine as a chain, and the orientation kinematics of
//! any such pair in closed form.
//!
//! # The model
//!
//! A machine has two rotary axes. Each turns either the **table** (the part) or the
//! **head** (the tool), about a direction given at zero (every axis at 0) as a unit vector
//! in the machine frame. Listed along the chain **from the part to the tool**, the first
//! axis is the one next to the part — the table that carries the part, or on a head-head
//! machine the head axis fixed to the frame — and the second is the one next to the tool.
//! Table axes come before head axes. The first is the **pole axis** (slot
//! [`crate::Axis::C`], whatever its letter): where the tool axis lies along it, turning it
//! does not change the tool axis. The second tilts the tool relative to it (slot
//! [`crate::Axis::Primary`]).
//!
//! **Senses** (ISO 841): a positive value of an axis with `sense = +1` turns the tool
//! relative to the part right-handed about the axis direction — a head axis turns the
//! head that way, a table axis turns the table the other way. `sense = −1` reverses it.
//!
//! With `a`, `b` the directions of the pole axis and the tilting axis at zero, `t0` the
//! tool direction at zero (from the tip towards the spindle), `sc`, `sp` the senses and
//! `R(u, θ)` the right-handed rotation about `u`, the tool axis in the part frame is, for
//! every layout (table-table, head-table, head-head):
//!
//! ```text
//! o_wp = R(a, sc·C) · R(b, sp·P) · t0
//! ```
//!
//! (a table axis rotates the part by −θ, so the tool relative to the part by +θ; composing
//! the chain from the part to the tool gives this one formula). The built-in machines are
//! `a = ẑ`, `b = x̂` (A) or `ŷ` (B), `t0 = ẑ`: G16 eq. 1.
//!
//! # Inverse kinematics (closed form)
//!
//! Turning about `a` keeps the angle to `a`, so P is found first: the tool at zero turned
//! about `b`, `v(β) = R(b, β)·t0`, must make the angle `γ = ∠(a, o)` with `a`. In the
//! spherical triangle of the unit vectors `b`, `a`, `v` the sides are `δ = ∠(b, a)`,
//! `τ = ∠(b, t0)` and `γ`, and the angle at `b` is `ψ = β − β_a`, where `β_a` is the
//! azimuth of `a` about `b` measured from `t0`. The half-angle form of the spherical law of
//! cosines gives `ψ` accurately at the pole (`γ → |δ − τ|`), where `acos` would not:
//!
//! ```text
//! tan²(ψ/2) = sin((γ − (δ − τ))/2)·sin((γ + (δ − τ))/2) / ( sin((δ + τ − γ)/2)·sin((δ + τ + γ)/2) )
//! β = β_a ± ψ,   P = sp·β
//! C = sc·atan2( a·(v⊥ × o⊥), v⊥·o⊥ )    v⊥ = v − (a·v)a, o⊥ = o − (a·o)a  (v turned onto o)
//! ```
//!
//! Two solutions, equal where `ψ = 0` or `π`. The orientations the pair can reach are those
//! with `|δ − τ| ≤ γ ≤ min(δ + τ, 2π − δ − τ)`; the pole (`o = a`) is reachable when
//! `δ = τ`, with P there `sp·β_a` (0 for every layout whose tool at zero lies along the pole
//! axis). For the built-in form the two solutions are `(P, C)` and `(−P, C + 180°)`.

use crate::tolerances::{POLE_SIN_TOL, REACH_TOL_RAD};
use crate::vec3::{cross, dot, norm, scale, sub};
use serde::{Deserialize, Serialize};

/// What a rotary axis turns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Carrier {
    /// The table: the axis turns the part.
    Table,
    /// The head: the axis turns the tool.
    Head,
}

/// One rotary axis of the chain, apart from its sense, range and limits (which live in the
/// machine's slot fields, [`crate::Machine::primary_sense`] and the others).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotaryAxis {
    /// Its address in NC words (`'A'`, `'B'`, `'C'`, or another letter the controller
    /// uses, see [`crate::machine::ROTARY_LETTERS`]).
    pub letter: char,
    /// Whether it turns the table or the head.
    pub carrier: Carrier,
    /// Its direction with every axis at zero, a unit vector in the machine frame.
    pub direction: [f64; 3],
}

/// The two rotary axes in their slots, and the tool direction at zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotaries {
    /// The axis next to the tool in the chain, which tilts the tool away from the pole
    /// (slot [`crate::Axis::Primary`]).
    pub primary: RotaryAxis,
    /// The axis next to the part in the chain: the pole axis (slot [`crate::Axis::C`]).
    pub c: RotaryAxis,
    /// The tool direction with every axis at zero, from the tip towards the spindle, a unit
    /// vector in the machine frame (`[0, 0, 1]` on a vertical machine).
    pub tool_direction: [f64; 3],
}

/// The layout of a machine, from what its two rotary axes turn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// Both axes turn the table (trunnion, cradle, nutating table).
    #[serde(alias = "table-table")]
    TableTable,
    /// The pole axis turns the table, the tilting axis the head (swivel head over a rotary
    /// table).
    #[serde(alias = "head-table")]
    HeadTable,
    /// Both axes turn the head (fork head).
    #[serde(alias = "head-head")]
    HeadHead,
}

impl Rotaries {
    /// A table-table machine: C turns the table about `ẑ`, the tilting axis (`'A'` about
    /// `x̂` or `'B'` about `ŷ`) carries it; the tool along `ẑ`. Today's `[primary]`/`[c]`
    /// machine files mean this.
    pub fn table_table(primary_letter: char) -> Rotaries {
        let direction = if primary_letter == 'B' {
            [0.0, 1.0, 0.0]
        } else {
            [1.0, 0.0, 0.0]
        };
        Rotaries {
            primary: RotaryAxis {
                letter: primary_letter,
                carrier: Carrier::Table,
                direction,
            },
            c: RotaryAxis {
                letter: 'C',
                carrier: Carrier::Table,
                direction: [0.0, 0.0, 1.0],
            },
            tool_direction: [0.0, 0.0, 1.0],
        }
    }

    /// The layout, from the carriers.
    pub fn layout(&self) -> Layout {
        match (self.c.carrier, self.primary.carrier) {
            (Carrier::Table, Carrier::Table) => Layout::TableTable,
            (Carrier::Head, Carrier::Head) => Layout::HeadHead,
            _ => Layout::HeadTable,
        }
    }
}

/// The angle between two vectors, radians in [0, π], accurate near 0 and π.
pub(crate) fn angle_rad(a: [f64; 3], b: [f64; 3]) -> f64 {
    norm(cross(a, b)).atan2(dot(a, b))
}

/// Which coordinate axis `u` is exactly, with its sign: `Some((k, ±1))` for `±e_k`.
pub(crate) fn coordinate_axis(u: [f64; 3]) -> Option<(usize, f64)> {
    let k = if u[0] != 0.0 {
        0
    } else if u[1] != 0.0 {
        1
    } else {
        2
    };
    let others_zero = (0..3).all(|i| i == k || u[i] == 0.0);
    (others_zero && u[k].abs() == 1.0).then_some((k, u[k]))
}

/// `R(u, θ)·v` for a unit axis `u` and an angle in degrees, right-handed about `u`.
///
/// About a coordinate axis the rotation is written out (exact zeros, the same operations as
/// the table-table formulas it replaces), otherwise Rodrigues' formula
/// `v cos θ + (u × v) sin θ + u (u·v)(1 − cos θ)`.
pub(crate) fn rotate_deg(u: [f64; 3], angle_deg: f64, v: [f64; 3]) -> [f64; 3] {
    match coordinate_axis(u) {
        Some((k, sign)) => {
            let (s, c) = (sign * angle_deg).to_radians().sin_cos();
            match k {
                0 => [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]],
                1 => [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]],
                _ => [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]],
            }
        }
        None => {
            let (s, c) = angle_deg.to_radians().sin_cos();
            let uxv = cross(u, v);
            let k = dot(u, v) * (1.0 - c);
            std::array::from_fn(|i| v[i] * c + uxv[i] * s + u[i] * k)
        }
    }
}

/// One joint solution, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution {
    /// Primary angle (the tilting axis: A or B on the built-ins), degrees.
    pub p_deg: f64,
    /// C angle (the pole axis), degrees, in (−180, 180] before unwrapping.
    pub c_deg: f64,
}

/// The solutions of the inverse kinematics of one tool axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ik {
    /// Off the pole: two joint solutions (P, C), degrees, both wrapped to (−180°, 180°];
    /// the first has the larger P. They are equal where the orientation is on the border
    /// of what the pair reaches.
    Two([IkSolution; 2]),
    /// On the pole (`o` along the pole axis, within [`POLE_SIN_TOL`]) or on the opposite
    /// pole (`o` against it, `opposite = true`): C does not change the tool axis and is
    /// undefined; P is `p_deg`.
    Pole {
        /// The primary angle there, degrees in (−180°, 180°].
        p_deg: f64,
        /// Whether the tool points against the pole axis.
        opposite: bool,
    },
    /// The pair cannot turn the tool to this orientation (beyond [`REACH_TOL_RAD`]): its
    /// angle from the pole axis is `angle_deg`, and the pair reaches from `reach_deg.0`
    /// to `reach_deg.1`.
    Unreachable {
        /// Angle between the tool axis and the pole axis, degrees.
        angle_deg: f64,
        /// The angles from the pole axis the pair reaches, degrees (min, max).
        reach_deg: (f64, f64),
    },
    /// The tool axis is zero or not finite.
    Invalid,
}

/// The fixed quantities of a pair's inverse kinematics (module docs).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PairGeometry {
    a: [f64; 3],
    b: [f64; 3],
    /// `b·t0`.
    bt: f64,
    /// `|t0 − (b·t0) b| = sin τ`.
    rt: f64,
    /// Unit `t0 − (b·t0) b` and `b × e1`: the basis of the circle `v(β)` runs on.
    e1: [f64; 3],
    e2: [f64; 3],
    /// `∠(b, a)`, `∠(b, t0)`, radians.
    delta: f64,
    tau: f64,
    /// Azimuth of `a` about `b` from `e1`, radians.
    beta_a: f64,
}

impl PairGeometry {
    /// The geometry of `rot`. The directions must be unit vectors, `b` neither along `a`
    /// nor along `t0` (checked when a machine is read).
    pub(crate) fn new(rot: &Rotaries) -> PairGeometry {
        let a = rot.c.direction;
        let b = rot.primary.direction;
        let t0 = rot.tool_direction;
        let bt = dot(b, t0);
        let perp = sub(t0, scale(b, bt));
        let rt = norm(perp);
        let e1 = scale(perp, 1.0 / rt);
        let e2 = cross(b, e1);
        PairGeometry {
            a,
            b,
            bt,
            rt,
            e1,
            e2,
            delta: angle_rad(b, a),
            tau: angle_rad(b, t0),
            beta_a: dot(a, e2).atan2(dot(a, e1)),
        }
    }

    /// `v(β) = R(b, β)·t0`, β in radians.
    fn v(&self, beta_rad: f64) -> [f64; 3] {
        let (s, c) = beta_rad.sin_cos();
        std::array::from_fn(|i| self.bt * self.b[i] + self.rt * (c * self.e1[i] + s * self.e2[i]))
    }

    /// The angles from the pole axis the pair reaches, radians (min, max).
    pub(crate) fn reach_rad(&self) -> (f64, f64) {
        let two_pi = 2.0 * std::f64::consts::PI;
        (
            (self.delta - self.tau).abs(),
            (self.delta + self.tau).min(two_pi - self.delta - self.tau),
        )
    }

    /// ψ ∈ [0, π] for an angle `gamma` from the pole axis, or `None` when out of reach.
    fn psi(&self, gamma: f64) -> Option<f64> {
        let (lo, hi) = self.reach_rad();
        if gamma < lo - REACH_TOL_RAD || gamma > hi + REACH_TOL_RAD {
            return None;
        }
        // δ − τ and δ + τ first: at the pole γ is tiny and δ − τ is 0, and γ − δ + τ
        // would lose γ's digits to δ.
        let (dm, dp) = (self.delta - self.tau, self.delta + self.tau);
        let n1 = ((gamma - dm) / 2.0).sin() * ((gamma + dm) / 2.0).sin();
        let n2 = ((dp - gamma) / 2.0).sin() * ((dp + gamma) / 2.0).sin();
        Some(2.0 * n1.max(0.0).sqrt().atan2(n2.max(0.0).sqrt()))
    }

    /// The two β (radians) at angle `gamma` from the pole axis: `β_a + ψ`, `β_a − ψ`.
    fn betas(&self, gamma: f64) -> Option<[f64; 2]> {
        self.psi(gamma)
            .map(|psi| [self.beta_a + psi, self.beta_a - psi])
    }

    /// The rotation about `a` (radians) that takes `v` onto `o`: the signed angle between
    /// their components across `a`, formed first (near the pole they are tiny, and
    /// `v·o − (a·v)(a·o)` would be lost to rounding).
    fn alpha(&self, v: [f64; 3], o: [f64; 3]) -> f64 {
        let a = self.a;
        let v_perp = sub(v, scale(a, dot(a, v)));
        let o_perp = sub(o, scale(a, dot(a, o)));
        dot(a, cross(v_perp, o_perp)).atan2(dot(v_perp, o_perp))
    }
}

/// Tool axis in the part frame, `R(a, sc·C)·R(b, sp·P)·t0`, for any pair (module docs).
pub(crate) fn forward_general(
    rot: &Rotaries,
    sp: f64,
    sc: f64,
    p_deg: f64,
    c_deg: f64,
) -> [f64; 3] {
    let v = rotate_deg(rot.primary.direction, sp * p_deg, rot.tool_direction);
    rotate_deg(rot.c.direction, sc * c_deg, v)
}

/// `(o, ∂o/∂P, ∂o/∂C)`, the derivatives per degree: `∂o/∂P = sp·R(a, sc·C)·(b × v)·π/180`,
/// `∂o/∂C = sc·(a × o)·π/180`, with `v = R(b, sp·P)·t0`.
pub(crate) fn jacobian_general(
    rot: &Rotaries,
    sp: f64,
    sc: f64,
    p_deg: f64,
    c_deg: f64,
) -> [[f64; 3]; 3] {
    let k = std::f64::consts::PI / 180.0;
    let a = rot.c.direction;
    let v = rotate_deg(rot.primary.direction, sp * p_deg, rot.tool_direction);
    let o = rotate_deg(a, sc * c_deg, v);
    let dv = cross(rot.primary.direction, v);
    let dp = rotate_deg(a, sc * c_deg, dv);
    [o, scale(dp, sp * k), scale(cross(a, o), sc * k)]
}

/// The inverse kinematics of any pair in closed form (module docs).
pub(crate) fn inverse_general(rot: &Rotaries, sp: f64, sc: f64, o_wp: [f64; 3]) -> Ik {
    let m = o_wp[0].abs().max(o_wp[1].abs()).max(o_wp[2].abs());
    if !(m > 0.0 && o_wp.iter().all(|x| x.is_finite())) {
        return Ik::Invalid;
    }
    let o = scale(o_wp, 1.0 / m);
    let o = scale(o, 1.0 / norm(o));
    let g = PairGeometry::new(rot);
    let sin_gamma = norm(cross(g.a, o));
    let gamma = sin_gamma.atan2(dot(g.a, o));
    let to_p = |beta: f64| crate::angles::wrap_deg(sp * beta.to_degrees());
    let Some(betas) = g.betas(gamma) else {
        let (lo, hi) = g.reach_rad();
        return Ik::Unreachable {
            angle_deg: gamma.to_degrees(),
            reach_deg: (lo.to_degrees(), hi.to_degrees()),
        };
    };
    if sin_gamma < POLE_SIN_TOL {
        return Ik::Pole {
            p_deg: to_p(betas[0]),
            opposite: gamma > std::f64::consts::FRAC_PI_2,
        };
    }
    let mut sols = betas.map(|beta| IkSolution {
        p_deg: to_p(beta),
        c_deg: crate::angles::wrap_deg(sc * g.alpha(g.v(beta), o).to_degrees()),
    });
    if sols[1].p_deg > sols[0].p_deg {
        sols.swap(0, 1);
    }
    Ik::Two(sols)
}

/// A pole of a pair: the primary angle, degrees, where the tool lies along the pole axis
/// line — with it (`opposite = false`) or against it (`opposite = true`). Turning the pole
/// axis does not change the tool axis at either.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoleAt {
    /// The primary angle there, degrees.
    pub p_deg: f64,
    /// Whether the tool there points against the pole axis' direction.
    pub opposite: bool,
}

/// The pole a machine's programs pass near, of the two a pair may reach: the tool along the
/// pole axis (`γ = 0`, reachable where `δ = τ`) and the tool against it (`γ = π`, reachable
/// where `δ + τ = π`). The first whose primary angle lies within `range_deg` (a turn added
/// where that brings it in; `γ = 0` first), else the first the geometry reaches (its P
/// wrapped to (−180°, 180°]), else `None`: the pair has no pole.
///
/// A pair whose tool at zero points against the pole axis (`tool_direction = [0, 0, −1]`
/// under a C table along `+Z`: the spindle below the tip) has its `γ = 0` pole at P = 180°,
/// usually beyond the range, and the `γ = π` one at P = 0°, where its programs are.
pub(crate) fn pole_general(rot: &Rotaries, sp: f64, range_deg: (f64, f64)) -> Option<PoleAt> {
    let g = PairGeometry::new(rot);
    let poles: Vec<PoleAt> = [(0.0, false), (std::f64::consts::PI, true)]
        .into_iter()
        .filter_map(|(gamma, opposite)| {
            g.betas(gamma).map(|b| PoleAt {
                p_deg: crate::angles::wrap_deg(sp * b[0].to_degrees()),
                opposite,
            })
        })
        .collect();
    let (lo, hi) = range_deg;
    let in_range = |pole: &PoleAt| {
        let turns = ((lo - pole.p_deg) / 360.0).ceil();
        let p = pole.p_deg + 360.0 * turns;
        (p <= hi).then_some(PoleAt { p_deg: p, ..*pole })
    };
    poles
        .iter()
        .find_map(in_range)
        .or_else(|| poles.first().copied())
}

/// The angle between the tool turned by the primary axis alone, `v = R(b, sp·P)·t0`, and
/// the pole axis' direction (`opposite = false`) or its reverse (`opposite = true`),
/// degrees in [0, 180]; C turns the tool about the pole axis at this constant angle.
pub(crate) fn pole_tilt_general(rot: &Rotaries, sp: f64, p_deg: f64, opposite: bool) -> f64 {
    let v = rotate_deg(rot.primary.direction, sp * p_deg, rot.tool_direction);
    let pole = if opposite {
        scale(rot.c.direction, -1.0)
    } else {
        rot.c.direction
    };
    angle_rad(pole, v).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{SplitMix64, all_kinds, pair_machine, unit};
    use crate::{
        IkSolution, Machine, forward, forward_jacobian, inverse, solve_ik, unwrap_near_deg,
        wrap_deg,
    };

    /// Rodrigues' formula written independently: `v cos θ + (u × v) sin θ + u (u·v)(1 − cos θ)`.
    fn rodrigues(u: [f64; 3], angle_deg: f64, v: [f64; 3]) -> [f64; 3] {
        let (s, c) = angle_deg.to_radians().sin_cos();
        let uv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        let x = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        std::array::from_fn(|i| v[i] * c + x[i] * s + u[i] * uv * (1.0 - c))
    }

    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        norm(sub(a, b))
    }

    #[test]
    fn rotation_about_coordinate_axes_is_right_handed_and_is_rodrigues() {
        // 90° about x takes ŷ to ẑ, about y takes ẑ to x̂, about z takes x̂ to ŷ.
        let cases = [
            ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
            ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ];
        let v = [0.3, -0.4, 0.866];
        for (u, from, to) in cases {
            assert!(dist(rotate_deg(u, 90.0, from), to) < 1e-15, "{u:?}");
            for angle in [-170.0, -33.3, 0.0, 12.5, 90.0, 180.0] {
                for sign in [1.0, -1.0] {
                    let u = scale(u, sign);
                    let want = rodrigues(u, angle, v);
                    assert!(dist(rotate_deg(u, angle, v), want) < 1e-15, "{u:?} {angle}");
                }
            }
        }
        // Off the coordinate axes, Rodrigues itself.
        let u = unit([1.0, 2.0, -0.5]);
        assert!(dist(rotate_deg(u, 33.0, v), rodrigues(u, 33.0, v)) < 1e-15);
    }

    #[test]
    fn coordinate_axes_are_recognised_exactly() {
        assert_eq!(coordinate_axis([0.0, 0.0, 1.0]), Some((2, 1.0)));
        assert_eq!(coordinate_axis([0.0, -1.0, 0.0]), Some((1, -1.0)));
        assert_eq!(coordinate_axis([-1.0, 0.0, 0.0]), Some((0, -1.0)));
        assert_eq!(coordinate_axis([0.0, 1e-17, 1.0]), None);
        assert_eq!(coordinate_axis([0.0, 0.0, 0.5]), None);
        assert_eq!(coordinate_axis([0.0, 0.0, 0.0]), None);
    }

    /// The standard form through the general formulas: the built-ins' pair with its axes
    /// written as directions the standard-form test does not recognise (a zero that is not
    /// exactly zero is not possible, so the general code is called directly).
    #[test]
    fn general_formulas_agree_with_the_standard_form() {
        let mut rng = SplitMix64(0x6e6e);
        for m in all_kinds() {
            let (sp, sc) = (m.primary_sense, m.c_sense);
            for n in 0..3000 {
                let p = if n % 5 == 0 {
                    rng.pick(&[0.0, 1e-9, -1e-7, 90.0, -90.0, 180.0])
                } else {
                    rng.uniform(-180.0, 180.0)
                };
                let c = rng.uniform(-400.0, 400.0);
                let o = forward(&m, p, c);
                assert!(dist(forward_general(&m.rotary, sp, sc, p, c), o) < 1e-15);
                let j = forward_jacobian(&m, p, c);
                let g = jacobian_general(&m.rotary, sp, sc, p, c);
                for r in 0..3 {
                    assert!(dist(j[r], g[r]) < 1e-15, "{p} {c} row {r}");
                }
                match (inverse(&m, o), inverse_general(&m.rotary, sp, sc, o)) {
                    (None, Ik::Pole { p_deg, .. }) => {
                        assert!(p_deg == 0.0 || p_deg.abs() == 180.0, "{p_deg}")
                    }
                    (Some(want), Ik::Two(got)) => {
                        let c_tol = 1e-12 / p.to_radians().sin().abs();
                        for k in 0..2 {
                            assert!((want[k].p_deg - got[k].p_deg).abs() < 1e-12, "{p} {c}");
                            let dc = wrap_deg(want[k].c_deg - got[k].c_deg).abs();
                            assert!(dc < c_tol.max(1e-12), "{p} {c}: {want:?} {got:?}");
                        }
                    }
                    other => panic!("P={p} C={c}: {other:?}"),
                }
                // The tilt from the pole is |P|.
                let tilt = pole_tilt_general(&m.rotary, sp, p, false);
                assert!((tilt - wrap_deg(p).abs()).abs() < 1e-12, "{p}: {tilt}");
            }
            let pole = pole_general(&m.rotary, sp, m.primary_range_deg);
            assert_eq!(
                pole,
                Some(PoleAt {
                    p_deg: 0.0,
                    opposite: false
                })
            );
        }
    }

    /// A random pair: directions far enough from parallel that the conditioning is bounded
    /// (the exactly degenerate ones are refused when a machine is read).
    fn random_pair(rng: &mut SplitMix64) -> Machine {
        let mut dir = || loop {
            let v = [
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            ];
            if norm(v) > 0.2 {
                return unit(v);
            }
        };
        loop {
            let (a, b, t0) = (dir(), dir(), dir());
            if angle_rad(a, b).sin() > 0.1 && angle_rad(b, t0).sin() > 0.1 {
                let sp = if rng.next_u64() % 2 == 0 { 1.0 } else { -1.0 };
                let sc = if rng.next_u64() % 2 == 0 { 1.0 } else { -1.0 };
                return pair_machine(a, b, t0, sp, sc);
            }
        }
    }

    /// A pair whose pole is reachable: the tool at zero along the pole axis.
    fn random_pole_pair(rng: &mut SplitMix64) -> Machine {
        let mut m = random_pair(rng);
        m.rotary.tool_direction = m.rotary.c.direction;
        m
    }

    /// The angles from the pole axis a pair reaches, found by sampling β (independent of
    /// the closed form): (min, max), radians.
    fn sampled_reach(m: &Machine) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi: f64 = 0.0;
        for k in 0..=36_000 {
            let v = rodrigues(
                m.rotary.primary.direction,
                f64::from(k) * 0.01,
                m.rotary.tool_direction,
            );
            let g = angle_rad(m.rotary.c.direction, v);
            lo = lo.min(g);
            hi = hi.max(g);
        }
        (lo, hi)
    }

    /// FK(IK(o)) = o for both solutions, and one of them is the (P, C) o came from, on
    /// random pairs, random senses and random joint values.
    #[test]
    fn fk_of_ik_is_the_identity_on_random_pairs() {
        let mut rng = SplitMix64(0xab_cdef);
        let mut checked = 0;
        for _ in 0..400 {
            let m = if rng.next_u64() % 2 == 0 {
                random_pair(&mut rng)
            } else {
                random_pole_pair(&mut rng)
            };
            for _ in 0..50 {
                let p = rng.uniform(-180.0, 180.0);
                let c = rng.uniform(-400.0, 400.0);
                let o = forward(&m, p, c);
                let sols = match solve_ik(&m, o) {
                    Ik::Two(s) => s,
                    Ik::Pole { p_deg, .. } => {
                        assert!(norm(cross(m.rotary.c.direction, o)) < 1e-9);
                        assert!(dist(forward(&m, p_deg, c), o) < 1e-9);
                        continue;
                    }
                    other => panic!("{:?} P={p} C={c}: {other:?}", m.rotary),
                };
                assert!(sols[0].p_deg >= sols[1].p_deg);
                for s in sols {
                    assert!(-180.0 < s.p_deg && s.p_deg <= 180.0, "{s:?}");
                    assert!(-180.0 < s.c_deg && s.c_deg <= 180.0, "{s:?}");
                    let back = forward(&m, s.p_deg, s.c_deg);
                    assert!(dist(back, o) < 1e-10, "{:?} P={p} C={c}: {s:?}", m.rotary);
                }
                // Away from the pole (C defined) and from the border of the reach (the two
                // solutions distinct), one solution is (P, C) itself.
                let tilt = m.pole_tilt_deg(p);
                let gap = wrap_deg(sols[0].p_deg - sols[1].p_deg).abs();
                if tilt > 0.5 && tilt < 179.5 && gap > 1e-3 {
                    let hit = sols.iter().any(|s| {
                        wrap_deg(s.p_deg - p).abs() < 1e-7 && wrap_deg(s.c_deg - c).abs() < 1e-7
                    });
                    assert!(hit, "{:?} P={p} C={c}: {sols:?}", m.rotary);
                    checked += 1;
                }
            }
        }
        assert!(checked > 10_000, "{checked}");
    }

    /// Every tool axis is classified right: two solutions that give it back, the pole, or
    /// out of reach — against a reach found by sampling.
    #[test]
    fn ik_classifies_random_tool_axes_against_a_sampled_reach() {
        let mut rng = SplitMix64(77);
        let (mut two, mut out) = (0, 0);
        for _ in 0..60 {
            let m = random_pair(&mut rng);
            let (lo, hi) = sampled_reach(&m);
            for _ in 0..200 {
                let o = unit([
                    rng.uniform(-1.0, 1.0),
                    rng.uniform(-1.0, 1.0),
                    rng.uniform(-1.0, 1.0),
                ]);
                let g = angle_rad(m.rotary.c.direction, o);
                match solve_ik(&m, o) {
                    Ik::Two(sols) => {
                        for s in sols {
                            assert!(dist(forward(&m, s.p_deg, s.c_deg), o) < 1e-10);
                        }
                        assert!(g >= lo - 1e-6 && g <= hi + 1e-6, "{g} in [{lo}, {hi}]");
                        two += 1;
                    }
                    Ik::Unreachable {
                        angle_deg,
                        reach_deg,
                    } => {
                        assert!((angle_deg - g.to_degrees()).abs() < 1e-9);
                        assert!(g < lo - 1e-9 || g > hi + 1e-9, "{g} in [{lo}, {hi}]");
                        assert!((reach_deg.0 - lo.to_degrees()).abs() < 1e-3);
                        assert!((reach_deg.1 - hi.to_degrees()).abs() < 1e-3);
                        out += 1;
                    }
                    other => panic!("{other:?}"),
                }
            }
        }
        assert!(two > 1000 && out > 1000, "{two} {out}");
    }

    /// The Jacobian against central finite differences on random pairs.
    #[test]
    fn jacobian_matches_finite_differences_on_random_pairs() {
        let mut rng = SplitMix64(5);
        let h = 1e-6;
        for _ in 0..200 {
            let m = random_pair(&mut rng);
            let (p, c) = (rng.uniform(-180.0, 180.0), rng.uniform(-360.0, 360.0));
            let [o, dp, dc] = forward_jacobian(&m, p, c);
            assert!(dist(o, forward(&m, p, c)) < 1e-15);
            let np = scale(sub(forward(&m, p + h, c), forward(&m, p - h, c)), 0.5 / h);
            let nc = scale(sub(forward(&m, p, c + h), forward(&m, p, c - h)), 0.5 / h);
            assert!(dist(np, dp) < 1e-9, "{np:?} {dp:?}");
            assert!(dist(nc, dc) < 1e-9, "{nc:?} {dc:?}");
            // |∂o/∂C| per radian is the sine of the tilt from the pole.
            let tilt = m.pole_tilt_deg(p).to_radians();
            assert!((norm(dc).to_degrees() - tilt.sin()).abs() < 1e-12);
        }
    }

    /// The other solution gives the same tool axis; the tilt from the pole does not depend
    /// on C; the pole is where the primary puts the tool along the pole axis.
    #[test]
    fn other_solution_tilt_and_pole_on_random_pairs() {
        let mut rng = SplitMix64(11);
        for _ in 0..300 {
            let m = random_pole_pair(&mut rng);
            let (p, c) = (rng.uniform(-180.0, 180.0), rng.uniform(-180.0, 180.0));
            let o = forward(&m, p, c);
            let s = m.other_solution(p, c).unwrap();
            assert!(dist(forward(&m, s.p_deg, s.c_deg), o) < 1e-10);
            assert!(wrap_deg(s.c_deg - c - 180.0).abs() <= 180.0);
            let tilt = m.pole_tilt_deg(p);
            assert!((tilt - angle_rad(m.pole_direction(), o).to_degrees()).abs() < 1e-9);
            let pole = m.pole_p_deg().expect("tool at zero along the pole axis");
            assert!(dist(forward(&m, pole, c), m.pole_direction()) < 1e-12);
            assert!(m.pole_tilt_deg(pole) < 1e-9);
        }
    }

    /// The degenerate cases on purpose: exactly on the pole, the opposite pole, axes at 90°
    /// in a rotated frame, a 45° nutating axis on the border of its reach.
    #[test]
    fn degenerate_cases_on_purpose() {
        // Axes at 90°, not along the coordinate axes: the pair is the standard form turned
        // as a whole, so its solutions are (P, C) and (−P, C + 180°) and the pole is P = 0.
        let a = unit([1.0, 1.0, 1.0]);
        let b = unit([1.0, -1.0, 0.0]);
        let m = pair_machine(a, b, a, 1.0, 1.0);
        assert!(m.standard_form().is_none());
        for (p, c) in [(30.0, 40.0), (1e-6, -179.0), (-90.0, 180.0), (179.0, 10.0)] {
            let Ik::Two(s) = solve_ik(&m, forward(&m, p, c)) else {
                panic!("{p} {c}")
            };
            let (pos, neg) = if p > 0.0 { (s[0], s[1]) } else { (s[1], s[0]) };
            let c_tol = 1e-12 / p.to_radians().sin().abs();
            assert!((pos.p_deg - p).abs() < 1e-9 && wrap_deg(pos.c_deg - c).abs() < c_tol);
            assert!((neg.p_deg + p).abs() < 1e-9);
            assert!(wrap_deg(neg.c_deg - c - 180.0).abs() < c_tol, "{s:?}");
        }
        // Exactly on the pole and the opposite pole.
        assert_eq!(
            solve_ik(&m, a),
            Ik::Pole {
                p_deg: 0.0,
                opposite: false
            }
        );
        match solve_ik(&m, scale(a, -1.0)) {
            Ik::Pole { p_deg, opposite } => assert!(opposite && p_deg.abs() == 180.0),
            other => panic!("{other:?}"),
        }
        assert!(inverse(&m, a).is_none());
        // 1e-9 rad off the pole is not the pole: two solutions, tilt ±1e-9 rad (to the
        // relative accuracy a unit vector holds its 1e-9 across a: 1e-16 / 1e-9).
        let near = rotate_deg(b, 1e-9f64.to_degrees(), a);
        let Ik::Two(s) = solve_ik(&m, near) else {
            panic!()
        };
        let want = 1e-9f64.to_degrees();
        assert!((s[0].p_deg - want).abs() < 1e-6 * want, "{s:?}");
        assert!((s[1].p_deg + want).abs() < 1e-6 * want, "{s:?}");

        // 45°: a nutating table, B at 45° between +Y and +Z carrying C. It reaches from the
        // pole (B = 0) to the horizontal (B = 180°), and no further.
        let m = pair_machine(
            [0.0, 0.0, 1.0],
            unit([0.0, 1.0, 1.0]),
            [0.0, 0.0, 1.0],
            1.0,
            1.0,
        );
        assert_eq!(m.pole_p_deg(), Some(0.0));
        assert!(dist(forward(&m, 180.0, 0.0), [0.0, 1.0, 0.0]) < 1e-15);
        assert!(
            dist(
                forward(&m, 90.0, 0.0),
                [std::f64::consts::FRAC_1_SQRT_2, 0.5, 0.5]
            ) < 1e-15
        );
        // Horizontal: the border, one posture (B = 180° twice).
        for c in [0.0, 33.0, -150.0] {
            let o = forward(&m, 180.0, c);
            let Ik::Two(s) = solve_ik(&m, o) else {
                panic!("{c}")
            };
            assert!(
                s.iter().all(|s| wrap_deg(s.p_deg - 180.0).abs() < 1e-6),
                "{s:?}"
            );
            assert!(
                s.iter()
                    .all(|s| dist(forward(&m, s.p_deg, s.c_deg), o) < 1e-12)
            );
        }
        // Below the horizontal: out of reach.
        match solve_ik(&m, unit([1.0, 0.0, -0.01])) {
            Ik::Unreachable { reach_deg, .. } => {
                assert!(reach_deg.0.abs() < 1e-12 && (reach_deg.1 - 90.0).abs() < 1e-12)
            }
            other => panic!("{other:?}"),
        }
        assert!(
            inverse(&m, unit([1.0, 0.0, -0.01])).unwrap()[0]
                .p_deg
                .is_nan()
        );
        // A sweep through the range: round trips, and (B, C) is one of the two.
        for k in 1..180 {
            let (p, c) = (f64::from(k), f64::from(k) * 7.0 - 600.0);
            let Ik::Two(s) = solve_ik(&m, forward(&m, p, c)) else {
                panic!("{p}")
            };
            assert!(
                s.iter().any(|s| (s.p_deg - p).abs() < 1e-9
                    && (unwrap_near_deg(s.c_deg, c) - c).abs() < 1e-9)
            );
            // The other is (−B, C + something): mirror image in the plane of b and the pole.
            assert!(s.iter().any(|s| (s.p_deg + p).abs() < 1e-9), "{s:?}");
        }
    }

    #[test]
    fn invalid_tool_axes_are_not_the_pole() {
        let m = pair_machine(
            [0.0, 0.0, 1.0],
            unit([0.0, 1.0, 1.0]),
            [0.0, 0.0, 1.0],
            1.0,
            1.0,
        );
        for o in [[0.0; 3], [f64::NAN, 0.0, 1.0], [0.0, f64::INFINITY, 1.0]] {
            assert_eq!(solve_ik(&m, o), Ik::Invalid);
            assert!(inverse(&m, o).unwrap()[0].p_deg.is_nan());
        }
        // Huge but finite: scaled first.
        let Ik::Two(s) = solve_ik(&m, [1e300, 0.0, 1e300]) else {
            panic!()
        };
        assert!(
            s.iter()
                .all(|s| dist(forward(&m, s.p_deg, s.c_deg), unit([1.0, 0.0, 1.0])) < 1e-12)
        );
        let _ = IkSolution {
            p_deg: 0.0,
            c_deg: 0.0,
        };
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        fn direction() -> impl Strategy<Value = [f64; 3]> {
            (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0)
                .prop_filter("not near zero", |(x, y, z)| norm([*x, *y, *z]) > 0.2)
                .prop_map(|(x, y, z)| unit([x, y, z]))
        }

        proptest! {
            /// FK(IK(o)) = o for both solutions: random pair, random senses, random reachable
            /// tool axis (made by FK, so reachable); one solution is the one o came from.
            #[test]
            fn fk_of_ik_round_trip(
                a in direction(), b in direction(), t0 in direction(),
                sp in proptest::sample::select(vec![1.0, -1.0]),
                sc in proptest::sample::select(vec![1.0, -1.0]),
                p in -180.0f64..180.0, c in -360.0f64..360.0,
                pole in any::<bool>(),
            ) {
                prop_assume!(angle_rad(a, b).sin() > 0.1 && angle_rad(b, t0).sin() > 0.1);
                let t0 = if pole { a } else { t0 };
                prop_assume!(angle_rad(b, t0).sin() > 0.1);
                let m = pair_machine(a, b, t0, sp, sc);
                let o = forward(&m, p, c);
                match solve_ik(&m, o) {
                    Ik::Two(sols) => {
                        for s in sols {
                            prop_assert!(dist(forward(&m, s.p_deg, s.c_deg), o) < 1e-10);
                        }
                        let tilt = m.pole_tilt_deg(p);
                        let gap = wrap_deg(sols[0].p_deg - sols[1].p_deg).abs();
                        if tilt > 0.5 && tilt < 179.5 && gap > 1e-3 {
                            prop_assert!(sols.iter().any(|s| wrap_deg(s.p_deg - p).abs() < 1e-7
                                && wrap_deg(s.c_deg - c).abs() < 1e-7), "{:?}", sols);
                        }
                    }
                    Ik::Pole { p_deg, .. } => {
                        prop_assert!(dist(forward(&m, p_deg, c), o) < 1e-9);
                    }
                    other => prop_assert!(false, "{:?}", other),
                }
            }
        }
    }
}
