//! The pole strategies that CAM posts and controllers document, as peers for the quality
//! suite (issue 8 §5): each rewrites the rotary values inside the singular cone by a fixed
//! rule, and `polepatch bench --strategy …` scores it with the same Equation-6 analysis as
//! polepatch's own patch.
//!
//! For each singular zone, the **cone stretch** is the maximal run of consecutive points
//! with |P| ≤ the cone around the zone's point of least |P|; `e0` and `e1` are the points
//! just before and after it (the entry and exit). Inside the stretch:
//! - [`Strategy::Freeze`] (ModuleWorks FREEZE, Fanuc's tool posture control): C holds its
//!   entry value `C(e0)`;
//! - [`Strategy::Linearize`] (ModuleWorks LINEAR_INTERPOLATION, Fusion LINEARIZE_ROTARY):
//!   C linear in s from `C(e0)` to `C(e1)` (the program's values, as unwrapped);
//! - [`Strategy::Smooth`] (ModuleWorks SMOOTH_INTERPOLATION, its default): C a cubic
//!   Hermite blend in s from `(C, C')(e0)` to `(C, C')(e1)`, slopes from the program's
//!   analysis spline.
//!
//! With C chosen, the primary axis takes the angle that puts the tool axis closest to the
//! programmed one on C's meridian — `P = atan2(o·d, o_z)` with `d` the meridian's
//! horizontal direction (∂o/∂P at P = 0) — which may pass through zero (through the pole).
//! Values are written with the file's decimals, as a post would. Nothing is verified and
//! nothing is kept back: a peer's result is what it is, and the suite reports it.

use crate::{
    analysis::Zone,
    driver::{Proposal, Proposer, Sink, Tail, ZoneCtx},
    report::{Method, QpStats},
    spline::AnalysisSpline,
};
use polepatch_kinematics::{Machine, forward_jacobian};
use serde::Serialize;

/// How the patcher treats a zone: polepatch's method (see [`PatchOptions::axes`]) or one of
/// the peers (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// polepatch: branch re-selection, joint patch, verification (or the C-only method).
    #[default]
    Polepatch,
    /// C held at its entry value inside the cone.
    Freeze,
    /// C linear in s across the cone.
    Linearize,
    /// C a cubic blend across the cone.
    Smooth,
}

impl Strategy {
    /// Every strategy, polepatch first.
    pub const ALL: [Strategy; 4] = [
        Strategy::Polepatch,
        Strategy::Freeze,
        Strategy::Linearize,
        Strategy::Smooth,
    ];
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Polepatch => "polepatch",
            Strategy::Freeze => "freeze",
            Strategy::Linearize => "linearize",
            Strategy::Smooth => "smooth",
        }
    }
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

/// Rewrite the cone stretch `[e0, a, b, e1]` of `(p, c)` by a peer's rule (module docs),
/// unrounded: C by the rule from the program's values `c0` (and the slopes of its analysis
/// spline `c_spline` for [`Strategy::Smooth`]), P on C's meridian closest to `target`.
#[allow(clippy::too_many_arguments)]
pub fn apply_rule(
    strategy: Strategy,
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
        c[i] = match strategy {
            Strategy::Freeze | Strategy::Polepatch => ca,
            Strategy::Linearize => ca + t * (cb - ca),
            Strategy::Smooth => {
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

/// A peer strategy as a method of the driver (module docs): it proposes its rule's values
/// over the zone's cone stretch, and the driver writes them as they are (unverified).
#[derive(Debug, Clone, Copy)]
pub struct Peer(pub Strategy);

impl Proposer for Peer {
    fn propose(&mut self, ctx: &ZoneCtx<'_>, sink: &mut dyn Sink) {
        let Some(st) = cone_stretch(ctx.p, ctx.zone, ctx.opts.cone_deg) else {
            return;
        };
        let Ok(spline) = AnalysisSpline::new(ctx.s, ctx.c) else {
            return;
        };
        let (mut p, mut c) = (ctx.p.to_vec(), ctx.c.to_vec());
        apply_rule(
            self.0,
            ctx.machine,
            ctx.s,
            ctx.c,
            &spline,
            ctx.target,
            st,
            &mut p,
            &mut c,
        );
        let [_, a, b, _] = st;
        if a < ctx.lower || b > ctx.end {
            return;
        }
        sink.offer(Proposal {
            method: Method::Peer,
            first: a,
            last: b,
            p: p[a..=b].to_vec(),
            c: c[a..=b].to_vec(),
            tail: Tail::Keep,
            qp: QpStats::default(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::{PatchOptions, round_written};
    use crate::path::Path;
    use crate::report::Reason;
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

    /// FREEZE holds C inside the cone and keeps the tool axis on the right meridian;
    /// LINEARIZE and SMOOTH meet the program at the stretch's ends.
    #[test]
    fn peers_follow_their_rules() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        // A C swing 1° from the pole (C17-like): tool axis (sin 1°, sin τ, 1).
        let n = 121;
        let (mut s_mm, mut axes) = (Vec::new(), Vec::new());
        let mut prev: Option<f64> = None;
        for k in 0..n {
            let s = k as f64;
            let v = [
                1f64.to_radians().sin(),
                ((s - 60.0) * 0.4).to_radians().sin(),
                1.0,
            ];
            let sol = polepatch_kinematics::inverse(&m, v).unwrap()[0];
            let c = prev.map_or(sol.c_deg, |pc| {
                polepatch_kinematics::unwrap_near_deg(sol.c_deg, pc)
            });
            prev = Some(c);
            s_mm.push(s);
            axes.push([
                s,
                0.0,
                0.0,
                round_written(sol.p_deg, 3),
                round_written(c, 3),
            ]);
        }
        let path = Path {
            s_mm,
            axes,
            feed_mm_min: 2000.0,
        };
        let opts = |strategy| PatchOptions {
            strategy,
            ..PatchOptions::default()
        };
        let inside: Vec<usize> = (1..n - 1)
            .filter(|&i| path.axes[i][3].abs() <= 5.0)
            .collect();
        let (a, b) = (inside[0], *inside.last().unwrap());
        for strategy in [Strategy::Freeze, Strategy::Linearize, Strategy::Smooth] {
            let r = crate::patch_path(&path, &m, &opts(strategy)).unwrap();
            assert_eq!(r.zones[0].method, Method::Peer);
            assert!(matches!(
                r.zones[0].reason,
                Reason::Reached | Reason::NotFound
            ));
            assert_eq!(r.zones.len(), 1, "{strategy:?}");
            assert!(
                (a..=b).any(|i| r.c_changed[i]),
                "{strategy:?} rewrites inside the cone"
            );
            assert!(
                !r.c_changed[a - 1] && !r.c_changed[b + 1],
                "{strategy:?} stays inside"
            );
            if strategy == Strategy::Freeze {
                assert!((a..=b).all(|i| r.c_deg[i] == path.axes[a - 1][4]));
            }
            // Every rewritten point is on its meridian's closest point: the deviation is
            // at most the distance to the pole (1°) plus rounding.
            assert!(
                r.zones[0].max_deviation_deg <= 5.0 + 1e-3,
                "{:?}",
                r.zones[0]
            );
        }
    }
}
