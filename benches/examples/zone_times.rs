//! Per-zone patch time and deviation on the held-out-like zones (`polepatch_benches::
//! held_out_zones`) and C17's SING on both machines: each run is patched `REPS` times
//! (`ZT_REPS` overrides) and the fastest is kept (wall time, one core, and the thread's CPU
//! time, which a shared machine's load disturbs less), with the number of solves and IPM
//! iterations; with `--reference`, each zone's deviation is compared with the bench
//! reference (`polepatch_patcher::quality::zone_reference`).
//!
//! `cargo run --release -p polepatch-benches --example zone_times -- [COUNT] [--reference]
//! [--only LABEL-TEXT] [--set SETTING=VALUE …]`
//! (the criterion figures are `benches/zone_solve.rs`; this is for quick looks).

use polepatch::load_nc;
use polepatch_benches::held_out_zones;
use polepatch_kinematics::Machine;
use polepatch_patcher::quality::{Reference, zone_reference};
use polepatch_patcher::{PatchOptions, Path, analyze_path, patch_path};
use std::time::Instant;

const REPS: usize = 5;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(24);
    let with_ref = args.iter().any(|a| a == "--reference");
    // `--set field=value` overrides of the solver settings, `--only TEXT` a label filter.
    let mut solver = polepatch_patcher::SolverSettings::default();
    let mut only: Option<String> = None;
    for w in args.windows(2) {
        if w[0] == "--only" {
            only = Some(w[1].clone());
        }
        if w[0] == "--set"
            && let Some((k, v)) = w[1].split_once('=')
        {
            let f: f64 = v.parse().expect("a number");
            match k {
                "joint_range_min_points" => solver.joint_range_min_points = f as usize,
                "joint_range_zone_factor" => solver.joint_range_zone_factor = f,
                "scp_max_solves" => solver.scp_max_solves = f as u32,
                "screen_solves" => solver.screen_solves = f as u32,
                "screen_keep" => solver.screen_keep = f as usize,
                "scp_rel_tol" => solver.scp_rel_tol = f,
                "ipm_tol" => {
                    solver.ipm.tol_feas = f;
                    solver.ipm.tol_gap = f;
                }
                "ipm_tol_gap" => solver.ipm.tol_gap = f,
                "ipm_tol_feas" => solver.ipm.tol_feas = f,
                "ipm_refinement_steps" => solver.ipm.refinement_steps = f as u32,
                "ipm_regularisation" => solver.ipm.regularisation = f,
                "ipm_unregularised_first" => solver.ipm.unregularised_first = f != 0.0,
                "ipm_warm_mu" => solver.ipm.warm_mu = f,
                "ipm_scale_objective" => solver.ipm.scale_objective = f != 0.0,
                "scp_warm_start" => solver.scp_warm_start = f != 0.0,
                "screen_ipm_tol" => solver.screen_ipm_tol = f,
                "screen_within_tol" => solver.screen_within_tol = f,
                other => panic!("unknown setting {other}"),
            }
        }
    }
    let mut cases: Vec<(String, Machine, Path, bool, usize)> = held_out_zones(0x5EED_0021, count)
        .into_iter()
        .map(|h| (h.label, h.machine, h.path, h.keep_last_point, h.decimals))
        .collect();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let sing = std::fs::read(root.join("fixtures/c17/SING.I")).expect("SING.I");
    // C17's SING is an A-C program: the A-C machine (the B-C one refuses it, issue 29).
    {
        let name = "mikron-ucp710";
        let m = Machine::builtin(name).expect("machine");
        let lp = load_nc(&sing, "SING", &m, None).expect("SING parses");
        for r in lp.runs {
            if let Ok(p) = r.path
                && p.axes.iter().any(|q| q[3].abs() < 5.0)
            {
                cases.push((format!("SING/{name}"), m.clone(), p, false, 3));
            }
        }
    }
    let mut times = Vec::new();
    let mut cpu_times = Vec::new();
    let mut ratios = Vec::new();
    for (label, m, path, pinned, decimals) in &cases {
        if only.as_ref().is_some_and(|o| !label.contains(o.as_str())) {
            continue;
        }
        let opts = PatchOptions {
            keep_last_point: *pinned,
            p_decimals: *decimals,
            c_decimals: *decimals,
            solver: solver.clone(),
            ..PatchOptions::default()
        };
        let mut best = f64::INFINITY;
        let mut best_cpu = f64::INFINITY;
        let mut res = None;
        let reps = std::env::var("ZT_REPS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(REPS);
        for _ in 0..reps {
            let (t, c) = (Instant::now(), thread_cpu_s());
            let r = patch_path(path, m, &opts).expect("valid path");
            best = best.min(t.elapsed().as_secs_f64());
            if let (Some(a), Some(b)) = (c, thread_cpu_s()) {
                best_cpu = best_cpu.min(b - a);
            }
            res = Some(r);
        }
        let Some(res) = res else { continue };
        if res.zones.is_empty() {
            println!("{label}: no zone");
            continue;
        }
        let per_zone = best / res.zones.len() as f64;
        let cpu_zone = best_cpu / res.zones.len() as f64;
        for z in &res.zones {
            times.push(per_zone * 1e3);
            if cpu_zone.is_finite() {
                cpu_times.push(cpu_zone * 1e3);
            }
            let mut line = format!(
                "{label}: {:?} {} dev {:.4}° solves {} it {} | {:.3} ms/zone (cpu {:.3} ms)",
                z.outcome,
                z.reason,
                z.max_deviation_deg,
                z.qp.solves,
                z.qp.iterations,
                per_zone * 1e3,
                cpu_zone * 1e3
            );
            if with_ref {
                let n = path.s_mm.len();
                let a = analyze_path(path, m, &Default::default()).expect("analysis");
                let zone = a
                    .zones
                    .iter()
                    .find(|x| x.first <= z.last && x.last >= z.first)
                    .cloned();
                if let Some(zone) = zone {
                    let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
                    let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
                    let last = if *pinned { n - 2 } else { n - 1 };
                    let r =
                        zone_reference(&path.s_mm, &p, &c, &zone, 1, last, m, path.feed_mm_min, 6);
                    match r {
                        Ok(Reference::Best {
                            deviation_deg,
                            method,
                        }) => {
                            let ratio = if deviation_deg > 1e-9 {
                                z.max_deviation_deg / deviation_deg
                            } else if z.max_deviation_deg < 1e-9 {
                                1.0
                            } else {
                                f64::INFINITY
                            };
                            ratios.push(ratio);
                            line +=
                                &format!(" | ref {deviation_deg:.4}° ({method}) ratio {ratio:.3}");
                        }
                        other => line += &format!(" | ref {other:?}"),
                    }
                }
            }
            println!("{line}");
        }
    }
    let q = |v: &mut Vec<f64>, f: f64| {
        v.sort_by(f64::total_cmp);
        v[((v.len() as f64 - 1.0) * f).round() as usize]
    };
    if !times.is_empty() {
        println!(
            "{} zones: median {:.3} ms, p90 {:.3} ms, max {:.3} ms",
            times.len(),
            q(&mut times, 0.5),
            q(&mut times, 0.9),
            q(&mut times, 1.0)
        );
    }
    if !cpu_times.is_empty() {
        println!(
            "{} zones, thread CPU time: median {:.3} ms, p90 {:.3} ms, max {:.3} ms",
            cpu_times.len(),
            q(&mut cpu_times, 0.5),
            q(&mut cpu_times, 0.9),
            q(&mut cpu_times, 1.0)
        );
    }
    if !ratios.is_empty() {
        println!(
            "deviation / reference: median {:.3}, worst {:.3}",
            q(&mut ratios, 0.5),
            q(&mut ratios, 1.0)
        );
    }
}

/// This thread's CPU time, seconds (Linux: the first field of
/// `/proc/thread-self/schedstat`, nanoseconds on the CPU), or `None` elsewhere.
fn thread_cpu_s() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}
