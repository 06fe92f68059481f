//! Bindings of `crate::io`.
use super::convert::{array2, array3, c_order, run};
use crate::io::exr_io;
use crate::io::image_io::{self, Pixels};
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Read a PNG or 8/16-bit TIFF. Returns an array of shape (rows, cols, channels)
/// with the file's own dtype (uint8, uint16 or float32).
#[pyfunction]
fn read_image(py: Python<'_>, path: PathBuf) -> PyResult<Py<PyAny>> {
    let r = run(py, Some(1), || image_io::read_image(&path))?;
    let shape = (r.rows, r.cols, r.channels);
    Ok(match r.pixels {
        Pixels::U8(v) => array3(py, shape, v)?.into_any().unbind(),
        Pixels::U16(v) => array3(py, shape, v)?.into_any().unbind(),
        Pixels::F32(v) => array3(py, shape, v)?.into_any().unbind(),
    })
}

/// Write a 2D uint8 or uint16 array as a single-band PNG, atomically.
#[pyfunction]
fn write_png(py: Python<'_>, path: PathBuf, image: &Bound<'_, PyAny>) -> PyResult<()> {
    let (pixels, (rows, cols)) = if let Ok(a) = image.extract::<PyReadonlyArray2<'_, u8>>() {
        let a = c_order(&a);
        (Pixels::U8(a.data.to_vec()), a.rows_cols())
    } else if let Ok(a) = image.extract::<PyReadonlyArray2<'_, u16>>() {
        let a = c_order(&a);
        (Pixels::U16(a.data.to_vec()), a.rows_cols())
    } else {
        return Err(PyTypeError::new_err(
            "image: expected a 2D uint8 or uint16 array",
        ));
    };
    run(py, Some(1), || {
        image_io::write_png_gray(&path, &pixels, rows, cols)
    })
}

/// `(rows, cols, channels, bytes_per_pixel)` of a PNG or TIFF from its header.
#[pyfunction]
fn image_header(py: Python<'_>, path: PathBuf) -> PyResult<(usize, usize, usize, usize)> {
    run(py, Some(1), || image_io::image_header(&path))
}

/// `(rows, cols, channels)` of an EXR's first layer from its header.
#[pyfunction]
fn exr_header(py: Python<'_>, path: PathBuf) -> PyResult<(usize, usize, usize)> {
    run(py, Some(1), || exr_io::exr_header(&path))
}

/// Read the "Y" (or only) channel of a float EXR as a 2D float32 array.
#[pyfunction]
fn read_exr<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let (v, rows, cols) = run(py, Some(1), || exr_io::read_exr_gray(&path))?;
    array2(py, (rows, cols), v)
}

/// Write a 2D float32 array as a single-channel ("Y") float EXR, atomically.
#[pyfunction]
fn write_exr(py: Python<'_>, path: PathBuf, image: PyReadonlyArray2<'_, f32>) -> PyResult<()> {
    let a = c_order(&image);
    let (rows, cols) = a.rows_cols();
    let v = a.data.into_owned();
    run(py, Some(1), || exr_io::write_exr_gray(&path, v, rows, cols))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(image_header, m)?)?;
    m.add_function(wrap_pyfunction!(exr_header, m)?)?;
    m.add_function(wrap_pyfunction!(write_png, m)?)?;
    m.add_function(wrap_pyfunction!(read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(write_exr, m)?)?;
    Ok(())
}
