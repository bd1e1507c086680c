//! The B-spline type and its evaluation.

use crate::cox_de_boor::{ders_basis, find_span};
use crate::error::SplineError;

/// A scalar B-spline of degree `degree` (≤ 3 in practice) with a clamped or general knot
/// vector `knots` (length `coeffs.len() + degree + 1`) and control points `coeffs`.
/// Its domain is `[knots[degree], knots[len - degree - 1]]`; evaluation outside extends the
/// end polynomial pieces.
#[derive(Debug, Clone, PartialEq)]
pub struct BSpline {
    degree: usize,
    knots: Vec<f64>,
    coeffs: Vec<f64>,
}

impl BSpline {
    /// A spline from its parts; checks lengths, non-decreasing finite knots.
    ///
    /// Also checked, each a [`SplineError`]: `degree ≤ 3` (the crate's evaluation and
    /// [`crate::BasisRow`] are written for cubics and below), at least `degree + 1`
    /// control points, all finite; no knot repeated more than `degree + 1` times; a
    /// non-empty domain (`knots[degree] < knots[len − degree − 1]`).
    pub fn new(degree: usize, knots: Vec<f64>, coeffs: Vec<f64>) -> Result<BSpline, SplineError> {
        if degree > 3 {
            return Err(SplineError::InvalidKnots {
                what: format!("degree {degree} is not supported (0..=3)"),
            });
        }
        if coeffs.len() < degree + 1 {
            return Err(SplineError::TooFewPoints {
                needed: degree + 1,
                got: coeffs.len(),
            });
        }
        if knots.len() != coeffs.len() + degree + 1 {
            return Err(SplineError::LengthMismatch {
                what: format!(
                    "{} knots for {} control points of degree {degree} (need {})",
                    knots.len(),
                    coeffs.len(),
                    coeffs.len() + degree + 1
                ),
            });
        }
        check_knots(&knots, degree)?;
        if let Some(i) = coeffs.iter().position(|c| !c.is_finite()) {
            return Err(SplineError::NotFinite {
                what: "coeffs",
                index: i,
                value: coeffs[i],
            });
        }
        Ok(BSpline {
            degree,
            knots,
            coeffs,
        })
    }

    /// A spline from parts already known to be valid (built by this crate).
    pub(crate) fn from_parts_unchecked(
        degree: usize,
        knots: Vec<f64>,
        coeffs: Vec<f64>,
    ) -> BSpline {
        debug_assert_eq!(knots.len(), coeffs.len() + degree + 1);
        BSpline {
            degree,
            knots,
            coeffs,
        }
    }

    /// Degree.
    pub fn degree(&self) -> usize {
        self.degree
    }
    /// Knot vector.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }
    /// Control points.
    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }
    /// Domain `(start, end)`.
    pub fn domain(&self) -> (f64, f64) {
        (
            self.knots[self.degree],
            self.knots[self.knots.len() - self.degree - 1],
        )
    }
    /// Value at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        self.eval_derivs(t)[0]
    }
    /// Value and first three derivatives at `t`: `[y, y', y'', y''']` (zero above degree).
    ///
    /// A binary search for the span, then (cubics) the span's Taylor form and Horner's
    /// rule, or (lower degrees) the Cox–de Boor recurrence. For many sorted parameters use
    /// [`BSpline::eval_derivs_sorted`] or [`crate::PpCubic`].
    pub fn eval_derivs(&self, t: f64) -> [f64; 4] {
        let span = find_span(&self.knots, self.degree, self.coeffs.len(), t);
        if self.degree == 3 {
            horner(&self.taylor_on_span(span), t - self.knots[span])
        } else {
            self.eval_derivs_on_span(span, t)
        }
    }

    /// `eval_derivs` at `t` using the polynomial piece of knot span `span`.
    pub(crate) fn eval_derivs_on_span(&self, span: usize, t: f64) -> [f64; 4] {
        let p = self.degree;
        let ders = ders_basis(&self.knots, p, span, t);
        let c = &self.coeffs[span - p..=span];
        let mut out = [0.0; 4];
        for (o, row) in out.iter_mut().zip(ders.iter()) {
            *o = row.iter().zip(c).map(|(w, c)| w * c).sum();
        }
        out
    }

    /// Taylor coefficients `[a0, a1, a2, a3]` of the polynomial piece of span `span` about
    /// its left knot: `f(t) = Σ a_k (t − knots[span])^k`.
    ///
    /// For cubics a closed form (about 10 divisions, no recurrence): with `u` the knots,
    /// `P` the control points of the span, the derivative control points
    /// `P⁽ᵏ⁾_j = (p−k+1)/(u_{j+p+1} − u_{j+k})·(P⁽ᵏ⁻¹⁾_{j+1} − P⁽ᵏ⁻¹⁾_j)` (Piegl & Tiller
    /// eq. 3.8) and the values at `u_i` of the quadratic and cubic B-splines that do not
    /// vanish there. Every denominator spans the non-empty interval `[u_i, u_{i+1}]`.
    pub(crate) fn taylor_on_span(&self, span: usize) -> [f64; 4] {
        if self.degree != 3 {
            let d = self.eval_derivs_on_span(span, self.knots[span]);
            return [d[0], d[1], 0.5 * d[2], d[3] / 6.0];
        }
        let i = span;
        let u = &self.knots[i - 2..i + 4]; // u[k] = knots[i − 2 + k]
        let (um2, um1, u0, u1, u2, u3) = (u[0], u[1], u[2], u[3], u[4], u[5]);
        let p = &self.coeffs[i - 3..=i];
        let h = u1 - u0;
        // First-derivative control points P1_{i−3}, P1_{i−2}, P1_{i−1}.
        let q0 = 3.0 * (p[1] - p[0]) / (u1 - um2);
        let q1 = 3.0 * (p[2] - p[1]) / (u2 - um1);
        let q2 = 3.0 * (p[3] - p[2]) / (u3 - u0);
        // Second: P2_{i−3}, P2_{i−2}; third: constant.
        let r0 = 2.0 * (q1 - q0) / (u1 - um1);
        let r1 = 2.0 * (q2 - q1) / (u2 - u0);
        let d3 = (r1 - r0) / h;
        // Values at u_i: f'' = P2_{i−3}; f' from the two quadratics alive at u_i; f from the
        // three cubics alive at u_i.
        let w = u1 - um1;
        let (a, b) = (h / w, (u0 - um1) / w);
        let d1 = a * q0 + b * q1;
        let n0 = h * h / ((u1 - um2) * w);
        let n2 = (u0 - um1) * (u0 - um1) / ((u2 - um1) * w);
        let d0 = n0 * p[0] + (1.0 - n0 - n2) * p[1] + n2 * p[2];
        [d0, d1, 0.5 * r0, d3 / 6.0]
    }

    /// `eval_derivs` at many sorted (non-decreasing) parameters, written into `out`
    /// (same length as `ts`). Amortises the span search; the fast path.
    ///
    /// Walks the spans forward with the parameters and converts each visited span once to
    /// its Taylor form, then evaluates value and derivatives by Horner's rule (a few ns per
    /// parameter, see `docs/bspline.md`). Unsorted input still gives correct results (a
    /// step backwards falls back to a binary search), only slower.
    ///
    /// # Panics
    /// If `out.len() != ts.len()`.
    pub fn eval_derivs_sorted(&self, ts: &[f64], out: &mut [[f64; 4]]) {
        assert_eq!(
            ts.len(),
            out.len(),
            "eval_derivs_sorted: ts and out lengths differ"
        );
        let Some(&t0) = ts.first() else {
            return;
        };
        let p = self.degree;
        let n = self.coeffs.len();
        let knots = &self.knots[..];
        let mut span = find_span(knots, p, n, t0);
        let mut left = knots[span];
        let mut right = self.next_break(span);
        let mut a = self.taylor_on_span(span);
        for (&t, o) in ts.iter().zip(out.iter_mut()) {
            if t >= right || t < left {
                span = if t >= right {
                    self.advance_span(span, t)
                } else {
                    find_span(knots, p, n, t)
                };
                left = knots[span];
                right = self.next_break(span);
                a = self.taylor_on_span(span);
            }
            *o = horner(&a, t - left);
        }
    }

    /// Right end of span `span` for the forward walk: `+∞` for the last non-empty span
    /// (which extends past the domain), else the next knot.
    #[inline]
    fn next_break(&self, span: usize) -> f64 {
        let n = self.coeffs.len();
        if span + 1 >= n || self.knots[span + 1] >= self.knots[n] {
            f64::INFINITY
        } else {
            self.knots[span + 1]
        }
    }

    /// The span containing `t ≥ knots[span + 1]`, walking forward from `span` (a few steps
    /// in the usual case), with a binary search if the walk would be long.
    fn advance_span(&self, span: usize, t: f64) -> usize {
        let n = self.coeffs.len();
        let k = &self.knots;
        let mut s = span;
        let mut steps = 0;
        while s + 1 < n && t >= k[s + 1] {
            s += 1;
            steps += 1;
            if steps > 8 {
                return find_span(k, self.degree, n, t);
            }
        }
        if k[s] < k[s + 1] {
            s
        } else {
            find_span(k, self.degree, n, t)
        }
    }

    /// The derivative spline (degree − 1).
    ///
    /// Control points `q_i = p·(c_{i+1} − c_i)/(t_{i+p+1} − t_{i+1})` on the knot vector
    /// without its first and last knot (a zero-length support gives 0). For degree 0 the
    /// result is the zero spline of degree 0 on the same knots.
    pub fn derivative(&self) -> BSpline {
        let p = self.degree;
        if p == 0 {
            return BSpline {
                degree: 0,
                knots: self.knots.clone(),
                coeffs: vec![0.0; self.coeffs.len()],
            };
        }
        let t = &self.knots;
        let coeffs = (0..self.coeffs.len() - 1)
            .map(|i| {
                let h = t[i + p + 1] - t[i + 1];
                if h > 0.0 {
                    p as f64 * (self.coeffs[i + 1] - self.coeffs[i]) / h
                } else {
                    0.0
                }
            })
            .collect();
        BSpline {
            degree: p - 1,
            knots: t[1..t.len() - 1].to_vec(),
            coeffs,
        }
    }
}

/// Value and three derivatives of `a0 + a1 u + a2 u² + a3 u³`.
#[inline(always)]
pub(crate) fn horner(a: &[f64; 4], u: f64) -> [f64; 4] {
    let [a0, a1, a2, a3] = *a;
    let a3x3 = 3.0 * a3;
    let a2x2 = 2.0 * a2;
    [
        a0 + u * (a1 + u * (a2 + u * a3)),
        a1 + u * (a2x2 + u * a3x3),
        a2x2 + 2.0 * a3x3 * u,
        2.0 * a3x3,
    ]
}

/// Knots finite, non-decreasing, multiplicity ≤ degree + 1, non-empty domain.
pub(crate) fn check_knots(knots: &[f64], degree: usize) -> Result<(), SplineError> {
    if let Some(i) = knots.iter().position(|k| !k.is_finite()) {
        return Err(SplineError::NotFinite {
            what: "knots",
            index: i,
            value: knots[i],
        });
    }
    if let Some(i) = (1..knots.len()).find(|&i| knots[i] < knots[i - 1]) {
        return Err(SplineError::InvalidKnots {
            what: format!(
                "knots[{i}] = {} is less than knots[{}] = {}",
                knots[i],
                i - 1,
                knots[i - 1]
            ),
        });
    }
    let mut run = 1;
    for i in 1..knots.len() {
        run = if knots[i] == knots[i - 1] { run + 1 } else { 1 };
        if run > degree + 1 {
            return Err(SplineError::InvalidKnots {
                what: format!(
                    "knot {} repeated more than degree + 1 = {} times (at index {i})",
                    knots[i],
                    degree + 1
                ),
            });
        }
    }
    let (a, b) = (knots[degree], knots[knots.len() - degree - 1]);
    if a >= b {
        return Err(SplineError::InvalidKnots {
            what: format!("empty domain [{a}, {b}]"),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::knots::clamped_cubic;

    fn sample() -> BSpline {
        BSpline::new(
            3,
            clamped_cubic(&[0.0, 0.5, 1.7, 2.0, 3.5]),
            vec![1.0, -2.0, 0.5, 4.0, 3.0, -1.0, 2.0],
        )
        .unwrap()
    }

    #[test]
    fn derivatives_agree_with_finite_differences() {
        let sp = sample();
        let h = 1e-5;
        for i in 0..=70 {
            let t = -0.25 + 4.0 * i as f64 / 70.0;
            // Stay off the knots, where higher derivatives jump.
            if sp.knots().iter().any(|k| (k - t).abs() < 2.0 * h) {
                continue;
            }
            let d = sp.eval_derivs(t);
            let (m, p) = (sp.eval_derivs(t - h), sp.eval_derivs(t + h));
            for k in 0..3 {
                let fd = (p[k] - m[k]) / (2.0 * h);
                assert!(
                    (fd - d[k + 1]).abs() <= 1e-5 * (1.0 + d[k + 1].abs()),
                    "t={t} order {}: {} vs fd {fd}",
                    k + 1,
                    d[k + 1]
                );
            }
        }
    }

    #[test]
    fn derivative_spline_matches_eval_derivs() {
        let sp = sample();
        let d1 = sp.derivative();
        let d2 = d1.derivative();
        let d3 = d2.derivative();
        assert_eq!((d1.degree(), d2.degree(), d3.degree()), (2, 1, 0));
        let d4 = d3.derivative();
        assert_eq!(d4.degree(), 0);
        for i in 0..=40 {
            let t = 3.5 * i as f64 / 40.0;
            let d = sp.eval_derivs(t);
            let e1 = d1.eval_derivs(t);
            assert!((e1[0] - d[1]).abs() < 1e-10);
            assert!((e1[1] - d[2]).abs() < 1e-10);
            assert!((e1[2] - d[3]).abs() < 1e-10);
            assert_eq!(e1[3], 0.0);
            assert!((d2.eval(t) - d[2]).abs() < 1e-10);
            assert!((d3.eval(t) - d[3]).abs() < 1e-10);
            assert_eq!(d4.eval(t), 0.0);
        }
    }

    #[test]
    fn sorted_evaluation_equals_pointwise_including_outside_and_unsorted() {
        let sp = sample();
        let mut ts: Vec<f64> = (0..500).map(|i| -0.3 + 4.2 * i as f64 / 499.0).collect();
        ts.extend([0.5, 0.5, 1.7, 3.5, 3.5, 0.1, -1.0, 9.0]); // knots exactly, then unsorted
        let mut out = vec![[0.0; 4]; ts.len()];
        sp.eval_derivs_sorted(&ts, &mut out);
        for (t, o) in ts.iter().zip(&out) {
            let d = sp.eval_derivs(*t);
            for k in 0..4 {
                assert!(
                    (o[k] - d[k]).abs() <= 1e-9 * (1.0 + d[k].abs()),
                    "t={t} k={k}: {} vs {}",
                    o[k],
                    d[k]
                );
            }
        }
        sp.eval_derivs_sorted(&[], &mut []);
    }

    #[test]
    fn closed_form_taylor_equals_the_recurrence_with_repeated_knots() {
        // Double and triple interior knots, unclamped ends.
        let knots = vec![-1.0, -0.5, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0, 2.2, 3.0, 3.5, 4.0];
        let coeffs = vec![1.0, -2.0, 0.5, 4.0, 3.0, -1.0, 2.0, 0.7];
        let sp = BSpline::new(3, knots.clone(), coeffs).unwrap();
        for span in 3..8 {
            if knots[span] == knots[span + 1] {
                continue;
            }
            let fast = sp.taylor_on_span(span);
            let d = sp.eval_derivs_on_span(span, knots[span]);
            let slow = [d[0], d[1], 0.5 * d[2], d[3] / 6.0];
            for k in 0..4 {
                assert!(
                    (fast[k] - slow[k]).abs() < 1e-12 * (1.0 + slow[k].abs()),
                    "span {span}"
                );
            }
            let t = 0.3 * knots[span] + 0.7 * knots[span + 1];
            let e = sp.eval_derivs(t);
            let r = sp.eval_derivs_on_span(span, t);
            for k in 0..4 {
                assert!(
                    (e[k] - r[k]).abs() < 1e-11 * (1.0 + r[k].abs()),
                    "span {span}"
                );
            }
        }
    }

    #[test]
    fn constructor_rejects_bad_parts() {
        let k = clamped_cubic(&[0.0, 1.0]);
        assert!(BSpline::new(3, k.clone(), vec![0.0; 4]).is_ok());
        assert!(matches!(
            BSpline::new(3, k.clone(), vec![0.0; 5]),
            Err(SplineError::LengthMismatch { .. })
        ));
        assert!(matches!(
            BSpline::new(3, k.clone(), vec![0.0, f64::NAN, 0.0, 0.0]),
            Err(SplineError::NotFinite {
                what: "coeffs",
                index: 1,
                ..
            })
        ));
        assert!(matches!(
            BSpline::new(4, vec![0.0; 10], vec![0.0; 5]),
            Err(SplineError::InvalidKnots { .. })
        ));
        assert!(matches!(
            BSpline::new(3, vec![0.0; 8], vec![0.0; 4]),
            Err(SplineError::InvalidKnots { .. })
        ));
        let mut bad = k.clone();
        bad[2] = f64::INFINITY;
        assert!(matches!(
            BSpline::new(3, bad, vec![0.0; 4]),
            Err(SplineError::NotFinite {
                what: "knots",
                index: 2,
                ..
            })
        ));
        assert!(matches!(
            BSpline::new(
                3,
                vec![0.0, 0.0, 0.0, 0.0, 2.0, 1.0, 1.0, 1.0, 1.0],
                vec![0.0; 5]
            ),
            Err(SplineError::InvalidKnots { .. })
        ));
        assert!(matches!(
            BSpline::new(3, vec![1.0; 3], vec![]),
            Err(SplineError::TooFewPoints { .. })
        ));
    }
}
