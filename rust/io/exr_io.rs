//! Single-channel float OpenEXR through the `exr` crate.
//!
//! A raster is one layer with one 32-bit float channel named "Y" (the
//! luminance name other tools show as grey), losslessly compressed. Reading
//! accepts the first layer's "Y" channel, or its only channel.
use crate::error::{CoreError, CoreResult};
use crate::io::image_io::{finish_atomic, temp_path};
use exr::prelude::*;
use std::path::Path;

/// Write `data` (row-major, `rows` x `cols`) as a float EXR, atomically.
pub fn write_exr_gray(path: &Path, data: Vec<f32>, rows: usize, cols: usize) -> CoreResult<()> {
    if rows == 0 || cols == 0 || data.len() != rows * cols {
        return Err(CoreError::invalid(
            "image",
            format!("bad image shape ({rows}, {cols})"),
        ));
    }
    let channel = AnyChannel::new("Y", FlatSamples::F32(data));
    let layer = Layer::new(
        (cols, rows),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(vec![channel].into()),
    );
    let image = Image::from_layer(layer);
    let tmp = temp_path(path);
    finish_atomic(image.write().to_file(&tmp), &tmp, path)
}

/// `(rows, cols, channels)` of the first layer from the file's header,
/// without reading the pixels (so a caller can check the memory a
/// [`read_exr_gray`] would need first: it decodes every channel as f32).
pub fn exr_header(path: &Path) -> CoreResult<(usize, usize, usize)> {
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| match e {
        exr::error::Error::Io(io) => {
            CoreError::from_io(format_args!("cannot read {}", path.display()), &io)
        }
        other => CoreError::Io(format!("cannot read {}: {other}", path.display())),
    })?;
    let h = meta
        .headers
        .first()
        .ok_or_else(|| CoreError::Io(format!("{}: no layer", path.display())))?;
    Ok((
        h.layer_size.height(),
        h.layer_size.width(),
        h.channels.list.len(),
    ))
}

/// Read the "Y" (or only) channel of the first layer: `(pixels, rows, cols)`.
pub fn read_exr_gray(path: &Path) -> CoreResult<(Vec<f32>, usize, usize)> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| match e {
            exr::error::Error::Io(io) => {
                CoreError::from_io(format_args!("cannot read {}", path.display()), &io)
            }
            other => CoreError::Io(format!("cannot read {}: {other}", path.display())),
        })?;
    let layer = &image.layer_data;
    let size = layer.size;
    let list = &layer.channel_data.list;
    let chan = list
        .iter()
        .find(|c| c.name == *"Y")
        .or(if list.len() == 1 { list.first() } else { None })
        .ok_or_else(|| {
            CoreError::Io(format!(
                "{}: no channel \"Y\" among {} channels",
                path.display(),
                list.len()
            ))
        })?;
    let values: Vec<f32> = chan.sample_data.values_as_f32().collect();
    Ok((values, size.height(), size.width()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip() {
        let dir = std::env::temp_dir().join(format!("fg_exr_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.exr");
        let data: Vec<f32> = (0..35)
            .map(|i| i as f32 * 0.37 - 3.0)
            .chain([f32::NAN])
            .take(35)
            .collect();
        write_exr_gray(&p, data.clone(), 5, 7).unwrap();
        let (back, r, c) = read_exr_gray(&p).unwrap();
        assert_eq!((r, c), (5, 7));
        assert_eq!(back, data);
        assert!(write_exr_gray(&p, vec![0.0; 3], 2, 2).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
