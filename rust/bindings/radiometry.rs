//! Bindings of `crate::radiometry`: BRF, albedo and images of a DEM scene.
//!
//! The scene is rebuilt from the DEM on every call (linear in the cells,
//! negligible beside the rays), so nothing is kept between calls.
use super::convert::{array1, array2, c_order, run};
use super::progress::{counter, ProgressCounter};
use crate::error::{CoreError, CoreResult};
use crate::radiometry::{direction, material, Heightfield, Scene, Split};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

fn build(
    z: &[f64],
    (rows, cols): (usize, usize),
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material_name: &str,
    params: &[f64],
) -> CoreResult<Scene> {
    let split = match split {
        "ne-sw" => Split::NeSw,
        "nw-se" => Split::NwSe,
        other => {
            return Err(CoreError::invalid(
                "split",
                format!("expected 'ne-sw' or 'nw-se', got {other:?}"),
            ))
        }
    };
    Ok(Scene {
        hf: Heightfield::new(z, rows, cols, cell_size, periodic, split)?,
        material: material::from_name(material_name, params)?,
    })
}

/// `(value, se, n)` of the BRF of a DEM scene (directions `(azimuth, zenith)` in degrees).
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, material, params, sun, view, spp, max_depth, seed, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn radiometry_brf(
    py: Python<'_>,
    dem: PyReadonlyArray2<'_, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material: &str,
    params: Vec<f64>,
    sun: (f64, f64),
    view: (f64, f64),
    spp: u64,
    max_depth: u32,
    seed: u64,
    n_threads: Option<usize>,
) -> PyResult<(f64, f64, u64)> {
    let z = c_order(&dem);
    let e = run(py, n_threads, || {
        let s = build(
            &z.data,
            z.rows_cols(),
            cell_size,
            periodic,
            split,
            material,
            &params,
        )?;
        s.brf(
            direction(sun, "sun")?,
            direction(view, "view")?,
            spp,
            max_depth,
            seed,
        )
    })?;
    Ok((e.value, e.se, e.n))
}

/// `(value, se, n)` of the directional-hemispherical albedo of a DEM scene.
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, material, params, sun, spp, max_depth, seed, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn radiometry_albedo(
    py: Python<'_>,
    dem: PyReadonlyArray2<'_, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material: &str,
    params: Vec<f64>,
    sun: (f64, f64),
    spp: u64,
    max_depth: u32,
    seed: u64,
    n_threads: Option<usize>,
) -> PyResult<(f64, f64, u64)> {
    let z = c_order(&dem);
    let e = run(py, n_threads, || {
        let s = build(
            &z.data,
            z.rows_cols(),
            cell_size,
            periodic,
            split,
            material,
            &params,
        )?;
        s.albedo(direction(sun, "sun")?, spp, max_depth, seed)
    })?;
    Ok((e.value, e.se, e.n))
}

/// A float32 radiance image of shape `shape` of a DEM scene (orthographic sensor).
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, material, params, sun, view, shape, spp, max_depth, seed, n_threads=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn radiometry_render<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    material: &str,
    params: Vec<f64>,
    sun: (f64, f64),
    view: (f64, f64),
    shape: (usize, usize),
    spp: u64,
    max_depth: u32,
    seed: u64,
    n_threads: Option<usize>,
    progress: Option<&Bound<'py, ProgressCounter>>,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let z = c_order(&dem);
    let pr = counter(progress);
    let img = run(py, n_threads, || {
        let s = build(
            &z.data,
            z.rows_cols(),
            cell_size,
            periodic,
            split,
            material,
            &params,
        )?;
        s.render_progress(
            direction(sun, "sun")?,
            direction(view, "view")?,
            shape,
            spp,
            max_depth,
            seed,
            pr.as_deref(),
        )
    })?;
    array2(py, shape, img)
}

/// Origins, directions and skipped facet indices of a batch of rays.
type RayBatch = (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<i64>);

/// Rays of a batch: `(n, 3)` origins and directions, `(n,)` skipped facets.
fn ray_batch(
    origins: &PyReadonlyArray2<'_, f64>,
    directions: &PyReadonlyArray2<'_, f64>,
    skip: Option<&PyReadonlyArray1<'_, i64>>,
) -> PyResult<RayBatch> {
    let rows3 = |a: &PyReadonlyArray2<'_, f64>, name: &str| -> PyResult<Vec<[f64; 3]>> {
        let c = c_order(a);
        if c.shape[1] != 3 {
            return Err(CoreError::invalid(
                name,
                format!("expected shape (n, 3), got {:?}", c.shape),
            )
            .into());
        }
        Ok(c.data.chunks_exact(3).map(|r| [r[0], r[1], r[2]]).collect())
    };
    let o = rows3(origins, "origins")?;
    let d = rows3(directions, "directions")?;
    if d.len() != o.len() {
        return Err(CoreError::invalid(
            "directions",
            format!("expected {} rows like origins, got {}", o.len(), d.len()),
        )
        .into());
    }
    let bad = |v: &[[f64; 3]]| v.iter().any(|r| r.iter().any(|x| !x.is_finite()));
    if bad(&o) {
        return Err(CoreError::invalid("origins", "expected finite coordinates").into());
    }
    if bad(&d) || d.iter().any(|r| r == &[0.0; 3]) {
        return Err(CoreError::invalid("directions", "expected finite non-zero directions").into());
    }
    let k = match skip {
        Some(s) => {
            let v: Vec<i64> = s.as_array().iter().copied().collect();
            if v.len() != o.len() {
                return Err(CoreError::invalid(
                    "skip",
                    format!(
                        "expected {} facet indices like origins, got {}",
                        o.len(),
                        v.len()
                    ),
                )
                .into());
            }
            v
        }
        None => vec![-1; o.len()],
    };
    Ok((o, d, k))
}

fn heightfield(
    z: &super::convert::CArray<'_, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
) -> CoreResult<Heightfield> {
    Ok(build(
        z.data.as_ref(),
        z.rows_cols(),
        cell_size,
        periodic,
        split,
        "lambertian",
        &[1.0],
    )?
    .hf)
}

/// Nearest hits of rays with a DEM's facets: `(t, facet index, unit normal)`
/// per ray (`inf`, -1 and zeros for a miss).
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, origins, directions, skip=None, n_threads=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn radiometry_intersect<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    origins: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    skip: Option<PyReadonlyArray1<'py, i64>>,
    n_threads: Option<usize>,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f64>>,
)> {
    let z = c_order(&dem);
    let (o, d, k) = ray_batch(&origins, &directions, skip.as_ref())?;
    let (t, f, n) = run(py, n_threads, || {
        Ok(heightfield(&z, cell_size, periodic, split)?.intersect_many(&o, &d, &k))
    })?;
    let rows = n.len();
    Ok((
        array1(py, t),
        array1(py, f),
        array2(py, (rows, 3), n.into_iter().flatten().collect())?,
    ))
}

/// Whether each ray hits a facet of the DEM (the shadow-ray test).
#[pyfunction]
#[pyo3(signature = (dem, cell_size, periodic, split, origins, directions, skip=None, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn radiometry_occluded<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    cell_size: (f64, f64),
    periodic: bool,
    split: &str,
    origins: PyReadonlyArray2<'py, f64>,
    directions: PyReadonlyArray2<'py, f64>,
    skip: Option<PyReadonlyArray1<'py, i64>>,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    let z = c_order(&dem);
    let (o, d, k) = ray_batch(&origins, &directions, skip.as_ref())?;
    let v = run(py, n_threads, || {
        Ok(heightfield(&z, cell_size, periodic, split)?.occluded_many(&o, &d, &k))
    })?;
    Ok(array1(py, v))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(radiometry_albedo, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_brf, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_intersect, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_occluded, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_render, m)?)?;
    Ok(())
}
