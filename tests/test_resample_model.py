"""Fractal resampling: the scale-aware default model, its diagnostics and the
bugs of issue 29 (each test here fails on the code before it)."""
import os
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.dem import _resample as R
from fractalgeo_rs.dem import _resample_model as M

DATA = os.path.join(os.path.dirname(__file__), "data")


def lag_var(z, k):
    return 0.5 * (np.nanmean((z[k:] - z[:-k]) ** 2) + np.nanmean((z[:, k:] - z[:, :-k]) ** 2))


def laplacian_sd(z):
    lap = z[1:-1, 2:] + z[1:-1, :-2] + z[2:, 1:-1] + z[:-2, 1:-1] - 4 * z[1:-1, 1:-1]
    return np.nanstd(lap)


def smooth_surface(n=64):
    """Smoother than any fBm at the pixel (raw lag-1/lag-2 H about 1)."""
    i, j = np.indices((n, n)) / n
    return 50 * np.sin(2.5 * i + 0.3) * np.cos(1.7 * j) + 20 * i * j


def test_model_shape_closed_forms():
    """D(h) / a: fBm for r = 0; h^2 H r^(2H - 2) for h << r; h^(2H) for
    h >> r; the block-mean structure function of white-noise-free fBm of
    H = 1/2 at lag 1 with 2 x 2 points against a direct double sum."""
    h = np.array([1e-3, 1.0, 1e3])
    np.testing.assert_allclose(M.shape_point(h, 0.0, 0.7), h ** 1.4)
    np.testing.assert_allclose(M.shape_point(1e-4, 2.0, 0.6), 1e-8 * 0.6 * 2.0 ** (1.2 - 2), rtol=1e-3)
    np.testing.assert_allclose(M.shape_point(1e6, 0.5, 0.6), 1e6 ** 1.2, rtol=1e-3)
    pts = [(a / 2 - 0.25, b / 2 - 0.25) for a in range(2) for b in range(2)]

    def mean_f(off):
        return np.mean([np.hypot(p[0] - q[0], p[1] - q[1] + off) for p in pts for q in pts])

    np.testing.assert_allclose(M.shape_block(1.0, 0.0, 0.5, 2), mean_f(1.0) - mean_f(0.0), rtol=1e-12)


@pytest.mark.parametrize("r, h", [(0.0, 0.4), (3.0, 0.5), (0.7, 0.8)])
def test_fit_recovers_the_model(r, h):
    """The fit of an exact model variogram returns its (r, H) (grid nodes)."""
    rr = M.R_GRID[np.argmin(np.abs(M.R_GRID - r))]
    hh = M.H_GRID[np.argmin(np.abs(M.H_GRID - h))]
    logd = np.log(7.0 * M.shape_point(np.array(M.LAGS, float), rr, hh))
    fr, fh, _ = M.fit(logd[None], 0)
    assert fr[0] == rr and fh[0] == hh


def test_level_params_reproduce_the_model_and_fbm():
    """Per-level power laws pass through D(s) and D(s/2); r = 0 gives the
    constant H and sigma of fBm at every level."""
    r, h, a = 1.5, 0.6, 4.0
    lh, ls = M.level_params(np.array(r), np.array(h), np.array(a), 3)
    assert lh[0] < lh[1] < M.LEVEL_H[1] == lh[2]  # smoother below r; clipped at the table's end
    for lvl in range(2):
        s = 2.0 ** -lvl
        for d in (s, s / 2):
            np.testing.assert_allclose(ls[lvl] ** 2 * d ** (2 * lh[lvl]), a * M.shape_point(d, r, h),
                                       rtol=1e-9)
    lh, ls = M.level_params(np.array(0.0), np.array(0.7), np.array(4.0), 3)
    np.testing.assert_allclose(lh, 0.7)
    np.testing.assert_allclose(ls, 2.0)


def test_fixed_hurst_with_local_sigma_does_not_warn_or_report_a_clip():
    """Bug: a fixed hurst with sigma='local' warned about clipping the local
    H (which is not used) and reported fraction_clipped = 0.91."""
    z = smooth_surface()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out, an = fg.fractal_resample(z, 2, hurst=0.5, sigma="local", seed=1, window_size=9,
                                      return_analysis=True)
    assert an.fraction_clipped == 0.0 and an.model == "fbm"
    assert np.all(an.hurst == 0.5)


def _block_variogram_lag1(h, n):
    """Var(Zbar(x + 1) - Zbar(x)) / sigma^2 for block means of n x n points
    at spacing 1/n (gamma(d) = d^(2H) / 2), by a direct double sum."""
    off = [(a + 0.5) / n - 0.5 for a in range(n)]
    pts = [(y, x) for y in off for x in off]

    def gbar(dx):
        return np.mean([0.5 * np.hypot(p[0] - q[0], p[1] - q[1] + dx) ** (2 * h) for p in pts for q in pts])

    return 2 * (gbar(1.0) - gbar(0.0))


def test_area_sigma_uses_the_users_hurst():
    """Bug: with support='area', a fixed hurst and sigma='local', sigma was
    g1 / gamma_block(1; local H) (22 % too small at hurst=0.5 on smooth
    terrain) instead of g1 / gamma_block(1; the user's H). On a plane
    3 i + 4 j the pooled lag-1 mean square is (9 + 16) / 2 in every window."""
    i, j = np.indices((40, 40), dtype=float)
    z = 3 * i + 4 * j
    _, an = fg.fractal_resample(z, 2, hurst=0.5, sigma="local", support="area", seed=1,
                                window_size=9, return_analysis=True)
    expect = np.sqrt(12.5 / _block_variogram_lag1(0.5, 2))
    np.testing.assert_allclose(an.sigma[20, 20], expect, rtol=2e-3)


def test_min_scale_needs_a_cell_size():
    """Bug: min_scale without cell_size took cells of 1 ground unit and
    silently removed all detail; coordinates in degrees are refused too."""
    z = fg.fbm_surface(33, 0.7, method="exact", seed=2)
    with pytest.raises(ValueError, match="^min_scale.*cell_size"):
        fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, min_scale=10.0)
    xr = pytest.importorskip("xarray")
    geo = xr.DataArray(z, dims=("lat", "lon"),
                       coords={"lat": 45 - np.arange(33) / 1200, "lon": 7 + np.arange(33) / 1200})
    with pytest.raises(ValueError, match="^cell_size.*degrees"):
        fg.fractal_resample(geo, 2, hurst=0.7, sigma=1.0, min_scale=10.0)
    # with the cell size in metres it runs
    fg.fractal_resample(geo, 2, hurst=0.7, sigma=1.0, min_scale=10.0, cell_size=(92.6, 66.7))


def test_anisotropic_cells_use_the_larger_side():
    """Bug: a 92 x 74 m cell was taken as 74 m (the x spacing only), so
    min_scale = 40 removed the detail of the first level's 46 x 37 m cells."""
    z = fg.fbm_surface(33, 0.7, method="exact", seed=2)
    ref = fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, seed=3)
    mean = fg.fractal_resample(z, 2, hurst=0.7, sigma=0.0, seed=3)
    a = fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, seed=3, cell_size=(92.0, 74.0), min_scale=40.0)
    assert np.array_equal(a, ref)
    b = fg.fractal_resample(z, 2, hurst=0.7, sigma=1.0, seed=3, cell_size=(92.0, 74.0), min_scale=50.0)
    assert np.array_equal(b, mean)
    xr = pytest.importorskip("xarray")
    da = xr.DataArray(z, dims=("y", "x"), coords={"y": 1e6 - 92.0 * np.arange(33), "x": 74.0 * np.arange(33)})
    c = fg.fractal_resample(da, 2, hurst=0.7, sigma=1.0, seed=3, min_scale=40.0)
    np.testing.assert_array_equal(c.values, ref)


def test_holes_grow_by_factor_minus_one_fine_cells_exactly():
    """A point-support output sample is NaN exactly when an input sample at
    a corner of the input cell it lies in is a hole (bilinear support):
    holes grow by f - 1 fine cells, not one (the old docs)."""
    rng = np.random.default_rng(4)
    z = fg.fbm_surface(24, 0.5, method="exact", seed=2)
    z[rng.random(z.shape) < 0.03] = np.nan
    z[10, 12] = np.nan
    for f in (2, 4):
        out = fg.fractal_resample(z, f, hurst=0.5, sigma=1.0, seed=1)
        hole = np.isnan(z)
        expect = np.zeros(out.shape, bool)
        for i, j in zip(*np.nonzero(hole)):
            expect[max(f * i - f + 1, 0):f * i + f, max(f * j - f + 1, 0):f * j + f] = True
        np.testing.assert_array_equal(np.isnan(out), expect)


def test_bicubic_baseline_is_on_the_output_grid():
    """Bug: the docs' and examples' bicubic baseline, zoom(c, f) cut to the
    output shape, is not on the output grid (off by up to half an input
    cell); the aligned baseline keeps the input samples (point) and
    reproduces a plane away from the edges (both supports; the spline's edge
    effect decays by 0.27 per cell), where zoom is off by up to 1.5."""
    from scipy import ndimage

    i, j = np.indices((40, 37), dtype=float)
    plane = 2 * i - 3 * j
    c = fg.fbm_surface(40, 0.5, method="exact", seed=1)[:, :37]
    m = 10
    for f in (2, 4):
        b = R._bicubic_aligned(c, f)
        np.testing.assert_allclose(b[::f, ::f], c, atol=1e-9)
        for support in ("point", "area"):
            p = R._bicubic_aligned(plane, f, support)
            off = 0.0 if support == "point" else 0.5 / f - 0.5
            ii, jj = np.indices(p.shape) / f + off
            inner = (slice(m * f, -m * f), slice(m * f, -m * f))
            np.testing.assert_allclose(p[inner], (2 * ii - 3 * jj)[inner], atol=1e-3)
        z = ndimage.zoom(plane, f, order=3)[:p.shape[0], :p.shape[1]]
        assert np.abs(z[inner] - (2 * ii - 3 * jj)[inner]).max() > 0.3


def test_clip_min_is_a_post_process():
    z = fg.fbm_surface(64, 0.5, method="exact", seed=3)
    z = z - z.min()  # every input >= 0, many new samples would go below
    a = fg.fractal_resample(z, 4, hurst=0.5, sigma=1.0, seed=1)
    b = fg.fractal_resample(z, 4, hurst=0.5, sigma=1.0, seed=1, clip_min=0.0)
    assert (a < 0).any() and b.min() == 0.0
    np.testing.assert_array_equal(b, np.maximum(a, 0.0))
    np.testing.assert_array_equal(b[::4, ::4], z)
    with pytest.raises(TypeError, match="^clip_min"):
        fg.fractal_resample(z, 2, clip_min="0")


def test_model_option_and_defaults():
    z = fg.fbm_surface(64, 0.6, method="exact", seed=3)
    _, an = fg.fractal_resample(z, 2, seed=1, return_analysis=True)
    assert an.model == "smooth" and an.level_hurst.shape == (1, 64, 64)
    _, an = fg.fractal_resample(z, 4, seed=1, return_analysis=True, model="fbm")
    assert an.model == "fbm" and an.level_hurst.shape == (1, 64, 64)
    with pytest.raises(ValueError, match="^model"):
        fg.fractal_resample(z, 2, hurst=0.6, model="smooth")
    with pytest.raises(ValueError, match="^model"):
        fg.fractal_resample(z, 2, model="kriging")


def test_smooth_terrain_gets_an_inner_scale_and_tapered_detail():
    """On a surface smoother than fBm at the pixel the default model finds an
    inner scale above one output cell everywhere, reports it (map, global,
    fractions, notes) and draws far less lag-1 variance than fBm of H = 0.95
    would; no warning (nothing was clipped)."""
    z = smooth_surface(96)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out, an = fg.fractal_resample(z, 4, seed=1, return_analysis=True, cell_size=30.0)
    assert an.fraction_smoother > 0.9 and an.fraction_tapered > 0.9
    assert np.median(an.inner_scale) > 1.0 and an.inner_scale_global > 1.0
    np.testing.assert_allclose(an.inner_scale_ground, 30.0 * an.inner_scale)
    assert any("tapered" in n for n in an.notes)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fb = fg.fractal_resample(z, 4, seed=1, model="fbm")
    mean = fg.fractal_resample(z, 4, seed=1, cell_size=1.0, min_scale=1e9)
    assert lag_var(out - mean, 1) < 0.5 * lag_var(fb - mean, 1)


def test_fbm_model_warning_says_which_side_and_what_it_does():
    z = smooth_surface()
    with pytest.warns(RuntimeWarning, match="smoother than fBm.*rougher than the DEM"):
        fg.fractal_resample(z, 2, seed=1, window_size=9, model="fbm")


def test_no_valid_increments_warns_naming_window_size():
    """Windows with a valid centre but no lag-1 pair (a sparse lattice of
    samples around a dense block): no detail there, and a warning that
    names window_size."""
    z = fg.fbm_surface(64, 0.6, method="exact", seed=3)
    i, j = np.indices(z.shape)
    z[(i % 3 != 0) | (j % 3 != 0)] = np.nan
    z[16:48, 16:48] = fg.fbm_surface(32, 0.6, method="exact", seed=4)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        fg.fractal_resample(z, 2, seed=1, window_size=5)
    assert any(str(w.message).startswith("window_size") and "no valid increments" in str(w.message)
               for w in rec), [str(w.message) for w in rec]


def test_numpy_dask_xarray_identical_and_coords():
    """Issue 25: xarray output coords in map units equal the fine grid's to
    1e-9; numpy, Dask and xarray (numpy- and Dask-backed) inputs give the
    same values, with the default (smooth) model and any chunking."""
    xr = pytest.importorskip("xarray")
    da = pytest.importorskip("dask.array")
    z = fg.fbm_surface(70, 0.6, method="exact", seed=3) * 40 + 500
    z[30:33, 5:9] = np.nan
    y = 4_000_000.0 - 30.0 * np.arange(70)
    x = 350_000.0 + 30.0 * np.arange(70)
    for support in ("point", "area"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            ref = fg.fractal_resample(z, 4, seed=2, support=support, window_size=9)
            arr = xr.DataArray(z, dims=("y", "x"), coords={"y": y, "x": x})
            a = fg.fractal_resample(arr, 4, seed=2, support=support, window_size=9)
            outs = [a.values]
            for chunks in ((20, 30), (70, 13)):
                outs.append(fg.fractal_resample(da.from_array(z, chunks=chunks), 4, seed=2,
                                                support=support, window_size=9).compute())
            b = fg.fractal_resample(arr.chunk({"y": 25, "x": 40}), 4, seed=2, support=support,
                                    window_size=9)
            outs.append(np.asarray(b.values))
        for o in outs:
            np.testing.assert_array_equal(o, ref)
        if support == "point":
            ey = y[0] - 7.5 * np.arange(4 * 69 + 1)
            ex = x[0] + 7.5 * np.arange(4 * 69 + 1)
        else:
            ey = y[0] + 15.0 - 7.5 * (np.arange(280) + 0.5)
            ex = x[0] - 15.0 + 7.5 * (np.arange(280) + 0.5)
        np.testing.assert_allclose(a.y.values, ey, rtol=0, atol=1e-9)
        np.testing.assert_allclose(a.x.values, ex, rtol=0, atol=1e-9)


def test_default_is_identical_for_any_thread_count_and_keeps_samples():
    z = fg.fbm_surface(80, 0.6, method="exact", seed=3)
    a = fg.fractal_resample(z, 4, seed=3, n_threads=1)
    b = fg.fractal_resample(z, 4, seed=3, n_threads=2)
    assert np.array_equal(a, b) and np.array_equal(a[::4, ::4], z)
    c = z.reshape(40, 2, 40, 2).mean((1, 3))
    o = fg.fractal_resample(c, 4, seed=3, support="area")
    np.testing.assert_allclose(o.reshape(40, 4, 40, 4).mean((1, 3)), c, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("holes", [False, True])
def test_node_variograms_match_direct_window_sums(holes):
    """Window sums and counts of squared increments at each lag at a few
    nodes, against a direct loop over the window (NaN halo, with and
    without holes: the two code paths)."""
    rng = np.random.default_rng(1)
    z = np.full((72, 80), np.nan)
    z[16:56, 16:64] = rng.standard_normal((40, 48)).cumsum(1)
    if holes:
        z[30:33, 40:42] = np.nan
    half = 5
    s, c, k0r, k0c = M.node_variograms(z, half)
    for a, b in ((2, 2), (3, 4), (5, 6), (4, 5)):
        p, q = (k0r + a) * R.STEP, (k0c + b) * R.STEP
        for li, lag in enumerate(M.LAGS):
            ss = cc = 0.0
            for i in range(p - half, p + half + 1):
                for j in range(q - half, q + half + 1):
                    for di, dj in ((lag, 0), (0, lag)):
                        if i + di < z.shape[0] and j + dj < z.shape[1]:
                            d = z[i + di, j + dj] - z[i, j]
                            if np.isfinite(d):
                                ss, cc = ss + d * d, cc + 1
            assert c[li, a, b] == cc, (a, b, lag)
            np.testing.assert_allclose(s[li, a, b], ss, rtol=1e-12)


@pytest.mark.parametrize("holes", [False, True])
@pytest.mark.parametrize("half", [16, 5, 3])
def test_rust_node_variograms_equal_the_numpy_reference(holes, half):
    """The Rust window sums (``_core.resample_node_variograms``) against the
    numpy twin on a real DEM (NaN halo; with holes: the masked code path of
    the reference), for every thread count: the same bits."""
    z = np.load(os.path.join(DATA, "bigtujunga_30m_crop128.npy")).astype(float)[:100, :90]
    if holes:
        z[30:33, 40:42] = np.nan
        z[70, 10] = np.nan
    zp = np.pad(z, M.pad_width(half), constant_values=np.nan)
    ref = M.node_variograms_reference(zp, half)
    for n in (1, 2, 3):
        got = M.node_variograms(zp, half, n_threads=n)
        assert got[2:] == ref[2:]
        np.testing.assert_array_equal(got[0], ref[0])
        np.testing.assert_array_equal(got[1], ref[1])


def test_rust_interp_to_pixels_equals_the_numpy_reference():
    rng = np.random.default_rng(4)
    half = 16
    t = M.pad_width(half)
    shape = (2 * t + 77, 2 * t + 50)
    k0r, k0c = 2, 3
    nr, nc = (shape[0] - t - 1) // R.STEP + 2 - k0r, (shape[1] - t - 1) // R.STEP + 2 - k0c
    v = rng.standard_normal((3, nr, nc))
    got = M.interp_to_pixels(v, k0r, k0c, shape, t)
    ref = M.interp_to_pixels_reference(v, k0r, k0c, shape, t)
    assert got.shape == ref.shape == (3, 77, 50)
    np.testing.assert_array_equal(got, ref)
    np.testing.assert_array_equal(M.interp_to_pixels(v, k0r, k0c, shape, t, n_threads=1), ref)
    with pytest.raises(ValueError, match="nodes"):
        M.interp_to_pixels(v[:, :-3], k0r, k0c, shape, t)


def test_resample_analysis_smooth_model_is_what_fractal_resample_uses():
    z = np.load(os.path.join(DATA, "bigtujunga_30m_crop128.npy")).astype(float)
    a = fg.dem.resample_analysis(z, model="smooth", factor=4, cell_size=30.0)
    _, b = fg.fractal_resample(z, 4, seed=1, return_analysis=True, cell_size=30.0)
    np.testing.assert_array_equal(a.level_hurst, b.level_hurst)
    np.testing.assert_array_equal(a.level_sigma, b.level_sigma)
    assert a.level_hurst.shape == (2,) + z.shape and a.model == "smooth"
    # real terrain: an inner scale above one output cell in most windows,
    # the finer level at least as smooth (the model's local exponent grows
    # towards small lags; here most windows reach the tables' 0.99)
    assert a.fraction_tapered > 0.5 and a.inner_scale_global > 0.25
    assert np.all(a.level_hurst[1] >= a.level_hurst[0])
    assert np.median(a.level_hurst[1]) > 0.9


@pytest.mark.parametrize("holes", [False, True])
def test_rust_local_amplitude_equals_the_numpy_reference_and_brute_force(holes):
    """``_core.resample_local_amplitude`` against the numpy twin (the same
    bits, any thread count) and against a direct loop over the 12
    increments of the 3 x 3 cells around a pixel (a closed form per pixel)."""
    z = np.load(os.path.join(DATA, "bigtujunga_30m_crop128.npy")).astype(float)[:70, :60]
    if holes:
        z[30:33, 40:42] = np.nan
        z[50, 10] = np.nan
    t = 8
    zp = np.pad(z, t, constant_values=np.nan)
    d1 = np.random.default_rng(3).uniform(50.0, 150.0, z.shape)
    d1[5, 5] = 0.0  # a window without detail: factor 1
    ref = M.local_amplitude_reference(zp, t, d1)
    for n in (1, 2, 3):
        np.testing.assert_array_equal(M.local_amplitude(zp, t, d1, n_threads=n), ref)
    assert ref[5, 5] == 1.0
    for i, j in [(0, 0), (10, 20), (31, 39), (49, 10), (69, 59)]:
        incs = []
        for a in range(i - 1, i + 2):
            for b in range(j - 1, j + 2):
                for da, db in ((1, 0), (0, 1)):
                    a2, b2 = a + da, b + db
                    if (a2 <= i + 1 and b2 <= j + 1 and 0 <= min(a, b) and a2 < z.shape[0]
                            and b2 < z.shape[1]):
                        d = z[a2, b2] - z[a, b]
                        if np.isfinite(d):
                            incs.append(d * d)
        want = np.sqrt(np.mean(incs) / d1[i, j]) if incs else 1.0
        np.testing.assert_allclose(ref[i, j], want, rtol=1e-12)


def test_detail_follows_the_local_relief():
    """Intermittency: a flat plain with one scarp. The window's lag-1
    variance is the scarp's, but the random detail sits on the scarp; on
    the flat part (no increment in the 3 x 3 cells around) it is 0, and the
    input samples are kept."""
    z = np.zeros((64, 64))
    z[:, 32:] = np.linspace(0.0, 30.0, 32)[None, :] + 5.0 * np.sin(np.arange(64) / 3.0)[:, None]
    out = fg.fractal_resample(z, 2, seed=1)
    np.testing.assert_array_equal(out[::2, ::2], z)
    # input columns 0-23: every 3 x 3 neighbourhood within 4 cells is flat
    # (the same-step conditioning carries under 1e-3 of the scarp's detail)
    assert np.abs(out[:, :48]).max() < 1e-3
    mean = fg.fractal_resample(z, 2, seed=1, cell_size=1.0, min_scale=10.0)
    assert np.std((out - mean)[:, 70:]) > 0.05
    # constant-H fBm spreads the window's amplitude over the flat part
    with pytest.warns(RuntimeWarning, match="smoother than fBm"):
        fbm = fg.fractal_resample(z, 2, seed=1, model="fbm")
    assert np.abs(fbm[:, 16:48]).max() > 0.05
