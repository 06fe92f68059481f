"""Radar: backscatter of rough and fractal surfaces, numerical physical
optics, speckle and synthetic SAR scenes from DEMs.

See ``docs/radar.md`` for the models, their validity, the conventions and
the measured accuracy.
"""
from fractalgeo_rs.radar._backscatter import (
    BackscatterValidity,
    RadarValidityWarning,
    backscatter,
    fresnel,
    to_db,
    validity,
)
from fractalgeo_rs.radar._po import PhysicalOptics, physical_optics, surface_realisation
from fractalgeo_rs.radar._scene import SARScene, simulate
from fractalgeo_rs.radar._speckle import speckle

__all__ = [
    "backscatter",
    "fresnel",
    "to_db",
    "validity",
    "BackscatterValidity",
    "RadarValidityWarning",
    "physical_optics",
    "PhysicalOptics",
    "surface_realisation",
    "speckle",
    "simulate",
    "SARScene",
]
