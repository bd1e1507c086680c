//! Parse + write throughput on a large synthetic Heidenhain ISO program without edits.
//!
//! `cargo run --release -p polepatch-nc --example throughput [MB]` (default 50 MB).
//! A measurement, not a test: it prints MB/s and never fails on speed. Besides wall
//! time it reports on-CPU time of this thread (Linux `/proc/thread-self/schedstat`), which
//! is what one core delivers when other jobs share the machine.

use polepatch_nc::{Dialect, parse, runs, write};
use std::time::Instant;

/// Nanoseconds this thread has run on a CPU, if the kernel says.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// (user, system) CPU seconds of this thread, 10 ms resolution (`/proc/thread-self/stat`).
fn user_sys() -> Option<(f64, f64)> {
    let s = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    let rest = &s[s.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    // Fields 14 and 15 of stat(5) (utime, stime), counted here from field 3.
    Some((
        f.get(11)?.parse::<f64>().ok()? / 100.0,
        f.get(12)?.parse::<f64>().ok()? / 100.0,
    ))
}

fn main() {
    let mb: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(50);
    let mut text = Vec::with_capacity(mb << 20);
    text.extend_from_slice(b"%BIG G71 *\nN10 G90 *\nN20 T5 *\nN30 M128 *\nN40 G01 X+0 Y+0 Z-8 A+14.825 C+137.259 F2000 *\n");
    let mut n = 50u64;
    while text.len() < mb << 20 {
        let k = n as f64;
        let line = format!(
            "N{n} X+{:.3} Y{:+.3} Z-8 A+{:.3} C+{:.3} *\n",
            k * 0.01 % 500.0,
            (k * 0.001).sin() * 20.0,
            1.0 + (k * 0.0003).cos().abs() * 14.0,
            (k * 0.07) % 360.0
        );
        text.extend_from_slice(line.as_bytes());
        n += 10;
    }
    let size_mb = text.len() as f64 / 1e6;
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let input = text.clone();
        let c0 = cpu_ns();
        let us0 = user_sys();
        let t0 = Instant::now();
        let program = parse(input, Dialect::Auto).expect("synthetic program parses");
        let t_parse = t0.elapsed().as_secs_f64();
        let out = write(&program, &[]);
        let t_all = t0.elapsed().as_secs_f64();
        let c_all = cpu_ns().zip(c0).map(|(c1, c0)| (c1 - c0) as f64 * 1e-9);
        if let Some(((u1, s1), (u0, s0))) = user_sys().zip(us0) {
            println!(
                "  parse+write: user {:.2} s, system (page faults of fresh memory) {:.2} s",
                u1 - u0,
                s1 - s0
            );
        }
        assert!(out == text);
        let t1 = Instant::now();
        let r = runs(&program);
        let t_runs = t1.elapsed().as_secs_f64();
        println!(
            "{size_mb:.1} MB, {} blocks, {} words: parse {:.0} MB/s, parse+write {:.0} MB/s (on-CPU {:.0} MB/s); runs {:.0} MB/s ({} runs)",
            program.blocks.len(),
            program.words.len(),
            size_mb / t_parse,
            size_mb / t_all,
            c_all.map_or(f64::NAN, |c| size_mb / c),
            size_mb / t_runs,
            r.len()
        );
        best = best.min(c_all.unwrap_or(t_all));
    }
    println!(
        "best parse+write: {:.0} MB/s (on-CPU time where available)",
        size_mb / best
    );
}
