//! polepatch-nc parse + write with no edits (the byte-identical rewrite of SPEC §6). Run:
//! `cargo bench -p polepatch-benches --bench nc_throughput -- --warm-up-time 1 --measurement-time 5`
//! Figures are written up in docs/performance-nc.md.

use std::hint::black_box;

use criterion::{BatchSize, BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use polepatch_benches::{Style, no_zone_program};
use polepatch_nc::{Dialect, parse, write};

/// Size of the generated program, bytes.
const SIZE: usize = 20 << 20;

fn parse_write(c: &mut Criterion) {
    let mut g = c.benchmark_group("nc");
    g.sample_size(10);
    for (name, style) in [("heidenhain", Style::Heidenhain), ("fanuc", Style::Fanuc)] {
        let text = no_zone_program(SIZE, style, 'B');
        g.throughput(Throughput::Bytes(text.len() as u64));
        // The input copy is made outside the timing (reading the file makes a fresh
        // buffer too); the parsed program and output are dropped outside it as well.
        g.bench_with_input(BenchmarkId::new("parse_write", name), &text, |b, text| {
            b.iter_batched(
                || text.clone(),
                |input| {
                    let program = parse(input, Dialect::Auto).expect("generated program parses");
                    let out = write(&program, &[]);
                    assert_eq!(out.len(), text.len());
                    (program, out)
                },
                BatchSize::PerIteration,
            )
        });
        g.bench_with_input(BenchmarkId::new("parse", name), &text, |b, text| {
            b.iter_batched(
                || text.clone(),
                |input| black_box(parse(input, Dialect::Auto).expect("parses")),
                BatchSize::PerIteration,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, parse_write);
criterion_main!(benches);
