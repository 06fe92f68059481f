"""``fractalgeo resample`` (fractal resampling of a GeoTIFF DEM) and
``fractalgeo hillshade`` (shaded relief)."""
from __future__ import annotations

import argparse
from typing import Any

from fractalgeo_rs._cli_common import (HelpFormatter, add_band, add_cell_size, add_n_threads, add_progress,
                                        add_raster_io, input_georef, is_geographic, pixel_size)


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "resample", formatter_class=HelpFormatter,
        help="resample a DEM on a finer grid with fractal detail",
        description="Fractal resampling (fractalgeo_rs.fractal_resample): the DEM is analysed for "
        "its local Hurst exponent and roughness and refined by --factor (a power of 2) with "
        "conditional fBm detail. The output GeoTIFF keeps the CRS; the pixel size is divided by "
        "the factor. With dask installed (pip install \"fractalgeo_rs[dask]\", needed for outputs above "
        "the memory limit) it is computed in blocks of --chunks input cells and written block by block; "
        "without dask a result that fits in memory is computed in one piece (the same values).",
    )
    p.add_argument("input", help="input DEM (GeoTIFF or any format rasterio reads; .npy with --cell-size)")
    p.add_argument("output", help="output GeoTIFF (.tif or .tiff; float32, nodata NaN)")
    add_band(p)
    add_cell_size(p)
    p.add_argument("--factor", type=int, default=2, help="refinement factor, a power of 2")
    p.add_argument("--min-scale", type=float, default=None,
                   help="no random detail in cells smaller than this, in ground units (metres on a "
                   "geographic grid such as EPSG:4326: the cell size in metres is the larger of its x and "
                   "y spacings at the centre latitude; None: detail at every level)")
    p.add_argument("--seed", type=int, default=None, help="seed in [0, 2**64) (None: one is drawn and printed)")
    p.add_argument("--hurst", default="local",
                   help="Hurst exponent: 'local' (estimated in each window) or a number in (0, 1)")
    p.add_argument("--sigma", default="local",
                   help="detail scale: 'local' (estimated in each window) or a number >= 0")
    p.add_argument("--window", type=int, default=33, help="analysis window (cells, odd)")
    p.add_argument("--support", default="point", choices=("point", "area"),
                   help="point: input samples kept at their positions; area: input cells are block means, kept")
    p.add_argument("--chunks", type=int, default=2048, help="block side in input cells")
    add_n_threads(p)
    add_progress(p)
    p.add_argument("--quiet", dest="progress", action="store_false", help=argparse.SUPPRESS)
    p.set_defaults(func=_run_resample)

    h = sub.add_parser(
        "hillshade", formatter_class=HelpFormatter,
        help="shaded relief of a DEM as an 8-bit PNG",
        description="Lambertian shaded relief with Horn's gradients (GDAL's conventions; 0 = nodata, "
        "1-255 = shade; with -compute_edges the bytes of gdaldem hillshade -compute_edges). Cell size and "
        "nodata come from the file's georeferencing when it has any. A .tif output keeps the DEM's CRS and "
        "transform with nodata 0; a .png output gets a world file (.pgw) and the CRS in .prj.",
    )
    add_raster_io(h, input="dem", output_help="output .png or .tif")
    h.add_argument("--azimuth", type=float, default=315.0, help="light azimuth, degrees clockwise from north")
    h.add_argument("--altitude", type=float, default=45.0, help="light altitude, degrees above the horizon")
    h.add_argument("--z-factor", type=float, default=1.0, help="vertical exaggeration, > 0")
    add_cell_size(h)
    h.add_argument("--multidirectional", action="store_true", help="GDAL's multidirectional shading")
    add_n_threads(h)
    h.set_defaults(func=_run_hillshade)


def _number_or_local(v, name):
    if v == "local":
        return v
    try:
        return float(v)
    except ValueError:
        raise ValueError(f"{name}: expected 'local' or a number, got {v!r}") from None


def _ground_cell(tr, crs, rows):
    """Cell size for ``min_scale`` and its unit: the transform's x spacing in
    map units on a projected grid; on a geographic one the larger of the x
    and y spacings in metres at the centre latitude (WGS84,
    :func:`~fractalgeo_rs.dem.metres_per_degree`)."""
    if not is_geographic(crs):
        return pixel_size(tr)[0], ""
    from fractalgeo_rs.dem import metres_per_degree

    lat = tr.f + tr.e * rows / 2.0
    if tr.b != 0 or tr.d != 0 or not -90.0 <= lat <= 90.0:
        raise ValueError("input: a geographic grid that is rotated or has its centre outside latitude "
                         "[-90, 90]: --min-scale needs its cell size in metres; give a projected DEM")
    m_lat, m_lon = metres_per_degree(lat)
    return max(abs(tr.a) * float(m_lon), abs(tr.e) * float(m_lat)), " m"


def _run_resample(args: argparse.Namespace) -> int:
    import numpy as np
    import rasterio
    from rasterio.windows import Window

    from fractalgeo_rs import _progress
    from fractalgeo_rs._validation import (MemoryLimitError, atomic_write_path, check_positive_int, check_seed,
                                           check_window)
    from fractalgeo_rs.dem import _resample as R
    from fractalgeo_rs.io import read_raster

    if not str(args.output).lower().endswith((".tif", ".tiff")):
        raise ValueError(f"output: expected a GeoTIFF (.tif or .tiff), got {args.output!r}")
    hurst = _number_or_local(args.hurst, "hurst")
    sigma = _number_or_local(args.sigma, "sigma")
    chunks = check_positive_int(args.chunks, "chunks")
    levels = R.levels_of(args.factor)
    f = 1 << levels
    z, profile = read_raster(args.input, band=args.band)
    g = input_georef(args, profile, z.shape)
    profile = dict(profile or {}, transform=g["transform"], crs=g["crs"], nodata=g["nodata"])
    tr = profile["transform"]
    cell, unit = _ground_cell(tr, profile.get("crs"), z.shape[0])
    z = R._as_float(z, profile.get("nodata"))
    R._check_shape(z.shape)
    if not np.isfinite(z).any():
        raise ValueError("dem: every sample is NaN or nodata")
    detail = R.detail_levels(levels, cell, args.min_scale)
    seed = check_seed(args.seed)
    window = check_window(args.window, minimum=5, cover=True)
    da: Any
    try:
        import dask.array as da
    except ImportError as exc:
        # Without dask: in memory when the result fits under the memory limit.
        try:
            R._check_memory(z.shape, f)
        except MemoryLimitError:
            raise ModuleNotFoundError(f"{exc}", name="dask") from None
        da = None
    prof = dict(profile)
    if prof.get("crs") is None:
        prof.pop("crs")  # rasterio warns about nothing then
    prof.update(driver="GTiff", count=1, dtype="float32", nodata=float("nan"),
                transform=R.fine_transform(tr, f, args.support), tiled=True,
                blockxsize=256, blockysize=256, compress="deflate")
    show = _progress.resolve(args.progress, cli=True)
    if da is None:
        out, _ = R.run_numpy(z, levels, hurst, sigma, window, detail, args.support, None, seed,
                             args.n_threads)
        prof.update(height=out.shape[0], width=out.shape[1])
        with atomic_write_path(args.output) as tmp, _progress.bar(1, "resample", show) as pbar:
            with rasterio.open(tmp, "w", **prof) as dst:
                dst.write(out.astype(np.float32), 1)
            pbar.update(1)
    else:
        from fractalgeo_rs.dem._resample_dask import run_dask

        an = R._maps(z, hurst, sigma, window, args.support, hurst == "local", sigma == "local",
                     min(1 << levels, 8), args.n_threads, levels=levels,
                     model=R.check_model(None, hurst == "local", sigma == "local"))
        out = run_dask(da.from_array(z, chunks=chunks), levels, an.level_hurst, an.level_sigma, window,
                       detail, args.support, None, seed, args.n_threads, False)
        prof.update(height=out.shape[0], width=out.shape[1])
        nb = out.numblocks
        total = nb[0] * nb[1]
        with atomic_write_path(args.output) as tmp, _progress.bar(total, "resample", show) as pbar:
            with rasterio.open(tmp, "w", **prof) as dst:
                r0 = 0
                for i in range(nb[0]):
                    c0 = 0
                    for j in range(nb[1]):
                        blk = np.asarray(out.blocks[i, j].compute(), dtype=np.float32)
                        dst.write(blk, 1, window=Window(c0, r0, blk.shape[1], blk.shape[0]))
                        c0 += blk.shape[1]
                        pbar.update(1)
                    r0 += out.chunks[0][i]
    print(f"resample: {z.shape[0]} x {z.shape[1]} -> {out.shape[0]} x {out.shape[1]} (factor {f}, "
          f"{args.support} support, cell {cell:g}{unit}, seed {seed}) -> {args.output}")
    return 0


def _run_hillshade(args: argparse.Namespace) -> int:
    import numpy as np

    from fractalgeo_rs.dem import hillshade
    from fractalgeo_rs.io import read_raster, write_raster

    z, prof = read_raster(args.dem, band=args.band)
    g = input_georef(args, prof, z.shape, name="dem")
    t = g["transform"]
    nodata = g["nodata"]
    sx, sy = g["cell"]
    cell: Any = (sy, sx)  # (row, column) spacing; sqrt(a^2 + d^2) etc. on rotated grids
    latitude = None
    if is_geographic(g["crs"]) and args.cell_size is None:
        latitude = t.f + t.e * (np.arange(z.shape[0]) + 0.5)
    s = hillshade(z, azimuth=args.azimuth, altitude=args.altitude, z_factor=args.z_factor, cell_size=cell,
                  nodata=nodata, multidirectional=args.multidirectional, latitude=latitude, byte=True,
                  n_threads=args.n_threads)
    crs = g["crs"]
    transform = t
    if str(args.output).lower().endswith((".tif", ".tiff")):
        write_raster(args.output, s, crs=crs, transform=transform, nodata=0)
    else:
        write_raster(args.output, s, crs=crs, transform=transform)
    cs = cell if isinstance(cell, tuple) else (cell, cell)
    print(f"hillshade: {z.shape[0]} x {z.shape[1]} DEM, cell {cs[0]:g} x {cs[1]:g}, azimuth {args.azimuth:g}, "
          f"altitude {args.altitude:g}, {int((s == 0).sum())} nodata pixels -> {args.output}")
    return 0


def read_dem_ground(path, band, cell_size, option: str = "dem"):
    """Heights (float64), the rasterio profile and the ``(dy, dx)`` cell in
    metres of a DEM file for the commands that need ground units (``render``,
    ``brf``, ``canopy --plant``): nodata cells are refused (naming
    ``option``), the cell comes from :func:`ground_cell_size` and
    ``cell_size`` (a number or a pair, ``--cell-size``) replaces it; ``None``
    when neither gives one (the caller names the missing option)."""
    import numpy as np

    from fractalgeo_rs.io import read_raster

    z, prof = read_raster(path, band=band)
    z = np.asarray(z, dtype=np.float64)
    cell = None
    if prof:
        nodata = prof.get("nodata")
        if nodata is not None and np.any(z == nodata):
            raise ValueError(f"{option}: {int(np.sum(z == nodata))} nodata cell(s); fill them first "
                             "(e.g. rasterio.fill.fillnodata)")
        cell = ground_cell_size(prof, z.shape[0])
    if cell_size is not None:
        cell = cell_size
    return z, prof, cell


def ground_cell_size(prof, rows):
    """``(dy, dx)``, the cell of a raster read by ``read_raster`` in metres
    (map units of a projected grid; metres at the grid's middle latitude for
    a geographic one): the pixel sides of its transform, rotated grids
    included (:func:`~fractalgeo_rs._cli_common.pixel_size`); ``None``
    without a transform."""
    from fractalgeo_rs._cli_common import is_geographic, pixel_size
    from fractalgeo_rs.dem import metres_per_degree

    t = prof.get("transform") if prof else None
    if t is None:
        return None
    dx, dy = pixel_size(t)
    if is_geographic(prof.get("crs")):
        m_lat, m_lon = metres_per_degree(t.f + t.e * rows / 2)
        dy, dx = dy * float(m_lat), dx * float(m_lon)
    return dy, dx
