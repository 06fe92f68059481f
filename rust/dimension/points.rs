//! Box counting of point sets given as coordinates (N points in d dimensions).
//!
//! A point `x` falls in box `floor((x - x_min + g) / s)` per axis, where
//! `x_min` is the per-axis minimum of the set (translation invariance) and `g`
//! a global lattice shift. The count is the number of distinct boxes.
use crate::error::{CoreError, CoreResult};
use rayon::prelude::*;

/// Result of [`point_box_count`].
#[derive(Debug, Clone, PartialEq)]
pub struct PointCounts {
    pub box_sizes: Vec<f64>,
    /// Per-lattice shift in units of the largest box size, per axis.
    pub shifts: Vec<Vec<f64>>,
    /// `counts[i][j]`: occupied boxes of size `box_sizes[i]` in lattice `j`.
    pub counts: Vec<Vec<u64>>,
}

/// `n` points of `d` finite coordinates each (row-major `coords`).
fn check_points(coords: &[f64], n: usize, d: usize) -> CoreResult<()> {
    if n == 0 || d == 0 || coords.len() != n * d {
        return Err(CoreError::invalid("data", "point set is empty"));
    }
    if coords.iter().any(|v| !v.is_finite()) {
        return Err(CoreError::invalid(
            "data",
            "coordinates must be finite (no NaN or inf)",
        ));
    }
    Ok(())
}

/// Count occupied boxes of an `n x d` row-major coordinate array.
pub fn point_box_count(
    coords: &[f64],
    n: usize,
    d: usize,
    box_sizes: &[f64],
    n_offsets: usize,
) -> CoreResult<PointCounts> {
    check_points(coords, n, d)?;
    if d > 16 {
        return Err(CoreError::invalid(
            "data",
            format!("at most 16 coordinates per point, got {d}"),
        ));
    }
    if n_offsets == 0 {
        return Err(CoreError::invalid("offsets", "must be a positive integer"));
    }
    let mut sizes: Vec<f64> = box_sizes.to_vec();
    if sizes.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(CoreError::invalid(
            "box_sizes",
            "box sizes must be positive finite numbers",
        ));
    }
    sizes.sort_by(|a, b| a.partial_cmp(b).unwrap());
    sizes.dedup();
    if sizes.len() < 3 {
        return Err(CoreError::invalid(
            "box_sizes",
            format!("need at least 3 distinct box sizes, got {}", sizes.len()),
        ));
    }
    let (mins, _) = bounds(coords, d);
    let s_max = *sizes.last().unwrap();
    // shifts: j / n_offsets of the largest box, all combinations over axes
    let mut shifts: Vec<Vec<f64>> = vec![vec![]];
    for _ in 0..d {
        let mut next = vec![];
        for b in &shifts {
            for j in 0..n_offsets {
                let mut v = b.clone();
                v.push(j as f64 * s_max / n_offsets as f64);
                next.push(v);
            }
        }
        shifts = next;
    }
    let mut counts = vec![vec![0u64; shifts.len()]; sizes.len()];
    for (i, &s) in sizes.iter().enumerate() {
        for (j, g) in shifts.iter().enumerate() {
            // keys: box index per axis packed in a Vec<u64> row (d words per point)
            let mut keys: Vec<Vec<u64>> = coords
                .par_chunks_exact(d)
                .map(|p| {
                    (0..d)
                        .map(|a| ((p[a] - mins[a] + g[a] % s) / s).floor() as u64)
                        .collect()
                })
                .collect();
            keys.par_sort_unstable();
            keys.dedup();
            counts[i][j] = keys.len() as u64;
        }
    }
    Ok(PointCounts {
        box_sizes: sizes,
        shifts,
        counts,
    })
}

/// Counts of one level of [`point_lattice_levels`].
#[derive(Debug, Clone, PartialEq)]
pub struct LatticeLevel {
    /// Box side `E / b^k` in coordinate units.
    pub size: f64,
    /// Occupied boxes of the lattice anchored at the set's minimum corner.
    pub aligned: u64,
    /// Mean number of occupied boxes over the `b^d` lattices shifted by
    /// `j s / b`, `0 <= j < b` per axis (`aligned` alone when `d > 3`).
    pub shifted: f64,
    /// Mean over the shifted lattices of the boxes lying wholly inside the
    /// set's bounding box, each divided by the share of the points they hold
    /// (the edge correction of a crop); NaN when no lattice has a box inside.
    pub shifted_inside: f64,
}

/// Most lattice shifts per level (`b^d` for `d <= 3`).
const MAX_SHIFT_DIMS: usize = 3;

/// Box counts of a point set on the boxes `E / b^k` (`E` the largest extent,
/// `k` from `k_first`), from the largest size down, stopping before the first
/// size whose aligned boxes hold fewer than `min_occupancy` points on
/// average (finer boxes only count the sample) or after `max_levels` levels.
///
/// Box indices at size `s` are formed from the integer indices of the grid
/// of side `s / b`, so the shifted lattices `j s / b` are exact integer
/// offsets on it. Keys are packed in a `u128` (at most 128 bits over the `d`
/// axes), sorted and counted; the lattices of one level run in parallel.
pub fn point_lattice_levels(
    coords: &[f64],
    n: usize,
    d: usize,
    base: u64,
    k_first: u32,
    min_occupancy: f64,
    max_levels: usize,
) -> CoreResult<Vec<LatticeLevel>> {
    check_points(coords, n, d)?;
    if !(2..=16).contains(&base) {
        return Err(CoreError::invalid(
            "base",
            format!("expected 2..=16, got {base}"),
        ));
    }
    let (lo, hi) = bounds(coords, d);
    let ext: Vec<f64> = lo.iter().zip(&hi).map(|(l, h)| h - l).collect();
    let e = ext.iter().cloned().fold(0.0f64, f64::max);
    if e <= 0.0 {
        return Err(CoreError::invalid(
            "data",
            "all points coincide; a box dimension needs an extended set",
        ));
    }
    let shift_dims = if d <= MAX_SHIFT_DIMS { d } else { 0 };
    let n_shifts = (base as usize).pow(shift_dims as u32);
    let mut out = Vec::new();
    let mut k = k_first;
    while out.len() < max_levels {
        let cells = (base as f64).powi(k as i32 + 1); // fine cells per largest axis
        let bits = (cells.log2().ceil() as u32 + 2).max(1);
        if bits as usize * d > 128 || !cells.is_finite() {
            break;
        }
        let sf = e / cells; // fine side: s / b
        let s = sf * base as f64;
        // fine cells wholly inside the bounding box, per axis
        let mf: Vec<i64> = ext
            .iter()
            .map(|x| ((x / sf) * (1.0 + 1e-12)).floor() as i64)
            .collect();
        let top = cells as i64 - 1;
        let fine: Vec<i64> = coords
            .par_chunks_exact(d)
            .flat_map_iter(|p| (0..d).map(|a| (((p[a] - lo[a]) / sf).floor() as i64).clamp(0, top)))
            .collect();
        let per_shift: Vec<(u64, u64, u64)> = (0..n_shifts)
            .into_par_iter()
            .map(|j| {
                let mut sh = [0i64; MAX_SHIFT_DIMS];
                let mut r = j;
                for v in sh.iter_mut().take(shift_dims) {
                    *v = (r % base as usize) as i64;
                    r /= base as usize;
                }
                let b = base as i64;
                let mut all: Vec<u128> = Vec::with_capacity(n);
                let mut inside: Vec<u128> = Vec::with_capacity(n);
                for f in fine.chunks_exact(d) {
                    let mut key = 0u128;
                    let mut ins = true;
                    for a in 0..d {
                        let g = if a < shift_dims { sh[a] } else { 0 };
                        let c = (f[a] + g) / b;
                        let low = c * b - g;
                        ins &= low >= 0 && low + b <= mf[a];
                        key = (key << bits) | c as u128;
                    }
                    all.push(key);
                    if ins {
                        inside.push(key);
                    }
                }
                let n_inside = inside.len() as u64;
                (distinct(&mut all), distinct(&mut inside), n_inside)
            })
            .collect();
        let aligned = per_shift[0].0;
        if (n as f64) / (aligned as f64) < min_occupancy {
            break;
        }
        let shifted = per_shift.iter().map(|t| t.0 as f64).sum::<f64>() / n_shifts as f64;
        let ins: Vec<f64> = per_shift
            .iter()
            .filter(|t| t.2 > 0)
            .map(|t| t.1 as f64 * n as f64 / t.2 as f64)
            .collect();
        let shifted_inside = if ins.is_empty() {
            f64::NAN
        } else {
            ins.iter().sum::<f64>() / ins.len() as f64
        };
        out.push(LatticeLevel {
            size: s,
            aligned,
            shifted,
            shifted_inside,
        });
        k += 1;
    }
    Ok(out)
}

fn distinct(v: &mut [u128]) -> u64 {
    if v.is_empty() {
        return 0;
    }
    v.sort_unstable();
    1 + v.windows(2).filter(|w| w[0] != w[1]).count() as u64
}

/// Per-axis minimum and maximum of an `n x d` row-major coordinate array.
fn bounds(coords: &[f64], d: usize) -> (Vec<f64>, Vec<f64>) {
    let mut lo = vec![f64::INFINITY; d];
    let mut hi = vec![f64::NEG_INFINITY; d];
    for p in coords.chunks_exact(d) {
        for a in 0..d {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    (lo, hi)
}

/// Largest extent of the set over its axes (for default box sizes).
pub fn extent(coords: &[f64], d: usize) -> f64 {
    let mut e = 0.0f64;
    for a in 0..d {
        let (lo, hi) = coords
            .iter()
            .skip(a)
            .step_by(d)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        e = e.max(hi - lo);
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cantor_points_counts_are_exact() {
        // Left ends of the level-6 middle-thirds Cantor set in units of 3^-6
        // (integers, exact in f64): N(3^j) = 2^(6-j).
        let mut pts = vec![0.0f64];
        for level in (0..6).rev() {
            let right: Vec<f64> = pts.iter().map(|x| x + 2.0 * 3f64.powi(level)).collect();
            pts.extend(right);
        }
        let sizes: Vec<f64> = (1..=5).map(|j| 3f64.powi(j)).collect();
        let r = point_box_count(&pts, pts.len(), 1, &sizes, 1).unwrap();
        let expect: Vec<u64> = (1..=5).map(|j| 2u64.pow(6 - j)).collect();
        assert_eq!(r.counts.iter().map(|c| c[0]).collect::<Vec<_>>(), expect);
    }

    /// Direct counts of every lattice of one level (boxes of side `s`,
    /// origin at `min - j s / b`), independent of the kernel's fine grid.
    fn direct_level(pts: &[f64], d: usize, b: usize, s: f64, k: i32) -> (u64, f64, f64) {
        let n = pts.len() / d;
        let mut lo = vec![f64::INFINITY; d];
        let mut hi = vec![f64::NEG_INFINITY; d];
        for p in pts.chunks_exact(d) {
            for a in 0..d {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        let shifts = b.pow(d as u32);
        let (mut aligned, mut sum_all, mut sum_in, mut n_in_lat) = (0u64, 0.0, 0.0, 0usize);
        for j in 0..shifts {
            let sh: Vec<f64> = (0..d).map(|a| ((j / b.pow(a as u32)) % b) as f64).collect();
            let mut all = std::collections::HashSet::new();
            let mut inside = std::collections::HashSet::new();
            let mut n_inside = 0usize;
            for p in pts.chunks_exact(d) {
                let mut key = vec![];
                let mut ins = true;
                for a in 0..d {
                    let mut c = ((p[a] - lo[a]) / s + sh[a] / b as f64).floor();
                    if sh[a] == 0.0 {
                        // an unshifted axis closes its last box at the top
                        c = c.min(b.pow(k as u32) as f64 - 1.0);
                    }
                    let low = c * s - sh[a] * s / b as f64;
                    ins &=
                        low >= -1e-9 * s && low + s <= (hi[a] - lo[a]) * (1.0 + 1e-12) + 1e-9 * s;
                    key.push(c as i64);
                }
                if ins {
                    inside.insert(key.clone());
                    n_inside += 1;
                }
                all.insert(key);
            }
            if j == 0 {
                aligned = all.len() as u64;
            }
            sum_all += all.len() as f64;
            if n_inside > 0 {
                sum_in += inside.len() as f64 * n as f64 / n_inside as f64;
                n_in_lat += 1;
            }
        }
        (aligned, sum_all / shifts as f64, sum_in / n_in_lat as f64)
    }

    #[test]
    fn lattice_levels_match_direct_counts() {
        // points in an annulus (2D) and on a random subset of a line (1D):
        // every level's aligned, shifted and edge-corrected counts equal
        // direct counts of the lattices at origin min - j s / b
        let u = crate::testdata::uniform(40_000, 7);
        let mut ring = vec![];
        for q in u.chunks_exact(2) {
            let (x, y) = (2.0 * q[0] - 1.0, 2.0 * q[1] - 1.0);
            let r = (x * x + y * y).sqrt();
            if (0.5..1.0).contains(&r) {
                ring.extend([3.0 * x + 10.0, 1.7 * y - 4.0]);
            }
        }
        let line: Vec<f64> = u.iter().take(5000).map(|v| 5.0 * v * v).collect();
        for (pts, d) in [(ring, 2usize), (line, 1usize)] {
            let n = pts.len() / d;
            for b in [2u64, 3] {
                let lv = point_lattice_levels(&pts, n, d, b, 1, 0.0, 5).unwrap();
                assert_eq!(lv.len(), 5);
                for (i, l) in lv.iter().enumerate() {
                    let (a, sh, si) = direct_level(&pts, d, b as usize, l.size, i as i32 + 1);
                    assert_eq!(l.aligned, a, "b {b} level {i} d {d}");
                    assert!(
                        (l.shifted - sh).abs() < 1e-9,
                        "{} {sh} b {b} level {i} d {d} n {n} size {}",
                        l.shifted,
                        l.size
                    );
                    assert!(
                        (l.shifted_inside - si).abs() < 1e-9 * si,
                        "{} {si}",
                        l.shifted_inside
                    );
                }
            }
        }
    }

    #[test]
    fn lattice_levels_stop_at_the_occupancy() {
        // 4096 points uniform in the unit square: 4^k aligned boxes of base 2
        // (all occupied while they hold many points); at least 20 per box
        // leaves k = 1..=7 (4^7 = 16384 boxes: 0.25 per box, stop earlier)
        let u = crate::testdata::uniform(8192, 3);
        let lv = point_lattice_levels(&u, 4096, 2, 2, 1, 20.0, 30).unwrap();
        assert_eq!(lv.len(), 3); // 4, 16, 64 boxes; 256 boxes hold 16 < 20
        assert_eq!(
            lv.iter().map(|l| l.aligned).collect::<Vec<_>>(),
            vec![4, 16, 64]
        );
    }

    #[test]
    fn lattice_levels_reject_bad_input() {
        assert!(point_lattice_levels(&[0.0, 0.0], 1, 2, 3, 1, 1.0, 4).is_err());
        assert!(point_lattice_levels(&[0.0, f64::NAN], 1, 2, 3, 1, 1.0, 4).is_err());
        assert!(point_lattice_levels(&[0.0, 1.0], 2, 1, 1, 1, 1.0, 4).is_err());
    }
}
