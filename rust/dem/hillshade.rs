//! Shaded relief (hillshade) with Horn's gradients, GDAL's conventions.
//!
//! For the 3 x 3 window `a b c / d e f / g h i` (row 0 to the north):
//!
//! ```text
//! dz/dx (east)  = ((c + 2f + i) - (a + 2d + g)) / (8 dx)     (Horn 1981)
//! dz/dy (north) = ((a + 2b + c) - (g + 2h + i)) / (8 dy)
//! cos(i) = (sin(alt) - cos(alt) (sin(az) z dz/dx + cos(az) z dz/dy)) / sqrt(1 + z^2 |grad|^2)
//! ```
//!
//! with the azimuth `az` clockwise from north (the direction the light comes
//! from) and `z` the z-factor: the Lambertian reflectance of the surface lit by
//! a distant sun, clamped at 0 (`gdaldem hillshade` writes `1 + 254 cos(i)`).
//! Multidirectional shading follows GDAL (Mark 1992): the weighted mean of
//! azimuths 225, 270, 315 and 360 with weights `sin^2(aspect - az)`, halved.
//!
//! Missing neighbours (outside the grid or nodata) take the centre value,
//! as `gdaldem -compute_edges` does; a nodata centre gives NaN.
use crate::error::{CoreError, CoreResult};
use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

/// Lighting options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadeParams {
    /// Degrees clockwise from north, where the light comes from.
    pub azimuth: f64,
    /// Degrees above the horizon.
    pub altitude: f64,
    /// Vertical exaggeration (and unit conversion of heights).
    pub z_factor: f64,
    /// GDAL's multidirectional shading (azimuth ignored).
    pub multidirectional: bool,
}

/// Hillshade of `z` (NaN = nodata) with a column spacing per row `dx[row]`
/// (so geographic grids have their metres-per-degree at each latitude) and a
/// row spacing `dy`, both positive. Returns the reflectance in [0, 1], NaN
/// where the centre is nodata.
pub fn hillshade(
    z: ArrayView2<f64>,
    dx: &[f64],
    dy: f64,
    p: &ShadeParams,
) -> CoreResult<Array2<f32>> {
    let (rows, cols) = z.dim();
    if rows == 0 || cols == 0 {
        return Err(CoreError::invalid("dem", "empty grid"));
    }
    if dx.len() != rows {
        return Err(CoreError::invalid(
            "cell_size",
            format!("need {rows} row spacings, got {}", dx.len()),
        ));
    }
    if dx.iter().any(|v| !(v.is_finite() && *v > 0.0)) || !(dy.is_finite() && dy > 0.0) {
        return Err(CoreError::invalid(
            "cell_size",
            "expected positive finite cell sizes",
        ));
    }
    if !(p.altitude.is_finite() && (0.0..=90.0).contains(&p.altitude)) {
        return Err(CoreError::invalid(
            "altitude",
            format!("expected degrees in [0, 90], got {}", p.altitude),
        ));
    }
    if !p.azimuth.is_finite() {
        return Err(CoreError::invalid(
            "azimuth",
            format!("expected a finite number of degrees, got {}", p.azimuth),
        ));
    }
    if !p.z_factor.is_finite() {
        return Err(CoreError::invalid(
            "z_factor",
            format!("expected a finite number, got {}", p.z_factor),
        ));
    }
    let alt = p.altitude.to_radians();
    let (sin_alt, cos_alt) = alt.sin_cos();
    let zf = p.z_factor;
    let sun = |az_deg: f64| -> (f64, f64) {
        let (s, c) = az_deg.to_radians().sin_cos();
        (cos_alt * zf * s, cos_alt * zf * c)
    };
    let main_sun = sun(p.azimuth);
    let multi = [sun(225.0), sun(270.0), sun(315.0), sun(360.0)];
    let zf2 = zf * zf;
    let shade = |gx: f64, gy: f64| -> f64 {
        let norm = 1.0 / (1.0 + zf2 * (gx * gx + gy * gy)).sqrt();
        let one = |(a, b): (f64, f64)| (sin_alt - (a * gx + b * gy)) * norm;
        let v = if p.multidirectional {
            // GDAL: aspect = atan2(y, x) of its own gradient (x = -gx, y = gy).
            let aspect = gy.atan2(-gx);
            let (sa, ca) = aspect.sin_cos();
            let w225 = 0.5 * (1.0 - 2.0 * sa * ca);
            let w270 = ca * ca;
            let w315 = 0.5 * (1.0 + 2.0 * sa * ca);
            let w360 = sa * sa;
            0.5 * (w225 * one(multi[0]).max(0.0)
                + w270 * one(multi[1]).max(0.0)
                + w315 * one(multi[2]).max(0.0)
                + w360 * one(multi[3]).max(0.0))
        } else {
            one(main_sun)
        };
        v.clamp(0.0, 1.0)
    };
    let zs = z.as_standard_layout();
    let zs = zs
        .as_slice()
        .ok_or_else(|| CoreError::Internal("dem not contiguous".into()))?;
    let mut out = vec![0.0f32; rows * cols];
    out.par_chunks_mut(cols).enumerate().for_each(|(i, row)| {
        let inv_x = 1.0 / (8.0 * dx[i]);
        let inv_y = 1.0 / (8.0 * dy);
        let cur = &zs[i * cols..(i + 1) * cols];
        let interior_row = i > 0 && i + 1 < rows;
        let (up, down) = if interior_row {
            (
                &zs[(i - 1) * cols..i * cols],
                &zs[(i + 1) * cols..(i + 2) * cols],
            )
        } else {
            (cur, cur)
        };
        // General path: missing neighbours (outside or NaN) take the centre value.
        let slow = |j: usize| -> f32 {
            let e = cur[j];
            if e.is_nan() {
                return f32::NAN;
            }
            let at = |di: isize, dj: isize| -> f64 {
                let (ii, jj) = (i as isize + di, j as isize + dj);
                if ii < 0 || jj < 0 || ii >= rows as isize || jj >= cols as isize {
                    return e;
                }
                let v = zs[ii as usize * cols + jj as usize];
                if v.is_nan() {
                    e
                } else {
                    v
                }
            };
            let (a, b, c) = (at(-1, -1), at(-1, 0), at(-1, 1));
            let (d, f) = (at(0, -1), at(0, 1));
            let (g, h, k) = (at(1, -1), at(1, 0), at(1, 1));
            let gx = ((c + 2.0 * f + k) - (a + 2.0 * d + g)) * inv_x;
            let gy = ((a + 2.0 * b + c) - (g + 2.0 * h + k)) * inv_y;
            shade(gx, gy) as f32
        };
        for j in 0..cols {
            if !interior_row || j == 0 || j + 1 == cols {
                row[j] = slow(j);
                continue;
            }
            let (a, b, c) = (up[j - 1], up[j], up[j + 1]);
            let (d, e, f) = (cur[j - 1], cur[j], cur[j + 1]);
            let (g, h, k) = (down[j - 1], down[j], down[j + 1]);
            let gx = ((c + 2.0 * f + k) - (a + 2.0 * d + g)) * inv_x;
            let gy = ((a + 2.0 * b + c) - (g + 2.0 * h + k)) * inv_y;
            // NaN anywhere in the window propagates to gx or gy.
            row[j] = if gx.is_nan() || gy.is_nan() || e.is_nan() {
                slow(j)
            } else {
                shade(gx, gy) as f32
            };
        }
    });
    Array2::from_shape_vec((rows, cols), out).map_err(|e| CoreError::Internal(e.to_string()))
}

/// GDAL's byte encoding of a reflectance: `round(1 + 254 L)`, 0 for NaN.
pub fn to_byte(shade: &[f32]) -> Vec<u8> {
    shade
        .par_iter()
        .map(|&v| {
            if v.is_nan() {
                0
            } else {
                (1.0 + 254.0 * v.clamp(0.0, 1.0)).round() as u8
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(az: f64) -> ShadeParams {
        ShadeParams {
            azimuth: az,
            altitude: 45.0,
            z_factor: 1.0,
            multidirectional: false,
        }
    }

    #[test]
    fn flat_is_sin_altitude() {
        let z = Array2::<f64>::from_elem((4, 5), 10.0);
        let s = hillshade(z.view(), &[1.0; 4], 1.0, &params(315.0)).unwrap();
        assert!(s
            .iter()
            .all(|v| (*v as f64 - 45f64.to_radians().sin()).abs() < 1e-6));
    }

    #[test]
    fn plane_facing_the_sun() {
        // Plane rising to the south-east (z = x - y, y north): its normal
        // points north-west; with the sun in the north-west at altitude
        // 90 - slope the light is normal: cos(i) = 1.
        let z = Array2::from_shape_fn((6, 6), |(i, j)| j as f64 + i as f64);
        // gradient: dz/dx = 1, dz/dy = -1 (north is row 0): |grad| = sqrt 2,
        // slope 54.7356 deg, normal towards azimuth 315.
        let slope = 2f64.sqrt().atan().to_degrees();
        let p = ShadeParams {
            azimuth: 315.0,
            altitude: 90.0 - slope,
            z_factor: 1.0,
            multidirectional: false,
        };
        let s = hillshade(z.view(), &[1.0; 6], 1.0, &p).unwrap();
        assert!((s[[2, 2]] - 1.0).abs() < 1e-6, "{}", s[[2, 2]]);
        // From the opposite side the slope is in shadow.
        let s2 = hillshade(z.view(), &[1.0; 6], 1.0, &params(135.0)).unwrap();
        assert_eq!(s2[[2, 2]], 0.0);
    }

    #[test]
    fn nodata_centre_is_nan() {
        let mut z = Array2::<f64>::zeros((3, 3));
        z[[1, 1]] = f64::NAN;
        let s = hillshade(z.view(), &[1.0; 3], 1.0, &params(315.0)).unwrap();
        assert!(s[[1, 1]].is_nan());
        assert!(s[[0, 0]].is_finite());
    }

    #[test]
    fn bad_cell_size() {
        let z = Array2::<f64>::zeros((3, 3));
        assert!(hillshade(z.view(), &[1.0, 0.0, 1.0], 1.0, &params(315.0)).is_err());
        assert!(hillshade(z.view(), &[1.0; 3], f64::NAN, &params(315.0)).is_err());
    }
}
