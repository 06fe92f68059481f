"""Sky light, point-spread functions, the bi-hemispherical reflectance and
the plot helpers of ``fractalgeo_rs.radiometry``, against closed forms,
quadrature and the estimators they are built on."""
import math

import numpy as np
import pytest

from fractalgeo_rs.radiometry import Lambertian, Scene
from surfaces import rough_tile, v_grooves




# ---- bi-hemispherical reflectance ----

def test_bhr_of_a_flat_lambertian_plane_is_rho():
    e = Scene.from_dem(np.zeros((6, 6)), material=Lambertian(0.42)).bhr(spp=3000)
    assert abs(e.value - 0.42) < 1e-12 and e.se < 1e-12 and e.n == 3000


def test_bhr_is_the_cosine_weighted_integral_of_the_albedo():
    # BHR = (1/pi) int albedo(s) cos(s) ds = int_0^1 du (1/2pi) int dphi albedo(u = sin^2 zenith, phi);
    # Gauss-Legendre in u, the trapezoid (exact for trigonometric polynomials) in azimuth
    scene = Scene.from_dem(rough_tile(amp=0.8), material=Lambertian(0.7))
    u, wu = np.polynomial.legendre.leggauss(6)
    u, wu = 0.5 * (u + 1), 0.5 * wu
    phis = np.arange(8) * 45.0
    est, var = 0.0, 0.0
    for ui, wi in zip(u, wu):
        zen = math.degrees(math.asin(math.sqrt(ui)))
        for k, ph in enumerate(phis):
            a = scene.albedo(sun=(ph, zen), spp=20000, seed=100 + k)
            est += wi / phis.size * a.value
            var += (wi / phis.size * a.se) ** 2
    b = scene.bhr(spp=200000, seed=5)
    assert b.value < 0.7  # the rough surface traps light
    assert abs(b.value - est) < 3 * math.sqrt(b.se ** 2 + var), (b, est, math.sqrt(var))


def test_bhr_threads_and_bad_input():
    scene = Scene.from_dem(rough_tile(8), material=Lambertian(0.5))
    assert scene.bhr(spp=5000, n_threads=1) == scene.bhr(spp=5000, n_threads=2)
    with pytest.raises(ValueError, match="spp"):
        scene.bhr(spp=0)
    with pytest.raises(ValueError, match="max_depth"):
        scene.bhr(max_depth=0)


# ---- sky light ----

@pytest.mark.parametrize("zen,sky", [(0.0, 0.25), (60.0, 1.5), (85.0, 0.1)])
def test_flat_lambertian_under_sun_and_sky(zen, sky):
    rho = 0.3
    s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(rho))
    e = s.brf(sun=(30.0, zen), view=(250.0, 40.0), spp=400, sky=sky)
    assert abs(e.value - rho) < 1e-12
    img = s.render(sun=(30.0, zen), view=(120.0, 20.0), shape=(3, 2), spp=3, sky=sky)
    want = rho * (math.cos(math.radians(zen)) + sky) / math.pi  # L = rho (E cos + E_sky) / pi
    assert np.allclose(img, want, rtol=1e-6, atol=0)


@pytest.mark.parametrize("sun", [(90.0, 50.0), (0.0, 30.0), (270.0, 20.0)])
def test_v_groove_sky_view_factor(sun):
    # single scattering of an isotropic sky by periodic V-grooves of slope s:
    # each wall sees the sky through the groove's opening with the view factor
    # F = 1 - sin(alpha/2) ... of the opening = cos(s) (crossed strings), so the
    # nadir radiance from the sky is rho E_sky cos(s) / pi. The same seed gives
    # the same sun paths with and without sky, so the difference is the sky term.
    rho, sky, s = 0.8, 2.0, math.radians(30.0)
    scene = Scene.from_dem(v_grooves(), material=Lambertian(rho))
    cz = math.cos(math.radians(sun[1]))
    with_sky = scene.brf(sun=sun, spp=60000, max_depth=1, sky=sky, seed=3)
    sun_only = scene.brf(sun=sun, spp=60000, max_depth=1, seed=3)
    sky_part = with_sky.value * (cz + sky) - sun_only.value * cz  # pi L_sky
    se = with_sky.se * (cz + sky) + sun_only.se * cz
    assert abs(sky_part - rho * sky * math.cos(s)) < 3 * se + 1e-12, (sky_part, rho * sky * math.cos(s), se)
    # sky = 0 is the plain BRF
    assert scene.brf(sun=sun, spp=3000, max_depth=1, sky=0.0, seed=3) == scene.brf(
        sun=sun, spp=3000, max_depth=1, seed=3)


def test_brf_sweep_with_sky_is_brf_with_sky():
    scene = Scene.from_dem(rough_tile(8), material=Lambertian(0.5))
    sw = scene.brf_sweep(sun_zenith=[10, 50], view_zenith=[0, 30], sun_azimuth=45.0, spp=2000, sky=0.5)
    for i, zs in enumerate((10, 50)):
        for j, zv in enumerate((0, 30)):
            assert sw.value[i, j] == scene.brf(sun=(45.0, zs), view=(0.0, zv), spp=2000, sky=0.5).value


def test_sky_bad_input():
    s = Scene.from_dem(np.zeros((4, 4)))
    for bad in (-0.1, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="sky"):
            s.brf(sun=(0.0, 30.0), spp=10, sky=bad)
        with pytest.raises(ValueError, match="sky"):
            s.render(sun=(0.0, 30.0), spp=1, sky=bad)
    with pytest.raises(TypeError, match="sky"):
        s.brf(sun=(0.0, 30.0), spp=10, sky="blue")


# ---- point-spread functions ----

def _roof(period=16, rows=2, slope_deg=20.0):
    """A periodic roof along x: heights rising for half a period (a
    west-facing slope), then falling (east-facing); cells of 1 m."""
    t = math.tan(math.radians(slope_deg))
    half = period // 2
    prof = np.array([t * c if c <= half else t * (period - c) for c in range(period)], dtype=float)
    return np.repeat(prof[None, :], rows, 0)


def _disc_gauss_cdf(a, sigma, radius):
    """P(X < a) for the x-marginal of an isotropic Gaussian truncated to a
    disc: density ~ exp(-x^2/2s^2) erf(sqrt(R^2 - x^2) / (s sqrt 2))."""
    x = np.linspace(-radius, radius, 400001)
    erf = np.vectorize(math.erf)
    m = np.exp(-0.5 * (x / sigma) ** 2) * erf(np.sqrt(np.maximum(radius ** 2 - x ** 2, 0)) / (sigma * math.sqrt(2)))
    c = np.concatenate([[0], np.cumsum(0.5 * (m[1:] + m[:-1]) * np.diff(x))])
    return np.interp(a, x, c / c[-1])


def test_gaussian_psf_is_the_analytic_convolution_of_a_radiance_step():
    # single scattering, nadir view, sun in the east below the slopes' limit:
    # the west-facing half has L_w = rho cos(theta + s) / pi, the east-facing
    # half L_e = rho cos(theta - s) / pi, exactly (no shadow, no masking)
    rho, s, theta, period = 0.6, math.radians(20.0), math.radians(40.0), 16
    scene = Scene.from_dem(_roof(period), material=Lambertian(rho))
    lw = rho * math.cos(theta + s) / math.pi
    le = rho * math.cos(theta - s) / math.pi
    box = scene.render(sun=(90.0, 40.0), shape=(2, period), spp=64, max_depth=1)
    assert np.allclose(box[:, : period // 2], lw, rtol=1e-6) and np.allclose(box[:, period // 2:], le, rtol=1e-6)
    sigma, trunc, spp = 1.2, 2.5, 40000
    img = scene.render(sun=(90.0, 40.0), shape=(2, period), spp=spp, max_depth=1, psf=("gaussian", sigma, trunc))
    x0 = np.arange(period) + 0.5
    r = sigma * trunc
    # fraction of the footprint on the east-facing half [8, 16) (mod 16)
    p = np.zeros(period)
    for shift in (-period, 0, period):
        lo, hi = period // 2 + shift - x0, period + shift - x0
        p += _disc_gauss_cdf(np.clip(hi, -r, r), sigma, r) - _disc_gauss_cdf(np.clip(lo, -r, r), sigma, r)
    want = lw + (le - lw) * p
    se = abs(le - lw) * np.sqrt(p * (1 - p) / spp)
    for row in img:
        assert np.all(np.abs(row - want) <= 4 * se + 2e-7 * want), (row, want, se)
    assert 0.3 < p[7] < 0.7 and p[3] < 1e-12  # the step is blurred, far pixels are exact


def test_array_psf_is_the_weighted_mean_of_neighbouring_boxes():
    rho, period, spp = 0.6, 16, 40000
    scene = Scene.from_dem(_roof(period), material=Lambertian(rho))
    box = scene.render(sun=(90.0, 40.0), shape=(1, period), spp=16, max_depth=1)[0].astype(float)
    w = np.array([[1.0, 2.0, 1.0]])
    img = scene.render(sun=(90.0, 40.0), shape=(1, period), spp=spp, max_depth=1, psf=w)[0]
    want = (np.roll(box, 1) + 2 * box + np.roll(box, -1)) / 4
    var = (np.roll(box, 1) ** 2 + 2 * box ** 2 + np.roll(box, -1) ** 2) / 4 - want ** 2
    assert np.all(np.abs(img - want) <= 4 * np.sqrt(np.maximum(var, 0) / spp) + 2e-7 * want)
    # cells two pixels wide: the weight-1 cells span [-3, -1) and [1, 3) pixels from the centre, i.e.
    # half of pixel j-3, all of j-2, half of j-1 (and mirrored), the pixels' edges at the centre +- 0.5
    img2 = scene.render(sun=(90.0, 40.0), shape=(1, period), spp=spp, max_depth=1, psf=[[1, 0, 1]],
                        psf_step=2.0)[0]
    wts = {3: 0.5, 2: 1.0, 1: 0.5, -1: 0.5, -2: 1.0, -3: 0.5}
    want2 = sum(w * np.roll(box, k) for k, w in wts.items()) / 4
    var2 = sum(w * np.roll(box, k) ** 2 for k, w in wts.items()) / 4 - want2 ** 2
    assert np.all(np.abs(img2 - want2) <= 4 * np.sqrt(np.maximum(var2, 0) / spp) + 2e-7 * want2)


def test_psf_box_and_threads():
    scene = Scene.from_dem(rough_tile(8), material=Lambertian(0.5))
    a = scene.render(sun=(100.0, 30.0), shape=(4, 4), spp=4, psf="box")
    assert np.array_equal(a, scene.render(sun=(100.0, 30.0), shape=(4, 4), spp=4))
    g1 = scene.render(sun=(100.0, 30.0), shape=(4, 4), spp=4, psf=("gaussian", 0.7), n_threads=1)
    g2 = scene.render(sun=(100.0, 30.0), shape=(4, 4), spp=4, psf=("gaussian", 0.7), n_threads=2)
    assert np.array_equal(g1, g2)


@pytest.mark.parametrize("psf,name", [("disc", "psf"), (("gaussian", -1.0), "psf"), (("airy", 1.0), "psf"),
                                      ([[1.0, -1.0]], "psf"), ([[0.0, 0.0]], "psf"), (np.ones(3), "psf")])
def test_psf_bad_input(psf, name):
    s = Scene.from_dem(np.zeros((4, 4)))
    with pytest.raises((ValueError, TypeError), match=name):
        s.render(sun=(0.0, 30.0), spp=1, psf=psf)
    with pytest.raises(ValueError, match="psf_step"):
        s.render(sun=(0.0, 30.0), spp=1, psf=[[1.0]], psf_step=0.0)


# ---- plot helpers (the plotted data, not pixels) ----

@pytest.fixture
def plt():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    yield plt
    plt.close("all")


def test_plot_principal_plane_data(plt):
    from fractalgeo_rs.radiometry import plot_brf_principal_plane

    scene = Scene.from_dem(rough_tile(8), material=Lambertian(0.5))
    vz = [-60, -30, 0, 30, 60]
    ax = plot_brf_principal_plane(scene, sun=(135.0, 40.0), view_zenith=vz, spp=2000, seed=4)
    x, y = ax.lines[0].get_xdata(), ax.lines[0].get_ydata()
    assert list(x) == vz
    for xi, yi in zip(x, y):
        view = (135.0 if xi >= 0 else 315.0, abs(xi))
        assert yi == scene.brf(sun=(135.0, 40.0), view=view, spp=2000, seed=4).value
    # the V-grooves' nadir point of the principal plane is rho cos(s)
    g = Scene.from_dem(v_grooves(), material=Lambertian(1.0))
    ax = plot_brf_principal_plane(g, sun=(90.0, 20.0), view_zenith=[0], spp=20000, max_depth=1)
    assert abs(ax.lines[0].get_ydata()[0] - math.cos(math.radians(30))) < 0.01


def test_plot_polar_data(plt):
    from fractalgeo_rs.radiometry import plot_brf_polar

    scene = Scene.from_dem(rough_tile(8), material=Lambertian(0.5))
    ax = plot_brf_polar(scene, sun=(45.0, 30.0), view_zenith=[0, 20, 40], view_azimuth=[0, 90, 180, 270],
                        spp=1000, seed=2)
    got = np.asarray(ax.collections[0].get_array()).reshape(3, 4)
    want = np.array([[scene.brf(sun=(45.0, 30.0), view=(a, z), spp=1000, seed=2).value
                      for a in (0, 90, 180, 270)] for z in (0, 20, 40)])
    assert np.array_equal(got, want)
    assert ax.name == "polar" and ax.get_theta_direction() == -1
    with pytest.raises(ValueError, match="view_azimuth"):
        plot_brf_polar(scene, sun=(45.0, 30.0), view_azimuth=[0, 400], spp=10)


def test_plot_incidence_series_data(plt):
    from fractalgeo_rs.radiometry import plot_incidence_series

    scene = Scene.from_dem(rough_tile(8), material=Lambertian(0.5))
    axes = plot_incidence_series(scene, sun_zenith=[0, 45, 89], shape=(8, 8), spp=2, seed=1)
    assert len(axes) == 3
    for a, z in zip(axes, (0, 45, 89)):
        assert np.array_equal(a.images[0].get_array(), scene.render(sun=(0.0, z), shape=(8, 8), spp=2, seed=1))
    assert len({a.images[0].get_clim() for a in axes}) == 1  # one grey scale
    with pytest.raises(TypeError, match="scene"):
        plot_incidence_series(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="axes"):
        plot_incidence_series(scene, sun_zenith=[0, 45], spp=1, axes=[axes[0]])


# ---- the full Oren-Nayar model ----

def _oren_nayar_full(rho, sigma, ti, to, dphi):
    """Oren & Nayar (1994), equations 27-29 and the interreflection term
    (section 4.4), transcribed from the paper in angles: the BRDF
    ``(L1 + L2) / (E0 cos(theta_i))``."""
    s2 = sigma ** 2
    alpha, beta = max(ti, to), min(ti, to)
    cd = math.cos(dphi)
    c1 = 1 - 0.5 * s2 / (s2 + 0.33)
    if cd >= 0:
        c2 = 0.45 * s2 / (s2 + 0.09) * math.sin(alpha)
    else:
        c2 = 0.45 * s2 / (s2 + 0.09) * (math.sin(alpha) - (2 * beta / math.pi) ** 3)
    c3 = 0.125 * (s2 / (s2 + 0.09)) * (4 * alpha * beta / math.pi ** 2) ** 2
    l1 = rho / math.pi * (c1 + cd * c2 * math.tan(beta) + (1 - abs(cd)) * c3 * math.tan((alpha + beta) / 2))
    l2 = 0.17 * rho ** 2 / math.pi * s2 / (s2 + 0.13) * (1 - cd * (2 * beta / math.pi) ** 2)
    return l1 + l2


@pytest.mark.parametrize("rho,sigma", [(0.5, 0.3), (0.9, 0.8), (0.3, 1.5)])
def test_full_oren_nayar_matches_the_paper(rho, sigma):
    # a flat plane, single scattering: BRF = pi f(sun, view) exactly
    from fractalgeo_rs.radiometry import OrenNayar

    s = Scene.from_dem(np.zeros((4, 4)), material=OrenNayar(rho, sigma, full=True))
    q = Scene.from_dem(np.zeros((4, 4)), material=OrenNayar(rho, sigma))
    for (az_s, zs), (az_v, zv) in [((0.0, 30.0), (0.0, 60.0)), ((0.0, 30.0), (180.0, 60.0)),
                                   ((40.0, 70.0), (130.0, 20.0)), ((10.0, 80.0), (300.0, 75.0)),
                                   ((0.0, 45.0), (0.0, 0.0)), ((200.0, 15.0), (90.0, 85.0))]:
        got = s.brf(sun=(az_s, zs), view=(az_v, zv), spp=64, max_depth=1).value
        want = math.pi * _oren_nayar_full(rho, sigma, math.radians(zs), math.radians(zv), math.radians(az_v - az_s))
        assert abs(got - want) <= 1e-12 * want, (got, want)
        assert abs(q.brf(sun=(az_s, zs), view=(az_v, zv), spp=64, max_depth=1).value - got) > 1e-4  # not the qualitative one


def test_full_oren_nayar_energy_and_input():
    from fractalgeo_rs.radiometry import OrenNayar

    with pytest.raises(ValueError, match="rho"):
        Scene.from_dem(np.zeros((4, 4)), material=OrenNayar(1.0, 0.3, full=True)).brf(sun=(0.0, 30.0), spp=10)
    with pytest.raises(TypeError, match="full"):
        OrenNayar(0.5, 0.3, full="yes")
    # a bright accepted surface: albedo of a flat plane (the model's own) at most 1
    s = Scene.from_dem(np.zeros((4, 4)), material=OrenNayar(0.9, 0.5, full=True))
    for zen in (0.0, 60.0, 85.0):
        assert s.albedo(sun=(0.0, zen), spp=20000).value <= 1.0


# ---- the perspective camera ----

def test_perspective_flat_plane_horizon_and_sky():
    rho, sky = 0.4, 0.3
    s = Scene.from_dem(np.zeros((5, 5)), material=Lambertian(rho))
    # horizontal view from 2 m: sky above the middle of the image, the lit plane below
    img = s.render_perspective(sun=(45.0, 30.0), eye=(1.0, -1.0, 2.0), target=(1.0, 50.0, 2.0), fov=60.0,
                               shape=(8, 6), spp=4, sky=sky)
    ground = rho * (math.cos(math.radians(30.0)) + sky) / math.pi
    assert np.allclose(img[:4], sky / math.pi, rtol=1e-6) and np.allclose(img[4:], ground, rtol=1e-6)
    a = s.render_perspective(sun=(45.0, 30.0), shape=(6, 8), spp=2, n_threads=1)
    assert np.array_equal(a, s.render_perspective(sun=(45.0, 30.0), shape=(6, 8), spp=2, n_threads=2))


def test_perspective_sees_the_same_surface_as_the_orthographic_sensor():
    # a camera far away with a narrow field of view looking straight down sees
    # the tile almost orthographically: the image means agree within noise
    scene = Scene.from_dem(rough_tile(16, amp=1.0), material=Lambertian(0.5))
    d = 4000.0
    fov = 2 * math.degrees(math.atan(8.0 / d))  # 16 m wide at the target
    img = scene.render_perspective(sun=(90.0, 40.0), view=(0.0, 0.0), distance=d, fov=fov, shape=(32, 32),
                                   spp=64, max_depth=1)
    ortho = scene.render(sun=(90.0, 40.0), shape=(32, 32), spp=64, max_depth=1)
    assert abs(img.mean() - ortho.mean()) < 0.01 * ortho.mean()
    assert np.corrcoef(img.ravel(), ortho.ravel())[0, 1] > 0.9


def test_perspective_bad_input():
    s = Scene.from_dem(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="fov"):
        s.render_perspective(sun=(0.0, 30.0), fov=180.0)
    with pytest.raises(ValueError, match="target"):
        s.render_perspective(sun=(0.0, 30.0), eye=(1.0, 1.0, 1.0), target=(1.0, 1.0, 1.0))
    with pytest.raises(TypeError, match="eye"):
        s.render_perspective(sun=(0.0, 30.0), eye=(1.0, 2.0))
    with pytest.raises(ValueError, match="distance"):
        s.render_perspective(sun=(0.0, 30.0), distance=-1.0)


def test_huge_spp_is_a_memory_error_not_an_abort():
    # the kernel keeps one partial sum per block of 1024 paths: spp = 2**62
    # asked for 9e16 bytes and aborted the interpreter (Rust OOM) before
    s = Scene.from_dem(np.zeros((4, 4)), material=Lambertian(0.5))
    for call in (lambda: s.brf(sun=(0.0, 30.0), spp=2**62), lambda: s.albedo(sun=(0.0, 30.0), spp=2**62),
                 lambda: s.bhr(spp=2**62), lambda: s.brf_sweep(sun_zenith=(0.0,), spp=2**62)):
        with pytest.raises(MemoryError, match="spp"):
            call()
    assert s.brf(sun=(0.0, 30.0), spp=1000).value == pytest.approx(0.5)


def test_perspective_image_is_not_georeferenced(tmp_path):
    # a camera view written with the DEM's transform scaled to the image was a
    # wrong map; orthographic images keep theirs
    pytest.importorskip("rasterio")
    from affine import Affine

    import fractalgeo_rs as fg

    prof = {"crs": "EPSG:32633", "transform": Affine(30, 0, 500, 0, -30, 900)}
    s = Scene.from_dem(np.zeros((4, 4)), profile=prof)
    persp = s.render_perspective(sun=(0.0, 30.0), shape=(3, 5), spp=1)
    ortho = s.render(sun=(0.0, 30.0), shape=(2, 2), spp=1)
    s.save_image(tmp_path / "p.tif", persp)
    s.save_image(tmp_path / "o.tif", ortho)
    s.save_image(tmp_path / "p.png", persp)
    s.save_image(tmp_path / "f.tif", persp, georeference=True)
    s.save_image(tmp_path / "n.tif", ortho, georeference=False)
    p, o = fg.read_raster(tmp_path / "p.tif")[1], fg.read_raster(tmp_path / "o.tif")[1]
    assert p["crs"] is None and p["transform"] == Affine.identity()
    assert o["crs"] is not None and tuple(o["transform"])[:6] == (60.0, 0.0, 515.0, 0.0, -60.0, 885.0)
    assert not (tmp_path / "p.pgw").exists()
    assert fg.read_raster(tmp_path / "f.tif")[1]["crs"] is not None
    assert fg.read_raster(tmp_path / "n.tif")[1]["crs"] is None
    with pytest.raises(TypeError, match="georeference"):
        s.save_image(tmp_path / "x.tif", ortho, georeference="yes")
    import pickle

    s2 = pickle.loads(pickle.dumps(s))  # still picklable after a perspective render
    assert np.array_equal(s2.dem, s.dem) and s2.profile == s.profile
