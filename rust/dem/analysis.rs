//! Local fractal analysis of a DEM: the Hurst and lag-1 variance maps that
//! `fractal_resample(hurst="local")` refines the DEM with.
//!
//! For lags 1 and 2, every sample `(i, j)` carries the squared increments
//! to `(i + lag, j)` and `(i, j + lag)` whose two ends are finite, and their
//! count. These are summed over the `(2 half + 1)^2` window at the nodes of
//! a grid of spacing `step` (nodes at multiples of `step`), interpolated
//! bilinearly to the pixels (along columns first, then along rows), and
//! give the mean squared increments `g1 = s1 / c1`, `g2 = s2 / c2`:
//!
//! * point support: `H = log2(g2 / g1) / 2`, `sigma^2 = g1`;
//! * area support: `H` inverts the tabulated ratio `gamma_B(2) / gamma_B(1)`
//!   of the block-mean variogram (linear interpolation, as `numpy.interp`;
//!   below the table `H = 0`, above it `H = 2`) and
//!   `sigma^2 = g1 / gamma_B(1; H)` with `H` clipped to the range first.
//!
//! `H` is then clipped to the given range; a pixel whose window has no
//! valid increments (or that is missing itself) gets `H = 0.5`, `sigma = 0`.
//!
//! The input is a block with a NaN halo of [`pad_width`] cells (real or
//! virtual: `border` cells of NaN around the array are taken as present), and
//! the maps are returned for the block without its halo. Each node sum is
//! formed in a fixed order from the values in its window only (blocks of
//! `step` rows, then of `step` columns, aligned on the node grid, then the
//! rows and columns left over), so any block of a larger array whose origin
//! (halo included) is a multiple of `step` gives bit-identical maps, for
//! any number of threads.
use crate::buffers::{try_filled, try_zeroed};
use crate::error::{CoreError, CoreResult};
use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;

/// Halo (cells, a multiple of `step`) the analysis of a block needs: the
/// window, the lag-2 increments and one node spacing for the interpolation.
pub fn pad_width(half: usize, step: usize) -> usize {
    (half + 2 + step).div_ceil(step) * step
}

/// The tabulated block-mean variogram of area support: `ratio[k]` is
/// `gamma_B(2) / gamma_B(1)` and `gamma1[k]` is `gamma_B(1)` (unit sigma)
/// at `hurst[k]`; `ratio` and `hurst` increase.
#[derive(Debug, Clone, Copy)]
pub struct AreaTable<'a> {
    pub hurst: &'a [f64],
    pub ratio: &'a [f64],
    pub gamma1: &'a [f64],
}

/// Options of the analysis.
#[derive(Debug, Clone, Copy)]
pub struct AnalysisParams<'a> {
    /// Half side of the window (cells).
    pub half: usize,
    /// Spacing of the nodes (cells).
    pub step: usize,
    /// Cells of NaN taken as present around the input on every side.
    pub border: usize,
    /// Range `H` is clipped to.
    pub hurst_range: (f64, f64),
    /// `None` for point support; the block-mean table for area support.
    pub area: Option<AreaTable<'a>>,
}

/// The maps on the block without its halo.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalMaps {
    /// Clipped local `H` (0.5 where there is none).
    pub hurst: Array2<f64>,
    /// Local lag-1 increment standard deviation (0 where there is none).
    pub sigma: Array2<f64>,
    /// Pixels whose `H` was finite but outside the range.
    pub n_clipped: u64,
    /// Pixels with a finite `H`.
    pub n_valid: u64,
}

/// Sums of squared increments and their counts at lags 1 and 2.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Quad {
    s1: f64,
    s2: f64,
    c1: u32,
    c2: u32,
}

impl Quad {
    #[inline]
    fn add(&mut self, o: &Quad) {
        self.s1 += o.s1;
        self.s2 += o.s2;
        self.c1 += o.c1;
        self.c2 += o.c2;
    }
}

/// Bilinear weights of the four sums, in floating point.
#[derive(Debug, Clone, Copy, Default)]
struct Quadf {
    s1: f64,
    c1: f64,
    s2: f64,
    c2: f64,
}

impl Quadf {
    /// `a (1 - u) + b u`, component by component.
    #[inline]
    fn lerp(a: &Quadf, b: &Quadf, u: f64) -> Quadf {
        let w = 1.0 - u;
        Quadf {
            s1: a.s1 * w + b.s1 * u,
            c1: a.c1 * w + b.c1 * u,
            s2: a.s2 * w + b.s2 * u,
            c2: a.c2 * w + b.c2 * u,
        }
    }
}

impl From<&Quad> for Quadf {
    fn from(q: &Quad) -> Self {
        Quadf {
            s1: q.s1,
            c1: q.c1 as f64,
            s2: q.s2,
            c2: q.c2 as f64,
        }
    }
}

/// The input seen with its virtual NaN border.
struct Padded<'a> {
    z: &'a [f64],
    rows: usize,
    cols: usize,
    border: usize,
}

impl Padded<'_> {
    fn n_rows(&self) -> usize {
        self.rows + 2 * self.border
    }

    fn n_cols(&self) -> usize {
        self.cols + 2 * self.border
    }

    /// Row `i` (padded index) with its border and 2 more NaN at the end
    /// into `buf` (rows past the last are NaN).
    fn row_into(&self, i: usize, buf: &mut Vec<f64>) {
        let b = self.border;
        buf.clear();
        buf.resize(self.n_cols() + 2, f64::NAN);
        if i >= b && i < self.rows + b {
            let r = i - b;
            buf[b..b + self.cols].copy_from_slice(&self.z[r * self.cols..(r + 1) * self.cols]);
        }
    }
}

/// Rows `first, first + 1, first + 2` of the input, as [`increments`] reads
/// them (one set per task; moving down one row copies one row).
#[derive(Default)]
struct RowBufs {
    r: [Vec<f64>; 3],
    first: Option<usize>,
}

impl RowBufs {
    fn load(&mut self, p: &Padded, i: usize) {
        match self.first {
            Some(f) if f == i => {}
            Some(f) if f + 1 == i => {
                self.r.rotate_left(1);
                p.row_into(i + 2, &mut self.r[2]);
            }
            _ => {
                for (k, buf) in self.r.iter_mut().enumerate() {
                    p.row_into(i + k, buf);
                }
            }
        }
        self.first = Some(i);
    }
}

/// The squared increments (each assigned to its first sample) of padded row
/// `i`, rows then columns, into `out` (the sums are `0 + row + column`,
/// absent pairs adding 0, as the numpy reference forms them).
fn increments(p: &Padded, i: usize, bufs: &mut RowBufs, out: &mut [Quad]) {
    bufs.load(p, i);
    let m = out.len();
    let [r0, r1, r2] = &bufs.r;
    let (r0, r1, r2) = (&r0[..m + 2], &r1[..m], &r2[..m]);
    for (j, q) in out.iter_mut().enumerate() {
        let a = r0[j];
        let sq = |b: f64| {
            let d = b - a;
            if a.is_finite() && b.is_finite() {
                (d * d, 1)
            } else {
                (0.0, 0)
            }
        };
        let ((v1, n1), (h1, m1)) = (sq(r1[j]), sq(r0[j + 1]));
        let ((v2, n2), (h2, m2)) = (sq(r2[j]), sq(r0[j + 2]));
        *q = Quad {
            s1: v1 + h1,
            s2: v2 + h2,
            c1: n1 + m1,
            c2: n2 + m2,
        };
    }
}

/// The lines (rows or columns) of the window of the node at line `p` that
/// the whole blocks `p / step - q .. p / step + q` (`q = half / step`) leave
/// over, below then above: the fixed order of every node sum is the blocks,
/// then these lines.
fn leftover(p: usize, half: usize, step: usize) -> impl Iterator<Item = usize> {
    let q = half / step;
    (p - half..p - q * step).chain(p + q * step..=p + half)
}

/// `acc += v`, element by element.
fn add_into(acc: &mut [Quad], v: &[Quad]) {
    for (a, b) in acc.iter_mut().zip(v) {
        a.add(b);
    }
}

/// Largest window half side, node step or border accepted (cells).
const MAX_CELLS: usize = 1 << 30;

fn check(z: &ArrayView2<f64>, p: &AnalysisParams) -> CoreResult<usize> {
    if p.half == 0 {
        return Err(CoreError::invalid(
            "half",
            "expected a positive integer, got 0",
        ));
    }
    if p.step == 0 {
        return Err(CoreError::invalid(
            "step",
            "expected a positive integer, got 0",
        ));
    }
    // the halo and the block sizes below stay far from overflowing
    for (name, v) in [("half", p.half), ("step", p.step), ("border", p.border)] {
        if v > MAX_CELLS {
            return Err(CoreError::invalid(
                name,
                format!("expected at most {MAX_CELLS} cells, got {v}"),
            ));
        }
    }
    let (lo, hi) = p.hurst_range;
    if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
        return Err(CoreError::invalid(
            "hurst_range",
            format!("expected finite lo <= hi, got ({lo}, {hi})"),
        ));
    }
    let t = pad_width(p.half, p.step);
    let (r, c) = z.dim();
    let (r, c) = (r + 2 * p.border, c + 2 * p.border);
    if r < 2 * t || c < 2 * t {
        return Err(CoreError::invalid(
            "dem",
            format!(
                "the padded block is {r} x {c}; the halo of window half {} needs at least {} x {}",
                p.half,
                2 * t,
                2 * t
            ),
        ));
    }
    if let Some(a) = &p.area {
        let n = a.hurst.len();
        if n < 2 || a.ratio.len() != n || a.gamma1.len() != n {
            return Err(CoreError::invalid(
                "table",
                "hurst, ratio and gamma1 must have one equal length >= 2",
            ));
        }
        let increasing =
            |v: &[f64]| v.windows(2).all(|w| w[0] < w[1]) && v.iter().all(|x| x.is_finite());
        if !increasing(a.hurst)
            || !increasing(a.ratio)
            || !a.gamma1.iter().all(|g| g.is_finite() && *g > 0.0)
        {
            return Err(CoreError::invalid(
                "table",
                "hurst and ratio must be finite and increasing, gamma1 finite and positive",
            ));
        }
    }
    Ok(t)
}

/// `numpy.interp(x, xp, fp, left, right)` for a finite `x` and an increasing
/// `xp`, with the same arithmetic (the slope of the bracketing interval
/// times the offset from its lower end). The interval is found from a
/// uniform grid of buckets over `xp` and a short scan, which gives the same
/// interval as a binary search.
pub struct Interp<'a> {
    xp: &'a [f64],
    fp: &'a [f64],
    left: f64,
    right: f64,
    /// `numpy.interp`'s slopes, computed once.
    slope: Vec<f64>,
    per_bucket: f64,
    /// The interval holding the lower edge of each bucket.
    start: Vec<usize>,
}

impl<'a> Interp<'a> {
    /// The interpolant of `(xp, fp)`, `xp` increasing with at least 2 values.
    pub fn new(xp: &'a [f64], fp: &'a [f64], left: f64, right: f64) -> Self {
        let n = xp.len();
        let m = 4 * n;
        let per_bucket = m as f64 / (xp[n - 1] - xp[0]);
        let start = (0..m)
            .map(|b| {
                let e = xp[0] + b as f64 / per_bucket;
                xp.partition_point(|&v| v <= e).saturating_sub(1)
            })
            .collect();
        let slope = (0..n - 1)
            .map(|j| (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]))
            .collect();
        Interp {
            xp,
            fp,
            left,
            right,
            slope,
            per_bucket,
            start,
        }
    }

    /// The interpolated value at `x`.
    #[inline]
    pub fn at(&self, x: f64) -> f64 {
        let (xp, fp, n) = (self.xp, self.fp, self.xp.len());
        if x < xp[0] {
            return self.left;
        }
        if x > xp[n - 1] {
            return self.right;
        }
        // the j with xp[j] <= x < xp[j + 1] (or j = n - 1 at the last point)
        let b = (((x - xp[0]) * self.per_bucket) as usize).min(self.start.len() - 1);
        // buckets are narrower than the intervals of the tables used here:
        // one step at most (without a branch); the loops cover any other xp
        let mut j = self.start[b];
        j += usize::from(j + 1 < n && xp[j + 1] <= x);
        while j > 0 && xp[j] > x {
            j -= 1;
        }
        while j + 1 < n && xp[j + 1] <= x {
            j += 1;
        }
        if j == n - 1 || xp[j] == x {
            return fp[j];
        }
        let slope = self.slope[j];
        let y = slope * (x - xp[j]) + fp[j];
        if y.is_nan() {
            let y2 = slope * (x - xp[j + 1]) + fp[j + 1];
            if y2.is_nan() && fp[j] == fp[j + 1] {
                return fp[j];
            }
            return y2;
        }
        y
    }
}

/// The two interpolants of area support: `H` from the ratio, `gamma_B(1)`
/// from `H`.
struct AreaFit<'a> {
    hurst_of_ratio: Interp<'a>,
    gamma1_of_hurst: Interp<'a>,
}

impl<'a> AreaFit<'a> {
    fn new(t: &AreaTable<'a>) -> Self {
        let n = t.gamma1.len();
        AreaFit {
            hurst_of_ratio: Interp::new(t.ratio, t.hurst, -1.0, 9.0),
            gamma1_of_hurst: Interp::new(t.hurst, t.gamma1, t.gamma1[0], t.gamma1[n - 1]),
        }
    }
}

/// Raw `H` and lag-1 variance from `g1` and `g2 / g1` (NaN when none).
#[inline]
fn fit(g1: f64, ratio: f64, area: Option<&AreaFit>, (lo, hi): (f64, f64)) -> (f64, f64) {
    if !(ratio.is_finite() && g1 > 0.0) {
        return (f64::NAN, f64::NAN);
    }
    match area {
        None => (0.5 * ratio.log2(), g1),
        Some(a) => {
            let h = match a.hurst_of_ratio.at(ratio) {
                -1.0 => 0.0,
                9.0 => 2.0,
                h => h,
            };
            let hc = h.max(lo).min(hi);
            (h, g1 / a.gamma1_of_hurst.at(hc))
        }
    }
}

/// The four interpolated sums along a row (one vector each).
#[derive(Default)]
struct Sums {
    s1: Vec<f64>,
    c1: Vec<f64>,
    s2: Vec<f64>,
    c2: Vec<f64>,
}

impl Sums {
    /// The first `n` values of `s1, c1, s2, c2`.
    fn slices(&self, n: usize) -> (&[f64], &[f64], &[f64], &[f64]) {
        (&self.s1[..n], &self.c1[..n], &self.s2[..n], &self.c2[..n])
    }

    /// Node row `nrow` (nodes `la ..`) interpolated to the columns
    /// `t .. t + oc`.
    fn along_columns(&mut self, nrow: &[Quad], la: usize, t: usize, oc: usize, step: usize) {
        for v in [&mut self.s1, &mut self.c1, &mut self.s2, &mut self.c2] {
            v.clear();
        }
        for px in t..t + oc {
            let l = px / step - la;
            let (a, b) = (Quadf::from(&nrow[l]), Quadf::from(&nrow[l + 1]));
            let v = Quadf::lerp(&a, &b, (px % step) as f64 / step as f64);
            self.s1.push(v.s1);
            self.c1.push(v.c1);
            self.s2.push(v.s2);
            self.c2.push(v.c2);
        }
    }
}

/// Local `H` and `sigma` maps of `z` (see the module docs); `z` has a NaN
/// halo of [`pad_width`] cells, `p.border` of them virtual.
pub fn local_maps(z: ArrayView2<f64>, p: &AnalysisParams) -> CoreResult<LocalMaps> {
    let t = check(&z, p)?;
    let zc = z.as_standard_layout();
    let data = zc
        .as_slice()
        .ok_or_else(|| CoreError::Internal("dem not contiguous".into()))?;
    let pad = Padded {
        z: data,
        rows: z.dim().0,
        cols: z.dim().1,
        border: p.border,
    };
    let (n0, n1) = (pad.n_rows(), pad.n_cols());
    let (half, step) = (p.half, p.step);
    let (or, oc) = (n0 - 2 * t, n1 - 2 * t);
    let (hurst, sigma) = (try_zeroed(or * oc, "dem")?, try_zeroed(or * oc, "dem")?);
    if or == 0 || oc == 0 {
        return Ok(LocalMaps {
            hurst: Array2::from_shape_vec((or, oc), hurst).map_err(internal)?,
            sigma: Array2::from_shape_vec((or, oc), sigma).map_err(internal)?,
            n_clipped: 0,
            n_valid: 0,
        });
    }
    let q = half / step;
    // Nodes used by the interpolation: rows ka..=kb, columns la..=lb.
    let (ka, kb) = (t / step, (n0 - t - 1) / step + 1);
    let (la, lb) = (t / step, (n1 - t - 1) / step + 1);
    // Blocks of `step` rows (ka - q .. kb + q), summed row by row.
    let b_first = ka - q;
    let b_count = (kb + q).saturating_sub(b_first);
    let mut blocks = try_filled(b_count * n1, Quad::default(), "dem")?;
    blocks.par_chunks_mut(n1).enumerate().for_each_init(
        || (RowBufs::default(), vec![Quad::default(); n1]),
        |(bufs, line), (bi, acc)| {
            let r0 = (b_first + bi) * step;
            increments(&pad, r0, bufs, acc);
            for r in r0 + 1..r0 + step {
                increments(&pad, r, bufs, line);
                for (a, l) in acc.iter_mut().zip(line.iter()) {
                    a.add(l);
                }
            }
        },
    );
    // Node sums: rows first (whole blocks of rows, then the rows left over),
    // then columns of those (blocks of columns, then the columns left over).
    let nl = lb - la + 1;
    let mut nodes = try_filled((kb - ka + 1) * nl, Quad::default(), "dem")?;
    let cb_first = la - q;
    let cb_count = (lb + q) - cb_first;
    nodes.par_chunks_mut(nl).enumerate().for_each_init(
        || {
            let v = vec![Quad::default(); n1];
            (
                RowBufs::default(),
                v.clone(),
                v,
                vec![Quad::default(); cb_count],
            )
        },
        |(bufs, line, rsum, cblocks), (ki, out)| {
            let k = ka + ki;
            rsum.fill(Quad::default());
            for b in k - q..k + q {
                let b = b - b_first;
                add_into(rsum, &blocks[b * n1..(b + 1) * n1]);
            }
            for r in leftover(k * step, half, step) {
                increments(&pad, r, bufs, line);
                add_into(rsum, line);
            }
            for (bi, cb) in cblocks.iter_mut().enumerate() {
                let c0 = (cb_first + bi) * step;
                *cb = rsum[c0];
                for v in &rsum[c0 + 1..c0 + step] {
                    cb.add(v);
                }
            }
            for (li, o) in out.iter_mut().enumerate() {
                let l = la + li;
                *o = Quad::default();
                for b in l - q..l + q {
                    o.add(&cblocks[b - cb_first]);
                }
                for c in leftover(l * step, half, step) {
                    o.add(&rsum[c]);
                }
            }
        },
    );
    // Interpolation to the pixels (node rows along the columns, then
    // between node rows) and the fit, in groups of `step` rows between two
    // node rows.
    let (lo, hi) = p.hurst_range;
    let area = p.area.as_ref().map(AreaFit::new);
    let mut hurst = hurst;
    let mut sigma = sigma;
    let (n_clipped, n_valid) = hurst
        .par_chunks_mut(step * oc)
        .zip(sigma.par_chunks_mut(step * oc))
        .enumerate()
        .map_init(
            || {
                (
                    Sums::default(),
                    Sums::default(),
                    vec![0.0; oc],
                    vec![0.0; oc],
                    Vec::new(),
                )
            },
            |(v0, v1, g1, ratio, zbuf), (g, (hrows, srows))| {
                let k = t / step + g;
                let node_row = |k: usize| &nodes[(k - ka) * nl..(k - ka + 1) * nl];
                v0.along_columns(node_row(k), la, t, oc, step);
                v1.along_columns(node_row(k + 1), la, t, oc, step);
                let (mut nc, mut nv) = (0u64, 0u64);
                let rows = hrows.chunks_mut(oc).zip(srows.chunks_mut(oc));
                for (r, (hrow, srow)) in rows.enumerate() {
                    let py = t + g * step + r;
                    let u = (py % step) as f64 / step as f64;
                    let w = 1.0 - u;
                    let (g1, ratio) = (&mut g1[..oc], &mut ratio[..oc]);
                    let (a, b) = (v0.slices(oc), v1.slices(oc));
                    for x in 0..oc {
                        let s1 = a.0[x] * w + b.0[x] * u;
                        let c1 = a.1[x] * w + b.1[x] * u;
                        let s2 = a.2[x] * w + b.2[x] * u;
                        let c2 = a.3[x] * w + b.3[x] * u;
                        // g2 / g1 with one division: NaN when either count
                        // or s1 is 0, as (s2 / c2) / (s1 / c1) is
                        g1[x] = s1 / c1;
                        ratio[x] = (s2 * c1) / (c2 * s1);
                    }
                    pad.row_into(py, zbuf);
                    let zrow = &zbuf[t..t + oc];
                    for x in 0..oc {
                        let (h, var1) = if zrow[x].is_finite() {
                            fit(g1[x], ratio[x], area.as_ref(), p.hurst_range)
                        } else {
                            (f64::NAN, f64::NAN)
                        };
                        if h.is_finite() {
                            nv += 1;
                            nc += u64::from(h < lo || h > hi);
                            hrow[x] = h.max(lo).min(hi);
                            srow[x] = if var1.is_finite() { var1.sqrt() } else { 0.0 };
                        } else {
                            hrow[x] = 0.5;
                            srow[x] = 0.0;
                        }
                    }
                }
                (nc, nv)
            },
        )
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    Ok(LocalMaps {
        hurst: Array2::from_shape_vec((or, oc), hurst).map_err(internal)?,
        sigma: Array2::from_shape_vec((or, oc), sigma).map_err(internal)?,
        n_clipped,
        n_valid,
    })
}

fn internal(e: ndarray::ShapeError) -> CoreError {
    CoreError::Internal(e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::run_in_pool;
    use crate::testdata::uniform;

    const RANGE: (f64, f64) = (0.05, 0.95);

    /// A rough surface (random walk in both directions) with NaN holes,
    /// padded by `t` NaN on every side.
    fn surface(r: usize, c: usize, t: usize, seed: u64) -> Array2<f64> {
        let u = uniform(r * c * 2, seed);
        let mut z = Array2::from_shape_fn((r, c), |(i, j)| u[i * c + j] - 0.5);
        for i in 1..r {
            for j in 0..c {
                z[(i, j)] += z[(i - 1, j)];
            }
        }
        for i in 0..r {
            for j in 1..c {
                z[(i, j)] += z[(i, j - 1)];
            }
        }
        for (k, v) in z.iter_mut().enumerate() {
            if u[r * c + k] < 0.05 {
                *v = f64::NAN;
            }
        }
        let mut p = Array2::from_elem((r + 2 * t, c + 2 * t), f64::NAN);
        p.slice_mut(ndarray::s![t..t + r, t..t + c]).assign(&z);
        p
    }

    fn params(half: usize, step: usize, area: Option<AreaTable<'_>>) -> AnalysisParams<'_> {
        AnalysisParams {
            half,
            step,
            border: 0,
            hurst_range: RANGE,
            area,
        }
    }

    /// Direct window sum of the squared increments at `lag` over the window
    /// of half side `half` centred on padded `(p, q)` (every pair counted at
    /// its first sample; pairs reaching into the last 2 rows or columns are
    /// not in any window the kernel uses).
    fn naive_sum(z: &Array2<f64>, p: usize, q: usize, half: usize, lag: usize) -> (f64, f64) {
        let (n0, n1) = z.dim();
        let (mut s, mut c) = (0.0, 0.0);
        for i in p - half..=p + half {
            for j in q - half..=q + half {
                for (di, dj) in [(lag, 0), (0, lag)] {
                    if i + di < n0 && j + dj < n1 {
                        let d = z[(i + di, j + dj)] - z[(i, j)];
                        if d.is_finite() {
                            s += d * d;
                            c += 1.0;
                        }
                    }
                }
            }
        }
        (s, c)
    }

    /// The maps from direct window sums at the 4 nodes around each pixel,
    /// interpolated bilinearly, point support.
    fn naive_maps(z: &Array2<f64>, half: usize, step: usize) -> (Array2<f64>, Array2<f64>) {
        let t = pad_width(half, step);
        let (n0, n1) = z.dim();
        let mut h = Array2::zeros((n0 - 2 * t, n1 - 2 * t));
        let mut s = h.clone();
        for y in t..n0 - t {
            for x in t..n1 - t {
                let (y0, x0) = (y / step * step, x / step * step);
                let (u, v) = ((y - y0) as f64 / step as f64, (x - x0) as f64 / step as f64);
                let mut g = [0.0; 2];
                for (lag, gl) in [1, 2].into_iter().zip(g.iter_mut()) {
                    let (mut ss, mut cc) = (0.0, 0.0);
                    for (dy, wy) in [(0, 1.0 - u), (step, u)] {
                        for (dx, wx) in [(0, 1.0 - v), (step, v)] {
                            let (a, b) = naive_sum(z, y0 + dy, x0 + dx, half, lag);
                            ss += wy * wx * a;
                            cc += wy * wx * b;
                        }
                    }
                    *gl = ss / cc;
                }
                let raw = 0.5 * (g[1] / g[0]).log2();
                let ok = z[(y, x)].is_finite() && raw.is_finite() && g[0] > 0.0;
                h[(y - t, x - t)] = if ok { raw.clamp(RANGE.0, RANGE.1) } else { 0.5 };
                s[(y - t, x - t)] = if ok { g[0].sqrt() } else { 0.0 };
            }
        }
        (h, s)
    }

    fn close(a: &Array2<f64>, b: &Array2<f64>, rtol: f64) {
        assert_eq!(a.dim(), b.dim());
        for (k, (x, y)) in a.iter().zip(b).enumerate() {
            assert!(
                (x - y).abs() <= rtol * y.abs().max(1e-300),
                "{k}: {x} vs {y}"
            );
        }
    }

    #[test]
    fn maps_match_direct_window_sums() {
        // windows smaller than, equal to and larger than the node spacing,
        // non-square blocks
        for (half, step, rows, cols) in [
            (2, 8, 20, 31),
            (4, 4, 25, 18),
            (8, 8, 19, 40),
            (11, 4, 30, 23),
            (6, 3, 17, 17),
        ] {
            let t = pad_width(half, step);
            let z = surface(rows, cols, t, half as u64);
            let m = local_maps(z.view(), &params(half, step, None)).unwrap();
            let (h, s) = naive_maps(&z, half, step);
            close(&m.hurst, &h, 1e-12);
            close(&m.sigma, &s, 1e-12);
            let raw_ok = h
                .iter()
                .zip(z.slice(ndarray::s![t..t + rows, t..t + cols]))
                .filter(|(_, v)| v.is_finite())
                .count();
            assert!(m.n_valid as usize <= raw_ok && m.n_valid > 0);
            assert!(m.hurst.iter().any(|&v| v > RANGE.0 && v < RANGE.1));
        }
    }

    #[test]
    fn blocks_on_the_node_grid_equal_the_whole() {
        let (half, step) = (5, 4);
        let t = pad_width(half, step);
        let z = surface(45, 38, t, 3);
        let whole = local_maps(z.view(), &params(half, step, None)).unwrap();
        // a block of the core starting at (8, 12) with its halo of t cells
        let (r0, c0, r1, c1) = (8, 12, 29, 33);
        let b = z.slice(ndarray::s![r0..r1 + 2 * t, c0..c1 + 2 * t]);
        let part = local_maps(b, &params(half, step, None)).unwrap();
        assert_eq!(part.hurst, whole.hurst.slice(ndarray::s![r0..r1, c0..c1]));
        assert_eq!(part.sigma, whole.sigma.slice(ndarray::s![r0..r1, c0..c1]));
    }

    #[test]
    fn any_thread_count_and_a_virtual_border_give_the_same_bits() {
        let (half, step) = (16, 8);
        let t = pad_width(half, step);
        let z = surface(70, 53, t, 9);
        let one = run_in_pool(Some(1), || local_maps(z.view(), &params(half, step, None))).unwrap();
        let three =
            run_in_pool(Some(3), || local_maps(z.view(), &params(half, step, None))).unwrap();
        assert_eq!(one, three);
        let inner = z.slice(ndarray::s![t..t + 70, t..t + 53]);
        let p = AnalysisParams {
            border: t,
            ..params(half, step, None)
        };
        assert_eq!(local_maps(inner, &p).unwrap(), one);
        // a Fortran-ordered input is read in its logical order
        let f = z.t().as_standard_layout().into_owned().reversed_axes(); // column-major
        assert!(!f.is_standard_layout());
        assert_eq!(
            local_maps(f.view(), &params(half, step, None)).unwrap(),
            one
        );
    }

    #[test]
    fn a_plane_has_h_one_and_its_slope_as_sigma() {
        // z = a i + b j with |a| = |b|: every increment at lag k is a^2 k^2,
        // so g2 / g1 = 4 (H = 1) and sigma = |a|, next to holes and edges too
        let (half, step) = (7, 8);
        let t = pad_width(half, step);
        let (a, b) = (0.3, -0.3);
        let mut z = Array2::from_elem((40 + 2 * t, 33 + 2 * t), f64::NAN);
        for i in 0..40 {
            for j in 0..33 {
                z[(t + i, t + j)] = a * i as f64 + b * j as f64;
            }
        }
        z[(t + 10, t + 12)] = f64::NAN;
        let mut p = params(half, step, None);
        p.hurst_range = (0.0, 2.0);
        let m = local_maps(z.view(), &p).unwrap();
        let sigma = 0.3;
        for ((i, j), &h) in m.hurst.indexed_iter() {
            if (i, j) == (10, 12) {
                assert_eq!((h, m.sigma[(i, j)]), (0.5, 0.0));
            } else {
                assert!((h - 1.0).abs() < 1e-12, "{i} {j} {h}");
                assert!((m.sigma[(i, j)] - sigma).abs() < 1e-12 * sigma);
            }
        }
        assert_eq!((m.n_valid, m.n_clipped), (40 * 33 - 1, 0));
        let m = local_maps(z.view(), &params(half, step, None)).unwrap();
        assert_eq!(m.n_clipped, m.n_valid);
        assert!(m.hurst.iter().all(|&h| h == RANGE.1 || h == 0.5));
    }

    #[test]
    fn interp_is_numpys() {
        let xp = [0.0, 1.0, 3.0];
        let fp = [10.0, 20.0, 0.0];
        let f = Interp::new(&xp, &fp, -1.0, 9.0);
        for (x, y) in [
            (-0.5, -1.0),
            (3.5, 9.0),
            (3.0, 0.0),
            (1.0, 20.0),
            (0.5, 15.0),
            (2.0, 10.0),
        ] {
            assert_eq!(f.at(x), y, "{x}");
        }
        // the buckets give the interval of a binary search
        let xp: Vec<f64> = (0..50).map(|k| (k as f64 * 0.3).exp()).collect();
        let fp: Vec<f64> = xp.iter().map(|x| x.sqrt()).collect();
        let f = Interp::new(&xp, &fp, -1.0, 9.0);
        for x in (0..4000).map(|k| k as f64 * 0.7).chain(xp.iter().copied()) {
            let y = if x < xp[0] {
                -1.0
            } else if x > xp[49] {
                9.0
            } else {
                let j = xp.partition_point(|&v| v <= x) - 1;
                if j == 49 || xp[j] == x {
                    fp[j]
                } else {
                    (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]) * (x - xp[j]) + fp[j]
                }
            };
            assert_eq!(f.at(x), y, "{x}");
        }
    }

    #[test]
    fn area_support_inverts_the_table() {
        // a table of ratio = 2^(2H) (the point model) gives the point maps
        let h: Vec<f64> = (0..=300).map(|k| k as f64 / 200.0).collect();
        let ratio: Vec<f64> = h.iter().map(|h| (2.0 * h).exp2()).collect();
        let gamma1 = vec![1.0; h.len()];
        let table = AreaTable {
            hurst: &h,
            ratio: &ratio,
            gamma1: &gamma1,
        };
        let (half, step) = (6, 4);
        let t = pad_width(half, step);
        let z = surface(30, 27, t, 11);
        let a = local_maps(z.view(), &params(half, step, Some(table))).unwrap();
        let p = local_maps(z.view(), &params(half, step, None)).unwrap();
        assert_eq!(a.sigma, p.sigma);
        assert_eq!((a.n_valid, a.n_clipped), (p.n_valid, p.n_clipped));
        for (x, y) in a.hurst.iter().zip(&p.hurst) {
            assert!((x - y).abs() < 1e-4, "{x} {y}");
        }
    }

    #[test]
    fn bad_input_names_the_parameter() {
        let z = Array2::<f64>::zeros((10, 10));
        let e = local_maps(z.view(), &params(2, 8, None))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("dem: "), "{e}");
        let z = Array2::<f64>::zeros((60, 60));
        for (half, step, name) in [
            (0, 8, "half: "),
            (2, 0, "step: "),
            (usize::MAX - 1, 8, "half: "),
        ] {
            let e = local_maps(z.view(), &params(half, step, None))
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(name), "{e}");
        }
        let bad = [0.0, 0.0];
        let table = AreaTable {
            hurst: &bad,
            ratio: &bad,
            gamma1: &bad,
        };
        let e = local_maps(z.view(), &params(2, 8, Some(table)))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("table: "), "{e}");
        let mut p = params(2, 8, None);
        p.hurst_range = (f64::NAN, 1.0);
        assert!(local_maps(z.view(), &p)
            .unwrap_err()
            .to_string()
            .starts_with("hurst_range: "));
        // an empty core is empty maps
        let z = Array2::<f64>::zeros((32, 34));
        let m = local_maps(z.view(), &params(2, 8, None)).unwrap();
        assert_eq!(m.hurst.dim(), (0, 2));
    }
}
