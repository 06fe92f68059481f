//! Instancing: many copies of a few shapes (trees of one species, leaves
//! of one template), one BVH per shape and a top-level BVH over the
//! instances' world boxes, so memory grows with the shapes, not the copies.
//!
//! A ray is tested against an instance by moving it into the shape's frame
//! (the inverse of the instance's affine transform; the direction is not
//! renormalised, so the ray parameter `t` is the world one). Facets are
//! `(instance, triangle)`; their index (material ids) runs over the
//! instances in order, each over its shape's triangles. Periodic tiles as
//! in [`super::mesh_tracer`]: an instance whose box crosses a side of the
//! tile is also stored shifted by one tile.
use glam::{DAffine3, DMat3, DVec3, Vec3A};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::builder::build_cwbvh;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::BvhBuildParams;

use super::mesh_tracer::{periodic_segments, MeshTracer};
use super::tracer::{TraceHit, Tracer};
use crate::error::{CoreError, CoreResult};
use crate::geometry::Mesh;

/// One placed copy of a shape.
#[derive(Debug, Clone)]
struct Inst {
    shape: usize,
    /// World to the shape's mesh frame.
    inv: DAffine3,
    /// Normals from the shape's frame to the world (inverse transpose).
    nxf: DMat3,
    /// Area factor sign (`det < 0` flips the winding).
    det: f64,
    /// Index of the instance's first facet.
    offset: usize,
}

/// Instances of triangle meshes ready for ray casting.
#[derive(Debug)]
pub struct InstancedTracer {
    shapes: Vec<MeshTracer>,
    inst: Vec<Inst>,
    tlas: CwBvh,
    /// Top-level primitives in BVH order: (instance, periodic shift code).
    tprims: Vec<(u32, u32)>,
    periodic: bool,
    tile: (f64, f64, f64, f64),
    zmin: f64,
    zmax: f64,
    zmean: f64,
    n_facets: usize,
    seg_eps: f64,
    skip_dist: f64,
}

impl InstancedTracer {
    /// `shapes` (map coordinates = origin + vertices), and `instances` as
    /// `(shape index, transform)` where the affine transform takes a
    /// shape's map coordinates to the world (the scene's frame, metres).
    /// `extent = (x0, y0, width, height)` in the world frame (required).
    /// Errors name `shapes`, `instances` or `extent`.
    pub fn new(
        shapes: &[Mesh],
        instances: &[(usize, DAffine3)],
        periodic: bool,
        extent: [f64; 4],
    ) -> CoreResult<InstancedTracer> {
        let [x0, y0, w, h] = extent;
        if !extent.iter().all(|v| v.is_finite()) || w <= 0.0 || h <= 0.0 {
            return Err(CoreError::invalid(
                "extent",
                format!("expected finite (x0, y0, width, height) with width, height > 0, got {extent:?}"),
            ));
        }
        if instances.is_empty() {
            return Err(CoreError::invalid(
                "instances",
                "expected at least one instance",
            ));
        }
        let mut tracers = Vec::with_capacity(shapes.len());
        for m in shapes {
            // the shape alone, in its own frame (footprint: its box, padded)
            let (lo, hi) = m
                .bounds()
                .ok_or_else(|| CoreError::invalid("shapes", "a shape has no vertices"))?;
            let ext = [
                lo[0] - 1.0,
                lo[1] - 1.0,
                hi[0] - lo[0] + 2.0,
                hi[1] - lo[1] + 2.0,
            ];
            tracers.push(MeshTracer::new(m, false, Some(ext)).map_err(|e| match e {
                CoreError::InvalidArgument { message, .. } => CoreError::invalid("shapes", message),
                other => other,
            })?);
        }
        let mut inst = Vec::with_capacity(instances.len());
        let mut boxes = Vec::new();
        let mut tprims = Vec::new();
        let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut az, mut a) = (0.0, 0.0);
        let mut offset = 0usize;
        for (k, &(s, xf)) in instances.iter().enumerate() {
            let det = xf.matrix3.determinant();
            if s >= shapes.len() || !det.is_finite() || det == 0.0 || !xf.translation.is_finite() {
                return Err(CoreError::invalid(
                    "instances",
                    format!(
                        "instance {k}: expected a shape index below {} and an invertible finite \
                         transform, got shape {s}, determinant {det}",
                        shapes.len()
                    ),
                ));
            }
            let o = DVec3::from_array(shapes[s].origin);
            // shape mesh frame -> world: xf(origin + p)
            let to_world = xf * DAffine3::from_translation(o);
            let inv = to_world.inverse();
            let nxf = to_world.matrix3.inverse().transpose();
            let tr = &tracers[s];
            // world box of the instance
            let (lo, hi) = tr.bounds();
            let (mut wl, mut wh) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            for c in 0..8 {
                let p = DVec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                );
                let q = to_world.transform_point3(p);
                wl = wl.min(q);
                wh = wh.max(q);
            }
            let cx = 0.5 * (wl.x + wh.x);
            let cy = 0.5 * (wl.y + wh.y);
            if cx < x0 || cx > x0 + w || cy < y0 || cy > y0 + h {
                return Err(CoreError::invalid(
                    "extent",
                    format!("{extent:?} does not cover instance {k} (box centre at ({cx}, {cy}))"),
                ));
            }
            if periodic && (wh.x - wl.x > w || wh.y - wl.y > h) {
                return Err(CoreError::invalid(
                    "extent",
                    format!("instance {k} is wider or taller than the periodic tile"),
                ));
            }
            zmin = zmin.min(wl.z);
            zmax = zmax.max(wh.z);
            for t in 0..tr.len() {
                let (area, n, c) = tr.triangle(t);
                let nw = nxf * n * det.abs();
                let aw = area * nw.length();
                let nzw = if aw > 0.0 {
                    (nw.z / nw.length()).abs()
                } else {
                    0.0
                };
                az += aw * nzw * to_world.transform_point3(c).z;
                a += aw * nzw;
            }
            let pad = 1e-5 * (wh - wl).max_element().max(1e-300)
                + 1e-5 * wl.abs().max(wh.abs()).max_element();
            for sy in -1i32..=1 {
                for sx in -1i32..=1 {
                    let (ox, oy) = (sx as f64 * w, sy as f64 * h);
                    let keep = (sx == 0 && sy == 0)
                        || (periodic
                            && wl.x + ox < x0 + w
                            && wh.x + ox > x0
                            && wl.y + oy < y0 + h
                            && wh.y + oy > y0);
                    if !keep {
                        continue;
                    }
                    let dd = DVec3::new(ox, oy, 0.0);
                    let (bl, bu) = (wl + dd - pad, wh + dd + pad);
                    boxes.push(Aabb::new(
                        Vec3A::new(bl.x as f32, bl.y as f32, bl.z as f32),
                        Vec3A::new(bu.x as f32, bu.y as f32, bu.z as f32),
                    ));
                    tprims.push((k as u32, ((sx + 1) + 3 * (sy + 1)) as u32));
                }
            }
            inst.push(Inst {
                shape: s,
                inv,
                nxf,
                det,
                offset,
            });
            offset += tr.len();
        }
        let tlas = build_cwbvh(
            &boxes,
            BvhBuildParams::medium_build(),
            &mut std::time::Duration::default(),
        );
        let tprims = tlas
            .primitive_indices
            .iter()
            .map(|&i| tprims[i as usize])
            .collect();
        let span = w + h + (zmax - zmin);
        Ok(InstancedTracer {
            shapes: tracers,
            inst,
            tlas,
            tprims,
            periodic,
            tile: (x0, y0, w, h),
            zmin,
            zmax,
            zmean: if a > 0.0 { az / a } else { 0.5 * (zmin + zmax) },
            n_facets: offset,
            seg_eps: 1e-9 * span,
            skip_dist: 1e-7 * span,
        })
    }

    /// Nearest hit `(t, (instance, triangle))` on `o + t d`, `t` in
    /// `[tlo, thi]`; ties go to the lower (instance, shift, triangle).
    fn search(
        &self,
        o: DVec3,
        d: DVec3,
        (tlo, thi): (f64, f64),
        skip: Option<(u32, u32)>,
        t_off: f64,
        any: bool,
    ) -> Option<(f64, (u32, u32))> {
        const BACK: f64 = 1e-3;
        let fmax = if thi.is_finite() {
            ((thi + BACK) as f32) * (1.0 + 1e-5) + 1e-5
        } else {
            f32::INFINITY
        };
        let ob = o - BACK * d;
        let pos0 = |x: f32| if x == 0.0 { 0.0 } else { x };
        let ray = Ray::new(
            Vec3A::new(ob.x as f32, ob.y as f32, ob.z as f32),
            Vec3A::new(pos0(d.x as f32), pos0(d.y as f32), pos0(d.z as f32)),
            0.0,
            fmax,
        );
        let (_, _, w, h) = self.tile;
        // the nearest hit in instance `k` of the top level: (t, key, triangle)
        let visit = |k: usize, bound: f64| -> Option<(f64, (u32, u32), u32)> {
            let (i, shift) = self.tprims[k];
            let ins = &self.inst[i as usize];
            let (sx, sy) = ((shift % 3) as f64 - 1.0, (shift / 3) as f64 - 1.0);
            let ow = o - DVec3::new(sx * w, sy * h, 0.0);
            let ol = ins.inv.transform_point3(ow);
            let dl = ins.inv.transform_vector3(d);
            let skip_tri = match skip {
                Some((si, st)) if si == i => Some(st),
                _ => None,
            };
            let tr = &self.shapes[ins.shape];
            let (t, kk) = tr.search(ol, dl, (tlo, bound), skip_tri, t_off, any)?;
            let tri = if any { 0 } else { tr.prim_tri(kk) };
            Some((t, (i, shift), tri))
        };
        if any {
            let miss = self.tlas.ray_traverse_miss(ray, |_r, k| {
                if visit(k, thi).is_some() {
                    0.0
                } else {
                    f32::INFINITY
                }
            });
            return if miss { None } else { Some((0.0, (0, 0))) };
        }
        let mut best: Option<(f64, (u32, u32), u32)> = None;
        let mut rh = obvhs::ray::RayHit::none();
        self.tlas.ray_traverse(ray, &mut rh, |_r, k| {
            let bound = best.map_or(thi, |b| b.0);
            if let Some((t, key, tri)) = visit(k, bound) {
                let better = match best {
                    None => true,
                    Some((bt, bk, bf)) => t < bt || (t == bt && (key, tri) < (bk, bf)),
                };
                if better {
                    best = Some((t, key, tri));
                }
            }
            match best {
                Some((bt, _, _)) => ((bt + BACK) as f32) * (1.0 + 1e-6) + 1e-6,
                None => f32::INFINITY,
            }
        });
        // the periodic skip rule of `MeshTracer`: the start facet is
        // skipped near the start only (handled in the shape's search)
        let _ = self.skip_dist;
        best.map(|(t, (i, _), tri)| (t, (i, tri)))
    }
}

impl Tracer for InstancedTracer {
    type Facet = (u32, u32);

    fn trace(&self, o: DVec3, d: DVec3, skip: Option<(u32, u32)>) -> Option<TraceHit<(u32, u32)>> {
        let (t, f) = if self.periodic {
            periodic_segments(
                self.tile,
                (self.zmin, self.zmax),
                self.seg_eps,
                o,
                d,
                |os, thi, t0| self.search(os, d, (-self.seg_eps, thi), skip, t0, false),
            )?
        } else {
            self.search(o, d, (0.0, f64::INFINITY), skip, 0.0, false)?
        };
        let ins = &self.inst[f.0 as usize];
        let (_, n, _) = self.shapes[ins.shape].triangle(f.1 as usize);
        let n = (ins.nxf * n * ins.det.signum()).normalize();
        Some(TraceHit {
            t,
            normal: if n.dot(d) > 0.0 { -n } else { n },
            facet: f,
        })
    }

    fn occluded(&self, o: DVec3, d: DVec3, skip: Option<(u32, u32)>) -> bool {
        if self.periodic {
            periodic_segments(
                self.tile,
                (self.zmin, self.zmax),
                self.seg_eps,
                o,
                d,
                |os, thi, t0| self.search(os, d, (-self.seg_eps, thi), skip, t0, true),
            )
            .is_some()
        } else {
            self.search(o, d, (0.0, f64::INFINITY), skip, 0.0, true)
                .is_some()
        }
    }

    fn wrap(&self, p: DVec3, f: (u32, u32)) -> (DVec3, (u32, u32)) {
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
    fn facet_index(&self, f: (u32, u32)) -> usize {
        self.inst[f.0 as usize].offset + f.1 as usize
    }

    fn facet_count(&self) -> usize {
        self.n_facets
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

    fn escapes(&self, d: DVec3) -> bool {
        !self.periodic || d.z > 0.0
    }

    fn facets(&self) -> Vec<(f64, DVec3)> {
        let mut out = Vec::with_capacity(self.n_facets);
        for ins in &self.inst {
            let tr = &self.shapes[ins.shape];
            for t in 0..tr.len() {
                let (area, n, _) = tr.triangle(t);
                let nw = ins.nxf * n * ins.det.abs();
                out.push((area * nw.length(), (nw * ins.det.signum()).normalize()));
            }
        }
        out
    }
}
