//! The geometry interface of the integrator: anything rays can be cast
//! against ([`super::Heightfield`], [`super::MeshTracer`]).
//!
//! The integrator is generic over [`Tracer`] (monomorphised: no dynamic
//! dispatch per ray), so the heightfield path compiles to the same code as
//! before the trait existed.
use glam::DVec3;

use super::heightfield::{FacetId, Heightfield};

/// The nearest intersection of a ray with a [`Tracer`]'s surface.
#[derive(Debug, Clone, Copy)]
pub struct TraceHit<F> {
    /// Ray parameter of the hit (metres along a unit direction).
    pub t: f64,
    /// Unit geometric normal of the facet hit, facing the incoming ray for
    /// two-sided geometry (meshes), upward for heightfields.
    pub normal: DVec3,
    /// The facet hit.
    pub facet: F,
}

/// A surface of facets that rays are cast against.
///
/// Coordinates are the world frame of the scene (`x` east, `y` north, `z`
/// up, metres). Periodic surfaces repeat a tile with footprint
/// [`Tracer::footprint`]; a ray that leaves one side re-enters the opposite
/// one.
pub trait Tracer: Send + Sync {
    /// Identifies a facet (of the unbounded surface, for periodic ones).
    type Facet: Copy + PartialEq + Send + Sync + std::fmt::Debug;

    /// The first facet hit by `o + t d` (`d` unit) with `t > 0`, ignoring
    /// `skip` (the facet the ray starts on).
    fn trace(&self, o: DVec3, d: DVec3, skip: Option<Self::Facet>)
        -> Option<TraceHit<Self::Facet>>;

    /// True when the ray `o + t d` hits any facet but `skip` (shadow rays).
    #[inline]
    fn occluded(&self, o: DVec3, d: DVec3, skip: Option<Self::Facet>) -> bool {
        self.trace(o, d, skip).is_some()
    }

    /// A hit point (and its facet) moved into the base tile; identity for
    /// non-periodic surfaces.
    fn wrap(&self, p: DVec3, f: Self::Facet) -> (DVec3, Self::Facet);

    /// Index of a facet in the tile's facet list ([`Tracer::facets`]), the
    /// index of its material id.
    fn facet_index(&self, f: Self::Facet) -> usize;

    /// Number of facets of one tile.
    fn facet_count(&self) -> usize;

    /// The sensor's reference area `(x0, y0, width, height)`: `x` in
    /// `[x0, x0 + width]`, `y` in `[y0, y0 + height]` (image row 0 at the
    /// north edge `y0 + height`).
    fn footprint(&self) -> (f64, f64, f64, f64);

    /// `(lowest, highest, reference)` height: sensor rays start above the
    /// highest facet, on the line through a point of the reference plane.
    fn z_range(&self) -> (f64, f64, f64);

    /// Whether the surface repeats periodically.
    fn is_periodic(&self) -> bool;

    /// Whether a ray that escapes going along `d` after scattering leaves
    /// the surface as reflected light (the albedo counts it).
    #[inline]
    fn escapes(&self, d: DVec3) -> bool {
        let _ = d;
        true
    }

    /// Area (square metres) and unit normal of every facet of one tile, in
    /// [`Tracer::facet_index`] order.
    fn facets(&self) -> Vec<(f64, DVec3)>;
}

impl Tracer for Heightfield {
    type Facet = FacetId;

    #[inline(always)]
    fn trace(&self, o: DVec3, d: DVec3, skip: Option<FacetId>) -> Option<TraceHit<FacetId>> {
        self.intersect(o, d, skip).map(|h| TraceHit {
            t: h.t,
            normal: h.normal,
            facet: h.facet,
        })
    }

    #[inline(always)]
    fn wrap(&self, p: DVec3, f: FacetId) -> (DVec3, FacetId) {
        Heightfield::wrap(self, p, f)
    }

    #[inline(always)]
    fn facet_index(&self, f: FacetId) -> usize {
        let c = f.ix.rem_euclid(self.ncc as i64) as usize;
        let r = f.iy.rem_euclid(self.ncr as i64) as usize;
        2 * (r * self.ncc + c) + f.tri as usize
    }

    fn facet_count(&self) -> usize {
        2 * self.ncr * self.ncc
    }

    fn footprint(&self) -> (f64, f64, f64, f64) {
        let (w, h) = self.extent();
        (0.0, -h, w, h)
    }

    #[inline(always)]
    fn z_range(&self) -> (f64, f64, f64) {
        (self.zmin, self.zmax, self.zmean)
    }

    fn is_periodic(&self) -> bool {
        self.periodic
    }

    fn facets(&self) -> Vec<(f64, DVec3)> {
        Heightfield::facets(self)
    }
}
