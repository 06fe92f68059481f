//! Bindings of `crate::radiometry`: BRF, albedo and images of a DEM scene.
//!
//! The scene is rebuilt from the DEM on every call (linear in the cells,
//! negligible beside the rays), so nothing is kept between calls.
use super::convert::{array2, c_order, run};
use super::progress::{counter, ProgressCounter};
use crate::error::{CoreError, CoreResult};
use crate::radiometry::{direction, material, Heightfield, Scene, Split};
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

fn build(
    z: &[f64],
    (rows, cols): (usize, usize),
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material_name: &str,
    params: &[f64],
) -> CoreResult<Scene> {
    let split = match split {
        "ne-sw" => Split::NeSw,
        "nw-se" => Split::NwSe,
        other => {
            return Err(CoreError::invalid(
                "split",
                format!("expected 'ne-sw' or 'nw-se', got {other:?}"),
            ))
        }
    };
    Ok(Scene {
        hf: Heightfield::new(z, rows, cols, cell_size, periodic, split)?,
        material: material::from_name(material_name, params)?,
    })
}

/// `(value, se, n)` of the BRF of a DEM scene (directions `(azimuth, zenith)` in degrees).
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, material, params, sun, view, spp, max_depth, seed, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn radiometry_brf(
    py: Python<'_>,
    dem: PyReadonlyArray2<'_, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material: &str,
    params: Vec<f64>,
    sun: (f64, f64),
    view: (f64, f64),
    spp: u64,
    max_depth: u32,
    seed: u64,
    n_threads: Option<usize>,
) -> PyResult<(f64, f64, u64)> {
    let z = c_order(&dem);
    let e = run(py, n_threads, || {
        let s = build(
            &z.data,
            z.rows_cols(),
            cell_size,
            periodic,
            split,
            material,
            &params,
        )?;
        s.brf(
            direction(sun, "sun")?,
            direction(view, "view")?,
            spp,
            max_depth,
            seed,
        )
    })?;
    Ok((e.value, e.se, e.n))
}

/// `(value, se, n)` of the directional-hemispherical albedo of a DEM scene.
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, material, params, sun, spp, max_depth, seed, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn radiometry_albedo(
    py: Python<'_>,
    dem: PyReadonlyArray2<'_, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material: &str,
    params: Vec<f64>,
    sun: (f64, f64),
    spp: u64,
    max_depth: u32,
    seed: u64,
    n_threads: Option<usize>,
) -> PyResult<(f64, f64, u64)> {
    let z = c_order(&dem);
    let e = run(py, n_threads, || {
        let s = build(
            &z.data,
            z.rows_cols(),
            cell_size,
            periodic,
            split,
            material,
            &params,
        )?;
        s.albedo(direction(sun, "sun")?, spp, max_depth, seed)
    })?;
    Ok((e.value, e.se, e.n))
}

/// A float32 radiance image of shape `shape` of a DEM scene (orthographic sensor).
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, material, params, sun, view, shape, spp, max_depth, seed, n_threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn radiometry_render<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material: &str,
    params: Vec<f64>,
    sun: (f64, f64),
    view: (f64, f64),
    shape: (usize, usize),
    spp: u64,
    max_depth: u32,
    seed: u64,
    n_threads: Option<usize>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let z = c_order(&dem);
    let pr = counter(progress);
    let img = run(py, n_threads, || {
        let s = build(
            &z.data,
            z.rows_cols(),
            cell_size,
            periodic,
            split,
            material,
            &params,
        )?;
        s.render_progress(
            direction(sun, "sun")?,
            direction(view, "view")?,
            shape,
            spp,
            max_depth,
            seed,
            pr.as_deref(),
        )
    })?;
    array2(py, shape, img)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(radiometry_albedo, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_brf, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_render, m)?)?;
    Ok(())
}
