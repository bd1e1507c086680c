//! Options of the patcher.

use crate::path::PathError;
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
#[serde(rename_all = "kebab-case")]
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

    /// Refuse options that would mean nothing: G16's join options with the default
    /// method, a cone, margin or cap out of range.
    pub fn validate(&self) -> Result<(), PathError> {
        let bad = |what: &str| Err(PathError::Options(what.to_string()));
        if self.axes == PatchAxes::Both && self.strategy == Strategy::Polepatch {
            if self.allow_c_offset {
                return bad(
                    "a 360° C offset (allow_c_offset) is G16's join option: it needs the C-only method",
                );
            }
            if !self.third_derivative_continuity {
                return bad(
                    "third-derivative continuity at the joins is G16's option: it needs the C-only method",
                );
            }
        }
        if !(self.cone_deg.is_finite() && self.cone_deg > 0.0) {
            return bad(&format!(
                "the singular cone must be a positive angle, got {}°",
                self.cone_deg
            ));
        }
        if !(self.pole_reach_deg.is_finite() && (0.0..=90.0).contains(&self.pole_reach_deg)) {
            return bad(&format!(
                "the pole reach must be an angle from 0° to 90°, got {}°",
                self.pole_reach_deg
            ));
        }
        if !(0.0..1.0).contains(&self.margin) {
            return bad(&format!(
                "the margin must be in [0, 1), got {}",
                self.margin
            ));
        }
        if let Some(d) = self.max_deviation_deg
            && !(d.is_finite() && d >= 0.0)
        {
            return bad(&format!("the largest deviation must be ≥ 0°, got {d}°"));
        }
        if let Some(k) = &self.keep_centre
            && !(k.radius_mm.is_finite()
                && k.radius_mm > 0.0
                && k.unit_mm.is_finite()
                && k.unit_mm > 0.0)
        {
            return bad(&format!(
                "keeping a ball's centre needs a positive radius and unit, got {} mm and {} mm",
                k.radius_mm, k.unit_mm
            ));
        }
        if let Some(l) = self.max_patch_length_mm
            && !(l.is_finite() && l > 0.0)
        {
            return bad(&format!(
                "the longest patch must be a positive length, got {l} mm"
            ));
        }
        Ok(())
    }
}
