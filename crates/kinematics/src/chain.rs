//! The kinematic chain of a table-table machine: where the rotary axes sit in the machine
//! frame, so that machine-frame X Y Z (what the linear axes do) and the tool tip in the
//! part frame can be converted into each other for given primary and C angles.
//!
//! Frames and conventions (all lengths mm, machine frame = the linear axes' frame):
//!
//! - The tool is fixed; its axis is ẑ of the machine frame. The table (C) rides on the
//!   primary cradle (A about X, or B about Y). A vector fixed to the part, `v_W` in part
//!   coordinates, is seen in the machine frame as `Q·v_W` with
//!   `Q(P, C) = Rp(−sp·P)·Rz(−sc·C)`, the inverse of [`crate::forward`]'s
//!   `o_wp = Rz(sc·C)·Rp(sp·P)·ẑ` (so `Q·o_wp = ẑ`: the tool axis is the machine's ẑ).
//! - `p` is a point on the primary axis line (a line along x for A, y for B) and `c` a
//!   point on the C axis at P = 0 (a line along z), both in machine coordinates; the axes
//!   need not intersect.
//! - `d` is the work offset (datum): the machine coordinates of the program's zero. The
//!   part's zero sits at `d` when P = C = 0 (how a post sets up a 3+2 or 5-axis job
//!   without TCPM), and the part's axes are then the machine's.
//!
//! A part point `x_W` is then at, in machine coordinates,
//!
//! ```text
//! x_M = p + Rp(−sp·P) · ( (c − p) + Rz(−sc·C) · (d + x_W − c) )
//! ```
//!
//! and the program's X Y Z without TCPM are `x_M − d` (the controller adds the datum).
//! Inversely `x_W = Rz(sc·C) · ( Rp(sp·P)·(x_M − p) − (c − p) ) + c − d`. With `p = c = d
//! = 0` this is C17's eq. 1, `P_M = Rx(−A)·Rz(−C)·P_W` (its senses).

use crate::machine::{Machine, PrimaryAxis};
use serde::{Deserialize, Serialize};

/// Where the rotary axes sit in the machine frame (module docs). Optional part of a
/// machine description (`[chain]` in the TOML).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Chain {
    /// A point on the primary axis line, machine coordinates, mm (`p`).
    pub primary_axis_point_mm: [f64; 3],
    /// A point on the C axis at primary = 0, machine coordinates, mm (`c`).
    pub c_axis_point_mm: [f64; 3],
}

/// Rotation of `v` about the machine's primary axis by `angle_deg` (right-handed about +x
/// for A, +y for B).
fn rot_p(primary: PrimaryAxis, angle_deg: f64, v: [f64; 3]) -> [f64; 3] {
    let (s, c) = angle_deg.to_radians().sin_cos();
    match primary {
        PrimaryAxis::A => [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]],
        PrimaryAxis::B => [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]],
    }
}

/// Rotation of `v` about +z by `angle_deg`.
fn rot_z(angle_deg: f64, v: [f64; 3]) -> [f64; 3] {
    let (s, c) = angle_deg.to_radians().sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

impl Chain {
    /// Rotary axes intersecting at machine zero (C17's set-up).
    pub const AT_ORIGIN: Chain = Chain {
        primary_axis_point_mm: [0.0; 3],
        c_axis_point_mm: [0.0; 3],
    };

    /// A part-frame vector (a direction, no position) in the machine frame: `Q·v_W`.
    pub fn part_vector_in_machine(
        machine: &Machine,
        p_deg: f64,
        c_deg: f64,
        v_w: [f64; 3],
    ) -> [f64; 3] {
        rot_p(
            machine.primary,
            -machine.primary_sense * p_deg,
            rot_z(-machine.c_sense * c_deg, v_w),
        )
    }

    /// The program's X Y Z without TCPM (machine coordinates minus the work offset
    /// `datum_mm`) that put the tool tip at `tip_part_mm` (part coordinates) with the
    /// rotary axes at `p_deg`, `c_deg`.
    pub fn program_xyz(
        &self,
        machine: &Machine,
        datum_mm: [f64; 3],
        p_deg: f64,
        c_deg: f64,
        tip_part_mm: [f64; 3],
    ) -> [f64; 3] {
        let p = self.primary_axis_point_mm;
        let c = self.c_axis_point_mm;
        let on_table = rot_z(-machine.c_sense * c_deg, sub(add(datum_mm, tip_part_mm), c));
        let on_cradle = add(sub(c, p), on_table);
        let x_m = add(
            p,
            rot_p(machine.primary, -machine.primary_sense * p_deg, on_cradle),
        );
        sub(x_m, datum_mm)
    }

    /// The tool tip in part coordinates for the program's X Y Z without TCPM
    /// (`program_mm`, machine coordinates minus `datum_mm`) at `p_deg`, `c_deg`: the
    /// inverse of [`Chain::program_xyz`].
    pub fn part_tip(
        &self,
        machine: &Machine,
        datum_mm: [f64; 3],
        p_deg: f64,
        c_deg: f64,
        program_mm: [f64; 3],
    ) -> [f64; 3] {
        let p = self.primary_axis_point_mm;
        let c = self.c_axis_point_mm;
        let x_m = add(program_mm, datum_mm);
        let on_cradle = rot_p(machine.primary, machine.primary_sense * p_deg, sub(x_m, p));
        let on_table = rot_z(machine.c_sense * c_deg, sub(on_cradle, sub(c, p)));
        sub(add(on_table, c), datum_mm)
    }

    /// Check the values: finite.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("chain.primary_axis_point_mm", self.primary_axis_point_mm),
            ("chain.c_axis_point_mm", self.c_axis_point_mm),
        ] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(format!("{name} must be finite, got {v:?}"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forward;

    fn machines() -> Vec<Machine> {
        let mut out = Vec::new();
        for name in Machine::builtin_names() {
            let m = Machine::builtin(name).unwrap();
            for (sp, sc) in [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)] {
                out.push(Machine {
                    primary_sense: sp,
                    c_sense: sc,
                    ..m.clone()
                });
            }
        }
        out
    }

    const CHAIN: Chain = Chain {
        primary_axis_point_mm: [3.0, -20.0, -150.0],
        c_axis_point_mm: [12.5, -7.0, -140.0],
    };
    const DATUM: [f64; 3] = [-30.489, -4.3, 38.054];

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
    }

    /// Angles including the pole, C at ±180° and beyond a turn.
    const ANGLES: [(f64, f64); 8] = [
        (0.0, 0.0),
        (0.0, 180.0),
        (1e-9, -180.0),
        (23.162, 333.802),
        (-45.0, 90.0),
        (90.0, -720.5),
        (-100.0, 12.0),
        (5.0, 1e6),
    ];

    #[test]
    fn part_tip_inverts_program_xyz() {
        for m in machines() {
            for (p, c) in ANGLES {
                for tip in [[0.0, 0.0, 0.0], [25.0, 0.0, -8.0], [-50.0, 70.0, 100.0]] {
                    let x = CHAIN.program_xyz(&m, DATUM, p, c, tip);
                    let back = CHAIN.part_tip(&m, DATUM, p, c, x);
                    assert!(close(back, tip, 1e-9), "{p} {c} {tip:?} → {back:?}");
                }
            }
        }
    }

    /// The tool axis (machine ẑ) seen from the part is `forward(P, C)`: moving the
    /// program point along machine ẑ moves the part-frame tip along o_wp.
    #[test]
    fn the_machine_z_axis_is_the_tool_axis_of_forward() {
        for m in machines() {
            for (p, c) in ANGLES {
                let x = [10.0, -3.0, 40.0];
                let a = CHAIN.part_tip(&m, DATUM, p, c, x);
                let b = CHAIN.part_tip(&m, DATUM, p, c, [x[0], x[1], x[2] + 1.0]);
                let o = forward(&m, p, c);
                assert!(close(sub(b, a), o, 1e-9), "{p} {c}");
                let q = Chain::part_vector_in_machine(&m, p, c, o);
                assert!(close(q, [0.0, 0.0, 1.0], 1e-12), "{q:?}");
            }
        }
    }

    /// C17 eq. 1 (axes intersecting at the origin, no datum): P_M = Rx(−A)·Rz(−C)·P_W with
    /// C17's senses.
    #[test]
    fn c17_equation_1_is_the_special_case() {
        let m = Machine {
            primary_sense: 1.0,
            c_sense: 1.0,
            ..Machine::builtin("mikron-ucp710").unwrap()
        };
        let (a, c) = (30.0f64, 60.0f64);
        let pw = [10.0, 20.0, 5.0];
        let got = Chain::AT_ORIGIN.program_xyz(&m, [0.0; 3], a, c, pw);
        // Rz(−C) then Rx(−A), written out.
        let (sc, cc) = (-c).to_radians().sin_cos();
        let r1 = [cc * pw[0] - sc * pw[1], sc * pw[0] + cc * pw[1], pw[2]];
        let (sa, ca) = (-a).to_radians().sin_cos();
        let r2 = [r1[0], ca * r1[1] - sa * r1[2], sa * r1[1] + ca * r1[2]];
        assert!(close(got, r2, 1e-12), "{got:?} vs {r2:?}");
    }

    /// A point on the C axis does not move when C turns; at the pole C turns the table
    /// about the tool axis, so the tool tip on the C axis is fixed for any C.
    #[test]
    fn points_on_the_axes_stay_put() {
        for m in machines() {
            // The part point that sits on the C axis at P = 0.
            let on_c = sub(sub(CHAIN.c_axis_point_mm, DATUM), [0.0, 0.0, 5.0]);
            let x0 = CHAIN.program_xyz(&m, DATUM, 0.0, 0.0, on_c);
            for c in [-180.0, -33.0, 180.0, 540.0] {
                let x = CHAIN.program_xyz(&m, DATUM, 0.0, c, on_c);
                assert!(close(x, x0, 1e-9), "{c}");
            }
        }
    }

    /// 50 mm off the C axis at the pole, 192 rpm on C moves the linear axes at
    /// 2π·50·192/60 mm/s ≈ 60.3 m/min (C17 eq. 6): finite differences of program_xyz.
    #[test]
    fn linear_axes_follow_the_table() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let tip = sub(add(CHAIN.c_axis_point_mm, [50.0, 0.0, 0.0]), DATUM);
        let dc_deg = 1e-4;
        let a = CHAIN.program_xyz(&m, DATUM, 0.0, 10.0, tip);
        let b = CHAIN.program_xyz(&m, DATUM, 0.0, 10.0 + dc_deg, tip);
        let mm_per_deg = sub(b, a).iter().map(|v| v * v).sum::<f64>().sqrt() / dc_deg;
        let m_min = mm_per_deg * 192.0 * 360.0 / 1000.0;
        assert!((m_min - 60.32).abs() < 0.01, "{m_min}");
    }
}
