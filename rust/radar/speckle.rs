//! Multiplicative speckle of fully developed scattering (Goodman 1976).
//!
//! A single-look complex pixel is a circular Gaussian field, so its
//! intensity is exponential with mean `sigma0`; the mean of `L` independent
//! looks is Gamma(shape `L`, scale `sigma0 / L`): mean `sigma0`, variance
//! `sigma0^2 / L`. Each look is drawn as `-ln U` (U uniform on (0, 1)), and
//! the `L` looks of a pixel as `-ln(U_1 ... U_L)` with the product taken 16
//! factors at a time (no underflow: `U > 2^-53`).
//!
//! The uniforms come from the counter-based generator
//! ([`crate::rng`]): look `j` of the pixel at global position
//! `(row, col)` of a grid with `global_cols` columns is the sample at index
//! `(row * global_cols + col) * L + j` of the stream `(seed, STREAM)`, so the
//! output is the same for any number of threads and for any tiling of the
//! grid (Dask chunks).
use crate::error::{CoreError, CoreResult};
use crate::rng::StreamKey;
use rayon::prelude::*;

/// The stream of the speckle draws.
pub const STREAM: u64 = 0x5eec_1e00;

/// Where a block sits in the whole grid (for tiled computation).
#[derive(Debug, Clone, Copy)]
pub struct Placement {
    /// Global `(row, col)` of the block's first element.
    pub origin: (u64, u64),
    /// Columns of the whole grid.
    pub global_cols: u64,
}

/// The mean of `looks` unit-mean exponential draws at `index` of `key`.
#[inline]
pub fn gamma_unit(key: StreamKey, index: u64, looks: u32) -> f64 {
    let base = index.wrapping_mul(looks as u64);
    let mut sum = 0.0;
    let mut prod = 1.0;
    for j in 0..looks as u64 {
        prod *= key.uniform(base.wrapping_add(j));
        if j % 16 == 15 {
            sum -= prod.ln();
            prod = 1.0;
        }
    }
    if looks % 16 != 0 {
        sum -= prod.ln();
    }
    sum / looks as f64
}

/// `intensity` (row-major, `cols` columns) times independent unit-mean
/// Gamma(`looks`) speckle. NaN stays NaN; a negative or infinite intensity is
/// an error.
pub fn speckle(
    intensity: &[f64],
    cols: usize,
    looks: u32,
    seed: u64,
    place: Placement,
) -> CoreResult<Vec<f64>> {
    if looks < 1 {
        return Err(CoreError::invalid("looks", "expected an integer >= 1"));
    }
    if cols == 0 && !intensity.is_empty() || cols != 0 && intensity.len() % cols != 0 {
        return Err(CoreError::invalid(
            "intensity",
            "length is not a multiple of cols",
        ));
    }
    if let Some(v) = intensity.iter().find(|v| **v < 0.0 || v.is_infinite()) {
        return Err(CoreError::invalid(
            "intensity",
            format!("expected finite values >= 0 (NaN = missing), found {v}"),
        ));
    }
    if place.global_cols < place.origin.1 + cols as u64 {
        return Err(CoreError::invalid(
            "global_cols",
            "the block extends beyond the global grid's columns",
        ));
    }
    let key = StreamKey::new(seed, STREAM);
    let mut out = vec![0.0; intensity.len()];
    if cols == 0 {
        return Ok(out);
    }
    out.par_chunks_mut(cols)
        .zip(intensity.par_chunks(cols))
        .enumerate()
        .for_each(|(r, (o, x))| {
            let grow = place.origin.0 + r as u64;
            let start = grow
                .wrapping_mul(place.global_cols)
                .wrapping_add(place.origin.1);
            for (c, (o, &v)) in o.iter_mut().zip(x).enumerate() {
                *o = if v.is_nan() {
                    f64::NAN
                } else {
                    v * gamma_unit(key, start.wrapping_add(c as u64), looks)
                };
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn whole(cols: usize) -> Placement {
        Placement {
            origin: (0, 0),
            global_cols: cols as u64,
        }
    }

    #[test]
    fn mean_and_variance_of_gamma_looks() {
        for looks in [1u32, 3, 20] {
            let n = 200_000usize;
            let x = vec![2.0; n];
            let y = speckle(&x, 1000, looks, 7, whole(1000)).unwrap();
            let m = y.iter().sum::<f64>() / n as f64;
            let v = y.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / (n - 1) as f64;
            let want_v = 4.0 / looks as f64;
            // standard errors: of the mean sqrt(v / n), of the variance
            // sqrt((mu4 - v^2) / n) with mu4 = 4! ... use the Gamma kurtosis
            let se_m = (want_v / n as f64).sqrt();
            let kurt_excess = 6.0 / looks as f64;
            let se_v = want_v * ((2.0 + kurt_excess) / n as f64).sqrt();
            assert!((m - 2.0).abs() < 4.0 * se_m, "L={looks} mean {m}");
            assert!((v - want_v).abs() < 4.0 * se_v, "L={looks} var {v}");
        }
    }

    #[test]
    fn tiles_equal_the_whole() {
        let (rows, cols) = (7usize, 9usize);
        let x: Vec<f64> = (0..rows * cols).map(|i| 1.0 + i as f64).collect();
        let all = speckle(&x, cols, 4, 3, whole(cols)).unwrap();
        // the block rows 2..5, cols 3..8
        let sub: Vec<f64> = (2..5)
            .flat_map(|r| (3..8).map(move |c| (r, c)))
            .map(|(r, c)| x[r * cols + c])
            .collect();
        let place = Placement {
            origin: (2, 3),
            global_cols: cols as u64,
        };
        let part = speckle(&sub, 5, 4, 3, place).unwrap();
        for (k, (r, c)) in (2..5).flat_map(|r| (3..8).map(move |c| (r, c))).enumerate() {
            assert_eq!(part[k], all[r * cols + c]);
        }
    }

    #[test]
    fn bad_input() {
        assert!(speckle(&[1.0, -1.0], 2, 1, 0, whole(2)).is_err());
        assert!(speckle(&[1.0, f64::INFINITY], 2, 1, 0, whole(2)).is_err());
        assert!(speckle(&[1.0], 1, 0, 0, whole(1)).is_err());
        let y = speckle(&[f64::NAN, 0.0], 2, 2, 0, whole(2)).unwrap();
        assert!(y[0].is_nan() && y[1] == 0.0);
    }
}
