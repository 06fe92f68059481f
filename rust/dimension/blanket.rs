//! Peleg's covering blanket (Peleg, Naor, Hartley and Avnir 1984): the
//! growth step and the image-wide areas of the `blanket` estimator. The
//! moving-window map on the same growth step is `crate::transform::blanket`.
//!
//! From `u_0 = b_0 = z / z_scale` the blankets grow one step at a time over
//! the 4-neighbourhood `N` (clipped at the edge of the data):
//!
//! ```text
//! u_e = max(u_{e-1} + 1, max_N u_{e-1}),   b_e = min(b_{e-1} - 1, min_N b_{e-1})
//! A(e) = sum over valid pixels of (u_e - b_e) / (2 e)
//! D    = 2 - slope of log A(e) against log e
//! ```
//!
//! Missing (NaN) pixels are not part of the surface: they hold no blanket and
//! pass none on (the blankets grow around holes); the edge of the data is
//! the same thing as a band of missing pixels. The estimator and the map run
//! the same growth step ([`step_row`]) on rows framed by one missing pixel,
//! so they give the same blankets bit for bit.
use crate::checks::positive_finite;
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

/// Larger of two non-NaN values (the planes hold finite values and
/// infinities only); compiles to one vector max.
#[inline(always)]
pub(crate) fn fmax(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

#[inline(always)]
pub(crate) fn fmin(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// One growth step of one row. The `u*`/`b*` rows (rows above, at and below,
/// `n + 2` samples with a missing sample at each end) are the blankets of
/// the previous step; `mu`/`mb` (`n` samples) are 0 on valid pixels and
/// `-inf`/`+inf` on missing ones. Writes samples `1 ..= n` of `nu`/`nb` and,
/// with `colsum`, adds `u - b` of the valid pixels to it column by column
/// (independent lanes, so the loop vectorises and the order is fixed).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn step_row(
    uu: &[f64],
    uc: &[f64],
    ud: &[f64],
    bu: &[f64],
    bc: &[f64],
    bd: &[f64],
    mu: &[f64],
    mb: &[f64],
    nu: &mut [f64],
    nb: &mut [f64],
    colsum: Option<&mut [f64]>,
) {
    let n = mu.len();
    let (uu, ud, ul, ur, uc) = (&uu[1..=n], &ud[1..=n], &uc[..n], &uc[2..n + 2], &uc[1..=n]);
    let (bu, bd, bl, br, bc) = (&bu[1..=n], &bd[1..=n], &bc[..n], &bc[2..n + 2], &bc[1..=n]);
    let (nu, nb) = (&mut nu[1..=n], &mut nb[1..=n]);
    let mb = &mb[..n];
    for c in 0..n {
        nu[c] = fmax(fmax(fmax(uc[c] + 1.0, uu[c]), fmax(ud[c], ul[c])), ur[c]) + mu[c];
        nb[c] = fmin(fmin(fmin(bc[c] - 1.0, bu[c]), fmin(bd[c], bl[c])), br[c]) + mb[c];
    }
    if let Some(cs) = colsum {
        // valid: u - b >= 2 e > 0; missing: -inf, counted as 0
        for (c, s) in cs[..n].iter_mut().enumerate() {
            *s += fmax(nu[c] - nb[c], 0.0);
        }
    }
}

/// Blanket sums `sum over valid pixels of rows [s0, s1) of (u_e - b_e)`,
/// `e = 1 ..= eps_max`, of the image rows `[r_lo, r_hi)` (rows outside are
/// missing), streamed row by row: level `e` keeps three rows and row `r` of
/// level `e` is computed as soon as row `r + 1` of level `e - 1` exists, so
/// the working set is `3 (eps_max + 1)` rows instead of whole planes.
#[allow(clippy::too_many_arguments)]
fn stream_sums(
    z: &[f64],
    cols: usize,
    r_lo: usize,
    r_hi: usize,
    s0: usize,
    s1: usize,
    eps_max: usize,
    z_scale: f64,
) -> Vec<f64> {
    let pw = cols + 2;
    let levels = eps_max + 1;
    let nm = eps_max + 2; // mask ring
    let mut lu = vec![f64::NEG_INFINITY; levels * 3 * pw];
    let mut lb = vec![f64::INFINITY; levels * 3 * pw];
    let mut mu = vec![0.0f64; nm * cols];
    let mut mb = vec![0.0f64; nm * cols];
    let mut colsum = vec![0.0f64; eps_max * cols];
    let slot = |e: usize, r: usize| (e * 3 + r % 3) * pw;
    for t in r_lo..r_hi + eps_max {
        // level 0: the input row t (missing past r_hi)
        let k = slot(0, t);
        if t < r_hi {
            let src = &z[t * cols..(t + 1) * cols];
            let m = (t % nm) * cols;
            for (c, &x) in src.iter().enumerate() {
                let ok = !x.is_nan();
                let v = if ok { x / z_scale } else { 0.0 };
                lu[k + 1 + c] = if ok { v } else { f64::NEG_INFINITY };
                lb[k + 1 + c] = if ok { v } else { f64::INFINITY };
                mu[m + c] = if ok { 0.0 } else { f64::NEG_INFINITY };
                mb[m + c] = if ok { 0.0 } else { f64::INFINITY };
            }
        } else {
            lu[k..k + pw].fill(f64::NEG_INFINITY);
            lb[k..k + pw].fill(f64::INFINITY);
        }
        for e in 1..=eps_max {
            if t < r_lo + e {
                break;
            }
            let r = t - e;
            let k = slot(e, r);
            if r >= r_hi {
                lu[k..k + pw].fill(f64::NEG_INFINITY);
                lb[k..k + pw].fill(f64::INFINITY);
                continue;
            }
            // rows r - 1, r, r + 1 of level e - 1 ((r + 2) % 3 = (r - 1) % 3)
            let (ku, kc, kd) = (slot(e - 1, r + 2), slot(e - 1, r), slot(e - 1, r + 1));
            let (prev_u, cur_u) = lu.split_at_mut(e * 3 * pw);
            let (prev_b, cur_b) = lb.split_at_mut(e * 3 * pw);
            let up_missing = r == r_lo;
            let m = (r % nm) * cols;
            let in_sum = (s0..s1).contains(&r);
            let cs = &mut colsum[(e - 1) * cols..e * cols];
            let kk = k - e * 3 * pw;
            // a missing row above: the upper row is the frame value
            let frame;
            let (up_u, up_b): (&[f64], &[f64]) = if up_missing {
                frame = (vec![f64::NEG_INFINITY; pw], vec![f64::INFINITY; pw]);
                (&frame.0, &frame.1)
            } else {
                (&prev_u[ku..ku + pw], &prev_b[ku..ku + pw])
            };
            step_row(
                up_u,
                &prev_u[kc..kc + pw],
                &prev_u[kd..kd + pw],
                up_b,
                &prev_b[kc..kc + pw],
                &prev_b[kd..kd + pw],
                &mu[m..m + cols],
                &mb[m..m + cols],
                &mut cur_u[kk..kk + pw],
                &mut cur_b[kk..kk + pw],
                in_sum.then_some(cs),
            );
        }
    }
    colsum.chunks(cols).map(|c| c.iter().sum::<f64>()).collect()
}

/// Image-wide blanket areas `A(e)` for `e = 1 ..= eps_max` and the number of
/// valid pixels. Bands of 256 rows grow their own blankets with a halo of
/// `eps_max` rows (a wrong value at a band's cut spreads one row per step,
/// so it never reaches the band's own rows) and are summed in a fixed order:
/// the result does not depend on the thread count.
pub fn blanket_areas(
    z: &[f64],
    rows: usize,
    cols: usize,
    eps_max: usize,
    z_scale: f64,
) -> CoreResult<(Vec<f64>, usize)> {
    if rows * cols == 0 || z.len() != rows * cols {
        return Err(CoreError::invalid("data", "image is empty"));
    }
    if eps_max == 0 {
        return Err(CoreError::invalid("epsilons", "expected positive integers"));
    }
    positive_finite(z_scale, "z_scale")?;
    let band = 256usize;
    let parts: Vec<(Vec<f64>, usize)> = (0..rows.div_ceil(band))
        .into_par_iter()
        .map(|bi| {
            let (o0, o1) = (bi * band, ((bi + 1) * band).min(rows));
            let (i0, i1) = (o0.saturating_sub(eps_max), (o1 + eps_max).min(rows));
            let n = z[o0 * cols..o1 * cols]
                .iter()
                .filter(|v| !v.is_nan())
                .count();
            let sums = stream_sums(z, cols, i0, i1, o0, o1, eps_max, z_scale);
            (sums, n)
        })
        .collect();
    let (sums, n) = super::sum_parts(parts, eps_max)?;
    let areas = sums
        .iter()
        .enumerate()
        .map(|(e, s)| s / (2.0 * (e + 1) as f64))
        .collect();
    Ok((areas, n))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Blanket areas from the definition, with explicit bounds checks.
    pub(crate) fn naive(z: &[f64], rows: usize, cols: usize, emax: usize) -> Vec<f64> {
        let mut u = z.to_vec();
        let mut b = z.to_vec();
        let mut out = vec![];
        for e in 1..=emax {
            let (mut nu, mut nb) = (u.clone(), b.clone());
            let mut s = 0.0;
            for r in 0..rows {
                for c in 0..cols {
                    let k = r * cols + c;
                    if z[k].is_nan() {
                        continue;
                    }
                    let (mut a, mut m) = (u[k] + 1.0, b[k] - 1.0);
                    for (dr, dc) in [(-1isize, 0isize), (1, 0), (0, -1), (0, 1)] {
                        let (rr, cc) = (r as isize + dr, c as isize + dc);
                        if rr >= 0 && cc >= 0 && (rr as usize) < rows && (cc as usize) < cols {
                            let q = rr as usize * cols + cc as usize;
                            if !z[q].is_nan() {
                                a = a.max(u[q]);
                                m = m.min(b[q]);
                            }
                        }
                    }
                    nu[k] = a;
                    nb[k] = m;
                    s += a - m;
                }
            }
            u = nu;
            b = nb;
            out.push(s / (2.0 * e as f64));
        }
        out
    }

    pub(crate) fn image(rows: usize, cols: usize) -> Vec<f64> {
        let u = crate::testdata::uniform(rows * cols, 17);
        (0..rows * cols)
            .map(|k| {
                if k % 19 == 4 {
                    f64::NAN
                } else {
                    (u[k] * 9.0).floor() + (k % cols) as f64 * 0.2
                }
            })
            .collect()
    }

    #[test]
    fn areas_match_definition_across_bands() {
        let (rows, cols) = (300usize, 23usize);
        let z = image(rows, cols);
        let (a, n) = blanket_areas(&z, rows, cols, 6, 1.0).unwrap();
        assert_eq!(n, z.iter().filter(|v| !v.is_nan()).count());
        for (x, y) in a.iter().zip(naive(&z, rows, cols, 6)) {
            assert!((x - y).abs() <= 1e-12 * y.abs(), "{x} vs {y}");
        }
    }
}
