//! Write the zigzag finishing program of the whole-process figure (issue 21: "the 100-zone
//! zigzag ≤ 0.2 s whole process"): `passes` passes at F2000, 1 mm spacing, domain-rule
//! post (A flips), 0.05°–4° from the pole, each pass its own run between rapid moves
//! (`polepatch_fixturegen::zigzag_program`, the program of `benches/zigzag_patch.rs`).
//!
//! `cargo run --release -p polepatch-benches --example zigzag -- PASSES OUT`, then
//! `/usr/bin/time -v target/release/polepatch patch OUT -o /tmp/out.I -m mikron-ucp710`.

use polepatch_fixturegen::{Pass, zigzag_program};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        eprintln!("usage: zigzag PASSES OUT");
        std::process::exit(1);
    }
    let passes: usize = args[1].parse().expect("PASSES is a number");
    let base = Pass {
        domain_rule: true,
        ..Pass::default()
    };
    let text = zigzag_program(&base, passes, &[0.1, 0.5, 1.0, 2.0, 4.0, 0.05], "ZIGZAG");
    std::fs::write(&args[2], text).expect("write OUT");
}
