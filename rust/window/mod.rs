//! The moving-window service every map kernel runs on: the argument checks
//! of a map, its output grid and bands, the valid-count gate, the log-log
//! line fit and the result type ([`driver`]), and the summed-area tables the
//! kernels build their window sums from ([`sat`]).
//!
//! It knows no statistic: a kernel (`crate::transform`'s, or any other
//! domain's) supplies the per-band work only.

pub mod driver;
pub(crate) mod sat;
