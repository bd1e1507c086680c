//! Forward kinematics: rotary angles (degrees) → tool axis in the workpiece frame.

use crate::machine::Machine;

/// Tool axis `o_wp = Rz(sc·C)·Rp(sp·P)·ẑ` (unit vector) for primary angle `p_deg` and
/// `c_deg`, both degrees.
pub fn forward(machine: &Machine, p_deg: f64, c_deg: f64) -> [f64; 3] {
    let _ = (machine, p_deg, c_deg);
    todo!()
}
