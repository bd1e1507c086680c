//! The interior-point loop (module docs of [`super`]): equilibration, the start, the
//! residuals, the scalings, the predictor and corrector steps.

// Index loops mirror the method's formulas (rows, cones).
#![allow(clippy::needless_range_loop)]

use super::band::{BorderedBand, refine};
use super::cones::{MAX_CONE, SocScaling, soc_div, soc_prod, soc_scaling, soc_step};
use super::kkt::Kkt;
use super::problem::Problem;
use super::{IpmSettings, IpmSolution, IpmStatus, IpmWarm, inf_norm};

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

    fn solve_scaled(&self, st: &IpmSettings, warm: Option<&IpmWarm>) -> IpmSolution {
        let sys = Kkt::new(self);
        let (nb, k) = (self.nb, self.k);
        let n = nb + k;
        let (ml, mi) = (sys.ml, sys.mi);
        let hv = &sys.h;
        let degree = (ml + sys.cones.len()).max(1) as f64;
        let w = self.half_bandwidth();
        let hmat = sys.h_matrix(w);
        let mut unreg = BorderedBand::new(nb, w, k);
        let mut kkt = BorderedBand::new(nb, w, k);
        let blocks: Vec<(usize, usize)> = sys.cones.iter().map(|c| (c.b0, c.q)).collect();
        let mut d = vec![1.0; ml];
        let mut d_sqrt = vec![1.0; ml];
        let ident = SocScaling {
            eta: 1.0,
            wbar: {
                let mut e = [0.0; MAX_CONE];
                e[0] = 1.0;
                e
            },
        };
        let mut scal: Vec<SocScaling> = vec![ident; blocks.len()];
        let mut yscratch: Vec<f64> = Vec::new();
        let (mut rhs, mut sol, mut tmp) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let warm = warm.filter(|w| w.x.len() == n && w.z.len() == mi);
        let (mut x, mut s, mut z) = (vec![0.0; n], vec![0.0; mi], vec![0.0; mi]);
        if let Some(w) = warm {
            // Warm: x as given, ŝ = h − G·x and the previous multipliers, centred by
            // Mehrotra's heuristic ([`centre`]) at least √warm_mu inside every cone: the
            // products start near `warm_mu`, where the previous solve was some iterations
            // before its end, not at its last complementarity (from which the changed
            // problem's residuals could not be reduced in full steps).
            x.copy_from_slice(&w.x);
            sys.g_mul(&x, &mut s);
            for (sr, hr) in s.iter_mut().zip(hv) {
                *sr = hr - *sr;
            }
            z.copy_from_slice(&w.z);
            centre(&mut s, &mut z, ml, &blocks, st.warm_mu.sqrt());
        } else {
            // Start (CVXOPT's): x̂ minimising ½xᵀHx + cᵀx + ½‖G·x − h‖², then ŝ = h − G·x̂ and
            // ẑ = −ŝ, each moved into the cones' interiors.
            if assemble_factor(
                &sys,
                &hmat,
                (&d, &scal),
                &mut yscratch,
                st,
                &mut unreg,
                &mut kkt,
            ) {
                for (r, c) in rhs.iter_mut().zip(&self.c) {
                    *r = -c;
                }
                sys.gt_mul_add(hv, &mut rhs);
                sol.copy_from_slice(&rhs);
                kkt.solve(&mut sol);
                refine(&kkt, &unreg, &rhs, &mut sol, &mut tmp, st.refinement_steps);
                if sol.iter().all(|v| v.is_finite()) {
                    x.copy_from_slice(&sol);
                }
            }
            sys.g_mul(&x, &mut s);
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
                let a = outside(v, ml, &blocks);
                if a >= -1e-8 || !a.is_finite() {
                    let shift = if a.is_finite() { 1.0 + a } else { 1.0 };
                    v[..ml].iter_mut().for_each(|x| *x += shift);
                    for &(b0, _) in &blocks {
                        v[b0] += shift;
                    }
                }
            }
        }
        let scale_h = 1.0 + inf_norm(hv);
        let scale_c = 1.0 + inf_norm(&self.c);
        let (mut rd, mut rg, mut hx) = (vec![0.0; n], vec![0.0; mi], vec![0.0; n]);
        let mut lam = vec![0.0; mi];
        let (mut w_r, mut dz, mut ds, mut gdx) =
            (vec![0.0; mi], vec![0.0; mi], vec![0.0; mi], vec![0.0; mi]);
        let (mut dz_a, mut ds_a, mut rc) = (vec![0.0; mi], vec![0.0; mi], vec![0.0; mi]);
        let mut dx = vec![0.0; n];
        for it in 0..st.max_iter {
            // Residuals.
            hmat.mul(&x, &mut hx);
            for ((r, c), h) in rd.iter_mut().zip(&self.c).zip(&hx) {
                *r = c + h;
            }
            sys.gt_mul_add(&z, &mut rd);
            sys.g_mul(&x, &mut rg);
            for ((r, sr), hr) in rg.iter_mut().zip(&s).zip(hv) {
                *r += sr - hr;
            }
            let mu = dot(&s, &z) / degree;
            let obj = 0.5 * dot(&hx, &x) + dot(&self.c, &x);
            if !(obj.is_finite() && mu.is_finite()) {
                return IpmSolution {
                    x,
                    z: z.clone(),
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            if inf_norm(&rg) <= st.tol_feas * scale_h
                && inf_norm(&rd) <= st.tol_feas * scale_c
                && mu <= st.tol_gap * (1.0 + obj.abs())
            {
                return IpmSolution {
                    x,
                    z: z.clone(),
                    status: IpmStatus::Solved,
                    iterations: it,
                };
            }
            // Scalings: linear slacks `V = z/s`, `W⁻¹ = sqrt(z/s)`; cones their `W`.
            for ((((l, dr), dq), sr), zr) in lam[..ml]
                .iter_mut()
                .zip(d.iter_mut())
                .zip(d_sqrt.iter_mut())
                .zip(&s[..ml])
                .zip(&z[..ml])
            {
                *l = (sr * zr).sqrt();
                *dr = zr / sr;
                *dq = dr.sqrt();
            }
            for (bi, &(b0, q)) in blocks.iter().enumerate() {
                scal[bi] = soc_scaling(&s[b0..b0 + q], &z[b0..b0 + q], &mut lam[b0..b0 + q]);
            }
            if !assemble_factor(
                &sys,
                &hmat,
                (&d, &scal),
                &mut yscratch,
                st,
                &mut unreg,
                &mut kkt,
            ) {
                return IpmSolution {
                    x,
                    z: z.clone(),
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            // One Newton solve for the complementarity residual `rc` (module docs, with
            // u = λ \ (−r_c), w = V·r_g + W⁻¹·u): the steps dx, dz, ds.
            let mut newton = |rc: &[f64], dz: &mut [f64], ds: &mut [f64], dx: &mut [f64]| {
                // Linear slacks: u = −r_c/λ, w = V·r_g + W⁻¹·u with V = z/s, W⁻¹ = √(z/s).
                for (((((wr, rcr), l), dr), dq), g) in w_r[..ml]
                    .iter_mut()
                    .zip(&rc[..ml])
                    .zip(&lam[..ml])
                    .zip(&d)
                    .zip(&d_sqrt)
                    .zip(&rg[..ml])
                {
                    *wr = dr * g + dq * (-rcr / l);
                }
                for (bi, &(b0, q)) in blocks.iter().enumerate() {
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
                rhs.copy_from_slice(&rd);
                sys.gt_mul_add(&w_r, &mut rhs);
                for v in rhs.iter_mut() {
                    *v = -*v;
                }
                sol.copy_from_slice(&rhs);
                kkt.solve(&mut sol);
                refine(&kkt, &unreg, &rhs, &mut sol, &mut tmp, st.refinement_steps);
                dx.copy_from_slice(&sol);
                sys.g_mul(dx, &mut gdx);
                for ((dsr, g), gd) in ds.iter_mut().zip(&rg).zip(&gdx) {
                    *dsr = -g - gd;
                }
                for (((dzr, dr), gd), wr) in dz[..ml].iter_mut().zip(&d).zip(&gdx[..ml]).zip(&w_r) {
                    *dzr = dr * gd + wr;
                }
                for (bi, &(b0, q)) in blocks.iter().enumerate() {
                    let (mut t, mut t2) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
                    scal[bi].apply_inv(&gdx[b0..b0 + q], &mut t[..q]);
                    scal[bi].apply_inv(&t[..q], &mut t2[..q]);
                    for a in 0..q {
                        dz[b0 + a] = t2[a] + w_r[b0 + a];
                    }
                }
            };
            let max_step = |v: &[f64], dv: &[f64]| -> f64 {
                let mut a = f64::INFINITY;
                for (vr, dr) in v[..ml].iter().zip(&dv[..ml]) {
                    if *dr < 0.0 {
                        a = a.min(-vr / dr);
                    }
                }
                for &(b0, q) in &blocks {
                    a = soc_step(&v[b0..b0 + q], &dv[b0..b0 + q], a);
                }
                a
            };
            // Predictor: r_c = λ∘λ.
            for (r, l) in rc[..ml].iter_mut().zip(&lam[..ml]) {
                *r = l * l;
            }
            for &(b0, q) in &blocks {
                let mut l = [0.0; MAX_CONE];
                l[..q].copy_from_slice(&lam[b0..b0 + q]);
                soc_prod(&l[..q], &l[..q], &mut rc[b0..b0 + q]);
            }
            newton(&rc, &mut dz_a, &mut ds_a, &mut dx);
            let a_aff = max_step(&s, &ds_a).min(max_step(&z, &dz_a)).min(1.0);
            let mu_aff = s
                .iter()
                .zip(&ds_a)
                .zip(z.iter().zip(&dz_a))
                .map(|((sr, dsr), (zr, dzr))| (sr + a_aff * dsr) * (zr + a_aff * dzr))
                .sum::<f64>()
                / degree;
            let sigma = if mu > 0.0 {
                (mu_aff / mu).powi(3).min(1.0)
            } else {
                0.0
            };
            // Corrector: r_c = λ∘λ + (W⁻ᵀ·ds_a)∘(W·dz_a) − σ·μ·e.
            let smu = sigma * mu;
            for (((r, l), dsr), dzr) in rc[..ml]
                .iter_mut()
                .zip(&lam[..ml])
                .zip(&ds_a[..ml])
                .zip(&dz_a[..ml])
            {
                *r = l * l + dsr * dzr - smu;
            }
            for (bi, &(b0, q)) in blocks.iter().enumerate() {
                let (mut sd, mut zd) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
                scal[bi].apply_inv(&ds_a[b0..b0 + q], &mut sd[..q]);
                scal[bi].apply(&dz_a[b0..b0 + q], &mut zd[..q]);
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
            newton(&rc, &mut dz, &mut ds, &mut dx);
            let alpha = (st.step_fraction * max_step(&s, &ds).min(max_step(&z, &dz))).min(1.0);
            if !(alpha.is_finite() && dx.iter().all(|v| v.is_finite())) {
                return IpmSolution {
                    x,
                    z: z.clone(),
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            for (xj, dj) in x.iter_mut().zip(&dx) {
                *xj += alpha * dj;
            }
            for ((sr, dsr), (zr, dzr)) in s.iter_mut().zip(&ds).zip(z.iter_mut().zip(&dz)) {
                *sr += alpha * dsr;
                *zr += alpha * dzr;
            }
            for (sr, zr) in s[..ml].iter_mut().zip(z[..ml].iter_mut()) {
                *sr = sr.max(1e-300);
                *zr = zr.max(1e-300);
            }
        }
        IpmSolution {
            x,
            z: z.clone(),
            status: IpmStatus::MaxIterations,
            iterations: st.max_iter,
        }
    }
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
