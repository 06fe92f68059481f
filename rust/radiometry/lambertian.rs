//! The Lambertian (perfectly diffuse) reflector: `f = rho / pi`.
use glam::DVec3;

use super::material::{check_unit, cosine_pdf, cosine_sample, Bsdf, BsdfSample};
use crate::error::CoreResult;
use std::f64::consts::FRAC_1_PI;

/// Lambertian reflectance `rho` (albedo = `rho` for every direction).
#[derive(Debug, Clone, Copy)]
pub struct Lambertian {
    rho: f64,
}

impl Lambertian {
    /// `rho` in [0, 1].
    pub fn new(rho: f64) -> CoreResult<Self> {
        Ok(Lambertian {
            rho: check_unit(rho, "rho")?,
        })
    }
}

impl Bsdf for Lambertian {
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z > 0.0 && wo.z > 0.0 {
            self.rho * FRAC_1_PI
        } else {
            0.0
        }
    }
    fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<BsdfSample> {
        cosine_sample(wo, u, |_| self.rho)
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        cosine_pdf(wi, wo)
    }
    fn albedo(&self, wo: DVec3) -> f64 {
        if wo.z > 0.0 {
            self.rho
        } else {
            0.0
        }
    }
}
