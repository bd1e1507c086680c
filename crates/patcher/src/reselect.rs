//! Branch re-selection: when the program switches IK branch inside a zone (the primary
//! axis changes sign with C jumping, as a domain-rule post writes it: G16 Table 1), the
//! points after the switch are put on the other branch as a block,
//! `(P, C) → (−P, C ± 180°)` — the same tool axes — to the end of the run, within the
//! machine's ranges ([`crate::starts::other_branch`]). The orientation does not change at
//! all; when Equation 6 then holds, the zone is done with deviation 0 ([`crate::driver`]'s
//! reason `reselected`).
//!
//! The same block move is the "other branch" start of the joint patch
//! ([`crate::joint_method`]), after the switch or the singular point.

use crate::protocol::{Proposal, Proposer, Sink, Tail, ZoneCtx};
use crate::report::{Method, QpStats};
use crate::starts::{branch_switch, tail_shift};

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
