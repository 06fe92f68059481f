//! Bindings of `crate::dimension`.
use super::convert::{array1, c_order, rows_array, run, run_on_grid, FloatArray2};
use crate::dimension::blanket::blanket_areas;
use crate::dimension::mass::mass_curve;
use crate::dimension::{affine, boxcount, dbc, higuchi, points};
use crate::with_float;
use numpy::{PyArray1, PyArray2, PyReadonlyArray2, PyReadonlyArrayDyn};
use pyo3::prelude::*;

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
    let a = c_order(&data);
    let (slice, dims) = (&a.data[..], &a.shape);
    let ndim = dims.len();
    let anchor = if anchor_bbox {
        boxcount::Anchor::BoundingBox
    } else {
        boxcount::Anchor::Array
    };
    let r = run(py, n_threads, || {
        let vol = boxcount::ByteVolume::new(slice, dims)?;
        boxcount::box_count(&vol, ndim, &box_sizes, offsets, anchor)
    })?;
    let sizes: Vec<u64> = r.box_sizes.iter().map(|&s| s as u64).collect();
    let lo = r.bbox_min[3 - ndim..].to_vec();
    let hi = r.bbox_max[3 - ndim..].to_vec();
    Ok((
        array1(py, sizes),
        rows_array(py, &r.counts)?,
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
    let p = c_order(&points);
    let (n, d) = p.rows_cols();
    let r = run(py, n_threads, || {
        points::point_box_count(&p.data, n, d, &box_sizes, offsets)
    })?;
    Ok((array1(py, r.box_sizes), rows_array(py, &r.counts)?))
}

/// Default lattice counts of a point set, level by level (see
/// `points::point_lattice_levels`). Returns (sizes, aligned, shifted,
/// shifted_inside).
#[pyfunction]
#[pyo3(signature = (points, base, k_first, min_occupancy, max_levels, n_threads=None))]
#[allow(clippy::type_complexity)]
fn box_count_point_levels<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    base: u64,
    k_first: u32,
    min_occupancy: f64,
    max_levels: usize,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    let p = c_order(&points);
    let (n, d) = p.rows_cols();
    let lv = run(py, n_threads, || {
        points::point_lattice_levels(&p.data, n, d, base, k_first, min_occupancy, max_levels)
    })?;
    Ok((
        array1(py, lv.iter().map(|l| l.size).collect()),
        array1(py, lv.iter().map(|l| l.aligned).collect()),
        array1(py, lv.iter().map(|l| l.shifted).collect()),
        array1(py, lv.iter().map(|l| l.shifted_inside).collect()),
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
    let r = with_float!(FloatArray2::extract(data, "data")?, |a| {
        run_on_grid(py, &a, n_threads, |z, rows, cols| {
            dbc::dbc_count(z, rows, cols, &box_sizes, offsets, z0, z_unit)
        })?
        .0
    });
    let sizes: Vec<u64> = r.box_sizes.iter().map(|&s| s as u64).collect();
    Ok((array1(py, sizes), rows_array(py, &r.counts)?))
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
    let ((m, n), _) = run_on_grid(py, &data, n_threads, |z, rows, cols| {
        affine::column_ranges(z, rows, cols, &box_sizes)
    })?;
    Ok((array1(py, m), array1(py, n)))
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
    let x = c_order(&data);
    let l = run(py, n_threads, || higuchi::higuchi_lengths(&x.data, k_max))?;
    Ok(array1(py, l))
}

/// Image-wide P(m, L) curve N(L) of a grayscale image (NaN = no point).
#[pyfunction]
#[pyo3(signature = (image, box_sizes, z_scale, n_threads=None))]
fn mass_curve_image<'py>(
    py: Python<'py>,
    image: PyReadonlyArray2<'py, f64>,
    box_sizes: Vec<usize>,
    z_scale: f64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (n, _) = run_on_grid(py, &image, n_threads, |z, rows, cols| {
        mass_curve(z, rows, cols, &box_sizes, z_scale)
    })?;
    Ok(array1(py, n))
}

/// Image-wide covering-blanket areas A(e), e = 1 ..= eps_max, and the number
/// of valid pixels.
#[pyfunction]
#[pyo3(signature = (image, eps_max, z_scale, n_threads=None))]
fn blanket_areas_image<'py>(
    py: Python<'py>,
    image: PyReadonlyArray2<'py, f64>,
    eps_max: usize,
    z_scale: f64,
    n_threads: Option<usize>,
) -> PyResult<(Bound<'py, PyArray1<f64>>, usize)> {
    let ((a, n), _) = run_on_grid(py, &image, n_threads, |z, rows, cols| {
        blanket_areas(z, rows, cols, eps_max, z_scale)
    })?;
    Ok((array1(py, a), n))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(higuchi_lengths, m)?)?;
    m.add_function(wrap_pyfunction!(box_count_binary, m)?)?;
    m.add_function(wrap_pyfunction!(box_count_points, m)?)?;
    m.add_function(wrap_pyfunction!(box_count_point_levels, m)?)?;
    m.add_function(wrap_pyfunction!(dbc_count, m)?)?;
    m.add_function(wrap_pyfunction!(column_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(mass_curve_image, m)?)?;
    m.add_function(wrap_pyfunction!(blanket_areas_image, m)?)?;
    Ok(())
}
