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

/// Smallest length a direction in a machine file may have before it is normalised
/// (`[[rotary]] direction`, `tool_direction`). Directions are written as unit vectors or
/// small integers (`[0, 1, 1]`); one shorter than this is a typo or garbage, and one of
/// subnormal values (`[1e-320, 0, 0]`) cannot even be normalised (1/1e-320 overflows and
/// the kinematics turn NaN).
pub const MIN_DIRECTION_NORM: f64 = 1e-6;
