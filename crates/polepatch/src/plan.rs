//! The plan over a program's passes: which branch each pass starts and ends on.
//!
//! A pass (a run) may end on the other IK branch where the blocks after it allow
//! ([`crate::end_pose`]: a free end), and may start on it where the positioning move before
//! it is that free end's move and goes to the pass's first point (the move's rotary words
//! are then rewritten: `(P, C) → (−P, C ± 180°)`, the same tool axis, the tool tip on the
//! same line above the clearance). Each pass offers a few **choices**, each a patch of its
//! zones ([`crate::patch`]): its end pinned, its end free, its start free. A choice fixes
//! the pose the pass starts and ends in; a **positioning move** between two passes costs
//! the time to travel from the one pose to the other ([`crate::end_pose::NextMove::time_s`]:
//! each axis at its velocity and acceleration limits, the slowest setting the time).
//!
//! # The objective, in its order
//! **A constraint first: the program is never slower than its input.** A choice whose pass
//! is slower than the input's (Equation 6 over the pass as written, beyond the estimate's
//! tolerance) is not offered, and a pass plus the positioning move after it may not take
//! longer than in the input (within [`RAPID_TIME_TOL_S`]): a zone brought to feed by an end
//! on the other branch whose next move then turns C half a revolution more, costing more
//! than the zone saves, is not done (`polepatch verify` would refuse it). Then, over every pass of the program (or of the stretch [`crate::stream`] hands over: passes
//! linked by such a move are always in one), the plan
//! 1. leaves the fewest zones below feed, and those it leaves the least below it;
//! 2. makes the positioning moves **no slower than the input's** (the time beyond the
//!    input's, each move's within [`RAPID_TIME_TOL_S`] not counted, the least): a zone that
//!    reaches feed only with its end on the other branch may make the next move slower
//!    where nothing else reaches feed and the pass saves more than the move costs — but
//!    never where a plan keeps the move;
//! 3. makes the **largest change of tool orientation** over the program the smallest, and
//!    among plans with the same largest, the sum of each pass's largest;
//! 4. takes the least time (zones plus positioning moves);
//! 5. changes the fewest ends from the program's branch.
//!
//! A branch carried from one pass into the next (its end and the next start both on the
//! other branch) costs no orientation and no table swing: that is what the alternating
//! passes of a zigzag need, and what the constraint leaves where the next move would
//! otherwise turn C by half a revolution more.
//!
//! # The method
//! Dynamic programming over the passes in order. The state between two passes is the
//! choice of the earlier one (its end pose); a transition to a choice of the next pays the
//! move between them. Criteria 1, 2, 4 and 5 add up over passes, 3 takes the maximum (then the sum), so a partial plan that is
//! better in one criterion may lose in another: each state keeps the partial plans no other
//! beats in all of them at once (a Pareto front, at most [`FRONT_MAX`] kept, the best by the
//! order above).

use crate::end_pose::NextMove;
use crate::tolerances::RAPID_TIME_TOL_S;
use polepatch_kinematics::Machine;

/// Partial plans kept per state (module docs).
pub const FRONT_MAX: usize = 8;

/// Two shortfalls closer than this are the same (criterion 1).
const SAME_SHORTFALL: f64 = 1e-6;

/// Two orientation changes closer than this are the same (criterion 3), degrees: a
/// thousandth of a degree moves a D10 ball's centre 0.09 µm, and two choices that differ by
/// less are a tie the next criteria break (else a cap at one's value could pick the other).
const SAME_DEVIATION_DEG: f64 = 1e-3;

/// One way to patch a pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// Primary axis and C at the pass's first point, degrees.
    pub start: [f64; 2],
    /// The same at its last point.
    pub end: [f64; 2],
    /// Zones left below feed.
    pub unreached: usize,
    /// How far below feed they are: the sum over them of `1 − ratio` (the lowest feed
    /// ratio a zone keeps after the patch).
    pub shortfall: f64,
    /// Largest change of tool orientation, degrees.
    pub deviation_deg: f64,
    /// Its time, s (Equation 6 over the run as written).
    pub time_s: f64,
    /// Ends (start, end) not on the program's branch: 0, 1 or 2.
    pub changed_ends: usize,
    /// The pass's start is the plan's to write (its positioning move goes there): its C
    /// values may all be written a whole number of turns away, the same orientations, so
    /// that the move before it turns C the short way.
    pub shiftable: bool,
    /// The smallest and largest C it writes, degrees (a shift keeps them in the machine's
    /// range).
    pub c_span_deg: [f64; 2],
}

/// A pass as the plan sees it.
#[derive(Debug, Clone)]
pub struct Pass {
    /// Its choices (at least one).
    pub choices: Vec<Choice>,
    /// Its time in the input, s (comparable with [`Choice::time_s`]; 0 where unknown).
    pub input_s: f64,
    /// The positioning move after it, when its end is free: the move's time depends on
    /// where the pass ends (and, when `into_next`, where the next pass starts).
    pub after: Option<After>,
}

/// The positioning move after a pass.
#[derive(Debug, Clone, Copy)]
pub struct After {
    /// The move (its target as the program states it).
    pub next: NextMove,
    /// Its time in the input, s.
    pub input_s: f64,
    /// The move goes to the next pass's first point, whose values the next pass's choice
    /// sets (its start may be free).
    pub into_next: bool,
}

impl After {
    /// The move's time from `end` to `target` (the program's target unless given), s.
    pub fn time_s(&self, machine: &Machine, end: [f64; 2], target: Option<[f64; 2]>) -> f64 {
        let mut next = self.next;
        if let Some([p, c]) = target {
            next.p_deg = p;
            next.c_deg = c;
        }
        next.time_s(machine, end[0], end[1])
    }

    /// A move of `t_s`: its time, and how much slower than the input's it is (0 within
    /// [`RAPID_TIME_TOL_S`]).
    fn cost(&self, t_s: f64) -> (f64, f64) {
        let excess = t_s - self.input_s;
        (
            t_s,
            if excess > RAPID_TIME_TOL_S {
                excess
            } else {
                0.0
            },
        )
    }
}

impl Pass {
    /// Whether the pass as `ch` writes it, with the move after it taking `move_s`, is no
    /// slower than in the input (the constraint: the program is never slower).
    fn no_slower(&self, ch: &Choice, move_s: f64) -> bool {
        match &self.after {
            Some(a) => ch.time_s + move_s <= self.input_s + a.input_s + RAPID_TIME_TOL_S,
            None => true,
        }
    }
}

/// A partial plan's figures (criteria 2 to 5) and where it came from.
#[derive(Debug, Clone, Copy)]
struct Entry {
    unreached: usize,
    shortfall: f64,
    /// Time the positioning moves take beyond the input's (each beyond
    /// [`RAPID_TIME_TOL_S`]), s.
    excess_s: f64,
    deviation_deg: f64,
    /// The passes' largest changes added up (criterion 3's tie-break: the largest equal,
    /// the plan that turns the other passes least).
    sum_deviation_deg: f64,
    time_s: f64,
    changed_ends: usize,
    /// The whole turns added to this pass's C values, degrees (a multiple of 360).
    shift_deg: f64,
    /// The previous pass's choice and entry.
    prev: Option<(usize, usize)>,
}

impl Entry {
    /// Better by the objective's order (criteria 2 to 5).
    fn better(&self, o: &Entry) -> bool {
        use std::cmp::Ordering::*;
        match self.unreached.cmp(&o.unreached) {
            Less => return true,
            Greater => return false,
            Equal => {}
        }
        if (self.shortfall - o.shortfall).abs() > SAME_SHORTFALL {
            return self.shortfall < o.shortfall;
        }
        if (self.excess_s - o.excess_s).abs() > RAPID_TIME_TOL_S {
            return self.excess_s < o.excess_s;
        }
        if (self.deviation_deg - o.deviation_deg).abs() > SAME_DEVIATION_DEG {
            return self.deviation_deg < o.deviation_deg;
        }
        if (self.sum_deviation_deg - o.sum_deviation_deg).abs() > SAME_DEVIATION_DEG {
            return self.sum_deviation_deg < o.sum_deviation_deg;
        }
        if (self.time_s - o.time_s).abs() > RAPID_TIME_TOL_S {
            return self.time_s < o.time_s;
        }
        self.changed_ends < o.changed_ends
    }

    /// No worse in any criterion (and the pass ends in the same place).
    fn dominates(&self, o: &Entry) -> bool {
        self.shift_deg == o.shift_deg
            && self.unreached <= o.unreached
            && self.shortfall <= o.shortfall + SAME_SHORTFALL
            && self.excess_s <= o.excess_s + RAPID_TIME_TOL_S
            && self.deviation_deg <= o.deviation_deg + SAME_DEVIATION_DEG
            && self.sum_deviation_deg <= o.sum_deviation_deg + SAME_DEVIATION_DEG
            && self.time_s <= o.time_s + RAPID_TIME_TOL_S
            && self.changed_ends <= o.changed_ends
    }

    /// This entry followed by `c` shifted by `shift_deg`, through a move of `move_s`.
    fn then(
        &self,
        c: &Choice,
        shift_deg: f64,
        (move_s, excess_s): (f64, f64),
        prev: (usize, usize),
    ) -> Entry {
        Entry {
            shift_deg,
            unreached: self.unreached + c.unreached,
            shortfall: self.shortfall + c.shortfall,
            excess_s: self.excess_s + excess_s,
            deviation_deg: self.deviation_deg.max(c.deviation_deg),
            sum_deviation_deg: self.sum_deviation_deg + c.deviation_deg,
            time_s: self.time_s + move_s + c.time_s,
            changed_ends: self.changed_ends + c.changed_ends,
            prev: Some(prev),
        }
    }
}

/// Add `e` to `front` unless an entry there dominates it; drop those it dominates; keep at
/// most [`FRONT_MAX`], the best first.
fn insert(front: &mut Vec<Entry>, e: Entry) {
    if front.iter().any(|f| f.dominates(&e)) {
        return;
    }
    front.retain(|f| !e.dominates(f));
    let at = front
        .iter()
        .position(|f| e.better(f))
        .unwrap_or(front.len());
    front.insert(at, e);
    front.truncate(FRONT_MAX);
}

/// The whole turns a choice's C values may be written with: 0, and for a shiftable choice
/// ±360° and ±720° where its C values stay in the machine's range `c_range`.
fn shifts(ch: &Choice, c_range: Option<(f64, f64)>) -> impl Iterator<Item = f64> + '_ {
    let turns: &[f64] = if ch.shiftable {
        &[0.0, 360.0, -360.0, 720.0, -720.0]
    } else {
        &[0.0]
    };
    turns.iter().copied().filter(move |k| {
        c_range.is_none_or(|(lo, hi)| ch.c_span_deg[0] + k >= lo && ch.c_span_deg[1] + k <= hi)
    })
}

/// The plan (module docs): each pass's choice and the whole turns (degrees, a multiple of
/// 360) its C values are written with (`None`: no pass).
pub fn plan(passes: &[Pass], machine: &Machine) -> Option<Vec<(usize, f64)>> {
    let c_range = machine.c_range_deg;
    let start = Entry {
        unreached: 0,
        shortfall: 0.0,
        excess_s: 0.0,
        deviation_deg: 0.0,
        sum_deviation_deg: 0.0,
        time_s: 0.0,
        changed_ends: 0,
        shift_deg: 0.0,
        prev: None,
    };
    // fronts[r][c]: the partial plans up to pass r ending with its choice c.
    let mut fronts: Vec<Vec<Vec<Entry>>> = Vec::with_capacity(passes.len());
    for (r, pass) in passes.iter().enumerate() {
        let mut here: Vec<Vec<Entry>> = vec![Vec::new(); pass.choices.len()];
        let Some(prev) = r.checked_sub(1) else {
            for (c, ch) in pass.choices.iter().enumerate() {
                let mut e = start.then(ch, 0.0, (0.0, 0.0), (0, 0));
                e.prev = None;
                here[c].push(e);
            }
            fronts.push(here);
            continue;
        };
        let before = &passes[prev];
        for (c, ch) in pass.choices.iter().enumerate() {
            for (pc, pch) in before.choices.iter().enumerate() {
                for (pe, e) in fronts[prev][pc].iter().enumerate() {
                    // The move between the passes, where its time depends on the choices
                    // (and the whole turns the pass is written with).
                    let end = [pch.end[0], pch.end[1] + e.shift_deg];
                    let (shift, cost): (f64, (f64, f64)) = match &before.after {
                        Some(a) if a.into_next => {
                            let shifts = shifts(ch, c_range);
                            let best = shifts
                                .map(|k| {
                                    let t = [ch.start[0], ch.start[1] + k];
                                    (k, a.cost(a.time_s(machine, end, Some(t))))
                                })
                                .min_by(|x, y| x.1.0.total_cmp(&y.1.0));
                            best.unwrap_or((0.0, a.cost(a.time_s(machine, end, Some(ch.start)))))
                        }
                        Some(a) => (0.0, a.cost(a.time_s(machine, end, None))),
                        None => (0.0, (0.0, 0.0)),
                    };
                    if !before.no_slower(pch, cost.0) {
                        continue;
                    }
                    insert(&mut here[c], e.then(ch, shift, cost, (pc, pe)));
                }
            }
        }
        fronts.push(here);
    }
    // The last pass's move goes to a target of the program's.
    let last = passes.len().checked_sub(1)?;
    let mut best: Option<(usize, usize, Entry)> = None;
    for (c, ch) in passes[last].choices.iter().enumerate() {
        for (k, e) in fronts[last][c].iter().enumerate() {
            let end = [ch.end[0], ch.end[1] + e.shift_deg];
            let (move_s, excess_s) = match &passes[last].after {
                Some(a) => a.cost(a.time_s(machine, end, None)),
                None => (0.0, 0.0),
            };
            if !passes[last].no_slower(ch, move_s) {
                continue;
            }
            let mut e = *e;
            e.time_s += move_s;
            e.excess_s += excess_s;
            if best.as_ref().is_none_or(|(_, _, b)| e.better(b)) {
                best = Some((c, k, e));
            }
        }
    }
    let (mut c, mut k, _) = best?;
    let mut chosen = vec![(0, 0.0); passes.len()];
    for r in (0..passes.len()).rev() {
        chosen[r] = (c, fronts[r][c][k].shift_deg);
        match fronts[r][c][k].prev {
            Some((pc, pk)) => (c, k) = (pc, pk),
            None => break,
        }
    }
    Some(chosen)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn machine() -> Machine {
        Machine::builtin("mikron-ucp710").expect("built-in")
    }

    fn choice(start: [f64; 2], end: [f64; 2], dev: f64, changed: usize) -> Choice {
        Choice {
            start,
            end,
            unreached: 0,
            shortfall: 0.0,
            deviation_deg: dev,
            time_s: 1.0,
            changed_ends: changed,
            shiftable: false,
            c_span_deg: [start[1].min(end[1]), start[1].max(end[1])],
        }
    }

    /// A move from the program's end pose `(10, 0)` to the next pass's first point
    /// `(10, 30)`.
    fn after(machine: &Machine, into_next: bool) -> After {
        let next = NextMove {
            line: 10,
            p_deg: 10.0,
            c_deg: 30.0,
            linear_mm: [5.0, 0.0, 0.0],
        };
        After {
            next,
            input_s: next.time_s(machine, 10.0, 0.0),
            into_next,
        }
    }

    /// Pass 1's free end costs nothing but ends on the other branch; pass 2 can start on
    /// that branch. The plan carries the branch (0° both) instead of pinning pass 1's end
    /// (2°), and never takes the free end alone (its move would turn C 180° more).
    #[test]
    fn a_branch_is_carried_into_the_next_pass_where_that_keeps_the_move() {
        let m = machine();
        let first = Pass {
            choices: vec![
                choice([20.0, 0.0], [10.0, 0.0], 2.0, 0),
                choice([20.0, 0.0], [-10.0, 180.0], 0.0, 1),
            ],
            input_s: 10.0,
            after: Some(after(&m, true)),
        };
        let second = Pass {
            choices: vec![
                choice([10.0, 30.0], [5.0, 30.0], 0.0, 0),
                choice([-10.0, 210.0], [5.0, 30.0], 0.0, 1),
            ],
            input_s: 10.0,
            after: None,
        };
        assert_eq!(
            plan(&[first.clone(), second], &m),
            Some(vec![(1, 0.0), (1, 0.0)])
        );
        // Without a start to carry into, the end is pinned: the free end's move is slower.
        let alone = Pass {
            choices: vec![choice([10.0, 30.0], [5.0, 30.0], 0.0, 0)],
            input_s: 10.0,
            after: None,
        };
        assert_eq!(plan(&[first, alone], &m), Some(vec![(0, 0.0), (0, 0.0)]));
    }

    /// The largest deviation decides before time, and time before the changed ends.
    #[test]
    fn the_order_of_the_criteria() {
        let m = machine();
        let mut slow = choice([0.0, 0.0], [0.0, 0.0], 1.0, 0);
        slow.time_s = 5.0;
        let fast = choice([0.0, 0.0], [0.0, 0.0], 1.5, 0);
        let p = Pass {
            choices: vec![fast, slow],
            input_s: 10.0,
            after: None,
        };
        assert_eq!(plan(&[p], &m), Some(vec![(1, 0.0)]));
        let a = choice([0.0, 0.0], [0.0, 0.0], 1.0, 1);
        let b = choice([0.0, 0.0], [0.0, 0.0], 1.0, 0);
        let p = Pass {
            choices: vec![a, b],
            input_s: 10.0,
            after: None,
        };
        assert_eq!(plan(&[p], &m), Some(vec![(1, 0.0)]));
        let mut reached = choice([0.0, 0.0], [0.0, 0.0], 3.0, 0);
        reached.unreached = 0;
        let mut below = choice([0.0, 0.0], [0.0, 0.0], 0.0, 0);
        below.unreached = 1;
        let p = Pass {
            choices: vec![below, reached],
            input_s: 10.0,
            after: None,
        };
        assert_eq!(plan(&[p], &m), Some(vec![(1, 0.0)]));
    }

    /// The maximum over passes is what counts: a plan whose worst pass is better wins even
    /// where another plan is better on one pass (the front keeps both partial plans).
    #[test]
    fn the_largest_deviation_over_the_program_is_minimised() {
        let m = machine();
        // Pass 1: 1° keeping the end, or 0° ending on the other branch.
        let first = Pass {
            choices: vec![
                choice([20.0, 0.0], [10.0, 0.0], 1.0, 0),
                choice([20.0, 0.0], [-10.0, 180.0], 0.0, 1),
            ],
            input_s: 10.0,
            after: Some(after(&m, true)),
        };
        // Pass 2 from the program's branch: 3°; from the other: 0.5°.
        let second = Pass {
            choices: vec![
                choice([10.0, 30.0], [5.0, 30.0], 3.0, 0),
                choice([-10.0, 210.0], [5.0, 30.0], 0.5, 1),
            ],
            input_s: 10.0,
            after: None,
        };
        assert_eq!(plan(&[first, second], &m), Some(vec![(1, 0.0), (1, 0.0)]));
    }
}

#[cfg(test)]
mod shift_tests {
    use super::*;

    /// A pass carried onto the other branch ends at C 238°; the next pass's start on that
    /// branch is C −119° as computed: written a turn further (C 241°) the move turns C 3°,
    /// not 357°.
    #[test]
    fn a_carried_start_is_written_the_short_way_round() {
        let m = Machine::builtin("mikron-hsm600").expect("built-in");
        let next = NextMove {
            line: 10,
            p_deg: 15.0,
            c_deg: 60.0,
            linear_mm: [5.0, 0.0, 0.0],
        };
        let c = |start: [f64; 2], end: [f64; 2], dev: f64, changed: usize| Choice {
            start,
            end,
            unreached: 0,
            shortfall: 0.0,
            deviation_deg: dev,
            time_s: 1.0,
            changed_ends: changed,
            shiftable: true,
            c_span_deg: [start[1].min(end[1]), start[1].max(end[1])],
        };
        let first = Pass {
            choices: vec![c([15.0, -58.0], [-15.0, 238.0], 0.0, 2)],
            input_s: 10.0,
            after: Some(After {
                next,
                input_s: next.time_s(&m, 15.0, 58.0),
                into_next: true,
            }),
        };
        let second = Pass {
            choices: vec![
                c([15.0, 60.0], [15.0, 61.0], 1.0, 0),
                c([-15.0, -119.0], [15.0, -60.0], 0.05, 1),
            ],
            input_s: 10.0,
            after: None,
        };
        assert_eq!(plan(&[first, second], &m), Some(vec![(0, 0.0), (1, 360.0)]));
    }
}
