"""Warnings that point at the user's line.

``warnings.warn(..., stacklevel=n)`` with a fixed ``n`` points into the
package as soon as a decorator or a helper adds a frame. Every warning of
the package passes ``stacklevel=user_stacklevel()`` instead, which walks the
stack out of the package and reports the first frame outside it (the user's
call), whatever the depth of the call inside the package.
"""
from __future__ import annotations

import os
import sys
from types import FrameType
from typing import Optional

__all__ = ["user_stacklevel"]

_PKG_DIR = os.path.dirname(os.path.abspath(__file__)) + os.sep


def _in_package(filename: str) -> bool:
    return os.path.abspath(filename).startswith(_PKG_DIR)


def user_stacklevel(skip: int = 1) -> int:
    """The ``stacklevel`` that makes a ``warnings.warn`` issued ``skip``
    frames above this call point at the first frame outside the package
    (``skip=1``: the function calling ``user_stacklevel`` issues the
    warning)."""
    frame: Optional[FrameType] = sys._getframe(skip)
    level = 1
    while frame is not None and _in_package(frame.f_code.co_filename):
        frame = frame.f_back
        level += 1
    return level

