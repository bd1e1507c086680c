//! The interior-point loop (module docs of [`super`]), written as Clarabel's solver loop
//! is: one driver ([`Problem::solve_warm`]) over named steps on the loop's state —
//!
//! 1. the start: [`Iterate::cold`] (CVXOPT's) or [`Iterate::warm`] (a previous solve's,
//!    centred);
//! 2. the residuals `r_d`, `r_g`, `μ` and the objective ([`Residuals::update`]) and the
//!    termination checks ([`Residuals::converged`]);
//! 3. the scalings at the iterate ([`Scalings::update`]) and the KKT factor
//!    ([`Newton::factor`]);
//! 4. the predictor: `r_c = λ∘λ` ([`affine_rc`]) and its Newton step
//!    ([`Newton::direction`]), then `σ` ([`centring`]);
//! 5. the corrector: `r_c = λ∘λ + (W⁻ᵀ·ds_a)∘(W·dz_a) − σ·μ·e` ([`corrector_rc`]) and its
//!    Newton step;
//! 6. the step length ([`step_length`]) and the step ([`Iterate::take_step`]).

// Index loops mirror the method's formulas (rows, cones).
#![allow(clippy::needless_range_loop)]

use super::band::{BorderedBand, refine};
use super::cones::{MAX_CONE, SocScaling, soc_div, soc_prod, soc_scaling, soc_step};
use super::kkt::Kkt;
use super::problem::Problem;
use super::{IpmSettings, IpmSolution, IpmStatus, IpmWarm, inf_norm};
use crate::tolerances::{IPM_COLD_DEPTH, IPM_SLACK_FLOOR};

impl Problem {
    /// Solve (module docs of [`super`]): Mehrotra's predictor–corrector with
    /// Nesterov–Todd scaling from CVXOPT's start, on the equilibrated problem.
    #[cfg(test)]
    pub fn solve(self, st: &IpmSettings) -> IpmSolution {
        self.equilibrated(st.scale_objective).solve_scaled(st, None)
    }

    /// [`Problem::solve`] from a warm start ([`IpmWarm`]: a previous solve's primal point
    /// and multipliers, of a problem of the same shape), or cold when `warm` is `None` or
    /// of another shape.
    pub fn solve_warm(self, st: &IpmSettings, warm: Option<&IpmWarm>) -> IpmSolution {
        self.equilibrated(st.scale_objective).solve_scaled(st, warm)
    }

    /// The loop (module docs): the steps in their order.
    fn solve_scaled(&self, st: &IpmSettings, warm: Option<&IpmWarm>) -> IpmSolution {
        let sys = Structure::new(self);
        let mut newton = Newton::new(&sys);
        let mut sc = Scalings::new(&sys);
        let warm = warm.filter(|w| w.x.len() == sys.n && w.z.len() == sys.kkt.mi);
        let mut it = match warm {
            Some(w) => Iterate::warm(&sys, w, st),
            None => Iterate::cold(&sys, &self.c, &sc, &mut newton, st),
        };
        let scale_h = 1.0 + inf_norm(&sys.kkt.h);
        let scale_c = 1.0 + inf_norm(&self.c);
        let mut res = Residuals::new(&sys);
        let (mut affine, mut step) = (Direction::new(&sys), Direction::new(&sys));
        let mut rc = vec![0.0; sys.kkt.mi];
        for k in 0..st.max_iter {
            let (mu, obj) = res.update(&sys, &self.c, &it);
            if !(obj.is_finite() && mu.is_finite()) {
                return it.end(IpmStatus::NumericalError, k);
            }
            if res.converged(st, (scale_h, scale_c), mu, obj) {
                return it.end(IpmStatus::Solved, k);
            }
            sc.update(&sys, &it);
            if !newton.factor(&sys, &sc, st) {
                return it.end(IpmStatus::NumericalError, k);
            }
            affine_rc(&sys, &sc, &mut rc);
            newton.direction(&sys, &sc, &res, &rc, &mut affine, st);
            let sigma = centring(&sys, &it, &affine, mu);
            let smu = sigma * mu;
            corrector_rc(&sys, &sc, &affine, smu, &mut rc);
            newton.direction(&sys, &sc, &res, &rc, &mut step, st);
            let alpha = step_length(&sys, &it, &step, st);
            if !(alpha.is_finite() && step.dx.iter().all(|v| v.is_finite())) {
                return it.end(IpmStatus::NumericalError, k);
            }
            it.take_step(&sys, alpha, &step);
        }
        it.end(IpmStatus::MaxIterations, st.max_iter)
    }
}

/// What the loop knows of the problem, fixed over its iterations: the KKT system's
/// structure, `H` as a bordered band, the cones' blocks `(first slack, rows)` and the
/// degree `ν` (one per linear row and per cone).
struct Structure<'a> {
    kkt: Kkt<'a>,
    hmat: BorderedBand,
    blocks: Vec<(usize, usize)>,
    /// Unknowns (band and border).
    n: usize,
    /// Linear slacks (the rest are the cones').
    ml: usize,
    /// Half-bandwidth of the KKT matrix.
    w: usize,
    degree: f64,
}

impl<'a> Structure<'a> {
    fn new(p: &'a Problem) -> Structure<'a> {
        let kkt = Kkt::new(p);
        let degree = (kkt.ml + kkt.cones.len()).max(1) as f64;
        let w = p.half_bandwidth();
        let hmat = kkt.h_matrix(w);
        let blocks = kkt.cones.iter().map(|c| (c.b0, c.q)).collect();
        Structure {
            n: p.nb + p.k,
            ml: kkt.ml,
            kkt,
            hmat,
            blocks,
            w,
            degree,
        }
    }
}

/// The iterate: the primal point `x`, the slacks `s` and the multipliers `z`.
struct Iterate {
    x: Vec<f64>,
    s: Vec<f64>,
    z: Vec<f64>,
}

impl Iterate {
    /// Warm: x as given, ŝ = h − G·x and the previous multipliers, centred by Mehrotra's
    /// heuristic ([`centre`]) at least √warm_mu inside every cone: the products start near
    /// `warm_mu`, where the previous solve was some iterations before its end, not at its
    /// last complementarity (from which the changed problem's residuals could not be
    /// reduced in full steps).
    fn warm(sys: &Structure<'_>, w: &IpmWarm, st: &IpmSettings) -> Iterate {
        let mi = sys.kkt.mi;
        let (mut x, mut s, mut z) = (vec![0.0; sys.n], vec![0.0; mi], vec![0.0; mi]);
        x.copy_from_slice(&w.x);
        sys.kkt.g_mul(&x, &mut s);
        for (sr, hr) in s.iter_mut().zip(&sys.kkt.h) {
            *sr = hr - *sr;
        }
        z.copy_from_slice(&w.z);
        centre(&mut s, &mut z, sys.ml, &sys.blocks, st.warm_mu.sqrt());
        Iterate { x, s, z }
    }

    /// Cold (CVXOPT's start): x̂ minimising ½xᵀHx + cᵀx + ½‖G·x − h‖² (the KKT matrix at
    /// the identity scalings `sc`), then ŝ = h − G·x̂ and ẑ = −ŝ, each moved into the
    /// cones' interiors.
    fn cold(
        sys: &Structure<'_>,
        c: &[f64],
        sc: &Scalings,
        newton: &mut Newton,
        st: &IpmSettings,
    ) -> Iterate {
        let (ml, mi, hv) = (sys.ml, sys.kkt.mi, &sys.kkt.h);
        let (mut x, mut s, mut z) = (vec![0.0; sys.n], vec![0.0; mi], vec![0.0; mi]);
        if newton.factor(sys, sc, st) {
            let Newton {
                unreg,
                kkt,
                rhs,
                sol,
                tmp,
                ..
            } = newton;
            for (r, c) in rhs.iter_mut().zip(c) {
                *r = -c;
            }
            sys.kkt.gt_mul_add(hv, rhs);
            sol.copy_from_slice(rhs);
            kkt.solve(sol);
            refine(kkt, unreg, rhs, sol, tmp, st.refinement_steps);
            if sol.iter().all(|v| v.is_finite()) {
                x.copy_from_slice(sol);
            }
        }
        sys.kkt.g_mul(&x, &mut s);
        for (sr, hr) in s.iter_mut().zip(hv) {
            *sr = hr - *sr;
        }
        for (zr, sr) in z.iter_mut().zip(&s) {
            *zr = -sr;
        }
        // Shift into the interior: by 1 + the distance outside (the largest violation).
        // (Mehrotra's heuristic, as a warm start is centred, took 11 % more
        // iterations on the held-out-like zones.)
        for v in [&mut s, &mut z] {
            let a = outside(v, ml, &sys.blocks);
            if a >= -IPM_COLD_DEPTH || !a.is_finite() {
                let shift = if a.is_finite() { 1.0 + a } else { 1.0 };
                v[..ml].iter_mut().for_each(|x| *x += shift);
                for &(b0, _) in &sys.blocks {
                    v[b0] += shift;
                }
            }
        }
        Iterate { x, s, z }
    }

    /// Step `alpha` along `dir`, the linear slacks and multipliers kept at least
    /// [`IPM_SLACK_FLOOR`].
    fn take_step(&mut self, sys: &Structure<'_>, alpha: f64, dir: &Direction) {
        let ml = sys.ml;
        let Iterate { x, s, z } = self;
        for (xj, dj) in x.iter_mut().zip(&dir.dx) {
            *xj += alpha * dj;
        }
        for ((sr, dsr), (zr, dzr)) in s.iter_mut().zip(&dir.ds).zip(z.iter_mut().zip(&dir.dz)) {
            *sr += alpha * dsr;
            *zr += alpha * dzr;
        }
        for (sr, zr) in s[..ml].iter_mut().zip(z[..ml].iter_mut()) {
            *sr = sr.max(IPM_SLACK_FLOOR);
            *zr = zr.max(IPM_SLACK_FLOOR);
        }
    }

    /// The solution as it stands, with how and after how many iterations the loop ended.
    fn end(self, status: IpmStatus, iterations: u32) -> IpmSolution {
        IpmSolution {
            x: self.x,
            z: self.z,
            status,
            iterations,
        }
    }
}

/// The residuals at the iterate: `r_d = H·x + c + Gᵀ·z`, `r_g = G·x + s − h`, and `H·x`.
struct Residuals {
    rd: Vec<f64>,
    rg: Vec<f64>,
    hx: Vec<f64>,
}

impl Residuals {
    fn new(sys: &Structure<'_>) -> Residuals {
        Residuals {
            rd: vec![0.0; sys.n],
            rg: vec![0.0; sys.kkt.mi],
            hx: vec![0.0; sys.n],
        }
    }

    /// The residuals at `it`; returns `μ = sᵀz/ν` and the objective `½xᵀHx + cᵀx`.
    fn update(&mut self, sys: &Structure<'_>, c: &[f64], it: &Iterate) -> (f64, f64) {
        let Residuals { rd, rg, hx } = self;
        sys.hmat.mul(&it.x, hx);
        for ((r, c), h) in rd.iter_mut().zip(c).zip(hx.iter()) {
            *r = c + h;
        }
        sys.kkt.gt_mul_add(&it.z, rd);
        sys.kkt.g_mul(&it.x, rg);
        for ((r, sr), hr) in rg.iter_mut().zip(&it.s).zip(&sys.kkt.h) {
            *r += sr - hr;
        }
        let mu = dot(&it.s, &it.z) / sys.degree;
        let obj = 0.5 * dot(hx, &it.x) + dot(c, &it.x);
        (mu, obj)
    }

    /// Converged: `‖r_g‖∞ ≤ tol_feas·(1 + ‖h‖∞)`, `‖r_d‖∞ ≤ tol_feas·(1 + ‖c‖∞)` and
    /// `μ ≤ tol_gap·(1 + |objective|)` (`scale`: the two `1 + ‖·‖∞`).
    fn converged(
        &self,
        st: &IpmSettings,
        (scale_h, scale_c): (f64, f64),
        mu: f64,
        obj: f64,
    ) -> bool {
        inf_norm(&self.rg) <= st.tol_feas * scale_h
            && inf_norm(&self.rd) <= st.tol_feas * scale_c
            && mu <= st.tol_gap * (1.0 + obj.abs())
    }
}

/// The scalings at the iterate: on the linear slacks `V = z/s` (`d`) and `W⁻¹ = √(z/s)`
/// (`d_sqrt`), on the cones their Nesterov–Todd `W`; and `λ = W·z`.
struct Scalings {
    d: Vec<f64>,
    d_sqrt: Vec<f64>,
    scal: Vec<SocScaling>,
    lam: Vec<f64>,
}

impl Scalings {
    /// The identity scalings (the cold start's KKT matrix).
    fn new(sys: &Structure<'_>) -> Scalings {
        let ident = SocScaling {
            eta: 1.0,
            wbar: {
                let mut e = [0.0; MAX_CONE];
                e[0] = 1.0;
                e
            },
        };
        Scalings {
            d: vec![1.0; sys.ml],
            d_sqrt: vec![1.0; sys.ml],
            scal: vec![ident; sys.blocks.len()],
            lam: vec![0.0; sys.kkt.mi],
        }
    }

    /// The scalings at `it`.
    fn update(&mut self, sys: &Structure<'_>, it: &Iterate) {
        let ml = sys.ml;
        let (s, z) = (&it.s, &it.z);
        for ((((l, dr), dq), sr), zr) in self.lam[..ml]
            .iter_mut()
            .zip(self.d.iter_mut())
            .zip(self.d_sqrt.iter_mut())
            .zip(&s[..ml])
            .zip(&z[..ml])
        {
            *l = (sr * zr).sqrt();
            *dr = zr / sr;
            *dq = dr.sqrt();
        }
        for (bi, &(b0, q)) in sys.blocks.iter().enumerate() {
            self.scal[bi] = soc_scaling(&s[b0..b0 + q], &z[b0..b0 + q], &mut self.lam[b0..b0 + q]);
        }
    }
}

/// A search direction `(dx, ds, dz)`.
struct Direction {
    dx: Vec<f64>,
    ds: Vec<f64>,
    dz: Vec<f64>,
}

impl Direction {
    fn new(sys: &Structure<'_>) -> Direction {
        Direction {
            dx: vec![0.0; sys.n],
            ds: vec![0.0; sys.kkt.mi],
            dz: vec![0.0; sys.kkt.mi],
        }
    }
}

/// The KKT matrix `H + Gᵀ·V·G` (factored, and unregularised for the refinement) and the
/// buffers of its Newton solves.
struct Newton {
    unreg: BorderedBand,
    kkt: BorderedBand,
    /// The assembly's scratch.
    y: Vec<f64>,
    rhs: Vec<f64>,
    sol: Vec<f64>,
    tmp: Vec<f64>,
    /// `w = V·r_g + W⁻¹·u`.
    w_r: Vec<f64>,
    /// `G·dx`.
    gdx: Vec<f64>,
}

impl Newton {
    fn new(sys: &Structure<'_>) -> Newton {
        let (nb, k, n, mi) = (sys.kkt.nb, sys.kkt.k, sys.n, sys.kkt.mi);
        Newton {
            unreg: BorderedBand::new(nb, sys.w, k),
            kkt: BorderedBand::new(nb, sys.w, k),
            y: Vec::new(),
            rhs: vec![0.0; n],
            sol: vec![0.0; n],
            tmp: vec![0.0; n],
            w_r: vec![0.0; mi],
            gdx: vec![0.0; mi],
        }
    }

    /// Assemble and factor the KKT matrix at the scalings `sc` ([`assemble_factor`]);
    /// `false` when it cannot be factored.
    fn factor(&mut self, sys: &Structure<'_>, sc: &Scalings, st: &IpmSettings) -> bool {
        assemble_factor(
            &sys.kkt,
            &sys.hmat,
            (&sc.d, &sc.scal),
            &mut self.y,
            st,
            &mut self.unreg,
            &mut self.kkt,
        )
    }

    /// One Newton solve for the complementarity residual `rc` (module docs of [`super`],
    /// with u = λ \ (−r_c), w = V·r_g + W⁻¹·u): the step `dir`.
    fn direction(
        &mut self,
        sys: &Structure<'_>,
        sc: &Scalings,
        res: &Residuals,
        rc: &[f64],
        dir: &mut Direction,
        st: &IpmSettings,
    ) {
        let ml = sys.ml;
        let (lam, d, d_sqrt, scal) = (&sc.lam, &sc.d, &sc.d_sqrt, &sc.scal);
        let (rd, rg) = (&res.rd, &res.rg);
        let Newton {
            unreg,
            kkt,
            rhs,
            sol,
            tmp,
            w_r,
            gdx,
            ..
        } = self;
        let Direction { dx, ds, dz } = dir;
        // Linear slacks: u = −r_c/λ, w = V·r_g + W⁻¹·u with V = z/s, W⁻¹ = √(z/s).
        for (((((wr, rcr), l), dr), dq), g) in w_r[..ml]
            .iter_mut()
            .zip(&rc[..ml])
            .zip(&lam[..ml])
            .zip(d)
            .zip(d_sqrt)
            .zip(&rg[..ml])
        {
            *wr = dr * g + dq * (-rcr / l);
        }
        for (bi, &(b0, q)) in sys.blocks.iter().enumerate() {
            let (mut neg, mut u) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
            for (dd, v) in neg.iter_mut().zip(&rc[b0..b0 + q]) {
                *dd = -v;
            }
            soc_div(&lam[b0..b0 + q], &neg[..q], &mut u[..q]);
            // W⁻¹·(W⁻¹·r_g + u).
            let mut t = [0.0; MAX_CONE];
            scal[bi].apply_inv(&rg[b0..b0 + q], &mut t[..q]);
            for a in 0..q {
                t[a] += u[a];
            }
            scal[bi].apply_inv(&t[..q], &mut w_r[b0..b0 + q]);
        }
        rhs.copy_from_slice(rd);
        sys.kkt.gt_mul_add(w_r, rhs);
        for v in rhs.iter_mut() {
            *v = -*v;
        }
        sol.copy_from_slice(rhs);
        kkt.solve(sol);
        refine(kkt, unreg, rhs, sol, tmp, st.refinement_steps);
        dx.copy_from_slice(sol);
        sys.kkt.g_mul(dx, gdx);
        for ((dsr, g), gd) in ds.iter_mut().zip(rg).zip(gdx.iter()) {
            *dsr = -g - gd;
        }
        for (((dzr, dr), gd), wr) in dz[..ml].iter_mut().zip(d).zip(&gdx[..ml]).zip(w_r.iter()) {
            *dzr = dr * gd + wr;
        }
        for (bi, &(b0, q)) in sys.blocks.iter().enumerate() {
            let (mut t, mut t2) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
            scal[bi].apply_inv(&gdx[b0..b0 + q], &mut t[..q]);
            scal[bi].apply_inv(&t[..q], &mut t2[..q]);
            for a in 0..q {
                dz[b0 + a] = t2[a] + w_r[b0 + a];
            }
        }
    }
}

/// The predictor's complementarity residual: `r_c = λ∘λ`.
fn affine_rc(sys: &Structure<'_>, sc: &Scalings, rc: &mut [f64]) {
    let (ml, lam) = (sys.ml, &sc.lam);
    for (r, l) in rc[..ml].iter_mut().zip(&lam[..ml]) {
        *r = l * l;
    }
    for &(b0, q) in &sys.blocks {
        let mut l = [0.0; MAX_CONE];
        l[..q].copy_from_slice(&lam[b0..b0 + q]);
        soc_prod(&l[..q], &l[..q], &mut rc[b0..b0 + q]);
    }
}

/// Mehrotra's centring parameter `σ = (μ_aff/μ)³` (at most 1; 0 when `μ` is not
/// positive), `μ_aff` the complementarity after the affine step `aff`'s largest length.
fn centring(sys: &Structure<'_>, it: &Iterate, aff: &Direction, mu: f64) -> f64 {
    let (s, z) = (&it.s, &it.z);
    let (ds_a, dz_a) = (&aff.ds, &aff.dz);
    let a_aff = max_step(sys, s, ds_a).min(max_step(sys, z, dz_a)).min(1.0);
    let mu_aff = s
        .iter()
        .zip(ds_a)
        .zip(z.iter().zip(dz_a))
        .map(|((sr, dsr), (zr, dzr))| (sr + a_aff * dsr) * (zr + a_aff * dzr))
        .sum::<f64>()
        / sys.degree;
    if mu > 0.0 {
        (mu_aff / mu).powi(3).min(1.0)
    } else {
        0.0
    }
}

/// The corrector's complementarity residual:
/// `r_c = λ∘λ + (W⁻ᵀ·ds_a)∘(W·dz_a) − σ·μ·e` (`smu` = σ·μ, `aff` the affine step).
fn corrector_rc(sys: &Structure<'_>, sc: &Scalings, aff: &Direction, smu: f64, rc: &mut [f64]) {
    let (ml, lam) = (sys.ml, &sc.lam);
    let (ds_a, dz_a) = (&aff.ds, &aff.dz);
    for (((r, l), dsr), dzr) in rc[..ml]
        .iter_mut()
        .zip(&lam[..ml])
        .zip(&ds_a[..ml])
        .zip(&dz_a[..ml])
    {
        *r = l * l + dsr * dzr - smu;
    }
    for (bi, &(b0, q)) in sys.blocks.iter().enumerate() {
        let (mut sd, mut zd) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
        sc.scal[bi].apply_inv(&ds_a[b0..b0 + q], &mut sd[..q]);
        sc.scal[bi].apply(&dz_a[b0..b0 + q], &mut zd[..q]);
        let mut l = [0.0; MAX_CONE];
        l[..q].copy_from_slice(&lam[b0..b0 + q]);
        let (mut ll, mut sz) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
        soc_prod(&l[..q], &l[..q], &mut ll[..q]);
        soc_prod(&sd[..q], &zd[..q], &mut sz[..q]);
        for a in 0..q {
            rc[b0 + a] = ll[a] + sz[a];
        }
        rc[b0] -= smu;
    }
}

/// The step length along `dir`: [`IpmSettings::step_fraction`] of the largest that keeps
/// `s` and `z` in their cones, at most 1.
fn step_length(sys: &Structure<'_>, it: &Iterate, dir: &Direction, st: &IpmSettings) -> f64 {
    (st.step_fraction * max_step(sys, &it.s, &dir.ds).min(max_step(sys, &it.z, &dir.dz))).min(1.0)
}

/// The largest step `a` with `v + a·dv` in the cones (∞ when every direction stays).
fn max_step(sys: &Structure<'_>, v: &[f64], dv: &[f64]) -> f64 {
    let ml = sys.ml;
    let mut a = f64::INFINITY;
    for (vr, dr) in v[..ml].iter().zip(&dv[..ml]) {
        if *dr < 0.0 {
            a = a.min(-vr / dr);
        }
    }
    for &(b0, q) in &sys.blocks {
        a = soc_step(&v[b0..b0 + q], &dv[b0..b0 + q], a);
    }
    a
}

/// Assemble `H + Gᵀ·V·G` and factor it: unregularised first when
/// [`IpmSettings::unregularised_first`] (the matrix is positive definite; the solves are then
/// exact to round-off and the refinement stops after its first residual), else — or when
/// that factorisation meets a zero or non-finite pivot — with `±δ` on the diagonal
/// ([`IpmSettings::regularisation`]), refined against the unregularised matrix.
fn assemble_factor(
    sys: &Kkt<'_>,
    hmat: &BorderedBand,
    (d, scal): (&[f64], &[SocScaling]),
    y: &mut Vec<f64>,
    st: &IpmSettings,
    unreg: &mut BorderedBand,
    kkt: &mut BorderedBand,
) -> bool {
    if st.unregularised_first {
        sys.assemble(hmat, d, scal, y, 0.0, unreg, kkt);
        if kkt.factor() {
            return true;
        }
    }
    sys.assemble(hmat, d, scal, y, st.regularisation, unreg, kkt);
    kkt.factor()
}

/// How far `v` lies outside its cones: the largest of −v over the `ml` linear entries and
/// ‖tail‖ − head over each second-order block (negative inside).
fn outside(v: &[f64], ml: usize, blocks: &[(usize, usize)]) -> f64 {
    let mut a = v[..ml].iter().fold(f64::NEG_INFINITY, |a, x| a.max(-x));
    for &(b0, q) in blocks {
        let tail = v[b0 + 1..b0 + q].iter().map(|t| t * t).sum::<f64>().sqrt();
        a = a.max(tail - v[b0]);
    }
    a
}

/// Move `s` and `z` into their cones' interiors (Mehrotra's start heuristic, Nocedal &
/// Wright §14.2): each by 1.5 times its distance outside, then both by the shifts that
/// balance the products, `δs = ½·sᵀz/Σz_e` and `δz = ½·sᵀz/Σs_e` (e: the cones'
/// identities), then at least `floor` inside every cone.
fn centre(s: &mut [f64], z: &mut [f64], ml: usize, blocks: &[(usize, usize)], floor: f64) {
    for v in [&mut *s, &mut *z] {
        let a = outside(v, ml, blocks);
        let shift = if a.is_finite() {
            (1.5 * a).max(0.0)
        } else {
            1.0
        };
        v[..ml].iter_mut().for_each(|x| *x += shift);
        for &(b0, _) in blocks {
            v[b0] += shift;
        }
    }
    let sz = dot(s, z);
    let e_sum =
        |v: &[f64]| v[..ml].iter().sum::<f64>() + blocks.iter().map(|&(b0, _)| v[b0]).sum::<f64>();
    let (ds, dz) = (0.5 * sz / e_sum(z), 0.5 * sz / e_sum(s));
    for (v, d) in [(s, ds), (z, dz)] {
        let d = if d.is_finite() { d } else { 0.0 };
        v[..ml].iter_mut().for_each(|x| *x = (*x + d).max(floor));
        for &(b0, q) in blocks {
            v[b0] += d;
            let tail = v[b0 + 1..b0 + q].iter().map(|t| t * t).sum::<f64>().sqrt();
            v[b0] = v[b0].max(tail + floor);
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// minimise (x0 − 1)² + (x1 − 2)² s.t. 0 ≤ x0 + x1 ≤ 1, x1 ≤ 0.5 → (0.5, 0.5).
    #[test]
    fn planted_qp_with_a_pair_and_a_bound() {
        let mut p = Problem::new(2, 0);
        p.add_square(&[(0, 1.0)], 1.0, 1.0);
        p.add_square(&[(1, 1.0)], 1.0, 2.0);
        p.add_pair(&[(0, 1.0), (1, 1.0)], 0.0, 1.0, None);
        p.add_le(&[(1, 1.0)], 0.5);
        let r = p.solve(&IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        assert!(
            (r.x[0] - 0.5).abs() < 1e-7 && (r.x[1] - 0.5).abs() < 1e-7,
            "{r:?}"
        );
    }

    /// A planted minimax with a border unknown: minimise t s.t. |x_i − a_i| ≤ t, with a
    /// chain `|x_{i+1} − x_i − 1| ≤ 0.25` along the band: without the chain the answer
    /// would be 0; with it, x_i = x_0 + i ± … and the answer is checked against a
    /// brute-force search of the same LP's optimum by bisection on t with a feasibility
    /// sweep (interval propagation along the chain, exact for this structure).
    #[test]
    fn planted_minimax_with_a_border() {
        let n = 40;
        let a: Vec<f64> = (0..n)
            .map(|i| i as f64 + 2.0 * (i as f64 * 0.7).sin())
            .collect();
        let mut p = Problem::new(n, 1);
        p.add_linear(n, 1.0);
        for i in 0..n - 1 {
            p.add_pair(&[(i + 1, 1.0), (i, -1.0)], 0.75, 1.25, None);
        }
        for (i, ai) in a.iter().enumerate() {
            p.add_le(&[(i, 1.0), (n, -1.0)], *ai);
            p.add_le(&[(i, -1.0), (n, -1.0)], -ai);
        }
        let r = p.solve(&IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        // Feasible for t: intervals [a_i − t, a_i + t] propagated along the chain.
        let feasible = |t: f64| {
            let (mut lo, mut hi) = (a[0] - t, a[0] + t);
            for ai in &a[1..] {
                lo = (lo + 0.75).max(ai - t);
                hi = (hi + 1.25).min(ai + t);
                if lo > hi {
                    return false;
                }
            }
            true
        };
        let (mut lo, mut hi) = (0.0, 10.0);
        for _ in 0..60 {
            let m = 0.5 * (lo + hi);
            if feasible(m) { hi = m } else { lo = m }
        }
        assert!((r.x[n] - hi).abs() < 1e-6, "{} vs {hi}", r.x[n]);
        assert!(r.iterations < 40, "{}", r.iterations);
    }

    /// Planted SOCP: minimise t s.t. ‖(x0 − 3, x1 − 4)‖ ≤ t, −1e-9 ≤ x0 + x1 ≤ 1e-9 → the
    /// distance from (3, 4) to the line x0 + x1 = 0 is 7/√2, at (−0.5, 0.5).
    #[test]
    fn planted_second_order_cone() {
        let mut p = Problem::new(2, 1);
        p.add_linear(2, 1.0);
        p.add_pair(&[(0, 1.0), (1, 1.0)], -1e-9, 1e-9, None);
        p.add_soc(&[(&[(2, -1.0)], 0.0), (&[(0, 1.0)], 3.0), (&[(1, 1.0)], 4.0)]);
        let r = p.solve(&IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        assert!((r.x[2] - 7.0 / 2f64.sqrt()).abs() < 1e-6, "{r:?}");
        assert!(
            (r.x[0] + 0.5).abs() < 1e-5 && (r.x[1] - 0.5).abs() < 1e-5,
            "{r:?}"
        );
    }

    /// A planted minimax of distances in the plane along a band (Weber-like): the point
    /// chain (x_i, y_i) = (x0 + i, y0) that comes closest, in the largest Euclidean
    /// distance, to scattered targets — written with the chain's steps as nearly tight
    /// pairs (±1e-9) along the band — checked against a brute-force grid search.
    #[test]
    fn planted_chain_minimax_of_distances() {
        let n = 12;
        let targets: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let t = i as f64;
                [t + (t * 1.3).sin(), (t * 0.7).cos()]
            })
            .collect();
        // Unknowns: (x_i, y_i) interleaved, then t.
        let mut p = Problem::new(2 * n, 1);
        p.add_linear(2 * n, 1.0);
        for i in 0..n - 1 {
            p.add_pair(
                &[(2 * i + 2, 1.0), (2 * i, -1.0)],
                1.0 - 1e-9,
                1.0 + 1e-9,
                None,
            );
            p.add_pair(&[(2 * i + 3, 1.0), (2 * i + 1, -1.0)], -1e-9, 1e-9, None);
        }
        for (i, tg) in targets.iter().enumerate() {
            p.add_soc(&[
                (&[(2 * n, -1.0)], 0.0),
                (&[(2 * i, 1.0)], tg[0]),
                (&[(2 * i + 1, 1.0)], tg[1]),
            ]);
        }
        let r = p.solve(&IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        // Brute force over the chain's start (x0, y0).
        let worst = |x0: f64, y0: f64| {
            targets
                .iter()
                .enumerate()
                .map(|(i, t)| ((x0 + i as f64 - t[0]).powi(2) + (y0 - t[1]).powi(2)).sqrt())
                .fold(0.0f64, f64::max)
        };
        let mut best = f64::INFINITY;
        for a in 0..400 {
            for b in 0..400 {
                best = best.min(worst(-2.0 + a as f64 * 0.01, -2.0 + b as f64 * 0.01));
            }
        }
        assert!(
            r.x[2 * n] <= best + 1e-6 && r.x[2 * n] > best - 0.02,
            "{} vs {best}",
            r.x[2 * n]
        );
        assert!((worst(r.x[0], r.x[1]) - r.x[2 * n]).abs() < 1e-6);
    }
}
