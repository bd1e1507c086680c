//! The pole strategies that CAM posts and controllers document, as peers for the quality
//! suite (issue 8 §5): each rewrites the rotary values inside the singular cone by a fixed
//! rule ([`crate::starts`]: FREEZE, LINEARIZE, SMOOTH across the cone stretch, P on C's
//! meridian), and `polepatch bench --strategy …` scores it with the same Equation-6
//! analysis as polepatch's own patch. Values are written with the file's decimals, as a
//! post would. Nothing is verified and nothing is kept back: a peer's result is what it
//! is, and the suite reports it.

use crate::{
    protocol::{Proposal, Proposer, Sink, Tail, ZoneCtx},
    report::{Method, QpStats},
    spline::AnalysisSpline,
    starts::{Rule, apply_rule, cone_stretch},
};

pub use crate::options::Strategy;

/// The cone rule of a peer strategy ([`Strategy::Polepatch`] has none: FREEZE's, as the
/// peers' rules always gave it).
pub fn rule_of(strategy: Strategy) -> Rule {
    match strategy {
        Strategy::Freeze | Strategy::Polepatch => Rule::Freeze,
        Strategy::Linearize => Rule::Linearize,
        Strategy::Smooth => Rule::Smooth,
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
            rule_of(self.0),
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
    use polepatch_kinematics::Machine;

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
