"""Synthetic DEMs: physical scaling."""
import math

import numpy as np
import pytest

from fractalgeo_rs.synth import expected_relief_std, synthetic_dem


def test_expected_relief_std_matches_brute_force():
    # Direct double sum over all pairs of a small grid (independent of the lag-count formula).
    rows, cols, h, cell = 7, 5, 0.6, 2.0
    ii, jj = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    p = np.column_stack([ii.ravel(), jj.ravel()]) * cell
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    want = math.sqrt(np.sum(d ** (2 * h)) / (2 * len(p) ** 2))
    assert abs(expected_relief_std((rows, cols), h, cell) - want) < 1e-12 * want


def test_expected_relief_std_strided_is_close():
    h = 0.7
    a = expected_relief_std((1030, 700), h)
    # Exact sum for the same shape by the lag formula without stride.
    i = np.arange(-1029, 1030.0)
    j = np.arange(-699, 700.0)
    w = np.einsum("i,ij,j->", 1030 - abs(i), np.hypot(i[:, None], j[None]) ** (2 * h), 700 - abs(j))
    assert abs(a / math.sqrt(w / (2 * (1030 * 700) ** 2)) - 1) < 1e-3


def test_relief_at_reference_lag():
    # Std of height differences at 300 m (10 cells of 30 m) = 100 m, over seeds.
    vals = []
    for s in range(16):
        z = synthetic_dem((96, 96), 0.7, cell_size=30.0, relief=100.0, relief_lag=300.0, seed=s)
        vals.append(0.5 * (np.mean((z[10:] - z[:-10]) ** 2) + np.mean((z[:, 10:] - z[:, :-10]) ** 2)))
    vals = np.array(vals)
    se = vals.std(ddof=1) / 4
    assert abs(vals.mean() - 100.0**2) <= 4 * se


def test_relief_as_std_and_mean():
    v = [np.var(synthetic_dem((64, 64), 0.5, cell_size=10.0, relief=50.0, mean_elevation=1000.0, seed=s))
         for s in range(64)]
    v = np.array(v)
    assert abs(v.mean() - 2500.0) <= 4 * v.std(ddof=1) / 8
    z = synthetic_dem((64, 64), 0.5, cell_size=10.0, relief=50.0, mean_elevation=1000.0, seed=1)
    assert abs(z.mean() - 1000.0) < 1e-9


def test_bad_input():
    with pytest.raises(ValueError, match="relief"):
        synthetic_dem((32, 32), 0.5, cell_size=1.0, relief=0.0)
    with pytest.raises(ValueError, match="relief_lag"):
        synthetic_dem((32, 32), 0.5, cell_size=1.0, relief=1.0, relief_lag=-1)
    with pytest.raises(ValueError, match="cell_size"):
        synthetic_dem((32, 32), 0.5, cell_size=float("nan"), relief=1.0)
    with pytest.raises(ValueError, match="hurst"):
        synthetic_dem((32, 32), 1.5, cell_size=1.0, relief=1.0)
