"""fractalgeo_rs: fractal geometry for geo-information processing.

Fractal dimension estimators (box counting, differential box counting,
self-affine box counting, ...), fractal transforms of SAR and optical scenes,
fBm synthesis, DEM tools and L-systems, with the heavy kernels in Rust.

The package mirrors the Rust crate's domains: :mod:`fractalgeo_rs.dimension`
(estimators and the :class:`DimensionFit` they return), :mod:`fractalgeo_rs.io`
(rasters), :mod:`fractalgeo_rs.synth`, :mod:`fractalgeo_rs.dem` and
:mod:`fractalgeo_rs.lsystem`.
"""
from fractalgeo_rs._core import __version__
from fractalgeo_rs import data, io
from fractalgeo_rs.fit import DimensionFit, FractalRangeWarning
from fractalgeo_rs.dimension import (
    Lacunarity,
    blanket,
    fbm_mle,
    higuchi,
    lacunarity,
    madogram,
    mass_dimension,
    minkowski,
    power_variation,
    scale_space,
    spectral_dimension,
    surface_variation,
    variogram,
    wavelet_dimension,
    whittle,
    gls_dimension,
    box_counting,
    box_counting_points,
    differential_box_counting,
    dimension,
    self_affine_box_counting,
)

# -- domain exports: each issue adds its own line below --
from fractalgeo_rs.lsystem import IFS, LString, LSystem
from fractalgeo_rs.transform import fractal_transform, lacunarity_map, segment
from fractalgeo_rs.synth import fbm, fbm_surface, validate_surface, SurfaceReport, synthetic_dem  # noqa: E402
from fractalgeo_rs.dem import fractal_resample, hillshade, lakes  # noqa: E402
from fractalgeo_rs.io import read_raster, write_raster  # noqa: E402
from fractalgeo_rs import tin  # noqa: E402
from fractalgeo_rs.tin import TIN, delaunay, grid_from_points, tin_from_dem  # noqa: E402

__all__ = [
    "__version__",
    "data",
    "io",
    "DimensionFit",
    "FractalRangeWarning",
    "Lacunarity",
    "blanket",
    "fbm_mle",
    "higuchi",
    "lacunarity",
    "madogram",
    "mass_dimension",
    "minkowski",
    "power_variation",
    "scale_space",
    "spectral_dimension",
    "surface_variation",
    "variogram",
    "wavelet_dimension",
    "whittle",
    "gls_dimension",
    "box_counting",
    "box_counting_points",
    "differential_box_counting",
    "dimension",
    "self_affine_box_counting",
    "IFS",
    "LString",
    "LSystem",
    "fractal_transform",
    "lacunarity_map",
    "segment",
    # synth / dem / io
    "fbm",
    "fbm_surface",
    "validate_surface",
    "SurfaceReport",
    "synthetic_dem",
    "hillshade",
    "lakes",
    "fractal_resample",
    "read_raster",
    "write_raster",
    # tin
    "tin",
    "TIN",
    "delaunay",
    "grid_from_points",
    "tin_from_dem",
]
