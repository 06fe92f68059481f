//! A smooth mirror facet with Fresnel reflectance: light arriving from `wi`
//! leaves only along its mirror image, with the unpolarised Fresnel
//! reflectance `F(cos theta)` of a medium of complex refractive index
//! `eta + i k` relative to the air above (k = 0: a dielectric such as water,
//! 1.33; k > 0: a conductor).
//!
//! The BRDF is a Dirac delta: [`Bsdf::eval`] and [`Bsdf::pdf`] are 0 for
//! every pair of directions (the mirror pair has measure zero), so the
//! directional sun never reaches the sensor by next-event estimation from a
//! mirror; light reaches it through [`Bsdf::sample`], which returns the
//! mirror direction with weight `F` (and an infinite density). Reciprocal
//! (`F` depends on the common angle only) and energy-bounded (`F <= 1`).
use glam::DVec3;

use super::material::{Bsdf, BsdfSample};
use crate::error::{CoreError, CoreResult};

/// Mirror with Fresnel reflectance.
#[derive(Debug, Clone, Copy)]
pub struct Specular {
    eta: f64,
    k: f64,
}

/// `sqrt(a + i b)`, the principal root.
#[inline]
fn csqrt(a: f64, b: f64) -> (f64, f64) {
    let m = a.hypot(b);
    let re = (0.5 * (m + a)).max(0.0).sqrt();
    let im = (0.5 * (m - a)).max(0.0).sqrt();
    (re, if b < 0.0 { -im } else { im })
}

/// `|(p - q) / (p + q)|^2` for complex `p`, `q`.
#[inline]
fn ratio2(p: (f64, f64), q: (f64, f64)) -> f64 {
    let num = (p.0 - q.0).powi(2) + (p.1 - q.1).powi(2);
    let den = (p.0 + q.0).powi(2) + (p.1 + q.1).powi(2);
    if den > 0.0 {
        num / den
    } else {
        1.0
    }
}

impl Specular {
    /// `eta` > 0 and `k` >= 0, both finite.
    pub fn new(eta: f64, k: f64) -> CoreResult<Self> {
        if !(eta.is_finite() && eta > 0.0) {
            return Err(CoreError::invalid(
                "eta",
                format!("expected a relative refractive index > 0, got {eta}"),
            ));
        }
        if !(k.is_finite() && k >= 0.0) {
            return Err(CoreError::invalid(
                "k",
                format!("expected an extinction coefficient >= 0, got {k}"),
            ));
        }
        Ok(Specular { eta, k })
    }

    /// Unpolarised Fresnel reflectance at incidence cosine `c` in [0, 1]
    /// (Born and Wolf, section 1.5): the mean of `|r_s|^2` and `|r_p|^2`.
    pub fn fresnel(&self, c: f64) -> f64 {
        let c = c.clamp(0.0, 1.0);
        let s2 = 1.0 - c * c;
        // eta^2 = (n + ik)^2
        let e2 = (
            self.eta * self.eta - self.k * self.k,
            2.0 * self.eta * self.k,
        );
        let w = csqrt(e2.0 - s2, e2.1); // sqrt(eta^2 - sin^2)
        let rs = ratio2((c, 0.0), w);
        let rp = ratio2((e2.0 * c, e2.1 * c), w);
        0.5 * (rs + rp)
    }
}

impl Bsdf for Specular {
    fn eval(&self, _wi: DVec3, _wo: DVec3) -> f64 {
        0.0
    }
    fn sample(&self, wo: DVec3, _u: [f64; 2]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi: DVec3::new(-wo.x, -wo.y, wo.z),
            weight: self.fresnel(wo.z),
            pdf: f64::INFINITY,
        })
    }
    fn pdf(&self, _wi: DVec3, _wo: DVec3) -> f64 {
        0.0
    }
    fn albedo(&self, wo: DVec3) -> f64 {
        if wo.z <= 0.0 {
            0.0
        } else {
            self.fresnel(wo.z)
        }
    }
}
