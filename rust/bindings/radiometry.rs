//! Bindings of `crate::radiometry`: BRF, albedo and images of a DEM scene.
//!
//! The scene is rebuilt from the DEM on every call (linear in the cells,
//! negligible beside the rays), so nothing is kept between calls.
use super::convert::{array1, array2, c_order, run};
use super::geometry::MeshIn;
use super::progress::{counter, ProgressCounter};
use crate::error::{CoreError, CoreResult};
use crate::radiometry::{direction, material, Heightfield, MeshTracer, Scene, Split};
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
    Ok(Scene::new(
        Heightfield::new(z, rows, cols, cell_size, periodic, split)?,
        material::from_name(material_name, params)?,
    ))
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

/// The geometry of a [`RadiometryScene`]: the integrator is monomorphised
/// per kind, the `match` runs once per call.
enum SceneKind {
    Dem(Scene<Heightfield>),
    Mesh(Scene<MeshTracer>),
}

/// Dispatch `$body` on the scene's kind with `$s` bound to the scene.
macro_rules! with_scene {
    ($kind:expr, $s:ident => $body:expr) => {
        match $kind {
            SceneKind::Dem($s) => $body,
            SceneKind::Mesh($s) => $body,
        }
    };
}

fn materials_of(specs: &[(String, Vec<f64>)]) -> CoreResult<Vec<Box<dyn material::Bsdf>>> {
    specs
        .iter()
        .map(|(name, p)| material::from_name(name, p))
        .collect()
}

fn ids_of(ids: Option<PyReadonlyArray1<'_, u32>>) -> Option<Vec<u32>> {
    ids.map(|a| a.as_array().to_vec())
}

fn scene_with<G: crate::radiometry::Tracer>(
    g: G,
    materials: Vec<Box<dyn material::Bsdf>>,
    ids: Option<Vec<u32>>,
) -> CoreResult<Scene<G>> {
    match ids {
        Some(ids) => Scene::with_materials(g, materials, ids),
        None => {
            if materials.len() != 1 {
                return Err(CoreError::invalid(
                    "material_ids",
                    format!(
                        "expected one material index per facet for {} materials, got None",
                        materials.len()
                    ),
                ));
            }
            Ok(Scene::new(g, materials.into_iter().next().unwrap()))
        }
    }
}

/// `(absorbed per material, reflected, trapped, n)`, each a `(value, se)`.
type AbsorptionOut = (Vec<(f64, f64)>, (f64, f64), (f64, f64), u64);

/// `(areas, normals)` of [`RadiometryScene::facets`].
type FacetArrays<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>);

/// A scene kept between calls (a mesh's BVH is built once): a DEM or a
/// triangle mesh with per-facet materials.
#[pyclass(frozen, module = "fractalgeo_rs._core")]
pub struct RadiometryScene {
    kind: SceneKind,
}

#[pymethods]
impl RadiometryScene {
    /// A triangle mesh (any object with `fractalgeo_rs.geometry.Mesh`'s
    /// attributes); `materials` as `(name, params)`, `material_ids` one per
    /// triangle; `extent = (x0, y0, width, height)` in map coordinates.
    #[staticmethod]
    #[pyo3(signature = (mesh, materials, material_ids, periodic, extent=None))]
    fn from_mesh(
        py: Python<'_>,
        mesh: MeshIn<'_>,
        materials: Vec<(String, Vec<f64>)>,
        material_ids: Option<PyReadonlyArray1<'_, u32>>,
        periodic: bool,
        extent: Option<[f64; 4]>,
    ) -> PyResult<Self> {
        let mesh = mesh.into_mesh()?;
        let ids = ids_of(material_ids);
        let s = run(py, Some(1), || {
            let m = materials_of(&materials)?;
            scene_with(MeshTracer::new(&mesh, periodic, extent)?, m, ids)
        })?;
        Ok(RadiometryScene {
            kind: SceneKind::Mesh(s),
        })
    }

    /// A DEM heightfield with per-facet materials (`material_ids` one per
    /// facet: cell row, cell column, facet of the cell).
    #[staticmethod]
    #[pyo3(signature = (dem, cell_size, periodic, split, materials, material_ids))]
    #[allow(clippy::too_many_arguments)]
    fn from_dem(
        py: Python<'_>,
        dem: PyReadonlyArray2<'_, f64>,
        cell_size: (f64, f64),
        periodic: bool,
        split: &str,
        materials: Vec<(String, Vec<f64>)>,
        material_ids: Option<PyReadonlyArray1<'_, u32>>,
    ) -> PyResult<Self> {
        let z = c_order(&dem);
        let ids = ids_of(material_ids);
        let s = run(py, Some(1), || {
            let first = materials.first().ok_or_else(|| {
                CoreError::invalid("materials", "expected at least one material, got none")
            })?;
            let base = build(
                &z.data,
                z.rows_cols(),
                cell_size,
                periodic,
                split,
                &first.0,
                &first.1,
            )?;
            scene_with(base.hf, materials_of(&materials)?, ids)
        })?;
        Ok(RadiometryScene {
            kind: SceneKind::Dem(s),
        })
    }

    /// `(value, se, n)` of the BRF (directions `(azimuth, zenith)` in degrees).
    #[pyo3(signature = (sun, view, spp, max_depth, seed, n_threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn brf(
        &self,
        py: Python<'_>,
        sun: (f64, f64),
        view: (f64, f64),
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
    ) -> PyResult<(f64, f64, u64)> {
        let e = run(py, n_threads, || {
            let (sun, view) = (direction(sun, "sun")?, direction(view, "view")?);
            with_scene!(&self.kind, s => s.brf(sun, view, spp, max_depth, seed))
        })?;
        Ok((e.value, e.se, e.n))
    }

    /// `(value, se, n)` of the directional-hemispherical albedo.
    #[pyo3(signature = (sun, spp, max_depth, seed, n_threads=None))]
    fn albedo(
        &self,
        py: Python<'_>,
        sun: (f64, f64),
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
    ) -> PyResult<(f64, f64, u64)> {
        let e = run(py, n_threads, || {
            let sun = direction(sun, "sun")?;
            with_scene!(&self.kind, s => s.albedo(sun, spp, max_depth, seed))
        })?;
        Ok((e.value, e.se, e.n))
    }

    /// `(value, se, n)` of the gap fraction towards `sun`: the fraction of
    /// `n` rays from the sun whose first hit has material `ground`.
    #[pyo3(signature = (sun, ground, n, seed, n_threads=None))]
    fn gap_fraction(
        &self,
        py: Python<'_>,
        sun: (f64, f64),
        ground: u32,
        n: u64,
        seed: u64,
        n_threads: Option<usize>,
    ) -> PyResult<(f64, f64, u64)> {
        let e = run(py, n_threads, || {
            let sun = direction(sun, "sun")?;
            with_scene!(&self.kind, s => s.gap_fraction(sun, ground, n, seed))
        })?;
        Ok((e.value, e.se, e.n))
    }

    /// `(absorbed, reflected, trapped, n)`: `(value, se)` of the fraction of
    /// the sun's light absorbed per material, reflected, and still
    /// travelling after `max_depth` events.
    #[pyo3(signature = (sun, spp, max_depth, seed, n_threads=None))]
    fn absorption(
        &self,
        py: Python<'_>,
        sun: (f64, f64),
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
    ) -> PyResult<AbsorptionOut> {
        let a = run(py, n_threads, || {
            let sun = direction(sun, "sun")?;
            with_scene!(&self.kind, s => s.absorption(sun, spp, max_depth, seed))
        })?;
        let pair = |e: crate::radiometry::Estimate| (e.value, e.se);
        Ok((
            a.absorbed.iter().map(|&e| pair(e)).collect(),
            pair(a.reflected),
            pair(a.trapped),
            a.reflected.n,
        ))
    }

    /// A float32 radiance image (orthographic sensor over the footprint).
    #[pyo3(signature = (sun, view, shape, spp, max_depth, seed, n_threads=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        sun: (f64, f64),
        view: (f64, f64),
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
        progress: Option<&Bound<'py, ProgressCounter>>,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let pr = counter(progress);
        let img = run(py, n_threads, || {
            let (sun, view) = (direction(sun, "sun")?, direction(view, "view")?);
            with_scene!(&self.kind, s => s.render_progress(
                sun, view, shape, spp, max_depth, seed, pr.as_deref()
            ))
        })?;
        array2(py, shape, img)
    }

    /// `(areas, normals)`: area (square metres) and unit normal of every
    /// facet of the tile, in material-id order.
    fn facets<'py>(&self, py: Python<'py>) -> PyResult<FacetArrays<'py>> {
        use crate::radiometry::Tracer;
        let f = with_scene!(&self.kind, s => s.hf.facets());
        let areas: Vec<f64> = f.iter().map(|x| x.0).collect();
        let normals: Vec<f64> = f.iter().flat_map(|x| x.1.to_array()).collect();
        let n = areas.len();
        Ok((array1(py, areas), array2(py, (n, 3), normals)?))
    }

    /// `(x0, y0, width, height)` of the sensor's footprint in the scene's
    /// frame (a mesh's frame is its `origin`).
    #[getter]
    fn footprint(&self) -> (f64, f64, f64, f64) {
        use crate::radiometry::Tracer;
        with_scene!(&self.kind, s => s.hf.footprint())
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<RadiometryScene>()?;
    m.add_function(wrap_pyfunction!(radiometry_albedo, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_brf, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_render, m)?)?;
    Ok(())
}
