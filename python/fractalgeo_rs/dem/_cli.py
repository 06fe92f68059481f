"""``fractalgeo resample``: fractal resampling of a GeoTIFF DEM."""
from __future__ import annotations

import argparse
import sys


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "resample",
        help="resample a DEM on a finer grid with fractal detail",
        description="Fractal resampling (fractalgeo_rs.fractal_resample): the DEM is analysed for "
        "its local Hurst exponent and roughness and refined by --factor (a power of 2) with "
        "conditional fBm detail. The output GeoTIFF keeps the CRS; the pixel size is divided by "
        "the factor. Computed in blocks of --chunks input cells and written block by block.",
    )
    p.add_argument("input", help="input DEM (GeoTIFF or any format rasterio reads)")
    p.add_argument("output", help="output GeoTIFF (float32, nodata NaN)")
    p.add_argument("--factor", type=int, default=2, help="power of 2 (default 2)")
    p.add_argument("--min-scale", type=float, default=None,
                   help="no random detail in cells smaller than this (ground units)")
    p.add_argument("--seed", type=int, default=None)
    p.add_argument("--hurst", default="local", help="'local' (default) or a number in (0, 1)")
    p.add_argument("--sigma", default="local", help="'local' (default) or a number >= 0")
    p.add_argument("--window", type=int, default=33, help="analysis window (cells, odd)")
    p.add_argument("--support", default="point", choices=("point", "area"))
    p.add_argument("--chunks", type=int, default=2048, help="block side in input cells")
    p.add_argument("--n-threads", type=int, default=None)
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=_run_resample)


def _number_or_local(v, name):
    if v == "local":
        return v
    try:
        return float(v)
    except ValueError:
        raise ValueError(f"{name}: expected 'local' or a number, got {v!r}") from None


def _run_resample(args: argparse.Namespace) -> int:
    import dask.array as da
    import numpy as np
    import rasterio
    from rasterio.windows import Window

    from fractalgeo_rs._validation import atomic_write_path, check_positive_int
    from fractalgeo_rs.dem import _resample as R
    from fractalgeo_rs.io import read_raster

    hurst = _number_or_local(args.hurst, "hurst")
    sigma = _number_or_local(args.sigma, "sigma")
    chunks = check_positive_int(args.chunks, "chunks")
    levels = R._levels(args.factor)
    f = 1 << levels
    z, profile = read_raster(args.input)
    if profile is None or profile.get("transform") is None:
        raise ValueError("input: expected a georeferenced raster (GeoTIFF)")
    tr = profile["transform"]
    cell = abs(tr.a)
    z = R._as_float(z, profile.get("nodata"))
    R._check_shape(z.shape)
    if not np.isfinite(z).any():
        raise ValueError("dem: every sample is NaN or nodata")
    detail = R._detail(levels, cell, args.min_scale)
    seed = R.resolve_seed(args.seed)
    an = R._maps(z, hurst, sigma, R._check_window(args.window), args.support,
                 hurst == "local", sigma == "local", min(1 << levels, 8))
    from fractalgeo_rs.dem._resample_dask import run_dask

    out = run_dask(da.from_array(z, chunks=chunks), levels, an.hurst, an.sigma, args.window,
                   detail, args.support, None, seed, args.n_threads, False)
    prof = dict(profile)
    prof.update(driver="GTiff", height=out.shape[0], width=out.shape[1], count=1,
                dtype="float32", nodata=float("nan"),
                transform=R.fine_transform(tr, f, args.support), tiled=True,
                blockxsize=256, blockysize=256, compress="deflate")
    nb = out.numblocks
    total = nb[0] * nb[1]
    with atomic_write_path(args.output) as tmp:
        with rasterio.open(tmp, "w", **prof) as dst:
            r0 = 0
            for i in range(nb[0]):
                c0 = 0
                for j in range(nb[1]):
                    blk = np.asarray(out.blocks[i, j].compute(), dtype=np.float32)
                    dst.write(blk, 1, window=Window(c0, r0, blk.shape[1], blk.shape[0]))
                    c0 += blk.shape[1]
                    if not args.quiet:
                        k = i * nb[1] + j + 1
                        bar = "#" * (30 * k // total)
                        print(f"\rresample [{bar:<30}] {k}/{total} blocks", end="",
                              file=sys.stderr, flush=True)
                r0 += out.chunks[0][i]
    if not args.quiet:
        print(file=sys.stderr)
    return 0
