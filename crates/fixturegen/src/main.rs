//! `polepatch-fixturegen DIR`: writes the committed set of synthetic fixtures into DIR.

use polepatch_fixturegen::{Dialect, Pass, program};
use std::path::PathBuf;

/// Pole distances of the committed set, degrees (0 = through the pole, 20 = nowhere near).
const DISTANCES: [f64; 8] = [0.0, 0.01, 0.1, 0.5, 1.0, 2.0, 4.0, 20.0];

fn main() -> std::io::Result<()> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "fixtures/generated".into()),
    );
    std::fs::create_dir_all(&dir)?;
    let mut count = 0;
    for (di, dialect) in Dialect::ALL.into_iter().enumerate() {
        for b_axis in [false, true] {
            for domain_rule in [true, false] {
                for (k, d) in DISTANCES.into_iter().enumerate() {
                    let pass = Pass {
                        pole_distance_deg: d,
                        b_axis,
                        domain_rule,
                        // Vary feed and spacing across the set so no constant is tuned to one.
                        feed_mm_min: [2000.0, 1500.0, 3000.0][di],
                        spacing_mm: if k % 2 == 0 { 1.0 } else { 0.5 },
                        // The domain rule flips where the path crosses its C = ±90° boundary:
                        // across j = 0 for A-C (azimuth 0), across i = 0 for B-C (azimuth 90°).
                        azimuth_deg: if b_axis { 90.0 } else { 0.0 },
                        ..Pass::default()
                    };
                    let kin = if b_axis { "bc" } else { "ac" };
                    let branch = if domain_rule { "flip" } else { "swing" };
                    let stem = format!("{}-{kin}-{branch}-d{d}", dialect.name());
                    let name = stem.to_uppercase().replace(['.', '-'], "_");
                    let text = program(&pass, dialect, &name);
                    std::fs::write(dir.join(format!("{stem}.{}", dialect.extension())), text)?;
                    count += 1;
                }
            }
        }
    }
    eprintln!("wrote {count} programs to {}", dir.display());
    Ok(())
}
