//! The joint patch as a method of the driver: which points move, from which start, and
//! what is proposed ([`crate::joint`] solves).
//!
//! - **Range.** The zone widened on each side by
//!   `max(joint_range_min_points, joint_range_zone_factor · zone length)` points
//!   ([`crate::settings::SolverSettings`]), within what the zone may change (after the
//!   previous zone's patch, before the run's last point when it must stay) and within
//!   `max_patch_length_mm` around the zone (a zone longer than that is not patched). When no solution on it meets the limits (the
//!   range is too short for the turn the axes must make), the widening doubles, up to all
//!   the points the zone may change.
//! - **Start.** Near the pole the best patch lets the tool axis pass through the pole, P
//!   changing sign at almost constant C. When the points after the zone may move to the
//!   other branch, the start is the program with the points after its branch switch (or
//!   after the point of least |P|) on the other branch ([`crate::starts::other_branch`]);
//!   the range is wide enough to hold the cone stretch;
//!   FREEZE's and LINEARIZE's rules across the cone (C held at its entry value, or linear
//!   in s, P on C's meridian: [`crate::starts`]) pass through the pole inside the range; the
//!   program's own values are the last start. Every start gets one solve, only to rank
//!   them (to the looser [`SolverSettings::screen_ipm_tol`]); the
//!   [`SolverSettings::screen_keep`] best (within the limits up to
//!   [`SolverSettings::screen_within_tol`], then less excess over them; then smaller
//!   deviation) go on for the rest of [`SolverSettings::screen_solves`], and the best of
//!   those for the rest of [`SolverSettings::scp_max_solves`]. A start's later solves go on
//!   from its solution and compare "not worse" with what its first did (the program's
//!   values, or for the other branch its own).
//! - **Proposals.** The refined solution, then the other start's; and, with
//!   `max_deviation_deg` when nothing within it passed, the capped solve from each start
//!   that keeps every tool axis — the program's values and the other branch (the least
//!   excess over the limits within the cap: the best improvement the cap allows, or a
//!   patch within it that reaches feed).

use crate::candidate::PatchFailure;
use crate::joint::{JointProblem, JointSolution, solve_joint};
use crate::limits::GeomLimits;
use crate::protocol::{Proposal, Proposer, Sink, Tail, ZoneCtx};
use crate::report::Method;
use crate::settings::SolverSettings;
use crate::starts::{
    Rule, apply_rule, branch_switch, cone_stretch, least_primary, other_branch, tail_shift,
};
use crate::tolerances::{POLE_DEG, ZERO_DEVIATION_DEG};
use polepatch_kinematics::Axis;

/// The joint method (module docs).
pub struct JointMethod;

/// On a point exactly on the pole (|P| ≤ [`POLE_DEG`]) C does not orient
/// the tool: give it C linear between its nearest neighbours off the pole within
/// `first..=last`, so a start does not carry a spike of C there (a post writes anything:
/// `atan2(0, 0)`). The tool axes are unchanged.
fn smooth_pole_c(p: &[f64], c: &mut [f64], first: usize, last: usize) {
    let on_pole = |i: usize| p[i].abs() <= POLE_DEG;
    for i in first..=last {
        if !on_pole(i) {
            continue;
        }
        let a = (first..i).rev().find(|&j| !on_pole(j));
        let b = (i + 1..=last).find(|&j| !on_pole(j));
        c[i] = match (a, b) {
            (Some(a), Some(b)) => c[a] + (c[b] - c[a]) * (i - a) as f64 / (b - a) as f64,
            (Some(a), None) => c[a],
            (None, Some(b)) => c[b],
            (None, None) => c[i],
        };
    }
}

/// A start: values of the whole path and what the points after the range do.
struct Start {
    p: Vec<f64>,
    c: Vec<f64>,
    tail: Tail,
    /// Rewritten by a rule inside the range: "not worse" compares with the values before.
    rule: bool,
}

impl JointMethod {
    /// The range of points to move with `extra` points either side of the zone, or `None`
    /// when the zone has none.
    fn range(ctx: &ZoneCtx<'_>, extra: usize) -> Option<(usize, usize)> {
        let n = ctx.s.len();
        let z = ctx.zone;
        let (a, b) = (z.first.saturating_sub(extra), (z.last + extra).min(n - 1));
        let (mut first, mut last) = (a.max(ctx.lower), b.min(ctx.end));
        if let Some(l) = ctx.opts.max_patch_length_mm {
            // Cut the range to the length, around the zone (never inside it).
            while ctx.s[last] - ctx.s[first] > l && (first < z.first || last > z.last) {
                let grow_left = z.first.saturating_sub(first);
                let grow_right = last.saturating_sub(z.last);
                if grow_left >= grow_right && first < z.first {
                    first += 1;
                } else if last > z.last {
                    last -= 1;
                } else {
                    first += 1;
                }
            }
        }
        let too_long = ctx
            .opts
            .max_patch_length_mm
            .is_some_and(|l| ctx.s[last] - ctx.s[first] > l);
        (first <= last && !too_long).then_some((first, last))
    }
}

impl Proposer for JointMethod {
    fn propose(&mut self, ctx: &ZoneCtx<'_>, sink: &mut dyn Sink) {
        let st = ctx.settings;
        let z = ctx.zone;
        let mut extra = st
            .joint_range_min_points
            .max(((z.last - z.first) as f64 * st.joint_range_zone_factor).ceil() as usize);
        // Wide enough to hold the cone stretch the peers' starts rewrite.
        if let Some([e0, _, _, e1]) = cone_stretch(ctx.p, z, ctx.opts.cone_deg) {
            extra = extra
                .max(z.first.saturating_sub(e0))
                .max(e1.saturating_sub(z.last));
        }
        let memo = crate::joint::WindowMemo::default();
        loop {
            let Some((first, last)) = Self::range(ctx, extra) else {
                return;
            };
            // The widest range: the next widening would not grow it.
            let widest = extra > ctx.s.len()
                || Self::range(ctx, 2 * extra).is_none_or(|r| r == (first, last));
            if Self::solve_range(ctx, sink, &memo, first, last, widest) || widest {
                return;
            }
            extra *= 2;
        }
    }
}

impl JointMethod {
    /// Solve and propose on the range `first..=last`; `true` when a solution within the
    /// limits was found (else the range is widened, unless `last_try`: then the best
    /// is proposed anyway, as an improvement).
    ///
    /// The steps: the starts ([`starts_on`]); the screening ([`RangeSolve::screen`]) and
    /// the refinement of the best ([`RangeSolve::refine`]); the proposals of the solutions
    /// ([`RangeSolve::offer_all`]); the capped solves when nothing passing met the caps
    /// ([`RangeSolve::offer_capped`]).
    fn solve_range(
        ctx: &ZoneCtx<'_>,
        sink: &mut dyn Sink,
        memo: &crate::joint::WindowMemo,
        first: usize,
        last: usize,
        last_try: bool,
    ) -> bool {
        let starts = starts_on(ctx, first, last);
        let rs = RangeSolve::new(ctx, memo, first, last);
        let st = ctx.settings;
        let mut screened = rs.screen(&starts, sink);
        rs.refine(&starts, &mut screened);
        let best = rs.best_start(&starts, &screened);
        let within = screened
            .first()
            .is_some_and(|(_, s)| s.excess <= st.elastic_tol);
        if !within && !last_try {
            for (_, s) in &screened {
                sink.add_stats(&s.qp);
            }
            return false;
        }
        rs.offer_all(&starts, screened, sink);
        if sink.best_passing_deg().is_none() {
            rs.offer_capped(&starts, best, sink);
        }
        true
    }
}

/// The starts on the range `first..=last` (module docs, **Start**): the other branch
/// after the switch (or the least |P|), the peers' rules across the cone stretch (with
/// FREEZE's the other branch after the stretch when the path passed the pole), the
/// program's values; C smoothed over the points on the pole ([`smooth_pole_c`]).
fn starts_on(ctx: &ZoneCtx<'_>, first: usize, last: usize) -> Vec<Start> {
    let (p, c) = (ctx.p, ctx.c);
    let mut starts: Vec<Start> = Vec::new();
    // Through the pole: the other branch after the switch (or the least |P|).
    let k = branch_switch(p, ctx.zone).unwrap_or_else(|| least_primary(p, ctx.zone));
    if k + 1 >= first
        && k < last
        && let Some(shift) = tail_shift(ctx.machine, p, c, k, ctx.opts.keep_last_point)
    {
        let (op, oc) = other_branch(p, c, k, shift);
        starts.push(Start {
            p: op,
            c: oc,
            tail: Tail::Reselect { shift_deg: shift },
            rule: false,
        });
    }
    // The peers' rules across the cone stretch: C held (FREEZE) or linear (LINEARIZE),
    // P on C's meridian — through the pole inside the range.
    if let (Some(stretch), Ok(spline)) = (
        cone_stretch(p, ctx.zone, ctx.opts.cone_deg),
        crate::spline::AnalysisSpline::new(ctx.s, c),
    ) && stretch[1] >= first
        && stretch[2] <= last
    {
        for rule in [Rule::Freeze, Rule::Linearize] {
            let (mut fp, mut fc) = (p.to_vec(), c.to_vec());
            apply_rule(
                rule,
                ctx.machine,
                ctx.s,
                c,
                &spline,
                ctx.target,
                stretch,
                &mut fp,
                &mut fc,
            );
            // Through the pole: P on C's meridian comes out of the stretch on the other
            // branch when the path passed the pole; then the points after it follow
            // on that branch (when they may move).
            let b = stretch[2];
            if rule == Rule::Freeze
                && b < last
                && fp[b].abs() > POLE_DEG
                && fp[b].signum() != p[b + 1].signum()
                && let Some(shift) = tail_shift(ctx.machine, &fp, &fc, b, ctx.opts.keep_last_point)
            {
                let (op, oc) = other_branch(&fp, &fc, b, shift);
                starts.push(Start {
                    p: op,
                    c: oc,
                    tail: Tail::Reselect { shift_deg: shift },
                    rule: true,
                });
            }
            starts.push(Start {
                p: fp,
                c: fc,
                tail: Tail::Keep,
                rule: true,
            });
        }
    }
    starts.push(Start {
        p: p.to_vec(),
        c: c.to_vec(),
        tail: Tail::Keep,
        rule: false,
    });
    for s0 in &mut starts {
        smooth_pole_c(&s0.p, &mut s0.c, first, last);
    }
    starts
}

/// A solution and the index of the start it came from.
type Screened = Vec<(usize, JointSolution)>;

/// Within the limits (an excess up to `tol`) first, by deviation, then the least excess.
fn key_within(s: &JointSolution, tol: f64) -> (u8, f64) {
    if s.excess <= tol {
        (0u8, s.max_deviation_deg)
    } else {
        (1u8, s.excess)
    }
}

/// Sort `v` by [`key_within`] with `tol`.
fn rank(v: &mut Screened, tol: f64) {
    v.sort_by(|a, b| {
        key_within(&a.1, tol)
            .partial_cmp(&key_within(&b.1, tol))
            .unwrap_or(std::cmp::Ordering::Equal)
    })
}

/// Within the limits (up to `elastic_tol`) and no orientation change: the best there is.
fn perfect(s: &JointSolution, st: &SolverSettings) -> bool {
    s.excess <= st.elastic_tol && s.max_deviation_deg <= ZERO_DEVIATION_DEG
}

/// What every solve on one range shares: the zone, the range, the limits at this rung,
/// the rounding, the spans judged by the pole passage and the screening's settings.
struct RangeSolve<'r, 'a> {
    ctx: &'r ZoneCtx<'a>,
    memo: &'r crate::joint::WindowMemo,
    first: usize,
    last: usize,
    lim_p: GeomLimits,
    lim_c: GeomLimits,
    /// Half a unit of the last written decimal, degrees.
    round_deg: f64,
    /// Beyond a side where the zone was cut from a longer stretch below feed, the
    /// program's own slowness need only not get worse (crate::analysis::detect_zones).
    pole_spans: std::ops::Range<usize>,
    /// Each start's first solve, when several are screened, only ranks them: to the
    /// screening's tolerance (those that go on are solved again at the full one, from
    /// where it ended), and within the limits up to `within_tol`.
    screen_st: SolverSettings,
    within_tol: f64,
}

impl<'r, 'a> RangeSolve<'r, 'a> {
    fn new(
        ctx: &'r ZoneCtx<'a>,
        memo: &'r crate::joint::WindowMemo,
        first: usize,
        last: usize,
    ) -> Self {
        let st = ctx.settings;
        let z = ctx.zone;
        RangeSolve {
            ctx,
            memo,
            first,
            last,
            lim_p: GeomLimits::of(ctx.machine, Axis::Primary, ctx.feed_mm_min, ctx.margin),
            lim_c: GeomLimits::of(ctx.machine, Axis::C, ctx.feed_mm_min, ctx.margin),
            round_deg: 0.5 * 10f64.powi(-(ctx.opts.max_decimals as i32)),
            pole_spans: if z.cut_before { z.first } else { 0 }..if z.cut_after {
                z.last
            } else {
                ctx.s.len()
            },
            screen_st: SolverSettings {
                ipm: crate::ipm::IpmSettings {
                    tol_feas: st.ipm.tol_feas.max(st.screen_ipm_tol),
                    tol_gap: st.ipm.tol_gap.max(st.screen_ipm_tol),
                    ..st.ipm
                },
                ..st.clone()
            },
            within_tol: st.elastic_tol.max(st.screen_within_tol),
        }
    }

    /// One joint solve from `(sp, sc)` on the range, or on `capped` with the caps: the
    /// least excess over the core's limits within them, nothing else worse
    /// (`crate::joint`, capped). `before`: what "not worse" compares with (None: the
    /// start's own values).
    #[allow(clippy::too_many_arguments)]
    fn problem(
        &self,
        sp: &[f64],
        sc: &[f64],
        before: Option<(&[f64], &[f64])>,
        capped: Option<(usize, usize)>,
        warm: bool,
        solves: u32,
        ipm_start: Option<&crate::ipm::IpmWarm>,
        settings: &SolverSettings,
    ) -> Result<JointSolution, PatchFailure> {
        let ctx = self.ctx;
        let (first, last) = capped.unwrap_or((self.first, self.last));
        let capped = capped.is_some();
        let pr = JointProblem {
            s_mm: ctx.s,
            p_deg: sp,
            c_deg: sc,
            target: ctx.target,
            first,
            last,
            lim_p: self.lim_p,
            lim_c: self.lim_c,
            feed_mm_min: ctx.feed_mm_min,
            machine: ctx.machine,
            core: ctx.core.clone(),
            round_p_deg: self.round_deg,
            round_c_deg: self.round_deg,
            reference: before,
            verified: (ctx.p, ctx.c),
            pole_spans: self.pole_spans.clone(),
            cap_deg: ctx.opts.max_deviation_deg.filter(|_| capped),
            point_cap_deg: capped.then_some(ctx.bound_deg),
            warm,
            max_solves: solves,
            ipm_start,
            memo: Some(self.memo),
            settings,
        };
        solve_joint(&pr)
    }

    /// The whole path's values of `s0` with `sol` on the range.
    fn with_solution(&self, s0: &Start, sol: &JointSolution) -> (Vec<f64>, Vec<f64>) {
        let (mut wp, mut wc) = (s0.p.clone(), s0.c.clone());
        wp[self.first..=self.last].copy_from_slice(&sol.p_deg);
        wc[self.first..=self.last].copy_from_slice(&sol.c_deg);
        (wp, wc)
    }

    /// More solves from a start's solution, with the same "before" as its first solves:
    /// the program's values for a rule's start, else the start's own values.
    fn go_on(
        &self,
        s0: &Start,
        sol: &JointSolution,
        solves: u32,
    ) -> Result<JointSolution, PatchFailure> {
        let (wp, wc) = self.with_solution(s0, sol);
        let warm = sol.excess <= self.within_tol;
        let before = if s0.rule {
            (self.ctx.p, self.ctx.c)
        } else {
            (s0.p.as_slice(), s0.c.as_slice())
        };
        self.problem(
            &wp,
            &wc,
            Some(before),
            None,
            warm,
            solves,
            sol.ipm_end.as_ref(),
            self.ctx.settings,
        )
    }

    /// Add `more` (solves from `sol`) to `sol` when it is better; its solves count.
    fn keep_better(&self, sol: &mut JointSolution, more: JointSolution) {
        let tol = self.ctx.settings.elastic_tol;
        let mut qp = sol.qp.clone();
        crate::qp::add_stats(&mut qp, &more.qp);
        if key_within(&more, tol) < key_within(sol, tol) {
            *sol = JointSolution { qp, ..more };
        } else {
            sol.qp = qp;
        }
    }

    /// One solve from every start (every solve when there is one start), until one is
    /// [`perfect`]; ranked within the limits up to `within_tol`: a loosely solved QP may
    /// leave a start that meets them just above `elastic_tol`.
    fn screen(&self, starts: &[Start], sink: &mut dyn Sink) -> Screened {
        let st = self.ctx.settings;
        let (p, c) = (self.ctx.p, self.ctx.c);
        let mut screened: Screened = Vec::new();
        for (i, s0) in starts.iter().enumerate() {
            let solves = if starts.len() == 1 {
                st.scp_max_solves
            } else {
                1
            };
            match self.problem(
                &s0.p,
                &s0.c,
                s0.rule.then_some((p, c)),
                None,
                false,
                solves,
                None,
                if solves < st.scp_max_solves {
                    &self.screen_st
                } else {
                    st
                },
            ) {
                Ok(sol) => {
                    let perfect = perfect(&sol, st);
                    screened.push((i, sol));
                    if perfect {
                        break; // within the limits, no orientation change: the best there is
                    }
                }
                Err(PatchFailure::Solver(q)) => sink.add_stats(&q),
                Err(_) => {}
            }
        }
        rank(&mut screened, self.within_tol);
        screened
    }

    /// Unless one start was screened or the best is [`perfect`]: the `screen_keep` best go
    /// on for the rest of `screen_solves`; then the best is refined up to
    /// `scp_max_solves`.
    fn refine(&self, starts: &[Start], screened: &mut Screened) {
        let st = self.ctx.settings;
        let screen = st.screen_solves.min(st.scp_max_solves).max(1);
        let perfect = screened.first().is_some_and(|(_, s)| perfect(s, st));
        if starts.len() > 1 && !perfect {
            if screen > 1 {
                for (i, sol) in screened.iter_mut().take(st.screen_keep.max(1)) {
                    if let Ok(more) = self.go_on(&starts[*i], sol, screen - 1) {
                        self.keep_better(sol, more);
                    }
                }
                rank(screened, st.elastic_tol);
            }
            if let Some((i, sol)) = screened.first_mut()
                && st.scp_max_solves > screen
                && let Ok(more) = self.go_on(&starts[*i], sol, st.scp_max_solves - screen)
            {
                self.keep_better(sol, more);
            }
        }
    }

    /// The best solution's values (whole path), its start's tail and what "not worse"
    /// compares with for it, for a capped solve; with its start's index.
    fn best_start(&self, starts: &[Start], screened: &Screened) -> Option<(Start, usize)> {
        screened.first().map(|(i, sol)| {
            let s0 = &starts[*i];
            let (wp, wc) = self.with_solution(s0, sol);
            (
                Start {
                    p: wp,
                    c: wc,
                    tail: s0.tail,
                    rule: s0.rule,
                },
                *i,
            )
        })
    }

    /// Offer the solutions best first, until one passes; the rest only count their solves.
    fn offer_all(&self, starts: &[Start], screened: Screened, sink: &mut dyn Sink) {
        let mut offered_all = true;
        for (i, sol) in screened {
            if !offered_all {
                sink.add_stats(&sol.qp);
                continue;
            }
            let passed = sink.offer(Proposal {
                method: Method::Joint,
                first: self.first,
                last: self.last,
                p: sol.p_deg,
                c: sol.c_deg,
                tail: starts[i].tail,
                qp: sol.qp,
            });
            if passed.is_some_and(|o| o.passes) {
                offered_all = false; // the rest only count their solves
            }
        }
    }

    /// When nothing passing met the caps — the user's `max_deviation_deg` and the safety
    /// bound near the pole (`crate::driver::pole_bound_deg`), or nothing passed at all:
    /// the least excess over the core's limits within them, every other span not worse
    /// (`crate::joint`, capped) — from the best solution (near the cap when it is just
    /// over it: a small step), and from each start that keeps every tool axis (the
    /// program's values, the other branch after the switch: within any cap; near the
    /// pole only the second passes through it). "Not worse" compares with what the
    /// verification compares with: the program's values, or for the other branch its
    /// own (the same sizes of every derivative past the switch). Beyond a side where the
    /// zone was cut from a longer stretch below feed the program is slow by its own
    /// doing, far from the pole: there the range keeps only `joint_range_min_points` to
    /// join it (and the best solution, which may reach further, is no start).
    fn offer_capped(&self, starts: &[Start], best: Option<(Start, usize)>, sink: &mut dyn Sink) {
        let ctx = self.ctx;
        let st = ctx.settings;
        let (first, last) = (self.first, self.last);
        let (p, c) = (ctx.p, ctx.c);
        let z = ctx.zone;
        let join = st.joint_range_min_points;
        let range = (
            if z.cut_before {
                first.max(z.first.saturating_sub(join))
            } else {
                first
            },
            if z.cut_after {
                last.min(z.last + join)
            } else {
                last
            },
        );
        let own = |s0: &Start| -> (Vec<f64>, Vec<f64>) {
            if s0.rule {
                (p.to_vec(), c.to_vec())
            } else {
                (s0.p.clone(), s0.c.clone())
            }
        };
        let capped = best
            .iter()
            .filter(|_| range == (first, last))
            .map(|(b, i)| (b, own(&starts[*i]), true))
            .chain(
                starts
                    .iter()
                    .filter(|s0| !s0.rule)
                    .map(|s0| (s0, own(s0), false)),
            );
        for (s0, (bp, bc), warm) in capped {
            let r = self.problem(
                &s0.p,
                &s0.c,
                Some((&bp, &bc)),
                Some(range),
                warm,
                st.scp_max_solves,
                None,
                st,
            );
            match r {
                Ok(sol) => {
                    sink.offer(Proposal {
                        method: Method::Joint,
                        first: range.0,
                        last: range.1,
                        p: sol.p_deg,
                        c: sol.c_deg,
                        tail: s0.tail,
                        qp: sol.qp,
                    });
                }
                Err(PatchFailure::Solver(q)) => sink.add_stats(&q),
                Err(_) => {}
            }
        }
    }
}
