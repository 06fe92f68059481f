"""Synthetic DEMs with physical scaling."""
from __future__ import annotations

import math
import numbers

import numpy as np

from fractalgeo_rs.synth import _common as c
from fractalgeo_rs.synth._fbm import fbm_surface

__all__ = ["synthetic_dem", "expected_relief_std"]


def expected_relief_std(shape, hurst, cell_size=1.0, sigma=1.0):
    r"""Expected standard deviation of the heights of fBm over a grid.

    For a field with :math:`\operatorname{Var}[Z(x)-Z(y)] = \sigma^2|x-y|^{2H}`
    the expected spatial variance over the ``N`` grid points is
    :math:`\frac{1}{2N^2}\sum_{x,y}\sigma^2|x-y|^{2H}`, summed here over the
    lag counts ``(rows - |i|)(cols - |j|)`` (on a strided lag lattice for
    grids above 512 cells, relative error below 1e-3).
    :func:`fractalgeo_rs.synthetic_dem` divides by it to give a DEM the
    relief asked for.

    Parameters
    ----------
    shape : (int, int)
        Grid size ``(rows, cols)``, each at least 2.
    hurst : float
        Hurst exponent ``H`` in (0, 1) (``D = 3 - H``).
    cell_size : float, default 1.0
        Grid spacing, in the length unit of the variogram (e.g. metres).
    sigma : float, default 1.0
        Standard deviation of the increments at unit distance, in height
        units (e.g. metres).

    Returns
    -------
    float
        The expected standard deviation of the heights about their mean over
        the grid, in the units of ``sigma``.

    References
    ----------
    Mandelbrot and Van Ness (1968), doi:10.1137/1010093; full entry in the
    :ref:`bibliography <ref-mandelbrot1968>`.

    Examples
    --------
    On a 2 x 2 grid the ordered pairs are 8 at distance 1 and 4 at distance
    ``sqrt(2)``: with ``H = 1/2`` the variance is ``(8 + 4 sqrt(2)) / (2 *
    16) = 0.4268``.

    >>> from fractalgeo_rs.synth import expected_relief_std
    >>> round(expected_relief_std((2, 2), 0.5), 12), round(((8 + 4 * 2 ** 0.5) / 32) ** 0.5, 12)
    (0.653281482438, 0.653281482438)
    >>> round(expected_relief_std((512, 512), 0.7, cell_size=30.0), 1)  # 30 m cells, sigma 1 m at 1 m
    394.2
    """
    rows, cols = c.check_shape(shape)
    h = c.check_hurst(hurst)
    s0 = max(1, rows // 512)
    s1 = max(1, cols // 512)
    i = np.arange(-(rows - 1), rows, s0, dtype=np.float64)
    j = np.arange(-(cols - 1), cols, s1, dtype=np.float64)
    wi = (rows - np.abs(i)) * s0
    wj = (cols - np.abs(j)) * s1
    d = np.hypot(i[:, None], j[None, :]) * cell_size
    total = np.einsum("i,ij,j->", wi, d ** (2 * h), wj)
    n = rows * cols
    return sigma * math.sqrt(total / (2.0 * n * n))


def synthetic_dem(shape, hurst, *, cell_size, relief, relief_lag=None, mean_elevation=0.0,
                  method="exact", seed=None, n_threads=None, progress=None):
    r"""A fractal DEM in physical units (metres).

    The surface is fBm (:func:`fbm_surface`) of Hurst exponent ``H``; its
    fractal dimension is ``D = 3 - H`` (seed paper eq. 22,
    ``D = T + (3 - beta) / 2`` with ``T = 2`` and ``beta = 2H + 2``), so a
    rough terrain of ``D = 2.3`` has ``H = 0.7``. The level lines and lake
    shores have ``D - 1``.

    Parameters
    ----------
    shape : (int, int)
        ``(rows, cols)``.
    hurst : float
        ``H`` in (0, 1).
    cell_size : float
        Grid spacing in metres.
    relief : float
        Relief in metres: with ``relief_lag=None`` the expected standard
        deviation of the heights over the whole grid (see
        :func:`~fractalgeo_rs.synth.expected_relief_std`); otherwise the standard deviation of
        height differences between points ``relief_lag`` metres apart,
        :math:`\sqrt{\operatorname{Var}[Z(x+h)-Z(x)]}` at ``|h| = relief_lag``.
    relief_lag : float or None
        Reference lag in metres.
    mean_elevation : float
        The output is shifted so that its mean is this (metres).
    method, seed, n_threads, progress
        As in :func:`fbm_surface`. The scaling is exact for ``"exact"``; the
        other methods follow the target variogram approximately (see
        ``docs/synthesis.md``).

    Returns
    -------
    numpy.ndarray
        float64 heights in metres, shape ``shape``.

    References
    ----------
    Stein (2002), doi:10.1198/106186002466; full entry in the :ref:`bibliography <ref-stein2002>`.

    Datcu and Seidel (1994), the seed paper; full entry in the :ref:`bibliography <ref-datcu1994>`.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> z = fg.synthetic_dem((64, 64), 0.7, cell_size=30.0, relief=100.0, relief_lag=300.0,
    ...                      mean_elevation=800.0, seed=1)
    >>> round(float(z.mean()), 6)
    800.0
    """
    rows, cols = c.check_shape(shape)
    h = c.check_hurst(hurst)
    cell = c.check_cell_size(cell_size)
    if isinstance(relief, bool) or not isinstance(relief, numbers.Real) or not np.isfinite(relief) or relief <= 0:
        raise ValueError(f"relief: expected a positive number of metres, got {relief!r}")
    if isinstance(mean_elevation, bool) or not isinstance(mean_elevation, numbers.Real) or not np.isfinite(
            mean_elevation):
        raise ValueError(f"mean_elevation: expected a finite number, got {mean_elevation!r}")
    if relief_lag is None:
        sigma = relief / expected_relief_std((rows, cols), h, cell, 1.0)
    else:
        if (isinstance(relief_lag, bool) or not isinstance(relief_lag, numbers.Real)
                or not np.isfinite(relief_lag) or relief_lag <= 0):
            raise ValueError(f"relief_lag: expected a positive number of metres, got {relief_lag!r}")
        sigma = relief / float(relief_lag) ** h
    z = fbm_surface((rows, cols), h, method=method, seed=seed, cell_size=cell, sigma=sigma,
                    n_threads=n_threads, progress=progress)
    z += float(mean_elevation) - z.mean()
    return z
