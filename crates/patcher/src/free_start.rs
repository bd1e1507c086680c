//! A run whose **first** point may change: the mirror of a free end
//! ([`PatchOptions::keep_last_point`] `= false`).
//!
//! A run's first point is where the positioning move before it left the axes. When that
//! move may end in another pose (the pipeline decides: a positioning move above the
//! clearance, under TCPM, which it rewrites), the run may start on the other IK branch —
//! `(P, C) → (−P, C ± 180°)`, the same tool axis — and a branch re-selection may then be
//! placed *before* a zone instead of after it.
//!
//! # The problem, and why reversal solves it
//! Equation 6 bounds |q'|, |q''| and |q'''| of each rotary axis along the path parameter
//! (velocity, acceleration and jerk of the axis at the programmed feed). Run the path
//! backwards, `s ↦ L − s`: q' and q''' change sign, q'' does not, so every bound holds on
//! the reversed path exactly where it holds on the forward one, and a patch of the
//! reversed path read backwards is a patch of the forward path with the same figures (the
//! zone analysis' finite-difference stencils are not mirror-exact: its figures agree to
//! the analysis' own discretisation). The patcher always keeps a path's first point; on
//! the reversed path that is the forward run's **last** point, and the reversed path's free
//! end is the forward run's **start**. So [`patch_path_free_start`] is [`patch_path`] on
//! the reversed path with its end free, read backwards: start free, end kept.
//!
//! A start and an end both free at once is not offered (the patcher keeps one end of a
//! path); the pipeline chooses among pinned, free end and free start ([`crate`] users:
//! the whole-program plan of `polepatch::patch`).

use crate::driver::PatchResult;
use crate::options::PatchOptions;
use crate::path::{Path, PathError};
use crate::strategy::patch_path;
use polepatch_kinematics::Machine;

/// `path` run backwards: `s ↦ s_last − s`, the points in reverse order.
pub fn reversed(path: &Path) -> Path {
    let last = path.s_mm.last().copied().unwrap_or(0.0);
    Path {
        s_mm: path.s_mm.iter().rev().map(|s| last - s).collect(),
        axes: path.axes.iter().rev().copied().collect(),
        feed_mm_min: path.feed_mm_min,
    }
}

/// A result of the reversed path (`n` points) read forwards: every per-point vector
/// reversed, and each zone's point indices mirrored (`k ↦ n − 1 − k`).
fn result_forwards(mut res: PatchResult, n: usize) -> PatchResult {
    res.p_deg.reverse();
    res.p_changed.reverse();
    res.c_deg.reverse();
    res.c_changed.reverse();
    res.xyz_mm.reverse();
    res.xyz_changed.reverse();
    let m = |k: usize| n - 1 - k.min(n - 1);
    for z in &mut res.zones {
        (z.first, z.last) = (m(z.last), m(z.first));
        z.core = [m(z.core[1]), m(z.core[0])];
    }
    res.zones.reverse();
    res
}

/// Patch `path` with its first point free and its last point kept (module docs):
/// `opts.keep_last_point` is ignored.
pub fn patch_path_free_start(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<PatchResult, PathError> {
    let n = path.s_mm.len();
    let o = PatchOptions {
        keep_last_point: false,
        ..opts.clone()
    };
    patch_path(&reversed(path), machine, &o).map(|r| result_forwards(r, n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::Outcome;
    use crate::testutil::{machine, planted};

    #[test]
    fn reversing_twice_is_the_identity() {
        let p = planted(41, 0.5, 0.5, false, 2000.0);
        let back = reversed(&reversed(&p));
        assert_eq!(back.axes, p.axes);
        for (a, b) in back.s_mm.iter().zip(&p.s_mm) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    /// A pass on the continuous branch (A ≥ 0, C swinging ~180° near the pole): with its
    /// start free, the branch is re-selected before the zone — the first point moves to
    /// the other branch, the last keeps its values — with the same orientation change as
    /// a free end needs on this mirror-symmetric pass.
    #[test]
    fn a_free_start_reselects_before_the_zone_and_keeps_the_end() {
        let m = machine("mikron-ucp710");
        for d in [0.0, 0.3] {
            let path = planted(241, 0.5, d, false, 2000.0);
            let opts = PatchOptions::default();
            let start = patch_path_free_start(&path, &m, &opts).expect("patched");
            let end = patch_path(
                &path,
                &m,
                &PatchOptions {
                    keep_last_point: false,
                    ..opts.clone()
                },
            )
            .expect("patched");
            let n = path.axes.len();
            assert!(
                start.p_changed[0] && start.c_changed[0],
                "d {d}: start moved"
            );
            assert!(
                !start.p_changed[n - 1] && !start.c_changed[n - 1],
                "d {d}: end kept"
            );
            assert!(
                (start.p_deg[0] + path.axes[0][3]).abs() < 1e-3,
                "d {d}: the other branch's primary value"
            );
            let dc = (start.c_deg[0] - path.axes[0][4]).rem_euclid(360.0);
            assert!(
                (dc - 180.0).abs() < 1e-3,
                "d {d}: C half a turn away ({dc})"
            );
            assert!(!start.zones.is_empty());
            for z in &start.zones {
                assert_eq!(z.outcome, Outcome::Reached, "d {d}");
                assert!(z.first <= z.last && z.core[0] <= z.core[1]);
            }
            let dev = |r: &PatchResult| {
                r.zones
                    .iter()
                    .map(|z| z.max_deviation_deg)
                    .fold(0.0, f64::max)
            };
            assert!(
                (dev(&start) - dev(&end)).abs() < 1e-3,
                "d {d}: {} against {}",
                dev(&start),
                dev(&end)
            );
        }
    }
}
