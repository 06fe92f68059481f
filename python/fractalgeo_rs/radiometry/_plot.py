"""Figures of the radiometric experiment: the BRF in the principal plane,
the polar BRF over the view hemisphere and the incidence series of images
(figure 9 of the seed paper). matplotlib is optional (``pip install
"fractalgeo_rs[plot]"``) and imported when a function is called."""
from __future__ import annotations

import math
from typing import Optional, Sequence

import numpy as np

from fractalgeo_rs._backend import require
from fractalgeo_rs.radiometry._scene import PAPER_SUN_ZENITHS, Scene

__all__ = ["plot_brf_polar", "plot_brf_principal_plane", "plot_incidence_series"]


def _sun(value):
    """``(azimuth, zenith)`` in degrees, zenith in [0, 90) (as ``Scene.brf`` checks it)."""
    try:
        az, zen = (float(v) for v in value)
    except (TypeError, ValueError):
        raise TypeError(f"sun: expected (azimuth, zenith) in degrees, got {value!r}") from None
    if not (math.isfinite(az) and math.isfinite(zen) and 0.0 <= zen < 90.0):
        raise ValueError(f"sun: expected a finite azimuth and a zenith in [0, 90) degrees, got {value!r}")
    return az, zen


def _check_scene(scene) -> None:
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a radiometry.Scene, got {type(scene).__name__}")


def _zeniths(value, name: str, signed: bool) -> np.ndarray:
    try:
        a = np.atleast_1d(np.asarray(value, dtype=np.float64))
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected a sequence of zenith angles in degrees, got {value!r}") from None
    lo_ok = (a > -90.0) if signed else (a >= 0.0)
    if a.ndim != 1 or a.size == 0 or not np.all(lo_ok & (a < 90.0)):
        raise ValueError(f"{name}: expected a non-empty 1D sequence of zenith angles in "
                         f"{'(-90, 90)' if signed else '[0, 90)'} degrees, got {value!r}")
    return a


def plot_brf_principal_plane(scene: Scene, sun, view_zenith: Sequence[float] = tuple(range(-80, 81, 10)),
                             spp: int = 16384, max_depth: int = 10, seed: int = 0,
                             n_threads: Optional[int] = None, ax=None, label: Optional[str] = None,
                             **kwargs):
    """Draw the BRF in the principal plane, with its standard errors.

    The view moves in the vertical plane that contains the sun: a positive
    view zenith is on the sun's side (view azimuth = sun azimuth; the
    hot spot of rough surfaces is at ``+sun zenith``), a negative one on the
    opposite side (forward scattering).

    Parameters
    ----------
    scene : Scene
        The scene.
    sun : (float, float)
        Direction towards the sun, ``(azimuth, zenith)`` in degrees.
    view_zenith : sequence of float
        Signed view zeniths, degrees in (-90, 90).
    spp, max_depth, seed, n_threads
        As in ``Scene.brf`` (one call per view zenith, same seed).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; a new figure when omitted.
    label : str, optional
        Legend label of the curve.
    **kwargs
        Passed to ``Scene.brf`` (e.g. ``sky``).

    Returns
    -------
    matplotlib.axes.Axes
        Its first line holds the plotted data: x the signed view zeniths,
        y the BRF values (the error bars are ``+-`` one standard error).

    Examples
    --------
    >>> import numpy as np
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from fractalgeo_rs.radiometry import Lambertian, Scene, plot_brf_principal_plane
    >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.3))
    >>> ax = plot_brf_principal_plane(s, sun=(90.0, 30.0), view_zenith=[-45, 0, 45], spp=100)
    >>> ax.lines[0].get_ydata().round(6).tolist()
    [0.3, 0.3, 0.3]
    >>> plt.close("all")

    References
    ----------
    F. E. Nicodemus et al., NBS Monograph 160, 1977 (principal plane and
    reflectance factor); M. Datcu and K. Seidel, 1995 (see ``Scene``).
    """
    plt = require("matplotlib.pyplot")
    _check_scene(scene)
    az_s, zen_s = _sun(sun)
    vz = _zeniths(view_zenith, "view_zenith", signed=True)
    val = np.empty(vz.size)
    se = np.empty(vz.size)
    for i, z in enumerate(vz):
        view = (az_s if z >= 0 else az_s + 180.0, abs(float(z)))
        e = scene.brf(sun=(az_s, zen_s), view=view, spp=spp, max_depth=max_depth, seed=seed,
                      n_threads=n_threads, **kwargs)
        val[i], se[i] = e.value, e.se
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 3.6))
    ax.errorbar(vz, val, yerr=se, marker="o", ms=3, capsize=2,
                label=label if label is not None else f"sun zenith {zen_s:g}")
    ax.axvline(zen_s, color="0.7", lw=0.8, ls=":")
    ax.set_xlabel("view zenith (degrees; + on the sun's side)")
    ax.set_ylabel("BRF")
    return ax


def plot_brf_polar(scene: Scene, sun, view_zenith: Sequence[float] = tuple(range(0, 81, 10)),
                   view_azimuth: Sequence[float] = tuple(range(0, 360, 30)), spp: int = 4096,
                   max_depth: int = 10, seed: int = 0, n_threads: Optional[int] = None, ax=None,
                   cmap: str = "viridis", **kwargs):
    """Draw the BRF over the view hemisphere in polar coordinates.

    Radius: view zenith; angle: view azimuth, clockwise from north (up).
    Each cell of the mesh is coloured by the BRF at the grid node of its
    lower zenith and azimuth (the grid of ``view_zenith`` x
    ``view_azimuth``); the sun is marked with a star.

    Parameters
    ----------
    scene : Scene
        The scene.
    sun : (float, float)
        Direction towards the sun, ``(azimuth, zenith)`` in degrees.
    view_zenith : sequence of float
        View zeniths, degrees in [0, 90), increasing.
    view_azimuth : sequence of float
        View azimuths, degrees clockwise from north, increasing.
    spp, max_depth, seed, n_threads
        As in ``Scene.brf`` (one call per direction, same seed).
    ax : matplotlib.axes.Axes, optional
        Polar axes to draw into; new ones when omitted.
    cmap : str
        Colour map.
    **kwargs
        Passed to ``Scene.brf`` (e.g. ``sky``).

    Returns
    -------
    matplotlib.axes.Axes
        ``ax.collections[0].get_array()`` holds the BRF, shape
        ``(len(view_zenith), len(view_azimuth))``.

    Examples
    --------
    >>> import numpy as np
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from fractalgeo_rs.radiometry import Lambertian, Scene, plot_brf_polar
    >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.3))
    >>> ax = plot_brf_polar(s, sun=(90.0, 30.0), view_zenith=[0, 30], view_azimuth=[0, 120, 240], spp=50)
    >>> np.asarray(ax.collections[0].get_array()).round(6).tolist()
    [[0.3, 0.3, 0.3], [0.3, 0.3, 0.3]]
    >>> plt.close("all")

    References
    ----------
    F. E. Nicodemus et al., NBS Monograph 160, 1977.
    """
    plt = require("matplotlib.pyplot")
    _check_scene(scene)
    az_s, zen_s = _sun(sun)
    vz = _zeniths(view_zenith, "view_zenith", signed=False)
    try:
        va = np.atleast_1d(np.asarray(view_azimuth, dtype=np.float64))
    except (TypeError, ValueError):
        raise TypeError(f"view_azimuth: expected a sequence of azimuths in degrees, got {view_azimuth!r}") from None
    if va.ndim != 1 or va.size == 0 or not np.all(np.isfinite(va)):
        raise ValueError(f"view_azimuth: expected a non-empty 1D sequence of finite azimuths, got {view_azimuth!r}")
    if np.any(np.diff(vz) <= 0):
        raise ValueError(f"view_zenith: expected increasing zeniths, got {view_zenith!r}")
    if np.any(np.diff(va) <= 0) or va[-1] >= va[0] + 360.0:
        raise ValueError(f"view_azimuth: expected increasing azimuths spanning less than 360 degrees, "
                         f"got {view_azimuth!r}")
    val = np.empty((va.size, vz.size))
    for i, a in enumerate(va):
        for j, z in enumerate(vz):
            val[i, j] = scene.brf(sun=(az_s, zen_s), view=(float(a), float(z)), spp=spp, max_depth=max_depth,
                                  seed=seed, n_threads=n_threads, **kwargs).value
    if ax is None:
        _, ax = plt.subplots(figsize=(4.6, 4.2), subplot_kw={"projection": "polar"})
    # cell edges: the nodes, closed by one more step (zenith capped below 90)
    za = np.append(vz, min(89.999, vz[-1] + (vz[-1] - vz[-2] if vz.size > 1 else 10.0)))
    aa = np.append(va, va[0] + 360.0)
    mesh = ax.pcolormesh(np.radians(aa), za, val.T, cmap=cmap, shading="flat")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.plot([np.radians(az_s)], [zen_s], "*", color="orange", ms=12, mec="k")
    ax.set_ylim(0, za[-1])
    ax.figure.colorbar(mesh, ax=ax, shrink=0.8, label="BRF")
    return ax


def plot_incidence_series(scene: Scene, sun_zenith: Sequence[float] = PAPER_SUN_ZENITHS,
                          sun_azimuth: float = 0.0, view="nadir", shape=None, spp: int = 16,
                          max_depth: int = 10, seed: int = 0, n_threads: Optional[int] = None,
                          axes=None, white: Optional[float] = None, **kwargs):
    """Draw the images of the scene for a series of sun zeniths (the
    incidence series of figure 9 of the seed paper).

    Every image is shown on one grey scale, from 0 to ``white``, so the
    darkening with incidence is visible.

    Parameters
    ----------
    scene : Scene
        The scene.
    sun_zenith : sequence of float
        Sun zeniths, degrees in [0, 90); default 0, 15, ..., 75, 89.
    sun_azimuth : float
        Sun azimuth, degrees clockwise from north (default 0, north: the
        default of ``Scene.brf_sweep`` and ``fractalgeo brf``).
    view, shape, spp, max_depth, seed, n_threads
        As in ``Scene.render``.
    axes : sequence of matplotlib.axes.Axes, optional
        One axes per sun zenith; a new row of axes when omitted.
    white : float, optional
        Radiance shown as white; default the largest pixel of the series.
    **kwargs
        Passed to ``Scene.render_series`` (e.g. ``sky``, ``psf``), which
        renders the series in one pass (each image equals ``Scene.render``
        at its sun).

    Returns
    -------
    list of matplotlib.axes.Axes
        ``axes[k].images[0].get_array()`` is the image for ``sun_zenith[k]``.

    Examples
    --------
    >>> import numpy as np
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from fractalgeo_rs.radiometry import Lambertian, Scene, plot_incidence_series
    >>> s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(1.0))
    >>> axes = plot_incidence_series(s, sun_zenith=[0, 60], spp=2)
    >>> [round(float(a.images[0].get_array().mean() * np.pi), 6) for a in axes]  # cos(zenith)
    [1.0, 0.5]
    >>> plt.close("all")

    References
    ----------
    M. Datcu and K. Seidel, 1995 (see ``Scene``), figure 9.
    """
    plt = require("matplotlib.pyplot")
    _check_scene(scene)
    zs = _zeniths(sun_zenith, "sun_zenith", signed=False)
    images = scene.render_series([(sun_azimuth, float(z)) for z in zs], view=view, shape=shape, spp=spp,
                                 max_depth=max_depth, seed=seed, n_threads=n_threads, **kwargs)
    if axes is None:
        fig, axes = plt.subplots(1, zs.size, figsize=(2.0 * zs.size, 2.3), squeeze=False)
        axes = list(axes[0])
    else:
        axes = list(np.ravel(axes))
        if len(axes) != zs.size:
            raise ValueError(f"axes: expected {zs.size} axes (one per sun zenith), got {len(axes)}")
    top = float(max(img.max() for img in images)) if white is None else float(white)
    if not top > 0:
        top = 1.0
    for a, z, img in zip(axes, zs, images):
        a.imshow(img, cmap="gray", vmin=0.0, vmax=top, interpolation="nearest")
        a.set_title(f"sun zenith {z:g}", fontsize=9)
        a.set_xticks([])
        a.set_yticks([])
    return axes
