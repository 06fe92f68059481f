"""Memory guards and bounded threads: huge requests raise Python exceptions
(never an abort), also under a lowered address-space limit."""
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import _validation as v
from fractalgeo_rs.synth import _fbm

HUGE = [
    "fg.fbm(10**12, 0.5, method='{m}')",
    "fg.fbm(2**62, 0.5, method='{m}')",
    "fg.fbm_surface((200000, 200000), 0.5, method='{m}')",
]
METHODS = ["exact", "midpoint", "additions", "spectral"]


@pytest.mark.parametrize("call", [c.format(m=m) for c in HUGE for m in METHODS])
def test_huge_requests_raise_memory_error_naming_the_parameter(call):
    with pytest.raises(MemoryError) as info:
        eval(call)
    msg = str(info.value)
    assert msg.startswith(("n:", "shape:")) and "max_memory" in msg and "GiB" in msg
    assert isinstance(info.value, ValueError)  # also a ValueError: the argument is too large


def test_memory_estimate_and_override():
    need = _fbm.fbm_memory_bytes(10**6)
    assert need == 64 * 10**6
    with pytest.raises(MemoryError, match="n:"):
        fg.fbm(10**6, 0.5, max_memory=need - 1)
    assert fg.fbm(10**6, 0.5, max_memory=need, seed=1).shape == (10**6,)
    est = _fbm.surface_memory_bytes((100, 150), 0.5, "spectral")
    with pytest.raises(MemoryError, match="shape:"):
        fg.fbm_surface((100, 150), 0.5, method="spectral", max_memory=est - 1)
    assert fg.fbm_surface((100, 150), 0.5, method="spectral", max_memory=est, seed=1).shape == (100, 150)
    with pytest.raises(TypeError, match="max_memory"):
        fg.fbm(100, 0.5, max_memory="1G")
    with pytest.raises(ValueError, match="max_memory"):
        fg.fbm(100, 0.5, max_memory=-1)


def test_default_limit_follows_environment(monkeypatch):
    monkeypatch.setenv(v.MAX_MEMORY_ENV, "1e6")
    assert v.default_max_memory() == 10**6
    with pytest.raises(MemoryError, match="FRACTALGEO_MAX_MEMORY"):
        fg.fbm(10**5, 0.5)
    monkeypatch.setenv(v.MAX_MEMORY_ENV, "lots")
    with pytest.raises(ValueError, match=v.MAX_MEMORY_ENV):
        v.default_max_memory()
    monkeypatch.delenv(v.MAX_MEMORY_ENV)
    assert 0 < v.default_max_memory() <= v._available_memory()


_CHILD = textwrap.dedent("""
    import resource, sys
    import fractalgeo_rs as fg
    import numpy as np
    # the package imports lazily: load the modules the calls use before the
    # limit, as an eager import did, so the limit meets the calls' own
    # allocations and not the import of scipy and the package's modules
    import fractalgeo_rs.dimension, fractalgeo_rs.io, fractalgeo_rs.lsystem, fractalgeo_rs.synth
    resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))
    calls = {calls!r}
    for call in calls:
        try:
            eval(call)
        except (MemoryError, ValueError) as exc:
            print("ok", type(exc).__name__, call, flush=True)
        else:
            print("no exception", call, flush=True)
            sys.exit(3)
""")


def _run_child(calls):
    code = _CHILD.format(calls=calls)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS semantics are Linux's")
def test_no_abort_under_an_address_space_limit():
    # The default limit follows RLIMIT_AS; with max_memory raised past it the
    # allocations themselves fail, in numpy or in Rust (try_reserve): both are
    # Python MemoryErrors, never SIGABRT (exit code 134 / -6).
    calls = [c.format(m=m) for c in HUGE for m in METHODS]
    calls += [c.format(m=m)[:-1] + ", max_memory=2**62)" for c in HUGE[:1] for m in METHODS]
    calls += ["fg.fbm_surface((40000, 40000), 0.5, method='{m}', max_memory=2**62)".format(m=m)
              for m in ("midpoint", "additions", "spectral")]
    calls += ["fg._core.normal_noise(2**40, 1, 0)", "fg._core.normal_noise(2**61, 1, 0)"]
    r = _run_child(calls)
    assert r.returncode == 0, (r.returncode, r.stdout[-2000:], r.stderr[-2000:])
    assert r.stdout.count("ok ") == len(calls)


def test_n_threads_is_bounded():
    cap = v.max_threads()
    z = np.eye(64, dtype=bool)
    with pytest.raises(ValueError, match="n_threads: expected at most"):
        fg.box_counting(z, n_threads=10**6)
    with pytest.raises(ValueError, match="n_threads"):
        fg.box_counting(z, n_threads=cap + 1)
    assert fg.box_counting(z, n_threads=cap).dimension == fg.box_counting(z, n_threads=1).dimension
    # the Rust layer enforces the same cap for direct callers of _core
    with pytest.raises(ValueError, match="n_threads"):
        fg._core.normal_noise(10, 1, 0, 0, cap + 1)


def _huge_npy(path, shape=(10**6, 10**6)):
    # a header announcing 8 TB of float64 and no data behind it
    with open(path, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": shape})


def _png_claiming(path, width, height):
    # a valid 4 x 4 PNG whose IHDR is rewritten to announce width x height
    fg.write_raster(path, np.zeros((4, 4), dtype=np.uint8))
    raw = bytearray(Path(path).read_bytes())
    raw[16:20] = width.to_bytes(4, "big")
    raw[20:24] = height.to_bytes(4, "big")
    Path(path).write_bytes(bytes(raw))


# the test writes GeoTIFFs without georeferencing: rasterio says so on reading
@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")
def test_readers_estimate_bytes_from_the_header(tmp_path):
    from fractalgeo_rs.io import RasterMemoryError

    npy = tmp_path / "huge.npy"
    _huge_npy(npy)
    with pytest.raises(RasterMemoryError, match=r"path: .*huge\.npy.*1000000 x 1000000 float64") as info:
        fg.read_raster(npy)
    assert isinstance(info.value, OSError) and isinstance(info.value, MemoryError)
    png = tmp_path / "huge.png"
    _png_claiming(png, 200000, 150000)
    with pytest.raises(RasterMemoryError, match=r"huge\.png.*150000 x 200000"):
        fg.read_raster(png)


# the test writes GeoTIFFs without georeferencing: rasterio says so on reading
@pytest.mark.filterwarnings("ignore::rasterio.errors.NotGeoreferencedWarning")
def test_readers_follow_the_memory_limit(tmp_path, monkeypatch):
    rasterio = pytest.importorskip("rasterio")
    z = np.zeros((300, 200), dtype=np.float32)
    tif, npy = tmp_path / "a.tif", tmp_path / "a.npy"
    with rasterio.open(tif, "w", driver="GTiff", width=200, height=300, count=1, dtype="float32") as dst:
        dst.write(z, 1)
    np.save(npy, z)
    monkeypatch.setenv(v.MAX_MEMORY_ENV, str(z.nbytes - 1))
    for p in (tif, npy):
        with pytest.raises(MemoryError, match="path: .*300 x 200"):
            fg.read_raster(p)
    monkeypatch.setenv(v.MAX_MEMORY_ENV, str(z.nbytes))
    for p in (tif, npy):
        assert fg.read_raster(p)[0].shape == (300, 200)


def test_grid_from_points_output_is_estimated():
    from fractalgeo_rs.tin import grid_from_points

    pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    with pytest.raises(MemoryError, match=r"shape: .*1000000 x 1000000 float64 grid"):
        grid_from_points(pts, np.arange(4.0), (10**6, 10**6))
    assert grid_from_points(pts, np.arange(4.0), (3, 3)).shape == (3, 3)


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS semantics are Linux's")
def test_lsystem_and_readers_under_an_address_space_limit(tmp_path):
    # A doubling L-system with max_length out of the way outgrows the 3 GiB
    # address space: its length is counted from the productions and refused
    # before expanding (MemoryLimitError naming n); when a condition hides
    # the growth from the count, the derived string's buffer is allocated
    # fallibly (MemoryError naming max_length), never an abort; a file
    # announcing 8 TB is refused from its header.
    npy = tmp_path / "huge.npy"
    _huge_npy(npy)
    calls = ["fg.lsystem.LSystem('A', {'A': 'AA'}, max_length=2**62).derive(40)",
             "fg.lsystem.LSystem('A', {'A': 'AB', 'B': 'A'}, max_length=2**62).derive(80)",
             "fg.lsystem.LSystem('A(1)', ['A(x): x > 0 -> A(x)A(x)'], max_length=2**62).derive(40)",
             f"fg.read_raster({str(npy)!r})"]
    r = _run_child(calls)
    assert r.returncode == 0, (r.returncode, r.stdout[-2000:], r.stderr[-2000:])
    assert r.stdout.count("ok ") == len(calls)
    lines = [ln for ln in r.stdout.splitlines() if ln.startswith("ok ")]
    assert [ln.split()[1] for ln in lines] == ["MemoryLimitError", "MemoryLimitError", "MemoryError",
                                               "RasterMemoryError"], r.stdout
