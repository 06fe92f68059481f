"""``fractalgeo render`` / ``fractalgeo brf`` options that mirror the API:
``--sky`` (Scene.render/brf_sweep ``sky=``), ``--psf`` (Scene.render
``psf=``) and the ``oren-nayar-full`` material (``OrenNayar(full=True)``).
Each CLI run equals the API call on the same DEM and seed, and differs from
the run without the option."""
import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import cli
from fractalgeo_rs.radiometry import Lambertian, OrenNayar, Scene


@pytest.fixture
def dem(tmp_path):
    z = fg.fbm_surface((8, 8), 0.5, seed=3) * 2.0
    path = tmp_path / "dem.npy"
    np.save(path, z)
    return z, str(path)


def _render(tmp_path, dem_path, *extra, name="out.npy"):
    out = tmp_path / name
    argv = ["render", dem_path, str(out), "--sun", "135", "40", "--spp", "4", "--seed", "7",
            "--cell-size", "1", "--no-progress", "--n-threads", "1", *extra]
    assert cli.main(argv) == 0
    return np.load(out)


def _api(z, material=Lambertian(0.5), **kw):
    return Scene.from_dem(z, cell_size=1.0, material=material).render(
        sun=(135.0, 40.0), spp=4, seed=7, n_threads=1, **kw)


def test_render_options_equal_the_api(tmp_path, dem, capsys):
    z, path = dem
    base = _render(tmp_path, path, name="base.npy")
    assert np.array_equal(base, _api(z).astype(base.dtype))
    cases = [
        (["--sky", "0.3"], dict(sky=0.3), {}),
        (["--psf", "gaussian:0.8"], dict(psf=("gaussian", 0.8)), {}),
        (["--material", "oren-nayar-full:0.5,0.4"], {}, dict(material=OrenNayar(0.5, 0.4, full=True))),
        (["--sky", "0.2", "--psf", "box"], dict(sky=0.2, psf="box"), {}),
    ]
    for k, (extra, kw, mat) in enumerate(cases):
        got = _render(tmp_path, path, *extra, name=f"o{k}.npy")
        want = _api(z, **mat, **kw).astype(got.dtype)
        assert np.array_equal(got, want), extra
        assert not np.array_equal(got, base), extra
    # the full Oren-Nayar model differs from the qualitative one
    qual = _render(tmp_path, path, "--material", "oren-nayar:0.5,0.4", name="q.npy")
    full = _render(tmp_path, path, "--material", "oren-nayar-full:0.5,0.4", name="f.npy")
    assert not np.array_equal(qual, full)
    assert "mean HDRF" in _sky_summary(tmp_path, path, capsys)


def _sky_summary(tmp_path, path, capsys):
    capsys.readouterr()
    _render(tmp_path, path, "--sky", "0.5", name="s.npy")
    return capsys.readouterr().out


def test_render_sky_on_a_flat_plane_is_the_closed_form(tmp_path):
    # L = rho (cos(sun zenith) + E) / pi on a flat Lambertian plane
    np.save(tmp_path / "flat.npy", np.zeros((6, 6)))
    img = _render(tmp_path, str(tmp_path / "flat.npy"), "--sky", "0.25", "--material", "lambertian:0.4")
    assert np.allclose(img, 0.4 * (np.cos(np.radians(40)) + 0.25) / np.pi, rtol=1e-5)


def test_brf_sky_reports_the_hdrf(tmp_path, dem, capsys):
    z, path = dem
    argv = ["brf", path, "--sun-zenith", "0,30,60", "--view-zenith", "0,20", "--spp", "64", "--seed", "2",
            "--cell-size", "1", "--no-progress", "--n-threads", "1"]
    capsys.readouterr()
    assert cli.main(argv) == 0
    base = capsys.readouterr().out
    assert base.splitlines()[0].split(",")[4] == "brf"
    for extra, kw, mat in ((["--sky", "0.3"], dict(sky=0.3), Lambertian(0.5)),
                           (["--material", "oren-nayar-full:0.5,0.4"], {}, OrenNayar(0.5, 0.4, full=True))):
        assert cli.main(argv + extra) == 0
        out = capsys.readouterr().out
        lines = out.splitlines()
        assert lines[0].split(",")[4] == ("hdrf" if "sky" in kw else "brf")
        sw = Scene.from_dem(z, cell_size=1.0, material=mat).brf_sweep(
            sun_zenith=[0, 30, 60], view_zenith=[0, 20], spp=64, seed=2, n_threads=1, **kw)
        got = np.array([float(r.split(",")[4]) for r in lines[1:]]).reshape(3, 2)
        assert np.allclose(got, sw.value, rtol=1e-7, atol=0), extra
        assert out != base, extra
    # a flat Lambertian plane under sun and sky: HDRF = rho
    np.save(tmp_path / "flat.npy", np.zeros((4, 4)))
    assert cli.main(["brf", str(tmp_path / "flat.npy"), "--sun-zenith", "30", "--sky", "0.5", "--spp", "32",
                     "--cell-size", "1", "--material", "lambertian:0.4", "--no-progress"]) == 0
    row = capsys.readouterr().out.splitlines()[1].split(",")
    assert abs(float(row[4]) - 0.4) < 1e-6


@pytest.mark.parametrize("command, extra, option", [
    ("render", ["--sky", "-1"], "--sky"),
    ("render", ["--sky", "abc"], "--sky"),
    ("render", ["--sky", "nan"], "--sky"),
    ("brf", ["--sky", "-0.5"], "--sky"),
    ("render", ["--psf", "gauss"], "--psf"),
    ("render", ["--psf", "gaussian:0"], "--psf"),
    ("render", ["--psf", "gaussian:x"], "--psf"),
    ("render", ["--psf", "gaussian"], "--psf"),
    ("render", ["--material", "oren-nayar-full:0.5"], "--material"),
    ("brf", ["--material", "oren-nayar-full:0.5,-1"], "--material"),
])
def test_bad_values_name_the_option(tmp_path, dem, capsys, command, extra, option):
    _, path = dem
    if command == "render":
        argv = ["render", path, str(tmp_path / "o.npy"), "--sun", "0", "30"]
    else:
        argv = ["brf", path, "--sun-zenith", "30"]
    capsys.readouterr()
    assert cli.main(argv + ["--cell-size", "1", "--spp", "2", "--no-progress", *extra]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith(f"fractalgeo {command}: error: {option}"), err
