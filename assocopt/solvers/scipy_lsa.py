"""2-D fast path: ``scipy.optimize.linear_sum_assignment`` (shortest augmenting path).

The cases (square, rectangular, with non-assignment costs) are those of
:mod:`assocopt.solvers.dense2d`: a problem built from a matrix is solved on that
matrix, miss costs through the ``n1 x (n2 + n1)`` reduced form (the classical
``(n1 + n2) x (n2 + n1)`` augmentation, :func:`augmented_matrix`, only when some rows
and some columns must be assigned); large gated candidate lists go to the sparse
engine (:mod:`assocopt.solvers.sparse2d`).
"""

from __future__ import annotations

import numpy as np

from ..problem import AssignmentProblem
from .base import Backend, RawResult, SolveOptions, register

__all__ = ["ScipyLsaBackend", "augmented_matrix"]

_SOLVE_2D = None


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
    """Exact 2-D assignment with ``scipy.optimize.linear_sum_assignment`` (large gated
    candidate lists: the compiled sparse engine of :mod:`assocopt.solvers.sparse2d`)."""

    name = "scipy-lsa"
    module = "scipy"
    distribution = "scipy"
    description = ("scipy.optimize.linear_sum_assignment, 2-D only (the dense matrix kept; "
                   "miss costs by clipped reduced costs) / compiled sparse LAP (gated "
                   "lists)")
    max_ndim = 2

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        self.settings(problem, options)          # no options of its own: rejects any
        global _SOLVE_2D
        if _SOLVE_2D is None:            # imported on first use, then kept (hot path)
            from .dense2d import solve_2d
            _SOLVE_2D = solve_2d
        return _SOLVE_2D(problem, options, "scipy", self.name)


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
