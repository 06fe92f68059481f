"""Stochastic plants placed on a DEM and merged into one scene mesh."""
from __future__ import annotations

import numbers
from typing import Optional, Sequence, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import as_array, check_n_threads, check_nonnegative_int, check_positive_float, check_seed
from fractalgeo_rs.lsystem.core import LSystem
from fractalgeo_rs.lsystem.geometry import Mesh, turtle_args

__all__ = ["plants_on_terrain"]


def plants_on_terrain(
    lsystem: LSystem,
    n: int,
    dem,
    *,
    cell_size: float,
    density: float,
    seed: Optional[int] = None,
    scale: float = 1.0,
    max_plants: int = 100_000,
    sides: int = 6,
    angle: float = 90.0,
    step: float = 1.0,
    width: float = 1.0,
    width_factor: float = 0.7,
    tropism: Sequence[float] = (0.0, 0.0, 0.0),
    elasticity: float = 0.0,
    n_threads: Optional[int] = None,
) -> Tuple[Mesh, np.ndarray]:
    """Place stochastic plant instances on a DEM, as one scene mesh.

    Parameters
    ----------
    lsystem : LSystem
        The plant (usually stochastic); plant ``i`` is derived ``n`` steps
        with its own seed, a hash of ``(seed, i)``.
    n : int
        Derivation steps per plant.
    dem : (rows, cols) array
        Heights; NaN is nodata (no plant stands there).
    cell_size : float
        Cell size in the units of the heights; cell ``(r, c)`` has its
        centre at ``x = (c + 0.5) cell_size``, ``y = (rows - r - 0.5)
        cell_size`` (row 0 is north).
    density : float
        Plants per unit area: ``round(density * area)`` plants are drawn
        over the extent of the cell centres, uniformly, with heights by
        bilinear interpolation and a uniform rotation about the vertical.
    seed : int, optional
        Scene seed; the scene is identical for any ``n_threads``.
    scale : float
        Plant size factor (turtle units to DEM units).
    max_plants : int
        Safety limit on the number of plants.
    sides, angle, step, width, width_factor, tropism, elasticity
        Mesh and turtle options, as in :func:`plant_mesh`.

    Returns
    -------
    mesh : Mesh
        ``mesh.instances`` holds the plant number of every triangle.
    bases : (P, 3) ndarray
        Base point of every plant placed.

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, section 1.7 (stochastic L-systems: every plant of a
    population differs).

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.lsystem import LSystem, plants_on_terrain
    >>> weed = LSystem("F", {"F": [("F[+F]F", 1), ("F[-F]F", 1)]})
    >>> dem = np.zeros((11, 11))
    >>> mesh, bases = plants_on_terrain(weed, 3, dem, cell_size=1.0, density=0.2, seed=1, angle=25)
    >>> bases.shape, int(mesh.instances.max())
    ((20, 3), 19)
    """
    if not isinstance(lsystem, LSystem):
        raise TypeError(f"lsystem: expected an LSystem, got {type(lsystem).__name__}")
    z = as_array(dem, "dem")
    if z.ndim != 2:
        raise ValueError(f"dem: expected a 2D array, got {z.ndim} dimensions")
    z = np.ascontiguousarray(z, dtype=np.float64)
    if isinstance(max_plants, bool) or not isinstance(max_plants, numbers.Integral) or max_plants < 0:
        raise ValueError(f"max_plants: expected a non-negative int, got {max_plants!r}")
    args = turtle_args(angle=angle, step=step, width=width, width_factor=width_factor, tropism=tropism,
                       elasticity=elasticity)
    arrays, bases = _core.plants_on_terrain(
        lsystem._core, check_nonnegative_int(n), z, check_positive_float(cell_size, "cell_size"), float(density),
        check_seed(seed), check_positive_float(scale, "scale"), int(max_plants), args, int(sides),
        check_n_threads(n_threads),
    )
    return Mesh._from_core(arrays), bases
