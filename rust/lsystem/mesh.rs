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
use glam::{DQuat, DVec3};

/// Triangle kinds in [`Mesh::kinds`].
pub const KIND_BRANCH: u8 = 0;
/// Leaf polygons.
pub const KIND_LEAF: u8 = 1;

/// An indexed triangle mesh with per-triangle attributes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub faces: Vec<[u32; 3]>,
    /// Turtle element of each triangle: segment number for branches, polygon
    /// number for leaves.
    pub part_ids: Vec<u32>,
    /// [`KIND_BRANCH`] or [`KIND_LEAF`].
    pub kinds: Vec<u8>,
    /// Colour index (`'`) of each triangle.
    pub colors: Vec<u32>,
    /// Instance number of each triangle (0 for one plant; see [`super::terrain`]).
    pub instances: Vec<u32>,
}

impl Mesh {
    /// Append `other` moved by `f` (applied to points) and `g` (to normals).
    pub fn append_transformed(&mut self, other: &Mesh, instance: u32, f: impl Fn(DVec3) -> DVec3, g: impl Fn(DVec3) -> DVec3) -> CoreResult<()> {
        let base = self.vertices.len();
        if base + other.vertices.len() > u32::MAX as usize {
            return Err(CoreError::invalid("n_plants", "the scene has more than 2^32 vertices"));
        }
        let b = base as u32;
        self.vertices.extend(other.vertices.iter().map(|v| f(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)).as_vec3().to_array()));
        self.normals.extend(other.normals.iter().map(|v| g(DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)).as_vec3().to_array()));
        self.uvs.extend_from_slice(&other.uvs);
        self.faces.extend(other.faces.iter().map(|t| [t[0] + b, t[1] + b, t[2] + b]));
        self.part_ids.extend_from_slice(&other.part_ids);
        self.kinds.extend_from_slice(&other.kinds);
        self.colors.extend_from_slice(&other.colors);
        self.instances.extend(std::iter::repeat_n(instance, other.faces.len()));
        Ok(())
    }
}

struct Ring {
    first: u32,
    reference: DVec3,
    v: f64,
}

/// The mesh builder: a turtle [`Sink`].
pub struct MeshBuilder {
    pub mesh: Mesh,
    sides: usize,
    cos_sin: Vec<(f64, f64)>,
    rings: Vec<Ring>,
    n_segments: u32,
    n_leaves: u32,
    overflow: bool,
}

impl MeshBuilder {
    /// A builder for tubes of `sides` (>= 3) sides.
    pub fn new(sides: usize) -> CoreResult<Self> {
        if !(3..=64).contains(&sides) {
            return Err(CoreError::invalid("sides", format!("must be between 3 and 64, got {sides}")));
        }
        let cos_sin = (0..=sides)
            .map(|j| {
                let t = std::f64::consts::TAU * j as f64 / sides as f64;
                (t.cos(), t.sin())
            })
            .collect();
        Ok(MeshBuilder { mesh: Mesh::default(), sides, cos_sin, rings: Vec::new(), n_segments: 0, n_leaves: 0, overflow: false })
    }

    fn ring(&mut self, center: DVec3, axis: DVec3, reference: DVec3, radius: f64, v: f64) -> u32 {
        let first = self.mesh.vertices.len();
        if first + self.sides + 1 > u32::MAX as usize {
            self.overflow = true;
        }
        let side = axis.cross(reference);
        for (j, &(c, s)) in self.cos_sin.iter().enumerate() {
            let n = reference * c + side * s;
            self.mesh.vertices.push((center + n * radius).as_vec3().to_array());
            self.mesh.normals.push(n.as_vec3().to_array());
            self.mesh.uvs.push([j as f32 / self.sides as f32, v as f32]);
        }
        self.rings.push(Ring { first: first as u32, reference, v });
        (self.rings.len() - 1) as u32
    }

    /// Finish; errors when the mesh is too large for u32 indices.
    pub fn finish(self) -> CoreResult<Mesh> {
        if self.overflow {
            return Err(CoreError::invalid("lstring", "the mesh has more than 2^32 vertices"));
        }
        Ok(self.mesh)
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
        let r = 0.5 * from.width;
        let start = if from.tag != NO_TAG {
            from.tag
        } else {
            let reference = perpendicular(from.l, axis, from.u);
            self.ring(from.pos, axis, reference, r, 0.0)
        };
        let (s_ref, s_v, s_first) = {
            let s = &self.rings[start as usize];
            (s.reference, s.v, s.first)
        };
        let reference = perpendicular(s_ref, axis, from.l);
        let end = self.ring(to.pos, axis, reference, 0.5 * to.width, s_v + len);
        let e_first = self.rings[end as usize].first;
        let part = self.n_segments;
        self.n_segments += 1;
        for j in 0..self.sides as u32 {
            let (a0, a1, b0, b1) = (s_first + j, s_first + j + 1, e_first + j, e_first + j + 1);
            self.mesh.faces.push([a0, a1, b1]);
            self.mesh.faces.push([a0, b1, b0]);
        }
        let n = 2 * self.sides;
        self.mesh.part_ids.extend(std::iter::repeat_n(part, n));
        self.mesh.kinds.extend(std::iter::repeat_n(KIND_BRANCH, n));
        self.mesh.colors.extend(std::iter::repeat_n(from.color, n));
        self.mesh.instances.extend(std::iter::repeat_n(0, n));
        end
    }

    fn polygon(&mut self, pts: &[DVec3], color: u32) {
        // Newell's normal
        let mut nrm = DVec3::ZERO;
        for k in 0..pts.len() {
            let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
            nrm += DVec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
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
        let first = self.mesh.vertices.len() as u32;
        for (p, c) in pts.iter().zip(&uv) {
            self.mesh.vertices.push(p.as_vec3().to_array());
            self.mesh.normals.push(nrm.as_vec3().to_array());
            let u = |k: usize| if hi[k] > lo[k] { ((c[k] - lo[k]) / (hi[k] - lo[k])) as f32 } else { 0.0 };
            self.mesh.uvs.push([u(0), u(1)]);
        }
        let part = self.n_leaves;
        self.n_leaves += 1;
        for k in 1..pts.len() as u32 - 1 {
            self.mesh.faces.push([first, first + k, first + k + 1]);
            self.mesh.part_ids.push(part);
            self.mesh.kinds.push(KIND_LEAF);
            self.mesh.colors.push(color);
            self.mesh.instances.push(0);
        }
    }
}

/// The mesh of a module string: tubes of `sides` sides and leaves.
pub fn build_mesh(s: &ModString, p: &TurtleParams, sides: usize) -> CoreResult<Mesh> {
    let mut b = MeshBuilder::new(sides)?;
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
            assert!((n[0] - v[0] / r).abs() < 1e-6 && (n[1] - v[1] / r).abs() < 1e-6 && n[2].abs() < 1e-6);
        }
        for f in &m.faces {
            let p: Vec<DVec3> = f.iter().map(|&i| DVec3::from_array(m.vertices[i as usize].map(|x| x as f64))).collect();
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            let c = (p[0] + p[1] + p[2]) / 3.0;
            assert!(n.dot(DVec3::new(c.x, c.y, 0.0)) > 0.0, "triangle faces inwards");
        }
        let vs: Vec<f32> = m.uvs.iter().map(|t| t[1]).collect();
        assert_eq!(vs[0], 0.0);
        assert_eq!(vs[13], 2.0);
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
        assert!(m.uvs.iter().all(|t| (0.0..=1.0).contains(&t[0]) && (0.0..=1.0).contains(&t[1])));
    }
}
