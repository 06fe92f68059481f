//! Multiplicative speckle of fully developed scattering (Goodman 1976).
//!
//! A single-look complex pixel is a circular Gaussian field, so its
//! intensity is exponential with mean `sigma0`; the mean of `L` independent
//! looks is Gamma(shape `L`, scale `sigma0 / L`): mean `sigma0`, variance
//! `sigma0^2 / L`. Each look is drawn as `-ln U` (U uniform on (0, 1)), and
//! the `L` looks of a pixel as `-ln(U_1 ... U_L)` with the product taken 16
//! factors at a time (no underflow: `U > 2^-53`).
//!
//! The uniforms come from the counter-based generator
//! ([`crate::rng`]): look `j` of the pixel at global position
//! `(row, col)` of a grid with `global_cols` columns is the sample at index
//! `(row * global_cols + col) * L + j` of the stream `(seed, STREAM)`, so the
//! output is the same for any number of threads and for any tiling of the
//! grid (Dask chunks).
use crate::error::{CoreError, CoreResult};
use crate::rng::StreamKey;
use rayon::prelude::*;

/// The stream of the speckle draws.
pub const STREAM: u64 = 0x5eec_1e00;

/// Where a block sits in the whole grid (for tiled computation).
#[derive(Debug, Clone, Copy)]
pub struct Placement {
    /// Global `(row, col)` of the block's first element.
    pub origin: (u64, u64),
    /// Columns of the whole grid.
    pub global_cols: u64,
}

/// The mean of `looks` unit-mean exponential draws at `index` of `key`.
#[inline]
pub fn gamma_unit(key: StreamKey, index: u64, looks: u32) -> f64 {
    let base = index.wrapping_mul(looks as u64);
    let mut sum = 0.0;
    let mut prod = 1.0;
    for j in 0..looks as u64 {
        prod *= key.uniform(base.wrapping_add(j));
        if j % 16 == 15 {
            sum += neg_ln(prod);
            prod = 1.0;
        }
    }
    if looks % 16 != 0 {
        sum += neg_ln(prod);
    }
    sum / looks as f64
}

/// The product of the `looks` (at most 16) uniforms of the pixel at `index`
/// of `key`: [`gamma_unit`] is `neg_ln` of it over `looks`, bit for bit
/// (see [`apply_products`]).
#[inline(always)]
pub fn uniform_product(key: StreamKey, index: u64, looks: u32) -> f64 {
    debug_assert!((1..=16).contains(&looks));
    let base = index.wrapping_mul(looks as u64);
    let mut prod = 1.0;
    for j in 0..looks as u64 {
        prod *= key.uniform(base.wrapping_add(j));
    }
    prod
}

/// `out[k] = uniform_product(key, start + k, looks)` for each `k` (`looks`
/// at most 16): the same bits, vectorised for up to 4 looks (AVX2 where the CPU has it, chosen at
/// run time; the 64-bit hash in vector lanes, the 53 bits converted to a
/// float in two exact halves).
pub fn fill_products(out: &mut [f64], key: StreamKey, start: u64, looks: u32) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx512vl")
    {
        // SAFETY: the CPU has AVX-512 DQ and VL (checked just above).
        unsafe { fill_products_avx512(out, key, start, looks) };
        return;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above).
        unsafe { fill_products_avx2(out, key, start, looks) };
        return;
    }
    fill_products_impl(out, key, start, looks);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn fill_products_avx2(out: &mut [f64], key: StreamKey, start: u64, looks: u32) {
    fill_products_impl(out, key, start, looks);
}

/// [`fill_products_impl`] with AVX-512's 64-bit lane multiply (`vpmullq`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512dq,avx512vl")]
unsafe fn fill_products_avx512(out: &mut [f64], key: StreamKey, start: u64, looks: u32) {
    fill_products_impl(out, key, start, looks);
}

#[inline(always)]
fn fill_products_impl(out: &mut [f64], key: StreamKey, start: u64, looks: u32) {
    match looks {
        1 => products::<1>(out, key, start),
        2 => products::<2>(out, key, start),
        3 => products::<3>(out, key, start),
        4 => products::<4>(out, key, start),
        _ => {
            for (k, o) in out.iter_mut().enumerate() {
                *o = uniform_product(key, start.wrapping_add(k as u64), looks);
            }
        }
    }
}

/// [`fill_products`] for `L` looks (a constant: the loop over the looks
/// unrolls and the loop over pixels vectorises).
#[inline(always)]
fn products<const L: u64>(out: &mut [f64], key: StreamKey, start: u64) {
    for (k, o) in out.iter_mut().enumerate() {
        let base = start.wrapping_add(k as u64).wrapping_mul(L);
        let mut prod = 1.0;
        for j in 0..L {
            prod *= open_unit(key.bits(base.wrapping_add(j)));
        }
        *o = prod;
    }
}

/// [`crate::rng::bits_to_open_unit`], the same value: the top 53 bits as a
/// float from their two halves (each exact through the exponent of 2^52,
/// and so their sum), no 64-bit integer conversion (which AVX2 lacks).
#[inline(always)]
fn open_unit(bits: u64) -> f64 {
    const MAGIC: u64 = 0x4330_0000_0000_0000;
    const TWO52: f64 = 4_503_599_627_370_496.0;
    let k = bits >> 11;
    let hi = f64::from_bits(MAGIC | (k >> 32)) - TWO52;
    let lo = f64::from_bits(MAGIC | (k & 0xffff_ffff)) - TWO52;
    ((hi * 4_294_967_296.0 + lo) + 0.5) * (1.0 / 9_007_199_254_740_992.0)
}

/// `out[k] = v[k] * (neg_ln(out[k]) / looks)`, NaN where `v[k]` is: with
/// `out` holding [`uniform_product`]s, `v` times [`gamma_unit`] speckle, the
/// same bits. Vectorised (AVX2 where the CPU has it, chosen at run time).
pub fn apply_products(out: &mut [f64], v: &[f64], looks: u32) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above).
        unsafe { apply_products_avx2(out, v, looks) };
        return;
    }
    apply_products_impl(out, v, looks);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn apply_products_avx2(out: &mut [f64], v: &[f64], looks: u32) {
    apply_products_impl(out, v, looks);
}

#[inline(always)]
fn apply_products_impl(out: &mut [f64], v: &[f64], looks: u32) {
    let l = looks as f64;
    for (o, &x) in out.iter_mut().zip(v) {
        let g = neg_ln(*o) / l;
        *o = if x.is_nan() { f64::NAN } else { x * g };
    }
}

const LN2_HI: f64 = 0.693_147_180_369_123_8;
const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
const LG: [f64; 7] = [
    0.666_666_666_666_673_5,
    0.399_999_999_994_094_2,
    0.285_714_287_436_623_9,
    0.222_221_984_321_497_84,
    0.181_835_721_616_180_5,
    0.153_138_376_992_093_73,
    0.147_981_986_051_165_86,
];

/// `-ln(x)` for a positive normal `x` (the product of at most 16 uniforms,
/// each above 2^-54), without a libm call or a branch, so that it
/// vectorises: fdlibm's `__ieee754_log` (Sun Microsystems 1993; error
/// below 1 ulp) with its two final formulas both computed and one selected.
/// Tested against libm.
#[inline(always)]
pub fn neg_ln(x: f64) -> f64 {
    let bits = x.to_bits();
    let hx = (bits >> 32) as i32;
    let k = (hx >> 20) - 1023;
    let hm = hx & 0x000f_ffff;
    // m in [sqrt(2)/2, sqrt(2)): x / 2^k, or x / 2^(k + 1)
    let i = (hm + 0x95f64) & 0x10_0000;
    let m = f64::from_bits(((hm | (i ^ 0x3ff0_0000)) as u32 as u64) << 32 | (bits & 0xffff_ffff));
    let dk = (k + (i >> 20)) as f64;
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let w = z * z;
    let t1 = w * (LG[1] + w * (LG[3] + w * LG[5]));
    let t2 = z * (LG[0] + w * (LG[2] + w * (LG[4] + w * LG[6])));
    let r = t2 + t1;
    let hfsq = 0.5 * f * f;
    let a = dk * LN2_HI - ((hfsq - (s * (hfsq + r) + dk * LN2_LO)) - f);
    let b = dk * LN2_HI - ((s * (f - r) - dk * LN2_LO) - f);
    if ((hm - 0x6147a) | (0x6b851 - hm)) > 0 {
        -a
    } else {
        -b
    }
}

/// `intensity` (row-major, `cols` columns) times independent unit-mean
/// Gamma(`looks`) speckle. NaN stays NaN; a negative or infinite intensity is
/// an error.
pub fn speckle(
    intensity: &[f64],
    cols: usize,
    looks: u32,
    seed: u64,
    place: Placement,
) -> CoreResult<Vec<f64>> {
    if looks < 1 {
        return Err(CoreError::invalid("looks", "expected an integer >= 1"));
    }
    if cols == 0 && !intensity.is_empty() || cols != 0 && intensity.len() % cols != 0 {
        return Err(CoreError::invalid(
            "intensity",
            "length is not a multiple of cols",
        ));
    }
    if let Some(v) = intensity.iter().find(|v| **v < 0.0 || v.is_infinite()) {
        return Err(CoreError::invalid(
            "intensity",
            format!("expected finite values >= 0 (NaN = missing), found {v}"),
        ));
    }
    if place.global_cols < place.origin.1 + cols as u64 {
        return Err(CoreError::invalid(
            "global_cols",
            "the block extends beyond the global grid's columns",
        ));
    }
    let key = StreamKey::new(seed, STREAM);
    let mut out = crate::buffers::zeroed(intensity.len());
    if cols == 0 {
        return Ok(out);
    }
    out.par_chunks_mut(cols)
        .zip(intensity.par_chunks(cols))
        .enumerate()
        .for_each(|(r, (o, x))| {
            let grow = place.origin.0 + r as u64;
            let start = grow
                .wrapping_mul(place.global_cols)
                .wrapping_add(place.origin.1);
            if looks <= 16 {
                // vectorised, the same bits (see `apply_products`)
                fill_products(o, key, start, looks);
                apply_products(o, x, looks);
                return;
            }
            for (c, (o, &v)) in o.iter_mut().zip(x).enumerate() {
                *o = if v.is_nan() {
                    f64::NAN
                } else {
                    v * gamma_unit(key, start.wrapping_add(c as u64), looks)
                };
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whole(cols: usize) -> Placement {
        Placement {
            origin: (0, 0),
            global_cols: cols as u64,
        }
    }

    #[test]
    fn mean_and_variance_of_gamma_looks() {
        for looks in [1u32, 3, 20] {
            let n = 200_000usize;
            let x = vec![2.0; n];
            let y = speckle(&x, 1000, looks, 7, whole(1000)).unwrap();
            let m = y.iter().sum::<f64>() / n as f64;
            let v = y.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / (n - 1) as f64;
            let want_v = 4.0 / looks as f64;
            // standard errors: of the mean sqrt(v / n), of the variance
            // sqrt((mu4 - v^2) / n) with mu4 = 4! ... use the Gamma kurtosis
            let se_m = (want_v / n as f64).sqrt();
            let kurt_excess = 6.0 / looks as f64;
            let se_v = want_v * ((2.0 + kurt_excess) / n as f64).sqrt();
            assert!((m - 2.0).abs() < 4.0 * se_m, "L={looks} mean {m}");
            assert!((v - want_v).abs() < 4.0 * se_v, "L={looks} var {v}");
        }
    }

    #[test]
    fn neg_ln_matches_libm() {
        // uniforms, products of up to 16 of them, powers of two and the
        // neighbourhood of the formula's switch points
        let key = StreamKey::new(1, 2);
        let mut xs: Vec<f64> = (0..400_000u64).map(|i| key.uniform(i)).collect();
        xs.extend((0..200_000u64).map(|i| uniform_product(key, i, 1 + (i % 16) as u32)));
        xs.extend((0..900).map(|e| 2f64.powi(-e)));
        xs.extend([
            1.0,
            1.0 - 1e-16,
            0.5,
            std::f64::consts::FRAC_1_SQRT_2,
            f64::from_bits(std::f64::consts::FRAC_1_SQRT_2.to_bits() - 1),
            1e-300,
        ]);
        for x in xs {
            let (a, b) = (neg_ln(x), -x.ln());
            let ulp = f64::from_bits(b.abs().to_bits() + 1) - b.abs();
            assert!((a - b).abs() <= ulp, "x = {x:e}: {a:e} vs libm {b:e}");
        }
    }

    #[test]
    fn products_give_gamma_unit_bit_for_bit() {
        let key = StreamKey::new(3, STREAM);
        for looks in [1u32, 2, 4, 7, 16] {
            let v: Vec<f64> = (0..999)
                .map(|i| {
                    if i % 97 == 3 {
                        f64::NAN
                    } else {
                        0.5 + i as f64
                    }
                })
                .collect();
            let mut out: Vec<f64> = (0..999u64)
                .map(|k| uniform_product(key, 5 + k, looks))
                .collect();
            apply_products(&mut out, &v, looks);
            for (k, (&o, &x)) in out.iter().zip(&v).enumerate() {
                let want = x * gamma_unit(key, 5 + k as u64, looks);
                assert!(o.to_bits() == want.to_bits() || o.is_nan() && x.is_nan());
            }
        }
    }

    #[test]
    fn vectorised_products_equal_the_scalar_ones() {
        let key = StreamKey::new(9, STREAM);
        for looks in 1..=16u32 {
            for start in [0u64, 12345, u64::MAX - 50] {
                let mut out = vec![0.0; 101];
                fill_products(&mut out, key, start, looks);
                for (k, &o) in out.iter().enumerate() {
                    let want = uniform_product(key, start.wrapping_add(k as u64), looks);
                    assert_eq!(o.to_bits(), want.to_bits(), "looks {looks} k {k}");
                }
            }
        }
        // the baseline code: the same bits
        for looks in [1u32, 3, 4, 9] {
            let mut a = vec![0.0; 77];
            let mut b = vec![0.0; 77];
            fill_products(&mut a, key, 99, looks);
            fill_products_impl(&mut b, key, 99, looks);
            assert_eq!(a, b);
            let v: Vec<f64> = (0..77)
                .map(|i| if i == 7 { f64::NAN } else { i as f64 })
                .collect();
            let mut c = a.clone();
            apply_products(&mut a, &v, looks);
            apply_products_impl(&mut c, &v, looks);
            assert!(a.iter().zip(&c).all(|(x, y)| x.to_bits() == y.to_bits()));
        }
        // the conversion at the ends of its range
        for bits in [0u64, 1 << 11, u64::MAX, u64::MAX >> 1, 0xffff_ffff << 11] {
            assert_eq!(
                open_unit(bits).to_bits(),
                crate::rng::bits_to_open_unit(bits).to_bits()
            );
        }
    }

    #[test]
    fn tiles_equal_the_whole() {
        let (rows, cols) = (7usize, 9usize);
        let x: Vec<f64> = (0..rows * cols).map(|i| 1.0 + i as f64).collect();
        let all = speckle(&x, cols, 4, 3, whole(cols)).unwrap();
        // the block rows 2..5, cols 3..8
        let sub: Vec<f64> = (2..5)
            .flat_map(|r| (3..8).map(move |c| (r, c)))
            .map(|(r, c)| x[r * cols + c])
            .collect();
        let place = Placement {
            origin: (2, 3),
            global_cols: cols as u64,
        };
        let part = speckle(&sub, 5, 4, 3, place).unwrap();
        for (k, (r, c)) in (2..5).flat_map(|r| (3..8).map(move |c| (r, c))).enumerate() {
            assert_eq!(part[k], all[r * cols + c]);
        }
    }

    #[test]
    fn bad_input() {
        assert!(speckle(&[1.0, -1.0], 2, 1, 0, whole(2)).is_err());
        assert!(speckle(&[1.0, f64::INFINITY], 2, 1, 0, whole(2)).is_err());
        assert!(speckle(&[1.0], 1, 0, 0, whole(1)).is_err());
        let y = speckle(&[f64::NAN, 0.0], 2, 2, 0, whole(2)).unwrap();
        assert!(y[0].is_nan() && y[1] == 0.0);
    }
}
