"""Minkowski sausage, Voss's P(m, L) mass dimension and Peleg's covering
blanket.

References
----------
Mandelbrot, B. B. (1982). *The Fractal Geometry of Nature*. Freeman
(Minkowski-Bouligand dimension; the paper's section 2.3, figure 1).
Voss, R. F. (1986). Characterization and measurement of random fractals.
*Physica Scripta* T13, 27-32 (the paper's eq. 13).
Peleg, S., Naor, J., Hartley, R., Avnir, D. (1984). Multiple resolution
texture analysis and classification. *IEEE Trans. PAMI* 6(4), 518-523.
"""
from __future__ import annotations

from typing import Optional, Sequence, Union

import numpy as np

from fractalgeo_rs._validation import as_array, as_list, check_choice, check_n_threads, check_positive_int
from fractalgeo_rs._zscale import resolve_z_scale
from fractalgeo_rs.dimension.boxcount import binary_bytes
from fractalgeo_rs.dimension._common import real_array, with_nodata
from fractalgeo_rs.fit import DimensionFit, ScaleRange, fit_loglog

__all__ = ["minkowski", "mass_dimension", "blanket"]


#: The default radii of :func:`minkowski` reach at least this far (samples).
MIN_DEFAULT_RADIUS = 4


def _radii_default(extent: float) -> np.ndarray:
    out = [r for r in np.unique(np.round(np.geomspace(1, max(extent / 8, MIN_DEFAULT_RADIUS), 12)).astype(int))
           if r >= 1]
    return np.asarray(out, dtype=float)


def minkowski(data, *, radii: Optional[Sequence[float]] = None, scale_range: ScaleRange = None) -> DimensionFit:
    """Minkowski-Bouligand (sausage) dimension of a binary set.

    The set is dilated by balls of radius ``r`` (exact Euclidean distance
    transform, ``scipy.ndimage.distance_transform_edt``); the volume of the
    dilated set ("the sausage") scales as ``V(r) ~ r^(n - D)``, so

        D = n - slope

    with ``n`` the dimension of the array (paper section 2.3, figure 1).

    Parameters
    ----------
    data : array_like of bool, shape (n,), (rows, cols) or (planes, rows, cols)
        The set; as in :func:`box_counting` (0/1 numbers accepted, NaN refused).
    radii : sequence of float, optional
        Radii in samples; default 12 geometric steps from 1 to an eighth of
        the set's extent (a set spanning fewer than 32 samples needs explicit
        radii). The array is padded by the largest radius, so the sausage is
        never cut by the array edge. Radii on both sides of the set's extent
        mix two regimes (the set, and the set seen as a point) and raise
        ``ValueError``; so does a set filling the whole array.

    Returns
    -------
    DimensionFit
        ``measures`` are the sausage volumes (samples within distance ``r``
        of the set, the set included).

    References
    ----------
    B. Dubuc, J. F. Quiniou, C. Roques-Carmes, C. Tricot and S. W. Zucker,
    Evaluating the fractal dimension of profiles, *Physical Review A* 39
    (1989) 1500-1512, doi:10.1103/PhysRevA.39.1500.

    Datcu and Seidel (1994), the seed paper; full entry in the :ref:`bibliography <ref-datcu1994>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> point = np.zeros((101, 101), dtype=bool); point[50, 50] = True
    >>> abs(round(fg.minkowski(point, radii=[4, 8, 16, 32]).dimension, 1))  # V(r) = pi r^2: D = 2 - 2 = 0
    0.0
    >>> land, info = fg.data.kilauea_land_mask()
    >>> coast = land & ~np.roll(land, 1, axis=0)  # land pixels with sea to the north
    >>> round(fg.minkowski(coast).dimension, 2)
    0.99
    """
    from scipy.ndimage import distance_transform_edt

    b, transposed = binary_bytes(data)
    mask = b.view(bool)
    coords = np.argwhere(mask)
    if coords.size == 0:
        raise ValueError("data: the set is empty (no foreground sample)")
    if mask.all() and mask.size > 1:
        raise ValueError(f"data: the set fills the whole array (shape {mask.shape}, every sample is foreground): "
                         f"its sausage only grows at the array's border, which says nothing of the set")
    extent = float((coords.max(axis=0) - coords.min(axis=0)).max() + 1)
    if radii is None:
        if extent < 8 * MIN_DEFAULT_RADIUS:
            raise ValueError(f"data: the set spans {extent:g} samples, too small for the default radii (1 to an "
                             f"eighth of the extent, at least 1..{MIN_DEFAULT_RADIUS}: a set of at least "
                             f"{8 * MIN_DEFAULT_RADIUS} samples); give radii")
        r = _radii_default(extent)
    else:
        try:
            r = np.asarray(sorted(set(float(v) for v in as_list(radii, "radii"))))
        except ValueError:
            raise ValueError(f"radii: expected positive numbers, got {radii!r}") from None
        if r.size < 3 or r[0] <= 0 or not np.isfinite(r).all():
            raise ValueError(f"radii: need at least 3 distinct positive radii, got {list(radii)}")
        if r[0] < extent <= r[-1]:
            raise ValueError(f"radii: {r[0]:g}..{r[-1]:g} straddle the set's extent ({extent:g} samples): below it "
                             f"the sausage measures the set, above it the set looks like a point (D = 0); use "
                             f"radii well below the extent")
    pad = int(np.ceil(r[-1])) + 1
    lo = coords.min(axis=0)
    hi = coords.max(axis=0) + 1
    crop = mask[tuple(slice(a, z) for a, z in zip(lo, hi))]
    padded = np.pad(crop, pad)
    dist = distance_transform_edt(~padded)
    d = np.sort(dist.ravel())
    vol = np.searchsorted(d, r, side="right").astype(float)
    n = mask.ndim
    return fit_loglog(r, vol, method="minkowski", domain=(0.0, float(mask.ndim)), dim_offset=float(n), dim_factor=-1.0, scale_range=scale_range,
                      x_label="radius r (samples)", y_label="sausage volume V(r)")


def summed_area_table(a: np.ndarray) -> np.ndarray:
    """Summed-area table with a zero first row and column."""
    s = np.zeros((a.shape[0] + 1, a.shape[1] + 1), dtype=np.float64)
    s[1:, 1:] = a.cumsum(0).cumsum(1)
    return s


def _box_sums_centred(sat: np.ndarray, ij: np.ndarray, half: int, shape) -> np.ndarray:
    r0 = np.clip(ij[:, 0] - half, 0, shape[0])
    r1 = np.clip(ij[:, 0] + half + 1, 0, shape[0])
    c0 = np.clip(ij[:, 1] - half, 0, shape[1])
    c1 = np.clip(ij[:, 1] + half + 1, 0, shape[1])
    return sat[r1, c1] - sat[r0, c1] - sat[r1, c0] + sat[r0, c0]


def mass_dimension(
    data,
    *,
    box_sizes: Optional[Sequence[int]] = None,
    kind: str = "auto",
    z_scale: Union[float, str] = "range",
    scale_range: ScaleRange = None,
    n_threads: Optional[int] = None,
) -> DimensionFit:
    """Voss's (1986) P(m, L) dimension (the paper's eq. 13).

    A box of side ``L`` is centred on every point of the set; ``P(m, L)`` is
    the fraction of points whose box holds ``m`` points, and

    .. math:: N(L) = \\sum_{m} \\frac{P(m, L)}{m} \\propto L^{-D}.

    Parameters
    ----------
    data : array_like
        ``kind="binary"``: a 2D binary image (points are the foreground
        pixels); ``kind="points"``: an (N, d) coordinate array; ``kind=
        "grayscale"``: a 2D image read as the 3D point set ``(i, j, z)`` with
        ``z = value / z_scale`` (the variant used on SAR in the paper).
        ``"auto"`` picks binary for bool arrays and grayscale for other 2D arrays.
    box_sizes : sequence of int, optional
        Odd box sides (in samples, or coordinate units for points); default
        ``3, 5, 9, 17, ...`` up to an eighth of the extent (for grayscale
        images at most 33: each box costs L^2 comparisons per pixel, done in
        Rust).
    z_scale : float, "auto" or "range", default "range"
        Grayscale only: intensity units per pixel. ``"range"``: ``(max - min)
        / max(rows, cols)`` as in DBC; ``"auto"``: ``1.4826 * median |lag-1
        increment|``. NaN pixels are not points.
    scale_range : None, "auto" or (float, float)
        Range of box sides fitted (see :func:`~fractalgeo_rs.box_counting`).
    n_threads : int, optional
        Threads of the grayscale kernel (default all cores); results are
        identical for any value.

    Returns
    -------
    DimensionFit
        ``measures`` are ``N(L)``; boxes are clipped at the data edge.

    References
    ----------
    Voss (1986), doi:10.1088/0031-8949/1986/T13/004; full entry in the
    :ref:`bibliography <ref-voss1986>`.

    Datcu and Seidel (1994), the seed paper; full entry in the :ref:`bibliography <ref-datcu1994>`.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> round(fg.mass_dimension(np.ones((128, 128), dtype=bool)).dimension, 1)  # a filled plane: D = 2
    2.0
    """
    check_choice(kind, "kind", ("auto", "binary", "points", "grayscale"))
    arr = as_array(data)
    if kind == "auto":
        kind = "binary" if arr.dtype == bool else "grayscale"
    if kind == "binary":
        b, _ = binary_bytes(arr)
        mask = b.view(bool)
        if mask.ndim != 2:
            raise ValueError(f"data: expected a 2D binary image, got {mask.ndim} dimensions")
        ij = np.argwhere(mask)
        if ij.size == 0:
            raise ValueError("data: the set is empty (no foreground sample)")
        extent = float(max(mask.shape))
    elif kind == "points":
        pts = real_array(arr, (2,), "data")
        if np.isnan(pts).any():
            raise ValueError("data: coordinates must be finite (no NaN)")
        extent = float((pts.max(0) - pts.min(0)).max())
    else:
        z = real_array(arr, (2,), "data")
        ok = ~np.isnan(z)
        if not ok.any():
            raise ValueError("data: no valid value (all NaN)")
        zmin = float(z[ok].min())
        z_unit = resolve_z_scale(z_scale, z)
        extent = float(max(z.shape))
    if box_sizes is None:
        # grayscale boxes cost L^2 per pixel: up to 33 pixels by default
        limit = extent / 8 if kind != "grayscale" else min(33.0, extent / 8)
        sizes = [2**k + 1 for k in range(1, 30) if 2**k + 1 <= limit]
    else:
        sizes = sorted(set(check_positive_int(v, "box_sizes") for v in as_list(box_sizes, "box_sizes", "ints")))
    if len(sizes) < 3:
        raise ValueError(f"box_sizes: need at least 3 distinct sizes, got {sizes} (data extent {extent:g})")
    if any(s % 2 == 0 for s in sizes) and kind in ("binary", "grayscale"):
        raise ValueError(f"box_sizes: boxes centred on pixels need odd sides, got {sizes}")
    N = []
    if kind == "binary":
        sat = summed_area_table(mask.astype(np.float64))
        for L in sizes:
            m = _box_sums_centred(sat, ij, L // 2, mask.shape)
            N.append(float(np.mean(1.0 / m)))
    elif kind == "grayscale":
        # Rust kernel (shared with the fractal transform): box masses per pixel
        from fractalgeo_rs import _core

        N = _core.mass_curve_image(np.ascontiguousarray(z - zmin), sizes, z_unit, check_n_threads(n_threads)).tolist()
    else:
        from scipy.spatial import cKDTree

        tree = cKDTree(pts)
        for L in sizes:
            m = tree.query_ball_point(pts, r=L / 2.0, p=np.inf, return_length=True)
            N.append(float(np.mean(1.0 / np.asarray(m, dtype=float))))
    dom = (2.0, 3.0) if kind == "grayscale" else (0.0, float(mask.ndim if kind == "binary" else pts.shape[1]))
    return fit_loglog(sizes, N, method="mass", domain=dom, dim_offset=0.0, dim_factor=-1.0, scale_range=scale_range,
                      x_label="box side L", y_label="N(L) = sum P(m,L)/m", extra={"kind": kind, **({"z_scale": z_unit} if kind == "grayscale" else {})})


#: Fewest rows and columns (and ``BLANKET_MIN_SIDE**2`` valid samples) of a
#: surface for :func:`blanket`.
BLANKET_MIN_SIDE = 3


def blanket(data, *, epsilons: Optional[Sequence[int]] = None, z_scale: Union[float, str] = "range",
            nodata: Optional[float] = None, scale_range: ScaleRange = None,
            n_threads: Optional[int] = None) -> DimensionFit:
    """Covering-blanket dimension of a grayscale surface (Peleg et al. 1984).

    Upper and lower blankets grow one step at a time,

    .. math::

        u_\\epsilon = \\max(u_{\\epsilon-1} + 1, \\max_{N} u_{\\epsilon-1}), \\qquad
        b_\\epsilon = \\min(b_{\\epsilon-1} - 1, \\min_{N} b_{\\epsilon-1}),

    from ``u_0 = b_0 = z / z_scale`` over the 4-neighbourhood ``N`` (clipped
    at the edge of the data); the area is ``A(epsilon) = sum(u - b) /
    (2 epsilon)`` over the valid pixels and ``A ~ epsilon^(2 - D)``, so
    ``D = 2 - slope`` of ``log A`` against ``log epsilon``.

    Parameters
    ----------
    data : array_like, shape (rows, cols)
        Grayscale surface, at least 3 x 3 with 9 valid samples
        (``ValueError`` below). NaN and ``nodata`` are missing samples: they are
        not part of the surface, hold no blanket and pass none on (blankets
        grow around holes, as at the edge of the data).
    epsilons : sequence of int, optional
        Blanket thicknesses used in the fit; default ``1 .. 16`` (every
        thickness up to the largest is computed).
    z_scale : float, "auto" or "range", default "range"
        Value units per blanket step: the blanket grows by ``z_scale`` data
        units per step. ``"range"``: ``(max - min) / max(rows, cols)``;
        ``"auto"``: ``1.4826 * median |lag-1 increment|`` (both scale with the
        data, so D does not depend on the height unit).
    nodata : float, optional
        Value marking missing data, in addition to NaN.
    scale_range : None, "auto" or (float, float)
        As in :func:`fractalgeo_rs.fit.fit_loglog`.
    n_threads : int, optional
        Threads (default all cores); results are identical for any value.

    Returns
    -------
    DimensionFit
        ``D = 2 - slope``; ``measures`` are the areas ``A(epsilon)`` (in
        pixels times ``z_scale`` units); ``extra`` holds ``z_scale`` and
        ``n_valid``.

    Notes
    -----
    The growth runs in Rust (rows in bands of 128 with a halo of
    ``max(epsilons)`` rows, GIL released), the same step as the moving-window
    map ``fractal_transform(method="blanket")``.

    References
    ----------
    Peleg, S., Naor, J., Hartley, R., Avnir, D. (1984). Multiple resolution
    texture analysis and classification. *IEEE Trans. PAMI* 6(4), 518-523.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> i, j = np.indices((64, 64))
    >>> round(fg.blanket(0.5 * i + 0.25 * j).dimension, 6)
    2.0
    """
    from fractalgeo_rs import _core
    from fractalgeo_rs._validation import check_n_threads

    z = with_nodata(real_array(data, (2,)), data, nodata)
    if np.isnan(z).all():
        raise ValueError("data: no valid value (all NaN or nodata)")
    if np.isinf(z).any():
        raise ValueError("data: contains inf; mark invalid samples with NaN or nodata")
    n_ok = int(np.count_nonzero(~np.isnan(z)))
    if min(z.shape) < BLANKET_MIN_SIDE or n_ok < BLANKET_MIN_SIDE ** 2:
        raise ValueError(f"data: the covering blanket needs a surface of at least {BLANKET_MIN_SIDE} x "
                         f"{BLANKET_MIN_SIDE} valid samples, got shape {z.shape} with {n_ok} valid (a smaller "
                         f"surface is all edge: its blanket measures the border, not the surface)")
    zs = resolve_z_scale(z_scale, z)
    eps = list(range(1, 17)) if epsilons is None else sorted(set(check_positive_int(e, "epsilons") for e in as_list(epsilons, "epsilons", "ints")))
    if len(eps) < 3:
        raise ValueError(f"epsilons: need at least 3 distinct thicknesses, got {eps}")
    areas, n_valid = _core.blanket_areas_image(np.ascontiguousarray(z, dtype=np.float64), eps[-1], zs,
                                               check_n_threads(n_threads))
    return fit_loglog(eps, [float(areas[e - 1]) for e in eps], method="blanket", domain=(2.0, 3.0), dim_offset=2.0, dim_factor=-1.0,
                      scale_range=scale_range, x_label="epsilon", y_label="blanket area A(epsilon)",
                      extra={"z_scale": zs, "n_valid": int(n_valid)})
