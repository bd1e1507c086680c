//! Reorienting the workpiece on a jig (C17 §3.2–3.4, its eq. 7): a rotation of the part
//! frame, `Ō_W = R_x(θx)·R_z(θz)·O_W`, applied to tool orientations and, about a pivot, to
//! tool-tip positions. θ in degrees; `R_x`, `R_z` right-handed rotations about the
//! workpiece frame's x and z axes.

/// The rotation `R = R_x(θx)·R_z(θz)` of a jig tilt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JigRotation {
    /// Row-major 3×3 matrix.
    pub m: [[f64; 3]; 3],
}

impl JigRotation {
    /// `R_x(theta_x_deg)·R_z(theta_z_deg)`.
    pub fn new(theta_x_deg: f64, theta_z_deg: f64) -> JigRotation {
        let (sx, cx) = theta_x_deg.to_radians().sin_cos();
        let (sz, cz) = theta_z_deg.to_radians().sin_cos();
        // R_x = [[1,0,0],[0,cx,-sx],[0,sx,cx]], R_z = [[cz,-sz,0],[sz,cz,0],[0,0,1]].
        JigRotation {
            m: [
                [cz, -sz, 0.0],
                [cx * sz, cx * cz, -sx],
                [sx * sz, sx * cz, cx],
            ],
        }
    }

    /// `R·v`.
    pub fn apply(&self, v: [f64; 3]) -> [f64; 3] {
        let m = &self.m;
        std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
    }

    /// `Rᵀ·v` (the inverse rotation).
    pub fn apply_inverse(&self, v: [f64; 3]) -> [f64; 3] {
        let m = &self.m;
        std::array::from_fn(|i| m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2])
    }

    /// A position rotated about `pivot`: `pivot + R·(x − pivot)`.
    pub fn apply_about(&self, pivot: [f64; 3], x: [f64; 3]) -> [f64; 3] {
        let r = self.apply([x[0] - pivot[0], x[1] - pivot[1], x[2] - pivot[2]]);
        [r[0] + pivot[0], r[1] + pivot[1], r[2] + pivot[2]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BranchRule, Machine, forward, inverse_path};

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
    }

    #[test]
    fn it_is_a_rotation_in_the_stated_order() {
        for (tx, tz) in [(10.0, 180.0), (-37.0, 12.5), (0.0, 90.0), (90.0, 0.0)] {
            let r = JigRotation::new(tx, tz);
            // Orthonormal with determinant +1.
            for v in [[1.0, 0.0, 0.0], [0.3, -0.4, 0.866], [0.0, 0.0, 1.0]] {
                let w = r.apply(v);
                let n = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
                assert!((n(w) - n(v)).abs() < 1e-12);
                assert!(close(r.apply_inverse(w), v, 1e-12));
            }
            let m = r.m;
            let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
            assert!((det - 1.0).abs() < 1e-12);
        }
        // R_z first: x̂ → (cos θz, sin θz, 0), then R_x tilts it.
        let r = JigRotation::new(90.0, 90.0);
        assert!(close(r.apply([1.0, 0.0, 0.0]), [0.0, 0.0, 1.0], 1e-12));
        // Right-handed about x: ŷ → ẑ for θx = 90°.
        let r = JigRotation::new(90.0, 0.0);
        assert!(close(r.apply([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0], 1e-12));
        // About a pivot: the pivot stays.
        let p = [25.0, 25.0, -8.0];
        assert!(close(
            JigRotation::new(10.0, 180.0).apply_about(p, p),
            p,
            1e-12
        ));
    }

    /// fk → rotate → ik → fk → rotate back returns the tool axis, at the pole and C ±180°.
    #[test]
    fn round_trip_through_ik() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let joints = [
            (0.0, 0.0),
            (1e-9, 180.0),
            (14.825, 137.259),
            (-30.0, -180.0),
        ];
        let axes: Vec<[f64; 3]> = joints.iter().map(|&(p, c)| forward(&m, p, c)).collect();
        let r = JigRotation::new(10.0, 180.0);
        let rotated: Vec<[f64; 3]> = axes.iter().map(|&o| r.apply(o)).collect();
        let ik = inverse_path(&m, &rotated, BranchRule::Nearest);
        for (k, s) in ik.iter().enumerate() {
            let back = r.apply_inverse(forward(&m, s.p_deg, s.c_deg));
            assert!(close(back, axes[k], 1e-12), "{k}");
        }
    }
}
