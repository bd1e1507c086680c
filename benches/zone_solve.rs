//! Time to patch one singular zone (SPEC §6, issue 21: median ≤ 1 ms, p90 ≤ 3 ms on one
//! core): `patch_path` on whole runs that hold one zone, with the default method (both
//! rotary axes: re-selection or the joint patch), on
//! - the held-out-like zones of `polepatch_benches::held_out_zones` (seed `0x5EED_0021`,
//!   24 zones: feeds 800–5000, spacings 0.25–1 mm, flips and swings 0–5° from the pole,
//!   both machines, pinned and free ends), and
//! - C17's `SING.I` main run on both machines;
//!
//! and `--only-c` on SING. The figure includes detection, every solve, verification and
//! the report figures. Run (one thread; the machine is shared):
//! `RAYON_NUM_THREADS=1 cargo bench -p polepatch-benches --bench zone_solve -- --warm-up-time 1 --measurement-time 3`
//! then `benches/zone_medians.sh` for the median and p90 over the zones. Figures are
//! written up in docs/performance-patcher.md.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use polepatch::load_nc;
use polepatch_benches::held_out_zones;
use polepatch_kinematics::Machine;
use polepatch_patcher::{PatchAxes, PatchOptions, Path, patch_path};

/// The runs of SING that hold a zone on `machine`.
fn sing_runs(machine: &Machine) -> Vec<Path> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let bytes = std::fs::read(root.join("fixtures/c17/SING.I")).expect("fixture");
    let lp = load_nc(&bytes, "SING", machine, None).expect("parsable fixture");
    lp.runs
        .into_iter()
        .filter_map(|r| {
            let path = r.path.ok()?;
            let res = patch_path(&path, machine, &PatchOptions::default()).ok()?;
            (!res.zones.is_empty()).then_some(path)
        })
        .collect()
}

fn zone_solve(c: &mut Criterion) {
    let mut g = c.benchmark_group("patcher/zone_solve");
    g.sample_size(10);
    for (k, h) in held_out_zones(0x5EED_0021, 24).into_iter().enumerate() {
        let opts = PatchOptions {
            keep_last_point: h.keep_last_point,
            p_decimals: h.decimals,
            c_decimals: h.decimals,
            ..PatchOptions::default()
        };
        let res = patch_path(&h.path, &h.machine, &opts).unwrap();
        if res.zones.len() != 1 {
            eprintln!(
                "held-out {k} ({}): {} zones, skipped from the per-zone set",
                h.label,
                res.zones.len()
            );
            continue;
        }
        g.bench_function(format!("both/held-out/{k:02}"), |b| {
            b.iter(|| patch_path(black_box(&h.path), &h.machine, &opts).unwrap())
        });
    }
    // C17's SING is an A-C program: the A-C machine (the B-C one refuses it, issue 29).
    {
        let mname = "mikron-ucp710";
        let m = Machine::builtin(mname).expect("built-in machine");
        for (method, axes) in [("both", PatchAxes::Both), ("only-c", PatchAxes::OnlyC)] {
            let opts = PatchOptions {
                axes,
                ..PatchOptions::default()
            };
            for (k, path) in sing_runs(&m).into_iter().enumerate() {
                g.bench_function(format!("{method}/sing/{mname}/run{k}"), |b| {
                    b.iter(|| patch_path(black_box(&path), &m, &opts).unwrap())
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, zone_solve);
criterion_main!(benches);
