//! Named tolerances of the kinematics crate.

/// |sin P| below which the tool axis is treated as on the pole (C undefined), where P is the
/// primary angle (in general: the sine of the angle between the tool axis and the pole
/// axis). 1e-12 rad of tilt is far below any NC resolution (0.0001° = 1.7e-6 rad).
pub const POLE_SIN_TOL: f64 = 1e-12;

/// How far, radians, a tool axis may lie beyond the orientations a rotary pair reaches and
/// still be solved (as the nearest reachable one): the border of the reach (a 45° nutating
/// table tilting the tool exactly 90°, the pole of a pair whose pole is reachable only in
/// exact arithmetic) is then not lost to rounding. 1e-9 rad is 6e-8°, far below any NC or
/// CL resolution.
pub const REACH_TOL_RAD: f64 = 1e-9;

/// Smallest sine of the angle between the two rotary axes, and between the tilting axis and
/// the tool, that a machine file may give: below it the two axes (or the tilting axis and
/// the tool) are parallel to within 0.0002° and cannot orient the tool.
pub const MIN_AXIS_SIN: f64 = 1e-6;
