//! Weighted least-squares fit with given knots.
//!
//! With `B` the m × N collocation matrix `B[i][j] = B_j(s_i)` and `W = diag(w)`, the
//! control points minimise `‖W^{1/2}(B c − y)‖²`. We solve it by a Householder QR of
//! `W^{1/2} B` (faer's dense `Qr`), not by the normal equations, which would square the
//! condition number. Rank deficiency (a control point that no weighted datum reaches,
//! the Schoenberg–Whitney condition failing) shows as a negligible diagonal entry of R
//! and is reported as [`SplineError::Singular`].

use faer::Mat;
use faer::linalg::solvers::SolveLstsq;

use crate::cox_de_boor::{basis_funs, find_span};
use crate::error::SplineError;
use crate::interp::{check_finite, check_lengths};
use crate::spline::{BSpline, check_knots};

pub use crate::tolerances::RANK_TOLERANCE;

/// The cubic spline on `knots` (clamped, as from [`crate::knots::clamped_cubic`]) minimising
/// `Σ w[i]·(f(s[i]) − y[i])²`; `w = None` means all ones.
///
/// `s` need not be sorted; data outside the knots' domain are fitted by the extended end
/// pieces. Weights must be finite and ≥ 0 (zero drops the datum). Any valid cubic knot
/// vector is accepted (see [`BSpline::new`]). Errors: length mismatches, non-finite or
/// negative input, fewer positively weighted data than control points
/// ([`SplineError::TooFewPoints`]), or data that do not determine every control point
/// ([`SplineError::Singular`]).
pub fn fit_least_squares(
    s: &[f64],
    y: &[f64],
    w: Option<&[f64]>,
    knots: &[f64],
) -> Result<BSpline, SplineError> {
    check_lengths(s, y)?;
    check_finite("s", s)?;
    check_finite("y", y)?;
    if let Some(w) = w {
        if w.len() != s.len() {
            return Err(SplineError::LengthMismatch {
                what: format!("{} weights for {} data points", w.len(), s.len()),
            });
        }
        check_finite("w", w)?;
        if let Some(index) = w.iter().position(|&x| x < 0.0) {
            return Err(SplineError::NegativeWeight {
                index,
                value: w[index],
            });
        }
    }
    if knots.len() < 8 {
        return Err(SplineError::InvalidKnots {
            what: format!("{} knots; a cubic needs at least 8", knots.len()),
        });
    }
    check_knots(knots, 3)?;
    let nc = knots.len() - 4;
    let weight = |i: usize| w.map_or(1.0, |w| w[i]);
    let rows: Vec<usize> = (0..s.len()).filter(|&i| weight(i) > 0.0).collect();
    if rows.len() < nc {
        return Err(SplineError::TooFewPoints {
            needed: nc,
            got: rows.len(),
        });
    }
    let m = rows.len();
    let mut a = Mat::<f64>::zeros(m, nc);
    let mut rhs = Mat::<f64>::zeros(m, 1);
    for (r, &i) in rows.iter().enumerate() {
        let sw = weight(i).sqrt();
        let span = find_span(knots, 3, nc, s[i]);
        let b = basis_funs(knots, 3, span, s[i]);
        for (k, bk) in b.iter().enumerate() {
            a[(r, span - 3 + k)] = sw * bk;
        }
        rhs[(r, 0)] = sw * y[i];
    }
    let qr = a.qr();
    let rdiag: Vec<f64> = {
        let r = qr.thin_R();
        (0..nc).map(|j| r[(j, j)].abs()).collect()
    };
    let rmax = rdiag.iter().cloned().fold(0.0, f64::max);
    if let Some(j) = rdiag
        .iter()
        .position(|&d| !d.is_finite() || d <= RANK_TOLERANCE * rmax)
    {
        return Err(SplineError::Singular {
            what: format!(
                "the data do not determine control point {j} (support [{}, {}])",
                knots[j],
                knots[j + 4]
            ),
        });
    }
    let c = qr.solve_lstsq(&rhs);
    let coeffs: Vec<f64> = (0..nc).map(|j| c[(j, 0)]).collect();
    if let Some(j) = coeffs.iter().position(|c| !c.is_finite()) {
        return Err(SplineError::Singular {
            what: format!("least squares overflowed at control point {j}"),
        });
    }
    Ok(BSpline::from_parts_unchecked(3, knots.to_vec(), coeffs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::knots::clamped_cubic;

    fn planted() -> BSpline {
        BSpline::new(
            3,
            clamped_cubic(&[0.0, 1.0, 1.5, 3.0, 4.0]),
            vec![2.0, -1.0, 0.5, 3.0, 1.0, 0.0, 4.0],
        )
        .unwrap()
    }

    #[test]
    fn recovers_a_spline_exactly_when_the_data_lie_on_it() {
        let f = planted();
        let s: Vec<f64> = (0..60).map(|i| 4.0 * (i as f64 / 59.0).powf(1.3)).collect();
        let y: Vec<f64> = s.iter().map(|&t| f.eval(t)).collect();
        let w: Vec<f64> = (0..60).map(|i| 0.5 + (i % 3) as f64).collect();
        for w in [None, Some(&w[..])] {
            let g = fit_least_squares(&s, &y, w, f.knots()).unwrap();
            for (a, b) in g.coeffs().iter().zip(f.coeffs()) {
                assert!((a - b).abs() < 1e-10, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn weights_pull_the_fit_and_zero_weights_drop_data() {
        // Fit a single cubic (4 control points) to 5 points, one an outlier.
        let knots = clamped_cubic(&[0.0, 4.0]);
        let s = [0.0, 1.0, 2.0, 3.0, 4.0];
        let y = [0.0, 1.0, 8.0, 27.0, 100.0];
        let w_drop = [1.0, 1.0, 1.0, 1.0, 0.0];
        let g = fit_least_squares(&s, &y, Some(&w_drop), &knots).unwrap();
        // Without the last point the cubic t³ fits exactly.
        for t in [0.5, 2.5, 4.0] {
            assert!((g.eval(t) - t * t * t).abs() < 1e-10);
        }
        let heavy = [1.0, 1.0, 1.0, 1.0, 1e6];
        let light = [1.0; 5];
        let gh = fit_least_squares(&s, &y, Some(&heavy), &knots).unwrap();
        let gl = fit_least_squares(&s, &y, Some(&light), &knots).unwrap();
        assert!((gh.eval(4.0) - 100.0).abs() < (gl.eval(4.0) - 100.0).abs());
        // Residual is orthogonal to the basis (normal equations hold).
        for j in 0..4 {
            let e: Vec<f64> = (0..4).map(|k| if k == j { 1.0 } else { 0.0 }).collect();
            let bj = BSpline::new(3, knots.clone(), e).unwrap();
            let dot: f64 = s
                .iter()
                .zip(&y)
                .map(|(&t, &v)| bj.eval(t) * (gl.eval(t) - v))
                .sum();
            assert!(dot.abs() < 1e-9, "normal equation {j}: {dot}");
        }
    }

    #[test]
    fn bad_input_is_an_error() {
        use SplineError::*;
        let k = clamped_cubic(&[0.0, 1.0, 2.0]);
        let s = [0.0, 0.5, 1.0, 1.5, 2.0];
        let y = [0.0; 5];
        assert!(fit_least_squares(&s, &y, None, &k).is_ok());
        assert!(matches!(
            fit_least_squares(&s[..4], &y, None, &k),
            Err(LengthMismatch { .. })
        ));
        assert!(matches!(
            fit_least_squares(&s, &y, Some(&[1.0; 4]), &k),
            Err(LengthMismatch { .. })
        ));
        assert!(matches!(
            fit_least_squares(&s, &y, Some(&[1.0, 1.0, -1.0, 1.0, 1.0]), &k),
            Err(NegativeWeight { index: 2, .. })
        ));
        assert!(matches!(
            fit_least_squares(&s, &y, Some(&[1.0, 1.0, f64::NAN, 1.0, 1.0]), &k),
            Err(NotFinite {
                what: "w",
                index: 2,
                ..
            })
        ));
        assert!(matches!(
            fit_least_squares(&[0.0, f64::NAN, 1.0, 1.5, 2.0], &y, None, &k),
            Err(NotFinite {
                what: "s",
                index: 1,
                ..
            })
        ));
        assert!(matches!(
            fit_least_squares(&s[..4], &y[..4], None, &k),
            Err(TooFewPoints { needed: 5, got: 4 })
        ));
        assert!(matches!(
            fit_least_squares(&s, &y, None, &k[..7]),
            Err(InvalidKnots { .. })
        ));
        let mut bad = k.clone();
        bad[4] = 3.0;
        assert!(matches!(
            fit_least_squares(&s, &y, None, &bad),
            Err(InvalidKnots { .. })
        ));
        // Enough points, but none in (1, 2]: the last control point is undetermined.
        let crowded = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0];
        let r = fit_least_squares(&crowded, &[0.0; 6], None, &k);
        assert!(matches!(r, Err(Singular { .. })), "{r:?}");
    }
}
