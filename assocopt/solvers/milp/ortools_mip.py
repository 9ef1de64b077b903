"""OR-Tools ``model_builder``: SCIP (or another MIP solver) for the ILP, GLOP for the LP.

The CSR model of :mod:`assocopt.model.formulation` goes into the model in one
``fill_model_from_sparse_data`` call (bounds, costs, row bounds and the matrix from
numpy), and the solution comes back as one numpy array (``variable_values``).  We
use the two pybind helpers of ``ortools.linear_solver.python.model_builder``
(``ModelBuilderHelper`` / ``ModelSolverHelper``) directly because the pandas
wrapper ``model_builder.Solver.values`` reads values one variable at a time.

Extra options:

``backend``     underlying solver, as OR-Tools names it.  ILP: ``"scip"`` (default),
                ``"cbc"``, ``"highs"``, ``"sat"``, ``"gurobi"``, ``"xpress"``.  LP:
                ``"glop"`` (default), ``"pdlp"``, ``"clp"``, ``"highs"``, ``"scip"``,
                ``"gurobi"``, ``"xpress"``.  One this OR-Tools build lacks raises
                :class:`~assocopt.runtime.errors.SolverNotInstalledError` (CBC and CLP are not in
                the 9.15 wheels).  PDLP is a first-order method: its LP optimum is
                accurate to about 1e-6 relative, not to simplex precision.
``parameters``  solver-specific parameter text appended to what assocopt sets
                (SCIP ``"limits/nodes = 100"``, SAT/GLOP/PDLP text protos, HiGHS
                ``"name = value"``).  Text the solver rejects raises InvalidProblemError.
"""

from __future__ import annotations

import contextlib
import ctypes
import dataclasses
import math
import os
import sys
import time
from typing import Any, Iterator

import numpy as np

from ...runtime.errors import InvalidProblemError, SolverNotInstalledError
from ...model.formulation import LinearModel
from ...problems.problem import AssignmentProblem
from ...model.solution import Status, relative_gap
from ..base import Backend, Option, RawResult, SolveOptions, register, remaining
from ..interruptible import run_cancellable
from .answer import built_model, note_isolated, take_point
from .limited import ISOLATE, solve_isolated_or_here
from ..status import from_table, settle_optimal

__all__ = ["OrtoolsMipBackend", "run_model"]

_MIP_BACKENDS = ("scip", "cbc", "highs", "sat", "gurobi", "xpress")
_LP_BACKENDS = ("glop", "pdlp", "clp", "highs", "scip", "gurobi", "xpress")

# How each back end takes a relative MIP gap and a thread count in its
# solver-specific parameter text, and how entries are separated.  None: not passed.
# The gap is always passed where possible: HiGHS and Gurobi default to 1e-4.
_PARAM_FORMAT: dict[str, tuple[str | None, str | None, str]] = {
    "scip": ("limits/gap = {}", None, "\n"),       # SCIP's tree search is sequential
    "sat": ("relative_gap_limit: {}", "num_workers: {}", " "),
    "highs": ("mip_rel_gap = {}", None, "\n"),     # HiGHS threads are process-global
    "gurobi": ("MIPGap {}", "Threads {}", "\n"),
    "pdlp": (None, "num_threads: {}", " "),
}

# Native SolveStatus name -> assocopt status, refined in ``_status``: OPTIMAL with a
# reached gap, FEASIBLE (stopped early: a limit, or the gap tolerance), and the
# "no result" statuses, which count as a time limit when the limit has elapsed.
_STATUS_TABLE: dict[str, Status] = {
    "OPTIMAL": Status.OPTIMAL,
    "FEASIBLE": Status.TIME_LIMIT,
    "INFEASIBLE": Status.INFEASIBLE,
    "UNBOUNDED": Status.ERROR,              # all variables are bounded: cannot happen
    "CANCELLED_BY_USER": Status.TIME_LIMIT,
    "NOT_SOLVED": Status.ERROR,
    "UNKNOWN_STATUS": Status.ERROR,
    "ABNORMAL": Status.ERROR,
    "MODEL_IS_VALID": Status.ERROR,
    "MODEL_INVALID": Status.ERROR,
    "INVALID_SOLVER_PARAMETERS": Status.ERROR,
    "SOLVER_TYPE_UNAVAILABLE": Status.ERROR,
    "INCOMPATIBLE_OPTIONS": Status.ERROR,
}
_NO_RESULT = ("NOT_SOLVED", "UNKNOWN_STATUS", "ABNORMAL")
#: A solver claiming OPTIMAL while its own bound is further than this is FEASIBLE
#: (CP-SAT through model_builder rounds float costs and can do that).
_CLAIM_TOL = 1e-6


@contextlib.contextmanager
def _silenced(active: bool) -> Iterator[None]:
    """Send file descriptors 1 and 2 to /dev/null while active.

    Some native solvers print regardless of ``enable_output(False)`` (the HiGHS
    banner, absl warnings when Gurobi's library is looked for), so quiet runs
    silence the process-level streams for the duration of the call.
    """
    if not active:
        yield
        return
    try:
        libc: Any = ctypes.CDLL(None)
    except OSError:                # no C runtime handle (Windows): skip the flush
        libc = None
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
    finally:
        if libc is not None:
            libc.fflush(None)      # drop what C stdio buffered while silenced
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, devnull):
            os.close(fd)


def _parameter_text(backend: str, options: SolveOptions, is_mip: bool,
                    user_text: str) -> tuple[str, dict[str, bool]]:
    """Solver-specific parameter text for the gap and threads, plus the user's text."""
    gap_fmt, threads_fmt, sep = _PARAM_FORMAT.get(backend, (None, None, "\n"))
    parts: list[str] = []
    passed = {"mip_gap": False, "threads": False}
    if is_mip and gap_fmt is not None:
        parts.append(gap_fmt.format(repr(float(options.mip_gap))))
        passed["mip_gap"] = True
    if options.threads is not None and threads_fmt is not None:
        parts.append(threads_fmt.format(int(options.threads)))
        passed["threads"] = True
    if user_text:
        parts.append(user_text)
    return sep.join(parts), passed


def run_model(model: LinearModel, backend: str, text: str, options: SolveOptions, *,
              time_limit: float | None = None) -> dict[str, Any]:
    """Solve ``model`` with OR-Tools' ``backend`` (parameter text ``text``) in this
    process; what the result needs, as plain values (the same in a worker process,
    :mod:`.limited`).  ``time_limit`` replaces the options' limit (what is left)."""
    from ortools.linear_solver.python import model_builder_helper as mbh

    t0 = time.perf_counter()
    if time_limit is not None:
        options = dataclasses.replace(options, time_limit=time_limit)
    with _silenced(not options.verbose):      # Gurobi/Xpress look-ups log to stderr
        solver = mbh.ModelSolverHelper(backend)
    helper = mbh.ModelBuilderHelper()
    helper.fill_model_from_sparse_data(model.lb, model.ub, model.c, model.row_lower,
                                       model.row_upper, model.A)
    if model.is_mip:
        # fill_model_from_sparse_data makes continuous variables and 9.15 has no
        # bulk integrality setter; add_var_array_with_bounds has one but then the
        # rows need one Python Variable object per nonzero.  Measured, K = 27 000 /
        # 1 000 000: this loop 16 ms / 0.44 s, the fill itself 9 ms / 0.30 s.
        for k in range(model.shape[1]):
            helper.set_var_integrality(k, True)
    solver.enable_output(bool(options.verbose))
    if options.time_limit is not None:       # what is left after filling the model
        solver.set_time_limit_in_seconds(float(remaining(options, t0).time_limit))
    if text:
        solver.set_solver_specific_parameters(text)
    t1 = time.perf_counter()
    with _silenced(not options.verbose):
        # at the deadline the solve is interrupted from outside too: the solver's
        # own clock is not looked at in every phase (SCIP's presolve)
        _, by_clock = run_cancellable(solver.solve, (helper,), solver.interrupt_solve,
                                      deadline=None if options.time_limit is None
                                      else t0 + options.time_limit)
    t2 = time.perf_counter()
    detail = solver.status_string() if solver.has_response() else ""
    if "SCIP status code 10" in detail and not by_clock:
        raise KeyboardInterrupt           # SCIP_STATUS_USERINTERRUPT: SCIP caught Ctrl-C
    has = solver.has_solution()
    return {"status": solver.status().name, "detail": detail,
            "fill_time": t1 - t0, "solve_time": t2 - t1,
            "x": np.asarray(solver.variable_values(), dtype=np.float64) if has else None,
            "objective": float(solver.objective_value()) if has else math.nan,
            "bound": float(solver.best_objective_bound()) if has and model.is_mip
            else math.nan}


@register
class OrtoolsMipBackend(Backend):
    """OR-Tools model_builder: SCIP branch and cut for the ILP, GLOP simplex for the LP."""

    name = "ortools-mip"
    module = "ortools"
    imports = ("ortools.linear_solver.pywraplp", "scipy.sparse")
    distribution = "ortools"
    description = "OR-Tools model_builder (SCIP MIP / GLOP LP), model passed as one CSR matrix"
    lp = True
    supports_time_limit = True
    options = (
        Option("backend", "choice", None, "underlying solver as OR-Tools names it (None: "
               "scip for the ILP, glop for the LP)",
               choices=tuple(dict.fromkeys(_MIP_BACKENDS + _LP_BACKENDS)), nullable=True),
        Option("parameters", "str", "", "solver-specific parameter text appended to "
               "what assocopt sets"),
        ISOLATE,
    )

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        from ortools.linear_solver.python import model_builder_helper as mbh

        is_mip = options.relax is None
        extra = self.settings(problem, options)
        backend = extra["backend"] or ("scip" if is_mip else "glop")
        user_text = extra["parameters"]
        isolate = extra.get("isolate")
        allowed = _MIP_BACKENDS if is_mip else _LP_BACKENDS
        if backend not in allowed:
            raise InvalidProblemError(
                f"ortools-mip backend {backend!r} cannot solve the "
                f"{'ILP' if is_mip else 'LP relaxation'}; choose one of {list(allowed)}")

        with _silenced(not options.verbose):      # Gurobi/Xpress look-ups log to stderr
            solver = mbh.ModelSolverHelper(backend)
            supported = solver.solver_is_supported()
        if not supported:
            raise SolverNotInstalledError(
                f"ortools-mip backend {backend!r} is not available in this OR-Tools build "
                "(or its library is not installed)")

        model, t0, start = built_model(problem, options)
        text, passed = _parameter_text(backend, options, is_mip, user_text)
        sub = SolveOptions(relax=options.relax, time_limit=options.time_limit,
                           mip_gap=options.mip_gap, threads=options.threads,
                           verbose=options.verbose, parsed=True)
        t1 = time.perf_counter()
        out = solve_isolated_or_here(self.name, run_model, (model, backend, text, sub),
                                     options, isolate, start, t0, t1)
        if isinstance(out, RawResult):
            return out
        native, detail = out["status"], out["detail"]
        if native == "INVALID_SOLVER_PARAMETERS" and user_text:
            raise InvalidProblemError(
                f"ortools-mip backend {backend!r} rejected the parameters {user_text!r}: "
                f"{detail}")
        info: dict[str, Any] = {"ortools_status": native, "ortools_backend": backend,
                                "mip_gap_passed": passed["mip_gap"],
                                "threads_passed": passed["threads"]}
        result = RawResult(status=Status.ERROR, build_time=t1 - t0 + out["fill_time"],
                           solve_time=out["solve_time"], info=note_isolated(info, out))
        objective = bound = None
        if out["x"] is not None:
            objective = out["objective"]
            take_point(result, out["x"], objective, is_mip)
            if is_mip and np.isfinite(out["bound"]):
                bound = result.bound = out["bound"]
        # the limit counts from t0 (in a child too, where the model was filled again)
        result.status, note = self._status(native, objective, bound, options,
                                           time.perf_counter() - t0)
        result.message = f"OR-Tools {backend}: {native}" + (f" ({detail})" if detail else "")
        if note:
            result.message += f"; {note}"
        return result

    @staticmethod
    def _status(native: str, objective: float | None, bound: float | None,
                options: SolveOptions, elapsed: float) -> tuple[Status, str]:
        """Map ``native`` through ``_STATUS_TABLE`` and refine it (see the table)."""
        status = from_table(_STATUS_TABLE, native)
        limit_elapsed = options.time_limit is not None and elapsed >= options.time_limit
        if native in _NO_RESULT and limit_elapsed:
            return Status.TIME_LIMIT, "no solution within the time limit"
        gap = relative_gap(objective, bound)
        if native == "FEASIBLE" and options.mip_gap > 0 and gap is not None \
                and gap <= options.mip_gap and not limit_elapsed:
            return Status.FEASIBLE, f"stopped at relative gap {gap:.3g}"
        mip_gap = options.mip_gap if options.relax is None else 0.0
        return settle_optimal(status, gap, mip_gap, claim_tol=_CLAIM_TOL)
