//! Peleg's covering blanket (Peleg, Naor, Hartley and Avnir 1984): the
//! image-wide areas of the `blanket` estimator and the moving-window map.
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
//! the same thing as a band of missing pixels. Both kernels run the same
//! growth step on planes framed by one missing pixel, so they give the same
//! blankets bit for bit.
//!
//! The map shares work between windows: a pixel whose L1 ball of radius `e`
//! lies inside the window has the same `u_e`, `b_e` as in the whole image
//! (every walk of `e` steps from it stays in the window), so the blankets
//! are grown once over a tile of the image and summed over the window's
//! interior shrunk by `e` from summed-area tables; only the frame of pixels
//! closer than `e` to the window's border is grown per window, starting at
//! step `e` from the image-wide values of the two rings at depth `e - 1` and
//! `e`. The cost per pixel is `O(w e_max^2)`: it still grows with the window,
//! linearly instead of as `w^2`.
//!
use super::driver::{Grid, LogFit, MapOut};
use super::sat::{band_rows, rect, sat};
use crate::checks::positive_finite;
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

/// Larger of two non-NaN values (the planes hold finite values and
/// infinities only); compiles to one vector max.
#[inline(always)]
fn fmax(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

#[inline(always)]
fn fmin(a: f64, b: f64) -> f64 {
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
fn step_row(
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

/// Planes of `(rows + 2) x (cols + 2)` samples framed by one missing pixel:
/// upper and lower blankets (missing: `-inf`, `+inf`), their next step, and
/// the masks added after each step (0 on valid pixels, `-inf` / `+inf` on
/// missing ones, so that missing pixels stay missing without a branch).
struct Planes {
    rows: usize,
    cols: usize,
    u: Vec<f64>,
    b: Vec<f64>,
    nu: Vec<f64>,
    nb: Vec<f64>,
    mu: Vec<f64>,
    mb: Vec<f64>,
    colsum: Vec<f64>,
}

impl Planes {
    fn new(rows: usize, cols: usize) -> Self {
        let n = (rows + 2) * (cols + 2);
        Planes {
            rows,
            cols,
            u: vec![f64::NEG_INFINITY; n],
            b: vec![f64::INFINITY; n],
            nu: vec![f64::NEG_INFINITY; n],
            nb: vec![f64::INFINITY; n],
            mu: vec![f64::NEG_INFINITY; n],
            mb: vec![f64::INFINITY; n],
            colsum: vec![0.0; cols],
        }
    }

    /// Load row `r` (`cols` values, NaN: missing) divided by `z_scale`;
    /// returns its number of valid pixels.
    #[inline]
    fn load_row(&mut self, r: usize, src: &[f64], z_scale: f64) -> usize {
        let k0 = (r + 1) * (self.cols + 2) + 1;
        let mut n = 0;
        for (c, &x) in src.iter().enumerate() {
            let k = k0 + c;
            if x.is_nan() {
                self.u[k] = f64::NEG_INFINITY;
                self.b[k] = f64::INFINITY;
                self.mu[k] = f64::NEG_INFINITY;
                self.mb[k] = f64::INFINITY;
            } else {
                let v = x / z_scale;
                self.u[k] = v;
                self.b[k] = v;
                self.mu[k] = 0.0;
                self.mb[k] = 0.0;
                n += 1;
            }
        }
        n
    }

    /// One growth step; returns `sum over valid pixels of (u - b)` for the
    /// rows `[s0, s1)` (plane rows without the frame).
    fn grow(&mut self, s0: usize, s1: usize) -> f64 {
        let pw = self.cols + 2;
        let n = self.cols;
        self.colsum.fill(0.0);
        for r in 1..=self.rows {
            let k = r * pw;
            let (u, b) = (&self.u, &self.b);
            let in_sum = (s0 + 1..=s1).contains(&r);
            step_row(
                &u[k - pw..k],
                &u[k..k + pw],
                &u[k + pw..k + 2 * pw],
                &b[k - pw..k],
                &b[k..k + pw],
                &b[k + pw..k + 2 * pw],
                &self.mu[k + 1..k + 1 + n],
                &self.mb[k + 1..k + 1 + n],
                &mut self.nu[k..k + pw],
                &mut self.nb[k..k + pw],
                in_sum.then_some(&mut self.colsum[..]),
            );
        }
        std::mem::swap(&mut self.u, &mut self.nu);
        std::mem::swap(&mut self.b, &mut self.nb);
        self.colsum.iter().sum()
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
            if up_missing {
                // a missing row above: the upper row is the frame value
                let fu = vec![f64::NEG_INFINITY; pw];
                let fb = vec![f64::INFINITY; pw];
                step_row(
                    &fu,
                    &prev_u[kc..kc + pw],
                    &prev_u[kd..kd + pw],
                    &fb,
                    &prev_b[kc..kc + pw],
                    &prev_b[kd..kd + pw],
                    &mu[m..m + cols],
                    &mb[m..m + cols],
                    &mut cur_u[kk..kk + pw],
                    &mut cur_b[kk..kk + pw],
                    in_sum.then_some(cs),
                );
            } else {
                step_row(
                    &prev_u[ku..ku + pw],
                    &prev_u[kc..kc + pw],
                    &prev_u[kd..kd + pw],
                    &prev_b[ku..ku + pw],
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
    let mut sums = vec![0.0f64; eps_max];
    let mut n = 0;
    for (s, c) in parts {
        for (a, b) in sums.iter_mut().zip(s) {
            *a += b;
        }
        n += c;
    }
    if n == 0 {
        return Err(CoreError::invalid("data", "no valid value (all NaN)"));
    }
    let areas = sums
        .iter()
        .enumerate()
        .map(|(e, s)| s / (2.0 * (e + 1) as f64))
        .collect();
    Ok((areas, n))
}

/// Blankets grown over a region of the NaN-padded image (rows `ri0 ..`,
/// columns `ci0 ..`), kept for every step: where a window's blanket does not
/// feel the window's border it equals these.
struct Grown {
    nc: usize,
    /// `u_e`, `b_e` for `e = 0 .. e_max - 1`, framed planes.
    u: Vec<Vec<f64>>,
    b: Vec<Vec<f64>>,
    /// Masks (0 valid, -inf / +inf missing), framed.
    mu: Vec<f64>,
    mb: Vec<f64>,
    /// Summed-area tables of valid `u_e - b_e`, `e = 1 ..= e_max`, and of validity.
    sats: Vec<Vec<f64>>,
    valid: Vec<f64>,
}

impl Grown {
    #[allow(clippy::too_many_arguments)]
    fn new(
        z: &[f64],
        rows: usize,
        cols: usize,
        ri0: isize,
        ci0: isize,
        nr: usize,
        nc: usize,
        emax: usize,
        z_scale: f64,
    ) -> Self {
        let mut p = Planes::new(nr, nc);
        let mut buf = vec![f64::NAN; nc];
        let c0 = ci0.max(0) as usize;
        let c1 = ((ci0 + nc as isize).max(0) as usize).min(cols);
        let off = (c0 as isize - ci0) as usize;
        for u in 0..nr {
            let r = ri0 + u as isize;
            if r < 0 || r >= rows as isize || c1 <= c0 {
                continue; // missing already
            }
            buf[off..off + c1 - c0]
                .copy_from_slice(&z[r as usize * cols + c0..r as usize * cols + c1]);
            p.load_row(u, &buf, z_scale);
        }
        let pw = nc + 2;
        // interior samples of a framed plane (row-major nr x nc) through f(index)
        let inner = |f: &dyn Fn(usize) -> f64| -> Vec<f64> {
            let mut out = Vec::with_capacity(nr * nc);
            for r in 0..nr {
                let k0 = (r + 1) * pw + 1;
                out.extend((k0..k0 + nc).map(f));
            }
            out
        };
        let valid = inner(&|i| (p.mu[i] == 0.0) as u8 as f64);
        let valid = sat(&valid, nr, nc);
        let mut u = vec![p.u.clone()];
        let mut b = vec![p.b.clone()];
        let mut sats = Vec::with_capacity(emax);
        for e in 1..=emax {
            p.grow(0, 0);
            let d = inner(&|i| fmax(p.u[i] - p.b[i], 0.0));
            sats.push(sat(&d, nr, nc));
            if e < emax {
                u.push(p.u.clone());
                b.push(p.b.clone());
            }
        }
        Grown {
            nc,
            u,
            b,
            mu: p.mu,
            mb: p.mb,
            sats,
            valid,
        }
    }
}

/// The blankets of one window: only the frame of pixels that feel the
/// window's border is grown here; the rest comes from [`Grown`].
struct Window {
    w: usize,
    lu: Vec<f64>,
    lb: Vec<f64>,
    lnu: Vec<f64>,
    lnb: Vec<f64>,
    cs: Vec<f64>,
}

impl Window {
    /// Copy the ring of pixels at depth `d` (distance to the window's
    /// border) from step `e` of `g`, for the window at `(u0, v0)`.
    fn load_ring(&mut self, g: &Grown, e: usize, d: usize, u0: usize, v0: usize) {
        let w = self.w;
        if 2 * d > w - 1 {
            return;
        }
        let (lpw, pw) = (w + 2, g.nc + 2);
        let (gu, gb) = (&g.u[e], &g.b[e]);
        let last = w - 1 - d;
        for a in d..=last {
            let li = (a + 1) * lpw + 1;
            let gi = (u0 + a + 1) * pw + v0 + 1;
            if a == d || a == last {
                self.lu[li + d..=li + last].copy_from_slice(&gu[gi + d..=gi + last]);
                self.lb[li + d..=li + last].copy_from_slice(&gb[gi + d..=gi + last]);
            } else {
                for c in [d, last] {
                    self.lu[li + c] = gu[gi + c];
                    self.lb[li + c] = gb[gi + c];
                }
            }
        }
    }

    /// Segments `[c0, c1)` of row `a` closer than `e` to the window's border.
    fn segments(w: usize, e: usize, a: usize) -> [(usize, usize); 2] {
        if a < e || a + e >= w || 2 * e >= w {
            [(0, w), (w, w)]
        } else {
            [(0, e), (w - e, w)]
        }
    }

    /// `A(e)`, `e = 1 ..= areas.len()`, of the window at `(u0, v0)`.
    fn areas(&mut self, g: &Grown, u0: usize, v0: usize, areas: &mut [f64]) {
        let w = self.w;
        let (lpw, pw) = (w + 2, g.nc + 2);
        for (e0, area) in areas.iter_mut().enumerate() {
            let e = e0 + 1;
            // step e - 1 at depths e - 1 and e equals the image-wide growth
            self.load_ring(g, e0, e - 1, u0, v0);
            self.load_ring(g, e0, e, u0, v0);
            self.cs.fill(0.0);
            for a in 0..w {
                for (c0, c1) in Self::segments(w, e, a) {
                    if c1 <= c0 {
                        continue;
                    }
                    let n = c1 - c0;
                    let gi = (u0 + a + 1) * pw + v0 + 1 + c0;
                    step_row(
                        &self.lu[a * lpw + c0..a * lpw + c1 + 2],
                        &self.lu[(a + 1) * lpw + c0..(a + 1) * lpw + c1 + 2],
                        &self.lu[(a + 2) * lpw + c0..(a + 2) * lpw + c1 + 2],
                        &self.lb[a * lpw + c0..a * lpw + c1 + 2],
                        &self.lb[(a + 1) * lpw + c0..(a + 1) * lpw + c1 + 2],
                        &self.lb[(a + 2) * lpw + c0..(a + 2) * lpw + c1 + 2],
                        &g.mu[gi..gi + n],
                        &g.mb[gi..gi + n],
                        &mut self.lnu[(a + 1) * lpw + c0..(a + 1) * lpw + c1 + 2],
                        &mut self.lnb[(a + 1) * lpw + c0..(a + 1) * lpw + c1 + 2],
                        Some(&mut self.cs[c0..c1]),
                    );
                }
            }
            for a in 0..w {
                for (c0, c1) in Self::segments(w, e, a) {
                    let k = (a + 1) * lpw + 1;
                    self.lu[k + c0..k + c1].copy_from_slice(&self.lnu[k + c0..k + c1]);
                    self.lb[k + c0..k + c1].copy_from_slice(&self.lnb[k + c0..k + c1]);
                }
            }
            let mut total: f64 = self.cs.iter().sum();
            if w > 2 * e {
                total += rect(
                    &g.sats[e0],
                    g.nc + 1,
                    u0 + e,
                    u0 + w - e,
                    v0 + e,
                    v0 + w - e,
                );
            }
            *area = total / (2.0 * e as f64);
        }
    }
}

/// Options of [`blanket_transform`].
#[derive(Debug, Clone)]
pub struct BlanketMapOptions {
    pub window: usize,
    /// Blanket thicknesses of the fit, at least three distinct positive values.
    pub epsilons: Vec<usize>,
    pub z_scale: f64,
    pub min_valid: f64,
    pub step: usize,
}

/// Local blanket dimension and r² maps on the grid of every `step`-th pixel
/// (NaN where the window has fewer valid pixels than `min_valid * w * w`).
/// Bands of output rows in parallel, tiles of columns in order, so the
/// result does not depend on the thread count.
pub fn blanket_transform(
    z: &[f64],
    rows: usize,
    cols: usize,
    opt: &BlanketMapOptions,
) -> CoreResult<MapOut> {
    let w = opt.window;
    let grid = Grid::new(z.len(), rows, cols, w, opt.min_valid, opt.step)?;
    let (min_pixels, ocols) = (grid.min_pixels, grid.ocols);
    let mut eps = opt.epsilons.clone();
    eps.sort_unstable();
    eps.dedup();
    if eps.len() < 3 || eps[0] == 0 {
        return Err(CoreError::invalid(
            "epsilons",
            format!(
                "need at least 3 distinct positive thicknesses, got {:?}",
                opt.epsilons
            ),
        ));
    }
    positive_finite(opt.z_scale, "z_scale")?;
    let emax = *eps.last().unwrap();
    let fit = LogFit::new(&eps, |slope| 2.0 - slope);
    let (h, step) = (grid.h, grid.step);
    grid.drive_pair(|_: &mut (), band, outs| {
        let (k0, k1) = (band.g0, band.g1);
        let ri0 = (k0 * step) as isize - h as isize;
        let nr = (k1 - 1 - k0) * step + 2 * h + 1;
        let tq = (band_rows(w) / step).max(1); // output columns per tile
        let lpw = w + 2;
        let mut win = Window {
            w,
            lu: vec![f64::NEG_INFINITY; lpw * lpw],
            lb: vec![f64::INFINITY; lpw * lpw],
            lnu: vec![f64::NEG_INFINITY; lpw * lpw],
            lnb: vec![f64::INFINITY; lpw * lpw],
            cs: vec![0.0; w],
        };
        let mut areas = vec![0.0f64; emax];
        let mut ys = vec![0.0f64; eps.len()];
        for q0 in (0..ocols).step_by(tq) {
            let q1 = (q0 + tq).min(ocols);
            let ci0 = (q0 * step) as isize - h as isize;
            let nc = (q1 - 1 - q0) * step + 2 * h + 1;
            let g = Grown::new(z, rows, cols, ri0, ci0, nr, nc, emax, opt.z_scale);
            for k in k0..k1 {
                let u0 = (k - k0) * step;
                for kc in q0..q1 {
                    let v0 = (kc - q0) * step;
                    if rect(&g.valid, nc + 1, u0, u0 + w, v0, v0 + w) < min_pixels {
                        continue;
                    }
                    win.areas(&g, u0, v0, &mut areas);
                    for (y, &e) in ys.iter_mut().zip(&eps) {
                        *y = areas[e - 1].ln();
                    }
                    fit.write(&ys, outs, (k - k0) * ocols + kc);
                }
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transform::sat::{line_fit, log_axis};

    /// Blanket areas from the definition, with explicit bounds checks.
    fn naive(z: &[f64], rows: usize, cols: usize, emax: usize) -> Vec<f64> {
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

    fn image(rows: usize, cols: usize) -> Vec<f64> {
        let mut s = 17u64;
        (0..rows * cols)
            .map(|k| {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(3);
                if k % 19 == 4 {
                    f64::NAN
                } else {
                    ((s >> 40) % 9) as f64 + (k % cols) as f64 * 0.2
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

    #[test]
    fn map_equals_areas_of_each_window() {
        // several bands and column tiles; thicknesses up to the half window
        for (rows, cols, w, eps, step) in [
            (20usize, 17usize, 7usize, vec![1usize, 2, 3, 4], 2usize),
            (150, 140, 11, vec![1, 2, 3, 5], 1),
            (90, 100, 9, vec![2, 3, 6], 3),
        ] {
            let z = image(rows, cols);
            let o = BlanketMapOptions {
                window: w,
                epsilons: eps.clone(),
                z_scale: 1.3,
                min_valid: 0.0,
                step,
            };
            let m = blanket_transform(&z, rows, cols, &o).unwrap();
            let emax = *eps.last().unwrap();
            let h = (w / 2) as isize;
            for k in (0..m.rows).step_by(3) {
                for kc in 0..m.cols {
                    let (i, j) = ((k * step) as isize, (kc * step) as isize);
                    let mut win = vec![f64::NAN; w * w];
                    for a in 0..w as isize {
                        for b in 0..w as isize {
                            let (r, c) = (i - h + a, j - h + b);
                            if r >= 0 && c >= 0 && r < rows as isize && c < cols as isize {
                                win[(a * w as isize + b) as usize] =
                                    z[r as usize * cols + c as usize] / 1.3;
                            }
                        }
                    }
                    let all = naive(&win, w, w, emax);
                    let ys: Vec<f64> = eps.iter().map(|&e| all[e - 1].ln()).collect();
                    let (xs, xm, sxx) = log_axis(&eps);
                    let e = 2.0 - line_fit(&xs, xm, sxx, &ys).0;
                    let d = m.d[k * m.cols + kc] as f64;
                    assert!((d - e).abs() < 1e-5, "w={w} ({k},{kc}) {d} vs {e}");
                }
            }
        }
    }
}
