"""Leaf angle distributions and the projection function G (Ross 1981)."""
from __future__ import annotations

import numbers
from typing import Callable, Dict, Union

import numpy as np

from fractalgeo_rs._validation import check_positive_int, check_seed

__all__ = ["LADS", "leaf_angle_density", "projection_g", "sample_leaf_normals"]

#: The named leaf angle distributions (de Wit 1965, in Bunnik's 1978 form).
LADS = ("planophile", "erectophile", "plagiophile", "extremophile", "uniform", "spherical")

Lad = Union[str, float]

_TWO_PI = 2.0 / np.pi

# density g(theta_L) of the leaf inclination theta_L (radians, normal from the
# vertical) on [0, pi/2], integrating to 1; and its cumulative distribution
_DENSITY: Dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "planophile": lambda t: _TWO_PI * (1.0 + np.cos(2.0 * t)),
    "erectophile": lambda t: _TWO_PI * (1.0 - np.cos(2.0 * t)),
    "plagiophile": lambda t: _TWO_PI * (1.0 - np.cos(4.0 * t)),
    "extremophile": lambda t: _TWO_PI * (1.0 + np.cos(4.0 * t)),
    "uniform": lambda t: np.full_like(t, _TWO_PI),
    "spherical": np.sin,
}
_CDF: Dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "planophile": lambda t: _TWO_PI * (t + np.sin(2.0 * t) / 2.0),
    "erectophile": lambda t: _TWO_PI * (t - np.sin(2.0 * t) / 2.0),
    "plagiophile": lambda t: _TWO_PI * (t - np.sin(4.0 * t) / 4.0),
    "extremophile": lambda t: _TWO_PI * (t + np.sin(4.0 * t) / 4.0),
    "uniform": lambda t: _TWO_PI * t,
    "spherical": lambda t: 1.0 - np.cos(t),
}


def check_lad(lad, name: str = "lad") -> Lad:
    """A named distribution (``LADS``) or one inclination in degrees [0, 90]."""
    if isinstance(lad, str):
        if lad not in _DENSITY:
            raise ValueError(f"{name}: expected one of {', '.join(repr(n) for n in LADS)} or a leaf inclination "
                             f"in degrees, got {lad!r}")
        return lad
    if isinstance(lad, bool) or not isinstance(lad, numbers.Real):
        raise TypeError(f"{name}: expected a distribution name ({', '.join(LADS)}) or a leaf inclination in "
                        f"degrees, got {lad!r}")
    v = float(lad)
    if not 0.0 <= v <= 90.0:
        raise ValueError(f"{name}: expected a leaf inclination in [0, 90] degrees, got {v}")
    return v


def leaf_angle_density(lad, inclination):
    """Density of the leaf inclination (angle of the leaf normal from the
    vertical), per radian, for a named leaf angle distribution.

    ============  =====================================
    name          ``g(theta_L)`` on [0, pi/2]
    ============  =====================================
    planophile    ``(2/pi) (1 + cos 2 theta_L)``
    erectophile   ``(2/pi) (1 - cos 2 theta_L)``
    plagiophile   ``(2/pi) (1 - cos 4 theta_L)``
    extremophile  ``(2/pi) (1 + cos 4 theta_L)``
    uniform       ``2/pi``
    spherical     ``sin theta_L``
    ============  =====================================

    Each integrates to 1 over [0, pi/2]; leaf azimuths are uniform.

    Parameters
    ----------
    lad : str
        One of ``LADS``.
    inclination : float or array_like
        Leaf inclination in degrees, [0, 90].

    Returns
    -------
    float or numpy.ndarray
        ``g(theta_L)`` per radian.

    Raises
    ------
    ValueError
        An unknown ``lad`` or an inclination outside [0, 90] degrees.

    Examples
    --------
    >>> from fractalgeo_rs.canopy import leaf_angle_density
    >>> [round(float(leaf_angle_density("planophile", a)), 6) for a in (0, 45, 90)]
    [1.27324, 0.63662, 0.0]

    References
    ----------
    C. T. de Wit, *Photosynthesis of Leaf Canopies*, Agricultural Research
    Report 663, Pudoc, Wageningen, 1965.
    N. J. J. Bunnik, *The Multispectral Reflectance of Shortwave Radiation by
    Agricultural Crops in Relation with Their Morphological and Optical
    Properties*, Mededelingen Landbouwhogeschool Wageningen 78-1, 1978.
    """
    lad = check_lad(lad)
    if not isinstance(lad, str):
        raise ValueError(f"lad: a single inclination ({lad} degrees) has no density; expected one of "
                         f"{', '.join(repr(n) for n in LADS)}")
    t = np.asarray(inclination, dtype=np.float64)
    if not np.all((t >= 0.0) & (t <= 90.0)):
        raise ValueError("inclination: expected degrees in [0, 90]")
    out = _DENSITY[lad](np.radians(t))
    return float(out) if out.ndim == 0 else out


def _psi(mu: np.ndarray, theta_l: np.ndarray) -> np.ndarray:
    """Ross's kernel: the mean ``|cos|`` between the direction of zenith
    ``arccos(mu)`` and leaf normals of inclination ``theta_l`` (radians)
    with uniform azimuth."""
    mu = np.clip(mu, 0.0, 1.0)
    s = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))
    cl, sl = np.cos(theta_l), np.sin(theta_l)
    a, b = mu * cl, s * sl  # n . w = a + b cos(phi)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(b > a, a / np.where(b > 0, b, 1.0), 1.0)
    phi = np.arccos(np.clip(c, -1.0, 1.0))
    crossing = a + (2.0 / np.pi) * (b * np.sqrt(np.maximum(0.0, 1.0 - c * c)) - a * phi)
    return np.where(b > a, crossing, a)


def projection_g(lad, zenith):
    """Ross's projection function ``G``: the mean projection of unit leaf
    area onto the plane normal to a direction of zenith ``zenith``.

    ``G(theta) = int_0^{pi/2} g(theta_L) psi(theta, theta_L) dtheta_L`` with
    ``psi = cos theta cos theta_L`` when ``theta + theta_L <= 90`` degrees
    and ``cos theta cos theta_L [1 + (2/pi)(tan phi - phi)]``, ``phi =
    arccos(cot theta cot theta_L)``, otherwise (the mean of ``|n . w|`` over
    uniform leaf azimuths). The integral is taken by 64-point Gauss-Legendre
    quadrature on each side of the kink of ``psi`` at ``theta_L = 90 -
    theta``, the upper part in the variable ``sqrt(theta_L - kink)`` (error
    below 1e-13). ``G`` enters Beer's law of the gap
    fraction, ``P_gap = exp(-G LAI / cos theta)``; for every distribution
    its hemispherical mean ``int G sin theta dtheta`` is 1/2.

    Parameters
    ----------
    lad : str or float
        A named distribution (``LADS``: planophile, erectophile,
        plagiophile, extremophile, uniform, spherical) or one leaf
        inclination in degrees (0: horizontal leaves, ``G = cos theta``;
        90: vertical leaves, ``G = (2/pi) sin theta``).
    zenith : float or array_like
        Direction zenith in degrees, [0, 90].

    Returns
    -------
    float or numpy.ndarray
        ``G``, dimensionless, in [0, 1].

    Raises
    ------
    ValueError
        An unknown ``lad`` (naming it) or a zenith outside [0, 90].

    Examples
    --------
    >>> from fractalgeo_rs.canopy import projection_g
    >>> round(projection_g("spherical", 37.0), 12)
    0.5
    >>> round(projection_g(0.0, 60.0), 12)  # horizontal leaves: cos(60)
    0.5
    >>> [round(float(g), 4) for g in projection_g("erectophile", [0.0, 57.5, 90.0])]  # 4/(3 pi) .. 16/(3 pi^2)
    [0.4244, 0.5041, 0.5404]

    References
    ----------
    J. Ross, *The Radiation Regime and Architecture of Plant Stands*, Junk,
    The Hague, 1981 (chapter 6).
    R. B. Myneni, J. Ross and G. Asrar, "A review on the theory of photon
    transport in leaf canopies", *Agric. For. Meteorol.* 45 (1989) 1-153,
    doi:10.1016/0168-1923(89)90002-6.
    """
    lad = check_lad(lad)
    th = np.asarray(zenith, dtype=np.float64)
    if not np.all((th >= 0.0) & (th <= 90.0)):
        raise ValueError(f"zenith: expected degrees in [0, 90], got {zenith!r}")
    mu = np.cos(np.radians(th))
    if not isinstance(lad, str):
        out = _psi(mu, np.full_like(mu, np.radians(lad)))
    else:
        x, w = np.polynomial.legendre.leggauss(64)
        s = (x + 1.0) / 2.0  # nodes on (0, 1), weights w / 2
        kink = np.pi / 2.0 - np.radians(th)  # theta_L where psi changes form
        # below the kink psi is smooth; above it psi - cos cos grows like
        # (theta_L - kink)^(3/2): theta_L = kink + (pi/2 - kink) s^2 makes it smooth
        tl = kink[..., None] * s
        out = kink * np.sum(w / 2.0 * _DENSITY[lad](tl) * _psi(mu[..., None], tl), axis=-1)
        span = (np.pi / 2.0 - kink)[..., None]
        tl = kink[..., None] + span * s * s
        jac = 2.0 * span * s
        out = out + np.sum(w / 2.0 * jac * _DENSITY[lad](tl) * _psi(mu[..., None], tl), axis=-1)
    out = np.clip(out, 0.0, 1.0)
    return float(out) if out.ndim == 0 else out


def _inclinations(lad: Lad, u: np.ndarray) -> np.ndarray:
    """Inclinations (radians) with the distribution's density, from uniforms
    ``u`` by inverting the cumulative distribution (closed form for the
    spherical one, 60 bisection steps otherwise: exact to 1e-16 rad)."""
    if not isinstance(lad, str):
        return np.full_like(u, np.radians(lad))
    if lad == "spherical":
        return np.arccos(1.0 - u)
    if lad == "uniform":
        return u * (np.pi / 2.0)
    cdf = _CDF[lad]
    lo, hi = np.zeros_like(u), np.full_like(u, np.pi / 2.0)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = cdf(mid) < u
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def normals_from_uniforms(lad: Lad, u: np.ndarray) -> np.ndarray:
    """Unit leaf normals (pointing up) from an (n, 2) array of uniforms:
    inclination from ``u[:, 0]``, azimuth ``2 pi u[:, 1]``."""
    t = _inclinations(lad, u[:, 0])
    a = 2.0 * np.pi * u[:, 1]
    st = np.sin(t)
    return np.stack([st * np.sin(a), st * np.cos(a), np.cos(t)], axis=1)


def sample_leaf_normals(lad, n: int, seed=None) -> np.ndarray:
    """Random unit leaf normals with a leaf angle distribution: the
    inclination (angle from the vertical) from ``g(theta_L)``, the azimuth
    uniform.

    Parameters
    ----------
    lad : str or float
        A named distribution (``LADS``) or one inclination in degrees.
    n : int
        Number of normals (> 0).
    seed : int, optional
        Seed of the generator (``numpy.random.default_rng``); None: fresh
        entropy.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Unit normals (east, north, up), ``up >= 0``.

    Raises
    ------
    ValueError
        An unknown ``lad``, ``n`` not positive.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.canopy import sample_leaf_normals
    >>> nrm = sample_leaf_normals("spherical", 200_000, seed=1)
    >>> nrm.shape, bool(abs(np.abs(nrm[:, 2]).mean() - 0.5) < 0.005)  # G(0) = 0.5
    ((200000, 3), True)

    References
    ----------
    C. T. de Wit, 1965; N. J. J. Bunnik, 1978 (see ``leaf_angle_density``).
    """
    lad = check_lad(lad)
    n = check_positive_int(n, "n")
    rng = np.random.default_rng(check_seed(seed))
    return normals_from_uniforms(lad, rng.random((n, 2)))


