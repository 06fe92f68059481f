//! Row kernels of the counters: nonzero search and count, pair OR and the
//! dyadic level row, with SSE2 / AVX2 bodies and their scalar twins.
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
pub(super) fn first_nonzero(row: &[u8]) -> Option<usize> {
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
pub(super) fn last_nonzero(row: &[u8]) -> Option<usize> {
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
pub(super) fn pair_or_into(row: &[u8], c: usize, out: &mut [u8], first: bool) {
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
pub(super) fn level_row(
    a: &[u8],
    b: Option<&[u8]>,
    out: &mut [u8],
    count_in: bool,
) -> (u64, u64, u64) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dimension::lattice::{box_range, n_boxes};
    use crate::testdata::uniform;

    /// Bytes from pairs of uniform draws: foreground with probability `p`,
    /// then any value in 1..=255 (any nonzero byte is foreground, not only 1).
    fn bytes(u: &[f64], p: f64) -> Vec<u8> {
        u.chunks_exact(2)
            .map(|w| {
                if w[0] < p {
                    1 + (w[1] * 255.0) as u8
                } else {
                    0
                }
            })
            .collect()
    }

    #[test]
    fn pair_or_matches_scalar_for_all_lengths_and_shifts() {
        for len in 0..200usize {
            let u = uniform(2 * len, 17 + len as u64);
            let row: Vec<u8> = u[..len].iter().map(|&x| (x < 1.0 / 3.0) as u8).collect();
            let prev: Vec<u8> = u[len..].iter().map(|&x| (x < 0.2) as u8).collect();
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
        for len in 0..400usize {
            for rep in 0..4u64 {
                // up to 3 nonzero bytes at random places with random values
                let u = uniform(7, 31 + 4 * len as u64 + rep);
                let mut row = vec![0u8; len];
                let nnz = (u[0] * 4.0) as usize;
                for w in u[1..].chunks_exact(2).take(nnz.min(len)) {
                    row[(w[0] * len as f64) as usize] = 1 + (w[1] * 255.0) as u8;
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
        for len in 0..300usize {
            let u = uniform(4 * len, 23 + len as u64);
            let a = bytes(&u[..2 * len], 1.0 / 3.0);
            let b = bytes(&u[2 * len..], 0.25);
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
}
