//! The joint patch's view of the analysis spline: a **window** of knots around the
//! points that move, in B-spline coefficient form with the window's equalities
//! eliminated, and Equation 6's rows on it.
//!
//! The analysis spline of an axis (SPEC §2: the not-a-knot cubic interpolant of its values
//! over s) is, on the window `lo..=hi` of knots, the clamped cubic B-spline with a knot at
//! every CL point and the spline's own slopes at the window's ends (it is C² with those
//! values, so it is that spline exactly). Its `nc = hi − lo + 3` coefficients `c` are the
//! variables (as changes `δc` from the current spline's): every value, slope and higher
//! derivative on a span is a combination of the span's four coefficients, and C²
//! continuity holds by construction.
//!
//! The points outside `first..=last` keep their values and each end of the window keeps
//! its condition — the current spline's slope where the window ends inside the path,
//! not-a-knot (`q'''` continuous at the second knot) at an end of the path. These are
//! `nc − (last − first + 1)` linear equalities `E·δc = 0`; at each end of the window they
//! involve the outermost coefficients (as many as the equalities there) and a few free
//! ones next to them, so the outer ones are `δc_M = −E_M⁻¹·E_R·δc_R` (one small dense
//! solve per window). What is left is **one free coefficient per movable point**: the
//! unknowns of the joint patch ([`crate::joint`]), with no equality rows. For a fixed end
//! slope each outer coefficient is a multiple of the free coefficient at the range's edge,
//! decaying by about 0.27 per knot outwards (the interpolant's decay).
//!
//! Everything here depends on the knots and the range only: one [`Window`] serves both
//! axes and every start of a zone ([`WindowMemo`]); a start's spline enters through its
//! coefficients ([`Window::coeffs`]), which give each row's constant.
//!
//! The tests check the rows against `polepatch_bspline::interpolate_not_a_knot` of the
//! changed data.

// Index loops mirror the formulas (coefficients, Taylor terms, knots).
#![allow(clippy::needless_range_loop)]

use crate::candidate::PatchFailure;
use crate::qp::Row;
use crate::spline::{AnalysisSpline, SplineSystem};
use crate::tolerances::{
    EDGE_SPANS, MIN_ROW_BOUND, NOT_WORSE_SAMPLES_PER_SPAN, NOT_WORSE_SLACK, PIVOT_REL_TOL,
    WIDEN_POINTS,
};

pub use crate::tolerances::JOINT_WINDOW_POINTS;

/// A linear form `Σ_j w[j]·c[first + j]` over four consecutive coefficients of the window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Local {
    first: usize,
    w: [f64; 4],
}

impl Local {
    /// Its value on the coefficients `c`.
    pub(crate) fn at(&self, c: &[f64]) -> f64 {
        (0..4).map(|j| self.w[j] * c[self.first + j]).sum()
    }

    fn lin(&self, a: f64, o: &Local, b: f64) -> Local {
        debug_assert_eq!(self.first, o.first);
        Local {
            first: self.first,
            w: std::array::from_fn(|j| a * self.w[j] + b * o.w[j]),
        }
    }
}

/// One span's four basis functions as Taylor coefficients at its left knot:
/// `taylor[r][j]` is the r-th derivative of basis function `first + j` there.
#[derive(Debug, Clone)]
struct SpanBasis {
    first: usize,
    h: f64,
    taylor: [[f64; 4]; 4],
}

impl SpanBasis {
    /// The `order`-th derivative at `τ` on the span (`0 ≤ τ ≤ h`).
    fn at(&self, tau: f64, order: usize) -> Local {
        let mut w = [0.0; 4];
        let mut f = 1.0;
        for p in order..4 {
            for j in 0..4 {
                w[j] += self.taylor[p][j] * f;
            }
            f *= tau / (p + 1 - order) as f64;
        }
        Local {
            first: self.first,
            w,
        }
    }

    /// The middle Bernstein coefficient of q' on the span: `3σ − m_k − m_{k+1}`.
    fn b1(&self) -> Local {
        let (y0, y1) = (self.at(0.0, 0), self.at(self.h, 0));
        let (m0, m1) = (self.at(0.0, 1), self.at(self.h, 1));
        let sec = y1.lin(3.0 / self.h, &y0, -3.0 / self.h);
        let m = m0.lin(1.0, &m1, 1.0);
        sec.lin(1.0, &m, -1.0)
    }
}

/// The window of a moving range `first..=last` (module docs).
#[derive(Debug, Clone)]
pub(crate) struct Window {
    pub(crate) lo: usize,
    pub(crate) hi: usize,
    pub(crate) first: usize,
    pub(crate) last: usize,
    /// Coefficients, and how many are eliminated at each end.
    nc: usize,
    ml: usize,
    mr: usize,
    /// The knots `s[lo..=hi]`, mm.
    knots: Vec<f64>,
    /// Span k of the path is `spans[k − lo]`.
    spans: Vec<SpanBasis>,
    /// For an eliminated coefficient, its combination of free ones (full indices).
    sub: Vec<Row>,
    /// Per span, what a change of at most 1 in every written value (`first..=last`) can
    /// add to `|q'|`, `|q''|`, `|q'''|` on it ([`Window::rounding_room`]).
    gains: Vec<[f64; 3]>,
}

impl Window {
    /// The window of `first..=last` widened by `window` points (clipped to the path).
    pub(crate) fn new(
        s: &[f64],
        first: usize,
        last: usize,
        window: usize,
    ) -> Result<Window, PatchFailure> {
        let n = s.len();
        if n < 2 || first > last || last >= n {
            return Err(PatchFailure::TooShort);
        }
        let (lo, hi) = (first.saturating_sub(window), (last + window).min(n - 1));
        // A path of 2 or 3 points is a line or a parabola: not this window's case.
        if hi - lo < 3 {
            return Err(PatchFailure::TooShort);
        }
        let knots = s[lo..=hi].to_vec();
        let nc = hi - lo + 3;
        // The basis: any clamped cubic on these knots.
        let basis =
            polepatch_bspline::interpolate_clamped(&knots, &vec![0.0; knots.len()], 0.0, 0.0)
                .map_err(|_| PatchFailure::TooShort)?;
        let spans: Vec<SpanBasis> = (lo..hi)
            .map(|k| {
                let rows: Vec<_> = (0..4).map(|r| basis.basis_row(s[k], r)).collect();
                debug_assert!(rows.iter().all(|r| r.first == rows[0].first));
                SpanBasis {
                    first: rows[0].first,
                    h: s[k + 1] - s[k],
                    taylor: std::array::from_fn(|r| rows[r].weights),
                }
            })
            .collect();
        let mut w = Window {
            lo,
            hi,
            first,
            last,
            nc,
            ml: 0,
            mr: 0,
            knots,
            spans,
            sub: Vec::new(),
            gains: Vec::new(),
        };
        w.eliminate(n)?;
        w.gains = w.rounding_gains()?;
        Ok(w)
    }

    /// The value at knot `k` (`lo..=hi`).
    fn value(&self, k: usize) -> Local {
        if k < self.hi {
            self.spans[k - self.lo].at(0.0, 0)
        } else {
            let sp = &self.spans[k - 1 - self.lo];
            sp.at(sp.h, 0)
        }
    }

    /// The equalities (module docs), each with its end (`true`: `lo`), over full
    /// coefficients; and the elimination of the outermost coefficients.
    fn eliminate(&mut self, n: usize) -> Result<(), PatchFailure> {
        let (lo, hi, nc) = (self.lo, self.hi, self.nc);
        let dense = |f: &Local| -> Row { (0..4).map(|j| (f.first + j, f.w[j])).collect() };
        let mut eqs: Vec<(Row, bool)> = (lo..=hi)
            .filter(|k| !(self.first..=self.last).contains(k))
            .map(|k| (dense(&self.value(k)), k < self.first))
            .collect();
        // q''' continuous at the second knot of an end: not-a-knot.
        let not_a_knot = |a: &SpanBasis, b: &SpanBasis| -> Row {
            let mut r = dense(&a.at(0.0, 3));
            r.extend(dense(&b.at(0.0, 3)).into_iter().map(|(j, v)| (j, -v)));
            r
        };
        let first_span = &self.spans[0];
        let last_span = &self.spans[hi - lo - 1];
        eqs.push((
            if lo > 0 {
                dense(&first_span.at(0.0, 1))
            } else {
                not_a_knot(first_span, &self.spans[1])
            },
            true,
        ));
        eqs.push((
            if hi < n - 1 {
                dense(&last_span.at(last_span.h, 1))
            } else {
                not_a_knot(&self.spans[hi - lo - 2], last_span)
            },
            false,
        ));
        let ml = eqs.iter().filter(|e| e.1).count();
        let mr = eqs.len() - ml;
        if ml + mr + (self.last - self.first + 1) != nc {
            return Err(PatchFailure::TooShort);
        }
        let free = ml..nc - mr;
        let outer: Vec<usize> = (0..ml).chain(nc - mr..nc).collect();
        let mut others: Vec<usize> = eqs
            .iter()
            .flat_map(|f| f.0.iter().map(|e| e.0))
            .filter(|j| free.contains(j))
            .collect();
        others.sort_unstable();
        others.dedup();
        let (m, no) = (outer.len(), others.len());
        // [E_M | E_R] dense, then E_M⁻¹·E_R by elimination with partial pivoting.
        let mut a = vec![0.0; m * (m + no)];
        for (r, (f, _)) in eqs.iter().enumerate() {
            for &(j, v) in f {
                let col = if free.contains(&j) {
                    m + others.binary_search(&j).unwrap_or(0)
                } else if j < ml {
                    j
                } else {
                    ml + j - (nc - mr)
                };
                a[r * (m + no) + col] += v;
            }
        }
        let t = solve_dense(&mut a, m, no).ok_or(PatchFailure::TooShort)?;
        self.sub = vec![Vec::new(); nc];
        for (r, &j) in outer.iter().enumerate() {
            self.sub[j] = others
                .iter()
                .enumerate()
                .map(|(q, &o)| (o, -t[r * no + q]))
                .filter(|e| e.1 != 0.0)
                .collect();
        }
        (self.ml, self.mr) = (ml, mr);
        Ok(())
    }

    /// Number of unknowns per axis: one per movable point.
    pub(crate) fn unknowns(&self) -> usize {
        self.last - self.first + 1
    }

    /// `f` in the free coefficients, unknown `r` (coefficient `ml + r`) at index
    /// `offset + stride·r`, appended to `out` (sorted, each unknown once).
    fn reduce_into(&self, f: &Local, offset: usize, stride: usize, out: &mut Row) {
        let start = out.len();
        let free = self.ml..self.nc - self.mr;
        for j in 0..4 {
            let (c, v) = (f.first + j, f.w[j]);
            if v == 0.0 {
                continue;
            }
            if free.contains(&c) {
                out.push((offset + stride * (c - self.ml), v));
            } else {
                for &(o, t) in &self.sub[c] {
                    out.push((offset + stride * (o - self.ml), v * t));
                }
            }
        }
        let tail = &mut out[start..];
        tail.sort_unstable_by_key(|e| e.0);
        let mut w = start;
        for r in start..out.len() {
            if w > start && out[w - 1].0 == out[r].0 {
                out[w - 1].1 += out[r].1;
            } else {
                out[w] = out[r];
                w += 1;
            }
        }
        out.truncate(w);
    }

    /// `f` as a row in the free coefficients (see [`Window::reduce_into`]).
    fn reduce(&self, f: &Local, offset: usize, stride: usize) -> Row {
        let mut out = Vec::with_capacity(4);
        self.reduce_into(f, offset, stride, &mut out);
        out
    }

    /// The window's spline of the values `y` (one per point of the path `s`): its
    /// coefficients, with the end slopes of the analysis spline of `y` on the window
    /// widened by `max(window, 16)` points.
    pub(crate) fn coeffs(&self, s: &[f64], y: &[f64]) -> Result<Vec<f64>, PatchFailure> {
        let n = s.len();
        let w = (self.hi - self.last)
            .max(self.first - self.lo)
            .max(WIDEN_POINTS);
        let (lo2, hi2) = (self.lo.saturating_sub(w), (self.hi + w).min(n - 1));
        let sp = AnalysisSpline::new(&s[lo2..=hi2], &y[lo2..=hi2])
            .map_err(|_| PatchFailure::TooShort)?;
        let cl = polepatch_bspline::interpolate_clamped(
            &self.knots,
            &y[self.lo..=self.hi],
            sp.eval_derivs(s[self.lo])[1],
            sp.eval_derivs(s[self.hi])[1],
        )
        .map_err(|_| PatchFailure::TooShort)?;
        Ok(cl.coeffs().to_vec())
    }

    /// The change of the value at point `i` (`first..=last`) as an affine form of the
    /// unknowns: `(row, constant)` with the spline of coefficients `c` at zero change and
    /// `y_i` the point's value.
    pub(crate) fn delta(
        &self,
        i: usize,
        c: &[f64],
        y_i: f64,
        offset: usize,
        stride: usize,
    ) -> (Row, f64) {
        let f = self.value(i);
        (self.reduce(&f, offset, stride), f.at(c) - y_i)
    }

    /// For every span of the window (`lo..hi`, index `k − lo`), what rounding the written
    /// values (points `first..=last`, each moved by at most `eps`) can add to the span's
    /// `|q'|`, `|q''|`, `|q'''|` at the points the bounds are taken (knots and middle):
    /// `eps·Σ_{i written} |w_i|` over the analysis spline's data rows
    /// ([`crate::spline::SplineSystem::data_row`], on the window).
    pub(crate) fn rounding_room(&self, eps: f64) -> Vec<[f64; 3]> {
        self.gains
            .iter()
            .map(|g| [g[0] * eps, g[1] * eps, g[2] * eps])
            .collect()
    }

    /// The gains of [`Window::rounding_room`]: per span, six data rows of the window's
    /// spline, each computed only where it is not negligible
    /// ([`crate::spline::SplineSystem::data_row_local`], exact to
    /// `polepatch_bspline::interp::DATA_ROW_TOL` of its largest weight), so that a window
    /// of n points costs O(n), not O(n²) (issue 26, a 100 000-point zone).
    fn rounding_gains(&self) -> Result<Vec<[f64; 3]>, PatchFailure> {
        let (a, b) = (self.first - self.lo, self.last - self.lo);
        let sys = SplineSystem::new(&self.knots).map_err(|_| PatchFailure::TooShort)?;
        let row = std::cell::RefCell::new(Vec::new());
        let l1 = |t: f64, order: usize| -> f64 {
            let mut row = row.borrow_mut();
            let start = sys.data_row_local(t, order, &mut row);
            let (from, to) = (a.max(start), b.min(start + row.len() - 1));
            if from > to {
                return 0.0;
            }
            row[from - start..=to - start]
                .iter()
                .map(|w| w.abs())
                .sum::<f64>()
        };
        Ok(self
            .knots
            .windows(2)
            .map(|k| {
                let (x0, x1) = (k[0], k[1]);
                let mid = 0.5 * (x0 + x1);
                [
                    l1(x0, 1).max(l1(mid, 1)).max(l1(x1, 1)),
                    l1(x0, 2).max(l1(x1, 2)),
                    l1(mid, 3),
                ]
            })
            .collect())
    }

    /// Equation 6's rows for one axis over the window's spans, in convex-hull form (the
    /// bounds then hold for every s of a span, hence at every sample): `|m_k| ≤ v`,
    /// `|b1| ≤ v`, `|q''(knot)| ≤ a`, `|q'''| ≤ j`, each row `(row, constant, bound)`
    /// saying `|row·x + constant| ≤ bound` in the unknowns at `offset + stride·r`, the
    /// constant the spline of coefficients `cur` (the start's). Which spans get rows, and
    /// which bounds, is `set`'s ([`RowSet`]).
    ///
    /// [`RowSet::Patch`]: a span in `core` (the spans that must reach feed) gets
    /// `limit − room`; so does a row of a span with both knots movable — unless the span
    /// lies beyond `pole` (the spans the pole's slowdown may reach: beyond a side where the
    /// zone was cut from a longer stretch below feed, `crate::analysis::detect_zones`) and
    /// the row exceeded the machine's own limit (`machine_lim`, without the margin `lim`
    /// has) on the values the verification compares with (the spline of coefficients
    /// `verified`); any other row gets `max(limit − room, |value before|·(1 + NOT_WORSE_SLACK))`
    /// — for q', where the span exceeded the velocity limit before (a span touching a fixed
    /// point: by its hull; between movable points: by its exact peak beyond the machine's
    /// limit), at
    /// [`NOT_WORSE_SAMPLES_PER_SPAN`] samples and the spline's vertex of q' before (where
    /// its exact peak is) against that exact peak instead of the hull: it may not get
    /// worse, and need not reach feed (a fixed neighbour may already exceed the limits,
    /// e.g. through the file's own rounding; a span outside the zone's core may be slow by
    /// the program's own doing, far from the pole: `crate::analysis::detect_zones`).
    /// [`RowSet::Core`]: the core's spans only, each at `limit − room`.
    /// [`RowSet::NotWorse`]: every span as a span touching a fixed point (a q' hull within
    /// the limit before may grow to the limit less the room, or to its size before when
    /// that is larger: the start meets every row).
    ///
    /// "Before" is the spline of coefficients `before` (the reference's values, or the
    /// start's). `room[k − lo][r]` ([`Window::rounding_room`]) is what rounding the
    /// written values can add to the (r+1)-th derivative on span k, so the limits still
    /// hold on the values as written; a span beyond its limit before need only not get
    /// worse before rounding: rounding may cost it up to its room, which the verification's
    /// tolerance for such spans absorbs ([`crate::verify::NOT_WORSE_REL`], 10⁻⁴ of the
    /// ratio; the room of a span next to the moving range is about 10⁻⁵ of its value at
    /// the 6 decimals written last). Demanding the room there too made the rows of the
    /// fixed margin contradict each other by that much (they can only move together, with
    /// the range's edge coefficient). The window is constrained but for its last
    /// [`EDGE_SPANS`] spans at each cut end, so that what lies beyond moves by about
    /// 0.27^(window − EDGE_SPANS) of the change only.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn limit_rows(
        &self,
        n: usize,
        cur: &[f64],
        before: &[f64],
        lim: &crate::limits::GeomLimits,
        (verified, machine_lim, pole): (
            &[f64],
            &crate::limits::GeomLimits,
            &std::ops::Range<usize>,
        ),
        room: &[[f64; 3]],
        core: std::ops::Range<usize>,
        set: RowSet,
        (offset, stride): (usize, usize),
        out: &mut Vec<(Row, f64, f64)>,
    ) {
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
        // beyond are fixed in this solve, and verification judges the whole zone (a core
        // reaching before the window panicked on a real Haas UMC program, issue 30).
        let spans =
            a.min(core.start).max(self.lo)..b.max(self.last).max(core.end).max(a + 1).min(self.hi);
        let mut taus = Vec::new();
        let push = |f: &Local, bound: f64, out: &mut Vec<(Row, f64, f64)>| {
            out.push((self.reduce(f, offset, stride), f.at(cur), bound));
        };
        for k in spans.clone() {
            if set == RowSet::Core && !core.contains(&k) {
                continue;
            }
            let sp = &self.spans[k - self.lo];
            let h = sp.h;
            let movable = |i: usize| i >= self.first && i <= self.last;
            let both = movable(k) && movable(k + 1);
            let strict = match set {
                RowSet::Patch => core.contains(&k) || (both && pole.contains(&k)),
                RowSet::Core => true,
                RowSet::NotWorse => false,
            };
            // Between movable points beyond the pole's spans: strict row by row.
            let between = set == RowSet::Patch && both && !strict;
            let room = room.get(k - self.lo).copied().unwrap_or([0.0; 3]);
            // Between movable points beyond the pole's spans, a row that exceeded the
            // machine's own limit on the values the verification compares with (the span
            // was below feed on it, by the program's own doing) need only not get worse.
            let bound = |f: &Local, (limit, machine_limit): (f64, f64), r: usize| {
                let b = limit - room[r];
                let was = f.at(before).abs();
                let b = if strict || (between && f.at(verified).abs() <= machine_limit) {
                    b
                } else {
                    b.max(was * (1.0 + NOT_WORSE_SLACK))
                };
                // Never below a sliver of the limit: the row stays well posed.
                b.max(MIN_ROW_BOUND * limit)
            };
            let (m0, m1, b1) = (sp.at(0.0, 1), sp.at(h, 1), sp.b1());
            let hull_now = [m0, b1, m1]
                .iter()
                .fold(0.0f64, |m, f| m.max(f.at(before).abs()));
            // The exact peak of q' over the span on the coefficients `on`: at the samples
            // and at the spline's vertex of q' (where its peak is, when inside); `taus` gets
            // them.
            let peak_on = |on: &[f64], taus: &mut Vec<f64>| {
                let d1 = |t: f64| sp.at(t, 1).at(on);
                crate::spline::span_offsets(h, NOT_WORSE_SAMPLES_PER_SPAN, taus);
                let (qa, qm, qb) = (d1(0.0), d1(0.5 * h), d1(h));
                // q'(τ) = qa + c1·τ + c2·τ² through the three values.
                let c2 = 2.0 * (qa - 2.0 * qm + qb) / (h * h);
                let c1 = (qb - qa) / h - c2 * h;
                if c2 != 0.0 {
                    let v = -c1 / (2.0 * c2);
                    if v > 0.0 && v < h {
                        taus.push(v);
                    }
                }
                taus.iter().fold(0.0f64, |m, &t| m.max(d1(t).abs()))
            };
            let hull_ok = strict
                || hull_now <= lim.v
                || (between && peak_on(verified, &mut taus) <= machine_lim.v);
            if hull_ok {
                // |q'| ≤ v on the whole span through its Bernstein coefficients (a span
                // within the limit before may only stay within it: "not worse").
                let hull_bound = if set == RowSet::NotWorse {
                    (lim.v - room[0]).max(hull_now * (1.0 + NOT_WORSE_SLACK))
                } else {
                    lim.v - room[0]
                };
                push(&b1, hull_bound.max(MIN_ROW_BOUND * lim.v), out);
            } else {
                // Beyond the limit before: "not worse" on q' against the span's exact peak
                // before (the hull overstates the peak, so it cannot stand for it).
                let peak = peak_on(before, &mut taus);
                let bnd = (lim.v - room[0])
                    .max(peak * (1.0 + NOT_WORSE_SLACK))
                    .max(MIN_ROW_BOUND * lim.v);
                for &tau in taus.iter().filter(|&&t| t > 0.0 && t < h) {
                    push(&sp.at(tau, 1), bnd, out);
                }
            }
            for (f, l, r) in [
                (m0, (lim.v, machine_lim.v), 0),
                (sp.at(0.0, 2), (lim.a, machine_lim.a), 1),
                (sp.at(0.0, 3), (lim.j, machine_lim.j), 2),
            ] {
                push(&f, bound(&f, l, r), out);
            }
            if k + 1 == spans.end {
                for (f, l, r) in [
                    (m1, (lim.v, machine_lim.v), 0),
                    (sp.at(h, 2), (lim.a, machine_lim.a), 1),
                ] {
                    push(&f, bound(&f, l, r), out);
                }
            }
        }
    }
}

/// Which of a window's Equation-6 rows [`Window::limit_rows`] gives, with which bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RowSet {
    /// The joint patch's rows: the core reaches feed; rows within their limit between
    /// movable points stay within it; every other row does not get worse.
    Patch,
    /// The core's rows only, at the limits (a capped solve relaxes them by its elastic).
    Core,
    /// Every span's rows "not worse" (a capped solve holds them: nothing gets slower).
    NotWorse,
}

/// `A⁻¹·B` for `a = [A | B]` (`m × (m + no)`, row-major), `A` square: Gaussian
/// elimination with partial pivoting, in place; `None` when a pivot vanishes (relative
/// to the largest entry of `A`).
fn solve_dense(a: &mut [f64], m: usize, no: usize) -> Option<Vec<f64>> {
    let wd = m + no;
    let scale = a.iter().fold(0.0f64, |x, v| x.max(v.abs()));
    for col in 0..m {
        let piv =
            (col..m).max_by(|&p, &q| a[p * wd + col].abs().total_cmp(&a[q * wd + col].abs()))?;
        if a[piv * wd + col].abs() <= PIVOT_REL_TOL * scale {
            return None;
        }
        if piv != col {
            for j in 0..wd {
                a.swap(piv * wd + j, col * wd + j);
            }
        }
        let d = a[col * wd + col];
        for r in col + 1..m {
            let f = a[r * wd + col] / d;
            if f != 0.0 {
                for j in col..wd {
                    a[r * wd + j] -= f * a[col * wd + j];
                }
            }
        }
    }
    let mut t = vec![0.0; m * no];
    for q in 0..no {
        for r in (0..m).rev() {
            let mut v = a[r * wd + m + q];
            for j in r + 1..m {
                v -= a[r * wd + j] * t[j * no + q];
            }
            t[r * no + q] = v / a[r * wd + r];
        }
    }
    Some(t)
}

/// What the solves of one zone share: the window of each range they constrain (its
/// elimination and rounding room depend on the knots and the range only). Create one per
/// zone (one path); it grows by one entry per range.
#[derive(Debug, Default)]
pub struct WindowMemo {
    entries: std::cell::RefCell<Vec<std::rc::Rc<Window>>>,
}

impl WindowMemo {
    /// The window of `first..=last` on the path `s` (the memo's path), computed once.
    pub(crate) fn get(
        &self,
        s: &[f64],
        first: usize,
        last: usize,
    ) -> Result<std::rc::Rc<Window>, PatchFailure> {
        let same = |w: &Window| {
            w.first == first
                && w.last == last
                && w.knots.len() == w.hi - w.lo + 1
                && w.hi < s.len()
                && w.knots
                    .iter()
                    .zip(&s[w.lo..=w.hi])
                    .all(|(a, b)| a.to_bits() == b.to_bits())
        };
        if let Some(hit) = self.entries.borrow().iter().find(|w| same(w)) {
            return Ok(hit.clone());
        }
        let w = std::rc::Rc::new(Window::new(s, first, last, JOINT_WINDOW_POINTS)?);
        self.entries.borrow_mut().push(w.clone());
        Ok(w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polepatch_bspline::interpolate_not_a_knot;

    /// Uneven knots and non-polynomial data.
    fn data(n: usize) -> (Vec<f64>, Vec<f64>) {
        let s: Vec<f64> = (0..n)
            .map(|i| i as f64 * 0.8 + (i as f64 * 1.3).sin() * 0.2)
            .collect();
        let y = s.iter().map(|t| (t * 1.7).cos() * 10.0 + 3.0 * t).collect();
        (s, y)
    }

    /// Planted response: with the changes of points `first..=last` given, the free
    /// coefficients they determine (one per point: a square system) give the analysis
    /// spline of the changed data — its value, first, second and third derivatives at
    /// points of every span of the window, through the forms the rows use — on windows
    /// inside the path (fixed end slopes), at either end of it and over all of it
    /// (not-a-knot); with no change the unknowns are 0 and the forms are the current
    /// spline's.
    #[test]
    fn window_is_the_spline_of_the_changed_data() {
        let (s, y) = data(60);
        for (first, last, window) in [
            (28, 32, 16),
            (1, 58, 60),
            (1, 30, JOINT_WINDOW_POINTS),
            (40, 58, JOINT_WINDOW_POINTS),
            (40, 59, JOINT_WINDOW_POINTS),
            (2, 3, 30),
            (57, 59, JOINT_WINDOW_POINTS),
            (30, 30, JOINT_WINDOW_POINTS),
        ] {
            let win = Window::new(&s, first, last, window)
                .unwrap_or_else(|e| panic!("{first}..={last}: {e:?}"));
            let nv = win.unknowns();
            assert_eq!(nv, last - first + 1);
            let cur = win.coeffs(&s, &y).unwrap();
            let delta: Vec<f64> = (first..=last)
                .map(|i| (i as f64 * 0.9).sin() * 4.0)
                .collect();
            // The changes' rows: a square system in the unknowns, solved densely.
            let mut rows: Vec<(Vec<f64>, f64)> = Vec::new();
            for (i, d) in (first..=last).zip(&delta) {
                let (row, c) = win.delta(i, &cur, y[i], 0, 1);
                assert!(c.abs() < 1e-9, "the current spline interpolates: {c}");
                let mut r = vec![0.0; nv];
                for (j, v) in row {
                    r[j] += v;
                }
                rows.push((r, d - c));
            }
            let mut a: Vec<f64> = rows.iter().flat_map(|r| r.0.clone()).collect();
            let mut ab = vec![0.0; nv * (nv + 1)];
            for r in 0..nv {
                ab[r * (nv + 1)..r * (nv + 1) + nv].copy_from_slice(&a[r * nv..(r + 1) * nv]);
                ab[r * (nv + 1) + nv] = rows[r].1;
            }
            a.clear();
            let x = solve_dense(&mut ab, nv, 1).expect("nonsingular");
            let mut y2 = y.clone();
            for (i, d) in (first..=last).zip(&delta) {
                y2[i] += d;
            }
            let sp = interpolate_not_a_knot(&s, &y2).unwrap();
            // Inside a window cut from the path the end slopes are fixed: the spline there
            // differs from the whole path's by what a change propagates (≈ 0.27^window).
            let tol = if win.lo > 0 || win.hi < s.len() - 1 {
                1e-6
            } else {
                1e-9
            };
            let at = |f: &Local| {
                let mut row = Vec::new();
                win.reduce_into(f, 0, 1, &mut row);
                f.at(&cur) + row.iter().map(|&(j, v)| v * x[j]).sum::<f64>()
            };
            for k in win.lo..win.hi {
                let sp_k = &win.spans[k - win.lo];
                let h = sp_k.h;
                for tau in [0.0, 0.37 * h, h] {
                    let d = sp.eval_derivs(s[k] + tau);
                    assert!((at(&sp_k.at(tau, 0)) - d[0]).abs() < tol, "{k}: q");
                    assert!((at(&sp_k.at(tau, 1)) - d[1]).abs() < 10.0 * tol, "{k}: q'");
                    assert!(
                        (at(&sp_k.at(tau, 2)) - d[2]).abs() < 100.0 * tol,
                        "{k}: q''"
                    );
                }
                let d3 = sp.eval_derivs(s[k] + 0.5 * h)[3];
                assert!(
                    (at(&sp_k.at(0.0, 3)) - d3).abs() < 1000.0 * tol,
                    "{k}: q'''"
                );
                // b1 is the middle Bernstein coefficient of q': its average is the secant.
                let secant = (y2[k + 1] - y2[k]) / h;
                let avg = (at(&sp_k.at(0.0, 1)) + at(&sp_k.b1()) + at(&sp_k.at(h, 1))) / 3.0;
                assert!((avg - secant).abs() < 10.0 * tol, "{k}: b1");
            }
            // No change: the current spline, which is the analysis spline of y.
            let sp0 = interpolate_not_a_knot(&s, &y).unwrap();
            for k in win.lo..win.hi {
                let f = win.spans[k - win.lo].at(0.0, 1);
                assert!((f.at(&cur) - sp0.eval_derivs(s[k])[1]).abs() < 1e-6);
            }
        }
    }

    /// With an offset and a stride, free coefficient r is unknown `offset + stride·r`
    /// and nothing else changes.
    #[test]
    fn offset_and_stride() {
        let (s, _) = data(50);
        let win = Window::new(&s, 20, 30, JOINT_WINDOW_POINTS).unwrap();
        assert_eq!(win.unknowns(), 11);
        for sp in &win.spans {
            for f in [sp.at(0.0, 3), sp.b1(), sp.at(0.0, 1)] {
                let (a, b) = (win.reduce(&f, 0, 1), win.reduce(&f, 1, 2));
                let moved: Row = a.iter().map(|&(j, v)| (1 + 2 * j, v)).collect();
                assert_eq!(moved, b);
            }
        }
    }

    /// Regression (issue 30, a real Haas UMC program with `--cone 7.5`): a core wider than
    /// the window, with spans before its first knot, indexed below the window; its rows are
    /// those of the window's spans only.
    #[test]
    fn a_core_wider_than_the_window_is_clipped_to_it() {
        let (s, y) = data(60);
        let win = Window::new(&s, 28, 32, 16).unwrap();
        let cur = win.coeffs(&s, &y).unwrap();
        let lim = crate::limits::GeomLimits {
            v: 1.0,
            a: 1.0,
            j: 1.0,
        };
        let room = vec![[0.0; 3]; win.hi - win.lo + 1];
        let mut out = Vec::new();
        win.limit_rows(
            s.len(),
            &cur,
            &y,
            &lim,
            (&y, &lim, &(0..60)),
            &room,
            0..59,
            RowSet::Patch,
            (0, 1),
            &mut out,
        );
        assert!(!out.is_empty());
    }
}
