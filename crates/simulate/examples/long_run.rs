//! Write a program that is one G1 run of N points, for measuring the simulator's memory
//! on a long motion (`/usr/bin/time -v polepatch simulate OUT --machine mikron-ucp710
//! --trajectory /dev/null`):
//!
//! `cargo run --release -p polepatch-simulate --example long_run -- N OUT`
//!
//! Fanuc words for an A-C table machine (`mikron-ucp710`), TCPM on (`G43.4`), one `F`
//! on the first block: a slow helix of the tool tip (radius 20 mm, points 0.1 mm apart,
//! Z rising and falling 2 mm over 30 000 points) with A swinging 20° ± 5° and C turning
//! 0.01° a point — every point a block (G1 modal), no stop between them.

use std::f64::consts::TAU;
use std::io::Write;

/// Radius of the helix, mm.
const RADIUS_MM: f64 = 20.0;
/// Distance between points along the circle, mm.
const STEP_MM: f64 = 0.1;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (Some(n), Some(out)) = (
        args.get(1).and_then(|n| n.parse::<usize>().ok()),
        args.get(2),
    ) else {
        eprintln!("usage: long_run N OUT");
        std::process::exit(2);
    };
    let file = std::fs::File::create(out).unwrap_or_else(|e| {
        eprintln!("long_run: {out}: {e}");
        std::process::exit(1);
    });
    let mut w = std::io::BufWriter::new(file);
    let mut text = String::from(
        "%\nO1000\n(one G1 run: a slow helix, A-C)\nG90 G21 G94\nT1 M6\nS12000 M3\nG43.4 H1\n",
    );
    let dtheta = STEP_MM / RADIUS_MM;
    for k in 0..n {
        let kf = k as f64;
        let th = kf * dtheta;
        let x = RADIUS_MM * th.cos();
        let y = RADIUS_MM * th.sin();
        let z = -5.0 + 2.0 * (TAU * kf / 30_000.0).sin();
        let a = 20.0 + 5.0 * (TAU * kf / 20_000.0).sin();
        let c = 0.01 * kf;
        let (g1, feed) = if k == 0 { ("G1 ", " F3000") } else { ("", "") };
        // Six decimals: with four, the rounding (±0.05 µm over 0.1 mm) is a third
        // derivative the jerk limits feel, and the motion crawls (simulated 9× Equation 6).
        text.push_str(&format!(
            "{g1}X{x:.6} Y{y:.6} Z{z:.6} A{a:.6} C{c:.4}{feed}\n"
        ));
        if text.len() > 1 << 16 {
            w.write_all(text.as_bytes()).expect("write");
            text.clear();
        }
    }
    text.push_str("M30\n%\n");
    w.write_all(text.as_bytes()).expect("write");
    w.flush().expect("write");
}
