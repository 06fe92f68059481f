//! Moving-window differential box counting (Sarkar and Chaudhuri 1994).
//!
//! The window is the `w x w` square centred on the output pixel, clipped to
//! the image (the image read as padded with NaN). Inside it, for box size
//! `s`, the lattice of `s x s` blocks is anchored at the window's top-left
//! corner; the last row and column of blocks hold `t = w mod s` rows or
//! columns when `s` does not divide `w`. A block whose valid values span
//! `[zmin, zmax]` needs
//!
//! ```text
//! n = floor((zmax - z0) / h) - floor((zmin - z0) / h) + 1,   h = s * z_unit
//! ```
//!
//! boxes (0 when it holds no valid value; with `partial_blocks = false` the
//! partial blocks are left out), `N(s)` is the window's sum and
//! `D = -slope` of `log N(s)` against `log s`. The box stacks start at a fixed
//! height `z0` and have a fixed unit `z_unit` for every window (not the
//! window's own range), so a block's count does not depend on the window.
//!
//! Work shared between windows: for every block shape (`s x s`, and `t x s`,
//! `s x t`, `t x t` for the partial blocks) the count of the block at every
//! top-left position comes from sliding minima and maxima (van Herk/Gil-Werman,
//! O(1) per pixel); a window's `N(s)` is then a sum over a lattice of stride
//! `s`, read from a summed-area table strided by `s` (one table holds every
//! grid offset). The cost per pixel does not grow with the window.
use super::driver::{scale_list, Grid, LogFit, MapOut};
use super::sat::{band_rows, rect, sat};
use super::sliding::rect_minmax;
use crate::checks::{finite, positive_finite};
use crate::error::CoreResult;
use crate::sample::Sample;

/// Options of [`dbc_transform`].
#[derive(Debug, Clone)]
pub struct DbcMapOptions {
    pub window: usize,
    /// Block sides in pixels, at least three distinct values in `[1, window]`.
    pub box_sizes: Vec<usize>,
    /// Box height per pixel of block side, in data units (`h = s * z_unit`).
    pub z_unit: f64,
    /// Reference height of the box stacks, in data units.
    pub z0: f64,
    /// Fewest valid pixels in a window, as a fraction of `w * w`.
    pub min_valid: f64,
    /// Output every `step`-th row and column (1: every pixel).
    pub step: usize,
    /// Count the partial blocks of the last row and column (`false`: drop
    /// them, so box size `s` covers the top-left `floor(w/s) s` square).
    pub partial_blocks: bool,
}

/// Strided-table read that is 0 above or left of the plane.
#[inline]
fn at(t: &[f64], width: usize, u: isize, v: isize) -> f64 {
    if u < 0 || v < 0 {
        0.0
    } else {
        t[u as usize * width + v as usize]
    }
}

/// Box counts of every `bh x bw` block of the `rows x cols` band planes, by
/// top-left sample.
fn count_field(
    lo: &[f64],
    hi: &[f64],
    (rows, cols): (usize, usize),
    (bh, bw): (usize, usize),
    z0: f64,
    h: f64,
) -> Vec<f64> {
    let (mut a, b) = rect_minmax(lo, hi, rows, cols, bh, bw);
    for (x, &y) in a.iter_mut().zip(&b) {
        *x = if y == f64::NEG_INFINITY {
            0.0
        } else {
            ((y - z0) / h).floor() - ((*x - z0) / h).floor() + 1.0
        };
    }
    a
}

/// Local DBC dimension and r² maps (NaN where the window has fewer valid
/// pixels than `min_valid * w * w`).
pub fn dbc_transform<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    opt: &DbcMapOptions,
) -> CoreResult<MapOut> {
    let (z_unit, z0) = (
        positive_finite(opt.z_unit, "z_scale")?,
        finite(opt.z0, "z0")?,
    );
    let grid = Grid::new(z.len(), rows, cols, opt.window, opt.min_valid, opt.step)?;
    let (w, min_pixels, ocols) = (grid.w, grid.min_pixels, grid.ocols);
    // [2, w], as the Python layer and the whole-image counter: a 1-pixel
    // block spans no height range (it always holds one box)
    let in_range = |s| (2..=w).contains(&s);
    let sizes = scale_list(
        &opt.box_sizes,
        "box_sizes",
        3,
        &format!("block sides in [2, {w}]"),
        in_range,
    )?;
    let (h, step) = (grid.h, grid.step);
    let fit = LogFit::new(&sizes, |slope| -slope);
    grid.drive_pair(|_: &mut (), band, outs| {
        let (k0, k1) = (band.g0, band.g1);
        // tiles of output columns, in order (results do not depend on
        // threads): planes of rows ri0 .. ri0 + nr and columns
        // ci0 .. ci0 + nc of the NaN-padded image, small enough to stay
        // in cache
        let ri0 = (k0 * step) as isize - h as isize;
        let nr = (k1 - 1 - k0) * step + 2 * h + 1;
        let tq = (band_rows(w) / step).max(1); // output columns per tile
        for q0 in (0..ocols).step_by(tq) {
            let q1 = (q0 + tq).min(ocols);
            let nq = q1 - q0;
            let ci0 = (q0 * step) as isize - h as isize;
            let nc = (q1 - 1 - q0) * step + 2 * h + 1;
            let mut lo = vec![f64::INFINITY; nr * nc];
            let mut hi = vec![f64::NEG_INFINITY; nr * nc];
            let mut valid = vec![0.0f64; nr * nc];
            // image columns c0 .. c1 of the tile
            let c0 = ci0.max(0) as usize;
            let c1 = ((ci0 + nc as isize) as usize).min(cols);
            for u in 0..nr {
                let r = ri0 + u as isize;
                if r < 0 || r >= rows as isize {
                    continue;
                }
                let src = &z[r as usize * cols + c0..r as usize * cols + c1];
                let base = u * nc + (c0 as isize - ci0) as usize;
                for (c, &x) in src.iter().enumerate() {
                    let x = x.to_f64();
                    if !x.is_nan() {
                        lo[base + c] = x;
                        hi[base + c] = x;
                        valid[base + c] = 1.0;
                    }
                }
            }
            let vsat = sat(&valid, nr, nc);
            drop(valid);
            let npix = (k1 - k0) * nq;
            let mut counts = vec![vec![0.0f64; npix]; sizes.len()];
            for (si, &s) in sizes.iter().enumerate() {
                let hgt = s as f64 * z_unit;
                let nf = w / s;
                let t = w % s;
                let si_ = s as isize;
                let last = ((nf - 1) * s) as isize;
                // full blocks: table strided by s
                let wss = nc - s + 1;
                let mut tss = count_field(&lo, &hi, (nr, nc), (s, s), z0, hgt);
                let nss = nr - s + 1;
                for row in tss.chunks_mut(wss) {
                    for v in s..wss {
                        row[v] += row[v - s];
                    }
                }
                for u in s..nss {
                    let (done, cur) = tss.split_at_mut(u * wss);
                    let prev = &done[(u - s) * wss..(u - s + 1) * wss];
                    for (x, &y) in cur[..wss].iter_mut().zip(prev) {
                        *x += y;
                    }
                }
                // partial blocks: bottom row (t x s), right column (s x t), corner (t x t)
                let partial = (t > 0 && opt.partial_blocks).then(|| {
                    let mut pts = count_field(&lo, &hi, (nr, nc), (t, s), z0, hgt);
                    for u in 0..nr - t + 1 {
                        for v in s..wss {
                            pts[u * wss + v] += pts[u * wss + v - s];
                        }
                    }
                    let wst = nc - t + 1;
                    let mut pst = count_field(&lo, &hi, (nr, nc), (s, t), z0, hgt);
                    for u in s..nr - s + 1 {
                        for v in 0..wst {
                            pst[u * wst + v] += pst[(u - s) * wst + v];
                        }
                    }
                    let ptt = count_field(&lo, &hi, (nr, nc), (t, t), z0, hgt);
                    (pts, pst, ptt, wst)
                });
                let out = &mut counts[si];
                for k in k0..k1 {
                    let u0 = ((k - k0) * step) as isize;
                    for kc in 0..nq {
                        let v0 = (kc * step) as isize;
                        let (a, b) = (u0 + last, v0 + last);
                        let mut n = at(&tss, wss, a, b)
                            - at(&tss, wss, u0 - si_, b)
                            - at(&tss, wss, a, v0 - si_)
                            + at(&tss, wss, u0 - si_, v0 - si_);
                        if let Some((pts, pst, ptt, wst)) = &partial {
                            let (ue, ve) = (u0 + (nf * s) as isize, v0 + (nf * s) as isize);
                            n += at(pts, wss, ue, b) - at(pts, wss, ue, v0 - si_);
                            n += at(pst, *wst, a, ve) - at(pst, *wst, u0 - si_, ve);
                            n += at(ptt, *wst, ue, ve);
                        }
                        out[(k - k0) * nq + kc] = n;
                    }
                }
            }
            let mut ys = vec![0.0f64; sizes.len()];
            let sw = nc + 1;
            for k in k0..k1 {
                let u0 = (k - k0) * step;
                for kc in 0..nq {
                    let v0 = kc * step;
                    if rect(&vsat, sw, u0, u0 + w, v0, v0 + w) < min_pixels {
                        continue;
                    }
                    let p = (k - k0) * nq + kc;
                    for (y, c) in ys.iter_mut().zip(&counts) {
                        *y = c[p].ln();
                    }
                    fit.write(&ys, outs, (k - k0) * ocols + q0 + kc);
                }
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dimension::dbc::dbc_count;
    use crate::transform::sat::{line_fit, log_axis};

    fn image(rows: usize, cols: usize, seed: u64) -> Vec<f64> {
        let mut acc = 0.0;
        crate::testdata::uniform(rows * cols, seed)
            .into_iter()
            .enumerate()
            .map(|(k, u)| {
                acc += (u - 0.5) * 3.0;
                if k % 23 == 5 {
                    f64::NAN
                } else {
                    acc + (k / cols) as f64 * 0.3
                }
            })
            .collect()
    }

    /// The global counter on the NaN-padded window, same z0 and unit.
    fn direct(z: &[f64], rows: usize, cols: usize, i: usize, j: usize, o: &DbcMapOptions) -> f64 {
        let (w, h) = (o.window, o.window / 2);
        let mut win = vec![f64::NAN; w * w];
        for a in 0..w {
            for b in 0..w {
                let (r, c) = (
                    i as isize + a as isize - h as isize,
                    j as isize + b as isize - h as isize,
                );
                if r >= 0 && c >= 0 && (r as usize) < rows && (c as usize) < cols {
                    win[a * w + b] = z[r as usize * cols + c as usize];
                }
            }
        }
        let r = dbc_count(&win, w, w, &o.box_sizes, 1, o.z0, o.z_unit).unwrap();
        let ys: Vec<f64> = r.counts.iter().map(|c| c[0].ln()).collect();
        let (xs, xm, sxx) = log_axis(&r.box_sizes);
        -line_fit(&xs, xm, sxx, &ys).0
    }

    #[test]
    fn equals_global_counter_on_every_window() {
        // several bands and column tiles (64 output columns per tile)
        let (rows, cols) = (70usize, 150usize);
        let z = image(rows, cols, 4);
        for (w, sizes, step) in [
            (9usize, vec![2usize, 3, 4], 1usize),
            (11, vec![2, 3, 5, 11], 1),
            (15, vec![2, 4, 8], 3),
        ] {
            let o = DbcMapOptions {
                window: w,
                box_sizes: sizes,
                z_unit: 0.7,
                z0: -1.5,
                min_valid: 0.0,
                step,
                partial_blocks: true,
            };
            let m = dbc_transform(&z, rows, cols, &o).unwrap();
            assert_eq!((m.rows, m.cols), (rows.div_ceil(step), cols.div_ceil(step)));
            for k in 0..m.rows {
                for kc in 0..m.cols {
                    let e = direct(&z, rows, cols, k * step, kc * step, &o);
                    let d = m.d[k * m.cols + kc] as f64;
                    assert!((d - e).abs() < 1e-5, "w={w} ({k},{kc}) {d} vs {e}");
                }
            }
        }
    }

    #[test]
    fn threads_agree_and_bad_options_fail() {
        let (rows, cols) = (150usize, 70usize);
        let z = image(rows, cols, 8);
        let o = DbcMapOptions {
            window: 13,
            box_sizes: vec![2, 3, 4, 6],
            z_unit: 0.5,
            z0: 0.0,
            min_valid: 0.5,
            step: 1,
            partial_blocks: false,
        };
        let run = |t| {
            let m = crate::parallel::run_in_pool(Some(t), || dbc_transform(&z, rows, cols, &o))
                .unwrap();
            m.d.iter()
                .zip(&m.r2)
                .map(|(a, b)| (a.to_bits(), b.to_bits()))
                .collect::<Vec<_>>()
        };
        assert!(run(1) == run(3));
        for bad in [
            DbcMapOptions {
                box_sizes: vec![2, 4],
                ..o.clone()
            },
            DbcMapOptions {
                box_sizes: vec![2, 4, 14],
                ..o.clone()
            },
            DbcMapOptions {
                box_sizes: vec![1, 2, 4],
                ..o.clone()
            },
            DbcMapOptions {
                z_unit: 0.0,
                ..o.clone()
            },
            DbcMapOptions {
                step: 0,
                ..o.clone()
            },
        ] {
            assert!(dbc_transform(&z, rows, cols, &bad).is_err());
        }
    }
}
