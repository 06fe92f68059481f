//! Peleg's covering blanket (Peleg, Naor, Hartley and Avnir 1984): the
//! moving-window map. The growth step and the image-wide estimator are in
//! `crate::dimension::blanket`.
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
use super::driver::{scale_list, Grid, LogFit, MapOut};
use super::sat::{band_rows, rect, sat};
use crate::checks::positive_finite;
use crate::dimension::blanket::{fmax, step_row};
use crate::error::CoreResult;
use crate::sample::Sample;

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
    fn new<T: Sample>(
        z: &[T],
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
            let src = &z[r as usize * cols + c0..r as usize * cols + c1];
            for (d, &x) in buf[off..off + c1 - c0].iter_mut().zip(src) {
                *d = x.to_f64();
            }
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
pub fn blanket_transform<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    opt: &BlanketMapOptions,
) -> CoreResult<MapOut> {
    positive_finite(opt.z_scale, "z_scale")?;
    let grid = Grid::new(z.len(), rows, cols, opt.window, opt.min_valid, opt.step)?;
    let eps = scale_list(&opt.epsilons, "epsilons", 3, "positive thicknesses", |e| {
        e > 0
    })?;
    let (w, min_pixels, ocols) = (grid.w, grid.min_pixels, grid.ocols);
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
    use crate::dimension::blanket::tests::{image, naive};
    use crate::transform::sat::{line_fit, log_axis};

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
