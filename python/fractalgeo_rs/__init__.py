"""fractalgeo_rs: fractal geometry for geo-information processing.

Fractal dimension estimators (box counting, differential box counting,
self-affine box counting, ...), fractal transforms of SAR and optical scenes,
fBm synthesis, DEM tools and L-systems, with the heavy kernels in Rust.

The package mirrors the Rust crate's domains: :mod:`fractalgeo_rs.dimension`
(estimators and the :class:`DimensionFit` they return), :mod:`fractalgeo_rs.io`
(rasters), :mod:`fractalgeo_rs.synth`, :mod:`fractalgeo_rs.dem` and
:mod:`fractalgeo_rs.lsystem`.

Names are imported on first use (PEP 562 ``__getattr__``), so ``import
fractalgeo_rs`` and the ``fractalgeo`` command start fast: ``_EXPORTS`` maps
each public name to the module that defines it, and is the one list of the
top-level API (``__all__`` is its keys in order). To add an export, add a
``"name": "fractalgeo_rs.module"`` row (a subpackage exported as a whole:
``"name": None``), and the name to the ``TYPE_CHECKING`` imports above it for
type checkers.
"""
from __future__ import annotations

import importlib
import importlib.util
import sys
import types
from typing import TYPE_CHECKING, Any, Dict, List, Optional

if TYPE_CHECKING:  # the names for type checkers and IDEs (not executed)
    from fractalgeo_rs import canopy, data, geometry, io, radar, radiometry, tin
    from fractalgeo_rs._core import __version__
    from fractalgeo_rs.dem import fractal_resample, hillshade, lakes
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
    from fractalgeo_rs.fit import DimensionFit, FractalRangeWarning
    from fractalgeo_rs.io import read_raster, write_raster
    from fractalgeo_rs.lsystem import IFS, LString, LSystem
    from fractalgeo_rs.synth import SurfaceReport, fbm, fbm_surface, synthetic_dem, validate_surface
    from fractalgeo_rs.tin import TIN, delaunay, grid_from_points, tin_from_dem
    from fractalgeo_rs.transform import fractal_transform, lacunarity_map
    # mypy also binds the submodules dimension.lacunarity and transform.segment to these names
    from fractalgeo_rs.dimension import lacunarity  # type: ignore[no-redef]
    from fractalgeo_rs.transform import segment  # type: ignore[no-redef]

#: public name -> the module it is imported from (None: the subpackage itself)
_EXPORTS: Dict[str, Optional[str]] = {
    "__version__": "fractalgeo_rs._core",
    # subpackages
    "canopy": None,
    "data": None,
    "geometry": None,
    "io": None,
    "radar": None,
    "radiometry": None,
    "tin": None,
    # results
    "DimensionFit": "fractalgeo_rs.fit",
    "FractalRangeWarning": "fractalgeo_rs.fit",
    # dimension estimators
    "Lacunarity": "fractalgeo_rs.dimension",
    "blanket": "fractalgeo_rs.dimension",
    "box_counting": "fractalgeo_rs.dimension",
    "box_counting_points": "fractalgeo_rs.dimension",
    "differential_box_counting": "fractalgeo_rs.dimension",
    "dimension": "fractalgeo_rs.dimension",
    "fbm_mle": "fractalgeo_rs.dimension",
    "gls_dimension": "fractalgeo_rs.dimension",
    "higuchi": "fractalgeo_rs.dimension",
    "lacunarity": "fractalgeo_rs.dimension",
    "madogram": "fractalgeo_rs.dimension",
    "mass_dimension": "fractalgeo_rs.dimension",
    "minkowski": "fractalgeo_rs.dimension",
    "power_variation": "fractalgeo_rs.dimension",
    "scale_space": "fractalgeo_rs.dimension",
    "self_affine_box_counting": "fractalgeo_rs.dimension",
    "spectral_dimension": "fractalgeo_rs.dimension",
    "surface_variation": "fractalgeo_rs.dimension",
    "variogram": "fractalgeo_rs.dimension",
    "wavelet_dimension": "fractalgeo_rs.dimension",
    "whittle": "fractalgeo_rs.dimension",
    # L-systems
    "IFS": "fractalgeo_rs.lsystem",
    "LString": "fractalgeo_rs.lsystem",
    "LSystem": "fractalgeo_rs.lsystem",
    # transforms
    "fractal_transform": "fractalgeo_rs.transform",
    "lacunarity_map": "fractalgeo_rs.transform",
    "segment": "fractalgeo_rs.transform",
    # synthesis
    "SurfaceReport": "fractalgeo_rs.synth",
    "fbm": "fractalgeo_rs.synth",
    "fbm_surface": "fractalgeo_rs.synth",
    "synthetic_dem": "fractalgeo_rs.synth",
    "validate_surface": "fractalgeo_rs.synth",
    # DEM tools
    "fractal_resample": "fractalgeo_rs.dem",
    "hillshade": "fractalgeo_rs.dem",
    "lakes": "fractalgeo_rs.dem",
    # raster I/O
    "read_raster": "fractalgeo_rs.io",
    "write_raster": "fractalgeo_rs.io",
    # TINs
    "TIN": "fractalgeo_rs.tin",
    "delaunay": "fractalgeo_rs.tin",
    "grid_from_points": "fractalgeo_rs.tin",
    "tin_from_dem": "fractalgeo_rs.tin",
}

__all__: List[str] = list(_EXPORTS)


def _is_submodule(name: str) -> bool:
    """``fractalgeo_rs.<name>`` is a module or subpackage of the package."""
    try:
        return importlib.util.find_spec(f"{__name__}.{name}") is not None
    except (ImportError, ValueError):
        return False


def __getattr__(name: str) -> Any:
    """Import a public name on first use and keep it in the module.

    A subpackage that is not a top-level export (``fractalgeo_rs.lsystem``,
    ``fractalgeo_rs.synth``, ...) is imported on first attribute access too,
    as the eager imports did (``fg.lsystem.LSystem`` keeps working)."""
    if name not in _EXPORTS:
        if name.isidentifier() and not name.startswith("_") and _is_submodule(name):
            module = importlib.import_module(f"{__name__}.{name}")
            globals()[name] = module
            return module
        raise AttributeError(f"module 'fractalgeo_rs' has no attribute {name!r}")
    source = _EXPORTS[name]
    value: Any
    if source is None:
        value = importlib.import_module(f"{__name__}.{name}")
    else:
        value = getattr(importlib.import_module(source), name)
    globals()[name] = value
    return value


def __dir__() -> List[str]:
    return sorted(set(globals()) | set(__all__))


class _Package(types.ModuleType):
    """The package module: importing a submodule that shares its name with
    an exported function (``fractalgeo_rs.dimension``) leaves the function
    the attribute, as the eager imports did."""

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(value, types.ModuleType) and _EXPORTS.get(name, None) is not None:
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
