"""``fractalgeo synth``: fBm profiles, fBm surfaces and physical synthetic DEMs."""
from __future__ import annotations

import argparse
import sys

from fractalgeo_rs._cli_common import HelpFormatter, add_n_threads, add_progress

#: Above this many samples the default 2D method is "spectral" (two FFTs of
#: the grid) instead of "exact" (an FFT over a torus about 2-3x larger per
#: axis): 4096 x 4096 exact took 25.7 s and 4.6 GB.
EXACT_DEFAULT_LIMIT = 2048 * 2048


def _bytes(text: str) -> int:
    """``--max-memory``: bytes, with an optional K, M, G or T suffix (powers of 1024)."""
    t = text.strip().upper().rstrip("B")
    mult = 1
    if t and t[-1] in "KMGT":
        mult = 1024 ** ("KMGT".index(t[-1]) + 1)
        t = t[:-1]
    try:
        v = float(t) * mult
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected bytes such as 8e9 or 6G, got {text!r}") from None
    if not v > 0:
        raise argparse.ArgumentTypeError(f"expected a positive size, got {text!r}")
    return int(v)


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "synth", formatter_class=HelpFormatter,
        help="synthesise fBm (1D), a fractal surface or a synthetic DEM in metres (2D)",
        description="Synthesise fractional Brownian motion (1D, --size N) or a fractional Brownian "
        "surface (2D, --size ROWS COLS) and write it (.npy, .exr, .tif; 1D: .npy only). With --relief "
        "the surface is a DEM in metres (fractalgeo_rs.synthetic_dem): heights whose expected standard deviation "
        "over the grid is that value (one draw's std scatters around it), or that std of height differences "
        "at --relief-lag metres, around --mean-elevation. A GeoTIFF gets "
        "a transform of --cell-size square cells (upper-left corner at (0, ROWS * cell size)), the --crs "
        "if given, and the tags CELL_SIZE, HURST, METHOD, SEED (the seed used, also printed: pass it "
        "back with --seed to repeat the run). Time and peak memory are printed. A progress bar is drawn "
        "when stderr is a terminal (--progress / --no-progress).",
    )
    p.add_argument("output", help="output file (.npy, .exr, .tif)")
    p.add_argument("--hurst", type=float, required=True, help="Hurst exponent H in (0, 1); D = 3 - H for surfaces")
    p.add_argument("--size", type=int, nargs="+", required=True, metavar="N",
                   help="N samples (1D) or ROWS COLS (2D); one value with --dim 2 means a square")
    p.add_argument("--dim", type=int, choices=(1, 2), default=None, help="1 or 2 (None: from --size)")
    p.add_argument("--method", default=None, choices=("exact", "midpoint", "additions", "spectral"),
                   help="synthesis method, see fractalgeo_rs.fbm_surface (None: exact, or spectral above "
                   f"{EXACT_DEFAULT_LIMIT} samples in 2D, for speed and memory)")
    p.add_argument("--seed", type=int, default=None, help="seed in [0, 2**64) (None: one is drawn and printed)")
    p.add_argument("--sigma", type=float, default=1.0,
                   help="increment std at unit distance (ignored with --relief)")
    p.add_argument("--relief", type=float, default=None,
                   help="2D: a DEM in metres with this expected height std over the grid, or this std of height "
                   "differences at --relief-lag metres (None: an fBm surface of --sigma)")
    p.add_argument("--relief-lag", type=float, default=None,
                   help="with --relief: lag in metres of the relief (None: the std over the grid)")
    p.add_argument("--mean-elevation", type=float, default=None,
                   help="with --relief: mean height in metres (None: 0)")
    p.add_argument("--cell-size", type=float, default=1.0, help="grid spacing (2D), written into the transform")
    p.add_argument("--crs", default=None, help="CRS of a GeoTIFF output, e.g. EPSG:32633 (None: none)")
    p.add_argument("--periodic", action="store_true", help="periodic surface (spectral; midpoint at 2**k)")
    p.add_argument("--hillshade", metavar="PNG", default=None,
                   help="also write a shaded-relief PNG (2D; None: none)")
    p.add_argument("--azimuth", type=float, default=315.0, help="light azimuth for --hillshade (degrees)")
    p.add_argument("--altitude", type=float, default=45.0, help="light altitude for --hillshade (degrees)")
    p.add_argument("--max-memory", type=_bytes, default=None,
                   help="largest working memory of the synthesis, bytes or e.g. 6G (None: "
                   "$FRACTALGEO_MAX_MEMORY, else half the available memory)")
    add_n_threads(p)
    add_progress(p)
    p.set_defaults(func=_run_synth)


def _peak_rss_bytes() -> float:
    try:
        import resource

        return float(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) * 1024.0  # kB on Linux
    except (ImportError, OSError):  # pragma: no cover - non-POSIX
        return float("nan")


def _run_synth(args: argparse.Namespace) -> int:
    import os

    from fractalgeo_rs._validation import MAX_MEMORY_ENV

    old = os.environ.get(MAX_MEMORY_ENV)
    if args.max_memory is not None:
        os.environ[MAX_MEMORY_ENV] = str(args.max_memory)  # read by every memory check of this run
    try:
        return _synth(args)
    finally:  # the process (a test, a script calling main) keeps its own limit
        if old is None:
            os.environ.pop(MAX_MEMORY_ENV, None)
        else:
            os.environ[MAX_MEMORY_ENV] = old


def _synth(args: argparse.Namespace) -> int:
    import time

    from fractalgeo_rs import _progress
    from fractalgeo_rs.io import write_raster
    from fractalgeo_rs.synth import fbm, fbm_surface, synthetic_dem
    from fractalgeo_rs.synth._common import resolve_seed

    dim = args.dim or (1 if len(args.size) == 1 else 2)
    if len(args.size) > 2 or (dim == 1 and len(args.size) != 1):
        raise ValueError(f"--size: expected N (1D) or ROWS COLS (2D), got {' '.join(map(str, args.size))}")
    dem_opts = (args.relief_lag, args.mean_elevation)
    if args.relief is None and any(v is not None for v in dem_opts):
        raise ValueError("--relief-lag, --mean-elevation: need --relief (a DEM in metres)")
    seed = resolve_seed(args.seed)
    show = _progress.resolve(args.progress, cli=True)
    t0 = time.perf_counter()
    if dim == 1:
        if args.hillshade:
            raise ValueError("--hillshade: only for 2D surfaces")
        if args.relief is not None:
            raise ValueError("--relief: only for 2D surfaces (a DEM)")
        if not str(args.output).lower().endswith(".npy"):
            raise ValueError("output: 1D fBm is written as .npy")
        method = args.method or "exact"
        x = fbm(args.size[0], args.hurst, method=method, seed=seed, sigma=args.sigma,
                n_threads=args.n_threads, max_memory=args.max_memory, progress=show)
        write_raster(args.output, x)
        print(f"synth: {args.size[0]} samples of fBm (H = {args.hurst}, {method}, seed {seed}) -> {args.output}")
        _report(t0)
        return 0
    shape = (args.size[0], args.size[-1])
    method = args.method
    if method is None:
        method = "exact" if shape[0] * shape[1] <= EXACT_DEFAULT_LIMIT else "spectral"
        if method != "exact":
            print(f"fractalgeo synth: note: --method spectral (the default above {EXACT_DEFAULT_LIMIT} samples, "
                  f"for speed and memory); --method exact gives the exact fBm covariance", file=sys.stderr)
    if args.relief is not None:
        z = synthetic_dem(shape, args.hurst, cell_size=args.cell_size, relief=args.relief,
                          relief_lag=args.relief_lag, mean_elevation=args.mean_elevation or 0.0, method=method,
                          seed=seed, n_threads=args.n_threads, progress=show)
        what = "synthetic DEM (m)"
    else:
        z = fbm_surface(shape, args.hurst, method=method, seed=seed, sigma=args.sigma,
                        cell_size=args.cell_size, periodic=args.periodic, n_threads=args.n_threads,
                        max_memory=args.max_memory, progress=show)
        what = "fBm surface"
    geo = {}
    if str(args.output).lower().endswith((".tif", ".tiff")) or args.hillshade:
        from fractalgeo_rs._cli_common import georeference_of_grid

        geo = {"transform": georeference_of_grid(shape[0], args.cell_size), "crs": args.crs}
    if str(args.output).lower().endswith((".tif", ".tiff")):
        tags = {"CELL_SIZE": repr(args.cell_size), "HURST": repr(args.hurst), "METHOD": method, "SEED": str(seed)}
        if args.relief is not None:
            tags.update(RELIEF=repr(args.relief), UNITS="m")
        write_raster(args.output, z, crs=geo["crs"], transform=geo["transform"], tags=tags)
    else:
        if args.crs is not None:
            raise ValueError(f"--crs: {args.output!r} cannot hold a CRS (write a .tif)")
        write_raster(args.output, z)
    print(f"synth: {shape[0]} x {shape[1]} {what} (H = {args.hurst}, {method}, cell size {args.cell_size:g}, "
          f"seed {seed}), heights {float(z.min()):.4g} to {float(z.max()):.4g} -> {args.output}")
    _report(t0)
    if args.hillshade:
        from fractalgeo_rs.dem import hillshade

        s = hillshade(z, azimuth=args.azimuth, altitude=args.altitude, cell_size=args.cell_size, byte=True,
                      n_threads=args.n_threads)
        write_raster(args.hillshade, s, crs=geo["crs"], transform=geo["transform"])
        print(f"hillshade: {args.hillshade}")
    return 0


def _report(t0: float) -> None:
    import time

    peak = _peak_rss_bytes()
    mem = f", peak memory {peak / 2**30:.2f} GiB" if peak == peak else ""
    print(f"time {time.perf_counter() - t0:.2f} s{mem}")
