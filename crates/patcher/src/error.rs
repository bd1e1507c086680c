//! The patcher's errors (one small error type per kind of bad input, ripgrep's
//! `regex/src/error.rs` manner): a path that is not one ([`PathError`]) and options out of
//! range ([`OptionsError`]). A zone that cannot reach feed is not an error: it is an
//! outcome with a reason in the report ([`crate::Reason`]).

use std::fmt;

/// Bad input to the patcher.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PathError {
    /// Fewer than two points.
    #[error("a path needs at least 2 points, got {0}")]
    TooShort(usize),
    /// `s_mm` and `axes` lengths differ.
    #[error("s has {s} entries but axes has {axes}")]
    LengthMismatch {
        /// s length.
        s: usize,
        /// axes length.
        axes: usize,
    },
    /// s not strictly increasing at a point.
    #[error("s must increase strictly: point {index} has s = {value} mm after {previous} mm")]
    NotIncreasing {
        /// Point index.
        index: usize,
        /// s there.
        value: f64,
        /// s before.
        previous: f64,
    },
    /// A value is NaN or infinite.
    #[error("point {index}: {what} is not finite ({value})")]
    NotFinite {
        /// Point index.
        index: usize,
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// The analysis spline could not be built (should not happen for a validated path).
    #[error("analysis spline: {0}")]
    Spline(String),
    /// Options out of range, or that mean nothing together
    /// ([`crate::PatchOptions::validate`]).
    #[error("options: {0}")]
    Options(#[from] OptionsError),
    /// Feed not positive and finite.
    #[error("programmed feed must be positive, got {0} mm/min")]
    BadFeed(f64),
}

/// An option that [`crate::PatchOptions::validate`] (or
/// [`crate::AnalysisOptions::validate`]) refuses: the field, the rule it breaks and the
/// value it had.
///
/// Its `Display` names the field by its Rust identifier
/// (`max_deviation_deg must be a positive number of degrees, got 0`); a front end that
/// spells its options otherwise maps [`OptionsError::field`] to its own name and calls
/// [`OptionsError::message`] (`--max-deviation must be a positive number of degrees, got
/// 0`).
#[derive(Debug, Clone, PartialEq)]
pub struct OptionsError {
    /// The field refused.
    pub field: OptionField,
    /// The rule its value breaks.
    pub rule: OptionRule,
    /// The value as given (for the message: a number, `true`/`false`).
    pub value: String,
}

impl OptionsError {
    /// The message with the field spelled `name` (a flag, a keyword, a struct member):
    /// `{name} {rule}, got {value}`.
    pub fn message(&self, name: &str) -> String {
        format!("{name} {}, got {}", self.rule, self.value)
    }
}

impl fmt::Display for OptionsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message(self.field.name()))
    }
}

impl std::error::Error for OptionsError {}

/// A field of the patcher's options that has a rule ([`crate::PatchOptions`], and the
/// fields [`crate::AnalysisOptions`] shares with it). Match it exhaustively to map every
/// field to a front end's spelling: a new field is then a compile error, not a message
/// with a Rust name in it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OptionField {
    /// `cone_deg`: the singular cone, degrees.
    ConeDeg,
    /// `pole_reach_deg`: the pole reach, degrees.
    PoleReachDeg,
    /// `max_deviation_deg`: the cap on the orientation change, degrees.
    MaxDeviationDeg,
    /// `tcy_s`: the interpolation cycle time override, seconds.
    TcyS,
    /// `margin`: the safety margin on the rotary axes' limits, a fraction.
    Margin,
    /// `third_derivative_continuity`: G16's join option.
    ThirdDerivativeContinuity,
    /// `max_decimals`: most decimal places written.
    MaxDecimals,
    /// `max_patch_length_mm`: the longest patch, mm.
    MaxPatchLengthMm,
    /// `allow_c_offset`: G16's join option.
    AllowCOffset,
    /// `keep_centre.radius_mm`: the ball's radius, mm.
    KeepCentreRadiusMm,
    /// `keep_centre.unit_mm`: millimetres per unit of the file's X Y Z.
    KeepCentreUnitMm,
}

impl OptionField {
    /// Every field with a rule, in the order [`crate::PatchOptions::validate`] checks them.
    pub const ALL: [OptionField; 11] = [
        OptionField::ConeDeg,
        OptionField::PoleReachDeg,
        OptionField::MaxDeviationDeg,
        OptionField::TcyS,
        OptionField::Margin,
        OptionField::ThirdDerivativeContinuity,
        OptionField::MaxDecimals,
        OptionField::MaxPatchLengthMm,
        OptionField::AllowCOffset,
        OptionField::KeepCentreRadiusMm,
        OptionField::KeepCentreUnitMm,
    ];

    /// The field's Rust identifier (`max_deviation_deg`; `keep_centre.radius_mm` for a
    /// member of a member).
    pub fn name(self) -> &'static str {
        match self {
            OptionField::ConeDeg => "cone_deg",
            OptionField::PoleReachDeg => "pole_reach_deg",
            OptionField::MaxDeviationDeg => "max_deviation_deg",
            OptionField::TcyS => "tcy_s",
            OptionField::Margin => "margin",
            OptionField::ThirdDerivativeContinuity => "third_derivative_continuity",
            OptionField::MaxDecimals => "max_decimals",
            OptionField::MaxPatchLengthMm => "max_patch_length_mm",
            OptionField::AllowCOffset => "allow_c_offset",
            OptionField::KeepCentreRadiusMm => "keep_centre.radius_mm",
            OptionField::KeepCentreUnitMm => "keep_centre.unit_mm",
        }
    }
}

/// The rule an option breaks (its `Display` is the message's middle:
/// `must be a positive number of degrees`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OptionRule {
    /// A finite number above 0, in `unit`.
    Positive {
        /// The unit, for the message (`degrees`, `seconds`, `mm`).
        unit: &'static str,
    },
    /// A finite angle from 0 to `max`, degrees, both included.
    AngleUpTo {
        /// The largest angle allowed, degrees.
        max: f64,
    },
    /// A fraction in `[0, below)`.
    FractionBelow {
        /// The bound, excluded.
        below: f64,
    },
    /// A count of at most `max`.
    AtMost {
        /// The largest count allowed.
        max: usize,
    },
    /// Only with the C-only method ([`crate::PatchAxes::OnlyC`]): G16's join options mean
    /// nothing to the default method, which has no joins.
    NeedsOnlyC,
}

impl fmt::Display for OptionRule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OptionRule::Positive { unit } => write!(f, "must be a positive number of {unit}"),
            OptionRule::AngleUpTo { max } => write!(f, "must be an angle from 0 to {max} degrees"),
            OptionRule::FractionBelow { below } => write!(f, "must be a fraction in [0, {below})"),
            OptionRule::AtMost { max } => write!(f, "must be at most {max}"),
            OptionRule::NeedsOnlyC => write!(
                f,
                "is G16's join option: it needs the C-only method (the default method has no joins)"
            ),
        }
    }
}
