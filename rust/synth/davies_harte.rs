//! Exact fractional Brownian motion in 1D by circulant embedding of
//! fractional Gaussian noise (Davies & Harte 1987, in the form of Wood & Chan
//! 1994), with real FFTs (`realfft` / `rustfft`).
//!
//! The fGn autocovariance `g(k) = (|k+1|^2H - 2|k|^2H + |k-1|^2H) / 2`,
//! `k = 0 .. m`, is the first row of a symmetric circulant of size `2m`
//! (`g(0), .., g(m), g(m-1), .., g(1)`); its eigenvalues are the (real) DFT of
//! that row, `lambda_k`, `k = 0 .. m`, all non-negative for fGn (Craigmile
//! 2003). A Hermitian random half-spectrum `W` with `W_0, W_m` real
//! `N(0, lambda / 2m)` and `W_k = sqrt(lambda_k / 2m) (Z1 + i Z2) / sqrt 2`
//! has a real inverse DFT (unnormalised, length `2m`) whose first `m` entries
//! have exactly the fGn covariance.
//!
//! Random numbers: stream `(seed, stream)` at positions `0 .. 2m` laid out as
//! `W_0 <- z[0]`, `W_m <- z[1]`, `Re W_k <- z[k + 1]`, `Im W_k <- z[m + k]`
//! (`k = 1 .. m-1`): the same layout as the former scipy implementation, so a
//! seed gives the same path up to rounding.
use crate::error::{CoreError, CoreResult};
use crate::progress::{add_total, tick, Progress};
use crate::rng::StreamKey;
use rayon::prelude::*;
use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use std::sync::{Arc, Mutex, OnceLock};

/// One planner for the process: plans (twiddle tables) are built once per
/// length and shared; the lock is held only while looking a plan up.
fn planner() -> &'static Mutex<RealFftPlanner<f64>> {
    static P: OnceLock<Mutex<RealFftPlanner<f64>>> = OnceLock::new();
    P.get_or_init(|| Mutex::new(RealFftPlanner::new()))
}

fn forward(n: usize) -> Arc<dyn RealToComplex<f64>> {
    let mut p = planner().lock().unwrap_or_else(|e| e.into_inner());
    p.plan_fft_forward(n)
}

fn inverse(n: usize) -> Arc<dyn ComplexToReal<f64>> {
    let mut p = planner().lock().unwrap_or_else(|e| e.into_inner());
    p.plan_fft_inverse(n)
}

fn check(m: usize, hurst: f64) -> CoreResult<()> {
    if !(hurst > 0.0 && hurst < 1.0) {
        return Err(CoreError::invalid(
            "hurst",
            format!("expected a number in (0, 1), got {hurst}"),
        ));
    }
    if m < 1 {
        return Err(CoreError::invalid("m", "the embedding needs m >= 1"));
    }
    Ok(())
}

/// `sqrt(lambda_k / (2m))`, `k = 0 .. m`: the square roots of the
/// eigenvalues of the size-`2m` circulant embedding of unit fGn, divided by
/// the length. Eigenvalues below `-1e-10 max` are an error (they do not occur
/// for fGn); tiny negative rounding is set to 0.
pub fn fgn_sqrt_eigenvalues(m: usize, hurst: f64) -> CoreResult<Vec<f64>> {
    check(m, hurst)?;
    let h2 = 2.0 * hurst;
    let g = |k: usize| {
        let k = k as f64;
        0.5 * ((k + 1.0).powf(h2) - 2.0 * k.powf(h2) + (k - 1.0).abs().powf(h2))
    };
    let n = m
        .checked_mul(2)
        .ok_or_else(|| CoreError::out_of_memory("m", m, 16))?;
    let mut row = crate::buffers::try_zeroed(n, "m")?;
    row.par_iter_mut()
        .with_min_len(1 << 14)
        .enumerate()
        .for_each(|(t, v)| *v = g(if t <= m { t } else { n - t }));
    let r2c = forward(n);
    let mut spec = r2c.make_output_vec();
    r2c.process(&mut row, &mut spec)
        .map_err(|e| CoreError::Internal(format!("fft: {e}")))?;
    let max = spec.iter().fold(0.0f64, |a, c| a.max(c.re));
    let min = spec.iter().fold(f64::INFINITY, |a, c| a.min(c.re));
    if min < -1e-10 * max {
        return Err(CoreError::Internal(
            "Davies-Harte embedding is not non-negative definite".into(),
        ));
    }
    let inv = 1.0 / n as f64;
    Ok(spec.iter().map(|c| (c.re.max(0.0) * inv).sqrt()).collect())
}

/// Exact fBm `x[0..n]` (`x[0] = 0`, unit-variance unit-lag increments) from
/// the square-root eigenvalues `sqrt_eig` (length `m + 1`, `m >= n - 1`) of
/// [`fgn_sqrt_eigenvalues`] and the noise stream `(seed, stream)`.
/// `progress` gets `3 m + 1 + n` units as total: the `m + 1` noise values
/// (ticked by blocks as they are drawn), the FFT of length `2 m` and the `n`
/// samples of the path.
pub fn fbm_from_eigenvalues(
    sqrt_eig: &[f64],
    n: usize,
    seed: u64,
    stream: u64,
    progress: Option<&Progress>,
) -> CoreResult<Vec<f64>> {
    if sqrt_eig.len() < 2 {
        return Err(CoreError::invalid(
            "sqrt_eig",
            format!("need m + 1 >= 2 values, got {}", sqrt_eig.len()),
        ));
    }
    let m = sqrt_eig.len() - 1;
    if n < 2 || n - 1 > m {
        return Err(CoreError::invalid(
            "n",
            format!("need 2 <= n <= m + 1 = {}, got {n}", m + 1),
        ));
    }
    if sqrt_eig.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(CoreError::invalid(
            "sqrt_eig",
            "expected finite numbers >= 0",
        ));
    }
    let key = StreamKey::new(seed, stream);
    let half = std::f64::consts::FRAC_1_SQRT_2;
    let mut spec: Vec<Complex<f64>> =
        crate::buffers::try_filled(m + 1, Complex::new(0.0, 0.0), "n")?;
    add_total(progress, (3 * m + 1 + n) as u64);
    const BLOCK: usize = 1 << 13;
    spec.par_chunks_mut(BLOCK)
        .enumerate()
        .for_each(|(ci, chunk)| {
            for (i, w) in chunk.iter_mut().enumerate() {
                let k = ci * BLOCK + i;
                let s = sqrt_eig[k];
                *w = if k == 0 {
                    Complex::new(s * key.normal(0), 0.0)
                } else if k == m {
                    Complex::new(s * key.normal(1), 0.0)
                } else {
                    let a = s * half;
                    Complex::new(a * key.normal(k as u64 + 1), a * key.normal((m + k) as u64))
                };
            }
            tick(progress, chunk.len() as u64);
        });
    let len = 2 * m;
    let c2r = inverse(len);
    let mut inc = c2r.make_output_vec();
    c2r.process(&mut spec, &mut inc)
        .map_err(|e| CoreError::Internal(format!("fft: {e}")))?;
    tick(progress, len as u64);
    let mut x = crate::buffers::try_with_capacity(n, "n")?;
    x.push(0.0);
    let mut acc = 0.0;
    for v in &inc[..n - 1] {
        acc += v;
        x.push(acc);
    }
    tick(progress, n as u64);
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigenvalues_match_direct_sum() {
        // lambda_k = g0 + (-1)^k g_m + 2 sum_{j=1}^{m-1} g_j cos(pi j k / m).
        let (m, h) = (12usize, 0.8);
        let s = fgn_sqrt_eigenvalues(m, h).unwrap();
        let g =
            |k: f64| 0.5 * ((k + 1.0).powf(1.6) - 2.0 * k.powf(1.6) + (k - 1.0).abs().powf(1.6));
        for (k, sk) in s.iter().enumerate() {
            let mut lam = g(0.0) + if k % 2 == 0 { 1.0 } else { -1.0 } * g(m as f64);
            for j in 1..m {
                lam += 2.0 * g(j as f64) * (std::f64::consts::PI * (j * k) as f64 / m as f64).cos();
            }
            assert!((sk * sk * 2.0 * m as f64 - lam).abs() < 1e-12, "k={k}");
        }
        // H = 1/2: white noise, all eigenvalues 1.
        let w = fgn_sqrt_eigenvalues(8, 0.5).unwrap();
        assert!(w.iter().all(|v| (v * v * 16.0 - 1.0).abs() < 1e-12));
    }

    #[test]
    fn brownian_motion_is_cumulated_white_noise_variance() {
        // H = 1/2: increments are iid N(0, 1): mean square 1 over 2^16 of them
        // (standard error sqrt(2 / 65536) = 0.0055).
        let s = fgn_sqrt_eigenvalues(1 << 16, 0.5).unwrap();
        let x = fbm_from_eigenvalues(&s, (1 << 16) + 1, 3, 12, None).unwrap();
        assert_eq!(x[0], 0.0);
        let ms: f64 = x.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / 65536.0;
        assert!((ms - 1.0).abs() < 4.0 * 0.0055, "{ms}");
    }

    #[test]
    fn counted_path_is_the_same_and_reaches_its_total() {
        // m = 40 000: several noise blocks of 8192, drawn by 2 threads.
        let s = fgn_sqrt_eigenvalues(40_000, 0.3).unwrap();
        let pr = Progress::new();
        let a = crate::parallel::run_in_pool(Some(2), || {
            fbm_from_eigenvalues(&s, 35_001, 7, 2, Some(&pr))
        })
        .unwrap();
        let b =
            crate::parallel::run_in_pool(Some(1), || fbm_from_eigenvalues(&s, 35_001, 7, 2, None))
                .unwrap();
        assert_eq!(a, b);
        assert_eq!(
            (pr.done(), pr.total()),
            (3 * 40_000 + 1 + 35_001, 3 * 40_000 + 1 + 35_001)
        );
    }

    #[test]
    fn bad_arguments() {
        assert!(fgn_sqrt_eigenvalues(8, 1.0).is_err());
        assert!(fgn_sqrt_eigenvalues(0, 0.5).is_err());
        let s = fgn_sqrt_eigenvalues(8, 0.5).unwrap();
        assert!(fbm_from_eigenvalues(&s, 9, 0, 0, None).is_ok());
        assert!(fbm_from_eigenvalues(&s, 10, 0, 0, None).is_err());
        assert!(fbm_from_eigenvalues(&s, 1, 0, 0, None).is_err());
        assert!(fbm_from_eigenvalues(&[1.0, f64::NAN], 2, 0, 0, None).is_err());
    }
}
