//! Time to patch one singular zone (SPEC §6: ≤ 1 ms median): `patch_path` on whole runs
//! whose zones are known, with the default method (both rotary axes: re-selection or the
//! joint SOCP) and with `--only-c` (G16's C-only method). Each benched run holds one zone;
//! the figure includes detection, every solve, verification and the report figures. Run:
//! `cargo bench -p polepatch-benches --bench zone_solve -- --warm-up-time 1 --measurement-time 5`
//! Figures are written up in docs/performance-patcher.md.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use polepatch::program::load_nc;
use polepatch_kinematics::Machine;
use polepatch_patcher::{PatchAxes, PatchOptions, Path, patch_path};

/// The runs of a fixture that have zones on `machine`, as the pipeline builds them.
fn zone_runs(file: &str, machine: &Machine) -> Vec<Path> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let bytes = std::fs::read(root.join(file)).expect("fixture");
    let lp = load_nc(bytes, file, machine, None).expect("parsable fixture");
    let opts = PatchOptions::default();
    lp.runs
        .into_iter()
        .filter_map(|r| {
            let path = r.path.ok()?;
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
    let mut g = c.benchmark_group("patcher/zone_solve");
    g.sample_size(10);
    for (method, axes) in [("both", PatchAxes::Both), ("only-c", PatchAxes::OnlyC)] {
        let opts = PatchOptions {
            axes,
            ..PatchOptions::default()
        };
        for mname in ["mikron-ucp710", "mikron-hsm600"] {
            let m = Machine::builtin(mname).expect("built-in machine");
            for (label, file) in cases {
                for (k, path) in zone_runs(file, &m).into_iter().enumerate() {
                    let res = patch_path(&path, &m, &opts).unwrap();
                    eprintln!(
                        "{method}/{label}/{mname}/run{k}: {} zone(s), {} points, {} solves",
                        res.zones.len(),
                        path.s_mm.len(),
                        res.zones.iter().map(|z| z.qp.solves).sum::<u32>()
                    );
                    g.bench_function(format!("{method}/{label}/{mname}/run{k}"), |b| {
                        b.iter(|| patch_path(black_box(&path), &m, &opts).unwrap())
                    });
                }
            }
        }
    }
    g.finish();
}

criterion_group!(benches, zone_solve);
criterion_main!(benches);
