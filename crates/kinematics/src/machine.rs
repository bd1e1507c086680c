//! Machine model: the two rotary axes as a chain, senses, ranges, kinematic limits,
//! interpolation cycle time, and the bounds a machine's values must keep (named in
//! [`crate::tolerances`]; loading a machine — built-in, TOML file, LinuxCNC INI — is in `load.rs`).

use crate::rotary::{Layout, Rotaries};
pub use crate::tolerances::{LIMIT_MAX, LIMIT_MIN, MAX_MACHINE_FILE_BYTES, TCY_MS_RANGE};
use serde::{Deserialize, Serialize};

/// The five axes of a 5-axis machine, in the fixed order used by every per-axis array in
/// polepatch: X, Y, Z, then the two rotary axes by their role (whatever their letters, see
/// [`crate::rotary`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Axis {
    /// Linear X.
    X,
    /// Linear Y.
    Y,
    /// Linear Z.
    Z,
    /// The rotary axis next to the tool in the chain, which tilts the tool relative to the
    /// pole axis (A or B on a table-table A-C or B-C machine).
    Primary,
    /// The rotary axis next to the part in the chain: the pole axis, whose rotation cannot
    /// change a tool axis along it (C on a table-table machine, whatever its letter).
    C,
}

impl Axis {
    /// All axes in array order.
    pub const ALL: [Axis; 5] = [Axis::X, Axis::Y, Axis::Z, Axis::Primary, Axis::C];
    /// Index of this axis in per-axis arrays.
    pub fn index(self) -> usize {
        self as usize
    }
    /// Whether the axis is rotary (degrees) rather than linear (mm).
    pub fn is_rotary(self) -> bool {
        matches!(self, Axis::Primary | Axis::C)
    }
}

/// The tilting axis of the built-in form (the `[primary]` letter of a table-table file):
/// which coordinate axis it turns about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PrimaryAxis {
    /// A: tilts about X.
    A,
    /// B: tilts about Y.
    B,
}

/// Kinematic limits of one axis, in internal units: mm/s, mm/s², mm/s³ for a linear axis;
/// °/s, °/s², °/s³ for a rotary axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AxisLimits {
    /// Maximum velocity (mm/s or °/s).
    pub v: f64,
    /// Maximum acceleration (mm/s² or °/s²).
    pub a: f64,
    /// Maximum jerk (mm/s³ or °/s³).
    pub j: f64,
}

/// The letters a rotary axis may have: A B C, and the addresses that no dialect polepatch
/// reads gives another meaning (E U V W; D F G H I J K L M N O P Q R S T X Y Z are taken).
pub const ROTARY_LETTERS: &str = "ABCEUVW";

/// A 5-axis machine: three linear axes and two rotary axes in a chain. See the crate docs
/// for units and [`crate::rotary`] for the chain, its senses and its kinematics.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// Short name, e.g. `mikron-ucp710`.
    pub name: String,
    /// The two rotary axes: letters, what each turns, directions at zero, and the tool
    /// direction at zero.
    pub rotary: Rotaries,
    /// Sense of the primary (tilting) axis, +1 or −1 (ISO 841 when +1, see
    /// [`crate::rotary`]).
    pub primary_sense: f64,
    /// Sense of the C (pole) axis, +1 or −1.
    pub c_sense: f64,
    /// Allowed range of the primary axis, degrees (min, max).
    pub primary_range_deg: (f64, f64),
    /// Allowed range of the C (pole) axis, degrees (min, max); `None` = endless.
    pub c_range_deg: Option<(f64, f64)>,
    /// Interpolation cycle time Tcy, seconds (default 0.001).
    pub tcy_s: f64,
    /// Limits per axis in [`Axis`] order, internal units.
    pub limits: [AxisLimits; 5],
    /// Points on the two rotary axes (`[chain]`, or `point_mm` of each `[[rotary]]`;
    /// optional): needed to patch programs without TCPM and to analyse the linear axes in
    /// the machine frame.
    pub chain: Option<crate::chain::Chain>,
    /// How the controller switches TCPM beyond its dialect's codes (`[controller]`,
    /// optional).
    pub controller: Controller,
    /// What the loader assumed where the source did not say (a LinuxCNC INI without jerk
    /// limits, a HAL pin it could not follow, …), one sentence each, for the caller to
    /// print. For TOML files only a `tool_direction` pointing down (the spindle below the
    /// tip) is said.
    pub warnings: Vec<String>,
}

/// `[controller]`: the machine's own TCPM codes, as NC words (`"M428"`, `"G43.4"`,
/// `"TRAORI"`), added to the built-in codes of the program's dialect by the NC reader; or
/// `tcpm_always = true` for kinematics that are always TCP (X Y Z are always tool-tip
/// positions in the part frame).
#[derive(Debug, Clone, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Controller {
    /// Codes that switch TCPM on. Default none.
    #[serde(default)]
    pub tcpm_on: Vec<String>,
    /// Codes that end it. Default none.
    #[serde(default)]
    pub tcpm_off: Vec<String>,
    /// Always TCP. Default false.
    #[serde(default)]
    pub tcpm_always: bool,
    /// Which point of the tool the programs' X Y Z state under TCPM, where the shop set
    /// the tool lengths so: `"tip"` or `"centre"` (of a ball). Default: each TCPM code's
    /// own (M128: centre; the others: tip).
    #[serde(default)]
    pub tool_point: Option<String>,
    /// Letters of auxiliary axes the programs carry that are not the machine's rotary axes
    /// (an extruder on `A` of a B-C printer, a quill): their words are carried through like
    /// `E`, never read as a rotary axis. Default none.
    #[serde(default)]
    pub auxiliary_axes: Vec<String>,
}

/// Errors of machine loading.
#[derive(Debug, thiserror::Error)]
pub enum MachineError {
    /// Name is neither a built-in nor an existing file.
    #[error("unknown machine '{name}': not a file, and not a built-in (built-ins: {builtins})")]
    Unknown {
        /// What the user asked for.
        name: String,
        /// Comma-separated built-in names.
        builtins: String,
    },
    /// File could not be read.
    #[error("cannot read machine file {path}: {cause}")]
    Io {
        /// Path.
        path: String,
        /// Cause (in the message, not a `source()`: an error chain would print it twice).
        cause: std::io::Error,
    },
    /// TOML is malformed or a field is invalid.
    #[error("machine file {path}: {message}")]
    Invalid {
        /// Path or built-in name.
        path: String,
        /// What is wrong, with the field name.
        message: String,
    },
}

impl Machine {
    /// Letter of the primary (tilting) axis in NC words (`'A'` or `'B'` on the built-ins).
    pub fn primary_letter(&self) -> char {
        self.rotary.primary.letter
    }
    /// Letter of the C (pole) axis in NC words (`'C'` on the built-ins; `'B'` on an A-B
    /// trunnion whose platter is B).
    pub fn c_letter(&self) -> char {
        self.rotary.c.letter
    }
    /// The NC letter of an axis: X, Y, Z, or the file's own rotary letters.
    pub fn letter(&self, axis: Axis) -> char {
        match axis {
            Axis::X => 'X',
            Axis::Y => 'Y',
            Axis::Z => 'Z',
            Axis::Primary => self.primary_letter(),
            Axis::C => self.c_letter(),
        }
    }
    /// The slot of a rotary letter (`Axis::Primary` or `Axis::C`), or `None` when the
    /// machine has no rotary axis of that letter (case-insensitive).
    pub fn rotary_axis_of(&self, letter: char) -> Option<Axis> {
        let l = letter.to_ascii_uppercase();
        if l == self.primary_letter() {
            Some(Axis::Primary)
        } else if l == self.c_letter() {
            Some(Axis::C)
        } else {
            None
        }
    }
    /// Limits of one axis.
    pub fn limit(&self, axis: Axis) -> &AxisLimits {
        &self.limits[axis.index()]
    }
    /// Table-table, head-table or head-head.
    pub fn layout(&self) -> Layout {
        self.rotary.layout()
    }
    /// The pole: the tool axis (unit, part frame) along the C (pole) axis line where the
    /// machine meets it ([`Machine::pole_p_deg`]), where turning C does not change the
    /// tool axis. `[0, 0, 1]` on the built-ins; the reverse of the pole axis' direction on
    /// a pair whose pole in range has the tool against it; the pole axis' direction on a
    /// pair that reaches no pole.
    pub fn pole_direction(&self) -> [f64; 3] {
        let a = self.rotary.c.direction;
        if self.standard_form().is_some() {
            return [0.0, 0.0, 1.0];
        }
        match self.pole() {
            Some(p) if p.opposite => [-a[0], -a[1], -a[2]],
            _ => a,
        }
    }
}

/// The whole file at `path`, as text, reading at most [`MAX_MACHINE_FILE_BYTES`] + 1
/// bytes: more is an error, as is text that is not UTF-8.
pub(crate) fn read_bounded(path: &std::path::Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(MAX_MACHINE_FILE_BYTES + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_MACHINE_FILE_BYTES {
        return Err(std::io::Error::other(format!(
            "longer than {MAX_MACHINE_FILE_BYTES} bytes (a machine description is a short TOML \
             file); is it the right file?"
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text (byte {} is not valid); a machine file is TOML",
                e.utf8_error().valid_up_to() + 1
            ),
        )
    })
}

/// A number for a message: the shortest form that reads back as the value (`1e-300`, not
/// three hundred digits), without a trailing `.0`.
pub(crate) fn num(v: f64) -> String {
    let text = format!("{v:?}");
    text.strip_suffix(".0").map_or(text.clone(), str::to_string)
}

/// `tcy_ms` within [`TCY_MS_RANGE`]; `name` is the field or option named in the error.
pub fn check_tcy_ms(name: &str, tcy_ms: f64) -> Result<f64, String> {
    let (lo, hi) = TCY_MS_RANGE;
    if tcy_ms.is_finite() && (lo..=hi).contains(&tcy_ms) {
        Ok(tcy_ms)
    } else {
        Err(format!(
            "{name} must be a cycle time from {lo} to {hi} ms, got {}",
            num(tcy_ms)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_order_and_kinds() {
        for (k, axis) in Axis::ALL.iter().enumerate() {
            assert_eq!(axis.index(), k);
        }
        assert!(!Axis::Z.is_rotary());
        assert!(Axis::Primary.is_rotary() && Axis::C.is_rotary());
    }
}
