//! Bindings of `crate::dem`: shaded relief, fractal resampling and its local analysis.
use super::convert::{array2, array3, c_order, run};
use crate::dem::analysis::{self, AnalysisParams, AreaTable};
use crate::dem::hillshade::{self, ShadeParams};
use crate::dem::model_nodes;
use crate::dem::resample::{self, ResampleParams, Support};
use crate::error::CoreError;
use numpy::ndarray::{ArrayView3, ArrayViewD, Axis, Ix3};
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3,
    PyReadonlyArrayDyn,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Hillshade in [0, 1] (NaN = nodata); `dx` per row, `dy` scalar.
#[pyfunction]
#[pyo3(signature = (dem, dx, dy, azimuth, altitude, z_factor, multidirectional, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn hillshade_f64<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    dx: Vec<f64>,
    dy: f64,
    azimuth: f64,
    altitude: f64,
    z_factor: f64,
    multidirectional: bool,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let z = dem.as_array();
    let p = ShadeParams {
        azimuth,
        altitude,
        z_factor,
        multidirectional,
    };
    let v = run(py, n_threads, || hillshade::hillshade(z, &dx, dy, &p))?;
    Ok(v.into_pyarray(py))
}

/// `gdaldem hillshade -compute_edges` bytes of a float32 DEM (NaN = nodata)
/// with cells `dx` by `dy`, bit for bit.
#[pyfunction]
#[pyo3(signature = (dem, dx, dy, azimuth, altitude, z_factor, multidirectional, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn hillshade_gdal_byte<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f32>,
    dx: f64,
    dy: f64,
    azimuth: f64,
    altitude: f64,
    z_factor: f64,
    multidirectional: bool,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<u8>>> {
    let z = dem.as_array();
    let p = ShadeParams {
        azimuth,
        altitude,
        z_factor,
        multidirectional,
    };
    let v = run(py, n_threads, || {
        hillshade::hillshade_gdal_byte(z, dx, dy, &p)
    })?;
    Ok(v.into_pyarray(py))
}

/// GDAL's byte encoding of a reflectance array: round(1 + 254 L), 0 for NaN.
#[pyfunction]
#[pyo3(signature = (shade, n_threads=None))]
fn shade_to_byte<'py>(
    py: Python<'py>,
    shade: PyReadonlyArray2<'py, f32>,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<u8>>> {
    let a = c_order(&shade);
    let b = run(py, n_threads, || Ok(hillshade::to_byte(&a.data)))?;
    array2(py, a.rows_cols(), b)
}

/// Fractal resampling by `2^levels`; `detail[l]` turns the residual of level
/// `l` on. `hurst` and `sigma`: 2D maps (or 1 x 1) for every level, or 3D
/// `(levels, rows, cols)` (or `(levels, 1, 1)`) per level. `origin` and
/// `global_cols` place a tile in the whole input grid.
#[pyfunction]
#[pyo3(signature = (dem, hurst, sigma, levels, area, seed, detail, origin=(0, 0), global_cols=0, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn fractal_resample<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    hurst: PyReadonlyArrayDyn<'py, f64>,
    sigma: PyReadonlyArrayDyn<'py, f64>,
    levels: u32,
    area: bool,
    seed: u64,
    detail: Vec<bool>,
    origin: (u64, u64),
    global_cols: u64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let d = dem.as_array();
    let h = per_level(hurst.as_array(), "hurst")?;
    let s = per_level(sigma.as_array(), "sigma")?;
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
    let out = run(py, n_threads, || resample::resample_levels(d, h, s, &p))?;
    Ok(out.into_pyarray(py))
}

/// A 2D parameter map as one level, or a 3D stack of levels.
fn per_level<'a>(a: ArrayViewD<'a, f64>, name: &str) -> PyResult<ArrayView3<'a, f64>> {
    let a = if a.ndim() == 2 {
        a.insert_axis(Axis(0))
    } else {
        a
    };
    a.into_dimensionality::<Ix3>().map_err(|_| {
        PyValueError::new_err(format!(
            "{name}: expected a 2D map or a 3D stack (levels, rows, cols)"
        ))
    })
}

/// Local `H` and `sigma` maps of a DEM block with a NaN halo of
/// `pad_width(half, step)` cells (`border` of them virtual), on the block
/// without its halo, and the counts of clipped and of valid pixels.
/// `table = (hurst, ratio, gamma1)` selects area support.
#[pyfunction]
#[pyo3(signature = (dem, half, step, border, hurst_range, table=None, n_threads=None))]
#[allow(clippy::type_complexity, clippy::too_many_arguments)]
fn resample_local_maps<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    half: usize,
    step: usize,
    border: usize,
    hurst_range: (f64, f64),
    table: Option<(
        PyReadonlyArray1<'py, f64>,
        PyReadonlyArray1<'py, f64>,
        PyReadonlyArray1<'py, f64>,
    )>,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    u64,
    u64,
)> {
    let z = dem.as_array();
    let t = table
        .as_ref()
        .map(|(h, r, g)| (c_order(h), c_order(r), c_order(g)));
    let p = AnalysisParams {
        half,
        step,
        border,
        hurst_range,
        area: t.as_ref().map(|(h, r, g)| AreaTable {
            hurst: &h.data,
            ratio: &r.data,
            gamma1: &g.data,
        }),
    };
    let m = run(py, n_threads, || analysis::local_maps(z, &p))?;
    Ok((
        m.hurst.into_pyarray(py),
        m.sigma.into_pyarray(py),
        m.n_clipped,
        m.n_valid,
    ))
}

/// Full-stencil kriging weights (16) and residual standard deviation (unit
/// sigma, coarse spacing 1) of stencil `which` (0 diamond, 1 square) in its
/// first phase (no same-step neighbours) at `hurst`, and the stencil's
/// source offsets.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn resample_stencil(
    py: Python<'_>,
    which: usize,
    hurst: f64,
) -> PyResult<(Vec<f64>, f64, Vec<(isize, isize)>)> {
    run(py, Some(1), || {
        let st = match which {
            0 => resample::diamond_stencil(),
            1 => resample::square_stencil(),
            _ => return Err(CoreError::invalid("which", "expected 0 or 1")),
        };
        let (w, sd) = resample::table_at(which, hurst);
        Ok((w.to_vec(), sd, st.offsets.to_vec()))
    })
}

/// Node sums of squared increments and their counts at every lag of `lags`
/// over the windows of half side `half` of a NaN-padded DEM block (the
/// scale-aware model's analysis): `(sums, counts, k0r, k0c)`, the arrays
/// `(lags, node rows, node cols)`, node `(a, b)` at pixel
/// `((k0r + a) step, (k0c + b) step)`.
#[pyfunction]
#[pyo3(signature = (dem, half, step, lags, n_threads=None))]
#[allow(clippy::type_complexity)]
fn resample_node_variograms<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    half: usize,
    step: usize,
    lags: Vec<usize>,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f64>>,
    usize,
    usize,
)> {
    let z = c_order(&dem);
    let shape = z.rows_cols();
    let nv = run(py, n_threads, || {
        model_nodes::node_variograms(&z.data, shape, half, step, &lags)
    })?;
    let dims = (lags.len(), nv.rows, nv.cols);
    Ok((
        array3(py, dims, nv.sums)?,
        array3(py, dims, nv.counts)?,
        nv.k0r,
        nv.k0c,
    ))
}

/// Bilinear interpolation of node maps `(maps, node rows, node cols)` (node
/// `(a, b)` at pixel `((k0r + a) step, (k0c + b) step)`) to the pixels of a
/// block of `shape` without a border of `t` cells: `(maps, rows - 2t, cols -
/// 2t)`.
#[pyfunction]
#[pyo3(signature = (nodes, k0r, k0c, shape, t, step, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn resample_interp_nodes<'py>(
    py: Python<'py>,
    nodes: PyReadonlyArray3<'py, f64>,
    k0r: usize,
    k0c: usize,
    shape: (usize, usize),
    t: usize,
    step: usize,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let v = nodes.as_array();
    let m = v.dim().0;
    let out = run(py, n_threads, || {
        model_nodes::interp_nodes(v, (k0r, k0c), shape, t, step)
    })?;
    let (or, oc) = (shape.0.saturating_sub(2 * t), shape.1.saturating_sub(2 * t));
    array3(py, (m, or, oc), out)
}

/// The local amplitude factor of the scale-aware model's detail at the
/// pixels of a NaN-padded block without a border of `t` cells:
/// `sqrt(g / d1)`, `g` the mean squared lag-1 increment of the 3 x 3 cells
/// around each pixel, `d1` the window's (`(rows - 2t, cols - 2t)`); 1 where
/// not finite.
#[pyfunction]
#[pyo3(signature = (dem, d1, t, n_threads=None))]
fn resample_local_amplitude<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    d1: PyReadonlyArray2<'py, f64>,
    t: usize,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let z = c_order(&dem);
    let d = c_order(&d1);
    let shape = z.rows_cols();
    let out = run(py, n_threads, || {
        model_nodes::local_amplitude(&z.data, shape, t, &d.data)
    })?;
    let (or, oc) = (shape.0.saturating_sub(2 * t), shape.1.saturating_sub(2 * t));
    array2(py, (or, oc), out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(hillshade_f64, m)?)?;
    m.add_function(wrap_pyfunction!(shade_to_byte, m)?)?;
    m.add_function(wrap_pyfunction!(hillshade_gdal_byte, m)?)?;
    m.add_function(wrap_pyfunction!(fractal_resample, m)?)?;
    m.add_function(wrap_pyfunction!(resample_stencil, m)?)?;
    m.add_function(wrap_pyfunction!(resample_local_maps, m)?)?;
    m.add_function(wrap_pyfunction!(resample_node_variograms, m)?)?;
    m.add_function(wrap_pyfunction!(resample_interp_nodes, m)?)?;
    m.add_function(wrap_pyfunction!(resample_local_amplitude, m)?)?;
    m.add("RESAMPLE_HALO", resample::HALO)?;
    Ok(())
}
