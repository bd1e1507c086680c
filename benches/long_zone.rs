//! One long near-pole zone (issue 26 §3 "bounded work"): time to patch a single G43.4 run
//! of N points at A0.5 with C turning 3.6° a point, which is one zone from end to end —
//! the program of `long_zone_program` (the same as the issue's `long_gen2.py`).
//! `patch_path` on the run: detection, every solve, verification, the report figures.
//! The throughput is per point, so a linear cost shows as a flat `elem/s` across N. Run:
//! `RAYON_NUM_THREADS=1 cargo bench -p polepatch-benches --bench long_zone -- --warm-up-time 1 --measurement-time 5`
//! Figures are written up in docs/performance-patcher.md.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use polepatch::load_nc;
use polepatch_kinematics::Machine;
use polepatch_patcher::{PatchOptions, Path, patch_path};

/// The program: one G43.4 run of `n` points, X advancing 0.5 mm, A0.5, C turning 3.6° a
/// point (wrapped to −180…180).
fn long_zone_program(n: usize) -> Vec<u8> {
    let mut s = String::from("%\nO1000\nG90 G21 G94\nT1 M6\nS12000 M3\nG43.4 H1\n");
    for k in 0..n {
        let x = k as f64 * 0.5;
        let c = (k as f64 * 3.6) % 360.0 - 180.0;
        if k == 0 {
            s.push_str(&format!("G1 X{x:.3} Y0 Z-5 A0.5 C{c:.3} F3000\n"));
        } else {
            s.push_str(&format!("X{x:.3} A0.5 C{c:.3}\n"));
        }
    }
    s.push_str("G49\nM30\n%\n");
    s.into_bytes()
}

/// The run of the program that holds the zone.
fn long_run(n: usize, machine: &Machine) -> Path {
    let lp = load_nc(&long_zone_program(n), "long", machine, None).expect("parsable program");
    lp.runs
        .into_iter()
        .filter_map(|r| r.path.ok())
        .max_by_key(|p| p.s_mm.len())
        .expect("one run")
}

fn long_zone(c: &mut Criterion) {
    let machine = Machine::builtin("mikron-ucp710").expect("built-in machine");
    let opts = PatchOptions::default();
    let mut g = c.benchmark_group("patcher/long_zone");
    g.sample_size(10);
    for n in [500, 1000, 2000, 4000] {
        let path = long_run(n, &machine);
        let res = patch_path(&path, &machine, &opts).unwrap();
        assert_eq!(res.zones.len(), 1, "one zone from end to end");
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &path, |b, path| {
            b.iter(|| patch_path(black_box(path), &machine, &opts).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, long_zone);
criterion_main!(benches);
