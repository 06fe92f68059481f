"""Progress: strips give the single-call result bit for bit; tqdm optional."""
import sys

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import _backend, _progress


def _image(shape=(70, 53), seed=3):
    z = fg.fbm_surface(shape, 0.6, seed=seed, method="spectral", sigma=4.0)
    z[5, 5] = z[40:43, 20:24] = np.nan
    return z


def test_resolve_rule(monkeypatch):
    assert _progress.resolve(None) is False  # API default: off
    assert _progress.resolve(True) is True and _progress.resolve(False) is False
    assert _progress.resolve(np.bool_(True)) is True
    with pytest.raises(TypeError, match="progress"):
        _progress.resolve("yes")

    class Tty:
        def __init__(self, tty):
            self.tty = tty

        def isatty(self):
            return self.tty

    monkeypatch.setattr(sys, "stderr", Tty(True))
    assert _progress.resolve(None, cli=True) is True  # CLI: on at a terminal
    assert _progress.resolve(False, cli=True) is False
    monkeypatch.setattr(sys, "stderr", Tty(False))
    assert _progress.resolve(None, cli=True) is False


@pytest.mark.parametrize("method,kw", [("mass", {}), ("variogram", {}), ("dbc", {}), ("blanket", {}),
                                       ("mass", {"step": 3}), ("variogram", {"step": 4, "return_fit": True}),
                                       ("whittle", {"step": 5}), ("gls", {"step": 4})])
def test_fractal_transform_strips_are_bit_identical(method, kw):
    z = _image()
    w = 9 if method != "gls" else 13
    ref = fg.fractal_transform(z, w, method=method, **kw)
    got = fg.fractal_transform(z, w, method=method, progress=True, **kw)
    for a, b in zip(np.atleast_3d(ref) if not isinstance(ref, tuple) else ref,
                    np.atleast_3d(got) if not isinstance(got, tuple) else got):
        np.testing.assert_array_equal(a, b)


def test_lacunarity_map_strips_are_bit_identical():
    z = np.abs(_image()) + 1.0
    np.testing.assert_array_equal(fg.lacunarity_map(z, 7, progress=True), fg.lacunarity_map(z, 7))


@pytest.mark.parametrize("rows", [1, 2, 5, 31, 32, 33, 97])
@pytest.mark.parametrize("boundary,depth,step", [("nan", 2, 1), ("nan", 3, 2), ("none", 1, 1)])
def test_run_raster_strips_any_height(rows, boundary, depth, step):
    # An independent windowed kernel: the sum over a (2 depth + 1)^2 window
    # of the block padded by edge replication (an edge rule of its own), on
    # the step grid, plus the global row index (locate) of every output row.
    def kernel(b, origin):
        p = np.pad(b, depth, mode="edge")
        r, c = b.shape
        s = sum(p[i:i + r, j:j + c] for i in range(2 * depth + 1) for j in range(2 * depth + 1))
        s = s[::step, ::step]
        return np.stack([s, np.broadcast_to((origin[0] + np.arange(0, r, step))[:, None], s.shape)])

    z = np.random.default_rng(rows).normal(size=(rows, 11))
    run = [_backend.run_raster(kernel, z, depth=depth, n_out=2, step=step, boundary=boundary, locate=True,
                               dtype=np.float64, progress=p) for p in (False, True)]
    for a, b in zip(*run):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(run[1][1][:, 0], np.arange(0, rows, step))


def test_missing_tqdm_means_no_bar_no_error_and_one_line(monkeypatch, capsys):
    from fractalgeo_rs import _progress

    monkeypatch.setitem(sys.modules, "tqdm", None)  # import tqdm raises ImportError
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    monkeypatch.setattr(_progress, "_told_no_tqdm", False)
    z = _image()
    np.testing.assert_array_equal(fg.fractal_transform(z, 9, progress=True), fg.fractal_transform(z, 9))
    err = capsys.readouterr().err
    assert err == _progress.NO_TQDM + "\n" and '"fractalgeo_rs[progress]"' in err
    fg.fractal_transform(z, 9, progress=True)  # said once per process
    assert capsys.readouterr().err == ""


def test_bar_is_drawn_with_tqdm(capsys):
    pytest.importorskip("tqdm")
    fg.fractal_transform(_image(), 9, method="variogram", progress=True)
    assert "fractal_transform (variogram)" in capsys.readouterr().err
    fg.fractal_transform(_image(), 9, method="variogram")  # default: off
    assert capsys.readouterr().err == ""


def test_dask_bar_context():
    assert _progress.dask_bar(False).__class__.__name__ == "nullcontext"
    pytest.importorskip("dask")
    from dask.diagnostics import ProgressBar

    assert isinstance(_progress.dask_bar(True), ProgressBar)
