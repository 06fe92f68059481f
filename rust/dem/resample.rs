//! Fractal resampling: refine a DEM by factors of 2 with the conditional
//! distribution of fractional Brownian motion (fBm) given the coarse samples.
//!
//! Each new sample is the intrinsic (ordinary) kriging mean of fBm given a
//! stencil of samples around it, plus a Gaussian residual with the kriging
//! variance; the new samples of a step are drawn in four phases, each
//! conditioned on the samples of the earlier ones (sequential Gaussian
//! simulation over a moving neighbourhood), so neighbouring residuals get
//! their conditional correlation. The semivariogram is
//! `gamma(d) = sigma^2 d^(2H) / 2` (`d` in cells of the input grid), so
//! increments at lag 1 of the input grid have variance `sigma^2`. A level
//! whose coarse spacing is `2^-l` input cells has residual variances scaled
//! by `2^(-2 H l)`.
//!
//! Two supports:
//!
//! * **point**: the grid `(r, c)` goes to `(2r - 1, 2c - 1)`; the sample
//!   `(i, j)` is kept at `(2i, 2j)`. The diamond step fills cell centres from
//!   the 4 x 4 coarse samples around them (fine offsets `{-3,-1,1,3}^2`), the
//!   square step fills edge midpoints from the 16 nearest samples of the
//!   45-degree lattice of old and diamond samples (fine offsets `(+-1, 0)`,
//!   `(0, +-1)`, `(+-2, +-1)`, `(+-1, +-2)`, `(+-3, 0)`, `(0, +-3)`). Each
//!   step runs in four phases by the parity of the targets' lattice
//!   coordinates (coarse cells for the diamond step, the 45-degree lattice
//!   of edge midpoints for the square step); a target is also conditioned on
//!   its 8 lattice neighbours of the same step drawn in an earlier phase.
//! * **area**: the grid `(r, c)` goes to `(2r, 2c)`; input cells are block
//!   means. Blocks are drawn in four phases by parity; the four children of
//!   a block are drawn jointly from the 7 x 7 coarse cells around it and the
//!   children of its neighbours drawn earlier (see `level_area`), then each
//!   block is shifted so that its mean equals the coarse value.
//!
//! Weights and variances are tabulated once on a grid of `H` (201 values in
//! `[0.01, 0.99]` for the full stencil of each step and phase, 41 for
//! stencils cut by an edge or a hole) and interpolated linearly in `H`.
//! Stencil samples outside the grid or not finite are dropped (the weights
//! are solved for the samples present); a new point-support sample whose 4
//! nearest stencil samples include a non-finite old one is NaN, and an
//! area-support fine cell is NaN when its coarse cell is.
//!
//! Random numbers are keyed by `(seed, level, step, global fine index)`
//! ([`crate::rng`]), so a tile computed with its global origin and a
//! halo of [`HALO`] input cells equals the same window of the whole.
use crate::error::{CoreError, CoreResult};
use crate::parallel::SharedMut;
use crate::rng::StreamKey;
use ndarray::{Array2, ArrayView2, ArrayView3, Axis};
use rayon::prelude::*;
use std::collections::{BTreeSet, HashMap};
use std::sync::{Arc, Mutex, OnceLock};

/// Streams of the resampling noise (disjoint from the synthesis streams).
pub const STREAM_BASE: u64 = 3 << 20;
/// Halo (input cells) that makes a tile equal the whole for any factor: the
/// dependency reach of the point phases (16 fine cells of a level, summing
/// to under 16 input cells) and of the area phases (under 12).
pub const HALO: usize = 16;
/// Range of `H` in the tables; values outside are clamped.
pub const H_MIN: f64 = 0.01;
/// Upper end of the `H` tables.
pub const H_MAX: f64 = 0.99;
const N_FULL: usize = 201;
/// `1 / (H_MAX - H_MIN)`.
const INV_H_SPAN: f64 = 1.0 / (H_MAX - H_MIN);
const N_PARTIAL: usize = 41;
const NS: usize = 16;

/// Support of the input samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Support {
    /// Point samples, kept exactly at `(2^L i, 2^L j)`.
    Point,
    /// Cell means, kept as the mean of each `2^L x 2^L` block.
    Area,
}

/// Options of a resampling run.
#[derive(Debug, Clone, PartialEq)]
pub struct ResampleParams {
    /// Number of x2 levels (factor `2^levels`).
    pub levels: u32,
    /// Sample support.
    pub support: Support,
    /// Random seed.
    pub seed: u64,
    /// Random detail added at level `l` (`detail[l]`); else the mean only.
    pub detail: Vec<bool>,
    /// Global position of the input's first sample in the whole input grid.
    pub origin: (u64, u64),
    /// Number of columns of the whole input grid (the noise key's stride).
    pub global_cols: u64,
}

/// Ordinary kriging of a point target from data that are means of point
/// sets, with the semivariogram `d^(2H) / 2`. Returns the weights (summing to
/// 1) and the kriging variance `Var(Z(x0) - sum w_a Zbar_a)`.
pub fn krige(data: &[Vec<(f64, f64)>], target: (f64, f64), hurst: f64) -> (Vec<f64>, f64) {
    let n = data.len();
    let g = |a: (f64, f64), b: (f64, f64)| {
        let d2 = (a.0 - b.0).powi(2) + (a.1 - b.1).powi(2);
        if d2 == 0.0 {
            0.0
        } else {
            0.5 * d2.powf(hurst)
        }
    };
    let gbar = |s: &[(f64, f64)], t: &[(f64, f64)]| {
        let mut acc = 0.0;
        for &a in s {
            for &b in t {
                acc += g(a, b);
            }
        }
        acc / (s.len() * t.len()) as f64
    };
    let m = n + 1;
    let mut a = vec![0.0; m * m];
    let mut rhs = vec![0.0; m];
    let mut g0 = vec![0.0; n];
    for i in 0..n {
        for j in 0..n {
            a[i * m + j] = gbar(&data[i], &data[j]);
        }
        a[i * m + n] = 1.0;
        a[n * m + i] = 1.0;
        g0[i] = gbar(&data[i], &[target]);
        rhs[i] = g0[i];
    }
    rhs[n] = 1.0;
    let x = solve(a, rhs, m);
    let w = x[..n].to_vec();
    // Var = 2 sum w_a gbar(a, x0) - sum w_a w_b gbar(a, b) - gbar(x0, x0) (= 0).
    let mut var = 0.0;
    for i in 0..n {
        var += 2.0 * w[i] * g0[i];
        for j in 0..n {
            var -= w[i] * w[j] * gbar(&data[i], &data[j]);
        }
    }
    (w, var.max(0.0))
}

/// Gaussian elimination with partial pivoting (small dense systems).
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, m: usize) -> Vec<f64> {
    for k in 0..m {
        let p = (k..m)
            .max_by(|&i, &j| a[i * m + k].abs().total_cmp(&a[j * m + k].abs()))
            .unwrap_or(k);
        if p != k {
            for j in 0..m {
                a.swap(k * m + j, p * m + j);
            }
            b.swap(k, p);
        }
        let d = a[k * m + k];
        if d == 0.0 {
            continue;
        }
        for i in k + 1..m {
            let f = a[i * m + k] / d;
            if f != 0.0 {
                for j in k..m {
                    a[i * m + j] -= f * a[k * m + j];
                }
                b[i] -= f * b[k];
            }
        }
    }
    let mut x = vec![0.0; m];
    for k in (0..m).rev() {
        let mut s = b[k];
        for j in k + 1..m {
            s -= a[k * m + j] * x[j];
        }
        let d = a[k * m + k];
        x[k] = if d == 0.0 { 0.0 } else { s / d };
    }
    x
}

/// Samples of a point stencil at most: the 16 nearest old (or old and
/// diamond) samples, then up to 8 samples of the same step drawn in an
/// earlier phase.
const NP: usize = NS + 8;
/// Point-support tables: step (0 diamond, 1 square) times 4 phases.
const N_POINT: usize = 8;

/// A point stencil: index offsets into the source grid, the data supports
/// (point sets, in coarse units, relative to the target) and the indices of
/// the 4 nearest samples.
#[derive(Debug, Clone)]
pub struct Stencil {
    /// `(row, col)` offsets into the source array: the 16 samples of the
    /// step, then the same-step samples of earlier phases.
    pub offsets: Vec<(isize, isize)>,
    /// Each datum as a set of points (coarse units, target at the origin).
    pub supports: Vec<Vec<(f64, f64)>>,
    /// Indices (into `offsets`) of the 4 nearest samples.
    pub inner: [usize; 4],
}

impl Stencil {
    fn of_points(offsets: Vec<(isize, isize)>, is_inner: fn(isize, isize) -> bool) -> Stencil {
        let supports = offsets
            .iter()
            .map(|&(dr, dc)| vec![(dr as f64 / 2.0, dc as f64 / 2.0)])
            .collect();
        let mut inner = [0; 4];
        let mut ni = 0;
        for (k, &(dr, dc)) in offsets.iter().enumerate() {
            if is_inner(dr, dc) {
                inner[ni] = k;
                ni += 1;
            }
        }
        Stencil {
            offsets,
            supports,
            inner,
        }
    }
    /// Mask with every sample present.
    fn all(&self) -> u32 {
        (1u32 << self.offsets.len()) - 1
    }
}

/// Diamond step of point support: offsets in the fine grid (the 4 x 4 old
/// samples around a cell centre).
pub fn diamond_stencil() -> Stencil {
    let v = [-3isize, -1, 1, 3];
    Stencil::of_points(
        v.iter()
            .flat_map(|&dr| v.iter().map(move |&dc| (dr, dc)))
            .collect(),
        |dr, dc| dr.abs() == 1 && dc.abs() == 1,
    )
}

/// Square step of point support: offsets in the fine grid (the 16 nearest
/// samples of the 45-degree lattice of old and diamond samples).
pub fn square_stencil() -> Stencil {
    let v = [-1.5f64, -0.5, 0.5, 1.5];
    Stencil::of_points(
        v.iter()
            .flat_map(|&u| v.iter().map(move |&w| ((u + w) as isize, (u - w) as isize)))
            .collect(),
        |dr, dc| dr.abs() + dc.abs() == 1,
    )
}

/// Fine offset of the same-step sample at lattice offset `(da, db)`: coarse
/// cells for the diamond step, the 45-degree lattice `(da + db, da - db)`
/// of edge midpoints for the square step.
fn same_step_offset(step: usize, da: isize, db: isize) -> (isize, isize) {
    if step == 0 {
        (2 * da, 2 * db)
    } else {
        (da + db, da - db)
    }
}

/// Lattice coordinates of a point-support target at the global fine
/// position `(gi, gj)` of step `step` (diamond: `i`, `j` odd; square:
/// `i + j` odd): the inverse of [`same_step_offset`].
fn lattice(step: usize, gi: i64, gj: i64) -> (i64, i64) {
    if step == 0 {
        ((gi - 1) / 2, (gj - 1) / 2)
    } else {
        ((gi + gj - 1) / 2, (gi - gj - 1) / 2)
    }
}

/// Phase (0-3) of a target: the parity of its lattice coordinates,
/// `2 (a % 2) + b % 2`.
fn point_phase(step: usize, gi: i64, gj: i64) -> usize {
    let (a, b) = lattice(step, gi, gj);
    2 * a.rem_euclid(2) as usize + b.rem_euclid(2) as usize
}

/// First column (local) of the targets of `(step, ph)` in the row of global
/// index `gi` (they repeat every 4 columns), or `None`.
fn first_target(step: usize, ph: usize, gi: i64, g1: i64) -> Option<usize> {
    (0..4usize).find(|&j| {
        let gj = g1 + j as i64;
        let is_target = if step == 0 {
            gi % 2 == 1 && gj % 2 == 1
        } else {
            (gi + gj) % 2 == 1
        };
        is_target && point_phase(step, gi, gj) == ph
    })
}

/// Stencil of step `step` (0 diamond, 1 square) in phase `ph`: the 16
/// samples of the step and its 8 lattice neighbours drawn in earlier phases
/// (phase 0: none; phase 3: all 8).
pub fn point_stencil(step: usize, ph: usize) -> Stencil {
    let mut st = if step == 0 {
        diamond_stencil()
    } else {
        square_stencil()
    };
    for n in 0..8 {
        let (da, db) = neighbour_offset(n);
        if drawn_before(ph, da, db) {
            let (dr, dc) = same_step_offset(step, da, db);
            st.offsets.push((dr, dc));
            st.supports.push(vec![(dr as f64 / 2.0, dc as f64 / 2.0)]);
        }
    }
    st
}

/// Weights (zero for absent samples) and variance for one `H`.
#[derive(Debug, Clone, Copy)]
struct Entry {
    w: [f64; NP],
    var: f64,
}

/// Kriging tables of a stencil with a mask of present samples, on a grid of H.
#[derive(Debug, Clone)]
struct Table {
    entries: Vec<Entry>,
}

fn h_node(k: usize, n: usize) -> f64 {
    H_MIN + (H_MAX - H_MIN) * k as f64 / (n - 1) as f64
}

impl Table {
    fn build(st: &Stencil, mask: u32, n: usize) -> Table {
        let idx: Vec<usize> = (0..st.offsets.len())
            .filter(|&k| mask & (1 << k) != 0)
            .collect();
        let data: Vec<Vec<(f64, f64)>> = idx.iter().map(|&k| st.supports[k].clone()).collect();
        let entries = (0..n)
            .map(|k| {
                let (w, var) = krige(&data, (0.0, 0.0), h_node(k, n));
                let mut e = Entry { w: [0.0; NP], var };
                for (q, &k) in idx.iter().enumerate() {
                    e.w[k] = w[q];
                }
                e
            })
            .collect();
        Table { entries }
    }
    /// The node `k` when `h` is within 1e-9 (in node units) of one.
    #[inline]
    fn node(&self, h: f64) -> Option<usize> {
        let n = self.entries.len();
        // Multiplication by the constant reciprocal (no division): the
        // 1e-9 tolerance absorbs the last-bit difference.
        let t = (h.clamp(H_MIN, H_MAX) - H_MIN) * ((n - 1) as f64 * INV_H_SPAN);
        // t >= 0: a truncating cast instead of `round` (a libm call
        // without SSE4.1); the same node within the tolerance.
        let k = (t + 0.5) as usize;
        ((t - k as f64).abs() < 1e-9).then_some(k)
    }
    /// Interpolated weights and standard deviation at `h`.
    #[inline]
    fn at(&self, h: f64) -> ([f64; NP], f64) {
        let n = self.entries.len();
        let t = ((h.clamp(H_MIN, H_MAX) - H_MIN) / (H_MAX - H_MIN)) * (n - 1) as f64;
        // t >= 0: the truncating cast is the floor (no libm call).
        let k = (t as usize).min(n - 2);
        let f = t - k as f64;
        let (a, b) = (&self.entries[k], &self.entries[k + 1]);
        let mut w = [0.0; NP];
        for (q, wq) in w.iter_mut().enumerate() {
            *wq = a.w[q] + f * (b.w[q] - a.w[q]);
        }
        (w, (a.var + f * (b.var - a.var)).max(0.0).sqrt())
    }
}

/// The stencils of the point steps, indexed `4 step + phase`.
fn all_stencils() -> [Stencil; N_POINT] {
    std::array::from_fn(|t| point_stencil(t / 4, t % 4))
}

/// Full-stencil tables (indexed `4 step + phase`), built once per process.
fn full_tables() -> &'static [Table; N_POINT] {
    static T: OnceLock<[Table; N_POINT]> = OnceLock::new();
    T.get_or_init(|| {
        let st = all_stencils();
        let v: Vec<Table> = st
            .par_iter()
            .map(|s| Table::build(s, s.all(), N_FULL))
            .collect();
        std::array::from_fn(|t| v[t].clone())
    })
}

/// Full-stencil weights and standard deviation (unit sigma, coarse units) of
/// stencil `which` (0 diamond, 1 square) in its first phase (the 16 samples
/// of [`diamond_stencil`] or [`square_stencil`]).
pub fn table_at(which: usize, h: f64) -> ([f64; NS], f64) {
    let (w, sd) = full_tables()[4 * which].at(h);
    let mut v = [0.0; NS];
    v.copy_from_slice(&w[..NS]);
    (v, sd)
}

/// Full-stencil weights (one per sample of [`point_stencil`]) and standard
/// deviation of step `step` in phase `ph` (unit sigma, coarse units).
pub fn point_table_at(step: usize, ph: usize, h: f64) -> (Vec<f64>, f64) {
    let n = point_stencil(step, ph).offsets.len();
    let (w, sd) = full_tables()[4 * step + ph].at(h);
    (w[..n].to_vec(), sd)
}

/// Tables for the stencils cut by an edge or a hole, keyed by mask.
struct Partial {
    map: HashMap<u32, Arc<Table>>,
}

/// Process-wide cache of the cut-stencil tables, keyed by (stencil, mask):
/// a table depends only on the geometry, so tiles and repeated calls share it.
type Cache = Mutex<HashMap<(usize, u32), Arc<Table>>>;

fn partial_cache() -> &'static Cache {
    static C: OnceLock<Cache> = OnceLock::new();
    C.get_or_init(|| Mutex::new(HashMap::new()))
}

impl Partial {
    fn build(st: &Stencil, which: usize, masks: BTreeSet<u32>) -> Partial {
        let cache = partial_cache();
        let missing: Vec<u32> = {
            let c = cache.lock().unwrap_or_else(|e| e.into_inner());
            masks
                .iter()
                .copied()
                .filter(|m| !c.contains_key(&(which, *m)))
                .collect()
        };
        let built: Vec<(u32, Arc<Table>)> = missing
            .into_par_iter()
            .map(|m| (m, Arc::new(Table::build(st, m, N_PARTIAL))))
            .collect();
        let mut c = cache.lock().unwrap_or_else(|e| e.into_inner());
        for (m, t) in built {
            c.entry((which, m)).or_insert(t);
        }
        let map = masks
            .into_iter()
            .filter_map(|m| c.get(&(which, m)).map(|t| (m, Arc::clone(t))))
            .collect();
        Partial { map }
    }
}

/// Read-only view of a source grid for stencil lookups.
/// A read-only view of a `rows x cols` grid. It holds a raw pointer, not a
/// `&[f64]`, because during a parallel step other rows write cells of the
/// other parity into the same buffer: a shared slice over memory being
/// written would be undefined behaviour even if the written cells are never
/// read through it.
struct Grid<'a> {
    v: *const f64,
    rows: usize,
    cols: usize,
    /// Point support: only old samples (even row and column) make holes;
    /// area support: no sample of the stencil makes a hole.
    point: bool,
    _buffer: std::marker::PhantomData<&'a [f64]>,
}

// SAFETY: a Grid only reads, and only cells that no thread writes while it
// exists (the parity rule of the steps; a grid built from a slice is not
// written at all), so sharing it between threads is sound.
unsafe impl Sync for Grid<'_> {}

impl<'a> Grid<'a> {
    /// A view of a slice that nothing writes while the view lives.
    fn of(v: &'a [f64], rows: usize, cols: usize, point: bool) -> Self {
        assert_eq!(v.len(), rows * cols);
        Grid {
            v: v.as_ptr(),
            rows,
            cols,
            point,
            _buffer: std::marker::PhantomData,
        }
    }

    /// A view of `rows * cols` values at `v`.
    ///
    /// # Safety
    /// `v` must be valid for reads of `rows * cols` values for `'a`, and the
    /// cells the view reads must not be written while it lives.
    unsafe fn from_raw(v: *const f64, rows: usize, cols: usize, point: bool) -> Self {
        Grid {
            v,
            rows,
            cols,
            point,
            _buffer: std::marker::PhantomData,
        }
    }

    #[inline]
    fn at(&self, k: usize) -> f64 {
        assert!(k < self.rows * self.cols);
        // SAFETY: k is inside the grid (asserted), which the constructors
        // guarantee readable, and the cell is not being written.
        unsafe { self.v.add(k).read() }
    }

    /// Mask of present (inside and finite) samples and whether one of the
    /// inner 4 is present but not finite (the result is then NaN).
    #[inline]
    fn mask(&self, st: &Stencil, i: usize, j: usize) -> (u32, bool) {
        let mut m = 0u32;
        let mut hole = false;
        for (k, &(dr, dc)) in st.offsets.iter().enumerate() {
            let (ii, jj) = (i as isize + dr, j as isize + dc);
            if ii >= 0 && jj >= 0 && (ii as usize) < self.rows && (jj as usize) < self.cols {
                let x = self.at(ii as usize * self.cols + jj as usize);
                if x.is_finite() {
                    m |= 1 << k;
                } else if self.point && ii % 2 == 0 && jj % 2 == 0 && st.inner.contains(&k) {
                    hole = true;
                }
            }
        }
        (m, hole)
    }
    #[inline]
    fn interior(&self, i: usize, j: usize, reach: usize) -> bool {
        i >= reach && j >= reach && i + reach < self.rows && j + reach < self.cols
    }
}

/// Per-point parameter maps on the input grid (row-major), looked up by
/// fine position; a 1 x 1 map is a constant.
struct Maps<'a> {
    h: &'a [f64],
    s: &'a [f64],
    rows: usize,
    cols: usize,
}

impl Maps<'_> {
    #[inline]
    fn at(&self, i: usize, j: usize) -> (f64, f64) {
        let k = i.min(self.rows - 1) * self.cols + j.min(self.cols - 1);
        (self.h[k], self.s[k])
    }
}

/// Collect the masks of the new samples with a cut stencil.
fn collect_masks<F>(
    g: &Grid,
    st: &Stencil,
    rows: usize,
    reach: usize,
    any_nan: bool,
    targets: F,
) -> BTreeSet<u32>
where
    F: Fn(usize) -> std::iter::StepBy<std::ops::Range<usize>> + Sync,
{
    (0..rows)
        .into_par_iter()
        .fold(BTreeSet::new, |mut set, i| {
            let mut add = |j: usize| {
                let (m, hole) = g.mask(st, i, j);
                if !hole && m != st.all() {
                    set.insert(m);
                }
            };
            if !any_nan && i >= reach && i + reach < g.rows {
                // Only the targets near the left and right edges are cut.
                let cols = g.cols;
                targets(i).take_while(|&j| j < reach).for_each(&mut add);
                targets(i)
                    .rev()
                    .take_while(|&j| j >= reach && j + reach >= cols)
                    .for_each(&mut add);
            } else {
                for j in targets(i) {
                    if any_nan || !g.interior(i, j, reach) {
                        add(j);
                    }
                }
            }
            set
        })
        .reduce(BTreeSet::new, |mut a, b| {
            a.extend(b);
            a
        })
}

fn check(
    dem: &ArrayView2<f64>,
    hurst: &ArrayView2<f64>,
    sigma: &ArrayView2<f64>,
    p: &ResampleParams,
) -> CoreResult<()> {
    let (r, c) = dem.dim();
    if r < 2 || c < 2 {
        return Err(CoreError::invalid(
            "dem",
            format!("need at least 2 x 2 samples, got {r} x {c}"),
        ));
    }
    if hurst.dim() != sigma.dim() || (hurst.dim() != (r, c) && hurst.dim() != (1, 1)) {
        return Err(CoreError::invalid(
            "hurst",
            "the hurst and sigma maps must have the shape of dem (or both be 1 x 1)",
        ));
    }
    if p.levels == 0 || p.levels > 12 {
        return Err(CoreError::invalid(
            "factor",
            format!("expected 1 to 12 levels, got {}", p.levels),
        ));
    }
    if p.detail.len() != p.levels as usize {
        return Err(CoreError::invalid("min_scale", "one detail flag per level"));
    }
    Ok(())
}

/// Resample `dem` by `2^levels` (see the module docs). `hurst` and `sigma`
/// are maps on the input grid, or both 1 x 1 for constants (sigma: the lag-1
/// increment standard deviation in height units; NaN in either gives NaN).
pub fn resample(
    dem: ArrayView2<f64>,
    hurst: ArrayView2<f64>,
    sigma: ArrayView2<f64>,
    p: &ResampleParams,
) -> CoreResult<Array2<f64>> {
    resample_levels(
        dem,
        hurst.insert_axis(Axis(0)),
        sigma.insert_axis(Axis(0)),
        p,
    )
}

/// [`resample`] with parameters per level: `hurst` and `sigma` have shape
/// `(n, rows, cols)` or `(n, 1, 1)` with `n = 1` (the same for every level)
/// or `n = levels` (slice `l` for level `l`). At level `l` the semivariogram
/// is `sigma_l^2 d^(2 H_l) / 2` (`d` in input cells): a scale-dependent
/// model enters as the power law matching it at the lags of that level.
pub fn resample_levels(
    dem: ArrayView2<f64>,
    hurst: ArrayView3<f64>,
    sigma: ArrayView3<f64>,
    p: &ResampleParams,
) -> CoreResult<Array2<f64>> {
    let (n, hr, hc) = hurst.dim();
    if hurst.dim() != sigma.dim() || (n != 1 && n != p.levels as usize) {
        return Err(CoreError::invalid(
            "hurst",
            format!(
                "the hurst and sigma parameters must have the same shape, with 1 or {} levels, got {:?} and {:?}",
                p.levels,
                hurst.dim(),
                sigma.dim()
            ),
        ));
    }
    let (hc3, sc3) = (hurst.as_standard_layout(), sigma.as_standard_layout());
    let (h, s) = match (hc3.as_slice(), sc3.as_slice()) {
        (Some(h), Some(s)) => (h, s),
        _ => return Err(CoreError::Internal("maps not contiguous".into())),
    };
    let rc = hr * hc;
    let maps_at = |l: u32| {
        let k = if n == 1 { 0 } else { l as usize };
        Maps {
            h: &h[k * rc..(k + 1) * rc],
            s: &s[k * rc..(k + 1) * rc],
            rows: hr,
            cols: hc,
        }
    };
    check(
        &dem,
        &hurst.index_axis(Axis(0), 0),
        &sigma.index_axis(Axis(0), 0),
        p,
    )?;
    let level = |v: ArrayView2<f64>, l: u32| {
        let maps = maps_at(l);
        match p.support {
            Support::Point => level_point(v, &maps, p, l),
            Support::Area => level_area(v, &maps, p, l),
        }
    };
    let mut cur = level(dem.as_standard_layout().view(), 0)?;
    for l in 1..p.levels {
        cur = level(cur.view(), l)?;
    }
    Ok(cur)
}

fn stream(p: &ResampleParams, level: u32, phase: u64) -> StreamKey {
    StreamKey::new(p.seed, STREAM_BASE + level as u64 * 4 + phase)
}

/// One point-support level: `(r, c)` -> `(2r - 1, 2c - 1)`.
///
/// The diamond step, then the square step, each in four phases by the
/// parity of the targets' lattice coordinates (global, so tiles agree): a
/// target is kriged from the 16 samples of its step and from its 8 lattice
/// neighbours of the same step drawn in an earlier phase, plus a residual
/// with that kriging variance (sequential Gaussian simulation: the
/// residuals of neighbouring new samples get their conditional correlation).
fn level_point(
    coarse: ArrayView2<f64>,
    maps: &Maps,
    p: &ResampleParams,
    l: u32,
) -> CoreResult<Array2<f64>> {
    let (r, c) = coarse.dim();
    let (fr, fc) = (2 * r - 1, 2 * c - 1);
    let cs = coarse
        .as_slice()
        .ok_or_else(|| CoreError::Internal("coarse grid not contiguous".into()))?;
    let any_nan = cs.iter().any(|x| !x.is_finite());
    let mut fine = crate::buffers::try_zeroed(fr * fc, "factor")?;
    // Old samples.
    fine.par_chunks_mut(fc).enumerate().for_each(|(i, row)| {
        if i % 2 == 0 {
            let cr = &cs[(i / 2) * c..(i / 2 + 1) * c];
            for (b, v) in cr.iter().enumerate() {
                row[2 * b] = *v;
            }
        }
    });
    let shift = l + 1; // fine cells per input cell: 2^shift
    let half = 1usize << l;
    let gmul = 1u64 << shift;
    let (g0, g1) = (p.origin.0 * gmul, p.origin.1 * gmul);
    let gcols = (p.global_cols.max(1) - 1) * gmul + 1;
    let scale = 2f64.powi(-(l as i32)); // coarse spacing in input cells
    let detail = p.detail[l as usize];
    let stencils = all_stencils();
    let tables = full_tables();
    for t in 0..N_POINT {
        let (step, ph) = (t / 4, t % 4);
        let st = &stencils[t];
        let full = &tables[t];
        // `(2^-l)^H sd_unit` at every node of the table (see `ParamCache`).
        let node_hf: Vec<f64> = full
            .entries
            .iter()
            .enumerate()
            .map(|(k, e)| h_factor(e.var.max(0.0).sqrt(), h_node(k, N_FULL), scale))
            .collect();
        let all = st.all();
        let key = stream(p, l, step as u64);
        // Targets of row i: the phase's cells of the step (every 4th column).
        let targets =
            move |i: usize| match first_target(step, ph, (g0 + i as u64) as i64, g1 as i64) {
                Some(j0) => (j0..fc).step_by(4),
                None => (0..0).step_by(4),
            };
        let partial = {
            let g = Grid::of(&fine, fr, fc, true);
            Partial::build(st, t, collect_masks(&g, st, fr, 3, any_nan, targets))
        };
        let offs: Vec<isize> = st
            .offsets
            .iter()
            .map(|&(dr, dc)| dr * fc as isize + dc)
            .collect();
        let ptr = SharedMut::new(&mut fine);
        let len = fine.len();
        (0..fr).into_par_iter().for_each(|i| {
            let base = ptr.get();
            // SAFETY: phase `ph` of a step writes only its own targets (row
            // i's, in this task) and reads old samples, samples of the
            // diamond step (square step) and same-step targets of earlier
            // phases: its stencils hold no target of the phase itself, so
            // reads never alias writes; every index is checked against `len`.
            let get = |ii: usize, jj: usize| {
                let k = ii * fc + jj;
                debug_assert!(k < len);
                // SAFETY: k < rows x cols (ii < fr, jj < fc: the mask keeps
                // only samples inside the grid) and the cell is not written
                // in this phase.
                unsafe { *base.add(k) }
            };
            // SAFETY: `base` points to the fr x fc buffer `fine`, alive for
            // the loop; the view reads only cells that this phase does not
            // write.
            let g = unsafe { Grid::from_raw(base as *const f64, fr, fc, true) };
            let mut pc = ParamCache::new(detail, scale);
            let row_inside = !any_nan && i >= 3 && i + 3 < fr;
            for j in targets(i) {
                let (h, s) = maps.at((i + half) >> shift, (j + half) >> shift);
                let val = if !(h.is_finite() && s.is_finite()) {
                    f64::NAN
                } else if row_inside && j >= 3 && j + 3 < fc {
                    pc.update(full, &node_hf, h, s);
                    let c0 = i * fc + j;
                    // Every stencil offset has |dr|, |dc| <= 3.
                    assert!(c0 >= 3 * fc + 3 && c0 + 3 * fc + 3 < len);
                    let mut acc = 0.0;
                    for (w, &o) in pc.weights(full).iter().zip(&offs) {
                        let k = c0.wrapping_add_signed(o);
                        debug_assert!(k < len);
                        // SAFETY: k lies within 3 rows and 3 columns of c0,
                        // inside the buffer (asserted above), and the cell is
                        // not written in this phase.
                        acc += w * unsafe { *base.add(k) };
                    }
                    acc + pc.noise(&key, g0, g1, gcols, i, j)
                } else {
                    let (m, hole) = g.mask(st, i, j);
                    if hole {
                        f64::NAN
                    } else {
                        // The full stencil as in the fast path (the same
                        // bits: a tile's edge and the whole array agree).
                        let (w, sd) = if m == all {
                            pc.update(full, &node_hf, h, s);
                            (*pc.weights(full), pc.sd)
                        } else {
                            match partial.map.get(&m) {
                                Some(t) => {
                                    let (w, sd) = t.at(h);
                                    (w, noise_sd(detail, sd, s, h, scale))
                                }
                                None => (([0.0; NP]), f64::NAN),
                            }
                        };
                        let mut acc = 0.0;
                        for (k, &(dr, dc)) in st.offsets.iter().enumerate() {
                            if m & (1 << k) != 0 {
                                acc += w[k]
                                    * get((i as isize + dr) as usize, (j as isize + dc) as usize);
                            }
                        }
                        acc + draw(sd, &key, g0, g1, gcols, i, j)
                    }
                };
                // SAFETY: (i, j) is a target of this phase in row i, inside the buffer.
                unsafe { *base.add(i * fc + j) = val };
            }
        });
    }
    Array2::from_shape_vec((fr, fc), fine).map_err(|e| CoreError::Internal(e.to_string()))
}

/// Standard deviation of the residual: `sigma (2^-l)^H sd_unit`, or 0 when
/// the level adds no detail.
#[inline]
fn noise_sd(detail: bool, sd_unit: f64, sigma: f64, h: f64, scale: f64) -> f64 {
    if !detail || sigma == 0.0 {
        return 0.0;
    }
    sigma * h_factor(sd_unit, h, scale)
}

/// The part of the residual sd that depends on `H` only: `(2^-l)^H sd_unit`.
#[inline]
fn h_factor(sd_unit: f64, h: f64, scale: f64) -> f64 {
    scale.powf(h.clamp(H_MIN, H_MAX)) * sd_unit
}

/// `sd` times the standard normal keyed by the global fine position.
#[inline]
fn draw(sd: f64, key: &StreamKey, g0: u64, g1: u64, gcols: u64, i: usize, j: usize) -> f64 {
    if sd == 0.0 {
        return 0.0;
    }
    sd * key.normal2(g0 + i as u64, g1 + j as u64, gcols)
}

/// Weights and residual sd of the full stencil for the last `H` seen: the
/// table lookup and the power are redone only when `H` changes (a map of
/// `sigma` alone costs one product per sample).
struct ParamCache {
    h: f64,
    /// The table node of `h`, or `NO_NODE` (then `w` holds the
    /// interpolated weights): a node's weights are read in place, not copied.
    k: usize,
    w: [f64; NP],
    hf: f64,
    sd: f64,
    detail: bool,
    scale: f64,
}

impl ParamCache {
    fn new(detail: bool, scale: f64) -> Self {
        ParamCache {
            h: f64::NAN,
            k: NO_NODE,
            w: [0.0; NP],
            hf: 0.0,
            sd: 0.0,
            detail,
            scale,
        }
    }
    #[inline]
    fn update(&mut self, t: &Table, node_hf: &[f64], h: f64, s: f64) {
        if h.to_bits() != self.h.to_bits() {
            match t.node(h) {
                // H on a node of the table (the estimated maps are rounded
                // to them): its weights, and sd and power from the node.
                Some(k) => {
                    self.k = k;
                    self.hf = node_hf[k];
                }
                None => {
                    let (w, sd) = t.at(h);
                    self.k = NO_NODE;
                    self.w = w;
                    self.hf = h_factor(sd, h, self.scale);
                }
            }
            self.h = h;
        }
        self.sd = if !self.detail || s == 0.0 {
            0.0
        } else {
            s * self.hf
        };
    }
    /// The weights of the last `update` (`t`: the table it was given).
    #[inline]
    fn weights<'t>(&'t self, t: &'t Table) -> &'t [f64; NP] {
        if self.k == NO_NODE {
            &self.w
        } else {
            &t.entries[self.k].w
        }
    }
    #[inline]
    fn noise(&self, key: &StreamKey, g0: u64, g1: u64, gcols: u64, i: usize, j: usize) -> f64 {
        draw(self.sd, key, g0, g1, gcols, i, j)
    }
}

/// `ParamCache::k` when `H` is not on a table node.
const NO_NODE: usize = usize::MAX;

/// One area-support level: `(r, c)` -> `(2r, 2c)`, block means kept.
///
/// Blocks are drawn in four phases by the parity of their global position
/// (`(even, even)`, `(even, odd)`, `(odd, even)`, `(odd, odd)`). The four
/// children of a block are drawn jointly given the 7 x 7 coarse cells around
/// it (the centre included) and the children of its 8 neighbours drawn in an
/// earlier phase (which replace those neighbours' coarse values): their
/// kriging means plus a residual with the joint conditional covariance `C`
/// (rank 3: the centre cell fixes the children's mean), drawn as `L n` for
/// three standard normals with `L` the Cholesky factor of `C` restricted to
/// children 0-2, and the fourth residual minus the sum of the others. This
/// is sequential Gaussian simulation over a moving neighbourhood: residuals
/// of adjacent blocks are correlated as in the fBm.
fn level_area(
    coarse: ArrayView2<f64>,
    maps: &Maps,
    p: &ResampleParams,
    l: u32,
) -> CoreResult<Array2<f64>> {
    let (r, c) = coarse.dim();
    let (fr, fc) = (2 * r, 2 * c);
    let cs = coarse
        .as_slice()
        .ok_or_else(|| CoreError::Internal("coarse grid not contiguous".into()))?;
    let shift = l + 1;
    let gmul = 1u64 << shift;
    let (g0, g1) = (p.origin.0 * gmul, p.origin.1 * gmul);
    let gcols = p.global_cols.max(1) * gmul;
    // Global parity of the first coarse cell of this level.
    let (pi0, pj0) = (
        ((p.origin.0 << l) % 2) as usize,
        ((p.origin.1 << l) % 2) as usize,
    );
    let scale = 2f64.powi(-(l as i32));
    let detail = p.detail[l as usize];
    let key = stream(p, l, 0);
    let mi = area_model(p.levels, l);
    let any_bad = cs.iter().any(|x| !x.is_finite())
        || maps.h.iter().any(|x| !x.is_finite())
        || maps.s.iter().any(|x| !x.is_finite());
    let ok = |i: usize, j: usize| {
        let (h, s) = maps.at(i >> l, j >> l);
        cs[i * c + j].is_finite() && h.is_finite() && s.is_finite()
    };
    let phase_of = |i: usize, j: usize| 2 * ((i + pi0) % 2) + (j + pj0) % 2;
    let inside = |i: usize, j: usize| {
        let w = AR as usize;
        !any_bad && i >= w && j >= w && i + w < r && j + w < c
    };
    let win = AreaWindow { cs, r, c, ok: &ok };
    // Tables of the windows cut by an edge or a hole, per phase.
    let masks: BTreeSet<(usize, AreaMask)> = (0..r)
        .into_par_iter()
        .fold(BTreeSet::new, |mut set, i| {
            for j in 0..c {
                if !inside(i, j) && ok(i, j) {
                    let ph = phase_of(i, j);
                    let m = win.mask(ph, i, j);
                    if m != area_all(ph) {
                        set.insert((ph, m));
                    }
                }
            }
            set
        })
        .reduce(BTreeSet::new, |mut a, b| {
            a.extend(b);
            a
        });
    let partial = area_partial(mi, masks);
    let fulls: [&AreaTable; 4] = std::array::from_fn(|ph| area_full(mi, ph));
    // Full-window gathers per phase: (slot, source offset, from the fine grid).
    let gathers: [Vec<(usize, isize, bool)>; 4] = std::array::from_fn(|ph| {
        let m = area_all(ph);
        (0..NB)
            .filter(|&k| m & (1 << k) != 0)
            .map(|k| {
                let (dr, dc, q) = slot_geometry(k);
                match q {
                    None => (k, dr * c as isize + dc, false),
                    Some(q) => {
                        let (a, b) = ((q / 2) as isize, (q % 2) as isize);
                        (k, (2 * dr + a) * fc as isize + 2 * dc + b, true)
                    }
                }
            })
            .collect()
    });
    let mut fine = crate::buffers::try_zeroed(fr * fc, "factor")?;
    let len = fine.len();
    let ptr = SharedMut::new(&mut fine);
    for ph in 0..4usize {
        let (pi, pj) = (ph / 2, ph % 2);
        let first_i = (pi + 2 - pi0) % 2;
        let first_j = (pj + 2 - pj0) % 2;
        let full = fulls[ph];
        let gather = &gathers[ph];
        (first_i..r).into_par_iter().step_by(2).for_each(|i| {
            let base = ptr.get();
            // SAFETY: phase `ph` writes only the children of blocks of parity
            // `(pi, pj)` (rows `2i`, `2i + 1` of block row `i`) and reads only
            // children of blocks of other parities, written in earlier
            // phases; every index is below `len` (checked where computed).
            let read = |k: usize| {
                assert!(k < len);
                // SAFETY: k < len and the cell is not written in this phase.
                unsafe { *base.add(k) }
            };
            let mut pc = AreaCache::new(detail, scale);
            for j in (first_j..c).step_by(2) {
                let z = cs[i * c + j];
                let (h, s) = maps.at(i >> l, j >> l);
                let f0 = 2 * i * fc + 2 * j;
                let mut v = [0.0; 4];
                if !ok(i, j) {
                    v = [f64::NAN; 4];
                } else {
                    if inside(i, j) {
                        pc.update(full, h, s);
                        let c0 = i * c + j;
                        for &(k, o, from_fine) in gather {
                            let x = if from_fine {
                                read(f0.wrapping_add_signed(o))
                            } else {
                                cs[c0.wrapping_add_signed(o)]
                            };
                            for (q, vq) in v.iter_mut().enumerate() {
                                *vq += pc.e.w[q][k] * x;
                            }
                        }
                    } else {
                        let m = win.mask(ph, i, j);
                        let t = if m == area_all(ph) {
                            full
                        } else {
                            match partial.get(&(ph, m)) {
                                Some(t) => t.as_ref(),
                                None => full,
                            }
                        };
                        pc.update_uncached(t, h, s);
                        for k in (0..NB).filter(|&k| m & (1 << k) != 0) {
                            let (dr, dc, q) = slot_geometry(k);
                            let (ii, jj) = ((i as isize + dr) as usize, (j as isize + dc) as usize);
                            let x = match q {
                                None => cs[ii * c + jj],
                                Some(q) => read((2 * ii + q / 2) * fc + 2 * jj + q % 2),
                            };
                            for (q, vq) in v.iter_mut().enumerate() {
                                *vq += pc.e.w[q][k] * x;
                            }
                        }
                    }
                    let mut e = [0.0; 4];
                    if pc.sd != 0.0 {
                        let (a, b) = (g0 + 2 * i as u64, g1 + 2 * j as u64);
                        let n0 = key.normal2(a, b, gcols);
                        let n1 = key.normal2(a, b + 1, gcols);
                        let n2 = key.normal2(a + 1, b, gcols);
                        let lf = &pc.e.l;
                        e[0] = pc.sd * (lf[0] * n0);
                        e[1] = pc.sd * (lf[1] * n0 + lf[2] * n1);
                        e[2] = pc.sd * (lf[3] * n0 + lf[4] * n1 + lf[5] * n2);
                        e[3] = -(e[0] + e[1] + e[2]);
                    }
                    let em = 0.25 * (e[0] + e[1] + e[2] + e[3]);
                    let vm = 0.25 * (v[0] + v[1] + v[2] + v[3]);
                    for q in 0..4 {
                        v[q] = v[q] - vm + z + (e[q] - em);
                    }
                }
                for (q, &vq) in v.iter().enumerate() {
                    let k = f0 + (q / 2) * fc + q % 2;
                    assert!(k < len);
                    // SAFETY: k < len; a child of block (i, j), which only
                    // this task writes, and no task of this phase reads.
                    unsafe { *base.add(k) = vq };
                }
            }
        });
    }
    Array2::from_shape_vec((fr, fc), fine).map_err(|e| CoreError::Internal(e.to_string()))
}

/// Half-width of the area coarse window (7 x 7 coarse cells around the
/// parent: with 5 x 5, the first phase's children keep a conditional
/// variance 1.2 % above the one given 9 x 9 cells at H = 0.9, which shows as
/// a crease between the phases; 0.15 % with 7 x 7).
const AR: isize = 3;
/// Cells of the area coarse window.
const NA: usize = (2 * AR as usize + 1) * (2 * AR as usize + 1);
/// Bit set of the data slots of an area window.
type AreaMask = u128;
/// Data slots: the 49 coarse cells, then the 4 children of each of the 8
/// neighbours (`NA + 4 n + q`, neighbours in row-major order without the
/// centre, children 0: top left, 1: top right, 2: bottom left, 3: bottom right).
const NB: usize = NA + 32;
/// H nodes of the area tables (full window) and of cut windows.
const N_AREA: usize = 101;
const N_AREA_PARTIAL: usize = 41;
/// Models of the children's support: `m x m` points, `m = 1, 2, 4`.
const N_MODELS: usize = 3;

#[inline]
fn area_offset(k: usize) -> (isize, isize) {
    let w = 2 * AR as usize + 1;
    ((k / w) as isize - AR, (k % w) as isize - AR)
}

/// Offset of neighbour `n` (0..8, row-major without the centre).
#[inline]
fn neighbour_offset(n: usize) -> (isize, isize) {
    let k = if n < 4 { n } else { n + 1 };
    ((k / 3) as isize - 1, (k % 3) as isize - 1)
}

/// Window cell offset of a slot and, for a child slot, the child index.
#[inline]
fn slot_geometry(k: usize) -> (isize, isize, Option<usize>) {
    if k < NA {
        let (dr, dc) = area_offset(k);
        (dr, dc, None)
    } else {
        let (dr, dc) = neighbour_offset((k - NA) / 4);
        (dr, dc, Some((k - NA) % 4))
    }
}

/// Whether a neighbour at `(dr, dc)` of a block of phase `ph` is drawn in an
/// earlier phase (phases by parity: `2 (row % 2) + col % 2`).
#[inline]
fn drawn_before(ph: usize, dr: isize, dc: isize) -> bool {
    let pr = ((ph / 2) as isize + dr).rem_euclid(2) as usize;
    let pc = ((ph % 2) as isize + dc).rem_euclid(2) as usize;
    2 * pr + pc < ph
}

/// The slots of phase `ph` with every cell present.
fn area_all(ph: usize) -> AreaMask {
    let mut m: AreaMask = 0;
    for k in 0..NA {
        let (dr, dc) = area_offset(k);
        if !(dr.abs() <= 1 && dc.abs() <= 1 && (dr, dc) != (0, 0) && drawn_before(ph, dr, dc)) {
            m |= 1 << k;
        }
    }
    for n in 0..8 {
        let (dr, dc) = neighbour_offset(n);
        if drawn_before(ph, dr, dc) {
            m |= 0xf << (NA + 4 * n);
        }
    }
    m
}

/// A coarse grid and its validity (value and parameters finite), for masks.
struct AreaWindow<'a, F: Fn(usize, usize) -> bool> {
    cs: &'a [f64],
    r: usize,
    c: usize,
    ok: &'a F,
}

impl<F: Fn(usize, usize) -> bool> AreaWindow<'_, F> {
    /// Slots present for the block `(i, j)` of phase `ph`: a neighbour drawn
    /// earlier with finite children gives its children, else its coarse
    /// value if finite; other cells their coarse value if inside and finite.
    fn mask(&self, ph: usize, i: usize, j: usize) -> AreaMask {
        let mut m: AreaMask = 0;
        for k in 0..NA {
            let (dr, dc) = area_offset(k);
            let (ii, jj) = (i as isize + dr, j as isize + dc);
            if ii < 0 || jj < 0 || ii as usize >= self.r || jj as usize >= self.c {
                continue;
            }
            let (ii, jj) = (ii as usize, jj as usize);
            let nb = dr.abs() <= 1 && dc.abs() <= 1 && (dr, dc) != (0, 0);
            if nb && drawn_before(ph, dr, dc) && (self.ok)(ii, jj) {
                let kk = (dr + 1) * 3 + dc + 1;
                let n = if kk < 4 { kk } else { kk - 1 } as usize;
                m |= 0xf << (NA + 4 * n);
            } else if self.cs[ii * self.c + jj].is_finite() {
                m |= 1 << k;
            }
        }
        m
    }
}

/// Index of the support model at level `l` of `levels`: the children of
/// level `l` are means of `2^(levels - 1 - l)` fine points per side (the
/// last level's children are points), capped at 4 x 4 points.
fn area_model(levels: u32, l: u32) -> usize {
    ((levels - 1 - l) as usize).min(N_MODELS - 1)
}

/// Kriging weights of the four children (`w[q][k]`, zero for absent slots)
/// and the Cholesky factor of their conditional covariance restricted to
/// children 0-2 (`l = [l00, l10, l11, l20, l21, l22]`), unit sigma, coarse
/// spacing 1.
#[derive(Debug, Clone, Copy)]
pub struct AreaEntry {
    /// Weights of child `q` (0: top left, 1: top right, 2: bottom left,
    /// 3: bottom right) on data slot `k` (see [`area_solve`]).
    pub w: [[f64; NB]; 4],
    /// Lower Cholesky factor, row-major.
    pub l: [f64; 6],
}

/// Area tables on a grid of `H`.
#[derive(Debug, Clone)]
pub struct AreaTable {
    entries: Vec<AreaEntry>,
}

impl AreaTable {
    /// Entry interpolated linearly in `H` (clamped to the table's range).
    pub fn at(&self, h: f64) -> AreaEntry {
        let n = self.entries.len();
        let t = ((h.clamp(H_MIN, H_MAX) - H_MIN) / (H_MAX - H_MIN)) * (n - 1) as f64;
        // t >= 0: the truncating cast is the floor (no libm call).
        let k = (t as usize).min(n - 2);
        let f = t - k as f64;
        let (a, b) = (&self.entries[k], &self.entries[k + 1]);
        let mut e = *a;
        for q in 0..4 {
            for k in 0..NB {
                e.w[q][k] = a.w[q][k] + f * (b.w[q][k] - a.w[q][k]);
            }
        }
        for k in 0..6 {
            e.l[k] = a.l[k] + f * (b.l[k] - a.l[k]);
        }
        e
    }
}

/// Tables of several `(phase, mask)` windows on `n` H nodes; the mean
/// semivariograms are shared between the windows of one H node.
fn build_tables(mi: usize, windows: &[(usize, AreaMask)], n: usize) -> Vec<AreaTable> {
    let per_h: Vec<Vec<AreaEntry>> = (0..n)
        .into_par_iter()
        .map(|k| {
            let mut g = Gbar::new(1 << mi, h_node(k, n));
            windows
                .iter()
                .map(|&(_, m)| area_solve_with(&mut g, m).0)
                .collect()
        })
        .collect();
    (0..windows.len())
        .map(|w| AreaTable {
            entries: per_h.iter().map(|v| v[w]).collect(),
        })
        .collect()
}

/// Points (coarse units, relative to the block centre) of a block of side
/// `side` sampled by `n x n` points at spacing `side / n`.
fn block_pattern(side: f64, n: usize) -> Vec<(f64, f64)> {
    let mut v = Vec::with_capacity(n * n);
    for a in 0..n {
        for b in 0..n {
            v.push((
                side * ((a as f64 + 0.5) / n as f64 - 0.5),
                side * ((b as f64 + 0.5) / n as f64 - 0.5),
            ));
        }
    }
    v
}

/// Mean semivariograms `d^(2H) / 2` between coarse cells (`2m x 2m` points)
/// and children (`m x m` points), memoised by kinds and centre offset (in
/// quarters of a coarse cell).
struct Gbar {
    hurst: f64,
    pats: [Vec<(f64, f64)>; 2],
    memo: HashMap<(u8, u8, i32, i32), f64>,
}

impl Gbar {
    fn new(m: usize, hurst: f64) -> Self {
        Gbar {
            hurst,
            pats: [block_pattern(1.0, 2 * m), block_pattern(0.5, m)],
            memo: HashMap::new(),
        }
    }
    /// `a`, `b`: (kind 0 coarse / 1 child, centre row, centre col in quarters).
    fn get(&mut self, a: (u8, i32, i32), b: (u8, i32, i32)) -> f64 {
        let key = (a.0, b.0, a.1 - b.1, a.2 - b.2);
        if let Some(&v) = self.memo.get(&key) {
            return v;
        }
        let (p, q) = (&self.pats[a.0 as usize], &self.pats[b.0 as usize]);
        let d = (key.2 as f64 / 4.0, key.3 as f64 / 4.0);
        let mut acc = 0.0;
        for x in p {
            for y in q {
                let d2 = (x.0 - y.0 + d.0).powi(2) + (x.1 - y.1 + d.1).powi(2);
                if d2 > 0.0 {
                    acc += 0.5 * d2.powf(self.hurst);
                }
            }
        }
        let v = acc / (p.len() * q.len()) as f64;
        self.memo.insert(key, v);
        v
    }
}

/// Support of data slot `k`: (kind, centre in quarters of a coarse cell).
fn slot_support(k: usize) -> (u8, i32, i32) {
    let (dr, dc, q) = slot_geometry(k);
    match q {
        None => (0, 4 * dr as i32, 4 * dc as i32),
        Some(q) => (
            1,
            4 * dr as i32 + 2 * (q / 2) as i32 - 1,
            4 * dc as i32 + 2 * (q % 2) as i32 - 1,
        ),
    }
}

/// Exact area kriging for children of `m x m` points (parents `2m x 2m`),
/// with the data slots in `mask` (slots
/// `0..49`: the 7 x 7 coarse cells, row-major, offsets -3..=3; slots
/// `49 + 4 n + q`: child `q` of neighbour `n`, the 8 neighbours row-major
/// without the centre): the entry and the full conditional covariance of
/// the four children (for tests).
pub fn area_solve(m: usize, mask: AreaMask, hurst: f64) -> (AreaEntry, [[f64; 4]; 4]) {
    area_solve_with(&mut Gbar::new(m, hurst), mask)
}

/// The slots of phase `ph` with every cell present (for tests).
pub fn area_full_mask(ph: usize) -> AreaMask {
    area_all(ph)
}

fn area_solve_with(g: &mut Gbar, mask: AreaMask) -> (AreaEntry, [[f64; 4]; 4]) {
    let idx: Vec<usize> = (0..NB).filter(|&k| mask & (1 << k) != 0).collect();
    let sup: Vec<(u8, i32, i32)> = idx.iter().map(|&k| slot_support(k)).collect();
    let child = |q: usize| (1u8, 2 * (q / 2) as i32 - 1, 2 * (q % 2) as i32 - 1);
    let n = idx.len();
    let mm = n + 1;
    let mut a = vec![0.0; mm * mm];
    for x in 0..n {
        for y in 0..n {
            a[x * mm + y] = g.get(sup[x], sup[y]);
        }
        a[x * mm + n] = 1.0;
        a[n * mm + x] = 1.0;
    }
    let g_kc: Vec<Vec<f64>> = (0..4)
        .map(|q| sup.iter().map(|&s| g.get(s, child(q))).collect())
        .collect();
    let mut e = AreaEntry {
        w: [[0.0; NB]; 4],
        l: [0.0; 6],
    };
    let mut wq = vec![vec![0.0; n]; 4];
    for q in 0..4 {
        let mut rhs = g_kc[q].clone();
        rhs.push(1.0);
        let x = solve(a.clone(), rhs, mm);
        wq[q] = x[..n].to_vec();
        for (t, &k) in idx.iter().enumerate() {
            e.w[q][k] = x[t];
        }
    }
    // Cov(e_q, e_r) = sum_a w_qa g(a, r) + sum_b w_rb g(b, q)
    //               - sum_ab w_qa w_rb g(a, b) - g(q, r).
    let mut cov = [[0.0; 4]; 4];
    for q in 0..4 {
        for rr in 0..4 {
            let mut v = -g.get(child(q), child(rr));
            for x in 0..n {
                v += wq[q][x] * g_kc[rr][x] + wq[rr][x] * g_kc[q][x];
                for y in 0..n {
                    v -= wq[q][x] * wq[rr][y] * a[x * mm + y];
                }
            }
            cov[q][rr] = v;
        }
    }
    // Cholesky of the leading 3 x 3 block (pivots clamped at 0).
    let c = &cov;
    let l00 = c[0][0].max(0.0).sqrt();
    let inv = |x: f64| if x > 0.0 { 1.0 / x } else { 0.0 };
    let l10 = c[1][0] * inv(l00);
    let l11 = (c[1][1] - l10 * l10).max(0.0).sqrt();
    let l20 = c[2][0] * inv(l00);
    let l21 = (c[2][1] - l20 * l10) * inv(l11);
    let l22 = (c[2][2] - l20 * l20 - l21 * l21).max(0.0).sqrt();
    e.l = [l00, l10, l11, l20, l21, l22];
    (e, cov)
}

/// Full-window area tables, one per support model and phase, built on
/// first use (the four phases of a model together).
pub fn area_full(mi: usize, ph: usize) -> &'static AreaTable {
    static T: [OnceLock<[AreaTable; 4]>; N_MODELS] =
        [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    &T[mi].get_or_init(|| {
        let w: Vec<(usize, AreaMask)> = (0..4).map(|ph| (ph, area_all(ph))).collect();
        let v = build_tables(mi, &w, N_AREA);
        std::array::from_fn(|k| v[k].clone())
    })[ph]
}

type AreaCacheMap = Mutex<HashMap<(usize, usize, AreaMask), Arc<AreaTable>>>;

/// Cut-window tables for `masks` (process-wide cache keyed by model, phase
/// and mask).
fn area_partial(
    mi: usize,
    masks: BTreeSet<(usize, AreaMask)>,
) -> HashMap<(usize, AreaMask), Arc<AreaTable>> {
    static C: OnceLock<AreaCacheMap> = OnceLock::new();
    let cache = C.get_or_init(|| Mutex::new(HashMap::new()));
    let missing: Vec<(usize, AreaMask)> = {
        let c = cache.lock().unwrap_or_else(|e| e.into_inner());
        masks
            .iter()
            .copied()
            .filter(|&(ph, m)| !c.contains_key(&(mi, ph, m)))
            .collect()
    };
    let built = build_tables(mi, &missing, N_AREA_PARTIAL);
    let mut c = cache.lock().unwrap_or_else(|e| e.into_inner());
    for (&(ph, m), t) in missing.iter().zip(built) {
        c.entry((mi, ph, m)).or_insert_with(|| Arc::new(t));
    }
    masks
        .into_iter()
        .filter_map(|(ph, m)| c.get(&(mi, ph, m)).map(|t| ((ph, m), Arc::clone(t))))
        .collect()
}

/// Area entry and residual scale for the last `H` seen (`sigma` alone
/// costs one product).
struct AreaCache {
    h: f64,
    e: AreaEntry,
    hf: f64,
    sd: f64,
    detail: bool,
    scale: f64,
    /// The entry came from the full table (a cut window forces a new lookup).
    full: bool,
}

impl AreaCache {
    fn new(detail: bool, scale: f64) -> Self {
        AreaCache {
            h: f64::NAN,
            e: AreaEntry {
                w: [[0.0; NB]; 4],
                l: [0.0; 6],
            },
            hf: 0.0,
            sd: 0.0,
            detail,
            scale,
            full: false,
        }
    }
    #[inline]
    fn update(&mut self, t: &AreaTable, h: f64, s: f64) {
        if !self.full || h.to_bits() != self.h.to_bits() {
            self.set(t, h);
            self.full = true;
        }
        self.set_sigma(s);
    }
    fn update_uncached(&mut self, t: &AreaTable, h: f64, s: f64) {
        self.set(t, h);
        self.set_sigma(s);
        self.full = false;
    }
    fn set(&mut self, t: &AreaTable, h: f64) {
        self.e = t.at(h);
        self.hf = h_factor(1.0, h, self.scale);
        self.h = h;
    }
    #[inline]
    fn set_sigma(&mut self, s: f64) {
        self.sd = if !self.detail || s == 0.0 {
            0.0
        } else {
            s * self.hf
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    fn params(levels: u32, support: Support, detail: bool) -> ResampleParams {
        ResampleParams {
            levels,
            support,
            seed: 7,
            detail: vec![detail; levels as usize],
            origin: (0, 0),
            global_cols: 0,
        }
    }

    fn field(r: usize, c: usize) -> Array2<f64> {
        Array2::from_shape_fn((r, c), |(i, j)| {
            ((i * 7 + j * 3) as f64).sin() * 5.0 + i as f64
        })
    }

    #[test]
    fn weights_sum_to_one_and_are_symmetric() {
        for h in [0.1, 0.5, 0.9] {
            for which in 0..2 {
                let (w, sd) = table_at(which, h);
                let s: f64 = w.iter().sum();
                assert!((s - 1.0).abs() < 1e-9, "{which} {h} {s}");
                assert!(sd > 0.0);
            }
            // Diamond: the 4 inner weights are equal by symmetry.
            let (w, _) = table_at(0, h);
            let st = diamond_stencil();
            for &k in &st.inner {
                assert!((w[k] - w[st.inner[0]]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn square_is_diamond_rotated_and_scaled() {
        // Power variogram: weights invariant to scale, variance scales by 2^-H.
        for h in [0.2, 0.7] {
            let (wd, sdd) = table_at(0, h);
            let (ws, sds) = table_at(1, h);
            let mut a: Vec<f64> = wd.to_vec();
            let mut b: Vec<f64> = ws.to_vec();
            a.sort_by(f64::total_cmp);
            b.sort_by(f64::total_cmp);
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() < 1e-6);
            }
            // Tables interpolate linearly in H: 1e-4; the direct solve is exact.
            assert!((sds * sds / (sdd * sdd) - 2f64.powf(-h)).abs() < 1e-4);
            let (d, s) = (diamond_stencil(), square_stencil());
            let (_, vd) = krige(&d.supports, (0.0, 0.0), h);
            let (_, vs) = krige(&s.supports, (0.0, 0.0), h);
            assert!((vs / vd - 2f64.powf(-h)).abs() < 1e-9, "{}", vs / vd);
        }
    }

    #[test]
    fn brownian_midpoint_closed_form() {
        // 1D Brownian motion (H = 1/2) between two points: weights 1/2, 1/2
        // and variance d/4 for spacing d (here d = 1: Var = 1/4).
        let (w, v) = krige(&[vec![(-0.5, 0.0)], vec![(0.5, 0.0)]], (0.0, 0.0), 0.5);
        assert!((w[0] - 0.5).abs() < 1e-12 && (w[1] - 0.5).abs() < 1e-12);
        assert!((v - 0.25).abs() < 1e-12);
    }

    #[test]
    fn point_keeps_samples_and_mean_is_linear() {
        let z = field(9, 11);
        let h = Array2::from_elem((9, 11), 0.6);
        let s = Array2::from_elem((9, 11), 1.0);
        let out = resample(
            z.view(),
            h.view(),
            s.view(),
            &params(2, Support::Point, true),
        )
        .unwrap();
        assert_eq!(out.dim(), (33, 41));
        for i in 0..9 {
            for j in 0..11 {
                assert_eq!(out[(4 * i, 4 * j)], z[(i, j)]);
            }
        }
        // A plane is reproduced exactly by the mean where every stencil it
        // depends on is whole (weights sum to 1 and every stencil is point
        // symmetric); cut stencils at the edges reproduce constants only (no
        // drift in fBm), and the phases carry that up to `point_reach()`
        // fine cells in.
        let n = 25;
        let h = Array2::from_elem((n, n), 0.6);
        let s = Array2::from_elem((n, n), 1.0);
        let plane = Array2::from_shape_fn((n, n), |(i, j)| 2.0 * i as f64 - 0.5 * j as f64 + 3.0);
        let out = resample(
            plane.view(),
            h.view(),
            s.view(),
            &params(1, Support::Point, false),
        )
        .unwrap();
        let flat = Array2::from_elem((n, n), 4.5);
        let outf = resample(
            flat.view(),
            h.view(),
            s.view(),
            &params(1, Support::Point, false),
        )
        .unwrap();
        assert!(outf.iter().all(|v| (v - 4.5).abs() < 1e-12));
        let (reach, fine) = (point_reach(), 2 * n - 1);
        let mut checked = 0;
        for ((i, j), v) in out.indexed_iter() {
            if i < reach || j < reach || i + reach >= fine || j + reach >= fine {
                continue;
            }
            let e = 2.0 * i as f64 / 2.0 - 0.5 * j as f64 / 2.0 + 3.0;
            assert!((v - e).abs() < 1e-9, "{i} {j} {v} {e}");
            checked += 1;
        }
        assert!(checked > 100);
    }

    /// Reach (fine cells of one level, per axis, the larger of the two) of
    /// the samples a point-support target depends on through the phases of
    /// its level: a stencil sample's offset plus that sample's own reach
    /// (old samples 0; a square step's diamond samples the largest diamond
    /// reach).
    fn point_reach() -> usize {
        let st = all_stencils();
        let mut r = [[0usize; 2]; N_POINT];
        for t in 0..N_POINT {
            let (step, ph) = (t / 4, t % 4);
            // Square targets of phases 0 and 3 lie in odd rows.
            let odd_row = ph == 0 || ph == 3;
            for (k, &(dr, dc)) in st[t].offsets.iter().enumerate() {
                let dep = if k >= NS {
                    let (da, db) = if step == 0 {
                        (dr / 2, dc / 2)
                    } else {
                        ((dr + dc) / 2, (dr - dc) / 2)
                    };
                    let q = 2 * ((ph / 2) as isize + da).rem_euclid(2) as usize
                        + ((ph % 2) as isize + db).rem_euclid(2) as usize;
                    assert!(q < ph);
                    r[4 * step + q]
                } else if step == 1 && (odd_row as isize + dr).rem_euclid(2) == 1 {
                    [0, 1].map(|a| (0..4).map(|q| r[q][a]).max().unwrap_or(0))
                } else {
                    [0, 0]
                };
                r[t][0] = r[t][0].max(dr.unsigned_abs() + dep[0]);
                r[t][1] = r[t][1].max(dc.unsigned_abs() + dep[1]);
            }
        }
        r.iter().flatten().copied().max().unwrap_or(0)
    }

    #[test]
    fn halo_covers_the_dependency_reach() {
        // Level l's fine cells are 2^-(l+1) input cells: a point-support
        // target depends on input cells within sum_l reach 2^-(l+1) < reach;
        // the area phases reach 6 coarse cells per level (a window of
        // half-width 3 plus 3 neighbours drawn in turn; sum < 12).
        let reach = point_reach();
        assert_eq!(reach, 16);
        assert!(HALO >= reach && HALO >= 2 * (AR as usize + 3));
    }

    #[test]
    fn point_phases_condition_on_earlier_phases() {
        // Phase k of a step adds its lattice neighbours drawn in phases < k
        // (0, 2, 6, 8 of them); the weights still sum to 1, are point
        // symmetric, and every later phase has a smaller kriging variance.
        for step in 0..2 {
            for h in [0.2, 0.5, 0.9] {
                let (_, sd0) = point_table_at(step, 0, h);
                for ph in 0..4 {
                    let st = point_stencil(step, ph);
                    assert_eq!(st.offsets.len(), NS + [0, 2, 6, 8][ph]);
                    let (w, sd) = point_table_at(step, ph, h);
                    assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-9);
                    for (k, &(dr, dc)) in st.offsets.iter().enumerate() {
                        let m = st.offsets.iter().position(|&o| o == (-dr, -dc)).unwrap();
                        assert!((w[k] - w[m]).abs() < 1e-9, "{step} {ph} {h} {k}");
                    }
                    if ph > 0 {
                        assert!(sd < sd0, "{step} {ph} {h}");
                    }
                }
            }
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn area_joint_draw_matches_point_kriging() {
        // Children of 1 point: each child's weights and variance equal the
        // point kriging of `krige` from the 49 window cells (2 x 2 points
        // each); the joint covariance has rows summing to 0 (the centre cell
        // fixes the mean) and L L^T reproduces its leading 3 x 3 block.
        for h in [0.2, 0.5, 0.8] {
            let (e, cov) = area_solve(1, area_full_mask(0), h);
            let data: Vec<Vec<(f64, f64)>> = (0..NA)
                .map(|k| {
                    let (dr, dc) = area_offset(k);
                    block_pattern(1.0, 2)
                        .into_iter()
                        .map(|(y, x)| (y + dr as f64, x + dc as f64))
                        .collect()
                })
                .collect();
            for q in 0..4 {
                let t = (-0.25 + 0.5 * (q / 2) as f64, -0.25 + 0.5 * (q % 2) as f64);
                let (w, v) = krige(&data, t, h);
                for k in 0..NA {
                    assert!((w[k] - e.w[q][k]).abs() < 1e-9, "{h} {q} {k}");
                }
                assert!(
                    (v - cov[q][q]).abs() < 1e-9 * v,
                    "{h} {q} {v} {}",
                    cov[q][q]
                );
                let row: f64 = cov[q].iter().sum();
                assert!(row.abs() < 1e-9 * v, "{h} {q} {row}");
            }
            let l = e.l;
            let ll = [
                [l[0] * l[0], l[0] * l[1], l[0] * l[3]],
                [
                    l[1] * l[0],
                    l[1] * l[1] + l[2] * l[2],
                    l[1] * l[3] + l[2] * l[4],
                ],
                [
                    l[3] * l[0],
                    l[3] * l[1] + l[4] * l[2],
                    l[3] * l[3] + l[4] * l[4] + l[5] * l[5],
                ],
            ];
            for a in 0..3 {
                for b in 0..3 {
                    assert!((ll[a][b] - cov[a][b]).abs() < 1e-9, "{h} {a} {b}");
                }
            }
        }
        // Larger child supports: still rank 3 (rows sum to 0).
        let (_, cov) = area_solve(2, area_full_mask(3), 0.7);
        for row in cov {
            assert!(row.iter().sum::<f64>().abs() < 1e-9);
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn area_later_phases_krige_on_neighbour_children() {
        // Phase 3 (every neighbour drawn): the weights and the conditional
        // variance of each child equal point kriging (`krige`) from the
        // 41 coarse cells left (2 x 2 points each) and the 32 neighbour
        // children (points); the centre cell still fixes the mean.
        for ph in 1..4 {
            let mask = area_full_mask(ph);
            let n_child = (NA..NB).filter(|&k| mask & (1 << k) != 0).count();
            assert_eq!(n_child, [0, 8, 24, 32][ph]);
        }
        for h in [0.3, 0.8] {
            let mask = area_full_mask(3);
            let (e, cov) = area_solve(1, mask, h);
            let idx: Vec<usize> = (0..NB).filter(|&k| mask & (1 << k) != 0).collect();
            let data: Vec<Vec<(f64, f64)>> = idx
                .iter()
                .map(|&k| {
                    let (dr, dc, q) = slot_geometry(k);
                    match q {
                        None => block_pattern(1.0, 2)
                            .into_iter()
                            .map(|(y, x)| (y + dr as f64, x + dc as f64))
                            .collect(),
                        Some(q) => vec![(
                            dr as f64 - 0.25 + 0.5 * (q / 2) as f64,
                            dc as f64 - 0.25 + 0.5 * (q % 2) as f64,
                        )],
                    }
                })
                .collect();
            for q in 0..4 {
                let t = (-0.25 + 0.5 * (q / 2) as f64, -0.25 + 0.5 * (q % 2) as f64);
                let (w, v) = krige(&data, t, h);
                for (x, &k) in idx.iter().enumerate() {
                    assert!((w[x] - e.w[q][k]).abs() < 1e-8, "{h} {q} {k}");
                }
                assert!((v - cov[q][q]).abs() < 1e-8 * v, "{h} {q}");
                assert!(cov[q].iter().sum::<f64>().abs() < 1e-9 * v);
            }
            // Conditioning on the neighbours' children lowers the variance.
            let (_, cov0) = area_solve(1, area_full_mask(0), h);
            assert!(cov[0][0] < cov0[0][0]);
        }
    }

    #[test]
    fn area_window_is_wide_enough() {
        // The first phase conditions on the window's coarse cells only: its
        // children's conditional variance is within 0.3 % of point kriging
        // (`krige`) from 11 x 11 cells (2 x 2 points each) at H = 0.9.
        let h = 0.9;
        let (_, cov) = area_solve(1, area_full_mask(0), h);
        let data: Vec<Vec<(f64, f64)>> = (-5..=5)
            .flat_map(|dr| (-5..=5).map(move |dc| (dr, dc)))
            .map(|(dr, dc)| {
                block_pattern(1.0, 2)
                    .into_iter()
                    .map(|(y, x)| (y + dr as f64, x + dc as f64))
                    .collect()
            })
            .collect();
        let (_, v) = krige(&data, (-0.25, -0.25), h);
        assert!(cov[0][0] > v && cov[0][0] < 1.003 * v, "{} {v}", cov[0][0]);
    }

    #[test]
    fn area_keeps_block_means() {
        let z = field(8, 10);
        let h = Array2::from_elem((8, 10), 0.4);
        let s = Array2::from_elem((8, 10), 2.0);
        let out = resample(
            z.view(),
            h.view(),
            s.view(),
            &params(2, Support::Area, true),
        )
        .unwrap();
        assert_eq!(out.dim(), (32, 40));
        for i in 0..8 {
            for j in 0..10 {
                let mut m = 0.0;
                for a in 0..4 {
                    for b in 0..4 {
                        m += out[(4 * i + a, 4 * j + b)];
                    }
                }
                assert!((m / 16.0 - z[(i, j)]).abs() < 1e-9 * (1.0 + z[(i, j)].abs()));
            }
        }
    }

    #[test]
    fn tiles_equal_the_whole() {
        let (r, c) = (64, 68);
        let z = field(r, c);
        let h = Array2::from_shape_fn((r, c), |(i, j)| 0.3 + 0.01 * ((i + j) % 40) as f64);
        let s = Array2::from_elem((r, c), 1.5);
        for support in [Support::Point, Support::Area] {
            let mut p = params(3, support, true);
            p.global_cols = c as u64;
            let whole = resample(z.view(), h.view(), s.view(), &p).unwrap();
            let (a0, a1, b0, b1) = (18usize, 44usize, 17usize, 50usize);
            let (t0, t1, u0, u1) = (a0 - HALO, a1 + HALO, b0 - HALO, b1 + HALO);
            let mut q = p.clone();
            q.origin = (t0 as u64, u0 as u64);
            let tile = resample(
                z.slice(ndarray::s![t0..t1, u0..u1]),
                h.slice(ndarray::s![t0..t1, u0..u1]),
                s.slice(ndarray::s![t0..t1, u0..u1]),
                &q,
            )
            .unwrap();
            let f = 8;
            for i in a0 * f..a1 * f {
                for j in b0 * f..b1 * f {
                    let x = tile[(i - t0 * f, j - u0 * f)];
                    assert_eq!(x.to_bits(), whole[(i, j)].to_bits(), "{support:?} {i} {j}");
                }
            }
        }
    }

    #[test]
    fn per_level_parameters() {
        // Equal slices give the 2D result bit for bit; changing the last
        // level's slice changes only what that level draws (the mean of the
        // first level's samples is kept: even fine positions equal the
        // one-level result).
        let z = field(20, 24);
        let h = Array2::from_elem((20, 24), 0.6);
        let s = Array2::from_elem((20, 24), 1.5);
        for support in [Support::Point, Support::Area] {
            let p = params(2, support, true);
            let whole = resample(z.view(), h.view(), s.view(), &p).unwrap();
            let h3 = ndarray::stack![Axis(0), h, h];
            let s3 = ndarray::stack![Axis(0), s, s];
            let lv = resample_levels(z.view(), h3.view(), s3.view(), &p).unwrap();
            assert!(whole
                .iter()
                .zip(lv.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            let s3b = ndarray::stack![Axis(0), s, s.mapv(|x| 0.0 * x)];
            let lv0 = resample_levels(z.view(), h3.view(), s3b.view(), &p).unwrap();
            assert!(whole.iter().zip(lv0.iter()).any(|(a, b)| a != b));
            let bad = resample_levels(
                z.view(),
                ndarray::stack![Axis(0), h, h, h].view(),
                ndarray::stack![Axis(0), s, s, s].view(),
                &p,
            );
            assert!(bad.is_err());
        }
        let p = params(2, Support::Point, true);
        let one = resample(
            z.view(),
            h.view(),
            s.view(),
            &params(1, Support::Point, true),
        )
        .unwrap();
        let s3b = ndarray::stack![Axis(0), s, s.mapv(|x| 0.0 * x)];
        let h3 = ndarray::stack![Axis(0), h, h];
        let lv0 = resample_levels(z.view(), h3.view(), s3b.view(), &p).unwrap();
        for ((i, j), v) in one.indexed_iter() {
            assert_eq!(v.to_bits(), lv0[(2 * i, 2 * j)].to_bits());
        }
    }

    #[test]
    fn holes_stay_holes() {
        let mut z = field(12, 12);
        z[(5, 5)] = f64::NAN;
        let h = Array2::from_elem((12, 12), 0.5);
        let s = Array2::from_elem((12, 12), 1.0);
        let out = resample(
            z.view(),
            h.view(),
            s.view(),
            &params(1, Support::Point, true),
        )
        .unwrap();
        assert!(out[(10, 10)].is_nan());
        assert!(out[(9, 9)].is_nan() && out[(11, 10)].is_nan());
        assert!(out[(8, 9)].is_finite() && out[(10, 7)].is_finite());
        let n_nan = out.iter().filter(|x| x.is_nan()).count();
        assert_eq!(n_nan, 1 + 4 + 4);
        let out = resample(
            z.view(),
            h.view(),
            s.view(),
            &params(1, Support::Area, true),
        )
        .unwrap();
        let n_nan = out.iter().filter(|x| x.is_nan()).count();
        assert_eq!(n_nan, 4);
        assert!(out[(10, 10)].is_nan() && out[(11, 11)].is_nan());
    }
}
