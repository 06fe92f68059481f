"""Iterated function systems: chaos game, deterministic iteration, rasters,
classic presets and Moran's equation.
"""
from __future__ import annotations

import numbers
from typing import Optional, Sequence, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import check_n_threads, check_positive_int, check_seed

__all__ = ["IFS", "IFS_PRESETS", "ifs_preset", "moran_dimension", "rasterize_points"]

#: Names accepted by :func:`~fractalgeo_rs.lsystem.ifs_preset`.
IFS_PRESETS = ("sierpinski_triangle", "sierpinski_carpet", "barnsley_fern", "koch_curve", "dragon", "vicsek")


def moran_dimension(ratios: Sequence[float]) -> float:
    r"""Similarity dimension: the root ``s`` of Moran's equation
    :math:`\sum_i r_i^s = 1`.

    Parameters
    ----------
    ratios : sequence of float
        Contraction ratios in (0, 1), one per map (dimensionless).

    Returns
    -------
    float
        The similarity dimension ``s >= 0``.

    Notes
    -----
    Under the open set condition ``s`` is the Hausdorff and box-counting
    dimension of the attractor (Moran 1946; Hutchinson 1981).

    References
    ----------
    P. A. P. Moran, Additive functions of intervals and Hausdorff measure,
    *Proc. Camb. Phil. Soc.* 42 (1946) 15-23, doi:10.1017/S0305004100022684.

    Hutchinson (1981), doi:10.1512/iumj.1981.30.30055; full entry in the
    :ref:`bibliography <ref-hutchinson1981>`.

    Examples
    --------
    >>> import math
    >>> from fractalgeo_rs.lsystem import moran_dimension
    >>> round(moran_dimension([1/3] * 4), 6), round(math.log(4) / math.log(3), 6)  # Koch curve
    (1.26186, 1.26186)
    >>> round(moran_dimension([0.5, 0.25, 0.25]), 12)  # 0.5 + 0.25 + 0.25 = 1: s = 1
    1.0
    """
    if isinstance(ratios, (str, bytes)):
        raise TypeError(f"ratios: expected a sequence of numbers, got {type(ratios).__name__}")
    try:
        r = np.asarray(ratios, dtype=float).ravel()
    except (TypeError, ValueError) as exc:
        raise TypeError(f"ratios: expected a sequence of numbers, could not convert: {exc}") from None
    return float(_core.moran_dimension(r.tolist()))


def _check_shape(shape) -> Tuple[int, int]:
    if isinstance(shape, numbers.Integral):
        shape = (shape, shape)
    try:
        rows, cols = shape
    except (TypeError, ValueError):
        raise TypeError(f"shape: expected an int or (rows, cols), got {shape!r}") from None
    return check_positive_int(rows, "shape"), check_positive_int(cols, "shape")


def rasterize_points(points, shape, *, bounds: Optional[Sequence[float]] = None) -> np.ndarray:
    """Binary raster of a 2D point set.

    The extent is divided into ``rows x cols`` equal cells; a cell is 1 when
    at least one point falls in it (points on ``xmax`` or ``ymin`` go to
    the last column or row). Box counting of the raster
    (:func:`fractalgeo_rs.box_counting`) estimates the dimension of the set.

    Parameters
    ----------
    points : array_like, shape (N, 2)
        ``(x, y)`` coordinates, e.g. from :meth:`fractalgeo_rs.IFS.chaos_game`.
    shape : int or (rows, cols)
        Raster size in cells (an int gives a square raster).
    bounds : (xmin, xmax, ymin, ymax), optional
        The extent covered by the raster, in the points' units; the points'
        bounding box if None. Row 0 is at ``ymax``. Points outside are
        dropped.

    Returns
    -------
    ndarray of uint8, shape (rows, cols)
        1 in the cells holding a point, 0 elsewhere.

    References
    ----------
    Barnsley (1988) (attractors drawn by the random iteration algorithm on a
    grid of pixels); full entry in the :ref:`bibliography <ref-barnsley1988>`.

    Examples
    --------
    Three points on the diagonal ``y = x``; row 0 is at the top:

    >>> import numpy as np
    >>> from fractalgeo_rs.lsystem import rasterize_points
    >>> rasterize_points(np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]]), 3)
    array([[0, 0, 1],
           [0, 1, 0],
           [1, 0, 0]], dtype=uint8)
    """
    pts = np.ascontiguousarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ValueError(f"points: expected shape (N, 2), got {pts.shape}")
    rows, cols = _check_shape(shape)
    b = None if bounds is None else [float(v) for v in bounds]
    if b is not None and len(b) != 4:
        raise ValueError(f"bounds: expected (xmin, xmax, ymin, ymax), got {bounds!r}")
    img, _ = _core.ifs_rasterize(pts, rows, cols, b)
    return img


class IFS:
    r"""An iterated function system of affine maps of the plane.

    Map ``i`` is ``(a, b, c, d, e, f)``: :math:`x' = a x + b y + e`,
    :math:`y' = c x + d y + f` (the layout of Barnsley 1988). The attractor
    is the unique compact set :math:`A = \bigcup_i w_i(A)` (Hutchinson 1981).

    Parameters
    ----------
    maps : (k, 6) array-like
        Every map must be a contraction (largest singular value < 1).
    probabilities : (k,) array-like, optional
        Chaos-game weights, normalised to sum 1; they must be >= 0 and sum
        to a positive number. Default: proportional to ``|det|`` with a
        floor of 1% of the largest.

    Attributes
    ----------
    maps : (k, 6) ndarray
    probabilities : (k,) ndarray
    similarity_dimension : float or None
        Root of Moran's equation when every map is a similarity.

    References
    ----------
    M. Barnsley, *Fractals Everywhere*, Academic Press, 1988.
    J. E. Hutchinson, Fractals and self-similarity, *Indiana Univ. Math. J.*
    30 (1981) 713-747.

    Examples
    --------
    >>> from fractalgeo_rs.lsystem import IFS
    >>> tri = IFS.preset("sierpinski_triangle")
    >>> round(tri.similarity_dimension, 4)
    1.585
    >>> tri.iterate(5).shape
    (243, 2)
    >>> tri.rasterize(64, depth=8).dtype
    dtype('uint8')
    """

    def __init__(self, maps, probabilities=None):
        m = np.ascontiguousarray(maps, dtype=float)
        if m.ndim != 2 or m.shape[1] != 6:
            raise ValueError(f"maps: expected shape (k, 6), got {m.shape}")
        p = None if probabilities is None else np.asarray(probabilities, dtype=float).ravel().tolist()
        self.maps, self.probabilities, self.similarity_dimension = _core.ifs_check(m, p)
        self._given_p = p
        self.dimension: Optional[float] = None

    @classmethod
    def preset(cls, name: str) -> "IFS":
        """A classic IFS (see ``IFS_PRESETS``); its exact dimension is in
        ``dimension`` (None for the fern)."""
        maps, probs, dim = _core.ifs_preset(name)
        obj = cls(maps, probs)
        obj.dimension = dim
        return obj

    def __repr__(self) -> str:
        return f"IFS(n_maps={len(self.maps)}, similarity_dimension={self.similarity_dimension})"

    def chaos_game(self, n_points: int, *, seed: Optional[int] = None, n_threads: Optional[int] = None) -> np.ndarray:
        """``n_points`` points of the attractor by the chaos game.

        Orbits of 65536 points start at the fixed point of the first map
        (which lies on the attractor, so nothing is discarded) and draw their
        maps from a hash of (seed, orbit, step): the same seed gives the same
        points on any number of threads.
        """
        n = check_positive_int(n_points, "n_points")
        return _core.ifs_chaos_game(self.maps, self.probabilities.tolist(), n, check_seed(seed), check_n_threads(n_threads))

    def iterate(self, depth: int, *, max_points: int = 1 << 24, n_threads: Optional[int] = None) -> np.ndarray:
        """Deterministic iteration: the ``k**depth`` images of the first
        map's fixed point under all compositions of ``depth`` maps."""
        if isinstance(depth, bool) or not isinstance(depth, numbers.Integral) or depth < 0:
            raise ValueError(f"depth: expected a non-negative int, got {depth!r}")
        return _core.ifs_iterate(self.maps, int(depth), check_positive_int(max_points, "max_points"), check_n_threads(n_threads))

    def rasterize(self, shape, *, depth: Optional[int] = None, n_points: Optional[int] = None,
                  seed: Optional[int] = None, bounds: Optional[Sequence[float]] = None,
                  n_threads: Optional[int] = None) -> np.ndarray:
        """Binary raster of the attractor.

        Uses deterministic iteration to ``depth`` when given, else the chaos
        game with ``n_points`` (default: 20 points per pixel, at most 2**27). See
        :func:`~fractalgeo_rs.lsystem.rasterize_points` for ``bounds``.
        """
        rows, cols = _check_shape(shape)
        if depth is not None and n_points is not None:
            raise ValueError("depth: give either depth or n_points, not both")
        if depth is not None:
            pts = self.iterate(depth, n_threads=n_threads)
        else:
            if n_points is None:
                n_points = min(20 * rows * cols, 1 << 27)
            pts = self.chaos_game(n_points, seed=seed, n_threads=n_threads)
        return rasterize_points(pts, (rows, cols), bounds=bounds)


def ifs_preset(name: str) -> IFS:
    """A classic iterated function system by name: the same as
    :meth:`fractalgeo_rs.IFS.preset`.

    Parameters
    ----------
    name : str
        One of ``fractalgeo_rs.lsystem.IFS_PRESETS``:
        ``"sierpinski_triangle"``, ``"sierpinski_carpet"``,
        ``"barnsley_fern"``, ``"koch_curve"``, ``"dragon"``, ``"vicsek"``.

    Returns
    -------
    IFS
        The maps and chaos-game weights; its ``dimension`` attribute is the
        exact dimension of the attractor (None for the fern, whose maps are
        not similarities).

    References
    ----------
    M. Barnsley, *Fractals Everywhere*, Academic Press, 1988 (the fern).
    J. E. Hutchinson, Fractals and self-similarity, *Indiana Univ. Math. J.*
    30 (1981) 713-747, doi:10.1512/iumj.1981.30.30055.

    Examples
    --------
    >>> import math
    >>> from fractalgeo_rs.lsystem import ifs_preset
    >>> koch = ifs_preset("koch_curve")
    >>> len(koch.maps), round(koch.dimension, 12) == round(math.log(4) / math.log(3), 12)
    (4, True)
    >>> ifs_preset("sierpinski_carpet").dimension == math.log(8) / math.log(3), ifs_preset("barnsley_fern").dimension
    (True, None)
    """
    return IFS.preset(name)
