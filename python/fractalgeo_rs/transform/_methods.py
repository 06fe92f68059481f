"""The registry of map methods of :func:`fractal_transform`.

Each method is one :class:`MapMethod`: how its options are checked and
defaulted for a window (``configure``), the kernel call that computes the
(dimension, quality) maps on the ``step`` grid of an image (``grid``), and
its policies (whether the Rust kernel reads float32 in place, whether it
uses a height unit ``z_scale``, the name of its quality map, the ends of its
``H`` search grid for the flag layer, the warning of the in-memory map).

Adding a method: write its ``configure`` and ``grid`` functions here and
one :class:`MapMethod` entry in :data:`METHODS`; document it in the
``fractal_transform`` docstring and ``docs/transform.md``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Dict, Optional, Sequence, Tuple

import numpy as np

from fractalgeo_rs import _core


@dataclass(frozen=True)
class MapOptions:
    """The method-specific options of one ``fractal_transform`` call, as given."""

    lags: Sequence[int]
    box_sizes: Optional[Sequence[int]]
    epsilons: Optional[Sequence[int]]
    edge_blocks: str
    dilations: Any
    anisotropy: Any


Opts = Dict[str, Any]


@dataclass(frozen=True)
class MapMethod:
    """One map method: option checks, kernel call and policies."""

    name: str
    configure: Callable[[int, MapOptions, Opts], int]
    """Check and default the method's options for window ``w`` into
    ``opts``; returns the extra halo (pixels beyond ``w // 2``) the kernel
    reads."""
    grid: Callable[[np.ndarray, int, Opts, float, int, Optional[int]], Tuple[np.ndarray, ...]]
    """``(z, w, opts, min_valid, step, n_threads)`` -> the maps on the
    ``step`` grid of ``z`` (NaN = missing)."""
    reads_float32: bool = False
    """The kernel reads a float32 image in place (else float64)."""
    uses_z_scale: bool = False
    """The method needs a height unit (``z_scale``; ``"auto"``:
    :func:`default_z_scale` of the whole image)."""
    quality: str = "r_squared"
    """Name of the second map (r² of the log-log fit or the standard error of D)."""
    power: Optional[float] = None
    """Increment methods: the power ``p`` of the variation."""
    square: Optional[bool] = None
    """Increment methods: square (second-order) increments."""
    extra_names: Callable[[Opts], Tuple[str, ...]] = field(default=lambda opts: ())
    """Names of the maps after the quality map (e.g. anisotropy)."""
    pinned: Callable[[], Tuple[float, ...]] = field(default=lambda: ())
    """Values of D at the ends of the method's H search grid (flag ``pinned``)."""
    warn_map: Optional[Callable[[np.ndarray], None]] = None
    """Warning on an in-memory dimension map (beyond the out-of-range one)."""


def int_list(values, name: str, what: str) -> list:
    """Sorted distinct ints of a 1D sequence (bools and floats are errors)."""
    if isinstance(values, (str, bytes)) or np.ndim(values) != 1:
        raise TypeError(f"{name}: expected a sequence of {what}, got {values!r}")
    out = []
    for v in values:
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
            raise TypeError(f"{name}: expected a sequence of {what}, got {values!r}")
        out.append(int(v))
    return sorted(set(out))


def dbc_default_sizes(w: int) -> list:
    """Powers of two from 2 up to half the window
    (:func:`~fractalgeo_rs.dimension._common.box_size_range`); windows too
    small for three of them fall back to 2, 3, 4, and windows under 5
    pixels are refused (whole-image DBC's rule: no 1-pixel blocks). This is
    the only place the small-window rule lives."""
    from fractalgeo_rs.dimension._common import box_size_range

    if w < 5:
        raise ValueError(f"window_size: method 'dbc' needs a window of at least 5 pixels (default block "
                         f"sides 2, 3, 4; 1-pixel blocks carry no height information), got {w}")
    sizes = box_size_range(w // 2, base=2, start=2)
    return sizes if len(sizes) >= 3 else [2, 3, 4]


# --- option checks ---------------------------------------------------------

def _configure_mass(w: int, o: MapOptions, opts: Opts) -> int:
    if o.box_sizes is None:
        sizes = [L for L in (3, 5, 7, 9) if L <= w]
    else:
        sizes = int_list(o.box_sizes, "box_sizes", "odd ints")
    if len(sizes) < 2 or any(L < 3 or L % 2 == 0 or L > w for L in sizes):
        raise ValueError(f"box_sizes: need at least 2 distinct odd sides in [3, {w}], got {sizes}")
    opts["sizes"] = sizes
    return max(sizes) // 2  # the boxes reach (L_max - 1) / 2 further


def _configure_dbc(w: int, o: MapOptions, opts: Opts) -> int:
    # One rule with the whole-image differential_box_counting: no 1-pixel
    # blocks (a 1-pixel block spans no height range: it always holds one box).
    sizes = dbc_default_sizes(w) if o.box_sizes is None else int_list(o.box_sizes, "box_sizes", "ints")
    if sizes and sizes[0] < 2:
        raise ValueError(f"box_sizes: DBC needs block sides of at least 2 pixels (a 1-pixel block spans no "
                         f"height range: it always holds one box), got {sizes}")
    if len(sizes) < 3 or sizes[-1] > w:
        raise ValueError(f"box_sizes: need at least 3 distinct block sides in [2, {w}], got {sizes}")
    opts["sizes"] = sizes
    opts["partial"] = o.edge_blocks == "count"
    return 0


def _configure_blanket(w: int, o: MapOptions, opts: Opts) -> int:
    eps = [1, 2, 3, 4] if o.epsilons is None else int_list(o.epsilons, "epsilons", "positive ints")
    if len(eps) < 3 or eps[0] < 1:
        raise ValueError(f"epsilons: need at least 3 distinct positive thicknesses, got {eps}")
    opts["epsilons"] = eps
    return 0


def _configure_gls(w: int, o: MapOptions, opts: Opts) -> int:
    from fractalgeo_rs.dimension.gls import check_dilations

    opts["dilations"] = check_dilations(o.dilations)
    if 4 * opts["dilations"] >= w:
        raise ValueError(f"dilations: {opts['dilations']} needs a window of at least "
                         f"{4 * opts['dilations'] + 1} pixels, got {w}")
    if not isinstance(o.anisotropy, (bool, np.bool_)):
        raise TypeError(f"anisotropy: expected a bool, got {o.anisotropy!r}")
    return 0


def _configure_whittle(w: int, o: MapOptions, opts: Opts) -> int:
    if w < 7:
        raise ValueError(f"window_size: method 'whittle' needs a window of at least 7 pixels, got {w}")
    return 0


def _configure_increments(w: int, o: MapOptions, opts: Opts) -> int:
    lags = opts["lags"]
    if len(lags) < 2 or lags[0] < 1 or lags[-1] >= w:
        raise ValueError(f"lags: need at least 2 distinct lags in [1, {w}), got {lags}")
    return 0


# --- kernel calls -----------------------------------------------------------

def _grid_mass(z, w, opts, min_valid, step, n_threads):
    return _core.mass_transform_map(z, w, opts["sizes"], opts["z_scale"], min_valid, step, n_threads)


def _grid_dbc(z, w, opts, min_valid, step, n_threads):
    return _core.dbc_transform_map(z, w, opts["sizes"], opts["z_scale"], 0.0, opts["partial"], min_valid, step,
                                   n_threads)


def _grid_blanket(z, w, opts, min_valid, step, n_threads):
    return _core.blanket_transform_map(z, w, opts["epsilons"], opts["z_scale"], min_valid, step, n_threads)


def _grid_whittle(z, w, opts, min_valid, step, n_threads):
    from fractalgeo_rs.transform._whittle import whittle_grid

    return whittle_grid(z, w, min_valid, step, n_threads)


def _grid_gls(z, w, opts, min_valid, step, n_threads):
    from fractalgeo_rs.dimension.gls import gls_grid

    return gls_grid(z, w, opts["dilations"], min_valid, step, n_threads, opts["anisotropy"])


def _grid_increments(power: float, square: bool):
    def grid(z, w, opts, min_valid, step, n_threads):
        return _core.variation_transform_map(z, w, opts["lags"], power, square, min_valid, step, n_threads)

    return grid


# --- policies ---------------------------------------------------------------

def _gls_pinned() -> Tuple[float, ...]:
    from fractalgeo_rs.dimension.gls import H_GRID

    return (3.0 - float(H_GRID[0]), 3.0 - float(H_GRID[-1]))


def _whittle_pinned() -> Tuple[float, ...]:
    from fractalgeo_rs.transform._whittle import WHITTLE_H_GRID

    return (3.0 - float(WHITTLE_H_GRID[0]), 3.0 - float(WHITTLE_H_GRID[-1]))


def _gls_warn(d: np.ndarray) -> None:
    from fractalgeo_rs.dimension.gls import warn_pinned_map

    warn_pinned_map(d)


def _gls_extra(opts: Opts) -> Tuple[str, ...]:
    return ("anisotropy_angle", "anisotropy_ratio") if opts["anisotropy"] else ()


def _increments(name: str, power: float, square: bool) -> MapMethod:
    return MapMethod(name, _configure_increments, _grid_increments(power, square), reads_float32=True,
                     power=power, square=square)


METHODS: Dict[str, MapMethod] = {
    m.name: m
    for m in (
        MapMethod("mass", _configure_mass, _grid_mass, reads_float32=True, uses_z_scale=True),
        MapMethod("dbc", _configure_dbc, _grid_dbc, reads_float32=True, uses_z_scale=True),
        MapMethod("blanket", _configure_blanket, _grid_blanket, reads_float32=True, uses_z_scale=True),
        MapMethod("whittle", _configure_whittle, _grid_whittle, quality="standard_error",
                  pinned=_whittle_pinned),
        MapMethod("gls", _configure_gls, _grid_gls, reads_float32=True, quality="standard_error",
                  extra_names=_gls_extra, pinned=_gls_pinned, warn_map=_gls_warn),
        _increments("variogram", 2.0, False),
        _increments("madogram", 1.0, False),
        _increments("square", 2.0, True),
    )
}
"""Every map method by name, in the order of the documentation."""

TRANSFORM_METHODS: Dict[str, Tuple[Optional[float], Optional[bool]]] = {
    name: (m.power, m.square) for name, m in METHODS.items()
}
"""Method names and, for the increment methods, ``(power p, square
increments)`` (``(None, None)`` for the others)."""
