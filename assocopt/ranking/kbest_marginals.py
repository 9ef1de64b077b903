"""Marginals of one cluster from its ``k`` best hypotheses, with a certified error bound.

Let ``Z_k`` be the weight of the ``k`` hypotheses summed, ``R`` the weight left out,
``A`` the summed weight of those containing a candidate and ``R_c <= R`` the left-out
part containing it.  The reported ``A / Z_k`` and the exact ``(A + R_c) / (Z_k + R)``
differ by at most ``R / (Z_k + R)`` (the two extremes ``R_c = R`` and ``R_c = 0`` give
``R (Z_k - A) / (Z_k (Z_k + R))`` and ``A R / (Z_k (Z_k + R))``), which grows with
``R``; so any upper bound ``R_max`` on ``R`` gives the certified bound
``R_max / (Z_k + R_max)``.  Every left-out hypothesis weighs at most the ``k``-th's
``w_k`` (Murty ranks them by cost), and there are at most ``H - k`` of them, with ``H``
a bound on the number of hypotheses: a hypothesis is fixed by the candidate covering
each index of all axes but one (the indices of the last axis not covered so are
covered by their singletons), so ``H <= prod deg(i)`` over the indices of every axis
but the one with the largest such product.  For a 2-D cluster whose columns may all
stay unassigned a second bound holds: with each pair's weight taken relative to its
column's miss, a hypothesis is a choice of one option (a column or the miss) per row,
so ``Z <= prod_j w(miss_j) * prod_i (w'(i, miss) + sum_j w'(i, j))`` =: ``Z_up`` and
``R <= Z_up - Z_k``, giving the bound ``1 - Z_k / Z_up``; the smaller of the two is
reported.  A ranking that ran out (``exhausted``) has ``R = 0``.
"""

from __future__ import annotations

import math

import numpy as np

from ..problems.problem import AssignmentProblem
from .clusters import Cluster

__all__ = ["cluster_ranked", "subproblem", "log_count_bound"]


def subproblem(problem: AssignmentProblem, cluster: Cluster) -> AssignmentProblem:
    """The cluster as a problem of its own (indices renumbered ``1..n`` per axis,
    candidates in the order of ``cluster.candidates``)."""
    off = problem.row_offsets
    axis = np.searchsorted(off, cluster.rows, side="right") - 1
    start = np.searchsorted(axis, np.arange(problem.ndim))
    local = np.arange(len(cluster.rows)) - start[axis] + 1        # 1-based per axis
    loc = np.zeros(problem.n_rows, np.int64)
    loc[cluster.rows] = local
    R = problem.entry_rows[cluster.candidates]
    tuples = np.where(R >= 0, loc[np.maximum(R, 0)], 0)
    sizes = tuple(int(n) for n in np.bincount(axis, minlength=problem.ndim))
    return AssignmentProblem.sparse(sizes, tuples, problem.costs[cluster.candidates])


def log_count_bound(sub: AssignmentProblem) -> float:
    """log of the bound ``H`` on the number of hypotheses (module docstring)."""
    deg = np.bincount(sub.entry_rows[sub.entry_rows >= 0], minlength=sub.n_rows)
    logs = np.log(np.maximum(deg, 1))
    off = list(sub.row_offsets) + [sub.n_rows]
    per_axis = [float(logs[off[s]:off[s + 1]].sum()) for s in range(sub.ndim)]
    return sum(per_axis) - max(per_axis)


def cluster_ranked(problem: AssignmentProblem, cluster: Cluster, k: int, T: float,
                   solver: str, enumerate_all: bool) -> tuple[float, np.ndarray, int, float]:
    """``(log Z_k, P, hypotheses summed, error bound)`` of one cluster, from its ``k``
    best hypotheses (or all of them, ``enumerate_all``)."""
    sub = subproblem(problem, cluster)
    if enumerate_all:
        from ..runtime.errors import ProblemTooLargeError
        from ..solvers.baseline.bruteforce import enumerate_solutions

        try:
            sels = list(enumerate_solutions(sub))
        except ProblemTooLargeError as exc:
            raise ProblemTooLargeError(
                f"method='enumerate' is for small clusters: {exc.args[0].split(';')[0]}; "
                "use method='kbest' (the k best, with an error bound) or method='exact' "
                "instead") from None
        exhausted = True
    else:
        from .kbest import kbest

        ranked = kbest(sub, k, solver)
        sels = [s.selected for s in ranked]
        exhausted = ranked.exhausted
    if not sels:
        return -math.inf, np.zeros(len(cluster.candidates)), 0, 0.0
    costs = np.array([sub.objective_of(s) for s in sels])
    logw = -costs / T
    top = logw.max()
    w = np.exp(logw - top)
    z = w.sum()
    P = np.zeros(sub.n_candidates)
    np.add.at(P, np.concatenate(sels), np.repeat(w / z, [len(s) for s in sels]))
    log_z = float(top + math.log(z))
    bound = 0.0
    if not exhausted:
        log_h = log_count_bound(sub)
        left = math.log(max(math.exp(min(log_h, 700.0)) - len(sels), 1.0)) \
            if log_h < 700 else log_h
        log_r = left + float(logw.min())                     # the k-th weight is the least
        bound = 1.0 / (1.0 + math.exp(min(log_z - log_r, 700.0)))
        log_up = _log_z_upper(sub, T)
        if log_up is not None:
            bound = min(bound, max(0.0, -math.expm1(min(log_z - log_up, 0.0))))
    return log_z, P, len(sels), bound


def _log_z_upper(sub: AssignmentProblem, T: float) -> float | None:
    """log ``Z_up`` of a 2-D cluster whose columns may all stay unassigned (module
    docstring), else None."""
    if sub.ndim != 2:
        return None
    n1, n2 = sub.sizes
    tup = sub.tuples
    lw = -np.asarray(sub.costs) / T
    cmiss = tup[:, 0] == 0
    lcm = np.full(n2, -np.inf)
    lcm[tup[cmiss, 1] - 1] = lw[cmiss]
    if not np.isfinite(lcm).all():
        return None
    rows = tup[~cmiss, 0] - 1
    rel = lw[~cmiss] - np.where(tup[~cmiss, 1] > 0, lcm[np.maximum(tup[~cmiss, 1] - 1, 0)], 0.0)
    top = np.full(n1, -np.inf)
    np.maximum.at(top, rows, rel)
    acc = np.zeros(n1)
    np.add.at(acc, rows, np.exp(rel - top[rows]))
    return float(lcm.sum() + (top + np.log(acc)).sum())
