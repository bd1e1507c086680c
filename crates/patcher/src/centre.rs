//! Keeping a ball-end mill's centre where the program states its tip.
//!
//! G16's premise is a ball whose **centre** is programmed: every orientation keeps the
//! contact with the surface. Controllers' TCPM (`FUNCTION TCPM` by default, `TRAORI`,
//! `G43.4`, `G234`, LinuxCNC's TCP kinematics) and APT's `GOTO/` state the **tip**. The
//! centre of a ball of radius R is `c = tip + R·o` (o the unit tool axis, pointing from the
//! tip into the tool, in the part frame: [`polepatch_kinematics::forward`]). A point whose
//! orientation the patch turns from o to o′ keeps its centre when its tip is rewritten
//!
//! ```text
//! tip′ = c − R·o′ = tip + R·(o − o′)
//! ```
//!
//! and only then (|o − o′| = 2 sin(δ/2) for a turn by δ: with the tip kept the centre would
//! move by 2R·sin(δ/2), 87 µm for a D10 ball at 1°). The written tip is rounded to the
//! file's decimals ([`KeepCentre::decimals`], in its unit), so the centre of the written
//! block is within `R·|rounding of o′| + rounding of the tip` of the original: the rotary
//! words' rounding (10⁻⁶° at most 6 decimals: 9·10⁻⁸ mm for R = 5) and the tip's (half a
//! unit of the last decimal per axis). A point whose rotary values do not change keeps its
//! X Y Z exactly; so does a point moved to the other IK branch, whose tool axis is the same
//! (the difference is the rounding's, far below a decimal of X Y Z).
//!
//! The path the controller then runs has the written tips: its length s is recomputed
//! from them, and the driver's whole-run verification checks X, Y and Z as well as the
//! rotary axes on it ([`crate::driver`]).

use crate::path::Path;
use polepatch_kinematics::vec3::{along, sub};
use polepatch_kinematics::{Axis, Machine, forward};

/// Keep a ball's centre: the ball's radius and how X Y Z are written
/// ([`crate::PatchOptions::keep_centre`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeepCentre {
    /// Ball radius, mm (half the cutter's diameter).
    pub radius_mm: f64,
    /// Decimal places the file writes X Y Z with (values are rounded to them in its unit).
    pub decimals: usize,
    /// Millimetres per unit of the file's X Y Z words: 1 (mm) or 25.4 (inch).
    pub unit_mm: f64,
    /// The path's s follows the tip path's length (feed per minute, each segment scaled by
    /// its block's feed: [`segment_scale`]): it is recomputed from the written tips. False
    /// under inverse-time feed (G93), where s is the time-like parameter every block keeps
    /// (its F, its time, is not changed).
    pub s_is_length: bool,
}

impl KeepCentre {
    /// A value of mm as the controller receives it when written in the file's unit and
    /// decimals.
    pub fn written_mm(&self, v_mm: f64) -> f64 {
        crate::path::round_written(v_mm / self.unit_mm, self.decimals) * self.unit_mm
    }

    /// The tip that keeps the centre of the ball at `tip_mm` with the tool axis of
    /// (`p0_deg`, `c0_deg`) when the axis turns to (`p_deg`, `c_deg`), exact (not rounded).
    pub fn tip_mm(
        &self,
        machine: &Machine,
        tip_mm: [f64; 3],
        (p0_deg, c0_deg): (f64, f64),
        (p_deg, c_deg): (f64, f64),
    ) -> [f64; 3] {
        let o0 = forward(machine, p0_deg, c0_deg);
        let o1 = forward(machine, p_deg, c_deg);
        // tip + R·(o − o′): the centre tip + R·o less R·o′.
        along(tip_mm, sub(o0, o1), self.radius_mm)
    }
}

/// The path parameter over the tips `xyz_mm` (points `lo`… of `path`), from `s0`: their
/// cumulative length, each segment scaled as `path` scales it ([`segment_scale`]).
pub fn tip_length(path: &Path, lo: usize, s0: f64, xyz_mm: &[[f64; 3]]) -> Vec<f64> {
    let mut s = Vec::with_capacity(xyz_mm.len());
    let mut acc = s0;
    for (k, p) in xyz_mm.iter().enumerate() {
        if k > 0 {
            let q = xyz_mm[k - 1];
            let d = (0..3).map(|i| (p[i] - q[i]).powi(2)).sum::<f64>().sqrt();
            acc += d * segment_scale(path, lo + k);
        }
        s.push(acc);
    }
    s
}

/// How `path`'s parameter grows with its tool-tip length on the segment from point k − 1 to
/// k: 1 under one feed per minute (s is the tip length); F_ref/F_k in a pass whose blocks
/// have their own feeds, where s spaces the blocks by their time (a block of length L_k at
/// F_k spans L_k·F_ref/F_k). When the tips move (a ball's centre kept) a segment keeps its
/// feed, so its span scales with its new length by the same factor. 1 on a segment whose
/// tips do not move.
pub fn segment_scale(path: &Path, k: usize) -> f64 {
    let (a, b) = (&path.axes[k - 1], &path.axes[k]);
    let l = (0..3).map(|i| (b[i] - a[i]).powi(2)).sum::<f64>().sqrt();
    if l > crate::tolerances::ZERO_SEGMENT_MM {
        (path.s_mm[k] - path.s_mm[k - 1]) / l
    } else {
        1.0
    }
}

/// The path as written when its rotary values become `p`, `c`: with `keep`, the tip of
/// every point whose rotary values changed is rewritten to keep the ball's centre (rounded
/// as written) and s is the length of the written tips; without, only the rotary values
/// change. `None` where the written tips do not make a path (two points on one spot).
pub fn written_path(
    path: &Path,
    p: &[f64],
    c: &[f64],
    machine: &Machine,
    keep: Option<&KeepCentre>,
) -> Option<Path> {
    let (pi, ci) = (Axis::Primary.index(), Axis::C.index());
    let mut out = path.clone();
    for (k, q) in out.axes.iter_mut().enumerate() {
        let before = (q[pi], q[ci]);
        q[pi] = p[k];
        q[ci] = c[k];
        if let Some(keep) = keep
            && before != (p[k], c[k])
        {
            let tip = keep.tip_mm(machine, [q[0], q[1], q[2]], before, (p[k], c[k]));
            for i in 0..3 {
                let w = keep.written_mm(tip[i]);
                // An axis the compensation does not move by a unit of the last decimal
                // keeps its value as read (not a re-rounded copy of it).
                if w != keep.written_mm(q[i]) {
                    q[i] = w;
                }
            }
        }
    }
    if keep.is_some_and(|k| k.s_is_length) {
        for k in 1..out.s_mm.len() {
            let d = (0..3)
                .map(|i| (out.axes[k][i] - out.axes[k - 1][i]).powi(2))
                .sum::<f64>()
                .sqrt();
            out.s_mm[k] = out.s_mm[k - 1] + d * segment_scale(path, k);
            if d.is_nan() || d <= 0.0 {
                return None;
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ucp() -> Machine {
        Machine::builtin("mikron-ucp710").unwrap()
    }

    /// Planted: the UCP710's tool axis at (A, C) = (0, 0) is +z; at (1°, 90°) it is
    /// (sin 1°, 0, cos 1°) (i = sin C sin A). A D10 ball keeping its centre moves its tip by
    /// R·(o − o′) = 5·(−sin 1°, 0, 1 − cos 1°) — and the centre tip + R·o stays.
    #[test]
    fn the_compensation_of_a_planted_case() {
        let m = ucp();
        let keep = KeepCentre {
            radius_mm: 5.0,
            decimals: 6,
            unit_mm: 1.0,
            s_is_length: true,
        };
        let tip = [10.0, -3.0, 2.0];
        let new = keep.tip_mm(&m, tip, (0.0, 0.0), (1.0, 90.0));
        let a = 1f64.to_radians();
        let want = [10.0 - 5.0 * a.sin(), -3.0, 2.0 + 5.0 * (1.0 - a.cos())];
        for i in 0..3 {
            assert!((new[i] - want[i]).abs() < 1e-12, "{new:?} {want:?}");
        }
        let o0 = forward(&m, 0.0, 0.0);
        let o1 = forward(&m, 1.0, 90.0);
        for i in 0..3 {
            let (c0, c1) = (tip[i] + 5.0 * o0[i], new[i] + 5.0 * o1[i]);
            assert!((c0 - c1).abs() < 1e-12);
        }
        // The shift the tip takes is the one the centre would have taken: 2R·sin(δ/2).
        let shift = (0..3)
            .map(|i| (new[i] - tip[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!((shift - 10.0 * (a / 2.0).sin()).abs() < 1e-12);
    }

    /// The other IK branch keeps the tool axis: no X Y Z word changes; rounding to inch
    /// decimals happens in inches.
    #[test]
    fn a_branch_change_keeps_the_tip_and_inches_round_in_inches() {
        let m = ucp();
        let path = Path {
            s_mm: vec![0.0, 1.0, 2.0],
            axes: vec![
                [0.0, 0.0, 0.0, 2.0, 30.0],
                [1.0, 0.0, 0.0, 2.0, 40.0],
                [2.0, 0.0, 0.0, 2.0, 50.0],
            ],
            feed_mm_min: 1000.0,
        };
        let keep = KeepCentre {
            radius_mm: 5.0,
            decimals: 3,
            unit_mm: 1.0,
            s_is_length: true,
        };
        let p = [2.0, -2.0, 2.5];
        let c = [30.0, 220.0, 50.0];
        let out = written_path(&path, &p, &c, &m, Some(&keep)).unwrap();
        assert_eq!(out.axes[0], path.axes[0]);
        assert_eq!(out.axes[1][..3], path.axes[1][..3], "same tool axis");
        assert_ne!(out.axes[2][..3], path.axes[2][..3], "turned by 0.5°");
        let inch = KeepCentre {
            radius_mm: 6.35,
            decimals: 4,
            unit_mm: 25.4,
            s_is_length: true,
        };
        let v = inch.written_mm(1.23456789);
        assert!((v / 25.4 * 1e4 - (v / 25.4 * 1e4).round()).abs() < 1e-6);
        assert!((v - 1.23456789).abs() <= 0.5e-4 * 25.4 + 1e-12);
    }
}
