"""Closed-form and semi-analytic backscatter of rough surfaces.

numpy/scipy, not Rust: each call evaluates a closed form, a short series or a
one-dimensional Hankel transform per incidence angle (microseconds to
milliseconds), vectorised over angles; there is no per-pixel work to move
into a kernel. The scene simulator evaluates these models on a table of
local incidence angles and interpolates (see :func:`~fractalgeo_rs.radar.simulate`).
"""
from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass, field
from typing import Dict

import numpy as np

from fractalgeo_rs._warn import user_stacklevel

__all__ = [
    "RadarValidityWarning",
    "BackscatterValidity",
    "backscatter",
    "fresnel",
    "to_db",
    "validity",
]

MODELS = ("geometric_optics", "kirchhoff", "spm")
CORRELATIONS = ("gaussian", "exponential", "fbm")
POLARIZATIONS = ("hh", "vv", "hv", "vh")


class RadarValidityWarning(UserWarning):
    """A backscatter model was evaluated outside its range of validity.

    The message gives the numbers (k*sigma, k*l, rms slope, radius of
    curvature, wavelength) and the criterion that failed; see
    :func:`~fractalgeo_rs.radar.validity`.

    Attributes
    ----------
    args : tuple
        The message.

    References
    ----------
    Ulaby, F. T., Moore, R. K. & Fung, A. K. (1982). *Microwave Remote
    Sensing*, vol. II, ch. 12. Addison-Wesley.

    Examples
    --------
    >>> import warnings, fractalgeo_rs as fg
    >>> with warnings.catch_warnings(record=True) as rec:
    ...     warnings.simplefilter("always")
    ...     _ = fg.radar.backscatter(30.0, model="spm", wavelength=0.056, permittivity=5 + 0.5j,
    ...                              rms_height=0.01, correlation_length=0.1)
    >>> rec[0].category.__name__
    'RadarValidityWarning'
    """


# ---------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------

def check_positive(value, name, *, allow_none=False):
    if value is None and allow_none:
        return None
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a positive number, got {value!r}")
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name}: expected a positive finite number, got {value!r}")
    return v


def check_incidence(incidence):
    if isinstance(incidence, (str, bytes)):
        raise TypeError(f"incidence: expected degrees (a number or an array), got {incidence!r}")
    try:
        t = np.asarray(incidence, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"incidence: expected degrees (a number or an array), got {incidence!r}") from None
    if not np.all(np.isfinite(t)) or np.any(t < 0) or np.any(t >= 90):
        bad = t[~(np.isfinite(t) & (t >= 0) & (t < 90))]
        raise ValueError(f"incidence: expected degrees in [0, 90), got {bad.ravel()[:3].tolist()}")
    return t


def check_permittivity(permittivity):
    if isinstance(permittivity, bool) or not isinstance(permittivity, numbers.Number):
        raise TypeError(f"permittivity: expected a complex number (relative permittivity), got {permittivity!r}")
    e = complex(permittivity)
    if not (math.isfinite(e.real) and math.isfinite(e.imag)):
        raise ValueError(f"permittivity: expected a finite number, got {permittivity!r}")
    if e.imag < 0:
        raise ValueError(
            f"permittivity: imaginary part {e.imag} < 0; this package uses the exp(-i omega t) time convention, "
            f"where a lossy medium has Im(eps) >= 0 (pass {e.real}+{-e.imag}j, the conjugate, for a value "
            f"written in the exp(+j omega t) engineering convention)")
    if e == 1:
        raise ValueError("permittivity: expected a medium different from vacuum (eps != 1)")
    return e


def _choice(value, name, choices):
    if not isinstance(value, str) or value.lower() not in choices:
        raise ValueError(f"{name}: expected one of {list(choices)}, got {value!r}")
    return value.lower()


# ---------------------------------------------------------------------------
# Fresnel
# ---------------------------------------------------------------------------

def _kz_ratio(eps, theta):
    # sqrt(eps - sin^2 theta), principal branch: Im >= 0 for Im(eps) >= 0,
    # so the transmitted wave exp(i k z') decays into the lower medium
    return np.sqrt(eps - np.sin(theta) ** 2 + 0j)


def fresnel(incidence, permittivity, polarization="h"):
    r"""Fresnel reflection coefficient of a plane interface, air over a medium.

    .. math::

        R_h = \frac{\cos\theta - \sqrt{\varepsilon - \sin^2\theta}}{\cos\theta + \sqrt{\varepsilon - \sin^2\theta}},
        \qquad
        R_v = \frac{\varepsilon\cos\theta - \sqrt{\varepsilon - \sin^2\theta}}
                   {\varepsilon\cos\theta + \sqrt{\varepsilon - \sin^2\theta}}

    (reflected over incident field, the convention of Ulaby & Long 2014:
    ``R_v = -R_h`` at normal incidence, where both reflectivities are
    ``|(1 - sqrt(eps)) / (1 + sqrt(eps))|^2``). **Sign convention**: fields vary in
    time as :math:`e^{-i\omega t}`, so a lossy medium has
    :math:`\operatorname{Im}\varepsilon \ge 0` and the square root is the
    principal one (:math:`\operatorname{Im} \ge 0`: the transmitted wave
    decays into the medium). A permittivity written in the engineering
    convention :math:`e^{j\omega t}` (e.g. ``15 - 3j``) is the conjugate of
    ours: pass ``15 + 3j``; a negative imaginary part is a ValueError. The
    reflectivity :math:`|R|^2` is the same in both conventions, ``R`` is
    conjugated.

    Parameters
    ----------
    incidence : float or array_like
        Incidence angle in degrees, in [0, 90).
    permittivity : complex
        Relative permittivity of the lower medium, ``Im >= 0``.
    polarization : {"h", "v"}
        ``"h"`` (TE) or ``"v"`` (TM).

    Returns
    -------
    complex or ndarray of complex
        The reflection coefficient (a 0-d result for a scalar angle is a
        Python complex).

    References
    ----------
    Born, M. & Wolf, E. (1999). *Principles of Optics*, 7th ed., section 1.5.
    Cambridge University Press.
    Ulaby, F. T. & Long, D. G. (2014). *Microwave Radar and Radiometric Remote
    Sensing*, section 2-7. University of Michigan Press.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> r = fg.radar.fresnel(0.0, 4.0)  # (1 - 2) / (1 + 2)
    >>> round(r.real, 12), round(abs(fg.radar.fresnel(30.0, 15 + 3j, "v")) ** 2, 4)
    (-0.333333333333, 0.3013)
    """
    t = np.deg2rad(check_incidence(incidence))
    eps = check_permittivity(permittivity)
    pol = _choice(polarization, "polarization", ("h", "v", "hh", "vv"))[0]
    root = _kz_ratio(eps, t)
    c = np.cos(t)
    if pol == "h":
        r = (c - root) / (c + root)
    else:
        r = (eps * c - root) / (eps * c + root)
    return complex(r) if np.ndim(r) == 0 else r


def to_db(sigma0):
    """Backscatter in decibels: ``10 log10(sigma0)``.

    Parameters
    ----------
    sigma0 : float or array_like
        Linear backscatter coefficient (m^2/m^2), ``>= 0``; 0 gives -inf.

    Returns
    -------
    float or ndarray
        ``10 log10(sigma0)`` in dB.

    References
    ----------
    Ulaby, F. T. & Long, D. G. (2014). *Microwave Radar and Radiometric Remote
    Sensing*, section 1-6. University of Michigan Press.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> fg.radar.to_db(0.1), fg.radar.to_db([1.0, 100.0]).tolist()
    (-10.0, [0.0, 20.0])
    """
    s = np.asarray(sigma0, dtype=np.float64)
    if np.any(s < 0):
        raise ValueError("sigma0: expected non-negative linear backscatter")
    with np.errstate(divide="ignore"):
        out = 10.0 * np.log10(s)
    return float(out) if out.ndim == 0 else out


# ---------------------------------------------------------------------------
# surface statistics
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class _Surface:
    correlation: str
    sigma: float  # rms height (NaN for fBm)
    l: float  # correlation length (NaN for fBm)
    hurst: float
    topothesy: float

    def structure(self, tau):
        """D(tau) = E[(z(x + tau) - z(x))^2] in m^2."""
        tau = np.asarray(tau, dtype=np.float64)
        if self.correlation == "gaussian":
            return 2 * self.sigma ** 2 * -np.expm1(-(tau / self.l) ** 2)
        if self.correlation == "exponential":
            return 2 * self.sigma ** 2 * -np.expm1(-tau / self.l)
        return self.topothesy ** (2 - 2 * self.hurst) * tau ** (2 * self.hurst)

    def spectrum(self, K):
        """sigma^2 W(K) = int_0^inf C(tau) J0(K tau) tau dtau (m^4); for fBm the
        power-law spectrum whose structure function is D(tau)."""
        K = np.asarray(K, dtype=np.float64)
        if self.correlation == "gaussian":
            return self.sigma ** 2 * self.l ** 2 / 2 * np.exp(-(K * self.l) ** 2 / 4)
        if self.correlation == "exponential":
            return self.sigma ** 2 * self.l ** 2 / (1 + (K * self.l) ** 2) ** 1.5
        h = self.hurst
        s0 = self.topothesy ** (2 - 2 * h) * h * math.gamma(1 + h) * 4 ** h / math.gamma(1 - h)
        with np.errstate(divide="ignore"):
            return s0 * K ** (-2 - 2 * h)


def check_surface(correlation, rms_height, correlation_length, hurst, topothesy):
    corr = _choice(correlation, "correlation", CORRELATIONS)
    if corr == "fbm":
        if hurst is None or topothesy is None:
            raise ValueError("hurst, topothesy: correlation='fbm' needs both (H in (0, 1), topothesy T in metres)")
        if isinstance(hurst, bool) or not isinstance(hurst, numbers.Real) or not 0 < float(hurst) < 1:
            raise ValueError(f"hurst: expected a number in (0, 1), got {hurst!r}")
        for name, v in (("rms_height", rms_height), ("correlation_length", correlation_length)):
            if v is not None:
                raise ValueError(f"{name}: an fBm surface has no {name.replace('_', ' ')}; "
                                 f"give hurst and topothesy only")
        return _Surface("fbm", math.nan, math.nan, float(hurst), check_positive(topothesy, "topothesy"))
    if rms_height is None or correlation_length is None:
        raise ValueError(f"rms_height, correlation_length: correlation={corr!r} needs both (metres)")
    for name, v in (("hurst", hurst), ("topothesy", topothesy)):
        if v is not None:
            raise ValueError(f"{name}: only for correlation='fbm', got {v!r} with correlation={corr!r}")
    return _Surface(corr, check_positive(rms_height, "rms_height"), check_positive(correlation_length, "correlation_length"),
                    math.nan, math.nan)


# ---------------------------------------------------------------------------
# validity
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class BackscatterValidity:
    """Roughness numbers of a surface at a wavelength and the models' ranges.

    Attributes
    ----------
    k_sigma : float
        ``k * rms_height`` (for fBm, ``k * sqrt(D(lambda))``, the rms height
        difference at the scale of the wavelength).
    k_l : float
        ``k * correlation_length`` (NaN for fBm).
    rms_slope : float
        Per-axis rms slope (``sqrt(2) sigma / l`` for the Gaussian
        correlation; ``inf`` for exponential; for fBm the slope at the scale of
        the wavelength, ``(T / lambda)^(1 - H)``).
    radius_of_curvature : float
        ``l^2 / (sqrt(12) sigma)`` for the Gaussian correlation (the
        inverse rms curvature); 0 for exponential (not differentiable); for
        fBm ``lambda^2 / sqrt(D(lambda))``, the radius at the scale of the
        wavelength, metres.
    valid : dict
        Model name -> bool, whether the model is inside its range.
    ranges : dict
        Model name -> the criteria, as text.

    References
    ----------
    Ulaby, F. T., Moore, R. K. & Fung, A. K. (1982). *Microwave Remote
    Sensing*, vol. II, ch. 12. Addison-Wesley.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> v = fg.radar.validity(wavelength=0.056, rms_height=0.01, correlation_length=0.1)
    >>> v.valid
    {'geometric_optics': False, 'kirchhoff': True, 'spm': False}
    """

    wavelength: float
    k_sigma: float
    k_l: float
    rms_slope: float
    radius_of_curvature: float
    valid: Dict[str, bool] = field(default_factory=dict)
    ranges: Dict[str, str] = field(default_factory=dict)

    def __str__(self):
        lines = [f"k*sigma = {self.k_sigma:.4g}, k*l = {self.k_l:.4g}, rms slope = {self.rms_slope:.4g}, "
                 f"radius of curvature = {self.radius_of_curvature:.4g} m (wavelength {self.wavelength:.4g} m)"]
        for m in MODELS:
            lines.append(f"  {m}: {'valid' if self.valid[m] else 'OUTSIDE'} ({self.ranges[m]})")
        return "\n".join(lines)


def _validity(surf, wavelength, incidence_max):
    k = 2 * math.pi / wavelength
    if surf.correlation == "fbm":
        d_lambda = float(surf.structure(wavelength))
        ks = k * math.sqrt(d_lambda)
        kl = math.nan
        slope = (surf.topothesy / wavelength) ** (1 - surf.hurst)
        rc = wavelength ** 2 / math.sqrt(d_lambda)
        valid = {
            "geometric_optics": False,
            "kirchhoff": rc > wavelength,
            "spm": ks < 0.3 and slope < 0.3,
        }
        ranges = {
            "geometric_optics": "needs a finite slope variance: not for fBm (use kirchhoff)",
            "kirchhoff": "radius of curvature at the wavelength scale > wavelength (Franceschetti & Riccio 2007)",
            "spm": "k*sqrt(D(lambda)) < 0.3 and slope at the wavelength scale < 0.3",
        }
    else:
        ks, kl = k * surf.sigma, k * surf.l
        if surf.correlation == "gaussian":
            slope = math.sqrt(2) * surf.sigma / surf.l
            rc = surf.l ** 2 / (math.sqrt(12) * surf.sigma)
        else:
            slope, rc = math.inf, 0.0
        c = math.cos(math.radians(incidence_max))
        ka = kl > 6 and surf.l ** 2 > 2.76 * surf.sigma * wavelength
        valid = {
            "geometric_optics": ka and surf.correlation == "gaussian" and (2 * ks * c) ** 2 > 10,
            "kirchhoff": ka,
            "spm": ks < 0.3 and (slope < 0.3 or surf.correlation == "exponential"),
        }
        ranges = {
            "geometric_optics": "Kirchhoff range and (2 k sigma cos theta)^2 > 10, Gaussian correlation",
            "kirchhoff": "k*l > 6 and l^2 > 2.76 sigma lambda (radius of curvature > ~0.8 lambda)",
            "spm": "k*sigma < 0.3 and rms slope < 0.3" if surf.correlation == "gaussian" else
                   "k*sigma < 0.3 (no slope criterion for the non-differentiable exponential surface)",
        }
    return BackscatterValidity(wavelength, ks, kl, slope, rc, valid, ranges)


def validity(*, wavelength, rms_height=None, correlation_length=None, correlation="gaussian", hurst=None,
             topothesy=None, incidence=0.0):
    """The roughness numbers of a surface at a wavelength and whether each
    backscatter model is inside its range of validity.

    Criteria (Ulaby, Moore & Fung 1982, vol. II, ch. 12; Fung 1994): the
    Kirchhoff approximation needs ``k l > 6`` and ``l^2 > 2.76 sigma
    lambda`` (a radius of curvature larger than about 0.8 wavelength);
    geometric optics in addition ``(2 k sigma cos theta)^2 > 10`` (checked at
    the largest incidence given) and a finite slope variance (Gaussian
    correlation); first-order SPM ``k sigma < 0.3`` and an rms slope
    below 0.3. For an fBm surface the numbers are taken at the scale of the
    wavelength (Franceschetti & Riccio 2007): ``sqrt(D(lambda))`` plays
    ``sigma``, the slope is ``(T / lambda)^(1 - H)`` and the Kirchhoff
    approximation holds while ``lambda^2 / sqrt(D(lambda)) > lambda``,
    i.e. ``T < lambda`` (our reading of their criterion).

    Parameters
    ----------
    wavelength : float
        Radar wavelength in metres.
    rms_height, correlation_length, correlation, hurst, topothesy
        The surface, as in :func:`~fractalgeo_rs.radar.backscatter`.
    incidence : float or array_like
        Incidence angle(s) in degrees (the largest sets the GO criterion).

    Returns
    -------
    BackscatterValidity
        The numbers and, per model, a flag and the criterion as text.

    References
    ----------
    Ulaby, F. T., Moore, R. K. & Fung, A. K. (1982). *Microwave Remote
    Sensing*, vol. II, ch. 12. Addison-Wesley.
    Franceschetti, G. & Riccio, D. (2007). *Scattering, Natural Surfaces and
    Fractals*. Academic Press.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> v = fg.radar.validity(wavelength=0.056, rms_height=0.002, correlation_length=0.02)
    >>> round(v.k_sigma, 3), v.valid["spm"], v.valid["kirchhoff"]
    (0.224, True, False)
    """
    wl = check_positive(wavelength, "wavelength")
    surf = check_surface(correlation, rms_height, correlation_length, hurst, topothesy)
    t = check_incidence(incidence)
    return _validity(surf, wl, float(np.max(t)) if t.size else 0.0)


# ---------------------------------------------------------------------------
# Hankel transform  int_0^inf J0(a tau) f(tau) tau dtau
# ---------------------------------------------------------------------------

_GL_X, _GL_W = np.polynomial.legendre.leggauss(40)


def _j0_zeros(n):
    from scipy.special import jn_zeros

    m = min(n, 200)
    z = jn_zeros(0, m)
    if n > m:
        beta = (np.arange(m + 1, n + 1) - 0.25) * np.pi
        z = np.concatenate([z, beta + 1 / (8 * beta) - 31 / (384 * beta ** 3)])
    return z


def _wynn(s):
    """Wynn's epsilon algorithm on partial sums ``s``: the estimate of the limit."""
    e_prev = np.zeros(len(s) + 1)
    e = np.asarray(s, dtype=np.float64).copy()
    best = e[-1]
    for k in range(1, len(s)):
        diff = e[1:] - e[:-1]
        with np.errstate(divide="ignore", invalid="ignore"):
            new = e_prev[1:len(e)] + 1.0 / diff
        if not np.all(np.isfinite(new)):
            break
        e_prev, e = e, new
        if k % 2 == 0:
            best = e[-1]
    return best


def _hankel(f, a, tau_max, max_intervals=4000):
    """``int_0^inf J0(a tau) f(tau) tau dtau`` for a smooth ``f`` negligible
    beyond ``tau_max``: Gauss-Legendre (40 points) between consecutive zeros of
    ``J0(a tau)``; beyond ``max_intervals`` half-periods the alternating tail
    is summed by Wynn's epsilon algorithm."""
    from scipy.special import j0

    if a == 0:
        edges = np.linspace(0.0, tau_max, 257)
        n_int = len(edges) - 1
    else:
        n_int = int(min(max_intervals, max(4, math.ceil(a * tau_max / math.pi) + 2)))
        edges = np.concatenate([[0.0], _j0_zeros(n_int)]) / a
    lo, hi = edges[:-1], edges[1:]
    half = (hi - lo)[:, None] / 2
    tau = (lo + hi)[:, None] / 2 + half * _GL_X[None, :]
    vals = (j0(a * tau) * f(tau) * tau * half) @ _GL_W
    if a == 0 or n_int < max_intervals or edges[-1] >= tau_max:
        return float(np.sum(vals))
    partial = np.cumsum(vals)
    return float(_wynn(partial[-40:]))


# ---------------------------------------------------------------------------
# the models
# ---------------------------------------------------------------------------

def _hankel_fbm(a, b, h):
    """``int_0^inf J0(a tau) exp(-b tau^2H) tau dtau`` for ``a, b > 0``.

    ``J0 = Re H0^(1)`` on the real axis and ``f = exp(-b tau^2H)`` is real
    there, so the integral is the real part of that of ``H0^(1)(a tau) f
    tau``, which is analytic in the right half-plane. Its contour is turned
    onto the ray ``tau = s e^(i phi)``, where ``H0^(1)`` decays as
    ``exp(-a s sin phi)`` and ``|f| = exp(-b s^2H cos(2 H phi))`` still
    decays (``phi < pi / (4H)``): the oscillating, slowly decaying integral
    becomes a smooth, exponentially decaying one (no tail to sum), evaluated
    by Gauss-Legendre on panels graded geometrically towards 0 (where the
    integrand behaves as ``s log s`` and ``s^(1+2H)``)."""
    from scipy.special import hankel1

    phi = min(math.pi / 3, 0.8 * math.pi / (4 * h))
    rot = complex(math.cos(phi), math.sin(phi))
    rot2h = complex(math.cos(2 * h * phi), math.sin(2 * h * phi))
    s_max = min(46 / (a * math.sin(phi)), (46 / (b * rot2h.real)) ** (1 / (2 * h)))
    inner = s_max * np.logspace(-14, -1, 27)
    edges = np.concatenate([[0.0], inner, np.linspace(0.1 * s_max, s_max, 121)[1:]])
    lo, hi = edges[:-1], edges[1:]
    half = (hi - lo)[:, None] / 2
    s = (lo + hi)[:, None] / 2 + half * _GL_X[None, :]
    tau = s * rot
    vals = hankel1(0, a * tau) * np.exp(-b * s ** (2 * h) * rot2h) * tau * rot * half
    return float(np.sum(vals @ _GL_W).real)


def _spm_alpha(eps, theta, pol):
    s2 = np.sin(theta) ** 2
    c = np.cos(theta)
    root = _kz_ratio(eps, theta)
    if pol == "hh":
        return (eps - 1) / (c + root) ** 2
    return (eps - 1) * (s2 - eps * (1 + s2)) / (eps * c + root) ** 2


def _spm(surf, k, eps, theta, pol):
    alpha = _spm_alpha(eps, theta, pol)
    K = 2 * k * np.sin(theta)
    return 8 * k ** 4 * np.cos(theta) ** 4 * np.abs(alpha) ** 2 * surf.spectrum(K)


def _go(surf, k, eps, theta):
    if surf.correlation != "gaussian":
        raise ValueError(f"model: geometric_optics needs a finite slope variance; the {surf.correlation} "
                         f"surface has none (use model='kirchhoff')")
    m2 = 2 * surf.sigma ** 2 / surf.l ** 2
    r0 = abs(fresnel(0.0, eps)) ** 2
    return r0 * np.exp(-np.tan(theta) ** 2 / (2 * m2)) / (2 * m2 * np.cos(theta) ** 4)


def _kirchhoff_series(surf, k, theta):
    """The Kirchhoff integral by its exact series (Gaussian and exponential
    correlations): exp(c rho) = sum c^n rho^n / n!, each term a closed-form
    Hankel transform. Returns the integral (without the prefactor)."""
    from scipy.special import gammaln

    out = np.empty(theta.shape)
    for idx, t in np.ndenumerate(theta):
        c = 4 * k ** 2 * math.cos(t) ** 2 * surf.sigma ** 2
        a = 2 * k * math.sin(t)
        n_max = int(c + 12 * math.sqrt(c) + 40)
        n = np.arange(1, n_max + 1, dtype=np.float64)
        logw = -c + n * math.log(c) - gammaln(n + 1)
        if surf.correlation == "gaussian":
            term = surf.l ** 2 / (2 * n) * np.exp(-(a * surf.l) ** 2 / (4 * n))
        else:
            b = n / surf.l
            term = b / (a * a + b * b) ** 1.5
        out[idx] = float(np.sum(np.exp(logw) * term))
    return out


def _kirchhoff_hankel(surf, k, theta):
    """The Kirchhoff integral by a numerical Hankel transform (any
    structure function; the fBm case)."""
    out = np.empty(theta.shape)
    for idx, t in np.ndenumerate(theta):
        p = 2 * k ** 2 * math.cos(t) ** 2
        a = 2 * k * math.sin(t)
        coherent = 0.0 if surf.correlation == "fbm" else math.exp(-2 * p * surf.sigma ** 2)
        if surf.correlation == "fbm":
            b = p * surf.topothesy ** (2 - 2 * surf.hurst)
            h = surf.hurst
            if a == 0:  # int exp(-b tau^2H) tau dtau
                out[idx] = math.gamma(1 / h) / (2 * h * b ** (1 / h))
            else:
                out[idx] = _hankel_fbm(a, b, h)
            continue
        elif surf.correlation == "gaussian":
            # bracket ~ e^{-2p sigma^2}(e^{2p sigma^2 rho} - 1): rho < 1e-17 at 6.3 l
            tau_max = surf.l * math.sqrt(40 + math.log1p(2 * p * surf.sigma ** 2))
        else:
            tau_max = surf.l * (40 + math.log1p(2 * p * surf.sigma ** 2))

        def f(tau, p=p, coherent=coherent):
            return np.exp(-p * surf.structure(tau)) - coherent

        out[idx] = _hankel(f, a, tau_max)
    return out


def backscatter(incidence, *, model="kirchhoff", wavelength, permittivity, rms_height=None,
                correlation_length=None, correlation="gaussian", hurst=None, topothesy=None,
                polarization="vv", return_validity=False):
    r"""Backscatter coefficient sigma0 of a rough surface (linear, m^2/m^2).

    ``k = 2 pi / wavelength``, ``theta`` the incidence, ``R(0)`` the Fresnel
    coefficient at normal incidence (:func:`~fractalgeo_rs.radar.fresnel`), ``W`` the roughness
    spectrum normalised so that :math:`\sigma^2 W(K) = \int_0^\infty C(\tau)
    J_0(K\tau)\tau\,d\tau` and ``D(tau) = E[(z(x + tau) - z(x))^2]`` the
    structure function.

    * ``"geometric_optics"`` (stationary phase, Kirchhoff at large ``k
      sigma``), Gaussian correlation only, ``m^2 = 2 sigma^2 / l^2`` the
      per-axis slope variance (the total mean-square slope is ``2 m^2``):

      .. math:: \sigma^0 = \frac{|R(0)|^2}{2 m^2 \cos^4\theta} e^{-\tan^2\theta / (2 m^2)}

    * ``"kirchhoff"``: the full Kirchhoff (physical optics) integral with the
      stationary-phase polarisation factor,

      .. math:: \sigma^0 = \frac{2 k^2 |R(0)|^2}{\cos^2\theta}\int_0^\infty J_0(2k\sin\theta\,\tau)
                \left[e^{-2k^2\cos^2\theta\,D(\tau)} - e^{-4k^2\cos^2\theta\,\sigma^2}\right]\tau\,d\tau,

      summed exactly as a series of closed-form Hankel transforms for the
      Gaussian and exponential correlations (:math:`e^{c\rho} = \sum c^n\rho^n/n!`)
      and by a numerical Hankel transform for fBm (the contour turned into
      the complex plane, where ``H0^(1)`` decays, then Gauss-Legendre), whose coherent term is
      0 (Franceschetti & Riccio 2007; for ``H = 1/2`` the integral is
      :math:`b/(a^2 + b^2)^{3/2}`, ``a = 2 k sin theta``, ``b = 2 k^2
      cos^2 theta T``).

    * ``"spm"``: first-order small perturbation,
      :math:`\sigma^0_{pp} = 8 k^4 \sigma^2 \cos^4\theta |\alpha_{pp}|^2 W(2k\sin\theta)`, with
      :math:`\alpha_{hh} = (\varepsilon - 1)/(\cos\theta + \sqrt{\varepsilon - \sin^2\theta})^2`,
      :math:`\alpha_{vv} = (\varepsilon - 1)[\sin^2\theta - \varepsilon(1 + \sin^2\theta)]
      /(\varepsilon\cos\theta + \sqrt{\varepsilon - \sin^2\theta})^2`; HV = 0 at first
      order. For fBm, :math:`\sigma^2 W(K) = S_0 K^{-2-2H}` with
      :math:`S_0 = T^{2-2H} H\,\Gamma(1+H)\,4^H/\Gamma(1-H)` (the power-law
      spectrum of the structure function ``T^(2-2H) tau^(2H)``), so sigma0
      scales as :math:`(2k\sin\theta)^{-2-2H}` (Franceschetti, Iodice,
      Migliaccio & Riccio 1999).

    Correlations: ``"gaussian"`` :math:`\rho = e^{-\tau^2/l^2}`,
    ``"exponential"`` :math:`\rho = e^{-\tau/l}`, ``"fbm"``
    :math:`D(\tau) = T^{2-2H}\tau^{2H}` (``topothesy`` ``T`` in metres: the
    lag at which the rms height difference equals the lag). Outside a
    model's validity range (:func:`~fractalgeo_rs.radar.validity`) a :class:`~fractalgeo_rs.radar.RadarValidityWarning`
    gives the numbers.

    Parameters
    ----------
    incidence : float or array_like
        Incidence angle(s) in degrees, in [0, 90).
    model : {"geometric_optics", "kirchhoff", "spm"}
        The scattering model.
    wavelength : float
        Radar wavelength in metres (C band: 0.056).
    permittivity : complex
        Relative permittivity of the ground, ``Im >= 0`` (time convention
        ``exp(-i omega t)``, see :func:`~fractalgeo_rs.radar.fresnel`).
    rms_height, correlation_length : float
        ``sigma`` and ``l`` in metres (Gaussian and exponential correlations).
    correlation : {"gaussian", "exponential", "fbm"}
        The surface's correlation function.
    hurst, topothesy : float
        ``H`` in (0, 1) and ``T`` in metres (``correlation="fbm"``).
    polarization : {"vv", "hh", "hv", "vh"}
        Only SPM distinguishes HH from VV; cross-polarised backscatter is 0
        in all three models.
    return_validity : bool
        Also return the :class:`~fractalgeo_rs.radar.BackscatterValidity`.

    Returns
    -------
    float or ndarray
        sigma0, linear, the shape of ``incidence`` (a float for a scalar);
        ``(sigma0, validity)`` with ``return_validity``.

    References
    ----------
    Beckmann, P. & Spizzichino, A. (1963). *The Scattering of Electromagnetic
    Waves from Rough Surfaces*. Pergamon.
    Ulaby, F. T., Moore, R. K. & Fung, A. K. (1982). *Microwave Remote
    Sensing*, vol. II, ch. 12. Addison-Wesley.
    Franceschetti, G., Iodice, A., Migliaccio, M. & Riccio, D. (1999).
    Scattering from natural rough surfaces modeled by fractional Brownian
    motion two-dimensional processes. *Radio Science* 34(5), 1073-1087,
    doi:10.1029/1999RS900053.
    Franceschetti, G. & Riccio, D. (2007). *Scattering, Natural Surfaces and
    Fractals*. Academic Press.

    Examples
    --------
    >>> import fractalgeo_rs as fg
    >>> s = fg.radar.backscatter([10.0, 30.0], model="geometric_optics", wavelength=0.056,
    ...                          permittivity=15 + 3j, rms_height=0.045, correlation_length=0.45)
    >>> fg.radar.to_db(s).round(2).tolist()
    [6.35, -24.23]
    >>> s = fg.radar.backscatter(30.0, model="spm", wavelength=0.056, permittivity=15 + 3j,
    ...                          rms_height=0.001, correlation_length=0.01, polarization="hh")
    >>> round(fg.radar.to_db(s), 2)
    -19.77
    """
    t_deg = check_incidence(incidence)
    m = _choice(model, "model", MODELS)
    wl = check_positive(wavelength, "wavelength")
    eps = check_permittivity(permittivity)
    pol = _choice(polarization, "polarization", POLARIZATIONS)
    surf = check_surface(correlation, rms_height, correlation_length, hurst, topothesy)
    val = _validity(surf, wl, float(np.max(t_deg)) if t_deg.size else 0.0)
    if not val.valid[m]:
        warnings.warn(f"backscatter: model={m!r} is outside its range of validity: {val.ranges[m]}; "
                      f"here k*sigma = {val.k_sigma:.3g}, k*l = {val.k_l:.3g}, rms slope = {val.rms_slope:.3g}, "
                      f"radius of curvature = {val.radius_of_curvature:.3g} m, wavelength = {wl:.3g} m",
                      RadarValidityWarning, stacklevel=user_stacklevel())
    k = 2 * math.pi / wl
    theta = np.deg2rad(t_deg)
    if pol in ("hv", "vh"):
        if m == "geometric_optics":
            _go(surf, k, eps, theta)  # the same checks
        out = np.zeros(theta.shape)
    elif m == "geometric_optics":
        out = _go(surf, k, eps, theta)
    elif m == "spm":
        out = _spm(surf, k, eps, theta, pol)
    else:
        r0 = abs(fresnel(0.0, eps)) ** 2
        integral = _kirchhoff_hankel(surf, k, theta) if surf.correlation == "fbm" else _kirchhoff_series(surf, k, theta)
        out = 2 * k ** 2 * r0 / np.cos(theta) ** 2 * integral
    out = np.asarray(out, dtype=np.float64)
    res = float(out) if out.ndim == 0 else out
    return (res, val) if return_validity else res
