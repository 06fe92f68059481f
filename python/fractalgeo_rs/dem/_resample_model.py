"""The scale-aware ("smooth") model of fractal resampling: a structure
function with an inner scale, fitted to the coarse DEM's variogram at lags
1, 2, 4 and 8 cells in every analysis window, and the per-level power laws
the kernel draws each x2 level with.

The model (input cells as the length unit)::

    D(h) = a r^(2H) ((1 + (h / r)^2)^H - 1)

is smooth (``D ~ h^2``) below the inner scale ``r`` and fBm with Hurst
exponent ``H`` above it; ``r = 0`` is fBm (``D = a h^(2H)``). A level whose
coarse spacing is ``s`` input cells is drawn as fBm with the local exponent
``H_s = log2(D(s) / D(s / 2)) / 2`` and the amplitude that gives ``D(s)``
at lag ``s``: the power law that matches the model at the two lags the
level's new samples sit between.
"""
from __future__ import annotations

import functools

import numpy as np

from fractalgeo_rs.dem import _resample_grid as R

#: Lags (input cells) of the local fit.
LAGS = (1, 2, 4, 8)
#: Grids of the fit: H of the fractal regime and the inner scale r (input
#: cells; 0 is fBm).
H_GRID = np.linspace(0.05, 0.95, 37)
R_GRID = np.concatenate([[0.0], np.geomspace(0.02, 64.0, 72)])
#: Fewest increments per lag for a window's fit (else the lag-1/lag-2 fBm
#: fit, else no detail).
MIN_PAIRS = 16
#: Smallest inner scale of the default model, in output cells (a DEM is
#: smooth at its own pixel: its heights are not point values of a fractal).
INNER_SCALE_FLOOR = 1.0
#: Range of the per-level exponents passed to the kernel (its tables) and
#: the number of nodes of its full-stencil tables (``rust/dem/resample.rs``).
LEVEL_H = (0.01, 0.99)
H_TABLE_NODES = 201


def shape_point(h, r, hurst):
    """``D(h) / a`` of point samples (broadcasting ``h``, ``r``, ``hurst``)."""
    h, r, hurst = np.broadcast_arrays(np.asarray(h, float), np.asarray(r, float),
                                      np.asarray(hurst, float))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        rr = np.where(r > 0, r, 1.0)
        smooth = rr ** (2 * hurst) * np.expm1(hurst * np.log1p((h / rr) ** 2))
        return np.where(r > 0, smooth, h ** (2 * hurst))


def shape_block(lag, r, hurst, n):
    """``D_B(lag) / a`` of block means (each cell the mean of ``n x n``
    points at spacing ``1 / n``): ``mean f(|p - q|) - mean f(|p - p'|)``
    over the points ``p``, ``p'`` of one block and ``q`` of the block
    ``lag`` cells away (rows or columns: the model is isotropic)."""
    m = np.arange(-(n - 1), n)
    w = (n - np.abs(m)) / n**2
    dy, dx = np.meshgrid(m / n, m / n, indexing="ij")
    ww = np.outer(w, w)
    r = np.asarray(r, float)[..., None, None]
    hurst = np.asarray(hurst, float)[..., None, None]
    d0 = np.hypot(dy, dx)
    base = (ww * shape_point(d0, r, hurst)).sum((-1, -2))
    d1 = np.hypot(dy, dx + lag)
    return (ww * shape_point(d1, r, hurst)).sum((-1, -2)) - base


@functools.lru_cache(maxsize=8)
def model_table(block, lags=LAGS):
    """``(r, H, log_shape)``: every model of the grid and its log structure
    function at ``lags`` (point samples for ``block = 0``, else block means
    of ``block x block`` points)."""
    rr, hh = np.meshgrid(R_GRID, H_GRID, indexing="ij")
    rr, hh = rr.ravel(), hh.ravel()
    cols = []
    for k in lags:
        v = shape_point(float(k), rr, hh) if block == 0 else shape_block(float(k), rr, hh, block)
        cols.append(np.log(v))
    return rr, hh, np.stack(cols, 1)


def lag_weights(lags):
    """Weights of the lags in the fit, ``1 / k`` normalised: the sampling
    variance of a window's log mean squared increment grows about linearly
    with the lag (increments of lag ``k`` are correlated over ``k`` cells,
    so a window holds about ``1 / k`` as many independent ones), so this is
    the inverse-variance (weighted least squares) weighting."""
    w = 1.0 / np.asarray(lags, dtype=float)
    return w / w.sum()


@functools.lru_cache(maxsize=8)
def _tree(block, lags=LAGS):
    from scipy.spatial import cKDTree

    _, _, ls = model_table(block, lags)
    w = lag_weights(lags)
    return cKDTree((ls - (ls * w).sum(1, keepdims=True)) * np.sqrt(w))


def fit(logd, block, lags=LAGS):
    """Weighted least-squares fit of the model's shape to log structure
    functions ``logd`` (``(..., len(lags))``, amplitude free; weights
    :func:`lag_weights`): ``(r, H, log_shape)`` of the nearest model of the
    grid in the weighted, centred log space."""
    rr, hh, ls = model_table(block, lags)
    w = lag_weights(lags)
    q = (logd - (logd * w).sum(-1, keepdims=True)) * np.sqrt(w)
    flat = q.reshape(-1, len(lags))
    idx = np.zeros(flat.shape[0], dtype=np.intp)
    ok = np.isfinite(flat).all(1)
    if ok.any():
        idx[ok] = _tree(block, lags).query(flat[ok])[1]
    shp = logd.shape[:-1]
    return rr[idx].reshape(shp), hh[idx].reshape(shp), ls[idx].reshape(shp + (len(lags),))


def level_params(r, hurst, amp, levels):
    """Per-level ``(H_l, sigma_l)`` (stacks of ``levels``) of the model
    ``amp * shape_point`` at the coarse spacings ``s = 2^-l``:
    ``H_l = log2(D(s) / D(s/2)) / 2`` (clipped to ``LEVEL_H``) and
    ``sigma_l = sqrt(D(s)) s^-H_l``, the kernel's power law through
    ``D(s)`` and ``D(s/2)``."""
    hs, ss = [], []
    for lvl in range(levels):
        s = 2.0 ** -lvl
        d1 = amp * shape_point(s, r, hurst)
        d2 = amp * shape_point(s / 2, r, hurst)
        with np.errstate(divide="ignore", invalid="ignore"):
            h = np.clip(0.5 * np.log2(d1 / d2), *LEVEL_H)
        h = np.where(np.isfinite(h), h, 0.5)
        sig = np.sqrt(np.maximum(d1, 0.0)) * s ** (-h)
        hs.append(h)
        ss.append(np.where(np.isfinite(sig), sig, 0.0))
    return np.stack(hs), np.stack(ss)


def pad_width(half, step=R.STEP):
    """NaN halo (a multiple of ``step``) the model analysis of a block
    needs: the window, the largest lag and one node spacing."""
    return -(-(half + max(LAGS) + step) // step) * step


def node_variograms(z, half, step=R.STEP, n_threads=None):
    """Window sums of squared increments and their counts at every lag of
    ``LAGS`` at the nodes of a ``step`` grid of the NaN-padded block ``z``:
    the Rust kernel (``_core.resample_node_variograms``, the same bits as
    :func:`node_variograms_reference` for any ``n_threads``):
    ``(sums, counts, k0r, k0c)``."""
    from fractalgeo_rs import _core

    return _core.resample_node_variograms(np.asarray(z, dtype=np.float64), half, step, list(LAGS),
                                          n_threads)


def node_variograms_reference(z, half, step=R.STEP):
    """numpy twin of :func:`node_variograms`: window sums of squared increments and their counts at every lag of
    ``LAGS`` (rows and columns pooled, each increment in the window of its
    first sample) at the nodes of a ``step`` grid of the NaN-padded block
    ``z`` (origin a multiple of ``step``): ``(sums, counts, k0r, k0c)``,
    arrays ``(len(LAGS), nodes_r, nodes_c)``, node ``(a, b)`` at pixel
    ``((k0r + a) step, (k0c + b) step)``. Each sum is formed in a fixed
    order from its window only (``_resample_grid.node_sums``), so any block of a
    larger array gives the same bits."""
    m = np.isfinite(z)
    zz = np.where(m, z, 0.0)
    # Valid samples filling a rectangle (a DEM without holes in its NaN
    # halo): the counts are products of 1D counts (integers, exact in
    # float64: the same bits as the 2D sums) and the increments need no mask.
    rows = np.flatnonzero(m.any(1))
    cols = np.flatnonzero(m.any(0))
    rect = False
    if rows.size and cols.size:
        r0, r1, c0, c1 = rows[0], rows[-1] + 1, cols[0], cols[-1] + 1
        rect = bool(m[r0:r1, c0:c1].all())

    def sums_1d(lo, hi, lag, n):
        u = np.zeros((n, 1))
        u[lo:max(hi - lag, lo)] = 1.0
        return R.node_sums(u, half, step)[0][:, 0]

    sums, counts = [], []
    k0r = k0c = 0
    for lag in LAGS:
        s = np.zeros(z.shape)
        d = zz[lag:] - zz[:-lag]
        d *= d
        if rect:
            d[:r0] = 0.0
            d[max(r1 - lag, 0):] = 0.0
        else:
            ok = m[lag:] & m[:-lag]
            d *= ok
        s[:-lag] = d
        d = zz[:, lag:] - zz[:, :-lag]
        d *= d
        if rect:
            d[:, :c0] = 0.0
            d[:, max(c1 - lag, 0):] = 0.0
        else:
            ok = m[:, lag:] & m[:, :-lag]
            d *= ok
        s[:, :-lag] += d
        rsum, k0r = R.node_sums(s, half, step)
        csum, k0c = R.node_sums(np.ascontiguousarray(rsum.T), half, step)
        sums.append(csum.T)
        if rect:
            ur, u0 = sums_1d(r0, r1, lag, z.shape[0]), sums_1d(r0, r1, 0, z.shape[0])
            vc, v0 = sums_1d(c0, c1, lag, z.shape[1]), sums_1d(c0, c1, 0, z.shape[1])
            counts.append(ur[:, None] * v0[None] + u0[:, None] * vc[None])
        else:
            c = np.zeros(z.shape)
            c[:-lag] += m[lag:] & m[:-lag]
            c[:, :-lag] += m[:, lag:] & m[:, :-lag]
            rc, _ = R.node_sums(c, half, step)
            cc, _ = R.node_sums(np.ascontiguousarray(rc.T), half, step)
            counts.append(cc.T)
    return np.stack(sums), np.stack(counts), k0r, k0c


def interp_to_pixels(v, k0r, k0c, shape, t, step=R.STEP, n_threads=None):
    """Bilinear interpolation of node values ``v`` (``(..., nodes_r,
    nodes_c)``) to the pixels of a block of ``shape`` trimmed by ``t``: the
    Rust kernel (``_core.resample_interp_nodes``, the same arithmetic as
    :func:`interp_to_pixels_reference`)."""
    from fractalgeo_rs import _core

    lead = v.shape[:-2]
    flat = np.ascontiguousarray(v, dtype=np.float64).reshape((-1,) + v.shape[-2:])
    out = _core.resample_interp_nodes(flat, int(k0r), int(k0c), tuple(shape), int(t), step,
                                      n_threads)
    return out.reshape(lead + out.shape[1:])


def interp_to_pixels_reference(v, k0r, k0c, shape, t, step=R.STEP):
    """numpy twin of :func:`interp_to_pixels`."""
    lead = v.shape[:-2]
    flat = v.reshape((-1,) + v.shape[-2:])
    out = []
    for a in flat:
        rows = R.interp_nodes(np.ascontiguousarray(a), k0r, t, shape[0] - t, step)
        out.append(R.interp_nodes(np.ascontiguousarray(rows.T), k0c, t, shape[1] - t, step).T)
    return np.stack(out).reshape(lead + (shape[0] - 2 * t, shape[1] - 2 * t))


def analyse_nodes(z, half, block, levels, r_floor=0.0, step=R.STEP, n_threads=None):
    """The model fit at the nodes of a NaN-padded block (see
    :func:`node_variograms`). Returns a dict of node arrays: ``r``, ``H``
    (the fit, ``r`` at least ``r_floor``; ``r = 0`` and the lag-1/lag-2
    ``H`` where a lag has too few increments), ``h12`` (raw lag-1/lag-2 exponent, NaN where none),
    ``valid`` (the window has lag-1 increments), ``level_h``, ``level_s``
    (``levels`` stacks), and ``k0r``, ``k0c``."""
    s, c, k0r, k0c = node_variograms(z, half, step, n_threads)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = s / c
        logd = np.log(np.moveaxis(d, 0, -1))
    enough = (np.moveaxis(c, 0, -1) >= MIN_PAIRS).all(-1) & np.isfinite(logd).all(-1)
    r, hfit, ls = fit(np.where(enough[..., None], logd, np.nan), block)
    d1, d2 = d[0], d[1]
    valid = np.isfinite(d1) & (c[0] > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = d2 / d1
    if block == 0:
        with np.errstate(divide="ignore", invalid="ignore"):
            h12 = 0.5 * np.log2(ratio)
    else:
        hh, rt, _ = R.ratio_table(block)
        h12 = np.interp(np.where(np.isfinite(ratio), ratio, 1.0), rt, hh, left=0.0, right=2.0)
    h12 = np.where(np.isfinite(ratio) & (d1 > 0), h12, np.nan)
    # Windows without all four lags: fBm of the lag-1/lag-2 exponent.
    fb = ~enough
    r = np.where(fb, 0.0, np.maximum(r, r_floor))
    hfit = np.where(fb, np.clip(np.where(np.isfinite(h12), h12, 0.5), *R.HURST_RANGE), hfit)
    # Amplitude from the lag-1 structure function (of the block means for
    # area support): D(1) of the fitted model equals the measured one.
    one = shape_point(1.0, r, hfit) if block == 0 else shape_block(1.0, r, hfit, block)
    with np.errstate(divide="ignore", invalid="ignore"):
        amp = np.where(valid & (d1 > 0), d1 / one, 0.0)
    amp = np.where(np.isfinite(amp), amp, 0.0)
    lh, lsg = level_params(r, hfit, amp, levels)
    return dict(r=r, H=hfit, h12=h12, valid=valid, enough=enough, level_h=lh, level_s=lsg,
                d1=np.where(valid & np.isfinite(d1), d1, 0.0), k0r=k0r, k0c=k0c)


def local_lag1(z, t):
    """Mean squared lag-1 increment (rows and columns, pairs of finite
    samples) over the increments with both ends in the 3 x 3 cells around
    each pixel of the core ``z[t:-t, t:-t]`` of a NaN-padded block
    (``t >= 1``); NaN where there is none. Each value is a fixed-order sum
    of its own neighbourhood, so any block of a larger array gives the same
    bits."""
    a = z[t - 1:z.shape[0] - t + 1, t - 1:z.shape[1] - t + 1]
    v = a[1:] - a[:-1]
    v *= v
    h = a[:, 1:] - a[:, :-1]
    h *= h
    vm = np.isfinite(v)
    hm = np.isfinite(h)
    v[~vm] = 0.0
    h[~hm] = 0.0
    # vertical increments of rows (i, i+1) and (i+1, i+2), columns j..j+2;
    # horizontal of rows i..i+2, column pairs (j, j+1) and (j+1, j+2).
    vs = v[:-1] + v[1:]
    hs = h[:, :-1] + h[:, 1:]
    tot = (vs[:, :-2] + vs[:, 1:-1] + vs[:, 2:]) + (hs[:-2] + hs[1:-1] + hs[2:])
    vc = vm[:-1].astype(np.int8) + vm[1:]
    hc = hm[:, :-1].astype(np.int8) + hm[:, 1:]
    cnt = (vc[:, :-2] + vc[:, 1:-1] + vc[:, 2:]) + (hc[:-2] + hc[1:-1] + hc[2:])
    with np.errstate(divide="ignore", invalid="ignore"):
        return tot / cnt


def local_amplitude_reference(z, t, d1_map):
    """numpy twin of :func:`local_amplitude` (the same bits)."""
    g = local_lag1(z, t)
    with np.errstate(divide="ignore", invalid="ignore"):
        m = np.sqrt(g / d1_map)
    return np.where(np.isfinite(m), m, 1.0)


def local_amplitude(z, t, d1_map, n_threads=None):
    """Factor on the detail's sd at each core pixel of a NaN-padded block:
    ``sqrt(g_loc / g_win)``, the rms lag-1 increment of the 3 x 3 cells
    around the pixel (:func:`local_lag1`) over the window's (``d1_map``,
    the analysis window's mean squared lag-1 increment interpolated to the
    pixels); 1 where either is missing (and where the window's is 0, whose
    sigma is 0 anyway). Real relief is intermittent: its fine-scale detail
    sits where the coarse DEM is locally rough (scarps, channel banks), not
    spread evenly over the window (docs/resampling.md). The Rust kernel
    (``_core.resample_local_amplitude``, the bits of
    :func:`local_amplitude_reference` for any ``n_threads``)."""
    from fractalgeo_rs import _core

    return _core.resample_local_amplitude(np.asarray(z, dtype=np.float64),
                                          np.ascontiguousarray(d1_map, dtype=np.float64), int(t),
                                          n_threads)


def analyse_padded(z, half, block, levels, r_floor, step=R.STEP, n_threads=None):
    """Pixel maps of a NaN-padded block trimmed by ``pad_width(half)``:
    ``(level_h, level_s, r, H)`` (``levels`` stacks, then the inner scale
    and the fitted H) and the counts of the nodes in the block's core
    ``(n_valid, n_smooth, n_rough, n_tapered, n_centre)`` (valid: lag-1
    increments in the window; smooth / rough: lag-1/lag-2 exponent above /
    below ``HURST_RANGE``; tapered: inner scale above one output cell;
    centre: a finite centre pixel). ``r_floor``: the inner scale used is at least this
    (input cells)."""
    nd = analyse_nodes(z, half, block, levels, r_floor, step, n_threads)
    t = pad_width(half, step)
    shape = z.shape
    k0r, k0c = nd["k0r"], nd["k0c"]
    maps = interp_to_pixels(np.concatenate([nd["level_h"], nd["level_s"], nd["r"][None],
                                            nd["H"][None], nd["d1"][None]]), k0r, k0c, shape, t,
                            step, n_threads)
    lv = nd["level_h"].shape[0]
    level_h, level_s, r_map, h_map = maps[:lv], maps[lv:2 * lv], maps[2 * lv], maps[2 * lv + 1]
    # The detail's amplitude follows the local relief (intermittency).
    level_s *= local_amplitude(z, t, maps[2 * lv + 2], n_threads)[None]
    # H on the nodes of the kernel's tables (201 in [0.01, 0.99], steps of
    # 0.0049): the kernel then redoes its table lookup only where H changes.
    q = (LEVEL_H[1] - LEVEL_H[0]) / (H_TABLE_NODES - 1)
    # (in place: the same operations as ``lo + rint((h - lo) / q) * q``)
    level_h -= LEVEL_H[0]
    level_h /= q
    np.rint(level_h, out=level_h)
    level_h *= q
    level_h += LEVEL_H[0]
    # Counts over the nodes whose pixel lies in the block's core.
    ar = (k0r + np.arange(nd["r"].shape[0])) * step
    ac = (k0c + np.arange(nd["r"].shape[1])) * step
    inside = (((ar >= t) & (ar < shape[0] - t))[:, None] & ((ac >= t) & (ac < shape[1] - t))[None])
    core_ok = np.zeros_like(inside)
    ii, jj = np.nonzero(inside)
    core_ok[ii, jj] = np.isfinite(z[ar[ii], ac[jj]])
    v = core_ok & nd["valid"]
    h12 = nd["h12"]
    lo, hi = R.HURST_RANGE
    r_out = 2.0 ** -levels
    counts = (int(v.sum()), int((v & (h12 > hi)).sum()), int((v & (h12 < lo)).sum()),
              int((v & nd["enough"] & (nd["r"] > r_out * (1 + 1e-9))).sum()), int(core_ok.sum()))
    return level_h, level_s, r_map, h_map, counts


def global_fit(z, block):
    """The model fitted to the whole DEM's variogram at every lag ``2^k``
    up to a quarter of its shorter side: ``(r, H)`` (input cells)."""
    n = min(z.shape)
    lags = tuple(2**k for k in range(0, 16) if 2**k <= max(n // 4, 2))
    if len(lags) < 3:
        return float("nan"), float("nan")
    # Without holes every increment counts (no NaN masks: dot products).
    full = bool(np.isfinite(z).all())
    logd = []
    for k in lags:
        # Lag k from the pairs starting on every max(2, k)-th row (unbiased;
        # all lags together cost about 1.5 passes over the DEM).
        t = max(2, k)
        a = z[k::t] - z[:-k:t][: z[k::t].shape[0]]
        b = z[::t, k:] - z[::t, :-k]
        if full:
            cnt = a.size + b.size
            a, b = a.ravel(), b.ravel()
            v = float(np.einsum("i,i->", a, a) + np.einsum("i,i->", b, b))
        else:
            cnt = int(np.count_nonzero(np.isfinite(a)) + np.count_nonzero(np.isfinite(b)))
            v = float(np.nansum(a * a) + np.nansum(b * b))
        if cnt == 0:
            return float("nan"), float("nan")
        logd.append(np.log(v / cnt) if v > 0 else np.nan)
    ld = np.array(logd)
    if not np.isfinite(ld).all():
        return float("nan"), float("nan")
    r, h, _ = fit(ld[None], block, lags)
    return float(r[0]), float(h[0])
