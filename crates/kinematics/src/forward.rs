//! Forward kinematics: rotary angles (degrees) → tool axis in the workpiece frame.
//!
//! Every machine: `o_wp = R(a, sc·C)·R(b, sp·P)·t0` ([`crate::rotary`]). The machines of the
//! **standard form** — the pole axis along ±Z, the tilting axis along ±X (A) or ±Y (B), the
//! tool along +Z: the built-ins and every `[primary]`/`[c]` file — are computed with the
//! written-out formulas below (exact zeros; the values are bit for bit those polepatch
//! always gave), every other pair with the general formula of [`crate::rotary`]. A test
//! keeps the two equal on the standard form.
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
use crate::rotary::{coordinate_axis, forward_general, jacobian_general};

/// A machine of the standard form (module docs): which coordinate axis the tilting axis
/// turns about, and the senses with the signs of the directions folded in (a pole axis
/// along −Z with sense +1 is one along +Z with sense −1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StandardForm {
    /// A (about ±X) or B (about ±Y).
    pub primary: PrimaryAxis,
    /// Effective sense of the tilting axis about +X or +Y, ±1.
    pub sp: f64,
    /// Effective sense of the pole axis about +Z, ±1.
    pub sc: f64,
}

impl Machine {
    /// The standard form of this machine's pair, if it has it (module docs): then the two
    /// joint solutions of every tool axis are (P, C) and (−P, C + 180°), the pole is P = 0,
    /// and the tilt from the pole is |P|.
    pub fn standard_form(&self) -> Option<StandardForm> {
        let r = &self.rotary;
        if r.tool_direction != [0.0, 0.0, 1.0] {
            return None;
        }
        let (2, c_sign) = coordinate_axis(r.c.direction)? else {
            return None;
        };
        let (k, p_sign) = coordinate_axis(r.primary.direction)?;
        let primary = match k {
            0 => PrimaryAxis::A,
            1 => PrimaryAxis::B,
            _ => return None,
        };
        Some(StandardForm {
            primary,
            sp: self.primary_sense * p_sign,
            sc: self.c_sense * c_sign,
        })
    }
}

/// Tool axis (unit vector, part frame) for primary angle `p_deg` and `c_deg`, both degrees:
/// `R(a, sc·C)·R(b, sp·P)·t0`; for the built-ins `Rz(sc·C)·Rp(sp·P)·ẑ`.
pub fn forward(machine: &Machine, p_deg: f64, c_deg: f64) -> [f64; 3] {
    match machine.standard_form() {
        Some(f) => forward_standard(f, p_deg, c_deg),
        None => forward_general(
            &machine.rotary,
            machine.primary_sense,
            machine.c_sense,
            p_deg,
            c_deg,
        ),
    }
}

/// [`forward`] of the standard form, written out.
fn forward_standard(f: StandardForm, p_deg: f64, c_deg: f64) -> [f64; 3] {
    let (sin_p, cos_p) = p_deg.to_radians().sin_cos();
    let (sin_c, cos_c) = (f.sc * c_deg).to_radians().sin_cos();
    // Horizontal length of Rp(sp·P)·ẑ, signed by the primary sense.
    let h = f.sp * sin_p;
    match f.primary {
        // Rx(a)·ẑ = (0, −sin a, cos a), then Rz(γ) gives (sin γ·sin a, −cos γ·sin a, cos a).
        PrimaryAxis::A => [h * sin_c, -h * cos_c, cos_p],
        // Ry(b)·ẑ = (sin b, 0, cos b), then Rz(γ) gives (cos γ·sin b, sin γ·sin b, cos b).
        PrimaryAxis::B => [h * cos_c, h * sin_c, cos_p],
    }
}

/// The tool axis and its partial derivatives with respect to the primary angle and C,
/// per **degree**: `(o_wp, ∂o_wp/∂P, ∂o_wp/∂C)`. In general `∂o/∂P = sp·R(a, sc·C)·(b × v)`
/// with `v = R(b, sp·P)·t0`, `∂o/∂C = sc·(a × o)` (times π/180); for the standard form, with
/// `h = sp·sin P`, `γ = sc·C`:
///
/// ```text
/// A:  ∂o/∂P = (sp cos P sin γ, −sp cos P cos γ, −sin P)·π/180
///     ∂o/∂C = sc·(h cos γ, h sin γ, 0)·π/180
/// B:  ∂o/∂P = (sp cos P cos γ,  sp cos P sin γ, −sin P)·π/180
///     ∂o/∂C = sc·(−h sin γ, h cos γ, 0)·π/180
/// ```
///
/// `∂o/∂C` has length `sin ∠(a, v)` per radian (`|sin P|` on the built-ins): near the pole C
/// barely moves the tool. `∂o/∂P` has length `sin ∠(b, t0)` (1 on the built-ins).
pub fn forward_jacobian(machine: &Machine, p_deg: f64, c_deg: f64) -> [[f64; 3]; 3] {
    let Some(f) = machine.standard_form() else {
        return jacobian_general(
            &machine.rotary,
            machine.primary_sense,
            machine.c_sense,
            p_deg,
            c_deg,
        );
    };
    let (sin_p, cos_p) = p_deg.to_radians().sin_cos();
    let sp = f.sp;
    let sc = f.sc;
    let (sin_c, cos_c) = (sc * c_deg).to_radians().sin_cos();
    let h = sp * sin_p;
    let k = std::f64::consts::PI / 180.0;
    match f.primary {
        PrimaryAxis::A => [
            [h * sin_c, -h * cos_c, cos_p],
            [k * sp * cos_p * sin_c, -k * sp * cos_p * cos_c, -k * sin_p],
            [k * sc * h * cos_c, k * sc * h * sin_c, 0.0],
        ],
        PrimaryAxis::B => [
            [h * cos_c, h * sin_c, cos_p],
            [k * sp * cos_p * cos_c, k * sp * cos_p * sin_c, -k * sin_p],
            [-k * sc * h * sin_c, k * sc * h * cos_c, 0.0],
        ],
    }
}

/// The angle between two tool axes, degrees, in [0, 180]: `atan2(|a × b|, a·b)`, accurate
/// for tiny and near-180° angles alike (`acos` of the dot product is not). The vectors need
/// not be normalised; a zero vector gives 0.
pub fn angle_between_deg(a: [f64; 3], b: [f64; 3]) -> f64 {
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let sin = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
    let cos = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    sin.atan2(cos).to_degrees()
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

    /// The Jacobian against central finite differences, every machine kind, angles
    /// including the pole and C at ±180°.
    #[test]
    fn jacobian_matches_finite_differences() {
        let h = 1e-6;
        for m in crate::testutil::all_kinds() {
            for &p in &ANGLES_DEG {
                for &c in &ANGLES_DEG {
                    let [o, dp, dc] = forward_jacobian(&m, p, c);
                    assert_close(o, forward(&m, p, c), "value");
                    let fp = |a: f64| forward(&m, a, c);
                    let fc = |a: f64| forward(&m, p, a);
                    for k in 0..3 {
                        let np = (fp(p + h)[k] - fp(p - h)[k]) / (2.0 * h);
                        let nc = (fc(c + h)[k] - fc(c - h)[k]) / (2.0 * h);
                        assert!((np - dp[k]).abs() < 1e-8, "dP {k} at P={p} C={c}");
                        assert!((nc - dc[k]).abs() < 1e-8, "dC {k} at P={p} C={c}");
                    }
                    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    let per_rad = 180.0 / std::f64::consts::PI;
                    assert!((norm(dp) * per_rad - 1.0).abs() < 1e-12);
                    assert!((norm(dc) * per_rad - p.to_radians().sin().abs()).abs() < 1e-12);
                }
            }
        }
    }

    /// The angle is exact for planted pairs, tiny or near 180°.
    #[test]
    fn angle_between_planted() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        for d in [0.0, 1e-9, 1e-4, 0.3, 45.0, 179.9999] {
            let a = forward(&m, 10.0, 30.0);
            let b = forward(&m, 10.0 + d, 30.0);
            assert!((angle_between_deg(a, b) - d).abs() < 1e-9, "{d}");
        }
        // Same axis, other branch: 0.
        let a = forward(&m, 3.0, 20.0);
        let b = forward(&m, -3.0, 200.0);
        assert!(angle_between_deg(a, b) < 1e-12);
        assert_eq!(angle_between_deg([0.0; 3], [0.0, 0.0, 1.0]), 0.0);
    }
}
