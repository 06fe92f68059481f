//! The amplitude filter of 2D spectral synthesis (seed paper figure 3) for
//! fBm sampled on a grid.
//!
//! Spectral synthesis multiplies the FFT of white noise by an amplitude
//! `A(f)` and transforms back; the field's variogram at an integer lag `h`
//! is the Riemann sum over the DFT frequencies `f = (k0/n0, k1/n1)` of
//! `2 (1 - cos 2 pi f.h) A(f)^2 / (n0 n1)`. Sampled fBm has, on the
//! frequency cell `[-1/2, 1/2]^2`, the *aliased* density
//!
//! `S_a(f) = sum over m in Z^2 of |f + m|^-(2H+2)`
//!
//! and its variogram is the integral of the same expression with `S_a`,
//! which is `K |h|^(2H)` with
//! `K = 2 pi^(1+2H) Gamma(1-H) / (H Gamma(1+H))` ([`variogram_constant`]).
//! The integrand is periodic and smooth except at `f = 0`, so the Riemann
//! sum of `S_a` is exact up to the neighbourhood of `f = 0`: the cell of
//! `f = 0` (the power at wavelengths longer than the grid) is missing. Its
//! leading effect at lags small against the grid is a quadratic term
//! `D |h|^2` (a random gradient, as in Stein's 2002 plane correction), which
//! [`filter_2d`] measures from the lag-one sums per axis and adds to the
//! lowest Fourier modes `(+-1, 0)` and `(0, +-1)` (keeping the field
//! periodic). The remaining error is of relative order
//! `(|h|/n)^(2-2H) (2 pi |h|/n)^2 / 12` (docs/synthesis.md).
//!
//! `S_a` is evaluated as `|f|^-(2H+2) + C(f)`, where the alias sum
//! `C(f) = sum over m != 0` is smooth on the cell: it is tabulated on a
//! 65 x 65 grid over `[0, 1/2]^2` (explicit terms `|m|_inf <= 4`, the rest by
//! the integral outside the square with its midpoint-rule and shift
//! corrections; relative error about 1e-5) and interpolated bilinearly
//! (error below 1e-3 relative to `C`).
use crate::error::{CoreError, CoreResult};
use ndarray::Array2;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Gamma function (Lanczos, g = 7, 9 terms; relative error about 1e-15).
pub fn gamma(x: f64) -> f64 {
    const P: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return PI / ((PI * x).sin() * gamma(1.0 - x));
    }
    let x = x - 1.0;
    let mut a = P[0];
    for (i, p) in P.iter().enumerate().skip(1) {
        a += p / (x + i as f64);
    }
    let t = x + 7.5;
    (2.0 * PI).sqrt() * t.powf(x + 0.5) * (-t).exp() * a
}

/// `K` in `integral over R^2 of 2 (1 - cos 2 pi f.h) |f|^-(2H+2) df = K |h|^(2H)`.
pub fn variogram_constant(hurst: f64) -> f64 {
    2.0 * PI * PI.powf(2.0 * hurst) * gamma(1.0 - hurst) / (hurst * gamma(1.0 + hurst))
}

/// `8 * integral_0^(pi/4) cos^p(t) dt` (Simpson, 256 intervals; smooth).
fn square_angle_integral(p: f64) -> f64 {
    let n = 256;
    let hstep = (PI / 4.0) / n as f64;
    let mut s = 0.0;
    for i in 0..=n {
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        s += w * (i as f64 * hstep).cos().powf(p);
    }
    8.0 * s * hstep / 3.0
}

/// `ln x` for a positive normal `x`, branch-free so that loops over it
/// vectorise: `x = 2^k m`, `m` in `[sqrt(1/2), sqrt 2)`,
/// `ln m = 2 atanh(s)`, `s = (m - 1) / (m + 1)`, `|s| <= 0.172`, series to
/// `s^17` (relative error below 1e-14).
#[inline(always)]
fn fast_ln(x: f64) -> f64 {
    let bits = x.to_bits();
    let mut k = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mut m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let big = m > std::f64::consts::SQRT_2;
    m = if big { 0.5 * m } else { m };
    k += big as i64;
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let p = 2.0 / 17.0;
    let p = p * s2 + 2.0 / 15.0;
    let p = p * s2 + 2.0 / 13.0;
    let p = p * s2 + 2.0 / 11.0;
    let p = p * s2 + 2.0 / 9.0;
    let p = p * s2 + 2.0 / 7.0;
    let p = p * s2 + 2.0 / 5.0;
    let p = p * s2 + 2.0 / 3.0;
    let p = p * s2 + 2.0;
    k as f64 * std::f64::consts::LN_2 + s * p
}

/// `exp y` for `|y| < 700`, branch-free: `y = k ln 2 + r`, `|r| <= ln 2 / 2`,
/// Taylor series of `exp r` to `r^13` (relative error below 1e-15), times
/// `2^k` by the exponent bits.
#[inline(always)]
fn fast_exp(y: f64) -> f64 {
    const LN2_HI: f64 = 0.693_147_180_369_123_8;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    // Round to nearest by the 1.5 * 2^52 trick (f64::round is a libm call
    // without SSE4.1, which stops vectorisation).
    const SHIFTER: f64 = 6_755_399_441_055_744.0;
    let k = (y * std::f64::consts::LOG2_E + SHIFTER) - SHIFTER;
    let r = (y - k * LN2_HI) - k * LN2_LO;
    let mut p = 1.0 / 6_227_020_800.0; // 1/13!
    let inv_fact = [
        1.0 / 479_001_600.0,
        1.0 / 39_916_800.0,
        1.0 / 3_628_800.0,
        1.0 / 362_880.0,
        1.0 / 40_320.0,
        1.0 / 5_040.0,
        1.0 / 720.0,
        1.0 / 120.0,
        1.0 / 24.0,
        1.0 / 6.0,
        0.5,
        1.0,
        1.0,
    ];
    for c in inv_fact {
        p = p * r + c;
    }
    p * f64::from_bits(((k as i64 + 1023) as u64) << 52)
}

/// Explicit alias terms `|m|_inf <= ALIAS_M`; the rest is integrated.
const ALIAS_M: i32 = 4;

/// The alias sum `C(f) = sum over m != 0 of |f + m|^-(2H+2)` for `f` in the
/// cell `[-1/2, 1/2]^2`.
pub struct AliasSum {
    beta: f64,
    tail: f64,
    shift: f64,
}

impl AliasSum {
    /// Constants of the tail for `hurst` in (0, 1).
    pub fn new(hurst: f64) -> Self {
        let beta = 2.0 * hurst + 2.0;
        let l = ALIAS_M as f64 + 0.5;
        // Integral of |x|^-beta outside the square [-L, L]^2, and of its
        // Laplacian beta^2 |x|^-(beta+2): the sum over the cells outside is
        // the integral minus 1/24 of the Laplacian's integral (midpoint
        // rule); shifting the cells by f adds |f|^2 / 4 of the latter.
        let integral = l.powf(-2.0 * hurst) / (2.0 * hurst) * square_angle_integral(2.0 * hurst);
        let lap = beta * l.powf(-beta) * square_angle_integral(beta);
        AliasSum {
            beta,
            tail: integral - lap / 24.0,
            shift: lap / 4.0,
        }
    }

    /// `C(f0, f1)`.
    pub fn eval(&self, f0: f64, f1: f64) -> f64 {
        let e = -0.5 * self.beta;
        let mut s = 0.0;
        for m0 in -ALIAS_M..=ALIAS_M {
            let a = f0 + m0 as f64;
            for m1 in -ALIAS_M..=ALIAS_M {
                if m0 == 0 && m1 == 0 {
                    continue;
                }
                let b = f1 + m1 as f64;
                s += (a * a + b * b).powf(e);
            }
        }
        s + self.tail + self.shift * (f0 * f0 + f1 * f1)
    }
}

/// Intervals of the table of `C` over `[0, 1/2]` per axis.
const TABLE_N: usize = 64;

struct AliasTable {
    v: Vec<f64>, // (TABLE_N + 1)^2, row-major in |f0|
}

impl AliasTable {
    fn new(hurst: f64) -> Self {
        let a = AliasSum::new(hurst);
        let step = 0.5 / TABLE_N as f64;
        let mut v = vec![0.0; (TABLE_N + 1) * (TABLE_N + 1)];
        v.par_chunks_mut(TABLE_N + 1)
            .enumerate()
            .for_each(|(i, row)| {
                for (j, x) in row.iter_mut().enumerate() {
                    *x = a.eval(i as f64 * step, j as f64 * step);
                }
            });
        AliasTable { v }
    }

    /// The table interpolated linearly at `|f0|` in `[0, 1/2]`: one row of
    /// `TABLE_N + 1` values over `|f1|`.
    fn row_at(&self, f0: f64) -> Vec<f64> {
        let (i, t) = cell(f0);
        let w = TABLE_N + 1;
        (0..w)
            .map(|j| (1.0 - t) * self.v[i * w + j] + t * self.v[(i + 1) * w + j])
            .collect()
    }
}

/// Table interval and fraction of `|f|` in `[0, 1/2]`.
#[inline]
fn cell(f: f64) -> (usize, f64) {
    let x = f * (2 * TABLE_N) as f64;
    let i = (x as usize).min(TABLE_N - 1);
    (i, x - i as f64)
}

/// The amplitude `A(f)` on the `rfft2` grid of an `(n0, n1)` field, shape
/// `(n0, n1/2 + 1)`: `A^2 = S_a(f) / K` with the low-frequency compensation
/// described in the module documentation; `A(0) = 0`.
///
/// The field `irfft2(A * W)`, `W` the `rfft2` of unit white noise, then has
/// the lag-one variance 1 along both axes, and its variogram follows
/// `|h|^(2H)` at lags small against the grid.
pub fn filter_2d(n0: usize, n1: usize, hurst: f64) -> CoreResult<Array2<f64>> {
    if !(hurst > 0.0 && hurst < 1.0) {
        return Err(CoreError::invalid(
            "hurst",
            format!("expected a number in (0, 1), got {hurst}"),
        ));
    }
    if n0 < 2 || n1 < 2 {
        return Err(CoreError::invalid(
            "shape",
            format!("need at least 2 x 2 samples, got {n0} x {n1}"),
        ));
    }
    let m = n1 / 2 + 1;
    let table = AliasTable::new(hurst);
    let e = -(hurst + 1.0);
    // Column weights of the half spectrum (columns 0 < k1 < n1/2 stand for
    // two bins of the full spectrum) and the lag-one factors 2 (1 - cos).
    let colw: Vec<f64> = (0..m)
        .map(|k1| {
            if k1 == 0 || (n1 % 2 == 0 && k1 == m - 1) {
                1.0
            } else {
                2.0
            }
        })
        .collect();
    let g1: Vec<f64> = (0..m)
        .map(|k1| 2.0 * (1.0 - (2.0 * PI * k1 as f64 / n1 as f64).cos()))
        .collect();
    let inv0 = 1.0 / n0 as f64;
    let f1s: Vec<f64> = (0..m).map(|k1| k1 as f64 / n1 as f64).collect();
    let cells: Vec<(usize, f64)> = f1s.iter().map(|&f| cell(f)).collect();
    // Rows k0 and n0 - k0 are equal: compute rows 0 ..= n0/2 (with their
    // lag-one sums, counted twice for the mirrored rows), mirror at the end.
    let half = n0 / 2 + 1;
    let mut a2 = crate::buffers::try_zeroed(crate::buffers::checked_len(n0, m, "shape")?, "shape")?;
    let per_row: Vec<(f64, f64)> = a2[..half * m]
        .par_chunks_mut(m)
        .enumerate()
        .map(|(k0, row)| {
            let f0 = k0 as f64 * inv0;
            let tab = table.row_at(f0);
            // Values first (a loop without a carried sum vectorises), then
            // the sums over the row.
            for ((v, &f1), &(j, t)) in row.iter_mut().zip(&f1s).zip(&cells) {
                let r2 = f0 * f0 + f1 * f1;
                let alias = (1.0 - t) * tab[j] + t * tab[j + 1];
                *v = fast_exp(e * fast_ln(r2)) + alias;
            }
            if k0 == 0 {
                row[0] = 0.0;
            }
            let (mut s0, mut s1) = (0.0, 0.0);
            for ((&x, &w), &g) in row.iter().zip(&colw).zip(&g1) {
                let xw = w * x;
                s0 += xw;
                s1 += xw * g;
            }
            let g0 = 2.0 * (1.0 - (2.0 * PI * f0).cos());
            let mult = if k0 == 0 || 2 * k0 == n0 { 1.0 } else { 2.0 };
            (mult * s0 * g0, mult * s1)
        })
        .collect();
    let nn = (n0 * n1) as f64;
    let v0: f64 = per_row.iter().map(|p| p.0).sum::<f64>() / nn;
    let v1: f64 = per_row.iter().map(|p| p.1).sum::<f64>() / nn;
    let k = variogram_constant(hurst);
    // Deficits against the integral: the power of the cell f = 0, put into
    // the lowest modes of each axis: (+-1, 0) are rows 1 and n0 - 1 (row 1
    // here, mirrored below; one row when n0 = 2), (0, +-1) is column 1
    // (weight 2 unless n1 = 2).
    let (d0, d1) = ((k - v0).max(0.0), (k - v1).max(0.0));
    let low0 = 2.0 * (1.0 - (2.0 * PI / n0 as f64).cos());
    let low1 = 2.0 * (1.0 - (2.0 * PI / n1 as f64).cos());
    let rows_low = if n0 > 2 { 2.0 } else { 1.0 };
    a2[m] += d0 * nn / (rows_low * low0);
    a2[1] += d1 * nn / (colw[1] * low1);
    // Lag-one variances are now max(K, v) per axis; normalise to 1 (their
    // mean when a deficit was negative, which does not happen for n >= 4).
    let scale = 1.0 / (0.5 * (v0 + d0 + v1 + d1));
    let (top, bottom) = a2.split_at_mut(half * m);
    top.par_iter_mut().for_each(|v| *v = (*v * scale).sqrt());
    bottom.par_chunks_mut(m).enumerate().for_each(|(t, row)| {
        let src = n0 - (half + t);
        row.copy_from_slice(&top[src * m..(src + 1) * m]);
    });
    Array2::from_shape_vec((n0, m), a2).map_err(|e| CoreError::Internal(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_ln_exp_match_std() {
        let mut x = 1e-9;
        while x < 10.0 {
            assert!(
                (fast_ln(x) - x.ln()).abs() < 1e-14 * (1.0 + x.ln().abs()),
                "{x}"
            );
            for e in [-2.0, -1.3, -1.0] {
                let want = x.powf(e);
                let got = fast_exp(e * fast_ln(x));
                assert!((got / want - 1.0).abs() < 1e-12, "{x}^{e}: {got} vs {want}");
            }
            x *= 1.0173;
        }
        for y in [-700.0, -3.0, -0.3, 0.0, 0.2, 5.0, 46.0, 700.0] {
            let f: f64 = y;
            assert!((fast_exp(y) / f.exp() - 1.0).abs() < 1e-14, "{y}");
        }
    }

    #[test]
    fn gamma_known_values() {
        assert!((gamma(0.5) - PI.sqrt()).abs() < 1e-13);
        assert!((gamma(1.0) - 1.0).abs() < 1e-13);
        assert!((gamma(4.0) - 6.0).abs() < 1e-12);
        assert!((gamma(1.5) - 0.5 * PI.sqrt()).abs() < 1e-13);
        assert!((gamma(0.2) - 4.590_843_711_998_803).abs() < 1e-12);
    }

    #[test]
    fn variogram_constant_matches_brownian_case() {
        // H = 1/2: integral over R^2 of (1 - cos k0) |k|^-3 dk = 2 pi
        // (polar coordinates), so with k = 2 pi f the constant is
        // 2 * (2 pi)^3 / (2 pi)^2 * 2 pi = 8 pi^2.
        assert!((variogram_constant(0.5) - 8.0 * PI * PI).abs() < 1e-10);
    }

    #[test]
    fn alias_sum_against_a_long_direct_sum() {
        for &h in &[0.1, 0.5, 0.9] {
            let a = AliasSum::new(h);
            for &(f0, f1) in &[(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (0.13, 0.37)] {
                let beta = 2.0 * h + 2.0;
                let mut s = 0.0;
                let big = 300i32;
                for m0 in -big..=big {
                    for m1 in -big..=big {
                        if m0 == 0 && m1 == 0 {
                            continue;
                        }
                        let (x, y) = (f0 + m0 as f64, f1 + m1 as f64);
                        s += (x * x + y * y).powf(-0.5 * beta);
                    }
                }
                // The direct sum stops at |m| = 300: add its own tail.
                let l = big as f64 + 0.5;
                s += l.powf(-2.0 * h) / (2.0 * h) * square_angle_integral(2.0 * h);
                let got = a.eval(f0, f1);
                assert!(
                    (got / s - 1.0).abs() < 5e-5,
                    "H={h} f=({f0},{f1}): {got} vs {s}"
                );
            }
        }
    }

    #[test]
    fn filter_has_unit_lag_one_variance_and_symmetric_rows() {
        for &(n0, n1) in &[(64usize, 64usize), (63, 90), (2, 5)] {
            let a = filter_2d(n0, n1, 0.7).unwrap();
            assert_eq!(a.dim(), (n0, n1 / 2 + 1));
            assert_eq!(a[[0, 0]], 0.0);
            for k0 in 1..n0 {
                assert_eq!(a.row(k0), a.row(n0 - k0));
            }
            let m = n1 / 2 + 1;
            let (mut v0, mut v1) = (0.0, 0.0);
            for k0 in 0..n0 {
                for k1 in 0..m {
                    let w = if k1 == 0 || (n1 % 2 == 0 && k1 == m - 1) {
                        1.0
                    } else {
                        2.0
                    };
                    let a2 = a[[k0, k1]].powi(2) * w;
                    v0 += a2 * 2.0 * (1.0 - (2.0 * PI * k0 as f64 / n0 as f64).cos());
                    v1 += a2 * 2.0 * (1.0 - (2.0 * PI * k1 as f64 / n1 as f64).cos());
                }
            }
            let nn = (n0 * n1) as f64;
            if n0 > 2 {
                assert!((v0 / nn - 1.0).abs() < 1e-12, "{n0}x{n1}: {}", v0 / nn);
                assert!((v1 / nn - 1.0).abs() < 1e-12, "{n0}x{n1}: {}", v1 / nn);
            }
        }
    }

    #[test]
    fn bad_arguments() {
        assert!(filter_2d(8, 8, 1.0).is_err());
        assert!(filter_2d(8, 8, f64::NAN).is_err());
        assert!(filter_2d(1, 8, 0.5).is_err());
    }
}
