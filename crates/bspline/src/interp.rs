//! Cubic interpolation: not-a-knot (the analysis spline) and clamped.
//!
//! Both are solved in B-spline form. With data parameters `s_0 < … < s_{n−1}`:
//!
//! * **Not-a-knot** (SPEC §2): knots `[s_0 ×4, s_2, …, s_{n−3}, s_{n−1} ×4]`
//!   ([`crate::knots::not_a_knot`]), `n` control points `c`, and the collocation system
//!   `Σ_j B_j(s_i)·c_j = y_i`. Row 0 is `c_0 = y_0`, row n−1 is `c_{n−1} = y_{n−1}`, the
//!   rows at interior knots have 3 non-zeros `(i−1, i, i+1)` and the rows at `s_1`,
//!   `s_{n−2}` (inside the first and last span) 4: a band matrix with 2 sub- and 2
//!   super-diagonals, factored by the crate's banded LU without pivoting (the matrix is
//!   totally positive; see `banded.rs`). Leaving out `s_1` and `s_{n−2}` as knots is exactly
//!   the not-a-knot condition (the third derivative is continuous there), so this is the
//!   same curve as `scipy.interpolate.CubicSpline(s, y)`.
//! * **Clamped**: knots `clamped_cubic(s)`, `n + 2` control points; the two extra
//!   equations are the end slopes `3(c_1 − c_0)/(s_1 − s_0) = d0` and
//!   `3(c_{n+1} − c_n)/(s_{n−1} − s_{n−2}) = dn`.
//!
//! n = 2 and n = 3 have no not-a-knot spline proper; like scipy we return the line and the
//! parabola through the points, written as one cubic Bézier span on `[s_0, s_{n−1}]`.
//!
//! The not-a-knot interpolant is linear in the data: `f(t) = Σ_i m_i(t)·y_i`.
//! [`NotAKnotSystem`] factors the system once for given `s` and then solves for any number
//! of data vectors (`solve`, `response`) or gives the weights `m_i(t)` of a value or
//! derivative at `t` directly (`data_row`, one transposed banded solve): the patcher's QP
//! constraints on the analysis spline's derivatives as linear functions of the C values.

use crate::banded::{BandedLu, W};
use crate::cox_de_boor::{basis_funs, ders_basis, find_span};
use crate::error::SplineError;
use crate::knots::{clamped_cubic, not_a_knot};
use crate::spline::BSpline;

/// The interpolating cubic spline through `(s[i], y[i])` with not-a-knot end conditions —
/// the same curve as `scipy.interpolate.CubicSpline(s, y)` (its default `bc_type`).
/// n = 2 gives the line and n = 3 the parabola through the points (as scipy); n < 2 is an
/// error, as are non-increasing or non-finite input.
///
/// The result has degree 3 and knots [`crate::knots::not_a_knot`]`(s)`. Cost O(n): a
/// banded solve (about 0.1 µs per point, see `docs/bspline.md`). To interpolate many data
/// vectors on the same `s`, use [`NotAKnotSystem`].
pub fn interpolate_not_a_knot(s: &[f64], y: &[f64]) -> Result<BSpline, SplineError> {
    check_lengths(s, y)?;
    NotAKnotSystem::new(s)?.solve(y)
}

/// The interpolating cubic spline through `(s[i], y[i])` with first derivatives `d0` at
/// `s[0]` and `dn` at `s[n-1]` (n ≥ 2).
///
/// The result has degree 3, knots [`crate::knots::clamped_cubic`]`(s)` and `n + 2`
/// control points. Errors as for [`interpolate_not_a_knot`]; a non-finite `d0` or `dn`
/// is [`SplineError::NotFinite`] with `what = "d0"` or `"dn"`.
pub fn interpolate_clamped(s: &[f64], y: &[f64], d0: f64, dn: f64) -> Result<BSpline, SplineError> {
    check_lengths(s, y)?;
    check_params(s)?;
    check_finite("y", y)?;
    check_finite("d0", &[d0])?;
    check_finite("dn", &[dn])?;
    let n = s.len();
    let knots = clamped_cubic(s);
    let m = n + 2;
    let mut rows = vec![[0.0; W]; m];
    let mut rhs = vec![0.0; m];
    // c_0 = y_0 and the start slope.
    rows[0][2] = 1.0;
    rhs[0] = y[0];
    let h0 = s[1] - s[0];
    rows[1][1] = -3.0 / h0;
    rows[1][2] = 3.0 / h0;
    rhs[1] = d0;
    // Interior data: s_i = knots[i + 3], span i + 3, columns i..=i+3 (the last is 0).
    for i in 1..n - 1 {
        let r = i + 1;
        let b = basis_funs(&knots, 3, i + 3, s[i]);
        for (k, &bk) in b.iter().enumerate() {
            let d = i + k + 2 - r;
            if d < W {
                rows[r][d] = bk;
            }
        }
        rhs[r] = y[i];
    }
    // The end slope and c_{n+1} = y_{n-1}.
    let hn = s[n - 1] - s[n - 2];
    rows[n][2] = -3.0 / hn;
    rows[n][3] = 3.0 / hn;
    rhs[n] = dn;
    rows[n + 1][2] = 1.0;
    rhs[n + 1] = y[n - 1];
    let lu = BandedLu::factor(rows).map_err(|k| SplineError::Singular {
        what: format!("clamped interpolation system has a zero pivot at row {k}"),
    })?;
    lu.solve_in_place(&mut rhs);
    finish(knots, rhs)
}

/// The not-a-knot interpolation system for fixed parameters `s`, factored once: solve it
/// for many data vectors, or get the interpolant's value or derivative at a parameter as
/// a linear function of the data.
///
/// ```
/// use polepatch_bspline::interp::NotAKnotSystem;
/// let s = [0.0, 1.0, 2.5, 3.0, 4.5];
/// let sys = NotAKnotSystem::new(&s)?;
/// let f = sys.solve(&[0.0, 1.0, 0.0, -1.0, 2.0])?;
/// // f''(0.7) as weights on the data values:
/// let m = sys.data_row(0.7, 2);
/// let y = [0.0, 1.0, 0.0, -1.0, 2.0];
/// let via_row: f64 = m.iter().zip(&y).map(|(m, y)| m * y).sum();
/// assert!((via_row - f.eval_derivs(0.7)[2]).abs() < 1e-12);
/// # Ok::<(), polepatch_bspline::SplineError>(())
/// ```
#[derive(Debug, Clone)]
pub struct NotAKnotSystem {
    knots: Vec<f64>,
    n: usize,
    kind: Kind,
}

#[derive(Debug, Clone)]
enum Kind {
    /// n = 2 or 3: the Bézier control points are `c = M·y` (4 × n, n ≤ 3).
    Small([[f64; 3]; 4]),
    /// n ≥ 4: the factored collocation matrix.
    Banded(BandedLu),
}

impl NotAKnotSystem {
    /// Check `s` (n ≥ 2, finite, strictly increasing) and factor the collocation matrix.
    pub fn new(s: &[f64]) -> Result<NotAKnotSystem, SplineError> {
        check_params(s)?;
        let n = s.len();
        let knots = not_a_knot(s);
        let kind = if n < 4 {
            Kind::Small(small_map(s)?)
        } else {
            let mut rows = vec![[0.0; W]; n];
            rows[0][2] = 1.0;
            rows[n - 1][2] = 1.0;
            for (i, row) in rows.iter_mut().enumerate().take(n - 1).skip(1) {
                let span = (i + 2).clamp(3, n - 1);
                if (2..n - 2).contains(&i) {
                    // s_i is the knot u_j (j = span): the three cubics alive there in closed
                    // form (2 divisions instead of the recurrence's 6).
                    let u = &knots[span - 2..span + 3];
                    let (um2, um1, u0, u1, u2) = (u[0], u[1], u[2], u[3], u[4]);
                    let w = u1 - um1;
                    let n0 = (u1 - u0) * (u1 - u0) / ((u1 - um2) * w);
                    let n2 = (u0 - um1) * (u0 - um1) / ((u2 - um1) * w);
                    *row = [0.0, n0, 1.0 - n0 - n2, n2, 0.0];
                    continue;
                }
                let b = basis_funs(&knots, 3, span, s[i]);
                for (k, &bk) in b.iter().enumerate() {
                    // Column span − 3 + k; band offset column − i + 2.
                    let d = (span + k + 2).wrapping_sub(i + 3);
                    if d < W {
                        row[d] = bk;
                    } else {
                        debug_assert_eq!(bk, 0.0, "entry outside the band");
                    }
                }
            }
            Kind::Banded(BandedLu::factor(rows).map_err(|k| SplineError::Singular {
                what: format!("not-a-knot system has a zero pivot at row {k}"),
            })?)
        };
        Ok(NotAKnotSystem { knots, n, kind })
    }

    /// Number of data points.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Always false (a system has at least 2 points); for symmetry with `len`.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The knot vector of every interpolant ([`crate::knots::not_a_knot`] of `s`).
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The not-a-knot interpolant of the data `y` (same length as `s`, finite).
    pub fn solve(&self, y: &[f64]) -> Result<BSpline, SplineError> {
        if y.len() != self.n {
            return Err(SplineError::LengthMismatch {
                what: format!("{} values for {} parameters", y.len(), self.n),
            });
        }
        check_finite("y", y)?;
        let coeffs = match &self.kind {
            Kind::Small(m) => m
                .iter()
                .map(|row| row[..self.n].iter().zip(y).map(|(a, b)| a * b).sum())
                .collect(),
            Kind::Banded(lu) => {
                let mut c = y.to_vec();
                lu.solve_in_place(&mut c);
                c
            }
        };
        finish(self.knots.clone(), coeffs)
    }

    /// The interpolant of the unit vector `e_index` (1 at `s[index]`, 0 elsewhere): the
    /// cardinal function `m_index(t)`. `index ≥ n` is a [`SplineError::LengthMismatch`].
    pub fn response(&self, index: usize) -> Result<BSpline, SplineError> {
        if index >= self.n {
            return Err(SplineError::LengthMismatch {
                what: format!("index {index} out of range for {} points", self.n),
            });
        }
        let mut y = vec![0.0; self.n];
        y[index] = 1.0;
        self.solve(&y)
    }

    /// The weights `m_i` with `f^(order)(t) = Σ_i m_i·y_i` for the interpolant `f` of any
    /// data `y` (order 0..=3; higher orders give zeros). Outside `[s_0, s_{n−1}]` the end
    /// pieces are extended, as in evaluation.
    ///
    /// Computed as `m = A⁻ᵀ b(t)` with `b(t)` the [`crate::BasisRow`] at `t`: one
    /// transposed banded solve, O(n).
    pub fn data_row(&self, t: f64, order: usize) -> Vec<f64> {
        let nc = self.knots.len() - 4;
        let span = find_span(&self.knots, 3, nc, t);
        let first = span - 3;
        let mut b = [0.0; 4];
        if order <= 3 {
            b = ders_basis(&self.knots, 3, span, t)[order];
        }
        match &self.kind {
            Kind::Small(m) => (0..self.n)
                .map(|j| (0..4).map(|k| b[k] * m[k][j]).sum())
                .collect(),
            Kind::Banded(lu) => {
                let mut z = vec![0.0; self.n];
                z[first..first + 4].copy_from_slice(&b);
                lu.solve_transpose_in_place(&mut z);
                z
            }
        }
    }

    /// [`NotAKnotSystem::data_row`] computed only where it is not negligible: the weights
    /// `m_i` for `i` in `start..start + out.len()` (the returned `start`; `out` is cleared
    /// first), every weight outside taken as zero. Cost O(1) in the number of points
    /// instead of O(n).
    ///
    /// The solve stops where the entries fall below [`DATA_ROW_TOL`] of the largest, and
    /// the entries left out decrease away from `t`: any weighted sum `Σ_i m_i·y_i` or
    /// `Σ |m_i|` over the row is that of [`NotAKnotSystem::data_row`] to a few
    /// `DATA_ROW_TOL` of its largest term (each weight within 10⁻¹⁶ of the largest,
    /// tested), at the rounding of a double. How far the row reaches depends on the knots
    /// (about 32 points either side of `t` on even knots, see [`DATA_ROW_TOL`]); the test
    /// `local_data_rows_match_the_full_ones` checks it on uneven knots and at both ends.
    pub fn data_row_local(&self, t: f64, order: usize, out: &mut Vec<f64>) -> usize {
        let nc = self.knots.len() - 4;
        let span = find_span(&self.knots, 3, nc, t);
        let first = span - 3;
        let mut b = [0.0; 4];
        if order <= 3 {
            b = ders_basis(&self.knots, 3, span, t)[order];
        }
        match &self.kind {
            Kind::Small(_) => {
                out.clear();
                out.extend(self.data_row(t, order));
                0
            }
            Kind::Banded(lu) => lu.solve_transpose_local(first, &b, DATA_ROW_TOL, out),
        }
    }
}

pub use crate::tolerances::DATA_ROW_TOL;

/// For n = 2, 3: the map from data to the Bézier control points of the line / parabola
/// through the points on `[s_0, s_{n−1}]`: `P0 = f(s_0)`, `P1 = f(s_0) + h·f'(s_0)/3`,
/// `P2 = f(s_e) − h·f'(s_e)/3`, `P3 = f(s_e)`.
fn small_map(s: &[f64]) -> Result<[[f64; 3]; 4], SplineError> {
    let n = s.len();
    let (a, e) = (s[0], s[n - 1]);
    let h = e - a;
    // Lagrange derivative weights at x.
    let dl = |x: f64| -> [f64; 3] {
        let mut w = [0.0; 3];
        for j in 0..n {
            let mut num = 0.0;
            for m in (0..n).filter(|&m| m != j) {
                num += (0..n)
                    .filter(|&l| l != j && l != m)
                    .map(|l| x - s[l])
                    .product::<f64>();
            }
            let den: f64 = (0..n).filter(|&l| l != j).map(|l| s[j] - s[l]).product();
            w[j] = num / den;
        }
        w
    };
    let (da, de) = (dl(a), dl(e));
    let mut m = [[0.0; 3]; 4];
    m[0][0] = 1.0;
    m[3][n - 1] = 1.0;
    for j in 0..n {
        m[1][j] = m[0][j] + h * da[j] / 3.0;
        m[2][j] = m[3][j] - h * de[j] / 3.0;
    }
    if m.iter().flatten().any(|v| !v.is_finite()) {
        return Err(SplineError::Singular {
            what: format!("parameters {s:?} are too close to interpolate"),
        });
    }
    Ok(m)
}

/// Wrap solved control points, refusing a non-finite result (overflow on extreme input).
fn finish(knots: Vec<f64>, coeffs: Vec<f64>) -> Result<BSpline, SplineError> {
    if let Some(i) = coeffs.iter().position(|c| !c.is_finite()) {
        return Err(SplineError::Singular {
            what: format!(
                "interpolation overflowed: control point {i} is {}",
                coeffs[i]
            ),
        });
    }
    Ok(BSpline::from_parts_unchecked(3, knots, coeffs))
}

pub(crate) fn check_lengths(s: &[f64], y: &[f64]) -> Result<(), SplineError> {
    if s.len() != y.len() {
        return Err(SplineError::LengthMismatch {
            what: format!("{} parameters s but {} values y", s.len(), y.len()),
        });
    }
    Ok(())
}

pub(crate) fn check_finite(what: &'static str, v: &[f64]) -> Result<(), SplineError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(SplineError::NotFinite {
            what,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

/// n ≥ 2, finite, strictly increasing.
fn check_params(s: &[f64]) -> Result<(), SplineError> {
    if s.len() < 2 {
        return Err(SplineError::TooFewPoints {
            needed: 2,
            got: s.len(),
        });
    }
    check_finite("s", s)?;
    if let Some(index) = (1..s.len()).find(|&i| s[i] <= s[i - 1]) {
        return Err(SplineError::NotIncreasing {
            index,
            value: s[index],
            previous: s[index - 1],
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubic(t: f64) -> [f64; 4] {
        // 2 − 3t + 0.5t² + 0.25t³
        [
            2.0 - 3.0 * t + 0.5 * t * t + 0.25 * t * t * t,
            -3.0 + t + 0.75 * t * t,
            1.0 + 1.5 * t,
            1.5,
        ]
    }

    fn uneven(n: usize) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let x = i as f64;
                x + 0.3 * (1.7 * x).sin()
            })
            .collect()
    }

    fn assert_close(got: [f64; 4], want: [f64; 4], tol: f64, what: &str) {
        for k in 0..4 {
            assert!(
                (got[k] - want[k]).abs() <= tol * (1.0 + want[k].abs()),
                "{what} derivative {k}: {} vs {}",
                got[k],
                want[k]
            );
        }
    }

    #[test]
    fn not_a_knot_reproduces_cubics_exactly() {
        for n in [4, 5, 6, 9, 50] {
            let s = uneven(n);
            let y: Vec<f64> = s.iter().map(|&t| cubic(t)[0]).collect();
            let f = interpolate_not_a_knot(&s, &y).unwrap();
            let (a, b) = (s[0], s[n - 1]);
            let mut ts: Vec<f64> = (0..=200)
                .map(|i| a - 1.0 + (b - a + 2.0) * i as f64 / 200.0)
                .collect();
            ts.extend(&s);
            for t in ts {
                assert_close(f.eval_derivs(t), cubic(t), 1e-9, &format!("n={n} t={t}"));
            }
        }
    }

    #[test]
    fn clamped_reproduces_cubics_exactly() {
        for n in [2, 3, 4, 7, 30] {
            let s = uneven(n);
            let y: Vec<f64> = s.iter().map(|&t| cubic(t)[0]).collect();
            let f = interpolate_clamped(&s, &y, cubic(s[0])[1], cubic(s[n - 1])[1]).unwrap();
            assert_eq!(f.coeffs().len(), n + 2);
            for i in 0..=100 {
                let t = s[0] - 0.5 + (s[n - 1] - s[0] + 1.0) * i as f64 / 100.0;
                assert_close(f.eval_derivs(t), cubic(t), 1e-9, &format!("n={n} t={t}"));
            }
        }
    }

    #[test]
    fn clamped_takes_the_given_end_slopes() {
        let s = [0.0, 1.0, 3.0];
        let y = [1.0, 0.0, 2.0];
        let f = interpolate_clamped(&s, &y, 5.0, -2.0).unwrap();
        assert!((f.eval_derivs(0.0)[1] - 5.0).abs() < 1e-12);
        assert!((f.eval_derivs(3.0)[1] + 2.0).abs() < 1e-12);
        for (t, v) in s.iter().zip(y) {
            assert!((f.eval(*t) - v).abs() < 1e-12);
        }
    }

    #[test]
    fn two_points_give_the_line_three_the_parabola() {
        let f = interpolate_not_a_knot(&[1.0, 3.0], &[2.0, 6.0]).unwrap();
        assert_close(f.eval_derivs(2.5), [5.0, 2.0, 0.0, 0.0], 1e-12, "line");
        assert_close(
            f.eval_derivs(-1.0),
            [-2.0, 2.0, 0.0, 0.0],
            1e-12,
            "line outside",
        );
        let s = [0.0, 0.5, 2.0];
        let p = |t: f64| [1.0 - 2.0 * t + 3.0 * t * t, -2.0 + 6.0 * t, 6.0, 0.0];
        let y: Vec<f64> = s.iter().map(|&t| p(t)[0]).collect();
        let f = interpolate_not_a_knot(&s, &y).unwrap();
        for t in [-0.3, 0.0, 0.25, 0.5, 1.9, 2.0, 2.4] {
            assert_close(f.eval_derivs(t), p(t), 1e-12, "parabola");
        }
    }

    #[test]
    fn interpolates_the_data_and_is_c2_with_c3_at_the_not_knots() {
        let s = uneven(12);
        let y: Vec<f64> = s.iter().map(|t| (0.8 * t).cos() * 40.0).collect();
        let f = interpolate_not_a_knot(&s, &y).unwrap();
        for (t, v) in s.iter().zip(&y) {
            assert!((f.eval(*t) - v).abs() < 1e-11);
        }
        let e = 1e-9;
        for (i, &t) in s.iter().enumerate().take(11).skip(1) {
            let (l, r) = (f.eval_derivs(t - e), f.eval_derivs(t + e));
            for k in 0..3 {
                assert!((l[k] - r[k]).abs() < 1e-6, "C2 at s[{i}], order {k}");
            }
            if i == 1 || i == 10 {
                assert!(
                    (l[3] - r[3]).abs() < 1e-6,
                    "third derivative continuous at s[{i}]"
                );
            }
        }
    }

    #[test]
    fn system_solves_many_right_hand_sides_and_data_rows_match() {
        for n in [2, 3, 4, 5, 20] {
            let s = uneven(n);
            let sys = NotAKnotSystem::new(&s).unwrap();
            assert_eq!(sys.len(), n);
            assert!(!sys.is_empty());
            let y: Vec<f64> = s.iter().map(|t| (1.3 * t).sin() + 0.1 * t).collect();
            let f = sys.solve(&y).unwrap();
            assert_eq!(f, interpolate_not_a_knot(&s, &y).unwrap());
            // Superposition of responses.
            let responses: Vec<BSpline> = (0..n).map(|i| sys.response(i).unwrap()).collect();
            for &t in &[
                s[0] - 0.5,
                s[0],
                0.5 * (s[0] + s[n - 1]),
                s[n - 1],
                s[n - 1] + 1.0,
            ] {
                let want = f.eval_derivs(t);
                for order in 0..4 {
                    let row = sys.data_row(t, order);
                    let via_row: f64 = row.iter().zip(&y).map(|(m, y)| m * y).sum();
                    let via_resp: f64 = responses
                        .iter()
                        .zip(&y)
                        .map(|(r, y)| r.eval_derivs(t)[order] * y)
                        .sum();
                    let tol = 1e-10 * (1.0 + want[order].abs());
                    assert!(
                        (via_row - want[order]).abs() < tol,
                        "n={n} t={t} order={order}"
                    );
                    assert!((via_resp - want[order]).abs() < tol);
                }
                assert!(sys.data_row(t, 4).iter().all(|&m| m == 0.0));
            }
            assert!(matches!(
                sys.response(n),
                Err(SplineError::LengthMismatch { .. })
            ));
            assert!(matches!(
                sys.solve(&y[1..]),
                Err(SplineError::LengthMismatch { .. })
            ));
        }
    }

    /// The local data rows against the full ones (`data_row`), on even knots and on knots
    /// whose spacing varies by up to 400× (random, and a fine stretch between coarse
    /// ones), at parameters all along the path and within a few knots of both ends (and
    /// outside them), every order: each weight within 100·`DATA_ROW_TOL` = 10⁻¹⁶ of the
    /// row's largest (the weights next to the cut carry the left-out tail, amplified by a
    /// few units through the two sweeps: measured up to about 6·`DATA_ROW_TOL`), the ℓ1
    /// norm over a range agreeing to rounding, and the row reaching a bounded number of
    /// knots whatever n.
    #[test]
    fn local_data_rows_match_the_full_ones() {
        let mut x = 0x2545_F491_4F6C_DD1Du64;
        let mut r = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut paths: Vec<Vec<f64>> = Vec::new();
        for n in [4, 5, 6, 9, 40, 400] {
            paths.push((0..n).map(|i| i as f64 * 0.5).collect());
            paths.push(uneven(n));
            let mut s = vec![0.0];
            for _ in 1..n {
                let h = (r() * 6.0 - 3.0).exp(); // 0.05 … 20
                s.push(s.last().unwrap() + h);
            }
            paths.push(s);
        }
        // Fine and coarse stretches (0.01 mm next to 4 mm).
        paths.push(
            (0..300)
                .scan(0.0, |acc, i| {
                    *acc += if (100..200).contains(&i) { 0.01 } else { 4.0 };
                    Some(*acc)
                })
                .collect(),
        );
        let mut local = Vec::new();
        let mut longest = 0;
        for s in &paths {
            let n = s.len();
            let sys = NotAKnotSystem::new(s).unwrap();
            let mut ts: Vec<f64> = vec![s[0] - 0.3, s[n - 1] + 0.3];
            for k in 0..n - 1 {
                if k < 5 || k + 6 > n || k % 7 == 0 {
                    let h = s[k + 1] - s[k];
                    ts.extend([s[k], s[k] + 0.37 * h, s[k] + h]);
                }
            }
            for &t in &ts {
                for order in 0..4 {
                    let full = sys.data_row(t, order);
                    let start = sys.data_row_local(t, order, &mut local);
                    assert!(start + local.len() <= n);
                    longest = longest.max(local.len());
                    let peak = full.iter().fold(0.0f64, |m, w| m.max(w.abs()));
                    for (i, &f) in full.iter().enumerate() {
                        let l = if (start..start + local.len()).contains(&i) {
                            local[i - start]
                        } else {
                            0.0
                        };
                        assert!(
                            (l - f).abs() <= 100.0 * DATA_ROW_TOL * peak + 1e-15 * f.abs(),
                            "n={n} t={t} order={order} i={i}: {l} vs {f} (peak {peak})"
                        );
                    }
                    // ℓ1 over a range, as the rounding gains take it.
                    let (a, b) = (n / 3, 2 * n / 3);
                    let l1_full: f64 = full[a..=b].iter().map(|w| w.abs()).sum();
                    let l1_local: f64 = (a..=b)
                        .filter(|i| (start..start + local.len()).contains(i))
                        .map(|i| local[i - start].abs())
                        .sum();
                    assert!(
                        (l1_full - l1_local).abs() <= 1e-15 * l1_full + 100.0 * DATA_ROW_TOL * peak,
                        "n={n} t={t} order={order}: ℓ1 {l1_local} vs {l1_full}"
                    );
                }
            }
        }
        // Local: on 400 points the row reaches far fewer (about 2·32 + 4 on even knots).
        assert!(longest < 200, "a local row spans {longest} weights");
    }

    #[test]
    fn degenerate_input_is_a_clear_error() {
        use SplineError::*;
        let e = |s: &[f64], y: &[f64]| interpolate_not_a_knot(s, y).unwrap_err();
        assert_eq!(e(&[], &[]), TooFewPoints { needed: 2, got: 0 });
        assert_eq!(e(&[1.0], &[1.0]), TooFewPoints { needed: 2, got: 1 });
        assert!(matches!(e(&[0.0, 1.0], &[1.0]), LengthMismatch { .. }));
        assert_eq!(
            e(&[0.0, 1.0, 1.0, 2.0], &[0.0; 4]),
            NotIncreasing {
                index: 2,
                value: 1.0,
                previous: 1.0
            }
        );
        assert_eq!(
            e(&[0.0, 2.0, 1.0, 3.0, 4.0], &[0.0; 5]),
            NotIncreasing {
                index: 2,
                value: 1.0,
                previous: 2.0
            }
        );
        assert!(matches!(
            e(&[1.0, 1.0], &[0.0; 2]),
            NotIncreasing { index: 1, .. }
        ));
        assert!(matches!(
            e(&[0.0, 1.0, 1.0], &[0.0; 3]),
            NotIncreasing { index: 2, .. }
        ));
        assert!(matches!(
            e(&[0.0, f64::NAN, 2.0, 3.0], &[0.0; 4]),
            NotFinite {
                what: "s",
                index: 1,
                ..
            }
        ));
        assert!(matches!(
            e(&[0.0, 1.0, 2.0, 3.0], &[0.0, 0.0, f64::INFINITY, 0.0]),
            NotFinite {
                what: "y",
                index: 2,
                ..
            }
        ));
        assert!(matches!(
            e(&[0.0, 1.0, 2.0], &[f64::NAN, 0.0, 0.0]),
            NotFinite {
                what: "y",
                index: 0,
                ..
            }
        ));
        let c = |s: &[f64], y: &[f64], d0, dn| interpolate_clamped(s, y, d0, dn).unwrap_err();
        assert!(matches!(c(&[0.0], &[0.0], 0.0, 0.0), TooFewPoints { .. }));
        assert!(matches!(
            c(&[0.0, 0.0], &[0.0; 2], 0.0, 0.0),
            NotIncreasing { .. }
        ));
        assert!(matches!(
            c(&[0.0, 1.0], &[0.0; 2], f64::NAN, 0.0),
            NotFinite { what: "d0", .. }
        ));
        assert!(matches!(
            c(&[0.0, 1.0], &[0.0; 2], 0.0, f64::NEG_INFINITY),
            NotFinite { what: "dn", .. }
        ));
        // Overflow is an error, never a silent NaN or infinity.
        let r = interpolate_not_a_knot(&[0.0, 1e-300, 1.0, 2.0], &[0.0, 1e300, -1e300, 0.0]);
        if let Ok(f) = r {
            assert!(f.coeffs().iter().all(|c| c.is_finite()));
        }
        let r = interpolate_not_a_knot(&[0.0, 5e-324, 1.0], &[0.0, 1.0, 0.0]);
        assert!(matches!(r, Err(Singular { .. })), "{r:?}");
    }
}
