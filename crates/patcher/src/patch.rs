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
    use crate::testutil::{machine, planted};

    /// No point within the cone: nothing changes, with either method, and no spline work
    /// is needed (no zone reported).
    #[test]
    fn no_point_in_cone_is_unchanged() {
        let m = machine("mikron-hsm600");
        let mut path = planted(41, 1.0, 8.0, false, 2000.0);
        for q in &mut path.axes {
            q[3] = q[3].abs().max(6.0);
        }
        for axes in [PatchAxes::Both, PatchAxes::OnlyC] {
            let opts = PatchOptions {
                axes,
                ..PatchOptions::default()
            };
            let res = patch_path(&path, &m, &opts).unwrap();
            assert!(res.zones.is_empty());
            assert!(!res.any_change());
            let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
            assert_eq!(res.c_deg, c);
            assert!(report_unpatched(&path, &m, &opts).unwrap().is_empty());
        }
    }

    /// A zone reported without patching: unchanged, same figures before and after.
    #[test]
    fn report_unpatched_reports_the_zone_as_it_is() {
        let m = machine("mikron-ucp710");
        let path = planted(241, 0.5, 0.5, false, 1000.0);
        let z = report_unpatched(&path, &m, &PatchOptions::default()).unwrap();
        assert_eq!(z.len(), 1);
        assert_eq!(z[0].outcome, Outcome::Unchanged);
        assert_eq!(z[0].method, Method::None);
        assert_eq!(z[0].before, z[0].after);
        assert!(z[0].before.c_ratio < 1.0);
        assert_eq!((z[0].points_modified, z[0].max_deviation_deg), (0, 0.0));
    }
}
