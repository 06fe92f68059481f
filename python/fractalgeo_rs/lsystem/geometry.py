"""Turtle interpretation of L-strings in 2D and 3D and triangle meshes.

Conventions of Prusinkiewicz and Lindenmayer (1990), sections 1.2, 1.5, 2.3
and 5.1; see :func:`~fractalgeo_rs.lsystem.turtle_3d` for the symbol table.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from fractalgeo_rs import _core
from fractalgeo_rs._validation import check_n_threads
from fractalgeo_rs.lsystem.core import LString
from fractalgeo_rs.lsystem.mesh import Mesh

__all__ = ["Polylines", "Segments", "Mesh", "turtle_2d", "turtle_3d", "plant_mesh", "TURTLE_SYMBOLS"]

#: The symbols the turtle interprets (others are ignored).
TURTLE_SYMBOLS = "F G f g + - & ^ \\ / | $ [ ] ! ' { } ."

_PLANAR = ((0.0, 1.0, 0.0), (-1.0, 0.0, 0.0))
_SPATIAL = ((0.0, 0.0, 1.0), (-1.0, 0.0, 0.0))


def _as_lstring(lstring) -> LString:
    if isinstance(lstring, LString):
        return lstring
    if isinstance(lstring, str):
        return LString.parse(lstring)
    raise TypeError(f"lstring: expected an LString or a str, got {type(lstring).__name__}")


def _real(v, name):
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise TypeError(f"{name}: expected a number, got {v!r}")
    return float(v)


def _vec3(v, name):
    a = np.asarray(v, dtype=float)
    if a.shape != (3,):
        raise ValueError(f"{name}: expected 3 numbers, got shape {a.shape}")
    return tuple(float(x) for x in a)


def _symbols(v, name):
    if not isinstance(v, str):
        raise TypeError(f"{name}: expected a str of symbols, got {type(v).__name__}")
    return v


class TurtleArgs(NamedTuple):
    """Validated turtle options, read by name by the Rust binding
    (``TurtleArgs`` in ``rust/bindings/lsystem.rs``)."""

    angle: float
    step: float
    width: float
    width_factor: float
    tropism: Tuple[float, float, float]
    elasticity: float
    heading: Tuple[float, float, float]
    left: Tuple[float, float, float]
    draw: str
    moves: str


def turtle_args(*, angle=90.0, step=1.0, width=1.0, width_factor=0.7, tropism=(0.0, 0.0, 0.0), elasticity=0.0,
                draw="FG", move="fg", planar=False) -> TurtleArgs:
    """Validated turtle options, as the named structure ``_core`` reads."""
    h, l = _PLANAR if planar else _SPATIAL
    return TurtleArgs(
        angle=_real(angle, "angle"),
        step=_real(step, "step"),
        width=_real(width, "width"),
        width_factor=_real(width_factor, "width_factor"),
        tropism=_vec3(tropism, "tropism"),
        elasticity=_real(elasticity, "elasticity"),
        heading=h,
        left=l,
        draw=_symbols(draw, "draw"),
        moves=_symbols(move, "move"),
    )


def _split(points: np.ndarray, offsets: np.ndarray) -> list:
    return [points[offsets[k]:offsets[k + 1]] for k in range(len(offsets) - 1)]


@dataclass(frozen=True)
class Polylines:
    """A 2D turtle drawing: the result of :func:`~fractalgeo_rs.lsystem.turtle_2d`.

    Attributes
    ----------
    xy : ndarray of float64, shape (N, 2)
        Vertices of every polyline, one after the other, in turtle units
        (``step`` is one unit unless set otherwise).
    offsets : ndarray of uint64, shape (n_lines + 1,)
        Polyline ``k`` is ``xy[offsets[k]:offsets[k+1]]``.
    polygons : list of ndarray, each (m, 2)
        Filled polygons (leaves, ``{ . }``), vertices in order.
    lines : list of ndarray
        The polylines as a list of (n_k, 2) arrays.
    n_segments : int
        Number of drawn segments (vertices minus polylines).

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, section 1.2, doi:10.1007/978-1-4613-8476-2.

    Examples
    --------
    A branch ``[...]`` ends the current polyline; the turtle comes back to
    the branching point and starts a new one:

    >>> from fractalgeo_rs.lsystem import turtle_2d
    >>> d = turtle_2d("F[+F]F")
    >>> (d.xy.round(12) + 0.0).tolist()
    [[0.0, 0.0], [0.0, 1.0], [-1.0, 1.0], [0.0, 1.0], [0.0, 2.0]]
    >>> d.offsets.tolist(), d.n_segments, [len(line) for line in d.lines]
    ([0, 3, 5], 3, [3, 2])
    """

    xy: np.ndarray
    offsets: np.ndarray
    polygons: list

    @property
    def lines(self) -> list:
        """The polylines as a list of (n_k, 2) arrays."""
        return _split(self.xy, self.offsets)

    @property
    def n_segments(self) -> int:
        """Number of drawn segments (vertices minus polylines)."""
        return int(len(self.xy) - (len(self.offsets) - 1))


@dataclass(frozen=True)
class Segments:
    """The segments drawn by the 3D turtle: the result of
    :func:`~fractalgeo_rs.lsystem.turtle_3d`. ``len(segments)`` is the
    number of segments.

    Attributes
    ----------
    starts, ends : ndarray of float64, shape (N, 3)
        End points of each segment, in turtle units.
    widths : ndarray of float64, shape (N,)
        Diameter of each segment (set by ``!``), in turtle units.
    colors : ndarray of uint32, shape (N,)
        Colour index of each segment (set by ``'``).
    polygons : list of ndarray, each (m, 3)
        Leaf polygons (``{ . }``), vertices in order.

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, sections 1.5 and 2.3, doi:10.1007/978-1-4613-8476-2.

    Examples
    --------
    ``!`` multiplies the width by ``width_factor``, ``'`` adds 1 to the
    colour index:

    >>> from fractalgeo_rs.lsystem import turtle_3d
    >>> seg = turtle_3d("F!F'F", width=2.0, width_factor=0.5)
    >>> len(seg), seg.widths.tolist(), seg.colors.tolist()
    (3, [2.0, 1.0, 1.0], [0, 0, 1])
    >>> seg.ends.tolist()
    [[0.0, 0.0, 1.0], [0.0, 0.0, 2.0], [0.0, 0.0, 3.0]]
    """

    starts: np.ndarray
    ends: np.ndarray
    widths: np.ndarray
    colors: np.ndarray
    polygons: list

    def __len__(self) -> int:
        return len(self.starts)


def turtle_2d(lstring: Union[LString, str], *, angle: float = 90.0, step: float = 1.0, draw: str = "FG",
              move: str = "fg") -> Polylines:
    """Interpret an L-string with the turtle in the plane.

    The turtle starts at the origin heading +y; ``+`` turns left
    (counter-clockwise) by ``angle`` degrees, ``-`` right; see
    :func:`~fractalgeo_rs.lsystem.turtle_3d` for all symbols. Symbols in ``draw`` move forward and
    draw, those in ``move`` move without drawing (e.g. ``draw="FLR"`` for
    the ``F_l``/``F_r`` edge-rewriting curves of ABOP section 1.4).

    Parameters
    ----------
    lstring : LString or str
        The string to draw, e.g. from :meth:`fractalgeo_rs.LSystem.derive`
        (a str is parsed with :meth:`fractalgeo_rs.LString.parse`).
    angle : float, default 90.0
        Turning angle of ``+`` and ``-``, degrees (a module's parameter,
        ``+(30)``, overrides it).
    step : float, default 1.0
        Length of a step, in drawing units (``F(2)`` overrides it).
    draw, move : str, default "FG", "fg"
        Symbols that move forward with and without drawing.

    Returns
    -------
    Polylines
        Connected runs of segments; a polyline ends where the pen lifts
        (``f``, ``]``).

    References
    ----------
    Prusinkiewicz and Lindenmayer (1990), section 1.2; full entry in the
    :ref:`bibliography <ref-prusinkiewicz1990>`.

    Examples
    --------
    >>> from fractalgeo_rs.lsystem import turtle_2d
    >>> (turtle_2d("F+F+F+F").xy.round(12) + 0.0).tolist()
    [[0.0, 0.0], [0.0, 1.0], [-1.0, 1.0], [-1.0, 0.0], [0.0, 0.0]]
    """
    s = _as_lstring(lstring)
    args = turtle_args(angle=angle, step=step, draw=draw, move=move, planar=True)
    xy, off, pxy, poff = _core.turtle_polylines(s._core, args)
    return Polylines(xy, off, _split(pxy, poff))


def turtle_3d(lstring: Union[LString, str], *, angle: float = 90.0, step: float = 1.0, width: float = 1.0,
              width_factor: float = 0.7, tropism: Sequence[float] = (0.0, 0.0, 0.0), elasticity: float = 0.0,
              draw: str = "FG", move: str = "fg") -> Segments:
    r"""Interpret an L-string with the turtle in space.

    The state is a position and a frame heading ``H`` (initially +z), left
    ``L`` (-x) and up ``U = H x L``. A module's first parameter overrides the
    default step, angle, width or colour.

    ============  ========================================================
    ``F`` ``G``   move forward by ``step`` and draw a segment
    ``f`` ``g``   move forward without drawing
    ``+`` ``-``   turn left / right by ``angle`` (about ``U``)
    ``&`` ``^``   pitch down / up (about ``L``)
    ``\`` ``/``   roll left / right (about ``H``)
    ``|``         turn around
    ``$``         roll so that ``L`` is horizontal
    ``[`` ``]``   push / pop the turtle state (branches)
    ``!``         set the width to the parameter, else multiply by ``width_factor``
    ``'``         set the colour index to the parameter, else add 1
    ``{`` ``}``   begin / end a polygon (leaf); ``.`` records a vertex
    ============  ========================================================

    Tropism (ABOP section 2.3.2): after each drawn step the frame turns about
    ``H x T`` by ``elasticity * |H x T|``.

    Parameters
    ----------
    lstring : LString or str
        The string to draw, e.g. from :meth:`fractalgeo_rs.LSystem.derive`
        (a str is parsed with :meth:`fractalgeo_rs.LString.parse`).
    angle : float, default 90.0
        Angle of the turns, pitches and rolls, degrees.
    step : float, default 1.0
        Length of a step, in drawing units.
    width : float, default 1.0
        Initial segment diameter, in drawing units.
    width_factor : float, default 0.7
        Factor applied to the width by ``!`` without a parameter.
    tropism : sequence of 3 float, default (0, 0, 0)
        Tropism vector ``T`` (e.g. ``(0, 0, -1)`` for gravity).
    elasticity : float, default 0.0
        Susceptibility to tropism (radians per unit of ``|H x T|``).
    draw, move : str, default "FG", "fg"
        Symbols that move forward with and without drawing.

    Returns
    -------
    Segments
        One segment per drawing step, with its width and colour index, and
        the leaf polygons.

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, sections 1.5 (turtle in three dimensions), 2.3.2
    (tropism) and 5.1 (polygons).

    Examples
    --------
    >>> from fractalgeo_rs.lsystem import turtle_3d
    >>> seg = turtle_3d("F&F", angle=90)
    >>> seg.ends.round(12).tolist()
    [[0.0, 0.0, 1.0], [0.0, 1.0, 1.0]]
    """
    s = _as_lstring(lstring)
    args = turtle_args(angle=angle, step=step, width=width, width_factor=width_factor, tropism=tropism,
                       elasticity=elasticity, draw=draw, move=move)
    st, en, w, c, pxyz, poff = _core.turtle_segments(s._core, args)
    return Segments(st, en, w, c, _split(pxyz, poff))


def plant_mesh(lstring: Union[LString, str], *, sides: int = 6, angle: float = 90.0, step: float = 1.0,
               width: float = 1.0, width_factor: float = 0.7, tropism: Sequence[float] = (0.0, 0.0, 0.0),
               elasticity: float = 0.0, draw: str = "FG", move: str = "fg",
               n_threads: Optional[int] = None) -> Mesh:
    """Triangle mesh of an L-string: generalised cylinders and leaves.

    Each chain of segments drawn without lifting the pen becomes one tube
    with ``sides`` sides whose rings are shared between consecutive segments
    (a ring of ``sides + 1`` vertices, the last repeating the first for the
    texture seam); a branch ``[`` starts a new tube. Leaves (``{ . }``) are
    fan-triangulated with their Newell normal. Turtle options as in
    :func:`~fractalgeo_rs.lsystem.turtle_3d`; the triangles are written by ``n_threads`` threads
    (all cores when None), with the same result for any number.

    Parameters
    ----------
    lstring : LString or str
        The string to draw, e.g. from :meth:`fractalgeo_rs.LSystem.derive`
        (a str is parsed with :meth:`fractalgeo_rs.LString.parse`).
    sides : int, default 6
        Sides of each branch tube, 3 to 64.
    angle, step, width, width_factor, tropism, elasticity, draw, move
        Turtle options, as in :func:`~fractalgeo_rs.lsystem.turtle_3d`.
    n_threads : int, optional
        Threads writing the triangles (all cores when None).

    Returns
    -------
    Mesh
        Vertices, normals and texture coordinates (float32), triangles
        (uint32) and per-triangle part, kind, colour and instance ids.

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, section 5.1; J. Bloomenthal, Modeling the mighty maple,
    *SIGGRAPH* 1985.

    Examples
    --------
    >>> from fractalgeo_rs.lsystem import plant_mesh
    >>> m = plant_mesh("FF", sides=6)
    >>> m.vertices.shape, m.faces.shape
    ((21, 3), (24, 3))
    """
    s = _as_lstring(lstring)
    if isinstance(sides, bool) or not isinstance(sides, numbers.Integral):
        raise TypeError(f"sides: expected an int, got {sides!r}")
    args = turtle_args(angle=angle, step=step, width=width, width_factor=width_factor, tropism=tropism,
                       elasticity=elasticity, draw=draw, move=move)
    return Mesh._from_core(_core.turtle_mesh(s._core, args, int(sides), check_n_threads(n_threads)))
