"""One result type for every formulation and back end."""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["Status", "Solution", "relative_gap"]


class Status(str, enum.Enum):
    """Outcome of a solve, mapped from each back end's native status table.

    ``OPTIMAL``: proven optimal (for ``relax="lp"``: the LP optimum).
    ``FEASIBLE``: a feasible solution without a proof of optimality (heuristics,
    or a gap tolerance above zero).
    ``INFEASIBLE``: proven that no feasible solution exists.
    ``TIME_LIMIT``: stopped by a time or iteration limit; a solution may or
    may not be attached (see :attr:`Solution.has_solution`).  Never "optimal".
    ``NODE_LIMIT``: stopped by a cap on search nodes that the method sets itself
    (``bruteforce``'s ``max_nodes``), with or without a time limit given; a solution
    may or may not be attached.  Never "optimal".
    ``ERROR``: the back end failed; see :attr:`Solution.message`.
    """

    OPTIMAL = "optimal"
    FEASIBLE = "feasible"
    INFEASIBLE = "infeasible"
    TIME_LIMIT = "time_limit"
    NODE_LIMIT = "node_limit"
    ERROR = "error"

    def __str__(self) -> str:
        return self.value

    @property
    def is_limit(self) -> bool:
        """True for a run stopped by a limit (time, iterations or nodes)."""
        return self in (Status.TIME_LIMIT, Status.NODE_LIMIT)


def relative_gap(objective: float | None, bound: float | None) -> float | None:
    """``(objective - bound) / |objective|`` (HiGHS's convention); 0 when both are 0."""
    if objective is None or bound is None:
        return None
    diff = objective - bound
    if diff <= 0:
        return 0.0
    if objective == 0:
        return math.inf
    return diff / abs(objective)


@dataclass
class Solution:
    """The answer of :func:`assocopt.solve`.

    Attributes
    ----------
    status : Status
    objective : float or None
        Cost of the returned solution, recomputed from the problem's costs (never
        taken on trust from the back end).  For ``relax="lp"``, the LP optimum.
    bound : float or None
        A proven bound on the optimum, where the method gives one: a lower bound, or an
        upper bound for a problem built with ``maximize=True``.
    selected : ndarray of int64 or None
        Positions of the chosen candidates in ``problem.tuples`` (slack included).
    tuples : ndarray of int64, shape (k, N), or None
        The chosen tuples in S-D convention (0 = dummy, real indices 1-based),
        slack candidates left out.  See :meth:`assignment` for 0-based arrays.
    solver : str
        The method that produced the answer: the back end asked for, or, when it
        handed the problem on (``bnb``'s fallback), the one that answered, with
        ``info["requested"]`` and ``info["fallback"]`` saying so.  ``solver_version``:
        assocopt's version for assocopt's own methods, else the solver package's.
    times : dict
        ``build`` (model construction), ``solve`` (back end) and ``total`` seconds;
        ``import`` (the first solve that needs a package: its import, e.g. scipy for
        the first 2-D solve), ``compile`` and ``cache_load`` (numba kernels) when they
        happened, which ``total`` includes and ``build`` / ``solve`` do not.
    relaxation : str or None
        ``"lp"`` when the LP relaxation was solved.
    x : ndarray or None
        The LP's (possibly fractional) value of every candidate.
    integral : bool or None
        For an LP: whether its optimum happened to be integral.
    message : str
        Human-readable detail (the back end's own status text where useful).
    info : dict
        Method-specific values that were used (scaling, options...), for records
        (in the minimisation sense: negated scores for a maximisation problem).
    maximize : bool
        The problem maximises: ``objective`` and ``bound`` are in the scores' sense.
    """

    status: Status
    objective: float | None = None
    bound: float | None = None
    selected: np.ndarray | None = None
    tuples: np.ndarray | None = None
    solver: str = ""
    solver_version: str = ""
    times: dict[str, float] = field(default_factory=dict)
    relaxation: str | None = None
    x: np.ndarray | None = None
    integral: bool | None = None
    message: str = ""
    info: dict[str, Any] = field(default_factory=dict)
    maximize: bool = False

    @property
    def gap(self) -> float | None:
        """Relative gap between :attr:`objective` and :attr:`bound` (None if no bound)."""
        if self.maximize and self.objective is not None and self.bound is not None:
            return relative_gap(-self.objective, -self.bound)
        return relative_gap(self.objective, self.bound)

    @property
    def has_solution(self) -> bool:
        """True when a feasible (integral) assignment is attached."""
        return self.selected is not None

    def assignment(self) -> tuple[np.ndarray, ...]:
        """0-based index arrays of the fully real chosen tuples, sorted by axis 0.

        For a 2-D problem this is ``(row_ind, col_ind)`` exactly like
        :func:`scipy.optimize.linear_sum_assignment`; unassigned indices are absent.
        """
        if self.tuples is None:
            raise ValueError(f"no assignment: status is {self.status}")
        T = self.tuples[(self.tuples > 0).all(axis=1)] - 1
        T = T[np.lexsort(T.T[::-1])] if len(T) else T
        return tuple(T[:, s].copy() for s in range(self.tuples.shape[1]))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary (tuples in S-D convention, 0 = dummy)."""
        def num(v: float | None) -> float | None | str:
            if v is None:
                return None
            return v if math.isfinite(v) else ("inf" if v > 0 else "-inf")
        return {
            "status": str(self.status),
            "objective": num(self.objective),
            "bound": num(self.bound),
            "gap": num(self.gap),
            "solver": self.solver,
            "solver_version": self.solver_version,
            "maximize": self.maximize,
            "relaxation": self.relaxation,
            "integral": self.integral,
            "tuples": None if self.tuples is None else self.tuples.tolist(),
            "time_s": self.times.get("total"),
            "times": dict(self.times),
            "message": self.message,
            "info": self.info,
        }

    def __repr__(self) -> str:
        obj = "None" if self.objective is None else f"{self.objective:.10g}"
        return (f"Solution(status={self.status.value}, objective={obj}, "
                f"gap={self.gap}, solver={self.solver!r})")
