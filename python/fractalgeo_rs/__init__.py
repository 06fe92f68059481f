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
from fractalgeo_rs import data, io, radiometry, tin
from fractalgeo_rs.fit import DimensionFit, FractalRangeWarning
from fractalgeo_rs.dimension import (
    Lacunarity,
    blanket,
    box_counting,
    box_counting_points,
    differential_box_counting,
    dimension,
    fbm_mle,
    gls_dimension,
    higuchi,
    lacunarity,
    madogram,
    mass_dimension,
    minkowski,
    power_variation,
    scale_space,
    self_affine_box_counting,
    spectral_dimension,
    surface_variation,
    variogram,
    wavelet_dimension,
    whittle,
)
from fractalgeo_rs.lsystem import IFS, LString, LSystem
from fractalgeo_rs.transform import fractal_transform, lacunarity_map, segment
from fractalgeo_rs.synth import SurfaceReport, fbm, fbm_surface, synthetic_dem, validate_surface
from fractalgeo_rs.dem import fractal_resample, hillshade, lakes
from fractalgeo_rs.io import read_raster, write_raster
from fractalgeo_rs.tin import TIN, delaunay, grid_from_points, tin_from_dem


def _exports():
    """The imports above are the one list of the top-level API: ``__all__`` is
    every public name they bind (classes and functions of this package, and
    the subpackages ``data``, ``io``, ``radiometry`` and ``tin``), in the order imported."""
    import types

    names = ["__version__"]
    for name, obj in list(globals().items()):
        if name.startswith("_"):
            continue
        if isinstance(obj, types.ModuleType):
            if name in ("data", "io", "radiometry", "tin"):
                names.append(name)
        elif getattr(obj, "__module__", "").startswith("fractalgeo_rs."):
            names.append(name)
    return names


__all__ = _exports()
