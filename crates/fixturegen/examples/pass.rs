//! Write one synthetic pass to stdout:
//! `cargo run -p polepatch-fixturegen --example pass -- DIALECT key=value ...`
//! with keys as the fields of `Pass` (`pole_distance_deg=0.5 b_axis=true ...`).

use polepatch_fixturegen::{Dialect, Pass, program};

fn main() {
    let mut args = std::env::args().skip(1);
    let dialect = match args.next().as_deref() {
        Some("heidenhain") => Dialect::Heidenhain,
        Some("sinumerik") => Dialect::Sinumerik,
        Some("fanuc") => Dialect::Fanuc,
        _ => {
            eprintln!("usage: pass heidenhain|sinumerik|fanuc [key=value ...]");
            std::process::exit(2);
        }
    };
    let mut p = Pass::default();
    for kv in args {
        let (k, v) = kv
            .split_once('=')
            .unwrap_or_else(|| panic!("expected key=value, got {kv}"));
        let f = || {
            v.parse::<f64>()
                .unwrap_or_else(|_| panic!("{k}: '{v}' is not a number"))
        };
        match k {
            "pole_distance_deg" => p.pole_distance_deg = f(),
            "circle_radius_deg" => p.circle_radius_deg = f(),
            "half_sweep_deg" => p.half_sweep_deg = f(),
            "azimuth_deg" => p.azimuth_deg = f(),
            "length_mm" => p.length_mm = f(),
            "spacing_mm" => p.spacing_mm = f(),
            "feed_mm_min" => p.feed_mm_min = f(),
            "b_axis" => p.b_axis = v == "true",
            "domain_rule" => p.domain_rule = v == "true",
            "rotary_decimals" => p.rotary_decimals = f() as usize,
            _ => panic!("unknown key {k}"),
        }
    }
    print!("{}", program(&p, dialect, "PASS"));
}
