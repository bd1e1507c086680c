//! Machine model: axes, senses, ranges, kinematic limits, interpolation cycle time.

use serde::{Deserialize, Serialize};

/// The five axes of a table-table machine, in the fixed order used by every per-axis
/// array in polepatch: X, Y, Z, primary rotary (A or B), C.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Axis {
    /// Linear X.
    X,
    /// Linear Y.
    Y,
    /// Linear Z.
    Z,
    /// Primary rotary axis (A about X or B about Y), the tilting one.
    Primary,
    /// Secondary rotary axis C about Z (the table), riding on the primary.
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

/// Which physical rotation the primary rotary axis performs.
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

/// A table-table 5-axis machine. See the crate docs for units and senses.
#[derive(Debug, Clone, PartialEq)]
pub struct Machine {
    /// Short name, e.g. `mikron-ucp710`.
    pub name: String,
    /// Primary rotary axis kind (A about X or B about Y).
    pub primary: PrimaryAxis,
    /// Sense of the primary rotation, +1 or −1 (see crate docs).
    pub primary_sense: f64,
    /// Sense of the C rotation, +1 or −1 (see crate docs).
    pub c_sense: f64,
    /// Allowed range of the primary axis, degrees (min, max).
    pub primary_range_deg: (f64, f64),
    /// Allowed range of C, degrees (min, max); `None` = endless rotary axis.
    pub c_range_deg: Option<(f64, f64)>,
    /// Interpolation cycle time Tcy, seconds (default 0.001).
    pub tcy_s: f64,
    /// Limits per axis in [`Axis`] order, internal units.
    pub limits: [AxisLimits; 5],
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
    #[error("cannot read machine file {path}: {source}")]
    Io {
        /// Path.
        path: String,
        /// Cause.
        source: std::io::Error,
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
    /// Names of the built-in machines.
    pub fn builtin_names() -> &'static [&'static str] {
        &["mikron-ucp710", "mikron-hsm600"]
    }
    /// A built-in machine by name.
    pub fn builtin(name: &str) -> Option<Machine> {
        let _ = name;
        todo!()
    }
    /// Parse a machine from TOML text; `origin` names the source in errors.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Machine, MachineError> {
        let _ = (text, origin);
        todo!()
    }
    /// A built-in name or a path to a TOML file.
    pub fn load(name_or_path: &str) -> Result<Machine, MachineError> {
        let _ = name_or_path;
        todo!()
    }
    /// Letter of the primary axis in NC words (`'A'` or `'B'`).
    pub fn primary_letter(&self) -> char {
        match self.primary {
            PrimaryAxis::A => 'A',
            PrimaryAxis::B => 'B',
        }
    }
    /// Limits of one axis.
    pub fn limit(&self, axis: Axis) -> &AxisLimits {
        &self.limits[axis.index()]
    }
}
