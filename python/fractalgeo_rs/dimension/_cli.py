"""``fractalgeo dimension``: every estimator of :data:`fractalgeo_rs.dimension.METHODS`."""
from __future__ import annotations

import argparse
import sys

from fractalgeo_rs._cli_common import (HelpFormatter, LazyChoices, add_band, add_cell_size, add_n_threads,
                                        add_progress, add_raster_io)

#: The default estimator of each input kind and its options: the ones
#: ``docs/accuracy.md`` measures as accurate on fBm (transect madogram on
#: 256 x 256 surfaces: bias of D at most 0.006, RMSE at most 0.037; the
#: variogram on 1024-sample profiles: bias at most 0.014, RMSE at most 0.033)
#: and box counting for sets. On the bundled SRTM crops the transect
#: madogram reads D = 2.077 (Alps) and 2.236 (Po plain), in the valid
#: domain, where the square increments read below 2 (1.466, 1.687: the 3
#: arc-second DEM is smooth at lags 1-2) and Whittle pins H at its bound.
DEFAULTS = {"set": ("box", {}), "surface": ("surface_variation", {"estimator": "transect", "p": 1.0}),
            "profile": ("variogram", {})}
DEFAULT_METHOD = {kind: m for kind, (m, _) in DEFAULTS.items()}

#: What each method reads: a binary set, a graph (profile or surface) or a point set.
SET_METHODS = ("box", "points", "minkowski")
#: Methods that take a set or a graph (``mass``: P(m, L) of a binary image or of a surface).
ANY_METHODS = ("mass",)


def _method_choices():
    from fractalgeo_rs.dimension import METHODS

    return list(METHODS)


#: Estimators the accuracy tables of the documentation measure as biased on
#: fBm surfaces (bias of D at 256 x 256, H = 0.1-0.9): a note says so.
BIASED = {"dbc": "low by 0.13-0.39", "blanket": "low by 0.06-0.84", "affine": "low by 0.02-0.33",
          "wavelet": "high by 0.04-0.24", "spectral": "off by up to 0.15"}


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "dimension", formatter_class=HelpFormatter,
        help="estimate the fractal dimension of a raster file",
        description=(
            "Estimate the fractal dimension of a raster or a profile with any estimator of the API "
            "(fractalgeo_rs.dimension.METHODS). Reads GeoTIFF (needs the geo extra: rasterio), PNG or "
            "8/16-bit TIFF, EXR or .npy (a 1D .npy, or a raster of one row or column, is a profile). The "
            "input kind decides the default estimator: a binary set (bool, or integers with 0 and at most "
            "one other value, or --threshold) is box-counted; a surface gets surface_variation with the "
            "transect madogram (the median of the row and column profile dimensions, plus 1) and a profile "
            "the variogram, the estimators the accuracy tables of the documentation find accurate "
            "(DBC, blanket and self-affine boxes are biased by 0.1-0.8 on fBm). Prints the dimension, its "
            "95 % interval, the scales fitted, and a warning with the reason when the answer is outside "
            "the valid domain."
        ),
    )
    add_raster_io(p, input="path", band=False)
    p.add_argument("--method", default=None, choices=LazyChoices(_method_choices), metavar="METHOD",
                   help="estimator, one of fractalgeo_rs.dimension.METHODS: %(choices)s (default: box for a "
                   "binary set, surface_variation (transect madogram) for a surface, variogram for a profile)")
    add_band(p)
    p.add_argument("--threshold", type=float, default=None,
                   help="binary set = value > THRESHOLD (None: the input's own 0/nonzero mask, if binary)")
    p.add_argument("--box-sizes", default=None,
                   help="comma-separated box sizes in samples, for box-counting methods (None: the method's)")
    p.add_argument("--offsets", type=int, default=None,
                   help="lattice shifts per axis of box and dbc (None: the method's)")
    p.add_argument("--scale-range", default=None,
                   help="'auto' or LOW,HIGH: scales used in the fit (None: the method's)")
    add_cell_size(p)
    p.add_argument("--plot", default=None, metavar="PNG", help="write the log-log plot to this PNG (None: none)")
    add_n_threads(p)
    add_progress(p)
    p.set_defaults(func=_run_dimension)


def _parse_range(text):
    if text is None:
        return None
    if text == "auto":
        return "auto"
    try:
        lo, hi = (float(v) for v in text.split(","))
    except ValueError:
        raise ValueError(f"--scale-range: expected 'auto' or LOW,HIGH, got {text!r}") from None
    return (lo, hi)


def _read(args):
    """``(data, profile)``: a 1D ``.npy`` as a profile, else the raster."""
    import numpy as np

    from fractalgeo_rs.io import read_raster

    if str(args.path).lower().endswith(".npy"):
        try:
            a = np.load(args.path, mmap_mode="r", allow_pickle=False)
        except (OSError, ValueError):
            a = None  # read_raster says what is wrong
        if a is not None and getattr(a, "ndim", 0) == 1:
            if args.band not in (None, 1):
                raise ValueError(f"--band: a 1D .npy profile has one band, asked for {args.band}")
            return np.array(a), None
    return read_raster(args.path, band=args.band)


def input_kind(data, threshold) -> str:
    """``"set"``, ``"profile"`` or ``"surface"``."""
    from fractalgeo_rs.io import is_binary_mask

    if threshold is not None or (data.ndim == 2 and is_binary_mask(data)) or data.dtype == bool:
        return "set"
    if data.ndim == 1 or 1 in data.shape:
        return "profile"
    return "surface"


def _options(func, given: dict) -> dict:
    """The given options that ``func`` takes; an option it does not take is
    an error naming the CLI option."""
    import inspect

    params = inspect.signature(func).parameters
    out = {}
    for key, (opt, value) in given.items():
        if value is None or key.startswith("_"):
            continue
        if key not in params:
            if key in ("cell_size", "n_threads", "progress"):
                continue  # dimensions are scale free; single-threaded methods; no bar

            raise ValueError(f"{opt}: not an option of --method {given['_method'][1]}")
        out[key] = value
    return out


def _run_dimension(args: argparse.Namespace) -> int:
    import numpy as np

    from fractalgeo_rs import _progress
    from fractalgeo_rs.dimension import METHODS

    data, profile = _read(args)
    nodata = (profile or {}).get("nodata")
    if nodata is not None and not np.isnan(nodata):
        data = np.where(data == nodata, np.nan, data.astype(np.float64))
    from fractalgeo_rs.dimension import GRAPH_ONLY

    kind = input_kind(data, args.threshold)
    method = args.method or DEFAULT_METHOD[kind]
    defaults = {} if args.method else dict(DEFAULTS[kind][1])
    if method in GRAPH_ONLY and kind != "set":
        ndim, others = GRAPH_ONLY[method]
        if (kind == "profile") != (ndim == 1):
            need = "profile" if ndim == 1 else "surface"
            raise ValueError(f"--method {method}: estimates the dimension of a {need} and the input is a {kind}; "
                             f"use --method '{others}")
    if kind == "set":
        if args.threshold is not None:
            data = np.nan_to_num(data.astype(float), nan=-np.inf) > args.threshold
        elif data.dtype != bool:
            data = data != 0  # a 0/1 or 0/255 mask: the nonzero value is the foreground
        if method not in SET_METHODS + ANY_METHODS:
            raise ValueError(f"--method {method}: estimates the dimension of a graph (a surface or profile) "
                             f"and the input is a binary set; use --method box, points, minkowski or mass")
    elif method in SET_METHODS:
        raise ValueError(f"--method {method}: estimates the dimension of a binary set and the input is a "
                         f"{kind} of heights; give --threshold T (the set value > T) or a graph method such as "
                         f"--method {DEFAULT_METHOD[kind]}")
    if kind == "profile":
        data = np.asarray(data, dtype=np.float64).ravel()
    if method == "points":
        data = np.argwhere(data).astype(np.float64)
    box_sizes = None
    if args.box_sizes:
        try:
            box_sizes = [int(v) for v in args.box_sizes.split(",")]
        except ValueError:
            raise ValueError(f"--box-sizes: expected comma-separated integers, got {args.box_sizes!r}") from None
    func = METHODS[method]
    given = {"_method": ("--method", method), "n_threads": ("--n-threads", args.n_threads),
             "scale_range": ("--scale-range", _parse_range(args.scale_range)),
             "box_sizes": ("--box-sizes", box_sizes), "offsets": ("--offsets", args.offsets),
             "cell_size": ("--cell-size", args.cell_size), "progress": ("--progress", _progress.resolve(args.progress, cli=True))}
    opts = {**defaults, **_options(func, given)}
    if method in BIASED and kind == "surface":
        print(f"fractalgeo dimension: note: --method {method} is biased on fBm surfaces (D {BIASED[method]} at "
              f"256 x 256 in the accuracy tables of the documentation); surface_variation, variogram and whittle "
              f"are accurate", file=sys.stderr)
    if method == "mle":
        print("fractalgeo dimension: note: --method mle is the exact Gaussian likelihood, O(n^3) in the samples "
              "(up to 4096 of them): it can take 10-20 s; --method whittle is fast and as accurate on large "
              "inputs", file=sys.stderr, flush=True)
    import warnings

    from fractalgeo_rs.fit import FractalRangeWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FractalRangeWarning)  # printed once below, from the fit
        fit = func(data, **opts)
    print(f"file: {args.path}")
    print(f"input: {kind}, shape {data.shape}, dtype {data.dtype}")
    chosen = "".join(f", {k} {v}" for k, v in defaults.items())
    print(f"method: {method}" + ("" if args.method else f" (the default for a {kind}{chosen})"))
    lo, hi = fit.ci95
    interval = f"95 % interval [{lo:.4f}, {hi:.4f}]" if np.isfinite(lo) and np.isfinite(hi) else "no interval"
    if opts.get("estimator") == "transect" and np.isfinite(lo):
        # the interval of the median takes the rows and columns as independent
        interval += (" (of the median over rows and columns taken as independent, so narrower than the error: "
                     "RMSE 0.002-0.037 on fBm surfaces of 256-512 samples a side in the accuracy tables)")
    hurst = f", H = {fit.extra['hurst']:.4f}" if "hurst" in fit.extra else ""
    print(f"D = {fit.dimension:.4f}, {interval}{hurst}")
    s_lo, s_hi = fit.scale_range
    r2 = fit.r_squared
    r2_text = f", r^2 {r2:.4f}" if np.isfinite(r2) and r2 >= 0 else ""
    print(f"fitted scales: {s_lo:g} to {s_hi:g} {fit.x_label} ({fit.n_used} of {len(fit.scales)} scales, "
          f"{fit.range_selection}{r2_text})")
    if not fit.valid or fit.flags:
        reason = fit.warning or ", ".join(fit.flags)
        print(f"fractalgeo dimension: warning: {reason}", file=sys.stderr)
    print(f"{'scale':>10}  {fit.y_label}")
    measures = np.asarray(fit.measures, dtype=float)
    for s, m, u in zip(fit.scales, measures, fit.used):
        print(f"{s:10g}  {m:.6g}{'' if u else '  (not fitted)'}")
    if method in ("box", "dbc", "affine") and np.any(np.abs(measures - np.round(measures)) > 1e-9):
        print("(non-integer counts: boxes cut by the raster edge count by the share of them inside, and "
              "counts are means over the shifted lattices of --offsets)")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from fractalgeo_rs.plotting import save_figure

        fig, ax = plt.subplots(figsize=(5, 4))
        fit.plot(ax=ax)
        ax.set_title(f"{args.path}")
        save_figure(fig, args.plot)
        print(f"plot: {args.plot}")
    return 0
