"""SAR radiometric scale: ``fractal_transform(scale=...)`` and ``fractalgeo
transform --scale``. Linear intensity is detected with a warning naming the
option, and ``--scale linear`` on linear intensity gives the map of the API
on the dB image."""
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main
from fractalgeo_rs.transform._api import looks_linear

W = 17


@pytest.fixture(scope="module")
def vv():
    db, _ = fg.data.sentinel1_vv_db()
    db = np.asarray(db[:160, :160], dtype=np.float64)
    return db, 10.0 ** (db / 10.0)


def test_linear_intensity_is_detected_and_db_is_not(vv):
    db, lin = vv
    assert looks_linear(lin)
    assert not looks_linear(db)
    for name in ("srtm_alps", "srtm_po_plain"):  # DEMs: positive, no heavy tail
        assert not looks_linear(getattr(fg.data, name)()[0])
    with pytest.warns(UserWarning, match="scale='linear'"):
        fg.fractal_transform(lin, W, method="variogram")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fg.fractal_transform(lin, W, method="variogram", scale="db")  # said to be on a log scale: no warning


@pytest.mark.parametrize("method", ["mass", "variogram"])
def test_api_scale_linear_equals_db(vv, method):
    db, lin = vv
    ref = fg.fractal_transform(db, W, method=method)
    got = fg.fractal_transform(lin, W, method=method, scale="linear")
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-5)
    amp = fg.fractal_transform(np.sqrt(lin), W, method=method, scale="amplitude")
    np.testing.assert_allclose(amp, ref, rtol=0, atol=1e-5)


def test_cli_warns_on_linear_and_scale_linear_equals_the_api_on_db(vv, tmp_path, capsys):
    db, lin = vv
    np.save(tmp_path / "lin.npy", lin)
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # the CLI prints it on one line
        assert main(["transform", str(tmp_path / "lin.npy"), str(tmp_path / "a.npy"), "--window", str(W)]) == 0
    err = capsys.readouterr().err
    assert "--scale linear" in err and "warning" in err
    assert main(["transform", str(tmp_path / "lin.npy"), str(tmp_path / "b.npy"), "--window", str(W),
                 "--scale", "linear"]) == 0
    err = capsys.readouterr().err
    assert "--scale" not in err
    ref = fg.fractal_transform(db, W, method="mass")
    np.testing.assert_allclose(np.load(tmp_path / "b.npy"), ref, rtol=0, atol=1e-5)


def test_scale_is_checked():
    with pytest.raises(ValueError, match="scale"):
        fg.fractal_transform(np.ones((20, 20)), 5, scale="log")
