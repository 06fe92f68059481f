"""Files: OBJ and PLY meshes (written in Rust), SVG drawings and PNG previews.

Every writer is atomic: the file is written under a temporary name beside
the target and renamed over it, so it appears whole or not at all.
"""
from __future__ import annotations

import os
from typing import Union

import numpy as np

from fractalgeo_rs._validation import atomic_write_path, check_positive_float, check_positive_int
from fractalgeo_rs.lsystem.geometry import Polylines, Segments
from fractalgeo_rs.lsystem.mesh import Mesh, write_mesh

__all__ = ["write_obj", "write_ply", "write_svg", "write_png"]

PathLike = Union[str, os.PathLike]


def write_obj(mesh: Mesh, path: PathLike) -> None:
    """Write a mesh as Wavefront OBJ (text).

    Vertices ``v``, texture coordinates ``vt``, normals ``vn`` and faces
    ``f v/vt/vn`` (1-based), branches and leaves in groups ``branches`` and
    ``leaves`` (other kinds in ``kind<k>``). The file is written atomically
    (under a temporary name, then renamed), with the JSON sidecar of
    :meth:`fractalgeo_rs.geometry.Mesh.write` (``name.json``: the offset
    ``mesh.origin``, the CRS) and the offset in a ``# offset X Y Z`` line.

    Parameters
    ----------
    mesh : Mesh
        E.g. from :func:`~fractalgeo_rs.lsystem.plant_mesh`.
    path : str or os.PathLike
        Output file.

    Returns
    -------
    None

    References
    ----------
    Wavefront Technologies, *Object Files (.obj)*, Appendix B1 of the
    Advanced Visualizer manual; mirrored at
    https://paulbourke.net/dataformats/obj/.

    Examples
    --------
    >>> import os, pathlib, tempfile
    >>> from fractalgeo_rs.lsystem import plant_mesh, write_obj
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_obj(plant_mesh("F", sides=3), os.path.join(d, "stem.obj"))
    ...     lines = pathlib.Path(d, "stem.obj").read_text().splitlines()
    >>> [sum(ln.startswith(k + " ") for ln in lines) for k in ("v", "vt", "vn", "f")]
    [8, 8, 8, 6]
    >>> [ln for ln in lines if ln.startswith(("g ", "f "))][:3]
    ['g branches', 'f 1/1/1 2/2/2 6/6/6', 'f 1/1/1 6/6/6 5/5/5']
    """
    write_mesh(mesh, path, "obj")


def write_ply(mesh: Mesh, path: PathLike) -> None:
    """Write a mesh as binary little-endian PLY.

    Vertex properties ``x y z nx ny nz s t`` (float32); face properties
    ``vertex_indices`` (uchar count, uint32 indices), ``part_id``, ``kind``
    (uchar), ``color`` and ``instance`` (uint32): 32 bytes per vertex and
    26 per triangle after the text header. The file is written atomically,
    with the JSON sidecar of :meth:`fractalgeo_rs.geometry.Mesh.write`
    (``name.json``) and the offset in a ``comment offset X Y Z`` line.

    Parameters
    ----------
    mesh : Mesh
        E.g. from :func:`~fractalgeo_rs.lsystem.plant_mesh`.
    path : str or os.PathLike
        Output file.

    Returns
    -------
    None

    References
    ----------
    G. Turk, *The PLY polygon file format*, Stanford University, 1994;
    https://paulbourke.net/dataformats/ply/.

    Examples
    --------
    >>> import os, pathlib, tempfile
    >>> from fractalgeo_rs.lsystem import plant_mesh, write_ply
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_ply(plant_mesh("F", sides=3), os.path.join(d, "stem.ply"))
    ...     data = pathlib.Path(d, "stem.ply").read_bytes()
    >>> header, body = data.split(b"end_header" + bytes([10]))  # the header ends with a newline
    >>> header.splitlines()[:2], len(body) == 8 * 32 + 6 * 26
    ([b'ply', b'format binary_little_endian 1.0'], True)
    """
    write_mesh(mesh, path, "ply")


def write_svg(drawing: Polylines, path: PathLike, *, size: float = 800.0, stroke_width: float = 1.0,
              margin: float = 10.0, stroke: str = "#1b5e20", fill: str = "#66bb6a") -> None:
    """Write a 2D turtle drawing as SVG (y up, scaled to fit ``size`` pixels).

    Polylines become ``<polyline>`` elements, leaf polygons ``<polygon>``.
    The longer side of the drawing spans ``size - 2 margin`` pixels. The
    file is written atomically.

    Parameters
    ----------
    drawing : Polylines
        From :func:`~fractalgeo_rs.lsystem.turtle_2d`.
    path : str or os.PathLike
        Output file.
    size : float, default 800.0
        Width or height of the picture (the larger of the two), pixels.
    stroke_width : float, default 1.0
        Line width, pixels.
    margin : float, default 10.0
        Empty border, pixels.
    stroke, fill : str
        SVG colours of the lines and of the leaf polygons.

    Returns
    -------
    None

    References
    ----------
    W3C (2011). *Scalable Vector Graphics (SVG) 1.1 (Second Edition)*, W3C
    Recommendation, https://www.w3.org/TR/SVG11/.

    Examples
    --------
    A unit square drawn in a 100-pixel picture with a 10-pixel margin (y
    points down in SVG):

    >>> import os, pathlib, tempfile
    >>> from fractalgeo_rs.lsystem import turtle_2d, write_svg
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_svg(turtle_2d("F+F+F+F"), os.path.join(d, "square.svg"), size=100)
    ...     svg = pathlib.Path(d, "square.svg").read_text()
    >>> svg.splitlines()[1].split('"')[1]
    '90.000,90.000 90.000,10.000 10.000,10.000 10.000,90.000 90.000,90.000'
    """
    if not isinstance(drawing, Polylines):
        raise TypeError(f"drawing: expected Polylines (from turtle_2d), got {type(drawing).__name__}")
    size = check_positive_float(size, "size")
    stroke_width = check_positive_float(stroke_width, "stroke_width")
    pts = [drawing.xy] + [np.asarray(p) for p in drawing.polygons]
    allp = np.concatenate([p for p in pts if len(p)]) if any(len(p) for p in pts) else np.zeros((1, 2))
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    span = float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-12))
    scale = (size - 2 * margin) / span
    w = (hi[0] - lo[0]) * scale + 2 * margin
    h = (hi[1] - lo[1]) * scale + 2 * margin

    def fmt(a: np.ndarray) -> str:
        x = (a[:, 0] - lo[0]) * scale + margin
        y = h - ((a[:, 1] - lo[1]) * scale + margin)
        return " ".join(f"{u:.3f},{v:.3f}" for u, v in zip(x, y))

    with atomic_write_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.1f}" height="{h:.1f}" '
                     f'viewBox="0 0 {w:.3f} {h:.3f}">\n')
            for poly in drawing.polygons:
                fh.write(f'<polygon points="{fmt(np.asarray(poly))}" fill="{fill}" stroke="none"/>\n')
            for line in drawing.lines:
                fh.write(f'<polyline points="{fmt(line)}" fill="none" stroke="{stroke}" '
                         f'stroke-width="{stroke_width}" stroke-linecap="round" stroke-linejoin="round"/>\n')
            fh.write("</svg>\n")


def write_png(geometry: Union[Polylines, Segments, Mesh], path: PathLike, *, size: int = 800,
              view: str = "side") -> None:
    """Write a PNG preview with matplotlib (imported only here).

    ``Polylines`` are drawn as lines; ``Segments`` and ``Mesh`` are projected
    orthographically: ``view="side"`` onto the x-z plane, ``"top"`` onto x-y.
    Segments are drawn with line widths proportional to their widths; a mesh
    as its triangles, leaves in green and branches in brown, on a white
    background. The file is written atomically.

    Parameters
    ----------
    geometry : Polylines, Segments or Mesh
        From :func:`~fractalgeo_rs.lsystem.turtle_2d`,
        :func:`~fractalgeo_rs.lsystem.turtle_3d` or
        :func:`~fractalgeo_rs.lsystem.plant_mesh`.
    path : str or os.PathLike
        Output file.
    size : int, default 800
        Side of the square picture, pixels.
    view : {"side", "top"}, default "side"
        Projection of 3D geometry.

    Returns
    -------
    None

    References
    ----------
    W3C (2003). *Portable Network Graphics (PNG) Specification (Second
    Edition)*, https://www.w3.org/TR/png/.
    J. D. Hunter, Matplotlib: a 2D graphics environment, *Computing in
    Science & Engineering* 9(3) (2007) 90-95, doi:10.1109/MCSE.2007.55.

    Examples
    --------
    >>> import os, tempfile
    >>> import matplotlib.image
    >>> from fractalgeo_rs.lsystem import turtle_3d, write_png
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_png(turtle_3d("F&F"), os.path.join(d, "preview.png"), size=64)
    ...     image = matplotlib.image.imread(os.path.join(d, "preview.png"))
    >>> image.shape
    (64, 64, 4)
    """
    size = check_positive_int(size, "size")
    if view not in ("side", "top"):
        raise ValueError(f"view: expected 'side' or 'top', got {view!r}")
    try:
        import matplotlib

        matplotlib.use("Agg", force=False)
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.collections import LineCollection, PolyCollection
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover
        raise ImportError("write_png needs matplotlib: pip install fractalgeo_rs[plot]") from exc
    ax2 = (0, 2) if view == "side" else (0, 1)
    fig = Figure(figsize=(size / 100, size / 100), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0, 0, 1, 1))
    ax.set_axis_off()
    ax.set_aspect("equal")
    if isinstance(geometry, Polylines):
        ax.add_collection(LineCollection(geometry.lines, colors="#1b5e20", linewidths=0.8))
        if geometry.polygons:
            ax.add_collection(PolyCollection(geometry.polygons, facecolors="#66bb6a"))
        pts = geometry.xy
    elif isinstance(geometry, Segments):
        segs = np.stack([geometry.starts[:, ax2], geometry.ends[:, ax2]], axis=1)
        wmax = float(geometry.widths.max()) if len(geometry.widths) else 1.0
        lw = 0.3 + 3.0 * geometry.widths / (wmax if wmax > 0 else 1.0)
        ax.add_collection(LineCollection(list(segs), colors="#5d4037", linewidths=lw))
        polys = [np.asarray(p)[:, ax2] for p in geometry.polygons]
        if polys:
            ax.add_collection(PolyCollection(polys, facecolors="#66bb6a"))
        pts = np.concatenate([geometry.starts[:, ax2], geometry.ends[:, ax2]] + polys) if len(segs) or polys else np.zeros((1, 2))
    elif isinstance(geometry, Mesh):
        tri = geometry.vertices[geometry.faces][:, :, ax2]
        colors = np.where(geometry.kinds[:, None] == 1, [[0.40, 0.73, 0.42, 1.0]], [[0.36, 0.25, 0.22, 1.0]])
        ax.add_collection(PolyCollection(tri, facecolors=colors, edgecolors="none"))
        pts = geometry.vertices[:, ax2] if len(geometry.vertices) else np.zeros((1, 2))
    else:
        raise TypeError(f"geometry: expected Polylines, Segments or Mesh, got {type(geometry).__name__}")
    if len(pts):
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.03 * float(max(hi[0] - lo[0], hi[1] - lo[1], 1e-9))
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
    with atomic_write_path(path) as tmp:
        fig.savefig(tmp, format="png", facecolor="white")
