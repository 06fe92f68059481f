"""L-systems: rules, derivation and derived strings.

The rewriting engine is in Rust (``fractalgeo_rs._core.LSystemCore``); this
module validates arguments and documents the API.
"""
from __future__ import annotations

import numbers
import os
from typing import Any, Mapping, Optional, Sequence, Union


from fractalgeo_rs import _core
from fractalgeo_rs._validation import MemoryLimitError, check_memory, check_n_threads, check_nonnegative_int, check_seed

__all__ = ["LSystem", "LString", "DEFAULT_MAX_LENGTH"]

#: Default limit on the number of modules of a derived string.
DEFAULT_MAX_LENGTH = 100_000_000

#: Bytes per module of a derived string at the peak of a derivation step
#: (the previous and the new string, one 4-byte symbol each; parameters come
#: on top).
BYTES_PER_MODULE = 8

RulesLike = Union[str, Mapping[str, Any], Sequence[str]]


def _modules(lower: int, upper: int) -> str:
    """The module count of a derivation for messages (exact below 10**12,
    else 3 digits; ``2**128 - 1`` is a saturated count)."""
    if lower >= 2**128 - 1:
        return f"more than {float(lower):.3g}"
    n = str(lower) if lower < 10**12 else f"{float(lower):.3g}"
    return f"exactly {n}" if lower == upper else f"at least {n}"


def _rule_lines(rules: RulesLike) -> list:
    """Normalise the accepted rule forms to production lines."""
    if isinstance(rules, str):
        return [ln.split("#")[0].strip() for ln in rules.splitlines() if ln.split("#")[0].strip()]
    if isinstance(rules, Mapping):
        lines = []
        for lhs, succ in rules.items():
            if not isinstance(lhs, str):
                raise TypeError(f"rules: predecessor {lhs!r} must be a str")
            if isinstance(succ, str):
                lines.append(f"{lhs} -> {succ}")
                continue
            try:
                alts = list(succ)
            except TypeError:
                raise TypeError(f"rules: successor of {lhs!r} must be a str or a list of (str, weight)") from None
            if not alts:
                raise ValueError(f"rules: {lhs!r} has an empty list of successors")
            for alt in alts:
                if not (isinstance(alt, (tuple, list)) and len(alt) == 2 and isinstance(alt[0], str)):
                    raise TypeError(f"rules: stochastic successors of {lhs!r} must be (str, weight) pairs, got {alt!r}")
                w = alt[1]
                if isinstance(w, bool) or not isinstance(w, numbers.Real):
                    raise TypeError(f"rules: weight {w!r} of {lhs!r} must be a number")
                lines.append(f"{lhs} -({float(w)!r})-> {alt[0]}")
        return lines
    if isinstance(rules, (list, tuple)):
        for r in rules:
            if not isinstance(r, str):
                raise TypeError(f"rules: expected production strings, got {r!r}")
        return [r for r in rules if r.strip()]
    raise TypeError(f"rules: expected a str, a dict or a list of str, got {type(rules).__name__}")


class LString:
    """A string of modules: symbols with optional real parameters.

    Returned by :meth:`~fractalgeo_rs.LSystem.derive`; also built from text with
    :meth:`~fractalgeo_rs.LString.parse`. ``str(s)`` gives the text form (``A(1,2.5)B``),
    ``len(s)`` the number of modules.

    Parameters
    ----------
    core : ``_core.ModuleString``
        The Rust string of modules; build an ``LString`` with
        :meth:`~fractalgeo_rs.LString.parse` or :meth:`~fractalgeo_rs.LSystem.derive` rather than directly.

    References
    ----------
    P. Prusinkiewicz and A. Lindenmayer, *The Algorithmic Beauty of Plants*,
    Springer, 1990, doi:10.1007/978-1-4613-8476-2.

    Examples
    --------
    >>> from fractalgeo_rs import LString, LSystem
    >>> s = LString.parse('A(1,2.5)B')
    >>> len(s), str(s), s.count('A')
    (2, 'A(1,2.5)B', 1)
    >>> str(LSystem('b', {'b': 'a', 'a': 'ab'}).derive(4))  # Fibonacci words, eq. 23 of the paper
    'abaab'
    """

    __slots__ = ("_core",)

    def __init__(self, core: "_core.ModuleString"):
        self._core = core

    @classmethod
    def parse(cls, text: str) -> "LString":
        """Parse a module string such as ``"F(1)[+A(2, 3)]"``.

        Parameters must be constant expressions.
        """
        if not isinstance(text, str):
            raise TypeError(f"text: expected a str, got {type(text).__name__}")
        return cls(_core.ModuleString.parse(text))

    def __len__(self) -> int:
        return len(self._core)

    def __str__(self) -> str:
        return str(self._core)

    def __repr__(self) -> str:
        s = str(self._core) if len(self._core) <= 60 else str(self._core)[:57] + "..."
        return f"LString({s!r}, n_modules={len(self)})"

    def __eq__(self, other) -> bool:
        if isinstance(other, LString):
            return self._core == other._core
        if isinstance(other, str):
            return str(self) == other
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def count(self, symbol: str) -> int:
        """Number of modules whose symbol is ``symbol`` (one character)."""
        if not isinstance(symbol, str) or len(symbol) != 1:
            raise ValueError(f"symbol: expected one character, got {symbol!r}")
        return self._core.count(symbol)

    @property
    def symbols(self) -> str:
        """The symbols without parameters."""
        return self._core.symbols()

    def parameters(self) -> tuple:
        """``(values, offsets)``: the parameters of module ``i`` are
        ``values[offsets[i]:offsets[i + 1]]``."""
        return self._core.parameters()


class LSystem:
    r"""A Lindenmayer system with parallel rewriting.

    DOL, bracketed, stochastic, context-sensitive and parametric productions
    (Prusinkiewicz and Lindenmayer 1990, chapter 1). In a derivation step
    every module is rewritten at the same time from the previous string;
    symbols are case-sensitive.

    Parameters
    ----------
    axiom : str
        The initial string, e.g. ``"F"`` or ``"B(2)A(4, 4)"``.
    rules : str, dict or list of str
        Productions. A list of lines or one multi-line str in the syntax
        ``[left <] pred [> right] [: condition] -> successor``, with a weight
        for stochastic alternatives: ``F -(0.33)-> F[+F]F``. A dict maps a
        predecessor (with optional context and condition) to a successor str
        or to a list of ``(successor, weight)`` pairs.
    ignore : str, optional
        Symbols skipped when matching contexts (ABOP's ``#ignore``).
    seed : int, optional
        Seed of the stochastic choices; None draws one (see :attr:`~fractalgeo_rs.LSystem.seed`).
        Choices come from a hash of (seed, step, position), so the same seed
        gives the same strings on any number of threads.
    max_length : int
        Largest allowed number of modules; a longer derivation raises
        ``ValueError`` instead of exhausting memory (see :meth:`derive`).
    defaults : mapping of str to str, optional
        Settings for the caller (``n``, ``angle``, ``step``, ...; the
        ``key: value`` lines of the text format), kept as the dict attribute
        ``defaults``; the L-system itself does not read them.

    Notes
    -----
    * A predecessor ``A(x, y)`` matches ``A`` with exactly two parameters; a
      bare ``A`` matches ``A`` with any parameters. Productions are tried in
      order, the first that matches applies; unmatched modules are copied.
    * Contexts follow ABOP section 1.8: the left context skips whole
      branches ``[...]`` and climbs out of the current one; the right
      context skips side branches and fails at the end of a branch; it may
      contain brackets (``B > [C]D``). Symbols in ``ignore`` are skipped.
    * Expressions: ``+ - * / % ^``, comparisons, ``&& || !`` (or ``and or
      not``), functions ``sin cos tan`` (degrees) ``sqrt abs exp log floor
      ceil round min max sign atan2``, constants ``pi`` and ``e``.

    References
    ----------
    Prusinkiewicz and Lindenmayer (1990); full entry in the
    :ref:`bibliography <ref-prusinkiewicz1990>`.

    Examples
    --------
    >>> from fractalgeo_rs.lsystem import LSystem
    >>> algae = LSystem("b", {"b": "a", "a": "ab"})
    >>> [str(algae.derive(n)) for n in range(6)]
    ['b', 'a', 'ab', 'aba', 'abaab', 'abaababa']
    >>> LSystem("B(2)A(4,4)", ["A(x,y): y <= 3 -> A(x*2, x+y)",
    ...                        "A(x,y): y > 3 -> B(x)A(x/y, 0)",
    ...                        "B(x): x < 1 -> C", "B(x): x >= 1 -> B(x-1)"]).derive(3)
    LString('CB(2)A(4,3)', n_modules=3)
    """

    def __init__(
        self,
        axiom: str,
        rules: RulesLike,
        *,
        ignore: Optional[str] = None,
        seed: Optional[int] = None,
        max_length: int = DEFAULT_MAX_LENGTH,
        defaults: Optional[Mapping[str, str]] = None,
    ):
        if not isinstance(axiom, str):
            raise TypeError(f"axiom: expected a str, got {type(axiom).__name__}")
        if ignore is not None and not isinstance(ignore, str):
            raise TypeError(f"ignore: expected a str of symbols or None, got {type(ignore).__name__}")
        if isinstance(max_length, bool) or not isinstance(max_length, numbers.Integral) or max_length < 1:
            raise ValueError(f"max_length: expected a positive int, got {max_length!r}")
        self._lines: tuple = tuple(_rule_lines(rules))
        self._seed: int = check_seed(seed)
        self._ignore: str = ignore or ""
        self._axiom: str = axiom
        self._max_length: int = int(max_length)
        self._core: _core.LSystemCore = _core.LSystemCore(axiom, list(self._lines), self._ignore, self._seed,
                                                          self._max_length)
        self.defaults: dict = dict(defaults or {})

    @classmethod
    def from_string(cls, text: str, *, seed: Optional[int] = None, max_length: int = DEFAULT_MAX_LENGTH) -> "LSystem":
        """Build from the rule text format.

        ``#`` starts a comment; ``axiom: ...`` and ``ignore: ...`` lines set
        those; any other ``key: value`` line (``n``, ``angle``, ``step``,
        ``width``, ...) is kept in the dict ``defaults`` for the caller; every
        line with ``->`` is a production. A ``seed: k`` line is used when
        ``seed`` is None.

        Examples
        --------
        >>> from fractalgeo_rs.lsystem import LSystem
        >>> plant = LSystem.from_string('''
        ... axiom: F
        ... n: 2
        ... angle: 25.7
        ... F -> F[+F]F[-F]F
        ... ''')
        >>> plant.defaults
        {'n': '2', 'angle': '25.7'}
        >>> len(plant.derive(2))
        61
        """
        if not isinstance(text, str):
            raise TypeError(f"text: expected a str, got {type(text).__name__}")
        axiom, ignore, rules, directives = _core.lsystem_parse_text(text)
        d = dict(directives)
        if seed is None and "seed" in d:
            try:
                seed = int(d["seed"])
            except ValueError:
                raise ValueError(f"text: seed must be an int, got {d['seed']!r}") from None
        return cls(axiom, rules, ignore=ignore, seed=seed, max_length=max_length, defaults=d)

    @classmethod
    def from_file(cls, path: Union[str, os.PathLike], **kwargs) -> "LSystem":
        """Read the rule text format from a file (see :meth:`from_string`)."""
        with open(os.fspath(path), encoding="utf-8") as fh:
            return cls.from_string(fh.read(), **kwargs)

    @property
    def axiom(self) -> str:
        """The axiom (the word of generation 0)."""
        return self._axiom

    @property
    def rules(self) -> tuple:
        """The production lines."""
        return self._lines

    @property
    def ignore(self) -> str:
        """Symbols skipped when matching the context of context-sensitive rules."""
        return self._ignore

    @property
    def seed(self) -> int:
        """The seed in use (drawn at construction when None was given)."""
        return self._seed

    @property
    def is_stochastic(self) -> bool:
        """True when a predecessor has more than one weighted successor."""
        return self._core.is_stochastic

    def __repr__(self) -> str:
        return f"LSystem(axiom={self._axiom!r}, rules={list(self._lines)!r}, ignore={self._ignore!r}, seed={self._seed})"

    def derive(self, n: int, *, seed: Optional[int] = None, n_threads: Optional[int] = None) -> LString:
        """Apply ``n`` parallel derivation steps to the axiom.

        Parameters
        ----------
        n : int
            Number of steps (0 gives the axiom).
        seed : int, optional
            Overrides :attr:`seed` for this derivation.
        n_threads : int, optional
            Threads for the rewriting (all cores when None); the result does
            not depend on it.

        Returns
        -------
        LString

        Raises
        ------
        MemoryError
            Before anything is expanded, when the length after ``n`` steps,
            counted from the productions (:meth:`length_bounds`), is above
            ``max_length`` or needs more than the memory limit
            (``BYTES_PER_MODULE = 8`` bytes per module; docs/input_policy.md).
            The error is a ``ValueError`` too and its message starts with
            ``n:``.
        ValueError
            When the string would exceed ``max_length`` modules during the
            expansion (only possible when the count is not exact), or a
            parametric production gives a non-finite value.
        """
        n = check_nonnegative_int(n)
        s = None if seed is None else check_seed(seed)
        n_threads = check_n_threads(n_threads)
        lower, upper = self._core.length_bounds(n)
        what = _modules(lower, upper)
        if lower > self._max_length:
            raise MemoryLimitError(
                f"n: {n} derivation steps give {what} modules (counted from the productions, nothing "
                f"expanded), more than max_length={self._max_length}; lower n or raise max_length")
        check_memory(lower * BYTES_PER_MODULE, "n", what=f"n={n} derivation steps ({what} modules)")
        return LString(self._core.derive(n, seed=s, n_threads=n_threads))

    def length_bounds(self, n: int) -> tuple:
        """Bounds ``(lower, upper)`` on the number of modules after ``n``
        steps, counted from the productions without expanding anything.

        The count of each symbol evolves as :math:`v_{k+1} = M v_k` (column
        ``c`` of ``M``: the symbol counts of the successor of ``c``;
        Prusinkiewicz & Lindenmayer 1990, growth functions of DOL-systems).
        Where the successor is not fixed (stochastic alternatives, or a
        production that may not apply because of a context, a condition or
        the number of parameters, the module then being copied), ``lower``
        takes the smallest count of each symbol over the possible successors
        and ``upper`` the largest, so ``lower <= len(derive(n)) <= upper``;
        for deterministic context-free systems ``lower == upper`` is the
        exact length. Counts saturate at ``2**128 - 1``.

        Parameters
        ----------
        n : int
            Number of derivation steps (at most 1 000 000).

        Returns
        -------
        tuple of int
            ``(lower, upper)`` numbers of modules.

        References
        ----------
        Prusinkiewicz and Lindenmayer (1990), section 1.2; full entry in the
        :ref:`bibliography <ref-prusinkiewicz1990>`.

        Examples
        --------
        >>> from fractalgeo_rs.lsystem import LSystem
        >>> koch = LSystem("F++F++F", {"F": "F-F++F-F"})
        >>> koch.length_bounds(3), len(koch.derive(3))  # 7 * 4**n
        ((448, 448), 448)
        >>> LSystem("F", {"F": "F" * 10}).length_bounds(30)[0] == 10**30
        True
        """
        return self._core.length_bounds(check_nonnegative_int(n))

    def generations(self, n: int, *, n_threads: Optional[int] = None) -> list:
        """The strings of steps 0, 1, ..., n (each with the same seed)."""
        n = check_nonnegative_int(n)
        return [self.derive(k, n_threads=n_threads) for k in range(n + 1)]
