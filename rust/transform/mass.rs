//! Moving-window P(m, L) mass dimension (Voss 1986; the paper's eq. 13 and
//! its SAR fractal transform, section 4.2).
//!
//! The image is the point set `(i, j, z / z_scale)`. For a box side
//! `L = 2k + 1` (pixels) centred on pixel `p`, `m_p(L)` is the number of valid
//! pixels `q` of the *image* with `|i_q - i_p| <= k`, `|j_q - j_p| <= k` and
//! `|z_q - z_p| <= L z_scale / 2` (so `m_p >= 1`). The value of a window is
//!
//! ```text
//! N(L) = mean over the window's valid pixels p of 1 / m_p(L)   (= sum_m P(m, L) / m)
//! D    = -slope of log N(L) against log L
//! ```
//!
//! Boxes count every pixel of the image, not only those of the window, so a
//! point's mass does not depend on where the analysis window sits and the
//! window sums come from summed-area tables: the cost per pixel is the box
//! neighbourhood (`L_max^2`), independent of the window. The box masses and
//! the image-wide curve are in `crate::dimension::mass`.
use super::driver::{scale_list, valid_sat, Grid, LogFit, MapOut};
use super::sat::{rect, sat_into};
use crate::checks::positive_finite;
use crate::dimension::mass::{box_masses_into, Band, MassBuf};
use crate::error::CoreResult;
use crate::sample::Sample;

/// Options of [`mass_transform`].
#[derive(Debug, Clone)]
pub struct MassOptions {
    pub window: usize,
    /// Odd box sides, ascending, at least two.
    pub box_sizes: Vec<usize>,
    pub z_scale: f64,
    pub min_valid: f64,
    /// Output every `step`-th pixel of every `step`-th row (1: all).
    pub step: usize,
}

/// Local P(m, L) dimension and r² maps (row-major; NaN where the window has
/// fewer valid pixels than `min_valid * w * w`), on the grid of every
/// `step`-th pixel: `ceil(rows / step) x ceil(cols / step)`.
pub fn mass_transform<T: Sample>(
    z: &[T],
    rows: usize,
    cols: usize,
    opt: &MassOptions,
) -> CoreResult<MapOut> {
    let grid = Grid::new(z.len(), rows, cols, opt.window, opt.min_valid, opt.step)?;
    let w = grid.w;
    let odd_side = |l| l >= 3 && l % 2 == 1 && l <= w;
    let sizes = scale_list(
        &opt.box_sizes,
        "box_sizes",
        2,
        &format!("odd box sides in [3, {w}]"),
        odd_side,
    )?;
    positive_finite(opt.z_scale, "z_scale")?;
    let ks: Vec<usize> = sizes.iter().map(|l| l / 2).collect();
    let fit = LogFit::new(&sizes, |slope| -slope);
    // per-thread buffers, reused from band to band (fresh ones would be
    // page-faulted and zeroed by the OS for every band)
    #[derive(Default)]
    struct Scratch {
        masses: MassBuf,
        vsat: Vec<f64>,
        isats: Vec<Vec<f64>>,
    }
    grid.drive_pair(|sc: &mut Scratch, band, outs| {
        let (i0, i1, nr) = (band.i0, band.i1, band.nr());
        let sw = cols + 1;
        let Scratch {
            masses,
            vsat,
            isats,
        } = sc;
        let job = Band {
            z,
            rows,
            cols,
            r0: i0,
            r1: i1,
            ks: &ks,
            z_scale: opt.z_scale,
        };
        box_masses_into(&job, masses);
        let masses = &masses.planes;
        valid_sat(vsat, band, cols, |r, c| z[(i0 + r) * cols + c].to_f64());
        isats.resize_with(masses.len(), Vec::new);
        for (s, m) in isats.iter_mut().zip(masses.iter()) {
            sat_into(s, nr, cols, |r, c| {
                let v = m[r * cols + c];
                if v > 0.0 {
                    1.0 / v
                } else {
                    0.0
                }
            });
        }
        let (vsat, isats) = (&*vsat, &*isats);
        let mut ys = vec![0.0f64; sizes.len()];
        grid.valid_windows(band, vsat, |k, r0, r1, c0, c1, n| {
            for (l, s) in isats.iter().enumerate() {
                ys[l] = (rect(s, sw, r0, r1, c0, c1) / n).ln();
            }
            fit.write(&ys, outs, k);
        });
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_image_is_two() {
        // all heights equal: m_p(L) = L^2 inside, N(L) = 1/L^2, D = 2
        let (rows, cols) = (60usize, 50usize);
        let z = vec![3.0f64; rows * cols];
        let opt = MassOptions {
            window: 15,
            box_sizes: vec![3, 5, 7],
            z_scale: 1.0,
            min_valid: 0.5,
            step: 1,
        };
        let d = mass_transform(&z, rows, cols, &opt).unwrap().d;
        // windows whose boxes stay inside the image
        for i in 10..rows - 10 {
            for j in 10..cols - 10 {
                assert!((d[i * cols + j] - 2.0).abs() < 1e-5);
            }
        }
    }
}
