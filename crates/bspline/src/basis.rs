//! Basis rows: the linear map from control points to a value or derivative.

use crate::cox_de_boor::{ders_basis, find_span};
use crate::spline::BSpline;

/// `value_or_derivative(t) = Σ_k weights[k] · coeffs[first + k]` for k in 0..=degree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BasisRow {
    /// Index of the first control point involved.
    pub first: usize,
    /// Weights of control points `first ..= first + degree` (unused entries are 0).
    pub weights: [f64; 4],
}

impl BSpline {
    /// The basis row of the `order`-th derivative (0..=3) at `t`, for this spline's knots.
    ///
    /// `first` is `span − degree`, where `span` is the knot span that [`BSpline::eval_derivs`]
    /// uses at `t` (outside the domain: the end span, so the row extends the end polynomial
    /// piece like the evaluation does). Weights above the degree, and all weights for
    /// `order > degree` (including `order > 3`), are 0. The row is consistent with
    /// evaluation: `Σ_k weights[k]·coeffs[first + k] == eval_derivs(t)[order]` up to
    /// rounding.
    pub fn basis_row(&self, t: f64, order: usize) -> BasisRow {
        let p = self.degree();
        let span = find_span(self.knots(), p, self.coeffs().len(), t);
        let mut weights = [0.0; 4];
        if order <= p {
            let ders = ders_basis(self.knots(), p, span, t);
            weights[..=p].copy_from_slice(&ders[order][..=p]);
        }
        BasisRow {
            first: span - p,
            weights,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::knots::clamped_cubic;

    fn spline(coeffs: Vec<f64>, breaks: &[f64]) -> BSpline {
        BSpline::new(3, clamped_cubic(breaks), coeffs).unwrap()
    }

    /// A tiny deterministic generator (xorshift) so the tests need no extra crates.
    fn rng(seed: u64) -> impl FnMut() -> f64 {
        let mut x = seed;
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn rows_reproduce_evaluation_for_random_coefficients() {
        let breaks = [0.0, 0.3, 0.35, 1.2, 2.0, 2.1, 4.0];
        let mut r = rng(7);
        for _ in 0..20 {
            let coeffs: Vec<f64> = (0..breaks.len() + 2).map(|_| 10.0 * r() - 5.0).collect();
            let sp = spline(coeffs.clone(), &breaks);
            for &t in &[-0.5, 0.0, 0.1, 0.3, 0.34, 1.0, 2.05, 3.9, 4.0, 4.7] {
                let d = sp.eval_derivs(t);
                for (order, &want) in d.iter().enumerate() {
                    let row = sp.basis_row(t, order);
                    let got: f64 = (0..4)
                        .filter(|k| row.first + k < coeffs.len())
                        .map(|k| row.weights[k] * coeffs[row.first + k])
                        .sum();
                    assert!(
                        (got - want).abs() <= 1e-9 * (1.0 + want.abs()),
                        "t={t} order={order}: row {got} vs eval {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn value_weights_are_a_partition_of_unity_and_higher_orders_vanish() {
        let sp = spline(vec![0.0; 6], &[0.0, 1.0, 2.5, 3.0]);
        for &t in &[0.0, 0.5, 1.0, 2.9, 3.0] {
            let w = sp.basis_row(t, 0).weights;
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            assert!(w.iter().all(|&x| x >= 0.0));
            let d1: f64 = sp.basis_row(t, 1).weights.iter().sum();
            assert!(d1.abs() < 1e-12, "derivative weights sum to 0");
            assert_eq!(sp.basis_row(t, 4).weights, [0.0; 4]);
        }
        let lin = BSpline::new(1, vec![0.0, 0.0, 1.0, 2.0, 2.0], vec![1.0, 2.0, 0.0]).unwrap();
        let row = lin.basis_row(0.25, 1);
        assert_eq!(row.weights[2..], [0.0, 0.0]);
        assert_eq!(lin.basis_row(0.25, 2).weights, [0.0; 4]);
    }
}
