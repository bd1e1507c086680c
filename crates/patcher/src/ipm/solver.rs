//! The interior-point loop (module docs of [`super`]): equilibration, the start, the
//! residuals, the scalings, the predictor and corrector steps.

// Index loops mirror the method's formulas (rows, cones).
#![allow(clippy::needless_range_loop)]

use super::band::{BorderedBand, Slot, refine};
use super::cones::{MAX_CONE, SocScaling, soc_div, soc_prod, soc_scaling, soc_step};
use super::kkt::{Assembler, Entry, Layout};
use super::{Banded, IpmSettings, IpmSolution, IpmStatus, Row, dot, inf_norm};

impl Banded {
    /// Solve from the primal point `x0` (any point; feasibility is not required).
    ///
    /// The problem is equilibrated first: every row (every cone's rows together) divided
    /// by its largest coefficient, the objective by its largest one. Neither changes the
    /// solution, and the tolerances then mean the same on every row.
    pub fn solve(&self, x0: &[f64], st: &IpmSettings) -> IpmSolution {
        let scale_row = |(row, rhs): &(Row, f64)| -> (Row, f64) {
            let m = row.iter().fold(0.0f64, |m, e| m.max(e.1.abs()));
            if m > 0.0 && m.is_finite() {
                (row.iter().map(|&(j, v)| (j, v / m)).collect(), rhs / m)
            } else {
                (row.clone(), *rhs)
            }
        };
        let obj = self
            .c
            .iter()
            .map(|v| v.abs())
            .chain(self.h.iter().map(|e| e.2.abs()))
            .fold(0.0f64, f64::max);
        let obj = if obj > 0.0 && obj.is_finite() {
            obj
        } else {
            1.0
        };
        let scaled = Banded {
            n: self.n,
            position: self.position.clone(),
            h: self.h.iter().map(|&(i, j, v)| (i, j, v / obj)).collect(),
            c: self.c.iter().map(|v| v / obj).collect(),
            eq: self.eq.iter().map(scale_row).collect(),
            le: self.le.iter().map(scale_row).collect(),
            soc: self
                .soc
                .iter()
                .map(|cone| {
                    let m = cone
                        .iter()
                        .flat_map(|(row, _)| row.iter())
                        .fold(0.0f64, |m, e| m.max(e.1.abs()));
                    let m = if m > 0.0 && m.is_finite() { m } else { 1.0 };
                    cone.iter()
                        .map(|(row, rhs)| (row.iter().map(|&(j, v)| (j, v / m)).collect(), rhs / m))
                        .collect()
                })
                .collect(),
        };
        scaled.solve_scaled(x0, st)
    }

    fn solve_scaled(&self, x0: &[f64], st: &IpmSettings) -> IpmSolution {
        assert!(
            self.soc.iter().all(|c| (2..=MAX_CONE).contains(&c.len())),
            "second-order cones have 2 to {MAX_CONE} rows"
        );
        let n = self.n;
        let me = self.eq.len();
        let ml = self.le.len();
        // Every cone row after the linear rows: rows[ml..], blocks of `soc` sizes.
        let rows: Vec<&(Row, f64)> = self.le.iter().chain(self.soc.iter().flatten()).collect();
        let mi = rows.len();
        let mut blocks: Vec<(usize, usize)> = Vec::with_capacity(self.soc.len());
        let mut at = ml;
        for cone in &self.soc {
            blocks.push((at, cone.len()));
            at += cone.len();
        }
        let degree = (ml + blocks.len()).max(1) as f64;
        let lay = Layout::new(self);
        let nk = lay.nb + lay.k;
        let slot_index = |sl: Slot| match sl {
            Slot::Band(i) => i,
            Slot::Border(r) => lay.nb + r,
        };
        let entries: Vec<Vec<Entry>> = rows
            .iter()
            .map(|(row, _)| {
                row.iter()
                    .map(|&(j, v)| Entry {
                        var: j,
                        slot: lay.var_slot(j),
                        v,
                    })
                    .collect()
            })
            .collect();
        let x_at: Vec<usize> = (0..n).map(|j| slot_index(lay.var_slot(j))).collect();
        let mut kkt = BorderedBand::new(lay.nb, lay.w, lay.k);
        let mut unreg = BorderedBand::new(lay.nb, lay.w, lay.k);
        let delta = st.regularisation;
        let asm = Assembler::new(self, &lay, &entries, &blocks);
        // The rows of G flat (compressed rows), for the products with G and Gᵀ.
        let mut ent_ptr: Vec<usize> = Vec::with_capacity(mi + 1);
        let (mut ent_var, mut ent_v): (Vec<u32>, Vec<f64>) = (Vec::new(), Vec::new());
        ent_ptr.push(0);
        for row in &entries {
            for e in row {
                ent_var.push(e.var as u32);
                ent_v.push(e.v);
            }
            ent_ptr.push(ent_var.len());
        }
        let mut gtw = vec![0.0; n];
        let mut vg: Vec<f64> = Vec::new();
        let mut d_lp = vec![1.0; ml];
        let mut d_sqrt = vec![1.0; ml];
        let mut v_cone: Vec<Vec<f64>> = blocks
            .iter()
            .map(|&(_, q)| {
                (0..q * q)
                    .map(|i| f64::from(u8::from(i % (q + 1) == 0)))
                    .collect()
            })
            .collect();
        let (mut rhs, mut sol, mut tmp) = (vec![0.0; nk], vec![0.0; nk], vec![0.0; nk]);
        // Start (CVXOPT's): x̂ minimising ½xᵀHx + cᵀx + ½‖G·x − h‖² with A·x = b, then
        // ŝ = h − G·x̂ and ẑ = −ŝ, each moved into the cones' interiors.
        asm.assemble(&d_lp, &v_cone, delta, &mut kkt, &mut unreg, &mut vg);
        let mut x = x0.to_vec();
        if kkt.factor() {
            for j in 0..n {
                rhs[x_at[j]] = -self.c[j];
            }
            for (r, (_, h)) in rows.iter().enumerate() {
                for e in &entries[r] {
                    rhs[x_at[e.var]] += e.v * h;
                }
            }
            for (r, (_, b)) in self.eq.iter().enumerate() {
                rhs[lay.eq_band[r]] = *b;
            }
            sol.copy_from_slice(&rhs);
            kkt.solve(&mut sol);
            refine(&kkt, &unreg, &rhs, &mut sol, &mut tmp, st.refinement_steps);
            if sol.iter().all(|v| v.is_finite()) {
                x = (0..n).map(|j| sol[x_at[j]]).collect();
            }
        }
        let _ = x0;
        let mut y = vec![0.0; me];
        let mut s: Vec<f64> = rows.iter().map(|(row, rhs)| rhs - dot(row, &x)).collect();
        let mut z: Vec<f64> = s.iter().map(|v| -v).collect();
        // Shift into the interior: by 1 + the distance outside (the largest violation).
        let outside = |v: &[f64]| -> f64 {
            let mut a = f64::NEG_INFINITY;
            for r in 0..ml {
                a = a.max(-v[r]);
            }
            for &(b0, q) in &blocks {
                let tail = v[b0 + 1..b0 + q].iter().map(|t| t * t).sum::<f64>().sqrt();
                a = a.max(tail - v[b0]);
            }
            a
        };
        for v in [&mut s, &mut z] {
            let a = outside(v);
            if a >= -1e-8 || !a.is_finite() {
                let shift = if a.is_finite() { 1.0 + a } else { 1.0 };
                for r in 0..ml {
                    v[r] += shift;
                }
                for &(b0, _) in &blocks {
                    v[b0] += shift;
                }
            }
        }
        let scale_b = 1.0 + self.eq.iter().fold(0.0f64, |m, e| m.max(e.1.abs()));
        let scale_h = 1.0 + rows.iter().fold(0.0f64, |m, e| m.max(e.1.abs()));
        let scale_c = 1.0 + inf_norm(&self.c);
        let (mut rd, mut rp, mut rg, mut hx) =
            (vec![0.0; n], vec![0.0; me], vec![0.0; mi], vec![0.0; n]);
        // Per-row scaling data: LP rows `V = z/s`, `W⁻¹ = sqrt(z/s)`; cones their matrices.
        let mut scal: Vec<SocScaling> = Vec::with_capacity(blocks.len());
        let mut lam = vec![0.0; mi];
        let (mut u, mut w_r, mut dz, mut ds, mut gdx) = (
            vec![0.0; mi],
            vec![0.0; mi],
            vec![0.0; mi],
            vec![0.0; mi],
            vec![0.0; mi],
        );
        let (mut dz_a, mut ds_a, mut rc) = (vec![0.0; mi], vec![0.0; mi], vec![0.0; mi]);
        let mut dxy: Vec<f64> = Vec::with_capacity(n + me);
        for it in 0..st.max_iter {
            // Residuals.
            rd.copy_from_slice(&self.c);
            hx.iter_mut().for_each(|v| *v = 0.0);
            self.h_mul(&x, &mut hx);
            for j in 0..n {
                rd[j] += hx[j];
            }
            for (r, (row, _)) in self.eq.iter().enumerate() {
                for &(j, v) in row {
                    rd[j] += v * y[r];
                }
            }
            for r in 0..mi {
                let mut g = 0.0;
                let zr = z[r];
                for k in ent_ptr[r]..ent_ptr[r + 1] {
                    let (j, v) = (ent_var[k] as usize, ent_v[k]);
                    g += v * x[j];
                    rd[j] += v * zr;
                }
                rg[r] = g + s[r] - rows[r].1;
            }
            for (r, (row, rhs_r)) in self.eq.iter().enumerate() {
                rp[r] = dot(row, &x) - rhs_r;
            }
            let mu = s.iter().zip(&z).map(|(a, b)| a * b).sum::<f64>() / degree;
            let obj = 0.5 * hx.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>()
                + self.c.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>();
            if !(obj.is_finite() && mu.is_finite()) {
                return IpmSolution {
                    x,
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            if inf_norm(&rp) <= st.tol_feas * scale_b
                && inf_norm(&rg) <= st.tol_feas * scale_h
                && inf_norm(&rd) <= st.tol_feas * scale_c
                && mu <= st.tol_gap * (1.0 + obj.abs())
            {
                return IpmSolution {
                    x,
                    status: IpmStatus::Solved,
                    iterations: it,
                };
            }
            // Scalings.
            for r in 0..ml {
                lam[r] = (s[r] * z[r]).sqrt();
            }
            scal.clear();
            for &(b0, q) in &blocks {
                let sc = soc_scaling(&s[b0..b0 + q], &z[b0..b0 + q]);
                lam[b0..b0 + q].copy_from_slice(&sc.lambda[..q]);
                scal.push(sc);
            }
            // The matrix: H + Gᵀ·V·G on the variables, A and Aᵀ, regularised.
            for r in 0..ml {
                d_lp[r] = z[r] / s[r];
                d_sqrt[r] = d_lp[r].sqrt();
            }
            for (bi, &(_, q)) in blocks.iter().enumerate() {
                // V = W⁻¹·W⁻¹ (symmetric).
                let wi = &scal[bi].winv;
                let v = &mut v_cone[bi];
                for a in 0..q {
                    for b in 0..q {
                        v[a * q + b] = (0..q).map(|m| wi[a * q + m] * wi[m * q + b]).sum();
                    }
                }
            }
            asm.assemble(&d_lp, &v_cone, delta, &mut kkt, &mut unreg, &mut vg);
            if !kkt.factor() {
                return IpmSolution {
                    x,
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            // One Newton solve for the complementarity residual `rc` (module docs, with
            // u = λ \ (−r_c), w = V·r_g + W⁻¹·u): the steps dx, dy, dz, ds.
            let mut newton = |rc: &[f64], dz: &mut [f64], ds: &mut [f64], dxy: &mut Vec<f64>| {
                for r in 0..ml {
                    u[r] = -rc[r] / lam[r];
                    // V·r_g + W⁻¹·u with V = z/s, W⁻¹ = sqrt(z/s).
                    w_r[r] = d_lp[r] * rg[r] + d_sqrt[r] * u[r];
                }
                for (bi, &(b0, q)) in blocks.iter().enumerate() {
                    let mut neg = [0.0; MAX_CONE];
                    for (d, v) in neg.iter_mut().zip(&rc[b0..b0 + q]) {
                        *d = -v;
                    }
                    soc_div(&lam[b0..b0 + q], &neg[..q], &mut u[b0..b0 + q]);
                    let wi = &scal[bi].winv;
                    // W⁻¹·(W⁻¹·r_g + u).
                    let mut t = [0.0; MAX_CONE];
                    for a in 0..q {
                        t[a] = (0..q).map(|m| wi[a * q + m] * rg[b0 + m]).sum::<f64>() + u[b0 + a];
                    }
                    for a in 0..q {
                        w_r[b0 + a] = (0..q).map(|m| wi[a * q + m] * t[m]).sum();
                    }
                }
                rhs.iter_mut().for_each(|v| *v = 0.0);
                gtw.iter_mut().for_each(|v| *v = 0.0);
                for r in 0..mi {
                    let wr = w_r[r];
                    for k in ent_ptr[r]..ent_ptr[r + 1] {
                        gtw[ent_var[k] as usize] += ent_v[k] * wr;
                    }
                }
                for j in 0..n {
                    rhs[x_at[j]] = -rd[j] - gtw[j];
                }
                for r in 0..me {
                    rhs[lay.eq_band[r]] = -rp[r];
                }
                sol.copy_from_slice(&rhs);
                kkt.solve(&mut sol);
                refine(&kkt, &unreg, &rhs, &mut sol, &mut tmp, st.refinement_steps);
                dxy.clear();
                dxy.extend((0..n).map(|j| sol[x_at[j]]));
                dxy.extend((0..me).map(|r| sol[lay.eq_band[r]]));
                for r in 0..mi {
                    gdx[r] = (ent_ptr[r]..ent_ptr[r + 1])
                        .map(|k| ent_v[k] * dxy[ent_var[k] as usize])
                        .sum();
                    ds[r] = -rg[r] - gdx[r];
                }
                for r in 0..ml {
                    dz[r] = d_lp[r] * gdx[r] + w_r[r];
                }
                for (bi, &(b0, q)) in blocks.iter().enumerate() {
                    let wi = &scal[bi].winv;
                    let mut t = [0.0; MAX_CONE];
                    for a in 0..q {
                        t[a] = (0..q).map(|m| wi[a * q + m] * gdx[b0 + m]).sum();
                    }
                    for a in 0..q {
                        dz[b0 + a] =
                            (0..q).map(|m| wi[a * q + m] * t[m]).sum::<f64>() + w_r[b0 + a];
                    }
                }
            };
            let max_step = |v: &[f64], dv: &[f64]| -> f64 {
                let mut a = f64::INFINITY;
                for r in 0..ml {
                    if dv[r] < 0.0 {
                        a = a.min(-v[r] / dv[r]);
                    }
                }
                for &(b0, q) in &blocks {
                    a = soc_step(&v[b0..b0 + q], &dv[b0..b0 + q], a);
                }
                a
            };
            // Predictor: r_c = λ∘λ.
            for r in 0..ml {
                rc[r] = lam[r] * lam[r];
            }
            for &(b0, q) in &blocks {
                let mut l = [0.0; MAX_CONE];
                l[..q].copy_from_slice(&lam[b0..b0 + q]);
                soc_prod(&l[..q], &l[..q], &mut rc[b0..b0 + q]);
            }
            newton(&rc, &mut dz_a, &mut ds_a, &mut dxy);
            let a_aff = max_step(&s, &ds_a).min(max_step(&z, &dz_a)).min(1.0);
            let mu_aff = (0..mi)
                .map(|r| (s[r] + a_aff * ds_a[r]) * (z[r] + a_aff * dz_a[r]))
                .sum::<f64>()
                / degree;
            let sigma = if mu > 0.0 {
                (mu_aff / mu).powi(3).min(1.0)
            } else {
                0.0
            };
            // Corrector: r_c = λ∘λ + (W⁻ᵀ·ds_a)∘(W·dz_a) − σ·μ·e.
            for r in 0..ml {
                rc[r] = lam[r] * lam[r] + ds_a[r] * dz_a[r] - sigma * mu;
            }
            for (bi, &(b0, q)) in blocks.iter().enumerate() {
                let (w, wi) = (&scal[bi].w, &scal[bi].winv);
                let (mut sd, mut zd) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
                for a in 0..q {
                    sd[a] = (0..q).map(|m| wi[a * q + m] * ds_a[b0 + m]).sum();
                    zd[a] = (0..q).map(|m| w[a * q + m] * dz_a[b0 + m]).sum();
                }
                let mut l = [0.0; MAX_CONE];
                l[..q].copy_from_slice(&lam[b0..b0 + q]);
                let (mut ll, mut sz) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
                soc_prod(&l[..q], &l[..q], &mut ll[..q]);
                soc_prod(&sd[..q], &zd[..q], &mut sz[..q]);
                for a in 0..q {
                    rc[b0 + a] = ll[a] + sz[a];
                }
                rc[b0] -= sigma * mu;
            }
            newton(&rc, &mut dz, &mut ds, &mut dxy);
            let alpha = (st.step_fraction * max_step(&s, &ds).min(max_step(&z, &dz))).min(1.0);
            if !(alpha.is_finite() && dxy.iter().all(|v| v.is_finite())) {
                return IpmSolution {
                    x,
                    status: IpmStatus::NumericalError,
                    iterations: it,
                };
            }
            for j in 0..n {
                x[j] += alpha * dxy[j];
            }
            for r in 0..me {
                y[r] += alpha * dxy[n + r];
            }
            for r in 0..mi {
                s[r] += alpha * ds[r];
                z[r] += alpha * dz[r];
            }
            for r in 0..ml {
                s[r] = s[r].max(1e-300);
                z[r] = z[r].max(1e-300);
            }
        }
        IpmSolution {
            x,
            status: IpmStatus::MaxIterations,
            iterations: st.max_iter,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// minimise (x0 − 1)² + (x1 − 2)² s.t. x0 + x1 = 1, x1 ≤ 0.5 → (0.5, 0.5).
    #[test]
    fn planted_qp_with_equality_and_bound() {
        let mut p = Banded::new(2);
        p.position = vec![Some(0.0), Some(1.0)];
        p.h = vec![(0, 0, 2.0), (1, 1, 2.0)];
        p.c = vec![-2.0, -4.0];
        p.eq.push((vec![(0, 1.0), (1, 1.0)], 1.0));
        p.le.push((vec![(1, 1.0)], 0.5));
        let r = p.solve(&[0.0, 0.0], &IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        assert!(
            (r.x[0] - 0.5).abs() < 1e-7 && (r.x[1] - 0.5).abs() < 1e-7,
            "{r:?}"
        );
    }

    /// A planted minimax with a border variable: minimise t s.t. |x_i − a_i| ≤ t and a
    /// chain of equalities x_{i+1} − x_i = 1 along the band: the answer is the half range
    /// of a_i − i.
    #[test]
    fn planted_minimax_with_a_border() {
        let n = 40;
        let a: Vec<f64> = (0..n).map(|i| i as f64 + (i as f64 * 0.7).sin()).collect();
        let mut p = Banded::new(n + 1);
        for i in 0..n {
            p.position[i] = Some(i as f64);
        }
        p.position[n] = None;
        p.c[n] = 1.0;
        for i in 0..n - 1 {
            p.eq.push((vec![(i + 1, 1.0), (i, -1.0)], 1.0));
        }
        for (i, ai) in a.iter().enumerate() {
            p.le.push((vec![(i, 1.0), (n, -1.0)], *ai));
            p.le.push((vec![(i, -1.0), (n, -1.0)], -ai));
        }
        let r = p.solve(&vec![0.0; n + 1], &IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        let d: Vec<f64> = a.iter().enumerate().map(|(i, v)| v - i as f64).collect();
        let (lo, hi) = d
            .iter()
            .fold((f64::MAX, f64::MIN), |m, v| (m.0.min(*v), m.1.max(*v)));
        assert!(
            (r.x[n] - 0.5 * (hi - lo)).abs() < 1e-6,
            "{} vs {}",
            r.x[n],
            0.5 * (hi - lo)
        );
        assert!(r.iterations < 40, "{}", r.iterations);
    }

    /// Planted SOCP: minimise t s.t. ‖(x0 − 3, x1 − 4)‖ ≤ t, x0 + x1 = 0 → the distance
    /// from (3, 4) to the line x0 + x1 = 0 is 7/√2, at (−0.5, 0.5).
    #[test]
    fn planted_second_order_cone() {
        let mut p = Banded::new(3);
        p.position = vec![Some(0.0), Some(0.0), None];
        p.c[2] = 1.0;
        p.eq.push((vec![(0, 1.0), (1, 1.0)], 0.0));
        p.soc.push(vec![
            (vec![(2, -1.0)], 0.0),
            (vec![(0, 1.0)], 3.0),
            (vec![(1, 1.0)], 4.0),
        ]);
        let r = p.solve(&[0.0; 3], &IpmSettings::default());
        assert_eq!(r.status, IpmStatus::Solved);
        assert!((r.x[2] - 7.0 / 2f64.sqrt()).abs() < 1e-6, "{r:?}");
        assert!(
            (r.x[0] + 0.5).abs() < 1e-5 && (r.x[1] - 0.5).abs() < 1e-5,
            "{r:?}"
        );
    }

    /// A planted minimax of distances in the plane along a band (Weber-like): the point
    /// chain x_{i+1} − x_i = (1, 0) that comes closest, in the largest Euclidean distance,
    /// to scattered targets: the answer is the smallest enclosing circle of the targets
    /// shifted back by i — checked against a brute-force grid search.
    #[test]
    fn planted_chain_minimax_of_distances() {
        let n = 12;
        let targets: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let t = i as f64;
                [t + (t * 1.3).sin(), (t * 0.7).cos()]
            })
            .collect();
        // Variables: (x_i, y_i) interleaved, then t.
        let mut p = Banded::new(2 * n + 1);
        for i in 0..n {
            p.position[2 * i] = Some(i as f64);
            p.position[2 * i + 1] = Some(i as f64);
        }
        p.position[2 * n] = None;
        p.c[2 * n] = 1.0;
        for i in 0..n - 1 {
            p.eq.push((vec![(2 * i + 2, 1.0), (2 * i, -1.0)], 1.0));
            p.eq.push((vec![(2 * i + 3, 1.0), (2 * i + 1, -1.0)], 0.0));
        }
        for (i, tg) in targets.iter().enumerate() {
            p.soc.push(vec![
                (vec![(2 * n, -1.0)], 0.0),
                (vec![(2 * i, 1.0)], tg[0]),
                (vec![(2 * i + 1, 1.0)], tg[1]),
            ]);
        }
        let r = p.solve(&vec![0.0; 2 * n + 1], &IpmSettings::default());
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
