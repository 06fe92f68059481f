"""Power-spectrum estimator of the dimension of profiles and surfaces.

A profile with Hurst exponent ``H`` has a power spectrum ``P(f) ~ f^-beta``
with ``beta = 2H + 1`` (1D), a surface a radially averaged spectrum with
``beta = 2H + 2`` (2D). With the paper's ``D = T + (3 - beta) / 2`` for the
spectrum of a 1D cut (T = 1 topological dimension of the profile) this gives

    D = (5 - beta) / 2   for profiles,       D = (8 - beta) / 2   for surfaces
                                               (2D radial spectrum).

Using the 1D relation on a 2D radial spectrum (or the reverse) is a known
trap: the two betas of one surface differ by 1.

References
----------
Voss, R. F. (1988). Fractals in nature: from characterization to simulation.
In *The Science of Fractal Images*, Springer, 21-70.
Turcotte, D. L. (1997). *Fractals and Chaos in Geology and Geophysics*, 2nd
ed., Cambridge University Press (chapter 7).
"""
from __future__ import annotations

from typing import Optional

import numpy as np

from fractalgeo_rs._compat import renamed_parameters
from fractalgeo_rs._validation import check_choice, check_positive_int
from fractalgeo_rs.dimension._common import real_array, with_nodata
from fractalgeo_rs.fit import DimensionFit, ScaleRange, fit_loglog

__all__ = ["spectral_dimension"]


def _detrend(z: np.ndarray) -> np.ndarray:
    """Remove the least-squares plane (2D) or line (1D)."""
    if z.ndim == 1:
        x = np.arange(z.size, dtype=float)
        a, b = np.polyfit(x, z, 1)
        return z - (a * x + b)
    # on a full grid the centred row and column indices are orthogonal to
    # each other and to the constant, so the least-squares plane separates:
    # slope along an axis = sum (i - mean i) z / sum (i - mean i)^2
    zc = z - z.mean()
    i = np.arange(z.shape[0], dtype=float) - (z.shape[0] - 1) / 2
    j = np.arange(z.shape[1], dtype=float) - (z.shape[1] - 1) / 2
    bi = (i @ zc.sum(axis=1)) / (z.shape[1] * (i @ i)) if z.shape[0] > 1 else 0.0
    bj = (zc.sum(axis=0) @ j) / (z.shape[0] * (j @ j)) if z.shape[1] > 1 else 0.0
    return zc - bi * i[:, None] - bj * j[None, :]


def _window(shape, kind: str) -> np.ndarray:
    if kind == "none":
        return np.ones(shape)
    w = [np.hanning(n) if kind == "hann" else np.ones(n) for n in shape]
    return w[0] if len(shape) == 1 else np.outer(w[0], w[1])


@renamed_parameters({"window": "taper"}, since="0.2.0")
def spectral_dimension(
    data,
    *,
    taper: str = "hann",
    detrend: bool = True,
    n_bins: int = 24,
    nodata: Optional[float] = None,
    scale_range: ScaleRange = "default",
) -> DimensionFit:
    """Fractal dimension from the slope of the power spectrum.

    Parameters
    ----------
    data : array_like, shape (n,) or (rows, cols)
        Profile or surface on a regular grid, without gaps (NaN or ``nodata``
        raise ValueError: fill or crop first, the FFT needs every sample).
    taper : {"hann", "none"}, default "hann"
        Taper against leakage (a separable Hann window in 2D); the same name
        as in :func:`~fractalgeo_rs.whittle`. (Called ``window`` before
        0.2.0; the old name still works, with a DeprecationWarning.)
    detrend : bool, default True
        Remove the least-squares line or plane first.
    n_bins : int, default 24
        The log-periodogram is averaged in this many logarithmic frequency
        bins (so the many high frequencies do not dominate the fit); empty
        bins are dropped. Each bin holds the geometric mean of its ordinates,
        so every bin carries the same bias of the log-periodogram.
    scale_range : None, "default", "auto" or (low, high)
        Frequencies (cycles per sample) used in the fit. ``"default"`` fits
        from 4 cycles per record (``4 / N``, N the shorter side) to 0.25 cycles
        per sample: the lowest frequencies are few and leak, the highest are
        inflated by aliasing of the sampled field. ``None`` fits every bin.

    Returns
    -------
    DimensionFit
        ``scales`` are frequencies in cycles per sample, ``measures`` the mean
        power per bin; ``extra["beta"]`` is ``-slope`` and ``extra["hurst"]``
        ``(beta - 1) / 2`` (1D) or ``(beta - 2) / 2`` (2D).

    References
    ----------
    Voss (1988), doi:10.1007/978-1-4612-3784-6_1; full entry in the
    :ref:`bibliography <ref-voss1988>`.

    Datcu and Seidel (1994), the seed paper; full entry in the :ref:`bibliography <ref-datcu1994>`.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> z = fg.fbm_surface((256, 256), 0.7, method='exact', seed=1)  # D = 3 - H = 2.3
    >>> round(fg.spectral_dimension(z).dimension, 1)  # the periodogram slope is biased on small grids
    2.4
    >>> x = fg.fbm(4096, 0.5, method='exact', seed=0)  # a profile: D = 2 - H = 1.5
    >>> round(fg.spectral_dimension(x).dimension, 1)
    1.5
    """
    z = with_nodata(real_array(data, (1, 2)), data, nodata)
    if np.isnan(z).any():
        raise ValueError("data: NaN or nodata present; the spectrum needs gap-free data (fill or crop first)")
    check_choice(taper, "taper", ("hann", "none"))
    n_bins = check_positive_int(n_bins, "n_bins")
    if n_bins < 3 or n_bins > z.size:
        raise ValueError(f"n_bins: expected 3 to {z.size} frequency bins (at most one per sample of the "
                         f"{'x'.join(map(str, z.shape))} data), got {n_bins}")
    if min(z.shape) < 8:
        raise ValueError(f"data: shape {z.shape} is too small for a spectrum (at least 8 samples per axis)")
    from scipy import fft

    magnitude = float(np.max(np.abs(z)))
    if detrend:
        z = _detrend(z)
    # degenerate data (constant, or a line/plane removed by the detrend): only
    # rounding noise is left, whose white spectrum would give D = 2.5 or 4
    if not np.ptp(z) > 1e-10 * max(magnitude, 1e-300):
        raise ValueError("data: no variation left" + (" after removing the least-squares line/plane"
                         if detrend else "") + " (constant or planar data has no fractal dimension)")
    z = z * _window(z.shape, taper)
    if z.ndim == 1:
        power = np.abs(fft.rfft(z)) ** 2
        freq = fft.rfftfreq(z.size)
        offset, factor, hurst_of_beta = 2.5, 0.5, lambda b: (b - 1) / 2
    else:
        power = np.abs(fft.rfft2(z)) ** 2
        fy = fft.fftfreq(z.shape[0])[:, None]
        fx = fft.rfftfreq(z.shape[1])[None, :]
        freq = np.hypot(fy, fx)
        offset, factor, hurst_of_beta = 4.0, 0.5, lambda b: (b - 2) / 2
    freq, power = freq.ravel(), power.ravel()
    keep = (freq > 0) & (freq <= 0.5)
    freq, power = freq[keep], power[keep]
    edges = np.geomspace(freq.min(), 0.5 * (1 + 1e-12), n_bins + 1)
    idx = np.clip(np.searchsorted(edges, freq, side="right") - 1, 0, n_bins - 1)
    cnt = np.bincount(idx, minlength=n_bins)
    ok = cnt > 0
    f_mean = np.exp(np.bincount(idx, weights=np.log(freq), minlength=n_bins)[ok] / cnt[ok])
    # geometric mean per bin: log-periodogram ordinates of every bin then carry
    # the same bias (-Euler's gamma), whereas the log of an arithmetic mean is
    # biased less in wide bins than in narrow ones and flattens the slope
    p_mean = np.exp(np.bincount(idx, weights=np.log(np.maximum(power, 1e-300)), minlength=n_bins)[ok] / cnt[ok])
    if isinstance(scale_range, str) and scale_range == "default":
        scale_range = (4.0 / min(z.shape), 0.25)
    fit = fit_loglog(f_mean, p_mean, method="spectral", dim_offset=offset, dim_factor=factor,
                     scale_range=scale_range, x_label="frequency (cycles per sample)",
                     domain=(float(z.ndim), z.ndim + 1.0), open_domain=True,
                     y_label="power", extra={"taper": taper, "detrend": detrend})
    fit.extra["beta"] = -fit.slope
    fit.extra["hurst"] = hurst_of_beta(-fit.slope)
    return fit
