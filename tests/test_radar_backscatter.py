"""Backscatter models against closed forms written out here independently,
published values (SMRT 1.7's geometric optics, docs/radar.md), limits
(Kirchhoff -> geometric optics), two evaluations of the Kirchhoff integral
(series and numerical Hankel transform) and the fBm spectrum's normalisation
(its structure function integrated back numerically)."""
import cmath
import math
import warnings

import numpy as np
import pytest
from scipy import integrate, special

import fractalgeo_rs as fg
from fractalgeo_rs.radar import _backscatter as bs

C_BAND = 0.056
K = 2 * math.pi / C_BAND
EPS = 15 + 3j


def _quiet(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fg.radar.RadarValidityWarning)
        return fg.radar.backscatter(**kw)


# --- Fresnel and the sign convention ---------------------------------------

def test_fresnel_normal_incidence_and_brewster():
    for eps in (4.0, 15 + 3j, 80 + 40j):
        r = (1 - cmath.sqrt(eps)) / (1 + cmath.sqrt(eps))
        assert abs(fg.radar.fresnel(0.0, eps, "h") - r) < 1e-15
        assert abs(fg.radar.fresnel(0.0, eps, "v") + r) < 1e-15  # R_v = -R_h at normal incidence
    # Brewster: R_v = 0 at tan(theta) = sqrt(eps) for a lossless medium
    tb = math.degrees(math.atan(2.0))
    assert abs(fg.radar.fresnel(tb, 4.0, "v")) < 1e-15
    assert abs(fg.radar.fresnel(tb, 4.0, "h")) > 0.3


def test_fresnel_sign_convention():
    """exp(-i omega t): a lossy medium has Im(eps) > 0 and the transmitted
    wave exp(i k_z' z') must decay downwards (Im k_z' > 0), |R| < 1; the
    engineering-convention value (Im < 0) is rejected, and its conjugate gives
    the conjugate coefficient with the same reflectivity."""
    for t in (0.0, 30.0, 60.0, 85.0):
        root = bs._kz_ratio(EPS, math.radians(t))
        assert root.imag > 0 and root.real > 0
        r = fg.radar.fresnel(t, EPS, "h")
        assert abs(r) < 1
        # the same coefficient computed in the e^{+j omega t} convention is its conjugate
        c, s2 = math.cos(math.radians(t)), math.sin(math.radians(t)) ** 2
        root_eng = cmath.sqrt(EPS.conjugate() - s2)  # principal root: Im < 0 there
        assert root_eng.imag < 0
        r_eng = (c - root_eng) / (c + root_eng)
        assert abs(r - r_eng.conjugate()) < 1e-14
    with pytest.raises(ValueError, match="permittivity.*exp\\(-i omega t\\)"):
        fg.radar.fresnel(10.0, 15 - 3j)
    with pytest.raises(ValueError, match="permittivity"):
        fg.radar.backscatter(10.0, model="spm", wavelength=C_BAND, permittivity=15 - 3j, rms_height=0.001,
                             correlation_length=0.01)


# --- geometric optics -------------------------------------------------------

def test_geometric_optics_closed_form():
    sigma, l = 0.05, 0.4
    m2 = 2 * sigma ** 2 / l ** 2
    r0 = abs((1 - cmath.sqrt(EPS)) / (1 + cmath.sqrt(EPS))) ** 2
    t = np.array([0.0, 5.0, 17.0, 33.0, 50.0])
    want = r0 * np.exp(-np.tan(np.radians(t)) ** 2 / (2 * m2)) / (2 * m2 * np.cos(np.radians(t)) ** 4)
    got = _quiet(incidence=t, model="geometric_optics", wavelength=C_BAND, permittivity=EPS, rms_height=sigma,
                 correlation_length=l)
    np.testing.assert_allclose(got, want, rtol=1e-12)


def test_geometric_optics_equals_smrt():
    """SMRT 1.7 ``geometrical_optics_backscatter`` (mean_square_slope=0.05,
    SMRT's per-axis slope variance, = our 2 sigma^2 / l^2; eps = 15 + 3j),
    values measured with SMRT 1.7 (pip install smrt) and recorded here."""
    l = 1.0
    sigma = math.sqrt(0.05 / 2) * l
    got = _quiet(incidence=[0.0, 10.0, 20.0, 30.0], model="geometric_optics", wavelength=C_BAND,
                 permittivity=EPS, rms_height=sigma, correlation_length=l)
    np.testing.assert_allclose(got, [3.535037, 2.753984, 1.205376, 0.224194], rtol=2e-6)


def test_geometric_optics_needs_slopes():
    with pytest.raises(ValueError, match="model: geometric_optics"):
        _quiet(incidence=10.0, model="geometric_optics", wavelength=C_BAND, permittivity=EPS, rms_height=0.05,
               correlation_length=0.5, correlation="exponential")


# --- Kirchhoff ----------------------------------------------------------------

def _go(t, ks, kl):
    return _quiet(incidence=t, model="geometric_optics", wavelength=C_BAND, permittivity=EPS, rms_height=ks / K,
                  correlation_length=kl / K)


def _ka(t, ks, kl, **kw):
    return _quiet(incidence=t, model="kirchhoff", wavelength=C_BAND, permittivity=EPS, rms_height=ks / K,
                  correlation_length=kl / K, **kw)


def test_kirchhoff_tends_to_geometric_optics():
    """k sigma = 5, k l = 50: the gap peaks at 1.06 % near 16 degrees (the
    issue asked 1 %; measured, see docs/radar.md) and falls as 1 / (k sigma)^2
    at a fixed slope (sigma / l = 0.1); it grows in the tail (+25 % at 30)."""
    t = np.arange(5.0, 20.5, 0.5)
    gap = np.abs(_ka(t, 5.0, 50.0) / _go(t, 5.0, 50.0) - 1)
    assert gap.max() < 0.011, gap
    assert abs(t[np.argmax(gap)] - 16.0) <= 0.5
    for angle in (5.0, 16.0):
        gaps = [abs(_ka(angle, ks, 10 * ks) / _go(angle, ks, 10 * ks) - 1) * ks ** 2 for ks in (5.0, 10.0, 20.0)]
        assert max(gaps) / min(gaps) < 1.03, gaps
    assert 0.2 < _ka(30.0, 5.0, 50.0) / _go(30.0, 5.0, 50.0) - 1 < 0.3
    # the 1 % the issue asks holds from k sigma = 5.2 on (0.98 % there, 0.27 / (k sigma)^2)
    for ks in (5.2, 7.0):
        gap = np.abs(_ka(t, ks, 10 * ks) / _go(t, ks, 10 * ks) - 1)
        assert gap.max() < 0.01, (ks, gap.max())


def test_kirchhoff_series_equals_numerical_hankel():
    """Two evaluations of the same integral: the exponential series of
    closed-form Hankel transforms, and Gauss-Legendre between zeros of J0."""
    for corr in ("gaussian", "exponential"):
        surf = bs.check_surface(corr, 0.02, 0.15, None, None)
        theta = np.radians(np.array([0.0, 10.0, 25.0, 40.0, 60.0]))
        a = bs._kirchhoff_series(surf, K, theta)
        b = bs._kirchhoff_hankel(surf, K, theta)
        np.testing.assert_allclose(a, b, rtol=1e-7, err_msg=corr)


@pytest.mark.parametrize("T", [0.004, 1e-5, 1e-7])
def test_kirchhoff_fbm_half_closed_form(T):
    """H = 1/2: int J0(a tau) exp(-b tau) tau dtau = b / (a^2 + b^2)^(3/2)
    (small T: thousands of J0 half-periods, the tail summed by Wynn's epsilon)."""
    t = np.array([0.0, 2.0, 10.0, 30.0, 55.0, 80.0])
    got = _quiet(incidence=t, model="kirchhoff", wavelength=C_BAND, permittivity=EPS, correlation="fbm",
                 hurst=0.5, topothesy=T)
    th = np.radians(t)
    a, b = 2 * K * np.sin(th), 2 * K ** 2 * np.cos(th) ** 2 * T
    r0 = abs((1 - cmath.sqrt(EPS)) / (1 + cmath.sqrt(EPS))) ** 2
    want = 2 * K ** 2 * r0 / np.cos(th) ** 2 * b / (a * a + b * b) ** 1.5
    # at T = 1e-7 the result b / a^3 is 1e-9 of the terms that cancel in it
    np.testing.assert_allclose(got, want, rtol=1e-9 if T > 1e-6 else 1e-8)


def test_kirchhoff_fbm_general_hurst_against_mpmath():
    mpmath = pytest.importorskip("mpmath")
    T, h, t = 0.01, 0.7, 25.0
    surf = bs.check_surface("fbm", None, None, h, T)
    got = bs._kirchhoff_hankel(surf, K, np.radians(np.array([t])))[0]
    a = 2 * K * math.sin(math.radians(t))
    b = 2 * K ** 2 * math.cos(math.radians(t)) ** 2 * T ** (2 - 2 * h)
    mpmath.mp.dps = 30
    want = mpmath.quadosc(lambda x: mpmath.besselj(0, a * x) * mpmath.exp(-b * x ** (2 * h)) * x,
                          [0, mpmath.inf], zeros=lambda n: mpmath.besseljzero(0, n) / a)
    assert abs(got / float(want) - 1) < 1e-7


def test_hh_equals_vv_at_normal_incidence():
    for model, kw in (("spm", dict(rms_height=0.001, correlation_length=0.01)),
                      ("kirchhoff", dict(rms_height=0.02, correlation_length=0.2))):
        hh = _quiet(incidence=0.0, model=model, wavelength=C_BAND, permittivity=EPS, polarization="hh", **kw)
        vv = _quiet(incidence=0.0, model=model, wavelength=C_BAND, permittivity=EPS, polarization="vv", **kw)
        assert hh == pytest.approx(vv, rel=1e-14)


# --- SPM ----------------------------------------------------------------------

def _spm_reference(t_deg, pol, sigma, l, eps, corr):
    t = math.radians(t_deg)
    s, c = math.sin(t), math.cos(t)
    root = cmath.sqrt(eps - s * s)
    if pol == "hh":
        alpha = (eps - 1) / (c + root) ** 2
    else:
        alpha = (eps - 1) * (s * s - eps * (1 + s * s)) / (eps * c + root) ** 2
    kk = 2 * K * s
    w = l * l / 2 * math.exp(-kk * kk * l * l / 4) if corr == "gaussian" else l * l / (1 + (kk * l) ** 2) ** 1.5
    return 8 * K ** 4 * sigma ** 2 * c ** 4 * abs(alpha) ** 2 * w


@pytest.mark.parametrize("corr", ["gaussian", "exponential"])
@pytest.mark.parametrize("pol", ["hh", "vv"])
def test_spm_closed_form(corr, pol):
    sigma, l = 0.0009, 0.009  # k sigma = 0.1, k l = 1
    t = [0.0, 20.0, 35.0, 50.0, 70.0]
    got = fg.radar.backscatter(t, model="spm", wavelength=C_BAND, permittivity=EPS, rms_height=sigma,
                               correlation_length=l, correlation=corr, polarization=pol)
    want = [_spm_reference(x, pol, sigma, l, EPS, corr) for x in t]
    np.testing.assert_allclose(got, want, rtol=1e-12)
    hv = fg.radar.backscatter(t, model="spm", wavelength=C_BAND, permittivity=EPS, rms_height=sigma,
                              correlation_length=l, correlation=corr, polarization="hv")
    assert np.all(hv == 0)


def test_fbm_spectrum_normalisation():
    """The power-law spectrum S0 K^(-2-2H) integrates back to the structure
    function: D(tau) = 2 int S0 K^(-2-2H) (1 - J0(K tau)) K dK = T^(2-2H) tau^(2H),
    i.e. 2 S0 I_H = T^(2-2H) with I_H = int_0^inf (1 - J0(u)) u^(-1-2H) du
    (quad on [0, 1], the closed part of the tail, the oscillating rest summed
    between the zeros of J0 with the last two partial sums averaged)."""
    T = 0.05
    zeros = special.jn_zeros(0, 3000)
    for h in (0.2, 0.5, 0.8):
        surf = bs.check_surface("fbm", None, None, h, T)
        s0 = float(surf.spectrum(1.0))
        head = integrate.quad(lambda u: (1 - special.j0(u)) * u ** (-1 - 2 * h), 0, 1)[0]
        edges = np.concatenate([[1.0], zeros[zeros > 1]])
        parts = [integrate.quad(lambda u: special.j0(u) * u ** (-1 - 2 * h), x0, x1)[0]
                 for x0, x1 in zip(edges[:-1], edges[1:])]
        partial = np.cumsum(parts)
        osc = (partial[-1] + partial[-2]) / 2
        i_h = head + 1 / (2 * h) - osc
        assert 2 * s0 * i_h == pytest.approx(T ** (2 - 2 * h), rel=1e-6), h


@pytest.mark.parametrize("h", [0.2, 0.5, 0.8])
def test_spm_fbm_angular_exponent(h):
    """sigma0 / (cos^4 |alpha|^2) is a power of 2 k sin(theta) with exponent
    -(2 + 2H) exactly."""
    t = np.linspace(15.0, 60.0, 10)
    s = fg.radar.backscatter(t, model="spm", wavelength=C_BAND, permittivity=EPS, correlation="fbm", hurst=h,
                             topothesy=1e-9, polarization="hh")
    th = np.radians(t)
    alpha = bs._spm_alpha(EPS, th, "hh")
    y = np.log(s / (np.cos(th) ** 4 * np.abs(alpha) ** 2))
    slope = np.polyfit(np.log(2 * K * np.sin(th)), y, 1)[0]
    assert slope == pytest.approx(-(2 + 2 * h), abs=1e-10)


@pytest.mark.parametrize("h, T", [(0.3, 1e-6), (0.5, 1e-7), (0.7, 1e-12)])
def test_spm_fbm_meets_kirchhoff_at_small_roughness(h, T):
    """Small roughness (b a^(-2H) << 1), near-normal incidence: first-order
    Kirchhoff and SPM share their leading term 8 k^4 |R(0)|^2 S0 a^(-2-2H)
    (|alpha_hh| -> |R(0)| as theta -> 0)."""
    kw = dict(wavelength=C_BAND, permittivity=EPS, correlation="fbm", hurst=h, topothesy=T, polarization="hh")
    ka = _quiet(incidence=1.0, model="kirchhoff", **kw)
    spm = _quiet(incidence=1.0, model="spm", **kw)
    assert ka == pytest.approx(spm, rel=3e-3)


# --- validity, errors ---------------------------------------------------------

def test_validity_report_and_warning():
    v = fg.radar.validity(wavelength=C_BAND, rms_height=0.01, correlation_length=0.1)
    assert v.k_sigma == pytest.approx(K * 0.01) and v.k_l == pytest.approx(K * 0.1)
    assert v.rms_slope == pytest.approx(math.sqrt(2) * 0.1)
    assert v.radius_of_curvature == pytest.approx(0.01 / (math.sqrt(12) * 0.01))
    assert v.valid == {"geometric_optics": False, "kirchhoff": True, "spm": False}
    assert "k*sigma" in str(v)
    with pytest.warns(fg.radar.RadarValidityWarning, match=r"spm.*k\*sigma = 1\.12") as rec:
        fg.radar.backscatter(30.0, model="spm", wavelength=C_BAND, permittivity=EPS, rms_height=0.01,
                             correlation_length=0.1)
    assert rec[0].filename == __file__


@pytest.mark.parametrize("kw, match", [
    (dict(incidence=90.0), "incidence"),
    (dict(incidence=-1.0), "incidence"),
    (dict(wavelength=0.0), "wavelength"),
    (dict(wavelength=-1.0), "wavelength"),
    (dict(model="iem"), "model"),
    (dict(polarization="xx"), "polarization"),
    (dict(correlation="fbm"), "hurst"),
    (dict(rms_height=-0.1), "rms_height"),
    (dict(correlation_length=None), "correlation_length"),
])
def test_bad_input(kw, match):
    args = dict(incidence=20.0, model="spm", wavelength=C_BAND, permittivity=EPS, rms_height=0.001,
                correlation_length=0.01)
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        fg.radar.backscatter(**args)


def test_inputs_are_not_modified():
    t = np.array([10.0, 20.0])
    fg.radar.backscatter(t, model="spm", wavelength=C_BAND, permittivity=EPS, rms_height=0.001,
                         correlation_length=0.01)
    assert t.tolist() == [10.0, 20.0]
