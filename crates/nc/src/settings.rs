//! The nc crate's settings: the values it writes where a program or a CL file does not say,
//! each with its unit and why (its round-off tolerances are in [`crate::tolerances`]).

/// Heidenhain cycle 203's retraction for chip breaking (Q256), mm: the CL does not state
/// one; 0.2 mm is the value in Heidenhain's cycle 203 examples.
pub const HEIDENHAIN_CHIP_BREAK_MM: f64 = 0.2;
