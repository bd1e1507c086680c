//! Starts: values that pass through the pole, which the methods begin from and the bench
//! reference starts its solves at. None is verified here; each is a whole-path rewrite
//! that keeps or nearly keeps the tool axes.
//!
//! **The other branch** ([`other_branch`]): the points after `k` move to the other IK
//! branch as a block, `(P, C) → (−P, C ± 180°)`: the same tool axes, every derivative's
//! size kept. `k` is where the program switches branch inside a zone ([`branch_switch`]:
//! the primary axis changes sign with C jumping, as a domain-rule post writes it, G16
//! Table 1) or the zone's point of least |P| ([`least_primary`]); the ±180° keeps C
//! continuous ([`tail_shift`]). Branch re-selection ([`crate::reselect`]) proposes it as
//! it is; the joint patch ([`crate::joint_method`]) starts from it.
//!
//! **The cone rules** ([`apply_rule`]), the pole strategies CAM posts and controllers
//! document. For each singular zone, the **cone stretch** ([`cone_stretch`]) is the
//! maximal run of consecutive points with |P| ≤ the cone around the zone's point of least
//! |P|; `e0` and `e1` are the points just before and after it (the entry and exit).
//! Inside the stretch:
//! - [`Rule::Freeze`] (ModuleWorks FREEZE, Fanuc's tool posture control): C holds its
//!   entry value `C(e0)`;
//! - [`Rule::Linearize`] (ModuleWorks LINEAR_INTERPOLATION, Fusion LINEARIZE_ROTARY):
//!   C linear in s from `C(e0)` to `C(e1)` (the program's values, as unwrapped);
//! - [`Rule::Smooth`] (ModuleWorks SMOOTH_INTERPOLATION, its default): C a cubic
//!   Hermite blend in s from `(C, C')(e0)` to `(C, C')(e1)`, slopes from the program's
//!   analysis spline.
//!
//! With C chosen, the primary axis takes the angle that puts the tool axis closest to the
//! programmed one on C's meridian — `P = atan2(o·d, o_z)` with `d` the meridian's
//! horizontal direction (∂o/∂P at P = 0) — which may pass through zero (through the pole)
//! ([`primary_on_meridian`]). FREEZE and LINEARIZE are starts of the joint patch and of
//! the bench reference; the bench scores all three as peers ([`crate::peers`]).

use crate::{
    analysis::Zone,
    spline::AnalysisSpline,
    tolerances::{HALF_TURN_SLACK_DEG, POLE_DEG},
};
use polepatch_kinematics::{Machine, forward_jacobian, wrap_deg};

/// A cone rule (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    /// C held at its entry value inside the cone.
    Freeze,
    /// C linear in s across the cone.
    Linearize,
    /// C a cubic blend across the cone.
    Smooth,
}

/// The index after which the program switches branch inside the zone: the last point
/// before the primary axis changes sign (points exactly at 0 skipped), nearest to the
/// zone's singular point.
pub fn branch_switch(p: &[f64], zone: &Zone) -> Option<usize> {
    let mut best: Option<usize> = None;
    let mut last_nonzero: Option<usize> = None;
    for i in zone.first..=zone.last {
        if p[i] == 0.0 {
            continue;
        }
        if let Some(j) = last_nonzero
            && p[j].signum() != p[i].signum()
            && best.is_none_or(|b| j.abs_diff(zone.singular) < b.abs_diff(zone.singular))
        {
            best = Some(j);
        }
        last_nonzero = Some(i);
    }
    best
}

/// The point of least |P| in the zone.
pub fn least_primary(p: &[f64], zone: &Zone) -> usize {
    (zone.first..=zone.last)
        .min_by(|&a, &b| p[a].abs().total_cmp(&p[b].abs()))
        .unwrap_or(zone.singular)
}

/// The ±180° that keeps C continuous when the points after `k` move to the other branch,
/// or `None` when the run's last point must stay or a re-selected value would leave the
/// machine's ranges.
pub fn tail_shift(
    machine: &Machine,
    p: &[f64],
    c: &[f64],
    k: usize,
    keep_last: bool,
) -> Option<f64> {
    let n = p.len();
    // The other branch is (−P, C ± 180°) on the standard form only; on another pair (a
    // 45° nutating table) the points after `k` would turn the tool.
    if k + 1 >= n || keep_last || machine.standard_form().is_none() {
        return None;
    }
    let (lo, hi) = machine.primary_range_deg;
    if p[k + 1..].iter().any(|&v| !(lo..=hi).contains(&-v)) {
        return None;
    }
    // C after the switch, moved by ±180°, nearest to C before it — before it on a point
    // off the pole (on the pole C does not orient the tool and may be anything).
    let r = (0..=k).rev().find(|&i| p[i].abs() > POLE_DEG).unwrap_or(k);
    let d = wrap_deg(c[k + 1] + 180.0 - c[r]) - (c[k + 1] + 180.0 - c[r]);
    let shift = 180.0 + d;
    let shift = if shift > 180.0 + HALF_TURN_SLACK_DEG {
        shift - 360.0
    } else {
        shift
    };
    if let Some((c_lo, c_hi)) = machine.c_range_deg
        && c[k + 1..]
            .iter()
            .any(|&v| !(c_lo..=c_hi).contains(&(v + shift)))
    {
        return None;
    }
    Some(shift)
}

/// The values of the whole path with the points after `k` on the other branch (C moved
/// by `shift`).
pub fn other_branch(p: &[f64], c: &[f64], k: usize, shift: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut op, mut oc) = (p.to_vec(), c.to_vec());
    for i in k + 1..p.len() {
        op[i] = -p[i];
        oc[i] = c[i] + shift;
    }
    (op, oc)
}

/// The primary angle, degrees, that puts the tool axis closest to `o` on the meridian of
/// `c_deg` (module docs).
pub fn primary_on_meridian(machine: &Machine, o: [f64; 3], c_deg: f64) -> f64 {
    let [_, d, _] = forward_jacobian(machine, 0.0, c_deg);
    let norm = (d[0] * d[0] + d[1] * d[1]).sqrt();
    let along = (o[0] * d[0] + o[1] * d[1]) / norm;
    along.atan2(o[2]).to_degrees()
}

/// The cone stretch of a zone (module docs): points `a..=b` with |P| ≤ `cone_deg` around
/// the zone's point of least |P|, and the entry and exit points `e0 = a − 1`, `e1 = b + 1`
/// (clipped to the path; the first point is never in a stretch). `None` when empty.
pub fn cone_stretch(p_deg: &[f64], zone: &Zone, cone_deg: f64) -> Option<[usize; 4]> {
    let n = p_deg.len();
    let k = (zone.first..=zone.last)
        .min_by(|&a, &b| p_deg[a].abs().total_cmp(&p_deg[b].abs()))
        .unwrap_or(zone.singular);
    let (mut a, mut b) = (k, k);
    while a > 1 && p_deg[a - 1].abs() <= cone_deg {
        a -= 1;
    }
    while b + 1 < n - 1 && p_deg[b + 1].abs() <= cone_deg {
        b += 1;
    }
    let (e0, e1) = (a.saturating_sub(1), (b + 1).min(n - 1));
    let a = a.max(1);
    (a <= b).then_some([e0, a, b, e1])
}

/// Rewrite the cone stretch `[e0, a, b, e1]` of `(p, c)` by `rule` (module docs),
/// unrounded: C by the rule from the program's values `c0` (and the slopes of its analysis
/// spline `c_spline` for [`Rule::Smooth`]), P on C's meridian closest to `target`.
#[allow(clippy::too_many_arguments)]
pub fn apply_rule(
    rule: Rule,
    machine: &Machine,
    s_mm: &[f64],
    c0: &[f64],
    c_spline: &AnalysisSpline,
    target: &[[f64; 3]],
    [e0, a, b, e1]: [usize; 4],
    p: &mut [f64],
    c: &mut [f64],
) {
    let (s0, s1) = (s_mm[e0], s_mm[e1]);
    let (ca, cb) = (c0[e0], c0[e1]);
    let (da, db) = (c_spline.eval_derivs(s0)[1], c_spline.eval_derivs(s1)[1]);
    for i in a..=b {
        let t = if s1 > s0 {
            (s_mm[i] - s0) / (s1 - s0)
        } else {
            0.0
        };
        c[i] = match rule {
            Rule::Freeze => ca,
            Rule::Linearize => ca + t * (cb - ca),
            Rule::Smooth => {
                // Cubic Hermite basis on [s0, s1].
                let h = s1 - s0;
                let (t2, t3) = (t * t, t * t * t);
                (2.0 * t3 - 3.0 * t2 + 1.0) * ca
                    + (t3 - 2.0 * t2 + t) * h * da
                    + (-2.0 * t3 + 3.0 * t2) * cb
                    + (t3 - t2) * h * db
            }
        };
        p[i] = primary_on_meridian(machine, target[i], c[i]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polepatch_kinematics::{angle_between_deg, forward};

    /// The meridian projection is exact for a tool axis on the meridian (either side of
    /// the pole) and the closest point otherwise.
    #[test]
    fn projection_onto_a_meridian() {
        for name in ["mikron-ucp710", "mikron-hsm600"] {
            let m = Machine::builtin(name).unwrap();
            for (p, c) in [(3.0, 40.0), (-7.5, 40.0), (0.0, 10.0), (25.0, -170.0)] {
                let o = forward(&m, p, c);
                assert!(
                    (primary_on_meridian(&m, o, c) - p).abs() < 1e-9,
                    "{name} {p} {c}"
                );
                // Off the meridian by 10°: the closest point beats its neighbours.
                let q = primary_on_meridian(&m, o, c + 10.0);
                let dev = |x: f64| angle_between_deg(o, forward(&m, x, c + 10.0));
                assert!(dev(q) <= dev(q + 0.01) && dev(q) <= dev(q - 0.01));
            }
        }
    }
}
