//! Triangle meshes from the turtle: generalised cylinders for branches and
//! fan-triangulated polygons for leaves (Prusinkiewicz and Lindenmayer 1990,
//! sections 1.5 and 5.1; Bloomenthal 1985 for generalised cylinders).
//!
//! A branch is a chain of segments drawn without lifting the pen; its tube is
//! a sequence of rings of `sides + 1` vertices (the last one duplicates the
//! first so that the texture seam has its own u = 1). Consecutive segments
//! share their ring; a branch `[` starts a new ring. The reference direction
//! of each ring is the previous ring's reference projected on the plane
//! perpendicular to the new segment (parallel transport), so tubes do not
//! twist when the turtle rolls. Texture coordinates: u in [0, 1] around the
//! tube, v = length along the branch in turtle units. Leaves get the polygon's
//! Newell normal and planar texture coordinates scaled to [0, 1].
use super::grammar::ModString;
use super::turtle::{interpret, Sink, State, TurtleParams, NO_TAG};
use crate::error::{CoreError, CoreResult};
pub use crate::geometry::Mesh;
use glam::{DQuat, DVec3};
use rayon::prelude::*;

/// Largest number of branch triangles of one mesh (2^28, about 7 GB of mesh).
pub const MAX_TRIANGLES: usize = 1 << 28;

/// Triangle kinds in [`Mesh::kinds`].
pub const KIND_BRANCH: u8 = 0;
/// Leaf polygons.
pub const KIND_LEAF: u8 = 1;

/// A ring of a tube, before its vertices are made.
struct Ring {
    center: DVec3,
    axis: DVec3,
    reference: DVec3,
    radius: f64,
    v: f64,
}

/// The mesh builder: a turtle [`Sink`]. The turtle pass only records rings
/// and tubes (cheap, sequential: each ring's reference depends on the one
/// before); [`MeshBuilder::finish`] then writes vertices and triangles in
/// parallel.
pub struct MeshBuilder {
    sides: usize,
    cos_sin: Vec<(f64, f64)>,
    rings: Vec<Ring>,
    /// (start ring, end ring, colour) per segment.
    tubes: Vec<(u32, u32, u32)>,
    leaves: Mesh,
    n_leaves: u32,
}

impl MeshBuilder {
    /// A builder for tubes of `sides` (3 to 64) sides.
    pub fn new(sides: usize) -> CoreResult<Self> {
        if !(3..=64).contains(&sides) {
            return Err(CoreError::invalid(
                "sides",
                format!("must be between 3 and 64, got {sides}"),
            ));
        }
        let cos_sin = (0..=sides)
            .map(|j| {
                let t = std::f64::consts::TAU * j as f64 / sides as f64;
                (t.cos(), t.sin())
            })
            .collect();
        Ok(MeshBuilder {
            sides,
            cos_sin,
            rings: Vec::new(),
            tubes: Vec::new(),
            leaves: Mesh::default(),
            n_leaves: 0,
        })
    }

    /// Reserve room for `n` segments and `starts` tube starts.
    pub fn reserve(&mut self, n: usize, starts: usize) {
        self.rings.reserve(n + starts.min(n));
        self.tubes.reserve(n);
    }

    fn ring(&mut self, center: DVec3, axis: DVec3, reference: DVec3, radius: f64, v: f64) -> u32 {
        self.rings.push(Ring {
            center,
            axis,
            reference,
            radius,
            v,
        });
        (self.rings.len() - 1) as u32
    }

    /// Write the vertices and triangles (in parallel in the current rayon
    /// pool). Errors when the mesh is too large for u32 indices.
    pub fn finish(self) -> CoreResult<Mesh> {
        let k1 = self.sides + 1;
        let n_tube_v = self.rings.len() * k1;
        if n_tube_v + self.leaves.vertices.len() > u32::MAX as usize {
            return Err(CoreError::invalid(
                "lstring",
                "the mesh has more than 2^32 vertices",
            ));
        }
        let mut m = Mesh {
            vertices: vec![[0.0; 3]; n_tube_v],
            normals: vec![[0.0; 3]; n_tube_v],
            uvs: vec![[0.0; 2]; n_tube_v],
            ..Mesh::default()
        };
        let (cs, sides) = (&self.cos_sin, self.sides);
        m.vertices
            .par_chunks_mut(k1)
            .zip(m.normals.par_chunks_mut(k1))
            .zip(m.uvs.par_chunks_mut(k1))
            .zip(self.rings.par_iter())
            .for_each(|(((vs, ns), ts), r)| {
                let side = r.axis.cross(r.reference);
                for (j, &(c, s)) in cs.iter().enumerate() {
                    let n = r.reference * c + side * s;
                    vs[j] = (r.center + n * r.radius).as_vec3().to_array();
                    ns[j] = n.as_vec3().to_array();
                    ts[j] = [j as f32 / sides as f32, r.v as f32];
                }
            });
        let per = 2 * sides;
        let nt = self.tubes.len() * per;
        m.faces = vec![[0; 3]; nt];
        m.part_ids = vec![0; nt];
        m.colors = vec![0; nt];
        m.faces
            .par_chunks_mut(per)
            .zip(m.part_ids.par_chunks_mut(per))
            .zip(m.colors.par_chunks_mut(per))
            .zip(self.tubes.par_iter().enumerate())
            .for_each(|(((fs, ps), cl), (i, &(a, b, color)))| {
                let (a, b) = (a * k1 as u32, b * k1 as u32);
                for j in 0..sides as u32 {
                    let (a0, a1, b0, b1) = (a + j, a + j + 1, b + j, b + j + 1);
                    fs[2 * j as usize] = [a0, a1, b1];
                    fs[2 * j as usize + 1] = [a0, b1, b0];
                }
                ps.fill(i as u32);
                cl.fill(color);
            });
        m.kinds = vec![KIND_BRANCH; nt];
        m.instances = vec![0; nt];
        m.append_transformed(&self.leaves, 0, |v| v, |n| n)?;
        Ok(m)
    }
}

fn perpendicular(v: DVec3, axis: DVec3, fallback: DVec3) -> DVec3 {
    let p = v - axis * v.dot(axis);
    let m = p.length();
    if m > 1e-9 {
        p / m
    } else {
        let q = fallback - axis * fallback.dot(axis);
        let m = q.length();
        if m > 1e-9 {
            q / m
        } else {
            axis.any_orthonormal_vector()
        }
    }
}

impl Sink for MeshBuilder {
    fn segment(&mut self, from: &State, to: &State) -> u32 {
        let d = to.pos - from.pos;
        let len = d.length();
        if len <= 0.0 {
            return from.tag;
        }
        let axis = d / len;
        let start = if from.tag != NO_TAG {
            from.tag
        } else {
            let reference = perpendicular(from.l, axis, from.u);
            self.ring(from.pos, axis, reference, 0.5 * from.width, 0.0)
        };
        let (s_ref, s_v) = {
            let s = &self.rings[start as usize];
            (s.reference, s.v)
        };
        let reference = perpendicular(s_ref, axis, from.l);
        let end = self.ring(to.pos, axis, reference, 0.5 * to.width, s_v + len);
        self.tubes.push((start, end, from.color));
        end
    }

    fn polygon(&mut self, pts: &[DVec3], color: u32) {
        // Vertices at the previous one, and closing vertices back at the
        // first (a leaf traced out and back, as in ABOP figure 1.25: the
        // turtle returns to its start up to rounding), add nothing but
        // zero-area (or sliver) fan triangles: closer than 1e-6 of the
        // polygon's size, they are dropped.
        let size = pts
            .iter()
            .map(|p| (*p - pts[0]).length())
            .fold(0.0, f64::max);
        let tol = 1e-6 * size;
        let same = |a: &DVec3, b: &DVec3| (*a - *b).length() <= tol;
        let mut kept: Vec<DVec3> = Vec::with_capacity(pts.len());
        for p in pts {
            if kept.last().is_none_or(|q| !same(q, p)) {
                kept.push(*p);
            }
        }
        while kept.len() > 1 && same(&kept[kept.len() - 1], &kept[0]) {
            kept.pop();
        }
        let f32_of = |p: &DVec3| p.as_vec3().to_array();
        if kept.len() < 3 {
            return; // degenerate leaf: nothing to draw
        }
        let pts = &kept[..];
        // Newell's normal
        let mut nrm = DVec3::ZERO;
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            nrm += DVec3::new(
                (a.y - b.y) * (a.z + b.z),
                (a.z - b.z) * (a.x + b.x),
                (a.x - b.x) * (a.y + b.y),
            );
        }
        let m = nrm.length();
        if !(m > 1e-12) {
            return; // degenerate leaf: nothing to draw
        }
        let nrm = nrm / m;
        let e1 = perpendicular(pts[1] - pts[0], nrm, nrm.any_orthonormal_vector());
        let e2 = nrm.cross(e1);
        let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
        let uv: Vec<[f64; 2]> = pts
            .iter()
            .map(|p| {
                let q = *p - pts[0];
                let c = [q.dot(e1), q.dot(e2)];
                for k in 0..2 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
                c
            })
            .collect();
        // fan triangles of zero area in the stored (f32) coordinates
        // (collinear corners) are left out: meshes must have none
        let stored = |k: usize| DVec3::from_array(f32_of(&pts[k]).map(|x| x as f64));
        let fan: Vec<u32> = (1..pts.len() - 1)
            .filter(|&k| {
                let (a, b, c) = (stored(0), stored(k), stored(k + 1));
                (b - a).cross(c - a).length_squared() > 0.0
            })
            .map(|k| k as u32)
            .collect();
        if fan.is_empty() {
            return;
        }
        let first = self.leaves.vertices.len() as u32;
        for (p, c) in pts.iter().zip(&uv) {
            self.leaves.vertices.push(p.as_vec3().to_array());
            self.leaves.normals.push(nrm.as_vec3().to_array());
            let u = |k: usize| {
                if hi[k] > lo[k] {
                    ((c[k] - lo[k]) / (hi[k] - lo[k])) as f32
                } else {
                    0.0
                }
            };
            self.leaves.uvs.push([u(0), u(1)]);
        }
        let part = self.n_leaves;
        self.n_leaves += 1;
        for k in fan {
            self.leaves.faces.push([first, first + k, first + k + 1]);
            self.leaves.part_ids.push(part);
            self.leaves.kinds.push(KIND_LEAF);
            self.leaves.colors.push(color);
            self.leaves.instances.push(0);
        }
    }
}

/// The mesh of a module string: tubes of `sides` sides and leaves.
pub fn build_mesh(s: &ModString, p: &TurtleParams, sides: usize) -> CoreResult<Mesh> {
    let mut b = MeshBuilder::new(sides)?;
    let (mut n_draw, mut n_new) = (0usize, 1usize);
    for c in &s.syms {
        if p.draw.contains(c) {
            n_draw += 1;
        } else if *c == '[' || *c == '}' || p.moves.contains(c) {
            n_new += 1; // places where a new tube may start
        }
    }
    if 2 * sides * n_draw > MAX_TRIANGLES {
        return Err(CoreError::invalid(
            "lstring",
            format!("the mesh would have {} branch triangles, more than {MAX_TRIANGLES}; derive fewer steps or use fewer sides", 2 * sides * n_draw),
        ));
    }
    b.reserve(n_draw, n_new);
    interpret(s, p, &mut b)?;
    b.finish()
}

/// Rotation about +z by `angle` radians, as a quaternion (for instances).
pub fn yaw(angle: f64) -> DQuat {
    DQuat::from_rotation_z(angle)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lsystem::grammar::parse_module_string;

    #[test]
    fn one_tube_is_closed_and_outward() {
        let s = parse_module_string("F", "axiom").unwrap();
        let m = build_mesh(&s, &TurtleParams::spatial(90.0, 2.0), 6).unwrap();
        assert_eq!(m.vertices.len(), 14);
        assert_eq!(m.faces.len(), 12);
        for (v, n) in m.vertices.iter().zip(&m.normals) {
            // radius 0.5 around the z axis, normal = radial direction
            let r = (v[0] * v[0] + v[1] * v[1]).sqrt();
            assert!((r - 0.5).abs() < 1e-6);
            assert!(
                (n[0] - v[0] / r).abs() < 1e-6
                    && (n[1] - v[1] / r).abs() < 1e-6
                    && n[2].abs() < 1e-6
            );
        }
        for f in &m.faces {
            let p: Vec<DVec3> = f
                .iter()
                .map(|&i| DVec3::from_array(m.vertices[i as usize].map(|x| x as f64)))
                .collect();
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let c = (p[0] + p[1] + p[2]) / 3.0;
            assert!(
                n.dot(DVec3::new(c.x, c.y, 0.0)) > 0.0,
                "triangle faces inwards"
            );
        }
        let vs: Vec<f32> = m.uvs.iter().map(|t| t[1]).collect();
        assert_eq!(vs[0], 0.0);
        assert_eq!(vs[13], 2.0);
    }

    #[test]
    fn a_tube_welded_at_its_seam_is_open_only_at_its_ends() {
        use crate::geometry::EdgeReport;
        let s = parse_module_string("F+F", "axiom").unwrap();
        let sides = 7;
        let m = build_mesh(&s, &TurtleParams::spatial(30.0, 1.0), sides).unwrap();
        assert_eq!(m.vertices.len(), 3 * (sides + 1));
        // the seam vertex (j = sides) repeats j = 0 up to rounding only:
        // cos(2 pi) and sin(2 pi) are not exactly 1 and 0
        let close = |a: [f32; 3], b: [f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-6);
        let weld: Vec<u32> = (0..m.vertices.len())
            .map(|i| {
                (0..=i)
                    .find(|&k| close(m.vertices[k], m.vertices[i]))
                    .unwrap() as u32
            })
            .collect();
        for r in 0..3 {
            assert_eq!(weld[r * (sides + 1) + sides] as usize, r * (sides + 1));
        }
        let mut w = m.clone();
        for f in &mut w.faces {
            *f = f.map(|i| weld[i as usize]);
        }
        // open at the two end rings only, consistently oriented
        assert_eq!(
            w.edges(),
            EdgeReport {
                boundary: 2 * sides,
                non_manifold: 0,
                inconsistent: 0
            }
        );
        m.validate().unwrap();
    }

    #[test]
    fn chains_share_rings_and_branches_do_not() {
        let s = parse_module_string("FF+F[-F]F", "axiom").unwrap();
        let m = build_mesh(&s, &TurtleParams::spatial(30.0, 1.0), 4).unwrap();
        // main chain F F + F F: 5 rings; branch: 2 rings; 5 segments in all
        assert_eq!(m.vertices.len(), 7 * 5);
        assert_eq!(m.faces.len(), 5 * 8);
        assert_eq!(*m.part_ids.iter().max().unwrap(), 4);
        for f in &m.faces {
            assert!(f.iter().all(|&i| (i as usize) < m.vertices.len()));
        }
    }

    #[test]
    fn leaves_are_fans_with_unit_normals() {
        let s = parse_module_string("{.f.+f.+f.}", "axiom").unwrap();
        let m = build_mesh(&s, &TurtleParams::spatial(90.0, 1.0), 6).unwrap();
        assert_eq!(m.faces.len(), 2);
        assert_eq!(m.kinds, vec![KIND_LEAF, KIND_LEAF]);
        // the square lies in the x-z plane: normal along +-y
        assert!((m.normals[0][1].abs() - 1.0).abs() < 1e-6);
        assert!(m
            .uvs
            .iter()
            .all(|t| (0.0..=1.0).contains(&t[0]) && (0.0..=1.0).contains(&t[1])));
    }

    #[test]
    fn leaves_traced_out_and_back_have_no_zero_area_triangle() {
        // ABOP figure 1.25's leaf: out along one side, | turns around, back
        // along the other; the last vertex is the first, and a repeated
        // vertex (f of length 0 is not possible, but `..` is) adds nothing
        let s = parse_module_string("{.-f.+f.+f.-|-f.+f.+f.}{.f..+f.+f.}", "axiom").unwrap();
        let m = build_mesh(&s, &TurtleParams::spatial(22.5, 1.0), 6).unwrap();
        m.validate().unwrap();
        assert_eq!(m.faces.len(), 4 + 2);
        assert_eq!(m.vertices.len(), 6 + 4);
    }
}
