"""Hillshade on Dask and xarray: the GDAL edge rule on the true edges only,
the same bytes and reflectances for any chunking, coords and attrs kept."""
import os

import numpy as np
import pytest

import fractalgeo_rs as fg

HERE = os.path.dirname(__file__)
CROP = os.path.join(HERE, "data", "bigtujunga_30m_crop128.npy")

da = pytest.importorskip("dask.array")


def _dem():
    z = np.load(CROP).astype(np.float64)[:100, :77].copy()
    z[0, 7] = z[40, 0] = z[50:53, 30:33] = z[99, 12] = np.nan  # voids on edges, corners of chunks
    z[31, 31] = -9999.0
    return z


CHUNKS = [(100, 77), (50, 40), (33, 20), (1, 77), (7, 1), (31, 31), ((60, 1, 39), (1, 75, 1))]
OPTS = [dict(byte=True), dict(byte=True, multidirectional=True), dict(byte=True, cell_size=(20.0, 30.0)),
        dict(), dict(latitude=np.linspace(40.0, 41.0, 100), cell_size=1 / 3600)]


@pytest.mark.parametrize("chunks", CHUNKS)
@pytest.mark.parametrize("opts", OPTS)
def test_any_chunking_gives_the_in_memory_result(chunks, opts):
    z = _dem()
    kw = dict(cell_size=30.0, nodata=-9999.0, azimuth=200.0, altitude=35.0)
    kw.update(opts)
    ref = fg.hillshade(z, **kw)
    lazy = fg.hillshade(da.from_array(z, chunks=chunks), **kw)
    assert isinstance(lazy, da.Array) and lazy.dtype == ref.dtype and lazy.shape == ref.shape
    got = lazy.compute(scheduler="sync")
    np.testing.assert_array_equal(got, ref)  # bit for bit, NaN where NaN


def test_chunk_borders_use_real_neighbours_not_the_edge_rule():
    # On a curved surface the edge rule (2a - b) differs from the real
    # neighbour: a chunk border treated as an edge would change the pixels
    # next to it; the result equals the unchunked one instead.
    i, j = np.mgrid[0:40, 0:40].astype(float)
    z = 0.05 * (i - 13) ** 2 + 0.03 * (j - 25) ** 2
    ref = fg.hillshade(z, byte=True)
    split = fg.hillshade(np.ascontiguousarray(z[:20]), byte=True)  # the top half alone
    assert np.any(split[-1] != ref[19])  # its last row is an edge: differs
    lazy = fg.hillshade(da.from_array(z, chunks=(20, 20)), byte=True).compute()
    np.testing.assert_array_equal(lazy, ref)


def test_xarray_keeps_coords_and_attrs():
    xr = pytest.importorskip("xarray")
    z = _dem()
    arr = xr.DataArray(z, dims=("y", "x"), coords={"y": 3800000.0 - 30 * np.arange(100), "x": 376000.0 + 30 * np.arange(77)},
                       attrs={"units": "m", "crs": "EPSG:32611"}, name="dem")
    ref = fg.hillshade(z, cell_size=30.0, nodata=-9999.0, byte=True)
    for a in (arr, arr.chunk({"y": 30, "x": 25})):
        out = fg.hillshade(a, cell_size=30.0, nodata=-9999.0, byte=True)
        assert isinstance(out, xr.DataArray) and out.dims == ("y", "x")
        np.testing.assert_array_equal(out["y"].values, arr["y"].values)
        np.testing.assert_array_equal(out["x"].values, arr["x"].values)
        assert out.attrs["crs"] == "EPSG:32611" and out.attrs["long_name"] == "hillshade"
        assert out.dtype == np.uint8
        np.testing.assert_array_equal(np.asarray(out), ref)
    np.testing.assert_array_equal(arr.values, z, err_msg="input modified")


def test_lazy_input_is_checked_without_computing():
    with pytest.raises(TypeError, match="dem"):
        fg.hillshade(da.zeros((4, 4), dtype=complex, chunks=2))
    with pytest.raises(ValueError, match="dem"):
        fg.hillshade(da.zeros((4,), chunks=2))
    with pytest.warns(RuntimeWarning, match="inf"):
        z = np.ones((6, 6))
        z[2, 2] = np.inf
        out = fg.hillshade(da.from_array(z, chunks=3), byte=True).compute()
    assert out[2, 2] == 0  # treated as missing, as in memory
