"""The ``fractalgeo`` command line.

Each domain adds its subcommands from its own ``_cli`` module, listed in
``_DOMAIN_CLIS``: the module has ``add_parsers(subparsers)`` which registers
subparsers whose ``func`` attribute takes the parsed ``args`` and returns an
exit code. ``_COMMANDS`` names the module and the one-line help of each
subcommand, so that a run imports only the module of its subcommand (and
``fractalgeo --help`` none): a new subcommand gets a row there too (without
one it still works, through the full parser).

Exit codes: 0 success; 1 a user error (bad argument value, unreadable or
unwritable file, a request above the memory limit, a missing optional
dependency), reported as one line on stderr (``--debug`` shows the
traceback); 2 a command-line usage error (argparse); 130 interrupted.
"""
from __future__ import annotations

import argparse
import importlib
import sys
import warnings
from typing import Optional, Sequence

_DOMAIN_CLIS = (
    "fractalgeo_rs.canopy._cli",
    "fractalgeo_rs.dem._cli",
    "fractalgeo_rs.dimension._cli",
    "fractalgeo_rs.demo",
    "fractalgeo_rs.lsystem._cli",
    "fractalgeo_rs.radar._cli",
    "fractalgeo_rs.radiometry._cli",
    "fractalgeo_rs.synth._cli",
    "fractalgeo_rs.transform._cli",
    "fractalgeo_rs.tin._cli",
)

#: subcommand -> (its ``_cli`` module, its one-line help as the module registers it)
_COMMANDS = {
    "resample": ("fractalgeo_rs.dem._cli", "resample a DEM on a finer grid with fractal detail"),
    "hillshade": ("fractalgeo_rs.dem._cli", "shaded relief of a DEM as an 8-bit PNG"),
    "dimension": ("fractalgeo_rs.dimension._cli", "estimate the fractal dimension of a raster file"),
    "demo": ("fractalgeo_rs.demo", "run the demo on bundled real data and write a figure"),
    "lsystem": ("fractalgeo_rs.lsystem._cli", "derive an L-system and write OBJ/PLY/SVG/PNG"),
    "synth": ("fractalgeo_rs.synth._cli",
              "synthesise fBm (1D), a fractal surface or a synthetic DEM in metres (2D)"),
    "transform": ("fractalgeo_rs.transform._cli",
                  "map of local fractal dimension (moving window) as a float32 GeoTIFF"),
    "tin": ("fractalgeo_rs.tin._cli", "error-bounded triangulated mesh (TIN) of a DEM as PLY or OBJ"),
    "sar": ("fractalgeo_rs.radar._cli", "synthetic SAR intensity image of a DEM (layover, shadow, speckle)"),
    "render": ("fractalgeo_rs.radiometry._cli",
               "radiance image of a DEM lit by the sun (virtual radiometric experiment)"),
    "brf": ("fractalgeo_rs.radiometry._cli",
            "BRF of a DEM over sun zenith angles (virtual radiometric experiment), as CSV"),
    "canopy": ("fractalgeo_rs.canopy._cli",
               "RAMI-like canopy of disc leaves over a soil, as a mesh, with its gap-fraction table"),
}


class _Version(argparse.Action):
    """``--version``: the version read from the extension when asked."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings=option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        from fractalgeo_rs._core import __version__

        print(f"fractalgeo_rs {__version__}")
        parser.exit()


def build_parser(command: Optional[str] = None) -> argparse.ArgumentParser:
    """The parser of every subcommand; with ``command`` (a key of
    ``_COMMANDS``) only that subcommand's module is imported, the others
    are listed by name and help."""
    parser = argparse.ArgumentParser(
        prog="fractalgeo",
        description="Fractal geometry for geo-information processing (fractalgeo_rs).",
    )
    parser.add_argument("--version", action=_Version, help="show the version and exit")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback of an error instead of one line")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    if command is not None and command in _COMMANDS or command == "":
        module = _COMMANDS[command][0] if command else None
        for name, (mod, text) in _COMMANDS.items():
            if mod == module:
                if name == command:
                    importlib.import_module(mod).add_parsers(sub)
            else:
                sub.add_parser(name, help=text)
        return parser
    for name in _DOMAIN_CLIS:
        importlib.import_module(name).add_parsers(sub)
    return parser


def _command_of(argv: Sequence[str]) -> Optional[str]:
    """The subcommand named in ``argv`` (its first non-option word), ``""``
    for none (top-level help or version), None when it is not in ``_COMMANDS``."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in _COMMANDS else None
    return ""


def _subparser(parser: argparse.ArgumentParser, command: str) -> Optional[argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return action.choices.get(command)
    return None


#: API parameters whose CLI option has another name: {API name: option dest}
_API_NAMES = {"window_size": "window"}


def option_names(sub: Optional[argparse.ArgumentParser]) -> dict:
    """``{dest: "--option"}`` of a subcommand's options (the long spelling),
    and the API names of :data:`_API_NAMES` spelled as their options."""
    names: dict = {}
    for action in (sub._actions if sub is not None else ()):
        longs = [o for o in action.option_strings if o.startswith("--")]
        if longs and action.dest not in names:
            names[action.dest] = longs[0]
    for api, dest in _API_NAMES.items():
        if dest in names and api not in names:
            names[api] = names[dest]
    return names


def cli_message(text: str, names: dict) -> str:
    """An API error message in the CLI's words: a leading ``param:`` and
    ``param=value`` spelled as the option (``--param:``, ``--param value``)."""
    import re

    head = re.match(r"([A-Za-z_][A-Za-z0-9_]*)(:)", text)
    if head and head.group(1) in names:
        text = names[head.group(1)] + text[head.end(1):]

    def sub(m):
        return f"{names[m.group(1)]} {m.group(2)}" if m.group(1) in names else m.group(0)

    text = re.sub(r"(?<![\w-])([a-z_][a-z0-9_]*)=('[^']*'|[^\s,;)]+)", sub, text)
    if "max_memory" in names:
        return re.sub(r"(?<![\w-])max_memory(?![\w])=?", "--max-memory", text)
    # a subcommand without --max-memory: the limit is the environment variable's
    text = re.sub(r"(?<![\w-])max_memory= or (\$\w+)", r"\1 (bytes)", text)
    return re.sub(r"(?<![\w-])max_memory(?![\w])", "memory limit", text)


def main(argv: Optional[Sequence[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(_command_of(argv))
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _one_line_warning(args.command)
            return int(args.func(args) or 0)
    except KeyboardInterrupt:
        if args.debug:
            raise
        print(f"fractalgeo {args.command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of stdout went away (e.g. | head): stop quietly, as Unix tools do
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # no second error when Python flushes stdout at exit
        return 0
    except ModuleNotFoundError as exc:
        if args.debug:
            raise
        print(f"fractalgeo {args.command}: error: {missing_dependency_message(exc)}", file=sys.stderr)
        return 1
    except (ValueError, TypeError, OSError, MemoryError) as exc:
        if args.debug:
            raise
        text = cli_message(str(exc), option_names(_subparser(parser, args.command)))
        print(f"fractalgeo {args.command}: error: {text}", file=sys.stderr)
        return 1


def _one_line_warning(command):
    """A ``warnings.showwarning`` printing ``fractalgeo CMD: warning: ...``
    on one line of stderr (no file name, line number or source line: they
    would point into the package)."""

    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        if command in ("render", "brf"):  # the CLI's spelling of a finite patch
            text = text.replace("pass periodic=False", "pass --finite")
        print(f"fractalgeo {command}: warning: {text}", file=sys.stderr if file is None else file)

    return show


#: Optional dependencies and the extra that installs them.
_EXTRAS = {"dask": "dask", "distributed": "dask", "xarray": "dask", "rasterio": "geo",
           "matplotlib": "plot"}


def missing_dependency_message(exc: ModuleNotFoundError) -> str:
    """One line naming the missing module and the extra that installs it."""
    name = (exc.name or "").split(".")[0]
    extra = _EXTRAS.get(name)
    if extra is None:
        return f"missing module {name or exc}: {exc}"
    return f"this needs {name}, which is not installed: pip install \"fractalgeo_rs[{extra}]\""


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
