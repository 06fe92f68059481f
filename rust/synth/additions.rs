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
use super::rng::StreamKey;
use crate::error::{CoreError, CoreResult};
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
    StreamKey::new(p.seed, STREAM_BASE + (p.level as u64) * 8 + phase)
}

fn check(p: &AdditionsParams) -> CoreResult<()> {
    if !(p.hurst > 0.0 && p.hurst < 1.0) {
        return Err(CoreError::invalid(
            "hurst",
            format!("expected a number in (0, 1), got {}", p.hurst),
        ));
    }
    if !(p.sigma.is_finite() && p.sigma >= 0.0) {
        return Err(CoreError::invalid(
            "sigma",
            format!("expected a finite number >= 0, got {}", p.sigma),
        ));
    }
    if !(p.coarse_spacing.is_finite() && p.coarse_spacing > 0.0) {
        return Err(CoreError::invalid(
            "coarse_spacing",
            format!("expected a positive number, got {}", p.coarse_spacing),
        ));
    }
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

/// Pad a grid by 2 on every side: wrap-around (periodic) or linear
/// extrapolation (`x[-k] = x[0] + k (x[0] - x[1])`; constant for 1 sample).
fn pad2(g: &[f64], r: usize, c: usize, periodic: bool) -> Vec<f64> {
    let (pr, pc) = (r + 4, c + 4);
    let mut out = vec![0.0; pr * pc];
    // Values at -2, -1 and n, n+1 of a line `v` of length n.
    let ends = |v0: f64, v1: f64, w1: f64, w0: f64, n: usize| -> [f64; 4] {
        // v0 = v[0], v1 = v[1], w1 = v[n-2], w0 = v[n-1]
        if n == 1 {
            [v0; 4]
        } else {
            let (d0, d1) = (v0 - v1, w0 - w1);
            [v0 + 2.0 * d0, v0 + d0, w0 + d1, w0 + 2.0 * d1]
        }
    };
    out[2 * pc..(r + 2) * pc]
        .par_chunks_mut(pc)
        .enumerate()
        .for_each(|(i, dst)| {
            let row = &g[i * c..(i + 1) * c];
            dst[2..c + 2].copy_from_slice(row);
            let e = if periodic {
                [row[(2 * c - 2) % c], row[c - 1], row[0], row[1 % c]]
            } else {
                ends(
                    row[0],
                    row[c.min(2) - 1],
                    row[c.saturating_sub(2)],
                    row[c - 1],
                    c,
                )
            };
            dst[0] = e[0];
            dst[1] = e[1];
            dst[c + 2] = e[2];
            dst[c + 3] = e[3];
        });
    // Padded rows -2, -1, r, r+1 from whole padded rows.
    let src = |k: usize| (k + 2) * pc; // start of padded row of original row k
    let mut extra = vec![0.0; 4 * pc];
    for jj in 0..pc {
        let e = if periodic {
            [
                out[src((2 * r - 2) % r) + jj],
                out[src(r - 1) + jj],
                out[src(0) + jj],
                out[src(1 % r) + jj],
            ]
        } else {
            ends(
                out[src(0) + jj],
                out[src(r.min(2) - 1) + jj],
                out[src(r.saturating_sub(2)) + jj],
                out[src(r - 1) + jj],
                r,
            )
        };
        for (t, v) in e.iter().enumerate() {
            extra[t * pc + jj] = *v;
        }
    }
    for (t, ii) in [0usize, 1, r + 2, r + 3].iter().enumerate() {
        out[ii * pc..(ii + 1) * pc].copy_from_slice(&extra[t * pc..(t + 1) * pc]);
    }
    out
}

/// One level: `(r, c) -> (2r - 1, 2c - 1)` (periodic: `(2r, 2c)`).
pub fn refine_2d(coarse: ArrayView2<f64>, p: &AdditionsParams) -> CoreResult<Array2<f64>> {
    check(p)?;
    let (r, c) = coarse.dim();
    if !p.periodic && (r < 2 || c < 2) {
        return Err(CoreError::invalid(
            "coarse",
            format!("need at least 2 x 2 samples, got {r} x {c}"),
        ));
    }
    if r < 1 || c < 1 {
        return Err(CoreError::invalid("coarse", "empty grid"));
    }
    let coarse = coarse.as_standard_layout();
    let cs: &[f64] = coarse
        .as_slice()
        .ok_or_else(|| CoreError::Internal("coarse grid not contiguous".into()))?;
    let (fr, fc) = if p.periodic {
        (2 * r, 2 * c)
    } else {
        (2 * r - 1, 2 * c - 1)
    };
    // Centres: (nr, nc) of them at fine (2a+1, 2b+1).
    let (nr, nc) = if p.periodic { (r, c) } else { (r - 1, c - 1) };
    let scale = p.sigma * p.coarse_spacing.powf(p.hurst);
    let sd = p.variances.map(|v| scale * v.sqrt());
    let (sd_a2, sd_c1, sd_c2, sd_e) = (sd[0], sd[1], sd[2], sd[3]);
    let w = p.tension;
    let wt = [-w, 0.5 + w, 0.5 + w, -w];
    let (kc1, kc2, ka2, ke) = (key(p, PH_C1), key(p, PH_C2), key(p, PH_A2), key(p, PH_E));
    let (o0, o1) = p.origin;
    let gc = p.global_cols.max(o1 + fc as u64);
    let gidx = |i: usize, j: usize| (o0 + i as u64) * gc + o1 + j as u64;

    let cp = pad2(cs, r, c, p.periodic);
    let pc = c + 4;
    // Diamond step: centres from the 4 x 4 old samples, plus c1.
    let mut cen = vec![0.0; nr * nc];
    cen.par_chunks_mut(nc).enumerate().for_each(|(a, row)| {
        for (b, v) in row.iter_mut().enumerate() {
            let mut s = 0.0;
            for (pi, wi) in wt.iter().enumerate() {
                let base = (a + 1 + pi) * pc + b + 1;
                let line = wt[0] * cp[base]
                    + wt[1] * cp[base + 1]
                    + wt[2] * cp[base + 2]
                    + wt[3] * cp[base + 3];
                s += wi * line;
            }
            *v = s + sd_c1 * kc1.normal(gidx(2 * a + 1, 2 * b + 1));
        }
    });
    let ep = pad2(&cen, nr, nc, p.periodic);
    let pn = nc + 4;

    let mut fine = vec![0.0f64; fr * fc];
    fine.par_chunks_mut(fc).enumerate().for_each(|(i, row)| {
        let a = i / 2;
        if i % 2 == 0 {
            // Old samples (+ a2) and edges (2a, 2b+1).
            let crow = (a + 2) * pc;
            for (j, v) in row.iter_mut().enumerate() {
                let b = j / 2;
                let g = gidx(i, j);
                *v = if j % 2 == 0 {
                    cs[a * c + b] + sd_a2 * ka2.normal(g)
                } else {
                    let k = crow + b + 1; // old b-1 .. b+2
                    let hor =
                        wt[0] * cp[k] + wt[1] * cp[k + 1] + wt[2] * cp[k + 2] + wt[3] * cp[k + 3];
                    // centres a-2 .. a+1 at column b -> padded rows a .. a+3
                    let col = b + 2;
                    let ver = wt[0] * ep[a * pn + col]
                        + wt[1] * ep[(a + 1) * pn + col]
                        + wt[2] * ep[(a + 2) * pn + col]
                        + wt[3] * ep[(a + 3) * pn + col];
                    0.5 * (hor + ver) + sd_e * ke.normal(g)
                };
            }
        } else {
            // Centres (+ c2) and edges (2a+1, 2b).
            let erow = (a + 2) * pn;
            for (j, v) in row.iter_mut().enumerate() {
                let b = j / 2;
                let g = gidx(i, j);
                *v = if j % 2 == 1 {
                    cen[a * nc + b] + sd_c2 * kc2.normal(g)
                } else {
                    // old a-1 .. a+2 at column b -> padded rows a+1 .. a+4
                    let col = b + 2;
                    let ver = wt[0] * cp[(a + 1) * pc + col]
                        + wt[1] * cp[(a + 2) * pc + col]
                        + wt[2] * cp[(a + 3) * pc + col]
                        + wt[3] * cp[(a + 4) * pc + col];
                    // centres b-2 .. b+1 in row a -> padded columns b .. b+3
                    let k = erow + b;
                    let hor =
                        wt[0] * ep[k] + wt[1] * ep[k + 1] + wt[2] * ep[k + 2] + wt[3] * ep[k + 3];
                    0.5 * (hor + ver) + sd_e * ke.normal(g)
                };
            }
        }
    });
    Array2::from_shape_vec((fr, fc), fine).map_err(|e| CoreError::Internal(e.to_string()))
}

/// Refine `levels` times (levels numbered from `base.level`), halving the
/// spacing each time; keys use the final grid of each level (origin 0).
pub fn refine_2d_levels(
    coarse: ArrayView2<f64>,
    levels: u32,
    base: &AdditionsParams,
) -> CoreResult<Array2<f64>> {
    check(base)?;
    let mut grid = coarse.to_owned();
    let mut p = *base;
    for l in 0..levels {
        let (r, c) = grid.dim();
        let fc = if p.periodic { 2 * c } else { 2 * c - 1 };
        let _ = r;
        p.level = base.level + l;
        p.global_cols = fc as u64;
        p.origin = (0, 0);
        grid = refine_2d(grid.view(), &p)?;
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
        let f = refine_2d(coarse.view(), &p).unwrap();
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
        let f = refine_2d(coarse.view(), &p).unwrap();
        assert_eq!(f.dim(), (6, 8));
        for i in 0..3 {
            for j in 0..4 {
                assert_eq!(f[[2 * i, 2 * j]], coarse[[i, j]]);
            }
        }
        // A constant field stays constant on the torus.
        let k = Array2::from_elem((4, 4), 2.5);
        let g = refine_2d(k.view(), &p).unwrap();
        assert!(g.iter().all(|v| (v - 2.5).abs() < 1e-12));
    }

    #[test]
    fn thread_count_does_not_matter() {
        let coarse = Array2::<f64>::zeros((3, 3));
        let a = run_in_pool(Some(1), || {
            refine_2d_levels(coarse.view(), 5, &params(false))
        })
        .unwrap();
        let b = run_in_pool(Some(2), || {
            refine_2d_levels(coarse.view(), 5, &params(false))
        })
        .unwrap();
        assert_eq!(a, b);
        assert_eq!(a.dim(), (65, 65));
    }

    #[test]
    fn bad_arguments() {
        let coarse = Array2::<f64>::zeros((2, 2));
        let mut p = params(false);
        p.variances[2] = -1.0;
        assert!(matches!(
            refine_2d(coarse.view(), &p),
            Err(CoreError::InvalidArgument { .. })
        ));
        let mut p = params(false);
        p.tension = f64::NAN;
        assert!(refine_2d(coarse.view(), &p).is_err());
        let one = Array2::<f64>::zeros((1, 3));
        assert!(refine_2d(one.view(), &params(false)).is_err());
    }
}
