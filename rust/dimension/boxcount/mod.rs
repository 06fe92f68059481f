//! Lattice box counting of binary sets (1, 2 or 3 dimensions).
//!
//! The count at box size `s` is the number of boxes of the lattice that
//! contain at least one foreground sample (definition 4 of the paper's
//! section 2.4, Falconer 1990). Policy, the same for every size:
//!
//! * the lattice is anchored at the first foreground sample of each axis
//!   (the corner of the set's bounding box) unless [`Anchor::Array`] is asked
//!   for, so translating the set or padding the array never changes a count;
//! * boxes that reach past the last sample are counted when they hold
//!   foreground (samples outside the data are background), which is exactly
//!   the lattice count of the set: no partial box is dropped or rescaled;
//! * the lattice may be shifted by global offsets (see [`super::lattice`]) and
//!   the counts of every shift are returned, for averaging or minimum.
//!
//! All sizes are counted in about one pass over the data: the occupancy of
//! size `s` is reduced from the finest computed size that divides it.
mod bbox;
mod dyadic;
mod reduce;
mod simd;
#[cfg(test)]
mod tests;

use super::lattice::{best_source, lattice_shifts, validate_box_sizes, Shape3};
use crate::error::{CoreError, CoreResult};
use bbox::scan;
use dyadic::{dyadic_2d, dyadic_depth, Dyadic};
use reduce::{reduce_or, Grid, Src};
pub use simd::count_nonzero;

/// Where the lattice starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// At the corner of the set's bounding box (translation invariant).
    BoundingBox,
    /// At sample 0 of every axis.
    Array,
}

/// A C-contiguous 3-axis view of bytes: nonzero means foreground.
#[derive(Clone, Copy)]
pub struct ByteVolume<'a> {
    pub data: &'a [u8],
    pub shape: Shape3,
}

impl<'a> ByteVolume<'a> {
    /// Wrap a contiguous buffer of 1, 2 or 3 axes (`dims`), padding to 3 axes.
    pub fn new(data: &'a [u8], dims: &[usize]) -> CoreResult<Self> {
        if dims.is_empty() || dims.len() > 3 {
            return Err(CoreError::invalid(
                "data",
                format!("expected 1, 2 or 3 dimensions, got {}", dims.len()),
            ));
        }
        let mut shape = [1usize; 3];
        shape[3 - dims.len()..].copy_from_slice(dims);
        let n: usize = shape.iter().product();
        if n != data.len() {
            return Err(CoreError::Internal(format!(
                "buffer of {} bytes for shape {:?}",
                data.len(),
                dims
            )));
        }
        if n == 0 {
            return Err(CoreError::invalid("data", "array is empty"));
        }
        Ok(ByteVolume { data, shape })
    }
}

/// Result of [`box_count`].
#[derive(Debug, Clone, PartialEq)]
pub struct BoxCounts {
    /// The box sizes, ascending, in samples.
    pub box_sizes: Vec<usize>,
    /// The lattice shifts used (per axis of the 3-axis padded shape).
    pub shifts: Vec<Shape3>,
    /// `counts[i][j]`: occupied boxes of size `box_sizes[i]` in lattice `shifts[j]`.
    pub counts: Vec<Vec<u64>>,
    /// Number of foreground samples.
    pub n_foreground: u64,
    /// First foreground sample per axis (padded to 3 axes).
    pub bbox_min: Shape3,
    /// One past the last foreground sample per axis.
    pub bbox_max: Shape3,
}

/// Default box sizes for a set whose bounding box spans `extent` samples along
/// its longest axis.
///
/// Preferred: the sizes that divide `extent`, so that whole boxes tile the
/// bounding box at every scale (no partial box at the far edge; on a set built
/// by a b-adic construction of side b^L these are the b^k that match it),
/// thinned so that consecutive sizes differ by a factor of at least 1.4, up to
/// `extent / DEFAULT_MIN_BOXES`. Used when that gives at least 3 sizes spanning
/// a factor of 8 or more with no gap wider than a factor of 4; otherwise the
/// powers of two up to the same limit.
pub fn default_box_sizes(extent: usize) -> Vec<usize> {
    let limit = (extent / DEFAULT_MIN_BOXES).max(1);
    let mut divisors = vec![];
    for d in 1..=limit {
        if extent % d == 0
            && divisors
                .last()
                .is_none_or(|&last: &usize| d as f64 >= 1.4 * last as f64)
        {
            divisors.push(d);
        }
    }
    let max_gap = divisors
        .windows(2)
        .map(|w| w[1] as f64 / w[0] as f64)
        .fold(1.0, f64::max);
    if divisors.len() >= 3 && divisors[divisors.len() - 1] >= 8 * divisors[0] && max_gap <= 4.0 {
        return divisors;
    }
    let mut v = vec![];
    let mut s = 1usize;
    while s <= limit {
        v.push(s);
        s *= 2;
    }
    v
}

/// The coarsest default lattice has at least this many boxes across the set.
pub const DEFAULT_MIN_BOXES: usize = 4;

/// Count occupied boxes of a binary set for every box size and lattice shift.
///
/// An empty `box_sizes` asks for [`default_box_sizes`] of the set's extent.
///
/// `box_sizes` are in samples (validated: positive, at least three distinct,
/// none larger than the longest axis). `n_offsets` shifts per axis give
/// `n_offsets^ndim` lattices. Runs on the current rayon pool.
pub fn box_count(
    vol: &ByteVolume,
    ndim: usize,
    box_sizes: &[usize],
    n_offsets: usize,
    anchor: Anchor,
) -> CoreResult<BoxCounts> {
    if n_offsets == 0 {
        return Err(CoreError::invalid("offsets", "must be a positive integer"));
    }
    let max_len = *vol.shape.iter().max().unwrap_or(&0);
    let given = if box_sizes.is_empty() {
        None
    } else {
        Some(validate_box_sizes(box_sizes, max_len)?)
    };
    let empty = || CoreError::invalid("data", "the set is empty (no foreground sample)");
    // A 2D set anchored at the array, with given sizes that start a dyadic
    // chain: the unshifted lattice of the whole array is counted in one fused
    // pass, which finds the bounding box on the way (no separate scan). With
    // the bounding-box anchor the box comes first (`scan` reads dense rows
    // only up to their first and last foreground sample) and the fused pass
    // runs on it below.
    let mut pre: Option<(usize, Dyadic)> = None;
    let pre_depth = match &given {
        Some(sz) if vol.shape[0] == 1 && anchor == Anchor::Array => dyadic_depth(sz, vol.shape[1]),
        _ => 0,
    };
    let (bmin, bmax) = if pre_depth > 0 {
        let [_, n1, n2] = vol.shape;
        let full = Src {
            data: vol.data,
            start: 0,
            strides: [n1 * n2, n2],
            shape: vol.shape,
        };
        let d = dyadic_2d(&full, pre_depth);
        let (lo, hi) = d.bbox.ok_or_else(empty)?;
        pre = Some((pre_depth, d));
        ([0, lo[0], lo[1]], [1, hi[0], hi[1]])
    } else {
        scan(vol).ok_or_else(empty)?
    };
    // the number of foreground samples (the count at size 1) comes from the
    // first reduction of the data, which reads every sample once
    let mut n_fg: Option<u64> = None;
    let sizes = match given {
        Some(sz) => sz,
        None => {
            let extent = (0..3).map(|a| bmax[a] - bmin[a]).max().unwrap_or(1);
            validate_box_sizes(&default_box_sizes(extent), max_len).map_err(|_| {
                CoreError::invalid(
                    "data",
                    format!("the set spans only {extent} samples: too small for the default box sizes (give box_sizes)"),
                )
            })?
        }
    };
    let (lo, hi) = match anchor {
        Anchor::BoundingBox => (bmin, bmax),
        Anchor::Array => ([0; 3], vol.shape),
    };
    let shape = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let [_, n1, n2] = vol.shape;
    let base = Src {
        data: vol.data,
        start: lo[0] * n1 * n2 + lo[1] * n2 + lo[2],
        strides: [n1 * n2, n2],
        shape,
    };
    let s_max = *sizes.last().unwrap();
    let shifts = lattice_shifts(ndim, n_offsets, s_max);
    let mut counts = vec![vec![0u64; shifts.len()]; sizes.len()];
    for (j, g) in shifts.iter().enumerate() {
        // computed grids of this lattice, by size (ascending)
        let mut done: Vec<usize> = Vec::new();
        let mut grids: Vec<Grid> = Vec::new();
        // 2D, unshifted lattice: sizes 2, 4, ..., 2^k in one fused pass
        let fused = if *g != [0; 3] || vol.shape[0] != 1 {
            None
        } else if let Some(kd) = pre.take() {
            // counted on the whole array, which is this lattice's origin
            Some(kd)
        } else {
            let k = dyadic_depth(&sizes, shape[1]);
            (k > 0).then(|| (k, dyadic_2d(&base, k)))
        };
        let fused = match fused {
            Some((k, d)) => {
                for (l, c) in d.counts.into_iter().enumerate() {
                    let i = sizes.binary_search(&(2 << l)).map_err(|_| {
                        CoreError::Internal("dyadic size missing from the size list".into())
                    })?;
                    counts[i][j] = c;
                }
                n_fg.get_or_insert(d.n_fg);
                done.push(1 << k);
                grids.push(d.grid);
                k
            }
            None => 0,
        };
        for (i, &s) in sizes.iter().enumerate() {
            if s == 1 || (s.is_power_of_two() && s <= 1 << fused) {
                continue; // size 1 is filled in below from n_fg
            }
            let t = best_source(s, &done);
            let m_ = s / t;
            let mut m = [1usize; 3];
            let mut c = [0usize; 3];
            for a in (3 - ndim)..3 {
                m[a] = m_;
                c[a] = ((g[a] % s) - (g[a] % t)) / t;
            }
            let (grid, cnt) = if t == 1 {
                let (g, cnt, read) = reduce_or(&base, m, c);
                n_fg.get_or_insert(read);
                (g, cnt)
            } else {
                let k = done.iter().position(|&d| d == t).unwrap();
                let gsrc = &grids[k];
                let src = Src {
                    data: &gsrc.data,
                    start: 0,
                    strides: [gsrc.shape[1] * gsrc.shape[2], gsrc.shape[2]],
                    shape: gsrc.shape,
                };
                let (g, cnt, _) = reduce_or(&src, m, c);
                (g, cnt)
            };
            counts[i][j] = cnt;
            // keep `done` ascending (best_source takes the largest divisor)
            let pos = done.partition_point(|&d| d < s);
            done.insert(pos, s);
            grids.insert(pos, grid);
        }
    }
    let n_fg =
        n_fg.ok_or_else(|| CoreError::Internal("no reduction of the data was made".into()))?;
    if sizes[0] == 1 {
        counts[0].iter_mut().for_each(|c| *c = n_fg);
    }
    Ok(BoxCounts {
        box_sizes: sizes,
        shifts,
        counts,
        n_foreground: n_fg,
        bbox_min: bmin,
        bbox_max: bmax,
    })
}
