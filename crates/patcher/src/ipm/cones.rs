//! The second-order cone's algebra: Nesterov–Todd scaling, the Jordan product and
//! division, and the largest step inside the cone.

// Index loops mirror the formulas (cone entries).
#![allow(clippy::needless_range_loop)]

/// The largest second-order cone (rows) [`super::Problem::solve`] takes.
pub const MAX_CONE: usize = 8;

/// Nesterov–Todd scaling of one second-order cone at `(s, z)` (both interior), kept as
/// `η` and the unit hyperbolic vector `w̄` (Vandenberghe, "The CVXOPT linear and
/// quadratic cone program solvers", §4.2):
///
/// ```text
/// W  = η·[ w̄0   w̄1ᵀ                 ]      W·z = W⁻¹·s = λ
///        [ w̄1   I + w̄1·w̄1ᵀ/(1 + w̄0) ]
/// W⁻¹ = (1/η)·[ w̄0   −w̄1ᵀ ; −w̄1   I + w̄1·w̄1ᵀ/(1 + w̄0) ]
/// ```
///
/// so that applying `W` or `W⁻¹` costs O(q).
#[derive(Debug, Clone, Copy)]
pub(super) struct SocScaling {
    pub(super) eta: f64,
    pub(super) wbar: [f64; MAX_CONE],
}

impl SocScaling {
    /// `out = W·v` (q = `v.len()`).
    pub(super) fn apply(&self, v: &[f64], out: &mut [f64]) {
        let q = v.len();
        let wb = &self.wbar;
        let dot: f64 = (1..q).map(|i| wb[i] * v[i]).sum();
        let f = dot / (1.0 + wb[0]);
        out[0] = self.eta * (wb[0] * v[0] + dot);
        for i in 1..q {
            out[i] = self.eta * (v[i] + wb[i] * (v[0] + f));
        }
    }

    /// `out = W⁻¹·v`.
    pub(super) fn apply_inv(&self, v: &[f64], out: &mut [f64]) {
        let q = v.len();
        let wb = &self.wbar;
        let dot: f64 = (1..q).map(|i| wb[i] * v[i]).sum();
        let f = dot / (1.0 + wb[0]);
        out[0] = (wb[0] * v[0] - dot) / self.eta;
        for i in 1..q {
            out[i] = (v[i] + wb[i] * (f - v[0])) / self.eta;
        }
    }
}

pub(super) fn soc_norm(v: &[f64]) -> f64 {
    let r = v[0] * v[0] - v[1..].iter().map(|x| x * x).sum::<f64>();
    r.max(0.0).sqrt()
}

/// The scaling at `(s, z)` and `λ = W·z` (into `lambda`).
pub(super) fn soc_scaling(s: &[f64], z: &[f64], lambda: &mut [f64]) -> SocScaling {
    let q = s.len();
    let (sn, zn) = (soc_norm(s), soc_norm(z));
    let (mut sb, mut zb) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
    for i in 0..q {
        sb[i] = s[i] / sn;
        zb[i] = z[i] / zn;
    }
    let gamma = ((1.0 + (0..q).map(|i| sb[i] * zb[i]).sum::<f64>()) / 2.0).sqrt();
    let mut wbar = [0.0; MAX_CONE];
    wbar[0] = (sb[0] + zb[0]) / (2.0 * gamma);
    for i in 1..q {
        wbar[i] = (sb[i] - zb[i]) / (2.0 * gamma);
    }
    let sc = SocScaling {
        eta: (sn / zn).sqrt(),
        wbar,
    };
    sc.apply(z, lambda);
    sc
}

/// `u ∘ v` of the second-order cone's Jordan algebra: `(uᵀv, u0·v1 + v0·u1)`.
pub(super) fn soc_prod(u: &[f64], v: &[f64], out: &mut [f64]) {
    out[0] = u.iter().zip(v).map(|(a, b)| a * b).sum();
    for i in 1..u.len() {
        out[i] = u[0] * v[i] + v[0] * u[i];
    }
}

/// The `u` with `λ ∘ u = r` (Jordan division; λ interior).
pub(super) fn soc_div(lambda: &[f64], r: &[f64], out: &mut [f64]) {
    let l0 = lambda[0];
    let l1r1: f64 = lambda[1..].iter().zip(&r[1..]).map(|(a, b)| a * b).sum();
    let det = l0 * l0 - lambda[1..].iter().map(|x| x * x).sum::<f64>();
    let u0 = (l0 * r[0] - l1r1) / det;
    out[0] = u0;
    for i in 1..lambda.len() {
        out[i] = (r[i] - u0 * lambda[i]) / l0;
    }
}

/// The largest α ≤ `cap` with `v + α·d` in the (closed) second-order cone (v interior).
pub(super) fn soc_step(v: &[f64], d: &[f64], cap: f64) -> f64 {
    let a = d[0] * d[0] - d[1..].iter().map(|x| x * x).sum::<f64>();
    let b = 2.0 * (v[0] * d[0] - v[1..].iter().zip(&d[1..]).map(|(x, y)| x * y).sum::<f64>());
    let c = (v[0] * v[0] - v[1..].iter().map(|x| x * x).sum::<f64>()).max(0.0);
    let mut alpha = cap;
    if d[0] < 0.0 {
        alpha = alpha.min(-v[0] / d[0]);
    }
    let disc = b * b - 4.0 * a * c;
    if a < 0.0 {
        // Concave: one positive root.
        let r = (-b - disc.max(0.0).sqrt()) / (2.0 * a);
        if r > 0.0 {
            alpha = alpha.min(r);
        }
    } else if a > 0.0 {
        if b < 0.0 && disc >= 0.0 {
            // Smallest positive root, computed without cancellation.
            let r = 2.0 * c / (-b + disc.sqrt());
            alpha = alpha.min(r);
        }
    } else if b < 0.0 {
        alpha = alpha.min(-c / b);
    }
    alpha.max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Nesterov–Todd scaling: `W·z = W⁻¹·s = λ`, `W·W⁻¹ = I`, on random interior points;
    /// Jordan division inverts the product; the cone step lands on the boundary.
    #[test]
    fn nesterov_todd_scaling_identities() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for q in [3usize, 5] {
            for _ in 0..50 {
                let (mut s, mut z) = (vec![0.0; q], vec![0.0; q]);
                for i in 1..q {
                    s[i] = rnd();
                    z[i] = rnd();
                }
                s[0] = soc_norm_tail(&s) + 0.1 + rnd().abs();
                z[0] = soc_norm_tail(&z) + 0.1 + rnd().abs();
                let mut lambda = vec![0.0; q];
                let sc = soc_scaling(&s, &z, &mut lambda);
                let (mut wz, mut wis) = (vec![0.0; q], vec![0.0; q]);
                sc.apply(&z, &mut wz);
                sc.apply_inv(&s, &mut wis);
                for a in 0..q {
                    assert!((wz[a] - lambda[a]).abs() < 1e-10, "{wz:?} {lambda:?}");
                    assert!((wis[a] - lambda[a]).abs() < 1e-10, "{wis:?} {lambda:?}");
                }
                for b in 0..q {
                    let mut e = vec![0.0; q];
                    e[b] = 1.0;
                    let (mut we, mut back) = (vec![0.0; q], vec![0.0; q]);
                    sc.apply(&e, &mut we);
                    sc.apply_inv(&we, &mut back);
                    for a in 0..q {
                        assert!((back[a] - e[a]).abs() < 1e-10);
                    }
                }
                let r: Vec<f64> = (0..q).map(|_| rnd()).collect();
                let mut u = vec![0.0; q];
                soc_div(&lambda, &r, &mut u);
                let mut back = vec![0.0; q];
                soc_prod(&lambda, &u, &mut back);
                for a in 0..q {
                    assert!((back[a] - r[a]).abs() < 1e-9);
                }
                // The cone step lands on the boundary (or is not limited).
                let d: Vec<f64> = (0..q).map(|_| rnd() * 5.0).collect();
                let al = soc_step(&s, &d, 1e6);
                let v: Vec<f64> = (0..q).map(|a| s[a] + al * d[a]).collect();
                assert!(v[0] >= -1e-9 && v[0] - soc_norm_tail(&v) >= -1e-7 * (1.0 + v[0]));
                if al < 1e6 {
                    let w: Vec<f64> = (0..q).map(|a| s[a] + 1.001 * al * d[a]).collect();
                    assert!(w[0] < soc_norm_tail(&w));
                }
            }
        }
    }

    fn soc_norm_tail(v: &[f64]) -> f64 {
        v[1..].iter().map(|x| x * x).sum::<f64>().sqrt()
    }
}
