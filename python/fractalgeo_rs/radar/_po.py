"""Numerical physical optics over synthetic periodic surfaces (numpy FFTs)."""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from fractalgeo_rs._validation import check_n_threads
from fractalgeo_rs.radar._backscatter import check_incidence, check_permittivity, check_positive, check_surface, fresnel
from fractalgeo_rs._validation import check_seed as resolve_seed

__all__ = ["PhysicalOptics", "physical_optics", "surface_realisation"]

_STREAM_GAUSSIAN = 0x7ad0_0001


@dataclass(frozen=True)
class PhysicalOptics:
    """Result of :func:`~fractalgeo_rs.radar.physical_optics`.

    Attributes
    ----------
    incidence : ndarray
        Incidence angles, degrees.
    sigma0 : ndarray
        Mean over realisations of the ring-averaged estimate, linear.
    standard_error : ndarray
        Standard error of that mean (the standard deviation over
        realisations over sqrt(realisations)).
    realisations : int
        Number of surfaces.
    ring_bins : ndarray
        Number of Fourier bins averaged in the ring of each angle.

    References
    ----------
    Beckmann, P. & Spizzichino, A. (1963). *The Scattering of Electromagnetic
    Waves from Rough Surfaces*. Pergamon.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> po = fg.radar.physical_optics([30.0], wavelength=0.056, permittivity=15 + 3j, rms_height=0.0134,
    ...                               correlation_length=0.089, shape=128, realisations=4, seed=1)
    >>> po.sigma0.shape, po.realisations
    ((1,), 4)
    """

    incidence: np.ndarray
    sigma0: np.ndarray
    standard_error: np.ndarray
    realisations: int
    ring_bins: np.ndarray


def surface_realisation(shape, cell_size, *, correlation, rms_height=None, correlation_length=None, hurst=None,
                        topothesy=None, seed=0, n_threads=None):
    r"""One periodic random surface with the statistics of :func:`~fractalgeo_rs.radar.backscatter`.

    ``"gaussian"``: spectral synthesis on the torus, the FFT of white noise
    (drawn by the package's counter-based generator, as
    :func:`fractalgeo_rs.fbm_surface` does) filtered by the square root of
    the Gaussian spectrum :math:`\sigma^2 l^2/(4\pi) e^{-K^2 l^2/4}` (the
    spectrum of :math:`\sigma^2 e^{-\tau^2/l^2}`); ``"fbm"``:
    :func:`fractalgeo_rs.fbm_surface` with ``method="spectral"``,
    ``periodic=True`` and ``sigma = T^(1 - H)`` (structure function
    ``T^(2-2H) tau^(2H)``).

    Parameters
    ----------
    shape : int
        Side ``n`` of the ``n x n`` periodic grid.
    cell_size : float
        Grid spacing, metres.
    correlation, rms_height, correlation_length, hurst, topothesy
        The surface, as in :func:`~fractalgeo_rs.radar.backscatter` (``"gaussian"`` or ``"fbm"``).
    seed : int
        Seed in ``[0, 2**64)``.
    n_threads : int or None
        Threads of the random-number kernel.

    Returns
    -------
    ndarray of float64, shape (n, n)
        Heights in metres.

    References
    ----------
    Voss, R. F. (1988). Fractals in nature. In Peitgen & Saupe (eds.), *The
    Science of Fractal Images*, 21-70. Springer.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> z = fg.radar.surface_realisation(256, 0.01, correlation="gaussian", rms_height=0.02,
    ...                                  correlation_length=0.1, seed=1)
    >>> round(float(z.std()) / 0.02, 1)
    1.0
    """
    from scipy import fft as sfft

    from fractalgeo_rs.synth._fbm import white_noise_rfft2

    surf = check_surface(correlation, rms_height, correlation_length, hurst, topothesy)
    n = int(shape)
    dx = check_positive(cell_size, "cell_size")
    if surf.correlation == "fbm":
        from fractalgeo_rs.synth import fbm_surface

        return fbm_surface((n, n), surf.hurst, method="spectral", periodic=True, seed=seed, cell_size=dx,
                           sigma=surf.topothesy ** (1 - surf.hurst), n_threads=n_threads)
    if surf.correlation != "gaussian":
        raise ValueError("correlation: surface_realisation makes 'gaussian' or 'fbm' surfaces")
    spec = white_noise_rfft2(n, n, seed, _STREAM_GAUSSIAN, n_threads)
    kx = 2 * np.pi * np.fft.fftfreq(n, dx)
    ky = 2 * np.pi * np.fft.rfftfreq(n, dx)
    K2 = kx[:, None] ** 2 + ky[None, :] ** 2
    dk = 2 * np.pi / (n * dx)
    # P(K) = sigma^2 W(K) / (2 pi); E|rfft2|^2 of the white noise is n^2, irfft2 divides by n^2
    psd = surf.sigma ** 2 * surf.l ** 2 / (4 * np.pi) * np.exp(-K2 * surf.l ** 2 / 4)
    spec *= np.sqrt(psd * dk * dk * n * n)
    return sfft.irfft2(spec, s=(n, n))


def physical_optics(incidence, *, wavelength, permittivity, rms_height=None, correlation_length=None,
                    correlation="gaussian", hurst=None, topothesy=None, shape=512, cell_size=None,
                    realisations=16, seed=None, n_threads=None):
    r"""Backscatter by numerical physical optics over synthetic surfaces.

    The Kirchhoff (physical-optics) field scattered back from a surface
    ``z(r)`` of area ``A`` with the stationary-phase polarisation factor is
    one Fourier transform of :math:`e^{i q_z z}`,

    .. math:: \sigma^0 = \frac{k^2 |R(0)|^2}{\pi \cos^2\theta\,A}
              \left\langle\left|\int_A e^{i(\mathbf{q}\cdot\mathbf{r} + q_z z(\mathbf{r}))}
              d\mathbf{r}\right|^2\right\rangle,
              \qquad |\mathbf{q}| = 2k\sin\theta,\ q_z = 2k\cos\theta,

    so each angle costs one FFT of ``exp(i q_z z)`` per periodic synthetic
    surface (:func:`~fractalgeo_rs.radar.surface_realisation`). The FFT bins whose ``|q|`` lies
    within half a bin of ``2 k sin theta`` (a ring: the surfaces are
    isotropic) are averaged, then the realisations; the spread over
    realisations gives the standard error. Its expectation is the Kirchhoff
    integral of :func:`~fractalgeo_rs.radar.backscatter` (``model="kirchhoff"``) up to the
    discretisation of the surface; it checks that integral and gives
    sigma0 for surfaces without a closed form.

    Parameters
    ----------
    incidence : float or array_like
        Incidence angles in degrees; ``2 k sin theta`` must lie between two
        Fourier bins ``2 pi / (shape cell_size)`` and the Nyquist frequency.
    wavelength, permittivity, rms_height, correlation_length, correlation, hurst, topothesy
        As in :func:`~fractalgeo_rs.radar.backscatter` (``correlation`` ``"gaussian"`` or ``"fbm"``).
    shape : int
        Side of the periodic grid, ``>= 16``.
    cell_size : float or None
        Grid spacing in metres; default ``correlation_length / 8``
        (Gaussian) or ``wavelength / 8`` (fBm).
    realisations : int
        Number of surfaces, ``>= 2``.
    seed : int or None
        Seed of the first surface (the others use ``seed + i``).
    n_threads : int or None
        Threads of the surface synthesis.

    Returns
    -------
    PhysicalOptics
        ``sigma0`` (linear) and its ``standard_error`` per angle.

    References
    ----------
    Beckmann, P. & Spizzichino, A. (1963). *The Scattering of Electromagnetic
    Waves from Rough Surfaces*. Pergamon.
    Tsang, L., Kong, J. A., Ding, K.-H. & Ao, C. O. (2001). *Scattering of
    Electromagnetic Waves: Numerical Simulations*, ch. 4. Wiley.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> po = fg.radar.physical_optics([20.0], wavelength=0.056, permittivity=15 + 3j, rms_height=0.0134,
    ...                               correlation_length=0.089, shape=256, realisations=8, seed=1)
    >>> ref = fg.radar.backscatter(20.0, wavelength=0.056, permittivity=15 + 3j, rms_height=0.0134,
    ...                            correlation_length=0.089)
    >>> bool(abs(po.sigma0[0] - ref) < 4 * po.standard_error[0])
    True
    """
    t_deg = np.atleast_1d(check_incidence(incidence)).astype(np.float64)
    wl = check_positive(wavelength, "wavelength")
    eps = check_permittivity(permittivity)
    surf = check_surface(correlation, rms_height, correlation_length, hurst, topothesy)
    if surf.correlation not in ("gaussian", "fbm"):
        raise ValueError("correlation: physical_optics synthesises 'gaussian' or 'fbm' surfaces")
    if isinstance(shape, bool) or not isinstance(shape, numbers.Integral) or shape < 16:
        raise ValueError(f"shape: expected an integer >= 16, got {shape!r}")
    if isinstance(realisations, bool) or not isinstance(realisations, numbers.Integral) or realisations < 2:
        raise ValueError(f"realisations: expected an integer >= 2, got {realisations!r}")
    n = int(shape)
    if cell_size is None:
        dx = surf.l / 8 if surf.correlation == "gaussian" else wl / 8
    else:
        dx = check_positive(cell_size, "cell_size")
    seed = resolve_seed(seed)
    n_threads = check_n_threads(n_threads)
    k = 2 * math.pi / wl
    a = 2 * k * np.sin(np.deg2rad(t_deg))
    dq = 2 * math.pi / (n * dx)
    if np.any(a < 2 * dq) or np.any(a > math.pi / dx - dq):
        raise ValueError(f"incidence: 2 k sin(theta) must lie in [{2 * dq:.4g}, {math.pi / dx - dq:.4g}] rad/m "
                         f"for shape={n}, cell_size={dx:.4g} m; got {a.min():.4g}..{a.max():.4g} "
                         f"(larger shape or smaller cell_size)")
    qx = 2 * math.pi * np.fft.fftfreq(n, dx)
    qabs = np.hypot(qx[:, None], qx[None, :])
    rings = [np.abs(qabs - ai) <= dq / 2 for ai in a]
    counts = np.array([int(r.sum()) for r in rings])
    r0 = abs(fresnel(0.0, eps)) ** 2
    est = np.empty((int(realisations), len(t_deg)))
    area = (n * dx) ** 2
    for i in range(int(realisations)):
        z = surface_realisation(n, dx, correlation=surf.correlation,
                                rms_height=None if surf.correlation == "fbm" else surf.sigma,
                                correlation_length=None if surf.correlation == "fbm" else surf.l,
                                hurst=surf.hurst if surf.correlation == "fbm" else None,
                                topothesy=surf.topothesy if surf.correlation == "fbm" else None,
                                seed=(seed + i) % 2 ** 64, n_threads=n_threads)
        for j, t in enumerate(np.deg2rad(t_deg)):
            qz = 2 * k * math.cos(t)
            F = np.fft.fft2(np.exp(1j * qz * z)) * dx * dx
            power = np.mean(np.abs(F[rings[j]]) ** 2) / area
            est[i, j] = k * k * r0 / (math.pi * math.cos(t) ** 2) * power
    mean = est.mean(axis=0)
    se = est.std(axis=0, ddof=1) / math.sqrt(est.shape[0])
    return PhysicalOptics(t_deg, mean, se, int(realisations), counts)
