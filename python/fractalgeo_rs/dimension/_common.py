"""Helpers shared by the box-counting estimators."""
from __future__ import annotations

import math
import numbers
from typing import List, Optional

import numpy as np

from fractalgeo_rs._validation import as_array, check_choice, check_nodata


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


def box_size_range(limit: float, *, base: int = 2, start: int = 1) -> list:
    """Box sizes ``start, start * base, start * base^2, ...`` up to ``limit``
    (inclusive): the one rule from which every default box-size range is
    derived (a window's or an extent's limit, e.g. ``w // 2`` or ``E / 4``).
    Empty when ``start > limit``."""
    out, s = [], start
    while s <= limit:
        out.append(s)
        s *= base
    return out


def dyadic_up_to(limit: float, start: int = 1) -> list:
    """Powers of two from ``start`` up to ``limit`` (inclusive)."""
    return box_size_range(limit, base=2, start=start)


# ---------------------------------------------------------------------------
# Default box sizes and lattice of ``box_counting``
# ---------------------------------------------------------------------------

DEFAULT_BASES = (2, 3)
"""Bases of the default box sizes ``1, b, b^2, ...``."""

DEFAULT_TOP = 4
"""Default box sizes stop at the set's largest extent divided by this."""


def _pool(a: np.ndarray, b: int, front=None) -> np.ndarray:
    """OR-pool a bool array by ``b`` along every axis, after padding
    ``front[ax]`` cells of background before it (a lattice shifted by
    ``-front`` cells); the back is padded to a multiple of ``b``."""
    front = (0,) * a.ndim if front is None else tuple(front)
    shape = tuple(-(-(n + f) // b) * b for n, f in zip(a.shape, front))
    if shape == a.shape and not any(front):
        p = a
    else:
        p = np.zeros(shape, dtype=bool)
        p[tuple(slice(f, f + n) for f, n in zip(front, a.shape))] = a
    split = []
    for n in shape:
        split += [n // b, b]
    return np.asarray(p.reshape(split).any(axis=tuple(range(1, 2 * a.ndim, 2))))


def _line_rms(sizes, counts) -> float:
    """Residual standard deviation (``n - 2`` degrees of freedom) of the OLS
    line through ``(log s, log N)``."""
    x, y = np.log(np.asarray(sizes, float)), np.log(np.asarray(counts, float))
    coef = np.polyfit(x, y, 1)
    return float(np.sqrt(np.sum((y - np.polyval(coef, x)) ** 2) / max(len(x) - 2, 1)))


def default_lattice_counts(box: np.ndarray) -> Optional[dict]:
    """Box counts of a binary set on the default sizes and lattice.

    ``box`` is the set cropped to its bounding box (bool, any dimension).
    For each base ``b`` in :data:`DEFAULT_BASES` the sizes are
    ``s = 1, b, b^2, ...`` up to ``E / DEFAULT_TOP`` (``E`` the largest
    extent), and two lattice counts are formed:

    * ``"aligned"``: the lattice anchored at the corner of the bounding box,
      counting only the boxes that lie wholly inside it, divided by the
      fraction of the set's samples those boxes hold (the edge correction
      of a crop: ``N(s) = N_inside(s) / f(s)``; exact, ``f = 1``, when
      ``s`` divides the extent; when every inside box is occupied, ``f`` is
      their share of the bounding box's volume instead);
    * ``"shifted"``: the mean count over the ``b^d`` lattices shifted by
      ``(j_1, ..., j_d) s / b``, ``0 <= j < b`` (the mean cover over lattice
      placements, which smooths the log-periodic oscillation of sets that
      follow no lattice, e.g. a curve at an arbitrary resolution).

    Of the four candidates the one whose ``log N`` against ``log s`` is
    straightest (smallest root mean square residual about its line) is
    returned: an exact ``b``-adic set, cropped or not, follows its own
    lattice exactly. Returns ``None`` when no base gives 3 sizes (extent
    under ``4 * DEFAULT_TOP``).

    Returns
    -------
    dict with ``sizes`` (list of int), ``measures`` (float array),
    ``counts`` (array ``(n_sizes, n_lattices)``: the raw counts),
    ``base``, ``lattice`` (``"aligned"`` or ``"shifted"``), ``fraction``
    (``f(s)`` of the aligned lattice, ones for ``"shifted"``) and ``rms``.
    """
    ext = max(box.shape)
    total = int(np.count_nonzero(box))
    best = None
    for b in DEFAULT_BASES:
        sizes = box_size_range(ext / DEFAULT_TOP, base=b)
        if len(sizes) < 3:
            continue
        levels = [box]
        for _ in sizes[1:]:
            levels.append(_pool(levels[-1], b))
        # aligned lattice, boxes inside the bounding box only, edge-corrected
        inside, frac = [], []
        for k, s in enumerate(sizes):
            m = tuple(max(1, n // s) for n in box.shape)  # an axis thinner than s keeps its one box
            inside.append(int(np.count_nonzero(levels[k][tuple(slice(0, v) for v in m)])))
            cover = tuple(slice(0, min(n, v * s)) for n, v in zip(box.shape, m))
            if inside[-1] == math.prod(m):
                # the set fills the inside boxes at this size: it fills the
                # rest in proportion to area (no sampling noise)
                frac.append(math.prod(c.stop for c in cover) / box.size)
            else:
                frac.append(np.count_nonzero(box[cover]) / total)
        frac_a = np.asarray(frac, dtype=float)
        meas_a = np.asarray(inside, dtype=float) / frac_a
        # shifted lattices: shifts j * s / b on the level below
        shifts = list(np.ndindex(*(b,) * box.ndim))
        counts_s = np.empty((len(sizes), len(shifts)))
        counts_s[0] = total
        for k in range(1, len(sizes)):
            for q, front in enumerate(shifts):
                counts_s[k, q] = np.count_nonzero(_pool(levels[k - 1], b, front))
        meas_s = counts_s.mean(axis=1)
        for lattice, meas, counts, frac_k in (
            ("aligned", meas_a, np.asarray(inside, dtype=float)[:, None], frac_a),
            ("shifted", meas_s, counts_s, np.ones(len(sizes))),
        ):
            k0 = sampling_start(sizes, meas)
            rms = _line_rms(sizes[k0:], meas[k0:])
            if best is None or rms < best["rms"] - 1e-12:
                best = {"sizes": sizes, "measures": meas, "counts": counts, "base": b,
                        "lattice": lattice, "fraction": frac_k, "rms": rms, "start": k0}
    return best


SAMPLING_SLOPE_CHANGE = 0.1
"""Change of local slope between the first two scale steps above which the
smallest scale is taken to be below the set's sampling."""


def sampling_start(sizes, counts, *, min_sizes: int = 3) -> int:
    """Index of the first size above the set's sampling scale.

    A rasterised curve or a point set is not fractal below a few samples: at
    the smallest boxes it is a line (or isolated points), and the local
    slope ``d log N / d log s`` there differs from the slope above. The
    smallest size is dropped while the local slope of its step differs from
    the next step's by more than :data:`SAMPLING_SLOPE_CHANGE` (in units of
    dimension), keeping at least ``min_sizes`` sizes. An exact lattice set
    (constant local slope) keeps every size.
    """
    x = np.log(np.asarray(sizes, dtype=float))
    y = np.log(np.asarray(counts, dtype=float))
    local = np.diff(y) / np.diff(x)
    k = 0
    while len(x) - k > min_sizes and abs(local[k] - local[k + 1]) > SAMPLING_SLOPE_CHANGE:
        k += 1
    return k


def real_array(data, ndims, name="data") -> np.ndarray:
    """``data`` as a float64 array of one of the dimensions ``ndims``: real,
    non-empty, no inf (NaN marks missing samples)."""
    arr = as_array(data, name)
    if arr.dtype.kind == "b" or arr.dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected a real numeric array, got dtype {arr.dtype}")
    if arr.ndim not in ndims:
        want = " or ".join(f"{d}D" for d in ndims)
        raise ValueError(f"{name}: expected a {want} array, got {arr.ndim} dimensions")
    if arr.size == 0:
        raise ValueError(f"{name}: array is empty (shape {arr.shape})")
    z = arr.astype(np.float64)
    if np.isinf(z).any():
        raise ValueError(f"{name}: contains inf; mark invalid samples with NaN or nodata")
    return z


def with_nodata(z: np.ndarray, data, nodata) -> np.ndarray:
    """``z`` with the samples where ``data == nodata`` set to NaN (a copy)."""
    nodata = check_nodata(nodata)
    if nodata is None:
        return z
    if not np.isnan(nodata):
        z = z.copy()
        z[np.asarray(data) == nodata] = np.nan
    return z
