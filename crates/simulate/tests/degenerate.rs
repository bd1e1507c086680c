//! Degenerate inputs on purpose: errors name what is wrong; extreme feeds finish with
//! bounded work; a feed change between two parts is not a stop.

mod common;

use common::{assert_within_limits, line, trajectory};
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
    let tr = trajectory(&[a, b], &m);
    assert_within_limits(&tr, &m, "feed change");
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
