//! The simulator's own peak memory on a long motion (`tests/memory*.rs`, one test a file:
//! the most resident memory is the process's).

use polepatch_kinematics::Machine;
use polepatch_patcher::Path;
use polepatch_simulate::{SimOptions, simulate};

/// A field of `/proc/self/status` in KiB (`VmRSS`: resident now, `VmHWM`: the most
/// resident so far).
pub fn status_kib(field: &str) -> usize {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status
        .lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .expect(field)
}

/// The path through `axes` at F3000, s the tool tip's chord lengths.
pub fn at_f3000(axes: Vec<[f64; 5]>) -> Path {
    super::chord_path(axes, 3000.0)
}

/// The most resident memory the simulation of `path` on the UCP710 adds, KiB, and its
/// bytes a point. The test calling it is alone in its process (one test a file): the
/// most resident so far is the path's.
pub fn peak_added(path: Path) -> (usize, usize) {
    let m = Machine::builtin("mikron-ucp710").expect("built-in machine");
    let points = path.axes.len();
    let parts = [path];
    let before_kib = status_kib("VmHWM").max(status_kib("VmRSS"));
    // On one worker thread: each thread's allocations go to an arena of its own, and how
    // the work falls on two moves the figure by a fifth from run to run.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a thread pool");
    let sim = pool
        .install(|| simulate(&parts, &m, &SimOptions::default(), &mut |_, _| {}))
        .expect("simulates");
    let peak_kib = status_kib("VmHWM").saturating_sub(before_kib);
    assert!(sim.time_s >= sim.parts[0].eq6_time_s, "{sim:?}");
    (peak_kib, peak_kib * 1024 / points)
}
