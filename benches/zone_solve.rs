//! Time to patch one singular zone (SPEC §6: ≤ 1 ms median): `patch_path` on whole runs
//! whose zones are known, reported per run (divide by the zone count printed at start-up).
//! Run:
//! `cargo bench -p polepatch-benches --bench zone_solve -- --warm-up-time 1 --measurement-time 5`
//! Figures are written up in docs/performance-patcher.md.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use polepatch_kinematics::Machine;
use polepatch_nc::{Dialect, modal, parse, primary_in_use, runs};
use polepatch_patcher::{PatchOptions, Path, patch_path};

/// The runs of a fixture that have zones on `machine`, as the CLI builds them.
fn zone_runs(file: &str, machine: &Machine) -> Vec<Path> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let bytes = std::fs::read(root.join(file)).expect("fixture");
    let prog = parse(bytes, Dialect::Auto).expect("parsable fixture");
    let rs = runs(&prog);
    let own = if machine.primary_letter() == 'A' {
        modal::A
    } else {
        modal::B
    };
    let pi = primary_in_use(&rs, own);
    let opts = PatchOptions::default();
    rs.iter()
        .filter_map(|r| {
            let path = Path {
                s_mm: r.s_mm.clone(),
                axes: r.axes5(pi),
                feed_mm_min: r.feed_mm_min?,
            };
            let res = patch_path(&path, machine, &opts).ok()?;
            (!res.zones.is_empty()).then_some(path)
        })
        .collect()
}

fn zone_solve(c: &mut Criterion) {
    let cases = [
        ("sing", "fixtures/c17/SING.I"),
        ("ac-flip-d2", "fixtures/generated/heidenhain-ac-flip-d2.I"),
        (
            "ac-swing-d0.5",
            "fixtures/generated/heidenhain-ac-swing-d0.5.I",
        ),
    ];
    let opts = PatchOptions::default();
    let mut g = c.benchmark_group("patcher/zone_solve");
    for mname in ["mikron-ucp710", "mikron-hsm600"] {
        let m = Machine::builtin(mname).expect("built-in machine");
        for (label, file) in cases {
            for (k, path) in zone_runs(file, &m).into_iter().enumerate() {
                let zones = patch_path(&path, &m, &opts).unwrap().zones.len();
                eprintln!(
                    "{label}/{mname}/run{k}: {zones} zone(s), {} points",
                    path.s_mm.len()
                );
                g.bench_function(format!("{label}/{mname}/run{k}"), |b| {
                    b.iter(|| patch_path(black_box(&path), &m, &opts).unwrap())
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, zone_solve);
criterion_main!(benches);
