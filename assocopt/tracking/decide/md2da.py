"""MD-2DA: paper 000's baseline decision as a 2-D assignment model (the paper gives its costs
and gating, so they are ours: docs/papers/zhang2009.md).

The paper compares its truncation rule with "2-D assignment on pi" but gives neither
the cost nor the handling of unpaired observations.  Ours (recorded with every
result):

* **Cost** (``cost="linear"``): a cross-sensor pair ``(i, j)`` costs ``-pi_ij``;
  leaving an observation unpaired costs ``-tau / 2``.  The total cost is then
  ``-(sum over matched pairs of (pi_ij - tau)) + constant``, so the model picks the
  one-to-one matching that maximises the total matching measure in excess of
  ``tau``: a pair is worth matching only if its ``pi`` beats the threshold.  This is
  the literal "2-D assignment on pi" of the paper's ref. [7] (sum of pair costs)
  with a reservation value.  ``cost="log"`` uses ``-ln pi_ij`` and ``-ln(tau)/2``
  (product of pi over matched pairs), as the alternative reading.
* **Threshold** (:func:`gate_threshold`): ``tau`` is the matching measure of a
  pair whose position lies exactly on the chi-square(2) gate of level ``alpha``
  (``m^p(M) = alpha``: ``m^p(M) = exp(-d^2/2)`` *is* the gate's chi-square(2) p-value) and whose
  attributes agree perfectly (``K = 0``).  Every measure is non-decreasing in
  ``m^p(M)`` and in ``1 - K``, so a pair outside the position gate can never be
  matched, whatever its attributes, and pairs inside compete on pi.  Default
  ``alpha = 0.01``, the usual 99 % gate.  ``tau = 0`` is the plain rectangular
  assignment: no non-assignment option at all, exactly ``min(N1, N2)`` pairs (not a
  miss cost of 0, which would tie with a pair of ``pi = 0`` and leave the answer to
  the back end's tie rule), so every exact back end gives the same decisions.

The model goes through :func:`assocopt.solve`, so any installed back end solves it.

Examples
--------
>>> import numpy as np
>>> pi = np.array([[np.nan, .01, .90, .02, .05],
...                [.01, np.nan, .03, .80, .04],
...                [.90, .03, np.nan, .02, .06],
...                [.02, .80, .02, np.nan, .01],
...                [.05, .04, .06, .01, np.nan]])
>>> res = md_2da(pi, [1, 1, 2, 2, 2], tau=0.1, solver="highs")
>>> res.relations.pairs, res.relations.isolated
(((0, 2), (1, 3)), (4,))
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ...solving.api import solve
from ..belief.group_matching import MeasureParams, Relations, pair_measure
from ...problems.problem import AssignmentProblem
from ...model.solution import Solution, Status
from .truncation import check_pi

__all__ = ["COSTS", "MD2DAResult", "md_2da_problem", "md_2da", "gate_threshold"]

#: Cost readings of the 2-D assignment on pi (see the module docstring).
COSTS = ("linear", "log")


@dataclass(frozen=True)
class MD2DAResult:
    """Relations decided by the 2-D assignment, and the solver's :class:`Solution`."""

    relations: Relations
    solution: Solution
    problem: AssignmentProblem


def gate_threshold(params: MeasureParams, alpha: float = 0.01) -> float:
    """``tau``: pi of a pair on the chi-square(2) gate of level ``alpha`` with ``K = 0``.

    >>> round(gate_threshold(MeasureParams("ncr", r_p=1.0, r_a=0.6), 0.01), 12)   # 0.01 * 0.8
    0.008
    """
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1), got {alpha!r}")
    return float(pair_measure(np.float64(alpha), np.float64(0.0), np.float64(0.0), params))


def md_2da_problem(pi: ArrayLike, sensor: ArrayLike, tau: float,
                   cost: str = "linear") -> tuple[AssignmentProblem, np.ndarray, np.ndarray]:
    """The 2-D assignment model: rows = sensor-1 observations, columns = sensor-2.

    Returns the problem and the pooled indices of its rows and columns.
    """
    P, s = check_pi(pi, sensor)
    if not (isinstance(tau, (int, float)) and math.isfinite(tau) and tau >= 0):
        raise ValueError(f"tau must be a finite number >= 0, got {tau!r}")
    if cost not in COSTS:
        raise ValueError(f"cost must be one of {COSTS}, got {cost!r}")
    rows, cols = np.flatnonzero(s == 1), np.flatnonzero(s == 2)
    cross = P[np.ix_(rows, cols)]
    if (cross < 0).any():
        raise ValueError("pi must be >= 0 between the two sensors")
    if cost == "linear":
        C = -cross
    else:
        with np.errstate(divide="ignore"):
            C = -np.log(cross)                      # pi = 0: +inf, a forbidden pair
    if tau == 0:
        # the rectangular assignment: min(N1, N2) pairs and no non-assignment option.
        # (A miss cost of -tau/2 = 0 would tie with pairing at pi = 0, and each back
        # end would break the tie its own way.)
        miss = None
    else:
        miss = -0.5 * tau if cost == "linear" else -0.5 * math.log(tau)
    problem = AssignmentProblem.two_d(C, row_miss=miss, col_miss=miss,
                                      name="zhang2009-md2da")
    return problem, rows, cols


def md_2da(pi: ArrayLike, sensor: ArrayLike, *, tau: float, cost: str = "linear",
           solver: str = "auto", **solve_options: Any) -> MD2DAResult:
    """Decide the relations by 2-D assignment on ``pi`` (see the module docstring).

    ``tau = 0`` (either cost) is the rectangular assignment without non-assignment:
    ``min(N1, N2)`` pairs.

    Raises
    ------
    RuntimeError
        If the back end returns no feasible assignment.
    """
    P, s = check_pi(pi, sensor)
    problem, rows, cols = md_2da_problem(P, s, tau, cost)
    sol = solve(problem, solver, **solve_options)
    if not sol.has_solution or sol.status not in (Status.OPTIMAL, Status.FEASIBLE):
        raise RuntimeError(f"MD-2DA: solver {sol.solver!r} returned no assignment "
                           f"(status {sol.status}): {sol.message}")
    r, c = sol.assignment()
    matched = set(rows[r].tolist()) | set(cols[c].tolist())
    clusters = [(int(rows[i]), int(cols[j])) for i, j in zip(r, c)]
    clusters += [(i,) for i in range(len(s)) if i not in matched]
    return MD2DAResult(Relations.from_clusters(clusters, s), sol, problem)
