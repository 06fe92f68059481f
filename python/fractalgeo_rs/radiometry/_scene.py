"""Scenes, reflectance models and estimators of the radiometric experiment
(kernels in ``rust/radiometry``)."""
from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass
from typing import List, Optional, Tuple, Union

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import (
    as_array,
    check_choice,
    check_memory,
    check_n_threads,
    check_positive_float,
    check_positive_int,
)
from fractalgeo_rs._warn import user_stacklevel

__all__ = ["Estimate", "Lambertian", "OrenNayar", "Phong", "Scene"]

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
    """The qualitative Oren-Nayar model of a rough diffuse facet.

    ``f = rho/pi (A + B max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta))`` with
    ``A = 1 - 0.5 s^2/(s^2 + 0.33)``, ``B = 0.45 s^2/(s^2 + 0.09)``,
    ``alpha = max(theta_i, theta_o)``, ``beta = min(theta_i, theta_o)``.
    Reciprocal; sampled cosine-weighted. ``sigma = 0`` is Lambertian.

    Parameters
    ----------
    rho : float
        Reflectance in [0, 1].
    sigma : float
        Standard deviation of the micro-facet slope angle, radians (>= 0).

    Examples
    --------
    >>> from fractalgeo_rs.radiometry import OrenNayar
    >>> OrenNayar(0.5, sigma=0.3).sigma
    0.3

    References
    ----------
    M. Oren and S. K. Nayar, "Generalization of Lambert's reflectance
    model", *SIGGRAPH '94*, 239-246, 1994, doi:10.1145/192161.192213
    (equation 30).
    """

    rho: float
    sigma: float

    def __post_init__(self):
        object.__setattr__(self, "rho", _reflectance(self.rho, "rho"))
        s = self.sigma
        if isinstance(s, bool) or not isinstance(s, numbers.Real):
            raise TypeError(f"sigma: expected a number of radians >= 0, got {s!r}")
        if not (math.isfinite(float(s)) and float(s) >= 0.0):
            raise ValueError(f"sigma: expected a slope standard deviation >= 0 in radians, got {s}")
        object.__setattr__(self, "sigma", float(s))

    def _spec(self) -> Tuple[str, List[float]]:
        return "oren-nayar", [self.rho, self.sigma]


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


Material = Union[Lambertian, OrenNayar, Phong]


@dataclass(frozen=True)
class Estimate:
    """A Monte Carlo estimate and its standard error.

    Attributes
    ----------
    value : float
        The sample mean.
    se : float
        Its standard error (sample standard deviation / sqrt(n)); 0 when
        every path gives the same value (e.g. a flat Lambertian plane).
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


def _depth(value) -> int:
    d = check_positive_int(value, "max_depth")
    if d > MAX_DEPTH:
        raise ValueError(f"max_depth: expected at most {MAX_DEPTH}, got {d}")
    return d


def _seed(value) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or not 0 <= int(value) < 2**64:
        raise ValueError(f"seed: expected an int in [0, 2**64), got {value!r}")
    return int(value)


def _cell_size(value) -> Tuple[float, float]:
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        v = check_positive_float(value, "cell_size")
        return (v, v)
    try:
        dx, dy = value
    except (TypeError, ValueError):
        raise TypeError(f"cell_size: expected a number or (dx, dy), got {value!r}") from None
    return (check_positive_float(dx, "cell_size"), check_positive_float(dy, "cell_size"))


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
        ``(dx, dy)``: cell size east-west and north-south, in the unit of
        the heights.
    periodic : bool
        Whether the DEM is one tile of an infinite periodic surface.
    material : Lambertian, OrenNayar or Phong
        The reflectance model of every facet.
    split : str
        The diagonal that splits each cell: ``"ne-sw"`` or ``"nw-se"``.

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

    def __init__(self, dem: np.ndarray, cell_size: Tuple[float, float], periodic: bool, material: Material,
                 split: str):
        self.dem = dem
        self.cell_size = cell_size
        self.periodic = periodic
        self.material = material
        self.split = split

    def __repr__(self) -> str:
        return (f"Scene({self.dem.shape[0]} x {self.dem.shape[1]} heights, cell_size={self.cell_size}, "
                f"periodic={self.periodic}, material={self.material!r}, split={self.split!r})")

    @classmethod
    def from_dem(cls, dem, cell_size: Union[float, Tuple[float, float]] = 1.0, periodic: bool = True,
                 material: Optional[Material] = None, split: str = "ne-sw") -> "Scene":
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
            Cell side, or ``(dx, dy)`` east-west and north-south (> 0), in
            the unit of the heights (e.g. the ``info["cell_size"]`` of the
            bundled geographic DEMs, in metres).
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
        material : Lambertian, OrenNayar or Phong, optional
            Reflectance model of every facet; default ``Lambertian(0.5)``.
        split : {"ne-sw", "nw-se"}
            The diagonal splitting each cell.

        Returns
        -------
        Scene

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.radiometry import Scene
        >>> Scene.from_dem(np.zeros((4, 5)), cell_size=30.0)
        Scene(4 x 5 heights, cell_size=(30.0, 30.0), periodic=True, material=Lambertian(rho=0.5), split='ne-sw')

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
        if not isinstance(material, (Lambertian, OrenNayar, Phong)):
            raise TypeError(f"material: expected Lambertian(...), OrenNayar(...) or Phong(...), got {material!r}")
        split = check_choice(split, "split", ("ne-sw", "nw-se"))
        if periodic:
            mismatch = _edge_mismatch(z)
            if mismatch:
                warnings.warn(f"dem: periodic=True but opposite edges do not match ({mismatch}); the "
                              "wrap adds a cliff. Mirror the DEM to make it tileable, or pass periodic=False",
                              UserWarning, stacklevel=user_stacklevel())
        z.setflags(write=False)
        return cls(z, cell_size, periodic, material, split)

    def _args(self) -> Tuple[np.ndarray, Tuple[float, float], bool, str, str, List[float]]:
        name, params = self.material._spec()
        return (self.dem, self.cell_size, self.periodic, self.split, name, params)

    def brf(self, sun, view="nadir", spp: int = 65536, max_depth: int = 10, seed: int = 0,
            n_threads: Optional[int] = None) -> Estimate:
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
            Number of paths (> 0); the standard error falls as 1/sqrt(spp).
        max_depth : int
            Scattering events per path: 1 = single scattering. Light of
            order k is about ``rho**k``; raise it for bright surfaces.
        seed : int
            Seed of the counter-based random numbers; the result is the same
            for any ``n_threads``.
        n_threads : int, optional
            Threads (default: all cores).

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
        args = self._args()
        v, se, n = _core.radiometry_brf(*args, _direction(sun, "sun"), _direction(view, "view"),
                                        check_positive_int(spp, "spp"), _depth(max_depth), _seed(seed),
                                        check_n_threads(n_threads))
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
        v, se, n = _core.radiometry_albedo(*self._args(), _direction(sun, "sun"),
                                           check_positive_int(spp, "spp"), _depth(max_depth), _seed(seed),
                                           check_n_threads(n_threads))
        return Estimate(v, se, n)

    def render(self, sun, view="nadir", shape: Optional[Tuple[int, int]] = None, spp: int = 16,
               max_depth: int = 10, seed: int = 0, n_threads: Optional[int] = None,
               max_memory=None) -> np.ndarray:
        """Radiance image seen by an orthographic sensor.

        The tile's horizontal extent is divided into ``shape`` pixels; pixel
        ``(i, j)`` (row 0 north) averages ``spp`` paths through uniform
        points of its box footprint on the reference plane (the DEM's mean
        height), traced as in ``brf``. Values are radiances for unit sun
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
        if shape is None:
            cells = self.dem.shape if self.periodic else (self.dem.shape[0] - 1, self.dem.shape[1] - 1)
            shape = (int(cells[0]), int(cells[1]))
        try:
            rows, cols = shape
        except (TypeError, ValueError):
            raise TypeError(f"shape: expected (rows, cols), got {shape!r}") from None
        rows, cols = check_positive_int(rows, "shape"), check_positive_int(cols, "shape")
        check_memory(rows * cols * 4, "shape", max_memory=max_memory, what=f"a {rows} x {cols} float32 image")
        return _core.radiometry_render(*self._args(), _direction(sun, "sun"), _direction(view, "view"),
                                       (rows, cols), check_positive_int(spp, "spp"), _depth(max_depth),
                                       _seed(seed), check_n_threads(n_threads))
