"""The one triangle mesh of the package (``rust/geometry/mesh.rs``): plants,
TINs and DEM grids all become a :class:`Mesh`, written to OBJ/PLY in Rust
and handed to trimesh or PyVista."""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, fields
from typing import Optional, Sequence, Tuple, Union

import numpy as np

from fractalgeo_rs import _core

__all__ = ["Mesh", "write_mesh"]

PathLike = Union[str, os.PathLike]

_DTYPES = {
    "vertices": np.float32, "normals": np.float32, "uvs": np.float32, "faces": np.uint32,
    "part_ids": np.uint32, "kinds": np.uint8, "colors": np.uint32, "instances": np.uint32,
}


@dataclass(frozen=True)
class Mesh:
    """An indexed triangle mesh: an L-system plant, a TIN or a DEM grid.

    Vertices are float32 offsets from a float64 ``origin``, so that a mesh in
    UTM metres keeps millimetres (bare float32 has about 3 cm at 500 km).
    Triangles are counter-clockwise seen from outside (from above for
    terrain), so their right-hand normals point out (up).

    Attributes
    ----------
    vertices, normals : (V, 3) float32
        Positions relative to ``origin`` and unit normals.
    uvs : (V, 2) float32
        Texture coordinates: for plants, u around a branch tube in [0, 1]
        and v along the branch in turtle units, leaves mapped to [0, 1]^2;
        for terrain, map ``x, y`` scaled to [0, 1] over the bounding box.
    faces : (T, 3) uint32
        Vertex indices, counter-clockwise seen from outside.
    part_ids : (T,) uint32
        Element of each triangle: turtle segment or polygon number
        (plants), triangle number (terrain).
    kinds : (T,) uint8
        Material kind: 0 for branches (and terrain), 1 for leaves.
    colors : (T,) uint32
        Colour (material) index set by ``'``.
    instances : (T,) uint32
        Object number in a scene (0 for a single plant).
    origin : (float, float, float)
        Map coordinates the vertices are relative to (0 for plants).
    crs : str or None
        The coordinate reference system of the map coordinates when the
        mesh knows it (:meth:`from_grid` of a grid with a CRS,
        ``TIN.to_mesh``, :meth:`placed_on`); written by :meth:`write`.

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

    A DEM grid of 30 m cells, two triangles per square of cell centres:

    >>> import numpy as np
    >>> from fractalgeo_rs.geometry import GeoGrid, Mesh
    >>> g = Mesh.from_grid(np.zeros((3, 4)), grid=GeoGrid((500000.0, 4000090.0), 30.0))
    >>> len(g), g.origin, g.bounds()[1].tolist()
    (12, (500015.0, 4000015.0, 0.0), [500105.0, 4000075.0, 0.0])
    """

    vertices: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    faces: np.ndarray
    part_ids: np.ndarray
    kinds: np.ndarray
    colors: np.ndarray
    instances: np.ndarray
    origin: Tuple[float, float, float] = (0.0, 0.0, 0.0)
    crs: Optional[str] = None

    def __len__(self) -> int:
        return int(len(self.faces))

    @classmethod
    def _from_core(cls, d, crs=None) -> "Mesh":
        if isinstance(d, dict):
            d = dict(d)
            d["origin"] = tuple(float(v) for v in d["origin"])
            d["crs"] = crs
            return cls(**d)
        return dataclasses.replace(cls(*d), crs=crs)

    # ------------------------------------------------------------ builders
    @classmethod
    def from_triangles(cls, vertices, faces) -> "Mesh":
        """A terrain-style mesh of map-coordinate ``vertices`` (n, 3) and
        triangles ``faces`` (m, 3), checked (:meth:`validate`): origin at
        the lower-left of the bounding box, area-weighted normals, texture
        coordinates ``x, y`` scaled to [0, 1].

        Raises
        ------
        ValueError
            Wrong shapes, NaN or infinite vertices (``vertices``), indices
            out of range or zero-area triangles (``faces``).
        """
        v = np.asarray(vertices)
        f = np.asarray(faces)
        if v.ndim != 2 or v.shape[1] != 3 or v.dtype.kind not in "fiu":
            raise ValueError(f"vertices: expected a real (n, 3) array, got shape {v.shape}, dtype {v.dtype}")
        if f.ndim != 2 or f.shape[1] != 3 or f.dtype.kind not in "iu":
            raise ValueError(f"faces: expected an integer (m, 3) array, got shape {f.shape}, dtype {f.dtype}")
        if f.dtype.kind == "u" and f.size and f.max() > np.iinfo(np.int64).max:
            raise ValueError("faces: index out of range")
        try:
            d = _core.mesh_from_tin(np.asarray(v, dtype=np.float64), np.asarray(f, dtype=np.int64))
        except ValueError as e:
            raise ValueError(str(e).replace("triangles:", "faces:", 1)) from None
        return cls._from_core(d).validate()

    @classmethod
    def from_grid(cls, dem, *, grid=None, transform=None, cell_size=None, split: str = "ne-sw", nodata=None,
                  n_threads: Optional[int] = None) -> "Mesh":
        """The mesh of a DEM grid: one vertex per cell centre (map
        coordinates of the grid), two triangles per square of four adjacent
        centres.

        With ``(i, j)`` the north-west centre of a square (row 0 north,
        columns east), ``split="ne-sw"`` cuts it along the NE-SW diagonal
        into ``(i, j)-(i+1, j)-(i, j+1)`` and ``(i, j+1)-(i+1, j)-(i+1,
        j+1)``, counter-clockwise seen from above (normals up);
        ``"nw-se"`` cuts along the other diagonal, ``"alternating"`` uses
        NE-SW where ``i + j`` is even. Triangles with a NaN (or ``nodata``)
        corner are left out, and vertices in no triangle.

        Parameters
        ----------
        dem : array_like or xarray.DataArray, shape (rows, cols)
            Heights (map units of the grid). Not modified.
        grid, transform, cell_size
            The georeference (at most one; see
            :meth:`~fractalgeo_rs.geometry.GeoGrid.of`); a
            DataArray's own coordinates otherwise; pixel units (cell size
            1, origin at the lower-left corner) for a bare array. A
            geographic grid (degrees) is refused: x, y and z need one unit.
        split : {"ne-sw", "nw-se", "alternating"}
        nodata : float, optional
            Height meaning "no data" (NaN always is).
        n_threads : int, optional
            Threads of the Rust kernel.

        Returns
        -------
        Mesh
            With the grid's CRS as ``crs`` (None without one).
        """
        from fractalgeo_rs._validation import check_n_threads, check_nodata
        from fractalgeo_rs.geometry._geogrid import GeoGrid

        if type(getattr(dem, "data", None)).__module__.startswith("dask") or \
                type(dem).__module__.startswith("dask"):
            raise TypeError("dem: a Dask array is not meshed lazily; call .compute() (or .load()) first")
        g = GeoGrid.of(dem, grid=grid, transform=transform, cell_size=cell_size, param="dem")
        if g is not None:
            g.require_projected("grid" if grid is not None else "dem")
        z = np.array(getattr(dem, "values", dem), dtype=np.float64, order="C", copy=True)
        if z.ndim != 2:
            raise ValueError(f"dem: expected a 2D array, got shape {z.shape}")
        if g is None:
            g = GeoGrid.from_cell_size(z.shape[0], 1.0)
        nd = check_nodata(nodata)
        if nd is not None and not np.isnan(nd):
            z[z == nd] = np.nan
        if not isinstance(split, str):
            raise TypeError(f"split: expected 'ne-sw', 'nw-se' or 'alternating', got {split!r}")
        return cls._from_core(_core.mesh_from_grid(z, g, split, check_n_threads(n_threads)), crs=g.crs)

    # ------------------------------------------------------------ queries
    def _arrays(self) -> "Mesh":
        """The mesh with every field in its exact dtype (any strides)."""
        conv = {}
        for f in fields(self):
            if f.name in ("origin", "crs"):
                continue
            a = np.asarray(getattr(self, f.name))
            want = np.dtype(_DTYPES[f.name])
            if a.dtype != want:
                if a.dtype.kind == "f" and want.kind != "f":
                    raise TypeError(f"{f.name}: expected integers, got dtype {a.dtype}")
                if a.dtype.kind in "iu" and a.size and (a.min() < 0 or a.max() > np.iinfo(want.name).max):
                    raise ValueError(f"{f.name}: values out of range of {want.name}")
                a = a.astype(want)
            conv[f.name] = a
        origin = np.asarray(self.origin, dtype=np.float64)
        if origin.shape != (3,):
            raise ValueError(f"origin: expected 3 numbers, got shape {origin.shape}")
        return Mesh(**conv, origin=(float(origin[0]), float(origin[1]), float(origin[2])), crs=self.crs)

    def validate(self) -> "Mesh":
        """Check the mesh and return it: one normal and uv per vertex, one
        of each id per triangle, every index in range, finite vertices, no
        zero-area triangle. ``ValueError`` naming the field otherwise
        (``faces``, ``vertices``, ``origin``, ``mesh`` for the layout)."""
        _core.mesh_validate(self._arrays())
        return self

    def map_vertices(self) -> np.ndarray:
        """Vertices in map coordinates, float64 (``origin`` added)."""
        return np.asarray(self.vertices, dtype=np.float64) + np.asarray(self.origin, dtype=np.float64)

    def bounds(self) -> Tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners of the bounding box, map coordinates."""
        v = self.map_vertices()
        if len(v) == 0:
            raise ValueError("mesh: has no vertices")
        return v.min(axis=0), v.max(axis=0)

    def edges(self) -> dict:
        """Edge counts: ``boundary`` (used by one triangle), ``non_manifold``
        (more than two), ``inconsistent`` (two neighbours of opposite
        orientation); vertices identified by index."""
        b, n, i = _core.mesh_edges(self._arrays())
        return {"boundary": b, "non_manifold": n, "inconsistent": i}

    def is_watertight(self) -> bool:
        """Closed and consistently oriented: every edge used by exactly two
        triangles, once in each direction (``trimesh``'s
        ``is_watertight and is_winding_consistent``)."""
        return len(self) > 0 and self.edges() == {"boundary": 0, "non_manifold": 0, "inconsistent": 0}

    # ------------------------------------------------------------ output
    def placed_on(self, grid, rows: int) -> "Mesh":
        r"""The mesh moved from a grid's local metric frame to the grid's
        map coordinates, with the grid's CRS.

        The local frame is the one of a DEM without georeference
        (:meth:`GeoGrid.from_cell_size`, ``Mesh.from_grid(dem,
        cell_size=)``, :func:`fractalgeo_rs.canopy.plant_stand`): the
        south-west (lower-left) corner of the grid's ``rows`` rows at
        ``(0, 0)``, x along the rows (east for a north-up grid), y up the
        columns (north), z up, in the grid's cell units. A local point
        ``(x, y, z)`` goes to

        .. math::

            X = x_s + x\cos\theta - y\sin\theta,\qquad
            Y = y_s + x\sin\theta + y\cos\theta,\qquad Z = z,

        with ``(x_s, y_s) = (x_0 + r\,\Delta y \sin\theta, y_0 - r\,\Delta y
        \cos\theta)`` the grid's corner of row ``r = rows``, column 0
        (:class:`GeoGrid`'s formula). A north-up grid only moves ``origin``
        (the float32 vertices are kept bit for bit); a rotated grid also
        rotates the vertices and normals (float32 rounding of the offsets).

        Parameters
        ----------
        grid : GeoGrid
            The grid, projected: x, y and z need one unit (a geographic grid
            is a ``ValueError`` naming ``grid``).
        rows : int
            Rows of the grid (>= 1): the local frame starts at its south
            edge.

        Returns
        -------
        Mesh

        Examples
        --------
        >>> import numpy as np
        >>> from fractalgeo_rs.geometry import GeoGrid, Mesh
        >>> local = Mesh.from_grid(np.zeros((3, 4)), cell_size=30.0)       # lower-left corner at (0, 0)
        >>> local.origin
        (15.0, 15.0, 0.0)
        >>> utm = GeoGrid((500000.0, 4000090.0), 30.0, crs="EPSG:32633")   # 3 rows: south edge 4000000
        >>> m = local.placed_on(utm, 3)
        >>> m.origin, m.crs
        ((500015.0, 4000015.0, 0.0), 'EPSG:32633')
        """
        import math
        import numbers

        from fractalgeo_rs.geometry._geogrid import GeoGrid

        if not isinstance(grid, GeoGrid):
            raise TypeError(f"grid: expected a GeoGrid, got {type(grid).__name__}")
        grid.require_projected("grid")
        if isinstance(rows, bool) or not isinstance(rows, numbers.Integral):
            raise TypeError(f"rows: expected an int, got {rows!r}")
        if rows < 1:
            raise ValueError(f"rows: expected at least 1 row, got {rows}")
        m = self._arrays()
        t = math.radians(grid.rotation)
        cos, sin = (1.0, 0.0) if grid.rotation == 0 else (math.cos(t), math.sin(t))
        xs = grid.x0 + int(rows) * grid.dy * sin
        ys = grid.y0 - int(rows) * grid.dy * cos
        ox, oy, oz = m.origin
        origin = (xs + ox * cos - oy * sin, ys + ox * sin + oy * cos, oz)
        if grid.rotation == 0:
            return dataclasses.replace(m, origin=origin, crs=grid.crs)
        rot = np.array([[cos, -sin, 0.0], [sin, cos, 0.0], [0.0, 0.0, 1.0]])
        return dataclasses.replace(
            m, origin=origin, crs=grid.crs,
            vertices=(np.asarray(m.vertices, dtype=np.float64) @ rot.T).astype(np.float32),
            normals=(np.asarray(m.normals, dtype=np.float64) @ rot.T).astype(np.float32))

    # ------------------------------------------------------------ output
    def write(self, path: PathLike, format: Optional[str] = None, *, crs=None) -> None:
        """Write the mesh as ``format`` ("obj" or "ply"; default: from the
        file name's extension), atomically, in Rust, with its place on Earth
        in a JSON sidecar.

        The file holds the float32 vertices relative to ``origin`` (as
        :meth:`write_obj` and :meth:`write_ply` do); ``name.json`` beside it
        records ``offset`` = ``origin`` (map ``x, y, z`` = file ``x, y, z``
        + offset), the CRS as WKT (``crs_wkt``, null without one) and the
        counts, in the sidecar format of ``fractalgeo tin``; with a CRS its
        WKT is also written to ``name.prj``. The file's header repeats the
        offset and CRS (OBJ ``# offset X Y Z`` and ``# crs WKT``, PLY
        ``comment`` lines), and an OBJ puts each triangle kind in its own
        group (``branches``, ``leaves``, ``kind<k>``). Each file appears
        whole or not at all.

        Parameters
        ----------
        path : str or os.PathLike
            The mesh file (``.obj`` or ``.ply`` unless ``format`` is given);
            the sidecars take its name with ``.json`` and ``.prj``.
        format : {"obj", "ply"}, optional
        crs : optional
            CRS of the map coordinates (``"EPSG:32633"``, WKT, a rasterio or
            pyproj CRS); default the mesh's own :attr:`crs`.

        Raises
        ------
        ValueError
            A name without ``.obj``/``.ply`` and no ``format``, or a name
            ending in ``.json``/``.prj`` (the sidecars' names) (``path``), a
            CRS rasterio does not read (``crs``), a bad layout (the field).

        Examples
        --------
        >>> import json, os, pathlib, tempfile
        >>> import numpy as np
        >>> from fractalgeo_rs.geometry import GeoGrid, Mesh
        >>> m = Mesh.from_grid(np.zeros((3, 4)), grid=GeoGrid((500000.0, 4000090.0), 30.0))
        >>> with tempfile.TemporaryDirectory() as d:
        ...     m.write(os.path.join(d, "grid.ply"))
        ...     meta = json.loads(pathlib.Path(d, "grid.json").read_text())
        ...     files = sorted(os.listdir(d))
        >>> files, meta["offset"], meta["crs_wkt"]
        (['grid.json', 'grid.ply'], [500015.0, 4000015.0, 0.0], None)
        """
        if format is None:
            ext = os.fspath(path).lower().rsplit(".", 1)[-1]
            if ext not in ("obj", "ply"):
                raise ValueError(f"path: expected a .obj or .ply file (or pass format=), got {os.fspath(path)!r}")
            format = ext
        write_mesh(self, path, format, crs=crs)

    def write_obj(self, path: PathLike, *, crs=None) -> None:
        """Write a Wavefront OBJ file (see :func:`fractalgeo_rs.lsystem.write_obj`)
        and its sidecars (see :meth:`write`)."""
        write_mesh(self, path, "obj", crs=crs)

    def write_ply(self, path: PathLike, *, crs=None) -> None:
        """Write a binary PLY file (see :func:`fractalgeo_rs.lsystem.write_ply`)
        and its sidecars (see :meth:`write`)."""
        write_mesh(self, path, "ply", crs=crs)

    def to_trimesh(self):
        """The mesh as a ``trimesh.Trimesh`` in map coordinates (float64),
        with its vertex normals, uvs and the per-face ids as
        ``face_attributes`` (needs ``pip install "fractalgeo_rs[mesh]"``)."""
        from fractalgeo_rs._backend import require

        trimesh = require("trimesh")
        m = self._arrays()
        visual = trimesh.visual.TextureVisuals(uv=np.asarray(m.uvs, dtype=np.float64))
        return trimesh.Trimesh(
            vertices=m.map_vertices(), faces=np.asarray(m.faces, dtype=np.int64),
            vertex_normals=np.asarray(m.normals, dtype=np.float64), visual=visual, process=False,
            face_attributes={k: np.asarray(getattr(m, k)) for k in ("part_ids", "kinds", "colors", "instances")},
        )

    def to_pyvista(self):
        """The mesh as a ``pyvista.PolyData`` in map coordinates, with
        point data ``Normals``, ``uv`` and cell data ``part_ids``, ``kinds``,
        ``colors``, ``instances`` (needs ``pip install "fractalgeo_rs[pyvista]"``)."""
        from fractalgeo_rs._backend import require

        pv = require("pyvista")
        m = self._arrays()
        cells = np.column_stack([np.full(len(m), 3, dtype=np.int64), np.asarray(m.faces, dtype=np.int64)])
        poly = pv.PolyData(m.map_vertices(), cells.ravel())
        poly.point_data["Normals"] = np.asarray(m.normals)
        poly.point_data["uv"] = np.asarray(m.uvs)
        for k in ("part_ids", "kinds", "colors", "instances"):
            poly.cell_data[k] = np.asarray(getattr(m, k))
        return poly


def write_mesh(mesh: Mesh, path: PathLike, fmt: str, *, crs=None, local_frame: Optional[dict] = None,
               groups: Sequence[str] = ()) -> Tuple[str, ...]:
    """Write ``mesh`` as ``fmt`` ("obj" or "ply"), atomically, in Rust, and
    its sidecars (``name.json``, ``name.prj`` with a CRS; see
    :meth:`Mesh.write`): the header records the offset and CRS too (OBJ
    ``# offset X Y Z``, PLY ``comment offset X Y Z``, as ``fractalgeo
    tin``'s files). ``crs`` replaces ``mesh.crs``; ``local_frame`` (a
    JSON-ready dict) is recorded for a mesh in a local metric frame of a
    geographic DEM; ``groups[k]`` names the OBJ group of the triangles of
    kind ``k`` (default ``branches``, ``leaves``, ``kind<k>``). Returns the
    paths written."""
    from fractalgeo_rs.geometry._meshfile import crs_wkt, header_lines, write_sidecars

    if not isinstance(mesh, Mesh):
        raise TypeError(f"mesh: expected a Mesh, got {type(mesh).__name__}")
    p = os.fspath(path)
    if os.path.splitext(p)[1].lower() in (".json", ".prj"):
        raise ValueError(f"path: a mesh file cannot be named like its own sidecar (.json, .prj), got {p!r}")
    m = mesh._arrays()
    wkt = crs_wkt(crs if crs is not None else m.crs)  # a bad CRS fails before any file is written
    head = header_lines("fractalgeo_rs mesh", len(m.vertices), len(m), m.origin, wkt, "local")[1:]
    if local_frame is not None:
        head.append("local_frame: see the .json sidecar (lon, lat from x, y)")
    _core.write_mesh(p, fmt, m, [line.encode("ascii", "replace").decode("ascii") for line in head],
                     [str(g) for g in groups])
    return (p,) + write_sidecars(
        p, m.origin, wkt=wkt, n_vertices=len(m.vertices), n_triangles=len(m.faces), coordinates="local",
        description="fractalgeo_rs mesh (map x, y, z = file x, y, z + offset)", local_frame=local_frame)
