//! Named tolerances of the kinematics crate.

/// |sin P| below which the tool axis is treated as on the pole (C undefined), where P is the
/// primary angle. 1e-12 rad of tilt is far below any NC resolution (0.0001° = 1.7e-6 rad).
pub const POLE_SIN_TOL: f64 = 1e-12;
