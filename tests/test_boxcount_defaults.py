"""Default box sizes and lattice of ``box_counting`` on cropped, offset and
padded exact fractals (docs/boxcounting.md), checked against the
constructions and against a plain-numpy box counter (tests/fractals.py)."""
from __future__ import annotations

import itertools

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractals import numpy_box_counts, sierpinski_carpet, sierpinski_triangle, triadic_koch_curve

LN = np.log


def vicsek(level: int) -> np.ndarray:
    a = np.ones((1, 1), dtype=bool)
    for _ in range(level):
        z = np.zeros_like(a)
        a = np.block([[z, a, z], [a, a, a], [z, a, z]])
    return a


def _variants(a):
    n = a.shape[0]
    m = int(0.9 * n)
    return {
        "whole": a,
        "cropped to 90 %": a[:m, :m],
        "offset (37, 11)": np.pad(a, ((37, 0), (11, 0)))[:n, :n],
        "padded by 100": np.pad(a, 100),
    }


SETS = {
    "triangle 1024": (lambda: sierpinski_triangle(10), LN(3) / LN(2)),
    "carpet 729": (lambda: sierpinski_carpet(6), LN(8) / LN(3)),
    "vicsek 729": (lambda: vicsek(6), LN(5) / LN(3)),
}


@pytest.mark.parametrize("name", list(SETS))
def test_cropped_offset_padded_lattice_sets_are_exact(name):
    make, dim = SETS[name]
    for variant, mask in _variants(make()).items():
        fit = fg.box_counting(mask)
        # the set follows its own lattice: the edge-corrected counts are a
        # power law to rounding, so D is exact
        assert fit.dimension == pytest.approx(dim, abs=1e-9), (name, variant, fit.scales)
        assert fit.extra["lattice"] == "aligned"
        assert fit.extra["base"] == (2 if name.startswith("triangle") else 3)


@pytest.mark.parametrize("width", [500, 1000, 2000])
def test_rasterised_koch_curve_within_0_02(width):
    fit = fg.box_counting(triadic_koch_curve(7, width))
    assert abs(fit.dimension - LN(4) / LN(3)) <= 0.02, fit
    assert fit.scales[-1] <= width / 4


@pytest.mark.parametrize("shape", [(613, 500), (1, 777), (37, 100), (60, 61, 59)])
def test_filled_boxes_of_any_extent_have_their_dimension_exactly(shape):
    # inside boxes floor(E/s) per axis, fraction prod(floor(E/s) s / E):
    # N = prod(E) / s^d exactly, so D = d (the number of axes longer than 1)
    fit = fg.box_counting(np.ones(shape, bool))
    d = sum(n > 1 for n in shape)
    assert fit.dimension == pytest.approx(d, abs=1e-12)
    assert fit.extra["lattice"] == "aligned"


def test_aligned_counts_equal_plain_numpy_on_the_inside_boxes():
    mask = np.pad(sierpinski_carpet(5)[:200, :230], ((5, 0), (9, 3)))
    fit = fg.box_counting(mask)
    assert fit.extra["lattice"] == "aligned" and fit.extra["base"] == 3
    lo = np.argwhere(mask).min(axis=0)
    hi = np.argwhere(mask).max(axis=0) + 1
    box = mask[lo[0]:hi[0], lo[1]:hi[1]]
    for k, s in enumerate(fit.scales.astype(int)):
        m = [max(1, n // s) * s for n in box.shape]
        inside = box[: m[0], : m[1]]
        assert fit.extra["counts"][k, 0] == numpy_box_counts(inside, [s], anchor="array")[0]
        assert fit.extra["fraction"][k] == pytest.approx(inside.sum() / box.sum(), rel=1e-15)
        assert fit.measures[k] == pytest.approx(fit.extra["counts"][k, 0] / fit.extra["fraction"][k], rel=1e-15)


def test_shifted_counts_equal_plain_numpy():
    mask = triadic_koch_curve(6, 700)
    fit = fg.box_counting(mask)
    assert fit.extra["lattice"] == "shifted"
    b = fit.extra["base"]
    counts = fit.extra["counts"]
    for k, s in enumerate(fit.scales.astype(int)):
        if s == 1:
            assert np.all(counts[k] == mask.sum())
            continue
        want = [numpy_box_counts(mask, [s], shift=(j1 * s // b, j2 * s // b))[0]
                for j1, j2 in itertools.product(range(b), repeat=2)]
        assert counts[k].tolist() == want
        assert fit.measures[k] == pytest.approx(np.mean(want), rel=1e-15)


def test_default_is_translation_invariant_and_independent_of_threads():
    mask = vicsek(5)[:200, :230]
    ref = fg.box_counting(mask)
    for before in [(1, 2), (40, 7)]:
        fit = fg.box_counting(np.pad(mask, [(before[0], 13), (before[1], 0)]))
        assert np.array_equal(fit.measures, ref.measures)
        assert fit.dimension == ref.dimension
    assert fg.box_counting(mask, n_threads=1).dimension == fg.box_counting(mask, n_threads=2).dimension


def test_lattice_options_count_on_the_default_sizes():
    mask = sierpinski_carpet(5)[:200, :200]
    ref = fg.box_counting(mask)
    fit = fg.box_counting(mask, offsets=2)
    assert fit.scales.tolist() == ref.scales.tolist()
    fit = fg.box_counting(mask, anchor="array")
    assert fit.scales.tolist() == ref.scales.tolist()


def test_input_not_modified():
    mask = sierpinski_triangle(7)[:100, :90]
    before = mask.copy()
    fg.box_counting(mask)
    assert np.array_equal(mask, before)
