"""``fractalgeo synth`` and ``fractalgeo hillshade``."""
from __future__ import annotations

import argparse


from fractalgeo_rs._cli_common import HelpFormatter, add_n_threads, add_progress


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "synth", formatter_class=HelpFormatter,
        help="synthesise fBm (1D) or a fractal surface (2D)",
        description="Synthesise fractional Brownian motion (1D, --size N) or a fractional Brownian "
        "surface (2D, --size ROWS COLS) and write it (.npy, .exr, .tif; 1D: .npy only). A GeoTIFF gets "
        "a transform of --cell-size square cells (upper-left corner at (0, ROWS * cell size)), the --crs "
        "if given, and the tags CELL_SIZE, HURST, METHOD, SEED. A progress bar of the synthesis is drawn "
        "when stderr is a terminal (--progress / --no-progress).",
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
    add_progress(p)
    p.set_defaults(func=_run_synth)


def _run_synth(args: argparse.Namespace) -> int:
    from fractalgeo_rs import _progress
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
                n_threads=args.n_threads, progress=_progress.resolve(args.progress, cli=True))
        if not str(args.output).lower().endswith(".npy"):
            raise ValueError("output: 1D fBm is written as .npy")
        write_raster(args.output, x)
        print(f"synth: {args.size[0]} samples of fBm (H = {args.hurst}, {args.method}) -> {args.output}")
        return 0
    shape = (args.size[0], args.size[-1])
    z = fbm_surface(shape, args.hurst, method=args.method, seed=args.seed, sigma=args.sigma,
                    cell_size=args.cell_size, periodic=args.periodic, n_threads=args.n_threads,
                    progress=_progress.resolve(args.progress, cli=True))
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
