"""The bundled geographic samples' ``cell_size`` in metres: on the WGS84
ellipsoid at the crop's middle latitude (the closed forms of the meridian and
parallel arcs, not the package's series), as the CLI converts the same grid.
It used to take the equator's 110.574 km for a degree of latitude, 0.5 %
short at 44 N."""
import math

import numpy as np
import pytest

import fractalgeo_rs as fg

A = 6378137.0
F = 1 / 298.257223563
E2 = F * (2 - F)


def _closed_form(a_deg, e_deg, lat):
    p = math.radians(lat)
    w = 1 - E2 * math.sin(p) ** 2
    m_lat = math.pi / 180 * A * (1 - E2) / w ** 1.5
    m_lon = math.pi / 180 * A * math.cos(p) / math.sqrt(w)
    return abs(a_deg) * m_lon, abs(e_deg) * m_lat


@pytest.mark.parametrize("loader", [fg.data.srtm_alps, fg.data.srtm_po_plain, fg.data.sentinel1_vv_db])
def test_geographic_cell_size_on_the_ellipsoid(loader):
    z, info = loader()
    a, _, _, _, e, f = info["transform"]
    lat = f + e * z.shape[0] / 2
    dy, dx = info["cell_size"]
    ex, ey = _closed_form(a, e, lat)
    assert isinstance(dx, float) and isinstance(dy, float)
    np.testing.assert_allclose([dx, dy], [ex, ey], rtol=2e-6)


def test_cli_reads_the_same_cell_size(tmp_path):
    pytest.importorskip("rasterio")
    from affine import Affine

    from fractalgeo_rs.dem._cli import ground_cell_size

    dem, info = fg.data.srtm_alps()
    fg.write_raster(tmp_path / "alps.tif", dem, crs=info["crs"], transform=Affine(*info["transform"]))
    _, prof = fg.read_raster(tmp_path / "alps.tif")
    dy, dx = ground_cell_size(prof, dem.shape[0])
    np.testing.assert_allclose(info["cell_size"], (dy, dx), rtol=1e-12)
