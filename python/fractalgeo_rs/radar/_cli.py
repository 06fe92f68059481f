"""``fractalgeo sar``: a synthetic SAR scene of a DEM."""
from __future__ import annotations

import argparse
import os

import numpy as np

from fractalgeo_rs._cli_common import HelpFormatter, add_n_threads, add_progress, add_raster_io


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "sar", formatter_class=HelpFormatter,
        help="synthetic SAR intensity image of a DEM (layover, shadow, speckle)",
        description="A synthetic SAR scene (fractalgeo_rs.radar.simulate): local incidence from the DEM's "
        "facets, radar shadow, slant-range projection with layover, facet sigma0 from a backscatter model, "
        "L-look speckle, terrain-geocoded onto the DEM's grid. The output (float32, linear sigma0 or dB with "
        "--db, nodata NaN) keeps the DEM's CRS and transform. Cell size from the file's georeferencing "
        "(metres; on a geographic grid converted at the centre latitude) or --cell-size. A progress bar over the "
        "range lines is drawn when stderr is a terminal (--progress / --no-progress).",
    )
    add_raster_io(p, input="dem", output_help="output .tif (or .npy)", cell_size=True)
    p.add_argument("--incidence", type=float, required=True, help="incidence angle, degrees in (0, 90)")
    p.add_argument("--look-azimuth", type=float, default=90.0,
                   help="direction the radar looks, degrees clockwise from north (any; 0/90/180/270 follow the grid)")
    p.add_argument("--wavelength", type=float, default=0.056, help="radar wavelength, metres (C band 0.056)")
    p.add_argument("--model", default="kirchhoff", choices=("kirchhoff", "geometric_optics", "spm"),
                   help="facet backscatter model")
    p.add_argument("--looks", type=int, default=1, help="speckle looks (0: no speckle)")
    p.add_argument("--seed", type=int, default=None, help="speckle seed in [0, 2**64); None draws one")
    p.add_argument("--db", action="store_true", help="write 10 log10(intensity) instead of linear")
    add_n_threads(p)
    add_progress(p)
    p.set_defaults(func=_run_sar)


def _run_sar(args: argparse.Namespace) -> int:
    from fractalgeo_rs import _progress
    from fractalgeo_rs.dem._cli import ground_cell_size
    from fractalgeo_rs.io import read_raster, write_raster
    from fractalgeo_rs.radar import simulate, to_db

    # checked before the simulation, not after it in write_raster
    ext = os.path.splitext(str(args.output))[1].lower()
    if ext not in (".tif", ".tiff", ".npy"):
        raise ValueError(f"output: expected a .tif or .npy file name, got {str(args.output)!r}")
    z, prof = read_raster(args.dem, band=args.band)
    z = np.asarray(z, dtype=np.float64)
    cell = None
    if prof:
        nodata = prof.get("nodata")
        if nodata is not None:
            z = np.where(z == nodata, np.nan, z)
        cell = ground_cell_size(prof, z.shape[0])
    if args.cell_size is not None:
        cell = args.cell_size
    if cell is None:
        raise ValueError("cell_size: the DEM has no georeferencing; pass --cell-size (metres)")
    scene = simulate(z, cell, look_azimuth=args.look_azimuth, incidence=args.incidence,
                     wavelength=args.wavelength, model=args.model, looks=args.looks or None, seed=args.seed,
                     n_threads=args.n_threads, progress=_progress.resolve(args.progress, cli=True))
    img = scene.image
    if args.db:
        with np.errstate(divide="ignore"):
            img = np.where(img > 0, to_db(np.where(img > 0, img, 1.0)), np.nan)
    out = np.asarray(img, dtype=np.float32)
    if ext == ".npy":  # a bare array: no georeferencing to keep
        write_raster(args.output, out)
    else:
        write_raster(args.output, out, crs=(prof or {}).get("crs"), transform=(prof or {}).get("transform"),
                     nodata=float("nan"))
    print(f"sar: {z.shape[0]} x {z.shape[1]} DEM, incidence {args.incidence:g}, look azimuth "
          f"{args.look_azimuth:g}, {args.looks} looks: layover {100 * scene.layover.mean():.1f} %, "
          f"shadow {100 * scene.shadow.mean():.1f} % -> {args.output}")
    return 0
