"""Kernels keep one rayon pool per thread count; a forked child must not use
(or wait on) its parent's pool threads, which do not exist in the child."""
import multiprocessing as mp
import sys

import numpy as np
import pytest

import fractalgeo_rs as fg


def _child(q):
    try:
        z = fg.fbm_surface((96, 96), 0.5, method="spectral", seed=3)
        q.put(fg.fractal_transform(z, 9, n_threads=2).tobytes())
    except Exception as e:  # pragma: no cover - reported to the parent
        q.put(repr(e))


@pytest.mark.skipif(sys.platform != "linux", reason="fork start method")
def test_kernel_in_forked_child_after_parent_used_its_pool():
    z = fg.fbm_surface((96, 96), 0.5, method="spectral", seed=3)
    ref = fg.fractal_transform(z, 9, n_threads=2)  # the parent now holds a 2-thread pool
    ctx = mp.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=_child, args=(q,))
    p.start()
    p.join(timeout=120)
    if p.is_alive():
        p.kill()
        pytest.fail("the forked child hung in its first kernel call")
    assert p.exitcode == 0
    got = q.get(timeout=10)
    assert isinstance(got, bytes), got
    assert np.array_equal(np.frombuffer(got, dtype=ref.dtype).reshape(ref.shape), ref, equal_nan=True)
    # and the parent's pool still works after the fork
    assert np.array_equal(fg.fractal_transform(z, 9, n_threads=2), ref, equal_nan=True)


def test_concurrent_calls_from_python_threads():
    """Python threads (the GIL is released in the kernels) each keep their
    own pools: concurrent calls with any thread counts give the serial results."""
    from concurrent.futures import ThreadPoolExecutor

    imgs = [fg.fbm_surface((80, 90), h, method="spectral", seed=s) for s, h in enumerate((0.3, 0.5, 0.7, 0.4))]
    jobs = [(k, n) for k in range(len(imgs)) for n in (1, 2, 3)] * 2
    ref = {k: fg.fractal_transform(imgs[k], 9, n_threads=1) for k in range(len(imgs))}
    with ThreadPoolExecutor(4) as ex:
        outs = list(ex.map(lambda kn: fg.fractal_transform(imgs[kn[0]], 9, n_threads=kn[1]), jobs))
    for (k, _), out in zip(jobs, outs):
        assert np.array_equal(out, ref[k], equal_nan=True)
