//! The bounding box of the foreground.
use super::simd::{first_nonzero, last_nonzero};
use super::ByteVolume;
use crate::dimension::lattice::Shape3;
use rayon::prelude::*;

/// Bounding box of the foreground (first sample and one past the last, per
/// axis), or None for an empty set. Rows stop at their first and last
/// foreground byte, so dense sets are scanned in a fraction of a pass.
pub(super) fn scan(vol: &ByteVolume) -> Option<(Shape3, Shape3)> {
    let [_, n1, n2] = vol.shape;
    let init = || ([usize::MAX; 3], [0usize; 3]);
    let (lo, hi) = vol
        .data
        .par_chunks(n2)
        .enumerate()
        .with_min_len((4096 / n2).max(1))
        .fold(init, |(mut lo, mut hi), (r, row)| {
            let Some(first) = first_nonzero(row) else {
                return (lo, hi);
            };
            let last = last_nonzero(row).unwrap_or(first);
            let (i0, i1) = (r / n1, r % n1);
            lo = [lo[0].min(i0), lo[1].min(i1), lo[2].min(first)];
            hi = [hi[0].max(i0 + 1), hi[1].max(i1 + 1), hi[2].max(last + 1)];
            (lo, hi)
        })
        .reduce(init, |a, b| {
            (
                [a.0[0].min(b.0[0]), a.0[1].min(b.0[1]), a.0[2].min(b.0[2])],
                [a.1[0].max(b.1[0]), a.1[1].max(b.1[1]), a.1[2].max(b.1[2])],
            )
        });
    if lo[0] == usize::MAX {
        None
    } else {
        Some((lo, hi))
    }
}
