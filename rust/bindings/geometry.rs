//! Bindings of `crate::geometry`, and the typed conversions of its types:
//! a [`Mesh`] crosses into Python as a dict of arrays (named fields, read
//! by `fractalgeo_rs.geometry.Mesh`) and comes back from any object with
//! those attributes ([`MeshIn`]); a `GeoGrid` is read from any object with
//! `origin, cell_size, rotation, crs` attributes ([`GeoGridIn`]); the
//! kernels' keyword enums ([`Split`], [`MeshFormat`]) are read from a str.
use super::convert::{run, run_on_grid};
use crate::error::CoreResult;
use crate::geometry::{GeoGrid, Mesh, Split};
use crate::io::mesh::MeshFormat;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

fn rows<T: Copy, const N: usize>(v: Vec<[T; N]>) -> Array2<T> {
    Array2::from_shape_fn((v.len(), N), |(i, k)| v[i][k])
}

/// A kernel enum from a Python str: the kernel's `parse` reads it (an
/// unknown value is its ValueError naming `param`); anything but a str is a
/// TypeError naming `param`.
fn keyword<T>(
    obj: &Borrowed<'_, '_, PyAny>,
    param: &str,
    parse: fn(&str) -> CoreResult<T>,
) -> PyResult<T> {
    match obj.cast::<PyString>() {
        Ok(s) => Ok(parse(&s.to_cow()?)?),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{param}: expected a str, got {}",
            obj.get_type().name()?
        ))),
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for Split {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        keyword(&obj, "split", Split::parse)
    }
}

impl<'a, 'py> FromPyObject<'a, 'py> for MeshFormat {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        keyword(&obj, "format", MeshFormat::parse)
    }
}

/// A [`Mesh`] on its way to Python: a dict `{"origin", "vertices",
/// "normals", "uvs", "faces", "part_ids", "kinds", "colors", "instances"}`.
pub struct MeshOut(pub Mesh);

impl<'py> IntoPyObject<'py> for MeshOut {
    type Target = PyDict;
    type Output = Bound<'py, PyDict>;
    type Error = PyErr;

    fn into_pyobject(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let m = self.0;
        let d = PyDict::new(py);
        d.set_item("origin", m.origin)?;
        d.set_item("vertices", rows(m.vertices).into_pyarray(py))?;
        d.set_item("normals", rows(m.normals).into_pyarray(py))?;
        d.set_item("uvs", rows(m.uvs).into_pyarray(py))?;
        d.set_item("faces", rows(m.faces).into_pyarray(py))?;
        d.set_item("part_ids", m.part_ids.into_pyarray(py))?;
        d.set_item("kinds", m.kinds.into_pyarray(py))?;
        d.set_item("colors", m.colors.into_pyarray(py))?;
        d.set_item("instances", m.instances.into_pyarray(py))?;
        Ok(d)
    }
}

/// A mesh from Python: any object with the attributes of
/// `fractalgeo_rs.geometry.Mesh` (arrays of any strides, exact dtypes).
#[derive(FromPyObject)]
pub struct MeshIn<'py> {
    origin: [f64; 3],
    vertices: PyReadonlyArray2<'py, f32>,
    normals: PyReadonlyArray2<'py, f32>,
    uvs: PyReadonlyArray2<'py, f32>,
    faces: PyReadonlyArray2<'py, u32>,
    part_ids: PyReadonlyArray1<'py, u32>,
    kinds: PyReadonlyArray1<'py, u8>,
    colors: PyReadonlyArray1<'py, u32>,
    instances: PyReadonlyArray1<'py, u32>,
}

impl MeshIn<'_> {
    /// The owned mesh (shapes checked, naming the field).
    pub fn into_mesh(self) -> PyResult<Mesh> {
        use super::convert::rows_in;
        Ok(Mesh {
            origin: self.origin,
            vertices: rows_in(&self.vertices, "vertices")?,
            normals: rows_in(&self.normals, "normals")?,
            uvs: rows_in(&self.uvs, "uvs")?,
            faces: rows_in(&self.faces, "faces")?,
            part_ids: self.part_ids.as_array().to_vec(),
            kinds: self.kinds.as_array().to_vec(),
            colors: self.colors.as_array().to_vec(),
            instances: self.instances.as_array().to_vec(),
        })
    }
}

/// A `GeoGrid` from Python: any object with `origin` (x0, y0), `cell_size`
/// (dx, dy), `rotation` and `crs`.
#[derive(FromPyObject)]
pub struct GeoGridIn {
    origin: [f64; 2],
    cell_size: [f64; 2],
    rotation: f64,
    crs: Option<String>,
}

impl GeoGridIn {
    /// The checked grid (errors name `cell_size`, `origin`, `rotation`).
    pub fn into_grid(self) -> PyResult<GeoGrid> {
        Ok(GeoGrid {
            x0: self.origin[0],
            y0: self.origin[1],
            dx: self.cell_size[0],
            dy: self.cell_size[1],
            rotation: self.rotation,
            crs: self.crs,
        }
        .checked()?)
    }
}

/// Mesh of a DEM grid (float64, NaN = nodata): two triangles per square of
/// cell centres, split "ne-sw", "nw-se" or "alternating".
#[pyfunction]
#[pyo3(signature = (dem, grid, split, n_threads=None))]
fn mesh_from_grid<'py>(
    py: Python<'py>,
    dem: PyReadonlyArray2<'py, f64>,
    grid: GeoGridIn,
    split: Split,
    n_threads: Option<usize>,
) -> PyResult<MeshOut> {
    let g = grid.into_grid()?;
    let (m, _) = run_on_grid(py, &dem, n_threads, |z, r, c| {
        Mesh::from_grid(z, r, c, &g, split)
    })?;
    Ok(MeshOut(m))
}

/// Terrain mesh of map-coordinate vertices (n, 3) and triangles (m, 3).
#[pyfunction]
#[pyo3(signature = (vertices, triangles))]
fn mesh_from_tin<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    triangles: PyReadonlyArray2<'py, i64>,
) -> PyResult<MeshOut> {
    use super::convert::rows_in;
    let v: Vec<[f64; 3]> = rows_in(&vertices, "vertices")?;
    let t: Vec<[i64; 3]> = rows_in(&triangles, "triangles")?;
    let nv = v.len();
    if let Some(bad) = t
        .iter()
        .find(|t| t.iter().any(|&i| i < 0 || i as usize >= nv))
    {
        return Err(crate::CoreError::invalid(
            "triangles",
            format!("triangle {bad:?} refers to a vertex out of range [0, {nv})"),
        )
        .into());
    }
    let t: Vec<[u32; 3]> = t.iter().map(|r| r.map(|i| i as u32)).collect();
    Ok(MeshOut(run(py, Some(1), || Mesh::from_tin(&v, &t))?))
}

/// Check a mesh: layout, indices in range, finite vertices, non-zero areas.
#[pyfunction]
fn mesh_validate(py: Python<'_>, mesh: MeshIn<'_>) -> PyResult<()> {
    let m = mesh.into_mesh()?;
    run(py, Some(1), || m.validate())
}

/// (boundary, non_manifold, inconsistent) edge counts of a mesh.
#[pyfunction]
fn mesh_edges(py: Python<'_>, mesh: MeshIn<'_>) -> PyResult<(usize, usize, usize)> {
    let m = mesh.into_mesh()?;
    m.check_layout()?;
    let e = run(py, Some(1), || Ok(m.edges()))?;
    Ok((e.boundary, e.non_manifold, e.inconsistent))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(mesh_from_grid, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_from_tin, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_validate, m)?)?;
    m.add_function(wrap_pyfunction!(mesh_edges, m)?)?;
    Ok(())
}
