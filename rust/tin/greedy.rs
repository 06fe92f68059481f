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
use crate::error::{CoreError, CoreResult};
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
    /// and the raster's edge samples with shared tile edges) set to the NaN
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

/// Greedy error-bounded TIN of the `rows x cols` raster `z` (row-major,
/// NaN = nodata).
///
/// * `max_error`: stop when every valid sample is within this vertical
///   distance of the mesh (same unit as `z`; >= 0), allowing for the
///   rounding of the interpolation (`16 eps max|z|`).
/// * `max_triangles`: stop when the mesh has this many triangles (the
///   initial mesh may already have more).
/// * `shared_edges`: the vertices on the four raster edges are chosen by a
///   1D simplification of the edge samples alone (within `max_error`) and no
///   other edge sample is inserted, so tiles of one raster meshed separately
///   have identical vertices on their common edges.
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
    let g = Grid {
        z,
        rows,
        cols,
        slack: 16.0 * f64::EPSILON * zmax,
    };
    let mut initial: Vec<usize> = valid_hull(&g)
        .into_iter()
        .map(|(c, r)| r as usize * cols + c as usize)
        .collect();
    if initial.len() < 3 {
        return Err(CoreError::invalid(
            "dem",
            "the valid samples are fewer than 3 or all on one line: there is no triangle",
        ));
    }
    let mut zq = Vec::new();
    zq.try_reserve_exact(n)
        .map_err(|_| CoreError::invalid("dem", format!("cannot allocate a copy of {n} samples")))?;
    zq.extend(z.iter().map(|&v| if v.is_nan() { f64::NAN } else { v }));
    let mut edge_error = 0.0f64;
    if shared_edges {
        let top: Vec<usize> = (0..cols).collect();
        let bottom: Vec<usize> = (0..cols).map(|c| (rows - 1) * cols + c).collect();
        let left: Vec<usize> = (0..rows).map(|r| r * cols).collect();
        let right: Vec<usize> = (0..rows).map(|r| r * cols + cols - 1).collect();
        for side in [&top, &bottom, &left, &right] {
            edge_error = edge_error.max(simplify_edge(&g, side, max_error, &mut initial));
            for &s in side {
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
    Ok(GreedyTin {
        grid,
        z: zs,
        triangles,
        max_error: achieved,
    })
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
