//! The interior-point method's settings (Clarabel's `DefaultSettings` manner).

/// Settings of [`super::Problem::solve`]. Plain struct: public fields, documented defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IpmSettings {
    /// Most iterations. Default 60.
    pub max_iter: u32,
    /// Feasibility tolerance, relative to the data's size (`1 + ‖b‖∞`, `1 + ‖h‖∞`,
    /// `1 + ‖c‖∞`). Default 1e-8.
    pub tol_feas: f64,
    /// Complementarity tolerance on `μ`, relative to `1 + |objective|`. Default 1e-8.
    pub tol_gap: f64,
    /// Fraction of the way to the boundary of `s, z ≥ 0` a step goes. Default 0.99.
    pub step_fraction: f64,
    /// Static regularisation of the KKT matrix (`±δ`, on the equilibrated problem).
    /// Default 1e-9.
    pub regularisation: f64,
    /// Factor the unregularised KKT matrix first, and add [`IpmSettings::regularisation`]
    /// only when that meets a zero or non-finite pivot. The joint patch's matrix is
    /// positive definite (every band unknown has a proximal square in H), so the solves
    /// are exact to round-off and iterative refinement stops after one residual, where
    /// with `δ` it took 2–3 more solves per Newton system. Default true.
    pub unregularised_first: bool,
    /// A warm start ([`super::Problem::solve_warm`]) moves every slack and multiplier at
    /// least `√warm_mu` inside its cone (on the equilibrated problem), so the products
    /// start near this complementarity rather than at the previous solve's last one,
    /// from which the changed problem's residuals could not be reduced in full steps.
    /// Default 1e-4.
    pub warm_mu: f64,
    /// Most iterative refinement steps per solve (it stops earlier when the residual is
    /// below [`crate::tolerances::IPM_REFINE_REL_TOL`] (1e-13) of the right-hand side).
    /// Default 4.
    pub refinement_steps: u32,
    /// Divide the objective (and `H`) by its largest coefficient before solving, as the
    /// rows are divided by theirs. The stopping rule's gap (`μ ≤ tol_gap·(1 + |objective|)`)
    /// is then relative to that coefficient: for the joint patch, whose objective is
    /// `t + M·e` with `M` = 10⁴, it leaves `t` — the largest orientation change, 10⁻³–10⁻¹
    /// — unsolved by a few per cent, and the SCP takes more, noisier steps; unscaled, the
    /// gap is on `t`'s own scale. Default true (the joint patch sets false:
    /// `SolverSettings::ipm`).
    pub scale_objective: bool,
}

impl Default for IpmSettings {
    fn default() -> Self {
        IpmSettings {
            max_iter: 60,
            tol_feas: 1e-8,
            tol_gap: 1e-8,
            step_fraction: 0.99,
            regularisation: 1e-9,
            unregularised_first: true,
            warm_mu: 1e-4,
            refinement_steps: 4,
            scale_objective: true,
        }
    }
}
