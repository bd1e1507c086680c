//! `polepatch-fixturegen DIR [SHOP_DIR]`: writes the committed set of synthetic fixtures into
//! DIR (and the shop forms of issue 20 into SHOP_DIR).

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
    // The shop forms (issue 20) of two passes: a flip at 0.5° and a swing at 1°, A-C.
    if let Some(shop) = std::env::args().nth(2).map(PathBuf::from) {
        std::fs::create_dir_all(&shop)?;
        let mut count = 0;
        for (stem, domain_rule, d) in [("ac-flip-d0.5", true, 0.5), ("ac-swing-d1", false, 1.0)] {
            let pass = polepatch_fixturegen::shop_pass(domain_rule, d);
            for form in polepatch_fixturegen::ShopForm::ALL {
                let name = stem.to_uppercase().replace(['.', '-'], "_");
                let text = polepatch_fixturegen::shop_program(&pass, form, &name);
                std::fs::write(shop.join(form.file_name(stem)), text)?;
                count += 1;
            }
            // Its G94 ISO twin, for the equality tests.
            let name = stem.to_uppercase().replace(['.', '-'], "_");
            let text = program(&pass, Dialect::Fanuc, &name);
            std::fs::write(shop.join(format!("{stem}-fanuc-g94.nc")), text)?;
            count += 1;
        }
        eprintln!("wrote {count} programs to {}", shop.display());
    }
    Ok(())
}
