//! A DEM as a triangulated heightfield and its ray caster.
//!
//! The grid is traversed cell by cell (Amanatides & Woo 1987) and each cell's
//! two facets are intersected exactly (ray against the facet's plane, then
//! the point-in-triangle test in the cell's own coordinates). Periodic
//! heightfields are one tile of an infinite surface: cell indices are kept
//! unbounded and heights are looked up modulo the tile, so a ray that leaves
//! one side re-enters the opposite one with no special case. Non-periodic
//! rays are clipped to the patch and escape when they leave it.
//!
//! Rays, points and normals are in the world frame (`x` east, `y` north,
//! `z` up, metres): vertex `(r, c)` sits at `(c dx, -r dy, z[r, c])`. Inside
//! [`Heightfield::intersect`] the ray is mapped linearly to grid coordinates
//! (`X = x / dx` = column, `Y = -y / dy` = row, `z` kept), which leaves the
//! ray parameter `t` unchanged, so cells may be rectangular.
use glam::DVec3;

use crate::error::{CoreError, CoreResult};

/// Which diagonal splits each cell into two facets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Split {
    /// The diagonal from the north-east to the south-west corner: facets
    /// (NW, NE, SW) and (NE, SE, SW).
    NeSw,
    /// The diagonal from the north-west to the south-east corner: facets
    /// (NW, NE, SE) and (NW, SE, SW).
    NwSe,
}

/// Identifies one facet of the unbounded (periodically repeated) surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FacetId {
    /// Column of the cell (unbounded for periodic surfaces).
    pub ix: i64,
    /// Row of the cell (unbounded for periodic surfaces).
    pub iy: i64,
    /// 0 or 1: the facet within the cell (see [`Split`]).
    pub tri: u8,
}

/// The nearest intersection of a ray with the surface.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Ray parameter of the hit (grid units along a unit direction).
    pub t: f64,
    /// Unit upward normal of the facet hit (grid frame).
    pub normal: DVec3,
    /// The facet hit.
    pub facet: FacetId,
}

/// Per cell: corner heights NW, NE, SW, SE, then the lowest and highest.
type CellData = [f64; 6];

/// A triangulated DEM ready for ray casting.
#[derive(Debug, Clone)]
pub struct Heightfield {
    cells: Vec<CellData>,
    /// Cell rows and columns.
    pub ncr: usize,
    /// Cell columns.
    pub ncc: usize,
    /// Whether the patch repeats periodically.
    pub periodic: bool,
    /// The diagonal split.
    pub split: Split,
    /// Cell size east-west (metres).
    pub dx: f64,
    /// Cell size north-south (metres).
    pub dy: f64,
    /// Lowest height (metres).
    pub zmin: f64,
    /// Highest height (metres).
    pub zmax: f64,
    /// Mean vertex height (metres): the reference plane of the sensor.
    pub zmean: f64,
}

/// Upper bound on cells visited by one ray (guards near-horizontal rays in
/// a periodic scene; such a ray is then treated as escaping when it does
/// not go down, as lost otherwise).
const MAX_STEPS: usize = 1 << 22;

/// Tolerance of the point-in-facet test, in cell units.
const EDGE_EPS: f64 = 1e-12;

impl Heightfield {
    /// Build from heights `z` (row-major, `rows x cols`, metres) with cells
    /// of `cell_size = (dx, dy)` metres (east-west, north-south).
    ///
    /// Periodic: the grid is one period, `rows x cols` cells, and the
    /// sample after the last column (row) is the first column (row).
    /// Non-periodic: `(rows - 1) x (cols - 1)` cells.
    pub fn new(
        z: &[f64],
        rows: usize,
        cols: usize,
        cell_size: (f64, f64),
        periodic: bool,
        split: Split,
    ) -> CoreResult<Heightfield> {
        let (dx, dy) = cell_size;
        crate::checks::positive_finite(dx, "cell_size")?;
        crate::checks::positive_finite(dy, "cell_size")?;
        if z.len() != rows * cols {
            return Err(CoreError::Internal(format!(
                "heightfield: {} heights for a {rows} x {cols} grid",
                z.len()
            )));
        }
        let min_side = if periodic { 1 } else { 2 };
        if rows < min_side || cols < min_side {
            return Err(CoreError::invalid(
                "dem",
                format!(
                    "expected at least {min_side} x {min_side} heights{}, got {rows} x {cols}",
                    if periodic {
                        ""
                    } else {
                        " for a non-periodic scene"
                    }
                ),
            ));
        }
        if let Some(i) = z.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::invalid(
                "dem",
                format!(
                    "expected finite heights, got {} at row {}, column {}",
                    z[i],
                    i / cols,
                    i % cols
                ),
            ));
        }
        let (ncr, ncc) = if periodic {
            (rows, cols)
        } else {
            (rows - 1, cols - 1)
        };
        let h = |r: usize, c: usize| z[(r % rows) * cols + (c % cols)];
        let mut cells: Vec<CellData> = crate::buffers::try_with_capacity(ncr * ncc, "dem")?;
        let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for r in 0..ncr {
            for c in 0..ncc {
                let (nw, ne, sw, se) = (h(r, c), h(r, c + 1), h(r + 1, c), h(r + 1, c + 1));
                let lo = nw.min(ne).min(sw).min(se);
                let hi = nw.max(ne).max(sw).max(se);
                zmin = zmin.min(lo);
                zmax = zmax.max(hi);
                cells.push([nw, ne, sw, se, lo, hi]);
            }
        }
        let zmean = z.iter().sum::<f64>() / z.len() as f64;
        Ok(Heightfield {
            cells,
            ncr,
            ncc,
            periodic,
            split,
            dx,
            dy,
            zmin,
            zmax,
            zmean,
        })
    }

    #[inline(always)]
    fn cell(&self, ix: i64, iy: i64) -> &CellData {
        let c = ix.rem_euclid(self.ncc as i64) as usize;
        let r = iy.rem_euclid(self.ncr as i64) as usize;
        &self.cells[r * self.ncc + c]
    }

    /// The plane of facet `tri` of a cell as `z = a + b fx + c fy` in the
    /// cell's coordinates `fx, fy` in [0, 1], and the facet's region test.
    #[inline(always)]
    fn plane(&self, cd: &CellData, tri: u8) -> (f64, f64, f64) {
        let [nw, ne, sw, se, _, _] = *cd;
        match (self.split, tri) {
            // (NW, NE, SW): fx + fy <= 1
            (Split::NeSw, 0) => (nw, ne - nw, sw - nw),
            // (NE, SE, SW): fx + fy >= 1; z = ne + sw - se + (se - sw) fx + (se - ne) fy
            (Split::NeSw, _) => (ne + sw - se, se - sw, se - ne),
            // (NW, NE, SE): fy <= fx
            (Split::NwSe, 0) => (nw, ne - nw, se - ne),
            // (NW, SE, SW): fy >= fx
            (_, _) => (nw, se - sw, sw - nw),
        }
    }

    #[inline(always)]
    fn inside(&self, tri: u8, fx: f64, fy: f64) -> bool {
        let r = -EDGE_EPS..=1.0 + EDGE_EPS;
        let box_ok = r.contains(&fx) && r.contains(&fy);
        box_ok
            && match (self.split, tri) {
                (Split::NeSw, 0) => fx + fy <= 1.0 + EDGE_EPS,
                (Split::NeSw, _) => fx + fy >= 1.0 - EDGE_EPS,
                (Split::NwSe, 0) => fy <= fx + EDGE_EPS,
                (_, _) => fy >= fx - EDGE_EPS,
            }
    }

    /// Upward normal (not unit) of the plane `z = a + b fx + c fy` in the
    /// world frame: `dz/dx = b / dx`, `dz/dy = -c / dy`.
    #[inline(always)]
    fn normal_of(&self, b: f64, c: f64) -> DVec3 {
        DVec3::new(-b / self.dx, c / self.dy, 1.0)
    }

    /// Unit upward normal of a facet (world frame).
    pub fn facet_normal(&self, f: FacetId) -> DVec3 {
        let (_, b, c) = self.plane(self.cell(f.ix, f.iy), f.tri);
        self.normal_of(b, c).normalize()
    }

    /// Area (square metres) and unit normal of every facet of one tile, in
    /// the order (row, column, facet).
    pub fn facets(&self) -> Vec<(f64, DVec3)> {
        let mut out = Vec::with_capacity(2 * self.ncr * self.ncc);
        for iy in 0..self.ncr as i64 {
            for ix in 0..self.ncc as i64 {
                for tri in 0..2u8 {
                    let (_, b, c) = self.plane(self.cell(ix, iy), tri);
                    let n = self.normal_of(b, c);
                    // a facet projects onto half a cell: area = 0.5 dx dy / nz
                    out.push((0.5 * self.dx * self.dy * n.length(), n.normalize()));
                }
            }
        }
        out
    }

    /// Tile size in metres (east-west, north-south); the tile covers
    /// `x` in [0, W] and `y` in [-H, 0].
    pub fn extent(&self) -> (f64, f64) {
        (self.ncc as f64 * self.dx, self.ncr as f64 * self.dy)
    }

    /// Move a point of a periodic surface (and the facet it lies on) into
    /// the base tile; no-op for non-periodic surfaces.
    pub fn wrap(&self, p: DVec3, f: FacetId) -> (DVec3, FacetId) {
        if !self.periodic {
            return (p, f);
        }
        let kx = f.ix.div_euclid(self.ncc as i64);
        let ky = f.iy.div_euclid(self.ncr as i64);
        (
            DVec3::new(
                p.x - (kx * self.ncc as i64) as f64 * self.dx,
                p.y + (ky * self.ncr as i64) as f64 * self.dy,
                p.z,
            ),
            FacetId {
                ix: f.ix - kx * self.ncc as i64,
                iy: f.iy - ky * self.ncr as i64,
                tri: f.tri,
            },
        )
    }

    /// The first facet hit by the ray `o + t d` (world frame, `d` a unit
    /// vector) with `t > 0`, ignoring facet `skip` (the one the ray starts on).
    pub fn intersect(&self, o: DVec3, d: DVec3, skip: Option<FacetId>) -> Option<Hit> {
        // grid coordinates: the same t
        let o = DVec3::new(o.x / self.dx, -o.y / self.dy, o.z);
        let d = DVec3::new(d.x / self.dx, -d.y / self.dy, d.z);
        let mut t_start = 0.0f64;
        if !self.periodic {
            // clip to the patch's footprint [0, ncc] x [0, ncr]
            let (w, h) = (self.ncc as f64, self.ncr as f64);
            let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
            for (oa, da, hi) in [(o.x, d.x, w), (o.y, d.y, h)] {
                if da == 0.0 {
                    if oa < 0.0 || oa > hi {
                        return None;
                    }
                } else {
                    let (a, b) = ((0.0 - oa) / da, (hi - oa) / da);
                    t0 = t0.max(a.min(b));
                    t1 = t1.min(a.max(b));
                }
            }
            if t0 > t1 {
                return None;
            }
            t_start = t0;
        }
        let p = o + t_start * d;
        let mut ix = p.x.floor() as i64;
        let mut iy = p.y.floor() as i64;
        if !self.periodic {
            ix = ix.clamp(0, self.ncc as i64 - 1);
            iy = iy.clamp(0, self.ncr as i64 - 1);
        }
        let (sx, sy) = (
            if d.x > 0.0 { 1 } else { -1 },
            if d.y > 0.0 { 1 } else { -1 },
        );
        let next_x = |ix: i64| -> f64 {
            if d.x == 0.0 {
                f64::INFINITY
            } else {
                ((ix + (d.x > 0.0) as i64) as f64 - o.x) / d.x
            }
        };
        let next_y = |iy: i64| -> f64 {
            if d.y == 0.0 {
                f64::INFINITY
            } else {
                ((iy + (d.y > 0.0) as i64) as f64 - o.y) / d.y
            }
        };
        let dtx = if d.x == 0.0 {
            f64::INFINITY
        } else {
            1.0 / d.x.abs()
        };
        let dty = if d.y == 0.0 {
            f64::INFINITY
        } else {
            1.0 / d.y.abs()
        };
        let mut tmx = next_x(ix);
        let mut tmy = next_y(iy);
        let mut t_enter = t_start;
        for _ in 0..MAX_STEPS {
            let t_exit = tmx.min(tmy);
            let z_enter = o.z + t_enter * d.z;
            let z_exit = if t_exit.is_finite() {
                o.z + t_exit * d.z
            } else if d.z < 0.0 {
                f64::NEG_INFINITY
            } else if d.z > 0.0 {
                f64::INFINITY
            } else {
                o.z
            };
            let cd = self.cell(ix, iy);
            if z_enter.min(z_exit) <= cd[5] + 1e-9 {
                let mut best: Option<Hit> = None;
                for tri in 0..2u8 {
                    let id = FacetId { ix, iy, tri };
                    if skip == Some(id) {
                        continue;
                    }
                    let (a, b, c) = self.plane(cd, tri);
                    let fx0 = o.x - ix as f64;
                    let fy0 = o.y - iy as f64;
                    let denom = d.z - b * d.x - c * d.y;
                    if denom == 0.0 {
                        continue;
                    }
                    let t = (a + b * fx0 + c * fy0 - o.z) / denom;
                    if t.is_nan() || t <= 1e-10 || best.is_some_and(|h| h.t <= t) {
                        continue;
                    }
                    let (fx, fy) = (fx0 + t * d.x, fy0 + t * d.y);
                    if self.inside(tri, fx, fy) {
                        best = Some(Hit {
                            t,
                            normal: self.normal_of(b, c).normalize(),
                            facet: id,
                        });
                    }
                }
                if best.is_some() {
                    return best;
                }
            }
            // leave the slab of the surface: above it going up, or below it
            // (a ray that slipped through; counted as lost)
            if (d.z >= 0.0 && z_exit > self.zmax) || (d.z < 0.0 && z_enter < self.zmin - 1e-9) {
                return None;
            }
            if !t_exit.is_finite() {
                return None;
            }
            if tmx < tmy {
                ix += sx;
                tmx += dtx;
            } else {
                iy += sy;
                tmy += dty;
            }
            if !self.periodic
                && (ix < 0 || iy < 0 || ix >= self.ncc as i64 || iy >= self.ncr as i64)
            {
                return None;
            }
            t_enter = t_exit;
        }
        None
    }
}
