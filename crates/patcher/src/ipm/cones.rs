//! The second-order cone's algebra: Nesterov–Todd scaling, the Jordan product and
//! division, and the largest step inside the cone.

// Index loops mirror the formulas (cone entries).
#![allow(clippy::needless_range_loop)]

/// The largest second-order cone (rows) [`super::Banded::solve`] takes.
pub const MAX_CONE: usize = 8;

/// Nesterov–Todd scaling of one second-order cone block at `(s, z)` (both interior):
/// `W` (symmetric, q × q, row-major) with `W·z = W⁻¹·s = λ`, its inverse, and `λ`
/// (Vandenberghe, "The CVXOPT linear and quadratic cone program solvers", §4.2).
pub(super) struct SocScaling {
    /// `W`, q × q row-major (first q² entries used).
    pub(super) w: [f64; MAX_CONE * MAX_CONE],
    /// `W⁻¹`, likewise.
    pub(super) winv: [f64; MAX_CONE * MAX_CONE],
    /// `λ` (first q entries).
    pub(super) lambda: [f64; MAX_CONE],
}

pub(super) fn soc_norm(v: &[f64]) -> f64 {
    let r = v[0] * v[0] - v[1..].iter().map(|x| x * x).sum::<f64>();
    r.max(0.0).sqrt()
}

pub(super) fn soc_scaling(s: &[f64], z: &[f64]) -> SocScaling {
    let q = s.len();
    let (sn, zn) = (soc_norm(s), soc_norm(z));
    let (mut sb, mut zb) = ([0.0; MAX_CONE], [0.0; MAX_CONE]);
    for i in 0..q {
        sb[i] = s[i] / sn;
        zb[i] = z[i] / zn;
    }
    let gamma = ((1.0 + (0..q).map(|i| sb[i] * zb[i]).sum::<f64>()) / 2.0).sqrt();
    let mut wb = [0.0; MAX_CONE];
    wb[0] = (sb[0] + zb[0]) / (2.0 * gamma);
    for i in 1..q {
        wb[i] = (sb[i] - zb[i]) / (2.0 * gamma);
    }
    let eta = (sn / zn).sqrt();
    let mut w = [0.0; MAX_CONE * MAX_CONE];
    let mut winv = [0.0; MAX_CONE * MAX_CONE];
    w[0] = eta * wb[0];
    winv[0] = wb[0] / eta;
    for i in 1..q {
        w[i] = eta * wb[i];
        w[i * q] = eta * wb[i];
        winv[i] = -wb[i] / eta;
        winv[i * q] = -wb[i] / eta;
        for j in 1..q {
            let m = f64::from(u8::from(i == j)) + wb[i] * wb[j] / (1.0 + wb[0]);
            w[i * q + j] = eta * m;
            winv[i * q + j] = m / eta;
        }
    }
    let mut lambda = [0.0; MAX_CONE];
    for i in 0..q {
        lambda[i] = (0..q).map(|j| w[i * q + j] * z[j]).sum();
    }
    SocScaling { w, winv, lambda }
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
    /// Jordan division inverts the product.
    #[test]
    fn nesterov_todd_scaling_identities() {
        let mut seed = 7u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for _ in 0..50 {
            let mut s = [0.0, rnd(), rnd()];
            let mut z = [0.0, rnd(), rnd()];
            s[0] = (s[1] * s[1] + s[2] * s[2]).sqrt() + 0.1 + rnd().abs();
            z[0] = (z[1] * z[1] + z[2] * z[2]).sqrt() + 0.1 + rnd().abs();
            let sc = soc_scaling(&s, &z);
            let mul = |m: &[f64], v: &[f64]| -> Vec<f64> {
                (0..3)
                    .map(|a| (0..3).map(|b| m[a * 3 + b] * v[b]).sum())
                    .collect()
            };
            let (wz, wis) = (mul(&sc.w, &z), mul(&sc.winv, &s));
            for a in 0..3 {
                assert!(
                    (wz[a] - sc.lambda[a]).abs() < 1e-10,
                    "{wz:?} {:?}",
                    sc.lambda
                );
                assert!(
                    (wis[a] - sc.lambda[a]).abs() < 1e-10,
                    "{wis:?} {:?}",
                    sc.lambda
                );
                for b in 0..3 {
                    let id: f64 = (0..3).map(|m| sc.w[a * 3 + m] * sc.winv[m * 3 + b]).sum();
                    assert!((id - f64::from(u8::from(a == b))).abs() < 1e-10);
                }
            }
            let r = [rnd(), rnd(), rnd()];
            let mut u = [0.0; 3];
            soc_div(&sc.lambda[..3], &r, &mut u);
            let mut back = [0.0; 3];
            soc_prod(&sc.lambda[..3], &u, &mut back);
            for a in 0..3 {
                assert!((back[a] - r[a]).abs() < 1e-9);
            }
            // The cone step lands on the boundary (or is not limited).
            let d = [rnd() * 5.0, rnd() * 5.0, rnd() * 5.0];
            let al = soc_step(&s, &d, 1e6);
            let v: Vec<f64> = (0..3).map(|a| s[a] + al * d[a]).collect();
            assert!(
                v[0] >= -1e-9
                    && v[0] * v[0] - v[1] * v[1] - v[2] * v[2] >= -1e-7 * (1.0 + v[0] * v[0])
            );
            if al < 1e6 {
                let w: Vec<f64> = (0..3).map(|a| s[a] + 1.001 * al * d[a]).collect();
                assert!(w[0] < 0.0 || w[0] * w[0] - w[1] * w[1] - w[2] * w[2] < 0.0);
            }
        }
    }
}
