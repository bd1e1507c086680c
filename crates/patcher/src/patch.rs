//! Orchestration: detect, patch, verify, extend, never worse.
//!
//! [`patch_path`] analyses a run ([`crate::analysis`]), finds its singular zones and hands
//! them to one of two methods, chosen by [`PatchOptions::axes`]:
//! - [`PatchAxes::Both`] (the default, [`crate::both`]): re-select the IK branch where that
//!   alone reaches feed (zero orientation change), else solve a joint patch of the primary
//!   axis and C ([`crate::joint`]); both rotary axes must reach feed;
//! - [`PatchAxes::OnlyC`] ([`crate::c_only`]): G16's method, C alone.
//!
//! Either way each candidate is rounded as it will be written and verified with Equation 6
//! on those values ([`crate::verify`]); a zone that cannot reach feed keeps its best
//! improvement or its original values, and no sample of a checked axis gets worse.

use crate::{
    analysis::{AnalysisOptions, Zone, ZoneKind, analyze_path, validate},
    options::{PatchAxes, PatchOptions},
    path::{Path, PathError},
    peers::Strategy,
    report::{Method, Outcome, QpStats, ZoneFigures, ZoneReport},
    verify::CORE_MARGIN_POINTS,
};
use polepatch_kinematics::{Axis, LimitKind, Machine};

/// Result of patching one path: the values of both rotary axes as they must be written.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchResult {
    /// Primary axis (A or B) per point, degrees, as it must be written (rounded to
    /// `p_decimals` where changed; the input value where unchanged).
    pub p_deg: Vec<f64>,
    /// Which points' primary value changed.
    pub p_changed: Vec<bool>,
    /// Decimal places to write the changed primary values with (≥ `opts.p_decimals`).
    pub p_decimals: usize,
    /// C per point, degrees, as it must be written (rounded to `c_decimals` where changed;
    /// the input value where unchanged).
    pub c_deg: Vec<f64>,
    /// Which points' C changed.
    pub c_changed: Vec<bool>,
    /// Decimal places to write the changed C values with (≥ `opts.c_decimals`).
    pub c_decimals: usize,
    /// One row per zone.
    pub zones: Vec<ZoneReport>,
}

impl PatchResult {
    /// The path unchanged: no zone, every value as it was.
    pub fn unchanged(path: &Path, opts: &PatchOptions) -> PatchResult {
        let n = path.s_mm.len();
        PatchResult {
            p_deg: path.axes.iter().map(|q| q[Axis::Primary.index()]).collect(),
            p_changed: vec![false; n],
            p_decimals: opts.p_decimals,
            c_deg: path.axes.iter().map(|q| q[Axis::C.index()]).collect(),
            c_changed: vec![false; n],
            c_decimals: opts.c_decimals,
            zones: Vec::new(),
        }
    }
    /// Whether any value changed.
    pub fn any_change(&self) -> bool {
        self.p_changed.iter().chain(&self.c_changed).any(|&c| c)
    }
}

/// The singular zones of `path` reported as they are, without patching: what a run that
/// must not be patched (no TCPM, say) reports. Every zone is [`Outcome::Unchanged`] with
/// [`Method::None`]; its figures before and after are the same.
pub fn report_unpatched(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<Vec<ZoneReport>, PathError> {
    validate(path)?;
    let pi = Axis::Primary.index();
    if !path.axes.iter().any(|q| q[pi].abs() <= opts.cone_deg) {
        return Ok(Vec::new());
    }
    let aopts = AnalysisOptions {
        cone_deg: opts.cone_deg,
        tcy_s: opts.tcy_s,
        keep_samples: false,
    };
    let analysis = analyze_path(path, machine, &aopts)?;
    merge_zones(&analysis.zones)
        .into_iter()
        .map(|zone| {
            let f = zone_figures(path, machine, &aopts, zone.first, zone.last)?;
            Ok(ZoneReport {
                first: zone.first,
                last: zone.last,
                kind: zone.kind,
                min_abs_primary_deg: zone.min_abs_primary_deg,
                before: f,
                after: f,
                ideal_time_s: (path.s_mm[zone.last] - path.s_mm[zone.first])
                    / (path.feed_mm_min / 60.0),
                max_deviation_deg: 0.0,
                points_modified: 0,
                primary_points_modified: 0,
                reselected_points: 0,
                patch_length_mm: 0.0,
                outcome: Outcome::Unchanged,
                method: Method::None,
                qp: QpStats::default(),
                decimals: opts.c_decimals,
                p_decimals: opts.p_decimals,
                c_offset_deg: 0.0,
            })
        })
        .collect()
}

/// Zones closer than this many points are patched as one.
const MERGE_GAP_POINTS: usize = 2 * CORE_MARGIN_POINTS;

/// Points of path either side of a zone's range analysed for its report figures.
const FIGURE_MARGIN_POINTS: usize = 30;

/// Patch every singular zone of `path` with the method of `opts.axes` (or, for the quality
/// suite, the peer rule of `opts.strategy`).
///
/// Bad input is an error; every numerical outcome is in the zone reports. A path with no
/// point within the singular cone is returned unchanged without any spline work.
pub fn patch_path(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<PatchResult, PathError> {
    match (opts.strategy, opts.axes) {
        (Strategy::Polepatch, PatchAxes::Both) => crate::both::patch_both(path, machine, opts),
        (Strategy::Polepatch, PatchAxes::OnlyC) => {
            crate::c_only::patch_c_only(path, machine, opts, crate::c_only::ALL_METHODS)
        }
        (peer, _) => crate::peers::peer_patch(path, machine, opts, peer),
    }
}

/// The zones the patcher treats: in order, those closer than [`MERGE_GAP_POINTS`] merged
/// (what a report row is about).
pub fn merged_zones(zones: &[Zone]) -> Vec<Zone> {
    merge_zones(zones)
}

/// Zones in order, those closer than [`MERGE_GAP_POINTS`] merged.
pub(crate) fn merge_zones(zones: &[Zone]) -> Vec<Zone> {
    let mut out: Vec<Zone> = Vec::new();
    let mut sorted = zones.to_vec();
    sorted.sort_by_key(|z| z.first);
    for z in sorted {
        match out.last_mut() {
            Some(m) if z.first <= m.last + MERGE_GAP_POINTS => {
                if z.min_abs_primary_deg < m.min_abs_primary_deg {
                    m.singular = z.singular;
                    m.min_abs_primary_deg = z.min_abs_primary_deg;
                }
                if z.kind == ZoneKind::AFlip {
                    m.kind = ZoneKind::AFlip;
                }
                m.last = m.last.max(z.last);
                m.c_ratio_min = m.c_ratio_min.min(z.c_ratio_min);
            }
            _ => out.push(z),
        }
    }
    out
}

/// Equation-6 figures over `[s(first), s(last)]`, from the analysis of a window of the
/// path around it.
pub(crate) fn zone_figures(
    path: &Path,
    machine: &Machine,
    aopts: &AnalysisOptions,
    first: usize,
    last: usize,
) -> Result<ZoneFigures, PathError> {
    let n = path.s_mm.len();
    let lo = first.saturating_sub(FIGURE_MARGIN_POINTS);
    let hi = (last + FIGURE_MARGIN_POINTS).min(n - 1);
    let window = Path {
        s_mm: path.s_mm[lo..=hi].to_vec(),
        axes: path.axes[lo..=hi].to_vec(),
        feed_mm_min: path.feed_mm_min,
    };
    let opts = AnalysisOptions {
        keep_samples: true,
        ..aopts.clone()
    };
    let a = analyze_path(&window, machine, &opts)?;
    let (s0, s1) = (path.s_mm[first], path.s_mm[last]);
    let mut f = ZoneFigures {
        c_ratio: 1.0,
        primary_ratio: 1.0,
        overall_ratio: f64::INFINITY,
        limiting_axis: None,
        limiting_kind: LimitKind::Feed,
        time_s: 0.0,
    };
    let mut prev: Option<(f64, f64)> = None;
    for smp in a.samples.iter().filter(|x| x.s_mm >= s0 && x.s_mm <= s1) {
        f.c_ratio = f.c_ratio.min(smp.axis_ratio[Axis::C.index()]);
        f.primary_ratio = f.primary_ratio.min(smp.axis_ratio[Axis::Primary.index()]);
        if smp.bound.ratio < f.overall_ratio {
            f.overall_ratio = smp.bound.ratio;
            f.limiting_axis = smp.bound.axis;
            f.limiting_kind = smp.bound.kind;
        }
        let inv = 1.0 / smp.bound.feed_mm_s;
        if let Some((sp, ip)) = prev {
            f.time_s += 0.5 * (inv + ip) * (smp.s_mm - sp);
        }
        prev = Some((smp.s_mm, inv));
    }
    if !f.overall_ratio.is_finite() {
        f.overall_ratio = 1.0;
    }
    Ok(f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::c_only::{Methods, patch_c_only as patch_path_with};
    use crate::direct::deviation_bound_sampled;
    use crate::limits::CLimits;
    use crate::options::round_written;

    const DIRECT_ONLY: Methods = Methods {
        g16: false,
        direct: true,
    };

    fn machine(name: &str) -> Machine {
        Machine::builtin(name).expect("built-in machine")
    }

    /// A straight pass s = X whose tool axis sweeps past the pole at angular distance
    /// `d_deg`: tool axis ∝ (sin d, sin(τ(s)), 1), τ sweeping 0.4°/mm. `flip`: primary
    /// and C by the domain rule (sign of j: A flips and C jumps ~180° where j crosses 0);
    /// else the continuous branch A ≥ 0 (C swings ~180°).
    fn planted(n: usize, spacing: f64, d_deg: f64, flip: bool, feed: f64) -> Path {
        let mid = (n - 1) as f64 * spacing / 2.0;
        let mut s_mm = Vec::new();
        let mut axes = Vec::new();
        let mut prev_c: Option<f64> = None;
        for k in 0..n {
            let s = k as f64 * spacing;
            let v = [
                d_deg.to_radians().sin(),
                ((s - mid) * 0.4).to_radians().sin(),
                1.0,
            ];
            let nv = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let (i, j, kk) = (v[0] / nv, v[1] / nv, v[2] / nv);
            // i = sin C sin A, j = −cos C sin A, k = cos A.
            let mut a = kk.clamp(-1.0, 1.0).acos().to_degrees();
            let mut c = i.atan2(-j).to_degrees();
            if flip && j > 0.0 {
                a = -a;
                c = (-i).atan2(j).to_degrees();
            }
            if let Some(pc) = prev_c
                && !flip
            {
                while c - pc > 180.0 {
                    c -= 360.0;
                }
                while c - pc < -180.0 {
                    c += 360.0;
                }
            }
            let c = round_written(c, 3);
            prev_c = Some(c);
            s_mm.push(s);
            axes.push([s, 0.0, 0.0, round_written(a, 3), c]);
        }
        Path {
            s_mm,
            axes,
            feed_mm_min: feed,
        }
    }

    /// Checks the invariants of a patched path and returns a summary line.
    fn check_invariants(path: &Path, m: &Machine, res: &PatchResult, opts: &PatchOptions) {
        let before = analyze_path(path, m, &AnalysisOptions::default()).unwrap();
        let mut after_path = path.clone();
        for (q, c) in after_path.axes.iter_mut().zip(&res.c_deg) {
            q[4] = *c;
        }
        // Only C changes, and `changed` says where.
        for (i, (a, b)) in path.axes.iter().zip(&after_path.axes).enumerate() {
            assert_eq!(a[..4], b[..4]);
            assert_eq!(res.c_changed[i], a[4] != b[4]);
        }
        let after = analyze_path(&after_path, m, &AnalysisOptions::default()).unwrap();
        // Never worse on C.
        assert!(
            after.axis_min[4].0 >= before.axis_min[4].0 - 1e-9,
            "C ratio got worse: {} -> {}",
            before.axis_min[4].0,
            after.axis_min[4].0
        );
        for z in &res.zones {
            if z.min_abs_primary_deg <= opts.cone_deg {
                assert_eq!(z.outcome, Outcome::Reached, "zone not reached: {z:#?}");
                assert!(z.after.c_ratio >= 1.0 - 1e-9, "{z:#?}");
            }
        }
        // C reaches feed everywhere the zones were.
        assert!(after.zones.is_empty(), "zones left: {:?}", after.zones);
    }

    #[test]
    fn planted_passes_reach_feed() {
        let opts = PatchOptions::default();
        for (mname, feed) in [("mikron-hsm600", 3000.0), ("mikron-ucp710", 1000.0)] {
            let m = machine(mname);
            for flip in [false, true] {
                for d in [0.01, 0.5, 2.0, 4.0] {
                    for spacing in [1.0, 0.5] {
                        let n = (120.0 / spacing) as usize + 1;
                        let path = planted(n, spacing, d, flip, feed);
                        let res = patch_path_with(&path, &m, &opts, DIRECT_ONLY).unwrap();
                        for z in &res.zones {
                            eprintln!(
                                "{mname} F{feed} flip={flip} d={d} h={spacing}: {:?} {:?} \
                                 c {:.3}->{:.3} len {:.1} pts {} dev {:.3} dec {} t {:.3}s/{}",
                                z.kind,
                                z.outcome,
                                z.before.c_ratio,
                                z.after.c_ratio,
                                z.patch_length_mm,
                                z.points_modified,
                                z.max_deviation_deg,
                                z.decimals,
                                z.qp.solve_time_s,
                                z.qp.solves
                            );
                        }
                        check_invariants(&path, &m, &res, &opts);
                    }
                }
            }
        }
    }

    /// The same planted passes through [`patch_path`] (G16 first, direct as fallback).
    #[test]
    fn planted_passes_reach_feed_with_g16() {
        let opts = PatchOptions {
            axes: PatchAxes::OnlyC,
            ..PatchOptions::default()
        };
        for (mname, feed) in [("mikron-hsm600", 2000.0), ("mikron-ucp710", 2000.0)] {
            let m = machine(mname);
            for flip in [false, true] {
                for d in [0.01, 0.5, 2.0, 4.0] {
                    let path = planted(121, 1.0, d, flip, feed);
                    let res = patch_path(&path, &m, &opts).unwrap();
                    for z in &res.zones {
                        eprintln!(
                            "g16+direct {mname} F{feed} flip={flip} d={d}: {:?} {:?} {:?} \
                             len {:.1} dev {:.3}",
                            z.kind, z.outcome, z.method, z.patch_length_mm, z.max_deviation_deg
                        );
                    }
                    check_invariants(&path, &m, &res, &opts);
                }
            }
        }
    }

    #[test]
    fn no_point_in_cone_is_unchanged() {
        let m = machine("mikron-hsm600");
        let mut path = planted(41, 1.0, 8.0, false, 2000.0);
        for q in &mut path.axes {
            q[3] = q[3].abs().max(6.0);
        }
        let res = patch_path(&path, &m, &PatchOptions::default()).unwrap();
        assert!(res.zones.is_empty());
        assert!(!res.any_change());
        let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
        assert_eq!(res.c_deg, c);
    }

    #[test]
    fn tiny_paths_and_the_exact_pole_do_not_panic() {
        let m = machine("mikron-ucp710");
        let three = Path {
            s_mm: vec![0.0, 1.0, 2.0],
            axes: vec![
                [0.0, 0.0, 0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0, 0.0, 90.0],
                [2.0, 0.0, 0.0, -1.0, 180.0],
            ],
            feed_mm_min: 2000.0,
        };
        let res = patch_path_with(&three, &m, &PatchOptions::default(), DIRECT_ONLY).unwrap();
        assert_eq!(res.c_deg.len(), 3);
        let mut pole = planted(81, 1.0, 0.0, false, 2000.0);
        pole.axes[40][3] = 0.0;
        let res = patch_path_with(&pole, &m, &PatchOptions::default(), DIRECT_ONLY).unwrap();
        assert_eq!(res.c_deg.len(), 81);
    }

    /// The C17 `%SING` program (N110..N620), s = X, on both built-in machines.
    #[test]
    fn c17_sing() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/c17/SING.I"
        ))
        .unwrap();
        let mut axes = Vec::new();
        for line in text.lines() {
            let nnum: usize = match line.strip_prefix('N').and_then(|r| r.split(' ').next()) {
                Some(v) => v.parse().unwrap_or(0),
                None => continue,
            };
            if !(110..=610).contains(&nnum) {
                continue;
            }
            let word = |l: char| -> f64 {
                line.split(' ')
                    .find_map(|w| w.strip_prefix(l))
                    .unwrap()
                    .parse()
                    .unwrap()
            };
            axes.push([word('X'), 0.0, -8.0, word('A'), word('C')]);
        }
        assert_eq!(axes.len(), 51);
        let path = Path {
            s_mm: axes.iter().map(|q| q[0]).collect(),
            axes,
            feed_mm_min: 2000.0,
        };
        let opts = PatchOptions::default();
        for mname in ["mikron-ucp710", "mikron-hsm600"] {
            let m = machine(mname);
            let res = patch_path_with(&path, &m, &opts, DIRECT_ONLY).unwrap();
            assert!(!res.zones.is_empty());
            let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
            let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
            for z in &res.zones {
                let step = 2000.0 / 60.0 * m.tcy_s;
                let lim0 = CLimits::new(&m, 2000.0, 0.0);
                let (bound, _) =
                    deviation_bound_sampled(&path.s_mm, &p, &c, z.first, z.last, &lim0, step)
                        .unwrap();
                eprintln!(
                    "SING {mname}: {:?} {:?} c {:.3}->{:.3} pts {}..{} len {:.1} mod {} \
                     dev {:.3} bound {:.3} dec {} qp {:.4}s/{} time {:.3}->{:.3} ideal {:.3}",
                    z.kind,
                    z.outcome,
                    z.before.c_ratio,
                    z.after.c_ratio,
                    z.first,
                    z.last,
                    z.patch_length_mm,
                    z.points_modified,
                    z.max_deviation_deg,
                    bound,
                    z.decimals,
                    z.qp.solve_time_s,
                    z.qp.solves,
                    z.before.time_s,
                    z.after.time_s,
                    z.ideal_time_s
                );
                assert!(bound <= z.max_deviation_deg + 1e-6);
            }
            check_invariants(&path, &m, &res, &opts);
        }
    }
}
