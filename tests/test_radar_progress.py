"""Progress of radar.simulate: the fused kernel ticks one unit per range line
of a counter read from Python while it runs; the bar ends at the range
frame's cell count; scenes are bit-identical with and without a bar, for any
look direction, path and n_threads."""
import contextlib

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import _core, _progress

KW = dict(incidence=35, wavelength=0.056, looks=4, seed=3)


class Recorder:
    """A bar that records its updates (stands in for tqdm)."""

    def __init__(self, total, desc):
        self.total, self.desc, self.n = total, desc, 0

    def update(self, n=1):
        self.n += n

    def close(self):
        pass


@pytest.fixture()
def bars(monkeypatch):
    seen = []

    @contextlib.contextmanager
    def fake(total, desc, enabled, unit="it"):
        b = Recorder(total, desc)
        seen.append(b)
        yield b

    monkeypatch.setattr(_progress, "bar", fake)
    return seen


@pytest.fixture(scope="module")
def dem():
    # relief with layover and shadow at 35 degrees, 30 x 20 cells of 10 m
    return fg.fbm_surface((30, 20), 0.6, method="spectral", seed=4, cell_size=10.0, sigma=40.0)


def _same(a, b):
    for x, y in zip((a.image, a.sigma0, a.layover, a.shadow, a.local_incidence),
                    (b.image, b.sigma0, b.layover, b.shadow, b.local_incidence)):
        np.testing.assert_array_equal(np.asarray(x), np.asarray(y))


def test_kernel_ticks_every_range_line(dem):
    table = list(np.linspace(1.0, 0.0, 900))
    pr = _core.ProgressCounter()
    z = np.ascontiguousarray(dem)
    full = _core.radar_scene(z, 10.0, 10.0, 35.0, table, 0.1, 2, 7, 2, progress=pr)
    assert (pr.done, pr.total) == (30, 30)
    # a strip of 11 lines on the same counter: totals add up
    lo, hi = _core.radar_slant_extent(z, 10.0, 35.0)
    strip = _core.radar_scene(np.ascontiguousarray(z[4:15]), 10.0, 10.0, 35.0, table, 0.1, 2, 7, 1, 4,
                              (lo, int(np.ceil(hi - lo)) + 1), progress=pr)
    assert (pr.done, pr.total) == (41, 41)
    plain = _core.radar_scene(z, 10.0, 10.0, 35.0, table, 0.1, 2, 7, 1)
    for a, b in zip(full, plain):
        np.testing.assert_array_equal(a, b)
    # the strip's inner lines are the scene's (with a line on each side for the derivative)
    np.testing.assert_array_equal(strip[1][1:-1], plain[1][5:14])


@pytest.mark.parametrize("n_threads", [1, 2])
@pytest.mark.parametrize("extra, cells", [
    (dict(look_azimuth=90), 30 * 20),            # range lines are rows
    (dict(look_azimuth=0), 20 * 30),             # range lines are columns
    (dict(look_azimuth=90, looks=None), 30 * 20),
])
def test_fused_bar_ends_at_the_cells_and_scene_is_unchanged(dem, bars, n_threads, extra, cells):
    kw = {**KW, **extra}
    plain = fg.radar.simulate(dem, 10.0, n_threads=n_threads, **kw)
    assert bars == []
    shown = fg.radar.simulate(dem, 10.0, n_threads=n_threads, progress=True, **kw)
    (b,) = bars
    assert b.desc == "radar.simulate" and b.total == cells and b.n == cells
    _same(plain, shown)


@pytest.mark.parametrize("extra", [dict(look_azimuth=30), dict(look_azimuth=180, multilook=2),
                                   dict(look_azimuth=270, ground_range=False)])
def test_other_paths_bar_ends_at_its_total_and_scene_is_unchanged(dem, bars, extra):
    kw = {**KW, **extra}
    plain = fg.radar.simulate(dem, 10.0, **kw)
    shown = fg.radar.simulate(dem, 10.0, progress=True, **kw)
    (b,) = bars
    assert b.total > 0 and b.n == b.total
    _same(plain, shown)


def test_progress_off_draws_no_bar(dem, bars):
    fg.radar.simulate(dem, 10.0, look_azimuth=90, progress=False, **KW)
    fg.radar.simulate(dem, 10.0, look_azimuth=90, progress=None, **KW)
    assert bars == []


def test_progress_argument_checked(dem):
    with pytest.raises(TypeError, match="^progress"):
        fg.radar.simulate(dem, 10.0, look_azimuth=90, progress="yes", **KW)


def test_dask_progress_is_dasks_bar(dem, capsys):
    da = pytest.importorskip("dask.array")
    lazy = fg.radar.simulate(da.from_array(dem, chunks=(10, 20)), 10.0, look_azimuth=90, progress=True, **KW)
    assert "Completed" in capsys.readouterr().err
    np.testing.assert_array_equal(lazy.image.compute(), fg.radar.simulate(dem, 10.0, look_azimuth=90, **KW).image)
