"""``fractalgeo transform``: a georeferenced map of local fractal dimension."""
from __future__ import annotations

import argparse
import sys

from fractalgeo_rs._cli_common import (HelpFormatter, LazyChoices, add_band, add_cell_size, add_n_threads, add_progress,
                                        add_raster_io, input_georef)

#: Where the flags are explained in what the wheel ships (it has no docs/ folder).
FLAGS_HELP = "python -m pydoc fractalgeo_rs.transform.TransformFit"


def add_parsers(sub) -> None:
    p = sub.add_parser(
        "transform", formatter_class=HelpFormatter,
        help="map of local fractal dimension (moving window) as a float32 GeoTIFF",
        description="Moving-window fractal transform of a raster (paper section 4.2). Reads GeoTIFF "
                    "(rasterio) or any format read_raster knows; writes a float32 GeoTIFF with the input's "
                    "CRS and transform and tags recording method, window, step and the z_scale used (or .npy). "
                    "With --chunks the scene is processed by Dask in blocks for scenes larger than memory. A "
                    "progress bar is drawn when stderr is a terminal (--progress / --no-progress).",
    )
    add_raster_io(p, output_help="output map (.tif or .npy)", band=False)
    p.add_argument("--window", type=int, default=33, help="odd window side in pixels")
    p.add_argument("--method", default="mass", choices=LazyChoices(_method_names), metavar="METHOD",
                   help="estimator, one of %(choices)s (default mass: Voss's P(m, L), the paper's method)")
    p.add_argument("--z-scale", type=_z_scale, default="auto",
                   help="mass, dbc, blanket: height units per pixel (e.g. 1 dB or 1 grey level); default auto: "
                        "1.4826 x median |lag-1 increment| of the whole image, printed; 'range': (max - min) / "
                        "max(rows, cols); 'cell': the file's cell size (cubic boxes for a DEM whose heights and "
                        "cells share a unit; in metres on a DEM in metres); pass a fixed value to compare maps across "
                        "scenes")
    p.add_argument("--scale", choices=("db", "linear", "amplitude"), default=None,
                   help="radiometric scale of a SAR input: linear intensity is converted to 10 log10, amplitude "
                        "to 20 log10 (the maps were validated on dB); db: used as it is (None: used as it is, "
                        "with a warning when the input looks like linear intensity)")
    p.add_argument("--step", type=int, default=1,
                   help="compute every STEP-th row and column only (output cells STEP pixels wide, "
                        "centred on the input pixels they sample)")
    add_band(p)
    add_cell_size(p)
    p.add_argument("--chunks", type=int, default=None,
                   help="process with Dask in chunks of this side, with a progress bar (needs the dask extra; "
                        "None: in memory)")
    add_n_threads(p)
    add_progress(p)
    p.set_defaults(func=_run)


def _method_names():
    from fractalgeo_rs.transform._methods import METHODS

    return list(METHODS)


def map_tags(params: dict, input_units=None, input_cell_size=None) -> dict:
    """GeoTIFF metadata tags of a transform map: what makes maps comparable
    and reproducible (method, window, step, the ``z_scale`` used, units, and
    the input's cell size when it has one)."""
    z = params.get("z_scale")
    tags = {
        "FRACTAL_METHOD": params["method"],
        "WINDOW_SIZE": str(params["window_size"]),
        "STEP": str(params["step"]),
        "Z_SCALE": "none" if z is None else repr(float(z)),
        "UNITS": "fractal dimension (dimensionless)",
    }
    if z is not None:
        tags["Z_SCALE_UNITS"] = f"{input_units} per pixel" if input_units else "input units per pixel"
    if input_cell_size is not None:
        tags["INPUT_CELL_SIZE"] = f"{input_cell_size:.9g}"
    return tags


def _z_scale(text: str):
    return text if text in ("auto", "range", "cell") else float(text)


def _run(args: argparse.Namespace) -> int:
    import numpy as np

    from fractalgeo_rs import _progress
    from fractalgeo_rs.io import read_raster, write_raster
    from fractalgeo_rs.transform import FLAGS, fractal_transform

    if args.chunks is not None and args.chunks < 1:
        raise ValueError(f"--chunks: expected a positive chunk side in pixels, got {args.chunks}")
    data, profile = read_raster(args.input, band=args.band)
    to_tif = args.output.lower().endswith((".tif", ".tiff"))
    g = input_georef(args, profile, data.shape, announce=to_tif and args.z_scale != "cell")
    nodata = g["nodata"]
    cell = g["cell"][0]  # the x pixel size, sqrt(a^2 + d^2) on rotated grids
    if args.z_scale == "cell":
        if g["assumed"]:
            raise ValueError("--z-scale: 'cell' needs the input's cell size: the input has no georeferencing, "
                             "give --cell-size")
        args.z_scale = cell
        print(f"fractalgeo transform: note: --z-scale cell: {cell:.6g} height units per box step (cubic boxes), "
              f"right only when heights and cells share a unit; on a DEM whose relief is small against its "
              f"cells the map is then near 2 (use 'auto' to compare textures)", file=sys.stderr)
    show = _progress.resolve(args.progress, cli=True)
    opts = dict(method=args.method, nodata=nodata, n_threads=args.n_threads, z_scale=args.z_scale,
                step=args.step, return_fit=True, scale=args.scale)
    if args.chunks is not None:
        import dask.array as da  # the CLI turns a missing module into one line naming the extra

        arr = da.from_array(data, chunks=args.chunks)
        fit = fractal_transform(arr, args.window, **opts)
        with _progress.dask_bar(show):
            dmap, flags = da.compute(fit[0], fit.flags, scheduler="threads", num_workers=1)
    else:
        fit = fractal_transform(data, args.window, progress=show, **opts)
        dmap, flags = fit[0], fit.flags
    dmap = np.asarray(dmap, dtype=np.float32)
    tags = map_tags(fit.params, "dB" if args.scale else (profile or {}).get("units"), cell)
    if args.scale:
        tags["INPUT_SCALE"] = args.scale
    if args.output.lower().endswith((".tif", ".tiff")):
        transform = g["transform"]
        if transform is not None and args.step > 1:
            # output cell (k, l) is centred on input pixel (k step, l step)
            from rasterio import Affine

            shift = 0.5 - args.step / 2.0
            # Affine(a, b, c, d, e, f): x = a col + b row + c; the cell is step
            # pixels wide with its corner shifted by (1 - step) / 2 pixels
            step_cell = Affine(args.step, 0.0, shift, 0.0, args.step, shift)
            transform = transform @ step_cell if hasattr(transform, "__matmul__") else transform * step_cell
        write_raster(args.output, dmap, crs=g["crs"], transform=transform, nodata=float("nan"),
                     tags=tags)
    else:
        write_raster(args.output, dmap)
    finite = dmap[np.isfinite(dmap)]
    scale = f", {args.scale} input converted to dB" if args.scale in ("linear", "amplitude") else ""
    print(f"{args.input}: {data.shape}, window {args.window}, method {args.method}{scale}")
    if fit.params["z_scale"] is not None:
        print(f"z_scale: {fit.params['z_scale']:.6g} data units per box step")
    if finite.size:
        print(f"local dimension: mean {finite.mean():.3f}, 5-95 % {np.percentile(finite, 5):.3f}-"
              f"{np.percentile(finite, 95):.3f}, NaN pixels {dmap.size - finite.size}")
        flags = np.asarray(flags)[np.isfinite(dmap)]
        out = [f"{100 * np.mean(flags & bit > 0):.1f} % {name}" for name, bit in FLAGS.items()
               if name != "too_few_valid" and np.any(flags & bit)]
        if out:
            print("outside the valid domain: " + ", ".join(out) + f" (flags: {FLAGS_HELP})")
    print(f"map: {args.output}")
    return 0
