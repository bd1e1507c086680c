//! Circular and helical moves (`CIRCLE/…` or `MOVARC/…` followed by the end `GOTO`).
//!
//! An arc starts at the previous point `s` and ends at the `GOTO` point `e`. The record
//! gives a centre `c`, an axis `n` (unit) and a radius r; the motion is **counter-clockwise
//! about n** (right-hand rule), as in APT/ISO 4343 (`CIRCLE` with n = (0,0,−1) is a
//! clockwise arc seen from +Z). With `a = s − c` split into its part along n, `a·n`, and
//! its part in the plane, `a⊥`, and the same for e:
//!
//! ```text
//! θ  = angle from a⊥ to e⊥ counter-clockwise about n, in (0, 2π]   (2π: a full circle)
//! p(t) = c + (a·n)n + Rot(n, tθ) a⊥ + t·h·n,   t ∈ [0, 1],   h = (e − s)·n (helix lead)
//! ```
//!
//! `MOVARC/…,ANGLE,φ` states θ (degrees) and may exceed 360° (several turns).
//!
//! Both ends must lie on the circle: |‖a⊥‖ − r| and |‖e⊥‖ − r| within
//! [`ON_CIRCLE_TOL_MM`]; else the record is refused (a file whose arcs do not close is
//! damaged, or not what it seems).
//!
//! Chordal tolerance: a chord of angle δ on radius r is at most r(1 − cos(δ/2)) from the
//! circle, so [`Arc::segments`] takes δ = 2·acos(1 − tol/r) (and never more than 90°). The
//! same holds on a helix: the axial part is linear in t on both the chord and the helix.

pub use crate::tolerances::ON_CIRCLE_TOL_MM;
use crate::tolerances::{MAX_ARC_CHORDS, SLERP_OPPOSITE_RAD, SLERP_SAME_RAD};
use polepatch_kinematics::vec3::{add, cross, dot, norm, scale, sub};

/// A circular or helical move.
#[derive(Debug, Clone, PartialEq)]
pub struct Arc {
    /// Centre, part frame, mm (in the plane of the start point).
    pub center_mm: [f64; 3],
    /// Unit axis; the motion is counter-clockwise about it.
    pub normal: [f64; 3],
    /// Radius, mm.
    pub radius_mm: f64,
    /// Start point (the previous point), mm.
    pub start_mm: [f64; 3],
    /// Swept angle counter-clockwise about `normal`, radians, > 0 (2π: a full circle).
    pub sweep_rad: f64,
    /// Travel along `normal` from start to end, mm (0: a plane arc; else a helix).
    pub lead_mm: f64,
    /// Tool axis at the start (the previous point's).
    pub start_axis: [f64; 3],
}

/// A principal plane of the part frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    /// XY (G17), normal Z.
    Xy,
    /// ZX (G18), normal Y.
    Zx,
    /// YZ (G19), normal X.
    Yz,
}

impl Plane {
    /// Index of the normal axis (X 0, Y 1, Z 2).
    pub fn normal_index(self) -> usize {
        match self {
            Plane::Xy => 2,
            Plane::Zx => 1,
            Plane::Yz => 0,
        }
    }
}

/// `v` rotated by `angle` radians counter-clockwise about the unit axis `n` (Rodrigues).
fn rotate(v: [f64; 3], n: [f64; 3], angle: f64) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    let k = cross(n, v);
    let d = dot(n, v) * (1.0 - c);
    [
        v[0] * c + k[0] * s + n[0] * d,
        v[1] * c + k[1] * s + n[1] * d,
        v[2] * c + k[2] * s + n[2] * d,
    ]
}

/// Great-circle interpolation between unit vectors `a` and `b` at fraction `t`; `None`
/// when they are opposite.
pub fn slerp(a: [f64; 3], b: [f64; 3], t: f64) -> Option<[f64; 3]> {
    let c = cross(a, b);
    let angle = norm(c).atan2(dot(a, b));
    if angle < SLERP_SAME_RAD {
        return Some(a);
    }
    if std::f64::consts::PI - angle < SLERP_OPPOSITE_RAD {
        return None;
    }
    let s = angle.sin();
    let (wa, wb) = (((1.0 - t) * angle).sin() / s, (t * angle).sin() / s);
    let v = add(scale(a, wa), scale(b, wb));
    let n = norm(v);
    Some(scale(v, 1.0 / n))
}

/// Why the values of an arc's record make no arc (the caller adds line and column).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ArcError {
    /// The radius is not positive.
    #[error("radius {radius_mm} must be positive")]
    Radius {
        /// The radius given, mm.
        radius_mm: f64,
    },
    /// An end point is more than [`ON_CIRCLE_TOL_MM`] off the circle.
    #[error(
        "the {which} point ({:.4}, {:.4}, {:.4}) is {off_mm:.4} mm off the circle (centre ({:.4}, {:.4}, {:.4}), radius {radius_mm}); more than {tol} mm",
        .point_mm[0], .point_mm[1], .point_mm[2], .center_mm[0], .center_mm[1], .center_mm[2],
        tol = ON_CIRCLE_TOL_MM
    )]
    OffCircle {
        /// `start` or `end`.
        which: &'static str,
        /// The end point, mm.
        point_mm: [f64; 3],
        /// Its distance from the circle, mm.
        off_mm: f64,
        /// The circle's centre, mm.
        center_mm: [f64; 3],
        /// The circle's radius, mm.
        radius_mm: f64,
    },
    /// A stated sweep (`ANGLE`) is not positive.
    #[error("ANGLE {deg}° must be positive (the direction is the axis's)")]
    Angle {
        /// The sweep stated, degrees.
        deg: f64,
    },
    /// A stated sweep does not end at the end point.
    #[error(
        "ANGLE {deg}° does not end at the end point ({:.4}° from the start point about the axis)",
        .end_rad.to_degrees()
    )]
    AngleEnd {
        /// The sweep stated, degrees.
        deg: f64,
        /// The end point's angle from the start point about the axis, radians.
        end_rad: f64,
    },
}

impl Arc {
    /// The arc from `start` to `end` on the circle (`center`, unit `normal`, `radius`),
    /// counter-clockwise about `normal`; `sweep_deg` when the record states it (MOVARC).
    /// Errors say what does not fit (the caller adds line and column).
    pub fn new(
        center: [f64; 3],
        normal: [f64; 3],
        radius_mm: f64,
        start: [f64; 3],
        end: [f64; 3],
        sweep_deg: Option<f64>,
        start_axis: [f64; 3],
    ) -> Result<Arc, ArcError> {
        if radius_mm.is_nan() || radius_mm <= 0.0 {
            return Err(ArcError::Radius { radius_mm });
        }
        let a = sub(start, center);
        let b = sub(end, center);
        let (a_ax, b_ax) = (dot(a, normal), dot(b, normal));
        let a_pl = sub(a, scale(normal, a_ax));
        let b_pl = sub(b, scale(normal, b_ax));
        for (which, v, p) in [("start", a_pl, start), ("end", b_pl, end)] {
            let off = (norm(v) - radius_mm).abs();
            if off > ON_CIRCLE_TOL_MM {
                return Err(ArcError::OffCircle {
                    which,
                    point_mm: p,
                    off_mm: off,
                    center_mm: center,
                    radius_mm,
                });
            }
        }
        let mut theta = dot(normal, cross(a_pl, b_pl)).atan2(dot(a_pl, b_pl));
        // The ends coincide in the plane: a full circle, not a zero-length arc.
        let closed = norm(sub(a_pl, b_pl)) <= ON_CIRCLE_TOL_MM;
        if closed || theta <= 0.0 {
            theta += std::f64::consts::TAU;
        }
        if closed {
            theta = std::f64::consts::TAU;
        }
        if let Some(deg) = sweep_deg {
            let stated = deg.to_radians();
            if stated.is_nan() || stated <= 0.0 {
                return Err(ArcError::Angle { deg });
            }
            // The stated angle must end where the end point is.
            let turns = ((stated - theta) / std::f64::consts::TAU).round();
            let off = (stated - theta - turns * std::f64::consts::TAU).abs() * radius_mm;
            if off > ON_CIRCLE_TOL_MM || turns < 0.0 {
                return Err(ArcError::AngleEnd {
                    deg,
                    end_rad: theta,
                });
            }
            theta = stated;
        }
        Ok(Arc {
            center_mm: add(center, scale(normal, a_ax)),
            normal,
            radius_mm,
            start_mm: start,
            sweep_rad: theta,
            lead_mm: b_ax - a_ax,
            start_axis,
        })
    }

    /// The point at fraction `t` ∈ [0, 1] of the sweep (module docs).
    pub fn point_at(&self, t: f64) -> [f64; 3] {
        let a = sub(self.start_mm, self.center_mm);
        let r = rotate(a, self.normal, t * self.sweep_rad);
        add(add(self.center_mm, r), scale(self.normal, t * self.lead_mm))
    }

    /// Number of chords that keep every chord within `tol_mm` of the arc (module docs).
    pub fn segments(&self, tol_mm: f64) -> usize {
        let r = self.radius_mm;
        let max_step = std::f64::consts::FRAC_PI_2;
        let step = if tol_mm >= r {
            max_step
        } else {
            (2.0 * (1.0 - tol_mm / r).acos()).min(max_step)
        };
        let n = (self.sweep_rad / step).ceil();
        // A tolerance far below the radius' precision would ask for billions of chords:
        // bounded (the caller checks the tolerance's range).
        n.clamp(1.0, MAX_ARC_CHORDS) as usize
    }

    /// The chord end points from the first after the start to `end` (the caller's exact end
    /// point, which the last chord ends at), `segments(tol_mm)` of them.
    pub fn chord_points(&self, tol_mm: f64, end: [f64; 3]) -> Vec<[f64; 3]> {
        let n = self.segments(tol_mm);
        (1..=n)
            .map(|k| {
                if k == n {
                    end
                } else {
                    self.point_at(k as f64 / n as f64)
                }
            })
            .collect()
    }

    /// The principal plane the arc lies in, when its axis is that plane's normal (either
    /// sense) closely enough that the circle leaves the plane by at most `tol_mm`:
    /// r·sin(angle between the axis and the plane normal) ≤ `tol_mm`.
    pub fn principal_plane(&self, tol_mm: f64) -> Option<Plane> {
        [Plane::Yz, Plane::Zx, Plane::Xy].into_iter().find(|p| {
            let i = p.normal_index();
            let off_axis = (0..3)
                .filter(|&k| k != i)
                .map(|k| self.normal[k] * self.normal[k])
                .sum::<f64>()
                .sqrt();
            self.radius_mm * off_axis <= tol_mm
        })
    }

    /// The tool axis at fraction `t` of the sweep when it turns from `start_axis` to
    /// `end_axis` along the arc: the great-circle interpolation (slerp) in proportion to the
    /// swept angle; `None` when the two are opposite (no unique turn).
    pub fn axis_at(&self, t: f64, end_axis: [f64; 3]) -> Option<[f64; 3]> {
        slerp(self.start_axis, end_axis, t)
    }

    /// Distance from `p` to the arc (mm): to the point of the arc at `p`'s own angle about
    /// the axis (the helix height taken there), or to an end of the arc when `p`'s angle is
    /// outside the sweep. An upper bound of the true distance, exact on the arc.
    pub fn distance_mm(&self, p: [f64; 3]) -> f64 {
        let v = sub(p, self.center_mm);
        let ax = dot(v, self.normal);
        let pl = sub(v, scale(self.normal, ax));
        let radial = norm(pl) - self.radius_mm;
        let a = sub(self.start_mm, self.center_mm);
        let mut phi = dot(self.normal, cross(a, pl)).atan2(dot(a, pl));
        if phi < 0.0 {
            phi += std::f64::consts::TAU;
        }
        let mut best = norm(sub(p, self.start_mm)).min(norm(sub(p, self.point_at(1.0))));
        let turns = (self.sweep_rad / std::f64::consts::TAU).ceil() as i64;
        for k in 0..=turns {
            let ang = phi + k as f64 * std::f64::consts::TAU;
            if ang <= self.sweep_rad {
                let h = ax - ang / self.sweep_rad * self.lead_mm;
                best = best.min(radial.hypot(h));
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const Z: [f64; 3] = [0.0, 0.0, 1.0];

    #[test]
    fn quarter_circles_both_senses() {
        // Counter-clockwise about +Z from (10,0) to (0,10): a quarter.
        let a = Arc::new(
            [0.0; 3],
            Z,
            10.0,
            [10.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
            None,
            Z,
        )
        .unwrap();
        assert!((a.sweep_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let m = a.point_at(0.5);
        assert!((m[0] - 10.0 / 2f64.sqrt()).abs() < 1e-12 && m[1] > 0.0);
        // About −Z the same ends are three quarters.
        let b = Arc::new(
            [0.0; 3],
            [0.0, 0.0, -1.0],
            10.0,
            [10.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
            None,
            Z,
        )
        .unwrap();
        assert!((b.sweep_rad - 1.5 * std::f64::consts::PI).abs() < 1e-12);
        assert!(b.point_at(0.5)[1] < 0.0, "passes through negative y");
    }

    #[test]
    fn closed_arcs_are_full_circles_and_angle_states_turns() {
        let s = [5.0, 0.0, 0.0];
        let a = Arc::new([0.0; 3], Z, 5.0, s, s, None, Z).unwrap();
        assert_eq!(a.sweep_rad, std::f64::consts::TAU);
        let b = Arc::new([0.0; 3], Z, 5.0, s, [5.0, 0.0, -2.0], Some(720.0), Z).unwrap();
        assert!((b.sweep_rad - 2.0 * std::f64::consts::TAU).abs() < 1e-12);
        assert_eq!(b.lead_mm, -2.0);
        assert!(Arc::new([0.0; 3], Z, 5.0, s, [0.0, 5.0, 0.0], Some(180.0), Z).is_err());
    }

    /// The distance is to the arc, not to its whole circle: the other side is far.
    #[test]
    fn distance_is_to_the_arc() {
        let a = Arc::new(
            [0.0; 3],
            Z,
            10.0,
            [10.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
            None,
            Z,
        )
        .unwrap();
        assert!(a.distance_mm([0.0, 10.0, 0.0]) < 1e-12);
        assert!((a.distance_mm([0.0, 11.0, 0.5]) - 1.25f64.sqrt()).abs() < 1e-12);
        // (0, −10) is on the circle, not on the quarter: nearest the start.
        assert!((a.distance_mm([0.0, -10.0, 0.0]) - 200f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn ends_off_the_circle_are_refused() {
        let e = Arc::new(
            [0.0; 3],
            Z,
            10.0,
            [10.0, 0.0, 0.0],
            [0.0, 10.1, 0.0],
            None,
            Z,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("end point") && e.contains("0.1000 mm off"),
            "{e}"
        );
        assert!(Arc::new([0.0; 3], Z, 0.0, [0.0; 3], [0.0; 3], None, Z).is_err());
    }

    /// Each refusal names its values, in the words the reader has always used (the
    /// caller prefixes `CIRCLE: ` and the line and column).
    #[test]
    fn arc_errors_name_their_values() {
        let s = [5.0, 0.0, 0.0];
        let msg = |r: Result<Arc, ArcError>| r.unwrap_err().to_string();
        assert_eq!(
            msg(Arc::new([0.0; 3], Z, 0.0, s, s, None, Z)),
            "radius 0 must be positive"
        );
        assert_eq!(
            msg(Arc::new(
                [0.0; 3],
                Z,
                10.0,
                [10.0, 0.0, 0.0],
                [0.0, 10.1, 0.0],
                None,
                Z
            )),
            "the end point (0.0000, 10.1000, 0.0000) is 0.1000 mm off the circle (centre (0.0000, 0.0000, 0.0000), radius 10); more than 0.005 mm"
        );
        assert_eq!(
            msg(Arc::new(
                [0.0; 3],
                Z,
                5.0,
                s,
                [0.0, 5.0, 0.0],
                Some(-5.0),
                Z
            )),
            "ANGLE -5° must be positive (the direction is the axis's)"
        );
        assert_eq!(
            msg(Arc::new(
                [0.0; 3],
                Z,
                5.0,
                s,
                [0.0, 5.0, 0.0],
                Some(180.0),
                Z
            )),
            "ANGLE 180° does not end at the end point (90.0000° from the start point about the axis)"
        );
    }

    /// Every chord end is on the circle and every chord's midpoint within the tolerance,
    /// for tolerances and radii over several decades, planar and helical.
    #[test]
    fn chords_stay_within_the_tolerance() {
        for (r, tol, lead) in [
            (10.0, 0.001, 0.0),
            (0.5, 0.001, 0.0),
            (250.0, 0.0001, 0.0),
            (3.0, 0.01, -4.0),
            (0.01, 0.001, 0.0),
        ] {
            let n = [0.6, 0.0, 0.8];
            let s = [r * 0.8, 7.0, -r * 0.6];
            let e_plane = [-r * 0.8, 7.0, r * 0.6];
            let e = add(e_plane, scale(n, lead));
            let a = Arc::new([0.0, 7.0, 0.0], n, r, s, e, None, n).unwrap();
            let pts = a.chord_points(tol, e);
            let mut prev = s;
            let mut worst = 0.0f64;
            for &p in &pts {
                assert!(a.distance_mm(p) < 1e-9, "r {r}: {p:?}");
                for f in [0.25, 0.5, 0.75] {
                    let q = add(prev, scale(sub(p, prev), f));
                    worst = worst.max(a.distance_mm(q));
                }
                prev = p;
            }
            assert!(worst <= tol * (1.0 + 1e-9), "r {r} tol {tol}: {worst}");
            assert_eq!(*pts.last().unwrap(), e);
        }
    }

    #[test]
    fn slerp_turns_at_a_constant_rate() {
        let a = [1.0, 0.0, 0.0];
        let b = [0.0, 0.6, 0.8];
        let mut prev = a;
        for k in 1..=10 {
            let v = slerp(a, b, k as f64 / 10.0).unwrap();
            assert!((norm(v) - 1.0).abs() < 1e-12);
            let step = norm(cross(prev, v)).atan2(dot(prev, v));
            assert!((step - std::f64::consts::FRAC_PI_2 / 10.0).abs() < 1e-12);
            prev = v;
        }
        assert!((norm(sub(prev, b))) < 1e-12);
        assert_eq!(slerp(a, [-1.0, 0.0, 0.0], 0.5), None);
        assert_eq!(slerp(a, a, 0.5), Some(a));
    }

    #[test]
    fn principal_planes() {
        let arc = |n: [f64; 3]| Arc {
            center_mm: [0.0; 3],
            normal: n,
            radius_mm: 100.0,
            start_mm: [0.0; 3],
            sweep_rad: 1.0,
            lead_mm: 0.0,
            start_axis: Z,
        };
        assert_eq!(
            arc([0.0, 0.0, -1.0]).principal_plane(0.001),
            Some(Plane::Xy)
        );
        assert_eq!(arc([0.0, 1.0, 0.0]).principal_plane(0.001), Some(Plane::Zx));
        assert_eq!(arc([1.0, 0.0, 0.0]).principal_plane(0.001), Some(Plane::Yz));
        // 1e-6 rad off Z on r = 100 leaves the plane by 1e-4 mm: XY.
        let t = 1e-6f64;
        assert_eq!(
            arc([t.sin(), 0.0, t.cos()]).principal_plane(0.001),
            Some(Plane::Xy)
        );
        // 1e-4 rad: 0.01 mm, a tilted circle.
        let t = 1e-4f64;
        assert_eq!(arc([t.sin(), 0.0, t.cos()]).principal_plane(0.001), None);
    }
}
