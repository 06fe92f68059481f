"""``fractalgeo tin`` keeps the mesh's place on Earth: the vertices written
(plus the offset recorded in the file) are the DEM's map coordinates of the
kept samples, the CRS is recorded, the preview is georeferenced."""
import json

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main
from fractalgeo_rs.tin._export import read_tin

rasterio = pytest.importorskip("rasterio")

#: a UTM 33N DEM, 30 m cells, upper-left corner at (500010, 4100020)
X0, Y0, CELL = 500010.0, 4100020.0, 30.0


@pytest.fixture
def utm_dem(tmp_path):
    z = (fg.fbm_surface((48, 40), 0.7, seed=3) * 50.0 + 900.0).astype(np.float32)
    path = tmp_path / "dem.tif"
    fg.write_raster(path, z, crs="EPSG:32633", transform=rasterio.Affine(CELL, 0, X0, 0, -CELL, Y0))
    return path, z


def _map_coordinates(z, rows, cols):
    """Map coordinates of sample centres, computed from the transform by hand."""
    return np.column_stack([X0 + (cols + 0.5) * CELL, Y0 - (rows + 0.5) * CELL, z[rows, cols]])


@pytest.mark.parametrize("ext", ["obj", "ply"])
@pytest.mark.parametrize("coordinates", ["local", "map"])
def test_vertices_plus_offset_are_map_coordinates(utm_dem, tmp_path, capsys, ext, coordinates):
    path, z = utm_dem
    out = tmp_path / f"tin.{ext}"
    assert main(["tin", str(path), str(out), "--max-error", "2", "--coordinates", coordinates,
                 "--preview", str(tmp_path / "p.png")]) == 0
    verts, tris, off = read_tin(out)
    # every vertex is a sample centre of the DEM: find its row and column from the map position
    cols = np.rint((verts[:, 0] - X0) / CELL - 0.5).astype(int)
    rows = np.rint((Y0 - verts[:, 1]) / CELL - 0.5).astype(int)
    np.testing.assert_allclose(verts, _map_coordinates(z.astype(np.float64), rows, cols), rtol=0, atol=1e-6)
    if coordinates == "local":
        assert off[0] >= X0 and off[1] >= Y0 - 48 * CELL and off[0] > 0
    else:
        assert not off.any()
    meta = json.loads((tmp_path / "tin.json").read_text())
    assert meta["offset"] == [float(v) for v in off]
    crs = rasterio.crs.CRS.from_wkt(meta["crs_wkt"])
    assert crs.to_epsg() == 32633
    assert rasterio.crs.CRS.from_wkt((tmp_path / "tin.prj").read_text()).to_epsg() == 32633
    assert tris.shape[1] == 3 and tris.max() < len(verts)
    head = (out.read_bytes()[:2000]).decode("latin1")
    assert "L-system" not in head and "terrain TIN" in head
    # the preview PNG has a world file on the DEM's grid
    pgw = [float(v) for v in (tmp_path / "p.pgw").read_text().split()]
    assert pgw == [CELL, 0.0, 0.0, -CELL, X0 + CELL / 2, Y0 - CELL / 2]
    assert (tmp_path / "p.prj").exists()


def test_npy_dem_assumes_cell_one_in_one_line(tmp_path, capsys):
    np.save(tmp_path / "d.npy", np.arange(64.0).reshape(8, 8) ** 1.5)
    assert main(["tin", str(tmp_path / "d.npy"), str(tmp_path / "a.obj")]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cell size 1 assumed" in err and "--cell-size" in err
    assert main(["tin", str(tmp_path / "d.npy"), str(tmp_path / "b.obj"), "--cell-size", "30",
                 "--crs", "EPSG:32633", "--coordinates", "map"]) == 0
    assert capsys.readouterr().err == ""
    verts, _, _ = read_tin(tmp_path / "b.obj")
    assert verts[:, 0].max() == pytest.approx(7.5 * 30) and verts[:, 1].max() == pytest.approx(7.5 * 30)
    assert rasterio.crs.CRS.from_wkt((tmp_path / "b.prj").read_text()).to_epsg() == 32633


def test_rotated_grid_cell_size_is_the_pixel_side(tmp_path, capsys):
    """A rotated transform (a = d = cos/sin * 0.6): hillshade and --z-scale
    cell use sqrt(a^2 + d^2), not |a|."""
    from fractalgeo_rs._cli_common import pixel_size

    c, s = np.cos(np.radians(76.0)), np.sin(np.radians(76.0))
    t = rasterio.Affine(0.6 * c, -0.6 * s, 1000.0, 0.6 * s, 0.6 * c, 2000.0)
    sx, sy = pixel_size(t)
    assert sx == pytest.approx(0.6, abs=1e-12) and sy == pytest.approx(0.6, abs=1e-12)
    z = (fg.fbm_surface((40, 40), 0.6, seed=1) * 3).astype(np.float32)
    src = tmp_path / "rot.tif"
    fg.write_raster(src, z, crs="EPSG:32633", transform=t)
    assert main(["transform", str(src), str(tmp_path / "m.tif"), "--window", "9", "--z-scale", "cell"]) == 0
    out = capsys.readouterr().out
    assert "z_scale: 0.6 " in out
