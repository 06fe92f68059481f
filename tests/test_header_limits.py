"""EXR and TIFF (read without rasterio) go through the memory limit from
their headers, before any pixel is decoded: a file of a few hundred bytes
claiming a huge image gives RasterMemoryError naming the path, the size and
the limit."""
import struct
import time

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import _core, _validation as v
from fractalgeo_rs import io as fio
from fractalgeo_rs.io import RasterMemoryError


def _tiff(path, width, height, pixels=b"\x00" * 16):
    """A minimal little-endian 8-bit greyscale TIFF with one strip; the
    header may claim more pixels than the strip holds."""
    entries = [  # tag, type (3 SHORT, 4 LONG), count, value
        (256, 4, 1, width), (257, 4, 1, height), (258, 3, 1, 8), (259, 3, 1, 1),
        (262, 3, 1, 1), (273, 4, 1, 0), (277, 3, 1, 1), (278, 4, 1, height), (279, 4, 1, len(pixels)),
    ]
    ifd_size = 2 + 12 * len(entries) + 4
    data_at = 8 + ifd_size
    out = bytearray(b"II*\x00" + struct.pack("<I", 8) + struct.pack("<H", len(entries)))
    for tag, typ, count, value in entries:
        if tag == 273:
            value = data_at
        packed = struct.pack("<H", value) + b"\x00\x00" if typ == 3 else struct.pack("<I", value)
        out += struct.pack("<HHI", tag, typ, count) + packed
    out += struct.pack("<I", 0) + pixels
    path.write_bytes(bytes(out))


def _exr_claiming(path, rows, cols):
    """A real 4 x 3 EXR whose data and display windows are rewritten."""
    _core.write_exr(path, np.zeros((4, 3), np.float32))
    raw = bytearray(path.read_bytes())
    for name in (b"dataWindow\x00box2i\x00", b"displayWindow\x00box2i\x00"):
        at = raw.index(name) + len(name)
        assert struct.unpack("<i", raw[at:at + 4])[0] == 16
        raw[at + 4:at + 20] = struct.pack("<iiii", 0, 0, cols - 1, rows - 1)
    path.write_bytes(bytes(raw))


@pytest.fixture()
def no_rasterio(monkeypatch):
    monkeypatch.setattr(fio, "_rasterio", lambda: None)


def test_small_tiff_is_read_without_rasterio(tmp_path, no_rasterio):
    p = tmp_path / "a.tif"
    _tiff(p, 4, 4, bytes(range(16)))
    a, profile = fg.read_raster(p)
    assert profile is None
    np.testing.assert_array_equal(a, np.arange(16, dtype=np.uint8).reshape(4, 4))
    assert _core.image_header(p) == (4, 4, 1, 1)


@pytest.mark.parametrize("fmt", ["tif", "exr"])
def test_header_claiming_a_huge_image_is_refused_before_decoding(tmp_path, monkeypatch, no_rasterio, fmt):
    p = tmp_path / f"huge.{fmt}"
    if fmt == "tif":
        _tiff(p, 300_000, 200_000)
    else:
        _exr_claiming(p, 200_000, 300_000)
    assert p.stat().st_size < 1000
    monkeypatch.setenv(v.MAX_MEMORY_ENV, str(2**30))
    t = time.perf_counter()
    with pytest.raises(RasterMemoryError, match=r"path: .*huge\.%s.*200000 x 300000" % fmt) as info:
        fg.read_raster(p)
    assert time.perf_counter() - t < 2.0
    msg = str(info.value)
    # the estimate (tif: decoded u8 buffer + array; exr: f32 channel + band) and the limit
    need = 2 * 200_000 * 300_000 if fmt == "tif" else 8 * 200_000 * 300_000
    assert f"({need} bytes)" in msg and "max_memory = 1 GiB" in msg, msg
    assert isinstance(info.value, OSError) and isinstance(info.value, MemoryError)


def test_exr_header_and_limit_at_the_estimate(tmp_path, monkeypatch):
    p = tmp_path / "a.exr"
    z = np.arange(30 * 20, dtype=np.float32).reshape(30, 20)
    _core.write_exr(p, z)
    assert _core.exr_header(p) == (30, 20, 1)
    need = 4 * 30 * 20 * 2  # the decoded channel and the band
    monkeypatch.setenv(v.MAX_MEMORY_ENV, str(need - 1))
    with pytest.raises(RasterMemoryError, match="30 x 20"):
        fg.read_raster(p)
    monkeypatch.setenv(v.MAX_MEMORY_ENV, str(need))
    np.testing.assert_array_equal(fg.read_raster(p)[0], z)


def test_unreadable_headers_are_oserrors_naming_the_path(tmp_path, no_rasterio):
    for name, data in (("bad.exr", b"v/1\x01" + b"\x00" * 40), ("bad.tif", b"II*\x00" + b"\xff" * 20)):
        p = tmp_path / name
        p.write_bytes(data)
        with pytest.raises(OSError, match=name):
            fg.read_raster(p)
