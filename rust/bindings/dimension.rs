//! Bindings of `crate::dimension`.
use crate::dimension::{affine, boxcount, dbc, higuchi, points};
use crate::parallel::run_in_pool;
use numpy::ndarray::Array2;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyReadonlyArrayDyn, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

fn contiguous<'a, T: numpy::Element>(a: &'a PyReadonlyArrayDyn<'_, T>) -> PyResult<&'a [T]> {
    a.as_slice()
        .map_err(|_| PyValueError::new_err("data: internal: array must be C-contiguous"))
}

fn counts_array<T: Copy>(counts: &[Vec<T>]) -> Array2<T> {
    let (n, k) = (counts.len(), counts.first().map_or(0, |c| c.len()));
    let flat: Vec<T> = counts.iter().flatten().copied().collect();
    Array2::from_shape_vec((n, k), flat).expect("rectangular counts")
}

/// Binary lattice box counts. Returns (box_sizes, counts[n_sizes, n_lattices],
/// n_foreground, bbox_min, bbox_max) with the bbox on the last `ndim` axes.
#[pyfunction]
#[pyo3(signature = (data, box_sizes, offsets, anchor_bbox, n_threads=None))]
#[allow(clippy::type_complexity)]
fn box_count_binary<'py>(
    py: Python<'py>,
    data: PyReadonlyArrayDyn<'py, u8>,
    box_sizes: Vec<usize>,
    offsets: usize,
    anchor_bbox: bool,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray2<u64>>,
    u64,
    Vec<usize>,
    Vec<usize>,
)> {
    let dims = data.shape().to_vec();
    let slice = contiguous(&data)?;
    let ndim = dims.len();
    let anchor = if anchor_bbox {
        boxcount::Anchor::BoundingBox
    } else {
        boxcount::Anchor::Array
    };
    let r = py.detach(|| {
        run_in_pool(n_threads, || {
            let vol = boxcount::ByteVolume::new(slice, &dims)?;
            boxcount::box_count(&vol, ndim, &box_sizes, offsets, anchor)
        })
    })?;
    let sizes: Vec<u64> = r.box_sizes.iter().map(|&s| s as u64).collect();
    let lo = r.bbox_min[3 - ndim..].to_vec();
    let hi = r.bbox_max[3 - ndim..].to_vec();
    Ok((
        sizes.into_pyarray(py),
        counts_array(&r.counts).into_pyarray(py),
        r.n_foreground,
        lo,
        hi,
    ))
}

/// Box counts of an (N, d) point set. Returns (box_sizes, counts[n_sizes, n_lattices]).
#[pyfunction]
#[pyo3(signature = (points, box_sizes, offsets, n_threads=None))]
#[allow(clippy::type_complexity)]
fn box_count_points<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    box_sizes: Vec<f64>,
    offsets: usize,
    n_threads: Option<usize>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<u64>>)> {
    let (n, d) = (points.shape()[0], points.shape()[1]);
    let slice = points
        .as_slice()
        .map_err(|_| PyValueError::new_err("points: internal: must be C-contiguous"))?;
    let r = py.detach(|| {
        run_in_pool(n_threads, || {
            points::point_box_count(slice, n, d, &box_sizes, offsets)
        })
    })?;
    Ok((
        r.box_sizes.into_pyarray(py),
        counts_array(&r.counts).into_pyarray(py),
    ))
}

/// Differential box counts of a 2D float32 or float64 image (NaN = nodata).
/// Returns (box_sizes, counts[n_sizes, n_lattices]).
#[pyfunction]
#[pyo3(signature = (data, box_sizes, offsets, z0, z_unit, n_threads=None))]
#[allow(clippy::type_complexity)]
fn dbc_count<'py>(
    py: Python<'py>,
    data: &Bound<'py, PyAny>,
    box_sizes: Vec<usize>,
    offsets: usize,
    z0: f64,
    z_unit: f64,
    n_threads: Option<usize>,
) -> PyResult<(Bound<'py, PyArray1<u64>>, Bound<'py, PyArray2<f64>>)> {
    let r = if let Ok(a) = data.extract::<PyReadonlyArray2<'py, f32>>() {
        let (rows, cols) = (a.shape()[0], a.shape()[1]);
        let s = a
            .as_slice()
            .map_err(|_| PyValueError::new_err("data: internal: must be C-contiguous"))?;
        py.detach(|| {
            run_in_pool(n_threads, || {
                dbc::dbc_count(s, rows, cols, &box_sizes, offsets, z0, z_unit)
            })
        })?
    } else if let Ok(a) = data.extract::<PyReadonlyArray2<'py, f64>>() {
        let (rows, cols) = (a.shape()[0], a.shape()[1]);
        let s = a
            .as_slice()
            .map_err(|_| PyValueError::new_err("data: internal: must be C-contiguous"))?;
        py.detach(|| {
            run_in_pool(n_threads, || {
                dbc::dbc_count(s, rows, cols, &box_sizes, offsets, z0, z_unit)
            })
        })?
    } else {
        return Err(PyTypeError::new_err(
            "data: expected a 2D float32 or float64 array",
        ));
    };
    let sizes: Vec<u64> = r.box_sizes.iter().map(|&s| s as u64).collect();
    Ok((
        sizes.into_pyarray(py),
        counts_array(&r.counts).into_pyarray(py),
    ))
}

/// Mean height range of complete columns (profile: shape (1, n)).
/// Returns (mean_range, n_columns) per box size.
#[pyfunction]
#[pyo3(signature = (data, box_sizes, n_threads=None))]
#[allow(clippy::type_complexity)]
fn column_ranges<'py>(
    py: Python<'py>,
    data: PyReadonlyArray2<'py, f64>,
    box_sizes: Vec<usize>,
    n_threads: Option<usize>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u64>>)> {
    let (rows, cols) = (data.shape()[0], data.shape()[1]);
    let s = data
        .as_slice()
        .map_err(|_| PyValueError::new_err("data: internal: must be C-contiguous"))?;
    let (m, n) = py.detach(|| {
        run_in_pool(n_threads, || {
            affine::column_ranges(s, rows, cols, &box_sizes)
        })
    })?;
    Ok((m.into_pyarray(py), n.into_pyarray(py)))
}

/// Higuchi curve lengths L(k), k = 1 ..= k_max, of a gap-free profile.
#[pyfunction]
#[pyo3(signature = (data, k_max, n_threads=None))]
fn higuchi_lengths<'py>(
    py: Python<'py>,
    data: PyReadonlyArrayDyn<'py, f64>,
    k_max: usize,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let x = contiguous(&data)?;
    let l = py.detach(|| run_in_pool(n_threads, || higuchi::higuchi_lengths(x, k_max)))?;
    Ok(l.into_pyarray(py))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(higuchi_lengths, m)?)?;
    m.add_function(wrap_pyfunction!(box_count_binary, m)?)?;
    m.add_function(wrap_pyfunction!(box_count_points, m)?)?;
    m.add_function(wrap_pyfunction!(dbc_count, m)?)?;
    m.add_function(wrap_pyfunction!(column_ranges, m)?)?;
    Ok(())
}
