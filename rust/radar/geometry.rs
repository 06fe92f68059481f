//! Side-looking radar geometry of a heightfield, in the range frame: rows
//! are azimuth lines, columns step away from the radar in ground range
//! (`dx` metres), rows are `dy` metres apart. The radar is far (plane wave):
//! every pixel sees it at the same incidence `theta` from the vertical.
//!
//! * **Local incidence**: the facet normal from central differences
//!   (one-sided on the edges), `cos theta_loc = (cos theta + sin theta
//!   z_x) / sqrt(1 + z_x^2 + z_y^2)`. A plane of slope `s` rising away from
//!   the radar has `theta_loc = theta - s`.
//! * **Slant range**: `r = x sin theta - z cos theta`; in units of the
//!   slant-range bin `dx sin theta` a pixel sits at `j - z cot theta / dx`
//!   (flat ground maps column `j` to bin `j`). Layover is where `r` decreases
//!   with `x`: slopes facing the radar steeper than `theta`.
//! * **Radar shadow**: a sample is hidden when a sample nearer the radar
//!   rises above the ray to it, `max_{x' < x} (z' + x' cot theta) > z + x cot
//!   theta`, a running maximum along the range line (exact for the
//!   piecewise-linear profile through the samples, whose maximum is at a
//!   sample), or when its facet faces away (`cos theta_loc <= 0`, slopes
//!   facing away steeper than `90 - theta`).
//! * **Projection**: each half of a pixel (from its centre to the midpoint to
//!   a neighbour) lands on the slant-range axis between the slant ranges of
//!   those two points, with half the pixel's power spread over the bins it
//!   overlaps in proportion to the overlap (power is conserved; at a fold,
//!   a crest in layover, both halves land on the same side).
//!   A bin is in layover when the footprints of more than one pixel of the
//!   line cover its centre.
use crate::buffers;
use crate::error::{CoreError, CoreResult};
use crate::progress::{self, Progress};
use crate::radar::speckle;
use rayon::prelude::*;

/// Bit of [`Geometry::flags`]: the pixel is in radar shadow (cast, or its
/// facet faces away beyond grazing).
pub const SHADOW: u8 = 1;
/// Bit of [`Geometry::flags`]: the facet faces the radar more steeply than
/// the incidence (active layover: slant range decreases with ground range).
pub const ACTIVE_LAYOVER: u8 = 2;

/// Per-pixel geometry of a scene (row-major, same shape as the DEM).
#[derive(Debug, Clone)]
pub struct Geometry {
    /// Local incidence angle in degrees (NaN where a height is missing;
    /// above 90 for facets facing away beyond grazing).
    pub theta_local: Vec<f64>,
    /// Backscattered power in units of a flat cell's: sigma0 at the local
    /// incidence (linear interpolation in the table) times the facet's area
    /// over the cell's, 0 in shadow, NaN where a height is missing.
    pub power: Vec<f64>,
    /// Slant-range position in bins of `dx sin theta`, from 0.
    pub position: Vec<f64>,
    /// [`SHADOW`] and [`ACTIVE_LAYOVER`] bits.
    pub flags: Vec<u8>,
    /// Number of slant-range bins that hold the scene.
    pub n_bins: usize,
}

fn check(z: &[f64], rows: usize, cols: usize, dx: f64, dy: f64, incidence: f64) -> CoreResult<()> {
    if rows * cols != z.len() || rows < 1 || cols < 2 || cols > i32::MAX as usize {
        return Err(CoreError::invalid(
            "dem",
            "expected a 2D grid with at least 2 columns along range",
        ));
    }
    for (name, v) in [("cell_size", dx), ("cell_size", dy)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(CoreError::invalid(name, format!("expected > 0, got {v}")));
        }
    }
    if !(incidence.is_finite() && incidence > 0.0 && incidence < 90.0) {
        return Err(CoreError::invalid(
            "incidence",
            format!("expected degrees in (0, 90), got {incidence}"),
        ));
    }
    Ok(())
}

/// `cot(incidence)` as the kernels compute it (for [`slant_extent`]).
pub fn cot_of(incidence: f64) -> f64 {
    let (st, ct) = incidence.to_radians().sin_cos();
    ct / st
}

/// Constants of the geometry at one incidence.
struct Params<'a> {
    st: f64,
    ct: f64,
    cot: f64,
    tan_t: f64,
    dx: f64,
    dy: f64,
    table: &'a [f64],
    step: f64,
}

impl<'a> Params<'a> {
    fn new(dx: f64, dy: f64, incidence: f64, table: &'a [f64], step: f64) -> Self {
        let (st, ct) = incidence.to_radians().sin_cos();
        Params {
            st,
            ct,
            cot: cot_of(incidence),
            tan_t: st / ct,
            dx,
            dy,
            table,
            step,
        }
    }
}

/// Coefficients of `asin(s) = s + s z P(z)`, `z = s^2`, on `s` in [0, 1/2]
/// (a least-squares fit on Chebyshev nodes of the Maclaurin series; the
/// error of [`fast_acos`] is below 2e-15 rad, see its test).
const ASIN_P: [f64; 11] = [
    0.1666666666666696,
    0.07499999999711905,
    0.044642857597766865,
    0.030381916507840744,
    0.02237303550867808,
    0.017336812498264156,
    0.014144396614212894,
    0.010270206855440509,
    0.015511194143790765,
    -0.00694636657411397,
    0.027970731079700266,
];

/// `acos(x)` for `x` in [-1, 1] (NaN stays NaN) without a libm call or a
/// branch (both sides of each choice are computed, then selected):
/// `pi/2 -+ asin(|x|)` for `|x| <= 1/2`, else `2 asin(sqrt((1 - |x|) / 2))`
/// (Sterbenz: `1 - |x|` is exact there), `asin` from [`ASIN_P`].
#[inline(always)]
fn fast_acos(x: f64) -> f64 {
    let a = x.abs();
    let big = a > 0.5;
    let s = if big { ((1.0 - a) * 0.5).sqrt() } else { a };
    let z = s * s;
    // Estrin's scheme: a short dependency chain (no FMA on the baseline target)
    let c = &ASIN_P;
    let (z2, z4) = (z * z, z * z * (z * z));
    let r0 = (c[0] + c[1] * z) + (c[2] + c[3] * z) * z2;
    let r1 = (c[4] + c[5] * z) + (c[6] + c[7] * z) * z2;
    let r2 = (c[8] + c[9] * z) + c[10] * z2;
    let h = r0 + r1 * z4 + r2 * (z4 * z4);
    let asn = s + s * z * h;
    let r = if big {
        2.0 * asn
    } else {
        std::f64::consts::FRAC_PI_2 - asn
    };
    if x < 0.0 {
        std::f64::consts::PI - r
    } else {
        r
    }
}

/// Scratch lines of one thread for [`geometry_row`].
/// The grid of range lines a geometry row reads, with the scene's
/// parameters and slant-axis origin `lo`.
#[derive(Clone, Copy)]
struct Lines<'a> {
    z: &'a [f64],
    rows: usize,
    cols: usize,
    p: &'a Params<'a>,
    lo: f64,
}

/// The outputs of one geometry row: local incidence, power, slant
/// position and flags per sample.
struct RowOut<'a> {
    th: &'a mut [f64],
    pw: &'a mut [f64],
    ps: &'a mut [f64],
    fl: &'a mut [u8],
}

struct RowScratch {
    /// `cos theta_loc` (first the range derivative `z_x`).
    c: Vec<f64>,
    /// `z + x cot theta`, the height of the ray to the radar through the sample.
    u: Vec<f64>,
}

impl RowScratch {
    fn new(cols: usize) -> Self {
        RowScratch {
            c: vec![0.0; cols],
            u: vec![0.0; cols],
        }
    }
}

/// The geometry of row `r` (see [`geometry`]), positions `ps` shifted by
/// `-lo` (column `j` of flat ground at bin `j - lo`).
///
/// Two passes over the line: the per-sample arithmetic (derivatives, facet
/// normal, local incidence, slant position), without branches so that it
/// vectorises, then the running maximum of the radar shadow and the table
/// lookup of sigma0, sequentially. On x86-64 CPUs with AVX2 the same code is
/// compiled for AVX2 and chosen at run time (four samples per instruction;
/// the same operations in the same order, so the same bits).
#[inline]
fn geometry_row(g: &Lines<'_>, r: usize, out: RowOut<'_>, scr: &mut RowScratch) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above).
        unsafe { geometry_row_avx2(g, r, out, scr) };
        return;
    }
    geometry_row_impl(g, r, out, scr);
}

/// [`geometry_row_impl`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn geometry_row_avx2(g: &Lines<'_>, r: usize, out: RowOut<'_>, scr: &mut RowScratch) {
    geometry_row_impl(g, r, out, scr);
}

/// The body of [`geometry_row`].
#[inline(always)]
fn geometry_row_impl(g: &Lines<'_>, r: usize, out: RowOut<'_>, scr: &mut RowScratch) {
    let Lines {
        z,
        rows,
        cols,
        p,
        lo,
    } = *g;
    let RowOut { th, pw, ps, fl } = out;
    let (st, ct, cot, dx) = (p.st, p.ct, p.cot, p.dx);
    let line = &z[r * cols..(r + 1) * cols];
    let up = if r > 0 {
        Some(&z[(r - 1) * cols..r * cols])
    } else {
        None
    };
    let down = if r + 1 < rows {
        Some(&z[(r + 1) * cols..(r + 2) * cols])
    } else {
        None
    };
    // the derivative across range lines: central inside, one-sided at the
    // edges (0 for a single line)
    let (lo_line, hi_line, inv_hy) = match (up, down) {
        (Some(u), Some(d)) => (u, d, 0.5 / p.dy),
        (None, Some(d)) => (line, d, 1.0 / p.dy),
        (Some(u), None) => (u, line, 1.0 / p.dy),
        (None, None) => (line, line, 0.0),
    };
    let single = up.is_none() && down.is_none();
    let (inv_dx, inv_2dx) = (1.0 / dx, 0.5 / dx);
    let cot_dx = cot / dx;
    let dx_cot = dx * cot;
    let tan_t = p.tan_t;
    let to_deg = 180.0 / std::f64::consts::PI;
    let inv_step = 1.0 / p.step;
    let table = p.table;
    // the last interval of the table (`table.len() >= 1`, checked)
    let last1 = table.len().max(2) - 2;
    let (cb, ub) = (&mut scr.c[..cols], &mut scr.u[..cols]);
    let (th, pw, ps, fl) = (
        &mut th[..cols],
        &mut pw[..cols],
        &mut ps[..cols],
        &mut fl[..cols],
    );
    let (lo_line, hi_line) = (&lo_line[..cols], &hi_line[..cols]);
    // the derivative along range, central inside and one-sided at the ends
    cb[0] = (line[1] - line[0]) * inv_dx;
    cb[cols - 1] = (line[cols - 1] - line[cols - 2]) * inv_dx;
    for ((c, &a), &b) in cb[1..cols - 1]
        .iter_mut()
        .zip(&line[2..])
        .zip(&line[..cols - 2])
    {
        *c = (a - b) * inv_2dx;
    }
    // per sample, branch-free: facet normal, local incidence, slant position
    // (`j` as i32: cols < 2^31, checked)
    for j in 0..cols {
        let zx = cb[j];
        let zy = if single {
            0.0
        } else {
            (hi_line[j] - lo_line[j]) * inv_hy
        };
        let norm = (1.0 + zx * zx + zy * zy).sqrt();
        let c = ((ct + st * zx) / norm).clamp(-1.0, 1.0);
        th[j] = fast_acos(c) * to_deg;
        cb[j] = c;
        pw[j] = norm;
        let zj = line[j];
        let jf = j as i32 as f64;
        ps[j] = (jf - zj * cot_dx) - lo;
        ub[j] = zj + jf * dx_cot;
        fl[j] = if zx > tan_t { ACTIVE_LAYOVER } else { 0 };
    }
    // sequential: the running maximum of the shadow test
    let mut umax = f64::NEG_INFINITY;
    for j in 0..cols {
        let (u, c) = (ub[j], cb[j]);
        // relative tolerance: a plane exactly at grazing slope is lit
        let tol = 1e-12 * (u.abs() + umax.abs().min(f64::MAX));
        let cast = u.is_finite() && umax > u + tol;
        let shadow = cast || c <= 0.0;
        fl[j] |= if shadow { SHADOW } else { 0 };
        pw[j] = if !u.is_finite() || c.is_nan() {
            f64::NAN
        } else if shadow {
            0.0
        } else {
            // sigma0 at the local incidence by linear interpolation in the
            // table, clamped at its ends (`x >= 0`: the cast is a floor, and
            // a weight clamped to 1 takes the last entry exactly), times the
            // facet's area over the cell's
            let x = (th[j] * inv_step).max(0.0);
            let s0 = if table.len() == 1 {
                table[0]
            } else {
                let i = (x as i64 as usize).min(last1);
                let f = (x - i as i64 as f64).min(1.0);
                table[i] * (1.0 - f) + table[i + 1] * f
            };
            pw[j] * s0
        };
        if u > umax {
            umax = u;
        }
    }
}

/// The geometry of the DEM `z` (`rows` x `cols`, NaN = missing) seen at
/// `incidence` degrees from the vertical, with the facet backscatter
/// `table[i]` = sigma0 at `i * table_step` degrees.
#[allow(clippy::too_many_arguments)]
pub fn geometry(
    z: &[f64],
    rows: usize,
    cols: usize,
    dx: f64,
    dy: f64,
    incidence: f64,
    table: &[f64],
    table_step: f64,
) -> CoreResult<Geometry> {
    geometry_on_axis(z, rows, cols, dx, dy, incidence, table, table_step, None)
}

/// [`geometry`] with the slant-range axis fixed to `slant = Some((lo,
/// n_bins))` (as [`scene_block`]: positions are bins from `lo`; `None`: the
/// grid's own axis). Lines computed on the whole scene's axis, with one line
/// more on each side where the scene has them, equal the same lines of the
/// whole scene.
#[allow(clippy::too_many_arguments)]
pub fn geometry_on_axis(
    z: &[f64],
    rows: usize,
    cols: usize,
    dx: f64,
    dy: f64,
    incidence: f64,
    table: &[f64],
    table_step: f64,
    slant: Option<(f64, usize)>,
) -> CoreResult<Geometry> {
    check(z, rows, cols, dx, dy, incidence)?;
    if table.is_empty() || !(table_step.is_finite() && table_step > 0.0) {
        return Err(CoreError::invalid(
            "table",
            "expected a non-empty sigma0 table and a positive step",
        ));
    }
    let prm = Params::new(dx, dy, incidence, table, table_step);
    let (lo, n_bins) = given_or_own_axis(slant, z, cols, &prm)?;
    let lines = Lines {
        z,
        rows,
        cols,
        p: &prm,
        lo,
    };
    let n = rows * cols;
    let mut theta = vec![0.0; n];
    let mut power = vec![0.0; n];
    let mut pos = vec![0.0; n];
    let mut flags = vec![0u8; n];
    theta
        .par_chunks_mut(cols)
        .zip(power.par_chunks_mut(cols))
        .zip(pos.par_chunks_mut(cols))
        .zip(flags.par_chunks_mut(cols))
        .enumerate()
        .for_each_init(
            || RowScratch::new(cols),
            |scr, (r, (((th, pw), ps), fl))| {
                geometry_row(&lines, r, RowOut { th, pw, ps, fl }, scr);
            },
        );
    Ok(Geometry {
        theta_local: theta,
        power,
        position: pos,
        flags,
        n_bins,
    })
}

/// A slant-range image and its coverage.
#[derive(Debug, Clone)]
pub struct Slant {
    /// Power per bin (`rows * n_bins`), in units of the power of one flat pixel.
    pub image: Vec<f64>,
    /// Number of pixel footprints covering each bin centre.
    pub count: Vec<u32>,
    /// Number of lit (non-shadowed, finite power > 0 or not) footprints covering it.
    pub lit: Vec<u32>,
}

/// The slant bin nearest to the position `p` (clamped to the axis). The
/// cast goes through `i64` (one instruction on x86-64, where `f64 as usize`
/// is several): the same index, since a value beyond `i64` saturates and is
/// clamped either way.
#[inline(always)]
fn slant_bin(p: f64, n_bins: usize) -> usize {
    ((p + 0.5).max(0.0) as i64 as usize).min(n_bins - 1)
}

/// Layover of a pixel whose bin has `count` footprints and whose flags are
/// `flag`: more than one footprint, or active layover.
#[inline(always)]
fn in_layover(count: u32, flag: u8) -> bool {
    count > 1 || flag & ACTIVE_LAYOVER != 0
}

/// Edges `(left, right)` of the footprint of pixel `j` of a line of slant
/// positions: the midpoints to its neighbours (extrapolated at the ends).
#[inline(always)]
fn footprint(p: &[f64], j: usize) -> (f64, f64) {
    let n = p.len();
    let pj = p[j];
    let half = |k: usize| -> Option<f64> {
        let q = p[k];
        q.is_finite().then_some((pj + q) / 2.0)
    };
    let left = if j > 0 { half(j - 1) } else { None };
    let right = if j + 1 < n { half(j + 1) } else { None };
    let (l, r) = match (left, right) {
        (Some(l), Some(r)) => (l, r),
        (Some(l), None) => (l, 2.0 * pj - l),
        (None, Some(r)) => (2.0 * pj - r, r),
        (None, None) => (pj - 0.5, pj + 0.5),
    };
    (l, r)
}

/// `max(ceil(a), 0)` as an index: casts truncate, so no libm `floor`/`ceil`
/// calls in the inner loops (the baseline x86-64 target has no `roundsd`).
#[inline]
fn ceil_nonneg(a: f64) -> usize {
    if a <= 0.0 {
        return 0;
    }
    let t = a as usize;
    if (t as f64) < a {
        t + 1
    } else {
        t
    }
}

/// Add `v` spread uniformly over the half-open slant interval between `e0`
/// and `e1` (either order) to `img`, and count the bins whose centre it
/// covers in `cnt` (and in `lt` when `lit`; `lt` is not touched unless
/// `LIT`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn deposit<const LIT: bool>(
    img: &mut [f64],
    cnt: &mut [u32],
    lt: &mut [u32],
    e0: f64,
    e1: f64,
    v: f64,
    lit: bool,
) {
    let n_bins = img.len();
    let (a, b) = if e0 <= e1 { (e0, e1) } else { (e1, e0) };
    let (a, b) = (a.max(-0.5), b.min(n_bins as f64 - 0.5));
    if b < a {
        return;
    }
    // the bin holding `a` (`a >= -0.5`: the cast is a floor)
    let ka = slant_bin(a, n_bins);
    let kb = slant_bin(b, n_bins);
    let len = b - a;
    if kb <= ka + 1 && len >= 1e-12 {
        // the common case, at most two bins: centres ka and kb counted when
        // inside [a, b), the power split at the edge between the bins.
        // Without branches (their outcome is a coin toss on rough terrain):
        // the second bin `k1` is written even when the interval ends in the
        // first (adding 0), `ka + 1 < b` is `kb > ka && kb < b`, and the
        // share of bin `ka` is clamped to 1 (the whole `v`) instead of
        // testing `kb == ka`; the other bin gets the rest (`v` is conserved).
        // `ka < 2^31`: through `i64`, one instruction.
        let kaf = ka as i64 as f64;
        let k1 = (ka + 1).min(n_bins - 1);
        let in_a = a <= kaf && kaf < b;
        let in_b = kaf + 1.0 < b;
        cnt[ka] += u32::from(in_a);
        cnt[k1] += u32::from(in_b);
        if LIT {
            lt[ka] += u32::from(in_a && lit);
            lt[k1] += u32::from(in_b && lit);
        }
        if !(v.is_finite() && v != 0.0) {
            return;
        }
        let va = v * (((kaf + 0.5) - a) / len).min(1.0);
        img[ka] += va;
        img[k1] += v - va;
        return;
    }
    // bins whose centre k lies in [a, b)
    let mut k = ceil_nonneg(a);
    while (k as f64) < b && k < n_bins {
        cnt[k] += 1;
        if LIT {
            lt[k] += u32::from(lit);
        }
        k += 1;
    }
    if !(v.is_finite() && v != 0.0) {
        return;
    }
    if len < 1e-12 {
        img[ka] += v;
        return;
    }
    let mut k = ka;
    while k < n_bins && (k as f64 - 0.5) < b {
        let lo = (k as f64 - 0.5).max(a);
        let hi = (k as f64 + 0.5).min(b);
        if hi > lo {
            img[k] += v * (hi - lo) / len;
        }
        k += 1;
    }
}

/// Bits of [`Halves::code`]: the half-footprint covers the centre of its
/// first bin, of the next one, the pixel is lit, the common case (at most
/// two bins, see [`deposit`]), or the general one. 0: no footprint (the
/// position is missing).
const H_IN_A: u8 = 1;
const H_IN_B: u8 = 2;
const H_LIT: u8 = 4;
const H_FAST: u8 = 8;
const H_GENERAL: u8 = 16;

/// The half-footprints of a line, prepared for [`project_row`]: index 0 the
/// halves from each pixel's left edge to its centre, 1 from its centre to
/// its right edge. In the common case, the first bin `ka` and the power
/// `va`, `vb` that go to it and to the next bin (as [`deposit`] splits it).
struct Halves {
    /// The bin of each pixel's centre ([`slant_bin`]; any value where the
    /// position is missing).
    kc: Vec<u32>,
    ka: [Vec<u32>; 2],
    va: [Vec<f64>; 2],
    vb: [Vec<f64>; 2],
    code: [Vec<u8>; 2],
}

impl Halves {
    fn new(cols: usize) -> Self {
        let f = || [vec![0.0; cols], vec![0.0; cols]];
        Halves {
            kc: vec![0; cols],
            ka: [vec![0; cols], vec![0; cols]],
            va: f(),
            vb: f(),
            code: [vec![0; cols], vec![0; cols]],
        }
    }
}

/// [`deposit`]'s common case of the half-footprint between `e0` and `e1`
/// with power `v` on `n_bins` bins, without branches:
/// `(ka, va, vb, code)` (see [`Halves`]); `ok` false: no footprint.
#[inline(always)]
fn prepare_half(
    e0: f64,
    e1: f64,
    v: f64,
    lit: bool,
    ok: bool,
    n_bins: usize,
) -> (u32, f64, f64, u8) {
    let nb = n_bins as f64;
    let (a, b) = if e0 <= e1 { (e0, e1) } else { (e1, e0) };
    let (a, b) = (a.max(-0.5), b.min(nb - 0.5));
    // `slant_bin`, the clamp before the cast (the same index): a value in
    // [0, n_bins - 1] with `n_bins <= 2^31` (checked), so that the cast
    // needs no saturation and vectorises
    let top = (n_bins - 1) as f64;
    // SAFETY: `max` maps NaN to 0 and the value lies in [0, 2^31 - 1]
    let ka = unsafe { (a + 0.5).max(0.0).min(top).to_int_unchecked::<i32>() };
    // SAFETY: as for `ka`
    let kb = unsafe { (b + 0.5).max(0.0).min(top).to_int_unchecked::<i32>() };
    let len = b - a;
    let kaf = ka as f64;
    let in_a = a <= kaf && kaf < b;
    let in_b = kaf + 1.0 < b;
    let fast = b >= a && kb <= ka + 1 && len >= 1e-12;
    // no power where it is not finite (0 adds nothing)
    let v = if v.is_finite() { v } else { 0.0 };
    let va = v * (((kaf + 0.5) - a) / len).min(1.0);
    let vb = v - va;
    let lit = if lit { H_LIT } else { 0 };
    let code = if !ok {
        0
    } else if fast {
        H_FAST | lit | u8::from(in_a) | u8::from(in_b) << 1
    } else {
        H_GENERAL | lit
    };
    (ka as u32, va, vb, code)
}

/// The footprint of a pixel at `pj` between neighbours at `pl` and `pr`
/// (NaN: missing), as [`footprint`], its two halves prepared, and the bin
/// of its centre.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn prepare_pixel(
    pl: f64,
    pj: f64,
    pr: f64,
    w: f64,
    flag: u8,
    n_bins: usize,
) -> ([(u32, f64, f64, u8); 2], u32) {
    let (lf, rf) = (pl.is_finite(), pr.is_finite());
    let (hl, hr) = ((pj + pl) / 2.0, (pj + pr) / 2.0);
    let l = if lf {
        hl
    } else if rf {
        2.0 * pj - hr
    } else {
        pj - 0.5
    };
    let r = if rf {
        hr
    } else if lf {
        2.0 * pj - hl
    } else {
        pj + 0.5
    };
    let (v, lit, ok) = (0.5 * w, flag & SHADOW == 0, pj.is_finite());
    // `slant_bin` with the clamp before the cast (see `prepare_half`)
    // SAFETY: `max` maps NaN to 0 and the value lies in [0, 2^31 - 1]
    let kc = unsafe {
        (pj + 0.5)
            .max(0.0)
            .min((n_bins - 1) as f64)
            .to_int_unchecked::<i32>()
    };
    (
        [
            prepare_half(l, pj, v, lit, ok, n_bins),
            prepare_half(pj, r, v, lit, ok, n_bins),
        ],
        kc as u32,
    )
}

/// Fill `h` for the line `p`, `w`, `l` ([`prepare_pixel`] for each pixel).
#[inline(always)]
fn prepare_line_impl(p: &[f64], w: &[f64], l: &[u8], n_bins: usize, h: &mut Halves) {
    let n = p.len();
    let [ka0, ka1] = &mut h.ka;
    let [va0, va1] = &mut h.va;
    let [vb0, vb1] = &mut h.vb;
    let [c0, c1] = &mut h.code;
    let kc = &mut h.kc;
    let mut put = |j: usize, (x, k): ([(u32, f64, f64, u8); 2], u32)| {
        (ka0[j], va0[j], vb0[j], c0[j]) = x[0];
        (ka1[j], va1[j], vb1[j], c1[j]) = x[1];
        kc[j] = k;
    };
    if n == 1 {
        put(
            0,
            prepare_pixel(f64::NAN, p[0], f64::NAN, w[0], l[0], n_bins),
        );
        return;
    }
    put(0, prepare_pixel(f64::NAN, p[0], p[1], w[0], l[0], n_bins));
    put(
        n - 1,
        prepare_pixel(p[n - 2], p[n - 1], f64::NAN, w[n - 1], l[n - 1], n_bins),
    );
    // the inside of the line: no branch, vectorised
    let (ka0, ka1) = (&mut ka0[1..n - 1], &mut ka1[1..n - 1]);
    let (va0, va1) = (&mut va0[1..n - 1], &mut va1[1..n - 1]);
    let (vb0, vb1) = (&mut vb0[1..n - 1], &mut vb1[1..n - 1]);
    let (c0, c1) = (&mut c0[1..n - 1], &mut c1[1..n - 1]);
    let kc = &mut h.kc[1..n - 1];
    let (pl, pj, pr) = (&p[..n - 2], &p[1..n - 1], &p[2..]);
    let (w, l) = (&w[1..n - 1], &l[1..n - 1]);
    for j in 0..n - 2 {
        let (x, k) = prepare_pixel(pl[j], pj[j], pr[j], w[j], l[j], n_bins);
        (ka0[j], va0[j], vb0[j], c0[j]) = x[0];
        (ka1[j], va1[j], vb1[j], c1[j]) = x[1];
        kc[j] = k;
    }
}

/// [`prepare_line_impl`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn prepare_line_avx2(p: &[f64], w: &[f64], l: &[u8], n_bins: usize, h: &mut Halves) {
    prepare_line_impl(p, w, l, n_bins, h);
}

/// Project one line (positions `p`, power `w`, flags `l`) onto the zeroed
/// slant line `img`, `cnt`, `lt` (`lt` only when `LIT`: the fused kernel
/// does not need it); bins no footprint reaches become NaN.
///
/// The half-footprints are first prepared for the whole line without
/// branches (vectorised, AVX2 where the CPU has it), then deposited in
/// order: two bins each in the common case, [`deposit`] otherwise. The same
/// values as depositing them one by one.
#[inline]
fn project_row<const LIT: bool>(
    p: &[f64],
    w: &[f64],
    l: &[u8],
    img: &mut [f64],
    cnt: &mut [u32],
    lt: &mut [u32],
    h: &mut Halves,
) {
    let n = p.len();
    let n_bins = img.len();
    #[cfg(target_arch = "x86_64")]
    let done = if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2 (checked just above).
        unsafe { prepare_line_avx2(p, w, l, n_bins, h) };
        true
    } else {
        false
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = false;
    if !done {
        prepare_line_impl(p, w, l, n_bins, h);
    }
    let top = n_bins - 1;
    for j in 0..n {
        // the two halves of the cell, from its centre to the midpoints to
        // its neighbours, each with half the power: at a fold (a crest seen
        // in layover) both land on one side
        for side in 0..2 {
            let c = h.code[side][j];
            if c & H_FAST != 0 {
                let ka = h.ka[side][j] as usize;
                let k1 = (ka + 1).min(top);
                cnt[ka] += u32::from(c & H_IN_A);
                cnt[k1] += u32::from((c & H_IN_B) >> 1);
                if LIT {
                    let lit = c & H_LIT != 0;
                    lt[ka] += u32::from(c & H_IN_A != 0 && lit);
                    lt[k1] += u32::from(c & H_IN_B != 0 && lit);
                }
                img[ka] += h.va[side][j];
                img[k1] += h.vb[side][j];
            } else if c & H_GENERAL != 0 {
                let (e0, e1) = footprint(p, j);
                let (e0, e1) = if side == 0 { (e0, p[j]) } else { (p[j], e1) };
                let lit = c & H_LIT != 0;
                deposit::<LIT>(img, cnt, lt, e0, e1, 0.5 * w[j], lit);
            }
        }
    }
    // at a sharp fold both halves of a footprint may miss the centre of the
    // pixel's own bin: a bin that no footprint covers is still seen by the
    // pixels that fall in it (its geocoded value is defined)
    for j in 0..n {
        if p[j].is_finite() {
            let k = h.kc[j] as usize;
            if cnt[k] == 0 {
                cnt[k] = 1;
                if LIT {
                    lt[k] = u32::from(l[j] & SHADOW == 0);
                }
            }
        }
    }
    for (v, &c) in img.iter_mut().zip(cnt.iter()) {
        *v = if c == 0 && *v == 0.0 { f64::NAN } else { *v };
    }
}

/// Project per-pixel `power` at slant `position` (from [`geometry`]) onto
/// `n_bins` slant-range bins per row. A pixel without the [`SHADOW`] bit of
/// `flags` counts as lit. Non-finite power or position contributes nothing.
/// Bins that no footprint reaches are NaN.
pub fn project(
    power: &[f64],
    position: &[f64],
    flags: &[u8],
    rows: usize,
    cols: usize,
    n_bins: usize,
) -> CoreResult<Slant> {
    let n = rows * cols;
    if power.len() != n || position.len() != n || flags.len() != n {
        return Err(CoreError::invalid(
            "power",
            "shapes of power, position and lit differ",
        ));
    }
    if n_bins == 0 || n_bins > 1 << 31 {
        return Err(CoreError::invalid(
            "n_bins",
            format!("expected 1..2^31, got {n_bins}"),
        ));
    }
    let mut image = vec![0.0; rows * n_bins];
    let mut count = vec![0u32; rows * n_bins];
    let mut lit = vec![0u32; rows * n_bins];
    image
        .par_chunks_mut(n_bins)
        .zip(count.par_chunks_mut(n_bins))
        .zip(lit.par_chunks_mut(n_bins))
        .enumerate()
        .for_each_init(
            || Halves::new(cols),
            |h, (r, ((img, cnt), lt))| {
                project_row::<true>(
                    &position[r * cols..(r + 1) * cols],
                    &power[r * cols..(r + 1) * cols],
                    &flags[r * cols..(r + 1) * cols],
                    img,
                    cnt,
                    lt,
                    h,
                );
            },
        );
    Ok(Slant { image, count, lit })
}

/// Terrain geocoding: each pixel takes the value of the slant bin nearest to
/// its `position` in each image of `slants` (`rows * n_bins` each); returns
/// those images on the DEM's grid (NaN where the position is) and the
/// layover mask (the bin is covered by more than one footprint, or the
/// pixel has the [`ACTIVE_LAYOVER`] bit).
pub fn geocode(
    slants: &[&[f64]],
    count: &[u32],
    position: &[f64],
    flags: &[u8],
    rows: usize,
    cols: usize,
    n_bins: usize,
) -> CoreResult<(Vec<Vec<f64>>, Vec<u8>)> {
    let n = rows * cols;
    if position.len() != n || flags.len() != n || count.len() != rows * n_bins {
        return Err(CoreError::invalid(
            "position",
            "shapes of the inputs differ",
        ));
    }
    if slants.iter().any(|s| s.len() != rows * n_bins) || n_bins == 0 {
        return Err(CoreError::invalid("slant", "expected rows x n_bins images"));
    }
    let bin = |p: f64| slant_bin(p, n_bins);
    let mut outs: Vec<Vec<f64>> = Vec::with_capacity(slants.len());
    for s in slants {
        let mut o = vec![0.0; n];
        o.par_chunks_mut(cols).enumerate().for_each(|(r, o)| {
            let p = &position[r * cols..(r + 1) * cols];
            let line = &s[r * n_bins..(r + 1) * n_bins];
            for (o, &p) in o.iter_mut().zip(p) {
                *o = if p.is_finite() {
                    line[bin(p)]
                } else {
                    f64::NAN
                };
            }
        });
        outs.push(o);
    }
    let mut lay = vec![0u8; n];
    lay.par_chunks_mut(cols).enumerate().for_each(|(r, o)| {
        let p = &position[r * cols..(r + 1) * cols];
        let f = &flags[r * cols..(r + 1) * cols];
        let c = &count[r * n_bins..(r + 1) * n_bins];
        for j in 0..cols {
            o[j] = u8::from(p[j].is_finite() && in_layover(c[bin(p[j])], f[j]));
        }
    });
    Ok((outs, lay))
}

/// A terrain-geocoded scene on the DEM's grid (see [`scene`]).
#[derive(Debug, Clone)]
pub struct Scene {
    /// Local incidence, degrees (as [`Geometry::theta_local`]).
    pub theta_local: Vec<f64>,
    /// Intensity with speckle (sigma0 when no looks are asked).
    pub image: Vec<f64>,
    /// Intensity without speckle.
    pub sigma0: Vec<f64>,
    /// 1 in layover (as [`geocode`]).
    pub layover: Vec<u8>,
    /// 1 in radar shadow.
    pub shadow: Vec<u8>,
}

/// The slant-range axis of a scene, as in [`geometry`]: `(lo, n_bins)`, the
/// smallest unshifted position and the number of bins from it.
/// The slant-range axis `slant` fixed by the caller (checked), or the
/// grid's own ([`slant_axis`]).
fn given_or_own_axis(
    slant: Option<(f64, usize)>,
    z: &[f64],
    cols: usize,
    prm: &Params,
) -> CoreResult<(f64, usize)> {
    match slant {
        Some((lo, n_bins)) => {
            if !lo.is_finite() || n_bins == 0 || n_bins > 1 << 31 {
                return Err(CoreError::invalid(
                    "slant",
                    format!("expected a finite origin and 1..2^31 bins, got ({lo}, {n_bins})"),
                ));
            }
            Ok((lo, n_bins))
        }
        None => slant_axis(z, cols, prm),
    }
}

fn slant_axis(z: &[f64], cols: usize, prm: &Params) -> CoreResult<(f64, usize)> {
    let (lo, hi) = slant_extent(z, cols, prm.dx, prm.cot);
    let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 0.0) };
    let span = hi - lo;
    if span > 1e9 {
        return Err(CoreError::invalid(
            "dem",
            format!("the scene spans {span:.3e} slant-range bins: heights and cell_size in the same units?"),
        ));
    }
    Ok((lo, span.ceil() as usize + 1))
}

/// The smallest and largest finite unshifted slant position `j - z cot / dx`
/// of the rows of `z` (`cols` columns) at cotangent `cot` (infinities when
/// none is finite); the positions of [`scene_block`]'s lines, bit for bit.
pub fn slant_extent(z: &[f64], cols: usize, dx: f64, cot: f64) -> (f64, f64) {
    let cot_dx = cot / dx;
    z.par_chunks(cols.max(1))
        .map(|line| {
            // four running extremes (min and max are exact in any order),
            // selects instead of a branch: it vectorises; `j` as i32:
            // cols < 2^31
            let mut lo = [f64::INFINITY; 4];
            let mut hi = [f64::NEG_INFINITY; 4];
            let mut put = |q: usize, j: usize, v: f64| {
                let p = j as i32 as f64 - v * cot_dx;
                let fin = p.is_finite();
                lo[q] = lo[q].min(if fin { p } else { f64::INFINITY });
                hi[q] = hi[q].max(if fin { p } else { f64::NEG_INFINITY });
            };
            let quads = line.chunks_exact(4);
            let rest = quads.remainder();
            for (i, v) in quads.enumerate() {
                for (q, &x) in v.iter().enumerate() {
                    put(q, 4 * i + q, x);
                }
            }
            for (i, &v) in rest.iter().enumerate() {
                put(i, line.len() - rest.len() + i, v);
            }
            (
                lo[0].min(lo[1]).min(lo[2].min(lo[3])),
                hi[0].max(hi[1]).max(hi[2].max(hi[3])),
            )
        })
        .reduce(
            || (f64::INFINITY, f64::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        )
}

/// [`geometry`], [`project`], speckle ([`crate::radar::speckle::speckle`]
/// of the slant image, `rows x n_bins`, origin `(0, 0)`) and [`geocode`]
/// fused per range line: the same values, without the intermediate
/// whole-scene arrays (each line works in buffers of its thread). `looks`
/// `None`: no speckle.
#[allow(clippy::too_many_arguments)]
pub fn scene(
    z: &[f64],
    rows: usize,
    cols: usize,
    dx: f64,
    dy: f64,
    incidence: f64,
    table: &[f64],
    table_step: f64,
    looks: Option<u32>,
    seed: u64,
) -> CoreResult<Scene> {
    scene_block(
        z, rows, cols, dx, dy, incidence, table, table_step, looks, seed, 0, None, None,
    )
}

/// [`scene`] of a strip of whole range lines of a larger scene: `row0` is
/// the global index of the strip's first line (it places the speckle draws)
/// and `slant = Some((lo, n_bins))` fixes the slant-range axis to the whole
/// scene's (the position `lo`, in bins of the unshifted axis, is bin 0;
/// `None`: the strip's own extent, as [`scene`]). A strip computed with the
/// whole scene's `(lo, n_bins)` and `row0`, and one line more on each side
/// where the scene has them (for the derivative across lines), equals the
/// same lines of the whole scene.
///
/// `progress`, when given, gets `rows` added to its total and one tick per
/// range line done; it never changes the result.
#[allow(clippy::too_many_arguments)]
pub fn scene_block(
    z: &[f64],
    rows: usize,
    cols: usize,
    dx: f64,
    dy: f64,
    incidence: f64,
    table: &[f64],
    table_step: f64,
    looks: Option<u32>,
    seed: u64,
    row0: u64,
    slant: Option<(f64, usize)>,
    progress: Option<&Progress>,
) -> CoreResult<Scene> {
    check(z, rows, cols, dx, dy, incidence)?;
    if table.is_empty() || !(table_step.is_finite() && table_step > 0.0) {
        return Err(CoreError::invalid(
            "table",
            "expected a non-empty sigma0 table and a positive step",
        ));
    }
    if looks == Some(0) {
        return Err(CoreError::invalid("looks", "expected an integer >= 1"));
    }
    let prm = Params::new(dx, dy, incidence, table, table_step);
    let (lo, n_bins) = given_or_own_axis(slant, z, cols, &prm)?;
    let lines = Lines {
        z,
        rows,
        cols,
        p: &prm,
        lo,
    };
    let key = crate::rng::StreamKey::new(seed, speckle::STREAM);
    progress::add_total(progress, rows as u64);
    let n = rows * cols;
    // written once each, in parallel; huge pages advised (a page fault per
    // 2 MiB instead of per 4 KiB where the system allows it)
    let mut theta = buffers::zeroed(n);
    let mut image = buffers::zeroed(n);
    let mut sigma0 = buffers::zeroed(n);
    let mut layover = buffers::zeroed_bytes(n);
    let mut shadow = buffers::zeroed_bytes(n);
    theta
        .par_chunks_mut(cols)
        .zip(image.par_chunks_mut(cols))
        .zip(sigma0.par_chunks_mut(cols))
        .zip(layover.par_chunks_mut(cols))
        .zip(shadow.par_chunks_mut(cols))
        .enumerate()
        .for_each_init(
            || {
                (
                    (RowScratch::new(cols), Halves::new(cols)),
                    vec![0.0; cols],
                    vec![0.0; cols],
                    vec![0u8; cols],
                    vec![0.0; n_bins],
                    vec![0u32; n_bins],
                    vec![0.0; n_bins],
                )
            },
            |((scr, hv), pw, ps, fl, img, cnt, spk), (r, ((((th, im), s0), lay), shd))| {
                geometry_row(&lines, r, RowOut { th, pw, ps, fl }, scr);
                img.fill(0.0);
                cnt.fill(0);
                project_row::<false>(ps, pw, fl, img, cnt, &mut [], hv);
                match looks {
                    // the products of the uniforms, then one vectorised pass
                    // for the logarithms: `gamma_unit`'s values
                    Some(l) if l <= 16 => {
                        let start = (row0 + r as u64).wrapping_mul(n_bins as u64);
                        speckle::fill_products(spk, key, start, l);
                        speckle::apply_products(spk, img, l);
                    }
                    Some(l) => {
                        let start = (row0 + r as u64).wrapping_mul(n_bins as u64);
                        for (k, (o, &v)) in spk.iter_mut().zip(img.iter()).enumerate() {
                            *o = if v.is_nan() {
                                f64::NAN
                            } else {
                                v * speckle::gamma_unit(key, start.wrapping_add(k as u64), l)
                            };
                        }
                    }
                    None => spk.copy_from_slice(img),
                }
                for j in 0..cols {
                    if ps[j].is_finite() {
                        // the bin of the pixel's centre (`slant_bin`)
                        let k = hv.kc[j] as usize;
                        im[j] = spk[k];
                        s0[j] = img[k];
                        lay[j] = u8::from(in_layover(cnt[k], fl[j]));
                    } else {
                        im[j] = f64::NAN;
                        s0[j] = f64::NAN;
                        lay[j] = 0;
                    }
                    shd[j] = fl[j] & SHADOW;
                }
                progress::tick(progress, 1);
            },
        );
    Ok(Scene {
        theta_local: theta,
        image,
        sigma0,
        layover,
        shadow,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_acos_matches_libm() {
        let n = 2_000_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let x = -1.0 + 2.0 * i as f64 / n as f64;
            worst = worst.max((fast_acos(x) - x.acos()).abs());
        }
        for x in [
            -1.0,
            -0.5,
            0.0,
            0.5,
            1.0,
            1e-300,
            -1e-300,
            0.5 + 1e-16,
            1.0 - 1e-16,
        ] {
            worst = worst.max((fast_acos(x) - f64::acos(x)).abs());
        }
        assert!(worst < 2e-15, "{worst}");
        assert!(fast_acos(f64::NAN).is_nan());
    }

    fn plane(rows: usize, cols: usize, dx: f64, slope_deg: f64) -> Vec<f64> {
        let g = slope_deg.to_radians().tan();
        (0..rows * cols)
            .map(|i| (i % cols) as f64 * dx * g)
            .collect()
    }

    #[test]
    fn local_incidence_of_a_plane() {
        for s in [-40.0f64, -10.0, 0.0, 12.0, 30.0] {
            let z = plane(3, 6, 2.0, s);
            let g = geometry(&z, 3, 6, 2.0, 2.0, 35.0, &[1.0, 1.0], 90.0).unwrap();
            for t in &g.theta_local {
                assert!((t - (35.0 - s).abs()).abs() < 1e-9, "slope {s}: {t}");
            }
            // flat table: power = facet area / cell area = 1 / cos(s)
            for p in &g.power {
                assert!((p - 1.0 / s.to_radians().cos()).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn shadow_onset_at_ninety_minus_incidence() {
        let theta = 35.0;
        for (s, want) in [(-54.9, 0u8), (-55.1, 1u8)] {
            let z = plane(2, 8, 1.0, s);
            let g = geometry(&z, 2, 8, 1.0, 1.0, theta, &[1.0], 1.0).unwrap();
            assert!(g.flags.iter().all(|&v| v & SHADOW == want), "slope {s}");
        }
    }

    #[test]
    fn cast_shadow_behind_a_step() {
        // a wall of height 10 at column 3, flat elsewhere: at 45 degrees the
        // shadow covers the 10 m behind it (columns 4..=12 strictly below the ray)
        let cols = 20;
        let z: Vec<f64> = (0..cols).map(|j| if j == 3 { 10.0 } else { 0.0 }).collect();
        let g = geometry(&z, 1, cols, 1.0, 1.0, 45.0, &[1.0], 1.0).unwrap();
        for j in 5..13 {
            assert_eq!(g.flags[j] & SHADOW, 1, "column {j}");
        }
        assert_eq!(g.flags[14] & SHADOW, 0);
    }

    #[test]
    fn flat_ground_projects_one_to_one_and_layover_counts() {
        let z = vec![0.0; 2 * 5];
        let g = geometry(&z, 2, 5, 1.0, 1.0, 30.0, &[1.0], 1.0).unwrap();
        let s = project(&[1.0; 10], &g.position, &g.flags, 2, 5, g.n_bins).unwrap();
        assert_eq!(g.n_bins, 5);
        assert!(s.image.iter().all(|v| (v - 1.0).abs() < 1e-12));
        assert!(s.count.iter().all(|&c| c == 1));
        // a plane steeper than the incidence: every bin in layover-free order
        // reversed (count 1), a ridge: forward then reversed -> count 2 at least
        let z = plane(1, 8, 1.0, 40.0);
        let g = geometry(&z, 1, 8, 1.0, 1.0, 30.0, &[1.0], 1.0).unwrap();
        assert!(g.position.windows(2).all(|w| w[1] < w[0]));
        assert!(g.flags.iter().all(|&f| f == ACTIVE_LAYOVER));
        let power = vec![1.0; 8];
        let s = project(&power, &g.position, &g.flags, 1, 8, g.n_bins).unwrap();
        let total: f64 = s.image.iter().filter(|v| v.is_finite()).sum();
        assert!((total - 8.0).abs() < 1e-9, "power conserved: {total}");
    }

    #[test]
    fn every_pixel_covers_its_own_bin_at_a_fold() {
        // a ridge whose front slope (50 deg) is steeper than the incidence:
        // the crest is a fold of the slant-range map
        let cols = 40;
        let z: Vec<f64> = (0..cols)
            .map(|j| {
                let x = j as f64;
                if x < 10.0 {
                    0.0
                } else if x < 20.0 {
                    (x - 10.0) * 50f64.to_radians().tan()
                } else {
                    (30.0 - x).max(0.0) * 50f64.to_radians().tan()
                }
            })
            .collect();
        let g = geometry(&z, 1, cols, 1.0, 1.0, 30.0, &[1.0], 1.0).unwrap();
        let s = project(&vec![1.0; cols], &g.position, &g.flags, 1, cols, g.n_bins).unwrap();
        for j in 0..cols {
            let k = ((g.position[j] + 0.5).floor() as usize).min(g.n_bins - 1);
            assert!(s.count[k] >= 1, "pixel {j} bin {k}");
        }
        let total: f64 = s.image.iter().filter(|v| v.is_finite()).sum();
        assert!((total - cols as f64).abs() < 1e-9);
    }

    #[test]
    fn a_sharp_spike_covers_its_own_bin() {
        // pixel 2 at 3.6 (bin 4), in shadow: both halves of its footprint
        // run back to the midpoint 2.3 and miss the centre of bin 4, which
        // is still covered (0, not NaN: no footprint)
        let p = [0.0, 1.0, 3.6, 1.0, 2.0];
        let s = project(
            &[1.0, 1.0, 0.0, 1.0, 1.0],
            &p,
            &[0, 0, SHADOW, 0, 0],
            1,
            5,
            5,
        )
        .unwrap();
        assert_eq!((s.count[4], s.lit[4]), (1, 0));
        assert_eq!(s.image[4], 0.0);
        let total: f64 = s.image.iter().filter(|v| v.is_finite()).sum();
        assert!((total - 4.0).abs() < 1e-12);
    }

    #[test]
    fn vector_paths_equal_the_baseline_code() {
        // the row kernels as dispatched (AVX2 where the CPU has it) against
        // the same code compiled for the baseline target: the same bits, on
        // relief with shadow, layover and a missing height
        let (rows, cols) = (5, 203);
        let z: Vec<f64> = (0..rows * cols)
            .map(|i| {
                let (r, c) = ((i / cols) as f64, (i % cols) as f64);
                let spike = if i % 37 == 5 { 9.0 } else { 0.0 };
                30.0 * (0.21 * c).sin() * (0.4 * r).cos()
                    + spike
                    + if i == 420 { f64::NAN } else { 0.0 }
            })
            .collect();
        let table: Vec<f64> = (0..900).map(|i| (-(i as f64) / 300.0).exp()).collect();
        let prm = Params::new(1.0, 1.0, 30.0, &table, 0.1);
        let (lo, n_bins) = slant_axis(&z, cols, &prm).unwrap();
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        for r in 0..rows {
            let mut a = (
                vec![0.0; cols],
                vec![0.0; cols],
                vec![0.0; cols],
                vec![0u8; cols],
            );
            let mut b = a.clone();
            let mut scr = RowScratch::new(cols);
            let lines = Lines {
                z: &z,
                rows,
                cols,
                p: &prm,
                lo,
            };
            let (a0, a1, a2, a3) = &mut a;
            let out_a = RowOut {
                th: a0,
                pw: a1,
                ps: a2,
                fl: a3,
            };
            geometry_row(&lines, r, out_a, &mut scr);
            let (b0, b1, b2, b3) = &mut b;
            let out_b = RowOut {
                th: b0,
                pw: b1,
                ps: b2,
                fl: b3,
            };
            geometry_row_impl(&lines, r, out_b, &mut scr);
            assert_eq!(bits(&a.0), bits(&b.0));
            assert_eq!(bits(&a.1), bits(&b.1));
            assert_eq!(bits(&a.2), bits(&b.2));
            assert_eq!(a.3, b.3);
            assert!(
                a.3.iter().any(|&f| f & SHADOW != 0)
                    && a.3.iter().any(|&f| f & ACTIVE_LAYOVER != 0)
            );
            let (mut ha, mut hb) = (Halves::new(cols), Halves::new(cols));
            // (the cfg must not take the baseline branch away on other targets)
            #[cfg(target_arch = "x86_64")]
            let avx2 = std::arch::is_x86_feature_detected!("avx2");
            #[cfg(not(target_arch = "x86_64"))]
            let avx2 = false;
            if avx2 {
                // SAFETY: the CPU has AVX2 (checked just above).
                #[cfg(target_arch = "x86_64")]
                unsafe {
                    prepare_line_avx2(&a.2, &a.1, &a.3, n_bins, &mut ha)
                };
            } else {
                prepare_line_impl(&a.2, &a.1, &a.3, n_bins, &mut ha);
            }
            prepare_line_impl(&a.2, &a.1, &a.3, n_bins, &mut hb);
            assert_eq!(ha.kc, hb.kc);
            for (j, &p) in a.2.iter().enumerate() {
                if p.is_finite() {
                    assert_eq!(ha.kc[j] as usize, slant_bin(p, n_bins));
                }
            }
            for side in 0..2 {
                assert_eq!(ha.ka[side], hb.ka[side]);
                assert_eq!(bits(&ha.va[side]), bits(&hb.va[side]));
                assert_eq!(bits(&ha.vb[side]), bits(&hb.vb[side]));
                assert_eq!(ha.code[side], hb.code[side]);
            }
        }
    }

    #[test]
    fn fused_scene_equals_the_composed_steps() {
        let (rows, cols) = (9, 31);
        let z: Vec<f64> = (0..rows * cols)
            .map(|i| {
                let (r, c) = ((i / cols) as f64, (i % cols) as f64);
                12.0 * (0.3 * c).sin() * (0.2 * r).cos() + if i == 40 { f64::NAN } else { 0.0 }
            })
            .collect();
        let table: Vec<f64> = (0..900).map(|i| (-(i as f64) / 300.0).exp()).collect();
        let sc = scene(&z, rows, cols, 1.5, 2.0, 35.0, &table, 0.1, Some(3), 7).unwrap();
        let g = geometry(&z, rows, cols, 1.5, 2.0, 35.0, &table, 0.1).unwrap();
        let s = project(&g.power, &g.position, &g.flags, rows, cols, g.n_bins).unwrap();
        let place = crate::radar::speckle::Placement {
            origin: (0, 0),
            global_cols: g.n_bins as u64,
        };
        let spk = crate::radar::speckle::speckle(&s.image, g.n_bins, 3, 7, place).unwrap();
        let (outs, lay) = geocode(
            &[&spk, &s.image],
            &s.count,
            &g.position,
            &g.flags,
            rows,
            cols,
            g.n_bins,
        )
        .unwrap();
        let same = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .all(|(x, y)| x.to_bits() == y.to_bits() || x.is_nan() && y.is_nan())
        };
        assert!(same(&sc.theta_local, &g.theta_local));
        assert!(same(&sc.image, &outs[0]));
        assert!(same(&sc.sigma0, &outs[1]));
        assert_eq!(sc.layover, lay);
        let shd: Vec<u8> = g.flags.iter().map(|f| f & SHADOW).collect();
        assert_eq!(sc.shadow, shd);
    }

    #[test]
    fn strips_of_range_lines_equal_the_whole() {
        let (rows, cols) = (11, 37);
        let z: Vec<f64> = (0..rows * cols)
            .map(|i| {
                let (r, c) = ((i / cols) as f64, (i % cols) as f64);
                20.0 * (0.4 * c).sin() * (0.3 * r).cos() + if i == 100 { f64::NAN } else { 0.0 }
            })
            .collect();
        let table: Vec<f64> = (0..900).map(|i| (-(i as f64) / 300.0).exp()).collect();
        let whole = scene(&z, rows, cols, 1.5, 2.0, 30.0, &table, 0.1, Some(2), 11).unwrap();
        let (lo, hi) = slant_extent(&z, cols, 1.5, cot_of(30.0));
        let axis = Some((lo, (hi - lo).ceil() as usize + 1));
        // strips [a, b) computed with one line more on each side where there is one
        for (a, b) in [(0, 4), (4, 5), (5, 11)] {
            let (h0, h1) = (a.max(1) - 1, (b + 1).min(rows));
            let blk = &z[h0 * cols..h1 * cols];
            let s = scene_block(
                blk,
                h1 - h0,
                cols,
                1.5,
                2.0,
                30.0,
                &table,
                0.1,
                Some(2),
                11,
                h0 as u64,
                axis,
                None,
            )
            .unwrap();
            let off = (a - h0) * cols;
            let m = (b - a) * cols;
            let same = |x: &[f64], y: &[f64]| {
                x.iter()
                    .zip(y)
                    .all(|(p, q)| p.to_bits() == q.to_bits() || p.is_nan() && q.is_nan())
            };
            assert!(same(
                &s.image[off..off + m],
                &whole.image[a * cols..b * cols]
            ));
            assert!(same(
                &s.sigma0[off..off + m],
                &whole.sigma0[a * cols..b * cols]
            ));
            assert!(same(
                &s.theta_local[off..off + m],
                &whole.theta_local[a * cols..b * cols]
            ));
            assert_eq!(&s.layover[off..off + m], &whole.layover[a * cols..b * cols]);
            assert_eq!(&s.shadow[off..off + m], &whole.shadow[a * cols..b * cols]);
        }
    }

    #[test]
    fn progress_ticks_each_range_line_and_changes_nothing() {
        let (rows, cols) = (13, 17);
        let z: Vec<f64> = (0..rows * cols)
            .map(|i| {
                let (r, c) = ((i / cols) as f64, (i % cols) as f64);
                15.0 * (0.5 * c).sin() * (0.2 * r).cos()
            })
            .collect();
        let table: Vec<f64> = (0..900).map(|i| (-(i as f64) / 300.0).exp()).collect();
        let plain = scene(&z, rows, cols, 1.5, 2.0, 30.0, &table, 0.1, Some(3), 5).unwrap();
        let p = Progress::new();
        let counted = scene_block(
            &z,
            rows,
            cols,
            1.5,
            2.0,
            30.0,
            &table,
            0.1,
            Some(3),
            5,
            0,
            None,
            Some(&p),
        )
        .unwrap();
        assert_eq!((p.done(), p.total()), (rows as u64, rows as u64));
        let bits = |x: &[f64]| x.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&plain.image), bits(&counted.image));
        assert_eq!(bits(&plain.sigma0), bits(&counted.sigma0));
        assert_eq!(plain.layover, counted.layover);
        assert_eq!(plain.shadow, counted.shadow);
    }
}
