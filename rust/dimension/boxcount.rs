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
use super::lattice::{best_source, box_range, lattice_shifts, n_boxes, validate_box_sizes, Shape3};
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

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

/// An occupancy grid: one byte per box, C order, 3 axes.
struct Grid {
    data: Vec<u8>,
    shape: Shape3,
}

/// Source of a reduction: a strided window of a byte buffer.
struct Src<'a> {
    data: &'a [u8],
    start: usize,
    strides: [usize; 2], // strides of axes 0 and 1; axis 2 is contiguous
    shape: Shape3,
}

/// Index of the first nonzero byte, scanning eight bytes at a time.
#[inline]
fn first_nonzero(row: &[u8]) -> Option<usize> {
    let words = row.chunks_exact(8);
    let rem_start = row.len() - words.remainder().len();
    for (k, w) in words.enumerate() {
        let v = u64::from_le_bytes(w.try_into().unwrap());
        if v != 0 {
            return Some(k * 8 + (v.trailing_zeros() / 8) as usize);
        }
    }
    row[rem_start..]
        .iter()
        .position(|&v| v != 0)
        .map(|p| rem_start + p)
}

/// Index of the last nonzero byte, scanning eight bytes at a time from the end.
#[inline]
fn last_nonzero(row: &[u8]) -> Option<usize> {
    let words = row.rchunks_exact(8);
    let rem_len = words.remainder().len();
    for (k, w) in words.enumerate() {
        let v = u64::from_le_bytes(w.try_into().unwrap());
        if v != 0 {
            return Some(row.len() - 8 * (k + 1) + 7 - (v.leading_zeros() / 8) as usize);
        }
    }
    row[..rem_len].iter().rposition(|&v| v != 0)
}

/// Bounding box of the foreground (first sample and one past the last, per
/// axis), or None for an empty set. Rows stop at their first and last
/// foreground byte, so dense sets are scanned in a fraction of a pass.
fn scan(vol: &ByteVolume) -> Option<(Shape3, Shape3)> {
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

/// Number of nonzero bytes (vectorises: bytes are mapped to 0/1 and summed in chunks).
#[inline]
pub fn count_nonzero(row: &[u8]) -> u64 {
    let mut total = 0u64;
    for chunk in row.chunks(255 * 32) {
        let mut acc = [0u8; 32];
        for block in chunk.chunks(32) {
            for (a, &b) in acc.iter_mut().zip(block) {
                *a += (b != 0) as u8;
            }
        }
        // a lane sees at most chunk.len() / 32 <= 255 values of 0 or 1: no overflow
        total += acc.iter().map(|&x| x as u64).sum::<u64>();
    }
    total
}

/// OR of the byte pairs of a little-endian word: bytes (b0|b1, b2|b3, b4|b5,
/// b6|b7) in the low four bytes.
#[inline(always)]
fn pair_or_word(w: u64) -> u64 {
    let x = (w | (w >> 8)) & 0x00FF_00FF_00FF_00FF;
    let x = (x | (x >> 8)) & 0x0000_FFFF_0000_FFFF;
    (x | (x >> 16)) & 0x0000_0000_FFFF_FFFF
}

/// `out[k] = body[2k] | body[2k + 1]` (or OR-ed into `out` when not `first`)
/// with SSE2; `body.len() == 2 * out.len()`, a multiple of 32.
#[cfg(target_arch = "x86_64")]
#[inline]
fn pair_or_sse2(body: &[u8], out: &mut [u8], first: bool) {
    use std::arch::x86_64::*;
    debug_assert_eq!(body.len(), 2 * out.len());
    debug_assert_eq!(body.len() % 32, 0);
    // SAFETY: SSE2 is always available on x86_64; every load and store is
    // unaligned (`loadu`/`storeu`) and stays inside `body` and `out`, whose
    // lengths are checked above (32 bytes read and 16 written per step).
    unsafe {
        let mask = _mm_set1_epi16(0x00FF);
        for (o, ch) in out.chunks_exact_mut(16).zip(body.chunks_exact(32)) {
            let x0 = _mm_loadu_si128(ch.as_ptr() as *const __m128i);
            let x1 = _mm_loadu_si128(ch.as_ptr().add(16) as *const __m128i);
            let y0 = _mm_and_si128(_mm_or_si128(x0, _mm_srli_epi16(x0, 8)), mask);
            let y1 = _mm_and_si128(_mm_or_si128(x1, _mm_srli_epi16(x1, 8)), mask);
            let mut v = _mm_packus_epi16(y0, y1);
            if !first {
                v = _mm_or_si128(v, _mm_loadu_si128(o.as_ptr() as *const __m128i));
            }
            _mm_storeu_si128(o.as_mut_ptr() as *mut __m128i, v);
        }
    }
}

/// OR adjacent byte pairs of `row` (the first box holds one byte when the
/// shift `c` is 1) into `out`: overwrite when `first`, else OR into it.
/// Works on 16 input bytes at a time with word arithmetic.
#[inline]
fn pair_or_into(row: &[u8], c: usize, out: &mut [u8], first: bool) {
    let (rest, out_rest) = if c == 1 {
        let (h, r) = row.split_at(1);
        let (oh, orr) = out.split_at_mut(1);
        oh[0] = if first { h[0] } else { oh[0] | h[0] };
        (r, orr)
    } else {
        (row, out)
    };
    #[cfg(target_arch = "x86_64")]
    let (rest, out_rest) = {
        // SSE2 is part of the x86_64 baseline: 32 input bytes -> 16 output bytes.
        let n32 = rest.len() / 32;
        let (body, tail) = rest.split_at(n32 * 32);
        let (obody, otail) = out_rest.split_at_mut(n32 * 16);
        pair_or_sse2(body, obody, first);
        (tail, otail)
    };
    let n16 = rest.len() / 16;
    let (body, tail) = rest.split_at(n16 * 16);
    let (obody, otail) = out_rest.split_at_mut(n16 * 8);
    for (o, ch) in obody.chunks_exact_mut(8).zip(body.chunks_exact(16)) {
        let lo = u64::from_le_bytes(ch[..8].try_into().unwrap());
        let hi = u64::from_le_bytes(ch[8..].try_into().unwrap());
        let mut v = pair_or_word(lo) | (pair_or_word(hi) << 32);
        if !first {
            v |= u64::from_le_bytes((&*o).try_into().unwrap());
        }
        o.copy_from_slice(&v.to_le_bytes());
    }
    for (k, o) in otail.iter_mut().enumerate() {
        let v = tail.get(2 * k).copied().unwrap_or(0) | tail.get(2 * k + 1).copied().unwrap_or(0);
        *o = if first { v } else { *o | v };
    }
}

/// Block-OR reduction of `src` by factors `m` and shifts `c` per axis.
/// Returns the reduced grid and its number of occupied boxes.
/// Also returns the number of nonzero source bytes read (every source byte
/// lies in exactly one box, so this is the source's count).
fn reduce_or(src: &Src, m: Shape3, c: Shape3) -> (Grid, u64, u64) {
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
    if !box_sizes.is_empty() {
        validate_box_sizes(box_sizes, max_len)?;
    }
    let Some((bmin, bmax)) = scan(vol) else {
        return Err(CoreError::invalid(
            "data",
            "the set is empty (no foreground sample)",
        ));
    };
    // the number of foreground samples (the count at size 1) comes from the
    // first reduction of the data, which reads every sample once
    let mut n_fg: Option<u64> = None;
    let sizes = if box_sizes.is_empty() {
        let extent = (0..3).map(|a| bmax[a] - bmin[a]).max().unwrap_or(1);
        validate_box_sizes(&default_box_sizes(extent), max_len).map_err(|_| {
            CoreError::invalid(
                "data",
                format!("the set spans only {extent} samples: too small for the default box sizes (give box_sizes)"),
            )
        })?
    } else {
        validate_box_sizes(box_sizes, max_len)?
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
        for (i, &s) in sizes.iter().enumerate() {
            if s == 1 {
                continue; // filled in below from n_fg
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
            done.push(s);
            grids.push(grid);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Direct count: box of every foreground sample, deduplicated.
    fn naive(data: &[u8], dims: &[usize], s: usize, g: Shape3, anchor: Anchor) -> u64 {
        let vol = ByteVolume::new(data, dims).unwrap();
        let (bmin, _) = scan(&vol).unwrap();
        let lo = if anchor == Anchor::BoundingBox {
            bmin
        } else {
            [0; 3]
        };
        let mut set = std::collections::HashSet::new();
        let [n0, n1, n2] = vol.shape;
        for i in 0..n0 {
            for j in 0..n1 {
                for k in 0..n2 {
                    if data[(i * n1 + j) * n2 + k] != 0 {
                        let key = [
                            (i - lo[0] + g[0] % s) / s,
                            (j - lo[1] + g[1] % s) / s,
                            (k - lo[2] + g[2] % s) / s,
                        ];
                        set.insert(key);
                    }
                }
            }
        }
        set.len() as u64
    }

    fn lcg(seed: &mut u64) -> u64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        *seed >> 33
    }

    #[test]
    fn matches_naive_count_on_random_sets() {
        let mut seed = 7u64;
        for trial in 0..40 {
            let ndim = 1 + trial % 3;
            let dims: Vec<usize> = (0..ndim)
                .map(|_| 3 + (lcg(&mut seed) % 30) as usize)
                .collect();
            let n: usize = dims.iter().product();
            let density = 1 + lcg(&mut seed) % 20;
            let mut data: Vec<u8> = (0..n)
                .map(|_| (lcg(&mut seed) % 100 < density) as u8)
                .collect();
            data[n / 2] = 1;
            let vol = ByteVolume::new(&data, &dims).unwrap();
            let maxlen = *dims.iter().max().unwrap();
            let sizes: Vec<usize> = vec![1, 2, 3, 4, 6, 8, 12]
                .into_iter()
                .filter(|&s| s <= maxlen)
                .collect();
            for anchor in [Anchor::BoundingBox, Anchor::Array] {
                for offs in [1usize, 2, 3] {
                    let r = box_count(&vol, ndim, &sizes, offs, anchor).unwrap();
                    for (i, &s) in r.box_sizes.iter().enumerate() {
                        for (j, g) in r.shifts.iter().enumerate() {
                            assert_eq!(
                                r.counts[i][j],
                                naive(&data, &dims, s, *g, anchor),
                                "s={s} g={g:?} dims={dims:?}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn sierpinski_triangle_counts_are_exact() {
        // Pascal's triangle mod 2 on a 2^L grid: N(2^k) = 3^(L-k).
        let l = 7;
        let n = 1usize << l;
        let data: Vec<u8> = (0..n * n).map(|p| ((p / n) & (p % n) == 0) as u8).collect();
        let vol = ByteVolume::new(&data, &[n, n]).unwrap();
        let sizes: Vec<usize> = (0..=l).map(|k| 1 << k).collect();
        let r = box_count(&vol, 2, &sizes, 1, Anchor::BoundingBox).unwrap();
        for (k, c) in r.counts.iter().enumerate() {
            assert_eq!(c[0], 3u64.pow((l - k) as u32));
        }
    }

    #[test]
    fn thread_count_does_not_change_counts() {
        let mut seed = 3u64;
        let dims = [301usize, 257];
        let data: Vec<u8> = (0..dims[0] * dims[1])
            .map(|_| (lcg(&mut seed) % 7 == 0) as u8)
            .collect();
        let vol = ByteVolume::new(&data, &dims).unwrap();
        let run = |t| {
            crate::parallel::run_in_pool(Some(t), || {
                box_count(&vol, 2, &[1, 2, 3, 5, 8, 16, 64], 3, Anchor::BoundingBox)
            })
            .unwrap()
        };
        assert_eq!(run(1), run(2));
        assert_eq!(run(1), run(5));
    }

    #[test]
    fn pair_or_matches_scalar_for_all_lengths_and_shifts() {
        let mut seed = 17u64;
        for len in 0..200usize {
            let row: Vec<u8> = (0..len).map(|_| (lcg(&mut seed) % 3 == 0) as u8).collect();
            let prev: Vec<u8> = (0..len).map(|_| (lcg(&mut seed) % 5 == 0) as u8).collect();
            for c in 0..2usize {
                if len == 0 && c == 1 {
                    continue;
                }
                let nout = n_boxes(len, 2, c);
                let expect = |first: bool| -> Vec<u8> {
                    (0..nout)
                        .map(|b| {
                            let (lo, hi) = box_range(b, 2, c, len);
                            let v = row[lo..hi].iter().fold(0, |a, &x| a | x);
                            if first {
                                v
                            } else {
                                v | prev[b]
                            }
                        })
                        .collect()
                };
                for first in [true, false] {
                    let mut out = prev[..nout].to_vec();
                    pair_or_into(&row, c, &mut out, first);
                    assert_eq!(out, expect(first), "len={len} c={c} first={first}");
                }
            }
        }
    }

    #[test]
    fn default_sizes_tile_the_extent_when_they_can() {
        assert_eq!(default_box_sizes(729), vec![1, 3, 9, 27, 81]);
        assert_eq!(default_box_sizes(512), vec![1, 2, 4, 8, 16, 32, 64, 128]);
        assert_eq!(default_box_sizes(81), vec![1, 3, 9]);
        // 613 is prime: powers of two
        assert_eq!(default_box_sizes(613), vec![1, 2, 4, 8, 16, 32, 64, 128]);
        assert_eq!(default_box_sizes(500), vec![1, 2, 4, 10, 20, 50, 100]);
        // 762 = 2 * 3 * 127: divisors leave a gap from 6 to 127, so powers of two
        assert_eq!(default_box_sizes(762), vec![1, 2, 4, 8, 16, 32, 64, 128]);
    }

    #[test]
    fn bad_input_is_an_error() {
        let data = vec![0u8; 16];
        let vol = ByteVolume::new(&data, &[4, 4]).unwrap();
        assert!(matches!(
            box_count(&vol, 2, &[1, 2, 4], 1, Anchor::BoundingBox),
            Err(CoreError::InvalidArgument { .. })
        ));
        assert!(ByteVolume::new(&[], &[0]).is_err());
        assert!(ByteVolume::new(&data, &[2, 2, 2, 2]).is_err());
    }
}
