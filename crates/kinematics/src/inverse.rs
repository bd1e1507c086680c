//! Inverse kinematics: tool axis → (primary, C) in degrees, both solutions, branch choice.
//!
//! Every machine: the closed form of [`crate::rotary`] ([`solve_ik`]). For the standard form
//! ([`crate::forward::StandardForm`], the built-ins) the written-out formulas below are
//! used, bit for bit what polepatch always computed; a test keeps the two equal. Off the
//! pole every unit tool axis `o_wp = (i, j, k)` the standard form reaches has exactly two
//! joint solutions:
//!
//! ```text
//! P1 = atan2(√(i² + j²), k) ∈ [0°, 180°]          (= acos k, but accurate near the pole)
//! A:  C1 = sc · atan2(sp·i, −sp·j)
//! B:  C1 = sc · atan2(sp·j,  sp·i)
//! (P2, C2) = (−P1, C1 + 180°)                      both C wrapped to (−180°, 180°]
//! ```
//!
//! On the pole (`|sin P| < POLE_SIN_TOL`, k ≈ ±1) C does not change the tool axis and is
//! undefined. k ≈ +1 is the singular pole of G16 and C17 (P = 0); k ≈ −1 (P = ±180°, the
//! tool pointing straight up at the table) is the same degeneracy, reported the same way
//! by [`inverse`] and resolved by [`inverse_path`] as P = ±180° with C held. On other pairs
//! the pole is the tool along the pole axis (the C slot), P there is
//! [`Machine::pole_p_deg`], and the two solutions are not in general (P, C) and
//! (−P, C + 180°) ([`Machine::other_solution`]).

pub use crate::angles::{unwrap_near_deg, wrap_deg};
use crate::forward::StandardForm;
use crate::machine::{Machine, PrimaryAxis};
pub use crate::rotary::IkSolution;
use crate::rotary::{Ik, PoleAt, inverse_general, pole_general, pole_tilt_general};
use crate::tolerances::POLE_SIN_TOL;

/// How [`inverse_path`] picks between the two solutions ((P, C) and (−P, C+180°) on the
/// built-ins).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchRule {
    /// The solution nearest to the previous point (max of |ΔP| and |ΔC| after unwrapping);
    /// the first point prefers the larger P (P ≥ 0 on the built-ins).
    Nearest,
    /// G16 Table 1: the solution whose C lies in [−90°, 90°] (on the built-ins the branch is
    /// chosen by the sign of j, which flips P near the pole); on other pairs the solution
    /// with the smaller |C|.
    DomainRule,
    /// Always the larger P (P ≥ 0 on the built-ins).
    PreferPositive,
    /// Always the smaller P (P ≤ 0 on the built-ins).
    PreferNegative,
}

/// Both solutions for a tool axis `o_wp`, any machine ([`crate::rotary`]); the pole, an
/// orientation the pair cannot reach and bad input each say so.
pub fn solve_ik(machine: &Machine, o_wp: [f64; 3]) -> Ik {
    match machine.standard_form() {
        Some(f) => match inverse_standard(f, o_wp) {
            Some(s) if s[0].p_deg.is_nan() => Ik::Invalid,
            Some(s) => Ik::Two(s),
            None => Ik::Pole {
                p_deg: if o_wp[2] < 0.0 { 180.0 } else { 0.0 },
                opposite: o_wp[2] < 0.0,
            },
        },
        None => inverse_general(
            &machine.rotary,
            machine.primary_sense,
            machine.c_sense,
            o_wp,
        ),
    }
}

/// Both solutions for a unit tool axis `o_wp`. Returns `None` on the pole (the tool along
/// the pole axis or against it, within [`crate::tolerances::POLE_SIN_TOL`]): C is undefined
/// there. The first solution has the larger P (P ≥ 0 on the built-ins). Both P lie within
/// (−180, 180].
///
/// `o_wp` need not be normalised. A zero or non-finite `o_wp` gives NaN solutions (never
/// `None`), so bad input is not mistaken for the pole; so does an orientation the machine's
/// pair cannot reach (only on pairs other than the standard form; [`solve_ik`] tells them
/// apart).
pub fn inverse(machine: &Machine, o_wp: [f64; 3]) -> Option<[IkSolution; 2]> {
    let nan = IkSolution {
        p_deg: f64::NAN,
        c_deg: f64::NAN,
    };
    match machine.standard_form() {
        Some(f) => inverse_standard(f, o_wp),
        None => match solve_ik(machine, o_wp) {
            Ik::Two(s) => Some(s),
            Ik::Pole { .. } => None,
            Ik::Unreachable { .. } | Ik::Invalid => Some([nan, nan]),
        },
    }
}

/// [`inverse`] of the standard form, written out (module docs).
fn inverse_standard(f: StandardForm, o_wp: [f64; 3]) -> Option<[IkSolution; 2]> {
    // Scaled to the largest component first: (f64::MAX, 0, f64::MAX) has a direction, but
    // its length overflows.
    let m = o_wp[0].abs().max(o_wp[1].abs()).max(o_wp[2].abs());
    let [i, j, k] = if m > 0.0 && m.is_finite() {
        [o_wp[0] / m, o_wp[1] / m, o_wp[2] / m]
    } else {
        o_wp
    };
    let h = i.hypot(j);
    let norm = h.hypot(k);
    if !(norm > 0.0 && norm.is_finite()) {
        let nan = IkSolution {
            p_deg: f64::NAN,
            c_deg: f64::NAN,
        };
        return Some([nan, nan]);
    }
    if h < POLE_SIN_TOL * norm {
        return None;
    }
    let p_deg = h.atan2(k).to_degrees();
    let (sp, sc) = (f.sp, f.sc);
    let theta_deg = match f.primary {
        PrimaryAxis::A => atan2_deg(sp * i, -sp * j),
        PrimaryAxis::B => atan2_deg(sp * j, sp * i),
    };
    let c_deg = wrap_deg(sc * theta_deg);
    Some([
        IkSolution { p_deg, c_deg },
        IkSolution {
            p_deg: -p_deg,
            c_deg: wrap_deg(c_deg + 180.0),
        },
    ])
}

impl Machine {
    /// The primary angle at which the tool lies along the pole axis line, degrees: 0 on the
    /// built-ins and on every pair whose tool at zero lies along the pole axis; `None` when
    /// the pair cannot reach the pole (then it has no singularity to patch). Of the two
    /// poles a pair may reach (the tool with the pole axis or against it), the one within
    /// the primary range (module docs of [`crate::rotary`], `pole_general`).
    pub fn pole_p_deg(&self) -> Option<f64> {
        match self.standard_form() {
            Some(_) => Some(0.0),
            None => self.pole().map(|p| p.p_deg),
        }
    }
    /// The pole of a pair that is not of the standard form ([`Machine::pole_p_deg`]).
    pub(crate) fn pole(&self) -> Option<PoleAt> {
        pole_general(&self.rotary, self.primary_sense, self.primary_range_deg)
    }
    /// The angle between the tool and the pole when the primary axis is at `p_deg`,
    /// degrees in [0, 180] (C turns the tool about the pole at this angle): `|P|` (folded
    /// into [0, 180]) on the built-ins; measured from the pole [`Machine::pole_p_deg`]
    /// names (the tool along the pole axis or against it). The distance from the pole is
    /// this angle; a change ΔC moves the tool by `2·asin(sin(tilt)·|sin(ΔC/2)|)`.
    pub fn pole_tilt_deg(&self, p_deg: f64) -> f64 {
        match self.standard_form() {
            Some(_) => wrap_deg(p_deg).abs(),
            None => {
                let opposite = self.pole().is_some_and(|p| p.opposite);
                pole_tilt_general(&self.rotary, self.primary_sense, p_deg, opposite)
            }
        }
    }
    /// The other joint solution of the tool axis at (`p_deg`, `c_deg`): `(−P, C + 180°)`
    /// on the standard form (exactly, C not wrapped); on other pairs the inverse kinematics'
    /// other solution with C unwrapped to within 180° of `c_deg + 180°`. On the pole, or
    /// where the two coincide, it is the same posture (P, C); `None` only for non-finite
    /// input.
    pub fn other_solution(&self, p_deg: f64, c_deg: f64) -> Option<IkSolution> {
        if !(p_deg.is_finite() && c_deg.is_finite()) {
            return None;
        }
        if self.standard_form().is_some() {
            return Some(IkSolution {
                p_deg: -p_deg,
                c_deg: c_deg + 180.0,
            });
        }
        let o = crate::forward::forward(self, p_deg, c_deg);
        match solve_ik(self, o) {
            Ik::Two(sols) => {
                // The one that is not (p, c): the farther in P, or in C when P ties.
                let far = |s: &IkSolution| {
                    (
                        wrap_deg(s.p_deg - p_deg).abs(),
                        wrap_deg(s.c_deg - c_deg).abs(),
                    )
                };
                let s = if far(&sols[0]) > far(&sols[1]) {
                    sols[0]
                } else {
                    sols[1]
                };
                Some(IkSolution {
                    p_deg: unwrap_near_deg(s.p_deg, p_deg),
                    c_deg: unwrap_near_deg(s.c_deg, c_deg + 180.0),
                })
            }
            _ => Some(IkSolution { p_deg, c_deg }),
        }
    }
}

/// atan2 in degrees, exact (0, ±90, 180) when an argument is zero, in (−180, 180].
fn atan2_deg(y: f64, x: f64) -> f64 {
    if y == 0.0 {
        if x < 0.0 { 180.0 } else { 0.0 }
    } else if x == 0.0 {
        if y > 0.0 { 90.0 } else { -90.0 }
    } else {
        wrap_deg(y.atan2(x).to_degrees())
    }
}

/// G16 Table 1, generalised to both senses and to B machines: index (0 or 1) of the
/// solution of [`inverse`] whose C, in (−180, 180], lies in [−90°, 90°]; at exactly ±90°
/// the one with P > 0 (index 0). On pairs other than the standard form: the solution with
/// the smaller |C| (index 0 on a tie), which is the same rule where the solutions are
/// (P, C) and (−P, C + 180°).
///
/// For the standard form cos C1 has the sign of `−sp·j` (A) or `sp·i` (B), so the choice
/// is made on that sign, exactly, and not on a rounded C. For the UCP710 (A, sp = +1) this
/// is G16's rule: j ≤ 0 → A = acos k; j > 0 → A = −acos k.
pub fn domain_rule_index(machine: &Machine, o_wp: [f64; 3]) -> usize {
    let Some(f) = machine.standard_form() else {
        return match inverse(machine, o_wp) {
            Some([s0, s1]) if s1.c_deg.abs() < s0.c_deg.abs() => 1,
            _ => 0,
        };
    };
    let [i, j, _] = o_wp;
    let cos_c1_sign = match f.primary {
        PrimaryAxis::A => -f.sp * j,
        PrimaryAxis::B => f.sp * i,
    };
    if cos_c1_sign < 0.0 { 1 } else { 0 }
}

/// Joint values for a sequence of tool axes: branch by `rule`, C unwrapped to be continuous
/// (each C within 180° of the previous one, so a C sweep past ±180° does not jump), and on
/// the pole C keeps the previous value (0 for a first point on the pole). Solutions outside
/// the machine's primary range are rejected in favour of the other one.
///
/// Per rule:
/// - [`BranchRule::Nearest`]: both candidates have C unwrapped to within 180° of the
///   previous C; the one with the smaller max(|ΔP|, |ΔC|) wins (ties: P ≥ 0). The first
///   point takes P ≥ 0 and C in (−180, 180].
/// - [`BranchRule::DomainRule`]: [`domain_rule_index`], and C is **not** unwrapped: it stays
///   in [−90°, 90°] (unless the range check swapped the solution), so P flips sign and C
///   jumps by up to 180° where j crosses 0 near the pole, as on the controllers G16 studies.
/// - [`BranchRule::PreferPositive`] / [`BranchRule::PreferNegative`]: P ≥ 0 / P ≤ 0,
///   C unwrapped.
///
/// On the pole (k ≈ +1) the output is P = 0 with C held. On the opposite pole (k ≈ −1) it
/// is P = 180° (P = −180° for `PreferNegative`, or for `Nearest` when the previous P is
/// negative) with C held, subject to the same range check; it is usually out of range.
/// On other pairs the pole gives P = [`Machine::pole_p_deg`] with C held (and the opposite
/// pole the P that points the tool against the pole axis). "P ≥ 0" and "P ≤ 0" above read
/// "the larger P" and "the smaller P" there.
/// C's own range (`c_range_deg`) is not checked here. A zero or non-finite tool axis gives
/// a NaN point, and the next point continues from the last finite one; so does an
/// orientation the pair cannot reach (never on the standard form; [`solve_ik`] says why).
pub fn inverse_path(machine: &Machine, o_wp: &[[f64; 3]], rule: BranchRule) -> Vec<IkSolution> {
    inverse_path_from(machine, o_wp, rule, None)
}

/// [`inverse_path`] continuing from `start` (the joint values before the first tool axis):
/// the first point is chosen and C unwrapped as if `start` were the previous point.
pub fn inverse_path_from(
    machine: &Machine,
    o_wp: &[[f64; 3]],
    rule: BranchRule,
    start: Option<IkSolution>,
) -> Vec<IkSolution> {
    let (p_lo, p_hi) = machine.primary_range_deg;
    let in_range = |s: &IkSolution| p_lo <= s.p_deg && s.p_deg <= p_hi;
    let mut out = Vec::with_capacity(o_wp.len());
    let mut prev: Option<IkSolution> = start.filter(|s| s.p_deg.is_finite() && s.c_deg.is_finite());
    let standard = machine.standard_form().is_some();
    let nan = IkSolution {
        p_deg: f64::NAN,
        c_deg: f64::NAN,
    };
    for &o in o_wp {
        let held_c = prev.map_or(0.0, |p| p.c_deg);
        let (solutions, pole_p_deg) = match standard {
            // Opposite pole: ±180°, two names of one posture; pole: 0° twice.
            true => (inverse(machine, o), if o[2] < 0.0 { 180.0 } else { 0.0 }),
            false => match solve_ik(machine, o) {
                Ik::Two(s) => (Some(s), 0.0),
                Ik::Pole { p_deg, .. } => (None, p_deg),
                Ik::Unreachable { .. } | Ik::Invalid => (Some([nan; 2]), 0.0),
            },
        };
        let on_pole = solutions.is_none();
        let mut cands = solutions.unwrap_or_else(|| {
            [
                IkSolution {
                    p_deg: pole_p_deg,
                    c_deg: held_c,
                },
                IkSolution {
                    p_deg: if pole_p_deg.abs() == 180.0 {
                        -pole_p_deg
                    } else {
                        pole_p_deg
                    },
                    c_deg: held_c,
                },
            ]
        });
        if let (true, Some(p)) = (rule != BranchRule::DomainRule, prev) {
            for s in &mut cands {
                s.c_deg = unwrap_near_deg(s.c_deg, p.c_deg);
            }
        }
        let pick = match (rule, prev) {
            (BranchRule::PreferNegative, _) => 1,
            (BranchRule::Nearest, Some(p)) => {
                let dist =
                    |s: &IkSolution| (s.p_deg - p.p_deg).abs().max((s.c_deg - p.c_deg).abs());
                usize::from(dist(&cands[1]) < dist(&cands[0]))
            }
            (BranchRule::DomainRule, _) if !on_pole => domain_rule_index(machine, o),
            _ => 0,
        };
        let pick = if !in_range(&cands[pick]) && in_range(&cands[1 - pick]) {
            1 - pick
        } else {
            pick
        };
        let s = cands[pick];
        out.push(s);
        if s.p_deg.is_finite() && s.c_deg.is_finite() {
            prev = Some(s);
        }
    }
    out
}

/// How far the tool is from a machine's pole, degrees, from its tilting axis' value: the
/// one rule of "near the pole" — the survey of a program, the patch's skip of a run with no
/// point near it, the patcher's fast path and its zones all ask it.
///
/// On the standard form (the built-ins, and every pair with the pole axis along Z and the
/// tilting axis about X or Y) the distance is `|P|` (not wrapped) and the signed distance P
/// itself, exactly; on other pairs the angle between the tool and the pole
/// ([`Machine::pole_tilt_deg`]), signed by the side of [`Machine::pole_p_deg`] the primary
/// axis is on; a pair that cannot reach the pole is 180° from it everywhere. Built once per
/// machine ([`PoleDistance::of`]: the pole is found then, not at every point).
#[derive(Debug, Clone)]
pub struct PoleDistance {
    rule: PoleRule,
}

#[derive(Debug, Clone)]
enum PoleRule {
    /// `|P|`.
    Standard,
    /// A pair that cannot reach the pole: 180°.
    NoPole,
    /// Through the pair's kinematics.
    General {
        rotary: crate::rotary::Rotaries,
        primary_sense: f64,
        pole_p_deg: f64,
        opposite: bool,
    },
}

impl PoleDistance {
    /// The rule of `machine`.
    pub fn of(machine: &Machine) -> PoleDistance {
        let rule = if machine.standard_form().is_some() {
            PoleRule::Standard
        } else {
            match machine.pole() {
                None => PoleRule::NoPole,
                Some(pole) => PoleRule::General {
                    rotary: machine.rotary,
                    primary_sense: machine.primary_sense,
                    pole_p_deg: pole.p_deg,
                    opposite: pole.opposite,
                },
            }
        };
        PoleDistance { rule }
    }

    /// The distance from the pole of a tool whose tilting axis is at `primary_deg`,
    /// degrees (≥ 0).
    pub fn deg(&self, primary_deg: f64) -> f64 {
        match &self.rule {
            PoleRule::Standard => primary_deg.abs(),
            PoleRule::NoPole => 180.0,
            PoleRule::General {
                rotary,
                primary_sense,
                opposite,
                ..
            } => pole_tilt_general(rotary, *primary_sense, primary_deg, *opposite),
        }
    }

    /// The signed distance: [`PoleDistance::deg`], negative where the primary axis is below
    /// the pole's value, so that a sign change is a pass through the pole onto the other
    /// branch (P itself on the standard form; 180° everywhere without a pole).
    pub fn signed_deg(&self, primary_deg: f64) -> f64 {
        match &self.rule {
            PoleRule::Standard => primary_deg,
            PoleRule::NoPole => 180.0,
            PoleRule::General { pole_p_deg, .. } => {
                let tilt = self.deg(primary_deg);
                if primary_deg < *pole_p_deg {
                    -tilt
                } else {
                    tilt
                }
            }
        }
    }

    /// Whether a tool whose tilting axis is at `primary_deg` lies within `reach_deg` of the
    /// pole (where a zone can be).
    pub fn near(&self, primary_deg: f64, reach_deg: f64) -> bool {
        self.deg(primary_deg) <= reach_deg
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forward::forward;
    use crate::testutil::{SplitMix64, all_kinds, machine};

    fn ucp710() -> Machine {
        Machine::builtin("mikron-ucp710").unwrap()
    }

    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    }

    /// The special angles a sweep must hit on purpose, besides random ones.
    fn p_choices(m: &Machine) -> Vec<f64> {
        let (lo, hi) = m.primary_range_deg;
        vec![
            0.0, -0.0, 1e-14, 1e-9, -1e-9, 0.5, -0.5, lo, hi, 90.0, -90.0, 180.0,
        ]
    }
    const C_CHOICES_DEG: [f64; 9] = [
        180.0, -180.0, 0.0, 90.0, -90.0, 179.999, -179.999, 360.0, 540.0,
    ];

    #[test]
    fn fk_of_ik_is_the_identity_on_a_seeded_sweep() {
        let mut rng = SplitMix64(0x5eed);
        let mut poles = 0;
        for m in all_kinds() {
            let ps = p_choices(&m);
            for n in 0..4000 {
                let p = if n % 2 == 0 {
                    rng.pick(&ps)
                } else {
                    rng.uniform(-180.0, 180.0)
                };
                let c = if n % 3 == 0 {
                    rng.pick(&C_CHOICES_DEG)
                } else {
                    rng.uniform(-400.0, 400.0)
                };
                let o = forward(&m, p, c);
                let Some(sols) = inverse(&m, o) else {
                    // Only on the pole: the tilt is below the tolerance.
                    assert!(p.to_radians().sin().abs() < POLE_SIN_TOL, "{p} {c}");
                    poles += 1;
                    continue;
                };
                assert!(sols[0].p_deg >= 0.0 && sols[1].p_deg <= 0.0, "{sols:?}");
                for s in sols {
                    assert!(-180.0 < s.c_deg && s.c_deg <= 180.0, "{s:?}");
                    assert!(-180.0 < s.p_deg && s.p_deg <= 180.0, "{s:?}");
                    let back = forward(&m, s.p_deg, s.c_deg);
                    assert!(
                        dist(back, o) < 4e-16 * 8.0,
                        "{:?} P={p} C={c}: {s:?}",
                        m.primary_letter()
                    );
                }
                // One of the two is (p, c) itself, up to a turn of C; C is only as
                // accurate as the tilt allows (error ~ ε / sin P).
                let s = if p >= 0.0 { sols[0] } else { sols[1] };
                let c_tol = 1e-13 / p.to_radians().sin().abs();
                assert!((s.p_deg - p).abs() < 1e-12, "P={p}: {s:?}");
                assert!(
                    wrap_deg(s.c_deg - c).abs() < c_tol.max(1e-12),
                    "P={p} C={c}: {s:?}"
                );
            }
        }
        assert!(poles > 100, "the sweep must hit the pole ({poles})");
    }

    #[test]
    fn inverse_is_none_exactly_on_the_pole_and_the_opposite_pole() {
        let m = ucp710();
        assert!(inverse(&m, [0.0, 0.0, 1.0]).is_none());
        assert!(inverse(&m, [0.0, 0.0, -1.0]).is_none());
        assert!(inverse(&m, [1e-13, -1e-13, 1.0]).is_none());
        // A tilt of 1e-11 rad is not the pole; an unnormalised vector is fine.
        let s = inverse(&m, [0.0, -1e-11 * 5.0, 5.0]).unwrap();
        assert!((s[0].p_deg - 1e-11f64.to_degrees()).abs() < 1e-20);
        assert_eq!(s[0].c_deg, 0.0);
    }

    #[test]
    fn bad_tool_axes_give_nan_not_the_pole() {
        let m = ucp710();
        for o in [[0.0; 3], [f64::NAN, 0.0, 1.0], [0.0, f64::INFINITY, 1.0]] {
            let s = inverse(&m, o).expect("not the pole");
            assert!(s[0].p_deg.is_nan() && s[1].c_deg.is_nan(), "{o:?}: {s:?}");
        }
        let path = inverse_path(
            &m,
            &[[0.0, -0.5, 0.866], [f64::NAN; 3], [0.0, -0.5, 0.866]],
            BranchRule::Nearest,
        );
        assert!(path[1].p_deg.is_nan());
        assert_eq!(
            path[2], path[0],
            "the path continues from the last finite point"
        );
    }

    /// Issue 19 §5: a huge but finite axis has a direction; its length overflowed.
    #[test]
    fn huge_tool_axes_are_scaled_not_nan() {
        let m = ucp710();
        for big in [1e300, f64::MAX] {
            let s = inverse(&m, [big, 0.0, big]).expect("not the pole");
            assert!((s[0].p_deg - 45.0).abs() < 1e-12, "{big}: {s:?}");
            let t = inverse(&m, [1.0, 0.0, 1.0]).unwrap();
            assert_eq!(s, t);
        }
    }

    /// G16 Table 1, both solutions, every cell, for the UCP710 (k = cos 30°).
    #[test]
    fn g16_table_1_case_by_case() {
        let m = ucp710();
        let k = 30f64.to_radians().cos();
        let acos_k = k.acos().to_degrees();
        let deg = |r: f64| r.to_degrees();
        // (i, j) on the circle of radius sin 30° = 0.5.
        let cells = [
            (-0.3, -0.4),
            (0.0, -0.5),
            (0.3, -0.4),
            (-0.5, 0.0),
            (0.5, 0.0),
            (-0.3, 0.4),
            (0.0, 0.5),
            (0.3, 0.4),
        ];
        for (i, j) in cells {
            let o = [i, j, k];
            // Table 1, literally (C wrapped to (−180, 180] where it says "+ π").
            let ((a1, c1), (a2, c2)) = if j < 0.0 {
                (
                    (acos_k, -deg((i / j).atan())),
                    (-acos_k, wrap_deg(-deg((i / j).atan()) + 180.0)),
                )
            } else if j > 0.0 {
                (
                    (acos_k, wrap_deg(-deg((i / j).atan()) + 180.0)),
                    (-acos_k, -deg((i / j).atan())),
                )
            } else if i < 0.0 {
                ((acos_k, -90.0), (-acos_k, 90.0))
            } else {
                ((acos_k, 90.0), (-acos_k, -90.0))
            };
            let [s1, s2] = inverse(&m, o).unwrap();
            let close = |s: IkSolution, a: f64, c: f64| {
                (s.p_deg - a).abs() < 1e-12 && wrap_deg(s.c_deg - c).abs() < 1e-12
            };
            assert!(close(s1, a1, c1), "i={i} j={j}: {s1:?} vs A1={a1} C1={c1}");
            assert!(close(s2, a2, c2), "i={i} j={j}: {s2:?} vs A2={a2} C2={c2}");
            // The domain rule (the controller's choice): j ≤ 0 → (A1, C1), j > 0 → (A2, C2).
            let d = inverse_path(&m, &[o], BranchRule::DomainRule)[0];
            let want = if j > 0.0 { s2 } else { s1 };
            assert_eq!(d, want, "i={i} j={j}");
            assert!((-90.0..=90.0).contains(&d.c_deg), "{d:?}");
        }
        // j = 0: C is exactly ±90 and A is positive.
        assert_eq!(
            inverse_path(&m, &[[-0.5, 0.0, k]], BranchRule::DomainRule)[0].c_deg,
            -90.0
        );
        assert_eq!(
            inverse_path(&m, &[[0.5, -0.0, k]], BranchRule::DomainRule)[0].c_deg,
            90.0
        );
        // i = j = 0: A = 0, C undefined (held, 0 for a first point).
        let pole = inverse_path(&m, &[[0.0, 0.0, 1.0]], BranchRule::DomainRule)[0];
        assert_eq!(
            pole,
            IkSolution {
                p_deg: 0.0,
                c_deg: 0.0
            }
        );
    }

    #[test]
    fn domain_rule_keeps_c_within_90_degrees_for_every_kind_of_machine() {
        let mut rng = SplitMix64(90);
        for m in all_kinds() {
            for _ in 0..2000 {
                let o = forward(&m, rng.uniform(1.0, 100.0), rng.uniform(-180.0, 180.0));
                let s = inverse_path(&m, &[o], BranchRule::DomainRule)[0];
                assert!(
                    (-90.0..=90.0).contains(&s.c_deg),
                    "{:?} {o:?}: {s:?}",
                    m.primary_letter()
                );
                assert!(dist(forward(&m, s.p_deg, s.c_deg), o) < 1e-14);
            }
        }
    }

    /// A planted pole crossing: the tool axis passes 0.02 rad (≈ 1.15°) beside the pole
    /// while j runs from −0.1 to 0.1 through exactly 0.
    fn crossing() -> Vec<[f64; 3]> {
        (-10..=10)
            .map(|n| {
                let (i, j) = (0.02, f64::from(n) * 0.01);
                [i, j, (1.0 - i * i - j * j).sqrt()]
            })
            .collect()
    }

    #[test]
    fn domain_rule_flips_p_and_jumps_c_where_j_crosses_zero() {
        let m = ucp710();
        let path = inverse_path(&m, &crossing(), BranchRule::DomainRule);
        for (n, s) in path.iter().enumerate() {
            // j ≤ 0 up to n = 10 (j = 0 exactly), then j > 0.
            assert_eq!(s.p_deg > 0.0, n <= 10, "point {n}: {s:?}");
            assert!((-90.0..=90.0).contains(&s.c_deg), "point {n}: {s:?}");
        }
        assert_eq!(path[10].c_deg, 90.0);
        // The jump: C1 = 90° at j = 0, C2 = −atan(0.02/0.01) = −63.4° just after.
        let jump = path[11].c_deg - path[10].c_deg;
        assert!(
            (jump + 90.0 + 2f64.atan().to_degrees()).abs() < 1e-9,
            "jump {jump}"
        );
        let steps = path
            .windows(2)
            .filter(|w| (w[1].c_deg - w[0].c_deg).abs() > 90.0)
            .count();
        assert_eq!(steps, 1, "exactly one jump of C");
        // P flips sign: the tilt after the crossing mirrors the one before it.
        assert_eq!(path[11].p_deg, -path[9].p_deg);
    }

    #[test]
    fn nearest_and_constant_sign_rules_stay_continuous_through_the_crossing() {
        let m = ucp710();
        let o = crossing();
        for (rule, sign) in [
            (BranchRule::Nearest, 1.0),
            (BranchRule::PreferPositive, 1.0),
            (BranchRule::PreferNegative, -1.0),
        ] {
            let path = inverse_path(&m, &o, rule);
            for (s, o) in path.iter().zip(&o) {
                assert!(s.p_deg * sign > 0.0, "{rule:?}: {s:?}");
                assert!(dist(forward(&m, s.p_deg, s.c_deg), *o) < 1e-15);
            }
            // C sweeps 180° − 2·atan(0.02/0.1) monotonically; the largest step,
            // 90° − atan 2 ≈ 26.6°, is next to the pole.
            let max_step = path
                .windows(2)
                .map(|w| (w[1].c_deg - w[0].c_deg).abs())
                .fold(0.0, f64::max);
            assert!(max_step < 27.0, "{rule:?}: max step {max_step}");
            let sweep = path[20].c_deg - path[0].c_deg;
            let want = 180.0 - 2.0 * 0.2f64.atan().to_degrees();
            assert!(
                (sweep - want).abs() < 1e-9,
                "{rule:?}: sweep {sweep} vs {want}"
            );
        }
    }

    #[test]
    fn c_is_unwrapped_past_180_degrees_except_under_the_domain_rule() {
        // Two full turns of C at a 20° tilt, 7.5° apart, for every kind of machine.
        for m in all_kinds() {
            let o: Vec<_> = (0..=96)
                .map(|n| forward(&m, 20.0, f64::from(n) * 7.5 - 180.0))
                .collect();
            for rule in [BranchRule::Nearest, BranchRule::PreferPositive] {
                let path = inverse_path(&m, &o, rule);
                assert_eq!(path[0].c_deg, 180.0, "first C in (−180, 180]");
                for (n, s) in path.iter().enumerate() {
                    let want = f64::from(n as u32) * 7.5 + 180.0;
                    assert!(
                        (s.c_deg - want).abs() < 1e-9 && (s.p_deg - 20.0).abs() < 1e-9,
                        "{rule:?} {n}: {s:?}"
                    );
                }
            }
            let neg = inverse_path(&m, &o, BranchRule::PreferNegative);
            assert!((neg[96].c_deg - neg[0].c_deg - 720.0).abs() < 1e-9);
            let dom = inverse_path(&m, &o, BranchRule::DomainRule);
            assert!(dom.iter().all(|s| (-90.0..=90.0).contains(&s.c_deg)));
        }
    }

    #[test]
    fn on_the_pole_p_is_zero_and_c_is_held() {
        let m = ucp710();
        let o = [
            [0.0, 0.0, 1.0],
            forward(&m, 10.0, 250.0),
            [0.0, 0.0, 1.0],
            forward(&m, 10.0, 255.0),
        ];
        for rule in [
            BranchRule::Nearest,
            BranchRule::DomainRule,
            BranchRule::PreferPositive,
            BranchRule::PreferNegative,
        ] {
            let path = inverse_path(&m, &o, rule);
            assert_eq!(
                path[0],
                IkSolution {
                    p_deg: 0.0,
                    c_deg: 0.0
                },
                "{rule:?}"
            );
            assert!(
                path[2].p_deg == 0.0 && path[2].p_deg.is_sign_positive(),
                "{rule:?}"
            );
            assert_eq!(path[2].c_deg, path[1].c_deg, "{rule:?}");
        }
        // Nearest from (0, 0): (10, −110) is 110 away, (−10, 70) only 70 (max of |ΔP|, |ΔC|).
        let path = inverse_path(&m, &o, BranchRule::Nearest);
        assert!((path[1].p_deg + 10.0).abs() < 1e-12 && (path[1].c_deg - 70.0).abs() < 1e-9);
        assert!((path[3].p_deg + 10.0).abs() < 1e-12, "{path:?}");
        assert!((path[3].c_deg - 75.0).abs() < 1e-9, "{path:?}");
    }

    #[test]
    fn opposite_pole_is_180_degrees_with_c_held() {
        let m = machine(crate::machine::PrimaryAxis::A, 1.0, 1.0, (-190.0, 190.0));
        let o = [forward(&m, -170.0, 30.0), [0.0, 0.0, -1.0]];
        let near = inverse_path(&m, &o, BranchRule::Nearest);
        assert_eq!(near[1].c_deg, near[0].c_deg);
        assert_eq!(near[1].p_deg, 180.0, "P ≥ 0 first, 170 is nearest");
        let neg = inverse_path(&m, &o, BranchRule::PreferNegative);
        assert!((neg[0].p_deg + 170.0).abs() < 1e-9);
        assert_eq!(neg[1].p_deg, -180.0);
        assert_eq!(inverse_path(&m, &o, BranchRule::DomainRule)[1].p_deg, 180.0);
        // Out of range on the UCP710 either way: the rule's choice stands.
        assert_eq!(
            inverse_path(&ucp710(), &o[1..], BranchRule::PreferNegative)[0].p_deg,
            -180.0
        );
    }

    #[test]
    fn a_solution_outside_the_primary_range_gives_way_to_the_other() {
        let m = ucp710(); // A in [−100, 120]
        let o = forward(&m, 110.0, 30.0);
        for rule in [
            BranchRule::Nearest,
            BranchRule::DomainRule,
            BranchRule::PreferPositive,
            BranchRule::PreferNegative,
        ] {
            let s = inverse_path(&m, &[o], rule)[0];
            assert!((s.p_deg - 110.0).abs() < 1e-9, "{rule:?}: {s:?}");
        }
        // Domain rule would choose A = −50 (C = −150 is outside ±90 for A = +50)...
        let m = machine(crate::machine::PrimaryAxis::A, 1.0, 1.0, (-30.0, 110.0));
        let o = forward(&m, 50.0, -150.0);
        assert_eq!(domain_rule_index(&m, o), 1);
        // ... but −50 is out of range, so the path keeps A = +50, C = −150.
        let s = inverse_path(&m, &[o], BranchRule::DomainRule)[0];
        assert!(
            (s.p_deg - 50.0).abs() < 1e-9 && (s.c_deg + 150.0).abs() < 1e-9,
            "{s:?}"
        );
        // When neither is in range, the rule's choice stands.
        let o = forward(&m, 150.0, 0.0);
        assert!(inverse_path(&m, &[o], BranchRule::PreferPositive)[0].p_deg > 0.0);
        assert!(inverse_path(&m, &[o], BranchRule::PreferNegative)[0].p_deg < 0.0);
    }

    /// A pair whose pole is not at P = 0: LinuxCNC's xyzab_tdr layout, the A table along X
    /// (the pole axis) carried by B along Y, tool along Z. The pole is B = ±90°.
    fn tdr() -> Machine {
        crate::testutil::pair_machine([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], 1.0, 1.0)
    }

    /// A 45° nutating table: B at 45° between +Y and +Z carrying C; it reaches 0° to 90°
    /// from its C axis.
    fn nutating() -> Machine {
        let mut m = crate::testutil::pair_machine(
            [0.0, 0.0, 1.0],
            crate::testutil::unit([0.0, 1.0, 1.0]),
            [0.0, 0.0, 1.0],
            1.0,
            1.0,
        );
        m.primary_range_deg = (-5.0, 185.0);
        m
    }

    /// A planted pass 1.15° beside the pole of a pair whose pole is at B = 90°: every rule
    /// gives joints whose FK is the tool axis; Nearest and the constant-sign rules stay
    /// continuous (C unwrapped), the domain rule keeps |C| the smaller of the two.
    #[test]
    fn paths_on_a_pair_whose_pole_is_not_at_zero() {
        let m = tdr();
        assert!(m.standard_form().is_none());
        // The tool axis passes 0.02 rad beside +X while its y component crosses 0.
        let o: Vec<[f64; 3]> = (-10..=10)
            .map(|n| {
                let (y, z) = (f64::from(n) * 0.01, 0.02);
                [(1.0 - y * y - z * z).sqrt(), y, z]
            })
            .collect();
        for rule in [
            BranchRule::Nearest,
            BranchRule::DomainRule,
            BranchRule::PreferPositive,
            BranchRule::PreferNegative,
        ] {
            let path = inverse_path(&m, &o, rule);
            for (s, o) in path.iter().zip(&o) {
                assert!(
                    dist(forward(&m, s.p_deg, s.c_deg), *o) < 1e-12,
                    "{rule:?}: {s:?}"
                );
                // Within 5.85° of the pole (the pass's ends: hypot(0.1, 0.02) rad), B is
                // within 5.85° of ±90°.
                assert!((s.p_deg.abs() - 90.0).abs() < 5.9, "{rule:?}: {s:?}");
            }
            if rule == BranchRule::DomainRule {
                for (s, o) in path.iter().zip(&o) {
                    let [a, b] = inverse(&m, *o).unwrap();
                    assert!(s.c_deg.abs() <= a.c_deg.abs().min(b.c_deg.abs()) + 1e-12);
                }
            } else {
                // A continuous C sweep: no step above 30°.
                let max_step = path
                    .windows(2)
                    .map(|w| (w[1].c_deg - w[0].c_deg).abs())
                    .fold(0.0, f64::max);
                assert!(max_step < 30.0, "{rule:?}: {max_step}");
            }
        }
        // On the pole: B at the pole, C held; the opposite pole: the other B.
        let path = inverse_path(
            &m,
            &[forward(&m, 80.0, 33.0), [1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]],
            BranchRule::Nearest,
        );
        assert!(
            (path[1].p_deg - m.pole_p_deg().unwrap()).abs() < 1e-12,
            "{path:?}"
        );
        assert!((path[1].p_deg.abs() - 90.0).abs() < 1e-12);
        assert_eq!(path[1].c_deg, path[0].c_deg);
        assert!(dist(forward(&m, path[2].p_deg, path[2].c_deg), [-1.0, 0.0, 0.0]) < 1e-12);
        assert_eq!(path[2].c_deg, path[0].c_deg);
    }

    /// A tool axis a nutating table cannot reach is a NaN point, and the path goes on from
    /// the last point it could.
    #[test]
    fn an_unreachable_tool_axis_is_a_nan_point_on_the_path() {
        let m = nutating();
        let o = [
            forward(&m, 60.0, 10.0),
            [1.0, 0.0, -0.2],
            forward(&m, 61.0, 11.0),
        ];
        let path = inverse_path(&m, &o, BranchRule::Nearest);
        assert!(path[1].p_deg.is_nan() && path[1].c_deg.is_nan());
        assert!((path[0].p_deg - 60.0).abs() < 1e-9 && (path[2].p_deg - 61.0).abs() < 1e-9);
        assert!((path[2].c_deg - 11.0).abs() < 1e-9);
        match solve_ik(&m, o[1]) {
            Ik::Unreachable {
                angle_deg,
                reach_deg,
            } => {
                assert!(angle_deg > 90.0 && (reach_deg.1 - 90.0).abs() < 1e-9)
            }
            other => panic!("{other:?}"),
        }
        // The range check picks the solution within B's travel: (−B) is out of it.
        let s = inverse_path(&m, &[forward(&m, 60.0, 10.0)], BranchRule::PreferNegative)[0];
        assert!((s.p_deg - 60.0).abs() < 1e-9, "{s:?}");
    }

    mod prop {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            /// fk(ik(o)) = o for any tool axis off the pole, any kind of machine.
            #[test]
            fn fk_of_ik_round_trip(kind in 0usize..8, x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0) {
                let m = &all_kinds()[kind];
                let n = (x * x + y * y + z * z).sqrt();
                prop_assume!(n > 1e-3);
                let o = [x / n, y / n, z / n];
                match inverse(m, o) {
                    None => prop_assert!(x.hypot(y) < POLE_SIN_TOL * n),
                    Some(sols) => for s in sols {
                        // A few ulps of a unit vector: degrees ↔ radians round twice.
                        prop_assert!(dist(forward(m, s.p_deg, s.c_deg), o) < 4e-15);
                    },
                }
            }
        }
    }

    /// The one rule agrees with the machine's own: |P| on the standard form, the tilt
    /// elsewhere, signed by the side of the pole; 180° on a pair without a pole.
    #[test]
    fn the_pole_distance_is_the_machines_tilt_signed_by_its_side() {
        let ucp = Machine::builtin("mikron-ucp710").unwrap();
        let d = PoleDistance::of(&ucp);
        assert_eq!((d.deg(-3.5), d.signed_deg(-3.5)), (3.5, -3.5));
        assert_eq!(d.deg(270.0), 270.0, "not wrapped");
        assert!(d.near(-2.0, 2.0) && !d.near(2.5, 2.0));
        let no_pole = crate::testutil::pair_machine(
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            crate::testutil::unit([1.0, 0.0, 1.0]),
            1.0,
            1.0,
        );
        assert!(no_pole.standard_form().is_none() && no_pole.pole_p_deg().is_none());
        for m in [tdr(), nutating(), no_pole] {
            let d = PoleDistance::of(&m);
            for p in [-40.0, -5.0, 0.0, 0.3, 7.0, 60.0, 89.0, 91.0] {
                match m.pole_p_deg() {
                    Some(pole) => {
                        let tilt = m.pole_tilt_deg(p);
                        assert_eq!(d.deg(p).to_bits(), tilt.to_bits());
                        let signed = if p < pole { -tilt } else { tilt };
                        assert_eq!(d.signed_deg(p).to_bits(), signed.to_bits());
                    }
                    None => assert_eq!((d.deg(p), d.signed_deg(p)), (180.0, 180.0)),
                }
            }
        }
    }
}
