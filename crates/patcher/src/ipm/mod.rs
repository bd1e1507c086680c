//! A primal–dual interior-point method for the joint patch's convex QPs, exploiting their
//! structure: every row of the Hermite forms touches the unknowns of two or three
//! neighbouring CL points, so with the unknowns ordered along the path the KKT matrix is
//! **banded**, apart from a few unknowns every row may touch (the epigraph `t` of the
//! largest deviation, the elastic `e`), kept as a dense **border**.
//!
//! The module is split the way Clarabel's solver is: [`Problem`] (`problem.rs`: the data,
//! its builders and equilibration), [`IpmSettings`] (`settings.rs`), the bordered band
//! `L·D·Lᵀ` and iterative refinement (`band.rs`), the second-order cone's algebra
//! (`cones.rs`), the KKT system's products and assembly (`kkt.rs`) and the loop
//! (`solver.rs`).
//!
//! # The problem
//!
//! ```text
//! minimise    ½·xᵀ·H·x + cᵀ·x
//! subject to  G·x + s = h,  s ∈ K = ℝ₊^m × Q^{q_1} × … × Q^{q_p}
//! ```
//!
//! with H positive semidefinite and `Q^q = {(s_0, s_1) : s_0 ≥ ‖s_1‖}` second-order cones
//! (the minimax of orientation changes: `‖r_i‖ ≤ t`). The linear rows come mostly as
//! **pairs** `lo ≤ a·x ≤ hi` (the limit rows `|f| ≤ b` and the trust region): one band row
//! for both sides, so each pair costs one row in every product and in the assembly. There
//! are no equalities: the joint patch eliminates its own (`crate::hermite`'s reduced
//! form), so the KKT matrix is positive definite and its band about half as wide.
//!
//! # The method (Mehrotra's predictor–corrector with Nesterov–Todd scaling)
//!
//! As in CVXOPT's `coneqp` (Vandenberghe, "The CVXOPT linear and quadratic cone program
//! solvers", 2010). With slacks `s ∈ K`, multipliers `z ∈ K`, residuals
//! `r_d = H·x + c + Gᵀ·z`, `r_g = G·x + s − h`, `μ = sᵀz/ν` (ν: one per linear row and per
//! cone), and the scaling `W` with `W·z = W⁻ᵀ·s = λ` (diagonal `√(s/z)` on the linear rows,
//! the Nesterov–Todd matrix on a cone), each iteration solves the Newton system twice with
//! one factorisation, eliminating `ds` and `dz` (`V = W⁻¹·W⁻ᵀ`, `u = λ \ (−r_c)` in the
//! cone's Jordan algebra, `w = V·r_g + W⁻¹·u`):
//!
//! ```text
//! (H + Gᵀ·V·G)·dx = −r_d − Gᵀ·w,     dz = V·G·dx + w,    ds = −r_g − G·dx
//! ```
//!
//! first with `r_c = λ∘λ` (the affine step), then with
//! `r_c = λ∘λ + (W⁻ᵀ·ds_aff)∘(W·dz_aff) − σ·μ·e` and `σ = (μ_aff/μ)³`; the step keeps `s`
//! and `z` inside K ([`IpmSettings::step_fraction`] of the way to its boundary).
//!
//! # The linear algebra
//!
//! The caller orders the band unknowns along the path (the joint patch interleaves the two
//! axes' coefficients), which makes `H + Gᵀ·V·G` banded of half-bandwidth `w` (six for
//! the joint patch), plus `k` border rows and columns. It is regularised (`+δ` on the
//! diagonal), factored as a banded `L·D·Lᵀ` in `O(n·w²)` with the border by its Schur
//! complement, and every solve is refined against the unregularised matrix
//! ([`IpmSettings::refinement_steps`]). An iteration costs `O(n·w² + nnz(G))`: linear in
//! the number of CL points, where a general sparse solver pays for its ordering and
//! symbolic analysis on every call.

mod band;
mod cones;
mod kkt;
mod problem;
mod settings;
mod solver;

pub use cones::MAX_CONE;
pub use problem::Problem;
pub use settings::IpmSettings;

/// How a solve ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpmStatus {
    /// Converged to the tolerances.
    Solved,
    /// Stopped at [`IpmSettings::max_iter`].
    MaxIterations,
    /// A pivot vanished or a value became non-finite.
    NumericalError,
}

/// A start for [`Problem::solve_warm`]: a previous solve's primal point and multipliers,
/// for a problem of the same shape (the same rows in the same order; only their
/// coefficients and right-hand sides changed).
#[derive(Debug, Clone, PartialEq)]
pub struct IpmWarm {
    /// The primal point (every unknown, band then border).
    pub x: Vec<f64>,
    /// The multipliers, per slack of the equilibrated problem ([`IpmSolution::z`]).
    pub z: Vec<f64>,
}

/// A solve's result.
#[derive(Debug, Clone, PartialEq)]
pub struct IpmSolution {
    /// The primal solution (every unknown, band then border).
    pub x: Vec<f64>,
    /// The multipliers of the equilibrated problem, per slack (pairs' upper and lower
    /// sides, the one-sided rows, the cones' rows): for a warm start ([`IpmWarm`]).
    pub z: Vec<f64>,
    /// Status.
    pub status: IpmStatus,
    /// Iterations made.
    pub iterations: u32,
}

pub(super) fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}
