//! Write a large generated program with no point near the pole, for whole-process
//! measurements (`/usr/bin/time -v polepatch patch …`):
//! `cargo run --release -p polepatch-benches --example big_program -- MB heidenhain|fanuc OUT [A|B]`

use polepatch_benches::{Style, no_zone_program};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!("usage: big_program MB heidenhain|fanuc OUT [A|B]");
        std::process::exit(1);
    }
    let mb: usize = args[1].parse().expect("MB is a number");
    let style = match args[2].as_str() {
        "heidenhain" => Style::Heidenhain,
        "fanuc" => Style::Fanuc,
        other => panic!("unknown style {other}"),
    };
    let primary = args.get(4).and_then(|s| s.chars().next()).unwrap_or('A');
    let text = no_zone_program(mb * 1_000_000, style, primary);
    std::fs::write(&args[3], &text).expect("write");
    println!("{} bytes", text.len());
}
