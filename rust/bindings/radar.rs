//! Bindings of `crate::radar`: speckle and the side-looking geometry.
use super::convert::{array2, c_order, run};
use super::progress::{counter, ProgressCounter};
use crate::radar::geometry;
use crate::radar::speckle::{self, Placement};
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `intensity` times unit-mean Gamma(`looks`) speckle; `origin` and
/// `global_cols` place a block in the whole grid (0 = the block's columns).
#[pyfunction]
#[pyo3(signature = (intensity, looks, seed, origin=(0, 0), global_cols=0, n_threads=None))]
fn speckle_f64<'py>(
    py: Python<'py>,
    intensity: PyReadonlyArray2<'py, f64>,
    looks: u32,
    seed: u64,
    origin: (u64, u64),
    global_cols: u64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let a = c_order(&intensity);
    let (rows, cols) = a.rows_cols();
    let place = Placement {
        origin,
        global_cols: if global_cols == 0 {
            origin.1 + cols as u64
        } else {
            global_cols
        },
    };
    let out = run(py, n_threads, || {
        speckle::speckle(&a.data, cols, looks, seed, place)
    })?;
    array2(py, (rows, cols), out)
}

/// Geometry of a DEM in the range frame (columns = ground range), with the
/// facet sigma0 `table` sampled every `table_step` degrees, on the slant
/// axis `slant = (lo, n_bins)` when given (a strip of a larger scene):
/// `(theta_local, power, position, flags, n_bins)`.
#[pyfunction]
#[pyo3(signature = (dem, dx, dy, incidence, table, table_step, n_threads=None, slant=None))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn radar_geometry<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    dx: f64,
    dy: f64,
    incidence: f64,
    table: Vec<f64>,
    table_step: f64,
    n_threads: Option<usize>,
    slant: Option<(f64, usize)>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u8>>,
    usize,
)> {
    let a = c_order(&dem);
    let (rows, cols) = a.rows_cols();
    let g = run(py, n_threads, || {
        geometry::geometry_on_axis(
            &a.data, rows, cols, dx, dy, incidence, &table, table_step, slant,
        )
    })?;
    Ok((
        array2(py, (rows, cols), g.theta_local)?,
        array2(py, (rows, cols), g.power)?,
        array2(py, (rows, cols), g.position)?,
        array2(py, (rows, cols), g.flags)?,
        g.n_bins,
    ))
}

/// Slant-range projection: `(image, count, lit)`, each `rows x n_bins`
/// (image NaN where no footprint reaches).
#[pyfunction]
#[pyo3(signature = (power, position, flags, n_bins, n_threads=None))]
#[allow(clippy::type_complexity)]
fn radar_project<'py>(
    py: Python<'py>,
    power: PyReadonlyArray2<'py, f64>,
    position: PyReadonlyArray2<'py, f64>,
    flags: PyReadonlyArray2<'py, u8>,
    n_bins: usize,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u32>>,
    Bound<'py, PyArray2<u32>>,
)> {
    let (w, p, l) = (c_order(&power), c_order(&position), c_order(&flags));
    let (rows, cols) = w.rows_cols();
    if p.rows_cols() != (rows, cols) || l.rows_cols() != (rows, cols) {
        return Err(PyValueError::new_err(
            "position, flags: expected the shape of power",
        ));
    }
    let s = run(py, n_threads, || {
        geometry::project(&w.data, &p.data, &l.data, rows, cols, n_bins)
    })?;
    Ok((
        array2(py, (rows, n_bins), s.image)?,
        array2(py, (rows, n_bins), s.count)?,
        array2(py, (rows, n_bins), s.lit)?,
    ))
}

/// Terrain geocoding of two slant-range images (e.g. with and without
/// speckle): `(ground_a, ground_b, layover)` on the DEM's grid.
#[pyfunction]
#[pyo3(signature = (slant_a, slant_b, count, position, flags, n_threads=None))]
#[allow(clippy::type_complexity)]
fn radar_geocode<'py>(
    py: Python<'py>,
    slant_a: PyReadonlyArray2<'py, f64>,
    slant_b: PyReadonlyArray2<'py, f64>,
    count: PyReadonlyArray2<'py, u32>,
    position: PyReadonlyArray2<'py, f64>,
    flags: PyReadonlyArray2<'py, u8>,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u8>>,
)> {
    let (a, b, c) = (c_order(&slant_a), c_order(&slant_b), c_order(&count));
    let (p, f) = (c_order(&position), c_order(&flags));
    let (rows, n_bins) = a.rows_cols();
    let (prow, cols) = p.rows_cols();
    if b.rows_cols() != (rows, n_bins)
        || c.rows_cols() != (rows, n_bins)
        || prow != rows
        || f.rows_cols() != (rows, cols)
    {
        return Err(PyValueError::new_err(
            "slant_b, count, position, flags: shapes do not match slant_a",
        ));
    }
    let (mut outs, lay) = run(py, n_threads, || {
        geometry::geocode(
            &[&a.data, &b.data],
            &c.data,
            &p.data,
            &f.data,
            rows,
            cols,
            n_bins,
        )
    })?;
    let gb = outs.pop().unwrap_or_default();
    let ga = outs.pop().unwrap_or_default();
    Ok((
        array2(py, (rows, cols), ga)?,
        array2(py, (rows, cols), gb)?,
        array2(py, (rows, cols), lay)?,
    ))
}

/// Geometry, projection, speckle and terrain geocoding fused per range
/// line: `(theta_local, image, sigma0, layover, shadow)` on the DEM's grid
/// (`looks` 0: no speckle).
///
/// A strip of whole range lines of a larger scene: `row0` the global index
/// of its first line, `slant = (lo, n_bins)` the whole scene's slant axis
/// (from `radar_slant_extent`).
#[pyfunction]
#[pyo3(signature = (dem, dx, dy, incidence, table, table_step, looks, seed, n_threads=None, row0=0, slant=None, progress=None))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn radar_scene<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    dx: f64,
    dy: f64,
    incidence: f64,
    table: Vec<f64>,
    table_step: f64,
    looks: u32,
    seed: u64,
    n_threads: Option<usize>,
    row0: u64,
    slant: Option<(f64, usize)>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<u8>>,
    Bound<'py, PyArray2<u8>>,
)> {
    let a = c_order(&dem);
    let (rows, cols) = a.rows_cols();
    let looks = (looks > 0).then_some(looks);
    let pr = counter(progress);
    let s = run(py, n_threads, || {
        geometry::scene_block(
            &a.data,
            rows,
            cols,
            dx,
            dy,
            incidence,
            &table,
            table_step,
            looks,
            seed,
            row0,
            slant,
            pr.as_deref(),
        )
    })?;
    Ok((
        array2(py, (rows, cols), s.theta_local)?,
        array2(py, (rows, cols), s.image)?,
        array2(py, (rows, cols), s.sigma0)?,
        array2(py, (rows, cols), s.layover)?,
        array2(py, (rows, cols), s.shadow)?,
    ))
}

/// The smallest and largest finite unshifted slant-range position (bins of
/// `dx sin(incidence)`) of the lines of a DEM in the range frame, as
/// `radar_scene` computes them (infinities when none is finite).
#[pyfunction]
#[pyo3(signature = (dem, dx, incidence, n_threads=None))]
fn radar_slant_extent(
    py: Python<'_>,
    dem: PyReadonlyArray2<'_, f64>,
    dx: f64,
    incidence: f64,
    n_threads: Option<usize>,
) -> PyResult<(f64, f64)> {
    let a = c_order(&dem);
    let (_, cols) = a.rows_cols();
    run(py, n_threads, || {
        Ok(geometry::slant_extent(
            &a.data,
            cols,
            dx,
            geometry::cot_of(incidence),
        ))
    })
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(speckle_f64, m)?)?;
    m.add_function(wrap_pyfunction!(radar_geometry, m)?)?;
    m.add_function(wrap_pyfunction!(radar_project, m)?)?;
    m.add_function(wrap_pyfunction!(radar_geocode, m)?)?;
    m.add_function(wrap_pyfunction!(radar_scene, m)?)?;
    m.add_function(wrap_pyfunction!(radar_slant_extent, m)?)?;
    Ok(())
}
