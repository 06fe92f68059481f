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

/// Whether a 64-byte block holds a nonzero byte (SSE2: four loads OR-ed, one test).
#[inline(always)]
fn block_nonzero(b: &[u8]) -> bool {
    debug_assert_eq!(b.len(), 64);
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        assert!(b.len() >= 64);
        // SAFETY: SSE2 is part of the x86_64 baseline; four unaligned 16-byte
        // loads at offsets 0, 16, 32 and 48 stay inside the 64 bytes checked above.
        unsafe {
            let p = b.as_ptr() as *const __m128i;
            let x = _mm_or_si128(
                _mm_or_si128(_mm_loadu_si128(p), _mm_loadu_si128(p.add(1))),
                _mm_or_si128(_mm_loadu_si128(p.add(2)), _mm_loadu_si128(p.add(3))),
            );
            _mm_movemask_epi8(_mm_cmpeq_epi8(x, _mm_setzero_si128())) != 0xFFFF
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        b.chunks_exact(8)
            .fold(0u64, |a, w| a | u64::from_le_bytes(w.try_into().unwrap()))
            != 0
    }
}

/// Index of the first nonzero byte, skipping zero blocks of 64 bytes.
#[inline]
fn first_nonzero(row: &[u8]) -> Option<usize> {
    let blocks = row.chunks_exact(64);
    let rem_start = row.len() - blocks.remainder().len();
    for (k, b) in blocks.enumerate() {
        if block_nonzero(b) {
            return b.iter().position(|&v| v != 0).map(|p| 64 * k + p);
        }
    }
    row[rem_start..]
        .iter()
        .position(|&v| v != 0)
        .map(|p| rem_start + p)
}

/// Index of the last nonzero byte, skipping zero blocks of 64 bytes from the end.
#[inline]
fn last_nonzero(row: &[u8]) -> Option<usize> {
    let blocks = row.rchunks_exact(64);
    let rem_len = blocks.remainder().len();
    for (k, b) in blocks.enumerate() {
        if block_nonzero(b) {
            let start = row.len() - 64 * (k + 1);
            return b.iter().rposition(|&v| v != 0).map(|p| start + p);
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

/// Nonzero bytes of a 16-byte vector, accumulated as 0/1 per lane.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn nz_acc(
    acc: std::arch::x86_64::__m128i,
    x: std::arch::x86_64::__m128i,
) -> std::arch::x86_64::__m128i {
    use std::arch::x86_64::*;
    _mm_add_epi8(acc, _mm_min_epu8(x, _mm_set1_epi8(1)))
}

/// Horizontal sum of the byte lanes of `acc`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn lane_sum(acc: std::arch::x86_64::__m128i) -> u64 {
    use std::arch::x86_64::*;
    let s = _mm_sad_epu8(acc, _mm_setzero_si128());
    (_mm_cvtsi128_si64(s) + _mm_cvtsi128_si64(_mm_unpackhi_epi64(s, s))) as u64
}

/// SSE2 body of [`level_row`] over the first `32 * n` bytes of `a` and `b`.
/// Returns (nonzero output bytes, nonzero bytes of `a`, nonzero bytes of `b`).
#[cfg(target_arch = "x86_64")]
fn level_row_sse2(a: &[u8], b: &[u8], out: &mut [u8], n: usize, count_in: bool) -> (u64, u64, u64) {
    use std::arch::x86_64::*;
    assert!(a.len() >= 32 * n && b.len() >= 32 * n && out.len() >= 16 * n);
    let (mut c_out, mut c_a, mut c_b) = (0u64, 0u64, 0u64);
    // SAFETY: SSE2 is part of the x86_64 baseline; the assert above keeps
    // every unaligned load (32 bytes of `a` and of `b` per step) and store
    // (16 bytes of `out` per step) inside the slices.
    unsafe {
        let mask = _mm_set1_epi16(0x00FF);
        let (pa, pb, po) = (a.as_ptr(), b.as_ptr(), out.as_mut_ptr());
        let mut k = 0;
        while k < n {
            // byte lanes count at most 2 per step: flush before 127 steps
            let end = (k + 120).min(n);
            let (mut ao, mut aa, mut ab) = (
                _mm_setzero_si128(),
                _mm_setzero_si128(),
                _mm_setzero_si128(),
            );
            while k < end {
                let a0 = _mm_loadu_si128(pa.add(32 * k) as *const __m128i);
                let a1 = _mm_loadu_si128(pa.add(32 * k + 16) as *const __m128i);
                let b0 = _mm_loadu_si128(pb.add(32 * k) as *const __m128i);
                let b1 = _mm_loadu_si128(pb.add(32 * k + 16) as *const __m128i);
                if count_in {
                    aa = nz_acc(nz_acc(aa, a0), a1);
                    ab = nz_acc(nz_acc(ab, b0), b1);
                }
                let x0 = _mm_or_si128(a0, b0);
                let x1 = _mm_or_si128(a1, b1);
                let y0 = _mm_and_si128(_mm_or_si128(x0, _mm_srli_epi16(x0, 8)), mask);
                let y1 = _mm_and_si128(_mm_or_si128(x1, _mm_srli_epi16(x1, 8)), mask);
                let v = _mm_packus_epi16(y0, y1);
                ao = nz_acc(ao, v);
                _mm_storeu_si128(po.add(16 * k) as *mut __m128i, v);
                k += 1;
            }
            c_out += lane_sum(ao);
            c_a += lane_sum(aa);
            c_b += lane_sum(ab);
        }
    }
    (c_out, c_a, c_b)
}

/// AVX2 body of [`level_row`] over the first `64 * n` bytes of `a` and `b`
/// (the same operation as [`level_row_sse2`], 32 output bytes per step).
///
/// # Safety
/// The CPU must support AVX2 (checked by the caller at run time).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn level_row_avx2(
    a: &[u8],
    b: &[u8],
    out: &mut [u8],
    n: usize,
    count_in: bool,
) -> (u64, u64, u64) {
    use std::arch::x86_64::*;
    assert!(a.len() >= 64 * n && b.len() >= 64 * n && out.len() >= 32 * n);
    let sum = |acc: __m256i| -> u64 {
        let s = _mm256_sad_epu8(acc, _mm256_setzero_si256());
        let s = _mm_add_epi64(_mm256_castsi256_si128(s), _mm256_extracti128_si256(s, 1));
        (_mm_cvtsi128_si64(s) + _mm_cvtsi128_si64(_mm_unpackhi_epi64(s, s))) as u64
    };
    let (mut c_out, mut c_a, mut c_b) = (0u64, 0u64, 0u64);
    let mask = _mm256_set1_epi16(0x00FF);
    let one = _mm256_set1_epi8(1);
    let (pa, pb, po) = (a.as_ptr(), b.as_ptr(), out.as_mut_ptr());
    let mut k = 0;
    while k < n {
        // byte lanes count at most 2 per step: flush before 127 steps
        let end = (k + 120).min(n);
        let (mut ao, mut aa, mut ab) = (
            _mm256_setzero_si256(),
            _mm256_setzero_si256(),
            _mm256_setzero_si256(),
        );
        while k < end {
            // SAFETY: the assert above keeps the unaligned loads (64 bytes of
            // `a` and of `b` per step) and the store (32 bytes) inside the slices.
            let a0 = _mm256_loadu_si256(pa.add(64 * k) as *const __m256i);
            let a1 = _mm256_loadu_si256(pa.add(64 * k + 32) as *const __m256i);
            let b0 = _mm256_loadu_si256(pb.add(64 * k) as *const __m256i);
            let b1 = _mm256_loadu_si256(pb.add(64 * k + 32) as *const __m256i);
            if count_in {
                aa = _mm256_add_epi8(
                    aa,
                    _mm256_add_epi8(_mm256_min_epu8(a0, one), _mm256_min_epu8(a1, one)),
                );
                ab = _mm256_add_epi8(
                    ab,
                    _mm256_add_epi8(_mm256_min_epu8(b0, one), _mm256_min_epu8(b1, one)),
                );
            }
            let x0 = _mm256_or_si256(a0, b0);
            let x1 = _mm256_or_si256(a1, b1);
            let y0 = _mm256_and_si256(_mm256_or_si256(x0, _mm256_srli_epi16(x0, 8)), mask);
            let y1 = _mm256_and_si256(_mm256_or_si256(x1, _mm256_srli_epi16(x1, 8)), mask);
            // packus works within 128-bit lanes: restore the order of the quarters
            let v = _mm256_permute4x64_epi64(_mm256_packus_epi16(y0, y1), 0b11_01_10_00);
            ao = _mm256_add_epi8(ao, _mm256_min_epu8(v, one));
            _mm256_storeu_si256(po.add(32 * k) as *mut __m256i, v);
            k += 1;
        }
        c_out += sum(ao);
        c_a += sum(aa);
        c_b += sum(ab);
    }
    (c_out, c_a, c_b)
}

/// One row of the next dyadic level: `out[k] = a[2k] | a[2k+1] | b[2k] | b[2k+1]`
/// (samples past the end, and the whole of an absent `b`, are background);
/// `out.len() == ceil(a.len() / 2)`. Returns the nonzero bytes of `out` and,
/// when `count_in`, those of `a` and of `b`.
fn level_row(a: &[u8], b: Option<&[u8]>, out: &mut [u8], count_in: bool) -> (u64, u64, u64) {
    debug_assert_eq!(out.len(), a.len().div_ceil(2));
    let bb = b.unwrap_or(a); // OR with itself changes nothing
    debug_assert_eq!(bb.len(), a.len());
    #[cfg(target_arch = "x86_64")]
    let (n, mut c_out, mut c_a, mut c_b) = {
        let (mut done, mut o, mut ca, mut cb) = (0, 0, 0, 0);
        if std::arch::is_x86_feature_detected!("avx2") {
            let n64 = a.len() / 64;
            // SAFETY: AVX2 is present (checked just above).
            (o, ca, cb) = unsafe { level_row_avx2(a, bb, out, n64, count_in) };
            done = 64 * n64;
        }
        let n32 = (a.len() - done) / 32;
        let r = level_row_sse2(&a[done..], &bb[done..], &mut out[done / 2..], n32, count_in);
        (done + 32 * n32, o + r.0, ca + r.1, cb + r.2)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let (n, mut c_out, mut c_a, mut c_b) = (0usize, 0u64, 0u64, 0u64);
    for (k, o) in out.iter_mut().enumerate().skip(n / 2) {
        let i = 2 * k;
        let (a0, a1) = (a[i], a.get(i + 1).copied().unwrap_or(0));
        let (b0, b1) = (bb[i], bb.get(i + 1).copied().unwrap_or(0));
        *o = a0 | a1 | b0 | b1;
        c_out += (*o != 0) as u64;
        if count_in {
            c_a += (a0 != 0) as u64 + (a1 != 0) as u64;
            c_b += (b0 != 0) as u64 + (b1 != 0) as u64;
        }
    }
    (c_out, c_a, if b.is_some() { c_b } else { 0 })
}

/// Row buffers of one band of [`dyadic_2d`]: per level, a row waiting for its
/// pair and a row being built.
struct Cascade {
    pending: Vec<Vec<u8>>,
    has: Vec<bool>,
    tmp: Vec<Vec<u8>>,
}

impl Cascade {
    fn new(n2: usize, k: usize) -> Self {
        let rows = || {
            (0..=k)
                .map(|l| vec![0u8; n_boxes(n2, 1 << l, 0)])
                .collect::<Vec<_>>()
        };
        Cascade {
            pending: rows(),
            has: vec![false; k + 1],
            tmp: rows(),
        }
    }

    /// A new row of level `l` is in `tmp[l]` (already counted): pair it with
    /// the waiting one, or wait; the level-`k` row goes to `out`.
    fn push(&mut self, mut l: usize, k: usize, counts: &mut [u64], out: &mut [u8]) {
        loop {
            if l == k {
                out.copy_from_slice(&self.tmp[l]);
                return;
            }
            if !self.has[l] {
                std::mem::swap(&mut self.pending[l], &mut self.tmp[l]);
                self.has[l] = true;
                return;
            }
            let (lo, hi) = self.tmp.split_at_mut(l + 1);
            counts[l] += level_row(&self.pending[l], Some(&lo[l]), &mut hi[0], false).0;
            self.has[l] = false;
            l += 1;
        }
    }

    /// End of a band: rows still waiting pair with background.
    fn flush(&mut self, k: usize, counts: &mut [u64], out: &mut [u8]) {
        for l in 1..k {
            if self.has[l] {
                self.has[l] = false;
                let (_, hi) = self.tmp.split_at_mut(l + 1);
                counts[l] += level_row(&self.pending[l], None, &mut hi[0], false).0;
                self.push(l + 1, k, counts, out);
            }
        }
    }
}

/// Result of [`dyadic_2d`].
struct Dyadic {
    /// `counts[l - 1]`: occupied boxes of size 2^l, l = 1..=k.
    counts: Vec<u64>,
    /// Nonzero source samples.
    n_fg: u64,
    /// Occupancy at size 2^k.
    grid: Grid,
    /// Bounding box of the foreground in source coordinates:
    /// `([first row, first column], [last row + 1, last column + 1])`;
    /// None when the source is empty.
    bbox: Option<([usize; 2], [usize; 2])>,
}

/// Bounding box of a band: `([first row, first column], [last row + 1, last column + 1])`.
type Bounds = ([usize; 2], [usize; 2]);

fn merge_bounds(a: Option<Bounds>, b: Option<Bounds>) -> Option<Bounds> {
    match (a, b) {
        (Some(x), Some(y)) => Some((
            [x.0[0].min(y.0[0]), x.0[1].min(y.0[1])],
            [x.1[0].max(y.1[0]), x.1[1].max(y.1[1])],
        )),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Columns (first, one past the last) of the foreground of source rows `a`
/// and `b` that lie outside `known`, found from their level-1 row `l1`
/// (only its part outside `known` is searched).
fn row_columns(
    a: &[u8],
    b: Option<&[u8]>,
    l1: &[u8],
    known: Option<[usize; 2]>,
) -> Option<[usize; 2]> {
    let at =
        |i: usize| a.get(i).copied().unwrap_or(0) | b.and_then(|b| b.get(i).copied()).unwrap_or(0);
    // level-1 cells before / after the known columns
    let (lo_end, hi_start) = match known {
        Some([lo, hi]) => (
            lo.div_ceil(2).min(l1.len()),
            (hi.saturating_sub(1) / 2).min(l1.len()),
        ),
        None => (l1.len(), 0),
    };
    let first =
        first_nonzero(&l1[..lo_end]).map(|f| if at(2 * f) != 0 { 2 * f } else { 2 * f + 1 });
    let last = last_nonzero(&l1[hi_start..])
        .map(|l| hi_start + l)
        .map(|l| {
            if at(2 * l + 1) != 0 {
                2 * l + 2
            } else {
                2 * l + 1
            }
        });
    match (known, first, last) {
        (None, Some(f), Some(l)) => Some([f, l]),
        (None, _, _) => None,
        (Some([lo, hi]), f, l) => Some([f.unwrap_or(lo).min(lo), l.unwrap_or(hi).max(hi)]),
    }
}

/// The unshifted dyadic lattice of a 2D source (`src.shape[0] == 1`) at box
/// sizes 2, 4, ..., 2^k in one read of the data: each band of 2^k rows is
/// reduced level by level through row buffers that stay in cache, and only
/// its level-k row is stored. The foreground's bounding box is found on the
/// way (rows from the per-row counts, columns from the level-1 rows).
fn dyadic_2d(src: &Src, k: usize) -> Dyadic {
    debug_assert!(k >= 1 && src.shape[0] == 1);
    let (n1, n2) = (src.shape[1], src.shape[2]);
    let band = 1usize << k;
    let shape = [1, n_boxes(n1, band, 0), n_boxes(n2, band, 0)];
    let mut data = vec![0u8; shape[1] * shape[2]];
    let row = |i: usize| {
        let off = src.start + i * src.strides[1];
        &src.data[off..off + n2]
    };
    let (counts, n_fg, bbox) = data
        .par_chunks_mut(shape[2])
        .enumerate()
        .map_init(
            || Cascade::new(n2, k),
            |cas, (b, out)| {
                // counts[l] is level l + 1 (size 2^(l + 1))
                let mut counts = vec![0u64; k];
                let mut n_fg = 0u64;
                let mut rows: Option<[usize; 2]> = None;
                let mut cols: Option<[usize; 2]> = None;
                let (r0, r1) = (b * band, ((b + 1) * band).min(n1));
                for i in (r0..r1).step_by(2) {
                    let second = (i + 1 < r1).then(|| row(i + 1));
                    let (c, ca, cb) = level_row(row(i), second, &mut cas.tmp[1], true);
                    counts[0] += c;
                    n_fg += ca + cb;
                    if c > 0 {
                        let (f, l) = (
                            if ca > 0 { i } else { i + 1 },
                            if cb > 0 { i + 2 } else { i + 1 },
                        );
                        rows = Some(rows.map_or([f, l], |[a, z]| [a.min(f), z.max(l)]));
                        cols = row_columns(row(i), second, &cas.tmp[1], cols);
                    }
                    cas.push(1, k, &mut counts[..], out);
                }
                cas.flush(k, &mut counts[..], out);
                let bounds = rows.zip(cols).map(|(r, c)| ([r[0], c[0]], [r[1], c[1]]));
                (counts, n_fg, bounds)
            },
        )
        .reduce(
            || (vec![0u64; k], 0u64, None),
            |(mut a, na, ba), (b, nb, bb)| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
                (a, na + nb, merge_bounds(ba, bb))
            },
        );
    Dyadic {
        counts,
        n_fg,
        grid: Grid { data, shape },
        bbox,
    }
}

/// Depth of the fused dyadic pass for these sizes: the longest chain 2, 4,
/// ..., 2^k among them, shortened so that every other even size is a
/// multiple of 2^k (its count is then reduced from the level-k grid, the
/// only level the pass keeps, instead of from the data), and until the rows
/// split into enough bands to keep every thread busy.
fn dyadic_depth(sizes: &[usize], n_rows: usize) -> usize {
    let mut k = 0;
    while sizes.contains(&(1usize << (k + 1))) {
        k += 1;
    }
    for &s in sizes {
        if s % 2 == 0 && !s.is_power_of_two() {
            k = k.min(s.trailing_zeros() as usize);
        }
    }
    let min_bands = 4 * rayon::current_num_threads();
    while k > 0 && n_boxes(n_rows, 1 << k, 0) < min_bands {
        k -= 1;
    }
    k
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
    fn first_and_last_nonzero_match_scalar() {
        let mut seed = 31u64;
        for len in 0..400usize {
            for _ in 0..4 {
                let mut row = vec![0u8; len];
                let nnz = lcg(&mut seed) % 4;
                for _ in 0..nnz.min(len as u64) {
                    let i = (lcg(&mut seed) as usize) % len;
                    row[i] = 1 + (lcg(&mut seed) % 255) as u8;
                }
                assert_eq!(
                    first_nonzero(&row),
                    row.iter().position(|&v| v != 0),
                    "len={len}"
                );
                assert_eq!(
                    last_nonzero(&row),
                    row.iter().rposition(|&v| v != 0),
                    "len={len}"
                );
            }
        }
    }

    #[test]
    fn level_row_matches_scalar_for_all_lengths() {
        let mut seed = 23u64;
        for len in 0..300usize {
            // any nonzero byte is foreground, not only 1
            let mut byte = |p: u64| -> u8 {
                if lcg(&mut seed) % p == 0 {
                    1 + (lcg(&mut seed) % 255) as u8
                } else {
                    0
                }
            };
            let a: Vec<u8> = (0..len).map(|_| byte(3)).collect();
            let b: Vec<u8> = (0..len).map(|_| byte(4)).collect();
            for with_b in [false, true] {
                let nout = len.div_ceil(2);
                let expect: Vec<bool> = (0..nout)
                    .map(|k| {
                        let hi = (2 * k + 2).min(len);
                        a[2 * k..hi].iter().any(|&v| v != 0)
                            || (with_b && b[2 * k..hi].iter().any(|&v| v != 0))
                    })
                    .collect();
                let n_in = a.iter().filter(|&&v| v != 0).count()
                    + if with_b {
                        b.iter().filter(|&&v| v != 0).count()
                    } else {
                        0
                    };
                let mut out = vec![7u8; nout];
                let bb = with_b.then_some(&b[..]);
                let (c_out, c_a, c_b) = level_row(&a, bb, &mut out, true);
                let c_in = c_a + c_b;
                let got: Vec<bool> = out.iter().map(|&v| v != 0).collect();
                assert_eq!(got, expect, "len={len} with_b={with_b}");
                assert_eq!(c_out as usize, expect.iter().filter(|&&v| v).count());
                assert_eq!(c_in as usize, n_in, "len={len} with_b={with_b}");
                assert_eq!(c_a as usize, a.iter().filter(|&&v| v != 0).count());
                let r = level_row(&a, bb, &mut out, false);
                assert_eq!((r.1, r.2), (0, 0));
                // the SSE2 body alone (the AVX2 one takes the long rows above
                // when the CPU has it)
                #[cfg(target_arch = "x86_64")]
                if with_b {
                    let n32 = len / 32;
                    let mut o = vec![0u8; 16 * n32];
                    let (co, ca, cb) = level_row_sse2(&a, &b, &mut o, n32, true);
                    let nz = |v: &[u8]| v.iter().filter(|&&x| x != 0).count() as u64;
                    assert_eq!(
                        o.iter().map(|&v| v != 0).collect::<Vec<_>>(),
                        expect[..16 * n32]
                    );
                    assert_eq!(
                        (co, ca, cb),
                        (nz(&o), nz(&a[..32 * n32]), nz(&b[..32 * n32]))
                    );
                }
            }
        }
    }

    #[test]
    fn fused_dyadic_pass_matches_naive_counts_and_grid() {
        let mut seed = 41u64;
        for trial in 0..60 {
            let dims = [
                1 + (lcg(&mut seed) % 90) as usize,
                1 + (lcg(&mut seed) % 140) as usize,
            ];
            let n = dims[0] * dims[1];
            // from a few points (a small bounding box) to dense sets
            let permille = [1, 3, 10, 100, 300][trial % 5];
            let mut data: Vec<u8> = (0..n)
                .map(|_| (lcg(&mut seed) % 1000 < permille) as u8)
                .collect();
            data[n / 2] = 1;
            let vol = ByteVolume::new(&data, &dims).unwrap();
            let src = Src {
                data: &data,
                start: 0,
                strides: [n, dims[1]],
                shape: vol.shape,
            };
            for k in 1..=6usize {
                let Dyadic {
                    counts,
                    n_fg,
                    grid,
                    bbox,
                } = dyadic_2d(&src, k);
                let (lo, hi) = scan(&vol).unwrap();
                assert_eq!(
                    bbox,
                    Some(([lo[1], lo[2]], [hi[1], hi[2]])),
                    "dims={dims:?} k={k}"
                );
                assert_eq!(n_fg, naive(&data, &dims, 1, [0; 3], Anchor::Array));
                for l in 1..=k {
                    let s = 1 << l;
                    let want = naive(&data, &dims, s, [0; 3], Anchor::Array);
                    assert_eq!(
                        counts[l - 1],
                        want,
                        "trial {trial} dims={dims:?} k={k} s={s}"
                    );
                }
                let (want, _, _) = reduce_or(&src, [1, 1 << k, 1 << k], [0; 3]);
                assert_eq!(grid.shape, want.shape);
                let nz = |g: &Grid| g.data.iter().map(|&v| v != 0).collect::<Vec<_>>();
                assert_eq!(nz(&grid), nz(&want), "trial {trial} dims={dims:?} k={k}");
            }
        }
    }

    #[test]
    fn long_rows_flush_the_byte_lane_counters() {
        // 20,000 bytes: the u8 lane counters of the SIMD bodies are flushed
        // many times (every 120 steps of 32 or 64 bytes)
        let n = 20_000usize;
        let a = vec![255u8; n];
        let b: Vec<u8> = (0..n).map(|i| (i % 3 == 0) as u8).collect();
        let mut out = vec![0u8; n / 2];
        let (c_out, c_a, c_b) = level_row(&a, Some(&b), &mut out, true);
        assert_eq!(
            (c_out, c_a, c_b),
            (n as u64 / 2, n as u64, n.div_ceil(3) as u64)
        );
        #[cfg(target_arch = "x86_64")]
        {
            let n32 = n / 32;
            let mut o = vec![0u8; 16 * n32];
            let r = level_row_sse2(&a, &b, &mut o, n32, true);
            let nb = b[..32 * n32].iter().filter(|&&v| v != 0).count() as u64;
            assert_eq!(r, (16 * n32 as u64, 32 * n32 as u64, nb));
        }
        let zeros = vec![0u8; n];
        assert_eq!(level_row(&zeros, Some(&zeros), &mut out, true), (0, 0, 0));
    }

    #[test]
    fn fused_depth_keeps_every_even_size_reducible() {
        crate::parallel::run_in_pool(Some(1), || {
            assert_eq!(dyadic_depth(&[1, 2, 4, 8, 16], 1024), 4);
            assert_eq!(dyadic_depth(&[1, 2, 4, 8, 12], 1024), 2); // 12 = 4 * 3
            assert_eq!(dyadic_depth(&[1, 2, 4, 10, 20, 50, 100], 1024), 1);
            assert_eq!(dyadic_depth(&[1, 3, 9, 27], 1024), 0);
            // one thread: at least 4 bands of 2^k rows
            assert_eq!(dyadic_depth(&[1, 2, 4, 8, 16], 16), 2);
            Ok(())
        })
        .unwrap();
    }

    #[test]
    fn empty_set_is_an_error_on_either_path() {
        // one thread: the array anchor takes the fused pre-pass (depth > 0),
        // the bounding-box anchor the scan
        let data = vec![0u8; 64 * 64];
        let vol = ByteVolume::new(&data, &[64, 64]).unwrap();
        crate::parallel::run_in_pool(Some(1), || {
            assert!(dyadic_depth(&[1, 2, 4, 8], 64) > 0);
            for anchor in [Anchor::Array, Anchor::BoundingBox] {
                assert!(matches!(
                    box_count(&vol, 2, &[1, 2, 4, 8], 1, anchor),
                    Err(CoreError::InvalidArgument { .. })
                ));
            }
            Ok(())
        })
        .unwrap();
    }

    #[test]
    fn fused_and_general_paths_agree_through_box_count() {
        // dyadic sizes take the fused pass on the unshifted lattice; offsets
        // and odd sizes take the general reduction from its grid
        let mut seed = 5u64;
        let dims = [203usize, 171];
        let data: Vec<u8> = (0..dims[0] * dims[1])
            .map(|_| (lcg(&mut seed) % 11 == 0) as u8)
            .collect();
        // sparse sets whose bounding box starts on the dyadic lattice of the
        // array (row 32, column 64) or off it (row 37, column 21)
        let sparse = |r0: usize, c0: usize| -> Vec<u8> {
            let mut seed = 9u64;
            let mut d = vec![0u8; dims[0] * dims[1]];
            d[r0 * dims[1] + c0 + 5] = 1;
            d[(r0 + 3) * dims[1] + c0] = 1;
            for _ in 0..40 {
                let r = r0 + (lcg(&mut seed) as usize) % (dims[0] - r0 - 20);
                let c = c0 + (lcg(&mut seed) as usize) % (dims[1] - c0 - 10);
                d[r * dims[1] + c] = 1;
            }
            d
        };
        // two threads: the fused depth (and so the paths taken) depends on
        // the thread count
        crate::parallel::run_in_pool(Some(2), || {
            for data in [&data, &sparse(32, 64), &sparse(37, 21)] {
                check_all_lattices(data, &dims);
            }
            Ok(())
        })
        .unwrap();
    }

    fn check_all_lattices(data: &[u8], dims: &[usize]) {
        let vol = ByteVolume::new(data, dims).unwrap();
        // with 12 the fused depth stops at 2 (12 = 4 x 3); without it, at 4
        let lists: [&[usize]; 2] = [
            &[1, 2, 4, 8, 12, 16, 24, 32, 48],
            &[1, 2, 3, 4, 5, 8, 16, 32],
        ];
        for (anchor, sizes) in [Anchor::BoundingBox, Anchor::Array]
            .into_iter()
            .flat_map(|a| lists.map(|l| (a, l)))
        {
            assert!(dyadic_depth(sizes, dims[0]) > 0);
            for offs in [1usize, 2] {
                let r = box_count(&vol, 2, sizes, offs, anchor).unwrap();
                assert_eq!(Some((r.bbox_min, r.bbox_max)), scan(&vol));
                for (i, &s) in r.box_sizes.iter().enumerate() {
                    for (j, g) in r.shifts.iter().enumerate() {
                        assert_eq!(
                            r.counts[i][j],
                            naive(data, dims, s, *g, anchor),
                            "s={s} g={g:?}"
                        );
                    }
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
