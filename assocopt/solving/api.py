"""``solve``: one entry point for every problem, formulation and back end."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..runtime.errors import InvalidProblemError
from ..problems.problem import AssignmentProblem, index_label
from ..model.solution import Solution, Status
from ..solvers.base import (Backend, RawResult, SolveOptions, check_capabilities,
                            empty_answer, get_backend, import_missing, module_installed)
from ..solvers.kernels import spent
from ..solvers.scaling import solve_in_range
from .choice import BNB_MAX_CANDIDATES, choose_solver

__all__ = ["solve", "choose_solver", "BNB_MAX_CANDIDATES"]


def solve(problem: AssignmentProblem, solver: str = "auto", *, relax: str | None = None,
          time_limit: float | None = None, mip_gap: float = 0.0,
          threads: int | None = None, verbose: bool = False,
          decompose: bool | None = None, **options: Any) -> Solution:
    """Solve ``problem`` with the back end ``solver``.

    Parameters
    ----------
    problem : AssignmentProblem
    solver : str
        A name from :func:`assocopt.solvers.available` or ``"auto"``.
    relax : None or "lp"
        ``"lp"`` solves the LP relaxation: ``objective`` is the LP optimum (a lower
        bound on the ILP), ``x`` the fractional solution, ``integral`` whether it
        happens to be integral (then ``tuples`` is filled too).
    time_limit : float, optional
        Seconds, for back ends that support a limit.
    mip_gap : float
        Relative gap at which MIP back ends may stop (default 0: proven optimum).
    threads : int, optional
        Threads for back ends that use them.
    decompose : bool or None
        Solve an S-D problem (N >= 3, integral, ``mip_gap`` 0) by its connected
        components (:mod:`assocopt.solving.decompose`): ``None`` (default) for problems of at
        least :data:`assocopt.solving.decompose.MIN_CANDIDATES` candidates, ``True`` always,
        ``False`` never.  ``Solution.info["decomposition"]`` says how many there were.
    **options
        Back-end specific options, declared by each back end (``assocopt solvers
        --options NAME``, docs/solver-options.md); an unknown one is an error.  The
        parsed values, defaults included, are in ``Solution.info["options"]``.

    Returns
    -------
    Solution

    Examples
    --------
    >>> import numpy as np
    >>> from assocopt import AssignmentProblem, solve
    >>> sol = solve(AssignmentProblem.dense([[4.0, 1.0], [2.0, 3.0]]), solver="highs")
    >>> sol.status.value, sol.objective, sol.assignment()
    ('optimal', 3.0, (array([0, 1]), array([1, 0])))
    """
    t0 = time.perf_counter()
    if not isinstance(problem, AssignmentProblem):
        raise InvalidProblemError(
            f"problem must be an AssignmentProblem, got {type(problem).__name__}")
    if (solver == "auto" or solver == "scipy-lsa") and problem._dense is not None and \
            not options and relax is None and time_limit is None and threads is None \
            and verbose is False and type(mip_gap) is float and mip_gap == 0.0:
        direct = _DIRECT or _direct_path()
        sol = direct(problem, problem._dense, t0)   # no dispatch, one pass
        if sol is not None:
            if direct is not _DIRECT_SEEN[0]:        # the first: scipy was imported
                _DIRECT_SEEN[0] = direct
                sol.times["import"] = _DIRECT_IMPORT[0]
            return sol
    if relax is not None and relax != "lp":
        raise InvalidProblemError(f"relax must be None or 'lp', got {relax!r}")
    name = choose_solver(problem, relax) if solver == "auto" else solver
    backend_cls = get_backend(name)
    check_capabilities(backend_cls, problem, relax)
    if backend_cls.module is not None and not module_installed(backend_cls.module):
        backend_cls.require()        # cached lookup first: a scan's solve is microseconds
    parsed = backend_cls.parse_options(options)
    imported = import_missing(backend_cls.imports_for(problem)) if backend_cls.imports \
        else 0.0
    if time_limit is None and threads is None and verbose is False and \
            type(mip_gap) is float and mip_gap == 0.0:
        opts = SolveOptions.parsed_defaults(relax, parsed)    # nothing to check
    else:       # SolveOptions checks the common options (the one place that does)
        opts = SolveOptions(relax=relax, time_limit=time_limit, mip_gap=mip_gap,
                            threads=threads, verbose=verbose, extra=parsed, parsed=True)

    if problem.n_uncovered:
        raw = _uncovered_answer(problem)
    elif problem.n_rows == 0:
        raw = empty_answer(problem, opts)
    else:
        k0 = spent()
        raw = None
        if decompose is not False and _decomposable(problem, opts):
            from .decompose import solve_decomposed
            raw = solve_decomposed(problem, solver if not options else name, name, opts,
                                   decompose)
        if raw is None:
            raw = solve_in_range(backend_cls(), problem, opts)
        k1 = spent()
        if k1 != k0:
            _kernel_times(raw, k0, k1)
    sol = _finalise(problem, backend_cls, raw, relax)
    sol.info.setdefault("options", parsed)
    if imported:
        sol.times["import"] = imported
    sol.times["total"] = time.perf_counter() - t0
    return sol


def _decomposable(problem: AssignmentProblem, opts: SolveOptions) -> bool:
    """Whether :mod:`assocopt.solving.decompose` applies: an S-D ILP solved to optimality
    (component gaps do not add up to a relative gap) with costs in range."""
    if problem.ndim < 3 or opts.relax is not None or opts.mip_gap != 0.0:
        return False
    from ..solvers.scaling import SCALE_ABOVE, max_abs_cost
    return max_abs_cost(problem) <= SCALE_ABOVE


_DIRECT = None
#: The seconds the direct path's import took, and the function once a solve has
#: reported them (as ``times["import"]``: scipy's import is no solve time).
_DIRECT_IMPORT = [0.0]
_DIRECT_SEEN: list[Any] = [None]


def _direct_path():
    """:func:`assocopt.solvers.twod.direct.solve_direct`, imported on first use (it loads
    scipy, which ``import assocopt`` does not)."""
    global _DIRECT
    if _DIRECT is None:
        t = time.perf_counter()
        from ..solvers.twod.direct import solve_direct
        _DIRECT_IMPORT[0] = time.perf_counter() - t
        _DIRECT = solve_direct
    return _DIRECT


def _uncovered_answer(problem: AssignmentProblem) -> RawResult:
    """The infeasible answer of a problem with real indices no candidate covers."""
    n_missing = problem.n_uncovered
    missing = problem.uncovered(limit=20)
    a, i = missing[0]
    more = f" (and {n_missing - 1} more)" if n_missing > 1 else ""
    return RawResult(Status.INFEASIBLE,
                     message=f"infeasible: {index_label(a, i)} is covered by no "
                             f"candidate{more}",
                     info={"uncovered": missing})


def _kernel_times(raw: RawResult, before: tuple[float, float],
                  after: tuple[float, float]) -> None:
    """Record the numba compilation / disk-cache loading done during a solve (the
    back ends leave it out of their build and solve times) as ``compile_time`` and
    ``cache_load_time`` in ``raw.info``; the Solution shows them in ``times``."""
    compiled, loaded = (a - b for a, b in zip(after, before))
    if compiled > 0 or loaded > 0:
        raw.info = dict(raw.info, compile_time=compiled, cache_load_time=loaded)


_INTEGRAL_TOL = 1e-6


def _finalise(problem: AssignmentProblem, cls: type[Backend], raw: RawResult,
              relax: str | None) -> Solution:
    """Common post-processing: never trust a back end's claim without checking it."""
    ran = get_backend(raw.solver) if raw.solver and raw.solver != cls.name else cls
    sol = Solution(status=raw.status, bound=raw.bound, solver=ran.name,
                   solver_version=ran.version(), relaxation=relax,
                   message=raw.message, info=dict(raw.info),
                   times={"build": raw.build_time, "solve": raw.solve_time})
    for key, name in (("compile_time", "compile"), ("cache_load_time", "cache_load")):
        if key in raw.info:
            sol.times[name] = raw.info[key]
    tuples = None
    if relax == "lp":
        _finalise_lp(problem, raw, sol)
    elif raw.col_of_row is not None:
        checked = problem.dense_view.check(raw.col_of_row)
        if isinstance(checked, str):
            return _infeasible_answer(problem, sol, checked)
        sol.selected, sol.objective, tuples = checked.selected, checked.objective, \
            checked.tuples
    elif raw.selected is not None:
        sel = np.sort(np.asarray(raw.selected, dtype=np.int64))
        why = problem.violations(sel)
        if why is not None:
            return _infeasible_answer(problem, sol, why)
        sol.selected = sel
        sol.objective = problem.objective_of(sel)
    if sol.objective is not None and sol.bound is not None and sol.bound > sol.objective:
        sol.bound = sol.objective   # tolerance noise: a lower bound never exceeds the optimum
    if sol.status is Status.OPTIMAL and sol.bound is None and ran.exact:
        sol.bound = sol.objective
    if sol.selected is not None:
        sol.tuples = tuples if tuples is not None else \
            problem.tuples[sol.selected[~problem.slack[sol.selected]]].copy()
    if problem.maximize:
        to_user_sense(sol)
    return sol


def to_user_sense(sol: Solution) -> Solution:
    """Report a maximisation problem's solution in the user's sense: the problem stores
    negated scores, so objective and bound change sign (the bound becomes an upper one)."""
    sol.maximize = True
    if sol.objective is not None:
        sol.objective = -sol.objective
    if sol.bound is not None:
        sol.bound = -sol.bound
    return sol


def _infeasible_answer(problem: AssignmentProblem, sol: Solution, why: str) -> Solution:
    sol.status = Status.ERROR
    sol.message = f"back end returned an infeasible assignment: {why}"
    return to_user_sense(sol) if problem.maximize else sol


def _finalise_lp(problem: AssignmentProblem, raw: RawResult, sol: Solution) -> None:
    if raw.x is None:
        return
    x = np.clip(np.asarray(raw.x, dtype=np.float64), 0.0, 1.0)
    sol.x = x
    sol.objective = float(problem.costs @ x)
    if raw.status is Status.OPTIMAL:
        sol.bound = sol.objective
    frac = np.abs(x - np.round(x))
    sol.integral = bool(frac.max(initial=0.0) <= _INTEGRAL_TOL)
    if sol.integral:
        sel = np.flatnonzero(x > 0.5)
        if problem.violations(sel) is None:
            sol.selected = sel
            sol.objective = problem.objective_of(sel)
