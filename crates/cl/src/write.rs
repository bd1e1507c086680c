//! Writing CL files: APT (straight, rapid, circular moves and holes) and CSV (points).

use crate::cycles::{Cycle, CycleKind};
use crate::records::{ClPoint, MoveKind};
use std::fmt::Write as _;

/// The `CYCLE/…` record of a cycle, mm.
fn cycle_record(c: &Cycle, d: usize) -> String {
    let mut s = format!(
        "CYCLE/{},FEDTO,{:.d$},MMPM,{},RAPTO,{:.d$}",
        c.mode, c.depth_mm, c.feed_mm_min, c.clearance_mm
    );
    if let Some(t) = c.retract_mm {
        let _ = write!(s, ",RTRCTO,{t:.d$}");
    }
    if c.dwell_s > 0.0 {
        let _ = write!(s, ",DWELL,{}", c.dwell_s);
    }
    if let Some(p) = c.peck_mm {
        let _ = write!(s, ",STEP,{p:.d$}");
    }
    debug_assert!(c.peck_mm.is_some() || !matches!(c.kind, CycleKind::Deep | CycleKind::ChipBreak));
    s
}

/// Write points as APT CLDATA (`UNITS/MM`, `MULTAX`, `FEDRAT/f,MMPM` where the feed
/// changes, `RAPID`, `CIRCLE/…` before an arc's end, `CYCLE/…` … `CYCLE/OFF` around holes,
/// `GOTO/x,y,z,i,j,k` with `decimals` places).
pub fn to_apt(points: &[ClPoint], name: &str, decimals: usize) -> String {
    let d = decimals;
    let mut s = format!("PARTNO/{name}\nUNITS/MM\nMULTAX/ON\n");
    let mut feed = None;
    let mut cycle: Option<&Cycle> = None;
    for p in points {
        let hole = match &p.kind {
            MoveKind::Hole(c) => Some(c),
            _ => None,
        };
        if cycle.is_some() && hole != cycle {
            s.push_str("CYCLE/OFF\n");
            cycle = None;
        }
        match &p.kind {
            MoveKind::Hole(c) => {
                if cycle != Some(c) {
                    s.push_str(&cycle_record(c, d));
                    s.push('\n');
                    cycle = Some(c);
                }
            }
            MoveKind::Rapid => s.push_str("RAPID\n"),
            MoveKind::Linear | MoveKind::Arc(_) => {
                if p.feed_mm_min != feed {
                    if let Some(f) = p.feed_mm_min {
                        let _ = writeln!(s, "FEDRAT/{f},MMPM");
                    }
                    feed = p.feed_mm_min;
                }
            }
        }
        if let MoveKind::Arc(a) = &p.kind {
            let (c, n) = (a.center_mm, a.normal);
            let _ = writeln!(
                s,
                "CIRCLE/{:.d$},{:.d$},{:.d$},{:.d$},{:.d$},{:.d$},{:.d$}",
                c[0], c[1], c[2], n[0], n[1], n[2], a.radius_mm
            );
        }
        let _ = writeln!(
            s,
            "GOTO/{:.d$},{:.d$},{:.d$},{:.d$},{:.d$},{:.d$}",
            p.pos_mm[0], p.pos_mm[1], p.pos_mm[2], p.axis[0], p.axis[1], p.axis[2]
        );
    }
    if cycle.is_some() {
        s.push_str("CYCLE/OFF\n");
    }
    s.push_str("FINI\n");
    s
}

/// Write points as CSV `x,y,z,i,j,k,f` with a header (positions only: arcs and holes are
/// written as their end points; use [`to_apt`] to keep them).
pub fn to_csv(points: &[ClPoint], decimals: usize) -> String {
    let mut s = String::from("x,y,z,i,j,k,f\n");
    let d = decimals;
    for p in points {
        let _ = write!(
            s,
            "{:.d$},{:.d$},{:.d$},{:.d$},{:.d$},{:.d$}",
            p.pos_mm[0], p.pos_mm[1], p.pos_mm[2], p.axis[0], p.axis[1], p.axis[2]
        );
        match p.feed_mm_min {
            Some(f) => {
                let _ = writeln!(s, ",{f}");
            }
            None => s.push('\n'),
        }
    }
    s
}
