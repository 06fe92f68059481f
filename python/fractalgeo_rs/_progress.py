"""Progress bars for long work, with tqdm when it is installed.

``progress`` arguments follow one rule (:func:`resolve`):

* ``None``: the API default, off; the CLI passes ``None`` through
  :func:`resolve` with ``cli=True``, which turns the bar on when stderr is a
  terminal;
* ``True`` / ``False``: on / off.

A bar needs tqdm (``pip install "fractalgeo_rs[progress]"``); without it no
bar is drawn and nothing fails. Work computed by Dask reports through
``dask.diagnostics.ProgressBar`` (:func:`dask_bar`), which needs no tqdm.
"""
from __future__ import annotations

import contextlib
import sys
from typing import Optional

__all__ = ["resolve", "bar", "dask_bar"]


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
def bar(total: int, desc: str, enabled: bool):
    """A tqdm bar of ``total`` steps on stderr when ``enabled`` and tqdm is
    importable, else an object whose ``update`` does nothing."""
    b = _NoBar()
    if enabled:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            tqdm = None
        if tqdm is not None:
            b = tqdm(total=total, desc=desc, file=sys.stderr, leave=False)
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
