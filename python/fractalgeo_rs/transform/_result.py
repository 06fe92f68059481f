"""The result of ``fractal_transform(..., return_fit=True)``: the maps, a
flag layer and the parameters that make maps comparable.

Flag layer (``uint8`` bits, 0 = a valid estimate):

======  ==================  =================================================
bit     name                meaning
======  ==================  =================================================
1       ``below_2``         ``D < 2``: smoother than any surface at the
                            window's scales (e.g. an interpolated DEM at
                            lags 1-2), not a dimension
2       ``above_3``         ``D > 3``: rougher than any surface (white noise,
                            SAR speckle), not a dimension
4       ``pinned``          the estimate sits at an end of the method's
                            search grid of ``H`` (``"gls"``, ``"whittle"``):
                            a bound, not an estimate
8       ``too_few_valid``   no value (NaN): fewer than ``min_valid`` of the
                            window's pixels are valid, or no fit exists
======  ==================  =================================================
"""
from __future__ import annotations

import warnings
from typing import Any, Dict, Tuple

import numpy as np

from fractalgeo_rs._backend import array_kind
from fractalgeo_rs._warn import user_stacklevel

FLAG_BELOW_2 = 1
FLAG_ABOVE_3 = 2
FLAG_PINNED = 4
FLAG_TOO_FEW_VALID = 8
FLAGS = {"below_2": FLAG_BELOW_2, "above_3": FLAG_ABOVE_3, "pinned": FLAG_PINNED,
         "too_few_valid": FLAG_TOO_FEW_VALID}
"""Flag names and their bits."""

RANGE_TOLERANCE = 1e-6
"""Maps are float32: values within this of 2 or 3 are in range."""

_PIN_TOLERANCE = 1e-4


def _pinned_values(method: str) -> Tuple[float, ...]:
    """Values of ``D`` at the ends of the method's ``H`` search grid."""
    from fractalgeo_rs.transform._methods import METHODS

    return METHODS[method].pinned()


def _flags_block(d: np.ndarray, pins: Tuple[float, ...]) -> np.ndarray:
    d = np.asarray(d, dtype=np.float64)
    f = np.zeros(d.shape, dtype=np.uint8)
    with np.errstate(invalid="ignore"):
        f[d < 2.0 - RANGE_TOLERANCE] |= FLAG_BELOW_2
        f[d > 3.0 + RANGE_TOLERANCE] |= FLAG_ABOVE_3
        for p in pins:
            f[np.abs(d - p) <= _PIN_TOLERANCE] |= FLAG_PINNED
    f[np.isnan(d)] |= FLAG_TOO_FEW_VALID
    return f


def flag_map(dmap, method: str):
    """The flag layer of a dimension map (numpy, Dask or xarray, the same
    type and shape as ``dmap``; Dask stays lazy)."""
    pins = _pinned_values(method)
    kind = array_kind(dmap)
    if kind == "xarray":
        out = dmap.copy(data=flag_map(dmap.data, method))
        out.name = "fractal_flags"
        out.attrs = dict(dmap.attrs)
        out.attrs["flag_meanings"] = " ".join(FLAGS)
        out.attrs["flag_masks"] = list(FLAGS.values())
        return out
    if kind == "dask":
        return dmap.map_blocks(_flags_block, pins, dtype=np.uint8)
    return _flags_block(dmap, pins)


def warn_out_of_range(dmap: np.ndarray, method: str) -> None:
    """One ``FractalRangeWarning`` giving the fractions of an in-memory map
    below 2 and above 3, when there are any."""
    from fractalgeo_rs.fit import FractalRangeWarning

    d = np.asarray(dmap)
    v = d[np.isfinite(d)]
    if v.size == 0:
        return
    lo = float(np.mean(v < 2.0 - RANGE_TOLERANCE))
    hi = float(np.mean(v > 3.0 + RANGE_TOLERANCE))
    smooth = "smoother than a surface at the window's scales"
    rough = "rougher than a surface: noise or speckle"
    if lo > 0 and hi > 0:
        what = (f"D is below 2 on {100 * lo:.1f} % of the valid windows ({smooth}) and above 3 on "
                f"{100 * hi:.1f} % ({rough})")
    elif lo > 0:
        what = f"D is below 2 on {100 * lo:.1f} % of the valid windows ({smooth})"
    elif hi > 0:
        what = f"D is above 3 on {100 * hi:.1f} % of the valid windows ({rough})"
    else:
        return
    warnings.warn(f"{method}: {what}, so those values are not dimensions of a surface; return_fit=True "
                  f"gives their flag layer (help(fractalgeo_rs.transform.TransformFit))", FractalRangeWarning, stacklevel=user_stacklevel())


class TransformFit(tuple):
    """The maps of ``fractal_transform(..., return_fit=True)``.

    A tuple (so ``d, r2 = fractal_transform(..., return_fit=True)`` unpacks
    as before) of the dimension map and the fit-quality map (r², or the
    standard error of ``D`` for ``"whittle"`` and ``"gls"``), followed by the
    anisotropy maps when asked, with two attributes:

    Attributes
    ----------
    flags : ndarray of uint8 (or the input's dask/xarray type)
        The flag layer (bits in ``fractalgeo_rs.transform.FLAGS``: 1 below 2, 2 above 3,
        4 pinned, 8 too few valid; 0 = valid).
    params : dict
        ``method``, ``window_size``, ``step``, ``z_scale`` (the value used,
        ``None`` for the scale-free methods) and ``z_units``.

    References
    ----------
    CF Conventions 1.11, section 3.5 (flags: ``flag_masks`` and
    ``flag_meanings``), https://cfconventions.org.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> i, j = np.indices((32, 32))
    >>> out = fg.fractal_transform((i * j).astype(float), 9, method="square", return_fit=True)
    >>> d, se = out                      # unpacks like a pair
    >>> float(np.nanmax(d))              # z = i j: square increments u^2, D = 3 - 2 = 1
    1.0
    >>> sorted(np.unique(out.flags).tolist())   # 1: below 2, 8: too few valid pixels
    [1, 8]
    >>> out.params["method"], out.params["window_size"], out.params["z_scale"]
    ('square', 9, None)
    """

    flags: Any
    params: Dict[str, Any]

    def __new__(cls, maps, flags, params):
        obj = super().__new__(cls, tuple(maps))
        obj.flags = flags
        obj.params = dict(params)
        return obj

    def __getnewargs__(self):
        return (tuple(self), self.flags, self.params)

    def __reduce__(self):
        return (TransformFit, (tuple(self), self.flags, self.params))

    @property
    def dimension(self):
        """The dimension map (the first element)."""
        return self[0]
