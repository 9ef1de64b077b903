"""2-D fast path: ``scipy.optimize.linear_sum_assignment`` (shortest augmenting path).

The cases (square, rectangular, with non-assignment costs) are those of
:mod:`assocopt.solvers.twod.dense`: a problem built from a matrix is solved on that
matrix, miss costs through the ``n1 x (n2 + n1)`` reduced form (the classical
``(n1 + n2) x (n2 + n1)`` augmentation,
:func:`assocopt.solvers.twod.lap.augmented_matrix`, only when some rows
and some columns must be assigned); large gated candidate lists go to the sparse
engine (:mod:`assocopt.solvers.twod.sparse`).
"""

from __future__ import annotations

import numpy as np

from ...problems.problem import AssignmentProblem
from ..base import Backend, RawResult, SolveOptions, register

__all__ = ["ScipyLsaBackend"]

_SOLVE_2D = None


@register
class ScipyLsaBackend(Backend):
    """Exact 2-D assignment with ``scipy.optimize.linear_sum_assignment`` (large gated
    candidate lists: the compiled sparse engine of :mod:`assocopt.solvers.twod.sparse`)."""

    name = "scipy-lsa"
    module = "scipy"
    imports = ("scipy.optimize",)
    distribution = "scipy"
    description = ("scipy.optimize.linear_sum_assignment, 2-D only (the dense matrix kept; "
                   "miss costs by clipped reduced costs) / compiled sparse LAP (gated "
                   "lists)")
    max_ndim = 2

    @classmethod
    def imports_for(cls, problem: AssignmentProblem) -> tuple[str, ...]:
        """None for a large gated candidate list (the sparse engine: no scipy.optimize)."""
        from .sparse import prefer_sparse
        if problem.dense_view is None and prefer_sparse(problem.sizes, problem.n_candidates):
            return ()
        return cls.imports

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        self.settings(problem, options)          # no options of its own: rejects any
        global _SOLVE_2D
        if _SOLVE_2D is None:            # imported on first use, then kept (hot path)
            from .dense import solve_2d
            _SOLVE_2D = solve_2d
        return _SOLVE_2D(problem, options, "scipy", self.name)
