"""Defaults of the fractal transform derived once from the whole image.

The box and mass maps (``"mass"``, ``"dbc"``, ``"blanket"``) count boxes of
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
from typing import Optional

import numpy as np

from fractalgeo_rs._validation import as_array

__all__ = ["default_z_scale"]

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
