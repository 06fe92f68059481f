"""Every bad input gives a clear ValueError/TypeError naming the parameter,
never a Rust panic (pyo3 PanicException derives from BaseException, so
`pytest.raises((ValueError, TypeError))` would not catch one)."""
import numpy as np
import pytest

import fractalgeo_rs as fg

ok2d = np.eye(64, dtype=bool)
surf = np.random.default_rng(0).normal(size=(64, 64))

BAD = [
    # (callable, exception, parameter named in the message)
    (lambda: fg.box_counting(np.zeros((0, 5), bool)), ValueError, "data"),
    (lambda: fg.box_counting(np.zeros((10, 10), bool)), ValueError, "data"),
    (lambda: fg.box_counting(np.array([[0, 1], [np.nan, 1]])), ValueError, "data"),
    (lambda: fg.box_counting(np.zeros((2, 2, 2, 2), bool)), ValueError, "data"),
    (lambda: fg.box_counting(np.ones(5, dtype=complex)), TypeError, "data"),
    (lambda: fg.box_counting(np.array(["a", "b"])), TypeError, "data"),
    (lambda: fg.box_counting("mask.png"), TypeError, "data"),
    (lambda: fg.box_counting(None), TypeError, "data"),
    (lambda: fg.box_counting(np.array([[0, 2], [1, 1]])), ValueError, "data"),
    (lambda: fg.box_counting(ok2d, box_sizes=[0, 1, 2]), ValueError, "box_sizes"),
    (lambda: fg.box_counting(ok2d, box_sizes=[-1, 1, 2]), ValueError, "box_sizes"),
    (lambda: fg.box_counting(ok2d, box_sizes=[1, 2, 200]), ValueError, "box_sizes"),
    (lambda: fg.box_counting(ok2d, box_sizes=[1, 2, 2]), ValueError, "box_sizes"),
    (lambda: fg.box_counting(ok2d, box_sizes=[1.5, 2, 4]), TypeError, "box_sizes"),
    (lambda: fg.box_counting(ok2d, box_sizes="124"), TypeError, "box_sizes"),
    (lambda: fg.box_counting(ok2d, offsets=0), ValueError, "offsets"),
    (lambda: fg.box_counting(ok2d, offset_reduce="max"), ValueError, "offset_reduce"),
    (lambda: fg.box_counting(ok2d, anchor="centre"), ValueError, "anchor"),
    (lambda: fg.box_counting(ok2d, n_threads=0), ValueError, "n_threads"),
    (lambda: fg.box_counting(ok2d, n_threads=1.5), TypeError, "n_threads"),
    (lambda: fg.box_counting(ok2d, scale_range=(100, 200)), ValueError, "scale_range"),
    (lambda: fg.box_counting(np.ones((3, 3), bool)), ValueError, "data"),
    (lambda: fg.box_counting_points(np.zeros((0, 2))), ValueError, "points"),
    (lambda: fg.box_counting_points(np.array([[0.0, np.nan]] * 5)), ValueError, "points"),
    (lambda: fg.box_counting_points(np.ones((5, 2))), ValueError, "points"),
    (lambda: fg.box_counting_points(np.ones(5)), ValueError, "points"),
    (lambda: fg.box_counting_points(np.random.rand(50, 2), box_sizes=[0.1, -1, 2]), ValueError, "box_sizes"),
    (lambda: fg.differential_box_counting(np.full((64, 64), np.nan)), ValueError, "data"),
    (lambda: fg.differential_box_counting(np.ones((8, 8))), ValueError, "data"),
    (lambda: fg.differential_box_counting(np.ones(64)), ValueError, "data"),
    (lambda: fg.differential_box_counting(ok2d), TypeError, "data"),
    (lambda: fg.differential_box_counting(np.array([[np.inf, 1.0]] * 40)), ValueError, "data"),
    (lambda: fg.differential_box_counting(surf, z_scale=-1), ValueError, "z_scale"),
    (lambda: fg.differential_box_counting(surf, z_scale=float("nan")), ValueError, "z_scale"),
    (lambda: fg.differential_box_counting(surf, box_sizes=[2, 4, 65]), ValueError, "box_sizes"),
    (lambda: fg.self_affine_box_counting(np.ones(100)), ValueError, "data"),
    (lambda: fg.self_affine_box_counting(np.arange(10.0)), ValueError, "data"),
    (lambda: fg.self_affine_box_counting(np.arange(100.0), box_sizes=[1, 2, 100]), ValueError, "box_sizes"),
    (lambda: fg.dimension(ok2d, method="hausdorff"), ValueError, "method"),
]


@pytest.mark.parametrize("call, exc, param", BAD, ids=[f"bad{i}" for i in range(len(BAD))])
def test_bad_input_raises_clear_error(call, exc, param):
    with pytest.raises(exc) as info:
        call()
    assert param in str(info.value)


def test_bad_file_paths():
    from fractalgeo_rs.io import read_raster

    with pytest.raises(OSError, match="path"):
        read_raster("/nonexistent/file.tif")
    with pytest.raises(OSError):
        fg._core.read_image("/nonexistent/file.png")
