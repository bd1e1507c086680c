//! Verification of a C change against Equation 6 (SPEC §2), on the C axis alone, and the
//! not-a-knot cubic of C over s written in Hermite form (slopes at the knots).
//!
//! The analysis spline of C is the not-a-knot interpolating cubic of the C values over s
//! (the same curve as `interpolate_not_a_knot`, built here directly in Hermite form so the
//! check is cheap and local). On the span `[s_k, s_{k+1}]`, with `h = s_{k+1} − s_k`, local
//! parameter `τ = s − s_k`, slopes `m_k`, and secant `σ_k = (y_{k+1} − y_k)/h`:
//!
//! ```text
//! q(τ)    = y_k + m_k τ + c2 τ² + c3 τ³
//! c2      = (3σ_k − 2m_k − m_{k+1}) / h
//! c3      = (m_k + m_{k+1} − 2σ_k) / h²
//! ```
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

/// Points of unchanged path kept either side of a change when verifying it.
pub const VERIFY_MARGIN_POINTS: usize = 30;

/// Points either side of the modified range where the C ratio must reach 1.
pub const CORE_MARGIN_POINTS: usize = 3;

/// Spans next to a window end that was cut (not a path end) left out of the "never worse"
/// comparison: there the window spline differs from the whole-path spline.
const WINDOW_GUARD_SPANS: usize = 10;

/// Slack of the "not lower than before" comparison (absorbs round-off).
const NOT_WORSE_TOL: f64 = 1e-12;

/// The not-a-knot slope system of a set of knots, factored once (tridiagonal after
/// eliminating the first and last unknown), solved for any values.
#[derive(Debug, Clone)]
pub(crate) struct NakSystem {
    s: Vec<f64>,
    dx: Vec<f64>,
    /// Thomas factors of the reduced system in m_1..m_{n-2}: modified super-diagonal and
    /// pivots.
    cp: Vec<f64>,
    piv: Vec<f64>,
    sub: Vec<f64>,
}

impl NakSystem {
    /// Factor the system for knots `s` (strictly increasing, n ≥ 2).
    pub(crate) fn new(s: &[f64]) -> NakSystem {
        let n = s.len();
        let dx: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
        let (mut cp, mut piv, mut sub) = (Vec::new(), Vec::new(), Vec::new());
        if n >= 4 {
            let r = n - 2; // unknowns m_1..m_{n-2}
            for row in 0..r {
                let k = row + 1;
                let (a, d, c) = if k == 1 {
                    (0.0, dx[0] + dx[1], dx[0])
                } else if k == n - 2 {
                    (dx[n - 2], dx[n - 3] + dx[n - 2], 0.0)
                } else {
                    (dx[k], 2.0 * (dx[k - 1] + dx[k]), dx[k - 1])
                };
                let p = if row == 0 { d } else { d - a * cp[row - 1] };
                piv.push(p);
                cp.push(c / p);
                sub.push(a);
            }
        }
        NakSystem {
            s: s.to_vec(),
            dx,
            cp,
            piv,
            sub,
        }
    }

    /// Number of knots.
    pub(crate) fn len(&self) -> usize {
        self.s.len()
    }

    /// Knots.
    pub(crate) fn knots(&self) -> &[f64] {
        &self.s
    }

    /// Slopes at the knots of the not-a-knot interpolant of `y`.
    pub(crate) fn slopes(&self, y: &[f64]) -> Vec<f64> {
        let n = self.s.len();
        let dx = &self.dx;
        let sl: Vec<f64> = (0..n - 1).map(|k| (y[k + 1] - y[k]) / dx[k]).collect();
        match n {
            2 => vec![sl[0]; 2],
            3 => {
                let d = dx[0] + dx[1];
                let a = (sl[1] - sl[0]) / d;
                vec![
                    sl[0] - a * dx[0],
                    (sl[0] * dx[1] + sl[1] * dx[0]) / d,
                    sl[1] + a * dx[1],
                ]
            }
            _ => {
                let d0 = dx[0] + dx[1];
                let r0 = ((dx[0] + 2.0 * d0) * dx[1] * sl[0] + dx[0] * dx[0] * sl[1]) / d0;
                let dn = dx[n - 3] + dx[n - 2];
                let rn = (dx[n - 2] * dx[n - 2] * sl[n - 3]
                    + (2.0 * dn + dx[n - 2]) * dx[n - 3] * sl[n - 2])
                    / dn;
                let interior = |k: usize| 3.0 * (dx[k] * sl[k - 1] + dx[k - 1] * sl[k]);
                let r = n - 2;
                let mut z = vec![0.0; r];
                for row in 0..r {
                    let k = row + 1;
                    let mut rhs = interior(k);
                    if k == 1 {
                        rhs -= r0;
                    }
                    if k == n - 2 {
                        rhs -= rn;
                    }
                    z[row] = if row == 0 {
                        rhs / self.piv[0]
                    } else {
                        (rhs - self.sub[row] * z[row - 1]) / self.piv[row]
                    };
                }
                for row in (0..r.saturating_sub(1)).rev() {
                    z[row] -= self.cp[row] * z[row + 1];
                }
                let mut m = Vec::with_capacity(n);
                m.push((r0 - d0 * z[0]) / dx[1]);
                m.extend_from_slice(&z);
                m.push((rn - dn * z[r - 1]) / dx[n - 3]);
                m
            }
        }
    }
}

/// Cubic coefficients of span `k` from values `y` and slopes `m`: `(m_k, c2, c3, h)`.
pub(crate) fn span_coeffs(s: &[f64], y: &[f64], m: &[f64], k: usize) -> (f64, f64, f64, f64) {
    let h = s[k + 1] - s[k];
    let sl = (y[k + 1] - y[k]) / h;
    let c2 = (3.0 * sl - 2.0 * m[k] - m[k + 1]) / h;
    let c3 = (m[k] + m[k + 1] - 2.0 * sl) / (h * h);
    (m[k], c2, c3, h)
}

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

/// Per-span minimum C ratio over the samples of spans `spans` of the spline of `y` on
/// knots `sys`.
fn span_min_ratios(
    sys: &NakSystem,
    y: &[f64],
    lim: &CLimits,
    step_mm: f64,
    spans: std::ops::Range<usize>,
) -> Vec<f64> {
    let s = sys.knots();
    let m = sys.slopes(y);
    let mut ts = Vec::new();
    let n = s.len();
    spans
        .map(|k| {
            let (m0, c2, c3, h) = span_coeffs(s, y, &m, k);
            span_offsets(h, step_mm, k + 2 == n, &mut ts);
            ts.iter()
                .map(|&t| {
                    let d = [
                        m0 + t * (2.0 * c2 + 3.0 * c3 * t),
                        2.0 * c2 + 6.0 * c3 * t,
                        6.0 * c3,
                    ];
                    c_ratio(lim, d)
                })
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
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
    let sys = NakSystem::new(&s_mm[lo..=hi]);
    let nw = hi - lo + 1;
    let before = span_min_ratios(&sys, &c_before[lo..=hi], lim, step_mm, 0..nw - 1);
    let after = span_min_ratios(&sys, &c_after[lo..=hi], lim, step_mm, 0..nw - 1);
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

    fn cubic(t: f64) -> f64 {
        0.3 * t * t * t - 1.2 * t * t + 0.7 * t + 2.0
    }

    /// The not-a-knot interpolant reproduces any cubic (uneven knots).
    #[test]
    fn reproduces_cubics() {
        let s = [0.0, 0.7, 1.5, 1.9, 3.0, 3.4, 5.0];
        let y: Vec<f64> = s.iter().map(|&t| cubic(t)).collect();
        let sys = NakSystem::new(&s);
        let m = sys.slopes(&y);
        for (k, &t) in s.iter().enumerate() {
            let exact = 0.9 * t * t - 2.4 * t + 0.7;
            assert!(
                (m[k] - exact).abs() < 1e-10,
                "knot {k}: {} vs {exact}",
                m[k]
            );
        }
        let (_, _, c3, _) = span_coeffs(&s, &y, &m, 2);
        assert!((6.0 * c3 - 1.8).abs() < 1e-9);
    }

    /// n = 4 (both reduced rows modified) and n = 3 (parabola) and n = 2 (line).
    #[test]
    fn short_knot_vectors() {
        for s in [
            vec![0.0, 1.0, 3.0, 3.5],
            vec![0.0, 1.0, 2.5],
            vec![1.0, 2.0],
        ] {
            let f = |t: f64| if s.len() == 2 { 2.0 * t } else { t * t - t };
            let df = |t: f64| if s.len() == 2 { 2.0 } else { 2.0 * t - 1.0 };
            let y: Vec<f64> = s.iter().map(|&t| f(t)).collect();
            let m = NakSystem::new(&s).slopes(&y);
            for (k, &t) in s.iter().enumerate() {
                assert!((m[k] - df(t)).abs() < 1e-12);
            }
        }
    }

    /// Not-a-knot: the third derivative is continuous at the second and the last-but-one
    /// knots (checked on non-polynomial data).
    #[test]
    fn not_a_knot_condition() {
        let s: Vec<f64> = (0..9)
            .map(|i| i as f64 * 0.8 + (i as f64 * 1.3).sin() * 0.2)
            .collect();
        let y: Vec<f64> = s.iter().map(|t| (t * 1.7).cos() * 10.0).collect();
        let m = NakSystem::new(&s).slopes(&y);
        let d3 = |k| 6.0 * span_coeffs(&s, &y, &m, k).2;
        assert!((d3(0) - d3(1)).abs() < 1e-9);
        assert!((d3(6) - d3(7)).abs() < 1e-9);
        // C2 continuity at an interior knot.
        let (_, c2a, c3a, ha) = span_coeffs(&s, &y, &m, 3);
        let (_, c2b, _, _) = span_coeffs(&s, &y, &m, 4);
        assert!((2.0 * c2a + 6.0 * c3a * ha - 2.0 * c2b).abs() < 1e-9);
    }
}
