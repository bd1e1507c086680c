//! Write a large program for whole-process measurements (`/usr/bin/time -v polepatch
//! patch …`):
//!
//! - `big_program MB heidenhain|fanuc OUT [A|B]`: generated 5-axis G1 with no point near
//!   the pole (no zone);
//! - `big_program MB heidenhain OUT A FILE K`: the same with the body of program FILE
//!   (its lines but the first and the last) inserted K times, evenly spread;
//! - `big_program MB repeat OUT FILE`: the body of FILE repeated to MB.
//!
//! `cargo run --release -p polepatch-benches --example big_program -- …`

use polepatch_benches::{Style, no_zone_program};

/// The lines of a program but its first and last (`%NAME G71 *` … `N999999 %NAME G71 *`).
fn body(path: &str) -> String {
    let text = std::fs::read_to_string(path).expect("read FILE");
    let lines: Vec<&str> = text.lines().collect();
    let inner = &lines[1.min(lines.len())..lines.len().saturating_sub(1)];
    inner.iter().map(|l| format!("{l}\n")).collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 4 {
        eprintln!(
            "usage: big_program MB heidenhain|fanuc OUT [A|B [FILE K]] | big_program MB repeat OUT FILE"
        );
        std::process::exit(1);
    }
    let mb: usize = args[1].parse().expect("MB is a number");
    let bytes = mb * 1_000_000;
    let text = if args[2] == "repeat" {
        let body = body(args.get(4).expect("FILE"));
        let mut t = String::from("%BIG G71 *\n");
        while t.len() < bytes {
            t.push_str(&body);
        }
        t.push_str("N999999 %BIG G71 *\n");
        t.into_bytes()
    } else {
        let style = match args[2].as_str() {
            "heidenhain" => Style::Heidenhain,
            "fanuc" => Style::Fanuc,
            other => panic!("unknown style {other}"),
        };
        let primary = args.get(4).and_then(|s| s.chars().next()).unwrap_or('A');
        let text = no_zone_program(bytes, style, primary);
        match (args.get(5), args.get(6)) {
            (Some(file), Some(k)) => {
                let body = body(file);
                let k: usize = k.parse().expect("K is a number");
                let lines: Vec<&[u8]> = text.split_inclusive(|&b| b == b'\n').collect();
                let mut t = Vec::with_capacity(text.len() + k * body.len());
                for (i, l) in lines.iter().enumerate() {
                    // After the header lines, before the last line.
                    if k > 0 && i > 2 && i % (lines.len() / k).max(1) == 0 && i + 1 < lines.len() {
                        t.extend_from_slice(body.as_bytes());
                    }
                    t.extend_from_slice(l);
                }
                t
            }
            _ => text,
        }
    };
    std::fs::write(&args[3], &text).expect("write");
    println!("{} bytes", text.len());
}
