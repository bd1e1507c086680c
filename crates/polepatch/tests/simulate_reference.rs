//! `simulate` against an independent lower bound (issue 43 item 5): TOPP-RA's
//! time-optimal parametrisation of each run's path under every axis' V and A and the feed
//! (no jerk limit: any motion within V, A and F along the path takes at least that long),
//! on the same not-a-knot spline through the points (`simulate/tests/reference/
//! reference.py`). The simulated time of a run is never below it (0.5 % slack for
//! TOPP-RA's grid). Needs Python with `ruckig` and `toppra` (see `reference.rs`); without
//! it the test says that it skipped and why.

#[path = "../../simulate/tests/common/reference.rs"]
mod reference;

use polepatch::kinematics::Machine;
use polepatch::simulate::SimulateOptions;
use polepatch::{load_nc, simulate_nc};
use reference::{json_list, python, time_s};
use std::path::PathBuf;

fn fixture(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(rel)
}

#[test]
fn simulate_is_never_faster_than_the_topp_ra_bound() {
    let py = match python() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("skipped: {why}");
            return;
        }
    };
    let mut compared = 0;
    for (f, machine) in [
        ("c17/SING.I", "mikron-ucp710"),
        ("c17/NON_SING.I", "mikron-ucp710"),
        ("generated/heidenhain-ac-flip-d0.5.I", "mikron-ucp710"),
        ("generated/heidenhain-ac-swing-d0.1.I", "mikron-ucp710"),
        ("generated/heidenhain-bc-flip-d0.1.I", "mikron-hsm600"),
        ("generated/heidenhain-bc-swing-d0.5.I", "mikron-hsm600"),
        ("generated/fanuc-ac-swing-d20.nc", "mikron-ucp710"),
    ] {
        let m = Machine::builtin(machine).unwrap();
        let bytes = std::fs::read(fixture(f)).unwrap();
        let lp = load_nc(&bytes, f, &m, None).unwrap();
        let rep = simulate_nc(&bytes, &m, &SimulateOptions::default()).unwrap();
        for (r, rp) in lp.runs.iter().enumerate() {
            let Ok(path) = &rp.path else { continue };
            let number = lp.run_number(r);
            let Some(row) = rep.runs.iter().find(|x| x.run == number) else {
                continue;
            };
            // A run joined to its neighbour (a feed change) is part of a longer motion.
            let next_joined = rep.runs.iter().any(|x| x.run == number + 1 && x.joined);
            if row.joined || next_joined || row.error.is_some() {
                continue;
            }
            let axes: Vec<String> = path
                .axes
                .iter()
                .map(|q| json_list(q.iter().copied()))
                .collect();
            let req = format!(
                "{{\"kind\":\"topp\",\"s_mm\":{},\"axes\":[{}],\"feed_mm_s\":{:e},\"v\":{},\"a\":{},\"grid\":2000}}",
                json_list(path.s_mm.iter().copied()),
                axes.join(","),
                path.feed_mm_min / 60.0,
                json_list(m.limits.iter().map(|l| l.v)),
                json_list(m.limits.iter().map(|l| l.a)),
            );
            let bound = time_s(&py, &req);
            println!(
                "| {f} | {machine} | {number} | {:.4} | {bound:.4} | {:.4} | {:+.1} % |",
                row.eq6_time_s,
                row.time_s,
                100.0 * (row.time_s / bound - 1.0)
            );
            assert!(
                row.time_s >= bound * (1.0 - 5e-3),
                "{f} on {machine} run {number}: simulated {} s, below TOPP-RA's {bound} s",
                row.time_s
            );
            compared += 1;
        }
    }
    assert!(compared >= 7, "{compared} runs compared");
}
