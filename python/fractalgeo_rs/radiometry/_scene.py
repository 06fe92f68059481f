"""Scenes, reflectance models and estimators of the radiometric experiment
(kernels in ``rust/radiometry``)."""
from __future__ import annotations

import math
import numbers
import os
import warnings
import weakref
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import (
    as_array,
    check_choice,
    check_memory,
    check_n_threads,
    check_positive_float,
    check_positive_int,
    warn_void_sentinel,
)
from fractalgeo_rs._warn import user_stacklevel
from fractalgeo_rs.radiometry._leaf import BiLambertian

__all__ = ["BrfSweep", "Estimate", "Hapke", "Lambertian", "OrenNayar", "Phong", "Scene", "Specular"]

#: Sun zeniths (degrees) of the paper's incidence series (figure 9), 0 to 90 in steps of 15, the
#: grazing 90 taken as 89 (at 90 the horizontal irradiance and the BRF's denominator are 0).
PAPER_SUN_ZENITHS = (0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 89.0)

#: The largest ``max_depth`` the kernel accepts.
MAX_DEPTH = 100_000


def _reflectance(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number in [0, 1], got {value!r}")
    v = float(value)
    if not 0.0 <= v <= 1.0:
        raise ValueError(f"{name}: expected a reflectance in [0, 1], got {v}")
    return v


@dataclass(frozen=True)
class Lambertian:
    """A perfectly diffuse facet: BRDF ``f = rho / pi``.

    Parameters
    ----------
    rho : float
        Reflectance (albedo) in [0, 1].

    Examples
    --------
    >>> from fractalgeo_rs.radiometry import Lambertian
    >>> Lambertian(0.25)
    Lambertian(rho=0.25)

    References
    ----------
    J. H. Lambert, *Photometria*, 1760. A flat Lambertian plane has BRF and
    albedo equal to ``rho`` for every sun and view direction.
    """

    rho: float

    def __post_init__(self):
        object.__setattr__(self, "rho", _reflectance(self.rho, "rho"))

    def _spec(self) -> Tuple[str, List[float]]:
        return "lambertian", [self.rho]


@dataclass(frozen=True)
class OrenNayar:
    """The Oren-Nayar model of a rough diffuse facet: qualitative, or the
    full 1994 model with the interreflection term.

    Qualitative (``full=False``, equation 30):
    ``f = rho/pi (A + B max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta))`` with
    ``A = 1 - 0.5 s^2/(s^2 + 0.33)``, ``B = 0.45 s^2/(s^2 + 0.09)``,
    ``alpha = max(theta_i, theta_o)``, ``beta = min(theta_i, theta_o)``.

    Full (``full=True``, equations 27-29 and the interreflection term of
    section 4.4): with ``c = cos(phi_i - phi_o)``,
    ``f = rho/pi [C1 + c C2 tan(beta) + (1 - |c|) C3 tan((alpha + beta)/2)]
    + 0.17 rho^2/pi s^2/(s^2 + 0.13) (1 - c (2 beta/pi)^2)``,
    ``C1 = A``, ``C2 = 0.45 s^2/(s^2 + 0.09) sin(alpha)`` for ``c >= 0`` and
    ``0.45 s^2/(s^2 + 0.09) (sin(alpha) - (2 beta/pi)^3)`` otherwise,
    ``C3 = 0.125 s^2/(s^2 + 0.09) (4 alpha beta/pi^2)^2``. The full model
    reflects slightly more light than it receives at grazing incidence when
    ``rho`` is near 1 (1.04 times at ``rho = 1, sigma = 0.3``, zenith 89
    degrees): such parameters raise ``ValueError`` naming ``rho`` when a
    scene uses them (the albedo is checked by quadrature at 12 zeniths).

    Both are reciprocal and sampled cosine-weighted; ``sigma = 0`` is
    Lambertian.

    Parameters
    ----------
    rho : float
        Reflectance in [0, 1].
    sigma : float
        Standard deviation of the micro-facet slope angle, radians (>= 0).
    full : bool
        The full model with the interreflection term (default False: the
        qualitative model).

    Examples
    --------
    >>> from fractalgeo_rs.radiometry import OrenNayar
    >>> OrenNayar(0.5, sigma=0.3).sigma
    0.3
    >>> OrenNayar(0.5, sigma=0.3, full=True).full
    True

    References
    ----------
    M. Oren and S. K. Nayar, "Generalization of Lambert's reflectance
    model", *SIGGRAPH '94*, 239-246, 1994, doi:10.1145/192161.192213
    (equations 27-30).
    """

    rho: float
    sigma: float
    full: bool = False

    def __post_init__(self):
        object.__setattr__(self, "rho", _reflectance(self.rho, "rho"))
        if not isinstance(self.full, (bool, np.bool_)):
            raise TypeError(f"full: expected True or False, got {self.full!r}")
        object.__setattr__(self, "full", bool(self.full))
        s = self.sigma
        if isinstance(s, bool) or not isinstance(s, numbers.Real):
            raise TypeError(f"sigma: expected a number of radians >= 0, got {s!r}")
        if not (math.isfinite(float(s)) and float(s) >= 0.0):
            raise ValueError(f"sigma: expected a slope standard deviation >= 0 in radians, got {s}")
        object.__setattr__(self, "sigma", float(s))

    def _spec(self) -> Tuple[str, List[float]]:
        return ("oren-nayar-full" if self.full else "oren-nayar"), [self.rho, self.sigma]


@dataclass(frozen=True)
class Phong:
    """The energy-normalised (modified) Phong model: a diffuse part and a
    lobe around the mirror direction.

    ``f = kd/pi + ks (n + 2)/(2 pi) cos^n(alpha)``, ``alpha`` the angle
    between the incident direction and the mirror image of the outgoing one.
    Reciprocal; the albedo is at most ``kd + ks`` (equal at normal
    incidence). Sampled as a mixture of the two parts.

    Parameters
    ----------
    kd : float
        Diffuse reflectance in [0, 1].
    ks : float
        Specular reflectance in [0, 1], with ``kd + ks <= 1``.
    exponent : float
        Phong exponent ``n`` (>= 0; larger is glossier).

    Examples
    --------
    >>> from fractalgeo_rs.radiometry import Phong
    >>> Phong(0.3, 0.2, exponent=20.0)
    Phong(kd=0.3, ks=0.2, exponent=20.0)

    References
    ----------
    E. P. Lafortune and Y. D. Willems, "Using the modified Phong reflectance
    model for physically based rendering", Report CW 197, KU Leuven, 1994.
    """

    kd: float
    ks: float
    exponent: float

    def __post_init__(self):
        kd, ks = _reflectance(self.kd, "kd"), _reflectance(self.ks, "ks")
        if kd + ks > 1.0:
            raise ValueError(f"ks: expected kd + ks <= 1 (energy), got {kd} + {ks}")
        n = self.exponent
        if isinstance(n, bool) or not isinstance(n, numbers.Real) or not (math.isfinite(float(n)) and n >= 0):
            raise ValueError(f"exponent: expected a finite number >= 0, got {n!r}")
        object.__setattr__(self, "kd", kd)
        object.__setattr__(self, "ks", ks)
        object.__setattr__(self, "exponent", float(n))

    def _spec(self) -> Tuple[str, List[float]]:
        return "phong", [self.kd, self.ks, self.exponent]


def _unit_param(value, name: str, upper_open: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a number in [0, 1{')' if upper_open else ']'}, got {value!r}")
    v = float(value)
    if not (0.0 <= v < 1.0 if upper_open else 0.0 <= v <= 1.0):
        raise ValueError(f"{name}: expected a number in [0, 1{')' if upper_open else ']'}, got {v}")
    return v


@dataclass(frozen=True)
class Hapke:
    """Hapke's model of a particulate, rough surface (the parametrisation of
    Eradiate's ``hapke`` BSDF).

    ``BRF = w/4 mu0e/(mu0e + mue)/mu0 [P(g)(1 + B(g)) + H(mu0e) H(mue) - 1] S``
    with ``P = (1 - c) HG(-b) + c HG(b)`` (double Henyey-Greenstein, ``c`` the
    back-scattered fraction, ``g`` the phase angle), ``B = B0/(1 + tan(g/2)/h)``
    (the shadow-hiding opposition surge), Hapke's (2002) approximation of the
    H-function, and the roughness correction (``mu0e``, ``mue``, ``S``) of
    Hapke (1984) for a mean facet slope ``theta_bar``. The BRDF is
    ``BRF / pi``.

    Finite everywhere: with ``h = 0`` the surge is ``B0`` at exact
    backscatter (its limit there for every ``h > 0``) and 0 elsewhere
    (Eradiate returns NaN there). Reciprocal. Hapke's model does not
    conserve energy for bright back-scattering surfaces (``w = 1, b = 0.7,
    c = 1`` reflects up to 1.46 times the incident flux), so parameters whose
    directional albedo exceeds 1 at some sun zenith raise ``ValueError``
    (naming ``w``) when a scene uses them. Sampled cosine-weighted.

    Agrees with Eradiate 0.5.0's ``hapke`` BSDF to 5e-7 at its reference
    directions (tested).

    Parameters
    ----------
    w : float
        Single-scattering albedo in [0, 1].
    b : float
        Henyey-Greenstein asymmetry in [0, 1).
    c : float
        Back-scattered fraction of the phase function in [0, 1].
    theta_bar : float
        Mean slope angle of the macroscopic roughness, degrees in [0, 90).
    B0 : float
        Amplitude of the opposition surge in [0, 1].
    h : float
        Angular width of the opposition surge in [0, 1].

    Examples
    --------
    >>> from fractalgeo_rs.radiometry import Hapke
    >>> Hapke(w=0.5, b=0.2, c=0.4, theta_bar=15.0, B0=1.0, h=0.05)
    Hapke(w=0.5, b=0.2, c=0.4, theta_bar=15.0, B0=1.0, h=0.05)

    References
    ----------
    B. Hapke, "Bidirectional reflectance spectroscopy 3. Correction for
    macroscopic roughness", *Icarus* 59, 41-59, 1984,
    doi:10.1016/0019-1035(84)90054-X (equations 45-58).
    B. Hapke, "Bidirectional reflectance spectroscopy 5. The coherent
    backscatter opposition effect and anisotropic scattering", *Icarus* 157,
    523-534, 2002, doi:10.1006/icar.2002.6853 (equation 13).
    Eradiate, ``hapke`` BSDF, https://eradiate.readthedocs.io.
    """

    w: float
    b: float
    c: float
    theta_bar: float
    B0: float
    h: float

    def __post_init__(self):
        object.__setattr__(self, "w", _unit_param(self.w, "w"))
        object.__setattr__(self, "b", _unit_param(self.b, "b", upper_open=True))
        object.__setattr__(self, "c", _unit_param(self.c, "c"))
        object.__setattr__(self, "B0", _unit_param(self.B0, "B0"))
        object.__setattr__(self, "h", _unit_param(self.h, "h"))
        t = self.theta_bar
        if isinstance(t, bool) or not isinstance(t, numbers.Real) or not (math.isfinite(float(t))
                                                                         and 0.0 <= float(t) < 90.0):
            raise ValueError(f"theta_bar: expected a mean slope angle in [0, 90) degrees, got {t!r}")
        object.__setattr__(self, "theta_bar", float(t))

    def _spec(self) -> Tuple[str, List[float]]:
        return "hapke", [self.w, self.b, self.c, self.theta_bar, self.B0, self.h]


@dataclass(frozen=True)
class Specular:
    """A smooth mirror facet with unpolarised Fresnel reflectance.

    Light leaves only along the mirror direction, with the fraction
    ``F(cos theta)`` of a medium of complex relative refractive index
    ``eta + i k`` (``k = 0``: a dielectric such as water, 1.33; ``k > 0``: a
    conductor). The BRDF is a Dirac delta: the directional sun reaches the
    sensor from a mirror facet only after another scattering event, and a
    flat mirror's BRF is 0 (its albedo is ``F``). Reciprocal and
    energy-bounded (``F <= 1``).

    Parameters
    ----------
    eta : float
        Real part of the relative refractive index (> 0).
    k : float
        Extinction coefficient (>= 0).

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.radiometry import Scene, Specular
    >>> s = Scene.from_dem(np.zeros((4, 4)), material=Specular(1.5))
    >>> round(s.albedo(sun=(0.0, 0.0), spp=10).value, 9)  # ((1.5 - 1) / (1.5 + 1))**2
    0.04

    References
    ----------
    M. Born and E. Wolf, *Principles of Optics*, 7th ed., Cambridge
    University Press, 1999, section 1.5 (Fresnel formulae).
    """

    eta: float
    k: float = 0.0

    def __post_init__(self):
        for name, lo_open in (("eta", True), ("k", False)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, numbers.Real):
                raise TypeError(f"{name}: expected a number, got {v!r}")
            v = float(v)
            if not math.isfinite(v) or (v <= 0.0 if lo_open else v < 0.0):
                raise ValueError(f"{name}: expected a finite number {'> 0' if lo_open else '>= 0'}, got {v}")
            object.__setattr__(self, name, v)

    def _spec(self) -> Tuple[str, List[float]]:
        return "specular", [self.eta, self.k]


Material = Union[Lambertian, OrenNayar, Phong, Hapke, Specular, BiLambertian]
_MATERIAL_TYPES = (Lambertian, OrenNayar, Phong, Hapke, Specular, BiLambertian)

#: Per-facet material choice: an integer array (one index into the material
#: list per facet) or a function ``f(slope, height)`` of the facets' slopes
#: (degrees) and centroid heights returning one.
MaterialIds = Union[np.ndarray, Sequence[int], Callable[[np.ndarray, np.ndarray], Any]]


def _materials(value, name: str = "material") -> Tuple[Material, ...]:
    """One material or a non-empty sequence of them, as a tuple."""
    if isinstance(value, _MATERIAL_TYPES):
        return (value,)
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{name}: expected a material (Lambertian(...), OrenNayar(...), Phong(...), Hapke(...) "
                        f"or Specular(...)) or a list of them, got {value!r}")
    out = tuple(value)
    if not out:
        raise ValueError(f"{name}: expected at least one material, got an empty list")
    for k, m in enumerate(out):
        if not isinstance(m, _MATERIAL_TYPES):
            raise TypeError(f"{name}: item {k} is not a material (Lambertian(...), OrenNayar(...), Phong(...), "
                            f"Hapke(...) or Specular(...)): {m!r}")
    return out


def _material_ids(value, n_materials: int, slope: Callable[[], np.ndarray], height: Callable[[], np.ndarray],
                  shape: Tuple[int, ...]) -> Optional[np.ndarray]:
    """``material_ids`` as a flat uint32 array of one index per facet (None:
    every facet material 0). ``slope`` and ``height`` compute the facets'
    slopes (degrees) and centroid heights, arrays of ``shape``, for a
    callable."""
    if value is None:
        if n_materials > 1:
            raise ValueError(f"material_ids: {n_materials} materials need material_ids (an index per facet, or "
                             "a function of slope and height), got None")
        return None
    if callable(value):
        value = value(slope(), height())
    a = np.asarray(value)
    if a.dtype.kind == "b":
        a = a.astype(np.int64)
    if a.dtype.kind not in "iu":
        raise TypeError(f"material_ids: expected integer material indices, got dtype {a.dtype}")
    n = int(np.prod(shape))
    if a.size != n or (a.ndim > 1 and a.shape != shape):
        raise ValueError(f"material_ids: expected one index per facet, shape {shape} ({n} facets), got shape "
                         f"{a.shape}")
    a = a.reshape(-1)
    bad = (a < 0) | (a >= n_materials)
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(f"material_ids: facet {k} has material index {int(a[k])}, but there are {n_materials} "
                         f"material(s) (indices 0 to {n_materials - 1})")
    return np.ascontiguousarray(a, dtype=np.uint32)


def _dem_facets(z: np.ndarray, cell_size: Tuple[float, float], periodic: bool,
                split: str) -> Tuple[np.ndarray, np.ndarray]:
    """Slope (degrees) and centroid height of every facet of a DEM scene,
    shape ``(cell rows, cell cols, 2)`` in the kernel's facet order."""
    zz = np.pad(z, ((0, 1), (0, 1)), mode="wrap") if periodic else z
    nw, ne, sw, se = zz[:-1, :-1], zz[:-1, 1:], zz[1:, :-1], zz[1:, 1:]
    if split == "ne-sw":
        tris = ((nw, ne, sw), (ne, se, sw))
        grads = ((ne - nw, sw - nw), (se - sw, se - ne))
    else:
        tris = ((nw, ne, se), (nw, se, sw))
        grads = ((ne - nw, se - ne), (se - sw, sw - nw))
    dy, dx = cell_size
    slope = np.stack([np.degrees(np.arctan(np.hypot(b / dx, c / dy))) for b, c in grads], axis=-1)
    height = np.stack([(a + b + c) / 3.0 for a, b, c in tris], axis=-1)
    return slope, height


def _mesh_facets(mesh) -> Tuple[np.ndarray, np.ndarray]:
    """Slope (degrees, of the unoriented facet) and centroid height (map
    z) of every triangle of a mesh."""
    v = np.asarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    p0, p1, p2 = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    n = np.cross(p1 - p0, p2 - p0)
    length = np.linalg.norm(n, axis=1)
    cos = np.divide(np.abs(n[:, 2]), length, out=np.ones_like(length), where=length > 0)
    slope = np.degrees(np.arccos(np.clip(cos, 0.0, 1.0)))
    height = (p0[:, 2] + p1[:, 2] + p2[:, 2]) / 3.0 + float(mesh.origin[2])
    return slope, height


def _extent(value) -> Optional[Tuple[float, float, float, float]]:
    if value is None:
        return None
    try:
        x0, y0, w, h = (float(v) for v in value)
    except (TypeError, ValueError):
        raise TypeError(f"extent: expected (x0, y0, width, height) in map coordinates, got {value!r}") from None
    if not all(math.isfinite(v) for v in (x0, y0, w, h)) or w <= 0 or h <= 0:
        raise ValueError(f"extent: expected finite (x0, y0, width, height) with width, height > 0, got {value!r}")
    return (x0, y0, w, h)


@dataclass(frozen=True)
class Estimate:
    """A Monte Carlo estimate and its standard error.

    Attributes
    ----------
    value : float
        The sample mean.
    se : float
        Its standard error: for ``albedo`` and ``bhr`` the sample standard
        deviation / sqrt(n); for ``brf`` the spread of the means of its
        independently scrambled quasi-Monte Carlo replicates / sqrt(number
        of replicates). 0 (``albedo``) or 1e-12 of the value (``brf``, the
        rounding of the sums) when every path gives the same value (e.g. a
        flat Lambertian plane).
    n : int
        Number of paths.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.radiometry import Scene
    >>> e = Scene.from_dem(np.zeros((4, 4))).albedo(sun=(0.0, 30.0), spp=100)
    >>> (round(e.value, 6), e.se, e.n)
    (0.5, 0.0, 100)

    References
    ----------
    E. Veach, *Robust Monte Carlo Methods for Light Transport Simulation*,
    PhD thesis, Stanford University, 1997 (chapter 2).
    """

    value: float
    se: float
    n: int


@dataclass(frozen=True)
class ScatteringOrders:
    """A reflectance factor split by scattering order (``Scene.brf_orders``).

    The three estimates come from the same paths: per path, ``single`` is
    its first-order next-event estimate of the sun (plus, with a sky, the
    sky light of paths that leave after one scattering event), ``total``
    the whole path and ``multiple`` their difference, so ``single.value +
    multiple.value == total.value`` to rounding and each standard error is
    that of its own per-path values (not a sum of standard errors).

    Attributes
    ----------
    single : Estimate
        Light scattered once; equals ``Scene.brf(..., max_depth=1)`` with
        the same seed exactly.
    multiple : Estimate
        Light scattered 2 to ``max_depth`` times.
    total : Estimate
        All orders; equals ``Scene.brf(...)`` with the same arguments
        exactly.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.radiometry import Lambertian, Scene
    >>> o = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.3)).brf_orders(sun=(0.0, 30.0), spp=100)
    >>> round(o.single.value, 9), o.multiple.value, o.multiple.se   # a plane scatters once
    (0.3, 0.0, 0.0)

    References
    ----------
    J. Ross, *The Radiation Regime and Architecture of Plant Stands*, Junk,
    The Hague, 1981 (single and multiple scattering in canopies).
    """

    single: Estimate
    multiple: Estimate
    total: Estimate


@dataclass(frozen=True)
class BrfSweep:
    """BRFs over a grid of sun and view zenith angles (``Scene.brf_sweep``).

    Attributes
    ----------
    sun_zenith : numpy.ndarray, shape (n_sun,)
        Sun zenith angles, degrees.
    view_zenith : numpy.ndarray, shape (n_view,)
        View zenith angles, degrees.
    sun_azimuth, view_azimuth : float
        The azimuths (degrees clockwise from north) of every sun and view
        direction.
    value : numpy.ndarray, shape (n_sun, n_view)
        BRF estimates; ``value[i, j]`` for ``sun_zenith[i]``,
        ``view_zenith[j]``.
    se : numpy.ndarray, shape (n_sun, n_view)
        Their Monte Carlo standard errors.
    n : int
        Paths per estimate.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.radiometry import Lambertian, Scene
    >>> sw = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.3)).brf_sweep(
    ...     sun_zenith=[0, 45], view_zenith=[0, 30], spp=100)
    >>> sw.value.shape, bool(np.allclose(sw.value, 0.3))
    ((2, 2), True)

    References
    ----------
    F. E. Nicodemus et al., NBS Monograph 160, 1977 (see ``Scene.brf``).
    """

    sun_zenith: np.ndarray
    view_zenith: np.ndarray
    sun_azimuth: float
    view_azimuth: float
    value: np.ndarray
    se: np.ndarray
    n: int


def _direction(value, name: str) -> Tuple[float, float]:
    """``(azimuth, zenith)`` in degrees, zenith in [0, 90)."""
    if isinstance(value, str) and value == "nadir":
        return (0.0, 0.0)
    try:
        az, zen = value
        az, zen = float(az), float(zen)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected (azimuth, zenith) in degrees, got {value!r}") from None
    if not (math.isfinite(az) and math.isfinite(zen)):
        raise ValueError(f"{name}: expected finite (azimuth, zenith) in degrees, got {value!r}")
    if not 0.0 <= zen < 90.0:
        raise ValueError(f"{name}: zenith must be in [0, 90) degrees (above the horizon), got {zen}")
    return (az, zen)


def _sky(value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"sky: expected a horizontal sky irradiance >= 0 (a number), got {value!r}")
    v = float(value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"sky: expected a finite sky irradiance >= 0, got {v}")
    return v


def _psf(value, step) -> Tuple[str, List[float], Optional[np.ndarray]]:
    """``(kind, params, table)`` for the kernel from the ``psf`` argument."""
    if isinstance(value, str):
        if value != "box":
            raise ValueError(f"psf: expected 'box', ('gaussian', sigma) or an array of weights, got {value!r}")
        return "box", [], None
    if isinstance(value, tuple) and value and isinstance(value[0], str):
        if value[0] != "gaussian" or len(value) not in (2, 3):
            raise ValueError(f"psf: expected ('gaussian', sigma) or ('gaussian', sigma, truncate), got {value!r}")
        sigma = check_positive_float(value[1], "psf")
        truncate = check_positive_float(value[2], "psf") if len(value) == 3 else 4.0
        return "gaussian", [sigma, truncate], None
    w = as_array(value, "psf")
    if w.ndim != 2 or w.size == 0 or w.dtype.kind not in "iuf":
        raise ValueError(f"psf: expected 'box', ('gaussian', sigma) or a non-empty 2D array of weights, "
                         f"got {value!r}")
    w = np.array(w, dtype=np.float64)
    if not np.all(np.isfinite(w)) or (w < 0).any() or w.sum() <= 0:
        raise ValueError("psf: expected finite weights >= 0 with a positive sum")
    return "table", [check_positive_float(step, "psf_step")], w


def _point(value, name: str) -> Tuple[float, float, float]:
    try:
        x, y, z = (float(v) for v in value)
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected (x, y, z), got {value!r}") from None
    if not all(math.isfinite(v) for v in (x, y, z)):
        raise ValueError(f"{name}: expected finite (x, y, z), got {value!r}")
    return (x, y, z)


def _depth(value) -> int:
    d = check_positive_int(value, "max_depth")
    if d > MAX_DEPTH:
        raise ValueError(f"max_depth: expected at most {MAX_DEPTH}, got {d}")
    return d


def _spp(value) -> int:
    """Paths of one estimate; the kernel keeps one partial sum (at most 40
    bytes) per block of up to 1024 paths (of each replicate of the BRF),
    checked against the memory limit before the call."""
    n = check_positive_int(value, "spp")
    check_memory((-(-n // 1024) + 16) * 40, "spp", what=f"spp={n} paths (40 bytes per block of 1024)")
    return n


def _seed(value) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not 0 <= int(value) < 2**64:
        raise ValueError(f"seed: expected an int in [0, 2**64), got {value!r}")
    return int(value)


def _cell_size(value) -> Tuple[float, float]:
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        v = check_positive_float(value, "cell_size")
        return (v, v)
    try:
        dy, dx = value
    except (TypeError, ValueError):
        raise TypeError(f"cell_size: expected a number or (row spacing, column spacing), got {value!r}") from None
    return (check_positive_float(dy, "cell_size"), check_positive_float(dx, "cell_size"))


def _edge_mismatch(z: np.ndarray) -> Optional[str]:
    """A description of the opposite edges of a periodic tile that do not
    join smoothly: the RMS step across the wrap (last row to first row, last
    column to first column) is compared with the RMS step between neighbours
    inside the tile; more than 3 times (and above 1e-9 of the relief) is a
    mismatch."""
    relief = float(np.ptp(z)) if z.size else 0.0
    out = []
    for axis, edge in ((0, "north-south"), (1, "east-west")):
        if z.shape[axis] < 3:
            continue
        inner = np.diff(z, axis=axis)
        wrap = np.take(z, 0, axis=axis) - np.take(z, -1, axis=axis)
        rms_in = float(np.sqrt(np.mean(inner ** 2)))
        rms_wrap = float(np.sqrt(np.mean(wrap ** 2)))
        if rms_wrap > 3.0 * rms_in and rms_wrap > 1e-9 * max(relief, 1.0):
            out.append(f"{edge} edges: RMS step across the wrap {rms_wrap:.4g} vs {rms_in:.4g} inside")
    return "; ".join(out) or None


class Scene:
    """A triangulated surface with a reflectance model, lit by a
    directional sun and seen by an orthographic sensor.

    Build one with ``from_dem``. Directions are ``(azimuth, zenith)`` in
    degrees: azimuth clockwise from north, zenith from the vertical, both
    pointing away from the surface (towards the sun or the sensor); the
    string ``"nadir"`` is ``(0, 0)``. The sun's irradiance is 1 on a plane
    normal to the beam.

    Attributes
    ----------
    dem : numpy.ndarray
        The heights (float64, read-only copy), metres; row 0 is north,
        columns go east.
    cell_size : tuple of float
        ``(dy, dx)``: row spacing (north-south) and column spacing
        (east-west), in the unit of the heights; numpy's axis order, as
        every ``cell_size`` pair of the package.
    periodic : bool
        Whether the DEM is one tile of an infinite periodic surface.
    material : Lambertian, OrenNayar, Phong, Hapke or Specular
        The reflectance model of every facet.
    split : str
        The diagonal that splits each cell: ``"ne-sw"`` or ``"nw-se"``.
    profile : dict or None
        The DEM's georeferencing (a rasterio profile with ``crs`` and
        ``transform``), kept for ``save_image``.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.radiometry import Lambertian, Scene
    >>> x = np.arange(8)
    >>> grooves = np.where(x % 2 == 1, np.tan(np.radians(30)), 0.0)[None, :].repeat(8, 0)
    >>> s = Scene.from_dem(grooves, material=Lambertian(1.0))
    >>> e = s.brf(sun=(90.0, 40.0), spp=20000, max_depth=1)  # rho cos(30 deg) = 0.866
    >>> bool(abs(e.value - np.cos(np.radians(30))) < 4 * e.se)
    True

    References
    ----------
    M. Datcu and K. Seidel, "Fractal and multiresolution techniques for the
    understanding of geo-information", in *Fractals in Geoscience and Remote
    Sensing*, JRC/EARSeL, 1995 (section 4.1).
    J. Amanatides and A. Woo, "A fast voxel traversal algorithm for ray
    tracing", *Eurographics '87*, 3-10, 1987.
    """

    def __init__(self, dem: Optional[np.ndarray], cell_size: Optional[Tuple[float, float]], periodic: bool,
                 material: Material, split: str, profile: Optional[dict] = None, *,
                 materials: Optional[Tuple[Material, ...]] = None, material_ids: Optional[np.ndarray] = None,
                 mesh=None, extent: Optional[Tuple[float, float, float, float]] = None, core=None):
        self.profile = profile
        # images returned by render_perspective (id -> weak reference): not maps, so
        # save_image does not georeference them
        self._perspective: Dict[int, weakref.ref] = {}
        self.dem = dem
        self.cell_size = cell_size
        self.periodic = periodic
        self.material = material
        #: All materials (``material`` is the first); facet ``k`` has
        #: ``materials[material_ids[k]]``.
        self.materials = materials if materials is not None else (material,)
        #: One material index per facet (uint32), or None (all ``material``).
        self.material_ids = material_ids
        #: The :class:`~fractalgeo_rs.geometry.Mesh` of a mesh scene, else None.
        self.mesh = mesh
        #: ``(x0, y0, width, height)``: a mesh scene's tile or footprint, map coordinates.
        self.extent = extent
        self._core = core
        # a one-material DEM scene builds its kernel scene on first use and
        # keeps it (keyed by what it was built from, so changed attributes
        # rebuild it); other scenes get theirs at construction
        self._lazy_core = core is None
        self._core_key: Optional[tuple] = None
        self.split = split

    def __getstate__(self) -> dict:
        # the perspective images' weak references are per process: not pickled;
        # nor is a lazily built kernel scene (rebuilt on first use)
        state = dict(self.__dict__)
        state["_perspective"] = {}
        if state.get("_lazy_core", False):
            state["_core"], state["_core_key"] = None, None
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self.__dict__.setdefault("_perspective", {})

    def __repr__(self) -> str:
        if self.dem is None and self.mesh is None:
            return (f"Scene(instances, extent={self.extent}, periodic={self.periodic}, "
                    f"materials={list(self.materials)!r})")
        if self.mesh is not None:
            return (f"Scene(mesh of {len(self.mesh)} triangles, extent={self.extent}, periodic={self.periodic}, "
                    f"materials={list(self.materials)!r})")
        dem = self._dem()
        if len(self.materials) > 1:
            return (f"Scene({dem.shape[0]} x {dem.shape[1]} heights, cell_size={self.cell_size}, "
                    f"periodic={self.periodic}, materials={list(self.materials)!r}, split={self.split!r})")
        return (f"Scene({dem.shape[0]} x {dem.shape[1]} heights, cell_size={self.cell_size}, "
                f"periodic={self.periodic}, material={self.material!r}, split={self.split!r})")

    @classmethod
    def from_dem(cls, dem, cell_size: Union[float, Tuple[float, float]] = 1.0, periodic: bool = True,
                 material: Union[None, Material, Sequence[Material]] = None, split: str = "ne-sw",
                 profile: Optional[dict] = None, material_ids: Optional[MaterialIds] = None) -> "Scene":
        """A scene of two triangular facets per DEM cell.

        Vertex ``(r, c)`` sits at ``x = c * dx`` east, ``y = -r * dy``
        north, height ``dem[r, c]``. With ``split="ne-sw"`` the
        facets of a cell are (NW, SW, NE) and (NE, SW, SE), counter-clockwise
        seen from above, so normals point up.

        Parameters
        ----------
        dem : array_like, shape (rows, cols)
            Heights in the same unit as ``cell_size``; NaN is an error.
        cell_size : float or (float, float)
            Cell side, or ``(dy, dx)``: row spacing (north-south) and column
            spacing (east-west), > 0, in the unit of the heights (numpy's axis
            order, as every ``cell_size`` pair of the package, e.g. the
            ``info["cell_size"]`` of the bundled geographic DEMs, in metres).
        periodic : bool
            True: the DEM is one period of an infinite surface, ``rows x
            cols`` cells, the sample after the last column (row) being the
            first column (row); rays leaving one side re-enter the opposite
            one. A ``UserWarning`` names the edges whose step across the wrap
            is more than 3 times the typical step inside the tile: make a
            real DEM tileable by mirroring it, e.g.
            ``np.block([[z, z[:, ::-1]], [z[::-1], z[::-1, ::-1]]])``.
            False: a finite patch of ``(rows - 1) x (cols - 1)`` cells; rays
            that leave it escape.
        material : Lambertian, OrenNayar, Phong, Hapke or Specular, or a list of them, optional
            Reflectance model of every facet; default ``Lambertian(0.5)``.
            A list: per-facet materials chosen by ``material_ids``.
        split : {"ne-sw", "nw-se"}
            The diagonal splitting each cell.
        profile : dict, optional
            Georeferencing of the DEM as :func:`fractalgeo_rs.read_raster`
            returns it (``crs``, ``transform``: heights at pixel centres);
            ``save_image`` then writes georeferenced GeoTIFF and PNG.
        material_ids : array_like of int or callable, optional
            The material (index into ``material``) of every facet: an array
            of shape ``(cell rows, cell cols, 2)`` (the two facets of each
            cell, as ordered by ``split``; cell rows and columns as in
            ``periodic``), or a function ``f(slope, height)`` of arrays of
            that shape (facet slope in degrees, centroid height) returning
            one. Required with several materials.

        Returns
        -------
        Scene

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Scene
        >>> Scene.from_dem(np.zeros((4, 5)), cell_size=30.0)
        Scene(4 x 5 heights, cell_size=(30.0, 30.0), periodic=True, material=Lambertian(rho=0.5), split='ne-sw')

        Dark facets steeper than 20 degrees, bright ones elsewhere:

        >>> from fractalgeo_rs.radiometry import Lambertian
        >>> z = np.add.outer(np.zeros(8), np.abs(np.arange(8) - 4.0))  # V-valley, 45 degree sides
        >>> s = Scene.from_dem(z, material=[Lambertian(0.8), Lambertian(0.1)],
        ...                    material_ids=lambda slope, height: slope > 20, periodic=False)
        >>> s.material_ids.reshape(7, 7, 2)[0, :, 0].tolist()
        [1, 1, 1, 1, 1, 1, 1]

        References
        ----------
        M. Datcu and K. Seidel, 1995 (see ``Scene``).
        """
        z = as_array(dem, "dem")
        if z.ndim != 2:
            raise ValueError(f"dem: expected a 2D array of heights, got {z.ndim} dimension(s)")
        if z.dtype.kind not in "iuf":
            raise TypeError(f"dem: expected real heights, got dtype {z.dtype}")
        z = np.array(z, dtype=np.float64, copy=True)
        warn_void_sentinel(z, "dem", hint="fill them first (e.g. rasterio.fill.fillnodata)")
        bad = ~np.isfinite(z)
        if bad.any():
            r, c = np.argwhere(bad)[0]
            raise ValueError(f"dem: expected finite heights, got {int(bad.sum())} NaN value(s) "
                             f"(first at row {r}, column {c}); fill them first")
        if not isinstance(periodic, (bool, np.bool_)):
            raise TypeError(f"periodic: expected True or False, got {periodic!r}")
        periodic = bool(periodic)
        need = 1 if periodic else 2
        if z.shape[0] < need or z.shape[1] < need:
            raise ValueError(f"dem: expected at least {need} x {need} heights, got {z.shape}")
        cell_size = _cell_size(cell_size)
        if material is None:
            material = Lambertian(0.5)
        per_facet = isinstance(material, (list, tuple)) or material_ids is not None
        if per_facet:
            materials = _materials(material)
            material = materials[0]
        elif not isinstance(material, (Lambertian, OrenNayar, Phong, Hapke, Specular)):
            raise TypeError("material: expected Lambertian(...), OrenNayar(...), Phong(...), Hapke(...) or Specular(...), "
                            f"got {material!r}")
        split = check_choice(split, "split", ("ne-sw", "nw-se"))
        if periodic:
            mismatch = _edge_mismatch(z)
            if mismatch:
                warnings.warn(f"dem: periodic=True but opposite edges do not match ({mismatch}); the "
                              "wrap adds a cliff. Mirror the DEM to make it tileable, or pass periodic=False",
                              UserWarning, stacklevel=user_stacklevel())
        if profile is not None and not isinstance(profile, dict):
            raise TypeError(f"profile: expected a dict (a rasterio profile) or None, got {type(profile).__name__}")
        z.setflags(write=False)
        profile = dict(profile) if profile else None
        if not per_facet:
            return cls(z, cell_size, periodic, material, split, profile=profile)
        cells = z.shape if periodic else (z.shape[0] - 1, z.shape[1] - 1)
        facets: dict = {}

        def geometry(i: int) -> np.ndarray:
            if not facets:
                facets["v"] = _dem_facets(z, cell_size, periodic, split)
            return facets["v"][i]

        ids = _material_ids(material_ids, len(materials), lambda: geometry(0), lambda: geometry(1),
                            (cells[0], cells[1], 2))
        if ids is not None:
            ids.setflags(write=False)
        core = _core.RadiometryScene.from_dem(z, (cell_size[1], cell_size[0]), periodic, split, [m._spec() for m in materials], ids)
        return cls(z, cell_size, periodic, material, split, profile=profile, materials=materials,
                   material_ids=ids, core=core)

    @classmethod
    def from_mesh(cls, mesh, materials: Union[None, Material, Sequence[Material]] = None,
                  material_ids: Optional[MaterialIds] = None, periodic: bool = True,
                  extent=None) -> "Scene":
        """A scene of the triangles of a mesh: terrain, TINs, plants.

        Facets are two-sided: the normal used for shading faces the
        incoming ray, so leaves are lit and seen from both sides. Rays are
        cast through a bounding volume hierarchy (the ``obvhs`` crate's
        compressed wide BVH) with exact double-precision triangle tests.
        The BVH is built once, here.

        Parameters
        ----------
        mesh : fractalgeo_rs.geometry.Mesh
            The triangles (map coordinates = ``origin`` + vertices). Every
            triangle must have a positive area and finite vertices.
        materials : material or list of materials, optional
            Reflectance models; default ``Lambertian(0.5)``. A material
            whose model transmits light lights both sides.
        material_ids : array_like of int or callable, optional
            The material (index into ``materials``) of every triangle, shape
            ``(len(mesh),)``, or a function ``f(slope, height)`` of the
            triangles' slopes (degrees, 0 for horizontal, of either side)
            and centroid heights (map z) returning one. Required with
            several materials; e.g. ``mesh.kinds`` (0 branch, 1 leaf).
        periodic : bool
            True: the mesh is one tile of an infinite surface over
            ``extent``; a ray that leaves a side of the tile re-enters from
            the opposite one. Triangles may cross the tile's sides (they are
            wrapped), but no triangle may be wider or taller than the tile,
            and the mesh must tile seamlessly for the result to mean an
            infinite surface. False: a finite patch; rays that miss it escape.
        extent : (float, float, float, float), optional
            ``(x0, y0, width, height)`` in map coordinates: the periodic
            tile, and the area the sensor sees (BRF, albedo and images are
            per unit of this horizontal area). Default: the mesh's
            horizontal bounding box. Every triangle's centroid must lie in
            it.

        Returns
        -------
        Scene

        Raises
        ------
        ValueError
            Naming ``mesh`` (no triangles, NaN or degenerate triangles),
            ``extent`` (not covering the mesh), ``material_ids`` (wrong
            length, index out of range) or ``materials``.

        Examples
        --------
        A flat Lambertian plane gives BRF = albedo = rho:

        >>> import numpy as np
        >>> from fractalgeo_rs.geometry import Mesh
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> plane = Mesh.from_triangles([[0, 0, 0], [4, 0, 0], [0, 4, 0], [4, 4, 0]], [[0, 1, 2], [1, 3, 2]])
        >>> s = Scene.from_mesh(plane, materials=Lambertian(0.3))
        >>> round(s.brf(sun=(40.0, 50.0), view=(200.0, 30.0), spp=1000).value, 9)
        0.3

        References
        ----------
        T. Möller and B. Trumbore, "Fast, minimum storage ray-triangle
        intersection", *Journal of Graphics Tools* 2(1), 21-28, 1997.
        S. Ylitie, T. Karras and S. Laine, "Efficient incoherent ray
        traversal on GPUs through compressed wide BVHs", *High Performance
        Graphics*, 2017 (the CWBVH of ``obvhs``).
        """
        from fractalgeo_rs.geometry import Mesh

        if not isinstance(mesh, Mesh):
            raise TypeError(f"mesh: expected a fractalgeo_rs.geometry.Mesh, got {type(mesh).__name__}")
        if not isinstance(periodic, (bool, np.bool_)):
            raise TypeError(f"periodic: expected True or False, got {periodic!r}")
        periodic = bool(periodic)
        mesh = mesh._arrays()
        mats = _materials(Lambertian(0.5) if materials is None else materials, "materials")
        ext = _extent(extent)
        facets: dict = {}

        def geometry(i: int) -> np.ndarray:
            if not facets:
                facets["v"] = _mesh_facets(mesh)
            return facets["v"][i]

        ids = _material_ids(material_ids, len(mats), lambda: geometry(0), lambda: geometry(1), (len(mesh),))
        if ids is not None:
            ids.setflags(write=False)
        core = _core.RadiometryScene.from_mesh(mesh, [m._spec() for m in mats], ids, periodic, ext)
        x0, y0, w, h = core.footprint
        ext = (x0 + float(mesh.origin[0]), y0 + float(mesh.origin[1]), w, h)
        return cls(None, None, periodic, mats[0], "ne-sw", materials=mats, material_ids=ids, mesh=mesh,
                   extent=ext, core=core)

    @classmethod
    def from_tin(cls, tin, materials: Union[None, Material, Sequence[Material]] = None,
                 material_ids: Optional[MaterialIds] = None, periodic: bool = False,
                 extent=None) -> "Scene":
        """A scene of the triangles of a TIN (``fractalgeo_rs.tin_from_dem``).

        ``Scene.from_mesh(tin.to_mesh(), ...)``; a TIN of a real DEM is
        rarely tileable, so ``periodic`` defaults to False here.

        Parameters
        ----------
        tin : fractalgeo_rs.tin.TIN
            The triangulated surface.
        materials, material_ids, periodic, extent
            As in ``from_mesh`` (``material_ids`` one per TIN triangle).

        Returns
        -------
        Scene

        Examples
        --------
        >>> import numpy as np, fractalgeo_rs as fg
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> i, j = np.indices((9, 9))
        >>> s = Scene.from_tin(fg.tin_from_dem(0.1 * i, max_error=0.01), materials=Lambertian(0.5))
        >>> e = s.brf(sun=(0.0, 0.0), spp=200, max_depth=1)  # rho n_z on a plane
        >>> bool(abs(e.value - 0.5 / np.sqrt(1.01)) < 1e-6)
        True

        References
        ----------
        See ``from_mesh``.
        """
        if not hasattr(tin, "to_mesh"):
            raise TypeError(f"tin: expected a fractalgeo_rs.tin.TIN, got {type(tin).__name__}")
        return cls.from_mesh(tin.to_mesh(), materials=materials, material_ids=material_ids, periodic=periodic,
                             extent=extent)

    @classmethod
    def from_instances(cls, shapes, instance_shapes, transforms, extent,
                       materials: Union[None, Material, Sequence[Material]] = None,
                       material_ids: Optional[MaterialIds] = None, periodic: bool = True) -> "Scene":
        """A scene of many placed copies of a few meshes (trees, leaves).

        Each shape gets its own BVH and a top-level BVH covers the
        instances' boxes, so memory grows with the shapes, not the copies.
        Facets are two-sided and periodic tiles work as in ``from_mesh``
        (an instance whose box crosses a side of the tile is wrapped).

        Parameters
        ----------
        shapes : list of fractalgeo_rs.geometry.Mesh
            The meshes (map coordinates = origin + vertices).
        instance_shapes : array_like of int, shape (k,)
            Shape of every instance.
        transforms : array_like of float, shape (k, 3, 4)
            Affine transform ``[R | t]`` of every instance, from the shape's
            map coordinates to the scene's (``x' = R x + t``; any invertible
            ``R``: rotation, scale, mirror).
        extent : (float, float, float, float)
            ``(x0, y0, width, height)`` of the tile (periodic) or footprint,
            scene coordinates; every instance's box centre must lie in it.
        materials : material or list of materials, optional
            Default ``Lambertian(0.5)``.
        material_ids : array_like of int or callable, optional
            One index per facet: instances in order, each over its shape's
            triangles (length ``sum(len(shapes[s]) for s in
            instance_shapes)``), or ``f(slope, height)``.
        periodic : bool
            As in ``from_mesh``.

        Returns
        -------
        Scene

        Examples
        --------
        Four copies of a unit square, scaled by 2, cover a 4 x 4 tile: a plane.

        >>> import numpy as np
        >>> from fractalgeo_rs.geometry import Mesh
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> sq = Mesh.from_triangles([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
        >>> xf = np.zeros((4, 3, 4)); xf[:, 0, 0] = xf[:, 1, 1] = 2.0; xf[:, 2, 2] = 1.0
        >>> xf[:, :2, 3] = [[0, 0], [2, 0], [0, 2], [2, 2]]
        >>> s = Scene.from_instances([sq], [0, 0, 0, 0], xf, extent=(0, 0, 4, 4), materials=Lambertian(0.3))
        >>> round(s.brf(sun=(20.0, 40.0), view=(90.0, 30.0), spp=500).value, 9)
        0.3

        References
        ----------
        See ``from_mesh``.
        """
        from fractalgeo_rs.geometry import Mesh

        if isinstance(shapes, Mesh) or not hasattr(shapes, "__iter__"):
            raise TypeError(f"shapes: expected a list of fractalgeo_rs.geometry.Mesh, got {type(shapes).__name__}")
        shapes = list(shapes)
        for k, m in enumerate(shapes):
            if not isinstance(m, Mesh):
                raise TypeError(f"shapes: item {k} is not a fractalgeo_rs.geometry.Mesh: {type(m).__name__}")
        shapes = [m._arrays() for m in shapes]
        which = np.asarray(instance_shapes)
        if which.ndim != 1 or which.dtype.kind not in "iu":
            raise TypeError(f"instance_shapes: expected a 1D integer array, got shape {which.shape}, dtype {which.dtype}")
        if which.size and (which.min() < 0 or which.max() >= len(shapes)):
            raise ValueError(f"instance_shapes: expected shape indices in [0, {len(shapes)}), got "
                             f"{int(which.min())}..{int(which.max())}")
        xf = np.asarray(transforms, dtype=np.float64)
        if xf.shape != (which.size, 3, 4):
            raise ValueError(f"transforms: expected shape ({which.size}, 3, 4), got {xf.shape}")
        if not np.isfinite(xf).all():
            raise ValueError("transforms: expected finite values")
        ext = _extent(extent)
        if ext is None:
            raise TypeError("extent: expected (x0, y0, width, height), got None")
        if not isinstance(periodic, (bool, np.bool_)):
            raise TypeError(f"periodic: expected True or False, got {periodic!r}")
        mats = _materials(Lambertian(0.5) if materials is None else materials, "materials")
        n_facets = int(sum(len(shapes[int(s)]) for s in which))
        facets: dict = {}

        def geometry(i: int) -> np.ndarray:
            if not facets:
                parts = []
                for s, t in zip(which, xf):
                    m = shapes[int(s)]
                    v = np.asarray(m.vertices, np.float64) + np.asarray(m.origin)
                    w = v @ t[:, :3].T + t[:, 3]
                    f = np.asarray(m.faces, np.int64)
                    p0, p1, p2 = w[f[:, 0]], w[f[:, 1]], w[f[:, 2]]
                    n = np.cross(p1 - p0, p2 - p0)
                    ln = np.linalg.norm(n, axis=1)
                    cos = np.divide(np.abs(n[:, 2]), ln, out=np.ones_like(ln), where=ln > 0)
                    parts.append((np.degrees(np.arccos(np.clip(cos, 0, 1))), (p0[:, 2] + p1[:, 2] + p2[:, 2]) / 3))
                facets["v"] = (np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts]))
            return facets["v"][i]

        ids = _material_ids(material_ids, len(mats), lambda: geometry(0), lambda: geometry(1), (n_facets,))
        if ids is not None:
            ids.setflags(write=False)
        core = _core.RadiometryScene.from_instances(shapes, np.ascontiguousarray(which, dtype=np.uint32), xf,
                                                    [m._spec() for m in mats], ids, bool(periodic), ext)
        return cls(None, None, bool(periodic), mats[0], "ne-sw", materials=mats, material_ids=ids, extent=ext,
                   core=core)

    def _swap(self, sun, view, sky: float, reciprocity: Optional[bool]) -> bool:
        """Whether to trace the reciprocal configuration (sun and view
        exchanged): with ``None``, when that is allowed (a periodic scene,
        no sky; every reflectance model here is reciprocal) and the sun is
        lower than the sensor, so the sun's next-event estimate sees fewer
        shadows."""
        if reciprocity is None:
            return bool(self.periodic) and sky == 0.0 and float(sun[1]) > float(view[1])
        if not isinstance(reciprocity, (bool, np.bool_)):
            raise TypeError(f"reciprocity: expected None, True or False, got {reciprocity!r}")
        if reciprocity and (not self.periodic or sky != 0.0):
            raise ValueError("reciprocity: exchanging sun and view needs a periodic scene and sky=0 "
                             f"(periodic={self.periodic}, sky={sky})")
        return bool(reciprocity)

    def _raw_brf(self, sun, view, sky: float, spp: int, depth: int, seed: int,
                 n_threads, reciprocity: Optional[bool] = None) -> Tuple[float, float, int]:
        core = self._scene_core()
        if self._swap(sun, view, sky, reciprocity):
            sun, view = view, sun
        if sky > 0.0:
            return core.brf_sky(sun, view, sky, spp, depth, seed, n_threads)
        return core.brf(sun, view, spp, depth, seed, n_threads)

    def _dem(self) -> np.ndarray:
        if self.dem is None:
            raise TypeError("a mesh scene has no DEM")
        return self.dem

    def _default_shape(self) -> Tuple[int, int]:
        if self.dem is None:
            return (128, 128)
        dem = self._dem()
        cells = dem.shape if self.periodic else (dem.shape[0] - 1, dem.shape[1] - 1)
        return (int(cells[0]), int(cells[1]))

    def brf(self, sun, view="nadir", spp: int = 65536, max_depth: int = 10, seed: int = 0,
            n_threads: Optional[int] = None, sky: float = 0.0,
            reciprocity: Optional[bool] = None) -> Estimate:
        """Bidirectional reflectance factor of the whole tile.

        ``BRF = pi L / cos(sun zenith)``, with ``L`` the radiance towards
        ``view`` averaged over the horizontal area of the tile, for unit
        irradiance normal to the beam. Each path starts at a uniform point of
        the tile, finds the facet the sensor sees, adds the sun's direct
        light when the facet is lit (next-event estimation), then scatters,
        up to ``max_depth`` scattering events. A flat Lambertian plane gives
        exactly ``rho``.

        Parameters
        ----------
        sun : (float, float)
            Direction towards the sun, ``(azimuth, zenith)`` in degrees;
            zenith in [0, 90).
        view : (float, float) or "nadir"
            Direction towards the sensor, same convention.
        spp : int
            Number of paths (> 0). They are randomised quasi-Monte Carlo
            points: ``max(16, ceil(spp / 65536))`` independently
            Owen-scrambled Sobol sequences (replicates) give the sensor
            point and the scattering directions; ``se`` is the spread of
            the replicate means. The standard error falls at least as fast
            as 1/sqrt(spp), faster where the radiance is smooth over the
            tile (at a grazing sun the shadows limit the gain).
        max_depth : int
            Scattering events per path: 1 = single scattering. Light of
            order k is about ``rho**k``; raise it for bright surfaces.
        seed : int
            Seed of the counter-based random numbers; the result is the same
            for any ``n_threads``.
        n_threads : int, optional
            Threads (default: all cores).
        sky : float
            Irradiance of a uniform (isotropic) sky on a horizontal plane,
            relative to the sun's irradiance normal to the beam (>= 0;
            default 0: the sun only). With ``sky > 0`` the result is the
            hemispherical-directional reflectance factor ``pi L / (cos(sun
            zenith) + sky)``, ``L`` including the sky light scattered up to
            ``max_depth`` times; a flat Lambertian plane still gives
            ``rho``.
        reciprocity : bool, optional
            Trace the reciprocal configuration, sun and view exchanged
            (Helmholtz reciprocity: the tile's BRF, each scattering order
            included, is symmetric in sun and view for a periodic scene of
            reciprocal reflectance models, which all models here are).
            ``None`` (default): exchange them when the scene is periodic,
            ``sky`` is 0 and the sun is lower than the sensor, so the
            sun's next-event estimate sees fewer shadows (same value, much
            smaller standard error at a grazing sun: at 89 degrees with a
            nadir sensor on a rough fBm tile, about 800 times less
            variance per path). ``False``: always trace from the sensor
            (what a test of reciprocity needs). ``True``: always exchange
            (a ValueError on a finite patch or with sky light).

        Returns
        -------
        Estimate
            ``value`` and its standard error ``se``.

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.2))
        >>> round(s.brf(sun=(0.0, 60.0), view=(90.0, 45.0), spp=500).value, 9)
        0.2

        References
        ----------
        F. E. Nicodemus et al., *Geometrical Considerations and Nomenclature
        for Reflectance*, NBS Monograph 160, 1977 (reflectance factor).
        """
        v, se, n = self._raw_brf(_direction(sun, "sun"), _direction(view, "view"), _sky(sky),
                                 _spp(spp), _depth(max_depth), _seed(seed),
                                 check_n_threads(n_threads), reciprocity)
        return Estimate(v, se, n)

    def brf_orders(self, sun, view="nadir", spp: int = 65536, max_depth: int = 10, seed: int = 0,
                   n_threads: Optional[int] = None, sky: float = 0.0,
                   reciprocity: Optional[bool] = None) -> ScatteringOrders:
        """The reflectance factor of ``brf`` split into single and multiple
        scattering over the same paths.

        Each path is traced once: its first-order next-event estimate of the
        sun (the sun's direct light on the first facet the sensor sees) is
        its single-scattering value, the rest of the path (orders 2 to
        ``max_depth``) its multiple-scattering value. With ``sky > 0`` the
        sky light of paths leaving after one scattering event counts as
        single scattering too. Random numbers are keyed by path and by
        bounce, so ``single`` is exactly ``brf(..., max_depth=1)`` with the
        same seed and ``total`` exactly ``brf(...)``; ``single.value +
        multiple.value`` equals ``total.value`` to rounding, and
        ``multiple.se`` is the standard error of the per-path differences
        (smaller than what two separate runs would give).

        Parameters
        ----------
        sun : (float, float)
            Direction towards the sun, ``(azimuth, zenith)`` in degrees;
            zenith in [0, 90).
        view : (float, float) or "nadir"
            Direction towards the sensor, same convention.
        spp : int
            Number of paths (> 0).
        max_depth : int
            Scattering events per path (>= 1; with 1, ``multiple`` is 0).
        seed : int
            Seed of the counter-based random numbers; the result is the same
            for any ``n_threads``.
        n_threads : int, optional
            Threads (default: all cores).
        sky : float
            Irradiance of a uniform sky on a horizontal plane relative to
            the sun's normal irradiance (>= 0), as in ``brf``; the parts are
            then HDRFs.
        reciprocity : bool, optional
            As in ``brf`` (each scattering order is reciprocal on its own,
            so the split holds in the exchanged configuration too).

        Returns
        -------
        ScatteringOrders
            ``single``, ``multiple`` and ``total``, each an ``Estimate``.

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> x = np.arange(16)
        >>> dem = np.where(x % 2 == 0, 0.0, 1.0)[None, :].repeat(16, axis=0)   # V-grooves
        >>> s = Scene.from_dem(dem, material=Lambertian(0.5))
        >>> o = s.brf_orders(sun=(90.0, 30.0), spp=4096)
        >>> bool(o.multiple.value > 0), abs(o.single.value + o.multiple.value - o.total.value) < 1e-12
        (True, True)

        References
        ----------
        E. Veach, *Robust Monte Carlo Methods for Light Transport
        Simulation*, PhD thesis, Stanford University, 1997 (path tracing
        with next-event estimation).
        """
        sun, view, sky = _direction(sun, "sun"), _direction(view, "view"), _sky(sky)
        if self._swap(sun, view, sky, reciprocity):
            sun, view = view, sun
        (sv, sse), (mv, mse), (tv, tse), n = self._scene_core().brf_orders(
            sun, view, sky, _spp(spp), _depth(max_depth), _seed(seed), check_n_threads(n_threads))
        return ScatteringOrders(Estimate(sv, sse, n), Estimate(mv, mse, n), Estimate(tv, tse, n))

    def bhr(self, spp: int = 65536, max_depth: int = 100, seed: int = 0,
            n_threads: Optional[int] = None) -> Estimate:
        """Bi-hemispherical reflectance (white-sky albedo).

        The fraction of the flux of a uniform sky on the tile's horizontal
        area that leaves it upwards: ``(2 / pi) * integral of albedo(theta,
        phi) cos(theta) sin(theta) dtheta dphi`` over the upper hemisphere,
        ``albedo`` the directional-hemispherical reflectance of ``albedo``.
        Each path draws its sun direction cosine-weighted (the distribution
        of a uniform sky's light on a horizontal plane), then follows the
        light as ``albedo`` does, so one estimate integrates over sun
        directions and positions at once.

        Parameters
        ----------
        spp : int
            Number of rays (> 0).
        max_depth : int
            Largest number of scattering events per ray.
        seed : int
            Seed of the counter-based random numbers.
        n_threads : int, optional
            Threads (default: all cores); the result does not depend on it.

        Returns
        -------
        Estimate

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.35))
        >>> round(s.bhr(spp=500).value, 9)
        0.35

        References
        ----------
        C. B. Schaaf et al., "First operational BRDF, albedo nadir
        reflectance products from MODIS", *Remote Sensing of Environment*
        83, 135-148, 2002, doi:10.1016/S0034-4257(02)00091-3 (white-sky
        albedo). F. E. Nicodemus et al., NBS Monograph 160, 1977
        (bi-hemispherical reflectance).
        """
        args = (_spp(spp), _depth(max_depth), _seed(seed), check_n_threads(n_threads))
        v, se, n = self._scene_core().bhr(*args)
        return Estimate(v, se, n)

    def albedo(self, sun, spp: int = 65536, max_depth: int = 100, seed: int = 0,
               n_threads: Optional[int] = None) -> Estimate:
        """Directional-hemispherical reflectance (black-sky albedo).

        The fraction of the sun's flux on the tile's horizontal area that
        leaves it upwards after at most ``max_depth`` scattering events
        (light still trapped after that is not counted). Rays follow the
        light from the sun; with ``rho = 1`` on a periodic surface the
        result tends to exactly 1. On a finite patch (``periodic=False``)
        sun rays that leave through a side before hitting are lost and
        scattered rays leaving through a side count as reflected.

        Parameters
        ----------
        sun : (float, float)
            Direction towards the sun, ``(azimuth, zenith)`` in degrees.
        spp : int
            Number of rays (> 0).
        max_depth : int
            Largest number of scattering events per ray.
        seed : int
            Seed of the counter-based random numbers.
        n_threads : int, optional
            Threads (default: all cores).

        Returns
        -------
        Estimate

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.35))
        >>> round(s.albedo(sun=(0.0, 45.0), spp=500).value, 9)
        0.35

        References
        ----------
        C. B. Schaaf et al., "First operational BRDF, albedo nadir
        reflectance products from MODIS", *Remote Sensing of Environment*
        83, 135-148, 2002, doi:10.1016/S0034-4257(02)00091-3.
        """
        args = (_direction(sun, "sun"), _spp(spp), _depth(max_depth), _seed(seed),
                check_n_threads(n_threads))
        v, se, n = self._scene_core().albedo(*args)
        return Estimate(v, se, n)

    def _scene_core(self):
        """The kernel scene (``_core.RadiometryScene``): a one-material DEM
        scene builds it on first use and keeps it, rebuilt when ``dem``,
        ``cell_size``, ``periodic``, ``split`` or ``material`` change."""
        if not self._lazy_core:
            return self._core
        dem, cell_size = self._dem(), self.cell_size
        if cell_size is None:
            raise TypeError("a mesh scene has no cell size")
        name, params = self.material._spec()
        key = (id(dem), dem.shape, tuple(cell_size), bool(self.periodic), self.split, name, tuple(params))
        if self._core is None or self._core_key != key:
            dy, dx = cell_size
            self._core = _core.RadiometryScene.from_dem(dem, (dx, dy), self.periodic, self.split,
                                                        [(name, list(params))], None)
            self._core_key = key
        return self._core

    def gap_fraction(self, zenith, azimuth: float = 0.0, n: int = 65536, ground: int = 0, seed: int = 0,
                     n_threads: Optional[int] = None) -> "Estimate":
        """Gap fraction: the fraction of the sun's rays at ``zenith`` that
        reach the ground (their first hit is a facet of material ``ground``)
        through the canopy.

        ``n`` parallel rays start above the highest facet, on lines through
        uniform points of the tile, and go down along the direction
        ``(azimuth, zenith)``; in a periodic scene they cross the tile's
        sides. For one realisation of a random canopy this is its own gap
        fraction; its expectation over placements of ``N`` independent
        leaves of area ``a`` in a tile of area ``A`` is ``(1 - a G / (A cos
        theta))^N`` (``canopy.DiscCanopy.gap_probability``).

        Parameters
        ----------
        zenith : float
            Zenith of the direction, degrees in [0, 90).
        azimuth : float
            Azimuth of the direction, degrees clockwise from north.
        n : int
            Number of rays.
        ground : int
            Index of the ground's material (0: the first; the soil of
            ``canopy.disc_canopy`` scenes).
        seed : int
            Seed; the result is the same for any ``n_threads``.
        n_threads : int, optional
            Threads (default all cores).

        Returns
        -------
        Estimate
            ``value`` (fraction in [0, 1]), ``se`` (binomial standard
            error), ``n``.

        Examples
        --------
        >>> from fractalgeo_rs.canopy import disc_canopy
        >>> s = disc_canopy(lai=1.0, leaf_radius=0.1, extent=2.0, height=(0.2, 1.0), seed=3).scene()
        >>> e = s.gap_fraction(30.0, n=20000)
        >>> bool(abs(e.value - 0.56) < 0.05), e.n
        (True, 20000)

        References
        ----------
        J. Ross, *The Radiation Regime and Architecture of Plant Stands*,
        Junk, The Hague, 1981.
        """
        sun = _direction((azimuth, zenith), "zenith")
        n = check_positive_int(n, "n")
        if isinstance(ground, bool) or not isinstance(ground, numbers.Integral) or \
                not 0 <= int(ground) < len(self.materials):
            raise ValueError(f"ground: expected a material index in [0, {len(self.materials)}), got {ground!r}")
        v, se, k = self._scene_core().gap_fraction(sun, int(ground), n, _seed(seed), check_n_threads(n_threads))
        return Estimate(v, se, k)

    def absorption(self, sun, spp: int = 65536, max_depth: int = 1000, seed: int = 0,
                   n_threads: Optional[int] = None) -> dict:
        """Where the sun's light goes: the fraction absorbed by each
        material (fAPAR of leaves and soil in a canopy), reflected (the
        albedo) and still travelling after ``max_depth`` scattering events.

        Rays from the sun start above the scene; at each hit the path's
        weight times ``1 - albedo`` of the facet's model is absorbed there,
        and the path continues with the sampling weight, so for Lambertian
        and bi-Lambertian facets absorbed + reflected + trapped is 1 on
        every path.

        Parameters
        ----------
        sun : (float, float)
            Direction towards the sun, ``(azimuth, zenith)`` in degrees.
        spp : int
            Number of paths.
        max_depth : int
            Scattering events per path.
        seed : int
            Seed; the result is the same for any ``n_threads``.
        n_threads : int, optional
            Threads (default all cores).

        Returns
        -------
        dict
            ``"absorbed"``: a list of one ``Estimate`` per material (in
            ``materials`` order), ``"reflected"`` and ``"trapped"``:
            ``Estimate``.

        Examples
        --------
        >>> from fractalgeo_rs.canopy import disc_canopy
        >>> from fractalgeo_rs.radiometry import BiLambertian, Lambertian
        >>> c = disc_canopy(lai=2.0, leaf_radius=0.1, extent=2.0, height=(0.2, 1.0), seed=1,
        ...                 leaf=BiLambertian(0.0, 0.0), soil=Lambertian(0.0))
        >>> a = c.scene().absorption(sun=(0.0, 0.0), spp=20000)
        >>> soil, leaves = a["absorbed"]  # black leaves: the soil absorbs the gap fraction
        >>> round(soil.value + leaves.value, 12), bool(abs(soil.value - 0.37) < 0.04)
        (1.0, True)

        References
        ----------
        B. Pinty et al., "Radiation transfer model intercomparison (RAMI)
        exercise", *J. Geophys. Res.* 106(D11) (2001) 11937-11956,
        doi:10.1029/2000JD900493 (absorption, transmission and albedo).
        """
        spp = check_positive_int(spp, "spp")
        absorbed, refl, trapped, n = self._scene_core().absorption(
            _direction(sun, "sun"), spp, _depth(max_depth), _seed(seed), check_n_threads(n_threads))
        return {"absorbed": [Estimate(v, se, n) for v, se in absorbed], "reflected": Estimate(refl[0], refl[1], n),
                "trapped": Estimate(trapped[0], trapped[1], n)}

    def render(self, sun, view="nadir", shape: Optional[Tuple[int, int]] = None, spp: int = 16,
               max_depth: int = 10, seed: int = 0, n_threads: Optional[int] = None,
               max_memory=None, progress: Optional[bool] = None, sky: float = 0.0, psf="box",
               psf_step: float = 1.0) -> np.ndarray:
        """Radiance image seen by an orthographic sensor.

        The tile's horizontal extent is divided into ``shape`` pixels; pixel
        ``(i, j)`` (row 0 north) averages ``spp`` paths through points of
        the reference plane (the DEM's mean height) drawn from its
        point-spread function ``psf`` (default: uniform over its box
        footprint), traced as in ``brf``. Values are radiances for unit sun
        irradiance normal to the beam: ``pi * image.mean() / cos(sun
        zenith)`` estimates the BRF.

        Parameters
        ----------
        sun : (float, float)
            Direction towards the sun, ``(azimuth, zenith)`` in degrees.
        view : (float, float) or "nadir"
            Direction towards the sensor.
        shape : (int, int), optional
            ``(rows, cols)`` of the image; default one pixel per cell.
        spp : int
            Paths per pixel.
        max_depth : int
            Scattering events per path (1 = single scattering).
        seed : int
            Seed; the image is the same for any ``n_threads``.
        n_threads : int, optional
            Threads (default: all cores).
        max_memory : int, optional
            Limit in bytes for the image (default: the package's limit);
            a larger image raises ``MemoryError`` before allocating.
        progress : bool, optional
            A progress bar over the image rows on stderr (needs tqdm); the
            image does not depend on it.
        sky : float
            Irradiance of a uniform sky on a horizontal plane relative to
            the sun's irradiance normal to the beam (>= 0, default 0). A
            flat Lambertian plane then has ``L = rho (cos(sun zenith) + sky)
            / pi``.
        psf : "box", ("gaussian", sigma[, truncate]) or array_like
            The sensor's point-spread function, over the reference plane
            around the pixel's centre, in image pixels: ``"box"`` (uniform
            over the pixel, the default); an isotropic Gaussian of standard
            deviation ``sigma`` pixels truncated to the disc of radius
            ``truncate * sigma`` (default ``truncate=4``); or a 2D array of
            non-negative weights, piecewise constant on cells ``psf_step``
            pixels wide centred on the pixel's centre (row 0 north). Each
            path's footprint point is drawn from the PSF, so a pixel
            estimates exactly the PSF-weighted mean radiance (footprints
            may overlap neighbouring pixels; outside a finite patch nothing
            is seen).
        psf_step : float
            Cell size of an array ``psf``, pixels (> 0).

        Returns
        -------
        numpy.ndarray of float32, shape ``shape``

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(1.0))
        >>> img = s.render(sun=(0.0, 60.0), shape=(2, 3), spp=4)
        >>> img.dtype, img.shape, bool(np.allclose(img, 0.5 / np.pi))
        (dtype('float32'), (2, 3), True)

        References
        ----------
        M. Pharr, W. Jakob and G. Humphreys, *Physically Based Rendering*,
        3rd ed., 2016 (path tracing with next-event estimation).
        """
        return self._render([_direction(sun, "sun")], view, shape, spp, max_depth, seed, n_threads, max_memory,
                            progress, sky, psf, psf_step)[0]

    def render_series(self, suns, view="nadir", shape: Optional[Tuple[int, int]] = None, spp: int = 16,
                      max_depth: int = 10, seed: int = 0, n_threads: Optional[int] = None,
                      max_memory=None, progress: Optional[bool] = None, sky: float = 0.0, psf="box",
                      psf_step: float = 1.0) -> np.ndarray:
        """Radiance images of the same scene under several suns, in one pass.

        Image ``k`` equals ``render(sun=suns[k], ...)`` with the same
        ``seed`` and other arguments bit for bit. The path a sensor ray
        starts does not depend on the sun (only its next-event estimates
        do), so each path is traced once and the sun's contribution at
        every scattering event is estimated for every sun: the cost is
        that of one image plus one shadow ray per sun and event. This is
        how to render the paper's incidence series (figure 9); see
        ``plot_incidence_series``.

        Parameters
        ----------
        suns : sequence of (float, float)
            Directions towards the sun, ``(azimuth, zenith)`` in degrees.
        view, shape, spp, max_depth, seed, n_threads, progress, sky, psf, psf_step
            As in ``render``.
        max_memory : int, optional
            Limit in bytes for the stack of images (default: the package's
            limit; the kernel writes the stack in place); a larger stack
            raises ``MemoryError`` before allocating.

        Returns
        -------
        numpy.ndarray of float32, shape ``(len(suns), rows, cols)``

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(1.0))
        >>> imgs = s.render_series([(0.0, 0.0), (0.0, 60.0)], shape=(2, 3), spp=4)
        >>> imgs.shape, bool(np.allclose(imgs[1], 0.5 / np.pi))
        ((2, 2, 3), True)
        >>> bool(np.array_equal(imgs[1], s.render(sun=(0.0, 60.0), shape=(2, 3), spp=4)))
        True
        """
        if isinstance(suns, (str, bytes)) or not hasattr(suns, "__len__"):
            raise TypeError(f"suns: expected a sequence of (azimuth, zenith) pairs, got {suns!r}")
        if len(suns) == 0:
            raise ValueError("suns: expected at least one (azimuth, zenith) pair, got none")
        return self._render([_direction(s, "suns") for s in suns], view, shape, spp, max_depth, seed, n_threads,
                            max_memory, progress, sky, psf, psf_step)

    def _render(self, suns, view, shape, spp, max_depth, seed, n_threads, max_memory, progress, sky, psf,
                psf_step) -> np.ndarray:
        """The orthographic images of ``render`` for the checked sun
        directions ``suns``: ``(len(suns), rows, cols)``."""
        if shape is None:
            shape = self._default_shape()
        try:
            rows, cols = shape
        except (TypeError, ValueError):
            raise TypeError(f"shape: expected (rows, cols), got {shape!r}") from None
        rows, cols = check_positive_int(rows, "shape"), check_positive_int(cols, "shape")
        n = len(suns)
        what = f"a {rows} x {cols} float32 image" + (f" x {n} suns" if n > 1 else "")
        check_memory(n * rows * cols * 4, "shape", max_memory=max_memory, what=what)
        from fractalgeo_rs import _progress

        sky = _sky(sky)
        kind, pparams, table = _psf(psf, psf_step)
        view = _direction(view, "view")
        rest = (check_positive_int(spp, "spp"), _depth(max_depth), _seed(seed))
        nt = check_n_threads(n_threads)
        core = self._scene_core()
        with _progress.Steps(rows, "render", _progress.resolve(progress)) as steps:
            return steps.counted(lambda counter: core.render_series(
                suns, view, sky, (rows, cols), *rest, kind, pparams, table, nt, progress=counter), rows)

    def render_perspective(self, sun, view=(135.0, 60.0), distance: Optional[float] = None, eye=None,
                           target=None, fov: float = 40.0, shape: Tuple[int, int] = (240, 320), spp: int = 16,
                           max_depth: int = 10, seed: int = 0, n_threads: Optional[int] = None, sky: float = 0.0,
                           max_memory=None, progress: Optional[bool] = None) -> np.ndarray:
        """Radiance image seen by a perspective (pinhole) camera: the 3D
        view that ends figure 9 of the seed paper.

        The camera looks at ``target`` (default the tile's centre at the
        DEM's mean height) from ``eye``, or, without ``eye``, from
        ``distance`` along the direction ``view`` (``(azimuth, zenith)``
        from the target, as for the sun). Image rows go down and columns
        right, the horizon horizontal. A periodic scene is seen as an
        infinite surface; rays that miss the surface see the sky radiance
        ``sky / pi`` above the horizon and 0 below it. Pixels are boxes of
        ``spp`` jittered rays, each traced as in ``render``.

        Parameters
        ----------
        sun : (float, float)
            Direction towards the sun, ``(azimuth, zenith)`` in degrees.
        view : (float, float)
            Direction from the target towards the camera when ``eye`` is
            not given.
        distance : float, optional
            Camera distance from the target (> 0), in the unit of the
            heights; default 1.2 times the tile's diagonal.
        eye, target : (float, float, float), optional
            Positions in the scene's frame: ``x`` east and ``y`` north of
            the DEM's first sample (the tile spans ``y`` from 0 to ``-rows
            * dy``), ``z`` the height; for a mesh scene, the mesh's frame
            (map coordinates minus ``mesh.origin``; default target the
            footprint's centre at the mean vertex height), for an instanced
            scene the scene's coordinates (default target height 0). The
            camera should be above the surface.
        fov : float
            Vertical field of view, degrees in (0, 180).
        shape : (int, int)
            ``(rows, cols)`` of the image.
        spp, max_depth, seed, n_threads, sky, max_memory, progress
            As in ``render``.

        Returns
        -------
        numpy.ndarray of float32, shape ``shape``

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(1.0))
        >>> img = s.render_perspective(sun=(0.0, 60.0), view=(180.0, 45.0), shape=(3, 4), spp=2)
        >>> bool(np.allclose(img, 0.5 / np.pi))  # a flat plane: rho cos(60) / pi everywhere
        True

        References
        ----------
        M. Pharr, W. Jakob and G. Humphreys, *Physically Based Rendering*,
        3rd ed., 2016 (the pinhole camera). M. Datcu and K. Seidel, 1995
        (see ``Scene``), figure 9.
        """
        try:
            rows, cols = shape
        except (TypeError, ValueError):
            raise TypeError(f"shape: expected (rows, cols), got {shape!r}") from None
        rows, cols = check_positive_int(rows, "shape"), check_positive_int(cols, "shape")
        check_memory(rows * cols * 4, "shape", max_memory=max_memory, what=f"a {rows} x {cols} float32 image")
        if self.dem is None and self._core is not None:
            # mesh (its frame: the mesh's origin) or instanced scene
            x0, y0, w, h = self._core.footprint
            zc = float(np.asarray(self.mesh.vertices, dtype=np.float64)[:, 2].mean()) if self.mesh is not None else 0.0
            centre = (x0 + 0.5 * w, y0 + 0.5 * h, zc)
        else:
            dem = self._dem()
            dy, dx = self.cell_size if self.cell_size is not None else (1.0, 1.0)
            cells = dem.shape if self.periodic else (dem.shape[0] - 1, dem.shape[1] - 1)
            w, h = cells[1] * dx, cells[0] * dy
            centre = (0.5 * w, -0.5 * h, float(dem.mean()))
        tgt = _point(target, "target") if target is not None else centre
        if eye is None:
            az, zen = _direction(view, "view")
            dist = 1.2 * math.hypot(w, h) if distance is None else check_positive_float(distance, "distance")
            a, z = math.radians(az), math.radians(zen)
            e = (tgt[0] + dist * math.sin(a) * math.sin(z), tgt[1] + dist * math.cos(a) * math.sin(z),
                 tgt[2] + dist * math.cos(z))
        else:
            e = _point(eye, "eye")
        if isinstance(fov, bool) or not isinstance(fov, numbers.Real) or not 0.0 < float(fov) < 180.0:
            raise ValueError(f"fov: expected a field of view in (0, 180) degrees, got {fov!r}")
        from fractalgeo_rs import _progress

        args = (_direction(sun, "sun"), _sky(sky), e, tgt, float(fov), (rows, cols),
                check_positive_int(spp, "spp"), _depth(max_depth), _seed(seed), check_n_threads(n_threads))
        core = self._scene_core()
        with _progress.Steps(rows, "render", _progress.resolve(progress)) as steps:
            img = steps.counted(lambda counter: core.render_perspective(*args, progress=counter), rows)
        key = id(img)
        self._perspective[key] = weakref.ref(img, lambda _r, k=key, d=self._perspective: d.pop(k, None))
        return img

    def brf_sweep(self, sun_zenith=PAPER_SUN_ZENITHS, view_zenith=(0.0,), sun_azimuth: float = 0.0,
                  view_azimuth: float = 0.0, spp: int = 65536, max_depth: int = 10, seed: int = 0,
                  n_threads: Optional[int] = None, progress: Optional[bool] = None, sky: float = 0.0,
                  reciprocity: Optional[bool] = None) -> BrfSweep:
        """BRF over every pair of sun and view zenith angles.

        One ``brf`` per pair (each with the same ``seed``: common random
        numbers, so differences between angles are smoother than their
        standard errors suggest).

        Parameters
        ----------
        sun_zenith : sequence of float
            Sun zenith angles, degrees in [0, 90); default the paper's
            incidence series 0, 15, ..., 75 and 89 (``PAPER_SUN_ZENITHS``;
            at 90 the BRF is 0/0).
        view_zenith : sequence of float
            View zenith angles, degrees in [0, 90); default nadir.
        sun_azimuth, view_azimuth : float
            Azimuths, degrees clockwise from north (equal: the view on the
            sun's side of the principal plane).
        spp, max_depth, seed, n_threads
            As in ``brf``.
        progress : bool, optional
            A progress bar over the angle pairs on stderr (needs tqdm).
        sky : float
            Horizontal irradiance of a uniform sky, as in ``brf`` (the
            values are then HDRFs).
        reciprocity : bool, optional
            As in ``brf``, for every pair.

        Returns
        -------
        BrfSweep
            ``value`` and ``se`` of shape ``(len(sun_zenith), len(view_zenith))``.

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Lambertian, Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.2))
        >>> s.brf_sweep(spp=50).value[:, 0].round(6).tolist()
        [0.2, 0.2, 0.2, 0.2, 0.2, 0.2, 0.2]

        References
        ----------
        M. Datcu and K. Seidel, 1995 (see ``Scene``; figure 9's incidence series).
        """
        from fractalgeo_rs import _progress

        suns = _angles(sun_zenith, "sun_zenith")
        views = _angles(view_zenith, "view_zenith")
        az_s = _azimuth(sun_azimuth, "sun_azimuth")
        az_v = _azimuth(view_azimuth, "view_azimuth")
        spp = _spp(spp)
        depth, seed, n_threads = _depth(max_depth), _seed(seed), check_n_threads(n_threads)
        sky = _sky(sky)
        value = np.empty((suns.size, views.size))
        se = np.empty_like(value)
        with _progress.bar(suns.size * views.size, "brf", _progress.resolve(progress)) as bar:
            for i, zs in enumerate(suns):
                for j, zv in enumerate(views):
                    value[i, j], se[i, j], _ = self._raw_brf(
                        (az_s, float(zs)), (az_v, float(zv)), sky, spp, depth, seed, n_threads, reciprocity)
                    bar.update(1)
        return BrfSweep(suns, views, az_s, az_v, value, se, spp)

    def image_transform(self, shape: Tuple[int, int]):
        """The affine transform (rasterio ``Affine``) of an image of
        ``shape`` rendered over this scene, or None without georeferencing.

        The scene's vertices are the DEM's pixel centres; an image covers the
        tile (``rows x cols`` cells when periodic, ``(rows - 1) x (cols -
        1)`` otherwise) from the first centre, so its transform is the
        DEM's shifted by half a pixel and scaled by cells per image pixel.

        Parameters
        ----------
        shape : (int, int)
            ``(rows, cols)`` of the image.

        Returns
        -------
        affine.Affine or None

        Examples
        --------
        >>> import numpy as np
        >>> from affine import Affine
        >>> from fractalgeo_rs.radiometry import Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)), profile={"transform": Affine(30, 0, 500, 0, -30, 900)})
        >>> tuple(s.image_transform((2, 2)))[:6]
        (60.0, 0.0, 515.0, 0.0, -60.0, 885.0)

        References
        ----------
        GDAL data model, https://gdal.org/user/raster_data_model.html (affine geotransform).
        """
        t = (self.profile or {}).get("transform")
        if t is None or self.dem is None:
            return None
        from affine import Affine

        if not isinstance(t, Affine):
            t = Affine(*tuple(t)[:6])
        rows, cols = shape
        cells = self.dem.shape if self.periodic else (self.dem.shape[0] - 1, self.dem.shape[1] - 1)
        return t * Affine.translation(0.5, 0.5) * Affine.scale(cells[1] / cols, cells[0] / rows)

    def save_image(self, path, image, white: float = 1.0 / math.pi, georeference: Optional[bool] = None) -> None:
        """Write a rendered image, atomically (temporary file and rename).

        The format follows the extension: ``.exr`` (float32 radiance, through
        the ``exr`` crate), ``.tif``/``.tiff`` (float32 GeoTIFF through
        rasterio, with the scene's CRS and ``image_transform`` when the scene
        has a ``profile``), ``.png`` (8-bit, ``255 * min(1, image / white)``;
        with a world file and ``.prj`` beside it when georeferenced), or
        ``.npy``.

        Parameters
        ----------
        path : str or os.PathLike
            Output file.
        image : numpy.ndarray, shape (rows, cols)
            Radiance from ``render``.
        white : float
            PNG only: the radiance shown as 255 (> 0). The default ``1 / pi``
            is a white Lambertian plane with the sun at zenith, so a series
            of sun zeniths keeps one scale.
        georeference : bool, optional
            Write the CRS and ``image_transform`` (GeoTIFF, PNG world file).
            Default: yes for an orthographic image of ``render``, no for an
            image returned by ``render_perspective`` (a camera view is not a
            map); False for any image that is not on the scene's grid.

        Returns
        -------
        None

        Examples
        --------
        >>> import os, tempfile
        >>> import numpy as np
        >>> from fractalgeo_rs import read_raster
        >>> from fractalgeo_rs.radiometry import Scene
        >>> s = Scene.from_dem(np.zeros((4, 4)))
        >>> path = os.path.join(tempfile.mkdtemp(), "img.exr")
        >>> s.save_image(path, s.render(sun=(0.0, 30.0), spp=2))
        >>> read_raster(path)[0].shape
        (4, 4)

        References
        ----------
        OpenEXR file layout, https://openexr.com/en/latest/OpenEXRFileLayout.html.
        """
        from fractalgeo_rs.io import write_raster

        img = np.asarray(image)
        if img.ndim != 2:
            raise ValueError(f"image: expected a 2D radiance image, got shape {img.shape}")
        if img.dtype.kind not in "iuf":
            raise TypeError(f"image: expected real radiances, got dtype {img.dtype}")
        ext = os.path.splitext(os.fspath(path))[1].lower()
        if georeference is None:
            ref = self._perspective.get(id(image))
            georeference = not (ref is not None and ref() is image)
        elif not isinstance(georeference, (bool, np.bool_)):
            raise TypeError(f"georeference: expected True, False or None, got {georeference!r}")
        t = self.image_transform(img.shape) if georeference else None
        crs = (self.profile or {}).get("crs") if georeference else None
        if ext == ".png":
            w = check_positive_float(white, "white")
            with np.errstate(invalid="ignore"):
                b = np.clip(np.nan_to_num(img.astype(np.float64) / w) * 255.0 + 0.5, 0, 255).astype(np.uint8)
            write_raster(path, b, crs=crs, transform=t)
        elif ext in (".tif", ".tiff"):
            write_raster(path, img.astype(np.float32), crs=crs, transform=t)
        elif ext in (".exr", ".npy"):
            write_raster(path, img.astype(np.float32))
        else:
            raise ValueError(f"path: expected a .exr, .tif, .png or .npy file name, got {os.fspath(path)!r}")


def _angles(value, name: str) -> np.ndarray:
    try:
        a = np.atleast_1d(np.asarray(value, dtype=np.float64))
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected a sequence of zenith angles in degrees, got {value!r}") from None
    if a.ndim != 1 or a.size == 0:
        raise ValueError(f"{name}: expected a non-empty 1D sequence of zenith angles, got shape {a.shape}")
    bad = ~((a >= 0.0) & (a < 90.0))
    if bad.any():
        raise ValueError(f"{name}: zenith angles must be in [0, 90) degrees (above the horizon), got "
                         f"{a[bad][0]:g}")
    return a


def _azimuth(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
        raise ValueError(f"{name}: expected a finite azimuth in degrees, got {value!r}")
    return float(value)
