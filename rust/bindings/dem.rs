//! Bindings of `crate::dem` (fractal resampling).
use crate::dem::resample::{self, ResampleParams, Support};
use crate::parallel::run_in_pool;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

/// Fractal resampling by `2^levels`; `detail[l]` turns the residual of level
/// `l` on. `origin` and `global_cols` place a tile in the whole input grid.
#[pyfunction]
#[pyo3(signature = (dem, hurst, sigma, levels, area, seed, detail, origin=(0, 0), global_cols=0, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn fractal_resample<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    hurst: PyReadonlyArray2<'py, f64>,
    sigma: PyReadonlyArray2<'py, f64>,
    levels: u32,
    area: bool,
    seed: u64,
    detail: Vec<bool>,
    origin: (u64, u64),
    global_cols: u64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (d, h, s) = (dem.as_array(), hurst.as_array(), sigma.as_array());
    let p = ResampleParams {
        levels,
        support: if area { Support::Area } else { Support::Point },
        seed,
        detail,
        origin,
        global_cols: if global_cols == 0 {
            d.dim().1 as u64
        } else {
            global_cols
        },
    };
    let out = py.detach(|| run_in_pool(n_threads, || resample::resample(d, h, s, &p)))?;
    Ok(out.into_pyarray(py))
}

/// Full-stencil kriging weights (16) and residual standard deviation (unit
/// sigma, coarse spacing 1) of stencil `which` (0 diamond, 1 square, 2-5 area
/// quadrants) at `hurst`, and the stencil's source offsets.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn resample_stencil(which: usize, hurst: f64) -> PyResult<(Vec<f64>, f64, Vec<(isize, isize)>)> {
    if which > 5 {
        return Err(pyo3::exceptions::PyValueError::new_err(
            "which: expected 0 to 5",
        ));
    }
    let (w, sd) = resample::table_at(which, hurst);
    let st = match which {
        0 => resample::diamond_stencil(),
        1 => resample::square_stencil(),
        q => resample::area_stencil((q - 2) / 2, (q - 2) % 2),
    };
    Ok((w.to_vec(), sd, st.offsets.to_vec()))
}

pub(super) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fractal_resample, m)?)?;
    m.add_function(wrap_pyfunction!(resample_stencil, m)?)?;
    m.add("RESAMPLE_HALO", resample::HALO)?;
    Ok(())
}
