"""Degenerate data: too few samples, constant sets, scales without height
information raise a clear ValueError naming the parameter, never a
dimension."""
import os
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg

HERE = os.path.dirname(__file__)
CROP = os.path.join(HERE, "data", "bigtujunga_30m_crop128.npy")


@pytest.mark.parametrize("call,param", [
    (lambda: fg.blanket(np.array([[1.0, 2.0]])), "data"),  # two samples
    (lambda: fg.blanket(np.array([[1.0], [5.0]])), "data"),
    (lambda: fg.blanket(np.arange(20.0).reshape(2, 10)), "data"),  # two rows: all edge
    (lambda: fg.blanket(np.where(np.eye(5, dtype=bool), 1.0, np.nan)), "data"),  # 5 valid of 25
    (lambda: fg.minkowski(np.array([True, True])), "data"),  # two samples, default radii
    (lambda: fg.minkowski(np.array([[True, True]])), "data"),
    (lambda: fg.minkowski(np.array([[True, False]]), radii=[0.5, 1, 2, 4]), "radii"),  # straddle the extent
    (lambda: fg.minkowski(np.ones((32, 32), bool)), "data"),  # constant: the set fills the array
    (lambda: fg.minkowski(np.ones((64, 64), bool), radii=[1, 2, 4]), "data"),
    (lambda: fg.differential_box_counting(np.load(CROP), box_sizes=[1, 2, 4]), "box_sizes"),
    (lambda: fg.differential_box_counting(np.load(CROP), box_sizes=[1, 4, 8, 16]), "box_sizes"),
])
def test_degenerate_inputs_raise_naming_the_parameter(call, param):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no dimension with a warning first
        with pytest.raises(ValueError, match=f"^{param}:"):
            call()


def test_the_valid_neighbours_still_work():
    # the smallest accepted inputs give dimensions in their domains
    i, j = np.indices((3, 3))
    assert fg.blanket(0.5 * i + 0.25 * j).dimension == pytest.approx(2.0)
    point = np.zeros((41, 41), bool)
    point[20, 20] = True
    assert fg.minkowski(point, radii=[4, 8, 16]).dimension == pytest.approx(0.0, abs=0.05)  # a point: D = 0
    alps, _ = fg.data.srtm_alps()
    d = fg.differential_box_counting(alps, box_sizes=[2, 4, 8, 16, 32, 64])  # the default sizes, given
    assert 2.0 <= d.dimension <= 3.0 and d.valid
