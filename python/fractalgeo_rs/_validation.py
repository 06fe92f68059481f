"""Argument checks shared by every public function.

Each check raises ``TypeError`` or ``ValueError`` with a message that starts
with the parameter's name and says what was expected, so users see e.g.
``ValueError: box_sizes: need at least 3 distinct box sizes, got 2``.
"""
from __future__ import annotations

import numbers
import os
import tempfile
from contextlib import contextmanager
from typing import Iterator, Optional

import numpy as np

__all__ = [
    "as_array",
    "check_n_threads",
    "check_positive_int",
    "check_positive_float",
    "check_choice",
    "atomic_write_path",
]


def as_array(data, name: str = "data") -> np.ndarray:
    """Return ``data`` as an ndarray (no copy when it already is one).

    Dask arrays, xarray objects and other array-likes go through
    ``np.asarray``; strings, None and ragged sequences are rejected.
    """
    if data is None or isinstance(data, (str, bytes)):
        raise TypeError(f"{name}: expected an array, got {type(data).__name__}")
    try:
        arr = np.asarray(data)
    except (ValueError, TypeError) as exc:  # ragged nested sequences
        raise TypeError(f"{name}: expected an array, could not convert: {exc}") from None
    if arr.dtype == object:
        raise TypeError(f"{name}: expected a numeric or boolean array, got dtype object")
    return arr


def check_n_threads(n_threads) -> Optional[int]:
    """``None`` (all cores) or a positive int."""
    if n_threads is None:
        return None
    if isinstance(n_threads, bool) or not isinstance(n_threads, numbers.Integral):
        raise TypeError(f"n_threads: expected a positive int or None, got {n_threads!r}")
    if n_threads < 1:
        raise ValueError(f"n_threads: expected a positive int or None, got {n_threads}")
    return int(n_threads)


def check_positive_int(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected a positive int, got {value!r}")
    if value < 1:
        raise ValueError(f"{name}: expected a positive int, got {value}")
    return int(value)


def check_positive_float(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a positive number, got {value!r}")
    value = float(value)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name}: expected a positive finite number, got {value}")
    return value


def check_nodata(nodata) -> Optional[float]:
    """``None`` or a real number (NaN allowed: NaN is always missing)."""
    if nodata is None:
        return None
    if isinstance(nodata, (bool, np.bool_)) or not isinstance(nodata, numbers.Real):
        raise TypeError(f"nodata: expected a number or None, got {nodata!r}")
    return float(nodata)


def check_choice(value, name: str, choices) -> str:
    if value not in choices:
        opts = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name}: expected one of {opts}, got {value!r}")
    return value


@contextmanager
def atomic_write_path(path) -> Iterator[str]:
    """Yield a temporary path beside ``path``; rename it over ``path`` on success.

    The file appears whole or not at all: on any exception the temporary file
    is removed and ``path`` is left as it was.
    """
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OSError(f"path: folder {folder!r} does not exist")
    base = os.path.basename(path)
    stem, ext = os.path.splitext(base)
    fd, tmp = tempfile.mkstemp(prefix=f".{stem}.", suffix=ext, dir=folder)
    os.close(fd)
    try:
        yield tmp
        # mkstemp creates 0600 files; give the result the usual permissions
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
