#!/usr/bin/env bash
# What the program does, recorded for a refactor that must not change it:
#   benches/golden/run.sh BIN OUTDIR
# runs BIN (a `polepatch` binary) on every fixture × both built-in machines:
#   patch × {default, --only-c, --tool ball:10 --tool-point tip} (output bytes, --report JSON,
#   stdout, stderr, exit code); analyze --json; simulate --json; and post --dialect heidenhain
#   of every CL fixture. Compare two such folders with benches/golden/compare.py A B.
# A build before and after a change, each run once, should compare with 0 differing files.
set -u
BIN=$1; OUT=$2
OUT=$(mkdir -p "$OUT" && cd "$OUT" && pwd)
rm -rf "${OUT:?}"/*
cd "$(dirname "$0")/../.."
for f in $(find fixtures -type f \( -name '*.nc' -o -name '*.I' -o -name '*.H' -o -name '*.h' -o -name '*.mpf' -o -name '*.ngc' \) | sort); do
  for m in mikron-ucp710 mikron-hsm600; do
    base=$OUT/$(echo "$f" | tr / _).$m
    for t in default onlyc balltip; do
      case $t in balltip) TO="--tool ball:10 --tool-point tip";; onlyc) TO="--only-c";; *) TO="";; esac
      o=$base.$t
      # shellcheck disable=SC2086
      "$BIN" patch "$f" -o "$o.out" --machine $m $TO --report "$o.json" > "$o.stdout" 2> "$o.stderr"; echo $? > "$o.rc"
    done
    "$BIN" analyze "$f" --machine $m --json > "$base.an.stdout" 2> "$base.an.stderr"; echo $? > "$base.an.rc"
    "$BIN" simulate "$f" --machine $m --json > "$base.sim.stdout" 2> "$base.sim.stderr"; echo $? > "$base.sim.rc"
  done
done
for f in $(find fixtures/cl -type f | sort); do
  for m in mikron-ucp710 mikron-hsm600; do
    o=$OUT/$(echo "$f" | tr / _).$m
    "$BIN" post "$f" --machine $m --dialect heidenhain -o "$o.post.out" --report "$o.post.json" > "$o.post.stdout" 2> "$o.post.stderr"; echo $? > "$o.post.rc"
  done
done
