"""The ``fractalgeo`` command line.

Each domain adds its subcommands from its own ``_cli`` module, listed in
``_DOMAIN_CLIS``: the module has ``add_parsers(subparsers)`` which registers
subparsers whose ``func`` attribute takes the parsed ``args`` and returns an
exit code.

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
    "fractalgeo_rs.dem._cli",
    "fractalgeo_rs.dimension._cli",
    "fractalgeo_rs.demo",
    "fractalgeo_rs.lsystem._cli",
    "fractalgeo_rs.radar._cli",
    "fractalgeo_rs.synth._cli",
    "fractalgeo_rs.transform._cli",
    "fractalgeo_rs.tin._cli",
)


def build_parser() -> argparse.ArgumentParser:
    from fractalgeo_rs import __version__

    parser = argparse.ArgumentParser(
        prog="fractalgeo",
        description="Fractal geometry for geo-information processing (fractalgeo_rs).",
    )
    parser.add_argument("--version", action="version", version=f"fractalgeo_rs {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback of an error instead of one line")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in _DOMAIN_CLIS:
        importlib.import_module(name).add_parsers(sub)
    return parser


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = build_parser()
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
    except ModuleNotFoundError as exc:
        if args.debug:
            raise
        print(f"fractalgeo {args.command}: error: {missing_dependency_message(exc)}", file=sys.stderr)
        return 1
    except (ValueError, TypeError, OSError, MemoryError) as exc:
        if args.debug:
            raise
        print(f"fractalgeo {args.command}: error: {exc}", file=sys.stderr)
        return 1


def _one_line_warning(command):
    """A ``warnings.showwarning`` printing ``fractalgeo CMD: warning: ...``
    on one line of stderr (no file name, line number or source line: they
    would point into the package)."""

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"fractalgeo {command}: warning: {message}", file=sys.stderr if file is None else file)

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
