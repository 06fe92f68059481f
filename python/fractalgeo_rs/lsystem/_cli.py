"""``fractalgeo lsystem``: derive an L-system from a rule file and write
its geometry.

Example::

    fractalgeo lsystem plant.txt -n 7 --out plant.obj --png plant.png

Turtle options not given on the command line come from the rule file's
directives (``n``, ``angle``, ``step``, ``width``, ``width_factor``,
``tropism``, ``elasticity``, ``sides``, ``draw``, ``move``, ``seed``);
``dimensions: 2`` makes a ``--png``-only run draw the 2D turtle.
"""
from __future__ import annotations

import argparse
import os


def add_parsers(sub) -> None:
    from fractalgeo_rs._cli_common import HelpFormatter, add_n_threads

    p = sub.add_parser(
        "lsystem", formatter_class=HelpFormatter,
        help="derive an L-system and write OBJ/PLY/SVG/PNG",
        description="Derive an L-system from a rule file (syntax: help(fractalgeo_rs.LSystem)) and write its geometry.",
    )
    p.add_argument("rules", help="rule file (axiom:, ignore:, key: value directives, A -> B productions)")
    p.add_argument("-n", type=int, default=None, help="derivation steps (default: the file's 'n', else 5)")
    p.add_argument("--out", help="output mesh (.obj or .ply) or 2D drawing (.svg)")
    p.add_argument("--png", help="PNG preview")
    p.add_argument("--seed", type=int, default=None, help="seed of stochastic rules")
    p.add_argument("--angle", type=float, default=None, help="turn angle in degrees")
    p.add_argument("--step", type=float, default=None, help="step length")
    p.add_argument("--width", type=float, default=None, help="initial segment width")
    p.add_argument("--sides", type=int, default=None, help="sides of branch tubes")
    p.add_argument("--view", choices=("side", "top"), default="side", help="projection of the 3D preview")
    add_n_threads(p)
    p.set_defaults(func=run)


def _opt(args_value, defaults, key, conv, fallback):
    if args_value is not None:
        return args_value
    if key in defaults:
        try:
            return conv(defaults[key])
        except ValueError:
            raise ValueError(f"rules: directive {key}: cannot read {defaults[key]!r}") from None
    return fallback


def _vec(text: str):
    vals = [float(v) for v in text.replace(",", " ").split()]
    if len(vals) != 3:
        raise ValueError(f"expected 3 numbers, got {text!r}")
    return tuple(vals)


def run(args: argparse.Namespace) -> int:
    from fractalgeo_rs.lsystem import LSystem, plant_mesh, turtle_2d, turtle_3d, write_obj, write_ply, write_png, write_svg

    if not args.out and not args.png:
        raise ValueError("give --out and/or --png")
    system = LSystem.from_file(args.rules, seed=args.seed)
    d = system.defaults
    n = _opt(args.n, d, "n", int, 5)
    turtle = dict(
        angle=_opt(args.angle, d, "angle", float, 90.0),
        step=_opt(args.step, d, "step", float, 1.0),
        draw=d.get("draw", "FG"),
        move=d.get("move", "fg"),
    )
    spatial = dict(
        width=_opt(args.width, d, "width", float, 1.0),
        width_factor=_opt(None, d, "width_factor", float, 0.7),
        tropism=_opt(None, d, "tropism", _vec, (0.0, 0.0, 0.0)),
        elasticity=_opt(None, d, "elasticity", float, 0.0),
    )
    sides = _opt(args.sides, d, "sides", int, 6)
    s = system.derive(n, n_threads=args.n_threads)
    ext = os.path.splitext(args.out)[1].lower() if args.out else ""
    if ext and ext not in (".obj", ".ply", ".svg"):
        raise ValueError(f"--out: expected a .obj, .ply or .svg file, got {args.out!r}")
    if ext == ".svg" or (args.png and not ext and d.get("dimensions", "3") == "2"):
        drawing = turtle_2d(s, **turtle)
        if ext == ".svg":
            write_svg(drawing, args.out)
        if args.png:
            write_png(drawing, args.png)
        print(f"{len(s)} modules, {drawing.n_segments} segments")
        return 0
    mesh = plant_mesh(s, sides=sides, **turtle, **spatial)
    if ext == ".obj":
        write_obj(mesh, args.out)
    elif ext == ".ply":
        write_ply(mesh, args.out)
    if args.png:
        write_png(turtle_3d(s, **turtle, **spatial), args.png, view=args.view)
    print(f"{len(s)} modules, {len(mesh.vertices)} vertices, {len(mesh.faces)} triangles")
    return 0
