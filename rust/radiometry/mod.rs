//! The virtual radiometric experiment (issue 26, paper section 4.1): BRF,
//! albedo and images of a rough surface of triangular facets lit by a
//! directional sun, by Monte Carlo path tracing.
//!
//! * [`heightfield`]: a DEM as two facets per cell and its ray caster
//!   (cell stepping with wrap-around for periodic tiles).
//! * [`material`]: the reflectance-model trait, with [`lambertian`],
//!   [`oren_nayar`], [`phong`], [`hapke`] and [`specular`].
//! * [`mesh_tracer`]: a triangle mesh through a BVH (two-sided facets,
//!   periodic tiles); [`tracer`]: the geometry trait both implement.
//! * [`integrator`]: path tracing with next-event estimation to the sun,
//!   and the BRF, albedo and image estimators.
//!
//! Conventions: azimuth in degrees clockwise from north, zenith in degrees
//! from the vertical; the sun's irradiance is 1 on a plane normal to the
//! beam (so a horizontal plane receives `cos(zenith)`).
//!
//! Random numbers are counter-based ([`crate::rng::StreamKey`]):
//! every path is keyed by `(seed, path index)`, and sums are formed per fixed
//! block of paths then added in order, so results are bit-identical for any
//! number of threads.
pub mod bilambertian;
pub mod canopy;
pub mod hapke;
pub mod heightfield;
pub mod instanced;
pub mod integrator;
pub mod lambertian;
pub mod material;
pub mod mesh_tracer;
pub mod oren_nayar;
pub mod oren_nayar_full;
pub mod phong;
pub mod specular;
pub mod tracer;

#[cfg(test)]
mod mesh_tests;
#[cfg(test)]
mod tests;

pub use heightfield::{Heightfield, Split};
pub use instanced::InstancedTracer;
pub use integrator::{Estimate, OrderSplit, Scene};
pub use mesh_tracer::MeshTracer;
pub use tracer::{TraceHit, Tracer};

use crate::error::{CoreError, CoreResult};
use glam::DVec3;

/// A direction given as `(azimuth, zenith)` in degrees (azimuth clockwise
/// from north, zenith from the vertical), as a unit vector (east, north,
/// up); it points away from the surface (towards the sun or the sensor).
/// The zenith must lie in [0, 90).
pub fn direction(az_zen: (f64, f64), param: &str) -> CoreResult<DVec3> {
    let (az, zen) = az_zen;
    if !az.is_finite() || !zen.is_finite() {
        return Err(CoreError::invalid(
            param,
            format!("expected finite (azimuth, zenith) in degrees, got ({az}, {zen})"),
        ));
    }
    if !(0.0..90.0).contains(&zen) {
        return Err(CoreError::invalid(
            param,
            format!("zenith must be in [0, 90) degrees (above the horizon), got {zen}"),
        ));
    }
    let (a, z) = (az.to_radians(), zen.to_radians());
    Ok(DVec3::new(a.sin() * z.sin(), a.cos() * z.sin(), z.cos()))
}
