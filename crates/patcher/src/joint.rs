//! The joint patch: new primary-axis (A or B) and C values at the existing CL points, so
//! that **both** rotary axes reach the programmed feed with the smallest change of tool
//! orientation (issue 8; G16 §4 names the step: "the algorithm could be also used to
//! modify this axis").
//!
//! # Why both axes
//! Near the pole the tool axis `o = Rz(sc·C)·Rp(sp·P)·ẑ` is, to first order, the vector
//! `P·(sin C, −cos C)` of the tangent plane: a signed radius P along the direction C.
//! A path passing at a distance d from the pole makes that direction turn by up to 180°
//! within a few d of path — the C swing — on either IK branch. Changing C alone (G16) keeps
//! the radius and moves the tool sideways; changing P too lets the path go *through* the
//! pole, where P changes sign at constant C (`(P, C)` and `(−P, C + 180°)` are one tool
//! axis): C then barely moves, P passes linearly through zero, and the orientation changes
//! by about d. The solver below finds the best such compromise for both axes' limits.
//!
//! # The problem
//! Points `i` of a path with path length `s_i`, target tool axes `o_i` (the program's,
//! [`polepatch_kinematics::forward`]) and base values `(P̂_i, Ĉ_i)` (the program's values,
//! possibly re-selected onto the other branch as a block: the same `o_i`). Points
//! `first..=last` move; every other point keeps its base values. Unknowns:
//!
//! ```text
//! γ^P_r, γ^C_r      r = 0 … last − first     the free changes of the coefficients of the
//!                                            analysis splines of P and C on the window
//!                                            (crate::window: one per
//!                                            movable point; the fixed points' values and
//!                                            the window's end conditions are eliminated),
//!                                            interleaved P, C along the path
//! t                                          largest orientation change (chord, linearised)
//! e ≥ 0                                      largest relative excess over a limit row
//! ```
//!
//! Every value change `δP_i`, `δC_i`, slope and higher derivative of either spline on the
//! window is a linear form in a few neighbouring γ.
//!
//! The exact problem is
//!
//! ```text
//! minimise  max_i ∠(o_i, fk(P̂_i + δP_i, Ĉ_i + δC_i))
//! s.t.      P and C are the analysis splines of their values             (by construction)
//!           |P'| ≤ v_P, |P''| ≤ a_P, |P'''| ≤ j_P on every span between movable points,
//!           |C'| ≤ v_C, |C''| ≤ a_C, |C'''| ≤ j_C  likewise     (Equation 6 at feed F,
//!                                                               convex-hull form)
//!           each of them ≤ max(its limit, its size before) on the other spans of the
//!           window that touch a fixed point (never worse), unless they are in the zone's
//!           core, which must reach feed
//!           p_min ≤ P̂_i + δP_i ≤ p_max      (the machine's primary range; C's when finite)
//! ```
//!
//! with `(v, a, j) = (1 − margin)·(V/F, A/F², J/F³)` per axis ([`GeomLimits`]), less what
//! rounding the written values can add (`Window::rounding_room`). The constraints are
//! linear in the values (hence in δ); the objective is not convex. It is solved by
//! sequential convex programming: at the iterate `(P̄, C̄) = base + δ̄` the tool axis is
//! linearised, `fk(P̂ + δP, Ĉ + δC) ≈ ō + a·(δP − δ̄P) + b·(δC − δ̄C)` with `ō = fk(P̄, C̄)`,
//! `a = ∂fk/∂P`, `b = ∂fk/∂C` (per degree, `forward_jacobian`), the change
//! `r_i = ō_i − o_i + a_i·(δP_i − δ̄P_i) + b_i·(δC_i − δ̄C_i)` is taken in the tangent plane
//! of `o_i` (basis `E_i`, 2 × 3), and the QP
//!
//! ```text
//! minimise  t + M·e + μ·Σ_i ‖E_i·r_i‖² + ε·Σ_i ((δP_i − δ̄P_i)² + (δC_i − δ̄C_i)²)
//! s.t.      u_k·E_i·r_i ≤ t     k = 0 … K−1, u_k = (cos 2πk/K, sin 2πk/K)   (a K-gon ⊇ the
//!                                                                     circle ‖E_i·r_i‖ ≤ t)
//!           each limit row relaxed by e:  row/bound ≤ 1 + e,   e ≥ 0
//!           the Hermite and range rows above, exactly
//!           |δP_i − δ̄P_i| ≤ ρ_P,  |δC_i − δ̄C_i| ≤ ρ_C                   (trust region)
//!           t ≤ sin d                                       (only for a capped solve, d)
//! ```
//!
//! is solved by the banded interior-point method of [`crate::ipm`] (all rows touch two or
//! three neighbouring points; `t` and `e` are its border). The elastic `e` makes every
//! QP feasible whatever the start (the values may start far outside the limits: that is
//! the zone), and its weight M ([`SolverSettings::elastic_weight`]) puts reaching feed
//! first; the limit rows are linear, so the excess of a point is exact, not a model. The
//! exact angle is what is accepted and reported.
//!
//! **Iteration.** The merit of values is `chord(exact largest angle) + M·(exact excess)`.
//! A QP's solution becomes the iterate when its merit is lower; otherwise the trust
//! region halves. The first solve uses a wide trust region
//! ([`SolverSettings::first_trust_p_deg`], [`SolverSettings::first_trust_c_deg`]) unless the
//! start already meets the limits ([`JointProblem::warm`]). It stops when an accepted step
//! improves the merit by less than [`SolverSettings::scp_rel_tol`], after
//! [`JointProblem::max_solves`] solves, or when the trust region falls below
//! [`SolverSettings::min_trust_deg`]. The caller rounds the result as it will be written and
//! verifies Equation 6 on it (`crate::verify`).
//!
//! **Capped.** With [`JointProblem::cap_deg`] the QP keeps `t ≤ sin d` (the tangent-plane
//! change of an exact change by θ is `sin θ`, so this bounds θ by d to first order; the
//! chord `2·sin(d/2)` would let θ reach `asin(2·sin(d/2)) ≈ d + d³/8`) and the
//! iteration lowers the excess e instead: the least excess over the limits with no point's
//! orientation changed by more than d (from a start within the cap: the base has 0).

use crate::{
    candidate::PatchFailure,
    hermite::Aff,
    ipm::{IpmStatus, IpmWarm, Problem},
    limits::GeomLimits,
    qp::Row,
    report::{QpStats, QpStatus},
    settings::SolverSettings,
    tolerances::{JOINT_WINDOW_POINTS, MIN_POINT_CAP_DEG, SCP_MERIT_FLOOR, ZERO_DEVIATION_DEG},
    window::{RowSet, Window},
};
use polepatch_kinematics::vec3::dot;
use polepatch_kinematics::{Axis, Machine, angle_between_deg, forward, forward_jacobian};
use std::time::Instant;

pub use crate::window::WindowMemo;

/// One joint solve's inputs. Every slice is per point of the whole path.
#[derive(Debug, Clone)]
pub struct JointProblem<'a> {
    /// Path length per point, mm.
    pub s_mm: &'a [f64],
    /// Base primary values, degrees (tool axes equal to `target`'s).
    pub p_deg: &'a [f64],
    /// Base C values, degrees.
    pub c_deg: &'a [f64],
    /// Target tool axes (unit vectors, workpiece frame).
    pub target: &'a [[f64; 3]],
    /// First movable point.
    pub first: usize,
    /// Last movable point.
    pub last: usize,
    /// Primary-axis limits along s (with the caller's margin).
    pub lim_p: GeomLimits,
    /// C limits along s (with the caller's margin).
    pub lim_c: GeomLimits,
    /// The programmed feed, mm/min: the machine's own limits along s (without the margin)
    /// tell which spans were below feed before.
    pub feed_mm_min: f64,
    /// The machine (kinematics and axis ranges).
    pub machine: &'a Machine,
    /// The spans that must reach feed (the zone's), `k` for `[s_k, s_{k+1}]`: they get the
    /// limits even where they touch a fixed point.
    pub core: std::ops::Range<usize>,
    /// Largest rounding error of a written primary value, degrees (half a unit of the
    /// last decimal written): every bound leaves room for its effect.
    pub round_p_deg: f64,
    /// The same for C.
    pub round_c_deg: f64,
    /// The values "not worse" compares against, when not the base's (a start that
    /// rewrote points of the range by a rule, FREEZE say, is not what the verification
    /// compares with: the values before it are). Per point of the whole path.
    pub reference: Option<(&'a [f64], &'a [f64])>,
    /// The values the verification compares with (the path's current values), per point
    /// of the whole path: a span between movable points outside the core that exceeded a
    /// limit on them need only not get worse there ([`Window::limit_rows`]).
    pub verified: (&'a [f64], &'a [f64]),
    /// The spans the pole's slowdown may reach (all, unless the zone was cut from a longer
    /// stretch below feed: [`crate::analysis::Zone::cut_before`]); beyond them a span the
    /// program itself keeps below feed need only not get worse ([`Window::limit_rows`]).
    pub pole_spans: std::ops::Range<usize>,
    /// `None`: minimise the largest orientation change. `Some(d)`: the least excess over
    /// the limits with no point's orientation changed by more than `d` degrees (module
    /// docs: capped).
    pub cap_deg: Option<f64>,
    /// Per point of the whole path, the most its orientation may change, degrees (the
    /// driver's safety bound near the pole, `crate::driver::pole_bound_deg`): with it the
    /// solve is capped too, each point at the smaller of this and `cap_deg`.
    pub point_cap_deg: Option<&'a [f64]>,
    /// The base already meets the limits (a previous solution): iterate from it with the
    /// narrow trust region.
    pub warm: bool,
    /// Most QP solves.
    pub max_solves: u32,
    /// Where the first QP's interior-point method starts, when the base is a previous
    /// solve's solution on the same range ([`JointSolution::ipm_end`]: its last QP's
    /// multipliers; the rows are the same, only the linearisation point and the trust
    /// region moved). `None`: cold. Used only with [`SolverSettings::scp_warm_start`].
    pub ipm_start: Option<&'a IpmWarm>,
    /// Where the rounding room of a window is kept between the solves of one zone
    /// (`None`: computed each time).
    pub memo: Option<&'a WindowMemo>,
    /// The numerical settings.
    pub settings: &'a SolverSettings,
}

/// The result of [`solve_joint`]: new values for `first..=last` (unrounded).
#[derive(Debug, Clone, PartialEq)]
pub struct JointSolution {
    /// New primary values, degrees, for `first..=last`.
    pub p_deg: Vec<f64>,
    /// New C values, degrees, for `first..=last`.
    pub c_deg: Vec<f64>,
    /// Exact largest orientation change against `target` over `first..=last`, degrees.
    pub max_deviation_deg: f64,
    /// Largest relative excess over a limit row (0: every row within its bound).
    pub excess: f64,
    /// Solver statistics of every solve made.
    pub qp: QpStats,
    /// The last QP's interior-point state at the solution returned (the band unknowns
    /// are changes from it: zero), for a later solve from this solution
    /// ([`JointProblem::ipm_start`]).
    pub ipm_end: Option<IpmWarm>,
}

/// The chord of an angle in degrees, `2·sin(d/2)`.
fn chord(deg: f64) -> f64 {
    2.0 * (deg.to_radians() / 2.0).sin()
}

/// An orthonormal basis of the plane orthogonal to the unit vector `o`.
fn tangent_basis(o: [f64; 3]) -> [[f64; 3]; 2] {
    let a = if o[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let d = a[0] * o[0] + a[1] * o[1] + a[2] * o[2];
    let mut e1 = [a[0] - d * o[0], a[1] - d * o[1], a[2] - d * o[2]];
    let n1 = (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]).sqrt();
    e1.iter_mut().for_each(|v| *v /= n1);
    let e2 = [
        o[1] * e1[2] - o[2] * e1[1],
        o[2] * e1[0] - o[0] * e1[2],
        o[0] * e1[1] - o[1] * e1[0],
    ];
    [e1, e2]
}

impl JointProblem<'_> {
    /// Whether the solve is capped (by `cap_deg` or per point): the least excess over the
    /// core's limits within the caps, nothing else worse (module docs).
    pub fn capped(&self) -> bool {
        self.cap_deg.is_some() || self.point_cap_deg.is_some()
    }
}

/// The problem's fixed part: the unknowns (each axis' free spline coefficients, interleaved
/// along the path, then `t` and `e`), the limit rows and the machine's ranges.
struct Model<'a> {
    pr: &'a JointProblem<'a>,
    /// The number of band unknowns (two per movable point).
    nb: usize,
    /// Per movable point, its changes `(δP_i, δC_i)` as affine forms of the unknowns.
    deltas: Vec<(Aff, Aff)>,
    /// The limit rows `|f| ≤ 1` in relative form (`f = row/bound`), relaxed by e.
    limits: Vec<Aff>,
    /// Capped: the rows that hold without relaxation (every span "not worse"), `|f| ≤ 1`.
    hard: Vec<Aff>,
    /// Capped: per point of the range, the most its orientation may change, degrees.
    caps: Option<Vec<f64>>,
    /// Per point of the range, the machine's ranges as bounds on its changes `(δP, δC)`
    /// (hard; C's infinite when it turns endlessly).
    ranges: Vec<[(f64, f64); 2]>,
}

impl<'a> Model<'a> {
    fn new(pr: &'a JointProblem<'a>) -> Result<Model<'a>, PatchFailure> {
        let (first, last) = (pr.first, pr.last);
        let n = pr.s_mm.len();
        let owned;
        let win: &Window = match pr.memo {
            Some(m) => {
                owned = m.get(pr.s_mm, first, last)?;
                &owned
            }
            None => {
                owned = std::rc::Rc::new(Window::new(pr.s_mm, first, last, JOINT_WINDOW_POINTS)?);
                &owned
            }
        };
        let nb = 2 * win.unknowns();
        // The start's splines (the unknowns are changes of their coefficients) and the
        // splines before (what "not worse" compares with): the start's, or the reference's.
        let (cp, cc) = (
            win.coeffs(pr.s_mm, pr.p_deg)?,
            win.coeffs(pr.s_mm, pr.c_deg)?,
        );
        let (bp, bc) = match pr.reference {
            None => (cp.clone(), cc.clone()),
            Some((rp, rc)) => (win.coeffs(pr.s_mm, rp)?, win.coeffs(pr.s_mm, rc)?),
        };
        let (vp, vc) = (
            win.coeffs(pr.s_mm, pr.verified.0)?,
            win.coeffs(pr.s_mm, pr.verified.1)?,
        );
        let capped = pr.capped();
        let mut rows: Vec<(Row, f64, f64)> = Vec::new();
        let mut hard_rows: Vec<(Row, f64, f64)> = Vec::new();
        // P's unknowns at even indices, C's at odd ones: interleaved along the path.
        for (c, b, v, lim, axis, round, offset) in [
            (&cp, &bp, &vp, &pr.lim_p, Axis::Primary, pr.round_p_deg, 0),
            (&cc, &bc, &vc, &pr.lim_c, Axis::C, pr.round_c_deg, 1),
        ] {
            let room = win.rounding_room(round);
            let core = pr.core.clone();
            let machine_lim = GeomLimits::of(pr.machine, axis, pr.feed_mm_min, 0.0);
            let was = (v.as_slice(), &machine_lim, &pr.pole_spans);
            let rows_of = |set, out: &mut Vec<(Row, f64, f64)>| {
                win.limit_rows(
                    n,
                    c,
                    b,
                    lim,
                    was,
                    &room,
                    core.clone(),
                    set,
                    (offset, 2),
                    out,
                );
            };
            if capped {
                // The core's limits, relaxed by e; every span not worse, held.
                rows_of(RowSet::Core, &mut rows);
                rows_of(RowSet::NotWorse, &mut hard_rows);
            } else {
                rows_of(RowSet::Patch, &mut rows);
            }
        }
        let relative = |rows: Vec<(Row, f64, f64)>| -> Vec<Aff> {
            rows.into_iter()
                .map(|(row, c, b)| Aff {
                    row: row.into_iter().map(|(j, v)| (j, v / b)).collect(),
                    c: c / b,
                })
                .collect()
        };
        let (limits, hard) = (relative(rows), relative(hard_rows));
        let caps = capped.then(|| {
            (first..=last)
                .map(|i| {
                    let point = pr.point_cap_deg.map_or(f64::INFINITY, |c| c[i]);
                    pr.cap_deg
                        .unwrap_or(f64::INFINITY)
                        .min(point)
                        .max(MIN_POINT_CAP_DEG)
                })
                .collect()
        });
        // The machine's ranges as bounds on each point's changes; the trust region
        // bounds the same forms, so each QP takes the intersection (one pair of rows).
        let (p_lo, p_hi) = pr.machine.primary_range_deg;
        let ranges = (first..=last)
            .map(|i| {
                let c = pr
                    .machine
                    .c_range_deg
                    .map_or((f64::NEG_INFINITY, f64::INFINITY), |(lo, hi)| {
                        (lo - pr.c_deg[i], hi - pr.c_deg[i])
                    });
                [(p_lo - pr.p_deg[i], p_hi - pr.p_deg[i]), c]
            })
            .collect();
        let deltas = (first..=last)
            .map(|i| {
                let (rp, kp) = win.delta(i, &cp, pr.p_deg[i], 0, 2);
                let (rc, kc) = win.delta(i, &cc, pr.c_deg[i], 1, 2);
                (Aff { row: rp, c: kp }, Aff { row: rc, c: kc })
            })
            .collect();
        Ok(Model {
            pr,
            nb,
            deltas,
            limits,
            hard,
            caps,
            ranges,
        })
    }

    /// Index of `t` and `e` among the unknowns.
    fn t(&self) -> usize {
        self.nb
    }
    fn e(&self) -> usize {
        self.nb + 1
    }

    /// The changes of point i, primary and C, at `x`.
    fn deltas(&self, i: usize, x: &[f64]) -> (f64, f64) {
        let (a, b) = &self.deltas[i - self.pr.first];
        (a.at(x), b.at(x))
    }

    /// The current spline (changes 0), t and e of it.
    fn start(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.nb + 2];
        x[self.e()] = self.excess(&x);
        x
    }

    /// The exact largest relative excess of `x` over the limit rows, and over the rows that
    /// hold (linear: exact).
    fn excess(&self, x: &[f64]) -> f64 {
        self.limits
            .iter()
            .chain(&self.hard)
            .map(|f| f.at(x).abs() - 1.0)
            .fold(0.0f64, f64::max)
    }

    /// Exact angle of point `i`'s values at `x` against its target, degrees.
    fn angle(&self, i: usize, x: &[f64]) -> f64 {
        let pr = self.pr;
        let (dp, dc) = self.deltas(i, x);
        let o = forward(pr.machine, pr.p_deg[i] + dp, pr.c_deg[i] + dc);
        angle_between_deg(o, pr.target[i])
    }

    /// Exact largest angle of `x`'s values against the targets, degrees.
    fn deviation(&self, x: &[f64]) -> f64 {
        let pr = self.pr;
        (pr.first..=pr.last)
            .map(|i| self.angle(i, x))
            .fold(0.0, f64::max)
    }

    /// Capped: the largest relative excess of a point's exact angle over its cap.
    fn over_caps(&self, x: &[f64]) -> f64 {
        let pr = self.pr;
        self.caps.as_ref().map_or(0.0, |caps| {
            (pr.first..=pr.last)
                .zip(caps)
                .map(|(i, &cap)| (self.angle(i, x) - cap).max(0.0) / cap)
                .fold(0.0, f64::max)
        })
    }

    /// The merit of `x` (module docs), with its exact largest angle and excess.
    fn merit(&self, x: &[f64], dev_deg: f64, excess: f64) -> f64 {
        let st = self.pr.settings;
        if self.caps.is_none() {
            chord(dev_deg) + st.elastic_weight * excess
        } else {
            // Capped: the excess first — over the limits, and of the exact angles over
            // the caps (the QP bounds the linearised change only) — the angle only to
            // break ties.
            st.elastic_weight * (excess + self.over_caps(x)) + st.cap_tie_weight * chord(dev_deg)
        }
    }

    /// The QP linearised at `x̄` with trust regions `(ρ_P, ρ_C)` (module docs).
    fn linearised(&self, xbar: &[f64], rho: (f64, f64)) -> Problem {
        let pr = self.pr;
        let st = pr.settings;
        let (t, e) = (self.t(), self.e());
        let mut qp = Problem::new(self.nb, 2);
        qp.add_linear(t, 1.0);
        qp.add_linear(e, st.elastic_weight);
        for f in &self.limits {
            qp.add_pair(&f.row, -1.0 - f.c, 1.0 - f.c, Some(e));
        }
        for f in &self.hard {
            qp.add_pair(&f.row, -1.0 - f.c, 1.0 - f.c, None);
        }
        qp.add_le(&[(e, -1.0)], 0.0);
        if self.caps.is_some() {
            // t is the largest change relative to each point's cap: at most 1.
            qp.add_le(&[(t, 1.0)], 1.0);
        }
        for (i, ((fp, fc), [rp, rc])) in
            (pr.first..=pr.last).zip(self.deltas.iter().zip(&self.ranges))
        {
            let (dp, dc) = (fp.at(xbar), fc.at(xbar));
            let [o, a, b] = forward_jacobian(pr.machine, pr.p_deg[i] + dp, pr.c_deg[i] + dc);
            // r = r0 + a·δP + b·δC with r0 = ō − o_target − a·δ̄P − b·δ̄C.
            let r0: [f64; 3] =
                std::array::from_fn(|m| o[m] - pr.target[i][m] - a[m] * dp - b[m] * dc);
            let [e1, e2] = tangent_basis(pr.target[i]);
            let (u0, ua, ub) = (dot(e1, r0), dot(e1, a), dot(e1, b));
            let (v0, va, vb) = (dot(e2, r0), dot(e2, a), dot(e2, b));
            // u = u0 + ua·δP + ub·δC (an affine form of the unknowns), v likewise.
            let u = Aff::sum(&[(ua, fp), (ub, fc), (u0, &Aff::constant(1.0))]);
            let v = Aff::sum(&[(va, fp), (vb, fc), (v0, &Aff::constant(1.0))]);
            // ‖(u, v)‖ ≤ t: slacks s_k = rhs_k − row_k·x are (t, u, v).
            let neg = |f: &Aff| f.row.iter().map(|&(j, c)| (j, -c)).collect::<Vec<_>>();
            let (nu, nv) = (neg(&u), neg(&v));
            // ‖(u, v)‖ ≤ t, or capped ‖(u, v)‖ ≤ t·sin(cap_i) (t ≤ 1: the tangent-plane
            // change of an exact change by θ is sin θ, module docs).
            let scale = self
                .caps
                .as_ref()
                .map_or(1.0, |caps| caps[i - pr.first].to_radians().sin());
            qp.add_soc(&[(&[(t, -scale)], 0.0), (&nu, u.c), (&nv, v.c)]);
            qp.add_square(&u.row, st.joint_quad_weight, -u.c);
            qp.add_square(&v.row, st.joint_quad_weight, -v.c);
            qp.add_square(&fp.row, st.proximal_weight, dp - fp.c);
            qp.add_square(&fc.row, st.proximal_weight, dc - fc.c);
            for (f, d, r, range) in [(fp, dp, rho.0, rp), (fc, dc, rho.1, rc)] {
                let (lo, hi) = ((d - r).max(range.0), (d + r).min(range.1));
                if lo <= hi {
                    qp.add_pair(&f.row, lo - f.c, hi - f.c, None);
                } else {
                    // Outside the range already: both, as they are (infeasible).
                    qp.add_pair(&f.row, d - r - f.c, d + r - f.c, None);
                    qp.add_pair(&f.row, range.0 - f.c, range.1 - f.c, None);
                }
            }
        }
        qp
    }
}

/// Solve the joint problem (module docs) by sequential convex programming.
///
/// `Err(PatchFailure::Solver)` when no QP could be solved; `Err(PatchFailure::TooShort)`
/// for a range outside the path.
pub fn solve_joint(pr: &JointProblem) -> Result<JointSolution, PatchFailure> {
    let (first, last) = (pr.first, pr.last);
    let n = pr.s_mm.len();
    if first > last || last >= n || pr.target.len() != n {
        return Err(PatchFailure::TooShort);
    }
    let st = pr.settings;
    let model = Model::new(pr)?;
    let mut stats = QpStats::default();
    let mut xbar = model.start();
    let mut dev = model.deviation(&xbar);
    let mut exc = xbar[model.e()];
    let mut merit = model.merit(&xbar, dev, exc);
    let mut rho = if pr.warm || exc <= st.elastic_tol {
        (st.trust_p_deg, st.trust_c_deg)
    } else {
        (st.first_trust_p_deg, st.first_trust_c_deg)
    };
    let mut solved_any = false;
    // A start already within the limits with no orientation change cannot be bettered.
    let solves = if exc <= st.elastic_tol && dev <= ZERO_DEVIATION_DEG {
        solved_any = true;
        0
    } else {
        pr.max_solves
    };
    // The next QP starts from the last one's multipliers (its rows are the same, at a
    // new linearisation point and trust region) and from the iterate.
    let mut warm: Option<IpmWarm> = pr.ipm_start.cloned();
    for _ in 0..solves {
        let started = Instant::now();
        let qp = model.linearised(&xbar, rho);
        let ipm = if model.caps.is_some() {
            &st.capped_ipm
        } else {
            &st.ipm
        };
        let sol = qp.solve_warm(ipm, warm.as_ref().filter(|_| st.scp_warm_start));
        stats.solves += 1;
        stats.iterations += sol.iterations;
        stats.solve_time_s += started.elapsed().as_secs_f64();
        stats.status = match sol.status {
            IpmStatus::Solved => QpStatus::Solved,
            IpmStatus::MaxIterations => QpStatus::MaxIterations,
            IpmStatus::NumericalError => QpStatus::NumericalError,
        };
        let x = sol.x;
        let usable = sol.status != IpmStatus::NumericalError && x.iter().all(|v| v.is_finite());
        warm = None;
        if !usable {
            rho = (0.5 * rho.0, 0.5 * rho.1);
            if rho.0 < st.min_trust_deg {
                break;
            }
            continue;
        }
        solved_any = true;
        let (d, ex) = (model.deviation(&x), model.excess(&x));
        let m = model.merit(&x, d, ex);
        let accepted = m < merit;
        warm = Some(IpmWarm {
            x: if accepted { x.clone() } else { xbar.clone() },
            z: sol.z,
        });
        if accepted {
            let gain = merit - m;
            let was_infeasible = exc > st.elastic_tol;
            (xbar, dev, exc, merit) = (x, d, ex, m);
            if exc <= st.elastic_tol {
                rho = (st.trust_p_deg, st.trust_c_deg);
            }
            // Stop on a small gain once the limits are met (not while reaching them).
            if !was_infeasible && gain < st.scp_rel_tol * merit.max(SCP_MERIT_FLOOR) {
                break;
            }
        } else {
            rho = (0.5 * rho.0, 0.5 * rho.1);
            if rho.0 < st.min_trust_deg {
                break;
            }
        }
    }
    if !solved_any {
        return Err(PatchFailure::Solver(stats));
    }
    Ok(JointSolution {
        p_deg: (first..=last)
            .map(|i| pr.p_deg[i] + model.deltas(i, &xbar).0)
            .collect(),
        c_deg: (first..=last)
            .map(|i| pr.c_deg[i] + model.deltas(i, &xbar).1)
            .collect(),
        max_deviation_deg: dev,
        excess: exc,
        qp: stats,
        ipm_end: warm.map(|mut w| {
            // The iterate becomes the next base: its changes are zero.
            w.x[..model.nb].iter_mut().for_each(|v| *v = 0.0);
            w
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{machine, planted, sing_path};

    /// The linearisation the QPs use, against finite differences and exactly: the
    /// Jacobian of the tool axis (per degree) matches central differences, and the
    /// linearised change `r0 + a·δP + b·δC` is off the exact `fk(P̄ + δP, C̄ + δC) − o`
    /// by at most the second-order bound `½·(π/180)²·(|δP| + |δC|)²` (the tool axis' second
    /// derivatives in degrees are at most (π/180)² in size).
    #[test]
    fn linearisation_against_finite_differences_and_its_error_bound() {
        let k = (1.0f64).to_radians().powi(2);
        for name in ["mikron-ucp710", "mikron-hsm600"] {
            let m = machine(name);
            for (p, c) in [(0.3, 40.0), (-2.0, 170.0), (12.0, -75.0), (0.0, 10.0)] {
                let [o, a, b] = forward_jacobian(&m, p, c);
                let h = 1e-5;
                let fp = |dp: f64, dc: f64| forward(&m, p + dp, c + dc);
                for i in 0..3 {
                    let dp = (fp(h, 0.0)[i] - fp(-h, 0.0)[i]) / (2.0 * h);
                    let dc = (fp(0.0, h)[i] - fp(0.0, -h)[i]) / (2.0 * h);
                    assert!((dp - a[i]).abs() < 1e-9, "{name} ∂P {p} {c}");
                    assert!((dc - b[i]).abs() < 1e-9, "{name} ∂C {p} {c}");
                }
                for (dp, dc) in [(0.5, 3.0), (-2.0, 30.0), (2.0, -180.0), (0.01, 0.1)] {
                    let exact = fp(dp, dc);
                    let err = (0..3)
                        .map(|i| (exact[i] - o[i] - a[i] * dp - b[i] * dc).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    let bound = 0.5 * k * (f64::abs(dp) + f64::abs(dc)).powi(2);
                    assert!(
                        err <= bound * (1.0 + 1e-9),
                        "{name} {p} {c} step {dp} {dc}: {err} > {bound}"
                    );
                }
            }
        }
    }

    /// The tangent-plane change the cones bound is the chord's component orthogonal to
    /// the target: `‖E·(o' − o)‖ = sin θ ≤ 2·sin(θ/2)`, equal to first order, so bounding
    /// it by `t` bounds the angle θ through `asin`.
    #[test]
    fn tangent_plane_change_is_the_sine_of_the_angle() {
        let m = machine("mikron-ucp710");
        for (p, c, p2, c2) in [
            (1.0, 20.0, 1.5, 35.0),
            (0.2, 0.0, -0.3, 180.0),
            (10.0, 5.0, 9.0, 5.0),
        ] {
            let (o, o2) = (forward(&m, p, c), forward(&m, p2, c2));
            let [e1, e2] = tangent_basis(o);
            let r = [o2[0] - o[0], o2[1] - o[1], o2[2] - o[2]];
            let tang = (dot(e1, r).powi(2) + dot(e2, r).powi(2)).sqrt();
            let theta = angle_between_deg(o, o2).to_radians();
            assert!(
                (tang - theta.sin()).abs() < 1e-12,
                "{tang} vs sin {}",
                theta.sin()
            );
            assert!(tang <= chord(theta.to_degrees()) + 1e-15);
            // The basis is orthonormal and orthogonal to o.
            assert!(
                dot(e1, o).abs() < 1e-15 && dot(e2, o).abs() < 1e-15 && dot(e1, e2).abs() < 1e-15
            );
        }
    }

    fn problem<'a>(
        path: &'a crate::path::Path,
        p: &'a [f64],
        c: &'a [f64],
        target: &'a [[f64; 3]],
        m: &'a Machine,
        st: &'a SolverSettings,
        cap: Option<f64>,
    ) -> JointProblem<'a> {
        let n = path.s_mm.len();
        JointProblem {
            s_mm: &path.s_mm,
            p_deg: p,
            c_deg: c,
            target,
            first: 1,
            last: n - 1,
            lim_p: GeomLimits::of(m, Axis::Primary, path.feed_mm_min, 0.02),
            lim_c: GeomLimits::of(m, Axis::C, path.feed_mm_min, 0.02),
            feed_mm_min: path.feed_mm_min,
            machine: m,
            core: 0..n - 1,
            round_p_deg: 0.0,
            round_c_deg: 0.0,
            reference: None,
            verified: (p, c),
            pole_spans: 0..n,
            cap_deg: cap,
            point_cap_deg: None,
            warm: false,
            max_solves: st.scp_max_solves,
            ipm_start: None,
            memo: None,
            settings: st,
        }
    }

    /// `%SING` from the program's values: the solution meets every limit row (excess 0)
    /// and its largest exact change is what passing through the pole costs (about the
    /// 1° the path passes from it); the rows it meets are the spline's limits, checked on
    /// the analysis spline of the solution's values (the model is the spline).
    #[test]
    fn sing_solution_meets_the_limits_on_the_analysis_spline() {
        let m = machine("mikron-ucp710");
        let path = sing_path();
        let st = SolverSettings::default();
        let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
        let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
        let target: Vec<[f64; 3]> = p.iter().zip(&c).map(|(a, b)| forward(&m, *a, *b)).collect();
        // Start on the other branch after the point of least |P| (through the pole).
        let k = (0..p.len())
            .min_by(|&a, &b| p[a].abs().total_cmp(&p[b].abs()))
            .unwrap();
        let shift = crate::starts::tail_shift(&m, &p, &c, k, false).unwrap();
        let (op, oc) = crate::starts::other_branch(&p, &c, k, shift);
        let sol = solve_joint(&problem(&path, &op, &oc, &target, &m, &st, None)).unwrap();
        assert!(sol.excess <= st.elastic_tol, "{sol:?}");
        assert!(sol.max_deviation_deg < 1.05, "{}", sol.max_deviation_deg);
        let (mut np, mut nc) = (op.clone(), oc.clone());
        np[1..].copy_from_slice(&sol.p_deg);
        nc[1..].copy_from_slice(&sol.c_deg);
        for (axis, y) in [(Axis::Primary, &np), (Axis::C, &nc)] {
            let lim = GeomLimits::of(&m, axis, path.feed_mm_min, 0.02);
            let sp = crate::spline::AnalysisSpline::new(&path.s_mm, y).unwrap();
            for (k, pk) in crate::spline::span_maxima(&path.s_mm, &sp)
                .iter()
                .enumerate()
            {
                let slack = 1e-6;
                assert!(
                    pk[0] <= lim.v * (1.0 + slack),
                    "{axis:?} span {k}: q' {} > {}",
                    pk[0],
                    lim.v
                );
                assert!(
                    pk[1] <= lim.a * (1.0 + slack),
                    "{axis:?} span {k}: q'' {} > {}",
                    pk[1],
                    lim.a
                );
                assert!(
                    pk[2] <= lim.j * (1.0 + slack),
                    "{axis:?} span {k}: q''' {} > {}",
                    pk[2],
                    lim.j
                );
            }
        }
        // The exact deviation reported is the exact angle of the values returned.
        let dev = (1..p.len())
            .map(|i| angle_between_deg(target[i], forward(&m, np[i], nc[i])))
            .fold(0.0, f64::max);
        assert!((dev - sol.max_deviation_deg).abs() < 1e-12);
    }

    /// Capped: no point's exact orientation change exceeds the cap (the cone bounds the
    /// tangent-plane change by the cap's chord, which is at least its sine), and the
    /// excess over the limits is what the cap leaves — positive when the cap is far
    /// below what reaching feed needs.
    #[test]
    fn capped_solve_stays_within_the_cap() {
        let m = machine("mikron-ucp710");
        let path = planted(241, 0.5, 0.5, false, 1000.0);
        let st = SolverSettings::default();
        let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
        let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
        let target: Vec<[f64; 3]> = p.iter().zip(&c).map(|(a, b)| forward(&m, *a, *b)).collect();
        for cap in [0.05, 0.2] {
            let mut pr = problem(&path, &p, &c, &target, &m, &st, Some(cap));
            pr.warm = true;
            let sol = solve_joint(&pr).unwrap();
            assert!(
                sol.max_deviation_deg <= cap * 1.01 + 1e-6,
                "cap {cap}: {}",
                sol.max_deviation_deg
            );
            assert!(
                sol.excess > 0.0,
                "cap {cap}: a 0.5° pass cannot reach feed within {cap}°"
            );
        }
    }

    /// A start that already meets every limit with no orientation change costs no solve.
    #[test]
    fn a_perfect_start_costs_no_solve() {
        let m = machine("mikron-ucp710");
        // Far from the pole and gentle: every limit met as programmed.
        let mut path = planted(81, 1.0, 20.0, false, 500.0);
        for q in &mut path.axes {
            q[4] *= 0.01;
        }
        let st = SolverSettings::default();
        let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
        let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
        let target: Vec<[f64; 3]> = p.iter().zip(&c).map(|(a, b)| forward(&m, *a, *b)).collect();
        let sol = solve_joint(&problem(&path, &p, &c, &target, &m, &st, None)).unwrap();
        assert_eq!(sol.qp.solves, 0, "{sol:?}");
        assert!(sol.max_deviation_deg < 1e-9 && sol.excess == 0.0, "{sol:?}");
    }
}
