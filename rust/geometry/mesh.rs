//! The one triangle mesh of the crate: plants, TINs and DEM grids all
//! become a [`Mesh`]; the OBJ and PLY writers are in [`crate::io::mesh`].
//!
//! Vertices are `f32` offsets from an `f64` [`Mesh::origin`], so that a mesh
//! in UTM coordinates keeps millimetres (a bare `f32` has about 3 cm of
//! resolution at 500 km). Triangles are `u32` vertex indices,
//! counter-clockwise seen from outside (from +z for terrain), so that the
//! right-hand normal points out (up).
use super::geogrid::GeoGrid;
use crate::error::{CoreError, CoreResult};
use glam::DVec3;
use std::collections::HashMap;

/// An indexed triangle mesh with per-vertex and per-triangle attributes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Map coordinates of the point the vertices are relative to.
    pub origin: [f64; 3],
    /// Vertex positions relative to [`Mesh::origin`].
    pub vertices: Vec<[f32; 3]>,
    /// Unit normal per vertex.
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates per vertex.
    pub uvs: Vec<[f32; 2]>,
    /// Vertex indices, counter-clockwise seen from outside.
    pub faces: Vec<[u32; 3]>,
    /// Element of each triangle (turtle segment or polygon, TIN triangle).
    pub part_ids: Vec<u32>,
    /// Material kind of each triangle (for plants: 0 branch, 1 leaf).
    pub kinds: Vec<u8>,
    /// Colour (material) index of each triangle.
    pub colors: Vec<u32>,
    /// Instance number of each triangle (0 for one object).
    pub instances: Vec<u32>,
}

/// How [`Mesh::from_grid`] splits each cell into two triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Split {
    /// Along the cell's NE-SW diagonal (the default).
    #[default]
    NeSw,
    /// Along the cell's NW-SE diagonal.
    NwSe,
    /// NE-SW where `row + col` is even, NW-SE where it is odd.
    Alternating,
}

impl Split {
    /// Parse `"ne-sw"`, `"nw-se"` or `"alternating"` (errors name `split`).
    pub fn parse(s: &str) -> CoreResult<Self> {
        match s {
            "ne-sw" => Ok(Split::NeSw),
            "nw-se" => Ok(Split::NwSe),
            "alternating" => Ok(Split::Alternating),
            _ => Err(CoreError::invalid(
                "split",
                format!("expected 'ne-sw', 'nw-se' or 'alternating', got {s:?}"),
            )),
        }
    }
}

/// Edge counts of a mesh (see [`Mesh::edges`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct EdgeReport {
    /// Edges used by one triangle only (holes, the rim of an open surface).
    pub boundary: usize,
    /// Edges used by more than two triangles.
    pub non_manifold: usize,
    /// Edges used twice in the same direction (neighbours of opposite orientation).
    pub inconsistent: usize,
}

/// Unit area-weighted vertex normals: the sum over the triangles around a
/// vertex of `(p1 - p0) x (p2 - p0)` (twice the area times the unit normal),
/// normalised; zero for a vertex in no triangle of non-zero area. The sum
/// runs over corner 0 of every triangle in order, then corner 1, then
/// corner 2 (numpy's `np.add.at` per column).
pub fn area_weighted_normals(vertices: &[[f64; 3]], faces: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let p = |i: u32| DVec3::from_array(vertices[i as usize]);
    let face_n: Vec<DVec3> = faces
        .iter()
        .map(|f| {
            let (a, b) = (p(f[1]) - p(f[0]), p(f[2]) - p(f[0]));
            DVec3::new(
                a.y * b.z - a.z * b.y,
                a.z * b.x - a.x * b.z,
                a.x * b.y - a.y * b.x,
            )
        })
        .collect();
    let mut n = vec![DVec3::ZERO; vertices.len()];
    for k in 0..3 {
        for (f, fnrm) in faces.iter().zip(&face_n) {
            n[f[k] as usize] += *fnrm;
        }
    }
    n.iter()
        .map(|v| {
            let len = (v.x * v.x + v.y * v.y + v.z * v.z).sqrt();
            if len > 0.0 {
                [v.x / len, v.y / len, v.z / len]
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

impl Mesh {
    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    /// True for a mesh without triangles.
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// A terrain mesh of map-coordinate vertices (a TIN, a grid): vertices
    /// relative to `origin = (min x, min y, 0)`, area-weighted normals
    /// computed in f64 from the map coordinates, texture coordinates = map
    /// `x, y` scaled to [0, 1] over the bounding box, `part_ids` = triangle
    /// number, every other id 0. Errors name `vertices` (non-finite) or
    /// `triangles` (index out of range).
    pub fn from_tin(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> CoreResult<Mesh> {
        if let Some(i) = vertices
            .iter()
            .position(|v| !v.iter().all(|x| x.is_finite()))
        {
            return Err(CoreError::invalid(
                "vertices",
                format!("vertex {i} is not finite: {:?}", vertices[i]),
            ));
        }
        let nv = vertices.len();
        if let Some(t) = triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= nv))
        {
            return Err(CoreError::invalid(
                "triangles",
                format!(
                    "triangle {t} refers to vertex {:?}, but there are {nv} vertices",
                    triangles[t]
                ),
            ));
        }
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for v in vertices {
            for k in 0..2 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        if nv == 0 {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        let span = [0, 1].map(|k| (hi[k] - lo[k]).max(f64::MIN_POSITIVE));
        let normals = area_weighted_normals(vertices, triangles);
        let m = triangles.len();
        Ok(Mesh {
            origin: [lo[0], lo[1], 0.0],
            vertices: vertices
                .iter()
                .map(|v| [(v[0] - lo[0]) as f32, (v[1] - lo[1]) as f32, v[2] as f32])
                .collect(),
            normals: normals.iter().map(|n| n.map(|x| x as f32)).collect(),
            uvs: vertices
                .iter()
                .map(|v| {
                    [
                        ((v[0] - lo[0]) / span[0]) as f32,
                        ((v[1] - lo[1]) / span[1]) as f32,
                    ]
                })
                .collect(),
            faces: triangles.to_vec(),
            part_ids: (0..m as u32).collect(),
            kinds: vec![0; m],
            colors: vec![0; m],
            instances: vec![0; m],
        })
    }

    /// The mesh of a regular grid of heights `z` (C order, `rows x cols`,
    /// row 0 north, columns east): one vertex per cell centre at its map
    /// position from `grid`, two triangles per square of four adjacent
    /// centres. With `(i, j)` the north-west centre of a square, the
    /// default NE-SW split gives `(i, j)-(i+1, j)-(i, j+1)` and
    /// `(i, j+1)-(i+1, j)-(i+1, j+1)`: counter-clockwise seen from above, so
    /// the normals point up. A square with a NaN corner loses the
    /// triangles that use it; vertices in no triangle are left out.
    /// Attributes as in [`Mesh::from_tin`].
    pub fn from_grid(
        z: &[f64],
        rows: usize,
        cols: usize,
        grid: &GeoGrid,
        split: Split,
    ) -> CoreResult<Mesh> {
        if rows < 2 || cols < 2 || z.len() != rows * cols {
            return Err(CoreError::invalid(
                "dem",
                format!(
                    "expected at least 2 x 2 heights in a {rows} x {cols} grid, got {}",
                    z.len()
                ),
            ));
        }
        if rows * cols > u32::MAX as usize {
            return Err(CoreError::invalid("dem", "more than 2^32 samples"));
        }
        if let Some(i) = z.iter().position(|v| v.is_infinite()) {
            return Err(CoreError::invalid(
                "dem",
                format!("sample {i} is infinite (NaN means no data)"),
            ));
        }
        let grid = grid.clone().checked()?;
        let id = |i: usize, j: usize| (i * cols + j) as u32;
        let mut faces = Vec::with_capacity(2 * (rows - 1) * (cols - 1));
        for i in 0..rows - 1 {
            for j in 0..cols - 1 {
                let (nw, ne, sw, se) = (id(i, j), id(i, j + 1), id(i + 1, j), id(i + 1, j + 1));
                let ne_sw = match split {
                    Split::NeSw => true,
                    Split::NwSe => false,
                    Split::Alternating => (i + j) % 2 == 0,
                };
                let pair = if ne_sw {
                    [[nw, sw, ne], [ne, sw, se]]
                } else {
                    [[nw, sw, se], [nw, se, ne]]
                };
                for t in pair {
                    if t.iter().all(|&k| !z[k as usize].is_nan()) {
                        faces.push(t);
                    }
                }
            }
        }
        // keep the vertices some triangle uses, in grid order
        let mut new_id = vec![u32::MAX; rows * cols];
        let mut vertices = Vec::new();
        for t in &faces {
            for &k in t {
                new_id[k as usize] = 0;
            }
        }
        for (k, slot) in new_id.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = vertices.len() as u32;
                let (i, j) = (k / cols, k % cols);
                let [x, y] = grid.center(i as f64, j as f64);
                vertices.push([x, y, z[k]]);
            }
        }
        for t in &mut faces {
            *t = t.map(|k| new_id[k as usize]);
        }
        Mesh::from_tin(&vertices, &faces)
    }

    /// Append `other` moved by `f` (applied to points) and `g` (to normals),
    /// its triangles tagged with `instance` (instancing: one plant many
    /// times). Positions are taken relative to each mesh's origin. Errors
    /// (naming `other`) when the result would have more than 2^32 vertices.
    pub fn append_transformed(
        &mut self,
        other: &Mesh,
        instance: u32,
        f: impl Fn(DVec3) -> DVec3,
        g: impl Fn(DVec3) -> DVec3,
    ) -> CoreResult<()> {
        let base = self.vertices.len();
        if base + other.vertices.len() > u32::MAX as usize {
            return Err(CoreError::invalid(
                "other",
                "the mesh would have more than 2^32 vertices",
            ));
        }
        let b = base as u32;
        self.vertices.extend(other.vertices.iter().map(|v| {
            f(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
                .as_vec3()
                .to_array()
        }));
        self.normals.extend(other.normals.iter().map(|v| {
            g(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64))
                .as_vec3()
                .to_array()
        }));
        self.uvs.extend_from_slice(&other.uvs);
        self.faces
            .extend(other.faces.iter().map(|t| [t[0] + b, t[1] + b, t[2] + b]));
        self.part_ids.extend_from_slice(&other.part_ids);
        self.kinds.extend_from_slice(&other.kinds);
        self.colors.extend_from_slice(&other.colors);
        self.instances
            .extend(std::iter::repeat_n(instance, other.faces.len()));
        Ok(())
    }

    /// Check the layout the writers need: one normal and one texture
    /// coordinate per vertex, one of each id per triangle, every index in
    /// range. Errors name `mesh`.
    pub fn check_layout(&self) -> CoreResult<()> {
        let (nv, nf) = (self.vertices.len(), self.faces.len());
        if self.normals.len() != nv || self.uvs.len() != nv {
            return Err(CoreError::invalid(
                "mesh",
                "normals and uvs must have one row per vertex",
            ));
        }
        if self.part_ids.len() != nf
            || self.kinds.len() != nf
            || self.colors.len() != nf
            || self.instances.len() != nf
        {
            return Err(CoreError::invalid(
                "mesh",
                "part_ids, kinds, colors and instances must have one entry per face",
            ));
        }
        if self.faces.iter().flatten().any(|&i| i as usize >= nv) {
            return Err(CoreError::invalid(
                "mesh",
                "a face refers to a vertex that does not exist",
            ));
        }
        Ok(())
    }

    /// [`Mesh::check_layout`] and the geometry: finite origin and vertices,
    /// every triangle of non-zero area. Errors name the failing field
    /// (`faces`, `vertices`, `origin`, ...).
    pub fn validate(&self) -> CoreResult<()> {
        let nv = self.vertices.len();
        if let Some(t) = self
            .faces
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= nv))
        {
            return Err(CoreError::invalid(
                "faces",
                format!(
                    "triangle {t} refers to vertex {:?}, but there are {nv} vertices",
                    self.faces[t]
                ),
            ));
        }
        self.check_layout()?;
        if !self.origin.iter().all(|x| x.is_finite()) {
            return Err(CoreError::invalid(
                "origin",
                format!("must be finite, got {:?}", self.origin),
            ));
        }
        if let Some(i) = self
            .vertices
            .iter()
            .position(|v| !v.iter().all(|x| x.is_finite()))
        {
            return Err(CoreError::invalid(
                "vertices",
                format!("vertex {i} is NaN or infinite: {:?}", self.vertices[i]),
            ));
        }
        let p = |i: u32| DVec3::from_array(self.vertices[i as usize].map(|x| x as f64));
        if let Some(t) = self.faces.iter().position(|f| {
            (p(f[1]) - p(f[0]))
                .cross(p(f[2]) - p(f[0]))
                .length_squared()
                == 0.0
        }) {
            return Err(CoreError::invalid(
                "faces",
                format!("triangle {t} {:?} has zero area", self.faces[t]),
            ));
        }
        Ok(())
    }

    /// Lower and upper corners of the bounding box in map coordinates
    /// (origin added); `None` for a mesh without vertices.
    pub fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = self.vertices.first()?;
        let mut lo = first.map(|x| x as f64);
        let mut hi = lo;
        for v in &self.vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k] as f64);
                hi[k] = hi[k].max(v[k] as f64);
            }
        }
        Some((
            [0, 1, 2].map(|k| lo[k] + self.origin[k]),
            [0, 1, 2].map(|k| hi[k] + self.origin[k]),
        ))
    }

    /// Unit area-weighted vertex normals of the mesh as it is (see
    /// [`area_weighted_normals`]).
    pub fn vertex_normals(&self) -> Vec<[f64; 3]> {
        let v: Vec<[f64; 3]> = self.vertices.iter().map(|p| p.map(|x| x as f64)).collect();
        area_weighted_normals(&v, &self.faces)
    }

    /// Count boundary, non-manifold and inconsistently oriented edges
    /// (vertices are identified by index).
    pub fn edges(&self) -> EdgeReport {
        // undirected edge -> (uses in direction lo->hi, uses hi->lo)
        let mut uses: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(3 * self.len());
        for f in &self.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                let e = uses.entry((a.min(b), a.max(b))).or_default();
                if a < b {
                    e.0 += 1
                } else {
                    e.1 += 1
                }
            }
        }
        let mut r = EdgeReport::default();
        for &(fwd, back) in uses.values() {
            match fwd + back {
                1 => r.boundary += 1,
                2 if fwd != 1 => r.inconsistent += 1,
                2 => {}
                _ => r.non_manifold += 1,
            }
        }
        r
    }

    /// The edges used by one triangle only, as vertex pairs in the
    /// triangle's direction, sorted.
    pub fn boundary_edges(&self) -> Vec<[u32; 2]> {
        let mut count: HashMap<(u32, u32), ([u32; 2], u32)> = HashMap::new();
        for f in &self.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                count.entry((a.min(b), a.max(b))).or_insert(([a, b], 0)).1 += 1;
            }
        }
        let mut out: Vec<[u32; 2]> = count
            .into_values()
            .filter(|&(_, n)| n == 1)
            .map(|(e, _)| e)
            .collect();
        out.sort_unstable();
        out
    }

    /// Closed, edge-manifold and consistently oriented: every edge is used
    /// by exactly two triangles, once in each direction.
    pub fn is_watertight(&self) -> bool {
        !self.is_empty() && self.edges() == EdgeReport::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> Mesh {
        let v: Vec<[f64; 3]> = (0..8)
            .map(|k| [(k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64])
            .collect();
        // outward counter-clockwise faces of the unit cube
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let f: Vec<[u32; 3]> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Mesh::from_tin(&v, &f).unwrap()
    }

    #[test]
    fn cube_is_watertight_with_outward_normals() {
        let m = cube();
        assert!(m.is_watertight());
        assert_eq!(m.edges(), EdgeReport::default());
        let (lo, hi) = m.bounds().unwrap();
        assert_eq!((lo, hi), ([0.0; 3], [1.0; 3]));
        // corner normals point away from the centre (into the corner's octant)
        for (v, n) in m.vertices.iter().zip(m.vertex_normals()) {
            for k in 0..3 {
                assert_eq!(
                    n[k].signum(),
                    (v[k] as f64 - 0.5).signum(),
                    "{n:?} at {v:?}"
                );
            }
            assert!(((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() - 1.0).abs() < 1e-12);
        }
        let mut open = m.clone();
        open.faces.pop();
        assert_eq!(open.edges().boundary, 3);
        assert!(!open.is_watertight());
        let mut flipped = m.clone();
        flipped.faces[0] = [
            flipped.faces[0][0],
            flipped.faces[0][2],
            flipped.faces[0][1],
        ];
        assert_eq!(flipped.edges().inconsistent, 3);
    }

    #[test]
    fn grid_splits_are_counter_clockwise_from_above() {
        let g = GeoGrid::new(100.0, 200.0, 30.0, 30.0).unwrap();
        let z = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        for split in [Split::NeSw, Split::NwSe, Split::Alternating] {
            let m = Mesh::from_grid(&z, 2, 3, &g, split).unwrap();
            assert_eq!(m.len(), 4);
            assert_eq!(m.origin, [115.0, 155.0, 0.0]);
            for f in &m.faces {
                let p: Vec<DVec3> = f
                    .iter()
                    .map(|&i| DVec3::from_array(m.vertices[i as usize].map(|x| x as f64)))
                    .collect();
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                assert!(n.z > 0.0, "{split:?}: {f:?} is clockwise");
                // each triangle is half a 30 m x 30 m square
                assert!((0.5 * n.z - 450.0).abs() < 1e-9);
            }
            m.validate().unwrap();
            assert!(m.normals.iter().all(|n| n[2] > 0.0));
        }
        // the NE-SW diagonal joins (0, 1) and (1, 0): vertices 1 and 3
        let m = Mesh::from_grid(&z, 2, 3, &g, Split::NeSw).unwrap();
        assert_eq!(m.faces[0], [0, 3, 1]);
        assert_eq!(m.faces[1], [1, 3, 4]);
        let m = Mesh::from_grid(&z, 2, 3, &g, Split::NwSe).unwrap();
        assert_eq!(m.faces[0], [0, 3, 4]);
        // map positions of the cell centres (row 0 north)
        assert_eq!(m.vertices[0], [0.0, 30.0, 1.0]);
        assert_eq!(m.vertices[5], [60.0, 0.0, 6.0]);
    }

    #[test]
    fn grid_with_nodata_drops_triangles_and_vertices() {
        let g = GeoGrid::pixels(3, 1.0).unwrap();
        let mut z = vec![0.0; 9];
        z[4] = f64::NAN; // the centre: every triangle touches it except none
        let m = Mesh::from_grid(&z, 3, 3, &g, Split::NeSw).unwrap();
        // NE-SW: the centre is in all triangles but the NW one of the
        // north-west square and the SE one of the south-east square
        assert_eq!(m.len(), 2);
        assert_eq!(m.vertices.len(), 6);
        m.validate().unwrap();
        let e = Mesh::from_grid(&z, 3, 2, &g, Split::NeSw)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("dem:"), "{e}");
    }

    #[test]
    fn bad_meshes_name_the_field() {
        let m = cube();
        let mut bad = m.clone();
        bad.faces[3] = [0, 1, 99];
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.starts_with("faces:") && e.contains("99"), "{e}");
        let mut bad = m.clone();
        bad.vertices[2][1] = f32::NAN;
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("vertices:"));
        let mut bad = m.clone();
        bad.faces[0] = [0, 1, 1];
        let e = bad.validate().unwrap_err().to_string();
        assert!(e.starts_with("faces:") && e.contains("zero area"), "{e}");
        let mut bad = m.clone();
        bad.kinds.pop();
        assert!(bad.validate().unwrap_err().to_string().starts_with("mesh:"));
        let e = Mesh::from_tin(&[[0.0, f64::NAN, 0.0]], &[]).unwrap_err();
        assert!(e.to_string().starts_with("vertices:"));
        let e = Mesh::from_tin(&[[0.0; 3]], &[[0, 0, 1]]).unwrap_err();
        assert!(e.to_string().starts_with("triangles:"));
        assert!(Split::parse("diagonal")
            .unwrap_err()
            .to_string()
            .starts_with("split:"));
    }

    #[test]
    fn instancing_offsets_indices_and_tags_instances() {
        let m = cube();
        let mut scene = Mesh::default();
        for k in 0..3 {
            scene
                .append_transformed(&m, k, |p| p + DVec3::X * (2.0 * k as f64), |n| n)
                .unwrap();
        }
        assert_eq!(scene.len(), 36);
        assert_eq!(scene.vertices.len(), 24);
        assert!(scene.is_watertight());
        assert_eq!(scene.instances[35], 2);
        assert_eq!(scene.bounds().unwrap(), ([0.0; 3], [5.0, 1.0, 1.0]));
    }
}
