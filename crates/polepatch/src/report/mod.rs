//! Report documents (serde): what `analyze` prints, as data.
//!
//! Every report type of the library in one place: [`AnalyzeReport`] (what `polepatch analyze`
//! reports), [`FileReport`] (`polepatch patch --report`), [`SimulateReport`] (`polepatch simulate`),
//! and the names they print axes, limits, feeds and feed modes with.
//!
//! # Typed fields
//! What a zone or a run is and how it ended are enums, compared as enums
//! (`z.outcome == Outcome::Reached`): a zone row's [`ZoneKind`], [`Outcome`],
//! [`ZoneReason`], [`EndFreedom`], [`Method`], [`FeedMode`](polepatch_nc::FeedMode),
//! [`ZoneTool`] and [`ToolPoint`](crate::tool::ToolPoint), a figure's [`LimitKind`], a
//! simulated run's [`SimFrame`]. The JSON writes every such enum in one spelling,
//! snake_case (`reached`, `c_swing`, `g16_patch`, `tool_limited`, `no_tcpm`, `solved`; issue
//! 40), except the symbols a machinist reads as such: `G94` for a feed mode
//! ([`feed_mode_name`]), `V`, `A`, `J`, `F` for a limit ([`limit_name`]), axis letters. The
//! CSV and the printed summaries write the names people read (`A-flip`, `g16-patch`, their
//! `Display` or `name()`); an optional one (a run not patched has no end pose or tool
//! point) is written `-`.

mod analyze;
mod patch;
mod simulate;

pub use analyze::{AnalyzeReport, MachineFrameFigures, RunFigures, RunReport, ZoneSummary};
pub use patch::{
    Branch, EndFreedom, FiguresRow, FileReport, UntouchedReason, UntouchedRun, ZoneReason, ZoneRow,
    ZoneTool, feed_mode_name,
};
pub use polepatch_kinematics::LimitKind;
pub use polepatch_patcher::{Method, Outcome, ZoneKind};
pub use simulate::{
    RunTimes, SimFrame, SimRun, SimTotals, SimulateReport, SimulatedTimes, compare,
};

/// A line carried through without analysis, and why ([`FileReport::not_analysed`]).
pub use crate::notes::{NotAnalysed, SkipReason};

use polepatch_kinematics::Axis;
use polepatch_nc::RotaryLetters;
use serde::Serializer;
use std::collections::BTreeMap;
use std::fmt::Display;

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

/// Serialise a typed field by its report name, its `Display` (module docs).
fn by_name<T: Display, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(value)
}

/// Serialise an optional typed field by its report name, `-` when there is none.
fn by_name_or_dash<T: Display, S: Serializer>(value: &Option<T>, s: S) -> Result<S::Ok, S::Error> {
    match value {
        Some(v) => s.collect_str(v),
        None => s.serialize_str("-"),
    }
}

/// Serialise a limit by its short name ([`limit_name`]).
fn limit_by_name<S: Serializer>(kind: &LimitKind, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(limit_name(*kind))
}

/// Serialise the limits per axis letter by their short names ([`limit_name`]).
fn limits_by_name<S: Serializer>(
    limits: &BTreeMap<String, LimitKind>,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.collect_map(limits.iter().map(|(axis, kind)| (axis, limit_name(*kind))))
}

/// Serialise a feed mode by its G code ([`feed_mode_name`]).
fn feed_mode_by_name<S: Serializer>(
    mode: &polepatch_nc::FeedMode,
    s: S,
) -> Result<S::Ok, S::Error> {
    s.serialize_str(feed_mode_name(*mode))
}

/// A feed for people, mm/min: 3 decimals (below 1, enough to keep its first significant
/// digits: `0.0001`), trailing zeros dropped (`248.92`, not `248.92000000000002`, the inch
/// feed F9.8 × 25.4 as computed).
pub fn feed_text(feed_mm_min: f64) -> String {
    // Three decimals, and below 1 as many more as keep its first significant digits (F0.0001
    // is not "0").
    let a = feed_mm_min.abs();
    let decimals = if a > 0.0 && a < 1.0 {
        (3.0 - a.log10().floor()).min(15.0) as usize
    } else {
        3
    };
    let s = format!("{feed_mm_min:.decimals$}");
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
        // Issue 43: a feed below 1 keeps its significant digits.
        assert_eq!(feed_text(0.0001), "0.0001");
        assert_eq!(feed_text(0.123456), "0.1235");
        assert_eq!(feed_text(0.0), "0");
        assert_eq!(feed_text(78.7 * 2.54), "199.898");
        assert_eq!(feed_text(0.0004), "0.0004");
        assert_eq!(feed_text(1500.5), "1500.5");
    }
}
