//! Planted paths for the tests of this crate.

use crate::options::round_written;
use crate::path::Path;
use polepatch_kinematics::Machine;

/// A built-in machine.
pub(crate) fn machine(name: &str) -> Machine {
    Machine::builtin(name).expect("built-in machine")
}

/// A straight pass s = X whose tool axis sweeps past the pole at angular distance
/// `d_deg`: tool axis ∝ (sin d, sin(τ(s)), 1), τ sweeping 0.4°/mm (G16 eq. 1 kinematics,
/// A-C). `flip`: primary and C by the domain rule (sign of j: A flips and C jumps ~180°
/// where j crosses 0); else the continuous branch A ≥ 0 (C swings ~180°). Values rounded
/// to 3 decimals, as a post writes them.
pub(crate) fn planted(n: usize, spacing: f64, d_deg: f64, flip: bool, feed: f64) -> Path {
    let mid = (n - 1) as f64 * spacing / 2.0;
    let mut s_mm = Vec::new();
    let mut axes = Vec::new();
    let mut prev_c: Option<f64> = None;
    for k in 0..n {
        let s = k as f64 * spacing;
        let v = [
            d_deg.to_radians().sin(),
            ((s - mid) * 0.4).to_radians().sin(),
            1.0,
        ];
        let nv = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let (i, j, kk) = (v[0] / nv, v[1] / nv, v[2] / nv);
        // i = sin C sin A, j = −cos C sin A, k = cos A.
        let mut a = kk.clamp(-1.0, 1.0).acos().to_degrees();
        let mut c = i.atan2(-j).to_degrees();
        if flip && j > 0.0 {
            a = -a;
            c = (-i).atan2(j).to_degrees();
        }
        if let Some(pc) = prev_c
            && !flip
        {
            while c - pc > 180.0 {
                c -= 360.0;
            }
            while c - pc < -180.0 {
                c += 360.0;
            }
        }
        let c = round_written(c, 3);
        prev_c = Some(c);
        s_mm.push(s);
        axes.push([s, 0.0, 0.0, round_written(a, 3), c]);
    }
    Path {
        s_mm,
        axes,
        feed_mm_min: feed,
    }
}

/// The cut of C17's `%SING` (N110..N610), s = X: 51 points, A down to 1° at X = 25.
pub(crate) fn sing_path() -> Path {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/c17/SING.I"
    ))
    .unwrap();
    let mut axes = Vec::new();
    for line in text.lines() {
        let nnum: usize = match line.strip_prefix('N').and_then(|r| r.split(' ').next()) {
            Some(v) => v.parse().unwrap_or(0),
            None => continue,
        };
        if !(110..=610).contains(&nnum) {
            continue;
        }
        let word = |l: char| -> f64 {
            line.split(' ')
                .find_map(|w| w.strip_prefix(l))
                .unwrap()
                .parse()
                .unwrap()
        };
        axes.push([word('X'), 0.0, -8.0, word('A'), word('C')]);
    }
    assert_eq!(axes.len(), 51);
    Path {
        s_mm: axes.iter().map(|q| q[0]).collect(),
        axes,
        feed_mm_min: 2000.0,
    }
}

/// A pass that starts near the pole and spirals out of it (the shape of a real NX post's
/// run on a Mori Seiki NMV5000): the primary axis rises from `p0_deg` at `p_rate` °/mm
/// while C turns at a constant `c_rate` °/mm, the tool tip moving along X at `spacing`
/// mm per point. Far from the pole C still crawls — by the program's own doing: its rate
/// is what the table turns round with the tool. Values rounded to 3 decimals.
pub(crate) fn spiral(
    n: usize,
    spacing: f64,
    (p0_deg, p_rate): (f64, f64),
    c_rate: f64,
    feed: f64,
) -> Path {
    let s_mm: Vec<f64> = (0..n).map(|k| k as f64 * spacing).collect();
    let axes = s_mm
        .iter()
        .map(|&s| {
            [
                s,
                0.0,
                0.0,
                -round_written(p0_deg + p_rate * s, 3),
                round_written(315.0 + c_rate * s, 3),
            ]
        })
        .collect();
    Path {
        s_mm,
        axes,
        feed_mm_min: feed,
    }
}
