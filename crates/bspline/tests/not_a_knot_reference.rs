//! Not-a-knot interpolation against scipy's `CubicSpline` on committed reference data
//! (`tests/data/not_a_knot_reference.csv`, made by `tests/data/make_reference.py`; see the
//! note there). Values and the three derivatives must agree to 1e-9 relative, relative to
//! the largest magnitude of that derivative over the set's evaluation points, or the data
//! magnitude over length^k if larger (a derivative passing through zero has no relative
//! error of its own).

#![allow(clippy::needless_range_loop)]

use polepatch_bspline::{NotAKnotSystem, interpolate_not_a_knot};

const CSV: &str = include_str!("data/not_a_knot_reference.csv");

struct Set {
    name: String,
    s: Vec<f64>,
    y: Vec<f64>,
    /// (t, [f, f', f'', f'''])
    eval: Vec<(f64, [f64; 4])>,
}

fn sets() -> Vec<Set> {
    let mut out: Vec<Set> = Vec::new();
    for line in CSV.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 7, "bad line {line}");
        if out.last().is_none_or(|s| s.name != f[0]) {
            out.push(Set {
                name: f[0].to_string(),
                s: vec![],
                y: vec![],
                eval: vec![],
            });
        }
        let set = out.last_mut().unwrap();
        let num = |i: usize| f[i].parse::<f64>().unwrap();
        match f[1] {
            "data" => {
                set.s.push(num(2));
                set.y.push(num(3));
            }
            "eval" => set.eval.push((num(2), [num(3), num(4), num(5), num(6)])),
            k => panic!("unknown kind {k}"),
        }
    }
    out
}

#[test]
fn matches_scipy_cubic_spline() {
    let sets = sets();
    let names: Vec<&str> = sets.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        ["n2", "n3", "n4", "n5", "uneven12", "n50", "c_swing30"]
    );
    for set in &sets {
        let f = interpolate_not_a_knot(&set.s, &set.y).unwrap();
        let pp = f.to_pp();
        let ts: Vec<f64> = set.eval.iter().map(|e| e.0).collect();
        let mut sorted = vec![[0.0; 4]; ts.len()];
        f.eval_derivs_sorted(&ts, &mut sorted);
        // Floor: the data magnitude over length^k (a parabola's third derivative is zero up
        // to rounding noise).
        let ymax = set.y.iter().fold(0.0f64, |m, y| m.max(y.abs()));
        let len = set.s[set.s.len() - 1] - set.s[0];
        let mut scale = [0.0f64; 4];
        for (k, sc) in scale.iter_mut().enumerate() {
            *sc = ymax / len.powi(k as i32);
        }
        for (_, v) in &set.eval {
            for k in 0..4 {
                scale[k] = scale[k].max(v[k].abs());
            }
        }
        let mut worst = [0.0f64; 4];
        for (i, (t, want)) in set.eval.iter().enumerate() {
            for got in [f.eval_derivs(*t), sorted[i], pp.eval_derivs(*t)] {
                for k in 0..4 {
                    let err = (got[k] - want[k]).abs() / scale[k];
                    worst[k] = worst[k].max(err);
                    assert!(
                        err <= 1e-9,
                        "{}: t = {t}, derivative {k}: ours {} scipy {} (rel {err:e})",
                        set.name,
                        got[k],
                        want[k]
                    );
                }
            }
        }
        eprintln!(
            "{:>10}: n = {:>2}, worst relative error per order {:.1e} {:.1e} {:.1e} {:.1e}",
            set.name,
            set.s.len(),
            worst[0],
            worst[1],
            worst[2],
            worst[3]
        );
    }
}

#[test]
fn data_rows_match_scipy_on_the_c_swing() {
    // The patcher's view: derivatives as linear functions of the data values.
    let sets = sets();
    let set = sets.iter().find(|s| s.name == "c_swing30").unwrap();
    let sys = NotAKnotSystem::new(&set.s).unwrap();
    for (t, want) in set.eval.iter().step_by(7) {
        for k in 0..4 {
            let m = sys.data_row(*t, k);
            let got: f64 = m.iter().zip(&set.y).map(|(m, y)| m * y).sum();
            assert!(
                (got - want[k]).abs() <= 1e-9 * want[k].abs().max(1.0),
                "t = {t}, derivative {k}: {got} vs {}",
                want[k]
            );
        }
    }
}
