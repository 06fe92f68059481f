//! Moving-window P(m, L) mass dimension (Voss 1986; the paper's eq. 13 and
//! its SAR fractal transform, section 4.2).
//!
//! The image is the point set `(i, j, z / z_scale)`. For a box side
//! `L = 2k + 1` (pixels) centred on pixel `p`, `m_p(L)` is the number of valid
//! pixels `q` of the *image* with `|i_q - i_p| <= k`, `|j_q - j_p| <= k` and
//! `|z_q - z_p| <= L z_scale / 2` (so `m_p >= 1`). The value of a window is
//!
//! ```text
//! N(L) = mean over the window's valid pixels p of 1 / m_p(L)   (= sum_m P(m, L) / m)
//! D    = -slope of log N(L) against log L
//! ```
//!
//! Boxes count every pixel of the image, not only those of the window, so a
//! point's mass does not depend on where the analysis window sits and the
//! window sums come from summed-area tables: the cost per pixel is the box
//! neighbourhood (`L_max^2`), independent of the window.
use super::sat::{band_rows, check_window, line_fit, log_axis, rect, sat};
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

/// Options of [`mass_transform`].
#[derive(Debug, Clone)]
pub struct MassOptions {
    pub window: usize,
    /// Odd box sides, ascending, at least two.
    pub box_sizes: Vec<usize>,
    pub z_scale: f64,
    pub min_valid: f64,
}

/// `m_p(L)` for every pixel of rows `[r0, r1)` and every box size; invalid
/// pixels get 0. Layout: `[size][row - r0][col]`.
///
/// Loops run over the neighbourhood offsets outside and over a row of pixels
/// inside, so the comparisons vectorise; a pair counts for box `k` when its
/// spatial offset is within `k` and `|z_q - z_p| <= (k + 1/2) z_scale`
/// (NaN on either side never counts).
pub fn box_masses(
    z: &[f64],
    rows: usize,
    cols: usize,
    r0: usize,
    r1: usize,
    ks: &[usize],
    z_scale: f64,
) -> Vec<Vec<f64>> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            return unsafe { box_masses_avx2(z, rows, cols, r0, r1, ks, z_scale) };
        }
    }
    box_masses_impl(z, rows, cols, r0, r1, ks, z_scale)
}

/// [`box_masses`] compiled for AVX2 (4 doubles per compare). The arithmetic
/// (one subtraction, `abs`, one comparison per pair) is the same IEEE
/// operations in either build, so the counts are identical.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn box_masses_avx2(
    z: &[f64],
    rows: usize,
    cols: usize,
    r0: usize,
    r1: usize,
    ks: &[usize],
    z_scale: f64,
) -> Vec<Vec<f64>> {
    box_masses_impl(z, rows, cols, r0, r1, ks, z_scale)
}

#[inline(always)]
fn box_masses_impl(
    z: &[f64],
    rows: usize,
    cols: usize,
    r0: usize,
    r1: usize,
    ks: &[usize],
    z_scale: f64,
) -> Vec<Vec<f64>> {
    let kmax = *ks.last().unwrap_or(&0) as isize;
    let nr = r1 - r0;
    let thr: Vec<f64> = ks.iter().map(|&k| (k as f64 + 0.5) * z_scale).collect();
    let mut out = vec![vec![0.0f64; nr * cols]; ks.len()];
    // counts kept as f64 (exact below 2^53) so compare, mask and add stay
    // in 64-bit lanes; |z_q - z_p| of one offset is computed once for all k
    let mut acc = vec![vec![0f64; cols]; ks.len()];
    let mut dbuf = vec![0f64; cols];
    for r in r0..r1 {
        acc.iter_mut()
            .for_each(|a| a.iter_mut().for_each(|v| *v = 0.0));
        let zp = &z[r * cols..(r + 1) * cols];
        for di in -kmax..=kmax {
            let q = r as isize + di;
            if q < 0 || q >= rows as isize {
                continue;
            }
            let zq = &z[q as usize * cols..(q as usize + 1) * cols];
            for dj in -kmax..=kmax {
                let ds = di.unsigned_abs().max(dj.unsigned_abs());
                // pixels c with 0 <= c + dj < cols
                let (c0, c1) = if dj >= 0 {
                    (0usize, cols.saturating_sub(dj as usize))
                } else {
                    ((-dj) as usize, cols)
                };
                if c1 <= c0 {
                    continue;
                }
                let n = c1 - c0;
                let qs = (c0 as isize + dj) as usize;
                let a = &zp[c0..c0 + n];
                let b = &zq[qs..qs + n];
                let d = &mut dbuf[..n];
                for ((d, &x), &y) in d.iter_mut().zip(a).zip(b) {
                    *d = (y - x).abs();
                }
                for (s, &k) in ks.iter().enumerate() {
                    if k < ds {
                        continue;
                    }
                    let t = thr[s];
                    for (m, &d) in acc[s][c0..c0 + n].iter_mut().zip(d.iter()) {
                        *m += if d <= t { 1.0 } else { 0.0 };
                    }
                }
            }
        }
        for s in 0..ks.len() {
            let row = &mut out[s][(r - r0) * cols..(r - r0 + 1) * cols];
            row.copy_from_slice(&acc[s]);
        }
    }
    out
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
    if !(z_scale.is_finite() && z_scale > 0.0) {
        return Err(CoreError::invalid(
            "z_scale",
            format!("expected a positive number, got {z_scale}"),
        ));
    }
    let mut order: Vec<usize> = (0..box_sizes.len()).collect();
    order.sort_by_key(|&i| box_sizes[i]);
    let ks: Vec<usize> = order.iter().map(|&i| box_sizes[i] / 2).collect();
    let band = 64usize;
    let partial: Vec<(Vec<f64>, f64)> = (0..rows.div_ceil(band))
        .into_par_iter()
        .map(|b| {
            let (r0, r1) = (b * band, ((b + 1) * band).min(rows));
            let m = box_masses(z, rows, cols, r0, r1, &ks, z_scale);
            let n = m[0].iter().filter(|&&v| v > 0.0).count() as f64;
            let sums = m
                .iter()
                .map(|plane| plane.iter().filter(|&&v| v > 0.0).map(|v| 1.0 / v).sum())
                .collect();
            (sums, n)
        })
        .collect();
    let mut sums = vec![0.0f64; ks.len()];
    let mut n = 0.0;
    for (s, c) in partial {
        for (a, b) in sums.iter_mut().zip(s) {
            *a += b;
        }
        n += c;
    }
    if n == 0.0 {
        return Err(CoreError::invalid("data", "no valid value (all NaN)"));
    }
    let mut out = vec![0.0f64; box_sizes.len()];
    for (slot, &i) in order.iter().enumerate() {
        out[i] = sums[slot] / n;
    }
    Ok(out)
}

/// Local P(m, L) dimension and r² maps (row-major; NaN where the window has
/// fewer valid pixels than `min_valid * w * w`).
pub fn mass_transform(
    z: &[f64],
    rows: usize,
    cols: usize,
    opt: &MassOptions,
) -> CoreResult<(Vec<f32>, Vec<f32>)> {
    let w = opt.window;
    let min_pixels = check_window(z.len(), rows, cols, w, opt.min_valid)?;
    let mut sizes = opt.box_sizes.clone();
    sizes.sort_unstable();
    sizes.dedup();
    if sizes.len() < 2 || sizes.iter().any(|&l| l < 3 || l % 2 == 0 || l > w) {
        return Err(CoreError::invalid(
            "box_sizes",
            format!(
                "need at least 2 distinct odd box sides in [3, {w}], got {:?}",
                opt.box_sizes
            ),
        ));
    }
    if !(opt.z_scale.is_finite() && opt.z_scale > 0.0) {
        return Err(CoreError::invalid(
            "z_scale",
            format!("expected a positive number, got {}", opt.z_scale),
        ));
    }
    let ks: Vec<usize> = sizes.iter().map(|l| l / 2).collect();
    let (xs, xm, sxx) = log_axis(&sizes);
    let h = w / 2;
    let band_rows = band_rows(w);
    let mut dim = vec![f32::NAN; rows * cols];
    let mut r2 = vec![f32::NAN; rows * cols];
    dim.par_chunks_mut(band_rows * cols)
        .zip(r2.par_chunks_mut(band_rows * cols))
        .enumerate()
        .for_each(|(band, (dout, rout))| {
            let o0 = band * band_rows;
            let o1 = (o0 + band_rows).min(rows);
            let i0 = o0.saturating_sub(h);
            let i1 = (o1 + h).min(rows);
            let nr = i1 - i0;
            let sw = cols + 1;
            let masses = box_masses(z, rows, cols, i0, i1, &ks, opt.z_scale);
            let valid: Vec<f64> = (0..nr * cols)
                .map(|k| (!z[i0 * cols + k].is_nan()) as u8 as f64)
                .collect();
            let vsat = sat(&valid, nr, cols);
            let isats: Vec<Vec<f64>> = masses
                .iter()
                .map(|m| {
                    let inv: Vec<f64> = m
                        .iter()
                        .map(|&v| if v > 0.0 { 1.0 / v } else { 0.0 })
                        .collect();
                    sat(&inv, nr, cols)
                })
                .collect();
            let mut ys = vec![0.0f64; sizes.len()];
            for i in o0..o1 {
                let r0 = i.saturating_sub(h) - i0;
                let r1 = (i + h + 1).min(rows) - i0;
                for j in 0..cols {
                    let c0 = j.saturating_sub(h);
                    let c1 = (j + h + 1).min(cols);
                    let n = rect(&vsat, sw, r0, r1, c0, c1);
                    if n < min_pixels {
                        continue;
                    }
                    for (l, s) in isats.iter().enumerate() {
                        ys[l] = (rect(s, sw, r0, r1, c0, c1) / n).ln();
                    }
                    let (slope, fit_r2) = line_fit(&xs, xm, sxx, &ys);
                    let k = (i - o0) * cols + j;
                    dout[k] = (-slope) as f32;
                    rout[k] = fit_r2 as f32;
                }
            }
        });
    Ok((dim, r2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_image_is_two() {
        // all heights equal: m_p(L) = L^2 inside, N(L) = 1/L^2, D = 2
        let (rows, cols) = (60usize, 50usize);
        let z = vec![3.0f64; rows * cols];
        let opt = MassOptions {
            window: 15,
            box_sizes: vec![3, 5, 7],
            z_scale: 1.0,
            min_valid: 0.5,
        };
        let (d, _) = mass_transform(&z, rows, cols, &opt).unwrap();
        // windows whose boxes stay inside the image
        for i in 10..rows - 10 {
            for j in 10..cols - 10 {
                assert!((d[i * cols + j] - 2.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn masses_match_brute_force() {
        let (rows, cols) = (23usize, 19usize);
        let mut seed = 9u64;
        let z: Vec<f64> = (0..rows * cols)
            .map(|k| {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                if k % 17 == 3 {
                    f64::NAN
                } else {
                    ((seed >> 40) % 13) as f64
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
