//! Bindings of `crate::tin`.
use crate::parallel::run_in_pool;
use crate::tin::{delaunay, greedy, interpolate};
use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

fn triangles_array(t: Vec<[i64; 3]>) -> Array2<i64> {
    let m = t.len();
    Array2::from_shape_vec((m, 3), t.into_iter().flatten().collect()).expect("m x 3 triangles")
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
    let edges: Option<Vec<[i64; 2]>> = constraints.as_ref().map(|c| {
        c.as_array()
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1]])
            .collect()
    });
    let t = py.detach(|| run_in_pool(n_threads, || delaunay::delaunay(&view, edges.as_deref())))?;
    Ok(triangles_array(t).into_pyarray(py))
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
    let (rows, cols) = (dem.shape()[0], dem.shape()[1]);
    let z = dem
        .as_slice()
        .map_err(|_| PyValueError::new_err("dem: internal: must be C-contiguous"))?;
    let r = py.detach(|| {
        run_in_pool(n_threads, || {
            greedy::greedy_tin(z, rows, cols, max_error, max_triangles, shared_edges)
        })
    })?;
    let n = r.grid.len();
    let grid = Array2::from_shape_vec(
        (n, 2),
        r.grid
            .iter()
            .flat_map(|g| [g[0] as i64, g[1] as i64])
            .collect(),
    )
    .expect("n x 2 grid positions");
    Ok((
        grid.into_pyarray(py),
        r.z.into_pyarray(py),
        triangles_array(r.triangles).into_pyarray(py),
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
    let vals: Vec<f64> = values.as_array().iter().copied().collect();
    let g = py.detach(|| {
        run_in_pool(n_threads, || {
            interpolate::grid_from_points(&view, &vals, rows, cols, transform, m)
        })
    })?;
    let a = Array2::from_shape_vec((rows, cols), g)
        .map_err(|_| PyValueError::new_err("shape: internal: size mismatch"))?;
    Ok(a.into_pyarray(py))
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
    let p: Vec<[f64; 2]> = xy
        .as_array()
        .rows()
        .into_iter()
        .map(|r| [r[0], r[1]])
        .collect();
    let zs: Vec<f64> = z.as_array().iter().copied().collect();
    let t: Vec<[i64; 3]> = triangles
        .as_array()
        .rows()
        .into_iter()
        .map(|r| [r[0], r[1], r[2]])
        .collect();
    let g = py.detach(|| run_in_pool(n_threads, || greedy::rasterize(&p, &zs, &t, rows, cols)))?;
    let a = Array2::from_shape_vec((rows, cols), g)
        .map_err(|_| PyValueError::new_err("shape: internal: size mismatch"))?;
    Ok(a.into_pyarray(py))
}
