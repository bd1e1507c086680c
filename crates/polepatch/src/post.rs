//! `polepatch post`: CL points (G16's stage 1) → joints by the machine's inverse
//! kinematics → a TCPM NC program in a chosen dialect → (unless asked not to) the one
//! patch pipeline, [`crate::patch_nc`], on that program.
//!
//! A post-processor with pole handling: the program is written first exactly as the IK
//! gives it (`--no-patch` stops there), then patched like any other program, so `post` and
//! `patch` can never disagree.

use crate::error::Error;
use crate::patch::FileReport;
use polepatch_cl::ClProgram;
use polepatch_kinematics::{BranchRule, Machine, inverse_path};
use polepatch_nc::Dialect;
use polepatch_nc::emit::{EmitOptions, EmitPoint, emit};

/// Options of [`post_cl`]. Plain struct; see each field for its default.
#[derive(Debug, Clone, PartialEq)]
pub struct PostOptions {
    /// Dialect written. Default Heidenhain ISO.
    pub dialect: Dialect,
    /// IK branch rule. Default [`BranchRule::Nearest`].
    pub branch: BranchRule,
    /// Patch the posted program (default `true`); `false` writes the joints as the IK
    /// gives them.
    pub patch: bool,
    /// Options of the patch (name, feed fallback for points without a feed, …).
    pub patch_options: crate::PatchOptions,
    /// Decimals of rotary words. Default 3.
    pub rotary_decimals: usize,
    /// Decimals of linear words. Default 3.
    pub linear_decimals: usize,
}

impl Default for PostOptions {
    fn default() -> Self {
        PostOptions {
            dialect: Dialect::Heidenhain,
            branch: BranchRule::Nearest,
            patch: true,
            patch_options: crate::PatchOptions::default(),
            rotary_decimals: 3,
            linear_decimals: 3,
        }
    }
}

/// Read a CL file (APT or CSV, [`polepatch_cl::parse`]); errors name `name`, the line and
/// the column.
pub fn read_cl(bytes: &[u8], name: &str) -> Result<ClProgram, Error> {
    polepatch_cl::parse(bytes).map_err(|record| Error::Cl {
        path: name.to_string(),
        record,
    })
}

/// The points of `cl` as joints for `machine` (x y z as given, primary and C by IK).
/// Errors name the CL line of a point that needs the primary axis outside its range or has
/// no feed.
pub fn cl_joints(
    cl: &ClProgram,
    machine: &Machine,
    opts: &PostOptions,
) -> Result<Vec<EmitPoint>, Error> {
    let name = &opts.patch_options.name;
    let axes: Vec<[f64; 3]> = cl.points.iter().map(|p| p.axis).collect();
    let ik = inverse_path(machine, &axes, opts.branch);
    let (lo, hi) = machine.primary_range_deg;
    let fallback = opts.patch_options.feed_fallback_mm_min;
    cl.points
        .iter()
        .zip(ik)
        .map(|(p, s)| {
            if !(lo <= s.p_deg && s.p_deg <= hi) {
                return Err(Error::Unsupported {
                    path: name.clone(),
                    line: p.line,
                    what: format!(
                        "the tool axis ({:.6}, {:.6}, {:.6}) needs {}{:.3}, outside the machine's range [{lo}, {hi}] on either IK branch",
                        p.axis[0],
                        p.axis[1],
                        p.axis[2],
                        machine.primary_letter(),
                        s.p_deg
                    ),
                });
            }
            let feed = p.feed_mm_min.or(fallback);
            if !p.rapid && feed.is_none() {
                return Err(Error::Unsupported {
                    path: name.clone(),
                    line: p.line,
                    what: "no feed for this move (no FEDRAT before it, no f column): give --feed"
                        .into(),
                });
            }
            Ok(EmitPoint {
                xyz_mm: p.pos_mm,
                p_deg: s.p_deg,
                c_deg: s.c_deg,
                feed_mm_min: if p.rapid { None } else { feed },
                rapid: p.rapid,
            })
        })
        .collect()
}

/// Post a CL program for `machine`: the NC bytes and, when patched, the patch report.
pub fn post_cl(
    cl: &ClProgram,
    machine: &Machine,
    opts: &PostOptions,
) -> Result<(Vec<u8>, Option<FileReport>), Error> {
    let points = cl_joints(cl, machine, opts)?;
    let program_name = cl
        .name
        .clone()
        .unwrap_or_else(|| "POLEPATCH".to_string())
        .split_whitespace()
        .next()
        .unwrap_or("POLEPATCH")
        .to_string();
    let mut comments = vec![format!(
        "posted by polepatch for {} from {}",
        machine.name, opts.patch_options.name
    )];
    comments.extend(cl.notes.iter().take(20).cloned());
    let bytes = emit(
        &points,
        &EmitOptions {
            dialect: opts.dialect,
            name: program_name,
            primary_letter: machine.primary_letter() as u8,
            rotary_decimals: opts.rotary_decimals,
            linear_decimals: opts.linear_decimals,
            comments,
        },
    );
    if !opts.patch {
        return Ok((bytes, None));
    }
    let (out, report) = crate::patch_nc(&bytes, machine, &opts.patch_options)?;
    Ok((out, Some(report)))
}
