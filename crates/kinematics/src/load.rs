//! Loading a machine: a built-in name, a TOML file in either form (`machine_file.rs`), or a
//! LinuxCNC INI file ([`crate::linuxcnc`]).

use crate::machine::{Machine, MachineError, read_bounded};

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
    /// Two forms (every field required unless marked optional; unknown fields are errors).
    /// **The chain form**, any layout — the two rotary axes from the part to the tool:
    ///
    /// ```toml
    /// name = "head-table-bc"
    /// description = "free text"        # optional, not kept
    /// tcy_ms = 1.0                     # optional, interpolation cycle time, default 1 ms
    /// tool_direction = [0.0, 0.0, 1.0] # optional, tip → spindle at zero, default [0, 0, 1]
    /// [x]                              # also [y] and [z]
    /// v_m_min = 30.0                   # max velocity, m/min
    /// a_m_s2 = 2.5                     # max acceleration, m/s²
    /// j_m_s3 = 5.0                     # max jerk, m/s³
    /// [[rotary]]                       # first: the axis next to the part (the pole axis)
    /// letter = "C"                     # its NC address: A B C, or E U V W
    /// moves = "table"                  # "table" or "head"
    /// direction = [0.0, 0.0, 1.0]      # at zero, machine frame (any length; 45° is fine)
    /// sense = 1                        # optional, default +1: ISO 841 (crate::rotary)
    /// # range_deg = [-360.0, 360.0]    # optional for this axis; omitted = endless
    /// v_rpm = 20.0                     # max velocity, rpm
    /// a_rev_s2 = 0.83                  # max acceleration, rev/s²
    /// j_rev_s3 = 50.0                  # max jerk, rev/s³
    /// # point_mm = [0.0, 0.0, 0.0]     # optional (with the other's): a point on the axis
    /// [[rotary]]                       # second: the axis next to the tool
    /// letter = "B"
    /// moves = "head"
    /// direction = [0.0, 1.0, 0.0]
    /// range_deg = [-110.0, 110.0]      # required for this axis
    /// v_rpm = 15.0
    /// a_rev_s2 = 0.83
    /// j_rev_s3 = 5.0
    /// [controller]                     # optional: the machine's own TCPM codes
    /// tcpm_on = ["M428"]               # added to the dialect's (M128, TRAORI, G43.4, …)
    /// tcpm_off = ["M429", "M430"]
    /// tcpm_always = false              # true: kinematics always TCP
    /// ```
    ///
    /// **The table-table form** (today's files, read as the chain C table `[0, 0, 1]` then
    /// A table `[1, 0, 0]` or B table `[0, 1, 0]`, tool `[0, 0, 1]`):
    ///
    /// ```toml
    /// [primary]
    /// letter = "A"                     # "A" tilts about X, "B" about Y
    /// sense = 1                        # +1 or -1, sp in o = Rz(sc·C)·Rp(sp·P)·ẑ
    /// range_deg = [-100.0, 120.0]      # travel, degrees
    /// v_rpm = 15.0
    /// a_rev_s2 = 0.83
    /// j_rev_s3 = 5.0
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
    /// auxiliary_axes = ["A"]           # optional: letters carried as they are (an
    ///                                  # extruder), not the machine's axes
    /// ```
    ///
    /// Every limit must lie within [`LIMIT_MIN`, `LIMIT_MAX`] = 0.001 to 10⁶ in the file's
    /// units, `tcy_ms` within [`TCY_MS_RANGE`] = 0.1 to 100 ms, a `range_deg` must have
    /// exactly two values and a direction or point exactly three (an error names the
    /// field). The two rotary axes must have different letters, the table axes come first,
    /// and the second axis may lie neither along the first nor along the tool.
    ///
    /// Limits are converted once to internal units: m/min → mm/s ×1000/60, m/s² → mm/s²
    /// ×1000, m/s³ → mm/s³ ×1000, rpm → °/s ×6, rev/s² → °/s² ×360, rev/s³ → °/s³ ×360.
    ///
    /// [`TCY_MS_RANGE`]: crate::machine::TCY_MS_RANGE
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Machine, MachineError> {
        let invalid = |message: String| MachineError::Invalid {
            path: origin.to_string(),
            message,
        };
        let file: crate::machine_file::MachineFile =
            toml::from_str(text).map_err(|e| invalid(e.to_string()))?;
        file.into_machine().map_err(invalid)
    }
    /// A built-in name, a path to a TOML file, or a path to a LinuxCNC INI file (a name
    /// ending in `.ini`, any case: [`crate::linuxcnc`]).
    ///
    /// Built-in names win over files of the same name in the working directory. At most
    /// [`MAX_MACHINE_FILE_BYTES`] are read (a device such as `/dev/zero` or a FIFO is read
    /// up to that bound, never without limit); a longer file is an error.
    ///
    /// [`MAX_MACHINE_FILE_BYTES`]: crate::machine::MAX_MACHINE_FILE_BYTES
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
    /// it: at most [`MAX_MACHINE_FILE_BYTES`]; a LinuxCNC INI when the name ends in `.ini`
    /// (any case), else TOML.
    ///
    /// [`MAX_MACHINE_FILE_BYTES`]: crate::machine::MAX_MACHINE_FILE_BYTES
    pub fn from_file(path: &std::path::Path) -> Result<Machine, MachineError> {
        let name = path.display().to_string();
        let text = read_bounded(path).map_err(|cause| MachineError::Io {
            path: name.clone(),
            cause,
        })?;
        let is_ini = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ini"));
        if is_ini {
            crate::linuxcnc::machine_from_ini(&text, path)
        } else {
            Machine::from_toml_str(&text, &name)
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::{Axis, MAX_MACHINE_FILE_BYTES, PrimaryAxis};

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
        assert_eq!(m.standard_form().unwrap().primary, PrimaryAxis::A);
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
        assert_eq!(m.standard_form().unwrap().primary, PrimaryAxis::B);
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
        assert_eq!(m.standard_form().unwrap().primary, PrimaryAxis::B);
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
