"""Every map method's output on fixed small inputs is bit-identical to the
output recorded (``tests/data/map_hashes.json``, by
``tests/data/make_map_hashes.py`` on the code of commit ec36600) before the
kernels were moved onto the shared moving-window driver.

The inputs are generated here with numpy only (no package code), so a change
in the synthesis code cannot move them.

Exception: the GLS entries (``gls/*`` and ``gls_aniso/*``) were recorded
again when the GLS model changed on purpose (every filter weighted, with the
Welch-Satterthwaite excess variance of each log variation; issue 13), from
the code of that change; every other entry is still that of ec36600.
"""
import hashlib
import json
import pathlib

import numpy as np
import pytest

import fractalgeo_rs as fg

HASHES = pathlib.Path(__file__).with_name("data") / "map_hashes.json"


def _rough() -> np.ndarray:
    """A seeded rough surface 96 x 80 (random walk in both directions plus noise)."""
    rng = np.random.default_rng(20261201)
    z = np.cumsum(np.cumsum(rng.standard_normal((96, 80)), axis=0), axis=1) / 40.0
    return z + 0.5 * rng.standard_normal((96, 80))


def _plane() -> np.ndarray:
    i, j = np.mgrid[0:64, 0:72]
    return 0.3 * i + 0.7 * j + 1.0


def _holes() -> np.ndarray:
    z = _rough()[:72, :64].copy()
    z[10:14, 20:30] = np.nan
    z[::7, ::5] = np.nan
    z[50:, :6] = np.nan
    return z


INPUTS = {"rough": _rough, "plane": _plane, "holes": _holes}

# method -> keyword options (explicit, so a change of a default does not move them)
METHODS = {
    "mass": dict(method="mass", box_sizes=[3, 5, 7], z_scale=0.5),
    "variogram": dict(method="variogram", lags=[1, 2, 3]),
    "madogram": dict(method="madogram", lags=[1, 2]),
    "square": dict(method="square", lags=[1, 2]),
    "dbc": dict(method="dbc", box_sizes=[2, 3, 4], z_scale=0.5),
    "dbc_count": dict(method="dbc", box_sizes=[2, 3, 4], z_scale=0.5, edge_blocks="count"),
    "blanket": dict(method="blanket", epsilons=[1, 2, 3], z_scale=0.5),
    "gls": dict(method="gls", dilations=2),
    "gls_aniso": dict(method="gls", dilations=2, anisotropy=True),
    "whittle": dict(method="whittle"),
}
# (window, step) pairs (the GLS filters at dilations 2 need 13 pixels or more)
LAYOUTS = [(9, 1), (15, 3)]
GLS_LAYOUTS = [(13, 1), (15, 3)]


def _cases() -> dict:
    cases = {}
    for inp in INPUTS:
        for m in METHODS:
            for w, s in GLS_LAYOUTS if m.startswith("gls") else LAYOUTS:
                if m == "whittle" and (s == 1 or inp == "plane"):
                    continue  # one FFT per pixel: strided only; a plane has nothing to fit
                cases[f"{m}/{inp}/w{w}/s{s}"] = (m, inp, w, s)
        for w in (9, 15):
            cases[f"lacunarity/{inp}/w{w}"] = ("lacunarity", inp, w, 1)
    return cases


CASES = _cases()


def compute(name: str) -> np.ndarray:
    m, inp, w, s = CASES[name]
    z = INPUTS[inp]()
    if m == "lacunarity":
        return fg.lacunarity_map(np.abs(z), w, box_sizes=[1, 2, 3], n_threads=2)
    return fg.fractal_transform(z, w, step=s, return_fit=True, n_threads=2, **METHODS[m])


def _digest(a) -> str:
    return hashlib.sha256(np.ascontiguousarray(a, dtype=np.float64).tobytes()).hexdigest()


@pytest.fixture(scope="module")
def stored() -> dict:
    return json.loads(HASHES.read_text())["hashes"]


def test_every_case_is_stored(stored):
    assert set(stored) == set(CASES)


@pytest.mark.parametrize("name", sorted(CASES))
def test_map_is_bit_identical(name, stored):
    got = compute(name)
    assert np.isfinite(got).any(), name  # a hash of an all-NaN map would prove little
    assert _digest(got) == stored[name], f"{name}: output changed since commit ec36600"
