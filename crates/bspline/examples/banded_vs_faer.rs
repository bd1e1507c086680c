//! Why the crate has its own banded solver: the not-a-knot collocation system at n = 5000
//! solved by `interpolate_not_a_knot` (assembly + banded LU + solve) against faer 0.24's
//! sparse LU (and, for scale, its dense LU at n = 1000) on the same matrix.
//!
//! `cargo run --release -p polepatch-bspline --example banded_vs_faer`
//!
//! Prints the median wall time of 31 runs of each, and checks the solutions agree.

use std::time::Instant;

use faer::prelude::*;
use faer::sparse::{SparseColMat, Triplet};
use polepatch_bspline::{BSpline, NotAKnotSystem, interpolate_not_a_knot, knots::not_a_knot};

fn data(n: usize) -> (Vec<f64>, Vec<f64>) {
    let s: Vec<f64> = (0..n)
        .map(|i| 0.5 * i as f64 + 0.1 * (i as f64 * 0.37).sin())
        .collect();
    let y = s.iter().map(|&x| 180.0 + 60.0 * (x * 0.05).sin()).collect();
    (s, y)
}

/// Collocation triplets `B_j(s_i)` from the public basis rows.
fn triplets(s: &[f64]) -> Vec<Triplet<usize, usize, f64>> {
    let n = s.len();
    let shape = BSpline::new(3, not_a_knot(s), vec![0.0; n]).unwrap();
    let mut t = Vec::with_capacity(4 * n);
    for (i, &si) in s.iter().enumerate() {
        let row = shape.basis_row(si, 0);
        for (k, &w) in row.weights.iter().enumerate() {
            if w != 0.0 {
                t.push(Triplet::new(i, row.first + k, w));
            }
        }
    }
    t
}

fn median_us(mut f: impl FnMut()) -> f64 {
    let mut v: Vec<f64> = (0..31)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let n = 5000;
    let (s, y) = data(n);
    let ours = interpolate_not_a_knot(&s, &y).unwrap();
    let trips = triplets(&s);
    let rhs = Col::<f64>::from_fn(n, |i| y[i]);

    let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trips).unwrap();
    let x = a.sp_lu().unwrap().solve(&rhs);
    let diff = (0..n)
        .map(|i| (x[i] - ours.coeffs()[i]).abs())
        .fold(0.0, f64::max);
    println!("n = {n}: max |c_banded - c_faer_sparse| = {diff:.1e}");
    assert!(diff < 1e-9);

    let t_ours = median_us(|| {
        std::hint::black_box(interpolate_not_a_knot(&s, &y).unwrap());
    });
    let sys = NotAKnotSystem::new(&s).unwrap();
    let t_ours_solve = median_us(|| {
        std::hint::black_box(sys.solve(&y).unwrap());
    });
    let t_faer_all = median_us(|| {
        let t = triplets(&s);
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
        std::hint::black_box(a.sp_lu().unwrap().solve(&rhs));
    });
    let t_faer_lu = median_us(|| {
        std::hint::black_box(a.sp_lu().unwrap().solve(&rhs));
    });
    println!("banded: interpolate_not_a_knot (assemble + factor + solve)  {t_ours:9.1} µs");
    println!("banded: NotAKnotSystem::solve (pre-factored)                {t_ours_solve:9.1} µs");
    println!("faer sparse LU: assemble + sp_lu + solve                    {t_faer_all:9.1} µs");
    println!("faer sparse LU: sp_lu + solve only (matrix prebuilt)        {t_faer_lu:9.1} µs");

    let m = 1000;
    let (s, y) = data(m);
    let dense = {
        let shape = BSpline::new(3, not_a_knot(&s), vec![0.0; m]).unwrap();
        let mut d = Mat::<f64>::zeros(m, m);
        for (i, &si) in s.iter().enumerate() {
            let row = shape.basis_row(si, 0);
            for (k, &w) in row.weights.iter().enumerate() {
                if row.first + k < m {
                    d[(i, row.first + k)] = w;
                }
            }
        }
        d
    };
    let rhs = Col::<f64>::from_fn(m, |i| y[i]);
    let t_dense = median_us(|| {
        std::hint::black_box(dense.partial_piv_lu().solve(&rhs));
    });
    let t_ours_1000 = median_us(|| {
        std::hint::black_box(interpolate_not_a_knot(&s, &y).unwrap());
    });
    println!("n = {m}: faer dense partial_piv_lu + solve                  {t_dense:9.1} µs");
    println!("n = {m}: banded interpolate_not_a_knot                      {t_ours_1000:9.1} µs");
}
