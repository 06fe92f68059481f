//! Synthesis of fractional Brownian motion and fractal surfaces.
//!
//! * [`rng`]: the counter-based generator (a sample is a pure function of
//!   `(seed, stream, index)`), used by every method;
//! * [`midpoint`]: random midpoint displacement and Voss's random additions as
//!   factor-2 refinement kernels in 1D and 2D (diamond-square).
//!
//! The FFT-based methods (Davies-Harte, Stein's circulant embedding, spectral
//! synthesis) run on the Python side with `scipy.fft` on noise drawn here.
pub mod midpoint;
pub mod rng;
