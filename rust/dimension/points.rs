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

/// Count occupied boxes of an `n x d` row-major coordinate array.
pub fn point_box_count(
    coords: &[f64],
    n: usize,
    d: usize,
    box_sizes: &[f64],
    n_offsets: usize,
) -> CoreResult<PointCounts> {
    if n == 0 || d == 0 || coords.len() != n * d {
        return Err(CoreError::invalid("data", "point set is empty"));
    }
    if d > 16 {
        return Err(CoreError::invalid(
            "data",
            format!("at most 16 coordinates per point, got {d}"),
        ));
    }
    if coords.iter().any(|v| !v.is_finite()) {
        return Err(CoreError::invalid(
            "data",
            "coordinates must be finite (no NaN or inf)",
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
    let mut mins = vec![f64::INFINITY; d];
    let mut maxs = vec![f64::NEG_INFINITY; d];
    for p in coords.chunks_exact(d) {
        for a in 0..d {
            mins[a] = mins[a].min(p[a]);
            maxs[a] = maxs[a].max(p[a]);
        }
    }
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
}
