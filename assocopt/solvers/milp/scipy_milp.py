"""scipy.optimize.milp: HiGHS behind scipy's interface (the peer users compare with).

``relax="lp"`` runs the same call with no integrality.  scipy exposes no option
beyond ``time_limit``, ``mip_rel_gap``, ``presolve``, ``node_limit`` and ``disp``;
``presolve`` and ``node_limit`` are accepted as extra options.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ...model.formulation import LinearModel
from ...problems.problem import AssignmentProblem
from ...model.solution import Status
from ..base import Backend, Option, RawResult, SolveOptions, register
from ..interruptible import run_cancellable
from .answer import opening, built_model, note_isolated, take_point
from .limited import ISOLATE, solve_isolated_or_here
from ..status import from_table, settle_optimal

__all__ = ["ScipyMilpBackend"]

#: scipy.optimize.milp's status codes (see its documentation).
_STATUS_TABLE: dict[str, Status] = {
    "0": Status.OPTIMAL,       # optimal solution found
    "1": Status.TIME_LIMIT,    # iteration or time limit reached
    "2": Status.INFEASIBLE,    # problem is infeasible
    "3": Status.ERROR,         # unbounded: impossible with 0 <= x <= 1, so a failure
    "4": Status.ERROR,         # other
}


@register
class ScipyMilpBackend(Backend):
    """``scipy.optimize.milp`` (HiGHS inside scipy) for the ILP and the LP relaxation."""

    name = "scipy"
    module = "scipy"
    imports = ("scipy.optimize", "scipy.sparse")
    distribution = "scipy"
    description = "scipy.optimize.milp (HiGHS bundled with scipy)"
    lp = True
    supports_time_limit = True
    options = (
        Option("presolve", "bool", None, "let HiGHS presolve the model (default: yes, "
               "but no under a time limit: HiGHS presolve does not look at the clock)",
               nullable=True),
        Option("node_limit", "int", None, "largest number of branch-and-bound nodes",
               low=1, nullable=True),
        ISOLATE,
    )

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        extra, isolate, empty = opening(self, problem, options)
        if empty is not None:
            return empty
        extra = {k: v for k, v in extra.items() if v is not None}
        model, t0, start = built_model(problem, options)
        opts: dict[str, object] = {"disp": bool(options.verbose),
                                   "mip_rel_gap": float(options.mip_gap)}
        if options.time_limit is not None:
            # HiGHS presolve ignores the clock (see assocopt.solvers.milp.highs): off with a limit
            opts["presolve"] = False
        opts.update(extra)
        t1 = time.perf_counter()
        res = solve_isolated_or_here(self.name, run_model, (model, opts), options, isolate,
                                     start, t0, t1)
        if isinstance(res, RawResult):
            return res
        t2 = time.perf_counter()
        status, _ = settle_optimal(from_table(_STATUS_TABLE, str(res["status"])),
                                   res["mip_gap"], options.mip_gap if model.is_mip else 0.0)
        bound = res["mip_dual_bound"]
        out = RawResult(status=status, message=f"scipy.milp: {res['message']}",
                        build_time=t1 - t0, solve_time=t2 - t1,
                        bound=float(bound) if bound is not None and np.isfinite(bound) else None,
                        info=note_isolated({"scipy_status": res["status"]}, res))
        return take_point(out, res["x"], res["fun"], model.is_mip)


def run_model(model: LinearModel, opts: dict[str, object], *,
              time_limit: float | None = None) -> dict[str, Any]:
    """``scipy.optimize.milp`` on ``model`` in this process (in a worker thread, so that
    Ctrl-C takes effect at once; the abandoned solve ends on its own, see
    :mod:`.interruptible`), its result as plain values (the same in a worker process,
    :mod:`.limited`)."""
    from scipy.optimize import Bounds, LinearConstraint, milp

    if time_limit is not None:
        opts = dict(opts, time_limit=float(time_limit))
    constraint = LinearConstraint(model.A, model.row_lower, model.row_upper)
    res, _ = run_cancellable(milp, (model.c,), None, kwargs=dict(
        integrality=model.integrality, bounds=Bounds(model.lb, model.ub),
        constraints=constraint, options=opts))
    gap = getattr(res, "mip_gap", None)
    return {"status": int(res.status), "message": str(res.message), "x": res.x,
            "fun": None if res.x is None else float(res.fun),
            "mip_gap": None if gap is None else float(gap),
            "mip_dual_bound": getattr(res, "mip_dual_bound", None)}
