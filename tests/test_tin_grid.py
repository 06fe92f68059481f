"""Gridding of scattered values: exact on linear functions, the same as
scipy's barycentric griddata and k-d tree nearest neighbours, NaN outside
the hull, interpolation at data points, bounded by the data, bad input."""
import numpy as np
import pytest
from scipy.interpolate import griddata
from scipy.spatial import Delaunay, cKDTree

from fractalgeo_rs.tin import grid_from_points


@pytest.fixture(scope="module")
def scattered():
    rng = np.random.default_rng(11)
    p = rng.uniform(0, 50, (2000, 2))
    v = np.sin(p[:, 0] / 7.0) + np.cos(p[:, 1] / 5.0)
    return p, v


def nodes(shape, transform=None):
    rows, cols = shape
    rr, cc = np.mgrid[0:rows, 0:cols]
    if transform is None:  # the default: unit cells, north up, origin at the lower left
        transform = (0.0, 1.0, 0.0, float(rows), 0.0, -1.0)
    c, a, b, f, d, e = transform  # GDAL order
    return c + a * (cc + 0.5) + b * (rr + 0.5), f + d * (cc + 0.5) + e * (rr + 0.5)


@pytest.mark.parametrize("method", ["natural", "natural_c1", "linear"])
def test_linear_functions_are_exact(method):
    rng = np.random.default_rng(1)
    p = np.vstack([[0, 0], [40, 0], [0, 30], [40, 30], rng.uniform([0, 0], [40, 30], (300, 2))])
    v = 5.0 - 0.3 * p[:, 0] + 0.7 * p[:, 1]
    g = grid_from_points(p, v, (30, 40), method=method)
    x, y = nodes((30, 40))
    np.testing.assert_allclose(g, 5.0 - 0.3 * x + 0.7 * y, atol=1e-9)


def test_linear_matches_scipy_griddata(scattered):
    p, v = scattered
    tr = (0.0, 0.5, 0.0, 50.0, 0.0, -0.5)  # GDAL, north up, covers [0, 50]^2
    g = grid_from_points(p, v, (100, 100), tr, method="linear")
    x, y = nodes((100, 100), tr)
    ref = griddata(p, v, (x, y), method="linear")
    np.testing.assert_array_equal(np.isnan(g), np.isnan(ref))  # NaN outside the hull
    assert np.isnan(g).sum() > 0
    np.testing.assert_allclose(g, ref, atol=1e-12, equal_nan=True)


def test_nearest_and_hull_mask(scattered):
    p, v = scattered
    tr = (-5.0, 0.6, 0.0, 55.0, 0.0, -0.6)
    g = grid_from_points(p, v, (100, 100), tr, method="nearest")
    x, y = nodes((100, 100), tr)
    q = np.column_stack([x.ravel(), y.ravel()])
    inside = Delaunay(p).find_simplex(q) >= 0
    _, k = cKDTree(p).query(q)
    gf = g.ravel()
    assert np.all(np.isnan(gf[~inside]))
    np.testing.assert_array_equal(gf[inside], v[k[inside]])


@pytest.mark.parametrize("method", ["natural", "natural_c1"])
def test_natural_neighbour_interpolates_and_is_bounded(method):
    # data on integer points, queried on the same lattice (values hit exactly)
    rng = np.random.default_rng(2)
    yy, xx = np.mgrid[0:20, 0:20]
    p = np.column_stack([xx.ravel(), yy.ravel()]).astype(float)
    keep = rng.uniform(size=len(p)) < 0.5
    keep[[0, 19, 380, 399]] = True
    p = p[keep]
    v = rng.normal(size=len(p))
    on_lattice = (-0.5, 1.0, 0.0, -0.5, 0.0, 1.0)  # cell centres at x = col, y = row
    g = grid_from_points(p, v, (20, 20), on_lattice, method=method)
    np.testing.assert_allclose(g[p[:, 1].astype(int), p[:, 0].astype(int)], v, atol=1e-12)
    if method == "natural":  # Sibson weights are a convex combination
        assert np.nanmin(g) >= v.min() - 1e-12 and np.nanmax(g) <= v.max() + 1e-12
    assert not np.isnan(g).any()  # the four corners make the hull the whole grid


def test_natural_is_smoother_than_linear(scattered):
    # Sibson's interpolant has no creases: its second differences are smaller than the
    # piecewise-linear one's on a smooth field
    p, v = scattered
    tr = (10.0, 0.1, 0.0, 40.0, 0.0, -0.1)
    gn = grid_from_points(p, v, (300, 300), tr, method="natural")
    gl = grid_from_points(p, v, (300, 300), tr, method="linear")
    def d2(g):
        return np.abs(np.diff(g, 2, axis=1)).mean()

    assert d2(gn) < d2(gl)


def test_identical_for_any_n_threads_and_input_kept(scattered):
    p, v = scattered
    p0, v0 = p.copy(), v.copy()
    for method in ["natural", "natural_c1", "linear", "nearest"]:
        ref = grid_from_points(p, v, (64, 64), (0, 0.8, 0, 50, 0, -0.8), method=method, n_threads=1)
        for n in (2, 3):
            g = grid_from_points(p, v, (64, 64), (0, 0.8, 0, 50, 0, -0.8), method=method, n_threads=n)
            np.testing.assert_array_equal(g, ref)
    np.testing.assert_array_equal(p, p0)
    np.testing.assert_array_equal(v, v0)


def test_duplicates_take_the_first_value():
    p = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0], [2.0, 2.0]])
    v = np.array([0.0, 0.0, 0.0, 1.0, 100.0])
    g = grid_from_points(p, v, (3, 3), (-0.5, 1.0, 0.0, -0.5, 0.0, 1.0), method="linear")
    assert g[2, 2] == 1.0


@pytest.mark.parametrize(
    "args, kwargs, exc, start",
    [
        ((np.zeros((3, 4)), np.zeros(3), (2, 2)), {}, ValueError, "points"),
        ((np.eye(3)[:, :2], np.zeros(2), (2, 2)), {}, ValueError, "values"),
        ((np.eye(3)[:, :2], np.array([0, np.nan, 1]), (2, 2)), {}, ValueError, "values"),
        ((np.eye(3)[:, :2], np.array(["a", "b", "c"]), (2, 2)), {}, TypeError, "values"),
        ((np.eye(3)[:, :2], np.zeros(3), (2, 0)), {}, ValueError, "shape"),
        ((np.eye(3)[:, :2], np.zeros(3), 5), {}, TypeError, "shape"),
        ((np.eye(3)[:, :2], np.zeros(3), (2, 2)), {"method": "cubic"}, ValueError, "method"),
        ((np.array([[0.0, 0], [1, 1], [2, 2]]), np.zeros(3), (2, 2)), {}, ValueError, "points"),
        ((np.array([[0.0, 0], [1, np.inf], [2, 0]]), np.zeros(3), (2, 2)), {}, ValueError, "points"),
        ((np.eye(3)[:, :2], np.zeros(3), (2, 2), (0, 0, 0, 0, 0, 0)), {}, ValueError, "transform"),
        ((np.eye(3)[:, :2], np.zeros(3), (2, 2)), {"n_threads": -1}, ValueError, "n_threads"),
    ],
)
def test_bad_input(args, kwargs, exc, start):
    with pytest.raises(exc) as info:
        grid_from_points(*args, **kwargs)
    assert str(info.value).startswith(start)


def test_default_grid_is_cell_centres_north_up():
    # cell (row, col) of the default grid is centred at x = col + 0.5, y = rows - row - 0.5
    p = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 3.0], [4.0, 3.0]])
    v = 10.0 * p[:, 0] + p[:, 1]
    g = grid_from_points(p, v, (3, 4), method="linear")
    assert g[0, 0] == pytest.approx(10.0 * 0.5 + 2.5)
    assert g[2, 3] == pytest.approx(10.0 * 3.5 + 0.5)
    g2 = grid_from_points(2.0 * p, v, (3, 4), cell_size=2.0, method="linear")
    np.testing.assert_allclose(g2, g, atol=1e-12)
    with pytest.raises(ValueError, match="^cell_size"):
        grid_from_points(p, v, (3, 4), (0, 1, 0, 3, 0, -1), cell_size=2.0)
