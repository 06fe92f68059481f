"""Figure helpers (matplotlib is imported lazily by the callers)."""
from __future__ import annotations

import os

from fractalgeo_rs._validation import atomic_write_path


def save_figure(fig, path, dpi: int = 120) -> None:
    """Save a matplotlib figure atomically (whole or not at all)."""
    ext = os.path.splitext(os.fspath(path))[1].lower().lstrip(".") or "png"
    with atomic_write_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=ext, bbox_inches="tight")
