"""The triangle mesh type of the turtle, the plant scenes and the TINs, and
its OBJ/PLY writer (in Rust).

Kept apart from :mod:`fractalgeo_rs.lsystem.geometry` (which builds meshes)
and :mod:`fractalgeo_rs.lsystem.export` (the public writers), so that
neither of those imports the other.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Union

import numpy as np

from fractalgeo_rs import _core

__all__ = ["Mesh", "write_mesh"]


@dataclass(frozen=True)
class Mesh:
    """An indexed triangle mesh.

    Attributes
    ----------
    vertices, normals : (V, 3) float32
    uvs : (V, 2) float32
        Texture coordinates: u around a branch tube in [0, 1], v along the
        branch in turtle units; leaves are mapped to [0, 1]^2.
    faces : (T, 3) uint32
        Counter-clockwise seen from outside.
    part_ids : (T,) uint32
        Turtle element of the triangle: segment number (branches) or
        polygon number (leaves).
    kinds : (T,) uint8
        0 for branches, 1 for leaves.
    colors : (T,) uint32
        Colour index set by ``'``.
    instances : (T,) uint32
        Plant number in a scene (0 for a single plant).

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, section 5.1, doi:10.1007/978-1-4613-8476-2.

    J. Bloomenthal, Modeling the mighty maple, *Computer Graphics
    (SIGGRAPH '85 Proceedings)* 19(3) (1985) 305-311.

    Examples
    --------
    One segment as a tube of 3 sides: two rings of 3 + 1 vertices (the last
    repeats the first for the texture seam) and 2 triangles per side:

    >>> from fractalgeo_rs.lsystem import plant_mesh
    >>> m = plant_mesh("F", sides=3)
    >>> m.vertices.shape, m.faces.shape, m.vertices.dtype, m.faces.dtype
    ((8, 3), (6, 3), dtype('float32'), dtype('uint32'))
    >>> m.vertices[:, 2].tolist(), m.kinds.tolist()
    ([0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0], [0, 0, 0, 0, 0, 0])
    """

    vertices: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    faces: np.ndarray
    part_ids: np.ndarray
    kinds: np.ndarray
    colors: np.ndarray
    instances: np.ndarray

    @classmethod
    def _from_core(cls, t) -> "Mesh":
        return cls(*t)

    def write_obj(self, path) -> None:
        """Write a Wavefront OBJ file (see :func:`fractalgeo_rs.lsystem.write_obj`)."""
        write_mesh(self, path, "obj")

    def write_ply(self, path) -> None:
        """Write a binary PLY file (see :func:`fractalgeo_rs.lsystem.write_ply`)."""
        write_mesh(self, path, "ply")


def _mesh_arrays(mesh: Mesh) -> tuple:
    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh: expected a Mesh, got {type(mesh).__name__}")
    return (
        np.ascontiguousarray(mesh.vertices, dtype=np.float32),
        np.ascontiguousarray(mesh.normals, dtype=np.float32),
        np.ascontiguousarray(mesh.uvs, dtype=np.float32),
        np.ascontiguousarray(mesh.faces, dtype=np.uint32),
        np.ascontiguousarray(mesh.part_ids, dtype=np.uint32),
        np.ascontiguousarray(mesh.kinds, dtype=np.uint8),
        np.ascontiguousarray(mesh.colors, dtype=np.uint32),
        np.ascontiguousarray(mesh.instances, dtype=np.uint32),
    )


def write_mesh(mesh: "Mesh", path: Union[str, os.PathLike], fmt: str) -> None:
    """Write ``mesh`` as ``fmt`` ("obj" or "ply"), atomically, in Rust."""
    _core.write_mesh(os.fspath(path), fmt, *_mesh_arrays(mesh))
