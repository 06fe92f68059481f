"""IFS presets: similarity dimensions, box counting, seeds, errors."""

import math

import numpy as np
import pytest

from fractalgeo_rs.lsystem import IFS, IFS_PRESETS, ifs_preset, moran_dimension, rasterize_points


def box_dim(img, sizes):
    """Independent box count: occupied s x s blocks of the array, slope fit."""
    counts = []
    for s in sizes:
        r, c = img.shape[0] // s * s, img.shape[1] // s * s
        counts.append(img[:r, :c].reshape(r // s, s, c // s, s).any(axis=(1, 3)).sum())
    return -np.polyfit(np.log(sizes), np.log(counts), 1)[0]


EXACT = {
    "sierpinski_triangle": math.log(3) / math.log(2),
    "sierpinski_carpet": math.log(8) / math.log(3),
    "koch_curve": math.log(4) / math.log(3),
    "dragon": 2.0,
    "vicsek": math.log(5) / math.log(3),
}


@pytest.mark.parametrize("name", IFS_PRESETS)
def test_preset_similarity_dimension(name):
    f = ifs_preset(name)
    if name == "barnsley_fern":
        assert f.similarity_dimension is None and f.dimension is None
    else:
        assert f.similarity_dimension == pytest.approx(EXACT[name], abs=1e-12)
        assert f.dimension == pytest.approx(EXACT[name], abs=1e-12)
    assert f.probabilities.sum() == pytest.approx(1.0)


def test_moran_unequal_ratios():
    # 0.5^s + 0.25^s = 1  ->  0.5^s = (sqrt(5) - 1) / 2
    s = moran_dimension([0.5, 0.25])
    assert 0.5 ** s == pytest.approx((math.sqrt(5) - 1) / 2, abs=1e-12)
    with pytest.raises(ValueError, match="^ratios:"):
        moran_dimension([0.5, 1.2])


# measured |box - similarity| with this independent counter: carpet, Vicsek
# 0 (grid-aligned, exact counts), triangle 0.023; tolerances 1e-9 and 0.03
@pytest.mark.parametrize(
    "name,depth,n,bounds,sizes,tol",
    [
        ("sierpinski_carpet", 7, 729, (-1e-9, 1 - 1e-9, -1e-9, 1 - 1e-9), [3, 9, 27, 81], 1e-9),
        ("vicsek", 7, 729, (-1e-9, 1 - 1e-9, -1e-9, 1 - 1e-9), [3, 9, 27, 81], 1e-9),
        ("sierpinski_triangle", 11, 1024, (0, 1, 0, 1), [4, 8, 16, 32, 64, 128], 0.03),
    ],
)
def test_box_counting_dimension_of_presets(name, depth, n, bounds, sizes, tol):
    f = ifs_preset(name)
    img = f.rasterize(n, depth=depth, bounds=bounds)
    assert img.shape == (n, n) and img.dtype == np.uint8
    assert abs(box_dim(img, sizes) - f.dimension) < tol


def test_chaos_game_seeded_thread_independent():
    f = ifs_preset("barnsley_fern")
    a = f.chaos_game(200_000, seed=3, n_threads=1)
    b = f.chaos_game(200_000, seed=3, n_threads=2)
    assert np.array_equal(a, b) and not np.array_equal(a, f.chaos_game(200_000, seed=4))
    # the fern's maps are used in proportion to their probabilities: map 0
    # sends every point to x = 0, y in [0, 0.16 * 10]
    on_stem = np.isclose(a[:, 0], 0.0) & (a[:, 1] <= 1.6 + 1e-12)
    assert on_stem.mean() == pytest.approx(0.01, abs=0.002)
    tri = ifs_preset("sierpinski_triangle")
    img = tri.rasterize(512, n_points=400_000, seed=1, bounds=(0, 1, 0, 1))
    assert abs(box_dim(img, [4, 8, 16, 32, 64]) - tri.dimension) < 0.05


def test_custom_ifs_and_errors():
    cantor = IFS([[1 / 3, 0, 0, 1 / 3, 0, 0], [1 / 3, 0, 0, 1 / 3, 2 / 3, 0]])
    assert cantor.similarity_dimension == pytest.approx(math.log(2) / math.log(3), abs=1e-12)
    pts = cantor.iterate(6)
    assert pts.shape == (64, 2) and np.all(pts[:, 1] == 0)
    # every point is a left end of a level-6 Cantor interval: 3^6 x has digits 0 or 2
    assert set(np.rint(pts[:, 0] * 729).astype(int) % 3) <= {0, 2}
    assert rasterize_points([[0.0, 0.0], [1.0, 1.0]], (2, 2)).tolist() == [[0, 1], [1, 0]]
    with pytest.raises(ValueError, match="^maps:"):
        IFS([[1.0, 0, 0, 1.0, 0, 0]])
    with pytest.raises(ValueError, match="^maps:"):
        IFS([[0.5, 0, 0]])
    with pytest.raises(ValueError, match="^probabilities:"):
        IFS([[0.5, 0, 0, 0.5, 0, 0]], [0.0])
    with pytest.raises(ValueError, match="^name:"):
        ifs_preset("mandelbrot")
    with pytest.raises(ValueError, match="^n_points:"):
        ifs_preset("dragon").chaos_game(2**40)
    with pytest.raises(ValueError, match="^shape:"):
        rasterize_points([[0.0, 0.0]], (10**6, 10**6))
    with pytest.raises(ValueError, match="^depth:"):
        ifs_preset("sierpinski_carpet").iterate(12, max_points=1000)
