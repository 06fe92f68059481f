"""``fractalgeo dimension``."""
from __future__ import annotations

import argparse

from fractalgeo_rs._cli_common import HelpFormatter, add_band, add_n_threads, add_raster_io


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "dimension", formatter_class=HelpFormatter,
        help="estimate the fractal dimension of a raster file",
        description=(
            "Estimate the fractal dimension of a raster: GeoTIFF (needs the geo extra: rasterio), "
            "PNG or 8/16-bit TIFF (Rust image crate), EXR or .npy. With --method box the raster is "
            "a binary set (nonzero = foreground, or --threshold); dbc and affine read it as a surface."
        ),
    )
    add_raster_io(p, input="path", band=False)
    p.add_argument("--method", default=None, choices=["box", "dbc", "affine"],
                   help="estimator (default: box for a binary mask: bool, or integers with 0 and at most one "
                        "other value such as 0/1 and 0/255 PNGs; else dbc)")
    add_band(p)
    p.add_argument("--threshold", type=float, default=None,
                   help="for --method box: foreground is value > THRESHOLD")
    p.add_argument("--box-sizes", default=None, help="comma-separated box sizes in samples")
    p.add_argument("--offsets", type=int, default=1, help="lattice shifts per axis (default 1)")
    p.add_argument("--scale-range", default=None,
                   help="'auto' or LOW,HIGH: box sizes used in the fit (default all)")
    p.add_argument("--plot", default=None, metavar="PNG", help="write the log-log plot to this PNG")
    add_n_threads(p)
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


def _run_dimension(args: argparse.Namespace) -> int:
    import numpy as np

    from fractalgeo_rs.dimension import dimension
    from fractalgeo_rs.io import is_binary_mask, read_raster

    data, profile = read_raster(args.path, band=args.band)
    nodata = (profile or {}).get("nodata")
    if nodata is not None and not np.isnan(nodata):
        data = np.where(data == nodata, np.nan, data.astype(np.float64))
    method = args.method
    if method is None:
        is_binary = is_binary_mask(data)
        method = "box" if is_binary or args.threshold is not None else "dbc"
        if is_binary and args.threshold is None and data.dtype != bool:
            data = data != 0  # a 0/1 or 0/255 mask: the nonzero value is the foreground
    opts = {"n_threads": args.n_threads, "scale_range": _parse_range(args.scale_range)}
    if args.box_sizes:
        try:
            opts["box_sizes"] = [int(v) for v in args.box_sizes.split(",")]
        except ValueError:
            raise ValueError(f"--box-sizes: expected comma-separated integers, got {args.box_sizes!r}") from None
    if method == "box":
        if args.threshold is not None:
            data = np.nan_to_num(data.astype(float), nan=-np.inf) > args.threshold
        opts["offsets"] = args.offsets
    elif method == "dbc":
        opts["offsets"] = args.offsets
    fit = dimension(data, method=method, **opts)
    print(f"file: {args.path}")
    print(f"shape: {data.shape}, dtype: {data.dtype}")
    print(fit)
    print("scale  measure")
    for s, m, u in zip(fit.scales, fit.measures, fit.used):
        print(f"{s:6g}  {m:.6g}{'' if u else '  (not fitted)'}")
    if args.plot:
        from fractalgeo_rs.plotting import save_figure

        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 4))
        fit.plot(ax=ax)
        ax.set_title(f"{args.path}")
        save_figure(fig, args.plot)
        print(f"plot: {args.plot}")
    return 0
