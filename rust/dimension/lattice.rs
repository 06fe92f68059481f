//! Box lattices shared by the counters.
//!
//! A lattice of box size `s` and per-axis shift `g` puts the sample at
//! position `x` (relative to the anchor, the first sample counted) into the box
//! `floor((x + (g mod s)) / s)`. Shifts are *global*: the same `g` is used for
//! every box size, so the lattices of sizes `t` and `s = m t` nest and the
//! occupancy at `s` is an exact block reduction of the occupancy at `t`. This
//! is what lets a whole set of box sizes be counted in about one pass over the
//! data (a pyramid), also with grid-offset averaging.
use crate::error::{CoreError, CoreResult};

/// Up to three axes; lower-dimensional data are padded with leading axes of length 1.
pub type Shape3 = [usize; 3];

/// Global shifts of the lattice, one per axis, for `n_offsets` shifts per
/// active axis: `floor(j * s_max / n_offsets)` for `j` in `0..n_offsets`,
/// in all combinations over the active (trailing `ndim`) axes.
pub fn lattice_shifts(ndim: usize, n_offsets: usize, s_max: usize) -> Vec<Shape3> {
    let k = n_offsets.max(1);
    let per_axis: Vec<usize> = {
        let mut v: Vec<usize> = (0..k).map(|j| j * s_max / k).collect();
        v.dedup();
        v
    };
    let mut out = vec![[0usize; 3]];
    for axis in (3 - ndim)..3 {
        let mut next = Vec::with_capacity(out.len() * per_axis.len());
        for base in &out {
            for &g in &per_axis {
                let mut b = *base;
                b[axis] = g;
                next.push(b);
            }
        }
        out = next;
    }
    out
}

/// Number of boxes along an axis of `len` samples for box size `m` (in units
/// of the source grid) and shift `c` (in the same units).
#[inline]
pub fn n_boxes(len: usize, m: usize, c: usize) -> usize {
    if len == 0 {
        0
    } else {
        (len - 1 + c) / m + 1
    }
}

/// Range of source indices `[lo, hi)` that fall in box `b` along an axis.
#[inline]
pub fn box_range(b: usize, m: usize, c: usize, len: usize) -> (usize, usize) {
    let lo = (b * m).saturating_sub(c);
    let hi = ((b + 1) * m).saturating_sub(c).min(len);
    (lo, hi)
}

/// Check box sizes: positive, strictly increasing after sorting and dedup,
/// at least three distinct, none larger than `max_len`.
pub fn validate_box_sizes(box_sizes: &[usize], max_len: usize) -> CoreResult<Vec<usize>> {
    let mut v = box_sizes.to_vec();
    v.sort_unstable();
    v.dedup();
    if v.first() == Some(&0) {
        return Err(CoreError::invalid(
            "box_sizes",
            "box sizes must be positive integers",
        ));
    }
    if v.len() < 3 {
        let n = v.len();
        return Err(CoreError::invalid(
            "box_sizes",
            format!("need at least 3 distinct box sizes for a fit, got {n}"),
        ));
    }
    if let Some(&s) = v.last() {
        if s > max_len {
            return Err(CoreError::invalid(
                "box_sizes",
                format!(
                    "box size {s} is larger than the data (largest axis has {max_len} samples)"
                ),
            ));
        }
    }
    Ok(v)
}

/// For box size `s`, among already computed sizes `done` (ascending), the
/// largest `t < s` that divides `s`; 1 (the data themselves) if none.
pub fn best_source(s: usize, done: &[usize]) -> usize {
    done.iter()
        .rev()
        .copied()
        .find(|&t| t < s && s % t == 0)
        .unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifts_cover_all_axis_combinations() {
        let s = lattice_shifts(2, 2, 8);
        assert_eq!(s, vec![[0, 0, 0], [0, 0, 4], [0, 4, 0], [0, 4, 4]]);
        assert_eq!(lattice_shifts(1, 1, 8), vec![[0, 0, 0]]);
        assert_eq!(lattice_shifts(3, 3, 9).len(), 27);
    }

    #[test]
    fn boxes_partition_the_axis() {
        for len in 1..40 {
            for m in 1..9 {
                for c in 0..m {
                    let n = n_boxes(len, m, c);
                    let mut covered = 0;
                    for b in 0..n {
                        let (lo, hi) = box_range(b, m, c, len);
                        assert!(hi > lo, "empty box {b} len={len} m={m} c={c}");
                        assert_eq!(lo, covered);
                        covered = hi;
                    }
                    assert_eq!(covered, len);
                }
            }
        }
    }

    #[test]
    fn nested_lattices_agree() {
        // box of x at size s with shift g equals the box of its size-t box.
        for g in 0..20usize {
            for (t, m) in [(2usize, 2usize), (3, 3), (2, 3), (4, 2)] {
                let s = t * m;
                let (ot, os) = (g % t, g % s);
                assert_eq!((os - ot) % t, 0);
                let c = (os - ot) / t;
                for x in 0..100usize {
                    let bt = (x + ot) / t;
                    assert_eq!((x + os) / s, (bt + c) / m);
                }
            }
        }
    }

    #[test]
    fn sizes_are_validated() {
        assert!(validate_box_sizes(&[1, 2], 10).is_err());
        assert!(validate_box_sizes(&[0, 1, 2], 10).is_err());
        assert!(validate_box_sizes(&[1, 2, 20], 10).is_err());
        assert_eq!(
            validate_box_sizes(&[4, 1, 2, 2], 10).unwrap(),
            vec![1, 2, 4]
        );
    }
}
