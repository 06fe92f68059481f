"""Greedy error-bounded TINs: the error bound checked by an independent
barycentric rasterisation, vertex counts against pydelatin, crack-free
tiles, holes at nodata, mesh files, bad input."""
import os

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.tin import TIN, tin_from_dem

DATA = os.path.join(os.path.dirname(__file__), "data", "bigtujunga_30m_crop128.npy")


@pytest.fixture(scope="module")
def crop():
    return np.load(DATA).astype(np.float64)


@pytest.fixture(scope="module")
def rough():
    s = np.asarray(fg.fbm_surface((128, 128), hurst=0.3, seed=3), dtype=np.float64)
    return (s - s.min()) / (s.max() - s.min()) * 100.0


def rasterize(tin: TIN):
    """Barycentric rasterisation in numpy at the sample centres (pixel
    coordinates from the inverse transform), independent of the kernel."""
    rows, cols = tin.shape
    a, b, c, d, e, f = tin.transform
    inv = np.linalg.inv(np.array([[a, b], [d, e]]))
    px = (tin.vertices[:, :2] - [c, f]) @ inv.T - 0.5  # (col, row)
    out = np.full(tin.shape, np.nan)
    for tr in tin.triangles:
        (x0, y0), (x1, y1), (x2, y2) = px[tr]
        z0, z1, z2 = tin.vertices[tr, 2]
        cs = np.arange(max(int(np.ceil(min(x0, x1, x2) - 1e-9)), 0), min(int(max(x0, x1, x2) + 1e-9), cols - 1) + 1)
        rs = np.arange(max(int(np.ceil(min(y0, y1, y2) - 1e-9)), 0), min(int(max(y0, y1, y2) + 1e-9), rows - 1) + 1)
        X, Y = np.meshgrid(cs, rs)
        det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        l1 = ((X - x0) * (y2 - y0) - (x2 - x0) * (Y - y0)) / det
        l2 = ((x1 - x0) * (Y - y0) - (X - x0) * (y1 - y0)) / det
        l0 = 1 - l1 - l2
        m = (l0 > -1e-9) & (l1 > -1e-9) & (l2 > -1e-9)
        out[Y[m], X[m]] = l0[m] * z0 + l1[m] * z1 + l2[m] * z2
    return out


def signed_area2(v, t):
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


@pytest.mark.parametrize("max_error", [3.0, 20.0])
@pytest.mark.parametrize("tile_edges", ["shared", "free"])
def test_error_bound_on_real_dem(crop, max_error, tile_edges):
    t = tin_from_dem(crop, max_error=max_error, cell_size=30.0, tile_edges=tile_edges)
    assert t.vertices.dtype == np.float64 and t.triangles.dtype == np.int64
    assert np.all(signed_area2(t.vertices, t.triangles) > 0)  # counter-clockwise from +z
    g = rasterize(t)
    assert not np.isnan(g).any()  # the whole raster is covered
    err = np.abs(g - crop).max()
    assert err <= max_error + 1e-9
    assert t.max_error == pytest.approx(err, abs=1e-9)
    np.testing.assert_allclose(t.to_grid(), g, atol=1e-9)
    # vertices are samples: their heights are the DEM's
    col = (t.vertices[:, 0] / 30.0 - 0.5).round().astype(int)
    row = (128 - t.vertices[:, 1] / 30.0 - 0.5).round().astype(int)
    np.testing.assert_array_equal(t.vertices[:, 2], crop[row, col])
    np.testing.assert_array_equal(t.grid, np.column_stack([col, row]))


def test_vertex_count_against_pydelatin(crop, rough):
    Delatin = pytest.importorskip("pydelatin").Delatin
    for dem, err in [(crop, 2.0), (crop, 10.0), (rough, 1.0), (rough, 5.0)]:
        ref = Delatin(dem.astype(np.float32), width=dem.shape[1], height=dem.shape[0], max_error=err)
        for edges in ("free", "shared"):
            t = tin_from_dem(dem, max_error=err, tile_edges=edges)
            assert len(t.vertices) <= 1.05 * len(ref.vertices), (err, edges, len(t.vertices), len(ref.vertices))


def test_plane_and_zero_error():
    yy, xx = np.mgrid[0:40, 0:30]
    t = tin_from_dem(3.0 * xx - 2.0 * yy, max_error=0.0)
    assert len(t.vertices) == 4 and len(t.triangles) == 2 and t.max_error < 1e-12
    rng = np.random.default_rng(0)
    z = rng.normal(size=(20, 25))
    t0 = tin_from_dem(z, max_error=0.0)
    assert len(t0.vertices) == z.size  # random heights: every sample is needed
    np.testing.assert_allclose(t0.to_grid(), z, atol=1e-12)


def test_transform_orientation_and_map_coordinates(crop):
    from affine import Affine

    tr = Affine(30.0, 0.0, 350000.0, 0.0, -30.0, 3800000.0)
    t = tin_from_dem(crop, max_error=5.0, transform=tr)
    assert np.all(signed_area2(t.vertices, t.triangles) > 0)
    x0, y0 = t.vertices[:, 0].min(), t.vertices[:, 1].max()
    assert (x0, y0) == (350015.0, 3799985.0)  # the centre of the upper-left sample
    gdal = (350000.0, 30.0, 0.0, 3800000.0, 0.0, -30.0)
    t2 = tin_from_dem(crop, max_error=5.0, transform=gdal)
    np.testing.assert_array_equal(t.vertices, t2.vertices)
    np.testing.assert_array_equal(t.triangles, t2.triangles)
    # a south-up grid flips the triangles back to counter-clockwise
    t3 = tin_from_dem(crop, max_error=5.0, transform=Affine(30.0, 0.0, 0.0, 0.0, 30.0, 0.0))
    assert np.all(signed_area2(t3.vertices, t3.triangles) > 0)
    assert np.abs(rasterize(t3) - crop).max() <= 5.0 + 1e-9


@pytest.mark.parametrize(
    "geo",
    [
        {},
        {"cell_size": 30.0},
        {"transform": (350000.0, 30.0, 0.0, 3800000.0, 0.0, -30.0)},  # GDAL, north up
        {"transform": (0.0, 10.0, 0.0, 0.0, 0.0, 10.0)},  # south up
        {"transform": (100.0, 3.0, 1.0, 50.0, 0.5, -2.0)},  # sheared
    ],
)
def test_round_trip_through_grid_from_points(crop, geo):
    # tin_from_dem and grid_from_points share one convention (cell centres of the
    # transform): gridding the TIN's vertices on the same geometry puts every vertex
    # back on its own DEM cell with its height
    from fractalgeo_rs.tin import grid_from_points

    t = tin_from_dem(crop, max_error=5.0, **geo)
    col, row = t.grid[:, 0], t.grid[:, 1]
    for method in ("linear", "natural", "natural_c1", "nearest"):
        g = grid_from_points(t.vertices[:, :2], t.vertices[:, 2], crop.shape, method=method, **geo)
        np.testing.assert_allclose(g[row, col], crop[row, col], rtol=0, atol=1e-9)


def test_adjacent_tiles_share_edge_vertices(crop, rough):
    for dem, err in [(crop, 3.0), (rough, 8.0)]:
        left, right = dem[:, :65], dem[:, 64:]  # common column 64
        tl = tin_from_dem(left, max_error=err, cell_size=1.0)
        tr = tin_from_dem(right, max_error=err, transform=(64.0, 1.0, 0.0, 128.0, 0.0, -1.0))
        x = 64.5
        el = tl.vertices[np.isclose(tl.vertices[:, 0], x)]
        er = tr.vertices[np.isclose(tr.vertices[:, 0], x)]
        el, er = el[np.argsort(el[:, 1])], er[np.argsort(er[:, 1])]
        assert len(el) >= 2
        np.testing.assert_array_equal(el, er)
        # consecutive edge vertices are joined by a triangle edge in both tiles: no T-junctions
        for t, ev in [(tl, el), (tr, er)]:
            idx = {tuple(v): i for i, v in enumerate(map(tuple, t.vertices))}
            e = np.sort(np.vstack([t.triangles[:, [0, 1]], t.triangles[:, [1, 2]], t.triangles[:, [2, 0]]]), 1)
            edges = set(map(tuple, e))
            for p, q in zip(ev[:-1], ev[1:]):
                assert tuple(sorted((idx[tuple(p)], idx[tuple(q)]))) in edges
        # the whole mosaic is within the bound
        for t, part in [(tl, left), (tr, right)]:
            assert np.abs(rasterize(t) - part).max() <= err + 1e-9


def test_nodata_becomes_holes(crop):
    z = crop.copy()
    z[40:70, 50:90] = -9999.0
    z[0:10, 0:20] = -9999.0  # touching the outer edge and a corner
    before = z.copy()
    t = tin_from_dem(z, max_error=3.0, nodata=-9999.0)
    np.testing.assert_array_equal(z, before)
    g = rasterize(t)
    hole = z == -9999.0
    assert np.isnan(g[hole]).all()  # no triangle covers a nodata sample
    valid = ~hole & ~np.isnan(g)
    assert valid.sum() >= 0.99 * (~hole).sum()
    assert np.abs(g[valid] - z[valid]).max() <= 3.0 + 1e-9
    zn = crop.copy()
    zn[hole] = np.nan
    tn = tin_from_dem(zn, max_error=3.0)
    np.testing.assert_array_equal(tn.vertices, t.vertices)


def test_triangle_budget(rough):
    full = tin_from_dem(rough, max_error=0.5)
    t = tin_from_dem(rough, max_error=0.5, max_triangles=2000)
    assert len(t.triangles) <= 2002 < len(full.triangles)
    assert t.max_error > 0.5
    assert np.abs(rasterize(t) - rough).max() == pytest.approx(t.max_error, abs=1e-9)


def test_identical_for_any_n_threads(rough):
    ref = tin_from_dem(rough, max_error=1.0, n_threads=1)
    for n in (2, 4):
        t = tin_from_dem(rough, max_error=1.0, n_threads=n)
        np.testing.assert_array_equal(t.vertices, ref.vertices)
        np.testing.assert_array_equal(t.triangles, ref.triangles)


@pytest.fixture(scope="module")
def big():
    """700 x 900 fBm, relief 100: several tiles of the kernel's tiling."""
    s = np.asarray(fg.fbm_surface((700, 900), hurst=0.8, seed=5), dtype=np.float64)
    return (s - s.min()) / (s.max() - s.min()) * 100.0


def edge_counts(t: TIN):
    """Undirected edges (sorted vertex pairs), how many triangles use each, and
    whether any directed edge is used twice (overlapping or folded triangles)."""
    d = np.vstack([t.triangles[:, [0, 1]], t.triangles[:, [1, 2]], t.triangles[:, [2, 0]]])
    folded = len(np.unique(d, axis=0)) < len(d)
    e, n = np.unique(np.sort(d, axis=1), axis=0, return_counts=True)
    return e, n, folded


def t_junctions(t: TIN):
    """Axis-parallel triangle edges with a mesh vertex strictly inside them."""
    verts = set(map(tuple, t.grid.tolist()))
    e, _, _ = edge_counts(t)
    p, q = t.grid[e[:, 0]], t.grid[e[:, 1]]
    bad = []
    for (c0, r0), (c1, r1) in zip(p[(p[:, 0] == q[:, 0]) | (p[:, 1] == q[:, 1])].tolist(),
                                  q[(p[:, 0] == q[:, 0]) | (p[:, 1] == q[:, 1])].tolist()):
        if c0 == c1:
            inside = [(c0, r) for r in range(min(r0, r1) + 1, max(r0, r1))]
        else:
            inside = [(c, r0) for c in range(min(c0, c1) + 1, max(c0, c1))]
        if any(v in verts for v in inside):
            bad.append((c0, r0, c1, r1))
    return bad


@pytest.mark.parametrize("tile_edges", ["shared", "free"])
def test_tiled_dem_bound_watertight_and_thread_independent(big, tile_edges):
    err = 1.0
    t = tin_from_dem(big, max_error=err, tile_edges=tile_edges, n_threads=1)
    t2 = tin_from_dem(big, max_error=err, tile_edges=tile_edges, n_threads=2)
    np.testing.assert_array_equal(t.vertices, t2.vertices)
    np.testing.assert_array_equal(t.triangles, t2.triangles)
    assert t.max_error == t2.max_error
    assert np.all(signed_area2(t.vertices, t.triangles) > 0)
    assert len(np.unique(t.grid, axis=0)) == len(t.grid)  # seam vertices merged
    g = rasterize(t)
    assert not np.isnan(g).any()
    measured = np.abs(g - big).max()
    assert measured <= err + 1e-9
    assert t.max_error == pytest.approx(measured, abs=1e-9)
    # watertight: every edge in two triangles except on the raster's outer boundary
    e, n, folded = edge_counts(t)
    assert not folded and n.max() == 2
    p, q = t.grid[e[n == 1, 0]], t.grid[e[n == 1, 1]]
    rows, cols = big.shape
    outer = (((p[:, 0] == q[:, 0]) & np.isin(p[:, 0], [0, cols - 1]))
             | ((p[:, 1] == q[:, 1]) & np.isin(p[:, 1], [0, rows - 1])))
    assert outer.all()
    # and the outer boundary is the raster's: its length is the perimeter
    length = np.abs(p - q).sum()
    assert length == 2 * (rows - 1) + 2 * (cols - 1)


def test_tiled_dem_holes_across_seams(big):
    z = big.copy()
    z[200:400, 400:500] = np.nan  # across the row and column seams
    z[:260, :230] = np.nan  # a corner region covering a whole tile or more
    z[450:452, :] = np.nan  # a nodata strip across the whole raster
    t = tin_from_dem(z, max_error=1.0)
    t2 = tin_from_dem(z, max_error=1.0, n_threads=2)
    np.testing.assert_array_equal(t.triangles, t2.triangles)
    np.testing.assert_array_equal(t.vertices, t2.vertices)
    g = rasterize(t)
    hole = np.isnan(z)
    assert np.isnan(g[hole]).all()
    valid = ~hole & ~np.isnan(g)
    assert valid.sum() >= 0.99 * (~hole).sum()
    assert np.abs(g[valid] - z[valid]).max() <= 1.0 + 1e-9
    _, n, folded = edge_counts(t)
    assert not folded and n.max() == 2
    assert t_junctions(t) == []


@pytest.mark.slow
def test_tiled_vertex_count_against_pydelatin():
    Delatin = pytest.importorskip("pydelatin").Delatin
    s = np.asarray(fg.fbm_surface((1024, 1024), hurst=0.5, seed=1, cell_size=10.0), dtype=np.float64)
    z = (s - s.min()) / (s.max() - s.min()) * 1000.0
    for err in (10.0, 30.0):
        ref = Delatin(z.astype(np.float32), width=1024, height=1024, max_error=err)
        for edges in ("free", "shared"):
            t = tin_from_dem(z, max_error=err, tile_edges=edges)
            assert len(t.vertices) <= 1.05 * len(ref.vertices), (err, edges, len(t.vertices), len(ref.vertices))
            assert t.max_error <= err + 1e-9


def test_default_max_error(crop):
    t = tin_from_dem(crop)
    lo, hi = np.percentile(crop, [2, 98])
    assert t.max_error <= 0.005 * (hi - lo)
    assert len(t.vertices) < crop.size / 2


def test_mesh_files_and_preview(crop, tmp_path):
    t = tin_from_dem(crop, max_error=10.0, cell_size=30.0)
    n = t.normals()
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-12)
    assert np.all(n[:, 2] > 0)
    m = t.to_mesh()
    assert m.uvs.min() >= 0.0 and m.uvs.max() <= 1.0
    np.testing.assert_allclose(m.vertices[:, :2] + t.vertices[:, :2].min(0), t.vertices[:, :2], atol=1e-2)
    t.write_obj(tmp_path / "a.obj")
    lines = (tmp_path / "a.obj").read_text().splitlines()
    assert sum(ln.startswith("v ") for ln in lines) == len(t.vertices)
    assert sum(ln.startswith("f ") for ln in lines) == len(t.triangles)
    t.write_ply(tmp_path / "a.ply")
    head = (tmp_path / "a.ply").read_bytes()[:400].decode("latin1")
    assert f"element vertex {len(t.vertices)}" in head and f"element face {len(t.triangles)}" in head
    t.write_png(tmp_path / "a.png")
    img, _ = fg.read_raster(tmp_path / "a.png")
    assert img.shape == crop.shape and img.dtype == np.uint8


def test_cli(crop, tmp_path, capsys):
    from fractalgeo_rs.cli import main

    np.save(tmp_path / "dem.npy", crop)
    rc = main(["tin", str(tmp_path / "dem.npy"), str(tmp_path / "out.ply"), "--max-error", "5",
               "--preview", str(tmp_path / "p.png")])
    assert rc == 0
    out = capsys.readouterr().out
    t = tin_from_dem(crop, max_error=5.0)
    assert out.startswith(f"{len(t.vertices)} vertices, {len(t.triangles)} triangles, max error")
    assert (tmp_path / "out.ply").exists() and (tmp_path / "p.png").exists()
    assert main(["tin", str(tmp_path / "dem.npy"), str(tmp_path / "out.stl")]) == 1


@pytest.mark.parametrize(
    "dem, kwargs, exc, start",
    [
        (np.zeros(10), {}, ValueError, "dem"),
        ("x", {}, TypeError, "dem"),
        (np.zeros((4, 4), dtype=bool), {}, TypeError, "dem"),
        (np.zeros((4, 4)), {"max_error": -1.0}, ValueError, "max_error"),
        (np.zeros((4, 4)), {"max_error": np.nan}, ValueError, "max_error"),
        (np.zeros((4, 4)), {"max_error": "1"}, TypeError, "max_error"),
        (np.zeros((4, 4)), {"max_triangles": 0}, ValueError, "max_triangles"),
        (np.zeros((4, 4)), {"tile_edges": "x"}, ValueError, "tile_edges"),
        (np.zeros((4, 4)), {"cell_size": -1.0}, ValueError, "cell_size"),
        (np.zeros((4, 4)), {"cell_size": 1.0, "transform": (0, 1, 0, 0, 0, -1)}, ValueError, "cell_size"),
        (np.zeros((4, 4)), {"transform": (0, 1, 0)}, ValueError, "transform"),
        (np.zeros((4, 4)), {"transform": (0, 0, 0, 0, 0, 0)}, ValueError, "transform"),
        (np.full((4, 4), np.nan), {}, ValueError, "dem"),
        (np.zeros((1, 5)), {}, ValueError, "dem"),
        (np.zeros((4, 4)), {"nodata": "a"}, TypeError, "nodata"),
    ],
)
def test_bad_input(dem, kwargs, exc, start):
    with pytest.raises(exc) as info:
        tin_from_dem(dem, **kwargs)
    assert str(info.value).startswith(start)
