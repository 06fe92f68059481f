"""The demo: box-counting dimensions of real data bundled with the package.

Run with ``fractalgeo demo --out DIR``. It prints the fits and writes
``DIR/fractalgeo_demo.png``.
"""
from __future__ import annotations

import argparse
import os
from typing import TYPE_CHECKING, Dict, List

if TYPE_CHECKING:  # imported when the demo runs (the CLI lists it without importing numpy)
    import numpy as np

    from fractalgeo_rs.fit import DimensionFit

#: window of the demo's local-dimension map (pixels of the Sentinel-1 scene, 10 m each)
MAP_WINDOW = 33
#: height of the contour line box-counted on the SRTM Alps crop (metres)
CONTOUR_LEVEL = 1200.0
#: a fit on fewer scales than this, or with a 95 % interval wider than
#: ``MAX_CI_WIDTH``, is flagged as not a trustworthy headline
MIN_SCALES = 5
MAX_CI_WIDTH = 0.2
#: box sizes of the contour fit (pixels): the contour of a 256 x 256 crop
#: spans 1 to 64 pixels with every factor of sqrt(2) measured (the dyadic
#: default leaves 3 sizes after its sampling check, an interval 1 wide)
CONTOUR_BOX_SIZES = (1, 2, 3, 4, 6, 8, 11, 16, 23, 32, 45, 64)
#: box sizes of the DBC fits (pixels): every factor of sqrt(2) from 2 to 64
DBC_BOX_SIZES = CONTOUR_BOX_SIZES[1:]


def coastline(land: np.ndarray) -> np.ndarray:
    """The coastline of a land mask as a 4-connected line of land pixels.

    Lakes and lowland patches inside the land are filled first, so only the
    sea shore remains; a land pixel is on the coast when one of its 8
    neighbours is sea (which makes the line 4-connected: diagonal steps of a
    1-pixel boundary would otherwise undercount at the smallest boxes).
    """
    import numpy as np
    from scipy import ndimage

    filled = ndimage.binary_fill_holes(land)
    sea = ndimage.binary_dilation(~filled, structure=np.ones((3, 3), bool))
    return filled & sea


#: Classes of the coastline panel, in colour order.
COAST_CLASSES = ("sea", "land", "coastline (box-counted)")


def coast_classes(land: np.ndarray) -> np.ndarray:
    """0 sea, 1 land, 2 the coastline pixels of :func:`coastline` (drawn 3
    pixels wide so that the line stays visible at figure size)."""
    import numpy as np
    from scipy import ndimage

    coast = ndimage.binary_dilation(coastline(land), structure=np.ones((3, 3), bool))
    return np.where(coast, 2, ndimage.binary_fill_holes(land).astype(np.int8)).astype(np.int8)


def draw_coast_panel(fig, ax, land: "np.ndarray") -> None:
    """The southern part of the Kilauea land mask with its coastline and a
    colorbar naming the classes."""
    from matplotlib.colors import BoundaryNorm, ListedColormap

    cmap = ListedColormap(["#9ecae1", "#e7d9b0", "#000000"])
    im = ax.imshow(coast_classes(land)[540:, :], cmap=cmap, norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3),
                   interpolation="nearest")
    cb = fig.colorbar(im, ax=ax, orientation="horizontal", location="bottom", shrink=0.9, ticks=[0, 1, 2])
    cb.ax.set_xticklabels(COAST_CLASSES, fontsize="small")
    cb.set_label("class (sea, land, coast)")
    ax.set_title("Kilauea land mask (30 m pixels),\nsouthern part", fontsize="medium")


def contour(dem: "np.ndarray", level: float) -> "np.ndarray":
    """Pixels above ``level`` with a neighbour at or below it: the contour line."""
    return coastline(dem > level)


#: the fits of the demo: label -> (short legend label, what is measured)
NAMES = {
    "coast": "Kilauea coastline (box counting)",
    "contour": f"Alps {CONTOUR_LEVEL:.0f} m contour (box counting)",
    "alps_dbc": "Alps DEM (differential box counting)",
    "po_dbc": "Po plain DEM (differential box counting)",
    "alps_affine": "Alps DEM (self-affine boxes)",
    "vv_dbc": "Sentinel-1 VV dB (differential box counting)",
}


def compute() -> Dict[str, "DimensionFit"]:
    """The fits the demo prints, by name."""
    from fractalgeo_rs.data import kilauea_land_mask, sentinel1_vv_db, srtm_alps, srtm_po_plain
    from fractalgeo_rs.dimension import box_counting, differential_box_counting, self_affine_box_counting

    land, _ = kilauea_land_mask()
    alps, _ = srtm_alps()
    plain, _ = srtm_po_plain()
    vv, _ = sentinel1_vv_db()
    return {
        NAMES["coast"]: box_counting(coastline(land)),
        NAMES["contour"]: box_counting(contour(alps, CONTOUR_LEVEL), box_sizes=list(CONTOUR_BOX_SIZES)),
        NAMES["alps_dbc"]: differential_box_counting(alps, box_sizes=list(DBC_BOX_SIZES)),
        NAMES["po_dbc"]: differential_box_counting(plain, box_sizes=list(DBC_BOX_SIZES)),
        NAMES["alps_affine"]: self_affine_box_counting(alps.astype(float)),
        NAMES["vv_dbc"]: differential_box_counting(vv, box_sizes=list(DBC_BOX_SIZES)),
    }


def local_map() -> "np.ndarray":
    """The local-dimension map of the Sentinel-1 VV scene: Voss's P(m, L) in
    ``MAP_WINDOW`` windows, heights in dB (1 dB per box step)."""
    from fractalgeo_rs.data import sentinel1_vv_db
    from fractalgeo_rs.transform import fractal_transform

    vv, _ = sentinel1_vv_db()
    return fractal_transform(vv, MAP_WINDOW, method="mass", z_scale=1.0)


def caveats(fit: "DimensionFit") -> List[str]:
    """Why a headline ``D`` should not be trusted as it stands: fewer than
    ``MIN_SCALES`` fitted scales, a 95 % interval wider than
    ``MAX_CI_WIDTH``, or two scaling regimes (``D`` then depends on the
    scales fitted; the regimes are printed and drawn dashed)."""
    import math

    lo, hi = fit.ci95
    out = []
    if fit.n_used < MIN_SCALES:
        out.append("few scales")
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi - lo > MAX_CI_WIDTH:
        out.append("wide interval")
    if len(fit.ranges) > 1:
        out.append("two regimes")
    return out


def fit_label(fit: "DimensionFit") -> str:
    """The legend text of a fit: the printed dimension and interval, the
    number of scales, and its caveats."""
    flag = "".join(f" - {c}" for c in caveats(fit))
    return f"{fit.interval_label()}, {fit.n_used} scales{flag}"


def map_summary(dmap: "np.ndarray") -> Dict[str, float]:
    import numpy as np

    return {"mean": float(np.nanmean(dmap)), "p5": float(np.nanpercentile(dmap, 5)),
            "p95": float(np.nanpercentile(dmap, 95))}


def report(fits: Dict[str, "DimensionFit"], dmap: "np.ndarray") -> List[str]:
    """The lines the demo prints (every number the figure draws is one of
    them, as written)."""
    lines = ["data: Kilauea land mask (30 m pixels), SRTM 3 arc-second DEM (about 92 x 66 m cells), "
             "Sentinel-1 VV sigma0 in dB (10 m pixels); D with its 95 % interval, flagged with fewer than "
             f"{MIN_SCALES} scales, an interval wider than {MAX_CI_WIDTH} or two scaling regimes"]
    for name, fit in fits.items():
        hurst = f"  H = {fit.extra['hurst']:.3f}" if "hurst" in fit.extra else ""
        lo, hi = fit.ci95
        flag = "".join(f"  {c}" for c in caveats(fit))
        lines.append(f"{name:46s} D = {fit.dimension:.3f}  [{lo:.3f}, {hi:.3f}]  r2 = {fit.r_squared:.4f}  "
                     f"{fit.n_used} scales {fit.scale_range[0]:g}-{fit.scale_range[1]:g}{hurst}{flag}")
        if len(fit.ranges) > 1:  # two regimes (drawn dashed): as the legend writes them
            lines.append(" " * 47 + "two regimes, D depends on the scales fitted: " + "; ".join(
                f"range {r.scale_range[0]:.4g}..{r.scale_range[1]:.4g}: D = {r.dimension:.3f}"
                + ("" if r.valid else " (invalid)") for r in fit.ranges))
    m = map_summary(dmap)
    lines.append(f"local dimension map (P(m, L) in {MAP_WINDOW}x{MAP_WINDOW} windows, 1 dB per pixel) of the "
                 f"Sentinel-1 VV scene: mean {m['mean']:.3f}, 5-95 % range {m['p5']:.3f}-{m['p95']:.3f}")
    return lines


def figure(fits: Dict[str, "DimensionFit"], dmap: "np.ndarray"):
    """The demo's figure: the coastline, DEM, SAR and local-dimension maps
    (each with a colorbar naming its unit) over the log-log fits, whose
    legends give each ``D`` with its 95 % interval ``ci95``, the number of
    scales and a flag on untrustworthy fits."""
    import matplotlib.pyplot as plt
    import numpy as np

    from fractalgeo_rs.data import kilauea_land_mask, sentinel1_vv_db, srtm_alps

    land, _ = kilauea_land_mask()
    alps, _ = srtm_alps()
    vv, _ = sentinel1_vv_db()
    fig, axes = plt.subplots(2, 4, figsize=(19, 9.5), layout="constrained")
    draw_coast_panel(fig, axes[0, 0], land)
    im_dem = axes[0, 1].imshow(alps, cmap="terrain")
    fig.colorbar(im_dem, ax=axes[0, 1], shrink=0.8, label="height (m)")
    axes[0, 1].contour(alps, levels=[CONTOUR_LEVEL], colors="k", linewidths=0.6)
    axes[0, 1].set_title(f"SRTM 3 arc-second DEM, Maritime Alps,\n{CONTOUR_LEVEL:.0f} m contour", fontsize="medium")
    im_vv = axes[0, 2].imshow(vv, cmap="gray", vmin=-25, vmax=5)
    fig.colorbar(im_vv, ax=axes[0, 2], shrink=0.8, label="VV backscatter sigma0 (dB)")
    axes[0, 2].set_title("Sentinel-1 VV (10 m pixels)", fontsize="medium")
    m = map_summary(dmap)
    im = axes[0, 3].imshow(dmap, cmap="magma", vmin=np.nanpercentile(dmap, 2), vmax=np.nanpercentile(dmap, 98))
    axes[0, 3].set_title(f"local P(m, L) dimension of VV,\n{MAP_WINDOW}x{MAP_WINDOW} windows", fontsize="medium")
    fig.colorbar(im, ax=axes[0, 3], shrink=0.8, label="local dimension D (dimensionless)")
    for ax in axes[0]:
        ax.set_xticks([])
        ax.set_yticks([])
    axes[1, 3].hist(dmap[np.isfinite(dmap)].ravel(), bins=60, color="C4")
    axes[1, 3].axvline(m["mean"], color="k", lw=1, label=f"mean {m['mean']:.3f}")
    axes[1, 3].axvspan(m["p5"], m["p95"], color="0.8", zorder=0,
                       label=f"5-95 % range {m['p5']:.3f}-{m['p95']:.3f}")
    axes[1, 3].set_xlabel("local dimension D (dimensionless)")
    axes[1, 3].set_ylabel("pixels")
    axes[1, 3].legend(fontsize="small")
    axes[1, 3].set_title("local dimensions of VV", fontsize="medium")
    panels = [(axes[1, 0], "coast", "Kilauea coast"), (axes[1, 0], "contour", f"Alps {CONTOUR_LEVEL:.0f} m contour"),
              (axes[1, 1], "alps_dbc", "Alps"), (axes[1, 1], "po_dbc", "Po plain"), (axes[1, 2], "vv_dbc", "VV")]
    for ax, key, label in panels:
        fit = fits[NAMES[key]]
        fit.plot(ax=ax, label=label)
        line = [ln for ln in ax.lines if ln.get_label() == fit.interval_label()]
        for ln in line:
            ln.set_label(fit_label(fit))
        ax.legend(fontsize="x-small", loc="lower left")
    axes[1, 0].set_title("box counting: coastline and contour", fontsize="medium")
    axes[1, 1].set_title("differential box counting: DEMs", fontsize="medium")
    axes[1, 2].set_title("differential box counting: VV (dB)", fontsize="medium")
    fig.suptitle("fractalgeo_rs demo: fractal dimensions of real data (bundled samples)")
    return fig


def run_demo(out: str = "demo-output") -> Dict[str, "DimensionFit"]:
    """Compute, print and draw the demo; returns the fits."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from fractalgeo_rs.data import sentinel1_vv_db
    from fractalgeo_rs.io import write_raster
    from fractalgeo_rs.plotting import save_figure

    fits = compute()
    dmap = local_map()
    lines = report(fits, dmap)
    print("\n".join(lines[:-1]))
    fig = figure(fits, dmap)
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, "fractalgeo_demo.png")
    save_figure(fig, path)
    plt.close(fig)
    print(f"figure: {path}")
    _, vv_info = sentinel1_vv_db()
    map_path = os.path.join(out, "s1_vv_local_dimension.tif")
    try:
        write_raster(map_path, dmap, crs=vv_info["crs"], transform=vv_info["transform"], nodata=float("nan"))
    except OSError:  # no rasterio: keep the map as .npy
        map_path = os.path.join(out, "s1_vv_local_dimension.npy")
        write_raster(map_path, np.asarray(dmap))
    print(lines[-1])
    print(f"map: {map_path}")
    return fits


def add_parsers(sub) -> None:
    """Register ``fractalgeo demo``."""
    from fractalgeo_rs._cli_common import HelpFormatter

    d = sub.add_parser("demo", formatter_class=HelpFormatter, help="run the demo on bundled real data and write a figure",
                       description="Box-counting dimensions of real data bundled with the package "
                                   "(SRTM DEM of the Alps, Kilauea coastline, Sentinel-1 backscatter); "
                                   "prints the fits and writes a PNG figure.")
    d.add_argument("--out", default="demo-output", help="output folder")
    d.set_defaults(func=_run_demo)


def _run_demo(args: argparse.Namespace) -> int:
    run_demo(args.out)  # prints the fits and the paths it wrote (shown in the README)
    return 0
