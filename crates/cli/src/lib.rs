//! polepatch: find and patch the places where the C axis slows a table-table 5-axis machine
//! near the pole.
//!
//! This facade re-exports the crates and holds the glue from NC programs to the in-memory
//! paths of the patcher ([`program`]), the report documents ([`report`]) and the quality
//! suite ([`bench`]).

pub use polepatch_bspline as bspline;
pub use polepatch_kinematics as kinematics;
pub use polepatch_nc as nc;
pub use polepatch_patcher as patcher;

pub mod bench;
pub mod job;
pub mod program;
pub mod report;
