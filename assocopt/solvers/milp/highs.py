"""HiGHS through highspy, directly (no scipy layer): the default exact back end.

The CSR model of :mod:`assocopt.model.formulation` is passed in one ``passModel`` call.
Extra keyword options are passed to HiGHS by name (``presolve="off"``,
``mip_heuristic_effort=0.1``...); an unknown HiGHS option is an error.
"""

from __future__ import annotations

import functools
import time
from typing import Any

import numpy as np

from ...runtime.errors import InvalidProblemError
from ...model.formulation import LinearModel
from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ..base import Backend, RawResult, SolveOptions, register
from .answer import opening, built_model, note_isolated, take_point
from .limited import ISOLATE, solve_isolated_or_here
from ..status import from_table, settle_optimal

__all__ = ["HighsBackend", "highs_from_model"]

#: HiGHS model status name -> assocopt status.  Variables are bounded, so
#: "unbounded or infeasible" means infeasible; every limit is a time limit.
_STATUS_TABLE: dict[str, Status] = {
    "kOptimal": Status.OPTIMAL,
    "kInfeasible": Status.INFEASIBLE,
    "kUnboundedOrInfeasible": Status.INFEASIBLE,
    "kTimeLimit": Status.TIME_LIMIT,
    "kIterationLimit": Status.TIME_LIMIT,
    "kSolutionLimit": Status.TIME_LIMIT,
    "kInterrupt": Status.TIME_LIMIT,
    "kHighsInterrupt": Status.TIME_LIMIT,
    "kObjectiveBound": Status.TIME_LIMIT,
    "kObjectiveTarget": Status.TIME_LIMIT,
}


@functools.lru_cache(maxsize=None)
def _highs_option_names() -> frozenset[str]:
    import highspy
    return frozenset(n for n in dir(highspy.HighsOptions()) if not n.startswith("_"))


def highs_from_model(model: LinearModel, options: SolveOptions | None = None) -> Any:
    """A ``highspy.Highs`` object holding ``model``, options applied, not yet run."""
    import highspy

    options = options or SolveOptions()
    h = highspy.Highs()
    h.setOptionValue("output_flag", bool(options.verbose))
    if options.time_limit is not None:
        h.setOptionValue("time_limit", float(options.time_limit))
        # HiGHS presolve does not look at the clock (Grundel n = 50: 11 s under a 0.5 s
        # limit, every presolve rule off or not): with a limit it is off unless asked for.
        h.setOptionValue("presolve", "off")
    h.setOptionValue("mip_rel_gap", float(options.mip_gap))
    if options.threads is not None:
        h.setOptionValue("threads", int(options.threads))
    for key, value in options.extra.items():
        status = h.setOptionValue(key, value)
        if status != highspy.HighsStatus.kOk:
            raise InvalidProblemError(f"HiGHS rejected option {key}={value!r}")
    A = model.A
    n_row, n_col = A.shape
    h.passModel(
        int(n_col), int(n_row), int(A.nnz),
        int(highspy.MatrixFormat.kRowwise), int(highspy.ObjSense.kMinimize), 0.0,
        np.ascontiguousarray(model.c, np.float64),
        np.ascontiguousarray(model.lb, np.float64),
        np.ascontiguousarray(model.ub, np.float64),
        np.ascontiguousarray(model.row_lower, np.float64),
        np.ascontiguousarray(model.row_upper, np.float64),
        np.ascontiguousarray(A.indptr[:-1], np.int32),
        np.ascontiguousarray(A.indices, np.int32),
        np.ascontiguousarray(A.data, np.float64),
        np.ascontiguousarray(model.integrality, np.int32),
    )
    return h


def _option(h: Any, name: str) -> Any:
    """An option's value (highspy returns ``(status, value)`` in some versions)."""
    value = h.getOptionValue(name)
    return value[1] if isinstance(value, tuple) else value


def run_highs(h: Any, deadline: float | None = None) -> None:
    """``h.run()`` in a worker thread, so that Ctrl-C reaches Python at once and asks
    HiGHS to stop through its interrupt callbacks (highspy's ``HandleUserInterrupt``);
    the interrupt is re-raised when HiGHS has returned.  At ``deadline``
    (``time.perf_counter()``) HiGHS is asked to stop the same way, a safety net for
    the phases where its own ``time_limit`` is not checked."""
    from ..interruptible import run_cancellable

    h.HandleUserInterrupt = True
    try:
        run_cancellable(h.run, (), h.cancelSolve, deadline=deadline)
    finally:
        h.HandleUserInterrupt = False


def run_model(model: LinearModel, options: SolveOptions, *,
              time_limit: float | None = None) -> dict[str, Any]:
    """Solve ``model`` with HiGHS in this process; what the result needs, as plain
    values (the same in a worker process, :mod:`.limited`).  ``time_limit`` replaces
    the options' limit (what is left of it in the child)."""
    import dataclasses

    if time_limit is not None:
        options = dataclasses.replace(options, time_limit=time_limit)
    h = highs_from_model(model, options)
    t1 = time.perf_counter()
    run_highs(h, None if options.time_limit is None else t1 + options.time_limit + 0.1)
    t2 = time.perf_counter()
    info = h.getInfo()
    has_primal = info.primal_solution_status == 2  # kSolutionStatusFeasible
    return {"status": h.getModelStatus().name, "solve_time": t2 - t1,
            "message": h.modelStatusToString(h.getModelStatus()),
            "x": np.asarray(h.getSolution().col_value, dtype=np.float64) if has_primal
            else None,
            "dual_bound": float(info.mip_dual_bound), "mip_gap": float(info.mip_gap),
            "objective": float(info.objective_function_value),
            "presolve": _option(h, "presolve"),
            "nodes": int(getattr(info, "mip_node_count", 0))}


@register
class HighsBackend(Backend):
    """HiGHS MIP (branch and cut) or LP (dual simplex / IPM) via highspy."""

    name = "highs"
    module = "highspy"
    imports = ("highspy", "scipy.sparse")
    distribution = "highspy"
    description = "HiGHS MIP/LP solver through highspy, model passed as one CSR matrix"
    lp = True
    supports_time_limit = True
    native_options = "any HiGHS option by name (presolve=\"off\", mip_heuristic_effort=0.1, ...)"
    options = (ISOLATE,)

    @classmethod
    def is_native_option(cls, name: str) -> bool:
        return cls.is_available() and name in _highs_option_names()

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        extra, isolate, empty = opening(self, problem, options)
        if empty is not None:
            return empty
        model, t0, start = built_model(problem, options)
        sub = SolveOptions(relax=options.relax, time_limit=options.time_limit,
                           mip_gap=options.mip_gap, threads=options.threads,
                           verbose=options.verbose, extra=extra, parsed=True)
        t1 = time.perf_counter()
        out = solve_isolated_or_here(self.name, run_model, (model, sub), options, isolate,
                                     start, t0, t1)
        if isinstance(out, RawResult):
            return out
        return self._result(out, model, options, t1 - t0)

    def _result(self, out: dict[str, Any], model: LinearModel, options: SolveOptions,
                build_time: float) -> RawResult:
        bound: float | None = None
        if model.is_mip and np.isfinite(out["dual_bound"]):
            bound = out["dual_bound"]
        gap = out["mip_gap"] if model.is_mip else 0.0
        status = settle_optimal(from_table(_STATUS_TABLE, out["status"]), gap,
                                options.mip_gap if model.is_mip else 0.0)[0]
        info = note_isolated({"highs_status": out["status"], "presolve": out["presolve"],
                              "mip_node_count": out["nodes"]}, out)
        result = RawResult(status=status, message=f"HiGHS: {out['message']}",
                           build_time=build_time, solve_time=out["solve_time"],
                           bound=bound, info=info)
        return take_point(result, out["x"], out["objective"], model.is_mip)
