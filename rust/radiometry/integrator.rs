//! Path tracing with next-event estimation to a directional sun, and the
//! BRF, albedo and image estimators built on it.
//!
//! A sensor ray starts on the reference plane (the mean height of the DEM)
//! at a uniformly drawn point of the tile (or of a pixel's footprint, a box)
//! and goes against the view direction. At each facet hit the sun's direct
//! contribution is added when the shadow ray towards the sun escapes; then a
//! new direction is drawn from the facet's reflectance model, up to
//! `max_depth` scattering events (1 = single scattering). An optional
//! isotropic sky lights paths that leave upwards after scattering; without
//! it, rays that escape carry no light. The same walk serves the BRF (HDRF
//! with a sky), the orthographic images (any point-spread function) and the
//! perspective camera; the geometry is any [`Tracer`] (heightfield or mesh)
//! with per-facet materials.
//!
//! BRF = `pi * L / cos(sun zenith)` with `L` the radiance averaged over the
//! horizontal reference area (unit irradiance normal to the beam). The BRF
//! draws its sensor points and scattering directions from independently
//! Owen-scrambled Sobol sequences (randomised quasi-Monte Carlo, its error
//! the spread of the replicates); images and albedos use independent
//! uniforms. The
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
    /// Standard error of the mean: sample standard deviation / sqrt(n), or
    /// for the BRF the spread of its replicate means ([`Scene::brf_sky`]).
    pub se: f64,
    /// Number of paths.
    pub n: u64,
}

/// A reflectance factor split by scattering order ([`Scene::brf_orders`]),
/// each part estimated from the same paths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrderSplit {
    /// Light scattered once (the first-order next-event estimate).
    pub single: Estimate,
    /// Light scattered two to `max_depth` times (per path: total - single).
    pub multiple: Estimate,
    /// All orders up to `max_depth` ([`Scene::brf_sky`]).
    pub total: Estimate,
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
const TAG_SOBOL: u64 = 0x736f_6200_0000_0000;

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

/// The uniforms of one path, by dimension (a pure function of the path).
trait PathSampler {
    /// The uniform in (0, 1) of dimension `dim`.
    fn uniform(&mut self, dim: u64) -> f64;
}

impl PathSampler for StreamKey {
    #[inline(always)]
    fn uniform(&mut self, dim: u64) -> f64 {
        StreamKey::uniform(*self, dim)
    }
}

/// Points per Owen-scrambled Sobol sequence ([`sobol_burley`] supports 2^16).
const SOBOL_POINTS: u64 = 1 << 16;

/// Dimensions taken from the Sobol sequence (the crate's 256); later ones
/// are independent uniforms.
const SOBOL_DIMS: u64 = sobol_burley::NUM_DIMENSIONS as u64;

/// The fewest independently scrambled replicates of an RQMC estimate (its
/// standard error is the spread of their means).
const MIN_REPLICATES: u64 = 16;

/// Replicates of a BRF estimate over `spp` paths: 16, or as many as keep
/// each at most 2^16 points; never more than `spp`.
pub fn replicates(spp: u64) -> u64 {
    spp.div_ceil(SOBOL_POINTS).max(MIN_REPLICATES).min(spp)
}

/// Point `index` of an Owen-scrambled Sobol sequence (Burley 2020, the
/// [`sobol_burley`] crate) with scramble seed `seed`: dimension `d < 256`
/// is the sequence's 23-bit value plus an independent uniform below its
/// last bit (so each coordinate is uniform on (0, 1) and the net structure
/// is kept); later dimensions are independent uniforms from `jitter`.
struct SobolPath {
    index: u32,
    seed: u32,
    jitter: StreamKey,
    set: u32,
    cache: [f32; 4],
}

impl SobolPath {
    #[inline]
    fn new(index: u32, seed: u32, jitter: StreamKey) -> Self {
        SobolPath {
            index,
            seed,
            jitter,
            set: u32::MAX,
            cache: [0.0; 4],
        }
    }
}

/// The last bit of [`sobol_burley`]'s values, 2^-23.
const SOBOL_ULP: f64 = 1.0 / (1u64 << 23) as f64;

/// The largest f64 below 1.
const BELOW_ONE: f64 = 1.0 - f64::EPSILON / 2.0;

impl PathSampler for SobolPath {
    #[inline]
    fn uniform(&mut self, dim: u64) -> f64 {
        let j = self.jitter.uniform(dim);
        if dim >= SOBOL_DIMS {
            return j;
        }
        let set = (dim / 4) as u32;
        if set != self.set {
            self.cache = sobol_burley::sample_4d(self.index, set, self.seed);
            self.set = set;
        }
        (f64::from(self.cache[(dim % 4) as usize]) + j * SOBOL_ULP).min(BELOW_ONE)
    }
}

/// Mean and standard error of a randomised quasi-Monte Carlo estimate from
/// per-replicate `(sum, sum of squares, n)`: replicates are independent, so
/// the standard error comes from the spread of their means (the per-path
/// formula would overstate it); with fewer than 8 replicates (fewer than 8
/// paths), the per-path formula is used. The standard error is at least
/// 1e-12 of the value (the rounding of the sums).
fn finish_replicates(blocks: &[(f64, f64, u64)]) -> Estimate {
    let e = finish(blocks);
    let k = blocks.len();
    if k < 8 {
        return e;
    }
    let nf = e.n as f64;
    let mut v = 0.0;
    for &(s1, _, n) in blocks {
        let m = s1 / n as f64;
        v += (n as f64 * (m - e.value)).powi(2);
    }
    let var = v / (nf * nf) * k as f64 / (k as f64 - 1.0);
    // when every block mean is the same (a closed-form case) what is left
    // is the rounding of the sums: never report less than that
    Estimate {
        se: var.sqrt().max(1e-12 * e.value.abs()),
        ..e
    }
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
    fn scatter<S: PathSampler>(
        m: &dyn Bsdf,
        (t, b, n): (DVec3, DVec3, DVec3),
        wo: DVec3,
        key: &mut S,
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
    /// irradiance normal to `s` plus an isotropic sky of radiance `sky_l`
    /// over the upper hemisphere, up to `max_depth` scattering events;
    /// `key` supplies uniforms from index `dim` on.
    ///
    /// At each facet hit the sun is added when the shadow ray escapes (also
    /// behind a transmitting facet); a path that leaves upwards after `k >= 1`
    /// scattering events (`k <= max_depth`) adds `throughput * sky_l`. With
    /// `sky_l = 0` the walk stops after the `max_depth`-th sun estimate (no
    /// further draw), so sky-free results do not depend on the sky code.
    ///
    /// Returns `(l, l1)`: the radiance and its single-scattering part (the
    /// sun's next-event estimate at the first hit and the sky light of paths
    /// that leave after one event). Bounce `k` draws the uniforms `dim + 2 (k
    /// - 1)`, `dim + 2 k - 1` whatever `max_depth` is, so `l1` is bit for bit
    /// the `l` of the same path with `max_depth = 1`.
    #[allow(clippy::too_many_arguments)]
    fn radiance_orders<S: PathSampler>(
        &self,
        o: DVec3,
        v: DVec3,
        s: DVec3,
        sky_l: f64,
        max_depth: u32,
        key: &mut S,
        dim: u64,
    ) -> (f64, f64) {
        let (mut l, mut l1) = ([0.0], [0.0]);
        self.radiance_suns(o, v, &[s], sky_l, max_depth, key, dim, &mut l, &mut l1);
        (l[0], l1[0])
    }

    /// [`Scene::radiance_orders`] of one path for every sun of `suns` at
    /// once: the path does not depend on the sun (only the next-event
    /// estimates do), so it is traced once and `l[k]`, `l1[k]` are set bit
    /// for bit to `radiance_orders(.., suns[k], ..)`.
    #[allow(clippy::too_many_arguments)]
    fn radiance_suns<S: PathSampler>(
        &self,
        mut o: DVec3,
        v: DVec3,
        suns: &[DVec3],
        sky_l: f64,
        max_depth: u32,
        key: &mut S,
        mut dim: u64,
        l: &mut [f64],
        l1: &mut [f64],
    ) {
        let hf = &self.hf;
        l.fill(0.0);
        l1.fill(0.0);
        let mut d = -v;
        let mut skip: Option<G::Facet> = None;
        let mut throughput = 1.0;
        let mut depth = 0u32;
        loop {
            let Some(hit) = hf.trace(o, d, skip) else {
                if depth > 0 && d.z > 0.0 {
                    let c = throughput * sky_l; // escaped into the sky
                    for k in 0..suns.len() {
                        l[k] += c;
                        if depth == 1 {
                            l1[k] += c;
                        }
                    }
                }
                break;
            };
            if depth == max_depth {
                break;
            }
            depth += 1;
            let n = hit.normal;
            if n.dot(d) >= 0.0 {
                break; // reached a facet from below: numerically lost
            }
            let (p, facet) = hf.wrap(o + hit.t * d, hit.facet);
            let (t, b) = basis(n);
            let wo = Self::local(n, t, b, -d);
            let m = self.bsdf(facet);
            for (k, &s) in suns.iter().enumerate() {
                let cos_s = n.dot(s);
                if (cos_s > 0.0 || (cos_s < 0.0 && m.transmits()))
                    && !hf.occluded(p, s, Some(facet))
                {
                    let wi = Self::local(n, t, b, s);
                    let c = throughput * m.eval(wi, wo) * cos_s.abs();
                    l[k] += c;
                    if depth == 1 {
                        l1[k] += c;
                    }
                }
            }
            if depth == max_depth && sky_l == 0.0 {
                break;
            }
            let Some((wi, weight)) = Self::scatter(m, (t, b, n), wo, &mut *key, &mut dim) else {
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
    }

    /// The radiance of [`Scene::radiance_orders`] (all orders).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn radiance<S: PathSampler>(
        &self,
        o: DVec3,
        v: DVec3,
        s: DVec3,
        sky_l: f64,
        max_depth: u32,
        key: &mut S,
        dim: u64,
    ) -> f64 {
        self.radiance_orders(o, v, s, sky_l, max_depth, key, dim).0
    }

    /// Bidirectional reflectance factor for the sun towards `sun` and the
    /// sensor towards `view` (unit vectors (east, north, up) from
    /// [`super::direction`]), over `spp` paths of at most `max_depth`
    /// scattering events: [`Scene::brf_sky`] with no sky.
    pub fn brf(
        &self,
        sun: DVec3,
        view: DVec3,
        spp: u64,
        max_depth: u32,
        seed: u64,
    ) -> CoreResult<Estimate> {
        self.brf_sky(sun, view, 0.0, spp, max_depth, seed)
    }

    /// The reflectance factor under the sun towards `sun` (irradiance 1
    /// normal to the beam) plus an isotropic sky whose irradiance on a
    /// horizontal plane is `sky` (same unit): `pi L / (cos(sun zenith) +
    /// sky)`, the hemispherical-directional reflectance factor (HDRF); the
    /// BRF for `sky = 0`: the `total` of [`Scene::brf_orders`].
    ///
    /// Randomised quasi-Monte Carlo: the `spp` paths are split into
    /// [`replicates`]`(spp)` independently Owen-scrambled Sobol sequences
    /// (at most 2^16 points each); point `i` of a sequence gives the sensor
    /// point (dimensions 0, 1) and the scattering draws (2, 3 for the first
    /// bounce, and so on) of one path. The value is the mean of all paths
    /// and its standard error the spread of the replicate means.
    pub fn brf_sky(
        &self,
        sun: DVec3,
        view: DVec3,
        sky: f64,
        spp: u64,
        max_depth: u32,
        seed: u64,
    ) -> CoreResult<Estimate> {
        Ok(self.brf_orders(sun, view, sky, spp, max_depth, seed)?.total)
    }

    /// [`Scene::brf_sky`] split by scattering order over the same paths:
    /// per path, the single-scattering value `r1` (the sun's next-event
    /// estimate at the first hit, plus the sky light of paths leaving after
    /// one event), the total `r` and the multiple-scattering value `r - r1`;
    /// each estimate is formed from its own per-path values (sums and sums
    /// of squares), so the standard error of `multiple` is that of the
    /// per-path differences. `single` equals [`Scene::brf_sky`] with
    /// `max_depth = 1` and the same seed bit for bit, `total` equals
    /// [`Scene::brf_sky`] bit for bit, and `single + multiple = total` to
    /// rounding.
    pub fn brf_orders(
        &self,
        sun: DVec3,
        view: DVec3,
        sky: f64,
        spp: u64,
        max_depth: u32,
        seed: u64,
    ) -> CoreResult<OrderSplit> {
        check_spp(spp)?;
        check_depth(max_depth)?;
        check_sky(sky)?;
        let (x0, y0, w, h) = self.hf.footprint();
        let ytop = y0 + h;
        let norm = PI / (sun.z + sky);
        let sky_l = sky / PI;
        let reps = replicates(spp);
        let (base, extra) = (spp / reps, spp % reps);
        let size = |r: u64| base + u64::from(r < extra);
        // work items (replicate, block of up to BLOCK points), replicate-major
        let items: Vec<(u64, u64)> = (0..reps)
            .flat_map(|r| (0..size(r).div_ceil(BLOCK)).map(move |b| (r, b)))
            .collect();
        type Sums = [(f64, f64, u64); 3];
        let sums: Vec<Sums> = items
            .into_par_iter()
            .map(|(r, blk)| {
                let scramble = (StreamKey::new(seed, TAG_SOBOL ^ r).bits(0) >> 32) as u32;
                // (total, single, multiple): sum and sum of squares
                let mut acc = [(0.0, 0.0); 3];
                let end = ((blk + 1) * BLOCK).min(size(r));
                for i in blk * BLOCK..end {
                    let mut u = SobolPath::new(
                        i as u32,
                        scramble,
                        StreamKey::new(seed, TAG_BRF ^ (r << 16 | i)),
                    );
                    let x = x0 + u.uniform(0) * w;
                    let y = ytop - u.uniform(1) * h;
                    let o = self.sensor_ray(x, y, view);
                    let (l, l1) = self.radiance_orders(o, view, sun, sky_l, max_depth, &mut u, 2);
                    let (t, t1) = (norm * l, norm * l1);
                    for (a, x) in acc.iter_mut().zip([t, t1, t - t1]) {
                        a.0 += x;
                        a.1 += x * x;
                    }
                }
                let k = end - blk * BLOCK;
                acc.map(|(s1, s2)| (s1, s2, k))
            })
            .collect();
        // per-replicate sums of each part, blocks added in order
        let part = |j: usize| {
            let mut per_rep: Vec<(f64, f64, u64)> = Vec::with_capacity(reps as usize);
            let mut k = 0;
            for r in 0..reps {
                let (mut a, mut b, mut n) = (0.0, 0.0, 0);
                for _ in 0..size(r).div_ceil(BLOCK) {
                    a += sums[k][j].0;
                    b += sums[k][j].1;
                    n += sums[k][j].2;
                    k += 1;
                }
                per_rep.push((a, b, n));
            }
            finish_replicates(&per_rep)
        };
        Ok(OrderSplit {
            total: part(0),
            single: part(1),
            multiple: part(2),
        })
    }

    /// The fraction of light arriving along `-sun` at the reference-plane
    /// point `(x, y)` that leaves (upwards, or through a side of a finite
    /// patch; [`Tracer::escapes`]) after at most `max_depth` scattering
    /// events: one path of [`Scene::albedo`], uniforms from `dim`.
    fn albedo_path(
        &self,
        sun: DVec3,
        (x, y): (f64, f64),
        max_depth: u32,
        mut key: StreamKey,
        mut dim: u64,
    ) -> f64 {
        let hf = &self.hf;
        let mut o = self.sensor_ray(x, y, sun);
        let mut d = -sun;
        let mut skip = None;
        let mut throughput = 1.0;
        for depth in 0..=max_depth {
            let Some(hit) = hf.trace(o, d, skip) else {
                // escaped after scattering (not counted before the first hit)
                return if depth > 0 && hf.escapes(d) {
                    throughput
                } else {
                    0.0
                };
            };
            if depth == max_depth || hit.normal.dot(d) >= 0.0 {
                return 0.0; // still trapped (or lost): not counted
            }
            let n = hit.normal;
            let (p, facet) = hf.wrap(o + hit.t * d, hit.facet);
            let (t, b) = basis(n);
            let wo = Self::local(n, t, b, -d);
            // reciprocity: sample the reflected direction as an incident
            // one for the light's arrival direction
            let m = self.bsdf(facet);
            let Some((wi, weight)) = Self::scatter(m, (t, b, n), wo, &mut key, &mut dim) else {
                return 0.0;
            };
            throughput *= weight;
            if throughput == 0.0 {
                return 0.0;
            }
            d = wi;
            o = p;
            skip = Some(facet);
        }
        0.0
    }

    /// Directional-hemispherical reflectance (black-sky albedo) for the sun
    /// towards `sun`, over `spp` rays of at most `max_depth` scattering events.
    pub fn albedo(&self, sun: DVec3, spp: u64, max_depth: u32, seed: u64) -> CoreResult<Estimate> {
        check_spp(spp)?;
        check_depth(max_depth)?;
        let (x0, y0, w, h) = self.hf.footprint();
        let ytop = y0 + h;
        let blocks: Vec<(f64, f64, u64)> = (0..spp.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let (mut s1, mut s2) = (0.0, 0.0);
                let end = ((blk + 1) * BLOCK).min(spp);
                for i in blk * BLOCK..end {
                    let key = StreamKey::new(seed, TAG_ALBEDO ^ i);
                    let (x, y) = (x0 + key.uniform(0) * w, ytop - key.uniform(1) * h);
                    let r = self.albedo_path(sun, (x, y), max_depth, key, 2);
                    s1 += r;
                    s2 += r * r;
                }
                (s1, s2, end - blk * BLOCK)
            })
            .collect();
        Ok(finish(&blocks))
    }

    /// Bi-hemispherical reflectance (white-sky albedo): the albedo under a
    /// uniform sky, `(1/pi) * integral of albedo(s) cos(s) ds` over the
    /// upper hemisphere. Each of the `spp` paths draws its sun direction
    /// cosine-weighted, then follows it as [`Scene::albedo`] does.
    pub fn bhr(&self, spp: u64, max_depth: u32, seed: u64) -> CoreResult<Estimate> {
        check_spp(spp)?;
        check_depth(max_depth)?;
        let (x0, y0, w, h) = self.hf.footprint();
        let ytop = y0 + h;
        let blocks: Vec<(f64, f64, u64)> = (0..spp.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let (mut s1, mut s2) = (0.0, 0.0);
                let end = ((blk + 1) * BLOCK).min(spp);
                for i in blk * BLOCK..end {
                    let key = StreamKey::new(seed, TAG_BHR ^ i);
                    let (x, y) = (x0 + key.uniform(0) * w, ytop - key.uniform(1) * h);
                    let sun = super::material::cosine_hemisphere([key.uniform(2), key.uniform(3)]);
                    let r = if sun.z > 0.0 {
                        self.albedo_path(sun, (x, y), max_depth, key, 4)
                    } else {
                        0.0
                    };
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
        self.render_psf(sun, view, 0.0, shape, spp, max_depth, seed, &Psf::Box, None)
    }

    /// [`Scene::render`] with an isotropic sky of horizontal
    /// irradiance `sky` and the point-spread function `psf`: each path's
    /// footprint point is drawn from the PSF around the pixel's centre
    /// (it may fall outside the pixel, and outside a finite patch, where
    /// nothing is seen), ticking `progress` once per image row (the image does
    /// not depend on it). `Psf::Box` and `sky = 0` is [`Scene::render`].
    #[allow(clippy::too_many_arguments)]
    pub fn render_psf(
        &self,
        sun: DVec3,
        view: DVec3,
        sky: f64,
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
        psf: &Psf,
        progress: Option<&crate::progress::Progress>,
    ) -> CoreResult<Vec<f32>> {
        self.render_series(
            &[sun],
            view,
            sky,
            shape,
            spp,
            max_depth,
            seed,
            psf,
            progress,
        )
    }

    /// One [`Scene::render_psf`] image per sun of `suns` (an `n x rows x
    /// cols` stack, row-major), each bit for bit the image of its sun with
    /// the same `seed`, in one pass: a path's geometry does not depend on
    /// the sun, so it is traced once and the sun's next-event estimate made
    /// for every sun (the paper's incidence series at little more than the
    /// cost of one image plus the shadow rays).
    #[allow(clippy::too_many_arguments)]
    pub fn render_series(
        &self,
        suns: &[DVec3],
        view: DVec3,
        sky: f64,
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
        psf: &Psf,
        progress: Option<&crate::progress::Progress>,
    ) -> CoreResult<Vec<f32>> {
        check_sky(sky)?;
        let ns = suns.len();
        if ns == 0 {
            return Err(CoreError::invalid(
                "suns",
                "expected at least one sun direction, got none",
            ));
        }
        let (rows, cols) = shape;
        let mut img = image_buffer((rows.saturating_mul(ns), cols), spp, max_depth, None)?;
        if let Some(p) = progress {
            p.add_total(rows as u64);
        }
        let (x0, y0, w, h) = self.hf.footprint();
        let ytop = y0 + h;
        let (pw, ph) = (w / cols as f64, h / rows as f64);
        let sky_l = sky / PI;
        let out = crate::parallel::SharedMut::new(&mut img);
        (0..rows).into_par_iter().for_each(|i| {
            let (mut l, mut l1, mut acc) = (vec![0.0; ns], vec![0.0; ns], vec![0.0; ns]);
            for j in 0..cols {
                let pixel = (i * cols + j) as u64;
                acc.fill(0.0);
                for k in 0..spp {
                    let key =
                        StreamKey::new(seed, TAG_IMAGE ^ pixel.wrapping_mul(spp).wrapping_add(k));
                    let (fx, fy) = psf.position([key.uniform(0), key.uniform(1)]);
                    let x = x0 + (j as f64 + fx) * pw;
                    let y = ytop - (i as f64 + fy) * ph;
                    let o = self.sensor_ray(x, y, view);
                    self.radiance_suns(
                        o,
                        view,
                        suns,
                        sky_l,
                        max_depth,
                        &mut { key },
                        2,
                        &mut l,
                        &mut l1,
                    );
                    for (a, v) in acc.iter_mut().zip(&l) {
                        *a += v;
                    }
                }
                for (s, a) in acc.iter().enumerate() {
                    // SAFETY: pixel (s, i, j) is inside the ns x rows x cols
                    // buffer, which outlives the loop, and only the task of
                    // row i writes it.
                    unsafe { *out.get().add((s * rows + i) * cols + j) = (a / spp as f64) as f32 };
                }
            }
            if let Some(p) = progress {
                p.tick(1);
            }
        });
        Ok(img)
    }

    /// A `rows x cols` radiance image seen by the pinhole camera `cam`
    /// (box pixels, `spp` paths each), the sun towards `sun` and an
    /// isotropic sky of horizontal irradiance `sky`. Rays that miss the
    /// surface see the sky radiance `sky / pi` above the horizon and 0
    /// below it.
    #[allow(clippy::too_many_arguments)]
    pub fn render_perspective(
        &self,
        sun: DVec3,
        sky: f64,
        cam: &Pinhole,
        shape: (usize, usize),
        spp: u64,
        max_depth: u32,
        seed: u64,
        progress: Option<&crate::progress::Progress>,
    ) -> CoreResult<Vec<f32>> {
        check_sky(sky)?;
        let mut img = image_buffer(shape, spp, max_depth, progress)?;
        let cols = shape.1;
        let hf = &self.hf;
        let (_, zmax, _) = hf.z_range();
        let top = zmax + 1e-6 * (1.0 + zmax.abs());
        let sky_l = sky / PI;
        img.par_chunks_mut(cols).enumerate().for_each(|(i, line)| {
            for (j, px) in line.iter_mut().enumerate() {
                let pixel = (i * cols + j) as u64;
                let mut s = 0.0;
                for k in 0..spp {
                    let key = StreamKey::new(
                        seed,
                        TAG_PERSPECTIVE ^ pixel.wrapping_mul(spp).wrapping_add(k),
                    );
                    let d = cam.ray(i as f64 + key.uniform(1), j as f64 + key.uniform(0), shape);
                    // start on the plane just above the highest facet
                    let o = if cam.eye.z > top {
                        if d.z < 0.0 {
                            Some(cam.eye + ((cam.eye.z - top) / -d.z) * d)
                        } else {
                            None
                        }
                    } else {
                        Some(cam.eye)
                    };
                    s += match o {
                        Some(o) if hf.trace(o, d, None).is_some() => {
                            self.radiance(o, -d, sun, sky_l, max_depth, &mut { key }, 2)
                        }
                        _ if d.z > 0.0 => sky_l,
                        _ => 0.0,
                    };
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

/// The checked, zeroed `rows x cols` image of a renderer (errors name
/// `spp`, `max_depth` or `shape`); `progress` gets one unit per row.
fn image_buffer(
    (rows, cols): (usize, usize),
    spp: u64,
    max_depth: u32,
    progress: Option<&crate::progress::Progress>,
) -> CoreResult<Vec<f32>> {
    check_spp(spp)?;
    check_depth(max_depth)?;
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
    let img: Vec<f32> = crate::buffers::try_filled(rows * cols, 0.0f32, "shape")?;
    if let Some(p) = progress {
        p.add_total(rows as u64);
    }
    Ok(img)
}

// ---- Sky light and sensor point-spread functions.

const TAG_BHR: u64 = 0x6268_7200_0000_0000;

/// The point-spread function of an image pixel: the weight with which the
/// reference plane around the pixel's centre contributes to it. The renderer
/// draws each path's footprint point from it, so a pixel estimates exactly
/// the PSF-weighted integral of the radiance.
#[derive(Debug, Clone, PartialEq)]
pub enum Psf {
    /// Uniform over the pixel's footprint (a box one pixel wide).
    Box,
    /// Isotropic Gaussian of standard deviation `sigma` pixels, truncated to
    /// the disc of radius `radius` pixels (and renormalised).
    Gaussian {
        /// Standard deviation, pixels.
        sigma: f64,
        /// Truncation radius, pixels.
        radius: f64,
    },
    /// Piecewise constant on a `rows x cols` grid of cells `step` pixels
    /// wide, centred on the pixel centre (row 0 north); `cdf` holds the
    /// running sums of the weights (row-major), the last one the total.
    Table {
        /// Rows of the grid.
        rows: usize,
        /// Columns of the grid.
        cols: usize,
        /// Cell side, pixels.
        step: f64,
        /// Running sums of the non-negative weights.
        cdf: Vec<f64>,
    },
}

impl Psf {
    /// A Gaussian PSF of `sigma` pixels truncated at `truncate * sigma`.
    pub fn gaussian(sigma: f64, truncate: f64) -> CoreResult<Psf> {
        if !(sigma.is_finite() && sigma > 0.0) {
            return Err(CoreError::invalid(
                "psf",
                format!("expected a Gaussian sigma > 0 pixels, got {sigma}"),
            ));
        }
        if !(truncate.is_finite() && truncate > 0.0) {
            return Err(CoreError::invalid(
                "psf",
                format!("expected a Gaussian truncation > 0 sigmas, got {truncate}"),
            ));
        }
        Ok(Psf::Gaussian {
            sigma,
            radius: truncate * sigma,
        })
    }

    /// A tabulated PSF: `weights` row-major `rows x cols`, non-negative
    /// with a positive sum, cells `step` pixels wide.
    pub fn table(weights: &[f64], rows: usize, cols: usize, step: f64) -> CoreResult<Psf> {
        if rows == 0 || cols == 0 || weights.len() != rows * cols {
            return Err(CoreError::invalid(
                "psf",
                format!(
                    "expected a non-empty 2D array of weights, got {} values for {rows} x {cols}",
                    weights.len()
                ),
            ));
        }
        if !(step.is_finite() && step > 0.0) {
            return Err(CoreError::invalid(
                "psf_step",
                format!("expected a cell size > 0 pixels, got {step}"),
            ));
        }
        let mut cdf = Vec::with_capacity(weights.len());
        let mut s = 0.0;
        for &w in weights {
            if !(w.is_finite() && w >= 0.0) {
                return Err(CoreError::invalid(
                    "psf",
                    format!("expected finite weights >= 0, got {w}"),
                ));
            }
            s += w;
            cdf.push(s);
        }
        if s <= 0.0 {
            return Err(CoreError::invalid(
                "psf",
                "expected weights with a positive sum, got all zeros",
            ));
        }
        Ok(Psf::Table {
            rows,
            cols,
            step,
            cdf,
        })
    }

    /// The footprint point, in pixels east and south of the pixel's
    /// north-west corner, for the uniforms `u` in (0, 1): distributed as
    /// the PSF centred on the pixel centre `(0.5, 0.5)`.
    #[inline]
    pub fn position(&self, u: [f64; 2]) -> (f64, f64) {
        match self {
            Psf::Box => (u[0], u[1]),
            Psf::Gaussian { sigma, radius } => {
                // radial inverse CDF of the disc-truncated Gaussian
                let tail = (-0.5 * (radius / sigma).powi(2)).exp_m1(); // e^{-R^2/2s^2} - 1
                let r = sigma * (-2.0 * (u[0] * tail).ln_1p()).max(0.0).sqrt();
                let phi = 2.0 * PI * u[1];
                (0.5 + r * phi.cos(), 0.5 + r * phi.sin())
            }
            Psf::Table {
                rows,
                cols,
                step,
                cdf,
            } => {
                let total = cdf[cdf.len() - 1];
                let t = u[0] * total;
                // first cell whose running sum exceeds t (never a zero-weight cell)
                let k = cdf.partition_point(|&c| c <= t).min(cdf.len() - 1);
                let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
                let w = cdf[k] - lo;
                let fx = if w > 0.0 {
                    ((t - lo) / w).clamp(0.0, 1.0)
                } else {
                    0.5
                };
                let (r, c) = ((k / cols) as f64, (k % cols) as f64);
                (
                    0.5 + (c + fx - 0.5 * *cols as f64) * step,
                    0.5 + (r + u[1] - 0.5 * *rows as f64) * step,
                )
            }
        }
    }
}

fn check_sky(sky: f64) -> CoreResult<()> {
    if !(sky.is_finite() && sky >= 0.0) {
        return Err(CoreError::invalid(
            "sky",
            format!("expected a finite sky irradiance >= 0, got {sky}"),
        ));
    }
    Ok(())
}

// ---- A perspective (pinhole) camera for 3D views.

const TAG_PERSPECTIVE: u64 = 0x7073_7000_0000_0000;

/// A pinhole camera at `eye` looking at `target`, world up `+z`.
#[derive(Debug, Clone, Copy)]
pub struct Pinhole {
    eye: DVec3,
    fwd: DVec3,
    right: DVec3,
    up: DVec3,
    /// tan(vertical field of view / 2).
    tan_half: f64,
}

impl Pinhole {
    /// A camera at `eye` looking at `target` with the vertical field of
    /// view `fov_deg` degrees in (0, 180); image rows go down, columns right.
    pub fn new(eye: DVec3, target: DVec3, fov_deg: f64) -> CoreResult<Pinhole> {
        if !(eye.is_finite() && target.is_finite()) {
            return Err(CoreError::invalid(
                "eye",
                "expected finite camera and target positions",
            ));
        }
        let f = target - eye;
        if f.length() <= 0.0 {
            return Err(CoreError::invalid(
                "target",
                "expected a target distinct from the camera position",
            ));
        }
        if !(fov_deg.is_finite() && fov_deg > 0.0 && fov_deg < 180.0) {
            return Err(CoreError::invalid(
                "fov",
                format!("expected a field of view in (0, 180) degrees, got {fov_deg}"),
            ));
        }
        let fwd = f.normalize();
        let r = fwd.cross(DVec3::Z);
        let right = if r.length() > 1e-12 {
            r.normalize()
        } else {
            DVec3::X // looking straight down or up: east to the right
        };
        let up = right.cross(fwd);
        Ok(Pinhole {
            eye,
            fwd,
            right,
            up,
            tan_half: (0.5 * fov_deg.to_radians()).tan(),
        })
    }

    /// The unit direction through the image point `(row, col)` (fractional
    /// pixels from the top-left corner) of a `rows x cols` image.
    #[inline]
    pub fn ray(&self, row: f64, col: f64, (rows, cols): (usize, usize)) -> DVec3 {
        let aspect = cols as f64 / rows as f64;
        let sx = (2.0 * col / cols as f64 - 1.0) * self.tan_half * aspect;
        let sy = (1.0 - 2.0 * row / rows as f64) * self.tan_half;
        (self.fwd + sx * self.right + sy * self.up).normalize()
    }
}

#[cfg(test)]
mod sobol_tests {
    use super::*;

    /// The first 2^10 points of a replicate put one point in each of the
    /// 32 x 32 cells of dimensions (0, 1) (a (0, 10, 2)-net: the sensor
    /// points) and in each of the 1024 intervals of every other dimension
    /// used (each one a (0, 1)-sequence); every coordinate lies in (0, 1).
    #[test]
    fn replicate_prefixes_are_nets() {
        for (seed, scramble) in [(0u64, 0u32), (7, 0x9e37_79b9), (123, 42)] {
            let mut cells = vec![0u32; 1024];
            let mut slots = vec![vec![0u32; 1024]; 22];
            for i in 0..1024u32 {
                let mut p = SobolPath::new(i, scramble, StreamKey::new(seed, i as u64));
                let u: Vec<f64> = (0..22).map(|d| p.uniform(d)).collect();
                assert!(u.iter().all(|&x| x > 0.0 && x < 1.0));
                cells[(u[0] * 32.0) as usize * 32 + (u[1] * 32.0) as usize] += 1;
                for (d, x) in u.iter().enumerate() {
                    slots[d][(x * 1024.0) as usize] += 1;
                }
            }
            assert!(cells.iter().all(|&c| c == 1), "{seed}");
            for (d, sl) in slots.iter().enumerate() {
                assert!(sl.iter().all(|&c| c == 1), "{seed} {d}");
            }
        }
    }

    #[test]
    fn replicates_hold_at_most_2_pow_16_points() {
        for spp in [1, 7, 16, 17, 1000, 1 << 20, (1 << 20) + 1, 5 << 20] {
            let r = replicates(spp);
            assert!(r <= spp && spp.div_ceil(r) <= SOBOL_POINTS, "{spp} {r}");
            assert!(r == spp || r >= MIN_REPLICATES);
        }
    }
}
