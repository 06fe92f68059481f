"""Geometry shared by every domain: one triangle mesh and one raster georeference.

:class:`~fractalgeo_rs.geometry.Mesh` holds plants, TINs and DEM grids
(OBJ/PLY, trimesh, PyVista); :class:`~fractalgeo_rs.geometry.GeoGrid` the
origin, cell size, rotation and CRS of a raster (row 0 north). Both mirror
``rust/geometry/``. See the user guide page on geometry.

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
