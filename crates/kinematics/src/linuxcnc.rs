//! LinuxCNC machines: a [`Machine`] from the INI file the controller runs.
//!
//! What is read, and from where (the INI's own directory for relative paths):
//!
//! - `[KINS] KINEMATICS`: the kinematics module and its parameters. Read:
//!   `xyzac-trt-kins` and `xyzbc-trt-kins` (`src/emc/kinematics/trtfuncs.c`: a tilting table,
//!   A about X or B about Y, carrying a C table about Z; with `sparm=identityfirst` the
//!   switchable type 0 is identity and type 1 the TCP kinematics, else type 0 is TCP and
//!   type 1 identity; type 2 is the user kinematics), and `xyzab_tdr_kins`
//!   (`src/hal/components/xyzab_tdr_kins.comp`: an A table about X carried by a B table
//!   about Y; type 0 identity, type 1 TCP), and `5axiskins` (`src/emc/kinematics/
//!   5axiskins.c`: the bridge mill's fork head, C about Z carrying B, with a W quill along
//!   the tool; switchable types as the trt modules'). Each module's conventions are its
//!   source's: for the tables the tool axis in the part frame is the third row of the
//!   rotation in its inverse kinematics (joints = M·(world − pivot) + …); for 5axiskins the
//!   direction from the tip to the pivot in its forward kinematics, `tip = joints +
//!   (0, 0, L) + s2r(L + W, C, 180° − B)` with `s2r(r, t, p) = r·(sin p cos t, sin p sin t,
//!   cos p)` and L the `pivot-length` pin. That gives
//!
//!   | module | tool axis `o_wp` | as a chain (`crate::rotary`) |
//!   |---|---|---|
//!   | `xyzac-trt-kins` | `(sin C sin A, −con cos C sin A, cos A)` | C table `ẑ`, A table `x̂`, senses `con` |
//!   | `xyzbc-trt-kins` | `(con cos C sin B, sin C sin B, cos B)` | C table `ẑ`, B table `ŷ`, senses `con` |
//!   | `xyzab_tdr_kins` | `(sin B, −sin A cos B, cos A cos B)` | A table `x̂`, B table `ŷ`, senses +1 |
//!   | `5axiskins` | `(−sin B cos C, −sin B sin C, cos B)` | C head `ẑ`, B head `ŷ`, senses C +1, B −1 |
//!
//!   5axiskins' W moves the tool along its axis inside the motion of X Y Z: its X Y Z are
//!   the tip at W = 0, the tool's tip is at X Y Z + W·o. W is not an axis of the model: its
//!   words are carried through, and a warning says that an orientation changed at W ≠ 0
//!   moves the tip.
//!
//!   with `con` = +1 when the HAL pin `<module>.conventional-directions` is set, −1 (the
//!   module's default: "the directions of the rotational axes are the opposite of the
//!   conventional axis directions") otherwise. So `xyzac-trt-kins` writes j = +cos C·sin A
//!   by default (C17's senses), the built-in UCP710 j = −cos C·sin A (G16's).
//!   Any other module is refused by name: describe such a machine in a TOML file.
//! - The pivot parameters, from the HAL pins `<module>.x-rot-point`, `y-rot-point`,
//!   `z-rot-point`, `x-offset`, `y-offset`, `z-offset` (5axiskins: `pivot-length`) as
//!   `setp` (or `sets` on the signal a pin is netted to) in the INI's `[HAL] HALFILE` files,
//!   `HALCMD` lines and `POSTGUI_HALFILE` files, in that order (`hal.rs`). A `HALFILE`'s
//!   first word is the file (the rest are a `.tcl` file's arguments), found in the INI's
//!   folder; `LIB:` files and names of LinuxCNC's own library (`lib/hallib`) not in that
//!   folder are LinuxCNC's and passed over; any other file that cannot be found or read is
//!   an error naming it. `.tcl` files are read by `haltcl.rs` (haltcl's `setp`, `sets`,
//!   `net`, `$::SECTION(KEY)`; a form it does not evaluate — an expression, a variable, a
//!   loop — makes the pins it may set unknown, named with its file, line and column);
//!   other files as halcmd lines (`[SECTION]KEY` substituted). A pin never set has the
//!   module's value (0; 5axiskins' `pivot-length` 250); one on a signal that nothing sets
//!   or drives is 0. They give the chain (points on the two axes): the pole axis through
//!   the rotation point `r`, the tilting axis through `r` plus the offsets (`xyzac`:
//!   `(0, y-offset, z-offset)`; `xyzbc`: `(x-offset, 0, z-offset)`), for `xyzab_tdr` the A
//!   axis through `r + (x-offset, 0, z-offset)`, the B axis through `r`, and for 5axiskins
//!   both head axes through the pivot, `(0, 0, pivot-length)` from the tip of a tool of
//!   length 0. The tool-offset pin (the current tool's length, a run-time value) is taken
//!   as 0. A pivot pin that cannot be known (driven at run time by another component, a
//!   Tcl form) gives no chain, with a warning; `conventional-directions` that cannot be
//!   known is an error (the senses depend on it).
//! - The limits: `MAX_VELOCITY`, `MAX_ACCELERATION` and `MAX_JERK` of `[AXIS_L]` and of the
//!   `[JOINT_n]` of that letter (joints numbered in the order of `[TRAJ] COORDINATES`, or
//!   the module's `coordinates=` parameter); where both give a value the smaller counts,
//!   since LinuxCNC holds both. Without a jerk (`MAX_JERK` absent or 0: LinuxCNC's
//!   trapezoidal planner has none) the jerk is [`default_jerk`]: the acceleration reached in
//!   one servo period, with a warning. Units: `[TRAJ] LINEAR_UNITS` (mm, inch) and
//!   `ANGULAR_UNITS` (deg, rad, grad), per second. Ranges: `MIN_LIMIT`/`MAX_LIMIT` (the
//!   narrower of axis and joints); the pole axis is endless when it has none or
//!   `WRAPPED_ROTARY = 1`; the tilting axis needs one.
//! - The interpolation cycle: `[EMCMOT] SERVO_PERIOD` (ns; LinuxCNC's default 1 ms).
//! - The TCPM codes: each `[RS274NGC] REMAP = Mnnn … ngc=NAME` whose subroutine
//!   (`NAME.ngc` in `SUBROUTINE_PATH`) sets `#<kinstype> = k`: `tcpm_on` when `k` is the
//!   module's TCP type, `tcpm_off` otherwise. Kinematics that start as TCP and are never
//!   switched are always TCP (`tcpm_always`).
//! - The name: `[EMC] MACHINE`, else the file's name.

use crate::chain::Chain;
use crate::hal::Hal;
use crate::ini::Entry;
pub use crate::ini::Ini;
use crate::machine::{AxisLimits, Controller, Machine, MachineError, num, read_bounded};
use crate::machine_file::{
    DEG_PER_REV, DEG_S_PER_RPM, MM_PER_M, MM_S_PER_M_MIN, check_pair, positive, range,
};
use crate::rotary::{Carrier, Rotaries, RotaryAxis};
use crate::tolerances::LINUXCNC_NO_LIMIT;
use crate::vec3::add;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The jerk given to an axis whose INI has none, in its units per second cubed: its
/// acceleration reached within one servo period, `MAX_ACCELERATION / SERVO_PERIOD` — what
/// LinuxCNC's trapezoidal planner does, whose acceleration steps from one servo cycle to
/// the next. (For the sample configs, 300 mm/s² at 1 ms: 300 000 mm/s³ = 300 m/s³.)
pub fn default_jerk(max_acceleration: f64, servo_period_s: f64) -> f64 {
    max_acceleration / servo_period_s
}

pub use crate::settings::DEFAULT_SERVO_PERIOD_S;

fn invalid(origin: &str, message: String) -> MachineError {
    MachineError::Invalid {
        path: origin.to_string(),
        message,
    }
}

/// A kinematics module polepatch reads (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Module {
    XyzacTrt,
    XyzbcTrt,
    XyzabTdr,
    /// `5axiskins`: the bridge mill's head-head C-B (with a W quill along the tool).
    FiveAxis,
}

impl Module {
    fn from_name(name: &str) -> Option<Module> {
        match name.to_ascii_lowercase().replace('_', "-").as_str() {
            "xyzac-trt-kins" => Some(Module::XyzacTrt),
            "xyzbc-trt-kins" => Some(Module::XyzbcTrt),
            "xyzab-tdr-kins" => Some(Module::XyzabTdr),
            "5axiskins" => Some(Module::FiveAxis),
            _ => None,
        }
    }
    /// The prefix of its HAL pins.
    fn hal_prefix(self) -> &'static str {
        match self {
            Module::XyzacTrt => "xyzac-trt-kins",
            Module::XyzbcTrt => "xyzbc-trt-kins",
            Module::XyzabTdr => "xyzab_tdr_kins",
            Module::FiveAxis => "5axiskins",
        }
    }
    /// The letters it requires, in its joints' default order.
    fn default_coordinates(self) -> &'static str {
        match self {
            Module::XyzacTrt => "XYZAC",
            Module::XyzbcTrt => "XYZBC",
            Module::XyzabTdr => "XYZAB",
            Module::FiveAxis => "XYZBCW",
        }
    }
    /// (pole axis letter and direction, tilting axis letter and direction).
    fn axes(self) -> ((char, [f64; 3]), (char, [f64; 3])) {
        match self {
            Module::XyzacTrt => (('C', [0.0, 0.0, 1.0]), ('A', [1.0, 0.0, 0.0])),
            Module::XyzbcTrt => (('C', [0.0, 0.0, 1.0]), ('B', [0.0, 1.0, 0.0])),
            Module::XyzabTdr => (('A', [1.0, 0.0, 0.0]), ('B', [0.0, 1.0, 0.0])),
            Module::FiveAxis => (('C', [0.0, 0.0, 1.0]), ('B', [0.0, 1.0, 0.0])),
        }
    }
    /// What its two rotary axes turn.
    fn carrier(self) -> Carrier {
        match self {
            Module::FiveAxis => Carrier::Head,
            _ => Carrier::Table,
        }
    }
    /// The HAL pins of its parameters polepatch reads, with the module's value for a pin
    /// never set (in the INI's linear units): 5axiskins.c creates `pivot-length` with
    /// `DEFAULT_PIVOT_LENGTH` 250; the other modules' pins start at HAL's 0.
    fn parameter_pins(self) -> &'static [(&'static str, f64)] {
        match self {
            Module::FiveAxis => &[("pivot-length", 250.0)],
            _ => &[
                ("x-rot-point", 0.0),
                ("y-rot-point", 0.0),
                ("z-rot-point", 0.0),
                ("x-offset", 0.0),
                ("y-offset", 0.0),
                ("z-offset", 0.0),
            ],
        }
    }
    /// The switchable kinematics type that is TCP, given the module's `sparm`.
    fn tcp_type(self, identity_first: bool) -> i64 {
        match self {
            Module::XyzabTdr => 1,
            _ if identity_first => 1,
            _ => 0,
        }
    }
}

/// Units: mm per the INI's linear unit, degrees per its angular unit.
fn linear_mm(unit: &str) -> Option<f64> {
    match unit.to_ascii_lowercase().as_str() {
        "mm" | "metric" | "millimeter" | "millimetre" => Some(1.0),
        "in" | "inch" | "imperial" => Some(25.4),
        "cm" => Some(10.0),
        _ => None,
    }
}

fn angular_deg(unit: &str) -> Option<f64> {
    match unit.to_ascii_lowercase().as_str() {
        "deg" | "degree" | "degrees" => Some(1.0),
        "rad" | "radian" | "radians" => Some(180.0 / std::f64::consts::PI),
        "grad" | "gon" => Some(0.9),
        _ => None,
    }
}

/// What [`machine_from_ini`] collects about one axis letter: values in the INI's units.
struct AxisIni {
    v: Option<f64>,
    a: Option<f64>,
    j: Option<f64>,
    range: Option<(f64, f64)>,
    wrapped: bool,
}

/// Reads a LinuxCNC INI (module docs) at `path` whose text is `text`.
pub(crate) fn machine_from_ini(text: &str, path: &Path) -> Result<Machine, MachineError> {
    machine_from_ini_text(text, &path.display().to_string(), path.parent())
}

/// [`Machine::load`] of an INI, from its text; `origin` names it in errors and `dir` is the
/// directory relative paths (HAL files, subroutines) start from (`None`: no file is read).
pub fn machine_from_ini_text(
    text: &str,
    origin: &str,
    dir: Option<&Path>,
) -> Result<Machine, MachineError> {
    let ini = Ini::parse(text, origin)?;
    let mut r = IniReading {
        ini: &ini,
        origin,
        dir,
        warnings: Vec::new(),
    };
    if let Some(line) = ini.includes.first() {
        r.warnings.push(format!(
            "{origin}: line {line}: #INCLUDE is expanded by LinuxCNC's start script, not read \
             here: keys in the included file are missing"
        ));
    }
    let (module, params) = r.kinematics_module()?;
    let identity_first = params
        .get("sparm")
        .is_some_and(|s| s.contains("identityfirst"));
    let units = r.units()?;
    let tcy_ms =
        crate::machine::check_tcy_ms("[EMCMOT] SERVO_PERIOD (as ms)", units.servo_period_s * 1e3)
            .map_err(|m| r.err(m))?;
    let axes = r.axes(module, &params, units)?;
    let hal = r.hal()?;
    let (con, chain) = r.chain(module, &hal, units.mm)?;
    let controller = r.tcpm_codes(module.tcp_type(identity_first))?;
    r.machine(module, con, tcy_ms, axes, chain, controller)
}

/// A LinuxCNC INI being read into a [`Machine`] (module docs): the file, where it is, and
/// the warnings so far.
struct IniReading<'a> {
    ini: &'a Ini,
    /// Names the INI in messages.
    origin: &'a str,
    /// The folder relative paths start from (`None`: no file is read).
    dir: Option<&'a Path>,
    warnings: Vec<String>,
}

/// The INI's units: mm per linear unit, degrees per angular unit, and the servo period
/// (seconds), in which an axis without a jerk reaches its acceleration.
#[derive(Debug, Clone, Copy)]
struct Units {
    mm: f64,
    deg: f64,
    servo_period_s: f64,
}

/// The axes read from the INI: the limits of X Y Z, the tilting axis and the pole axis (in
/// internal units), and the travels of the two rotary axes (degrees).
struct Axes {
    limits: [AxisLimits; 5],
    primary_range_deg: (f64, f64),
    c_range_deg: Option<(f64, f64)>,
}

impl IniReading<'_> {
    fn err(&self, message: String) -> MachineError {
        invalid(self.origin, message)
    }

    /// `[KINS] KINEMATICS = module params…`: the module and its parameters (keys lower
    /// case).
    fn kinematics_module(&self) -> Result<(Module, HashMap<String, String>), MachineError> {
        let kins = self.ini.entry("KINS", "KINEMATICS").ok_or_else(|| {
            self.err("no [KINS] KINEMATICS: which kinematics module runs the machine?".into())
        })?;
        let mut words = kins.value.split_whitespace();
        let module_name = words.next().unwrap_or("");
        let params: HashMap<String, String> = words
            .filter_map(|w| w.split_once('='))
            .map(|(k, v)| (k.to_ascii_lowercase(), v.to_string()))
            .collect();
        let module = Module::from_name(module_name).ok_or_else(|| {
            self.err(format!(
                "line {}: [KINS] KINEMATICS = {module_name}: polepatch reads the 5-axis modules \
                 xyzac-trt-kins, xyzbc-trt-kins, xyzab_tdr_kins and 5axiskins; describe this machine in a \
                 TOML file (its two rotary axes as [[rotary]], see the README)",
                kins.line
            ))
        })?;
        Ok((module, params))
    }

    /// `[TRAJ] LINEAR_UNITS`, `ANGULAR_UNITS` and `[EMCMOT] SERVO_PERIOD`.
    fn units(&self) -> Result<Units, MachineError> {
        let ini = self.ini;
        let lin = ini.get("TRAJ", "LINEAR_UNITS").unwrap_or("mm");
        let mm = linear_mm(lin)
            .ok_or_else(|| self.err(format!("[TRAJ] LINEAR_UNITS = {lin}: not mm or inch")))?;
        let ang = ini.get("TRAJ", "ANGULAR_UNITS").unwrap_or("deg");
        let deg = angular_deg(ang).ok_or_else(|| {
            self.err(format!(
                "[TRAJ] ANGULAR_UNITS = {ang}: not deg, rad or grad"
            ))
        })?;
        let servo_period_s = match ini.get("EMCMOT", "SERVO_PERIOD") {
            Some(v) => {
                let ns = number(v).ok_or_else(|| {
                    self.err(format!("[EMCMOT] SERVO_PERIOD = {v}: not a number"))
                })?;
                ns * 1e-9
            }
            None => DEFAULT_SERVO_PERIOD_S,
        };
        Ok(Units {
            mm,
            deg,
            servo_period_s,
        })
    }

    /// The letters of the joints, in their order: the module's `coordinates=`, else
    /// `[TRAJ] COORDINATES`, else the module's default.
    fn coordinates(&self, module: Module, params: &HashMap<String, String>) -> String {
        params
            .get("coordinates")
            .map(String::as_str)
            .or(self.ini.get("TRAJ", "COORDINATES"))
            .unwrap_or(module.default_coordinates())
            .chars()
            .filter(|c| !c.is_whitespace())
            .map(|c| c.to_ascii_uppercase())
            .collect()
    }

    /// The limits and travels of the module's axes (module docs), converted to internal
    /// units (mm/s…, °/s…) and checked in the TOML's units; axes without a jerk are warned
    /// about.
    fn axes(
        &mut self,
        module: Module,
        params: &HashMap<String, String>,
        units: Units,
    ) -> Result<Axes, MachineError> {
        let coordinates = self.coordinates(module, params);
        let mut no_jerk = Vec::new();
        let mut limits_of = |letter: char, rotary: bool| {
            self.limits_of(&coordinates, letter, rotary, units, &mut no_jerk)
        };
        let (lx, _) = limits_of('X', false)?;
        let (ly, _) = limits_of('Y', false)?;
        let (lz, _) = limits_of('Z', false)?;
        let ((pole_letter, _), (tilt_letter, _)) = module.axes();
        let (lp, tilt_ini) = limits_of(tilt_letter, true)?;
        let (lc, pole_ini) = limits_of(pole_letter, true)?;
        if !no_jerk.is_empty() {
            self.warnings.push(format!(
                "{}: no MAX_JERK for {}: jerk taken as MAX_ACCELERATION / SERVO_PERIOD ({} \
                 ms), the acceleration reached in one servo cycle as LinuxCNC's trapezoidal \
                 planner does",
                self.origin,
                no_jerk
                    .iter()
                    .map(char::to_string)
                    .collect::<Vec<_>>()
                    .join(" "),
                num(units.servo_period_s * 1e3)
            ));
        }
        let deg = units.deg;
        let to_deg = |(lo, hi): (f64, f64)| (lo * deg, hi * deg);
        let primary_range_deg = match tilt_ini.range.map(to_deg) {
            Some((lo, hi)) => range(
                &format!("[AXIS_{tilt_letter}] MIN_LIMIT/MAX_LIMIT"),
                &[lo, hi],
            )
            .map_err(|m| self.err(m))?,
            None => {
                return Err(self.err(format!(
                    "axis {tilt_letter} tilts the tool and needs a travel: MIN_LIMIT and MAX_LIMIT in \
                     [AXIS_{tilt_letter}]"
                )));
            }
        };
        let c_range_deg = match (pole_ini.wrapped, pole_ini.range.map(to_deg)) {
            (false, Some((lo, hi))) if lo > -LINUXCNC_NO_LIMIT && hi < LINUXCNC_NO_LIMIT => Some(
                range(
                    &format!("[AXIS_{pole_letter}] MIN_LIMIT/MAX_LIMIT"),
                    &[lo, hi],
                )
                .map_err(|m| self.err(m))?,
            ),
            _ => None,
        };
        Ok(Axes {
            limits: [lx, ly, lz, lp, lc],
            primary_range_deg,
            c_range_deg,
        })
    }

    /// The values of axis `letter` over `[AXIS_L]` and its joints (`coordinates`), in the
    /// INI's units.
    fn read_axis(&self, coordinates: &str, letter: char) -> Result<AxisIni, MachineError> {
        let ini = self.ini;
        let mut sections = vec![format!("AXIS_{letter}")];
        sections.extend(
            joints_of(coordinates, letter)
                .into_iter()
                .map(|n| format!("JOINT_{n}")),
        );
        // The values of `key` over the axis and its joints, combined by `pick` (the smaller
        // limit, the larger MIN_LIMIT).
        let combined =
            |key: &str, pick: fn(f64, f64) -> f64| -> Result<Option<f64>, MachineError> {
                let mut best: Option<f64> = None;
                for s in &sections {
                    if let Some(e) = ini.entry(s, key) {
                        let v = number(&e.value).ok_or_else(|| {
                            self.err(format!(
                                "line {}: [{s}] {key} = {}: not a number",
                                e.line, e.value
                            ))
                        })?;
                        best = Some(best.map_or(v, |b| pick(b, v)));
                    }
                }
                Ok(best)
            };
        let value = |key: &str| combined(key, f64::min);
        let (lo, hi) = (
            combined("MIN_LIMIT", f64::max)?,
            combined("MAX_LIMIT", f64::min)?,
        );
        Ok(AxisIni {
            v: value("MAX_VELOCITY")?,
            a: value("MAX_ACCELERATION")?,
            j: value("MAX_JERK")?.filter(|&j| j > 0.0),
            range: lo.zip(hi),
            wrapped: ini
                .get(&format!("AXIS_{letter}"), "WRAPPED_ROTARY")
                .is_some_and(|v| v.trim() == "1"),
        })
    }

    /// The limits of axis `letter` (converted to internal units and checked in the TOML's
    /// units) and what the INI gives for it; a letter without a jerk is added to `no_jerk`.
    fn limits_of(
        &self,
        coordinates: &str,
        letter: char,
        rotary: bool,
        units: Units,
        no_jerk: &mut Vec<char>,
    ) -> Result<(AxisLimits, AxisIni), MachineError> {
        let ax = self.read_axis(coordinates, letter)?;
        let joints = joints_of(coordinates, letter);
        let where_ = if joints.is_empty() {
            format!("[AXIS_{letter}]")
        } else {
            format!(
                "[AXIS_{letter}] or [JOINT_{}]",
                joints
                    .iter()
                    .map(usize::to_string)
                    .collect::<Vec<_>>()
                    .join("]/[JOINT_")
            )
        };
        let need = |v: Option<f64>, key: &str| {
            v.ok_or_else(|| self.err(format!("no {key} for axis {letter} in {where_}")))
        };
        let unit = if rotary { units.deg } else { units.mm };
        let v = need(ax.v, "MAX_VELOCITY")? * unit;
        let a = need(ax.a, "MAX_ACCELERATION")? * unit;
        let j = match ax.j {
            Some(j) => j * unit,
            None => {
                no_jerk.push(letter);
                default_jerk(a, units.servo_period_s)
            }
        };
        let field = |key: &str| format!("{where_} {key}");
        // The TOML file's units: m/min, m/s², m/s³ or rpm, rev/s², rev/s³.
        let (kv, ka) = if rotary {
            (DEG_S_PER_RPM, DEG_PER_REV)
        } else {
            (MM_S_PER_M_MIN, MM_PER_M)
        };
        let err = |m| self.err(m);
        positive(&field("MAX_VELOCITY (converted)"), v / kv).map_err(err)?;
        positive(&field("MAX_ACCELERATION (converted)"), a / ka).map_err(err)?;
        positive(&field("jerk (converted)"), j / ka).map_err(err)?;
        Ok((AxisLimits { v, a, j }, ax))
    }

    /// The HAL the INI runs: `[HAL] HALFILE`, `HALCMD` and `POSTGUI_HALFILE`, in that order.
    fn hal(&self) -> Result<Hal, MachineError> {
        let mut hal = Hal::default();
        for key in ["HALFILE", "HALCMD", "POSTGUI_HALFILE"] {
            for e in self.ini.entries_of("HAL", key) {
                if key == "HALCMD" {
                    hal.halcmd_line(&e.value, self.ini);
                } else {
                    hal_file(self.ini, self.origin, self.dir, e, &mut hal)?;
                }
            }
        }
        Ok(hal)
    }

    /// From the module's HAL pins: the sense `con` of its rotary axes
    /// (`conventional-directions`) and the chain its pivot parameters give (`mm`: mm per
    /// linear unit), or none, with a warning, where a pin cannot be known or the module's
    /// offsets are not a pair of fixed axes.
    fn chain(
        &mut self,
        module: Module,
        hal: &Hal,
        mm: f64,
    ) -> Result<(f64, Option<Chain>), MachineError> {
        let origin = self.origin;
        let prefix = module.hal_prefix();
        let pin = |name: &str| hal.value(&format!("{prefix}.{name}"));
        let con = match module {
            Module::XyzabTdr | Module::FiveAxis => 1.0,
            _ => match pin("conventional-directions") {
                Ok(Some(v)) if v != 0.0 => 1.0,
                Ok(_) => -1.0,
                Err(why) => {
                    return Err(self.err(format!(
                        "{why}: the senses of the rotary axes depend on it (set it with setp)"
                    )));
                }
            },
        };
        let mut pivot = HashMap::new();
        let mut unknown = Vec::new();
        for &(name, default) in module.parameter_pins() {
            match pin(name) {
                Ok(v) => {
                    pivot.insert(name, v.unwrap_or(default) * mm);
                }
                Err(why) => unknown.push(why),
            }
        }
        if !unknown.is_empty() {
            self.warnings.push(format!(
                "{origin}: no kinematic chain (programs without TCP are then not patched): {}",
                unknown.join("; ")
            ));
            return Ok((con, None));
        }
        if module == Module::FiveAxis {
            // Both head axes through the pivot, `pivot-length` above the tip of a tool of
            // length 0 at B = 0 (the tool-offset part of the pin taken as 0, as for the trt
            // modules' tool-offset pin).
            let pivot = [0.0, 0.0, pivot["pivot-length"]];
            return Ok((
                con,
                Some(Chain {
                    c_axis_point_mm: pivot,
                    primary_axis_point_mm: pivot,
                }),
            ));
        }
        let r = [
            pivot["x-rot-point"],
            pivot["y-rot-point"],
            pivot["z-rot-point"],
        ];
        let (dx, dy, dz) = (pivot["x-offset"], pivot["y-offset"], pivot["z-offset"]);
        let chain = match module {
            Module::XyzacTrt => Some(Chain {
                c_axis_point_mm: r,
                primary_axis_point_mm: add(r, [0.0, dy, dz]),
            }),
            Module::XyzbcTrt if con < 0.0 && (dx != 0.0 || dz != 0.0) => {
                self.warnings.push(format!(
                    "{origin}: no kinematic chain: xyzbc-trt-kins with x-offset/z-offset and \
                     conventional-directions 0 turns its offsets with −B while it turns the table \
                     with +B (trtfuncs.c, dpx/dpz), which no pair of fixed axes does"
                ));
                None
            }
            Module::XyzbcTrt => Some(Chain {
                c_axis_point_mm: r,
                primary_axis_point_mm: add(r, [dx, 0.0, dz]),
            }),
            Module::XyzabTdr => Some(Chain {
                c_axis_point_mm: add(r, [dx, 0.0, dz]),
                primary_axis_point_mm: r,
            }),
            Module::FiveAxis => unreachable!("read above"),
        };
        Ok((con, chain))
    }

    /// The TCPM codes: each `[RS274NGC] REMAP` whose subroutine sets `#<kinstype>`
    /// (`tcp_type`: the module's TCP type), and whether the kinematics are always TCP.
    fn tcpm_codes(&mut self, tcp_type: i64) -> Result<Controller, MachineError> {
        let origin = self.origin;
        let dir = self.dir;
        let read_dir = |rel: &str| -> Option<PathBuf> { dir.map(|d| d.join(rel)) };
        let mut controller = Controller::default();
        let sub_dirs: Vec<PathBuf> = self
            .ini
            .get("RS274NGC", "SUBROUTINE_PATH")
            .map(|p| p.split(':').filter_map(|d| read_dir(d.trim())).collect())
            .unwrap_or_default();
        for remap in self.ini.all("RS274NGC", "REMAP") {
            let mut words = remap.split_whitespace();
            let code = words.next().unwrap_or("").to_ascii_uppercase();
            let Some(ngc) = words.find_map(|w| w.strip_prefix("ngc=")) else {
                continue;
            };
            match kinstype_of(ngc, &sub_dirs) {
                Ok(Some(k)) if k == tcp_type => controller.tcpm_on.push(code),
                Ok(Some(_)) => controller.tcpm_off.push(code),
                Ok(None) => {}
                Err(why) => {
                    self.warnings.push(format!(
                        "{origin}: REMAP {code}: {why}; taken as ending TCP (a run after it is not \
                         patched as TCP)"
                    ));
                    controller.tcpm_off.push(code);
                }
            }
        }
        let switched = !controller.tcpm_on.is_empty() || !controller.tcpm_off.is_empty();
        let starts_tcp = tcp_type == 0;
        if starts_tcp && !switched {
            controller.tcpm_always = true;
        } else if starts_tcp {
            self.warnings.push(format!(
                "{origin}: the kinematics start as TCP (switchkins type 0) and {} switch them: \
                 polepatch takes TCP as off until a program's first switching code",
                [controller.tcpm_on.clone(), controller.tcpm_off.clone()]
                    .concat()
                    .join(", ")
            ));
        } else if controller.tcpm_on.is_empty() {
            self.warnings.push(format!(
                "{origin}: the kinematics start as identity and no REMAP switches them to TCP \
                 (type {tcp_type}): every run is read as without TCP"
            ));
        }
        crate::machine_file::checked_controller(controller).map_err(|m| self.err(m))
    }

    /// The machine: the module's rotary axes and senses (`con`), checked as a pair, and its
    /// name (`[EMC] MACHINE`, else the file's).
    fn machine(
        mut self,
        module: Module,
        con: f64,
        tcy_ms: f64,
        axes: Axes,
        chain: Option<Chain>,
        controller: Controller,
    ) -> Result<Machine, MachineError> {
        let origin = self.origin;
        let ((pole_letter, pole_dir), (tilt_letter, tilt_dir)) = module.axes();
        let rotary = Rotaries {
            primary: RotaryAxis {
                letter: tilt_letter,
                carrier: module.carrier(),
                direction: tilt_dir,
            },
            c: RotaryAxis {
                letter: pole_letter,
                carrier: module.carrier(),
                direction: pole_dir,
            },
            tool_direction: [0.0, 0.0, 1.0],
        };
        // The senses (module docs): the trt modules' `con` on both axes; 5axiskins' B turns
        // the tool against the conventional direction (its note 10), its C with it.
        let (primary_sense, c_sense) = match module {
            Module::FiveAxis => (-1.0, 1.0),
            _ => (con, con),
        };
        if module == Module::FiveAxis {
            self.warnings.push(format!(
                "{origin}: 5axiskins moves the tool along its axis by W (5axiskins.c: the tool's \
                 tip is at X Y Z + W·o, o the tool axis from the tip towards the spindle; W < 0 \
                 drills): polepatch carries W words through, and where a block at W ≠ 0 has its B \
                 or C changed the tip moves by |W| times the change of orientation (radians)"
            ));
        }
        check_pair(
            &rotary,
            [&pole_letter.to_string(), &tilt_letter.to_string()],
        )
        .map_err(|m| self.err(m))?;
        let name = self
            .ini
            .get("EMC", "MACHINE")
            .map(str::to_string)
            .unwrap_or_else(|| {
                Path::new(origin)
                    .file_stem()
                    .map_or(origin.to_string(), |s| s.to_string_lossy().into_owned())
            });
        Ok(Machine {
            name,
            rotary,
            primary_sense,
            c_sense,
            primary_range_deg: axes.primary_range_deg,
            c_range_deg: axes.c_range_deg,
            tcy_s: tcy_ms / 1000.0,
            limits: axes.limits,
            chain,
            controller,
            warnings: self.warnings,
        })
    }
}

/// The joints of axis `letter`: its places in `coordinates`.
fn joints_of(coordinates: &str, letter: char) -> Vec<usize> {
    coordinates
        .chars()
        .enumerate()
        .filter(|&(_, c)| c == letter)
        .map(|(n, _)| n)
        .collect()
}

/// The files of LinuxCNC's own HAL library (`lib/hallib`), which `linuxcnc` finds there
/// when the configuration's folder has no file of that name (`HALLIB_PATH = .:HALLIB_DIR`).
/// They set no parameter of the kinematics modules polepatch reads.
const LINUXCNC_HALLIB: &[&str] = &[
    "axis_manualtoolchange.hal",
    "basic_sim.tcl",
    "check_xyz_constraints.hal",
    "core_servo.hal",
    "core_sim.hal",
    "core_sim9.hal",
    "core_stepper.hal",
    "gantrysim.hal",
    "hal_procs_lib.tcl",
    "halcheck.tcl",
    "hookup_moveoff.tcl",
    "lathe.hal",
    "lh_chart.tcl",
    "locking_indexer.hal",
    "moveoff_external.hal",
    "plasmac.tcl",
    "qtplasmac_comp.hal",
    "servo_sim.hal",
    "sim_lib.tcl",
    "sim_spindle_encoder.hal",
    "simulated-gantry-home.hal",
    "simulated-xyyz-home.hal",
    "simulated_home.hal",
    "simulated_limits.hal",
    "tripodsim.hal",
    "util_lib.tcl",
    "var_show.tcl",
    "wheeljogpins.tcl",
    "xhc-hb04.tcl",
];

/// One `[HAL] HALFILE` or `POSTGUI_HALFILE` entry read into `hal`, as LinuxCNC runs it: the
/// file name is the first word (the rest are arguments of a `.tcl` file); `LIB:NAME` and a
/// name of LinuxCNC's library not in the configuration's folder are LinuxCNC's own files
/// (passed over); a `.tcl` file is read by `haltcl.rs`, any other as halcmd lines. A file
/// that cannot be found or read is an error naming it: its commands could set the
/// kinematics' parameters, and LinuxCNC itself does not start without it.
fn hal_file(
    ini: &Ini,
    origin: &str,
    dir: Option<&Path>,
    e: &Entry,
    hal: &mut Hal,
) -> Result<(), MachineError> {
    let name = e.value.split_whitespace().next().unwrap_or("");
    if name.is_empty() || name.starts_with("LIB:") {
        return Ok(());
    }
    let refuse = |why: String| {
        invalid(
            origin,
            format!(
                "line {}: [HAL] {} = {}: {why}; its commands may set the kinematics' \
                 parameters, which are then not known",
                e.line, e.key, e.value
            ),
        )
    };
    let path = match dir {
        Some(d) => d.join(name),
        None if Path::new(name).is_absolute() => PathBuf::from(name),
        None => return Err(refuse("not read (no folder to find it in)".into())),
    };
    if !path.is_file() {
        if !name.contains('/') && LINUXCNC_HALLIB.contains(&name) {
            return Ok(());
        }
        return Err(refuse(format!(
            "{} is not there (nor is it one of LinuxCNC's library files)",
            path.display()
        )));
    }
    let text = read_bounded(&path).map_err(|e| refuse(format!("{}: {e}", path.display())))?;
    let shown = path.display().to_string();
    if Path::new(name)
        .extension()
        .is_some_and(|x| x.eq_ignore_ascii_case("tcl"))
    {
        crate::haltcl::read(&text, &shown, ini, hal);
    } else {
        text.lines().for_each(|l| hal.halcmd_line(l, ini));
    }
    Ok(())
}

/// A number as LinuxCNC's INI reader takes it.
fn number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// The `#<kinstype> = k` a remap subroutine sets: `Ok(None)` when it sets none (the code does
/// not switch kinematics), `Err` when the file cannot be found or read.
fn kinstype_of(ngc: &str, dirs: &[PathBuf]) -> Result<Option<i64>, String> {
    let file = format!("{ngc}.ngc");
    let Some(path) = dirs.iter().map(|d| d.join(&file)).find(|p| p.is_file()) else {
        return Err(format!(
            "its subroutine {file} is not in SUBROUTINE_PATH, so what it switches is unknown"
        ));
    };
    let text = read_bounded(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    for line in text.lines() {
        // Code before a ';' comment, without spaces, lower case.
        let code: String = line
            .split(';')
            .next()
            .unwrap_or("")
            .chars()
            .filter(|c| !c.is_whitespace())
            .collect::<String>()
            .to_ascii_lowercase();
        if let Some(value) = code.strip_prefix("#<kinstype>=") {
            return value.parse::<i64>().map(Some).map_err(|_| {
                format!(
                    "{}: #<kinstype> = {value} is not an integer",
                    path.display()
                )
            });
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Axis, forward};

    fn config(rel: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/linuxcnc")
            .join(rel)
    }

    fn load(rel: &str) -> Machine {
        Machine::load(config(rel).to_str().unwrap()).unwrap()
    }

    /// The HAL pins of the trt and tdr modules.
    #[derive(Clone, Copy, Default)]
    struct Pins {
        rot: [f64; 3],
        dx: f64,
        dy: f64,
        dz: f64,
        /// conventional-directions: +1 set, −1 not (trt only).
        con: f64,
    }

    /// `xyzacKinematicsInverse` of trtfuncs.c, transcribed (tool offset 0): world → joints.
    fn xyzac_inverse(pins: Pins, pos: [f64; 3], a_deg: f64, c_deg: f64) -> [f64; 3] {
        let [xr, yr, zr] = pins.rot;
        let (dy, dz, con) = (pins.dy, pins.dz, pins.con);
        let (sa, ca) = a_deg.to_radians().sin_cos();
        let (sc, cc) = c_deg.to_radians().sin_cos();
        let (x, y, z) = (pos[0], pos[1], pos[2]);
        [
            cc * (x - xr) + con * sc * (y - yr) + xr,
            -con * sc * ca * (x - xr) + cc * ca * (y - yr) + con * sa * (z - zr)
                - ca * dy
                - con * sa * dz
                + dy
                + yr,
            sc * sa * (x - xr) - con * cc * sa * (y - yr) + ca * (z - zr) + con * sa * dy - ca * dz
                + dz
                + zr,
        ]
    }

    /// `xyzbcKinematicsInverse` of trtfuncs.c, transcribed (tool offset 0).
    fn xyzbc_inverse(pins: Pins, pos: [f64; 3], b_deg: f64, c_deg: f64) -> [f64; 3] {
        let [xr, yr, zr] = pins.rot;
        let (dx, dz, con) = (pins.dx, pins.dz, pins.con);
        let (sb, cb) = b_deg.to_radians().sin_cos();
        let (sc, cc) = c_deg.to_radians().sin_cos();
        let dpx = -cb * dx + sb * dz + dx;
        let dpz = -sb * dx - cb * dz + dz;
        let (x, y, z) = (pos[0], pos[1], pos[2]);
        [
            cc * cb * (x - xr) + con * sc * cb * (y - yr) - con * sb * (z - zr) + dpx + xr,
            -con * sc * (x - xr) + cc * (y - yr) + yr,
            con * cc * sb * (x - xr) + sc * sb * (y - yr) + cb * (z - zr) + dpz + zr,
        ]
    }

    /// `kinematicsInverse` type 1 of xyzab_tdr_kins.comp, transcribed (tool offset 0).
    fn xyzab_tdr_inverse(pins: Pins, pos: [f64; 3], a_deg: f64, b_deg: f64) -> [f64; 3] {
        let [xr, yr, zr] = pins.rot;
        let (dx, dz) = (pins.dx, pins.dz);
        let (sa, ca) = a_deg.to_radians().sin_cos();
        let (sb, cb) = b_deg.to_radians().sin_cos();
        let qx = pos[0] - xr - dx;
        let qy = pos[1] - yr;
        let qz = pos[2] - zr - dz;
        [
            cb * qx + sa * sb * qy - ca * sb * qz + cb * dx - sb * dz + xr,
            ca * qy + sa * qz + yr,
            sb * qx - sa * cb * qy + ca * cb * qz + sb * dx + cb * dz + zr,
        ]
    }

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() <= tol)
    }

    /// Each module's conventions, from its source: moving the world point along
    /// `forward(P, C)` moves the joints along machine Z only (the tool is Z), and the chain
    /// gives the module's joints for every world point and angle.
    fn check_against_source(
        m: &Machine,
        inverse: impl Fn([f64; 3], f64, f64) -> [f64; 3],
        with_chain: bool,
    ) {
        let mut rng = crate::testutil::SplitMix64(21);
        for _ in 0..500 {
            let (p, c) = (rng.uniform(-90.0, 50.0), rng.uniform(-400.0, 400.0));
            let pos = [
                rng.uniform(-80.0, 80.0),
                rng.uniform(-80.0, 80.0),
                rng.uniform(-60.0, 60.0),
            ];
            let o = forward(m, p, c);
            let j0 = inverse(pos, p, c);
            let j1 = inverse(
                [
                    pos[0] + 10.0 * o[0],
                    pos[1] + 10.0 * o[1],
                    pos[2] + 10.0 * o[2],
                ],
                p,
                c,
            );
            let d = [j1[0] - j0[0], j1[1] - j0[1], j1[2] - j0[2]];
            assert!(
                close(d, [0.0, 0.0, 10.0], 1e-9),
                "{}: {d:?} at P={p} C={c}",
                m.name
            );
            if with_chain {
                let chain = m.chain.expect("a chain");
                let datum = [3.0, -7.0, 12.0];
                // The part point x_W is the world point pos − datum (G54 = datum).
                let x =
                    chain.program_xyz(m, datum, p, c, [pos[0] - 3.0, pos[1] + 7.0, pos[2] - 12.0]);
                let x_m = [x[0] + 3.0, x[1] - 7.0, x[2] + 12.0];
                assert!(close(x_m, j0, 1e-9), "{}: {x_m:?} vs {j0:?}", m.name);
            }
        }
    }

    #[test]
    fn xyzac_trt_follows_trtfuncs_and_the_ini() {
        let m = load("xyzac-trt/xyzac-trt.ini");
        assert_eq!(m.name, "test-xyzac-trt (switchkins)");
        assert_eq!((m.primary_letter(), m.c_letter()), ('A', 'C'));
        // conventional-directions 0: j = +cos C · sin A (C17's senses), the opposite of the
        // UCP710's j = −cos C · sin A.
        assert_eq!((m.primary_sense, m.c_sense), (-1.0, -1.0));
        let (a, c) = (25f64.to_radians(), 40f64.to_radians());
        let o = forward(&m, 25.0, 40.0);
        assert!(close(
            o,
            [c.sin() * a.sin(), c.cos() * a.sin(), a.cos()],
            1e-15
        ));
        let ucp = Machine::builtin("mikron-ucp710").unwrap();
        assert!((forward(&ucp, 25.0, 40.0)[1] + c.cos() * a.sin()).abs() < 1e-15);
        let pins = Pins {
            rot: [5.0, -3.0, -40.0],
            dx: 0.0,
            dy: 20.0,
            dz: 10.0,
            con: -1.0,
        };
        check_against_source(&m, |pos, p, c| xyzac_inverse(pins, pos, p, c), true);
        // conventional-directions 1: G16's senses, and still the source's joints.
        let text = std::fs::read_to_string(config("xyzac-trt/xyzac-trt.ini"))
            .unwrap()
            .replace("conventional-directions 0", "conventional-directions 1");
        let dir = config("xyzac-trt");
        let m1 = machine_from_ini_text(&text, "conv.ini", Some(&dir)).unwrap();
        assert_eq!((m1.primary_sense, m1.c_sense), (1.0, 1.0));
        let pins1 = Pins { con: 1.0, ..pins };
        check_against_source(&m1, |pos, p, c| xyzac_inverse(pins1, pos, p, c), true);
    }

    #[test]
    fn xyzac_trt_ini_has_the_limits_of_the_equivalent_toml() {
        let ini = load("xyzac-trt/xyzac-trt.ini");
        let toml = Machine::load(config("xyzac-trt/xyzac-trt.toml").to_str().unwrap()).unwrap();
        for axis in Axis::ALL {
            let (a, b) = (ini.limit(axis), toml.limit(axis));
            for (x, y, what) in [(a.v, b.v, "v"), (a.a, b.a, "a"), (a.j, b.j, "j")] {
                assert!(
                    (x - y).abs() <= 1e-12 * y,
                    "{axis:?} {what}: INI {x} TOML {y}"
                );
            }
        }
        // X's joint is slower than its axis: the joint counts (18 mm/s); Z's joint jerk.
        assert!((ini.limit(Axis::X).v - 18.0).abs() < 1e-12);
        assert_eq!(ini.limit(Axis::Z).j, 5000.0);
        assert_eq!(ini.primary_range_deg, toml.primary_range_deg);
        assert_eq!(ini.primary_range_deg, (-90.0, 50.0));
        assert_eq!(ini.c_range_deg, toml.c_range_deg);
        assert_eq!(ini.tcy_s, toml.tcy_s);
        assert_eq!(ini.rotary, toml.rotary);
        assert_eq!(
            (ini.primary_sense, ini.c_sense),
            (toml.primary_sense, toml.c_sense)
        );
        assert_eq!(ini.chain, toml.chain);
        assert_eq!(ini.controller, toml.controller);
        // The one assumption said: the jerk of the axes without MAX_JERK.
        assert_eq!(ini.warnings.len(), 1, "{:?}", ini.warnings);
        assert!(
            ini.warnings[0].contains("no MAX_JERK for X Y A C")
                && ini.warnings[0].contains("MAX_ACCELERATION / SERVO_PERIOD (1 ms)"),
            "{:?}",
            ini.warnings
        );
    }

    #[test]
    fn switchkins_remaps_are_the_tcpm_codes() {
        let m = load("xyzac-trt/xyzac-trt.ini");
        // sparm=identityfirst: type 1 is the TCP kinematics. M6's remap switches nothing.
        assert_eq!(m.controller.tcpm_on, ["M428"]);
        assert_eq!(m.controller.tcpm_off, ["M429", "M430"]);
        assert!(!m.controller.tcpm_always);
        // Without sparm, type 0 is TCP: M429 (type 0) switches it on, and the kinematics
        // start as TCP (said in a warning).
        let text = std::fs::read_to_string(config("xyzac-trt/xyzac-trt.ini"))
            .unwrap()
            .replace(" sparm=identityfirst", "");
        let dir = config("xyzac-trt");
        let m = machine_from_ini_text(&text, "t.ini", Some(&dir)).unwrap();
        assert_eq!(m.controller.tcpm_on, ["M429"]);
        assert_eq!(m.controller.tcpm_off, ["M428", "M430"]);
        assert!(
            m.warnings.iter().any(|w| w.contains("start as TCP")),
            "{:?}",
            m.warnings
        );
        // Not switched at all: always TCP.
        let text: String = text
            .lines()
            .filter(|l| !l.contains("REMAP"))
            .map(|l| format!("{l}\n"))
            .collect();
        let m = machine_from_ini_text(&text, "t.ini", Some(&dir)).unwrap();
        assert!(m.controller.tcpm_always);
        assert!(m.controller.tcpm_on.is_empty() && m.controller.tcpm_off.is_empty());
        // A remap whose subroutine cannot be found: taken as ending TCP, with a warning.
        let text = std::fs::read_to_string(config("xyzac-trt/xyzac-trt.ini"))
            .unwrap()
            .replace("ngc=430remap", "ngc=431remap");
        let m = machine_from_ini_text(&text, "t.ini", Some(&dir)).unwrap();
        assert_eq!(m.controller.tcpm_off, ["M429", "M430"]);
        assert!(
            m.warnings
                .iter()
                .any(|w| w.contains("REMAP M430") && w.contains("431remap.ngc")),
            "{:?}",
            m.warnings
        );
    }

    #[test]
    fn xyzbc_trt_follows_trtfuncs_with_pins_from_a_hal_file() {
        let m = load("xyzbc-trt/xyzbc-trt.ini");
        assert_eq!((m.primary_letter(), m.c_letter()), ('B', 'C'));
        assert_eq!((m.primary_sense, m.c_sense), (1.0, 1.0));
        // Not switched: always TCP.
        assert!(m.controller.tcpm_always);
        // Inch: 2 in/s = 50.8 mm/s; the rot point and offsets in mm; half a ms servo.
        assert!((m.limit(Axis::X).v - 50.8).abs() < 1e-12);
        assert!((m.limit(Axis::Z).j - 200.0 * 25.4).abs() < 1e-9);
        assert_eq!(m.limit(Axis::C).j, 20_000.0);
        assert!((m.limit(Axis::Primary).j - 900.0 / 5e-4).abs() < 1e-6);
        assert_eq!(m.tcy_s, 5e-4);
        assert_eq!(m.c_range_deg, None, "WRAPPED_ROTARY");
        assert_eq!(m.primary_range_deg, (-120.0, 120.0));
        let mm = |v: f64| v * 25.4;
        let pins = Pins {
            rot: [mm(1.5), mm(-0.5), mm(-2.0)],
            dx: mm(-0.8),
            dy: 0.0,
            dz: mm(-0.6),
            con: 1.0,
        };
        check_against_source(&m, |pos, p, c| xyzbc_inverse(pins, pos, p, c), true);
        // A HAL file that is not there is refused by name (issue 39: it could set
        // conventional-directions; LinuxCNC does not start without it either).
        let dir = config("xyzbc-trt");
        let text = std::fs::read_to_string(dir.join("xyzbc-trt.ini")).unwrap();
        for (from, to) in [
            ("= xyzbc-postgui.hal", "= missing_postgui.hal"),
            ("= xyzbc-pivot.hal", "= pivot.hal"),
        ] {
            let err = machine_from_ini_text(&text.replace(from, to), "t.ini", Some(&dir))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains(&format!("HALFILE {to}"))
                    && err.contains("is not there")
                    && err.contains("may set the kinematics' parameters"),
                "{err}"
            );
        }
        // conventional-directions 0 with offsets: the source turns its offsets the other way
        // than the table (dpx, dpz carry no `con`), which no pair of fixed axes does: the
        // orientation is still the source's, but no chain is taken, with a warning.
        let dir = config("xyzbc-trt");
        let hal = std::fs::read_to_string(dir.join("xyzbc-pivot.hal"))
            .unwrap()
            .replace("conventional-directions 1", "conventional-directions 0");
        let tmp = std::env::temp_dir().join(format!("polepatch-lcnc-{}", std::process::id()));
        std::fs::create_dir_all(&tmp).unwrap();
        std::fs::write(tmp.join("xyzbc-pivot.hal"), hal).unwrap();
        std::fs::copy(dir.join("xyzbc-postgui.hal"), tmp.join("xyzbc-postgui.hal")).unwrap();
        let text = std::fs::read_to_string(dir.join("xyzbc-trt.ini")).unwrap();
        let m0 = machine_from_ini_text(&text, "t.ini", Some(&tmp)).unwrap();
        assert_eq!((m0.primary_sense, m0.c_sense), (-1.0, -1.0));
        assert_eq!(m0.chain, None);
        assert!(
            m0.warnings.iter().any(|w| w.contains("dpx/dpz")),
            "{:?}",
            m0.warnings
        );
        let pins0 = Pins { con: -1.0, ..pins };
        check_against_source(&m0, |pos, p, c| xyzbc_inverse(pins0, pos, p, c), false);
        // Without offsets it is a chain again, and the source's joints.
        let text0 = text
            .replace("X_OFFSET = -0.8", "X_OFFSET = 0")
            .replace("Z_OFFSET = -0.6", "Z_OFFSET = 0");
        let m0 = machine_from_ini_text(&text0, "t.ini", Some(&tmp)).unwrap();
        let pins0 = Pins {
            dx: 0.0,
            dz: 0.0,
            ..pins0
        };
        check_against_source(&m0, |pos, p, c| xyzbc_inverse(pins0, pos, p, c), true);
        std::fs::remove_dir_all(&tmp).unwrap();
    }

    #[test]
    fn xyzab_tdr_has_its_pole_along_x() {
        let m = load("xyzab-tdr/xyzab-tdr.ini");
        // The A table (the pole axis, next to the part) along X, carried by B along Y.
        assert_eq!((m.primary_letter(), m.c_letter()), ('B', 'A'));
        assert_eq!(m.pole_direction(), [1.0, 0.0, 0.0]);
        // Its source's tool axis: (sin B, −sin A cos B, cos A cos B).
        let (a, b) = (30f64.to_radians(), 20f64.to_radians());
        let o = forward(&m, 20.0, 30.0);
        assert!(close(
            o,
            [b.sin(), -a.sin() * b.cos(), a.cos() * b.cos()],
            1e-15
        ));
        // The pole is B = ±90°: there A cannot change the tool axis.
        let pole = m.pole_p_deg().unwrap();
        assert!((pole.abs() - 90.0).abs() < 1e-12, "{pole}");
        assert!(close(
            forward(&m, 90.0, 17.0),
            forward(&m, 90.0, -140.0),
            1e-15
        ));
        assert!((m.pole_tilt_deg(80.0) - 10.0).abs() < 1e-12);
        let pins = Pins {
            rot: [-50.0, -50.0, -100.0],
            dx: -20.0,
            dy: 0.0,
            dz: -10.0,
            con: 1.0,
        };
        check_against_source(&m, |pos, p, c| xyzab_tdr_inverse(pins, pos, c, p), true);
        assert_eq!(m.controller.tcpm_on, ["M428"]);
        assert_eq!(m.controller.tcpm_off, ["M429"]);
        assert_eq!(m.c_range_deg, Some((-3600.0, 3600.0)));
        assert_eq!(m.primary_range_deg, (-180.0, 180.0));
        assert_eq!(m.limit(Axis::C).v, 30.0);
    }

    /// A folder for one test: the fixture folder `rel` copied, then `edits` (file name,
    /// text) written over it.
    fn edited_config(rel: &str, tag: &str, edits: &[(&str, &str)]) -> PathBuf {
        let tmp = std::env::temp_dir().join(format!("polepatch-lcnc-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&tmp);
        std::fs::create_dir_all(&tmp).unwrap();
        for f in std::fs::read_dir(config(rel)).unwrap() {
            let f = f.unwrap().path();
            if f.is_file() {
                std::fs::copy(&f, tmp.join(f.file_name().unwrap())).unwrap();
            }
        }
        for (name, text) in edits {
            std::fs::write(tmp.join(name), text).unwrap();
        }
        tmp
    }

    /// Issue 39, class 5: `HALFILE = kins.tcl` holding `setp
    /// xyzac-trt-kins.conventional-directions 1` was passed over, the default senses taken,
    /// and the tip rewrite mirrored. It is read as the same lines in `[HAL] HALCMD` are.
    #[test]
    fn a_tcl_hal_file_is_read_as_halcmd_lines_are() {
        let m = load("xyzac-trt-tcl/xyzac-trt-tcl.ini");
        assert_eq!((m.primary_sense, m.c_sense), (1.0, 1.0));
        let ucp = Machine::builtin("mikron-ucp710").unwrap();
        for (a, c) in [(25.0, 40.0), (-3.0, 200.0)] {
            assert_eq!(forward(&m, a, c), forward(&ucp, a, c));
        }
        let chain = m.chain.unwrap();
        assert_eq!(chain.c_axis_point_mm, [0.0, -5.0, -60.0]);
        assert_eq!(chain.primary_axis_point_mm, [0.0, 10.0, -35.0]);
        // The same parameters as halcmd lines: the same machine.
        let dir = config("xyzac-trt-tcl");
        let text = std::fs::read_to_string(dir.join("xyzac-trt-tcl.ini")).unwrap();
        let halcmd = text.replace(
            "HALFILE = kins.tcl\n",
            "HALCMD = setp xyzac-trt-kins.y-rot-point -5\n\
             HALCMD = setp xyzac-trt-kins.z-rot-point -60\n\
             HALCMD = setp xyzac-trt-kins.y-offset [KINS]Y_OFFSET\n\
             HALCMD = setp xyzac-trt-kins.z-offset [KINS]Z_OFFSET\n\
             HALCMD = setp xyzac-trt-kins.conventional-directions 1\n",
        );
        assert_ne!(halcmd, text);
        let origin = dir.join("xyzac-trt-tcl.ini").display().to_string();
        let h = machine_from_ini_text(&halcmd, &origin, None).unwrap();
        assert_eq!(h, m);
        let pins = Pins {
            rot: [0.0, -5.0, -60.0],
            dx: 0.0,
            dy: 15.0,
            dz: 25.0,
            con: 1.0,
        };
        check_against_source(&m, |pos, p, c| xyzac_inverse(pins, pos, p, c), true);
    }

    /// A form of a haltcl file polepatch does not evaluate: refused, naming the file, line,
    /// column and the form, where the senses depend on it; where only the chain does, no
    /// chain, said. Never a default in silence.
    #[test]
    fn a_tcl_form_that_is_not_read_is_refused_where_it_matters() {
        let kins = std::fs::read_to_string(config("xyzac-trt-tcl/kins.tcl")).unwrap();
        let ini = config("xyzac-trt-tcl/xyzac-trt-tcl.ini");
        let ini_text = std::fs::read_to_string(&ini).unwrap();
        let load_with = |tag: &str, tcl: &str| {
            let dir = edited_config("xyzac-trt-tcl", tag, &[("kins.tcl", tcl)]);
            let r = machine_from_ini_text(&ini_text, "t.ini", Some(&dir));
            std::fs::remove_dir_all(&dir).unwrap();
            r
        };
        let line = "setp xyzac-trt-kins.conventional-directions 1";
        assert!(kins.contains(line));
        let refused: &[(&str, &str)] = &[
            (
                "foreach p {conventional-directions} {\n  setp $kins.$p 1\n}",
                "kins.tcl:14:1: a Tcl loop (foreach)",
            ),
            (
                "setp xyzac-trt-kins.conventional-directions [expr {1}]",
                "kins.tcl:14:45: '[expr {1}]', a Tcl command substitution",
            ),
            (
                "setp xyzac-trt-kins.conventional-directions $on",
                "kins.tcl:14:45: '$on', a Tcl variable",
            ),
            (
                "if {$::KINS(JOINTS) == 5} {setp xyzac-trt-kins.conventional-directions 1}",
                "kins.tcl:14:1: a Tcl condition (if)",
            ),
            (
                "setp $kins.conventional-directions 1",
                "kins.tcl:14:6: setp of '$kins.conventional-directions', a Tcl variable",
            ),
        ];
        for (tag, (form, want)) in refused.iter().enumerate() {
            let err = load_with(&format!("r{tag}"), &kins.replace(line, form))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("t.ini")
                    && err.contains(want)
                    && err.contains("the senses of the rotary axes depend on it"),
                "{form}: {err}"
            );
        }
        // An expression on a pivot pin: the senses are known, the chain is not.
        let m = load_with(
            "pivot",
            &kins.replace(
                "setp xyzac-trt-kins.z-rot-point -60",
                "setp xyzac-trt-kins.z-rot-point -50-10",
            ),
        )
        .unwrap();
        assert_eq!((m.primary_sense, m.c_sense), (1.0, 1.0));
        assert_eq!(m.chain, None);
        assert!(
            m.warnings.iter().any(|w| w.contains("no kinematic chain")
                && w.contains("kins.tcl:7:33: '-50-10' is a Tcl expression")),
            "{:?}",
            m.warnings
        );
    }

    /// `fiveaxis_KinematicsForward` of 5axiskins.c, transcribed: joints (x, y, z, B, C, W)
    /// → the tool position, `s2r(r, t, p) = r·(sin p cos t, sin p sin t, cos p)`.
    fn five_axis_forward(pivot_length: f64, j: [f64; 6]) -> [f64; 3] {
        let s2r = |r: f64, t_deg: f64, p_deg: f64| {
            let (t, p) = (t_deg.to_radians(), p_deg.to_radians());
            [r * p.sin() * t.cos(), r * p.sin() * t.sin(), r * p.cos()]
        };
        let [x, y, z, b, c, w] = j;
        let r = s2r(pivot_length + w, c, 180.0 - b);
        [x + r[0], y + r[1], z + pivot_length + r[2]]
    }

    /// Issue 42 item 3: LinuxCNC's bridge mill, `5axiskins`: a head-head C-B machine.
    #[test]
    fn five_axis_bridge_follows_5axiskins() {
        let m = load("5axis-bridge/5axis-bridge.ini");
        assert_eq!(m.name, "test-5axis-bridge (xyzbcw)");
        assert_eq!((m.primary_letter(), m.c_letter()), ('B', 'C'));
        assert_eq!(m.layout(), crate::Layout::HeadHead);
        assert_eq!((m.primary_sense, m.c_sense), (-1.0, 1.0));
        assert!(m.standard_form().is_some());
        assert!(m.controller.tcpm_always);
        // Y's second joint (JOINT_6, coordinates=xyzbcwy) is the slower.
        assert_eq!(m.limit(Axis::Y).v, 140.0);
        assert_eq!(m.limit(Axis::Y).a, 550.0);
        assert_eq!(m.limit(Axis::Primary).v, 45.0);
        assert_eq!(m.limit(Axis::C).a, 240.0);
        assert_eq!(m.primary_range_deg, (-110.0, 110.0));
        assert_eq!(m.c_range_deg, Some((-36000.0, 36000.0)));
        let l = 180.0;
        assert_eq!(
            m.chain,
            Some(Chain {
                c_axis_point_mm: [0.0, 0.0, l],
                primary_axis_point_mm: [0.0, 0.0, l],
            })
        );
        assert!(
            m.warnings
                .iter()
                .any(|w| w.contains("moves the tool along its axis by W")),
            "{:?}",
            m.warnings
        );
        let chain = m.chain.unwrap();
        let mut rng = crate::testutil::SplitMix64(42);
        for _ in 0..500 {
            let (b, c) = (rng.uniform(-110.0, 110.0), rng.uniform(-400.0, 400.0));
            let w = rng.uniform(-60.0, 60.0);
            let x = [
                rng.uniform(-300.0, 300.0),
                rng.uniform(-300.0, 300.0),
                rng.uniform(-300.0, 50.0),
            ];
            // The tool axis: from the tip (W = 0) to the pivot, L above the joints.
            let tip = five_axis_forward(l, [x[0], x[1], x[2], b, c, 0.0]);
            let pivot = [x[0], x[1], x[2] + l];
            let o_src = std::array::from_fn(|k| (pivot[k] - tip[k]) / l);
            let o = forward(&m, b, c);
            assert!(close(o, o_src, 1e-12), "B={b} C={c}: {o:?} {o_src:?}");
            // W: the position the module gives is the tool's tip moved by −W·o, so the
            // tip is X Y Z + W·o (what the warning says).
            let pos_w = five_axis_forward(l, [x[0], x[1], x[2], b, c, w]);
            let moved = std::array::from_fn(|k| pos_w[k] + w * o[k]);
            assert!(close(moved, tip, 1e-9), "W={w}: {moved:?} {tip:?}");
            // Without TCP (identity kinematics) the program's X Y Z are the joints: the
            // chain puts the tip where the module does.
            let datum = [12.0, -4.0, 30.0];
            let x_w = std::array::from_fn(|k| tip[k] - datum[k]);
            let p = chain.program_xyz(&m, datum, b, c, x_w);
            let joints = std::array::from_fn(|k| p[k] + datum[k]);
            assert!(close(joints, x, 1e-9), "{joints:?} {x:?}");
        }
        // pivot-length never set: the module's 250; driven at run time as in LinuxCNC's
        // sample (the GUI's length plus the tool's): no chain, said; the tool axis the same.
        let hal = std::fs::read_to_string(config("5axis-bridge/5axis-bridge.hal")).unwrap();
        let set = "setp 5axiskins.pivot-length [KINS]PIVOT_LENGTH\n";
        assert!(hal.contains(set));
        let ini = std::fs::read_to_string(config("5axis-bridge/5axis-bridge.ini")).unwrap();
        let with = |tag: &str, hal: &str| {
            let dir = edited_config("5axis-bridge", tag, &[("5axis-bridge.hal", hal)]);
            let m = machine_from_ini_text(&ini, "b.ini", Some(&dir)).unwrap();
            std::fs::remove_dir_all(&dir).unwrap();
            m
        };
        let m250 = with("default", &hal.replace(set, ""));
        assert_eq!(m250.chain.unwrap().c_axis_point_mm, [0.0, 0.0, 250.0]);
        let run_time = hal.replace(
            set,
            "loadrt sum2 names=pivotsum\naddf pivotsum servo-thread\n\
             net :gui-pivot-len <= 5axisgui.pivot_len => pivotsum.in0\n\
             net :tool-len <= motion.tooloffset.z => pivotsum.in1\n\
             net :pivot-len <= pivotsum.out => 5axiskins.pivot-length\n",
        );
        let mrt = with("runtime", &run_time);
        assert_eq!(mrt.chain, None);
        assert!(
            mrt.warnings
                .iter()
                .any(|w| w.contains("5axiskins.pivot-length is netted to :pivot-len")),
            "{:?}",
            mrt.warnings
        );
        assert_eq!(forward(&mrt, 30.0, 70.0), forward(&m, 30.0, 70.0));
        // sparm=identityfirst: type 1 is 5axiskins; without remaps it never switches to it.
        let ident = ini.replace(
            "coordinates=xyzbcwy",
            "coordinates=xyzbcwy sparm=identityfirst",
        );
        let mi = machine_from_ini_text(&ident, "b.ini", Some(&config("5axis-bridge"))).unwrap();
        assert!(!mi.controller.tcpm_always);
        assert!(mi.warnings.iter().any(|w| w.contains("start as identity")));
    }

    #[test]
    fn bad_inis_are_refused_by_name() {
        let good = std::fs::read_to_string(config("xyzab-tdr/xyzab-tdr.ini")).unwrap();
        let cases: &[(&str, &str, &str)] = &[
            (
                "KINEMATICS = xyzab_tdr_kins",
                "KINEMATICS = trivkins coordinates=xyzab",
                "[KINS] KINEMATICS = trivkins: polepatch reads the 5-axis modules",
            ),
            ("KINEMATICS = xyzab_tdr_kins", "", "no [KINS] KINEMATICS"),
            (
                "    MAX_VELOCITY =   20\nMAX_ACCELERATION =  300\n\n[AXIS_Y]",
                "MAX_ACCELERATION =  300\n\n[AXIS_Y]",
                "no MAX_VELOCITY for axis X in [AXIS_X] or [JOINT_0]",
            ),
            (
                "    MAX_VELOCITY =    30\nMAX_ACCELERATION =   300\n\n[AXIS_B]",
                "    MAX_VELOCITY =    3O\nMAX_ACCELERATION =   300\n\n[AXIS_B]",
                "[AXIS_A] MAX_VELOCITY = 3O: not a number",
            ),
            (
                "       MIN_LIMIT =   -180\n",
                "",
                "axis B tilts the tool and needs a travel",
            ),
            (
                "LINEAR_UNITS = mm",
                "LINEAR_UNITS = furlong",
                "not mm or inch",
            ),
            (
                "[EMCMOT]",
                "[EMCMOT\n",
                "a section header must end with ']'",
            ),
            (
                "SERVO_PERIOD = 1000000",
                "SERVO_PERIOD = 1000",
                "SERVO_PERIOD (as ms) must be a cycle time from 0.1 to 100 ms, got 0.001",
            ),
            (
                "    MAX_VELOCITY =   20\nMAX_ACCELERATION =  300\n\n[AXIS_Y]",
                "    MAX_VELOCITY =   1e-9\nMAX_ACCELERATION =  300\n\n[AXIS_Y]",
                "is outside the accepted range",
            ),
        ];
        for (from, to, want) in cases {
            assert!(good.contains(from), "edit {from:?} does not apply");
            let text = good.replacen(from, to, 1);
            let err = machine_from_ini_text(&text, "bad.ini", None)
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("bad.ini") && err.contains(want),
                "{to:?}: {err}"
            );
        }
        // A signal with no value and no other pin is HAL's 0 (a chain); one a GUI slider
        // drives at run time gives no chain, said.
        let text = good.replace("HALCMD = sets :x-offset     -20\n", "");
        let m = machine_from_ini_text(&text, "t.ini", None).unwrap();
        assert_eq!(m.chain.unwrap().c_axis_point_mm, [-50.0, -50.0, -110.0]);
        let text = good.replace(
            "HALCMD = sets :x-offset     -20\n",
            "HALCMD = net :x-offset => pyvcp.x-offset-f\n",
        );
        let m = machine_from_ini_text(&text, "t.ini", None).unwrap();
        assert_eq!(m.chain, None);
        assert!(
            m.warnings
                .iter()
                .any(|w| w.contains("xyzab_tdr_kins.x-offset is netted to :x-offset")),
            "{:?}",
            m.warnings
        );
        // Without a directory the remap subroutines are not read: said, taken as ending TCP.
        assert!(m.controller.tcpm_on.is_empty());
        assert!(
            m.warnings.iter().any(|w| w.contains("REMAP M428")),
            "{:?}",
            m.warnings
        );
    }

    #[test]
    fn ini_syntax_as_linuxcnc_reads_it() {
        let ini = Ini::parse(
            "# comment\n; other comment\n[A]\nK = 1\n  K = 2\nL=x = y\n[B]\nK = 3\n",
            "t",
        )
        .unwrap();
        assert_eq!(ini.get("A", "K"), Some("1"));
        assert_eq!(ini.all("A", "K").collect::<Vec<_>>(), ["1", "2"]);
        assert_eq!(ini.get("A", "L"), Some("x = y"));
        assert_eq!(ini.get("B", "K"), Some("3"));
        assert_eq!(ini.get("C", "K"), None);
        assert_eq!(ini.includes, Vec::<usize>::new());
        let with = Ini::parse("[A]\n#INCLUDE joints.inc\nK = 1\n", "t").unwrap();
        assert_eq!(with.includes, [2]);
        let err = Ini::parse("[A]\nnonsense\n", "t.ini")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("line 2") && err.contains("KEY = VALUE"),
            "{err}"
        );
    }
}
