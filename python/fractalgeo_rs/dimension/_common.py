"""Helpers shared by the box-counting estimators."""
from __future__ import annotations

import numbers
from typing import List, Optional

import numpy as np

from fractalgeo_rs._validation import check_choice


def check_box_sizes(box_sizes, *, integer: bool = True, name: str = "box_sizes") -> Optional[list]:
    """``None`` or a list of positive numbers (ints for rasters)."""
    if box_sizes is None:
        return None
    if isinstance(box_sizes, (str, bytes)) or np.ndim(box_sizes) != 1:
        raise TypeError(f"{name}: expected a 1D sequence of {'ints' if integer else 'numbers'}, got {box_sizes!r}")
    out: List[float] = []
    for v in box_sizes:
        if isinstance(v, (bool, np.bool_)):
            raise TypeError(f"{name}: expected numbers, got a bool")
        if integer:
            if not isinstance(v, numbers.Integral):
                if isinstance(v, numbers.Real) and float(v).is_integer():
                    v = int(float(v))
                else:
                    raise TypeError(f"{name}: expected integer box sizes in samples, got {v!r}")
            if v <= 0:
                raise ValueError(f"{name}: box sizes must be positive, got {v}")
            out.append(int(v))
        else:
            if not isinstance(v, numbers.Real) or not np.isfinite(float(v)) or v <= 0:
                raise ValueError(f"{name}: box sizes must be positive finite numbers, got {v!r}")
            out.append(float(v))
    if len(set(out)) < 3:
        raise ValueError(f"{name}: need at least 3 distinct box sizes for a fit, got {len(set(out))}")
    return sorted(set(out))


def reduce_offsets(counts: np.ndarray, offset_reduce: str) -> np.ndarray:
    """Combine the counts of the shifted lattices: mean (bias reduction) or
    min (the least cover over the shifts, definition 3 of box dimension)."""
    check_choice(offset_reduce, "offset_reduce", ("mean", "min"))
    counts = np.asarray(counts, dtype=float)
    return counts.mean(axis=1) if offset_reduce == "mean" else counts.min(axis=1)


def dyadic_up_to(limit: float, start: int = 1) -> list:
    """Powers of two from ``start`` up to ``limit`` (inclusive)."""
    out, s = [], start
    while s <= limit:
        out.append(s)
        s *= 2
    return out
