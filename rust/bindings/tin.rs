//! Bindings of `crate::tin`.
use super::convert::{array1, array2, c_order, rows_in, run, run_on_grid};
use crate::tin::{delaunay, greedy, interpolate};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

fn triangles_array(py: Python<'_>, t: Vec<[i64; 3]>) -> PyResult<Bound<'_, PyArray2<i64>>> {
    let m = t.len();
    array2(py, (m, 3), t.into_flattened())
}

/// Delaunay (or constrained Delaunay) triangles of `points[:, :2]` (any strides).
#[pyfunction]
#[pyo3(signature = (points, constraints=None, n_threads=None))]
fn tin_delaunay<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    constraints: Option<PyReadonlyArray2<'py, i64>>,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<i64>>> {
    let view = points.as_array();
    let edges: Option<Vec<[i64; 2]>> = match constraints.as_ref() {
        Some(c) => Some(rows_in(c, "constraints")?),
        None => None,
    };
    let t = run(py, n_threads, || {
        delaunay::delaunay(&view, edges.as_deref())
    })?;
    triangles_array(py, t)
}

/// Greedy error-bounded TIN of a float64 raster (NaN = nodata, C-contiguous).
/// Returns (grid[(n, 2)] as (col, row), z[n], triangles[(m, 3)], max_error).
#[pyfunction]
#[pyo3(signature = (dem, max_error, max_triangles=None, shared_edges=true, n_threads=None))]
#[allow(clippy::type_complexity)]
fn tin_greedy<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    max_error: f64,
    max_triangles: Option<usize>,
    shared_edges: bool,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray2<i64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray2<i64>>,
    f64,
)> {
    let (r, _) = run_on_grid(py, &dem, n_threads, |z, rows, cols| {
        greedy::greedy_tin(z, rows, cols, max_error, max_triangles, shared_edges)
    })?;
    let n = r.grid.len();
    let grid: Vec<i64> = r
        .grid
        .iter()
        .flat_map(|g| [g[0] as i64, g[1] as i64])
        .collect();
    Ok((
        array2(py, (n, 2), grid)?,
        array1(py, r.z),
        triangles_array(py, r.triangles)?,
        r.max_error,
    ))
}

/// Interpolate `values` at `points[:, :2]` onto a `rows x cols` grid of node
/// positions `x = t0 + t1 c + t2 r`, `y = t3 + t4 c + t5 r`.
#[pyfunction]
#[pyo3(signature = (points, values, rows, cols, transform, method, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn tin_grid<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    values: PyReadonlyArray1<'py, f64>,
    rows: usize,
    cols: usize,
    transform: [f64; 6],
    method: &str,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = interpolate::Method::parse(method)?;
    let view = points.as_array();
    let vals = c_order(&values);
    let g = run(py, n_threads, || {
        interpolate::grid_from_points(&view, &vals.data, rows, cols, transform, m)
    })?;
    array2(py, (rows, cols), g)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(tin_delaunay, m)?)?;
    m.add_function(wrap_pyfunction!(tin_greedy, m)?)?;
    m.add_function(wrap_pyfunction!(tin_grid, m)?)?;
    m.add_function(wrap_pyfunction!(tin_rasterize, m)?)?;
    Ok(())
}

/// Barycentric rasterisation of a mesh given in grid coordinates (col, row).
#[pyfunction]
#[pyo3(signature = (xy, z, triangles, rows, cols, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn tin_rasterize<'py>(
    py: Python<'py>,
    xy: PyReadonlyArray2<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
    triangles: PyReadonlyArray2<'py, i64>,
    rows: usize,
    cols: usize,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let p: Vec<[f64; 2]> = rows_in(&xy, "xy")?;
    let zs = c_order(&z);
    let t: Vec<[i64; 3]> = rows_in(&triangles, "triangles")?;
    let g = run(py, n_threads, || {
        greedy::rasterize(&p, &zs.data, &t, rows, cols)
    })?;
    array2(py, (rows, cols), g)
}
