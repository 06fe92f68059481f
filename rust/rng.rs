//! Counter-based random numbers: every sample is a pure function of
//! `(seed, stream, index)`.
//!
//! There is no generator state. A sample at a given position of a given level
//! of a synthesis is the hash of its key, so a field comes out bit-identical
//! for any number of threads, in any order of evaluation, and when tiles of a
//! large field are computed separately.
//!
//! `(seed, stream)` is hashed once with SplitMix64's finaliser (Steele, Lea &
//! Flood 2014) into a 64-bit stream key; the sample at `index` is SplitMix64
//! started from that key, evaluated directly at position `index` (one
//! finaliser per sample: `mix64(key + (index + 1) * golden_gamma)`).
//! Uniforms are the top 53 bits mapped to the open interval (0, 1); standard
//! normals come from the ziggurat method (Marsaglia & Tsang 2000) applied to
//! those 64 bits, where a rejection (about 1.2 %) re-hashes the bits, so a
//! normal too is a pure function of its key. [`inverse_normal_cdf`] (Acklam)
//! is kept for quantile work.

/// SplitMix64 finaliser: a bijective avalanche mix of 64 bits.
#[inline(always)]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

const GOLDEN: u64 = 0x9e37_79b9_7f4a_7c15;

/// One SplitMix64 step from state `z`: `mix64(z + golden_gamma)`.
#[inline(always)]
pub fn splitmix64(z: u64) -> u64 {
    mix64(z.wrapping_add(GOLDEN))
}

/// The chained hash of three words used by the L-system and IFS kernels:
/// `splitmix64(splitmix64(splitmix64(seed) ^ a) ^ b)`. Cheaper to key per
/// call than [`StreamKey`] when each `(seed, a)` is used once or twice.
#[inline]
pub fn chain_hash3(seed: u64, a: u64, b: u64) -> u64 {
    splitmix64(splitmix64(splitmix64(seed) ^ a) ^ b)
}

/// Uniform number in [0, 1) from [`chain_hash3`]`(seed, a, b)` (top 53 bits).
#[inline]
pub fn chain_unit3(seed: u64, a: u64, b: u64) -> f64 {
    (chain_hash3(seed, a, b) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Hash of the key `(seed, stream, index)` to 64 random bits.
#[inline(always)]
pub fn hash3(seed: u64, stream: u64, index: u64) -> u64 {
    StreamKey::new(seed, stream).bits(index)
}

/// Key prefix that is hashed once per stream: `StreamKey::new(seed, stream)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamKey(u64);

impl StreamKey {
    /// Fix `(seed, stream)`; samples are then drawn by index.
    pub fn new(seed: u64, stream: u64) -> Self {
        let a = mix64(seed.wrapping_add(GOLDEN));
        StreamKey(mix64(
            a ^ stream
                .wrapping_mul(0xd6e8_feb8_6659_fd93)
                .wrapping_add(GOLDEN),
        ))
    }
    /// 64 random bits at `index`; equals `hash3(seed, stream, index)`.
    ///
    /// This is SplitMix64 (Steele, Lea & Flood 2014) with the stream key as
    /// its starting state, evaluated at position `index`.
    #[inline(always)]
    pub fn bits(self, index: u64) -> u64 {
        mix64(
            self.0
                .wrapping_add(index.wrapping_add(1).wrapping_mul(GOLDEN)),
        )
    }
    /// Uniform in the open interval (0, 1) at `index`.
    #[inline(always)]
    pub fn uniform(self, index: u64) -> f64 {
        bits_to_open_unit(self.bits(index))
    }
    /// Standard normal at `index` (ziggurat on the hash of the key).
    #[inline(always)]
    pub fn normal(self, index: u64) -> f64 {
        ziggurat_normal(self.bits(index))
    }
    /// Standard normal at the 2D position `(row, col)` of a grid that has
    /// `cols_total` columns (the index is `row * cols_total + col`).
    #[inline(always)]
    pub fn normal2(self, row: u64, col: u64, cols_total: u64) -> f64 {
        self.normal(row.wrapping_mul(cols_total).wrapping_add(col))
    }
}

const ZIG_N: usize = 128;
const ZIG_R: f64 = 3.442_619_855_899;
const ZIG_V: f64 = 9.912_563_035_262_17e-3;

struct ZigTables {
    x: [f64; ZIG_N + 1],
    f: [f64; ZIG_N + 1],
}

fn zig_tables() -> &'static ZigTables {
    static T: std::sync::OnceLock<ZigTables> = std::sync::OnceLock::new();
    T.get_or_init(|| {
        // Marsaglia & Tsang (2000): 128 layers of equal area v; x[1] = r.
        let f = |x: f64| (-0.5 * x * x).exp();
        let mut x = [0.0; ZIG_N + 1];
        x[0] = ZIG_V / f(ZIG_R);
        x[1] = ZIG_R;
        for i in 2..ZIG_N {
            x[i] = (-2.0 * (ZIG_V / x[i - 1] + f(x[i - 1])).ln()).sqrt();
        }
        x[ZIG_N] = 0.0;
        let mut fx = [0.0; ZIG_N + 1];
        for i in 0..=ZIG_N {
            fx[i] = f(x[i]);
        }
        ZigTables { x, f: fx }
    })
}

/// A standard normal from 64 random bits, by the ziggurat method (Marsaglia
/// & Tsang 2000, 128 layers). Rejections (about 1.2 %) draw new bits by
/// re-hashing, so the value stays a pure function of `bits`.
///
/// The test of the first rectangle (98.8 % of the calls) is inlined; the rest
/// is [`ziggurat_loop`], which starts over with the same bits.
#[inline(always)]
pub fn ziggurat_normal(bits: u64) -> f64 {
    let t = zig_tables();
    let i = (bits & 0x7f) as usize;
    let u = ((bits >> 11) as f64) * (2.0 / 9_007_199_254_740_992.0) - 1.0; // [-1, 1)
    let z = u * t.x[i];
    if z.abs() < t.x[i + 1] {
        return z;
    }
    ziggurat_loop(bits)
}

/// The whole ziggurat method (see [`ziggurat_normal`]), out of line.
#[cold]
#[inline(never)]
fn ziggurat_loop(mut bits: u64) -> f64 {
    let t = zig_tables();
    loop {
        let i = (bits & 0x7f) as usize;
        let u = ((bits >> 11) as f64) * (2.0 / 9_007_199_254_740_992.0) - 1.0; // [-1, 1)
        let z = u * t.x[i];
        if z.abs() < t.x[i + 1] {
            return z;
        }
        bits = mix64(bits ^ 0x5851_f42d_4c95_7f2d);
        if i == 0 {
            // Tail beyond r (Marsaglia 1964).
            loop {
                let u1 = bits_to_open_unit(bits);
                bits = mix64(bits ^ 0x5851_f42d_4c95_7f2d);
                let u2 = bits_to_open_unit(bits);
                bits = mix64(bits ^ 0x5851_f42d_4c95_7f2d);
                let a = -u1.ln() / ZIG_R;
                let b = -u2.ln();
                if 2.0 * b > a * a {
                    return if u < 0.0 { -(ZIG_R + a) } else { ZIG_R + a };
                }
            }
        }
        let y = t.f[i] + bits_to_open_unit(bits) * (t.f[i + 1] - t.f[i]);
        if y < (-0.5 * z * z).exp() {
            return z;
        }
        bits = mix64(bits ^ 0x5851_f42d_4c95_7f2d);
    }
}

/// Top 53 bits to (0, 1): (k + 0.5) / 2^53, never 0 or 1.
#[inline(always)]
pub fn bits_to_open_unit(bits: u64) -> f64 {
    // `as i64`: the 53 bits fit, and a signed conversion is one instruction
    ((bits >> 11) as i64 as f64 + 0.5) * (1.0 / 9_007_199_254_740_992.0)
}

/// Inverse of the standard normal CDF for p in (0, 1).
///
/// Acklam's algorithm (2003): a rational approximation in the central region
/// 0.02425 <= p <= 0.97575 and another in the tails (relative error < 1.15e-9).
#[inline]
pub fn inverse_normal_cdf(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.02425;
    if p < P_LOW {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    }
}

/// Fill `out` with standard normals of stream `(seed, stream)` at indices
/// `start .. start + out.len()`, in parallel (the result does not depend on
/// the number of threads), ticking `progress` by the values drawn (total:
/// `out.len()`).
pub fn fill_normal(
    out: &mut [f64],
    seed: u64,
    stream: u64,
    start: u64,
    progress: Option<&crate::progress::Progress>,
) {
    use rayon::prelude::*;
    let key = StreamKey::new(seed, stream);
    crate::progress::add_total(progress, out.len() as u64);
    out.par_chunks_mut(1 << 14)
        .enumerate()
        .for_each(|(ci, chunk)| {
            let base = start + (ci as u64) * (1 << 14);
            for (i, v) in chunk.iter_mut().enumerate() {
                *v = key.normal(base + i as u64);
            }
            crate::progress::tick(progress, chunk.len() as u64);
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_hash_is_the_lsystem_hash_bit_for_bit() {
        // the L-system kernels' former private finaliser, kept here as the
        // reference for the seeds users already have
        fn old_mix64(mut z: u64) -> u64 {
            z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        for (s, a, b) in [
            (0u64, 0u64, 0u64),
            (42, 7, 3),
            (u64::MAX, 1, 0x1f5),
            (12345, 99, 4),
        ] {
            assert_eq!(
                chain_hash3(s, a, b),
                old_mix64(old_mix64(old_mix64(s) ^ a) ^ b)
            );
        }
    }

    #[test]
    fn splitmix64_reference() {
        // SplitMix64 from state 0: first output 0xe220a8397b1dcdaf (Vigna's reference code).
        assert_eq!(mix64(GOLDEN), 0xe220_a839_7b1d_cdaf);
        // A stream is SplitMix64 started from its key, read at any position.
        let k = StreamKey::new(42, 7);
        let mut state = k.0;
        for i in 0..100u64 {
            state = state.wrapping_add(GOLDEN);
            assert_eq!(k.bits(i), mix64(state));
        }
        for i in [0u64, 1, 2, 1000, u64::MAX] {
            assert_eq!(k.bits(i), hash3(42, 7, i));
        }
        assert_ne!(hash3(42, 7, 0), hash3(42, 8, 0));
        assert_ne!(hash3(42, 7, 0), hash3(43, 7, 0));
    }

    #[test]
    fn inverse_cdf_known_quantiles() {
        // Quantiles of N(0, 1) from tables (Abramowitz & Stegun 26.2).
        let cases = [
            (0.5, 0.0),
            (0.975, 1.959_963_984_540_054),
            (0.841_344_746_068_543, 1.0),
            (0.001, -3.090_232_306_167_813),
        ];
        for (p, x) in cases {
            assert!((inverse_normal_cdf(p) - x).abs() < 1e-8, "p={p}");
        }
    }

    #[test]
    fn normal_moments() {
        let n = 400_000u64;
        let k = StreamKey::new(1, 0);
        let (mut s1, mut s2, mut s4) = (0.0, 0.0, 0.0);
        for i in 0..n {
            let z = k.normal(i);
            s1 += z;
            s2 += z * z;
            s4 += z * z * z * z;
        }
        let nf = n as f64;
        // Standard errors: mean 1/sqrt(n)=0.0016, var sqrt(2/n)=0.0022, 4th moment sqrt(96/n)=0.015.
        assert!((s1 / nf).abs() < 0.008);
        assert!((s2 / nf - 1.0).abs() < 0.011);
        assert!((s4 / nf - 3.0).abs() < 0.08);
    }

    #[test]
    fn fill_is_thread_independent() {
        let mut a = vec![0.0; 100_000];
        let mut b = vec![0.0; 100_000];
        crate::parallel::run_in_pool(Some(1), || {
            fill_normal(&mut a, 9, 3, 10, None);
            Ok(())
        })
        .unwrap();
        crate::parallel::run_in_pool(Some(2), || {
            fill_normal(&mut b, 9, 3, 10, None);
            Ok(())
        })
        .unwrap();
        assert_eq!(a, b);
        assert_eq!(a[5], StreamKey::new(9, 3).normal(15));
    }
}

#[cfg(test)]
mod zig_tests {
    use super::*;

    #[test]
    fn ziggurat_tables_close() {
        // The layers must close at the top: x[127] small, area v each.
        let t = zig_tables();
        assert!(
            t.x[ZIG_N - 1] > 0.0 && t.x[ZIG_N - 1] < 0.3,
            "{}",
            t.x[ZIG_N - 1]
        );
        let last_area = t.x[ZIG_N - 1] * (1.0 - t.f[ZIG_N - 1]);
        assert!(
            (last_area - ZIG_V).abs() < 1e-6 * ZIG_V * 1000.0,
            "{last_area}"
        );
    }

    #[test]
    fn inline_first_rectangle_agrees_with_the_whole_method() {
        // About 12 000 of these draws leave the first rectangle.
        let k = StreamKey::new(8, 2);
        for i in 0..1_000_000u64 {
            let b = k.bits(i);
            assert_eq!(ziggurat_normal(b).to_bits(), ziggurat_loop(b).to_bits());
        }
    }

    #[test]
    fn ziggurat_cdf_matches_normal() {
        // Empirical CDF at fixed points against Phi (A&S 26.2 values); 10^6
        // samples: standard error of a proportion <= 0.0005.
        let k = StreamKey::new(3, 1);
        let pts = [
            (-3.0, 0.001_349_898),
            (-1.0, 0.158_655_254),
            (0.0, 0.5),
            (0.5, 0.691_462_461),
            (2.0, 0.977_249_868),
            (3.5, 0.999_767_371),
        ];
        let n = 1_000_000u64;
        let mut counts = [0u64; 6];
        for i in 0..n {
            let z = k.normal(i);
            for (c, (x, _)) in counts.iter_mut().zip(pts.iter()) {
                if z <= *x {
                    *c += 1;
                }
            }
        }
        for (c, (x, p)) in counts.iter().zip(pts.iter()) {
            let se = (p * (1.0 - p) / n as f64).sqrt();
            assert!((*c as f64 / n as f64 - p).abs() < 4.0 * se + 1e-6, "x={x}");
        }
    }
}
