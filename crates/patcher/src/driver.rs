//! The one driver: where a reader learns the algorithm. Every method (branch
//! re-selection, the joint patch, G16's C-only method, the peers' rules) only *proposes*
//! new values for a zone; this module owns the sequence around them:
//!
//! 1. **Validate** the path; a path with no point within the singular cone is returned
//!    unchanged without any spline work.
//! 2. **Analyse** the run ([`crate::analysis::analyze_spans`]: Equation 6 exact over every
//!    span) and find its singular zones; zones closer than
//!    [`SolverSettings::merge_gap_points`] are one.
//! 3. For each zone, in path order, on the values the zones before it left:
//!    - the methods of the strategy ([`crate::strategy::methods`]) propose candidates through a [`Sink`],
//!      for each rung of the margin ladder ([`SolverSettings::margin_ladder`]) until one
//!      passes;
//!    - every candidate is **rounded as it will be written** (the file's decimals, then one
//!      more at a time up to `max_decimals` where rounding alone breaks it) and **verified**
//!      ([`crate::verify::verify_change_with_core`]): the checked rotary axes (both, or C
//!      with `--only-c`) reach feed over the zone's core (the zone ±
//!      [`SolverSettings::core_margin_points`]), and nothing gets worse around it;
//!    - **selection**: of the passing candidates whose exact largest orientation change
//!      (the angle between the old and new tool axes, on the written values) is within
//!      `max_deviation_deg` and within every point's safety bound ([`pole_bound_deg`],
//!      on the exact angle of the written words), the smallest; else the best improvement
//!      within them (a change beyond them scaled into them, or the joint method's capped
//!      solve); else nothing.
//! 4. **Verify what is written, whole** ([`whole_run_worse`]): the whole run with the
//!    written values is analysed again, exactly as `analyze` does; a zone whose patch made
//!    any span of a checked axis worse than before ([`crate::verify::not_worse_floor`]: a
//!    span at feed stays at feed, one below it may lose 0.01 % of its ratio) is put back as
//!    it was, until nothing is worse. The
//!    report's "after" figures are this analysis.
//! 5. **Report** each zone with its outcome and a [`Reason`] from a fixed set (below).
//!
//! # Reasons
//! - `reached`: a patch reaches feed (joint, G16, direct, or a peer's rule);
//! - `reselected`: branch re-selection alone reaches feed: no orientation change at all;
//! - `deviation_cap`: a patch that reaches feed exists, but its orientation change exceeds
//!   `max_deviation_deg`;
//! - `safety_bound`: a patch that reaches feed exists, but it turns some point's tool axis
//!   beyond the safety bound ([`pole_bound_deg`]: the pole reach);
//! - `tip_path`: a ball kept at its tip: a patch reaches feed on the tip path it was solved
//!   on, but not on the tips it writes;
//! - `end_pinned`: the run's last point must keep its values (`keep_last_point`, the NC
//!   pipeline says which block pins it), and with it held **no** values reach feed, while
//!   with it free some would (both by the relaxation of [`crate::proof::reachable`]);
//! - `range`: the machine's axis ranges forbid every values that would reach feed (the
//!   relaxation is infeasible with them, feasible without);
//! - `proven_unreachable`: no values of the movable points reach feed at all (the
//!   relaxation is infeasible — a proof, see [`crate::proof`]);
//! - `not_found`: none of the above: polepatch found no patch, and cannot prove there is
//!   none (or a patch failed the whole-run verification);
//! - `not_patched`: the run may not be patched (no TCPM, incremental, …: the caller's
//!   reason), so the zone is only reported ([`crate::report_unpatched`]).

use crate::{
    analysis::{AnalysisOptions, SpanFigures, Zone, analyze_spans, validate},
    centre::{KeepCentre, tip_length, written_path},
    options::{PatchAxes, PatchOptions, round_written},
    path::{Path, PathError},
    proof::why_not_reached,
    protocol::{Offered, Proposal, Proposer, Sink, Tail, ZoneCtx},
    qp::add_stats,
    report::{Method, Outcome, QpStats, Reason, ZoneFigures, ZoneReport},
    settings::SolverSettings,
    tolerances::{CAP_SLACK_DEG, CENTRE_TIME_REL, CHECK_MARGIN_POINTS, RATIO_TOL},
    verify::{AxisChange, Verdict, not_worse_floor, verify_change_on, verify_change_with_core},
};
use polepatch_kinematics::{Axis, Machine, PoleDistance, angle_between_deg, forward};

pub use crate::zones::{core_margins, figures_over, merge_zones, zone_core};

/// A candidate after rounding and verification.
#[derive(Debug, Clone)]
struct Checked {
    prop: Proposal,
    /// Decimals written for P and C.
    decimals: (usize, usize),
    verdict: Verdict,
    deviation_deg: f64,
    /// The largest ratio of a point's exact orientation change to its safety bound
    /// ([`pole_bound_deg`]; 0 where nothing changed).
    bound_ratio: f64,
    /// Every point's change within its safety bound, up to the rounding of the words
    /// written ([`bound_room_deg`]).
    within_bound: bool,
    /// With a ball's centre kept: it fails on the tips it writes, but passes on the path
    /// length the methods solved on (the moved tips spoiled it).
    tips_spoiled: bool,
}

/// The points a candidate check looks at: the candidate's `first..=last`, the last point
/// it changes (`changed_hi`: past `last` when its tail moves), and the window `lo..=hi`
/// handed to the verification (its change and the zone, ± [`CHECK_MARGIN_POINTS`]).
#[derive(Debug, Clone, Copy)]
struct CheckWindow {
    first: usize,
    last: usize,
    changed_hi: usize,
    lo: usize,
    hi: usize,
}

/// The safety bound on the orientation change of a point whose primary axis is programmed
/// at `_p_deg`, degrees (docs/method.md, "The safety bound"): the pole reach `reach_deg`
/// (the cone, or the pole reach beyond it: how far from the pole a zone lies), at every
/// point. Twice the point's distance from the pole was tried and forbids what the joint
/// patch needs: it moves the primary axis through zero, to the far side of the pole (a
/// C-swing 0.1° from the pole on the HSM600 reaches feed turning a point 1.08°, where 2|P|
/// allowed 0.2°). The programmed value stays an argument: the bound is a point's.
pub fn pole_bound_deg(_p_deg: f64, reach_deg: f64) -> f64 {
    reach_deg
}

/// What the rounding of the written words adds to a point's orientation change at most,
/// degrees, with `decimals` (P, C): half a unit of the last decimal of each (a change of
/// C by δ turns the tool axis by at most δ·sin|P| ≤ δ).
fn bound_room_deg(decimals: (usize, usize)) -> f64 {
    0.5 * (10f64.powi(-(decimals.0 as i32)) + 10f64.powi(-(decimals.1 as i32))) + CAP_SLACK_DEG
}

/// The driver's [`Sink`] for one zone: checks proposals and keeps the best.
struct Selection<'a> {
    s: &'a [f64],
    /// The path as read (its parameter's scale per segment: [`centre::segment_scale`]).
    path: &'a Path,
    /// The path's axis values (the tips the program states).
    axes: &'a [[f64; 5]],
    target: &'a [[f64; 3]],
    /// Per point, the safety bound on its orientation change ([`pole_bound_deg`]).
    bound: &'a [f64],
    machine: &'a Machine,
    opts: &'a PatchOptions,
    zone: &'a Zone,
    p: &'a [f64],
    c: &'a [f64],
    lower: usize,
    end: usize,
    feed_mm_s: f64,
    verify: bool,
    stats: QpStats,
    passed: Option<Checked>,
    improved: Option<Checked>,
    /// The smallest deviation of a passing proposal within the safety bound but beyond
    /// the cap.
    over_cap_deg: Option<f64>,
    /// The smallest deviation of a passing proposal beyond the safety bound.
    over_bound_deg: Option<f64>,
    /// A proposal within the safety bound passed on the path length it was solved on
    /// but not on the tips it writes (a ball's centre kept).
    tips_spoiled: bool,
    /// The one of those within the cap with the smallest deviation.
    spoiled: Option<Checked>,
    /// The peer's proposal, taken as it is.
    as_is: Option<Checked>,
}

impl Selection<'_> {
    fn axes(&self) -> &'static [Axis] {
        checked_axes(self.opts.axes)
    }

    /// Values of `(p, c)` on `lo..=hi` with `prop` applied, rounded with `decimals` where
    /// they change (`None`: unrounded).
    fn materialize(
        &self,
        prop: &Proposal,
        lo: usize,
        hi: usize,
        decimals: Option<(usize, usize)>,
    ) -> (Vec<f64>, Vec<f64>) {
        materialize(self.p, self.c, prop, lo, hi, decimals)
    }

    /// Where `prop` may be checked: `None` when it is malformed, changes points the zone
    /// may not change, moves the last point that must stay, or is longer than the caller
    /// allows; else the window of the check (`prop`'s change and the zone, ±
    /// [`CHECK_MARGIN_POINTS`]).
    fn window(&self, prop: &Proposal) -> Option<CheckWindow> {
        let n = self.s.len();
        let (first, last) = (prop.first, prop.last);
        if first < self.lower
            || first > last
            || last > self.end
            || prop.p.len() != last - first + 1
            || prop.c.len() != last - first + 1
            || prop.p.iter().chain(&prop.c).any(|v| !v.is_finite())
        {
            return None;
        }
        if !matches!(prop.tail, Tail::Keep) && self.opts.keep_last_point {
            return None; // the tail would move the last point, which must stay
        }
        if self
            .opts
            .max_patch_length_mm
            .is_some_and(|l| self.s[last] - self.s[first] > l)
        {
            return None; // longer than the caller allows
        }
        let changed_hi = match prop.tail {
            Tail::Keep => last,
            _ => (last + 1).min(n - 1),
        };
        let lo = first
            .min(self.zone.first)
            .saturating_sub(CHECK_MARGIN_POINTS);
        let hi = (changed_hi.max(self.zone.last) + CHECK_MARGIN_POINTS).min(n - 1);
        Some(CheckWindow {
            first,
            last,
            changed_hi,
            lo,
            hi,
        })
    }

    /// With a ball's centre kept (its `s` the tip path's length), the tip path's length
    /// over the window with the values `(wp, wc)` (unrounded: the whole-run check picks
    /// the decimals); `None` otherwise.
    fn tip_s(&self, w: &CheckWindow, wp: &[f64], wc: &[f64]) -> Option<Vec<f64>> {
        let (lo, hi) = (w.lo, w.hi);
        let keep = self.opts.keep_centre.filter(|k| k.s_is_length)?;
        let tips: Vec<[f64; 3]> = (lo..=hi)
            .map(|i| {
                let q = &self.axes[i];
                let o0 = self.target[i];
                let o1 = forward(self.machine, wp[i - lo], wc[i - lo]);
                std::array::from_fn(|j| q[j] + keep.radius_mm * (o0[j] - o1[j]))
            })
            .collect();
        Some(tip_length(self.path, lo, self.s[lo], &tips))
    }

    /// The verification of the window's values `(wp, wc)`. `tips`: on the tips the values
    /// write (with a ball's centre kept — before and after each on its own), else on the
    /// path length the methods solved on.
    fn verify_on(&self, w: &CheckWindow, wp: &[f64], wc: &[f64], tips: bool) -> Verdict {
        let (lo, hi) = (w.lo, w.hi);
        let (bp, bc) = (&self.p[lo..=hi], &self.c[lo..=hi]);
        let margin = core_margins(self.zone, self.opts.solver.core_margin_points);
        let ch: Vec<AxisChange> = self
            .axes()
            .iter()
            .map(|&axis| AxisChange {
                axis,
                before: if axis == Axis::C { bc } else { bp },
                after: if axis == Axis::C { wc } else { wp },
            })
            .collect();
        let (changed, core) = (
            (w.first - lo, w.changed_hi - lo),
            (self.zone.first.max(lo) - lo, self.zone.last.min(hi) - lo),
        );
        let moved = || Some((self.tip_s(w, bp, bc)?, self.tip_s(w, wp, wc)?)).filter(|_| tips);
        match moved() {
            Some((sb, sa)) => verify_change_on(
                &sb,
                &sa,
                &ch,
                changed,
                core,
                margin,
                self.machine,
                self.feed_mm_s,
            ),
            _ => verify_change_with_core(
                &self.s[lo..=hi],
                &ch,
                changed,
                core,
                margin,
                self.machine,
                self.feed_mm_s,
            ),
        }
    }

    /// With a ball's centre kept: whether the values pass on the path length they were
    /// solved on (so that, failing on the tips they write, the moved tips spoiled them).
    fn spoiled(&self, w: &CheckWindow, wp: &[f64], wc: &[f64]) -> bool {
        let keeps_centre = self.opts.keep_centre.is_some_and(|k| k.s_is_length);
        keeps_centre && self.verify_on(w, wp, wc, false).passes()
    }

    /// The largest exact change of the window's values `(wp, wc)`, its largest ratio to
    /// the safety bound, and whether every point is within its bound (up to the rounding
    /// of `d`'s decimals).
    fn deviation(
        &self,
        w: &CheckWindow,
        wp: &[f64],
        wc: &[f64],
        d: (usize, usize),
    ) -> (f64, f64, bool) {
        let lo = w.lo;
        let room = bound_room_deg(d);
        let (mut dev, mut ratio, mut within) = (0.0f64, 0.0f64, true);
        for i in w.first..=w.last {
            let a = angle_between_deg(
                self.target[i],
                forward(self.machine, wp[i - lo], wc[i - lo]),
            );
            dev = dev.max(a);
            if a > 0.0 {
                ratio = ratio.max(a / self.bound[i].max(f64::MIN_POSITIVE));
            }
            within &= a <= self.bound[i] + room;
        }
        (dev, ratio, within)
    }

    /// `prop` rounded with `d` decimals (P, C), verified on the tips it writes, and its
    /// deviations.
    fn checked_with(&self, prop: &Proposal, w: &CheckWindow, d: (usize, usize)) -> Checked {
        let (wp, wc) = self.materialize(prop, w.lo, w.hi, Some(d));
        let verdict = self.verify_on(w, &wp, &wc, true);
        let (deviation_deg, bound_ratio, within_bound) = self.deviation(w, &wp, &wc, d);
        Checked {
            prop: prop.clone(),
            decimals: d,
            verdict,
            deviation_deg,
            bound_ratio,
            within_bound,
            tips_spoiled: false,
        }
    }

    /// Round, verify and measure `prop` ([`Checked`]; `None` when it cannot be checked:
    /// [`Selection::window`]), and whether it passes. Without verification, with the
    /// file's decimals; else with one more decimal at a time up to `max_decimals` while
    /// only the rounding fails it.
    fn check(&self, prop: &Proposal) -> Option<(Checked, bool)> {
        let w = self.window(prop)?;
        let (pd0, cd0) = (self.opts.p_decimals, self.opts.c_decimals);
        if !self.verify {
            return Some((self.checked_with(prop, &w, (pd0, cd0)), false));
        }
        // (Unrounded: where only the rounding fails on the solve's path length, more
        // decimals would mend it, as they do on the tips.)
        let keeps_centre = self.opts.keep_centre.is_some_and(|k| k.s_is_length);
        let fails = |mut checked: Checked| {
            if keeps_centre {
                let (up, uc) = self.materialize(prop, w.lo, w.hi, None);
                checked.tips_spoiled = self.spoiled(&w, &up, &uc);
            }
            Some((checked, false))
        };
        let max_d = self.opts.max_decimals.max(pd0).max(cd0);
        let mut last_checked: Option<Checked> = None;
        // Only an improvement to keep (the unrounded values improve, but do not reach
        // feed): more decimals until the rounding no longer spoils it.
        let mut improving = false;
        for extra in 0..=max_d - pd0.min(cd0) {
            let d = ((pd0 + extra).min(max_d), (cd0 + extra).min(max_d));
            if last_checked.as_ref().is_some_and(|l| l.decimals == d) {
                break;
            }
            let checked = self.checked_with(prop, &w, d);
            let verdict = checked.verdict;
            if verdict.passes() {
                return Some((checked, true));
            }
            if improving && verdict.improves() {
                return fails(checked);
            }
            if extra == 0 {
                // Not a rounding problem if the unrounded values fail too — unless they
                // improve the zone and the rounding made a span worse (a capped solve's
                // best improvement: its spans beyond their limits may not grow).
                let (up, uc) = self.materialize(prop, w.lo, w.hi, None);
                let unrounded = self.verify_on(&w, &up, &uc, true);
                if !unrounded.passes() {
                    if verdict.improves() || !unrounded.improves() {
                        return fails(checked);
                    }
                    improving = true;
                }
            }
            last_checked = Some(checked);
        }
        last_checked.and_then(fails)
    }

    /// Whether `prop` keeps to the pole passage: beyond a side where the zone was cut from
    /// a longer stretch below feed (the program slow by its own doing, far from the pole,
    /// `crate::analysis::detect_zones`) it changes at most
    /// [`SolverSettings::joint_range_min_points`] points, to join the program.
    fn local(&self, prop: &Proposal) -> bool {
        let (z, join) = (self.zone, self.opts.solver.joint_range_min_points);
        let changed_last = match prop.tail {
            Tail::Keep => prop.last,
            _ => self.s.len() - 1,
        };
        (!z.cut_before || prop.first + join >= z.first)
            && (!z.cut_after || changed_last <= z.last + join)
    }

    /// Keep `ck` as the best improvement so far when it improves the zone more (and keeps
    /// to the pole passage: [`Selection::local`]).
    fn consider_improved(&mut self, ck: Checked) {
        if ck.verdict.improves()
            && self.local(&ck.prop)
            && ck.verdict.core_min_after > 0.0
            && self
                .improved
                .as_ref()
                .is_none_or(|b| ck.verdict.core_min_after > b.verdict.core_min_after + RATIO_TOL)
        {
            self.improved = Some(ck);
        }
    }

    /// `prop`'s change from the current values scaled by λ < 1 so that its deviation
    /// (`dev_deg` unscaled) is within the cap and every point's within its safety bound
    /// (`bound_ratio` unscaled: the largest ratio of a point's change to its bound), checked
    /// as written; λ shrinks by the ratio of cap to deviation (or of bound to change) until
    /// it fits (a few tries: the deviation is nearly linear in λ). `None` for a change that
    /// moves the points after it (a re-selected tail is not a change to scale) or that
    /// does not fit.
    fn scaled_into_cap(&self, prop: &Proposal, dev_deg: f64, bound_ratio: f64) -> Option<Checked> {
        let cap = self.opts.max_deviation_deg.unwrap_or(f64::INFINITY);
        if !matches!(prop.tail, Tail::Keep) || cap <= 0.0 {
            return None;
        }
        let mut lambda = 1.0;
        let (mut dev, mut ratio) = (dev_deg, bound_ratio);
        let st = &self.opts.solver;
        for _ in 0..st.scale_tries {
            let over = (dev / cap).max(ratio);
            if !(over > 0.0 && over.is_finite()) {
                return None;
            }
            lambda *= st.scale_safety / over;
            let mut scaled = prop.clone();
            for (k, i) in (prop.first..=prop.last).enumerate() {
                scaled.p[k] = self.p[i] + lambda * (prop.p[k] - self.p[i]);
                scaled.c[k] = self.c[i] + lambda * (prop.c[k] - self.c[i]);
            }
            let (ck, _) = self.check(&scaled)?;
            if self.within_cap(ck.deviation_deg) && ck.within_bound {
                return Some(ck);
            }
            (dev, ratio) = (ck.deviation_deg, ck.bound_ratio);
        }
        None
    }

    fn within_cap(&self, dev: f64) -> bool {
        self.opts
            .max_deviation_deg
            .is_none_or(|cap| dev <= cap + CAP_SLACK_DEG)
    }
}

impl Sink for Selection<'_> {
    fn offer(&mut self, prop: Proposal) -> Option<Offered> {
        add_stats(&mut self.stats, &prop.qp);
        let (ck, passes) = self.check(&prop)?;
        let out = Offered {
            passes,
            deviation_deg: ck.deviation_deg,
        };
        if !self.verify {
            self.as_is = Some(ck);
            return Some(out);
        }
        let in_cap = self.within_cap(ck.deviation_deg);
        let in_bound = ck.within_bound;
        self.tips_spoiled |= ck.tips_spoiled && in_bound;
        if ck.tips_spoiled
            && in_bound
            && in_cap
            && self
                .spoiled
                .as_ref()
                .is_none_or(|b| ck.deviation_deg < b.deviation_deg)
        {
            self.spoiled = Some(ck.clone());
        }
        let keep_min =
            |x: Option<f64>| Some(x.map_or(ck.deviation_deg, |d| d.min(ck.deviation_deg)));
        // Beyond the bound, a change that reaches feed on the path it was solved on counts
        // even where the moved tips spoil it: the bound refuses it first.
        if (passes || ck.tips_spoiled) && !in_bound {
            self.over_bound_deg = keep_min(self.over_bound_deg);
        } else if passes && !in_cap {
            self.over_cap_deg = keep_min(self.over_cap_deg);
        }
        if !in_cap || !in_bound {
            // The best improvement within the cap and the bound: the change scaled down
            // until its deviation as written fits (issue 26: a cap below what the zone
            // needs gave nothing; a solve capped at the limit can exceed it by its
            // rounding).
            if let Some(scaled) = self.scaled_into_cap(&prop, ck.deviation_deg, ck.bound_ratio) {
                self.consider_improved(scaled);
            }
        } else if passes {
            if self
                .passed
                .as_ref()
                .is_none_or(|b| ck.deviation_deg < b.deviation_deg)
            {
                self.passed = Some(ck);
            }
        } else {
            self.consider_improved(ck);
        }
        Some(out)
    }

    fn add_stats(&mut self, qp: &QpStats) {
        add_stats(&mut self.stats, qp);
    }

    fn best_passing_deg(&self) -> Option<f64> {
        self.passed.as_ref().map(|c| c.deviation_deg)
    }
}

/// `(p, c)` on `lo..=hi` with `prop` applied, rounded with `decimals` (P, C) where they
/// change (`None`: unrounded).
fn materialize(
    p: &[f64],
    c: &[f64],
    prop: &Proposal,
    lo: usize,
    hi: usize,
    decimals: Option<(usize, usize)>,
) -> (Vec<f64>, Vec<f64>) {
    let rp = |v: f64| decimals.map_or(v, |d| round_written(v, d.0));
    let rc = |v: f64| decimals.map_or(v, |d| round_written(v, d.1));
    let mut wp = p[lo..=hi].to_vec();
    let mut wc = c[lo..=hi].to_vec();
    for i in lo..=hi {
        if (prop.first..=prop.last).contains(&i) {
            let k = i - prop.first;
            // A value the proposal leaves as it is stays as written.
            if prop.p[k] != p[i] {
                wp[i - lo] = rp(prop.p[k]);
            }
            if prop.c[k] != c[i] {
                wc[i - lo] = rc(prop.c[k]);
            }
        } else if i > prop.last {
            match prop.tail {
                Tail::Keep => {}
                Tail::Reselect { shift_deg } => {
                    wp[i - lo] = rp(-p[i]);
                    wc[i - lo] = rc(c[i] + shift_deg);
                }
                Tail::COffset { deg } => wc[i - lo] = rc(c[i] + deg),
            }
        }
    }
    (wp, wc)
}

/// What was kept for one zone.
struct Done {
    zone: Zone,
    kept: Option<Checked>,
    stats: QpStats,
    over_cap_deg: Option<f64>,
    over_bound_deg: Option<f64>,
    /// A patch passed on the path length it was solved on but not on the tips it writes.
    tips_spoiled: bool,
    /// The best such patch within the cap (the next solve aims at its tips).
    spoiled: Option<Checked>,
    /// The zone's patch was put back by the whole-run verification.
    reverted: bool,
    /// The first and last point its patch could change.
    bounds: (usize, usize),
}

/// Result of patching one path: the values of both rotary axes as they must be written.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchResult {
    /// Primary axis (A or B) per point, degrees, as it must be written (rounded to
    /// `p_decimals` where changed; the input value where unchanged).
    pub p_deg: Vec<f64>,
    /// Which points' primary value changed.
    pub p_changed: Vec<bool>,
    /// Decimal places to write the changed primary values with (≥ `opts.p_decimals`).
    pub p_decimals: usize,
    /// C per point, degrees, as it must be written (rounded to `c_decimals` where changed;
    /// the input value where unchanged).
    pub c_deg: Vec<f64>,
    /// Which points' C changed.
    pub c_changed: Vec<bool>,
    /// Decimal places to write the changed C values with (≥ `opts.c_decimals`).
    pub c_decimals: usize,
    /// X Y Z per point, mm, as they must be written: the input values, except where
    /// [`PatchOptions::keep_centre`] rewrote a tip (rounded as written).
    pub xyz_mm: Vec<[f64; 3]>,
    /// Which points' X, Y, Z changed.
    pub xyz_changed: Vec<[bool; 3]>,
    /// Decimal places to write the changed X Y Z with, in the file's unit (≥ those of
    /// [`PatchOptions::keep_centre`]); 0 when none changed.
    pub xyz_decimals: usize,
    /// One row per zone.
    pub zones: Vec<ZoneReport>,
}

impl PatchResult {
    /// The path unchanged: no zone, every value as it was.
    pub fn unchanged(path: &Path, opts: &PatchOptions) -> PatchResult {
        let n = path.s_mm.len();
        PatchResult {
            p_deg: path.axes.iter().map(|q| q[Axis::Primary.index()]).collect(),
            p_changed: vec![false; n],
            p_decimals: opts.p_decimals,
            c_deg: path.axes.iter().map(|q| q[Axis::C.index()]).collect(),
            c_changed: vec![false; n],
            c_decimals: opts.c_decimals,
            xyz_mm: path.axes.iter().map(|q| [q[0], q[1], q[2]]).collect(),
            xyz_changed: vec![[false; 3]; n],
            xyz_decimals: 0,
            zones: Vec::new(),
        }
    }
    /// Whether any value changed.
    pub fn any_change(&self) -> bool {
        self.p_changed.iter().chain(&self.c_changed).any(|&c| c)
    }
}

/// The options' analysis options.
pub(crate) fn analysis_options(opts: &PatchOptions) -> AnalysisOptions {
    AnalysisOptions {
        cone_deg: opts.cone_deg,
        pole_reach_deg: opts.pole_reach_deg,
        tcy_s: opts.tcy_s,
        keep_samples: false,
    }
}

/// Spans on which the machine is slower after than before: the overall ratio (every axis
/// and the feed) below [`crate::verify::not_worse_floor`] of the ratio before. Where a
/// patch moves the tips (a ball's centre kept), a linear axis may take over a span's limit
/// from a rotary axis the patch freed — what counts is that the span gets no slower.
pub fn whole_run_slower(before: &[SpanFigures], after: &[SpanFigures]) -> Vec<usize> {
    before
        .iter()
        .zip(after)
        .enumerate()
        .filter(|(_, (b, a))| a.bound.ratio < not_worse_floor(b.bound.ratio))
        .map(|(k, _)| k)
        .collect()
}

/// Spans of `axes` on which `after` is worse than `before`: its ratio below
/// [`crate::verify::not_worse_floor`] of the ratio before (the verification's rule).
pub fn whole_run_worse(before: &[SpanFigures], after: &[SpanFigures], axes: &[Axis]) -> Vec<usize> {
    before
        .iter()
        .zip(after)
        .enumerate()
        .filter(|(_, (b, a))| {
            axes.iter().any(|ax| {
                let k = ax.index();
                a.axis_ratio[k] < not_worse_floor(b.axis_ratio[k])
            })
        })
        .map(|(k, _)| k)
        .collect()
}

/// What stays the same for every zone of a path.
struct Fixed<'a> {
    path: &'a Path,
    /// The path length the methods solve on: the path's, or with a ball's centre kept the
    /// length of the tips the last solve wrote ([`patch_with`]).
    s: &'a [f64],
    machine: &'a Machine,
    opts: &'a PatchOptions,
    /// The program's tool axes.
    target: Vec<[f64; 3]>,
    /// Per point, the safety bound on its orientation change ([`pole_bound_deg`]).
    bound: Vec<f64>,
    verify: bool,
}

/// Ask every method for `zone` (points `lower..=end` may change, from the current values
/// `cur_p`, `cur_c`), down the margin ladder; the best proposal kept.
fn solve_zone(
    f: &Fixed<'_>,
    methods: &mut [Box<dyn Proposer>],
    zone: Zone,
    cur_p: &[f64],
    cur_c: &[f64],
    lower: usize,
    end: usize,
) -> Done {
    let (path, opts, st) = (f.path, f.opts, &f.opts.solver);
    let n = path.s_mm.len();
    let core = zone_core(&zone, n, st.core_margin_points);
    let mut sel = Selection {
        s: f.s,
        path,
        axes: &path.axes,
        target: &f.target,
        bound: &f.bound,
        machine: f.machine,
        opts,
        zone: &zone,
        p: cur_p,
        c: cur_c,
        lower,
        end,
        feed_mm_s: path.feed_mm_min / 60.0,
        verify: f.verify,
        stats: QpStats::default(),
        passed: None,
        improved: None,
        over_cap_deg: None,
        over_bound_deg: None,
        tips_spoiled: false,
        spoiled: None,
        as_is: None,
    };
    for (rung, factor) in st.margin_ladder.iter().enumerate() {
        let ctx = ZoneCtx {
            s: f.s,
            target: &f.target,
            bound_deg: &f.bound,
            machine: f.machine,
            opts,
            settings: st,
            feed_mm_min: path.feed_mm_min,
            zone: &zone,
            core: core.clone(),
            lower,
            end,
            p: cur_p,
            c: cur_c,
            margin: opts.margin * factor,
            rung,
        };
        for m in methods.iter_mut() {
            m.propose(&ctx, &mut sel);
            // Re-selection keeps every tool axis (its deviation is the rounding's):
            // nothing can do better.
            if sel
                .passed
                .as_ref()
                .is_some_and(|c| c.prop.method == Method::Reselect)
            {
                break;
            }
        }
        if sel.passed.is_some() || !f.verify || opts.margin == 0.0 {
            break;
        }
    }
    let kept = if f.verify {
        sel.passed.take().or(sel.improved.take())
    } else {
        sel.as_is.take()
    };
    let (stats, over_cap_deg, over_bound_deg, tips_spoiled) = (
        sel.stats.clone(),
        sel.over_cap_deg,
        sel.over_bound_deg,
        sel.tips_spoiled,
    );
    let spoiled = sel.spoiled.take();
    Done {
        zone,
        kept,
        stats,
        over_cap_deg,
        over_bound_deg,
        tips_spoiled,
        spoiled,
        reverted: false,
        bounds: (lower, end),
    }
}

/// [`crate::patch_path`] with the given methods (asked in order) and whether their
/// proposals are verified: the strategy table ([`crate::strategy::methods`]) gives them.
///
/// Keeping a ball's centre ([`PatchOptions::keep_centre`]) moves the tips, so the tip
/// path's length s — Equation 6's parameter — depends on the solution: the zones are
/// solved again on the length of the tips the last solve wrote, until the lengths agree
/// within [`SolverSettings::centre_s_tol`] (a fixed point: a few solves), and the solve that reaches feed
/// on most zones is kept. Every solve is verified on the path as written, with its own s.
pub fn patch_with(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
    mut methods: Vec<Box<dyn Proposer>>,
    verify: bool,
) -> Result<PatchResult, PathError> {
    let (mut best, mut next_s) = patch_on(path, &path.s_mm, machine, opts, &mut methods, verify)?;
    if opts.keep_centre.is_none_or(|k| !k.s_is_length) {
        return Ok(best);
    }
    let reached = |r: &PatchResult| {
        r.zones
            .iter()
            .filter(|z| z.outcome == Outcome::Reached)
            .count()
    };
    // More zones at feed, else less time over the zones (each solve's figures are those of
    // the tips it writes): a later solve that only improves more is kept too.
    let time = |r: &PatchResult| r.zones.iter().map(|z| z.after.time_s).sum::<f64>();
    let better = |a: &PatchResult, b: &PatchResult| {
        reached(a) > reached(b)
            || (reached(a) == reached(b) && time(a) < time(b) * (1.0 - CENTRE_TIME_REL))
    };
    // Every path length solved on: solving on one again would go round in a cycle (a
    // solve that kept nothing and had nothing spoiled by its tips writes the program's
    // tips, whose length was solved on first).
    let mut solved: Vec<Vec<f64>> = vec![path.s_mm.clone()];
    let moved = |s: &[f64], t: &[f64]| {
        s.windows(2)
            .zip(t.windows(2))
            .map(|(a, b)| ((a[1] - a[0]) - (b[1] - b[0])).abs() / (b[1] - b[0]))
            .fold(0.0, f64::max)
    };
    for _ in 0..opts.solver.centre_s_iterations {
        if reached(&best) == best.zones.len() {
            break;
        }
        let Some(s) = next_s else { break };
        if s.windows(2).any(|w| w[1].is_nan() || w[1] <= w[0])
            || solved.iter().any(|t| {
                let m = moved(&s, t);
                m.is_nan() || m <= opts.solver.centre_s_tol
            })
        {
            break;
        }
        let last;
        (last, next_s) = patch_on(path, &s, machine, opts, &mut methods, verify)?;
        solved.push(s);
        if better(&last, &best) {
            best = last;
        }
    }
    Ok(best)
}

/// [`patch_with`] with the methods solving on the path length `solve_s`: the steps of the
/// module docs, one function each. With a ball's centre kept, also the path length to
/// solve on next: the length of the tips written, where a zone kept nothing with those of
/// its best change that passed on `solve_s` but not on its own tips ([`Run::next_s`]).
fn patch_on(
    path: &Path,
    solve_s: &[f64],
    machine: &Machine,
    opts: &PatchOptions,
    methods: &mut [Box<dyn Proposer>],
    verify: bool,
) -> Result<(PatchResult, Option<Vec<f64>>), PathError> {
    // 1. Validate; a path with no point near the pole is unchanged.
    validate(path)?;
    opts.validate()?;
    if !near_pole(path, machine, opts) {
        return Ok((PatchResult::unchanged(path, opts), None));
    }
    // 2. Analyse the run and find its zones.
    let aopts = analysis_options(opts);
    let (analysis, spans_before) = analyze_spans(path, machine, &aopts)?;
    if analysis.zones.is_empty() {
        return Ok((PatchResult::unchanged(path, opts), None));
    }
    let run = Run::new(path, solve_s, machine, opts, verify, aopts, spans_before);
    // 3. Each zone, in path order, on the values the zones before it left.
    let mut state = run.solve_zones(methods, &analysis.zones);
    // 4. Verify what is written, whole: a zone whose patch made a span worse is put back.
    let written = run.verify_whole(methods, &mut state)?;
    // 5. Report each zone with its outcome and reason.
    let zones = state
        .done
        .iter()
        .map(|d| run.zone_report(&state, &written, d))
        .collect();
    let next_s = run.next_s(&state, written.keep.as_ref());
    Ok((run.result(state, written, zones), next_s))
}

/// Whether some point of `path` is near enough the pole to lie in a zone
/// ([`PatchOptions::reach_deg`]).
fn near_pole(path: &Path, machine: &Machine, opts: &PatchOptions) -> bool {
    let (pole, reach) = (PoleDistance::of(machine), opts.reach_deg());
    let pi = Axis::Primary.index();
    path.axes.iter().any(|q| pole.near(q[pi], reach))
}

/// The rotary axes that must reach feed and may not get worse.
fn checked_axes(axes: PatchAxes) -> &'static [Axis] {
    match axes {
        PatchAxes::Both => &[Axis::Primary, Axis::C],
        PatchAxes::OnlyC => &[Axis::C],
    }
}

/// The lowest ratio of the checked rotary axes over `f`.
fn worst_ratio(axes: PatchAxes, f: &ZoneFigures) -> f64 {
    match axes {
        PatchAxes::Both => f.c_ratio.min(f.primary_ratio),
        PatchAxes::OnlyC => f.c_ratio,
    }
}

/// One solve of a path: what the steps of [`patch_on`] share.
struct Run<'a> {
    /// What every zone's solve sees.
    f: Fixed<'a>,
    /// The analysis options.
    aopts: AnalysisOptions,
    /// The run's span figures as programmed.
    spans_before: Vec<SpanFigures>,
    /// The program's primary values, degrees.
    p0: Vec<f64>,
    /// The program's C values, degrees.
    c0: Vec<f64>,
    /// The last point a patch may change (the one before the last when it must stay).
    end: usize,
}

/// The values as they stand, and what was kept for each zone.
struct Patched {
    /// Primary values, degrees, as written.
    p: Vec<f64>,
    /// C values, degrees, as written.
    c: Vec<f64>,
    /// One per zone, in path order.
    done: Vec<Done>,
}

/// What is written, as the whole-run verification left it.
struct Written {
    /// The run's span figures as written (the report's "after").
    spans_after: Vec<SpanFigures>,
    /// The zones `analyze` finds in the run as written (empty where nothing is written).
    zones_after: Vec<Zone>,
    /// The path as written (its tips moved where a ball's centre is kept); `None` when the
    /// written tips make no path.
    path: Option<Path>,
    /// How the tips are written, with a ball's centre kept.
    keep: Option<KeepCentre>,
}

impl<'a> Run<'a> {
    fn new(
        path: &'a Path,
        solve_s: &'a [f64],
        machine: &'a Machine,
        opts: &'a PatchOptions,
        verify: bool,
        aopts: AnalysisOptions,
        spans_before: Vec<SpanFigures>,
    ) -> Run<'a> {
        let (pi, ci) = (Axis::Primary.index(), Axis::C.index());
        let n = path.s_mm.len();
        let p0: Vec<f64> = path.axes.iter().map(|q| q[pi]).collect();
        let c0: Vec<f64> = path.axes.iter().map(|q| q[ci]).collect();
        let target: Vec<[f64; 3]> = p0
            .iter()
            .zip(&c0)
            .map(|(p, c)| forward(machine, *p, *c))
            .collect();
        let bound = p0
            .iter()
            .map(|&p| pole_bound_deg(p, opts.reach_deg()))
            .collect();
        Run {
            f: Fixed {
                path,
                s: solve_s,
                machine,
                opts,
                target,
                bound,
                verify,
            },
            aopts,
            spans_before,
            p0,
            c0,
            end: if opts.keep_last_point { n - 2 } else { n - 1 },
        }
    }

    /// Step 3: the zones (those closer than `merge_gap_points` merged) in path order, each
    /// solved on the values the zones before it left and from the point after the last
    /// patch ([`solve_zone`]).
    fn solve_zones(&self, methods: &mut [Box<dyn Proposer>], zones: &[Zone]) -> Patched {
        let n = self.f.path.s_mm.len();
        let (mut p, mut c) = (self.p0.clone(), self.c0.clone());
        let mut lower = 1;
        let mut done: Vec<Done> = Vec::new();
        for zone in merge_zones(zones, self.f.opts.solver.merge_gap_points) {
            let d = solve_zone(&self.f, methods, zone, &p, &c, lower, self.end);
            if let Some(k) = &d.kept {
                (p, c) = materialize(&p, &c, &k.prop, 0, n - 1, Some(k.decimals));
                lower = k.prop.last + 1;
            } else {
                lower = lower.max(d.zone.last + 1);
            }
            done.push(d);
        }
        Patched { p, c, done }
    }

    /// Step 4: verify what is written, whole. The run is analysed again as written; a zone
    /// whose patch made a span of a checked axis worse is put back, until nothing is
    /// worse.
    ///
    /// Keeping a ball's centre rewrites X Y Z with the rotary values: they are checked too.
    /// The tips are written with the file's decimals, and more where their rounding would
    /// slow the run (the rounding of a tip moves the path's length s, and jitter in s eats
    /// the rotary axes' jerk budget: at 0.5 mm spacing, 0.5 µm of it takes a third of the
    /// UCP710's A budget at F3000) — up to `max_decimals`, as for the rotary words.
    fn verify_whole(
        &self,
        methods: &mut [Box<dyn Proposer>],
        state: &mut Patched,
    ) -> Result<Written, PathError> {
        let (path, opts) = (self.f.path, self.f.opts);
        let mut keep_written = opts.keep_centre;
        loop {
            let keep = keep_written.as_ref();
            // Written tips that do not make a path (two on one spot) count as worse at the
            // first span.
            let written = written_path(path, &state.p, &state.c, self.f.machine, keep);
            let (worse, spans_after, zones_after) = match &written {
                Some(w) => {
                    let (analysis, spans_after) = analyze_spans(w, self.f.machine, &self.aopts)?;
                    if !self.f.verify {
                        return Ok(Written {
                            spans_after,
                            zones_after: analysis.zones,
                            path: written,
                            keep: keep_written,
                        });
                    }
                    let worse = self.worse_spans(&spans_after, keep.is_some());
                    (worse, spans_after, analysis.zones)
                }
                None => (vec![0], self.spans_before.clone(), Vec::new()),
            };
            // The tips' rounding may also keep a zone the candidate brought to feed below
            // it: more decimals first.
            if let Some(kw) = keep_written.as_mut()
                && kw.decimals < opts.max_decimals
                && (!worse.is_empty() || self.short_of_feed(state, &spans_after))
            {
                kw.decimals += 1;
                continue;
            }
            let Some(&k) = worse.first() else {
                return Ok(Written {
                    spans_after,
                    zones_after,
                    path: written,
                    keep: keep_written,
                });
            };
            let Some(i) = culprit(&state.done, k) else {
                // Nothing left to put back (only possible with written tips that are not a
                // path): every value as it was.
                (state.p, state.c) = (self.p0.clone(), self.c0.clone());
                return Ok(Written {
                    spans_after: self.spans_before.clone(),
                    zones_after: Vec::new(),
                    path: Some(path.clone()),
                    keep: keep_written,
                });
            };
            self.put_back(state, i);
            // Keeping a ball's centre moves the tips wherever the orientation changes, and a
            // wide patch may slow a linear axis at a corner far from the zone: narrow the
            // patch so that span keeps its values, and solve the zone again.
            if let Some(kw) = keep_written.as_mut() {
                // Start the decimals over for the narrowed patch.
                kw.decimals = opts.keep_centre.map_or(kw.decimals, |k| k.decimals);
                self.narrow_and_solve_again(methods, state, i, k);
            }
        }
    }

    /// The spans worse after than before on a checked axis; with the tips moved
    /// (`tips_moved`: a ball's centre kept) also those where the machine is slower: the
    /// linear axes the tips moved may not make it slower there.
    fn worse_spans(&self, spans_after: &[SpanFigures], tips_moved: bool) -> Vec<usize> {
        let axes = checked_axes(self.f.opts.axes);
        let mut w = whole_run_worse(&self.spans_before, spans_after, axes);
        if tips_moved {
            w.extend(whole_run_slower(&self.spans_before, spans_after));
            w.sort_unstable();
            w.dedup();
        }
        w
    }

    /// Whether a kept zone's core is below feed on a checked axis as written.
    fn short_of_feed(&self, state: &Patched, spans_after: &[SpanFigures]) -> bool {
        let n = self.f.path.s_mm.len();
        let st = &self.f.opts.solver;
        state
            .done
            .iter()
            .filter(|d| d.kept.is_some() && !d.reverted)
            .any(|d| {
                let f = figures_over(spans_after, zone_core(&d.zone, n, st.core_margin_points));
                worst_ratio(self.f.opts.axes, &f) < 1.0 - RATIO_TOL
            })
    }

    /// Put zone `i`'s patch back: its points (and a re-selected or offset tail) as they
    /// were.
    fn put_back(&self, state: &mut Patched, i: usize) {
        let n = self.f.path.s_mm.len();
        let d = &mut state.done[i];
        if let Some(prop) = d.kept.as_ref().map(|c| &c.prop) {
            let hi = if matches!(prop.tail, Tail::Keep) {
                prop.last
            } else {
                n - 1
            };
            state.p[prop.first..=hi].copy_from_slice(&self.p0[prop.first..=hi]);
            state.c[prop.first..=hi].copy_from_slice(&self.c0[prop.first..=hi]);
        }
        d.reverted = true;
    }

    /// Solve zone `i`, put back for the worse span `k`, again on a narrower range that
    /// leaves `k` alone ([`narrowed`]), when there is one.
    fn narrow_and_solve_again(
        &self,
        methods: &mut [Box<dyn Proposer>],
        state: &mut Patched,
        i: usize,
        k: usize,
    ) {
        let n = self.f.path.s_mm.len();
        let d = &state.done[i];
        let Some((lo, hi)) = narrowed(d, k, n, &self.f.opts.solver) else {
            return;
        };
        let zone = d.zone.clone();
        let again = solve_zone(&self.f, methods, zone, &state.p, &state.c, lo, hi);
        if let Some(kept) = &again.kept {
            (state.p, state.c) = materialize(
                &state.p,
                &state.c,
                &kept.prop,
                0,
                n - 1,
                Some(kept.decimals),
            );
        }
        state.done[i] = again;
    }

    /// With a ball's centre kept (X Y Z the tip, s its length, `written` how the tips were
    /// written): the tip path's length to solve on next — that of the values written, with, for each zone that kept nothing,
    /// its best change that reached feed on the path length it was solved on but not on the
    /// tips it writes (the solve must see those tips to aim at them; a zone that kept
    /// nothing otherwise leaves the program's tips, solved on already).
    fn next_s(&self, state: &Patched, written: Option<&KeepCentre>) -> Option<Vec<f64>> {
        // The tips as written (with the decimals the whole-run verification chose).
        let keep = written.copied().filter(|k| k.s_is_length)?;
        let n = self.f.path.s_mm.len();
        let (mut p, mut c) = (state.p.clone(), state.c.clone());
        for d in &state.done {
            if let Some(sp) = d
                .spoiled
                .as_ref()
                .filter(|_| d.kept.is_none() || d.reverted)
            {
                (p, c) = materialize(&p, &c, &sp.prop, 0, n - 1, Some(sp.decimals));
            }
        }
        written_path(self.f.path, &p, &c, self.f.machine, Some(&keep)).map(|w| w.s_mm)
    }

    /// Step 5: the report of zone `d` on the values as written.
    fn zone_report(&self, state: &Patched, written: &Written, d: &Done) -> ZoneReport {
        let (path, machine, opts) = (self.f.path, self.f.machine, self.f.opts);
        let st = &opts.solver;
        let n = path.s_mm.len();
        let (cur_p, cur_c) = (&state.p, &state.c);
        let kept = d.kept.as_ref().filter(|_| !d.reverted);
        let (first, last) = match kept {
            Some(k) => (d.zone.first.min(k.prop.first), d.zone.last.max(k.prop.last)),
            None => (d.zone.first, d.zone.last),
        };
        let core = zone_core(&d.zone, n, st.core_margin_points);
        // The figures: over the zone's core (what must reach feed) — and over the range a
        // C-only or peer patch rewrote, which its own limits cover; a joint patch's wider
        // range may keep a slowness of the program's own (its rounding, say) that it only
        // must not make worse.
        let own_range = kept.is_some_and(|k| {
            matches!(
                k.prop.method,
                Method::G16Patch | Method::Direct | Method::Peer
            )
        });
        let mut range = if own_range {
            core.start.min(first.saturating_sub(st.core_margin_points))
                ..core.end.max((last + st.core_margin_points).min(n - 1))
        } else {
            core.clone()
        };
        // What `analyze` of the written program finds must agree: a zone there within the
        // patch's points (its shoulder left crawling within the pole reach, say, where the
        // program's own slowdown was not the pole's before and is now) means the run is
        // not at feed there, whatever the core does. The figures then cover it too.
        let mut left_in_range = false;
        for z in written
            .zones_after
            .iter()
            .filter(|z| kept.is_some() && z.first <= last && z.last >= first)
        {
            left_in_range = true;
            range = range.start.min(z.first)..range.end.max(z.last.min(n - 1));
        }
        let before = figures_over(&self.spans_before, range.clone());
        let after = figures_over(&written.spans_after, range.clone());
        let core_after = figures_over(&written.spans_after, core.clone());
        let reached = worst_ratio(opts.axes, &core_after) >= 1.0 - RATIO_TOL && !left_in_range;
        let core_before = figures_over(&self.spans_before, core.clone());
        let outcome = if reached {
            Outcome::Reached
        } else if kept.is_some()
            && worst_ratio(opts.axes, &core_after) > worst_ratio(opts.axes, &core_before)
        {
            Outcome::Improved
        } else {
            Outcome::Unchanged
        };
        let method = kept.map_or(Method::None, |k| k.prop.method);
        let reason = if reached && method == Method::Reselect {
            Reason::Reselected
        } else if reached {
            Reason::Reached
        } else if !self.f.verify {
            Reason::NotFound
        } else if d.over_cap_deg.is_some() {
            Reason::DeviationCap
        } else if d.tips_spoiled {
            Reason::TipPath
        } else if d.over_bound_deg.is_some() {
            Reason::SafetyBound
        } else if d.reverted {
            Reason::NotFound
        } else {
            why_not_reached(
                path,
                cur_p,
                cur_c,
                &d.zone,
                machine,
                opts,
                lower_of(&state.done, d),
                self.end,
            )
        };
        let target = &self.f.target;
        let dev = (first..=last)
            .map(|i| angle_between_deg(target[i], forward(machine, cur_p[i], cur_c[i])))
            .fold(0.0, f64::max);
        let (p0, c0) = (&self.p0, &self.c0);
        let modified = |v: &[f64], v0: &[f64]| (first..=last).filter(|&i| v[i] != v0[i]).count();
        ZoneReport {
            first,
            last,
            kind: d.zone.kind,
            min_abs_primary_deg: d.zone.min_abs_primary_deg,
            core: [core.start, core.end],
            before,
            after,
            ideal_time_s: (path.s_mm[range.end] - path.s_mm[range.start])
                / (path.feed_mm_min / 60.0),
            max_deviation_deg: dev,
            points_modified: (first..=last)
                .filter(|&i| cur_p[i] != p0[i] || cur_c[i] != c0[i])
                .count(),
            primary_points_modified: modified(cur_p, p0),
            reselected_points: kept
                .filter(|k| matches!(k.prop.tail, Tail::Reselect { .. }))
                .map_or(0, |k| n - 1 - k.prop.last),
            patch_length_mm: kept.map_or(0.0, |k| path.s_mm[k.prop.last] - path.s_mm[k.prop.first]),
            outcome,
            reason,
            method,
            qp: d.stats.clone(),
            decimals: kept.map_or(opts.c_decimals, |k| k.decimals.1),
            p_decimals: kept.map_or(opts.p_decimals, |k| k.decimals.0),
            c_offset_deg: kept.map_or(0.0, |k| match k.prop.tail {
                Tail::COffset { deg } => deg,
                _ => 0.0,
            }),
            needed_deviation_deg: match reason {
                Reason::DeviationCap => d.over_cap_deg,
                Reason::SafetyBound => d.over_bound_deg,
                _ => None,
            },
        }
    }

    /// The values as they must be written, with the zones' reports: the decimals are the
    /// most any kept patch needs (the file's where nothing changed).
    fn result(&self, state: Patched, written: Written, zones: Vec<ZoneReport>) -> PatchResult {
        let (path, opts) = (self.f.path, self.f.opts);
        let decimals = state
            .done
            .iter()
            .filter(|d| !d.reverted)
            .filter_map(|d| d.kept.as_ref())
            .fold((opts.p_decimals, opts.c_decimals), |acc, k| {
                (acc.0.max(k.decimals.0), acc.1.max(k.decimals.1))
            });
        let p_changed: Vec<bool> = state.p.iter().zip(&self.p0).map(|(a, b)| a != b).collect();
        let c_changed: Vec<bool> = state.c.iter().zip(&self.c0).map(|(a, b)| a != b).collect();
        let xyz_mm: Vec<[f64; 3]> = written
            .path
            .as_ref()
            .unwrap_or(path)
            .axes
            .iter()
            .map(|q| [q[0], q[1], q[2]])
            .collect();
        let xyz_changed = xyz_mm
            .iter()
            .zip(&path.axes)
            .map(|(w, q)| std::array::from_fn(|i| w[i] != q[i]))
            .collect();
        PatchResult {
            xyz_mm,
            xyz_changed,
            xyz_decimals: written.keep.map_or(0, |k| k.decimals),
            p_decimals: if p_changed.iter().any(|&x| x) {
                decimals.0
            } else {
                opts.p_decimals
            },
            c_decimals: if c_changed.iter().any(|&x| x) {
                decimals.1
            } else {
                opts.c_decimals
            },
            p_deg: state.p,
            p_changed,
            c_deg: state.c,
            c_changed,
            zones,
        }
    }
}

/// The kept zone whose change lies nearest the worse span `k` (not one already put back).
fn culprit(done: &[Done], k: usize) -> Option<usize> {
    done.iter()
        .enumerate()
        .filter(|(_, d)| d.kept.is_some() && !d.reverted)
        .min_by_key(|(_, d)| {
            let pr = &d
                .kept
                .as_ref()
                .map(|c| (c.prop.first, c.prop.last))
                .unwrap_or((0, 0));
            if k + 1 < pr.0 {
                pr.0 - k - 1
            } else {
                k.saturating_sub(pr.1)
            }
        })
        .map(|(i, _)| i)
}

/// The range a zone put back for the worse span `k` may change next: its bounds narrowed
/// so that `k` keeps its values, by at least 1/[`SolverSettings::narrow_step_div`] of the
/// way to the zone (the analysis spline is not local: a change a few points away still
/// reaches the span); `None` when `k` is in the zone's core or nothing narrower holds the
/// zone.
fn narrowed(d: &Done, k: usize, n: usize, st: &SolverSettings) -> Option<(usize, usize)> {
    let core = zone_core(&d.zone, n, st.core_margin_points);
    let (lo, hi) = d.bounds;
    let (lo2, hi2) = if k + 1 < core.start {
        let step = (d.zone.first.saturating_sub(lo) / st.narrow_step_div).max(1);
        ((lo + step).max(k + 2).min(d.zone.first), hi)
    } else if k >= core.end {
        let step = (hi.saturating_sub(d.zone.last) / st.narrow_step_div).max(1);
        (
            lo,
            hi.saturating_sub(step)
                .min(k.saturating_sub(1))
                .max(d.zone.last),
        )
    } else {
        return None;
    };
    ((lo2, hi2) != (lo, hi) && lo2 <= d.zone.first && hi2 >= d.zone.last).then_some((lo2, hi2))
}

/// The first point the patch of `d`'s zone could change (after the previous kept zone).
fn lower_of(done: &[Done], d: &Done) -> usize {
    done.iter()
        .take_while(|x| !std::ptr::eq(*x, d))
        .filter_map(|x| {
            x.kept
                .as_ref()
                .filter(|_| !x.reverted)
                .map(|k| k.prop.last + 1)
        })
        .max()
        .unwrap_or(1)
}

/// The singular zones of `path` reported as they are, without patching: what a run that
/// must not be patched (no TCPM, say) reports. Every zone is [`Outcome::Unchanged`] with
/// [`Method::None`] and [`Reason::NotPatched`]; its figures before and after are the same.
pub fn report_unpatched(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<Vec<ZoneReport>, PathError> {
    validate(path)?;
    if !near_pole(path, machine, opts) {
        return Ok(Vec::new());
    }
    let n = path.s_mm.len();
    let st = &opts.solver;
    let (analysis, spans) = analyze_spans(path, machine, &analysis_options(opts))?;
    Ok(merge_zones(&analysis.zones, st.merge_gap_points)
        .into_iter()
        .map(|zone| {
            let core = zone_core(&zone, n, st.core_margin_points);
            let f = figures_over(&spans, core.clone());
            ZoneReport {
                first: zone.first,
                last: zone.last,
                kind: zone.kind,
                min_abs_primary_deg: zone.min_abs_primary_deg,
                core: [core.start, core.end],
                before: f,
                after: f,
                ideal_time_s: (path.s_mm[core.end] - path.s_mm[core.start])
                    / (path.feed_mm_min / 60.0),
                max_deviation_deg: 0.0,
                points_modified: 0,
                primary_points_modified: 0,
                reselected_points: 0,
                patch_length_mm: 0.0,
                outcome: Outcome::Unchanged,
                reason: Reason::NotPatched,
                method: Method::None,
                qp: QpStats::default(),
                decimals: opts.c_decimals,
                p_decimals: opts.p_decimals,
                c_offset_deg: 0.0,
                needed_deviation_deg: None,
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::analyze_path;
    use crate::report::ZoneFigures;
    use crate::strategy::patch_path;
    use crate::testutil::{machine, planted, sing_path};
    use crate::verify::{NOT_WORSE_REL, not_worse_floor};

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
        // No point turned beyond its safety bound, as written.
        let (reach, room) = (
            PatchOptions::default().reach_deg(),
            bound_room_deg((res.p_decimals, res.c_decimals)),
        );
        for (i, q) in path.axes.iter().enumerate() {
            let turned = angle_between_deg(
                forward(m, q[3], q[4]),
                forward(m, res.p_deg[i], res.c_deg[i]),
            );
            let bound = pole_bound_deg(q[3], reach);
            assert!(
                turned <= bound + room,
                "{what}: point {i} at P {} turned {turned}° > {bound}°",
                q[3]
            );
        }
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
        let res = patch_path(&path, &m, &PatchOptions::default()).unwrap();
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
                    let res = patch_path(&path, &m, &opts).unwrap();
                    zones += res.zones.len();
                    let what = format!("{mname} F{feed} flip={flip} d={d}");
                    let dev = check_both(&path, &m, &res, &what);
                    assert!(dev <= 1.25 * d + 0.01, "{what}: {dev}°");
                }
            }
        }
        assert!(zones >= 16, "{zones}");
    }

    /// A pass that starts near the pole and spirals out (a real NX post for a Mori Seiki
    /// NMV5000, B-C, G43.4: B 0 → −62° and +89° while C turns 1800°, the tip barely
    /// moving): C crawls over the whole run, but the pole's doing only near its start. The
    /// zone is that pole passage, and no patch turns a tool axis by more than the pole
    /// reach: the sweep far from the pole
    /// keeps its orientations, and nothing gets slower. (The whole run was one zone, and
    /// its patch turned tool axes 60–90° from the pole by up to 94°.)
    #[test]
    fn a_zone_is_the_pole_passage_not_the_sweep_after_it() {
        let opts = PatchOptions::default();
        let reach = opts.reach_deg();
        // C at 28 (UCP710) and 15 (HSM600) times what reaching feed allows.
        for (name, c_rate, feed) in [
            ("mikron-ucp710", 200.0, 1000.0),
            ("mikron-hsm600", 400.0, 5000.0),
        ] {
            let m = machine(name);
            // B from −0.2° to −70° (1°/mm), 0.1 mm a point.
            let path = crate::testutil::spiral(701, 0.1, (0.0, 1.0), c_rate, feed);
            let p = |i: usize| path.axes[i][Axis::Primary.index()];
            let before = analyze_path(&path, &m, &AnalysisOptions::default()).unwrap();
            assert!(
                before.axis_min[Axis::C.index()].0 < 0.1,
                "{name}: C crawls over the run"
            );
            // One zone, at the start, within reach of the pole (the sweep after it is the
            // program's own slowness: the pole does not dominate it).
            assert_eq!(before.zones.len(), 1, "{name}: {:?}", before.zones);
            let z = &before.zones[0];
            assert!(
                (z.first..=z.last).all(|i| p(i).abs() <= 2.0 * reach),
                "{name}: zone {}..={} reaches |B| {}",
                z.first,
                z.last,
                p(z.last).abs()
            );
            let res = patch_path(&path, &m, &opts).unwrap();
            assert_eq!(res.zones.len(), 1, "{name}");
            // No point turned beyond its bound; the sweep (beyond twice the reach) as it was.
            for i in 0..path.s_mm.len() {
                let dev = angle_between_deg(
                    forward(&m, p(i), path.axes[i][4]),
                    forward(&m, res.p_deg[i], res.c_deg[i]),
                );
                let bound = (2.0 * p(i).abs()).min(reach);
                assert!(
                    dev <= bound + 1e-3,
                    "{name}: point {i} |B| {}: {dev}°",
                    p(i).abs()
                );
                if p(i).abs() > 2.0 * reach {
                    assert!(
                        !res.p_changed[i] && !res.c_changed[i],
                        "{name}: point {i} at |B| {} changed",
                        p(i).abs()
                    );
                }
            }
            // Nothing slower anywhere.
            let after = written(&path, &res);
            for (k, (x, y)) in spans(&path, &m).iter().zip(&spans(&after, &m)).enumerate() {
                assert!(
                    y.bound.ratio >= not_worse_floor(x.bound.ratio),
                    "{name}: span {k} slower: {} → {}",
                    x.bound.ratio,
                    y.bound.ratio
                );
            }
            // The report says why the zone ended as it did.
            let zr = &res.zones[0];
            assert!(
                zr.outcome == Outcome::Reached || zr.reason != Reason::Reached,
                "{name}: {zr:#?}"
            );
        }
    }

    /// Issue 26 §4: a cap below what C17's `%SING` needs (1.0° through the pole) gives the
    /// best improvement within it that makes nothing slower — at 0.5°, 0.9° and 0.99° the
    /// zone's lowest ratio rises, no span of the run gets slower, the written change is
    /// within the cap, and the reason says what reaching feed needed; a cap at or above what
    /// the default achieves writes the default's values.
    #[test]
    fn a_cap_below_the_need_gives_the_best_improvement_within_it() {
        let m = machine("mikron-ucp710");
        let path = sing_path();
        let default = patch_path(&path, &m, &PatchOptions::default()).unwrap();
        let need = default.zones[0].max_deviation_deg;
        // About 1° (the pass's distance from the pole; 0.999995° with the warm-started,
        // unregularised interior-point method, 1.0001° before it).
        assert!((0.99..1.01).contains(&need), "{need}");
        let capped = |cap: f64| {
            let opts = PatchOptions {
                max_deviation_deg: Some(cap),
                ..PatchOptions::default()
            };
            patch_path(&path, &m, &opts).unwrap()
        };
        for cap in [0.5, 0.9, 0.99] {
            let res = capped(cap);
            assert_eq!(res.zones.len(), 1);
            let z = &res.zones[0];
            assert_eq!(z.outcome, Outcome::Improved, "cap {cap}: {z:#?}");
            assert_eq!(z.reason, Reason::DeviationCap, "cap {cap}");
            assert!(z.needed_deviation_deg.is_some_and(|d| d > cap), "cap {cap}");
            let worst = |f: &ZoneFigures| f.c_ratio.min(f.primary_ratio);
            assert!(
                worst(&z.after) > worst(&z.before) * 1.2,
                "cap {cap}: {:?} → {:?}",
                z.before,
                z.after
            );
            assert!(z.max_deviation_deg <= cap + CAP_SLACK_DEG, "cap {cap}");
            let after = written(&path, &res);
            for (k, (x, y)) in spans(&path, &m).iter().zip(&spans(&after, &m)).enumerate() {
                assert!(
                    y.bound.ratio >= not_worse_floor(x.bound.ratio),
                    "cap {cap}: span {k} slower: {} → {}",
                    x.bound.ratio,
                    y.bound.ratio
                );
            }
        }
        for cap in [need, 2.0] {
            let res = capped(cap);
            assert_eq!(
                (&res.p_deg, &res.c_deg, res.p_decimals, res.c_decimals),
                (
                    &default.p_deg,
                    &default.c_deg,
                    default.p_decimals,
                    default.c_decimals
                ),
                "cap {cap}"
            );
        }
    }

    /// A ball kept at its tip on points 0.02 mm apart: turning the tool axis by δ moves a
    /// tip by 2R·sin(δ/2) (87 µm for R = 5 mm at 1°), several times the spacing, so the
    /// tip path's length — Equation 6's s — changes with the solution. A zone that ends
    /// short of feed so says it (`tip_path`), never `not_found` without a why.
    #[test]
    fn a_zone_the_moved_tips_spoil_says_so() {
        let m = machine("mikron-hsm600");
        let path = planted(241, 0.05, 0.5, false, 3000.0);
        let res = patch_path(&path, &m, &PatchOptions::default()).unwrap();
        check_both(&path, &m, &res, "centre programmed");
        let opts = PatchOptions {
            keep_centre: Some(crate::centre::KeepCentre {
                radius_mm: 5.0,
                decimals: 4,
                unit_mm: 1.0,
                s_is_length: true,
            }),
            ..PatchOptions::default()
        };
        let res = patch_path(&path, &m, &opts).unwrap();
        assert_eq!(res.zones.len(), 1);
        let z = &res.zones[0];
        assert_ne!(z.outcome, Outcome::Reached, "{z:#?}");
        assert_eq!(z.reason, Reason::TipPath, "{z:#?}");
    }

    /// C17's `%SING` on the UCP710: A and C both reach feed, the tool passes (within
    /// rounding) through the pole, about 1° from the programmed axes (C-only: 3.35°).
    #[test]
    fn sing_reaches_feed_on_both_axes() {
        let m = machine("mikron-ucp710");
        let path = sing_path();
        let res = patch_path(&path, &m, &PatchOptions::default()).unwrap();
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
            let res = patch_path(&path, &m, &PatchOptions::default()).unwrap();
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
        let res = patch_path(&three, &m, &PatchOptions::default()).unwrap();
        assert_eq!(res.c_deg.len(), 3);
        assert!(!res.p_changed[0] && !res.c_changed[0]);
        let mut pole = planted(81, 1.0, 0.0, false, 2000.0);
        pole.axes[40][3] = 0.0;
        let res = patch_path(&pole, &m, &PatchOptions::default()).unwrap();
        check_both(&pole, &m, &res, "exact pole");
        // The point on the pole (bound 0) keeps its tool axis, the pole: the zone through
        // it is still patched (its C is free there; re-selection keeps every tool axis).
        let on_pole = angle_between_deg(
            forward(&m, 0.0, pole.axes[40][4]),
            forward(&m, res.p_deg[40], res.c_deg[40]),
        );
        assert!(
            on_pole <= bound_room_deg((res.p_decimals, res.c_decimals)),
            "{on_pole}"
        );
    }
    /// No point within reach of the pole (the cone, or the pole reach beyond it): nothing
    /// changes, with either method, and no spline work is needed (no zone reported).
    #[test]
    fn no_point_in_cone_is_unchanged() {
        let m = machine("mikron-hsm600");
        let mut path = planted(41, 1.0, 8.0, false, 2000.0);
        let reach = PatchOptions::default().reach_deg();
        for q in &mut path.axes {
            q[3] = q[3].abs().max(reach + 1.0);
        }
        for axes in [PatchAxes::Both, PatchAxes::OnlyC] {
            let opts = PatchOptions {
                axes,
                ..PatchOptions::default()
            };
            let res = patch_path(&path, &m, &opts).unwrap();
            assert!(res.zones.is_empty());
            assert!(!res.any_change());
            let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
            assert_eq!(res.c_deg, c);
            assert!(report_unpatched(&path, &m, &opts).unwrap().is_empty());
        }
    }

    /// A zone reported without patching: unchanged, same figures before and after.
    #[test]
    fn report_unpatched_reports_the_zone_as_it_is() {
        let m = machine("mikron-ucp710");
        let path = planted(241, 0.5, 0.5, false, 1000.0);
        let z = report_unpatched(&path, &m, &PatchOptions::default()).unwrap();
        assert_eq!(z.len(), 1);
        assert_eq!(z[0].outcome, Outcome::Unchanged);
        assert_eq!(z[0].method, Method::None);
        assert_eq!(z[0].before, z[0].after);
        assert!(z[0].before.c_ratio < 1.0);
        assert_eq!((z[0].points_modified, z[0].max_deviation_deg), (0, 0.0));
    }

    /// The safety bound: no point turns beyond the pole reach, wherever it lies (on the
    /// pole, beside it, or far out in a long zone).
    #[test]
    fn the_bound_is_the_pole_reach() {
        let reach = PatchOptions::default().reach_deg();
        assert_eq!(reach, 10.0);
        for p in [0.0, 0.1, -1.0, 3.0, -30.0, 90.0] {
            assert_eq!(pole_bound_deg(p, reach), reach, "P = {p}");
        }
        assert_eq!(pole_bound_deg(3.0, 5.0), 5.0);
        // The room for rounding: half a unit of each word's last decimal (and round-off).
        assert!((bound_room_deg((3, 3)) - 1e-3).abs() < 1e-8);
        assert!((bound_room_deg((4, 5)) - 0.5 * (1e-4 + 1e-5)).abs() < 1e-8);
        // On the pole a C change turns nothing; a primary change turns the tool by itself.
        let m = machine("mikron-ucp710");
        assert!(angle_between_deg(forward(&m, 0.0, 0.0), forward(&m, 0.0, 137.0)) < 1e-9);
        assert!(
            (angle_between_deg(forward(&m, 1.0, 0.0), forward(&m, -1.0, 0.0)) - 2.0).abs() < 1e-9
        );
    }

    /// Every method wrapped so that each proposal it offers also turns the tool axes far
    /// from the pole (points 10..=70 of a 241-point planted pass, |A| 10°–22°) by a smooth
    /// bump of the primary axis of `bump_deg`: a change that still reaches feed (the bump
    /// is slow), but beyond the safety bound there (the pole reach, 10°).
    struct Bumped {
        inner: Vec<Box<dyn Proposer>>,
        bump_deg: f64,
    }

    struct BumpSink<'s> {
        sink: &'s mut dyn Sink,
        p: Vec<f64>,
        c: Vec<f64>,
        bump_deg: f64,
    }

    const BUMP: (usize, usize) = (10, 70);

    impl Sink for BumpSink<'_> {
        fn offer(&mut self, prop: Proposal) -> Option<crate::protocol::Offered> {
            let (first, last) = (prop.first.min(BUMP.0), prop.last.max(BUMP.1));
            let (mut p, mut c) = (self.p.clone(), self.c.clone());
            p[prop.first..=prop.last].copy_from_slice(&prop.p);
            c[prop.first..=prop.last].copy_from_slice(&prop.c);
            for (i, q) in p.iter_mut().enumerate().take(BUMP.1 + 1).skip(BUMP.0) {
                let x = (i - BUMP.0) as f64 / (BUMP.1 - BUMP.0) as f64;
                let w = 0.5 * (1.0 - (2.0 * std::f64::consts::PI * x).cos());
                *q += self.bump_deg * w * q.signum();
            }
            self.sink.offer(Proposal {
                first,
                last,
                p: p[first..=last].to_vec(),
                c: c[first..=last].to_vec(),
                ..prop
            })
        }
        fn add_stats(&mut self, qp: &QpStats) {
            self.sink.add_stats(qp);
        }
        fn best_passing_deg(&self) -> Option<f64> {
            self.sink.best_passing_deg()
        }
    }

    impl Proposer for Bumped {
        fn propose(&mut self, ctx: &ZoneCtx<'_>, sink: &mut dyn Sink) {
            assert!(ctx.lower <= BUMP.0 && ctx.zone.first > BUMP.1);
            let mut bs = BumpSink {
                sink,
                p: ctx.p.to_vec(),
                c: ctx.c.to_vec(),
                bump_deg: self.bump_deg,
            };
            for m in &mut self.inner {
                m.propose(ctx, &mut bs);
            }
        }
    }

    /// A zone whose only changes that reach feed turn some point beyond its safety bound:
    /// none is written (every point's change as written is within its bound), the zone
    /// does not count as reached, and its report says why (`safety_bound`) and what reaching
    /// feed needed. The same bump within the bound is written and the zone reached.
    #[test]
    fn a_patch_beyond_the_bound_is_not_written_and_says_so() {
        let m = machine("mikron-ucp710");
        let path = planted(241, 0.5, 1.0, false, 1000.0);
        let opts = PatchOptions::default();
        let reach = opts.reach_deg();
        let run = |bump_deg: f64| {
            let (inner, verify) = crate::strategy::methods(&opts);
            let methods: Vec<Box<dyn Proposer>> = vec![Box::new(Bumped { inner, bump_deg })];
            patch_with(&path, &m, &opts, methods, verify).unwrap()
        };
        let turned = |res: &PatchResult, i: usize| {
            angle_between_deg(
                forward(&m, path.axes[i][3], path.axes[i][4]),
                forward(&m, res.p_deg[i], res.c_deg[i]),
            )
        };
        // Within the bound (5° where the bound is 10°): written, the zone reached.
        let res = run(5.0);
        assert_eq!(res.zones.len(), 1);
        assert_eq!(
            res.zones[0].outcome,
            Outcome::Reached,
            "{:#?}",
            res.zones[0]
        );
        assert!(
            (turned(&res, 40) - 5.0).abs() < 0.01,
            "{}",
            turned(&res, 40)
        );
        // Beyond it (12°): not written.
        let res = run(12.0);
        assert_eq!(res.zones.len(), 1);
        let z = &res.zones[0];
        assert_ne!(z.outcome, Outcome::Reached, "{z:#?}");
        assert_eq!(z.reason, Reason::SafetyBound, "{z:#?}");
        assert!(z.needed_deviation_deg.is_some_and(|d| d > reach), "{z:#?}");
        // What is written is the best improvement within the bound (the bump scaled down).
        assert!(z.max_deviation_deg <= reach + 1e-3, "{z:#?}");
        let room = bound_room_deg((res.p_decimals, res.c_decimals));
        for i in 0..path.s_mm.len() {
            let bound = pole_bound_deg(path.axes[i][3], reach);
            assert!(
                turned(&res, i) <= bound + room,
                "point {i}: {} > {bound}",
                turned(&res, i)
            );
        }
    }
}
