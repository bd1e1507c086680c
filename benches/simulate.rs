//! `polepatch::simulate_nc` (the jerk-limited simulation of every run). Run:
//! `cargo bench -p polepatch-benches --bench simulate -- --warm-up-time 1 --measurement-time 3`
//! Figures are written up in docs/simulation.md.
//!
//! The work is one step per interpolation cycle of the simulated motion (two passes), so
//! it grows with the program's machining time, not its bytes: the throughput is given
//! per simulated second.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use polepatch::kinematics::Machine;
use polepatch::{SimulateOptions, simulate_nc};
use polepatch_benches::{Style, no_zone_program};

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
    g.finish();
}

criterion_group!(benches, simulate);
criterion_main!(benches);
