"""Synthetic SAR scenes: local incidence, radar shadow and layover of planes
and of an analytic ridge against the slant-range geometry worked out by hand;
flat ground gives sigma0; power is conserved by the projection."""
import math

import numpy as np
import pytest

import fractalgeo_rs as fg

WL = 0.056
SURF = dict(wavelength=WL, model="kirchhoff", permittivity=5 + 0.5j, rms_height=0.01, correlation_length=0.1,
            correlation="exponential")


def _sigma0(t):
    return fg.radar.backscatter(t, **{k: v for k, v in SURF.items()})


def _plane(shape, dx, slope_deg, look):
    """A plane rising away from a radar looking along ``look`` (negative
    slope: falling away)."""
    r, c = np.mgrid[0:shape[0], 0:shape[1]] * dx
    g = math.tan(math.radians(slope_deg))
    ground_range = {90: c, 270: -c, 180: r, 0: -r}[look]  # row index grows southwards
    return g * ground_range


def test_flat_ground_is_sigma0():
    for gr in (True, False):
        s = fg.radar.simulate(np.zeros((20, 30)), 5.0, look_azimuth=90, incidence=35, looks=None,
                              ground_range=gr, **SURF)
        np.testing.assert_allclose(s.image, _sigma0(35.0), rtol=1e-9)
        assert not s.layover.any() and not s.shadow.any()
    assert s.slant_range_spacing == pytest.approx(5.0 * math.sin(math.radians(35)))


@pytest.mark.parametrize("look", [0, 90, 180, 270])
@pytest.mark.parametrize("slope", [-30.0, 10.0, 25.0])
def test_local_incidence_of_a_plane(look, slope):
    z = _plane((12, 14), 2.0, slope, look)
    s = fg.radar.simulate(z, 2.0, look_azimuth=look, incidence=40, looks=None, **SURF)
    np.testing.assert_allclose(s.local_incidence, abs(40 - slope), atol=1e-9)
    # facet sigma0 x facet area / ground area x ground cells per slant bin:
    # sigma0(theta - s) / cos(s) * sin(theta) cos(s) / sin(theta - s)
    t = math.radians(40.0)
    want = _sigma0(abs(40 - slope)) * math.sin(t) / math.sin(t - math.radians(slope))
    np.testing.assert_allclose(s.sigma0[2:-2, 2:-2], want, rtol=1e-3)


@pytest.mark.parametrize("look", [90, 0])
def test_shadow_onset_at_ninety_minus_incidence(look):
    theta = 35.0
    lit = fg.radar.simulate(_plane((8, 9), 1.0, -(90 - theta) + 0.05, look), 1.0, look_azimuth=look,
                            incidence=theta, looks=None, **SURF)
    dark = fg.radar.simulate(_plane((8, 9), 1.0, -(90 - theta) - 0.05, look), 1.0, look_azimuth=look,
                             incidence=theta, looks=None, **SURF)
    assert not lit.shadow.any()
    assert dark.shadow.all()


def test_layover_when_slope_exceeds_incidence():
    theta = 30.0
    for slope, want in ((29.9, False), (30.1, True)):
        s = fg.radar.simulate(_plane((6, 10), 1.0, slope, 90), 1.0, look_azimuth=90, incidence=theta,
                              looks=None, **SURF)
        assert (s.layover.all() if want else not s.layover.any()), slope


def _ridge(cols, dx, x_foot, x_peak, x_back, h):
    x = np.arange(cols) * dx
    z = np.where(x < x_foot, 0.0, np.where(x <= x_peak, h * (x - x_foot) / (x_peak - x_foot),
                 np.where(x <= x_back, h * (x_back - x) / (x_back - x_peak), 0.0)))
    return x, z


def test_ridge_masks_match_the_slant_geometry():
    """Front slope 45 deg > theta = 30 (layover), back slope 63.4 deg > 60
    (shadow); the shadow runs on beyond the back foot until x - x_peak =
    h tan(theta); the flat ground in front shares slant range with the front
    slope (layover) for x_peak - h cot(theta) < x < x_foot."""
    dx, h, theta = 1.0, 40.0, 30.0
    x, z = _ridge(400, dx, 150.0, 190.0, 210.0, h)
    dem = np.tile(z, (3, 1))
    s = fg.radar.simulate(dem, dx, look_azimuth=90, incidence=theta, looks=None, **SURF)
    t = math.radians(theta)
    # shadow: cast by the peak (strictly below the ray) or facing away
    shadow = (x > 190.0) & (x - 190.0 < h * math.tan(t))
    margin = np.abs(x - 190.0 - h * math.tan(t)) > 1.5 * dx
    np.testing.assert_array_equal(s.shadow[1][margin], shadow[margin])
    # layover on the flat ground in front of the ridge
    front = x < 150.0
    lay = front & (x > 190.0 - h / math.tan(t))
    ok = front & (np.abs(x - (190.0 - h / math.tan(t))) > 1.5 * dx) & (np.abs(x - 150.0) > 1.5 * dx)
    np.testing.assert_array_equal(s.layover[1][ok], lay[ok])
    assert s.layover[1][(x > 151) & (x < 189)].all()  # the front slope itself
    assert not s.layover[1][x > 260].any() and not s.shadow[1][x > 260].any()


def test_power_is_conserved_in_slant_range():
    dem = fg.fbm_surface(64, 0.7, seed=3, sigma=3.0)
    s = fg.radar.simulate(dem, 2.0, look_azimuth=90, incidence=35, looks=None, ground_range=False, **SURF)
    g = fg.radar.simulate(dem, 2.0, look_azimuth=90, incidence=35, looks=None, **SURF)
    lit = ~g.shadow
    gx, gy = np.gradient(dem, 2.0)
    area = np.sqrt(1 + gx ** 2 + gy ** 2)
    want = (_sigma0(np.minimum(g.local_incidence, 89.9)) * area)[lit].sum()
    # edge footprints may reach beyond the first or last bin: compare the total
    assert np.nansum(s.sigma0) == pytest.approx(want, rel=2e-3)


def test_speckle_is_seeded_and_thread_invariant():
    dem = fg.fbm_surface(48, 0.6, seed=4, sigma=2.0)
    a = fg.radar.simulate(dem, 3.0, look_azimuth=270, incidence=30, looks=4, seed=8, n_threads=1, **SURF)
    b = fg.radar.simulate(dem, 3.0, look_azimuth=270, incidence=30, looks=4, seed=8, n_threads=3, **SURF)
    np.testing.assert_array_equal(a.image, b.image)
    lit = a.sigma0 > 0
    ratio = a.image[lit] / a.sigma0[lit]
    assert 0.8 < ratio.mean() < 1.2


def test_dataarray_keeps_coords_and_gives_cell_size():
    xr = pytest.importorskip("xarray")
    z = fg.fbm_surface(32, 0.7, seed=1, sigma=2.0)
    da = xr.DataArray(z, dims=("y", "x"), coords={"y": 1000.0 - 10.0 * np.arange(32), "x": 10.0 * np.arange(32)},
                      attrs={"crs": "EPSG:32632"})
    s = fg.radar.simulate(da, look_azimuth=90, incidence=35, looks=None, **SURF)
    ref = fg.radar.simulate(z, 10.0, look_azimuth=90, incidence=35, looks=None, **SURF)
    assert isinstance(s.image, xr.DataArray) and s.image.attrs["crs"] == "EPSG:32632"
    np.testing.assert_array_equal(s.image["x"], da["x"])
    np.testing.assert_allclose(s.image.values, ref.image)


@pytest.mark.parametrize("kw, err, match", [
    (dict(cell_size=None), ValueError, "cell_size"),
    (dict(look_azimuth=float("nan")), ValueError, "look_azimuth"),
    (dict(look_azimuth="east"), TypeError, "look_azimuth"),
    (dict(multilook=0), ValueError, "multilook"),
    (dict(multilook=(2, 2.5)), TypeError, "multilook"),
    (dict(incidence=90), ValueError, "incidence"),
    (dict(incidence=0), ValueError, "incidence"),
    (dict(wavelength=0.0), ValueError, "wavelength"),
    (dict(looks=0), ValueError, "looks"),
    (dict(model="iem"), ValueError, "model"),
])
def test_bad_input(kw, err, match):
    args = dict(SURF, cell_size=1.0, look_azimuth=90, incidence=35, looks=1, seed=1)
    args.update(kw)
    with pytest.raises(err, match=match):
        fg.radar.simulate(np.zeros((5, 5)), **args)


def test_bundled_real_dem():
    """SRTM Maritime Alps (66 x 92 m cells): a finite image everywhere, and
    layover shrinking as the incidence grows (slopes steeper than theta)."""
    dem, info = fg.data.srtm_alps()
    ns, ew = info["cell_size"]
    lay = []
    for inc in (25, 35, 45):
        s = fg.radar.simulate(dem, (ns, ew), look_azimuth=90, incidence=inc, looks=4, seed=1, **SURF)
        assert np.isfinite(s.image).all() and (s.image >= 0).all()
        lay.append(s.layover.mean())
    assert lay[0] > lay[1] > lay[2] >= 0 and lay[0] > 0.01


def test_validity_judged_at_the_scene_incidence():
    """Geometric optics is valid at 20 degrees for this surface (not at the
    89.9 degrees of the sigma0 table): no warning; SPM is not: one warning
    pointing at this file."""
    kw = dict(wavelength=WL, permittivity=5 + 0.5j, rms_height=0.05, correlation_length=0.5)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fg.radar.simulate(np.zeros((6, 6)), 1.0, look_azimuth=90, incidence=20, model="geometric_optics",
                          correlation="gaussian", looks=None, **kw)
    with pytest.warns(fg.radar.RadarValidityWarning, match="simulate: model='spm'") as rec:
        fg.radar.simulate(np.zeros((6, 6)), 1.0, look_azimuth=90, incidence=20, model="spm",
                          correlation="gaussian", looks=None, **kw)
    assert rec[0].filename == __file__


def _tilted(shape, dy, dx, grad_east, grad_north):
    i, j = np.mgrid[0:shape[0], 0:shape[1]]
    return grad_east * j * dx - grad_north * i * dy  # row index grows southwards


@pytest.mark.parametrize("look", [30.0, 137.5, 250.0, 341.0])
def test_arbitrary_azimuth_plane_closed_form(look):
    """A plane of gradient G seen from any azimuth: cos(theta_loc) = (cos theta + sin theta G.u) /
    sqrt(1 + |G|^2) (u the look direction) and the image sigma0(theta_loc) sqrt(1 + |G|^2) sin theta /
    (sin theta - G.u cos theta) (facet area over cell area times ground cells per slant bin); the
    DEM is resampled bilinearly (exact for a plane) onto a grid rotated to the look direction."""
    dy, dx, G = 3.0, 2.0, np.array([0.3, -0.2])
    z = _tilted((40, 50), dy, dx, *G)
    s = fg.radar.simulate(z, (dy, dx), look_azimuth=look, incidence=40, looks=None, **SURF)
    t, a = math.radians(40.0), math.radians(look)
    gu = G @ np.array([math.sin(a), math.cos(a)])
    cos_loc = (math.cos(t) + math.sin(t) * gu) / math.sqrt(1 + G @ G)
    want_inc = math.degrees(math.acos(cos_loc))
    np.testing.assert_allclose(s.local_incidence[3:-3, 3:-3], want_inc, atol=1e-9)
    want = _sigma0(want_inc) * math.sqrt(1 + G @ G) * math.sin(t) / (math.sin(t) - gu * math.cos(t))
    np.testing.assert_allclose(s.sigma0[3:-3, 3:-3], want, rtol=2e-3)
    assert not s.layover.any() and not s.shadow.any() and np.isfinite(s.image).all()


@pytest.mark.parametrize("look", [30.0, 212.0])
def test_arbitrary_azimuth_shadow_and_layover_onsets(look):
    theta = 35.0
    a = math.radians(look)
    u = np.array([math.sin(a), math.cos(a)])

    def run(slope):
        g = math.tan(math.radians(slope)) * u  # rising away from the radar along the look direction
        z = _tilted((30, 30), 1.0, 1.0, *g)
        return fg.radar.simulate(z, 1.0, look_azimuth=look, incidence=theta, looks=None, **SURF)

    inner = (slice(4, -4), slice(4, -4))
    assert not run(-(90 - theta) + 0.1).shadow[inner].any()
    assert run(-(90 - theta) - 0.1).shadow[inner].all()
    assert not run(theta - 0.1).layover[inner].any()
    assert run(theta + 0.1).layover[inner].all()


def test_grid_azimuths_unchanged_by_the_rotated_path():
    """0/90/180/270 take the exact grid path: 90 + 1e-12 is 90; the rotated path at 90 + 1e-6 agrees
    with it on a smooth DEM (nearest-cell resampling of the rotated grid)."""
    dem = fg.fbm_surface(64, 0.8, seed=2, sigma=1.0)
    a = fg.radar.simulate(dem, 5.0, look_azimuth=90, incidence=35, looks=4, seed=3, **SURF)
    b = fg.radar.simulate(dem, 5.0, look_azimuth=90 + 1e-12, incidence=35, looks=4, seed=3, **SURF)
    np.testing.assert_array_equal(a.image, b.image)
    c = fg.radar.simulate(dem, 5.0, look_azimuth=90 + 1e-6, incidence=35, looks=None, **SURF)
    np.testing.assert_allclose(c.local_incidence[3:-3, 3:-3], a.local_incidence[3:-3, 3:-3], atol=1e-3)


@pytest.mark.parametrize("looks, block", [(1, (3, 4)), (2, (2, 2)), (4, (1, 3))])
def test_multilook_enl(looks, block):
    """Block averaging n = az x rg independent L-look Gamma intensities gives Gamma(L n, sigma0 / (L n)):
    ENL = L n (mean, variance within 3 standard errors; Kolmogorov-Smirnov)."""
    st = pytest.importorskip("scipy.stats")
    az, rg = block
    n_eq = looks * az * rg
    s = fg.radar.simulate(np.zeros((150 * az, 150 * rg)), 5.0, look_azimuth=90, incidence=35, looks=looks,
                          seed=11, multilook=block, ground_range=False, **SURF)
    s0 = _sigma0(35.0)
    v = s.image.ravel()
    assert s.image.shape == (150, 150) and s.slant_range_spacing == pytest.approx(rg * 5.0 * math.sin(
        math.radians(35)))
    np.testing.assert_allclose(s.sigma0, s0, rtol=1e-9)
    n = v.size
    assert abs(v.mean() - s0) < 3 * s0 / math.sqrt(n_eq * n)
    var_se = s0 ** 2 / n_eq * math.sqrt((2 + 6 / n_eq) / n)
    assert abs(v.var() - s0 ** 2 / n_eq) < 3 * var_se
    assert st.kstest(v, st.gamma(n_eq, scale=s0 / n_eq).cdf).pvalue > 1e-3
    # terrain-geocoded: every cell of a block carries the block's value (flat ground: column j -> bin j)
    g = fg.radar.simulate(np.zeros((150 * az, 150 * rg)), 5.0, look_azimuth=90, incidence=35, looks=looks,
                          seed=11, multilook=block, **SURF)
    np.testing.assert_array_equal(g.image[::az, ::rg], s.image)
    np.testing.assert_array_equal(g.image, np.repeat(np.repeat(s.image, az, 0), rg, 1))


@pytest.mark.parametrize("look", [90, 270, 0, 180])
def test_dask_strips_equal_numpy(look):
    """Strips of whole range lines on the whole scene's slant axis, speckle placed by the global line:
    two chunkings (one splitting the range axis, rechunked to whole lines) give the numpy scene bit
    for bit, with relief that casts shadow and layover across chunk borders."""
    da = pytest.importorskip("dask.array")
    dem = fg.fbm_surface(72, 0.5, seed=6, sigma=30.0)
    dem[10, 20] = np.nan
    kw = dict(look_azimuth=look, incidence=25, looks=3, seed=4, **SURF)
    ref = fg.radar.simulate(dem, (3.0, 2.0), **kw)
    assert ref.shadow.any() and ref.layover.any()
    for chunks in ((17, 72), (25, 30)):
        s = fg.radar.simulate(da.from_array(dem, chunks=chunks), (3.0, 2.0), **kw)
        assert isinstance(s.image, da.Array)
        for a, b in ((s.image, ref.image), (s.sigma0, ref.sigma0), (s.local_incidence, ref.local_incidence),
                     (s.layover, ref.layover), (s.shadow, ref.shadow)):
            np.testing.assert_array_equal(a.compute(), b)
    # strips cut to fit dask's chunk-size budget (4 lines here)
    import dask

    with dask.config.set({"array.chunk-size": "2KiB"}):
        s = fg.radar.simulate(da.from_array(dem, chunks=(40, 72)), (3.0, 2.0), **kw)
        np.testing.assert_array_equal(s.image.compute(), ref.image)


def test_dask_xarray_keeps_coords():
    da = pytest.importorskip("dask.array")
    xr = pytest.importorskip("xarray")
    dem = fg.fbm_surface(32, 0.6, seed=2, sigma=5.0)
    x = xr.DataArray(da.from_array(dem, chunks=10), dims=("y", "x"),
                     coords={"y": 100.0 - 4.0 * np.arange(32), "x": 4.0 * np.arange(32)}, attrs={"crs": "x"})
    s = fg.radar.simulate(x, look_azimuth=90, incidence=35, looks=2, seed=3, **SURF)
    ref = fg.radar.simulate(dem, 4.0, look_azimuth=90, incidence=35, looks=2, seed=3, **SURF)
    np.testing.assert_array_equal(s.image.compute().values, ref.image)
    assert s.image.attrs["crs"] == "x" and s.image.name == "sar_intensity"


def test_dask_refuses_what_would_not_be_exact():
    da = pytest.importorskip("dask.array")
    d = da.zeros((16, 16), chunks=8)
    with pytest.raises(ValueError, match="look_azimuth: with a Dask DEM, expected a multiple of 90"):
        fg.radar.simulate(d, 1.0, look_azimuth=33, incidence=35, looks=None, **SURF)


@pytest.mark.parametrize("look,multilook,ground", [(90, None, False), (270, (3, 2), False), (0, (4, 1), True),
                                                   (180, (2, 3), True), (90, (5, 4), False)])
def test_dask_slant_range_and_multilook_equal_numpy(look, multilook, ground):
    """Slant-range images and multilooked scenes of a Dask DEM: strips of whole blocks of lines on the
    whole scene's slant axis give the numpy scene bit for bit, for two chunkings and a tight
    chunk-size budget (strips of a few blocks), with shadow and layover across strip borders."""
    da = pytest.importorskip("dask.array")
    import dask

    dem = fg.fbm_surface(61, 0.5, seed=6, sigma=30.0)[:, :58]
    dem[10, 20] = np.nan
    kw = dict(look_azimuth=look, incidence=25, looks=3, seed=4, multilook=multilook, ground_range=ground, **SURF)
    ref = fg.radar.simulate(dem, (3.0, 2.0), **kw)
    assert ref.geometry == ("ground" if ground else "slant")
    assert ref.layover.any()
    for chunks, budget in (((17, 58), None), ((25, 30), None), ((40, 58), "3KiB")):
        with dask.config.set({"array.chunk-size": budget or "128MiB"}):
            s = fg.radar.simulate(da.from_array(dem, chunks=chunks), (3.0, 2.0), **kw)
        assert isinstance(s.image, da.Array) and s.geometry == ref.geometry
        assert s.slant_range_spacing == ref.slant_range_spacing
        for a, b in ((s.image, ref.image), (s.sigma0, ref.sigma0), (s.local_incidence, ref.local_incidence),
                     (s.layover, ref.layover), (s.shadow, ref.shadow)):
            assert a.shape == b.shape
            np.testing.assert_array_equal(a.compute(), b)


@pytest.mark.parametrize("look", [90, 180, 33.0])
def test_fused_scene_equals_the_composed_kernels(look):
    """simulate's fused per-line kernel gives exactly what geometry, projection, speckle and geocoding
    give as separate whole-scene steps (those reached through the multilook-free slant path)."""
    from fractalgeo_rs import _core

    dem = fg.fbm_surface(40, 0.6, seed=5, sigma=4.0)
    dem[7, 9] = np.nan
    s = fg.radar.simulate(dem, 2.0, look_azimuth=look, incidence=30, looks=3, seed=9, **SURF)
    sl = fg.radar.simulate(dem, 2.0, look_azimuth=look, incidence=30, looks=3, seed=9, ground_range=False,
                           **SURF)
    # the geocoding of the separate steps, on the range frame of the slant path
    from fractalgeo_rs.radar import _scene

    az, key = _scene._look(look)
    frame = None
    if key is None:
        frame = _scene._rotated_grid(dem.shape, 2.0, 2.0, az)
        zr = _scene._to_rotated(dem, 2.0, 2.0, frame)
    else:
        zr = np.ascontiguousarray(_scene._TO_RANGE[key](dem))
    table = fg.radar.backscatter(np.arange(900) * 0.1, **SURF)
    _, _, pos, flags, n_bins = _core.radar_geometry(zr, 2.0, 2.0, 30.0, list(table), 0.1)
    count = _core.radar_project(_core.radar_geometry(zr, 2.0, 2.0, 30.0, list(table), 0.1)[1], pos, flags,
                                n_bins)[1]
    g_img, g_s0, g_lay = _core.radar_geocode(sl.image, sl.sigma0, count, pos, flags)
    ref = _scene._to_ground(g_img, g_s0, g_lay.view(bool), (flags & 1).view(bool), sl.local_incidence, dem,
                            dem, "numpy", key, frame, 2.0, 2.0, sl.slant_range_spacing)
    for a, b in ((s.image, ref.image), (s.sigma0, ref.sigma0), (s.local_incidence, ref.local_incidence)):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(s.layover, ref.layover)
    np.testing.assert_array_equal(s.shadow, ref.shadow)
    assert np.isnan(s.image[7, 9]) and np.isfinite(s.image[20:, 20:]).all()


def test_dataarray_in_degrees_needs_cell_size():
    # lat/lon coords in degrees were taken as metres: 0.0008 m cells, a scene
    # 96 % in shadow and 85 % in layover instead of an error
    xr = pytest.importorskip("xarray")
    z = np.zeros((8, 8))
    lat, lon = 44.5 - 0.00083 * np.arange(8), 7.2 + 0.00083 * np.arange(8)
    for dims, coords in ((("lat", "lon"), {"lat": lat, "lon": lon}),
                         (("y", "x"), {"y": xr.DataArray(lat, dims="y", attrs={"units": "degrees_north"}),
                                       "x": xr.DataArray(lon, dims="x", attrs={"units": "degrees_east"})})):
        geo = xr.DataArray(z, dims=dims, coords=coords)
        with pytest.raises(ValueError, match="^cell_size:.*degrees"):
            fg.radar.simulate(geo, look_azimuth=90, incidence=35, wavelength=0.056, looks=None)
        s = fg.radar.simulate(geo, (92.6, 66.3), look_azimuth=90, incidence=35, wavelength=0.056, looks=None)
        assert not s.shadow.any() and not s.layover.any()


def test_fbm_microscale_needs_only_hurst_and_topothesy():
    # simulate's rms_height/correlation_length defaults (0.01, 0.1) were passed on with
    # correlation="fbm", which then raised "rms_height: an fBm surface has no rms height"
    import warnings

    kw = dict(wavelength=0.056, correlation="fbm", hurst=0.7, topothesy=1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", fg.radar.RadarValidityWarning)
        s = fg.radar.simulate(np.zeros((6, 6)), 10.0, look_azimuth=90, incidence=35, looks=None, **kw)
        ref = fg.radar.backscatter(35.0, permittivity=5 + 0.5j, **kw)
    np.testing.assert_allclose(s.image, ref, rtol=1e-12)
    flat = fg.radar.simulate(np.zeros((6, 6)), 10.0, look_azimuth=90, incidence=35, wavelength=0.056, looks=None)
    np.testing.assert_allclose(flat.image, fg.radar.backscatter(35.0, wavelength=0.056, permittivity=5 + 0.5j,
                                                                rms_height=0.01, correlation_length=0.1,
                                                                correlation="exponential"), rtol=1e-12)
