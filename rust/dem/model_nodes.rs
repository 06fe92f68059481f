//! Window sums of the scale-aware ("smooth") resampling model's analysis
//! (`python/fractalgeo_rs/dem/_resample_model.py`): the sums of squared
//! increments and their counts at several lags, and the bilinear
//! interpolation of node values to the pixels.
//!
//! Every sample `(i, j)` of a NaN-padded block carries, for each lag `k`,
//! the squared increments to `(i + k, j)` and `(i, j + k)` whose two ends
//! are finite (`0 + row + column`, absent pairs adding 0) and their count.
//! These are summed over the `(2 half + 1)^2` window at the nodes
//! `(k step, l step)` of the block whose window fits (`half <= k step` and
//! `k step + half <= n - 3`), in the fixed order of the numpy reference
//! (`_resample_grid.node_sums`): blocks of `step` rows aligned on the node
//! grid, then the rows left over, then the same along the columns of those
//! row sums. Each node sum therefore depends on its window only, gives the
//! same bits as the numpy reference and is the same for any number of
//! threads.
use crate::buffers::try_zeroed;
use crate::error::{CoreError, CoreResult};
use ndarray::ArrayView3;
use rayon::prelude::*;

/// Largest window half side, node step or lag accepted (cells).
const MAX_CELLS: usize = 1 << 30;

/// The node sums of a block: `sums` and `counts` are `(lags, rows, cols)`
/// row-major; node `(a, b)` is the pixel `((k0r + a) step, (k0c + b) step)`.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeVariograms {
    pub sums: Vec<f64>,
    pub counts: Vec<f64>,
    pub rows: usize,
    pub cols: usize,
    pub k0r: usize,
    pub k0c: usize,
}

/// The nodes `k0 .. k1` along a line of `n` samples (empty when none fits),
/// as `_resample_grid.node_sums` takes them.
fn node_range(n: usize, half: usize, step: usize) -> (usize, usize) {
    let k0 = half.div_ceil(step);
    let k1 = if n >= 3 + half {
        (n - 3 - half) / step + 1
    } else {
        0
    };
    (k0, k1.max(k0))
}

/// Squared increments and counts of row `i` at every lag, lag-major
/// (`s[l * n1 + j]`).
fn increments(
    z: &[f64],
    n0: usize,
    n1: usize,
    lags: &[usize],
    i: usize,
    s: &mut [f64],
    c: &mut [f64],
) {
    let row = &z[i * n1..(i + 1) * n1];
    for (li, &lag) in lags.iter().enumerate() {
        let (sl, cl) = (
            &mut s[li * n1..(li + 1) * n1],
            &mut c[li * n1..(li + 1) * n1],
        );
        // branch-free (vectorised): an absent pair adds 0, which leaves a
        // non-negative sum's bits unchanged
        if i + lag < n0 {
            let below = &z[(i + lag) * n1..(i + lag + 1) * n1];
            let pairs = row.iter().zip(below);
            for ((s, c), (&a, &b)) in sl.iter_mut().zip(cl.iter_mut()).zip(pairs) {
                let d = b - a;
                let ok = a.is_finite() & b.is_finite();
                *s = if ok { d * d } else { 0.0 };
                *c = if ok { 1.0 } else { 0.0 };
            }
        } else {
            sl.fill(0.0);
            cl.fill(0.0);
        }
        if lag < n1 {
            let pairs = row.iter().zip(&row[lag..]);
            for ((s, c), (&a, &b)) in sl.iter_mut().zip(cl.iter_mut()).zip(pairs) {
                let d = b - a;
                let ok = a.is_finite() & b.is_finite();
                *s += if ok { d * d } else { 0.0 };
                *c += if ok { 1.0 } else { 0.0 };
            }
        }
    }
}

/// The lines of the window of the node at line `p` that the whole blocks
/// leave over, below then above (the order of the numpy reference).
fn leftover(p: usize, half: usize, step: usize) -> impl Iterator<Item = usize> {
    let q = half / step;
    (p - half..p - q * step).chain(p + q * step..=p + half)
}

fn add_into(acc: &mut [f64], v: &[f64]) {
    for (a, b) in acc.iter_mut().zip(v) {
        *a += b;
    }
}

fn check(half: usize, step: usize, lags: &[usize]) -> CoreResult<()> {
    if step == 0 {
        return Err(CoreError::invalid(
            "step",
            "expected a positive integer, got 0",
        ));
    }
    if lags.is_empty() || lags.contains(&0) {
        return Err(CoreError::invalid(
            "lags",
            "expected one or more positive integers",
        ));
    }
    for (name, v) in [("half", half), ("step", step)]
        .into_iter()
        .chain(lags.iter().map(|&l| ("lags", l)))
    {
        if v > MAX_CELLS {
            return Err(CoreError::invalid(
                name,
                format!("expected at most {MAX_CELLS} cells, got {v}"),
            ));
        }
    }
    Ok(())
}

/// Node sums of squared increments and their counts at every lag of `lags`
/// over the windows of half side `half` of the row-major block `z`
/// (`n0 x n1`, see the module docs).
pub fn node_variograms(
    z: &[f64],
    (n0, n1): (usize, usize),
    half: usize,
    step: usize,
    lags: &[usize],
) -> CoreResult<NodeVariograms> {
    check(half, step, lags)?;
    if z.len() != n0 * n1 {
        return Err(CoreError::Internal("dem shape".into()));
    }
    let nl = lags.len();
    let q = half / step;
    let (k0r, k1r) = node_range(n0, half, step);
    let (k0c, k1c) = node_range(n1, half, step);
    let (nr, nc) = (k1r - k0r, k1c - k0c);
    let mut sums = try_zeroed(nl * nr * nc, "dem")?;
    let mut counts = try_zeroed(nl * nr * nc, "dem")?;
    let empty = NodeVariograms {
        sums: Vec::new(),
        counts: Vec::new(),
        rows: nr,
        cols: nc,
        k0r,
        k0c,
    };
    if nr == 0 || nc == 0 {
        return Ok(empty);
    }
    let w = nl * n1;
    // Blocks of `step` rows k0r - q .. k1r - 1 + q, each the rows in order.
    let b_first = k0r - q;
    let b_count = if q == 0 { 0 } else { nr - 1 + 2 * q };
    let mut bsum = try_zeroed(b_count * w, "dem")?;
    let mut bcnt = try_zeroed(b_count * w, "dem")?;
    bsum.par_chunks_mut(w)
        .zip(bcnt.par_chunks_mut(w))
        .enumerate()
        .for_each_init(
            || (vec![0.0; w], vec![0.0; w]),
            |(ls, lc), (bi, (s, c))| {
                let r0 = (b_first + bi) * step;
                increments(z, n0, n1, lags, r0, s, c);
                for r in r0 + 1..r0 + step {
                    increments(z, n0, n1, lags, r, ls, lc);
                    add_into(s, ls);
                    add_into(c, lc);
                }
            },
        );
    // Per node row: the row sums (blocks, then rows left over), then the
    // column sums of those (blocks of columns, then columns left over).
    let cb_first = k0c - q;
    let cb_count = if q == 0 { 0 } else { nc - 1 + 2 * q };
    let mut rows_out: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    (0..nr)
        .into_par_iter()
        .map_init(
            || {
                (
                    vec![0.0; w],
                    vec![0.0; w],
                    vec![0.0; w],
                    vec![0.0; w],
                    vec![0.0; cb_count],
                )
            },
            |(ls, lc, rs, rc, cblk), ki| {
                let k = k0r + ki;
                rs.fill(0.0);
                rc.fill(0.0);
                for b in k - q..k + q {
                    let b = b - b_first;
                    add_into(rs, &bsum[b * w..(b + 1) * w]);
                    add_into(rc, &bcnt[b * w..(b + 1) * w]);
                }
                for r in leftover(k * step, half, step) {
                    increments(z, n0, n1, lags, r, ls, lc);
                    add_into(rs, ls);
                    add_into(rc, lc);
                }
                let mut os = vec![0.0; nl * nc];
                let mut oc = vec![0.0; nl * nc];
                for li in 0..nl {
                    for (src, dst) in [(&*rs, &mut os), (&*rc, &mut oc)] {
                        let line = &src[li * n1..(li + 1) * n1];
                        for (bi, cb) in cblk.iter_mut().enumerate() {
                            let c0 = (cb_first + bi) * step;
                            *cb = line[c0];
                            for v in &line[c0 + 1..c0 + step] {
                                *cb += v;
                            }
                        }
                        for (a, o) in dst[li * nc..(li + 1) * nc].iter_mut().enumerate() {
                            let l = k0c + a;
                            let mut acc = 0.0;
                            for b in l - q..l + q {
                                acc += cblk[b - cb_first];
                            }
                            for cc in leftover(l * step, half, step) {
                                acc += line[cc];
                            }
                            *o = acc;
                        }
                    }
                }
                (os, oc)
            },
        )
        .collect_into_vec(&mut rows_out);
    for (ki, (os, oc)) in rows_out.into_iter().enumerate() {
        for li in 0..nl {
            let d = (li * nr + ki) * nc;
            sums[d..d + nc].copy_from_slice(&os[li * nc..(li + 1) * nc]);
            counts[d..d + nc].copy_from_slice(&oc[li * nc..(li + 1) * nc]);
        }
    }
    Ok(NodeVariograms {
        sums,
        counts,
        ..empty
    })
}

/// Bilinear interpolation of node values `v` (`(maps, node rows, node
/// cols)`, node `(a, b)` at pixel `((k0r + a) step, (k0c + b) step)`) to
/// the pixels `t .. rows - t`, `t .. cols - t` of a block of `(rows, cols)`
/// (`t` a multiple of `step`): along the rows first, then along the columns,
/// `v0 (1 - u) + v1 u` with `u = (pixel mod step) / step`, as
/// `_resample_model.interp_to_pixels`. Returns `(maps, rows - 2t, cols -
/// 2t)` row-major.
pub fn interp_nodes(
    v: ArrayView3<f64>,
    (k0r, k0c): (usize, usize),
    (rows, cols): (usize, usize),
    t: usize,
    step: usize,
) -> CoreResult<Vec<f64>> {
    if step == 0 {
        return Err(CoreError::invalid(
            "step",
            "expected a positive integer, got 0",
        ));
    }
    if t % step != 0 || rows < 2 * t || cols < 2 * t {
        return Err(CoreError::invalid(
            "t",
            format!("expected a multiple of step {step} at most half the block {rows} x {cols}, got {t}"),
        ));
    }
    let (m, nr, nc) = v.dim();
    let (or, oc) = (rows - 2 * t, cols - 2 * t);
    // nodes needed: rows t / step - k0r ..= (rows - t - 1) / step + 1 - k0r
    let need = |lo: usize, hi: usize, k0: usize, n: usize| {
        hi == lo || (lo / step >= k0 && (hi - 1) / step + 1 - k0 < n)
    };
    if !(need(t, rows - t, k0r, nr) && need(t, cols - t, k0c, nc)) {
        return Err(CoreError::invalid(
            "nodes",
            format!(
                "the {nr} x {nc} nodes from ({k0r}, {k0c}) do not cover the pixels of the block"
            ),
        ));
    }
    let mut out = try_zeroed(m * or * oc, "dem")?;
    if or == 0 || oc == 0 {
        return Ok(out);
    }
    let vc = v.as_standard_layout();
    let vs = vc
        .as_slice()
        .ok_or_else(|| CoreError::Internal("nodes not contiguous".into()))?;
    let sf = step as f64;
    let ux: Vec<f64> = (0..step).map(|k| k as f64 / sf).collect();
    let wx: Vec<f64> = ux.iter().map(|u| 1.0 - u).collect();
    out.par_chunks_mut(oc).enumerate().for_each_init(
        || vec![0.0; nc],
        |rbuf, (g, orow)| {
            let (mi, y) = (g / or, t + g % or);
            let a = y / step - k0r;
            let u = (y % step) as f64 / sf;
            let w = 1.0 - u;
            let base = mi * nr * nc;
            let (n0, n1) = (&vs[base + a * nc..][..nc], &vs[base + (a + 1) * nc..][..nc]);
            for ((r, x0), x1) in rbuf.iter_mut().zip(n0).zip(n1) {
                *r = x0 * w + x1 * u;
            }
            // pixels in runs of `step` between two nodes (`t` is a multiple
            // of `step`: every run starts on a node)
            for (ci, run) in orow.chunks_mut(step).enumerate() {
                let b = t / step + ci - k0c;
                let (r0, r1) = (rbuf[b], rbuf[b + 1]);
                for ((o, &u), &w) in run.iter_mut().zip(&ux).zip(&wx) {
                    *o = r0 * w + r1 * u;
                }
            }
        },
    );
    Ok(out)
}

/// Squared increment `(b - a)^2`, or `None` when it is not finite (a hole).
#[inline]
fn sq(a: f64, b: f64) -> Option<f64> {
    let d = b - a;
    let d = d * d;
    d.is_finite().then_some(d)
}

/// The local amplitude factor of the detail at the pixels `t .. rows - t`,
/// `t .. cols - t` of a NaN-padded block `z` (`t >= 1`): `sqrt(g / d1)`,
/// `g` the mean squared lag-1 increment (rows and columns, finite pairs)
/// over the 12 increments with both ends in the 3 x 3 cells around the
/// pixel and `d1` the window's (`(rows - 2t, cols - 2t)`, row-major); 1
/// where that is not finite. The sums are formed in the order of the numpy
/// reference (`_resample_model.local_amplitude_reference`): vertical
/// increments `((v(i-1, j-1) + v(i, j-1)) + (v(i-1, j) + v(i, j))) +
/// (v(i-1, j+1) + v(i, j+1))`, then the horizontal ones likewise, so the
/// bits are the reference's for any block and thread count.
pub fn local_amplitude(
    z: &[f64],
    (rows, cols): (usize, usize),
    t: usize,
    d1: &[f64],
) -> CoreResult<Vec<f64>> {
    if z.len() != rows * cols {
        return Err(CoreError::Internal("dem shape".into()));
    }
    if t == 0 || rows < 2 * t || cols < 2 * t {
        return Err(CoreError::invalid(
            "t",
            format!("expected 1 <= t <= half the block {rows} x {cols}, got {t}"),
        ));
    }
    let (or, oc) = (rows - 2 * t, cols - 2 * t);
    if d1.len() != or * oc {
        return Err(CoreError::invalid(
            "d1",
            format!("expected {or} x {oc} values, got {}", d1.len()),
        ));
    }
    let mut out = try_zeroed(or * oc, "dem")?;
    if or == 0 || oc == 0 {
        return Ok(out);
    }
    out.par_chunks_mut(oc).enumerate().for_each_init(
        || (vec![0.0; oc + 2], vec![0u8; oc + 2]),
        |(vs, vc), (oi, orow)| {
            let i = oi + t; // pixel row in z
            let row = |r: usize| &z[r * cols + t - 1..r * cols + t + oc + 1];
            let (a0, a1, a2) = (row(i - 1), row(i), row(i + 1));
            // vs[c] = v(i-1, c) + v(i, c) over the columns t-1 .. t+oc+1
            for c in 0..oc + 2 {
                let (x, nx) = match sq(a0[c], a1[c]) {
                    Some(d) => (d, 1u8),
                    None => (0.0, 0),
                };
                let (y, ny) = match sq(a1[c], a2[c]) {
                    Some(d) => (d, 1u8),
                    None => (0.0, 0),
                };
                vs[c] = x + y;
                vc[c] = nx + ny;
            }
            // horizontal: ((h(i-1, j) + h(i-1, j+1)) + (h(i, j) + h(i, j+1))) +
            // (h(i+1, j) + h(i+1, j+1)), h(r, c) = (z[r, c+1] - z[r, c])^2
            for (j, o) in orow.iter_mut().enumerate() {
                let vsum = (vs[j] + vs[j + 1]) + vs[j + 2];
                let vn = vc[j] as u32 + vc[j + 1] as u32 + vc[j + 2] as u32;
                let mut hsum = 0.0;
                let mut hn = 0u32;
                for (k, a) in [a0, a1, a2].iter().enumerate() {
                    let x = sq(a[j], a[j + 1]);
                    let y = sq(a[j + 1], a[j + 2]);
                    let part = x.unwrap_or(0.0) + y.unwrap_or(0.0);
                    hn += x.is_some() as u32 + y.is_some() as u32;
                    hsum = if k == 0 { part } else { hsum + part };
                }
                let n = vn + hn;
                let g = (vsum + hsum) / n as f64;
                let m = (g / d1[oi * oc + j]).sqrt();
                *o = if m.is_finite() { m } else { 1.0 };
            }
        },
    );
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::run_in_pool;
    use crate::testdata::uniform;

    /// Brute-force sums: every increment in the window of its first sample.
    fn brute(
        z: &[f64],
        (n0, n1): (usize, usize),
        half: usize,
        lag: usize,
        p: (usize, usize),
    ) -> (f64, f64) {
        let at = |i: usize, j: usize| z[i * n1 + j];
        let (mut s, mut c) = (0.0, 0.0);
        for i in p.0 - half..=p.0 + half {
            for j in p.1 - half..=p.1 + half {
                let a = at(i, j);
                for (ii, jj) in [(i + lag, j), (i, j + lag)] {
                    if ii < n0 && jj < n1 && a.is_finite() && at(ii, jj).is_finite() {
                        let d = at(ii, jj) - a;
                        s += d * d;
                        c += 1.0;
                    }
                }
            }
        }
        (s, c)
    }

    fn surface(n0: usize, n1: usize) -> Vec<f64> {
        let u = uniform(n0 * n1, 3);
        let mut z: Vec<f64> = u.iter().map(|x| x - 0.5).collect();
        for i in 1..n0 {
            for j in 0..n1 {
                z[i * n1 + j] += z[(i - 1) * n1 + j];
            }
        }
        for (k, v) in z.iter_mut().enumerate() {
            if k % 37 == 5 || (k / n1 < 6) {
                *v = f64::NAN;
            }
        }
        z
    }

    #[test]
    fn sums_match_brute_force_and_threads() {
        let (n0, n1) = (75, 61);
        let z = surface(n0, n1);
        let lags = [1, 2, 4, 8];
        for (half, step) in [(16, 8), (5, 4), (3, 8)] {
            let nv = node_variograms(&z, (n0, n1), half, step, &lags).unwrap();
            assert!(nv.rows > 0 && nv.cols > 0);
            for (li, &lag) in lags.iter().enumerate() {
                for a in 0..nv.rows {
                    for b in 0..nv.cols {
                        let p = ((nv.k0r + a) * step, (nv.k0c + b) * step);
                        let (s, c) = brute(&z, (n0, n1), half, lag, p);
                        let k = (li * nv.rows + a) * nv.cols + b;
                        assert_eq!(nv.counts[k], c);
                        assert!((nv.sums[k] - s).abs() <= 1e-12 * s.max(1.0));
                    }
                }
            }
            for n in [1, 2, 3] {
                let other =
                    run_in_pool(Some(n), || node_variograms(&z, (n0, n1), half, step, &lags))
                        .unwrap();
                assert_eq!(other, nv);
            }
        }
    }

    #[test]
    fn interp_is_bilinear_and_exact_on_planes() {
        // a plane a + b i + c j at the nodes is reproduced at every pixel
        let (k0r, k0c, step, t) = (1, 2, 4, 8);
        let (nr, nc) = (6, 5);
        let v = ndarray::Array3::from_shape_fn((2, nr, nc), |(m, a, b)| {
            let (i, j) = (((k0r + a) * step) as f64, ((k0c + b) * step) as f64);
            1.0 + m as f64 + 0.25 * i - 0.5 * j
        });
        let (rows, cols) = (nr * step + 2, nc * step + 8);
        let (rows, cols) = (rows.min(28), cols.min(28));
        let out = interp_nodes(v.view(), (k0r, k0c), (rows, cols), t, step).unwrap();
        let (or, oc) = (rows - 2 * t, cols - 2 * t);
        for m in 0..2 {
            for y in 0..or {
                for x in 0..oc {
                    let (i, j) = ((y + t) as f64, (x + t) as f64);
                    let want = 1.0 + m as f64 + 0.25 * i - 0.5 * j;
                    assert!((out[(m * or + y) * oc + x] - want).abs() < 1e-12);
                }
            }
        }
        assert!(interp_nodes(v.view(), (k0r, k0c), (rows + 40, cols), t, step).is_err());
        assert!(interp_nodes(v.view(), (k0r, k0c), (rows, cols), 3, step).is_err());
    }
}
