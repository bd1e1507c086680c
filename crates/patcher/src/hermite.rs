//! The analysis spline in Hermite form: the linear map from CL values to the spline's
//! derivatives that the solvers constrain (the same spline as [`crate::spline`]; the tests
//! check it against `polepatch_bspline::interpolate_not_a_knot`).
//!
//! The analysis spline of C (SPEC §2) is the not-a-knot cubic interpolant of the C values
//! y_k over s. On the span `[s_k, s_{k+1}]`, `h_k = s_{k+1} − s_k`, `τ = s − s_k`, with the
//! knot slopes `m_k` and the secant `σ_k = (y_{k+1} − y_k)/h_k`:
//!
//! ```text
//! q(τ)    = y_k + m_k τ + c2 τ² + c3 τ³
//! c2      = (3σ_k − 2m_k − m_{k+1}) / h_k
//! c3      = (m_k + m_{k+1} − 2σ_k) / h_k²
//! q'(τ)   = m_k + 2c2 τ + 3c3 τ²,   q''(τ) = 2c2 + 6c3 τ,   q''' = 6c3
//! ```
//!
//! Every derivative at a point of span k is a linear form in the four unknowns
//! `y_k, y_{k+1}, m_k, m_{k+1}`. The slopes are tied to the values by C² continuity at each
//! interior knot k (tridiagonal):
//!
//! ```text
//! h_k m_{k−1} + 2(h_{k−1} + h_k) m_k + h_{k−1} m_{k+1} = 3(h_k σ_{k−1} + h_{k−1} σ_k)
//! ```
//!
//! and one condition at each end of the window `lo..=hi` of knots the QP sees:
//! - at an end of the **path**, not-a-knot: `c3` of the end span equals `c3` of its
//!   neighbour (the condition of `polepatch_bspline::interpolate_not_a_knot`); a path of 2
//!   or 3 points is a line or a parabola, `c3 = 0` on every span (and `c2 = 0` for 2);
//! - at a window end **inside** the path, the slope is fixed to the current spline's
//!   (`interpolate_not_a_knot` on the window widened by [`HERMITE_WINDOW_POINTS`] more points).
//!   A change of the values moves that slope by ≈ 0.27^[`HERMITE_WINDOW_POINTS`] of itself
//!   (the not-a-knot system's decay per knot), which the caller's verification on the
//!   whole path covers.
//!
//! [`Hermite`] builds these rows; its test checks them against `interpolate_not_a_knot`.
//!
//! Several axes can share one problem: each [`Hermite`] numbers its variables from an
//! `offset` (its changes first, then its slopes), so a primary-axis and a C-axis Hermite
//! built with offsets `0` and `hp.vars()` live side by side in one QP.

use crate::spline::AnalysisSpline;
use crate::tolerances::{CONSTRAINED_MARGIN_POINTS, HERMITE_WINDOW_POINTS, SIGN_ROW_SCALE_FLOOR};
use crate::{
    candidate::PatchFailure,
    qp::{QpBuilder, Row},
};

/// An affine form `Σ coeff·x[var] + c`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Aff {
    pub(crate) row: Row,
    pub(crate) c: f64,
}

impl Aff {
    pub(crate) fn constant(c: f64) -> Aff {
        Aff { row: Vec::new(), c }
    }
    pub(crate) fn var(k: usize) -> Aff {
        Aff {
            row: vec![(k, 1.0)],
            c: 0.0,
        }
    }
    /// `Σ coef·form`.
    pub(crate) fn sum(parts: &[(f64, &Aff)]) -> Aff {
        let mut out = Aff::default();
        for (a, f) in parts {
            out.row.extend(f.row.iter().map(|&(k, v)| (k, a * v)));
            out.c += a * f.c;
        }
        out
    }
    /// Value at `x`.
    pub(crate) fn at(&self, x: &[f64]) -> f64 {
        self.c + self.row.iter().map(|&(k, v)| v * x[k]).sum::<f64>()
    }
}

/// The analysis spline of C on the window `lo..=hi` of a path in Hermite form, with the
/// values at `first..=last` and the slopes at `lo..=hi` as unknowns (module docs).
///
/// Variables (from `offset`): `δ_i` (the change of the value at point i, degrees or mm)
/// at index `offset + i − first`, then the slope `m_k` (per mm) at index
/// `offset + nd + k − lo`.
pub(crate) struct Hermite<'a> {
    pub(crate) s: &'a [f64],
    c: &'a [f64],
    pub(crate) first: usize,
    pub(crate) last: usize,
    pub(crate) lo: usize,
    pub(crate) hi: usize,
    pub(crate) nd: usize,
    offset: usize,
    /// Current spline's slope at `lo` / `hi` when that end is inside the path.
    fixed: [Option<f64>; 2],
}

impl<'a> Hermite<'a> {
    /// The window of `first..=last` widened by `window` points (clipped to the path), its
    /// variables numbered from 0.
    pub(crate) fn new(
        s: &'a [f64],
        c: &'a [f64],
        first: usize,
        last: usize,
        window: usize,
    ) -> Result<Hermite<'a>, PatchFailure> {
        Hermite::with_offset(s, c, first, last, window, 0)
    }

    /// [`Hermite::new`] with the variables numbered from `offset`.
    pub(crate) fn with_offset(
        s: &'a [f64],
        c: &'a [f64],
        first: usize,
        last: usize,
        window: usize,
        offset: usize,
    ) -> Result<Hermite<'a>, PatchFailure> {
        let n = s.len();
        if n < 2 || first > last || last >= n || c.len() != n {
            return Err(PatchFailure::TooShort);
        }
        let lo = first.saturating_sub(window);
        let hi = (last + window).min(n - 1);
        let mut fixed = [None, None];
        if lo > 0 || hi < n - 1 {
            let lo2 = lo.saturating_sub(window.max(HERMITE_WINDOW_POINTS));
            let hi2 = (hi + window.max(HERMITE_WINDOW_POINTS)).min(n - 1);
            let sp = AnalysisSpline::new(&s[lo2..=hi2], &c[lo2..=hi2])
                .map_err(|_| PatchFailure::TooShort)?;
            if lo > 0 {
                fixed[0] = Some(sp.eval_derivs(s[lo])[1]);
            }
            if hi < n - 1 {
                fixed[1] = Some(sp.eval_derivs(s[hi])[1]);
            }
        }
        Ok(Hermite {
            s,
            c,
            first,
            last,
            lo,
            hi,
            nd: last - first + 1,
            offset,
            fixed,
        })
    }

    /// Index of the variable `δ_i` (point `i` in `first..=last`).
    pub(crate) fn delta_var(&self, i: usize) -> usize {
        self.offset + i - self.first
    }

    /// Number of variables (changes, then slopes).
    pub(crate) fn vars(&self) -> usize {
        self.nd + self.hi - self.lo + 1
    }

    pub(crate) fn h(&self, k: usize) -> f64 {
        self.s[k + 1] - self.s[k]
    }

    /// Value at path point k.
    fn y(&self, k: usize) -> Aff {
        let mut a = Aff::constant(self.c[k]);
        if (self.first..=self.last).contains(&k) {
            a.row.push((self.delta_var(k), 1.0));
        }
        a
    }

    /// Slope at path knot k (lo ≤ k ≤ hi).
    pub(crate) fn m(&self, k: usize) -> Aff {
        Aff::var(self.offset + self.nd + k - self.lo)
    }

    fn secant(&self, k: usize) -> Aff {
        let h = self.h(k);
        Aff::sum(&[(1.0 / h, &self.y(k + 1)), (-1.0 / h, &self.y(k))])
    }

    fn c2(&self, k: usize) -> Aff {
        let h = self.h(k);
        Aff::sum(&[
            (3.0 / h, &self.secant(k)),
            (-2.0 / h, &self.m(k)),
            (-1.0 / h, &self.m(k + 1)),
        ])
    }

    fn c3(&self, k: usize) -> Aff {
        let h2 = self.h(k) * self.h(k);
        Aff::sum(&[
            (1.0 / h2, &self.m(k)),
            (1.0 / h2, &self.m(k + 1)),
            (-2.0 / h2, &self.secant(k)),
        ])
    }

    /// `q'(s_k + τ)` on span k.
    pub(crate) fn d1(&self, k: usize, tau: f64) -> Aff {
        Aff::sum(&[
            (1.0, &self.m(k)),
            (2.0 * tau, &self.c2(k)),
            (3.0 * tau * tau, &self.c3(k)),
        ])
    }

    /// `q''(s_k + τ)` on span k.
    pub(crate) fn d2(&self, k: usize, tau: f64) -> Aff {
        Aff::sum(&[(2.0, &self.c2(k)), (6.0 * tau, &self.c3(k))])
    }

    /// `q'''` on span k.
    pub(crate) fn d3(&self, k: usize) -> Aff {
        Aff::sum(&[(6.0, &self.c3(k))])
    }

    /// Middle Bernstein coefficient of `q'` on span k: `3σ_k − m_k − m_{k+1}`.
    pub(crate) fn b1(&self, k: usize) -> Aff {
        Aff::sum(&[
            (3.0, &self.secant(k)),
            (-1.0, &self.m(k)),
            (-1.0, &self.m(k + 1)),
        ])
    }

    /// The rows tying the slopes to the values (each `form = 0`): C² continuity at every
    /// interior knot, then the two end conditions (module docs).
    pub(crate) fn equalities(&self) -> Vec<Aff> {
        let (lo, hi) = (self.lo, self.hi);
        let mut eqs = Vec::with_capacity(hi - lo + 1);
        for k in lo + 1..hi {
            let (ha, hb) = (self.h(k - 1), self.h(k));
            let w = 1.0 / (ha + hb);
            eqs.push(Aff::sum(&[
                (hb * w, &self.m(k - 1)),
                (2.0, &self.m(k)),
                (ha * w, &self.m(k + 1)),
                (-3.0 * hb * w, &self.secant(k - 1)),
                (-3.0 * ha * w, &self.secant(k)),
            ]));
        }
        let nw = hi - lo + 1;
        let both_path_ends = self.fixed == [None, None];
        if both_path_ends && nw <= 3 {
            // A line (2 points) or a parabola (3 points).
            for k in lo..hi {
                eqs.push(Aff::sum(&[(self.h(k) * self.h(k), &self.c3(k))]));
            }
            if nw == 2 {
                eqs.push(Aff::sum(&[(self.h(lo), &self.c2(lo))]));
            }
            return eqs;
        }
        let not_a_knot = |a: usize| {
            let (ha, hb) = (self.h(a), self.h(a + 1));
            Aff::sum(&[(ha * hb, &self.c3(a)), (-ha * hb, &self.c3(a + 1))])
        };
        eqs.push(match self.fixed[0] {
            Some(m) => Aff::sum(&[(1.0, &self.m(lo)), (-m, &Aff::constant(1.0))]),
            None => not_a_knot(lo),
        });
        eqs.push(match self.fixed[1] {
            Some(m) => Aff::sum(&[(1.0, &self.m(hi)), (-m, &Aff::constant(1.0))]),
            None => not_a_knot(hi - 2),
        });
        eqs
    }

    /// Path spans constrained for the modified range: those within
    /// [`CONSTRAINED_MARGIN_POINTS`] of it, in the window.
    pub(crate) fn constrained_spans(&self) -> std::ops::Range<usize> {
        let a = self
            .first
            .saturating_sub(CONSTRAINED_MARGIN_POINTS)
            .max(self.lo);
        let b = (self.last + CONSTRAINED_MARGIN_POINTS).min(self.hi);
        a..b.max(a + 1).min(self.hi)
    }

    /// Add this Hermite's equalities to `qp`.
    pub(crate) fn add_equalities(&self, qp: &mut QpBuilder) {
        for e in self.equalities() {
            qp.add_eq(&e.row, -e.c);
        }
    }

    /// A builder over the variables plus `extra` more, with the equalities.
    pub(crate) fn builder(&self, extra: usize) -> QpBuilder {
        let mut qp = QpBuilder::new(self.vars() + extra);
        for e in self.equalities() {
            qp.add_eq(&e.row, -e.c);
        }
        qp
    }
}

/// Push `|f| ≤ bound` (two rows, scaled by 1/bound).
pub(crate) fn push_abs(qp: &mut QpBuilder, f: &Aff, bound: f64) {
    for sgn in [1.0, -1.0] {
        let row: Row = f.row.iter().map(|&(k, v)| (k, sgn * v / bound)).collect();
        qp.add_le(&row, (bound - sgn * f.c) / bound);
    }
}

/// Push `σ·f ≥ 0`, scaled by the form's largest coefficient.
pub(crate) fn push_sign(qp: &mut QpBuilder, f: &Aff, sigma: f64) {
    let scale = f
        .row
        .iter()
        .fold(f.c.abs(), |m, e| m.max(e.1.abs()))
        .max(SIGN_ROW_SCALE_FLOOR);
    let row: Row = f
        .row
        .iter()
        .map(|&(k, v)| (k, -sigma * v / scale))
        .collect();
    qp.add_le(&row, sigma * f.c / scale);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::QpStats;
    use polepatch_bspline::interpolate_not_a_knot;

    /// Uneven knots and non-polynomial data.
    fn data(n: usize) -> (Vec<f64>, Vec<f64>) {
        let s: Vec<f64> = (0..n)
            .map(|i| i as f64 * 0.8 + (i as f64 * 1.3).sin() * 0.2)
            .collect();
        let y = s.iter().map(|t| (t * 1.7).cos() * 10.0 + 3.0 * t).collect();
        (s, y)
    }

    /// The Hermite rows describe `interpolate_not_a_knot`'s curve: its knot slopes satisfy
    /// every equality, there is one equality per slope, and the derivative forms evaluate
    /// to its derivatives, on whole paths (not-a-knot ends, 2..5 and 40 points) and on a
    /// cut window (fixed end slopes).
    #[test]
    fn hermite_rows_match_interpolate_not_a_knot() {
        for n in [2usize, 3, 4, 5, 40] {
            let (s, y) = data(n);
            let sp = interpolate_not_a_knot(&s, &y).unwrap();
            for (first, last, window) in [(0, n - 1, HERMITE_WINDOW_POINTS), (n / 2, n / 2, 3)] {
                let hm = Hermite::new(&s, &y, first, last, window).unwrap();
                let mut x = vec![0.0; hm.vars()];
                for k in hm.lo..=hm.hi {
                    x[hm.nd + k - hm.lo] = sp.eval_derivs(s[k])[1];
                }
                let eqs = hm.equalities();
                assert_eq!(eqs.len(), hm.hi - hm.lo + 1, "n {n}");
                for e in &eqs {
                    assert!(e.at(&x).abs() < 1e-8, "n {n}: residual {}", e.at(&x));
                }
                for k in hm.lo..hm.hi {
                    let h = hm.h(k);
                    for tau in [0.0, h / 3.0, 0.99 * h] {
                        let d = sp.eval_derivs(hm.s[k] + tau);
                        assert!((hm.d1(k, tau).at(&x) - d[1]).abs() < 1e-8);
                        assert!((hm.d2(k, tau).at(&x) - d[2]).abs() < 1e-7);
                    }
                    let d3 = sp.eval_derivs(hm.s[k] + h / 2.0)[3];
                    assert!((hm.d3(k).at(&x) - d3).abs() < 1e-6);
                }
            }
        }
    }

    /// Planted response: fixing δ at one point, the slopes the QP's equalities determine
    /// are those of the interpolant of the changed data (the equalities have a unique
    /// solution and it is the right one).
    #[test]
    fn hermite_response_is_the_spline_of_the_changed_data() {
        let (s, y) = data(60);
        let (first, last) = (28, 32);
        let hm = Hermite::new(&s, &y, first, last, HERMITE_WINDOW_POINTS).unwrap();
        let mut qp = hm.builder(0);
        let delta = [0.0, 3.0, -7.0, 1.0, 0.0];
        for (i, d) in delta.iter().enumerate() {
            qp.add_eq(&[(i, 1.0)], *d);
        }
        let x = qp.solve(&mut QpStats::default()).unwrap();
        let mut y2 = y.clone();
        for (i, d) in delta.iter().enumerate() {
            y2[first + i] += d;
        }
        let sp = interpolate_not_a_knot(&s, &y2).unwrap();
        for k in hm.lo..=hm.hi {
            let m = sp.eval_derivs(s[k])[1];
            assert!((x[hm.nd + k - hm.lo] - m).abs() < 1e-5, "knot {k}");
        }
    }

    /// With an offset, the same rows move to the offset's variables.
    #[test]
    fn offset_shifts_every_variable() {
        let (s, y) = data(12);
        let a = Hermite::new(&s, &y, 4, 7, 3).unwrap();
        let b = Hermite::with_offset(&s, &y, 4, 7, 3, 100).unwrap();
        assert_eq!(a.vars(), b.vars());
        for (ea, eb) in a.equalities().iter().zip(&b.equalities()) {
            let shifted: Row = ea.row.iter().map(|&(k, v)| (k + 100, v)).collect();
            assert_eq!(shifted, eb.row);
            assert_eq!(ea.c, eb.c);
        }
        assert_eq!(b.delta_var(5), 101);
    }
}
