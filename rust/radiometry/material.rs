//! Reflectance models: one trait, one file per model, registered by name.
//!
//! Directions are unit vectors in the facet's local frame (`z` along the
//! facet normal), both pointing away from the surface: `wi` towards the
//! light, `wo` towards the viewer. Every model is reciprocal
//! (`eval(wi, wo) == eval(wo, wi)`) and energy-bounded (`albedo <= 1`).
use glam::DVec3;

use crate::error::{CoreError, CoreResult};

/// A direction drawn by [`Bsdf::sample`].
#[derive(Debug, Clone, Copy)]
pub struct BsdfSample {
    /// The sampled incident direction (local frame, `z > 0`).
    pub wi: DVec3,
    /// `eval(wi, wo) * wi.z / pdf`: the factor the path throughput takes.
    pub weight: f64,
    /// Probability density of `wi` per steradian.
    pub pdf: f64,
}

/// A reflectance model (a BRDF: nothing is transmitted).
pub trait Bsdf: Send + Sync + std::fmt::Debug {
    /// The BRDF `f(wi, wo)` in 1/sr; 0 when either direction is below the facet.
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64;
    /// Draw `wi` for a given `wo` from two uniforms in (0, 1); `None` when
    /// the draw falls outside the upper hemisphere (weight 0).
    fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<BsdfSample>;
    /// The density [`Bsdf::sample`] draws `wi` with, per steradian.
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64;
    /// Directional-hemispherical reflectance for light leaving along `wo`
    /// (by reciprocity, also the albedo for light arriving from `wo`).
    fn albedo(&self, wo: DVec3) -> f64;
    /// Whether light also leaves through the facet (two-sided facets such
    /// as leaves): then `eval` and `sample` accept `wi` below the facet
    /// (`wi.z < 0`, transmission), the sampling weight taking `|wi.z|`, and
    /// the integrator adds the sun behind the facet. Default `false`.
    fn transmits(&self) -> bool {
        false
    }
}

/// Cosine-weighted direction on the upper hemisphere (Malley's method:
/// a uniform point on the unit disc lifted to the hemisphere).
#[inline]
pub fn cosine_hemisphere(u: [f64; 2]) -> DVec3 {
    let r = u[0].sqrt();
    let phi = 2.0 * std::f64::consts::PI * u[1];
    let z = (1.0 - u[0]).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A cosine-weighted draw of `wi` for `wo` (both above the facet), with the
/// sampling weight `f cos / pdf` given by `weight(wi)`: the sampler of every
/// model that importance-samples the cosine (Lambertian, Oren-Nayar).
#[inline]
pub fn cosine_sample(wo: DVec3, u: [f64; 2], weight: impl Fn(DVec3) -> f64) -> Option<BsdfSample> {
    if wo.z <= 0.0 {
        return None;
    }
    let wi = cosine_hemisphere(u);
    if wi.z <= 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi,
        weight: weight(wi),
        pdf: wi.z * std::f64::consts::FRAC_1_PI,
    })
}

/// The density of [`cosine_sample`], per steradian (0 below the facet).
#[inline]
pub fn cosine_pdf(wi: DVec3, wo: DVec3) -> f64 {
    if wi.z > 0.0 && wo.z > 0.0 {
        wi.z * std::f64::consts::FRAC_1_PI
    } else {
        0.0
    }
}

/// An orthonormal basis `(t, b)` completing the unit vector `n`
/// (Duff et al. 2017, "Building an orthonormal basis, revisited").
#[inline]
pub fn basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Build a model from its registered name and parameters.
///
/// | name | parameters |
/// |---|---|
/// | `lambertian` | `rho` in [0, 1] |
/// | `oren-nayar` | `rho` in [0, 1], `sigma` (slope standard deviation, radians) >= 0 |
/// | `oren-nayar-full` | the same, full 1994 model with the interreflection term |
/// | `phong` | `kd`, `ks` in [0, 1] with `kd + ks <= 1`, exponent >= 0 |
/// | `hapke` | `w`, `b`, `c`, `theta_bar` (degrees), `B0`, `h` |
/// | `specular` | `eta` > 0, `k` >= 0 (complex relative refractive index) |
/// | `bilambertian` | `reflectance`, `transmittance` in [0, 1] with sum <= 1 (two-sided leaf) |
pub fn from_name(name: &str, params: &[f64]) -> CoreResult<Box<dyn Bsdf>> {
    let want = |n: usize, what: &str| -> CoreResult<()> {
        if params.len() == n {
            Ok(())
        } else {
            Err(CoreError::invalid(
                "material",
                format!(
                    "{name} takes {n} parameter(s) ({what}), got {}",
                    params.len()
                ),
            ))
        }
    };
    match name {
        "lambertian" => {
            want(1, "rho")?;
            Ok(Box::new(super::lambertian::Lambertian::new(params[0])?))
        }
        "oren-nayar" => {
            want(2, "rho, sigma")?;
            Ok(Box::new(super::oren_nayar::OrenNayar::new(
                params[0], params[1],
            )?))
        }
        "oren-nayar-full" => {
            want(2, "rho, sigma")?;
            Ok(Box::new(super::oren_nayar_full::OrenNayarFull::new(
                params[0], params[1],
            )?))
        }
        "phong" => {
            want(3, "kd, ks, exponent")?;
            Ok(Box::new(super::phong::Phong::new(
                params[0], params[1], params[2],
            )?))
        }
        "hapke" => {
            want(6, "w, b, c, theta_bar, B0, h")?;
            Ok(Box::new(super::hapke::Hapke::new(
                params[0], params[1], params[2], params[3], params[4], params[5],
            )?))
        }
        "specular" => {
            want(2, "eta, k")?;
            Ok(Box::new(super::specular::Specular::new(
                params[0], params[1],
            )?))
        }
        "bilambertian" => {
            want(2, "reflectance, transmittance")?;
            Ok(Box::new(super::bilambertian::BiLambertian::new(
                params[0], params[1],
            )?))
        }
        _ => Err(CoreError::invalid(
            "material",
            format!(
                "expected one of 'lambertian', 'oren-nayar', 'oren-nayar-full', 'phong', 'hapke', 'specular', 'bilambertian', got {name:?}"
            ),
        )),
    }
}

/// `rho` must lie in [0, 1].
pub fn check_unit(value: f64, param: &str) -> CoreResult<f64> {
    if (0.0..=1.0).contains(&value) {
        Ok(value)
    } else {
        Err(CoreError::invalid(
            param,
            format!("expected a reflectance in [0, 1], got {value}"),
        ))
    }
}
