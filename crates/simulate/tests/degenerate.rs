//! Degenerate inputs on purpose: errors name what is wrong; extreme feeds finish with
//! bounded work; a feed change between two parts is not a stop.

mod common;

use common::{assert_within_limits, chord_path, line, trajectory};
use polepatch_kinematics::Machine;
use polepatch_patcher::Path;
use polepatch_simulate::{SimError, SimOptions, simulate};

fn ucp() -> Machine {
    Machine::builtin("mikron-ucp710").unwrap()
}

#[test]
fn bad_input_is_an_error_that_names_it() {
    let m = ucp();
    let none = |_: &polepatch_simulate::Step, _: &polepatch_simulate::Geometry| {};
    let mut sink = none;
    assert_eq!(
        simulate(&[], &m, &SimOptions::default(), &mut sink),
        Err(SimError::Empty)
    );
    // Two parts that do not share their boundary point.
    let a = line(0, 10.0, 1.0, 1000.0);
    let mut b = line(0, 10.0, 1.0, 2000.0);
    for q in &mut b.axes {
        q[0] += 20.0;
    }
    let e = simulate(&[a.clone(), b], &m, &SimOptions::default(), &mut sink).unwrap_err();
    assert!(
        matches!(
            e,
            SimError::NotJoined {
                part: 1,
                previous: 0,
                ..
            }
        ),
        "{e}"
    );
    // A bad feed and a bad cycle time.
    let mut bad = a.clone();
    bad.feed_mm_min = 0.0;
    let e = simulate(&[bad], &m, &SimOptions::default(), &mut sink).unwrap_err();
    assert!(matches!(e, SimError::Path { part: 0, .. }), "{e}");
    let opts = SimOptions {
        tcy_s: Some(0.0),
        ..SimOptions::default()
    };
    assert_eq!(
        simulate(&[a], &m, &opts, &mut sink),
        Err(SimError::BadCycleTime(0.0))
    );
}

/// F = 0.6 mm/min over 100 mm (10 000 s of motion): the report takes few steps (the
/// cruise at F is jumped from grid point to grid point), and the time is L/F plus the
/// negligible ramps.
#[test]
fn an_extremely_slow_feed_is_bounded_work() {
    let m = ucp();
    let p = line(0, 100.0, 1.0, 0.6);
    let sim = simulate(&[p], &m, &SimOptions::default(), &mut |_, _| {}).unwrap();
    let lf = 100.0 / (0.6 / 60.0);
    // Within 0.5 %: below one cycle of jerk the cruise is within 10⁻³ of the feed
    // (tolerances::CRAWL_CRUISE_REL).
    assert!(
        (sim.time_s / lf - 1.0).abs() < 5e-3,
        "{} vs {lf}",
        sim.time_s
    );
    assert!(sim.steps < 10_000, "{} steps", sim.steps);
    // (Equation 6's estimate beside it samples every F·Tcy: 10⁷ samples here; that
    // sampling is the analysis's, not the simulator's.)
}

/// Two parts joined at a feed change: one motion, no stop at the shared point (the feed
/// there is the lower F), the parts' times add up to the total, within the limits.
#[test]
fn a_feed_change_is_not_a_stop() {
    let m = ucp();
    let a = line(0, 50.0, 1.0, 3000.0);
    let mut b = line(0, 50.0, 1.0, 1500.0);
    for q in &mut b.axes {
        q[0] += 50.0;
    }
    let tr = trajectory(&[a.clone(), b.clone()], &m);
    // (Its finite differences: `a_feed_change_is_within_the_limits_by_finite_differences`.)
    let at_join =
        tr.s.iter()
            .zip(&tr.feed)
            .filter(|(s, _)| (**s - 50.0).abs() < 0.05)
            .map(|(_, f)| *f)
            .fold(f64::INFINITY, f64::min);
    assert!(
        (at_join - 25.0).abs() < 0.1,
        "feed at the join {at_join} mm/s, the lower F is 25"
    );
    let parts: f64 = tr.sim.parts.iter().map(|p| p.time_s).sum();
    assert!((parts - tr.sim.time_s).abs() < 1e-9);
    // Never above either part's F on its own part.
    for (s, f) in tr.s.iter().zip(&tr.feed) {
        let cap = if *s < 50.0 { 50.0 } else { 25.0 };
        assert!(*f <= cap * (1.0 + 1e-9), "s = {s}: {f}");
    }
}

/// [`a_feed_change_is_not_a_stop`]'s trajectory within every axis' limits by finite
/// differences. (Failed until 2026-11-29 with the per-cycle passes, then the default:
/// X at 1.066× J where the motion braked from F3000 towards the feed change.)
#[test]
fn a_feed_change_is_within_the_limits_by_finite_differences() {
    let m = ucp();
    let a = line(0, 50.0, 1.0, 3000.0);
    let mut b = line(0, 50.0, 1.0, 1500.0);
    for q in &mut b.axes {
        q[0] += 50.0;
    }
    let tr = trajectory(&[a, b], &m);
    assert_within_limits(&tr, &m, "feed change");
}

/// A path that stands on the pole side of a flip with a tiny limit: the motion crawls
/// through and ends; a zero-length run is refused by the path check, never a hang.
#[test]
fn a_tiny_limit_is_crossed() {
    let m = ucp();
    // C turns 170° over 0.2 mm in the middle of a 20 mm line.
    let n = 101;
    let s_mm: Vec<f64> = (0..n).map(|k| 0.2 * k as f64).collect();
    let axes: Vec<[f64; 5]> = s_mm
        .iter()
        .map(|&s| {
            let c = 85.0 * (1.0 + ((s - 10.0) / 0.05).tanh());
            [s, 0.0, 0.0, 1.0, c]
        })
        .collect();
    let p = Path {
        s_mm,
        axes,
        feed_mm_min: 2000.0,
    };
    let sim = simulate(
        std::slice::from_ref(&p),
        &m,
        &SimOptions::default(),
        &mut |_, _| {},
    )
    .unwrap();
    assert!(
        sim.time_s > sim.parts[0].eq6_time_s * (1.0 - 1e-3),
        "{sim:?}"
    );
    let tr = trajectory(&[p], &m);
    assert_eq!(*tr.s.last().unwrap(), 20.0);
}

/// The path of issue 43's "no motion" report, rebuilt: a smooth G1 line along X whose
/// tilt and C follow slow sines, written to 0.0001 mm and 0.001°, at F3264 on the HSM600
/// (found by a random sweep of smooth programs). Before 2026-11-28 the default simulation
/// stopped with "the limits allow no motion at s = 29.1 mm" while the one with every cycle
/// handed out finished (12 s): the backward profile comes to a near standstill there, and
/// a forward state on it with v > 0 was put back on it every cycle without moving.
fn issue_43_rot_path() -> Path {
    let (n, h, r) = (1529usize, 0.021767693275594042, 6.675940539746756);
    let round = |x: f64, d: i32| (x * 10f64.powi(d)).round() / 10f64.powi(d);
    let axes: Vec<[f64; 5]> = (0..=n)
        .map(|k| {
            let s = h * k as f64;
            [
                round(s, 4),
                0.0,
                0.0,
                round(20.0 + 10.0 * (s / r).sin(), 3),
                round(30.0 + 40.0 * (s / r / 3.0).sin(), 3),
            ]
        })
        .collect();
    chord_path(axes, 3264.0)
}

/// Issue 43, "one answer": a motion the limits allow is simulated, and the answer does
/// not depend on whether every cycle is handed out (the forward pass takes the same steps;
/// a trajectory cuts its jumped cruises into cycles).
#[test]
fn the_answer_does_not_depend_on_the_trajectory() {
    let m = Machine::builtin("mikron-hsm600").unwrap();
    let p = issue_43_rot_path();
    let run = |every_cycle: bool| {
        let opts = SimOptions {
            every_cycle,
            ..SimOptions::default()
        };
        let mut states = 0usize;
        let sim = simulate(std::slice::from_ref(&p), &m, &opts, &mut |_, _| states += 1)
            .expect("a motion the limits allow is simulated");
        (sim, states)
    };
    let ((quick, n_quick), (every, n_every)) = (run(false), run(true));
    assert_eq!(quick.time_s.to_bits(), every.time_s.to_bits());
    assert_eq!(quick.clips, every.clips);
    assert_eq!(quick.parts, every.parts);
    // Every cycle handed out: at least one state per cycle of the motion.
    assert!(n_every as f64 >= every.time_s / m.tcy_s, "{n_every}");
    assert!(n_quick <= n_every);
    // And on a line with a cruise (jumped in whole cycles), the same.
    let line = line(1, 200.0, 1.0, 3000.0);
    let t = |every_cycle: bool| {
        simulate(
            std::slice::from_ref(&line),
            &ucp(),
            &SimOptions {
                every_cycle,
                ..SimOptions::default()
            },
            &mut |_, _| {},
        )
        .unwrap()
        .time_s
    };
    assert_eq!(t(false).to_bits(), t(true).to_bits());
}
