//! Bindings of `crate::radiometry`: one scene object
//! ([`RadiometryScene`], built once from a DEM, a mesh or instances and kept
//! between calls) with its BRF, albedo, images and canopy methods, and the
//! ray-batch queries of a DEM heightfield.
use super::convert::{array1, array2, array3, c_order, run};
use super::geometry::MeshIn;
use super::progress::{counter, ProgressCounter};
use crate::error::{CoreError, CoreResult};
use crate::radiometry::integrator::{Pinhole, Psf};
use crate::radiometry::{
    direction, material, Heightfield, InstancedTracer, MeshTracer, Scene, Split,
};
use glam::{DAffine3, DMat3, DVec3};
use numpy::{PyArray1, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
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

/// The point-spread function named `psf`: "box", "gaussian"
/// (`psf_params` = [sigma, truncate]) or "table" (`table` weights,
/// `psf_params` = [cell size in pixels]).
fn psf_of(
    psf: &str,
    psf_params: &[f64],
    table: Option<&super::convert::CArray<'_, f64>>,
) -> CoreResult<Psf> {
    Ok(match (psf, psf_params, table) {
        ("box", [], None) => Psf::Box,
        ("gaussian", &[sigma, truncate], None) => Psf::gaussian(sigma, truncate)?,
        ("table", &[step], Some(t)) => {
            let (r, c) = t.rows_cols();
            Psf::table(&t.data, r, c, step)?
        }
        _ => {
            return Err(CoreError::invalid(
                "psf",
                format!(
                    "expected 'box', 'gaussian' with [sigma, truncate] or 'table' with [step] and weights, got {psf:?} with {} parameter(s)",
                    psf_params.len()
                ),
            ))
        }
    })
}

/// Origins and directions (flat `[x, y, z, ...]`, borrowed when
/// C-contiguous) and skipped facet indices of a batch of rays.
struct RayBatch<'a> {
    o: super::convert::CArray<'a, f64>,
    d: super::convert::CArray<'a, f64>,
    skip: Option<super::convert::CArray<'a, i64>>,
}

/// Rays of a batch: `(n, 3)` origins and directions, `(n,)` skipped facets.
fn ray_batch<'a>(
    origins: &'a PyReadonlyArray2<'_, f64>,
    directions: &'a PyReadonlyArray2<'_, f64>,
    skip: Option<&'a PyReadonlyArray1<'_, i64>>,
) -> PyResult<RayBatch<'a>> {
    let rows3 = |a: &'a PyReadonlyArray2<'_, f64>, name: &str| {
        let c = c_order(a);
        if c.shape[1] != 3 {
            return Err(CoreError::invalid(
                name,
                format!("expected shape (n, 3), got {:?}", c.shape),
            ));
        }
        Ok(c)
    };
    let o = rows3(origins, "origins")?;
    let d = rows3(directions, "directions")?;
    let n = o.shape[0];
    if d.shape[0] != n {
        return Err(CoreError::invalid(
            "directions",
            format!("expected {n} rows like origins, got {}", d.shape[0]),
        )
        .into());
    }
    // scans without early exit (vectorised)
    let finite = |v: &[f64]| v.iter().fold(true, |a, x| a & x.is_finite());
    if !finite(&o.data) {
        return Err(CoreError::invalid("origins", "expected finite coordinates").into());
    }
    let shortest = d.data.chunks_exact(3).fold(f64::INFINITY, |m, r| {
        m.min(r[0].abs() + r[1].abs() + r[2].abs())
    });
    if !finite(&d.data) || shortest <= 0.0 {
        return Err(CoreError::invalid("directions", "expected finite non-zero directions").into());
    }
    let skip = skip.map(c_order);
    if let Some(s) = &skip {
        if s.data.len() != n {
            return Err(CoreError::invalid(
                "skip",
                format!(
                    "expected {n} facet indices like origins, got {}",
                    s.data.len()
                ),
            )
            .into());
        }
    }
    Ok(RayBatch { o, d, skip })
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
    let b = ray_batch(&origins, &directions, skip.as_ref())?;
    let (t, f, n) = run(py, n_threads, || {
        Ok(heightfield(&z, cell_size, periodic, split)?.intersect_many(
            &b.o.data,
            &b.d.data,
            b.skip.as_ref().map(|s| &*s.data),
        ))
    })?;
    let rows = t.len();
    Ok((array1(py, t), array1(py, f), array2(py, (rows, 3), n)?))
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
    let b = ray_batch(&origins, &directions, skip.as_ref())?;
    let v = run(py, n_threads, || {
        Ok(heightfield(&z, cell_size, periodic, split)?.occluded_many(
            &b.o.data,
            &b.d.data,
            b.skip.as_ref().map(|s| &*s.data),
        ))
    })?;
    Ok(array1(py, v))
}

/// The geometry of a [`RadiometryScene`]: the integrator is monomorphised
/// per kind, the `match` runs once per call.
enum SceneKind {
    Dem(Scene<Heightfield>),
    Mesh(Scene<MeshTracer>),
    Instanced(Scene<InstancedTracer>),
}

/// Dispatch `$body` on the scene's kind with `$s` bound to the scene.
macro_rules! with_scene {
    ($kind:expr, $s:ident => $body:expr) => {
        match $kind {
            SceneKind::Dem($s) => $body,
            SceneKind::Mesh($s) => $body,
            SceneKind::Instanced($s) => $body,
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

/// `(single, multiple, total, n)` of [`RadiometryScene::brf_orders`], each a `(value, se)`.
type OrdersOut = ((f64, f64), (f64, f64), (f64, f64), u64);

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

    /// Instances of shapes: `instance_shapes[k]` is the shape of instance
    /// `k` and `transforms[k]` (3 x 4, row-major `[R | t]`) takes the
    /// shape's map coordinates to the world; `material_ids` one per facet
    /// (instances in order, each over its shape's triangles).
    #[staticmethod]
    #[pyo3(signature = (shapes, instance_shapes, transforms, materials, material_ids, periodic, extent))]
    #[allow(clippy::too_many_arguments)]
    fn from_instances(
        py: Python<'_>,
        shapes: Vec<MeshIn<'_>>,
        instance_shapes: PyReadonlyArray1<'_, u32>,
        transforms: PyReadonlyArray3<'_, f64>,
        materials: Vec<(String, Vec<f64>)>,
        material_ids: Option<PyReadonlyArray1<'_, u32>>,
        periodic: bool,
        extent: [f64; 4],
    ) -> PyResult<Self> {
        let shapes: Vec<crate::geometry::Mesh> = shapes
            .into_iter()
            .map(|m| m.into_mesh())
            .collect::<PyResult<_>>()?;
        let which = instance_shapes.as_array();
        let xf = transforms.as_array();
        if xf.shape() != [which.len(), 3, 4] {
            return Err(CoreError::invalid(
                "transforms",
                format!(
                    "expected shape ({}, 3, 4), got {:?}",
                    which.len(),
                    xf.shape()
                ),
            )
            .into());
        }
        let instances: Vec<(usize, DAffine3)> = (0..which.len())
            .map(|k| {
                let m = |r: usize, c: usize| xf[[k, r, c]];
                let cols = DMat3::from_cols(
                    DVec3::new(m(0, 0), m(1, 0), m(2, 0)),
                    DVec3::new(m(0, 1), m(1, 1), m(2, 1)),
                    DVec3::new(m(0, 2), m(1, 2), m(2, 2)),
                );
                (
                    which[k] as usize,
                    DAffine3::from_mat3_translation(cols, DVec3::new(m(0, 3), m(1, 3), m(2, 3))),
                )
            })
            .collect();
        let ids = ids_of(material_ids);
        let s = run(py, Some(1), || {
            let m = materials_of(&materials)?;
            scene_with(
                InstancedTracer::new(&shapes, &instances, periodic, extent)?,
                m,
                ids,
            )
        })?;
        Ok(RadiometryScene {
            kind: SceneKind::Instanced(s),
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

    /// `(value, se, n)` of the reflectance factor under the sun and an
    /// isotropic sky of horizontal irradiance `sky` (the HDRF).
    #[pyo3(signature = (sun, view, sky, spp, max_depth, seed, n_threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn brf_sky(
        &self,
        py: Python<'_>,
        sun: (f64, f64),
        view: (f64, f64),
        sky: f64,
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
    ) -> PyResult<(f64, f64, u64)> {
        let e = run(py, n_threads, || {
            let (sun, view) = (direction(sun, "sun")?, direction(view, "view")?);
            with_scene!(&self.kind, s => s.brf_sky(sun, view, sky, spp, max_depth, seed))
        })?;
        Ok((e.value, e.se, e.n))
    }

    /// `((value, se), (value, se), (value, se), n)`: the reflectance factor
    /// of [`RadiometryScene::brf_sky`] split into single and multiple
    /// scattering, and the total, over the same paths.
    #[pyo3(signature = (sun, view, sky, spp, max_depth, seed, n_threads=None))]
    #[allow(clippy::too_many_arguments)]
    fn brf_orders(
        &self,
        py: Python<'_>,
        sun: (f64, f64),
        view: (f64, f64),
        sky: f64,
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
    ) -> PyResult<OrdersOut> {
        let o = run(py, n_threads, || {
            let (sun, view) = (direction(sun, "sun")?, direction(view, "view")?);
            with_scene!(&self.kind, s => s.brf_orders(sun, view, sky, spp, max_depth, seed))
        })?;
        let pair = |e: crate::radiometry::Estimate| (e.value, e.se);
        Ok((pair(o.single), pair(o.multiple), pair(o.total), o.total.n))
    }

    /// `(value, se, n)` of the bi-hemispherical reflectance (white-sky albedo).
    #[pyo3(signature = (spp, max_depth, seed, n_threads=None))]
    fn bhr(
        &self,
        py: Python<'_>,
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
    ) -> PyResult<(f64, f64, u64)> {
        let e = run(
            py,
            n_threads,
            || with_scene!(&self.kind, s => s.bhr(spp, max_depth, seed)),
        )?;
        Ok((e.value, e.se, e.n))
    }

    /// Float32 radiance images, one per sun of `suns` (`(n, rows, cols)`),
    /// with sky light and a point-spread function: `psf` is "box",
    /// "gaussian" (`psf_params` = [sigma, truncate], pixels and sigmas) or
    /// "table" (`psf_table` weights, `psf_params` = [cell size in pixels]).
    #[pyo3(signature = (suns, view, sky, shape, spp, max_depth, seed, psf, psf_params, psf_table=None, n_threads=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render_series<'py>(
        &self,
        py: Python<'py>,
        suns: Vec<(f64, f64)>,
        view: (f64, f64),
        sky: f64,
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
        psf: &str,
        psf_params: Vec<f64>,
        psf_table: Option<PyReadonlyArray2<'py, f64>>,
        n_threads: Option<usize>,
        progress: Option<&Bound<'py, ProgressCounter>>,
    ) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let table = psf_table.as_ref().map(c_order);
        let pr = counter(progress);
        let ns = suns.len();
        let img = run(py, n_threads, || {
            let kernel = psf_of(psf, &psf_params, table.as_ref())?;
            let suns = suns
                .iter()
                .map(|&s| direction(s, "sun"))
                .collect::<CoreResult<Vec<_>>>()?;
            let view = direction(view, "view")?;
            with_scene!(&self.kind, s => s.render_series(
                &suns, view, sky, shape, spp, max_depth, seed, &kernel, pr.as_deref()
            ))
        })?;
        array3(py, (ns, shape.0, shape.1), img)
    }

    /// A float32 radiance image seen by a pinhole camera at `eye` looking
    /// at `target` (the scene's frame) with the vertical field of view `fov`
    /// degrees.
    #[pyo3(signature = (sun, sky, eye, target, fov, shape, spp, max_depth, seed, n_threads=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render_perspective<'py>(
        &self,
        py: Python<'py>,
        sun: (f64, f64),
        sky: f64,
        eye: (f64, f64, f64),
        target: (f64, f64, f64),
        fov: f64,
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
        n_threads: Option<usize>,
        progress: Option<&Bound<'py, ProgressCounter>>,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let pr = counter(progress);
        let img = run(py, n_threads, || {
            let cam = Pinhole::new(eye.into(), target.into(), fov)?;
            let sun = direction(sun, "sun")?;
            with_scene!(&self.kind, s => s.render_perspective(
                sun, sky, &cam, shape, spp, max_depth, seed, pr.as_deref()
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
    m.add_function(wrap_pyfunction!(radiometry_intersect, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry_occluded, m)?)?;
    Ok(())
}
