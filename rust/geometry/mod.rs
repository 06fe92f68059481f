//! Geometry shared by every domain: the triangle [`Mesh`] and the raster
//! georeference [`GeoGrid`]. Nothing here imports a domain module (`tin`,
//! `lsystem`, `dem`, ...); the domains build on it.
//!
//! | module | what |
//! |---|---|
//! | [`mesh`] | `Mesh` (f32 vertices relative to an f64 origin, u32 triangles, per-triangle ids), grid and TIN constructors, normals, watertightness |
//! | [`geogrid`] | `GeoGrid`: origin, cell size, rotation, CRS of a row-0-north raster |
pub mod geogrid;
pub mod mesh;

pub use geogrid::GeoGrid;
pub use mesh::{EdgeReport, Mesh, Split};
