//! Triangulated irregular networks (TINs) through the `spade` crate.
//!
//! | module | what |
//! |---|---|
//! | [`delaunay`] | Delaunay and constrained Delaunay triangulation of scattered points |
//! | [`greedy`] | error-bounded terrain meshes of a raster (Garland and Heckbert 1995) |
//! | [`interpolate`] | gridding of scattered values: natural neighbour (Sibson), linear, nearest |
//!
//! spade uses exact geometric predicates, so every result is a true
//! (constrained) Delaunay triangulation of the input coordinates.
pub mod delaunay;
pub mod greedy;
pub mod interpolate;

use crate::error::{CoreError, CoreResult};
use spade::{HasPosition, Point2};

/// A vertex that remembers its row in the caller's point array.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Indexed {
    pub pos: Point2<f64>,
    pub idx: usize,
}

impl HasPosition for Indexed {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

/// Map a spade insertion error to an error naming `param`.
pub(crate) fn insertion_error(param: &str, e: spade::InsertionError) -> CoreError {
    use spade::InsertionError::*;
    let msg = match e {
        TooSmall => format!(
            "coordinates must be 0 or of absolute value at least {:e}",
            spade::MIN_ALLOWED_VALUE
        ),
        TooLarge => format!(
            "coordinates must be of absolute value at most {:e}",
            spade::MAX_ALLOWED_VALUE
        ),
        NAN => "coordinates must not be NaN".to_string(),
    };
    CoreError::invalid(param, msg)
}

/// Read `n` points from `xy(i) -> (x, y)`, rejecting NaN, inf and values
/// outside spade's range, into indexed vertices (`-0.0` becomes `0.0`).
pub(crate) fn indexed_points(
    param: &str,
    n: usize,
    xy: impl Fn(usize) -> (f64, f64),
) -> CoreResult<Vec<Indexed>> {
    let mut out = Vec::new();
    out.try_reserve_exact(n)
        .map_err(|_| CoreError::invalid(param, format!("cannot allocate {n} vertices")))?;
    for i in 0..n {
        let (x, y) = xy(i);
        if !x.is_finite() || !y.is_finite() {
            return Err(CoreError::invalid(
                param,
                format!("row {i} has a NaN or infinite coordinate ({x}, {y})"),
            ));
        }
        let p = Point2::new(x + 0.0, y + 0.0);
        spade::validate_coordinate(p.x)
            .and_then(|_| spade::validate_coordinate(p.y))
            .map_err(|e| insertion_error(param, e))?;
        out.push(Indexed { pos: p, idx: i });
    }
    Ok(out)
}
