"""Gliding-box lacunarity (Allain and Cloitre 1991; Plotnick et al. 1993).

For box side ``r`` the box slides over every position; with box masses ``M``
(foreground count, or sum of values for grayscale data)

    Lambda(r) = E[M^2] / E[M]^2 = 1 + Var(M) / E[M]^2.

Lambda = 1 for a translation-invariant (filled) pattern and grows with
gappiness; its decay with ``r`` describes texture scale (paper section 4.2).

References
----------
Allain, C., Cloitre, M. (1991). Characterizing the lacunarity of random and
deterministic fractal sets. *Physical Review A* 44(6), 3552-3558.
Plotnick, R. E., Gardner, R. H., O'Neill, R. V. (1993). Lacunarity indices as
measures of landscape texture. *Landscape Ecology* 8(3), 201-211.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from fractalgeo_rs._compat import keyword_only_since
from fractalgeo_rs._validation import as_array, as_list, check_positive_int

__all__ = ["Lacunarity", "lacunarity"]


@dataclass(frozen=True)
class Lacunarity:
    """Gliding-box lacunarity per box side.

    Attributes
    ----------
    box_sizes : ndarray
        Box sides in pixels.
    lacunarity : ndarray
        ``Lambda(r)``.
    n_boxes : ndarray
        Number of box positions (boxes touching NaN are left out).

    References
    ----------
    Allain and Cloitre (1991), doi:10.1103/PhysRevA.44.3552; full entry in the
    :ref:`bibliography <ref-allain1991>`.

    Plotnick, Gardner and O'Neill (1993), doi:10.1007/BF00125351; full entry in the
    :ref:`bibliography <ref-plotnick1993>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> lac = fg.lacunarity(np.ones((32, 32), dtype=bool), box_sizes=[1, 2, 4])
    >>> lac.box_sizes.tolist(), lac.lacunarity.tolist()
    ([1, 2, 4], [1.0, 1.0, 1.0])
    """

    box_sizes: np.ndarray
    lacunarity: np.ndarray
    n_boxes: np.ndarray

    def plot(self, ax=None):
        """log-log plot of ``Lambda(r)``; returns the axes."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(4.5, 3.6))
        ax.loglog(self.box_sizes, self.lacunarity, "o-")
        ax.set_xlabel("box side r (pixels)")
        ax.set_ylabel("lacunarity Λ(r)")
        return ax


@keyword_only_since(["box_sizes"], since="0.2.0")
def lacunarity(data, *, box_sizes: Optional[Sequence[int]] = None) -> Lacunarity:
    """Gliding-box lacunarity of a binary or grayscale 2D array.

    Parameters
    ----------
    data : array_like, shape (rows, cols)
        Bool (mass = number of True pixels in the box) or real values (mass =
        sum; values should be non-negative, e.g. intensities). Boxes holding a
        NaN are not used.
    box_sizes : sequence of int, optional
        Box sides; default ``1, 2, 4, ...`` up to a quarter of the shorter side.

    Returns
    -------
    Lacunarity

    References
    ----------
    Allain and Cloitre (1991), doi:10.1103/PhysRevA.44.3552; full entry in the
    :ref:`bibliography <ref-allain1991>`.

    Plotnick, Gardner and O'Neill (1993), doi:10.1007/BF00125351; full entry in the
    :ref:`bibliography <ref-plotnick1993>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> full = fg.lacunarity(np.ones((32, 32), dtype=bool), box_sizes=[1, 2, 4])
    >>> full.lacunarity.tolist()  # a full set has no gaps: Lambda = 1
    [1.0, 1.0, 1.0]
    >>> half = np.zeros((32, 32), dtype=bool); half[:, ::2] = True
    >>> fg.lacunarity(half, box_sizes=[1]).lacunarity.tolist()  # single pixels: Lambda(1) = 1 / fill fraction
    [2.0]
    """
    arr = as_array(data)
    if arr.ndim != 2:
        raise ValueError(f"data: expected a 2D array, got {arr.ndim} dimensions")
    if arr.size == 0:
        raise ValueError("data: array is empty")
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"data: expected a bool or real array, got dtype {arr.dtype}")
    z = arr.astype(np.float64)
    if np.isinf(z).any():
        raise ValueError("data: contains inf")
    nan = np.isnan(z)
    if nan.all():
        raise ValueError("data: no valid value (all NaN)")
    if (z[~nan] < 0).any():
        raise ValueError("data: lacunarity needs non-negative masses (e.g. intensity, not dB)")
    if box_sizes is None:
        box_sizes = [2**k for k in range(20) if 2**k <= min(z.shape) / 4]
    sizes = sorted(set(check_positive_int(v, "box_sizes") for v in as_list(box_sizes, "box_sizes", "ints")))
    if not sizes or sizes[-1] > min(z.shape):
        raise ValueError(f"box_sizes: sizes must be in [1, {min(z.shape)}], got {sizes}")
    holes = bool(nan.any())
    zz = np.where(nan, 0.0, z) if holes else z
    sat = np.zeros((z.shape[0] + 1, z.shape[1] + 1))
    np.cumsum(zz, axis=0, out=sat[1:, 1:])
    np.cumsum(sat[1:, 1:], axis=1, out=sat[1:, 1:])
    if holes:
        nsat = np.zeros_like(sat)
        nsat[1:, 1:] = nan.astype(float).cumsum(0).cumsum(1)
    lam, nb = [], []
    for r in sizes:
        box = lambda s: s[r:, r:] - s[:-r, r:] - s[r:, :-r] + s[:-r, :-r]  # noqa: E731
        m = box(sat)
        if holes:
            m = m[box(nsat) == 0]
        mean = m.mean() if m.size else np.nan
        lam.append(float(np.mean(m**2) / mean**2) if m.size and mean > 0 else np.nan)
        nb.append(int(m.size))
    return Lacunarity(np.asarray(sizes), np.asarray(lam), np.asarray(nb))
