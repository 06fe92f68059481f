"""The demo: box-counting dimensions of real data bundled with the package.

Run with ``fractalgeo demo --out DIR``. It prints the fits and writes
``DIR/fractalgeo_demo.png``.
"""
from __future__ import annotations

import argparse
import os
from typing import Dict

import numpy as np

from fractalgeo_rs.data import kilauea_land_mask, sentinel1_vv_db, srtm_alps, srtm_po_plain
from fractalgeo_rs.dimension import box_counting, differential_box_counting, self_affine_box_counting
from fractalgeo_rs.fit import DimensionFit
from fractalgeo_rs.transform import fractal_transform

#: window of the demo's local-dimension map (pixels, 10 m each)
MAP_WINDOW = 33


def coastline(land: np.ndarray) -> np.ndarray:
    """The coastline of a land mask as a 4-connected line of land pixels.

    Lakes and lowland patches inside the land are filled first, so only the
    sea shore remains; a land pixel is on the coast when one of its 8
    neighbours is sea (which makes the line 4-connected: diagonal steps of a
    1-pixel boundary would otherwise undercount at the smallest boxes).
    """
    from scipy import ndimage

    filled = ndimage.binary_fill_holes(land)
    sea = ndimage.binary_dilation(~filled, structure=np.ones((3, 3), bool))
    return filled & sea


#: Classes of the coastline panel, in colour order.
COAST_CLASSES = ("sea", "land", "coastline (box-counted)")


def coast_classes(land: np.ndarray) -> np.ndarray:
    """0 sea, 1 land, 2 the coastline pixels of :func:`coastline` (drawn 3
    pixels wide so that the line stays visible at figure size)."""
    from scipy import ndimage

    coast = ndimage.binary_dilation(coastline(land), structure=np.ones((3, 3), bool))
    return np.where(coast, 2, ndimage.binary_fill_holes(land).astype(np.int8)).astype(np.int8)


def draw_coast_panel(fig, ax, land: np.ndarray) -> None:
    """The southern part of the Kilauea land mask with its coastline and a
    colorbar naming the classes."""
    from matplotlib.colors import BoundaryNorm, ListedColormap

    cmap = ListedColormap(["#9ecae1", "#e7d9b0", "#000000"])
    im = ax.imshow(coast_classes(land)[540:, :], cmap=cmap, norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3),
                   interpolation="nearest")
    cb = fig.colorbar(im, ax=ax, shrink=0.8, ticks=[0, 1, 2])
    cb.ax.set_yticklabels(COAST_CLASSES)
    cb.set_label("class (30 m pixels)")
    ax.set_title("Kilauea coastline (30 m), southern part")


def contour(dem: np.ndarray, level: float) -> np.ndarray:
    """Pixels above ``level`` with a neighbour at or below it: the contour line."""
    return coastline(dem > level)


def compute() -> Dict[str, DimensionFit]:
    """The fits the demo prints, by name."""
    land, _ = kilauea_land_mask()
    alps, alps_info = srtm_alps()
    plain, _ = srtm_po_plain()
    vv, _ = sentinel1_vv_db()
    return {
        "Kilauea coastline (box counting)": box_counting(coastline(land)),
        "Alps 1200 m contour (box counting)": box_counting(contour(alps, 1200.0)),
        "Alps DEM (differential box counting)": differential_box_counting(alps),
        "Po plain DEM (differential box counting)": differential_box_counting(plain),
        "Alps DEM (self-affine boxes)": self_affine_box_counting(alps.astype(float)),
        "Sentinel-1 VV dB (differential box counting)": differential_box_counting(vv),
    }


def figure(fits: Dict[str, DimensionFit], dmap: np.ndarray):
    """The demo's figure: the coastline, DEM, SAR and local-dimension maps
    (each with a colorbar naming its unit) over the log-log fits, whose
    legends give each ``D`` with its 95 % interval ``ci95``."""
    import matplotlib.pyplot as plt

    land, _ = kilauea_land_mask()
    alps, _ = srtm_alps()
    vv, _ = sentinel1_vv_db()
    fig, axes = plt.subplots(2, 4, figsize=(17, 8))
    draw_coast_panel(fig, axes[0, 0], land)
    im_dem = axes[0, 1].imshow(alps, cmap="terrain")
    fig.colorbar(im_dem, ax=axes[0, 1], shrink=0.8, label="height (m)")
    axes[0, 1].contour(alps, levels=[1200.0], colors="k", linewidths=0.6)
    axes[0, 1].set_title("SRTM: Maritime Alps, 1200 m contour")
    im_vv = axes[0, 2].imshow(vv, cmap="gray", vmin=-25, vmax=5)
    fig.colorbar(im_vv, ax=axes[0, 2], shrink=0.8, label="VV backscatter (dB)")
    axes[0, 2].set_title("Sentinel-1 VV (dB)")
    im = axes[0, 3].imshow(dmap, cmap="magma", vmin=np.nanpercentile(dmap, 2), vmax=np.nanpercentile(dmap, 98))
    axes[0, 3].set_title(f"local P(m, L) dimension, {MAP_WINDOW}x{MAP_WINDOW} windows")
    fig.colorbar(im, ax=axes[0, 3], shrink=0.8, label="local dimension D (dimensionless)")
    for ax in axes[0]:
        ax.set_xticks([])
        ax.set_yticks([])
    axes[1, 3].hist(dmap[np.isfinite(dmap)].ravel(), bins=60, color="C4")
    axes[1, 3].set_xlabel("local dimension D")
    axes[1, 3].set_ylabel("pixels")
    names = list(fits)
    fits[names[0]].plot(ax=axes[1, 0], label="Kilauea coast")
    fits[names[1]].plot(ax=axes[1, 0], label="Alps 1200 m contour")
    fits[names[2]].plot(ax=axes[1, 1], label="Alps")
    fits[names[3]].plot(ax=axes[1, 1], label="Po plain")
    fits[names[5]].plot(ax=axes[1, 2], label="VV")
    fig.suptitle("fractalgeo_rs demo: fractal dimensions of real data (bundled samples)")
    fig.tight_layout()
    return fig


def run_demo(out: str = "demo-output") -> Dict[str, DimensionFit]:
    """Compute, print and draw the demo; returns the fits."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from fractalgeo_rs.plotting import save_figure

    fits = compute()
    vv, vv_info = sentinel1_vv_db()
    dmap = fractal_transform(vv, MAP_WINDOW, method="mass", z_scale=1.0)  # P(m, L), heights in dB
    for name, fit in fits.items():
        hurst = f"  H = {fit.extra['hurst']:.3f}" if "hurst" in fit.extra else ""
        lo, hi = fit.ci95
        print(f"{name:46s} D = {fit.dimension:.3f}  [{lo:.3f}, {hi:.3f}]  r2 = {fit.r_squared:.4f}{hurst}")

    fig = figure(fits, dmap)
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, "fractalgeo_demo.png")
    save_figure(fig, path)
    plt.close(fig)
    print(f"figure: {path}")
    os.makedirs(out, exist_ok=True)
    map_path = os.path.join(out, "s1_vv_local_dimension.tif")
    try:
        from fractalgeo_rs.io import write_raster

        write_raster(map_path, dmap, crs=vv_info["crs"], transform=vv_info["transform"], nodata=float("nan"))
    except OSError:  # no rasterio: keep the map as .npy
        map_path = os.path.join(out, "s1_vv_local_dimension.npy")
        from fractalgeo_rs.io import write_raster

        write_raster(map_path, dmap)
    print(
        f"local dimension map (P(m, L) in {MAP_WINDOW}x{MAP_WINDOW} windows, 1 dB per pixel) of the Sentinel-1 VV scene: "
        f"mean {np.nanmean(dmap):.3f}, 5-95 % range {np.nanpercentile(dmap, 5):.3f}-{np.nanpercentile(dmap, 95):.3f}"
    )
    print(f"map: {map_path}")
    return fits


def add_parsers(sub) -> None:
    """Register ``fractalgeo demo``."""
    from fractalgeo_rs._cli_common import HelpFormatter

    d = sub.add_parser("demo", formatter_class=HelpFormatter, help="run the demo on bundled real data and write a figure",
                       description="Box-counting dimensions of real data bundled with the package "
                                   "(SRTM DEM of the Alps, Kilauea coastline, Sentinel-1 backscatter); "
                                   "prints the fits and writes a PNG figure.")
    d.add_argument("--out", default="demo-output", help="output folder (default ./demo-output)")
    d.set_defaults(func=_run_demo)


def _run_demo(args: argparse.Namespace) -> int:
    run_demo(args.out)  # prints the fits and the paths it wrote (shown in the README)
    return 0
