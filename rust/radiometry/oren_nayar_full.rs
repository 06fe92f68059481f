//! The full Oren-Nayar model (Oren & Nayar 1994, equations 27-29 with the
//! interreflection term of section 4.4): a rough diffuse surface of
//! V-cavities whose facet slopes have standard deviation `sigma` (radians).
//!
//! With `alpha = max(theta_i, theta_o)`, `beta = min(theta_i, theta_o)`,
//! `c = cos(phi_i - phi_o)`, `s2 = sigma^2`:
//!
//! * `C1 = 1 - 0.5 s2 / (s2 + 0.33)`
//! * `C2 = 0.45 s2 / (s2 + 0.09) sin(alpha)` when `c >= 0`, else
//!   `0.45 s2 / (s2 + 0.09) (sin(alpha) - (2 beta / pi)^3)`
//! * `C3 = 0.125 s2 / (s2 + 0.09) (4 alpha beta / pi^2)^2`
//! * direct: `f1 = rho/pi [C1 + c C2 tan(beta) + (1 - |c|) C3 tan((alpha + beta)/2)]`
//! * interreflection: `f2 = 0.17 rho^2/pi s2 / (s2 + 0.13) (1 - c (2 beta / pi)^2)`
//!
//! `f = f1 + f2`, symmetric in the two directions (reciprocal). The model is
//! an approximation and reflects slightly more than the incident light at
//! grazing incidence for `rho` near 1 (1.04 at `rho = 1`, `sigma = 0.3`,
//! zenith 89 degrees): parameters whose directional albedo exceeds 1 are
//! rejected, as for Hapke. Sampled cosine-weighted.
use glam::DVec3;

use super::material::{check_unit, cosine_hemisphere, cosine_pdf, cosine_sample, Bsdf, BsdfSample};
use crate::error::{CoreError, CoreResult};
use std::f64::consts::{FRAC_1_PI, PI};

/// Full Oren-Nayar reflectance with the interreflection term.
#[derive(Debug, Clone, Copy)]
pub struct OrenNayarFull {
    rho: f64,
    c1: f64,
    k2: f64,
    k3: f64,
    k_ir: f64,
}

/// Zenith angles (degrees) at which [`OrenNayarFull::new`] checks the albedo.
const ALBEDO_CHECK_ZENITHS: [f64; 12] = [
    0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 75.0, 80.0, 85.0, 89.0,
];

impl OrenNayarFull {
    /// `rho` in [0, 1]; `sigma` (radians) finite and >= 0 (0 is Lambertian).
    /// Parameters whose directional albedo exceeds 1 are an error naming `rho`.
    pub fn new(rho: f64, sigma: f64) -> CoreResult<Self> {
        let rho = check_unit(rho, "rho")?;
        if !(sigma.is_finite() && sigma >= 0.0) {
            return Err(CoreError::invalid(
                "sigma",
                format!("expected a slope standard deviation >= 0 in radians, got {sigma}"),
            ));
        }
        let s2 = sigma * sigma;
        let m = OrenNayarFull {
            rho,
            c1: 1.0 - 0.5 * s2 / (s2 + 0.33),
            k2: 0.45 * s2 / (s2 + 0.09),
            k3: 0.125 * s2 / (s2 + 0.09),
            k_ir: 0.17 * rho * s2 / (s2 + 0.13),
        };
        for zen in ALBEDO_CHECK_ZENITHS {
            let z = zen.to_radians();
            let a = m.albedo_n(DVec3::new(z.sin(), 0.0, z.cos()), 128);
            if a > 1.0 {
                return Err(CoreError::invalid(
                    "rho",
                    format!(
                        "OrenNayar(rho={rho}, sigma={sigma}, full=True) reflects {a:.4} > 1 of the \
                         light arriving at zenith {zen} degrees (the model does not conserve energy \
                         there); lower rho"
                    ),
                ));
            }
        }
        Ok(m)
    }

    /// Directional albedo by the midpoint rule on an `n x n` grid of the
    /// cosine sampler's unit square.
    fn albedo_n(&self, wo: DVec3, n: usize) -> f64 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        let mut s = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = [(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64];
                s += PI * self.eval(cosine_hemisphere(u), wo);
            }
        }
        s / (n * n) as f64
    }
}

impl Bsdf for OrenNayarFull {
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let (si, so) = (
            (wi.x * wi.x + wi.y * wi.y).sqrt(),
            (wo.x * wo.x + wo.y * wo.y).sqrt(),
        );
        let ti = si.atan2(wi.z);
        let to = so.atan2(wo.z);
        let (alpha, beta) = if ti > to { (ti, to) } else { (to, ti) };
        // azimuth undefined at the pole: the terms it multiplies vanish there
        let c = if si > 0.0 && so > 0.0 {
            ((wi.x * wo.x + wi.y * wo.y) / (si * so)).clamp(-1.0, 1.0)
        } else {
            0.0
        };
        let b2 = 2.0 * beta * FRAC_1_PI;
        let c2 = if c >= 0.0 {
            self.k2 * alpha.sin()
        } else {
            self.k2 * (alpha.sin() - b2 * b2 * b2)
        };
        let c3 = self.k3 * (4.0 * alpha * beta * FRAC_1_PI * FRAC_1_PI).powi(2);
        let direct =
            self.c1 + c * c2 * beta.tan() + (1.0 - c.abs()) * c3 * (0.5 * (alpha + beta)).tan();
        let inter = self.k_ir * (1.0 - c * b2 * b2);
        (self.rho * FRAC_1_PI * (direct + inter)).max(0.0)
    }
    fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<BsdfSample> {
        cosine_sample(wo, u, |wi| PI * self.eval(wi, wo))
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        cosine_pdf(wi, wo)
    }
    fn albedo(&self, wo: DVec3) -> f64 {
        self.albedo_n(wo, 256)
    }
}
