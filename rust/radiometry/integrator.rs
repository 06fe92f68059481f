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

use super::heightfield::{FacetId, Heightfield};
use super::material::{basis, Bsdf};
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

/// A heightfield with one reflectance model.
#[derive(Debug)]
pub struct Scene {
    /// The geometry.
    pub hf: Heightfield,
    /// The reflectance model of every facet.
    pub material: Box<dyn Bsdf>,
}

/// Streams: the stream of path `i` of an experiment is `(seed, i)` mixed with
/// a tag so that BRF, albedo and image paths differ for the same seed.
const TAG_BRF: u64 = 0x6272_6600_0000_0000;
const TAG_ALBEDO: u64 = 0x616c_6200_0000_0000;
const TAG_IMAGE: u64 = 0x696d_6700_0000_0000;
const TAG_STRATA: u64 = 0x7374_7200_0000_0000;

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

/// Strata of the BRF estimator: each full block of [`BLOCK`] paths puts one
/// point in each of `STRATA x STRATA` equal cells of the tile.
const STRATA: u64 = 32;
const _: () = assert!(STRATA * STRATA == BLOCK);

/// Mean and standard error of a stratified estimate from per-block
/// `(sum, sum of squares, n)`: full blocks are independent stratified
/// samples, so the standard error comes from the spread of the block means
/// (the per-path formula would overstate it); with fewer than 8 blocks, the
/// per-path formula (conservative) is used. The standard error is at least
/// 1e-12 of the value (the rounding of the sums).
fn finish_stratified(blocks: &[(f64, f64, u64)]) -> Estimate {
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

impl Scene {
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
        &self,
        (t, b, n): (DVec3, DVec3, DVec3),
        wo: DVec3,
        key: StreamKey,
        dim: &mut u64,
    ) -> Option<(DVec3, f64)> {
        let u = [key.uniform(*dim), key.uniform(*dim + 1)];
        *dim += 2;
        let smp = self.material.sample(wo, u)?;
        Some((smp.wi.x * t + smp.wi.y * b + smp.wi.z * n, smp.weight))
    }

    /// Start of a ray through the reference-plane point `(x, y)` going
    /// against `v` (from above the highest facet).
    #[inline]
    fn sensor_ray(&self, x: f64, y: f64, v: DVec3) -> DVec3 {
        let hf = &self.hf;
        let top = hf.zmax + 1e-6 * (1.0 + hf.zmax.abs());
        let lift = (top - hf.zmean).max(0.0) / v.z;
        DVec3::new(x, y, hf.zmean) + lift * v
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
        let mut skip: Option<FacetId> = None;
        let mut throughput = 1.0;
        let mut l = 0.0;
        for depth in 1..=max_depth {
            let Some(hit) = hf.intersect(o, d, skip) else {
                break;
            };
            let n = hit.normal;
            if n.dot(d) >= 0.0 {
                break; // reached a facet from below: numerically lost
            }
            let (p, facet) = hf.wrap(o + hit.t * d, hit.facet);
            let (t, b) = basis(n);
            let wo = Self::local(n, t, b, -d);
            let cos_s = n.dot(s);
            if cos_s > 0.0 && !hf.occluded(p, s, Some(facet), f64::INFINITY) {
                let wi = Self::local(n, t, b, s);
                l += throughput * self.material.eval(wi, wo) * cos_s;
            }
            if depth == max_depth {
                break;
            }
            let Some((wi, weight)) = self.scatter((t, b, n), wo, key, &mut dim) else {
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
        let (w, h) = self.hf.extent();
        let norm = PI / sun.z;
        let blocks: Vec<(f64, f64, u64)> = (0..spp.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let (mut s1, mut s2) = (0.0, 0.0);
                let end = ((blk + 1) * BLOCK).min(spp);
                // path j of the block takes stratum (797 j + b) mod 1024, an odd
                // multiplier and a random offset per block: every stratum once
                // in a full block, and each point uniform over the tile
                let off = (StreamKey::new(seed, TAG_STRATA ^ blk).uniform(0) * BLOCK as f64) as u64;
                for i in blk * BLOCK..end {
                    let key = StreamKey::new(seed, TAG_BRF ^ i);
                    let st = (797 * (i - blk * BLOCK) + off) % BLOCK;
                    let (sx, sy) = ((st % STRATA) as f64, (st / STRATA) as f64);
                    let x = (sx + key.uniform(0)) / STRATA as f64 * w;
                    let y = -(sy + key.uniform(1)) / STRATA as f64 * h;
                    let o = self.sensor_ray(x, y, view);
                    let r = norm * self.radiance(o, view, sun, max_depth, key, 2);
                    s1 += r;
                    s2 += r * r;
                }
                (s1, s2, end - blk * BLOCK)
            })
            .collect();
        Ok(finish_stratified(&blocks))
    }

    /// Directional-hemispherical reflectance (black-sky albedo) for the sun
    /// towards `sun`, over `spp` rays of at most `max_depth` scattering events.
    pub fn albedo(&self, sun: DVec3, spp: u64, max_depth: u32, seed: u64) -> CoreResult<Estimate> {
        check_spp(spp)?;
        check_depth(max_depth)?;
        let (w, h) = self.hf.extent();
        let hf = &self.hf;
        let blocks: Vec<(f64, f64, u64)> = (0..spp.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let (mut s1, mut s2) = (0.0, 0.0);
                let end = ((blk + 1) * BLOCK).min(spp);
                for i in blk * BLOCK..end {
                    let key = StreamKey::new(seed, TAG_ALBEDO ^ i);
                    let (x, y) = (key.uniform(0) * w, -key.uniform(1) * h);
                    let mut o = self.sensor_ray(x, y, sun);
                    let mut d = -sun;
                    let mut skip = None;
                    let mut throughput = 1.0;
                    let mut r = 0.0;
                    let mut dim = 2u64;
                    for depth in 0..=max_depth {
                        let Some(hit) = hf.intersect(o, d, skip) else {
                            if depth > 0 {
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
                        let Some((wi, weight)) = self.scatter((t, b, n), wo, key, &mut dim) else {
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
        let (w, h) = self.hf.extent();
        let (pw, ph) = (w / cols as f64, h / rows as f64);
        img.par_chunks_mut(cols).enumerate().for_each(|(i, line)| {
            for (j, px) in line.iter_mut().enumerate() {
                let pixel = (i * cols + j) as u64;
                let mut s = 0.0;
                for k in 0..spp {
                    let key =
                        StreamKey::new(seed, TAG_IMAGE ^ pixel.wrapping_mul(spp).wrapping_add(k));
                    let x = (j as f64 + key.uniform(0)) * pw;
                    let y = -(i as f64 + key.uniform(1)) * ph;
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
