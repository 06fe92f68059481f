"""Triangulated irregular networks: Delaunay triangulation (through the Rust
crate ``spade``), error-bounded terrain meshes of rasters and gridding of
scattered heights by natural-neighbour interpolation."""
from fractalgeo_rs.tin._tin import TIN, delaunay, grid_from_points, tin_from_dem

__all__ = ["TIN", "delaunay", "grid_from_points", "tin_from_dem"]
