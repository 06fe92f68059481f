"""Options shared by the ``fractalgeo`` subcommands: one spelling each.

``--n-threads`` is the thread option of every subcommand (the older
``--threads`` and ``--workers`` are accepted as hidden aliases), and every
subcommand shows its defaults in ``--help``.
"""
from __future__ import annotations

import argparse


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows ``(default: ...)`` after every option that has help text."""


def add_n_threads(parser: argparse.ArgumentParser) -> None:
    """``--n-threads N`` (default all cores), with hidden old spellings."""
    parser.add_argument("--n-threads", dest="n_threads", type=int, default=None,
                        help="threads of the Rust kernels (None: one per core)")
    parser.add_argument("--threads", "--workers", dest="n_threads", type=int, help=argparse.SUPPRESS)


def georeference_of_grid(rows: int, cell_size: float):
    """Transform of a synthetic grid: ``cell_size`` square cells, the
    upper-left corner at (0, rows * cell_size) so that y grows to the north,
    as the 6 affine coefficients ``(a, b, c, d, e, f)`` (``rasterio.Affine``
    order; no rasterio needed)."""
    return (float(cell_size), 0.0, 0.0, 0.0, -float(cell_size), rows * float(cell_size))


def add_progress(parser: argparse.ArgumentParser) -> None:
    """``--progress`` / ``--no-progress`` (default: a bar when stderr is a
    terminal; tqdm draws it, Dask's own bar with ``--chunks``)."""
    parser.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                        help="progress bar on stderr (None: on when stderr is a terminal; needs tqdm, "
                             "pip install \"fractalgeo_rs[progress]\", except with --chunks)")
