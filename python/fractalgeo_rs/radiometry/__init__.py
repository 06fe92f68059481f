"""The virtual radiometric experiment: BRF, albedo and images of rough
triangulated surfaces lit by a directional sun (paper section 4.1).

A DEM becomes a surface of triangular facets (two per cell), periodic by
default (one tile of an infinite surface), each facet with a reflectance
model; a Monte Carlo path tracer in Rust with next-event estimation to the
sun gives the bidirectional reflectance factor, the directional-hemispherical
albedo and orthographic images, with standard errors. See
:doc:`/radiometry`.

Examples
--------
>>> import numpy as np
>>> from fractalgeo_rs import radiometry
>>> scene = radiometry.Scene.from_dem(np.zeros((8, 8)), material=radiometry.Lambertian(0.3))
>>> round(scene.brf(sun=(135.0, 30.0), spp=1000).value, 6)  # a flat plane: rho
0.3
"""
from fractalgeo_rs.radiometry._leaf import BiLambertian
from fractalgeo_rs.radiometry._scene import (
    PAPER_SUN_ZENITHS,
    BrfSweep,
    Estimate,
    Hapke,
    Lambertian,
    OrenNayar,
    Phong,
    ScatteringOrders,
    Scene,
    Specular,
)
from fractalgeo_rs.radiometry._plot import plot_brf_polar, plot_brf_principal_plane, plot_incidence_series

__all__ = ["BiLambertian", "BrfSweep", "Estimate", "Hapke", "Lambertian", "OrenNayar", "PAPER_SUN_ZENITHS", "Phong",
           "ScatteringOrders", "Scene", "Specular", "plot_brf_polar", "plot_brf_principal_plane", "plot_incidence_series"]
