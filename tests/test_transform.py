"""Fractal transform: exactness against the per-window estimator, Dask and
xarray equality, errors."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractals import spectral_surface


def per_window(z, w, method, lags=(1, 2), min_valid=0.5):
    """surface_variation on every window of the NaN-padded image."""
    est, p = {"variogram": ("first", 2.0), "madogram": ("first", 1.0), "square": ("square", 2.0)}[method]
    h = w // 2
    zp = np.pad(z.astype(float), h, constant_values=np.nan)
    win = np.lib.stride_tricks.sliding_window_view(zp, (w, w))
    out = np.full(z.shape, np.nan)
    for i in range(z.shape[0]):
        for j in range(z.shape[1]):
            a = win[i, j]
            if np.count_nonzero(~np.isnan(a)) < min_valid * w * w:
                continue
            try:
                out[i, j] = fg.surface_variation(a, estimator=est, p=p, lags=lags).dimension
            except ValueError:
                pass
    return out


@pytest.mark.parametrize("method", ["variogram", "madogram", "square"])
def test_map_equals_per_window_estimator_with_holes(method):
    rng = np.random.default_rng(1)
    z = spectral_surface(64, 0.5, 3)[:40, :29] * 10
    z[rng.random(z.shape) < 0.08] = np.nan
    z[5:12, 3:9] = np.nan
    d = fg.fractal_transform(z, 7, method=method, lags=(1, 2, 3))
    ref = per_window(z, 7, method, lags=(1, 2, 3))
    assert np.array_equal(np.isnan(d), np.isnan(ref))
    ok = ~np.isnan(ref)
    assert np.allclose(d[ok], ref[ok], atol=1e-5)


def test_real_sar_window():
    vv, _ = fg.data.sentinel1_vv_db()
    z = vv[100:160, 200:250]
    d = fg.fractal_transform(z, 9, method="variogram")
    ref = per_window(z, 9, "variogram")
    assert np.allclose(d, ref, atol=1e-5, equal_nan=True)


def test_threads_and_input_untouched():
    z = spectral_surface(128, 0.4, 0)
    z32 = z.astype(np.float32)
    before = z32.copy()
    a = fg.fractal_transform(z32, 15, n_threads=1)
    b = fg.fractal_transform(z32, 15, n_threads=3)
    assert np.array_equal(a, b, equal_nan=True)
    assert np.array_equal(z32, before)
    assert a.dtype == np.float32 and a.shape == z32.shape


def test_dask_equals_in_memory_for_any_chunking():
    da = pytest.importorskip("dask.array")
    z = spectral_surface(128, 0.6, 4)[:100, :90]
    z[40:44, 10:70] = np.nan
    ref = fg.fractal_transform(z, 11)
    for chunks in [(50, 45), (33, 90), (100, 20), (4, 4)]:
        out = fg.fractal_transform(da.from_array(z, chunks=chunks), 11).compute()
        assert np.allclose(out, ref, atol=1e-6, equal_nan=True), chunks


@pytest.mark.parametrize("method", ["mass", "variogram", "madogram", "square"])
def test_step_grid_is_the_full_map_subsampled(method):
    """The Rust kernels compute only the step grid (every step-th pixel of
    every step-th row); it must be the full map's values there, NaN holes and
    edges included, in memory and through Dask."""
    z = spectral_surface(128, 0.6, 4)[:101, :87] * 3
    z[40:44, 10:70] = np.nan
    z[:6, :9] = np.nan
    ref = fg.fractal_transform(z, 11, method=method, return_fit=True)
    for step in (2, 3, 5, 11, 40):
        out = fg.fractal_transform(z, 11, method=method, step=step, return_fit=True)
        for a, b in zip(out, ref):
            assert a.dtype == np.float32 and a.shape == b[::step, ::step].shape
            assert np.array_equal(np.isnan(a), np.isnan(b[::step, ::step])), step
            assert np.allclose(a, b[::step, ::step], atol=1e-6, equal_nan=True), step
    da = pytest.importorskip("dask.array")
    for chunks in [(50, 45), (30, 87)]:
        got = fg.fractal_transform(da.from_array(z, chunks=chunks), 11, method=method, step=3).compute()
        assert np.allclose(got, ref[0][::3, ::3], atol=1e-6, equal_nan=True), chunks


@pytest.mark.parametrize("method", ["mass", "variogram", "square"])
def test_float32_is_read_in_place_with_float64_results(method):
    """A float32 scene goes to the kernel without a float64 copy; every
    float32 is exactly a float64, so the map is bit-identical to the one of
    its float64 cast. A nodata value is compared as given (in float64)."""
    z = (spectral_surface(96, 0.5, 6) * 7).astype(np.float32)
    z[10:14, 20:40] = -9999.0
    z[50, 50] = np.float32(0.1)
    before = z.copy()
    for nodata in (None, -9999.0, 0.1):
        a = fg.fractal_transform(z, 11, method=method, nodata=nodata, return_fit=True)
        b = fg.fractal_transform(z.astype(np.float64), 11, method=method, nodata=nodata, return_fit=True)
        for x, y in zip(a, b):
            assert np.array_equal(x, y, equal_nan=True), nodata
    # 0.1 is not a float32: no float32 pixel equals it as given
    a = fg.fractal_transform(z, 11, method=method, nodata=0.1)
    assert np.array_equal(a, fg.fractal_transform(z, 11, method=method), equal_nan=True)
    assert np.array_equal(z, before)


def test_xarray_keeps_coords_and_attrs():
    xr = pytest.importorskip("xarray")
    z = spectral_surface(64, 0.5, 2)
    arr = xr.DataArray(z, dims=("y", "x"), coords={"y": np.arange(64) * -10.0, "x": np.arange(64) * 10.0},
                       attrs={"crs": "EPSG:32633"})
    out = fg.fractal_transform(arr, 9)
    assert out.dims == ("y", "x") and out.attrs["crs"] == "EPSG:32633"
    assert np.array_equal(out["x"].values, arr["x"].values)
    assert np.allclose(out.values, fg.fractal_transform(z, 9), equal_nan=True)


def test_plane_is_two_in_the_interior_and_rough_is_higher():
    i, j = np.indices((80, 80))
    d = fg.fractal_transform(0.2 * i + 0.5 * j, 9, method="variogram")
    assert np.allclose(d[4:-4, 4:-4], 2.0, atol=1e-5)
    rough = fg.fractal_transform(spectral_surface(128, 0.2, 1), 17, method="variogram")
    smooth = fg.fractal_transform(spectral_surface(128, 0.8, 1), 17, method="variogram")
    assert np.nanmean(rough) > np.nanmean(smooth) + 0.3


@pytest.mark.parametrize(
    "kwargs, exc, param",
    [
        (dict(window_size=8), ValueError, "window_size"),
        (dict(window_size=1), ValueError, "window_size"),
        (dict(window_size=201), ValueError, "window_size"),
        (dict(window_size=9, method="fractal"), ValueError, "method"),
        (dict(window_size=9, method="dbc", box_sizes=[2, 4]), ValueError, "box_sizes"),
        (dict(window_size=9, method="dbc", box_sizes=[2, 4, 10]), ValueError, "box_sizes"),
        (dict(window_size=9, method="dbc", box_sizes=[0, 2, 4]), ValueError, "box_sizes"),
        (dict(window_size=9, method="dbc", box_sizes=[2.5, 3, 4]), TypeError, "box_sizes"),
        (dict(window_size=9, method="dbc", z_scale=-1.0), ValueError, "z_scale"),
        (dict(window_size=9, method="blanket", epsilons=[1, 2]), ValueError, "epsilons"),
        (dict(window_size=9, method="blanket", epsilons=[0, 1, 2]), ValueError, "epsilons"),
        (dict(window_size=9, method="blanket", z_scale=float("nan")), ValueError, "z_scale"),
        (dict(window_size=9, method="dbc", step=0), ValueError, "step"),
        (dict(window_size=9, step=1.5), TypeError, "step"),
        (dict(window_size=9, method="dbc", edge_blocks="keep"), ValueError, "edge_blocks"),
        (dict(window_size=9, box_sizes=[3, 4]), ValueError, "box_sizes"),
        (dict(window_size=9, box_sizes=[3, 11]), ValueError, "box_sizes"),
        (dict(window_size=9, z_scale=0), ValueError, "z_scale"),
        (dict(window_size=9, method="variogram", lags=(1,)), ValueError, "lags"),
        (dict(window_size=9, method="variogram", lags=(1, 9)), ValueError, "lags"),
        (dict(window_size=9, min_valid=2), ValueError, "min_valid"),
        (dict(window_size=9, n_threads=0), ValueError, "n_threads"),
        (dict(window_size=9, nodata="x"), TypeError, "nodata"),
        (dict(window_size=9, nodata=True), TypeError, "nodata"),
        (dict(window_size=9, z_scale="1"), TypeError, "z_scale"),
    ],
)
def test_bad_arguments(kwargs, exc, param):
    with pytest.raises(exc, match=param):
        fg.fractal_transform(np.zeros((50, 50)), **kwargs)


def test_dbc_map_and_whole_image_dbc_refuse_one_pixel_blocks():
    # one rule: no 1-pixel blocks; windows under 5 have no default sizes
    z = fg.fbm_surface((40, 40), 0.5, seed=2)
    with pytest.raises(ValueError, match="^window_size: method 'dbc' needs a window of at least 5 pixels.*got 3$"):
        fg.fractal_transform(z, 3, method="dbc")
    with pytest.raises(ValueError, match=r"^box_sizes: DBC needs block sides of at least 2 pixels.*\[1, 2, 3\]$") as m:
        fg.fractal_transform(z, 9, method="dbc", box_sizes=[1, 2, 3])
    with pytest.raises(ValueError) as whole:
        fg.differential_box_counting(z, box_sizes=[1, 2, 3])
    assert str(m.value) == str(whole.value)
    # the smallest valid window: defaults 2, 3, 4, the map equals the per-window estimator
    d = fg.fractal_transform(z, 5, method="dbc", z_scale=0.5)
    ref = fg.differential_box_counting(z[10:15, 20:25], box_sizes=[2, 3, 4], z_scale=0.5, z0=0.0,
                                       edge_blocks="drop").dimension
    assert abs(d[12, 22] - ref) < 1e-5


def test_bad_images():
    with pytest.raises(ValueError, match="band"):
        fg.fractal_transform(np.zeros((2, 50, 50)), 9)
    with pytest.raises(TypeError, match="image"):
        fg.fractal_transform(np.zeros((50, 50), bool), 9)
    with pytest.raises(ValueError, match="image"):
        fg.fractal_transform(np.full((30, 30), np.nan), 9)
    out = fg.fractal_transform(np.zeros((2, 30, 30)) + np.indices((30, 30)).sum(0), 9, band=1)
    assert out.shape == (30, 30)


def test_segment_otsu_and_kmeans():
    rng = np.random.default_rng(0)
    a = np.where(np.arange(100)[:, None] < 40, 2.2, 2.6) + rng.normal(0, 0.02, (100, 80))
    a[0, 0] = np.nan
    lab = fg.segment(a)
    assert lab[0, 0] == -1 and lab.dtype == np.int8
    assert np.mean(lab[1:40] == 0) > 0.99 and np.mean(lab[40:] == 1) > 0.99
    b = rng.normal(size=a.shape)
    k1 = fg.segment([a, b], method="kmeans", n_classes=2, seed=3)
    k2 = fg.segment([a, b], method="kmeans", n_classes=2, seed=3)
    assert np.array_equal(k1, k2)
    # classes are ordered by the first feature: low-D region is class 0
    assert np.mean(k1[1:40] == 0) > 0.95 and np.mean(k1[40:] == 1) > 0.95
    with pytest.raises(ValueError, match="method"):
        fg.segment([a, b], method="otsu")
    with pytest.raises(ValueError, match="features"):
        fg.segment([a, b[:10]])
    with pytest.raises(ValueError, match="n_classes"):
        fg.segment(a, method="kmeans", n_classes=1)


def test_transform_cli_geotiff(tmp_path, capsys):
    rasterio = pytest.importorskip("rasterio")
    pytest.importorskip("dask")
    from rasterio.transform import from_origin

    from fractalgeo_rs.cli import main

    z = spectral_surface(128, 0.5, 9).astype(np.float32)
    src = tmp_path / "in.tif"
    with rasterio.open(src, "w", driver="GTiff", width=128, height=128, count=1, dtype="float32",
                       crs="EPSG:32633", transform=from_origin(500000, 4000000, 10, 10)) as dst:
        dst.write(z, 1)
    for extra in ([], ["--chunks", "40"]):
        out = tmp_path / f"out{len(extra)}.tif"
        assert main(["transform", str(src), str(out), "--window", "9", *extra]) == 0
        with rasterio.open(out) as r:
            assert r.crs.to_epsg() == 32633 and r.transform == from_origin(500000, 4000000, 10, 10)
            got = r.read(1)
        assert np.allclose(got, fg.fractal_transform(z, 9), atol=1e-6, equal_nan=True)
    assert "local dimension" in capsys.readouterr().out
    # --step 4: cells 40 m wide whose centres are those of the sampled pixels
    ref = fg.fractal_transform(z, 9, method="whittle", step=4)
    for extra in ([], ["--chunks", "40"]):
        out = tmp_path / f"step{len(extra)}.tif"
        assert main(["transform", str(src), str(out), "--window", "9", "--step", "4", "--method", "whittle",
                     *extra]) == 0
        with rasterio.open(out) as r:
            assert r.shape == (32, 32) and r.transform.a == 40.0 and r.transform.e == -40.0
            assert r.xy(3, 5) == (500000 + (5 * 4 + 0.5) * 10, 4000000 - (3 * 4 + 0.5) * 10)
            got = r.read(1)
        assert np.allclose(got, ref, atol=1e-6, equal_nan=True), extra


def test_dask_distributed_two_worker_processes():
    """Two worker processes (started by dask.distributed) run the Rust kernel;
    a forked child never uses its parent's kept rayon pools (tests/test_fork.py)."""
    distributed = pytest.importorskip("distributed")
    da = pytest.importorskip("dask.array")
    z = spectral_surface(128, 0.5, 5)
    ref = fg.fractal_transform(z, 9)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        out = fg.fractal_transform(da.from_array(z, chunks=(40, 64)), 9, n_threads=1)
        got = client.compute(out).result()
    assert np.allclose(got, ref, atol=1e-6, equal_nan=True)


def mass_reference(z, w, sizes, z_scale, min_valid=0.5):
    """P(m, L) map from its definition: m_p(L) counts the image's valid pixels
    in the box of side L around p (heights in z_scale units); each window
    averages 1 / m_p over its valid pixels; D = -slope of log N vs log L."""
    rows, cols = z.shape
    ok = ~np.isnan(z)
    inv = []
    for L in sizes:
        k = L // 2
        m = np.zeros(z.shape)
        for i in range(rows):
            for j in range(cols):
                if not ok[i, j]:
                    continue
                blk = z[max(0, i - k): i + k + 1, max(0, j - k): j + k + 1]
                m[i, j] = np.count_nonzero(np.abs(blk - z[i, j]) <= (k + 0.5) * z_scale)
        inv.append(np.where(ok, 1.0 / np.where(m > 0, m, 1), 0.0))
    h = w // 2
    out = np.full(z.shape, np.nan)
    x = np.log(sizes)
    for i in range(rows):
        for j in range(cols):
            sl = (slice(max(0, i - h), i + h + 1), slice(max(0, j - h), j + h + 1))
            n = np.count_nonzero(ok[sl])
            if n < min_valid * w * w:
                continue
            y = np.log([a[sl].sum() / n for a in inv])
            out[i, j] = -np.polyfit(x, y, 1)[0]
    return out


def test_mass_map_equals_definition_with_holes():
    rng = np.random.default_rng(7)
    vv, _ = fg.data.sentinel1_vv_db()
    z = vv[300:336, 50:81].astype(np.float64)
    z[rng.random(z.shape) < 0.07] = np.nan
    z[2:6, 20:27] = np.nan
    for sizes, zs in [((3, 5, 7), 1.0), ((3, 5), 2.5)]:
        d = fg.fractal_transform(z, 9, method="mass", box_sizes=sizes, z_scale=zs)
        ref = mass_reference(z, 9, sizes, zs)
        assert np.array_equal(np.isnan(d), np.isnan(ref))
        assert np.allclose(d[~np.isnan(ref)], ref[~np.isnan(ref)], atol=1e-5)


def test_mass_map_flat_is_two_and_dask_matches():
    da = pytest.importorskip("dask.array")
    d = fg.fractal_transform(np.full((60, 60), 4.0), 15, method="mass")
    assert np.allclose(d[12:-12, 12:-12], 2.0, atol=1e-5)
    vv, _ = fg.data.sentinel1_vv_db()
    z = vv[:150, :130]
    ref = fg.fractal_transform(z, 17)
    for chunks in [(50, 65), (7, 130), (150, 30)]:
        out = fg.fractal_transform(da.from_array(z, chunks=chunks), 17).compute()
        assert np.allclose(out, ref, atol=1e-6, equal_nan=True), chunks


def test_lacunarity_map_equals_per_window_lacunarity():
    rng = np.random.default_rng(11)
    z = rng.gamma(2.0, 1.0, size=(31, 27))
    z[rng.random(z.shape) < 0.05] = np.nan
    w, sizes = 9, [1, 2, 3, 5]
    lmap = fg.lacunarity_map(z, w, box_sizes=sizes, min_valid=0.3)
    zp = np.pad(z, w // 2, constant_values=np.nan)
    win = np.lib.stride_tricks.sliding_window_view(zp, (w, w))
    for i in range(z.shape[0]):
        for j in range(z.shape[1]):
            a = win[i, j]
            if np.count_nonzero(~np.isnan(a)) < 0.3 * w * w:
                assert np.isnan(lmap[:, i, j]).all()
                continue
            ref = fg.lacunarity(a, box_sizes=sizes).lacunarity
            assert np.allclose(lmap[:, i, j], ref, rtol=1e-6, equal_nan=True), (i, j)
    with pytest.raises(ValueError, match="image"):
        fg.lacunarity_map(z - 5, 9)
    with pytest.raises(ValueError, match="box_sizes"):
        fg.lacunarity_map(z, 9, box_sizes=[10])


# ---- DBC and covering-blanket maps ----------------------------------------


def windows(z, w):
    """Every w x w window of the NaN-padded image (skimage's view_as_windows;
    numpy's sliding_window_view, the same view, where skimage is missing:
    it is not a test dependency)."""
    try:
        from skimage.util import view_as_windows
    except ImportError:
        from numpy.lib.stride_tricks import sliding_window_view as view_as_windows

    zp = np.pad(np.asarray(z, dtype=float), w // 2, constant_values=np.nan)
    return view_as_windows(zp, (w, w))


def per_window_estimator(z, w, estimator, min_valid=0.5, step=1, **kw):
    win = windows(z, w)
    out = np.full(z.shape, np.nan)[::step, ::step]
    for a, i in enumerate(range(0, z.shape[0], step)):
        for b, j in enumerate(range(0, z.shape[1], step)):
            x = win[i, j]
            if np.count_nonzero(~np.isnan(x)) >= min_valid * w * w:
                out[a, b] = estimator(x, **kw).dimension
    return out


def numpy_dbc_counts(z, sizes, z0, z_unit, drop=False):
    """DBC counts from the definition: s x s blocks from the top-left
    corner, partial blocks at the right and bottom (or none: drop), NaN
    skipped."""
    out = []
    for s in sizes:
        h = s * z_unit
        n = 0.0
        for r in range(0, z.shape[0], s):
            for c in range(0, z.shape[1], s):
                blk = z[r:r + s, c:c + s]
                if drop and blk.shape != (s, s):
                    continue
                blk = blk[~np.isnan(blk)]
                if blk.size:
                    n += np.floor((blk.max() - z0) / h) - np.floor((blk.min() - z0) / h) + 1
        out.append(n)
    return out


def numpy_blanket_areas_nan(z, eps_max, z_scale=1.0):
    """Peleg blanket from the definition with missing samples: NaN pixels
    hold no blanket (-inf / +inf) and the plane is framed by missing pixels."""
    ok = ~np.isnan(z)
    u = np.pad(np.where(ok, z / z_scale, -np.inf), 1, constant_values=-np.inf)
    b = np.pad(np.where(ok, z / z_scale, np.inf), 1, constant_values=np.inf)
    okp = np.pad(ok, 1)
    out = []
    for e in range(1, eps_max + 1):
        nu = np.max([u + 1, np.roll(u, 1, 0), np.roll(u, -1, 0), np.roll(u, 1, 1), np.roll(u, -1, 1)], axis=0)
        nb = np.min([b - 1, np.roll(b, 1, 0), np.roll(b, -1, 0), np.roll(b, 1, 1), np.roll(b, -1, 1)], axis=0)
        u = np.where(okp, nu, -np.inf)
        b = np.where(okp, nb, np.inf)
        out.append(float(np.sum((u - b)[okp])) / (2 * e))
    return out


def holed(shape, seed, scale=10.0):
    rng = np.random.default_rng(seed)
    z = spectral_surface(64, 0.5, seed)[: shape[0], : shape[1]] * scale
    z[rng.random(z.shape) < 0.08] = np.nan
    z[5:12, 3:9] = np.nan
    return z


def test_dbc_estimator_z0_equals_numpy_counts():
    z = holed((40, 29), 3)
    for z0, zs in [(0.0, 0.5), (-3.0, 1.7)]:
        fit = fg.differential_box_counting(z, box_sizes=[2, 3, 5, 8], z_scale=zs, z0=z0)
        assert fit.measures.tolist() == numpy_dbc_counts(z, [2, 3, 5, 8], z0, zs)
        fit = fg.differential_box_counting(z, box_sizes=[2, 3, 5, 8], z_scale=zs, z0=z0, edge_blocks="drop")
        assert fit.measures.tolist() == numpy_dbc_counts(z, [2, 3, 5, 8], z0, zs, drop=True)
    with pytest.raises(ValueError, match="edge_blocks"):
        fg.differential_box_counting(z, box_sizes=[2, 3, 5], edge_blocks="drop", offsets=2)
    with pytest.raises(ValueError, match="z0"):
        fg.differential_box_counting(z, z0=float("nan"))


@pytest.mark.parametrize("w, sizes, zs, edge", [(7, [2, 3, 4], 0.5, "count"), (9, [2, 4, 9], 2.0, "drop"),
                                                 (11, [2, 3, 5], 1.0, "drop"), (11, [2, 3, 5], 1.0, "count")])
def test_dbc_map_equals_per_window_estimator_with_holes(w, sizes, zs, edge):
    z = holed((40, 29), 1)
    d, r2 = fg.fractal_transform(z, w, method="dbc", box_sizes=sizes, z_scale=zs, edge_blocks=edge, return_fit=True)
    kw = dict(box_sizes=sizes, z_scale=zs, z0=0.0, edge_blocks=edge)
    ref = per_window_estimator(z, w, fg.differential_box_counting, **kw)
    assert np.array_equal(np.isnan(d), np.isnan(ref))
    assert np.allclose(d, ref, atol=1e-5, equal_nan=True)
    ref_r2 = per_window_estimator(
        z, w, lambda x, **k: type("F", (), {"dimension": fg.differential_box_counting(x, **k).r_squared})(), **kw)
    assert np.allclose(r2, ref_r2, atol=1e-5, equal_nan=True)
    # the counts themselves: one window against the numpy definition
    win = windows(z, w)[20, 14]
    fit = fg.differential_box_counting(win, **kw)
    assert fit.measures.tolist() == numpy_dbc_counts(win, sizes, 0.0, zs, drop=edge == "drop")


def test_dbc_map_random_image_step_and_nodata():
    rng = np.random.default_rng(7)
    z = rng.integers(0, 40, size=(37, 45)).astype(np.float32)
    z[10:14, 20:30] = -9999
    d = fg.fractal_transform(z, 13, method="dbc", nodata=-9999, step=3, z_scale=1.0)
    zn = np.where(z == -9999, np.nan, z.astype(float))
    ref = per_window_estimator(zn, 13, fg.differential_box_counting, step=3, box_sizes=[2, 3, 4], z_scale=1.0, z0=0.0,
                               edge_blocks="drop")
    assert d.shape == (13, 15)
    assert np.allclose(d, ref, atol=1e-5, equal_nan=True) and np.isfinite(d).sum() > 100


def test_dbc_map_real_sar_window():
    vv, _ = fg.data.sentinel1_vv_db()
    z = vv[100:160, 200:250]
    # z_scale=1 pinned (the default is "auto" since the real-data defaults)
    d = fg.fractal_transform(z, 17, method="dbc", z_scale=1.0)  # sizes 2, 4, 8; 1 dB per pixel
    ref = per_window_estimator(z, 17, fg.differential_box_counting, box_sizes=[2, 4, 8], z_scale=1.0, z0=0.0,
                               edge_blocks="drop")
    assert np.allclose(d, ref, atol=1e-5, equal_nan=True)
    assert np.isfinite(d[8:-8, 8:-8]).all()


@pytest.mark.parametrize("w, eps, zs", [(7, [1, 2, 3], 1.0), (9, [1, 2, 4], 0.3)])
def test_blanket_map_equals_per_window_estimator_with_holes(w, eps, zs):
    z = holed((30, 23), 2, scale=4.0)
    d, r2 = fg.fractal_transform(z, w, method="blanket", epsilons=eps, z_scale=zs, return_fit=True)
    ref = per_window_estimator(z, w, fg.blanket, epsilons=eps, z_scale=zs)
    assert np.array_equal(np.isnan(d), np.isnan(ref))
    assert np.allclose(d, ref, atol=1e-5, equal_nan=True)
    # the areas of one edge window and one holed window: numpy definition
    for i, j in [(0, 3), (8, 6), (15, 11)]:
        win = windows(z, w)[i, j]
        if np.count_nonzero(~np.isnan(win)) < 9:  # under 3 x 3 valid samples: all edge, refused
            with pytest.raises(ValueError, match="3 x 3"):
                fg.blanket(win, epsilons=range(1, max(eps) + 1), z_scale=zs)
            continue
        fit = fg.blanket(win, epsilons=range(1, max(eps) + 1), z_scale=zs)
        assert fit.measures.tolist() == pytest.approx(numpy_blanket_areas_nan(win, max(eps), zs), rel=1e-12)


def test_blanket_map_real_sar_window_and_step():
    vv, _ = fg.data.sentinel1_vv_db()
    z = vv[100:150, 200:240]
    d = fg.fractal_transform(z, 11, method="blanket", step=2, z_scale=1.0)  # default is "auto"
    ref = per_window_estimator(z, 11, fg.blanket, step=2, epsilons=[1, 2, 3, 4], z_scale=1.0)
    assert d.shape == (25, 20)
    assert np.allclose(d, ref, atol=1e-5, equal_nan=True)


def test_blanket_estimator_equals_numpy_with_holes():
    rng = np.random.default_rng(5)
    for shape in [(300, 41), (33, 290)]:  # several of the kernel's 128-row bands
        z = np.round(rng.normal(0, 3, size=shape).cumsum(axis=1))
        z[rng.random(shape) < 0.05] = np.nan
        z[20:30, 10:25] = np.nan
        for zs in (1.0, 2.5):
            fit = fg.blanket(z, epsilons=range(1, 11), z_scale=zs)
            assert fit.measures.tolist() == pytest.approx(numpy_blanket_areas_nan(z, 10, zs), rel=1e-12)
            assert fit.extra["n_valid"] == np.count_nonzero(~np.isnan(z))
        assert fg.blanket(z, n_threads=1).measures.tolist() == fg.blanket(z, n_threads=3).measures.tolist()


@pytest.mark.parametrize("method", ["dbc", "blanket"])
def test_new_methods_threads_dask_xarray(method):
    z = spectral_surface(128, 0.6, 4)[:100, :90] * 20
    z[40:44, 10:70] = np.nan
    z32 = z.astype(np.float32)
    before = z32.copy()
    ref = fg.fractal_transform(z32, 11, method=method, n_threads=1, return_fit=True)
    for t in (2, 3):
        out = fg.fractal_transform(z32, 11, method=method, n_threads=t, return_fit=True)
        assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(out, ref))
    assert np.array_equal(z32, before, equal_nan=True)
    assert ref[0].dtype == np.float32 and ref[0].shape == z.shape
    da = pytest.importorskip("dask.array")
    for chunks in [(50, 45), (33, 90), (100, 20), (4, 4)]:
        for step in (1, 3):
            out = fg.fractal_transform(da.from_array(z32, chunks=chunks), 11, method=method, step=step,
                                       return_fit=True)
            for a, b in zip(out, ref):
                a = a.compute()
                assert a.shape == b[::step, ::step].shape
                assert np.allclose(a, b[::step, ::step], atol=1e-6, equal_nan=True), (chunks, step)
    xr = pytest.importorskip("xarray")
    arr = xr.DataArray(z32, dims=("y", "x"), coords={"y": np.arange(100) * -10.0, "x": np.arange(90) * 10.0},
                       attrs={"crs": "EPSG:32633"})
    out = fg.fractal_transform(arr, 11, method=method, step=2)
    assert out.attrs["crs"] == "EPSG:32633" and np.array_equal(out["x"].values, arr["x"].values[::2])
    assert np.allclose(out.values, ref[0][::2, ::2], equal_nan=True)


def test_new_methods_plane_and_roughness():
    i, j = np.indices((80, 80))
    plane = 0.5 * i + 0.25 * j
    # z_scale=1 pinned: the default "auto" unit is the images' own step
    assert np.allclose(fg.fractal_transform(plane, 9, method="blanket", z_scale=1.0)[4:-4, 4:-4], 2.0, atol=1e-5)
    rough = fg.fractal_transform(spectral_surface(128, 0.2, 1) * 30, 17, method="dbc", z_scale=1.0)
    smooth = fg.fractal_transform(spectral_surface(128, 0.8, 1) * 30, 17, method="dbc", z_scale=1.0)
    assert np.nanmean(rough) > np.nanmean(smooth) + 0.1


def test_lacunarity_map_on_dask_and_xarray_equals_in_memory():
    """The backend dispatcher gives lacunarity_map the Dask and xarray paths
    of the dimension maps: same values for any chunking (NaN halo = the
    in-memory edge policy), coords and attrs kept."""
    da = pytest.importorskip("dask.array")
    xr = pytest.importorskip("xarray")
    rng = np.random.default_rng(3)
    img = rng.gamma(2.0, size=(70, 53))
    img[10:14, 20:30] = np.nan
    ref = fg.lacunarity_map(img, 9, box_sizes=[1, 2, 4])
    for chunks in [(70, 53), (20, 17), (5, 40)]:
        got = fg.lacunarity_map(da.from_array(img, chunks=chunks), 9, box_sizes=[1, 2, 4]).compute()
        np.testing.assert_allclose(got, ref, rtol=1e-5, atol=1e-6, equal_nan=True)
    x = xr.DataArray(img, dims=("y", "x"), coords={"y": np.arange(70) * -10.0, "x": np.arange(53) * 10.0},
                     attrs={"units": "linear"})
    out = fg.lacunarity_map(x, 9, box_sizes=[1, 2, 4])
    assert out.dims == ("box_size", "y", "x")
    assert list(out.box_size.values) == [1, 2, 4]
    np.testing.assert_array_equal(out.x.values, x.x.values)
    assert out.attrs["units"] == "linear"
    np.testing.assert_allclose(out.values, ref, equal_nan=True)


def test_transform_xarray_outputs_named_and_keep_attrs():
    xr = pytest.importorskip("xarray")
    z = spectral_surface(64, 0.5, seed=2)
    x = xr.DataArray(z, dims=("y", "x"), coords={"y": np.arange(64.0), "x": np.arange(64.0)},
                     attrs={"crs": "EPSG:32611"})
    d, r2 = fg.fractal_transform(x, 9, method="variogram", step=2, return_fit=True)
    assert d.name == "fractal_dimension" and r2.name == "r_squared"
    assert d.attrs["crs"] == "EPSG:32611"
    np.testing.assert_array_equal(d.y.values, np.arange(0.0, 64.0, 2.0))
    np.testing.assert_allclose(d.values, fg.fractal_transform(z, 9, method="variogram", step=2))


def test_dask_halo_larger_than_an_image_side():
    """A window wider than one side of the image (allowed: it is at most the
    longer side) has a halo the Dask overlap cannot give; the dispatcher
    pads that axis with NaN and still equals the in-memory map."""
    da = pytest.importorskip("dask.array")
    img = np.random.default_rng(0).random((10, 100))
    for method, step in [("variogram", 1), ("mass", 3)]:
        ref = fg.fractal_transform(img, 51, method=method, step=step)
        got = fg.fractal_transform(da.from_array(img, chunks=(5, 30)), 51, method=method, step=step).compute()
        np.testing.assert_allclose(got, ref, atol=1e-6, equal_nan=True)
    np.testing.assert_allclose(fg.lacunarity_map(da.from_array(img, chunks=(5, 30)), 51).compute(),
                               fg.lacunarity_map(img, 51), atol=1e-6, equal_nan=True)
