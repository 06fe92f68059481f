//! Synthesis of fractional Brownian motion and fractal surfaces.
//!
//! * [`rng`]: the counter-based generator (a sample is a pure function of
//!   `(seed, stream, index)`), used by every method; it is the crate-level
//!   service `crate::rng`, re-exported here;
//! * [`midpoint`]: random midpoint displacement and Voss's random additions as
//!   factor-2 refinement kernels in 1D and 2D (diamond-square);
//! * [`additions`]: successive random additions with 4-point interpolation
//!   and variances balanced against creases (2D `"additions"`);
//! * [`davies_harte`]: exact 1D fBm by circulant embedding with real FFTs;
//! * [`spectral`]: the amplitude filter of 2D spectral synthesis (aliased
//!   fBm density with a low-frequency compensation).
//!
//! Stein's 2D circulant embedding and the FFTs of spectral synthesis run on
//! the Python side with `scipy.fft` on noise and filters computed here.
pub mod additions;
pub mod davies_harte;
pub mod midpoint;
pub mod spectral;

pub use crate::rng;

use crate::error::{CoreError, CoreResult};
use crate::rng::StreamKey;
use ndarray::{ArrayView2, CowArray, Ix2};

/// The stream key of `phase` of refinement `level` of a kernel whose streams
/// start at `base` (eight phases per level).
pub(crate) fn level_key(seed: u64, base: u64, level: u32, phase: u64) -> StreamKey {
    StreamKey::new(seed, base + (level as u64) * 8 + phase)
}

/// The checks every refinement level shares: `hurst` in (0, 1), `sigma`
/// finite and `>= 0`, `coarse_spacing` positive and finite.
pub(crate) fn check_level(hurst: f64, sigma: f64, coarse_spacing: f64) -> CoreResult<()> {
    if !(hurst > 0.0 && hurst < 1.0) {
        return Err(CoreError::invalid(
            "hurst",
            format!("expected a number in (0, 1), got {hurst}"),
        ));
    }
    if !(sigma.is_finite() && sigma >= 0.0) {
        return Err(CoreError::invalid(
            "sigma",
            format!("expected a finite number >= 0, got {sigma}"),
        ));
    }
    if !(coarse_spacing.is_finite() && coarse_spacing > 0.0) {
        return Err(CoreError::invalid(
            "coarse_spacing",
            format!("expected a positive number, got {coarse_spacing}"),
        ));
    }
    Ok(())
}

/// The input of one factor-2 refinement of a 2D grid: the coarse grid in
/// standard layout, its shape `(r, c)` and the fine shape (`(2r - 1, 2c - 1)`,
/// periodic: `(2r, 2c)`). A non-periodic grid needs 2 x 2 samples.
#[allow(clippy::type_complexity)]
pub(crate) fn refine_input(
    coarse: ArrayView2<'_, f64>,
    periodic: bool,
) -> CoreResult<(CowArray<'_, f64, Ix2>, (usize, usize), (usize, usize))> {
    let (r, c) = coarse.dim();
    if !periodic && (r < 2 || c < 2) {
        return Err(CoreError::invalid(
            "coarse",
            format!("need at least 2 x 2 samples, got {r} x {c}"),
        ));
    }
    if r < 1 || c < 1 {
        return Err(CoreError::invalid("coarse", "empty grid"));
    }
    let fine = if periodic {
        (2 * r, 2 * c)
    } else {
        (2 * r - 1, 2 * c - 1)
    };
    let coarse = if coarse.is_standard_layout() {
        CowArray::from(coarse)
    } else {
        CowArray::from(coarse.as_standard_layout().into_owned())
    };
    Ok((coarse, (r, c), fine))
}

/// The samples of a grid in standard layout, row-major.
pub(crate) fn as_slice<'a>(a: &'a CowArray<'_, f64, Ix2>) -> CoreResult<&'a [f64]> {
    a.as_slice()
        .ok_or_else(|| CoreError::Internal("coarse grid not contiguous".into()))
}
