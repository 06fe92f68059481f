"""Progress of synthesis: the Rust kernels tick a counter read from Python
while they run; fields are bit-identical with and without a bar, for any
n_threads; a worker's exception reaches the caller unchanged."""
import contextlib

import numpy as np
import pytest

import fractalgeo_rs as fg
from fractalgeo_rs import _core, _progress
from fractalgeo_rs.cli import main


class Recorder:
    """A bar that records its updates (stands in for tqdm)."""

    def __init__(self):
        self.n = 0
        self.updates = []

    def update(self, n=1):
        self.updates.append(n)
        self.n += n

    def close(self):
        pass


@pytest.fixture()
def recorder(monkeypatch):
    bars = []

    @contextlib.contextmanager
    def fake(total, desc, enabled, unit="it"):
        b = Recorder()
        b.total, b.desc = total, desc
        bars.append(b)
        yield b

    monkeypatch.setattr(_progress, "bar", fake)
    return bars


@pytest.mark.parametrize("method", ["exact", "spectral", "midpoint", "additions"])
@pytest.mark.parametrize("n_threads", [1, 2])
def test_fields_bit_identical_with_progress(method, n_threads, recorder):
    ref = fg.fbm_surface((70, 45), 0.7, method=method, seed=11, n_threads=1)
    got = fg.fbm_surface((70, 45), 0.7, method=method, seed=11, n_threads=n_threads, progress=True)
    np.testing.assert_array_equal(ref, got)
    (b,) = recorder
    assert b.n == b.total > 0 and all(u > 0 for u in b.updates)
    assert method in b.desc


def test_periodic_and_dem_bit_identical_with_progress(recorder):
    for method in ("spectral", "midpoint", "additions"):
        ref = fg.fbm_surface((64, 64), 0.4, method=method, seed=3, periodic=True)
        got = fg.fbm_surface((64, 64), 0.4, method=method, seed=3, periodic=True, progress=True, n_threads=2)
        np.testing.assert_array_equal(ref, got)
    kw = dict(cell_size=30.0, relief=50.0, seed=4, method="additions")
    np.testing.assert_array_equal(fg.synthetic_dem((40, 50), 0.8, **kw),
                                  fg.synthetic_dem((40, 50), 0.8, progress=True, **kw))
    assert all(b.n == b.total for b in recorder)


def test_progress_off_draws_no_bar(recorder):
    fg.fbm_surface((20, 20), 0.5, method="midpoint", seed=1, progress=False)
    fg.fbm_surface((20, 20), 0.5, method="midpoint", seed=1)
    assert recorder == []


def test_counter_counts_the_cells_of_every_level():
    # coarse 3 x 3, three levels: 5 x 5, 9 x 9, 17 x 17 cells
    pr = _core.ProgressCounter()
    assert (pr.done, pr.total) == (0, 0)
    coarse = np.zeros((3, 3))
    a = _core.midpoint_refine_2d(coarse, 3, 0.5, 1.0, 8.0, False, False, 1, 0, 2, pr)
    assert (pr.done, pr.total) == (25 + 81 + 289, 25 + 81 + 289)
    np.testing.assert_array_equal(a, _core.midpoint_refine_2d(coarse, 3, 0.5, 1.0, 8.0, False, False, 1, 0, 1))
    pr = _core.ProgressCounter()
    _core.additions_refine_2d(coarse, 2, 0.5, 1.0, 4.0, 0.1, [0.01, 0.09, 0.02, 0.09], False, 1, 0, None,
                              (6, 7), pr)
    assert (pr.done, pr.total) == (25 + 6 * 7, 25 + 6 * 7)
    pr = _core.ProgressCounter()
    z = _core.normal_noise(100_001, 5, 3, 0, 2, pr)
    assert (pr.done, pr.total) == (100_001, 100_001)
    np.testing.assert_array_equal(z, _core.normal_noise(100_001, 5, 3))


def test_counted_call_moves_the_bar_to_its_weight(recorder):
    # a refinement of 16 M cells polled every 0.1 s ends at exactly the weight
    steps = _progress.Steps(1000, "t", True)
    coarse = np.zeros((9, 9))
    with steps:
        steps.counted(lambda pr: _core.midpoint_refine_2d(coarse, 9, 0.5, 1.0, 512.0, False, False, 1, 0, 1,
                                                          pr), 1000)
    (b,) = recorder
    assert b.n == 1000


def test_worker_exception_is_reraised_unchanged(recorder):
    with pytest.raises(ValueError) as direct:
        _core.additions_refine_2d(np.zeros((2, 2)), 1, 0.5, 1.0, 1.0, 0.1, [0.1] * 4, False, 1, 0, None, (9, 9))
    with _progress.Steps(10, "t", True) as steps, pytest.raises(ValueError) as threaded:
        steps.counted(lambda pr: _core.additions_refine_2d(np.zeros((2, 2)), 1, 0.5, 1.0, 1.0, 0.1, [0.1] * 4,
                                                           False, 1, 0, None, (9, 9), pr), 10)
    assert str(threaded.value) == str(direct.value)

    class Boom(Exception):
        pass

    def fail(pr):
        raise Boom("x")

    with _progress.Steps(1, "t", True) as steps, pytest.raises(Boom, match="^x$"):
        steps.counted(fail, 1)


def test_progress_argument_checked():
    with pytest.raises(TypeError, match="^progress"):
        fg.fbm_surface((8, 8), 0.5, progress="yes")


def test_synth_cli_progress_flags(tmp_path, capsys):
    pytest.importorskip("tqdm")
    outs = []
    for i, extra in enumerate([[], ["--progress"], ["--no-progress"]]):
        out = tmp_path / f"z{i}.npy"
        assert main(["synth", str(out), "--hurst", "0.7", "--size", "40", "50", "--method", "additions",
                     "--seed", "2", *extra]) == 0
        err = capsys.readouterr().err
        assert ("fbm_surface (additions)" in err) == (extra == ["--progress"])
        outs.append(np.load(out))
    np.testing.assert_array_equal(outs[0], outs[1])
    np.testing.assert_array_equal(outs[0], outs[2])


@pytest.mark.parametrize("method", ["exact", "spectral", "midpoint", "additions"])
@pytest.mark.parametrize("n_threads", [1, 2])
def test_fbm_bit_identical_with_progress(method, n_threads, recorder):
    # 50 001 samples: several noise blocks per kernel call
    ref = fg.fbm(50_001, 0.3, method=method, seed=8, n_threads=1)
    got = fg.fbm(50_001, 0.3, method=method, seed=8, n_threads=n_threads, progress=True)
    np.testing.assert_array_equal(ref, got)
    (b,) = recorder
    assert b.n == b.total > 0 and all(u > 0 for u in b.updates)
    assert f"fbm ({method})" == b.desc
    fg.fbm(100, 0.3, method=method, seed=8, progress=False)
    assert len(recorder) == 1
    with pytest.raises(TypeError, match="^progress"):
        fg.fbm(100, 0.3, method=method, progress=1)


def test_1d_counters_count_every_sample():
    # midpoint 1D: coarse 3 samples, 4 levels: 5 + 9 + 17 + 33 samples
    pr = _core.ProgressCounter()
    x = _core.midpoint_refine_1d(np.array([0.0, 1.0, -1.0]), 4, 0.5, 1.0, 16.0, True, 3, 0, 2, pr)
    assert x.size == 33 and (pr.done, pr.total) == (5 + 9 + 17 + 33,) * 2
    np.testing.assert_array_equal(x, _core.midpoint_refine_1d(np.array([0.0, 1.0, -1.0]), 4, 0.5, 1.0, 16.0,
                                                              True, 3, 0, 1))
    # Davies-Harte: m + 1 noise values, an FFT of 2m, the n path samples
    m, n = 20_000, 19_001
    s = _core.fgn_sqrt_eigenvalues(m, 0.6)
    pr = _core.ProgressCounter()
    a = _core.davies_harte_fbm(s, n, 4, 9, 2, pr)
    assert (pr.done, pr.total) == (3 * m + 1 + n,) * 2
    np.testing.assert_array_equal(a, _core.davies_harte_fbm(s, n, 4, 9, 1))


def test_synth_cli_1d_progress_flag(tmp_path, capsys):
    pytest.importorskip("tqdm")
    out = tmp_path / "x.npy"
    assert main(["synth", str(out), "--hurst", "0.6", "--size", "5000", "--seed", "2", "--progress"]) == 0
    assert "fbm (exact)" in capsys.readouterr().err
    np.testing.assert_array_equal(np.load(out), fg.fbm(5000, 0.6, seed=2))
