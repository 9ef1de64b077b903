"""CVXPY modelling layer over any installed LP/MIP solver.

The model is one vectorised expression: ``x = Variable(K, boolean=True)`` (or
``bounds=[0, 1]`` for the LP relaxation), ``A @ x == 1`` with the scipy CSR matrix,
``minimize c @ x``.  Compilation (``get_problem_data``) and the solver call
(``solve_via_data``) are run separately so that build and solve times are honest:
``build_time`` covers assocopt's CSR model, the CVXPY expression and CVXPY's
canonicalisation; ``solve_time`` the solver call and unpacking its result.

Extra options:

``cvxpy_solver``    CVXPY solver name.  Default for the ILP: the first installed of
                    HIGHS, SCIP, GLPK_MI, CBC, SCIPY, GUROBI, CPLEX, XPRESS, MOSEK; for
                    the LP: the first of HIGHS, CLARABEL, SCIPY, GLOP, GUROBI, CPLEX,
                    MOSEK, XPRESS, PDLP, SCS.  Recorded in ``info["cvxpy_solver"]``.
``solver_options``  dict of solver keyword options passed to CVXPY, merged over the
                    limits assocopt sets (nested dicts such as ``scipy_options`` or
                    ``scip_params`` are merged key by key).

``time_limit``, ``mip_gap`` and ``threads`` are translated for HIGHS, SCIPY, SCIP,
GUROBI, CPLEX and MOSEK (time limit also CLARABEL, GLOP, PDLP, SCS); for other
solvers they are not passed, which ``info["limits_passed"]`` records.  The gap is
always passed to the solvers that take it (HiGHS, Gurobi, CPLEX and MOSEK default
to 1e-4, not 0).  A reached gap is known for HIGHS and SCIPY (they report a bound);
with another solver and ``mip_gap > 0`` a solution is FEASIBLE, never OPTIMAL.
"""

from __future__ import annotations

import dataclasses
import time
import warnings
from typing import Any

import numpy as np

from ...runtime.errors import InvalidProblemError, SolverCapabilityError, SolverNotInstalledError
from ...model.formulation import LinearModel
from ...problems.problem import AssignmentProblem
from ...model.solution import Status, relative_gap
from ..base import Backend, Option, RawResult, SolveOptions, register, remaining
from ..interruptible import run_cancellable
from .answer import opening, built_model, note_isolated, take_point
from .limited import ISOLATE, solve_isolated_or_here
from ..status import from_table, settle_optimal

__all__ = ["CvxpyBackend"]

_MIP_ORDER = ("HIGHS", "SCIP", "GLPK_MI", "CBC", "SCIPY", "GUROBI", "CPLEX", "XPRESS", "MOSEK")
_LP_ORDER = ("HIGHS", "CLARABEL", "SCIPY", "GLOP", "GUROBI", "CPLEX", "MOSEK", "XPRESS",
             "PDLP", "SCS")

# CVXPY status -> assocopt status.  OPTIMAL_INACCURATE is what several interfaces
# return when a limit stopped the solver with a solution (SCIP, CBC, SCIPY), or for
# reduced accuracy (interior point): refined in ``_status``.  Variables are bounded,
# so "unbounded" can only come from numerical failure.
_STATUS_TABLE: dict[str, Status] = {
    "optimal": Status.OPTIMAL,
    "optimal_inaccurate": Status.FEASIBLE,
    "infeasible": Status.INFEASIBLE,
    "infeasible_inaccurate": Status.INFEASIBLE,
    "infeasible_or_unbounded": Status.INFEASIBLE,
    "unbounded": Status.ERROR,
    "unbounded_inaccurate": Status.ERROR,
    "user_limit": Status.TIME_LIMIT,
    "solver_error": Status.ERROR,
}
#: Solvers whose OPTIMAL_INACCURATE always means "stopped by a time/iteration limit".
_INACCURATE_IS_LIMIT = ("SCIPY",)
#: CVXPY 1.9 interfaces that fail on any variable bounds (even ``nonneg``): the LP
#: uses ``0 <= x <= 1`` constraint rows instead.
_NO_VARIABLE_BOUNDS = ("PDLP",)


def _limit_options(solver: str, options: SolveOptions,
                   is_mip: bool) -> tuple[dict[str, Any], list[str]]:
    """CVXPY keyword options for the time limit, gap and threads of ``solver``."""
    t, gap, n = options.time_limit, float(options.mip_gap), options.threads
    opts: dict[str, Any] = {}
    nested: dict[str, Any] = {}

    def put(limit: str, target: dict[str, Any], key: str, value: Any) -> None:
        if value is not None:
            target[key] = value
            passed.append(limit)

    passed: list[str] = []
    gap_ = gap if is_mip else None
    if solver == "HIGHS":
        put("time_limit", opts, "time_limit", None if t is None else float(t))
        if t is not None:       # HiGHS presolve ignores the clock (assocopt.solvers.milp.highs)
            opts["presolve"] = "off"
        put("mip_gap", opts, "mip_rel_gap", gap_)
        put("threads", opts, "threads", n)
    elif solver == "SCIPY":
        opts["scipy_options"] = nested
        put("time_limit", nested, "time_limit", None if t is None else float(t))
        if t is not None:
            nested["presolve"] = False
        put("mip_gap", nested, "mip_rel_gap", gap_)
    elif solver == "SCIP":
        opts["scip_params"] = nested
        put("time_limit", nested, "limits/time", None if t is None else float(t))
        put("mip_gap", nested, "limits/gap", gap_)
    elif solver == "GUROBI":
        put("time_limit", opts, "TimeLimit", t)
        put("mip_gap", opts, "MIPGap", gap_)
        put("threads", opts, "Threads", n)
    elif solver == "CPLEX":
        opts["cplex_params"] = nested
        put("time_limit", nested, "timelimit", t)
        put("mip_gap", nested, "mip.tolerances.mipgap", gap_)
        put("threads", nested, "threads", n)
    elif solver == "MOSEK":
        opts["mosek_params"] = nested
        put("time_limit", nested, "MSK_DPAR_OPTIMIZER_MAX_TIME", t)
        put("mip_gap", nested, "MSK_DPAR_MIO_TOL_REL_GAP", gap_)
        put("threads", nested, "MSK_IPAR_NUM_THREADS", n)
    elif solver == "CLARABEL":
        put("time_limit", opts, "time_limit", t)
    elif solver in ("GLOP", "PDLP"):
        put("time_limit", opts, "time_limit_sec", t)
    elif solver == "SCS":
        put("time_limit", opts, "time_limit_secs", t)
    return opts, passed


def _merge(base: dict[str, Any], user: dict[str, Any]) -> dict[str, Any]:
    """``base`` updated by ``user``, merging one level of nested dicts."""
    out = dict(base)
    for key, value in user.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = {**out[key], **value}
        else:
            out[key] = value
    return out


def _choose_solver(requested: Any, is_mip: bool, installed: list[str]) -> str:
    """The CVXPY solver to use: the requested one (checked) or the first installed."""
    try:
        from cvxpy.reductions.solvers.defines import MI_SOLVERS
    except ImportError:                    # layout changed: let CVXPY itself refuse
        MI_SOLVERS = installed
    order = _MIP_ORDER if is_mip else _LP_ORDER
    if requested is None:
        for name in order:
            if name in installed:
                return name
        raise SolverNotInstalledError(
            f"cvxpy has no {'MIP' if is_mip else 'LP'} solver installed; install one of "
            f"{', '.join(order)} (e.g. pip install highspy)")
    name = requested.upper()
    if name not in installed:
        raise SolverNotInstalledError(
            f"cvxpy solver {requested!r} is not installed; installed: {', '.join(installed)}")
    if is_mip and name not in MI_SOLVERS:
        raise SolverCapabilityError(
            f"cvxpy solver {name} cannot solve integer programs; use relax='lp' or one of "
            f"{', '.join(n for n in _MIP_ORDER if n in installed)}")
    return name


@register
class CvxpyBackend(Backend):
    """CVXPY, one vectorised constraint ``A @ x == 1``, solved by any installed solver."""

    name = "cvxpy"
    module = "cvxpy"
    imports = ("cvxpy", "scipy.sparse")
    distribution = "cvxpy"
    description = "CVXPY model (boolean x, A @ x == 1) on HiGHS or another installed solver"
    lp = True
    supports_time_limit = True
    options = (
        Option("cvxpy_solver", "str", None, "CVXPY solver name (None: the first installed "
               "of HIGHS, SCIP, ... for the ILP; HIGHS, CLARABEL, ... for the LP)",
               nullable=True),
        Option("solver_options", "dict", {}, "solver keyword options passed to CVXPY, "
               "merged over the limits assocopt sets"),
        ISOLATE,
    )

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        is_mip = options.relax is None
        extra, isolate, empty = opening(self, problem, options)
        if empty is not None:
            return empty
        model, t0, start = built_model(problem, options)
        t_model = time.perf_counter()
        args = (model, extra["cvxpy_solver"], dict(extra["solver_options"]),
                dataclasses.replace(options, extra={}, parsed=True))
        # killed at the limit: all counts as solving (CVXPY's compilation is in the child)
        out = solve_isolated_or_here(self.name, run_model, args, options, isolate,
                                     start, t0, t0)
        if isinstance(out, RawResult):
            return out
        info: dict[str, Any] = note_isolated({"cvxpy_solver": out["solver"],
                                              "limits_passed": out["limits_passed"]}, out)
        solver, build, solve_time = out["solver"], out["build_time"], out["solve_time"]
        build += t_model - t0                  # assocopt's CSR model, then CVXPY's
        if "solver_error" in out:
            # SCIPY (and others) report "no solution" as an error when the limit hits.
            if options.time_limit is not None and solve_time >= options.time_limit:
                return RawResult(Status.TIME_LIMIT, info=info, build_time=build,
                                 solve_time=solve_time,
                                 message=f"cvxpy/{solver}: no solution within the time "
                                         f"limit ({out['solver_error']})")
            return RawResult(Status.ERROR, message=f"cvxpy/{solver}: {out['solver_error']}",
                             info=info, build_time=build, solve_time=solve_time)
        native = out["status"]
        info["cvxpy_status"] = native
        result = RawResult(Status.ERROR, info=info, build_time=build, solve_time=solve_time)
        values, objective, bound = out["x"], None, None
        if values is not None and native in ("optimal", "optimal_inaccurate", "user_limit"):
            objective = out["objective"]
            take_point(result, values, objective, is_mip)
            if is_mip:
                # A limit-stopped solver may hand back a non-incumbent point: keep
                # only a selection that is a feasible assignment.
                if native != "optimal" and problem.violations(result.selected) is not None:
                    result.selected = None
                bound = result.bound = out["bound"]
        result.status, note = self._status(native, solver, objective, bound, options,
                                           is_mip, solve_time)
        result.message = f"cvxpy/{solver}: {native}" + (f"; {note}" if note else "")
        return result

    @staticmethod
    def _bound(prob: Any) -> float | None:
        """The MIP dual bound that HIGHS and SCIPY report through ``extra_stats``."""
        stats = getattr(prob.solver_stats, "extra_stats", None)
        if stats is None:
            return None
        value = stats.get("mip_dual_bound") if isinstance(stats, dict) else \
            getattr(stats, "mip_dual_bound", None)
        try:
            value = float(value)
        except (TypeError, ValueError):
            return None
        return value if np.isfinite(value) else None

    @staticmethod
    def _status(native: str, solver: str, objective: float | None, bound: float | None,
                options: SolveOptions, is_mip: bool, elapsed: float) -> tuple[Status, str]:
        """Map ``native`` through ``_STATUS_TABLE`` and refine it."""
        status = from_table(_STATUS_TABLE, native)
        limit_elapsed = options.time_limit is not None and elapsed >= options.time_limit
        if native == "optimal_inaccurate" and (solver in _INACCURATE_IS_LIMIT or limit_elapsed):
            return Status.TIME_LIMIT, "stopped by a limit"
        if native == "infeasible_inaccurate":
            return status, "infeasibility reported with reduced accuracy"
        if native not in _STATUS_TABLE:
            return Status.ERROR, f"unexpected CVXPY status {native!r}"
        return settle_optimal(status, relative_gap(objective, bound),
                              options.mip_gap if is_mip else 0.0)


def run_model(model: LinearModel, requested: str | None, user_opts: dict[str, Any],
              options: SolveOptions, *, time_limit: float | None = None) -> dict[str, Any]:
    """CVXPY's model of ``model`` compiled and solved in this process (the solver call in
    a worker thread, so that Ctrl-C takes effect at once, see :mod:`.interruptible`);
    what the result needs as plain values (the same in a worker process, :mod:`.limited`).
    ``time_limit`` counts from the call; the solver gets what compilation left of it."""
    import cvxpy as cp

    t0 = time.perf_counter()
    if time_limit is not None:
        options = dataclasses.replace(options, time_limit=time_limit)
    is_mip = options.relax is None
    solver = _choose_solver(requested, is_mip, cp.installed_solvers())
    limit_opts, passed = _limit_options(solver, options, is_mip)
    solver_opts = _merge(limit_opts, user_opts)
    out: dict[str, Any] = {"solver": solver, "limits_passed": passed,
                           "build_time": 0.0, "solve_time": 0.0}
    K = model.shape[1]
    constraints: list[Any] = []
    if is_mip:
        x = cp.Variable(K, boolean=True)
    elif solver in _NO_VARIABLE_BOUNDS:
        x = cp.Variable(K)
        constraints += [x >= 0, x <= 1]
    else:                  # column bounds, not K extra rows, where the solver takes them
        x = cp.Variable(K, bounds=[0.0, 1.0])
    constraints.append(model.A @ x == 1)
    prob = cp.Problem(cp.Minimize(model.c @ x), constraints)
    t1: float | None = None
    try:
        with warnings.catch_warnings():
            if not options.verbose:
                warnings.simplefilter("ignore")
            data, chain, inverse = prob.get_problem_data(
                solver=solver, verbose=bool(options.verbose), solver_opts=solver_opts)
            t1 = time.perf_counter()
            # the solver gets what is left of the limit after CVXPY's compilation
            limit_opts, out["limits_passed"] = _limit_options(
                solver, remaining(options, t0), is_mip)
            solver_opts = _merge(limit_opts, user_opts)
            raw, _ = run_cancellable(chain.solve_via_data, (prob, data), None, kwargs=dict(
                warm_start=False, verbose=bool(options.verbose), solver_opts=solver_opts))
            prob.unpack_results(raw, chain, inverse)
    except cp.error.SolverError as exc:      # includes CVXPY's "solver_error" status
        t2 = time.perf_counter()
        t1 = t2 if t1 is None else t1
        out.update(solver_error=str(exc), build_time=t1 - t0, solve_time=t2 - t1)
        return out
    except (ValueError, TypeError) as exc:
        if user_opts:                         # most likely a rejected solver option
            raise InvalidProblemError(
                f"cvxpy/{solver} rejected solver_options {user_opts!r}: {exc}") from exc
        raise
    t2 = time.perf_counter()
    values = x.value
    out.update(build_time=t1 - t0, solve_time=t2 - t1, status=str(prob.status),
               x=None if values is None else np.asarray(values, np.float64).ravel(),
               objective=None if prob.value is None or values is None else float(prob.value),
               bound=CvxpyBackend._bound(prob) if is_mip else None)
    return out
