"""Numbers and types that the API reference states, checked against
independent constructions."""
import numpy as np

from fractalgeo_rs.dem import metres_per_degree
from fractalgeo_rs.io import is_binary_mask

# WGS84 (NIMA TR8350.2): semi-major axis and flattening
A = 6378137.0
F = 1.0 / 298.257223563
E2 = F * (2.0 - F)


def test_metres_per_degree_matches_the_ellipsoid_closed_forms():
    lat = np.linspace(-90.0, 90.0, 3601)
    p = np.deg2rad(lat)
    w = 1.0 - E2 * np.sin(p) ** 2
    meridian = np.pi / 180.0 * A * (1.0 - E2) / w**1.5  # radius of curvature M, one degree
    parallel = np.pi / 180.0 * A * np.cos(p) / np.sqrt(w)  # N cos(p), one degree
    m_lat, m_lon = metres_per_degree(lat)
    assert m_lat.shape == m_lon.shape == lat.shape
    assert np.abs(m_lat - meridian).max() < 0.07  # the docstring's bounds
    assert np.abs(m_lon - parallel).max() < 0.16


def test_is_binary_mask_returns_a_python_bool():
    cases = [np.array([[0, 255]], np.uint8), np.array([[0, 1, 2]], np.uint8), np.zeros((2, 2), bool),
             np.array([[0.0, 1.0]]), np.zeros((0,), np.uint8)]
    got = [is_binary_mask(a) for a in cases]
    assert got == [True, False, True, False, False]
    assert all(type(v) is bool for v in got)
