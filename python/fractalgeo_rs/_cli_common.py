"""Options shared by the ``fractalgeo`` subcommands: one spelling each.

``--n-threads`` is the thread option of every subcommand (the older
``--threads`` and ``--workers`` are accepted as hidden aliases), and every
subcommand shows its defaults in ``--help``.
"""
from __future__ import annotations

import argparse


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows ``(default: ...)`` after every option that has help text."""


#: Help of the input raster of every subcommand that reads one with
#: ``fractalgeo_rs.io.read_raster`` (one wording everywhere).
INPUT_HELP = "input raster (.tif/.tiff, .npy, .exr, .png, or any format rasterio reads)"
#: Help of ``--band``.
BAND_HELP = "1-based band of the input (None: its only band)"
#: Help of ``--cell-size`` on subcommands that read a raster.
CELL_SIZE_HELP = ("cell size of the input in map units, replacing its transform's (None: the transform's, "
                  "1 without one)")
#: Help of ``--progress`` / ``--no-progress``.
PROGRESS_HELP = ("progress bar on stderr (None: on when stderr is a terminal; needs tqdm, "
                 "pip install \"fractalgeo_rs[progress]\", except with --chunks)")
#: Help of ``--n-threads``.
N_THREADS_HELP = "threads of the Rust kernels (None: one per core)"


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


def add_cell_size(parser: argparse.ArgumentParser) -> None:
    """``--cell-size C`` replacing the input's cell size (default: its
    transform's, 1 without one)."""
    parser.add_argument("--cell-size", type=float, default=None, help=CELL_SIZE_HELP)


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
