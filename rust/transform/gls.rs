//! Moving-window GLS estimate of the Hurst exponent over the log quadratic
//! variations of increment filters.
//!
//! Filters (the order of the tables): first then second differences, along
//! rows `(0, 1)`, columns `(1, 0)`, the diagonal `(1, 1)` and the
//! anti-diagonal `(1, -1)`, at dilations `1 ..= k`: `8 k` filters. For each
//! window (the `w x w` square centred on the pixel, clipped to the image),
//! `y_f = ln V_f` with `V_f` the mean square of the valid increments of `f`
//! whose taps all lie in the window, and `H` is found by Gauss-Newton steps
//! `H <- H + g(H) . (y - a(H))` from `H = 0.5`, with `a` (cubic Hermite from
//! `a` and `da/dH`) and `g` (linear) interpolated in tables on a uniform
//! grid of `H` computed by the Python layer from the exact fBm covariance of
//! the window's quadratic variations. The standard error is `se(H)` of the
//! tables times `sqrt(w² / valid pixels)`. Window sums come from summed-area
//! tables built per band of rows at fixed positions (as in
//! [`super::variation`]), so the cost per pixel does not grow with the window
//! and the result does not depend on the thread count.
use super::driver::{Band, Grid, MapOut};
use crate::error::{CoreError, CoreResult};
use crate::sample::Sample;

const DIRS: [(isize, isize); 4] = [(0, 1), (1, 0), (1, 1), (1, -1)];

/// One increment filter: up to three taps `(row, col, weight)` at
/// non-negative offsets, and its span (largest offsets).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Filter {
    pub taps: [(usize, usize, f64); 3],
    pub n_taps: usize,
    pub span: (usize, usize),
    pub order: usize,
    pub dir: usize,
    pub dilation: usize,
}

/// The `8 k` filters in table order.
pub fn filters(k: usize) -> Vec<Filter> {
    let mut out = Vec::with_capacity(8 * k);
    for order in [1usize, 2] {
        let w: &[f64] = if order == 1 {
            &[-1.0, 1.0]
        } else {
            &[1.0, -2.0, 1.0]
        };
        for (dir, &(er, ec)) in DIRS.iter().enumerate() {
            for u in 1..=k {
                let offs: Vec<(isize, isize)> = (0..=order as isize)
                    .map(|t| (t * u as isize * er, t * u as isize * ec))
                    .collect();
                let (mr, mc) = offs
                    .iter()
                    .fold((0isize, 0isize), |(a, b), &(r, c)| (a.min(r), b.min(c)));
                let mut taps = [(0usize, 0usize, 0.0f64); 3];
                let mut span = (0usize, 0usize);
                for (t, &(r, c)) in offs.iter().enumerate() {
                    let (r, c) = ((r - mr) as usize, (c - mc) as usize);
                    taps[t] = (r, c, w[t]);
                    span = (span.0.max(r), span.1.max(c));
                }
                out.push(Filter {
                    taps,
                    n_taps: order + 1,
                    span,
                    order,
                    dir,
                    dilation: u,
                });
            }
        }
    }
    out
}

/// GLS tables on the grid `h0, h0 + dh, ...` (`n_h` values), row-major
/// `(n_h, K)` for `a`, `da` and `g`, `(n_h,)` for `se`.
#[derive(Debug, Clone)]
pub struct GlsTables {
    pub h0: f64,
    pub dh: f64,
    pub n_h: usize,
    pub a: Vec<f64>,
    pub da: Vec<f64>,
    pub g: Vec<f64>,
    pub se: Vec<f64>,
}

impl GlsTables {
    fn check(&self, k: usize) -> CoreResult<()> {
        let ok = self.n_h >= 2
            && self.dh.is_finite()
            && self.dh > 0.0
            && self.h0.is_finite()
            && [&self.a, &self.da, &self.g]
                .iter()
                .all(|t| t.len() == self.n_h * k && t.iter().all(|v| v.is_finite()))
            && self.se.len() == self.n_h;
        if ok {
            Ok(())
        } else {
            Err(CoreError::invalid(
                "tables",
                format!("expected finite GLS tables of {k} filters on at least 2 values of H"),
            ))
        }
    }

    /// Node index and position in `[0, 1]` of `h` on the grid.
    #[inline]
    fn locate(&self, h: f64) -> (usize, f64) {
        let x = (h - self.h0) / self.dh;
        // floor of x clamped to [0, n_h - 2] (a cast truncates: floor for x >= 0)
        // (through i64: one conversion instruction, same value, saturating)
        let i = (x.max(0.0) as i64 as usize).min(self.n_h - 2);
        (i, x - i as f64)
    }

    /// Per interval `i` of the grid, the coefficients in `s` of
    /// `sum_f g_f(s) a_f(s)` (`g` linear, `a` cubic Hermite: a quartic), so
    /// that a Gauss-Newton step needs two dot products with `y` only.
    pub fn step_polys(&self, k: usize) -> Vec<[f64; 5]> {
        let dh = self.dh;
        (0..self.n_h - 1)
            .map(|i| {
                let (r0, r1) = (i * k, (i + 1) * k);
                let mut c = [0.0f64; 5];
                for f in 0..k {
                    let (a0, a1) = (self.a[r0 + f], self.a[r1 + f]);
                    let (d0, d1) = (dh * self.da[r0 + f], dh * self.da[r1 + f]);
                    let aa = [
                        a0,
                        d0,
                        -3.0 * a0 - 2.0 * d0 + 3.0 * a1 - d1,
                        2.0 * a0 + d0 - 2.0 * a1 + d1,
                    ];
                    let (b0, b1) = (self.g[r0 + f], self.g[r1 + f] - self.g[r0 + f]);
                    c[0] += b0 * aa[0];
                    c[1] += b0 * aa[1] + b1 * aa[0];
                    c[2] += b0 * aa[2] + b1 * aa[1];
                    c[3] += b0 * aa[3] + b1 * aa[2];
                    c[4] += b1 * aa[3];
                }
                c
            })
            .collect()
    }

    /// [`GlsTables::solve`] with the polynomials of [`GlsTables::step_polys`]
    /// (equal to rounding).
    pub fn solve_with(&self, polys: &[[f64; 5]], ys: &[f64], steps: usize) -> (f64, f64) {
        let k = ys.len();
        let hi = self.h0 + self.dh * (self.n_h - 1) as f64;
        let mut h = 0.5f64;
        // the dot products of an interval, reused while the steps stay in it
        let (mut last, mut y0, mut y1) = (usize::MAX, 0.0, 0.0);
        for _ in 0..steps {
            let (i, s) = self.locate(h);
            if i != last {
                let (g0, g1) = (
                    &self.g[i * k..(i + 1) * k],
                    &self.g[(i + 1) * k..(i + 2) * k],
                );
                (y0, y1) = (0.0, 0.0);
                for f in 0..k {
                    y0 += g0[f] * ys[f];
                    y1 += g1[f] * ys[f];
                }
                last = i;
            }
            let c = &polys[i];
            let ga = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * c[4])));
            h = (h + (1.0 - s) * y0 + s * y1 - ga).clamp(self.h0, hi);
        }
        let (i, s) = self.locate(h);
        (h, (1.0 - s) * self.se[i] + s * self.se[i + 1])
    }

    /// [`GlsTables::solve_with`] on `n = hs.len()` windows at once (`ys`
    /// row-major `n x K`), the steps of the windows interleaved so that their
    /// dependency chains (division, dot products, quartic) overlap; each
    /// window's arithmetic is that of `solve_with`, so the results are equal
    /// bit for bit. Writes `(H, se of H)` to `hs`, `ses`.
    #[inline(always)]
    pub fn solve_batch(
        &self,
        polys: &[[f64; 5]],
        ys: &[f64],
        steps: usize,
        hs: &mut [f64],
        ses: &mut [f64],
    ) {
        const B: usize = 8;
        let n = hs.len();
        let Some(k) = ys.len().checked_div(n) else {
            return;
        };
        let hi = self.h0 + self.dh * (self.n_h - 1) as f64;
        for b0 in (0..n).step_by(B) {
            let m = B.min(n - b0);
            let mut h = [0.5f64; B];
            let mut last = [usize::MAX; B];
            let (mut y0, mut y1) = ([0.0f64; B], [0.0f64; B]);
            for _ in 0..steps {
                for l in 0..m {
                    let (i, s) = self.locate(h[l]);
                    if i != last[l] {
                        let y = &ys[(b0 + l) * k..(b0 + l + 1) * k];
                        let (g0, g1) = (
                            &self.g[i * k..(i + 1) * k],
                            &self.g[(i + 1) * k..(i + 2) * k],
                        );
                        let (mut a0, mut a1) = (0.0, 0.0);
                        for f in 0..k {
                            a0 += g0[f] * y[f];
                            a1 += g1[f] * y[f];
                        }
                        (y0[l], y1[l], last[l]) = (a0, a1, i);
                    }
                    let c = &polys[i];
                    let ga = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * c[4])));
                    h[l] = (h[l] + (1.0 - s) * y0[l] + s * y1[l] - ga).clamp(self.h0, hi);
                }
            }
            for l in 0..m {
                let (i, s) = self.locate(h[l]);
                hs[b0 + l] = h[l];
                ses[b0 + l] = (1.0 - s) * self.se[i] + s * self.se[i + 1];
            }
        }
    }

    /// Gauss-Newton steps from `H = 0.5`; returns `(H, se of H)`.
    pub fn solve(&self, ys: &[f64], steps: usize) -> (f64, f64) {
        let k = ys.len();
        let hi = self.h0 + self.dh * (self.n_h - 1) as f64;
        let mut h = 0.5f64;
        for _ in 0..steps {
            let (i, s) = self.locate(h);
            let (s2, s3) = (s * s, s * s * s);
            let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
            let h10 = (s3 - 2.0 * s2 + s) * self.dh;
            let h01 = -2.0 * s3 + 3.0 * s2;
            let h11 = (s3 - s2) * self.dh;
            let (r0, r1) = (i * k, (i + 1) * k);
            let mut step = 0.0;
            for (f, &y) in ys.iter().enumerate().take(k) {
                let a = h00 * self.a[r0 + f]
                    + h10 * self.da[r0 + f]
                    + h01 * self.a[r1 + f]
                    + h11 * self.da[r1 + f];
                let g = (1.0 - s) * self.g[r0 + f] + s * self.g[r1 + f];
                step += g * (y - a);
            }
            h = (h + step).clamp(self.h0, hi);
        }
        let (i, s) = self.locate(h);
        (h, (1.0 - s) * self.se[i] + s * self.se[i + 1])
    }
}

/// Direction (degrees in `[0, 180)` from the column axis towards the row
/// axis) and ratio (`>= 1`) of geometric anisotropy from the log first-order
/// quadratic variations `ys` (table order) at Hurst exponent `h`: `q_e =
/// exp(mean over dilations u of (y / h - 2 ln u))` per direction, `M` the
/// least-squares fit of `q_e = e' M e`, the direction that of the leading
/// eigenvector of `M`, the ratio `sqrt(lambda_max / lambda_min)` (NaN when
/// `M` is not positive definite).
pub fn anisotropy(ys: &[f64], k: usize, h: f64) -> (f64, f64) {
    let mut q = [0.0f64; 4];
    for (d, qd) in q.iter_mut().enumerate() {
        let mut m = 0.0;
        for u in 1..=k {
            m += ys[d * k + u - 1] / h - 2.0 * (u as f64).ln();
        }
        *qd = (m / k as f64).exp();
    }
    // rows (0,1): m_cc; columns (1,0): m_rr; diagonals: m_rr + m_cc +- 2 m_rc
    let m_rc = (q[2] - q[3]) / 4.0;
    let s = (q[2] + q[3]) / 2.0;
    let e = (q[0] + q[1] - s) / 5.0;
    let (m_cc, m_rr) = (q[0] - 2.0 * e, q[1] - 2.0 * e);
    let half = (m_rr + m_cc) / 2.0;
    let rad = (((m_rr - m_cc) / 2.0).powi(2) + m_rc * m_rc).sqrt();
    let (lmax, lmin) = (half + rad, half - rad);
    let phi = 0.5 * (2.0 * m_rc).atan2(m_rr - m_cc); // from the row axis
    let ang = (90.0 - phi.to_degrees()).rem_euclid(180.0);
    let ratio = if lmin > 0.0 {
        (lmax / lmin).sqrt()
    } else {
        f64::NAN
    };
    (ang, ratio)
}

/// Options of [`gls_transform`].
#[derive(Debug, Clone)]
pub struct GlsOptions {
    pub window: usize,
    /// Largest dilation `k` (`8 k` filters).
    pub dilations: usize,
    /// Gauss-Newton steps from `H = 0.5`.
    pub steps: usize,
    pub min_valid: f64,
    pub step: usize,
    /// Also compute the anisotropy direction and ratio maps.
    pub anisotropy: bool,
}

/// `ln` of a positive normal finite value: a polynomial (atanh series to
/// `s^13`, relative error below 1e-10) the compiler vectorises.
#[inline(always)]
fn ln_normal(x: f64) -> f64 {
    const SQRT2: f64 = std::f64::consts::SQRT_2;
    const LN2: f64 = std::f64::consts::LN_2;
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    let big = m > SQRT2;
    let (m, e) = if big { (m * 0.5, e + 1) } else { (m, e) };
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let p = 1.0
        + s2 * (1.0 / 3.0
            + s2 * (1.0 / 5.0
                + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0 + s2 * (1.0 / 11.0 + s2 * (1.0 / 13.0))))));
    e as f64 * LN2 + 2.0 * s * p
}

/// `ln` of positive finite values in place: [`ln_normal`], or the library
/// `ln` for all of them when one is subnormal.
fn ln_in_place(v: &mut [f64]) {
    if v.iter().any(|&x| x < f64::MIN_POSITIVE) {
        v.iter_mut().for_each(|x| *x = x.ln());
        return;
    }
    v.iter_mut().for_each(|x| *x = ln_normal(*x));
}

#[test]
fn fast_ln_matches_the_library() {
    let mut xs: Vec<f64> = (0..2000)
        .map(|k| 1.37f64.powf(k as f64 / 7.0 - 140.0))
        .collect();
    xs.push(1e-310);
    let want: Vec<f64> = xs.iter().map(|x| x.ln()).collect();
    ln_in_place(&mut xs[..2000]);
    for (a, b) in xs[..2000].iter().zip(&want) {
        assert!((a - b).abs() <= 1e-10 * b.abs().max(1.0), "{a} {b}");
    }
    let mut t = vec![1e-310, 2.0];
    ln_in_place(&mut t);
    assert_eq!(t, vec![(1e-310f64).ln(), 2f64.ln()]);
}

/// `hi + lo += x` without losing the low-order bits (Knuth's TwoSum): the
/// pair holds the running sum to about `eps²` of the largest partial sum,
/// so a window sum left after a large value has slid out is not swamped by
/// its rounding.
#[inline(always)]
fn add2(hi: &mut f64, lo: &mut f64, x: f64) {
    let s = *hi + x;
    let bp = s - *hi;
    *lo += (*hi - (s - bp)) + (x - bp);
    *hi = s;
}

/// Squares of the increments of filter `f` anchored on band row `r`,
/// columns `0 .. n` (taps on rows `r + dr`), added to (`sign = 1`) or taken
/// from (`sign = -1`) the column sums `(hi, lo)` and, with `cnt`, the
/// counts; a square that is not finite (a NaN sample, or an overflow) is
/// left out.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn slide_row<T: Sample, const N: usize>(
    z: &[T],
    cols: usize,
    row0: usize,
    f: &Filter,
    sign: f64,
    hi: &mut [f64],
    lo: &mut [f64],
    cnt: Option<&mut [f64]>,
) {
    let n = cols.saturating_sub(f.span.1);
    if n == 0 {
        return;
    }
    let taps: [(&[T], f64); N] = std::array::from_fn(|t| {
        let (dr, dc, wt) = f.taps[t];
        let at = (row0 + dr) * cols + dc;
        (&z[at..at + n], wt)
    });
    let sq = |c: usize| -> f64 {
        let mut d = 0.0;
        for (row, wt) in &taps {
            d += wt * row[c].to_f64();
        }
        d * d
    };
    match cnt {
        None => {
            for c in 0..n {
                add2(&mut hi[c], &mut lo[c], sign * sq(c));
            }
        }
        Some(cnt) => {
            for c in 0..n {
                let v = sq(c);
                let ok = v.is_finite();
                add2(&mut hi[c], &mut lo[c], if ok { sign * v } else { 0.0 });
                cnt[c] += if ok { sign } else { 0.0 };
            }
        }
    }
}

/// Prefix sums along the row of the per-filter column sums `hi + lo`
/// (`nf x cols`), compensated (two [`add2`] per value, `hi` then `lo`):
/// `phi + plo` at `c * nf + f` is the sum over columns `0 .. c` of filter
/// `f`. Filters in pairs with SSE2 on x86_64 (the same operations, so the
/// same bits as the scalar loop).
#[inline(always)]
fn prefix_sums(hi: &[f64], lo: &[f64], cols: usize, nf: usize, phi: &mut [f64], plo: &mut [f64]) {
    assert!(hi.len() >= nf * cols && lo.len() >= nf * cols);
    assert!(phi.len() >= (cols + 1) * nf && plo.len() >= (cols + 1) * nf);
    phi[..nf].fill(0.0);
    plo[..nf].fill(0.0);
    #[cfg(not(target_arch = "x86_64"))]
    let f0 = 0;
    #[cfg(target_arch = "x86_64")]
    let f0 = {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of x86_64; every index is below the lengths
        // asserted above (f + 1 < nf, c < cols).
        unsafe {
            #[inline(always)]
            unsafe fn add2v(h: &mut __m128d, l: &mut __m128d, x: __m128d) {
                let s = _mm_add_pd(*h, x);
                let bp = _mm_sub_pd(s, *h);
                let t = _mm_add_pd(_mm_sub_pd(*h, _mm_sub_pd(s, bp)), _mm_sub_pd(x, bp));
                *l = _mm_add_pd(*l, t);
                *h = s;
            }
            let (hp, lp) = (hi.as_ptr(), lo.as_ptr());
            let (pp, qp) = (phi.as_mut_ptr(), plo.as_mut_ptr());
            let pairs = nf / 2;
            for c in 0..cols {
                for j in 0..pairs {
                    let f = 2 * j;
                    let (p, q) = (c * nf + f, (c + 1) * nf + f);
                    let mut ph = _mm_loadu_pd(pp.add(p));
                    let mut pl = _mm_loadu_pd(qp.add(p));
                    let xh = _mm_set_pd(*hp.add((f + 1) * cols + c), *hp.add(f * cols + c));
                    let xl = _mm_set_pd(*lp.add((f + 1) * cols + c), *lp.add(f * cols + c));
                    add2v(&mut ph, &mut pl, xh);
                    add2v(&mut ph, &mut pl, xl);
                    _mm_storeu_pd(pp.add(q), ph);
                    _mm_storeu_pd(qp.add(q), pl);
                }
            }
            2 * pairs
        }
    };
    for c in 0..cols {
        let (p, q) = (c * nf, (c + 1) * nf);
        for fi in f0..nf {
            let (mut ph, mut pl) = (phi[p + fi], plo[p + fi]);
            add2(&mut ph, &mut pl, hi[fi * cols + c]);
            add2(&mut ph, &mut pl, lo[fi * cols + c]);
            phi[q + fi] = ph;
            plo[q + fi] = pl;
        }
    }
}

/// Per-thread buffers of [`gls_transform`], reused from band to band.
#[derive(Default)]
struct GlsScratch {
    /// Per filter, column sums (`hi`, `lo`) and counts of the squared
    /// increments anchored in the current window rows (`nf x cols`).
    hi: Vec<f64>,
    lo: Vec<f64>,
    cnt: Vec<f64>,
    /// Valid samples per column in the current window rows.
    vcol: Vec<f64>,
    /// Prefix sums along the row of those, `(cols + 1) x nf` (counts and
    /// valid samples: `(cols + 1) x (nf + 1)`).
    phi: Vec<f64>,
    plo: Vec<f64>,
    pcnt: Vec<f64>,
    /// Anchor rows `lo .. hi` summed now, per filter (and for `vcol`).
    span: Vec<(usize, usize)>,
    /// `V_f` (then `ln V_f`) of the row's windows to fit, packed, with
    /// their output columns and valid counts, and their `(H, se)`.
    vrow: Vec<f64>,
    todo: Vec<(usize, f64)>,
    /// Per filter, the increment counts of the window and those of the
    /// row's interior windows (bands without holes).
    nbuf: Vec<f64>,
    nrow: Vec<f64>,
    hbuf: Vec<f64>,
    sebuf: Vec<f64>,
}

/// What [`gls_band`] reads: the image, the window grid, the filters and the
/// tables.
struct BandCtx<'a, T> {
    z: &'a [T],
    cols: usize,
    grid: &'a Grid,
    fl: &'a [Filter],
    k: usize,
    w: usize,
    full: f64,
    polys: &'a [[f64; 5]],
    sx: &'a [usize],
    opt: &'a GlsOptions,
    tab: &'a GlsTables,
}

/// [`gls_band`] compiled for AVX2 and FMA (the loops over columns and
/// filters vectorise 4 wide instead of 2).
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn gls_band_avx2<T: Sample>(
    cx: &BandCtx<'_, T>,
    sc: &mut GlsScratch,
    band: &Band,
    outs: &mut [&mut [f32]],
) {
    gls_band(cx, sc, band, outs)
}

/// The maps of one band of output rows (see [`gls_transform`]).
#[inline(always)]
fn gls_band<T: Sample>(
    cx: &BandCtx<'_, T>,
    sc: &mut GlsScratch,
    band: &Band,
    outs: &mut [&mut [f32]],
) {
    let BandCtx {
        z,
        cols,
        grid,
        fl,
        k,
        w,
        full,
        polys,
        sx,
        opt,
        tab,
    } = *cx;
    let nf = fl.len();
    let (ocols, min_pixels) = (grid.ocols, grid.min_pixels);
    let an = opt.anisotropy;
    let i0 = band.i0;
    let zb = &z[i0 * cols..band.i1 * cols];
    // a band of finite samples whose squares cannot overflow needs no
    // counts: every increment is valid
    let complete = zb.iter().all(|v| v.to_f64().abs() <= 1e100);
    let nc = if complete { 0 } else { nf + 1 };
    sc.hi.resize(nf * cols, 0.0);
    sc.lo.resize(nf * cols, 0.0);
    sc.cnt.resize(nf * cols, 0.0);
    sc.vcol.resize(cols, 0.0);
    sc.phi.resize((cols + 1) * nf, 0.0);
    sc.plo.resize((cols + 1) * nf, 0.0);
    sc.pcnt.resize((cols + 1) * (nf + 1), 0.0);
    sc.span.clear();
    sc.span.resize(nf + 1, (0, 0));
    sc.vrow.resize(ocols * nf, 0.0);
    sc.hbuf.resize(ocols, 0.0);
    sc.nbuf.resize(nf, 0.0);
    sc.nrow.resize(nf, 0.0);
    sc.sebuf.resize(ocols, 0.0);
    let GlsScratch {
        hi,
        lo,
        cnt,
        vcol,
        phi,
        plo,
        pcnt,
        span,
        vrow,
        todo,
        nbuf,
        nrow,
        hbuf,
        sebuf,
    } = sc;
    for g in band.g0..band.g1 {
        let (r0, r1) = grid.win_rows(band, g);
        // slide each filter's column sums to anchor rows r0 .. rr1
        for (fi, f) in fl.iter().enumerate() {
            let rr1 = r1.saturating_sub(f.span.0).max(r0);
            let (mut a, mut b) = span[fi];
            let (h, l) = (
                &mut hi[fi * cols..(fi + 1) * cols],
                &mut lo[fi * cols..(fi + 1) * cols],
            );
            let mut ct = (!complete).then(|| &mut cnt[fi * cols..(fi + 1) * cols]);
            if g == band.g0 || r0 >= b {
                // first row of the band, or no overlap: from scratch
                h.fill(0.0);
                l.fill(0.0);
                if let Some(c) = ct.as_deref_mut() {
                    c.fill(0.0);
                }
                (a, b) = (r0, r0);
            }
            // (a loop, not a closure: a closure would not be compiled with
            // the AVX2 features of `gls_band_avx2`)
            for (r, sign) in (b..rr1).map(|r| (r, 1.0)).chain((a..r0).map(|r| (r, -1.0))) {
                let c = ct.as_deref_mut();
                if f.n_taps == 2 {
                    slide_row::<T, 2>(zb, cols, r, f, sign, h, l, c);
                } else {
                    slide_row::<T, 3>(zb, cols, r, f, sign, h, l, c);
                }
            }
            span[fi] = (r0, rr1.max(b));
        }
        // valid samples per column in rows r0 .. r1 (exact: counts)
        if !complete {
            let (mut a, mut b) = span[nf];
            if g == band.g0 || r0 >= b {
                vcol.fill(0.0);
                (a, b) = (r0, r0);
            }
            for (r, sign) in (b..r1).map(|r| (r, 1.0)).chain((a..r0).map(|r| (r, -1.0))) {
                for (v, x) in vcol.iter_mut().zip(&zb[r * cols..(r + 1) * cols]) {
                    *v += if x.to_f64().is_nan() { 0.0 } else { sign };
                }
            }
            span[nf] = (r0, r1);
        }
        // prefix sums along the row, filter-interleaved
        prefix_sums(hi, lo, cols, nf, phi, plo);
        if !complete {
            pcnt[..nc].fill(0.0);
            for c in 0..cols {
                let (p, q) = (c * nc, (c + 1) * nc);
                for fi in 0..nf {
                    pcnt[q + fi] = pcnt[p + fi] + cnt[fi * cols + c];
                }
                pcnt[q + nf] = pcnt[p + nf] + vcol[c];
            }
        }
        // the windows of the row that pass the gates: their V_f packed
        // in `vrow` (`todo` their columns and valid counts), then ln and
        // the Gauss-Newton steps over all of them at once
        todo.clear();
        for (fi, f) in fl.iter().enumerate() {
            nrow[fi] = ((r1 - r0).saturating_sub(f.span.0) * (w - f.span.1)) as f64;
        }
        for q in 0..ocols {
            let (c0, c1) = grid.win_cols(q);
            let valid = if complete {
                ((r1 - r0) * (c1 - c0)) as f64
            } else {
                pcnt[c1 * nc + nf] - pcnt[c0 * nc + nf]
            };
            if valid < min_pixels {
                continue;
            }
            let j = todo.len();
            let ys = &mut vrow[j * nf..(j + 1) * nf];
            let ns = &mut nbuf[..nf];
            let jc = q * grid.step;
            if complete && jc >= grid.h && jc + grid.h < cols {
                // an interior window of a band without holes: the
                // increment counts are the row's, the taps of every
                // anchor column fit (w > span), cc1 = c1 - span
                let (x0, y0) = (c1 * nf, c0 * nf);
                for fi in 0..nf {
                    let (x, y) = (x0 + fi - sx[fi], y0 + fi);
                    ys[fi] = (phi[x] - phi[y]) + (plo[x] - plo[y]);
                }
                ns.copy_from_slice(&nrow[..nf]);
            } else {
                for (fi, f) in fl.iter().enumerate() {
                    let cc1 = c1.saturating_sub(f.span.1).max(c0);
                    let (x, y) = (cc1 * nf + fi, c0 * nf + fi);
                    ys[fi] = (phi[x] - phi[y]) + (plo[x] - plo[y]);
                    let rr1 = r1.saturating_sub(f.span.0).max(r0);
                    ns[fi] = if complete {
                        ((rr1 - r0) * (cc1 - c0)) as f64
                    } else {
                        pcnt[cc1 * nc + fi] - pcnt[c0 * nc + fi]
                    };
                }
            }
            // no valid increment, a zero variation, or one that
            // overflowed: not fitted
            let (mut fit, mut tiny) = (true, false);
            for (v, &n) in ys.iter_mut().zip(ns.iter()) {
                *v /= n;
                fit &= (n >= 0.5) & (*v > 0.0) & (*v < f64::INFINITY);
                tiny |= *v < f64::MIN_POSITIVE;
            }
            if !fit {
                continue;
            }
            if tiny {
                // a subnormal variation: the library ln, solved alone
                ln_in_place(ys);
                let (hh, se) = tab.solve_with(polys, ys, opt.steps);
                let kk = (g - band.g0) * ocols + q;
                outs[0][kk] = hh as f32;
                outs[1][kk] = (se * (full / valid).sqrt()) as f32;
                if an {
                    let (ang, rat) = anisotropy(&ys[..4 * k], k, hh);
                    outs[2][kk] = ang as f32;
                    outs[3][kk] = rat as f32;
                }
                continue;
            }
            todo.push((q, valid));
        }
        let nt = todo.len();
        let ys = &mut vrow[..nt * nf];
        ys.iter_mut().for_each(|x| *x = ln_normal(*x));
        tab.solve_batch(polys, ys, opt.steps, &mut hbuf[..nt], &mut sebuf[..nt]);
        for (j, &(q, valid)) in todo.iter().enumerate() {
            let (hh, se) = (hbuf[j], sebuf[j]);
            let kk = (g - band.g0) * ocols + q;
            outs[0][kk] = hh as f32;
            outs[1][kk] = (se * (full / valid).sqrt()) as f32;
            if an {
                let (ang, rat) = anisotropy(&ys[j * nf..j * nf + 4 * k], k, hh);
                outs[2][kk] = ang as f32;
                outs[3][kk] = rat as f32;
            }
        }
    }
}

/// Moving-window GLS Hurst exponent (see the module docs); NaN where the
/// window has too few valid pixels or a filter has no valid increment.
/// Maps: `d` the Hurst exponent, `r2` its standard error, `extra` the
/// anisotropy direction and ratio (empty unless asked).
///
/// Window sums of the squared increments slide down each band (the rows
/// entering the window added to per-column sums, the rows leaving taken
/// off, compensated so that no rounding accumulates), then prefix sums
/// along the output row (compensated too) give every window's sum: one
/// pass over the band per filter, no table of the band in memory. The
/// sums restart at each band, whose layout depends on the window and
/// `step` only, so the result does not depend on the thread count.
pub fn gls_transform<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    opt: &GlsOptions,
    tab: &GlsTables,
) -> CoreResult<MapOut> {
    gls_transform_on(z, rows, cols, opt, tab, true)
}

/// [`gls_transform`], on x86_64 with the band kernel compiled for AVX2 and
/// FMA when `allow_avx2` and the CPU has them. The arithmetic is the same
/// sequence of IEEE operations either way (Rust never fuses a multiply and
/// an add on its own), so the maps are equal bit for bit (tested).
fn gls_transform_on<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    opt: &GlsOptions,
    tab: &GlsTables,
    allow_avx2: bool,
) -> CoreResult<MapOut> {
    let w = opt.window;
    let grid = Grid::new(z.len(), rows, cols, w, opt.min_valid, opt.step)?;
    let k = opt.dilations;
    if k == 0 || 4 * k >= w {
        return Err(CoreError::invalid(
            "dilations",
            format!(
                "expected an int in [1, {}) for window {w}, got {k}",
                w.div_ceil(4)
            ),
        ));
    }
    let fl = filters(k);
    let nf = fl.len();
    tab.check(nf)?;
    let full = (w * w) as f64;
    let polys = tab.step_polys(nf);
    // per filter, its column span times nf (offset of its window sums' end)
    let sx: Vec<usize> = fl.iter().map(|f| f.span.1 * nf).collect();
    let an = opt.anisotropy;
    let cx = BandCtx {
        z,
        cols,
        grid: &grid,
        fl: &fl,
        k,
        w,
        full,
        polys: &polys,
        sx: &sx,
        opt,
        tab,
    };
    #[cfg(target_arch = "x86_64")]
    let avx2 = allow_avx2 && is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = {
        let _ = allow_avx2;
        false
    };
    let maps = grid.drive(&[true, true, an, an], |sc: &mut GlsScratch, band, outs| {
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            // SAFETY: the CPU has AVX2 and FMA (checked above)
            unsafe { gls_band_avx2(&cx, sc, band, outs) };
            return;
        }
        gls_band(&cx, sc, band, outs);
    })?;
    Ok(grid.map_out(maps))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toy_tables(k: usize) -> GlsTables {
        // a = 2 H ln(step length) (first differences' exact law, all filters
        // treated alike), g the OLS row: any tables with g . 1 = 0 will do
        let fl = filters(k);
        let n_h = 5;
        let nf = fl.len();
        let len = |f: &Filter| {
            let (r, c) = (
                f.taps[1].0 as f64 - f.taps[0].0 as f64,
                f.taps[1].1 as f64 - f.taps[0].1 as f64,
            );
            (r * r + c * c).sqrt().ln()
        };
        let x: Vec<f64> = fl.iter().map(len).collect();
        let xm = x.iter().sum::<f64>() / nf as f64;
        let sxx: f64 = x.iter().map(|v| (v - xm) * (v - xm)).sum();
        let mut t = GlsTables {
            h0: 0.1,
            dh: 0.2,
            n_h,
            a: vec![],
            da: vec![],
            g: vec![],
            se: vec![0.01; n_h],
        };
        for i in 0..n_h {
            let hh = 0.1 + 0.2 * i as f64;
            for &xv in &x {
                t.a.push(2.0 * hh * xv);
                t.da.push(2.0 * xv);
                t.g.push((xv - xm) / sxx / 2.0);
            }
        }
        t
    }

    #[test]
    fn fast_steps_equal_the_interpolated_steps() {
        let tab = toy_tables(2);
        let polys = tab.step_polys(16);
        for t in 0..50 {
            let ys: Vec<f64> = (0..16)
                .map(|f| ((f * 7 + t * 3) % 11) as f64 * 0.1 - 0.4)
                .collect();
            let (a, b) = (tab.solve(&ys, 4), tab.solve_with(&polys, &ys, 4));
            assert!(
                (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12,
                "{a:?} {b:?}"
            );
        }
    }

    #[test]
    fn threads_step_and_holes() {
        let (rows, cols) = (90usize, 70usize);
        let mut z: Vec<f64> = crate::testdata::uniform(rows * cols, 9);
        for k in (0..z.len()).step_by(53) {
            z[k] = f64::NAN;
        }
        let tab = toy_tables(2);
        let opt = GlsOptions {
            window: 15,
            dilations: 2,
            steps: 3,
            min_valid: 0.5,
            step: 1,
            anisotropy: true,
        };
        let run = |t, o: &GlsOptions| {
            crate::parallel::run_in_pool(Some(t), || gls_transform(&z, rows, cols, o, &tab))
                .unwrap()
        };
        let a = run(1, &opt);
        let b = run(3, &opt);
        assert_eq!(
            a.d.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            b.d.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert!(a.d[40 * cols + 30].is_finite() && a.extra[0][40 * cols + 30].is_finite());
        for step in [2usize, 5] {
            let g = run(
                2,
                &GlsOptions {
                    step,
                    anisotropy: false,
                    ..opt.clone()
                },
            );
            assert!(g.extra[0].is_empty());
            let ocols = cols.div_ceil(step);
            for gi in 0..rows.div_ceil(step) {
                for gj in 0..ocols {
                    let (x, y) = (g.d[gi * ocols + gj], a.d[gi * step * cols + gj * step]);
                    assert!(
                        (x.is_nan() && y.is_nan()) || (x - y).abs() < 1e-6,
                        "step {step}"
                    );
                }
            }
        }
        assert!(gls_transform(
            &z,
            rows,
            cols,
            &GlsOptions {
                dilations: 4,
                ..opt.clone()
            },
            &tab
        )
        .is_err());
    }

    #[test]
    fn avx2_and_baseline_kernels_are_equal_bit_for_bit() {
        // float32 and float64 images, with and without holes (the counted
        // and the complete paths), anisotropy on: every map equal bit for bit
        let (rows, cols) = (75usize, 83usize);
        let z: Vec<f64> = crate::testdata::uniform(rows * cols, 4)
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.01 * (i % cols) as f64)
            .collect();
        let mut zh = z.clone();
        for k in (0..zh.len()).step_by(41) {
            zh[k] = f64::NAN;
        }
        let tab = toy_tables(2);
        let opt = GlsOptions {
            window: 17,
            dilations: 2,
            steps: 4,
            min_valid: 0.5,
            step: 1,
            anisotropy: true,
        };
        let bits = |m: &MapOut| {
            std::iter::once(&m.d)
                .chain(std::iter::once(&m.r2))
                .chain(m.extra.iter())
                .flat_map(|v| v.iter().map(|x| x.to_bits()))
                .collect::<Vec<_>>()
        };
        for img in [&z, &zh] {
            let a = gls_transform_on(img, rows, cols, &opt, &tab, false).unwrap();
            let b = gls_transform_on(img, rows, cols, &opt, &tab, true).unwrap();
            assert!(a.d.iter().filter(|v| v.is_finite()).count() > rows * cols / 2);
            assert_eq!(bits(&a), bits(&b));
            let z32: Vec<f32> = img.iter().map(|&v| v as f32).collect();
            let a = gls_transform_on(&z32, rows, cols, &opt, &tab, false).unwrap();
            let b = gls_transform_on(&z32, rows, cols, &opt, &tab, true).unwrap();
            assert_eq!(bits(&a), bits(&b));
        }
    }

    #[test]
    fn isotropic_quadratic_variations_have_ratio_one_and_a_stretch_is_found() {
        let k = 2;
        // y for first-order filters of |A h|^(2H) with M = diag(4, 1): rows
        // (m_cc = 1), columns (m_rr = 4): fastest variation along the rows' axis
        let h = 0.6;
        let m = [[4.0, 0.0], [0.0, 1.0]];
        let mut ys = vec![];
        for &(er, ec) in &DIRS {
            for u in 1..=k {
                let (r, c) = ((er * u as isize) as f64, (ec * u as isize) as f64);
                let q = m[0][0] * r * r + 2.0 * m[0][1] * r * c + m[1][1] * c * c;
                ys.push(h * q.ln());
            }
        }
        let (ang, ratio) = anisotropy(&ys, k, h);
        assert!(
            (ratio - 2.0).abs() < 1e-9 && (ang - 90.0).abs() < 1e-9,
            "{ang} {ratio}"
        );
    }

    /// `ln V_f` of one window from the definition (clipped window, taps
    /// inside it, increments touching NaN left out).
    fn direct_ys(
        z: &[f64],
        rows: usize,
        cols: usize,
        i: usize,
        j: usize,
        w: usize,
        k: usize,
    ) -> Option<Vec<f64>> {
        let h = w / 2;
        let (r0, r1) = (i.saturating_sub(h), (i + h + 1).min(rows));
        let (c0, c1) = (j.saturating_sub(h), (j + h + 1).min(cols));
        let mut ys = vec![];
        for f in filters(k) {
            let (mut s, mut n) = (0.0f64, 0.0f64);
            for r in r0..r1 {
                for c in c0..c1 {
                    if r + f.span.0 >= r1 || c + f.span.1 >= c1 {
                        continue;
                    }
                    let d: f64 = f.taps[..f.n_taps]
                        .iter()
                        .map(|&(dr, dc, wt)| wt * z[(r + dr) * cols + c + dc])
                        .sum();
                    if !d.is_nan() {
                        s += d * d;
                        n += 1.0;
                    }
                }
            }
            if n < 0.5 || s <= 0.0 {
                return None;
            }
            ys.push((s / n).ln());
        }
        Some(ys)
    }

    #[test]
    fn sliding_sums_equal_direct_window_sums_with_holes_edges_and_a_spike() {
        let (rows, cols, w, k) = (150usize, 61usize, 15usize, 2usize);
        let mut z: Vec<f64> = crate::testdata::uniform(rows * cols, 11);
        // a spike 1e9 times the background: windows it has left must not
        // keep its rounding; and missing samples
        z[40 * cols + 30] = 1e9;
        for q in (0..z.len()).step_by(97) {
            z[q] = f64::NAN;
        }
        let tab = toy_tables(k);
        let polys = tab.step_polys(8 * k);
        for step in [1usize, 4] {
            let opt = GlsOptions {
                window: w,
                dilations: k,
                steps: 3,
                min_valid: 0.0,
                step,
                anisotropy: false,
            };
            let m = gls_transform(&z, rows, cols, &opt, &tab).unwrap();
            let ocols = cols.div_ceil(step);
            let mut checked = 0;
            for gi in 0..rows.div_ceil(step) {
                for gj in 0..ocols {
                    let got = m.d[gi * ocols + gj];
                    match direct_ys(&z, rows, cols, gi * step, gj * step, w, k) {
                        None => assert!(got.is_nan()),
                        Some(ys) => {
                            let (want, _) = tab.solve_with(&polys, &ys, 3);
                            assert!(
                                (got as f64 - want).abs() < 1e-6,
                                "step {step} ({gi},{gj}) {got} {want}"
                            );
                            checked += 1;
                        }
                    }
                }
            }
            assert!(checked > 100);
        }
    }

    #[test]
    fn batched_steps_equal_single_steps_bit_for_bit() {
        let tab = toy_tables(2);
        let polys = tab.step_polys(16);
        // 21 windows (two full batches and a partial one), spread over H
        let n = 21;
        // y = 2 H ln|step| (the toy law) for H from 0.1 to 0.9, perturbed
        let x: Vec<f64> = filters(2)
            .iter()
            .map(|f| {
                let (r, c) = (
                    f.taps[1].0 as f64 - f.taps[0].0 as f64,
                    f.taps[1].1 as f64 - f.taps[0].1 as f64,
                );
                (r * r + c * c).sqrt().ln()
            })
            .collect();
        let ys: Vec<f64> = (0..n * 16)
            .map(|v| {
                let h = 0.1 + 0.04 * (v / 16) as f64;
                2.0 * h * x[v % 16] + ((v * 7) % 5) as f64 * 0.01
            })
            .collect();
        let (mut hs, mut ses) = (vec![0.0; n], vec![0.0; n]);
        tab.solve_batch(&polys, &ys, 4, &mut hs, &mut ses);
        let mut distinct = std::collections::BTreeSet::new();
        for j in 0..n {
            let (h, se) = tab.solve_with(&polys, &ys[j * 16..(j + 1) * 16], 4);
            assert_eq!(
                (h.to_bits(), se.to_bits()),
                (hs[j].to_bits(), ses[j].to_bits())
            );
            distinct.insert(h.to_bits());
        }
        assert!(distinct.len() > 5);
    }

    #[test]
    fn prefix_sums_equal_the_scalar_compensated_sums() {
        let cols = 37;
        for nf in [16usize, 5] {
            let hi = crate::testdata::uniform(nf * cols, 3);
            let lo: Vec<f64> = crate::testdata::uniform(nf * cols, 4)
                .iter()
                .map(|v| v * 1e-17)
                .collect();
            let (mut phi, mut plo) = (vec![1.0; (cols + 1) * nf], vec![1.0; (cols + 1) * nf]);
            prefix_sums(&hi, &lo, cols, nf, &mut phi, &mut plo);
            for fi in 0..nf {
                let (mut ph, mut pl) = (0.0, 0.0);
                for c in 0..cols {
                    add2(&mut ph, &mut pl, hi[fi * cols + c]);
                    add2(&mut ph, &mut pl, lo[fi * cols + c]);
                    let q = (c + 1) * nf + fi;
                    assert_eq!(
                        (phi[q].to_bits(), plo[q].to_bits()),
                        (ph.to_bits(), pl.to_bits())
                    );
                }
                assert_eq!((phi[fi], plo[fi]), (0.0, 0.0));
            }
        }
    }
}
