"""The optional ``lapjv`` 2-D back end: lapx's Jonker-Volgenant LAP (``pip install lapx``).

The cases are those of ``scipy-lsa`` (:mod:`assocopt.solvers.twod.dense`), with lapx's
dense LAP (:func:`assocopt.solvers.twod.lap.linear_assignment`) in place of scipy's.
"""

from __future__ import annotations

from ...problems.problem import AssignmentProblem
from ..base import Backend, Option, RawResult, SolveOptions, register

__all__ = ["LapjvBackend"]


@register
class LapjvBackend(Backend):
    """Exact 2-D assignment with lapx's Jonker-Volgenant code (optional package).

    Same cases as ``scipy-lsa`` (:mod:`assocopt.solvers.twod.dense`); large gated
    candidate lists use the sparse engine (:mod:`assocopt.solvers.twod.sparse`).  Extra
    option ``method``: ``"auto"`` (default), ``"lapx"`` or ``"sparse"``.
    """

    name = "lapjv"
    module = "lap"
    distribution = "lapx"
    description = ("lapx Jonker-Volgenant LAP (dense) / compiled sparse LAP (gated lists), "
                   "2-D only")
    max_ndim = 2
    options = (Option("method", "choice", "auto", "LAP engine: lapx (dense; 'auto' "
                      "means lapx) or the sparse engine of gated lists",
                      choices=("auto", "lapx", "sparse")),)

    def solve(self, problem: AssignmentProblem, options: SolveOptions) -> RawResult:
        from .dense import solve_2d        # loads scipy: not when the back ends are listed

        method = self.settings(problem, options)["method"]
        mode = {"auto": "auto", "lapx": "dense", "sparse": "sparse"}[method]
        raw = solve_2d(problem, options, "lapx", self.name, mode)
        raw.info["lap_method"] = raw.info.pop("lsa_mode", None)
        raw.info["lapx_version"] = self.version()
        return raw
