"""Delaunay triangulation, greedy terrain TINs and gridding (kernels in ``rust/tin``)."""
from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._backend import array_kind
from fractalgeo_rs.geometry import GeoGrid, Mesh
from fractalgeo_rs._validation import (
    as_array,
    check_memory,
    check_choice,
    check_n_threads,
    check_nodata,
    warn_void_sentinel,
    check_positive_float,
    check_positive_int,
)

__all__ = ["TIN", "delaunay", "tin_from_dem", "grid_from_points"]


def _points(points, name: str = "points") -> np.ndarray:
    p = as_array(points, name)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"{name}: expected shape (n, 2) or (n, 3), got {p.shape}")
    if p.dtype.kind not in "fiu":
        raise TypeError(f"{name}: expected a real-valued array, got dtype {p.dtype}")
    return p if p.dtype == np.float64 else p.astype(np.float64)


def _affine(transform, cell_size, rows: int) -> Tuple[float, float, float, float, float, float]:
    """``(a, b, c, d, e, f)`` with ``x = a col + b row + c``, ``y = d col + e row + f``
    for pixel-corner coordinates (rasterio's ``Affine``)."""
    if transform is not None and cell_size is not None:
        raise ValueError("cell_size: give either transform or cell_size, not both")
    if transform is None:
        h = 1.0 if cell_size is None else check_positive_float(cell_size, "cell_size")
        return (h, 0.0, 0.0, 0.0, -h, rows * h)
    if all(hasattr(transform, k) for k in "abcdef"):
        a, b, c, d, e, f = (float(getattr(transform, k)) for k in "abcdef")
        t = (a, b, c, d, e, f)
    else:
        try:
            g = [float(v) for v in transform]
        except (TypeError, ValueError):
            raise TypeError("transform: expected an Affine or a GDAL 6-tuple") from None
        if len(g) != 6:
            raise ValueError(f"transform: expected 6 numbers (GDAL order), got {len(g)}")
        t = (float(g[1]), float(g[2]), float(g[0]), float(g[4]), float(g[5]), float(g[3]))
    if not all(np.isfinite(t)) or t[0] * t[4] - t[1] * t[3] == 0:
        raise ValueError(f"transform: must be finite and invertible, got {t}")
    return t


def delaunay(points, *, constraints=None, n_threads=None) -> np.ndarray:
    r"""Delaunay triangulation of 2D points, optionally constrained.

    The triangulation is computed by the Rust crate spade (bulk loading,
    exact predicates), so the empty-circumcircle property holds exactly for
    the input coordinates: no input point lies strictly inside the
    circumcircle of any triangle. For points in general position the
    triangulation is unique and has :math:`2n - 2 - h` triangles (:math:`h`
    points on the convex hull); for degenerate sets (grids, cocircular
    points) one of the valid triangulations is returned.

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        Coordinates ``x, y`` (a third column, e.g. heights, is ignored and
        stays with its row). Any strides; converted to float64. Not modified.
    constraints : array_like of int, shape (k, 2), optional
        Break lines as pairs of point indices (rivers, ridges, shorelines):
        the result is the constrained Delaunay triangulation (Chew 1989) in
        which every constraint segment is a union of triangle edges (split
        at any input point lying on it). Constraints may share end points
        but not cross.
    n_threads : int, optional
        Threads for the parallel parts: sorting the points into the order of
        spade's circle sweep, and reading out the triangles. The sweep
        itself is sequential. The result does not depend on it.

    Returns
    -------
    triangles : ndarray of int64, shape (m, 3)
        Row indices into ``points``, counter-clockwise (positive signed area
        in the ``x, y`` plane). Exact duplicate points are merged: triangles
        refer to the first occurrence, later copies appear in no triangle.

    Raises
    ------
    ValueError
        Fewer than 3 distinct points, all points collinear, NaN or infinite
        coordinates, a constraint index out of range, a constraint joining a
        point to itself or crossing an earlier one.

    References
    ----------
    Delaunay, B. (1934). Sur la sphère vide. Bull. Acad. Sci. URSS 6, 793-800.
    Chew, L. P. (1989). Constrained Delaunay triangulations. Algorithmica 4,
    97-108. https://doi.org/10.1007/BF01553881

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.tin import delaunay
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.4]])
    >>> delaunay(sq).shape
    (4, 3)
    >>> tri = delaunay(sq[:4], constraints=[[1, 3]])
    >>> bool(np.all([(1 in t) and (3 in t) for t in tri]))
    True
    """
    p = _points(points)
    n_threads = check_n_threads(n_threads)
    c = None
    if constraints is not None:
        c = as_array(constraints, "constraints")
        if c.size == 0:
            c = None
        else:
            if c.dtype.kind not in "iu":
                raise TypeError(f"constraints: expected integer point indices, got dtype {c.dtype}")
            if c.ndim != 2 or c.shape[1] != 2:
                raise ValueError(f"constraints: expected shape (k, 2), got {c.shape}")
            if c.dtype.kind == "u" and c.size and c.max() > np.iinfo(np.int64).max:
                raise ValueError("constraints: index out of range")
            c = np.ascontiguousarray(c, dtype=np.int64)
    return _core.tin_delaunay(p, c, n_threads)


@dataclass(frozen=True)
class TIN:
    """A triangulated terrain surface.

    Attributes
    ----------
    vertices : ndarray of float64, shape (n, 3)
        Map coordinates ``x, y`` (sample centres) and height ``z``.
    triangles : ndarray of int64, shape (m, 3)
        Vertex indices, counter-clockwise seen from +z.
    max_error : float
        Largest vertical distance ``|z - mesh|`` over the valid samples the
        mesh covers (same unit as the DEM).
    grid : ndarray of int64, shape (n, 2)
        ``(col, row)`` of the DEM sample of every vertex.
    shape : tuple of int
        The DEM's ``(rows, cols)``.
    transform : tuple of float
        ``(a, b, c, d, e, f)``: pixel corner ``(col, row)`` maps to
        ``(a col + b row + c, d col + e row + f)`` (rasterio's ``Affine``).
    crs : str or None
        The DEM's coordinate reference system when it had one (a DataArray's
        or ``grid``'s), else None.

    References
    ----------
    Garland, M., Heckbert, P. S. (1995). Fast polygonal approximation of
    terrains and height fields. Technical Report CMU-CS-95-181, Carnegie
    Mellon University.

    Examples
    --------
    >>> import numpy as np, fractalgeo_rs as fg
    >>> i, j = np.indices((9, 9))
    >>> tin = fg.tin_from_dem(0.5 * i + 0.25 * j, max_error=0.01)
    >>> len(tin), tin.vertices.shape  # a plane needs only its four corners
    (2, (4, 3))
    >>> bool(np.allclose(tin.to_grid(), 0.5 * i + 0.25 * j))
    True
    """

    vertices: np.ndarray
    triangles: np.ndarray
    max_error: float
    grid: np.ndarray
    shape: Tuple[int, int]
    transform: Tuple[float, float, float, float, float, float]
    crs: Optional[str] = None

    def __len__(self) -> int:
        return len(self.triangles)

    def _grid_triangles(self) -> np.ndarray:
        a, b, _, d, e, _ = self.transform
        return self.triangles if a * e - b * d > 0 else self.triangles[:, [0, 2, 1]]

    def to_grid(self, n_threads=None) -> np.ndarray:
        """Rasterise the mesh back onto the DEM grid (barycentric
        interpolation at the sample centres); NaN where no triangle covers a
        sample (holes, outside the hull).

        Returns
        -------
        ndarray of float64, shape ``self.shape``
        """
        n_threads = check_n_threads(n_threads)
        return _core.tin_rasterize(
            np.ascontiguousarray(self.grid, dtype=np.float64),
            np.ascontiguousarray(self.vertices[:, 2]),
            np.ascontiguousarray(self._grid_triangles()),
            self.shape[0],
            self.shape[1],
            n_threads,
        )

    def normals(self) -> np.ndarray:
        """Unit per-vertex normals: area-weighted sums of the face normals
        (the cross product of two edges has length twice the area)."""
        v = self.vertices
        t = self.triangles
        fn = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
        n = np.zeros_like(v)
        for k in range(3):
            np.add.at(n, t[:, k], fn)
        length = np.linalg.norm(n, axis=1, keepdims=True)
        return np.divide(n, length, out=np.zeros_like(n), where=length > 0)

    def to_mesh(self) -> Mesh:
        """The TIN as a :class:`~fractalgeo_rs.geometry.Mesh`, built in
        Rust: float32 vertices relative to ``origin`` = the lower-left
        vertex (map ``x, y`` minima, z = 0), so that float32 keeps
        millimetres in UTM; per-vertex area-weighted normals (:meth:`normals`);
        UVs = map ``x, y`` scaled to [0, 1] over the mesh's bounding box;
        ``part_ids`` = triangle number; ``crs`` the TIN's."""
        return Mesh._from_core(_core.mesh_from_tin(np.ascontiguousarray(self.vertices, dtype=np.float64),
                                                   np.ascontiguousarray(self.triangles, dtype=np.int64)),
                               crs=self.crs)

    def write_obj(self, path, *, coordinates: str = "local", crs=None) -> None:
        """Write the mesh as Wavefront OBJ, georeferenced.

        Vertices ``v x y z`` in float64 text, relative to the offset
        recorded in the header comment ``# offset X Y Z`` (``coordinates=
        "local"``: the lower-left corner) or in map coordinates
        (``"map"``); faces ``f i j k`` (1-based). A sidecar ``name.json``
        records the offset, the CRS (WKT) and the DEM's transform; with a
        ``crs`` its WKT is also written to ``name.prj``. Map ``x, y, z`` =
        file ``x, y, z`` + offset.
        """
        from fractalgeo_rs.tin._export import write_tin

        write_tin(self, path, coordinates=coordinates, crs=crs if crs is not None else self.crs)

    def write_ply(self, path, *, coordinates: str = "local", crs=None) -> None:
        """Write the mesh as binary little-endian PLY, georeferenced:
        vertices ``x y z`` as doubles, the offset in the header comment
        ``comment offset X Y Z`` and the sidecars of :meth:`write_obj`."""
        from fractalgeo_rs.tin._export import write_tin

        write_tin(self, path, coordinates=coordinates, crs=crs if crs is not None else self.crs)

    def write_png(self, path, *, azimuth: float = 315.0, altitude: float = 45.0, crs=None) -> None:
        """Write a shaded-relief PNG preview of the mesh: :meth:`to_grid`
        shaded by :func:`fractalgeo_rs.hillshade` (0 = no triangle), on the
        DEM's grid: georeferenced by a world file (``.pgw``) and, with a
        ``crs`` (default: the TIN's own ``crs``), its WKT in ``.prj``."""
        from fractalgeo_rs.dem import hillshade
        from fractalgeo_rs.io import write_raster

        a, b, c, d, e, f = self.transform
        cell = (float(np.hypot(b, e)), float(np.hypot(a, d)))  # (row, column) spacing, rotated grids too
        shade = hillshade(self.to_grid(), azimuth=azimuth, altitude=altitude, cell_size=cell, byte=True)
        write_raster(path, shade, transform=(a, b, c, d, e, f), crs=crs)


def _default_max_error(z: np.ndarray) -> float:
    valid = z[~np.isnan(z)]
    if valid.size == 0:
        return 0.0
    lo, hi = np.percentile(valid, [2.0, 98.0])
    return 0.005 * float(hi - lo)


def tin_from_dem(dem, *, max_error=None, max_triangles=None, transform=None, cell_size=None,
                 nodata=None, tile_edges="shared", grid=None, n_threads=None) -> TIN:
    r"""Error-bounded triangulated irregular network of a DEM.

    Greedy insertion (Garland and Heckbert 1995, the scheme of Delatin):
    starting from the convex hull of the valid samples (the four corners of a
    DEM without nodata), the sample of largest vertical error

    .. math:: e = |z_{ij} - \pi_T(x_j, y_i)|,

    with :math:`\pi_T` the plane of the triangle :math:`T` containing it, is
    inserted into the Delaunay triangulation until every valid sample is
    within ``max_error`` of the mesh or the mesh has ``max_triangles``
    triangles. Only the triangles around each new vertex are re-examined.

    A DEM of more than 129 samples along a side is meshed in tiles of at most
    129 x 129 samples (a fixed tiling by the shape alone: ``ceil((n - 1) /
    128)`` tiles of nearly equal size along an axis of ``n`` samples,
    neighbours sharing a seam row or column), in parallel. Every seam gets
    its vertices from the 1D simplification of its samples described under
    ``tile_edges="shared"``, so both sides have the same vertices there and
    the merged mesh is watertight; vertices are merged by grid position and
    the triangles concatenated in tile order, so the result is the same for
    any ``n_threads``.

    Vertices are in the DEM's map units: a ``xarray.DataArray`` brings its
    georeference (coordinates or rioxarray transform and CRS, read by
    :meth:`fractalgeo_rs.geometry.GeoGrid.of`), a numpy array takes
    ``transform``, ``cell_size`` or ``grid``. A grid in degrees (a
    geographic CRS) is refused unless ``cell_size`` gives the ground
    spacing in metres (the mesh is then in a local metric frame with its
    origin at the lower-left corner): a mesh needs one unit for x, y and z.

    Parameters
    ----------
    dem : array_like or xarray.DataArray, shape (rows, cols)
        Heights; any real dtype. NaN (and ``nodata``) samples are left out:
        triangles covering them are dropped, so nodata areas become holes.
        Not modified. A Dask array (or a DataArray backed by one) is refused
        with a ``TypeError``: the greedy insertion needs the whole raster,
        so call ``.compute()`` first.
    max_error : float, optional
        Largest allowed vertical error (DEM units), >= 0. Default: 0.5 % of
        the robust relief (98th minus 2nd percentile of the valid heights);
        ``0`` keeps every sample that is not on a plane through its
        neighbours.
    max_triangles : int, optional
        Triangle budget: refinement stops when it is reached (the achieved
        ``max_error`` is then larger than asked). The budget is spent
        worst-first over the whole DEM, so with ``max_triangles`` the DEM is
        meshed as one tile, sequentially.
    transform : Affine or GDAL 6-tuple, optional
        Georeferencing of the DEM (pixel corners); vertices sit at sample
        centres. Default: ``cell_size`` spacing, north up, origin at the lower
        left corner of the raster.
    cell_size : float, optional
        Sample spacing when there is no ``transform`` (default 1).
    nodata : float, optional
        Height value meaning "no data" (NaN always is).
    grid : GeoGrid, optional
        The georeference as a :class:`~fractalgeo_rs.geometry.GeoGrid`
        (instead of ``transform`` or ``cell_size``); its CRS must match a
        DataArray's.
    tile_edges : {"shared", "free"}
        ``"shared"``: the vertices on the four raster edges are chosen from
        the edge samples alone (Douglas-Peucker within ``max_error`` on each
        run of valid edge samples) and no other edge sample is inserted, so
        adjacent tiles of one DEM meshed separately have identical vertices
        on their common edge and join without cracks. ``"free"``: edge
        samples are refined like any other (fewer vertices). The option
        applies to the DEM's outer edges; the seams between the internal
        tiles are always simplified as shared edges.
    n_threads : int, optional
        Tiles are meshed in parallel on this many threads (default: all
        cores); the result does not depend on it.

    Returns
    -------
    TIN
        ``vertices`` (n, 3), ``triangles`` (m, 3) counter-clockwise from +z,
        the achieved ``max_error``, ``to_grid()``, ``to_mesh()``.

    References
    ----------
    Garland, M. and Heckbert, P. S. (1995). Fast polygonal approximation of
    terrains and height fields. CMU-CS-95-181, Carnegie Mellon University.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.tin import tin_from_dem
    >>> yy, xx = np.mgrid[0:65, 0:65]
    >>> dem = 100.0 + 0.5 * xx - 0.25 * yy          # a plane
    >>> t = tin_from_dem(dem, max_error=0.01, cell_size=30.0)
    >>> t.vertices.shape, t.triangles.shape
    ((4, 3), (2, 3))
    >>> bool(np.allclose(t.to_grid(), dem))
    True
    """
    kind = array_kind(dem)
    if array_kind(dem.data if kind == "xarray" else dem) == "dask":
        raise TypeError("dem: a Dask array is not meshed lazily (the greedy insertion needs the whole raster); "
                        "pass dem.compute() (or dem.load() for a DataArray)")
    geo = None
    if kind == "xarray" or grid is not None:
        geo = GeoGrid.of(dem, grid=grid, transform=transform, cell_size=cell_size, param="dem",
                         rows=int(np.shape(dem)[0]) if np.ndim(dem) == 2 else None)
        if geo is not None:
            geo.require_projected("grid" if grid is not None else "dem")
    a = as_array(dem.values if kind == "xarray" else dem, "dem")
    if a.ndim != 2:
        raise ValueError(f"dem: expected a 2D array, got shape {a.shape}")
    if a.dtype.kind not in "fiu":
        raise TypeError(f"dem: expected a real-valued array, got dtype {a.dtype}")
    z = np.array(a, dtype=np.float64, order="C", copy=True)
    nd = check_nodata(nodata)
    warn_void_sentinel(a, "dem", nd)
    if nd is not None and not np.isnan(nd):
        z[z == nd] = np.nan
    if max_error is None:
        max_error = _default_max_error(z)
    else:
        if isinstance(max_error, bool) or not isinstance(max_error, numbers.Real):
            raise TypeError(f"max_error: expected a number >= 0, got {max_error!r}")
        max_error = float(max_error)
        if not np.isfinite(max_error) or max_error < 0:
            raise ValueError(f"max_error: expected a finite number >= 0, got {max_error}")
    if max_triangles is not None:
        max_triangles = check_positive_int(max_triangles, "max_triangles")
    check_choice(tile_edges, "tile_edges", ("shared", "free"))
    n_threads = check_n_threads(n_threads)
    t = geo.affine if geo is not None else _affine(transform, cell_size, z.shape[0])
    cells, zs, tris, achieved = _core.tin_greedy(z, max_error, max_triangles, tile_edges == "shared", n_threads)
    ta, tb, tc, td, te, tf = t
    cc = cells[:, 0] + 0.5
    rr = cells[:, 1] + 0.5
    verts = np.column_stack([ta * cc + tb * rr + tc, td * cc + te * rr + tf, zs])
    if ta * te - tb * td < 0:
        tris = tris[:, [0, 2, 1]]
    return TIN(vertices=verts, triangles=np.ascontiguousarray(tris), max_error=float(achieved),
               grid=cells, shape=(int(z.shape[0]), int(z.shape[1])), transform=t,
               crs=geo.crs if geo is not None else None)


def grid_from_points(points, values, shape, transform=None, *, cell_size=None, method="natural",
                     n_threads=None) -> np.ndarray:
    r"""Grid scattered values through their Delaunay triangulation.

    Methods: ``"natural"``, Sibson's natural-neighbour interpolation

    .. math:: f(\mathbf x) = \sum_i \lambda_i(\mathbf x) f_i,

    with :math:`\lambda_i` the share of the Voronoi cell that
    :math:`\mathbf x` would take from point :math:`i` (continuous, smooth
    except at the data points); ``"natural_c1"``, Sibson's C1 variant with
    gradients estimated from the area-weighted normals of the triangles
    around each point (flatness 1); ``"linear"``, barycentric interpolation
    in the Delaunay triangle (``scipy.interpolate.griddata(method="linear")``);
    ``"nearest"``, the nearest point's value. All methods reproduce linear
    functions exactly (``nearest`` excepted) and give NaN outside the convex
    hull of the points.

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        Point coordinates ``x, y`` (a third column is ignored). Not modified.
    values : array_like, shape (n,)
        Finite values at the points. Exact duplicate points take the value
        of their first occurrence.
    shape : (int, int)
        ``(rows, cols)`` of the output grid.
    transform : Affine or GDAL 6-tuple, optional
        Georeferencing of the output grid (pixel corners, GDAL's
        convention); values are computed at cell centres, ``x = x0 + (col +
        0.5) dx``, ``y = y0 + (row + 0.5) dy`` for a north-up grid. Default:
        spacing ``cell_size``, north up, origin at the lower-left corner of
        the grid, so cell ``(row, col)`` is centred at ``x = (col + 0.5) h``,
        ``y = (rows - row - 0.5) h``. This is the convention of
        :func:`tin_from_dem`: ``grid_from_points(tin.vertices[:, :2],
        tin.vertices[:, 2], dem.shape, transform)`` puts every vertex back
        on its DEM cell.
    cell_size : float, optional
        Cell size ``h`` when there is no ``transform`` (default 1).
    method : {"natural", "natural_c1", "linear", "nearest"}
    n_threads : int, optional
        Rows are interpolated in parallel; the result does not depend on it.

    Returns
    -------
    ndarray of float64, shape ``shape``

    References
    ----------
    Sibson, R. (1981). A brief description of natural neighbour
    interpolation. In V. Barnett (ed.), Interpreting Multivariate Data,
    21-36. Wiley.

    Examples
    --------
    >>> import numpy as np
    >>> from fractalgeo_rs.tin import grid_from_points
    >>> rng = np.random.default_rng(0)
    >>> pts = np.vstack([[0, 0], [10, 0], [0, 10], [10, 10], rng.uniform(0, 10, (50, 2))])
    >>> vals = 2.0 * pts[:, 0] - pts[:, 1]
    >>> g = grid_from_points(pts, vals, (10, 10))   # cells of size 1 over [0, 10]^2
    >>> row, col = np.mgrid[0:10, 0:10]
    >>> x, y = col + 0.5, 10 - row - 0.5            # cell centres, north up
    >>> bool(np.allclose(g, 2.0 * x - y))
    True
    """
    p = _points(points)
    v = as_array(values, "values")
    if v.ndim != 1 or v.shape[0] != p.shape[0]:
        raise ValueError(f"values: expected shape ({p.shape[0]},), got {v.shape}")
    if v.dtype.kind not in "fiu":
        raise TypeError(f"values: expected a real-valued array, got dtype {v.dtype}")
    if isinstance(shape, (str, bytes)) or not hasattr(shape, "__len__") or len(shape) != 2:
        raise TypeError(f"shape: expected (rows, cols), got {shape!r}")
    rows, cols = (check_positive_int(s, "shape") for s in shape)
    check_memory(8 * rows * cols, "shape", what=f"a {rows} x {cols} float64 grid")
    check_choice(method, "method", ("natural", "natural_c1", "linear", "nearest"))
    n_threads = check_n_threads(n_threads)
    a, b, c, d, e, f = _affine(transform, cell_size, rows)
    g = [c + 0.5 * a + 0.5 * b, a, b, f + 0.5 * d + 0.5 * e, d, e]
    return _core.tin_grid(p, np.ascontiguousarray(v, dtype=np.float64), rows, cols, g, method, n_threads)
