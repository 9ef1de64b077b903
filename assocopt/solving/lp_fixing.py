"""LP relaxation by pricing, and exact ILP by reduced-cost fixing, for large S-D problems.

Solves many S-D problems with thousands of candidates quickly and *exactly* (paper
002's reproduction solves thousands with up to 8000 candidates this way); the
candidates of the final, small ILP are solved through :func:`assocopt.solve` with any
exact back end.

* :func:`lp_relaxation` -- the LP relaxation of the S-D set-partitioning
  model (:mod:`assocopt.model.formulation`) solved by HiGHS, with its row
  duals ``u`` and the reduced costs ``d = c - A^T u`` of every candidate (gathered,
  no matrix product).
* :func:`solve_with_fixing` -- with ``L(u) = sum(u) + sum(min(d, 0))`` (a valid lower
  bound for *any* multipliers ``u``), a candidate with ``d_k > UB - L(u)`` is 0 in
  every solution of cost <= UB.  A small ILP on the candidates of smallest reduced
  cost gives UB; if every candidate that could still improve on it lies inside that
  small ILP, its optimum is optimal; otherwise the ILP on all such candidates is solved.

Neither step trusts the LP's accuracy for correctness: the fixing bound is recomputed
from ``u`` and the final answer is an ILP optimum over a provably sufficient subset.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .api import solve
from ..model.formulation import build_model
from ..problems.problem import AssignmentProblem
from ..model.solution import Solution, Status
from ..solvers.baseline.greedy import take_in_order

__all__ = ["LPResult", "lp_relaxation", "lp_relaxations", "solve_with_fixing", "greedy_cover",
           "reduced_costs"]

#: Relative tolerance on reduced costs.
RTOL = 1e-9


@dataclass
class LPResult:
    """Optimum of the LP relaxation: ``x`` and reduced costs ``d`` for every candidate."""

    x: np.ndarray
    u: np.ndarray
    d: np.ndarray
    objective: float
    integral: bool

    def selection(self) -> np.ndarray:
        return np.flatnonzero(self.x > 0.5)


def reduced_costs(prob: AssignmentProblem, u: np.ndarray) -> np.ndarray:
    """``c - A^T u`` for all candidates, by gathering (no matrix product)."""
    T = prob.tuples
    d = prob.costs.copy()
    for s, off in enumerate(prob.row_offsets):
        upad = np.concatenate([[0.0], u[off:off + prob.sizes[s]]])
        d -= upad[T[:, s]]
    return d


def greedy_cover(prob: AssignmentProblem, order: np.ndarray) -> np.ndarray | None:
    """Candidates taken in ``order`` while they fit; None if no exact cover results."""
    chosen, covered = take_in_order(prob, order)
    return chosen if covered.all() else None


def lp_relaxation(prob: AssignmentProblem) -> LPResult | None:
    """Optimum of the LP relaxation with HiGHS (dual simplex, presolve off), with duals.

    This is the model :func:`assocopt.solve` builds for ``relax="lp"``
    (:func:`assocopt.model.formulation.build_model`) passed to HiGHS directly, because the
    row duals are needed for fixing.  Returns None if HiGHS does not report optimal.
    """
    return lp_relaxations([prob])[0]


def lp_relaxations(problems: list[AssignmentProblem]) -> list[LPResult | None]:
    """:func:`lp_relaxation` of several problems.  Consecutive problems with the same
    candidate tuples (same constraints, other costs) reuse one HiGHS model: only the
    costs change and the simplex starts from the previous optimal basis."""
    from ..solvers.base import SolveOptions
    from ..solvers.milp.highs import highs_from_model

    out: list[LPResult | None] = []
    h, prev = None, None
    for prob in problems:
        same = prev is not None and (prob.tuples is prev.tuples or (
            prob.tuples.shape == prev.tuples.shape and np.array_equal(prob.tuples, prev.tuples)))
        if h is None or not same:
            h = highs_from_model(build_model(prob, "lp"),
                                 SolveOptions(extra={"presolve": "off"}))
        else:
            K = prob.n_candidates
            h.changeColsCost(K, np.arange(K, dtype=np.int32),
                             np.ascontiguousarray(prob.costs, dtype=np.float64))
        prev = prob
        h.run()
        if h.getModelStatus().name != "kOptimal":
            out.append(None)
            h = None
            continue
        sol = h.getSolution()
        x = np.clip(np.asarray(sol.col_value, dtype=np.float64), 0.0, 1.0)
        u = np.asarray(sol.row_dual, dtype=np.float64)
        integral = bool(np.abs(x - np.round(x)).max(initial=0.0) <= 1e-6)
        if integral and prob.violations(np.flatnonzero(x > 0.5)) is not None:
            integral = False
        out.append(LPResult(x=x, u=u, d=reduced_costs(prob, u),
                            objective=float(prob.costs @ x), integral=integral))
    return out


def solve_with_fixing(prob: AssignmentProblem, lp: LPResult, solver: str
                      ) -> tuple[Solution, int]:
    """Exact ILP optimum of ``prob`` from its LP relaxation (see the module docstring).

    Returns the Solution (its ``tuples`` are tuples of ``prob``) and the number of
    candidates in the last ILP solved.
    """
    d = lp.d
    if not np.isfinite(d).all():
        return solve(prob, solver), prob.n_candidates
    L = float(lp.u.sum() + np.minimum(d, 0.0).sum())
    sel0 = greedy_cover(prob, np.lexsort((d, -lp.x)))
    if sel0 is None:
        return solve(prob, solver), prob.n_candidates
    ub0 = prob.objective_of(sel0)
    n1 = min(prob.n_candidates, 3 * prob.n_rows)
    k1 = np.zeros(prob.n_candidates, dtype=bool)
    k1[np.argpartition(d, n1 - 1)[:n1]] = True
    k1[sel0] = True
    sol1 = _solve_subset(prob, k1, solver)
    ok1 = sol1.has_solution and sol1.status is Status.OPTIMAL
    ub = min(ub0, sol1.objective) if ok1 else ub0
    tol = RTOL * (1.0 + abs(ub) + abs(L))
    kstar = d <= (ub - L) + tol
    if ok1 and not (kstar & ~k1).any():
        return sol1, int(k1.sum())
    kstar[sel0] = True
    return _solve_subset(prob, kstar, solver), int(kstar.sum())


def _solve_subset(prob: AssignmentProblem, keep: np.ndarray, solver: str) -> Solution:
    idx = np.flatnonzero(keep)
    return solve(AssignmentProblem.sparse(prob.sizes, prob.tuples[idx], prob.costs[idx]),
                 solver)
