//! Bindings of `crate::lsystem`: L-systems, turtle geometry, mesh files, IFS
//! and plants on terrain. The documented API is `fractalgeo_rs.lsystem`.
//! Every kernel runs through `run_in_pool`, so even a bug (a panic) comes
//! back as RuntimeError, never as a PanicException.
use super::convert::{array2, rows_in, run, run_on_grid};
use super::geometry::{MeshIn, MeshOut};
use crate::io::mesh::MeshFormat;
use crate::lsystem::derive::LSystem;
use crate::lsystem::grammar::{parse_module_string, parse_rule_text, ModString};
use crate::lsystem::ifs;
use crate::lsystem::mesh::build_mesh;
use crate::lsystem::terrain::{plants_on_terrain as scene_kernel, SceneParams};
use crate::lsystem::turtle::{polylines, segments, TurtleParams};
use crate::parallel::run_in_pool;
use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Arc;

/// Turtle options as passed from Python: any object with these attributes
/// (`fractalgeo_rs.lsystem.geometry.TurtleArgs`, a named tuple).
#[derive(FromPyObject)]
struct TurtleArgs {
    angle: f64,
    step: f64,
    width: f64,
    width_factor: f64,
    tropism: [f64; 3],
    elasticity: f64,
    heading: [f64; 3],
    left: [f64; 3],
    draw: String,
    moves: String,
}

fn turtle_params(t: TurtleArgs) -> TurtleParams {
    TurtleParams {
        angle: t.angle,
        step: t.step,
        width: t.width,
        width_factor: t.width_factor,
        tropism: DVec3::from_array(t.tropism),
        elasticity: t.elasticity,
        heading: DVec3::from_array(t.heading),
        left: DVec3::from_array(t.left),
        draw: t.draw.chars().collect(),
        moves: t.moves.chars().collect(),
    }
}

fn rows<T: Copy, const N: usize>(v: Vec<[T; N]>) -> Array2<T> {
    Array2::from_shape_fn((v.len(), N), |(i, k)| v[i][k])
}

fn flat_polys<const N: usize>(polys: Vec<Vec<[f64; N]>>) -> (Array2<f64>, Array1<u64>) {
    let mut offsets = vec![0u64];
    let mut pts = Vec::new();
    for p in polys {
        pts.extend(p);
        offsets.push(pts.len() as u64);
    }
    (rows(pts), Array1::from_vec(offsets))
}

/// A compiled L-system (see `fractalgeo_rs.lsystem.LSystem`).
#[pyclass(frozen, module = "fractalgeo_rs._core")]
pub struct LSystemCore {
    inner: Arc<LSystem>,
}

/// A derived string of modules (see `fractalgeo_rs.lsystem.LString`).
#[pyclass(frozen, module = "fractalgeo_rs._core")]
pub struct ModuleString {
    inner: Arc<ModString>,
}

#[pymethods]
impl LSystemCore {
    #[new]
    #[pyo3(signature = (axiom, rules, ignore, seed, max_length))]
    fn new(
        axiom: &str,
        rules: Vec<String>,
        ignore: &str,
        seed: u64,
        max_length: usize,
    ) -> PyResult<Self> {
        let l = run_in_pool(Some(1), || {
            LSystem::new(axiom, &rules, ignore, seed, max_length)
        })?;
        Ok(LSystemCore { inner: Arc::new(l) })
    }

    /// Derive `n` steps with `seed` (the system's seed when None).
    #[pyo3(signature = (n, seed=None, n_threads=None))]
    fn derive(
        &self,
        py: Python<'_>,
        n: usize,
        seed: Option<u64>,
        n_threads: Option<usize>,
    ) -> PyResult<ModuleString> {
        let l = self.inner.clone();
        let seed = seed.unwrap_or(l.seed);
        let s = run(py, n_threads, || l.derive_with_seed(n, seed))?;
        Ok(ModuleString { inner: Arc::new(s) })
    }

    /// `(lower, upper)` bounds on the number of modules after `n` steps,
    /// counted from the productions without expanding (equal when exact).
    fn length_bounds(&self, py: Python<'_>, n: usize) -> PyResult<(u128, u128)> {
        if n > crate::lsystem::derive::MAX_STEPS {
            return Err(crate::error::CoreError::invalid(
                "n",
                format!(
                    "at most {} derivation steps, got {n}",
                    crate::lsystem::derive::MAX_STEPS
                ),
            )
            .into());
        }
        let l = self.inner.clone();
        Ok(py.detach(move || l.length_bounds(n)))
    }

    #[getter]
    fn is_stochastic(&self) -> bool {
        self.inner.is_stochastic()
    }

    #[getter]
    fn n_rules(&self) -> usize {
        self.inner.rules.len()
    }

    #[getter]
    fn axiom(&self) -> ModuleString {
        ModuleString {
            inner: Arc::new(self.inner.axiom.clone()),
        }
    }
}

#[pymethods]
impl ModuleString {
    /// Parse a module string such as `"F(1)[+A(2,3)]"` (constant parameters).
    #[staticmethod]
    fn parse(text: &str) -> PyResult<Self> {
        Ok(ModuleString {
            inner: Arc::new(run_in_pool(Some(1), || parse_module_string(text, "text"))?),
        })
    }
    fn __len__(&self) -> usize {
        self.inner.len()
    }
    fn __str__(&self) -> String {
        self.inner.to_text()
    }
    fn __eq__(&self, other: &ModuleString) -> bool {
        self.inner == other.inner
    }
    /// Number of modules with this symbol.
    fn count(&self, symbol: char) -> usize {
        self.inner.count(symbol)
    }
    /// The symbols alone, as a str.
    fn symbols(&self) -> String {
        self.inner.syms.iter().collect()
    }
    /// (parameters (P,), offsets (N+1,)): parameters of module i are
    /// params[offsets[i]:offsets[i+1]].
    fn parameters<'py>(
        &self,
        py: Python<'py>,
    ) -> (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<u64>>) {
        let s = &self.inner;
        let off: Vec<u64> = if s.pstart.is_empty() {
            vec![0; s.len() + 1]
        } else {
            s.pstart.iter().map(|&v| v as u64).collect()
        };
        (s.params.clone().into_pyarray(py), off.into_pyarray(py))
    }
}

/// Parse the rule text format: (axiom, ignore or None, rules, directives).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn lsystem_parse_text(
    text: &str,
) -> PyResult<(String, Option<String>, Vec<String>, Vec<(String, String)>)> {
    let t = run_in_pool(Some(1), || parse_rule_text(text))?;
    Ok((t.axiom.unwrap_or_default(), t.ignore, t.rules, t.directives))
}

/// 2D turtle: (xy (N,2), offsets (K+1,), polygon_xy (M,2), polygon_offsets (P+1,)).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn turtle_polylines<'py>(
    py: Python<'py>,
    lstring: &ModuleString,
    turtle: TurtleArgs,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<u64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<u64>>,
)> {
    let s = lstring.inner.clone();
    let p = turtle_params(turtle);
    let r = run(py, Some(1), || polylines(&s, &p))?;
    let off: Vec<u64> = r.offsets.iter().map(|&v| v as u64).collect();
    let (pp, po) = flat_polys(r.polygons);
    Ok((
        rows(r.xy).into_pyarray(py),
        off.into_pyarray(py),
        pp.into_pyarray(py),
        po.into_pyarray(py),
    ))
}

/// 3D turtle: (starts (N,3), ends (N,3), widths (N,), colors (N,),
/// polygon_xyz (M,3), polygon_offsets (P+1,)).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn turtle_segments<'py>(
    py: Python<'py>,
    lstring: &ModuleString,
    turtle: TurtleArgs,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<u32>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<u64>>,
)> {
    let s = lstring.inner.clone();
    let p = turtle_params(turtle);
    let r = run(py, Some(1), || segments(&s, &p))?;
    let (pp, po) = flat_polys(r.polygons);
    Ok((
        rows(r.starts).into_pyarray(py),
        rows(r.ends).into_pyarray(py),
        r.widths.into_pyarray(py),
        r.colors.into_pyarray(py),
        pp.into_pyarray(py),
        po.into_pyarray(py),
    ))
}

/// Mesh of a module string (a dict of the mesh's fields, see `MeshOut`).
#[pyfunction]
#[pyo3(signature = (lstring, turtle, sides, n_threads=None))]
fn turtle_mesh<'py>(
    py: Python<'py>,
    lstring: &ModuleString,
    turtle: TurtleArgs,
    sides: usize,
    n_threads: Option<usize>,
) -> PyResult<MeshOut> {
    let s = lstring.inner.clone();
    let p = turtle_params(turtle);
    let m = run(py, n_threads, || build_mesh(&s, &p, sides))?;
    Ok(MeshOut(m))
}

/// Write a mesh as OBJ (`format="obj"`) or binary PLY (`format="ply"`), atomically,
/// with extra header lines `comments` and the OBJ group name of each kind `groups`.
#[pyfunction]
#[pyo3(signature = (path, format, mesh, comments=Vec::new(), groups=Vec::new()))]
fn write_mesh(
    py: Python<'_>,
    path: PathBuf,
    format: MeshFormat,
    mesh: MeshIn<'_>,
    comments: Vec<String>,
    groups: Vec<String>,
) -> PyResult<()> {
    let m = mesh.into_mesh()?;
    run(py, Some(1), || {
        crate::io::mesh::write_mesh_with(&m, &path, format, &comments, &groups)
    })
}

/// Plants on a DEM: mesh arrays plus the plant base points (P,3).
#[pyfunction]
#[pyo3(signature = (lsystem, n, dem, cell_size, density, seed, scale, max_plants, turtle, sides, n_threads=None))]
#[allow(clippy::too_many_arguments)]
fn plants_on_terrain<'py>(
    py: Python<'py>,
    lsystem: &LSystemCore,
    n: usize,
    dem: PyReadonlyArray2<'py, f64>,
    cell_size: f64,
    density: f64,
    seed: u64,
    scale: f64,
    max_plants: usize,
    turtle: TurtleArgs,
    sides: usize,
    n_threads: Option<usize>,
) -> PyResult<(MeshOut, Bound<'py, PyArray2<f64>>)> {
    let l = lsystem.inner.clone();
    let p = SceneParams {
        n,
        turtle: turtle_params(turtle),
        sides,
        cell_size,
        density,
        seed,
        scale,
        max_plants,
    };
    let ((m, bases), _) =
        run_on_grid(py, &dem, n_threads, |z, r, c| scene_kernel(&l, z, r, c, &p))?;
    Ok((MeshOut(m), rows(bases).into_pyarray(py)))
}

fn ifs_from(
    maps: &PyReadonlyArray2<'_, f64>,
    probabilities: Option<Vec<f64>>,
) -> PyResult<ifs::Ifs> {
    let rows_: Vec<[f64; 6]> = rows_in(maps, "maps")?;
    Ok(run_in_pool(Some(1), || {
        ifs::Ifs::new(&rows_, probabilities.as_deref())
    })?)
}

/// Validate an IFS: returns (maps (k,6), probabilities (k,), similarity dimension or None).
#[pyfunction]
#[pyo3(signature = (maps, probabilities=None))]
#[allow(clippy::type_complexity)]
fn ifs_check<'py>(
    py: Python<'py>,
    maps: PyReadonlyArray2<'py, f64>,
    probabilities: Option<Vec<f64>>,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Option<f64>,
)> {
    let f = ifs_from(&maps, probabilities)?;
    Ok((
        rows(f.rows()).into_pyarray(py),
        f.probs.clone().into_pyarray(py),
        f.similarity_dimension(),
    ))
}

/// A preset IFS: (maps (k,6), probabilities (k,), exact dimension or None).
#[pyfunction]
#[allow(clippy::type_complexity)]
fn ifs_preset<'py>(
    py: Python<'py>,
    name: &str,
) -> PyResult<(
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    Option<f64>,
)> {
    let (f, d) = run_in_pool(Some(1), || ifs::preset(name))?;
    Ok((
        rows(f.rows()).into_pyarray(py),
        f.probs.clone().into_pyarray(py),
        d,
    ))
}

/// Chaos game points (n_points, 2).
#[pyfunction]
#[pyo3(signature = (maps, probabilities, n_points, seed, n_threads=None))]
fn ifs_chaos_game<'py>(
    py: Python<'py>,
    maps: PyReadonlyArray2<'py, f64>,
    probabilities: Option<Vec<f64>>,
    n_points: usize,
    seed: u64,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let f = ifs_from(&maps, probabilities)?;
    let pts = run(py, n_threads, || f.chaos_game(n_points, seed))?;
    Ok(rows(pts).into_pyarray(py))
}

/// Deterministic iteration points (k^depth, 2).
#[pyfunction]
#[pyo3(signature = (maps, depth, max_points, n_threads=None))]
fn ifs_iterate<'py>(
    py: Python<'py>,
    maps: PyReadonlyArray2<'py, f64>,
    depth: usize,
    max_points: usize,
    n_threads: Option<usize>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let f = ifs_from(&maps, None)?;
    let pts = run(py, n_threads, || f.iterate(depth, max_points))?;
    Ok(rows(pts).into_pyarray(py))
}

/// Rasterise points (N,2) to a (rows, cols) uint8 image; returns (image, bounds).
#[pyfunction]
#[pyo3(signature = (points, n_rows, n_cols, bounds=None))]
fn ifs_rasterize<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    n_rows: usize,
    n_cols: usize,
    bounds: Option<[f64; 4]>,
) -> PyResult<(Bound<'py, PyArray2<u8>>, [f64; 4])> {
    let pts: Vec<[f64; 2]> = rows_in(&points, "points")?;
    let b = bounds.unwrap_or_else(|| ifs::bounds(&pts));
    let img = run(py, Some(1), || ifs::rasterize(&pts, n_rows, n_cols, b))?;
    Ok((array2(py, (n_rows, n_cols), img)?, b))
}

/// Root of Moran's equation sum r_i^s = 1.
#[pyfunction]
fn moran_dimension(ratios: Vec<f64>) -> PyResult<f64> {
    Ok(run_in_pool(Some(1), || ifs::moran_dimension(&ratios))?)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<LSystemCore>()?;
    m.add_class::<ModuleString>()?;
    m.add_function(wrap_pyfunction!(lsystem_parse_text, m)?)?;
    m.add_function(wrap_pyfunction!(turtle_polylines, m)?)?;
    m.add_function(wrap_pyfunction!(turtle_segments, m)?)?;
    m.add_function(wrap_pyfunction!(turtle_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(plants_on_terrain, m)?)?;
    m.add_function(wrap_pyfunction!(ifs_check, m)?)?;
    m.add_function(wrap_pyfunction!(ifs_preset, m)?)?;
    m.add_function(wrap_pyfunction!(ifs_chaos_game, m)?)?;
    m.add_function(wrap_pyfunction!(ifs_iterate, m)?)?;
    m.add_function(wrap_pyfunction!(ifs_rasterize, m)?)?;
    m.add_function(wrap_pyfunction!(moran_dimension, m)?)?;
    Ok(())
}
