"""``Mesh.write`` keeps a mesh's place on Earth: the file's float32 offsets
plus the offset recorded in the JSON sidecar are the mesh's map coordinates
(read back by the independent parsers of ``tests/meshfiles.py``), the CRS is
in the sidecar and ``.prj``; ``Mesh.placed_on`` moves a local-frame mesh
onto a grid by the corner formula of a (rotated) grid, computed here by hand."""
import math
import os

import numpy as np
import pytest
from meshfiles import absolute, read_mesh, read_obj, read_ply, sidecar

from fractalgeo_rs.geometry import GeoGrid, Mesh
from fractalgeo_rs.lsystem import plant_mesh, write_obj

#: a UTM 33N grid, 30 m cells, north-west corner at (500010, 4100020)
X0, Y0, CELL = 500010.0, 4100020.0, 30.0


def _dem(rows=7, cols=9):
    y, x = np.mgrid[0:rows, 0:cols]
    return 900.0 + 3.0 * np.sin(x / 2.0) + 2.0 * np.cos(y / 1.7) + 0.25 * x * y


def _centres(z, x0, y0, dx, dy, theta_deg=0.0):
    """Map coordinates of the cell centres of a (rotated) grid, by GDAL's formula."""
    r, c = np.mgrid[0:z.shape[0], 0:z.shape[1]]
    r, c = r.ravel() + 0.5, c.ravel() + 0.5
    t = math.radians(theta_deg)
    x = x0 + c * dx * math.cos(t) + r * dy * math.sin(t)
    y = y0 + c * dx * math.sin(t) - r * dy * math.cos(t)
    return np.column_stack([x, y, z.ravel()])


def _same_points(a, b, atol):
    """Every row of ``a`` matches a row of ``b`` (sorted lexicographically) within ``atol``."""
    assert a.shape == b.shape
    ia, ib = np.lexsort(np.round(a / 1e-3).T[::-1]), np.lexsort(np.round(b / 1e-3).T[::-1])
    np.testing.assert_allclose(a[ia], b[ib], rtol=0, atol=atol)


@pytest.mark.parametrize("ext", ["obj", "ply"])
def test_write_round_trip_restores_map_coordinates(tmp_path, ext):
    z = _dem()
    m = Mesh.from_grid(z, grid=GeoGrid((X0, Y0), CELL, crs="EPSG:32633"))
    assert m.crs == "EPSG:32633" and m.origin[0] > 500000.0
    out = tmp_path / f"grid.{ext}"
    m.write(out)
    v, f, _, meta = absolute(out)
    assert meta["offset"] == list(m.origin) and meta["coordinates"] == "local"
    assert (meta["vertices"], meta["triangles"]) == (len(m.vertices), len(m))
    # file + offset = the origin-added float32 vertices, to 1e-6 m (float64 sums)
    expected = np.asarray(m.vertices, dtype=np.float64) + np.asarray(m.origin)
    np.testing.assert_allclose(v, expected, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(f, m.faces)
    # the file's header records the same offset (exact reprs), as fractalgeo tin's files do
    comments = read_obj(out)[3] if ext == "obj" else read_ply(out)[2]
    offsets = [c.split()[1:] for c in comments if c.startswith("offset ")]
    assert [[float(x) for x in o] for o in offsets] == [meta["offset"]]
    assert any(c.startswith("crs PROJCS") or c.startswith("crs EPSG") for c in comments) or meta["crs_wkt"] is None
    # and those are the DEM's cell centres in UTM, within float32 rounding of offsets up to 240 m
    _same_points(v, _centres(z, X0, Y0, CELL, CELL), atol=1e-4)
    rasterio = pytest.importorskip("rasterio")
    assert rasterio.crs.CRS.from_wkt(meta["crs_wkt"]).to_epsg() == 32633
    assert rasterio.crs.CRS.from_wkt((tmp_path / "grid.prj").read_text()).to_epsg() == 32633


def test_crs_argument_and_no_crs(tmp_path):
    pytest.importorskip("rasterio")
    m = Mesh.from_grid(_dem(), cell_size=2.0)
    assert m.crs is None
    m.write_obj(tmp_path / "a.obj")
    assert sidecar(tmp_path / "a.obj")["crs_wkt"] is None and not (tmp_path / "a.prj").exists()
    m.write_ply(tmp_path / "b.ply", crs="EPSG:32631")
    assert "UTM zone 31N" in sidecar(tmp_path / "b.ply")["crs_wkt"] and (tmp_path / "b.prj").exists()
    # crs= replaces the mesh's own
    g = Mesh.from_grid(_dem(), grid=GeoGrid((X0, Y0), CELL, crs="EPSG:32633"))
    g.write(tmp_path / "c.ply", crs="EPSG:32632")
    assert "UTM zone 32N" in sidecar(tmp_path / "c.ply")["crs_wkt"]


def test_plant_mesh_sidecar_says_origin_zero(tmp_path):
    m = plant_mesh("F[+F]F", sides=3)
    write_obj(m, tmp_path / "p.obj")
    meta = sidecar(tmp_path / "p.obj")
    assert meta["offset"] == [0.0, 0.0, 0.0] and meta["crs_wkt"] is None
    v, _, _ = read_mesh(tmp_path / "p.obj")
    np.testing.assert_array_equal(v, np.asarray(m.vertices, dtype=np.float64))


def test_bad_input_names_the_parameter_and_writes_nothing(tmp_path):
    pytest.importorskip("rasterio")
    m = Mesh.from_grid(_dem(), cell_size=1.0)
    with pytest.raises(ValueError, match="^path:"):
        m.write(tmp_path / "a.stl")
    with pytest.raises(ValueError, match="^crs:"):
        m.write(tmp_path / "a.ply", crs="EPSG:999999")
    with pytest.raises(ValueError, match="^format:"):
        m.write(tmp_path / "a.ply", format="stl")
    assert not os.listdir(tmp_path)  # nothing written, no temporary left
    with pytest.raises((OSError, FileNotFoundError)):
        m.write(tmp_path / "missing" / "a.ply")
    assert not os.listdir(tmp_path)


def test_placed_on_north_up_moves_only_the_origin():
    z = _dem()
    local = Mesh.from_grid(z, cell_size=CELL)
    grid = GeoGrid((X0, Y0), CELL, crs="EPSG:32633")
    m = local.placed_on(grid, z.shape[0])
    assert m.crs == "EPSG:32633"
    np.testing.assert_array_equal(m.vertices, local.vertices)  # bit for bit
    np.testing.assert_array_equal(m.normals, local.normals)
    assert m.origin == (X0 + local.origin[0], Y0 - z.shape[0] * CELL + local.origin[1], local.origin[2])
    _same_points(m.map_vertices(), _centres(z, X0, Y0, CELL, CELL), atol=1e-4)  # z: float32 at 900 m


@pytest.mark.parametrize("theta", [30.0, -76.0])
def test_placed_on_rotated_grid_lands_on_the_cell_centres(theta):
    z = _dem()
    dx, dy = 20.0, 30.0
    local = Mesh.from_triangles(
        np.column_stack([(np.mgrid[0:7, 0:9][1].ravel() + 0.5) * dx,
                         (z.shape[0] - np.mgrid[0:7, 0:9][0].ravel() - 0.5) * dy, z.ravel()]),
        Mesh.from_grid(z).faces.astype(np.int64))
    grid = GeoGrid((X0, Y0), (dx, dy), rotation=theta)
    m = local.placed_on(grid, z.shape[0])
    _same_points(m.map_vertices(), _centres(z, X0, Y0, dx, dy, theta), atol=1e-4)
    # normals are rotated with the mesh: still unit, z unchanged, same angle to the map's x axis shifted by theta
    np.testing.assert_allclose(np.linalg.norm(m.normals, axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(m.normals[:, 2], local.normals[:, 2], atol=1e-7)
    t = math.radians(theta)
    n = local.normals.astype(np.float64)
    rotated = np.column_stack([n[:, 0] * math.cos(t) - n[:, 1] * math.sin(t),
                               n[:, 0] * math.sin(t) + n[:, 1] * math.cos(t)])
    np.testing.assert_allclose(m.normals[:, :2], rotated, atol=1e-6)


def test_placed_on_errors_name_the_parameter():
    m = Mesh.from_grid(_dem(), cell_size=1.0)
    with pytest.raises(TypeError, match="^grid:"):
        m.placed_on((X0, Y0), 7)
    with pytest.raises(ValueError, match="^grid:"):
        m.placed_on(GeoGrid((7.0, 44.0), 1 / 3600, crs="EPSG:4326"), 7)
    with pytest.raises(TypeError, match="^rows:"):
        m.placed_on(GeoGrid((X0, Y0), 1.0), 7.0)
    with pytest.raises(ValueError, match="^rows:"):
        m.placed_on(GeoGrid((X0, Y0), 1.0), 0)


@pytest.mark.parametrize("ext", ["obj", "ply"])
def test_rewriting_without_a_crs_removes_the_old_prj(tmp_path, ext):
    """A mesh written again without a CRS leaves no ``.prj`` of the old
    write behind (GIS tools read it and would place the file in that CRS
    while the sidecar says ``crs_wkt: null``)."""
    z = _dem()
    out = tmp_path / f"grid.{ext}"
    Mesh.from_grid(z, grid=GeoGrid((X0, Y0), CELL, crs="EPSG:32633")).write(out)
    assert (tmp_path / "grid.prj").exists()
    Mesh.from_grid(z, grid=GeoGrid((X0, Y0), CELL)).write(out)
    assert sidecar(out)["crs_wkt"] is None
    assert not (tmp_path / "grid.prj").exists()


@pytest.mark.parametrize("name", ["grid.json", "grid.PRJ"])
def test_a_mesh_file_named_like_its_sidecar_is_refused(tmp_path, name):
    """``Mesh.write("x.json", format="ply")`` would write the mesh and then
    its sidecar over it: refused before anything is written."""
    m = Mesh.from_grid(_dem(), grid=GeoGrid((X0, Y0), CELL))
    with pytest.raises(ValueError, match=r"^path: .*sidecar"):
        m.write(tmp_path / name, format="ply")
    with pytest.raises(ValueError, match=r"^path: .*sidecar"):
        m.write_obj(tmp_path / name)
    assert list(tmp_path.iterdir()) == []
