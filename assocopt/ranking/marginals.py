"""Marginal association probabilities, cluster by cluster.

A *hypothesis* is a feasible solution ``h`` of cost ``c(h)``; with temperature ``T`` it
gets the weight ``exp(-c(h) / T)`` (for a ``maximize=True`` problem of scores ``s``:
``exp(s(h) / T)``, the posterior of a log-likelihood score at ``T = 1``).  The marginal
of a candidate is the normalised weight of the hypotheses that contain it:

    P(candidate) = sum_{h contains it} exp(-c(h)/T) / sum_h exp(-c(h)/T).

The problem is first split into its independent clusters (:mod:`.clusters`); each is
summed on its own and the log-partitions add up.  Methods, per cluster:

* ``"exact"``: the hypothesis net of :mod:`.hypothesis_net` (EHM class, any N): exact;
  a cluster too large for its memory budget (``max_nodes``) is a
  :class:`~assocopt.ProblemTooLargeError` naming the cluster.
* ``"kbest"``: the ``k`` best hypotheses (Murty's ranking, :func:`assocopt.kbest`), with
  a certified bound on the error (:mod:`.kbest_marginals`).
* ``"lbp"``: loopy belief propagation (Williams and Lau), 2-D only, to a tolerance
  (:mod:`.lbp`); no certified bound.
* ``"auto"`` (default): exact where the net fits, else ``kbest`` with its bound, with a
  warning when that bound exceeds ``1e-3``.
* ``"enumerate"``: every hypothesis of each cluster, one by one (small clusters only).

For 2-D problems the result also has the ``n1 x n2`` matrix of pair probabilities and
each row's and column's probability of staying unassigned, so each row sums to 1 over
its columns and its miss.  For any N, ``unassigned[s][i]``: the probability that index
``i + 1`` of axis ``s`` is covered by its singleton (a missed track, a false alarm).
"""

from __future__ import annotations

import math
import numbers
import warnings
from dataclasses import dataclass

import numpy as np

from ..runtime.errors import InvalidProblemError
from ..problems.problem import AssignmentProblem
from .clusters import clusters as _clusters
from .hypothesis_net import MAX_NODES

__all__ = ["marginals", "Marginals", "METHODS", "WARN_BOUND"]

#: Accepted ``method`` values.
METHODS = ("auto", "exact", "kbest", "lbp", "enumerate")
#: ``method="auto"`` warns when its error bound exceeds this.
WARN_BOUND = 1e-3


@dataclass
class Marginals:
    """Marginal probabilities (see the module docstring).

    ``candidate[c]``: probability of candidate ``c`` (positions in ``problem.tuples``).
    2-D only (else None): ``pairs[i, j]`` (0-based) that row i is assigned to column j;
    ``row_miss[i]`` / ``col_miss[j]``: that row i / column j stays unassigned (for a
    rectangular ``dense`` problem, that the surplus index is left free).
    ``hypotheses``: how many were summed one by one (``kbest``, ``enumerate``; 0 for
    ``exact`` and ``lbp``, which list none); ``exhaustive``: the marginals are exact;
    ``log_partition``: ``log sum_h exp(-c(h)/T)`` over the hypotheses summed (exact for
    ``exact``; a lower bound for a truncated ``kbest``; NaN for ``lbp``).
    ``error_bound``: a certified upper bound on ``max |P - P_exact|`` over the
    candidates (0 when exact; NaN for ``lbp``, which has none); ``iterations`` and
    ``residual``: of ``lbp`` (its last largest message change; 0 otherwise);
    ``clusters``: how many independent clusters; ``approximated``: how many of them
    were not summed exactly; ``nodes``: the size of the largest cluster's net;
    ``unassigned``: per axis, each index's probability of being covered by its
    singleton (missed / false alarm).
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
    error_bound: float = 0.0
    iterations: int = 0
    residual: float = 0.0
    clusters: int = 1
    approximated: int = 0
    nodes: int = 0
    unassigned: tuple[np.ndarray, ...] | None = None


def marginals(problem: AssignmentProblem, k: int = 100, temperature: float = 1.0, *,
              method: str = "auto", solver: str = "auto", max_nodes: int = MAX_NODES,
              tolerance: float = 1e-10, max_iterations: int = 1000) -> Marginals:
    """Marginal association probabilities of ``problem`` (see the module docstring).

    ``k``: how many best hypotheses ``kbest`` sums per cluster (and ``auto`` where the
    net does not fit); ``temperature``: a positive finite number; ``solver``: the exact
    back end of :func:`assocopt.kbest`; ``max_nodes``: the memory budget of one
    cluster's exact net; ``tolerance`` / ``max_iterations``: of ``lbp``.  A problem
    without a feasible solution (an index no candidate covers, say) is an
    :class:`~assocopt.InvalidProblemError`.

    Examples
    --------
    >>> from assocopt import AssignmentProblem
    >>> m = marginals(AssignmentProblem.two_d([[0.0, 5.0]], 1.0, 1.0))
    >>> m.exhaustive, m.clusters, round(float(m.pairs[0].sum() + m.row_miss[0]), 12)
    (True, 1, 1.0)
    """
    if (isinstance(temperature, bool) or not isinstance(temperature, numbers.Real)
            or not (math.isfinite(temperature) and temperature > 0)):
        raise InvalidProblemError(f"temperature must be a positive number, got {temperature!r}")
    if method not in METHODS:
        raise InvalidProblemError(f"method must be one of {METHODS}, got {method!r}")
    if isinstance(max_nodes, bool) or not isinstance(max_nodes, numbers.Integral) \
            or not 1 <= max_nodes < 2**31:
        raise InvalidProblemError(f"max_nodes must be an integer in 1..2**31-1, got {max_nodes!r}")
    T = float(temperature)
    gap = problem.uncovered(1)
    if gap:
        axis, i = gap[0]
        raise InvalidProblemError(
            f"the problem has no feasible solution: no marginals (index {i} of axis "
            f"{axis} has no allowed candidate and may not stay unassigned)")
    logw = -np.asarray(problem.costs, np.float64) / T
    if method == "lbp":
        from .lbp import lbp_marginals

        P, it, res = lbp_marginals(problem, logw, tolerance, max_iterations)
        n_parts = len(_clusters(problem))
        return _result(problem, P, 0, False, T, math.nan, "lbp", math.nan, it, res,
                       n_parts, n_parts, 0)
    if method in ("exact", "auto"):
        return _exact(problem, logw, k, T, solver, method, max_nodes)
    P = np.zeros(problem.n_candidates)
    parts = _clusters(problem)
    log_z, hyps, approx, bound = _sum_ranked(problem, parts, k, T, solver, method, P)
    return _result(problem, P, hyps, bound == 0.0, T, log_z, method, bound, 0, 0.0,
                   len(parts), approx, 0)


def _sum_ranked(problem: AssignmentProblem, parts: list, k: int, T: float, solver: str,
                method: str, P: np.ndarray) -> tuple[float, int, int, float]:
    """The k-best sums of the clusters ``parts``, written into ``P``; returns their
    log-partition, hypotheses summed, clusters approximated and largest error bound."""
    log_z, hyps, approx, bound = 0.0, 0, 0, 0.0
    for cl in parts:
        lz, p, h, b = _ranked(problem, cl, k, T, solver, method)
        if not lz > -math.inf:
            raise InvalidProblemError("the problem has no feasible solution: no marginals")
        approx += b > 0
        P[cl.candidates] = p
        log_z += lz
        hyps += h
        bound = max(bound, b)
    return log_z, hyps, approx, bound


def _exact(problem: AssignmentProblem, logw: np.ndarray, k: int, T: float, solver: str,
           method: str, max_nodes: int) -> Marginals:
    """``exact`` / ``auto``: every cluster by its net, or (``auto``) by k-best sums
    with their bound where the net does not fit."""
    from ..runtime.errors import ProblemTooLargeError
    from .hypothesis_net import exact_marginals, too_large

    ex = exact_marginals(problem, logw, max_nodes)
    if (ex.status == 2).any():
        raise InvalidProblemError("the problem has no feasible solution: no marginals")
    P = ex.P
    left = np.flatnonzero(ex.status != 0)
    if method == "exact" and len(left):
        c = int(left[0])
        raise ProblemTooLargeError(too_large(problem, ex.cluster(c), int(ex.status[c]),
                                             int(ex.width[c]), max_nodes))
    lz, hyps, approx, bound = _sum_ranked(problem, [ex.cluster(int(c)) for c in left], k, T,
                                          solver, "kbest", P)
    log_z = float(ex.log_z[ex.status == 0].sum()) + lz
    if bound > WARN_BOUND:
        warnings.warn(f"marginals: {approx} of {len(ex.log_z)} clusters are too large for "
                      f"the exact net (max_nodes={max_nodes}); their k-best sums (k={k}) "
                      f"are within {bound:.3g} only", RuntimeWarning, stacklevel=3)
    return _result(problem, P, hyps, bound == 0.0, T, log_z, method, bound, 0, 0.0,
                   len(ex.log_z), approx, int(ex.nodes.max(initial=0)))


def _ranked(problem: AssignmentProblem, cl, k: int, T: float, solver: str, method: str
            ) -> tuple[float, np.ndarray, int, float]:
    from .kbest_marginals import cluster_ranked

    return cluster_ranked(problem, cl, k, T, solver, method == "enumerate")


def _result(problem: AssignmentProblem, P: np.ndarray, hyps: int, exhaustive: bool,
            T: float, log_z: float, method: str, bound: float, iterations: int,
            residual: float, n_clusters: int, approx: int, nodes: int) -> Marginals:
    """Assemble a :class:`Marginals` (the 2-D matrices and each index's singleton)."""
    tup = problem.tuples
    real = tup > 0
    single = real.sum(axis=1) == 1
    unassigned = []
    for s, n in enumerate(problem.sizes):
        u = np.zeros(n)
        sel = single & real[:, s]
        u[tup[sel, s] - 1] = P[sel]
        unassigned.append(u)
    pairs = row_miss = col_miss = None
    if problem.ndim == 2:
        n1, n2 = problem.sizes
        pairs = np.zeros((n1, n2))
        both = real.all(axis=1)
        pairs[tup[both, 0] - 1, tup[both, 1] - 1] = P[both]
        row_miss, col_miss = unassigned[0].copy(), unassigned[1].copy()
    return Marginals(P, pairs, row_miss, col_miss, int(hyps), bool(exhaustive), T,
                     float(log_z), method, float(bound), int(iterations), float(residual),
                     int(n_clusters), int(approx), int(nodes), tuple(unassigned))
