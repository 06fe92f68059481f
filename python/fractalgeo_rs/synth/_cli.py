"""``fractalgeo synth`` and ``fractalgeo hillshade``."""
from __future__ import annotations

import argparse

import numpy as np


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "synth",
        help="synthesise fBm (1D) or a fractal surface (2D)",
        description="Synthesise fractional Brownian motion (1D, --size N) or a fractional Brownian "
        "surface (2D, --size ROWS COLS) and write it (.npy, .exr, .tif; 1D: .npy only).",
    )
    p.add_argument("output", help="output file (.npy, .exr, .tif)")
    p.add_argument("--hurst", type=float, required=True, help="Hurst exponent H in (0, 1); D = 3 - H for surfaces")
    p.add_argument("--size", type=int, nargs="+", required=True, metavar="N",
                   help="N samples (1D) or ROWS COLS (2D); one value with --dim 2 means a square")
    p.add_argument("--dim", type=int, choices=(1, 2), default=None, help="1 or 2 (default: from --size)")
    p.add_argument("--method", default="exact", choices=("exact", "midpoint", "additions", "spectral"))
    p.add_argument("--seed", type=int, default=None)
    p.add_argument("--sigma", type=float, default=1.0, help="increment std at unit distance")
    p.add_argument("--cell-size", type=float, default=1.0, help="grid spacing (2D)")
    p.add_argument("--periodic", action="store_true", help="periodic surface (spectral; midpoint at 2**k)")
    p.add_argument("--hillshade", metavar="PNG", default=None, help="also write a shaded-relief PNG (2D)")
    p.add_argument("--azimuth", type=float, default=315.0, help="light azimuth for --hillshade (degrees)")
    p.add_argument("--n-threads", type=int, default=None)
    p.set_defaults(func=_run_synth)

    h = sub.add_parser(
        "hillshade",
        help="shaded relief of a DEM as an 8-bit PNG",
        description="Lambertian shaded relief with Horn's gradients (GDAL's conventions; 0 = nodata, "
        "1-255 = shade). Cell size and nodata come from the file's georeferencing when it has any.",
    )
    h.add_argument("dem", help="DEM (.tif, .npy, .exr, .png, any GDAL format with rasterio)")
    h.add_argument("output", help="output PNG")
    h.add_argument("--azimuth", type=float, default=315.0)
    h.add_argument("--altitude", type=float, default=45.0)
    h.add_argument("--z-factor", type=float, default=1.0)
    h.add_argument("--cell-size", type=float, default=None, help="override the cell size")
    h.add_argument("--multidirectional", action="store_true")
    h.add_argument("--n-threads", type=int, default=None)
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
        return 0
    shape = (args.size[0], args.size[-1])
    z = fbm_surface(shape, args.hurst, method=args.method, seed=args.seed, sigma=args.sigma,
                    cell_size=args.cell_size, periodic=args.periodic, n_threads=args.n_threads)
    write_raster(args.output, z)
    if args.hillshade:
        s = hillshade(z, azimuth=args.azimuth, cell_size=args.cell_size, byte=True, n_threads=args.n_threads)
        write_raster(args.hillshade, s)
    return 0


def _run_hillshade(args: argparse.Namespace) -> int:
    from fractalgeo_rs.dem import hillshade
    from fractalgeo_rs.io import read_raster, write_raster

    z, prof = read_raster(args.dem)
    cell = 1.0
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
    write_raster(args.output, s)
    return 0
