//! Hapke's bidirectional reflectance of a particulate, rough surface
//! (Hapke 1984, Icarus 59, 41-59, equations 45-58 for the macroscopic
//! roughness; Hapke 2002, Icarus 157, 523-534, equation 13 for the
//! H-function), in the parametrisation of Eradiate's `hapke` BSDF:
//!
//! `BRF = w/4 * mu0e / (mu0e + mue) / mu0 * (P(g) (1 + B(g)) + M) * S`,
//!
//! * `P(g) = (1 - c) HG(-b) + c HG(b)`: a double Henyey-Greenstein phase
//!   function, `HG(b) = (1 - b^2) / (1 - 2 b cos g + b^2)^1.5`, `c` the
//!   back-scattered fraction, `g` the phase angle (between the directions
//!   to the sun and to the sensor);
//! * `B(g) = B0 / (1 + tan(g / 2) / h)`: the shadow-hiding opposition
//!   surge; with `h = 0` it is `B0` at exact backscatter (its limit there
//!   for every `h > 0`) and 0 elsewhere, so the model is finite everywhere;
//! * `M = H(mu0e) H(mue) - 1`: isotropic multiple scattering;
//! * `mu0e`, `mue`, `S`: the effective cosines and shadowing function of a
//!   surface whose facet slopes have mean `theta_bar`.
//!
//! The BRDF is `BRF / pi`. It is reciprocal. Hapke's model does not
//! conserve energy for bright, back-scattering surfaces (with `w = 1` its
//! directional albedo reaches 1.46), so [`Hapke::new`] rejects parameters
//! whose directional albedo exceeds 1 at some sun zenith. Sampled
//! cosine-weighted (as Eradiate does).
use glam::DVec3;

use super::material::{check_unit, cosine_hemisphere, cosine_pdf, cosine_sample, Bsdf, BsdfSample};
use crate::error::{CoreError, CoreResult};
use std::f64::consts::{FRAC_1_PI, FRAC_PI_2, PI};

/// Hapke reflectance.
#[derive(Debug, Clone, Copy)]
pub struct Hapke {
    w: f64,
    b: f64,
    c: f64,
    /// `tan(theta_bar)`.
    t: f64,
    b0: f64,
    h: f64,
    /// `r0 = (1 - gamma) / (1 + gamma)`, `gamma = sqrt(1 - w)`.
    r0: f64,
    /// `chi(theta_bar) = 1 / sqrt(1 + pi tan^2 theta_bar)`.
    chi: f64,
}

/// Zenith angles (degrees) at which [`Hapke::new`] checks the albedo.
const ALBEDO_CHECK_ZENITHS: [f64; 12] = [
    0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 75.0, 80.0, 85.0, 89.0,
];

impl Hapke {
    /// `w`, `b`, `c`, `b0`, `h` in [0, 1]; `theta_bar` in [0, 90) degrees.
    /// Parameters whose directional albedo exceeds 1 are an error.
    pub fn new(w: f64, b: f64, c: f64, theta_bar: f64, b0: f64, h: f64) -> CoreResult<Self> {
        let w = check_unit(w, "w")?;
        let b = check_unit(b, "b")?;
        let c = check_unit(c, "c")?;
        let b0 = check_unit(b0, "B0")?;
        let h = check_unit(h, "h")?;
        if !(theta_bar.is_finite() && (0.0..90.0).contains(&theta_bar)) {
            return Err(CoreError::invalid(
                "theta_bar",
                format!("expected a mean slope angle in [0, 90) degrees, got {theta_bar}"),
            ));
        }
        if b >= 1.0 {
            return Err(CoreError::invalid(
                "b",
                format!("expected a Henyey-Greenstein asymmetry in [0, 1), got {b}"),
            ));
        }
        let t = theta_bar.to_radians().tan();
        let gamma = (1.0 - w).sqrt();
        let m = Hapke {
            w,
            b,
            c,
            t,
            b0,
            h,
            r0: (1.0 - gamma) / (1.0 + gamma),
            chi: 1.0 / (1.0 + PI * t * t).sqrt(),
        };
        for zen in ALBEDO_CHECK_ZENITHS {
            let z = zen.to_radians();
            let a = m.albedo_n(DVec3::new(z.sin(), 0.0, z.cos()), 64);
            if a > 1.0 {
                return Err(CoreError::invalid(
                    "w",
                    format!(
                        "Hapke(w={w}, b={b}, c={c}, theta_bar={theta_bar}, B0={b0}, h={h}) reflects \
                         {a:.4} > 1 of the light arriving at zenith {zen} degrees (the model does not \
                         conserve energy there); lower w, B0 or c"
                    ),
                ));
            }
        }
        Ok(m)
    }

    /// Hapke's (2002, eq. 13) approximation of Chandrasekhar's H-function.
    #[inline]
    fn h_fn(&self, x: f64) -> f64 {
        if x <= 0.0 {
            return 1.0;
        }
        let r0 = self.r0;
        1.0 / (1.0 - self.w * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * ((1.0 + x) / x).ln()))
    }

    /// Hapke 1984 eq. 45 (`E1`) and 46 (`E2`) at zenith angle `x` (radians).
    #[inline]
    fn e1_e2(&self, x: f64) -> (f64, f64) {
        let tx = x.tan();
        if tx <= 0.0 {
            return (0.0, 0.0);
        }
        let u = self.t * tx;
        ((-2.0 * FRAC_1_PI / u).exp(), (-FRAC_1_PI / (u * u)).exp())
    }

    /// The bidirectional reflectance factor `pi f` for the directions with
    /// cosines `mu0` (sun) and `mu` (sensor), both in (0, 1], and
    /// `cos_g`, the cosine of the phase angle; `cos_psi` is the cosine of
    /// the azimuth difference (1 when a direction is the normal).
    pub fn brf(&self, mu0: f64, mu: f64, cos_g: f64, cos_psi: f64) -> f64 {
        let cos_g = cos_g.clamp(-1.0, 1.0);
        let (b, c) = (self.b, self.c);
        let b2 = b * b;
        let p = (1.0 - c) * (1.0 - b2) / (1.0 + 2.0 * b * cos_g + b2).powf(1.5)
            + c * (1.0 - b2) / (1.0 - 2.0 * b * cos_g + b2).powf(1.5);
        // tan(g/2) = sqrt((1 - cos g) / (1 + cos g)), exact 0 at cos g = 1
        let opp = if self.b0 == 0.0 {
            0.0
        } else if cos_g >= 1.0 {
            self.b0
        } else if self.h == 0.0 || cos_g <= -1.0 {
            0.0
        } else {
            let tan_half = ((1.0 - cos_g) / (1.0 + cos_g)).sqrt();
            self.b0 / (1.0 + tan_half / self.h)
        };
        let (m0, me, s) = if self.t == 0.0 {
            (mu0, mu, 1.0)
        } else {
            self.roughness(mu0, mu, cos_psi)
        };
        let m = self.h_fn(m0) * self.h_fn(me) - 1.0;
        0.25 * self.w * m0 / (m0 + me) / mu0 * (p * (1.0 + opp) + m) * s
    }

    /// `(mu0e, mue, S)` of Hapke 1984, equations 47-58.
    fn roughness(&self, mu0: f64, mu: f64, cos_psi: f64) -> (f64, f64, f64) {
        let (t, chi) = (self.t, self.chi);
        let i = mu0.clamp(-1.0, 1.0).acos();
        let e = mu.clamp(-1.0, 1.0).acos();
        let (sin_i, sin_e) = (i.sin(), e.sin());
        let psi = cos_psi.clamp(-1.0, 1.0).acos();
        let s2 = (0.5 * psi).sin().powi(2);
        // f(psi) = exp(-2 tan(psi / 2)), 0 at psi = pi
        let f = if psi >= PI - 1e-12 {
            0.0
        } else {
            (-2.0 * (0.5 * psi).min(FRAC_PI_2).tan()).exp()
        };
        let (e1i, e2i) = self.e1_e2(i);
        let (e1e, e2e) = self.e1_e2(e);
        let eta = |cx: f64, sx: f64, e1: f64, e2: f64| chi * (cx + sx * t * e2 / (2.0 - e1));
        let eta_i = eta(mu0, sin_i, e1i, e2i);
        let eta_e = eta(mu, sin_e, e1e, e2e);
        if i <= e {
            let d = 2.0 - e1e - psi * FRAC_1_PI * e1i;
            let m0 = chi * (mu0 + sin_i * t * (cos_psi * e2e + s2 * e2i) / d);
            let me = chi * (mu + sin_e * t * (e2e - s2 * e2i) / d);
            let s = me / eta_e * mu0 / eta_i * chi / (1.0 - f + f * chi * mu0 / eta_i);
            (m0, me, s)
        } else {
            let d = 2.0 - e1i - psi * FRAC_1_PI * e1e;
            let m0 = chi * (mu0 + sin_i * t * (e2i - s2 * e2e) / d);
            let me = chi * (mu + sin_e * t * (cos_psi * e2i + s2 * e2e) / d);
            let s = me / eta_e * mu0 / eta_i * chi / (1.0 - f + f * chi * mu / eta_e);
            (m0, me, s)
        }
    }

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

impl Bsdf for Hapke {
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let (si, so) = (wi.x.hypot(wi.y), wo.x.hypot(wo.y));
        let cos_psi = if si > 0.0 && so > 0.0 {
            ((wi.x * wo.x + wi.y * wo.y) / (si * so)).clamp(-1.0, 1.0)
        } else {
            1.0
        };
        let cos_g = wi.dot(wo) / (wi.length() * wo.length());
        self.brf(wi.z.min(1.0), wo.z.min(1.0), cos_g, cos_psi) * FRAC_1_PI
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
