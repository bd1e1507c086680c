//! Shared checks of the simulator tests.

#![allow(dead_code)]

use polepatch_kinematics::Machine;
use polepatch_patcher::Path;
use polepatch_simulate::{SimOptions, Simulation, Step, simulate};

/// Finite differences of a trajectory may exceed a limit by this fraction (plus
/// [`FD_ABS`] of the limit): a difference quotient over a few cycles of a motion that
/// switches its jerk within them is not the derivative at one instant.
pub const FD_REL: f64 = 0.01;
/// … plus this fraction of the limit, for states near rest where the quotients are tiny.
pub const FD_ABS: f64 = 1e-6;

/// A trajectory sampled every cycle: time, s, feed and the axis values.
pub struct Trajectory {
    pub t: Vec<f64>,
    pub s: Vec<f64>,
    pub feed: Vec<f64>,
    pub q: Vec<[f64; 5]>,
    pub sim: Simulation,
    pub cycle: Vec<bool>,
}

/// Simulate with every cycle handed out.
pub fn trajectory(parts: &[Path], m: &Machine) -> Trajectory {
    let mut tr = Trajectory {
        t: Vec::new(),
        s: Vec::new(),
        feed: Vec::new(),
        q: Vec::new(),
        sim: Simulation {
            parts: Vec::new(),
            time_s: 0.0,
            clips: 0,
            steps: 0,
        },
        cycle: Vec::new(),
    };
    let opts = SimOptions {
        every_cycle: true,
        ..SimOptions::default()
    };
    let sim = simulate(parts, m, &opts, &mut |st: &Step, geo| {
        tr.t.push(st.t_s);
        tr.s.push(st.s_mm);
        tr.feed.push(st.feed_mm_s);
        tr.q.push(geo.axes(st.s_mm));
        tr.cycle.push(st.cycle);
    })
    .expect("simulates");
    tr.sim = sim;
    tr
}

/// Largest ratio |finite difference| / limit for V, A, J of each axis, over the cycles
/// (uniform spacing Tcy; the last, partial cycle is left out).
pub fn fd_ratios(tr: &Trajectory, m: &Machine) -> [[f64; 3]; 5] {
    let dt = m.tcy_s;
    let mut worst = [[0.0f64; 3]; 5];
    // Uniform stretch: every state after the first is one cycle after the previous.
    let n = tr.t.len();
    let last = (1..n).rev().find(|&k| tr.cycle[k]).unwrap_or(0);
    for k in 0..last {
        for (i, w) in worst.iter_mut().enumerate() {
            let l = m.limits[i];
            let q = |o: usize| tr.q[k + o][i];
            if k < last {
                let v = (q(1) - q(0)) / dt;
                w[0] = w[0].max(v.abs() / l.v);
            }
            if k + 2 <= last {
                let a = (q(2) - 2.0 * q(1) + q(0)) / (dt * dt);
                w[1] = w[1].max(a.abs() / l.a);
            }
            if k + 3 <= last {
                let j = (q(3) - 3.0 * q(2) + 3.0 * q(1) - q(0)) / (dt * dt * dt);
                w[2] = w[2].max(j.abs() / l.j);
            }
        }
    }
    worst
}

/// Assert every finite-difference ratio is within the limit (with [`FD_REL`]).
pub fn assert_within_limits(tr: &Trajectory, m: &Machine, what: &str) {
    let w = fd_ratios(tr, m);
    for (i, r) in w.iter().enumerate() {
        for (k, name) in ["V", "A", "J"].iter().enumerate() {
            assert!(
                r[k] <= 1.0 + FD_REL + FD_ABS,
                "{what}: axis {i} {name}: finite differences reach {:.4} of the limit ({w:?})",
                r[k]
            );
        }
    }
}

/// A straight line of `len` mm along axis `axis` (0 X, 1 Y, 2 Z), points every
/// `spacing` mm, rotary axes still.
pub fn line(axis: usize, len: f64, spacing: f64, feed_mm_min: f64) -> Path {
    let n = (len / spacing).round() as usize;
    let s_mm: Vec<f64> = (0..=n).map(|k| len * k as f64 / n as f64).collect();
    let axes = s_mm
        .iter()
        .map(|&s| {
            let mut q = [10.0, -20.0, 5.0, 20.0, 30.0];
            q[axis] += s;
            q
        })
        .collect();
    Path {
        s_mm,
        axes,
        feed_mm_min,
    }
}

/// The path through `axes` at `feed_mm_min`, s the tool tip's chord lengths (X Y Z).
pub fn chord_path(axes: Vec<[f64; 5]>, feed_mm_min: f64) -> Path {
    let mut s_mm = vec![0.0];
    for k in 1..axes.len() {
        let d: f64 = (0..3)
            .map(|i| (axes[k][i] - axes[k - 1][i]).powi(2))
            .sum::<f64>()
            .sqrt();
        s_mm.push(s_mm[k - 1] + d);
    }
    Path {
        s_mm,
        axes,
        feed_mm_min,
    }
}

pub mod memory;
pub mod reference;
