"""Argument checks and seeds shared by the synthesis functions."""
from __future__ import annotations

import numbers

import numpy as np

from fractalgeo_rs._validation import check_positive_float, check_seed

# Random streams of the counter-based generator (one per use of a seed), so
# that no two parts of one synthesis ever share random numbers.
STREAM_SPECTRAL_1D = 11
STREAM_EXACT_1D = 12
STREAM_COARSE_1D = 13
STREAM_SPECTRAL_2D = 21
STREAM_EXACT_2D = 22
STREAM_EXACT_2D_LINEAR = 23
STREAM_COARSE_2D = 24

METHODS = ("exact", "midpoint", "additions", "spectral")


def check_hurst(hurst) -> float:
    if isinstance(hurst, bool) or not isinstance(hurst, numbers.Real):
        raise TypeError(f"hurst: expected a number in (0, 1), got {hurst!r}")
    h = float(hurst)
    if not (0.0 < h < 1.0):
        raise ValueError(f"hurst: expected a number in (0, 1), got {hurst}")
    return h


def check_sigma(sigma) -> float:
    if isinstance(sigma, bool) or not isinstance(sigma, numbers.Real):
        raise TypeError(f"sigma: expected a number >= 0, got {sigma!r}")
    s = float(sigma)
    if not np.isfinite(s) or s < 0:
        raise ValueError(f"sigma: expected a finite number >= 0, got {sigma}")
    return s


#: The package's seed policy (``_validation.check_seed``), under the name
#: the synthesis code and its callers use.
resolve_seed = check_seed


def check_shape(shape, minimum: int = 2) -> tuple:
    if isinstance(shape, numbers.Integral) and not isinstance(shape, bool):
        shape = (int(shape), int(shape))
    try:
        dims = tuple(shape)
    except TypeError:
        raise TypeError(f"shape: expected an int or a pair of ints, got {shape!r}") from None
    if len(dims) != 2 or any(isinstance(d, bool) or not isinstance(d, numbers.Integral) for d in dims):
        raise TypeError(f"shape: expected a pair of ints (rows, cols), got {shape!r}")
    if any(d < minimum for d in dims):
        raise ValueError(f"shape: each size must be at least {minimum}, got {tuple(int(d) for d in dims)}")
    return int(dims[0]), int(dims[1])


def check_cell_size(cell_size) -> float:
    return check_positive_float(cell_size, "cell_size")
