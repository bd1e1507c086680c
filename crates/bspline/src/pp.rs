//! Piecewise-polynomial (Taylor) form of a cubic spline, for fast repeated evaluation.
//!
//! On break interval j, `f(t) = a0 + a1·u + a2·u² + a3·u³` with `u = t − breaks[j]`. Value
//! and three derivatives then cost one Horner pass (about ten flops), with no knot
//! arithmetic at all. Converting a [`BSpline`] costs one `eval_derivs` per span.

use crate::spline::{BSpline, horner};
use std::sync::Arc;

/// A spline of degree ≤ 3 as polynomial pieces: `coefs[j] = [a0, a1, a2, a3]` on
/// `[breaks[j], breaks[j + 1])`, in powers of `t − breaks[j]`. Outside
/// `[breaks[0], breaks[last]]` the end pieces are extended (as [`BSpline`] does). Splines
/// on the same breaks may hold one copy of them ([`PpCubic::share_breaks`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PpCubic {
    breaks: Arc<[f64]>,
    coefs: Vec<[f64; 4]>,
}

impl BSpline {
    /// This spline in piecewise-polynomial form (breaks = the distinct knots of the
    /// domain). Evaluations agree with [`BSpline::eval_derivs`] to rounding.
    pub fn to_pp(&self) -> PpCubic {
        let p = self.degree();
        let n = self.coeffs().len();
        let k = self.knots();
        let mut breaks = Vec::with_capacity(n - p + 1);
        let mut coefs = Vec::with_capacity(n - p);
        for span in p..n {
            if k[span] < k[span + 1] {
                breaks.push(k[span]);
                coefs.push(self.taylor_on_span(span));
            }
        }
        breaks.push(k[n]);
        PpCubic {
            breaks: breaks.into(),
            coefs,
        }
    }
}

impl PpCubic {
    /// Break points (strictly increasing, `pieces + 1` of them).
    pub fn breaks(&self) -> &[f64] {
        &self.breaks
    }

    /// The break points, to share with splines on the same ones
    /// ([`PpCubic::share_breaks`]).
    pub fn shared_breaks(&self) -> Arc<[f64]> {
        Arc::clone(&self.breaks)
    }

    /// Hold `breaks` instead of this spline's own copy when they are the same values (the
    /// spline unchanged: the same numbers, one allocation for the splines of one knot
    /// vector); whether they were.
    pub fn share_breaks(&mut self, breaks: &Arc<[f64]>) -> bool {
        let same = *self.breaks == **breaks;
        if same {
            self.breaks = Arc::clone(breaks);
        }
        same
    }

    /// Taylor coefficients of each piece about its left break.
    pub fn coefs(&self) -> &[[f64; 4]] {
        &self.coefs
    }

    /// The piece used at `t` (end pieces outside; NaN gives the first).
    fn piece(&self, t: f64) -> usize {
        // breaks[0] and the last break play the role of clamped knots.
        let m = self.coefs.len();
        self.breaks[1..m].partition_point(|&b| b <= t).min(m - 1)
    }

    /// The piece used at `t`, looked for first at `hint` and its neighbours (for
    /// evaluations that move a little along t, either way); the same piece as
    /// [`PpCubic::eval_derivs`] uses.
    pub fn piece_near(&self, t: f64, hint: usize) -> usize {
        let m = self.coefs.len();
        // Piece j is used for breaks[j] ≤ t < breaks[j + 1], the first piece below
        // breaks[1] and the last from breaks[m − 1] on.
        let fits =
            |j: usize| (j == 0 || self.breaks[j] <= t) && (j + 1 >= m || t < self.breaks[j + 1]);
        let h = hint.min(m - 1);
        if fits(h) {
            h
        } else if h + 1 < m && fits(h + 1) {
            h + 1
        } else if h > 0 && fits(h - 1) {
            h - 1
        } else {
            self.piece(t)
        }
    }

    /// [`PpCubic::eval_derivs`] on piece `j` (from [`PpCubic::piece_near`]).
    ///
    /// # Panics
    /// If `j` is not a piece.
    pub fn eval_derivs_on(&self, j: usize, t: f64) -> [f64; 4] {
        horner(&self.coefs[j], t - self.breaks[j])
    }

    /// Value at `t`.
    pub fn eval(&self, t: f64) -> f64 {
        self.eval_derivs(t)[0]
    }

    /// Value and first three derivatives at `t`: `[y, y', y'', y''']`.
    pub fn eval_derivs(&self, t: f64) -> [f64; 4] {
        let j = self.piece(t);
        horner(&self.coefs[j], t - self.breaks[j])
    }

    /// [`PpCubic::eval_derivs`] at sorted (non-decreasing) parameters `ts`, into `out`.
    /// Unsorted input is still evaluated correctly, only slower.
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
        let m = self.coefs.len();
        let mut j = self.piece(t0);
        let mut left = self.breaks[j];
        let mut right = if j + 1 < m {
            self.breaks[j + 1]
        } else {
            f64::INFINITY
        };
        for (&t, o) in ts.iter().zip(out.iter_mut()) {
            if t >= right || t < left {
                if t >= right && j + 2 < m && t < self.breaks[j + 2] {
                    j += 1;
                } else {
                    j = self.piece(t);
                }
                left = self.breaks[j];
                right = if j + 1 < m {
                    self.breaks[j + 1]
                } else {
                    f64::INFINITY
                };
            }
            *o = horner(&self.coefs[j], t - left);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::knots::clamped_cubic;
    use crate::spline::BSpline;

    #[test]
    fn pp_form_agrees_with_b_spline_form() {
        let sp = BSpline::new(
            3,
            clamped_cubic(&[0.0, 0.4, 1.0, 1.0, 2.2, 3.0]),
            vec![0.0, 1.0, -1.0, 2.0, 0.5, 0.25, 3.0, 1.0],
        );
        // A repeated interior break (double knot at 1.0) is allowed.
        let sp = sp.unwrap();
        let pp = sp.to_pp();
        assert_eq!(pp.breaks(), &[0.0, 0.4, 1.0, 2.2, 3.0]);
        assert_eq!(pp.coefs().len(), 4);
        let mut ts: Vec<f64> = (0..=300).map(|i| -0.5 + 4.0 * i as f64 / 300.0).collect();
        ts.extend([0.4, 1.0, 3.0, 0.2, -2.0, 5.0]);
        let mut out = vec![[0.0; 4]; ts.len()];
        pp.eval_derivs_sorted(&ts, &mut out);
        for (t, o) in ts.iter().zip(&out) {
            let want = sp.eval_derivs(*t);
            let single = pp.eval_derivs(*t);
            for k in 0..4 {
                let tol = 1e-9 * (1.0 + want[k].abs());
                assert!((o[k] - want[k]).abs() < tol, "t={t} k={k}");
                assert!((single[k] - want[k]).abs() < tol, "t={t} k={k}");
            }
            assert_eq!(pp.eval(*t), single[0]);
            // The hinted search finds the same piece from any hint.
            for hint in [0, 1, 2, 3, 7] {
                let j = pp.piece_near(*t, hint);
                assert_eq!(pp.eval_derivs_on(j, *t), single, "t={t} hint={hint}");
            }
        }
        assert_eq!(pp.piece_near(f64::NAN, 2), pp.piece(f64::NAN));
    }

    #[test]
    fn lower_degrees_convert_too() {
        let lin = BSpline::new(1, vec![0.0, 0.0, 1.0, 3.0, 3.0], vec![1.0, 3.0, -1.0]).unwrap();
        let pp = lin.to_pp();
        assert_eq!(pp.breaks(), &[0.0, 1.0, 3.0]);
        assert_eq!(pp.eval_derivs(2.0), [1.0, -2.0, 0.0, 0.0]);
        assert_eq!(pp.eval_derivs(0.5), [2.0, 2.0, 0.0, 0.0]);
    }
}
