//! The fused dyadic pass: sizes 2, 4, ..., 2^k of a 2D set in one read.
use super::reduce::{Grid, Src};
use super::simd::{first_nonzero, last_nonzero, level_row};
use crate::dimension::lattice::n_boxes;
use rayon::prelude::*;

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
pub(super) struct Dyadic {
    /// `counts[l - 1]`: occupied boxes of size 2^l, l = 1..=k.
    pub(super) counts: Vec<u64>,
    /// Nonzero source samples.
    pub(super) n_fg: u64,
    /// Occupancy at size 2^k.
    pub(super) grid: Grid,
    /// Bounding box of the foreground in source coordinates:
    /// `([first row, first column], [last row + 1, last column + 1])`;
    /// None when the source is empty.
    pub(super) bbox: Option<([usize; 2], [usize; 2])>,
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
pub(super) fn dyadic_2d(src: &Src, k: usize) -> Dyadic {
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
pub(super) fn dyadic_depth(sizes: &[usize], n_rows: usize) -> usize {
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

#[cfg(test)]
mod tests {
    use super::super::bbox::scan;
    use super::super::reduce::reduce_or;
    use super::super::tests::naive;
    use super::super::{Anchor, ByteVolume};
    use super::*;
    use crate::testdata::uniform;

    #[test]
    fn fused_dyadic_pass_matches_naive_counts_and_grid() {
        for trial in 0..60 {
            let u = uniform(2, 41 + trial as u64);
            let dims = [1 + (u[0] * 90.0) as usize, 1 + (u[1] * 140.0) as usize];
            let n = dims[0] * dims[1];
            // from a few points (a small bounding box) to dense sets
            let p = [0.001, 0.003, 0.01, 0.1, 0.3][trial % 5];
            let mut data: Vec<u8> = uniform(n, 1041 + trial as u64)
                .into_iter()
                .map(|x| (x < p) as u8)
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
}
