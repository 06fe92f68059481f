//! One georeference for every raster: [`GeoGrid`].
//!
//! Convention (the GDAL/rasterio one): row 0 is north, columns run east.
//! Cell `(row, col)` has its outer corner at
//!
//! ```text
//! x = x0 + col dx cos(r) + row dy sin(r)
//! y = y0 + col dx sin(r) - row dy cos(r)
//! ```
//!
//! with `(x0, y0)` the outer (north-west) corner of cell `(0, 0)`, `dx, dy > 0`
//! the cell sizes along a row and down a column, and `r` the counter-clockwise
//! rotation of the grid in degrees (0 for a north-up grid). Cell centres are
//! at `col + 0.5`, `row + 0.5`. As an affine transform (rasterio's `Affine`,
//! `x = a col + b row + c`, `y = d col + e row + f`) the grid is
//! `a = dx cos r, b = dy sin r, c = x0, d = dx sin r, e = -dy cos r, f = y0`.
use crate::error::{CoreError, CoreResult};

/// Origin, cell size, rotation and CRS of a row-0-north raster.
#[derive(Debug, Clone, PartialEq)]
pub struct GeoGrid {
    /// Map x of the outer corner of cell (0, 0).
    pub x0: f64,
    /// Map y of the outer corner of cell (0, 0).
    pub y0: f64,
    /// Cell size along a row (map units, > 0).
    pub dx: f64,
    /// Cell size down a column (map units, > 0).
    pub dy: f64,
    /// Counter-clockwise rotation of the grid, degrees.
    pub rotation: f64,
    /// Coordinate reference system (WKT, EPSG code or PROJ string), if known.
    pub crs: Option<String>,
}

impl GeoGrid {
    /// A north-up grid, checked: `dx`, `dy` finite and > 0, origin finite.
    pub fn new(x0: f64, y0: f64, dx: f64, dy: f64) -> CoreResult<Self> {
        GeoGrid {
            x0,
            y0,
            dx,
            dy,
            rotation: 0.0,
            crs: None,
        }
        .checked()
    }

    /// The grid of pixel units used when a raster has no georeference:
    /// cell size `h`, origin at the lower-left corner of `rows` rows
    /// (`x0 = 0`, `y0 = rows h`).
    pub fn pixels(rows: usize, h: f64) -> CoreResult<Self> {
        GeoGrid::new(0.0, rows as f64 * h, h, h)
    }

    /// Check every field; errors name `cell_size`, `origin` or `rotation`.
    pub fn checked(self) -> CoreResult<Self> {
        for (v, what) in [(self.dx, "dx"), (self.dy, "dy")] {
            if !v.is_finite() || v <= 0.0 {
                return Err(CoreError::invalid(
                    "cell_size",
                    format!("{what} must be a finite number > 0, got {v}"),
                ));
            }
        }
        if !self.x0.is_finite() || !self.y0.is_finite() {
            return Err(CoreError::invalid(
                "origin",
                format!("must be finite, got ({}, {})", self.x0, self.y0),
            ));
        }
        if !self.rotation.is_finite() {
            return Err(CoreError::invalid(
                "rotation",
                format!("must be finite, got {}", self.rotation),
            ));
        }
        Ok(self)
    }

    /// The affine transform `(a, b, c, d, e, f)` (rasterio order).
    pub fn affine(&self) -> [f64; 6] {
        if self.rotation == 0.0 {
            return [self.dx, 0.0, self.x0, 0.0, -self.dy, self.y0];
        }
        let (s, c) = self.rotation.to_radians().sin_cos();
        [
            self.dx * c,
            self.dy * s,
            self.x0,
            self.dx * s,
            -self.dy * c,
            self.y0,
        ]
    }

    /// The grid of an affine transform `(a, b, c, d, e, f)`; errors (naming
    /// `transform`) when it is not a row-0-north grid of square-angled cells
    /// (a similarity with a reflection: rows must run south of columns).
    pub fn from_affine(t: [f64; 6], crs: Option<String>) -> CoreResult<Self> {
        let [a, b, c, d, e, f] = t;
        if !t.iter().all(|v| v.is_finite()) {
            return Err(CoreError::invalid(
                "transform",
                format!("must be finite, got {t:?}"),
            ));
        }
        let (dx, dy) = (a.hypot(d), b.hypot(e));
        let det = a * e - b * d;
        // columns along (a, d), rows along (b, e) = (dy sin r, -dy cos r):
        // perpendicular, and clockwise of the columns (row 0 north)
        let ortho = (a * b + d * e).abs() <= 1e-12 * dx * dy;
        // finite inputs: det is a number, so `det >= 0.0` is the negation of `det < 0.0`
        if det >= 0.0 || !ortho {
            return Err(CoreError::invalid(
                "transform",
                format!(
                    "expected a grid with row 0 north and square-angled cells \
                     (e < 0 when not rotated), got {t:?}"
                ),
            ));
        }
        let rotation = if b == 0.0 && d == 0.0 {
            0.0
        } else {
            d.atan2(a).to_degrees()
        };
        GeoGrid {
            x0: c,
            y0: f,
            dx,
            dy,
            rotation,
            crs,
        }
        .checked()
    }

    /// Map coordinates of the centre of cell `(row, col)` (fractional
    /// indices allowed).
    #[inline]
    pub fn center(&self, row: f64, col: f64) -> [f64; 2] {
        self.point(row + 0.5, col + 0.5)
    }

    /// Map coordinates of grid position `(row, col)` in corner units.
    #[inline]
    pub fn point(&self, row: f64, col: f64) -> [f64; 2] {
        let [a, b, c, d, e, f] = self.affine();
        [a * col + b * row + c, d * col + e * row + f]
    }

    /// Error (naming `param`) when the two grids have different CRSs; a
    /// missing CRS matches any.
    pub fn check_same_crs(&self, other: &GeoGrid, param: &str) -> CoreResult<()> {
        match (&self.crs, &other.crs) {
            (Some(a), Some(b)) if a != b => Err(CoreError::invalid(
                param,
                format!("CRS {b:?} does not match {a:?}"),
            )),
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn north_up_centres_and_affine_round_trip() {
        let g = GeoGrid::new(500_000.0, 4_000_000.0, 30.0, 25.0).unwrap();
        assert_eq!(g.center(0.0, 0.0), [500_015.0, 3_999_987.5]);
        assert_eq!(g.center(2.0, 3.0), [500_105.0, 3_999_937.5]);
        let back = GeoGrid::from_affine(g.affine(), None).unwrap();
        assert_eq!(back, g);
    }

    #[test]
    fn rotated_grid_keeps_cell_sizes() {
        let g = GeoGrid {
            rotation: 30.0,
            ..GeoGrid::new(10.0, 20.0, 2.0, 3.0).unwrap()
        };
        let back = GeoGrid::from_affine(g.affine(), None).unwrap();
        assert!((back.dx - 2.0).abs() < 1e-12 && (back.dy - 3.0).abs() < 1e-12);
        assert!((back.rotation - 30.0).abs() < 1e-9);
        // one step along a row moves dx along the rotated x axis
        let (p, q) = (g.point(0.0, 0.0), g.point(0.0, 1.0));
        let (s, c) = 30f64.to_radians().sin_cos();
        assert!((q[0] - p[0] - 2.0 * c).abs() < 1e-12 && (q[1] - p[1] - 2.0 * s).abs() < 1e-12);
    }

    #[test]
    fn bad_grids_name_the_parameter() {
        for (dx, dy) in [
            (0.0, 1.0),
            (1.0, -1.0),
            (f64::NAN, 1.0),
            (1.0, f64::INFINITY),
        ] {
            let e = GeoGrid::new(0.0, 0.0, dx, dy).unwrap_err().to_string();
            assert!(e.starts_with("cell_size:"), "{e}");
        }
        let e = GeoGrid::new(f64::NAN, 0.0, 1.0, 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("origin:"), "{e}");
        // south-up (e > 0) and sheared transforms are refused
        for t in [
            [1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            [1.0, 0.5, 0.0, 0.0, -1.0, 0.0],
        ] {
            let e = GeoGrid::from_affine(t, None).unwrap_err().to_string();
            assert!(e.starts_with("transform:"), "{e}");
        }
        let a = GeoGrid {
            crs: Some("EPSG:32633".into()),
            ..GeoGrid::pixels(4, 1.0).unwrap()
        };
        let b = GeoGrid {
            crs: Some("EPSG:4326".into()),
            ..a.clone()
        };
        let e = a.check_same_crs(&b, "other").unwrap_err().to_string();
        assert!(e.starts_with("other:") && e.contains("EPSG:4326"), "{e}");
        assert!(a
            .check_same_crs(&GeoGrid::pixels(4, 1.0).unwrap(), "other")
            .is_ok());
    }
}
