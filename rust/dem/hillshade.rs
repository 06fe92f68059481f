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

/// The checks both hillshades share: a non-empty grid, positive finite
/// cell sizes (`dx` one per row or a single one), an altitude in degrees in
/// [0, 90], and a finite azimuth and z factor.
fn check_inputs(rows: usize, cols: usize, dx: &[f64], dy: f64, p: &ShadeParams) -> CoreResult<()> {
    if rows == 0 || cols == 0 {
        return Err(CoreError::invalid("dem", "empty grid"));
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
    Ok(())
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
    check_inputs(rows, cols, dx, dy, p)?;
    if dx.len() != rows {
        return Err(CoreError::invalid(
            "cell_size",
            format!("need {rows} row spacings, got {}", dx.len()),
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

/// Rows of bands processed in parallel by [`gdal_rows`]: enough work per
/// task to amortise the scheduling, small enough to balance two cores.
const BAND_ROWS: usize = 16;

/// Bytes of four neighbouring interior cells at once: `quad(up, cur, down,
/// j)` for the centres `j..j + 4` of the row `cur` (reading columns `j - 1
/// ..= j + 4` of the three rows), or `None` when one of them needs the
/// scalar path (a NaN value or centre).
type Quad = fn(&SameRes, &[f32], &[f32], &[f32], usize) -> Option<[u8; 4]>;

/// Bytes of `value` (GDAL's algorithm on a 3 x 3 window) for every cell of
/// the row-major grid `zs` into `out`, in parallel bands of rows.
///
/// The interior of each interior row runs over the three row slices with no
/// edge test, four cells at a time with `quad` when given (its results are
/// those of `value`, bit for bit); a window whose value is NaN (a NaN
/// neighbour propagates through Horn's sums) or whose centre is NaN is
/// rebuilt with the nodata rule of [`gdal_window`], as are the first and
/// last rows and columns.
#[allow(clippy::needless_range_loop)] // columns index three rows at once
fn gdal_rows<F>(
    zs: &[f32],
    rows: usize,
    cols: usize,
    out: &mut [u8],
    value: F,
    quad: Option<(Quad, SameRes)>,
) where
    F: Fn(&[f32; 9]) -> f32 + Sync,
{
    let edge = |i: usize, j: usize| -> u8 {
        match gdal_window(zs, rows, cols, i, j) {
            Some(w) => gdal_to_byte(value(&w)),
            None => 0,
        }
    };
    out.par_chunks_mut(cols * BAND_ROWS)
        .enumerate()
        .for_each(|(band, chunk)| {
            for (k, row) in chunk.chunks_mut(cols).enumerate() {
                let i = band * BAND_ROWS + k;
                if i == 0 || i + 1 == rows || cols < 3 {
                    for (j, o) in row.iter_mut().enumerate() {
                        *o = edge(i, j);
                    }
                    continue;
                }
                let up = &zs[(i - 1) * cols..i * cols];
                let cur = &zs[i * cols..(i + 1) * cols];
                let down = &zs[(i + 1) * cols..(i + 2) * cols];
                let scalar = |j: usize| -> u8 {
                    let w = [
                        up[j - 1],
                        up[j],
                        up[j + 1],
                        cur[j - 1],
                        cur[j],
                        cur[j + 1],
                        down[j - 1],
                        down[j],
                        down[j + 1],
                    ];
                    let v = value(&w);
                    if v.is_nan() || w[4].is_nan() {
                        edge(i, j)
                    } else {
                        gdal_to_byte(v)
                    }
                };
                row[0] = edge(i, 0);
                row[cols - 1] = edge(i, cols - 1);
                let mut j = 1;
                if let Some((q, k)) = &quad {
                    // the last quad reads column j + 4 <= cols - 1
                    while j + 5 <= cols {
                        match q(k, up, cur, down, j) {
                            Some(b) => row[j..j + 4].copy_from_slice(&b),
                            None => {
                                for jj in j..j + 4 {
                                    row[jj] = scalar(jj);
                                }
                            }
                        }
                        j += 4;
                    }
                }
                for jj in j..cols - 1 {
                    row[jj] = scalar(jj);
                }
            }
        });
}

/// Constants of GDAL's same-resolution hillshade (`GDALHillshadeAlg_same_res`).
#[derive(Debug, Clone, Copy)]
struct SameRes {
    sin_alt_254: f64,
    sin_fact: f64,
    cos_fact: f64,
    square_z_inv2: f64,
}

impl SameRes {
    /// One cell of `GDALHillshadeAlg_same_res` (Horn gradient, GDAL's
    /// operation order), as a grey level 1..255 before truncation.
    #[inline(always)]
    fn shade(&self, w: &[f32; 9]) -> f32 {
        let (sin_alt_254, sin_fact, cos_fact, square_z_inv2) = (
            self.sin_alt_254,
            self.sin_fact,
            self.cos_fact,
            self.square_z_inv2,
        );
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
    }
}

/// Four cells of `GDALHillshadeAlg_same_res` with SSE2 (part of the x86_64
/// baseline: no runtime detection needed), the same operations in the same
/// order as the scalar closure `same` of [`hillshade_gdal_byte`]: float32
/// Horn sums, double-precision shade, `rsqrtps` (per lane the estimate of
/// `rsqrtss`) and one Newton step, `max(1 + c, 1)` (equal to GDAL's
/// `c <= 0 ? 1 : 1 + c` for every non-NaN `c`), then GDAL's float-to-byte
/// rounding. `None` when a value or a centre is NaN.
#[cfg(target_arch = "x86_64")]
fn same_res_quad(k: &SameRes, up: &[f32], cur: &[f32], down: &[f32], j: usize) -> Option<[u8; 4]> {
    use std::arch::x86_64::*;
    assert!(j >= 1 && j + 5 <= up.len() && up.len() == cur.len() && cur.len() == down.len());
    // SAFETY: SSE2 is in the x86_64 baseline. Every load reads the four
    // floats at offsets o..o + 4 with o in {j - 1, j, j + 1}, so at most up
    // to index j + 4 < len (asserted above) of slices of equal length; the
    // store writes a local array of four i32.
    unsafe {
        let ld = |s: &[f32], o: usize| _mm_loadu_ps(s.as_ptr().add(o));
        let (a, b, c) = (ld(up, j - 1), ld(up, j), ld(up, j + 1));
        let (d, e, f) = (ld(cur, j - 1), ld(cur, j), ld(cur, j + 1));
        let (g, h, i) = (ld(down, j - 1), ld(down, j), ld(down, j + 1));
        let mut ax = _mm_sub_ps(a, i);
        let six_minus_two = _mm_sub_ps(g, c);
        let mut ay = ax;
        let three_minus_five = _mm_sub_ps(d, f);
        let one_minus_seven = _mm_sub_ps(b, h);
        ax = _mm_add_ps(ax, three_minus_five);
        ay = _mm_add_ps(ay, one_minus_seven);
        ax = _mm_add_ps(ax, three_minus_five);
        ay = _mm_add_ps(ay, one_minus_seven);
        ax = _mm_add_ps(ax, six_minus_two);
        ay = _mm_sub_ps(ay, six_minus_two);
        let one = _mm_set1_pd(1.0);
        let half = _mm_set1_pd(0.5);
        let one_and_half = _mm_set1_pd(1.5);
        let sin_alt = _mm_set1_pd(k.sin_alt_254);
        let sin_fact = _mm_set1_pd(k.sin_fact);
        let cos_fact = _mm_set1_pd(k.cos_fact);
        let sq = _mm_set1_pd(k.square_z_inv2);
        let shade = |x: __m128d, y: __m128d| -> __m128d {
            let num = _mm_add_pd(
                sin_alt,
                _mm_add_pd(_mm_mul_pd(x, sin_fact), _mm_mul_pd(y, cos_fact)),
            );
            let den = _mm_add_pd(
                one,
                _mm_mul_pd(sq, _mm_add_pd(_mm_mul_pd(x, x), _mm_mul_pd(y, y))),
            );
            let r = _mm_cvtps_pd(_mm_rsqrt_ps(_mm_cvtpd_ps(den)));
            let r = _mm_mul_pd(
                r,
                _mm_sub_pd(
                    one_and_half,
                    _mm_mul_pd(_mm_mul_pd(den, half), _mm_mul_pd(r, r)),
                ),
            );
            _mm_mul_pd(num, r)
        };
        let c0 = shade(_mm_cvtps_pd(ax), _mm_cvtps_pd(ay));
        let c1 = shade(
            _mm_cvtps_pd(_mm_movehl_ps(ax, ax)),
            _mm_cvtps_pd(_mm_movehl_ps(ay, ay)),
        );
        let nan = _mm_movemask_pd(_mm_cmpunord_pd(c0, c0))
            | _mm_movemask_pd(_mm_cmpunord_pd(c1, c1))
            | _mm_movemask_ps(_mm_cmpunord_ps(e, e));
        if nan != 0 {
            return None;
        }
        let v0 = _mm_cvtpd_ps(_mm_max_pd(_mm_add_pd(one, c0), one));
        let v1 = _mm_cvtpd_ps(_mm_max_pd(_mm_add_pd(one, c1), one));
        let v = _mm_movelh_ps(v0, v1);
        let v = _mm_min_ps(
            _mm_max_ps(_mm_add_ps(v, _mm_set1_ps(0.5)), _mm_setzero_ps()),
            _mm_set1_ps(255.0),
        );
        let mut o = [0i32; 4];
        _mm_storeu_si128(o.as_mut_ptr() as *mut __m128i, _mm_cvttps_epi32(v));
        Some([o[0] as u8, o[1] as u8, o[2] as u8, o[3] as u8])
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn same_res_quad(_: &SameRes, _: &[f32], _: &[f32], _: &[f32], _: usize) -> Option<[u8; 4]> {
    None
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
    check_inputs(rows, cols, &[dx], dy, p)?;
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
    // One closure per GDAL algorithm, each monomorphised into its own
    // driver loop (no per-pixel test of the mode).
    let multi = |w: &[f32; 9]| -> f32 {
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
    };
    let k = SameRes {
        sin_alt_254,
        sin_fact,
        cos_fact,
        square_z_inv2,
    };
    let same = |w: &[f32; 9]| -> f32 { k.shade(w) };
    let general = |w: &[f32; 9]| -> f32 {
        let (x, y) = horn(w);
        let c = approx_a_div_sqrt_b(
            sin_alt_254 - (y * cos_az_z_254 - x * sin_az_z_254),
            1.0 + square_z * (x * x + y * y),
        );
        (if c <= 0.0 { 1.0 } else { 1.0 + c }) as f32
    };
    let zs = z.as_standard_layout();
    let zs = zs
        .as_slice()
        .ok_or_else(|| CoreError::Internal("dem not contiguous".into()))?;
    let mut out =
        crate::buffers::try_filled(crate::buffers::checked_len(rows, cols, "dem")?, 0u8, "dem")?;
    if p.multidirectional {
        gdal_rows(zs, rows, cols, &mut out, multi, None);
    } else if same_res {
        gdal_rows(
            zs,
            rows,
            cols,
            &mut out,
            same,
            Some((same_res_quad as Quad, k)),
        );
    } else {
        gdal_rows(zs, rows, cols, &mut out, general, None);
    }
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
    fn quads_equal_the_scalar_path() {
        // random heights with NaN voids and a wide range of slopes: the SSE2
        // quads and the scalar closure give the same bytes everywhere
        let (rows, cols) = (37, 53);
        let noise = crate::testdata::uniform(rows * cols, 12345);
        let mut z = Array2::from_shape_fn((rows, cols), |(i, j)| (i * j) as f32 * 0.7);
        for (v, u) in z.iter_mut().zip(&noise) {
            *v += 300.0 * *u as f32;
        }
        for &(i, j) in &[(5, 5), (10, 20), (10, 21), (36, 3), (0, 9), (20, 52)] {
            z[[i, j]] = f32::NAN;
        }
        let mut seen = std::collections::BTreeSet::new();
        for p in [params(315.0), params(135.0), params(20.0)] {
            for zf in [0.3, 1.0, 7.0] {
                let p = ShadeParams { z_factor: zf, ..p };
                let fast = hillshade_gdal_byte(z.view(), 3.0, 3.0, &p).unwrap();
                // the same cells through the scalar path only (rectangular
                // code path disabled: equal cells, no quads)
                let zs: Vec<f32> = z.iter().copied().collect();
                let mut slow = vec![0u8; rows * cols];
                let d2r = std::f64::consts::PI / 180.0;
                let zf8 = zf / 8.0;
                let inv = 1.0 / 3.0;
                let cos_alt_z = (p.altitude * d2r).cos() * zf8;
                let az = p.azimuth * d2r;
                let k = SameRes {
                    sin_alt_254: 254.0 * (p.altitude * d2r).sin(),
                    sin_fact: 254.0 * az.sin() * cos_alt_z * inv,
                    cos_fact: 254.0 * az.cos() * cos_alt_z * -inv,
                    square_z_inv2: zf8 * zf8 * inv * inv,
                };
                let same = |w: &[f32; 9]| -> f32 { k.shade(w) };
                gdal_rows(&zs, rows, cols, &mut slow, same, None);
                assert_eq!(
                    fast.as_slice().unwrap(),
                    &slow[..],
                    "az {} z {zf}",
                    p.azimuth
                );
                seen.extend(fast.iter().copied());
            }
        }
        // shadowed cells (1), bright ones and voids (0) were all exercised
        assert!(seen.contains(&0) && seen.contains(&1) && seen.iter().any(|&b| b > 200));
    }

    #[test]
    fn bad_cell_size() {
        let z = Array2::<f64>::zeros((3, 3));
        assert!(hillshade(z.view(), &[1.0, 0.0, 1.0], 1.0, &params(315.0)).is_err());
        assert!(hillshade(z.view(), &[1.0; 3], f64::NAN, &params(315.0)).is_err());
    }

    #[test]
    fn both_hillshades_name_the_bad_parameter() {
        let param = |r: CoreResult<()>| match r {
            Err(CoreError::InvalidArgument { param, .. }) => param,
            other => panic!("expected InvalidArgument, got {other:?}"),
        };
        let z = Array2::<f64>::zeros((3, 3));
        let z32 = Array2::<f32>::zeros((3, 3));
        let bad = [
            (
                "altitude",
                ShadeParams {
                    altitude: 91.0,
                    ..params(315.0)
                },
            ),
            ("azimuth", params(f64::NAN)),
            (
                "z_factor",
                ShadeParams {
                    z_factor: f64::INFINITY,
                    ..params(315.0)
                },
            ),
        ];
        for (name, p) in bad {
            assert_eq!(
                param(hillshade(z.view(), &[1.0; 3], 1.0, &p).map(|_| ())),
                name
            );
            assert_eq!(
                param(hillshade_gdal_byte(z32.view(), 1.0, 1.0, &p).map(|_| ())),
                name
            );
        }
        let empty = Array2::<f32>::zeros((0, 3));
        assert_eq!(
            param(hillshade_gdal_byte(empty.view(), 1.0, 1.0, &params(315.0)).map(|_| ())),
            "dem"
        );
        assert_eq!(
            param(hillshade_gdal_byte(z32.view(), 0.0, 1.0, &params(315.0)).map(|_| ())),
            "cell_size"
        );
    }
}
