//! The qualitative Oren-Nayar model (Oren & Nayar 1994, eq. 30): a rough
//! diffuse surface of V-cavities whose facet slopes have standard deviation
//! `sigma` (radians):
//!
//! `f = rho/pi * (A + B * max(0, cos(phi_i - phi_o)) * sin(alpha) * tan(beta))`,
//! `A = 1 - 0.5 s^2 / (s^2 + 0.33)`, `B = 0.45 s^2 / (s^2 + 0.09)`,
//! `alpha = max(theta_i, theta_o)`, `beta = min(theta_i, theta_o)`.
//!
//! Sampled cosine-weighted; its albedo has no closed form and is computed by
//! quadrature.
use glam::DVec3;

use super::material::{check_unit, cosine_hemisphere, cosine_pdf, cosine_sample, Bsdf, BsdfSample};
use crate::error::{CoreError, CoreResult};
use std::f64::consts::{FRAC_1_PI, PI};

/// Qualitative Oren-Nayar reflectance.
#[derive(Debug, Clone, Copy)]
pub struct OrenNayar {
    rho: f64,
    a: f64,
    b: f64,
}

impl OrenNayar {
    /// `rho` in [0, 1]; `sigma` (radians) finite and >= 0 (0 is Lambertian).
    pub fn new(rho: f64, sigma: f64) -> CoreResult<Self> {
        let rho = check_unit(rho, "rho")?;
        if !(sigma.is_finite() && sigma >= 0.0) {
            return Err(CoreError::invalid(
                "sigma",
                format!("expected a slope standard deviation >= 0 in radians, got {sigma}"),
            ));
        }
        let s2 = sigma * sigma;
        Ok(OrenNayar {
            rho,
            a: 1.0 - 0.5 * s2 / (s2 + 0.33),
            b: 0.45 * s2 / (s2 + 0.09),
        })
    }
}

impl Bsdf for OrenNayar {
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let (si, so) = (
            (wi.x * wi.x + wi.y * wi.y).sqrt(),
            (wo.x * wo.x + wo.y * wo.y).sqrt(),
        );
        let mut term = 0.0;
        if si > 0.0 && so > 0.0 {
            let cos_dphi = (wi.x * wo.x + wi.y * wo.y) / (si * so);
            if cos_dphi > 0.0 {
                // alpha = the larger zenith angle (smaller cosine)
                let (sin_a, tan_b) = if wi.z < wo.z {
                    (si, so / wo.z)
                } else {
                    (so, si / wi.z)
                };
                term = cos_dphi * sin_a * tan_b;
            }
        }
        self.rho * FRAC_1_PI * (self.a + self.b * term)
    }
    fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<BsdfSample> {
        cosine_sample(wo, u, |wi| PI * self.eval(wi, wo))
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        cosine_pdf(wi, wo)
    }
    fn albedo(&self, wo: DVec3) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        // E[pi f] over cosine-weighted wi: midpoint rule in the sampler's
        // (u1, u2) square (the integrand is smooth there but for the max()).
        const N: usize = 256;
        let mut s = 0.0;
        for i in 0..N {
            for j in 0..N {
                let u = [(i as f64 + 0.5) / N as f64, (j as f64 + 0.5) / N as f64];
                s += PI * self.eval(cosine_hemisphere(u), wo);
            }
        }
        s / (N * N) as f64
    }
}
