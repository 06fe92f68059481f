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
//! | [`geometry`] | the shared triangle `Mesh` and raster georeference `GeoGrid` (below every domain) |
//! | [`io`] | raster readers and writers that the bindings expose, mesh files |
//! | [`synth`] | fBm and surface synthesis |
//! | [`dem`] | DEM work: shaded relief, lakes, resampling |
//! | [`lsystem`] | L-systems, turtle geometry and IFS |
//! | [`transform`] | moving-window maps of local dimension |
//! | [`radar`] | speckle and side-looking SAR geometry |
//! | [`radiometry`] | the virtual radiometric experiment: BRF, albedo and images of rough surfaces |
//!
//! Crate-level services that every domain may use (and that use no domain):
//!
//! | module | what |
//! |---|---|
//! | [`rng`] | counter-based random streams keyed by `(seed, stream, index)` |
//! | [`sample`] | the sample types (`f32`, `f64`) raster kernels read |
//! | [`progress`] | a work counter kernels tick for progress bars |
//! | [`window`] | the moving-window driver and summed-area tables |
//! | [`parallel`] | thread pools sized by `n_threads`, and shared output buffers |
//! | [`checks`] | value checks that name the parameter |

#![warn(clippy::undocumented_unsafe_blocks)]

pub mod buffers;
pub mod checks;
pub mod dem;
pub mod dimension;
pub mod error;
pub mod geometry;
pub mod io;
pub mod lsystem;
pub mod parallel;
pub mod progress;
pub mod radar;
pub mod radiometry;
pub mod rng;
pub mod sample;
pub mod synth;
pub mod tin;
pub mod transform;
pub mod window;

#[cfg(test)]
mod testdata;

#[cfg(feature = "python")]
pub mod bindings;

pub use error::{CoreError, CoreResult};
