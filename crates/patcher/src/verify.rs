//! Verification of a C change against Equation 6 (SPEC §2), on the C axis alone.
//!
//! The analysis spline of C is the not-a-knot interpolating cubic of the C values over s,
//! built with `polepatch_bspline` ([`NotAKnotSystem`], factored once per window and solved
//! for the values before and after) and evaluated in piecewise-polynomial form
//! ([`polepatch_bspline::PpCubic::eval_derivs_sorted`]) on every span's samples.
//!
//! The C-limited ratio at a sample is `min(1, v/|q'|, sqrt(a/|q''|), cbrt(j/|q'''|))`
//! with `(v, a, j)` the C limits at the programmed feed without margin
//! ([`CLimits::new`] with margin 0): Equation 6 for C divided by F.
//!
//! A window of the path is enough: the influence of a changed value on the spline decays
//! by a factor ≈ 2 − √3 ≈ 0.27 per knot, so [`VERIFY_MARGIN_POINTS`] points either side of
//! the change make the window spline equal to the whole-path spline to round-off where
//! the checks are made.

use crate::{analysis::RATIO_TOL, limits::CLimits};
use polepatch_bspline::NotAKnotSystem;

/// Points of unchanged path kept either side of a change when verifying it.
pub const VERIFY_MARGIN_POINTS: usize = 30;

/// Points either side of the modified range where the C ratio must reach 1.
pub const CORE_MARGIN_POINTS: usize = 3;

/// Spans next to a window end that was cut (not a path end) left out of the "never worse"
/// comparison: there the window spline differs from the whole-path spline.
const WINDOW_GUARD_SPANS: usize = 10;

/// Slack of the "not lower than before" comparison (absorbs round-off).
const NOT_WORSE_TOL: f64 = 1e-12;

/// Local sample offsets on a span of length `h` at `step`: `0, step, 2·step, … < h`, and
/// `h` itself when `with_end` (the analysis sampling rule: every step and every knot).
pub(crate) fn span_offsets(h: f64, step: f64, with_end: bool, out: &mut Vec<f64>) {
    out.clear();
    let count = (h / step).ceil().max(1.0) as usize;
    for i in 0..count {
        let t = i as f64 * step;
        if t < h {
            out.push(t);
        }
    }
    if with_end {
        out.push(h);
    }
}

/// C-limited Equation-6 ratio from `[q', q'', q''']` and the limits without margin.
pub fn c_ratio(lim: &CLimits, d: [f64; 3]) -> f64 {
    let rv = lim.v / d[0].abs();
    let ra = (lim.a / d[1].abs()).sqrt();
    let rj = (lim.j / d[2].abs()).cbrt();
    rv.min(ra).min(rj).min(1.0)
}

/// Per-span minimum C ratio over the samples of every span of the spline of `y` on the
/// knots of `sys` (`s`); `None` when the spline cannot be built (non-finite values).
fn span_min_ratios(
    sys: &NotAKnotSystem,
    s: &[f64],
    y: &[f64],
    lim: &CLimits,
    step_mm: f64,
) -> Option<Vec<f64>> {
    let pp = sys.solve(y).ok()?.to_pp();
    let n = s.len();
    let mut ts = Vec::new();
    let mut at = Vec::new();
    let mut span_of = Vec::new();
    for k in 0..n - 1 {
        span_offsets(s[k + 1] - s[k], step_mm, k + 2 == n, &mut ts);
        at.extend(ts.iter().map(|t| s[k] + t));
        span_of.extend(std::iter::repeat_n(k, ts.len()));
    }
    let mut d = vec![[0.0; 4]; at.len()];
    pp.eval_derivs_sorted(&at, &mut d);
    // The ratio is decreasing in each |derivative|, so the span's least ratio is the ratio
    // of its largest |q'|, |q''|, |q'''|: one sqrt and one cbrt per span, not per sample.
    let mut peak = vec![[0.0f64; 3]; n - 1];
    for (k, e) in span_of.iter().zip(&d) {
        let pk = &mut peak[*k];
        for (m, v) in pk.iter_mut().zip(&e[1..]) {
            *m = m.max(v.abs());
        }
    }
    Some(peak.into_iter().map(|pk| c_ratio(lim, pk)).collect())
}

/// Verdict of [`verify_c_change`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// Lowest C ratio after the change over the core (modified points ±
    /// [`CORE_MARGIN_POINTS`]).
    pub core_min_after: f64,
    /// Lowest C ratio before the change over the same core.
    pub core_min_before: f64,
    /// Whether some sample of the checked window got a C ratio below
    /// `min(before, 1 − RATIO_TOL)`.
    pub worse_somewhere: bool,
}

impl Verdict {
    /// C reaches feed over the core and nothing got worse.
    pub fn passes(&self) -> bool {
        self.core_min_after >= 1.0 - RATIO_TOL && !self.worse_somewhere
    }
    /// Better than before over the core and nothing got worse elsewhere (a kept "best
    /// improvement").
    pub fn improves(&self) -> bool {
        !self.worse_somewhere && self.core_min_after > self.core_min_before
    }
}

/// Check a C change: `c_before` and `c_after` (whole path, degrees, as written) differ at
/// most in `first..` (points `first..=last` modified, points after `last` possibly shifted
/// by a 360° multiple). `lim` are the C limits at the programmed feed without margin,
/// `step_mm` the sampling step F·Tcy.
///
/// C must reach feed (ratio ≥ 1 − [`RATIO_TOL`]) on every sample of the spans within
/// [`CORE_MARGIN_POINTS`] points of the modified range, and no sample of the window may get
/// a ratio below `min(before, 1 − RATIO_TOL)`.
pub fn verify_c_change(
    s_mm: &[f64],
    c_before: &[f64],
    c_after: &[f64],
    first: usize,
    last: usize,
    lim: &CLimits,
    step_mm: f64,
) -> Verdict {
    let n = s_mm.len();
    let lo = first.saturating_sub(VERIFY_MARGIN_POINTS);
    let hi = (last + 1 + VERIFY_MARGIN_POINTS).min(n - 1);
    let nw = hi - lo + 1;
    let s = &s_mm[lo..=hi];
    let ratios = NotAKnotSystem::new(s).ok().and_then(|sys| {
        Some((
            span_min_ratios(&sys, s, &c_before[lo..=hi], lim, step_mm)?,
            span_min_ratios(&sys, s, &c_after[lo..=hi], lim, step_mm)?,
        ))
    });
    let Some((before, after)) = ratios else {
        // No spline (non-finite values): fails.
        return Verdict {
            core_min_after: 0.0,
            core_min_before: 0.0,
            worse_somewhere: true,
        };
    };
    let core_lo = first.saturating_sub(CORE_MARGIN_POINTS).max(lo) - lo;
    let core_hi = (last + CORE_MARGIN_POINTS).min(hi) - lo; // knot index, exclusive span end
    let guard_lo = if lo > 0 { WINDOW_GUARD_SPANS } else { 0 };
    let guard_hi = if hi < n - 1 {
        (nw - 1).saturating_sub(WINDOW_GUARD_SPANS)
    } else {
        nw - 1
    };
    let mut core_min_after = f64::INFINITY;
    let mut core_min_before = f64::INFINITY;
    let mut worse = false;
    for k in 0..nw - 1 {
        let in_core = k >= core_lo && k < core_hi.max(core_lo + 1);
        if in_core {
            core_min_after = core_min_after.min(after[k]);
            core_min_before = core_min_before.min(before[k]);
        }
        if (in_core || (k >= guard_lo && k < guard_hi))
            && after[k] < before[k].min(1.0 - RATIO_TOL) - NOT_WORSE_TOL
        {
            worse = true;
        }
    }
    Verdict {
        core_min_after,
        core_min_before,
        worse_somewhere: worse,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Planted: a line at slope v/2 reaches feed; raising one value so the spline's slope
    /// exceeds v is found below feed in the core and worse than before.
    #[test]
    fn planted_bump_fails_and_line_passes() {
        let s: Vec<f64> = (0..41).map(|i| i as f64 * 0.5).collect();
        let lim = CLimits {
            v: 2.0,
            a: 50.0,
            j: 1000.0,
        };
        let y: Vec<f64> = s.to_vec();
        let same = verify_c_change(&s, &y, &y, 20, 20, &lim, 0.05);
        assert!(same.passes(), "{same:?}");
        let mut bumped = y.clone();
        bumped[20] += 2.0;
        let v = verify_c_change(&s, &y, &bumped, 20, 20, &lim, 0.05);
        assert!(v.core_min_after < 1.0 && v.worse_somewhere, "{v:?}");
        assert!(!v.passes());
    }

    /// The sample offsets: every step from 0, below h, and h itself on request.
    #[test]
    fn offsets_follow_the_sampling_rule() {
        let mut o = Vec::new();
        span_offsets(1.0, 0.3, false, &mut o);
        assert_eq!(o.len(), 4);
        span_offsets(1.0, 0.3, true, &mut o);
        assert_eq!(*o.last().unwrap(), 1.0);
        span_offsets(0.1, 0.3, false, &mut o);
        assert_eq!(o, vec![0.0]);
    }
}
