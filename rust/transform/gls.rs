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
use super::driver::{valid_sat, Grid, MapOut};
use super::sat::{rect, sat_into, sats_into};
use crate::dimension::dbc::Sample;
use crate::error::{CoreError, CoreResult};

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
        let i = x.floor().clamp(0.0, (self.n_h - 2) as f64) as usize;
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
        for _ in 0..steps {
            let (i, s) = self.locate(h);
            let (g0, g1) = (
                &self.g[i * k..(i + 1) * k],
                &self.g[(i + 1) * k..(i + 2) * k],
            );
            let (mut y0, mut y1) = (0.0, 0.0);
            for f in 0..k {
                y0 += g0[f] * ys[f];
                y1 += g1[f] * ys[f];
            }
            let c = &polys[i];
            let ga = c[0] + s * (c[1] + s * (c[2] + s * (c[3] + s * c[4])));
            h = (h + (1.0 - s) * y0 + s * y1 - ga).clamp(self.h0, hi);
        }
        let (i, s) = self.locate(h);
        (h, (1.0 - s) * self.se[i] + s * self.se[i + 1])
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

/// `ln` of positive finite values in place: a polynomial (atanh series to
/// `s^13`, relative error below 1e-10) the compiler vectorises, with the
/// library `ln` for the rare subnormal values.
fn ln_in_place(v: &mut [f64]) {
    const SQRT2: f64 = std::f64::consts::SQRT_2;
    const LN2: f64 = std::f64::consts::LN_2;
    if v.iter().any(|&x| x < f64::MIN_POSITIVE) {
        v.iter_mut().for_each(|x| *x = x.ln());
        return;
    }
    for x in v.iter_mut() {
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
        *x = e as f64 * LN2 + 2.0 * s * p;
    }
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

/// Moving-window GLS Hurst exponent (see the module docs); NaN where the
/// window has too few valid pixels or a filter has no valid increment.
/// Maps: `d` the Hurst exponent, `r2` its standard error, `extra` the
/// anisotropy direction and ratio (empty unless asked).
pub fn gls_transform<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    opt: &GlsOptions,
    tab: &GlsTables,
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
    let (ocols, min_pixels) = (grid.ocols, grid.min_pixels);
    let full = (w * w) as f64;
    let polys = tab.step_polys(nf);
    #[derive(Default)]
    struct Scratch {
        vsat: Vec<f64>,
        power: Vec<Vec<f64>>,
        count: Vec<Vec<f64>>,
    }
    let an = opt.anisotropy;
    let mut maps = grid.drive(&[true, true, an, an], |sc: &mut Scratch, band, outs| {
        let (i0, nr) = (band.i0, band.nr());
        let sw = cols + 1;
        let get = |r: usize, c: usize| z[(i0 + r) * cols + c].to_f64();
        valid_sat(&mut sc.vsat, band, cols, get);
        // a band without missing samples needs no count tables
        let complete = sc.vsat[nr * sw + cols] == (nr * cols) as f64;
        sc.power.resize_with(nf, Vec::new);
        sc.count.resize_with(nf, Vec::new);
        for (fi, f) in fl.iter().enumerate() {
            let inc = |r: usize, c: usize| -> f64 {
                if r + f.span.0 >= nr || c + f.span.1 >= cols {
                    return f64::NAN;
                }
                let mut d = 0.0;
                for &(dr, dc, wt) in &f.taps[..f.n_taps] {
                    d += wt * get(r + dr, c + dc);
                }
                d
            };
            if complete {
                sat_into(&mut sc.power[fi], nr, cols, |r, c| {
                    let d = inc(r, c);
                    if d.is_nan() {
                        0.0
                    } else {
                        d * d
                    }
                });
            } else {
                let (p, n) = (&mut sc.power[fi], &mut sc.count[fi]);
                sats_into([p, n], nr, cols, |r, c| {
                    let d = inc(r, c);
                    if d.is_nan() {
                        [0.0, 0.0]
                    } else {
                        [d * d, 1.0]
                    }
                });
            }
        }
        // one output row at a time, filter by filter (sequential reads of
        // each table), then the fit per pixel: vrow[q * nf + fi] = V_f,
        // 0 where the window is skipped or the filter has no valid increment
        let mut vrow = vec![0.0f64; ocols * nf];
        let mut validrow = vec![0.0f64; ocols];
        for g in band.g0..band.g1 {
            let (r0, r1) = grid.win_rows(band, g);
            for (q, v) in validrow.iter_mut().enumerate() {
                let (c0, c1) = grid.win_cols(q);
                *v = rect(&sc.vsat, sw, r0, r1, c0, c1);
            }
            for (fi, f) in fl.iter().enumerate() {
                let rr1 = r1.saturating_sub(f.span.0);
                let (ps, cs) = (&sc.power[fi], &sc.count[fi]);
                for q in 0..ocols {
                    let (c0, c1) = grid.win_cols(q);
                    let cc1 = c1.saturating_sub(f.span.1);
                    let sp = rect(ps, sw, r0, rr1, c0, cc1);
                    let n = if complete {
                        (rr1.saturating_sub(r0) * cc1.saturating_sub(c0)) as f64
                    } else {
                        rect(cs, sw, r0, rr1, c0, cc1)
                    };
                    // no valid increment, a zero variation, or one
                    // that overflowed (inf samples): not fitted
                    let v = sp / n;
                    vrow[q * nf + fi] = if n >= 0.5 && v > 0.0 && v.is_finite() {
                        v
                    } else {
                        0.0
                    };
                }
            }
            for q in 0..ocols {
                let kk = (g - band.g0) * ocols + q;
                let valid = validrow[q];
                let ys = &mut vrow[q * nf..(q + 1) * nf];
                if valid < min_pixels || ys.contains(&0.0) {
                    continue;
                }
                ln_in_place(ys);
                let (hh, se) = tab.solve_with(&polys, ys, opt.steps);
                outs[0][kk] = hh as f32;
                outs[1][kk] = (se * (full / valid).sqrt()) as f32;
                if an {
                    let (ang, rat) = anisotropy(&ys[..4 * k], k, hh);
                    outs[2][kk] = ang as f32;
                    outs[3][kk] = rat as f32;
                }
            }
        }
    })?;
    let extra = maps.split_off(2);
    let r2 = maps.pop().unwrap_or_default();
    let d = maps.pop().unwrap_or_default();
    Ok(MapOut {
        rows: grid.orows,
        cols: grid.ocols,
        d,
        r2,
        extra,
    })
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
        let mut seed = 9u64;
        let mut z: Vec<f64> = (0..rows * cols)
            .map(|_| {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64
            })
            .collect();
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
}
