//! Per-column height ranges for self-affine (anisotropic) box counting of
//! graphs of functions: profiles `z(x)` and surfaces `z(x, y)` (paper section
//! 2.4: boxes scaled by `alpha` horizontally and `alpha^H` vertically).
//!
//! The graph is taken as the continuous piecewise-linear (profile) or
//! piecewise-bilinear (surface) interpolant of the samples, so the column over
//! the closed interval `[i s, i s + s]` (and its square in 2D) spans exactly the
//! height range `[min, max]` of the `s + 1` (or `(s + 1)^2`) samples it holds.
//! Averaged over vertical placements of the lattice, that column needs
//! `range / delta + 1` boxes of height `delta`. Only complete columns are used.
//! The caller turns the mean ranges into counts for a trial `H` and solves for
//! the `H` at which counts scale as `alpha^-d` (self-affine invariance).
use super::dbc::nan_minmax;
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

/// Mean height range of complete columns of width `s` (samples), and their number.
///
/// `data` is row-major `rows x cols`; a profile has `rows == 1`. NaN values are
/// skipped; columns with fewer than two valid samples are not used.
pub fn column_ranges(
    data: &[f64],
    rows: usize,
    cols: usize,
    box_sizes: &[usize],
) -> CoreResult<(Vec<f64>, Vec<u64>)> {
    if rows * cols == 0 || data.len() != rows * cols {
        return Err(CoreError::invalid("data", "array is empty"));
    }
    let profile = rows == 1;
    let mut means = Vec::with_capacity(box_sizes.len());
    let mut counts = Vec::with_capacity(box_sizes.len());
    for &s in box_sizes {
        if s == 0 {
            return Err(CoreError::invalid(
                "box_sizes",
                "box sizes must be positive integers",
            ));
        }
        let nc = (cols - 1) / s;
        let nr = if profile { 1 } else { (rows - 1) / s };
        if nc == 0 || nr == 0 {
            return Err(CoreError::invalid(
                "box_sizes",
                format!("box size {s} leaves no complete column in data of shape ({rows}, {cols})"),
            ));
        }
        // per block row in parallel, summed in row order: a float reduce
        // in rayon's order would depend on the thread count and scheduling
        let per_row: Vec<(f64, u64)> = (0..nr)
            .into_par_iter()
            .map(|bi| {
                let (r0, r1) = if profile {
                    (0, 1)
                } else {
                    (bi * s, bi * s + s + 1)
                };
                let mut sum = 0.0f64;
                let mut n = 0u64;
                for bj in 0..nc {
                    let (c0, c1) = (bj * s, bj * s + s + 1);
                    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                    let mut valid = 0usize;
                    for r in r0..r1 {
                        let seg = &data[r * cols + c0..r * cols + c1];
                        valid += seg.iter().filter(|v| !v.is_nan()).count();
                        let (a, b) = nan_minmax(seg);
                        lo = lo.min(a);
                        hi = hi.max(b);
                    }
                    if valid >= 2 {
                        sum += hi - lo;
                        n += 1;
                    }
                }
                (sum, n)
            })
            .collect();
        let (sum, n) = per_row.iter().fold((0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        if n == 0 {
            return Err(CoreError::invalid(
                "data",
                format!("no column of width {s} has two valid samples"),
            ));
        }
        means.push(sum / n as f64);
        counts.push(n);
    }
    Ok((means, counts))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_profile_range_is_slope_times_width() {
        let z: Vec<f64> = (0..101).map(|i| 0.5 * i as f64).collect();
        let (m, n) = column_ranges(&z, 1, 101, &[1, 4, 10]).unwrap();
        assert_eq!(m, vec![0.5, 2.0, 5.0]);
        assert_eq!(n, vec![100, 25, 10]);
    }

    #[test]
    fn plane_surface_range() {
        let (rows, cols) = (9usize, 17usize);
        let z: Vec<f64> = (0..rows * cols)
            .map(|p| (p / cols) as f64 + 2.0 * (p % cols) as f64)
            .collect();
        let (m, n) = column_ranges(&z, rows, cols, &[1, 2, 4]).unwrap();
        assert_eq!(m, vec![3.0, 6.0, 12.0]);
        assert_eq!(n, vec![8 * 16, 4 * 8, 2 * 4]);
    }
}
