"""Numerical physical optics (one FFT of exp(i q_z z) per angle over periodic
synthetic surfaces) against the Kirchhoff integral, and the angular exponent
-(2 + 2H) of fBm surfaces at small roughness."""
import math

import numpy as np
import pytest

import fractalgeo_rs as fg

WL = 0.056
K = 2 * math.pi / WL
EPS = 15 + 3j


def test_gaussian_surfaces_match_the_kirchhoff_integral():
    """k sigma = 1.5, k l = 10 (the references' check), 512^2 surfaces, ring
    averaging: within 3 standard errors of the integral at each angle."""
    sigma, l = 1.5 / K, 10 / K
    t = [10.0, 20.0, 30.0]
    po = fg.radar.physical_optics(t, wavelength=WL, permittivity=EPS, rms_height=sigma, correlation_length=l,
                                  shape=512, realisations=12, seed=3)
    ref = fg.radar.backscatter(t, model="kirchhoff", wavelength=WL, permittivity=EPS, rms_height=sigma,
                               correlation_length=l)
    z = (po.sigma0 - ref) / po.standard_error
    assert np.all(np.abs(z) < 3), (fg.radar.to_db(po.sigma0), fg.radar.to_db(ref), z)
    # and the standard error is a few per cent (ring averaging)
    assert np.all(po.standard_error / po.sigma0 < 0.08)


@pytest.mark.slow
@pytest.mark.parametrize("h, shape, cell", [(0.3, 1024, 0.002), (0.7, 512, 0.004)])
def test_fbm_angular_exponent(h, shape, cell):
    """Small roughness: sigma0 ~ 8 k^4 |R(0)|^2 S0 (2 k sin theta)^(-2-2H).
    The sampled surface's spectrum is flatter near the Nyquist frequency
    (aliasing): at H = 0.3 a 4 mm grid (2 k sin 60 deg = 0.43 Nyquist) gives
    -2.56 over 64 surfaces, a 2 mm grid -2.59."""
    t = np.linspace(20.0, 60.0, 9)
    po = fg.radar.physical_optics(t, wavelength=WL, permittivity=EPS, correlation="fbm", hurst=h, topothesy=1e-6,
                                  shape=shape, cell_size=cell, realisations=8 if shape > 512 else 16, seed=1)
    slope = np.polyfit(np.log(2 * K * np.sin(np.radians(t))), np.log(po.sigma0), 1)[0]
    assert slope == pytest.approx(-(2 + 2 * h), abs=0.05)


def test_surface_realisation_statistics():
    z = fg.radar.surface_realisation(512, 0.01, correlation="gaussian", rms_height=0.02, correlation_length=0.1,
                                     seed=2)
    assert z.std() == pytest.approx(0.02, rel=0.1)
    # the correlation at lag l is exp(-1)
    c = np.mean(z * np.roll(z, 10, axis=1)) / z.var()
    assert c == pytest.approx(math.exp(-1), abs=0.06)


@pytest.mark.parametrize("kw, match", [
    (dict(shape=8), "shape"),
    (dict(realisations=1), "realisations"),
    (dict(incidence=0.0), "incidence"),
    (dict(correlation="exponential"), "correlation"),
])
def test_bad_input(kw, match):
    args = dict(incidence=20.0, wavelength=WL, permittivity=EPS, rms_height=0.01, correlation_length=0.1,
                shape=64, realisations=2, seed=1)
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        fg.radar.physical_optics(**args)
