//! Curve lengths of Higuchi's (1988) method for a profile or time series.
//!
//! For `k = 1 .. k_max` and 0-based offsets `m = 0 .. k - 1` with
//! `c_m = (n - 1 - m) / k >= 1` increments,
//!
//! ```text
//! L_m(k) = (sum_i |x[m + i k] - x[m + (i - 1) k]|) (n - 1) / (c_m k) / k
//! L(k)   = mean over m of L_m(k)
//! ```
//!
//! Each `k` reads the series once, in order, accumulating the `k` offset sums
//! side by side (so memory is streamed, not strided). Values of `k` run in
//! parallel; every `L(k)` is computed by one thread in a fixed order, so the
//! result does not depend on the thread count.
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

/// `L(k)` for `k = 1 ..= k_max` of a gap-free series `x`.
pub fn higuchi_lengths(x: &[f64], k_max: usize) -> CoreResult<Vec<f64>> {
    let n = x.len();
    if k_max < 1 || n < 2 || k_max > n / 2 {
        return Err(CoreError::invalid(
            "k_max",
            format!(
                "expected an int in [1, {}] for {n} samples, got {k_max}",
                n / 2
            ),
        ));
    }
    if x.iter().any(|v| !v.is_finite()) {
        return Err(CoreError::invalid("data", "contains NaN or inf"));
    }
    Ok((1..=k_max).into_par_iter().map(|k| length(x, k)).collect())
}

fn length(x: &[f64], k: usize) -> f64 {
    let n = x.len();
    let mut sums = vec![0.0f64; k];
    // increment j -> j + k belongs to offset j mod k
    for (c, b) in x[k..].chunks(k).zip(x.chunks(k)) {
        for ((s, &u), &v) in sums.iter_mut().zip(c).zip(b) {
            *s += (u - v).abs();
        }
    }
    let mut total = 0.0;
    let mut used = 0usize;
    for (m, s) in sums.iter().enumerate() {
        let cnt = (n - 1 - m) / k;
        if cnt >= 1 {
            total += s * (n - 1) as f64 / (cnt * k) as f64 / k as f64;
            used += 1;
        }
    }
    total / used as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive(x: &[f64], k: usize) -> f64 {
        let n = x.len();
        let mut lm = vec![];
        for m in 0..k {
            let idx: Vec<usize> = (m..n).step_by(k).collect();
            if idx.len() < 2 {
                continue;
            }
            let s: f64 = idx.windows(2).map(|w| (x[w[1]] - x[w[0]]).abs()).sum();
            lm.push(s * (n - 1) as f64 / ((idx.len() - 1) * k) as f64 / k as f64);
        }
        lm.iter().sum::<f64>() / lm.len() as f64
    }

    #[test]
    fn matches_the_definition_for_uneven_lengths() {
        let x: Vec<f64> = (0..103)
            .map(|i| ((i * 37 % 11) as f64).sin() * i as f64)
            .collect();
        let l = higuchi_lengths(&x, 20).unwrap();
        for k in 1..=20 {
            assert!((l[k - 1] - naive(&x, k)).abs() <= 1e-12 * naive(&x, k).abs());
        }
    }

    #[test]
    fn straight_line_has_length_independent_of_k() {
        let x: Vec<f64> = (0..1000).map(|i| 0.5 * i as f64).collect();
        let l = higuchi_lengths(&x, 10).unwrap();
        // each increment is 0.5 k, so L_m(k) = 0.5 k c_m (n - 1) / (c_m k) / k
        for (i, v) in l.iter().enumerate() {
            let k = (i + 1) as f64;
            assert!((v - 0.5 * 999.0 / k).abs() < 1e-9);
        }
    }

    #[test]
    fn rejects_bad_k_and_nan() {
        assert!(higuchi_lengths(&[1.0, 2.0, 3.0], 2).is_err());
        assert!(higuchi_lengths(&[1.0, f64::NAN, 3.0, 4.0], 2).is_err());
    }
}
