//! Forward kinematics: rotary angles (degrees) → tool axis in the workpiece frame.
//!
//! ```text
//! o_wp = Rz(sc·C) · Rp(sp·P) · ẑ
//!   A (Rp = Rx):  o_wp = ( sp·sin P · sin(sc·C), −sp·sin P · cos(sc·C), cos P )
//!   B (Rp = Ry):  o_wp = ( sp·sin P · cos(sc·C),  sp·sin P · sin(sc·C), cos P )
//! ```
//!
//! With A and `sp = sc = +1` this is G16 eq. 1: `i = sin C sin A, j = −cos C sin A,
//! k = cos A`; with `sp = sc = −1` it is C17 eq. 2: `i = sin C sin A, j = cos C sin A`.

use crate::machine::{Machine, PrimaryAxis};

/// Tool axis `o_wp = Rz(sc·C)·Rp(sp·P)·ẑ` (unit vector) for primary angle `p_deg` and
/// `c_deg`, both degrees.
pub fn forward(machine: &Machine, p_deg: f64, c_deg: f64) -> [f64; 3] {
    let (sin_p, cos_p) = p_deg.to_radians().sin_cos();
    let (sin_c, cos_c) = (machine.c_sense * c_deg).to_radians().sin_cos();
    // Horizontal length of Rp(sp·P)·ẑ, signed by the primary sense.
    let h = machine.primary_sense * sin_p;
    match machine.primary {
        // Rx(a)·ẑ = (0, −sin a, cos a), then Rz(γ) gives (sin γ·sin a, −cos γ·sin a, cos a).
        PrimaryAxis::A => [h * sin_c, -h * cos_c, cos_p],
        // Ry(b)·ẑ = (sin b, 0, cos b), then Rz(γ) gives (cos γ·sin b, sin γ·sin b, cos b).
        PrimaryAxis::B => [h * cos_c, h * sin_c, cos_p],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Machine;
    use crate::testutil::machine;

    fn assert_close(a: [f64; 3], b: [f64; 3], what: &str) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-14, "{what}: {a:?} vs {b:?}");
        }
    }

    const ANGLES_DEG: [f64; 9] = [-180.0, -135.0, -90.0, -12.5, 0.0, 0.3, 45.0, 90.0, 179.0];

    #[test]
    fn g16_eq1_for_the_ucp710() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        for &a in &ANGLES_DEG {
            for &c in &ANGLES_DEG {
                let (ar, cr) = (a.to_radians(), c.to_radians());
                let want = [cr.sin() * ar.sin(), -cr.cos() * ar.sin(), ar.cos()];
                assert_close(forward(&m, a, c), want, &format!("A={a} C={c}"));
            }
        }
    }

    #[test]
    fn c17_eq2_with_negative_senses() {
        let m = machine(PrimaryAxis::A, -1.0, -1.0, (-120.0, 120.0));
        for &a in &ANGLES_DEG {
            for &c in &ANGLES_DEG {
                let (ar, cr) = (a.to_radians(), c.to_radians());
                let want = [cr.sin() * ar.sin(), cr.cos() * ar.sin(), ar.cos()];
                assert_close(forward(&m, a, c), want, &format!("A={a} C={c}"));
            }
        }
    }

    #[test]
    fn b_machine_tilts_about_y() {
        let m = Machine::builtin("mikron-hsm600").unwrap();
        // B = +90 with C = 0 puts the tool along +X (Ry(90°)·ẑ = x̂).
        assert_close(forward(&m, 90.0, 0.0), [1.0, 0.0, 0.0], "B=90 C=0");
        // Then C = +90 turns it to +Y (Rz(90°)·x̂ = ŷ).
        assert_close(forward(&m, 90.0, 90.0), [0.0, 1.0, 0.0], "B=90 C=90");
        // Negative senses flip both.
        let n = machine(PrimaryAxis::B, -1.0, -1.0, (-120.0, 120.0));
        assert_close(forward(&n, 90.0, 0.0), [-1.0, 0.0, 0.0], "sp=-1");
        assert_close(forward(&n, 90.0, 90.0), [0.0, 1.0, 0.0], "sp=sc=-1");
    }

    #[test]
    fn c_does_not_move_the_tool_on_the_pole_and_the_result_is_unit() {
        for m in crate::testutil::all_kinds() {
            for &c in &ANGLES_DEG {
                assert_eq!(forward(&m, 0.0, c), [0.0, 0.0, 1.0]);
                for &p in &ANGLES_DEG {
                    let o = forward(&m, p, c);
                    let n = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt();
                    assert!((n - 1.0).abs() < 1e-15);
                }
            }
        }
    }
}
