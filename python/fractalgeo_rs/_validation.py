"""Argument checks shared by every public function.

Each check raises ``TypeError`` or ``ValueError`` with a message that starts
with the parameter's name and says what was expected, so users see e.g.
``ValueError: box_sizes: need at least 3 distinct box sizes, got 2``.
"""
from __future__ import annotations

import math
import numbers
import os
import secrets
import tempfile
import warnings
from contextlib import contextmanager
from typing import Iterator, Optional

import numpy as np

from fractalgeo_rs._warn import user_stacklevel

__all__ = [
    "as_array",
    "as_list",
    "check_real_array",
    "check_memory",
    "resolve_max_memory",
    "default_max_memory",
    "MemoryLimitError",
    "MAX_THREADS_PER_CORE",
    "max_threads",
    "available_cores",
    "check_n_threads",
    "check_z_factor",
    "check_integer_lags",
    "check_positive_int",
    "check_nonnegative_int",
    "check_positive_float",
    "check_choice",
    "check_seed",
    "check_window",
    "atomic_write_path",
]


def as_array(data, name: str = "data") -> np.ndarray:
    """Return ``data`` as an ndarray (no copy when it already is one).

    Dask arrays, xarray objects and other array-likes go through
    ``np.asarray``; strings, None and ragged sequences are rejected. The
    package's input policy is applied (:func:`check_real_array`): complex
    data is a ``TypeError``, ±inf becomes NaN with a ``RuntimeWarning``.
    """
    if data is None or isinstance(data, (str, bytes)):
        raise TypeError(f"{name}: expected an array, got {type(data).__name__}")
    try:
        arr = np.asarray(data)
    except (ValueError, TypeError) as exc:  # ragged nested sequences
        raise TypeError(f"{name}: expected an array, could not convert: {exc}") from None
    if arr.dtype == object:
        raise TypeError(f"{name}: expected a numeric or boolean array, got dtype object")
    return _real_policy(arr, name)


def _real_policy(arr: np.ndarray, name: str) -> np.ndarray:
    if arr.dtype.kind == "c":
        raise TypeError(f"{name}: complex data is not accepted (dtype {arr.dtype}); "
                        f"pass a real array such as np.abs({name}) or {name}.real")
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"{name}: expected a real numeric or boolean array, got dtype {arr.dtype}")
    if arr.dtype.kind == "f" and arr.size and not _surely_no_inf(arr):
        inf = np.isinf(arr)
        count = int(np.count_nonzero(inf))
        if count:
            warnings.warn(f"{name}: {count} value(s) are ±inf; they are treated as missing (NaN)",
                          RuntimeWarning, stacklevel=user_stacklevel())
            arr = np.where(inf, np.asarray(np.nan, dtype=arr.dtype), arr)
    return arr


def _surely_no_inf(arr: np.ndarray) -> bool:
    """True when the float array holds no ±inf, decided from its extremes
    (two passes without a temporary array); False when unsure (NaN makes
    the extremes NaN) or when there is an infinity."""
    with np.errstate(invalid="ignore"):
        lo, hi = np.min(arr), np.max(arr)
    return bool(np.isfinite(lo) and np.isfinite(hi))


def check_real_array(data, name: str = "data") -> np.ndarray:
    """``data`` as a real (bool, integer or float) ndarray, with the package's
    ±inf rule applied.

    * complex dtypes raise ``TypeError`` (no function takes the modulus or the
      real part silently: pass ``np.abs(z)`` or ``z.real``);
    * ±inf is missing data, as NaN is: a float array holding ±inf is returned
      as a copy with NaN in their place and a ``RuntimeWarning`` naming the
      count and the parameter (``10 * log10(0)`` of a SAR amplitude is
      ``-inf``). The input is never modified. What a function does with NaN
      (treat as missing or reject) is then the same for ±inf.

    See ``docs/input_policy.md``.
    """
    return as_array(data, name)


#: ``n_threads`` may be at most this many times the available cores ...
MAX_THREADS_PER_CORE = 4
#: ... and the cap is never below this (rust/parallel.rs has the same rule).
MIN_THREAD_CAP = 16


def max_threads() -> int:
    """The largest accepted ``n_threads``: ``max(4 x cores, 16)``."""
    return max(MAX_THREADS_PER_CORE * available_cores(), MIN_THREAD_CAP)


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where known)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - non-Linux
        return max(1, os.cpu_count() or 1)


def check_n_threads(n_threads) -> Optional[int]:
    """``None`` (all cores) or a positive int of at most :func:`max_threads`
    (4 per available core, at least 16: more threads only slow the machine
    down; the Rust layer enforces the same cap)."""
    if n_threads is None:
        return None
    if isinstance(n_threads, bool) or not isinstance(n_threads, numbers.Integral):
        raise TypeError(f"n_threads: expected a positive int or None, got {n_threads!r}")
    n_threads = int(n_threads)
    if n_threads < 1:
        raise ValueError(f"n_threads: expected a positive int or None, got {n_threads}")
    cap = max_threads()
    if n_threads > cap:
        raise ValueError(f"n_threads: expected at most {cap} ({MAX_THREADS_PER_CORE} per available core, "
                         f"{available_cores()} cores, at least {MIN_THREAD_CAP}), got {n_threads}; "
                         f"None uses one thread per core")
    return int(n_threads)


# ----------------------------------------------------------------- memory

class MemoryLimitError(MemoryError, ValueError):
    """A request whose estimated working memory is above ``max_memory``.

    A ``MemoryError`` (nothing was allocated) and a ``ValueError`` (the
    argument that sets the size is too large for this machine)."""


#: Default limit: this fraction of the memory available when the call starts.
DEFAULT_MEMORY_FRACTION = 0.5

#: Environment variable overriding the default limit (bytes, e.g. ``8e9``).
MAX_MEMORY_ENV = "FRACTALGEO_MAX_MEMORY"


def _available_memory() -> int:
    """Bytes available to this process: ``MemAvailable`` (Linux), else the
    physical memory; at most the address-space limit (``RLIMIT_AS``)."""
    avail = None
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    avail = int(line.split()[1]) * 1024
                    break
    except OSError:  # pragma: no cover - non-Linux
        pass
    if avail is None:  # pragma: no cover - non-Linux
        try:
            avail = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):
            avail = 8 * 2**30
    try:
        import resource

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY and soft > 0:
            avail = min(avail, soft)
    except (ImportError, OSError, ValueError):  # pragma: no cover - non-POSIX
        pass
    return int(avail)


def default_max_memory() -> int:
    """The limit used when ``max_memory=None``: ``$FRACTALGEO_MAX_MEMORY``
    bytes when set, else ``DEFAULT_MEMORY_FRACTION`` (one half) of the
    memory available now (``MemAvailable``, capped by ``RLIMIT_AS``)."""
    env = os.environ.get(MAX_MEMORY_ENV)
    if env:
        try:
            value = float(env)
        except ValueError:
            raise ValueError(f"{MAX_MEMORY_ENV}: expected a number of bytes, got {env!r}") from None
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{MAX_MEMORY_ENV}: expected a positive number of bytes, got {env!r}")
        return int(value)
    return int(DEFAULT_MEMORY_FRACTION * _available_memory())


def resolve_max_memory(max_memory=None) -> int:
    """Check a ``max_memory`` argument (bytes or None) and return the limit."""
    if max_memory is None:
        return default_max_memory()
    if isinstance(max_memory, bool) or not isinstance(max_memory, numbers.Real):
        raise TypeError(f"max_memory: expected a number of bytes or None, got {max_memory!r}")
    limit = float(max_memory)
    if not (limit > 0 and math.isfinite(limit)):
        raise ValueError(f"max_memory: expected a positive number of bytes, got {max_memory}")
    return int(limit)


def _gib(n: float) -> str:
    return f"{n / 2**30:.3g} GiB"


def check_memory(n_bytes, param: str, *, max_memory=None, what: str = "") -> int:
    """Raise :class:`MemoryLimitError` naming ``param`` when ``n_bytes`` (the
    estimated working memory of a request, computed before allocating) is
    above the limit (``max_memory``, or :func:`default_max_memory`).

    Returns the estimate (an int). ``what`` describes the request in the
    message (e.g. ``"n=10**12 samples"``).
    """
    limit = resolve_max_memory(max_memory)
    need = int(n_bytes)
    if need > limit:
        detail = f" for {what}" if what else ""
        raise MemoryLimitError(
            f"{param}: needs about {_gib(need)} ({need} bytes) of working memory{detail}, above the "
            f"limit max_memory = {_gib(limit)}; use a smaller {param}, or raise the limit with "
            f"max_memory= or ${MAX_MEMORY_ENV}")
    return need


def check_z_factor(value, name: str = "z_factor") -> float:
    """A positive finite height exaggeration (``z_factor <= 0`` would flatten
    or invert the relief)."""
    return check_positive_float(value, name)


def check_integer_lags(lags, name: str = "lags", *, minimum: int = 1) -> list:
    """Sorted distinct integer lags ``>= minimum`` (floats equal to an integer
    are accepted; ``1.5`` is an error, never truncated)."""
    if isinstance(lags, (str, bytes)) or np.ndim(lags) != 1:
        raise TypeError(f"{name}: expected a 1D sequence of integer lags, got {lags!r}")
    out = []
    for v in np.asarray(lags).tolist():
        if isinstance(v, bool):
            raise TypeError(f"{name}: expected integer lags, got a bool")
        if isinstance(v, float) and v.is_integer():
            v = int(v)
        if not isinstance(v, int):
            raise TypeError(f"{name}: expected integer lags in samples, got {v!r}")
        if v < minimum:
            raise ValueError(f"{name}: lags must be >= {minimum}, got {v}")
        out.append(v)
    return sorted(set(out))


def as_list(value, name: str, what: str = "numbers") -> list:
    """The items of a sequence argument (e.g. ``box_sizes``, ``radii``), or
    a TypeError naming it when it is a scalar, a string or not iterable."""
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        raise TypeError(f"{name}: expected a sequence of {what}, got {value!r}")
    return list(value)


def check_positive_int(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected a positive int, got {value!r}")
    if value < 1:
        raise ValueError(f"{name}: expected a positive int, got {value}")
    return int(value)


def check_nonnegative_int(value, name: str = "n") -> int:
    """An int ``>= 0`` (e.g. a number of derivation steps)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: expected a non-negative int, got {value!r}")
    if value < 0:
        raise ValueError(f"{name}: expected a non-negative int, got {value}")
    return int(value)


def check_fraction(value, name: str) -> float:
    """A number in [0, 1] (e.g. ``min_valid``), as a float."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (0.0 <= float(value) <= 1.0):
        raise ValueError(f"{name}: expected a fraction in [0, 1], got {value!r}")
    return float(value)


def check_positive_float(value, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a positive number, got {value!r}")
    value = float(value)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name}: expected a positive finite number, got {value}")
    return value


def check_seed(seed, name: str = "seed") -> int:
    """The package's one seed policy: ``None`` draws a fresh 64-bit seed from
    the operating system's entropy; otherwise an int in ``[0, 2**64)``.

    Every random result is a pure function of the seed (counter-based
    streams keyed by seed and position, ``rust/rng.rs``), so a given seed
    gives the same result for any ``n_threads``, tiling or machine.
    """
    if seed is None:
        return secrets.randbits(64)
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise TypeError(f"{name}: expected an int in [0, 2**64) or None, got {seed!r}")
    if not 0 <= int(seed) < 2**64:
        raise ValueError(f"{name}: expected an int in [0, 2**64) or None, got {seed}")
    return int(seed)


def check_window(value, name: str = "window_size", *, minimum: int = 3, shape=None, cover: bool = False) -> int:
    """An odd window side ``>= minimum`` (pixels), the one window check.

    With ``shape`` the window is also bounded by the image: at most its
    longer side (``cover=False``: a moving window that lies inside the image,
    as the fractal transform's), or at most ``2 * max(shape) + 1`` (``cover=True``:
    a window centred on any pixel that may reach past the edges, as the
    resampling analysis's; a larger one covers nothing more).
    """
    expected = f"expected an odd int >= {minimum}"
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name}: {expected}, got {value!r}")
    w = int(value)
    if w < minimum or w % 2 == 0:
        raise ValueError(f"{name}: {expected}, got {w}")
    if shape is not None:
        side = max(shape)
        if cover and w > 2 * side + 1:
            raise ValueError(f"{name}: {w} is more than twice the image's side {side}; "
                             f"a window of at most {2 * side + 1} already covers it")
        if not cover and w > side:
            raise ValueError(f"{name}: window {w} is larger than the image {tuple(shape)}")
    return w


def check_nodata(nodata) -> Optional[float]:
    """``None`` or a real number (NaN allowed: NaN is always missing)."""
    if nodata is None:
        return None
    if isinstance(nodata, (bool, np.bool_)) or not isinstance(nodata, numbers.Real):
        raise TypeError(f"nodata: expected a number or None, got {nodata!r}")
    return float(nodata)


#: Values that DEM formats use for voids: SRTM's and GDAL's int16 ``-32768``
#: and GDAL's float32 lowest (``-3.4028235e38``; anything below -1e30).
VOID_SENTINEL = -32768.0


def warn_void_sentinel(z, name: str = "dem", nodata=None, hint: str = "pass nodata=-32768") -> None:
    """Warn when heights hold a void sentinel and ``nodata`` does not cover it.

    SRTM and many GDAL int16 DEMs store voids as ``-32768`` and float DEMs as
    the lowest float32; read without their nodata value they are taken as
    real heights (a 30 km pit) and every result near them is garbage. One
    ``RuntimeWarning`` names the parameter, the count and the remedy. Dask
    arrays are not scanned (it would compute them)."""
    if not isinstance(z, np.ndarray) or z.dtype.kind not in "iuf" or not z.size:
        return
    nd = None if nodata is None else float(nodata)
    with np.errstate(invalid="ignore"):
        lo = z.min()  # NaN when a NaN is present: then the cells are counted below
    if lo > VOID_SENTINEL:
        return
    void = (z == VOID_SENTINEL) | (z < -1e30)
    if nd is not None:
        void &= z != nd
    count = int(np.count_nonzero(void))
    if count:
        warnings.warn(f"{name}: {count} cell(s) hold a void value (-32768 or the lowest float32) that "
                      f"no nodata covers; they are taken as real heights: {hint}",
                      RuntimeWarning, stacklevel=user_stacklevel())


def check_choice(value, name: str, choices) -> str:
    if value not in choices:
        opts = ", ".join(repr(c) for c in choices)
        raise ValueError(f"{name}: expected one of {opts}, got {value!r}")
    return value


@contextmanager
def atomic_write_path(path) -> Iterator[str]:
    """Yield a temporary path beside ``path``; rename it over ``path`` on success.

    The file appears whole or not at all: on any exception the temporary file
    is removed and ``path`` is left as it was.
    """
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OSError(f"path: folder {folder!r} does not exist")
    base = os.path.basename(path)
    stem, ext = os.path.splitext(base)
    fd, tmp = tempfile.mkstemp(prefix=f".{stem}.", suffix=ext, dir=folder)
    os.close(fd)
    try:
        yield tmp
        # mkstemp creates 0600 files; give the result the usual permissions
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
