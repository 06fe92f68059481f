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

/// Per cell: corner heights NW, NE, SW, SE.
type Corners = [f64; 4];

/// A cell's corners on one half cache line: a cell visited costs one load.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(32))]
struct Cell(Corners);

/// A triangulated DEM ready for ray casting.
#[derive(Debug, Clone)]
pub struct Heightfield {
    /// Corner heights of every cell, `ncr x ncc` row-major.
    cells: Vec<Cell>,
    /// Side of a block of the coarse level, in cells (0: no coarse level).
    bside: usize,
    /// Block rows and columns of the coarse level.
    nbr: usize,
    nbc: usize,
    /// Highest corner of every block plus the traversal tolerance.
    bmax: Vec<f64>,
    /// Cell rows.
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
    /// Height tolerance of the culling tests (metres).
    zeps: f64,
    /// The largest squared gradient of a facet in grid coordinates,
    /// `b^2 + c^2` of its plane `z = a + b fx + c fy` (a Lipschitz bound of
    /// the surface: see [`Heightfield::escapes`]).
    grad2: f64,
}

/// Upper bound on cells visited by one ray (guards near-horizontal rays in
/// a periodic scene; such a ray is then treated as escaping when it does
/// not go down, as lost otherwise).
const MAX_STEPS: usize = 1 << 22;

/// Tolerance of the point-in-facet test, in cell units.
const EDGE_EPS: f64 = 1e-12;

/// Grids with at least this many cells get the coarse (block) level.
const BLOCK_MIN_CELLS: usize = 96 * 96;

/// Rays per parallel task of the batch casts.
const RAY_CHUNK: usize = 4096;

/// Ray `k` of flat origin and direction slices.
#[inline(always)]
fn ray_at(origins: &[f64], dirs: &[f64], k: usize) -> (DVec3, DVec3) {
    let (o, d) = (&origins[3 * k..3 * k + 3], &dirs[3 * k..3 * k + 3]);
    (DVec3::new(o[0], o[1], o[2]), DVec3::new(d[0], d[1], d[2]))
}

/// `floor(v)` as an integer (no libm call on baseline x86-64).
#[inline(always)]
fn ifloor(v: f64) -> i64 {
    let i = v as i64;
    if (i as f64) > v {
        i - 1
    } else {
        i
    }
}

/// The larger of two finite values (one `maxsd`: no NaN handling).
#[inline(always)]
fn fmax(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// The smaller of two finite values.
#[inline(always)]
fn fmin(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// `i` modulo `n` in `0..n` (the division only when `i` is outside).
#[inline(always)]
fn wrap_index(i: i64, n: usize) -> usize {
    if (i as u64) < n as u64 {
        i as usize
    } else {
        i.rem_euclid(n as i64) as usize
    }
}

/// A ray in grid coordinates with its stepping constants.
struct GridRay {
    o: DVec3,
    d: DVec3,
    skip: Option<FacetId>,
    t_max: f64,
    sx: i64,
    sy: i64,
    /// `1 / |d.x|`, `1 / |d.y|` (infinite for 0).
    idx: f64,
    idy: f64,
}

impl GridRay {
    /// Ray parameter where the ray crosses the grid line `x = k` (`y = k`).
    #[inline(always)]
    fn cross_x(&self, k: i64) -> f64 {
        if self.d.x == 0.0 {
            f64::INFINITY
        } else {
            (k as f64 - self.o.x) / self.d.x
        }
    }
    #[inline(always)]
    fn cross_y(&self, k: i64) -> f64 {
        if self.d.y == 0.0 {
            f64::INFINITY
        } else {
            (k as f64 - self.o.y) / self.d.y
        }
    }
}

/// Outcome of walking the cells of one block.
enum Walk {
    /// A facet hit: `t`, the facet and its plane slopes `(b, c)`.
    Hit(f64, FacetId, f64, f64),
    /// The ray is done (escaped, lost, left the patch or passed `t_max`).
    Stop,
    /// The ray left the block.
    Next,
}

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
        // the sample after the last row (column) is the first (periodic)
        let next = |i: usize, n: usize| if i + 1 == n { 0 } else { i + 1 };
        let mut cells: Vec<Cell> = crate::buffers::try_with_capacity(ncr * ncc, "dem")?;
        let (mut zmin, mut zmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for r in 0..ncr {
            let (top, bottom) = (
                &z[r * cols..(r + 1) * cols],
                &z[next(r, rows) * cols..][..cols],
            );
            for c in 0..ncc {
                let c1 = next(c, cols);
                let cd = [top[c], top[c1], bottom[c], bottom[c1]];
                zmin = fmin(zmin, fmin(fmin(cd[0], cd[1]), fmin(cd[2], cd[3])));
                zmax = fmax(zmax, fmax(fmax(cd[0], cd[1]), fmax(cd[2], cd[3])));
                cells.push(Cell(cd));
            }
        }
        // absolute tolerance of the culling tests: far above the rounding
        // of `o.z + t d.z` at these heights
        let zeps = 1e-9 * (1.0 + zmin.abs().max(zmax.abs()));
        let zmean = z.iter().sum::<f64>() / z.len() as f64;
        let mut hf = Heightfield {
            cells,
            bside: 0,
            nbr: 0,
            nbc: 0,
            bmax: Vec::new(),
            ncr,
            ncc,
            periodic,
            split,
            dx,
            dy,
            zmin,
            zmax,
            zmean,
            zeps,
            grad2: 0.0,
        };
        hf.grad2 = hf
            .cells
            .iter()
            .flat_map(|cell| [hf.plane(&cell.0, 0), hf.plane(&cell.0, 1)])
            .map(|(_, b, c)| b * b + c * c)
            .fold(0.0, fmax);
        if ncr * ncc >= BLOCK_MIN_CELLS {
            // periodic: blocks must tile the period
            let side = [16usize, 8, 4]
                .into_iter()
                .find(|b| !periodic || (ncr % b == 0 && ncc % b == 0));
            if let Some(b) = side {
                hf.set_block_side(b);
            }
        }
        Ok(hf)
    }

    /// Build the coarse level with blocks of `b x b` cells (0: none).
    /// Periodic grids need `b` to divide both sides; otherwise no coarse level
    /// is built. The results of ray casting do not depend on it.
    pub fn set_block_side(&mut self, b: usize) {
        if b == 0 || (self.periodic && (self.ncr % b != 0 || self.ncc % b != 0)) {
            self.bside = 0;
            self.bmax = Vec::new();
            return;
        }
        let (nbr, nbc) = (self.ncr.div_ceil(b), self.ncc.div_ceil(b));
        let mut bmax = vec![f64::NEG_INFINITY; nbr * nbc];
        for r in 0..self.ncr {
            for c in 0..self.ncc {
                let m = &mut bmax[(r / b) * nbc + c / b];
                let [a, b, c, d] = self.cells[r * self.ncc + c].0;
                *m = m.max(a.max(b).max(c).max(d) + self.zeps);
            }
        }
        self.bside = b;
        self.nbr = nbr;
        self.nbc = nbc;
        self.bmax = bmax;
    }

    /// Corner heights (NW, NE, SW, SE) of the cell at wrapped indices.
    #[inline(always)]
    fn corners(&self, cx: usize, cy: usize) -> Corners {
        self.cells[cy * self.ncc + cx].0
    }

    #[inline(always)]
    fn cell(&self, ix: i64, iy: i64) -> Corners {
        self.corners(wrap_index(ix, self.ncc), wrap_index(iy, self.ncr))
    }

    /// The plane of facet `tri` of a cell as `z = a + b fx + c fy` in the
    /// cell's coordinates `fx, fy` in [0, 1], and the facet's region test.
    #[inline(always)]
    fn plane(&self, cd: &Corners, tri: u8) -> (f64, f64, f64) {
        let [nw, ne, sw, se] = *cd;
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
        let (_, b, c) = self.plane(&self.cell(f.ix, f.iy), f.tri);
        self.normal_of(b, c).normalize()
    }

    /// Area (square metres) and unit normal of every facet of one tile, in
    /// the order (row, column, facet).
    pub fn facets(&self) -> Vec<(f64, DVec3)> {
        let mut out = Vec::with_capacity(2 * self.ncr * self.ncc);
        for iy in 0..self.ncr {
            for ix in 0..self.ncc {
                for tri in 0..2u8 {
                    let (_, b, c) = self.plane(&self.corners(ix, iy), tri);
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
        let (ncc, ncr) = (self.ncc as i64, self.ncr as i64);
        if (0..ncc).contains(&f.ix) && (0..ncr).contains(&f.iy) {
            return (p, f);
        }
        let kx = f.ix.div_euclid(ncc);
        let ky = f.iy.div_euclid(ncr);
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
        match self.trace::<false>(o, d, skip, f64::INFINITY) {
            Walk::Hit(t, facet, b, c) => Some(Hit {
                t,
                normal: self.normal_of(b, c).normalize(),
                facet,
            }),
            _ => None,
        }
    }

    /// Whether the ray `o + t d` (world frame, `d` a unit vector) hits a
    /// facet other than `skip` at some `0 < t <= t_max`: the shadow-ray test,
    /// which stops at the first facet found. `occluded(o, d, skip, inf)` is
    /// `intersect(o, d, skip).is_some()`.
    pub fn occluded(&self, o: DVec3, d: DVec3, skip: Option<FacetId>, t_max: f64) -> bool {
        matches!(self.trace::<true>(o, d, skip, t_max), Walk::Hit(..))
    }

    /// Index of a facet of the base tile, `2 (iy ncc + ix) + tri`, after
    /// moving it into the base tile (periodic).
    pub fn facet_index(&self, f: FacetId) -> i64 {
        let ix = wrap_index(f.ix, self.ncc);
        let iy = wrap_index(f.iy, self.ncr);
        (2 * (iy * self.ncc + ix)) as i64 + f.tri as i64
    }

    /// The facet of index `k` ([`Heightfield::facet_index`]); `None` for a
    /// negative or out-of-range index.
    pub fn facet_at(&self, k: i64) -> Option<FacetId> {
        let n = 2 * (self.ncr * self.ncc) as i64;
        (0..n).contains(&k).then(|| {
            let cell = k / 2;
            FacetId {
                ix: cell % self.ncc as i64,
                iy: cell / self.ncc as i64,
                tri: (k % 2) as u8,
            }
        })
    }

    /// [`Heightfield::intersect`] of many rays in parallel (rayon): origins
    /// and unit directions as flat `[x, y, z, x, y, z, ...]` slices, the
    /// facet index each ray ignores (negative or `None`: none). Returns per
    /// ray `t` (infinite for a miss), the facet index hit (-1 for a miss)
    /// and the unit normal as a flat slice (zero for a miss).
    pub fn intersect_many(
        &self,
        origins: &[f64],
        dirs: &[f64],
        skip: Option<&[i64]>,
    ) -> (Vec<f64>, Vec<i64>, Vec<f64>) {
        use rayon::prelude::*;
        let n = origins.len() / 3;
        let (mut t, mut f, mut nrm) = (vec![0.0; n], vec![0i64; n], vec![0.0; 3 * n]);
        t.par_chunks_mut(RAY_CHUNK)
            .zip(f.par_chunks_mut(RAY_CHUNK))
            .zip(nrm.par_chunks_mut(3 * RAY_CHUNK))
            .enumerate()
            .for_each(|(c, ((t, f), nrm))| {
                for (i, ((t, f), nrm)) in
                    t.iter_mut().zip(f).zip(nrm.chunks_exact_mut(3)).enumerate()
                {
                    let k = c * RAY_CHUNK + i;
                    let (o, d) = ray_at(origins, dirs, k);
                    let sk = skip.and_then(|s| self.facet_at(s[k]));
                    match self.intersect(o, d, sk) {
                        Some(h) => {
                            *t = h.t;
                            *f = self.facet_index(h.facet);
                            nrm.copy_from_slice(&h.normal.to_array());
                        }
                        None => {
                            *t = f64::INFINITY;
                            *f = -1;
                        }
                    }
                }
            });
        (t, f, nrm)
    }

    /// [`Heightfield::occluded`] of many rays in parallel (rayon), with no
    /// distance limit; arguments as in [`Heightfield::intersect_many`].
    pub fn occluded_many(&self, origins: &[f64], dirs: &[f64], skip: Option<&[i64]>) -> Vec<bool> {
        use rayon::prelude::*;
        let mut out = vec![false; origins.len() / 3];
        out.par_chunks_mut(RAY_CHUNK)
            .enumerate()
            .for_each(|(c, out)| {
                for (i, v) in out.iter_mut().enumerate() {
                    let k = c * RAY_CHUNK + i;
                    let (o, d) = ray_at(origins, dirs, k);
                    *v = self.occluded(o, d, skip.and_then(|s| self.facet_at(s[k])), f64::INFINITY);
                }
            });
        out
    }

    /// The traversal: clip (non-periodic), then walk the blocks of the
    /// coarse level, and the cells of every block the ray may touch; without
    /// a coarse level, walk the cells directly. `ANY`: stop at the first hit.
    #[inline(always)]
    fn trace<const ANY: bool>(
        &self,
        o: DVec3,
        d: DVec3,
        skip: Option<FacetId>,
        t_max: f64,
    ) -> Walk {
        // grid coordinates: the same t
        let o = DVec3::new(o.x / self.dx, -o.y / self.dy, o.z);
        let d = DVec3::new(d.x / self.dx, -d.y / self.dy, d.z);
        if d.z > 0.0 && self.escapes(o, d) {
            return Walk::Stop;
        }
        let mut t_start = 0.0f64;
        if !self.periodic {
            // clip to the patch's footprint [0, ncc] x [0, ncr]
            let (w, h) = (self.ncc as f64, self.ncr as f64);
            let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
            for (oa, da, hi) in [(o.x, d.x, w), (o.y, d.y, h)] {
                if da == 0.0 {
                    if oa < 0.0 || oa > hi {
                        return Walk::Stop;
                    }
                } else {
                    let (a, b) = ((0.0 - oa) / da, (hi - oa) / da);
                    t0 = t0.max(a.min(b));
                    t1 = t1.min(a.max(b));
                }
            }
            if t0 > t1 {
                return Walk::Stop;
            }
            t_start = t0;
        }
        let ray = GridRay {
            o,
            d,
            skip,
            t_max,
            sx: if d.x > 0.0 { 1 } else { -1 },
            sy: if d.y > 0.0 { 1 } else { -1 },
            idx: if d.x == 0.0 {
                f64::INFINITY
            } else {
                1.0 / d.x.abs()
            },
            idy: if d.y == 0.0 {
                f64::INFINITY
            } else {
                1.0 / d.y.abs()
            },
        };
        if d.x == 0.0 && d.y == 0.0 {
            // a vertical ray meets only the cell under its origin
            let (mut ix, mut iy) = (ifloor(o.x), ifloor(o.y));
            if !self.periodic {
                ix = ix.clamp(0, self.ncc as i64 - 1);
                iy = iy.clamp(0, self.ncr as i64 - 1);
            }
            return match self.test_cell::<ANY>(&ray, ix, iy, &self.cell(ix, iy)) {
                Some((t, tri, b, c)) => Walk::Hit(t, FacetId { ix, iy, tri }, b, c),
                None => Walk::Stop,
            };
        }
        let mut steps = 0usize;
        if self.bside == 0 {
            let (lo, hi) = if self.periodic {
                ((i64::MIN, i64::MIN), (i64::MAX, i64::MAX))
            } else {
                ((0, 0), (self.ncc as i64 - 1, self.ncr as i64 - 1))
            };
            return match self.walk_cells::<ANY>(&ray, t_start, lo, hi, self.zmax, &mut steps) {
                Walk::Next => Walk::Stop,
                w => w,
            };
        }
        // the coarse level: blocks of bs x bs cells
        let bs = self.bside as i64;
        let (nbc, nbr) = (self.nbc as i64, self.nbr as i64);
        let p = o + t_start * d;
        let mut bx = ifloor(p.x / bs as f64);
        let mut by = ifloor(p.y / bs as f64);
        if !self.periodic {
            bx = bx.clamp(0, nbc - 1);
            by = by.clamp(0, nbr - 1);
        }
        let mut bxw = wrap_index(bx, self.nbc);
        let mut byw = wrap_index(by, self.nbr);
        let mut tmx = ray.cross_x((bx + (d.x > 0.0) as i64) * bs);
        let mut tmy = ray.cross_y((by + (d.y > 0.0) as i64) * bs);
        let (dtx, dty) = (bs as f64 * ray.idx, bs as f64 * ray.idy);
        let mut t_enter = t_start;
        let mut z_enter = o.z + t_start * d.z;
        loop {
            let t_exit = tmx.min(tmy);
            let z_exit = o.z + t_exit * d.z;
            let cap = self.bmax[byw * self.nbc + bxw];
            if fmin(z_enter, z_exit) <= cap {
                let lo = (bx * bs, by * bs);
                let mut hi = (lo.0 + bs - 1, lo.1 + bs - 1);
                if !self.periodic {
                    hi = (hi.0.min(self.ncc as i64 - 1), hi.1.min(self.ncr as i64 - 1));
                }
                match self.walk_cells::<ANY>(&ray, t_enter, lo, hi, cap, &mut steps) {
                    Walk::Next => {}
                    w => return w,
                }
            }
            if (d.z >= 0.0 && z_exit > self.zmax)
                || (d.z < 0.0 && z_enter < self.zmin - self.zeps)
                || t_exit > t_max
            {
                return Walk::Stop;
            }
            if tmx < tmy {
                bx += ray.sx;
                tmx += dtx;
                bxw = if ray.sx > 0 {
                    if bxw + 1 == self.nbc {
                        0
                    } else {
                        bxw + 1
                    }
                } else if bxw == 0 {
                    self.nbc - 1
                } else {
                    bxw - 1
                };
                if !self.periodic && (bx < 0 || bx >= nbc) {
                    return Walk::Stop;
                }
            } else {
                by += ray.sy;
                tmy += dty;
                byw = if ray.sy > 0 {
                    if byw + 1 == self.nbr {
                        0
                    } else {
                        byw + 1
                    }
                } else if byw == 0 {
                    self.nbr - 1
                } else {
                    byw - 1
                };
                if !self.periodic && (by < 0 || by >= nbr) {
                    return Walk::Stop;
                }
            }
            steps += 1;
            if steps > MAX_STEPS {
                return Walk::Stop;
            }
            t_enter = t_exit;
            z_enter = z_exit;
        }
    }

    /// Whether the upward ray `o + t d` (grid coordinates, `d.z > 0`) can
    /// meet no facet: it rises faster than any facet and starts on or above
    /// the surface. The surface is continuous and piecewise linear, so
    /// between two points of the plane it rises by at most `sqrt(grad2)` per
    /// unit of horizontal distance (grid coordinates) and stays below such a
    /// ray. One cell lookup: rays leaving the surface steeper than its
    /// steepest facet skip the traversal.
    #[inline(always)]
    fn escapes(&self, o: DVec3, d: DVec3) -> bool {
        let h2 = d.x * d.x + d.y * d.y;
        if d.z * d.z <= self.grad2 * h2 * (1.0 + 1e-9) {
            return false;
        }
        let (ix, iy) = (ifloor(o.x), ifloor(o.y));
        if !self.periodic && (ix < 0 || iy < 0 || ix >= self.ncc as i64 || iy >= self.ncr as i64) {
            return false;
        }
        let (fx, fy) = (o.x - ix as f64, o.y - iy as f64);
        let tri = match self.split {
            Split::NeSw => u8::from(fx + fy > 1.0),
            Split::NwSe => u8::from(fy > fx),
        };
        let (a, b, c) = self.plane(&self.cell(ix, iy), tri);
        o.z >= a + b * fx + c * fy - self.zeps
    }

    /// Walk the cells from ray parameter `t0` while the cell indices stay
    /// within `lo..=hi` (a block, or the patch), testing the facets of every
    /// cell whose highest corner the ray segment does not pass above; a
    /// rising ray leaves as soon as it is above `cap`, the highest corner of
    /// the block (it can meet nothing more there).
    #[inline(always)]
    fn walk_cells<const ANY: bool>(
        &self,
        ray: &GridRay,
        t0: f64,
        lo: (i64, i64),
        hi: (i64, i64),
        cap: f64,
        steps: &mut usize,
    ) -> Walk {
        let (o, d) = (ray.o, ray.d);
        let p = o + t0 * d;
        let mut ix = ifloor(p.x).clamp(lo.0, hi.0);
        let mut iy = ifloor(p.y).clamp(lo.1, hi.1);
        let (ncc, ncr) = (self.ncc, self.ncr);
        let mut cx = wrap_index(ix, ncc);
        let mut cy = wrap_index(iy, ncr);
        let mut tmx = ray.cross_x(ix + (d.x > 0.0) as i64);
        let mut tmy = ray.cross_y(iy + (d.y > 0.0) as i64);
        let mut z_enter = o.z + t0 * d.z;
        loop {
            let t_exit = tmx.min(tmy);
            let z_exit = o.z + t_exit * d.z;
            let cd = self.corners(cx, cy);
            if fmin(z_enter, z_exit) <= fmax(fmax(cd[0], cd[1]), fmax(cd[2], cd[3])) + self.zeps {
                if let Some((t, tri, b, c)) = self.test_cell::<ANY>(ray, ix, iy, &cd) {
                    return Walk::Hit(t, FacetId { ix, iy, tri }, b, c);
                }
            }
            // leave the slab of the surface: above it going up, or below it
            // (a ray that slipped through; counted as lost)
            if (d.z >= 0.0 && z_exit > self.zmax)
                || (d.z < 0.0 && z_enter < self.zmin - self.zeps)
                || t_exit > ray.t_max
            {
                return Walk::Stop;
            }
            if d.z >= 0.0 && z_exit > cap {
                return Walk::Next; // above the block for the rest of it
            }
            *steps += 1;
            if *steps > MAX_STEPS {
                return Walk::Stop;
            }
            if tmx < tmy {
                ix += ray.sx;
                tmx += ray.idx;
                if ix < lo.0 || ix > hi.0 {
                    return Walk::Next;
                }
                cx = if ray.sx > 0 {
                    if cx + 1 == ncc {
                        0
                    } else {
                        cx + 1
                    }
                } else if cx == 0 {
                    ncc - 1
                } else {
                    cx - 1
                };
            } else {
                iy += ray.sy;
                tmy += ray.idy;
                if iy < lo.1 || iy > hi.1 {
                    return Walk::Next;
                }
                cy = if ray.sy > 0 {
                    if cy + 1 == ncr {
                        0
                    } else {
                        cy + 1
                    }
                } else if cy == 0 {
                    ncr - 1
                } else {
                    cy - 1
                };
            }
            z_enter = z_exit;
        }
    }

    /// The nearest hit (`ANY`: the first found) of the ray with the two
    /// facets of cell `(ix, iy)` with corners `cd`: `(t, facet, b, c)`.
    #[inline(always)]
    fn test_cell<const ANY: bool>(
        &self,
        ray: &GridRay,
        ix: i64,
        iy: i64,
        cd: &Corners,
    ) -> Option<(f64, u8, f64, f64)> {
        let (o, d) = (ray.o, ray.d);
        let fx0 = o.x - ix as f64;
        let fy0 = o.y - iy as f64;
        let mut best: Option<(f64, u8, f64, f64)> = None;
        for tri in 0..2u8 {
            if ray.skip == Some(FacetId { ix, iy, tri }) {
                continue;
            }
            let (a, b, c) = self.plane(cd, tri);
            let denom = d.z - b * d.x - c * d.y;
            if denom == 0.0 {
                continue;
            }
            let t = (a + b * fx0 + c * fy0 - o.z) / denom;
            if t.is_nan() || t <= 1e-10 || t > ray.t_max || best.is_some_and(|h| h.0 <= t) {
                continue;
            }
            let (fx, fy) = (fx0 + t * d.x, fy0 + t * d.y);
            if self.inside(tri, fx, fy) {
                best = Some((t, tri, b, c));
                if ANY {
                    return best;
                }
            }
        }
        best
    }
}
