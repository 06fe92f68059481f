//! Raster input/output done in Rust: 8/16-bit PNG and TIFF through the `image`
//! crate. GeoTIFF with georeferencing is read on the Python side (rasterio).
pub mod image_io;
