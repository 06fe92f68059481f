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
        (lambda: fg.spectral_dimension(np.arange(100.0), taper="blackman"), ValueError, "taper"),
        (lambda: fg.scale_space(np.arange(100.0), cell_size=-1), ValueError, "cell_size"),
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


def weierstrass_mandelbrot(n, hurst, gamma=1.5, k_max=45):
    """Weierstrass-Mandelbrot function sampled at t = j/n (graph D = 2 - H),
    with terms far beyond the sampling frequency so the samples are those of
    the continuous function."""
    t = np.arange(n) / n
    w = np.zeros(n)
    for k in range(-10, k_max + 1):
        w += gamma ** (-k * hurst) * (1 - np.cos(2 * np.pi * gamma**k * t))
    return w


def test_weierstrass_mandelbrot_graph():
    # Measured errors at n = 4096 (H = 0.3, 0.5, 0.7): variogram over lags
    # 1..16 <= 0.015, madogram <= 0.029, Higuchi <= 0.046, wavelet <= 0.040,
    # scale space <= 0.078. The log-periodic modulation of the WM increments
    # (period ln 1.5) makes two-lag fits unreliable, hence 16 lags here.
    for h in (0.3, 0.5, 0.7):
        z = weierstrass_mandelbrot(4096, h)
        assert fg.variogram(z, lags=range(1, 17)).dimension == pytest.approx(2 - h, abs=0.03)
        assert fg.madogram(z, lags=range(1, 17)).dimension == pytest.approx(2 - h, abs=0.04)
        assert fg.higuchi(z).dimension == pytest.approx(2 - h, abs=0.06)
        assert fg.wavelet_dimension(z).dimension == pytest.approx(2 - h, abs=0.06)
        assert fg.scale_space(z).dimension == pytest.approx(2 - h, abs=0.1)


def numpy_blanket_areas(z, eps_max):
    """Peleg blanket from the definition, with explicit neighbour shifts
    (edges replicate the border value, as scipy's mode="nearest")."""
    u = z.astype(float).copy()
    b = u.copy()
    out = []
    for e in range(1, eps_max + 1):
        pu = np.pad(u, 1, mode="edge")
        pb = np.pad(b, 1, mode="edge")
        nu = np.max([pu[1:-1, 1:-1], pu[:-2, 1:-1], pu[2:, 1:-1], pu[1:-1, :-2], pu[1:-1, 2:]], axis=0)
        nb = np.min([pb[1:-1, 1:-1], pb[:-2, 1:-1], pb[2:, 1:-1], pb[1:-1, :-2], pb[1:-1, 2:]], axis=0)
        u = np.maximum(u + 1, nu)
        b = np.minimum(b - 1, nb)
        out.append(np.sum(u - b) / (2 * e))
    return out


def numpy_mass_N(z, sizes, z_scale):
    """Voss N(L) of the point set (i, j, (z - zmin) / z_scale), brute force."""
    ok = ~np.isnan(z)
    ij = np.argwhere(ok).astype(float)
    pts = np.column_stack([ij, (z[ok] - np.nanmin(z)) / z_scale])
    cheb = np.max(np.abs(pts[:, None, :] - pts[None, :, :]), axis=2)
    return [float(np.mean(1.0 / np.sum(cheb <= L / 2.0, axis=1))) for L in sizes]


def test_blanket_and_mass_equal_independent_numpy():
    rng = np.random.default_rng(4)
    for shape in [(17, 23), (30, 30)]:
        z = np.round(rng.normal(0, 8, size=shape).cumsum(axis=1))
        fit = fg.blanket(z, epsilons=range(1, 9), z_scale=1.0)
        assert fit.measures.tolist() == pytest.approx(numpy_blanket_areas(z, 8), rel=1e-12)
        zn = z.copy()
        zn[3:6, 4:9] = np.nan
        fit = fg.mass_dimension(zn, box_sizes=[3, 5, 7, 9], z_scale=2.0)
        assert fit.measures.tolist() == pytest.approx(numpy_mass_N(zn, [3, 5, 7, 9], 2.0), rel=1e-12)


def test_height_unit_conventions():
    """Grayscale estimators and the units of heights (docs/estimators.md):
    DBC, mass and blanket default to the data's own range (z_scale="range"),
    so scaling heights changes nothing; a fixed z_scale counts in data units
    per step, so heights times c with z_scale = c is the same surface;
    increment estimators are invariant."""
    z = spectral_surface(64, 0.5, 2)
    z = 2.0 * z / z.std()  # a few grey levels of relief: the blanket's unit step matters
    c = 50.0
    assert fg.differential_box_counting(c * z).dimension == pytest.approx(fg.differential_box_counting(z).dimension, abs=1e-9)
    m1 = fg.mass_dimension(z, box_sizes=[3, 5, 9])
    m2 = fg.mass_dimension(c * z, box_sizes=[3, 5, 9])
    assert np.allclose(m1.measures, m2.measures, rtol=1e-12)
    b1 = fg.blanket(z, z_scale=1.0)
    assert fg.blanket(c * z, z_scale=c).measures == pytest.approx(b1.measures, rel=1e-9)
    # ... a fixed unit that does not follow the data changes the answer ...
    assert abs(fg.blanket(c * z, z_scale=1.0).dimension - b1.dimension) > 0.05
    # ... and the default unit follows the data
    assert fg.blanket(c * z).measures == pytest.approx(fg.blanket(z).measures, rel=1e-9)
    assert fg.surface_variation(c * z).dimension == pytest.approx(fg.surface_variation(z).dimension, abs=1e-12)


def dragon_boundary(n=16):
    """Boundary pixels of the Heighway dragon (level n, edges drawn at twice
    the resolution and the enclosed cells filled). The boundary of the
    dragon has dimension 1.5236 (2 log2 of the real root of x^3 - x^2 - 2)."""
    from scipy import ndimage

    from fractalgeo_rs.lsystem import turtle_2d

    s = fg.LSystem("FX", {"X": "X+YF+", "Y": "-FX-Y"}).derive(n)
    xy = np.round(turtle_2d(s, angle=90, step=1).xy).astype(int)
    xy -= xy.min(axis=0)
    img = np.zeros((2 * xy[:, 1].max() + 1, 2 * xy[:, 0].max() + 1), bool)
    p = 2 * xy
    img[p[:, 1], p[:, 0]] = True
    mid = (p[1:] + p[:-1]) // 2
    img[mid[:, 1], mid[:, 0]] = True
    filled = ndimage.binary_fill_holes(ndimage.binary_closing(img, structure=np.ones((3, 3))))
    return filled & ndimage.binary_dilation(~filled, structure=np.ones((3, 3)))


def test_dragon_curve_boundary():
    root = np.roots([1, -1, 0, -2])
    d = 2.0 * float(np.log2(root[np.isreal(root)].real[0]))
    assert d == pytest.approx(1.5236, abs=1e-4)
    bd = dragon_boundary(16)
    # measured: Minkowski 1.518, mass 1.517, box counting 1.559 on boxes 4..128;
    # boxes of 1-2 pixels see the raster line (local slope 1.0), so the box
    # fit starts above the construction's resolution
    assert fg.minkowski(bd).dimension == pytest.approx(d, abs=0.02)
    assert fg.mass_dimension(bd).dimension == pytest.approx(d, abs=0.02)
    assert fg.box_counting(bd, scale_range=(4, 128)).dimension == pytest.approx(d, abs=0.05)


def test_scale_space_filter_bank_equals_scipy_gaussian_filter():
    # the wide kernels go through one shared FFT; each smoothed profile must
    # equal scipy's direct filter (same sampled, normalised, reflected kernel)
    from scipy.ndimage import gaussian_filter1d

    from fractalgeo_rs.dimension.profile import _gaussian_bank

    for n in (257, 5000):
        z = fg.fbm(n, 0.4, method="exact", seed=n)
        sig = np.array([1.0, 3.0, 6.0, 7.5, 16.0, n / 12])
        for s, g in zip(sig, _gaussian_bank(z, sig)):
            ref = gaussian_filter1d(z, s, mode="reflect")
            np.testing.assert_allclose(g, ref, rtol=0, atol=1e-10 * np.abs(ref).max())


def test_higuchi_lengths_equal_the_definition_and_any_thread_count():
    # L(k) from a direct loop over offsets m (Higuchi 1988, with the final 1/k)
    def lengths(z, k_max):
        n, out = z.size, []
        for k in range(1, k_max + 1):
            lm = []
            for m in range(k):
                x = z[m::k]
                if x.size >= 2:
                    lm.append(np.abs(np.diff(x)).sum() * (n - 1) / ((x.size - 1) * k) / k)
            out.append(np.mean(lm))
        return np.array(out)

    for n, k_max in ((21, 10), (101, 17), (1000, 64)):
        z = fg.fbm(n, 0.3, method="exact", seed=n)
        fit = fg.higuchi(z, k_max=k_max)
        np.testing.assert_allclose(fit.measures, lengths(z, k_max), rtol=1e-12)
        assert np.array_equal(fit.measures, fg.higuchi(z, k_max=k_max, n_threads=1).measures)
        assert np.array_equal(fit.measures, fg.higuchi(z, k_max=k_max, n_threads=3).measures)


def test_transect_dimensions_equal_a_per_line_fit_with_nan_holes():
    # independent: np.polyfit per row and column on the NaN-free increments
    z = fg.fbm_surface((64, 80), 0.4, method="exact", seed=3).astype(float)
    z[5, 7] = np.nan
    z[20:23, :] = np.nan
    z[:, 40] = np.nan
    lags = (1, 2, 3)
    for p in (1.0, 2.0, 1.5):
        fit = fg.surface_variation(z, estimator="transect", p=p, lags=lags)
        dims = []
        for line in list(z) + list(z.T):
            m = []
            for u in lags:
                d = line[u:] - line[:-u]
                d = d[~np.isnan(d)]
                m.append(np.mean(np.abs(d) ** p) / 2 if d.size else np.nan)
            m = np.array(m)
            if np.all(m > 0) and np.isfinite(m).all():
                dims.append(2 - np.polyfit(np.log(lags), np.log(m), 1)[0] / p)
        np.testing.assert_allclose(fit.extra["transect_dimensions"], np.array(dims) + 1, rtol=1e-12)
        assert fit.dimension == pytest.approx(np.median(dims) + 1, rel=1e-12)


def test_spectral_detrend_removes_the_least_squares_plane():
    from fractalgeo_rs.dimension.spectral import _detrend

    rng = np.random.default_rng(1)
    for shape in [(7, 9), (1, 5), (50, 1), (33, 64)]:
        z = rng.normal(size=shape) + np.add.outer(np.arange(shape[0]) * 0.3, np.arange(shape[1]) * -0.7)
        i, j = np.indices(shape, dtype=float)
        a = np.column_stack([np.ones(z.size), i.ravel(), j.ravel()])
        coef, *_ = np.linalg.lstsq(a, z.ravel(), rcond=None)
        np.testing.assert_allclose(_detrend(z), z - (a @ coef).reshape(shape), atol=1e-10)
