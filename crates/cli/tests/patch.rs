//! The patcher's invariants on every fixture and the built-in machines it fits, and on seeded
//! random near-pole passes, for both methods:
//! - default (issue 8): every zone reaches feed on both rotary axes when the written file
//!   is read back and analysed; only rotary words differ; nothing gets worse anywhere;
//! - `--only-c` (issue 4): every zone reaches feed on C; only C words differ; no run's C
//!   ratio gets worse.
//!
//! Either way a program without zone comes out byte-identical.

mod common;
use common::*;
use polepatch::kinematics::Axis;
use polepatch::patcher::{PatchAxes, PatchOptions};

/// The options of the C-only method, otherwise the defaults.
fn only_c() -> PatchOptions {
    PatchOptions {
        axes: PatchAxes::OnlyC,
        ..PatchOptions::default()
    }
}
use polepatch_fixturegen::{Dialect, Pass, program};

/// Every fixture on each built-in machine it was posted for (on the other it is refused,
/// [`machines_for`]).
#[test]
fn every_fixture_on_its_machines() {
    let files = fixtures();
    assert!(
        files.len() >= 50,
        "expected the committed fixture set, found {}",
        files.len()
    );
    let mut zones = 0;
    for f in &files {
        let bytes = std::fs::read(f).unwrap();
        for m in machines_for(&name_of(f), &bytes) {
            for opts in [PatchOptions::default(), only_c()] {
                let (rep, _) = check_patch(&name_of(f), &bytes, &m, &opts);
                zones += rep.zones.len();
            }
        }
    }
    assert!(zones > 0);
}

/// splitmix64: a tiny seeded generator, so the sweep is reproducible.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[((self.next() * xs.len() as f64) as usize).min(xs.len() - 1)]
    }
}

#[test]
fn seeded_random_near_pole_passes() {
    let mut rng = Rng(0x5EED_2026);
    let machines = machines();
    let opts = PatchOptions::default();
    for case in 0..40 {
        let m = &machines[(rng.next() * 2.0) as usize % 2];
        let feed_mm_min: f64 = rng.pick(&[800.0, 1500.0, 2000.0, 3000.0, 5000.0]);
        // Near the pole the tool axis' azimuth turns by up to 180°; with C-only changes C
        // must make that turn at |C_s| ≤ V/F, so a run shorter than ~180°/(V/F) cannot
        // reach feed whatever the patch. Draw runs long enough for a patch to exist (the
        // impossible case has its own test below).
        let v_deg_mm = m.limit(Axis::C).v / (feed_mm_min / 60.0);
        let length_mm = (20.0 + 60.0 * rng.next()).max(1.5 * 180.0 / v_deg_mm + 10.0);
        let spacing_mm = rng.pick(&[0.25f64, 0.5, 1.0]).max(length_mm / 300.0);
        let pass = Pass {
            pole_distance_deg: rng.pick(&[0.0, 0.001, 0.05, 0.3, 1.0, 2.5, 4.0])
                * (0.5 + rng.next()),
            circle_radius_deg: 5.0 + 25.0 * rng.next(),
            half_sweep_deg: 30.0 + 60.0 * rng.next(),
            azimuth_deg: 360.0 * rng.next(),
            length_mm,
            spacing_mm,
            feed_mm_min,
            // Posted for the machine drawn (its tilting letter); the draw is kept so the
            // sequence of cases stays the same.
            b_axis: {
                let _ = rng.next();
                m.primary_letter() == 'B'
            },
            domain_rule: rng.next() < 0.5,
            rotary_decimals: rng.pick(&[3, 4]),
        };
        let dialect = rng.pick(&Dialect::ALL);
        let text = program(&pass, dialect, "CASE");
        for opts in [&opts, &only_c()] {
            check_patch(
                &format!("case {case} on {}: {pass:?} {dialect:?}", m.name),
                text.as_bytes(),
                m,
                opts,
            );
        }
    }
}

/// Seeded case 36 above (Sinumerik, an A flip 3.18° from the pole at F800 on the UCP710):
/// the analysis spline carries the flip's turn of C into the spans before it, 5°–8° from
/// the pole, at 0.73 → 0.03 of feed, and no span-by-span dominance test attributes them to
/// the pole. While they were outside the zone (lines 40–57), the patch had only to keep them
/// "not worse"; with the regularised factorisation first it lifted them to 0.982 and said
/// `reached`, and `analyze` of its output found a zone there. Within the pole reach they
/// are the zone's (lines 34–57), so the patch must reach feed over them with either
/// factorisation (`check_patch` analyses the written program).
#[test]
fn spans_a_flip_slows_within_the_reach_are_its_zone() {
    let pass = Pass {
        pole_distance_deg: 3.183_191_916_212_654_5,
        circle_radius_deg: 23.201_020_158_566_607,
        half_sweep_deg: 52.748_714_207_990_93,
        azimuth_deg: 223.730_113_551_432_65,
        length_mm: 40.0,
        spacing_mm: 0.5,
        feed_mm_min: 800.0,
        b_axis: false,
        domain_rule: true,
        rotary_decimals: 3,
    };
    let text = program(&pass, Dialect::Sinumerik, "CASE");
    let m = polepatch::kinematics::Machine::builtin("mikron-ucp710").unwrap();
    // The zone: from the first span below feed (|A| 7.8°) through the flip (|A| 3.18°).
    assert_eq!(analysed_zone_lines(text.as_bytes(), &m), [[34, 57]]);
    for unregularised_first in [true, false] {
        let mut opts = PatchOptions::default();
        opts.solver.ipm.unregularised_first = unregularised_first;
        let name = format!("case 36, unregularised first {unregularised_first}");
        let (report, _) = check_patch(&name, text.as_bytes(), &m, &opts);
        assert_eq!(report.zones.len(), 1, "{name}: {:?}", report.zones);
        let z = &report.zones[0];
        assert_eq!(
            z.outcome,
            polepatch::patcher::Outcome::Reached,
            "{name}: {z:?}"
        );
    }
}

/// Seeded case 63 of the sequence above, beyond its first 40 (Heidenhain, B-C on the
/// HSM600: a flip 0.04° from the pole, and the (−180°, 180°] domain flipping B at 10.0° →
/// −10.9°, just beyond the pole reach, at 0.095 of feed: not a zone). The patch of the pole
/// flip reaches feed over its core, but its range ends in the domain flip and leaves B at
/// 7.7° there with C at 0.388: better than before, yet `analyze` of the written program
/// finds a zone there. The report said `reached`; it must agree with the analysis of what
/// it wrote: `reached` only when that finds no zone within the patch's lines, else the
/// figures cover that zone too.
#[test]
fn a_reached_claim_agrees_with_the_analysis_of_the_output() {
    let pass = Pass {
        pole_distance_deg: 0.041_260_729_517_458_09,
        circle_radius_deg: 24.713_642_664_709_464,
        half_sweep_deg: 74.480_663_728_953_25,
        azimuth_deg: 192.006_061_848_677_4,
        length_mm: 35.438_970_353_524_745,
        spacing_mm: 0.5,
        feed_mm_min: 800.0,
        b_axis: true,
        domain_rule: true,
        rotary_decimals: 4,
    };
    let text = program(&pass, Dialect::Heidenhain, "CASE");
    let m = polepatch::kinematics::Machine::builtin("mikron-hsm600").unwrap();
    assert_eq!(analysed_zone_lines(text.as_bytes(), &m).len(), 1);
    let (out, report) =
        polepatch::patch_nc(text.as_bytes(), &m, &polepatch::PatchOptions::default()).unwrap();
    assert_eq!(report.zones.len(), 1, "{:?}", report.zones);
    let z = &report.zones[0];
    let left: Vec<_> = analysed_zone_lines(&out, &m)
        .into_iter()
        .filter(|l| l[0] <= z.lines[1] && l[1] >= z.lines[0])
        .collect();
    if z.outcome == polepatch::Outcome::Reached {
        assert!(
            left.is_empty(),
            "reached, yet analyze finds {left:?}: {z:?}"
        );
    } else {
        assert!(
            !left.is_empty() && z.after.overall_ratio < 1.0,
            "{left:?} {z:?}"
        );
        assert!(z.after.overall_ratio > z.before.overall_ratio, "{z:?}");
    }
}

/// Seeded case 279 of the sequence above, beyond its first 40 (Sinumerik, B-C on the
/// HSM600, through the pole at F1500): the post's (−180°, 180°] domain switches the branch
/// at B +10.27° → −11.45° (C 180° round), just beyond the pole reach, and the spans before
/// it crawl within the reach. The zone stopped at the reach, and no patch of it reached feed
/// (`not_found`, while the feasibility LP says values that do exist). The switch is the
/// zone's: re-selecting the branch reaches feed with no change of orientation.
#[test]
fn a_branch_switch_just_beyond_the_reach_is_reselected() {
    let pass = Pass {
        pole_distance_deg: 0.001_250_637_539_959_201_2,
        circle_radius_deg: 19.849_896_186_897_936,
        half_sweep_deg: 70.147_051_961_694_93,
        azimuth_deg: 194.601_265_055_904_66,
        length_mm: 39.114_014_431_998_01,
        spacing_mm: 1.0,
        feed_mm_min: 1500.0,
        b_axis: true,
        domain_rule: true,
        rotary_decimals: 4,
    };
    let text = program(&pass, Dialect::Sinumerik, "CASE");
    let m = polepatch::kinematics::Machine::builtin("mikron-hsm600").unwrap();
    let (report, _) = check_patch("case 279", text.as_bytes(), &m, &PatchOptions::default());
    assert_eq!(report.zones.len(), 1, "{:?}", report.zones);
    let z = &report.zones[0];
    assert_eq!(z.reason, polepatch::ZoneReason::Reselected, "{z:?}");
    assert!(z.max_deviation_deg < 1e-9, "{z:?}");
}

/// A pass 1° from the pole on a 5° circle, 15 mm long at F5000 on the UCP710, followed by
/// a move that programs the rotary axes with a linear move (so its last point must stay,
/// `polepatch::end_pose`): the tool axis must turn far more than A and C can in 15 mm.
/// No values of the run's points reach feed — the convex feasibility LP proves it — and
/// both methods keep what they have (best improvement or nothing), never worse.
#[test]
fn impossible_zone_keeps_the_best_improvement() {
    let pass = Pass {
        pole_distance_deg: 1.0,
        circle_radius_deg: 5.0,
        half_sweep_deg: 80.0,
        azimuth_deg: 0.0,
        length_mm: 15.0,
        spacing_mm: 0.5,
        feed_mm_min: 5000.0,
        b_axis: false,
        domain_rule: false,
        rotary_decimals: 3,
    };
    let text =
        program(&pass, Dialect::Fanuc, "SHORT").replace("\nG49\n", "\nG0 Z50. A0. C0.\nG49\n");
    let m = polepatch::kinematics::Machine::builtin("mikron-ucp710").unwrap();
    let lp = load_bytes(text.as_bytes(), "short", &m);
    assert!(!lp.end_pose(0).free);
    // The proof: with the last point fixed, no values of points 1..n−2 reach feed.
    let path = lp.runs[0].path.as_ref().unwrap();
    let n = path.s_mm.len();
    let p: Vec<f64> = path.axes.iter().map(|q| q[Axis::Primary.index()]).collect();
    let c: Vec<f64> = path.axes.iter().map(|q| q[Axis::C.index()]).collect();
    let reachable = polepatch::patcher::quality::reachable(
        &path.s_mm,
        &p,
        &c,
        1,
        n - 2,
        0..n - 1,
        &m,
        path.feed_mm_min,
        polepatch::patcher::PatchAxes::Both,
        true,
    )
    .unwrap();
    assert!(!reachable, "the planted zone must be unreachable");
    for opts in [PatchOptions::default(), only_c()] {
        let (out, report) = patch_lp(&lp, &m, &opts);
        assert!(!report.zones.is_empty());
        for z in &report.zones {
            assert_ne!(z.outcome, polepatch::Outcome::Reached, "{z:?}");
            assert!(z.after.c_ratio >= z.before.c_ratio, "{z:?}");
            assert!(z.after.primary_ratio >= z.before.primary_ratio, "{z:?}");
        }
        assert_only_rotary_words_differ("short", text.as_bytes(), &out);
        let before = c_ratios_and_zones(&lp, &m, 5.0);
        let after = c_ratios_and_zones(&load_bytes(&out, "short", &m), &m, 5.0);
        assert!(after[0].0 >= before[0].0, "{before:?} → {after:?}");
    }
}

/// With both axes free but the orientation change capped far below what any patch needs
/// (`max_deviation_deg`), `%SING` cannot reach feed: the zone keeps its best improvement
/// within the cap (or its values), and no sample of any axis gets worse.
#[test]
fn capped_deviation_keeps_the_best_improvement() {
    let bytes = std::fs::read(root().join("fixtures/c17/SING.I")).unwrap();
    let m = polepatch::kinematics::Machine::builtin("mikron-ucp710").unwrap();
    let opts = PatchOptions {
        max_deviation_deg: Some(0.05),
        ..PatchOptions::default()
    };
    let lp = load_bytes(&bytes, "SING", &m);
    let (out, report) = patch_lp(&lp, &m, &opts);
    assert_eq!(report.zones.len(), 1);
    let z = &report.zones[0];
    assert_ne!(z.outcome, polepatch::Outcome::Reached, "{z:?}");
    assert_eq!(z.reason, polepatch::ZoneReason::DeviationCap, "{z:?}");
    assert!(z.max_deviation_deg <= 0.05 + 1e-9, "{z:?}");
    assert!(z.after.c_ratio >= z.before.c_ratio && z.after.primary_ratio >= z.before.primary_ratio);
    assert_only_rotary_words_differ("SING", &bytes, &out);
}

/// Issue 21: `max_deviation_deg` holds on the exact angle of the written words, and a cap
/// the default meets changes nothing: on every fixture and both machines, capped at the
/// default's largest deviation in the file, every zone still reaches feed within the cap
/// and the output is the default's, byte for byte — or (issue 41's plan, below) one that
/// turns the tool less.
#[test]
fn a_cap_the_default_meets_changes_nothing() {
    let (mut capped, mut changed) = (0, 0);
    for f in &fixtures() {
        let bytes = std::fs::read(f).unwrap();
        let name = name_of(f);
        for m in machines_for(&name, &bytes) {
            let lp = load_bytes(&bytes, &name, &m);
            let (out, report) = patch_lp(&lp, &m, &PatchOptions::default());
            if report.zones.is_empty() {
                continue;
            }
            let worst = report
                .zones
                .iter()
                .map(|z| z.max_deviation_deg)
                .fold(0.0, f64::max);
            if worst <= 0.0
                || report
                    .zones
                    .iter()
                    .any(|z| z.reason == polepatch::ZoneReason::ToolLimited)
            {
                // The default is itself capped here, by a flat or bull-nose cutter's
                // surface bound: its best improvement within that cap is not one a lower
                // cap must reproduce (and a cap of 0 is a different request).
                continue;
            }
            let opts = PatchOptions {
                max_deviation_deg: Some(worst),
                ..PatchOptions::default()
            };
            let (out_c, report_c) = patch_lp(&lp, &m, &opts);
            for (a, b) in report.zones.iter().zip(&report_c.zones) {
                assert!(
                    b.max_deviation_deg <= worst + 1e-9,
                    "{name} on {}: {b:?}",
                    m.name
                );
                assert_eq!(
                    (a.outcome, a.reason),
                    (b.outcome, b.reason),
                    "{name} on {}",
                    m.name
                );
            }
            // The plan chooses among a run's patches (end pinned, end free, start free:
            // crate::plan) the one that turns the tool least; the patcher's search is not
            // monotone in the cap (capped, it may find a patch below the cap that the
            // uncapped search passed by), so the capped plan may pick another patch — never
            // one that turns the tool more.
            let worst_c = report_c
                .zones
                .iter()
                .map(|z| z.max_deviation_deg)
                .fold(0.0, f64::max);
            assert!(
                out == out_c || worst_c < worst,
                "{name} on {}: the cap changed the output ({worst:.4}° → {worst_c:.4}°)",
                m.name
            );
            changed += usize::from(out != out_c);
            capped += 1;
        }
    }
    assert!(capped > 50, "{capped}");
    // Most programs: the same output, byte for byte.
    assert!(changed * 10 <= capped, "{changed} of {capped} changed");
}

/// Issue 21: C17's `%SING` reached feed at 1.000° by default but was left unchanged with
/// `--max-deviation 1.0` or `1.2` (the cap was imposed on a linearised chord of a cold
/// solve). Now it reaches feed within any cap from the default's deviation up — which
/// is the pass's distance from the pole, 1°, to 1e-3 (the tool passes through the pole).
/// A cap below the default's deviation by less than the SCP's stopping tolerance
/// (1 %; SING's default is 1.0001° today, 0.99999° at margin 0 with the previous solver)
/// may or may not be met: SPEC §6 promises caps at or above what the default achieves.
#[test]
fn sing_capped_at_one_degree_or_more_reaches_feed() {
    let bytes = std::fs::read(root().join("fixtures/c17/SING.I")).unwrap();
    let m = polepatch::kinematics::Machine::builtin("mikron-ucp710").unwrap();
    let lp = load_bytes(&bytes, "SING", &m);
    let (_, report) = patch_lp(&lp, &m, &PatchOptions::default());
    let default_deg = report.zones[0].max_deviation_deg;
    assert!((default_deg - 1.0).abs() < 1e-3, "{default_deg}");
    for cap in [default_deg, 1.2] {
        let opts = PatchOptions {
            max_deviation_deg: Some(cap),
            ..PatchOptions::default()
        };
        let (_, report) = patch_lp(&lp, &m, &opts);
        let z = &report.zones[0];
        assert_eq!(
            (z.outcome, z.reason),
            (polepatch::Outcome::Reached, polepatch::ZoneReason::Reached),
            "cap {cap}: {z:?}"
        );
        assert!(z.max_deviation_deg <= cap + 1e-9, "cap {cap}: {z:?}");
    }
}

/// A zigzag finishing program: many runs, one zone each, patched in one file.
#[test]
fn zigzag_program_with_many_zones() {
    let base = Pass {
        domain_rule: true,
        ..Pass::default()
    };
    for m in machines() {
        let base = Pass {
            b_axis: m.primary_letter() == 'B',
            ..base.clone()
        };
        let text = polepatch_fixturegen::zigzag_program(
            &base,
            8,
            &[0.1, 0.5, 1.0, 2.0, 4.0, 0.05],
            "ZIGZAG",
        );
        for opts in [PatchOptions::default(), only_c()] {
            let (rep, _) = check_patch("zigzag", text.as_bytes(), &m, &opts);
            assert!(
                rep.zones.len() >= 6,
                "{} zones on {}",
                rep.zones.len(),
                m.name
            );
        }
    }
}

/// Issue 8: a generated HSM600 pass at F4000 with 3-decimal rotary words reached feed only
/// with `--max-decimals 6` (the old default, 4, left it "improved"). With the defaults it
/// reaches feed on both axes — written with the file's decimals when the patch's values
/// hold Equation 6 rounded to them, else with more, up to 6 — and the report says how many.
#[test]
fn f4000_on_the_hsm600_with_three_decimals_reaches_feed_by_default() {
    let m = polepatch::kinematics::Machine::builtin("mikron-hsm600").unwrap();
    for (spacing_mm, d) in [(0.25, 1.0), (0.5, 0.5)] {
        let pass = Pass {
            pole_distance_deg: d,
            spacing_mm,
            feed_mm_min: 4000.0,
            b_axis: true,
            rotary_decimals: 3,
            ..Pass::default()
        };
        let text = program(&pass, Dialect::Fanuc, "F4K");
        let (rep, _) = check_patch("f4000", text.as_bytes(), &m, &PatchOptions::default());
        assert!(!rep.zones.is_empty());
        assert!(
            rep.zones
                .iter()
                .all(|z| z.outcome == polepatch::Outcome::Reached),
            "{rep:?}"
        );
        assert_eq!(rep.file_c_decimals, Some(3));
        let written = rep.written_c_decimals.unwrap();
        assert!((3..=6).contains(&written), "{rep:?}");
        assert!(
            rep.zones
                .iter()
                .all(|z| z.decimals <= 6 && z.primary_decimals <= 6)
        );
    }
}

/// Issue 31 §3: the positioning move after a run whose end is free starts from the patched
/// end. On a zigzag of near-pole passes every such move's time is reported before and after,
/// and a run whose patched end makes that move slower keeps the end only when the run plus
/// the move is still faster than with its end pinned: over each run, zone times plus the
/// move's time after are at most what they were before.
#[test]
fn rapids_after_runs_are_accounted_for() {
    let base = Pass {
        domain_rule: true,
        ..Pass::default()
    };
    for m in machines() {
        let base = Pass {
            b_axis: m.primary_letter() == 'B',
            ..base.clone()
        };
        let text = polepatch_fixturegen::zigzag_program(
            &base,
            10,
            &[0.1, 0.5, 1.0, 2.0, 4.0, 0.3, 0.05, 1.5, 0.2, 3.0],
            "ZIGZAG",
        );
        let lp = load_bytes(text.as_bytes(), "zigzag", &m);
        let (_, report) = patch_lp(&lp, &m, &PatchOptions::default());
        let mut with_rapid = 0;
        let runs: std::collections::BTreeSet<usize> = report.zones.iter().map(|z| z.run).collect();
        for run in runs {
            let zones: Vec<_> = report.zones.iter().filter(|z| z.run == run).collect();
            let last = zones.last().unwrap();
            let (Some(rb), Some(ra)) = (last.rapid_time_before_s, last.rapid_time_after_s) else {
                continue;
            };
            with_rapid += 1;
            assert!(last.rapid_line.is_some(), "{last:?}");
            let before: f64 = zones.iter().map(|z| z.before.time_s).sum::<f64>() + rb;
            let after: f64 = zones.iter().map(|z| z.after.time_s).sum::<f64>() + ra;
            assert!(
                after <= before + 1e-3,
                "{} run {run}: zones and rapid {before:.3} s → {after:.3} s",
                m.name
            );
            // The plan keeps every positioning move as fast (crate::plan).
            assert!(ra <= rb + 1e-3, "{} run {run}: {rb} s → {ra} s", m.name);
        }
        // Every pass but the last is followed by the next pass's positioning move.
        assert!(
            with_rapid >= 8,
            "{}: {with_rapid} runs with a rapid",
            m.name
        );
    }
}

/// Issue 41: a zigzag of near-pole passes posted on the continuous branch (A ≥ 0, C
/// swinging half a turn where a pass goes by the pole), the passes alternating direction.
/// A pass's zone is cheapest re-selected onto the other branch, which its end then keeps;
/// the next pass can start on that branch (the positioning move between them rewritten to
/// the same tool axis). The plan over the passes carries the branch: every zone reaches
/// feed, each within 1.25× (+0.01°) of the reference that lets each run end on either
/// branch, every positioning move no slower than the input's, and the written program
/// verifies (`verify_nc`: the move's clearance included).
#[test]
fn zigzag_passes_carry_the_branch_and_keep_the_positioning_moves() {
    use polepatch::patcher::patch_path;
    let base = Pass {
        domain_rule: false,
        ..Pass::default()
    };
    for m in machines() {
        let base = Pass {
            b_axis: m.primary_letter() == 'B',
            ..base.clone()
        };
        let text = polepatch_fixturegen::zigzag_program(&base, 8, &[0.0, 0.4, 0.9, 0.05], "ZIGZAG");
        let lp = load_bytes(text.as_bytes(), "zigzag", &m);
        let opts = PatchOptions::default();
        let (out, report) = patch_lp(&lp, &m, &opts);
        // The reference: each run alone, its end free.
        let free = PatchOptions {
            keep_last_point: false,
            ..opts.clone()
        };
        let mut carried = 0;
        let mut worst_ref = 0.0f64;
        for run in report
            .zones
            .iter()
            .map(|z| z.run)
            .collect::<std::collections::BTreeSet<_>>()
        {
            let zones: Vec<_> = report.zones.iter().filter(|z| z.run == run).collect();
            let path = lp.runs[run - 1].path.as_ref().expect("a path");
            let reference = patch_path(path, &m, &free).expect("the reference patch");
            let ref_dev = reference
                .zones
                .iter()
                .map(|z| z.max_deviation_deg)
                .fold(0.0, f64::max);
            worst_ref = worst_ref.max(ref_dev);
            for z in &zones {
                assert_eq!(
                    z.outcome,
                    polepatch::patcher::Outcome::Reached,
                    "{} {z:?}",
                    m.name
                );
                assert!(
                    z.max_deviation_deg <= 1.25 * ref_dev + 0.01,
                    "{} run {run}: {:.3}° against the reference's {ref_dev:.3}°",
                    m.name,
                    z.max_deviation_deg
                );
            }
            let last = zones.last().expect("a zone");
            if let (Some(rb), Some(ra)) = (last.rapid_time_before_s, last.rapid_time_after_s) {
                assert!(ra <= rb + 1e-3, "{} run {run}: {rb} s → {ra} s", m.name);
            }
            carried += usize::from(zones[0].start_branch == Some(polepatch::Branch::Other));
        }
        assert!(
            carried >= 2,
            "{}: {carried} passes start on the other branch",
            m.name
        );
        let v = polepatch::verify::verify_nc(
            text.as_bytes(),
            &out,
            &m,
            &polepatch::PatchOptions::default(),
            "zigzag",
        )
        .expect("verify reads both");
        assert!(v.passed(), "{}: {:?}", m.name, v.violations);
        assert!(v.time_after_s <= v.time_before_s, "{}: {v:?}", m.name);
        // `--max-deviation` at 1.1× the reference's largest: every zone still at feed.
        let capped = PatchOptions {
            max_deviation_deg: Some(1.1 * worst_ref),
            ..PatchOptions::default()
        };
        let (_, report_c) = patch_lp(&lp, &m, &capped);
        for z in &report_c.zones {
            assert_eq!(
                z.outcome,
                polepatch::patcher::Outcome::Reached,
                "{} {z:?}",
                m.name
            );
            assert!(
                z.max_deviation_deg <= 1.1 * worst_ref + 1e-9,
                "{} {z:?}",
                m.name
            );
        }
    }
}
