//! Bindings of `crate::io`.
use crate::io::image_io::{self, Pixels};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;

/// Read a PNG or 8/16-bit TIFF. Returns an array of shape (rows, cols, channels)
/// with the file's own dtype (uint8, uint16 or float32).
#[pyfunction]
fn read_image(py: Python<'_>, path: PathBuf) -> PyResult<Py<PyAny>> {
    let r = py.detach(|| image_io::read_image(&path))?;
    let shape = (r.rows, r.cols, r.channels);
    let bad = |_| PyValueError::new_err("internal: pixel buffer does not match the image shape");
    Ok(match r.pixels {
        Pixels::U8(v) => Array3::from_shape_vec(shape, v)
            .map_err(bad)?
            .into_pyarray(py)
            .into_any()
            .unbind(),
        Pixels::U16(v) => Array3::from_shape_vec(shape, v)
            .map_err(bad)?
            .into_pyarray(py)
            .into_any()
            .unbind(),
        Pixels::F32(v) => Array3::from_shape_vec(shape, v)
            .map_err(bad)?
            .into_pyarray(py)
            .into_any()
            .unbind(),
    })
}

/// Write a 2D uint8 or uint16 array as a single-band PNG, atomically.
#[pyfunction]
fn write_png(py: Python<'_>, path: PathBuf, image: &Bound<'_, PyAny>) -> PyResult<()> {
    let (pixels, rows, cols) = if let Ok(a) = image.extract::<PyReadonlyArray2<'_, u8>>() {
        (
            Pixels::U8(a.as_array().iter().copied().collect()),
            a.shape()[0],
            a.shape()[1],
        )
    } else if let Ok(a) = image.extract::<PyReadonlyArray2<'_, u16>>() {
        (
            Pixels::U16(a.as_array().iter().copied().collect()),
            a.shape()[0],
            a.shape()[1],
        )
    } else {
        return Err(PyTypeError::new_err(
            "image: expected a 2D uint8 or uint16 array",
        ));
    };
    py.detach(|| image_io::write_png_gray(&path, &pixels, rows, cols))?;
    Ok(())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(write_png, m)?)?;
    Ok(())
}
