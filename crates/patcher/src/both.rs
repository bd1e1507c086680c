//! The default method: both rotary axes may change, and both must reach feed (issue 8).
//!
//! For each singular zone, in path order, on the values already updated by the zones
//! before it:
//!
//! 1. **Branch re-selection.** When the program switches IK branch inside the zone (the
//!    primary axis changes sign with C jumping, as a domain-rule post writes it: G16
//!    Table 1), the points after the switch are put on the other branch as a block,
//!    `(P, C) → (−P, C ± 180°)` — the same tool axes — to the end of the run, within the
//!    machine's primary range. The orientation does not change at all; when Equation 6
//!    then holds on both rotary axes the zone is done, with deviation 0.
//! 2. **Joint patch** ([`crate::joint`]): new P and C at the points of a range around the
//!    zone, from several starts (the SCP is local): the values as they are; the same with
//!    the tail after the singular point on the other branch (the "through the pole" start:
//!    near the pole the best patch often lets P pass through zero at almost constant C);
//!    and the peers' FREEZE and LINEARIZE rules across the cone ([`crate::peers`]). The range widens by
//!    levels ([`WIDENING_POINTS`], then the whole run) while that lowers the largest
//!    deviation; at each level a feasibility LP ([`crate::reference::reachable`]) first
//!    tells whether any values of the range can reach feed, and the SCP runs only if so.
//! 3. Every candidate is rounded as it will be written (the file's decimals, then one more
//!    at a time up to `max_decimals` when rounding alone breaks it) and verified
//!    ([`crate::verify::verify_change_with_core`]): both rotary axes reach feed over the
//!    zone (± `CORE_MARGIN_POINTS`), and no sample of either gets worse anywhere. The passing
//!    candidate with the smallest exact largest deviation (the angle between the old and
//!    new tool axes, [`polepatch_kinematics::angle_between_deg`]) is kept; when none passes,
//!    the best improvement, else nothing. With no candidate passing at the configured
//!    margin, the margin is lowered ([`MARGIN_LADDER`]) before giving up.
//!
//! The run's first point never moves (it belongs to the block before the run).

use crate::{
    analysis::{AnalysisOptions, RATIO_TOL, Zone, analyze_path, validate},
    joint::{JointProblem, JointSolution, solve_joint},
    limits::GeomLimits,
    options::{PatchOptions, round_written},
    patch::{PatchResult, merge_zones, zone_figures},
    path::{Path, PathError},
    peers::Strategy,
    qp::add_stats,
    report::{Method, Outcome, QpStats, ZoneReport},
    verify::{AxisChange, VERIFY_MARGIN_POINTS, Verdict, verify_change_with_core},
};
use polepatch_kinematics::{Axis, Machine, angle_between_deg, forward, wrap_deg};

/// Factors applied to `PatchOptions::margin`, in order, when no candidate passes
/// verification: the configured margin, a quarter of it, none.
pub const MARGIN_LADDER: [f64; 3] = [1.0, 0.25, 0.0];

/// Points added on each side of the zone at the successive widening levels of the joint
/// patch (clipped to the run); after the last, the whole run is tried.
pub const WIDENING_POINTS: [usize; 5] = [4, 10, 22, 46, 94];

/// |P| below which a point counts as on the pole when C's continuity is judged, degrees
/// (C does not orient the tool there).
pub const POLE_DEG: f64 = 1e-6;

/// Solves each start gets when several are screened at a level; the best then goes on
/// (warm) for the rest of [`crate::joint::SCP_MAX_SOLVES`].
pub const SCREEN_SOLVES: usize = 2;

/// Screened starts whose largest deviation is within this factor of the best screened go
/// on to the full SCP.
pub const SCREEN_KEEP: f64 = 2.0;

/// A level after the first passing one that lowers the best largest deviation by less than
/// this fraction of it ends the widening.
pub const DEVIATION_IMPROVEMENT_MIN: f64 = 0.05;

/// A candidate: new values for `first..=last`, and optionally the points after `last`
/// re-selected onto the other branch as a block.
#[derive(Debug, Clone)]
struct Candidate {
    method: Method,
    first: usize,
    last: usize,
    /// New primary values for `first..=last` (unrounded), degrees.
    p: Vec<f64>,
    /// New C values for `first..=last` (unrounded), degrees.
    c: Vec<f64>,
    /// Points after `last` become `(−P, C + shift)` (shift ±180°).
    tail_shift_deg: Option<f64>,
}

/// A start of the joint patch: primary and C values of the whole path (the same tool axes
/// as the program's outside the zone), and — for the start on the other branch — the
/// point after which the tail is re-selected and C's shift there.
type Start = (Vec<f64>, Vec<f64>, Option<(usize, f64)>);

/// A candidate after rounding and verification.
#[derive(Debug, Clone)]
struct Checked {
    cand: Candidate,
    /// Decimals written for P and C.
    decimals: (usize, usize),
    verdict: Verdict,
    /// Exact largest orientation change over `first..=last`, degrees.
    deviation_deg: f64,
}

/// What every zone of a path shares.
struct Ctx<'a> {
    s: &'a [f64],
    /// The program's tool axes (targets of every change).
    target: Vec<[f64; 3]>,
    machine: &'a Machine,
    opts: &'a PatchOptions,
    feed_mm_min: f64,
}

/// Patch every zone of `path` with both rotary axes (module docs).
pub(crate) fn patch_both(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<PatchResult, PathError> {
    validate(path)?;
    let n = path.s_mm.len();
    let pi = Axis::Primary.index();
    let ci = Axis::C.index();
    if !path.axes.iter().any(|q| q[pi].abs() <= opts.cone_deg) {
        return Ok(PatchResult::unchanged(path, opts));
    }
    let aopts = AnalysisOptions {
        cone_deg: opts.cone_deg,
        tcy_s: opts.tcy_s,
        keep_samples: false,
    };
    let analysis = analyze_path(path, machine, &aopts)?;
    if analysis.zones.is_empty() {
        return Ok(PatchResult::unchanged(path, opts));
    }
    let p0: Vec<f64> = path.axes.iter().map(|q| q[pi]).collect();
    let c0: Vec<f64> = path.axes.iter().map(|q| q[ci]).collect();
    let ctx = Ctx {
        s: &path.s_mm,
        target: p0
            .iter()
            .zip(&c0)
            .map(|(p, c)| forward(machine, *p, *c))
            .collect(),
        machine,
        opts,
        feed_mm_min: path.feed_mm_min,
    };
    let (mut cur_p, mut cur_c) = (p0.clone(), c0.clone());
    let mut decimals = (opts.p_decimals, opts.c_decimals);
    let mut lower = 1;
    let mut done = Vec::new();
    for zone in merge_zones(&analysis.zones) {
        let mut stats = QpStats::default();
        let mut found: Option<(Checked, bool)> = None;
        for factor in MARGIN_LADDER {
            match ctx.patch_zone(
                &cur_p,
                &cur_c,
                &zone,
                lower,
                opts.margin * factor,
                &mut stats,
            ) {
                Some((c, true)) => {
                    found = Some((c, true));
                    break;
                }
                Some((c, false))
                    if found.as_ref().is_none_or(|(b, _)| {
                        c.verdict.core_min_after > b.verdict.core_min_after + RATIO_TOL
                    }) =>
                {
                    found = Some((c, false));
                }
                _ => {}
            }
            if opts.margin == 0.0 {
                break;
            }
        }
        let outcome = match &found {
            Some((_, true)) => Outcome::Reached,
            Some((_, false)) => Outcome::Improved,
            None => Outcome::Unchanged,
        };
        let kept = found.map(|(c, _)| c);
        if let Some(k) = &kept {
            let (p, c) = ctx.materialize(&cur_p, &cur_c, &k.cand, 0, n - 1, Some(k.decimals));
            (cur_p, cur_c) = (p, c);
            decimals = (decimals.0.max(k.decimals.0), decimals.1.max(k.decimals.1));
            lower = k.cand.last + 1;
        } else {
            lower = lower.max(zone.last + 1);
        }
        done.push((zone, kept, outcome, stats));
    }

    let mut after_path = path.clone();
    for (q, (p, c)) in after_path.axes.iter_mut().zip(cur_p.iter().zip(&cur_c)) {
        q[pi] = *p;
        q[ci] = *c;
    }
    let mut reports = Vec::with_capacity(done.len());
    for (zone, kept, outcome, qp) in done {
        let (first, last) = match &kept {
            Some(k) => (zone.first.min(k.cand.first), zone.last.max(k.cand.last)),
            None => (zone.first, zone.last),
        };
        // Figures over the stretch that must reach feed (the zone's core, as verified);
        // around it the patch may only not get worse.
        let core = crate::reference::zone_core(&zone, n);
        let (fa, fb) = (core.start, core.end);
        let before = zone_figures(path, machine, &aopts, fa, fb)?;
        let after = match &kept {
            Some(_) => zone_figures(&after_path, machine, &aopts, fa, fb)?,
            None => before,
        };
        let range = first..=last;
        let max_dev = range
            .clone()
            .map(|i| angle_between_deg(ctx.target[i], forward(machine, cur_p[i], cur_c[i])))
            .fold(0.0, f64::max);
        let modified = |v: &[f64], v0: &[f64]| range.clone().filter(|&i| v[i] != v0[i]).count();
        reports.push(ZoneReport {
            first,
            last,
            kind: zone.kind,
            min_abs_primary_deg: zone.min_abs_primary_deg,
            before,
            after,
            ideal_time_s: (path.s_mm[fb] - path.s_mm[fa]) / (path.feed_mm_min / 60.0),
            max_deviation_deg: max_dev,
            points_modified: range
                .clone()
                .filter(|&i| cur_p[i] != p0[i] || cur_c[i] != c0[i])
                .count(),
            primary_points_modified: modified(&cur_p, &p0),
            reselected_points: kept
                .as_ref()
                .filter(|k| k.cand.tail_shift_deg.is_some())
                .map_or(0, |k| n - 1 - k.cand.last),
            patch_length_mm: kept
                .as_ref()
                .map_or(0.0, |k| path.s_mm[k.cand.last] - path.s_mm[k.cand.first]),
            outcome,
            method: kept.as_ref().map_or(Method::None, |k| k.cand.method),
            qp,
            decimals: kept.as_ref().map_or(opts.c_decimals, |k| k.decimals.1),
            p_decimals: kept.as_ref().map_or(opts.p_decimals, |k| k.decimals.0),
            c_offset_deg: 0.0,
        });
    }
    let p_changed: Vec<bool> = cur_p.iter().zip(&p0).map(|(a, b)| a != b).collect();
    let c_changed: Vec<bool> = cur_c.iter().zip(&c0).map(|(a, b)| a != b).collect();
    Ok(PatchResult {
        p_deg: cur_p,
        p_changed,
        p_decimals: decimals.0,
        c_deg: cur_c,
        c_changed,
        c_decimals: decimals.1,
        zones: reports,
    })
}

/// The index after which the program switches branch inside the zone: the last point
/// before the primary axis changes sign (points exactly at 0 skipped), nearest to the
/// zone's singular point.
fn branch_switch(p: &[f64], zone: &Zone) -> Option<usize> {
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
fn least_primary(p: &[f64], zone: &Zone) -> usize {
    (zone.first..=zone.last)
        .min_by(|&a, &b| p[a].abs().total_cmp(&p[b].abs()))
        .unwrap_or(zone.singular)
}

impl Ctx<'_> {
    /// The ±180° that keeps C continuous when the points after `k` move to the other
    /// branch, or `None` when a re-selected primary value would leave the machine's range.
    fn tail_shift(&self, p: &[f64], c: &[f64], k: usize) -> Option<f64> {
        let n = p.len();
        if k + 1 >= n || self.opts.keep_last_point {
            return None;
        }
        let (lo, hi) = self.machine.primary_range_deg;
        if p[k + 1..].iter().any(|&v| !(lo..=hi).contains(&-v)) {
            return None;
        }
        // C after the switch, moved by ±180°, nearest to C before it — before it on a
        // point off the pole (on the pole C does not orient the tool and may be anything).
        let r = (0..=k).rev().find(|&i| p[i].abs() > POLE_DEG).unwrap_or(k);
        let d = wrap_deg(c[k + 1] + 180.0 - c[r]) - (c[k + 1] + 180.0 - c[r]);
        let shift = 180.0 + d;
        let shift = if shift > 180.0 + 1e-9 {
            shift - 360.0
        } else {
            shift
        };
        if let Some((c_lo, c_hi)) = self.machine.c_range_deg
            && c[k + 1..]
                .iter()
                .any(|&v| !(c_lo..=c_hi).contains(&(v + shift)))
        {
            return None;
        }
        Some(shift)
    }

    /// The values of a candidate applied to `(p, c)` on the window `lo..=hi`, rounded as
    /// written with `decimals` (P, C) where they change (`None`: unrounded).
    fn materialize(
        &self,
        p: &[f64],
        c: &[f64],
        cand: &Candidate,
        lo: usize,
        hi: usize,
        decimals: Option<(usize, usize)>,
    ) -> (Vec<f64>, Vec<f64>) {
        let rp = |v: f64| decimals.map_or(v, |d| round_written(v, d.0));
        let rc = |v: f64| decimals.map_or(v, |d| round_written(v, d.1));
        let mut wp = p[lo..=hi].to_vec();
        let mut wc = c[lo..=hi].to_vec();
        for i in lo..=hi {
            if (cand.first..=cand.last).contains(&i) {
                let k = i - cand.first;
                wp[i - lo] = rp(cand.p[k]);
                wc[i - lo] = rc(cand.c[k]);
            } else if i > cand.last
                && let Some(shift) = cand.tail_shift_deg
            {
                wp[i - lo] = rp(-p[i]);
                wc[i - lo] = rc(c[i] + shift);
            }
        }
        (wp, wc)
    }

    /// Round and verify a candidate against the current values; the checked candidate and
    /// whether it passes.
    fn check(
        &self,
        p: &[f64],
        c: &[f64],
        cand: &Candidate,
        zone: &Zone,
    ) -> Option<(Checked, bool)> {
        let n = self.s.len();
        if cand.p.iter().chain(&cand.c).any(|v| !v.is_finite()) {
            return None;
        }
        // The block after `last` keeps every derivative's size beyond the window.
        let changed = (
            cand.first,
            cand.last + usize::from(cand.tail_shift_deg.is_some()),
        );
        let changed = (changed.0, changed.1.min(n - 1));
        let lo = changed
            .0
            .min(zone.first)
            .saturating_sub(VERIFY_MARGIN_POINTS + 1);
        let hi = (changed.1.max(zone.last) + VERIFY_MARGIN_POINTS + 1).min(n - 1);
        let (bp, bc) = (&p[lo..=hi], &c[lo..=hi]);
        let verify = |wp: &[f64], wc: &[f64]| {
            let ch = [
                AxisChange {
                    axis: Axis::Primary,
                    before: bp,
                    after: wp,
                },
                AxisChange {
                    axis: Axis::C,
                    before: bc,
                    after: wc,
                },
            ];
            verify_change_with_core(
                &self.s[lo..=hi],
                &ch,
                (changed.0 - lo, changed.1 - lo),
                (zone.first.max(lo) - lo, zone.last.min(hi) - lo),
                self.machine,
                self.feed_mm_min / 60.0,
            )
        };
        let (pd0, cd0) = (self.opts.p_decimals, self.opts.c_decimals);
        let max_d = self.opts.max_decimals.max(pd0).max(cd0);
        let mut last: Option<Checked> = None;
        for extra in 0..=max_d - pd0.min(cd0) {
            let d = ((pd0 + extra).min(max_d), (cd0 + extra).min(max_d));
            if last.as_ref().is_some_and(|l| l.decimals == d) {
                break;
            }
            let (wp, wc) = self.materialize(p, c, cand, lo, hi, Some(d));
            let verdict = verify(&wp, &wc);
            let deviation_deg = (cand.first..=cand.last)
                .map(|i| {
                    angle_between_deg(
                        self.target[i],
                        forward(self.machine, wp[i - lo], wc[i - lo]),
                    )
                })
                .fold(0.0, f64::max);
            let checked = Checked {
                cand: cand.clone(),
                decimals: d,
                verdict,
                deviation_deg,
            };
            if verdict.passes() {
                return Some((checked, true));
            }
            if extra == 0 {
                // Not a rounding problem if the unrounded values fail too.
                let (up, uc) = self.materialize(p, c, cand, lo, hi, None);
                if !verify(&up, &uc).passes() {
                    return Some((checked, false));
                }
            }
            last = Some(checked);
        }
        last.map(|l| (l, false))
    }

    /// Candidates for one zone on the current values `(p, c)`, not touching points before
    /// `lower`, with the limits scaled by `1 − margin`. `Some((kept, reached))`, or `None`
    /// when nothing better was found.
    fn patch_zone(
        &self,
        p: &[f64],
        c: &[f64],
        zone: &Zone,
        lower: usize,
        margin: f64,
        stats: &mut QpStats,
    ) -> Option<(Checked, bool)> {
        let n = self.s.len();
        let mut best: Option<Checked> = None;
        let mut passed: Option<Checked> = None;
        let consider = |ck: Option<(Checked, bool)>,
                        best: &mut Option<Checked>,
                        passed: &mut Option<Checked>| {
            match ck {
                Some((ck, true))
                    if passed
                        .as_ref()
                        .is_none_or(|b| ck.deviation_deg < b.deviation_deg) =>
                {
                    *passed = Some(ck);
                }
                Some((ck, false))
                    if ck.verdict.improves()
                        && ck.verdict.core_min_after > 0.0
                        && best.as_ref().is_none_or(|b| {
                            ck.verdict.core_min_after > b.verdict.core_min_after + RATIO_TOL
                        }) =>
                {
                    *best = Some(ck);
                }
                _ => {}
            }
        };

        // The two starts: the values as they are, and the tail after the switch (or the
        // singular point) on the other branch.
        let switch = branch_switch(p, zone).filter(|&k| k + 1 >= lower);
        let k_other = switch.unwrap_or_else(|| least_primary(p, zone));
        let mut starts: Vec<Start> = vec![(p.to_vec(), c.to_vec(), None)];
        if k_other + 1 >= lower
            && let Some(shift) = self.tail_shift(p, c, k_other)
        {
            let (mut op, mut oc) = (p.to_vec(), c.to_vec());
            for i in k_other + 1..n {
                op[i] = -p[i];
                oc[i] = c[i] + shift;
            }
            // 1. Re-selection alone (a program that switches branch in the zone).
            if switch.is_some() {
                let cand = Candidate {
                    method: Method::Reselect,
                    first: k_other + 1,
                    last: k_other + 1,
                    p: vec![op[k_other + 1]],
                    c: vec![oc[k_other + 1]],
                    tail_shift_deg: Some(shift),
                };
                let ck = self.check(p, c, &cand, zone);
                if let Some((ck, true)) = ck {
                    return Some((ck, true)); // deviation 0: nothing can be better
                }
                consider(ck, &mut best, &mut passed);
            }
            starts.push((op, oc, Some((k_other, shift))));
        }
        // The peers' rules as starts too: C held, or linear, across the cone stretch, P on
        // C's meridian (the SCP is local; on coarse programs these lead elsewhere).
        if let (Some(st), Ok(spline)) = (
            crate::peers::cone_stretch(p, zone, self.opts.cone_deg),
            crate::spline::AnalysisSpline::new(self.s, c),
        ) && st[1] >= lower
        {
            for rule in [Strategy::Freeze, Strategy::Linearize] {
                let (mut rp, mut rc) = (p.to_vec(), c.to_vec());
                crate::peers::apply_rule(
                    rule,
                    self.machine,
                    self.s,
                    c,
                    &spline,
                    &self.target,
                    st,
                    &mut rp,
                    &mut rc,
                );
                starts.push((rp, rc, None));
            }
        }

        // 2. The joint patch from each start, on widening ranges, within the limits less
        //    the margin, and less what rounding to the most decimals allowed can add.
        let lim_p = GeomLimits::of(self.machine, Axis::Primary, self.feed_mm_min, margin);
        let lim_c = GeomLimits::of(self.machine, Axis::C, self.feed_mm_min, margin);
        let round_deg = 0.5 * 10f64.powi(-(self.opts.max_decimals as i32));
        let mut best_before_level: Option<f64> = None;
        let end = if self.opts.keep_last_point {
            n - 2
        } else {
            n - 1
        };
        let core = crate::reference::zone_core(zone, n);
        let levels = WIDENING_POINTS.iter().copied().chain([n]);
        for extra in levels {
            let first = zone.first.saturating_sub(extra).max(lower);
            let last = (zone.last + extra).min(end);
            if first > last {
                break;
            }
            // The feasibility LP first: a range on which no values reach feed is not worth
            // the SCP's solves. Starts that keep the branch share their fixed points, hence
            // one LP; the other-branch start has its own.
            let mut reach: [Option<bool>; 2] = [None, None];
            let mut reachable = |other: bool, sp: &[f64], sc: &[f64]| -> bool {
                *reach[usize::from(other)].get_or_insert_with(|| {
                    crate::reference::reachable(
                        self.s,
                        sp,
                        sc,
                        first,
                        last,
                        core.clone(),
                        self.machine,
                        self.feed_mm_min,
                        self.opts.max_decimals,
                    ) != Ok(false)
                })
            };
            let active: Vec<usize> = (0..starts.len()).collect();
            let screen = active.len() > 1;
            // Screening: every active start for a few solves; then the best one refined.
            let mut screened: Vec<(usize, JointSolution)> = Vec::new();
            for &k in &active {
                let (sp, sc, other) = &starts[k];
                if !reachable(other.is_some(), sp, sc) {
                    continue;
                }
                let pr = JointProblem {
                    s_mm: self.s,
                    p_deg: sp,
                    c_deg: sc,
                    target: &self.target,
                    first,
                    last,
                    lim_p,
                    lim_c,
                    machine: self.machine,
                    max_deviation_deg: self.opts.max_deviation_deg,
                    max_solves: if screen {
                        SCREEN_SOLVES
                    } else {
                        crate::joint::SCP_MAX_SOLVES
                    },
                    rel_tol: crate::joint::SCP_REL_TOL,
                    core: core.clone(),
                    round_p_deg: round_deg,
                    round_c_deg: round_deg,
                    warm: false,
                };
                match solve_joint(&pr) {
                    Ok(sol) => {
                        add_stats(stats, &sol.qp);
                        screened.push((k, sol));
                    }
                    Err(crate::candidate::PatchFailure::Solver(st)) => add_stats(stats, &st),
                    Err(_) => {}
                }
            }
            // The screened starts within SCREEN_KEEP of the best go on from their solutions
            // (warm: the base is feasible, the SCP only accepts improvements); a start
            // that looks worse after two solves may still end lower.
            if screen
                && let Some(top) = screened
                    .iter()
                    .map(|x| x.1.max_deviation_deg)
                    .reduce(f64::min)
            {
                let keep = SCREEN_KEEP * top + 1e-9;
                for (k, sol) in screened.iter_mut() {
                    if sol.max_deviation_deg > keep {
                        continue;
                    }
                    let (sp, sc, _) = &starts[*k];
                    let (mut wp, mut wc) = (sp.clone(), sc.clone());
                    wp[first..=last].copy_from_slice(&sol.p_deg);
                    wc[first..=last].copy_from_slice(&sol.c_deg);
                    let pr = JointProblem {
                        s_mm: self.s,
                        p_deg: &wp,
                        c_deg: &wc,
                        target: &self.target,
                        first,
                        last,
                        lim_p,
                        lim_c,
                        machine: self.machine,
                        max_deviation_deg: self.opts.max_deviation_deg,
                        max_solves: crate::joint::SCP_MAX_SOLVES - SCREEN_SOLVES,
                        rel_tol: crate::joint::SCP_REL_TOL,
                        core: core.clone(),
                        round_p_deg: round_deg,
                        round_c_deg: round_deg,
                        warm: true,
                    };
                    if let Ok(refined) = solve_joint(&pr) {
                        add_stats(stats, &refined.qp);
                        if refined.max_deviation_deg < sol.max_deviation_deg {
                            *sol = refined;
                        }
                    }
                }
                screened.sort_by(|a, b| a.1.max_deviation_deg.total_cmp(&b.1.max_deviation_deg));
            }
            for (k, sol) in screened {
                // A start on the other branch carries its tail from the end of the range
                // (the switch lies inside the zone, hence inside the range).
                let cand = Candidate {
                    method: Method::Joint,
                    first,
                    last,
                    p: sol.p_deg,
                    c: sol.c_deg,
                    tail_shift_deg: starts[k].2.map(|(_, shift)| shift),
                };
                let before = passed.as_ref().map(|p| p.deviation_deg);
                consider(self.check(p, c, &cand, zone), &mut best, &mut passed);
                if passed.as_ref().map(|p| p.deviation_deg) != before {
                    break; // sorted by deviation: the first that passes is the best here
                }
            }
            if let Some(pb) = &passed {
                let dev = pb.deviation_deg;
                if dev == 0.0 {
                    break;
                }
                if let Some(prev) = best_before_level
                    && prev - dev < DEVIATION_IMPROVEMENT_MIN * prev
                {
                    break;
                }
                best_before_level = Some(dev);
            }
            if first == lower.max(1) && last == end {
                break;
            }
        }
        match passed {
            Some(ck) => Some((ck, true)),
            None => best.map(|b| (b, false)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{machine, planted, sing_path};
    use crate::verify::NOT_WORSE_REL;

    fn spans(path: &Path, m: &Machine) -> Vec<crate::analysis::SpanFigures> {
        crate::analysis::analyze_spans(path, m, &AnalysisOptions::default())
            .unwrap()
            .1
    }

    /// The path with the result's values.
    fn written(path: &Path, res: &PatchResult) -> Path {
        let mut out = path.clone();
        for (q, (p, c)) in out.axes.iter_mut().zip(res.p_deg.iter().zip(&res.c_deg)) {
            q[3] = *p;
            q[4] = *c;
        }
        out
    }

    /// The invariants of the default method: X Y Z unchanged and the changed flags right;
    /// on every span no axis ratio falls below `min(before, 1)` (to
    /// NOT_WORSE_REL); every zone reaches feed on both rotary axes; the result read back
    /// has no zone left. Returns the largest orientation change.
    fn check_both(path: &Path, m: &Machine, res: &PatchResult, what: &str) -> f64 {
        let after = written(path, res);
        for (i, (a, b)) in path.axes.iter().zip(&after.axes).enumerate() {
            assert_eq!(a[..3], b[..3], "{what}: X Y Z moved at {i}");
            assert_eq!(res.p_changed[i], a[3] != b[3], "{what}");
            assert_eq!(res.c_changed[i], a[4] != b[4], "{what}");
        }
        assert!(
            !res.p_changed[0] && !res.c_changed[0],
            "{what}: the first point moved"
        );
        for (x, y) in spans(path, m).iter().zip(&spans(&after, m)) {
            for k in 0..5 {
                let floor = x.axis_ratio[k].min(1.0) * (1.0 - NOT_WORSE_REL) - 1e-12;
                assert!(
                    y.axis_ratio[k] >= floor,
                    "{what}: axis {k} at s = {:.3}: {} → {}",
                    x.min_s_mm,
                    x.axis_ratio[k],
                    y.axis_ratio[k]
                );
            }
        }
        for z in &res.zones {
            assert_eq!(z.outcome, Outcome::Reached, "{what}: {z:#?}");
            assert!(z.after.c_ratio >= 1.0 - 1e-9 && z.after.primary_ratio >= 1.0 - 1e-9);
        }
        let a = analyze_path(&after, m, &AnalysisOptions::default()).unwrap();
        assert!(a.zones.is_empty(), "{what}: zones left {:?}", a.zones);
        (0..path.s_mm.len())
            .map(|i| {
                let o = forward(m, path.axes[i][3], path.axes[i][4]);
                angle_between_deg(o, forward(m, res.p_deg[i], res.c_deg[i]))
            })
            .fold(0.0, f64::max)
    }

    /// Issue 8's planted check: a domain-rule flip 4° from the pole on the UCP710 (F1000,
    /// 0.5 mm spacing) reaches feed on both axes by re-selection alone, every point's tool
    /// axis unchanged (< 0.01°).
    #[test]
    fn domain_rule_flip_at_4_degrees_is_reselected() {
        let m = machine("mikron-ucp710");
        let path = planted(241, 0.5, 4.0, true, 1000.0);
        let before = analyze_path(&path, &m, &AnalysisOptions::default()).unwrap();
        assert_eq!(before.zones.len(), 1, "the planted zone");
        assert!(
            before.axis_min[Axis::Primary.index()].0 < 0.5,
            "A crawls before"
        );
        let res = patch_both(&path, &m, &PatchOptions::default()).unwrap();
        assert_eq!(res.zones.len(), 1);
        let z = &res.zones[0];
        assert_eq!(z.method, Method::Reselect, "{z:#?}");
        assert!(z.reselected_points > 100, "{z:#?}");
        let dev = check_both(&path, &m, &res, "flip 4°");
        assert!(dev < 0.01, "largest deviation {dev}°");
        assert!(z.max_deviation_deg < 0.01);
        // Every primary value past the switch has the other sign, on one branch.
        assert!(res.p_deg.iter().all(|&p| p >= 0.0));
    }

    /// Flips and swings 0 … 4° from the pole, both machines: both rotary axes reach feed,
    /// nothing gets worse, and the orientation changes by no more than going through the
    /// pole costs (about the distance to it), to SPEC §6's 1.25×.
    #[test]
    fn planted_passes_reach_feed_on_both_axes() {
        let opts = PatchOptions::default();
        let mut zones = 0;
        for (mname, feed) in [("mikron-hsm600", 3000.0), ("mikron-ucp710", 1000.0)] {
            let m = machine(mname);
            for flip in [false, true] {
                for d in [0.0, 0.01, 0.5, 2.0, 4.0] {
                    let path = planted(241, 0.5, d, flip, feed);
                    let res = patch_both(&path, &m, &opts).unwrap();
                    zones += res.zones.len();
                    let what = format!("{mname} F{feed} flip={flip} d={d}");
                    let dev = check_both(&path, &m, &res, &what);
                    assert!(dev <= 1.25 * d + 0.01, "{what}: {dev}°");
                }
            }
        }
        assert!(zones >= 16, "{zones}");
    }

    /// C17's `%SING` on the UCP710: A and C both reach feed, the tool passes (within
    /// rounding) through the pole, about 1° from the programmed axes (C-only: 3.35°).
    #[test]
    fn sing_reaches_feed_on_both_axes() {
        let m = machine("mikron-ucp710");
        let path = sing_path();
        let res = patch_both(&path, &m, &PatchOptions::default()).unwrap();
        let dev = check_both(&path, &m, &res, "SING");
        assert!(dev < 1.01, "{dev}°");
        let sign_changes = res.p_deg.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
        assert_eq!(sign_changes, 1, "A passes through zero once");
    }

    /// A machine whose primary range forbids the other branch ([0°, 120°]): nothing is ever
    /// written outside it, and the zones are still patched on the programmed side.
    #[test]
    fn primary_range_forbids_the_other_branch() {
        let mut m = machine("mikron-ucp710");
        m.primary_range_deg = (0.0, 120.0);
        for d in [0.01, 0.5, 2.0] {
            let path = planted(241, 0.5, d, false, 1000.0);
            let res = patch_both(&path, &m, &PatchOptions::default()).unwrap();
            assert!(
                res.p_deg.iter().all(|&p| (0.0..=120.0).contains(&p)),
                "d={d}: a primary value left the range"
            );
            assert!(!res.zones.is_empty(), "d={d}");
            check_both(&path, &m, &res, &format!("range [0, 120], d={d}"));
        }
    }

    /// Degenerate inputs: three points across the pole, and a point exactly on the pole.
    #[test]
    fn tiny_paths_and_the_exact_pole_do_not_panic() {
        let m = machine("mikron-ucp710");
        let three = Path {
            s_mm: vec![0.0, 1.0, 2.0],
            axes: vec![
                [0.0, 0.0, 0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0, 0.0, 90.0],
                [2.0, 0.0, 0.0, -1.0, 180.0],
            ],
            feed_mm_min: 2000.0,
        };
        let res = patch_both(&three, &m, &PatchOptions::default()).unwrap();
        assert_eq!(res.c_deg.len(), 3);
        assert!(!res.p_changed[0] && !res.c_changed[0]);
        let mut pole = planted(81, 1.0, 0.0, false, 2000.0);
        pole.axes[40][3] = 0.0;
        let res = patch_both(&pole, &m, &PatchOptions::default()).unwrap();
        check_both(&pole, &m, &res, "exact pole");
    }
}
