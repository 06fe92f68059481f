//! Block-OR reduction of an occupancy grid by integer factors.
use super::simd::{count_nonzero, pair_or_into};
use crate::dimension::lattice::{box_range, n_boxes, Shape3};
use rayon::prelude::*;

/// An occupancy grid: one byte per box, C order, 3 axes.
pub(super) struct Grid {
    pub(super) data: Vec<u8>,
    pub(super) shape: Shape3,
}

/// Source of a reduction: a strided window of a byte buffer.
pub(super) struct Src<'a> {
    pub(super) data: &'a [u8],
    pub(super) start: usize,
    pub(super) strides: [usize; 2], // strides of axes 0 and 1; axis 2 is contiguous
    pub(super) shape: Shape3,
}

/// Block-OR reduction of `src` by factors `m` and shifts `c` per axis.
/// Returns the reduced grid and its number of occupied boxes.
/// Also returns the number of nonzero source bytes read (every source byte
/// lies in exactly one box, so this is the source's count).
pub(super) fn reduce_or(src: &Src, m: Shape3, c: Shape3) -> (Grid, u64, u64) {
    let out_shape = [
        n_boxes(src.shape[0], m[0], c[0]),
        n_boxes(src.shape[1], m[1], c[1]),
        n_boxes(src.shape[2], m[2], c[2]),
    ];
    let n2 = src.shape[2];
    let o2 = out_shape[2];
    let mut out = vec![0u8; out_shape[0] * out_shape[1] * o2];
    let (count, src_count): (u64, u64) = out
        .par_chunks_mut(o2)
        .enumerate()
        .with_min_len((1 << 14) / (n2 * m[0] * m[1]).max(1) + 1)
        .map_init(
            || vec![0u8; n2],
            |acc, (idx, orow)| {
                let (b0, b1) = (idx / out_shape[1], idx % out_shape[1]);
                let (lo0, hi0) = box_range(b0, m[0], c[0], src.shape[0]);
                let (lo1, hi1) = box_range(b1, m[1], c[1], src.shape[1]);
                let rows = (lo0..hi0).flat_map(|i| (lo1..hi1).map(move |j| (i, j)));
                let row_at = |(i, j): (usize, usize)| {
                    let off = src.start + i * src.strides[0] + j * src.strides[1];
                    &src.data[off..off + n2]
                };
                let mut read = 0u64;
                if m[2] == 2 {
                    // Fast path of the dyadic pyramid: OR byte pairs of every source
                    // row straight into the output row (word-wise; no accumulator).
                    for (k, ij) in rows.enumerate() {
                        let row = row_at(ij);
                        read += count_nonzero(row);
                        pair_or_into(row, c[2], orow, k == 0);
                    }
                    return (count_nonzero(orow), read);
                }
                acc.iter_mut().for_each(|a| *a = 0);
                for ij in rows {
                    let row = row_at(ij);
                    read += count_nonzero(row);
                    for (a, &v) in acc.iter_mut().zip(row) {
                        *a |= v;
                    }
                }
                let mut cnt = 0u64;
                if m[2] == 1 && c[2] == 0 {
                    for (o, &a) in orow.iter_mut().zip(acc.iter()) {
                        *o = (a != 0) as u8;
                        cnt += *o as u64;
                    }
                } else {
                    for (b2, o) in orow.iter_mut().enumerate() {
                        let (lo, hi) = box_range(b2, m[2], c[2], n2);
                        *o = acc[lo..hi].iter().any(|&v| v != 0) as u8;
                        cnt += *o as u64;
                    }
                }
                (cnt, read)
            },
        )
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    (
        Grid {
            data: out,
            shape: out_shape,
        },
        count,
        src_count,
    )
}
