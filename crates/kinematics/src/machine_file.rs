//! The machine TOML file, in its two forms, read into a [`Machine`].
//!
//! - **The chain form**: `[[rotary]]` twice, the two rotary axes from the part to the tool
//!   (letter, what each turns, direction at zero, sense, range, limits, optionally a point
//!   on it), `tool_direction`. Any layout.
//! - **The table-table form**: `[primary]` (A about X or B about Y), `[c]` (the table about
//!   Z, carried by the primary), optional `[chain]`. It is read as the equivalent chain:
//!   `[[rotary]]` C (table, `[0, 0, 1]`) then A (table, `[1, 0, 0]`) or B (table,
//!   `[0, 1, 0]`), the same senses, ranges and limits, the tool along `[0, 0, 1]`.
//!
//! Both forms share `name`, `description`, `tcy_ms`, `[x]`, `[y]`, `[z]` and
//! `[controller]`; a file has one form or the other.

use crate::chain::Chain;
use crate::machine::{
    AxisLimits, Controller, LIMIT_MAX, LIMIT_MIN, Machine, PrimaryAxis, ROTARY_LETTERS,
    check_tcy_ms, num,
};
use crate::rotary::{Carrier, Rotaries, RotaryAxis, angle_rad};
use crate::tolerances::{MIN_AXIS_SIN, MIN_DIRECTION_NORM, UNIT_NORM_TOL};
use crate::vec3::{norm, scale};
use serde::Deserialize;

/// mm/s per m/min.
pub(crate) const MM_S_PER_M_MIN: f64 = 1000.0 / 60.0;
/// mm per m (for m/s² and m/s³).
pub(crate) const MM_PER_M: f64 = 1000.0;
/// °/s per rpm.
pub(crate) const DEG_S_PER_RPM: f64 = 6.0;
/// Degrees per revolution (for rev/s² and rev/s³).
pub(crate) const DEG_PER_REV: f64 = 360.0;

/// The TOML file as written (units of the machine tables).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MachineFile {
    name: String,
    #[allow(dead_code)]
    description: Option<String>,
    tcy_ms: Option<f64>,
    tool_direction: Option<Vec<f64>>,
    x: LinearFile,
    y: LinearFile,
    z: LinearFile,
    primary: Option<PrimaryFile>,
    c: Option<CFile>,
    chain: Option<ChainFile>,
    rotary: Option<Vec<RotaryFile>>,
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
    fn into_chain(self) -> Result<Chain, String> {
        let chain = Chain {
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

/// `[primary]` (table-table form).
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

/// `[c]` (table-table form).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CFile {
    sense: f64,
    range_deg: Option<Vec<f64>>,
    v_rpm: f64,
    a_rev_s2: f64,
    j_rev_s3: f64,
}

/// One `[[rotary]]` (chain form).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RotaryFile {
    letter: String,
    moves: Carrier,
    direction: Vec<f64>,
    sense: Option<f64>,
    range_deg: Option<Vec<f64>>,
    v_rpm: f64,
    a_rev_s2: f64,
    j_rev_s3: f64,
    point_mm: Option<Vec<f64>>,
}

/// A limit must be positive, finite and within [`LIMIT_MIN`, `LIMIT_MAX`] (file units);
/// `field` is its dotted TOML name.
pub(crate) fn positive(field: &str, value: f64) -> Result<f64, String> {
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
pub(crate) fn range(field: &str, r: &[f64]) -> Result<(f64, f64), String> {
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

/// A direction: three finite values of length at least [`MIN_DIRECTION_NORM`]; returned
/// as a unit vector.
fn direction(field: &str, d: &[f64]) -> Result<[f64; 3], String> {
    let v: [f64; 3] = exactly(field, d)?;
    let n = norm(v);
    if !(n.is_finite() && n > 0.0) || v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "{field} must be a direction (three finite values, not all zero), got {v:?}"
        ));
    }
    if n < MIN_DIRECTION_NORM {
        return Err(format!(
            "{field} = [{}, {}, {}] is too short to be a direction (length {}, below {}): \
             write it as a unit vector or in small numbers, such as [0, 1, 1]",
            num(v[0]),
            num(v[1]),
            num(v[2]),
            num(n),
            num(MIN_DIRECTION_NORM)
        ));
    }
    // [0, 0, 1] and [0, 0, 2] both give exactly [0, 0, 1].
    let u = scale(v, 1.0 / n);
    // Held by the bound above; kept so that no NaN direction can ever leave here.
    if (norm(u) - 1.0).abs().is_nan() || (norm(u) - 1.0).abs() >= UNIT_NORM_TOL {
        return Err(format!("{field} = {v:?} cannot be normalised"));
    }
    Ok(u)
}

/// A point: three finite values, mm.
fn point(field: &str, p: &[f64]) -> Result<[f64; 3], String> {
    let v: [f64; 3] = exactly(field, p)?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(format!("{field} must be finite, got {v:?}"));
    }
    Ok(v)
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

/// The controller's codes, checked to be NC codes.
pub(crate) fn checked_controller(controller: Controller) -> Result<Controller, String> {
    for (field, codes) in [
        ("controller.tcpm_on", &controller.tcpm_on),
        ("controller.tcpm_off", &controller.tcpm_off),
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
    if let Some(p) = &controller.tool_point
        && !matches!(
            p.trim().to_ascii_lowercase().as_str(),
            "tip" | "centre" | "center"
        )
    {
        return Err(format!(
            "controller.tool_point: '{p}' is not \"tip\" or \"centre\""
        ));
    }
    Ok(controller)
}

/// A rotary letter: one of [`ROTARY_LETTERS`].
pub(crate) fn rotary_letter(field: &str, text: &str) -> Result<char, String> {
    let mut chars = text.trim().chars();
    match (chars.next(), chars.next()) {
        (Some(l), None) if ROTARY_LETTERS.contains(l.to_ascii_uppercase()) => {
            Ok(l.to_ascii_uppercase())
        }
        _ => Err(format!(
            "{field} must be one letter, an NC address free for a rotary axis (one of \
             {}), got \"{text}\"",
            ROTARY_LETTERS
                .chars()
                .map(String::from)
                .collect::<Vec<_>>()
                .join(" ")
        )),
    }
}

/// The checks every pair must pass, wherever it was read from: distinct letters, table
/// axes before head axes, the tilting axis neither along the pole axis nor along the tool.
/// `names` are the two axes as the source names them (pole axis first).
pub(crate) fn check_pair(rot: &Rotaries, names: [&str; 2]) -> Result<(), String> {
    if rot.c.letter == rot.primary.letter {
        return Err(format!(
            "{} and {} have the same letter '{}'",
            names[0], names[1], rot.c.letter
        ));
    }
    if rot.c.carrier == Carrier::Head && rot.primary.carrier == Carrier::Table {
        return Err(format!(
            "{} moves the head and {} the table: list the axes from the part to the tool \
             (the table axes first)",
            names[0], names[1]
        ));
    }
    let (a, b, t0) = (rot.c.direction, rot.primary.direction, rot.tool_direction);
    if angle_rad(a, b).sin() < MIN_AXIS_SIN {
        return Err(format!(
            "{} and {} are parallel: two rotary axes along one direction cannot orient the \
             tool",
            names[0], names[1]
        ));
    }
    if angle_rad(b, t0).sin() < MIN_AXIS_SIN {
        return Err(format!(
            "{} lies along the tool direction: it would turn the tool about itself",
            names[1]
        ));
    }
    Ok(())
}

/// A tool direction that points down: the spindle below the tip. A machine built so is
/// read as written (its pole is where its geometry puts it, [`Machine::pole_p_deg`]), but
/// the direction is from the tip towards the spindle, and a vertical spindle above the
/// table written `[0, 0, -1]` (the way the tool points) would mirror every tip rewrite of a
/// ball: said.
fn tool_direction_warning(t0: [f64; 3]) -> Option<String> {
    (t0[2] < 0.0).then(|| {
        format!(
            "tool_direction = [{}, {}, {}] points from the tip down to the spindle (a spindle \
             below the part, the tool pointing up): tool_direction is from the tip towards the \
             spindle, [0, 0, 1] for a vertical spindle above the table",
            num(t0[0]),
            num(t0[1]),
            num(t0[2])
        )
    })
}

impl MachineFile {
    /// Validate and convert to internal units; the error names the field.
    pub(crate) fn into_machine(self) -> Result<Machine, String> {
        let tcy_ms = check_tcy_ms("tcy_ms", self.tcy_ms.unwrap_or(1.0))?;
        let linear = [
            self.x.limits("x")?,
            self.y.limits("y")?,
            self.z.limits("z")?,
        ];
        let controller = checked_controller(self.controller)?;
        match (self.primary, self.c, self.rotary) {
            (Some(p), Some(c), None) => {
                if self.tool_direction.is_some() {
                    return Err(
                        "tool_direction belongs to the [[rotary]] form; the [primary]/[c] form \
                         has the tool along [0, 0, 1]"
                            .to_string(),
                    );
                }
                let letter = match p.letter {
                    PrimaryAxis::A => 'A',
                    PrimaryAxis::B => 'B',
                };
                Ok(Machine {
                    name: self.name,
                    rotary: Rotaries::table_table(letter),
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
                        linear[0],
                        linear[1],
                        linear[2],
                        rotary_limits("primary", p.v_rpm, p.a_rev_s2, p.j_rev_s3)?,
                        rotary_limits("c", c.v_rpm, c.a_rev_s2, c.j_rev_s3)?,
                    ],
                    chain: self.chain.map(ChainFile::into_chain).transpose()?,
                    controller,
                    warnings: Vec::new(),
                })
            }
            (None, None, Some(axes)) => {
                if self.chain.is_some() {
                    return Err(
                        "[chain] belongs to the [primary]/[c] form; in the [[rotary]] form give \
                         point_mm in each [[rotary]]"
                            .to_string(),
                    );
                }
                let [pole, tilt]: [RotaryFile; 2] = axes.try_into().map_err(|v: Vec<_>| {
                    format!(
                        "[[rotary]] must be given exactly twice (the two rotary axes, from the \
                         part to the tool), got {}",
                        v.len()
                    )
                })?;
                let tool_direction = match &self.tool_direction {
                    Some(d) => direction("tool_direction", d)?,
                    None => [0.0, 0.0, 1.0],
                };
                let axis = |i: usize, r: &RotaryFile| -> Result<RotaryAxis, String> {
                    Ok(RotaryAxis {
                        letter: rotary_letter(&format!("rotary[{i}].letter"), &r.letter)?,
                        carrier: r.moves,
                        direction: direction(&format!("rotary[{i}].direction"), &r.direction)?,
                    })
                };
                let rotary = Rotaries {
                    primary: axis(1, &tilt)?,
                    c: axis(0, &pole)?,
                    tool_direction,
                };
                check_pair(
                    &rotary,
                    [
                        &format!("rotary[0] ({})", rotary.c.letter),
                        &format!("rotary[1] ({})", rotary.primary.letter),
                    ],
                )?;
                let chain = match (&pole.point_mm, &tilt.point_mm) {
                    (None, None) => None,
                    (Some(c), Some(p)) => Some(Chain {
                        primary_axis_point_mm: point("rotary[1].point_mm", p)?,
                        c_axis_point_mm: point("rotary[0].point_mm", c)?,
                    }),
                    (None, Some(_)) | (Some(_), None) => {
                        return Err(
                            "point_mm must be given for both rotary axes or for neither".into()
                        );
                    }
                };
                Ok(Machine {
                    name: self.name,
                    rotary,
                    primary_sense: sense("rotary[1].sense", tilt.sense.unwrap_or(1.0))?,
                    c_sense: sense("rotary[0].sense", pole.sense.unwrap_or(1.0))?,
                    primary_range_deg: range(
                        "rotary[1].range_deg",
                        tilt.range_deg.as_deref().ok_or(
                            "rotary[1].range_deg is required: the travel of the axis that tilts \
                             the tool",
                        )?,
                    )?,
                    c_range_deg: pole
                        .range_deg
                        .as_deref()
                        .map(|r| range("rotary[0].range_deg", r))
                        .transpose()?,
                    tcy_s: tcy_ms / 1000.0,
                    limits: [
                        linear[0],
                        linear[1],
                        linear[2],
                        rotary_limits("rotary[1]", tilt.v_rpm, tilt.a_rev_s2, tilt.j_rev_s3)?,
                        rotary_limits("rotary[0]", pole.v_rpm, pole.a_rev_s2, pole.j_rev_s3)?,
                    ],
                    chain,
                    controller,
                    warnings: tool_direction_warning(tool_direction).into_iter().collect(),
                })
            }
            (None, None, None) => Err(
                "no rotary axes: give [[rotary]] twice (the chain form) or [primary] and [c]"
                    .to_string(),
            ),
            (Some(_), None, None) => Err("missing field `c` (the [c] table)".to_string()),
            (None, Some(_), None) => Err("missing field `primary`".to_string()),
            (_, _, Some(_)) => Err(
                "a machine file has either [[rotary]] (the chain form) or [primary] and [c], not \
                 both"
                    .to_string(),
            ),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use crate::rotary::{Carrier, Layout};
    use crate::{Axis, Machine, MachineError, forward};

    /// The example machine files next to the built-ins, by name.
    pub(crate) const EXAMPLES: &[(&str, &str)] = &[
        (
            "mikron-ucp710-chain-form",
            include_str!("../machines/mikron-ucp710-chain-form.toml"),
        ),
        (
            "mikron-hsm600-chain-form",
            include_str!("../machines/mikron-hsm600-chain-form.toml"),
        ),
        (
            "example-head-table-bc",
            include_str!("../machines/example-head-table-bc.toml"),
        ),
        (
            "example-head-head-cb",
            include_str!("../machines/example-head-head-cb.toml"),
        ),
        (
            "example-nutating-table-45",
            include_str!("../machines/example-nutating-table-45.toml"),
        ),
        (
            "example-trunnion-ab",
            include_str!("../machines/example-trunnion-ab.toml"),
        ),
    ];

    pub(crate) fn example(name: &str) -> Machine {
        let text = EXAMPLES.iter().find(|e| e.0 == name).unwrap().1;
        Machine::from_toml_str(text, name).unwrap()
    }

    #[test]
    fn every_example_machine_file_loads_and_names_itself() {
        for (name, text) in EXAMPLES {
            let m = Machine::from_toml_str(text, name).unwrap();
            assert_eq!(&m.name, name);
            assert!(m.warnings.is_empty());
        }
    }

    /// Today's files and the chain form of the same machine are the same machine.
    #[test]
    fn the_builtins_in_the_chain_form_are_the_builtins() {
        for builtin in Machine::builtin_names() {
            let mut chain_form = example(&format!("{builtin}-chain-form"));
            chain_form.name = builtin.to_string();
            assert_eq!(chain_form, Machine::builtin(builtin).unwrap(), "{builtin}");
            assert!(chain_form.standard_form().is_some());
        }
    }

    /// `[chain]` of the table-table form is `point_mm` of the chain form.
    #[test]
    fn a_chain_section_is_the_points_of_the_rotary_axes() {
        let legacy = Machine::from_toml_str(
            include_str!("../machines/mikron-ucp710-example-chain.toml"),
            "t",
        )
        .unwrap();
        let text = include_str!("../machines/mikron-ucp710-chain-form.toml")
            .replace(
                "j_rev_s3 = 50.0\n",
                "j_rev_s3 = 50.0\npoint_mm = [0.0, 0.0, 0.0]\n",
            )
            .replace(
                "j_rev_s3 = 5.0\n",
                "j_rev_s3 = 5.0\npoint_mm = [0.0, 0.0, -50.0]\n",
            );
        let chain_form = Machine::from_toml_str(&text, "t").unwrap();
        assert_eq!(chain_form.chain, legacy.chain);
        assert!(legacy.chain.is_some());
    }

    #[test]
    fn the_examples_have_their_layouts_letters_and_poles() {
        let cases = [
            ("example-head-table-bc", Layout::HeadTable, 'B', 'C'),
            ("example-head-head-cb", Layout::HeadHead, 'B', 'C'),
            ("example-nutating-table-45", Layout::TableTable, 'B', 'C'),
            ("example-trunnion-ab", Layout::TableTable, 'A', 'B'),
        ];
        for (name, layout, p, c) in cases {
            let m = example(name);
            assert_eq!(m.layout(), layout, "{name}");
            assert_eq!((m.primary_letter(), m.c_letter()), (p, c), "{name}");
            assert_eq!(m.letter(Axis::Primary), p);
            assert_eq!(m.rotary_axis_of(c.to_ascii_lowercase()), Some(Axis::C));
            assert_eq!(m.rotary_axis_of('X'), None);
            assert_eq!(m.pole_direction(), [0.0, 0.0, 1.0], "{name}");
            assert_eq!(m.pole_p_deg(), Some(0.0), "{name}");
            assert_eq!(forward(&m, 0.0, 77.0), [0.0, 0.0, 1.0], "{name}");
        }
        // The trunnion: A tilts about X, the platter B about Z: G16 eq. 1 with B for C.
        let m = example("example-trunnion-ab");
        let (a, b) = (20f64.to_radians(), 30f64.to_radians());
        let o = forward(&m, 20.0, 30.0);
        let want = [b.sin() * a.sin(), -b.cos() * a.sin(), a.cos()];
        assert!((0..3).all(|k| (o[k] - want[k]).abs() < 1e-15), "{o:?}");
        // The head-table machine's head turns the tool: B = 90° points it along +X.
        let m = example("example-head-table-bc");
        assert_eq!(m.rotary.primary.carrier, Carrier::Head);
        let o = forward(&m, 90.0, 0.0);
        assert!((o[0] - 1.0).abs() < 1e-15 && o[2].abs() < 1e-15, "{o:?}");
        let nut = example("example-nutating-table-45");
        assert!(nut.standard_form().is_none());
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let d = nut.rotary.primary.direction;
        assert!(d[0] == 0.0 && (d[1] - s).abs() < 1e-15 && (d[2] - s).abs() < 1e-15);
    }

    /// A small valid chain-form machine; tests edit one line of it.
    const GOOD: &str = r#"
name = "test-head-table"
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
[[rotary]]
letter = "C"
moves = "table"
direction = [0, 0, 1]
v_rpm = 10
a_rev_s2 = 1
j_rev_s3 = 1
[[rotary]]
letter = "B"
moves = "head"
direction = [0, 1, 0]
sense = -1
range_deg = [-90, 90]
v_rpm = 20
a_rev_s2 = 2
j_rev_s3 = 2
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
    fn a_chain_form_machine_reads_into_its_slots() {
        let m = Machine::from_toml_str(GOOD, "good.toml").unwrap();
        assert_eq!(m.layout(), Layout::HeadTable);
        assert_eq!((m.primary_sense, m.c_sense), (-1.0, 1.0));
        assert_eq!(m.primary_range_deg, (-90.0, 90.0));
        assert_eq!(m.c_range_deg, None);
        // The tilting axis is slot Primary: 20 rpm = 120 °/s; the pole axis slot C.
        assert_eq!(m.limit(Axis::Primary).v, 120.0);
        assert_eq!(m.limit(Axis::C).v, 60.0);
        assert_eq!(m.chain, None);
        assert_eq!(m.tcy_s, 0.001);
    }

    #[test]
    fn invalid_chain_form_fields_are_named_in_the_message() {
        let edits: &[(&str, &str, &str)] = &[
            (
                "letter = \"B\"",
                "letter = \"C\"",
                "have the same letter 'C'",
            ),
            (
                "letter = \"B\"",
                "letter = \"X\"",
                "rotary[1].letter must be one letter",
            ),
            ("letter = \"B\"", "letter = \"BB\"", "one of A B C E U V W"),
            (
                "moves = \"head\"",
                "moves = \"spindle\"",
                "unknown variant `spindle`",
            ),
            (
                "direction = [0, 1, 0]",
                "direction = [0, 0, -3]",
                "rotary[0] (C) and rotary[1] (B) are parallel",
            ),
            (
                "direction = [0, 1, 0]",
                "direction = [0, 1, 0, 0]",
                "rotary[1].direction must have 3 values, got 4",
            ),
            (
                "direction = [0, 0, 1]",
                "direction = [0, 0, 0]",
                "rotary[0].direction must be a direction",
            ),
            // Issue 39: a subnormal direction was normalised to NaN and every kinematics
            // after it was NaN ("no singular zone", "needs ANaN").
            (
                "direction = [0, 1, 0]",
                "direction = [1e-320, 0, 0]",
                "rotary[1].direction = [1e-320, 0, 0] is too short to be a direction",
            ),
            (
                "direction = [0, 0, 1]",
                "direction = [0, 0, 1e-9]",
                "rotary[0].direction = [0, 0, 1e-9] is too short",
            ),
            (
                "name = \"test-head-table\"",
                "name = \"t\"\ntool_direction = [0, 5e-324, 0]",
                "tool_direction = [0, 5e-324, 0] is too short",
            ),
            (
                "name = \"test-head-table\"",
                "name = \"t\"\ntool_direction = [0, 1, 0]",
                "rotary[1] (B) lies along the tool direction",
            ),
            (
                "range_deg = [-90, 90]\n",
                "",
                "rotary[1].range_deg is required",
            ),
            (
                "sense = -1",
                "sense = 0.5",
                "rotary[1].sense must be +1 or -1, got 0.5",
            ),
            (
                "v_rpm = 20",
                "v_rpm = 0",
                "rotary[1].v_rpm must be positive and finite, got 0",
            ),
            (
                "j_rev_s3 = 1\n[[rotary]]",
                "j_rev_s3 = 1\npoint_mm = [0, 0, 0]\n[[rotary]]",
                "point_mm must be given for both rotary axes or for neither",
            ),
            (
                "v_rpm = 10",
                "v_rpm = 10\nrange_deg = [5, 1]",
                "rotary[0].range_deg: min must be below max",
            ),
            (
                "name = \"test-head-table\"",
                "name = \"t\"\n[chain]\nprimary_axis_point_mm = [0, 0, 0]\nc_axis_point_mm = [0, 0, 0]",
                "[chain] belongs to the [primary]/[c] form",
            ),
            (
                "moves = \"table\"",
                "moves = \"table\"\nlength = 3",
                "unknown field `length`",
            ),
        ];
        for (from, to, want) in edits {
            assert!(GOOD.contains(from), "test edit {from:?} does not apply");
            let msg = invalid_message(&GOOD.replacen(from, to, 1));
            assert!(
                msg.contains(want),
                "edit {to:?}: message {msg:?} lacks {want:?}"
            );
        }
        // A head axis before a table axis.
        let swapped = GOOD
            .replacen("moves = \"table\"", "moves = \"X\"", 1)
            .replacen("moves = \"head\"", "moves = \"table\"", 1)
            .replacen("moves = \"X\"", "moves = \"head\"", 1);
        let msg = invalid_message(&swapped);
        assert!(
            msg.contains("list the axes from the part to the tool"),
            "{msg}"
        );
        // Three axes, or one.
        let third =
            &GOOD[GOOD.find("[[rotary]]\nletter = \"B\"").unwrap()..].replace("\"B\"", "\"A\"");
        let msg = invalid_message(&format!("{GOOD}{third}"));
        assert!(
            msg.contains("exactly twice") && msg.contains("got 3"),
            "{msg}"
        );
        let one = &GOOD[..GOOD.find("[[rotary]]\nletter = \"B\"").unwrap()];
        assert!(invalid_message(one).contains("got 1"));
        // Neither form, both forms.
        let none = &GOOD[..GOOD.find("[[rotary]]").unwrap()];
        assert!(invalid_message(none).contains("no rotary axes"));
        let legacy = "[primary]\nletter = \"A\"\nsense = 1\nrange_deg = [-1, 1]\nv_rpm = 1\na_rev_s2 = 1\nj_rev_s3 = 1\n";
        assert!(invalid_message(&format!("{GOOD}{legacy}")).contains("not both"));
        // tool_direction only in the chain form.
        let ucp = include_str!("../machines/mikron-ucp710.toml")
            .replace("tcy_ms = 1.0", "tcy_ms = 1.0\ntool_direction = [0, 0, 1]");
        assert!(invalid_message(&ucp).contains("tool_direction belongs to the [[rotary]] form"));
    }

    /// Issue 39: `tool_direction = [0, 0, -1]` (the spindle below the tip) under an A-C
    /// table. Its tool at zero points against the C axis, so its pole in range is P = 0
    /// with the tool against C (the tool along C needs A = 180°, beyond the travel): C
    /// turns the tool at |A| from it there. It was measured from the pole along C, 180°
    /// away, and SING had "no singular zone".
    #[test]
    fn a_tool_pointing_up_meets_its_pole_against_the_c_axis() {
        let ucp = include_str!("../machines/mikron-ucp710-chain-form.toml");
        let up = ucp.replace(
            "tool_direction = [0.0, 0.0, 1.0]",
            "tool_direction = [0.0, 0.0, -1.0]",
        );
        assert_ne!(up, ucp);
        let m = Machine::from_toml_str(&up, "up.toml").unwrap();
        assert!(m.standard_form().is_none());
        assert_eq!(m.pole_p_deg(), Some(0.0));
        assert_eq!(m.pole_direction(), [0.0, 0.0, -1.0]);
        assert_eq!(forward(&m, 0.0, 77.0), [0.0, 0.0, -1.0]);
        // The distance from the pole is |A| on both sides, as on the upright machine.
        for a in [1.0, -1.0, 4.5, -30.0, 100.0] {
            assert!((m.pole_tilt_deg(a) - f64::abs(a)).abs() < 1e-12, "{a}");
        }
        // And C cannot turn the tool there: the pole is where the geometry is singular.
        let j = crate::forward_jacobian(&m, 0.0, 40.0);
        assert!(j[2].iter().all(|x| x.abs() < 1e-15), "{j:?}");
        // The tool is the upright machine's, reversed.
        let std = Machine::builtin("mikron-ucp710").unwrap();
        for (a, c) in [(10.0, 20.0), (-50.0, 190.0)] {
            let (o, s) = (forward(&m, a, c), forward(&std, a, c));
            assert!((0..3).all(|k| (o[k] + s[k]).abs() < 1e-15), "{o:?} {s:?}");
        }
        // Said, for a file that meant the tool's pointing direction.
        assert!(
            m.warnings.len() == 1 && m.warnings[0].contains("tool_direction = [0, 0, -1]"),
            "{:?}",
            m.warnings
        );
        // With a travel that holds A = 180° instead, the pole along C is the one in range.
        let turned = up.replace("range_deg = [-100.0, 120.0]", "range_deg = [100.0, 260.0]");
        let m = Machine::from_toml_str(&turned, "t").unwrap();
        assert_eq!(m.pole_p_deg(), Some(180.0));
        assert_eq!(m.pole_direction(), [0.0, 0.0, 1.0]);
        assert!((m.pole_tilt_deg(175.0) - 5.0).abs() < 1e-12);
        // With neither pole in range: the pole along C, as the geometry first reaches it.
        let neither = up.replace("range_deg = [-100.0, 120.0]", "range_deg = [20.0, 60.0]");
        let m = Machine::from_toml_str(&neither, "t").unwrap();
        assert_eq!(m.pole_p_deg(), Some(180.0));
    }

    /// A pole axis along −Z with sense +1 is the standard form with sense −1: one machine.
    #[test]
    fn a_negative_direction_is_the_opposite_sense() {
        let flipped = GOOD
            .replace("direction = [0, 0, 1]", "direction = [0, 0, -1]")
            .replace("moves = \"head\"", "moves = \"table\"");
        let m = Machine::from_toml_str(&flipped, "t").unwrap();
        let f = m.standard_form().unwrap();
        assert_eq!((f.sp, f.sc), (-1.0, -1.0));
        let mut n = m.clone();
        n.rotary.c.direction = [0.0, 0.0, 1.0];
        n.c_sense = -1.0;
        for (p, c) in [(10.0, 20.0), (-50.0, 190.0)] {
            assert_eq!(forward(&m, p, c), forward(&n, p, c));
        }
    }
}
