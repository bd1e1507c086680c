//! The simulator's own memory on a long motion (issue 43, item 3): what it holds at its
//! peak, per point of the motion, as the process's most resident memory (`VmHWM`, Linux)
//! above what was resident before (the path).
//!
//! What it holds is the motion's spline and the plan over it, then, once those are freed,
//! Equation 6's analysis of each part (its own spline and solver). Until 2026-11-29 the
//! analysis ran while the passes' arrays were still held: 806 bytes a point at the peak
//! on this path; 480 with the analysis after the passes, the limit curve computed where
//! asked (`pass::Limit`) and the record kept in blocks; 327 with the segments of constant
//! limits as the default (`e2ed2b8`). Since, the five axes' splines hold one copy of their
//! breaks, and are solved before any is put in piecewise-polynomial form, the system's
//! factors freed between (`SplineSystem::fit_axes`), the axes' values gathered one axis
//! at a time: 223 (docs/journal/simulate-memory.md). The bound below sits above, so that
//! a copy of every point's values or the factors held with the five splines again
//! fails. It is a bound per point, not a bound by a window of the path: every array of
//! the motion is still whole (the journal says what is left). The helix is planned in a
//! few long segments; `tests/memory_segments.rs` holds a run of many short ones. The
//! simulation runs on one worker thread (`common::memory::peak_added`).

#![cfg(target_os = "linux")]

use std::f64::consts::TAU;

mod common;

use common::memory::{at_f3000, peak_added};
use polepatch_patcher::Path;

/// Points of the motion.
const POINTS: usize = 100_000;
/// Largest resident memory the simulation may add at its peak, bytes per point of the
/// motion (module docs: 327 at `e2ed2b8`, 223 now).
const PEAK_BYTES_PER_POINT: usize = 250;

/// One G1 run as `examples/long_run.rs` writes it (a slow helix, radius 20 mm, points
/// 0.1 mm apart, A 20° ± 5°, C 0.01° a point, F3000), as the path the reader makes of
/// it: s the tool tip's chord lengths.
fn helix(n: usize) -> Path {
    let (radius_mm, step_mm) = (20.0, 0.1);
    let axes: Vec<[f64; 5]> = (0..n)
        .map(|k| {
            let kf = k as f64;
            let th = kf * step_mm / radius_mm;
            [
                radius_mm * th.cos(),
                radius_mm * th.sin(),
                -5.0 + 2.0 * (TAU * kf / 30_000.0).sin(),
                20.0 + 5.0 * (TAU * kf / 20_000.0).sin(),
                0.01 * kf,
            ]
        })
        .collect();
    at_f3000(axes)
}

#[test]
fn the_simulation_holds_the_passes_or_the_analysis_never_both() {
    let (peak_kib, per_point) = peak_added(helix(POINTS));
    assert!(
        per_point <= PEAK_BYTES_PER_POINT,
        "the simulation's peak resident memory was {peak_kib} KiB above what was resident \
         before, {per_point} bytes a point (bound {PEAK_BYTES_PER_POINT})"
    );
}
