"""``fractalgeo synth`` and ``fractalgeo hillshade``."""
from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from fractalgeo_rs._cli_common import HelpFormatter, add_n_threads


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "synth", formatter_class=HelpFormatter,
        help="synthesise fBm (1D) or a fractal surface (2D)",
        description="Synthesise fractional Brownian motion (1D, --size N) or a fractional Brownian "
        "surface (2D, --size ROWS COLS) and write it (.npy, .exr, .tif; 1D: .npy only). A GeoTIFF gets "
        "a transform of --cell-size square cells (upper-left corner at (0, ROWS * cell size)), the --crs "
        "if given, and the tags CELL_SIZE, HURST, METHOD, SEED.",
    )
    p.add_argument("output", help="output file (.npy, .exr, .tif)")
    p.add_argument("--hurst", type=float, required=True, help="Hurst exponent H in (0, 1); D = 3 - H for surfaces")
    p.add_argument("--size", type=int, nargs="+", required=True, metavar="N",
                   help="N samples (1D) or ROWS COLS (2D); one value with --dim 2 means a square")
    p.add_argument("--dim", type=int, choices=(1, 2), default=None, help="1 or 2 (default: from --size)")
    p.add_argument("--method", default="exact", choices=("exact", "midpoint", "additions", "spectral"),
                   help="synthesis method (see fractalgeo_rs.fbm_surface)")
    p.add_argument("--seed", type=int, default=None, help="seed in [0, 2**64); None draws one")
    p.add_argument("--sigma", type=float, default=1.0, help="increment std at unit distance")
    p.add_argument("--cell-size", type=float, default=1.0, help="grid spacing (2D), written into the transform")
    p.add_argument("--crs", default=None, help="CRS of a GeoTIFF output, e.g. EPSG:32633 (default: none)")
    p.add_argument("--periodic", action="store_true", help="periodic surface (spectral; midpoint at 2**k)")
    p.add_argument("--hillshade", metavar="PNG", default=None, help="also write a shaded-relief PNG (2D)")
    p.add_argument("--azimuth", type=float, default=315.0, help="light azimuth for --hillshade (degrees)")
    p.add_argument("--altitude", type=float, default=45.0, help="light altitude for --hillshade (degrees)")
    add_n_threads(p)
    p.set_defaults(func=_run_synth)

    h = sub.add_parser(
        "hillshade", formatter_class=HelpFormatter,
        help="shaded relief of a DEM as an 8-bit PNG",
        description="Lambertian shaded relief with Horn's gradients (GDAL's conventions; 0 = nodata, "
        "1-255 = shade; with -compute_edges the bytes of gdaldem hillshade -compute_edges). Cell size and "
        "nodata come from the file's georeferencing when it has any. A .tif output keeps the DEM's CRS and "
        "transform with nodata 0; a .png output gets a world file (.pgw) and the CRS in .prj.",
    )
    h.add_argument("dem", help="DEM (.tif, .npy, .exr, .png, any GDAL format with rasterio)")
    h.add_argument("output", help="output .png or .tif")
    h.add_argument("--band", type=int, default=None, help="1-based band of the DEM (None: its only band)")
    h.add_argument("--azimuth", type=float, default=315.0, help="light azimuth, degrees clockwise from north")
    h.add_argument("--altitude", type=float, default=45.0, help="light altitude, degrees above the horizon")
    h.add_argument("--z-factor", type=float, default=1.0, help="vertical exaggeration, > 0")
    h.add_argument("--cell-size", type=float, default=None, help="override the file's cell size")
    h.add_argument("--multidirectional", action="store_true", help="GDAL's multidirectional shading")
    add_n_threads(h)
    h.set_defaults(func=_run_hillshade)


def _run_synth(args: argparse.Namespace) -> int:
    from fractalgeo_rs.dem import hillshade
    from fractalgeo_rs.io import write_raster
    from fractalgeo_rs.synth import fbm, fbm_surface

    dim = args.dim or (1 if len(args.size) == 1 else 2)
    if len(args.size) > 2 or (dim == 1 and len(args.size) != 1):
        raise ValueError(f"size: expected N (1D) or ROWS COLS (2D), got {args.size}")
    if dim == 1:
        if args.hillshade:
            raise ValueError("hillshade: only for 2D surfaces")
        x = fbm(args.size[0], args.hurst, method=args.method, seed=args.seed, sigma=args.sigma,
                n_threads=args.n_threads)
        if not str(args.output).lower().endswith(".npy"):
            raise ValueError("output: 1D fBm is written as .npy")
        write_raster(args.output, x)
        print(f"synth: {args.size[0]} samples of fBm (H = {args.hurst}, {args.method}) -> {args.output}")
        return 0
    shape = (args.size[0], args.size[-1])
    z = fbm_surface(shape, args.hurst, method=args.method, seed=args.seed, sigma=args.sigma,
                    cell_size=args.cell_size, periodic=args.periodic, n_threads=args.n_threads)
    geo = {}
    if str(args.output).lower().endswith((".tif", ".tiff")) or args.hillshade:
        from fractalgeo_rs._cli_common import georeference_of_grid

        geo = {"transform": georeference_of_grid(shape[0], args.cell_size), "crs": args.crs}
    if str(args.output).lower().endswith((".tif", ".tiff")):
        write_raster(args.output, z, crs=geo["crs"], transform=geo["transform"],
                     tags={"CELL_SIZE": repr(args.cell_size), "HURST": repr(args.hurst), "METHOD": args.method,
                           "SEED": str(args.seed)})
    else:
        if args.crs is not None:
            raise ValueError(f"crs: {args.output!r} cannot hold a CRS (write a .tif)")
        write_raster(args.output, z)
    print(f"synth: {shape[0]} x {shape[1]} fBm surface (H = {args.hurst}, {args.method}, cell size "
          f"{args.cell_size:g}), heights {float(z.min()):.4g} to {float(z.max()):.4g} -> {args.output}")
    if args.hillshade:
        s = hillshade(z, azimuth=args.azimuth, altitude=args.altitude, cell_size=args.cell_size, byte=True,
                      n_threads=args.n_threads)
        write_raster(args.hillshade, s, crs=geo["crs"], transform=geo["transform"])
        print(f"hillshade: {args.hillshade}")
    return 0


def _run_hillshade(args: argparse.Namespace) -> int:
    from fractalgeo_rs.dem import hillshade
    from fractalgeo_rs.io import read_raster, write_raster

    z, prof = read_raster(args.dem, band=args.band)
    cell: Any = 1.0
    latitude = None
    nodata = None
    if prof:
        t = prof.get("transform")
        nodata = prof.get("nodata")
        if t is not None:
            cell = (abs(t.e), abs(t.a))
            crs = prof.get("crs")
            if crs is not None and getattr(crs, "is_geographic", False):
                latitude = t.f + t.e * (np.arange(z.shape[0]) + 0.5)
    if args.cell_size is not None:
        cell = args.cell_size
    s = hillshade(z, azimuth=args.azimuth, altitude=args.altitude, z_factor=args.z_factor, cell_size=cell,
                  nodata=nodata, multidirectional=args.multidirectional, latitude=latitude, byte=True,
                  n_threads=args.n_threads)
    crs = (prof or {}).get("crs")
    transform = (prof or {}).get("transform")
    if str(args.output).lower().endswith((".tif", ".tiff")):
        write_raster(args.output, s, crs=crs, transform=transform, nodata=0)
    else:
        write_raster(args.output, s, crs=crs, transform=transform)
    cs = cell if isinstance(cell, tuple) else (cell, cell)
    print(f"hillshade: {z.shape[0]} x {z.shape[1]} DEM, cell {cs[0]:g} x {cs[1]:g}, azimuth {args.azimuth:g}, "
          f"altitude {args.altitude:g}, {int((s == 0).sum())} nodata pixels -> {args.output}")
    return 0
