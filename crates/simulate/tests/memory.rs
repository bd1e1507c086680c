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
//! few long segments; the second case, a run of many short ones, holds each plan's
//! look-ahead rather than its segments (`segments.rs::Lookahead`): 343–345 bytes a point
//! with every plan's segments held, 256–302 with the look-ahead.

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

/// One G1 run as an NC program writes it, its values rounded to the written 0.001: a
/// line in X and Y while C turns 0.0713° a point at A 35° (as `big_program`'s body). The
/// rounding makes the path's derivatives vary from span to span: a plan of many short
/// segments (about one for every three points).
fn rounded_line(n: usize) -> Path {
    let round = |v: f64| (v * 1000.0).round() / 1000.0;
    let axes: Vec<[f64; 5]> = (0..n)
        .map(|k| {
            let kf = k as f64;
            [
                round(0.0137 * kf),
                round(0.0213 * kf),
                -8.0,
                35.0,
                round(-360.0 + 0.0713 * kf),
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

/// Largest resident memory the simulation of [`rounded_line`] may add at its peak, bytes
/// per point: 343–345 in 10 runs when every plan held all its segments (until
/// 2026-11-29), 256–302 in 20 runs with each plan's look-ahead (`segments.rs::Lookahead`;
/// where the allocator puts the threads' blocks moves it); the spline and the path are
/// the rest.
const MANY_SEGMENTS_PEAK_BYTES_PER_POINT: usize = 330;

#[test]
fn a_plan_of_many_segments_holds_its_look_ahead_not_its_segments() {
    let m = Machine::builtin("mikron-ucp710").expect("built-in machine");
    let parts = [rounded_line(POINTS)];
    let opts = SimOptions::default();
    let before_kib = status_kib("VmHWM").max(status_kib("VmRSS"));
    let sim = simulate(&parts, &m, &opts, &mut |_, _| {}).expect("simulates");
    let peak_kib = status_kib("VmHWM").saturating_sub(before_kib);
    let per_point = peak_kib * 1024 / POINTS;
    assert!(sim.time_s >= sim.parts[0].eq6_time_s, "{sim:?}");
    assert!(
        per_point <= MANY_SEGMENTS_PEAK_BYTES_PER_POINT,
        "the simulation's peak resident memory was {peak_kib} KiB above what was resident \
         before, {per_point} bytes a point (bound {MANY_SEGMENTS_PEAK_BYTES_PER_POINT})"
    );
}
