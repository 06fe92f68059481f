"""Fractional Brownian motion in 1D and fractional Brownian surfaces in 2D."""
from __future__ import annotations

import functools
import math

import numpy as np
import scipy.fft as sfft

from fractalgeo_rs import _core, _progress
from fractalgeo_rs._validation import (
    MemoryLimitError,
    check_choice,
    check_memory,
    check_n_threads,
    check_positive_int,
    resolve_max_memory,
)
from fractalgeo_rs.synth import _additions
from fractalgeo_rs.synth import _common as c

__all__ = ["fbm", "fbm_surface"]


def _workers(n_threads):
    return n_threads if n_threads is not None else -1


def _noise(n, seed, stream, n_threads, steps=None):
    steps = steps if steps is not None else _progress.Steps(0, "", False)
    return steps.counted(lambda pr: _core.normal_noise(int(n), seed, stream, 0, n_threads, pr), int(n))


# --------------------------------------------------------------------- 1D

def fbm(n, hurst, *, method="exact", seed=None, sigma=1.0, n_threads=None, max_memory=None,
        progress=None):
    r"""Sample fractional Brownian motion :math:`B_H` at ``n`` equally spaced times.

    The output starts at 0: ``x[0] = 0`` and ``x[k] = B_H(k)`` for
    ``k = 0 .. n-1`` (unit time step), with

    .. math:: \operatorname{Var}[B_H(t+k) - B_H(t)] = \sigma^2 |k|^{2H}

    (seed paper eq. 19). The increments ``np.diff(x)`` are fractional Gaussian
    noise (fGn) with autocovariance
    :math:`\gamma(k) = \tfrac{\sigma^2}{2}(|k+1|^{2H} - 2|k|^{2H} + |k-1|^{2H})`.
    ``H = 0.5`` is ordinary Brownian motion. The graph of ``x`` has the
    dimension ``D = 2 - H`` (``D = T + (3 - beta) / 2`` with ``T = 1``,
    ``beta = 2H + 1``).

    Parameters
    ----------
    n : int
        Number of samples, at least 2 (``n - 1`` increments).
    hurst : float
        Hurst exponent ``H`` in (0, 1).
    method : {"exact", "midpoint", "additions", "spectral"}
        * ``"exact"``: circulant embedding of fGn (Davies & Harte 1987), exact
          covariance, ``O(n log n)``, real FFTs in Rust;
        * ``"midpoint"``: random midpoint displacement with the variance
          schedule of eq. 20, :math:`\sigma_n^2 = \sigma_{n-1}^2 / 2^{2H}`
          (Peitgen & Saupe 1988), started from 9 exact samples; neighbour
          increments have the exact variance, longer lags are approximate;
        * ``"additions"``: Voss's successive random additions (Voss 1985): at
          each level the new midpoints are interpolated and every sample
          receives a Gaussian addition;
        * ``"spectral"``: Gaussian white noise filtered by
          :math:`|f|^{-\beta/2}`, :math:`\beta = 2H + 1` (seed paper eq. 21-22),
          scaled so the lag-1 increments have variance :math:`\sigma^2`; the
          result is periodic (``x[-1]`` continues into ``x[0]``) up to the
          removal of ``x[0]``.
    seed : int or None
        Seed in ``[0, 2**64)``. A seed gives the same result on every machine
        and for any ``n_threads`` (counter-based generator). ``None`` draws a
        fresh seed.
    sigma : float
        Standard deviation of the unit-lag increments (units of ``x``).
    n_threads : int or None
        Threads of the Rust kernels and of the FFT; ``None`` uses all cores.
    max_memory : int or None
        Limit in bytes for the working memory, estimated before anything is
        allocated as ``BYTES_PER_SAMPLE_1D = 64`` bytes per sample (every
        method; see ``fbm_memory_bytes``); above it a ``MemoryError`` (also a
        ``ValueError``) naming ``n`` is raised. ``None``: the package default
        (half the available memory, ``$FRACTALGEO_MAX_MEMORY`` to override;
        docs/input_policy.md).
    progress : bool or None
        A tqdm bar on stderr (``pip install "fractalgeo_rs[progress]"``)
        moved by the Rust kernels as they draw and refine the samples;
        ``None`` or ``False``: no bar. The samples are the same with and
        without a bar.

    Returns
    -------
    numpy.ndarray
        float64, shape ``(n,)``, ``x[0] == 0``.

    References
    ----------
    Davies, R. B. & Harte, D. S. (1987). Tests for Hurst effect. Biometrika 74, 95-101.
    Voss, R. F. (1985, 1988). Random fractal forgeries; Fractals in nature. In
    Peitgen & Saupe (eds.), The Science of Fractal Images, Springer 1988, ch. 1-2.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> x = fg.fbm(1025, 0.7, method="midpoint", seed=1)
    >>> x.shape, float(x[0])
    ((1025,), 0.0)
    """
    n = check_positive_int(n, "n")
    if n < 2:
        raise ValueError(f"n: need at least 2 samples, got {n}")
    h = c.check_hurst(hurst)
    check_choice(method, "method", c.METHODS)
    seed = c.resolve_seed(seed)
    sigma = c.check_sigma(sigma)
    n_threads = check_n_threads(n_threads)
    check_memory(fbm_memory_bytes(n), "n", max_memory=max_memory, what=f"n={n} samples")
    show = _progress.resolve(progress)
    # Bar units: samples, n per pass (exact: eigenvalues and path; spectral:
    # noise, forward and inverse FFT; midpoint: the refinement).
    passes = {"exact": 2, "spectral": 3}.get(method, 1)
    with _progress.Steps(passes * n, f"fbm ({method})", show) as steps:
        if method == "exact":
            x = _fbm_exact(n, h, seed, n_threads, steps)
        elif method == "spectral":
            x = _fbm_spectral(n, h, seed, n_threads, steps)
        else:
            x = _fbm_midpoint(n, h, seed, method == "additions", n_threads, steps)
    x = x * sigma
    x -= x[0]
    return x


#: Bytes per sample at the peak of ``fbm`` (any method): the noise or the
#: spectrum (16), the FFT or refinement buffers (8 per sample of a length up
#: to twice ``n``), the cumulated path and the scaled copy (16).
BYTES_PER_SAMPLE_1D = 64


def fbm_memory_bytes(n):
    """Estimated peak working memory (bytes) of ``fbm(n, ...)``."""
    return BYTES_PER_SAMPLE_1D * int(n)


def fgn_autocovariance(k, hurst):
    """Autocovariance of unit fractional Gaussian noise at integer lags ``k``."""
    k = np.abs(np.asarray(k, dtype=np.float64))
    h2 = 2.0 * hurst
    return 0.5 * (np.abs(k + 1) ** h2 - 2 * k**h2 + np.abs(k - 1) ** h2)


@functools.lru_cache(maxsize=16)
def _davies_harte_sqrt_eig(m: int, hurst: float) -> np.ndarray:
    """sqrt(lambda_k / 2m), k = 0 .. m, of the circulant embedding of unit fGn
    (Rust real FFT of the symmetric circulant row); cached read-only."""
    out = _core.fgn_sqrt_eigenvalues(m, hurst)
    out.setflags(write=False)
    return out


def _fbm_exact(n, h, seed, n_threads, steps=None):
    # Davies & Harte (1987) in the form of Wood & Chan (1994): a Hermitian
    # random vector W with E|W_k|^2 = lambda_k / (2m) (lambda: eigenvalues of
    # the circulant of size 2m holding the fGn autocovariance), whose inverse
    # real FFT has exactly the fGn covariance on its first m entries. Noise,
    # FFT and cumulative sum run in Rust (rust/synth/davies_harte.rs).
    m = sfft.next_fast_len(n - 1, real=True)
    m += m % 2
    steps = steps if steps is not None else _progress.Steps(0, "", False)
    s = _davies_harte_sqrt_eig(m, h)
    steps.step(n)
    return steps.counted(lambda pr: _core.davies_harte_fbm(s, n, seed, c.STREAM_EXACT_1D, n_threads, pr), n)


def _spectral_lag1_variance_1d(amp2: np.ndarray, n: int) -> float:
    """Lag-1 increment variance of irfft(amp * rfft(white noise)) of length n."""
    k = np.arange(amp2.size)
    weight = np.full(amp2.size, 2.0)
    weight[0] = 1.0
    if n % 2 == 0:
        weight[-1] = 1.0
    return float(np.sum(weight * amp2 * 2 * (1 - np.cos(2 * np.pi * k / n))) / n)


def _fbm_spectral(n, h, seed, n_threads, steps=None):
    steps = steps if steps is not None else _progress.Steps(0, "", False)
    w = _noise(n, seed, c.STREAM_SPECTRAL_1D, n_threads, steps)
    spec = sfft.rfft(w, workers=_workers(n_threads))
    steps.step(n)
    f = np.arange(spec.size) / n
    amp = np.zeros(spec.size)
    amp[1:] = f[1:] ** (-(2 * h + 1) / 2)
    scale = 1.0 / math.sqrt(_spectral_lag1_variance_1d(amp**2, n))
    x = sfft.irfft(spec * (amp * scale), n, workers=_workers(n_threads))
    steps.step(n)
    return x


def _fbm_cov(points_a, points_b, h):
    """fBm covariance of positions (n, d) anchored at the origin (unit sigma)."""
    pa = np.atleast_2d(points_a)
    pb = np.atleast_2d(points_b)
    na = np.linalg.norm(pa, axis=1) ** (2 * h)
    nb = np.linalg.norm(pb, axis=1) ** (2 * h)
    d = np.linalg.norm(pa[:, None, :] - pb[None, :, :], axis=2) ** (2 * h)
    return 0.5 * (na[:, None] + nb[None, :] - d)


def _exact_coarse(points, h, seed, stream, n_threads):
    """Exact fBm values at ``points`` (first point must be the origin)."""
    cov = _fbm_cov(points[1:], points[1:], h)
    chol = np.linalg.cholesky(cov + 1e-12 * np.eye(len(cov)) * cov.diagonal().max())
    z = _noise(len(cov), seed, stream, n_threads)
    return np.concatenate([[0.0], chol @ z])


def _levels_for(span: int, max_coarse: int = 8) -> int:
    """Number of doublings so that the coarse grid has <= max_coarse intervals."""
    if span <= max_coarse:
        return 0
    return int(math.ceil(math.log2(span / max_coarse)))


def _fbm_midpoint(n, h, seed, additions, n_threads, steps=None):
    levels = _levels_for(n - 1)
    step = 2**levels
    n_coarse = -(-(n - 1) // step) + 1
    pos = np.arange(n_coarse, dtype=np.float64)[:, None] * step
    coarse = _exact_coarse(pos, h, seed, c.STREAM_COARSE_1D, n_threads)
    steps = steps if steps is not None else _progress.Steps(0, "", False)
    x = steps.counted(lambda pr: _core.midpoint_refine_1d(coarse, levels, h, 1.0, float(step), additions,
                                                         seed, 0, n_threads, pr), n)
    return np.ascontiguousarray(x[:n])


# --------------------------------------------------------------------- 2D

def fbm_surface(shape, hurst, *, method="exact", seed=None, cell_size=1.0, sigma=1.0,
                periodic=False, n_threads=None, max_memory=None, progress=None):
    r"""Fractional Brownian surface (isotropic fBm on a grid).

    The target statistics are those of 2D fBm,

    .. math:: \operatorname{Var}[Z(\mathbf{x}+\mathbf{h}) - Z(\mathbf{x})] = \sigma^2 |\mathbf{h}|^{2H},

    with :math:`|\mathbf{h}|` in the units of ``cell_size`` (grid lag times
    ``cell_size``): the variogram at a lag of one cell is
    ``sigma**2 * cell_size**(2 * hurst)``. The surface has the fractal
    dimension ``D = 3 - H`` (seed paper eq. 22: ``D = T + (3 - beta) / 2``
    with ``T = 2`` and the radial spectrum slope ``beta = 2H + 2``), and its
    level lines (coastlines) have ``D - 1 = 2 - H``.

    Parameters
    ----------
    shape : int or (int, int)
        ``(rows, cols)``, each at least 2. Any size: the midpoint methods
        refine a coarse grid of at most 9 x 9 exact samples by factors of 2
        until the shape is covered and crop.
    hurst : float
        ``H`` in (0, 1).
    method : {"exact", "midpoint", "additions", "spectral"}
        * ``"exact"``: Stein's (2002) intrinsic circulant embedding: the
          variogram is exactly :math:`\sigma^2|\mathbf{h}|^{2H}` at every lag of
          the grid. Cost grows with the embedding torus, about
          ``(1 + 1.42 R)^2`` times the output (``R = 1`` for ``H <= 0.75``,
          ``R = 2`` above), in memory too.
        * ``"spectral"``: figure 3 of the seed paper: a random matrix (white
          noise), its FFT, the filter :math:`|f|^{-\beta/2}` with
          :math:`\beta = 2H + 2`, the inverse FFT (Voss 1988). The filter is
          that of fBm sampled on the grid: the aliased density
          :math:`\sum_m |f + m|^{-\beta}` plus, in the lowest modes, the
          power of wavelengths longer than the grid, so the variogram
          follows :math:`|h|^{2H}` from lag 1 on (0.1 % to lag 16; below it
          at lags comparable to the grid). The FFT of the
          random matrix is drawn directly with its exact distribution, which
          saves one FFT. Periodic on the
          generated grid; with ``periodic=False`` the grid is padded by a
          quarter in each direction and cropped. Scaled so that the lag-one
          increments have the variance above.
        * ``"midpoint"``: diamond-square random midpoint displacement
          (Fournier, Fussell & Carpenter 1982; Peitgen & Saupe 1988,
          ``MidPointFM2D``) from an exact coarse grid, variance schedule of
          eq. 20 per level; existing samples are kept (the kernel is
          ``_core.midpoint_refine_2d``, reused for fractal resampling).
        * ``"additions"``: Voss's successive random additions in
          diamond-square order with 4-point interpolating rules (tension
          rising with ``H``): cell centres and edge points get displacements,
          old samples and centres additions, with variances derived so that
          second differences have the same variance at every kind of
          position (no creases: crease ratio 1.03-1.07 at 1024²) and the
          lag-one variance is that of fBm (docs/synthesis.md; Dyn, Levin &
          Gregory 1987 for the 4-point rule).
    seed : int or None
        Seed in ``[0, 2**64)``; the same field for any ``n_threads``.
    cell_size : float
        Grid spacing (e.g. metres).
    sigma : float
        Increment standard deviation at unit distance (units of ``Z`` per
        unit of ``cell_size`` to the power ``H``).
    periodic : bool
        Periodic output (the field wraps around both edges). Available for
        ``"spectral"`` (any shape) and for ``"midpoint"``/``"additions"`` when
        the shape is ``(2**k, 2**k)``; ``"exact"`` fBm cannot be periodic.
    n_threads : int or None
        Threads for the Rust kernels and the FFTs; ``None`` = all cores.
    max_memory : int or None
        Limit in bytes for the working memory, estimated before anything is
        allocated (``surface_memory_bytes``): 48 bytes per cell of the
        embedding torus for ``"exact"`` and of the padded grid for
        ``"spectral"``, 32 bytes per cell of the refined grid (which covers
        the shape) for ``"midpoint"`` and ``"additions"``. Above it a
        ``MemoryError`` (also a ``ValueError``) naming ``shape`` is raised.
        ``None``: the package default (half the available memory,
        ``$FRACTALGEO_MAX_MEMORY`` to override; docs/input_policy.md).
    progress : bool or None
        A tqdm bar on stderr (``pip install "fractalgeo_rs[progress]"``)
        over the work in grid cells: the random numbers drawn, each
        refinement level, each FFT. The Rust kernels tick while they run
        (GIL released, the bar is updated every 0.1 s). ``None``/``False``:
        no bar. The field is the same with and without it.

    Returns
    -------
    numpy.ndarray
        float64, shape ``(rows, cols)``; ``z[0, 0] == 0`` for ``"exact"``,
        ``"midpoint"`` and ``"additions"`` (non-periodic).

    References
    ----------
    Stein, M. L. (2002). Fast and exact simulation of fractional Brownian
    surfaces. J. Comput. Graph. Statist. 11(3), 587-599.
    Peitgen, H.-O. & Saupe, D. (eds.) (1988). The Science of Fractal Images. Springer.
    Voss, R. F. (1985). Random fractal forgeries. In Fundamental Algorithms for
    Computer Graphics, Springer, 805-835.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> z = fg.fbm_surface((100, 150), 0.8, method="additions", seed=3)
    >>> z.shape
    (100, 150)
    """
    rows, cols = c.check_shape(shape)
    h = c.check_hurst(hurst)
    check_choice(method, "method", c.METHODS)
    seed = c.resolve_seed(seed)
    cell = c.check_cell_size(cell_size)
    sigma = c.check_sigma(sigma)
    n_threads = check_n_threads(n_threads)
    if not isinstance(periodic, (bool, np.bool_)):
        raise TypeError(f"periodic: expected a bool, got {periodic!r}")
    show = _progress.resolve(progress)
    # All kernels work in units of cells with unit sigma; physical scale last.
    scale = sigma * cell**h
    if method == "exact":
        if periodic:
            raise ValueError('periodic: fBm is not periodic; "exact" cannot give periodic output '
                             '(use method="spectral")')
        _check_exact_memory(rows, cols, h, max_memory)
        n0, n1, _ = _stein_torus(rows, cols, h)
        with _progress.Steps(5 * n0 * n1, "fbm_surface (exact)", show) as steps:
            z = _surface_exact(rows, cols, h, seed, n_threads, steps)
        if scale != 1.0:
            z *= scale
        return z
    check_memory(surface_memory_bytes((rows, cols), h, method, bool(periodic)), "shape",
                 max_memory=max_memory, what=f"method={method!r} on a {rows} x {cols} grid")
    if method == "spectral":
        n0, n1 = _spectral_grid(rows, cols, bool(periodic))
        total = 2 * n0 * (n1 // 2 + 1) + n0 * n1
        with _progress.Steps(total, "fbm_surface (spectral)", show) as steps:
            z = _surface_spectral(rows, cols, h, seed, bool(periodic), n_threads, steps)
    else:
        fr, fc = _midpoint_grid(rows, cols, bool(periodic))
        with _progress.Steps(fr * fc * 4 // 3, f"fbm_surface ({method})", show) as steps:
            z = _surface_midpoint(rows, cols, h, seed, method == "additions", bool(periodic), n_threads,
                                  steps)
    if scale != 1.0:  # x * 1.0 == x: skip a pass over the grid
        z *= scale
    return z


def _surface_midpoint(rows, cols, h, seed, additions, periodic, n_threads, steps=None):
    if periodic:
        k = int(round(math.log2(rows))) if rows > 0 else 0
        if rows != cols or 2**k != rows:
            raise ValueError(f"periodic: the midpoint methods give periodic output for shapes (2**k, 2**k) "
                             f"only, got {(rows, cols)}")
        return _refine(np.zeros((1, 1)), k, h, float(rows), additions, True, seed, n_threads, steps=steps)
    levels = _levels_for(max(rows, cols) - 1)
    step = 2**levels
    nr = max(-(-(rows - 1) // step) + 1, 2)
    nc = max(-(-(cols - 1) // step) + 1, 2)
    ii, jj = np.meshgrid(np.arange(nr), np.arange(nc), indexing="ij")
    pos = np.column_stack([ii.ravel(), jj.ravel()]).astype(np.float64) * step
    coarse = _exact_coarse(pos, h, seed, c.STREAM_COARSE_2D, n_threads).reshape(nr, nc)
    return _refine(coarse, levels, h, float(step), additions, False, seed, n_threads, shape=(rows, cols),
                   steps=steps)


def _refine(coarse, levels, h, spacing, additions, periodic, seed, n_threads, shape=None, steps=None):
    """The refined grid, or its ``shape = (rows, cols)`` corner (the
    additions kernel computes that corner only; midpoint is cropped).
    ``steps``: a :class:`~fractalgeo_rs._progress.Steps` bar whose total
    includes about 4/3 of the final grid's cells for this call."""
    steps = steps if steps is not None else _progress.Steps(0, "", False)
    fr, fc = _refined_shape(coarse.shape, levels, periodic)
    weight = fr * fc * 4 // 3
    if additions:
        w, var = _additions.schedule(h)
        return steps.counted(lambda pr: _core.additions_refine_2d(
            coarse, levels, h, 1.0, spacing, w, list(var), periodic, seed, 0, n_threads, shape, pr), weight)
    z = steps.counted(lambda pr: _core.midpoint_refine_2d(
        coarse, levels, h, 1.0, spacing, False, periodic, seed, 0, n_threads, pr), weight)
    return z if shape is None else np.ascontiguousarray(z[:shape[0], :shape[1]])


def _refined_shape(shape, levels, periodic):
    r, c_ = shape
    for _ in range(levels):
        r, c_ = (2 * r, 2 * c_) if periodic else (2 * r - 1, 2 * c_ - 1)
    return r, c_


@functools.lru_cache(maxsize=2)
def _spectral_amplitude(n0, n1, h):
    """Amplitude filter on the rfft2 grid (``_core.spectral_filter_2d``):
    ``A^2`` is the aliased fBm density ``sum over m of |f + m|^-(2H+2)``
    plus the power of the cell ``f = 0`` in the lowest modes, scaled to unit
    lag-one increment variance along both axes (docs/synthesis.md). Cached
    (read-only) for repeated syntheses of one shape."""
    amp = _core.spectral_filter_2d(int(n0), int(n1), float(h))
    amp.setflags(write=False)
    return amp


def white_noise_rfft2(n0, n1, seed, stream, n_threads, steps=None):
    """A random matrix with the distribution of ``rfft2`` of an (n0, n1) white
    noise matrix (unit variance), drawn directly in the frequency domain.

    Columns ``0 < k1 < n1/2`` are independent complex Gaussians with
    ``E|W|^2 = n0 n1``; the self-conjugate columns (``k1 = 0`` and, for even
    ``n1``, ``k1 = n1/2``) are FFTs along axis 0 of real white noise of
    variance ``n1``, exactly as in ``rfft2``. This saves the forward FFT of
    figure 3 without changing the distribution.
    """
    m = n1 // 2 + 1
    z = _noise(2 * n0 * m, seed, stream, n_threads, steps)
    spec = np.empty((n0, m), dtype=np.complex128)
    half = math.sqrt(n0 * n1 / 2.0)
    spec.real = z[: n0 * m].reshape(n0, m)
    spec.imag = z[n0 * m :].reshape(n0, m)
    spec *= half
    special = [0] + ([m - 1] if n1 % 2 == 0 else [])
    for k, col in enumerate(special):
        real_noise = spec.real[:, col] / half  # unit normals not used elsewhere
        spec[:, col] = sfft.fft(real_noise * math.sqrt(n1))
    return spec


def _surface_spectral(rows, cols, h, seed, periodic, n_threads, steps=None):
    n0, n1 = _spectral_grid(rows, cols, periodic)
    spec = white_noise_rfft2(n0, n1, seed, c.STREAM_SPECTRAL_2D, n_threads, steps)
    spec *= _spectral_amplitude(n0, n1, h)
    z = sfft.irfft2(spec, s=(n0, n1), workers=_workers(n_threads), overwrite_x=True)
    if steps is not None:
        steps.step(n0 * n1)
    if not periodic:
        z = np.ascontiguousarray(z[:rows, :cols])
    return z


def _stein_rho_params(alpha):
    if alpha <= 1.5:
        return 1.0, 0.0, alpha / 2.0, 1.0 - alpha / 2.0  # R, beta, c2, c0
    r = 2.0
    beta = alpha * (2.0 - alpha) / (3.0 * r * (r * r - 1.0))
    c2 = (alpha - beta * (r - 1.0) ** 2 * (r + 2.0)) / 2.0
    c0 = beta * (r - 1.0) ** 3 + 1.0 - c2
    return r, beta, c2, c0


def _stein_rho(dist, alpha, r_max, beta, c2, c0):
    out = np.zeros_like(dist)
    inner = dist <= 1.0
    d = dist[inner]
    out[inner] = c0 - d**alpha + c2 * d * d
    if beta > 0:
        mid = (dist > 1.0) & (dist < r_max)
        d = dist[mid]
        out[mid] = beta * (r_max - d) ** 3 / d
    return out


def _stein_torus(rows, cols, h):
    """Sides (n0, n1) of Stein's embedding torus and the grid step in his units."""
    r_max = _stein_rho_params(2.0 * h)[0]
    unit = 1.0 / math.hypot(rows - 1, cols - 1)  # grid step: the grid's diagonal is 1
    # Torus sides: the image of a lag inside the grid must stay >= R away.
    n0 = sfft.next_fast_len(max(rows, int(math.ceil(r_max / unit)) + rows))
    n1 = sfft.next_fast_len(max(cols, int(math.ceil(r_max / unit)) + cols))
    return n0, n1, unit


#: Bytes per torus cell at the peak of ``_surface_exact``: the complex
#: spectrum (16), the noise pairs (16) and the eigenvalue amplitudes (8), plus
#: 8 for the float64 temporaries of the covariance and the FFT output.
EXACT_BYTES_PER_CELL = 48


def exact_memory_bytes(rows, cols, hurst):
    """Estimated peak working memory (bytes) of ``fbm_surface(..., method="exact")``."""
    n0, n1, _ = _stein_torus(rows, cols, hurst)
    return EXACT_BYTES_PER_CELL * n0 * n1


#: Bytes per cell of the padded grid at the peak of the spectral method: the
#: half spectrum (8 per cell), the noise drawn for it (8), the filter (4),
#: the inverse FFT output (8), the crop (8) and temporaries.
SPECTRAL_BYTES_PER_CELL = 48

#: Bytes per cell of the refined grid at the peak of the midpoint methods:
#: the fine grid and the previous level (10), the crop and the scaled copy.
MIDPOINT_BYTES_PER_CELL = 32


def _spectral_grid(rows, cols, periodic):
    if periodic:
        return rows, cols
    pad = max(rows, cols) // 4
    return (sfft.next_fast_len(rows + pad, real=True), sfft.next_fast_len(cols + pad, real=True))


def _midpoint_grid(rows, cols, periodic):
    if periodic:
        return rows, cols
    step = 2 ** _levels_for(max(rows, cols) - 1)
    nr = max(-(-(rows - 1) // step) + 1, 2)
    nc = max(-(-(cols - 1) // step) + 1, 2)
    return (nr - 1) * step + 1, (nc - 1) * step + 1


def surface_memory_bytes(shape, hurst, method, periodic=False):
    """Estimated peak working memory (bytes) of ``fbm_surface(shape, hurst,
    method=method, periodic=periodic)``, computed without allocating."""
    rows, cols = c.check_shape(shape)
    if method == "exact":
        return exact_memory_bytes(rows, cols, hurst)
    if method == "spectral":
        n0, n1 = _spectral_grid(rows, cols, periodic)
        return SPECTRAL_BYTES_PER_CELL * n0 * n1
    fr, fc = _midpoint_grid(rows, cols, periodic)
    return MIDPOINT_BYTES_PER_CELL * fr * fc


def _check_exact_memory(rows, cols, h, max_memory):
    limit = resolve_max_memory(max_memory)
    need = exact_memory_bytes(rows, cols, h)
    if need > limit:
        n0, n1, _ = _stein_torus(rows, cols, h)
        raise MemoryLimitError(
            f"shape: method=\"exact\" for {(rows, cols)} at hurst={h} embeds the grid in a "
            f"{n0} x {n1} torus and needs about {need / 2**30:.1f} GiB, above max_memory = "
            f"{limit / 2**30:.1f} GiB; use method=\"spectral\" (or \"additions\") for large grids, "
            f"or raise max_memory")


def _surface_exact(rows, cols, h, seed, n_threads, steps=None):
    """Stein's embedding; ``steps`` (total ``5 n0 n1``): covariance and its
    FFT one unit each, the noise two, the final FFT one."""
    steps = steps if steps is not None else _progress.Steps(0, "", False)
    alpha = 2.0 * h
    r_max, beta, c2, c0 = _stein_rho_params(alpha)
    n0, n1, unit = _stein_torus(rows, cols, h)
    l0 = np.arange(n0, dtype=np.float64)
    l1 = np.arange(n1, dtype=np.float64)
    # Periodised covariance: sum over the images that can be within R.
    row = np.zeros((n0, n1))
    for s0 in (0.0, -n0):
        for s1 in (0.0, -n1):
            d = np.hypot((l0 + s0)[:, None] * unit, (l1 + s1)[None, :] * unit)
            row += _stein_rho(d, alpha, r_max, beta, c2, c0)
    steps.step(n0 * n1 // 2)
    lam = sfft.fft2(row, workers=_workers(n_threads)).real
    steps.step(n0 * n1 - n0 * n1 // 2)
    del row
    if lam.min() < -1e-9 * lam.max():  # pragma: no cover - guaranteed by Stein (2002)
        raise RuntimeError("circulant embedding is not non-negative definite")
    np.clip(lam, 0.0, None, out=lam)
    amp = np.sqrt(lam / (n0 * n1))
    del lam
    z = _noise(2 * n0 * n1, seed, c.STREAM_EXACT_2D, n_threads, steps)
    w = np.empty((n0, n1), dtype=np.complex128)
    w.real = z[: n0 * n1].reshape(n0, n1)
    w.imag = z[n0 * n1 :].reshape(n0, n1)
    del z
    w *= amp
    del amp
    y = sfft.fft2(w, workers=_workers(n_threads), overwrite_x=True)
    steps.step(2 * n0 * n1)
    field = np.array(y.real[:rows, :cols])
    del y, w
    field -= field[0, 0]
    lin = _noise(2, seed, c.STREAM_EXACT_2D_LINEAR, n_threads)
    yy = np.arange(rows)[:, None] * unit
    xx = np.arange(cols)[None, :] * unit
    field += math.sqrt(2.0 * c2) * (lin[0] * yy + lin[1] * xx)
    # Variogram now 2 r^alpha (r in Stein units): to cells, unit sigma.
    field *= (1.0 / unit) ** h / math.sqrt(2.0)
    return field
