//! The simulator's own memory on a run the plan cuts into many short segments (issue 43,
//! item 3): each plan holds its look-ahead (`segments.rs::Lookahead`), not its segments.
//! Alone in its file (and so in its process): the most resident memory is the process's.
//! The simulation runs on one worker thread: on two, where the allocator puts each
//! thread's blocks moved the figures by a fifth from run to run (256–311 bytes a point
//! with the look-ahead, 343–345 without).

#![cfg(target_os = "linux")]

mod common;

use common::memory::{at_f3000, peak_added};
use polepatch_patcher::Path;

/// Points of the motion.
const POINTS: usize = 100_000;

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
    at_f3000(axes)
}

/// Largest resident memory the simulation of [`rounded_line`] may add at its peak, bytes
/// per point: 324–327 in 5 runs when every plan held all its segments (`4503d4c`),
/// 292–295 in 10 with each plan's look-ahead; the spline and the path are the rest.
const MANY_SEGMENTS_PEAK_BYTES_PER_POINT: usize = 310;

#[test]
fn a_plan_of_many_segments_holds_its_look_ahead_not_its_segments() {
    let (peak_kib, per_point) = peak_added(rounded_line(POINTS));
    assert!(
        per_point <= MANY_SEGMENTS_PEAK_BYTES_PER_POINT,
        "the simulation's peak resident memory was {peak_kib} KiB above what was resident \
         before, {per_point} bytes a point (bound {MANY_SEGMENTS_PEAK_BYTES_PER_POINT})"
    );
}
