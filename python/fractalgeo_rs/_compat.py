"""Deprecation shims for renamed parameters (the naming table of the docs).

A parameter renamed to follow the package's naming rules keeps working under
its old name for one release, with a ``DeprecationWarning`` that names the
new spelling; an option that became keyword-only still accepts its old
position the same way. Both decorators keep the wrapped function's
signature (``inspect.signature`` shows the new one), so the docs, the stubs
and the signature test see only the current names.
"""
from __future__ import annotations

import functools
import inspect
import warnings

from fractalgeo_rs._warn import user_stacklevel
from typing import Callable, Dict, Sequence, TypeVar

F = TypeVar("F", bound=Callable)


def renamed_parameters(renames: Dict[str, str], *, since: str) -> Callable[[F], F]:
    """Accept old keyword names ``renames = {old: new}`` with a DeprecationWarning."""

    def decorate(func: F) -> F:
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            for old, new in renames.items():
                if old in kwargs:
                    if new in kwargs:
                        raise TypeError(f"{func.__name__}: got both {new!r} and its deprecated name {old!r}")
                    warnings.warn(
                        f"{func.__name__}: the parameter {old!r} is now called {new!r} (renamed in {since}; "
                        f"the old name will be removed in the next release)",
                        DeprecationWarning, stacklevel=user_stacklevel())
                    kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)

        return wrapper  # type: ignore[return-value]

    return decorate


def keyword_only_since(names: Sequence[str], *, since: str) -> Callable[[F], F]:
    """Accept ``names`` (now keyword-only) at their old positions, with a DeprecationWarning.

    ``names`` are the parameters that used to follow the positional ones, in
    their old order.
    """

    def decorate(func: F) -> F:
        params = inspect.signature(func).parameters.values()
        n_pos = sum(p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) for p in params)

        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if len(args) > n_pos:
                extra = args[n_pos:]
                if len(extra) > len(names):
                    raise TypeError(f"{func.__name__}() takes {n_pos} positional arguments but {len(args)} were given")
                moved = list(names[: len(extra)])
                for name, value in zip(moved, extra):
                    if name in kwargs:
                        raise TypeError(f"{func.__name__}() got multiple values for argument {name!r}")
                    kwargs[name] = value
                warnings.warn(
                    f"{func.__name__}: pass {', '.join(moved)} by keyword ({'=..., '.join(moved)}=...); "
                    f"positional use is deprecated since {since} and will be removed in the next release",
                    DeprecationWarning, stacklevel=user_stacklevel())
                args = args[:n_pos]
            return func(*args, **kwargs)

        return wrapper  # type: ignore[return-value]

    return decorate
