//! Raster input/output done in Rust: 8/16-bit PNG and TIFF through the `image`
//! crate, single-channel float EXR through `exr`; mesh files (OBJ, PLY) in [`mesh`]. GeoTIFF with georeferencing is read on the Python side (rasterio).
pub mod exr_io;
pub mod image_io;
pub mod mesh;
