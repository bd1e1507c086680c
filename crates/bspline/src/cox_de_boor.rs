//! The low-level routines everything else is built on: the span search and the Cox–de Boor
//! recurrence for the non-zero basis functions and their derivatives (Piegl & Tiller,
//! *The NURBS Book*, 2nd ed., algorithms A2.1–A2.3).

/// The knot span `i` used to evaluate at `t`: `knots[i] ≤ t < knots[i + 1]` with
/// `degree ≤ i < n_coeffs` and `knots[i] < knots[i + 1]`; below the domain the first
/// non-empty span, at or above its end the last one (so evaluation extends the end
/// pieces). NaN gives the first span.
///
/// Requires a valid knot vector (as checked by [`BSpline::new`]): at least one non-empty
/// span in `degree..n_coeffs`.
pub(crate) fn find_span(knots: &[f64], degree: usize, n_coeffs: usize, t: f64) -> usize {
    let p = degree;
    let n = n_coeffs;
    // Number of knots in knots[p+1..n] that are <= t.
    let inner = &knots[p + 1..n];
    let mut span = p + inner.partition_point(|&k| k <= t);
    // Skip empty spans (repeated knots): forward from the front, backward at the end.
    if span == n - 1 || t >= knots[n] {
        span = n - 1;
        while knots[span] >= knots[span + 1] && span > p {
            span -= 1;
        }
    } else {
        while knots[span] >= knots[span + 1] && span + 1 < n {
            span += 1;
        }
    }
    span
}

/// The non-zero basis functions `N_{span−p+j, p}(t)`, j = 0..=p (p ≤ 3), of span `span`
/// (algorithm A2.2). Entries above `p` are 0.
pub(crate) fn basis_funs(knots: &[f64], p: usize, span: usize, t: f64) -> [f64; 4] {
    let mut n = [0.0; 4];
    let mut left = [0.0; 4];
    let mut right = [0.0; 4];
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = n[r] / (right[r + 1] + left[j - r]);
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

/// `ders[k][j]` = k-th derivative of `N_{span−p+j, p}` at `t`, k = 0..=3, j = 0..=p (p ≤ 3)
/// (algorithm A2.3). Derivatives above the degree are 0.
pub(crate) fn ders_basis(knots: &[f64], p: usize, span: usize, t: f64) -> [[f64; 4]; 4] {
    debug_assert!(p <= 3);
    // ndu: upper triangle basis functions of increasing degree, lower triangle knot
    // differences.
    let mut ndu = [[0.0f64; 4]; 4];
    let mut left = [0.0; 4];
    let mut right = [0.0; 4];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = t - knots[span + 1 - j];
        right[j] = knots[span + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let mut ders = [[0.0f64; 4]; 4];
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let pi = p as isize;
    for r in 0..=pi {
        let mut a = [[0.0f64; 4]; 2];
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=pi {
            let mut d = 0.0;
            let rk = r - k;
            let pk = pi - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[(pk + 1) as usize][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk as usize];
            }
            let j1 = if rk >= -1 { 1 } else { -rk };
            let j2 = if r - 1 <= pk { k - 1 } else { pi - r };
            for j in j1..=j2 {
                let (ju, rkj) = (j as usize, (rk + j) as usize);
                a[s2][ju] = (a[s1][ju] - a[s1][ju - 1]) / ndu[(pk + 1) as usize][rkj];
                d += a[s2][ju] * ndu[rkj][pk as usize];
            }
            if r <= pk {
                let ku = k as usize;
                a[s2][ku] = -a[s1][ku - 1] / ndu[(pk + 1) as usize][r as usize];
                d += a[s2][ku] * ndu[r as usize][pk as usize];
            }
            ders[k as usize][r as usize] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for k in 1..=p {
        for d in ders[k].iter_mut().take(p + 1) {
            *d *= factor;
        }
        factor *= (p - k) as f64;
    }
    ders
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn span_search_skips_repeated_knots_and_clamps_outside() {
        // degree 3, knots with a double interior knot at 1.0.
        let knots = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 2.0, 2.0];
        let n = knots.len() - 4;
        assert_eq!(find_span(&knots, 3, n, -1.0), 3);
        assert_eq!(find_span(&knots, 3, n, 0.0), 3);
        assert_eq!(find_span(&knots, 3, n, 0.999), 3);
        assert_eq!(find_span(&knots, 3, n, 1.0), 5);
        assert_eq!(find_span(&knots, 3, n, 2.0), 5);
        assert_eq!(find_span(&knots, 3, n, 9.0), 5);
        assert_eq!(find_span(&knots, 3, n, f64::NAN), 3);
    }
}
