//! Options of the patcher.

use crate::analysis::AnalysisOptions;
use crate::error::{OptionField, OptionRule, OptionsError};
pub use crate::path::round_written;
use crate::settings::SolverSettings;

/// Which rotary axes the patcher may change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum PatchAxes {
    /// The primary axis and C (re-selecting the IK branch where that suffices): the machine
    /// reaches the programmed feed on both rotary axes. The default.
    #[default]
    Both,
    /// C only, the primary axis as programmed (G16's method, `--only-c`).
    OnlyC,
}

/// How the patcher treats a zone: polepatch's method (see [`PatchOptions::axes`]) or one of
/// the peers' rules ([`crate::peers`]); [`crate::strategy`] says which methods
/// answer each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// polepatch: branch re-selection, joint patch, verification (or the C-only method).
    #[default]
    Polepatch,
    /// C held at its entry value inside the cone.
    Freeze,
    /// C linear in s across the cone.
    Linearize,
    /// C a cubic blend across the cone.
    Smooth,
}

impl Strategy {
    /// Every strategy, polepatch first.
    pub const ALL: [Strategy; 4] = [
        Strategy::Polepatch,
        Strategy::Freeze,
        Strategy::Linearize,
        Strategy::Smooth,
    ];
    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Polepatch => "polepatch",
            Strategy::Freeze => "freeze",
            Strategy::Linearize => "linearize",
            Strategy::Smooth => "smooth",
        }
    }
}

/// Options of [`crate::patch_path`]. Plain struct: every field public, documented default.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchOptions {
    /// Singular cone, degrees: a stretch below feed with a point with |primary| ≤ this is a
    /// zone; the cone stretch of FREEZE and LINEARIZE. Default
    /// [`crate::analysis::CONE_DEG`] (5).
    pub cone_deg: f64,
    /// Pole reach, degrees: out to here a stretch below feed is a zone when the pole
    /// dominates its slowdown ([`crate::analysis::pole_dominates`]); at or below `cone_deg`
    /// only the cone counts. Default [`crate::analysis::POLE_REACH_DEG`] (10).
    pub pole_reach_deg: f64,
    /// Which rotary axes may change. Default [`PatchAxes::Both`].
    pub axes: PatchAxes,
    /// polepatch's method, or a peer's rule for comparison ([`crate::peers`]). Default
    /// [`Strategy::Polepatch`].
    pub strategy: Strategy,
    /// Largest orientation deviation allowed at any point, degrees; `None` = no limit
    /// (the deviation is still minimised). Default `None`.
    pub max_deviation_deg: Option<f64>,
    /// Interpolation cycle time override, seconds; `None` = the machine's. Default `None`.
    pub tcy_s: Option<f64>,
    /// Safety margin on the C limits: the QP uses (1 − margin)·V, A, J. Default 0.02.
    pub margin: f64,
    /// Ask for third-derivative continuity at the joins of G16's patch where feasible.
    /// [`PatchAxes::OnlyC`] only: the default method has no joins (its values are those of
    /// one analysis spline), and [`PatchOptions::validate`] refuses `false` with it.
    /// Default true.
    pub third_derivative_continuity: bool,
    /// Decimal places of the file's C words (values are verified rounded to these).
    /// Default 3.
    pub c_decimals: usize,
    /// Decimal places of the file's primary-axis words (A or B). Default 3.
    pub p_decimals: usize,
    /// Most decimal places polepatch may write when the file's precision cannot hold
    /// Equation 6 (the joint method also aims within the limits by what rounding to this
    /// many decimals can add). Default 6: at 0.5 mm spacing and F3000 the UCP710's A jerk
    /// budget (J/F³ = 0.0144 °/mm³) is eaten to 28 % by rounding to 4 decimals, to 0.3 % by
    /// rounding to 6. The machine's control must accept that many.
    pub max_decimals: usize,
    /// Longest patch, mm; `None` = up to the whole run. Both methods hold to it (the joint
    /// patch's range is cut to it around the zone). Default `None`.
    pub max_patch_length_mm: Option<f64>,
    /// Keep the path's last point as it is, like its first (default false). A caller sets
    /// it when what follows the path depends on the pose the path ends in (the NC pipeline
    /// decides per run: see `polepatch::end_pose`); otherwise the last point may change,
    /// and the path may end on the other IK branch.
    pub keep_last_point: bool,
    /// Allow a 360° multiple offset of C after the singular point when it shortens the
    /// join (G16's method, [`PatchAxes::OnlyC`] only; [`PatchOptions::validate`] refuses it
    /// with the default method, which re-selects the branch instead). The rest of the run
    /// then carries the offset, and the move after the run has to turn C the extra
    /// revolution back, so it is off by default. Default false.
    pub allow_c_offset: bool,
    /// Keep a ball-end mill's centre where X Y Z are its tip: the tip of every point whose
    /// orientation changes is rewritten, `tip′ = tip + R·(o − o′)` ([`crate::centre`]), and
    /// verified with the rotary axes. `None`: X Y Z never change (they are the centre, or
    /// the tool is not a ball). Default `None`.
    pub keep_centre: Option<crate::centre::KeepCentre>,
    /// Numerical settings ([`SolverSettings`]). Default [`SolverSettings::default`].
    pub solver: SolverSettings,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            cone_deg: crate::analysis::CONE_DEG,
            pole_reach_deg: crate::analysis::POLE_REACH_DEG,
            axes: PatchAxes::Both,
            strategy: Strategy::Polepatch,
            max_deviation_deg: None,
            tcy_s: None,
            margin: 0.02,
            third_derivative_continuity: true,
            c_decimals: 3,
            p_decimals: 3,
            max_decimals: 6,
            max_patch_length_mm: None,
            keep_last_point: false,
            allow_c_offset: false,
            keep_centre: None,
            solver: SolverSettings::default(),
        }
    }
}

impl PatchOptions {
    /// How far from the pole a zone can lie, degrees: the larger of the cone and the pole
    /// reach. A path with no point this close holds no zone.
    pub fn reach_deg(&self) -> f64 {
        self.cone_deg.max(self.pole_reach_deg)
    }

    /// The one rule set of the patcher's options (the library, the CLI, the C ABI and
    /// Python all call it and map [`OptionsError::field`] to their own spelling). The first
    /// field that breaks its rule, in the order of [`OptionField::ALL`]:
    ///
    /// | field | rule |
    /// |---|---|
    /// | `cone_deg` | a positive angle, degrees |
    /// | `pole_reach_deg` | an angle from 0 to [`MAX_POLE_REACH_DEG`] (90) |
    /// | `max_deviation_deg` | `None` (no limit) or a positive angle: 0 is no patch at all, not "no limit" |
    /// | `tcy_s` | `None` or a positive time, seconds |
    /// | `margin` | a fraction in `[0, MAX_MARGIN)` ([`MAX_MARGIN`] = 0.5: the solvers aim at (1 − margin) of the limits) |
    /// | `third_derivative_continuity` | `false` only with the C-only method |
    /// | `max_decimals` | at most [`MAX_WRITTEN_DECIMALS`] (9) |
    /// | `max_patch_length_mm` | `None` (the whole run) or a positive length, mm |
    /// | `allow_c_offset` | `true` only with the C-only method |
    /// | `keep_centre` | `None`, or a positive radius (mm) and unit (mm) |
    ///
    /// The G16 options are refused only for polepatch's default method ([`Strategy::Polepatch`]
    /// with [`PatchAxes::Both`]); a peer's strategy ignores them. `c_decimals`, `p_decimals`
    /// (the file's) and the [`SolverSettings`] have no rule here.
    pub fn validate(&self) -> Result<(), OptionsError> {
        rule_positive(OptionField::ConeDeg, self.cone_deg, "degrees")?;
        rule_angle(OptionField::PoleReachDeg, self.pole_reach_deg)?;
        if let Some(d) = self.max_deviation_deg {
            rule_positive(OptionField::MaxDeviationDeg, d, "degrees")?;
        }
        if let Some(t) = self.tcy_s {
            rule_positive(OptionField::TcyS, t, "seconds")?;
        }
        if !(0.0..MAX_MARGIN).contains(&self.margin) {
            return Err(OptionsError {
                field: OptionField::Margin,
                rule: OptionRule::FractionBelow { below: MAX_MARGIN },
                value: self.margin.to_string(),
            });
        }
        let default_method = self.axes == PatchAxes::Both && self.strategy == Strategy::Polepatch;
        if default_method && !self.third_derivative_continuity {
            return Err(OptionsError {
                field: OptionField::ThirdDerivativeContinuity,
                rule: OptionRule::NeedsOnlyC,
                value: "false".to_string(),
            });
        }
        if self.max_decimals > MAX_WRITTEN_DECIMALS {
            return Err(OptionsError {
                field: OptionField::MaxDecimals,
                rule: OptionRule::AtMost {
                    max: MAX_WRITTEN_DECIMALS,
                },
                value: self.max_decimals.to_string(),
            });
        }
        if let Some(l) = self.max_patch_length_mm {
            rule_positive(OptionField::MaxPatchLengthMm, l, "mm")?;
        }
        if default_method && self.allow_c_offset {
            return Err(OptionsError {
                field: OptionField::AllowCOffset,
                rule: OptionRule::NeedsOnlyC,
                value: "true".to_string(),
            });
        }
        if let Some(k) = &self.keep_centre {
            rule_positive(OptionField::KeepCentreRadiusMm, k.radius_mm, "mm")?;
            rule_positive(OptionField::KeepCentreUnitMm, k.unit_mm, "mm")?;
        }
        Ok(())
    }
}

impl AnalysisOptions {
    /// The rules of [`PatchOptions::validate`] for the fields the analysis shares with it:
    /// `cone_deg`, `pole_reach_deg`, `tcy_s`.
    pub fn validate(&self) -> Result<(), OptionsError> {
        rule_positive(OptionField::ConeDeg, self.cone_deg, "degrees")?;
        rule_angle(OptionField::PoleReachDeg, self.pole_reach_deg)?;
        if let Some(t) = self.tcy_s {
            rule_positive(OptionField::TcyS, t, "seconds")?;
        }
        Ok(())
    }
}

pub use crate::settings::MAX_WRITTEN_DECIMALS;

/// The margin is below this (`margin` ∈ `[0, MAX_MARGIN)`): the solvers aim at
/// (1 − margin) of the rotary axes' limits, and at half of them or less a patch gives
/// away more than it gains.
pub const MAX_MARGIN: f64 = 0.5;

/// The pole reach is at most this, degrees (the pole is 90° from the equator).
pub const MAX_POLE_REACH_DEG: f64 = 90.0;

/// `v` is a finite number above 0 (in `unit`).
fn rule_positive(field: OptionField, v: f64, unit: &'static str) -> Result<(), OptionsError> {
    if v.is_finite() && v > 0.0 {
        return Ok(());
    }
    Err(OptionsError {
        field,
        rule: OptionRule::Positive { unit },
        value: v.to_string(),
    })
}

/// `v` is a finite angle from 0 to [`MAX_POLE_REACH_DEG`].
fn rule_angle(field: OptionField, v: f64) -> Result<(), OptionsError> {
    if v.is_finite() && (0.0..=MAX_POLE_REACH_DEG).contains(&v) {
        return Ok(());
    }
    Err(OptionsError {
        field,
        rule: OptionRule::AngleUpTo {
            max: MAX_POLE_REACH_DEG,
        },
        value: v.to_string(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::centre::KeepCentre;

    fn with(change: impl Fn(&mut PatchOptions)) -> PatchOptions {
        let mut o = PatchOptions::default();
        change(&mut o);
        o
    }

    /// The defaults pass; every field out of range is refused with its field and rule, and
    /// the message names it as the caller spells it.
    #[test]
    fn one_rule_set_names_the_field() {
        assert_eq!(PatchOptions::default().validate(), Ok(()));
        assert_eq!(AnalysisOptions::default().validate(), Ok(()));
        let only_c = |o: &mut PatchOptions| o.axes = PatchAxes::OnlyC;
        let centre = |r: f64, u: f64| KeepCentre {
            radius_mm: r,
            decimals: 3,
            unit_mm: u,
            s_is_length: true,
        };
        let cases: Vec<(OptionField, PatchOptions)> = vec![
            (OptionField::ConeDeg, with(|o| o.cone_deg = 0.0)),
            (OptionField::ConeDeg, with(|o| o.cone_deg = f64::NAN)),
            (OptionField::PoleReachDeg, with(|o| o.pole_reach_deg = -1.0)),
            (OptionField::PoleReachDeg, with(|o| o.pole_reach_deg = 91.0)),
            (
                OptionField::MaxDeviationDeg,
                with(|o| o.max_deviation_deg = Some(0.0)),
            ),
            (
                OptionField::MaxDeviationDeg,
                with(|o| o.max_deviation_deg = Some(f64::INFINITY)),
            ),
            (OptionField::TcyS, with(|o| o.tcy_s = Some(-0.001))),
            (OptionField::Margin, with(|o| o.margin = -0.01)),
            (OptionField::Margin, with(|o| o.margin = MAX_MARGIN)),
            (
                OptionField::ThirdDerivativeContinuity,
                with(|o| o.third_derivative_continuity = false),
            ),
            (OptionField::MaxDecimals, with(|o| o.max_decimals = 12)),
            (
                OptionField::MaxPatchLengthMm,
                with(|o| o.max_patch_length_mm = Some(0.0)),
            ),
            (OptionField::AllowCOffset, with(|o| o.allow_c_offset = true)),
            (
                OptionField::KeepCentreRadiusMm,
                with(|o| o.keep_centre = Some(centre(0.0, 1.0))),
            ),
            (
                OptionField::KeepCentreUnitMm,
                with(|o| o.keep_centre = Some(centre(5.0, f64::NAN))),
            ),
        ];
        for (field, o) in cases {
            let e = o.validate().unwrap_err();
            assert_eq!(e.field, field, "{e}");
            assert!(e.to_string().starts_with(field.name()), "{e}");
            assert!(e.message("--the-flag").starts_with("--the-flag "), "{e}");
            assert!(OptionField::ALL.contains(&field));
        }
        // G16's join options are the C-only method's, and a peer ignores them.
        let g16 = |o: &mut PatchOptions| {
            o.allow_c_offset = true;
            o.third_derivative_continuity = false;
        };
        assert_eq!(
            with(|o| {
                g16(o);
                only_c(o)
            })
            .validate(),
            Ok(())
        );
        assert_eq!(
            with(|o| {
                g16(o);
                o.strategy = Strategy::Freeze
            })
            .validate(),
            Ok(())
        );
        // The limits themselves pass.
        assert_eq!(
            with(|o| {
                o.max_decimals = MAX_WRITTEN_DECIMALS;
                o.margin = 0.0;
                o.pole_reach_deg = MAX_POLE_REACH_DEG;
            })
            .validate(),
            Ok(())
        );
    }

    /// The refusals of issue 28, as the library's field names.
    #[test]
    fn refusals_read_as_the_rule() {
        let msg = |o: PatchOptions| o.validate().unwrap_err().to_string();
        assert_eq!(
            msg(with(|o| o.max_deviation_deg = Some(0.0))),
            "max_deviation_deg must be a positive number of degrees, got 0"
        );
        assert_eq!(
            msg(with(|o| o.margin = -0.1)),
            "margin must be a fraction in [0, 0.5), got -0.1"
        );
        assert_eq!(
            msg(with(|o| o.max_decimals = 12)),
            "max_decimals must be at most 9, got 12"
        );
        let e = with(|o| o.max_decimals = 12).validate().unwrap_err();
        assert_eq!(
            e.message("--max-decimals"),
            "--max-decimals must be at most 9, got 12"
        );
    }
}
