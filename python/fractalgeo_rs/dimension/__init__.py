"""Fractal dimension estimators.

One entry point, :func:`dimension`, dispatches on ``method`` to a named
function; every estimator returns a :class:`fractalgeo_rs.DimensionFit`.

=============  ===============================================  =====================================
method         data                                             function
=============  ===============================================  =====================================
``"box"``      binary sets, 1D/2D/3D arrays                     :func:`box_counting`
``"points"``   point sets, (N, d) coordinates                   :func:`box_counting_points`
``"dbc"``      grayscale images, DEMs                           :func:`differential_box_counting`
``"affine"``   graphs of profiles and surfaces (self-affine)    :func:`self_affine_box_counting`
``"minkowski"`` binary sets (sausage of radius r)               :func:`minkowski`
``"mass"``     binary images, point sets, grayscale (P(m,L))    :func:`mass_dimension`
``"blanket"``  grayscale surfaces (Peleg covering blanket)      :func:`blanket`
``"spectral"`` profiles and surfaces (power spectrum)           :func:`spectral_dimension`
``"variogram"`` profiles, surfaces (p=2, first differences)     :func:`variogram`
``"madogram"`` profiles, surfaces (p=1, first differences)      :func:`madogram`
``"variation"`` profiles, power variation (p, order)            :func:`power_variation`
``"surface_variation"`` surfaces: square, first or transect     :func:`surface_variation`
``"wavelet"``  profiles and surfaces (Haar detail variance)     :func:`wavelet_dimension`
``"scale_space"`` profiles (Gaussian scale space, eq. 14)       :func:`scale_space`
``"higuchi"``  profiles and time series                         :func:`higuchi`
``"whittle"``  fBm profiles and surfaces (debiased Whittle)     :func:`whittle`
``"mle"``      small fBm profiles and surfaces (exact Gaussian) :func:`fbm_mle`
``"gls"``      fBm profiles and surfaces (GLS of increments)    :func:`gls_dimension`
=============  ===============================================  =====================================

:func:`lacunarity` (gliding box) returns its own :class:`Lacunarity` result.
"""
from __future__ import annotations

from typing import Callable, Dict

import numpy as np

from fractalgeo_rs.dimension.boxcount import (
    box_counting,
    box_counting_points,
    differential_box_counting,
    self_affine_box_counting,
)
from fractalgeo_rs.dimension.lacunarity import Lacunarity, lacunarity
from fractalgeo_rs.dimension.profile import higuchi, scale_space, wavelet_dimension
from fractalgeo_rs.dimension.spectral import spectral_dimension
from fractalgeo_rs.dimension.surface import blanket, mass_dimension, minkowski
from fractalgeo_rs.dimension.variation import madogram, power_variation, surface_variation, variogram
from fractalgeo_rs.dimension.likelihood import fbm_mle, whittle
from fractalgeo_rs.dimension.gls import gls_dimension
from fractalgeo_rs.fit import DimensionFit

__all__ = [
    "METHODS",
    "Lacunarity",
    "blanket",
    "fbm_mle",
    "higuchi",
    "lacunarity",
    "madogram",
    "mass_dimension",
    "minkowski",
    "power_variation",
    "scale_space",
    "spectral_dimension",
    "surface_variation",
    "variogram",
    "wavelet_dimension",
    "whittle",
    "gls_dimension",
    "box_counting",
    "box_counting_points",
    "differential_box_counting",
    "dimension",
    "self_affine_box_counting",
]

METHODS: Dict[str, Callable[..., DimensionFit]] = {
    "box": box_counting,
    "points": box_counting_points,
    "dbc": differential_box_counting,
    "affine": self_affine_box_counting,
    "minkowski": minkowski,
    "mass": mass_dimension,
    "blanket": blanket,
    "spectral": spectral_dimension,
    "variogram": variogram,
    "madogram": madogram,
    "variation": power_variation,
    "surface_variation": surface_variation,
    "wavelet": wavelet_dimension,
    "scale_space": scale_space,
    "higuchi": higuchi,
    "whittle": whittle,
    "mle": fbm_mle,
    "gls": gls_dimension,
}


# methods defined for one dimensionality of a profile or surface only, and
# what to use on the other
GRAPH_ONLY = {
    "dbc": (2, "variogram', 'madogram', 'variation', 'higuchi', 'spectral' or 'whittle"),
    "blanket": (2, "variogram', 'madogram', 'variation', 'higuchi', 'spectral' or 'whittle"),
    "surface_variation": (2, "variation', 'variogram' or 'madogram"),
    "variation": (1, "surface_variation', 'variogram' or 'madogram"),
    "scale_space": (1, "wavelet', 'spectral', 'surface_variation' or 'whittle"),
    "higuchi": (1, "surface_variation', 'dbc', 'wavelet' or 'whittle"),
}


def dimension(data, method: str = "box", **options) -> DimensionFit:
    """Estimate the fractal dimension of ``data`` with ``method``.

    ``fit.method`` of the result is the key that produced it, so
    ``dimension(data, method=fit.method)`` computes the same fit again. A
    method defined for profiles only (or surfaces only) raises ValueError
    naming the methods to use instead.

    Parameters
    ----------
    data : array_like
        What the method accepts (see the table in this module's docstring).
    method : str, default "box"
        One of ``METHODS``.
    **options
        Keyword options of the method's function (``box_sizes``,
        ``scale_range``, ``n_threads``, ...).

    Returns
    -------
    DimensionFit

    References
    ----------
    Datcu and Seidel (1994), the seed paper; full entry in the :ref:`bibliography <ref-datcu1994>`.

    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> square = np.ones((100, 100), dtype=bool)
    >>> round(fg.dimension(square, method="box").dimension, 3)
    2.0
    """
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"method: expected one of {', '.join(map(repr, METHODS))}, got {method!r}")
    if method in GRAPH_ONLY:
        nd, other = GRAPH_ONLY[method]
        have = np.ndim(data)
        if have in (1, 2) and have != nd:
            kind = {1: "1D profiles", 2: "2D surfaces"}[have]
            raise ValueError(f"method: {method!r} is not defined for {kind}, use '{other}'")
    return METHODS[method](data, **options)
