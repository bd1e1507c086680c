//! Machines, tool-axis kinematics and the Equation-6 feed bound.
//!
//! # Units (one rule for the whole crate)
//! - Angles are **degrees** in every public value (as in NC files); functions convert to
//!   radians internally only.
//! - Lengths are millimetres, time is seconds. Internal limits are stored as
//!   mm/s, mm/s², mm/s³ for linear axes and °/s, °/s², °/s³ for rotary axes; the TOML
//!   machine files use the units of the machine tables (m/min, m/s², m/s³ for linear axes;
//!   rpm, rev/s², rev/s³ for rotary axes), converted once on load.
//! - Geometric derivatives along the tool-tip path length s are per mm: mm/mm for a
//!   linear axis, °/mm, °/mm², °/mm³ for a rotary axis.
//!
//! # Frames and senses
//! The tool axis `o_wp = (i, j, k)` is expressed in the workpiece frame. A machine's two
//! rotary axes form a chain ([`rotary`]): the pole axis (slot [`Axis::C`]) next to the part,
//! the tilting axis (slot [`Axis::Primary`]) next to the tool, each turning the table or
//! the head about its own direction, with its own letter. With senses `sp`, `sc` = ±1:
//! `o_wp = R(a, sc·C) · R(b, sp·P) · t0`. On the built-ins (a table-table A-C and B-C) this
//! is `o_wp = Rz(sc·C) · Rp(sp·P) · ẑ`, where `Rp` is `Rx` for A and `Ry` for B.
//! G16 eq. 1 is `sp = sc = +1` with A (`i = sin C sin A, j = −cos C sin A, k = cos A`);
//! C17 eq. 2 is `sp = sc = −1` (`i = sin C sin A, j = cos C sin A, k = cos A`).
//!
//! # Machine sources
//! A built-in name, a TOML file in either form ([`Machine::from_toml_str`]), or a
//! LinuxCNC INI file ([`linuxcnc`]), all through [`Machine::load`].

mod angles;
pub mod chain;
pub mod feed;
pub mod forward;
mod frames;
mod hal;
mod haltcl;
mod ini;
pub mod inverse;
pub mod linuxcnc;
mod load;
pub mod machine;
mod machine_file;
pub mod reorient;
pub mod rotary;
pub mod settings;
pub mod tolerances;
pub mod vec3;

#[cfg(test)]
mod testutil;

pub use angles::{unwrap_near_deg, wrap_deg};
pub use chain::Chain;
pub use feed::{AxisBound, FeedBound, LimitKind, axis_feed_bound, axis_feed_ratio, feed_bound};
pub use forward::{StandardForm, angle_between_deg, forward, forward_jacobian};
pub use inverse::{
    BranchRule, PoleDistance, domain_rule_index, inverse, inverse_path, inverse_path_from, solve_ik,
};
pub use machine::{Axis, AxisLimits, Controller, Machine, MachineError, PrimaryAxis};
pub use reorient::JigRotation;
pub use rotary::{Carrier, Ik, IkSolution, Layout, Rotaries, RotaryAxis};
