//! Canopy estimators on any scene ([`Scene`] over a [`Tracer`]): the gap
//! fraction along a direction and the fractions of the incident light
//! absorbed by each material (fAPAR of leaves, soil, ...).
//!
//! Both follow rays from the sun, started above the highest facet on the
//! line through a uniform point of the tile's reference plane, keyed by
//! `(seed, ray index)` and summed per fixed block of rays, so results are
//! bit-identical for any number of threads.
use glam::DVec3;
use rayon::prelude::*;

use super::integrator::{Estimate, Scene};
use super::material::basis;
use super::tracer::Tracer;
use crate::error::{CoreError, CoreResult};
use crate::rng::StreamKey;

/// Rays per block: sums are formed per block and blocks added in order.
const BLOCK: u64 = 1024;

const TAG_GAP: u64 = 0x6761_7000_0000_0000;
const TAG_ABS: u64 = 0x6162_7300_0000_0000;

fn check_rays(n: u64, param: &str) -> CoreResult<()> {
    if n == 0 {
        return Err(CoreError::invalid(
            param,
            "expected a positive number of rays, got 0",
        ));
    }
    Ok(())
}

/// Mean and standard error of per-block `(sum, sum of squares)` over `n` rays.
fn estimate(s1: f64, s2: f64, n: u64) -> Estimate {
    let nf = n as f64;
    let mean = s1 / nf;
    let var = if n > 1 {
        ((s2 - s1 * mean) / (nf - 1.0)).max(0.0)
    } else {
        0.0
    };
    Estimate {
        value: mean,
        se: (var / nf).sqrt(),
        n,
    }
}

/// The fractions of the incident light a scene absorbs per material and
/// reflects (escapes upwards).
#[derive(Debug, Clone, PartialEq)]
pub struct Absorption {
    /// Absorbed fraction per material index.
    pub absorbed: Vec<Estimate>,
    /// Reflected fraction (the albedo).
    pub reflected: Estimate,
    /// Fraction still travelling after `max_depth` scattering events.
    pub trapped: Estimate,
}

impl<G: Tracer> Scene<G> {
    /// Material index of a facet.
    #[inline]
    fn material_index(&self, f: G::Facet) -> usize {
        if self.material_ids.is_empty() {
            0
        } else {
            self.material_ids[self.hf.facet_index(f)] as usize
        }
    }

    /// Start of the sun ray `i`: above the highest facet, on the line along
    /// `sun` through a uniform point of the reference plane.
    #[inline]
    fn sun_ray(&self, key: StreamKey, sun: DVec3) -> DVec3 {
        let (x0, y0, w, h) = self.hf.footprint();
        let (x, y) = (x0 + key.uniform(0) * w, y0 + key.uniform(1) * h);
        let (_, zmax, zref) = self.hf.z_range();
        let top = zmax + 1e-6 * (1.0 + zmax.abs());
        DVec3::new(x, y, zref) + ((top - zref).max(0.0) / sun.z) * sun
    }

    /// Gap fraction towards `sun` (unit vector, pointing up): the fraction
    /// of `n` rays from the sun whose first hit is a facet of material
    /// `ground` (the soil), with its standard error.
    pub fn gap_fraction(&self, sun: DVec3, ground: u32, n: u64, seed: u64) -> CoreResult<Estimate> {
        check_rays(n, "n")?;
        let nm = self.more_materials.len() + 1;
        if ground as usize >= nm {
            return Err(CoreError::invalid(
                "ground",
                format!("expected a material index below {nm}, got {ground}"),
            ));
        }
        let blocks: Vec<(f64, u64)> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let end = ((blk + 1) * BLOCK).min(n);
                let mut s = 0.0;
                for i in blk * BLOCK..end {
                    let key = StreamKey::new(seed, TAG_GAP ^ i);
                    let o = self.sun_ray(key, sun);
                    if let Some(hit) = self.hf.trace(o, -sun, None) {
                        let (_, f) = self.hf.wrap(o - hit.t * sun, hit.facet);
                        if self.material_index(f) == ground as usize {
                            s += 1.0;
                        }
                    }
                }
                (s, end - blk * BLOCK)
            })
            .collect();
        let hits: f64 = blocks.iter().map(|b| b.0).sum();
        // a 0/1 variable: sum of squares = sum
        Ok(estimate(hits, hits, n))
    }

    /// Fractions of the light from the sun towards `sun` absorbed per
    /// material, reflected and still trapped after `max_depth` scattering
    /// events, over `spp` paths. At each hit the path's weight times
    /// `1 - albedo(wo)` of the facet's model is absorbed there (its
    /// expectation), and the path continues with the sampling weight, so
    /// absorbed + reflected + trapped = 1 on every path of energy-conserving
    /// models sampled by their albedo (Lambertian, bi-Lambertian).
    pub fn absorption(
        &self,
        sun: DVec3,
        spp: u64,
        max_depth: u32,
        seed: u64,
    ) -> CoreResult<Absorption> {
        check_rays(spp, "spp")?;
        if max_depth == 0 || max_depth > super::integrator::MAX_DEPTH {
            return Err(CoreError::invalid(
                "max_depth",
                format!(
                    "expected 1 to {}, got {max_depth}",
                    super::integrator::MAX_DEPTH
                ),
            ));
        }
        let nm = self.more_materials.len() + 1;
        let hf = &self.hf;
        // per block: [absorbed per material..., reflected, trapped] sums and squares
        let k = nm + 2;
        let blocks: Vec<Vec<(f64, f64)>> = (0..spp.div_ceil(BLOCK))
            .into_par_iter()
            .map(|blk| {
                let mut acc = vec![(0.0, 0.0); k];
                let mut path = vec![0.0; k];
                let end = ((blk + 1) * BLOCK).min(spp);
                for i in blk * BLOCK..end {
                    path.iter_mut().for_each(|v| *v = 0.0);
                    let key = StreamKey::new(seed, TAG_ABS ^ i);
                    let mut o = self.sun_ray(key, sun);
                    let mut d = -sun;
                    let mut skip = None;
                    let mut throughput = 1.0;
                    let mut dim = 2u64;
                    let mut depth = 0u32;
                    loop {
                        let Some(hit) = hf.trace(o, d, skip) else {
                            if depth > 0 && hf.escapes(d) {
                                path[nm] += throughput;
                            }
                            break;
                        };
                        if hit.normal.dot(d) >= 0.0 {
                            break; // reached a facet from below: numerically lost
                        }
                        let n = hit.normal;
                        let (p, facet) = hf.wrap(o + hit.t * d, hit.facet);
                        let (t, b) = basis(n);
                        let wo = DVec3::new(-d.dot(t), -d.dot(b), -d.dot(n));
                        let m = self.bsdf(facet);
                        let a = m.albedo(wo).clamp(0.0, 1.0);
                        path[self.material_index(facet)] += throughput * (1.0 - a);
                        depth += 1;
                        if depth == max_depth {
                            path[nm + 1] += throughput * a;
                            break;
                        }
                        let u = [key.uniform(dim), key.uniform(dim + 1)];
                        dim += 2;
                        let Some(smp) = m.sample(wo, u) else {
                            break;
                        };
                        throughput *= smp.weight;
                        if throughput == 0.0 {
                            break;
                        }
                        d = smp.wi.x * t + smp.wi.y * b + smp.wi.z * n;
                        o = p;
                        skip = Some(facet);
                    }
                    for (s, v) in acc.iter_mut().zip(&path) {
                        s.0 += v;
                        s.1 += v * v;
                    }
                }
                acc
            })
            .collect();
        let mut tot = vec![(0.0, 0.0); k];
        for b in &blocks {
            for (t, v) in tot.iter_mut().zip(b) {
                t.0 += v.0;
                t.1 += v.1;
            }
        }
        let est: Vec<Estimate> = tot.iter().map(|&(s1, s2)| estimate(s1, s2, spp)).collect();
        Ok(Absorption {
            absorbed: est[..nm].to_vec(),
            reflected: est[nm],
            trapped: est[nm + 1],
        })
    }
}
