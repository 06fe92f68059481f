"""Progress in the CLI: on by default when stderr is a terminal, forced with
--progress, off with --no-progress; the map is the same either way."""

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main


@pytest.fixture()
def scene(tmp_path):
    p = tmp_path / "z.npy"
    np.save(p, fg.fbm_surface((64, 48), 0.6, seed=2, method="spectral"))
    return p


def _transform(tmp_path, scene, capsys, *extra, name="d.npy"):
    out = tmp_path / name
    code = main(["transform", str(scene), str(out), "--window", "9", "--method", "variogram", *extra])
    cap = capsys.readouterr()
    return code, np.load(out), cap.err


def test_transform_progress_flags(tmp_path, scene, capsys):
    pytest.importorskip("tqdm")
    code, quiet, err = _transform(tmp_path, scene, capsys, name="a.npy")  # stderr is not a terminal here
    assert code == 0 and "fractal_transform" not in err
    code, shown, err = _transform(tmp_path, scene, capsys, "--progress", name="b.npy")
    assert code == 0 and "fractal_transform (variogram)" in err
    code, off, err = _transform(tmp_path, scene, capsys, "--no-progress", name="c.npy")
    assert code == 0 and "fractal_transform" not in err
    np.testing.assert_array_equal(quiet, shown)
    np.testing.assert_array_equal(quiet, off)


def test_transform_progress_on_at_a_terminal(tmp_path, scene, capsys, monkeypatch):
    pytest.importorskip("tqdm")
    from fractalgeo_rs import _progress

    monkeypatch.setattr(_progress.sys.stderr, "isatty", lambda: True, raising=False)
    assert _progress.resolve(None, cli=True)
    code, _, err = _transform(tmp_path, scene, capsys)
    assert code == 0 and "fractal_transform (variogram)" in err


def test_transform_chunks_progress_uses_dask_bar(tmp_path, scene, capsys):
    pytest.importorskip("dask")
    code, lazy, err = _transform(tmp_path, scene, capsys, "--chunks", "32", "--progress", name="k.npy")
    assert code == 0 and "Completed" in err
    code, mem, _ = _transform(tmp_path, scene, capsys, name="m.npy")
    np.testing.assert_allclose(lazy, mem, equal_nan=True)


def _sar(tmp_path, scene, capsys, *extra, name="s.npy"):
    out = tmp_path / name
    code = main(["sar", str(scene), str(out), "--cell-size", "10", "--incidence", "35", "--looks", "4",
                 "--seed", "3", *extra])
    cap = capsys.readouterr()
    return code, np.load(out), cap.err


def test_sar_progress_flags(tmp_path, scene, capsys):
    pytest.importorskip("tqdm")
    code, quiet, err = _sar(tmp_path, scene, capsys, name="a.npy")  # stderr is not a terminal here
    assert code == 0 and "radar.simulate" not in err
    code, shown, err = _sar(tmp_path, scene, capsys, "--progress", name="b.npy")
    assert code == 0 and "radar.simulate" in err
    code, off, err = _sar(tmp_path, scene, capsys, "--no-progress", name="c.npy")
    assert code == 0 and "radar.simulate" not in err
    np.testing.assert_array_equal(quiet, shown)
    np.testing.assert_array_equal(quiet, off)


def test_sar_progress_on_at_a_terminal(tmp_path, scene, capsys, monkeypatch):
    pytest.importorskip("tqdm")
    from fractalgeo_rs import _progress

    monkeypatch.setattr(_progress.sys.stderr, "isatty", lambda: True, raising=False)
    code, _, err = _sar(tmp_path, scene, capsys, "--look-azimuth", "0")
    assert code == 0 and "radar.simulate" in err
