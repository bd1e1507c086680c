//! Write the zigzag finishing program of the whole-process figure (issue 21: "the 100-zone
//! zigzag ≤ 0.2 s whole process"): `passes` passes at F2000, 1 mm spacing, domain-rule
//! post (A flips), 0.05°–4° from the pole, each pass its own run between rapid moves
//! (`polepatch_fixturegen::zigzag_program`, the program of `benches/zigzag_patch.rs`).
//!
//! `cargo run --release -p polepatch-benches --example zigzag -- PASSES OUT [POST [D,D,…
//! [A|B]]]` (POST `domain` — the default — or `continuous`: the primary axis ≥ 0 and C
//! swinging; the pole distances in degrees, cycled over the passes; the primary axis'
//! letter, A by default), then
//! `/usr/bin/time -v target/release/polepatch patch OUT -o /tmp/out.I -m mikron-ucp710`.

use polepatch_fixturegen::{Pass, zigzag_program};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(3..=6).contains(&args.len()) {
        eprintln!("usage: zigzag PASSES OUT [domain|continuous [D,D,... [A|B]]]");
        std::process::exit(1);
    }
    let passes: usize = args[1].parse().expect("PASSES is a number");
    let base = Pass {
        domain_rule: args.get(3).is_none_or(|p| p != "continuous"),
        b_axis: args.get(5).is_some_and(|l| l == "B"),
        ..Pass::default()
    };
    let distances: Vec<f64> = args
        .get(4)
        .map_or(vec![0.1, 0.5, 1.0, 2.0, 4.0, 0.05], |d| {
            d.split(',')
                .map(|x| x.parse().expect("a pole distance in degrees"))
                .collect()
        });
    let text = zigzag_program(&base, passes, &distances, "ZIGZAG");
    std::fs::write(&args[2], text).expect("write OUT");
}
