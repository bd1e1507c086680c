//! Whole-file patch of a zigzag program with many zones: parse, runs, patch every run,
//! write (the `polepatch patch` job without the file system).

use criterion::{Criterion, criterion_group, criterion_main};
use polepatch::kinematics::Machine;
use polepatch::{PatchOptions, patch_nc};
use polepatch_fixturegen::{Pass, zigzag_program};

fn zigzag(c: &mut Criterion) {
    // 12 passes at F2000, 1 mm spacing, 0.1°–4° from the pole, domain-rule post (A flips).
    let base = Pass {
        domain_rule: true,
        ..Pass::default()
    };
    let mut group = c.benchmark_group("zigzag_patch");
    group.sample_size(10);
    for name in ["mikron-ucp710", "mikron-hsm600"] {
        let machine = Machine::builtin(name).unwrap();
        // Written with the machine's tilting letter (a program of the other letter is
        // refused, issue 29).
        let pass = Pass {
            b_axis: machine.primary_letter() == 'B',
            ..base.clone()
        };
        let text = zigzag_program(&pass, 12, &[0.1, 0.5, 1.0, 2.0, 4.0, 0.05], "ZIGZAG");
        group.bench_function(name, |b| {
            b.iter(|| {
                let (out, report) =
                    patch_nc(text.as_bytes(), &machine, &PatchOptions::default()).unwrap();
                (out.len(), report.zones.len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, zigzag);
criterion_main!(benches);
