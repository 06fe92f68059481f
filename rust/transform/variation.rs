//! Moving-window increment estimators of surface dimension.
//!
//! For each pixel the window is the `w x w` square centred on it, clipped to
//! the image (equivalently: the image padded with NaN). Inside the window,
//! `V(u)` is half the mean of `|increment|^p` over the valid increments at
//! dilation `u` that lie entirely in the window:
//!
//! * first differences (`z(r, c+u) - z(r, c)` and `z(r+u, c) - z(r, c)`,
//!   pooled), or
//! * square increments (`z(r+u, c+u) - z(r+u, c) - z(r, c+u) + z(r, c)`),
//!
//! and `D = 3 - slope / p` with `slope` the least-squares slope of `log V(u)`
//! against `log u`. Sums over windows come from summed-area tables of the
//! increment powers and counts, built per band of rows at fixed positions,
//! so the cost per pixel is independent of `w` and the result does not
//! depend on the thread count.
use super::driver::{scale_list, valid_sat, Grid, LogFit, MapOut};
use super::sat::{rect, sats_into};
use crate::checks::positive_finite;
use crate::error::CoreResult;
use crate::sample::Sample;

/// Which increments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Increments {
    First,
    Square,
}

/// Options of [`variation_transform`].
#[derive(Debug, Clone)]
pub struct VariationOptions {
    pub window: usize,
    pub lags: Vec<usize>,
    pub p: f64,
    pub increments: Increments,
    /// Fewest valid pixels in a window, as a fraction of `w * w`.
    pub min_valid: f64,
    /// Output every `step`-th pixel of every `step`-th row (1: all).
    pub step: usize,
}

/// Local dimension and r² maps (row-major, NaN where the window has too few
/// valid pixels or a lag has no valid increment) on the grid of every
/// `step`-th pixel: `ceil(rows / step) x ceil(cols / step)`.
pub fn variation_transform<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    opt: &VariationOptions,
) -> CoreResult<MapOut> {
    let p = positive_finite(opt.p, "p")?;
    let grid = Grid::new(z.len(), rows, cols, opt.window, opt.min_valid, opt.step)?;
    let w = grid.w;
    let lags = scale_list(&opt.lags, "lags", 2, &format!("lags in [1, {w})"), |l| {
        l > 0 && l < w
    })?;
    let fit = LogFit::new(&lags, |slope| 3.0 - slope / p);
    let power = move |d: f64| -> f64 {
        if p == 2.0 {
            d * d
        } else if p == 1.0 {
            d.abs()
        } else {
            d.abs().powf(p)
        }
    };
    // the components (row and column offsets) of each lag's increments
    let comps: Vec<Vec<(usize, usize)>> = lags
        .iter()
        .map(|&u| match opt.increments {
            Increments::First => vec![(0, u), (u, 0)],
            Increments::Square => vec![(u, u)],
        })
        .collect();
    // per-thread tables, reused from band to band (fresh ones would be
    // page-faulted and zeroed by the OS for every band)
    #[derive(Default)]
    struct Scratch {
        vsat: Vec<f64>,
        tables: Vec<Vec<(Vec<f64>, Vec<f64>)>>,
    }
    grid.drive_pair(|sc: &mut Scratch, band, outs| {
        let (i0, nr) = (band.i0, band.nr());
        let sw = cols + 1;
        let get = |r: usize, c: usize| z[(i0 + r) * cols + c].to_f64();
        valid_sat(&mut sc.vsat, band, cols, get);
        // per lag and component: (power SAT, count SAT) of the increments
        // anchored at (r, c); 0 where the increment leaves the band or is NaN
        sc.tables.resize_with(lags.len(), Vec::new);
        for ((t, cs), &u) in sc.tables.iter_mut().zip(&comps).zip(&lags) {
            t.resize_with(cs.len(), Default::default);
            for ((ps, ct), &(du_r, du_c)) in t.iter_mut().zip(cs) {
                let inc = |r: usize, c: usize| -> f64 {
                    if r + du_r >= nr || c + du_c >= cols {
                        return f64::NAN;
                    }
                    match opt.increments {
                        Increments::First => get(r + du_r, c + du_c) - get(r, c),
                        Increments::Square => {
                            get(r + u, c + u) - get(r + u, c) - get(r, c + u) + get(r, c)
                        }
                    }
                };
                // power and count of each increment, computed once
                sats_into([ps, ct], nr, cols, |r, c| {
                    let d = inc(r, c);
                    if d.is_nan() {
                        [0.0, 0.0]
                    } else {
                        [power(d), 1.0]
                    }
                });
            }
        }
        let (vsat, tables) = (&sc.vsat, &sc.tables);
        let mut ys = vec![0.0f64; lags.len()];
        grid.valid_windows(band, vsat, |k, r0, r1, c0, c1, _| {
            // per lag, the (power, count) tables of each component
            for (li, (t, offs)) in tables.iter().zip(&comps).enumerate() {
                let (mut sp, mut sc) = (0.0, 0.0);
                for ((ps, cs), &(du_r, du_c)) in t.iter().zip(offs) {
                    // anchors whose partner lies in the window too
                    let rr1 = r1.saturating_sub(du_r);
                    let cc1 = c1.saturating_sub(du_c);
                    sp += rect(ps, sw, r0, rr1, c0, cc1);
                    sc += rect(cs, sw, r0, rr1, c0, cc1);
                }
                // counts are sums of ones: exact in f64
                if sc < 0.5 || sp <= 0.0 {
                    return;
                }
                ys[li] = (sp / sc / 2.0).ln();
            }
            fit.write(&ys, outs, k);
        });
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per-window estimator from the definition (NaN padding at the edges).
    fn direct(
        z: &[f64],
        rows: usize,
        cols: usize,
        i: usize,
        j: usize,
        opt: &VariationOptions,
    ) -> f64 {
        let h = opt.window as isize / 2;
        let at = |r: isize, c: isize| -> f64 {
            if r < i as isize - h || r > i as isize + h || c < j as isize - h || c > j as isize + h
            {
                return f64::NAN;
            }
            if r < 0 || c < 0 || r >= rows as isize || c >= cols as isize {
                return f64::NAN;
            }
            z[r as usize * cols + c as usize]
        };
        let mut pts = vec![];
        for &u in &opt.lags {
            let u = u as isize;
            let (mut s, mut n) = (0.0, 0.0);
            for r in (i as isize - h)..=(i as isize + h) {
                for c in (j as isize - h)..=(j as isize + h) {
                    let ds: Vec<f64> = match opt.increments {
                        Increments::First => vec![at(r, c + u) - at(r, c), at(r + u, c) - at(r, c)],
                        Increments::Square => {
                            vec![at(r + u, c + u) - at(r + u, c) - at(r, c + u) + at(r, c)]
                        }
                    };
                    for d in ds {
                        if !d.is_nan() {
                            s += d.abs().powf(opt.p);
                            n += 1.0;
                        }
                    }
                }
            }
            pts.push(((u as f64).ln(), (s / n / 2.0).ln()));
        }
        let xm = pts.iter().map(|p| p.0).sum::<f64>() / pts.len() as f64;
        let ym = pts.iter().map(|p| p.1).sum::<f64>() / pts.len() as f64;
        let sxy: f64 = pts.iter().map(|p| (p.0 - xm) * (p.1 - ym)).sum();
        let sxx: f64 = pts.iter().map(|p| (p.0 - xm).powi(2)).sum();
        3.0 - sxy / sxx / opt.p
    }

    #[test]
    fn equals_direct_window_sums_with_holes_and_edges() {
        let (rows, cols) = (70usize, 45usize);
        let mut z: Vec<f64> = crate::testdata::uniform(rows * cols, 5);
        for k in (0..z.len()).step_by(37) {
            z[k] = f64::NAN;
        }
        for inc in [Increments::First, Increments::Square] {
            let opt = VariationOptions {
                window: 9,
                lags: vec![1, 2, 3],
                p: 2.0,
                increments: inc,
                min_valid: 0.0,
                step: 1,
            };
            let d = variation_transform(&z, rows, cols, &opt).unwrap().d;
            for &(i, j) in &[
                (0usize, 0usize),
                (3, 40),
                (35, 22),
                (69, 44),
                (64, 1),
                (63, 20),
            ] {
                let e = direct(&z, rows, cols, i, j, &opt);
                assert!(
                    (d[i * cols + j] as f64 - e).abs() < 1e-5,
                    "{inc:?} ({i},{j}) {} vs {e}",
                    d[i * cols + j]
                );
            }
        }
    }

    #[test]
    fn plane_is_two_and_threads_agree() {
        let (rows, cols) = (130usize, 90usize);
        let z: Vec<f64> = (0..rows * cols)
            .map(|k| 0.3 * (k / cols) as f64 + 0.7 * (k % cols) as f64)
            .collect();
        let opt = VariationOptions {
            window: 11,
            lags: vec![1, 2],
            p: 2.0,
            increments: Increments::First,
            min_valid: 0.5,
            step: 1,
        };
        let run = |t| {
            crate::parallel::run_in_pool(Some(t), || variation_transform(&z, rows, cols, &opt))
                .unwrap()
        };
        let a = run(1).d;
        // interior (full windows): exactly a plane's D = 2; at the edges the
        // clipped window pools unequal numbers of row and column increments
        for i in 5..rows - 5 {
            for j in 5..cols - 5 {
                assert!(
                    (a[i * cols + j] - 2.0).abs() < 1e-5,
                    "({i},{j}) {}",
                    a[i * cols + j]
                );
            }
        }
        // a corner window holds 6 x 6 = 36 pixels, fewer than half of 11 x 11
        assert!(a[0].is_nan() && a[cols + 5].is_finite());
        let bits = |m: MapOut| -> Vec<(u32, u32)> {
            m.d.iter()
                .zip(&m.r2)
                .map(|(a, b)| (a.to_bits(), b.to_bits()))
                .collect()
        };
        assert!(
            bits(run(1)) == bits(run(3)),
            "results differ between 1 and 3 threads"
        );
        // the step grid is the full map's every step-th pixel (sums of the
        // same tables, from other band origins: equal to rounding)
        for step in [2usize, 3, 7] {
            let g = variation_transform(
                &z,
                rows,
                cols,
                &VariationOptions {
                    step,
                    ..opt.clone()
                },
            )
            .unwrap()
            .d;
            let (orows, ocols) = (rows.div_ceil(step), cols.div_ceil(step));
            assert_eq!(g.len(), orows * ocols);
            for gi in 0..orows {
                for gj in 0..ocols {
                    let (x, y) = (g[gi * ocols + gj], a[gi * step * cols + gj * step]);
                    assert!(
                        x == y || (x - y).abs() < 1e-6 || (x.is_nan() && y.is_nan()),
                        "step {step}"
                    );
                }
            }
        }
        assert!(variation_transform(
            &z,
            rows,
            cols,
            &VariationOptions {
                step: 0,
                ..opt.clone()
            }
        )
        .is_err());
        assert!(variation_transform(
            &z,
            rows,
            cols,
            &VariationOptions {
                window: 10,
                ..opt.clone()
            }
        )
        .is_err());
        assert!(variation_transform(
            &z,
            rows,
            cols,
            &VariationOptions {
                lags: vec![1],
                ..opt.clone()
            }
        )
        .is_err());
    }
}
