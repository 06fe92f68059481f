"""The height unit ``z_scale`` of the box, mass and blanket methods: one resolver.

Every function that takes ``z_scale`` (``differential_box_counting``,
``mass_dimension``, ``blanket``, ``fractal_transform``) accepts the same
spellings and resolves them here:

* a positive number: data units per box height step (e.g. ``cell_size`` for
  cubic boxes on a DEM);
* ``"auto"``: ``1.4826 * median |lag-1 increment|`` of the data
  (:func:`fractalgeo_rs.transform.default_z_scale`);
* ``"range"``: ``(max - min) / max(rows, cols)``, the normalisation of
  Sarkar and Chaudhuri (1994, doi:10.1109/21.259692) that puts the surface
  in a cube.

Both data-derived units scale with the data, so a default call gives the
same dimension whatever the height unit (metres or millimetres, dB or
tenths of a dB). The measured choice of each function's default is in
``docs/conventions.md``.
"""
from __future__ import annotations

import numbers
from typing import Optional, Union

import numpy as np

from fractalgeo_rs._validation import check_positive_float

__all__ = ["Z_SCALE_NAMES", "resolve_z_scale", "range_z_scale"]

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
        from fractalgeo_rs.transform._defaults import default_z_scale

        return default_z_scale(z, nodata)
    return range_z_scale(z, nodata)
