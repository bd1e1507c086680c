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
//!   (`interpolate_not_a_knot` on the window widened by [`WINDOW_POINTS`] more points).
//!   A change of the values moves that slope by ≈ 0.27^[`WINDOW_POINTS`] of itself
//!   (the not-a-knot system's decay per knot), which the caller's verification on the
//!   whole path covers.
//!
//! [`Hermite`] builds these rows; its test checks them against `interpolate_not_a_knot`.
//!
//! Several axes can share one problem: each [`Hermite`] numbers its variables from an
//! `offset` (its changes first, then its slopes), so a primary-axis and a C-axis Hermite
//! built with offsets `0` and `hp.vars()` live side by side in one QP.

use crate::spline::AnalysisSpline;
use crate::{
    candidate::PatchFailure,
    qp::{QpBuilder, Row},
};

/// Points of the path kept either side of the modified range as Hermite unknowns; beyond
/// them the slope is fixed to the current spline's (module docs).
pub const WINDOW_POINTS: usize = 16;

/// Points either side of the modified range whose spans are constrained.
pub const CONSTRAINED_MARGIN_POINTS: usize = 3;

/// Points of the joint solver's Hermite window either side of the modified range (more than
/// the C-only QP's [`WINDOW_POINTS`]: the joint solver constrains the window's spans to be
/// no worse than before, which needs the model exact there, see [`EDGE_SPANS`]).
pub const JOINT_WINDOW_POINTS: usize = 24;

/// Spans at each end of a Hermite window inside the path that [`Hermite::push_limits`]
/// leaves unconstrained: the fixed end slope is exact only to about 0.27^window of the
/// change, and next to the end that error enters q''' amplified by 6/h²; 8 spans further
/// it has decayed by 0.27⁸ ≈ 3·10⁻⁵.
pub const EDGE_SPANS: usize = 8;

/// Rows per span (plus the current spline's vertex of q') of the "not worse" velocity rows
/// on a span that exceeded the velocity limit before (`Hermite::push_limits`).
pub const NOT_WORSE_SAMPLES_PER_SPAN: usize = 8;

/// Relative slack of a "not worse than before" bound (round-off only).
pub const NOT_WORSE_SLACK: f64 = 1e-9;

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
    /// In coefficient form ([`Hermite::coefficient_form`]): the window's cubic B-spline
    /// (clamped knots at every CL point of the window) with the current spline's
    /// coefficients; the variables are the changes of those coefficients.
    basis: Option<polepatch_bspline::BSpline>,
    /// In coefficient form: the value and slope forms at each knot of the window
    /// (`lo..=hi`), computed once.
    knot_forms: Vec<[Aff; 2]>,
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
            let lo2 = lo.saturating_sub(window.max(WINDOW_POINTS));
            let hi2 = (hi + window.max(WINDOW_POINTS)).min(n - 1);
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
            basis: None,
            knot_forms: Vec::new(),
        })
    }

    /// The same window in **coefficient form**: the variables are the `hi − lo + 3`
    /// coefficients of the cubic B-spline with a knot at every CL point of the window
    /// (clamped at its ends), numbered from `offset`. Every value and slope is then a
    /// combination of three neighbouring coefficients, C² continuity holds by
    /// construction (no rows for it), and the equalities are the fixed points' values and
    /// the two end conditions. The forms (`d1`, `d2`, `d3`, `b1`, …) and
    /// [`Hermite::push_limits`] are the same functions of the values and slopes; the
    /// changes are [`Hermite::delta`]. About a third of the unknowns of the point form and
    /// a third of its bandwidth: what the banded interior-point method wants
    /// ([`crate::ipm`]).
    pub(crate) fn coefficient_form(mut self) -> Result<Hermite<'a>, PatchFailure> {
        // The current spline on the window: the clamped interpolant with its own end
        // slopes (it is C² with these values, so it is that spline exactly); the variables
        // are changes of its coefficients, so a fixed point's value is exact (its row has
        // right-hand side 0) whatever the solver's tolerance.
        let (a, b) = (self.lo, self.hi);
        let sp = self.widened()?;
        let cl = polepatch_bspline::interpolate_clamped(
            &self.s[a..=b],
            &self.c[a..=b],
            sp.eval_derivs(self.s[a])[1],
            sp.eval_derivs(self.s[b])[1],
        )
        .map_err(|_| PatchFailure::TooShort)?;
        self.knot_forms = (self.lo..=self.hi)
            .map(|k| {
                [
                    Self::form_at(&cl, self.s[k], self.offset, 0),
                    Self::form_at(&cl, self.s[k], self.offset, 1),
                ]
            })
            .collect();
        self.basis = Some(cl);
        Ok(self)
    }

    /// The value (`order` 0) or slope (1) at `t` as an affine form of the changes of the
    /// coefficients of `b` (numbered from `offset`): the current spline's plus the basis
    /// row.
    fn form_at(b: &polepatch_bspline::BSpline, t: f64, offset: usize, order: usize) -> Aff {
        let r = b.basis_row(t, order);
        let cur = &b.coeffs()[r.first..];
        Aff {
            row: (0..4)
                .filter(|&j| r.weights[j] != 0.0)
                .map(|j| (offset + r.first + j, r.weights[j]))
                .collect(),
            c: (0..4)
                .map(|j| r.weights[j] * cur.get(j).copied().unwrap_or(0.0))
                .sum(),
        }
    }

    /// The current spline's coefficients (coefficient form only).
    pub(crate) fn coefficients(&self) -> Option<&[f64]> {
        self.basis.as_ref().map(|b| b.coeffs())
    }

    /// The analysis spline of the current values on the window widened by
    /// [`WINDOW_POINTS`] or more (where the window's slopes are taken from).
    fn widened(&self) -> Result<AnalysisSpline, PatchFailure> {
        let n = self.s.len();
        let w = (self.hi - self.last)
            .max(self.first - self.lo)
            .max(WINDOW_POINTS);
        let lo2 = self.lo.saturating_sub(w);
        let hi2 = (self.hi + w).min(n - 1);
        AnalysisSpline::new(&self.s[lo2..=hi2], &self.c[lo2..=hi2])
            .map_err(|_| PatchFailure::TooShort)
    }

    /// The value (`order` 0) or slope (1) at knot `k` of the window, in coefficient form.
    fn basis_aff(&self, k: usize, order: usize) -> Aff {
        self.knot_forms[k - self.lo][order].clone()
    }

    /// The change `δ_i` of the value at point `i` (in `first..=last`): one variable in
    /// point form, a combination of coefficients minus the current value in coefficient
    /// form.
    pub(crate) fn delta(&self, i: usize) -> Aff {
        match &self.basis {
            None => Aff::var(self.delta_var(i)),
            Some(_) => {
                let mut a = self.basis_aff(i, 0);
                a.c -= self.c[i];
                a
            }
        }
    }

    /// Index of this Hermite's first variable.
    pub(crate) fn offset(&self) -> usize {
        self.offset
    }

    /// Index of the variable `δ_i` (point `i` in `first..=last`).
    pub(crate) fn delta_var(&self, i: usize) -> usize {
        self.offset + i - self.first
    }

    /// Number of variables (changes, then slopes; or the coefficients).
    pub(crate) fn vars(&self) -> usize {
        match &self.basis {
            None => self.nd + self.hi - self.lo + 1,
            Some(_) => self.hi - self.lo + 3,
        }
    }

    pub(crate) fn h(&self, k: usize) -> f64 {
        self.s[k + 1] - self.s[k]
    }

    /// Value at path point k.
    fn y(&self, k: usize) -> Aff {
        if self.basis.is_some() {
            return self.basis_aff(k, 0);
        }
        let mut a = Aff::constant(self.c[k]);
        if (self.first..=self.last).contains(&k) {
            a.row.push((self.delta_var(k), 1.0));
        }
        a
    }

    /// Slope at path knot k (lo ≤ k ≤ hi).
    pub(crate) fn m(&self, k: usize) -> Aff {
        match &self.basis {
            None => Aff::var(self.offset + self.nd + k - self.lo),
            Some(_) => self.basis_aff(k, 1),
        }
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
        if self.basis.is_some() {
            // Coefficient form: C² holds by construction; the fixed points keep their
            // values.
            for k in (lo..=hi).filter(|k| !(self.first..=self.last).contains(k)) {
                eqs.push(Aff::sum(&[
                    (1.0, &self.y(k)),
                    (-self.c[k], &Aff::constant(1.0)),
                ]));
            }
        }
        for k in (lo + 1..hi).filter(|_| self.basis.is_none()) {
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

    /// Write the current spline into `x` (the variables of this Hermite): every change 0,
    /// every knot slope the slope of the analysis spline of the current values (on the
    /// window widened by [`WINDOW_POINTS`], as the fixed end slopes are).
    pub(crate) fn write_current(&self, x: &mut [f64]) -> Result<(), PatchFailure> {
        let n = self.s.len();
        let w = (self.hi - self.last)
            .max(self.first - self.lo)
            .max(WINDOW_POINTS);
        let lo2 = self.lo.saturating_sub(w);
        let hi2 = (self.hi + w).min(n - 1);
        if self.basis.is_some() {
            // The current spline: no change of its coefficients.
            for j in 0..self.vars() {
                x[self.offset + j] = 0.0;
            }
            return Ok(());
        }
        let sp = AnalysisSpline::new(&self.s[lo2..=hi2], &self.c[lo2..=hi2])
            .map_err(|_| PatchFailure::TooShort)?;
        for i in self.first..=self.last {
            x[self.delta_var(i)] = 0.0;
        }
        for k in self.lo..=self.hi {
            x[self.offset + self.nd + k - self.lo] = sp.eval_derivs(self.s[k])[1];
        }
        Ok(())
    }

    /// For every span `k` of the window (`lo..hi`, index `k − lo`), what rounding the
    /// written values (points `first..=last`, each moved by at most `eps`) can add to the
    /// span's `|q'|`, `|q''|`, `|q'''|` at the points the bounds are taken (knots and
    /// middle): `eps·Σ_{i written} |w_i|` over the analysis spline's data rows
    /// ([`crate::spline::SplineSystem::data_row`], on the window).
    pub(crate) fn rounding_room(
        &self,
        eps: f64,
        memo: Option<&crate::joint::RoundingMemo>,
    ) -> Result<Vec<[f64; 3]>, PatchFailure> {
        let gains = self.rounding_gains(memo)?;
        Ok(gains
            .iter()
            .map(|g| [g[0] * eps, g[1] * eps, g[2] * eps])
            .collect())
    }

    /// [`Hermite::rounding_room`] for `eps = 1`. It depends only on the window's knots and
    /// which of them are written, and one zone's solves (every start, both axes) ask for
    /// the same window again and again: with a `memo` the results are kept there, keyed
    /// by exactly those inputs (the knots compared bit for bit).
    fn rounding_gains(
        &self,
        memo: Option<&crate::joint::RoundingMemo>,
    ) -> Result<Vec<[f64; 3]>, PatchFailure> {
        let knots = &self.s[self.lo..=self.hi];
        let (a, b) = (self.first - self.lo, self.last - self.lo);
        let same = |k: &[f64]| {
            k.len() == knots.len() && k.iter().zip(knots).all(|(x, y)| x.to_bits() == y.to_bits())
        };
        if let Some(hit) = memo.and_then(|m| {
            m.entries
                .borrow()
                .iter()
                .find(|e| e.1 == (a, b) && same(&e.0))
                .map(|e| e.2.clone())
        }) {
            return Ok(hit);
        }
        let sys = crate::spline::SplineSystem::new(knots).map_err(|_| PatchFailure::TooShort)?;
        let l1 = |t: f64, order: usize| -> f64 {
            sys.data_row(t, order)[a..=b]
                .iter()
                .map(|w| w.abs())
                .sum::<f64>()
        };
        let gains: Vec<[f64; 3]> = (self.lo..self.hi)
            .map(|k| {
                let (x0, x1) = (self.s[k], self.s[k + 1]);
                let mid = 0.5 * (x0 + x1);
                [
                    l1(x0, 1).max(l1(mid, 1)).max(l1(x1, 1)),
                    l1(x0, 2).max(l1(x1, 2)),
                    l1(mid, 3),
                ]
            })
            .collect();
        if let Some(m) = memo {
            m.entries
                .borrow_mut()
                .push((knots.to_vec(), (a, b), gains.clone()));
        }
        Ok(gains)
    }

    /// Push Equation 6's rows for this axis over every span of the window, in convex-hull
    /// form (the bounds then hold for every s of a span, hence at every sample):
    /// `|m_k| ≤ v`, `|b1| ≤ v`, `|q''(knot)| ≤ a`, `|q'''| ≤ j`. A span with both knots
    /// movable, or in `core` (the spans that must reach feed), gets `limit − room`; any
    /// other span that touches a fixed point gets
    /// `max(limit, |current value|·(1 + NOT_WORSE_SLACK)) − room` — for q', where the span
    /// exceeded the velocity limit before, at [`NOT_WORSE_SAMPLES_PER_SPAN`] samples and the
    /// current spline's vertex of q' (where its exact peak is) against that exact peak
    /// instead of the hull: it may not get worse, and need not reach
    /// feed (a fixed neighbour may already exceed the limits, e.g. through the file's own
    /// rounding). `room[k − lo][r]` ([`Hermite::rounding_room`]) is
    /// what rounding the written values can add to the (r+1)-th derivative on span k, so
    /// the bounds still hold on the values as written. `current` holds
    /// [`Hermite::write_current`]'s values. The window is constrained but for its last
    /// [`EDGE_SPANS`] spans at each cut end, so that what lies beyond moves by about
    /// 0.27^(window − EDGE_SPANS) of the change only.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn push_limits(
        &self,
        qp: &mut QpBuilder,
        lim: &crate::limits::GeomLimits,
        current: &[f64],
        room: &[[f64; 3]],
        core: std::ops::Range<usize>,
    ) {
        // Spans next to a window end inside the path are left out: there the fixed end
        // slope's error (about 0.27^window of the change) enters q''' amplified by 6/h².
        let n = self.s.len();
        let a = if self.lo > 0 {
            self.lo + EDGE_SPANS
        } else {
            self.lo
        };
        let b = if self.hi < n - 1 {
            self.hi.saturating_sub(EDGE_SPANS)
        } else {
            self.hi
        };
        let a = a.min(self.first);
        // Only the window's spans have rows here: a core that reaches past the window's
        // ends (a zone wider than the range being solved) is clipped to it — the points
        // beyond are fixed in this solve, and verification judges the whole zone.
        let spans =
            a.min(core.start).max(self.lo)..b.max(self.last).max(core.end).max(a + 1).min(self.hi);
        let mut taus = Vec::new();
        for k in spans.clone() {
            let movable = |i: usize| i >= self.first && i <= self.last;
            let strict = (movable(k) && movable(k + 1)) || core.contains(&k);
            let room = room.get(k - self.lo).copied().unwrap_or([0.0; 3]);
            let bound = |f: &Aff, limit: f64, r: usize| {
                let b = if strict {
                    limit
                } else {
                    limit.max(f.at(current).abs() * (1.0 + NOT_WORSE_SLACK))
                };
                // Never below a sliver of the limit: the row stays well posed.
                (b - room[r]).max(1e-3 * limit)
            };
            let rows = vec![
                (self.m(k), lim.v, 0),
                (self.d2(k, 0.0), lim.a, 1),
                (self.d3(k), lim.j, 2),
            ];
            let hull = [self.m(k), self.b1(k), self.m(k + 1)];
            let hull_now = hull.iter().fold(0.0f64, |m, f| m.max(f.at(current).abs()));
            if strict || hull_now <= lim.v {
                // |q'| ≤ v on the whole span through its Bernstein coefficients (a span
                // within the limit before may only stay within it: "not worse").
                let b = (lim.v - room[0]).max(1e-3 * lim.v);
                push_abs(qp, &self.b1(k), b);
            } else {
                // Beyond the limit before: "not worse" on q' against the span's exact peak
                // before (the hull overstates the peak, so it cannot stand for it).
                crate::spline::span_offsets(self.h(k), NOT_WORSE_SAMPLES_PER_SPAN, &mut taus);
                // Rows at the samples and at the current spline's vertex of q' (its peak
                // on the span, when inside), against that peak.
                let d1 = |t: f64| self.d1(k, t).at(current);
                let (qa, qm, qb) = (d1(0.0), d1(0.5 * self.h(k)), d1(self.h(k)));
                // q'(τ) = qa + c1·τ + c2·τ² through the three values.
                let h = self.h(k);
                let c2 = 2.0 * (qa - 2.0 * qm + qb) / (h * h);
                let c1 = (qb - qa) / h - c2 * h;
                if c2 != 0.0 {
                    let v = -c1 / (2.0 * c2);
                    if v > 0.0 && v < h {
                        taus.push(v);
                    }
                }
                let peak = taus.iter().fold(0.0f64, |m, &t| m.max(d1(t).abs()));
                let b = (lim.v.max(peak * (1.0 + NOT_WORSE_SLACK)) - room[0]).max(1e-3 * lim.v);
                for &tau in taus.iter().filter(|&&t| t > 0.0 && t < h) {
                    push_abs(qp, &self.d1(k, tau), b);
                }
            }
            for (f, l, r) in rows {
                let b = bound(&f, l, r);
                push_abs(qp, &f, b);
            }
            if k + 1 == spans.end {
                for (f, l, r) in [(self.m(k + 1), lim.v, 0), (self.d2(k, self.h(k)), lim.a, 1)] {
                    let b = bound(&f, l, r);
                    push_abs(qp, &f, b);
                }
            }
        }
    }

    /// The position along the path (the knot index) of each of this Hermite's variables,
    /// in variable order: the changes `δ_i` at `i`, the slopes `m_k` at `k`.
    pub(crate) fn positions(&self) -> Vec<f64> {
        if self.basis.is_some() {
            // Coefficient j of a clamped cubic lives around knot j − 1 of the window.
            return (0..self.vars())
                .map(|j| (self.lo + j).saturating_sub(1).clamp(self.lo, self.hi) as f64)
                .collect();
        }
        (self.first..=self.last)
            .chain(self.lo..=self.hi)
            .map(|k| k as f64)
            .collect()
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
        .max(1e-300);
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
            for (first, last, window) in [(0, n - 1, WINDOW_POINTS), (n / 2, n / 2, 3)] {
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
        let hm = Hermite::new(&s, &y, first, last, WINDOW_POINTS).unwrap();
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

    /// Coefficient form, the planted response: with the changes of points `first..=last`
    /// fixed, the coefficients the equalities determine give the analysis spline of the
    /// changed data — its value, first, second and third derivatives at points of every
    /// span of the window, through the same forms (`d1`, `d2`, `d3`, `b1`) the limits use
    /// — on a window inside the path (fixed end slopes) and on the whole path (not-a-knot).
    #[test]
    fn coefficient_form_is_the_spline_of_the_changed_data() {
        let (s, y) = data(60);
        for (first, last, window) in [(28, 32, WINDOW_POINTS), (1, 58, 60)] {
            let hm = Hermite::new(&s, &y, first, last, window)
                .unwrap()
                .coefficient_form()
                .unwrap();
            let delta: Vec<f64> = (first..=last)
                .map(|i| (i as f64 * 0.9).sin() * 4.0)
                .collect();
            // The equalities and the changes make a square system in the coefficients:
            // solve it exactly (Gaussian elimination with partial pivoting).
            let nv = hm.vars();
            let mut rows: Vec<(Vec<f64>, f64)> = Vec::new();
            let dense = |f: &Aff| {
                let mut r = vec![0.0; nv];
                for &(j, v) in &f.row {
                    r[j] += v;
                }
                r
            };
            for e in hm.equalities() {
                rows.push((dense(&e), -e.c));
            }
            for (i, d) in (first..=last).zip(&delta) {
                let f = hm.delta(i);
                rows.push((dense(&f), d - f.c));
            }
            assert_eq!(rows.len(), nv, "one row per coefficient");
            for col in 0..nv {
                let piv = (col..nv)
                    .max_by(|&a, &b| rows[a].0[col].abs().total_cmp(&rows[b].0[col].abs()))
                    .unwrap();
                rows.swap(col, piv);
                let (head, tail) = rows.split_at_mut(col + 1);
                let p = &head[col];
                for r in tail.iter_mut() {
                    let f = r.0[col] / p.0[col];
                    for j in col..nv {
                        r.0[j] -= f * p.0[j];
                    }
                    r.1 -= f * p.1;
                }
            }
            let mut x = vec![0.0; nv];
            for col in (0..nv).rev() {
                let acc: f64 = (col + 1..nv).map(|j| rows[col].0[j] * x[j]).sum();
                x[col] = (rows[col].1 - acc) / rows[col].0[col];
            }
            let mut y2 = y.clone();
            for (i, d) in (first..=last).zip(&delta) {
                y2[i] += d;
            }
            let sp = interpolate_not_a_knot(&s, &y2).unwrap();
            // Inside a window cut from the path the end slopes are fixed: the spline there
            // differs from the whole path's by what a change propagates (≈ 0.27^16).
            for k in hm.lo..hm.hi {
                let h = hm.h(k);
                for tau in [0.0, 0.37 * h, h] {
                    // q' and q'' are continuous: at τ = h either span's piece will do.
                    let d = sp.eval_derivs(s[k] + tau);
                    assert!((hm.d1(k, tau).at(&x) - d[1]).abs() < 1e-7, "{k}: q'");
                    assert!((hm.d2(k, tau).at(&x) - d[2]).abs() < 1e-6, "{k}: q''");
                }
                assert!((hm.d3(k).at(&x) - sp.eval_derivs(s[k] + 0.5 * h)[3]).abs() < 1e-5);
                // b1 is the middle Bernstein coefficient of q': its average is the secant.
                let b1 = hm.b1(k).at(&x);
                let secant = (y2[k + 1] - y2[k]) / h;
                let avg = (hm.m(k).at(&x) + b1 + hm.m(k + 1).at(&x)) / 3.0;
                assert!((avg - secant).abs() < 1e-6, "{k}");
            }
            for i in first..=last {
                assert!((hm.delta(i).at(&x) - delta[i - first]).abs() < 1e-9);
            }
            // With no change at all the variables are zero: the current spline.
            let mut cur = vec![0.0; hm.vars()];
            hm.write_current(&mut cur).unwrap();
            assert!(cur.iter().all(|&v| v == 0.0));
            assert!(
                (hm.m(first).at(&cur)
                    - interpolate_not_a_knot(&s, &y)
                        .unwrap()
                        .eval_derivs(s[first])[1])
                    .abs()
                    < 1e-6
            );
        }
    }

    /// With an offset, the same rows move to the offset's variables.
    /// Regression (issue 30, a real Haas UMC program with `--cone 7.5`): a core wider
    /// than the window — spans before its first knot — panicked with an index below the
    /// window; its rows are those of the window's spans only.
    #[test]
    fn a_core_wider_than_the_window_is_clipped_to_it() {
        let (s, y) = data(60);
        for form in [false, true] {
            let mut hm = Hermite::new(&s, &y, 28, 32, 3).unwrap();
            if form {
                hm = hm.coefficient_form().unwrap();
            }
            let mut current = vec![0.0; hm.vars()];
            hm.write_current(&mut current).unwrap();
            let room = vec![[0.0; 3]; hm.hi - hm.lo + 1];
            let lim = crate::limits::GeomLimits {
                v: 1.0,
                a: 1.0,
                j: 1.0,
            };
            let mut qp = QpBuilder::new(hm.vars());
            hm.push_limits(&mut qp, &lim, &current, &room, 0..59);
            assert!(qp.le_len() > 0);
        }
    }

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
