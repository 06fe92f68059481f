"""One dispatcher from array type to runner for every map and raster function.

A raster function is written once as a numpy kernel over a 2D float block
(NaN = missing) that returns its outputs stacked on a leading axis, shape
``(k, ceil(rows / step), ceil(cols / step))``. :func:`run_raster` then runs
it on a numpy array, a dask array (``overlap`` with a NaN halo of ``depth``
pixels, blocks computed independently, halos cropped) or an
``xarray.DataArray`` (its data through one of the two, the result re-wrapped
with the input's coords, subsampled by ``step``, and attrs), in the manner of
xarray-spatial's ``ArrayTypeFunctionMapping``.

The NaN halo is the edge policy of the windowed kernels (the image is taken
as NaN-padded), so a chunked result equals the in-memory one. A kernel with
its own rule at the raster's edges (hillshade's GDAL extrapolation) is run
with ``boundary="none"``: blocks at the raster's edges get no halo there and
the kernel applies its rule to the true edges only, chunk borders keep their
real neighbours.

With ``progress`` an in-memory image is computed in strips of rows, each
with the kernel's halo of real rows (none beyond the raster's edges), and a
bar ticks per strip: the result is the one of a single call, bit for bit.
"""
from __future__ import annotations

from typing import Callable, Dict, Optional, Sequence

import numpy as np

__all__ = ["run_raster", "halo_blocks", "array_kind", "require"]

_EXTRAS = {"dask": "dask", "xarray": "dask", "rasterio": "geo", "matplotlib": "plot", "tqdm": "progress",
           "trimesh": "mesh", "pyvista": "pyvista"}


def require(module: str):
    """Import an optional dependency, or raise one clear ImportError naming
    the extra that installs it."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        extra = _EXTRAS.get(module.split(".")[0], module)
        raise ImportError(f"{module} is needed here: pip install \"fractalgeo_rs[{extra}]\"") from None


def array_kind(data) -> str:
    """``"xarray"``, ``"dask"`` or ``"numpy"`` (anything else array-like)."""
    mod = type(data).__module__
    if mod.startswith("xarray") and hasattr(data, "dims"):
        return "xarray"
    if mod.startswith("dask"):
        return "dask"
    return "numpy"


def _even_chunks(n: int, size: int, step: int, depth: int) -> tuple:
    """Chunks of ``size`` rounded up to a multiple of ``step``, the last one
    merged into its neighbour when it is shorter than ``depth``."""
    size = -(-size // step) * step
    out = [size] * (n // size) + ([n % size] if n % size else [])
    if len(out) > 1 and out[-1] < depth:
        tail = out.pop()
        out[-1] += tail
    return tuple(out)


#: Strips of an in-memory image computed with progress (about this many).
PROGRESS_STRIPS = 32


def _call(kernel, block, origin, locate):
    return kernel(block, origin) if locate else kernel(block)


def _stacked(out):
    """The kernel's maps as one ``(n_out, ...)`` array (a kernel may return a
    sequence of equally shaped maps, which is not copied where no caller
    needs them stacked)."""
    return np.stack(out) if isinstance(out, (list, tuple)) else out


def _run_numpy(kernel, arr, *, n_out, depth, step, dtype, locate=False, progress=False, desc="", **_):
    rows = arr.shape[0]
    if not progress:
        out = _call(kernel, arr, (0, 0), locate)
        assert len(out) == n_out
        return out
    from fractalgeo_rs._progress import bar

    # strips of a multiple of step rows, each read with a halo of real rows
    # rounded up to the step (so its first output row stays on the grid)
    halo = -(-depth // step) * step
    height = max(step, -(-(-(-rows // PROGRESS_STRIPS)) // step) * step)
    starts = list(range(0, rows, height))
    parts = []
    with bar(len(starts), desc, True) as b:
        for r0 in starts:
            r1 = min(rows, r0 + height)
            a0, a1 = max(0, r0 - halo), min(rows, r1 + halo)
            res = _stacked(_call(kernel, arr[a0:a1], (a0, 0), locate))
            k0 = (r0 - a0) // step
            parts.append(res[:, k0:k0 + -(-(r1 - r0) // step)])
            b.update(1)
    out = np.concatenate(parts, axis=1) if len(parts) > 1 else parts[0]
    assert out.shape[0] == n_out
    return out


def halo_blocks(arr, depth: int, step: int = 1):
    """``(padded, core)``: the dask array ``arr`` with a NaN halo of
    ``depth`` pixels around every block, and the chunks of the blocks it
    was cut into (before the halo).

    Chunks smaller than the halo are merged into their neighbours (and with
    a ``step`` every chunk but the last is a multiple of it); an axis
    shorter than the halo is taken as one block padded with NaN, which is
    what the halo of an edge block holds anyway."""
    import dask.array as da

    if depth == 0:
        return arr, arr.chunks
    if any(n <= depth for n in arr.shape):
        one = arr.rechunk(arr.shape)
        padded = da.pad(one, depth, mode="constant", constant_values=np.nan)
        return padded.rechunk(tuple(n + 2 * depth for n in arr.shape)), one.chunks
    chunks = arr.chunks
    if step > 1 or min(min(c) for c in chunks) < depth:
        # every chunk must hold the halo its neighbours need, and with a
        # step every chunk but the last a multiple of it
        arr = arr.rechunk(tuple(_even_chunks(n, max(depth, max(c)), step, depth)
                                for n, c in zip(arr.shape, chunks)))
    return da.overlap.overlap(arr, depth=depth, boundary=np.nan), arr.chunks


def _run_dask_own_edges(kernel, arr, *, depth: int, n_out: int, dtype, locate=False):
    """Blocks with a halo of real neighbours inside the raster and none
    beyond its edges (``boundary="none"``), step 1."""
    import dask.array as da

    if depth == 0 or any(n <= depth for n in arr.shape):
        arr = arr.rechunk(arr.shape) if depth else arr
        return arr.map_blocks(lambda b, block_info=None: _call(
            kernel, b, tuple(lo for lo, _ in block_info[0]["array-location"]), locate).astype(dtype, copy=False),
            new_axis=0, chunks=((n_out,),) + arr.chunks, dtype=dtype, meta=np.empty((0, 0, 0), dtype))
    if min(min(c) for c in arr.chunks) < depth:
        arr = arr.rechunk(tuple(_even_chunks(n, max(depth, max(c)), 1, depth)
                                for n, c in zip(arr.shape, arr.chunks)))
    core = arr.chunks
    padded = da.overlap.overlap(arr, depth=depth, boundary="none")
    starts = [np.concatenate([[0], np.cumsum(c)[:-1]]) for c in core]

    def block_fn(b, block_info=None):
        loc = block_info[0]["chunk-location"]
        lo = [depth if k > 0 else 0 for k in loc]
        origin = tuple(int(starts[ax][loc[ax]]) - lo[ax] for ax in range(2))
        res = _call(kernel, b, origin, locate)
        n0, n1 = core[0][loc[0]], core[1][loc[1]]
        return res[:, lo[0]:lo[0] + n0, lo[1]:lo[1] + n1].astype(dtype, copy=False)

    return padded.map_blocks(block_fn, new_axis=0, chunks=((n_out,),) + core, dtype=dtype,
                             meta=np.empty((0, 0, 0), dtype))


def _run_dask(kernel, arr, *, depth: int, step: int, n_out: int, dtype, boundary="nan", locate=False, **_):
    if boundary == "none":
        assert step == 1
        return _run_dask_own_edges(kernel, arr, depth=depth, n_out=n_out, dtype=dtype, locate=locate)
    # halo: what a window reaches, rounded up to the step so that every
    # chunk's first output pixel sits on the step grid of its padded block
    depth = -(-depth // step) * step
    padded, _ = halo_blocks(arr, depth, step)
    d0 = depth // step

    def block_fn(b, block_info=None):
        origin = (0, 0)
        if locate:  # global position of the padded block's first pixel
            loc = block_info[0]["chunk-location"]
            origin = tuple(lo - depth * (2 * k + 1)
                           for (lo, _), k in zip(block_info[0]["array-location"], loc))
        res = _call(kernel, b, origin, locate)
        n0 = -(-(b.shape[0] - 2 * depth) // step)
        n1 = -(-(b.shape[1] - 2 * depth) // step)
        return res[:, d0:d0 + n0, d0:d0 + n1].astype(dtype, copy=False)

    out_chunks = ((n_out,),) + tuple(tuple(-(-(c - 2 * depth) // step) for c in cs) for cs in padded.chunks)
    return padded.map_blocks(block_fn, new_axis=0, chunks=out_chunks, dtype=dtype,
                             meta=np.empty((0, 0, 0), dtype))


_RUNNERS: Dict[str, Callable] = {"numpy": _run_numpy, "dask": _run_dask}


def _georeferenced(image, xr_obj, grid):
    """The DataArray whose coords and attrs the outputs take: the input's
    (its CRS checked against the grid's) or one built from the grid."""
    crs = getattr(grid, "crs", None)
    if xr_obj is not None:
        own = xr_obj.attrs.get("crs")
        if own is not None and crs is not None and str(own) != crs:
            raise ValueError(f"grid: CRS {crs!r} does not match the image's CRS {str(own)!r}")
        if crs is not None and own is None:
            xr_obj = xr_obj.copy(deep=False)
            xr_obj.attrs = {**xr_obj.attrs, "crs": crs}
        return xr_obj
    xr = require("xarray")
    y, x = grid.coords(image.shape)
    attrs = {"crs": crs} if crs is not None else {}
    return xr.DataArray(image, dims=("y", "x"), coords={"y": y, "x": x}, attrs=attrs)


def run_raster(
    kernel: Callable[[np.ndarray], np.ndarray],
    image,
    *,
    depth: int,
    n_out: int,
    step: int = 1,
    dtype=np.float32,
    prepare: Optional[Callable] = None,
    names: Optional[Sequence[str]] = None,
    stack_dim: Optional[tuple] = None,
    attrs: Optional[dict] = None,
    boundary: str = "nan",
    locate: bool = False,
    progress: bool = False,
    desc: str = "",
    grid=None,
):
    """Run ``kernel`` on ``image`` of any array type; returns ``k`` outputs.

    Parameters
    ----------
    kernel : callable
        ``kernel(block) -> ndarray (n_out, ceil(r / step), ceil(c / step))``
        (or a list of ``n_out`` such 2D maps) on a 2D block of the image
        (numpy, NaN = missing).
    image : ndarray, dask.array.Array or xarray.DataArray, 2D
        Already validated (real dtype, 2D).
    depth : int
        Pixels of neighbourhood a value depends on (the dask halo).
    n_out : int
        Outputs stacked on the kernel's leading axis.
    step : int
        Output on every ``step``-th row and column.
    prepare : callable, optional
        Applied to every block (or the whole array) before ``kernel``, e.g.
        the float conversion and the nodata mask.
    names : sequence of str, optional
        xarray: the name of each output DataArray.
    stack_dim : (str, values), optional
        Return one 3D output (the kernel's stack) instead of ``n_out``
        arrays; for xarray, the new leading dimension's name and coords.
    attrs : dict, optional
        xarray: attributes added to the outputs' (merged over the input's).
    boundary : {"nan", "none"}
        Beyond the raster's edges: ``"nan"``, the image is taken as
        NaN-padded (the Dask halo there is NaN); ``"none"``, no halo there,
        the kernel applies its own edge rule to the true edges (step 1).
    locate : bool
        Call ``kernel(block, (row, col))`` with the global index of the
        block's first pixel (halo included; negative in a NaN halo).
    progress : bool
        In memory: compute in row strips (with the halo, bit-identical to
        one call) and tick a bar per strip (tqdm if installed). Dask work
        is lazy: wrap its ``compute`` in ``_progress.dask_bar``.
    desc : str
        The bar's label.
    grid : fractalgeo_rs.geometry.GeoGrid, optional
        The input's georeference, read once by the caller
        (``GeoGrid.of``). A DataArray input keeps its coords and gets a
        ``crs`` attribute from the grid when it has none (a different CRS
        is a ``ValueError`` naming ``grid``); a numpy or Dask input gives
        ``xarray.DataArray`` outputs with the grid's cell-centre ``y, x``
        coordinates (every ``step``-th) and ``crs``. Without ``grid`` the
        outputs are as before.

    Returns
    -------
    list of arrays of the input's type (or one 3D array with ``stack_dim``).
    """
    kind = array_kind(image)
    xr_obj = image if kind == "xarray" else None
    data = image.data if xr_obj is not None else image
    inner = "dask" if array_kind(data) == "dask" else "numpy"
    prep = prepare or (lambda b: b)
    if boundary not in ("nan", "none"):
        raise ValueError(f"boundary: expected 'nan' or 'none', got {boundary!r}")
    def run(b, *origin):  # origin: the block's (row, col) when locate is set
        out = kernel(prep(b), *origin)
        return out if inner == "numpy" else _stacked(out)
    stacked = _RUNNERS[inner](run, data, depth=depth, step=step, n_out=n_out, dtype=dtype,
                              boundary=boundary, locate=locate, progress=progress, desc=desc)
    if stack_dim is not None:
        stacked = _stacked(stacked)
    if grid is not None:
        xr_obj = _georeferenced(image, xr_obj, grid)
    if xr_obj is None:
        return stacked if stack_dim is not None else [stacked[k] for k in range(n_out)]
    dims = xr_obj.dims
    grid = xr_obj.isel({dims[0]: slice(None, None, step), dims[1]: slice(None, None, step)})
    new_attrs = {**xr_obj.attrs, **(attrs or {})}
    if stack_dim is not None:
        import xarray as xr

        dim, values = stack_dim
        coords = {dim: list(values), **{k: v for k, v in grid.coords.items()}}
        return xr.DataArray(stacked, dims=(dim,) + tuple(dims), coords=coords, attrs=new_attrs,
                            name=names[0] if names else None)
    out = []
    for k in range(n_out):
        a = grid.copy(data=stacked[k]).astype(dtype)
        a.attrs = dict(new_attrs)
        out.append(a.rename(names[k] if names else xr_obj.name))
    return out
