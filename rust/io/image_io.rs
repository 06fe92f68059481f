//! PNG and 8/16-bit TIFF through the `image` crate.
//!
//! `image` 0.25 does not decode single-band float TIFF (the usual GeoTIFF of
//! DEMs and SAR) and keeps no georeferencing: such files go through rasterio.
use crate::error::{CoreError, CoreResult};
use image::{DynamicImage, ImageBuffer, ImageDecoder, ImageReader, Luma};
use std::path::Path;

/// Decoded pixels, row-major `(rows, cols, channels)`.
#[derive(Debug, Clone, PartialEq)]
pub enum Pixels {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

/// A decoded raster.
#[derive(Debug, Clone, PartialEq)]
pub struct Raster {
    pub pixels: Pixels,
    pub rows: usize,
    pub cols: usize,
    pub channels: usize,
}

/// `(rows, cols, channels, bytes per pixel)` of a PNG or TIFF from its
/// header, without decoding the pixels (so a caller can check the memory a
/// [`read_image`] would need first).
pub fn image_header(path: &Path) -> CoreResult<(usize, usize, usize, usize)> {
    let decoder = ImageReader::open(path)
        .map_err(|e| CoreError::from_io(format_args!("cannot open {}", path.display()), &e))?
        .with_guessed_format()
        .map_err(|e| CoreError::from_io(format_args!("cannot read {}", path.display()), &e))?
        .into_decoder()
        .map_err(|e| CoreError::Io(format!("cannot decode {}: {e}", path.display())))?;
    let (cols, rows) = decoder.dimensions();
    let color = decoder.color_type();
    Ok((
        rows as usize,
        cols as usize,
        color.channel_count() as usize,
        color.bytes_per_pixel() as usize,
    ))
}

/// Read a PNG or TIFF file, keeping its bit depth and channels.
pub fn read_image(path: &Path) -> CoreResult<Raster> {
    let reader = ImageReader::open(path)
        .map_err(|e| CoreError::from_io(format_args!("cannot open {}", path.display()), &e))?
        .with_guessed_format()
        .map_err(|e| CoreError::from_io(format_args!("cannot read {}", path.display()), &e))?;
    let img = reader
        .decode()
        .map_err(|e| CoreError::Io(format!("cannot decode {}: {e}", path.display())))?;
    let (cols, rows) = (img.width() as usize, img.height() as usize);
    let channels = img.color().channel_count() as usize;
    let pixels = match img {
        DynamicImage::ImageLuma8(b) => Pixels::U8(b.into_raw()),
        DynamicImage::ImageLumaA8(b) => Pixels::U8(b.into_raw()),
        DynamicImage::ImageRgb8(b) => Pixels::U8(b.into_raw()),
        DynamicImage::ImageRgba8(b) => Pixels::U8(b.into_raw()),
        DynamicImage::ImageLuma16(b) => Pixels::U16(b.into_raw()),
        DynamicImage::ImageLumaA16(b) => Pixels::U16(b.into_raw()),
        DynamicImage::ImageRgb16(b) => Pixels::U16(b.into_raw()),
        DynamicImage::ImageRgba16(b) => Pixels::U16(b.into_raw()),
        DynamicImage::ImageRgb32F(b) => Pixels::F32(b.into_raw()),
        DynamicImage::ImageRgba32F(b) => Pixels::F32(b.into_raw()),
        other => {
            return Err(CoreError::Io(format!(
                "unsupported pixel type {:?} in {}",
                other.color(),
                path.display()
            )))
        }
    };
    Ok(Raster {
        pixels,
        rows,
        cols,
        channels,
    })
}

/// Write a single-band 8- or 16-bit PNG atomically (temporary file in the
/// same folder, then rename): the file is written whole or not at all.
pub fn write_png_gray(path: &Path, pixels: &Pixels, rows: usize, cols: usize) -> CoreResult<()> {
    let (w, h) = (u32::try_from(cols), u32::try_from(rows));
    let (w, h) = match (w, h) {
        (Ok(w), Ok(h)) if w > 0 && h > 0 => (w, h),
        _ => {
            return Err(CoreError::invalid(
                "image",
                format!("bad image shape ({rows}, {cols})"),
            ))
        }
    };
    let tmp = temp_path(path);
    let result = match pixels {
        Pixels::U8(v) => ImageBuffer::<Luma<u8>, _>::from_raw(w, h, v.clone())
            .ok_or_else(|| CoreError::Internal("buffer size".into()))?
            .save_with_format(&tmp, image::ImageFormat::Png),
        Pixels::U16(v) => ImageBuffer::<Luma<u16>, _>::from_raw(w, h, v.clone())
            .ok_or_else(|| CoreError::Internal("buffer size".into()))?
            .save_with_format(&tmp, image::ImageFormat::Png),
        Pixels::F32(_) => {
            return Err(CoreError::invalid(
                "image",
                "PNG holds 8- or 16-bit integers, not float",
            ))
        }
    };
    finish_atomic(result, &tmp, path)
}

/// Complete an atomic write: on success rename `tmp` over `path`; on any
/// error remove `tmp` and report it for `path`.
pub fn finish_atomic<E: std::fmt::Display>(
    result: Result<(), E>,
    tmp: &Path,
    path: &Path,
) -> CoreResult<()> {
    if let Err(e) = result {
        let _ = std::fs::remove_file(tmp);
        return Err(CoreError::Io(format!(
            "cannot write {}: {e}",
            path.display()
        )));
    }
    std::fs::rename(tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(tmp);
        CoreError::Io(format!("cannot write {}: {e}", path.display()))
    })
}

/// A temporary name beside `path` (same filesystem, so rename is atomic).
pub fn temp_path(path: &Path) -> std::path::PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trip_16_bit() {
        let dir = std::env::temp_dir().join(format!("fgrs-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.png");
        let v: Vec<u16> = (0..6 * 7).map(|i| (i * 1500) as u16).collect();
        write_png_gray(&p, &Pixels::U16(v.clone()), 6, 7).unwrap();
        let r = read_image(&p).unwrap();
        assert_eq!((r.rows, r.cols, r.channels), (6, 7, 1));
        assert_eq!(r.pixels, Pixels::U16(v));
        assert!(read_image(&dir.join("missing.png")).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
