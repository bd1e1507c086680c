#!/bin/sh
# Median and p90 over the zones of the last `cargo bench --bench zone_solve` run: each
# benchmark's criterion median (target/criterion/patcher_zone_solve/*/new/estimates.json),
# then the median and p90 of those, for the default method (both/...).
set -eu
dir="${CARGO_TARGET_DIR:-target}/criterion/patcher_zone_solve"
for f in "$dir"/both_*/new/estimates.json; do
  grep -o '"median":{"confidence_interval":{[^}]*},"point_estimate":[0-9.e+-]*' "$f" |
    sed 's/.*"point_estimate"://'
done | sort -g | awk '
  { v[NR] = $1 / 1e6 }
  END {
    if (NR == 0) { print "no estimates (run the bench first)"; exit 1 }
    m = v[int((NR + 1) / 2)]; p = v[int(0.9 * NR + 0.999)]
    printf "%d zones: median %.3f ms, p90 %.3f ms, max %.3f ms\n", NR, m, p, v[NR]
  }'
