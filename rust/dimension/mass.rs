//! Voss's (1986) P(m, L) mass of grayscale images (the paper's eq. 13): the
//! box masses of every pixel and the image-wide curve `N(L)` of the
//! `mass_dimension` estimator. The moving-window map on the same masses is
//! `crate::transform::mass`.
//!
//! The image is the point set `(i, j, z / z_scale)`. For a box side
//! `L = 2k + 1` (pixels) centred on pixel `p`, `m_p(L)` is the number of valid
//! pixels `q` of the *image* with `|i_q - i_p| <= k`, `|j_q - j_p| <= k` and
//! `|z_q - z_p| <= L z_scale / 2` (so `m_p >= 1`), and
//!
//! ```text
//! N(L) = mean over the valid pixels p of 1 / m_p(L)   (= sum_m P(m, L) / m)
//! D    = -slope of log N(L) against log L
//! ```
use crate::checks::positive_finite;
use crate::error::{CoreError, CoreResult};
use crate::sample::Sample;
use rayon::prelude::*;

/// `m_p(L)` for every pixel of rows `[r0, r1)` and every box size; invalid
/// pixels get 0. Layout: `[size][row - r0][col]`.
///
/// `ks` (box half-sides) ascending. A pair counts for box `k` when its
/// spatial offset is within `k` and `|z_q - z_p| <= (k + 1/2) z_scale`
/// (NaN on either side never counts). Pixels go by blocks of [`BLOCK`] along
/// a row, their counters kept in registers while the offsets are walked.
pub fn box_masses<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    r0: usize,
    r1: usize,
    ks: &[usize],
    z_scale: f64,
) -> Vec<Vec<f64>> {
    let mut buf = MassBuf::default();
    let band = Band {
        z,
        rows,
        cols,
        r0,
        r1,
        ks,
        z_scale,
    };
    box_masses_into(&band, &mut buf);
    buf.planes
}

/// Rows `[r0, r1)` of a `rows x cols` image, with the box half-sides `ks`
/// (ascending) and the height unit `z_scale` of [`box_masses`].
pub(crate) struct Band<'a, T> {
    pub z: &'a [T],
    pub rows: usize,
    pub cols: usize,
    pub r0: usize,
    pub r1: usize,
    pub ks: &'a [usize],
    pub z_scale: f64,
}

/// Buffers of [`box_masses_into`], reusable from band to band: the
/// NaN-padded band and the mass planes (`[size][row - r0][col]`).
#[derive(Default)]
pub(crate) struct MassBuf {
    zp: Vec<f64>,
    pub planes: Vec<Vec<f64>>,
}

/// [`box_masses`] into reusable buffers (`buf.planes` holds the result).
pub(crate) fn box_masses_into<T: Sample>(band: &Band<T>, buf: &mut MassBuf) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { box_masses_avx2(band, buf) };
        }
    }
    box_masses_impl::<false, T>(band, buf)
}

/// [`box_masses`] compiled for AVX2 (4 doubles per compare). The arithmetic
/// (one subtraction, `abs`, one comparison per pair) is the same IEEE
/// operations in either build, so the counts are identical.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn box_masses_avx2<T: Sample>(band: &Band<T>, buf: &mut MassBuf) {
    box_masses_impl::<true, T>(band, buf)
}

/// Pixels per block of [`box_masses_impl`]: the block's counters stay in
/// registers while the neighbourhood offsets are walked.
const BLOCK: usize = 16;
/// At most this many thresholds (box sizes) per pass over a ring of offsets.
const MAX_THR: usize = 2;

/// `AVX2`: count with the AVX2 intrinsics of [`avx2::ring`] (only
/// instantiated by [`box_masses_avx2`], which runs once AVX2 is detected).
#[inline(always)]
fn box_masses_impl<const AVX2: bool, T: Sample>(band: &Band<T>, buf: &mut MassBuf) {
    let &Band {
        z,
        rows,
        cols,
        r0,
        r1,
        ks,
        z_scale,
    } = band;
    let MassBuf { zp, planes: out } = buf;
    let kmax = *ks.last().unwrap_or(&0);
    let nr = r1 - r0;
    let thr: Vec<f64> = ks.iter().map(|&k| (k as f64 + 0.5) * z_scale).collect();
    // every value of every plane is written below (blocks cover the columns):
    // a reused plane keeps its old values until then, with no zeroing pass
    out.resize_with(ks.len(), Vec::new);
    for o in out.iter_mut() {
        o.resize(nr * cols, 0.0);
    }
    if nr == 0 || cols == 0 || ks.is_empty() {
        return;
    }
    // The band's rows with a NaN margin of `kmax` on every side (and the
    // columns rounded up to whole blocks): NaN never counts, so the offsets
    // need no bounds tests.
    let ncb = cols.div_ceil(BLOCK);
    let pw = ncb * BLOCK + 2 * kmax;
    let ph = nr + 2 * kmax;
    zp.clear();
    zp.resize(ph * pw, f64::NAN);
    for (pr, prow) in zp.chunks_exact_mut(pw).enumerate() {
        let r = (r0 + pr).wrapping_sub(kmax);
        if r < rows {
            for (d, &v) in prow[kmax..kmax + cols]
                .iter_mut()
                .zip(&z[r * cols..(r + 1) * cols])
            {
                *d = v.to_f64();
            }
        }
    }
    // Box k counts the offsets with Chebyshev radius <= k. Ring s holds the
    // radii (k_{s-1}, k_s]; its pairs count for boxes s, s + 1, .. with their
    // own thresholds, so m_p(k_s) = sum over rings t <= s of ring t's count
    // at threshold s. A pass walks one ring with up to MAX_THR thresholds.
    let mut passes: Vec<(usize, usize, usize, usize)> = Vec::new(); // (lo, hi, first box, boxes)
    for (s, &hi) in ks.iter().enumerate() {
        let lo = if s == 0 { 0 } else { ks[s - 1] + 1 };
        if lo > hi {
            continue;
        }
        let mut b = s;
        while b < ks.len() {
            let n = (ks.len() - b).min(MAX_THR);
            passes.push((lo, hi, b, n));
            b += n;
        }
    }
    let mut cnt = vec![[0u64; BLOCK]; ks.len()];
    for r in 0..nr {
        for cb in 0..ncb {
            let c = cb * BLOCK;
            let centre = (r + kmax) * pw + kmax + c;
            cnt.iter_mut().for_each(|a| *a = [0; BLOCK]);
            for &(lo, hi, b, n) in &passes {
                let (t, c) = (&thr[b..b + n], &mut cnt[b..b + n]);
                #[cfg(target_arch = "x86_64")]
                if AVX2 {
                    // SAFETY: AVX2 is available (see the const parameter).
                    unsafe {
                        match n {
                            1 => avx2::ring::<1>(zp, pw, centre, lo, hi, t, c),
                            _ => avx2::ring::<2>(zp, pw, centre, lo, hi, t, c),
                        }
                    }
                    continue;
                }
                match n {
                    1 => ring::<1>(zp, pw, centre, lo, hi, t, c),
                    _ => ring::<2>(zp, pw, centre, lo, hi, t, c),
                }
            }
            let m = BLOCK.min(cols - c);
            for (o, a) in out.iter_mut().zip(&cnt) {
                let dst = &mut o[r * cols + c..r * cols + c + m];
                for (d, &v) in dst.iter_mut().zip(a.iter()) {
                    *d = v as f64;
                }
            }
        }
    }
}

/// Adds to `cnt[t][l]` the pairs (pixel `centre + l`, pixel at offset
/// `(di, dj)`) with Chebyshev radius `max(|di|, |dj|)` in `[lo, hi]` and
/// `|z_q - z_p| <= thr[t]`, for the `N` thresholds.
#[inline(always)]
fn ring<const N: usize>(
    zp: &[f64],
    pw: usize,
    centre: usize,
    lo: usize,
    hi: usize,
    thr: &[f64],
    cnt: &mut [[u64; BLOCK]],
) {
    let p: [f64; BLOCK] = zp[centre..centre + BLOCK].try_into().unwrap();
    let t: [f64; N] = thr.try_into().unwrap();
    let mut acc = [[0u64; BLOCK]; N];
    for di in 0..=2 * hi {
        // row offset di - hi; columns centre - hi ..= centre + hi
        let base = centre + di * pw - hi * pw - hi;
        if di.abs_diff(hi) >= lo {
            run(&zp[base..base + 2 * hi + BLOCK], &p, &t, &mut acc);
        } else {
            // |di - hi| < lo: only the columns with |dj| >= lo
            run(&zp[base..base + hi - lo + BLOCK], &p, &t, &mut acc);
            run(&zp[base + hi + lo..base + 2 * hi + BLOCK], &p, &t, &mut acc);
        }
    }
    for (c, a) in cnt.iter_mut().zip(&acc) {
        for (c, &a) in c.iter_mut().zip(a) {
            *c += a;
        }
    }
}

/// The pairs of the block `p` with every block-long window of `seg`.
#[inline(always)]
fn run<const N: usize>(seg: &[f64], p: &[f64; BLOCK], t: &[f64; N], acc: &mut [[u64; BLOCK]; N]) {
    for zq in seg.windows(BLOCK) {
        let zq: &[f64; BLOCK] = zq.try_into().unwrap();
        for l in 0..BLOCK {
            let d = (zq[l] - p[l]).abs();
            for n in 0..N {
                acc[n][l] += (d <= t[n]) as u64;
            }
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::BLOCK;
    use std::arch::x86_64::*;

    /// [`super::ring`] with AVX2 intrinsics: the block is four vectors of
    /// four doubles and its `4 N` counters stay in registers. Same IEEE
    /// operations per pair (subtract, clear the sign, ordered `<=`), so the
    /// counts are the same.
    #[target_feature(enable = "avx2")]
    #[inline]
    pub(super) unsafe fn ring<const N: usize>(
        zp: &[f64],
        pw: usize,
        centre: usize,
        lo: usize,
        hi: usize,
        thr: &[f64],
        cnt: &mut [[u64; BLOCK]],
    ) {
        // every window read below lies in rows centre -+ hi, columns -+ hi
        assert!(centre >= hi * pw + hi && centre + hi * pw + hi + BLOCK <= zp.len());
        assert!(thr.len() == N && cnt.len() == N && lo <= hi + 1);
        let z = zp.as_ptr();
        let p = [0, 4, 8, 12].map(|o| _mm256_loadu_pd(z.add(centre + o)));
        let t: [__m256d; N] = std::array::from_fn(|n| _mm256_set1_pd(thr[n]));
        let sign = _mm256_set1_pd(-0.0);
        let mut acc = [[_mm256_setzero_si256(); 4]; N];
        let mut run = |q0: usize, q1: usize| {
            for q in q0..=q1 {
                let w = z.add(q);
                for v in 0..4 {
                    let d =
                        _mm256_andnot_pd(sign, _mm256_sub_pd(_mm256_loadu_pd(w.add(4 * v)), p[v]));
                    for n in 0..N {
                        let m = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_LE_OQ>(d, t[n]));
                        // the mask is -1 where the pair counts
                        acc[n][v] = _mm256_sub_epi64(acc[n][v], m);
                    }
                }
            }
        };
        for di in 0..=2 * hi {
            let base = centre + di * pw - hi * pw - hi;
            if di.abs_diff(hi) >= lo {
                run(base, base + 2 * hi);
            } else {
                run(base, base + hi - lo);
                run(base + hi + lo, base + 2 * hi);
            }
        }
        for (c, a) in cnt.iter_mut().zip(&acc) {
            let mut buf = [0u64; BLOCK];
            for (v, x) in a.iter().enumerate() {
                _mm256_storeu_si256(buf.as_mut_ptr().add(4 * v) as *mut __m256i, *x);
            }
            for (c, b) in c.iter_mut().zip(buf) {
                *c += b;
            }
        }
    }
}

/// Image-wide `N(L) = mean over valid pixels of 1 / m_p(L)` for every box
/// side (the global P(m, L) estimator of a grayscale image). Bands of rows
/// are summed in a fixed order, so the result does not depend on threads.
pub fn mass_curve(
    z: &[f64],
    rows: usize,
    cols: usize,
    box_sizes: &[usize],
    z_scale: f64,
) -> CoreResult<Vec<f64>> {
    if rows * cols == 0 || z.len() != rows * cols {
        return Err(CoreError::invalid("data", "image is empty"));
    }
    if box_sizes.is_empty() || box_sizes.iter().any(|&l| l < 1 || l % 2 == 0) {
        return Err(CoreError::invalid(
            "box_sizes",
            format!("box sides must be odd and positive, got {box_sizes:?}"),
        ));
    }
    positive_finite(z_scale, "z_scale")?;
    let mut order: Vec<usize> = (0..box_sizes.len()).collect();
    order.sort_by_key(|&i| box_sizes[i]);
    let ks: Vec<usize> = order.iter().map(|&i| box_sizes[i] / 2).collect();
    let band = 64usize;
    let partial: Vec<(Vec<f64>, usize)> = (0..rows.div_ceil(band))
        .into_par_iter()
        .map_init(MassBuf::default, |buf, b| {
            let (r0, r1) = (b * band, ((b + 1) * band).min(rows));
            let job = Band {
                z,
                rows,
                cols,
                r0,
                r1,
                ks: &ks,
                z_scale,
            };
            box_masses_into(&job, buf);
            let m = &buf.planes;
            let n = m[0].iter().filter(|&&v| v > 0.0).count();
            let sums = m
                .iter()
                .map(|plane| plane.iter().filter(|&&v| v > 0.0).map(|v| 1.0 / v).sum())
                .collect();
            (sums, n)
        })
        .collect();
    let (sums, n) = super::sum_parts(partial, ks.len())?;
    // an exact integer count (below 2^53), as the band counts' f64 sum was
    let n = n as f64;
    let mut out = vec![0.0f64; box_sizes.len()];
    for (slot, &i) in order.iter().enumerate() {
        out[i] = sums[slot] / n;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `m_p(k)` by direct pairwise counting over the whole image.
    fn naive_masses(
        z: &[f64],
        rows: usize,
        cols: usize,
        r: usize,
        c: usize,
        k: usize,
        zs: f64,
    ) -> f64 {
        let zp = z[r * cols + c];
        let t = (k as f64 + 0.5) * zs;
        let mut n = 0.0;
        for q in r.saturating_sub(k)..(r + k + 1).min(rows) {
            for qc in c.saturating_sub(k)..(c + k + 1).min(cols) {
                if (z[q * cols + qc] - zp).abs() <= t {
                    n += 1.0;
                }
            }
        }
        n
    }

    #[test]
    fn masses_match_naive_pairs_on_bands_and_box_lists() {
        for (seed, &(rows, cols)) in [(1usize, 1usize), (7, 40), (31, 17), (40, 53), (5, 3)]
            .iter()
            .enumerate()
        {
            let u = crate::testdata::uniform(rows * cols, 5 + seed as u64);
            let z: Vec<f64> = (0..rows * cols)
                .map(|k| match k % 23 {
                    4 => f64::NAN,
                    9 => f64::INFINITY,
                    15 => f64::NEG_INFINITY,
                    11 => -0.0,
                    _ => (u[k] * 11.0).floor() * 0.37 - 1.0,
                })
                .collect();
            let lists: [&[usize]; 6] = [
                &[0],
                &[0, 1, 2],
                &[1, 2, 4, 8],
                &[2, 2, 3],
                &[3, 5, 6, 7, 9, 10],
                &[20],
            ];
            // reused buffers, dirty everywhere (3.0, 7.0, then the previous
            // call's results), as in the band drivers
            let mut buf = MassBuf {
                zp: vec![7.0; 100_000],
                planes: vec![vec![3.0; 100_000]; 8],
            };
            for ks in lists {
                for &(r0, r1) in &[(0, rows), (rows / 3, rows), (rows / 2, rows / 2 + 1)] {
                    let job = Band {
                        z: &z[..],
                        rows,
                        cols,
                        r0,
                        r1,
                        ks,
                        z_scale: 0.61,
                    };
                    box_masses_impl::<false, f64>(&job, &mut buf);
                    let out = buf.planes.clone();
                    for m in [box_masses(&z, rows, cols, r0, r1, ks, 0.61), out.clone()] {
                        assert_eq!(m.len(), ks.len());
                        for (s, &k) in ks.iter().enumerate() {
                            assert_eq!(m[s].len(), (r1 - r0) * cols);
                            for r in r0..r1 {
                                for c in 0..cols {
                                    let want = naive_masses(&z, rows, cols, r, c, k, 0.61);
                                    assert_eq!(
                                        m[s][(r - r0) * cols + c],
                                        want,
                                        "{rows}x{cols} ks={ks:?} r={r} c={c} k={k}"
                                    );
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn masses_match_brute_force() {
        let (rows, cols) = (23usize, 19usize);
        let u = crate::testdata::uniform(rows * cols, 9);
        let z: Vec<f64> = (0..rows * cols)
            .map(|k| {
                if k % 17 == 3 {
                    f64::NAN
                } else {
                    (u[k] * 13.0).floor()
                }
            })
            .collect();
        let ks = [1usize, 2, 4];
        let m = box_masses(&z, rows, cols, 0, rows, &ks, 1.7);
        for r in 0..rows {
            for c in 0..cols {
                for (s, &k) in ks.iter().enumerate() {
                    let zp = z[r * cols + c];
                    let mut n = 0.0;
                    if !zp.is_nan() {
                        for q in 0..rows {
                            for qc in 0..cols {
                                let zq = z[q * cols + qc];
                                if !zq.is_nan()
                                    && q.abs_diff(r) <= k
                                    && qc.abs_diff(c) <= k
                                    && (zq - zp).abs() <= (2 * k + 1) as f64 * 1.7 / 2.0
                                {
                                    n += 1.0;
                                }
                            }
                        }
                    }
                    assert_eq!(m[s][r * cols + c], n, "r={r} c={c} k={k}");
                }
            }
        }
    }
}
