//! The one reader reads a program the same whatever its stretches: `analyze_nc` (every run
//! a stretch) gives the analysis of the whole file read as one stretch (`load_nc` +
//! `analyze_program`), and `patch_nc` patches the stretches near the pole: on fixtures,
//! both machines, and programs built so that runs, stretches, feed changes, end poses,
//! frame changes and feedless runs meet at stretch boundaries.

mod common;
use polepatch::ReadOptions;
use polepatch::analyze_program;
use polepatch::kinematics::Machine;
use polepatch::patcher::AnalysisOptions;
use polepatch::{AnalyzeOptions, FileReport, PatchOptions};
use polepatch::{analyze_nc as analyze_nc_stretches, patch_nc_to};
use std::path::PathBuf;

/// The whole program, loaded.
fn whole(
    bytes: &[u8],
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<polepatch::LoadedProgram, polepatch::Error> {
    polepatch::load_nc_with(
        bytes,
        machine,
        &AnalyzeOptions {
            read: opts.read.clone(),
            ..AnalyzeOptions::default()
        },
    )
}

/// `analyze` both ways (every run a stretch, and the whole program); panics with `what`
/// where they differ.
fn same_analysis(bytes: &[u8], machine: &Machine, opts: &PatchOptions, what: &str) {
    let aopts = AnalyzeOptions {
        read: opts.read.clone(),
        analysis: AnalysisOptions {
            cone_deg: opts.patch.cone_deg,
            ..AnalysisOptions::default()
        },
    };
    let full = whole(bytes, machine, opts).map(|lp| analyze_program(&lp, machine, &aopts.analysis));
    match (full, analyze_nc_stretches(bytes, machine, &aopts)) {
        (Ok(a), Ok(b)) => assert_eq!(format!("{a:?}"), format!("{b:?}"), "{what}: analyze"),
        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "{what}: analyze"),
        (a, b) => panic!("{what}: analyze {:?} vs {:?}", a.err(), b.err()),
    }
}

/// `analyze` both ways ([`same_analysis`]) and the patch; panics with `what` where the
/// analyses differ. Returns the patch report (that of no zone after an error, which
/// `load_nc` must give too).
fn same(bytes: &[u8], machine: &Machine, opts: &PatchOptions, what: &str) -> FileReport {
    same_analysis(bytes, machine, opts, what);
    let mut out = Vec::new();
    match (
        patch_nc_to(bytes, machine, opts, &mut out),
        whole(bytes, machine, opts),
    ) {
        (Ok(rep), _) => rep,
        (Err(a), Err(b)) => {
            assert_eq!(a.to_string(), b.to_string(), "{what}");
            FileReport::unchanged(&opts.read.name, machine, Vec::new())
        }
        (Err(a), Ok(_)) => panic!("{what}: {a}"),
    }
}

fn fixture(rel: &str) -> Vec<u8> {
    std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../fixtures")
            .join(rel),
    )
    .unwrap()
}

fn machines() -> [Machine; 2] {
    ["mikron-ucp710", "mikron-hsm600"].map(|m| Machine::builtin(m).unwrap())
}

/// The C17 and dialect fixtures, and a generated one of each dialect, axis pair and kind
/// at two distances from the pole.
#[test]
fn fixtures_give_the_whole_program_answer() {
    let mut files: Vec<String> = [
        "c17/SING.I",
        "c17/NON_SING.I",
        "dialects/fanuc.nc",
        "dialects/heidenhain_latin1.I",
        "dialects/sinumerik.mpf",
    ]
    .map(String::from)
    .to_vec();
    for (dialect, ext) in [("heidenhain", "I"), ("sinumerik", "mpf"), ("fanuc", "nc")] {
        for pair in ["ac", "bc"] {
            for kind in ["flip", "swing"] {
                for d in ["0.1", "2"] {
                    files.push(format!("generated/{dialect}-{pair}-{kind}-d{d}.{ext}"));
                }
            }
        }
    }
    let mut zones = 0;
    for f in &files {
        let bytes = fixture(f);
        for machine in machines() {
            for cone_deg in [0.05, 5.0] {
                let mut opts = PatchOptions::named(f.clone());
                opts.patch.cone_deg = cone_deg;
                let rep = same(
                    &bytes,
                    &machine,
                    &opts,
                    &format!("{f} {} {cone_deg}", machine.name),
                );
                zones += rep.zones.len();
            }
        }
    }
    assert!(zones >= 40, "{zones} zones");
}

/// Several programs one after the other in one file (stretches with far runs between
/// them, run numbers counted across), C17's SING with its feed changed halfway (two runs
/// sharing a point, one stretch), a run without feed far from the pole (reported), a
/// tool change right after a run (end pose free) and a rotary move with a linear one
/// right after another (end pose fixed).
#[test]
fn programs_built_across_stretch_boundaries() {
    let sing = String::from_utf8(fixture("c17/SING.I")).unwrap();
    let non = String::from_utf8(fixture("c17/NON_SING.I")).unwrap();
    let body = |s: &str| -> String {
        s.lines()
            .filter(|l| !l.starts_with('%') && !l.contains("M30") && !l.contains("M00"))
            .map(|l| format!("{l}\n"))
            .collect()
    };
    // SING with a feed change in the middle of its zone.
    let split: String = body(&sing)
        .lines()
        .map(|l| {
            if l.starts_with("N400 ") {
                format!("{} F2500 *\n", l.trim_end_matches('*').trim_end())
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    assert_ne!(split, body(&sing), "the feed change went in");
    let far_feedless = "N1 G01 X+0 Y+0 Z+50 A+40 C+0 *\nN2 X+10 A+41 C+5 *\n";
    let fixed_after = "N3 G01 X+5 Y+5 Z+20 A+10 C+10 *\n";
    // The feedless run comes first, before any F.
    let text = format!(
        "%ALL G71 *\n{}{}{}T7 M6 *\n{}{}{}N5 M129 *\nN999 M30 *\n",
        far_feedless,
        body(&sing),
        body(&non),
        split,
        fixed_after,
        body(&sing),
    );
    let bytes = text.into_bytes();
    for machine in common::machines_for("all.I", &bytes) {
        let opts = PatchOptions::named("all.I");
        let rep = same(&bytes, &machine, &opts, &machine.name);
        assert!(
            rep.zones.len() >= 3,
            "{}: {} zones",
            machine.name,
            rep.zones.len()
        );
        assert!(rep.zones.iter().map(|z| z.run).max() > Some(3));
        assert_eq!(rep.untouched_runs.len(), 1, "the feedless run");
        assert_eq!(rep.untouched_runs[0].run, 1);
        // With a fallback feed the last run has one.
        let mut opts = opts;
        opts.read.feed_fallback_mm_min = Some(1500.0);
        same(
            &bytes,
            &machine,
            &opts,
            &format!("{} fallback", machine.name),
        );
    }
}

/// With a kinematic chain: SING without M128 (machine coordinates; its stated datum), the
/// same after a G92 (work offset unknown), and with `--work-offset` on a program that
/// names nothing.
#[test]
fn chain_runs_get_their_work_offset_from_the_whole_file() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let path = root.join("crates/kinematics/machines/mikron-ucp710-example-chain.toml");
    let machine = Machine::load(path.to_str().unwrap()).unwrap();
    let sing = String::from_utf8(fixture("c17/SING.I")).unwrap();
    let no_tcpm = sing.replace("N65 M128 *\n", "");
    let g92 = no_tcpm.replace("N65 ", "N64 G92 X+0 *\nN65 ");
    let tcpm_after_g92 = sing.replace("N65 M128 *\n", "N64 G92 X+0 *\nN65 M128 *\n");
    for (what, text, offset) in [
        ("SING", sing.clone(), None),
        ("no M128", no_tcpm.clone(), None),
        ("no M128, G92", g92, Some([1.0, 2.0, 3.0])),
        ("M128 after G92", tcpm_after_g92, Some([1.0, 2.0, 3.0])),
        (
            "no M128, offset",
            no_tcpm.replace("N60 G54", "N60 G55"),
            Some([-30.0, -7.0, 38.0]),
        ),
    ] {
        let opts = PatchOptions {
            read: ReadOptions {
                name: what.into(),
                work_offset_mm: offset,
                ..ReadOptions::default()
            },
            ..PatchOptions::default()
        };
        same(text.as_bytes(), &machine, &opts, what);
    }
}
