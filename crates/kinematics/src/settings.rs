//! The kinematics crate's settings: defaults taken where a machine file does not say, each
//! with its unit and why (its round-off tolerances are in [`crate::tolerances`]).

/// LinuxCNC's default servo period when `[EMCMOT] SERVO_PERIOD` is absent, seconds.
pub const DEFAULT_SERVO_PERIOD_S: f64 = 1e-3;
