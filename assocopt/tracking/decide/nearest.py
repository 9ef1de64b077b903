"""Report-to-track association as optimisation (GNN) and its greedy baseline (NN).

Both take a cost matrix ``C`` (reports x tracks; ``inf`` = outside the gate) and a
new-target cost ``c_new``: the cost of leaving a report out of every track (it then
starts a new track).

* :func:`gnn_assign`: global nearest neighbour, the 2-D assignment with
  non-assignment costs solved by :func:`assocopt.solve` (any back end): a report
  costs ``c_new`` when unassigned, a track 0, so a pair is used only when it costs
  less than ``c_new``, and no track gets two reports;
* :func:`nearest_neighbour`: each track independently takes its cheapest report below
  ``c_new`` (Singer's nearest neighbour; two tracks may take the same report).

>>> import numpy as np
>>> C = np.array([[1.0, 2.0], [1.5, 9.0]])
>>> gnn_assign(C, 5.0).tolist()          # report -> track (-1: new target)
[1, 0]
>>> nearest_neighbour(C, 5.0).tolist()   # track -> report
[0, 0]
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...solving.api import solve
from ...problems.problem import AssignmentProblem
from ...model.solution import Status

__all__ = ["gnn_assign", "nearest_neighbour", "check_costs"]


def check_costs(costs: ArrayLike, c_new: float) -> np.ndarray:
    """Validated float cost matrix (NaN and -inf refused; +inf = gated out)."""
    C = np.asarray(costs, dtype=np.float64)
    if C.ndim != 2:
        raise ValueError(f"cost matrix must be 2-D (reports x tracks), got shape {C.shape}")
    if np.isnan(C).any() or np.isneginf(C).any():
        raise ValueError("cost matrix must not hold NaN or -inf")
    if not (isinstance(c_new, (int, float, np.floating)) and math.isfinite(c_new)):
        raise ValueError(f"c_new must be a finite number, got {c_new!r}")
    return C


def gnn_assign(costs: ArrayLike, c_new: float, solver: str = "auto",
               **solve_options: Any) -> np.ndarray:
    """Track (0-based) of each report by the optimal 2-D assignment; -1 = new target."""
    C = check_costs(costs, c_new)
    n_r, n_t = C.shape
    out = np.full(n_r, -1, dtype=np.int64)
    C = np.where(C < c_new, C, np.inf)          # a pair at or above c_new is never used
    if n_r == 0 or n_t == 0 or not np.isfinite(C).any():
        return out
    problem = AssignmentProblem.two_d(C, row_miss=float(c_new), col_miss=0.0, name="gnn")
    sol = solve(problem, solver, **solve_options)
    if not sol.has_solution or sol.status not in (Status.OPTIMAL, Status.FEASIBLE):
        raise RuntimeError(f"GNN: solver {sol.solver!r} returned no assignment "
                           f"(status {sol.status}): {sol.message}")
    r, c = sol.assignment()
    out[r] = c
    return out


def nearest_neighbour(costs: ArrayLike, c_new: float) -> np.ndarray:
    """Report (0-based) taken by each track, its cheapest below ``c_new``; -1 = none."""
    C = check_costs(costs, c_new)
    n_r, n_t = C.shape
    if n_r == 0:
        return np.full(n_t, -1, dtype=np.int64)
    best = np.argmin(C, axis=0)
    ok = C[best, np.arange(n_t)] < c_new
    return np.where(ok, best, -1).astype(np.int64)
