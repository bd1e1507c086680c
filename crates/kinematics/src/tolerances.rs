//! Named tolerances and bounds of the kinematics crate: each with its unit and why it has
//! its value.

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

/// Relative margin of the test that skips the cube root in [`crate::axis_feed_bound`]:
/// cbrt(t) < f implies t < f³, and the margin covers the rounding of f³ (a few units in the
/// last place, ~1e-16 relative), so a root that could bind is never skipped and the result
/// is the same as always taking it.
pub(crate) const CBRT_SKIP_MARGIN: f64 = 1e-9;

/// How far from 1 the norm of a normalised machine-file direction may be: dividing a vector
/// of norm at least [`MIN_DIRECTION_NORM`] by its norm gives a unit vector to a few units in
/// the last place (~1e-16); the check is kept only so that no NaN direction can ever leave
/// the reader.
pub(crate) const UNIT_NORM_TOL: f64 = 1e-12;

/// Degrees: a LinuxCNC pole axis whose `MIN_LIMIT`/`MAX_LIMIT` (converted to degrees) reach
/// ±1e98 has no travel and is endless. LinuxCNC's INI readers (`iniaxis.cc`, `inijoint.cc`)
/// default a missing limit to ±1e99, which stays beyond ±1e98 in every angular unit
/// (×0.9 for grad, ×57.3 for rad); no real travel comes near it.
pub(crate) const LINUXCNC_NO_LIMIT: f64 = 1e98;

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
