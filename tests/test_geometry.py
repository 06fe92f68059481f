"""The one geometry layer: ``fractalgeo_rs.geometry.Mesh`` and ``GeoGrid``.

Vertices of a georeferenced TIN are checked against the DataArray's own
coordinates; mesh files are read back by independent parsers (numpy for
PLY, text for OBJ) and by trimesh; the TIN mesh built in Rust is compared
bit for bit with the numpy construction it replaces; watertightness of
tiled TINs is checked by counting edges."""
import os

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.geometry import GeoGrid, Mesh
from fractalgeo_rs.lsystem import plant_mesh
from fractalgeo_rs.tin import tin_from_dem

DATA = os.path.join(os.path.dirname(__file__), "data", "bigtujunga_30m_crop128.npy")


@pytest.fixture(scope="module")
def crop():
    return np.load(DATA).astype(np.float64)


def _xr_dem(z, x0=500000.0, y0=4000000.0, h=30.0, crs=None):
    xr = pytest.importorskip("xarray")
    rows, cols = z.shape
    x = x0 + h * (np.arange(cols) + 0.5)
    y = y0 - h * (np.arange(rows) + 0.5)
    attrs = {"crs": crs} if crs else {}
    return xr.DataArray(z, dims=("y", "x"), coords={"y": y, "x": x}, attrs=attrs), x, y


# ---------------------------------------------------------------- GeoGrid

def test_geogrid_affine_centres_and_transform_round_trip():
    g = GeoGrid((500000.0, 4000000.0), (30.0, 25.0), crs="EPSG:32633")
    assert g.affine == (30.0, 0.0, 500000.0, 0.0, -25.0, 4000000.0)
    assert g.center(2, 3) == (500000.0 + 3.5 * 30.0, 4000000.0 - 2.5 * 25.0)
    assert g.gdal == (500000.0, 30.0, 0.0, 4000000.0, 0.0, -25.0)
    assert GeoGrid.from_transform(g.gdal, crs="EPSG:32633") == g
    assert GeoGrid.from_affine(g.affine, crs="EPSG:32633") == g
    affine = pytest.importorskip("affine")
    assert GeoGrid.from_transform(affine.Affine(*g.affine)) == GeoGrid((500000.0, 4000000.0), (30.0, 25.0))
    r = GeoGrid((10.0, 20.0), (2.0, 3.0), rotation=30.0)
    back = GeoGrid.from_transform(r.gdal)
    assert back.cell_size == pytest.approx((2.0, 3.0), abs=1e-12)
    assert back.rotation == pytest.approx(30.0, abs=1e-9)
    y, x = g.coords((3, 2))
    np.testing.assert_array_equal(x, [500015.0, 500045.0])
    np.testing.assert_array_equal(y, [4000000.0 - 12.5, 4000000.0 - 37.5, 4000000.0 - 62.5])


@pytest.mark.parametrize("size", [0.0, -30.0, (30.0, 0.0), (30.0, -1.0), np.nan, np.inf])
def test_geogrid_bad_cell_size_names_the_parameter(size):
    with pytest.raises(ValueError, match="^cell_size:"):
        GeoGrid((0.0, 0.0), size)


def test_geogrid_bad_origin_rotation_and_transform():
    with pytest.raises(ValueError, match="^origin:"):
        GeoGrid((np.nan, 0.0), 1.0)
    with pytest.raises(ValueError, match="^rotation:"):
        GeoGrid((0.0, 0.0), 1.0, rotation=np.inf)
    with pytest.raises(TypeError, match="^origin:"):
        GeoGrid(5.0, 1.0)
    with pytest.raises(ValueError, match="^transform:.*row 0 north"):
        GeoGrid.from_transform((0.0, 1.0, 0.0, 0.0, 0.0, 1.0))  # GDAL order, south up
    with pytest.raises(ValueError, match="^transform:"):
        GeoGrid.from_transform((0.0, 1.0, 0.5, 0.0, 0.0, -1.0))  # sheared


def test_geogrid_geographic_and_mismatched_crs():
    assert GeoGrid((7.0, 45.0), 1 / 3600, crs="EPSG:4326").is_geographic
    assert not GeoGrid((0.0, 0.0), 30.0, crs="EPSG:32632").is_geographic
    assert not GeoGrid((0.0, 0.0), 30.0).is_geographic
    a = GeoGrid((0.0, 0.0), 30.0, crs="EPSG:32632")
    with pytest.raises(ValueError, match="^other:.*EPSG:32633"):
        a.check_same_crs(GeoGrid((0.0, 0.0), 30.0, crs="EPSG:32633"), "other")
    a.check_same_crs(GeoGrid((0.0, 0.0), 30.0))  # a missing CRS matches any
    with pytest.raises(ValueError, match="^dem:.*geographic"):
        GeoGrid((7.0, 45.0), 1 / 3600, crs="EPSG:4326").require_projected("dem")


def test_geogrid_of_reads_one_source():
    z = np.zeros((4, 5))
    da, x, y = _xr_dem(z, crs="EPSG:32611")
    g = GeoGrid.of(da)
    assert g == GeoGrid((500000.0, 4000000.0), 30.0, crs="EPSG:32611")
    assert GeoGrid.of(z) is None
    assert GeoGrid.of(z, cell_size=2.0) == GeoGrid((0.0, 8.0), 2.0)
    with pytest.raises(ValueError, match="only one"):
        GeoGrid.of(z, cell_size=2.0, transform=(0.0, 1.0, 0.0, 0.0, 0.0, -1.0))
    with pytest.raises(ValueError, match="^grid:.*EPSG:32612.*EPSG:32611"):
        GeoGrid.of(da, grid=GeoGrid((0.0, 0.0), 30.0, crs="EPSG:32612"))
    with pytest.raises(ValueError, match="^crs:"):
        GeoGrid.of(da, crs="EPSG:32612")
    with pytest.raises(TypeError, match="^grid:"):
        GeoGrid.of(z, grid=(0.0, 0.0, 1.0))
    up = da.isel(y=slice(None, None, -1))  # row 0 south
    with pytest.raises(ValueError, match="^dem:.*row 0 north"):
        GeoGrid.of(up)
    uneven = da.assign_coords(x=x + np.array([0.0, 0.0, 1.0, 0.0, 0.0]))
    with pytest.raises(ValueError, match="^dem:.*equally spaced"):
        GeoGrid.of(uneven)


# ---------------------------------------------------------------- TINs in map units

def test_bundled_geographic_dem_is_refused_and_meshes_on_a_metric_grid():
    dem, info = fg.data.srtm_alps()
    g = GeoGrid.from_affine(info["transform"], crs=info["crs"])
    assert g.is_geographic and g.cell_size == pytest.approx((1 / 1200, 1 / 1200))
    with pytest.raises(ValueError, match="^grid:.*geographic"):
        tin_from_dem(dem, max_error=5.0, grid=g)
    with pytest.raises(ValueError, match="^grid:.*geographic"):
        Mesh.from_grid(dem, grid=g)
    dy, dx = (float(v) for v in info["cell_size"])  # metres north-south, east-west
    local = GeoGrid((0.0, dem.shape[0] * dy), (dx, dy))
    t = tin_from_dem(dem, max_error=5.0, grid=local)
    col, row = t.grid[:, 0], t.grid[:, 1]
    np.testing.assert_allclose(t.vertices[:, 0], (col + 0.5) * dx, rtol=0, atol=1e-9)
    np.testing.assert_allclose(t.vertices[:, 1], (dem.shape[0] - row - 0.5) * dy, rtol=0, atol=1e-9)
    m = t.to_mesh()
    assert m.edges()["boundary"] == _rim_vertices(m)
    assert m.edges()["inconsistent"] == 0 and np.all(m.normals[:, 2] > 0)


def test_tin_from_xarray_has_vertices_in_metres(crop):
    da, x, y = _xr_dem(crop, crs="EPSG:32611")
    t = tin_from_dem(da, max_error=5.0)
    col, row = t.grid[:, 0], t.grid[:, 1]
    np.testing.assert_allclose(t.vertices[:, 0], x[col], rtol=0, atol=1e-9)
    np.testing.assert_allclose(t.vertices[:, 1], y[row], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(t.vertices[:, 2], crop[row, col])
    assert t.crs == "EPSG:32611"
    # the same mesh as the numpy DEM with the equivalent transform
    ref = tin_from_dem(crop, max_error=5.0, transform=(500000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0))
    np.testing.assert_array_equal(t.triangles, ref.triangles)
    np.testing.assert_allclose(t.vertices, ref.vertices, rtol=0, atol=1e-9)
    # and the same as an explicit GeoGrid on the numpy array
    g = tin_from_dem(crop, max_error=5.0, grid=GeoGrid((500000.0, 4000000.0), 30.0))
    np.testing.assert_array_equal(g.vertices, t.vertices)


def test_tin_from_geographic_xarray_is_refused_or_converted(crop):
    xr = pytest.importorskip("xarray")
    rows, cols = crop.shape
    h = 1 / 3600
    da = xr.DataArray(crop, dims=("y", "x"), attrs={"crs": "EPSG:4326"},
                      coords={"y": 45.0 - h * (np.arange(rows) + 0.5), "x": 7.0 + h * (np.arange(cols) + 0.5)})
    with pytest.raises(ValueError, match="^dem:.*geographic.*cell_size"):
        tin_from_dem(da, max_error=5.0)
    with pytest.raises(ValueError, match="^grid:.*geographic"):
        tin_from_dem(crop, max_error=5.0, grid=GeoGrid((7.0, 45.0), h, crs="EPSG:4326"))
    t = tin_from_dem(da, max_error=5.0, cell_size=30.0)  # ground spacing given: a local metric frame
    np.testing.assert_array_equal(t.vertices, tin_from_dem(crop, max_error=5.0, cell_size=30.0).vertices)


def test_tin_from_dask_is_refused_with_a_clear_message(crop):
    da = pytest.importorskip("dask.array")
    with pytest.raises(TypeError, match="^dem: a Dask array.*compute"):
        tin_from_dem(da.from_array(crop, chunks=64), max_error=5.0)
    xr = pytest.importorskip("xarray")
    with pytest.raises(TypeError, match="^dem: a Dask array"):
        tin_from_dem(xr.DataArray(da.from_array(crop, chunks=64), dims=("y", "x")), max_error=5.0)


def _numpy_tin_mesh(t):
    """The numpy construction that ``TIN.to_mesh`` used before it moved to
    Rust (an independent implementation of the same arithmetic)."""
    v, tri = t.vertices, t.triangles
    fn = np.cross(v[tri[:, 1]] - v[tri[:, 0]], v[tri[:, 2]] - v[tri[:, 0]])
    n = np.zeros_like(v)
    for k in range(3):
        np.add.at(n, tri[:, k], fn)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    lo = v[:, :2].min(axis=0)
    span = np.maximum(v[:, :2].max(axis=0) - lo, np.finfo(float).tiny)
    rel = v.copy()
    rel[:, :2] -= lo
    return rel.astype(np.float32), n.astype(np.float32), ((v[:, :2] - lo) / span).astype(np.float32), lo


def test_tin_mesh_in_rust_is_the_numpy_one_bit_for_bit(crop, tmp_path):
    t = tin_from_dem(crop, max_error=3.0, transform=(386000.0, 30.0, 0.0, 3795000.0, 0.0, -30.0))
    m = t.to_mesh()
    verts, normals, uvs, lo = _numpy_tin_mesh(t)
    np.testing.assert_array_equal(m.vertices, verts)
    np.testing.assert_array_equal(m.normals, normals)
    np.testing.assert_array_equal(m.uvs, uvs)
    np.testing.assert_array_equal(m.faces, t.triangles.astype(np.uint32))
    np.testing.assert_array_equal(m.part_ids, np.arange(len(t), dtype=np.uint32))
    assert m.origin == (lo[0], lo[1], 0.0)
    np.testing.assert_allclose(m.map_vertices(), t.vertices, rtol=0, atol=1e-3)
    m.validate()


# ---------------------------------------------------------------- watertightness

def _rim_vertices(m):
    v = m.map_vertices()
    lo, hi = m.bounds()
    return int(np.sum(np.isclose(v[:, 0], lo[0]) | np.isclose(v[:, 0], hi[0])
                      | np.isclose(v[:, 1], lo[1]) | np.isclose(v[:, 1], hi[1])))


@pytest.mark.parametrize("tile_edges", ["shared", "free"])
def test_tiled_tin_is_crack_free(tile_edges):
    rng = np.random.default_rng(4)
    rows, cols = 300, 270  # 3 x 3 tiles of at most 129 samples
    r, c = np.mgrid[0:rows, 0:cols]
    z = 20 * np.sin(r / 37.0) * np.cos(c / 23.0) + 5 * rng.random((rows, cols))
    t = tin_from_dem(z, max_error=2.0, cell_size=30.0, tile_edges=tile_edges)
    m = t.to_mesh()
    e = m.edges()
    assert e["non_manifold"] == 0 and e["inconsistent"] == 0
    # the only open edges form the outer rim: one edge per rim vertex (a
    # closed loop), none inside (a crack would add open edges inside)
    assert e["boundary"] == _rim_vertices(m)
    assert not m.is_watertight()  # an open surface
    trimesh = pytest.importorskip("trimesh")
    tm = m.to_trimesh()
    assert tm.is_winding_consistent
    assert len(trimesh.grouping.group_rows(tm.edges_sorted, require_count=1)) == e["boundary"]


def test_closed_mesh_is_watertight_and_agrees_with_trimesh():
    # a tetrahedron, counter-clockwise from outside
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    m = Mesh.from_triangles(v, f)
    assert m.is_watertight()
    pytest.importorskip("trimesh")
    tm = m.to_trimesh()
    assert tm.is_watertight and tm.is_winding_consistent
    assert tm.volume == pytest.approx(1 / 6, rel=1e-12)  # positive: normals out
    flipped = Mesh.from_triangles(v, np.vstack([f[:3], f[3, [0, 2, 1]]]))
    assert flipped.edges()["inconsistent"] == 3


# ---------------------------------------------------------------- grids

def test_grid_mesh_is_counter_clockwise_in_map_units():
    z = np.add.outer(np.arange(5.0), np.arange(6.0))
    da, x, y = _xr_dem(z, crs="EPSG:32611")
    for split in ("ne-sw", "nw-se", "alternating"):
        m = Mesh.from_grid(da, split=split)
        assert len(m) == 2 * 4 * 5
        v = m.map_vertices()
        np.testing.assert_allclose(np.sort(np.unique(v[:, 0])), x, atol=1e-9, rtol=0)
        np.testing.assert_allclose(np.sort(np.unique(v[:, 1])), np.sort(y), atol=1e-9, rtol=0)
        f = m.faces.astype(np.int64)
        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        np.testing.assert_allclose(area2, 900.0)  # half a 30 m square, counter-clockwise
        assert np.all(m.normals[:, 2] > 0)
        assert m.edges() == {"boundary": 2 * (4 + 5), "non_manifold": 0, "inconsistent": 0}
    # the NE-SW split: the first square's diagonal joins its NE and SW centres
    m = Mesh.from_grid(z, split="ne-sw")
    assert m.faces[0].tolist() == [0, 6, 1] and m.faces[1].tolist() == [1, 6, 7]
    with pytest.raises(ValueError, match="^split:"):
        Mesh.from_grid(z, split="diagonal")


def test_grid_mesh_area_of_a_tilted_plane():
    # z = 0.3 x - 0.4 y over a 30 m grid: area = projected area * sqrt(1 + 0.3^2 + 0.4^2)
    rows, cols = 7, 9
    g = GeoGrid((0.0, rows * 30.0), 30.0)
    yy, xx = g.coords((rows, cols))
    z = 0.3 * xx[None, :] - 0.4 * yy[:, None]
    m = Mesh.from_grid(z, grid=g)
    v = m.map_vertices()
    f = m.faces.astype(np.int64)
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum()
    assert area == pytest.approx((rows - 1) * (cols - 1) * 900.0 * np.sqrt(1.25), rel=1e-12)
    n = m.normals[0].astype(np.float64)
    np.testing.assert_allclose(n, np.array([-0.3, 0.4, 1.0]) / np.sqrt(1.25), atol=1e-6)


def test_grid_mesh_nodata_and_dask():
    z = np.zeros((3, 3))
    z[1, 1] = -9999.0
    m = Mesh.from_grid(z, nodata=-9999.0)
    assert len(m) == 2 and len(m.vertices) == 6
    da = pytest.importorskip("dask.array")
    with pytest.raises(TypeError, match="^dem: a Dask array"):
        Mesh.from_grid(da.from_array(z))


# ---------------------------------------------------------------- files and trimesh

def _read_ply(path):
    with open(path, "rb") as fh:
        data = fh.read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    nv = int(next(ln for ln in lines if ln.startswith("element vertex")).split()[-1])
    nf = int(next(ln for ln in lines if ln.startswith("element face")).split()[-1])
    vdt = np.dtype([(k, "<f4") for k in ("x", "y", "z", "nx", "ny", "nz", "s", "t")])
    fdt = np.dtype([("n", "u1"), ("idx", "<u4", 3), ("part_id", "<u4"), ("kind", "u1"), ("color", "<u4"),
                    ("instance", "<u4")])
    vert = np.frombuffer(body, vdt, nv)
    face = np.frombuffer(body, fdt, nf, offset=nv * vdt.itemsize)
    assert len(body) == nv * vdt.itemsize + nf * fdt.itemsize
    return vert, face


def _read_obj(path):
    v, f = [], []
    with open(path) as fh:
        lines = fh.readlines()
    for ln in lines:
        if ln.startswith("v "):
            v.append([np.float32(s) for s in ln.split()[1:]])
        elif ln.startswith("f "):
            f.append([int(s.split("/")[0]) - 1 for s in ln.split()[1:]])
    return np.array(v, np.float32), np.array(f)


@pytest.mark.parametrize("make", ["plant", "tin", "grid"])
def test_mesh_round_trips_through_obj_and_ply(make, crop, tmp_path):
    if make == "plant":
        m = plant_mesh("F[+F{.f.+f.+f.}]F", sides=5, angle=30)
    elif make == "tin":
        m = tin_from_dem(crop, max_error=5.0, cell_size=30.0).to_mesh()
    else:
        m = Mesh.from_grid(crop[:20, :30], cell_size=30.0, split="alternating")
    m.write(tmp_path / "a.ply")
    vert, face = _read_ply(tmp_path / "a.ply")
    np.testing.assert_array_equal(np.column_stack([vert["x"], vert["y"], vert["z"]]), m.vertices)
    np.testing.assert_array_equal(np.column_stack([vert["nx"], vert["ny"], vert["nz"]]), m.normals)
    np.testing.assert_array_equal(np.column_stack([vert["s"], vert["t"]]), m.uvs)
    np.testing.assert_array_equal(face["idx"], m.faces)
    np.testing.assert_array_equal(face["part_id"], m.part_ids)
    np.testing.assert_array_equal(face["kind"], m.kinds)
    m.write(tmp_path / "a.obj")
    v, f = _read_obj(tmp_path / "a.obj")
    np.testing.assert_array_equal(v, m.vertices)
    # OBJ groups faces by kind (branches, then leaves)
    order = np.argsort(m.kinds, kind="stable")
    np.testing.assert_array_equal(f, m.faces[order])
    # the same bytes as the writers of the L-system and TIN modules
    fg.lsystem.write_ply(m, tmp_path / "b.ply")
    assert (tmp_path / "a.ply").read_bytes() == (tmp_path / "b.ply").read_bytes()
    with pytest.raises(ValueError, match="^path:"):
        m.write(tmp_path / "a.stl")


@pytest.mark.parametrize("ext", ["obj", "ply"])
def test_mesh_round_trips_through_trimesh(ext, crop, tmp_path):
    trimesh = pytest.importorskip("trimesh")
    m = tin_from_dem(crop, max_error=5.0, cell_size=30.0).to_mesh()
    tm = m.to_trimesh()
    np.testing.assert_array_equal(tm.vertices, m.map_vertices())
    np.testing.assert_array_equal(tm.faces, m.faces)
    # trimesh's area equals the sum of triangle areas computed here
    v = m.map_vertices()
    f = m.faces.astype(np.int64)
    area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1).sum()
    assert tm.area == pytest.approx(area, rel=1e-12)
    # files written in Rust, read by trimesh: same vertices (relative to origin) and faces
    m.write(tmp_path / f"t.{ext}")
    back = trimesh.load(tmp_path / f"t.{ext}", process=False, force="mesh")
    np.testing.assert_allclose(back.vertices, m.vertices, rtol=0, atol=0)
    np.testing.assert_array_equal(back.faces, m.faces)
    # and a trimesh mesh comes back as a Mesh
    again = Mesh.from_triangles(back.vertices + m.origin, back.faces)
    np.testing.assert_allclose(again.map_vertices(), m.map_vertices(), rtol=0, atol=1e-6)


def test_missing_optional_library_says_which_extra(monkeypatch):
    import sys

    m = plant_mesh("F", sides=3)
    monkeypatch.setitem(sys.modules, "pyvista", None)
    with pytest.raises(ImportError, match=r'pyvista is needed here: pip install "fractalgeo_rs\[pyvista\]"'):
        m.to_pyvista()
    monkeypatch.setitem(sys.modules, "trimesh", None)
    with pytest.raises(ImportError, match=r'pip install "fractalgeo_rs\[mesh\]"'):
        m.to_trimesh()


# ---------------------------------------------------------------- bad meshes

def test_bad_meshes_name_the_parameter():
    v = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    with pytest.raises(ValueError, match="^faces:.*vertex"):
        Mesh.from_triangles(v, [[0, 1, 3]])
    with pytest.raises(ValueError, match="^faces:"):
        Mesh.from_triangles(v, [[0, 1, -1]])
    with pytest.raises(ValueError, match="^vertices:.*(NaN|finite)"):
        Mesh.from_triangles(np.array([[0.0, 0.0, np.nan], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]), [[0, 1, 2]])
    with pytest.raises(ValueError, match="^faces:.*zero area"):
        Mesh.from_triangles(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]), [[0, 1, 2]])
    with pytest.raises(ValueError, match="^vertices:"):
        Mesh.from_triangles(v[:, :2], [[0, 1, 2]])
    good = Mesh.from_triangles(v, [[0, 1, 2]])
    import dataclasses

    with pytest.raises(ValueError, match="^faces:"):
        dataclasses.replace(good, faces=np.array([[0, 1, 7]], np.uint32)).validate()
    with pytest.raises(ValueError, match="^vertices:"):
        dataclasses.replace(good, vertices=np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]], np.float32)).validate()
    with pytest.raises(ValueError, match="^mesh:"):
        dataclasses.replace(good, kinds=np.zeros(2, np.uint8)).validate()
    with pytest.raises(TypeError, match="^mesh:"):
        fg.lsystem.write_obj("not a mesh", "x.obj")


# ---------------------------------------------------------------- the raster dispatcher

def test_run_raster_writes_the_grid_to_its_output():
    xr = pytest.importorskip("xarray")
    from fractalgeo_rs._backend import run_raster

    z = np.arange(20.0).reshape(4, 5)
    g = GeoGrid((100.0, 200.0), 10.0, crs="EPSG:32633")
    # without a grid, nothing changes
    (plain,) = run_raster(lambda b: b[None] * 2, z, depth=0, n_out=1, dtype=np.float64)
    assert isinstance(plain, np.ndarray)
    (out,) = run_raster(lambda b: b[None] * 2, z, depth=0, n_out=1, dtype=np.float64, grid=g)
    assert isinstance(out, xr.DataArray) and out.attrs["crs"] == "EPSG:32633"
    np.testing.assert_array_equal(out.values, 2 * z)
    np.testing.assert_array_equal(out.x, 100.0 + 10.0 * (np.arange(5) + 0.5))
    assert GeoGrid.of(out) == g
    da, _, _ = _xr_dem(z, crs="EPSG:32611")
    with pytest.raises(ValueError, match="^grid:.*EPSG:32633.*EPSG:32611"):
        run_raster(lambda b: b[None], da, depth=0, n_out=1, grid=g)
