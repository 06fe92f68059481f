"""The triangle mesh type of the turtle and the plant scenes, now
:class:`fractalgeo_rs.geometry.Mesh` (one mesh for plants, TINs and DEM
grids); this module keeps the old import path.
"""
from __future__ import annotations

from fractalgeo_rs.geometry._mesh import Mesh, write_mesh

__all__ = ["Mesh", "write_mesh"]
