"""2-D fast path: ``scipy.optimize.linear_sum_assignment`` (shortest augmenting path).

Three cases, chosen from the candidate structure:

* square, no dummies: LSA on the cost matrix (``inf`` = forbidden);
* rectangular ``dense`` (only zero-cost column or row slack on the larger side): LSA
  on the rectangular matrix, which assigns the smaller side completely;
* anything with non-assignment costs: the standard augmentation to an
  ``(n1 + n2) x (n2 + n1)`` matrix ``[[C, diag(row_miss)], [diag(col_miss), 0]]``
  whose off-diagonal entries of the miss blocks are forbidden.
"""

from __future__ import annotations

import time

import numpy as np

from ..problem import AssignmentProblem
from ..solution import Status
from .base import Backend, RawResult, SolveOptions, register

__all__ = ["ScipyLsaBackend", "augmented_matrix"]


def augmented_matrix(C: np.ndarray, row_miss: np.ndarray, col_miss: np.ndarray) -> np.ndarray:
    """The ``(n1+n2) x (n2+n1)`` LAP equivalent to 2-D assignment with miss costs.

    Row ``n1 + j`` paired with column ``j`` means column j unassigned; column
    ``n2 + i`` paired with row ``i`` means row i unassigned; dummy rows and dummy
    columns pair with each other at cost 0.
    """
    n1, n2 = C.shape
    big = np.full((n1 + n2, n2 + n1), np.inf)
    big[:n1, :n2] = C
    big[np.arange(n1), n2 + np.arange(n1)] = row_miss
    big[n1 + np.arange(n2), np.arange(n2)] = col_miss
    big[n1:, n2:] = 0.0
    return big


@register
class ScipyLsaBackend(Backend):
    """Exact 2-D assignment with ``scipy.optimize.linear_sum_assignment``."""

    name = "scipy-lsa"
    module = "scipy"
    distribution = "scipy"
    description = "scipy.optimize.linear_sum_assignment, 2-D only (miss costs by augmentation)"
    max_ndim = 2

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        from scipy.optimize import linear_sum_assignment

        self.settings(problem, options)          # no options of its own: rejects any
        t0 = time.perf_counter()
        n1, n2 = problem.sizes
        C = problem.to_cost_matrix()
        rm, cm = problem.miss_costs()
        mode = self._mode(problem, rm, cm)
        if mode == "plain":
            M = C
        elif mode == "transposed":
            M = C.T
        else:
            M = augmented_matrix(C, rm, cm)
        t1 = time.perf_counter()
        try:
            r, c = linear_sum_assignment(M)
        except ValueError as exc:
            if "infeasible" not in str(exc):
                raise
            return RawResult(Status.INFEASIBLE, message=f"scipy-lsa: {exc}",
                             build_time=t1 - t0, solve_time=time.perf_counter() - t1)
        t2 = time.perf_counter()
        if mode == "transposed":
            r, c = c, r
        if mode == "augmented":
            pairs = self._unaugment(r, c, n1, n2)
        else:
            pairs = np.stack([r + 1, c + 1], axis=1)
            pairs = self._with_slack(pairs, n1, n2)
        selected = _positions(problem, pairs)
        info = {"lsa_mode": mode}
        msg = "scipy-lsa: optimal"
        if options.time_limit is not None:
            msg += " (time_limit not supported by scipy-lsa; ran to completion)"
        return RawResult(Status.OPTIMAL, selected=selected, message=msg, info=info,
                         build_time=t1 - t0, solve_time=t2 - t1)

    @staticmethod
    def _mode(problem: AssignmentProblem, rm: np.ndarray, cm: np.ndarray) -> str:
        """Pick the plain, transposed or augmented LAP (see the module docstring)."""
        n1, n2 = problem.sizes
        no_rm, no_cm = np.isinf(rm).all(), np.isinf(cm).all()
        if no_rm and no_cm and n1 == n2:
            return "plain"
        if no_rm and n1 <= n2 and (cm == 0).all():
            return "plain"          # columns free at no cost: rectangular LSA
        if no_cm and n2 <= n1 and (rm == 0).all():
            return "transposed"     # rows free at no cost
        return "augmented"

    @staticmethod
    def _unaugment(r: np.ndarray, c: np.ndarray, n1: int, n2: int) -> np.ndarray:
        real = (r < n1) & (c < n2)
        row_miss = (r < n1) & (c >= n2)
        col_miss = (r >= n1) & (c < n2)
        parts = [np.stack([r[real] + 1, c[real] + 1], axis=1),
                 np.stack([r[row_miss] + 1, np.zeros(row_miss.sum(), np.int64)], axis=1),
                 np.stack([np.zeros(col_miss.sum(), np.int64), c[col_miss] + 1], axis=1)]
        return np.concatenate(parts).astype(np.int64)

    @staticmethod
    def _with_slack(pairs: np.ndarray, n1: int, n2: int) -> np.ndarray:
        """Add the zero-cost single-index tuples of the indices LSA left free."""
        free_r = np.setdiff1d(np.arange(1, n1 + 1), pairs[:, 0])
        free_c = np.setdiff1d(np.arange(1, n2 + 1), pairs[:, 1])
        extra = [np.stack([free_r, np.zeros_like(free_r)], axis=1),
                 np.stack([np.zeros_like(free_c), free_c], axis=1)]
        return np.concatenate([pairs] + extra).astype(np.int64)


def _positions(problem: AssignmentProblem, pairs: np.ndarray) -> np.ndarray:
    """Candidate positions of the 2-D tuples ``pairs`` (bulk search on packed keys)."""
    n2 = problem.sizes[1] + 1
    keys = problem.tuples[:, 0] * n2 + problem.tuples[:, 1]
    order = np.argsort(keys, kind="stable")
    want = pairs[:, 0] * n2 + pairs[:, 1]
    pos = np.searchsorted(keys[order], want)
    pos = np.minimum(pos, len(keys) - 1)
    found = keys[order][pos] == want
    if not found.all():
        missing = pairs[~found][0].tolist()
        raise RuntimeError(f"scipy-lsa chose {missing}, which is not a candidate")
    return order[pos]
