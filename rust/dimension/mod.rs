//! Fractal dimension estimators: the heavy counting work. The log-log fit and
//! the choice of scale range are done by the caller (the Python
//! `DimensionFit`), so every kernel here returns raw measures per scale.
//!
//! * [`boxcount`]: lattice box counting of binary sets in 1, 2 and 3 dimensions.
//! * [`points`]: box counting of point sets given as coordinates.
//! * [`dbc`]: differential box counting of grayscale images and DEMs.
//! * [`affine`]: per-column height ranges for self-affine box counting of graphs.
//! * [`higuchi`]: curve lengths of Higuchi's method for profiles.
//! * [`mass`]: Voss's P(m, L) box masses and the image-wide mass curve.
//! * [`blanket`]: Peleg's covering blanket growth and image-wide areas.
//! * [`lattice`]: the box lattices (sizes, grid shifts) shared by the counters.

pub mod affine;
pub mod blanket;
pub mod boxcount;
pub mod dbc;
pub mod higuchi;
pub mod lattice;
pub mod mass;
pub mod points;

/// The sums of per-band parts `(sums, valid count)`, added in band order
/// (so the result does not depend on the thread count), and the total
/// count; no valid value at all is an error naming `data`.
pub(crate) fn sum_parts(
    parts: Vec<(Vec<f64>, usize)>,
    len: usize,
) -> crate::CoreResult<(Vec<f64>, usize)> {
    let mut sums = vec![0.0f64; len];
    let mut n = 0;
    for (s, c) in parts {
        for (a, b) in sums.iter_mut().zip(s) {
            *a += b;
        }
        n += c;
    }
    if n == 0 {
        return Err(crate::CoreError::invalid(
            "data",
            "no valid value (all NaN)",
        ));
    }
    Ok((sums, n))
}
