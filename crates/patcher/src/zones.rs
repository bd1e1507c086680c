//! Zones as the driver patches them: merged when close ([`merge_zones`]), each with the
//! spans its patch must bring to feed ([`zone_core`]), and Equation 6's figures over a
//! range of spans ([`figures_over`]).

use crate::{
    analysis::{SpanFigures, Zone, ZoneKind},
    report::ZoneFigures,
};
use polepatch_kinematics::{Axis, LimitKind};
use std::ops::Range;

/// Zones in order, those closer than `gap` points merged.
pub fn merge_zones(zones: &[Zone], gap: usize) -> Vec<Zone> {
    let mut out: Vec<Zone> = Vec::new();
    let mut sorted = zones.to_vec();
    sorted.sort_by_key(|z| z.first);
    for z in sorted {
        match out.last_mut() {
            Some(m) if z.first <= m.last + gap => {
                if z.min_abs_primary_deg < m.min_abs_primary_deg {
                    m.singular = z.singular;
                    m.min_abs_primary_deg = z.min_abs_primary_deg;
                }
                if z.kind == ZoneKind::AFlip {
                    m.kind = ZoneKind::AFlip;
                }
                if z.last > m.last {
                    m.last = z.last;
                    m.cut_after = z.cut_after;
                }
                m.c_ratio_min = m.c_ratio_min.min(z.c_ratio_min);
            }
            _ => out.push(z),
        }
    }
    out
}

/// The spans a zone's patch must bring to feed: the zone's, ± `margin` points — except on
/// a side where the zone was cut from a longer stretch below feed ([`Zone::cut_before`],
/// [`Zone::cut_after`]): the spans beyond are slow by the program's own doing, which the
/// patch need only not make worse.
pub fn zone_core(zone: &Zone, n: usize, margin: usize) -> Range<usize> {
    let (before, after) = core_margins(zone, margin);
    zone.first.saturating_sub(before)..(zone.last + after).min(n - 1)
}

/// The core margins of `zone` before and after it, points: `margin`, or 0 on a cut side
/// ([`zone_core`]).
pub fn core_margins(zone: &Zone, margin: usize) -> (usize, usize) {
    (
        if zone.cut_before { 0 } else { margin },
        if zone.cut_after { 0 } else { margin },
    )
}

/// Equation-6 figures over the spans `spans` of a run's span figures.
pub fn figures_over(spans: &[SpanFigures], range: Range<usize>) -> ZoneFigures {
    let mut f = ZoneFigures {
        c_ratio: 1.0,
        primary_ratio: 1.0,
        overall_ratio: 1.0,
        limiting_axis: None,
        limiting_kind: LimitKind::Feed,
        time_s: 0.0,
    };
    for sp in &spans[range.start.min(spans.len())..range.end.min(spans.len())] {
        f.c_ratio = f.c_ratio.min(sp.axis_ratio[Axis::C.index()]);
        f.primary_ratio = f.primary_ratio.min(sp.axis_ratio[Axis::Primary.index()]);
        if sp.bound.ratio < f.overall_ratio {
            f.overall_ratio = sp.bound.ratio;
            f.limiting_axis = sp.bound.axis;
            f.limiting_kind = sp.bound.kind;
        }
        f.time_s += sp.time_s;
    }
    f
}
