"""Marginal association probabilities from ranked hypotheses.

A *hypothesis* is a feasible solution ``h`` of cost ``c(h)``; with temperature ``T`` it
gets the weight ``exp(-c(h) / T)`` (for a ``maximize=True`` problem of scores ``s``:
``exp(s(h) / T)``, the posterior of a log-likelihood score at ``T = 1``).  The marginal
of a candidate is the normalised weight of the hypotheses that contain it:

    P(candidate) = sum_{h contains it} exp(-c(h)/T) / sum_h exp(-c(h)/T).

``method="kbest"`` (default) sums over the ``k`` best hypotheses (:func:`assocopt.kbest`),
the usual approximation in trackers (JPDA-style marginals from Murty's ranking);
``method="enumerate"`` over every feasible solution (exact; small problems only).  For
2-D problems the result also has the ``n1 x n2`` matrix of pair probabilities and each
row's and column's probability of staying unassigned, so each row sums to 1 over its
columns and its miss.  How close the k-best sum gets is measured in
``docs/benchmarks-2d.md`` (``benchmarks/twod.py``).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from ..runtime.errors import InvalidProblemError
from ..problems.problem import AssignmentProblem

__all__ = ["marginals", "Marginals", "METHODS"]

#: Accepted ``method`` values.
METHODS = ("kbest", "enumerate")


@dataclass
class Marginals:
    """Marginal probabilities (see the module docstring).

    ``candidate[c]``: probability of candidate ``c`` (positions in ``problem.tuples``).
    2-D only (else None): ``pairs[i, j]`` (0-based) that row i is assigned to column j;
    ``row_miss[i]`` / ``col_miss[j]``: that row i / column j stays unassigned (for a
    rectangular ``dense`` problem, that the surplus index is left free).
    ``hypotheses``: how many were summed; ``exhaustive``: all feasible ones were (the
    marginals are exact); ``log_partition``: ``log sum_h exp(-c(h)/T)`` over them.
    """

    candidate: np.ndarray
    pairs: np.ndarray | None
    row_miss: np.ndarray | None
    col_miss: np.ndarray | None
    hypotheses: int
    exhaustive: bool
    temperature: float
    log_partition: float
    method: str


def marginals(problem: AssignmentProblem, k: int = 100, temperature: float = 1.0, *,
              method: str = "kbest", solver: str = "auto") -> Marginals:
    """Marginal association probabilities of ``problem`` (see the module docstring).

    ``k``: how many best hypotheses ``method="kbest"`` sums (ignored by
    ``"enumerate"``); ``temperature``: a positive finite number; ``solver``: the exact
    back end of :func:`assocopt.kbest`.  A problem without a feasible solution is an
    :class:`~assocopt.InvalidProblemError`.

    Examples
    --------
    >>> from assocopt import AssignmentProblem
    >>> m = marginals(AssignmentProblem.two_d([[0.0, 5.0]], 1.0, 1.0), k=10)
    >>> m.hypotheses, m.exhaustive, round(float(m.pairs[0].sum() + m.row_miss[0]), 12)
    (3, True, 1.0)
    """
    if (isinstance(temperature, bool) or not isinstance(temperature, numbers.Real)
            or not (math.isfinite(temperature) and temperature > 0)):
        raise InvalidProblemError(f"temperature must be a positive number, got {temperature!r}")
    if method not in METHODS:
        raise InvalidProblemError(f"method must be one of {METHODS}, got {method!r}")
    if method == "kbest":
        from .kbest import kbest

        ranked = kbest(problem, k, solver)
        sels = [s.selected for s in ranked]
        exhaustive = ranked.exhausted
    else:
        from ..runtime.errors import ProblemTooLargeError
        from ..solvers.baseline.bruteforce import enumerate_solutions

        try:
            sels = list(enumerate_solutions(problem))
        except ProblemTooLargeError as exc:
            raise ProblemTooLargeError(
                f"method='enumerate' is for small problems: {exc.args[0].split(';')[0]}; "
                "use method='kbest' (the k best hypotheses) instead") from None
        exhaustive = True
    if not sels:
        raise InvalidProblemError("the problem has no feasible solution: no marginals")
    costs = np.array([problem.objective_of(s) for s in sels])
    logw = -(costs - costs.min()) / float(temperature)
    w = np.exp(logw)
    z = w.sum()
    P = np.zeros(problem.n_candidates)
    np.add.at(P, np.concatenate(sels), np.repeat(w / z, [len(s) for s in sels]))
    pairs = row_miss = col_miss = None
    if problem.ndim == 2:
        pairs, row_miss, col_miss = _two_d(problem, P)
    return Marginals(P, pairs, row_miss, col_miss, len(sels), exhaustive,
                     float(temperature), float(math.log(z) - costs.min() / temperature),
                     method)


def _two_d(problem: AssignmentProblem, P: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    n1, n2 = problem.sizes
    T = problem.tuples
    pairs = np.zeros((n1, n2))
    row_miss = np.zeros(n1)
    col_miss = np.zeros(n2)
    both = (T[:, 0] > 0) & (T[:, 1] > 0)
    pairs[T[both, 0] - 1, T[both, 1] - 1] = P[both]
    r = (T[:, 0] > 0) & (T[:, 1] == 0)
    c = (T[:, 0] == 0) & (T[:, 1] > 0)
    row_miss[T[r, 0] - 1] = P[r]
    col_miss[T[c, 1] - 1] = P[c]
    return pairs, row_miss, col_miss
