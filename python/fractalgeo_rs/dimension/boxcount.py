"""Box counting: binary sets, point sets, grayscale surfaces (DBC) and
self-affine graphs.

All four count boxes of a lattice at several box sizes ``s`` and fit
``log N(s) = a + b log s`` (:func:`fractalgeo_rs.fit.fit_loglog`). The counting
runs in Rust with the GIL released, in a pool of ``n_threads`` threads; counts
are integers, so results do not depend on the thread count.

References
----------
Falconer, K. (1990). *Fractal Geometry: Mathematical Foundations and
Applications*. Wiley. (Box-counting dimension, section 3.1.)
Sarkar, N., Chaudhuri, B. B. (1994). An efficient differential box-counting
approach to compute fractal dimension of image. *IEEE Trans. Systems, Man, and
Cybernetics* 24(1), 115-120.
Voss, R. F. (1985). Random fractal forgeries. In *Fundamental Algorithms for
Computer Graphics*, Springer, 805-835. (Self-affine scaling of graphs.)
"""
from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import replace
from typing import Optional, Sequence, Tuple, Union

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._compat import renamed_parameters
from fractalgeo_rs._warn import user_stacklevel
from fractalgeo_rs._validation import (
    as_array,
    as_list,
    check_choice,
    check_memory,
    check_n_threads,
    check_nodata,
    check_positive_int,
)
from fractalgeo_rs._zscale import resolve_z_scale
from fractalgeo_rs.dimension._common import (
    DEFAULT_BASES,
    DEFAULT_TOP,
    box_size_range,
    check_box_sizes,
    default_lattice_counts,
    dyadic_up_to,
    reduce_offsets,
)
from fractalgeo_rs.fit import DimensionFit, FractalRangeWarning, ScaleRange, fit_loglog, mark_invalid

__all__ = [
    "box_counting",
    "box_counting_points",
    "differential_box_counting",
    "self_affine_box_counting",
]


def _lattice_fit(method, sizes, counts, offset_reduce, scale_range, x_label, y_label, extra, domain) -> DimensionFit:
    """Fit ``D = -slope`` to lattice counts combined over the shifted lattices."""
    return fit_loglog(
        sizes,
        reduce_offsets(counts, offset_reduce),
        method=method,
        scale_range=scale_range,
        x_label=x_label,
        y_label=y_label,
        extra={"counts": counts, "offset_reduce": offset_reduce, **extra},
        domain=domain,
    )


_NEAR_POWER = math.log(1.05)  # extents within 5 % of a power of 2 or 3


def _uneven(sizes) -> bool:
    """Consecutive ratios of ``sizes`` neither all equal nor all <= 2."""
    r = np.asarray(sizes, dtype=float)
    if r.size < 3:
        return False
    q = r[1:] / r[:-1]
    return not (np.allclose(q, q[0]) or np.all(q <= 2.0 + 1e-12))


def _default_box_sizes(b: np.ndarray, bbox: bool) -> Optional[list]:
    """Powers of 2 or of 3 up to a quarter of the set's extent (at least 3
    sizes), the base whose powers come closest to the extent in log scale:
    an exact fractal of side b^L, cropped, offset or padded, is then counted
    on boxes of its own base (a carpet of side 729 on 1, 3, 9, ...; a
    triangle cropped to 1000 on 1, 2, 4, ...). ``None`` leaves the choice to
    the kernel (empty set, extent under 4)."""
    if bbox:
        ext = 0
        for ax in range(b.ndim):
            occ = np.flatnonzero(b.any(axis=tuple(a for a in range(b.ndim) if a != ax)))
            if occ.size == 0:
                return None
            ext = max(ext, int(occ[-1] - occ[0] + 1))
    else:
        ext = max(b.shape)
    if ext < 4:
        return None

    def powers(base):
        return box_size_range(ext / DEFAULT_TOP, base=base)

    def misfit(base):
        x = math.log(ext, base)
        return abs(x - round(x)) * math.log(base)  # distance in natural-log units

    best = min((2, 3), key=misfit)
    if misfit(best) > _NEAR_POWER:  # not a set of side b^L: keep the kernel's sizes
        return None
    sizes = powers(best)
    if len(sizes) < 3:
        sizes = powers(2)
    return sizes if len(sizes) >= 3 else None


def _bounds(b: np.ndarray):
    """``(lo, hi)`` of the foreground's bounding box (``hi`` exclusive), or
    ``None`` for an empty set."""
    lo, hi = [], []
    for ax in range(b.ndim):
        occ = np.flatnonzero(b.any(axis=tuple(a for a in range(b.ndim) if a != ax)))
        if occ.size == 0:
            return None
        lo.append(int(occ[0]))
        hi.append(int(occ[-1]) + 1)
    return tuple(lo), tuple(hi)


def binary_bytes(data) -> Tuple[np.ndarray, bool]:
    """A C-contiguous uint8 view (0/1) of a binary set, and whether the axes
    were reversed (a Fortran-ordered input is counted through its transpose,
    which has the same counts, without a copy)."""
    arr = as_array(data)
    if arr.ndim not in (1, 2, 3):
        raise ValueError(f"data: expected a 1D, 2D or 3D binary array, got {arr.ndim} dimensions")
    if arr.size == 0:
        raise ValueError(f"data: array is empty (shape {arr.shape})")
    kind = arr.dtype.kind
    if kind == "b":
        b = arr
    elif kind in "iuf":
        if kind == "f" and np.isnan(arr).any():
            raise ValueError("data: NaN in a binary set; mark the set with True/1 and the rest with False/0")
        if not np.all((arr == 0) | (arr == 1)):
            raise ValueError(
                "data: a binary set must be bool or hold only 0 and 1; threshold it first "
                "(e.g. data > level) or use method='dbc' for a grayscale image"
            )
        b = arr != 0
    else:
        raise TypeError(f"data: expected a bool or numeric array, got dtype {arr.dtype}")
    transposed = False
    if not b.flags.c_contiguous:
        if b.T.flags.c_contiguous:
            b, transposed = b.T, True
        else:
            b = np.ascontiguousarray(b)
    return b.view(np.uint8), transposed


def box_counting(
    data,
    *,
    box_sizes: Optional[Sequence[int]] = None,
    offsets: int = 1,
    offset_reduce: str = "mean",
    anchor: str = "bbox",
    scale_range: ScaleRange = None,
    n_threads: Optional[int] = None,
) -> DimensionFit:
    """Box-counting dimension of a binary set in 1, 2 or 3 dimensions.

    ``N(s)`` is the number of boxes of a cubic lattice of side ``s`` samples
    that contain at least one foreground sample (Falconer 1990, definition 4
    of box dimension; the paper's section 2.4 and figure 2), and

    .. math:: D = -\\frac{d \\log N(s)}{d \\log s}.

    Parameters
    ----------
    data : array_like of bool, shape (n,), (rows, cols) or (planes, rows, cols)
        The set: True (or 1) marks a foreground sample. Integer and float
        arrays are accepted when they hold only 0 and 1; NaN is an error.
        Any memory layout works (Fortran order and strided views too).
    box_sizes : sequence of int, optional
        Box sides in samples; any positive integers (not only powers of two),
        at least three distinct, none larger than the longest axis. Default:
        ``1, b, b^2, ...`` up to a quarter of the set's extent for ``b`` = 2
        and 3, each counted on the bounding-box lattice with an edge
        correction for partial boxes and as the mean over ``b^d`` shifted
        lattices; the straightest of the four log-log relations is fitted,
        from the first size above the set's sampling scale (see
        ``docs/boxcounting.md``: within 0.013 of the dimension on cropped,
        offset and padded exact fractals). ``extra`` records ``base``,
        ``lattice`` and ``fraction``.
    offsets : int, default 1
        Number of lattice shifts per axis (``offsets**ndim`` lattices). The
        shifts ``j * s_max / offsets`` are global (the same for every box
        size), so the lattices stay nested and counting stays one pass.
    offset_reduce : {"mean", "min"}, default "mean"
        How the counts of the shifted lattices are combined: their mean
        (reduces the bias of one grid registration) or their minimum (the
        least cover, closer to the "fewest boxes" definition).
    anchor : {"bbox", "array"}, default "bbox"
        Where the lattice starts: at the corner of the set's bounding box, so
        translating or padding the set never changes a count, or at sample 0.
    scale_range : None, "auto" or (low, high)
        Box sizes used in the fit; see :func:`fractalgeo_rs.fit.fit_loglog`.
    n_threads : int, optional
        Threads for the counting (default: all cores). Results do not depend on it.

    Returns
    -------
    DimensionFit
        ``scales`` are the box sizes (samples), ``measures`` the counts
        (averaged or minimised over lattices); ``extra`` holds ``counts``
        (every lattice), ``n_foreground``, ``bbox`` and ``offsets``.

    Notes
    -----
    Partial boxes: the lattice covers the set's bounding box (or the array)
    and boxes that reach past the last sample are counted when they hold
    foreground; samples outside the array are background. This is the exact
    lattice count of the set for any array size, so sizes that are not powers
    of two need no padding or cropping. Where the lattice matches a
    self-similar construction (boxes ``2^k`` on a ``2^L`` Sierpinski
    triangle, ``3^k`` on a ``3^L`` carpet) the counts are exact.

    References
    ----------
    Falconer (1990); full entry in the :ref:`bibliography <ref-falconer1990>`.

    Datcu and Seidel (1994), the seed paper; full entry in the :ref:`bibliography <ref-datcu1994>`.

    Examples
    --------
    >>> import numpy as np
    >>> import fractalgeo_rs as fg
    >>> n = 256
    >>> i, j = np.indices((n, n))
    >>> triangle = (i & j) == 0          # Sierpinski triangle (Pascal mod 2)
    >>> fit = fg.box_counting(triangle)
    >>> round(fit.dimension, 6), round(float(np.log(3) / np.log(2)), 6)
    (1.584963, 1.584963)
    """
    b, transposed = binary_bytes(data)
    sizes = check_box_sizes(box_sizes)
    offsets = check_positive_int(offsets, "offsets")
    check_choice(offset_reduce, "offset_reduce", ("mean", "min"))
    check_choice(anchor, "anchor", ("bbox", "array"))
    n_threads = check_n_threads(n_threads)
    if sizes is None:
        bounds = _bounds(b)
        if bounds is not None:
            lo, hi = bounds
            check_memory(3 * b.size, "data", what=f"the default box counts of an array of shape {b.shape}")
            box = b[tuple(slice(a, z) for a, z in zip(lo, hi))].view(bool)
            res = default_lattice_counts(box)
            if res is not None and anchor == "bbox" and offsets == 1:
                if transposed:
                    lo, hi = lo[::-1], hi[::-1]
                if scale_range is None and res["start"] > 0:  # smallest sizes below the sampling
                    scale_range = (res["sizes"][res["start"]], res["sizes"][-1])
                fit = fit_loglog(
                    res["sizes"], res["measures"], method="box", scale_range=scale_range,
                    x_label="box size s (samples)", y_label="occupied boxes N(s)",
                    extra={"counts": res["counts"], "offset_reduce": offset_reduce,
                           "n_foreground": int(np.count_nonzero(box)), "bbox": (tuple(lo), tuple(hi)),
                           "offsets": offsets, "anchor": anchor, "base": res["base"],
                           "lattice": res["lattice"], "fraction": res["fraction"]},
                    domain=(0.0, float(b.ndim)),
                )
                return fit
            if res is not None:  # the user's lattice options on the default sizes
                sizes = res["sizes"]
    s, counts, n_fg, lo, hi = _core.box_count_binary(b, sizes or [], offsets, anchor == "bbox", n_threads)
    if sizes is None and _uneven(s):
        # the kernel's default (divisors of the extent, else powers of 2)
        # jumps unevenly on extents such as 1000 (8, 20, 40, 100): count
        # again on powers of the base closest to the extent
        alt = _default_box_sizes(b, anchor == "bbox")
        if alt is not None:
            s, counts, n_fg, lo, hi = _core.box_count_binary(b, alt, offsets, anchor == "bbox", n_threads)
    if transposed:
        lo, hi = lo[::-1], hi[::-1]
    return _lattice_fit(
        "box", s, counts, offset_reduce, scale_range, "box size s (samples)", "occupied boxes N(s)",
        {"n_foreground": int(n_fg), "bbox": (tuple(lo), tuple(hi)), "offsets": offsets, "anchor": anchor},
        (0.0, float(b.ndim)),
    )


def box_counting_points(
    points,
    *,
    box_sizes: Optional[Sequence[float]] = None,
    offsets: int = 1,
    offset_reduce: str = "mean",
    scale_range: ScaleRange = None,
    n_threads: Optional[int] = None,
) -> DimensionFit:
    """Box-counting dimension of a point set given as coordinates.

    Parameters
    ----------
    points : array_like of float, shape (N, d)
        Coordinates of N points in d dimensions (1 <= d <= 16), any units.
        NaN and inf are errors.
    box_sizes : sequence of float, optional
        Box sides in coordinate units. Default (see Notes): ``E / b^k`` for
        ``b`` = 2 and 3, from ``E / 4`` (``E`` the largest extent of the
        set) down to the last size whose boxes hold at least
        ``POINT_MIN_OCCUPANCY`` (20) points on average, counted on
        shifted lattices; the base and lattice with the straightest
        log-log line are fitted.
    offsets, offset_reduce, scale_range, n_threads
        As in :func:`box_counting`; the lattice starts at the per-axis
        minimum of the set. ``offsets`` and ``offset_reduce`` apply to given
        ``box_sizes`` only.

    Returns
    -------
    DimensionFit
        With the default sizes, ``extra`` records ``base``, ``lattice``
        (``"shifted"`` or ``"shifted_inside"``) and the counts of every
        candidate. Fewer points than 3 sizes of 20 points per box need give
        the flag ``"undersampled"`` and a
        :class:`~fractalgeo_rs.FractalRangeWarning` (the estimate is biased
        low: sparse boxes miss parts of the set). Fewer than 3 fitted
        sizes with distinct counts (e.g. a few points, each alone in its box
        at every size) give ``valid=False``, the flag ``"unresolved"`` and
        NaN ``stderr`` and ``ci95``: not an estimate.

    Raises
    ------
    ValueError
        ``points``: fewer than 2 distinct points (or not an (N, d) array of
        finite coordinates).

    Notes
    -----
    A finite sample of a set (e.g. a chaos game) covers it only at scales
    where the boxes hold many points: below, the count approaches the
    number of points and the slope flattens. The default stops at a mean of
    20 points per box. At each size ``s`` the count is the mean over the
    ``b^d`` lattices shifted by ``j s / b`` (``0 <= j < b`` per axis; the
    unshifted lattice alone for ``d > 3``), which smooths the log-periodic
    oscillation of sets that follow no lattice (an equilateral Sierpinski
    triangle, a Koch curve), in two versions: every occupied box
    (``"shifted"``), and only the boxes wholly inside the bounding box,
    divided by the share of the points they hold (``"shifted_inside"``,
    the edge correction of a set that fills its bounding box, such as a
    carpet). Of the four candidates (2 bases x 2 versions) the one whose
    ``log N`` against ``log s`` has the smallest root mean square residual
    about its line is fitted. The lattice is not anchored at the sample's
    bounding box alone because a sample's box is slightly smaller than
    the set's, which puts points near box faces on the wrong side.
    Accuracy on chaos-game samples of exact fractals is in the docs
    (``boxcounting.md``).

    References
    ----------
    Falconer (1990); full entry in the :ref:`bibliography <ref-falconer1990>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> t = np.linspace(0.0, 1.0, 4097)
    >>> segment = np.c_[t, 0.5 * t]  # points on a straight segment: D = 1
    >>> round(fg.box_counting_points(segment).dimension, 2)
    1.0
    >>> square = np.random.default_rng(0).random((100_000, 2))  # dense in the unit square: D = 2
    >>> round(fg.box_counting_points(square, box_sizes=[1/4, 1/8, 1/16, 1/32]).dimension, 2)
    2.0
    """
    arr = as_array(points, "points")
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"points: expected a numeric (N, d) array, got dtype {arr.dtype}")
    if arr.ndim != 2:
        raise ValueError(f"points: expected an (N, d) array of coordinates, got {arr.ndim} dimensions")
    if arr.shape[0] == 0 or arr.shape[1] == 0:
        raise ValueError(f"points: point set is empty (shape {arr.shape})")
    if not np.isfinite(arr).all():
        raise ValueError("points: coordinates must be finite (no NaN or inf)")
    if arr.shape[1] > 16:
        raise ValueError(f"points: at most 16 coordinates per point, got {arr.shape[1]}")
    pts = np.ascontiguousarray(arr, dtype=np.float64)
    if not np.any(pts != pts[0]):
        raise ValueError(f"points: need at least 2 distinct points for a box dimension, got "
                         f"{pts.shape[0]} point(s) all at {pts[0].tolist()}")
    sizes = check_box_sizes(box_sizes, integer=False)
    offsets = check_positive_int(offsets, "offsets")
    check_choice(offset_reduce, "offset_reduce", ("mean", "min"))
    n_threads = check_n_threads(n_threads)
    n = pts.shape[0]
    if sizes is None:
        return _default_points_fit(pts, scale_range, n_threads)
    s, counts = _core.box_count_points(pts, sizes, offsets, n_threads)
    return _check_resolved(_lattice_fit(
        "points", s, counts, offset_reduce, scale_range, "box size s", "occupied boxes N(s)",
        {"n_points": n, "offsets": offsets},
        (0.0, float(pts.shape[1])),
    ))


def _check_resolved(fit: DimensionFit) -> DimensionFit:
    """Mark a point fit invalid (flag ``"unresolved"``, NaN interval) when
    fewer than 3 of its fitted box sizes give distinct counts: the slope
    then is not an estimate (e.g. every box holds one point at every size,
    N(s) = number of points, D = 0 with a perfect line)."""
    a, b = fit.scale_range
    s = np.asarray(fit.scales, dtype=float)
    m = np.asarray(fit.measures, dtype=float)[(s >= a) & (s <= b)]
    if np.unique(m).size >= 3:
        return fit
    return mark_invalid(fit, "unresolved",
                        f"points: only {np.unique(m).size} distinct box count(s) over box sizes {a:g}..{b:g} "
                        f"({fit.extra.get('n_points')} points): the fit measures no scaling; use more points "
                        f"or box sizes where boxes hold several points")


#: Fewest points per box (mean over the aligned lattice) at the smallest
#: default box size of :func:`box_counting_points`.
POINT_MIN_OCCUPANCY = 20.0


def _rms_line(sizes: np.ndarray, meas: np.ndarray) -> float:
    """Root mean square residual of ``log meas`` about its straight line."""
    x, y = np.log(sizes), np.log(meas)
    coef = np.polyfit(x, y, 1)
    return float(np.sqrt(np.mean((y - np.polyval(coef, x)) ** 2)))


def _default_points_fit(pts: np.ndarray, scale_range: ScaleRange, n_threads) -> DimensionFit:
    n, d = pts.shape
    extent = float(np.max(pts.max(axis=0) - pts.min(axis=0)))
    if extent <= 0:
        raise ValueError("points: all points coincide; a box dimension needs an extended set")
    cands, levels = [], {}
    for occupancy in (POINT_MIN_OCCUPANCY, 0.0):
        for b in DEFAULT_BASES:
            k_first = int(math.ceil(math.log(DEFAULT_TOP) / math.log(b) - 1e-12))
            # too few points (second pass): the 3 largest sizes whatever their occupancy
            max_levels = 40 if occupancy > 0 else 3
            sz, aligned, shifted, inside = _core.box_count_point_levels(
                pts, b, k_first, occupancy, max_levels, n_threads)
            levels[b] = {"sizes": sz, "aligned": aligned, "shifted": shifted, "shifted_inside": inside}
            for lattice, meas in (("shifted", shifted), ("shifted_inside", inside)):
                if sz.size >= 3 and np.all(np.isfinite(meas)) and np.all(meas > 0):
                    cands.append((_rms_line(sz, meas), b, lattice))
        if cands:
            break
    undersampled = occupancy == 0.0
    if not cands:
        raise ValueError(f"points: {n} points give no 3 box sizes to fit; the set is too small")
    _, b, lattice = min(cands)
    lv = levels[b]
    fit = fit_loglog(
        lv["sizes"], lv[lattice], method="points", scale_range=scale_range,
        x_label="box size s", y_label="occupied boxes N(s)",
        extra={"n_points": n, "base": b, "lattice": lattice, "min_occupancy": POINT_MIN_OCCUPANCY,
               "counts": {k: np.asarray(v) for k, v in lv.items() if k != "sizes"}},
        domain=(0.0, float(d)),
    )
    fit = _check_resolved(fit)
    if undersampled:
        msg = (f"points: {n} points are too few for 3 box sizes holding {POINT_MIN_OCCUPANCY:g} points each "
               f"on average; the fit uses sparser boxes and reads the dimension low")
        fit = replace(fit, flags=tuple(fit.flags) + ("undersampled",), warning=(fit.warning + " " + msg).strip())
        if fit.valid:  # an invalid fit has had its warning
            warnings.warn(FractalRangeWarning(msg), stacklevel=user_stacklevel())
    return fit


def _nan_range(z: np.ndarray) -> Tuple[float, float]:
    """Lowest and highest valid value (no copy of the data)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN slice
        lo = float(np.nanmin(z))
    if math.isnan(lo):
        raise ValueError("data: no valid value (all NaN or nodata)")
    return lo, float(np.nanmax(z))


def _surface_float(data, nodata, name: str = "data", ndims=(2,)) -> np.ndarray:
    """A C-contiguous float32/float64 copy or view with nodata as NaN."""
    arr = as_array(data, name)
    if arr.ndim not in ndims:
        want = " or ".join(f"{d}D" for d in ndims)
        raise ValueError(f"{name}: expected a {want} array, got {arr.ndim} dimensions")
    if arr.size == 0:
        raise ValueError(f"{name}: array is empty (shape {arr.shape})")
    if arr.dtype.kind == "b":
        raise TypeError(f"{name}: a bool array is a binary set: use method='box' (box_counting)")
    if arr.dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected a numeric array, got dtype {arr.dtype}")
    out = arr if arr.dtype in (np.float32, np.float64) else arr.astype(np.float64)
    nodata = check_nodata(nodata)
    if nodata is not None:
        if np.isnan(nodata):
            pass  # NaN is always nodata
        else:
            mask = arr == nodata
            if mask.any():
                out = np.array(out, dtype=np.float64 if out.dtype == np.float64 else out.dtype, copy=True)
                out[mask] = np.nan
    out = np.ascontiguousarray(out)
    if np.isinf(out).any():
        raise ValueError(f"{name}: contains inf; mark invalid samples with NaN or nodata")
    return out


@renamed_parameters({"image": "data"}, since="0.2.0")
def differential_box_counting(
    data,
    *,
    box_sizes: Optional[Sequence[int]] = None,
    z_scale: Union[float, str] = "range",
    z0: Optional[float] = None,
    edge_blocks: str = "count",
    nodata: Optional[float] = None,
    offsets: int = 1,
    offset_reduce: str = "mean",
    scale_range: ScaleRange = None,
    n_threads: Optional[int] = None,
) -> DimensionFit:
    """Differential box counting (DBC) of a grayscale image or DEM.

    The image is read as a surface ``z(i, j)``. For box size ``s`` the plane
    is cut into ``s x s`` blocks and each block column is stacked with boxes
    of height ``h = s * z_scale``. A block whose values span ``[zmin, zmax]``
    needs ``floor((zmax - z0)/h) - floor((zmin - z0)/h) + 1`` boxes (``z0``:
    the base of the box stacks, by default the lowest valid value), ``N(s)``
    is their sum, and ``D = -slope`` of
    ``log N`` against ``log s`` (Sarkar and Chaudhuri 1994), between 2 and 3.

    Parameters
    ----------
    data : array_like, shape (rows, cols)
        Grayscale image or DEM, any real dtype (float32 and float64 are read
        without a copy). NaN is nodata and is skipped. (Called ``image``
        before 0.2.0; the old keyword still works, with a DeprecationWarning.)
    box_sizes : sequence of int, optional
        Block sides in pixels, at least 2. Default ``2, 4, 8, ...`` up to a
        quarter of the shorter side (``s = 1`` carries no height information
        in DBC: it raises ``ValueError``).
    z_scale : float, "auto" or "range", default "range"
        Box height per pixel of box size, in data units (e.g. metres per
        pixel). ``"range"``: ``(zmax - zmin) / max(rows, cols)``, which puts the
        surface in a cube as in Sarkar and Chaudhuri (G gray levels over an
        M x M image); for a DEM, ``z_scale = cell_size`` gives cubic boxes in
        physical units; ``"auto"``: ``1.4826 * median |lag-1 increment|``.
        Both data-derived units scale with the data, so D does not depend on
        the height unit; the measured choice is in ``docs/conventions.md``.
        Estimates depend on this choice: compare surfaces with the same
        convention.
    z0 : float, optional
        Base height of the box stacks, in data units. Default: the lowest
        valid value. A fixed ``z0`` (with a fixed ``z_scale``) makes a
        block's count independent of the rest of the image: this is how
        ``fractal_transform(method="dbc")`` defines its windows (``z0 = 0``).
    edge_blocks : {"count", "drop"}, default "count"
        Blocks of the last row and column that hold fewer than ``s`` rows or
        columns (when ``s`` does not divide the side): ``"count"`` counts them
        with the pixels they hold; ``"drop"`` leaves them out, so size ``s``
        covers the top-left ``floor(rows/s) s x floor(cols/s) s`` part (needs
        ``offsets=1``). On small images (moving windows) counting partial
        blocks biases ``D`` low: a 33-pixel side has 5 rows of 8-pixel
        blocks, not 4.
    nodata : float, optional
        Value marking missing data, in addition to NaN.
    offsets, offset_reduce, scale_range, n_threads
        As in :func:`box_counting` (here the lattice starts at pixel (0, 0)).

    Returns
    -------
    DimensionFit
        ``extra`` holds ``z_scale`` (the value used), ``z0`` and ``counts``.

    Notes
    -----
    Blocks at the right and bottom edges that hold fewer than ``s x s``
    pixels are counted with the pixels they hold (the lattice count of the
    surface over its domain); blocks with no valid pixel are skipped.

    References
    ----------
    Sarkar and Chaudhuri (1994), doi:10.1109/21.259692; full entry in the
    :ref:`bibliography <ref-sarkar1994>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> round(fg.differential_box_counting(np.zeros((64, 64))).dimension, 6)  # a flat image: D = 2
    2.0
    >>> dem, info = fg.data.srtm_alps()
    >>> round(fg.differential_box_counting(dem).dimension, 3)
    2.094
    """
    z = _surface_float(data, nodata, "data")
    sizes = check_box_sizes(box_sizes)
    if sizes is not None and sizes[0] < 2:
        raise ValueError(f"box_sizes: DBC needs block sides of at least 2 pixels (a 1-pixel block spans no "
                         f"height range: it always holds one box), got {sizes}")
    offsets = check_positive_int(offsets, "offsets")
    check_choice(offset_reduce, "offset_reduce", ("mean", "min"))
    n_threads = check_n_threads(n_threads)
    zmin, zmax = _nan_range(z)
    rows, cols = z.shape
    z_unit = resolve_z_scale(z_scale, z)
    if z0 is None:
        z0 = zmin
    else:
        if isinstance(z0, bool) or not isinstance(z0, numbers.Real) or not np.isfinite(z0):
            raise ValueError(f"z0: expected a finite number, got {z0!r}")
        z0 = float(z0)
    if sizes is None:
        sizes = dyadic_up_to(min(rows, cols) / 4, start=2)
        if len(sizes) < 3:
            raise ValueError(
                f"data: shape {z.shape} is too small for the default box sizes 2, 4, 8 (needs at least 32 pixels a side); give box_sizes"
            )
    check_choice(edge_blocks, "edge_blocks", ("count", "drop"))
    if edge_blocks == "drop" and offsets != 1:
        raise ValueError("edge_blocks: 'drop' needs offsets=1 (the partial blocks of shifted lattices differ)")
    s, counts = _core.dbc_count(z, sizes, offsets, z0, z_unit, n_threads)
    if edge_blocks == "drop":
        counts = np.array(counts, dtype=float, copy=True)
        for k, size in enumerate(np.asarray(s).tolist()):
            counts[k] -= _partial_block_counts(z, int(size), z0, z_unit)
    return _lattice_fit(
        "dbc", s, counts, offset_reduce, scale_range, "box size s (pixels)", "box count N(s)",
        {"z_scale": z_unit, "z0": z0, "offsets": offsets, "edge_blocks": edge_blocks},
        (2.0, 3.0),
    )


def _partial_block_counts(z: np.ndarray, s: int, z0: float, z_unit: float) -> float:
    """DBC boxes of the partial blocks (the last row and column of blocks
    when ``s`` does not divide the side), with the counter's arithmetic."""
    rows, cols = z.shape
    nr, nc = rows // s, cols // s
    h = s * z_unit
    total = 0.0
    # bottom strip (all columns, partial ones too) and right strip (full rows of blocks)
    for strip in (z[nr * s:, :], z[: nr * s, nc * s:].T):
        if strip.size == 0:
            continue
        t, n = strip.shape
        nb = -(-n // s)
        pad = np.full((t, nb * s), np.nan)
        pad[:, :n] = strip
        blk = pad.reshape(t, nb, s).transpose(1, 0, 2).reshape(nb, t * s)
        ok = ~np.isnan(blk)
        has = ok.any(axis=1)
        lo = np.where(ok, blk, np.inf).min(axis=1)[has]
        hi = np.where(ok, blk, -np.inf).max(axis=1)[has]
        total += float(np.sum(np.floor((hi - z0) / h) - np.floor((lo - z0) / h) + 1))
    return total


def self_affine_box_counting(
    data,
    *,
    box_sizes: Optional[Sequence[int]] = None,
    nodata: Optional[float] = None,
    scale_range: ScaleRange = None,
    n_threads: Optional[int] = None,
) -> DimensionFit:
    """Anisotropic (self-affine) box counting of a profile or surface graph.

    A self-affine graph ``z(x)`` is statistically similar to
    ``alpha^-H z(alpha x)``, so boxes must be scaled by ``alpha`` across and
    ``alpha^H`` up (paper section 2.4). With columns of width ``s`` samples
    and boxes of height ``delta(s) = delta_1 s^h``, a column whose graph spans
    the height range ``R`` needs on average ``R / delta + 1`` boxes (the
    average over vertical placements of the lattice). The graph is
    self-affine with exponent ``h`` exactly when the mean count per column
    does not change with ``s`` (``N_alpha / N`` is then ``alpha^-d``, the
    ratio of section 2.4); this function solves for that ``h`` by bisection
    on ``(0, 1)`` and returns

    .. math:: H = h, \\qquad D = d + 1 - H

    with ``d = 1`` for profiles and ``d = 2`` for surfaces.

    Parameters
    ----------
    data : array_like, shape (n,) or (rows, cols)
        A profile or a surface (DEM) sampled on a regular grid. NaN (and
        ``nodata``) samples are skipped.
    box_sizes : sequence of int, optional
        Column widths in samples. Default ``1, 2, 4, ...`` while at least 8
        complete columns fit along each axis.
    nodata : float, optional
        Value marking missing samples, in addition to NaN.
    scale_range, n_threads
        As in :func:`box_counting`.

    Returns
    -------
    DimensionFit
        ``dimension`` is D; ``extra["hurst"]`` is H. ``measures`` are the
        heights covered per column, ``n(s) * delta(s)``, whose log-log slope is
        H; ``extra["mean_range"]`` holds the mean column ranges and
        ``extra["converged"]`` is False when H hit 0 or 1.

    Notes
    -----
    The graph is the piecewise-linear (bilinear for surfaces) interpolant of
    the samples, so a column over ``[i s, i s + s]`` spans exactly the range
    of the ``s + 1`` samples it holds; only complete columns are used.
    ``delta_1`` is the mean range of unit columns. The ``+ 1`` of each column
    is what separates this estimator from a plain range-scaling fit; it
    cancels only at the self-affine ``h``.

    References
    ----------
    B. B. Mandelbrot, Self-affine fractals and fractal dimension, *Physica
    Scripta* 32 (1985) 257-260, doi:10.1088/0031-8949/32/4/001.

    Falconer (1990); full entry in the :ref:`bibliography <ref-falconer1990>`.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> x = fg.fbm(4097, 0.7, method='exact', seed=0)  # H = 0.7, D = 2 - H = 1.3
    >>> fit = fg.self_affine_box_counting(x)
    >>> round(fit.extra['hurst'], 1), round(fit.dimension, 1)
    (0.7, 1.3)
    """
    z = _surface_float(data, nodata, "data", ndims=(1, 2))
    profile = z.ndim == 1
    z2 = np.ascontiguousarray(z.reshape(1, -1) if profile else z, dtype=np.float64)
    sizes = check_box_sizes(box_sizes)
    n_threads = check_n_threads(n_threads)
    rows, cols = z2.shape
    if sizes is None:
        lim = (cols - 1) / 8 if profile else (min(rows, cols) - 1) / 8
        sizes = dyadic_up_to(lim)
        if len(sizes) < 3:
            raise ValueError(
                f"data: shape {z.shape} is too small for the default column widths 1, 2, 4 "
                "(needs at least 33 samples per axis); give box_sizes"
            )
    ranges, ncols = _core.column_ranges(z2, sizes, n_threads)
    s = np.asarray(sizes, dtype=float)
    if scale_range is not None and not isinstance(scale_range, str):
        try:
            lo, hi = (float(v) for v in as_list(scale_range, "scale_range", "two numbers (low, high)"))
        except ValueError:
            raise ValueError(f"scale_range: expected 'auto' or two numbers (low, high), got {scale_range!r}") from None
        sel = (s >= lo) & (s <= hi)
    else:
        sel = np.ones_like(s, dtype=bool)
    if not np.all(ranges > 0):
        raise ValueError("data: the graph is flat over some column width; a self-affine fit needs relief")
    delta1 = float(ranges[0]) if s[0] == 1 else float(ranges[0] / s[0])
    ls = np.log(s)

    def count_slope(h: float, mask) -> float:
        n = ranges / (delta1 * s**h) + 1.0
        x, y = ls[mask], np.log(n[mask])
        xm = x.mean()
        return float(np.sum((x - xm) * (y - y.mean())) / np.sum((x - xm) ** 2))

    def solve(mask) -> Tuple[float, bool]:
        lo, hi = 0.0, 1.0
        if count_slope(lo, mask) <= 0:
            return 0.0, False
        if count_slope(hi, mask) >= 0:
            return 1.0, False
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if count_slope(mid, mask) > 0:
                lo = mid
            else:
                hi = mid
        return 0.5 * (lo + hi), True

    if np.count_nonzero(sel) < 3:
        raise ValueError("scale_range: holds fewer than 3 column widths")
    h, converged = solve(sel)
    covered = (ranges / (delta1 * s**h) + 1.0) * delta1 * s**h
    d = 1 if profile else 2
    fit = fit_loglog(
        s,
        covered,
        method="affine",
        domain=(float(d), d + 1.0),
        dim_offset=d + 1.0,
        dim_factor=-1.0,
        scale_range=scale_range,
        x_label="column width s (samples)",
        y_label="height covered per column n(s)·δ(s)",
        extra={"hurst": h, "mean_range": ranges, "n_columns": ncols, "delta_1": delta1, "converged": converged},
    )
    if isinstance(scale_range, str):  # "auto": solve again on the chosen range
        h, converged = solve(fit.used)
        covered = (ranges / (delta1 * s**h) + 1.0) * delta1 * s**h
        fit = fit_loglog(
            s,
            covered,
            method="affine",
            dim_offset=d + 1.0,
            dim_factor=-1.0,
            scale_range=fit.scale_range,
            x_label=fit.x_label,
            y_label=fit.y_label,
            extra={"hurst": h, "mean_range": ranges, "n_columns": ncols, "delta_1": delta1, "converged": converged},
        )
        object.__setattr__(fit, "range_selection", "auto")
    return fit
