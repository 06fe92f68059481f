"""Seeded mutation fuzzing of the raster readers: corrupt, truncated, empty
and random files of every supported format raise only the documented
exceptions (OSError naming the path, ValueError for a band), never abort or
hang. Bounded to a few seconds."""
import os
import time

import numpy as np
import pytest

from fractalgeo_rs.io import read_raster, write_raster
from pathlib import Path

BUDGET_S = 4.0


def _valid_files(folder):
    rng = np.random.default_rng(0)
    files = []
    z = rng.normal(size=(23, 17))
    for name, data in [("a.npy", z), ("b.npy", np.stack([z, z])), ("c.exr", z.astype(np.float32)),
                       ("d.png", (rng.random((19, 21)) * 255).astype(np.uint8)),
                       ("e.png", (rng.random((19, 21)) * 65535).astype(np.uint16))]:
        p = os.path.join(folder, name)
        write_raster(p, data)
        files.append(p)
    try:
        import rasterio  # noqa: F401

        p = os.path.join(folder, "f.tif")
        write_raster(p, z.astype(np.float32), crs="EPSG:32633", transform=(30, 0, 0, 0, -30, 600), nodata=-1)
        files.append(p)
    except ImportError:
        pass
    return files


def _mutations(data, rng):
    n = len(data)
    yield b""
    yield data[: n // 2]
    yield data[: max(1, n - 7)]
    yield bytes(rng.integers(0, 256, size=n, dtype=np.uint8))
    for _ in range(6):
        b = bytearray(data)
        for i in rng.integers(0, n, size=int(rng.integers(1, 16))):
            b[i] = int(rng.integers(0, 256))
        yield bytes(b)
    # a mutation of the header only
    b = bytearray(data)
    for i in range(min(64, n)):
        if rng.random() < 0.2:
            b[i] ^= 0xFF
    yield bytes(b)


# a mutated TIFF header often loses its geotransform: rasterio says so
@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")
def test_readers_only_raise_documented_exceptions(tmp_path):
    rng = np.random.default_rng(1234)
    t0 = time.monotonic()
    outcomes = {"ok": 0, "OSError": 0, "ValueError": 0}
    rounds = 0
    os.makedirs(tmp_path / "valid")
    valid = _valid_files(str(tmp_path / "valid"))
    while time.monotonic() - t0 < BUDGET_S:
        for src in valid:
            data = Path(src).read_bytes()
            ext = os.path.splitext(src)[1]
            for k, m in enumerate(_mutations(data, rng)):
                p = tmp_path / f"m{rounds}_{k}{ext}"
                p.write_bytes(m)
                try:
                    a, _ = read_raster(p, band=1)
                    assert isinstance(a, np.ndarray)
                    outcomes["ok"] += 1
                except OSError as exc:
                    assert str(p) in str(exc) or repr(str(p)) in str(exc), exc
                    outcomes["OSError"] += 1
                except ValueError as exc:
                    assert str(exc).startswith("band"), exc
                    outcomes["ValueError"] += 1
                p.unlink()
        rounds += 1
        if rounds >= 20:
            break
    assert outcomes["OSError"] > 0 and rounds >= 1, outcomes


def test_reader_errors_name_the_path(tmp_path):
    empty = tmp_path / "empty.npy"
    empty.write_bytes(b"")
    with pytest.raises(OSError, match="empty.npy"):
        read_raster(empty)
    junk = tmp_path / "junk.npy"
    junk.write_bytes(os.urandom(300))
    with pytest.raises(OSError, match="junk.npy") as info:
        read_raster(junk)
    assert "allow_pickle" not in str(info.value)
    obj = tmp_path / "obj.npy"
    np.save(obj, np.array([{"a": 1}], dtype=object), allow_pickle=True)
    with pytest.raises(OSError, match="obj.npy"):
        read_raster(obj)
    with pytest.raises(IsADirectoryError, match="directory"):
        read_raster(tmp_path)


def test_several_bands_need_a_band_and_masks_are_recognised(tmp_path):
    from fractalgeo_rs.io import is_binary_mask

    assert is_binary_mask(np.array([[0, 255], [255, 0]], np.uint8))
    assert is_binary_mask(np.array([[0, 1]], np.int16)) and is_binary_mask(np.zeros((2, 2), bool))
    assert not is_binary_mask(np.array([[0, 1, 2]], np.uint8))
    assert not is_binary_mask(np.array([[3, 5]], np.uint8))
    assert not is_binary_mask(np.array([[0.0, 1.0]]))
    three = tmp_path / "three.npy"
    np.save(three, np.zeros((3, 4, 5)))
    with pytest.raises(ValueError, match="band: .* has 3 bands"):
        read_raster(three)
    assert read_raster(three, band=2)[0].shape == (4, 5)


def test_write_raster_refuses_complex_and_directories(tmp_path):
    with pytest.raises(TypeError, match="complex"):
        write_raster(tmp_path / "c.tif", np.ones((3, 3), complex))
    with pytest.raises(IsADirectoryError, match="directory"):
        write_raster(tmp_path, np.ones((3, 3)))
