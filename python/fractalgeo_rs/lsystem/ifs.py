"""Iterated function systems: chaos game, deterministic iteration, rasters,
classic presets and Moran's equation.
"""
from __future__ import annotations

import numbers
from typing import Optional, Sequence, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import check_n_threads, check_positive_int
from fractalgeo_rs.lsystem.core import _check_seed

__all__ = ["IFS", "IFS_PRESETS", "ifs_preset", "moran_dimension", "rasterize_points"]

#: Names accepted by :func:`ifs_preset`.
IFS_PRESETS = ("sierpinski_triangle", "sierpinski_carpet", "barnsley_fern", "koch_curve", "dragon", "vicsek")


def moran_dimension(ratios: Sequence[float]) -> float:
    r"""Similarity dimension: the root ``s`` of Moran's equation
    :math:`\sum_i r_i^s = 1`.

    Parameters
    ----------
    ratios : sequence of float
        Contraction ratios in (0, 1).

    Notes
    -----
    Under the open set condition ``s`` is the Hausdorff and box-counting
    dimension of the attractor (Moran 1946; Hutchinson 1981).

    References
    ----------
    P. A. P. Moran, Additive functions of intervals and Hausdorff measure,
    *Proc. Camb. Phil. Soc.* 42 (1946) 15-23. J. E. Hutchinson, Fractals and
    self-similarity, *Indiana Univ. Math. J.* 30 (1981) 713-747.

    Examples
    --------
    >>> from fractalgeo_rs.lsystem import moran_dimension
    >>> round(moran_dimension([1/3] * 4), 6)   # Koch curve: log 4 / log 3
    1.26186
    """
    r = np.asarray(ratios, dtype=float).ravel()
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

    Parameters
    ----------
    points : (N, 2) array
    shape : int or (rows, cols)
    bounds : (xmin, xmax, ymin, ymax), optional
        The extent covered by the raster; the points' bounding box if None.
        Row 0 is at ``ymax``. Points outside are dropped.

    Returns
    -------
    (rows, cols) uint8 array of 0 and 1.
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
        """A classic IFS (see :data:`IFS_PRESETS`); its exact dimension is in
        :attr:`dimension` (None for the fern)."""
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
        return _core.ifs_chaos_game(self.maps, self.probabilities.tolist(), n, _check_seed(seed), check_n_threads(n_threads))

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
        :func:`rasterize_points` for ``bounds``.
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
    """Shorthand for :meth:`IFS.preset`."""
    return IFS.preset(name)
