"""The GLS local-H map (fractal_transform(method="gls")) and its whole-image
estimator (gls_dimension / dimension(method="gls"))."""
import importlib

import numpy as np
import pytest

import fractalgeo_rs as fg

G = importlib.import_module("fractalgeo_rs.dimension.gls")

W = 17  # tables for 17 x 17 are quick to build


@pytest.fixture(scope="module")
def field():
    return fg.fbm_surface((160, 160), 0.5, method="exact", seed=3)


def test_expected_variation_is_the_closed_form():
    # first differences: c = |step|^(2H); second differences: 4 - 4^H along
    # the step (4 |u|^(2H) - |2u|^(2H) with unit sigma)
    t = G.tables((W, W), 2)
    h = G.H_GRID[20]
    for (offs, w, _, (order, di, u)), a, r in zip(t["filters"], t["a"][20], t["rel_var"][20]):
        step = u * (np.sqrt(2.0) if di >= 2 else 1.0)
        c = step ** (2 * h) if order == 1 else (4 - 2 ** (2 * h)) * step ** (2 * h)
        assert a == pytest.approx(np.log(c) - r / 2, abs=1e-12)


def test_log_covariance_is_the_delta_method_plus_the_satterthwaite_excess():
    # off the diagonal: the correlation of the V_f (unchanged by the
    # independent term); on it: psi'(1 / r) = Var log of a scaled chi-square
    # with 2 / r degrees of freedom, checked against a simulated chi-square
    t = G.tables((W, W), 2)
    r, sig = t["rel_var"][40], t["sigma"][40]
    nu = 2.0 / r
    rng = np.random.default_rng(5)
    for k in (0, int(np.argmax(r))):
        draws = np.log(rng.chisquare(nu[k], 400_000))
        assert sig[k, k] == pytest.approx(draws.var(), rel=0.01), k
    off = sig - np.diag(np.diag(sig))
    assert np.all(np.diag(sig) > r)  # the excess is positive
    np.testing.assert_allclose(off, off.T)
    assert np.all(np.linalg.eigvalsh(sig) > 0)


def test_da_is_the_derivative_of_a_and_hermite_interpolation_is_exact_enough():
    # da/dH against a centred difference of tables computed at H -+ e, and a
    # (Hermite from a, da on H_GRID) against tables computed at the midpoints
    e = 1e-5
    for h in (0.31, 0.79):
        t = G._tables((W, W), 2, h_grid=[h - e, h, h + e])
        np.testing.assert_allclose(t["da"][1], (t["a"][2] - t["a"][0]) / (2 * e), atol=1e-6)
    t = G.tables((W, W), 2)
    mids = G.H_GRID[:-1] + 0.01
    tm = G._tables((W, W), 2, h_grid=mids)
    for i, h in enumerate(mids):
        a, g, _ = G.interp(t, float(h))
        # the error in H of one Gauss-Newton step, against the standard error
        assert abs(g @ (tm["a"][i] - a)) < 0.005 * tm["se"][i], h


def test_variance_of_a_variation_matches_simulation():
    # Var(V_f) of the tables against the spread of V over exact fBm windows
    rng_vals = []
    for s in range(60):
        z = fg.fbm_surface((W, W), 0.3, method="exact", seed=100 + s)
        rng_vals.append(G.quadratic_variations(z, 1)[0])
    y = np.log(np.array(rng_vals))
    t = G.tables((W, W), 1)
    i = int(np.argmin(abs(G.H_GRID - 0.3)))
    pred = np.sqrt(np.diag(t["sigma"][i]))
    # sd of a sample sd of 60 draws: about 9 %; allow 30 % per filter
    np.testing.assert_allclose(y.std(axis=0, ddof=1), pred, rtol=0.3)


def test_map_equals_the_whole_image_estimator_on_windows(field):
    z = field.copy()
    z[40:44, 60:63] = np.nan
    d, se = fg.fractal_transform(z, W, method="gls", return_fit=True)
    h = W // 2
    for i, j in [(80, 80), (42, 61), (0, 0), (5, 159), (159, 70), (45, 58)]:
        win = z[max(i - h, 0):i + h + 1, max(j - h, 0):j + h + 1]
        if np.count_nonzero(~np.isnan(win)) < 0.5 * W * W:
            assert np.isnan(d[i, j])
            continue
        fit = fg.dimension(win, method="gls", design=(W, W))
        assert d[i, j] == pytest.approx(fit.dimension, abs=1e-5), (i, j)
        assert se[i, j] == pytest.approx(fit.stderr, rel=1e-4), (i, j)


def test_bias_and_spread_on_exact_fbm_within_the_standard_error():
    for h in (0.3, 0.7):
        ds, ses = [], []
        for s in range(3):
            z = fg.fbm_surface((272, 272), h, method="exact", seed=s)
            d, se = fg.fractal_transform(z, W, method="gls", return_fit=True)
            ds.append(d[W:-W:W, W:-W:W].ravel())  # disjoint windows
            ses.append(se[W:-W:W, W:-W:W].ravel())
        d, se = np.concatenate(ds), np.concatenate(ses)
        n = d.size  # 3 x 14 x 14
        # windows of one field are correlated through the field: allow 4 sd of the mean
        assert abs(d.mean() - (3 - h)) < 4 * se.mean() / np.sqrt(n) + 0.003, h
        # the standard-error map matches the spread across windows (sd of a
        # sd from ~590 values: 3 %)
        assert d.std() == pytest.approx(se.mean(), rel=0.12), h


def test_profile_estimator_on_exact_fbm():
    hs = []
    for s in range(20):
        x = fg.fbm(2048, 0.3, seed=s)
        fit = fg.dimension(x, method="gls")
        hs.append(fit.dimension)
    hs = np.array(hs)
    assert fit.method == "gls" and fit.extra["hurst"] == pytest.approx(2 - fit.dimension)
    assert abs(hs.mean() - 1.7) < 4 * fit.stderr / np.sqrt(len(hs))
    assert hs.std() == pytest.approx(fit.stderr, rel=0.4)


def test_threads_step_and_dtypes(field):
    a = fg.fractal_transform(field, W, method="gls", n_threads=1)
    b = fg.fractal_transform(field, W, method="gls", n_threads=2)
    assert a.tobytes() == b.tobytes()
    g = fg.fractal_transform(field, W, method="gls", step=3)
    np.testing.assert_allclose(g, a[::3, ::3], atol=1e-5)
    f32 = fg.fractal_transform(field.astype(np.float32), W, method="gls")
    np.testing.assert_allclose(f32, fg.fractal_transform(field.astype(np.float32).astype(np.float64), W,
                                                         method="gls"), atol=1e-5)
    assert not np.shares_memory(a, field)


def test_scale_free_and_plane_free(field):
    a = fg.fractal_transform(field, W, method="gls")
    i, j = np.indices(field.shape)
    b = fg.fractal_transform(7.5 * field + 3.0, W, method="gls")
    np.testing.assert_allclose(a, b, atol=2e-5)
    # a plane changes first differences: only the second differences are
    # plane free, so a strong plane changes the estimate (no invariance claim)
    assert np.isfinite(fg.fractal_transform(field + 0.001 * i, W, method="gls")[8:-8, 8:-8]).all()


def test_nodata_and_min_valid(field):
    z = field.copy()
    z[:, :30] = -9999.0
    d = fg.fractal_transform(z, W, method="gls", nodata=-9999.0)
    zn = field.copy()
    zn[:, :30] = np.nan
    np.testing.assert_array_equal(d, fg.fractal_transform(zn, W, method="gls"))
    assert np.isnan(d[:, :20]).all() and np.isfinite(d[10:-10, 40:-10]).all()


def test_anisotropy_of_an_affine_fbm():
    # isotropic exact fBm sampled on a fine grid, read on a stretched rotated
    # lattice: z(p) = B(A p) with A = R(theta) diag(s, 1) R(theta)' (nearest
    # fine-grid sample; the fine grid is 4x finer than the coarse lattice)
    h, s, theta = 0.5, 2.0, np.radians(30.0)
    fine = fg.fbm_surface((1024, 1024), h, method="exact", seed=11)
    R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    A = R @ np.diag([s, 1.0]) @ R.T
    n = 96
    i, j = np.indices((n, n)).reshape(2, -1).astype(float)
    p = A @ np.vstack([j, i])  # (x = col, y = row)
    x = np.rint(4 * (p[0] - p[0].min())).astype(int)
    y = np.rint(4 * (p[1] - p[1].min())).astype(int)
    z = fine[y, x].reshape(n, n)
    fit = fg.dimension(z, method="gls", anisotropy=True)
    # M = A' A: fastest variation along A's stretched axis at 30 degrees from
    # the column axis towards the row axis; ratio of singular values s
    assert fit.extra["anisotropy_ratio"] == pytest.approx(s, rel=0.15)
    assert abs(fit.extra["anisotropy_angle"] - 30.0) < 8.0
    iso = fg.dimension(fg.fbm_surface((96, 96), h, method="exact", seed=2), method="gls", anisotropy=True)
    assert iso.extra["anisotropy_ratio"] < 1.25
    # the map's anisotropy layers equal the whole-image value on a window
    d, se, ang, ratio = fg.fractal_transform(z, 33, method="gls", anisotropy=True, return_fit=True)
    win = z[48 - 16:48 + 17, 40 - 16:40 + 17]
    wfit = fg.dimension(win, method="gls", anisotropy=True)
    assert ang[48, 40] == pytest.approx(wfit.extra["anisotropy_angle"], abs=1e-3)
    assert ratio[48, 40] == pytest.approx(wfit.extra["anisotropy_ratio"], rel=1e-4)
    only = fg.fractal_transform(z, 33, method="gls", anisotropy=True)
    assert len(only) == 3 and np.array_equal(only[1], ang, equal_nan=True)


def test_dask_and_xarray_equal_in_memory(field):
    da = pytest.importorskip("dask.array")
    xr = pytest.importorskip("xarray")
    ref = fg.fractal_transform(field, W, method="gls", return_fit=True)
    out = fg.fractal_transform(da.from_array(field, chunks=50), W, method="gls", return_fit=True)
    for r, o in zip(ref, out):
        np.testing.assert_allclose(o.compute(), r, atol=1e-5, equal_nan=True)
    x = xr.DataArray(field, dims=("y", "x"), attrs={"units": "m"})
    xd = fg.fractal_transform(x, W, method="gls")
    np.testing.assert_allclose(xd.values, ref[0], atol=0, equal_nan=True)


def test_bad_inputs(field):
    with pytest.raises(ValueError, match="^dilations"):
        fg.fractal_transform(field, 7, method="gls", dilations=2)
    with pytest.raises(ValueError, match="^dilations"):
        fg.fractal_transform(field, W, method="gls", dilations=0)
    with pytest.raises(TypeError, match="^dilations"):
        fg.fractal_transform(field, W, method="gls", dilations=1.5)
    with pytest.raises(TypeError, match="^anisotropy"):
        fg.fractal_transform(field, W, method="gls", anisotropy="yes")
    with pytest.raises(ValueError, match="^window_size"):
        fg.fractal_transform(field, 16, method="gls")
    with pytest.raises(ValueError, match="^data"):
        fg.dimension(np.zeros((40, 40)), method="gls")
    with pytest.raises(ValueError, match="^anisotropy"):
        fg.dimension(fg.fbm(256, 0.5, seed=1), method="gls", anisotropy=True)
    with pytest.raises(ValueError, match="^design"):
        fg.dimension(field, method="gls", design=(5,))


def test_inf_is_missing_and_huge_values_never_give_garbage(field):
    z = field.copy()
    z[80, 80] = np.inf
    with pytest.warns(RuntimeWarning, match="inf"):
        d = fg.fractal_transform(z, W, method="gls")
    zn = field.copy()
    zn[80, 80] = np.nan
    np.testing.assert_array_equal(d, fg.fractal_transform(zn, W, method="gls"))
    # squares that overflow: those windows are missing, never a finite garbage value
    big = fg.fractal_transform(field * 1e200, W, method="gls")
    ok = np.isfinite(big)
    ref = fg.fractal_transform(field, W, method="gls")
    np.testing.assert_allclose(big[ok], ref[ok], atol=1e-4)


def test_small_windows_estimate_within_their_standard_error(field):
    # window 9 (the smallest for dilations 2): every filter has a
    # non-singular covariance; spread across disjoint windows (256 of them:
    # sd of a sd about 5 %) close to the standard-error map
    d, se = fg.fractal_transform(field, 9, method="gls", dilations=2, return_fit=True)
    d, se = d[9:-9:9, 9:-9:9].ravel(), se[9:-9:9, 9:-9:9].ravel()
    assert np.isfinite(d).all()
    assert abs(d.mean() - 2.5) < 4 * se.mean() / np.sqrt(d.size) + 0.01
    assert d.std() == pytest.approx(se.mean(), rel=0.2)
    # a window below 4 k + 1 pixels is refused, naming the parameter
    with pytest.raises(ValueError, match="^dilations: 2 needs a window of at least 9"):
        fg.fractal_transform(field, 7, method="gls", dilations=2)


def test_design_and_anisotropy_checks_name_the_parameter():
    z = np.random.default_rng(1).standard_normal((33, 33)).cumsum(0).cumsum(1)
    for kw, exc, start in [({"design": 5}, TypeError, "design"), ({"design": ("a", "b")}, TypeError, "design"),
                           ({"design": (1000, 1000)}, ValueError, "design"),
                           ({"anisotropy": "yes"}, TypeError, "anisotropy")]:
        with pytest.raises(exc, match=f"^{start}"):
            fg.gls_dimension(z, **kw)


def test_pinned_estimates_are_flagged_and_warned():
    """Surfaces smoother than fBm at dilations 1-2 (smoothed white noise;
    windows of the bundled Sentinel-1 dB scene) drive H to the end of the
    grid: the whole-image fit is flagged invalid with no interval, and the
    map warns with the pinned fraction."""
    from scipy import ndimage

    vv, _ = fg.data.sentinel1_vv_db()
    smooth = ndimage.gaussian_filter(np.random.default_rng(0).standard_normal((128, 128)), 2.0)
    with pytest.warns(fg.FractalRangeWarning, match="pinned at the upper end"):
        fit = fg.gls_dimension(smooth)
    assert not fit.valid and "pinned" in fit.flags and np.isnan(fit.ci95[0])
    with pytest.warns(fg.FractalRangeWarning, match=r"% of the windows are pinned"):
        fg.fractal_transform(vv, 33, method="gls", step=8)
    with pytest.warns(fg.FractalRangeWarning, match="lower end"):
        fg.gls_dimension(np.random.default_rng(0).standard_normal((128, 128)))
