#!/usr/bin/env bash
# Points modified on passes comparable to G16's test path (§4.3: 12 CL points modified,
# UCP710, 1 m/min, 1 mm discretisation, domain-rule post so A flips), for
# docs/g16-comparison.md. Run from the repository root.
set -euo pipefail
dir=target/g16-comparison
rm -rf "$dir" && mkdir -p "$dir"
cargo build -q --release -p polepatch -p polepatch-fixturegen --examples
for r in 5 15; do
  for d in 0.05 0.2 0.5 1 2 4; do
    cargo run -q --release -p polepatch-fixturegen --example pass -- heidenhain \
      pole_distance_deg=$d circle_radius_deg=$r half_sweep_deg=60 length_mm=60 \
      spacing_mm=1 feed_mm_min=1000 domain_rule=true > "$dir/r${r}-d${d}.I"
  done
done
cargo run -q --release -- patch "$dir" --out-dir target/g16-comparison-out --machine mikron-ucp710 \
  --csv docs/g16-comparison.csv

