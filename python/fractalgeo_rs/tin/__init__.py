"""Triangulated irregular networks: Delaunay triangulation (through the Rust
crate ``spade``), error-bounded terrain meshes of rasters and gridding of
scattered heights by natural-neighbour interpolation.

Examples
--------
>>> import numpy as np
>>> from fractalgeo_rs import tin
>>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [0.4, 0.6]])
>>> tin.delaunay(pts).shape  # 2n - 2 - h = 10 - 2 - 4 triangles
(4, 3)
"""
from fractalgeo_rs.tin._tin import TIN, delaunay, grid_from_points, tin_from_dem

__all__ = ["TIN", "delaunay", "grid_from_points", "tin_from_dem"]
