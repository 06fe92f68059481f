"""The height unit ``z_scale`` of the box, mass and blanket methods: one resolver.

Every function that takes ``z_scale`` (``differential_box_counting``,
``mass_dimension``, ``blanket``, ``fractal_transform``) accepts the same
spellings and resolves them here:

* a positive number: data units per box height step (e.g. ``cell_size`` for
  cubic boxes on a DEM);
* ``"auto"``: ``1.4826 * median |lag-1 increment|`` of the data
  (:func:`fractalgeo_rs.transform.default_z_scale`, defined here with the
  reasoning behind it);
* ``"range"``: ``(max - min) / max(rows, cols)``, the normalisation of
  Sarkar and Chaudhuri (1994, doi:10.1109/21.259692) that puts the surface
  in a cube.

Both data-derived units scale with the data, so a default call gives the
same dimension whatever the height unit (metres or millimetres, dB or
tenths of a dB). The measured choice of each function's default is in
``docs/conventions.md``.

The ``"auto"`` unit, derived once from the whole image. The box and mass maps (``"mass"``, ``"dbc"``, ``"blanket"``) count boxes of
``z_scale`` height units; their values depend on that unit. A unit of 1
(1 m, 1 dB, 1 grey level) makes the map constant on a 1 m lidar DEM (D = 2
wherever the relief inside a box is under a metre) and out of range on a
3-arc-second DEM. The default unit is instead a robust scale of the image's
lag-1 increments,

.. math::

    z_{scale} = 1.4826 \\, \\operatorname{median} |z(p + e) - z(p)|,

over the row and column neighbours ``e`` (the normal-consistent median
absolute increment; Rousseeuw and Croux 1993, doi:10.1080/01621459.1993.10476408),
so that one box of side 1 holds about one typical step of the surface.
Large images are sampled on every ``stride``-th row and column (``stride =
ceil(max(rows, cols) / 2048)``; the increments along each sampled line are
all used), the same rule for numpy and Dask inputs, so maps computed either
way use the same unit. Maps are comparable only at equal ``z_scale``: pass a
fixed number across scenes.
"""
from __future__ import annotations

import math
import numbers
from typing import Optional, Union

import numpy as np

from fractalgeo_rs._validation import as_array, check_positive_float

__all__ = ["Z_SCALE_NAMES", "resolve_z_scale", "range_z_scale", "default_z_scale", "MAD_TO_SIGMA"]

Z_SCALE_NAMES = ("auto", "range")
"""The data-derived spellings of ``z_scale``."""

ZScale = Union[float, str]


def range_z_scale(z, nodata: Optional[float] = None) -> float:
    """``(max - min) / max(rows, cols)`` over the finite values of ``z``
    other than ``nodata`` (1.0 for a constant or empty image). ``z`` may be
    a dask array (two reductions are computed)."""
    ok = np.isfinite(z)
    if nodata is not None and not np.isnan(nodata):
        ok = ok & (z != nodata)
    zmin = float(np.min(np.where(ok, z, np.inf)))
    zmax = float(np.max(np.where(ok, z, -np.inf)))
    if not (np.isfinite(zmin) and zmax > zmin):
        return 1.0
    return (zmax - zmin) / max(z.shape)


def check_z_scale(z_scale) -> ZScale:
    """``z_scale`` checked without the data: a positive finite float, or one
    of :data:`Z_SCALE_NAMES`."""
    if isinstance(z_scale, str):
        if z_scale not in Z_SCALE_NAMES:  # a string, but not a known one: the type (str) is wrong
            raise TypeError(f"z_scale: expected a positive number, 'auto' or 'range', got {z_scale!r}")
        return z_scale
    if isinstance(z_scale, bool) or not isinstance(z_scale, numbers.Real):
        raise TypeError(f"z_scale: expected a positive number, 'auto' or 'range', got {z_scale!r}")
    return check_positive_float(z_scale, "z_scale")


def resolve_z_scale(z_scale, z, nodata: Optional[float] = None) -> float:
    """The height unit, in data units, for ``z_scale`` on the image ``z``.

    Parameters
    ----------
    z_scale : float, "auto" or "range"
        As described in the module docstring.
    z : array_like or dask array, shape (rows, cols)
        The image; NaN, ±inf and ``nodata`` are left out of the data-derived
        units.
    nodata : float, optional
        Value marking missing samples.

    Returns
    -------
    float
        A positive finite height unit.
    """
    z_scale = check_z_scale(z_scale)
    if not isinstance(z_scale, str):
        return z_scale
    if z_scale == "auto":
        return default_z_scale(z, nodata)
    return range_z_scale(z, nodata)


MAD_TO_SIGMA = 1.4826  # 1 / Phi^-1(3/4): the MAD of a normal sample times this is its sigma
_SAMPLE_SIDE = 2048


def _lines(image, stride: int):
    """Every ``stride``-th row and column of ``image`` as numpy arrays."""
    rows = image[::stride, :]
    cols = image[:, ::stride]
    if type(image).__module__.startswith("dask"):
        import dask

        rows, cols = dask.compute(rows, cols)
    return np.asarray(rows, dtype=np.float64), np.asarray(cols, dtype=np.float64)


def default_z_scale(image, nodata: Optional[float] = None) -> float:
    """The default height unit of the box and mass maps of ``image``.

    Parameters
    ----------
    image : array_like or dask array, shape (rows, cols)
        The image (heights, dB, grey levels). NaN, ±inf and ``nodata`` are
        left out.
    nodata : float, optional
        Value marking missing samples.

    Returns
    -------
    float
        ``1.4826 * median |lag-1 increment|`` over rows and columns (in the
        image's units); when more than half of the increments are 0
        (quantised or flat data), ``sqrt(pi / 2) * mean |increment|`` over
        the increments (the same scale for Gaussian increments); 1.0 for a
        constant image.

    References
    ----------
    Rousseeuw, P. J., Croux, C. (1993). Alternatives to the median absolute
    deviation. *Journal of the American Statistical Association* 88(424),
    1273-1283. doi:10.1080/01621459.1993.10476408 (1.4826 = 1 / Phi^-1(3/4)).

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.transform import default_z_scale
    >>> i, j = np.indices((50, 50))
    >>> round(default_z_scale(3.0 * i + 4.0 * j), 4)  # median of |3| and |4| steps
    5.1891
    """
    if not hasattr(image, "shape"):
        image = as_array(image, "image")
    shape = image.shape
    if len(shape) != 2:
        raise ValueError(f"image: expected a 2D image, got {len(shape)} dimensions")
    stride = max(1, math.ceil(max(shape) / _SAMPLE_SIDE))
    rows, cols = _lines(image, stride)
    if nodata is not None and not np.isnan(nodata):
        rows = np.where(rows == nodata, np.nan, rows)
        cols = np.where(cols == nodata, np.nan, cols)
    inc = np.concatenate([np.abs(np.diff(rows, axis=1)).ravel(), np.abs(np.diff(cols, axis=0)).ravel()])
    inc = inc[np.isfinite(inc)]
    if inc.size == 0:
        return 1.0
    med = float(np.median(inc))
    if med > 0:
        return MAD_TO_SIGMA * med
    mean = float(np.mean(inc))
    return math.sqrt(math.pi / 2) * mean if mean > 0 else 1.0
