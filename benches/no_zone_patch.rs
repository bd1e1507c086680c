//! The whole no-zone path of `polepatch patch` minus the file system: `polepatch::patch_nc`
//! (the one reader's first read, which finds no run near the pole, then a copy). Run:
//! `cargo bench -p polepatch-benches --bench no_zone_patch -- --warm-up-time 1 --measurement-time 5`
//! Figures are written up in docs/performance-nc.md.

use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use polepatch::{PatchOptions, patch_nc};
use polepatch_benches::{Style, no_zone_program};
use polepatch_kinematics::Machine;

/// Size of the generated program, bytes.
const SIZE: usize = 20 << 20;

fn no_zone(c: &mut Criterion) {
    let machine = Machine::builtin("mikron-hsm600").expect("built-in machine");
    let primary = machine.primary_letter();
    let opts = PatchOptions::named("bench");
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
    }
    g.finish();
}

criterion_group!(benches, no_zone);
criterion_main!(benches);
