"""Costs beyond the safe range: big-M penalties set aside when provably unused, else
an exact power-of-two scaling.

Back ends work best on moderate numbers: HiGHS treats ``|c| >= 1e20`` as infinite,
CP-SAT scales costs to integers, and every floating-point method compares reduced
costs against absolute tolerances.  A problem whose largest ``|cost|`` exceeds
:data:`SCALE_ABOVE` is therefore not handed over as it is:

1. **Big-M penalties.**  Users often write "forbidden" as a huge positive cost.  Let
   ``M`` be the smallest cost above :data:`SCALE_ABOVE` (all such costs positive) and
   ``s = sum(n_s) * (max(0, c_max) - min(0, c_min))`` over the other costs.  A solution
   selects at most ``sum(n_s)`` candidates, so one that uses a big cost costs at least
   ``M + sum(n_s) * min(0, c_min)``, while any solution of the problem without the big
   costs costs at most ``sum(n_s) * max(0, c_max)``.  When ``M > s`` and the problem
   without them is feasible, its optimum is the optimum, and its bound a bound: it is
   solved instead, on unscaled costs (``info["big_m"]`` says how many were set aside).
2. **Scaling.**  Otherwise every cost is multiplied by a power of two (exact in
   floating point) so that the largest is about ``2**40``; the objective is recomputed
   from the original costs by :func:`assocopt.solve`, the bound scaled back, and
   ``info["cost_scale"]`` records the factor.  Costs far below the largest then carry
   little weight in the back end's tolerances, which is why step 1 comes first.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..problems.problem import AssignmentProblem
from ..model.solution import Status
from .base import Backend, RawResult, SolveOptions
from ..problems.twod_tables import _finite_amax

__all__ = ["SCALE_ABOVE", "solve_in_range", "max_abs_cost"]

#: Costs larger than this in magnitude are not handed to a back end as they are.
SCALE_ABOVE = 2.0 ** 50
#: Scaled costs have their largest magnitude just below ``2**SCALE_TO_EXPONENT``.
SCALE_TO_EXPONENT = 40


def max_abs_cost(problem: AssignmentProblem) -> float:
    """Largest finite |cost|, or, for a dense 2-D problem, an upper bound on it when
    that bound already shows it is within :data:`SCALE_ABOVE` (read from its matrix,
    reusing what its validation found; the candidate list is not built for it)."""
    d = problem.dense_view
    if d is not None:
        bound = d.cost_bound()
        return bound if bound <= SCALE_ABOVE else d.max_abs_cost()
    return _finite_amax(problem.costs)


def solve_in_range(backend: Backend, problem: AssignmentProblem,
                   opts: SolveOptions) -> RawResult:
    """``backend.solve`` on ``problem``, with costs beyond :data:`SCALE_ABOVE` handled
    as the module docstring says."""
    if max_abs_cost(problem) <= SCALE_ABOVE:
        return backend.solve(problem, opts)
    if opts.relax is None:
        raw = _without_big_m(backend, problem, opts)
        if raw is not None:
            return raw
    return _scaled(backend, problem, opts)


def _without_big_m(backend: Backend, problem: AssignmentProblem,
                   opts: SolveOptions) -> RawResult | None:
    """The answer of the problem without its big costs, when that is provably the
    answer (step 1 of the module docstring); None when it is not."""
    costs = problem.costs
    big = costs > SCALE_ABOVE
    if (costs < -SCALE_ABOVE).any() or big.all():
        return None
    rest = costs[~big]
    spread = sum(problem.sizes) * (max(0.0, float(rest.max())) - min(0.0, float(rest.min())))
    if not float(costs[big].min()) > spread:
        return None
    keep = np.flatnonzero(~big)
    sub = dataclasses.replace(problem, tuples=problem.tuples[keep], costs=costs[keep],
                              slack=problem.slack[keep], optimum=None,
                              meta=dict(problem.meta))
    for arr in (sub.tuples, sub.costs, sub.slack):
        arr.setflags(write=False)
    if sub.n_uncovered:
        return None               # some index is covered by big costs only
    raw = backend.solve(sub, opts)
    if raw.status is Status.INFEASIBLE or raw.status is Status.ERROR:
        return None
    if raw.selected is not None:
        raw.selected = keep[np.asarray(raw.selected, dtype=np.int64)]
    raw.info = {**raw.info, "big_m": {"set_aside": int(big.sum()),
                                      "smallest": float(costs[big].min()),
                                      "exceeds": spread}}
    return raw


def _scaled(backend: Backend, problem: AssignmentProblem, opts: SolveOptions) -> RawResult:
    """Step 2 of the module docstring: every cost times a power of two."""
    amax = max_abs_cost(problem)
    shift = math.frexp(amax)[1] - SCALE_TO_EXPONENT
    factor = math.ldexp(1.0, shift)
    scaled = dataclasses.replace(problem, costs=np.ldexp(problem.costs, -shift),
                                 optimum=None, meta=dict(problem.meta))
    scaled.costs.setflags(write=False)
    raw = backend.solve(scaled, opts)
    if raw.bound is not None and math.isfinite(raw.bound):
        raw.bound = raw.bound * factor
    if raw.objective is not None and math.isfinite(raw.objective):
        raw.objective = raw.objective * factor
    raw.info = {**raw.info, "cost_scale": factor}
    return raw
