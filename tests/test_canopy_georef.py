"""``fractalgeo canopy`` meshes keep their place on Earth: with a projected
GeoTIFF the stand's mesh file plus the sidecar's offset is in the DEM's CRS
(x east, y north, z height): the soil vertices are the DEM's cell centres
with their heights, every plant's trunk stands inside the DEM's bounds at
the DEM's bilinear height there (an interpolation written here from the
GeoTIFF's transform); a geographic DEM gives a local metric frame whose
sidecar anchor turns the vertices back into the cells' lon/lat. The files
are read by the independent parsers of ``tests/meshfiles.py``."""
import math

import numpy as np
import pytest
from meshfiles import absolute, read_obj

from fractalgeo_rs import cli
from fractalgeo_rs.canopy import plant_stand

rasterio = pytest.importorskip("rasterio")
from rasterio.transform import Affine, from_origin  # noqa: E402

#: a UTM 31N DEM: north-west corner (500123.5, 4000456.25)
X0, Y0 = 500123.5, 4000456.25


def _hills(rows, cols):
    y, x = np.mgrid[0:rows, 0:cols]
    return 250.0 + 0.9 * np.sin(x / 3.0) + 0.6 * np.cos(y / 2.5) + 0.05 * x * y


def _tif(path, z, transform, crs):
    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1, dtype="float64",
                       crs=crs, transform=transform) as d:
        d.write(z, 1)
    return str(path)


def _bilinear(z, transform, x, y):
    """The DEM's bilinear height at map ``(x, y)``: samples at cell centres
    (GDAL: pixel ``(col + 0.5, row + 0.5)``), fractional row and column from
    the inverse transform."""
    col, row = ~transform * (x, y)
    c, r = np.asarray(col) - 0.5, np.asarray(row) - 0.5
    c0 = np.clip(np.floor(c).astype(int), 0, z.shape[1] - 2)
    r0 = np.clip(np.floor(r).astype(int), 0, z.shape[0] - 2)
    fc, fr = c - c0, r - r0
    return ((1 - fr) * ((1 - fc) * z[r0, c0] + fc * z[r0, c0 + 1])
            + fr * ((1 - fc) * z[r0 + 1, c0] + fc * z[r0 + 1, c0 + 1]))


def n_soil_tri(z):
    """Triangles of a DEM's grid mesh: two per square of four cell centres."""
    return 2 * (z.shape[0] - 1) * (z.shape[1] - 1)


def _trunk_bases(v, f, kinds, bases_z):
    """Centres of the trunks' bottom rings (a herb's trunk starts vertical,
    so its first ring is horizontal at the base): bark vertices at a plant's
    base height (within 1e-4 m) grouped by base height; the ring centre is the
    midpoint of its extreme x and y (a ring of 4 vertices is centrally
    symmetric). Returns (centre x, centre y, z) per ring found."""
    bark = np.unique(f[kinds == 1].ravel())
    out = []
    for bz in bases_z:
        ring = bark[np.abs(v[bark, 2] - bz) < 1e-4]
        if len(ring) < 4:
            continue  # a trunk cut by the ground's edge
        p = v[ring]
        if np.ptp(p[:, 0]) > 1.0 or np.ptp(p[:, 1]) > 1.0:
            continue  # two plants at the same height: ambiguous
        out.append([(p[:, 0].min() + p[:, 0].max()) / 2, (p[:, 1].min() + p[:, 1].max()) / 2, bz])
    return np.array(out).reshape(-1, 3)


@pytest.mark.parametrize("ext", ["ply", "obj"])
@pytest.mark.parametrize("cell", [(2.0, 2.0), (1.5, 2.5)])
def test_stand_mesh_is_in_the_dem_crs(tmp_path, capsys, ext, cell):
    dy, dx = cell
    z = _hills(17, 13)
    t = from_origin(X0, Y0, dx, dy)
    dem = _tif(tmp_path / "hills.tif", z, t, "EPSG:32631")
    out = tmp_path / f"stand.{ext}"
    assert cli.main(["canopy", "--plant", "herb", "--density", "0.1", "--dem", dem, str(out), "--seed", "3",
                     "--spp", "64", "--zenith", "0"]) == 0
    assert "EPSG:32631" in capsys.readouterr().out
    v, f, kinds, meta = absolute(out)
    assert rasterio.crs.CRS.from_wkt(meta["crs_wkt"]).to_epsg() == 32631
    assert rasterio.crs.CRS.from_wkt((tmp_path / "stand.prj").read_text()).to_epsg() == 32631
    # the soil: the DEM's cell centres in UTM metres with the DEM's heights
    r, c = np.mgrid[0:z.shape[0], 0:z.shape[1]]
    cx, cy = t * (c.ravel() + 0.5, r.ravel() + 0.5)
    centres = np.column_stack([cx, cy, z.ravel()])
    tree = {(round(x, 3), round(y, 3)): h for x, y, h in centres}
    n_soil = z.size
    soil = v[:n_soil]  # the ground's vertices come first in a stand's mesh
    for x, y, h in soil:
        assert abs(tree[(round(x, 3), round(y, 3))] - h) < 1e-4  # float32 heights at 250 m
    assert len({(round(x, 3), round(y, 3)) for x, y, _ in soil}) == z.size
    # every triangle inside the DEM's bounds in UTM, but for branches of edge plants hanging over them
    left, bottom, right, top = rasterio.transform.array_bounds(z.shape[0], z.shape[1], t)  # W, S, E, N
    u = v[np.unique(f)]
    assert np.all((u[:, 0] > left - 1) & (u[:, 0] < right + 1) & (u[:, 1] > bottom - 1) & (u[:, 1] < top + 1))
    if kinds is None:  # OBJ: every triangle, grouped by material, the offset in the header too
        _, _, groups, comments = read_obj(out)
        assert len(groups) == meta["triangles"] and set(groups) == {"soil", "bark", "leaves"}
        assert groups[:n_soil_tri(z)] == ["soil"] * n_soil_tri(z)
        assert f"offset {meta['offset'][0]!r} {meta['offset'][1]!r} {meta['offset'][2]!r}" in comments
        return
    # every trunk's base on the DEM's bilinear height at its UTM position
    st = plant_stand("herb", 0.1, z, cell_size=cell, seed=3)
    found = _trunk_bases(v, f, np.asarray(kinds), st.bases[:, 2])
    assert len(found) >= 0.8 * len(st.bases) > 0
    assert np.all((found[:, 0] > left) & (found[:, 0] < right) & (found[:, 1] > bottom) & (found[:, 1] < top))
    np.testing.assert_allclose(found[:, 2], _bilinear(z, t, found[:, 0], found[:, 1]), rtol=0, atol=2e-4)
    # and they are the API's bases moved to the DEM's south-west corner
    expected = st.bases[:, :2] + [X0, Y0 - z.shape[0] * dy]
    d = np.hypot(*(found[:, None, :2] - expected[None, :, :]).transpose(2, 0, 1)).min(axis=1)
    assert d.max() < 1e-4


def test_rotated_dem_places_the_soil_on_the_rotated_cells(tmp_path):
    z = _hills(9, 11)
    t = Affine.translation(X0, Y0) * Affine.rotation(25.0) * Affine.scale(2.0, -2.0)
    dem = _tif(tmp_path / "rot.tif", z, t, "EPSG:32631")
    out = tmp_path / "rot.ply"
    assert cli.main(["canopy", "--plant", "herb", "--density", "0.2", "--dem", dem, str(out), "--seed", "1",
                     "--spp", "64", "--zenith", "0"]) == 0
    v, _, _, _ = absolute(out)
    r, c = np.mgrid[0:z.shape[0], 0:z.shape[1]]
    cx, cy = t * (c.ravel() + 0.5, r.ravel() + 0.5)
    np.testing.assert_allclose(v[:z.size, 0], cx, rtol=0, atol=1e-4)  # the ground's vertices, row by row
    np.testing.assert_allclose(v[:z.size, 1], cy, rtol=0, atol=1e-4)
    np.testing.assert_allclose(v[:z.size, 2], z.ravel(), rtol=0, atol=1e-4)


def test_geographic_dem_gives_a_local_metric_frame_anchored_in_the_sidecar(tmp_path, capsys):
    # 1 arcsecond cells at 44 N, about 30.9 m x 22.2 m
    z = _hills(11, 9)
    a = 1 / 3600
    t = from_origin(7.0, 44.003, a, a)
    dem = _tif(tmp_path / "geo.tif", z, t, "EPSG:4326")
    out = tmp_path / "geo.obj"
    assert cli.main(["canopy", "--plant", "herb", "--density", "0.001", "--dem", dem, str(out), "--seed", "1",
                     "--spp", "64", "--zenith", "0"]) == 0
    assert "local metric frame" in capsys.readouterr().out
    v, _, _, meta = absolute(out)
    assert meta["crs_wkt"] is None and not (tmp_path / "geo.prj").exists()  # no CRS describes the frame
    frame = meta["local_frame"]
    assert frame["corner_lonlat"] == [7.0, pytest.approx(44.003 - 11 * a, abs=1e-12)]
    assert rasterio.crs.CRS.from_wkt(frame["crs_wkt"]).to_epsg() == 4326
    m_lon, m_lat = frame["metres_per_degree"]
    lat_mid = 44.003 - 5.5 * a  # the cell in metres is taken at the middle latitude
    p = math.radians(lat_mid)
    assert m_lat == pytest.approx(111132.92 - 559.82 * math.cos(2 * p) + 1.175 * math.cos(4 * p), rel=1e-6)
    assert m_lon == pytest.approx(111412.84 * math.cos(math.radians(lat_mid)), rel=1e-3)
    # the rule turns the soil vertices back into the cells' lon/lat, heights kept
    lon = frame["corner_lonlat"][0] + v[:z.size, 0] / m_lon
    lat = frame["corner_lonlat"][1] + v[:z.size, 1] / m_lat
    r, c = np.mgrid[0:z.shape[0], 0:z.shape[1]]
    clon, clat = t * (c.ravel() + 0.5, r.ravel() + 0.5)
    np.testing.assert_allclose(lon, clon, rtol=0, atol=1e-9)  # 1e-9 degree: 0.1 mm
    np.testing.assert_allclose(lat, clat, rtol=0, atol=1e-9)
    np.testing.assert_allclose(v[:z.size, 2], z.ravel(), rtol=0, atol=1e-4)


def test_dem_without_georeferencing_and_disc_canopy_are_local(tmp_path, capsys):
    np.save(tmp_path / "z.npy", _hills(6, 6))
    out = tmp_path / "s.ply"
    assert cli.main(["canopy", "--plant", "herb", "--density", "0.5", "--dem", str(tmp_path / "z.npy"),
                     "--cell-size", "2", str(out), "--seed", "1", "--spp", "64", "--zenith", "0"]) == 0
    v, _, _, meta = absolute(out)
    assert meta["crs_wkt"] is None and "local_frame" not in meta
    np.testing.assert_allclose(v[0, :2], [1.0, 11.0], atol=1e-6)  # the north-west cell centre, metres
    out = tmp_path / "d.obj"
    assert cli.main(["canopy", str(out), "--lai", "1", "--leaf-radius", "0.1", "--extent", "3",
                     "2", "--height", "0.2", "1", "--seed", "1"]) == 0
    v, _, _, meta = absolute(out)
    assert meta["crs_wkt"] is None
    assert v[:, 0].min() >= -0.2 and v[:, 0].max() <= 3.2 and v[:, 1].min() >= -0.2 and v[:, 1].max() <= 2.2


def test_bad_dem_grids_and_output_name_the_option(tmp_path):
    z = _hills(6, 6)
    sheared = _tif(tmp_path / "sh.tif", z, Affine(2.0, 0.5, X0, 0.0, -2.0, Y0), "EPSG:32631")
    args = cli.build_parser("canopy").parse_args(["canopy", "--plant", "bush", "--density", "0.1", "--dem", sheared,
                                                  str(tmp_path / "a.ply")])
    with pytest.raises(ValueError, match="^--dem:.*north-up"):
        args.func(args)
    rot_geo = _tif(tmp_path / "rg.tif", z, Affine.translation(7.0, 44.0) * Affine.rotation(10.0)
                   * Affine.scale(1 / 3600, -1 / 3600), "EPSG:4326")
    args = cli.build_parser("canopy").parse_args(["canopy", "--plant", "bush", "--density", "0.1", "--dem", rot_geo,
                                                  str(tmp_path / "a.ply")])
    with pytest.raises(ValueError, match="^--dem:.*north up"):
        args.func(args)
    ok = _tif(tmp_path / "ok.tif", z, from_origin(X0, Y0, 1.0, 1.0), "EPSG:32631")
    for argv in (["--plant", "bush", "--density", "0.1", "--dem", ok], ["--lai", "1", "--leaf-radius", "0.1",
                                                                        "--extent", "3", "2", "--height", "0.2", "1"]):
        args = cli.build_parser("canopy").parse_args(["canopy", str(tmp_path / "a.stl"), *argv])
        with pytest.raises(ValueError, match="^output:"):
            args.func(args)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ok.tif", "rg.tif", "sh.tif"]  # nothing written
