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
//! Edges follow `gdaldem -compute_edges` (GDAL's `GDALGeneric3x3Processing`):
//! a neighbour outside the grid is extrapolated linearly from the two cells
//! inward, `2a - b` (`a` the cell on the edge, `b` the next one in); in the
//! first and last rows the columns beyond the corners repeat the centre
//! column. A missing (nodata) neighbour, or an extrapolation from a missing
//! cell, then takes the centre value; a nodata centre gives NaN. Grids of a
//! single row or column have no cell to extrapolate from: missing
//! neighbours take the centre value.
//!
//! [`hillshade_gdal_byte`] reproduces `gdaldem hillshade -compute_edges`
//! bit for bit: float32 window arithmetic, GDAL's reciprocal square root
//! (`rsqrtss` and one Newton step on x86_64) and its float-to-byte rounding.
use crate::error::{CoreError, CoreResult};
use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

/// A sample of a height grid: its missing-value test and GDAL's edge
/// extrapolation `2a - b`, in the sample's own precision.
pub(crate) trait Cell: Copy {
    fn missing(self) -> bool;
    fn extrapolate(a: Self, b: Self) -> Self;
}

impl Cell for f64 {
    #[inline]
    fn missing(self) -> bool {
        self.is_nan()
    }
    #[inline]
    fn extrapolate(a: f64, b: f64) -> f64 {
        2.0 * a - b
    }
}

impl Cell for f32 {
    #[inline]
    fn missing(self) -> bool {
        self.is_nan()
    }
    #[inline]
    fn extrapolate(a: f32, b: f32) -> f32 {
        2.0 * a - b
    }
}

/// The 3 x 3 window `a b c / d e f / g h i` (row-major) of cell `(i, j)` of
/// the row-major grid `z` with GDAL's `-compute_edges` rule (module docs),
/// or `None` when the centre is missing.
#[inline]
pub(crate) fn gdal_window<T: Cell>(
    z: &[T],
    rows: usize,
    cols: usize,
    i: usize,
    j: usize,
) -> Option<[T; 9]> {
    let at = |r: usize, c: usize| z[r * cols + c];
    let e = at(i, j);
    if e.missing() {
        return None;
    }
    let mut w = [e; 9];
    if rows < 2 || cols < 2 {
        for di in 0..3usize {
            for dj in 0..3usize {
                let (r, c) = ((i + di).wrapping_sub(1), (j + dj).wrapping_sub(1));
                if r < rows && c < cols {
                    w[3 * di + dj] = at(r, c);
                }
            }
        }
    } else if i == 0 || i + 1 == rows {
        let cs = [
            if j == 0 { j } else { j - 1 },
            j,
            if j + 1 == cols { j } else { j + 1 },
        ];
        for (k, &c) in cs.iter().enumerate() {
            if i == 0 {
                w[k] = T::extrapolate(at(0, c), at(1, c));
                w[3 + k] = at(0, c);
                w[6 + k] = at(1, c);
            } else {
                w[k] = at(i - 1, c);
                w[3 + k] = at(i, c);
                w[6 + k] = T::extrapolate(at(i, c), at(i - 1, c));
            }
        }
    } else if j == 0 || j + 1 == cols {
        for (k, r) in [i - 1, i, i + 1].into_iter().enumerate() {
            if j == 0 {
                w[3 * k] = T::extrapolate(at(r, 0), at(r, 1));
                w[3 * k + 1] = at(r, 0);
                w[3 * k + 2] = at(r, 1);
            } else {
                w[3 * k] = at(r, j - 1);
                w[3 * k + 1] = at(r, j);
                w[3 * k + 2] = T::extrapolate(at(r, j), at(r, j - 1));
            }
        }
    } else {
        for di in 0..3 {
            for dj in 0..3 {
                w[3 * di + dj] = at(i + di - 1, j + dj - 1);
            }
        }
    }
    for v in w.iter_mut() {
        if v.missing() {
            *v = e;
        }
    }
    Some(w)
}

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
        // General path: GDAL's edge and nodata rule (module docs).
        let slow = |j: usize| -> f32 {
            let Some([a, b, c, d, _, f, g, h, k]) = gdal_window(zs, rows, cols, i, j) else {
                return f32::NAN;
            };
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

/// `a / sqrt(b)` as GDAL computes it on x86_64: the single-precision
/// reciprocal square root estimate (`rsqrtss`) refined by one Newton step in
/// double precision (`ApproxADivByInvSqrtB` in `gdaldem_lib.cpp`).
#[inline]
fn approx_a_div_sqrt_b(a: f64, b: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvtss_f32, _mm_rsqrt_ss, _mm_set_ss};
        // SAFETY: SSE is part of the x86_64 baseline; the intrinsics only
        // read and write registers.
        let r = unsafe { _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(b as f32))) } as f64;
        let r = r * (1.5 - (b * 0.5) * (r * r));
        a * r
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        a / b.sqrt()
    }
}

/// GDAL's float-to-byte conversion of an output value: `trunc(v + 0.5)`
/// clamped to [0, 255].
#[inline]
fn gdal_to_byte(v: f32) -> u8 {
    (v + 0.5).clamp(0.0, 255.0) as u8
}

/// `gdaldem hillshade -compute_edges` as bytes (`1 + 254 L`, 0 = nodata),
/// bit for bit, for a float32 grid `z` (NaN = nodata) with square or
/// rectangular cells `dx` (east) by `dy` (north), both positive.
///
/// The arithmetic is GDAL's: windows and Horn sums in float32 (its
/// `GDALHillshadeAlg_same_res` when `dx == dy`, `GDALHillshadeAlg` else,
/// `GDALHillshadeMultiDirectionalAlg` for multidirectional shading), the
/// shade in double precision with [`approx_a_div_sqrt_b`], the result
/// stored as float32 and converted by [`gdal_to_byte`].
pub fn hillshade_gdal_byte(
    z: ArrayView2<f32>,
    dx: f64,
    dy: f64,
    p: &ShadeParams,
) -> CoreResult<Array2<u8>> {
    let (rows, cols) = z.dim();
    if rows == 0 || cols == 0 {
        return Err(CoreError::invalid("dem", "empty grid"));
    }
    if !(dx.is_finite() && dx > 0.0 && dy.is_finite() && dy > 0.0) {
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
    if !(p.azimuth.is_finite() && p.z_factor.is_finite()) {
        return Err(CoreError::invalid(
            "azimuth",
            "expected finite azimuth and z_factor",
        ));
    }
    let d2r = std::f64::consts::PI / 180.0;
    // GDAL's geotransform: gt[1] = dx, gt[5] = -dy.
    let inv_ew = 1.0 / dx;
    let inv_ns = 1.0 / -dy;
    let zf = p.z_factor / 8.0;
    let sin_alt = (p.altitude * d2r).sin();
    let cos_alt_z = (p.altitude * d2r).cos() * zf;
    let az = p.azimuth * d2r;
    let cos_az_z = az.cos() * cos_alt_z;
    let sin_az_z = az.sin() * cos_alt_z;
    let square_z = zf * zf;
    let sin_alt_254 = 254.0 * sin_alt;
    let cos_az_z_254 = 254.0 * cos_az_z;
    let sin_az_z_254 = 254.0 * sin_az_z;
    let same_res = dx == dy;
    let square_z_inv2 = square_z * inv_ew * inv_ew;
    let cos_fact = cos_az_z_254 * -inv_ew;
    let sin_fact = sin_az_z_254 * inv_ew;
    // multidirectional constants
    let sin_alt_127 = 127.0 * sin_alt;
    let cos_alt_z_127 = 127.0 * cos_alt_z;
    let cos225_127 = 127.0 * (225.0 * d2r).cos() * cos_alt_z;
    let horn = |w: &[f32; 9]| -> (f64, f64) {
        let x = ((w[0] + w[3] + w[3] + w[6]) - (w[2] + w[5] + w[5] + w[8])) as f64 * inv_ew;
        let y = ((w[6] + w[7] + w[7] + w[8]) - (w[0] + w[1] + w[1] + w[2])) as f64 * inv_ns;
        (x, y)
    };
    let value = |w: &[f32; 9]| -> f32 {
        if p.multidirectional {
            let (x, y) = horn(w);
            let (xx, yy) = (x * x, y * y);
            let xx_plus_yy = xx + yy;
            if xx_plus_yy == 0.0 {
                return (1.0 + sin_alt_254) as f32;
            }
            let v225 = (sin_alt_127 + (x - y) * cos225_127).max(0.0);
            let v270 = (sin_alt_127 - x * cos_alt_z_127).max(0.0);
            let v315 = (sin_alt_127 + (x + y) * cos225_127).max(0.0);
            let v360 = (sin_alt_127 - y * cos_alt_z_127).max(0.0);
            let w225 = 0.5 * xx_plus_yy - x * y;
            let w270 = xx;
            let w315 = xx_plus_yy - w225;
            let w360 = yy;
            let c127 = approx_a_div_sqrt_b(
                (w225 * v225 + w270 * v270 + w315 * v315 + w360 * v360) / xx_plus_yy,
                1.0 + square_z * xx_plus_yy,
            );
            (1.0 + c127) as f32
        } else if same_res {
            let mut acc_x = w[0] - w[8];
            let six_minus_two = w[6] - w[2];
            let mut acc_y = acc_x;
            let three_minus_five = w[3] - w[5];
            let one_minus_seven = w[1] - w[7];
            acc_x += three_minus_five;
            acc_y += one_minus_seven;
            acc_x += three_minus_five;
            acc_y += one_minus_seven;
            acc_x += six_minus_two;
            acc_y -= six_minus_two;
            let (x, y) = (acc_x as f64, acc_y as f64);
            let c = approx_a_div_sqrt_b(
                sin_alt_254 + (x * sin_fact + y * cos_fact),
                1.0 + square_z_inv2 * (x * x + y * y),
            );
            (if c <= 0.0 { 1.0 } else { 1.0 + c }) as f32
        } else {
            let (x, y) = horn(w);
            let c = approx_a_div_sqrt_b(
                sin_alt_254 - (y * cos_az_z_254 - x * sin_az_z_254),
                1.0 + square_z * (x * x + y * y),
            );
            (if c <= 0.0 { 1.0 } else { 1.0 + c }) as f32
        }
    };
    let zs = z.as_standard_layout();
    let zs = zs
        .as_slice()
        .ok_or_else(|| CoreError::Internal("dem not contiguous".into()))?;
    let mut out =
        crate::buffers::try_filled(crate::buffers::checked_len(rows, cols, "dem")?, 0u8, "dem")?;
    out.par_chunks_mut(cols).enumerate().for_each(|(i, row)| {
        let interior_row = i > 0 && i + 1 < rows;
        for (j, o) in row.iter_mut().enumerate() {
            if interior_row && j > 0 && j + 1 < cols {
                // NaN anywhere around the centre propagates to the value
                // (the centre itself is not in Horn's sums): only then is the
                // window rebuilt with the nodata rule
                let b = (i - 1) * cols + j - 1;
                let w = [
                    zs[b],
                    zs[b + 1],
                    zs[b + 2],
                    zs[b + cols],
                    zs[b + cols + 1],
                    zs[b + cols + 2],
                    zs[b + 2 * cols],
                    zs[b + 2 * cols + 1],
                    zs[b + 2 * cols + 2],
                ];
                let v = value(&w);
                if !(v.is_nan() || w[4].is_nan()) {
                    *o = gdal_to_byte(v);
                    continue;
                }
            }
            let w = gdal_window(zs, rows, cols, i, j);
            *o = match w {
                Some(w) => gdal_to_byte(value(&w)),
                None => 0,
            };
        }
    });
    Array2::from_shape_vec((rows, cols), out).map_err(|e| CoreError::Internal(e.to_string()))
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
    fn edges_extrapolate_like_gdal() {
        // On a plane the extrapolation 2a - b continues the plane, so every
        // cell but the four corners (whose outer column repeats the centre
        // column, as in GDAL) has the plane's shade.
        let z = Array2::from_shape_fn((5, 7), |(i, j)| 3.0 * j as f64 - 2.0 * i as f64);
        let s = hillshade(z.view(), &[1.0; 5], 1.0, &params(315.0)).unwrap();
        for i in 0..5 {
            for j in 0..7 {
                let corner = (i == 0 || i == 4) && (j == 0 || j == 6);
                assert_eq!(corner, (s[[i, j]] - s[[2, 3]]).abs() > 1e-6, "{i} {j}");
            }
        }
        // first row, first column: the left column repeats the centre column
        let zz: Vec<f64> = z.iter().copied().collect();
        let w = gdal_window(&zz, 5, 7, 0, 0).unwrap();
        assert_eq!(w, [2.0, 2.0, 5.0, 0.0, 0.0, 3.0, -2.0, -2.0, 1.0]);
        // a missing neighbour, and an extrapolation from one, take the centre
        let mut m = zz.clone();
        m[7] = f64::NAN; // (1, 0)
        let w = gdal_window(&m, 5, 7, 0, 0).unwrap();
        assert_eq!(w, [0.0, 0.0, 5.0, 0.0, 0.0, 3.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn gdal_bytes_of_a_plane() {
        let z = Array2::from_shape_fn((6, 6), |(i, j)| (j as f32) * 0.5 + i as f32);
        let b = hillshade_gdal_byte(z.view(), 1.0, 1.0, &params(315.0)).unwrap();
        let s = hillshade(z.mapv(|v| v as f64).view(), &[1.0; 6], 1.0, &params(315.0)).unwrap();
        let want = (1.0 + 254.0 * s[[2, 2]] as f64).round() as u8;
        let corner = |i: usize, j: usize| (i == 0 || i == 5) && (j == 0 || j == 5);
        for ((i, j), &v) in b.indexed_iter() {
            assert_eq!(corner(i, j), v != want, "{b:?} {want}");
        }
        let mut zn = z.clone();
        zn[[3, 3]] = f32::NAN;
        let b = hillshade_gdal_byte(zn.view(), 1.0, 1.0, &params(315.0)).unwrap();
        assert_eq!(b[[3, 3]], 0);
        assert_eq!(b[[0, 2]], want);
        assert_eq!(b[[5, 2]], want);
    }

    #[test]
    fn bad_cell_size() {
        let z = Array2::<f64>::zeros((3, 3));
        assert!(hillshade(z.view(), &[1.0, 0.0, 1.0], 1.0, &params(315.0)).is_err());
        assert!(hillshade(z.view(), &[1.0; 3], f64::NAN, &params(315.0)).is_err());
    }
}
