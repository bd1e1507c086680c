//! Equation 6 of G16: the feed bound from geometric derivatives along the path.
//!
//! With s̈ = s⃛ = 0 at a local feed minimum, for each axis q with derivatives
//! q_s, q_ss, q_sss along the tool-tip path length s:
//!
//! ```text
//! ṡ ≤ min( F, V/|q_s|, sqrt(A/|q_ss|), cbrt(J/|q_sss|) )   over axes      (eq. 6)
//! ```
//!
//! Conventions, so that no bad sample reads as a "fine" one:
//! - a zero derivative puts no bound on its term (+∞), even with a zero limit;
//! - a NaN or infinite derivative bounds its term to 0 (ratio 0), never NaN;
//! - ties go to the earlier term (V, then A, then J) and the earlier axis, and the
//!   programmed feed F wins a tie with any axis.

use crate::machine::{Axis, AxisLimits, Machine};
use crate::tolerances::CBRT_SKIP_MARGIN;
use serde::Serialize;

/// Which term of Equation 6 binds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum LimitKind {
    /// The programmed feed itself (nothing else limits).
    Feed,
    /// The axis velocity limit V.
    Velocity,
    /// The axis acceleration limit A.
    Acceleration,
    /// The axis jerk limit J.
    Jerk,
}

/// The bound of one axis: min(V/|q_s|, sqrt(A/|q_ss|), cbrt(J/|q_sss|)) in mm/s and the
/// term that gives it. A zero derivative gives +∞ for its term.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AxisBound {
    /// Bound on the feed, mm/s (may be +∞).
    pub feed_mm_s: f64,
    /// Binding term (never `Feed`).
    pub kind: LimitKind,
}

/// The overall bound at one path parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FeedBound {
    /// Reachable feed, mm/s, ≤ the programmed feed.
    pub feed_mm_s: f64,
    /// `feed_mm_s / programmed feed`, in (0, 1].
    pub ratio: f64,
    /// Limiting axis, `None` when the programmed feed binds.
    pub axis: Option<Axis>,
    /// Binding term.
    pub kind: LimitKind,
}

/// Equation 6 for one axis. `d = [q_s, q_ss, q_sss]` per mm (mm/mm or °/mm^k).
#[inline]
pub fn axis_feed_bound(limits: &AxisLimits, d: [f64; 3]) -> AxisBound {
    let mut feed_mm_s = term(limits.v, d[0]);
    let mut kind = LimitKind::Velocity;
    let a = term(limits.a, d[1]).sqrt();
    if a < feed_mm_s {
        feed_mm_s = a;
        kind = LimitKind::Acceleration;
    }
    // The cube root (a slow libm call, the bulk of an analysis) only where it can bind:
    // cbrt(t) < f implies t < f³ (the margin covers the rounding of f³), so the result
    // is the same as always taking it.
    let tj = term(limits.j, d[2]);
    if tj < feed_mm_s * feed_mm_s * feed_mm_s * (1.0 + CBRT_SKIP_MARGIN) {
        let j = tj.cbrt();
        if j < feed_mm_s {
            feed_mm_s = j;
            kind = LimitKind::Jerk;
        }
    }
    AxisBound { feed_mm_s, kind }
}

/// The feed ratio of one axis: `min(1, bound / F)` with the bound of
/// [`axis_feed_bound`] and `feed_mm_s` the programmed feed F (mm/s, positive). A NaN or
/// infinite derivative gives 0, never NaN.
#[inline]
pub fn axis_feed_ratio(limits: &AxisLimits, d: [f64; 3], feed_mm_s: f64) -> f64 {
    (axis_feed_bound(limits, d).feed_mm_s / feed_mm_s).min(1.0)
}

/// `limit / |derivative|` with +∞ for a zero derivative and 0 for a NaN or infinite one.
#[inline]
fn term(limit: f64, derivative: f64) -> f64 {
    let r = limit / derivative.abs();
    if r.is_nan() {
        // 0/0 (zero limit, axis still) or x/NaN or ∞/∞.
        if derivative == 0.0 {
            f64::INFINITY
        } else {
            0.0
        }
    } else {
        r
    }
}

/// Equation 6 over all axes. `d[axis] = [q_s, q_ss, q_sss]` in [`Axis`] order; `feed_mm_s`
/// is the programmed feed. Ties go to the earlier axis and the earlier term.
///
/// `feed_mm_s` must be positive and finite; otherwise `ratio` is NaN (when F binds) so the
/// mistake cannot pass for a sample that reaches feed.
pub fn feed_bound(machine: &Machine, d: &[[f64; 3]; 5], feed_mm_s: f64) -> FeedBound {
    let mut best = FeedBound {
        feed_mm_s,
        ratio: 1.0,
        axis: None,
        kind: LimitKind::Feed,
    };
    for axis in Axis::ALL {
        let b = axis_feed_bound(machine.limit(axis), d[axis.index()]);
        if b.feed_mm_s < best.feed_mm_s {
            best.feed_mm_s = b.feed_mm_s;
            best.axis = Some(axis);
            best.kind = b.kind;
        }
    }
    best.ratio = best.feed_mm_s / feed_mm_s;
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIM: AxisLimits = AxisLimits {
        v: 100.0,
        a: 400.0,
        j: 8000.0,
    };

    /// Taking the cube root only where it can bind gives the bound of always taking it,
    /// bit for bit: on a sweep of derivatives over 24 decades (each term binding in turn,
    /// and ties between the jerk and the other terms), zero, infinite and NaN ones.
    #[test]
    fn skipping_the_cube_root_changes_nothing() {
        let reference = |l: &AxisLimits, d: [f64; 3]| {
            let mut f = term(l.v, d[0]);
            let mut kind = LimitKind::Velocity;
            let a = term(l.a, d[1]).sqrt();
            if a < f {
                f = a;
                kind = LimitKind::Acceleration;
            }
            let j = term(l.j, d[2]).cbrt();
            if j < f {
                f = j;
                kind = LimitKind::Jerk;
            }
            AxisBound { feed_mm_s: f, kind }
        };
        let mut values = vec![0.0, -0.0, f64::INFINITY, f64::NAN, f64::MIN_POSITIVE];
        let mut x = 1e-12;
        while x < 1e12 {
            values.extend([x, -x, x * (1.0 + 1e-15)]);
            x *= 1.37;
        }
        // Exact ties: q_sss such that cbrt(J/q_sss) equals the velocity bound 100/q_s.
        for qs in [1.0, 3.0, 7.5] {
            let f: f64 = LIM.v / qs;
            values.push(LIM.j / (f * f * f));
        }
        let mut n = 0;
        for (k, &a) in values.iter().enumerate() {
            for &b in values.iter().skip(k % 7).step_by(7) {
                for &c in &values {
                    let d = [a, b, c];
                    let got = axis_feed_bound(&LIM, d);
                    let want = reference(&LIM, d);
                    assert!(
                        got.kind == want.kind
                            && (got.feed_mm_s.to_bits() == want.feed_mm_s.to_bits()),
                        "{d:?}: {got:?} vs {want:?}"
                    );
                    n += 1;
                }
            }
        }
        assert!(n > 100_000, "{n}");
    }

    #[test]
    fn velocity_binds() {
        // V/|q_s| = 100/4 = 25; sqrt(400/0.01) = 200; cbrt(8000/1e-3) = 200.
        let b = axis_feed_bound(&LIM, [-4.0, 0.01, 1e-3]);
        assert_eq!(
            b,
            AxisBound {
                feed_mm_s: 25.0,
                kind: LimitKind::Velocity
            }
        );
    }

    #[test]
    fn acceleration_binds() {
        // V/|q_s| = 100; sqrt(400/-1) = 20; cbrt(8000/1) = 20 ties and loses to A.
        let b = axis_feed_bound(&LIM, [1.0, -1.0, 1.0]);
        assert_eq!(
            b,
            AxisBound {
                feed_mm_s: 20.0,
                kind: LimitKind::Acceleration
            }
        );
    }

    #[test]
    fn jerk_binds() {
        // cbrt(8000/8) = 10 < sqrt(400/1) = 20 < 100/0.5 = 200.
        let b = axis_feed_bound(&LIM, [0.5, 1.0, -8.0]);
        assert_eq!(
            b,
            AxisBound {
                feed_mm_s: 10.0,
                kind: LimitKind::Jerk
            }
        );
    }

    #[test]
    fn ties_go_to_the_earlier_term() {
        // 100/5 = 20 = sqrt(400/1) = cbrt(8000/1).
        let b = axis_feed_bound(&LIM, [5.0, 1.0, 1.0]);
        assert_eq!(b.kind, LimitKind::Velocity);
        assert_eq!(b.feed_mm_s, 20.0);
    }

    #[test]
    fn zero_derivatives_put_no_bound() {
        let b = axis_feed_bound(&LIM, [0.0, -0.0, 0.0]);
        assert_eq!(b.feed_mm_s, f64::INFINITY);
        // Even a zero limit does not bind an axis that does not move.
        let zero = AxisLimits {
            v: 0.0,
            a: 0.0,
            j: 0.0,
        };
        assert_eq!(axis_feed_bound(&zero, [0.0; 3]).feed_mm_s, f64::INFINITY);
        // Only the jerk term is finite.
        let b = axis_feed_bound(&LIM, [0.0, 0.0, 1.0]);
        assert_eq!(
            b,
            AxisBound {
                feed_mm_s: 20.0,
                kind: LimitKind::Jerk
            }
        );
    }

    #[test]
    fn nan_or_infinite_derivative_bounds_to_zero_not_nan() {
        for (k, kind) in [
            LimitKind::Velocity,
            LimitKind::Acceleration,
            LimitKind::Jerk,
        ]
        .into_iter()
        .enumerate()
        {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let mut d = [1e-9; 3];
                d[k] = bad;
                let b = axis_feed_bound(&LIM, d);
                assert_eq!(
                    b,
                    AxisBound {
                        feed_mm_s: 0.0,
                        kind
                    },
                    "d = {d:?}"
                );
            }
        }
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let mut d = [[0.0; 3]; 5];
        d[Axis::C.index()][2] = f64::NAN;
        let f = feed_bound(&m, &d, 50.0);
        assert_eq!((f.feed_mm_s, f.ratio), (0.0, 0.0));
        assert_eq!((f.axis, f.kind), (Some(Axis::C), LimitKind::Jerk));
    }

    #[test]
    fn axis_ratio_is_the_bound_over_f_capped_at_one() {
        // Bound 25 mm/s (velocity, as in `velocity_binds`).
        let d = [-4.0, 0.01, 1e-3];
        assert_eq!(axis_feed_ratio(&LIM, d, 50.0), 0.5);
        assert_eq!(axis_feed_ratio(&LIM, d, 20.0), 1.0);
        assert_eq!(axis_feed_ratio(&LIM, [0.0; 3], 20.0), 1.0);
        assert_eq!(axis_feed_ratio(&LIM, [f64::NAN, 0.0, 0.0], 20.0), 0.0);
    }

    #[test]
    fn programmed_feed_binds_when_nothing_else_does() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        // A straight line along X: X moves 1 mm/mm, nothing else. X: V = 500 mm/s.
        let mut d = [[0.0; 3]; 5];
        d[0] = [1.0, 0.0, 0.0];
        let f = feed_bound(&m, &d, 2000.0 / 60.0);
        assert_eq!(f.axis, None);
        assert_eq!(f.kind, LimitKind::Feed);
        assert_eq!(f.ratio, 1.0);
        assert_eq!(f.feed_mm_s, 2000.0 / 60.0);
        // F equal to the axis bound: F wins the tie.
        let f = feed_bound(&m, &d, 500.0);
        assert_eq!((f.axis, f.kind, f.ratio), (None, LimitKind::Feed, 1.0));
    }

    #[test]
    fn c_axis_jerk_limits_a_ucp710_near_the_pole() {
        // UCP710 C: V = 120 °/s, A = 298.8 °/s², J = 18000 °/s³. A C swing of
        // C_s = 2 °/mm, C_ss = 3 °/mm², C_sss = 18 °/mm³ at F = 3000 mm/min = 50 mm/s:
        // V/|C_s| = 60, sqrt(298.8/3) = 9.98, cbrt(18000/18) = 10 → A binds at 9.98 mm/s.
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let mut d = [[0.0; 3]; 5];
        d[Axis::X.index()] = [1.0, 0.0, 0.0];
        d[Axis::C.index()] = [2.0, 3.0, 18.0];
        let f = feed_bound(&m, &d, 50.0);
        let want = (298.8f64 / 3.0).sqrt();
        assert!((f.feed_mm_s - want).abs() < 1e-12, "{f:?}");
        assert!((f.ratio - want / 50.0).abs() < 1e-12);
        assert_eq!((f.axis, f.kind), (Some(Axis::C), LimitKind::Acceleration));
        // With C_sss = 36 the jerk term cbrt(500) = 7.94 takes over.
        d[Axis::C.index()][2] = 36.0;
        let f = feed_bound(&m, &d, 50.0);
        assert!((f.feed_mm_s - 500f64.cbrt()).abs() < 1e-12, "{f:?}");
        assert_eq!((f.axis, f.kind), (Some(Axis::C), LimitKind::Jerk));
    }

    #[test]
    fn ties_go_to_the_earlier_axis() {
        let m = Machine::builtin("mikron-hsm600").unwrap();
        // X and Y share V = 1666.7 mm/s: equal q_s bind equally, X reported.
        let mut d = [[0.0; 3]; 5];
        d[0] = [100.0, 0.0, 0.0];
        d[1] = [-100.0, 0.0, 0.0];
        let f = feed_bound(&m, &d, 1000.0);
        assert_eq!((f.axis, f.kind), (Some(Axis::X), LimitKind::Velocity));
        // But a strictly tighter later axis wins.
        d[1][0] = -100.5;
        assert_eq!(feed_bound(&m, &d, 1000.0).axis, Some(Axis::Y));
    }

    #[test]
    fn a_bad_programmed_feed_gives_a_nan_ratio() {
        let m = Machine::builtin("mikron-hsm600").unwrap();
        let d = [[0.0; 3]; 5];
        for f in [0.0, f64::NAN, f64::INFINITY] {
            assert!(feed_bound(&m, &d, f).ratio.is_nan(), "F = {f}");
        }
    }

    #[test]
    fn axis_bound_is_eq6_against_the_textbook_formula() {
        // Random derivatives: the bound equals min over the three closed forms.
        let mut rng = crate::testutil::SplitMix64(6);
        for _ in 0..10_000 {
            let d = [
                rng.uniform(-10.0, 10.0) * rng.pick(&[0.0, 1.0, 1e-6]),
                rng.uniform(-10.0, 10.0) * rng.pick(&[0.0, 1.0, 1e-6]),
                rng.uniform(-10.0, 10.0) * rng.pick(&[0.0, 1.0, 1e-6]),
            ];
            let want = (LIM.v / d[0].abs())
                .min((LIM.a / d[1].abs()).sqrt())
                .min((LIM.j / d[2].abs()).cbrt());
            assert_eq!(axis_feed_bound(&LIM, d).feed_mm_s, want, "d = {d:?}");
        }
    }
}
