//! Successive random additions with 4-point interpolation (diamond-square
//! order), a refinement kernel without creases.
//!
//! One level refines a grid of spacing `s` to spacing `s/2`:
//!
//! 1. **diamond step**: a cell centre `(2a+1, 2b+1)` is the tensor-product
//!    4-point rule of the 4 x 4 old samples around it, weights
//!    `(-w, 1/2 + w, 1/2 + w, -w)` per axis (`w = 1/16` is the cubic rule of
//!    Dubuc / Deslauriers-Dubuc, `w = 0` the bilinear mean; Dyn, Levin &
//!    Gregory 1987 call `w` the tension), plus a Gaussian of variance `c1`;
//! 2. **square step**: an edge point (`(2a, 2b+1)` or `(2a+1, 2b)`) is the
//!    mean of the 4-point rule along the row and along the column; one of them
//!    runs over old samples at distances 1 and 3, the other over the cell
//!    centres of step 1 at distances 1 and 3; plus a Gaussian of variance `e`;
//! 3. **additions** (Voss): the old samples receive a Gaussian of variance
//!    `a2`, the cell centres another one of variance `c2`.
//!
//! The variances are given in units of `sigma^2 s^(2H)`; they are derived on
//! the Python side (`fractalgeo_rs.synth._additions`) so that the variance of
//! the second differences is the same at old samples, edge points and centres
//! along both axes and the lag-one variance is `sigma^2 (s/2)^(2H)` when the
//! coarse grid is fBm (docs/synthesis.md). Outside the grid (non-periodic), old
//! samples and centres are extended linearly, which reproduces planes.
//!
//! Random numbers are keyed by `(seed, level, phase, global fine index)`, so
//! the result does not depend on the number of threads and a tile (`origin`)
//! agrees with the whole.
//!
//! A level is one parallel pass over blocks of fine rows: a block pads the
//! coarse rows it reads and computes the centre rows it reads (3 more than
//! its own) into per-thread scratch, then writes its fine rows with their
//! noise; there is no padded copy of a whole grid and no grid of centres.
use crate::error::{CoreError, CoreResult};
use crate::progress::{add_total, tick, Progress};
use crate::rng::StreamKey;
use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

/// Options of one level of [`refine_2d`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdditionsParams {
    /// Hurst exponent in (0, 1).
    pub hurst: f64,
    /// Increment standard deviation at unit distance.
    pub sigma: f64,
    /// Spacing `s` of the coarse grid (length units).
    pub coarse_spacing: f64,
    /// Tension `w` of the 4-point rule (`1/16`: cubic).
    pub tension: f64,
    /// Variances `[a2, c1, c2, e]` in units of `sigma^2 s^(2H)`.
    pub variances: [f64; 4],
    /// Torus (`n -> 2n`) instead of `n -> 2n - 1`.
    pub periodic: bool,
    /// Random seed.
    pub seed: u64,
    /// Level number (part of the random key).
    pub level: u32,
    /// Global position of the fine grid's first sample (tiles).
    pub origin: (u64, u64),
    /// Columns of the global fine grid (the key's row stride).
    pub global_cols: u64,
}

/// Streams of this kernel start here (disjoint from the midpoint kernel's).
pub const STREAM_BASE: u64 = 1 << 21;
const PH_C1: u64 = 0;
const PH_C2: u64 = 1;
const PH_A2: u64 = 2;
const PH_E: u64 = 3;

fn key(p: &AdditionsParams, phase: u64) -> StreamKey {
    super::level_key(p.seed, STREAM_BASE, p.level, phase)
}

fn check(p: &AdditionsParams) -> CoreResult<()> {
    super::check_level(p.hurst, p.sigma, p.coarse_spacing)?;
    if !(p.tension.is_finite() && p.tension.abs() <= 0.25) {
        return Err(CoreError::invalid(
            "tension",
            format!("expected a number in [-0.25, 0.25], got {}", p.tension),
        ));
    }
    if p.variances.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(CoreError::invalid(
            "variances",
            format!("expected 4 finite numbers >= 0, got {:?}", p.variances),
        ));
    }
    Ok(())
}

/// Values at -2, -1 and n, n+1 of a line of length `n` from `v0 = v[0]`,
/// `v1 = v[1]`, `w1 = v[n-2]`, `w0 = v[n-1]`: linear extrapolation
/// (`x[-k] = x[0] + k (x[0] - x[1])`; constant for 1 sample).
#[inline]
fn ends(v0: f64, v1: f64, w1: f64, w0: f64, n: usize) -> [f64; 4] {
    if n == 1 {
        [v0; 4]
    } else {
        let (d0, d1) = (v0 - v1, w0 - w1);
        [v0 + 2.0 * d0, v0 + d0, w0 + d1, w0 + 2.0 * d1]
    }
}

/// Pad a line in place: `line[2..n + 2]` holds the `n` values, `line[0..2]`
/// and `line[n + 2..n + 4]` receive the wrap-around (periodic) or the linear
/// extension.
#[inline]
fn pad_ends(line: &mut [f64], periodic: bool) {
    let n = line.len() - 4;
    let v = &line[2..n + 2];
    let e = if periodic {
        [v[(2 * n - 2) % n], v[n - 1], v[0], v[1 % n]]
    } else {
        ends(v[0], v[n.min(2) - 1], v[n.saturating_sub(2)], v[n - 1], n)
    };
    line[0] = e[0];
    line[1] = e[1];
    line[n + 2] = e[2];
    line[n + 3] = e[3];
}

/// Padded row `k` (in `-2 .. n + 2`) of a grid of `n` rows that is padded by
/// 2 on every side, rows outside the grid wrapped (periodic) or extended
/// linearly from the padded rows (so the corners extend the padded columns).
/// `row(i, dst)` writes the padded row `i` in `0 .. n` (`dst.len()` values).
fn padded_row(
    k: isize,
    n: usize,
    periodic: bool,
    dst: &mut [f64],
    row: &mut impl FnMut(usize, &mut [f64]),
) {
    if k >= 0 && (k as usize) < n {
        return row(k as usize, dst);
    }
    if periodic {
        return row(k.rem_euclid(n as isize) as usize, dst);
    }
    // Rows 0, 1 (above) or n-1, n-2 (below): x0 + (1 or 2) (x0 - x1).
    let (first, second) = if k < 0 {
        (0, n.min(2) - 1)
    } else {
        (n - 1, n.saturating_sub(2))
    };
    row(first, dst);
    if n == 1 {
        return;
    }
    let mut x1 = vec![0.0; dst.len()];
    row(second, &mut x1);
    let far = k < -1 || k > n as isize;
    for (d, x1) in dst.iter_mut().zip(&x1) {
        let x0 = *d;
        let dd = x0 - x1;
        *d = if far { x0 + 2.0 * dd } else { x0 + dd };
    }
}

/// Pairs of fine rows (an even and an odd one) per parallel block; a block
/// recomputes the 3 rows of centres it shares with its neighbours.
const BLOCK_PAIRS: usize = 32;

/// One level, read-only: the coarse grid, the rules and the random streams.
struct Level<'a> {
    cs: &'a [f64],
    r: usize,
    c: usize,
    nr: usize,
    nc: usize,
    periodic: bool,
    wt: [f64; 4],
    /// Standard deviations `[a2, c1, c2, e]`.
    sd: [f64; 4],
    kc1: StreamKey,
    kc2: StreamKey,
    ka2: StreamKey,
    ke: StreamKey,
    origin: (u64, u64),
    gc: u64,
}

impl Level<'_> {
    #[inline(always)]
    fn gidx(&self, i: usize, j: usize) -> u64 {
        (self.origin.0 + i as u64) * self.gc + self.origin.1 + j as u64
    }

    /// Padded coarse row `k` in `-2 .. r + 2` (`c + 4` values).
    fn coarse_row(&self, k: isize, dst: &mut [f64]) {
        let c = self.c;
        padded_row(k, self.r, self.periodic, dst, &mut |i, d: &mut [f64]| {
            d[2..c + 2].copy_from_slice(&self.cs[i * c..(i + 1) * c]);
            pad_ends(d, self.periodic);
        });
    }

    /// Padded centre row `a` (`nc + 4` values): the 4 x 4 rule on the padded
    /// coarse rows `a - 1 .. a + 2` (`rows`), plus `c1`.
    fn centre_row(&self, a: usize, rows: [&[f64]; 4], dst: &mut [f64]) {
        let wt = self.wt;
        let nc = self.nc;
        let out = &mut dst[2..nc + 2];
        // The rule first (a loop the compiler vectorises), then the noise.
        let [r0, r1, r2, r3] = rows.map(|cp| &cp[..nc + 4]);
        for (b, v) in out.iter_mut().enumerate() {
            let mut s = 0.0;
            for (wi, cp) in wt.iter().zip([r0, r1, r2, r3]) {
                let line =
                    wt[0] * cp[b + 1] + wt[1] * cp[b + 2] + wt[2] * cp[b + 3] + wt[3] * cp[b + 4];
                s += wi * line;
            }
            *v = s;
        }
        let g = self.gidx(2 * a + 1, 1);
        for (b, v) in out.iter_mut().enumerate() {
            *v += self.sd[1] * self.kc1.normal(g + 2 * b as u64);
        }
        pad_ends(dst, self.periodic);
    }

    /// Padded centre row `k` in `-2 .. nr + 2`, computed from the coarse grid
    /// alone (rows outside the grid and the edges of a block).
    fn centre_row_alone(&self, k: isize, dst: &mut [f64]) {
        let pc = self.c + 4;
        let mut buf = vec![0.0; 4 * pc];
        padded_row(k, self.nr, self.periodic, dst, &mut |a, d: &mut [f64]| {
            for (t, chunk) in buf.chunks_mut(pc).enumerate() {
                self.coarse_row(a as isize - 1 + t as isize, chunk);
            }
            let rows = [
                &buf[..pc],
                &buf[pc..2 * pc],
                &buf[2 * pc..3 * pc],
                &buf[3 * pc..],
            ];
            self.centre_row(a, rows, d);
        });
    }

    /// Fine rows `i0 .. i0 + out.len() / cols` (`cols` columns from column 0)
    /// into `out`; `co` and `ce` are scratch buffers.
    fn block(&self, i0: usize, cols: usize, out: &mut [f64], co: &mut Vec<f64>, ce: &mut Vec<f64>) {
        let (pc, pn) = (self.c + 4, self.nc + 4);
        let i1 = i0 + out.len() / cols;
        let (a0, a1) = ((i0 / 2) as isize, ((i1 - 1) / 2 + 1) as isize);
        // Padded coarse rows kc0 ..= kc1 and centre rows a0 - 2 ..= a1.
        let kc0 = (a0 - 3).max(-2);
        let kc1 = (a1 + 2).min(self.r as isize + 1);
        co.resize(((kc1 - kc0 + 1) as usize) * pc, 0.0);
        for (t, chunk) in co.chunks_mut(pc).enumerate() {
            self.coarse_row(kc0 + t as isize, chunk);
        }
        let crow = |k: isize| -> &[f64] {
            let s = ((k - kc0) as usize) * pc;
            &co[s..s + pc]
        };
        let ka0 = a0 - 2;
        ce.resize(((a1 - ka0 + 1) as usize) * pn, 0.0);
        for (t, chunk) in ce.chunks_mut(pn).enumerate() {
            let k = ka0 + t as isize;
            if k >= 0 && (k as usize) < self.nr {
                let rows = [crow(k - 1), crow(k), crow(k + 1), crow(k + 2)];
                self.centre_row(k as usize, rows, chunk);
            } else {
                self.centre_row_alone(k, chunk);
            }
        }
        let erow = |k: isize| -> &[f64] {
            let s = ((k - ka0) as usize) * pn;
            &ce[s..s + pn]
        };
        let wt = self.wt;
        let [sd_a2, _, sd_c2, sd_e] = self.sd;
        // Per row, the rules first (vectorisable loops), then the noise.
        for (t, row) in out.chunks_mut(cols).enumerate() {
            let i = i0 + t;
            let a = (i / 2) as isize;
            let mut pairs = row.chunks_exact_mut(2);
            if i % 2 == 0 {
                // Old samples (+ a2) and edges (2a, 2b+1): the rule along the
                // row on old samples b-1 .. b+2, along the column on centres
                // a-2 .. a+1.
                let cp = crow(a);
                let (e0, e1, e2, e3) = (erow(a - 2), erow(a - 1), erow(a), erow(a + 1));
                for (b, v) in pairs.by_ref().enumerate() {
                    let hor = wt[0] * cp[b + 1]
                        + wt[1] * cp[b + 2]
                        + wt[2] * cp[b + 3]
                        + wt[3] * cp[b + 4];
                    let col = b + 2;
                    let ver = wt[0] * e0[col] + wt[1] * e1[col] + wt[2] * e2[col] + wt[3] * e3[col];
                    v[0] = cp[b + 2];
                    v[1] = 0.5 * (hor + ver);
                }
                if let [v] = pairs.into_remainder() {
                    *v = cp[cols / 2 + 2];
                }
                self.add_noise(row, self.gidx(i, 0), (sd_a2, self.ka2), (sd_e, self.ke));
            } else {
                // Edges (2a+1, 2b): the rule along the column on old samples
                // a-1 .. a+2, along the row on centres b-2 .. b+1; centres (+ c2).
                let (c0, c1, c2, c3) = (crow(a - 1), crow(a), crow(a + 1), crow(a + 2));
                let ep = erow(a);
                let edge = |b: usize| {
                    let col = b + 2;
                    let ver = wt[0] * c0[col] + wt[1] * c1[col] + wt[2] * c2[col] + wt[3] * c3[col];
                    let hor =
                        wt[0] * ep[b] + wt[1] * ep[b + 1] + wt[2] * ep[b + 2] + wt[3] * ep[b + 3];
                    0.5 * (hor + ver)
                };
                for (b, v) in pairs.by_ref().enumerate() {
                    v[0] = edge(b);
                    v[1] = ep[b + 2];
                }
                if let [v] = pairs.into_remainder() {
                    *v = edge(cols / 2);
                }
                self.add_noise(row, self.gidx(i, 0), (sd_e, self.ke), (sd_c2, self.kc2));
            }
        }
    }

    /// Add the noise of a fine row whose first sample has the key index `g`:
    /// `sd * normal` of stream `even` at even columns, of `odd` at odd ones.
    #[inline(always)]
    fn add_noise(&self, row: &mut [f64], g: u64, even: (f64, StreamKey), odd: (f64, StreamKey)) {
        let mut pairs = row.chunks_exact_mut(2);
        for (b, v) in pairs.by_ref().enumerate() {
            let gj = g + 2 * b as u64;
            v[0] += even.0 * even.1.normal(gj);
            v[1] += odd.0 * odd.1.normal(gj + 1);
        }
        let n = row.len();
        if n % 2 == 1 {
            row[n - 1] += even.0 * even.1.normal(g + (n - 1) as u64);
        }
    }
}

/// One level: `(r, c) -> (2r - 1, 2c - 1)` (periodic: `(2r, 2c)`), keeping
/// only the first `shape = (rows, cols)` of the fine grid (`None`: all of
/// it; a window's samples are those of the whole grid). `progress` is ticked
/// by the cells kept, block of rows by block (the caller announces the
/// total).
pub fn refine_2d(
    coarse: ArrayView2<f64>,
    p: &AdditionsParams,
    shape: Option<(usize, usize)>,
    progress: Option<&Progress>,
) -> CoreResult<Array2<f64>> {
    check(p)?;
    let (coarse, (r, c), (fr, fc)) = super::refine_input(coarse, p.periodic)?;
    let cs = super::as_slice(&coarse)?;
    let (or, oc) = window_shape(shape, (fr, fc))?;
    // Centres: (nr, nc) of them at fine (2a+1, 2b+1).
    let (nr, nc) = if p.periodic { (r, c) } else { (r - 1, c - 1) };
    let scale = p.sigma * p.coarse_spacing.powf(p.hurst);
    let w = p.tension;
    let lv = Level {
        cs,
        r,
        c,
        nr,
        nc,
        periodic: p.periodic,
        wt: [-w, 0.5 + w, 0.5 + w, -w],
        sd: p.variances.map(|v| scale * v.sqrt()),
        kc1: key(p, PH_C1),
        kc2: key(p, PH_C2),
        ka2: key(p, PH_A2),
        ke: key(p, PH_E),
        origin: p.origin,
        gc: p.global_cols.max(p.origin.1 + fc as u64),
    };
    let mut fine =
        crate::buffers::try_zeroed(crate::buffers::checked_len(or, oc, "shape")?, "shape")?;
    fine.par_chunks_mut(2 * BLOCK_PAIRS * oc)
        .enumerate()
        .for_each_init(
            || (Vec::new(), Vec::new()),
            |(co, ce), (bi, out)| {
                lv.block(2 * BLOCK_PAIRS * bi, oc, out, co, ce);
                tick(progress, out.len() as u64);
            },
        );
    Array2::from_shape_vec((or, oc), fine).map_err(|e| CoreError::Internal(e.to_string()))
}

/// The `shape = (rows, cols)` kept of a grid of `full` samples (`None`:
/// all of it), checked to be a non-empty corner of it.
fn window_shape(shape: Option<(usize, usize)>, full: (usize, usize)) -> CoreResult<(usize, usize)> {
    let (fr, fc) = full;
    let (or, oc) = shape.unwrap_or(full);
    if or < 1 || oc < 1 || or > fr || oc > fc {
        return Err(CoreError::invalid(
            "shape",
            format!("expected 1 .. {fr} rows and 1 .. {fc} columns, got {or} x {oc}"),
        ));
    }
    Ok((or, oc))
}

/// Refine `levels` times (levels numbered from `base.level`), halving the
/// spacing each time; keys use the final grid of each level (origin 0).
/// `shape = (rows, cols)`: keep only the first rows and columns of the final
/// grid (`None`: all of it); the last level computes no sample outside it,
/// and the samples are those of the whole grid. `progress` gets the cells of
/// every level's grid (the window at the last level) as total and is ticked
/// block of rows by block.
pub fn refine_2d_levels(
    coarse: ArrayView2<f64>,
    levels: u32,
    base: &AdditionsParams,
    shape: Option<(usize, usize)>,
    progress: Option<&Progress>,
) -> CoreResult<Array2<f64>> {
    check(base)?;
    if levels == 0 {
        let Some(shape) = shape else {
            return Ok(coarse.to_owned());
        };
        let (or, oc) = window_shape(Some(shape), coarse.dim())?;
        return Ok(coarse.slice(ndarray::s![..or, ..oc]).to_owned());
    }
    add_total(
        progress,
        crate::synth::midpoint::refined_cells(coarse.dim(), levels, base.periodic, shape),
    );
    let mut grid = coarse.to_owned();
    let mut p = *base;
    for l in 0..levels {
        let c = grid.ncols();
        let fc = if p.periodic { 2 * c } else { 2 * c - 1 };
        p.level = base.level + l;
        p.global_cols = fc as u64;
        p.origin = (0, 0);
        let window = if l + 1 == levels { shape } else { None };
        grid = refine_2d(grid.view(), &p, window, progress)?;
        p.coarse_spacing /= 2.0;
    }
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::run_in_pool;

    fn params(periodic: bool) -> AdditionsParams {
        AdditionsParams {
            hurst: 0.7,
            sigma: 1.0,
            coarse_spacing: 8.0,
            tension: 0.1,
            variances: [0.01, 0.09, 0.02, 0.09],
            periodic,
            seed: 5,
            level: 0,
            origin: (0, 0),
            global_cols: 0,
        }
    }

    #[test]
    fn zero_noise_reproduces_planes() {
        // The 4-point rules and the linear extension are exact for planes.
        let coarse = Array2::from_shape_fn((4, 5), |(i, j)| 2.0 * i as f64 - 3.0 * j as f64 + 1.0);
        let mut p = params(false);
        p.sigma = 0.0;
        let f = refine_2d(coarse.view(), &p, None, None).unwrap();
        assert_eq!(f.dim(), (7, 9));
        for ((i, j), v) in f.indexed_iter() {
            let want = 2.0 * (i as f64 / 2.0) - 3.0 * (j as f64 / 2.0) + 1.0;
            assert!((v - want).abs() < 1e-12, "({i}, {j}): {v} vs {want}");
        }
    }

    #[test]
    fn zero_noise_keeps_old_samples_and_periodic_sizes() {
        let coarse = Array2::from_shape_fn((3, 4), |(i, j)| ((i * 7 + j * 3) % 5) as f64);
        let mut p = params(true);
        p.sigma = 0.0;
        let f = refine_2d(coarse.view(), &p, None, None).unwrap();
        assert_eq!(f.dim(), (6, 8));
        for i in 0..3 {
            for j in 0..4 {
                assert_eq!(f[[2 * i, 2 * j]], coarse[[i, j]]);
            }
        }
        // A constant field stays constant on the torus.
        let k = Array2::from_elem((4, 4), 2.5);
        let g = refine_2d(k.view(), &p, None, None).unwrap();
        assert!(g.iter().all(|v| (v - 2.5).abs() < 1e-12));
    }

    #[test]
    fn thread_count_does_not_matter() {
        let coarse = Array2::<f64>::zeros((3, 3));
        let a = run_in_pool(Some(1), || {
            refine_2d_levels(coarse.view(), 5, &params(false), None, None)
        })
        .unwrap();
        let b = run_in_pool(Some(2), || {
            refine_2d_levels(coarse.view(), 5, &params(false), None, None)
        })
        .unwrap();
        assert_eq!(a, b);
        assert_eq!(a.dim(), (65, 65));
    }

    #[test]
    fn window_is_the_top_left_of_the_whole() {
        // Several parallel blocks (2 x BLOCK_PAIRS fine rows each), odd sizes.
        for periodic in [false, true] {
            let coarse = Array2::from_shape_fn((2 * BLOCK_PAIRS + 7, 37), |(i, j)| {
                ((i * 13 + j * 7) % 11) as f64 - 5.0
            });
            let p = params(periodic);
            let whole = refine_2d(coarse.view(), &p, None, None).unwrap();
            let (fr, fc) = whole.dim();
            for (rows, cols) in [
                (fr, fc),
                (fr - 1, fc - 2),
                (2 * BLOCK_PAIRS + 1, 1),
                (1, fc),
            ] {
                let w = run_in_pool(Some(2), || {
                    refine_2d(coarse.view(), &p, Some((rows, cols)), None)
                })
                .unwrap();
                assert_eq!(w, whole.slice(ndarray::s![..rows, ..cols]));
            }
            assert!(refine_2d(coarse.view(), &p, Some((fr + 1, fc)), None).is_err());
            assert!(refine_2d(coarse.view(), &p, Some((0, fc)), None).is_err());
        }
    }

    #[test]
    fn counted_refinement_is_the_same_and_reaches_its_total() {
        let coarse = Array2::from_shape_fn((3, 4), |(i, j)| (i * 4 + j) as f64);
        for (periodic, shape) in [(false, Some((16, 20))), (false, None), (true, None)] {
            let p = params(periodic);
            let pr = Progress::new();
            let a = run_in_pool(Some(2), || {
                refine_2d_levels(coarse.view(), 3, &p, shape, Some(&pr))
            })
            .unwrap();
            let b = run_in_pool(Some(1), || {
                refine_2d_levels(coarse.view(), 3, &p, shape, None)
            })
            .unwrap();
            assert_eq!(a, b);
            assert_eq!(pr.done(), pr.total());
            // the levels' grids: 5 x 7, 9 x 13 and the last (window or whole)
            let last = shape.unwrap_or(if periodic { (24, 32) } else { (17, 25) });
            let first = if periodic {
                6 * 8 + 12 * 16
            } else {
                5 * 7 + 9 * 13
            };
            assert_eq!(pr.total(), (first + last.0 * last.1) as u64);
        }
    }

    #[test]
    fn levels_window_is_the_top_left_of_the_whole() {
        let coarse = Array2::from_shape_fn((3, 4), |(i, j)| (i as f64) - 0.5 * j as f64);
        let p = params(false);
        let whole = refine_2d_levels(coarse.view(), 3, &p, None, None).unwrap();
        assert_eq!(whole.dim(), (17, 25));
        let w = refine_2d_levels(coarse.view(), 3, &p, Some((16, 20)), None).unwrap();
        assert_eq!(w, whole.slice(ndarray::s![..16, ..20]));
        let w0 = refine_2d_levels(coarse.view(), 0, &p, Some((2, 3)), None).unwrap();
        assert_eq!(w0, coarse.slice(ndarray::s![..2, ..3]));
        assert!(refine_2d_levels(coarse.view(), 0, &p, Some((4, 3)), None).is_err());
        assert!(refine_2d_levels(coarse.view(), 3, &p, Some((18, 3)), None).is_err());
    }

    #[test]
    fn bad_arguments() {
        let coarse = Array2::<f64>::zeros((2, 2));
        let mut p = params(false);
        p.variances[2] = -1.0;
        assert!(matches!(
            refine_2d(coarse.view(), &p, None, None),
            Err(CoreError::InvalidArgument { .. })
        ));
        let mut p = params(false);
        p.tension = f64::NAN;
        assert!(refine_2d(coarse.view(), &p, None, None).is_err());
        let one = Array2::<f64>::zeros((1, 3));
        assert!(refine_2d(one.view(), &params(false), None, None).is_err());
    }
}
