"""The small interface every back end implements, and the registry of back ends.

A back end is a class with a ``name``, capability flags, ``is_available()`` (checked
without importing the package), ``version()`` and ``solve(problem, options)``, which
returns a :class:`RawResult` in terms of candidate positions.  Turning that into a
:class:`~assocopt.model.solution.Solution` (recomputing the objective, checking
feasibility, timing) is done once, in :mod:`assocopt.solving.api`, for every back end.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.metadata
import importlib.util
import sys
import time
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ..runtime.errors import (InvalidProblemError, SolverCapabilityError, SolverNotInstalledError,
                              UnknownSolverError)
from ..problems.problem import AssignmentProblem
from ..model.solution import Status
from .options import COMMON_OPTIONS, Option, check_common, options_table, parse_options

__all__ = ["SolveOptions", "RawResult", "Backend", "register", "declare", "get_backend",
           "registered", "available", "names", "check_capabilities", "empty_answer",
           "Option", "options_page"]


@dataclass(frozen=True)
class SolveOptions:
    """Options common to all back ends; ``extra`` holds back-end specific ones.

    relax : None or "lp"
        Solve the ILP, or its LP relaxation.
    time_limit : float or None
        Seconds; a back end stopped by it reports ``Status.TIME_LIMIT``.
    mip_gap : float
        Relative gap at which a MIP solver may stop (0 = prove optimality).  A
        solution returned with a positive gap is ``FEASIBLE``, not ``OPTIMAL``,
        unless the reached gap is 0.
    threads : int or None
        Worker threads for back ends that use them (None: the back end's default).
    verbose : bool
        Let the back end print its log.
    extra : dict
        The back end's own options; ``parsed`` says they were already checked
        against its declaration (:meth:`Backend.parse_options`, done by
        :func:`assocopt.solve`), so the back end need not check them again.

    The common options are checked here (:func:`~assocopt.solvers.options.check_common`),
    so a back end called directly gets the same checks as one called through
    :func:`assocopt.solve`.
    """

    relax: str | None = None
    time_limit: float | None = None
    mip_gap: float = 0.0
    threads: int | None = None
    verbose: bool = False
    extra: dict[str, Any] = field(default_factory=dict)
    parsed: bool = False

    @classmethod
    def parsed_defaults(cls, relax: str | None, extra: dict[str, Any]) -> "SolveOptions":
        """The common options at their defaults with back-end options ``extra``
        already parsed: what :func:`assocopt.solve` builds for almost every call,
        filled in without the dataclass ``__init__`` (the defaults need no check;
        ``relax`` must be None or "lp", checked by the caller)."""
        opts = object.__new__(cls)
        opts.__dict__.update(relax=relax, time_limit=None, mip_gap=0.0, threads=None,
                             verbose=False, extra=extra, parsed=True)
        return opts

    def __post_init__(self) -> None:
        if self.relax not in (None, "lp"):
            raise InvalidProblemError(f"relax must be None or 'lp', got {self.relax!r}")
        if self.time_limit is None and self.threads is None and self.verbose is False \
                and type(self.mip_gap) is float and self.mip_gap == 0.0:
            return                         # the defaults: the hot path of small solves
        values = check_common(self.time_limit, self.mip_gap, self.threads, self.verbose)
        for name, value in zip(("time_limit", "mip_gap", "threads", "verbose"), values):
            object.__setattr__(self, name, value)


@dataclass
class RawResult:
    """What a back end hands back, before the common checks of :func:`assocopt.solve`.

    ``selected``: candidate positions of an integral solution (or None);
    ``x``: the LP values of all candidates (LP relaxations only);
    ``bound``: a proven lower bound, if the method gives one;
    ``objective``: the back end's own objective (used for LPs; for integral
    solutions the objective is recomputed from the costs);
    ``build_time`` / ``solve_time``: seconds spent building the back end's model
    and inside the back end's solve call; ``solver``: the method that produced the
    answer when it is not the back end that was called (a fallback; its name is then
    reported as ``Solution.solver``);
    ``col_of_row``: instead of ``selected``, for a problem with a dense 2-D view
    (:attr:`AssignmentProblem.dense_view`): the column of each row, ``-1`` = left out.
    """

    status: Status
    selected: np.ndarray | None = None
    x: np.ndarray | None = None
    bound: float | None = None
    objective: float | None = None
    message: str = ""
    info: dict[str, Any] = field(default_factory=dict)
    build_time: float = 0.0
    solve_time: float = 0.0
    solver: str = ""
    col_of_row: np.ndarray | None = None


def remaining(options: SolveOptions, start: float) -> SolveOptions:
    """``options`` with the time limit reduced by what has passed since ``start``
    (``time.perf_counter()``): building a model counts against the limit too."""
    if options.time_limit is None:
        return options
    left = max(options.time_limit - (time.perf_counter() - start), 1e-3)
    return dataclasses.replace(options, time_limit=left)


@functools.lru_cache(maxsize=None)
def _distribution_version(dist: str) -> str:
    """Installed version of ``dist``; cached: reading metadata costs milliseconds."""
    try:
        return importlib.metadata.version(dist)
    except importlib.metadata.PackageNotFoundError:
        return ""


def import_missing(modules: tuple[str, ...]) -> float:
    """Import those of ``modules`` not yet loaded; the seconds it took (0.0 when all
    were loaded: a dictionary lookup each)."""
    import sys
    missing = [m for m in modules if m not in sys.modules]
    if not missing:
        return 0.0
    import time
    t = time.perf_counter()
    for m in missing:
        importlib.import_module(m)
    return time.perf_counter() - t


@functools.lru_cache(maxsize=None)
def module_installed(module: str) -> bool:
    """Whether ``module`` can be imported, looked up once per process (``find_spec``
    costs tens of microseconds, a small solve a few hundred): for hot paths such as
    ``auto``'s choice; :meth:`Backend.is_available` looks afresh each time."""
    try:
        return importlib.util.find_spec(module) is not None
    except (ImportError, ValueError):
        return False


class Backend:
    """Base class of the back ends.  Subclasses set the class attributes and ``solve``.

    Capability flags, checked by :func:`assocopt.solve` before dispatch:

    ``integer``: solves the ILP; ``lp``: solves the LP relaxation; ``exact``: proves
    optimality of the ILP; ``gives_bound``: reports a lower bound; ``max_ndim``:
    largest N it accepts (None: any); ``supports_time_limit``;
    ``exact_float_costs``: proves optimality for arbitrary float costs, not only for
    integer ones (False for CP-SAT, which scales costs to integers).

    ``options``: the back end's own options, declared once (see
    :mod:`assocopt.solvers.options`); ``native_options``: when not empty, the back
    end also passes other names through to its solver (say which, e.g. "any HiGHS
    option by name"), and :meth:`is_native_option` tells which names exist.
    """

    name: ClassVar[str] = ""
    module: ClassVar[str | None] = None         # import name checked by is_available
    distribution: ClassVar[str | None] = None   # pip name for the install hint
    description: ClassVar[str] = ""
    integer: ClassVar[bool] = True
    lp: ClassVar[bool] = False
    exact: ClassVar[bool] = True
    gives_bound: ClassVar[bool] = True
    max_ndim: ClassVar[int | None] = None
    supports_time_limit: ClassVar[bool] = False
    exact_float_costs: ClassVar[bool] = True
    options: ClassVar[tuple[Option, ...]] = ()
    native_options: ClassVar[str] = ""
    #: The method is assocopt's own (its version is assocopt's, even when a package
    #: such as numba runs it).
    own_method: ClassVar[bool] = False
    #: Modules its solve imports on first use (the solver package and what building
    #: its model needs): :func:`assocopt.solve` imports the missing ones first and
    #: reports the seconds as ``times["import"]``, not as build or solve time.
    imports: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def imports_for(cls, problem: AssignmentProblem) -> tuple[str, ...]:
        """:attr:`imports` of a solve of ``problem`` (a back end whose route depends on
        the problem narrows them)."""
        return cls.imports

    @classmethod
    def is_native_option(cls, name: str) -> bool:
        """Whether ``name`` is an option of the underlying solver (passed through)."""
        return False

    @classmethod
    def parse_options(cls, given: dict[str, Any]) -> dict[str, Any]:
        """``given`` checked against :attr:`options`, defaults filled in."""
        return parse_options(cls, given)

    def settings(self, problem: AssignmentProblem, options: SolveOptions) -> dict[str, Any]:
        """What every ``solve`` starts with: refuse what the capability flags rule
        out, and the parsed options (taken as they are when already parsed)."""
        check_capabilities(type(self), problem, options.relax)
        return dict(options.extra) if options.parsed else self.parse_options(options.extra)

    @classmethod
    def is_available(cls) -> bool:
        """Whether the back end's package is installed (without importing it)."""
        if cls.module is None:
            return True
        try:
            return importlib.util.find_spec(cls.module) is not None
        except (ImportError, ValueError):
            return False

    @classmethod
    def version(cls) -> str:
        """Version of the method: assocopt's for its own methods, else that of the
        package doing the work ("" when not installed): the imported module's
        ``__version__`` when the module is the distribution (no metadata scan: the
        first costs 10-15 ms), else the installed metadata."""
        if cls.own_method or cls.distribution is None:
            from .._version import __version__
            return __version__
        dist = cls.distribution
        mod = sys.modules.get(dist) if (cls.module or dist) == dist else None
        found = getattr(mod, "__version__", None)
        return found if isinstance(found, str) and found else _distribution_version(dist)

    @classmethod
    def require(cls) -> None:
        """Raise :class:`SolverNotInstalledError` naming the package if it is missing."""
        if not cls.is_available():
            raise SolverNotInstalledError(
                f"solver {cls.name!r} needs the Python package {cls.distribution!r}: "
                f"pip install {cls.distribution}")

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        raise NotImplementedError


def check_capabilities(cls: type[Backend], problem: AssignmentProblem,
                       relax: str | None) -> None:
    """Raise :class:`SolverCapabilityError` when ``cls``'s flags rule the request out."""
    if relax == "lp" and not cls.lp:
        raise SolverCapabilityError(f"solver {cls.name!r} cannot solve LP relaxations")
    if relax is None and not cls.integer:
        raise SolverCapabilityError(f"solver {cls.name!r} solves LP relaxations only; "
                                    "pass relax='lp'")
    if cls.max_ndim is not None and problem.ndim > cls.max_ndim:
        raise SolverCapabilityError(
            f"solver {cls.name!r} handles problems of at most {cls.max_ndim} axes, "
            f"this one has {problem.ndim}")


def empty_answer(problem: AssignmentProblem, options: SolveOptions,
                 name: str = "") -> RawResult | None:
    """The answer when there is nothing to cover (no real index, so no candidate):
    the empty selection, optimal.  None for any other problem.  Back ends whose
    solver refuses an empty model return this first."""
    if problem.n_rows:
        return None
    return RawResult(Status.OPTIMAL, selected=np.zeros(0, np.int64),
                     x=np.zeros(problem.n_candidates) if options.relax else None,
                     bound=0.0, objective=0.0,
                     message=f"{name}: empty problem" if name else "empty problem")


_REGISTRY: dict[str, type[Backend]] = {}
#: Back ends known by name whose module has not been imported yet: name -> module.
#: :func:`get_backend` imports the one module asked for, :func:`registered` all of
#: them, so ``import assocopt`` and a solve load only the chosen back end's code.
_DECLARED: dict[str, str] = {}


def declare(name: str, module: str) -> None:
    """Make back end ``name`` known without importing ``module`` (which registers it)."""
    if name not in _REGISTRY:
        _DECLARED[name] = module


def register(cls: type[Backend]) -> type[Backend]:
    """Class decorator: add a back end to the registry under ``cls.name``."""
    if not cls.name:
        raise ValueError("a back end needs a name")
    _REGISTRY[cls.name] = cls
    _DECLARED.pop(cls.name, None)
    return cls


def _load(name: str) -> None:
    """Import the module of a declared back end (registering it)."""
    module = _DECLARED.get(name)
    if module is not None:
        importlib.import_module(module)
        _DECLARED.pop(name, None)     # a module that did not register it: unknown


def _load_all() -> None:
    for name in list(_DECLARED):
        _load(name)


def names() -> list[str]:
    """Names of all back ends, registered or declared, without importing any."""
    return sorted(set(_REGISTRY) | set(_DECLARED))


def registered() -> dict[str, type[Backend]]:
    """All registered back ends by name, installed or not (imports their modules,
    which import no optional package)."""
    _load_all()
    return dict(_REGISTRY)


def get_backend(name: str) -> type[Backend]:
    """The back end class called ``name``; unknown names list the valid ones."""
    if name not in _REGISTRY and isinstance(name, str):
        _load(name)
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        valid = ", ".join(names() + ["auto"])
        raise UnknownSolverError(f"unknown solver {name!r}; valid names: {valid}") from None


def available() -> list[str]:
    """Names of the back ends whose packages are installed."""
    return sorted(n for n, cls in registered().items() if cls.is_available())


def _md(text: str) -> str:
    return text.replace("|", "\\|")


def options_page() -> str:
    """The Markdown page ``docs/solver-options.md``, generated from the declarations."""
    lines = ["# Back-end options", "",
             "Generated from the back ends' declared options by",
             "`python -m assocopt solvers --options all --markdown > "
             "docs/solver-options.md`;",
             "`tests/test_options.py` checks that this page matches them.  Every back "
             "end also takes the",
             "common options below; an unknown option is an error that lists the "
             "valid ones.", "",
             "## Common options (every back end)", "",
             "| option | accepts | default | description |", "|---|---|---|---|"]
    lines += [f"| `{o.name}` | {_md(o.describe())} | `{o.default_text()}` | {_md(o.doc)} |"
              for o in COMMON_OPTIONS]
    for name, cls in sorted(registered().items()):
        lines += ["", f"## `{name}`", ""]
        if cls.options:
            lines += ["| option | accepts | default | description |", "|---|---|---|---|"]
            lines += [f"| `{n}` | {_md(a)} | `{_md(d)}` | {_md(doc)} |"
                      for n, a, d, doc in options_table(cls)]
        else:
            lines.append("No options of its own.")
        if cls.native_options:
            lines += ["", f"Also accepts {cls.native_options}, passed through by name."]
    return "\n".join(lines) + "\n"
