//! Differential box counting (DBC) of grayscale images and DEMs
//! (Sarkar and Chaudhuri 1994).
//!
//! The image is a surface `z(i, j)`. For box size `s` (pixels) the plane is cut
//! into `s x s` blocks of a lattice anchored at pixel (0, 0) (optionally shifted,
//! see [`super::lattice`]) and each block column is stacked with boxes of
//! height `h = s * z_unit`. A block whose valid values have minimum `zmin` and
//! maximum `zmax` needs `floor((zmax - z0)/h) - floor((zmin - z0)/h) + 1` boxes;
//! `N(s)` is the sum over blocks holding at least one valid (non-NaN) value.
//! Blocks that reach past the image edge are counted with the pixels they
//! hold, like the binary counter. NaN marks nodata and is skipped.
use super::lattice::{best_source, box_range, lattice_shifts, n_boxes, validate_box_sizes, Shape3};
use crate::error::{CoreError, CoreResult};
pub use crate::sample::Sample;
use rayon::prelude::*;

/// Minimum and maximum per block; empty blocks hold (+inf, -inf).
pub(crate) struct MinMax {
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    pub shape: [usize; 2],
}

/// Fold one source row into the block minima/maxima of its block row.
///
/// Block `b` covers source columns `[b m - c, (b + 1) m - c)` (clipped), as
/// [`box_range`]; `lo_row`/`hi_row` are the row's minima/maxima (the same
/// slice for raw data). `f64::min`/`max` skip NaN.
#[inline]
fn fold_row<T: Sample>(
    lo_row: &[T],
    hi_row: &[T],
    m: usize,
    c: usize,
    lrow: &mut [f64],
    hrow: &mut [f64],
) {
    let len = lo_row.len();
    if c == 0 && m == 2 {
        // the finest level dominates the cost: a branch-free pairwise loop
        let full = len / 2;
        for (b, (l, h)) in lo_row
            .chunks_exact(2)
            .zip(hi_row.chunks_exact(2))
            .enumerate()
        {
            lrow[b] = lrow[b].min(l[0].to_f64().min(l[1].to_f64()));
            hrow[b] = hrow[b].max(h[0].to_f64().max(h[1].to_f64()));
        }
        if len % 2 == 1 {
            lrow[full] = lrow[full].min(lo_row[len - 1].to_f64());
            hrow[full] = hrow[full].max(hi_row[len - 1].to_f64());
        }
        return;
    }
    let (mut k, mut b) = (0usize, 0usize);
    while k < len {
        let end = ((b + 1) * m - c).min(len);
        let (mut a, mut z) = (lrow[b], hrow[b]);
        for i in k..end {
            a = a.min(lo_row[i].to_f64());
            z = z.max(hi_row[i].to_f64());
        }
        lrow[b] = a;
        hrow[b] = z;
        k = end;
        b += 1;
    }
}

/// Block min/max by factor `m`, shift `c` of a row-major `rows x cols`
/// source given as per-row minima and maxima (`row(r) -> (lo, hi)`).
fn reduce_minmax<'a, T, F>(rows: usize, cols: usize, m: usize, c: [usize; 2], row: F) -> MinMax
where
    T: Sample + 'a,
    F: Fn(usize) -> (&'a [T], &'a [T]) + Sync,
{
    let shape = [n_boxes(rows, m, c[0]), n_boxes(cols, m, c[1])];
    let mut lo = vec![f64::INFINITY; shape[0] * shape[1]];
    let mut hi = vec![f64::NEG_INFINITY; shape[0] * shape[1]];
    lo.par_chunks_mut(shape[1])
        .zip(hi.par_chunks_mut(shape[1]))
        .enumerate()
        .for_each(|(b0, (lrow, hrow))| {
            let (r0, r1) = box_range(b0, m, c[0], rows);
            for r in r0..r1 {
                let (l, h) = row(r);
                fold_row(&l[..cols], &h[..cols], m, c[1], lrow, hrow);
            }
        });
    MinMax { lo, hi, shape }
}

/// Min and max of the valid (non-NaN) values of a slice; (+inf, -inf) if none.
#[inline]
pub(crate) fn nan_minmax<T: Sample>(v: &[T]) -> (f64, f64) {
    let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
    for &x in v {
        let x = x.to_f64();
        // NaN compares false both ways, so it never updates a or b.
        if x < a {
            a = x;
        }
        if x > b {
            b = x;
        }
    }
    (a, b)
}

/// Result of [`dbc_count`].
#[derive(Debug, Clone, PartialEq)]
pub struct DbcCounts {
    pub box_sizes: Vec<usize>,
    pub shifts: Vec<Shape3>,
    /// `counts[i][j]`: N(s) for size `box_sizes[i]` and lattice `shifts[j]`.
    pub counts: Vec<Vec<f64>>,
}

/// Differential box counts of a row-major `rows x cols` image.
///
/// `z0` is the reference height of the box stacks (usually the minimum valid
/// value) and `z_unit` the box height per pixel of box size, in data units
/// (`h = s * z_unit`). Runs on the current rayon pool.
pub fn dbc_count<T: Sample>(
    data: &[T],
    rows: usize,
    cols: usize,
    box_sizes: &[usize],
    n_offsets: usize,
    z0: f64,
    z_unit: f64,
) -> CoreResult<DbcCounts> {
    if rows * cols == 0 || data.len() != rows * cols {
        return Err(CoreError::invalid("data", "image is empty"));
    }
    crate::checks::positive_finite(z_unit, "z_scale")?;
    if !z0.is_finite() {
        return Err(CoreError::invalid(
            "data",
            "no valid (non-NaN, finite) value",
        ));
    }
    if n_offsets == 0 {
        return Err(CoreError::invalid("offsets", "must be a positive integer"));
    }
    let sizes = validate_box_sizes(box_sizes, rows.max(cols))?;
    if sizes[0] < 2 {
        return Err(CoreError::invalid(
            "box_sizes",
            format!(
                "DBC needs block sides of at least 2 pixels (a 1-pixel block spans no \
                 height range: it always holds one box), got {sizes:?}"
            ),
        ));
    }
    let shifts = lattice_shifts(2, n_offsets, *sizes.last().unwrap());
    let mut counts = vec![vec![0f64; shifts.len()]; sizes.len()];
    for (j, g) in shifts.iter().enumerate() {
        let mut done: Vec<usize> = Vec::new();
        let mut grids: Vec<MinMax> = Vec::new();
        for (i, &s) in sizes.iter().enumerate() {
            let t = best_source(s, &done);
            let m = s / t;
            let c = [((g[1] % s) - (g[1] % t)) / t, ((g[2] % s) - (g[2] % t)) / t];
            let mm = if t == 1 {
                reduce_minmax(rows, cols, m, c, |r| {
                    let row = &data[r * cols..(r + 1) * cols];
                    (row, row)
                })
            } else {
                let k = done.iter().position(|&d| d == t).unwrap();
                let src = &grids[k];
                let w = src.shape[1];
                reduce_minmax(src.shape[0], w, m, c, |r| {
                    (&src.lo[r * w..(r + 1) * w], &src.hi[r * w..(r + 1) * w])
                })
            };
            let h = s as f64 * z_unit;
            counts[i][j] = mm
                .lo
                .par_iter()
                .zip(mm.hi.par_iter())
                .filter(|(a, b)| a <= b)
                .map(|(&a, &b)| ((b - z0) / h).floor() - ((a - z0) / h).floor() + 1.0)
                .sum::<f64>();
            done.push(s);
            grids.push(mm);
        }
    }
    Ok(DbcCounts {
        box_sizes: sizes,
        shifts,
        counts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn naive(data: &[f64], rows: usize, cols: usize, s: usize, z0: f64, zu: f64) -> f64 {
        let h = s as f64 * zu;
        let mut n = 0.0;
        for bi in 0..rows.div_ceil(s) {
            for bj in 0..cols.div_ceil(s) {
                let mut v = vec![];
                for r in bi * s..((bi + 1) * s).min(rows) {
                    for c in bj * s..((bj + 1) * s).min(cols) {
                        if !data[r * cols + c].is_nan() {
                            v.push(data[r * cols + c]);
                        }
                    }
                }
                if !v.is_empty() {
                    let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
                    let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
                    n += ((hi - z0) / h).floor() - ((lo - z0) / h).floor() + 1.0;
                }
            }
        }
        n
    }

    #[test]
    fn matches_naive_with_nan_holes() {
        for (seed, (rows, cols)) in [(17usize, 23usize), (32, 32), (5, 40), (64, 33)]
            .into_iter()
            .enumerate()
        {
            let data: Vec<f64> = crate::testdata::uniform(rows * cols, 11 + seed as u64)
                .into_iter()
                .map(|u| if u < 0.1 { f64::NAN } else { u * 50.0 })
                .collect();
            let sizes = [2usize, 3, 4, 6, 8, 12, 16];
            let sizes: Vec<usize> = sizes.into_iter().filter(|&s| s <= rows.max(cols)).collect();
            let r = dbc_count(&data, rows, cols, &sizes, 1, 0.0, 0.7).unwrap();
            for (i, &s) in r.box_sizes.iter().enumerate() {
                assert_eq!(
                    r.counts[i][0],
                    naive(&data, rows, cols, s, 0.0, 0.7),
                    "s={s} {rows}x{cols}"
                );
            }
        }
    }

    #[test]
    fn flat_image_counts_one_box_per_block() {
        let data = vec![3.0f32; 40 * 40];
        let r = dbc_count(&data, 40, 40, &[2, 4, 8], 1, 3.0, 1.0).unwrap();
        assert_eq!(r.counts, vec![vec![400.0], vec![100.0], vec![25.0]]);
    }
}
