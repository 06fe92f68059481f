"""Options shared by the ``fractalgeo`` subcommands: one spelling each.

``--n-threads`` is the thread option of every subcommand (the older
``--threads`` and ``--workers`` are accepted as hidden aliases), and every
subcommand shows its defaults in ``--help``.
"""
from __future__ import annotations

import argparse
from typing import NamedTuple


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows ``(default: ...)`` after every option that has help text,
    once: a help text that already states its default (it contains the
    word "default") and a required option (it has no default) are shown
    as written."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text.lower() or getattr(action, "required", False):
            return text
        return super()._get_help_string(action)


#: Help of the input raster of every subcommand that reads one with
#: ``fractalgeo_rs.io.read_raster`` (one wording everywhere).
INPUT_HELP = "input raster (.tif/.tiff, .npy, .exr, .png, or any format rasterio reads)"
#: Help of ``--band``.
BAND_HELP = "1-based band of the input (None: its only band)"
#: Help of ``--cell-size`` on subcommands that read a raster.
CELL_SIZE_HELP = ("cell size of the input in map units, replacing its transform's (None: the transform's "
                  "pixel size; 1, said in one line, for an input without georeferencing such as .npy)")
#: Help of ``--crs`` on subcommands that read a raster.
CRS_HELP = ("CRS of an input without one, e.g. EPSG:32633, recorded in the outputs (None: the input's "
            "CRS, none for .npy/.png/.exr)")
#: Help of ``--progress`` / ``--no-progress``.
PROGRESS_HELP = ("progress bar on stderr (None: on when stderr is a terminal; needs tqdm, "
                 "pip install \"fractalgeo_rs[progress]\", except for the Dask bar of transform --chunks)")
#: Help of ``--n-threads``.
N_THREADS_HELP = "threads of the Rust kernels (None: one per core)"


class LazyChoices:
    """The ``choices`` of an option read from a registry on first use (so
    that building the parser imports no estimator module): ``loader()``
    returns the names."""

    def __init__(self, loader):
        self._loader = loader
        self._names = None

    def _get(self) -> tuple:
        if self._names is None:
            self._names = tuple(self._loader())
        return self._names

    def __iter__(self):
        return iter(self._get())

    def __contains__(self, name) -> bool:
        return name in self._get()

    def __len__(self) -> int:
        return len(self._get())


def add_raster_io(parser: argparse.ArgumentParser, *, input: str = "input", output_help: str = "",
                  band: bool = True, cell_size: bool = False) -> None:
    """The raster input positional (named ``input``: the attribute of the
    parsed arguments), the ``output`` positional when ``output_help`` is
    given, and the options ``--band`` and ``--cell-size`` (when asked), all
    with the shared help texts."""
    parser.add_argument(input, help=INPUT_HELP)
    if output_help:
        parser.add_argument("output", help=output_help)
    if band:
        add_band(parser)
    if cell_size:
        add_cell_size(parser)


def add_band(parser: argparse.ArgumentParser) -> None:
    """``--band B`` (1-based; default: the file's only band)."""
    parser.add_argument("--band", type=int, default=None, help=BAND_HELP)


def add_cell_size(parser: argparse.ArgumentParser, crs: bool = True) -> None:
    """``--cell-size C`` replacing the input's cell size (default: its
    transform's, 1 without one) and ``--crs`` (the CRS of an input without
    one)."""
    parser.add_argument("--cell-size", type=float, default=None, help=CELL_SIZE_HELP)
    if crs:
        parser.add_argument("--crs", default=None, help=CRS_HELP)


def pixel_size(transform) -> "tuple[float, float]":
    """``(x spacing, y spacing)`` of an affine transform ``(a, b, c, d, e,
    f)`` (``x = a col + b row + c``, ``y = d col + e row + f``): the lengths
    ``sqrt(a^2 + d^2)`` of a column step and ``sqrt(b^2 + e^2)`` of a row
    step, which are the pixel sides of a rotated grid too."""
    import math

    a, b, _, d, e, _ = (float(v) for v in tuple(transform)[:6])
    return math.hypot(a, d), math.hypot(b, e)


class AffineTuple(NamedTuple):
    """The six coefficients of an affine transform in ``rasterio.Affine``
    order with its attribute names (for inputs read without rasterio)."""

    a: float
    b: float
    c: float
    d: float
    e: float
    f: float


def _is_identity(t) -> bool:
    return tuple(float(v) for v in tuple(t)[:6]) == (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)


def input_georef(args: argparse.Namespace, profile, shape, name: str = "input", announce: bool = True) -> dict:
    """The georeferencing of a CLI input: ``{"transform": Affine-order
    6-tuple or rasterio Affine, "crs", "cell": (x, y) pixel size, "nodata",
    "assumed": bool}``.

    ``--cell-size`` replaces the pixel size (keeping the file's origin and
    rotation); an input without georeferencing (``.npy``, ``.png``, a TIFF
    without a transform, whose rasterio transform is the identity) gets
    ``--cell-size`` square cells, or cell size 1, which is said in one line
    on stderr (``announce``: when the command uses it); ``--crs`` gives the
    CRS of an input without one."""
    import math
    import sys

    prof = profile or {}
    t = prof.get("transform")
    crs = prof.get("crs")
    if t is not None and crs is None and _is_identity(t):
        t = None  # rasterio's transform of a file without georeferencing
    cs = getattr(args, "cell_size", None)
    if cs is not None and (not math.isfinite(cs) or cs <= 0):
        raise ValueError(f"--cell-size: expected a positive cell size in map units, got {cs!r}")
    given_crs = getattr(args, "crs", None)
    if given_crs is not None:
        if crs is not None:
            raise ValueError(f"--crs: {getattr(args, name, name)!r} already has a CRS; --crs is for inputs "
                             f"without one")
        crs = given_crs
    assumed = False
    if t is None:
        if cs is None:
            assumed = True
            cs = 1.0
            if announce:
                print(f"fractalgeo {args.command}: note: {getattr(args, name, name)} has no georeferencing: "
                      f"cell size 1 assumed (give --cell-size)", file=sys.stderr)
        t = georeference_of_grid(shape[0], cs)
    elif cs is not None:
        a, b, c, d, e, f = (float(v) for v in tuple(t)[:6])
        sx, sy = pixel_size(t)
        t = (a * cs / sx, b * cs / sy, c, d * cs / sx, e * cs / sy, f)
    if not hasattr(t, "a"):
        try:
            from rasterio import Affine

            t = Affine(*tuple(t)[:6])
        except ImportError:  # the same attributes a..f, no rasterio needed
            t = AffineTuple(*tuple(t)[:6])
    return {"transform": t, "crs": crs, "cell": pixel_size(t), "nodata": prof.get("nodata"), "assumed": assumed}


def add_n_threads(parser: argparse.ArgumentParser) -> None:
    """``--n-threads N`` (default all cores), with hidden old spellings."""
    parser.add_argument("--n-threads", dest="n_threads", type=int, default=None, help=N_THREADS_HELP)
    parser.add_argument("--threads", "--workers", dest="n_threads", type=int, help=argparse.SUPPRESS)


def is_geographic(crs) -> bool:
    """True for a rasterio CRS in degrees (e.g. EPSG:4326); False for None."""
    return crs is not None and bool(getattr(crs, "is_geographic", False))


def georeference_of_grid(rows: int, cell_size: float):
    """Transform of a synthetic grid: ``cell_size`` square cells, the
    upper-left corner at (0, rows * cell_size) so that y grows to the north,
    as the 6 affine coefficients ``(a, b, c, d, e, f)`` (``rasterio.Affine``
    order; no rasterio needed)."""
    return (float(cell_size), 0.0, 0.0, 0.0, -float(cell_size), rows * float(cell_size))


def add_progress(parser: argparse.ArgumentParser) -> None:
    """``--progress`` / ``--no-progress`` (default: a bar when stderr is a
    terminal; tqdm draws it, Dask's own bar with ``--chunks``)."""
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None, help=PROGRESS_HELP)
