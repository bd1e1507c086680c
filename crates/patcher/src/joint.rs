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
//! `first..=last` move; every other point keeps its base values. Variables:
//!
//! ```text
//! δP_i, δC_i        i ∈ first..=last        change from the base, degrees
//! m^P_k, m^C_k      k ∈ window               knot slopes of the analysis splines of P and C
//!                                            (crate::hermite, one Hermite per axis)
//! t                                          chord bound (dimensionless)
//! ```
//!
//! The exact problem is
//!
//! ```text
//! minimise  max_i ∠(o_i, fk(P̂_i + δP_i, Ĉ_i + δC_i))
//! s.t.      Hermite equalities of P and of C                          (the analysis splines)
//!           |P'| ≤ v_P, |P''| ≤ a_P, |P'''| ≤ j_P on every span between movable points,
//!           |C'| ≤ v_C, |C''| ≤ a_C, |C'''| ≤ j_C  likewise     (Equation 6 at feed F,
//!                                                               convex-hull form)
//!           each of them ≤ max(its limit, its size before) on the other spans of the
//!           window that touch a fixed point (never worse), unless they are in the zone's
//!           core, which must reach feed
//!           p_min ≤ P̂_i + δP_i ≤ p_max      (the machine's primary range; C's when finite)
//! ```
//!
//! with `(v, a, j) = (1 − margin)·(V/F, A/F², J/F³)` per axis ([`GeomLimits`]). The
//! constraints are linear in the values (hence in δ), exactly as in the C-only direct QP;
//! the objective is not convex. It is solved by sequential convex programming: at the
//! iterate `(P̄, C̄) = base + δ̄` the tool axis is linearised,
//!
//! ```text
//! fk(P̂_i + δP_i, Ĉ_i + δC_i) ≈ ō_i + a_i·(δP_i − δ̄P_i) + b_i·(δC_i − δ̄C_i)
//! ō_i = fk(P̄_i, C̄_i),  a_i = ∂fk/∂P,  b_i = ∂fk/∂C  (per degree, forward_jacobian)
//! ```
//!
//! and the second-order-cone program
//!
//! ```text
//! minimise  t + μ·Σ_i ‖r_i‖² + ε·Σ_i ((δP_i − δ̄P_i)² + (δC_i − δ̄C_i)²)
//! s.t.      ‖r_i‖₂ ≤ t,   r_i = ō_i − o_i + a_i·(δP_i − δ̄P_i) + b_i·(δC_i − δ̄C_i)
//!           the Hermite, limit and range rows above
//!           |δP_i − δ̄P_i| ≤ ρ_P,  |δC_i − δ̄C_i| ≤ ρ_C                   (trust region)
//!           t ≤ 2·sin(d_max/2)                                          (with max_deviation)
//! ```
//!
//! is solved with clarabel. `‖o' − o‖ = 2·sin(∠/2)` (the chord) is increasing in the angle,
//! so the largest chord bounds the largest angle. μ ([`JOINT_QUAD_WEIGHT`]) pulls the points
//! that do not bind the maximum towards their targets; ε ([`PROXIMAL_WEIGHT`]) keeps a
//! point exactly on the pole (where C does not move the tool) determined.
//!
//! The iteration: the first solve starts from the base (which violates the limits — that
//! is the zone) with a wide trust region ([`FIRST_TRUST_P_DEG`], [`FIRST_TRUST_C_DEG`],
//! doubled while the solve is infeasible, up to the primary axis' whole range);
//! its solution satisfies every limit row, and every later iterate does too (the rows are
//! exact). A solution becomes the iterate when its **exact** largest angle is lower than the
//! iterate's; otherwise the trust region halves. It stops when an accepted step improves the
//! largest angle by less than [`SCP_REL_TOL`], after [`SCP_MAX_SOLVES`] solves, or when the
//! trust region falls below [`SCP_MIN_TRUST_DEG`]. The caller rounds the result as it will be
//! written and verifies Equation 6 on it (`crate::verify`).

use crate::{
    candidate::PatchFailure,
    hermite::{Hermite, JOINT_WINDOW_POINTS},
    limits::GeomLimits,
    qp::QpBuilder,
    report::QpStats,
};
use polepatch_kinematics::{Machine, angle_between_deg, forward, forward_jacobian};

/// μ: weight of the sum of squared (linearised) chords against the largest chord `t`
/// (dimensionless): small, it only chooses among the minimax solutions.
pub const JOINT_QUAD_WEIGHT: f64 = 1e-2;

/// ε: weight of the proximal term on each step, per degree².
pub const PROXIMAL_WEIGHT: f64 = 1e-8;

/// Trust region of the first solve (from the base, which violates the limits), degrees:
/// the primary axis may move by this much.
pub const FIRST_TRUST_P_DEG: f64 = 15.0;

/// Trust region of the first solve for C, degrees (a half turn: near the pole C may have to
/// move that far).
pub const FIRST_TRUST_C_DEG: f64 = 180.0;

/// Trust region of the later solves (around a feasible iterate), primary axis, degrees.
pub const TRUST_P_DEG: f64 = 2.0;

/// Trust region of the later solves, C, degrees.
pub const TRUST_C_DEG: f64 = 30.0;

/// An accepted step that lowers the exact largest angle by less than this fraction ends
/// the iteration.
pub const SCP_REL_TOL: f64 = 0.01;

/// Most solves of one [`solve_joint`].
pub const SCP_MAX_SOLVES: usize = 8;

/// The iteration ends when the primary trust region falls below this, degrees.
pub const SCP_MIN_TRUST_DEG: f64 = 1e-3;

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
    /// The machine (kinematics and axis ranges).
    pub machine: &'a Machine,
    /// Largest orientation change allowed, degrees (`None`: no limit).
    pub max_deviation_deg: Option<f64>,
    /// Most solves ([`SCP_MAX_SOLVES`] by default).
    pub max_solves: usize,
    /// Relative improvement below which an accepted step ends the iteration
    /// ([`SCP_REL_TOL`] by default).
    pub rel_tol: f64,
    /// The spans that must reach feed (the zone's), `k` for `[s_k, s_{k+1}]`: they get the
    /// limits even where they touch a fixed point.
    pub core: std::ops::Range<usize>,
    /// Largest rounding error of a written primary value, degrees (half a unit of the
    /// last decimal written): every bound leaves room for its effect.
    pub round_p_deg: f64,
    /// The same for C.
    pub round_c_deg: f64,
    /// The base already satisfies every row (a previous solution): iterate from it with
    /// the narrow trust region, accepting only steps that lower its largest deviation.
    pub warm: bool,
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
    /// Solver statistics of every solve made.
    pub qp: QpStats,
}

/// Largest exact angle between `target` and the tool axes of the values `base + δ` over
/// `first..=last`, degrees.
fn exact_max_deviation(pr: &JointProblem, dp: &[f64], dc: &[f64]) -> f64 {
    (pr.first..=pr.last)
        .map(|i| {
            let k = i - pr.first;
            let o = forward(pr.machine, pr.p_deg[i] + dp[k], pr.c_deg[i] + dc[k]);
            angle_between_deg(o, pr.target[i])
        })
        .fold(0.0, f64::max)
}

/// Solve the joint problem (module docs) by sequential convex programming.
///
/// `Err(PatchFailure::Solver)` when the first solve finds no solution (infeasible within
/// the first trust region, or a solver failure); `Err(PatchFailure::TooShort)` for a range
/// outside the path.
pub fn solve_joint(pr: &JointProblem) -> Result<JointSolution, PatchFailure> {
    let (first, last) = (pr.first, pr.last);
    let n = pr.s_mm.len();
    if first > last || last >= n || pr.target.len() != n {
        return Err(PatchFailure::TooShort);
    }
    let hp = Hermite::with_offset(pr.s_mm, pr.p_deg, first, last, JOINT_WINDOW_POINTS, 0)?;
    let hc = Hermite::with_offset(
        pr.s_mm,
        pr.c_deg,
        first,
        last,
        JOINT_WINDOW_POINTS,
        hp.vars(),
    )?;
    let t = hp.vars() + hc.vars();
    let nd = last - first + 1;
    let mut base = QpBuilder::new(t + 1);
    hp.add_equalities(&mut base);
    hc.add_equalities(&mut base);
    let mut current = vec![0.0; t + 1];
    hp.write_current(&mut current)?;
    hc.write_current(&mut current)?;
    let (rp, rc) = (
        hp.rounding_room(pr.round_p_deg)?,
        hc.rounding_room(pr.round_c_deg)?,
    );
    hp.push_limits(&mut base, &pr.lim_p, &current, &rp, pr.core.clone());
    hc.push_limits(&mut base, &pr.lim_c, &current, &rc, pr.core.clone());
    let (p_lo, p_hi) = pr.machine.primary_range_deg;
    for i in first..=last {
        let v = hp.delta_var(i);
        base.add_le(&[(v, 1.0)], p_hi - pr.p_deg[i]);
        base.add_le(&[(v, -1.0)], pr.p_deg[i] - p_lo);
        if let Some((c_lo, c_hi)) = pr.machine.c_range_deg {
            let v = hc.delta_var(i);
            base.add_le(&[(v, 1.0)], c_hi - pr.c_deg[i]);
            base.add_le(&[(v, -1.0)], pr.c_deg[i] - c_lo);
        }
    }
    if let Some(d) = pr.max_deviation_deg {
        base.add_le(&[(t, 1.0)], 2.0 * (d.to_radians() / 2.0).sin());
    }
    base.add_linear(t, 1.0);

    let mut stats = QpStats::default();
    // The iterate: δ̄ (zero = the base) and its exact largest angle (None: not yet feasible).
    let mut dbar_p = vec![0.0; nd];
    let mut dbar_c = vec![0.0; nd];
    let mut dev: Option<f64> = None;
    let (mut rho_p, mut rho_c) = (FIRST_TRUST_P_DEG, FIRST_TRUST_C_DEG);
    if pr.warm {
        dev = Some(exact_max_deviation(pr, &dbar_p, &dbar_c));
        (rho_p, rho_c) = (TRUST_P_DEG, TRUST_C_DEG);
    }
    for _ in 0..pr.max_solves {
        let mut qp = base.clone();
        for i in first..=last {
            let k = i - first;
            let (ip, ic) = (hp.delta_var(i), hc.delta_var(i));
            let (pb, cb) = (pr.p_deg[i] + dbar_p[k], pr.c_deg[i] + dbar_c[k]);
            let [o, a, b] = forward_jacobian(pr.machine, pb, cb);
            // r = r0 + a·δP + b·δC with r0 = ō − o_target − a·δ̄P − b·δ̄C.
            let r0: [f64; 3] = std::array::from_fn(|m| {
                o[m] - pr.target[i][m] - a[m] * dbar_p[k] - b[m] * dbar_c[k]
            });
            let mut block = vec![(vec![(t, -1.0)], 0.0)];
            for m in 0..3 {
                block.push((vec![(ip, -a[m]), (ic, -b[m])], r0[m]));
                qp.add_square(&[(ip, a[m]), (ic, b[m])], JOINT_QUAD_WEIGHT, -r0[m]);
            }
            qp.add_soc(&block);
            qp.add_square(&[(ip, 1.0)], PROXIMAL_WEIGHT, dbar_p[k]);
            qp.add_square(&[(ic, 1.0)], PROXIMAL_WEIGHT, dbar_c[k]);
            qp.add_le(&[(ip, 1.0)], dbar_p[k] + rho_p);
            qp.add_le(&[(ip, -1.0)], rho_p - dbar_p[k]);
            qp.add_le(&[(ic, 1.0)], dbar_c[k] + rho_c);
            qp.add_le(&[(ic, -1.0)], rho_c - dbar_c[k]);
        }
        let x = match qp.solve(&mut stats) {
            Ok(x) => x,
            Err(st) if dev.is_none() => {
                // No feasible point near the base: widen the first trust region (the limits
                // may force the values far from the program's) up to the primary axis'
                // whole range before giving up.
                let (lo, hi) = pr.machine.primary_range_deg;
                if st.is_infeasible() && rho_p < hi - lo {
                    rho_p = (2.0 * rho_p).min(hi - lo);
                    rho_c = 2.0 * FIRST_TRUST_C_DEG;
                    continue;
                }
                return Err(PatchFailure::Solver(stats));
            }
            Err(_) => {
                // Around a feasible iterate the problem is feasible: a numerical failure.
                // Try a smaller step.
                rho_p *= 0.5;
                rho_c *= 0.5;
                if rho_p < SCP_MIN_TRUST_DEG {
                    break;
                }
                continue;
            }
        };
        let xp: Vec<f64> = (first..=last).map(|i| x[hp.delta_var(i)]).collect();
        let xc: Vec<f64> = (first..=last).map(|i| x[hc.delta_var(i)]).collect();
        if xp.iter().chain(&xc).any(|v| !v.is_finite()) {
            return Err(PatchFailure::Solver(stats));
        }
        let d = exact_max_deviation(pr, &xp, &xc);
        match dev {
            None => {
                (dbar_p, dbar_c, dev) = (xp, xc, Some(d));
                (rho_p, rho_c) = (TRUST_P_DEG, TRUST_C_DEG);
            }
            Some(cur) if d < cur => {
                (dbar_p, dbar_c, dev) = (xp, xc, Some(d));
                if cur - d < pr.rel_tol * cur {
                    break;
                }
            }
            Some(_) => {
                rho_p *= 0.5;
                rho_c *= 0.5;
                if rho_p < SCP_MIN_TRUST_DEG {
                    break;
                }
            }
        }
    }
    let Some(max_deviation_deg) = dev else {
        return Err(PatchFailure::Solver(stats));
    };
    Ok(JointSolution {
        p_deg: (first..=last)
            .map(|i| pr.p_deg[i] + dbar_p[i - first])
            .collect(),
        c_deg: (first..=last)
            .map(|i| pr.c_deg[i] + dbar_c[i - first])
            .collect(),
        max_deviation_deg,
        qp: stats,
    })
}
