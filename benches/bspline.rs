//! polepatch-bspline hot operations. Run:
//! `cargo bench -p polepatch-benches --bench bspline -- --warm-up-time 1 --measurement-time 3`
//! Figures are written up in docs/bspline.md.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use polepatch_bspline::{
    NotAKnotSystem, fit_least_squares, interpolate_not_a_knot, knots::clamped_cubic, sample_params,
};

/// CL-point-like data: ~0.5 mm spacing (±10 %), a C-axis-like signal in degrees.
fn data(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut s = Vec::with_capacity(n);
    let mut t = 0.0;
    for i in 0..n {
        s.push(t);
        t += 0.5 + 0.05 * ((i as f64) * 0.37).sin();
    }
    let y = s
        .iter()
        .map(|&x| 180.0 + 60.0 * (x * 0.05).sin() + 65.0 * ((x - 100.0) / 0.6).atan() / 1.6)
        .collect();
    (s, y)
}

fn interpolation(c: &mut Criterion) {
    let mut g = c.benchmark_group("bspline/interpolate_not_a_knot");
    for n in [100, 5_000, 10_000] {
        let (s, y) = data(n);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| interpolate_not_a_knot(black_box(&s), black_box(&y)).unwrap())
        });
    }
    g.finish();

    let mut g = c.benchmark_group("bspline/not_a_knot_system");
    let (s, y) = data(1_000);
    let sys = NotAKnotSystem::new(&s).unwrap();
    g.bench_function("solve_1000", |b| {
        b.iter(|| sys.solve(black_box(&y)).unwrap())
    });
    g.bench_function("data_row_1000", |b| {
        b.iter(|| sys.data_row(black_box(250.3), black_box(2)))
    });
    g.finish();
}

fn evaluation(c: &mut Criterion) {
    let (s, y) = data(10_000);
    let f = interpolate_not_a_knot(&s, &y).unwrap();
    let (a, e) = f.domain();
    // 100 000 sorted parameters over a 10 000-point spline: 10 per span, like sampling at
    // fs = F·Tcy = 0.05 mm (F3000, Tcy 1 ms) with 0.5 mm CL spacing.
    let ts = sample_params(a, e, (e - a) / 99_999.0);
    assert_eq!(ts.len(), 100_000);
    let mut out = vec![[0.0; 4]; ts.len()];
    let pp = f.to_pp();

    let mut g = c.benchmark_group("bspline/eval_derivs_sorted");
    g.throughput(Throughput::Elements(ts.len() as u64));
    g.bench_function("bspline_100k", |b| {
        b.iter(|| f.eval_derivs_sorted(black_box(&ts), black_box(&mut out)))
    });
    g.bench_function("pp_100k", |b| {
        b.iter(|| pp.eval_derivs_sorted(black_box(&ts), black_box(&mut out)))
    });
    g.finish();

    let mut g = c.benchmark_group("bspline/eval_derivs_single");
    g.bench_function("bspline", |b| b.iter(|| f.eval_derivs(black_box(2345.6))));
    g.bench_function("pp", |b| b.iter(|| pp.eval_derivs(black_box(2345.6))));
    g.bench_function("basis_row_order2", |b| {
        b.iter(|| f.basis_row(black_box(2345.6), black_box(2)))
    });
    g.finish();

    let mut g = c.benchmark_group("bspline/to_pp");
    g.throughput(Throughput::Elements(10_000));
    g.bench_function("10k_points", |b| b.iter(|| black_box(&f).to_pp()));
    g.finish();
}

fn least_squares(c: &mut Criterion) {
    let (s, y) = data(2_000);
    let breaks: Vec<f64> = (0..=100)
        .map(|i| s[0] + (s[1999] - s[0]) * i as f64 / 100.0)
        .collect();
    let knots = clamped_cubic(&breaks);
    let mut g = c.benchmark_group("bspline/fit_least_squares");
    g.bench_function("2000_points_102_coeffs", |b| {
        b.iter(|| fit_least_squares(black_box(&s), black_box(&y), None, &knots).unwrap())
    });
    g.finish();
}

criterion_group!(benches, interpolation, evaluation, least_squares);
criterion_main!(benches);
