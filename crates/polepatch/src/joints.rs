//! Joint arrays held in memory, for CAM plugins that hold CL points rather than a file:
//! the machine's inverse kinematics on CL points ([`cl_to_joints`]) and the patcher on one
//! run of joint values ([`patch_joints`]). The C ABI (`pp_cl_to_joints`,
//! `pp_patch_joints`) and the Python package (`cl_to_joints`, `patch_joints`) are thin
//! layers over these two functions.
//!
//! Arrays are per point, in the order of the rows: CL points `[x, y, z, i, j, k]` (tool
//! tip in the part frame, mm; tool axis, any length but zero) and joints `[x, y, z, p, c]`
//! (x y z as given — the tool tip in the part frame, as under TCPM — and the primary
//! rotary axis and C, degrees).

use crate::error::Error;
pub use crate::tolerances::SAME_TIP_MM;
pub use crate::tolerances::ZERO_AXIS_NORM;
use polepatch_kinematics::{BranchRule, Machine, inverse_path};
use polepatch_patcher::{PatchOptions, Path, ZoneReport, patch_path};

/// Joints for CL points: each `[x, y, z, i, j, k]` becomes `[x, y, z, p, c]`, x y z as
/// given, p and c in degrees from the machine's inverse kinematics with `rule` (C
/// continuous along the points). The tool axis is normalised here.
///
/// Errors: a value that is not finite, or a zero tool axis ([`Error::Point`]).
pub fn cl_to_joints(
    machine: &Machine,
    cl_xyzijk: &[[f64; 6]],
    rule: BranchRule,
) -> Result<Vec<[f64; 5]>, Error> {
    let mut axes = Vec::with_capacity(cl_xyzijk.len());
    for (index, p) in cl_xyzijk.iter().enumerate() {
        if let Some(v) = p.iter().find(|v| !v.is_finite()) {
            return Err(Error::Point {
                index,
                message: format!("a value is not finite ({v})"),
            });
        }
        // Scaled by the largest component before normalising: the squares of
        // (1e300, 0, 1e300) overflow to infinity and the axis would become (0, 0, 0),
        // then NaN joints (issue 19 §5).
        let m = p[3].abs().max(p[4].abs()).max(p[5].abs());
        let v = if m > 0.0 {
            [p[3] / m, p[4] / m, p[5] / m]
        } else {
            [0.0; 3]
        };
        let unit = v[0].hypot(v[1]).hypot(v[2]);
        if m * unit < ZERO_AXIS_NORM {
            return Err(Error::Point {
                index,
                message: format!("the tool axis ({}, {}, {}) is zero", p[3], p[4], p[5]),
            });
        }
        axes.push([v[0] / unit, v[1] / unit, v[2] / unit]);
    }
    let joints = inverse_path(machine, &axes, rule);
    // Nothing is returned unless every point has joints.
    if let Some(index) = joints
        .iter()
        .position(|s| !(s.p_deg.is_finite() && s.c_deg.is_finite()))
    {
        let p = &cl_xyzijk[index];
        return Err(Error::Point {
            index,
            message: format!(
                "no joint values for the tool axis ({}, {}, {})",
                p[3], p[4], p[5]
            ),
        });
    }
    // A joint value the machine cannot reach is an error, never a silent result: the
    // primary axis outside its range on the branch the rule picked (issue 26: A = 180° on
    // a machine whose range ends at 120°), or C outside a bounded range.
    let letter = machine.primary_letter();
    for (index, s) in joints.iter().enumerate() {
        let (lo, hi) = machine.primary_range_deg;
        if !(lo..=hi).contains(&s.p_deg) {
            return Err(Error::OutOfRange {
                index,
                message: format!(
                    "{letter} = {:.6}° is outside the machine's range {lo}° to {hi}°",
                    s.p_deg
                ),
            });
        }
        if let Some((lo, hi)) = machine.c_range_deg
            && !(lo..=hi).contains(&s.c_deg)
        {
            return Err(Error::OutOfRange {
                index,
                message: format!(
                    "C = {:.6}° is outside the machine's range {lo}° to {hi}°",
                    s.c_deg
                ),
            });
        }
    }
    Ok(cl_xyzijk
        .iter()
        .zip(&joints)
        .map(|(p, s)| [p[0], p[1], p[2], s.p_deg, s.c_deg])
        .collect())
}

/// The patcher's [`Path`] of one run of joint values moved through in order at
/// `feed_mm_min`: s is the cumulative length of the tool-tip path (x y z).
///
/// Errors: fewer than two points or a feed that is not positive ([`Error::Path`]), a
/// value that is not finite, or two consecutive points with the same tool tip
/// ([`Error::Point`], naming the second).
pub fn joints_path(xyzpc: &[[f64; 5]], feed_mm_min: f64) -> Result<Path, Error> {
    if xyzpc.len() < 2 {
        return Err(polepatch_patcher::PathError::TooShort(xyzpc.len()).into());
    }
    if !(feed_mm_min.is_finite() && feed_mm_min > 0.0) {
        return Err(polepatch_patcher::PathError::BadFeed(feed_mm_min).into());
    }
    let mut s_mm = Vec::with_capacity(xyzpc.len());
    let mut s = 0.0;
    for (index, q) in xyzpc.iter().enumerate() {
        if let Some(v) = q.iter().find(|v| !v.is_finite()) {
            return Err(Error::Point {
                index,
                message: format!("a value is not finite ({v})"),
            });
        }
        if index > 0 {
            let b = &xyzpc[index - 1];
            let d = ((q[0] - b[0]).powi(2) + (q[1] - b[1]).powi(2) + (q[2] - b[2]).powi(2)).sqrt();
            if d < SAME_TIP_MM {
                return Err(Error::Point {
                    index,
                    message: format!(
                        "the same tool tip as point {} ({}, {}, {}): split the run there",
                        index - 1,
                        q[0],
                        q[1],
                        q[2]
                    ),
                });
            }
            s += d;
        }
        s_mm.push(s);
    }
    Ok(Path {
        s_mm,
        axes: xyzpc.to_vec(),
        feed_mm_min,
    })
}

/// What [`patch_joints`] gives back.
#[derive(Debug, Clone, PartialEq)]
pub struct JointsPatch {
    /// The points with the new p and c (x y z unchanged; p and c rounded to
    /// `max_decimals` where changed, the input value where not).
    pub xyzpc: Vec<[f64; 5]>,
    /// One report per singular zone.
    pub zones: Vec<ZoneReport>,
}

/// Patch one run of joint values ([`joints_path`]) with the patcher's options `opts`.
///
/// The values are not read from a file, so there is no file precision to keep: changed
/// values are verified and written rounded to `opts.max_decimals` (`c_decimals` and
/// `p_decimals` are set to it). The first and the last point keep their values (what
/// comes before and after the run is not known here).
///
/// Errors: bad options ([`crate::options::check_patcher_options`]) and the refusals of
/// [`joints_path`].
pub fn patch_joints(
    machine: &Machine,
    xyzpc: &[[f64; 5]],
    feed_mm_min: f64,
    opts: &PatchOptions,
) -> Result<JointsPatch, Error> {
    crate::options::check_patcher_options(opts)?;
    let path = joints_path(xyzpc, feed_mm_min)?;
    let opts = PatchOptions {
        c_decimals: opts.max_decimals,
        p_decimals: opts.max_decimals,
        keep_last_point: true,
        ..opts.clone()
    };
    let result = patch_path(&path, machine, &opts)?;
    let xyzpc = path
        .axes
        .iter()
        .zip(result.p_deg.iter().zip(&result.c_deg))
        .map(|(q, (&p, &c))| [q[0], q[1], q[2], p, c])
        .collect();
    Ok(JointsPatch {
        xyzpc,
        zones: result.zones,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use polepatch_kinematics::forward;

    fn ucp710() -> Machine {
        Machine::builtin("mikron-ucp710").unwrap()
    }

    #[test]
    fn cl_to_joints_inverts_forward_kinematics_and_normalises() {
        let m = ucp710();
        let joints = [(14.825, 137.259), (1.0, 180.0), (0.5, -170.0), (-3.0, 12.0)];
        let cl: Vec<[f64; 6]> = joints
            .iter()
            .enumerate()
            .map(|(k, &(p, c))| {
                let o = forward(&m, p, c);
                [k as f64, 0.0, -8.0, 3.0 * o[0], 3.0 * o[1], 3.0 * o[2]]
            })
            .collect();
        let out = cl_to_joints(&m, &cl, BranchRule::Nearest).unwrap();
        for (q, p) in out.iter().zip(&cl) {
            assert_eq!(&q[..3], &p[..3]);
            let o = forward(&m, q[3], q[4]);
            for i in 0..3 {
                assert!((o[i] - p[3 + i] / 3.0).abs() < 1e-12, "{q:?} {p:?}");
            }
        }
    }

    #[test]
    fn bad_points_are_refused_by_index() {
        let m = ucp710();
        let cl = [
            [0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        ];
        match cl_to_joints(&m, &cl, BranchRule::Nearest) {
            Err(Error::Point { index: 1, message }) => {
                assert!(message.contains("zero"), "{message}")
            }
            other => panic!("{other:?}"),
        }
        let cl = [[f64::NAN, 0.0, 0.0, 0.0, 0.0, 1.0]];
        assert!(matches!(
            cl_to_joints(&m, &cl, BranchRule::Nearest),
            Err(Error::Point { index: 0, .. })
        ));
        let still = [[0.0, 0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 2.0, 90.0]];
        match joints_path(&still, 1000.0) {
            Err(Error::Point { index: 1, message }) => {
                assert!(message.contains("same tool tip"), "{message}")
            }
            other => panic!("{other:?}"),
        }
        let one = [[0.0, 0.0, 0.0, 1.0, 0.0]];
        assert!(matches!(joints_path(&one, 1000.0), Err(Error::Path(_))));
        let two = [[0.0, 0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 1.0, 0.0]];
        assert!(matches!(joints_path(&two, 0.0), Err(Error::Path(_))));
        let bad = PatchOptions {
            margin: 0.5,
            ..PatchOptions::default()
        };
        assert!(matches!(
            patch_joints(&m, &two, 1000.0, &bad),
            Err(Error::Options(e)) if e.field == "margin"
        ));
    }

    #[test]
    fn s_is_the_tool_tip_length() {
        let pts = [
            [0.0, 0.0, 0.0, 1.0, 0.0],
            [3.0, 4.0, 0.0, 1.0, 0.0],
            [3.0, 4.0, 12.0, 1.0, 0.0],
        ];
        let p = joints_path(&pts, 1000.0).unwrap();
        assert_eq!(p.s_mm, vec![0.0, 5.0, 17.0]);
        assert_eq!(p.axes, pts.to_vec());
    }
}
