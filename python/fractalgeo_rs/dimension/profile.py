"""Profile estimators: Higuchi, Gaussian scale space, and the wavelet
(detail-variance) estimator for profiles and surfaces.

References
----------
Higuchi, T. (1988). Approach to an irregular time series on the basis of the
fractal theory. *Physica D* 31, 277-283.
Witkin, A. P. (1983). Scale-space filtering. *Proc. IJCAI*, 1019-1022; the
paper's eq. 14 (length of the smoothed signal against sigma).
Flandrin, P. (1992). Wavelet analysis and synthesis of fractional Brownian
motion. *IEEE Trans. Information Theory* 38(2), 910-917.
"""
from __future__ import annotations

import numbers
from typing import Optional, Sequence

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._compat import renamed_parameters
from fractalgeo_rs._validation import as_list, check_n_threads, check_positive_int
from fractalgeo_rs.dimension._common import real_array, with_nodata
from fractalgeo_rs.fit import DimensionFit, ScaleRange, fit_loglog

__all__ = ["higuchi", "scale_space", "wavelet_dimension"]


_HIGUCHI_K_MAX = 8  # default largest interval, from benches/accuracy_higuchi.py


def _gap_free(z: np.ndarray, method: str) -> None:
    if np.isnan(z).any():
        raise ValueError(f"data: NaN or nodata present; {method} needs a gap-free series (fill or crop first)")


def higuchi(data, *, k_max: Optional[int] = None, nodata: Optional[float] = None,
            scale_range: ScaleRange = None, n_threads: Optional[int] = None) -> DimensionFit:
    """Higuchi's (1988) dimension of a profile or time series.

    For ``k = 1 .. k_max`` and offsets ``m = 1 .. k`` the curve length is

    .. math::

        L_m(k) = \\frac{1}{k} \\left( \\sum_{i=1}^{\\lfloor (N-m)/k \\rfloor}
        |x_{m+ik} - x_{m+(i-1)k}| \\right) \\frac{N - 1}{\\lfloor (N-m)/k \\rfloor k},

    ``L(k)`` is its mean over ``m`` and ``L(k) ~ k^-D``. Note the final
    ``1/k``: without it the slope is off by one.

    Parameters
    ----------
    data : array_like, shape (n,)
        Gap-free series (NaN raises ValueError).
    k_max : int, optional
        Largest interval; default ``min(8, n // 10)`` (at least 3): the
        smallest RMSE on exact fBm profiles of 256 to 4096 samples over
        H = 0.1-0.9 (0.024 at n = 1024, against 0.044 with 64; table in
        ``docs/higuchi_kmax.md``, ``benches/accuracy_higuchi.py``; antropy
        uses 10).
    n_threads : int, optional
        Threads of the Rust kernel (default: all cores); the result does not
        depend on it.

    Returns
    -------
    DimensionFit
        ``scales`` are the intervals ``k``, ``measures`` ``L(k)``.

    References
    ----------
    Higuchi (1988), doi:10.1016/0167-2789(88)90081-4; full entry in the
    :ref:`bibliography <ref-higuchi1988>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> round(fg.higuchi(np.arange(1000.0)).dimension, 6)  # a straight line: D = 1
    1.0
    >>> x = fg.fbm(4096, 0.5, method='exact', seed=0)  # Brownian motion: D = 2 - H = 1.5
    >>> round(fg.higuchi(x).dimension, 1)
    1.5
    """
    z = with_nodata(real_array(data, (1,)), data, nodata)
    _gap_free(z, "Higuchi's method")
    n = z.size
    if k_max is None:
        k_max = max(3, min(_HIGUCHI_K_MAX, n // 10))
    k_max = check_positive_int(k_max, "k_max")
    if k_max < 3 or k_max > n // 2:
        raise ValueError(f"k_max: expected an int in [3, {n // 2}] for {n} samples, got {k_max}")
    ks = np.arange(1, k_max + 1)
    # Rust kernel: one streaming pass per k, k values in parallel
    L = _core.higuchi_lengths(np.ascontiguousarray(z, dtype=np.float64), k_max, check_n_threads(n_threads))
    return fit_loglog(ks, L, method="higuchi", domain=(1.0, 2.0), dim_offset=0.0, dim_factor=-1.0, scale_range=scale_range,
                      x_label="interval k (samples)", y_label="curve length L(k)")


_FFT_SIGMA = 6.0  # above this width the filter bank runs through one shared FFT


def _gaussian_bank(z: np.ndarray, sigmas: np.ndarray):
    """Yield ``scipy.ndimage.gaussian_filter1d(z, s, mode="reflect")`` for
    each width (same sampled kernel, radius ``int(4 s + 0.5)``, normalised).

    Narrow kernels are applied directly; wide ones (whose direct cost grows
    with ``s``) as products with the FFT of the signal, reflected once by the
    largest radius and transformed once for all widths. A circular
    convolution of that padded signal equals the linear one on the central
    ``n`` samples because no kernel reaches past the padding; results agree
    with the direct filter to rounding (about 1e-12 relative).
    """
    from scipy import fft as sfft
    from scipy.ndimage import gaussian_filter1d

    z = np.asarray(z, dtype=np.float64)
    n = z.size
    wide = [s for s in sigmas if s > _FFT_SIGMA]
    if wide:
        big = int(4.0 * max(wide) + 0.5)
        if big >= n:
            wide = []  # reflection by more than the profile: use the direct filter
    spec = None
    for s in sigmas:
        if s not in wide:
            yield gaussian_filter1d(z, s, mode="reflect")
            continue
        if spec is None:
            y = np.pad(z, big, mode="symmetric")  # scipy's "reflect": d c b a | a b c d
            size = sfft.next_fast_len(y.size, real=True)
            spec = sfft.rfft(y, size)
        r = int(4.0 * s + 0.5)
        k = np.arange(-r, r + 1, dtype=np.float64)
        w = np.exp(-0.5 * (k / s) ** 2)
        w /= w.sum()
        kern = np.zeros(size)
        kern[: r + 1] = w[r:]
        kern[size - r:] = w[:r]
        yield sfft.irfft(spec * sfft.rfft(kern), size)[big:big + n]


@renamed_parameters({"sample_spacing": "cell_size"}, since="0.2.0")
def scale_space(data, *, sigmas: Optional[Sequence[float]] = None, cell_size: float = 0.0,
                nodata: Optional[float] = None, scale_range: ScaleRange = None) -> DimensionFit:
    """Gaussian scale-space dimension of a profile (the paper's eq. 14).

    The profile is smoothed by Gaussians of width ``sigma`` (samples) and the
    length of the smoothed curve ``L(sigma) = sum sqrt(dx^2 + dg^2)`` is
    measured; a fractal curve has ``L(sigma) ~ sigma^(1 - D)``.

    Parameters
    ----------
    data : array_like, shape (n,)
        Gap-free profile (NaN raises ValueError).
    sigmas : sequence of float, optional
        Gaussian widths in samples; default ``1, 1.5, 2, 3, ...`` (ratio
        sqrt 2) up to ``n / 16`` or 256, whichever is smaller (the filter's
        cost grows with sigma).
    cell_size : float, default 0
        Distance between samples in the units of the values (e.g. metres for
        a height profile in metres). The length of a self-affine graph mixes
        both axes and its scaling depends on their ratio; with the default 0
        the length is the total variation ``sum |dg|``, the steep-graph limit
        in which ``L ~ sigma^(H - 1) = sigma^(1 - D)`` holds at every scale.
        (Called ``sample_spacing`` before 0.2.0; the old name still works,
        with a DeprecationWarning.)

    Returns
    -------
    DimensionFit
        ``D = 1 - slope``. Edges are handled by reflection
        (``scipy.ndimage.gaussian_filter1d``, mode "reflect").

    References
    ----------
    T. Lindeberg, *Scale-Space Theory in Computer Vision*, Kluwer, 1994,
    doi:10.1007/978-1-4757-6465-9.

    Gneiting, Sevcikova and Percival (2012), doi:10.1214/11-STS370; full entry in the
    :ref:`bibliography <ref-gneiting2012>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> x = fg.fbm(4096, 0.5, method='exact', seed=0)  # D = 2 - H = 1.5
    >>> round(fg.scale_space(x).dimension, 1)
    1.5
    """
    z = with_nodata(real_array(data, (1,)), data, nodata)
    _gap_free(z, "scale space")
    if isinstance(cell_size, bool) or not isinstance(cell_size, numbers.Real) or not cell_size >= 0:
        raise ValueError(f"cell_size: expected a number >= 0, got {cell_size!r}")
    dx = float(cell_size)
    if sigmas is None:
        sigmas = [2 ** (k / 2) for k in range(0, 40) if 2 ** (k / 2) <= min(z.size / 16, 256)]
    try:
        sig = np.asarray(sorted(set(float(s) for s in as_list(sigmas, "sigmas"))))
    except ValueError:
        raise ValueError(f"sigmas: expected positive widths in samples, got {sigmas!r}") from None
    if sig.size < 3 or sig[0] <= 0 or not np.isfinite(sig).all():
        raise ValueError(f"sigmas: need at least 3 distinct positive widths, got {sig.tolist()}")
    lengths = np.array([np.sum(np.hypot(dx, np.diff(g))) for g in _gaussian_bank(z, sig)])
    return fit_loglog(sig, lengths, method="scale_space", domain=(1.0, 2.0), dim_offset=1.0, dim_factor=-1.0,
                      scale_range=scale_range, x_label="sigma (samples)", y_label="length L(sigma)",
                      extra={"cell_size": dx})


def _haar_details(z: np.ndarray):
    """Orthonormal Haar detail coefficients per level (1D or 2D, all three
    orientations pooled in 2D), on the largest dyadic crop."""
    a = z
    levels = []
    while min(a.shape) >= 2:
        if a.ndim == 1:
            m = (a.shape[0] // 2) * 2
            e, o = a[0:m:2], a[1:m:2]
            levels.append((e - o) / np.sqrt(2))
            a = (e + o) / np.sqrt(2)
        else:
            r, c = (a.shape[0] // 2) * 2, (a.shape[1] // 2) * 2
            a00, a01, a10, a11 = a[0:r:2, 0:c:2], a[0:r:2, 1:c:2], a[1:r:2, 0:c:2], a[1:r:2, 1:c:2]
            h = (a00 - a01 + a10 - a11) / 2
            v = (a00 + a01 - a10 - a11) / 2
            d = (a00 - a01 - a10 + a11) / 2
            levels.append(np.concatenate([h.ravel(), v.ravel(), d.ravel()]))
            a = (a00 + a01 + a10 + a11) / 2
    return levels


def wavelet_dimension(data, *, levels: Optional[Sequence[int]] = None, nodata: Optional[float] = None,
                      scale_range: ScaleRange = None) -> DimensionFit:
    """Wavelet estimator: variance of Haar detail coefficients against scale.

    For fBm the orthonormal Haar details at scale ``2^j`` have variance
    ``~ 2^(j (2H + 1))`` for profiles and ``~ 2^(j (2H + 2))`` for surfaces
    (Flandrin 1992; the paper's eq. 15), so

        D = 2.5 - slope / 2  (profiles),    D = 4 - slope / 2  (surfaces)

    where ``slope`` is that of ``log var`` against ``log 2^j``.

    Parameters
    ----------
    data : array_like, shape (n,) or (rows, cols)
        Gap-free profile or surface (NaN raises ValueError).
    levels : sequence of int, optional
        Levels ``j`` (1 = finest) in the fit; default every level with at
        least 8 coefficients (1D) or 16 (2D).

    Returns
    -------
    DimensionFit
        ``scales`` are ``2^j`` samples, ``measures`` the detail variances.

    References
    ----------
    P. Flandrin, Wavelet analysis and synthesis of fractional Brownian
    motion, *IEEE Transactions on Information Theory* 38(2) (1992) 910-917,
    doi:10.1109/18.119751.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> x = fg.fbm(4096, 0.5, method='exact', seed=0)  # D = 2 - H = 1.5
    >>> round(fg.wavelet_dimension(x).dimension, 1)
    1.5
    """
    z = with_nodata(real_array(data, (1, 2)), data, nodata)
    _gap_free(z, "the wavelet estimator")
    det = _haar_details(z)
    min_n = 8 if z.ndim == 1 else 48
    js = np.arange(1, len(det) + 1)
    if levels is None:
        sel = [int(j) for j in js if det[j - 1].size >= min_n]
    else:
        sel = sorted(set(check_positive_int(j, "levels") for j in as_list(levels, "levels", "ints")))
        if not sel or sel[0] < 1 or sel[-1] > len(det):
            raise ValueError(f"levels: expected levels in [1, {len(det)}], got {list(levels)}")
    if len(sel) < 3:
        raise ValueError(f"data: shape {z.shape} gives fewer than 3 wavelet levels with enough coefficients")
    var = np.array([np.mean(det[j - 1] ** 2) for j in sel])
    offset = 2.5 if z.ndim == 1 else 4.0
    fit = fit_loglog(2.0 ** np.array(sel), var, method="wavelet", domain=(float(z.ndim), z.ndim + 1.0),
                     open_domain=True, dim_offset=offset, dim_factor=-0.5,
                     scale_range=scale_range, x_label="scale 2^j (samples)", y_label="detail variance")
    fit.extra["hurst"] = (fit.slope - z.ndim) / 2
    return fit
