//! The moving-window driver every map kernel runs on: the argument checks of
//! a map (image, window, `min_valid`, `step`), the output grid of every
//! `step`-th pixel, its split into bands of output rows with the input rows
//! (halo) their windows touch, the valid-count gate, the log-log line fit
//! and the write of `D` and r², and one result type ([`MapOut`]).
//!
//! A kernel supplies the per-band work only (tables of its statistic over
//! the band's input rows, then one value per window). The band split is a
//! function of the window and `step` only, never of the thread count, so a
//! kernel whose band work is deterministic gives results identical for any
//! `n_threads`.
use super::sat::{band_rows, check_window, line_fit, log_axis, rect, sat_into};
use crate::checks::step_grid;
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

/// Maps on the grid of every `step`-th pixel, row-major `rows x cols`:
/// the dimension, r² (or the kernel's second map, e.g. a standard error)
/// and any further maps of the kernel (empty vectors for maps not asked).
#[derive(Debug, Clone, Default)]
pub struct MapOut {
    pub rows: usize,
    pub cols: usize,
    pub d: Vec<f32>,
    pub r2: Vec<f32>,
    pub extra: Vec<Vec<f32>>,
}

impl MapOut {
    /// Every map in order (`d`, `r2`, then `extra`).
    pub fn into_maps(self) -> Vec<Vec<f32>> {
        let mut v = vec![self.d, self.r2];
        v.extend(self.extra);
        v
    }
}

/// The output grid of a map and its bands.
#[derive(Debug, Clone, Copy)]
pub struct Grid {
    pub rows: usize,
    pub cols: usize,
    /// Window side and half side.
    pub w: usize,
    pub h: usize,
    pub step: usize,
    /// Output grid shape: `ceil(rows / step) x ceil(cols / step)`.
    pub orows: usize,
    pub ocols: usize,
    /// Output rows per band.
    pub ob: usize,
    /// Fewest valid pixels a window needs.
    pub min_pixels: f64,
}

/// One band: output rows `g0 .. g1`, input rows `i0 .. i1` (every row a
/// window of the band touches).
#[derive(Debug, Clone, Copy)]
pub struct Band {
    pub g0: usize,
    pub g1: usize,
    pub i0: usize,
    pub i1: usize,
}

impl Band {
    /// Input rows of the band.
    #[inline]
    pub fn nr(&self) -> usize {
        self.i1 - self.i0
    }
}

/// The scale list of a map kernel (box sizes, lags, thicknesses): its
/// distinct values in ascending order, or an error naming `param` when fewer
/// than `min_count` are distinct or one of them fails `ok` (`expected` says
/// what the values must be, e.g. "lags in [1, 9)").
pub fn scale_list(
    values: &[usize],
    param: &str,
    min_count: usize,
    expected: &str,
    ok: impl Fn(usize) -> bool,
) -> CoreResult<Vec<usize>> {
    let mut v = values.to_vec();
    v.sort_unstable();
    v.dedup();
    if v.len() < min_count || !v.iter().all(|&x| ok(x)) {
        return Err(CoreError::invalid(
            param,
            format!("need at least {min_count} distinct {expected}, got {values:?}"),
        ));
    }
    Ok(v)
}

impl Grid {
    /// Check the image (`z_len` samples, `rows x cols`), the window (odd,
    /// `>= 3`, not larger than the image), `min_valid` (a fraction) and
    /// `step` (positive); each error names its parameter.
    pub fn new(
        z_len: usize,
        rows: usize,
        cols: usize,
        w: usize,
        min_valid: f64,
        step: usize,
    ) -> CoreResult<Self> {
        let min_pixels = check_window(z_len, rows, cols, w, min_valid)?;
        let (orows, ocols) = step_grid(step, rows, cols)?;
        Ok(Grid {
            rows,
            cols,
            w,
            h: w / 2,
            step,
            orows,
            ocols,
            ob: (band_rows(w) / step).max(1),
            min_pixels,
        })
    }

    pub fn n_bands(&self) -> usize {
        self.orows.div_ceil(self.ob)
    }

    /// Band `b` and the input rows its windows touch.
    pub fn band(&self, b: usize) -> Band {
        let g0 = b * self.ob;
        let g1 = (g0 + self.ob).min(self.orows);
        Band {
            g0,
            g1,
            i0: (g0 * self.step).saturating_sub(self.h),
            i1: ((g1 - 1) * self.step + self.h + 1).min(self.rows),
        }
    }

    /// Rows `r0 .. r1` of the window of output row `g`, relative to the
    /// band's first input row.
    #[inline]
    pub fn win_rows(&self, band: &Band, g: usize) -> (usize, usize) {
        let i = g * self.step;
        (
            i.saturating_sub(self.h) - band.i0,
            (i + self.h + 1).min(self.rows) - band.i0,
        )
    }

    /// Columns `c0 .. c1` of the window of output column `q`.
    #[inline]
    pub fn win_cols(&self, q: usize) -> (usize, usize) {
        let j = q * self.step;
        (j.saturating_sub(self.h), (j + self.h + 1).min(self.cols))
    }

    /// Run `kernel(scratch, band, outs)` on every band in parallel and
    /// return the `wanted.len()` maps (NaN where the kernel writes nothing;
    /// an empty map where `wanted` is false). `outs[m]` is the band's rows
    /// of map `m` (`(g1 - g0) * ocols` values, empty when not wanted);
    /// `scratch` is per thread and reused from band to band, so a kernel
    /// must overwrite what it reads of it.
    pub fn drive<S, K>(&self, wanted: &[bool], kernel: K) -> CoreResult<Vec<Vec<f32>>>
    where
        S: Default + Send,
        K: Fn(&mut S, &Band, &mut [&mut [f32]]) + Sync + Send,
    {
        let n_out = self.orows * self.ocols;
        let mut maps = wanted
            .iter()
            .map(|&on| crate::buffers::try_filled(if on { n_out } else { 0 }, f32::NAN, "image"))
            .collect::<CoreResult<Vec<Vec<f32>>>>()?;
        let n_bands = self.n_bands();
        let chunk = self.ob * self.ocols;
        let mut bands: Vec<Vec<&mut [f32]>> = (0..n_bands).map(|_| Vec::new()).collect();
        for m in maps.iter_mut() {
            if m.is_empty() {
                bands
                    .iter_mut()
                    .for_each(|b| b.push(<&mut [f32]>::default()));
            } else {
                for (b, part) in bands.iter_mut().zip(m.chunks_mut(chunk)) {
                    b.push(part);
                }
            }
        }
        bands
            .into_par_iter()
            .enumerate()
            .for_each_init(S::default, |sc, (b, mut outs)| {
                kernel(sc, &self.band(b), &mut outs)
            });
        Ok(maps)
    }

    /// [`Grid::drive`] for a kernel writing `D` and a second map.
    pub fn drive_pair<S, K>(&self, kernel: K) -> CoreResult<MapOut>
    where
        S: Default + Send,
        K: Fn(&mut S, &Band, &mut [&mut [f32]]) + Sync + Send,
    {
        Ok(self.map_out(self.drive(&[true, true], kernel)?))
    }

    /// The [`MapOut`] of this grid from the maps of [`Grid::drive`] in
    /// order: `D`, the second map, then any further maps.
    pub fn map_out(&self, maps: Vec<Vec<f32>>) -> MapOut {
        let mut maps = maps.into_iter();
        MapOut {
            rows: self.orows,
            cols: self.ocols,
            d: maps.next().unwrap_or_default(),
            r2: maps.next().unwrap_or_default(),
            extra: maps.collect(),
        }
    }

    /// Every window of the band whose valid-pixel count (from `vsat`, a
    /// [`valid_sat`] of the band) reaches the gate: `f(k, r0, r1, c0, c1,
    /// valid)` with `k` the index in the band's output rows and the window
    /// in band rows and image columns.
    #[inline]
    pub fn valid_windows(
        &self,
        band: &Band,
        vsat: &[f64],
        mut f: impl FnMut(usize, usize, usize, usize, usize, f64),
    ) {
        let sw = self.cols + 1;
        for g in band.g0..band.g1 {
            let (r0, r1) = self.win_rows(band, g);
            for q in 0..self.ocols {
                let (c0, c1) = self.win_cols(q);
                let n = rect(vsat, sw, r0, r1, c0, c1);
                if n < self.min_pixels {
                    continue;
                }
                f((g - band.g0) * self.ocols + q, r0, r1, c0, c1, n);
            }
        }
    }
}

/// Summed-area table of the band's valid (not NaN) samples, into `s`.
pub fn valid_sat(s: &mut Vec<f64>, band: &Band, cols: usize, get: impl Fn(usize, usize) -> f64) {
    sat_into(s, band.nr(), cols, |r, c| {
        (!get(r, c).is_nan()) as u8 as f64
    });
}

/// Least-squares line of `ln(statistic)` against `ln(scale)` and the map of
/// its slope to a dimension (`to_d`).
#[derive(Debug, Clone)]
pub struct LogFit<F> {
    xs: Vec<f64>,
    xm: f64,
    sxx: f64,
    to_d: F,
}

impl<F: Fn(f64) -> f64> LogFit<F> {
    pub fn new(scales: &[usize], to_d: F) -> Self {
        let (xs, xm, sxx) = log_axis(scales);
        LogFit { xs, xm, sxx, to_d }
    }

    /// Fit `ys` (one `ln` value per scale) and write `D` to `outs[0][k]` and
    /// r² to `outs[1][k]`.
    #[inline]
    pub fn write(&self, ys: &[f64], outs: &mut [&mut [f32]], k: usize) {
        let (slope, r2) = line_fit(&self.xs, self.xm, self.sxx, ys);
        outs[0][k] = (self.to_d)(slope) as f32;
        outs[1][k] = r2 as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_the_grid_and_their_halo() {
        for (rows, w, step) in [
            (300usize, 9usize, 1usize),
            (301, 33, 3),
            (70, 15, 7),
            (5, 5, 9),
        ] {
            let g = Grid::new(rows * 4, rows, 4, w.min(rows | 1), 0.5, step).unwrap();
            let mut next = 0;
            for b in 0..g.n_bands() {
                let band = g.band(b);
                assert_eq!(band.g0, next);
                next = band.g1;
                for gi in band.g0..band.g1 {
                    let (r0, r1) = g.win_rows(&band, gi);
                    let i = gi * step;
                    assert_eq!(r0 + band.i0, i.saturating_sub(g.h));
                    assert_eq!(r1 + band.i0, (i + g.h + 1).min(rows));
                    assert!(r1 <= band.nr());
                }
            }
            assert_eq!(next, g.orows);
        }
        assert!(Grid::new(100, 10, 10, 3, 0.5, 0)
            .unwrap_err()
            .to_string()
            .starts_with("step: "));
        assert!(Grid::new(100, 10, 10, 4, 0.5, 1)
            .unwrap_err()
            .to_string()
            .starts_with("window_size: "));
    }

    #[test]
    fn drive_writes_each_band_once_and_skips_unwanted_maps() {
        let g = Grid::new(200 * 7, 200, 7, 5, 0.0, 2).unwrap();
        let maps = crate::parallel::run_in_pool(Some(3), || {
            g.drive::<(), _>(&[true, false, true], |_, band, outs| {
                assert!(outs[1].is_empty());
                for (k, v) in outs[0].iter_mut().enumerate() {
                    *v = (band.g0 * g.ocols + k) as f32;
                }
                outs[2].fill(band.g0 as f32);
            })
        })
        .unwrap();
        assert_eq!(
            maps[0],
            (0..g.orows * g.ocols).map(|k| k as f32).collect::<Vec<_>>()
        );
        assert!(maps[1].is_empty());
        assert!(maps[2].iter().all(|v| v.is_finite()));
    }
}
