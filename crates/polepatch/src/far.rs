//! The no-zone fast path: prove from a streaming read that no run comes within the
//! singular cone, without building the program.
//!
//! A zone needs a CL point with |primary| ≤ the cone (`patcher::detect_zones`), so a
//! program none of whose run points is that close has no zone, and [`crate::patch_nc`]
//! returns it unchanged. [`far_from_pole`] decides that with [`polepatch_nc::scan`] and
//! [`polepatch_nc::RunBuilder`] — the same reading and the same runs as the full path,
//! one block and one run at a time — so memory is the input plus one run, and it stops
//! at the first run that comes near the pole (the full path then takes over).
//!
//! It answers only when the answer is the full path's exactly: whenever the report would
//! have more than the file name, the machine and a warning — a run without a feed, no
//! run at all, no rotary words — it says "not decided" and the full path runs (and gives
//! the error or the report).

use crate::patch::FileReport;
use crate::program::primary_mismatch_warning;
use polepatch_kinematics::Machine;
use polepatch_nc::modal::{A, B, C};
use polepatch_nc::{RunBuilder, scan_blocks_with};
use std::ops::ControlFlow;

/// What the scan found, run by run.
#[derive(Debug, Default)]
struct Seen {
    runs: usize,
    /// Some run point has a value for X Y Z A B C (index as `Modal::pos`).
    uses: [bool; 6],
    /// Least |A| and |B| over all run points, a missing value read as 0 (as the full path
    /// reads it).
    min_abs_a_deg: f64,
    min_abs_b_deg: f64,
    /// A run that cannot be analysed (no feed, …: [`crate::program::run_check`]) if A
    /// (index 0) or B (index 1) is the tilting letter: the full path reports it.
    feedless: [bool; 2],
}

/// The report of a program that is proven to have no run point within reach of the pole
/// (`opts.patch.reach_deg()`: the cone, or the pole reach beyond it)
/// of the pole (no zone: the output is the input), or `None` when that is not proven and
/// the full path must run. Errors are bad options ([`crate::PatchOptions::check`]) and the
/// input's syntax errors, as [`crate::patch_nc`] gives them.
pub fn far_from_pole(
    bytes: &[u8],
    machine: &Machine,
    opts: &crate::PatchOptions,
) -> Result<Option<FileReport>, crate::Error> {
    opts.check()?;
    // Where a zone can lie: the cone, or the pole reach beyond it.
    let cone_deg = opts.patch.reach_deg();
    let fallback = opts.feed_fallback_mm_min;
    let mut seen = Seen {
        min_abs_a_deg: f64::INFINITY,
        min_abs_b_deg: f64::INFINITY,
        ..Seen::default()
    };
    let mut builder = RunBuilder::default();
    let mut near = false;
    let take = |run: polepatch_nc::Run, seen: &mut Seen| {
        seen.runs += 1;
        for (l, p) in [A, B].into_iter().enumerate() {
            seen.feedless[l] |= crate::program::run_check(&run, p, fallback, 0).is_err();
        }
        for p in &run.pos {
            for (u, v) in seen.uses.iter_mut().zip(p) {
                *u |= v.is_some();
            }
            seen.min_abs_a_deg = seen.min_abs_a_deg.min(p[A].unwrap_or(0.0).abs());
            seen.min_abs_b_deg = seen.min_abs_b_deg.min(p[B].unwrap_or(0.0).abs());
        }
    };
    let mut i = 0usize;
    let read = crate::program::read_options_with(machine, opts.inch)?;
    let mut notes = crate::notes::Notes::new();
    let mut prev = read.initial();
    let settled = scan_blocks_with(bytes, &read, |s| {
        let (block, st) = (s.block, s.state);
        notes.push(block, s.words, &prev, st);
        prev = *st;
        builder.push(i, block, st, &mut |run| take(run, &mut seen));
        i += 1;
        // Whichever tilting letter turns out to be the primary, a point is in the cone.
        near = (seen.feedless[0] || seen.min_abs_a_deg <= cone_deg)
            && (seen.feedless[1] || seen.min_abs_b_deg <= cone_deg);
        if near {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .map_err(|e| crate::Error::Parse(e.with_path(&opts.name)))?;
    // Program flow settles TCPM only on a second read: the full path does it (whether a
    // point is near the pole does not depend on it, but the report's notes may).
    if near || matches!(settled, polepatch_nc::Settled::Again(_)) {
        return Ok(None);
    }
    builder.finish(&mut |run| take(run, &mut seen));
    let own = if machine.primary_letter() == 'A' {
        A
    } else {
        B
    };
    let p_idx = polepatch_nc::primary_of(&seen.uses, own);
    let min_abs = if p_idx == A {
        seen.min_abs_a_deg
    } else {
        seen.min_abs_b_deg
    };
    if seen.runs == 0
        || seen.feedless[usize::from(p_idx == B)]
        || (!seen.uses[p_idx] && !seen.uses[C])
        || min_abs <= cone_deg
    {
        return Ok(None);
    }
    let mut report = FileReport::unchanged(
        &opts.name,
        machine,
        primary_mismatch_warning(&opts.name, machine, p_idx)
            .into_iter()
            .collect(),
    );
    let (not_analysed, warnings) = notes.finish(p_idx, cone_deg, &opts.name);
    report.not_analysed = not_analysed;
    report.warnings.extend(warnings);
    Ok(Some(report))
}
