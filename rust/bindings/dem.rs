//! Bindings of `crate::dem`.
use super::convert::{array2, c_order, run};
use crate::dem::hillshade::{self, ShadeParams};
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

/// Hillshade in [0, 1] (NaN = nodata); `dx` per row, `dy` scalar.
#[pyfunction]
#[pyo3(signature = (dem, dx, dy, azimuth, altitude, z_factor, multidirectional, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn hillshade_f64<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    dx: Vec<f64>,
    dy: f64,
    azimuth: f64,
    altitude: f64,
    z_factor: f64,
    multidirectional: bool,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let z = dem.as_array();
    let p = ShadeParams {
        azimuth,
        altitude,
        z_factor,
        multidirectional,
    };
    let v = run(py, n_threads, || hillshade::hillshade(z, &dx, dy, &p))?;
    Ok(v.into_pyarray(py))
}

/// GDAL's byte encoding of a reflectance array: round(1 + 254 L), 0 for NaN.
#[pyfunction]
#[pyo3(signature = (shade, n_threads=None))]
fn shade_to_byte<'py>(
    py: Python<'py>,
    shade: PyReadonlyArray2<'py, f32>,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<u8>>> {
    let a = c_order(&shade);
    let b = run(py, n_threads, || Ok(hillshade::to_byte(&a.data)))?;
    array2(py, a.rows_cols(), b)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(hillshade_f64, m)?)?;
    m.add_function(wrap_pyfunction!(shade_to_byte, m)?)?;
    Ok(())
}
