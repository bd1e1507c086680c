//! Orchestration: detect, patch, verify, extend, never worse.
//!
//! For each singular zone (in path order, on the C values already updated by the zones
//! before it), candidates are tried at widening levels `extra` = 0, 1, 2, 4, 8, …: the
//! G16 patch ([`crate::g16::g16_patch`]) with `extra` CL points beyond its joins, and the
//! direct QP ([`crate::direct::direct_patch`]) over the hull of the zone widened by
//! `extra`, the G16 patch's range and the previous level's direct range, monotone with the
//! sign of the net change, then (only if that does not pass) without monotonicity. A
//! candidate is applied, rounded as written (`c_decimals`, then one more decimal at a time
//! up to `max_decimals` when only the rounding breaks it) and verified
//! ([`crate::verify::verify_c_change`]): C reaches feed around the patch and no sample gets
//! worse.
//!
//! **Selection (SPEC §6).** Of the passing candidates the one with the smallest exact max
//! orientation deviation ([`orientation_deviation_deg`]) is kept. Widening goes on after
//! the first pass while a level lowers the best deviation by at least
//! [`DEVIATION_IMPROVEMENT_MIN`], for at most [`MAX_LEVELS_AFTER_PASS`] levels. When no
//! candidate passes within the limits, the best improvement (if any) is kept, else the
//! zone is left as it was.

use crate::{
    analysis::{AnalysisOptions, RATIO_TOL, Zone, ZoneKind, analyze_path, validate},
    candidate::{Candidate, PatchFailure},
    direct::{direct_patch, orientation_deviation_deg},
    g16::g16_patch,
    limits::CLimits,
    options::{PatchOptions, round_written},
    path::{Path, PathError},
    qp::add_stats,
    report::{Method, Outcome, QpStats, ZoneFigures, ZoneReport},
    verify::{CORE_MARGIN_POINTS, VERIFY_MARGIN_POINTS, Verdict, verify_c_change},
};
use polepatch_kinematics::{Axis, LimitKind, Machine};

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
            zones: Vec::new(),
        }
    }
    /// Whether any value changed.
    pub fn any_change(&self) -> bool {
        self.p_changed.iter().chain(&self.c_changed).any(|&c| c)
    }
}

/// The singular zones of `path` reported as they are, without patching: what a run that
/// must not be patched (no TCPM, say) reports. Every zone is [`Outcome::Unchanged`] with
/// [`Method::None`]; its figures before and after are the same.
pub fn report_unpatched(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<Vec<ZoneReport>, PathError> {
    validate(path)?;
    let pi = Axis::Primary.index();
    if !path.axes.iter().any(|q| q[pi].abs() <= opts.cone_deg) {
        return Ok(Vec::new());
    }
    let aopts = AnalysisOptions {
        cone_deg: opts.cone_deg,
        tcy_s: opts.tcy_s,
        keep_samples: false,
    };
    let analysis = analyze_path(path, machine, &aopts)?;
    merge_zones(&analysis.zones)
        .into_iter()
        .map(|zone| {
            let f = zone_figures(path, machine, &aopts, zone.first, zone.last)?;
            Ok(ZoneReport {
                first: zone.first,
                last: zone.last,
                kind: zone.kind,
                min_abs_primary_deg: zone.min_abs_primary_deg,
                before: f,
                after: f,
                ideal_time_s: (path.s_mm[zone.last] - path.s_mm[zone.first])
                    / (path.feed_mm_min / 60.0),
                max_deviation_deg: 0.0,
                points_modified: 0,
                patch_length_mm: 0.0,
                outcome: Outcome::Unchanged,
                method: Method::None,
                qp: QpStats::default(),
                decimals: opts.c_decimals,
                c_offset_deg: 0.0,
            })
        })
        .collect()
}

/// Factors applied to `PatchOptions::margin`, in order, when no candidate passes
/// verification: the configured margin, a quarter of it, none.
pub const MARGIN_LADDER: [f64; 3] = [1.0, 0.25, 0.0];

/// Zones closer than this many points are patched as one.
const MERGE_GAP_POINTS: usize = 2 * CORE_MARGIN_POINTS;

/// Largest range the direct QP is tried on, points (its rows are sparse, but a wider
/// range than this is not a patch any more).
pub const DIRECT_MAX_POINTS: usize = 400;

/// A widening level after the first passing candidate that lowers the best max
/// orientation deviation by less than this fraction of it ends the search (the direct QP's
/// min-max over a growing range only goes down, and levels off within a few levels).
pub const DEVIATION_IMPROVEMENT_MIN: f64 = 0.05;

/// Most widening levels tried after the level of the first passing candidate (a cap on
/// the extra solves the improvement search may cost).
pub const MAX_LEVELS_AFTER_PASS: usize = 3;

/// Points of path either side of a zone's range analysed for its report figures.
const FIGURE_MARGIN_POINTS: usize = 30;

/// Which formulations [`patch_path_with`] may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Methods {
    /// Try the G16 patch.
    pub g16: bool,
    /// Try the direct QP.
    pub direct: bool,
}

/// Patch every singular zone of `path`.
///
/// Bad input is an error; every numerical outcome is in the zone reports. A path with no
/// point within the singular cone is returned unchanged without any spline work.
pub fn patch_path(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<PatchResult, PathError> {
    patch_path_with(
        path,
        machine,
        opts,
        Methods {
            g16: true,
            direct: true,
        },
    )
}

/// A candidate after rounding and verification.
#[derive(Debug, Clone)]
struct Checked {
    method: Method,
    first: usize,
    last: usize,
    /// Written values for `first..=last`.
    values: Vec<f64>,
    offset: f64,
    decimals: usize,
    verdict: Verdict,
}

/// [`patch_path`] with a choice of formulations.
pub(crate) fn patch_path_with(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
    methods: Methods,
) -> Result<PatchResult, PathError> {
    validate(path)?;
    let n = path.s_mm.len();
    let c0: Vec<f64> = path.axes.iter().map(|q| q[Axis::C.index()]).collect();
    let pi = Axis::Primary.index();
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
    let ctx = Ctx {
        s: &path.s_mm,
        p: path.axes.iter().map(|q| q[pi]).collect(),
        lim: std::cell::Cell::new(CLimits::new(machine, path.feed_mm_min, opts.margin)),
        lim0: CLimits::new(machine, path.feed_mm_min, 0.0),
        step: analysis.step_mm,
        opts,
        methods,
    };
    let mut cur = c0.clone();
    let mut changed = vec![false; n];
    let mut done: Vec<(Zone, Option<Checked>, Outcome, QpStats)> = Vec::new();
    // Point 0 is where the run starts: it belongs to the block before the run and is never moved.
    let mut lower = 1;
    for zone in merge_zones(&analysis.zones) {
        let mut stats = QpStats::default();
        // The margin only guards the solvers' aim against projection and rounding; what
        // counts is the verification on the written values, without margin. When nothing
        // passes with the configured margin, aim closer to the limits before giving up.
        let mut found: Option<(Checked, bool)> = None;
        for factor in MARGIN_LADDER {
            ctx.lim.set(CLimits::new(
                machine,
                path.feed_mm_min,
                opts.margin * factor,
            ));
            match ctx.patch_zone(&cur, &zone, lower, &mut stats) {
                Some((c, true)) => {
                    found = Some((c, true));
                    break;
                }
                Some((c, false)) => {
                    let better = found.as_ref().is_none_or(|(b, _)| {
                        c.verdict.core_min_after > b.verdict.core_min_after + RATIO_TOL
                    });
                    if better {
                        found = Some((c, false));
                    }
                }
                None => {}
            }
            if opts.margin == 0.0 {
                break;
            }
        }
        let (kept, outcome) = match found {
            Some((c, true)) => (Some(c), Outcome::Reached),
            Some((c, false)) => (Some(c), Outcome::Improved),
            None => (None, Outcome::Unchanged),
        };
        if let Some(k) = &kept {
            for (i, v) in (k.first..=k.last).zip(&k.values) {
                cur[i] = *v;
                changed[i] = cur[i] != c0[i];
            }
            if k.offset != 0.0 {
                for i in k.last + 1..n {
                    cur[i] = round_written(cur[i] + k.offset, k.decimals);
                    changed[i] = cur[i] != c0[i];
                }
            }
            lower = k.last + 1;
        } else {
            lower = lower.max(zone.last + 1);
        }
        done.push((zone, kept, outcome, stats));
    }

    let mut after_path = path.clone();
    for (q, c) in after_path.axes.iter_mut().zip(&cur) {
        q[Axis::C.index()] = *c;
    }
    let mut reports = Vec::with_capacity(done.len());
    let mut decimals = opts.c_decimals;
    for (zone, kept, outcome, qp) in done {
        let (first, last) = match &kept {
            Some(k) => (zone.first.min(k.first), zone.last.max(k.last)),
            None => (zone.first, zone.last),
        };
        let before = zone_figures(path, machine, &aopts, first, last)?;
        let after = match &kept {
            Some(_) => zone_figures(&after_path, machine, &aopts, first, last)?,
            None => before,
        };
        let max_dev = (first..=last)
            .map(|i| orientation_deviation_deg(ctx.p[i], cur[i] - c0[i]))
            .fold(0.0, f64::max);
        let d = kept.as_ref().map_or(opts.c_decimals, |k| k.decimals);
        decimals = decimals.max(d);
        reports.push(ZoneReport {
            first,
            last,
            kind: zone.kind,
            min_abs_primary_deg: zone.min_abs_primary_deg,
            before,
            after,
            ideal_time_s: (path.s_mm[last] - path.s_mm[first]) / (path.feed_mm_min / 60.0),
            max_deviation_deg: max_dev,
            points_modified: kept
                .as_ref()
                .map_or(0, |k| (k.first..=k.last).filter(|&i| changed[i]).count()),
            patch_length_mm: kept
                .as_ref()
                .map_or(0.0, |k| path.s_mm[k.last] - path.s_mm[k.first]),
            outcome,
            method: kept.as_ref().map_or(Method::None, |k| k.method),
            qp,
            decimals: d,
            c_offset_deg: kept.as_ref().map_or(0.0, |k| k.offset),
        });
    }
    Ok(PatchResult {
        p_deg: ctx.p.clone(),
        p_changed: vec![false; n],
        p_decimals: opts.p_decimals,
        c_deg: cur,
        c_changed: changed,
        c_decimals: decimals,
        zones: reports,
    })
}

/// Zones in order, those closer than [`MERGE_GAP_POINTS`] merged.
fn merge_zones(zones: &[Zone]) -> Vec<Zone> {
    let mut out: Vec<Zone> = Vec::new();
    let mut sorted = zones.to_vec();
    sorted.sort_by_key(|z| z.first);
    for z in sorted {
        match out.last_mut() {
            Some(m) if z.first <= m.last + MERGE_GAP_POINTS => {
                if z.min_abs_primary_deg < m.min_abs_primary_deg {
                    m.singular = z.singular;
                    m.min_abs_primary_deg = z.min_abs_primary_deg;
                }
                if z.kind == ZoneKind::AFlip {
                    m.kind = ZoneKind::AFlip;
                }
                m.last = m.last.max(z.last);
                m.c_ratio_min = m.c_ratio_min.min(z.c_ratio_min);
            }
            _ => out.push(z),
        }
    }
    out
}

/// What every zone shares.
struct Ctx<'a> {
    s: &'a [f64],
    p: Vec<f64>,
    /// Limits with the margin (what the solvers aim at); lowered along
    /// [`MARGIN_LADDER`] when no candidate passes.
    lim: std::cell::Cell<CLimits>,
    /// Limits without margin (what the verification checks).
    lim0: CLimits,
    step: f64,
    opts: &'a PatchOptions,
    methods: Methods,
}

impl Ctx<'_> {
    /// Try candidates for `zone` on the current values `cur`, not touching points before
    /// `lower`. `Some((kept, reached))`, or `None` when nothing better was found.
    ///
    /// Widening levels `extra` = 0, 1, 2, 4, …: at each, the G16 patch widened by `extra`
    /// and the direct QP over the hull of the zone widened by `extra`, the G16 patch's
    /// range and the previous level's direct range (so the direct range only grows and its
    /// min-max deviation can only go down), monotone first, without monotonicity only
    /// when the monotone candidate does not pass. Among the passing candidates the one with
    /// the smallest exact max deviation is kept. The widening stops at the first level
    /// after a pass that lowers the best deviation by less than
    /// [`DEVIATION_IMPROVEMENT_MIN`], after [`MAX_LEVELS_AFTER_PASS`] levels past the
    /// first pass, or at the run's ends / `max_patch_length_mm`.
    ///
    /// Needless solves are cut: the direct QP is not solved again on the range of the
    /// previous level (same problem, same answer), and once the G16 patch fails (no join, or
    /// infeasible after its own widening to the run's ends) it is not tried at wider levels,
    /// which would repeat that widening.
    fn patch_zone(
        &self,
        cur: &[f64],
        zone: &Zone,
        lower: usize,
        stats: &mut QpStats,
    ) -> Option<(Checked, bool)> {
        let n = self.s.len();
        let mut best: Option<Checked> = None;
        let mut passed: Option<(Checked, f64)> = None;
        let mut direct_range: Option<(usize, usize)> = None;
        let mut levels_after_pass = 0usize;
        let mut g16_gave_up = false;
        let mut extra = 0usize;
        loop {
            let zone_range = (
                zone.first.saturating_sub(extra).max(lower),
                (zone.last + extra).min(n - 1),
            );
            if zone_range.0 > zone_range.1 {
                break;
            }
            let best_before = passed.as_ref().map(|p| p.1);
            let mut range = zone_range;
            let consider = |c: Checked, passed: &mut Option<(Checked, f64)>| {
                let dev = self.max_deviation(cur, &c);
                if passed.as_ref().is_none_or(|p| dev < p.1) {
                    *passed = Some((c, dev));
                }
            };
            if self.methods.g16 && !g16_gave_up {
                match g16_patch(
                    self.s,
                    &self.p,
                    cur,
                    zone,
                    extra,
                    &self.lim.get(),
                    self.opts,
                ) {
                    Ok(c) => {
                        add_stats(stats, &c.qp);
                        if c.first >= lower && c.last < n && c.first <= c.last {
                            range = (range.0.min(c.first), range.1.max(c.last));
                            if let Some(ok) = self.check(cur, &c, Method::G16Patch, &mut best) {
                                consider(ok, &mut passed);
                            }
                        }
                    }
                    Err(PatchFailure::Solver(st)) => {
                        add_stats(stats, &st);
                        g16_gave_up = true;
                    }
                    Err(_) => g16_gave_up = true,
                }
            }
            if let Some(d) = direct_range {
                range = (range.0.min(d.0), range.1.max(d.1));
            }
            if self.methods.direct
                && range.1 - range.0 < DIRECT_MAX_POINTS
                && direct_range != Some(range)
            {
                direct_range = Some(range);
                let (first, last) = range;
                let net = cur[last] - cur[first];
                let sigma = (net.abs() > 1e-9).then(|| net.signum());
                let tries: &[Option<f64>] = if sigma.is_some() {
                    &[sigma, None]
                } else {
                    &[None]
                };
                for &mono in tries {
                    match direct_patch(
                        self.s,
                        &self.p,
                        cur,
                        first,
                        last,
                        &self.lim.get(),
                        mono,
                        self.opts,
                    ) {
                        Ok(c) => {
                            add_stats(stats, &c.qp);
                            if let Some(ok) = self.check(cur, &c, Method::Direct, &mut best) {
                                consider(ok, &mut passed);
                                break;
                            }
                        }
                        Err(PatchFailure::Solver(st)) => add_stats(stats, &st),
                        Err(_) => {}
                    }
                }
            }
            if let Some((_, dev)) = &passed {
                if let Some(prev) = best_before
                    && prev - dev < DEVIATION_IMPROVEMENT_MIN * prev
                {
                    break;
                }
                if *dev == 0.0 || levels_after_pass >= MAX_LEVELS_AFTER_PASS {
                    break;
                }
                levels_after_pass += 1;
            }
            let at_ends = range.0 <= lower && range.1 >= n - 1;
            let too_long = self
                .opts
                .max_patch_length_mm
                .is_some_and(|l| self.s[range.1] - self.s[range.0] >= l);
            if at_ends || too_long || extra > n {
                break;
            }
            extra = if extra == 0 { 1 } else { 2 * extra };
        }
        match passed {
            Some((c, _)) => Some((c, true)),
            None => best.map(|b| (b, false)),
        }
    }

    /// Largest exact orientation deviation of a checked candidate against `cur`.
    fn max_deviation(&self, cur: &[f64], c: &Checked) -> f64 {
        (c.first..=c.last)
            .zip(&c.values)
            .map(|(i, v)| orientation_deviation_deg(self.p[i], v - cur[i]))
            .fold(0.0, f64::max)
    }

    /// Round and verify a candidate; `Some` when it passes, else it may become `best`.
    fn check(
        &self,
        cur: &[f64],
        cand: &Candidate,
        method: Method,
        best: &mut Option<Checked>,
    ) -> Option<Checked> {
        let n = self.s.len();
        let (first, last) = (cand.first, cand.last);
        if cand.c_deg.len() != last - first + 1 || cand.c_deg.iter().any(|v| !v.is_finite()) {
            return None;
        }
        // Window of the path that the verification reads.
        let lo = first.saturating_sub(VERIFY_MARGIN_POINTS + 1);
        let hi = (last + VERIFY_MARGIN_POINTS + 1).min(n - 1);
        let before = &cur[lo..=hi];
        let build = |d: Option<usize>| -> Vec<f64> {
            let r = |v: f64| d.map_or(v, |d| round_written(v, d));
            let mut w = before.to_vec();
            for (i, v) in (first..=last).zip(&cand.c_deg) {
                w[i - lo] = r(*v);
            }
            if cand.c_offset_deg != 0.0 {
                for i in last + 1..=hi {
                    w[i - lo] = r(cur[i] + cand.c_offset_deg);
                }
            }
            w
        };
        let verify = |after: &[f64]| {
            verify_c_change(
                &self.s[lo..=hi],
                before,
                after,
                first - lo,
                last - lo,
                &self.lim0,
                self.step,
            )
        };
        let mut last_checked = None;
        for d in self.opts.c_decimals..=self.opts.max_decimals.max(self.opts.c_decimals) {
            let w = build(Some(d));
            let v = verify(&w);
            let checked = Checked {
                method,
                first,
                last,
                values: w[first - lo..=last - lo].to_vec(),
                offset: cand.c_offset_deg,
                decimals: d,
                verdict: v,
            };
            if v.passes() {
                return Some(checked);
            }
            last_checked = Some(checked);
            if d == self.opts.c_decimals && !verify(&build(None)).passes() {
                break; // not a rounding problem: more decimals will not help
            }
        }
        if let Some(c) = last_checked
            && c.verdict.improves()
            && c.verdict.core_min_after > 0.0
            && best
                .as_ref()
                .is_none_or(|b| c.verdict.core_min_after > b.verdict.core_min_after + RATIO_TOL)
        {
            *best = Some(c);
        }
        None
    }
}

/// Equation-6 figures over `[s(first), s(last)]`, from the analysis of a window of the
/// path around it.
fn zone_figures(
    path: &Path,
    machine: &Machine,
    aopts: &AnalysisOptions,
    first: usize,
    last: usize,
) -> Result<ZoneFigures, PathError> {
    let n = path.s_mm.len();
    let lo = first.saturating_sub(FIGURE_MARGIN_POINTS);
    let hi = (last + FIGURE_MARGIN_POINTS).min(n - 1);
    let window = Path {
        s_mm: path.s_mm[lo..=hi].to_vec(),
        axes: path.axes[lo..=hi].to_vec(),
        feed_mm_min: path.feed_mm_min,
    };
    let opts = AnalysisOptions {
        keep_samples: true,
        ..aopts.clone()
    };
    let a = analyze_path(&window, machine, &opts)?;
    let (s0, s1) = (path.s_mm[first], path.s_mm[last]);
    let mut f = ZoneFigures {
        c_ratio: 1.0,
        primary_ratio: 1.0,
        overall_ratio: f64::INFINITY,
        limiting_axis: None,
        limiting_kind: LimitKind::Feed,
        time_s: 0.0,
    };
    let mut prev: Option<(f64, f64)> = None;
    for smp in a.samples.iter().filter(|x| x.s_mm >= s0 && x.s_mm <= s1) {
        f.c_ratio = f.c_ratio.min(smp.axis_ratio[Axis::C.index()]);
        f.primary_ratio = f.primary_ratio.min(smp.axis_ratio[Axis::Primary.index()]);
        if smp.bound.ratio < f.overall_ratio {
            f.overall_ratio = smp.bound.ratio;
            f.limiting_axis = smp.bound.axis;
            f.limiting_kind = smp.bound.kind;
        }
        let inv = 1.0 / smp.bound.feed_mm_s;
        if let Some((sp, ip)) = prev {
            f.time_s += 0.5 * (inv + ip) * (smp.s_mm - sp);
        }
        prev = Some((smp.s_mm, inv));
    }
    if !f.overall_ratio.is_finite() {
        f.overall_ratio = 1.0;
    }
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::direct::deviation_bound_sampled;

    const DIRECT_ONLY: Methods = Methods {
        g16: false,
        direct: true,
    };

    fn machine(name: &str) -> Machine {
        Machine::builtin(name).expect("built-in machine")
    }

    /// A straight pass s = X whose tool axis sweeps past the pole at angular distance
    /// `d_deg`: tool axis ∝ (sin d, sin(τ(s)), 1), τ sweeping 0.4°/mm. `flip`: primary
    /// and C by the domain rule (sign of j: A flips and C jumps ~180° where j crosses 0);
    /// else the continuous branch A ≥ 0 (C swings ~180°).
    fn planted(n: usize, spacing: f64, d_deg: f64, flip: bool, feed: f64) -> Path {
        let mid = (n - 1) as f64 * spacing / 2.0;
        let mut s_mm = Vec::new();
        let mut axes = Vec::new();
        let mut prev_c: Option<f64> = None;
        for k in 0..n {
            let s = k as f64 * spacing;
            let v = [
                d_deg.to_radians().sin(),
                ((s - mid) * 0.4).to_radians().sin(),
                1.0,
            ];
            let nv = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let (i, j, kk) = (v[0] / nv, v[1] / nv, v[2] / nv);
            // i = sin C sin A, j = −cos C sin A, k = cos A.
            let mut a = kk.clamp(-1.0, 1.0).acos().to_degrees();
            let mut c = i.atan2(-j).to_degrees();
            if flip && j > 0.0 {
                a = -a;
                c = (-i).atan2(j).to_degrees();
            }
            if let Some(pc) = prev_c
                && !flip
            {
                while c - pc > 180.0 {
                    c -= 360.0;
                }
                while c - pc < -180.0 {
                    c += 360.0;
                }
            }
            let c = round_written(c, 3);
            prev_c = Some(c);
            s_mm.push(s);
            axes.push([s, 0.0, 0.0, round_written(a, 3), c]);
        }
        Path {
            s_mm,
            axes,
            feed_mm_min: feed,
        }
    }

    /// Checks the invariants of a patched path and returns a summary line.
    fn check_invariants(path: &Path, m: &Machine, res: &PatchResult, opts: &PatchOptions) {
        let before = analyze_path(path, m, &AnalysisOptions::default()).unwrap();
        let mut after_path = path.clone();
        for (q, c) in after_path.axes.iter_mut().zip(&res.c_deg) {
            q[4] = *c;
        }
        // Only C changes, and `changed` says where.
        for (i, (a, b)) in path.axes.iter().zip(&after_path.axes).enumerate() {
            assert_eq!(a[..4], b[..4]);
            assert_eq!(res.c_changed[i], a[4] != b[4]);
        }
        let after = analyze_path(&after_path, m, &AnalysisOptions::default()).unwrap();
        // Never worse on C.
        assert!(
            after.axis_min[4].0 >= before.axis_min[4].0 - 1e-9,
            "C ratio got worse: {} -> {}",
            before.axis_min[4].0,
            after.axis_min[4].0
        );
        for z in &res.zones {
            if z.min_abs_primary_deg <= opts.cone_deg {
                assert_eq!(z.outcome, Outcome::Reached, "zone not reached: {z:#?}");
                assert!(z.after.c_ratio >= 1.0 - 1e-9, "{z:#?}");
            }
        }
        // C reaches feed everywhere the zones were.
        assert!(after.zones.is_empty(), "zones left: {:?}", after.zones);
    }

    #[test]
    fn planted_passes_reach_feed() {
        let opts = PatchOptions::default();
        for (mname, feed) in [("mikron-hsm600", 3000.0), ("mikron-ucp710", 1000.0)] {
            let m = machine(mname);
            for flip in [false, true] {
                for d in [0.01, 0.5, 2.0, 4.0] {
                    for spacing in [1.0, 0.5] {
                        let n = (120.0 / spacing) as usize + 1;
                        let path = planted(n, spacing, d, flip, feed);
                        let res = patch_path_with(&path, &m, &opts, DIRECT_ONLY).unwrap();
                        for z in &res.zones {
                            eprintln!(
                                "{mname} F{feed} flip={flip} d={d} h={spacing}: {:?} {:?} \
                                 c {:.3}->{:.3} len {:.1} pts {} dev {:.3} dec {} t {:.3}s/{}",
                                z.kind,
                                z.outcome,
                                z.before.c_ratio,
                                z.after.c_ratio,
                                z.patch_length_mm,
                                z.points_modified,
                                z.max_deviation_deg,
                                z.decimals,
                                z.qp.solve_time_s,
                                z.qp.solves
                            );
                        }
                        check_invariants(&path, &m, &res, &opts);
                    }
                }
            }
        }
    }

    /// The same planted passes through [`patch_path`] (G16 first, direct as fallback).
    #[test]
    fn planted_passes_reach_feed_with_g16() {
        let opts = PatchOptions::default();
        for (mname, feed) in [("mikron-hsm600", 2000.0), ("mikron-ucp710", 2000.0)] {
            let m = machine(mname);
            for flip in [false, true] {
                for d in [0.01, 0.5, 2.0, 4.0] {
                    let path = planted(121, 1.0, d, flip, feed);
                    let res = patch_path(&path, &m, &opts).unwrap();
                    for z in &res.zones {
                        eprintln!(
                            "g16+direct {mname} F{feed} flip={flip} d={d}: {:?} {:?} {:?} \
                             len {:.1} dev {:.3}",
                            z.kind, z.outcome, z.method, z.patch_length_mm, z.max_deviation_deg
                        );
                    }
                    check_invariants(&path, &m, &res, &opts);
                }
            }
        }
    }

    #[test]
    fn no_point_in_cone_is_unchanged() {
        let m = machine("mikron-hsm600");
        let mut path = planted(41, 1.0, 8.0, false, 2000.0);
        for q in &mut path.axes {
            q[3] = q[3].abs().max(6.0);
        }
        let res = patch_path(&path, &m, &PatchOptions::default()).unwrap();
        assert!(res.zones.is_empty());
        assert!(!res.any_change());
        let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
        assert_eq!(res.c_deg, c);
    }

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
        let res = patch_path_with(&three, &m, &PatchOptions::default(), DIRECT_ONLY).unwrap();
        assert_eq!(res.c_deg.len(), 3);
        let mut pole = planted(81, 1.0, 0.0, false, 2000.0);
        pole.axes[40][3] = 0.0;
        let res = patch_path_with(&pole, &m, &PatchOptions::default(), DIRECT_ONLY).unwrap();
        assert_eq!(res.c_deg.len(), 81);
    }

    /// The C17 `%SING` program (N110..N620), s = X, on both built-in machines.
    #[test]
    fn c17_sing() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/c17/SING.I"
        ))
        .unwrap();
        let mut axes = Vec::new();
        for line in text.lines() {
            let nnum: usize = match line.strip_prefix('N').and_then(|r| r.split(' ').next()) {
                Some(v) => v.parse().unwrap_or(0),
                None => continue,
            };
            if !(110..=610).contains(&nnum) {
                continue;
            }
            let word = |l: char| -> f64 {
                line.split(' ')
                    .find_map(|w| w.strip_prefix(l))
                    .unwrap()
                    .parse()
                    .unwrap()
            };
            axes.push([word('X'), 0.0, -8.0, word('A'), word('C')]);
        }
        assert_eq!(axes.len(), 51);
        let path = Path {
            s_mm: axes.iter().map(|q| q[0]).collect(),
            axes,
            feed_mm_min: 2000.0,
        };
        let opts = PatchOptions::default();
        for mname in ["mikron-ucp710", "mikron-hsm600"] {
            let m = machine(mname);
            let res = patch_path_with(&path, &m, &opts, DIRECT_ONLY).unwrap();
            assert!(!res.zones.is_empty());
            let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
            let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
            for z in &res.zones {
                let step = 2000.0 / 60.0 * m.tcy_s;
                let lim0 = CLimits::new(&m, 2000.0, 0.0);
                let (bound, _) =
                    deviation_bound_sampled(&path.s_mm, &p, &c, z.first, z.last, &lim0, step)
                        .unwrap();
                eprintln!(
                    "SING {mname}: {:?} {:?} c {:.3}->{:.3} pts {}..{} len {:.1} mod {} \
                     dev {:.3} bound {:.3} dec {} qp {:.4}s/{} time {:.3}->{:.3} ideal {:.3}",
                    z.kind,
                    z.outcome,
                    z.before.c_ratio,
                    z.after.c_ratio,
                    z.first,
                    z.last,
                    z.patch_length_mm,
                    z.points_modified,
                    z.max_deviation_deg,
                    bound,
                    z.decimals,
                    z.qp.solve_time_s,
                    z.qp.solves,
                    z.before.time_s,
                    z.after.time_s,
                    z.ideal_time_s
                );
                assert!(bound <= z.max_deviation_deg + 1e-6);
            }
            check_invariants(&path, &m, &res, &opts);
        }
    }
}
