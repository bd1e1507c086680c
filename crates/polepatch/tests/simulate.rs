//! `simulate` on C17's %SING, its patched version and generated flips and swings: the feed
//! never exceeds F, every programmed point is passed, the patched program is faster, and
//! the simulated time is at least Equation 6's estimate, itself at least L/F. The
//! trajectory's finite differences within every axis' V, A and J on every fixture:
//! `every_fixture_is_within_the_limits_by_finite_differences` (issue 43 item 1).

mod common;
use polepatch::ReadOptions;
use polepatch::SimulateReport;
use polepatch::kinematics::Machine;
use polepatch::simulate::{SimState, SimulateOptions};
use polepatch::{PatchOptions, patch_nc, simulate_nc_with};
use std::path::PathBuf;

fn fixture(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(rel)
}

/// Simulate with every cycle, checking the trajectory as it comes.
fn check(bytes: &[u8], m: &Machine, what: &str) -> SimulateReport {
    let opts = SimulateOptions {
        read: ReadOptions {
            name: what.to_string(),
            ..ReadOptions::default()
        },
        sim: polepatch::sim::SimOptions {
            every_cycle: true,
            ..Default::default()
        },
    };
    let mut states: Vec<SimState> = Vec::new();
    let mut on = |s: &SimState| states.push(*s);
    let rep = simulate_nc_with(bytes, m, &opts, Some(&mut on)).expect("simulates");
    assert!(rep.total.runs > 0, "{what}: no run simulated");
    for run in rep.runs.iter().filter(|r| r.error.is_none()) {
        let st: Vec<&SimState> = states.iter().filter(|s| s.run == run.run).collect();
        assert!(st.len() > 3, "{what} run {}: {} states", run.run, st.len());
        let f = run.feed_mm_min.unwrap();
        // Feed within F, s increasing to the run's end (every point passed).
        for w in st.windows(2) {
            assert!(
                w[1].s_mm >= w[0].s_mm - 1e-12,
                "{what} run {}: s goes back",
                run.run
            );
            // Each state once: time moves on at every state of a run (the end was
            // written a second time at the same t before 2026-11-25).
            assert!(
                w[1].t_s > w[0].t_s,
                "{what} run {}: two states at t = {} s",
                run.run,
                w[0].t_s
            );
        }
        for s in &st {
            assert!(
                s.feed_mm_min <= f * (1.0 + 1e-9),
                "{what}: feed {} > F {f}",
                s.feed_mm_min
            );
        }
        let last = st.last().unwrap();
        assert!(
            (last.s_mm - run.length_mm).abs() < 1e-6,
            "{what} run {}: ends at s = {} of {}",
            run.run,
            last.s_mm,
            run.length_mm
        );
        // Finite differences: printed here, held to the limits by
        // `every_fixture_is_within_the_limits_by_finite_differences`. Until 2026-11-28 this function asserted them within 2 % over windows
        // of states flagged as whole cycles; the flag compared t₁ − t₀ == Tcy exactly,
        // which rounding made false at random, so most windows were never checked
        // (%SING on the UCP710: X at 4.76× J at s = 145.44 mm once they are).
        let mine: Vec<SimState> = st.iter().map(|s| **s).collect();
        let worst = worst_over_limits(&mine, m);
        println!(
            "{what} run {}: V A J over their limits by {worst:?}",
            run.run
        );
        // Simulated ≥ Equation 6 ≥ L/F.
        assert!(
            run.time_s >= run.eq6_time_s * (1.0 - 1e-3),
            "{what} run {}: simulated {} < Equation 6 {}",
            run.run,
            run.time_s,
            run.eq6_time_s
        );
        assert!(run.eq6_time_s >= run.ideal_time_s * (1.0 - 1e-9));
    }
    rep
}

#[test]
fn sing_and_its_patch_on_both_machines() {
    let bytes = std::fs::read(fixture("c17/SING.I")).unwrap();
    for m in common::machines_for("SING", &bytes) {
        let name = &m.name;
        let before = check(&bytes, &m, &format!("SING on {name}"));
        let (patched, _) = patch_nc(&bytes, &m, &PatchOptions::default()).unwrap();
        let after = check(&patched, &m, &format!("SING patched for {name}"));
        assert!(
            after.total.time_s < before.total.time_s,
            "{name}: patched {} s, original {} s",
            after.total.time_s,
            before.total.time_s
        );
        assert!(after.total.time_s >= after.total.eq6_time_s * (1.0 - 1e-3));
    }
}

#[test]
fn generated_flips_and_swings() {
    for f in [
        "generated/heidenhain-ac-flip-d0.5.I",
        "generated/heidenhain-ac-swing-d0.1.I",
        "generated/heidenhain-bc-flip-d0.1.I",
        "generated/heidenhain-bc-swing-d0.5.I",
    ] {
        let bytes = std::fs::read(fixture(f)).unwrap();
        for m in common::machines_for(f, &bytes) {
            let name = &m.name;
            let before = check(&bytes, &m, &format!("{f} on {name}"));
            let (patched, _) = patch_nc(&bytes, &m, &PatchOptions::default()).unwrap();
            if patched != bytes {
                let after = check(&patched, &m, &format!("{f} patched for {name}"));
                assert!(
                    after.total.time_s < before.total.time_s,
                    "{f} {name}: patched {} s, original {} s",
                    after.total.time_s,
                    before.total.time_s
                );
            }
        }
    }
}

/// One answer (issue 43): the default simulation and the one that hands out every cycle
/// take the same steps (the trajectory cuts the jumped cruises into their cycles), so
/// their times are equal to the bit. Before 2026-11-28 they were two computations that
/// agreed but for the discretisation (on these near-pole swings once 2.24 s against
/// 12.65 s), and on some programs one of them stopped with "the limits allow no motion".
#[test]
fn the_default_and_the_every_cycle_simulation_are_one_answer() {
    for f in [
        "generated/heidenhain-ac-swing-d0.5.I",
        "generated/heidenhain-ac-swing-d0.01.I",
        "generated/fanuc-bc-swing-d0.01.nc",
    ] {
        let bytes = std::fs::read(fixture(f)).unwrap();
        for m in common::machines_for(f, &bytes) {
            let name = &m.name;
            let time = |every_cycle: bool| {
                let opts = SimulateOptions {
                    read: ReadOptions {
                        name: f.to_string(),
                        ..ReadOptions::default()
                    },
                    sim: polepatch::sim::SimOptions {
                        every_cycle,
                        ..Default::default()
                    },
                };
                // (Every cycle is only computed for a caller that takes the states.)
                let mut on = |_: &SimState| {};
                simulate_nc_with(&bytes, &m, &opts, Some(&mut on))
                    .expect("simulates")
                    .total
                    .time_s
            };
            let (quick, every) = (time(false), time(true));
            assert_eq!(
                quick.to_bits(),
                every.to_bits(),
                "{f} on {name}: {quick} s by default, {every} s cycle by cycle"
            );
        }
    }
}

/// The largest |difference quotient| / limit of V, A and J over the axes, every window of
/// 1, 2 and 3 full cycles within a run of `states` (a simulation with every cycle), as a
/// user's scope would take them from the trajectory.
fn worst_over_limits(states: &[SimState], m: &Machine) -> [f64; 3] {
    let dt = m.tcy_s;
    let mut worst = [0.0f64; 3];
    for n in 1..=3usize {
        for w in states.windows(n + 1) {
            if w.iter().any(|s| s.run != w[0].run)
                || w.windows(2)
                    .any(|p| (p[1].t_s - p[0].t_s - dt).abs() > 1e-9)
            {
                continue;
            }
            for i in 0..5 {
                let q: Vec<f64> = w.iter().map(|s| s.axes[i]).collect();
                let d = match n {
                    1 => (q[1] - q[0]) / dt,
                    2 => (q[2] - 2.0 * q[1] + q[0]) / (dt * dt),
                    _ => (q[3] - 3.0 * q[2] + 3.0 * q[1] - q[0]) / (dt * dt * dt),
                };
                let l = m.limits[i];
                let lim = [l.v, l.a, l.j][n - 1];
                worst[n - 1] = worst[n - 1].max(d.abs() / lim);
            }
        }
    }
    worst
}

/// Issue 32's tolerances on [`worst_over_limits`]: 1.05× V, 1.10× A, 1.25× J (for finite
/// differencing, not for the motion).
fn within_issue_32(worst: [f64; 3]) -> bool {
    worst[0] <= 1.05 && worst[1] <= 1.10 && worst[2] <= 1.25
}

/// The states of `bytes` on `m`, every cycle, with or without [`SimOptions::rewind`];
/// `None` where it does not simulate.
///
/// [`SimOptions::rewind`]: polepatch::sim::SimOptions::rewind
fn every_cycle(bytes: &[u8], m: &Machine, rewind: bool) -> Option<Vec<SimState>> {
    let opts = SimulateOptions {
        sim: polepatch::sim::SimOptions {
            every_cycle: true,
            rewind,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut states: Vec<SimState> = Vec::new();
    let mut on = |s: &SimState| states.push(*s);
    simulate_nc_with(bytes, m, &opts, Some(&mut on)).ok()?;
    Some(states)
}

/// With rewinds (`SimOptions::rewind`), C17's two programs on the UCP710 move within
/// every axis' V, A and J by finite differences at issue 32's tolerances. Without them
/// (the default), `%SING`'s clips jump the acceleration: 17.2× J on the tilting axis.
#[test]
fn c17_on_the_ucp710_with_rewinds_is_within_the_limits_by_finite_differences() {
    let m = Machine::builtin("mikron-ucp710").unwrap();
    for f in ["c17/SING.I", "c17/NON_SING.I"] {
        let bytes = std::fs::read(fixture(f)).unwrap();
        let states = every_cycle(&bytes, &m, true).expect("simulates");
        let worst = worst_over_limits(&states, &m);
        assert!(
            within_issue_32(worst),
            "{f}: V, A, J over their limits by {worst:?}"
        );
    }
}

/// Issue 32's check, as a user's scope would make it: on every program in `fixtures/` on
/// both built-in machines, the finite differences of the trajectory within 1.05× V,
/// 1.10× A and 1.25× J of each axis' limits, by default.
///
/// It failed until 2026-11-29 (the per-cycle passes, then the default: 130 of 132 runs
/// over, largest J 142×; with rewinds 52); the segments of constant limits keep every
/// run within the limits by construction (`polepatch-simulate`'s `segments.rs`).
/// `docs/simulation.md` ("Jerk at every cycle") has the figures; `-- --nocapture` prints
/// each run's.
#[test]
fn every_fixture_is_within_the_limits_by_finite_differences() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let mut files = Vec::new();
    let mut dirs = vec![root.clone()];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p
                .extension()
                .and_then(|x| x.to_str())
                .is_some_and(|x| ["I", "H", "nc", "mpf", "ngc"].contains(&x))
            {
                files.push(p);
            }
        }
    }
    files.sort();
    let (mut failures, mut runs) = (Vec::new(), 0);
    for f in &files {
        let bytes = std::fs::read(f).unwrap();
        for name in Machine::builtin_names() {
            let m = Machine::builtin(name).unwrap();
            let Some(states) = every_cycle(&bytes, &m, false) else {
                continue;
            };
            let worst = worst_over_limits(&states, &m);
            let within = within_issue_32(worst);
            let rel = f.strip_prefix(&root).unwrap_or(f).display();
            println!(
                "{rel} {name}: V {:.3} A {:.3} J {:.3}{}",
                worst[0],
                worst[1],
                worst[2],
                if within { "" } else { "  OVER" }
            );
            runs += 1;
            if !within {
                failures.push(format!("{rel} on {name}: {worst:?}"));
            }
        }
    }
    assert!(runs >= 100, "{runs} runs simulated");
    assert!(
        failures.is_empty(),
        "{} of {runs} runs over: {failures:#?}",
        failures.len(),
    );
}
