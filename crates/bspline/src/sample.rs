//! Sampling parameters at a fixed step (fs = F·Tcy, G16 eq. 8).

/// Parameters from `a` to `b` inclusive, spaced by at most `step` (> 0): `a, a+step, …`
/// and `b` itself (the last gap may be shorter). `a == b` gives `[a]`.
///
/// The k-th parameter is computed as `a + k·step` (no accumulated rounding), so gaps
/// exceed `step` at most by the rounding of the parameters themselves (a few ulp of
/// `max(|a|, |b|)`). A step
/// larger than the interval gives `[a, b]`. If `b < a` the parameters run downwards
/// (`a, a−step, …, b`). Degenerate input never panics: a step that is not a positive
/// finite number, or a non-finite end, gives just the ends `[a, b]` (`[a]` if equal).
/// The caller chooses the step: `(b − a)/step` parameters are allocated.
pub fn sample_params(a: f64, b: f64, step: f64) -> Vec<f64> {
    if a == b {
        return vec![a];
    }
    if !(step > 0.0 && step.is_finite() && a.is_finite() && b.is_finite()) {
        return vec![a, b];
    }
    let len = (b - a).abs();
    let dir = if b > a { step } else { -step };
    let count = (len / step).ceil();
    let mut out = Vec::with_capacity(count as usize + 1);
    out.push(a);
    let mut k = 1.0;
    while k < count {
        let t = a + k * dir;
        // Rounding can put the last interior sample at or past b; b is pushed below.
        if (b - t) * dir.signum() <= 0.0 {
            break;
        }
        out.push(t);
        k += 1.0;
    }
    out.push(b);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(a: f64, b: f64, step: f64) -> Vec<f64> {
        let p = sample_params(a, b, step);
        assert_eq!(p[0], a);
        assert_eq!(*p.last().unwrap(), b);
        for w in p.windows(2) {
            let gap = (w[1] - w[0]) * (b - a).signum();
            assert!(gap > 0.0, "strictly monotone: {w:?}");
            // Up to the rounding of the parameters themselves.
            let tol = 4.0 * f64::EPSILON * a.abs().max(b.abs());
            assert!(gap <= step + tol, "gap {gap} > step {step}");
        }
        p
    }

    #[test]
    fn spacing_is_at_most_step_and_both_ends_are_included() {
        let p = check(0.0, 1.0, 0.3);
        assert_eq!(p.len(), 5);
        assert!((p[3] - 0.9).abs() < 1e-15);
        // An exact multiple: no near-duplicate before b.
        assert_eq!(check(0.0, 1.0, 0.1).len(), 11);
        assert_eq!(check(0.0, 3.0, 1.0), vec![0.0, 1.0, 2.0, 3.0]);
        // fs = F·Tcy: F3000 mm/min, Tcy 1 ms → 0.05 mm over a 12.34 mm run.
        let fs = 3000.0 / 60.0 * 1e-3;
        let p = check(100.0, 112.34, fs);
        assert_eq!(p.len(), 248);
        check(-5.0, 7.0, 1e-3);
    }

    #[test]
    fn degenerate_intervals_and_steps() {
        assert_eq!(sample_params(2.0, 2.0, 0.1), vec![2.0]);
        assert_eq!(sample_params(0.0, 1.0, 5.0), vec![0.0, 1.0]);
        assert_eq!(sample_params(0.0, 1.0, 1.0), vec![0.0, 1.0]);
        assert_eq!(sample_params(0.0, 1.0, 0.0), vec![0.0, 1.0]);
        assert_eq!(sample_params(0.0, 1.0, -0.1), vec![0.0, 1.0]);
        assert_eq!(sample_params(0.0, 1.0, f64::NAN), vec![0.0, 1.0]);
        assert_eq!(
            sample_params(0.0, f64::INFINITY, 0.1),
            vec![0.0, f64::INFINITY]
        );
        let p = check(1.0, 0.0, 0.25);
        assert_eq!(p, vec![1.0, 0.75, 0.5, 0.25, 0.0]);
    }
}
