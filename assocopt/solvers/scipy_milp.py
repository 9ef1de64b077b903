"""scipy.optimize.milp: HiGHS behind scipy's interface (the peer users compare with).

``relax="lp"`` runs the same call with no integrality.  scipy exposes no option
beyond ``time_limit``, ``mip_rel_gap``, ``presolve``, ``node_limit`` and ``disp``;
``presolve`` and ``node_limit`` are accepted as extra options.
"""

from __future__ import annotations

import time

import numpy as np

from ..errors import InvalidProblemError
from ..formulation import build_model
from ..problem import AssignmentProblem
from ..solution import Status
from .base import Backend, RawResult, SolveOptions, register

__all__ = ["ScipyMilpBackend"]

#: scipy.optimize.milp's status codes (see its documentation).
_STATUS = {
    0: Status.OPTIMAL,       # optimal solution found
    1: Status.TIME_LIMIT,    # iteration or time limit reached
    2: Status.INFEASIBLE,    # problem is infeasible
    3: Status.ERROR,         # unbounded: impossible with 0 <= x <= 1, so a failure
    4: Status.ERROR,         # other
}
_EXTRA = ("presolve", "node_limit")


@register
class ScipyMilpBackend(Backend):
    """``scipy.optimize.milp`` (HiGHS inside scipy) for the ILP and the LP relaxation."""

    name = "scipy"
    module = "scipy"
    distribution = "scipy"
    description = "scipy.optimize.milp (HiGHS bundled with scipy)"
    lp = True
    supports_time_limit = True

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        from scipy.optimize import Bounds, LinearConstraint, milp

        unknown = set(options.extra) - set(_EXTRA)
        if unknown:
            raise InvalidProblemError(
                f"unknown option(s) for solver 'scipy': {sorted(unknown)}; "
                f"valid: {list(_EXTRA)}")
        t0 = time.perf_counter()
        model = build_model(problem, options.relax)
        constraint = LinearConstraint(model.A, model.row_lower, model.row_upper)
        opts: dict[str, object] = {"disp": bool(options.verbose),
                                   "mip_rel_gap": float(options.mip_gap)}
        if options.time_limit is not None:
            opts["time_limit"] = float(options.time_limit)
        opts.update(options.extra)
        t1 = time.perf_counter()
        res = milp(model.c, integrality=model.integrality, bounds=Bounds(model.lb, model.ub),
                   constraints=constraint, options=opts)
        t2 = time.perf_counter()
        status = _STATUS.get(int(res.status), Status.ERROR)
        gap = getattr(res, "mip_gap", None)
        if (status is Status.OPTIMAL and model.is_mip and options.mip_gap > 0
                and gap is not None and gap > 1e-9):
            status = Status.FEASIBLE
        bound = getattr(res, "mip_dual_bound", None)
        out = RawResult(status=status, message=f"scipy.milp: {res.message}",
                        build_time=t1 - t0, solve_time=t2 - t1,
                        bound=float(bound) if bound is not None and np.isfinite(bound) else None,
                        info={"scipy_status": int(res.status)})
        if res.x is not None:
            if model.is_mip:
                out.selected = np.flatnonzero(res.x > 0.5)
            else:
                out.x = np.asarray(res.x, dtype=np.float64)
                out.objective = float(res.fun)
        return out
