//! Inverse kinematics: tool axis → (primary, C) in degrees, both solutions, branch choice.
//!
//! Off the pole every unit tool axis `o_wp = (i, j, k)` has exactly two joint solutions
//! (see [`crate::forward`] for the model):
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
//! by [`inverse`] and resolved by [`inverse_path`] as P = ±180° with C held.

use crate::machine::{Machine, PrimaryAxis};
use crate::tolerances::POLE_SIN_TOL;

/// One joint solution, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution {
    /// Primary angle (A or B), degrees.
    pub p_deg: f64,
    /// C angle, degrees, in (−180, 180] before unwrapping.
    pub c_deg: f64,
}

/// How [`inverse_path`] picks between the two solutions (P, C) and (−P, C+180°).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchRule {
    /// The solution nearest to the previous point (max of |ΔP| and |ΔC| after unwrapping);
    /// the first point prefers positive P.
    Nearest,
    /// G16 Table 1: the branch is chosen by the sign of j (flips P near the pole).
    DomainRule,
    /// Always P ≥ 0.
    PreferPositive,
    /// Always P ≤ 0.
    PreferNegative,
}

/// Both solutions for a unit tool axis `o_wp`. Returns `None` on the pole (|sin P| below
/// [`crate::tolerances::POLE_SIN_TOL`]): C is undefined there. The first solution has
/// P ≥ 0. Both P lie within (−180, 180].
///
/// `o_wp` need not be normalised. A zero or non-finite `o_wp` gives NaN solutions (never
/// `None`), so bad input is not mistaken for the pole.
pub fn inverse(machine: &Machine, o_wp: [f64; 3]) -> Option<[IkSolution; 2]> {
    let [i, j, k] = o_wp;
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
    let (sp, sc) = (machine.primary_sense, machine.c_sense);
    let theta_deg = match machine.primary {
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

/// An angle in degrees wrapped to (−180, 180].
pub fn wrap_deg(angle_deg: f64) -> f64 {
    let w = angle_deg.rem_euclid(360.0); // [0, 360], 360 only by rounding
    if w > 180.0 { w - 360.0 } else { w }
}

/// `angle_deg + n·360` for the integer n that puts it within (ref − 180, ref + 180], degrees.
pub fn unwrap_near_deg(angle_deg: f64, ref_deg: f64) -> f64 {
    ref_deg + wrap_deg(angle_deg - ref_deg)
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
/// the one with P > 0 (index 0).
///
/// cos C1 has the sign of `−sp·j` (A) or `sp·i` (B), so the choice is made on that sign,
/// exactly, and not on a rounded C. For the UCP710 (A, sp = +1) this is G16's rule:
/// j ≤ 0 → A = acos k; j > 0 → A = −acos k.
pub fn domain_rule_index(machine: &Machine, o_wp: [f64; 3]) -> usize {
    let [i, j, _] = o_wp;
    let cos_c1_sign = match machine.primary {
        PrimaryAxis::A => -machine.primary_sense * j,
        PrimaryAxis::B => machine.primary_sense * i,
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
/// C's own range (`c_range_deg`) is not checked here. A zero or non-finite tool axis gives
/// a NaN point, and the next point continues from the last finite one.
pub fn inverse_path(machine: &Machine, o_wp: &[[f64; 3]], rule: BranchRule) -> Vec<IkSolution> {
    let (p_lo, p_hi) = machine.primary_range_deg;
    let in_range = |s: &IkSolution| p_lo <= s.p_deg && s.p_deg <= p_hi;
    let mut out = Vec::with_capacity(o_wp.len());
    let mut prev: Option<IkSolution> = None;
    for &o in o_wp {
        let held_c = prev.map_or(0.0, |p| p.c_deg);
        let solutions = inverse(machine, o);
        let on_pole = solutions.is_none();
        let mut cands = solutions.unwrap_or_else(|| {
            // Opposite pole: ±180°, two names of one posture; pole: 0° twice.
            let p_deg = if o[2] < 0.0 { 180.0 } else { 0.0 };
            [
                IkSolution {
                    p_deg,
                    c_deg: held_c,
                },
                IkSolution {
                    p_deg: if p_deg == 0.0 { 0.0 } else { -p_deg },
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
