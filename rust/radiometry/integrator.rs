//! Path tracing with next-event estimation to a directional sun, and the
//! BRF, albedo and image estimators built on it.
//!
//! A sensor ray starts on the reference plane (the mean height of the DEM)
//! at a uniformly drawn point of the tile (or of a pixel's footprint, a box)
//! and goes against the view direction. At each facet hit the sun's direct
//! contribution is added when the shadow ray towards the sun escapes; then a
//! new direction is drawn from the facet's reflectance model, up to
//! `max_depth` scattering events (1 = single scattering). There is no sky:
//! rays that escape carry no light.
//!
//! BRF = `pi * L / cos(sun zenith)` with `L` the radiance averaged over the
//! horizontal reference area (unit irradiance normal to the beam). The
//! directional-hemispherical albedo follows rays from the sun: each carries
//! the product of the sampling weights of its scattering events and counts
//! when it escapes upwards (or, without periodicity, through a side).
use glam::DVec3;
use rayon::prelude::*;

use super::heightfield::Heightfield;
use super::material::{basis, Bsdf};
use super::tracer::Tracer;
use crate::error::{CoreError, CoreResult};
use crate::rng::StreamKey;
use std::f64::consts::PI;

/// Paths per block: sums are formed per block and blocks added in order.
const BLOCK: u64 = 1024;

/// The largest image the renderer allocates (pixels), 2^28 (1 GiB of f32).
pub const MAX_PIXELS: u64 = 1 << 28;

/// The largest `max_depth` accepted.
pub const MAX_DEPTH: u32 = 100_000;

/// A Monte Carlo estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Sample mean.
    pub value: f64,
    /// Standard error of the mean (sample standard deviation / sqrt(n)).
    pub se: f64,
    /// Number of paths.
    pub n: u64,
}

/// A surface (a [`Heightfield`] by default, or any [`Tracer`] such as a
/// [`super::MeshTracer`]) with its reflectance models.
///
/// Facet `k` of the tile ([`Tracer::facet_index`]) has material
/// `material_ids[k]`: 0 is [`Scene::material`], `i >= 1` is
/// `more_materials[i - 1]`. Empty `material_ids`: every facet has
/// material 0.
#[derive(Debug)]
pub struct Scene<G: Tracer = Heightfield> {
    /// The geometry.
    pub hf: G,
    /// Material 0 (the reflectance model of every facet when
    /// `material_ids` is empty).
    pub material: Box<dyn Bsdf>,
    /// Materials 1, 2, ...
    pub more_materials: Vec<Box<dyn Bsdf>>,
    /// Material of every facet of the tile (empty: all 0).
    pub material_ids: Vec<u32>,
}

/// Streams: the stream of path `i` of an experiment is `(seed, i)` mixed with
/// a tag so that BRF, albedo and image paths differ for the same seed.
const TAG_BRF: u64 = 0x6272_6600_0000_0000;
const TAG_ALBEDO: u64 = 0x616c_6200_0000_0000;
const TAG_IMAGE: u64 = 0x696d_6700_0000_0000;

fn check_spp(spp: u64) -> CoreResult<()> {
    if spp == 0 {
        return Err(CoreError::invalid(
            "spp",
            "expected a positive number of samples, got 0",
        ));
    }
    Ok(())
}

fn check_depth(max_depth: u32) -> CoreResult<()> {
    if max_depth == 0 || max_depth > MAX_DEPTH {
        return Err(CoreError::invalid(
            "max_depth",
            format!("expected 1 (single scattering) to {MAX_DEPTH}, got {max_depth}"),
        ));
    }
    Ok(())
}

/// Mean and standard error from per-block `(sum, sum of squares, n)` added in order.
fn finish(blocks: &[(f64, f64, u64)]) -> Estimate {
    let (mut s, mut s2, mut n) = (0.0, 0.0, 0u64);
    for &(a, b, k) in blocks {
        s += a;
        s2 += b;
        n += k;
    }
    let nf = n as f64;
    let mean = s / nf;
    let var = if n > 1 {
        ((s2 - s * mean) / (nf - 1.0)).max(0.0)
    } else {
        0.0
    };
    Estimate {
        value: mean,
        se: (var / nf).sqrt(),
        n,
    }
}

impl<G: Tracer> Scene<G> {
    /// One material on every facet.
    pub fn new(hf: G, material: Box<dyn Bsdf>) -> Self {
        Scene {
            hf,
            material,
            more_materials: Vec::new(),
            material_ids: Vec::new(),
        }
    }

    /// Per-facet materials: `material_ids[k]` (one per facet of the tile,
    /// [`Tracer::facet_index`] order) indexes `materials`. Errors name
    /// `materials` (empty) or `material_ids` (wrong length, index out of
    /// range).
    pub fn with_materials(
        hf: G,
        materials: Vec<Box<dyn Bsdf>>,
        material_ids: Vec<u32>,
    ) -> CoreResult<Self> {
        let mut it = materials.into_iter();
        let Some(first) = it.next() else {
            return Err(CoreError::invalid(
                "materials",
                "expected at least one material, got none",
            ));
        };
        let more: Vec<Box<dyn Bsdf>> = it.collect();
        let nf = hf.facet_count();
        if material_ids.len() != nf {
            return Err(CoreError::invalid(
                "material_ids",
                format!(
                    "expected one material index per facet ({nf}), got {}",
                    material_ids.len()
                ),
            ));
        }
        let nm = more.len() + 1;
        if let Some(k) = material_ids.iter().position(|&i| i as usize >= nm) {
            return Err(CoreError::invalid(
                "material_ids",
                format!(
                    "facet {k} has material index {}, but there are {nm} materials",
                    material_ids[k]
                ),
            ));
        }
        Ok(Scene {
            hf,
            material: first,
            more_materials: more,
            material_ids,
        })
    }

    /// The reflectance model of a facet.
    #[inline(always)]
    pub fn bsdf(&self, f: G::Facet) -> &dyn Bsdf {
        if self.material_ids.is_empty() {
            return &*self.material;
        }
        match self.material_ids[self.hf.facet_index(f)] {
            0 => &*self.material,
            i => &*self.more_materials[i as usize - 1],
        }
    }

    /// World-to-local of `w` in the frame of normal `n`.
    #[inline]
    fn local(n: DVec3, t: DVec3, b: DVec3, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(t), w.dot(b), w.dot(n))
    }

    /// One scattering draw at a facet with frame `(t, b, n)` for light
    /// leaving along local `wo`: the new world direction and the sampling
    /// weight, from the uniforms `dim`, `dim + 1` of `key` (`dim` advances).
    #[inline]
    fn scatter(
        m: &dyn Bsdf,
        (t, b, n): (DVec3, DVec3, DVec3),
        wo: DVec3,
        key: StreamKey,
        dim: &mut u64,
    ) -> Option<(DVec3, f64)> {
        let u = [key.uniform(*dim), key.uniform(*dim + 1)];
        *dim += 2;
        let smp = m.sample(wo, u)?;
        Some((smp.wi.x * t + smp.wi.y * b + smp.wi.z * n, smp.weight))
    }

    /// Start of a ray through the reference-plane point `(x, y)` going
    /// against `v` (from above the highest facet).
    #[inline]
    fn sensor_ray(&self, x: f64, y: f64, v: DVec3) -> DVec3 {
        let (_, zmax, zref) = self.hf.z_range();
        let top = zmax + 1e-6 * (1.0 + zmax.abs());
        let lift = (top - zref).max(0.0) / v.z;
        DVec3::new(x, y, zref) + lift * v
    }

    /// Radiance along the ray `o - t v` (towards the surface) for unit sun
    /// irradiance normal to `s`, up to `max_depth` scattering events; `key`
    /// supplies uniforms from index `dim` on.
    fn radiance(
        &self,
        mut o: DVec3,
        v: DVec3,
        s: DVec3,
        max_depth: u32,
        key: StreamKey,
        mut dim: u64,
    ) -> f64 {
        let hf = &self.hf;
        let mut d = -v;
        let mut skip: Option<G::Facet> = None;
        let mut throughput = 1.0;
        let mut l = 0.0;
        for depth in 1..=max_depth {
            let Some(hit) = hf.trace(o, d, skip) else {
                break;
            };
            let n = hit.normal;
            if n.dot(d) >= 0.0 {
                break; // reached a facet from below: numerically lost
            }
            let (p, facet) = hf.wrap(o + hit.t * d, hit.facet);
            let (t, b) = basis(n);
            let wo = Self::local(n, t, b, -d);
            let m = self.bsdf(facet);
            let cos_s = n.dot(s);
            if (cos_s > 0.0 || (cos_s < 0.0 && m.transmits())) && !hf.occluded(p, s, Some(facet)) {
                let wi = Self::local(n, t, b, s);
                l += throughput * m.eval(wi, wo) * cos_s.abs();
            }
            if depth == max_depth {
                break;
            }
            let Some((wi, weight)) = Self::scatter(m, (t, b, n), wo, key, &mut dim) else {
                break;
            };
            throughput *= weight;
            if throughput == 0.0 {
                break;
            }
            d = wi;
            o = p;
            skip = Some(facet);
        }
        l
    }

    /// Bidirectional reflectance factor for the sun towards `sun` and the
    /// sensor towards `view` (unit vectors (east, north, up) from
    /// [`super::direction`]), over `spp` paths of at most `max_depth`
    /// scattering events.
    pub fn brf(
        &self,
        sun: DVec3,
        view: DVec3,
        spp: u64,
        max_depth: u32,
        seed: u64,
    ) -> CoreResult<Estimate> {
        check_spp(spp)?;
        check_depth(max_depth)?;
        let (x0, y0, w, h) = self.hf.footprint();
        let ytop = y0 + h;
        let norm = PI / sun.z;
        let blocks: Vec<(f64, f64, u64)> = (0..spp.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let (mut s1, mut s2) = (0.0, 0.0);
                let end = ((blk + 1) * BLOCK).min(spp);
                for i in blk * BLOCK..end {
                    let key = StreamKey::new(seed, TAG_BRF ^ i);
                    let (x, y) = (x0 + key.uniform(0) * w, ytop - key.uniform(1) * h);
                    let o = self.sensor_ray(x, y, view);
                    let r = norm * self.radiance(o, view, sun, max_depth, key, 2);
                    s1 += r;
                    s2 += r * r;
                }
                (s1, s2, end - blk * BLOCK)
            })
            .collect();
        Ok(finish(&blocks))
    }

    /// Directional-hemispherical reflectance (black-sky albedo) for the sun
    /// towards `sun`, over `spp` rays of at most `max_depth` scattering events.
    pub fn albedo(&self, sun: DVec3, spp: u64, max_depth: u32, seed: u64) -> CoreResult<Estimate> {
        check_spp(spp)?;
        check_depth(max_depth)?;
        let (x0, y0, w, h) = self.hf.footprint();
        let ytop = y0 + h;
        let hf = &self.hf;
        let blocks: Vec<(f64, f64, u64)> = (0..spp.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let (mut s1, mut s2) = (0.0, 0.0);
                let end = ((blk + 1) * BLOCK).min(spp);
                for i in blk * BLOCK..end {
                    let key = StreamKey::new(seed, TAG_ALBEDO ^ i);
                    let (x, y) = (x0 + key.uniform(0) * w, ytop - key.uniform(1) * h);
                    let mut o = self.sensor_ray(x, y, sun);
                    let mut d = -sun;
                    let mut skip = None;
                    let mut throughput = 1.0;
                    let mut r = 0.0;
                    let mut dim = 2u64;
                    for depth in 0..=max_depth {
                        let Some(hit) = hf.trace(o, d, skip) else {
                            if depth > 0 && hf.escapes(d) {
                                r = throughput; // escaped after scattering
                            }
                            break;
                        };
                        if depth == max_depth || hit.normal.dot(d) >= 0.0 {
                            break; // still trapped (or lost): not counted
                        }
                        let n = hit.normal;
                        let (p, facet) = hf.wrap(o + hit.t * d, hit.facet);
                        let (t, b) = basis(n);
                        let wo = Self::local(n, t, b, -d);
                        // reciprocity: sample the reflected direction as an
                        // incident one for the light's arrival direction
                        let m = self.bsdf(facet);
                        let Some((wi, weight)) = Self::scatter(m, (t, b, n), wo, key, &mut dim)
                        else {
                            break;
                        };
                        throughput *= weight;
                        if throughput == 0.0 {
                            break;
                        }
                        d = wi;
                        o = p;
                        skip = Some(facet);
                    }
                    s1 += r;
                    s2 += r * r;
                }
                (s1, s2, end - blk * BLOCK)
            })
            .collect();
        Ok(finish(&blocks))
    }

    /// A `rows x cols` radiance image (row-major, unit sun irradiance normal
    /// to the beam) seen by an orthographic sensor towards `view`: pixel
    /// `(i, j)` averages `spp` paths through uniform points of its box
    /// footprint on the reference plane, the tile divided evenly.
    pub fn render(
        &self,
        sun: DVec3,
        view: DVec3,
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
    ) -> CoreResult<Vec<f32>> {
        self.render_progress(sun, view, shape, spp, max_depth, seed, None)
    }

    /// [`Scene::render`], ticking `progress` once per image row (the image
    /// does not depend on it).
    #[allow(clippy::too_many_arguments)]
    pub fn render_progress(
        &self,
        sun: DVec3,
        view: DVec3,
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
        progress: Option<&crate::progress::Progress>,
    ) -> CoreResult<Vec<f32>> {
        check_spp(spp)?;
        check_depth(max_depth)?;
        let (rows, cols) = shape;
        if rows == 0 || cols == 0 {
            return Err(CoreError::invalid(
                "shape",
                format!("expected a positive number of rows and columns, got ({rows}, {cols})"),
            ));
        }
        let npix = rows as u128 * cols as u128;
        if npix > MAX_PIXELS as u128 {
            return Err(CoreError::OutOfMemory {
                param: "shape".into(),
                bytes: npix * 4,
            });
        }
        let mut img: Vec<f32> = crate::buffers::try_filled(rows * cols, 0.0f32, "shape")?;
        if let Some(p) = progress {
            p.add_total(rows as u64);
        }
        let (x0, y0, w, h) = self.hf.footprint();
        let ytop = y0 + h;
        let (pw, ph) = (w / cols as f64, h / rows as f64);
        img.par_chunks_mut(cols).enumerate().for_each(|(i, line)| {
            for (j, px) in line.iter_mut().enumerate() {
                let pixel = (i * cols + j) as u64;
                let mut s = 0.0;
                for k in 0..spp {
                    let key =
                        StreamKey::new(seed, TAG_IMAGE ^ pixel.wrapping_mul(spp).wrapping_add(k));
                    let x = x0 + (j as f64 + key.uniform(0)) * pw;
                    let y = ytop - (i as f64 + key.uniform(1)) * ph;
                    let o = self.sensor_ray(x, y, view);
                    s += self.radiance(o, view, sun, max_depth, key, 2);
                }
                *px = (s / spp as f64) as f32;
            }
            if let Some(p) = progress {
                p.tick(1);
            }
        });
        Ok(img)
    }
}
