//! The options of every entry point, read once at the door.
//!
//! [`ReadOptions`] is how a program is read — its name in messages, the feed of runs with
//! none in force, the work offset of a machine with a kinematic chain, the length unit of a
//! program that states none — and sits, the same struct, inside the options of every entry
//! that reads a program ([`PatchOptions`], [`AnalyzeOptions`], [`SimulateOptions`]; `verify`
//! and `post` take [`PatchOptions`]). The CLI builds it once from one group of flags that
//! every subcommand flattens; the C ABI and the Python package fill it from their own
//! arguments. What each entry adds beside it are the user's settings of that job; facts of
//! a file (its decimals) or of a run (whether its end is free) are not options and are
//! found while reading.
//!
//! Each options struct has a `check` that every entry calls before reading a byte: a value
//! out of range is an [`Error::Options`] naming the field, its unit and the value.

use crate::error::{Error, OptionError};
use crate::{machine_frame, patcher, tool};
use polepatch_patcher::AnalysisOptions;
use polepatch_simulate::SimOptions;

/// How a program is read: the part of every entry's options that is about the input.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Name of the input in messages and in the report (`file`). Default `"input"`.
    pub name: String,
    /// Feed, mm/min, for runs with no F in force. Default `None` (such runs are reported
    /// and left as they are).
    pub feed_fallback_mm_min: Option<f64>,
    /// Work offset (machine coordinates of the program's zero, mm) for a machine with a
    /// kinematic chain. Default `None`: the program's own datum (Heidenhain `G54 X Y Z`).
    pub work_offset_mm: Option<[f64; 3]>,
    /// Read a program that states no length units (no G20/G21, G70/G71, G700/G710,
    /// `%NAME G71`, `BEGIN PGM … MM|INCH`) in inches, as a control set to inches does
    /// (`--units inch`). Default false: mm. The report's warnings say which was assumed.
    pub inch: bool,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            name: "input".to_string(),
            feed_fallback_mm_min: None,
            work_offset_mm: None,
            inch: false,
        }
    }
}

impl ReadOptions {
    /// The default reading of an input called `name`.
    pub fn named(name: impl Into<String>) -> Self {
        ReadOptions {
            name: name.into(),
            ..ReadOptions::default()
        }
    }

    /// Every value in range, or an [`Error::Options`] naming the field.
    pub fn check(&self) -> Result<(), Error> {
        if let Some(f) = self.feed_fallback_mm_min {
            positive("feed_fallback_mm_min", "mm/min", f)?;
        }
        if let Some(w) = self.work_offset_mm
            && w.iter().any(|v| !v.is_finite())
        {
            return Err(OptionError::new(
                "work_offset_mm",
                format_args!("must be three finite numbers of mm, got {w:?}"),
            )
            .into());
        }
        Ok(())
    }
}

/// Options of [`crate::patch_nc`] (and `verify`, `post`, `filter`). Plain struct; see each
/// field for its default.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchOptions {
    /// How the program is read (name, feed fallback, work offset, units).
    pub read: ReadOptions,
    /// Options of the patcher (cone, margin, decimals, …). Default: [`patcher::PatchOptions`]'s.
    /// Its `c_decimals` and `p_decimals` are read from the file and need not be set.
    pub patch: patcher::PatchOptions,
    /// With a kinematic chain, for runs without TCPM: how far the tool tip may leave the
    /// programmed line between two points when the rewritten block's axes are
    /// interpolated linearly, mm (never more than the original block did, either).
    /// Default [`machine_frame::CHORD_TOLERANCE_MM`] (0.005 mm). Also how far the centre
    /// of a ball programmed at its tip may leave its original path between two points
    /// ([`tool`]).
    pub chord_tolerance_mm: f64,
    /// The cutting tool and the point X Y Z state ([`tool`]). Default: from the program
    /// and the TCPM codes.
    pub tool: tool::ToolOptions,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            read: ReadOptions::default(),
            patch: patcher::PatchOptions::default(),
            chord_tolerance_mm: machine_frame::CHORD_TOLERANCE_MM,
            tool: tool::ToolOptions::default(),
        }
    }
}

/// Options of [`crate::analyze_nc`]. Plain struct; see each field for its default.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AnalyzeOptions {
    /// How the program is read (name, feed fallback, work offset, units).
    pub read: ReadOptions,
    /// Options of the analysis (cone, Tcy). Default: [`AnalysisOptions`]'s.
    pub analysis: AnalysisOptions,
}

/// Options of [`crate::simulate_nc`]. Plain struct; see each field for its default.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SimulateOptions {
    /// How the program is read (name, feed fallback, work offset, units: `patch --units
    /// inch --simulate` simulates what it patched). Runs with no F in force and no fallback
    /// are listed with the reason and not simulated.
    pub read: ReadOptions,
    /// Options of the simulator (Tcy, grid). Default: [`SimOptions`]'s.
    pub sim: SimOptions,
}

/// `v` is a positive, finite number, else an [`Error::Options`] naming `field` and `unit`.
pub(crate) fn positive(field: &str, unit: &str, v: f64) -> Result<(), Error> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(OptionError::new(
            field,
            format_args!("must be a positive number of {unit}, got {v}"),
        )
        .into())
    }
}

/// Check the patcher's options: the patcher's one rule set
/// ([`patcher::PatchOptions::validate`]), its refusal as an [`Error::Options`] naming the
/// field, its unit and the value. [`PatchOptions::check`] and [`crate::joints::patch_joints`]
/// call it.
pub fn check_patcher_options(p: &patcher::PatchOptions) -> Result<(), Error> {
    p.validate().map_err(|e| OptionError::of_patcher(&e).into())
}

impl PatchOptions {
    /// The default options of a patch of an input called `name`.
    pub fn named(name: impl Into<String>) -> Self {
        PatchOptions {
            read: ReadOptions::named(name),
            ..PatchOptions::default()
        }
    }

    /// Every value in range, or an [`Error::Options`] naming the field. The entry points
    /// ([`crate::patch_nc`], [`crate::patch_nc_to`]) call it, so a caller need not; a front
    /// end checks earlier only to name its own flags.
    pub fn check(&self) -> Result<(), Error> {
        check_patcher_options(&self.patch)?;
        self.tool.check()?;
        self.read.check()
    }
}

impl AnalyzeOptions {
    /// Every value in range, or an [`Error::Options`] naming the field ([`crate::analyze_nc`]
    /// and [`crate::analyze_nc_each`] call it).
    pub fn check(&self) -> Result<(), Error> {
        self.analysis
            .validate()
            .map_err(|e| Error::from(OptionError::of_patcher(&e)))?;
        self.read.check()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        Error, MAX_WRITTEN_DECIMALS, analyze_nc, kinematics, patch_nc, patch_nc_to, patcher,
        reorient,
    };

    /// The default options with one change.
    fn with(change: impl Fn(&mut PatchOptions)) -> PatchOptions {
        let mut o = PatchOptions::default();
        change(&mut o);
        o
    }

    #[test]
    fn defaults_pass_the_checks() {
        assert!(PatchOptions::default().check().is_ok());
        assert!(AnalyzeOptions::default().check().is_ok());
    }

    #[test]
    fn every_option_out_of_range_is_named() {
        let bad: Vec<(&str, PatchOptions)> = vec![
            ("cone_deg", with(|o| o.patch.cone_deg = 0.0)),
            ("cone_deg", with(|o| o.patch.cone_deg = f64::NAN)),
            (
                "max_deviation_deg",
                with(|o| o.patch.max_deviation_deg = Some(-1.0)),
            ),
            ("tcy_s", with(|o| o.patch.tcy_s = Some(f64::INFINITY))),
            (
                "max_patch_length_mm",
                with(|o| o.patch.max_patch_length_mm = Some(0.0)),
            ),
            ("margin", with(|o| o.patch.margin = 0.5)),
            ("margin", with(|o| o.patch.margin = -0.01)),
            (
                "max_decimals",
                with(|o| o.patch.max_decimals = MAX_WRITTEN_DECIMALS + 1),
            ),
            (
                "feed_fallback_mm_min",
                with(|o| o.read.feed_fallback_mm_min = Some(0.0)),
            ),
            (
                "work_offset_mm",
                with(|o| o.read.work_offset_mm = Some([0.0, f64::NAN, 0.0])),
            ),
        ];
        let program = b"%P G71 *\nN10 G01 X0 Y0 Z0 A1 C0 F1000 *\nN20 X1 A0.5 C90 *\n";
        let m = kinematics::Machine::builtin("mikron-ucp710").unwrap();
        for (field, o) in bad {
            match o.check() {
                Err(Error::Options(e)) => {
                    assert_eq!(e.field, field, "{e}");
                    assert!(e.message.starts_with(field), "{field}: {e}");
                }
                other => panic!("{field}: {other:?}"),
            }
            // Every entry point refuses them, before reading the program.
            assert!(
                matches!(patch_nc(program, &m, &o), Err(Error::Options(_))),
                "{field}"
            );
            let mut sink = Vec::new();
            assert!(
                matches!(
                    patch_nc_to(program, &m, &o, &mut sink),
                    Err(Error::Options(_))
                ),
                "{field}"
            );
        }
    }

    #[test]
    fn analysis_and_reorientation_options_are_checked() {
        let program = b"%P G71 *\nN10 G01 X0 Y0 Z0 A1 C0 F1000 *\nN20 X1 A0.5 C90 *\n";
        let m = kinematics::Machine::builtin("mikron-ucp710").unwrap();
        let analyze = |cone_deg, tcy_s| {
            let opts = AnalyzeOptions {
                analysis: patcher::AnalysisOptions {
                    cone_deg,
                    tcy_s,
                    ..patcher::AnalysisOptions::default()
                },
                ..AnalyzeOptions::default()
            };
            match analyze_nc(program, &m, &opts) {
                Err(Error::Options(e)) => e.field,
                other => panic!("{other:?}"),
            }
        };
        assert_eq!(analyze(-5.0, None), "cone_deg");
        assert_eq!(analyze(5.0, Some(0.0)), "tcy_s");
        let tilt = |theta_x_deg, pivot_mm| reorient::Tilt {
            theta_x_deg,
            theta_z_deg: 0.0,
            pivot_mm,
        };
        for (t, cone, field) in [
            (tilt(f64::NAN, [0.0; 3]), 5.0, "θx"),
            (tilt(10.0, [0.0, f64::INFINITY, 0.0]), 5.0, "pivot_mm"),
            (tilt(10.0, [0.0; 3]), 0.0, "cone_deg"),
        ] {
            match reorient::reorient_nc(program, &m, &t, "p", cone) {
                Err(Error::Options(e)) => assert_eq!(e.field, field, "{e}"),
                other => panic!("{field}: {other:?}"),
            }
        }
        assert!(matches!(
            reorient::search(program, &m, [0.0; 3], "p", -1.0),
            Err(Error::Options(e)) if e.field == "cone_deg"
        ));
    }
}
