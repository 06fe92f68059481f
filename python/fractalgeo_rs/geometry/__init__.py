"""Geometry shared by every domain: the triangle :class:`Mesh` (plants,
TINs, DEM grids; OBJ/PLY, trimesh, PyVista) and the raster georeference
:class:`GeoGrid` (origin, cell size, rotation, CRS; row 0 north). Both
mirror ``rust/geometry/``.

Examples
--------
>>> import numpy as np
>>> from fractalgeo_rs.geometry import GeoGrid, Mesh
>>> m = Mesh.from_grid(np.arange(12.0).reshape(3, 4), grid=GeoGrid((0.0, 90.0), 30.0))
>>> len(m), bool(np.all(m.normals[:, 2] > 0))   # counter-clockwise from above
(12, True)
"""
from fractalgeo_rs.geometry._geogrid import GeoGrid
from fractalgeo_rs.geometry._mesh import Mesh

__all__ = ["GeoGrid", "Mesh"]
