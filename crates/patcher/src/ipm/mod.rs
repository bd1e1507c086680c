//! A primal–dual interior-point method for the patcher's convex QPs, exploiting their
//! structure: every row of the Hermite forms touches the variables of two or three
//! neighbouring CL points, so with the variables ordered along the path the KKT matrix is
//! **banded**, apart from a few variables every row may touch (the epigraph `t` of the
//! largest deviation, the elastic `e`), kept as a dense **border**.
//!
//! # The problem
//!
//! ```text
//! minimise    ½·xᵀ·H·x + cᵀ·x
//! subject to  A·x = b          (equalities)
//!             G·x + s = h,  s ∈ K = ℝ₊^m × Q^{q_1} × … × Q^{q_p}
//! ```
//!
//! with H positive semidefinite and `Q^q = {(s_0, s_1) : s_0 ≥ ‖s_1‖}` second-order cones
//! (the minimax of orientation changes: `‖r_i‖ ≤ t`). Each variable has a position along the path
//! ([`Banded::position`]; `None` for a border variable).
//!
//! # The method (Mehrotra's predictor–corrector with Nesterov–Todd scaling)
//!
//! As in CVXOPT's `coneqp` (Vandenberghe, "The CVXOPT linear and quadratic cone program
//! solvers", 2010). With slacks `s ∈ K`, multipliers `y`, `z ∈ K`, residuals
//! `r_d = H·x + c + Aᵀ·y + Gᵀ·z`, `r_p = A·x − b`, `r_g = G·x + s − h`, `μ = sᵀz/ν` (ν: one
//! per linear row and per cone), and the scaling `W` with `W·z = W⁻ᵀ·s = λ` (diagonal
//! `√(s/z)` on the linear rows, the Nesterov–Todd matrix on a cone), each iteration solves
//! the Newton system twice with one factorisation, eliminating `ds` and `dz`
//! (`V = W⁻¹·W⁻ᵀ`, `u = λ \ (−r_c)` in the cone's Jordan algebra, `w = V·r_g + W⁻¹·u`):
//!
//! ```text
//! [ H + Gᵀ·V·G   Aᵀ ] [dx]   [ −r_d − Gᵀ·w ]
//! [ A             0 ] [dy] = [ −r_p         ]
//! dz = V·G·dx + w,    ds = −r_g − G·dx
//! ```
//!
//! first with `r_c = λ∘λ` (the affine step), then with
//! `r_c = λ∘λ + (W⁻ᵀ·ds_aff)∘(W·dz_aff) − σ·μ·e` and `σ = (μ_aff/μ)³`; the step keeps `s`
//! and `z` inside K ([`IpmSettings::step_fraction`] of the way to its boundary).
//!
//! # The linear algebra
//!
//! The unknowns `(x, y)` are ordered by position (each equality's multiplier right after
//! the last variable it touches), which makes the matrix above banded of half-bandwidth
//! `w` (about ten for the joint patch), plus `k` border rows and columns. It is regularised
//! (`+δ` on the variables, `−δ` on the multipliers: quasi-definite, so `L·D·Lᵀ` exists in any
//! order without pivoting), factored as a banded `L·D·Lᵀ` in `O(n·w²)` with the border by
//! its Schur complement, and every solve is refined against the unregularised matrix
//! ([`IpmSettings::refinement_steps`]). An iteration costs `O(n·w² + nnz(G)·r)` for `r` the
//! largest row length: linear in the number of CL points, where a general sparse solver
//! pays for its ordering and symbolic analysis on every call.

// Index loops mirror the factorisation's formulas (rows, columns, band offsets).
#![allow(clippy::needless_range_loop)]

mod band;
mod cones;
mod kkt;
mod settings;
mod solver;

pub use cones::MAX_CONE;
pub use settings::IpmSettings;

/// A sparse linear form: `Σ coeff · x[var]` over `(var, coeff)`.
pub type Row = Vec<(usize, f64)>;

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

/// A solve's result.
#[derive(Debug, Clone, PartialEq)]
pub struct IpmSolution {
    /// The primal solution.
    pub x: Vec<f64>,
    /// Status.
    pub status: IpmStatus,
    /// Iterations made.
    pub iterations: u32,
}

/// A QP with variables placed along the path (module docs).
#[derive(Debug, Clone, Default)]
pub struct Banded {
    n: usize,
    /// Position of each variable along the path; `None`: a border variable.
    pub position: Vec<Option<f64>>,
    /// Upper-or-lower triangle entries of H (`(i, j, v)`, each pair once; `i == j` on the
    /// diagonal).
    pub h: Vec<(usize, usize, f64)>,
    /// Linear objective.
    pub c: Vec<f64>,
    /// Equality rows `row·x = rhs`.
    pub eq: Vec<(Row, f64)>,
    /// Inequality rows `row·x ≤ rhs`.
    pub le: Vec<(Row, f64)>,
    /// Second-order cones: each block of rows `(row_k, rhs_k)` says
    /// `‖(rhs_k − row_k·x)_{k≥1}‖₂ ≤ rhs_0 − row_0·x` (at most [`MAX_CONE`] rows).
    pub soc: Vec<Vec<(Row, f64)>>,
}

impl Banded {
    /// An empty problem in `n` variables, all in the band at position 0.
    pub fn new(n: usize) -> Banded {
        Banded {
            n,
            position: vec![Some(0.0); n],
            h: Vec::new(),
            c: vec![0.0; n],
            eq: Vec::new(),
            le: Vec::new(),
            soc: Vec::new(),
        }
    }

    /// Number of variables.
    pub fn vars(&self) -> usize {
        self.n
    }

    pub(super) fn h_mul(&self, x: &[f64], out: &mut [f64]) {
        for &(i, j, v) in &self.h {
            out[i] += v * x[j];
            if i != j {
                out[j] += v * x[i];
            }
        }
    }
}

pub(super) fn dot(row: &Row, x: &[f64]) -> f64 {
    row.iter().map(|&(j, v)| v * x[j]).sum()
}

pub(super) fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}
