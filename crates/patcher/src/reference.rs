//! The reference a zone's joint patch is judged against (the quality suite, SPEC §6):
//! the best orientation change *found* when both rotary axes may change, and a proof of
//! unreachability when there is none.
//!
//! # Unreachable (a proof)
//! With the orientation left free, reaching feed on both rotary axes is a convex
//! feasibility problem: the Hermite rows of the analysis splines of P and C
//! ([`crate::hermite`]) with Equation 6's bounds (no margin, convex-hull form) on every
//! span between movable points, "not worse than before" on the spans that touch a fixed
//! point, and the machine's primary range, in the values of the movable points. If that
//! LP is infeasible, no values of the movable points whatsoever reach feed without making
//! something worse: the zone is [`Reference::Unreachable`], whatever the patcher does.
//! Every bound leaves the room rounding to the most decimals allowed can take (a zone that
//! reaches feed only with unrounded values, exactly at a limit, cannot be written).
//!
//! # The best found (an upper bound on the optimum)
//! Otherwise the reference is the smallest exact largest deviation over several methods,
//! each run with more effort than the patcher spends by default:
//! - branch re-selection alone (deviation 0) when it reaches feed;
//! - the joint SCP ([`crate::joint`]) over the whole movable territory, with a margin of
//!   [`REFERENCE_MARGIN`] only, unrounded, from four starts: the values as they are; the tail after the zone's
//!   singular point on the other branch; C held at its value at the singular point across
//!   the zone (ModuleWorks' FREEZE); C linear in s across the zone (LINEARIZE).
//!
//! It is not a lower bound: the problem is not convex, and a better patch may exist. The
//! suite reports `ours / reference`; below 1 means the patcher beat every reference start.

use crate::peers::Strategy;
use crate::{
    analysis::Zone,
    candidate::PatchFailure,
    hermite::{Hermite, JOINT_WINDOW_POINTS},
    joint::{JointProblem, solve_joint},
    limits::GeomLimits,
    qp::QpBuilder,
    report::QpStats,
    verify::{AxisChange, verify_change_with_core},
};
use polepatch_kinematics::{Axis, Machine, forward, unwrap_near_deg};

/// Most solves of each reference start (the patcher allows
/// [`crate::joint::SCP_MAX_SOLVES`]).
pub const REFERENCE_MAX_SOLVES: usize = 24;

/// A reference start stops when a step improves its largest deviation by less than this
/// fraction (the patcher: [`crate::joint::SCP_REL_TOL`]).
pub const REFERENCE_REL_TOL: f64 = 1e-3;

/// Margin of the reference solves on the limits (the patcher's default is 0.02): just
/// enough that the solution passes the verification's round-off tolerances, so the
/// reference is what the limits themselves allow.
pub const REFERENCE_MARGIN: f64 = 1e-3;

/// The reference of one zone.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// No values of the movable points reach feed on both rotary axes (the LP is
    /// infeasible: a proof).
    Unreachable,
    /// The smallest largest deviation found, degrees, and the method that found it.
    Best {
        /// Largest orientation change over the movable points, degrees.
        deviation_deg: f64,
        /// `reselect`, `as-is`, `other-branch`, `freeze` or `linearize`.
        method: &'static str,
    },
    /// Every method failed numerically (reported, never hidden).
    Failed,
}

/// Whether some values of points `first..=last` make both rotary axes meet Equation 6 on
/// every constrained span (the convex feasibility LP of the module docs). `p_deg`, `c_deg`
/// are the current values of the whole path.
/// The spans a zone's patch must bring to feed: the zone's, ± the verification's core
/// margin (as `crate::verify` checks them).
pub fn zone_core(zone: &Zone, n: usize) -> std::ops::Range<usize> {
    let m = crate::verify::CORE_MARGIN_POINTS;
    zone.first.saturating_sub(m)..(zone.last + m).min(n - 1)
}

/// Whether some values of points `first..=last`, written with `max_decimals` decimals,
/// bring the spans `core` to feed on both rotary axes while no other span of the window
/// gets worse (the LP of the module docs; every bound leaves the room rounding to that many
/// decimals can take, [`Hermite::rounding_room`], and no other margin).
#[allow(clippy::too_many_arguments)]
pub fn reachable(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    first: usize,
    last: usize,
    core: std::ops::Range<usize>,
    machine: &Machine,
    feed_mm_min: f64,
    max_decimals: usize,
) -> Result<bool, PatchFailure> {
    let hp = Hermite::with_offset(s_mm, p_deg, first, last, JOINT_WINDOW_POINTS, 0)?;
    let hc = Hermite::with_offset(s_mm, c_deg, first, last, JOINT_WINDOW_POINTS, hp.vars())?;
    let nv = hp.vars() + hc.vars();
    let mut qp = QpBuilder::new(nv);
    hp.add_equalities(&mut qp);
    hc.add_equalities(&mut qp);
    let mut current = vec![0.0; nv];
    hp.write_current(&mut current)?;
    hc.write_current(&mut current)?;
    let lim = |axis| GeomLimits::of(machine, axis, feed_mm_min, 0.0);
    let eps = 0.5 * 10f64.powi(-(max_decimals as i32));
    let (rp, rc) = (hp.rounding_room(eps)?, hc.rounding_room(eps)?);
    hp.push_limits(&mut qp, &lim(Axis::Primary), &current, &rp, core.clone());
    hc.push_limits(&mut qp, &lim(Axis::C), &current, &rc, core);
    let (lo, hi) = machine.primary_range_deg;
    for (i, p) in p_deg.iter().enumerate().take(last + 1).skip(first) {
        let v = hp.delta_var(i);
        qp.add_le(&[(v, 1.0)], hi - p);
        qp.add_le(&[(v, -1.0)], p - lo);
    }
    let mut st = QpStats::default();
    match qp.solve(&mut st) {
        Ok(_) => Ok(true),
        Err(s) if s.is_infeasible() => Ok(false),
        Err(_) => Err(PatchFailure::Solver(st)),
    }
}

/// The reference of `zone` on a path given by `s_mm`, `p_deg`, `c_deg` (the program's
/// values), with points `first..=last` movable (module docs). `max_decimals` the most decimals that may be written (the unreachability
/// proof leaves room for their rounding).
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
    let n = s_mm.len();
    if first > last || last >= n || first == 0 {
        return Err(PatchFailure::TooShort);
    }
    let core = zone_core(zone, n);
    if !reachable(
        s_mm,
        p_deg,
        c_deg,
        first,
        last,
        core,
        machine,
        feed_mm_min,
        max_decimals,
    )? {
        return Ok(Reference::Unreachable);
    }
    let target: Vec<[f64; 3]> = p_deg
        .iter()
        .zip(c_deg)
        .map(|(p, c)| forward(machine, *p, *c))
        .collect();
    let passes = |p: &[f64], c: &[f64], changed: (usize, usize)| {
        let ch = [
            AxisChange {
                axis: Axis::Primary,
                before: p_deg,
                after: p,
            },
            AxisChange {
                axis: Axis::C,
                before: c_deg,
                after: c,
            },
        ];
        verify_change_with_core(
            s_mm,
            &ch,
            changed,
            (zone.first, zone.last),
            machine,
            feed_mm_min / 60.0,
        )
        .passes()
    };
    // The singular point and the other branch after it.
    let k = (zone.first..=zone.last)
        .min_by(|&a, &b| p_deg[a].abs().total_cmp(&p_deg[b].abs()))
        .unwrap_or(zone.singular);
    let flipped = |after: usize| -> (Vec<f64>, Vec<f64>) {
        let (mut p, mut c) = (p_deg.to_vec(), c_deg.to_vec());
        if after + 1 < n {
            // Continuous with the last point off the pole (on it C does not orient the tool).
            let r = (0..=after)
                .rev()
                .find(|&i| p_deg[i].abs() > crate::both::POLE_DEG)
                .unwrap_or(after);
            let shift = unwrap_near_deg(c_deg[after + 1] + 180.0, c_deg[r]) - c_deg[after + 1];
            for i in after + 1..n {
                p[i] = -p_deg[i];
                c[i] = c_deg[i] + shift;
            }
        }
        (p, c)
    };
    let (lo, hi) = machine.primary_range_deg;
    let in_range = |p: &[f64]| p.iter().all(|v| (lo..=hi).contains(v));
    // Re-selection alone: the flip point of a domain-rule program, if any.
    if let Some(f) = (zone.first..zone.last).find(|&i| {
        p_deg[i] != 0.0 && p_deg[i + 1] != 0.0 && p_deg[i].signum() != p_deg[i + 1].signum()
    }) {
        let (p, c) = flipped(f);
        if in_range(&p) && passes(&p, &c, (f + 1, f + 1)) {
            return Ok(Reference::Best {
                deviation_deg: 0.0,
                method: "reselect",
            });
        }
    }
    let mut starts: Vec<(&'static str, Vec<f64>, Vec<f64>)> =
        vec![("as-is", p_deg.to_vec(), c_deg.to_vec())];
    let (op, oc) = flipped(k);
    if in_range(&op) {
        starts.push(("other-branch", op, oc));
    }
    // FREEZE and LINEARIZE across the cone stretch (the peers' rules, crate::peers).
    let cone = 5.0f64.max(zone.min_abs_primary_deg);
    if let (Some(st), Ok(spline)) = (
        crate::peers::cone_stretch(p_deg, zone, cone),
        crate::spline::AnalysisSpline::new(s_mm, c_deg),
    ) {
        for (name, rule) in [
            ("freeze", Strategy::Freeze),
            ("linearize", Strategy::Linearize),
        ] {
            let (mut rp, mut rc) = (p_deg.to_vec(), c_deg.to_vec());
            crate::peers::apply_rule(
                rule, machine, s_mm, c_deg, &spline, &target, st, &mut rp, &mut rc,
            );
            starts.push((name, rp, rc));
        }
    }
    let mut best: Option<(f64, &'static str)> = None;
    for (name, sp, sc) in &starts {
        let pr = JointProblem {
            s_mm,
            p_deg: sp,
            c_deg: sc,
            target: &target,
            first,
            last,
            lim_p: GeomLimits::of(machine, Axis::Primary, feed_mm_min, REFERENCE_MARGIN),
            lim_c: GeomLimits::of(machine, Axis::C, feed_mm_min, REFERENCE_MARGIN),
            machine,
            max_deviation_deg: None,
            max_solves: REFERENCE_MAX_SOLVES,
            rel_tol: REFERENCE_REL_TOL,
            core: zone_core(zone, n),
            round_p_deg: 0.0,
            round_c_deg: 0.0,
            warm: false,
        };
        let Ok(sol) = solve_joint(&pr) else { continue };
        let (mut p, mut c) = (sp.clone(), sc.clone());
        p[first..=last].copy_from_slice(&sol.p_deg);
        c[first..=last].copy_from_slice(&sol.c_deg);
        // Starts other than "as-is" change points outside the range only as a block that
        // keeps the tool axes; the deviation counts the range.
        if passes(&p, &c, (first, last)) && best.is_none_or(|(d, _)| sol.max_deviation_deg < d) {
            best = Some((sol.max_deviation_deg, name));
        }
    }
    Ok(match best {
        Some((deviation_deg, method)) => Reference::Best {
            deviation_deg,
            method,
        },
        None => Reference::Failed,
    })
}
