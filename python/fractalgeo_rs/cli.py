"""The ``fractalgeo`` command line.

Each domain adds its subcommands from its own ``_cli`` module, listed in
``_DOMAIN_CLIS``: the module has ``add_parsers(subparsers)`` which registers
subparsers whose ``func`` attribute takes the parsed ``args`` and returns an
exit code.
"""
from __future__ import annotations

import argparse
import importlib
import sys
from typing import Optional, Sequence

_DOMAIN_CLIS = (
    "fractalgeo_rs.dimension._cli",
    "fractalgeo_rs.lsystem._cli",
    "fractalgeo_rs.synth._cli",
    "fractalgeo_rs.transform._cli",
    "fractalgeo_rs.tin._cli",
    # each issue adds its domain's _cli module here
)


def build_parser() -> argparse.ArgumentParser:
    from fractalgeo_rs import __version__

    parser = argparse.ArgumentParser(
        prog="fractalgeo",
        description="Fractal geometry for geo-information processing (fractalgeo_rs).",
    )
    parser.add_argument("--version", action="version", version=f"fractalgeo_rs {__version__}")
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
        return int(args.func(args) or 0)
    except (ValueError, TypeError, OSError) as exc:
        print(f"fractalgeo {args.command}: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
