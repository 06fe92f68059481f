"""The estimators beyond box counting: known values, invariants and accuracy
on exact fBm profiles (Davies-Harte, tests/fractals.py)."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractals import (
    cantor_dust,
    fbm_profile,
    sierpinski_carpet,
    sierpinski_triangle,
    spectral_surface,
    triadic_koch_curve,
)

LN = np.log


@pytest.fixture(scope="module")
def profiles():
    return {h: [fbm_profile(1024, h, s) for s in range(100)] for h in (0.3, 0.5, 0.8)}


def rmse(est, truth):
    est = np.asarray(est)
    return float(np.sqrt(np.mean((est - truth) ** 2)))


def test_variogram_and_madogram_meet_published_accuracy(profiles):
    # Targets (R fractaldim on exact fBm, n = 1024): variogram RMSE <= 0.027,
    # madogram <= 0.032 for H in {0.3, 0.5, 0.8}.
    for h, zs in profiles.items():
        dv = [fg.variogram(z).dimension for z in zs]
        dm = [fg.madogram(z).dimension for z in zs]
        assert rmse(dv, 2 - h) <= 0.027, (h, rmse(dv, 2 - h))
        assert rmse(dm, 2 - h) <= 0.032, (h, rmse(dm, 2 - h))
        assert abs(np.mean(dv) - (2 - h)) < 0.01


def test_other_profile_estimators_are_unbiased_on_fbm(profiles):
    # tolerances: 3 standard errors of the mean over 100 replicates, from the
    # spreads measured in docs/estimators.md, plus the measured bias
    for h, zs in profiles.items():
        for f, tol in [(fg.higuchi, 0.02), (fg.power_variation, 0.02), (fg.scale_space, 0.05),
                       (fg.spectral_dimension, 0.05)]:
            d = np.mean([f(z).dimension for z in zs])
            assert abs(d - (2 - h)) <= tol, (f.__name__, h, d)


def test_variation_invariants():
    z = fbm_profile(2049, 0.6, 3)
    a = fg.variogram(z)
    assert fg.variogram(3.0 * z - 7.0).dimension == pytest.approx(a.dimension, abs=1e-12)
    assert fg.variogram(z[::-1]).dimension == pytest.approx(a.dimension, abs=1e-12)
    assert np.isnan(a.stderr)  # two lags: exact fit
    # NaN gaps: increments touching them are skipped
    zn = z.copy()
    zn[100:120] = np.nan
    inc = np.diff(zn)
    expect = np.nanmean(inc**2) / 2
    assert fg.variogram(zn).measures[0] == pytest.approx(expect)
    assert fg.variogram(np.where(np.isnan(zn), -9999.0, zn), nodata=-9999.0).measures[0] == pytest.approx(expect)


def test_higuchi_line_is_one_and_keeps_the_final_1_over_k():
    fit = fg.higuchi(np.linspace(0, 5, 1000))
    assert fit.dimension == pytest.approx(1.0, abs=1e-9)
    # L(k) for a line of slope a over N samples is |a| (N - 1) / k exactly
    a = 5 / 999
    assert fit.measures[:5] == pytest.approx([a * 999 / k for k in range(1, 6)])


def test_spectral_relations_1d_and_2d_agree_on_one_surface():
    # the 2D radial spectrum uses D = (8 - beta)/2, rows use D = (5 - beta)/2:
    # the surface's D is its profiles' D plus one
    d2, d1 = [], []
    for s in range(6):
        z = spectral_surface(256, 0.5, s)
        d2.append(fg.spectral_dimension(z).dimension)
        d1.append(np.mean([fg.spectral_dimension(row).dimension for row in z[::16]]))
    assert np.mean(d2) == pytest.approx(np.mean(d1) + 1.0, abs=0.06)
    assert np.mean(d2) == pytest.approx(2.5, abs=0.1)


def test_blanket_of_a_plane_is_two():
    i, j = np.indices((64, 64))
    for z in (np.zeros((64, 64)), 0.3 * i + 0.2 * j):
        assert fg.blanket(z).dimension == pytest.approx(2.0, abs=1e-9)


def test_surface_variation_plane_and_rough_ordering():
    i, j = np.indices((64, 64))
    assert fg.surface_variation(0.3 * i + 0.1 * j, estimator="first").dimension == pytest.approx(2.0, abs=1e-12)
    d = [fg.surface_variation(spectral_surface(128, h, 1), estimator=e).dimension
         for e in ("first", "square", "transect") for h in (0.2, 0.5, 0.8)]
    for k in range(0, 9, 3):
        assert d[k] > d[k + 1] > d[k + 2]


def test_minkowski_known_sets():
    point = np.zeros((200, 200), bool)
    point[100, 100] = True
    assert fg.minkowski(point, radii=[4, 8, 16, 32]).dimension == pytest.approx(0.0, abs=0.03)
    # measured errors (docs/estimators.md): triangle -0.018, Koch +0.007,
    # carpet -0.068, dust -0.080: the sausage of lacunar triadic sets fills
    # their holes early, a known slow convergence of the Minkowski content
    assert fg.minkowski(sierpinski_triangle(9)).dimension == pytest.approx(LN(3) / LN(2), abs=0.03)
    assert fg.minkowski(triadic_koch_curve(6, 729)).dimension == pytest.approx(LN(4) / LN(3), abs=0.03)
    assert fg.minkowski(sierpinski_carpet(6)).dimension == pytest.approx(LN(8) / LN(3), abs=0.1)
    assert fg.minkowski(cantor_dust(6)).dimension == pytest.approx(2 * LN(2) / LN(3), abs=0.1)
    # a filled disc: the sausage grows from a 2D set, D = 2
    i, j = np.indices((300, 300))
    disc = (i - 150) ** 2 + (j - 150) ** 2 < 100**2
    assert fg.minkowski(disc, radii=[1, 2, 4, 8]).dimension == pytest.approx(2.0, abs=0.1)


def test_mass_dimension_binary_and_points_agree():
    tri = sierpinski_triangle(9)
    fb = fg.mass_dimension(tri)
    fp = fg.mass_dimension(np.argwhere(tri).astype(float), kind="points", box_sizes=fb.scales.astype(int))
    assert np.allclose(fb.measures, fp.measures)
    assert fb.dimension == pytest.approx(LN(3) / LN(2), abs=0.05)
    assert fg.mass_dimension(np.ones((300, 300), bool)).dimension == pytest.approx(2.0, abs=0.05)


def test_wavelet_on_fbm(profiles):
    for h in (0.5, 0.8):
        d = np.mean([fg.wavelet_dimension(z).dimension for z in profiles[h]])
        assert abs(d - (2 - h)) < 0.06


def test_lacunarity_known_values():
    lac = fg.lacunarity(np.ones((64, 64), bool))
    assert np.allclose(lac.lacunarity, 1.0)
    rng = np.random.default_rng(0)
    m = rng.random((200, 200)) < 0.2
    lac = fg.lacunarity(m, box_sizes=[1, 2, 4])
    assert lac.lacunarity[0] == pytest.approx(1 / m.mean())
    assert lac.lacunarity[0] > lac.lacunarity[1] > lac.lacunarity[2] > 1.0
    # a box touching NaN is not used
    z = rng.random((50, 50))
    z[10, 10] = np.nan
    assert fg.lacunarity(z, box_sizes=[3]).n_boxes[0] == 48 * 48 - 9


@pytest.mark.parametrize(
    "call, exc, param",
    [
        (lambda: fg.variogram(np.ones((4, 4))), ValueError, "data"),
        (lambda: fg.variogram(np.ones(100)), ValueError, "data"),
        (lambda: fg.variogram(np.arange(10.0), lags=[1]), ValueError, "lags"),
        (lambda: fg.variogram(np.arange(10.0), lags=[1, 20]), ValueError, "lags"),
        (lambda: fg.power_variation(np.arange(10.0), p=0), ValueError, "p"),
        (lambda: fg.power_variation(np.arange(10.0), order=3), ValueError, "order"),
        (lambda: fg.higuchi(np.array([1.0, np.nan] * 50)), ValueError, "data"),
        (lambda: fg.higuchi(np.arange(100.0), k_max=80), ValueError, "k_max"),
        (lambda: fg.spectral_dimension(np.arange(4.0)), ValueError, "data"),
        (lambda: fg.spectral_dimension(np.arange(100.0), window="blackman"), ValueError, "window"),
        (lambda: fg.scale_space(np.arange(100.0), sample_spacing=-1), ValueError, "sample_spacing"),
        (lambda: fg.wavelet_dimension(np.arange(8.0)), ValueError, "data"),
        (lambda: fg.blanket(np.full((20, 20), np.nan)), ValueError, "data"),
        (lambda: fg.blanket(np.zeros((20, 20)), epsilons=[1, 2]), ValueError, "epsilons"),
        (lambda: fg.minkowski(np.zeros((20, 20), bool)), ValueError, "data"),
        (lambda: fg.mass_dimension(np.ones((100, 100), bool), box_sizes=[2, 4, 8]), ValueError, "box_sizes"),
        (lambda: fg.mass_dimension(np.ones((10, 10)), kind="cloud"), ValueError, "kind"),
        (lambda: fg.surface_variation(np.ones(10)), ValueError, "data"),
        (lambda: fg.surface_variation(np.ones((10, 10)), estimator="diag"), ValueError, "estimator"),
        (lambda: fg.lacunarity(np.ones((10, 10)) * -1), ValueError, "data"),
        (lambda: fg.lacunarity(np.ones((10, 10)), box_sizes=[20]), ValueError, "box_sizes"),
        (lambda: fg.lacunarity(np.ones(10)), ValueError, "data"),
    ],
)
def test_estimator_bad_input(call, exc, param):
    with pytest.raises(exc) as info:
        call()
    assert param in str(info.value)
