//! The machine frame: what the linear axes must do, from the machine's kinematic chain
//! ([`polepatch_kinematics::Chain`]) and the work offset.
//!
//! Two uses, both only when the machine description has a `[chain]`:
//!
//! - **Runs without TCPM** (X Y Z are machine coordinates minus the work offset) can be
//!   patched: the tool tip in the part frame is computed for every point (C17 eq. 1), the
//!   patcher changes the rotary values on that part-frame path exactly as for a TCPM run,
//!   and X Y Z are recomputed for every changed point from the *written* (rounded) rotary
//!   values, then rounded with at least [`MIN_XYZ_DECIMALS`] decimals, so the part-frame
//!   tool tip of the written block is within [`TIP_TOLERANCE_MM`] of the original.
//!   Between the points the controller interpolates every axis linearly (no TCPM), so the
//!   tool tip leaves the programmed line by a chord error that grows with the rotary step:
//!   every block whose values change is checked there ([`chord_error_mm`]), and a run
//!   where one would leave the line by more than the chord tolerance
//!   ([`CHORD_TOLERANCE_MM`] by default) — and by more than the original block did — keeps
//!   its original values. (Inserting intermediate points instead is not done.)
//! - **Every run with a chain** is checked in the machine frame after the patch: Equation 6
//!   on the machine-frame X Y Z (C17 eq. 6: near the pole the linear axes follow the
//!   table), before and after, span by span with the written program's rule
//!   ([`crate::verify::worse_spans`]: a span at feed stays at feed, one below it gets no
//!   lower); a run whose patch would make a span worse keeps its original values, and the
//!   report says where and why.
//!
//! # The path parameter s
//! Equation 6 needs the path the programmed feed refers to. With TCPM the controller
//! moves the tool tip along the part at F: s is the part-frame tool-tip length (the
//! run's s). Without TCPM the controller interpolates X Y Z at F: s is the length of the
//! program's X Y Z path (also the run's s as read). The machine-frame check uses those.
//! The patcher, for a run without TCPM, works on the part-frame path (s = part-frame tool
//! tip length, the cutting path the CAM system planned), which is what its orientation
//! deviation and continuity are about; the machine-frame check then decides on the
//! program as the controller will run it.
//!
//! # The work offset
//! [`crate::program::LoadedProgram::datum_mm`]: the last Heidenhain datum shift with values (`G54 X… Y… Z…`) before the
//! run when no other frame change came after it; else the caller's (`--work-offset`) when
//! the program changes its frame at most once before the run (it only names `G54`); else
//! unknown — the run is left as it is, with a message asking for `--work-offset`, and no
//! machine-frame check is made.

pub use crate::settings::CHORD_SAMPLES;
pub use crate::settings::CHORD_TOLERANCE_MM;
pub use crate::tolerances::MIN_XYZ_DECIMALS;
pub use crate::tolerances::PART_ZERO_LENGTH_MM;
pub use crate::tolerances::TIP_TOLERANCE_MM;
use polepatch_kinematics::{Chain, Machine};
use polepatch_patcher::Path;

/// The work offset of a run whose first block is `first` ([`crate::program::LoadedProgram::datum_mm`]), from the program's stated datum
/// shifts and other frame changes (block indices in file order, as in
/// [`polepatch_nc::Program`]).
pub fn datum_at(
    datum_shifts: &[(usize, [f64; 3])],
    frame_changes: &[usize],
    first: usize,
    given: Option<[f64; 3]>,
) -> Option<[f64; 3]> {
    let stated = datum_shifts.iter().rev().find(|(b, _)| *b <= first);
    let other = frame_changes.iter().rev().find(|&&b| b <= first);
    match (stated, other) {
        (Some((sb, d)), o) if o.is_none_or(|ob| ob < sb) => Some(*d),
        _ => {
            let changes = datum_shifts.iter().filter(|(b, _)| *b <= first).count()
                + frame_changes.iter().filter(|&&b| b <= first).count();
            if changes <= 1 { given } else { None }
        }
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn cumulative(points: &[[f64; 3]]) -> Vec<f64> {
    let mut s = Vec::with_capacity(points.len());
    let mut acc = 0.0;
    for (k, p) in points.iter().enumerate() {
        if k > 0 {
            acc += dist(points[k - 1], *p);
        }
        s.push(acc);
    }
    s
}

/// A run without TCPM as a part-frame path: the tool tip of every point through the
/// chain, s its length.
pub fn part_frame_path(chain: &Chain, machine: &Machine, datum_mm: [f64; 3], path: &Path) -> Path {
    let tips: Vec<[f64; 3]> = path
        .axes
        .iter()
        .map(|q| chain.part_tip(machine, datum_mm, q[3], q[4], [q[0], q[1], q[2]]))
        .collect();
    Path {
        s_mm: cumulative(&tips),
        axes: tips
            .iter()
            .zip(&path.axes)
            .map(|(t, q)| [t[0], t[1], t[2], q[3], q[4]])
            .collect(),
        feed_mm_min: path.feed_mm_min,
    }
}

/// The program's values `[X, Y, Z, P, C]` per point as the machine runs them: X Y Z in
/// the machine frame (minus the datum) and s as the controller's feed refers to it
/// (module docs).
pub fn machine_frame_path(
    chain: &Chain,
    machine: &Machine,
    datum_mm: [f64; 3],
    tcpm: bool,
    program_values: &[[f64; 5]],
    tcpm_s_mm: &[f64],
    feed_mm_min: f64,
) -> Path {
    let axes: Vec<[f64; 5]> = program_values
        .iter()
        .map(|q| {
            if tcpm {
                let x = chain.program_xyz(machine, datum_mm, q[3], q[4], [q[0], q[1], q[2]]);
                [x[0], x[1], x[2], q[3], q[4]]
            } else {
                *q
            }
        })
        .collect();
    let s_mm = if tcpm {
        tcpm_s_mm.to_vec()
    } else {
        let xyz: Vec<[f64; 3]> = axes.iter().map(|q| [q[0], q[1], q[2]]).collect();
        cumulative(&xyz)
    };
    Path {
        s_mm,
        axes,
        feed_mm_min,
    }
}

/// Largest distance of the part-frame tool tip from the programmed line `tips[0]`–`tips[1]`
/// while a block without TCPM moves from program values `from` to `to` (`[X, Y, Z, P, C]`),
/// every axis interpolated linearly as the controller does without TCPM: sampled at
/// [`CHORD_SAMPLES`] steps, mm.
pub fn chord_error_mm(
    chain: &Chain,
    machine: &Machine,
    datum_mm: [f64; 3],
    from: &[f64; 5],
    to: &[f64; 5],
    tips: [[f64; 3]; 2],
) -> f64 {
    let [a, b] = tips;
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let mut worst: f64 = 0.0;
    for i in 1..CHORD_SAMPLES {
        let u = i as f64 / CHORD_SAMPLES as f64;
        let q: [f64; 5] = std::array::from_fn(|j| from[j] + u * (to[j] - from[j]));
        let t = chain.part_tip(machine, datum_mm, q[3], q[4], [q[0], q[1], q[2]]);
        let at = [t[0] - a[0], t[1] - a[1], t[2] - a[2]];
        let w = if len2 > 0.0 {
            ((at[0] * ab[0] + at[1] * ab[1] + at[2] * ab[2]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let d = [at[0] - w * ab[0], at[1] - w * ab[1], at[2] - w * ab[2]];
        worst = worst.max((d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
    }
    worst
}

/// Round to `decimals`.
pub fn round_to(v: f64, decimals: usize) -> f64 {
    let k = 10f64.powi(decimals as i32);
    (v * k).round() / k
}

/// [`polepatch_patcher::patch_path`] on a part-frame path that may stand still at places:
/// each stretch between [`PART_ZERO_LENGTH_MM`] segments is patched on its own, its last
/// point kept unless it ends the path (then `opts.keep_last_point` decides), and the
/// results are put back together with zone indices of the whole path.
pub fn patch_part_frame(
    path: &Path,
    machine: &Machine,
    opts: &polepatch_patcher::PatchOptions,
) -> Result<polepatch_patcher::PatchResult, polepatch_patcher::PathError> {
    use polepatch_patcher::{PatchOptions, PatchResult, patch_path};
    let n = path.s_mm.len();
    let mut out = PatchResult::unchanged(path, opts);
    let mut a = 0;
    while a + 1 < n {
        let mut b = a;
        while b + 1 < n && path.s_mm[b + 1] - path.s_mm[b] > PART_ZERO_LENGTH_MM {
            b += 1;
        }
        if b > a {
            let sub = Path {
                s_mm: path.s_mm[a..=b].iter().map(|s| s - path.s_mm[a]).collect(),
                axes: path.axes[a..=b].to_vec(),
                feed_mm_min: path.feed_mm_min,
            };
            let sub_opts = PatchOptions {
                keep_last_point: opts.keep_last_point || b + 1 < n,
                ..opts.clone()
            };
            let r = patch_path(&sub, machine, &sub_opts)?;
            for k in 0..=b - a {
                out.p_deg[a + k] = r.p_deg[k];
                out.p_changed[a + k] = r.p_changed[k];
                out.c_deg[a + k] = r.c_deg[k];
                out.c_changed[a + k] = r.c_changed[k];
                // A ball's centre kept: the tips moved with the orientation (issue 39
                // class 4: without them the chain kept the tip, not the centre).
                out.xyz_mm[a + k] = r.xyz_mm[k];
                out.xyz_changed[a + k] = r.xyz_changed[k];
            }
            out.p_decimals = out.p_decimals.max(r.p_decimals);
            out.c_decimals = out.c_decimals.max(r.c_decimals);
            out.xyz_decimals = out.xyz_decimals.max(r.xyz_decimals);
            out.zones.extend(r.zones.into_iter().map(|mut z| {
                z.first += a;
                z.last += a;
                z
            }));
        }
        a = b + 1;
    }
    Ok(out)
}
