"""Vegetation canopies for the radiometric experiment: leaf angle
distributions, Ross's projection function ``G`` and RAMI-like homogeneous
canopies of disc leaves in a periodic tile, and stands of L-system plants
on a DEM. See :doc:`/canopy`.

Examples
--------
>>> from fractalgeo_rs import canopy
>>> round(canopy.projection_g("spherical", 60.0), 12)
0.5
>>> c = canopy.disc_canopy(lai=1.0, leaf_radius=0.1, extent=2.0, height=(0.2, 1.0), seed=3)
>>> c.n_leaves
127
"""
from fractalgeo_rs.canopy._discs import DiscCanopy, disc_canopy
from fractalgeo_rs.canopy._lad import LADS, leaf_angle_density, projection_g, sample_leaf_normals
from fractalgeo_rs.canopy._stand import PLANT_PRESETS, PlantStand, plant_stand

__all__ = ["DiscCanopy", "LADS", "PLANT_PRESETS", "PlantStand", "disc_canopy", "leaf_angle_density", "plant_stand",
           "projection_g", "sample_leaf_normals"]
