//! Issue 11 §2: CL round trip. Joints of every generated fixture and of C17's programs →
//! forward kinematics → a CL file (APT and CSV) → `post` → the same joints, within the
//! file's precision; and the posted program patches like the original (same zones, same
//! outcomes, the same new rotary values).

use polepatch::LoadedProgram;
use polepatch::cl::{ClPoint, parse, to_apt, to_csv};
use polepatch::kinematics::{BranchRule, Machine, forward};
use polepatch::load_nc;
use polepatch::nc::{Motion, NumberStyle, modal};
use polepatch::post::{PostOptions, post_cl};
use polepatch::{PatchOptions, patch_nc};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every move under TCPM with known values: its block and state, with X Y Z P C.
fn tcpm_blocks(lp: &LoadedProgram) -> Vec<(usize, polepatch::nc::Modal, [f64; 5])> {
    let p = &lp.program;
    let pi = lp.primary_index();
    (0..p.blocks.len())
        .filter(|&b| p.blocks[b].is_move)
        .filter_map(|b| {
            let st = p.state(b);
            if !st.tcpm.is_on() {
                return None;
            }
            let v = |i: usize| st.pos[i];
            let q = [
                v(modal::X)?,
                v(modal::Y)?,
                v(modal::Z)?,
                v(pi)?,
                v(modal::C)?,
            ];
            Some((b, st, q))
        })
        .collect()
}

/// X Y Z P C of every move under TCPM with known values.
fn tcpm_moves(lp: &LoadedProgram) -> Vec<[f64; 5]> {
    tcpm_blocks(lp).into_iter().map(|(_, _, q)| q).collect()
}

fn cl_points(lp: &LoadedProgram, machine: &Machine) -> Vec<ClPoint> {
    tcpm_blocks(lp)
        .into_iter()
        .map(|(b, st, q)| {
            ClPoint::straight(
                [q[0], q[1], q[2]],
                forward(machine, q[3], q[4]),
                st.feed_mm_min,
                st.motion == Motion::Rapid,
                lp.program.blocks[b].line,
            )
        })
        .collect()
}

fn mod360(d: f64) -> f64 {
    let w = d.rem_euclid(360.0);
    w.min(360.0 - w)
}

/// Same joints: X Y Z to the last written digit, P within `tol`, C modulo 360° within
/// `tol` off the pole (on it C is free).
fn same_joints(a: &[[f64; 5]], b: &[[f64; 5]], tol: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: point count");
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        for i in 0..3 {
            assert!(
                (x[i] - y[i]).abs() <= 0.0005 + 1e-9,
                "{what} point {k} axis {i}: {} vs {}",
                x[i],
                y[i]
            );
        }
        assert!(
            (x[3] - y[3]).abs() <= tol,
            "{what} point {k}: P {} vs {}",
            x[3],
            y[3]
        );
        if x[3].abs() > 0.01 {
            assert!(
                mod360(x[4] - y[4]) <= tol,
                "{what} point {k}: C {} vs {}",
                x[4],
                y[4]
            );
        }
    }
}

fn cases() -> Vec<(PathBuf, Machine, BranchRule)> {
    let mut out = Vec::new();
    let mut c17 = Machine::builtin("mikron-ucp710").unwrap();
    c17.primary_sense = -1.0;
    c17.c_sense = -1.0;
    for f in ["fixtures/c17/SING.I", "fixtures/c17/NON_SING.I"] {
        // C17's post keeps A ≥ 0 (from the pole at the first move, "nearest" would take
        // the other branch).
        out.push((root().join(f), c17.clone(), BranchRule::PreferPositive));
    }
    let mut generated: Vec<PathBuf> = std::fs::read_dir(root().join("fixtures/generated"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x != "md"))
        .collect();
    generated.sort();
    for p in generated {
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        let machine = if name.contains("-ac-") {
            "mikron-ucp710"
        } else {
            "mikron-hsm600"
        };
        let rule = if name.contains("-flip-") {
            BranchRule::DomainRule
        } else {
            BranchRule::Nearest
        };
        out.push((p, Machine::builtin(machine).unwrap(), rule));
    }
    out
}

#[test]
fn joints_to_cl_to_post_gives_the_same_joints() {
    let mut n = 0;
    for (path, machine, rule) in cases() {
        let what = path.display().to_string();
        let lp = load_nc(&std::fs::read(&path).unwrap(), &what, &machine, None).unwrap();
        let original = tcpm_moves(&lp);
        let pts = cl_points(&lp, &machine);
        let decimals = NumberStyle::of(&lp.program, lp.primary_letter)
            .decimals
            .max(NumberStyle::of(&lp.program, b'C').decimals);
        for (kind, text) in [("apt", to_apt(&pts, "RT", 12)), ("csv", to_csv(&pts, 12))] {
            let cl = parse(text.as_bytes()).unwrap();
            let opts = PostOptions {
                branch: rule,
                patch: false,
                rotary_decimals: decimals,
                ..PostOptions::default()
            };
            let (bytes, report) = post_cl(&cl, &machine, &opts).unwrap();
            assert!(report.is_none());
            let posted = load_nc(&bytes, "posted", &machine, None).unwrap();
            // Rounding to the file's decimals twice (the original, then the post).
            same_joints(
                &original,
                &tcpm_moves(&posted),
                1.5 * 10f64.powi(-(decimals as i32)),
                &format!("{what} {kind}"),
            );
        }
        n += 1;
    }
    assert_eq!(n, 98);
}

#[test]
fn the_posted_program_patches_like_the_original() {
    for (path, machine, rule) in cases().into_iter().step_by(3) {
        let what = path.display().to_string();
        let bytes = std::fs::read(&path).unwrap();
        let lp = load_nc(&bytes, &what, &machine, None).unwrap();
        let decimals = NumberStyle::of(&lp.program, lp.primary_letter)
            .decimals
            .max(NumberStyle::of(&lp.program, b'C').decimals);
        let cl = parse(to_apt(&cl_points(&lp, &machine), "RT", 12).as_bytes()).unwrap();
        let opts = PostOptions {
            branch: rule,
            rotary_decimals: decimals,
            ..PostOptions::default()
        };
        let (posted, report) = post_cl(&cl, &machine, &opts).unwrap();
        let report = report.unwrap();
        let (orig_out, orig_report) = patch_nc(&bytes, &machine, &PatchOptions::default()).unwrap();
        let outcomes =
            |r: &polepatch::FileReport| r.zones.iter().map(|z| z.outcome).collect::<Vec<_>>();
        assert_eq!(outcomes(&report), outcomes(&orig_report), "{what}");
        let a = tcpm_moves(&load_nc(&orig_out, "a", &machine, None).unwrap());
        let b = tcpm_moves(&load_nc(&posted, "b", &machine, None).unwrap());
        let tol =
            1.5 * 10f64.powi(-(report.written_c_decimals.unwrap_or(decimals).max(decimals) as i32));
        same_joints(&a, &b, tol.max(1.5e-3), &what);
    }
}
