//! Random midpoint displacement and Voss's successive random additions, as
//! refinement kernels: a grid is refined by a factor 2 per level, the existing
//! samples are kept (plain midpoint displacement) and the new ones are the mean
//! of their neighbours plus a Gaussian displacement.
//!
//! Variance schedule (seed paper eq. 19-20; Peitgen & Saupe 1988, ch. 2): the
//! displacement standard deviation at a level whose *coarse* spacing is `s`
//! (length units) is `sigma * s^H * k`, so it shrinks by `2^-H` per level
//! (`sigma_n^2 = sigma_{n-1}^2 / 2^{2H}`, eq. 20). The constant `k` makes the
//! increments between neighbours have variance `sigma^2 * d^{2H}` (eq. 19)
//! when the coarse grid has it:
//!
//! * 1D, midpoint: `k^2 = 1 - 2^{2H-2}` (exact for neighbours at every level);
//! * 2D diamond-square, per half step: `k^2 = 2^{-H} - (2 + 2^H) / 8`, from
//!   `Var(mean of 4 corners - corner) = (2 gamma(s) + gamma(s sqrt 2)) / 8`;
//!   the square step uses the same `k` with the spacing `s / sqrt 2`;
//! * with random additions (Voss 1985, 1988; Peitgen & Saupe 1988,
//!   `AdditionsFM1D`/`MidPointFM2D` with addition): the new samples are the
//!   mean of their neighbours, then every sample, old and new, receives an
//!   independent Gaussian; the constant is divided by `sqrt 2` so the neighbour
//!   increments keep the variance above (`v' = v/4 + 2 delta^2` in 1D).
//!
//! Random numbers are keyed by `(seed, stream = f(level, phase), global index
//! in the refined grid)` (see [`super::rng`]), so the output does not depend on
//! the number of threads, and the noise at a global position is the same
//! whichever tile (`origin`) computes it.
use crate::error::{CoreError, CoreResult};
use crate::parallel::SharedMut;
use crate::progress::{add_total, tick, Progress};
use crate::rng::StreamKey;
use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

/// Options of one refinement level.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineParams {
    /// Hurst exponent in (0, 1).
    pub hurst: f64,
    /// Scale: the increment standard deviation at unit distance.
    pub sigma: f64,
    /// Spacing of the coarse grid in length units (the fine spacing is half).
    pub coarse_spacing: f64,
    /// Voss's random additions to all samples (existing samples then change).
    pub additions: bool,
    /// Treat the grid as a torus (coarse `n` -> fine `2n`), else `n` -> `2n - 1`.
    pub periodic: bool,
    /// Random seed.
    pub seed: u64,
    /// Level number, part of the random key (use distinct levels per call).
    pub level: u32,
    /// Global position of the fine grid's first sample (tiles).
    pub origin: (u64, u64),
    /// Number of columns of the global fine grid (the key's row stride).
    pub global_cols: u64,
}

const PHASE_DISPLACE: u64 = 0;
const PHASE_ADD: u64 = 1;
const PHASE_DISPLACE_SQ: u64 = 2;
const PHASE_ADD_SQ: u64 = 3;
/// Streams below this are free for other uses of the seed.
pub const STREAM_BASE: u64 = 1 << 20;

fn key(p: &RefineParams, phase: u64) -> StreamKey {
    super::level_key(p.seed, STREAM_BASE, p.level, phase)
}

fn check(p: &RefineParams) -> CoreResult<()> {
    super::check_level(p.hurst, p.sigma, p.coarse_spacing)
}

/// The neighbour index before `k` on a line of `n` (wrapping on a torus).
#[inline]
fn before(k: usize, n: usize, periodic: bool) -> Option<usize> {
    if k > 0 {
        Some(k - 1)
    } else {
        periodic.then(|| n - 1)
    }
}

/// The neighbour index after `k` on a line of `n` (wrapping on a torus).
#[inline]
fn after(k: usize, n: usize, periodic: bool) -> Option<usize> {
    if k + 1 < n {
        Some(k + 1)
    } else {
        periodic.then_some(0)
    }
}

/// Constant `k` of the 1D schedule (see the module docs).
pub fn k1(hurst: f64, additions: bool) -> f64 {
    let k2 = 1.0 - 2f64.powf(2.0 * hurst - 2.0);
    (if additions { k2 / 2.0 } else { k2 }).sqrt()
}

/// Constant `k` of the 2D diamond-square schedule, per half step.
pub fn k2(hurst: f64, additions: bool) -> f64 {
    let k2 = 2f64.powf(-hurst) - (2.0 + 2f64.powf(hurst)) / 8.0;
    (if additions { k2 / 2.0 } else { k2 }).max(0.0).sqrt()
}

/// Refine a 1D profile by a factor 2: samples `i` of `coarse` go to `2 i`.
/// `progress` is ticked by the output samples, block by block (the caller
/// announces the total).
pub fn refine_1d(
    coarse: &[f64],
    p: &RefineParams,
    progress: Option<&Progress>,
) -> CoreResult<Vec<f64>> {
    check(p)?;
    let n = coarse.len();
    if n < 1 || (!p.periodic && n < 2) {
        return Err(CoreError::invalid(
            "coarse",
            format!("need at least 2 samples, got {n}"),
        ));
    }
    let m = if p.periodic { 2 * n } else { 2 * n - 1 };
    // delta = sigma * (s/2)^H * k: the new neighbour distance is s/2.
    let delta = p.sigma * (p.coarse_spacing / 2.0).powf(p.hurst) * k1(p.hurst, p.additions);
    let kd = key(p, PHASE_DISPLACE);
    let ka = key(p, PHASE_ADD);
    let o = p.origin.1;
    let mut out = crate::buffers::try_zeroed(m, "n")?;
    out.par_chunks_mut(1 << 12)
        .enumerate()
        .for_each(|(ci, chunk)| {
            let base = ci << 12;
            for (j, v) in chunk.iter_mut().enumerate() {
                let i = base + j;
                let g = o + i as u64;
                let mut x = if i % 2 == 0 {
                    coarse[i / 2]
                } else {
                    let a = coarse[i / 2];
                    let b = coarse[(i / 2 + 1) % n];
                    let mid = 0.5 * (a + b);
                    if p.additions {
                        mid
                    } else {
                        mid + delta * kd.normal(g)
                    }
                };
                if p.additions {
                    x += delta * ka.normal(g);
                }
                *v = x;
            }
            tick(progress, chunk.len() as u64);
        });
    Ok(out)
}

/// Refine a 2D grid by a factor 2 with the diamond-square scheme.
///
/// Non-periodic: `(r, c)` -> `(2r - 1, 2c - 1)`; periodic: `(2r, 2c)`. The
/// sample `(i, j)` of `coarse` goes to `(2i, 2j)` and is kept unchanged unless
/// `additions` is set. Edge samples of the square step average the 3
/// neighbours that exist (non-periodic). `progress` is ticked by the fine
/// grid's cells, row by row within each pass (the caller announces the
/// total).
pub fn refine_2d(
    coarse: ArrayView2<f64>,
    p: &RefineParams,
    progress: Option<&Progress>,
) -> CoreResult<Array2<f64>> {
    check(p)?;
    let (coarse, (r, c), (fr, fc)) = super::refine_input(coarse, p.periodic)?;
    let cs = super::as_slice(&coarse)?;
    let s = p.coarse_spacing;
    let kk = k2(p.hurst, p.additions);
    // Diamond step: the coarse side is s; square step: the lattice side is s / sqrt 2.
    let delta_d = p.sigma * s.powf(p.hurst) * kk;
    let delta_s = p.sigma * s.powf(p.hurst) * 2f64.powf(-p.hurst / 2.0) * kk;
    let (kd, ka, ks, kas) = (
        key(p, PHASE_DISPLACE),
        key(p, PHASE_ADD),
        key(p, PHASE_DISPLACE_SQ),
        key(p, PHASE_ADD_SQ),
    );
    let (o0, o1, gc) = (
        p.origin.0,
        p.origin.1,
        p.global_cols.max((p.origin.1) + fc as u64),
    );
    let add = p.additions;
    // Each fine row ticks its fc cells in parts over the 2 (3 with
    // additions) passes, so a level's bar moves row by row.
    let part = (fc / if add { 3 } else { 2 }) as u64;
    let (tick_a, tick_b) = (part, if add { part } else { fc as u64 - part });
    let tick_c = fc as u64 - tick_a - tick_b;

    // Pass A (diamond step): old samples and cell centres, row by row.
    let mut fine =
        crate::buffers::try_zeroed(crate::buffers::checked_len(fr, fc, "shape")?, "shape")?;
    fine.par_chunks_mut(fc).enumerate().for_each(|(i, row)| {
        let gbase = (o0 + i as u64) * gc + o1;
        let a = i / 2;
        if i % 2 == 0 {
            let crow = &cs[a * c..(a + 1) * c];
            for (b, v) in crow.iter().enumerate() {
                let j = 2 * b;
                row[j] = if add {
                    v + delta_d * ka.normal(gbase + j as u64)
                } else {
                    *v
                };
            }
        } else {
            let a1 = if a + 1 == r { 0 } else { a + 1 };
            let (r0, r1) = (&cs[a * c..(a + 1) * c], &cs[a1 * c..(a1 + 1) * c]);
            let mut j = 1;
            while j < fc {
                let b = j / 2;
                let b1 = if b + 1 == c { 0 } else { b + 1 };
                let mean = 0.25 * (r0[b] + r0[b1] + r1[b] + r1[b1]);
                let g = gbase + j as u64;
                row[j] = if add {
                    mean + delta_d * ka.normal(g)
                } else {
                    mean + delta_d * kd.normal(g)
                };
                j += 2;
            }
        }
        tick(progress, tick_a);
    });

    // Pass B (square step), in place: it writes only the samples with i + j
    // odd and reads only samples with i + j even (written by pass A), so the
    // rows can be processed in parallel through a shared pointer (row i
    // writes its own odd-parity cells only; `fine` outlives the loop).
    let ptr = SharedMut::new(&mut fine);
    let periodic = p.periodic;
    (0..fr).into_par_iter().for_each(|i| {
        let base = ptr.get();
        // SAFETY: reads target even-parity cells, writes odd-parity cells of
        // row i only; both are inside the fr * fc buffer.
        let get = |ii: usize, jj: usize| unsafe { *base.add(ii * fc + jj) };
        let gbase = (o0 + i as u64) * gc + o1;
        let (up, down) = (before(i, fr, periodic), after(i, fr, periodic));
        let mut j = if i % 2 == 0 { 1 } else { 0 };
        while j < fc {
            let (left, right) = (before(j, fc, periodic), after(j, fc, periodic));
            let (mut sum, mut cnt) = (0.0, 0.0);
            // the neighbours present, in the order up, down, left, right
            let cells = [up.map(|u| (u, j)), down.map(|d| (d, j))];
            let cells = cells
                .into_iter()
                .chain([left.map(|l| (i, l)), right.map(|r| (i, r))]);
            for (ii, jj) in cells.flatten() {
                sum += get(ii, jj);
                cnt += 1.0;
            }
            let mean = sum / cnt;
            let v = if add {
                mean
            } else {
                mean + delta_s * ks.normal(gbase + j as u64)
            };
            debug_assert!(i * fc + j < fr * fc);
            // SAFETY: (i, j) has i + j odd, a cell only row i writes in this
            // pass, and i < fr, j < fc keep it inside the fr * fc buffer.
            unsafe { *base.add(i * fc + j) = v };
            j += 2;
        }
        tick(progress, tick_b);
    });

    // Pass C: Voss's additions to every sample after the square step.
    if add {
        fine.par_chunks_mut(fc).enumerate().for_each(|(i, row)| {
            let gbase = (o0 + i as u64) * gc + o1;
            for (j, v) in row.iter_mut().enumerate() {
                *v += delta_s * kas.normal(gbase + j as u64);
            }
            tick(progress, tick_c);
        });
    }
    Array2::from_shape_vec((fr, fc), fine).map_err(|e| CoreError::Internal(e.to_string()))
}

/// Cells of the grids produced by `levels` refinements of an `(r, c)` grid
/// (the work [`refine_2d_levels`] announces).
pub(crate) fn refined_cells(
    (mut r, mut c): (usize, usize),
    levels: u32,
    periodic: bool,
    last: Option<(usize, usize)>,
) -> u64 {
    let mut total = 0u64;
    for l in 0..levels {
        (r, c) = if periodic {
            (2 * r, 2 * c)
        } else {
            (2 * r - 1, 2 * c - 1)
        };
        let (wr, wc) = match last {
            Some(w) if l + 1 == levels => w,
            _ => (r, c),
        };
        total = total.saturating_add((wr as u64).saturating_mul(wc as u64));
    }
    total
}

/// Refine `levels` times (levels numbered `base.level ..`), each time
/// halving the spacing. The global column count used for the keys is that of
/// each level's grid (origin 0). `progress` gets the cells of every level's
/// grid as total and is ticked row by row as they are computed.
pub fn refine_2d_levels(
    coarse: ArrayView2<f64>,
    levels: u32,
    base: &RefineParams,
    progress: Option<&Progress>,
) -> CoreResult<Array2<f64>> {
    add_total(
        progress,
        refined_cells(coarse.dim(), levels, base.periodic, None),
    );
    let mut grid = coarse.to_owned();
    let mut p = *base;
    for l in 0..levels {
        let (r, c) = grid.dim();
        let (fr, fc) = if p.periodic {
            (2 * r, 2 * c)
        } else {
            (2 * r - 1, 2 * c - 1)
        };
        let _ = fr;
        p.level = base.level + l;
        p.global_cols = fc as u64;
        p.origin = (0, 0);
        grid = refine_2d(grid.view(), &p, progress)?;
        p.coarse_spacing /= 2.0;
    }
    Ok(grid)
}

/// 1D counterpart of [`refine_2d_levels`]: `progress` gets the samples of
/// every level as total, ticked by blocks of samples.
pub fn refine_1d_levels(
    coarse: &[f64],
    levels: u32,
    base: &RefineParams,
    progress: Option<&Progress>,
) -> CoreResult<Vec<f64>> {
    let (mut n, mut total) = (coarse.len() as u64, 0u64);
    for _ in 0..levels {
        n = if base.periodic {
            n.saturating_mul(2)
        } else {
            n.saturating_mul(2).saturating_sub(1)
        };
        total = total.saturating_add(n);
    }
    add_total(progress, total);
    let mut x = coarse.to_vec();
    let mut p = *base;
    for l in 0..levels {
        p.level = base.level + l;
        p.origin = (0, 0);
        x = refine_1d(&x, &p, progress)?;
        p.coarse_spacing /= 2.0;
    }
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::run_in_pool;

    fn params(additions: bool, periodic: bool) -> RefineParams {
        RefineParams {
            hurst: 0.7,
            sigma: 1.0,
            coarse_spacing: 8.0,
            additions,
            periodic,
            seed: 5,
            level: 0,
            origin: (0, 0),
            global_cols: 0,
        }
    }

    #[test]
    fn counted_refinement_is_the_same_and_reaches_its_total() {
        let coarse = Array2::from_shape_fn((3, 3), |(i, j)| (i + 2 * j) as f64);
        let p = params(true, false);
        let pr = Progress::new();
        let a = run_in_pool(Some(2), || {
            refine_2d_levels(coarse.view(), 3, &p, Some(&pr))
        })
        .unwrap();
        let b = run_in_pool(Some(1), || refine_2d_levels(coarse.view(), 3, &p, None)).unwrap();
        assert_eq!(a, b);
        // 5 x 5, 9 x 9, 17 x 17
        assert_eq!((pr.done(), pr.total()), (25 + 81 + 289, 25 + 81 + 289));
    }

    #[test]
    fn one_level_ticks_every_cell_once() {
        // The per-pass parts of a row add up to its cells, with and without
        // additions, for odd and even widths; 1D likewise.
        for (additions, periodic) in [(false, false), (true, false), (true, true), (false, true)] {
            let coarse = Array2::from_shape_fn((4, 6), |(i, j)| (i * j) as f64);
            let pr = Progress::new();
            let f = run_in_pool(Some(2), || {
                refine_2d(coarse.view(), &params(additions, periodic), Some(&pr))
            })
            .unwrap();
            assert_eq!(pr.done(), f.len() as u64);
            let pr = Progress::new();
            let x = refine_1d_levels(&[0.0, 1.0, 3.0], 4, &params(additions, periodic), Some(&pr))
                .unwrap();
            // 5, 9, 17, 33 samples (periodic: 6, 12, 24, 48)
            let (last, want) = if periodic {
                (48, 6 + 12 + 24 + 48)
            } else {
                (33, 5 + 9 + 17 + 33)
            };
            assert_eq!((x.len() as u64, pr.done(), pr.total()), (last, want, want));
        }
    }

    #[test]
    fn midpoint_keeps_coarse_samples() {
        let coarse = Array2::from_shape_fn((5, 7), |(i, j)| (i * 10 + j) as f64);
        let f = refine_2d(coarse.view(), &params(false, false), None).unwrap();
        assert_eq!(f.dim(), (9, 13));
        for i in 0..5 {
            for j in 0..7 {
                assert_eq!(f[[2 * i, 2 * j]], coarse[[i, j]]);
            }
        }
        let x = refine_1d(&[1.0, 2.0, 5.0], &params(false, false), None).unwrap();
        assert_eq!((x.len(), x[0], x[2], x[4]), (5, 1.0, 2.0, 5.0));
    }

    #[test]
    fn zero_sigma_is_interpolation() {
        let coarse = Array2::from_shape_fn((3, 3), |(i, j)| (2 * i + 3 * j) as f64);
        let mut p = params(true, false);
        p.sigma = 0.0;
        let f = refine_2d(coarse.view(), &p, None).unwrap();
        // A plane is reproduced exactly by the 4-point means (interior).
        assert!((f[[1, 1]] - (1.0 + 1.5)).abs() < 1e-12);
        assert!((f[[2, 1]] - (2.0 + 1.5)).abs() < 1e-12);
    }

    #[test]
    fn thread_count_does_not_matter() {
        let coarse = Array2::<f64>::zeros((3, 3));
        let a = run_in_pool(Some(1), || {
            refine_2d_levels(coarse.view(), 6, &params(true, false), None)
        })
        .unwrap();
        let b = run_in_pool(Some(2), || {
            refine_2d_levels(coarse.view(), 6, &params(true, false), None)
        })
        .unwrap();
        assert_eq!(a, b);
        assert_eq!(a.dim(), (129, 129));
    }

    #[test]
    fn periodic_sizes() {
        let coarse = Array2::<f64>::zeros((1, 1));
        let f = refine_2d_levels(coarse.view(), 4, &params(false, true), None).unwrap();
        assert_eq!(f.dim(), (16, 16));
    }

    #[test]
    fn one_d_neighbour_variance() {
        // 1D midpoint: Var(x[i+1] - x[i]) = sigma^2 * d^{2H} at the finest level
        // when the coarse profile has it (two points at distance 1024).
        let h = 0.7;
        let mut acc = 0.0;
        let mut n = 0.0;
        for seed in 0..200u64 {
            let end = StreamKey::new(seed, 1).normal(0) * 1024f64.powf(h);
            let mut p = params(false, false);
            p.hurst = h;
            p.seed = seed;
            p.coarse_spacing = 1024.0;
            let x = refine_1d_levels(&[0.0, end], 10, &p, None).unwrap();
            for w in x.windows(2) {
                acc += (w[1] - w[0]).powi(2);
                n += 1.0;
            }
        }
        // 204,800 increments: expected 1.0 (unit spacing); the standard error
        // of the mean of squared Gaussians is sqrt(2/N_eff) with correlated
        // increments, well below 0.05.
        assert!((acc / n - 1.0).abs() < 0.05, "{}", acc / n);
    }

    #[test]
    fn bad_hurst() {
        let coarse = Array2::<f64>::zeros((2, 2));
        let mut p = params(false, false);
        p.hurst = 1.0;
        assert!(matches!(
            refine_2d(coarse.view(), &p, None),
            Err(CoreError::InvalidArgument { .. })
        ));
    }
}
