"""L-systems, turtle geometry and iterated function systems.

* :class:`~fractalgeo_rs.LSystem` - DOL, bracketed, stochastic,
  context-sensitive and parametric rewriting in Rust, loadable from a small
  text format;
* :func:`~fractalgeo_rs.lsystem.turtle_2d`,
  :func:`~fractalgeo_rs.lsystem.turtle_3d`,
  :func:`~fractalgeo_rs.lsystem.plant_mesh` - turtle interpretation to
  polylines, segments and triangle meshes;
* :func:`~fractalgeo_rs.lsystem.write_obj`,
  :func:`~fractalgeo_rs.lsystem.write_ply`,
  :func:`~fractalgeo_rs.lsystem.write_svg`,
  :func:`~fractalgeo_rs.lsystem.write_png`;
* :class:`~fractalgeo_rs.IFS`, :func:`~fractalgeo_rs.lsystem.ifs_preset`,
  :func:`~fractalgeo_rs.lsystem.moran_dimension` - iterated function
  systems;
* :func:`~fractalgeo_rs.lsystem.plants_on_terrain` - a scene of plants on a
  DEM.

References
----------
P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
Springer, 1990. M. Barnsley, *Fractals Everywhere*, Academic Press, 1988.
J. E. Hutchinson, Fractals and self-similarity, *Indiana Univ. Math. J.* 30
(1981) 713-747.
"""
from fractalgeo_rs.lsystem.core import DEFAULT_MAX_LENGTH, LString, LSystem
from fractalgeo_rs.lsystem.export import write_obj, write_ply, write_png, write_svg
from fractalgeo_rs.lsystem.geometry import TURTLE_SYMBOLS, Polylines, Segments, plant_mesh, turtle_2d, turtle_3d
# the mesh type is fractalgeo_rs.geometry.Mesh (documented there); kept importable from here
from fractalgeo_rs.lsystem.geometry import Mesh as Mesh
from fractalgeo_rs.lsystem.ifs import IFS, IFS_PRESETS, ifs_preset, moran_dimension, rasterize_points
from fractalgeo_rs.lsystem.terrain import plants_on_terrain

__all__ = [
    "DEFAULT_MAX_LENGTH",
    "IFS",
    "IFS_PRESETS",
    "LString",
    "LSystem",
    "Polylines",
    "Segments",
    "TURTLE_SYMBOLS",
    "ifs_preset",
    "moran_dimension",
    "plant_mesh",
    "plants_on_terrain",
    "rasterize_points",
    "turtle_2d",
    "turtle_3d",
    "write_obj",
    "write_ply",
    "write_png",
    "write_svg",
]
