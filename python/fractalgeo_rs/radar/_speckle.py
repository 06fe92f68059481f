"""Multiplicative speckle (the kernel is Rust: ``_core.speckle_f64``)."""
from __future__ import annotations

import numbers

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._backend import array_kind, run_raster
from fractalgeo_rs._validation import check_n_threads, check_real_array
from fractalgeo_rs._validation import check_seed as resolve_seed

__all__ = ["speckle", "check_looks"]


def check_looks(looks) -> int:
    if isinstance(looks, bool) or not isinstance(looks, numbers.Integral):
        raise TypeError(f"looks: expected an integer >= 1, got {looks!r}")
    if not 1 <= int(looks) <= 1_000_000:
        raise ValueError(f"looks: expected an integer in [1, 1e6], got {looks}")
    return int(looks)


def speckle(intensity, looks=1, seed=None, *, n_threads=None):
    r"""Multiply an intensity image by fully developed speckle.

    A single-look complex pixel of a distributed target is a circular
    Gaussian field, so its intensity is exponential with mean ``sigma0``
    (the amplitude is Rayleigh); the mean of ``L`` independent looks is
    Gamma distributed with shape ``L`` and scale ``sigma0 / L``:

    .. math:: p(I) = \frac{L^L I^{L-1}}{\Gamma(L)\,\sigma_0^L} e^{-L I/\sigma_0},
              \qquad E[I] = \sigma_0,\quad \operatorname{Var}[I] = \sigma_0^2 / L.

    Each look is ``-ln U`` with ``U`` from the package's counter-based
    generator keyed by ``(seed, pixel, look)``, so the image is identical
    for any ``n_threads`` and for any Dask chunking.

    Parameters
    ----------
    intensity : array_like, dask.array.Array or xarray.DataArray, shape (rows, cols)
        Mean intensity (e.g. sigma0, linear), ``>= 0``; NaN = missing (kept).
        Not modified.
    looks : int
        Number of independent looks ``L >= 1`` (1: single-look intensity).
    seed : int or None
        Seed in ``[0, 2**64)``; ``None`` draws one.
    n_threads : int or None
        Threads of the Rust kernel.

    Returns
    -------
    ndarray (or the input's array type), float64
        The speckled intensity.

    References
    ----------
    Goodman, J. W. (1976). Some fundamental properties of speckle. *J. Opt.
    Soc. Am.* 66(11), 1145-1150, doi:10.1364/JOSA.66.001145.
    Oliver, C. & Quegan, S. (1998). *Understanding Synthetic Aperture Radar
    Images*, ch. 4. Artech House.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> y = fg.radar.speckle(np.full((500, 500), 2.0), looks=4, seed=1)
    >>> round(float(y.mean()), 2), round(float(y.var() / 4.0), 2)  # mean 2, variance 2^2 / 4 -> ratio 1/4
    (2.0, 0.25)
    """
    looks = check_looks(looks)
    seed = resolve_seed(seed)
    n_threads = check_n_threads(n_threads)
    kind = array_kind(intensity)
    data = intensity.data if kind == "xarray" else intensity
    lazy = array_kind(data) == "dask"
    a = data if lazy else check_real_array(data, "intensity")
    if a.ndim != 2:
        raise ValueError(f"intensity: expected a 2D array, got shape {a.shape}")
    if a.dtype.kind not in "iuf":
        raise TypeError(f"intensity: expected a real numeric array, got dtype {a.dtype}")
    global_cols = int(a.shape[1])

    def prepare(block):
        b = np.ascontiguousarray(block, dtype=np.float64)
        if np.any(b < 0):
            raise ValueError("intensity: expected values >= 0 (NaN = missing)")
        return b

    def kernel(block, origin):
        r0, c0 = (int(v) for v in origin)
        return _core.speckle_f64(block, looks, seed, (r0, c0), global_cols, n_threads)[None]

    image = intensity.copy(data=a) if kind == "xarray" and not lazy else intensity if kind == "xarray" else a
    return run_raster(kernel, image, depth=0, n_out=1, dtype=np.float64, prepare=prepare, locate=True,
                      attrs={"long_name": f"speckled intensity ({looks} looks)"} if kind == "xarray" else None)[0]
