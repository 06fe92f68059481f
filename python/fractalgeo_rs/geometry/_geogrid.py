"""``GeoGrid``: the one georeference of a raster (origin, cell size,
rotation, CRS; row 0 north), the same fields as ``rust/geometry/geogrid.rs``."""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

__all__ = ["GeoGrid"]


def _crs_text(crs) -> Optional[str]:
    """A CRS as text: a str as given, a rasterio/pyproj CRS as its
    ``EPSG:n`` authority string when it has one, else its WKT."""
    if crs is None:
        return None
    if isinstance(crs, str):
        return crs or None
    to_epsg = getattr(crs, "to_epsg", None)
    if callable(to_epsg):
        try:
            code = to_epsg()
        except Exception:  # noqa: BLE001 - a CRS without an EPSG code
            code = None
        if code:
            return f"EPSG:{code}"
    to_wkt = getattr(crs, "to_wkt", None)
    if callable(to_wkt):
        return str(to_wkt())
    if isinstance(crs, numbers.Integral) and not isinstance(crs, bool):
        return f"EPSG:{int(crs)}"
    raise TypeError(f"crs: expected a str, an EPSG code or a CRS object, got {type(crs).__name__}")


_GEOGRAPHIC_CODES = {"EPSG:4326", "EPSG:4258", "EPSG:4269", "EPSG:4267", "EPSG:4979", "OGC:CRS84"}


def _is_geographic(crs: Optional[str]) -> bool:
    if crs is None:
        return False
    for module in ("pyproj", "rasterio.crs"):
        try:
            mod = __import__(module, fromlist=["CRS"])
        except ImportError:
            continue
        try:
            return bool(mod.CRS.from_user_input(crs).is_geographic)
        except Exception:  # noqa: BLE001 - not understood: fall back to the text
            break
    text = crs.strip().upper()
    return (text in _GEOGRAPHIC_CODES or text.startswith(("GEOGCS", "GEOGCRS", "GEODCRS"))
            or "+PROJ=LONGLAT" in text.replace(" ", "") or "+PROJ=LATLONG" in text.replace(" ", ""))


def _real(v, name: str) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise TypeError(f"{name}: expected a number, got {v!r}")
    return float(v)


def _two(v, name: str) -> Tuple[float, float]:
    if isinstance(v, numbers.Real) and not isinstance(v, bool) and name == "cell_size":
        return (float(v), float(v))
    try:
        a, b = v
    except (TypeError, ValueError):
        raise TypeError(f"{name}: expected two numbers, got {v!r}") from None
    return (_real(a, name), _real(b, name))


def _six(transform) -> Tuple[float, ...]:
    """``(a, b, c, d, e, f)`` of an ``Affine`` or a GDAL 6-tuple."""
    if all(hasattr(transform, k) for k in "abcdef"):
        return tuple(float(getattr(transform, k)) for k in "abcdef")
    try:
        g = [float(v) for v in transform]
    except (TypeError, ValueError):
        raise TypeError("transform: expected an Affine or a GDAL 6-tuple") from None
    if len(g) != 6:
        raise ValueError(f"transform: expected 6 numbers (GDAL order), got {len(g)}")
    return (g[1], g[2], g[0], g[4], g[5], g[3])


@dataclass(frozen=True)
class GeoGrid:
    r"""Where a raster's cells are: origin, cell size, rotation and CRS.

    Row 0 is north and columns run east (GDAL's convention). Cell
    ``(row, col)`` spans the corner positions ``row .. row + 1``,
    ``col .. col + 1`` with corner ``(r, c)`` at

    .. math::

        x = x_0 + c\,\Delta x \cos\theta + r\,\Delta y \sin\theta,\qquad
        y = y_0 + c\,\Delta x \sin\theta - r\,\Delta y \cos\theta,

    so the centre of cell ``(0, 0)`` of a north-up grid is
    ``(x0 + dx / 2, y0 - dy / 2)``. The same fields as the Rust
    ``geometry::GeoGrid``; a mesh or raster function reads it once from its
    input (:meth:`of`) and gives map units.

    Attributes
    ----------
    origin : (float, float)
        Map ``(x0, y0)`` of the outer (north-west) corner of cell (0, 0).
    cell_size : (float, float)
        ``(dx, dy)``: cell size along a row and down a column (map units,
        > 0); a single number means square cells.
    rotation : float
        Counter-clockwise rotation of the grid, degrees (0: north up).
    crs : str or None
        Coordinate reference system (``"EPSG:32632"``, WKT or PROJ text; a
        rasterio or pyproj CRS is stored as its ``EPSG:n`` code or WKT).

    Raises
    ------
    ValueError
        A cell size zero, negative or not finite (names ``cell_size``), a
        non-finite ``origin`` or ``rotation``.

    References
    ----------
    GDAL Raster Data Model, affine geotransform:
    https://gdal.org/en/stable/user/raster_data_model.html#affine-geotransform

    Examples
    --------
    >>> from fractalgeo_rs.geometry import GeoGrid
    >>> g = GeoGrid((500000.0, 4000000.0), 30.0, crs="EPSG:32633")
    >>> g.center(0, 0), g.affine
    ((500015.0, 3999985.0), (30.0, 0.0, 500000.0, 0.0, -30.0, 4000000.0))
    >>> g.gdal
    (500000.0, 30.0, 0.0, 4000000.0, 0.0, -30.0)
    >>> GeoGrid.from_transform(g.gdal, crs="EPSG:32633") == g
    True
    """

    origin: Tuple[float, float]
    cell_size: Tuple[float, float]
    rotation: float = 0.0
    crs: Optional[str] = None

    def __post_init__(self):
        origin = _two(self.origin, "origin")
        size = _two(self.cell_size, "cell_size")
        for v in size:
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"cell_size: expected finite numbers > 0, got {self.cell_size!r}")
        if not all(math.isfinite(v) for v in origin):
            raise ValueError(f"origin: must be finite, got {self.origin!r}")
        rotation = _real(self.rotation, "rotation")
        if not math.isfinite(rotation):
            raise ValueError(f"rotation: must be finite, got {self.rotation}")
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "cell_size", size)
        object.__setattr__(self, "rotation", rotation)
        object.__setattr__(self, "crs", _crs_text(self.crs))

    @property
    def x0(self) -> float:
        """Map x of the outer corner of cell (0, 0)."""
        return self.origin[0]

    @property
    def y0(self) -> float:
        """Map y of the outer corner of cell (0, 0)."""
        return self.origin[1]

    @property
    def dx(self) -> float:
        """Cell size along a row."""
        return self.cell_size[0]

    @property
    def dy(self) -> float:
        """Cell size down a column."""
        return self.cell_size[1]

    # ------------------------------------------------------------ builders
    @classmethod
    def from_transform(cls, transform, crs=None) -> "GeoGrid":
        """The grid of an affine transform: a rasterio ``Affine`` (or any
        object with attributes ``a`` to ``f``) or a GDAL 6-tuple ``(c, a, b,
        f, d, e)`` (see :attr:`gdal`), as ``tin_from_dem(transform=)``. Only row-0-north grids with square-angled cells are
        grids: a south-up or sheared transform is a ``ValueError`` naming
        ``transform``."""
        a, b, c, d, e, f = _six(transform)
        t = (a, b, c, d, e, f)
        if not all(math.isfinite(v) for v in t):
            raise ValueError(f"transform: must be finite, got {t}")
        dx, dy = math.hypot(a, d), math.hypot(b, e)
        if not (a * e - b * d < 0) or abs(a * b + d * e) > 1e-12 * dx * dy:
            raise ValueError(f"transform: expected a grid with row 0 north and square-angled cells "
                             f"(e < 0 when not rotated), got {t}")
        rotation = 0.0 if b == 0 and d == 0 else math.degrees(math.atan2(d, a))
        return cls((c, f), (dx, dy), rotation, crs)

    @classmethod
    def from_affine(cls, coefficients, crs=None) -> "GeoGrid":
        """The grid of the six affine coefficients in rasterio's order
        ``(a, b, c, d, e, f)`` (``x = a col + b row + c``, ``y = d col + e
        row + f``), e.g. the ``transform`` of the bundled data's info dict
        (:attr:`affine` is the inverse)."""
        try:
            a, b, c, d, e, f = (float(v) for v in coefficients)
        except (TypeError, ValueError):
            raise TypeError(f"transform: expected 6 numbers (a, b, c, d, e, f), got {coefficients!r}") from None
        return cls.from_transform((c, a, b, f, d, e), crs)

    @classmethod
    def from_cell_size(cls, rows: int, cell_size, crs=None) -> "GeoGrid":
        """The grid used when a raster has no georeference: square cells of
        ``cell_size``, north up, the lower-left corner of ``rows`` rows at
        the origin (``y0 = rows * cell_size``)."""
        h = _real(cell_size, "cell_size")
        return cls((0.0, int(rows) * h), (h, h), 0.0, crs)

    @classmethod
    def from_xarray(cls, da, *, param: str = "dem") -> "GeoGrid":
        """The grid of a 2D ``xarray.DataArray``: rioxarray's transform and
        CRS when present, else equally spaced cell-centre coordinates of its
        two dimensions (``y`` decreasing down the rows) and a ``crs``
        attribute. Errors name ``param``."""
        if getattr(da, "ndim", None) != 2:
            raise ValueError(f"{param}: expected a 2D DataArray, got dims {getattr(da, 'dims', None)}")
        crs = _xarray_crs(da)
        rio = _rio(da)
        if rio is not None:
            return cls.from_transform(rio.transform(recalc=True), crs)
        ydim, xdim = da.dims
        if ydim not in da.coords or xdim not in da.coords:
            t = da.attrs.get("transform")
            if t is not None:
                return cls.from_transform(t, crs)
            raise ValueError(f"{param}: the DataArray has no coordinates on {da.dims} and no transform "
                             f"attribute; pass cell_size= or transform= for a numpy array instead")
        x = np.asarray(da.coords[xdim].values, dtype=np.float64)
        y = np.asarray(da.coords[ydim].values, dtype=np.float64)
        if x.size < 2 or y.size < 2:
            raise ValueError(f"{param}: need at least 2 coordinates along each dimension to know the "
                             f"cell size, got {y.size} x {x.size}")
        dx = (x[-1] - x[0]) / (x.size - 1)
        dy = (y[0] - y[-1]) / (y.size - 1)
        for v, step, name in ((x, dx, xdim), (y, -dy, ydim)):
            if not np.allclose(np.diff(v), step, rtol=1e-6, atol=0.0):
                raise ValueError(f"{param}: coordinate {name!r} is not equally spaced")
        if not dx > 0:
            raise ValueError(f"{param}: coordinate {xdim!r} must increase to the east, got step {dx}")
        if not dy > 0:
            raise ValueError(f"{param}: coordinate {ydim!r} must decrease down the rows (row 0 north), got "
                             f"step {-dy}; flip it with .isel({ydim}=slice(None, None, -1))")
        return cls((float(x[0] - dx / 2), float(y[0] + dy / 2)), (float(dx), float(dy)), 0.0, crs)

    @classmethod
    def of(cls, image, *, grid=None, transform=None, cell_size=None, crs=None, param: str = "dem",
           rows: Optional[int] = None) -> Optional["GeoGrid"]:
        """The one reader: the grid of ``image`` from exactly one source.

        ``grid`` (a GeoGrid), ``transform`` (with ``crs``) or ``cell_size``
        when given (at most one of them); else the coordinates or rioxarray
        attributes of an ``xarray.DataArray``; else ``None`` (a bare array).
        A ``crs`` (or ``grid.crs``) that differs from the DataArray's is a
        ``ValueError`` naming ``crs`` (or ``grid``).
        """
        given = [k for k, v in (("grid", grid), ("transform", transform), ("cell_size", cell_size))
                 if v is not None]
        if len(given) > 1:
            raise ValueError(f"{given[-1]}: give only one of grid, transform and cell_size, got {given}")
        is_xr = type(image).__module__.startswith("xarray") and hasattr(image, "dims")
        own = None
        if is_xr and not given:
            own = cls.from_xarray(image, param=param)
        elif is_xr:
            own_crs = _xarray_crs(image)
            other = grid.crs if grid is not None else _crs_text(crs)
            if own_crs and other and own_crs != other:
                raise ValueError(f"{'grid' if grid is not None else 'crs'}: CRS {other!r} does not match "
                                 f"the {param}'s CRS {own_crs!r}")
        if grid is not None:
            if not isinstance(grid, GeoGrid):
                raise TypeError(f"grid: expected a GeoGrid, got {type(grid).__name__}")
            if crs is not None and grid.crs is not None and _crs_text(crs) != grid.crs:
                raise ValueError(f"crs: {_crs_text(crs)!r} does not match grid.crs {grid.crs!r}")
            return grid
        if transform is not None:
            return cls.from_transform(transform, crs)
        if cell_size is not None:
            n = rows if rows is not None else int(np.shape(image)[0])
            return cls.from_cell_size(n, cell_size, crs)
        if own is not None and crs is not None:
            if own.crs is not None and own.crs != _crs_text(crs):
                raise ValueError(f"crs: {_crs_text(crs)!r} does not match the {param}'s CRS {own.crs!r}")
            return GeoGrid(own.origin, own.cell_size, own.rotation, crs)
        return own

    # ------------------------------------------------------------ queries
    @property
    def affine(self) -> Tuple[float, float, float, float, float, float]:
        """``(a, b, c, d, e, f)``: ``x = a col + b row + c``, ``y = d col +
        e row + f`` for corner positions (rasterio's ``Affine`` order)."""
        if self.rotation == 0.0:
            return (self.dx, 0.0, self.x0, 0.0, -self.dy, self.y0)
        s, c = math.sin(math.radians(self.rotation)), math.cos(math.radians(self.rotation))
        return (self.dx * c, self.dy * s, self.x0, self.dx * s, -self.dy * c, self.y0)

    @property
    def gdal(self) -> Tuple[float, float, float, float, float, float]:
        """The GDAL geotransform ``(c, a, b, f, d, e)`` (what
        :meth:`from_transform` takes as a 6-tuple)."""
        a, b, c, d, e, f = self.affine
        return (c, a, b, f, d, e)

    @property
    def is_geographic(self) -> bool:
        """True when the CRS is in degrees (e.g. EPSG:4326); uses pyproj or
        rasterio when installed, else recognises the common codes and WKT."""
        return _is_geographic(self.crs)

    def center(self, row, col):
        """Map ``(x, y)`` of the centre of cell ``(row, col)`` (scalars or arrays)."""
        a, b, c, d, e, f = self.affine
        cc, rr = np.add(col, 0.5), np.add(row, 0.5)
        x, y = a * cc + b * rr + c, d * cc + e * rr + f
        if np.ndim(x) == 0:
            return float(x), float(y)
        return x, y

    def coords(self, shape) -> Tuple[np.ndarray, np.ndarray]:
        """``(y, x)``: the cell-centre coordinates of the rows and columns of
        a north-up grid of ``shape`` (for an ``xarray.DataArray``)."""
        if self.rotation != 0.0:
            raise ValueError("grid: a rotated grid has no 1D row and column coordinates")
        rows, cols = (int(n) for n in shape)
        return (self.y0 - self.dy * (np.arange(rows) + 0.5), self.x0 + self.dx * (np.arange(cols) + 0.5))

    def check_same_crs(self, other: "GeoGrid", param: str = "grid") -> None:
        """``ValueError`` naming ``param`` when both grids have a CRS and
        they differ (a missing CRS matches any)."""
        if self.crs is not None and other.crs is not None and self.crs != other.crs:
            raise ValueError(f"{param}: CRS {other.crs!r} does not match {self.crs!r}")

    def require_projected(self, param: str = "dem") -> None:
        """``ValueError`` naming ``param`` when the CRS is geographic
        (degrees): a mesh or a slope needs the same unit in x, y and z."""
        if self.is_geographic:
            raise ValueError(f"{param}: the grid's CRS {self.crs!r} is geographic (degrees); reproject it "
                             f"to a projected CRS in metres (e.g. UTM, rioxarray's .rio.reproject), or give the ground "
                             f"spacing in metres (cell_size=, or a GeoGrid without a geographic CRS)")


def _rio(da):
    """rioxarray's accessor when it is installed and the array has a transform."""
    try:
        import rioxarray  # noqa: F401
    except ImportError:
        return None
    rio = getattr(da, "rio", None)
    if rio is None:
        return None
    try:
        if rio.crs is None and "transform" not in da.attrs and not (
                rio.x_dim in da.coords and rio.y_dim in da.coords):
            return None
        rio.transform(recalc=True)
    except Exception:  # noqa: BLE001 - no spatial dimensions rioxarray knows
        return None
    return rio


def _xarray_crs(da) -> Optional[str]:
    rio = _rio(da)
    if rio is not None and rio.crs is not None:
        return _crs_text(rio.crs)
    crs = da.attrs.get("crs")
    if crs is None and "spatial_ref" in da.coords:
        sr = da.coords["spatial_ref"].attrs
        crs = sr.get("crs_wkt") or sr.get("spatial_ref")
    return _crs_text(crs) if crs is not None else None
