//! Error-bounded terrain meshes of a raster by greedy insertion
//! (Garland and Heckbert 1995, "Fast polygonal approximation of terrains and
//! height fields", CMU-CS-95-181; the same scheme as Delatin).
//!
//! Samples sit at integer grid positions `(col, row)`. The mesh starts from
//! the convex hull of the valid samples (the four corners of a raster
//! without nodata) and, with shared tile edges, from a 1D greedy
//! simplification of every raster edge. Each triangle keeps the sample of
//! largest vertical error `|z - plane|` inside it (found by rasterising the
//! triangle with exact integer edge functions); a priority queue pops the
//! worst triangle, its sample is inserted into the Delaunay triangulation
//! (spade, with the face's vertex as the location hint) and only the
//! triangles around the new vertex are rasterised again: a Delaunay
//! insertion changes no other triangle. Refinement stops when every valid
//! sample is within `max_error` of the mesh or the triangle budget is spent.
//!
//! Nodata samples (NaN) are never inserted. A triangle that covers a nodata
//! sample is refined first (any valid sample inside it is inserted) and is
//! left out of the result when it has no valid sample left to insert, so
//! nodata regions become holes.
//!
//! A raster larger than one [`TILE`] is meshed as a fixed grid of tiles in
//! parallel, each with its seams simplified in 1D like shared edges, and the
//! tiles' meshes are merged (see [`greedy_tin`]).
use crate::error::{CoreError, CoreResult};
use crate::geometry::{GeoGrid, Mesh};
use spade::handles::{FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{DelaunayTriangulation, HasPosition, Point2, Triangulation};

/// The result of [`greedy_tin`].
#[derive(Debug, Clone, PartialEq)]
pub struct GreedyTin {
    /// Grid position `(col, row)` of every vertex.
    pub grid: Vec<[u32; 2]>,
    /// Height of every vertex (the sample's value).
    pub z: Vec<f64>,
    /// Triangles as vertex indices, counter-clockwise in `(col, row)` axes.
    pub triangles: Vec<[i64; 3]>,
    /// Largest `|z - mesh|` over the valid samples covered by the result.
    pub max_error: f64,
}

impl GreedyTin {
    /// Map coordinates `(x, y, z)` of the vertices: the centre of each
    /// vertex's sample on `grid`.
    pub fn map_vertices(&self, grid: &GeoGrid) -> Vec<[f64; 3]> {
        self.grid
            .iter()
            .zip(&self.z)
            .map(|(g, &z)| {
                let [x, y] = grid.center(g[1] as f64, g[0] as f64);
                [x, y, z]
            })
            .collect()
    }

    /// Triangles counter-clockwise seen from +z in map axes: the grid's
    /// `(col, row)` axes are mirrored on a row-0-north [`GeoGrid`], so every
    /// triangle's last two corners are swapped.
    pub fn map_triangles(&self) -> Vec<[u32; 3]> {
        self.triangles
            .iter()
            .map(|t| [t[0] as u32, t[2] as u32, t[1] as u32])
            .collect()
    }

    /// The TIN as a [`Mesh`] in map coordinates of `grid` (see
    /// [`Mesh::from_tin`]), built in Rust from the kernel's result.
    pub fn to_mesh(&self, grid: &GeoGrid) -> CoreResult<Mesh> {
        let grid = grid.clone().checked()?;
        Mesh::from_tin(&self.map_vertices(&grid), &self.map_triangles())
    }
}

#[derive(Clone, Copy)]
struct GridVertex {
    pos: Point2<f64>,
    sample: u32,
    z: f64,
}

impl HasPosition for GridVertex {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.pos
    }
}

type Tri = DelaunayTriangulation<GridVertex>;

const NONE: u32 = u32::MAX;

/// A quiet NaN with a payload no arithmetic produces, marking skipped
/// samples in `Refiner::zq` (nodata samples are the canonical NaN there).
const SKIP: u64 = 0x7ff8_dead_beef_0001;

#[derive(Clone, Copy)]
struct FaceInfo {
    handle: Option<FixedFaceHandle<InnerTag>>,
    version: u32,
    err: f64,
    cand: u32,
    mixed: bool,
}

impl Default for FaceInfo {
    fn default() -> Self {
        FaceInfo {
            handle: None,
            version: 0,
            err: 0.0,
            cand: NONE,
            mixed: false,
        }
    }
}

/// A queue entry: the priority's bits (non-negative floats order like their
/// bit patterns), then the lower face index first, then the version.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Entry {
    key: u64,
    face_rev: u32,
    version: u32,
}

/// A 4-ary max-heap of entries with lazy deletion by the caller (stale
/// entries are skipped when popped). Entries are totally ordered, so the
/// pop sequence is that of any other max-priority queue; a 4-ary heap has
/// half the depth of a binary one, hence about half the cache misses per
/// pop when the queue is large.
#[derive(Default)]
struct Queue {
    v: Vec<Entry>,
}

impl Queue {
    fn push(&mut self, e: Entry) {
        let mut i = self.v.len();
        self.v.push(e);
        while i > 0 {
            let p = (i - 1) / 4;
            if self.v[p] >= e {
                break;
            }
            self.v[i] = self.v[p];
            i = p;
        }
        self.v[i] = e;
    }

    fn pop(&mut self) -> Option<Entry> {
        let last = self.v.pop()?;
        let n = self.v.len();
        if n == 0 {
            return Some(last);
        }
        let top = self.v[0];
        let mut i = 0;
        loop {
            let c = 4 * i + 1;
            if c >= n {
                break;
            }
            let mut m = c;
            for j in c + 1..(c + 4).min(n) {
                if self.v[j] > self.v[m] {
                    m = j;
                }
            }
            if self.v[m] <= last {
                break;
            }
            self.v[i] = self.v[m];
            i = m;
        }
        self.v[i] = last;
        Some(top)
    }
}

struct Grid<'a> {
    z: &'a [f64],
    rows: usize,
    cols: usize,
    /// Rounding allowance of an interpolated height: errors up to
    /// `max_error + slack` count as within the bound.
    slack: f64,
}

impl Grid<'_> {
    fn valid(&self, r: usize, c: usize) -> bool {
        !self.z[r * self.cols + c].is_nan()
    }
}

/// Convex hull (counter-clockwise, no collinear points) of the valid samples,
/// from the first and last valid sample of every row.
fn valid_hull(g: &Grid) -> Vec<(i64, i64)> {
    let mut pts: Vec<(i64, i64)> = Vec::new();
    for r in 0..g.rows {
        let first = (0..g.cols).find(|&c| g.valid(r, c));
        if let Some(c0) = first {
            let c1 = (0..g.cols).rev().find(|&c| g.valid(r, c)).unwrap_or(c0);
            pts.push((c0 as i64, r as i64));
            if c1 != c0 {
                pts.push((c1 as i64, r as i64));
            }
        }
    }
    pts.sort_unstable();
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: (i64, i64), a: (i64, i64), b: (i64, i64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(i64, i64)> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(i64, i64)>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Douglas-Peucker simplification of each run of valid samples along one
/// raster edge: the run's ends, then recursively the sample farthest (in
/// height) from the chord while it is more than `max_error` away. Marks the
/// kept samples in `keep`, returns the largest residual error.
fn simplify_edge(g: &Grid, samples: &[usize], max_error: f64, keep: &mut Vec<usize>) -> f64 {
    let mut worst = 0.0f64;
    let mut i = 0;
    while i < samples.len() {
        if g.z[samples[i]].is_nan() {
            i += 1;
            continue;
        }
        let mut j = i;
        while j + 1 < samples.len() && !g.z[samples[j + 1]].is_nan() {
            j += 1;
        }
        keep.push(samples[i]);
        keep.push(samples[j]);
        let mut stack = vec![(i, j)];
        while let Some((a, b)) = stack.pop() {
            if b <= a + 1 {
                continue;
            }
            let (za, zb) = (g.z[samples[a]], g.z[samples[b]]);
            let mut best = (0.0f64, NONE as usize);
            for (k, &sk) in samples.iter().enumerate().take(b).skip(a + 1) {
                let t = (k - a) as f64 / (b - a) as f64;
                let e = (g.z[sk] - (za + t * (zb - za))).abs();
                if e > best.0 || best.1 == NONE as usize {
                    best = (e, k);
                }
            }
            if best.0 > max_error + g.slack {
                keep.push(samples[best.1]);
                stack.push((a, best.1));
                stack.push((best.1, b));
            } else {
                worst = worst.max(best.0);
            }
        }
        i = j + 1;
    }
    worst
}

struct Refiner<'a> {
    g: Grid<'a>,
    tri: Tri,
    /// The heights, with the samples that are never candidates (vertices,
    /// and the valid samples of shared edges) set to the NaN
    /// [`SKIP`]: one load per sample tells valid, nodata and skipped apart.
    zq: Vec<f64>,
    faces: Vec<FaceInfo>,
    heap: Queue,
    max_error: f64,
}

impl Refiner<'_> {
    /// Rasterise face `f` and store its worst sample.
    fn update(&mut self, f: FixedFaceHandle<InnerTag>) {
        let face = self.tri.face(f);
        let vs = face.vertices();
        let p = vs.map(|v| (v.position().x as i64, v.position().y as i64));
        let zs = vs.map(|v| v.data().z);
        let area2 = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[1].1 - p[0].1) * (p[2].0 - p[0].0);
        let mut info = FaceInfo::default();
        if area2 > 0 {
            let x0 = p.iter().map(|q| q.0).min().unwrap_or(0);
            let x1 = p.iter().map(|q| q.0).max().unwrap_or(0);
            let y0 = p.iter().map(|q| q.1).min().unwrap_or(0);
            let y1 = p.iter().map(|q| q.1).max().unwrap_or(0);
            // Edge function of edge a->b at (x, y): weight of the opposite vertex.
            let edge = |a: (i64, i64), b: (i64, i64), x: i64, y: i64| {
                (b.0 - a.0) * (y - a.1) - (b.1 - a.1) * (x - a.0)
            };
            let inv = 1.0 / area2 as f64;
            let mut best = -1.0f64;
            for y in y0..=y1 {
                let row = y as usize * self.g.cols;
                // Edge functions are linear in x: step them along the row.
                let w = [
                    edge(p[1], p[2], x0, y),
                    edge(p[2], p[0], x0, y),
                    edge(p[0], p[1], x0, y),
                ];
                let d = [-(p[2].1 - p[1].1), -(p[0].1 - p[2].1), -(p[1].1 - p[0].1)];
                // The columns where all three edge functions are >= 0, exactly:
                // w + d k >= 0 for k = x - x0.
                let (mut k0, mut k1) = (0i64, x1 - x0);
                for i in 0..3 {
                    if d[i] > 0 {
                        if w[i] < 0 {
                            k0 = k0.max((-w[i] + d[i] - 1).div_euclid(d[i]));
                        }
                    } else if d[i] < 0 {
                        k1 = k1.min(w[i].div_euclid(-d[i]));
                    } else if w[i] < 0 {
                        k1 = -1;
                    }
                }
                if k0 > k1 {
                    continue;
                }
                // Step the (exact, integer) edge functions along the row.
                let (mut w0, mut w1, mut w2) =
                    (w[0] + d[0] * k0, w[1] + d[1] * k0, w[2] + d[2] * k0);
                let start = row + (x0 + k0) as usize;
                let end = row + (x0 + k1) as usize + 1;
                for (j, &z) in self.zq[start..end].iter().enumerate() {
                    if z.is_nan() {
                        info.mixed |= z.to_bits() != SKIP;
                    } else {
                        let plane =
                            (w0 as f64 * zs[0] + w1 as f64 * zs[1] + w2 as f64 * zs[2]) * inv;
                        let e = (z - plane).abs();
                        if e > best {
                            best = e;
                            info.cand = (start + j) as u32;
                        }
                    }
                    w0 += d[0];
                    w1 += d[1];
                    w2 += d[2];
                }
            }
            info.err = best.max(0.0);
        }
        let i = f.index();
        if i >= self.faces.len() {
            self.faces.resize(i + 1, FaceInfo::default());
        }
        info.version = self.faces[i].version.wrapping_add(1);
        info.handle = Some(f);
        self.faces[i] = info;
        let prio = if info.mixed { f64::INFINITY } else { info.err };
        // A face within the bound never needs a split: keep it out of the
        // queue (most faces end there; a smaller heap pops faster).
        if info.cand != NONE && prio > self.max_error + self.g.slack {
            self.heap.push(Entry {
                key: prio.to_bits(),
                face_rev: !(i as u32),
                version: info.version,
            });
        }
    }

    fn insert(
        &mut self,
        s: usize,
        hint: Option<FixedVertexHandle>,
    ) -> CoreResult<FixedVertexHandle> {
        let (r, c) = (s / self.g.cols, s % self.g.cols);
        let v = GridVertex {
            pos: Point2::new(c as f64, r as f64),
            sample: s as u32,
            z: self.g.z[s],
        };
        self.zq[s] = f64::from_bits(SKIP);
        let h = match hint {
            Some(h) => self.tri.insert_with_hint(v, h),
            None => self.tri.insert(v),
        };
        h.map_err(|e| CoreError::Internal(format!("vertex insertion failed: {e:?}")))
    }
}

/// Ask the CPU to start loading the heights in the bounding box of the
/// grid points `p` (at most 64 cache lines, row by row): the popped face's
/// samples are rasterised again right after spade has inserted its
/// candidate, so their loads overlap with the insertion. A hint only: it
/// reads nothing and changes no result.
#[inline]
fn prefetch_box(zq: &[f64], cols: usize, p: [(usize, usize); 3]) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let (x0, x1) = (p.iter().map(|q| q.0).min(), p.iter().map(|q| q.0).max());
        let (y0, y1) = (p.iter().map(|q| q.1).min(), p.iter().map(|q| q.1).max());
        let (Some(x0), Some(x1), Some(y0), Some(y1)) = (x0, x1, y0, y1) else {
            return;
        };
        let mut budget = 64usize;
        for y in y0..=y1 {
            let Some(row) = zq.get(y * cols + x0..=y * cols + x1) else {
                return;
            };
            for k in (0..row.len()).step_by(8) {
                if budget == 0 {
                    return;
                }
                budget -= 1;
                // SAFETY: `k < row.len()`, so the pointer is inside `zq`;
                // a prefetch never faults and has no observable effect.
                unsafe { _mm_prefetch(row.as_ptr().add(k) as *const i8, _MM_HINT_T0) };
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (zq, cols, p);
}

/// Side length, in sample spacings, above which a raster is meshed in tiles:
/// a raster of more than `TILE + 1` samples along an axis is cut into
/// `ceil((n - 1) / TILE)` tiles of nearly equal size along it (cuts at
/// samples `i (n - 1) / k`, `i = 0..=k`), neighbouring tiles sharing their
/// seam row or column. The tiling depends on the shape alone, never on the
/// thread count. 128 was the fastest of 128, 256 and 512 on a 1024² fBm and
/// on Big Tujunga (`benches/bench_tin.py`): a tile's heights (129² float64,
/// 130 kB) and its triangulation stay in the L2 cache.
pub const TILE: usize = 128;

/// The sample indices `0 = c_0 < c_1 < ... < c_k = n - 1` of the tile
/// boundaries along an axis of `n` samples (see [`TILE`]).
fn tile_cuts(n: usize) -> Vec<usize> {
    let spans = n.saturating_sub(1);
    let k = spans.div_ceil(TILE).max(1);
    (0..=k).map(|i| i * spans / k).collect()
}

/// Greedy error-bounded TIN of the `rows x cols` raster `z` (row-major,
/// NaN = nodata).
///
/// * `max_error`: stop when every valid sample is within this vertical
///   distance of the mesh (same unit as `z`; >= 0), allowing for the
///   rounding of the interpolation (`16 eps max|z|`).
/// * `max_triangles`: stop when the mesh has this many triangles (the
///   initial mesh may already have more). The budget is spent worst-first
///   over the whole raster, so the raster is meshed as one tile.
/// * `shared_edges`: the vertices on the four raster edges are chosen by a
///   1D simplification of the edge samples alone (within `max_error`) and no
///   other edge sample is inserted, so tiles of one raster meshed separately
///   have identical vertices on their common edges.
///
/// Without `max_triangles`, a raster larger than one [`TILE`] is cut into
/// tiles that are meshed independently (in parallel) with their seams
/// simplified in 1D as shared edges are, whatever `shared_edges` says
/// (which then applies to the raster's outer edges only); the tiles' meshes
/// are merged in tile order, vertices deduplicated by grid position. The
/// result does not depend on the thread count.
pub fn greedy_tin(
    z: &[f64],
    rows: usize,
    cols: usize,
    max_error: f64,
    max_triangles: Option<usize>,
    shared_edges: bool,
) -> CoreResult<GreedyTin> {
    if max_error.is_nan() || max_error < 0.0 {
        return Err(CoreError::invalid(
            "max_error",
            format!("must be >= 0, got {max_error}"),
        ));
    }
    let n = rows
        .checked_mul(cols)
        .filter(|&n| n == z.len() && n < u32::MAX as usize)
        .ok_or_else(|| {
            CoreError::invalid(
                "dem",
                "shape does not match the data or has 2^32 samples or more",
            )
        })?;
    if let Some(bad) = z.iter().find(|v| v.is_infinite()) {
        return Err(CoreError::invalid(
            "dem",
            format!("contains an infinite value ({bad})"),
        ));
    }
    let zmax = z
        .iter()
        .filter(|v| !v.is_nan())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let slack = 16.0 * f64::EPSILON * zmax;
    let no_triangle = || {
        CoreError::invalid(
            "dem",
            "the valid samples are fewer than 3 or all on one line: there is no triangle",
        )
    };
    let (rcuts, ccuts) = (tile_cuts(rows), tile_cuts(cols));
    if max_triangles.is_some() || (rcuts.len() == 2 && ccuts.len() == 2) {
        return greedy_tile(
            z,
            rows,
            cols,
            max_error,
            max_triangles,
            [shared_edges; 4],
            slack,
        )?
        .ok_or_else(no_triangle);
    }
    let whole = Grid {
        z,
        rows,
        cols,
        slack,
    };
    if valid_hull(&whole).len() < 3 {
        return Err(no_triangle());
    }
    // Tiles in row-major order: (first row, last row, first col, last col).
    let mut tiles = Vec::new();
    for rw in rcuts.windows(2) {
        for cw in ccuts.windows(2) {
            tiles.push((rw[0], rw[1], cw[0], cw[1]));
        }
    }
    use rayon::prelude::*;
    let meshes: Vec<Option<GreedyTin>> = tiles
        .par_iter()
        .map(|&(r0, r1, c0, c1)| {
            let (tr, tc) = (r1 - r0 + 1, c1 - c0 + 1);
            let mut sub = Vec::new();
            sub.try_reserve_exact(tr * tc).map_err(|_| {
                CoreError::invalid("dem", format!("cannot allocate a tile of {tr} x {tc}"))
            })?;
            for r in r0..=r1 {
                sub.extend_from_slice(&z[r * cols + c0..=r * cols + c1]);
            }
            // Seams are always shared; the raster's own edges as asked.
            let sides = [
                r0 > 0 || shared_edges,
                r1 < rows - 1 || shared_edges,
                c0 > 0 || shared_edges,
                c1 < cols - 1 || shared_edges,
            ];
            greedy_tile(&sub, tr, tc, max_error, None, sides, slack)
        })
        .collect::<CoreResult<_>>()?;
    // Merge in tile order: a seam vertex gets the index of its first tile.
    let mut index = vec![u32::MAX; n];
    let mut out = GreedyTin {
        grid: Vec::new(),
        z: Vec::new(),
        triangles: Vec::new(),
        max_error: 0.0,
    };
    for (&(r0, _, c0, _), mesh) in tiles.iter().zip(&meshes) {
        let Some(m) = mesh else { continue };
        out.max_error = out.max_error.max(m.max_error);
        let global: Vec<u32> = m
            .grid
            .iter()
            .map(|&[c, r]| {
                let (gc, gr) = (c0 + c as usize, r0 + r as usize);
                let s = gr * cols + gc;
                if index[s] == u32::MAX {
                    index[s] = out.grid.len() as u32;
                    out.grid.push([gc as u32, gr as u32]);
                    out.z.push(z[s]);
                }
                index[s]
            })
            .collect();
        out.triangles.extend(
            m.triangles
                .iter()
                .map(|t| t.map(|i| global[i as usize] as i64)),
        );
    }
    Ok(out)
}

/// [`greedy_tin`] of one tile, with the slack of the whole raster and the
/// sides (top, bottom, left, right) simplified in 1D flagged in `sides`;
/// `None` when the tile's valid samples are fewer than 3 or collinear.
fn greedy_tile(
    z: &[f64],
    rows: usize,
    cols: usize,
    max_error: f64,
    max_triangles: Option<usize>,
    sides: [bool; 4],
    slack: f64,
) -> CoreResult<Option<GreedyTin>> {
    let n = rows * cols;
    let g = Grid {
        z,
        rows,
        cols,
        slack,
    };
    let mut initial: Vec<usize> = valid_hull(&g)
        .into_iter()
        .map(|(c, r)| r as usize * cols + c as usize)
        .collect();
    if initial.len() < 3 {
        return Ok(None);
    }
    let mut zq = Vec::new();
    zq.try_reserve_exact(n)
        .map_err(|_| CoreError::invalid("dem", format!("cannot allocate a copy of {n} samples")))?;
    zq.extend(z.iter().map(|&v| if v.is_nan() { f64::NAN } else { v }));
    let mut edge_error = 0.0f64;
    let top: Vec<usize> = (0..cols).collect();
    let bottom: Vec<usize> = (0..cols).map(|c| (rows - 1) * cols + c).collect();
    let left: Vec<usize> = (0..rows).map(|r| r * cols).collect();
    let right: Vec<usize> = (0..rows).map(|r| r * cols + cols - 1).collect();
    for (side, shared) in [&top, &bottom, &left, &right].into_iter().zip(sides) {
        if !shared {
            continue;
        }
        edge_error = edge_error.max(simplify_edge(&g, side, max_error, &mut initial));
        // Valid edge samples are never candidates; nodata ones stay NaN, so
        // a triangle across a gap of the edge counts as covering nodata.
        for &s in side {
            if !z[s].is_nan() {
                zq[s] = f64::from_bits(SKIP);
            }
        }
    }
    initial.sort_unstable();
    initial.dedup();
    let mut rf = Refiner {
        g,
        tri: Tri::new(),
        zq,
        faces: Vec::new(),
        heap: Queue::default(),
        max_error,
    };
    for &s in &initial {
        rf.insert(s, None)?;
    }
    let all: Vec<_> = rf.tri.fixed_inner_faces().collect();
    for f in all {
        rf.update(f);
    }
    let budget = max_triangles.unwrap_or(usize::MAX);
    let mut star: Vec<FixedFaceHandle<InnerTag>> = Vec::new();
    while let Some(top) = rf.heap.pop() {
        let info = rf.faces[!top.face_rev as usize];
        if info.version != top.version {
            continue;
        }
        if rf.tri.num_inner_faces() >= budget {
            break;
        }
        let Some(handle) = info.handle else {
            return Err(CoreError::Internal("queued face without a handle".into()));
        };
        let face = rf.tri.face(handle);
        let vs = face.vertices();
        prefetch_box(
            &rf.zq,
            cols,
            vs.map(|v| (v.position().x as usize, v.position().y as usize)),
        );
        let hint = vs[0].fix();
        let v = rf.insert(info.cand as usize, Some(hint))?;
        star.clear();
        star.extend(
            rf.tri
                .vertex(v)
                .out_edges()
                .filter_map(|e| e.face().as_inner().map(|f| f.fix())),
        );
        for &f in &star {
            rf.update(f);
        }
    }
    // Collect the kept triangles and the vertices they use.
    let mut index = vec![u32::MAX; rf.tri.num_vertices()];
    let mut grid = Vec::new();
    let mut zs = Vec::new();
    let mut triangles = Vec::new();
    let mut achieved = edge_error;
    for f in rf.tri.inner_faces() {
        let info = rf.faces[f.fix().index()];
        if info.mixed {
            continue;
        }
        achieved = achieved.max(info.err);
        let mut t = [0i64; 3];
        for (k, v) in f.vertices().iter().enumerate() {
            let vi = v.fix().index();
            if index[vi] == u32::MAX {
                index[vi] = grid.len() as u32;
                let s = v.data().sample as usize;
                grid.push([(s % cols) as u32, (s / cols) as u32]);
                zs.push(z[s]);
            }
            t[k] = index[vi] as i64;
        }
        triangles.push(t);
    }
    Ok(Some(GreedyTin {
        grid,
        z: zs,
        triangles,
        max_error: achieved,
    }))
}

/// Rasterise the triangle mesh (`xy` in grid coordinates `(col, row)`,
/// heights `z`) onto a `rows x cols` grid by barycentric interpolation;
/// samples covered by no triangle are NaN. A sample on a shared edge takes
/// the value of the first triangle that covers it.
pub fn rasterize(
    xy: &[[f64; 2]],
    z: &[f64],
    triangles: &[[i64; 3]],
    rows: usize,
    cols: usize,
) -> CoreResult<Vec<f64>> {
    let n = xy.len();
    if z.len() != n {
        return Err(CoreError::invalid("z", "needs one height per vertex"));
    }
    let cells = rows
        .checked_mul(cols)
        .filter(|&c| c <= (1usize << 40))
        .ok_or_else(|| CoreError::invalid("shape", "is too large"))?;
    let mut out = Vec::new();
    out.try_reserve_exact(cells).map_err(|_| {
        CoreError::invalid("shape", format!("cannot allocate {rows} x {cols} values"))
    })?;
    out.resize(cells, f64::NAN);
    for (k, t) in triangles.iter().enumerate() {
        if t.iter().any(|&i| i < 0 || i as u64 >= n as u64) {
            return Err(CoreError::invalid(
                "triangles",
                format!("row {k} has a vertex index outside [0, {n})"),
            ));
        }
        let [a, b, c] = t.map(|i| xy[i as usize]);
        let [za, zb, zc] = t.map(|i| z[i as usize]);
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        if area == 0.0 || !area.is_finite() {
            continue;
        }
        let tol = -1e-9 * area.abs();
        let lo = |u: f64, v: f64, w: f64| u.min(v).min(w).ceil().max(0.0);
        let hi = |u: f64, v: f64, w: f64, m: usize| u.max(v).max(w).floor().min(m as f64 - 1.0);
        let (x0, x1) = (lo(a[0], b[0], c[0]), hi(a[0], b[0], c[0], cols));
        let (y0, y1) = (lo(a[1], b[1], c[1]), hi(a[1], b[1], c[1], rows));
        if x0 > x1 || y0 > y1 {
            continue;
        }
        for y in y0 as usize..=y1 as usize {
            for x in x0 as usize..=x1 as usize {
                let (px, py) = (x as f64, y as f64);
                let w0 =
                    ((c[0] - b[0]) * (py - b[1]) - (c[1] - b[1]) * (px - b[0])) / area.signum();
                let w1 =
                    ((a[0] - c[0]) * (py - c[1]) - (a[1] - c[1]) * (px - c[0])) / area.signum();
                let w2 =
                    ((b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])) / area.signum();
                if w0 >= tol && w1 >= tol && w2 >= tol {
                    let o = &mut out[y * cols + x];
                    if o.is_nan() {
                        *o = (w0 * za + w1 * zb + w2 * zc) / area.abs();
                    }
                }
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_needs_only_corners() {
        let (rows, cols) = (17, 23);
        let z: Vec<f64> = (0..rows * cols)
            .map(|s| 2.0 * (s % cols) as f64 - 0.5 * (s / cols) as f64 + 3.0)
            .collect();
        let t = greedy_tin(&z, rows, cols, 0.0, None, false).unwrap();
        assert_eq!(t.grid.len(), 4);
        assert_eq!(t.triangles.len(), 2);
        assert!(t.max_error < 1e-9);
    }

    /// A smooth-plus-random field: sums of sines and uniform noise.
    fn field(rows: usize, cols: usize, seed: u64) -> Vec<f64> {
        let noise = crate::testdata::uniform(rows * cols, seed);
        (0..rows * cols)
            .map(|s| {
                let (r, c) = ((s / cols) as f64, (s % cols) as f64);
                20.0 * (r / 37.0).sin() * (c / 23.0).cos() + 5.0 * noise[s]
            })
            .collect()
    }

    /// Every valid sample within `bound` of the mesh and no nodata sample
    /// covered (the kernel's own rasteriser, which `tests/test_tin_dem.py`
    /// checks against an independent one); returns the coverage.
    fn check_bound(t: &GreedyTin, z: &[f64], rows: usize, cols: usize, bound: f64) -> Vec<f64> {
        let xy: Vec<[f64; 2]> = t.grid.iter().map(|g| [g[0] as f64, g[1] as f64]).collect();
        let g = rasterize(&xy, &t.z, &t.triangles, rows, cols).unwrap();
        for s in 0..rows * cols {
            if z[s].is_nan() {
                assert!(g[s].is_nan(), "nodata sample {s} covered");
            } else if !g[s].is_nan() {
                assert!((g[s] - z[s]).abs() <= bound + 1e-9, "sample {s}");
            }
        }
        g
    }

    /// Undirected edges used by more than two triangles or directed edges
    /// used twice (a fold or overlap), and edges used once that are not on
    /// the raster's outer boundary.
    fn open_edges(t: &GreedyTin, rows: usize, cols: usize) -> Vec<[u32; 4]> {
        use std::collections::HashMap;
        let mut count: HashMap<(i64, i64), (u32, u32)> = HashMap::new();
        for tr in &t.triangles {
            for k in 0..3 {
                let (a, b) = (tr[k], tr[(k + 1) % 3]);
                let e = count.entry((a.min(b), a.max(b))).or_default();
                if a < b {
                    e.0 += 1;
                } else {
                    e.1 += 1;
                }
            }
        }
        let mut bad = Vec::new();
        for (&(a, b), &(f, r)) in &count {
            let (p, q) = (t.grid[a as usize], t.grid[b as usize]);
            let on_outer = (p[0] == q[0] && (p[0] == 0 || p[0] as usize == cols - 1))
                || (p[1] == q[1] && (p[1] == 0 || p[1] as usize == rows - 1));
            if f > 1 || r > 1 || (f + r == 1 && !on_outer) {
                bad.push([p[0], p[1], q[0], q[1]]);
            }
        }
        bad
    }

    /// Triangle edges along a seam (or any grid line) with a mesh vertex
    /// strictly inside them: T-junctions.
    fn t_junctions(t: &GreedyTin) -> Vec<[u32; 4]> {
        use std::collections::HashSet;
        let verts: HashSet<[u32; 2]> = t.grid.iter().copied().collect();
        let mut bad = Vec::new();
        for tr in &t.triangles {
            for k in 0..3 {
                let (p, q) = (t.grid[tr[k] as usize], t.grid[tr[(k + 1) % 3] as usize]);
                let inside: Vec<[u32; 2]> = if p[0] == q[0] {
                    (p[1].min(q[1]) + 1..p[1].max(q[1]))
                        .map(|r| [p[0], r])
                        .collect()
                } else if p[1] == q[1] {
                    (p[0].min(q[0]) + 1..p[0].max(q[0]))
                        .map(|c| [c, p[1]])
                        .collect()
                } else {
                    Vec::new()
                };
                if inside.iter().any(|v| verts.contains(v)) {
                    bad.push([p[0], p[1], q[0], q[1]]);
                }
            }
        }
        bad
    }

    #[test]
    fn tile_cuts_are_balanced_and_fixed() {
        assert_eq!(tile_cuts(1), vec![0, 0]);
        assert_eq!(tile_cuts(TILE + 1), vec![0, TILE]);
        assert_eq!(tile_cuts(TILE + 2).len(), 3);
        let c = tile_cuts(1024);
        assert_eq!(*c.first().unwrap(), 0);
        assert_eq!(*c.last().unwrap(), 1023);
        assert!(c
            .windows(2)
            .all(|w| w[1] - w[0] <= TILE && w[1] - w[0] >= TILE / 2));
    }

    #[test]
    fn tiles_join_without_cracks_and_keep_the_bound() {
        let (rows, cols) = (2 * TILE + 40, TILE + 90);
        let z = field(rows, cols, 7);
        for shared in [false, true] {
            let t = greedy_tin(&z, rows, cols, 2.0, None, shared).unwrap();
            let g = check_bound(&t, &z, rows, cols, 2.0);
            assert!(g.iter().all(|v| !v.is_nan()), "the raster is covered");
            assert!(t.max_error <= 2.0 + 1e-9);
            assert_eq!(open_edges(&t, rows, cols), Vec::<[u32; 4]>::new());
            assert_eq!(t_junctions(&t), Vec::<[u32; 4]>::new());
            // no vertex twice
            let mut pos = t.grid.clone();
            pos.sort_unstable();
            pos.dedup();
            assert_eq!(pos.len(), t.grid.len());
            // the tiled mesh is not far from the single-tile one
            let one = greedy_tin(&z, rows, cols, 2.0, Some(usize::MAX), shared).unwrap();
            assert!(t.grid.len() as f64 <= 1.05 * one.grid.len() as f64);
        }
    }

    #[test]
    fn tiled_tin_mesh_is_crack_free_with_its_rim_on_the_raster_edge() {
        let (rows, cols) = (2 * TILE + 40, TILE + 90);
        let z = field(rows, cols, 11);
        let grid = GeoGrid::new(500_000.0, 4_000_000.0, 30.0, 30.0).unwrap();
        for shared in [false, true] {
            let t = greedy_tin(&z, rows, cols, 2.0, None, shared).unwrap();
            let m = t.to_mesh(&grid).unwrap();
            m.validate().unwrap();
            let e = m.edges();
            assert_eq!((e.non_manifold, e.inconsistent), (0, 0));
            // every open edge runs along the raster's outer edge, and they
            // add up to its perimeter: no crack inside
            let (lo, hi) = m.bounds().unwrap();
            let rim = m.boundary_edges();
            assert_eq!(rim.len(), e.boundary);
            let mut length = 0.0;
            for [a, b] in rim {
                let (p, q) = (m.vertices[a as usize], m.vertices[b as usize]);
                let on = |k: usize, v: f64| {
                    (p[k] as f64 + m.origin[k] - v).abs() < 1e-6
                        && (q[k] as f64 + m.origin[k] - v).abs() < 1e-6
                };
                assert!(
                    on(0, lo[0]) || on(0, hi[0]) || on(1, lo[1]) || on(1, hi[1]),
                    "open edge {p:?}-{q:?} inside the raster"
                );
                length += ((p[0] - q[0]) as f64).hypot((p[1] - q[1]) as f64);
            }
            let perimeter = 2.0 * 30.0 * ((rows - 1) + (cols - 1)) as f64;
            assert!(
                (length - perimeter).abs() < 1e-6 * perimeter,
                "{length} {perimeter}"
            );
            // counter-clockwise from above: every normal points up
            assert!(m.normals.iter().all(|n| n[2] > 0.0));
            // vertices at the sample centres, in metres
            for (k, g) in t.grid.iter().enumerate() {
                let x = 500_015.0 + 30.0 * g[0] as f64;
                let y = 4_000_000.0 - 15.0 - 30.0 * g[1] as f64;
                let v = m.vertices[k];
                assert!((v[0] as f64 + m.origin[0] - x).abs() < 1e-3);
                assert!((v[1] as f64 + m.origin[1] - y).abs() < 1e-3);
            }
        }
    }

    #[test]
    fn identical_for_any_thread_count() {
        let (rows, cols) = (TILE + 60, 2 * TILE + 10);
        let z = field(rows, cols, 9);
        let run = |n| {
            crate::parallel::run_in_pool(Some(n), || greedy_tin(&z, rows, cols, 1.0, None, true))
        };
        let a = run(1).unwrap();
        assert_eq!(a, run(2).unwrap());
        assert_eq!(a, run(3).unwrap());
    }

    #[test]
    fn nodata_tiles_and_holes_across_seams() {
        let (rows, cols) = (2 * TILE + 1, 2 * TILE + 1);
        let mut z = field(rows, cols, 11);
        // the first tile entirely nodata, a hole across the vertical seam,
        // a one-sample-wide nodata line along part of the horizontal seam
        for r in 0..=TILE {
            for c in 0..=TILE {
                z[r * cols + c] = f64::NAN;
            }
        }
        for r in TILE + 40..TILE + 90 {
            for c in TILE - 30..TILE + 25 {
                z[r * cols + c] = f64::NAN;
            }
        }
        for c in TILE + 50..TILE + 70 {
            z[TILE * cols + c] = f64::NAN;
        }
        let t = greedy_tin(&z, rows, cols, 1.5, None, true).unwrap();
        let g = check_bound(&t, &z, rows, cols, 1.5);
        let covered = (0..rows * cols).filter(|&s| !g[s].is_nan()).count();
        let valid = z.iter().filter(|v| !v.is_nan()).count();
        assert!(covered as f64 >= 0.99 * valid as f64);
        assert_eq!(t_junctions(&t), Vec::<[u32; 4]>::new());
        // a whole raster of nodata but three samples in three tiles
        let mut sparse = vec![f64::NAN; rows * cols];
        sparse[0] = 1.0;
        sparse[rows * cols - 1] = 2.0;
        sparse[cols - 1] = 3.0;
        let t = greedy_tin(&sparse, rows, cols, 0.0, None, true).unwrap();
        assert!(t.triangles.is_empty());
        let mut line = vec![f64::NAN; rows * cols];
        for c in 0..cols {
            line[TILE * cols + c] = c as f64;
        }
        assert!(greedy_tin(&line, rows, cols, 0.0, None, true).is_err());
    }

    #[test]
    fn zero_error_on_random_is_every_sample() {
        let (rows, cols) = (9, 11);
        let z: Vec<f64> = crate::testdata::uniform(rows * cols, 12345);
        for shared in [false, true] {
            let t = greedy_tin(&z, rows, cols, 0.0, None, shared).unwrap();
            assert_eq!(t.grid.len(), rows * cols);
            assert_eq!(t.max_error, 0.0);
        }
    }
}
