//! Verification of a change against Equation 6 (SPEC §2) on the values as written.
//!
//! For each axis checked, the analysis spline ([`crate::spline`]) of the values before and
//! after is built on a window of the path around the change (one factored system, two fits
//! per axis) and reduced to each span's peak |q'|, |q''|, |q'''| over its samples; the
//! span's ratio is Equation 6 for that axis at the programmed feed
//! ([`polepatch_kinematics::axis_feed_ratio`]), without margin.
//!
//! A window of the path is enough: the influence of a changed value on the spline decays
//! by a factor ≈ 2 − √3 ≈ 0.27 per knot, so [`VERIFY_MARGIN_POINTS`] points either side of
//! the change make the window spline equal to the whole-path spline to round-off where
//! the checks are made.

use crate::spline::{SplineSystem, span_maxima};
use crate::tolerances::{RATIO_TOL, VERIFY_MARGIN_POINTS, WINDOW_GUARD_SPANS};

pub use crate::tolerances::NOT_WORSE_REL;
use polepatch_kinematics::{Axis, Machine, axis_feed_ratio};

/// The lowest ratio a span may have after a change when it had `before`: a span at feed
/// (`before ≥ 1 − RATIO_TOL`) stays at feed — a patch never makes a new slow spot — and a
/// span below feed may lose [`NOT_WORSE_REL`] of its ratio (round-off, the solvers'
/// tolerance).
pub fn not_worse_floor(before: f64) -> f64 {
    if before >= 1.0 - RATIO_TOL {
        1.0 - RATIO_TOL
    } else {
        before * (1.0 - NOT_WORSE_REL)
    }
}

/// One axis of a change: its values along the whole path before and after (degrees or
/// mm, as written), and which axis it is (for its limits).
#[derive(Debug, Clone, Copy)]
pub struct AxisChange<'a> {
    /// The axis (its machine limits apply).
    pub axis: Axis,
    /// Values before the change, one per path point.
    pub before: &'a [f64],
    /// Values after the change, one per path point.
    pub after: &'a [f64],
}

/// Verdict of [`verify_change`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// Lowest ratio after the change over the core (the core points ± the caller's
    /// `core_margin`, [`crate::SolverSettings::core_margin_points`]), over every axis
    /// checked.
    pub core_min_after: f64,
    /// Lowest ratio before the change over the same core and axes.
    pub core_min_before: f64,
    /// Whether some sample of the checked window got a ratio below
    /// `min(before, 1 − RATIO_TOL)` on some axis.
    pub worse_somewhere: bool,
}

impl Verdict {
    /// Every axis reaches feed over the core and nothing got worse.
    pub fn passes(&self) -> bool {
        self.core_min_after >= 1.0 - RATIO_TOL && !self.worse_somewhere
    }
    /// Better than before over the core and nothing got worse elsewhere (a kept "best
    /// improvement").
    pub fn improves(&self) -> bool {
        !self.worse_somewhere && self.core_min_after > self.core_min_before
    }
    /// The verdict of a change that could not be evaluated (non-finite values): fails.
    pub fn failed() -> Verdict {
        Verdict {
            core_min_after: 0.0,
            core_min_before: 0.0,
            worse_somewhere: true,
        }
    }
}

/// Per-span ratios of `y` on the window's system.
fn span_ratios(
    sys: &SplineSystem,
    s: &[f64],
    y: &[f64],
    machine: &Machine,
    axis: Axis,
    feed_mm_s: f64,
) -> Option<Vec<f64>> {
    let sp = sys.fit(y).ok()?;
    let lim = machine.limit(axis);
    Some(
        span_maxima(s, &sp)
            .into_iter()
            .map(|pk| axis_feed_ratio(lim, pk, feed_mm_s))
            .collect(),
    )
}

/// Check a change: for every entry of `changes`, the values before and after (whole path,
/// as written) differ at most in `first..` (points `first..=last` modified, later points
/// possibly changed as a block that keeps every derivative's size: a 360° offset of C, or
/// a branch re-selection `(P, C) → (−P, C ± 180°)`).
/// `feed_mm_s` is the programmed feed.
///
/// Every axis must reach feed (ratio ≥ 1 − [`RATIO_TOL`]) on every sample of the spans
/// within `core_margin` points of the modified range (the driver passes
/// [`crate::SolverSettings::core_margin_points`]), and no span of the window
/// may get a ratio below [`not_worse_floor`] of its ratio before on any checked axis.
#[cfg(test)]
#[allow(clippy::too_many_arguments)]
pub fn verify_change(
    s_mm: &[f64],
    changes: &[AxisChange],
    first: usize,
    last: usize,
    core_margin: usize,
    machine: &Machine,
    feed_mm_s: f64,
) -> Verdict {
    verify_change_with_core(
        s_mm,
        changes,
        (first, last),
        (first, last),
        (core_margin, core_margin),
        machine,
        feed_mm_s,
    )
}

/// [`verify_change`] where the stretch that must reach feed is given apart from the
/// modified points: every axis must reach feed on the spans within `core_margin` points
/// of `core` (a point range, inclusive; the margin before and after it: a zone cut from a
/// longer stretch below feed takes none on that side, [`crate::zone_core`]), and nothing
/// may get worse in the window around
/// `core ∪ changed`. The joint method passes the zone as `core`: where the original was
/// below feed the result must reach it; around it, where the program's own values (its
/// rounding, say) may already exceed a limit, it may only not get worse.
#[allow(clippy::too_many_arguments)]
pub fn verify_change_with_core(
    s_mm: &[f64],
    changes: &[AxisChange],
    changed: (usize, usize),
    core: (usize, usize),
    core_margin: (usize, usize),
    machine: &Machine,
    feed_mm_s: f64,
) -> Verdict {
    verify_change_on(
        s_mm,
        s_mm,
        changes,
        changed,
        core,
        core_margin,
        machine,
        feed_mm_s,
    )
}

/// [`verify_change_with_core`] where the values after run on another path length
/// `s_after_mm` (same points): a change that moves the tips (a ball's centre kept,
/// [`crate::centre`]) changes the tip path's length too.
#[allow(clippy::too_many_arguments)]
pub fn verify_change_on(
    s_mm: &[f64],
    s_after_mm: &[f64],
    changes: &[AxisChange],
    changed: (usize, usize),
    core: (usize, usize),
    core_margin: (usize, usize),
    machine: &Machine,
    feed_mm_s: f64,
) -> Verdict {
    let n = s_mm.len();
    let first = changed.0.min(core.0);
    let last = changed.1.max(core.1).min(n - 1);
    let lo = first.saturating_sub(VERIFY_MARGIN_POINTS);
    let hi = (last + 1 + VERIFY_MARGIN_POINTS).min(n - 1);
    let nw = hi - lo + 1;
    let s = &s_mm[lo..=hi];
    let s_after = &s_after_mm[lo..=hi];
    let Ok(sys) = SplineSystem::new(s) else {
        return Verdict::failed();
    };
    let sys_after = if s_after == s {
        None
    } else {
        match SplineSystem::new(s_after) {
            Ok(x) => Some(x),
            Err(_) => return Verdict::failed(),
        }
    };
    let core_lo = core.0.saturating_sub(core_margin.0).max(lo) - lo;
    let core_hi = (core.1 + core_margin.1).min(hi) - lo; // knot index, exclusive span end
    let guard_lo = if lo > 0 { WINDOW_GUARD_SPANS } else { 0 };
    let guard_hi = if hi < n - 1 {
        (nw - 1).saturating_sub(WINDOW_GUARD_SPANS)
    } else {
        nw - 1
    };
    let mut v = Verdict {
        core_min_after: f64::INFINITY,
        core_min_before: f64::INFINITY,
        worse_somewhere: false,
    };
    for ch in changes {
        let before = span_ratios(&sys, s, &ch.before[lo..=hi], machine, ch.axis, feed_mm_s);
        let after = match &sys_after {
            None => span_ratios(&sys, s, &ch.after[lo..=hi], machine, ch.axis, feed_mm_s),
            Some(sa) => span_ratios(sa, s_after, &ch.after[lo..=hi], machine, ch.axis, feed_mm_s),
        };
        let (Some(before), Some(after)) = (before, after) else {
            return Verdict::failed();
        };
        for k in 0..nw - 1 {
            let in_core = k >= core_lo && k < core_hi.max(core_lo + 1);
            if in_core {
                v.core_min_after = v.core_min_after.min(after[k]);
                v.core_min_before = v.core_min_before.min(before[k]);
            }
            if (in_core || (k >= guard_lo && k < guard_hi)) && after[k] < not_worse_floor(before[k])
            {
                v.worse_somewhere = true;
            }
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ucp710() -> Machine {
        Machine::builtin("mikron-ucp710").unwrap()
    }

    /// Planted: C on a line at half its velocity limit reaches feed; raising one value so
    /// the spline's slope exceeds V/F is found below feed in the core and worse than before.
    #[test]
    fn planted_bump_fails_and_line_passes() {
        let m = ucp710();
        let feed_mm_s = 20.0;
        // C: V = 120 °/s → V/F = 6 °/mm; a line at 3 °/mm.
        let s: Vec<f64> = (0..41).map(|i| i as f64 * 0.5).collect();
        let y: Vec<f64> = s.iter().map(|x| 3.0 * x).collect();
        let c = |after: &[f64]| {
            let ch = [AxisChange {
                axis: Axis::C,
                before: &y,
                after,
            }];
            verify_change(&s, &ch, 20, 20, 3, &m, feed_mm_s)
        };
        assert!(c(&y).passes(), "{:?}", c(&y));
        let mut bumped = y.clone();
        bumped[20] += 2.0;
        let v = c(&bumped);
        assert!(v.core_min_after < 1.0 && v.worse_somewhere, "{v:?}");
        assert!(!v.passes());
    }

    /// The core margin is the caller's (`SolverSettings::core_margin_points`, no constant
    /// of its own): a kink of C two points from a change, whose jerk keeps its spans below
    /// feed, is in the core with a margin of 3 (the change fails: those spans do not reach
    /// feed) and outside it with a margin of 0 (unchanged there, so not worse: it passes).
    #[test]
    fn the_core_margin_is_the_callers() {
        let m = ucp710();
        let feed_mm_s = 20.0;
        // C at 3 °/mm (half of V/F) up to point 12, at 3.4 °/mm after it: a kink.
        let s: Vec<f64> = (0..61).map(|i| i as f64 * 0.5).collect();
        let y: Vec<f64> = s
            .iter()
            .map(|&x| 3.0 * x + 0.4 * (x - 6.0).max(0.0))
            .collect();
        let ch = [AxisChange {
            axis: Axis::C,
            before: &y,
            after: &y,
        }];
        let with = |margin| verify_change(&s, &ch, 10, 10, margin, &m, feed_mm_s);
        assert!(with(0).passes(), "{:?}", with(0));
        let v = with(3);
        assert!(!v.passes() && v.core_min_after < 1.0, "{v:?}");
    }

    /// Two axes: a change that frees C but breaks the primary fails; the verdict is the
    /// worse of the two.
    #[test]
    fn every_checked_axis_counts() {
        let m = ucp710();
        let feed_mm_s = 20.0;
        let s: Vec<f64> = (0..41).map(|i| i as f64 * 0.5).collect();
        let line: Vec<f64> = s.iter().map(|x| 0.1 * x).collect();
        let mut kinked = line.clone();
        kinked[20] += 1.0; // A's jerk limit is 1800 °/s³: far beyond it at 20 mm/s
        let only_c = [AxisChange {
            axis: Axis::C,
            before: &line,
            after: &line,
        }];
        assert!(verify_change(&s, &only_c, 18, 22, 3, &m, feed_mm_s).passes());
        let both = [
            only_c[0],
            AxisChange {
                axis: Axis::Primary,
                before: &line,
                after: &kinked,
            },
        ];
        let v = verify_change(&s, &both, 18, 22, 3, &m, feed_mm_s);
        assert!(!v.passes() && v.worse_somewhere, "{v:?}");
    }

    /// Non-finite values fail, never pass.
    #[test]
    fn non_finite_values_fail() {
        let m = ucp710();
        let s: Vec<f64> = (0..10).map(f64::from).collect();
        let y = vec![0.0; 10];
        let mut bad = y.clone();
        bad[5] = f64::NAN;
        let ch = [AxisChange {
            axis: Axis::C,
            before: &y,
            after: &bad,
        }];
        assert_eq!(verify_change(&s, &ch, 5, 5, 3, &m, 10.0), Verdict::failed());
    }
}
