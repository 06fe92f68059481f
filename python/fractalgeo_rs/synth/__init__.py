"""Synthesis of fractal signals and surfaces: fBm in 1D and 2D, synthetic DEMs,
and :func:`validate_surface` to check what a generator produced.

See ``docs/synthesis.md`` for the methods, their costs and their accuracy.
"""
from fractalgeo_rs.synth._fbm import fbm, fbm_surface
from fractalgeo_rs.synth._validate import SurfaceReport, validate_surface
from fractalgeo_rs.synth._dem import expected_relief_std, synthetic_dem

__all__ = ["fbm", "fbm_surface", "validate_surface", "SurfaceReport", "synthetic_dem", "expected_relief_std"]
