//! The energy-normalised (modified) Phong model of Lafortune & Willems
//! (1994): a Lambertian part plus a lobe around the mirror direction,
//!
//! `f = kd / pi + ks (n + 2) / (2 pi) cos^n(alpha)`,
//!
//! `alpha` the angle between `wi` and the mirror image of `wo` about the
//! normal (0 when that cosine is negative). Reciprocal; with `kd + ks <= 1`
//! the albedo is at most `kd + ks` (equal at normal incidence). Sampled as a
//! mixture: cosine-weighted with probability `kd / (kd + ks)`, else
//! `cos(alpha) = u^(1 / (n + 1))` around the mirror direction.
use glam::DVec3;

use super::material::{basis, check_unit, cosine_hemisphere, Bsdf, BsdfSample};
use crate::error::{CoreError, CoreResult};
use std::f64::consts::{FRAC_1_PI, PI};

/// Modified Phong reflectance.
#[derive(Debug, Clone, Copy)]
pub struct Phong {
    kd: f64,
    ks: f64,
    n: f64,
}

/// The mirror image of `w` about the local normal `z`.
#[inline]
fn mirror(w: DVec3) -> DVec3 {
    DVec3::new(-w.x, -w.y, w.z)
}

impl Phong {
    /// `kd`, `ks` in [0, 1] with `kd + ks <= 1`; exponent `n` finite, >= 0.
    pub fn new(kd: f64, ks: f64, n: f64) -> CoreResult<Self> {
        let kd = check_unit(kd, "kd")?;
        let ks = check_unit(ks, "ks")?;
        if kd + ks > 1.0 {
            return Err(CoreError::invalid(
                "ks",
                format!("expected kd + ks <= 1 (energy), got {kd} + {ks}"),
            ));
        }
        if !(n.is_finite() && n >= 0.0) {
            return Err(CoreError::invalid(
                "exponent",
                format!("expected a finite exponent >= 0, got {n}"),
            ));
        }
        Ok(Phong { kd, ks, n })
    }

    #[inline]
    fn lobe(&self, wi: DVec3, wo: DVec3) -> f64 {
        let c = wi.dot(mirror(wo));
        if c > 0.0 {
            c.powf(self.n)
        } else {
            0.0
        }
    }

    #[inline]
    fn p_diffuse(&self) -> f64 {
        let t = self.kd + self.ks;
        if t > 0.0 {
            self.kd / t
        } else {
            1.0
        }
    }
}

impl Bsdf for Phong {
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        self.kd * FRAC_1_PI + self.ks * (self.n + 2.0) / (2.0 * PI) * self.lobe(wi, wo)
    }
    fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 || self.kd + self.ks == 0.0 {
            return None;
        }
        let pd = self.p_diffuse();
        let wi = if u[0] < pd {
            cosine_hemisphere([u[0] / pd, u[1]])
        } else {
            let v = (u[0] - pd) / (1.0 - pd);
            let ca = v.powf(1.0 / (self.n + 1.0));
            let sa = (1.0 - ca * ca).max(0.0).sqrt();
            let phi = 2.0 * PI * u[1];
            let r = mirror(wo);
            let (t, b) = basis(r);
            (sa * phi.cos()) * t + (sa * phi.sin()) * b + ca * r
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf(wi, wo);
        if pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.eval(wi, wo) * wi.z / pdf,
            pdf,
        })
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let pd = self.p_diffuse();
        pd * wi.z * FRAC_1_PI + (1.0 - pd) * (self.n + 1.0) / (2.0 * PI) * self.lobe(wi, wo)
    }
    fn albedo(&self, wo: DVec3) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        // diffuse part kd; lobe part ks (n+2)/(n+1) E_lobe[max(0, cos theta_i)]
        // by the midpoint rule in the lobe sampler's (u1, u2) square
        const N: usize = 256;
        let r = mirror(wo);
        let (t, b) = basis(r);
        let mut s = 0.0;
        for i in 0..N {
            let ca = ((i as f64 + 0.5) / N as f64).powf(1.0 / (self.n + 1.0));
            let sa = (1.0 - ca * ca).max(0.0).sqrt();
            for j in 0..N {
                let phi = 2.0 * PI * (j as f64 + 0.5) / N as f64;
                let wi = (sa * phi.cos()) * t + (sa * phi.sin()) * b + ca * r;
                s += wi.z.max(0.0);
            }
        }
        self.kd + self.ks * (self.n + 2.0) / (self.n + 1.0) * s / (N * N) as f64
    }
}
