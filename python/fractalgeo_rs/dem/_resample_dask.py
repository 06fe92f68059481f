"""Dask runner of :func:`fractalgeo_rs.fractal_resample`: chunk by chunk with
a halo, equal to the in-memory result for any chunking."""
from __future__ import annotations

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._backend import halo_blocks
from fractalgeo_rs.dem import _resample as R


def _out_bounds(a, b, n, f, point):
    """Fine index range of the input rows ``[a, b)`` of ``n``."""
    if point:
        return f * a, (f * (b - 1) + 1 if b == n else f * b)
    return f * a, f * b


def _analysis_maps(dem, hurst, sigma, window, support, nodata, block=2, n_threads=None, levels=1,
                   model="fbm"):
    """Per-level hurst and sigma stacks ``(n, rows, cols)`` (``n`` = 1 or
    ``levels``) as dask arrays chunked like ``dem`` in the last two axes."""
    import dask.array as da

    local_h = isinstance(hurst, str) and hurst == "local"
    local_s = isinstance(sigma, str) and sigma == "local"
    shape = dem.shape
    z = dem.map_blocks(R._as_float, nodata, dtype=np.float64) if (local_h or local_s) else None
    if model == "smooth":
        from fractalgeo_rs.dem import _resample_model as M

        half = window // 2
        t = M.pad_width(half)
        mb = 0 if support == "point" else block
        floor = M.INNER_SCALE_FLOOR / (1 << levels)

        def smooth_fn(b):
            lh, ls, _, _, _ = M.analyse_padded(b, half, mb, levels, floor)
            return np.concatenate([lh, ls])

        padded, core = halo_blocks(z, t, R.STEP)
        hs = padded.map_blocks(smooth_fn, dtype=np.float64, new_axis=0,
                               chunks=((2 * levels,),) + core)
        chunks = ((levels,),) + dem.chunks
        return hs[:levels].rechunk(chunks), hs[levels:].rechunk(chunks)
    if isinstance(hurst, np.ndarray) and hurst.ndim == 3:
        # Per-level stacks computed beforehand (the CLI).
        chunks = ((hurst.shape[0],),) + dem.chunks
        return (da.from_array(np.ascontiguousarray(hurst), chunks=chunks),
                da.from_array(np.ascontiguousarray(sigma), chunks=chunks))
    if local_h or local_s:
        half = window // 2
        t = R._pad_width(half)

        def block_fn(b):
            h, s, _, _ = R._analyse_padded(b, half, support, block, n_threads=n_threads)
            return np.stack([h, s])

        # Chunks on multiples of the node step: the nodes sit on one global grid.
        padded, core = halo_blocks(z, t, R.STEP)
        hs = padded.map_blocks(block_fn, dtype=np.float64, new_axis=0,
                               chunks=((2,),) + core)
        h_map, s_map = hs[0].rechunk(dem.chunks), hs[1].rechunk(dem.chunks)
    h = h_map if local_h else da.from_array(
        R._param_map(hurst, "hurst", shape, 0.0, 1.0, True, True), chunks=dem.chunks)
    if local_s:
        s = s_map
        if support == "area" and not local_h:
            hh, _, g1tab = R.ratio_table(block)

            def user_sigma(sl, hl, hu):
                g1 = sl**2 * np.interp(hl, hh, g1tab)
                return np.sqrt(g1 / np.interp(np.clip(hu, hh[0], hh[-1]), hh, g1tab))

            s = da.map_blocks(user_sigma, s_map, h_map, h, dtype=np.float64)
    else:
        s = da.from_array(R._param_map(sigma, "sigma", shape, 0.0, np.inf, False, False),
                          chunks=dem.chunks)
    return h.rechunk(dem.chunks)[None], s.rechunk(dem.chunks)[None]


def run_dask(dem, levels, hurst, sigma, window, detail, support, nodata, seed, n_threads,
             return_analysis, model=None, clip_min=None):
    """Lazy fractal resampling of a 2D dask array."""
    import dask
    import dask.array as da

    if dem.ndim != 2:
        raise ValueError(f"dem: expected a 2D array, got shape {dem.shape}")
    R._check_shape(dem.shape)
    f = 1 << levels
    point = support == "point"
    local_h = isinstance(hurst, str) and hurst == "local"
    local_s = isinstance(sigma, str) and sigma == "local"
    model = R.check_model(model, local_h, local_s)
    if local_h or local_s:
        R._warn_window(window, dem.shape)
    h_map, s_map = _analysis_maps(dem, hurst, sigma, window, support, nodata, min(f, 8), n_threads,
                                  levels, model)
    n0, n1 = dem.shape
    halo = R._HALO
    row_edges = np.concatenate([[0], np.cumsum(dem.chunks[0])])
    col_edges = np.concatenate([[0], np.cumsum(dem.chunks[1])])

    def tile(z, h, s, t0, u0, r0, r1, c0, c1):
        z = R._as_float(z, nodata)
        out = _core.fractal_resample(z, np.ascontiguousarray(h, dtype=np.float64),
                                     np.ascontiguousarray(s, dtype=np.float64), levels,
                                     not point, seed, detail, (t0, u0), n1, n_threads)
        return out[r0:r1, c0:c1]

    rows = []
    for bi in range(len(dem.chunks[0])):
        a, b = int(row_edges[bi]), int(row_edges[bi + 1])
        t0, t1 = max(a - halo, 0), min(b + halo, n0)
        fa, fb = _out_bounds(a, b, n0, f, point)
        row = []
        for bj in range(len(dem.chunks[1])):
            c, d = int(col_edges[bj]), int(col_edges[bj + 1])
            u0, u1 = max(c - halo, 0), min(d + halo, n1)
            fc, fd = _out_bounds(c, d, n1, f, point)
            sl = (slice(t0, t1), slice(u0, u1))
            part = dask.delayed(tile)(dem[sl], h_map[(slice(None),) + sl], s_map[(slice(None),) + sl],
                                      t0, u0,
                                      fa - f * t0, fb - f * t0, fc - f * u0, fd - f * u0)
            row.append(da.from_delayed(part, shape=(fb - fa, fd - fc), dtype=np.float64))
        rows.append(row)
    out = da.block(rows)
    if clip_min is not None:
        out = da.maximum(out, clip_min)
    if return_analysis:
        return out, R.ResampleAnalysis(h_map[0], s_map[0], float("nan"), window, model=model,
                                       level_hurst=h_map, level_sigma=s_map)
    return out
