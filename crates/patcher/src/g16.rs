//! The G16 patch (SPEC §3 steps 3–5): split, fit C_b and C_a, join search, patch QP,
//! projection of the CL points.
//!
//! Units: s in mm, every angle in degrees (C, the primary axis, the deviation), C
//! derivatives in °/mm, °/mm², °/mm³. Nothing here converts to radians except the
//! `sin` of the primary axis.
//!
//! # Stages (G16 §3.2, Figure 5; SPEC §3)
//!
//! 1. **Split** (G16 stage 2) at the singular point `zone.singular`: points `..=singular`
//!    are *before*, `singular + 1..` *after*.
//! 2. **Fit** (stage 3) the not-a-knot interpolating cubics C_b(s) through the before
//!    points and C_a(s) through the after points, on a local window of
//!    [`SolverSettings::g16_fit_margin_points`] CL points (plus the patch extension) beyond the zone on each
//!    side: the far parts of the path do not matter to the patch.
//! 3. **Offset and direction.** C_a may be shifted by k·360°, k ∈ {−1, 0, 1} (only with
//!    `allow_c_offset`), and the patch moves C in the direction σ = ±1.
//! 4. **Join search** (stages 4–6): for each (k, σ), step from the split outward with
//!    h = [`SolverSettings::g16_join_step_fraction`] · (median CL spacing), backwards on C_b and forwards on
//!    C_a independently, until σ·C'(s) ≥ 0: the *core* [s_b*, s_a*], where the patch
//!    must be monotone. A choice is consistent when the change it asks,
//!    gap = C_a(s_a*) + k·360 − C_b(s_b*), has the sign σ; among consistent choices the
//!    shortest join |gap| wins. (The plain rule "k from the jump at the split, σ from the
//!    net change over the window" picks, for a domain-rule flip whose jump is close to
//!    180°, a direction against the motion on both sides, for which no join exists; and
//!    for a C swing like C17 `%SING` it may pick the long way round.)
//!    The patch ends s_b ≤ min(s_b*, s(zone.first − 1)) and
//!    s_a ≥ max(s_a*, s(zone.last + 1)) are the first samples further out where
//!    |C'| ≤ v and |C''| ≤ a (the joins are at least one CL point outside the zone). The
//!    patch [s_b, s_a] is then widened by `extra` (+ the internal growth, below) CL
//!    points on each side, clipped to the fit window; the first and last points of the
//!    path are never modified.
//! 5. **Patch QP** (stages 8–9), below.
//! 6. **Projection** (stage 10): every CL point strictly inside (s_b, s_a) gets
//!    C_i = P(s_i) (unrounded; the caller rounds and verifies).
//!
//! The sampling step fs = F·Tcy of G16 eq. 8 is not known here (neither F nor Tcy is an
//! argument). It is not needed: every bound is imposed on the control polygons of the
//! derivative splines of P, which by the convex-hull property of B-splines bounds the
//! derivative at **every** s, hence at every sample whatever fs is. Sampling is only used
//! by the join search, with the step h above.
//!
//! # The patch QP
//!
//! P(s) is a clamped cubic B-spline on [s_b, s_a] with breakpoints s_b, the CL points
//! strictly inside (those closer than [`SolverSettings::g16_min_span_fraction`] of the median spacing to
//! s_b or s_a are skipped) and s_a; knots T (4-fold ends), control points x_0..x_{m−1}.
//! Its derivatives are splines with control points
//!
//! ```text
//! d_k = 3 (x_{k+1} − x_k) / (T_{k+4} − T_{k+1})       P'   (degree 2), k = 0..m−2
//! e_k = 2 (d_{k+1} − d_k) / (T_{k+4} − T_{k+2})       P''  (degree 1), k = 0..m−3
//! f_k =   (e_{k+1} − e_k) / (T_{k+4} − T_{k+3})       P''' (constant on span k)
//! ```
//!
//! Variables: x (degrees, shifted by C_b(s_b) for conditioning) and t, the largest
//! weighted deviation (degrees). With w_i = |sin p_i| and C_i the original C (plus k·360
//! after the split) of each CL point i strictly inside (s_b, s_a):
//!
//! ```text
//! minimise   t + μ Σ_i (w_i (P(s_i) − C_i))² + ε Σ_k (T_{k+4} − T_{k+3}) f_k²
//! subject to x_0 = C_b(s_b),  d_0 = C_b'(s_b),  e_0 = C_b''(s_b)       (joins, C²)
//!            x_{m−1} = C_a(s_a), d_{m−2} = C_a'(s_a), e_{m−3} = C_a''(s_a)
//!            f_0 = C_b'''(s_b), f_{m−4} = C_a'''(s_a)   (C³, when asked and feasible)
//!            σ d_k ≥ ℓ_k                                 (monotone, see below)
//!            |d_k| ≤ v,  |e_k| ≤ a,  |f_k| ≤ j           (Equation 6 reaches F)
//!            −t ≤ w_i (P(s_i) − C_i) ≤ t
//!            t ≤ max_deviation_deg                       (when given)
//! ```
//!
//! μ = [`SolverSettings::g16_lsq_weight`], ε = [`SolverSettings::g16_jerk_weight`]. The deviation of a point, SPEC §3:
//! 2·asin(|sin p|·|sin(ΔC/2)|), is replaced by its small-angle form |sin p|·|ΔC| (both in
//! degrees); the form is exact to first order and over-estimates the true deviation
//! (asin x ≥ x, |sin y| ≤ |y|), so `t ≤ max_deviation_deg` is conservative.
//!
//! **Monotonicity.** Inside the core, ℓ_k = 0 (G16 stage 9: P never reverses). Between
//! the core and the patch ends (the zone's shoulders, `extra` and the growth) the original
//! curve itself may move against σ, and P' equals C' at the joins, so there
//! ℓ_k = min(0, min σ·C'(s) over the part of the support of d_k outside the core): P
//! never reverses faster than the original path did there.
//!
//! **Growth.** When the QP is infeasible (first with C³ joins when asked, then with C²
//! joins), the patch is widened by 1, 2, 4, 8, … more CL points on each side and solved
//! again, up to the path ends or `max_patch_length_mm`. A widening that cannot pass a
//! necessary test (the change |C_a(s_a) − C_b(s_b)| must be within reach of a velocity
//! profile starting and ending at the join slopes with |C'| ≤ v, |C''| ≤ a) is skipped
//! without a solve.

use crate::{
    analysis::Zone,
    candidate::{Candidate, PatchFailure},
    limits::CLimits,
    options::PatchOptions,
    qp::{QpBuilder, Row, combine, scaled},
    report::{QpStats, QpStatus},
    settings::SolverSettings,
    tolerances::{G16_SPACING_POINTS, REACH_SLACK, REACH_STEPS},
};
use polepatch_bspline::{BSpline, interpolate_not_a_knot, knots::clamped_cubic};

/// Propose new C values for `zone` of a path (`s_mm`, primary `p_deg`, `c_deg` per point)
/// by the G16 method; `extra` widens the patch by that many CL points on each side beyond
/// the join found by the join search (the caller's extension loop).
pub fn g16_patch(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    zone: &Zone,
    extra: usize,
    lim: &CLimits,
    opts: &PatchOptions,
) -> Result<Candidate, PatchFailure> {
    g16_patch_detail(s_mm, p_deg, c_deg, zone, extra, lim, opts).map(|(c, _)| c)
}

/// The patch curve behind a [`Candidate`] (for tests and plots).
#[derive(Debug, Clone)]
#[cfg_attr(not(test), allow(dead_code))]
struct PatchCurve {
    /// P(s) on [s_b, s_a], degrees.
    spline: BSpline,
    /// C_b (fit before the split), degrees.
    cb: BSpline,
    /// C_a + k·360 (fit after the split), degrees.
    ca: BSpline,
    /// Joins, mm.
    s_b: f64,
    s_a: f64,
    /// Core joins from the join search, mm.
    core_b: f64,
    core_a: f64,
    /// Direction of the net change.
    sigma: f64,
    /// Whether the C³ joins were kept.
    third: bool,
}

/// [`g16_patch`] with the patch curve. The steps: the split ([`Split::new`]); per attempt
/// the fits on the window ([`Split::fit`]), the join search ([`Split::join`]), the patch
/// ends widened by `extra` and the growth ([`Split::patch_ends`]), the patch QP when the
/// change is within reach ([`solve_if_reachable`]); a join window enlarged when no join
/// exists, the patch widened when no solution does.
fn g16_patch_detail(
    s_mm: &[f64],
    p_deg: &[f64],
    c_deg: &[f64],
    zone: &Zone,
    extra: usize,
    lim: &CLimits,
    opts: &PatchOptions,
) -> Result<(Candidate, PatchCurve), PatchFailure> {
    let settings = &opts.solver;
    let split = Split::new(s_mm, p_deg, c_deg, zone, settings)?;
    let (n, sing) = (s_mm.len(), split.sing);

    // Offsets k·360 of C_a to consider (G16 stage 3, generalised).
    let offsets: &[f64] = if opts.allow_c_offset {
        &[0.0, 360.0, -360.0]
    } else {
        &[0.0]
    };

    let mut stats = QpStats::default();
    let mut fit_margin = settings.g16_fit_margin_points;
    let mut grow = 0usize;

    for _ in 0..settings.g16_max_attempts {
        let ext = extra + grow;
        let lo_fit = split.first_z.saturating_sub(fit_margin + ext);
        let hi_fit = (split.last_z + fit_margin + ext).min(n - 1);
        let cb = split.fit(lo_fit..=sing, 0.0)?;
        let Some(join) = split.join(&cb, (lo_fit, hi_fit), lim, offsets)? else {
            if lo_fit == 0 && hi_fit == n - 1 {
                return Err(PatchFailure::NoJoin);
            }
            fit_margin *= 2;
            continue;
        };
        let (s_b, s_a, can_grow) = split.patch_ends(&join, ext, (lo_fit, hi_fit));
        if let Some(max_len) = opts.max_patch_length_mm
            && s_a - s_b > max_len
        {
            return Err(if stats.solves == 0 && ext == 0 {
                PatchFailure::NoJoin
            } else {
                PatchFailure::Solver(stats)
            });
        }
        let setup = PatchSetup {
            s_mm,
            p_deg,
            cb: &cb,
            ca: &join.ca,
            s_b,
            s_a,
            core_b: join.core_b,
            core_a: join.core_a,
            sigma: join.sigma,
            h_cl: split.h_cl,
            lim,
            max_dev: opts.max_deviation_deg,
            settings,
        };
        let target = |i: usize| c_deg[i] + if i > sing { join.off } else { 0.0 };
        let solved = solve_if_reachable(&setup, &target, opts, &mut stats)?;
        if let Some(((first, last, c_new), spline, third)) = solved {
            let curve = PatchCurve {
                spline,
                cb,
                s_b,
                s_a,
                core_b: join.core_b,
                core_a: join.core_a,
                sigma: join.sigma,
                third,
                ca: join.ca,
            };
            let cand = Candidate {
                first,
                last,
                c_deg: c_new,
                c_offset_deg: join.off,
                qp: stats,
            };
            return Ok((cand, curve));
        }
        if !can_grow {
            if stats.solves == 0 {
                // The patch is too short for the velocity bound.
                stats.status = QpStatus::SkippedInfeasible;
            }
            return Err(PatchFailure::Solver(stats));
        }
        grow = (2 * grow).max(1);
    }
    Err(PatchFailure::Solver(stats))
}

/// The path around one zone split at its singular point (stage 1): points `..=sing` are
/// before, `sing + 1..` after; the zone widened to hold the split, and the join search's
/// step.
struct Split<'a> {
    s_mm: &'a [f64],
    c_deg: &'a [f64],
    sing: usize,
    /// First point of the zone, at most `sing`.
    first_z: usize,
    /// Last point of the zone, at least `sing + 1`.
    last_z: usize,
    /// Median CL spacing around the zone, mm.
    h_cl: f64,
    /// The join search's step, mm.
    h: f64,
}

/// The choice of the join search (stage 6): the offset k·360 of C_a, the direction σ,
/// C_a with the offset, and the joins, mm: the patch ends `join_b`, `join_a` and the core
/// `core_b`, `core_a`.
struct Join {
    off: f64,
    sigma: f64,
    ca: BSpline,
    join_b: f64,
    core_b: f64,
    core_a: f64,
    join_a: f64,
}

impl<'a> Split<'a> {
    /// The split of `zone`; [`PatchFailure::TooShort`] unless there are at least two
    /// points on each side and the arrays agree.
    fn new(
        s_mm: &'a [f64],
        p_deg: &[f64],
        c_deg: &'a [f64],
        zone: &Zone,
        settings: &SolverSettings,
    ) -> Result<Split<'a>, PatchFailure> {
        let n = s_mm.len();
        let sing = zone.singular;
        // At least two points on each side of the split, and consistent arrays.
        if p_deg.len() != n || c_deg.len() != n || sing == 0 || sing + 2 >= n {
            return Err(PatchFailure::TooShort);
        }
        let first_z = zone.first.min(sing);
        let last_z = zone.last.max(sing + 1).min(n - 1);

        let h_cl = median_spacing(
            s_mm,
            first_z.saturating_sub(G16_SPACING_POINTS),
            (last_z + G16_SPACING_POINTS).min(n - 1),
        );
        if h_cl.is_nan() || h_cl <= 0.0 {
            return Err(PatchFailure::TooShort);
        }
        Ok(Split {
            s_mm,
            c_deg,
            sing,
            first_z,
            last_z,
            h_cl,
            h: h_cl * settings.g16_join_step_fraction,
        })
    }

    /// The not-a-knot cubic through the points `range` with C + `off` (stage 3).
    fn fit(
        &self,
        range: std::ops::RangeInclusive<usize>,
        off: f64,
    ) -> Result<BSpline, PatchFailure> {
        let y: Vec<f64> = self.c_deg[range.clone()].iter().map(|c| c + off).collect();
        interpolate_not_a_knot(&self.s_mm[range], &y).map_err(|_| PatchFailure::TooShort)
    }

    /// Stage 6, for every offset k and direction σ: the core (monotone) joins from the
    /// split, then the patch ends at least one CL point outside the zone where C' and C''
    /// are within the limits. Keep the consistent choices (σ·gap ≥ 0) and among them the
    /// shortest join |gap|; `None` when there is none on the fit window
    /// `(lo_fit, hi_fit)`.
    fn join(
        &self,
        cb: &BSpline,
        (lo_fit, hi_fit): (usize, usize),
        lim: &CLimits,
        offsets: &[f64],
    ) -> Result<Option<Join>, PatchFailure> {
        let (s_mm, sing, h) = (self.s_mm, self.sing, self.h);
        let n = s_mm.len();
        let within = |d: [f64; 4]| d[1].abs() <= lim.v && d[2].abs() <= lim.a;
        let end_b = s_mm[self.first_z.saturating_sub(1)];
        let end_a = s_mm[(self.last_z + 1).min(n - 1)];
        let (stop_b, stop_a) = (s_mm[lo_fit], s_mm[hi_fit]);
        let joins_b: Vec<Option<(f64, f64)>> = [1.0, -1.0]
            .iter()
            .map(|&sg| {
                let core = join_search(cb, s_mm[sing], stop_b, -h, |d| sg * d[1] >= 0.0)?;
                let end = join_search(cb, core.min(end_b), stop_b, -h, within)?;
                Some((core, end))
            })
            .collect();
        let mut best: Option<(f64, Join)> = None;
        for &off in offsets {
            let ca = self.fit(sing + 1..=hi_fit, off)?;
            for (si, sigma) in [1.0, -1.0].into_iter().enumerate() {
                let Some((core_b, join_b)) = joins_b[si] else {
                    continue;
                };
                let Some(core_a) =
                    join_search(&ca, s_mm[sing + 1], stop_a, h, |d| sigma * d[1] >= 0.0)
                else {
                    continue;
                };
                let Some(join_a) = join_search(&ca, core_a.max(end_a), stop_a, h, within) else {
                    continue;
                };
                let gap = ca.eval(core_a) - cb.eval(core_b);
                if sigma * gap < 0.0 {
                    continue;
                }
                if best.as_ref().is_none_or(|b| gap.abs() < b.0) {
                    let join = Join {
                        off,
                        sigma,
                        ca: ca.clone(),
                        join_b,
                        core_b,
                        core_a,
                        join_a,
                    };
                    best = Some((gap.abs(), join));
                }
            }
        }
        Ok(best.map(|(_, join)| join))
    }

    /// The patch ends `(s_b, s_a)`: the joins widened by `ext` CL points each side,
    /// inside the fit window `(lo_fit, hi_fit)`; and whether a further widening could
    /// grow the patch.
    fn patch_ends(
        &self,
        join: &Join,
        ext: usize,
        (lo_fit, hi_fit): (usize, usize),
    ) -> (f64, f64, bool) {
        let s_mm = self.s_mm;
        let n = s_mm.len();
        let ib = s_mm
            .partition_point(|&x| x <= join.join_b)
            .saturating_sub(1);
        let ia = s_mm.partition_point(|&x| x < join.join_a).min(n - 1);
        let (s_b, s_a) = if ext == 0 {
            (join.join_b, join.join_a)
        } else {
            (
                s_mm[ib.saturating_sub(ext).max(lo_fit)],
                s_mm[(ia + ext).min(hi_fit)],
            )
        };
        let can_grow = ib.saturating_sub(ext) > 0 || ia + ext < n - 1;
        (s_b, s_a, can_grow)
    }
}

/// The patch QP on `setup` (with C³ joins first when asked, then C²), unless a necessary
/// condition of |P'| ≤ v, |P''| ≤ a with the join slopes fails: hopeless widenings are
/// skipped without a solve. The projected points, P and whether the C³ joins were kept;
/// `None` when skipped or no mode produced a solution.
fn solve_if_reachable(
    setup: &PatchSetup<'_>,
    target: &dyn Fn(usize) -> f64,
    opts: &PatchOptions,
    stats: &mut QpStats,
) -> Result<Option<(Projected, BSpline, bool)>, PatchFailure> {
    let (cb, ca, lim) = (setup.cb, setup.ca, setup.lim);
    let (s_b, s_a) = (setup.s_b, setup.s_a);
    let gap = ca.eval(s_a) - cb.eval(s_b);
    let (vb, va) = (cb.eval_derivs(s_b)[1], ca.eval_derivs(s_a)[1]);
    let sg = if gap >= 0.0 { 1.0 } else { -1.0 };
    let reach = reachable(s_a - s_b, sg * vb, sg * va, lim.v, lim.a);
    let hopeless = gap.abs() > reach * (1.0 + REACH_SLACK);
    if hopeless {
        return Ok(None);
    }
    let modes: &[bool] = if opts.third_derivative_continuity {
        &[true, false]
    } else {
        &[false]
    };
    for &third in modes {
        if let Some((proj, spline)) = solve_patch(setup, target, third, stats)? {
            return Ok(Some((proj, spline, third)));
        }
    }
    Ok(None)
}

/// Largest change of C over a patch of length `len` (mm) that starts with slope `v0` and
/// ends with slope `v1` (°/mm) under |C'| ≤ `v`, |C''| ≤ `a`: the integral of the
/// velocity envelope min(v, v0 + a·s, v1 + a·(len − s)) (a double integrator; the jerk
/// bound only lowers it, so this is a necessary condition for the QP).
fn reachable(len: f64, v0: f64, v1: f64, v: f64, a: f64) -> f64 {
    let u = |s: f64| v.min(v0 + a * s).min(v1 + a * (len - s));
    let dx = len / REACH_STEPS as f64;
    (0..REACH_STEPS)
        .map(|k| 0.5 * (u(k as f64 * dx) + u((k + 1) as f64 * dx)) * dx)
        .sum()
}

/// Median of the CL spacings between points `lo..=hi`, mm.
fn median_spacing(s_mm: &[f64], lo: usize, hi: usize) -> f64 {
    let mut d: Vec<f64> = s_mm[lo..=hi].windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return 0.0;
    }
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

/// Step from `start` towards `stop` by `step` (negative: backwards) until `ok` holds for
/// `[C, C', C'', C''']`; the first such s, or `None`.
fn join_search(
    sp: &BSpline,
    start: f64,
    stop: f64,
    step: f64,
    ok: impl Fn([f64; 4]) -> bool,
) -> Option<f64> {
    let past = |s: f64| if step < 0.0 { s < stop } else { s > stop };
    let mut s = if past(start) { stop } else { start };
    loop {
        if ok(sp.eval_derivs(s)) {
            return Some(s);
        }
        if s == stop {
            return None;
        }
        s += step;
        if past(s) {
            s = stop;
        }
    }
}

/// Everything the patch QP needs besides the options of one solve.
struct PatchSetup<'a> {
    s_mm: &'a [f64],
    p_deg: &'a [f64],
    cb: &'a BSpline,
    ca: &'a BSpline,
    s_b: f64,
    s_a: f64,
    core_b: f64,
    core_a: f64,
    sigma: f64,
    h_cl: f64,
    lim: &'a CLimits,
    max_dev: Option<f64>,
    settings: &'a SolverSettings,
}

/// A projected patch: first and last modified point and their new C, degrees.
type Projected = (usize, usize, Vec<f64>);

/// Build and solve the patch QP; the projected points and P. `Ok(None)`: the solver did
/// not produce a solution (infeasible or not converged; `stats` holds its status).
fn solve_patch(
    st: &PatchSetup,
    target: &dyn Fn(usize) -> f64,
    third: bool,
    stats: &mut QpStats,
) -> Result<Option<(Projected, BSpline)>, PatchFailure> {
    let s = st.s_mm;
    let (s_b, s_a) = (st.s_b, st.s_a);
    // CL points strictly inside (s_b, s_a): projected and weighed.
    let first = s.partition_point(|&x| x <= s_b);
    let last_excl = s.partition_point(|&x| x < s_a);
    if first >= last_excl {
        return Err(PatchFailure::TooShort);
    }
    let last = last_excl - 1;
    let min_span = st.settings.g16_min_span_fraction * st.h_cl;
    let mut breaks = vec![s_b];
    breaks.extend(
        s[first..=last]
            .iter()
            .copied()
            .filter(|&x| x - s_b >= min_span && s_a - x >= min_span),
    );
    breaks.push(s_a);
    let knots = clamped_cubic(&breaks);
    let m = breaks.len() + 2;
    let t_var = m;
    let basis = BSpline::new(3, knots.clone(), vec![0.0; m]).map_err(|_| PatchFailure::TooShort)?;
    let tk = |i: usize| knots[i];

    // Control-point rows of P', P'', P'''.
    let d: Vec<Row> = (0..m - 1)
        .map(|k| {
            let c = 3.0 / (tk(k + 4) - tk(k + 1));
            vec![(k + 1, c), (k, -c)]
        })
        .collect();
    let e: Vec<Row> = (0..m - 2)
        .map(|k| {
            let c = 2.0 / (tk(k + 4) - tk(k + 2));
            combine(c, &d[k + 1], -c, &d[k])
        })
        .collect();
    let f: Vec<Row> = (0..m - 3)
        .map(|k| {
            let c = 1.0 / (tk(k + 4) - tk(k + 3));
            combine(c, &e[k + 1], -c, &e[k])
        })
        .collect();

    let c_ref = st.cb.eval(s_b);
    let jb = st.cb.eval_derivs(s_b);
    let ja = st.ca.eval_derivs(s_a);
    let mut qp = QpBuilder::new(m + 1);

    // Joins.
    qp.add_eq(&[(0, 1.0)], 0.0);
    qp.add_eq(&d[0], jb[1]);
    qp.add_eq(&e[0], jb[2]);
    qp.add_eq(&[(m - 1, 1.0)], ja[0] - c_ref);
    qp.add_eq(&d[m - 2], ja[1]);
    qp.add_eq(&e[m - 3], ja[2]);
    if third {
        qp.add_eq(&f[0], jb[3]);
        qp.add_eq(&f[m - 4], ja[3]);
    }

    // Monotone and Equation-6 bounds on the control polygons.
    let sigma = st.sigma;
    for (k, dk) in d.iter().enumerate() {
        let mut floor = monotone_floor(st, tk(k + 1), tk(k + 4));
        if k == 0 {
            floor = floor.min(sigma * jb[1]);
        }
        if k == m - 2 {
            floor = floor.min(sigma * ja[1]);
        }
        qp.add_le(&scaled(-sigma, dk), -floor);
        qp.add_le(dk, st.lim.v);
        qp.add_le(&scaled(-1.0, dk), st.lim.v);
    }
    for ek in &e {
        qp.add_le(ek, st.lim.a);
        qp.add_le(&scaled(-1.0, ek), st.lim.a);
    }
    for (k, fk) in f.iter().enumerate() {
        qp.add_le(fk, st.lim.j);
        qp.add_le(&scaled(-1.0, fk), st.lim.j);
        qp.add_square(
            fk,
            st.settings.g16_jerk_weight * (tk(k + 4) - tk(k + 3)),
            0.0,
        );
    }

    // Deviation at the CL points.
    let rows: Vec<Row> = (first..=last)
        .map(|i| {
            let b = basis.basis_row(s[i], 0);
            (0..4)
                .filter(|&q| b.first + q < m && b.weights[q] != 0.0)
                .map(|q| (b.first + q, b.weights[q]))
                .collect()
        })
        .collect();
    for (i, r) in (first..=last).zip(&rows) {
        let w = st.p_deg[i].to_radians().sin().abs();
        let y = target(i) - c_ref;
        let mut up = scaled(w, r);
        up.push((t_var, -1.0));
        qp.add_le(&up, w * y);
        let mut dn = scaled(-w, r);
        dn.push((t_var, -1.0));
        qp.add_le(&dn, -w * y);
        qp.add_square(r, st.settings.g16_lsq_weight * w * w, y);
    }
    qp.add_linear(t_var, 1.0);
    if let Some(dmax) = st.max_dev {
        qp.add_le(&[(t_var, 1.0)], dmax);
    }

    match qp.solve(stats) {
        Ok(x) => {
            let c_new = rows
                .iter()
                .map(|r| c_ref + r.iter().map(|&(k, w)| w * x[k]).sum::<f64>())
                .collect();
            let coeffs = x[..m].iter().map(|v| v + c_ref).collect();
            let spline = BSpline::new(3, knots, coeffs).map_err(|_| PatchFailure::TooShort)?;
            Ok(Some(((first, last, c_new), spline)))
        }
        Err(_) => Ok(None),
    }
}

/// ℓ for a control point of P' whose support is [lo, hi]: 0 inside the core, and in the
/// extensions the most negative σ·C' of the original curve over the support (never > 0).
fn monotone_floor(st: &PatchSetup, lo: f64, hi: f64) -> f64 {
    let mut floor: f64 = 0.0;
    let mut probe = |sp: &BSpline, a: f64, b: f64| {
        if a < b {
            let probes = st.settings.g16_monotone_probes;
            for q in 0..=probes {
                let x = a + (b - a) * q as f64 / probes as f64;
                floor = floor.min(st.sigma * sp.eval_derivs(x)[1]);
            }
        }
    };
    probe(st.cb, lo.max(st.s_b), hi.min(st.core_b));
    probe(st.ca, lo.max(st.core_a), hi.min(st.s_a));
    floor
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::ZoneKind;

    /// C limits from machine figures (°/s, °/s², °/s³) at `feed_mm_min`, margin applied.
    fn limits(v: f64, a: f64, j: f64, feed_mm_min: f64, margin: f64) -> CLimits {
        let f = feed_mm_min / 60.0;
        let k = 1.0 - margin;
        CLimits {
            v: k * v / f,
            a: k * a / (f * f),
            j: k * j / (f * f * f),
        }
    }
    fn ucp710(feed: f64) -> CLimits {
        limits(120.0, 298.8, 18000.0, feed, 0.02)
    }
    fn hsm600(feed: f64) -> CLimits {
        limits(2160.0, 2520.0, 36000.0, feed, 0.02)
    }

    /// A straight pass s = X with the tool axis o(s) = (tan d, g·(s − mid), 1) normalised:
    /// a great circle passing at angle `d_deg` from the pole at `mid` and tilting to
    /// `end_tilt_deg` at the ends. UCP710 kinematics i = sin C sin A, j = −cos C sin A,
    /// k = cos A. `flip`: domain rule (cos C ≥ 0, A changes sign); otherwise the
    /// continuous branch (A > 0, C unwrapped).
    fn planted(n: usize, ds: f64, d_deg: f64, end_tilt_deg: f64, flip: bool) -> [Vec<f64>; 3] {
        planted_rot(n, ds, d_deg, end_tilt_deg, flip, 0.0)
    }

    /// [`planted`] with the tool axis turned by `phi_deg` about Z (the domain-rule flip then
    /// happens away from the closest approach to the pole).
    fn planted_rot(
        n: usize,
        ds: f64,
        d_deg: f64,
        end_tilt_deg: f64,
        flip: bool,
        phi_deg: f64,
    ) -> [Vec<f64>; 3] {
        let (sf, cf) = phi_deg.to_radians().sin_cos();
        let len = (n - 1) as f64 * ds;
        let mid = 0.5 * len + 0.3 * ds;
        let g = end_tilt_deg.to_radians().tan() / (0.5 * len);
        let (mut s, mut p, mut c): (Vec<f64>, Vec<f64>, Vec<f64>) = (vec![], vec![], vec![]);
        for k in 0..n {
            let x = k as f64 * ds;
            let o0 = [d_deg.to_radians().tan(), g * (x - mid)];
            let o = [cf * o0[0] - sf * o0[1], sf * o0[0] + cf * o0[1], 1.0];
            let nrm = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt();
            let mut a = (o[2] / nrm).acos().to_degrees();
            let mut cc = o[0].atan2(-o[1]).to_degrees();
            if flip && cc.to_radians().cos() < 0.0 {
                a = -a;
                cc -= 180.0f64.copysign(cc);
            }
            if !flip && let Some(&prev) = c.last() {
                cc += 360.0 * ((prev - cc) / 360.0f64).round();
            }
            s.push(x);
            p.push(a);
            c.push(cc);
        }
        [s, p, c]
    }

    /// Largest |C_s|/v, |C_ss|/a, |C_sss|/j of the analysis spline through `c` over
    /// [s(lo), s(hi)], sampled at `step` and at every knot.
    fn analysis_ratios(s: &[f64], c: &[f64], lo: usize, hi: usize, lim: &CLimits) -> [f64; 3] {
        let sp = interpolate_not_a_knot(s, c).unwrap();
        let mut r = [0.0f64; 3];
        let mut ts: Vec<f64> = Vec::new();
        for i in lo..hi {
            for q in 0..40 {
                ts.push(s[i] + (s[i + 1] - s[i]) * q as f64 / 40.0);
            }
            // Just inside the right end of the span (third derivative is per span).
            ts.push(s[i + 1] - 1e-9);
        }
        for t in ts {
            let d = sp.eval_derivs(t);
            r[0] = r[0].max(d[1].abs() / lim.v);
            r[1] = r[1].max(d[2].abs() / lim.a);
            r[2] = r[2].max(d[3].abs() / lim.j);
        }
        r
    }

    /// The zone as the analysis would find it: a run of spans where the analysis spline
    /// breaks a C bound, with a point of |p| ≤ 5° in it (the singular cone); singular =
    /// least |p| (for a sign change, the point before it).
    fn zone_of(s: &[f64], p: &[f64], c: &[f64], lim: &CLimits) -> Option<Zone> {
        let n = s.len();
        let sp = interpolate_not_a_knot(s, c).unwrap();
        let bad: Vec<bool> = (0..n - 1)
            .map(|i| {
                (0..=40).any(|q| {
                    let t = s[i] + (s[i + 1] - s[i]) * q as f64 / 40.0;
                    let d = sp.eval_derivs(t.min(s[i + 1] - 1e-9));
                    d[1].abs() > lim.v || d[2].abs() > lim.a || d[3].abs() > lim.j
                })
            })
            .collect();
        let mut i = 0;
        while i < n - 1 {
            if !bad[i] {
                i += 1;
                continue;
            }
            let mut k = i;
            while k + 1 < n - 1 && bad[k + 1] {
                k += 1;
            }
            // Spans i..=k: points i..=k+1.
            let (first, last) = (i, k + 1);
            if (first..=last).any(|q| p[q].abs() <= 5.0) {
                let flip = (first..last).find(|&q| p[q] * p[q + 1] < 0.0);
                let singular = flip.unwrap_or_else(|| {
                    (first..=last)
                        .min_by(|&a, &b| p[a].abs().total_cmp(&p[b].abs()))
                        .unwrap()
                });
                return Some(Zone {
                    first,
                    last,
                    singular,
                    kind: if flip.is_some() {
                        ZoneKind::AFlip
                    } else {
                        ZoneKind::CSwing
                    },
                    min_abs_primary_deg: (first..=last)
                        .fold(f64::INFINITY, |m, q| m.min(p[q].abs())),
                    c_ratio_min: 0.0,
                    cut_before: false,
                    cut_after: false,
                });
            }
            i = k + 1;
        }
        None
    }

    /// Figures of one patched case (printed with `--nocapture`).
    #[derive(Debug)]
    #[allow(dead_code)]
    struct Figures {
        patch_mm: f64,
        modified: usize,
        max_dev_deg: f64,
        analysis: [f64; 3],
    }

    /// Patch, check the patch curve against every promise, and return the figures.
    fn check_case(name: &str, [s, p, c]: &[Vec<f64>; 3], lim: &CLimits) -> Figures {
        let zone = zone_of(s, p, c, lim).expect("planted case has a zone");
        // The G16 method as the paper has it: C after the split may take a 360° offset
        // (off by default since it moves the rest of the run; see flip_without_offset_has_no_join).
        let opts = PatchOptions {
            allow_c_offset: true,
            ..PatchOptions::default()
        };
        let (cand, curve) = g16_patch_detail(s, p, c, &zone, 0, lim, &opts)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
        let tol = 1e-6;
        // Joins: value and first two derivatives (third when kept) continuous.
        let (pb, cb) = (
            curve.spline.eval_derivs(curve.s_b),
            curve.cb.eval_derivs(curve.s_b),
        );
        let (pa, ca) = (
            curve.spline.eval_derivs(curve.s_a),
            curve.ca.eval_derivs(curve.s_a),
        );
        let orders = if curve.third { 4 } else { 3 };
        for o in 0..orders {
            assert!(
                (pb[o] - cb[o]).abs() <= tol * (1.0 + cb[o].abs()),
                "{name} b{o}"
            );
            assert!(
                (pa[o] - ca[o]).abs() <= tol * (1.0 + ca[o].abs()),
                "{name} a{o}"
            );
        }
        // Bounds and monotonicity at dense samples.
        let nsamp = 4000;
        for q in 0..=nsamp {
            let t = curve.s_b + (curve.s_a - curve.s_b) * q as f64 / nsamp as f64;
            let d = curve.spline.eval_derivs(t.min(curve.s_a - 1e-9));
            assert!(
                d[1].abs() <= lim.v * (1.0 + tol),
                "{name} v at {t}: {}",
                d[1]
            );
            assert!(
                d[2].abs() <= lim.a * (1.0 + tol),
                "{name} a at {t}: {}",
                d[2]
            );
            assert!(
                d[3].abs() <= lim.j * (1.0 + tol),
                "{name} j at {t}: {}",
                d[3]
            );
            if t >= curve.core_b && t <= curve.core_a {
                assert!(curve.sigma * d[1] >= -tol * lim.v, "{name} monotone at {t}");
            }
        }
        // Projection and deviations.
        let sing = zone.singular;
        let mut new_c = c.clone();
        let mut max_dev: f64 = 0.0;
        for (k, i) in (cand.first..=cand.last).enumerate() {
            let orig = c[i] + if i > sing { cand.c_offset_deg } else { 0.0 };
            assert!((cand.c_deg[k] - curve.spline.eval(s[i])).abs() < 1e-9);
            let dc = (cand.c_deg[k] - orig).to_radians();
            let dev = 2.0
                * (p[i].to_radians().sin().abs() * (0.5 * dc).sin().abs())
                    .asin()
                    .to_degrees();
            max_dev = max_dev.max(dev);
            new_c[i] = cand.c_deg[k];
        }
        for v in &mut new_c[cand.last + 1..] {
            *v += cand.c_offset_deg;
        }
        assert!(
            cand.first > 0 && cand.last < s.len() - 1,
            "{name}: path ends fixed"
        );
        assert!(max_dev.is_finite() && max_dev < 90.0);
        assert!(
            cand.qp.solves >= 1 && cand.qp.status.is_solved(),
            "{:?}",
            cand.qp.status
        );
        let lo = cand.first.saturating_sub(5);
        let hi = (cand.last + 5).min(s.len() - 1);
        let analysis = analysis_ratios(s, &new_c, lo, hi, lim);
        let fig = Figures {
            patch_mm: curve.s_a - curve.s_b,
            modified: cand.last - cand.first + 1,
            max_dev_deg: max_dev,
            analysis,
        };
        eprintln!(
            "{name}: {fig:?} offset {} third {} solves {} iters {} {:.2} ms",
            cand.c_offset_deg,
            curve.third,
            cand.qp.solves,
            cand.qp.iterations,
            cand.qp.solve_time_s * 1e3
        );
        fig
    }

    #[test]
    fn planted_swing_and_flip_on_both_machines() {
        // The HSM600 reaches feed at 1° from the pole: pass at 0.1° for it.
        let machines = [
            ("ucp710", ucp710 as fn(f64) -> CLimits, 1.0),
            ("hsm600", hsm600, 0.1),
        ];
        for (mname, mk, d) in machines {
            for feed in [1000.0, 2000.0] {
                let lim = mk(feed);
                for (ds, n) in [(1.0, 201), (0.5, 401)] {
                    for (flip, phi) in [(false, 0.0), (true, 0.0), (true, 40.0)] {
                        let case = planted_rot(n, ds, d, 15.0, flip, phi);
                        let name = format!("{mname} F{feed} ds{ds} flip={flip} phi={phi}");
                        let fig = check_case(&name, &case, &lim);
                        // The analysis spline through the projected points is what the
                        // caller verifies: it must be close to the patch's limits.
                        for r in fig.analysis {
                            assert!(r < 1.5, "{name}: analysis ratio {r}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn flip_without_offset_has_no_join() {
        let [s, p, c] = planted(201, 1.0, 1.0, 15.0, true);
        let lim = ucp710(1000.0);
        let zone = zone_of(&s, &p, &c, &lim).unwrap();
        let opts = PatchOptions {
            allow_c_offset: false,
            ..PatchOptions::default()
        };
        // The jump is ~180° against the motion on both sides, so without a 360° offset
        // no monotone patch can join.
        let r = g16_patch(&s, &p, &c, &zone, 0, &lim, &opts);
        assert_eq!(r, Err(PatchFailure::NoJoin));
    }

    #[test]
    fn extra_widens_by_that_many_points() {
        // A case solved at the first try (no internal widening), so the only difference
        // is `extra`.
        let case = planted(201, 1.0, 1.0, 15.0, true);
        let lim = ucp710(2000.0);
        let zone = zone_of(&case[0], &case[1], &case[2], &lim).unwrap();
        // The G16 method as the paper has it: C after the split may take a 360° offset
        // (off by default since it moves the rest of the run; see flip_without_offset_has_no_join).
        let opts = PatchOptions {
            allow_c_offset: true,
            ..PatchOptions::default()
        };
        let a = g16_patch(&case[0], &case[1], &case[2], &zone, 0, &lim, &opts).unwrap();
        assert_eq!(a.qp.solves, 1);
        let b = g16_patch(&case[0], &case[1], &case[2], &zone, 3, &lim, &opts).unwrap();
        assert_eq!(b.last - b.first, a.last - a.first + 6);
    }

    #[test]
    fn reachable_matches_the_trapezoid_profile() {
        // From rest to rest: accelerate over v/a, cruise, decelerate: v·L − v²/a.
        let (v, a, len) = (3.0, 0.5, 40.0);
        let want = v * len - v * v / a;
        assert!((reachable(len, 0.0, 0.0, v, a) - want).abs() < 1e-3 * want);
        // Starting against the motion costs reach.
        assert!(reachable(len, -1.0, 0.0, v, a) < want);
    }

    #[test]
    fn three_points_are_too_short() {
        let s = [0.0, 1.0, 2.0];
        let p = [2.0, 0.5, -2.0];
        let c = [10.0, 100.0, 190.0];
        let zone = Zone {
            first: 0,
            last: 2,
            singular: 1,
            kind: ZoneKind::AFlip,
            min_abs_primary_deg: 0.5,
            c_ratio_min: 0.1,
            cut_before: false,
            cut_after: false,
        };
        let lim = ucp710(1000.0);
        for sing in 0..3 {
            let z = Zone {
                singular: sing,
                ..zone.clone()
            };
            let r = g16_patch(&s, &p, &c, &z, 0, &lim, &PatchOptions::default());
            assert_eq!(r, Err(PatchFailure::TooShort));
        }
    }

    #[test]
    fn no_zone_on_a_gentle_path() {
        // Far from the pole the analysis finds no zone, so g16_patch is never called.
        let [s, p, c] = planted(201, 1.0, 20.0, 15.0, false);
        assert!(zone_of(&s, &p, &c, &ucp710(2000.0)).is_none());
    }

    /// C17 `%SING` (N110..N610: X = 0..50, A and C as written), s = X.
    fn c17_sing() -> [Vec<f64>; 3] {
        let text = include_str!("../../../fixtures/c17/SING.I");
        let (mut s, mut p, mut c) = (vec![], vec![], vec![]);
        for line in text.lines() {
            let words: Vec<&str> = line.split_whitespace().collect();
            let Some(nn) = words.first().and_then(|w| w.strip_prefix('N')) else {
                continue;
            };
            let Ok(nn) = nn.parse::<u32>() else { continue };
            if !(110..=610).contains(&nn) {
                continue;
            }
            let get = |k: char| {
                words
                    .iter()
                    .find_map(|w| w.strip_prefix(k).and_then(|v| v.parse::<f64>().ok()))
                    .unwrap()
            };
            s.push(get('X'));
            p.push(get('A'));
            c.push(get('C'));
        }
        assert_eq!(s.len(), 51);
        [s, p, c]
    }

    #[test]
    fn c17_sing_patched_where_the_limits_allow() {
        let case = c17_sing();
        // UCP710 F1000 and HSM600 F2000 have room within X = 0..50.
        for (name, lim) in [
            ("SING ucp710 F1000", ucp710(1000.0)),
            ("SING hsm600 F2000", hsm600(2000.0)),
        ] {
            let fig = check_case(name, &case, &lim);
            assert!(fig.max_dev_deg < 10.0, "{name}: {fig:?}");
        }
    }

    #[test]
    fn c17_sing_ucp710_f2000_cannot_fit_in_50_mm() {
        // C must rise ~85° net from C' ≈ −1.6 °/mm at X = 0 to C' ≈ −1.5 °/mm at X = 50
        // with |C_s| ≤ 3.53 °/mm and |C_ss| ≤ 0.264 °/mm²: the most a 50 mm patch can
        // cover is ~78°, so no patch exists with the path's ends fixed.
        let [s, p, c] = c17_sing();
        let lim = ucp710(2000.0);
        let zone = zone_of(&s, &p, &c, &lim).unwrap();
        let r = g16_patch(&s, &p, &c, &zone, 0, &lim, &PatchOptions::default());
        match r {
            Err(PatchFailure::Solver(st)) => eprintln!("SING ucp710 F2000: {st:?}"),
            other => panic!("expected a solver failure, got {other:?}"),
        }
    }
}
