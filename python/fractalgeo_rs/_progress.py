"""Progress bars for long work, with tqdm when it is installed.

``progress`` arguments follow one rule (:func:`resolve`):

* ``None``: the API default, off; the CLI passes ``None`` through
  :func:`resolve` with ``cli=True``, which turns the bar on when stderr is a
  terminal;
* ``True`` / ``False``: on / off.

A bar needs tqdm (``pip install "fractalgeo_rs[progress]"``); without it no
bar is drawn, nothing fails, and the first request for a bar prints one line
on stderr naming the extra (:data:`NO_TQDM`). Work computed by Dask reports through
``dask.diagnostics.ProgressBar`` (:func:`dask_bar`), which needs no tqdm.

One long Rust call reports through a ``_core.ProgressCounter`` that the
kernel ticks with the GIL released: :class:`Steps` runs the call on a worker
thread and copies the counter into the bar every 0.1 s from the calling
thread (:meth:`Steps.counted`). The counter never changes the work: results
are the same with and without a bar.
"""
from __future__ import annotations

import contextlib
import sys
import threading
from typing import Any, ContextManager, Optional

__all__ = ["resolve", "bar", "dask_bar", "Steps"]

#: The one line printed (once per process) when a bar is asked for without tqdm.
NO_TQDM = 'progress: no bar without tqdm; pip install "fractalgeo_rs[progress]"'
_told_no_tqdm = False

#: Seconds between two reads of a running kernel's counter.
POLL_SECONDS = 0.1


def resolve(progress: Optional[bool], *, cli: bool = False) -> bool:
    """Whether to show progress: ``progress`` if given, else (``None``) on
    in the CLI when stderr is a terminal and off in the API."""
    if progress is None:
        if not cli:
            return False
        try:
            return bool(sys.stderr.isatty())
        except (AttributeError, ValueError):  # closed or replaced stderr
            return False
    if not isinstance(progress, bool):
        import numpy as np

        if not isinstance(progress, np.bool_):
            raise TypeError(f"progress: expected True, False or None, got {progress!r}")
    return bool(progress)


class _NoBar:
    """The bar of disabled progress: accepts updates, draws nothing."""

    def update(self, n: int = 1) -> None:
        pass

    def close(self) -> None:
        pass


@contextlib.contextmanager
def bar(total: Optional[int], desc: str, enabled: bool, unit: str = "it"):
    """A tqdm bar of ``total`` steps (``None``: a counter without a total) (of ``unit``, scaled with k/M prefixes
    unless ``"it"``) on stderr when ``enabled`` and tqdm is importable, else
    an object whose ``update`` does nothing."""
    b = _NoBar()
    if enabled:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            tqdm = None
            global _told_no_tqdm
            if not _told_no_tqdm:
                _told_no_tqdm = True
                print(NO_TQDM, file=sys.stderr)
        if tqdm is not None:
            b = tqdm(total=total, desc=desc, file=sys.stderr, leave=False, unit=unit,
                     unit_scale=unit != "it")
    try:
        yield b
    finally:
        b.close()


def dask_bar(enabled: bool):
    """Dask's ``ProgressBar`` around a ``compute`` when ``enabled`` (dask
    installed), else a context that does nothing."""
    if not enabled:
        return contextlib.nullcontext()
    try:
        from dask.diagnostics import ProgressBar
    except ImportError:
        return contextlib.nullcontext()
    return ProgressBar(out=sys.stderr)


class Steps:
    """The steps of one computation on one bar of ``total`` units.

    :meth:`step` advances the bar by work done in Python; :meth:`counted`
    runs a ``_core`` call that takes a ``progress`` counter and moves the bar
    through ``weight`` units as the kernel ticks. With ``enabled=False`` the
    call runs on the calling thread with ``progress=None``.
    """

    def __init__(self, total: int, desc: str, enabled: bool):
        self.total = int(total)
        self.desc = desc
        self.enabled = bool(enabled)
        self._bar: Any = _NoBar()
        self._ctx: Optional[ContextManager[Any]] = None

    def __enter__(self) -> "Steps":
        if self.enabled:
            ctx = bar(self.total, self.desc, True, unit="cell")
            self._bar = ctx.__enter__()
            self._ctx = ctx
        return self

    def __exit__(self, *exc) -> None:
        if self._ctx is not None:
            self._ctx.__exit__(*exc)

    def step(self, n: int) -> None:
        """Advance the bar by ``n`` units."""
        self._bar.update(int(n))

    def counted(self, call, weight: int):
        """``call(counter)`` (``counter`` a ``_core.ProgressCounter``, or
        ``None`` when disabled), moving the bar through ``weight`` units.
        The worker's exception is re-raised unchanged; a KeyboardInterrupt
        reaches the calling thread between polls (the kernel then finishes
        in the background, its result discarded)."""
        if not self.enabled:
            return call(None)
        from . import _core

        counter = _core.ProgressCounter()
        box = {}

        def work():
            try:
                box["value"] = call(counter)
            except BaseException as e:  # re-raised on the calling thread
                box["error"] = e

        t = threading.Thread(target=work, name="fractalgeo-kernel", daemon=True)
        shown = 0
        t.start()
        while True:
            t.join(POLL_SECONDS)
            finished = not t.is_alive()
            total = counter.total
            now = weight if finished else (weight * counter.done // total if total else 0)
            if now > shown:
                self._bar.update(now - shown)
                shown = now
            if finished:
                break
        if "error" in box:
            raise box["error"]
        return box["value"]
