"""The timing helper of the benches: best wall time of repeated calls."""
from __future__ import annotations

import time
from typing import Any, Callable, Tuple


def best_with_result(fn: Callable[[], Any], repeat: int = 3) -> Tuple[float, Any]:
    """(shortest wall time in seconds of ``repeat`` calls of ``fn``, the last call's result)."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def best(fn: Callable[[], Any], repeat: int = 3) -> float:
    """Shortest wall time in seconds of ``repeat`` calls of ``fn``."""
    return best_with_result(fn, repeat)[0]
