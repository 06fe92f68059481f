//! fractalgeo_rs: fractal geometry for geo-information processing.
//!
//! The crate is organised by domain. Every kernel is plain Rust over slices and
//! `ndarray` views, returns `Result<_, CoreError>` and knows nothing of Python,
//! so `cargo test` and `cargo bench` run without an interpreter. The PyO3
//! bindings live in [`bindings`] behind the `python` cargo feature and do only
//! conversion, GIL release and error mapping.
//!
//! | module | what |
//! |---|---|
//! | [`dimension`] | fractal dimension estimators (box counting, DBC, self-affine boxes) |
//! | [`io`] | raster readers and writers that the bindings expose |
//! | [`synth`] | fBm and surface synthesis |
//! | [`dem`] | DEM work: shaded relief, lakes, resampling |
//! | [`lsystem`] | L-systems, turtle geometry and IFS |
//! | [`transform`] | moving-window maps of local dimension |
//! | [`progress`] | a work counter kernels tick for progress bars |
//! | [`radiometry`] | the virtual radiometric experiment: BRF, albedo and images of rough surfaces |

#![warn(clippy::undocumented_unsafe_blocks)]

pub mod buffers;
pub mod checks;
pub mod dem;
pub mod dimension;
pub mod error;
pub mod io;
pub mod lsystem;
pub mod parallel;
pub mod progress;
pub mod radiometry;
pub mod synth;
pub mod tin;
pub mod transform;

#[cfg(test)]
mod testdata;

#[cfg(feature = "python")]
pub mod bindings;

pub use error::{CoreError, CoreResult};
