//! The whole no-zone path of `polepatch patch` minus the file system: `polepatch::patch_nc`
//! (since issue 10 §2 the streaming scan `far::far_from_pole` that proves no point is in
//! the cone, then a copy), and the full path's analysis alone from a parsed program
//! (`program::load` → `patch_program`). Run:
//! `cargo bench -p polepatch-benches --bench no_zone_patch -- --warm-up-time 1 --measurement-time 5`
//! Figures are written up in docs/performance-nc.md.

use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use polepatch::program::{load, parse_program};
use polepatch::{PatchOptions, patch_nc, patch_program};
use polepatch_benches::{Style, no_zone_program};
use polepatch_kinematics::Machine;

/// Size of the generated program, bytes.
const SIZE: usize = 20 << 20;

fn no_zone(c: &mut Criterion) {
    let machine = Machine::builtin("mikron-hsm600").expect("built-in machine");
    let primary = machine.primary_letter();
    let opts = PatchOptions {
        name: "bench".into(),
        ..PatchOptions::default()
    };
    let mut g = c.benchmark_group("no_zone_patch");
    g.sample_size(10);
    for (name, style) in [("heidenhain", Style::Heidenhain), ("fanuc", Style::Fanuc)] {
        let text = no_zone_program(SIZE, style, primary);
        g.throughput(Throughput::Bytes(text.len() as u64));
        g.bench_with_input(BenchmarkId::new("pipeline", name), &text, |b, text| {
            b.iter_batched(
                || text.clone(),
                |input| {
                    let (out, report) = patch_nc(&input, &machine, &opts).expect("parses");
                    assert!(
                        report.words_changed == 0 && report.zones.is_empty(),
                        "no zone"
                    );
                    assert_eq!(out.len(), text.len());
                    (input, out)
                },
                BatchSize::PerIteration,
            )
        });
        // The analysis alone, from a parsed program: runs, paths, patch_path per run.
        let parsed = parse_program(text.clone(), "bench", &machine).expect("parses");
        g.bench_with_input(BenchmarkId::new("runs_and_patch", name), &parsed, |b, p| {
            b.iter_batched(
                || p.clone(),
                |program| {
                    let lp = load(program, "bench", &machine, None).expect("has runs");
                    let (edits, _) = patch_program(&lp, &machine, &opts.patch);
                    assert!(edits.is_empty());
                    lp
                },
                BatchSize::PerIteration,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, no_zone);
criterion_main!(benches);
