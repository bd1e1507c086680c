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
    /// Where the rotary axes sit in the machine frame (`[chain]`, optional): needed to
    /// patch programs without TCPM and to analyse the linear axes in the machine frame.
    pub chain: Option<crate::chain::Chain>,
    /// How the controller switches TCPM beyond its dialect's codes (`[controller]`,
    /// optional).
    pub controller: Controller,
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
    /// Names of the built-in machines.
    pub fn builtin_names() -> &'static [&'static str] {
        &["mikron-ucp710", "mikron-hsm600"]
    }
    /// A built-in machine by name.
    pub fn builtin(name: &str) -> Option<Machine> {
        let text = builtin_toml(name)?;
        // The built-in files are checked by the tests; a failure here is a build defect.
        Some(Machine::from_toml_str(text, name).expect("built-in machine file is valid"))
    }
    /// Parse a machine from TOML text; `origin` names the source in errors.
    ///
    /// The format (every field required unless marked optional; unknown fields are errors):
    ///
    /// ```toml
    /// name = "mikron-ucp710"
    /// description = "free text"        # optional, not kept
    /// tcy_ms = 1.0                     # optional, interpolation cycle time, default 1 ms
    /// [x]                              # also [y] and [z]
    /// v_m_min = 30.0                   # max velocity, m/min
    /// a_m_s2 = 2.5                     # max acceleration, m/s²
    /// j_m_s3 = 5.0                     # max jerk, m/s³
    /// [primary]
    /// letter = "A"                     # "A" tilts about X, "B" about Y
    /// sense = 1                        # +1 or -1, sp in o = Rz(sc·C)·Rp(sp·P)·ẑ
    /// range_deg = [-100.0, 120.0]      # travel, degrees
    /// v_rpm = 15.0                     # max velocity, rpm
    /// a_rev_s2 = 0.83                  # max acceleration, rev/s²
    /// j_rev_s3 = 5.0                   # max jerk, rev/s³
    /// [c]
    /// sense = 1                        # +1 or -1, sc
    /// range_deg = [-360.0, 360.0]      # optional; omitted = endless
    /// v_rpm = 20.0
    /// a_rev_s2 = 0.83
    /// j_rev_s3 = 50.0
    /// [chain]                          # optional: where the rotary axes sit (mm, machine frame)
    /// primary_axis_point_mm = [0.0, 0.0, -150.0]   # a point on the primary axis line
    /// c_axis_point_mm = [0.0, 0.0, -100.0]         # a point on the C axis at primary = 0
    /// [controller]                     # optional: the machine's own TCPM codes
    /// tcpm_on = ["M428"]               # added to the dialect's (M128, TRAORI, G43.4, …)
    /// tcpm_off = ["M429", "M430"]
    /// tcpm_always = false              # true: kinematics always TCP
    /// tool_point = "tip"               # optional: X Y Z under TCPM are the tool tip or
    ///                                  # the ball's "centre" (default: the TCPM code's)
    /// ```
    ///
    /// Every limit must lie within [`LIMIT_MIN`, `LIMIT_MAX`] = 0.001 to 10⁶ in the file's
    /// units, `tcy_ms` within [`TCY_MS_RANGE`] = 0.1 to 100 ms, a `range_deg` must have
    /// exactly two values and a chain point exactly three (an error names the field).
    ///
    /// Limits are converted once to internal units: m/min → mm/s ×1000/60, m/s² → mm/s²
    /// ×1000, m/s³ → mm/s³ ×1000, rpm → °/s ×6, rev/s² → °/s² ×360, rev/s³ → °/s³ ×360.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Machine, MachineError> {
        let invalid = |message: String| MachineError::Invalid {
            path: origin.to_string(),
            message,
        };
        let file: MachineFile = toml::from_str(text).map_err(|e| invalid(e.to_string()))?;
        file.into_machine().map_err(invalid)
    }
    /// A built-in name or a path to a TOML file.
    ///
    /// Built-in names win over files of the same name in the working directory. At most
    /// [`MAX_MACHINE_FILE_BYTES`] are read (a device such as `/dev/zero` or a FIFO is read
    /// up to that bound, never without limit); a longer file is an error.
    pub fn load(name_or_path: &str) -> Result<Machine, MachineError> {
        if let Some(m) = Machine::builtin(name_or_path) {
            return Ok(m);
        }
        let path = std::path::Path::new(name_or_path);
        if !path.exists() {
            return Err(MachineError::Unknown {
                name: name_or_path.to_string(),
                builtins: Machine::builtin_names().join(", "),
            });
        }
        Machine::from_file(path)
    }
    /// A machine file at `path` (never a built-in name), read as [`Machine::load`] reads
    /// it: at most [`MAX_MACHINE_FILE_BYTES`].
    pub fn from_file(path: &std::path::Path) -> Result<Machine, MachineError> {
        let name = path.display().to_string();
        let text = read_bounded(path).map_err(|cause| MachineError::Io {
            path: name.clone(),
            cause,
        })?;
        Machine::from_toml_str(&text, &name)
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

/// TOML text of a built-in machine.
fn builtin_toml(name: &str) -> Option<&'static str> {
    match name {
        "mikron-ucp710" => Some(include_str!("../machines/mikron-ucp710.toml")),
        "mikron-hsm600" => Some(include_str!("../machines/mikron-hsm600.toml")),
        _ => None,
    }
}

/// Largest machine file read, bytes (1 MiB; a machine description is under 2 KB). A longer
/// file, or a device that never ends (`/dev/zero`), is refused rather than read whole.
pub const MAX_MACHINE_FILE_BYTES: u64 = 1 << 20;

/// Smallest kinematic limit accepted, in the file's units (m/min, m/s², m/s³, rpm, rev/s²,
/// rev/s³). The slowest axis of a real machine is orders of magnitude above it; a value
/// below is a unit mistake, and would make every time estimate astronomically long.
pub const LIMIT_MIN: f64 = 1e-3;
/// Largest kinematic limit accepted, in the file's units (the fastest real axes are below
/// 10⁴ in every one of them).
pub const LIMIT_MAX: f64 = 1e6;
/// Range of the interpolation cycle time `tcy_ms` accepted, milliseconds: controllers
/// interpolate every 0.1 ms (the fastest) to a few ms; 100 ms is a generous bound, and the
/// analysis samples every F·Tcy, so a Tcy far below 0.1 ms only multiplies the work.
pub const TCY_MS_RANGE: (f64, f64) = (0.1, 100.0);

/// The whole file at `path`, as text, reading at most [`MAX_MACHINE_FILE_BYTES`] + 1
/// bytes: more is an error, as is text that is not UTF-8.
fn read_bounded(path: &std::path::Path) -> std::io::Result<String> {
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
fn num(v: f64) -> String {
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

/// mm/s per m/min.
const MM_S_PER_M_MIN: f64 = 1000.0 / 60.0;
/// mm per m (for m/s² and m/s³).
const MM_PER_M: f64 = 1000.0;
/// °/s per rpm.
const DEG_S_PER_RPM: f64 = 6.0;
/// Degrees per revolution (for rev/s² and rev/s³).
const DEG_PER_REV: f64 = 360.0;

/// The TOML file as written (units of the machine tables).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineFile {
    name: String,
    #[allow(dead_code)]
    description: Option<String>,
    tcy_ms: Option<f64>,
    x: LinearFile,
    y: LinearFile,
    z: LinearFile,
    primary: PrimaryFile,
    c: CFile,
    chain: Option<ChainFile>,
    #[serde(default)]
    controller: Controller,
}

/// `[chain]` as written: arrays of any length, checked for three values each (a fixed-size
/// array would be filled from the first three values and the rest ignored).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ChainFile {
    primary_axis_point_mm: Vec<f64>,
    c_axis_point_mm: Vec<f64>,
}

impl ChainFile {
    fn into_chain(self) -> Result<crate::chain::Chain, String> {
        let chain = crate::chain::Chain {
            primary_axis_point_mm: exactly(
                "chain.primary_axis_point_mm",
                &self.primary_axis_point_mm,
            )?,
            c_axis_point_mm: exactly("chain.c_axis_point_mm", &self.c_axis_point_mm)?,
        };
        chain.validate()?;
        Ok(chain)
    }
}

/// The `N` values of an array field, or an error naming it when it has another length.
fn exactly<const N: usize>(field: &str, values: &[f64]) -> Result<[f64; N], String> {
    values.try_into().map_err(|_| {
        format!(
            "{field} must have {N} values, got {}: {values:?}",
            values.len()
        )
    })
}

/// `[x]`, `[y]`, `[z]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct LinearFile {
    v_m_min: f64,
    a_m_s2: f64,
    j_m_s3: f64,
}

/// `[primary]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PrimaryFile {
    letter: PrimaryAxis,
    sense: f64,
    range_deg: Vec<f64>,
    v_rpm: f64,
    a_rev_s2: f64,
    j_rev_s3: f64,
}

/// `[c]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CFile {
    sense: f64,
    range_deg: Option<Vec<f64>>,
    v_rpm: f64,
    a_rev_s2: f64,
    j_rev_s3: f64,
}

/// A limit must be positive, finite and within [`LIMIT_MIN`, `LIMIT_MAX`] (file units);
/// `field` is its dotted TOML name.
fn positive(field: &str, value: f64) -> Result<f64, String> {
    if !(value.is_finite() && value > 0.0) {
        return Err(format!(
            "{field} must be positive and finite, got {}",
            num(value)
        ));
    }
    if !(LIMIT_MIN..=LIMIT_MAX).contains(&value) {
        return Err(format!(
            "{field} = {} is outside the accepted range {} to {} (in the file's units; a \
             unit mistake?)",
            num(value),
            num(LIMIT_MIN),
            num(LIMIT_MAX)
        ));
    }
    Ok(value)
}

/// A sense must be exactly +1 or −1.
fn sense(field: &str, value: f64) -> Result<f64, String> {
    if value == 1.0 || value == -1.0 {
        Ok(value)
    } else {
        Err(format!("{field} must be +1 or -1, got {}", num(value)))
    }
}

/// A range must be two finite values with min < max.
fn range(field: &str, r: &[f64]) -> Result<(f64, f64), String> {
    let [lo, hi] = exactly(field, r)?;
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(format!(
            "{field} must be finite, got [{}, {}]",
            num(lo),
            num(hi)
        ));
    }
    if lo >= hi {
        return Err(format!(
            "{field}: min must be below max, got [{}, {}]",
            num(lo),
            num(hi)
        ));
    }
    Ok((lo, hi))
}

impl LinearFile {
    fn limits(&self, axis: &str) -> Result<AxisLimits, String> {
        Ok(AxisLimits {
            v: positive(&format!("{axis}.v_m_min"), self.v_m_min)? * MM_S_PER_M_MIN,
            a: positive(&format!("{axis}.a_m_s2"), self.a_m_s2)? * MM_PER_M,
            j: positive(&format!("{axis}.j_m_s3"), self.j_m_s3)? * MM_PER_M,
        })
    }
}

/// Rotary limits from rpm, rev/s², rev/s³.
fn rotary_limits(
    axis: &str,
    v_rpm: f64,
    a_rev_s2: f64,
    j_rev_s3: f64,
) -> Result<AxisLimits, String> {
    Ok(AxisLimits {
        v: positive(&format!("{axis}.v_rpm"), v_rpm)? * DEG_S_PER_RPM,
        a: positive(&format!("{axis}.a_rev_s2"), a_rev_s2)? * DEG_PER_REV,
        j: positive(&format!("{axis}.j_rev_s3"), j_rev_s3)? * DEG_PER_REV,
    })
}

impl MachineFile {
    /// Validate and convert to internal units; the error names the field.
    fn into_machine(self) -> Result<Machine, String> {
        let tcy_ms = check_tcy_ms("tcy_ms", self.tcy_ms.unwrap_or(1.0))?;
        let p = &self.primary;
        let c = &self.c;
        Ok(Machine {
            name: self.name,
            primary: p.letter,
            primary_sense: sense("primary.sense", p.sense)?,
            c_sense: sense("c.sense", c.sense)?,
            primary_range_deg: range("primary.range_deg", &p.range_deg)?,
            c_range_deg: c
                .range_deg
                .as_deref()
                .map(|r| range("c.range_deg", r))
                .transpose()?,
            tcy_s: tcy_ms / 1000.0,
            limits: [
                self.x.limits("x")?,
                self.y.limits("y")?,
                self.z.limits("z")?,
                rotary_limits("primary", p.v_rpm, p.a_rev_s2, p.j_rev_s3)?,
                rotary_limits("c", c.v_rpm, c.a_rev_s2, c.j_rev_s3)?,
            ],
            chain: self.chain.map(ChainFile::into_chain).transpose()?,
            controller: {
                for (field, codes) in [
                    ("controller.tcpm_on", &self.controller.tcpm_on),
                    ("controller.tcpm_off", &self.controller.tcpm_off),
                ] {
                    if let Some(bad) = codes.iter().find(|c| {
                        c.trim().is_empty()
                            || !c
                                .trim()
                                .bytes()
                                .all(|b| b.is_ascii_alphanumeric() || b == b'.' || b == b'_')
                    }) {
                        return Err(format!(
                            "{field}: '{bad}' is not an NC code (write a G or M code such as \
                             \"M428\" or \"G43.4\", or a word such as \"TRAORI\")"
                        ));
                    }
                }
                if let Some(p) = &self.controller.tool_point
                    && !matches!(
                        p.trim().to_ascii_lowercase().as_str(),
                        "tip" | "centre" | "center"
                    )
                {
                    return Err(format!(
                        "controller.tool_point: '{p}' is not \"tip\" or \"centre\""
                    ));
                }
                self.controller
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative closeness for converted figures (the conversions multiply by inexact
    /// constants such as 1000/60).
    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * b.abs().max(1.0)
    }

    fn assert_limits(m: &Machine, axis: Axis, v: f64, a: f64, j: f64) {
        let l = m.limit(axis);
        assert!(close(l.v, v), "{} {axis:?} v = {}, want {v}", m.name, l.v);
        assert!(close(l.a, a), "{} {axis:?} a = {}, want {a}", m.name, l.a);
        assert!(close(l.j, j), "{} {axis:?} j = {}, want {j}", m.name, l.j);
    }

    #[test]
    fn ucp710_has_the_figures_of_g16_table_2_in_internal_units() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        assert_eq!(m.name, "mikron-ucp710");
        assert_eq!(m.primary, PrimaryAxis::A);
        assert_eq!(m.primary_letter(), 'A');
        assert_eq!((m.primary_sense, m.c_sense), (1.0, 1.0));
        assert_eq!(m.primary_range_deg, (-100.0, 120.0));
        assert_eq!(m.c_range_deg, None);
        assert_eq!(m.tcy_s, 0.001);
        // 30 m/min = 500 mm/s.
        assert_limits(&m, Axis::X, 500.0, 2500.0, 5000.0);
        assert_limits(&m, Axis::Y, 500.0, 3000.0, 5000.0);
        assert_limits(&m, Axis::Z, 500.0, 2100.0, 50000.0);
        // A: 15 rpm = 90 °/s, 0.83 rev/s² = 298.8 °/s², 5 rev/s³ = 1800 °/s³.
        assert_limits(&m, Axis::Primary, 90.0, 298.8, 1800.0);
        // C: 20 rpm = 120 °/s, 0.83 rev/s² = 298.8 °/s², 50 rev/s³ = 18000 °/s³.
        assert_limits(&m, Axis::C, 120.0, 298.8, 18000.0);
    }

    #[test]
    fn hsm600_has_the_figures_of_g16_table_3_in_internal_units() {
        let m = Machine::builtin("mikron-hsm600").unwrap();
        assert_eq!(m.name, "mikron-hsm600");
        assert_eq!(m.primary, PrimaryAxis::B);
        assert_eq!(m.primary_letter(), 'B');
        assert_eq!((m.primary_sense, m.c_sense), (1.0, 1.0));
        assert_eq!(m.primary_range_deg, (-120.0, 120.0));
        assert_eq!(m.c_range_deg, None);
        assert_eq!(m.tcy_s, 0.001);
        // 100 m/min = 1666.67 mm/s.
        let v = 100_000.0 / 60.0;
        assert_limits(&m, Axis::X, v, 10_000.0, 100_000.0);
        assert_limits(&m, Axis::Y, v, 9_000.0, 100_000.0);
        assert_limits(&m, Axis::Z, v, 10_000.0, 100_000.0);
        // B: 200 rpm = 1200 °/s, 1.7 rev/s² = 612 °/s², 50 rev/s³ = 18000 °/s³.
        assert_limits(&m, Axis::Primary, 1200.0, 612.0, 18_000.0);
        // C: 360 rpm = 2160 °/s, 7 rev/s² = 2520 °/s², 100 rev/s³ = 36000 °/s³.
        assert_limits(&m, Axis::C, 2160.0, 2520.0, 36_000.0);
    }

    #[test]
    fn every_builtin_name_loads_and_names_itself() {
        for name in Machine::builtin_names() {
            let m = Machine::load(name).unwrap();
            assert_eq!(&m.name, name);
        }
        assert!(Machine::builtin("mikron-ucp711").is_none());
    }

    #[test]
    fn axis_order_and_kinds() {
        for (k, axis) in Axis::ALL.iter().enumerate() {
            assert_eq!(axis.index(), k);
        }
        assert!(!Axis::Z.is_rotary());
        assert!(Axis::Primary.is_rotary() && Axis::C.is_rotary());
    }

    /// A small valid machine; tests edit one line of it.
    const GOOD: &str = r#"
name = "test-bc"
tcy_ms = 2.0
[x]
v_m_min = 60
a_m_s2 = 1
j_m_s3 = 10
[y]
v_m_min = 60
a_m_s2 = 1
j_m_s3 = 10
[z]
v_m_min = 60
a_m_s2 = 1
j_m_s3 = 10
[primary]
letter = "B"
sense = -1
range_deg = [-30, 110]
v_rpm = 10
a_rev_s2 = 1
j_rev_s3 = 1
[c]
sense = -1
range_deg = [-360.0, 360.0]
v_rpm = 10
a_rev_s2 = 1
j_rev_s3 = 1
"#;

    fn invalid_message(text: &str) -> String {
        match Machine::from_toml_str(text, "bad.toml") {
            Err(MachineError::Invalid { path, message }) => {
                assert_eq!(path, "bad.toml");
                message
            }
            other => panic!("expected Invalid, got {other:?}"),
        }
    }

    #[test]
    fn user_machine_with_integers_negative_senses_and_c_range() {
        let m = Machine::from_toml_str(GOOD, "good.toml").unwrap();
        assert_eq!(m.name, "test-bc");
        assert_eq!(m.primary, PrimaryAxis::B);
        assert_eq!((m.primary_sense, m.c_sense), (-1.0, -1.0));
        assert_eq!(m.primary_range_deg, (-30.0, 110.0));
        assert_eq!(m.c_range_deg, Some((-360.0, 360.0)));
        assert_eq!(m.tcy_s, 0.002);
        assert_limits(&m, Axis::X, 1000.0, 1000.0, 10_000.0);
        assert_limits(&m, Axis::C, 60.0, 360.0, 360.0);
    }

    #[test]
    fn omitted_tcy_is_one_millisecond() {
        let text = GOOD.replace("tcy_ms = 2.0\n", "");
        assert_eq!(Machine::from_toml_str(&text, "t").unwrap().tcy_s, 0.001);
    }

    #[test]
    fn invalid_fields_are_named_in_the_message() {
        // (text of GOOD, its replacement, what the message must contain); first match only.
        let edits: &[(&str, &str, &str)] = &[
            (
                "v_rpm = 10",
                "v_rpm = -10",
                "primary.v_rpm must be positive and finite, got -10",
            ),
            (
                "360.0]\nv_rpm = 10",
                "360.0]\nv_rpm = 0",
                "c.v_rpm must be positive and finite, got 0",
            ),
            (
                "[x]\nv_m_min = 60",
                "[x]\nv_m_min = 0",
                "x.v_m_min must be positive and finite, got 0",
            ),
            (
                "[y]\nv_m_min = 60\na_m_s2 = 1",
                "[y]\nv_m_min = 60\na_m_s2 = nan",
                "y.a_m_s2 must be positive and finite, got NaN",
            ),
            (
                "[z]\nv_m_min = 60\na_m_s2 = 1\nj_m_s3 = 10",
                "[z]\nv_m_min = 60\na_m_s2 = 1\nj_m_s3 = inf",
                "z.j_m_s3 must be positive and finite, got inf",
            ),
            (
                "sense = -1\nrange_deg = [-30",
                "sense = 2\nrange_deg = [-30",
                "primary.sense must be +1 or -1, got 2",
            ),
            (
                "sense = -1\nrange_deg = [-360.0",
                "sense = 0\nrange_deg = [-360.0",
                "c.sense must be +1 or -1, got 0",
            ),
            (
                "range_deg = [-30, 110]",
                "range_deg = [110, -30]",
                "primary.range_deg: min must be below max, got [110, -30]",
            ),
            (
                "range_deg = [-360.0, 360.0]",
                "range_deg = [5.0, 5.0]",
                "c.range_deg: min must be below max, got [5, 5]",
            ),
            (
                "tcy_ms = 2.0",
                "tcy_ms = 0.0",
                "tcy_ms must be a cycle time from 0.1 to 100 ms, got 0",
            ),
            (
                "tcy_ms = 2.0",
                "tcy_ms = -1.0",
                "tcy_ms must be a cycle time from 0.1 to 100 ms, got -1",
            ),
            (
                "tcy_ms = 2.0",
                "tcy_ms = 1e-300",
                "tcy_ms must be a cycle time from 0.1 to 100 ms, got 1e-300",
            ),
            (
                "tcy_ms = 2.0",
                "tcy_ms = 1000",
                "tcy_ms must be a cycle time from 0.1 to 100 ms, got 1000",
            ),
            // Issue 19: v_rpm = 1e-300 made a 300-digit time estimate.
            (
                "v_rpm = 10",
                "v_rpm = 1e-300",
                "primary.v_rpm = 1e-300 is outside the accepted range 0.001 to 1000000",
            ),
            (
                "[x]\nv_m_min = 60\na_m_s2 = 1",
                "[x]\nv_m_min = 60\na_m_s2 = 1e300",
                "x.a_m_s2 = 1e300 is outside the accepted range",
            ),
            (
                "360.0]\nv_rpm = 10\na_rev_s2 = 1\nj_rev_s3 = 1",
                "360.0]\nv_rpm = 10\na_rev_s2 = 1\nj_rev_s3 = 0.0001",
                "c.j_rev_s3 = 0.0001 is outside the accepted range",
            ),
            // Issue 19: a third value was silently dropped.
            (
                "range_deg = [-30, 110]",
                "range_deg = [-30, 110, 5]",
                "primary.range_deg must have 2 values, got 3: [-30.0, 110.0, 5.0]",
            ),
            (
                "range_deg = [-30, 110]",
                "range_deg = [-30]",
                "primary.range_deg must have 2 values, got 1",
            ),
            (
                "range_deg = [-360.0, 360.0]",
                "range_deg = [-360.0, 360.0, 0.0]",
                "c.range_deg must have 2 values, got 3",
            ),
            (
                "j_rev_s3 = 1\n[c]",
                "j_rev_s3 = 1\nc_rpm = 3\n[c]",
                "unknown field `c_rpm`",
            ),
            ("tcy_ms = 2.0", "tcy = 2.0", "unknown field `tcy`"),
            ("letter = \"B\"", "letter = \"D\"", "unknown variant `D`"),
            ("name = \"test-bc\"\n", "", "missing field `name`"),
            ("[x]\nv_m_min = 60", "[x]\nv_m_min = \"fast\"", "v_m_min"),
        ];
        for (from, to, want) in edits {
            assert!(GOOD.contains(from), "test edit {from:?} does not apply");
            let msg = invalid_message(&GOOD.replacen(from, to, 1));
            assert!(
                msg.contains(want),
                "edit {to:?}: message {msg:?} lacks {want:?}"
            );
        }
    }

    #[test]
    fn limits_at_the_bounds_are_accepted() {
        let text = GOOD
            .replace("v_rpm = 10", "v_rpm = 0.001")
            .replace("[x]\nv_m_min = 60", "[x]\nv_m_min = 1000000")
            .replace("tcy_ms = 2.0", "tcy_ms = 0.1");
        let m = Machine::from_toml_str(&text, "t").unwrap();
        assert!(close(m.limit(Axis::Primary).v, 0.006));
        assert!(close(m.tcy_s, 0.0001));
        let text = GOOD.replace("tcy_ms = 2.0", "tcy_ms = 100");
        assert!(close(
            Machine::from_toml_str(&text, "t").unwrap().tcy_s,
            0.1
        ));
    }

    #[test]
    fn chain_points_need_exactly_three_values() {
        let chain = "[chain]\nprimary_axis_point_mm = [0.0, 0.0, -150.0]\nc_axis_point_mm = [0.0, 0.0, -100.0]\n";
        let m = Machine::from_toml_str(&format!("{GOOD}{chain}"), "t").unwrap();
        assert_eq!(m.chain.unwrap().c_axis_point_mm, [0.0, 0.0, -100.0]);
        let four = chain.replace("[0.0, 0.0, -100.0]", "[0.0, 0.0, -100.0, 7.0]");
        let msg = invalid_message(&format!("{GOOD}{four}"));
        assert!(
            msg.contains("chain.c_axis_point_mm must have 3 values, got 4"),
            "{msg}"
        );
        let two = chain.replace("[0.0, 0.0, -150.0]", "[0.0, -150.0]");
        let msg = invalid_message(&format!("{GOOD}{two}"));
        assert!(
            msg.contains("chain.primary_axis_point_mm must have 3 values, got 2"),
            "{msg}"
        );
    }

    /// Issue 19: `--machine /dev/zero` was read without limit.
    #[cfg(unix)]
    #[test]
    fn an_endless_or_huge_machine_file_is_refused_after_a_bounded_read() {
        let msg = Machine::load("/dev/zero").unwrap_err().to_string();
        assert!(
            msg.contains("/dev/zero") && msg.contains("longer than 1048576 bytes"),
            "{msg}"
        );
        let dir = std::env::temp_dir().join(format!("polepatch-kin-big-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let big = dir.join("big.toml");
        // A valid machine padded with a comment past the bound.
        let mut text = GOOD.to_string();
        text.push('#');
        text.push_str(&"x".repeat(MAX_MACHINE_FILE_BYTES as usize));
        std::fs::write(&big, &text).unwrap();
        let msg = Machine::load(big.to_str().unwrap())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("longer than"), "{msg}");
        // Exactly at the bound it is read.
        text.truncate(MAX_MACHINE_FILE_BYTES as usize);
        std::fs::write(&big, &text).unwrap();
        assert_eq!(
            Machine::load(big.to_str().unwrap()).unwrap().name,
            "test-bc"
        );
        std::fs::write(&big, b"name = \"\xff\"\n").unwrap();
        let msg = Machine::load(big.to_str().unwrap())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("not UTF-8"), "{msg}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_io_error_is_printed_once_in_an_error_chain() {
        let dir = std::env::temp_dir();
        let err = Machine::load(dir.to_str().unwrap()).unwrap_err();
        assert!(std::error::Error::source(&err).is_none(), "{err:?}");
    }

    #[test]
    fn unknown_machine_lists_the_builtins() {
        let err = Machine::load("no-such-machine-xyz").unwrap_err();
        assert!(matches!(err, MachineError::Unknown { .. }), "{err:?}");
        let msg = err.to_string();
        assert!(msg.contains("'no-such-machine-xyz'"), "{msg}");
        assert!(msg.contains("mikron-ucp710, mikron-hsm600"), "{msg}");
    }

    #[test]
    fn load_reads_a_file_path_and_reports_it_in_errors() {
        let dir = std::env::temp_dir().join(format!("polepatch-kin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let good = dir.join("good.toml");
        std::fs::write(&good, GOOD).unwrap();
        let m = Machine::load(good.to_str().unwrap()).unwrap();
        assert_eq!(m.name, "test-bc");

        let bad = dir.join("bad.toml");
        std::fs::write(
            &bad,
            GOOD.replace(
                "sense = -1\nrange_deg = [-30",
                "sense = 3\nrange_deg = [-30",
            ),
        )
        .unwrap();
        let msg = Machine::load(bad.to_str().unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("bad.toml") && msg.contains("primary.sense"),
            "{msg}"
        );

        // A directory exists but cannot be read as a file.
        let err = Machine::load(dir.to_str().unwrap()).unwrap_err();
        assert!(matches!(err, MachineError::Io { .. }), "{err:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
