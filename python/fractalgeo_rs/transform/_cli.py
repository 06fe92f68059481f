"""``fractalgeo transform``: a georeferenced map of local fractal dimension."""
from __future__ import annotations

import argparse

from fractalgeo_rs._cli_common import HelpFormatter, add_band, add_n_threads, add_progress, add_raster_io


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
    p.add_argument("--window", type=int, default=33, help="odd window side in pixels (default 33)")
    from fractalgeo_rs.transform._methods import METHODS

    p.add_argument("--method", default="mass", choices=list(METHODS),
                   help="estimator (default mass: Voss's P(m, L), the paper's method)")
    p.add_argument("--z-scale", type=_z_scale, default="auto",
                   help="mass, dbc, blanket: height units per pixel (e.g. 1 dB or 1 grey level); default auto: "
                        "1.4826 x median |lag-1 increment| of the whole image, printed; 'range': (max - min) / "
                        "max(rows, cols); 'cell': the file's cell size (cubic boxes for a DEM whose heights and "
                        "cells share a unit); pass a fixed value to compare maps across scenes")
    p.add_argument("--step", type=int, default=1,
                   help="compute every STEP-th row and column only (output cells STEP pixels wide, "
                        "centred on the input pixels they sample; default 1)")
    add_band(p)
    p.add_argument("--chunks", type=int, default=None,
                   help="process with Dask in chunks of this side, with a progress bar (needs the dask extra)")
    add_n_threads(p)
    add_progress(p)
    p.set_defaults(func=_run)


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
    nodata = (profile or {}).get("nodata")
    geo = (profile or {}).get("transform")
    cell = abs(geo.a) if geo is not None else None
    if args.z_scale == "cell":
        if cell is None:
            raise ValueError("--z-scale: 'cell' needs a georeferenced input (a cell size in its transform)")
        args.z_scale = cell
    show = _progress.resolve(args.progress, cli=True)
    opts = dict(method=args.method, nodata=nodata, n_threads=args.n_threads, z_scale=args.z_scale,
                step=args.step, return_fit=True)
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
    tags = map_tags(fit.params, (profile or {}).get("units"), cell)
    if args.output.lower().endswith((".tif", ".tiff")):
        transform = (profile or {}).get("transform")
        if transform is not None and args.step > 1:
            # output cell (k, l) is centred on input pixel (k step, l step)
            from rasterio import Affine

            shift = 0.5 - args.step / 2.0
            # Affine(a, b, c, d, e, f): x = a col + b row + c; the cell is step
            # pixels wide with its corner shifted by (1 - step) / 2 pixels
            step_cell = Affine(args.step, 0.0, shift, 0.0, args.step, shift)
            transform = transform @ step_cell if hasattr(transform, "__matmul__") else transform * step_cell
        write_raster(args.output, dmap, crs=(profile or {}).get("crs"), transform=transform, nodata=float("nan"),
                     tags=tags)
    else:
        write_raster(args.output, dmap)
    finite = dmap[np.isfinite(dmap)]
    print(f"{args.input}: {data.shape}, window {args.window}, method {args.method}")
    if fit.params["z_scale"] is not None:
        print(f"z_scale: {fit.params['z_scale']:.6g} data units per box step")
    if finite.size:
        print(f"local dimension: mean {finite.mean():.3f}, 5-95 % {np.percentile(finite, 5):.3f}-"
              f"{np.percentile(finite, 95):.3f}, NaN pixels {dmap.size - finite.size}")
        flags = np.asarray(flags)[np.isfinite(dmap)]
        out = [f"{100 * np.mean(flags & bit > 0):.1f} % {name}" for name, bit in FLAGS.items()
               if name != "too_few_valid" and np.any(flags & bit)]
        if out:
            print("outside the valid domain: " + ", ".join(out) + " (see docs/transform.md)")
    print(f"map: {args.output}")
    return 0
