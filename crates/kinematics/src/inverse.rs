//! Inverse kinematics: tool axis → (primary, C) in degrees, both solutions, branch choice.

use crate::machine::Machine;

/// One joint solution, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSolution {
    /// Primary angle (A or B), degrees.
    pub p_deg: f64,
    /// C angle, degrees, in (−180, 180] before unwrapping.
    pub c_deg: f64,
}

/// How [`inverse_path`] picks between the two solutions (P, C) and (−P, C+180°).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BranchRule {
    /// The solution nearest to the previous point (max of |ΔP| and |ΔC| after unwrapping);
    /// the first point prefers positive P.
    Nearest,
    /// G16 Table 1: the branch is chosen by the sign of j (flips P near the pole).
    DomainRule,
    /// Always P ≥ 0.
    PreferPositive,
    /// Always P ≤ 0.
    PreferNegative,
}

/// Both solutions for a unit tool axis `o_wp`. Returns `None` on the pole (|sin P| below
/// [`crate::tolerances::POLE_SIN_TOL`]): C is undefined there. The first solution has
/// P ≥ 0. Both P lie within (−180, 180].
pub fn inverse(machine: &Machine, o_wp: [f64; 3]) -> Option<[IkSolution; 2]> {
    let _ = (machine, o_wp);
    todo!()
}

/// Joint values for a sequence of tool axes: branch by `rule`, C unwrapped to be continuous
/// (each C within 180° of the previous one, so a C sweep past ±180° does not jump), and on
/// the pole C keeps the previous value (0 for a first point on the pole). Solutions outside
/// the machine's primary range are rejected in favour of the other one.
pub fn inverse_path(machine: &Machine, o_wp: &[[f64; 3]], rule: BranchRule) -> Vec<IkSolution> {
    let _ = (machine, o_wp, rule);
    todo!()
}
