//! The simulator's own memory on a long motion (issue 43, item 3): what it holds at its
//! peak, per point of the motion, as the process's most resident memory (`VmHWM`, Linux)
//! above what was resident before (the path).
//!
//! What it holds is the motion's spline, the grid of its velocity limit, the passes'
//! ceilings and the backward profile — then, once those are freed, Equation 6's analysis
//! of each part (its own spline and solver). Until 2026-11-29 the analysis ran while the
//! passes' arrays were still held, and the backward profile was a reversed copy of the
//! backward pass's record: 806 bytes a point at the peak on this path. Since, with the
//! analysis after the passes, the limit curve the forward pass consults beside its
//! profile computed where it is asked for (`pass::Limit`) and the record kept in blocks:
//! 480 (docs/journal/simulate-memory.md). The bound below sits between, so that holding
//! the analysis on top of the passes again fails. It is a bound per point, not a bound by
//! a window of the path: every array of the motion is still whole (the journal says what
//! is left).

#![cfg(target_os = "linux")]

use std::f64::consts::TAU;

use polepatch_kinematics::Machine;
use polepatch_patcher::Path;
use polepatch_simulate::{SimOptions, simulate};

/// A field of `/proc/self/status` in KiB (`VmRSS`: resident now, `VmHWM`: the most
/// resident so far).
fn status_kib(field: &str) -> usize {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status
        .lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .expect(field)
}

/// Points of the motion.
const POINTS: usize = 100_000;
/// Largest resident memory the simulation may add at its peak, bytes per point of the
/// motion (module docs: 806 before, 480 now).
const PEAK_BYTES_PER_POINT: usize = 560;

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
    let mut s_mm = vec![0.0];
    for k in 1..n {
        let d: f64 = (0..3)
            .map(|i| (axes[k][i] - axes[k - 1][i]).powi(2))
            .sum::<f64>()
            .sqrt();
        s_mm.push(s_mm[k - 1] + d);
    }
    Path {
        s_mm,
        axes,
        feed_mm_min: 3000.0,
    }
}

#[test]
fn the_simulation_holds_the_passes_or_the_analysis_never_both() {
    let m = Machine::builtin("mikron-ucp710").expect("built-in machine");
    let parts = [helix(POINTS)];
    let opts = SimOptions::default();
    // This test is alone in its process: the most resident so far is the path's.
    let before_kib = status_kib("VmHWM").max(status_kib("VmRSS"));
    let sim = simulate(&parts, &m, &opts, &mut |_, _| {}).expect("simulates");
    let peak_kib = status_kib("VmHWM").saturating_sub(before_kib);
    let per_point = peak_kib * 1024 / POINTS;
    assert!(sim.time_s >= sim.parts[0].eq6_time_s, "{sim:?}");
    assert!(
        per_point <= PEAK_BYTES_PER_POINT,
        "the simulation's peak resident memory was {peak_kib} KiB above what was resident \
         before, {per_point} bytes a point (bound {PEAK_BYTES_PER_POINT})"
    );
}
