//! The pieces every binding is made of, so that a binding is a few lines:
//!
//! * arrays in: [`c_order`] gives the data of a NumPy array of any strides
//!   (C-ordered, Fortran-ordered, negative strides, sliced) as a row-major
//!   slice with its shape, borrowed when the array is already C-contiguous
//!   and copied once otherwise;
//! * one dtype dispatch: [`FloatArray2`] takes a 2D float32 or float64
//!   array, and [`with_float!`](crate::with_float) runs one generic body on
//!   either;
//! * the kernel off the GIL: [`run`] releases the GIL, runs the kernel in a
//!   pool of `n_threads` threads with panics caught, and maps a
//!   [`CoreError`](crate::error::CoreError) to the Python exception;
//! * arrays out: [`array1`], [`array2`] and [`array3`] hand a Rust `Vec` to
//!   NumPy without a copy;
//! * the common case of all three: [`run_on_grid`] runs
//!   `kernel(data, rows, cols)` on a 2D array off the GIL.
use std::borrow::Cow;

use crate::error::{CoreError, CoreResult};
use crate::parallel::run_in_pool;
use numpy::ndarray::{Array1, Array2, Array3, Dimension};
use numpy::{
    Element, IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray, PyReadonlyArray2,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// The data of an array in row-major order with its shape.
pub struct CArray<'a, T: Clone> {
    /// The elements, row-major (borrowed from NumPy, or a copy).
    pub data: Cow<'a, [T]>,
    /// The array's shape.
    pub shape: Vec<usize>,
}

impl<T: Clone> CArray<'_, T> {
    /// `(rows, cols)` of a 2D array.
    pub fn rows_cols(&self) -> (usize, usize) {
        (self.shape[0], self.shape[1])
    }
}

/// The data of `a` in row-major (C) order: borrowed when `a` is
/// C-contiguous, copied once in its logical order otherwise (a
/// Fortran-ordered, strided or negatively strided array), so kernels that
/// read a flat row-major slice see the same values for every layout.
pub fn c_order<'a, T: Element + Clone, D: Dimension>(
    a: &'a PyReadonlyArray<'_, T, D>,
) -> CArray<'a, T> {
    let shape = a.shape().to_vec();
    let data = match a.as_slice() {
        // `as_slice` also accepts Fortran order: take it only for C order
        Ok(s) if a.is_c_contiguous() => Cow::Borrowed(s),
        _ => Cow::Owned(a.as_array().iter().cloned().collect()),
    };
    CArray { data, shape }
}

/// Release the GIL and run `f` in a pool of `n_threads` threads (panics
/// caught), mapping a core error to its Python exception.
pub fn run<T, F>(py: Python<'_>, n_threads: Option<usize>, f: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce() -> CoreResult<T> + Send,
{
    Ok(py.detach(|| run_in_pool(n_threads, f))?)
}

/// Release the GIL and run `kernel(data, rows, cols)` in the pool on a 2D
/// array read in row-major order ([`c_order`]: borrowed when C-contiguous,
/// copied once otherwise); returns the kernel's result and `(rows, cols)`.
pub fn run_on_grid<T, R, F>(
    py: Python<'_>,
    a: &PyReadonlyArray2<'_, T>,
    n_threads: Option<usize>,
    kernel: F,
) -> PyResult<(R, (usize, usize))>
where
    T: Element + Clone + Sync,
    R: Send,
    F: FnOnce(&[T], usize, usize) -> CoreResult<R> + Send,
{
    let z = c_order(a);
    let (rows, cols) = z.rows_cols();
    let r = run(py, n_threads, || kernel(&z.data, rows, cols))?;
    Ok((r, (rows, cols)))
}

fn shape_error(what: &str, len: usize, shape: &[usize]) -> PyErr {
    CoreError::Internal(format!(
        "{what}: {len} values do not fill the shape {shape:?}"
    ))
    .into()
}

/// A 1D NumPy array owning `v` (no copy).
pub fn array1<T: Element>(py: Python<'_>, v: Vec<T>) -> Bound<'_, PyArray1<T>> {
    Array1::from_vec(v).into_pyarray(py)
}

/// A 2D NumPy array of shape `(rows, cols)` owning `v` (row-major, no copy).
pub fn array2<T: Element>(
    py: Python<'_>,
    (rows, cols): (usize, usize),
    v: Vec<T>,
) -> PyResult<Bound<'_, PyArray2<T>>> {
    let n = v.len();
    Array2::from_shape_vec((rows, cols), v)
        .map(|a| a.into_pyarray(py))
        .map_err(|_| shape_error("array", n, &[rows, cols]))
}

/// A 3D NumPy array of shape `(a, b, c)` owning `v` (row-major, no copy).
pub fn array3<T: Element>(
    py: Python<'_>,
    (a, b, c): (usize, usize, usize),
    v: Vec<T>,
) -> PyResult<Bound<'_, PyArray3<T>>> {
    let n = v.len();
    Array3::from_shape_vec((a, b, c), v)
        .map(|x| x.into_pyarray(py))
        .map_err(|_| shape_error("array", n, &[a, b, c]))
}

/// A 2D `(n, k)` NumPy array from rows of equal length.
pub fn rows_array<'py, T: Element + Copy>(
    py: Python<'py>,
    rows: &[Vec<T>],
) -> PyResult<Bound<'py, PyArray2<T>>> {
    let (n, k) = (rows.len(), rows.first().map_or(0, |r| r.len()));
    if rows.iter().any(|r| r.len() != k) {
        return Err(CoreError::Internal("rows of unequal length".into()).into());
    }
    array2(py, (n, k), rows.iter().flatten().copied().collect())
}

/// The rows of an `(n, N)` array as fixed-size rows (any strides); `name`
/// is the parameter named in the `ValueError` for another shape.
pub fn rows_in<T: Element + Copy, const N: usize>(
    a: &PyReadonlyArray2<'_, T>,
    name: &str,
) -> PyResult<Vec<[T; N]>> {
    let v = a.as_array();
    if v.ncols() != N {
        return Err(PyValueError::new_err(format!(
            "{name}: expected shape (n, {N}), got {:?}",
            a.shape()
        )));
    }
    Ok(v.rows()
        .into_iter()
        .map(|r| std::array::from_fn(|k| r[k]))
        .collect())
}

/// A 2D image of float32 or float64 samples: the one dtype dispatch of the
/// map and DEM kernels, which read either in place.
pub enum FloatArray2<'py> {
    F32(PyReadonlyArray2<'py, f32>),
    F64(PyReadonlyArray2<'py, f64>),
}

impl<'py> FloatArray2<'py> {
    /// Extract `obj` as a 2D float32 or float64 array; `name` is the
    /// parameter named in the `TypeError` otherwise.
    pub fn extract(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Self> {
        if let Ok(a) = obj.extract::<PyReadonlyArray2<'py, f32>>() {
            Ok(FloatArray2::F32(a))
        } else if let Ok(a) = obj.extract::<PyReadonlyArray2<'py, f64>>() {
            Ok(FloatArray2::F64(a))
        } else {
            Err(PyTypeError::new_err(format!(
                "{name}: expected a 2D float32 or float64 array"
            )))
        }
    }
}

/// Run one body on a [`FloatArray2`] of either dtype:
/// `with_float!(image, |a| kernel(&c_order(&a)))`, where `a` is the
/// `PyReadonlyArray2` of the matching element type.
#[macro_export]
macro_rules! with_float {
    ($image:expr, |$a:ident| $body:expr) => {
        match $image {
            $crate::bindings::convert::FloatArray2::F32($a) => $body,
            $crate::bindings::convert::FloatArray2::F64($a) => $body,
        }
    };
}
