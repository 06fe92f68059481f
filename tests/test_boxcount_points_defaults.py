"""Default box sizes and lattices of ``box_counting_points`` on chaos-game
samples of exact self-similar sets (dimension from Moran's equation)."""
import math
import warnings

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs.lsystem import IFS

SETS = ("sierpinski_triangle", "sierpinski_carpet", "koch_curve", "vicsek")


@pytest.mark.parametrize("name", SETS)
@pytest.mark.parametrize("seed", [1, 2])
def test_chaos_game_samples_within_0_02(name, seed):
    ifs = IFS.preset(name)
    pts = ifs.chaos_game(100_000, seed=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit = fg.box_counting_points(pts)
    assert abs(fit.dimension - ifs.dimension) <= 0.02, (fit.dimension, ifs.dimension, fit.extra["lattice"])
    assert fit.extra["base"] in (2, 3) and "undersampled" not in fit.flags
    # the smallest fitted boxes hold at least 20 points on average
    assert pts.shape[0] / fit.extra["counts"]["aligned"][-1] >= 20


def test_rotated_and_scaled_sample_gives_the_same_dimension():
    pts = IFS.preset("vicsek").chaos_game(100_000, seed=3)
    a = math.radians(27.0)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    fit = fg.box_counting_points(1e3 * pts @ rot.T + 5.0)
    assert abs(fit.dimension - math.log(5) / math.log(3)) <= 0.03


def test_few_points_are_flagged_undersampled():
    pts = IFS.preset("sierpinski_carpet").chaos_game(300, seed=1)
    with pytest.warns(fg.FractalRangeWarning, match="too few"):
        fit = fg.box_counting_points(pts)
    assert "undersampled" in fit.flags


def test_given_sizes_keep_the_old_path():
    square = np.random.default_rng(0).random((100_000, 2))
    fit = fg.box_counting_points(square, box_sizes=[1 / 4, 1 / 8, 1 / 16, 1 / 32])
    assert abs(fit.dimension - 2.0) < 0.01
    assert "base" not in fit.extra


@pytest.mark.parametrize("box_sizes", [None, [0.1, 0.2, 0.4]])
def test_saturated_counts_are_not_an_estimate(box_sizes):
    # two points: N(s) = 2 at every size, a perfect line of slope 0 that measures nothing
    with pytest.warns(fg.FractalRangeWarning, match="distinct box count"):
        fit = fg.box_counting_points(np.array([[0, 0], [1, 1.0]]), box_sizes=box_sizes)
    assert not fit.valid and "unresolved" in fit.flags
    assert np.isnan(fit.ci95[0]) and np.isnan(fit.ci95[1]) and np.isnan(fit.stderr)


@pytest.mark.parametrize("pts", [np.zeros((1, 2)), np.ones((5, 3))])
@pytest.mark.parametrize("box_sizes", [None, [0.1, 0.2, 0.4]])
def test_fewer_than_two_distinct_points_is_a_value_error(pts, box_sizes):
    with pytest.raises(ValueError, match="^points: need at least 2 distinct points"):
        fg.box_counting_points(pts, box_sizes=box_sizes)
