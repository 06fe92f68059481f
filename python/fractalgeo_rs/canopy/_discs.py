"""Homogeneous canopies of disc leaves in a periodic tile (RAMI's HOM scenes)."""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Optional, Tuple, Union

import numpy as np

from fractalgeo_rs._validation import check_positive_float, check_positive_int, check_seed
from fractalgeo_rs.canopy._lad import check_lad, normals_from_uniforms, projection_g
from fractalgeo_rs.geometry import Mesh
from fractalgeo_rs.radiometry import BiLambertian, Hapke, Lambertian, OrenNayar, Phong, Scene

__all__ = ["DiscCanopy", "disc_canopy"]

#: RAMI's near-infrared leaf and soil (Pinty et al. 2001, HOM scenes).
RAMI_NIR_LEAF = BiLambertian(0.4957, 0.4409)
RAMI_NIR_SOIL = Lambertian(0.159)

#: Material ids of the triangles (the mesh's ``kinds``): soil, leaves.
SOIL, LEAF = 0, 1

_SOILS = (Lambertian, OrenNayar, Phong, Hapke)


@dataclass(frozen=True, eq=False)
class DiscCanopy:
    """A periodic tile of disc leaves over a flat soil, as a triangle mesh.

    Attributes
    ----------
    mesh : fractalgeo_rs.geometry.Mesh
        One period of the canopy: the soil (two triangles covering the tile
        at height 0) and the leaf polygons as fans of ``sides - 2``
        triangles, each triangle shifted by whole tiles so that its centroid
        lies in the tile (a leaf crossing a tile edge is cut into pieces on
        both sides, which join in a periodic scene, where rays leaving one
        side re-enter the opposite one). ``mesh.kinds`` is the material id
        of each triangle (0 soil, 1 leaf) and ``mesh.part_ids`` the leaf
        number (0 for the soil). Origin ``(0, 0, 0)``: the tile is ``[0,
        extent[0]) x [0, extent[1])``, metres.
    material_ids : numpy.ndarray of uint32, shape (T,)
        ``mesh.kinds`` as uint32: the index into ``materials``.
    materials : tuple
        ``(soil, leaf)``.
    centres, normals : numpy.ndarray, shape (N, 3)
        Leaf centres (in the tile) and unit normals (pointing up).
    leaf_radius : float
        The disc radius ``r``; each leaf is a regular polygon of
        ``sides`` sides with the disc's area ``pi r^2`` (its circumradius
        is ``r sqrt(2 pi / (sides sin(2 pi / sides)))``).
    leaf_area : float
        ``a = pi r^2``, one side, square metres.
    lai : float
        The realised leaf area index ``N a / A`` (the requested one rounded
        to a whole number of leaves).
    lad : str or float
        The leaf angle distribution.
    extent : (float, float)
        Tile size east-west and north-south, metres.
    height : (float, float)
        The range of the leaf-centre heights, metres.
    overlap : bool
        Whether leaves were placed independently (and may intersect).
    seed : int
        The seed the placement used.

    Examples
    --------
    >>> from fractalgeo_rs.canopy import disc_canopy
    >>> c = disc_canopy(lai=1.0, leaf_radius=0.1, extent=2.0, height=(0.2, 1.0), seed=3)
    >>> c.n_leaves, round(c.lai, 4), c.materials[1]
    (127, 0.9975, BiLambertian(reflectance=0.4957, transmittance=0.4409))

    References
    ----------
    B. Pinty et al., "Radiation transfer model intercomparison (RAMI)
    exercise", *J. Geophys. Res.* 106(D11) (2001) 11937-11956,
    doi:10.1029/2000JD900493.
    """

    mesh: Mesh
    material_ids: np.ndarray
    materials: tuple
    centres: np.ndarray
    normals: np.ndarray
    leaf_radius: float
    leaf_area: float
    lai: float
    lad: Union[str, float]
    extent: Tuple[float, float]
    height: Tuple[float, float]
    overlap: bool
    seed: int

    @property
    def n_leaves(self) -> int:
        """Number of leaves ``N``."""
        return int(len(self.centres))

    def __repr__(self) -> str:
        return (f"DiscCanopy({self.n_leaves} leaves of radius {self.leaf_radius}, lai={self.lai:.6g}, "
                f"lad={self.lad!r}, extent={self.extent}, height={self.height}, overlap={self.overlap}, "
                f"{len(self.mesh)} triangles)")

    def scene(self) -> Scene:
        """The canopy as a periodic radiometric scene: the mesh over the
        tile ``(0, 0, extent)``, material 0 the soil and 1 the leaves
        (two-sided facets), so the scene's ``brf``, ``albedo``, ``render``,
        ``gap_fraction`` and ``absorption`` apply.

        Returns
        -------
        fractalgeo_rs.radiometry.Scene

        Examples
        --------
        >>> from fractalgeo_rs.canopy import disc_canopy
        >>> s = disc_canopy(lai=1.0, leaf_radius=0.1, extent=2.0, height=(0.2, 1.0), seed=3).scene()
        >>> s.materials[1], s.periodic
        (BiLambertian(reflectance=0.4957, transmittance=0.4409), True)

        References
        ----------
        B. Pinty et al., 2001 (see ``DiscCanopy``): cyclic boundary
        conditions.
        """
        return Scene.from_mesh(self.mesh, materials=list(self.materials), material_ids=self.material_ids,
                               periodic=True, extent=(0.0, 0.0, self.extent[0], self.extent[1]))

    def gap_probability(self, zenith):
        """The exact gap probability of this canopy's leaf statistics:
        ``(1 - a G(theta) / (A cos theta))^N`` for ``N`` leaves of area
        ``a`` placed independently (``overlap=True``) in a tile of area
        ``A``, with ``G`` of the leaf angle distribution.

        A planar leaf of area ``a`` and normal ``n`` casts a shadow of area
        ``a |n . w| / cos theta`` on the soil along the direction ``w`` of
        zenith ``theta``, whatever its outline, so the polygons give the
        same value as discs. For non-overlapping leaves this is only
        approximate.

        Parameters
        ----------
        zenith : float or array_like
            Zenith in degrees, [0, 90).

        Returns
        -------
        float or numpy.ndarray
            Probability that a ray at ``zenith`` reaches the soil.

        Examples
        --------
        >>> from fractalgeo_rs.canopy import disc_canopy
        >>> c = disc_canopy(lai=2.0, leaf_radius=0.05, extent=1.0, height=(0.1, 1.0), seed=0)
        >>> round(float(c.gap_probability(0.0)), 4), round(float(np.exp(-0.5 * c.lai)), 4)  # Beer
        (0.3666, 0.3674)

        References
        ----------
        J. Ross, *The Radiation Regime and Architecture of Plant Stands*,
        Junk, The Hague, 1981.
        """
        th = np.asarray(zenith, dtype=np.float64)
        if not np.all((th >= 0.0) & (th < 90.0)):
            raise ValueError(f"zenith: expected degrees in [0, 90), got {zenith!r}")
        area = self.extent[0] * self.extent[1]
        shadow = self.leaf_area * projection_g(self.lad, th) / (area * np.cos(np.radians(th)))
        out = np.clip(1.0 - shadow, 0.0, 1.0) ** self.n_leaves
        return float(out) if np.ndim(out) == 0 else out


def _pair(value, name: str) -> Tuple[float, float]:
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        v = check_positive_float(value, name)
        return (v, v)
    try:
        a, b = value
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected a number or a pair of numbers, got {value!r}") from None
    return (check_positive_float(a, name), check_positive_float(b, name))


def _height(value, radius: float) -> Tuple[float, float]:
    try:
        lo, hi = value
    except (TypeError, ValueError):
        raise TypeError(f"height: expected (bottom, top) in metres, got {value!r}") from None
    for v in (lo, hi):
        if isinstance(v, bool) or not isinstance(v, numbers.Real) or not math.isfinite(float(v)):
            raise ValueError(f"height: expected finite (bottom, top) in metres, got {value!r}")
    lo, hi = float(lo), float(hi)
    if hi < lo:
        raise ValueError(f"height: expected bottom <= top, got ({lo}, {hi})")
    if lo < radius:
        raise ValueError(f"height: the bottom ({lo}) must be at least the leaf polygon's circumradius "
                         f"({radius:.6g} m) so that no leaf reaches the soil")
    return lo, hi


def _frames(n: np.ndarray):
    """Orthonormal ``(t, b)`` completing each unit normal (Duff et al. 2017)."""
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], axis=1)
    bb = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return t, bb


def _discs_intersect(c1, n1, c2, n2, radius: float) -> np.ndarray:
    """Whether the discs ``(c1, n1)`` and ``(c2, n2)`` of radius ``radius``
    intersect (exact: the chords the two discs cut on the line where their
    planes meet overlap). Arrays of shape (k, 3)."""
    d = c2 - c1
    cr = np.cross(n1, n2)
    s = np.linalg.norm(cr, axis=1)
    parallel = s < 1e-12
    s_safe = np.where(parallel, 1.0, s)
    u = cr / s_safe[:, None]
    w = np.cross(u, n1)
    lam = np.einsum("ij,ij->i", n2, d) / s_safe
    q = c1 + lam[:, None] * w
    e = c2 - q
    t2 = np.einsum("ij,ij->i", u, e)
    h2sq = np.einsum("ij,ij->i", e, e) - t2 * t2
    r2 = radius * radius
    a1 = np.sqrt(np.maximum(0.0, r2 - lam * lam))
    a2 = np.sqrt(np.maximum(0.0, r2 - h2sq))
    crossing = (lam * lam <= r2) & (h2sq <= r2) & (np.abs(t2) <= a1 + a2)
    coplanar = (np.abs(np.einsum("ij,ij->i", n1, d)) <= 1e-12 * radius) & (np.linalg.norm(d, axis=1) <= 2 * radius)
    return np.where(parallel, coplanar, crossing)


def _min_image(d: np.ndarray, ext: Tuple[float, float]) -> np.ndarray:
    d = d.copy()
    for k in (0, 1):
        d[:, k] -= ext[k] * np.round(d[:, k] / ext[k])
    return d


def _place_without_overlap(n, draw, radius, ext, height, max_attempts):
    """Random sequential addition: candidates in order, each kept when its
    disc meets none of those kept before (periodic in x and y)."""
    from scipy.spatial import cKDTree

    lz = height[1] + 4.0 * radius + 1.0  # a z period no pair can wrap across
    box = (ext[0], ext[1], lz)
    kept_c = np.empty((0, 3))
    kept_n = np.empty((0, 3))
    kept_u = np.empty((0,))
    tried = 0
    while len(kept_c) < n and tried < max_attempts:
        m = int(min(max(256, 2 * (n - len(kept_c))), max_attempts - tried))
        c, nr, rot = draw(m)
        tried += m
        ok = np.ones(m, dtype=bool)
        if len(kept_c):
            tree = cKDTree(np.mod(kept_c, box), boxsize=box)
            near = tree.query_ball_point(np.mod(c, box), 2.0 * radius)
            ii = np.repeat(np.arange(m), [len(v) for v in near])
            jj = np.fromiter((j for v in near for j in v), dtype=np.int64, count=len(ii))
            if len(ii):
                d = _min_image(kept_c[jj] - c[ii], ext)
                hit = _discs_intersect(c[ii], nr[ii], c[ii] + d, kept_n[jj], radius)
                ok[ii[hit]] = False
        pairs = cKDTree(np.mod(c, box), boxsize=box).query_pairs(2.0 * radius, output_type="ndarray")
        conflicts: dict = {}
        if len(pairs):
            i, j = pairs.min(axis=1), pairs.max(axis=1)
            d = _min_image(c[j] - c[i], ext)
            hit = _discs_intersect(c[i], nr[i], c[i] + d, nr[j], radius)
            for a, b in zip(i[hit].tolist(), j[hit].tolist()):
                conflicts.setdefault(b, []).append(a)
        take = np.zeros(m, dtype=bool)
        for k in range(m):
            if ok[k] and not any(take[a] for a in conflicts.get(k, ())):
                take[k] = True
        idx = np.flatnonzero(take)[: n - len(kept_c)]
        kept_c = np.concatenate([kept_c, c[idx]])
        kept_n = np.concatenate([kept_n, nr[idx]])
        kept_u = np.concatenate([kept_u, rot[idx]])
    return kept_c, kept_n, kept_u, tried


def _build_mesh(centres, normals, rot, circumradius, sides, ext) -> Mesh:
    n = len(centres)
    t, b = _frames(normals)
    ang = rot[:, None] + 2.0 * np.pi * np.arange(sides)[None, :] / sides  # (N, k)
    ca, sa = np.cos(ang), np.sin(ang)
    poly = centres[:, None, :] + circumradius * (ca[..., None] * t[:, None, :] + sa[..., None] * b[:, None, :])
    fan = np.stack([np.zeros(sides - 2, dtype=np.int64), np.arange(1, sides - 1), np.arange(2, sides)], axis=1)
    # one period: each triangle shifted by whole tiles so its centroid lies in the tile (a leaf crossing
    # an edge is cut along its fan; the periodic scene sees the pieces join across the edge)
    tri = poly[:, fan, :]  # (N, k - 2, 3, 3)
    cen = tri.mean(axis=2)
    for k in (0, 1):
        tri[..., k] -= (np.floor(cen[..., k] / ext[k]) * ext[k])[..., None]
    m = n * (sides - 2)
    verts = tri.reshape(-1, 3)
    nrm = np.repeat(normals, 3 * (sides - 2), axis=0)
    corner = 2 * np.pi * np.arange(sides) / sides
    uv_poly = np.stack([0.5 + 0.5 * np.cos(corner), 0.5 + 0.5 * np.sin(corner)], axis=1)
    uv_leaf = np.tile(uv_poly[fan].reshape(-1, 2), (n, 1))
    faces_leaf = 4 + np.arange(3 * m, dtype=np.int64).reshape(-1, 3)
    soil_v = np.array([[0.0, 0.0, 0.0], [ext[0], 0.0, 0.0], [ext[0], ext[1], 0.0], [0.0, ext[1], 0.0]])
    soil_f = np.array([[0, 1, 2], [0, 2, 3]])
    vertices = np.concatenate([soil_v, verts]).astype(np.float32)
    normals_v = np.concatenate([np.tile([0.0, 0.0, 1.0], (4, 1)), nrm]).astype(np.float32)
    uvs = np.concatenate([[[0, 0], [1, 0], [1, 1], [0, 1]], uv_leaf]).astype(np.float32)
    faces = np.concatenate([soil_f, faces_leaf]).astype(np.uint32)
    nt = len(faces)
    kinds = np.concatenate([np.zeros(2), np.ones(len(faces_leaf))]).astype(np.uint8)
    part_ids = np.concatenate([np.zeros(2, dtype=np.int64), np.repeat(np.arange(n), sides - 2)]).astype(np.uint32)
    return Mesh(vertices=vertices, normals=normals_v, uvs=uvs, faces=faces, part_ids=part_ids, kinds=kinds,
                colors=np.zeros(nt, dtype=np.uint32), instances=np.zeros(nt, dtype=np.uint32),
                origin=(0.0, 0.0, 0.0)).validate()


def disc_canopy(*, lai, leaf_radius, extent, height, lad="spherical", overlap: bool = True,
                leaf: Optional[BiLambertian] = None, soil=None, sides: int = 12, seed=None,
                max_attempts: Optional[int] = None) -> DiscCanopy:
    """A homogeneous canopy of disc leaves over a flat soil in a periodic
    tile, RAMI's "HOM" discrete scenes.

    ``N = round(lai * A / (pi r^2))`` leaves of radius ``r`` in a tile of
    area ``A``: centres uniform in the tile and in the height range, normals
    drawn from the leaf angle distribution (uniform azimuth), each leaf a
    regular polygon turned by a uniform angle in its plane. The polygon has
    the disc's area ``pi r^2``: the projected area of any planar leaf of
    area ``a`` along a direction ``w`` is ``a |n . w|`` whatever its outline,
    so the gap fraction of the polygons is the disc canopy's, exactly
    (:meth:`DiscCanopy.gap_probability`).

    Parameters
    ----------
    lai : float
        Leaf area index (one-sided leaf area per ground area), >= 0.
    leaf_radius : float
        Disc radius ``r``, metres (> 0).
    extent : float or (float, float)
        Tile side, or ``(east-west, north-south)`` sides, metres; larger
        than a leaf.
    height : (float, float)
        ``(bottom, top)``: the range of the leaf-centre heights above the
        soil, metres; ``bottom`` at least the polygon's circumradius, so no
        leaf touches the soil.
    lad : str or float
        Leaf angle distribution: ``"planophile"``, ``"erectophile"``,
        ``"plagiophile"``, ``"extremophile"``, ``"uniform"``,
        ``"spherical"`` (de Wit 1965), or one inclination in degrees.
    overlap : bool
        True: leaves placed independently (they may intersect; the gap
        fraction is then exactly ``(1 - a G / (A cos theta))^N``). False:
        non-overlapping leaves by random sequential addition (each
        candidate kept when it meets no leaf kept before; exact
        disc-disc test on the polygons' circumscribed discs), as in
        RAMI's HOM scenes.
    leaf : BiLambertian, optional
        Leaf optics; default RAMI's near-infrared leaf ``BiLambertian(0.4957,
        0.4409)``.
    soil : Lambertian, OrenNayar, Phong or Hapke, optional
        Soil reflectance model; default RAMI's near-infrared soil
        ``Lambertian(0.159)``.
    sides : int
        Sides of each leaf polygon (>= 3); default 12.
    seed : int, optional
        Seed of the placement (``numpy.random.default_rng``); None: fresh
        entropy.
    max_attempts : int, optional
        Candidates tried before ``overlap=False`` gives up; default
        ``50 N + 10000``.

    Returns
    -------
    DiscCanopy
        The mesh (soil and leaves with their material ids) and the leaf
        statistics.

    Raises
    ------
    ValueError
        ``lai`` negative, ``leaf_radius`` not positive, an unknown ``lad``,
        a leaf larger than the tile (``leaf_radius``), a bad ``height``, or
        (``overlap=False``) leaves that do not fit (``lai``).
    TypeError
        ``leaf`` not a BiLambertian, ``soil`` not a reflectance model.

    Examples
    --------
    >>> from fractalgeo_rs.canopy import disc_canopy
    >>> c = disc_canopy(lai=3.0, leaf_radius=0.05, extent=1.0, height=(0.1, 1.0), lad="erectophile",
    ...                 overlap=False, seed=7)
    >>> c.n_leaves, round(c.lai, 4), len(c.mesh)  # 2 soil triangles, 10 per 12-gon leaf
    (382, 3.0002, 3822)

    References
    ----------
    B. Pinty et al., "Radiation transfer model intercomparison (RAMI)
    exercise", *J. Geophys. Res.* 106(D11) (2001) 11937-11956,
    doi:10.1029/2000JD900493 (HOM scenes: discs over a Lambertian soil).
    C. T. de Wit, *Photosynthesis of Leaf Canopies*, Pudoc, Wageningen, 1965.
    B. Widom, "Random sequential addition of hard spheres to a volume",
    *J. Chem. Phys.* 44 (1966) 3888-3894, doi:10.1063/1.1726548.
    """
    if isinstance(lai, bool) or not isinstance(lai, numbers.Real):
        raise TypeError(f"lai: expected a number >= 0, got {lai!r}")
    lai = float(lai)
    if not math.isfinite(lai) or lai < 0.0:
        raise ValueError(f"lai: expected a finite leaf area index >= 0, got {lai}")
    radius = check_positive_float(leaf_radius, "leaf_radius")
    ext = _pair(extent, "extent")
    lad = check_lad(lad)
    if not isinstance(overlap, (bool, np.bool_)):
        raise TypeError(f"overlap: expected True or False, got {overlap!r}")
    sides = check_positive_int(sides, "sides")
    if sides < 3:
        raise ValueError(f"sides: expected at least 3, got {sides}")
    circum = radius * math.sqrt(2.0 * math.pi / (sides * math.sin(2.0 * math.pi / sides)))
    if 2.0 * circum >= min(ext):
        raise ValueError(f"leaf_radius: a leaf ({2 * circum:.6g} m across) must be smaller than the tile "
                         f"{ext}; raise extent or lower leaf_radius")
    hgt = _height(height, circum)
    leaf = RAMI_NIR_LEAF if leaf is None else leaf
    if not isinstance(leaf, BiLambertian):
        raise TypeError(f"leaf: expected BiLambertian(reflectance, transmittance), got {leaf!r}")
    soil = RAMI_NIR_SOIL if soil is None else soil
    if not isinstance(soil, _SOILS):
        raise TypeError(f"soil: expected Lambertian, OrenNayar, Phong or Hapke, got {soil!r}")
    seed = check_seed(seed)
    area = ext[0] * ext[1]
    leaf_area = math.pi * radius * radius
    n = int(round(lai * area / leaf_area))
    if n > 50_000_000:
        raise ValueError(f"lai: {n} leaves is more than the 5e7 this builder accepts; lower lai or extent")
    rng = np.random.default_rng(seed)

    def draw(m: int):
        u = rng.random((m, 6))
        c = np.stack([u[:, 0] * ext[0], u[:, 1] * ext[1], hgt[0] + u[:, 2] * (hgt[1] - hgt[0])], axis=1)
        return c, normals_from_uniforms(lad, u[:, 3:5]), 2.0 * np.pi * u[:, 5]

    if overlap or n == 0:
        centres, normals, rot = draw(n)
    else:
        if max_attempts is None:
            max_attempts = 50 * n + 10_000
        max_attempts = check_positive_int(max_attempts, "max_attempts")
        centres, normals, rot, tried = _place_without_overlap(n, draw, circum, ext, hgt, max_attempts)
        if len(centres) < n:
            raise ValueError(f"lai: {n} non-overlapping leaves of radius {radius} do not fit in the tile "
                             f"{ext} with centres at heights {hgt} (placed {len(centres)} after {tried} "
                             "candidates). Lower lai or leaf_radius, widen height, or pass overlap=True")
    mesh = _build_mesh(centres, normals, rot, circum, sides, ext)
    centres.setflags(write=False)
    normals.setflags(write=False)
    ids = np.asarray(mesh.kinds, dtype=np.uint32)
    ids.setflags(write=False)
    return DiscCanopy(mesh=mesh, material_ids=ids, materials=(soil, leaf), centres=centres, normals=normals,
                      leaf_radius=radius, leaf_area=leaf_area, lai=n * leaf_area / area, lad=lad, extent=ext,
                      height=hgt, overlap=bool(overlap), seed=seed)
