"""``canopy.plant_stand`` and ``fractalgeo canopy --plant``: L-system plants on a
DEM with bark, leaf and soil materials, and the BRF table, against closed forms
(a bare flat soil, a tilted plane's heights, the gap at the nadir hot spot)."""
import math

import numpy as np
import pytest

from fractalgeo_rs import cli
from fractalgeo_rs.canopy import PLANT_PRESETS, PlantStand, plant_stand
from fractalgeo_rs.radiometry import BiLambertian, Lambertian

rasterio = pytest.importorskip("rasterio")
from rasterio.transform import from_origin  # noqa: E402


def _tif(path, z, transform, crs="EPSG:32631"):
    with rasterio.open(path, "w", driver="GTiff", height=z.shape[0], width=z.shape[1], count=1, dtype="float64",
                       crs=crs, transform=transform) as d:
        d.write(z, 1)
    return str(path)


def _table(text):
    lines = [r for r in text.splitlines() if r and not r.startswith("#")]
    head = lines[0].split(",")
    return head, [dict(zip(head, map(float, r.split(",")))) for r in lines[1:]]


def _args(argv):
    parser = cli.build_parser("canopy")
    return parser.parse_args(["canopy", *argv])


def test_presets_counts_and_materials():
    assert PLANT_PRESETS == ("bush", "herb")
    z = np.zeros((21, 21))
    for plant in PLANT_PRESETS:
        st = plant_stand(plant, 0.05, z, cell_size=1.0, seed=3)
        assert isinstance(st, PlantStand) and st.plant == plant and st.seed == 3
        assert len(st.bases) == round(0.05 * 20 * 20)  # density x the cell centres' box
        ids = st.material_ids
        assert np.sum(ids == 0) == 2 * 20 * 20 and set(np.unique(ids)) == {0, 1, 2}
        assert np.array_equal(st.mesh.kinds, ids.astype(np.uint8))
        v = st.mesh.vertices.astype(float) + np.asarray(st.mesh.origin)
        f = st.mesh.faces
        area = 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
        assert st.leaf_area == pytest.approx(area[ids == 2].sum(), rel=1e-5)
        assert st.lai == pytest.approx(st.leaf_area / 400.0, rel=1e-12)
        c = v[f].mean(axis=1)  # every triangle's centroid over the ground
        x0, y0, w, h = st.extent
        assert (x0, y0, w, h) == (0.5, 0.5, 20.0, 20.0)
        assert np.all((c[:, 0] >= x0 - 1e-6) & (c[:, 0] <= x0 + w + 1e-6) & (c[:, 1] >= y0 - 1e-6)
                      & (c[:, 1] <= y0 + h + 1e-6))
    # the same seed gives the same stand; stochastic herbs differ from plant to plant
    a, b = plant_stand("herb", 0.05, z, seed=4), plant_stand("herb", 0.05, z, seed=4)
    assert np.array_equal(a.mesh.vertices, b.mesh.vertices) and np.array_equal(a.bases, b.bases)


@pytest.mark.parametrize("cell", [(1.0, 1.0), (2.0, 1.0), (0.5, 1.5)])
def test_plants_stand_on_the_dem_for_any_cell_shape(cell):
    # a tilted plane z = a x + b y: bilinear interpolation is exact, so every base
    # is on the plane at its own (x, y), and every base lies over the ground
    dy, dx = cell
    rows, cols = 15, 12
    a, b = 0.1, -0.05
    x = (np.arange(cols) + 0.5) * dx
    y = (rows - np.arange(rows) - 0.5) * dy
    z = a * x[None, :] + b * y[:, None]
    st = plant_stand("bush", 0.3, z, cell_size=cell, seed=5)
    area = (cols - 1) * dx * (rows - 1) * dy
    assert len(st.bases) == round(0.3 * area)
    bx, by, bz = st.bases.T
    assert np.allclose(bz, a * bx + b * by, atol=1e-9)
    assert bx.min() >= 0.5 * dx and bx.max() <= (cols - 0.5) * dx
    assert by.min() >= 0.5 * dy and by.max() <= (rows - 0.5) * dy
    # plants keep their shape: the deterministic bush is as tall above its base everywhere
    v = st.mesh.vertices.astype(float) + np.asarray(st.mesh.origin)
    assert v[:, 2].max() - bz.max() <= 1.5618 + 1e-3


def test_bare_flat_dem_gives_the_soil_reflectance_exactly():
    st = plant_stand("bush", 0.0, np.full((6, 7), 3.0), cell_size=(2.0, 1.5), soil=Lambertian(0.27), seed=1)
    assert len(st.bases) == 0 and st.lai == 0.0
    o = st.scene().brf_orders(sun=(0.0, 40.0), spp=3000, max_depth=20)
    assert o.total.value == pytest.approx(0.27, abs=1e-12)
    assert (o.multiple.value, o.multiple.se) == (0.0, 0.0)


def test_black_plants_at_the_nadir_hot_spot_show_the_gap_fraction():
    # sun and view at nadir, black bark and leaves: a path counts soil * 1 when its ray
    # reaches the soil (the shadow ray goes back along it), so BRF = rho_soil * gap(0)
    st = plant_stand("bush", 0.08, np.zeros((21, 21)), soil=Lambertian(0.5), bark=Lambertian(0.0),
                     leaf=BiLambertian(0.0, 0.0), seed=2)
    s = st.scene()
    brf = s.brf(sun=(0.0, 0.0), spp=40_000, max_depth=5, seed=1)
    gap = s.gap_fraction(0.0, n=40_000, seed=2)
    assert 0.3 < gap.value < 0.95
    assert abs(brf.value - 0.5 * gap.value) < 3 * math.hypot(brf.se, 0.5 * gap.se), (brf, gap)


def test_cli_flat_dem_zero_density_is_the_soil(tmp_path, capsys):
    dem = _tif(tmp_path / "flat.tif", np.zeros((9, 9)), from_origin(500000.0, 4000000.0, 1.0, 1.0))
    assert cli.main(["canopy", "--plant", "bush", "--density", "0", "--dem", dem, "--soil", "0.31",
                     "--spp", "2000", "--zenith", "0,45", "--seed", "1"]) == 0
    head, rows = _table(capsys.readouterr().out)
    assert head == ["sun_zenith", "brf", "se", "single", "single_se", "multiple", "multiple_se"]
    for r in rows:
        assert (r["brf"], r["single"], r["multiple"]) == (0.31, 0.31, 0.0)


def test_cli_default_run_writes_the_mesh_and_a_table(tmp_path, capsys):
    y, x = np.mgrid[0:21, 0:21]
    dem = _tif(tmp_path / "hills.tif", 0.4 * np.sin(x / 4.0) + 0.3 * np.cos(y / 3.0),
               from_origin(500000.0, 4000000.0, 1.0, 1.0))
    out = tmp_path / "stand.ply"
    assert cli.main(["canopy", "--plant", "bush", "--density", "0.05", "--dem", dem, str(out), "--seed", "7"]) == 0
    text = capsys.readouterr().out
    assert "20 bush plants" in text and out.stat().st_size > 0
    head, rows = _table(text)
    assert [r["sun_zenith"] for r in rows] == [0, 15, 30, 45, 60, 75]
    for r in rows:
        assert all(0 < r[k] < 1 for k in ("brf", "single", "multiple"))
        assert 0 < r["se"] < 0.01
        assert r["single"] + r["multiple"] == pytest.approx(r["brf"], abs=2e-6)  # printed to 6 decimals
    # the table does not depend on the thread count
    assert cli.main(["canopy", "--plant", "bush", "--density", "0.05", "--dem", dem, "--seed", "7", "--spp", "3000",
                     "--zenith", "30", "--n-threads", "1"]) == 0
    one = capsys.readouterr().out
    assert cli.main(["canopy", "--plant", "bush", "--density", "0.05", "--dem", dem, "--seed", "7", "--spp", "3000",
                     "--zenith", "30", "--n-threads", "2"]) == 0
    assert capsys.readouterr().out == one


def test_cli_geographic_dem_is_in_metres(tmp_path, capsys):
    # 1 arcsecond cells at 44 N: about 30.9 m north-south and 30.9 cos(44) = 22.2 m east-west
    dem = _tif(tmp_path / "geo.tif", np.zeros((11, 11)), from_origin(7.0, 44.003, 1 / 3600, 1 / 3600), "EPSG:4326")
    assert cli.main(["canopy", "--plant", "herb", "--density", "0.001", "--dem", dem, "--spp", "1000",
                     "--zenith", "30", "--seed", "1"]) == 0
    head = capsys.readouterr().out.splitlines()[0]
    ns = 10 * 1852.0 * 60 / 3600  # a minute of latitude is about a nautical mile
    ew = ns * math.cos(math.radians(44.0015))
    w = float(head.split("ground ")[1].split(" m x ")[0])
    h = float(head.split(" m x ")[1].split(" m")[0])
    assert w == pytest.approx(ew, rel=0.01) and h == pytest.approx(ns, rel=0.01), head


@pytest.mark.parametrize("argv, option", [
    (["--plant", "tree", "--density", "1"], "--plant"),
    (["--plant", "bush", "--density", "-1"], "--density"),
    (["--plant", "bush", "--density", "nan"], "--density"),
    (["--plant", "bush"], "--density"),
    (["--plant", "bush", "--density", "1", "--lai", "2"], "--lai"),
    (["--plant", "bush", "--density", "1", "--leaf", "0.7,0.5"], "--leaf"),
    (["--plant", "bush", "--density", "1", "--leaf", "0.5"], "--leaf"),
    (["--plant", "bush", "--density", "1", "--soil", "1.5"], "--soil"),
    (["--plant", "bush", "--density", "1", "--bark", "-0.1"], "--bark"),
    (["--plant", "bush", "--density", "1", "--plant-scale", "0"], "--plant-scale"),
    (["--plant", "bush", "--density", "1", "--spp", "0"], "--spp"),
    (["--plant", "bush", "--density", "1", "--max-depth", "0"], "--max-depth"),
    (["--plant", "bush", "--density", "1", "--zenith", "95"], "zenith"),
    (["--plant", "bush", "--density", "1000"], "--density"),
    (["--density", "1"], "--density"),
    (["--lai", "1"], "--leaf-radius"),
])
def test_bad_options_name_the_option(tmp_path, argv, option):
    dem = _tif(tmp_path / "d.tif", np.zeros((30, 30)), from_origin(500000.0, 4000000.0, 2.0, 2.0))
    if "--plant" in argv and "--density" in argv:
        argv = [*argv, "--dem", dem]
    args = _args(argv)
    with pytest.raises(ValueError, match=f"^{option}:"):
        args.func(args)


def test_dem_errors_name_the_dem(tmp_path):
    z = np.zeros((6, 6))
    z[2, 3] = -9999.0
    with rasterio.open(tmp_path / "nd.tif", "w", driver="GTiff", height=6, width=6, count=1, dtype="float64",
                       crs="EPSG:32631", transform=from_origin(0.0, 6.0, 1.0, 1.0), nodata=-9999.0) as d:
        d.write(z, 1)
    args = _args(["--plant", "bush", "--density", "0.1", "--dem", str(tmp_path / "nd.tif")])
    with pytest.raises(ValueError, match="^--dem:.*nodata"):
        args.func(args)
    np.save(tmp_path / "z.npy", np.zeros((6, 6)))
    args = _args(["--plant", "bush", "--density", "0.1", "--dem", str(tmp_path / "z.npy")])
    with pytest.raises(ValueError, match="^--cell-size:"):
        args.func(args)


@pytest.mark.parametrize("kwargs, param, exc", [
    (dict(plant="oak"), "plant", ValueError), (dict(density=-0.1), "density", ValueError),
    (dict(density="x"), "density", TypeError), (dict(dem=np.zeros(5)), "dem", ValueError),
    (dict(dem=np.full((3, 3), np.nan)), "dem", ValueError), (dict(cell_size=0.0), "cell_size", ValueError),
    (dict(cell_size=(1.0, 2.0, 3.0)), "cell_size", TypeError), (dict(scale=-1.0), "scale", ValueError),
    (dict(leaf=Lambertian(0.5)), "leaf", TypeError), (dict(bark=BiLambertian(0.1, 0.1)), "bark", TypeError),
    (dict(soil="dirt"), "soil", TypeError),
])
def test_api_errors_name_the_parameter(kwargs, param, exc):
    base = dict(plant="bush", density=0.01, dem=np.zeros((5, 5)))
    with pytest.raises(exc, match=f"^{param}:"):
        plant_stand(**{**base, **kwargs})
