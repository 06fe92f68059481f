"""``fractalgeo dimension`` offers every estimator of the registry: each
``--method`` on a synthetic fBm surface (D = 2.3) and on an exact fractal set
(the Sierpinski carpet, D = log 8 / log 3) gives the answer, a warning that
names the reason, or a one-line error saying which input the method needs."""
import math
import re

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.cli import main
from fractalgeo_rs.dimension import METHODS
from fractalgeo_rs.dimension._cli import DEFAULT_METHOD, SET_METHODS, ANY_METHODS

H = 0.7
D_SURFACE = 3 - H
D_CARPET = math.log(8) / math.log(3)
#: estimators docs/accuracy.md measures as biased on fBm surfaces (bias of D
#: 0.1-0.8 at 128 x 128): their answer must be a surface dimension, in [2, 3]
BIASED = {"dbc", "blanket", "affine", "wavelet", "spectral", "mass"}
#: profile-only methods: on a surface, a one-line error naming the alternatives
PROFILE_ONLY = {"variation", "scale_space", "higuchi"}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("dim")
    surf = d / "surface.npy"
    np.save(surf, fg.fbm_surface((128, 128), H, seed=11))
    i, j = np.indices((243, 243))
    carpet = np.ones((243, 243), dtype=np.uint8)
    for k in range(5):
        carpet[((i // 3**k) % 3 == 1) & ((j // 3**k) % 3 == 1)] = 0
    setp = d / "carpet.npy"
    np.save(setp, carpet)
    small = d / "small.npy"  # the exact likelihood is O(n^3): 32 x 32
    np.save(small, fg.fbm_surface((32, 32), H, seed=4))
    prof = d / "profile.npy"
    np.save(prof, fg.fbm(4096, H, seed=2))
    return {"surface": surf, "set": setp, "profile": prof, "small": small}


def _d(out):
    return float(re.search(r"^D = (\S+?),", out, re.M).group(1))


@pytest.mark.parametrize("method", list(METHODS))
def test_every_method_on_a_surface(files, method, capsys):
    code = main(["dimension", str(files["small" if method == "mle" else "surface"]), "--method", method])
    out, err = capsys.readouterr()
    if method in SET_METHODS:
        assert code == 1 and err.count("\n") == 1 and f"--method {method}" in err and "--threshold" in err, err
        return
    if method in PROFILE_ONLY:
        assert code == 1 and err.count("\n") == 1 and f"--method {method}: estimates the dimension of a " \
            "profile and the input is a surface; use --method" in err, err
        return
    assert code == 0, err
    d = _d(out)
    assert "fitted scales:" in out
    if "warning:" in err:  # outside the valid domain: the reason is given
        assert len(err.split("warning:")[1].strip()) > 20
    elif method in BIASED:
        assert 2.0 <= d <= 3.0, (method, d)
    else:
        assert abs(d - D_SURFACE) < (0.15 if method == "mle" else 0.06), (method, d)


@pytest.mark.parametrize("method", list(METHODS))
def test_every_method_on_a_binary_set(files, method, capsys):
    code = main(["dimension", str(files["set"]), "--method", method])
    out, err = capsys.readouterr()
    if method not in SET_METHODS + ANY_METHODS:
        assert code == 1 and err.count("\n") == 1 and f"--method {method}" in err and "binary set" in err, err
        return
    assert code == 0, err
    d = _d(out)
    if "warning:" not in err:
        assert abs(d - D_CARPET) < 0.1, (method, d)


@pytest.mark.parametrize("kind", ["surface", "set", "profile"])
def test_default_method_per_input_kind(files, kind, capsys):
    assert main(["dimension", str(files[kind])]) == 0
    out = capsys.readouterr().out
    assert f"method: {DEFAULT_METHOD[kind]} (the default for a {kind}" in out
    truth = {"surface": D_SURFACE, "set": D_CARPET, "profile": 2 - H}[kind]
    assert abs(_d(out) - truth) < 0.05, (kind, out)


def test_default_surface_method_is_in_domain_on_the_bundled_dems(tmp_path, capsys):
    for name in ("srtm_alps", "srtm_po_plain"):
        dem, _ = getattr(fg.data, name)()
        np.save(tmp_path / "d.npy", dem)
        assert main(["dimension", str(tmp_path / "d.npy")]) == 0
        out, err = capsys.readouterr()
        assert "warning" not in err, (name, err)
        assert 2.0 < _d(out) < 3.0


def test_option_a_method_does_not_take_is_named(files, capsys):
    assert main(["dimension", str(files["surface"]), "--method", "whittle", "--box-sizes", "2,4"]) == 1
    err = capsys.readouterr().err
    assert err.strip() == "fractalgeo dimension: error: --box-sizes: not an option of --method whittle"
