//! A trajectory is handed out as it is computed: the memory a simulation holds does not
//! grow with the run's duration (issue 26: `simulate --trajectory` on a long line at F1
//! used to record the backward pass cycle by cycle, 140 → 544 MB in 20 s, and write
//! nothing until the end).
//!
//! Measured as a user would: the process's resident memory (`VmRSS` of
//! `/proc/self/status`, Linux) sampled while a 10 mm line at F1 (600 s of motion, 600 000
//! cycles) is simulated cycle by cycle; before the fix it grew by about 24 bytes a cycle
//! (14 MB over this run).

#![cfg(target_os = "linux")]

use polepatch::kinematics::Machine;
use polepatch::simulate::{SimState, SimulateOptions};
use polepatch::simulate_nc_with;

/// Resident memory of this process, KiB.
fn rss_kib() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("/proc/self/status");
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .expect("VmRSS")
}

#[test]
fn a_long_slow_run_is_simulated_in_bounded_memory() {
    let program =
        "%L G71 *\nN10 G90 *\nN20 G01 X+0 Y+0 Z+0 A+20 C+30 F1 *\nN30 X+10 *\nN40 M30 *\n";
    let m = Machine::builtin("mikron-ucp710").unwrap();
    let mut opts = SimulateOptions::default();
    opts.sim.every_cycle = true;
    let mut states = 0usize;
    let mut last_t = f64::NEG_INFINITY;
    // (states handed out, resident KiB) every 50 000 states.
    let mut samples: Vec<(usize, u64)> = Vec::with_capacity(64);
    let mut on = |s: &SimState| {
        assert!(s.t_s >= last_t, "states out of order");
        last_t = s.t_s;
        states += 1;
        if states.is_multiple_of(50_000) {
            samples.push((states, rss_kib()));
        }
    };
    let before = rss_kib();
    let rep = simulate_nc_with(program.as_bytes(), &m, &opts, Some(&mut on)).unwrap();
    assert_eq!(rep.total.runs, 1);
    let lf_s = 10.0 / (1.0 / 60.0);
    assert!(
        (rep.total.time_s / lf_s - 1.0).abs() < 5e-3,
        "{} s",
        rep.total.time_s
    );
    // Every cycle handed out, as it was computed (samples taken during the run)…
    assert!(states > 590_000, "{states} states");
    assert!(samples.len() >= 11, "{samples:?}");
    // …in memory that does not depend on the run's duration: from before the simulation
    // to any point of it, within 4 MiB (holding 24 bytes a cycle would take 14 MB).
    let most = samples.iter().map(|s| s.1).max().unwrap();
    assert!(
        most <= before + 4096,
        "resident memory grew from {before} KiB to {most} KiB: {samples:?}"
    );
}
