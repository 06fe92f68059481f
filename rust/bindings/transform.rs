//! Bindings of `crate::transform`.
use super::convert::{array2, array3, run_on_grid, FloatArray2};
use crate::transform::blanket::{blanket_transform, BlanketMapOptions};
use crate::transform::dbc::{dbc_transform, DbcMapOptions};
use crate::transform::driver::MapOut;
use crate::transform::gls::{gls_transform, GlsOptions, GlsTables};
use crate::transform::lacunarity::lacunarity_transform;
use crate::transform::mass::{mass_transform, MassOptions};
use crate::transform::variation::{variation_transform, Increments, VariationOptions};
use crate::with_float;
use numpy::{PyArray2, PyArray3, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

type MapPair<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray2<f32>>);

/// The (dimension, r²) pair of a map on the grid of every `step`-th pixel.
fn map_pair(py: Python<'_>, m: MapOut) -> PyResult<MapPair<'_>> {
    let shape = (m.rows, m.cols);
    Ok((array2(py, shape, m.d)?, array2(py, shape, m.r2)?))
}

/// Run `kernel(z, rows, cols)` on a 2D float32 or float64 image, read in
/// place (no float64 copy of a float32 scene); evaluates to
/// `(result, (rows, cols))`.
macro_rules! on_float_image {
    ($py:expr, $image:expr, $n_threads:expr, $kernel:path, $($opt:expr),+) => {
        with_float!(FloatArray2::extract($image, "image")?, |a| {
            run_on_grid($py, &a, $n_threads, |z, rows, cols| $kernel(z, rows, cols, $($opt),+))?
        })
    };
}

/// Moving-window increment estimator on a float32 or float64 image.
/// Returns (dimension, r_squared) float32 maps on the `step` grid.
#[pyfunction]
#[pyo3(signature = (image, window_size, lags, p, square, min_valid, step=1, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn variation_transform_map<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    window_size: usize,
    lags: Vec<usize>,
    p: f64,
    square: bool,
    min_valid: f64,
    step: usize,
    n_threads: Option<usize>,
) -> PyResult<MapPair<'py>> {
    let opt = VariationOptions {
        window: window_size,
        lags,
        p,
        increments: if square {
            Increments::Square
        } else {
            Increments::First
        },
        min_valid,
        step,
    };
    let (maps, _) = on_float_image!(py, image, n_threads, variation_transform, &opt);
    map_pair(py, maps)
}

/// Moving-window P(m, L) mass dimension on a float32 or float64 image.
/// Returns (dimension, r_squared) float32 maps on the `step` grid.
#[pyfunction]
#[pyo3(signature = (image, window_size, box_sizes, z_scale, min_valid, step=1, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn mass_transform_map<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    window_size: usize,
    box_sizes: Vec<usize>,
    z_scale: f64,
    min_valid: f64,
    step: usize,
    n_threads: Option<usize>,
) -> PyResult<MapPair<'py>> {
    let opt = MassOptions {
        window: window_size,
        box_sizes,
        z_scale,
        min_valid,
        step,
    };
    let (maps, _) = on_float_image!(py, image, n_threads, mass_transform, &opt);
    map_pair(py, maps)
}

/// Moving-window GLS Hurst exponent on a float32 or float64 image, with the
/// tables of `fractalgeo_rs.dimension.gls.tables` (`a`, `da`, `g`: (nH, K);
/// `se`: (nH,); grid `h0 + i dh`). Returns [hurst, se] float32 maps on the
/// `step` grid, and [angle, ratio] after them with `anisotropy`.
#[pyfunction]
#[pyo3(signature = (image, window_size, dilations, h0, dh, a, da, g, se, steps, min_valid, step=1, anisotropy=false, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn gls_transform_map<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    window_size: usize,
    dilations: usize,
    h0: f64,
    dh: f64,
    a: PyReadonlyArray2<'py, f64>,
    da: PyReadonlyArray2<'py, f64>,
    g: PyReadonlyArray2<'py, f64>,
    se: Vec<f64>,
    steps: usize,
    min_valid: f64,
    step: usize,
    anisotropy: bool,
    n_threads: Option<usize>,
) -> PyResult<Vec<Bound<'py, PyArray2<f32>>>> {
    let n_h = a.shape()[0];
    let flat = |t: &PyReadonlyArray2<'py, f64>| -> PyResult<Vec<f64>> {
        if t.shape()[0] != n_h {
            return Err(pyo3::exceptions::PyValueError::new_err(
                "tables: a, da and g need the same shape",
            ));
        }
        Ok(t.as_array().iter().copied().collect())
    };
    let tab = GlsTables {
        h0,
        dh,
        n_h,
        a: flat(&a)?,
        da: flat(&da)?,
        g: flat(&g)?,
        se,
    };
    let opt = GlsOptions {
        window: window_size,
        dilations,
        steps,
        min_valid,
        step,
        anisotropy,
    };
    let (maps, _) = on_float_image!(py, image, n_threads, gls_transform, &opt, &tab);
    let shape = (maps.rows, maps.cols);
    maps.into_maps()
        .into_iter()
        .filter(|v| !v.is_empty())
        .map(|v| array2(py, shape, v))
        .collect()
}

/// Moving-window differential box counting on the grid of every `step`-th
/// pixel. Returns (dimension, r_squared) float32 maps.
#[pyfunction]
#[pyo3(signature = (image, window_size, box_sizes, z_scale, z0, partial_blocks, min_valid, step, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn dbc_transform_map<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    window_size: usize,
    box_sizes: Vec<usize>,
    z_scale: f64,
    z0: f64,
    partial_blocks: bool,
    min_valid: f64,
    step: usize,
    n_threads: Option<usize>,
) -> PyResult<MapPair<'py>> {
    let opt = DbcMapOptions {
        window: window_size,
        box_sizes,
        z_unit: z_scale,
        z0,
        min_valid,
        step,
        partial_blocks,
    };
    let (m, _) = on_float_image!(py, image, n_threads, dbc_transform, &opt);
    map_pair(py, m)
}

/// Moving-window covering blanket on the grid of every `step`-th pixel.
/// Returns (dimension, r_squared) float32 maps.
#[pyfunction]
#[pyo3(signature = (image, window_size, epsilons, z_scale, min_valid, step, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn blanket_transform_map<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    window_size: usize,
    epsilons: Vec<usize>,
    z_scale: f64,
    min_valid: f64,
    step: usize,
    n_threads: Option<usize>,
) -> PyResult<MapPair<'py>> {
    let opt = BlanketMapOptions {
        window: window_size,
        epsilons,
        z_scale,
        min_valid,
        step,
    };
    let (m, _) = on_float_image!(py, image, n_threads, blanket_transform, &opt);
    map_pair(py, m)
}

/// Moving-window gliding-box lacunarity, shape (n_sizes, rows, cols) float32.
#[pyfunction]
#[pyo3(signature = (image, window_size, box_sizes, min_valid, n_threads=None))]
fn lacunarity_transform_map<'py>(
    py: Python<'py>,
    image: &Bound<'py, PyAny>,
    window_size: usize,
    box_sizes: Vec<usize>,
    min_valid: f64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let n = box_sizes.len();
    let (l, (rows, cols)) = on_float_image!(
        py,
        image,
        n_threads,
        lacunarity_transform,
        window_size,
        &box_sizes,
        min_valid
    );
    array3(py, (n, rows, cols), l)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(lacunarity_transform_map, m)?)?;
    m.add_function(wrap_pyfunction!(variation_transform_map, m)?)?;
    m.add_function(wrap_pyfunction!(gls_transform_map, m)?)?;
    m.add_function(wrap_pyfunction!(mass_transform_map, m)?)?;
    m.add_function(wrap_pyfunction!(dbc_transform_map, m)?)?;
    m.add_function(wrap_pyfunction!(blanket_transform_map, m)?)?;
    Ok(())
}
