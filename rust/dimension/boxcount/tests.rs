//! Tests of [`box_count`] against a direct count, and of the default sizes.
use super::*;
use crate::testdata::uniform;

/// Direct count: box of every foreground sample, deduplicated.
pub(super) fn naive(data: &[u8], dims: &[usize], s: usize, g: Shape3, anchor: Anchor) -> u64 {
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

#[test]
fn matches_naive_count_on_random_sets() {
    for trial in 0..40 {
        let ndim = 1 + trial % 3;
        // ndim axis lengths in 3..33, then a density of 1 to 20 percent
        let u = uniform(ndim + 1, 7 + trial as u64);
        let dims: Vec<usize> = u[..ndim].iter().map(|&x| 3 + (x * 30.0) as usize).collect();
        let n: usize = dims.iter().product();
        let density = (1 + (u[ndim] * 20.0) as usize) as f64 / 100.0;
        let mut data: Vec<u8> = uniform(n, 1007 + trial as u64)
            .into_iter()
            .map(|x| (x < density) as u8)
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
    let dims = [301usize, 257];
    let data: Vec<u8> = uniform(dims[0] * dims[1], 3)
        .into_iter()
        .map(|x| (x < 1.0 / 7.0) as u8)
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
    let dims = [203usize, 171];
    let data: Vec<u8> = uniform(dims[0] * dims[1], 5)
        .into_iter()
        .map(|x| (x < 1.0 / 11.0) as u8)
        .collect();
    // sparse sets whose bounding box starts on the dyadic lattice of the
    // array (row 32, column 64) or off it (row 37, column 21)
    let sparse = |r0: usize, c0: usize| -> Vec<u8> {
        let mut d = vec![0u8; dims[0] * dims[1]];
        d[r0 * dims[1] + c0 + 5] = 1;
        d[(r0 + 3) * dims[1] + c0] = 1;
        for w in uniform(80, 9).chunks_exact(2) {
            let r = r0 + (w[0] * (dims[0] - r0 - 20) as f64) as usize;
            let c = c0 + (w[1] * (dims[1] - c0 - 10) as f64) as usize;
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
