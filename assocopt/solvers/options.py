"""Declared back-end options: each back end lists its options once, one parser checks them.

An :class:`Option` names one option, its kind (integer, number, flag, choice, text,
table, pair of axes), its range or choices, its default and a one-line description.
Each :class:`~assocopt.solvers.base.Backend` declares ``options: tuple[Option, ...]``;
:func:`parse_options` validates what a caller passes against that declaration for
every back end with one wording, rejects unknown names (unless the back end passes
names through to its own solver, such as HiGHS or CP-SAT parameters) and returns the
values with the defaults filled in; :func:`assocopt.solve` records them in
``Solution.info["options"]``.  The options common to every back end (``time_limit``,
``mip_gap``, ``threads``, ``verbose``) are declared in :data:`COMMON_OPTIONS` and
checked by :func:`check_common`, the one place that does it.

The same declarations feed ``assocopt solvers --options NAME``, the checks of model
files (:mod:`assocopt.workflow.models`) and the page ``docs/solver-options.md``
(:func:`assocopt.solvers.base.options_page`, which lists the registry).  This module
reads a back end's declaration only, never the registry.

Examples
--------
>>> from assocopt.solvers import get_backend
>>> get_backend("bruteforce").parse_options({"max_nodes": 10})
{'max_nodes': 10}
>>> get_backend("bruteforce").parse_options({"max_nodez": 10})
Traceback (most recent call last):
...
assocopt.solvers.options.OptionError: unknown option 'max_nodez' for solver 'bruteforce'; valid options: max_nodes
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping, Protocol

import numpy as np

from ..runtime.errors import InvalidProblemError

__all__ = ["Option", "OptionError", "COMMON_OPTIONS", "COMMON_NAMES", "parse_options",
           "check_common", "options_table"]

class Declaring(Protocol):
    """What the checks read of a back-end class (:class:`~assocopt.solvers.base.Backend`)."""

    name: str
    options: tuple["Option", ...]
    native_options: str

    def is_native_option(self, name: str) -> bool:
        """Whether ``name`` is passed through to the back end's own solver."""


#: Kinds of value an :class:`Option` takes.
KINDS = ("int", "float", "bool", "choice", "str", "dict", "axes")


class OptionError(InvalidProblemError):
    """A bad or unknown option; ``option`` names it and ``reason`` says what is wrong
    (without the solver's name, for callers that add their own context)."""

    def __init__(self, message: str, option: str, reason: str) -> None:
        super().__init__(message)
        self.option = option
        self.reason = reason


@dataclass(frozen=True)
class Option:
    """One declared option of a back end.

    ``kind``: one of :data:`KINDS`.  ``low`` / ``high``: the range of an ``int`` or
    ``float`` (None: unbounded), ``low_open`` / ``high_open`` exclude the end point;
    NaN is never accepted, infinities only where the range includes them.
    ``choices``: the values of a ``choice``; for ``float`` options, literal strings
    accepted besides numbers (``"auto"``).  ``nullable``: None is accepted too.
    """

    name: str
    kind: str
    default: Any
    doc: str
    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    choices: tuple[Any, ...] = ()
    nullable: bool = False

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"option {self.name}: kind must be one of {KINDS}, "
                             f"got {self.kind!r}")

    # ----------------------------------------------------------------- text
    def describe(self) -> str:
        """What the option accepts, in words: ``"a positive integer"``..."""
        text = {"bool": "True or False", "str": "a string", "dict": "a table (dict)",
                "axes": "two different axis numbers"}.get(self.kind)
        if self.kind == "choice":
            text = "one of " + ", ".join(repr(c) for c in self.choices)
        elif self.kind in ("int", "float"):
            text = self._describe_range()
            if self.choices:
                text = " or ".join(repr(c) for c in self.choices) + " or " + text
        return f"{text} (or None)" if self.nullable else str(text)

    def _describe_range(self) -> str:
        noun = "integer" if self.kind == "int" else "number"
        lo, hi = self.low, self.high
        open_top = hi is None or hi == math.inf
        finite = " finite" if self.kind == "float" and hi == math.inf and self.high_open else ""
        if lo == 0 and open_top:
            return f"a {'positive' if self.low_open else 'non-negative'}{finite} {noun}"
        if self.kind == "int" and lo == 1 and open_top:
            return "a positive integer"
        article = "an" if noun == "integer" and not finite else "a"
        if lo is None and open_top:
            return f"{article}{finite} {noun}"
        if open_top:
            return f"{article}{finite} {noun} {'>' if self.low_open else '>='} {lo:g}"
        left = "(" if self.low_open or lo is None else "["
        right = ")" if self.high_open else "]"
        low_text = "-inf" if lo is None else f"{lo:g}"
        return f"{article} {noun} in {left}{low_text}, {hi:g}{right}"

    def default_text(self) -> str:
        return "None" if self.default is None else repr(self.default)

    # ----------------------------------------------------------------- check
    def check(self, value: Any) -> Any:
        """``value`` normalised (``int``, ``float``, ``bool``, tuple), or ValueError
        with the reason."""
        if value is None and self.nullable:
            return None
        ok, out = getattr(self, f"_check_{self.kind}")(value)
        if not ok:
            raise ValueError(f"must be {self.describe()}, got {value!r}")
        return out

    def _in_range(self, v: float) -> bool:
        lo = -math.inf if self.low is None else self.low
        hi = math.inf if self.high is None else self.high
        if math.isnan(v) or v < lo or v > hi:
            return False
        return not ((self.low_open and v == lo) or (self.high_open and v == hi))

    def _check_int(self, v: Any) -> tuple[bool, Any]:
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
            return False, None
        return self._in_range(float(v)), int(v)

    def _check_float(self, v: Any) -> tuple[bool, Any]:
        if isinstance(v, str) and v in self.choices:
            return True, v
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer,
                                                                  np.floating)):
            return False, None
        return self._in_range(float(v)), float(v)

    def _check_bool(self, v: Any) -> tuple[bool, Any]:
        return isinstance(v, (bool, np.bool_)), bool(v)

    def _check_choice(self, v: Any) -> tuple[bool, Any]:
        try:
            return v in self.choices, v
        except TypeError:
            return False, None

    def _check_str(self, v: Any) -> tuple[bool, Any]:
        return isinstance(v, str), v

    def _check_dict(self, v: Any) -> tuple[bool, Any]:
        return isinstance(v, Mapping), dict(v) if isinstance(v, Mapping) else None

    def _check_axes(self, v: Any) -> tuple[bool, Any]:
        if isinstance(v, (str, bytes)) or not isinstance(v, Iterable):
            return False, None
        items = list(v)
        if len(items) != 2 or not all(isinstance(a, (int, np.integer))
                                      and not isinstance(a, (bool, np.bool_)) for a in items):
            return False, None
        a, b = (int(x) for x in items)
        return a != b and a >= 0 and b >= 0, (a, b)


#: The options every back end takes (arguments of :func:`assocopt.solve`).
COMMON_OPTIONS: tuple[Option, ...] = (
    Option("time_limit", "float", None, "seconds (inf or None: no limit); a run stopped "
           "by it reports time_limit", low=0.0, low_open=True, nullable=True),
    Option("mip_gap", "float", 0.0, "relative gap at which a MIP solver may stop "
           "(0: prove optimality)", low=0.0, high=1.0, high_open=True),
    Option("threads", "int", None, "worker threads (None: the back end's default)",
           low=1, nullable=True),
    Option("verbose", "bool", False, "let the back end print its log"),
)
COMMON_NAMES = tuple(o.name for o in COMMON_OPTIONS)
_COMMON = {o.name: o for o in COMMON_OPTIONS}


def check_common(time_limit: Any = None, mip_gap: Any = 0.0, threads: Any = None,
                 verbose: Any = False) -> tuple[float | None, float, int | None, bool]:
    """The common options checked and normalised; :class:`OptionError` names the
    option and the value (``time_limit=True``, ``mip_gap=1.5``, ``threads=2.0``...)."""
    if time_limit is None and threads is None and verbose is False and \
            type(mip_gap) in (float, int) and mip_gap == 0:
        return None, 0.0, None, False       # the defaults: the hot path of small solves
    values = {"time_limit": time_limit, "mip_gap": mip_gap, "threads": threads,
              "verbose": verbose}
    out = []
    for name, value in values.items():
        try:
            out.append(_COMMON[name].check(value))
        except ValueError as exc:
            raise OptionError(f"{name} {exc}", name, str(exc)) from None
    if out[0] == math.inf:                  # no limit, as in HiGHS
        out[0] = None
    return out[0], out[1], out[2], out[3]


def parse_options(backend: type[Declaring], given: Mapping[str, Any]) -> dict[str, Any]:
    """``given`` checked against ``backend.options``: every declared option with its
    value or default, plus any names the back end passes through to its solver.

    Raises :class:`OptionError` (an :class:`~assocopt.runtime.errors.InvalidProblemError`) for
    an unknown name or a bad value, with one wording for every back end.
    """
    declared, defaults, mutable = _declared(backend)
    out = dict(defaults)
    for key in mutable:                   # a fresh copy of a mutable default
        out[key] = dict(out[key])
    for key, value in given.items():
        opt = declared.get(key)
        if opt is None:
            if isinstance(key, str) and backend.is_native_option(key):
                out[key] = value
                continue
            raise OptionError(unknown_message(backend, key), str(key), "unknown option")
        try:
            out[key] = opt.check(value)
        except ValueError as exc:
            raise OptionError(f"solver {backend.name!r}: option {key} {exc}", key,
                              str(exc)) from None
    return out


_DECLARED: dict[type, tuple[Any, ...]] = {}


def _declared(backend: type[Declaring]
              ) -> tuple[dict[str, Option], dict[str, Any], tuple[str, ...]]:
    """``backend``'s options by name, their defaults and the names of the mutable
    ones (cached per class while its declaration is the same object: options are
    parsed on every solve)."""
    hit = _DECLARED.get(backend)
    if hit is None or hit[0] is not backend.options:
        opts = backend.options
        hit = _DECLARED[backend] = (opts, {o.name: o for o in opts},
                                    {o.name: o.default for o in opts},
                                    tuple(o.name for o in opts if isinstance(o.default, dict)))
    return hit[1], hit[2], hit[3]


def unknown_message(backend: type[Declaring], key: Any) -> str:
    """The one wording of an unknown option."""
    names = ", ".join(o.name for o in backend.options) or "none"
    more = f"; it also takes {backend.native_options}" if backend.native_options else ""
    return f"unknown option {key!r} for solver {backend.name!r}; valid options: {names}{more}"


# ---------------------------------------------------------------- documentation
def options_table(backend: type[Declaring]) -> list[tuple[str, str, str, str]]:
    """Rows ``(name, accepts, default, description)`` of ``backend``'s options."""
    return [(o.name, o.describe(), o.default_text(), o.doc) for o in backend.options]
