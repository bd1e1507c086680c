//! Report documents (serde): what `analyze` prints, as data.
//!
//! Every report type of the library in one place: [`AnalyzeReport`] (what `polepatch analyze`
//! reports), [`FileReport`] (`polepatch patch --report`), [`SimulateReport`] (`polepatch simulate`),
//! and the names they print axes, limits, zone kinds, feeds and feed modes with.

mod analyze;
mod patch;
mod simulate;

pub use analyze::{AnalyzeReport, MachineFrameFigures, RunFigures, RunReport, ZoneSummary};
pub use patch::{
    FiguresRow, FileReport, UntouchedReason, UntouchedRun, ZoneRow, feed_mode_name, method_name,
    outcome_name,
};
pub use simulate::{RunTimes, SimRun, SimTotals, SimulateReport, SimulatedTimes, compare};

/// A line carried through without analysis, and why ([`FileReport::not_analysed`]).
pub use crate::notes::{NotAnalysed, SkipReason};

use polepatch_kinematics::{Axis, LimitKind};
use polepatch_nc::RotaryLetters;
use polepatch_patcher::ZoneKind;

/// Axis letter as written in the program (the rotary axes: the letters in use, e.g. A
/// and C, or A and B on an A-B trunnion).
pub fn axis_letter(axis: Axis, letters: RotaryLetters) -> String {
    match axis {
        Axis::X => "X".into(),
        Axis::Y => "Y".into(),
        Axis::Z => "Z".into(),
        Axis::Primary => (letters.tilt as char).to_string(),
        Axis::C => (letters.pole as char).to_string(),
    }
}

/// Short name of a limit: `V`, `A`, `J`, or `F` (the programmed feed).
pub fn limit_name(kind: LimitKind) -> &'static str {
    match kind {
        LimitKind::Feed => "F",
        LimitKind::Velocity => "V",
        LimitKind::Acceleration => "A",
        LimitKind::Jerk => "J",
    }
}

/// Speed in the machine tables' units: m/min for a linear axis (from mm/s), rpm for a
/// rotary axis (from °/s).
pub fn machine_units(axis: Axis, internal: f64) -> f64 {
    if axis.is_rotary() {
        internal / 6.0
    } else {
        internal * 0.06
    }
}

/// Name of a zone kind in reports.
pub fn zone_kind_name(kind: ZoneKind) -> &'static str {
    match kind {
        ZoneKind::AFlip => "A-flip",
        ZoneKind::CSwing => "C-swing",
    }
}

/// A feed for people, mm/min: at most 3 decimals, trailing zeros dropped (`248.92`, not
/// `248.92000000000002`, the inch feed F9.8 × 25.4 as computed).
pub fn feed_text(feed_mm_min: f64) -> String {
    let s = format!("{feed_mm_min:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}

#[cfg(test)]
mod tests {
    use super::feed_text;

    /// Issue 30 item 9: feeds are printed rounded for people.
    #[test]
    fn feeds_for_people() {
        assert_eq!(feed_text(9.8 * 25.4), "248.92");
        assert_eq!(feed_text(2000.0), "2000");
        assert_eq!(feed_text(78.7 * 2.54), "199.898");
        assert_eq!(feed_text(0.0004), "0");
        assert_eq!(feed_text(1500.5), "1500.5");
    }
}
