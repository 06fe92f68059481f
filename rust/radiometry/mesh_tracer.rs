//! A triangle mesh as a [`Tracer`]: a compressed wide BVH (`obvhs` CWBVH8)
//! over the triangles, exact `f64` ray-triangle tests (Möller & Trumbore
//! 1997), two-sided facets, and periodic tiles.
//!
//! Frame: the mesh's own (vertex offsets from [`Mesh::origin`], metres, `x`
//! east, `y` north, `z` up); the tile box is given in map coordinates and
//! moved into it.
//!
//! Periodic tiles: a triangle that crosses a side of the tile box is also
//! stored shifted by one tile width (height) so that every point of the
//! infinite surface inside the box is represented once. A ray is clipped to
//! the box; the BVH is searched over that segment only; when nothing is hit
//! the ray re-enters from the opposite side (the origin moves by one tile,
//! the ray parameter `t` is unchanged) and continues until it hits, or
//! leaves the slab between the lowest and highest vertex.
use glam::{DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::BvhBuildParams;

use super::tracer::{TraceHit, Tracer};
use crate::error::{CoreError, CoreResult};
use crate::geometry::Mesh;

/// Upper bound on tile crossings of one ray (near-horizontal rays in a
/// periodic scene); such a ray is then treated as escaping.
const MAX_WRAPS: usize = 1 << 16;

/// How far (ray parameter) the BVH's `f32` ray starts behind the exact one.
const BVH_BACK: f64 = 1e-3;

/// Tolerance of the barycentric test (edges shared by two triangles are
/// then never missed by both).
const BARY_EPS: f64 = 1e-10;

/// One BVH primitive: a triangle (or a periodic copy of it).
#[derive(Debug, Clone, Copy)]
struct Prim {
    v: [[f32; 3]; 3],
    /// Original triangle index.
    tri: u32,
    /// Shift in tiles, `(sx + 1) + 3 (sy + 1)` with `sx, sy` in {-1, 0, 1}.
    shift: u32,
}

/// A triangle mesh ready for ray casting (see the module docs).
#[derive(Debug, Clone)]
pub struct MeshTracer {
    bvh: CwBvh,
    prims: Vec<Prim>,
    /// Area and unit normal (right-handed winding) of every triangle.
    tri_facets: Vec<(f64, DVec3)>,
    /// Centroid of every triangle (mesh frame).
    tri_centroids: Vec<DVec3>,
    /// Whether the tile repeats periodically.
    pub periodic: bool,
    /// Tile box in the mesh frame: `(x0, y0, width, height)`.
    pub tile: (f64, f64, f64, f64),
    /// Map coordinates of the mesh frame's origin.
    pub origin: [f64; 3],
    /// Lowest vertex height (mesh frame).
    pub zmin: f64,
    /// Highest vertex height (mesh frame).
    pub zmax: f64,
    /// The reference plane of the sensor: the mean height of the surface
    /// seen from above (triangle centroid heights weighted by projected
    /// area).
    pub zmean: f64,
    /// Distance below which a ray does not hit the facet it starts on.
    skip_dist: f64,
    /// Tolerance of the segment ends (periodic tiles).
    seg_eps: f64,
}

#[inline(always)]
fn v64(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// `x` with `-0.0` replaced by `+0.0`.
#[inline(always)]
fn pos0(x: f32) -> f32 {
    if x == 0.0 {
        0.0
    } else {
        x
    }
}

impl MeshTracer {
    /// Build from a mesh; `extent = (x0, y0, width, height)` in map
    /// coordinates is the tile (periodic) or the sensor's footprint
    /// (default: the mesh's horizontal bounding box). Every triangle's
    /// centroid must lie in the extent; with `periodic`, no triangle may be
    /// wider or taller than the tile. Errors name `mesh` (no triangles,
    /// indices out of range, non-finite or degenerate triangles) or
    /// `extent`.
    pub fn new(mesh: &Mesh, periodic: bool, extent: Option<[f64; 4]>) -> CoreResult<MeshTracer> {
        if mesh.faces.is_empty() {
            return Err(CoreError::invalid(
                "mesh",
                "expected at least one triangle, got none",
            ));
        }
        if mesh.faces.len() >= (u32::MAX / 9) as usize {
            return Err(CoreError::invalid("mesh", "more than 4.7e8 triangles"));
        }
        if !mesh.origin.iter().all(|x| x.is_finite()) {
            return Err(CoreError::invalid(
                "mesh",
                format!("origin must be finite, got {:?}", mesh.origin),
            ));
        }
        let nv = mesh.vertices.len();
        let mut tri_facets = crate::buffers::try_with_capacity(mesh.faces.len(), "mesh")?;
        for (k, f) in mesh.faces.iter().enumerate() {
            if f.iter().any(|&i| i as usize >= nv) {
                return Err(CoreError::invalid(
                    "mesh",
                    format!("triangle {k} refers to vertex {f:?}, but there are {nv} vertices"),
                ));
            }
            let p = f.map(|i| mesh.vertices[i as usize]);
            if !p.iter().flatten().all(|x| x.is_finite()) {
                return Err(CoreError::invalid(
                    "mesh",
                    format!("triangle {k} has a NaN or infinite vertex: {p:?}"),
                ));
            }
            let (a, b, c) = (v64(p[0]), v64(p[1]), v64(p[2]));
            let n = (b - a).cross(c - a);
            let len = n.length();
            let scale = (b - a).length() * (c - a).length();
            if len <= 1e-12 * scale {
                return Err(CoreError::invalid(
                    "mesh",
                    format!("triangle {k} {f:?} is degenerate (zero area): {p:?}"),
                ));
            }
            tri_facets.push((0.5 * len, n / len));
        }
        // bounds of the used vertices (mesh frame)
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let mut zsum = 0.0;
        let mut used = vec![false; nv];
        for f in &mesh.faces {
            for &i in f {
                let p = v64(mesh.vertices[i as usize]);
                lo = lo.min(p);
                hi = hi.max(p);
                if !used[i as usize] {
                    used[i as usize] = true;
                    zsum += p.z;
                }
            }
        }
        // reference height: the mean height of the surface seen from above
        // (centroid heights weighted by projected area; for a periodic grid
        // the mean vertex height), else the mean vertex height
        let (mut az, mut a) = (0.0, 0.0);
        for (f, (area, n)) in mesh.faces.iter().zip(&tri_facets) {
            let w = area * n.z.abs();
            let zc: f64 = f.iter().map(|&i| mesh.vertices[i as usize][2] as f64).sum();
            az += w * zc / 3.0;
            a += w;
        }
        let zmean = if a > 0.0 {
            az / a
        } else {
            zsum / used.iter().filter(|&&u| u).count() as f64
        };
        let tile = match extent {
            None => {
                let (w, h) = (hi.x - lo.x, hi.y - lo.y);
                if !(w > 0.0 && h > 0.0) {
                    return Err(CoreError::invalid(
                        "extent",
                        format!(
                            "the mesh's horizontal extent is {w} x {h}: give an extent \
                             (x0, y0, width, height) of positive area"
                        ),
                    ));
                }
                (lo.x, lo.y, w, h)
            }
            Some([x0, y0, w, h]) => {
                if !(x0.is_finite() && y0.is_finite() && w.is_finite() && h.is_finite())
                    || w <= 0.0
                    || h <= 0.0
                {
                    return Err(CoreError::invalid(
                        "extent",
                        format!(
                            "expected finite (x0, y0, width, height) with positive width and \
                             height, got ({x0}, {y0}, {w}, {h})"
                        ),
                    ));
                }
                (x0 - mesh.origin[0], y0 - mesh.origin[1], w, h)
            }
        };
        let (x0, y0, w, h) = tile;
        let tol = 1e-9 * (w + h + x0.abs() + y0.abs());
        for (k, f) in mesh.faces.iter().enumerate() {
            let p = f.map(|i| v64(mesh.vertices[i as usize]));
            let c = (p[0] + p[1] + p[2]) / 3.0;
            if c.x < x0 - tol || c.x > x0 + w + tol || c.y < y0 - tol || c.y > y0 + h + tol {
                return Err(CoreError::invalid(
                    "extent",
                    format!(
                        "({}, {}, {w}, {h}) does not cover the mesh: the centroid of triangle {k} \
                         is at ({}, {}) (map coordinates)",
                        x0 + mesh.origin[0],
                        y0 + mesh.origin[1],
                        c.x + mesh.origin[0],
                        c.y + mesh.origin[1]
                    ),
                ));
            }
            if periodic {
                let (l, u) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
                if u.x - l.x > w || u.y - l.y > h {
                    return Err(CoreError::invalid(
                        "extent",
                        format!(
                            "triangle {k} is wider or taller ({} x {}) than the periodic tile \
                             ({w} x {h})",
                            u.x - l.x,
                            u.y - l.y
                        ),
                    ));
                }
            }
        }
        // primitives (with periodic copies) and their padded boxes
        let scale = (hi - lo).abs().max_element().max(w).max(h);
        let pad = 1e-5 * (scale + lo.abs().max_element() + hi.abs().max_element());
        let mut prims = Vec::with_capacity(mesh.faces.len());
        let mut boxes = Vec::with_capacity(mesh.faces.len());
        for (k, f) in mesh.faces.iter().enumerate() {
            let v = f.map(|i| mesh.vertices[i as usize]);
            let p = v.map(v64);
            let (l, u) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            for sy in -1i32..=1 {
                for sx in -1i32..=1 {
                    let (ox, oy) = (sx as f64 * w, sy as f64 * h);
                    let keep = if !periodic {
                        sx == 0 && sy == 0
                    } else {
                        (sx == 0 && sy == 0)
                            || (l.x + ox < x0 + w
                                && u.x + ox > x0
                                && l.y + oy < y0 + h
                                && u.y + oy > y0)
                    };
                    if !keep {
                        continue;
                    }
                    let d = DVec3::new(ox, oy, 0.0);
                    let (bl, bu) = (l + d - pad, u + d + pad);
                    boxes.push(Aabb::new(
                        Vec3A::new(bl.x as f32, bl.y as f32, bl.z as f32),
                        Vec3A::new(bu.x as f32, bu.y as f32, bu.z as f32),
                    ));
                    prims.push(Prim {
                        v,
                        tri: k as u32,
                        shift: ((sx + 1) + 3 * (sy + 1)) as u32,
                    });
                }
            }
        }
        let bvh = build_cwbvh(
            &boxes,
            BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let prims = bvh
            .primitive_indices
            .iter()
            .map(|&i| prims[i as usize])
            .collect();
        let tri_centroids = mesh
            .faces
            .iter()
            .map(|f| {
                f.iter()
                    .map(|&i| v64(mesh.vertices[i as usize]))
                    .sum::<DVec3>()
                    / 3.0
            })
            .collect();
        Ok(MeshTracer {
            bvh,
            prims,
            tri_facets,
            tri_centroids,
            periodic,
            tile,
            origin: mesh.origin,
            zmin: lo.z,
            zmax: hi.z,
            zmean,
            skip_dist: 1e-7 * (w + h + (hi.z - lo.z)),
            seg_eps: 1e-9 * (w + h + (hi.z - lo.z)),
        })
    }

    /// Number of triangles (without periodic copies).
    pub fn len(&self) -> usize {
        self.tri_facets.len()
    }

    /// True for a mesh without triangles (never: construction refuses it).
    pub fn is_empty(&self) -> bool {
        self.tri_facets.is_empty()
    }

    /// Number of BVH primitives (triangles and their periodic copies).
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// `t` of the ray `o + t d` on primitive `k` within `[tlo, thi]`, or
    /// `None`; `t_off` is added to compare with the skip distance.
    #[inline(always)]
    fn hit_prim(
        &self,
        k: usize,
        o: DVec3,
        d: DVec3,
        (tlo, thi): (f64, f64),
        skip: Option<u32>,
        t_off: f64,
    ) -> Option<f64> {
        let p = &self.prims[k];
        let (sx, sy) = ((p.shift % 3) as f64 - 1.0, (p.shift / 3) as f64 - 1.0);
        let v0 = v64(p.v[0]) + DVec3::new(sx * self.tile.2, sy * self.tile.3, 0.0);
        let e1 = v64(p.v[1]) - v64(p.v[0]);
        let e2 = v64(p.v[2]) - v64(p.v[0]);
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let inv = 1.0 / det;
        let tv = o - v0;
        let u = tv.dot(pv) * inv;
        if !(-BARY_EPS..=1.0 + BARY_EPS).contains(&u) {
            return None;
        }
        let q = tv.cross(e1);
        let v = d.dot(q) * inv;
        if v < -BARY_EPS || u + v > 1.0 + BARY_EPS {
            return None;
        }
        let t = e2.dot(q) * inv;
        if !(t >= tlo && t <= thi) || t + t_off <= 1e-10 {
            return None;
        }
        if skip == Some(p.tri) && (!self.periodic || t + t_off < self.skip_dist) {
            return None;
        }
        Some(t)
    }

    /// Nearest hit `(t, primitive)` on `o + t d`, `t` in `[tlo, thi]`
    /// (`any`: the first hit found, for shadow rays). Ties go to the lower
    /// primitive (triangle, shift), so the result does not depend on the
    /// BVH's layout.
    #[inline]
    pub(crate) fn search(
        &self,
        o: DVec3,
        d: DVec3,
        (tlo, thi): (f64, f64),
        skip: Option<u32>,
        t_off: f64,
        any: bool,
    ) -> Option<(f64, usize)> {
        // obvhs culls nodes whose exit is below t = 1e-4 whatever the
        // ray's tmin: its f32 ray starts BVH_BACK behind the f64 one (the
        // exact test below uses the f64 ray)
        let fmax = if thi.is_finite() {
            ((thi + BVH_BACK) as f32) * (1.0 + 1e-5) + 1e-5
        } else {
            f32::INFINITY
        };
        let ob = o - BVH_BACK * d;
        let ray = Ray::new(
            Vec3A::new(ob.x as f32, ob.y as f32, ob.z as f32),
            // no negative zeros: obvhs orders children by the sign bits
            Vec3A::new(pos0(d.x as f32), pos0(d.y as f32), pos0(d.z as f32)),
            0.0,
            fmax,
        );
        let mut best: Option<(f64, usize)> = None;
        if any {
            let miss = self.bvh.ray_traverse_miss(ray, |_r, k| {
                match self.hit_prim(k, o, d, (tlo, thi), skip, t_off) {
                    Some(_) => 0.0,
                    None => f32::INFINITY,
                }
            });
            return if miss { None } else { Some((0.0, 0)) };
        }
        let mut hit = obvhs::ray::RayHit::none();
        self.bvh.ray_traverse(ray, &mut hit, |_r, k| {
            let Some(t) = self.hit_prim(k, o, d, (tlo, thi), skip, t_off) else {
                return f32::INFINITY;
            };
            let better = match best {
                None => true,
                Some((bt, bk)) => t < bt || (t == bt && self.prim_key(k) < self.prim_key(bk)),
            };
            if better {
                best = Some((t, k));
            }
            // a bound for the traversal no smaller than t
            let b = best.map_or(t, |(bt, _)| bt) + BVH_BACK;
            (b as f32) * (1.0 + 1e-6) + 1e-6
        });
        best
    }

    /// The triangle of BVH primitive `k`.
    #[inline(always)]
    pub(crate) fn prim_tri(&self, k: usize) -> u32 {
        self.prims[k].tri
    }

    /// Area, unit normal and centroid of triangle `tri` (mesh frame).
    pub(crate) fn triangle(&self, tri: usize) -> (f64, DVec3, DVec3) {
        let (a, n) = self.tri_facets[tri];
        (a, n, self.tri_centroids[tri])
    }

    /// Lower and upper corners of the triangles' bounding box (mesh frame).
    pub(crate) fn bounds(&self) -> (DVec3, DVec3) {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in &self.prims {
            for v in p.v {
                lo = lo.min(v64(v));
                hi = hi.max(v64(v));
            }
        }
        (lo, hi)
    }

    #[inline]
    pub(crate) fn prim_key(&self, k: usize) -> (u32, u32) {
        (self.prims[k].tri, self.prims[k].shift)
    }

    /// The nearest hit (`any`: whether something is hit) over all tiles.
    pub(crate) fn cast(
        &self,
        o: DVec3,
        d: DVec3,
        skip: Option<u32>,
        any: bool,
    ) -> Option<(f64, usize)> {
        if !self.periodic {
            return self.search(o, d, (0.0, f64::INFINITY), skip, 0.0, any);
        }
        periodic_segments(
            self.tile,
            (self.zmin, self.zmax),
            self.seg_eps,
            o,
            d,
            |os, thi, t0| self.search(os, d, (-self.seg_eps, thi), skip, t0, any),
        )
    }
}

/// The periodic ray walk shared by the mesh tracers: `o + t d` is clipped
/// to the tile box `(x0, y0, width, height)`; `search(os, thi, t0)` looks
/// for a hit on the segment from `os` (the point at `t0`, moved into the
/// tile) up to `thi` past it and returns `(t - t0, payload)`; with no hit
/// the ray re-enters from the opposite side, until it leaves the slab
/// `zr = (lowest, highest)`. Returns the nearest `(t, payload)`.
pub(crate) fn periodic_segments<X>(
    (x0, y0, w, h): (f64, f64, f64, f64),
    (zmin, zmax): (f64, f64),
    eps: f64,
    o: DVec3,
    d: DVec3,
    mut search: impl FnMut(DVec3, f64, f64) -> Option<(f64, X)>,
) -> Option<(f64, X)> {
    let (x1, y1) = (x0 + w, y0 + h);
    let mut oc = o;
    oc.x -= ((o.x - x0) / w).floor() * w;
    oc.y -= ((o.y - y0) / h).floor() * h;
    let mut t0 = 0.0f64;
    for _ in 0..MAX_WRAPS {
        let tx = if d.x > 0.0 {
            (x1 - oc.x) / d.x
        } else if d.x < 0.0 {
            (x0 - oc.x) / d.x
        } else {
            f64::INFINITY
        };
        let ty = if d.y > 0.0 {
            (y1 - oc.y) / d.y
        } else if d.y < 0.0 {
            (y0 - oc.y) / d.y
        } else {
            f64::INFINITY
        };
        let t1 = tx.min(ty).max(t0);
        let z0 = oc.z + t0 * d.z;
        let z1 = if t1.is_finite() {
            oc.z + t1 * d.z
        } else if d.z > 0.0 {
            f64::INFINITY
        } else if d.z < 0.0 {
            f64::NEG_INFINITY
        } else {
            oc.z
        };
        if z0.min(z1) <= zmax + eps && z0.max(z1) >= zmin - eps {
            // search the segment from its own start (small f32 offsets)
            let os = oc + t0 * d;
            let thi = if t1.is_finite() {
                t1 - t0 + eps
            } else {
                f64::INFINITY
            };
            if let Some((t, k)) = search(os, thi, t0) {
                return Some((t + t0, k));
            }
        }
        if !t1.is_finite() || (d.z >= 0.0 && z1 > zmax) || (d.z < 0.0 && z1 < zmin) {
            return None;
        }
        if tx <= ty {
            oc.x -= d.x.signum() * w;
        }
        if ty <= tx {
            oc.y -= d.y.signum() * h;
        }
        t0 = t1;
    }
    None
}

impl Tracer for MeshTracer {
    type Facet = u32;

    fn trace(&self, o: DVec3, d: DVec3, skip: Option<u32>) -> Option<TraceHit<u32>> {
        let (t, k) = self.cast(o, d, skip, false)?;
        let tri = self.prims[k].tri;
        let n = self.tri_facets[tri as usize].1;
        Some(TraceHit {
            t,
            normal: if n.dot(d) > 0.0 { -n } else { n },
            facet: tri,
        })
    }

    fn occluded(&self, o: DVec3, d: DVec3, skip: Option<u32>) -> bool {
        self.cast(o, d, skip, true).is_some()
    }

    fn wrap(&self, p: DVec3, f: u32) -> (DVec3, u32) {
        if !self.periodic {
            return (p, f);
        }
        let (x0, y0, w, h) = self.tile;
        (
            DVec3::new(
                p.x - ((p.x - x0) / w).floor() * w,
                p.y - ((p.y - y0) / h).floor() * h,
                p.z,
            ),
            f,
        )
    }

    #[inline(always)]
    fn facet_index(&self, f: u32) -> usize {
        f as usize
    }

    fn facet_count(&self) -> usize {
        self.tri_facets.len()
    }

    fn footprint(&self) -> (f64, f64, f64, f64) {
        self.tile
    }

    fn z_range(&self) -> (f64, f64, f64) {
        (self.zmin, self.zmax, self.zmean)
    }

    fn is_periodic(&self) -> bool {
        self.periodic
    }

    /// Periodic: only rays going up leave the surface as reflected light
    /// (a ray leaving below the lowest vertex went through the layer).
    fn escapes(&self, d: DVec3) -> bool {
        !self.periodic || d.z > 0.0
    }

    fn facets(&self) -> Vec<(f64, DVec3)> {
        self.tri_facets.clone()
    }
}
