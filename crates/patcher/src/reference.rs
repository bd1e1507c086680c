//! What a zone's patch is judged against (the quality suite, SPEC §6): the best found over
//! several methods, each with more effort than the patcher's. First the relaxation of
//! [`crate::proof`]: when it is infeasible no values reach feed and the zone's reference is
//! [`Reference::Unreachable`].
//!
//! # The best found (an upper bound on the optimum)
//! [`zone_reference`] is the smallest exact largest deviation over several methods, each
//! run with [`SolverSettings::reference`] — the patcher's settings with more effort:
//! - branch re-selection alone (deviation 0) when it reaches feed;
//! - the joint SCP ([`crate::joint`]) over the given points, with a margin of
//!   [`SolverSettings::reference_margin`] only, unrounded, from four starts: the values as
//!   they are; the tail after the zone's singular point on the other branch (only when the
//!   run's last point may move: the tail includes it); C held at its value at the singular
//!   point across the zone (ModuleWorks' FREEZE); C linear in s across the zone
//!   (LINEARIZE).
//!
//! It is not a lower bound: the problem is not convex, and a better patch may exist. The
//! suite reports `ours / reference`; below 1 means the patcher beat every reference start.

use crate::{
    analysis::{CONE_DEG, Zone},
    candidate::PatchFailure,
    joint::{JointProblem, solve_joint},
    limits::GeomLimits,
    options::PatchAxes,
    settings::SolverSettings,
    spline::AnalysisSpline,
    starts::{Rule, apply_rule, cone_stretch},
    tolerances::POLE_DEG,
    verify::{AxisChange, verify_change_with_core},
    zones::{core_margins, zone_core},
};
use polepatch_kinematics::{Axis, Machine, forward, unwrap_near_deg};

pub use crate::proof::reachable;

/// The reference of one zone.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// No values of the movable points reach feed on both rotary axes (the relaxation is
    /// infeasible: a proof).
    Unreachable,
    /// The smallest largest deviation found, degrees, and the method that found it.
    Best {
        /// Largest orientation change over the movable points, degrees.
        deviation_deg: f64,
        /// The method that found it.
        method: ReferenceMethod,
    },
    /// Every method failed numerically (reported, never hidden).
    Failed,
}

/// The method that found a [`Reference::Best`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReferenceMethod {
    /// Branch re-selection alone (no orientation change).
    Reselect,
    /// The joint solve started from the program's values.
    AsIs,
    /// The joint solve started from the other IK branch.
    OtherBranch,
    /// The joint solve started from FREEZE across the cone (a peer's rule).
    Freeze,
    /// The joint solve started from LINEARIZE across the cone (a peer's rule).
    Linearize,
}

impl ReferenceMethod {
    /// `reselect`, `as-is`, `other-branch`, `freeze` or `linearize`: its serde form.
    pub fn name(self) -> &'static str {
        match self {
            ReferenceMethod::Reselect => "reselect",
            ReferenceMethod::AsIs => "as-is",
            ReferenceMethod::OtherBranch => "other-branch",
            ReferenceMethod::Freeze => "freeze",
            ReferenceMethod::Linearize => "linearize",
        }
    }
}

impl std::fmt::Display for ReferenceMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The reference of `zone` on a path given by `s_mm`, `p_deg`, `c_deg` (the program's
/// values), with points `first..=last` movable (module docs). `max_decimals` is unused by
/// the relaxation (it allows any values) and kept for the callers.
///
/// The steps: the relaxation ([`reachable`]: unreachable is a proof); re-selection alone
/// ([`RefPath::reselect`]); the starts ([`RefPath::starts`]); the joint solve from each
/// ([`RefPath::best`]).
#[allow(clippy::too_many_arguments)]
pub fn zone_reference(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    zone: &Zone,
    first: usize,
    last: usize,
    machine: &Machine,
    feed_mm_min: f64,
    max_decimals: usize,
) -> Result<Reference, PatchFailure> {
    let _ = max_decimals;
    let n = s_mm.len();
    if first > last || last >= n || first == 0 {
        return Err(PatchFailure::TooShort);
    }
    let st = SolverSettings::reference();
    let core = zone_core(zone, n, st.core_margin_points);
    if !reachable(
        s_mm,
        p_deg,
        c_deg,
        first,
        last,
        core.clone(),
        machine,
        feed_mm_min,
        PatchAxes::Both,
        true,
    )? {
        return Ok(Reference::Unreachable);
    }
    let target: Vec<[f64; 3]> = p_deg
        .iter()
        .zip(c_deg)
        .map(|(p, c)| forward(machine, *p, *c))
        .collect();
    let rp = RefPath {
        s_mm,
        p_deg,
        c_deg,
        zone,
        first,
        last,
        machine,
        feed_mm_min,
        target,
        st,
        core,
    };
    if rp.reselect() {
        return Ok(Reference::Best {
            deviation_deg: 0.0,
            method: ReferenceMethod::Reselect,
        });
    }
    Ok(match rp.best(&rp.starts()) {
        Some((deviation_deg, method)) => Reference::Best {
            deviation_deg,
            method,
        },
        None => Reference::Failed,
    })
}

/// One zone's reference problem (the arguments of [`zone_reference`]), the program's tool
/// axes, the reference's settings and the zone's core.
struct RefPath<'a> {
    s_mm: &'a [f64],
    p_deg: &'a [f64],
    c_deg: &'a [f64],
    zone: &'a Zone,
    first: usize,
    last: usize,
    machine: &'a Machine,
    feed_mm_min: f64,
    target: Vec<[f64; 3]>,
    st: SolverSettings,
    core: std::ops::Range<usize>,
}

/// A start of the joint solve: the method it stands for and the whole path's values.
type RefStart = (ReferenceMethod, Vec<f64>, Vec<f64>);

impl RefPath<'_> {
    /// Whether `(p, c)`, changed on `changed`, passes the verification against the
    /// program's values.
    fn passes(&self, p: &[f64], c: &[f64], changed: (usize, usize)) -> bool {
        let ch = [
            AxisChange {
                axis: Axis::Primary,
                before: self.p_deg,
                after: p,
            },
            AxisChange {
                axis: Axis::C,
                before: self.c_deg,
                after: c,
            },
        ];
        verify_change_with_core(
            self.s_mm,
            &ch,
            changed,
            (self.zone.first, self.zone.last),
            core_margins(self.zone, self.st.core_margin_points),
            self.machine,
            self.feed_mm_min / 60.0,
        )
        .passes()
    }

    /// The program's values with the points after `after` on the other branch,
    /// continuous with the last point off the pole (on it C does not orient the tool).
    fn flipped(&self, after: usize) -> (Vec<f64>, Vec<f64>) {
        let (p_deg, c_deg) = (self.p_deg, self.c_deg);
        let n = self.s_mm.len();
        let (mut p, mut c) = (p_deg.to_vec(), c_deg.to_vec());
        if after + 1 < n {
            // Continuous with the last point off the pole (on it C does not orient the tool).
            let r = (0..=after)
                .rev()
                .find(|&i| p_deg[i].abs() > POLE_DEG)
                .unwrap_or(after);
            let shift = unwrap_near_deg(c_deg[after + 1] + 180.0, c_deg[r]) - c_deg[after + 1];
            for i in after + 1..n {
                p[i] = -p_deg[i];
                c[i] = c_deg[i] + shift;
            }
        }
        (p, c)
    }

    /// Every primary value within the machine's range.
    fn in_range(&self, p: &[f64]) -> bool {
        let (lo, hi) = self.machine.primary_range_deg;
        p.iter().all(|v| (lo..=hi).contains(v))
    }

    /// The points after the range keep their values unless the last point may move: then
    /// they may go to the other branch as a block.
    fn tail_free(&self) -> bool {
        self.last == self.s_mm.len() - 1
    }

    /// Re-selection alone: the flip point of a domain-rule program, if any, and the other
    /// branch after it reaches feed.
    fn reselect(&self) -> bool {
        let (zone, p_deg) = (self.zone, self.p_deg);
        if let Some(f) = (zone.first..zone.last)
            .filter(|_| self.tail_free())
            .find(|&i| {
                p_deg[i] != 0.0 && p_deg[i + 1] != 0.0 && p_deg[i].signum() != p_deg[i + 1].signum()
            })
        {
            let (p, c) = self.flipped(f);
            return self.in_range(&p) && self.passes(&p, &c, (f + 1, f + 1));
        }
        false
    }

    /// The starts (module docs): as-is; the other branch after the singular point (the
    /// least |P| of the zone); FREEZE and LINEARIZE across the cone stretch (the peers'
    /// rules, crate::starts).
    fn starts(&self) -> Vec<RefStart> {
        let (zone, p_deg, c_deg) = (self.zone, self.p_deg, self.c_deg);
        // The singular point and the other branch after it.
        let k = (zone.first..=zone.last)
            .min_by(|&a, &b| p_deg[a].abs().total_cmp(&p_deg[b].abs()))
            .unwrap_or(zone.singular);
        let mut starts: Vec<RefStart> =
            vec![(ReferenceMethod::AsIs, p_deg.to_vec(), c_deg.to_vec())];
        let (op, oc) = self.flipped(k);
        if self.tail_free() && self.in_range(&op) {
            starts.push((ReferenceMethod::OtherBranch, op, oc));
        }
        // FREEZE and LINEARIZE across the cone stretch (the peers' rules, crate::starts).
        let cone = CONE_DEG.max(zone.min_abs_primary_deg);
        if let (Some(stretch), Ok(spline)) = (
            cone_stretch(p_deg, zone, cone),
            AnalysisSpline::new(self.s_mm, c_deg),
        ) {
            for (name, rule) in [
                (ReferenceMethod::Freeze, Rule::Freeze),
                (ReferenceMethod::Linearize, Rule::Linearize),
            ] {
                let (mut rp, mut rc) = (p_deg.to_vec(), c_deg.to_vec());
                apply_rule(
                    rule,
                    self.machine,
                    self.s_mm,
                    c_deg,
                    &spline,
                    &self.target,
                    stretch,
                    &mut rp,
                    &mut rc,
                );
                starts.push((name, rp, rc));
            }
        }
        starts
    }

    /// The joint solve from every start; the smallest largest deviation of a solution
    /// that passes, and its start's method.
    fn best(&self, starts: &[RefStart]) -> Option<(f64, ReferenceMethod)> {
        let (s_mm, p_deg, c_deg, zone) = (self.s_mm, self.p_deg, self.c_deg, self.zone);
        let (first, last, machine, feed_mm_min) =
            (self.first, self.last, self.machine, self.feed_mm_min);
        let st = &self.st;
        let n = s_mm.len();
        let mut best: Option<(f64, ReferenceMethod)> = None;
        for (name, sp, sc) in starts {
            let pr = JointProblem {
                s_mm,
                p_deg: sp,
                c_deg: sc,
                target: &self.target,
                first,
                last,
                lim_p: GeomLimits::of(machine, Axis::Primary, feed_mm_min, st.reference_margin),
                lim_c: GeomLimits::of(machine, Axis::C, feed_mm_min, st.reference_margin),
                feed_mm_min,
                machine,
                core: self.core.clone(),
                round_p_deg: 0.0,
                round_c_deg: 0.0,
                reference: Some((p_deg, c_deg)),
                verified: (p_deg, c_deg),
                pole_spans: if zone.cut_before { zone.first } else { 0 }..if zone.cut_after {
                    zone.last
                } else {
                    n
                },
                cap_deg: None,
                point_cap_deg: None,
                warm: false,
                max_solves: st.scp_max_solves,
                ipm_start: None,
                memo: None,
                settings: st,
            };
            let Ok(sol) = solve_joint(&pr) else { continue };
            let (mut p, mut c) = (sp.clone(), sc.clone());
            p[first..=last].copy_from_slice(&sol.p_deg);
            c[first..=last].copy_from_slice(&sol.c_deg);
            // Starts other than "as-is" change points outside the range only as a block that
            // keeps the tool axes; the deviation counts the range.
            if self.passes(&p, &c, (first, last))
                && best.is_none_or(|(d, _)| sol.max_deviation_deg < d)
            {
                best = Some((sol.max_deviation_deg, *name));
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::PatchOptions;
    use crate::path::Path;
    use crate::testutil::{machine, planted, sing_path};

    fn pc(path: &Path) -> (Vec<f64>, Vec<f64>) {
        (
            path.axes.iter().map(|q| q[3]).collect(),
            path.axes.iter().map(|q| q[4]).collect(),
        )
    }

    /// The reference on SING: the best found is at most what the patcher writes (it is
    /// the same method with more effort) to within the patcher's rounding, and a flip that
    /// re-selection fixes has reference 0.
    #[test]
    fn references_of_sing_and_a_reselectable_flip() {
        for name in ["mikron-ucp710", "mikron-hsm600"] {
            let m = machine(name);
            let path = sing_path();
            let (p, c) = pc(&path);
            let n = p.len();
            let a = crate::analyze_path(&path, &m, &Default::default()).unwrap();
            let r =
                zone_reference(&path.s_mm, &p, &c, &a.zones[0], 1, n - 1, &m, 2000.0, 6).unwrap();
            let ours = crate::patch_path(&path, &m, &PatchOptions::default())
                .unwrap()
                .zones[0]
                .max_deviation_deg;
            match r {
                Reference::Best { deviation_deg, .. } => {
                    assert!(
                        deviation_deg <= ours * 1.1 + 1e-3,
                        "{name}: ref {deviation_deg} ours {ours}"
                    );
                    assert!(
                        ours <= 1.25 * deviation_deg,
                        "{name}: ours {ours} ref {deviation_deg}"
                    );
                }
                other => panic!("{name}: {other:?}"),
            }
        }
        let m = machine("mikron-ucp710");
        let flip = planted(241, 0.5, 4.0, true, 1000.0);
        let (p, c) = pc(&flip);
        let a = crate::analyze_path(&flip, &m, &Default::default()).unwrap();
        let r = zone_reference(&flip.s_mm, &p, &c, &a.zones[0], 1, 240, &m, 1000.0, 6).unwrap();
        assert_eq!(
            r,
            Reference::Best {
                deviation_deg: 0.0,
                method: ReferenceMethod::Reselect
            }
        );
    }
}
