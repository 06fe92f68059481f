//! Synthesis of fractional Brownian motion and fractal surfaces.
//!
//! * [`rng`]: the counter-based generator (a sample is a pure function of
//!   `(seed, stream, index)`), used by every method;
//! * [`midpoint`]: random midpoint displacement and Voss's random additions as
//!   factor-2 refinement kernels in 1D and 2D (diamond-square);
//! * [`additions`]: successive random additions with 4-point interpolation
//!   and variances balanced against creases (2D `"additions"`);
//! * [`davies_harte`]: exact 1D fBm by circulant embedding with real FFTs.
//!
//! Stein's 2D circulant embedding and spectral synthesis run on the Python
//! side with `scipy.fft` on noise drawn here.
pub mod additions;
pub mod davies_harte;
pub mod midpoint;
pub mod rng;
