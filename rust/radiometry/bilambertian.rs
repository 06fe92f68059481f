//! The bi-Lambertian leaf: a thin facet that reflects diffusely into the
//! side the light comes from and transmits diffusely into the other,
//! `f = r / pi` on the incident side and `t / pi` across.
//!
//! Unlike the one-sided models of [`super::material`], directions may lie on
//! either side of the facet: `wi` and `wo` on the same side (`wi.z * wo.z > 0`)
//! is reflection, on opposite sides transmission. The model is reciprocal
//! (`eval(wi, wo) == eval(wo, wi)`) and its albedo (reflected plus transmitted)
//! is `r + t <= 1` for every direction.
//!
//! Reference: the radiative-transfer leaf of the RAMI exercises (Pinty et al.
//! 2001, J. Geophys. Res. 106(D11) 11937-11956, doi:10.1029/2000JD900493):
//! Lambertian reflection `r` and Lambertian transmission `t`.
use glam::DVec3;

use super::material::{check_unit, cosine_hemisphere, Bsdf, BsdfSample};
use crate::error::{CoreError, CoreResult};
use std::f64::consts::FRAC_1_PI;

/// Bi-Lambertian leaf: reflectance `r`, transmittance `t`, `r + t <= 1`.
#[derive(Debug, Clone, Copy)]
pub struct BiLambertian {
    r: f64,
    t: f64,
}

impl BiLambertian {
    /// `reflectance` and `transmittance` in [0, 1] with a sum of at most 1.
    pub fn new(reflectance: f64, transmittance: f64) -> CoreResult<Self> {
        let r = check_unit(reflectance, "reflectance")?;
        let t = check_unit(transmittance, "transmittance")?;
        if r + t > 1.0 {
            return Err(CoreError::invalid(
                "transmittance",
                format!(
                    "expected reflectance + transmittance <= 1 (energy conservation), got {r} + {t} = {}",
                    r + t
                ),
            ));
        }
        Ok(BiLambertian { r, t })
    }

    /// Probability of choosing reflection when sampling.
    #[inline]
    fn p_reflect(&self) -> f64 {
        self.r / (self.r + self.t)
    }
}

impl Bsdf for BiLambertian {
    fn transmits(&self) -> bool {
        self.t > 0.0
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> f64 {
        let s = wi.z * wo.z;
        if s > 0.0 {
            self.r * FRAC_1_PI
        } else if s < 0.0 {
            self.t * FRAC_1_PI
        } else {
            0.0
        }
    }
    fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<BsdfSample> {
        if wo.z == 0.0 || self.r + self.t <= 0.0 {
            return None;
        }
        let pr = self.p_reflect();
        // choose the side with u[0], then reuse it (rescaled) for the radius
        let (reflect, u0) = if u[0] < pr {
            (true, u[0] / pr)
        } else {
            (false, (u[0] - pr) / (1.0 - pr))
        };
        let mut wi = cosine_hemisphere([u0.clamp(0.0, 1.0), u[1]]);
        if wi.z <= 0.0 {
            return None;
        }
        // wi.z > 0 is the side of the facet's normal; reflection goes to wo's side
        if (wo.z > 0.0) != reflect {
            wi.z = -wi.z;
        }
        let (p_side, weight) = if reflect {
            (pr, self.r / pr)
        } else {
            (1.0 - pr, self.t / (1.0 - pr))
        };
        Some(BsdfSample {
            wi,
            weight,
            pdf: p_side * wi.z.abs() * FRAC_1_PI,
        })
    }
    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let total = self.r + self.t;
        let s = wi.z * wo.z;
        if total <= 0.0 || s == 0.0 {
            return 0.0;
        }
        let p_side = if s > 0.0 {
            self.p_reflect()
        } else {
            1.0 - self.p_reflect()
        };
        p_side * wi.z.abs() * FRAC_1_PI
    }
    fn albedo(&self, wo: DVec3) -> f64 {
        if wo.z != 0.0 {
            self.r + self.t
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::material::{self, Bsdf};
    use super::BiLambertian;
    use crate::error::CoreError;
    use crate::rng::StreamKey;
    use glam::DVec3;
    use std::f64::consts::PI;

    fn local(zen: f64, az: f64) -> DVec3 {
        let (z, a) = (zen.to_radians(), az.to_radians());
        DVec3::new(z.sin() * a.cos(), z.sin() * a.sin(), z.cos())
    }

    #[test]
    fn sampler_passes_chi_square_on_both_sides_and_matches_its_density() {
        // cos^2 of a cosine-weighted direction is uniform on (0, 1) on each
        // side; the sides are drawn with probabilities r / (r + t), t / (r + t)
        let (r, t) = (0.45, 0.3);
        let m = material::from_name("bilambertian", &[r, t]).unwrap();
        for wo in [local(35.0, 20.0), -local(60.0, 200.0)] {
            let key = StreamKey::new(5, 11);
            let (bins, n) = (20usize, 200_000u64);
            let mut count = vec![0u64; 2 * bins];
            let (mut s1, mut s2) = (0.0, 0.0);
            for i in 0..n {
                let s = m
                    .sample(wo, [key.uniform(2 * i), key.uniform(2 * i + 1)])
                    .unwrap();
                assert!((s.pdf - m.pdf(s.wi, wo)).abs() < 1e-15);
                let want = m.eval(s.wi, wo) * s.wi.z.abs() / s.pdf;
                assert!((s.weight - want).abs() <= 1e-12);
                assert!((s.wi.length() - 1.0).abs() < 1e-12);
                s1 += s.weight;
                s2 += s.weight * s.weight;
                let side = usize::from(s.wi.z * wo.z < 0.0);
                let k = ((s.wi.z * s.wi.z * bins as f64) as usize).min(bins - 1);
                count[side * bins + k] += 1;
            }
            let chi2: f64 = count
                .iter()
                .enumerate()
                .map(|(j, &c)| {
                    let p = if j < bins { r } else { t } / (r + t);
                    let e = n as f64 * p / bins as f64;
                    (c as f64 - e).powi(2) / e
                })
                .sum();
            assert!(chi2 < 73.4, "{chi2}"); // 39 dof, p = 0.001
                                            // the mean sampling weight is the albedo r + t (here exactly: constant weights)
            let mean = s1 / n as f64;
            let se = ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
            assert!((mean - (r + t)).abs() < 4.0 * se + 1e-12, "{mean} {se}");
        }
    }

    #[test]
    fn eval_integrates_to_r_and_t_and_is_reciprocal() {
        // independent quadrature of f |cos| over each hemisphere (midpoint in
        // cos^2 and azimuth): the reflected and transmitted fractions
        let (r, t) = (0.2, 0.7);
        let m = BiLambertian::new(r, t).unwrap();
        let wo = local(50.0, 10.0);
        let (nu, nphi) = (200usize, 64usize);
        let (mut refl, mut trans) = (0.0, 0.0);
        for i in 0..nu {
            // |mu| d omega = d(mu^2) d(phi) / 2, so the integral is pi * mean(f) over (mu^2, phi)
            let mu = ((i as f64 + 0.5) / nu as f64).sqrt();
            let s = (1.0 - mu * mu).sqrt();
            for j in 0..nphi {
                let phi = 2.0 * PI * (j as f64 + 0.5) / nphi as f64;
                let up = DVec3::new(s * phi.cos(), s * phi.sin(), mu);
                let down = DVec3::new(up.x, up.y, -mu);
                refl += m.eval(up, wo) * PI / (nu * nphi) as f64;
                trans += m.eval(down, wo) * PI / (nu * nphi) as f64;
                assert_eq!(m.eval(up, wo), m.eval(wo, up));
                assert_eq!(m.eval(down, wo), m.eval(wo, down));
            }
        }
        assert!((refl - r).abs() < 1e-12, "{refl}");
        assert!((trans - t).abs() < 1e-12, "{trans}");
        assert_eq!(m.albedo(wo), r + t);
        assert_eq!(m.albedo(-wo), r + t);
    }

    #[test]
    fn pure_reflector_and_pure_transmitter_stay_on_their_side() {
        let key = StreamKey::new(1, 1);
        let wo = local(20.0, 0.0);
        for (r, t, same) in [(0.6, 0.0, true), (0.0, 0.8, false)] {
            let m = BiLambertian::new(r, t).unwrap();
            for i in 0..1000 {
                let s = m
                    .sample(wo, [key.uniform(2 * i), key.uniform(2 * i + 1)])
                    .unwrap();
                assert_eq!(s.wi.z > 0.0, same);
                assert!((s.weight - (r + t)).abs() < 1e-15);
            }
        }
        let black = BiLambertian::new(0.0, 0.0).unwrap();
        assert!(black.sample(wo, [0.3, 0.3]).is_none());
        assert_eq!(black.pdf(wo, wo), 0.0);
    }

    #[test]
    fn bad_input_names_the_parameter() {
        let p = |e: CoreError| match e {
            CoreError::InvalidArgument { param, .. } => param,
            _ => String::new(),
        };
        assert_eq!(p(BiLambertian::new(0.6, 0.5).unwrap_err()), "transmittance");
        assert_eq!(p(BiLambertian::new(-0.1, 0.5).unwrap_err()), "reflectance");
        assert_eq!(p(BiLambertian::new(0.1, 1.5).unwrap_err()), "transmittance");
        assert_eq!(
            p(BiLambertian::new(f64::NAN, 0.5).unwrap_err()),
            "reflectance"
        );
        assert_eq!(
            p(material::from_name("bilambertian", &[0.5]).unwrap_err()),
            "material"
        );
        let msg = BiLambertian::new(0.6, 0.5).unwrap_err().to_string();
        assert!(msg.contains("reflectance + transmittance"), "{msg}");
    }
}
