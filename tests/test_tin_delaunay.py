"""Delaunay triangulation checked without spade: empty circumcircles (k-d
tree over all points), Euler's count, scipy's (Qhull's) triangles on points
in general position, constraint edges, degenerate inputs, bad input."""
import numpy as np
import pytest
from scipy.spatial import ConvexHull, Delaunay, cKDTree

from fractalgeo_rs.tin import delaunay


def signed_area2(p, t):
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    return (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])


def edge_set(t):
    e = np.sort(np.vstack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    return set(map(tuple, e))


def assert_empty_circumcircles(p, t):
    """No point of ``p`` strictly inside the circumcircle of any triangle of ``t``
    (points on the circle, as in cocircular sets, are allowed)."""
    # circumcentres and radii, then every point within the radius
    a, b, c = p[t[:, 0]], p[t[:, 1]], p[t[:, 2]]
    d = 2 * (a[:, 0] * (b[:, 1] - c[:, 1]) + b[:, 0] * (c[:, 1] - a[:, 1]) + c[:, 0] * (a[:, 1] - b[:, 1]))
    sa, sb, sc = (a ** 2).sum(1), (b ** 2).sum(1), (c ** 2).sum(1)
    ux = (sa * (b[:, 1] - c[:, 1]) + sb * (c[:, 1] - a[:, 1]) + sc * (a[:, 1] - b[:, 1])) / d
    uy = (sa * (c[:, 0] - b[:, 0]) + sb * (a[:, 0] - c[:, 0]) + sc * (b[:, 0] - a[:, 0])) / d
    r = np.hypot(a[:, 0] - ux, a[:, 1] - uy)
    tree = cKDTree(p)
    inside = tree.query_ball_point(np.column_stack([ux, uy]), r * (1 - 1e-9))
    for k, pts in enumerate(inside):
        assert set(pts) <= set(t[k]), f"triangle {k} has points {set(pts) - set(t[k])} in its circumcircle"


def test_empty_circumcircles_and_euler_count_on_10k_points():
    rng = np.random.default_rng(1)
    p = rng.uniform(0, 1000, (10_000, 2))
    t = delaunay(p)
    assert t.dtype == np.int64 and t.shape[1] == 3
    assert np.all(signed_area2(p, t) > 0)  # counter-clockwise
    h = len(ConvexHull(p).vertices)
    assert len(t) == 2 * len(p) - 2 - h
    assert_empty_circumcircles(p, t)


def test_same_triangles_as_qhull_in_general_position():
    rng = np.random.default_rng(2)
    p = rng.normal(size=(3000, 2))
    ours = {tuple(sorted(x)) for x in delaunay(p)}
    qhull = {tuple(sorted(x)) for x in Delaunay(p).simplices}
    assert ours == qhull


def test_heights_column_is_carried_and_any_strides():
    rng = np.random.default_rng(3)
    p3 = rng.uniform(size=(500, 3))
    t2 = delaunay(np.ascontiguousarray(p3[:, :2]))
    np.testing.assert_array_equal(delaunay(p3), t2)
    big = np.zeros((500, 5))
    big[:, 1], big[:, 3] = p3[:, 0], p3[:, 1]
    np.testing.assert_array_equal(delaunay(big[:, 1::2]), t2)  # strided view, no copy needed
    before = p3.copy()
    delaunay(p3.astype(np.float32))
    np.testing.assert_array_equal(p3, before)


def test_identical_for_any_n_threads():
    p = np.random.default_rng(4).uniform(size=(2000, 2))
    ref = delaunay(p, n_threads=1)
    for n in (2, 3):
        np.testing.assert_array_equal(delaunay(p, n_threads=n), ref)


def test_constraint_edges_present():
    rng = np.random.default_rng(5)
    p = rng.uniform(0, 100, (2000, 2))
    # a river: a polyline monotone in x through 40 of the points (cannot self-cross)
    river = np.argsort(p[:, 0])[::50]
    cons = np.column_stack([river[:-1], river[1:]])
    t = delaunay(p, constraints=cons)
    assert np.all(signed_area2(p, t) > 0)
    edges = edge_set(t)
    for a, b in cons:
        assert tuple(sorted((a, b))) in edges
    # the unconstrained triangulation does not have them all (the test is not vacuous)
    free = edge_set(delaunay(p))
    assert any(tuple(sorted((a, b))) not in free for a, b in cons)
    # area is conserved: the constrained triangulation still covers the hull
    np.testing.assert_allclose(signed_area2(p, t).sum() / 2, ConvexHull(p).volume, rtol=1e-12)


def test_constraint_through_a_point_is_split():
    p = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0], [1.0, 1.0], [1.5, 0.2]])
    t = delaunay(p, constraints=[[0, 2]])
    e = edge_set(t)
    assert (0, 4) in e and (2, 4) in e


def test_regular_grid_cocircular_points_and_duplicates():
    yy, xx = np.mgrid[0:50, 0:50]
    g = np.column_stack([xx.ravel(), yy.ravel()]).astype(float)
    t = delaunay(g)
    assert len(t) == 2 * 49 * 49
    assert np.all(signed_area2(g, t) == 1.0)  # unit right triangles only (twice the area 1/2)
    ang = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    circ = np.column_stack([np.cos(ang), np.sin(ang)])
    tc = delaunay(circ)
    assert len(tc) == 62 and np.all(signed_area2(circ, tc) > 0)
    rng = np.random.default_rng(6)
    p = rng.uniform(size=(300, 2))
    dup = np.vstack([p, p[::3], p[:5]])  # later copies of earlier rows
    td = delaunay(dup)
    assert td.max() < 300  # the first occurrence is kept
    assert {tuple(sorted(x)) for x in td} == {tuple(sorted(x)) for x in delaunay(p)}
    # a duplicate before its original: the lower index is kept
    p2 = np.vstack([p[7], p])
    t2 = delaunay(p2)
    assert 8 not in t2 and 0 in t2
    # -0.0 and 0.0 are the same point
    z = np.array([[0.0, 0.0], [-0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    assert 1 not in delaunay(z)


def lattice_points(nx, ny, seed):
    """A rectilinear lattice with unequal, non-uniform spacings in x and y."""
    rng = np.random.default_rng(seed)
    xs = np.cumsum(rng.uniform(0.5, 3.0, nx))
    ys = -40.0 + np.cumsum(rng.uniform(0.01, 0.2, ny))
    yy, xx = np.meshgrid(ys, xs, indexing="ij")
    return np.column_stack([xx.ravel(), yy.ravel()])


def test_lattice_shuffled_with_unequal_spacing_is_delaunay():
    nx, ny = 37, 23
    rng = np.random.default_rng(11)
    g = lattice_points(nx, ny, 7)[rng.permutation(nx * ny)]
    p = np.vstack([g, g[::97]])  # later copies of some rows
    t = delaunay(p)
    assert np.all(signed_area2(p, t) > 0)
    assert t.max() < len(g)  # duplicates index the first occurrence
    h = 2 * (nx - 1) + 2 * (ny - 1)  # hull points, the collinear ones included
    assert len(t) == 2 * len(g) - 2 - h
    assert_empty_circumcircles(p, t)
    # the triangles tile the lattice's rectangle exactly
    area = (g[:, 0].max() - g[:, 0].min()) * (g[:, 1].max() - g[:, 1].min())
    np.testing.assert_allclose(signed_area2(p, t).sum() / 2, area, rtol=1e-12)
    assert len({tuple(sorted(x)) for x in t}) == len(t)
    for n in (1, 3):
        np.testing.assert_array_equal(delaunay(p, n_threads=n), t)


@pytest.mark.parametrize("drop", [0, 5, 400])
def test_lattice_with_one_point_missing_is_still_delaunay(drop):
    nx, ny = 30, 20
    g = np.delete(lattice_points(nx, ny, 8), drop, axis=0)
    t = delaunay(g)
    assert np.all(signed_area2(g, t) > 0)
    assert set(np.unique(t)) == set(range(len(g)))
    # h: points on the hull; a missing corner (0) or edge point (5) is one
    # fewer, a missing interior point (400) changes nothing
    hull = 2 * (nx - 1) + 2 * (ny - 1) - int(drop in (0, 5))
    assert len(t) == 2 * len(g) - 2 - hull
    assert_empty_circumcircles(g, t)


@pytest.mark.parametrize(
    "points, kwargs, exc, start",
    [
        (np.zeros((4, 4)), {}, ValueError, "points"),
        (np.zeros(8), {}, ValueError, "points"),
        ("abc", {}, TypeError, "points"),
        (np.array([[0, 0], [1, 0], [0, 1]], dtype=complex), {}, TypeError, "points"),
        (np.array([[0.0, 0.0], [1.0, 0.0]]), {}, ValueError, "points"),
        (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [1.0, 0.0]]), {}, ValueError, "points"),
        (np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]]), {}, ValueError, "points"),
        (np.array([[0.0, 0.0], [1.0, 0.0], [np.nan, 1.0]]), {}, ValueError, "points"),
        (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, np.inf]]), {}, ValueError, "points"),
        (np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1e300]]), {}, ValueError, "points"),
        (np.eye(3)[:, :2], {"constraints": [[0, 3]]}, ValueError, "constraints"),
        (np.eye(3)[:, :2], {"constraints": [[0, -1]]}, ValueError, "constraints"),
        (np.eye(3)[:, :2], {"constraints": [[1, 1]]}, ValueError, "constraints"),
        (np.eye(3)[:, :2], {"constraints": [[0.0, 1.0]]}, TypeError, "constraints"),
        (np.eye(3)[:, :2], {"constraints": [0, 1]}, ValueError, "constraints"),
        (np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]), {"constraints": [[0, 2], [1, 3]]}, ValueError,
         "constraints: row 1"),
        (np.eye(3)[:, :2], {"n_threads": 0}, ValueError, "n_threads"),
    ],
)
def test_bad_input(points, kwargs, exc, start):
    with pytest.raises(exc) as info:
        delaunay(points, **kwargs)
    assert str(info.value).startswith(start)
