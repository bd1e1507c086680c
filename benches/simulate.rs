//! `polepatch::simulate_nc` (the jerk-limited simulation of every run). Run:
//! `cargo bench -p polepatch-benches --bench simulate -- --warm-up-time 1 --measurement-time 3`
//! Figures are written up in docs/simulation.md.
//!
//! The work is one step per interpolation cycle of the simulated motion (two passes), so
//! it grows with the program's machining time, not its bytes: the throughput is given
//! per simulated millisecond. `sing_trajectory_csv` is `simulate --trajectory`'s work
//! (every cycle, formatted as CSV) without the disk.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use polepatch::kinematics::Machine;
use polepatch::simulate::SimState;
use polepatch::{SimulateOptions, simulate_nc, simulate_nc_with};
use polepatch_benches::{Style, no_zone_program};
use std::io::Write;

/// C17's %SING with its body repeated `k` times (one program of 3·k runs).
fn sing_repeated(k: usize) -> Vec<u8> {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fixtures/c17/SING.I"
    ))
    .expect("SING.I");
    let lines: Vec<&str> = text.lines().collect();
    let body: String = lines[1..lines.len() - 1]
        .iter()
        .map(|l| format!("{l}\n"))
        .collect();
    let mut out = format!("{}\n", lines[0]);
    for _ in 0..k {
        out.push_str(&body);
    }
    out.push_str(lines[lines.len() - 1]);
    out.push('\n');
    out.into_bytes()
}

fn simulate(c: &mut Criterion) {
    let mut g = c.benchmark_group("simulate");
    g.sample_size(10);
    let m = Machine::builtin("mikron-ucp710").expect("built-in");
    let opts = SimulateOptions::default();
    for (name, bytes) in [
        ("sing_x10", sing_repeated(10)),
        (
            "no_zone_256k",
            no_zone_program(256 << 10, Style::Heidenhain, 'A'),
        ),
    ] {
        let seconds = simulate_nc(&bytes, &m, &opts)
            .expect("simulates")
            .total
            .time_s;
        // Throughput in simulated milliseconds (criterion counts "elements").
        g.throughput(Throughput::Elements((seconds * 1000.0) as u64));
        g.bench_with_input(BenchmarkId::new("ucp710", name), &bytes, |b, bytes| {
            b.iter(|| black_box(simulate_nc(bytes, &m, &opts).expect("simulates")))
        });
    }
    // The trajectory: every cycle handed out and written as CSV text to a sink that
    // drops it (`simulate --trajectory`'s work without the disk): what a user's
    // `--trajectory` costs on top of the report, streamed, nothing held per cycle.
    let bytes = sing_repeated(1);
    let mut opts_traj = SimulateOptions::default();
    opts_traj.sim.every_cycle = true;
    let seconds = simulate_nc(&bytes, &m, &opts)
        .expect("simulates")
        .total
        .time_s;
    g.throughput(Throughput::Elements((seconds * 1000.0) as u64));
    g.bench_with_input(
        BenchmarkId::new("ucp710", "sing_trajectory_csv"),
        &bytes,
        |b, bytes| {
            b.iter(|| {
                let mut out = std::io::sink();
                let mut rows = 0u64;
                let mut on = |s: &SimState| {
                    let q = s.axes;
                    rows += 1;
                    let _ = writeln!(
                        out,
                        "{},{},{},{},{},{},{},{},{}",
                        s.run, s.t_s, s.s_mm, q[0], q[1], q[2], q[3], q[4], s.feed_mm_min
                    );
                };
                let rep = simulate_nc_with(bytes, &m, &opts_traj, Some(&mut on));
                black_box((rep.expect("simulates"), rows))
            })
        },
    );
    g.finish();
}

criterion_group!(benches, simulate);
criterion_main!(benches);
