//! Property tests: cubic reproduction on random parameters, and degenerate input that is
//! always a clear error (never a panic, never a silent NaN).

#![allow(clippy::needless_range_loop)]

use polepatch_bspline::{
    NotAKnotSystem, SplineError, fit_least_squares, interpolate_clamped, interpolate_not_a_knot,
    knots::clamped_cubic, sample_params,
};
use proptest::prelude::*;

/// Strictly increasing parameters from positive gaps (ratios up to 100).
fn params(n: std::ops::Range<usize>) -> impl Strategy<Value = Vec<f64>> {
    (-100.0f64..100.0, prop::collection::vec(0.01f64..1.0, n)).prop_map(|(start, gaps)| {
        let mut s = vec![start];
        for g in gaps {
            let last = *s.last().unwrap();
            s.push(last + g);
        }
        s
    })
}

fn cubic(c: [f64; 4], t: f64) -> [f64; 4] {
    [
        c[0] + t * (c[1] + t * (c[2] + t * c[3])),
        c[1] + t * (2.0 * c[2] + 3.0 * t * c[3]),
        2.0 * c[2] + 6.0 * t * c[3],
        6.0 * c[3],
    ]
}

proptest! {
    #[test]
    fn interpolation_reproduces_any_cubic(
        s in params(3..40),
        c in prop::array::uniform4(-2.0f64..2.0),
        probe in 0.0f64..1.0,
    ) {
        let n = s.len();
        let mid = 0.5 * (s[0] + s[n - 1]);
        // Polynomial about the middle of the data, so values stay well scaled.
        let f = |t: f64| cubic(c, t - mid);
        let y: Vec<f64> = s.iter().map(|&t| f(t)[0]).collect();
        let nak = interpolate_not_a_knot(&s, &y).unwrap();
        let cl = interpolate_clamped(&s, &y, f(s[0])[1], f(s[n - 1])[1]).unwrap();
        // Inside, at the ends, and half an end span beyond (far extrapolation from a short
        // end span is ill-conditioned for any method).
        let len = s[n - 1] - s[0];
        let hmin = s.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
        let ymax = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        let outside = [s[0] - 0.5 * (s[1] - s[0]), s[n - 1] + 0.5 * (s[n - 1] - s[n - 2])];
        for t in [s[0], s[n - 1], s[0] + probe * len, outside[0], outside[1]] {
            let want = f(t);
            for got in [nak.eval_derivs(t), cl.eval_derivs(t)] {
                for k in 0..4 {
                    // Rounding of the data-sized control points, divided by h^k.
                    let tol = 1e-9 * (1.0 + want[k].abs()) + 1e-13 * ymax / hmin.powi(k as i32);
                    prop_assert!((got[k] - want[k]).abs() <= tol,
                        "t={} k={} got {} want {}", t, k, got[k], want[k]);
                }
            }
        }
    }

    #[test]
    fn repeated_or_decreasing_parameters_are_an_error(
        mut s in params(2..20),
        at in any::<prop::sample::Index>(),
        decrease in any::<bool>(),
    ) {
        let n = s.len();
        let i = 1 + at.index(n - 1);
        s[i] = if decrease { s[i - 1] - 0.5 } else { s[i - 1] };
        let y = vec![1.0; n];
        let e = interpolate_not_a_knot(&s, &y).unwrap_err();
        let is_not_increasing = matches!(e, SplineError::NotIncreasing { .. });
        prop_assert!(is_not_increasing, "{:?}", e);
        prop_assert!(NotAKnotSystem::new(&s).is_err());
        prop_assert!(interpolate_clamped(&s, &y, 0.0, 0.0).is_err());
    }

    #[test]
    fn non_finite_input_is_an_error(
        s in params(2..20),
        at in any::<prop::sample::Index>(),
        which in 0usize..3,
        in_s in any::<bool>(),
    ) {
        let bad = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][which];
        let n = s.len();
        let (mut s, mut y) = (s, vec![0.5; n]);
        let i = at.index(n);
        if in_s { s[i] = bad } else { y[i] = bad }
        let e = interpolate_not_a_knot(&s, &y).unwrap_err();
        let expected = if in_s { "s" } else { "y" };
        let ok = matches!(e, SplineError::NotFinite { what, index, .. } if what == expected && index == i);
        prop_assert!(ok, "{:?}", e);
        let knots = clamped_cubic(&[-200.0, 200.0]);
        prop_assert!(fit_least_squares(&s, &y, None, &knots).is_err());
    }

    #[test]
    fn results_are_finite_or_an_error(
        s in params(2..12),
        y in prop::collection::vec(-1e300f64..1e300, 12),
        squeeze in 1e-300f64..1e-3,
    ) {
        // Extreme values and near-coincident parameters: finite spline or an error.
        let n = s.len();
        let mut s = s;
        if n > 2 {
            s[1] = s[0] + squeeze * (s[2] - s[0]);
        }
        if let Ok(f) = interpolate_not_a_knot(&s, &y[..n]) {
            prop_assert!(f.coeffs().iter().all(|c| c.is_finite()));
        }
    }

    #[test]
    fn samples_cover_the_interval(a in -1e3f64..1e3, len in 0.0f64..50.0, step in 1e-3f64..10.0) {
        let b = a + len;
        let p = sample_params(a, b, step);
        prop_assert_eq!(p[0], a);
        prop_assert_eq!(*p.last().unwrap(), b);
        let tol = 4.0 * f64::EPSILON * a.abs().max(b.abs());
        for w in p.windows(2) {
            prop_assert!(w[1] > w[0] && w[1] - w[0] <= step + tol);
        }
    }
}
