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
as NaN-padded), so a chunked result equals the in-memory one.
"""
from __future__ import annotations

from typing import Callable, Dict, Optional, Sequence

import numpy as np

__all__ = ["run_raster", "halo_blocks", "array_kind", "require"]

_EXTRAS = {"dask": "dask", "xarray": "dask", "rasterio": "geo", "matplotlib": "plot", "tqdm": "progress"}


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


def _run_numpy(kernel, arr, *, n_out, **_):
    out = kernel(arr)
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


def _run_dask(kernel, arr, *, depth: int, step: int, n_out: int, dtype):
    # halo: what a window reaches, rounded up to the step so that every
    # chunk's first output pixel sits on the step grid of its padded block
    depth = -(-depth // step) * step
    padded, _ = halo_blocks(arr, depth, step)
    d0 = depth // step

    def block_fn(b):
        res = kernel(b)
        n0 = -(-(b.shape[0] - 2 * depth) // step)
        n1 = -(-(b.shape[1] - 2 * depth) // step)
        return res[:, d0:d0 + n0, d0:d0 + n1].astype(dtype, copy=False)

    out_chunks = ((n_out,),) + tuple(tuple(-(-(c - 2 * depth) // step) for c in cs) for cs in padded.chunks)
    return padded.map_blocks(block_fn, new_axis=0, chunks=out_chunks, dtype=dtype,
                             meta=np.empty((0, 0, 0), dtype))


_RUNNERS: Dict[str, Callable] = {"numpy": _run_numpy, "dask": _run_dask}


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
):
    """Run ``kernel`` on ``image`` of any array type; returns ``k`` outputs.

    Parameters
    ----------
    kernel : callable
        ``kernel(block) -> ndarray (n_out, ceil(r / step), ceil(c / step))``
        on a 2D block of the image (numpy, NaN = missing).
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

    Returns
    -------
    list of arrays of the input's type (or one 3D array with ``stack_dim``).
    """
    kind = array_kind(image)
    xr_obj = image if kind == "xarray" else None
    data = image.data if xr_obj is not None else image
    inner = "dask" if array_kind(data) == "dask" else "numpy"
    prep = prepare or (lambda b: b)
    stacked = _RUNNERS[inner](lambda b: kernel(prep(b)), data, depth=depth, step=step, n_out=n_out,
                              dtype=dtype)
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
