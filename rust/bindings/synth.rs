//! Bindings of `crate::synth`.
use super::convert::{array1, c_order, run};
use super::progress::{counter, ProgressCounter};
use crate::rng;
use crate::synth::additions::{self, AdditionsParams};
use crate::synth::davies_harte;
use crate::synth::midpoint::{self, RefineParams};
use crate::synth::spectral;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

/// `n` standard normals of stream `(seed, stream)` at indices `start ..`.
#[pyfunction]
#[pyo3(signature = (n, seed, stream, start=0, n_threads=None, progress=None))]
fn normal_noise<'py>(
    py: Python<'py>,
    n: usize,
    seed: u64,
    stream: u64,
    start: u64,
    n_threads: Option<usize>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let pr = counter(progress);
    let v = run(py, n_threads, || {
        let mut v = crate::buffers::try_zeroed(n, "n")?;
        rng::fill_normal(&mut v, seed, stream, start, pr.as_deref());
        Ok(v)
    })?;
    Ok(v.into_pyarray(py))
}

#[allow(clippy::too_many_arguments)]
fn params(
    hurst: f64,
    sigma: f64,
    coarse_spacing: f64,
    additions: bool,
    periodic: bool,
    seed: u64,
    first_level: u32,
) -> RefineParams {
    RefineParams {
        hurst,
        sigma,
        coarse_spacing,
        additions,
        periodic,
        seed,
        level: first_level,
        origin: (0, 0),
        global_cols: 0,
    }
}

/// Refine a 1D profile `levels` times by factors of 2 (midpoint displacement,
/// optionally with random additions).
#[pyfunction]
#[pyo3(signature = (coarse, levels, hurst, sigma, coarse_spacing, additions, seed, first_level=0, n_threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn midpoint_refine_1d<'py>(
    py: Python<'py>,
    coarse: PyReadonlyArray1<'py, f64>,
    levels: u32,
    hurst: f64,
    sigma: f64,
    coarse_spacing: f64,
    additions: bool,
    seed: u64,
    first_level: u32,
    n_threads: Option<usize>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let pr = counter(progress);
    let c: Vec<f64> = coarse.as_array().to_vec();
    let p = params(
        hurst,
        sigma,
        coarse_spacing,
        additions,
        false,
        seed,
        first_level,
    );
    let v = run(py, n_threads, || {
        midpoint::refine_1d_levels(&c, levels, &p, pr.as_deref())
    })?;
    Ok(v.into_pyarray(py))
}

/// Refine a 2D grid `levels` times by factors of 2 (diamond-square, optionally
/// with random additions; periodic: torus).
#[pyfunction]
#[pyo3(signature = (coarse, levels, hurst, sigma, coarse_spacing, additions, periodic, seed, first_level=0, n_threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn midpoint_refine_2d<'py>(
    py: Python<'py>,
    coarse: PyReadonlyArray2<'py, f64>,
    levels: u32,
    hurst: f64,
    sigma: f64,
    coarse_spacing: f64,
    additions: bool,
    periodic: bool,
    seed: u64,
    first_level: u32,
    n_threads: Option<usize>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let pr = counter(progress);
    let c = coarse.as_array();
    let p = params(
        hurst,
        sigma,
        coarse_spacing,
        additions,
        periodic,
        seed,
        first_level,
    );
    let v = run(py, n_threads, || {
        midpoint::refine_2d_levels(c, levels, &p, pr.as_deref())
    })?;
    Ok(v.into_pyarray(py))
}

/// Refine a 2D grid `levels` times by successive random additions with the
/// 4-point rule of tension `tension` and the variances `[a2, c1, c2, e]` in
/// units of `sigma^2 s^(2H)` (see `crate::synth::additions`). `shape`:
/// keep only the top-left `(rows, cols)` of the result (computed alone).
#[pyfunction]
#[pyo3(signature = (coarse, levels, hurst, sigma, coarse_spacing, tension, variances, periodic, seed, first_level=0, n_threads=None, shape=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn additions_refine_2d<'py>(
    py: Python<'py>,
    coarse: PyReadonlyArray2<'py, f64>,
    levels: u32,
    hurst: f64,
    sigma: f64,
    coarse_spacing: f64,
    tension: f64,
    variances: [f64; 4],
    periodic: bool,
    seed: u64,
    first_level: u32,
    n_threads: Option<usize>,
    shape: Option<(usize, usize)>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let pr = counter(progress);
    let c = coarse.as_array();
    let p = AdditionsParams {
        hurst,
        sigma,
        coarse_spacing,
        tension,
        variances,
        periodic,
        seed,
        level: first_level,
        origin: (0, 0),
        global_cols: 0,
    };
    let v = run(py, n_threads, || {
        additions::refine_2d_levels(c, levels, &p, shape, pr.as_deref())
    })?;
    Ok(v.into_pyarray(py))
}

/// `sqrt(lambda_k / 2m)`, `k = 0 .. m`, of the circulant embedding of unit fGn.
#[pyfunction]
#[pyo3(signature = (m, hurst, n_threads=None))]
fn fgn_sqrt_eigenvalues<'py>(
    py: Python<'py>,
    m: usize,
    hurst: f64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let v = run(py, n_threads, || {
        davies_harte::fgn_sqrt_eigenvalues(m, hurst)
    })?;
    Ok(v.into_pyarray(py))
}

/// Amplitude filter of 2D spectral synthesis on the `rfft2` grid of an
/// `(n0, n1)` field: aliased fBm density with the low-frequency
/// compensation, unit lag-one variance (`crate::synth::spectral`).
#[pyfunction]
#[pyo3(signature = (n0, n1, hurst, n_threads=None))]
fn spectral_filter_2d<'py>(
    py: Python<'py>,
    n0: usize,
    n1: usize,
    hurst: f64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let v = run(py, n_threads, || spectral::filter_2d(n0, n1, hurst))?;
    Ok(v.into_pyarray(py))
}

/// Exact fBm path of `n` samples (Davies-Harte) from `fgn_sqrt_eigenvalues`.
#[pyfunction]
#[pyo3(signature = (sqrt_eig, n, seed, stream, n_threads=None, progress=None))]
fn davies_harte_fbm<'py>(
    py: Python<'py>,
    sqrt_eig: PyReadonlyArray1<'py, f64>,
    n: usize,
    seed: u64,
    stream: u64,
    n_threads: Option<usize>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let pr = counter(progress);
    let s = c_order(&sqrt_eig);
    let v = run(py, n_threads, || {
        davies_harte::fbm_from_eigenvalues(&s.data, n, seed, stream, pr.as_deref())
    })?;
    Ok(array1(py, v))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(normal_noise, m)?)?;
    m.add_function(wrap_pyfunction!(midpoint_refine_1d, m)?)?;
    m.add_function(wrap_pyfunction!(midpoint_refine_2d, m)?)?;
    m.add_function(wrap_pyfunction!(additions_refine_2d, m)?)?;
    m.add_function(wrap_pyfunction!(fgn_sqrt_eigenvalues, m)?)?;
    m.add_function(wrap_pyfunction!(davies_harte_fbm, m)?)?;
    m.add_function(wrap_pyfunction!(spectral_filter_2d, m)?)?;
    Ok(())
}
