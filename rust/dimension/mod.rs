//! Fractal dimension estimators: the heavy counting work. The log-log fit and
//! the choice of scale range are done by the caller (the Python
//! `DimensionFit`), so every kernel here returns raw measures per scale.
//!
//! * [`boxcount`]: lattice box counting of binary sets in 1, 2 and 3 dimensions.
//! * [`points`]: box counting of point sets given as coordinates.
//! * [`dbc`]: differential box counting of grayscale images and DEMs.
//! * [`affine`]: per-column height ranges for self-affine box counting of graphs.
//! * [`higuchi`]: curve lengths of Higuchi's method for profiles.
//! * [`mass`]: Voss's P(m, L) box masses and the image-wide mass curve.
//! * [`blanket`]: Peleg's covering blanket growth and image-wide areas.
//! * [`lattice`]: the box lattices (sizes, grid shifts) shared by the counters.

pub mod affine;
pub mod blanket;
pub mod boxcount;
pub mod dbc;
pub mod higuchi;
pub mod lattice;
pub mod mass;
pub mod points;
