"""The triangle mesh type of the turtle and the plant scenes is
:class:`fractalgeo_rs.geometry.Mesh` (one mesh for plants, TINs and DEM
grids); this module keeps the old import path and the writer the public
:mod:`fractalgeo_rs.lsystem.export` functions call.
"""
from __future__ import annotations

import os
from typing import Union

from fractalgeo_rs.geometry import Mesh

__all__ = ["Mesh", "write_mesh"]


def write_mesh(mesh: Mesh, path: Union[str, os.PathLike], fmt: str) -> None:
    """Write ``mesh`` as ``fmt`` ("obj" or "ply"), atomically, in Rust."""
    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh: expected a Mesh, got {type(mesh).__name__}")
    mesh.write(path, fmt)
