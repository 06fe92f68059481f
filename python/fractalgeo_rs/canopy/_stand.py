"""A stand of L-system plants placed on a DEM (``plants_on_terrain``), with
bark, leaf and soil materials, as a radiometric scene."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Optional, Tuple, Union

import numpy as np

from fractalgeo_rs._validation import check_seed
from fractalgeo_rs.geometry import Mesh
from fractalgeo_rs.radiometry import BiLambertian, Hapke, Lambertian, OrenNayar, Phong, Scene

__all__ = ["PLANT_PRESETS", "PlantStand", "plant_stand"]

#: The named plants of :func:`plant_stand`.
PLANT_PRESETS = ("bush", "herb")

# name: (rules, derivation steps, branching angle (degrees), scale (metres per turtle step),
#        initial width (turtle steps), width factor, tube sides)
_PRESETS = {
    # ABOP figure 1.25 (Prusinkiewicz and Lindenmayer 1990): a bush with leaves on every segment,
    # 7.8 turtle steps tall after 4 steps; deterministic (plants differ by rotation and position)
    "bush": ("""axiom: A
A -> [&FL!A]/////'[&FL!A]///////'[&FL!A]
F -> S/////F
S -> F L
L -> ['''^^{-f+f+f-|-f+f+f}]
""", 4, 22.5, 0.2, 1.0, 0.7, 4),
    # a stochastic herb in the manner of ABOP figure 1.27 (three equiprobable branchings), leaves
    # on the side branches; every plant differs
    "herb": ("""axiom: F
F -(1)-> F[+FL]/////F[-FL]F
F -(1)-> F[+FL]/////F
F -(1)-> F[-FL]/////F
L -> [^^{-ff+ff+ff-|-ff+ff+ff}]
""", 2, 25.7, 0.08, 0.3, 0.7, 4),
}

#: Material ids of a stand's triangles: soil (the DEM), bark (branches), leaves.
SOIL, BARK, LEAF = 0, 1, 2

_OPAQUE = (Lambertian, OrenNayar, Phong, Hapke)


@dataclass(frozen=True, eq=False)
class PlantStand:
    """L-system plants on a DEM, with per-triangle materials.

    Attributes
    ----------
    mesh : fractalgeo_rs.geometry.Mesh
        The ground (two triangles per square of four DEM cell centres)
        followed by the plants' triangles; map coordinates in metres, the
        DEM's north-west cell centre at ``(dx / 2, (rows - 1/2) dy)``.
        Plant triangles whose centroid lies outside the ground's extent are
        dropped (the sensor sees only the ground's extent). ``mesh.kinds``
        holds the material ids (so a written PLY or OBJ keeps them).
    material_ids : numpy.ndarray of uint32, shape (T,)
        0 soil, 1 bark (the plants' branches, ``kinds == 0``), 2 leaves
        (``kinds == 1``): the index into ``materials``.
    materials : tuple
        ``(soil, bark, leaf)``.
    bases : numpy.ndarray, shape (P, 3)
        The base point of every plant, metres.
    extent : (float, float, float, float)
        ``(x0, y0, width, height)`` of the ground (the cell centres' box).
    leaf_area : float
        One-sided area of the leaf triangles kept, square metres.
    lai : float
        ``leaf_area`` per horizontal ground area of ``extent``.
    plant : str
        The preset's name.
    seed : int
        Seed of the placement and of stochastic plants.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.canopy import plant_stand
    >>> st = plant_stand("herb", 2.0, np.zeros((6, 6)), cell_size=1.0, seed=1)
    >>> len(st.bases), st.extent, st.materials[0]
    (50, (0.5, 0.5, 5.0, 5.0), Lambertian(rho=0.159))

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, section 1.7 (stochastic plants on a terrain).
    """

    mesh: Mesh
    material_ids: np.ndarray
    materials: Tuple
    bases: np.ndarray
    extent: Tuple[float, float, float, float]
    leaf_area: float
    lai: float
    plant: str
    seed: int

    def __repr__(self) -> str:
        return (f"PlantStand({len(self.bases)} {self.plant} plants, lai={self.lai:.6g}, "
                f"{len(self.mesh)} triangles, seed={self.seed})")

    def scene(self) -> Scene:
        """The stand as a finite radiometric scene (``Scene.from_mesh`` with
        ``periodic=False`` over ``extent``; material 0 soil, 1 bark, 2 leaves;
        two-sided facets, leaves transmitting).

        Returns
        -------
        fractalgeo_rs.radiometry.Scene

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.canopy import plant_stand
        >>> s = plant_stand("bush", 0.0, np.zeros((5, 5))).scene()   # no plants: the soil
        >>> round(s.brf(sun=(0.0, 30.0), spp=200).value, 9)
        0.159
        """
        return Scene.from_mesh(self.mesh, materials=list(self.materials), material_ids=self.material_ids,
                               periodic=False, extent=self.extent)


def _areas(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Areas of the triangles ``f`` of the vertices ``v``."""
    return 0.5 * np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)


def _cell(cell_size) -> Tuple[float, float]:
    if isinstance(cell_size, bool):
        raise TypeError(f"cell_size: expected a number or (dy, dx) in metres, got {cell_size!r}")
    try:
        if np.ndim(cell_size) == 0:
            dy = dx = float(cell_size)
        else:
            dy, dx = (float(v) for v in cell_size)
    except (TypeError, ValueError):
        raise TypeError(f"cell_size: expected a number or (dy, dx) in metres, got {cell_size!r}") from None
    if not (math.isfinite(dy) and math.isfinite(dx) and dy > 0 and dx > 0):
        raise ValueError(f"cell_size: expected finite (dy, dx) > 0 metres, got {cell_size!r}")
    return dy, dx


def plant_stand(plant: str, density: float, dem, cell_size: Union[float, Tuple[float, float]] = 1.0, *,
                bark=None, leaf: Optional[BiLambertian] = None, soil=None, scale: Optional[float] = None,
                seed: Optional[int] = None, max_plants: int = 100_000) -> PlantStand:
    """Plants of a preset placed on a DEM, with bark, leaf and soil materials.

    ``round(density * A)`` plants (``A`` the area of the box of the DEM's
    cell centres) are placed by :func:`fractalgeo_rs.lsystem.plants_on_terrain`:
    uniform positions, heights by bilinear interpolation of the DEM, a
    uniform rotation about the vertical, each plant derived with its own
    seed (stochastic presets differ from plant to plant). The ground is the
    DEM's mesh (:meth:`fractalgeo_rs.geometry.Mesh.from_grid`, two
    triangles per square of four cell centres).

    Parameters
    ----------
    plant : str
        One of ``PLANT_PRESETS``: ``"bush"`` (ABOP figure 1.25, 4 steps,
        22.5 degrees, 0.2 m per turtle step: 1.56 m tall, 2.47 m^2 of
        leaves, 1248 triangles) or ``"herb"`` (a stochastic herb after
        ABOP figure 1.27, 2 steps, 25.7 degrees, 0.08 m per step: about
        1 m tall, 0.05-0.06 m^2 of leaves, about 120 triangles).
    density : float
        Plants per square metre (>= 0).
    dem : array_like, shape (rows, cols)
        Heights in metres, at least 2 x 2, finite.
    cell_size : float or (float, float)
        Cell size ``(dy, dx)`` in metres (a number: square cells).
    bark, soil : material, optional
        ``Lambertian``, ``OrenNayar``, ``Phong`` or ``Hapke``; defaults
        ``Lambertian(0.3)`` (bark, the gallery stand's) and RAMI's
        near-infrared soil ``Lambertian(0.159)``.
    leaf : BiLambertian, optional
        Two-sided leaves; default RAMI's near-infrared leaf
        ``BiLambertian(0.4957, 0.4409)``.
    scale : float, optional
        Metres per turtle step (default: the preset's).
    seed : int, optional
        Seed of the placement and of the plants (None: fresh entropy, kept
        in ``PlantStand.seed``).
    max_plants : int
        Safety limit on the number of plants.

    Returns
    -------
    PlantStand

    Raises
    ------
    ValueError
        Naming ``plant``, ``density``, ``dem``, ``cell_size``, ``scale`` or
        ``max_plants``; ``TypeError`` naming ``bark``, ``leaf`` or ``soil``.

    Notes
    -----
    ``plants_on_terrain`` works on square cells; with ``dy != dx`` the
    plants are placed on the grid with ``dx`` cells (density scaled so the
    count is ``round(density * A)``) and each plant is then moved rigidly
    north or south to its base's true position, so shapes keep their
    proportions, positions stay uniform and heights follow the DEM.

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990 (figures 1.25 and 1.27). B. Pinty et al., "Radiation
    transfer model intercomparison (RAMI) exercise", *J. Geophys. Res.*
    106(D11), 11937-11956, 2001 (the default leaf and soil).

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.canopy import plant_stand
    >>> st = plant_stand("bush", 0.05, np.zeros((21, 21)), cell_size=1.0, seed=1)
    >>> len(st.bases), st.materials[2]
    (20, BiLambertian(reflectance=0.4957, transmittance=0.4409))
    """
    from fractalgeo_rs.lsystem import LSystem, plants_on_terrain

    if not isinstance(plant, str) or plant.strip().lower() not in _PRESETS:
        raise ValueError(f"plant: expected one of {', '.join(PLANT_PRESETS)}, got {plant!r}")
    plant = plant.strip().lower()
    rules, n, angle, default_scale, width, width_factor, sides = _PRESETS[plant]
    if isinstance(density, bool):
        raise TypeError(f"density: expected plants per square metre, got {density!r}")
    try:
        dens = float(density)
    except (TypeError, ValueError):
        raise TypeError(f"density: expected plants per square metre, got {density!r}") from None
    if not (math.isfinite(dens) and dens >= 0):
        raise ValueError(f"density: expected a finite number of plants per square metre >= 0, got {density!r}")
    z = np.array(getattr(dem, "values", dem), dtype=np.float64)
    if z.ndim != 2 or z.shape[0] < 2 or z.shape[1] < 2:
        raise ValueError(f"dem: expected a 2D array of at least 2 x 2 heights, got shape {z.shape}")
    if not np.all(np.isfinite(z)):
        raise ValueError(f"dem: {int(np.sum(~np.isfinite(z)))} height(s) are NaN or infinite; fill them first")
    dy, dx = _cell(cell_size)
    if scale is None:
        sc = default_scale
    else:
        sc = float(scale)
        if not (math.isfinite(sc) and sc > 0):
            raise ValueError(f"scale: expected metres per turtle step > 0, got {scale!r}")
    bark = Lambertian(0.3) if bark is None else bark
    if not isinstance(bark, _OPAQUE):
        raise TypeError(f"bark: expected Lambertian, OrenNayar, Phong or Hapke, got {bark!r}")
    leaf = BiLambertian(0.4957, 0.4409) if leaf is None else leaf
    if not isinstance(leaf, BiLambertian):
        raise TypeError(f"leaf: expected BiLambertian(reflectance, transmittance), got {leaf!r}")
    soil = Lambertian(0.159) if soil is None else soil
    if not isinstance(soil, _OPAQUE):
        raise TypeError(f"soil: expected Lambertian, OrenNayar, Phong or Hapke, got {soil!r}")
    seed = check_seed(seed)
    rows, cols = z.shape
    # the ground: cell centres, row 0 north, the south-west corner of the grid at (0, 0)
    ground = Mesh.from_grid(z, transform=(0.0, dx, 0.0, rows * dy, 0.0, -dy))
    x0, y0 = 0.5 * dx, 0.5 * dy
    ext = (x0, y0, (cols - 1) * dx, (rows - 1) * dy)
    gv = ground.vertices.astype(np.float64) + np.asarray(ground.origin)
    gf = ground.faces.astype(np.int64)
    system = LSystem.from_string(rules, seed=seed)
    plants, bases = plants_on_terrain(system, n, z, cell_size=dx, density=dens * dy / dx, seed=seed, scale=sc,
                                      max_plants=max_plants, sides=sides, angle=angle, width=width,
                                      width_factor=width_factor)
    pv = plants.vertices.astype(np.float64) + np.asarray(plants.origin)
    pf = plants.faces.astype(np.int64)
    bases = np.array(bases, dtype=np.float64).reshape(-1, 3)
    if dy != dx and len(pf):
        # rigid north-south move of each plant to its base's place on the true grid
        inst = np.zeros(len(pv), dtype=np.int64)
        inst[pf.ravel()] = np.repeat(plants.instances.astype(np.int64), 3)
        shift = bases[:, 1] * (dy / dx - 1.0)
        pv[:, 1] += shift[inst]
        bases[:, 1] += shift
    kinds = plants.kinds
    if len(pf):
        c = pv[pf].mean(axis=1)
        area = _areas(pv, pf)
        # the mesh keeps float32 offsets from (min x, min y, 0) (Mesh.from_triangles): a sliver can
        # lose its area there
        org = np.minimum(gv.min(axis=0), pv.min(axis=0))
        org[2] = 0.0
        area32 = _areas((pv - org).astype(np.float32).astype(np.float64), pf)
        eps = 1e-9 * max(dx, dy)
        keep = ((area > 0) & (area32 > 0) & (c[:, 0] >= ext[0] - eps) & (c[:, 0] <= ext[0] + ext[2] + eps)
                & (c[:, 1] >= ext[1] - eps) & (c[:, 1] <= ext[1] + ext[3] + eps))
        pf, kinds, area = pf[keep], kinds[keep], area[keep]
        leaf_area = float(area[kinds == 1].sum())
    else:
        leaf_area = 0.0
    v = np.vstack([gv, pv])
    f = np.vstack([gf, pf + len(gv)])
    ids = np.concatenate([np.full(len(gf), SOIL), np.where(kinds == 1, LEAF, BARK)]).astype(np.uint32)
    mesh = dataclasses.replace(Mesh.from_triangles(v, f), kinds=ids.astype(np.uint8))
    return PlantStand(mesh=mesh, material_ids=ids, materials=(soil, bark, leaf), bases=bases, extent=ext,
                      leaf_area=leaf_area, lai=leaf_area / (ext[2] * ext[3]), plant=plant, seed=seed)
