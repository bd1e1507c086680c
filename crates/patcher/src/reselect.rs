//! Branch re-selection: when the program switches IK branch inside a zone (the primary
//! axis changes sign with C jumping, as a domain-rule post writes it: G16 Table 1), the
//! points after the switch are put on the other branch as a block,
//! `(P, C) → (−P, C ± 180°)` — the same tool axes — to the end of the run, within the
//! machine's ranges. The orientation does not change at all; when Equation 6 then holds,
//! the zone is done with deviation 0 ([`crate::driver`]'s reason `reselected`).
//!
//! The same block move is the "other branch" start of the joint patch
//! ([`crate::joint_method`]), after the switch or the singular point.

use crate::analysis::Zone;
use crate::driver::{Proposal, Proposer, Sink, Tail, ZoneCtx};
use crate::report::{Method, QpStats};
use polepatch_kinematics::{Machine, wrap_deg};

/// |P| below which a point counts as on the pole when C's continuity is judged, degrees
/// (C does not orient the tool there).
pub const POLE_DEG: f64 = 1e-6;

/// The index after which the program switches branch inside the zone: the last point
/// before the primary axis changes sign (points exactly at 0 skipped), nearest to the
/// zone's singular point.
pub fn branch_switch(p: &[f64], zone: &Zone) -> Option<usize> {
    let mut best: Option<usize> = None;
    let mut last_nonzero: Option<usize> = None;
    for i in zone.first..=zone.last {
        if p[i] == 0.0 {
            continue;
        }
        if let Some(j) = last_nonzero
            && p[j].signum() != p[i].signum()
            && best.is_none_or(|b| j.abs_diff(zone.singular) < b.abs_diff(zone.singular))
        {
            best = Some(j);
        }
        last_nonzero = Some(i);
    }
    best
}

/// The point of least |P| in the zone.
pub fn least_primary(p: &[f64], zone: &Zone) -> usize {
    (zone.first..=zone.last)
        .min_by(|&a, &b| p[a].abs().total_cmp(&p[b].abs()))
        .unwrap_or(zone.singular)
}

/// The ±180° that keeps C continuous when the points after `k` move to the other branch,
/// or `None` when the run's last point must stay or a re-selected value would leave the
/// machine's ranges.
pub fn tail_shift(
    machine: &Machine,
    p: &[f64],
    c: &[f64],
    k: usize,
    keep_last: bool,
) -> Option<f64> {
    let n = p.len();
    if k + 1 >= n || keep_last {
        return None;
    }
    let (lo, hi) = machine.primary_range_deg;
    if p[k + 1..].iter().any(|&v| !(lo..=hi).contains(&-v)) {
        return None;
    }
    // C after the switch, moved by ±180°, nearest to C before it — before it on a point
    // off the pole (on the pole C does not orient the tool and may be anything).
    let r = (0..=k).rev().find(|&i| p[i].abs() > POLE_DEG).unwrap_or(k);
    let d = wrap_deg(c[k + 1] + 180.0 - c[r]) - (c[k + 1] + 180.0 - c[r]);
    let shift = 180.0 + d;
    let shift = if shift > 180.0 + 1e-9 {
        shift - 360.0
    } else {
        shift
    };
    if let Some((c_lo, c_hi)) = machine.c_range_deg
        && c[k + 1..]
            .iter()
            .any(|&v| !(c_lo..=c_hi).contains(&(v + shift)))
    {
        return None;
    }
    Some(shift)
}

/// The values of the whole path with the points after `k` on the other branch (C moved
/// by `shift`).
pub fn other_branch(p: &[f64], c: &[f64], k: usize, shift: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut op, mut oc) = (p.to_vec(), c.to_vec());
    for i in k + 1..p.len() {
        op[i] = -p[i];
        oc[i] = c[i] + shift;
    }
    (op, oc)
}

/// The re-selection method (module docs).
pub struct Reselect;

impl Proposer for Reselect {
    fn propose(&mut self, ctx: &ZoneCtx<'_>, sink: &mut dyn Sink) {
        // The margin does not enter a re-selection: one try, on the first rung.
        if ctx.rung > 0 {
            return;
        }
        let Some(k) = branch_switch(ctx.p, ctx.zone).filter(|&k| k + 1 >= ctx.lower) else {
            return;
        };
        let Some(shift) = tail_shift(ctx.machine, ctx.p, ctx.c, k, ctx.opts.keep_last_point) else {
            return;
        };
        sink.offer(Proposal {
            method: Method::Reselect,
            first: k + 1,
            last: k + 1,
            p: vec![-ctx.p[k + 1]],
            c: vec![ctx.c[k + 1] + shift],
            tail: Tail::Reselect { shift_deg: shift },
            qp: QpStats::default(),
        });
    }
}
